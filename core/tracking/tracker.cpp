#include "core/tracking/tracker.h"

#include "core/tracking/feature_matching.h"
#include "core/tracking/motion_ba.h"
#include "core/tracking/preprocess.h"
#include "core/tracking/relocalization.h"
#include "core/tracking/se3.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace rrg {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

}  // namespace

std::string to_string(TrackingState state) {
  switch (state) {
    case TrackingState::Ok: return "ok";
    case TrackingState::Degraded: return "degraded";
    case TrackingState::Lost: return "lost";
  }
  return "?";
}

Tracker::Tracker(const TrackingParams& params, const Intrinsics& K, const Device& device)
    : params_(params), K_(K), device_(device), keyframes_(params.keyframes.max_keyframes) {
  params_.validate();
  if (!K.valid()) throw std::invalid_argument("Tracker: invalid intrinsics " + K.to_string());
  require_device(device);
}

void Tracker::set_initial_pose(const Eigen::Isometry3f& T_wc) { T_initial_ = T_wc; }

void Tracker::set_pose_prior(const Eigen::Isometry3f& T_wc) {
  T_prev_ = T_wc;
  velocity_ = Eigen::Isometry3f::Identity();
}

void Tracker::resume(const Eigen::Isometry3f& T_wc) {
  started_ = true;
  T_initial_ = T_prev_ = T_wc;
  velocity_ = Eigen::Isometry3f::Identity();
}

TrackerState Tracker::export_state() const {
  TrackerState s;
  s.started = started_;
  s.T_initial = T_initial_;
  s.T_prev = T_prev_;
  s.velocity = velocity_;
  s.state = state_;
  s.next_keyframe_id = next_keyframe_id_;
  s.keyframes.assign(keyframes_.all().begin(), keyframes_.all().end());
  return s;
}

void Tracker::import_state(const TrackerState& s) {
  started_ = s.started;
  T_initial_ = s.T_initial;
  T_prev_ = s.T_prev;
  velocity_ = s.velocity;
  state_ = s.state;
  next_keyframe_id_ = s.next_keyframe_id;
  keyframes_.clear();
  for (const Keyframe& k : s.keyframes) keyframes_.add(k);
}

bool Tracker::icp_failed(const IcpResult& icp) const {
  return icp.diverged || icp.valid == 0 || icp.agreement < params_.icp.min_agreement;
}

void Tracker::add_keyframe(size_t index, const Eigen::Isometry3f& T_wc, const OrbFrame& orb) {
  keyframes_.add(make_keyframe(next_keyframe_id_++, index, T_wc, orb));
}

