#include "core/common/parallel_for.h"
#include "core/gaussians/gaussian_set_impl.h"

namespace rrg::kernel {

void move_words_cpu(Span<uint32_t> data, int words, Span<const int32_t> src, Span<const int32_t> dst) {
  move_words(CpuBackend{}, data, words, src, dst);
}

}  // namespace rrg::kernel
