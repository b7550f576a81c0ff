#include "core/common/parallel_for_cuda.cuh"
#include "core/render/project_impl.h"

namespace rrg::kernel {

void project_splats_cuda(View view, GaussianViews g, Span<Splat> splats, Span<TileRect> rects) {
  project_splats(CudaBackend{}, view, g, splats, rects);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void count_tiles_cuda(Span<const TileRect> rects, Span<const int32_t> plane_ids, int32_t plane,
                      Span<int32_t> counts) {
  count_tiles(CudaBackend{}, rects, plane_ids, plane, counts);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void write_keys_cuda(int tiles_x, Span<const TileRect> rects, Span<const Splat> splats,
                     Span<const int32_t> counts, Span<const int32_t> offsets, bool with_depth,
                     Span<uint64_t> keys, Span<int32_t> values) {
  write_keys(CudaBackend{}, tiles_x, rects, splats, counts, offsets, with_depth, keys, values);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void tile_ranges_cuda(Span<const uint64_t> keys, bool with_depth, Span<TileRange> ranges) {
  tile_ranges(CudaBackend{}, keys, with_depth, ranges);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void project_bwd_cuda(View view, GaussianViews g, Span<const SplatGrad> v_splats, GaussianGradViews v) {
  project_bwd(CudaBackend{}, view, g, v_splats, v);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
