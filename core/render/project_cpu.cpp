#include "core/common/parallel_for.h"
#include "core/render/project_impl.h"

namespace rrg::kernel {

void project_splats_cpu(View view, GaussianViews g, Span<Splat> splats, Span<TileRect> rects) {
  project_splats(CpuBackend{}, view, g, splats, rects);
}

void count_tiles_cpu(Span<const TileRect> rects, Span<const int32_t> plane_ids, int32_t plane,
                     Span<int32_t> counts) {
  count_tiles(CpuBackend{}, rects, plane_ids, plane, counts);
}

void write_keys_cpu(int tiles_x, Span<const TileRect> rects, Span<const Splat> splats,
                    Span<const int32_t> counts, Span<const int32_t> offsets, bool with_depth,
                    Span<uint64_t> keys, Span<int32_t> values) {
  write_keys(CpuBackend{}, tiles_x, rects, splats, counts, offsets, with_depth, keys, values);
}

void tile_ranges_cpu(Span<const uint64_t> keys, bool with_depth, Span<TileRange> ranges) {
  tile_ranges(CpuBackend{}, keys, with_depth, ranges);
}

void project_bwd_cpu(View view, GaussianViews g, Span<const SplatGrad> v_splats, GaussianGradViews v) {
  project_bwd(CpuBackend{}, view, g, v_splats, v);
}

}  // namespace rrg::kernel
