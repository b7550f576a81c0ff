#include "core/tracking/tracking_params.h"

#include <cmath>
#include <stdexcept>

namespace rrg {

TrackingMode parse_tracking_mode(const std::string& text) {
  if (text == "icp") return TrackingMode::Icp;
  if (text == "icp+orb") return TrackingMode::IcpOrb;
  if (text == "icp+orb+mask") return TrackingMode::IcpOrbMask;
  throw std::invalid_argument("unknown tracking mode '" + text + "' (expected icp, icp+orb or icp+orb+mask)");
}

std::string to_string(TrackingMode mode) {
  switch (mode) {
    case TrackingMode::Icp: return "icp";
    case TrackingMode::IcpOrb: return "icp+orb";
    case TrackingMode::IcpOrbMask: return "icp+orb+mask";
  }
  return "?";
}

void TrackingParams::validate() const {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("tracking params: " + what); };
  if (preprocess.levels < 1 || preprocess.levels > 3) fail("preprocess.levels must be 1..3");
  if (preprocess.bilateral_radius < 1) fail("preprocess.bilateral_radius must be >= 1");
  if (!(preprocess.sigma_space_px > 0) || !(preprocess.sigma_depth_m > 0)) fail("bilateral sigmas must be > 0");
  for (int it : icp.iterations)
    if (it < 0) fail("icp.iterations must be >= 0");
  if (!(icp.max_distance_m > 0)) fail("icp.max_distance_m must be > 0");
  if (!(icp.max_normal_angle_deg > 0 && icp.max_normal_angle_deg <= 90)) fail("icp.max_normal_angle_deg must be in (0, 90]");
  if (!(icp.huber_delta_m > 0)) fail("icp.huber_delta_m must be > 0");
  if (icp.noise_weighting) {
    if (!icp.noise.valid()) fail("icp.noise must have a, b >= 0 and be finite");
    if (!(icp.noise_reference_depth_m > 0)) fail("icp.noise_reference_depth_m must be > 0");
    if (!(icp.model_sigma_m >= 0 && std::isfinite(icp.model_sigma_m))) fail("icp.model_sigma_m must be >= 0 metres");
    // σ_n(z) >= a, its value at z0: a > 0 keeps every pair's weight finite.
    if (!(icp.noise.a > 0)) fail("icp.noise.a must be > 0 with noise weighting (σ_n(z) >= a divides the residuals)");
  }
  if (!(icp.agreement_sigmas > 0)) fail("icp.agreement_sigmas must be > 0");
  if (!(icp.min_agreement >= 0 && icp.min_agreement <= icp.ok_agreement && icp.ok_agreement <= 1))
    fail("icp.min_agreement and icp.ok_agreement must satisfy 0 <= min <= ok <= 1");
  if (orb.features < 10) fail("orb.features must be >= 10");
  if (!(orb.ratio > 0 && orb.ratio <= 1)) fail("orb.ratio must be in (0, 1]");
  if (!(orb.icp_prior_scale >= 0)) fail("orb.icp_prior_scale must be >= 0");
  if (!(orb.max_depth_range >= 0)) fail("orb.max_depth_range must be >= 0 (0 = off)");
  if (!(orb.icp_consistency_chi2 > 0)) fail("orb.icp_consistency_chi2 must be > 0");
  if (orb.window_keyframes < 1) fail("orb.window_keyframes must be >= 1");
  if (orb.min_inliers < 6) fail("orb.min_inliers must be >= 6");
  if (orb.mask_downsample < 1 || orb.mask_downsample > 8) fail("orb.mask_downsample must be in [1, 8]");
  if (ba.rounds < 1 || ba.iterations < 1) fail("ba.rounds and ba.iterations must be >= 1");
  if (!(keyframes.delta_angle_deg > 0) || !(keyframes.delta_move_m > 0)) fail("keyframe thresholds must be > 0");
  if (keyframes.max_keyframes < 1) fail("keyframes.max_keyframes must be >= 1");
  if (reloc.ransac_iterations < 1 || reloc.min_inliers < 3) fail("reloc: iterations >= 1, min_inliers >= 3");
}

}  // namespace rrg
