#include "core/tracking/keyframes.h"

#include "core/tracking/se3.h"

#include <numbers>

namespace rrg {

bool needs_keyframe(const Eigen::Isometry3f& T_wc_last_keyframe, const Eigen::Isometry3f& T_wc,
                    const KeyframeParams& params) {
  const Eigen::Isometry3d a = T_wc_last_keyframe.cast<double>(), b = T_wc.cast<double>();
  return rotation_distance(a, b) > params.delta_angle_deg * std::numbers::pi / 180.0 ||
         translation_distance(a, b) > params.delta_move_m;
}

Keyframe make_keyframe(int id, size_t frame_index, const Eigen::Isometry3f& T_wc, const OrbFrame& orb) {
  Keyframe kf;
  kf.id = id;
  kf.frame_index = frame_index;
  kf.T_wc = T_wc;
  std::vector<int> rows;
  for (size_t i = 0; i < orb.keypoints.size(); ++i)
    if (orb.points_cam[i].z() > 0.0f) rows.push_back(int(i));
  kf.descriptors.create(int(rows.size()), 32, CV_8U);
  for (size_t k = 0; k < rows.size(); ++k) {
    const int i = rows[k];
    kf.keypoints.push_back(orb.keypoints[size_t(i)]);
    kf.points_world.push_back(T_wc * orb.points_cam[size_t(i)]);
    orb.descriptors.row(i).copyTo(kf.descriptors.row(int(k)));
  }
  return kf;
}

void KeyframeSet::add(Keyframe keyframe) {
  frames_.push_back(std::move(keyframe));
  while (int(frames_.size()) > max_) frames_.pop_front();
}

std::vector<const Keyframe*> KeyframeSet::recent(int count) const {
  std::vector<const Keyframe*> out;
  for (auto it = frames_.rbegin(); it != frames_.rend() && int(out.size()) < count; ++it) out.push_back(&*it);
  return out;
}

}  // namespace rrg
