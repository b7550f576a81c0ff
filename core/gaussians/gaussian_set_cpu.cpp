#include "core/common/parallel_for.h"
#include "core/gaussians/gaussian_set_impl.h"

namespace rrg::kernel {

void move_words_cpu(Span<uint32_t> data, int words, Span<const int32_t> src, Span<const int32_t> dst) {
  move_words(CpuBackend{}, data, words, src, dst);
}

void pad_sh_rows_cpu(Span<Eigen::Vector3f> dst, int to, Span<const Eigen::Vector3f> src, int from, int64_t n) {
  pad_rows(CpuBackend{}, dst, to, src, from, n);
}

void remap_ids_cpu(Span<int32_t> ids, Span<const int32_t> remap) { remap_ids(CpuBackend{}, ids, remap); }

}  // namespace rrg::kernel