TrackResult Tracker::track(const TrackInput& in, ModelSource& model, MaskSource* masks) {
  if (!in.color || !in.depth) throw std::invalid_argument("track: frame " + std::to_string(in.index) + " has no colour or depth");
  if (in.depth->width() != K_.width || in.depth->height() != K_.height || !in.color->same_size(*in.depth))
    throw std::invalid_argument("track: frame " + std::to_string(in.index) + " is not " + K_.to_string());
  const bool use_mask = params_.mode == TrackingMode::IcpOrbMask;
  if (use_mask && !masks) throw std::invalid_argument("track: tracking mode icp+orb+mask needs a mask source");
  TrackResult r;

  // Lazily extracted ORB features; the mask (at the pose given) only in icp+orb+mask mode.
  std::optional<OrbFrame> orb;
  const auto orb_at = [&](const Eigen::Isometry3f& T_wc) -> const OrbFrame& {
    if (!orb) {
      const auto t0 = Clock::now();
      std::optional<MaskImage> mask;
      if (use_mask) {
        mask = masks->mask(in.index, T_wc);
        r.ms_mask += ms_since(t0);
        r.mask_pixels = std::count_if(mask->pixels().begin(), mask->pixels().end(), [](uint8_t m) { return m != 0; });
      }
      orb = extract_orb(*in.color, *in.depth, K_, mask ? &*mask : nullptr, params_.orb);
      r.orb_keypoints = int(orb->keypoints.size());
      r.ms_orb += ms_since(t0);
    }
    return *orb;
  };

  // Preprocessing, also on the first frame: its filtered depth gives fusion its normals.
  auto t0 = Clock::now();
  const DeviceImage<float>* depth = in.depth_device;
  if (!depth || !(depth->device() == device_)) {
    upload_.upload(*in.depth, device_);
    depth = &upload_;
  }
  build_pyramid_into(pyramid_, *depth, K_, params_.preprocess);
  const FramePyramid& pyramid = pyramid_;
  r.ms_preprocess = ms_since(t0);

  if (!started_) {
    started_ = true;
    r.first = true;
    r.T_wc = T_initial_;
    T_prev_ = T_initial_;
    add_keyframe(in.index, r.T_wc, orb_at(r.T_wc));
    r.keyframe = true;
    state_ = r.state = TrackingState::Ok;
    return r;
  }

  // Stage 1: ICP against the raycast at T_{k−1}, from the constant-velocity prediction.
  t0 = Clock::now();
  const Eigen::Isometry3f T_pred = predicted_pose();
  r.icp = icp_align(pyramid, model.model_at(T_prev_), T_pred, params_.icp);
  r.ms_icp = ms_since(t0);

  if (icp_failed(r.icp)) {
    // Recovery: ORB relocalisation against the keyframes, verified by ICP from the found pose.
    const RelocResult reloc = relocalise(orb_at(T_pred), keyframes_, K_, params_);
    bool recovered = false;
    if (reloc.ok) {
      t0 = Clock::now();
      const IcpResult icp2 = icp_align(pyramid, model.model_at(reloc.T_wc), reloc.T_wc, params_.icp);
      r.ms_icp += ms_since(t0);
      if (!icp_failed(icp2)) {
        r.icp = icp2;
        recovered = true;
      }
    }
    if (!recovered) {
      r.T_wc = T_prev_;
      r.state = state_ = TrackingState::Lost;
      velocity_ = Eigen::Isometry3f::Identity();
      r.note = reloc.ok ? "icp failed; relocalised pose not confirmed by icp" : "icp failed; relocalisation failed";
      return r;
    }
    r.relocalised = true;
    r.note = "icp failed (agreement " + std::to_string(r.icp.agreement) + "); relocalised against keyframe " +
             std::to_string(reloc.keyframe_id) + " (" + std::to_string(reloc.inliers) + " inliers)";
  }
  r.T_wc = r.icp.T_wc;

  // Stage 2: masked ORB refinement by motion-only BA from the ICP pose.
  if (params_.mode != TrackingMode::Icp && !keyframes_.empty()) {
    const OrbFrame& f = orb_at(r.icp.T_wc);
    t0 = Clock::now();
    const auto matches = match_by_projection(f, keyframes_.recent(params_.orb.window_keyframes), K_, r.icp.T_wc, params_.orb);
    r.orb_matches = int(matches.size());
    if (r.orb_matches < params_.orb.min_inliers) {
      r.note += (r.note.empty() ? "" : "; ") + std::string("orb: ") + std::to_string(r.orb_matches) +
                " matches, kept the icp pose";
    } else {
      const auto obs = to_observations(f, matches, params_.orb);
      PosePrior prior;
      prior.T_wc = r.icp.T_wc.cast<double>();
      const double sigma = std::max(double(r.icp.rmse_ref_m), 1e-3);
      prior.information = double(params_.orb.icp_prior_scale) * r.icp.jtj / (sigma * sigma);
      const BaResult ba = optimize_pose(obs, K_, params_.orb.baseline_fx, prior.T_wc, params_.ba,
                                        params_.orb.icp_prior_scale > 0 ? &prior : nullptr);
      r.orb_inliers = ba.inliers;
      const Eigen::Isometry3d T_icp = r.icp.T_wc.cast<double>();
      const bool plausible = translation_distance(ba.T_wc, T_icp) <= params_.orb.max_correction_m &&
                             rotation_distance(ba.T_wc, T_icp) <= params_.orb.max_correction_deg * std::numbers::pi / 180.0;
      // Evidence: the refined pose must explain the features better than the ICP pose does.
      const PoseScore at_icp = score_pose(obs, K_, params_.orb.baseline_fx, T_icp, params_.ba);
      const PoseScore at_ba = score_pose(obs, K_, params_.orb.baseline_fx, ba.T_wc, params_.ba);
      const bool better = at_ba.inliers >= at_icp.inliers && at_ba.cost < at_icp.cost;
      bool consistent = true;
      if (params_.orb.icp_prior_scale > 0) {
        const Vector6d e = pose_difference_twist(ba.T_wc, T_icp);
        consistent = e.dot(prior.information * e) <= double(params_.orb.icp_consistency_chi2);
      }
      if (ba.inliers >= params_.orb.min_inliers && plausible && better && consistent) {
        r.T_wc = ba.T_wc.cast<float>();
        r.orb_refined = true;
      } else {
        r.note += (r.note.empty() ? "" : "; ") + std::string("orb: ") + std::to_string(ba.inliers) + " inliers" +
                  (plausible ? "" : ", correction too large") +
                  (consistent ? "" : ", inconsistent with the icp information") +
                  (better ? "" : ", no better than icp (" + std::to_string(at_ba.inliers) + " vs " +
                                     std::to_string(at_icp.inliers) + " inliers)") +
                  ", kept the icp pose";
      }
    }
    r.ms_orb += ms_since(t0);
  }

  r.state = r.relocalised || r.icp.agreement < params_.icp.ok_agreement ? TrackingState::Degraded : TrackingState::Ok;
  state_ = r.state;
  if (r.state == TrackingState::Ok &&
      (keyframes_.empty() || needs_keyframe(keyframes_.back().T_wc, r.T_wc, params_.keyframes))) {  // empty after resume()
    add_keyframe(in.index, r.T_wc, orb_at(r.T_wc));
    r.keyframe = true;
  }
  velocity_ = r.relocalised ? Eigen::Isometry3f::Identity() : T_prev_.inverse() * r.T_wc;
  T_prev_ = r.T_wc;
  return r;
}

}  // namespace rrg
