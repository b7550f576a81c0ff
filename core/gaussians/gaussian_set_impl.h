#pragma once
// Per-Gaussian moves of GaussianSet::prune / apply_compaction, templated on the back end.
#include "core/common/span.h"

#include <cstdint>

namespace rrg::kernel {

// data[dst[j] * words + w] = data[src[j] * words + w]. Sources all lie at or past the new size and
// destinations before it, so the moves never overlap and run in parallel.
template <class Backend>
void move_words(Backend backend, Span<uint32_t> data, int words, Span<const int32_t> src,
                Span<const int32_t> dst) {
  parallel_for(backend, src.size * words, [=] RRG_HD(int64_t i) {
    const int64_t j = i / words, w = i % words;
    data[int64_t(dst[j]) * words + w] = data[int64_t(src[j]) * words + w];
  });
}

void move_words_cpu(Span<uint32_t> data, int words, Span<const int32_t> src, Span<const int32_t> dst);
void move_words_cuda(Span<uint32_t> data, int words, Span<const int32_t> src, Span<const int32_t> dst);

}  // namespace rrg::kernel
