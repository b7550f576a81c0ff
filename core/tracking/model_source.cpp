#include "core/tracking/model_source.h"

namespace rrg {

IcpModel TsdfModelSource::model_at(const Eigen::Isometry3f& T_wc) {
  if (!valid_ || cached_T_.matrix() != T_wc.matrix()) {
    raycast_into(cached_, volume_, K_, T_wc, {}, RaycastOutputs::geometry());  // ICP reads V*, N* only
    cached_T_ = T_wc;
    valid_ = true;
  }
  return {&cached_.vertices, &cached_.normals, K_, T_wc};
}

}  // namespace rrg
