#include "core/tracking/mask_source.h"

#include "core/io/synth_layout.h"

#include <stdexcept>

namespace rrg {

MaskImage tracking_mask_from_reflection(const ColorImage& reflection_color, float threshold) {
  MaskImage mask(reflection_color.width(), reflection_color.height(), 0);
  for (size_t i = 0; i < reflection_color.size(); ++i)
    mask[i] = reflection_color[i].sum() / 3.0f > threshold ? 1 : 0;
  return mask;
}

MaskImage RenderedReflectionMasks::mask(size_t frame_index, const Eigen::Isometry3f& T_wc_icp) {
  const ReflectionView view = render_(frame_index, T_wc_icp, threshold_);
  MaskImage mask = tracking_mask_from_reflection(view.color, threshold_);
  if (!view.unmodelled.empty()) {
    if (!view.unmodelled.same_size(mask))
      throw std::invalid_argument("tracking mask: the unmodelled-reflection mask is not the size of C_r");
    for (size_t i = 0; i < mask.size(); ++i) mask[i] |= view.unmodelled[i] ? 1 : 0;
  }
  return mask;
}

SynthReflectionMasks::SynthReflectionMasks(std::filesystem::path root) : root_(std::move(root)) {
  if (!std::filesystem::is_directory(root_ / "reflection"))
    throw std::runtime_error("tracking mask: " + (root_ / "reflection").string() +
                             " not found (ground-truth reflection masks need a synthetic dataset)");
}

MaskImage SynthReflectionMasks::mask(size_t frame_index, const Eigen::Isometry3f&) {
  return io::read_synth_reflection(root_, frame_index);
}

}  // namespace rrg
