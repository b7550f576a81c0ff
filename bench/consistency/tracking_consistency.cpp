// rrg_tracking_consistency: how much the two stages of tracking claim to know about a pose, against
// what they know, on a sequence with ground-truth poses (docs/tracking.md "How much to trust ICP").
//
// Every frame is tracked from the ground truth: the model is fused at the ground-truth poses, ICP
// starts from the previous ground-truth pose, and the ORB keyframes are made at ground-truth poses.
// So each stage's error e (the PosePrior's world-frame twist of T_est T_gt⁻¹) is its own, not
// inherited drift, and its normalised estimation error squared NEES = eᵀ Λ e, with the information
// Λ the stage claims (ICP: JᵀJ / σ², the prior's Λ at s = 1; ORB: the motion-only BA's Σ Ω JᵀJ),
// averages 6 (six degrees of freedom) when Λ is honest. mean(NEES) / 6 = k is how many times too
// confident a stage is; the ICP prior's honest scale next to the BA's own information is then
// s = k_orb / k_icp. The median is reported too (χ²₆'s median is 5.348), since a few bad frames
// dominate a mean of squares.
#include "core/common/device.h"
#include "core/io/dataset.h"
#include "core/tracking/feature_matching.h"
#include "core/tracking/keyframes.h"
#include "core/tracking/mask_source.h"
#include "core/tracking/motion_ba.h"
#include "core/tracking/orb_features.h"
#include "core/tracking/se3.h"
#include "core/tracking/tracker.h"
#include "core/tsdf/tsdf_integrate.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <memory>
#include <numbers>
#include <cstdio>
#include <vector>

namespace {

using namespace rrg;

struct Stats {
  std::vector<double> nees, translation_mm, rotation_deg;
  void add(const Vector6d& e, const Matrix6d& info) {
    nees.push_back(e.dot(info * e));
    translation_mm.push_back(e.head<3>().norm() * 1e3);
    rotation_deg.push_back(e.tail<3>().norm() * 180.0 / std::numbers::pi);
  }
  static double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
  }
  static double mean(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / double(v.size());
  }
  double k_mean() const { return mean(nees) / 6.0; }
  double k_median() const { return median(nees) / 5.348; }
  void print(const char* name) const {
    std::printf("%-4s frames %4zu  error median %.2f mm %.3f deg  NEES mean %.4g median %.4g  k = %.4g (mean) %.4g (median)\n",
                name, nees.size(), median(translation_mm), median(rotation_deg), mean(nees), median(nees), k_mean(),
                k_median());
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ICP and ORB pose information against ground truth (NEES): the honest ICP prior scale"};
  std::string dataset_path;
  float voxel = 0.01f, max_depth = 5.0f;
  int max_frames = 0, skip = 1;
  bool synth_masks = false;
  float orb_depth_range = OrbParams{}.max_depth_range;
  app.add_option("--dataset", dataset_path, "dataset with ground-truth poses")->required();
  app.add_option("--voxel", voxel, "TSDF voxel size, metres");
  app.add_option("--max-depth", max_depth, "ignore depth beyond, metres");
  app.add_option("--max-frames", max_frames, "stop after N frames (0 = all)");
  float model_sigma = 0.0f;
  app.add_option("--model-sigma", model_sigma, "σ_m of ICP's model term, metres (IcpParams::model_sigma_m)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--skip", skip, "track every N-th frame (larger motion per frame)")->check(CLI::PositiveNumber);
  app.add_flag("--synth-masks", synth_masks,
               "keep ORB off the generator's ground-truth reflection masks (reflection/), as icp+orb+mask does");
  app.add_option("--orb-depth-range", orb_depth_range,
                 "a keypoint whose window's depths span more than this fraction of its depth keeps no depth (0 = off)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  try {
    const auto dataset = io::open_dataset(dataset_path);
    const Intrinsics& K = dataset->intrinsics();
    TrackingParams params;
    params.mode = TrackingMode::Icp;  // stage 2 is run here, from the ground-truth keyframes
    params.orb.max_depth_range = orb_depth_range;
    params.icp.model_sigma_m = model_sigma;
    TsdfParams tsdf;
    tsdf.voxel_size = voxel;
    tsdf.truncation = 4.0f * voxel;
    tsdf.noise = params.icp.noise;
    tsdf.max_depth = max_depth;
    const Device device = Device::cpu();
    TsdfVolume volume(tsdf, device);
    TsdfModelSource model(volume, K);
    Tracker tracker(params, K, device);
    KeyframeSet keyframes(params.keyframes.max_keyframes);
    Stats icp, orb;
    int keyframe_id = 0;
    std::unique_ptr<SynthReflectionMasks> masks;
    if (synth_masks) masks = std::make_unique<SynthReflectionMasks>(dataset_path);
    const size_t n = max_frames > 0 ? std::min(dataset->size(), size_t(max_frames)) : dataset->size();
    Eigen::Isometry3d T_prev_gt = Eigen::Isometry3d::Identity();
    for (size_t i = 0; i < n; i += size_t(skip)) {
      const io::Frame f = dataset->load(i);
      if (!f.T_wc_gt) throw std::runtime_error("frame " + std::to_string(i) + " has no ground-truth pose");
      const Eigen::Isometry3d T_gt = *f.T_wc_gt;
      const auto depth = DeviceImage<float>::from_host(f.depth, device);
      const auto color = DeviceImage<Color>::from_host(f.color, device);
      if (i == 0) {
        tracker.set_initial_pose(T_gt.cast<float>());
      } else {
        tracker.set_pose_prior(T_prev_gt.cast<float>());
      }
      const TrackResult r = tracker.track({i, &f.color, &f.depth, &depth}, model, nullptr);
      if (!r.first && r.state == TrackingState::Ok) {
        const double sigma = std::max(double(r.icp.rmse_ref_m), 1e-6);
        icp.add(pose_difference_twist(r.icp.T_wc.cast<double>(), T_gt), r.icp.jtj / (sigma * sigma));
      }
      const MaskImage mask = masks ? masks->mask(i, T_gt.cast<float>()) : MaskImage();
      const OrbFrame features = extract_orb(f.color, f.depth, K, masks ? &mask : nullptr, params.orb);
      if (!keyframes.empty() && !r.first) {
        const auto matches = match_by_projection(features, keyframes.recent(params.orb.window_keyframes), K,
                                                 r.icp.T_wc, params.orb);
        const auto obs = to_observations(features, matches, params.orb);
        const BaResult ba = optimize_pose(obs, K, params.orb.baseline_fx, r.icp.T_wc.cast<double>(), params.ba);
        if (ba.inliers >= params.orb.min_inliers) orb.add(pose_difference_twist(ba.T_wc, T_gt), ba.information);
      }
      if (keyframes.empty() || needs_keyframe(keyframes.back().T_wc, T_gt.cast<float>(), params.keyframes))
        keyframes.add(make_keyframe(keyframe_id++, i, T_gt.cast<float>(), features));
      integrate(volume, depth, color, K, T_gt.cast<float>(), nullptr, tracker.normal_depth());
      model.invalidate();
      T_prev_gt = T_gt;
      if ((i / size_t(skip)) % 50 == 0) spdlog::info("frame {} / {}", i, n);
    }
    icp.print("icp");
    orb.print("orb");
    std::printf("honest ICP prior scale s = k_orb / k_icp: %.4g (means) %.4g (medians)\n",
                orb.k_mean() / icp.k_mean(), orb.k_median() / icp.k_median());
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
