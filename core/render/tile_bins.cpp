#include "core/render/tile_bins.h"

#include "core/common/dispatch.h"
#include "core/render/project_impl.h"

namespace rrg {

void TileBins::build(const kernel::View& view, Span<const kernel::Splat> splats, Span<const kernel::TileRect> rects,
                     Span<const int32_t> plane_ids, int32_t plane, bool sort_by_depth, const Device& device) {
  const int64_t n = rects.size;
  tiles_ = int64_t(view.tiles_x()) * view.tiles_y();
  ensure_size(counts_, n, device);
  ensure_size(offsets_, n, device);
  ensure_size(ranges_, tiles_, device);
  Span<int32_t> counts{counts_.data(), n}, offsets{offsets_.data(), n};
  RRG_DISPATCH(device, kernel::count_tiles_cpu(rects, plane_ids, plane, counts),
               kernel::count_tiles_cuda(rects, plane_ids, plane, counts));
  entries_ = exclusive_scan(counts, offsets, device, scratch_);
  ensure_size(keys_, entries_, device);
  ensure_size(values_, entries_, device);
  Span<uint64_t> keys{keys_.data(), entries_};
  Span<int32_t> values{values_.data(), entries_};
  RRG_DISPATCH(device,
               kernel::write_keys_cpu(view.tiles_x(), rects, splats, counts, offsets, sort_by_depth, keys, values),
               kernel::write_keys_cuda(view.tiles_x(), rects, splats, counts, offsets, sort_by_depth, keys, values));
  const int tile_bits = bits_for(uint64_t(tiles_));
  sort_pairs(keys, values, sort_by_depth ? 32 + tile_bits : tile_bits, device, scratch_);
  mem::fill_zero(ranges_.data(), size_t(tiles_) * sizeof(kernel::TileRange), device);
  Span<kernel::TileRange> ranges{ranges_.data(), tiles_};
  RRG_DISPATCH(device, kernel::tile_ranges_cpu(keys, sort_by_depth, ranges),
               kernel::tile_ranges_cuda(keys, sort_by_depth, ranges));
}

kernel::BinViews TileBins::views() const {
  return {{values_.data(), entries_}, {ranges_.data(), tiles_}};
}

}  // namespace rrg
