#include "core/common/parallel_for_cuda.cuh"
#include "core/gaussians/gaussian_set_impl.h"

namespace rrg::kernel {

void move_words_cuda(Span<uint32_t> data, int words, Span<const int32_t> src, Span<const int32_t> dst) {
  move_words(CudaBackend{}, data, words, src, dst);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void pad_sh_rows_cuda(Span<Eigen::Vector3f> dst, int to, Span<const Eigen::Vector3f> src, int from, int64_t n) {
  pad_rows(CudaBackend{}, dst, to, src, from, n);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void remap_ids_cuda(Span<int32_t> ids, Span<const int32_t> remap) {
  remap_ids(CudaBackend{}, ids, remap);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
