#pragma once
// Where the tracking mask R_k^track comes from (paper §4.1.2): the reflection image C_r rendered
// at the ICP pose, R_k^track(u) = mean RGB of C_r(u) > 0.1. Until the Gaussian engine exists the
// source is pluggable; the synthetic generator's ground-truth reflection masks are one source.
#include "core/common/image.h"

#include <Eigen/Geometry>

#include <filesystem>
#include <functional>

namespace rrg {

class MaskSource {
 public:
  virtual ~MaskSource() = default;
  // R_k^track of frame `frame_index` seen from T_wc_icp (non-zero = reflection, no features).
  virtual MaskImage mask(size_t frame_index, const Eigen::Isometry3f& T_wc_icp) = 0;
};

// R^track(u) = (C_r,r + C_r,g + C_r,b) / 3 > threshold.
MaskImage tracking_mask_from_reflection(const ColorImage& reflection_color, float threshold = 0.1f);

// What a reflection renderer gives the mask at a pose: C_r, and the pixels whose reflection the
// model cannot render yet (a session's planes that a semantic cue calls reflective and whose vote
// is still open, or accepted planes without reflection Gaussians so far: docs/tracking.md
// "Reflections not modelled yet"). Both are kept out of ORB.
struct ReflectionView {
  ColorImage color;      // C_r
  MaskImage unmodelled;  // non-zero: reflection not modelled yet; empty: none
};

// Renders C_r with a callback (the reflection Gaussians) and thresholds it, or'ed with the view's
// unmodelled pixels. The callback gets the threshold: C_r only needs to be exact where its mean RGB
// stays at or below it (a renderer may stop a pixel once it is above,
// Renderer::render_reflection's stop_mean), so the stop and the test are one value.
class RenderedReflectionMasks final : public MaskSource {
 public:
  using Renderer = std::function<ReflectionView(size_t frame_index, const Eigen::Isometry3f& T_wc, float threshold)>;
  RenderedReflectionMasks(Renderer render, float threshold) : render_(std::move(render)), threshold_(threshold) {}
  MaskImage mask(size_t frame_index, const Eigen::Isometry3f& T_wc_icp) override;

 private:
  Renderer render_;
  float threshold_;
};

// Ground-truth reflection masks of a synthetic dataset (reflection/NNNNNN.png, core/io/synth_layout.h).
class SynthReflectionMasks final : public MaskSource {
 public:
  explicit SynthReflectionMasks(std::filesystem::path root);  // throws if root/reflection is missing
  MaskImage mask(size_t frame_index, const Eigen::Isometry3f& T_wc_icp) override;

 private:
  std::filesystem::path root_;
};

}  // namespace rrg
