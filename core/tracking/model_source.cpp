#include "core/tracking/model_source.h"

#include <algorithm>

namespace rrg {

IcpModel TsdfModelSource::model_at(const Eigen::Isometry3f& T_wc) {
  if (!valid_ || cached_T_.matrix() != T_wc.matrix()) {
    // ICP reads V*, N* only; I for the tracking mask's warp when asked for.
    raycast_into(cached_, volume_, K_, T_wc, remap_,
                 RaycastOutputs{.color = false, .reflection = plane_ids_, .normals = true});
    cached_T_ = T_wc;
    valid_ = true;
  }
  return {&cached_.vertices, &cached_.normals, K_, T_wc};
}

void TsdfModelSource::set_plane_ids(bool on, std::span<const int32_t> remap) {
  if (on == plane_ids_ && (!on || std::equal(remap.begin(), remap.end(), remap_.begin(), remap_.end()))) return;
  plane_ids_ = on;
  if (on) remap_.assign(remap.begin(), remap.end());
  else remap_.clear();
  valid_ = false;
}

}  // namespace rrg
