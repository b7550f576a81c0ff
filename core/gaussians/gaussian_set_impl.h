#pragma once
// Per-Gaussian moves of GaussianSet::prune / apply_compaction, the SH padding of
// GaussianSet::append and the plane-id remap of GaussianSet::remap_plane_ids, templated on the
// back end.
#include "core/common/span.h"

#include <Eigen/Core>

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

// Coefficient rows of n Gaussians with `from` SH coefficients each (src, [n, from]) written into
// rows of `to` >= from coefficients (dst, [n, to]), the higher bands zero: a batch of new Gaussians
// (DC only, say) appended to a set of higher degree.
template <class Backend, class C>
void pad_rows(Backend backend, Span<C> dst, int to, Span<const C> src, int from, int64_t n) {
  parallel_for(backend, n * to, [=] RRG_HD(int64_t i) {
    const int64_t g = i / to, k = i % to;
    dst[i] = k < from ? src[g * from + k] : C::Zero();
  });
}

// Plane ids through an id -> canonical id table (the global plane table's merges): ids[i] =
// remap[ids[i]] where ids[i] is a positive id inside the table and remap holds a positive id for it;
// others (0 = none, ids the table does not know) stay.
template <class Backend>
void remap_ids(Backend backend, Span<int32_t> ids, Span<const int32_t> remap) {
  parallel_for(backend, ids.size, [=] RRG_HD(int64_t i) {
    const int32_t l = ids[i];
    if (l > 0 && l < remap.size && remap[l] > 0) ids[i] = remap[l];
  });
}

void move_words_cpu(Span<uint32_t> data, int words, Span<const int32_t> src, Span<const int32_t> dst);
void move_words_cuda(Span<uint32_t> data, int words, Span<const int32_t> src, Span<const int32_t> dst);
void pad_sh_rows_cpu(Span<Eigen::Vector3f> dst, int to, Span<const Eigen::Vector3f> src, int from, int64_t n);
void pad_sh_rows_cuda(Span<Eigen::Vector3f> dst, int to, Span<const Eigen::Vector3f> src, int from, int64_t n);
void remap_ids_cpu(Span<int32_t> ids, Span<const int32_t> remap);
void remap_ids_cuda(Span<int32_t> ids, Span<const int32_t> remap);

}  // namespace rrg::kernel
