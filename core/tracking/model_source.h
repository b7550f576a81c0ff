#pragma once
// Where ICP's model comes from: a raycast of the map at a pose. Tracking asks for the model at the
// previous pose T_{k−1} (and at a relocalised pose to verify it). The TSDF source raycasts
// core/tsdf; tests can serve fixed maps.
#include "core/tracking/icp.h"
#include "core/tsdf/tsdf_raycast.h"
#include "core/tsdf/tsdf_volume.h"

#include <span>
#include <vector>

namespace rrg {

class ModelSource {
 public:
  virtual ~ModelSource() = default;
  // The model seen from T_wc; its images stay valid until the next call.
  virtual IcpModel model_at(const Eigen::Isometry3f& T_wc) = 0;
};

// Raycasts a TSDF volume (V*, N* in the world frame; the geometry only, RaycastOutputs) with
// intrinsics K; the last raycast is kept and reused when asked again for the same pose, and its
// images are raycast into again for the next pose (no allocation per frame).
class TsdfModelSource final : public ModelSource {
 public:
  TsdfModelSource(const TsdfVolume& volume, const Intrinsics& K) : volume_(volume), K_(K) {}
  IcpModel model_at(const Eigen::Isometry3f& T_wc) override;
  // Forgets the cached raycast (call after fusing a frame).
  void invalidate() { valid_ = false; }
  // With plane ids the raycast also keeps I (RaycastOutputs::reflection), canonical through
  // `remap`, so that the tracking mask can warp it to the ICP pose (raycast_warp.h) instead of
  // raycasting again. A change forgets the cached raycast.
  void set_plane_ids(bool on, std::span<const int32_t> remap = {});
  // The cached raycast (D_t, V*, N*, and I with plane ids), or null when there is none.
  const RaycastResult* last() const { return valid_ ? &cached_ : nullptr; }

 private:
  const TsdfVolume& volume_;
  Intrinsics K_;
  RaycastResult cached_;
  bool plane_ids_ = false;
  std::vector<int32_t> remap_;
  bool valid_ = false;
  Eigen::Isometry3f cached_T_ = Eigen::Isometry3f::Identity();
};

}  // namespace rrg
