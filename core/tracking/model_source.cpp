#include "core/tracking/model_source.h"

namespace rrg {

IcpModel TsdfModelSource::model_at(const Eigen::Isometry3f& T_wc) {
  if (!cached_ || cached_T_.matrix() != T_wc.matrix()) {
    cached_ = raycast(volume_, K_, T_wc, {}, RaycastOutputs::geometry());  // ICP reads V*, N* only
    cached_T_ = T_wc;
  }
  return {&cached_->vertices, &cached_->normals, K_, T_wc};
}

}  // namespace rrg
