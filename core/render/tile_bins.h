#pragma once
// Tile binning of projected splats (16 x 16 tiles): every (tile, Gaussian) overlap becomes an entry,
// entries are sorted by tile (pass 2: sort-free, tile only) or by (tile, depth) (pass 3), and each
// tile gets its [begin, end) range. Owns its scratch; reuses it across frames.
#include "core/common/buffer.h"
#include "core/render/device_sort.h"
#include "core/render/splat.h"
#include "core/render/stage_args.h"

namespace rrg {

class TileBins {
 public:
  // Bins the splats whose plane id equals `plane` (plane < 0: all) on rects' device.
  void build(const kernel::View& view, Span<const kernel::Splat> splats, Span<const kernel::TileRect> rects,
             Span<const int32_t> plane_ids, int32_t plane, bool sort_by_depth, const Device& device);
  kernel::BinViews views() const;
  int64_t entries() const { return entries_; }

 private:
  Buffer<int32_t> counts_, offsets_;
  Buffer<uint64_t> keys_;
  Buffer<int32_t> values_;
  Buffer<kernel::TileRange> ranges_;
  int64_t entries_ = 0, tiles_ = 0;
  SortScratch scratch_;
};

// Grows b to at least n elements on device (contents not kept; 1.5x headroom).
template <class T>
void ensure_size(Buffer<T>& b, int64_t n, const Device& device) {
  if (int64_t(b.size()) < n || b.device() != device) b = Buffer<T>(size_t(n + n / 2), device);
}

}  // namespace rrg
