#include "core/common/parallel_for.h"
#include "core/tracking/preprocess_impl.h"

namespace rrg::kernel {

void bilateral_cpu(ImageView<const float> in, ImageView<float> out, int radius, float sigma_s, float sigma_d) {
  bilateral(CpuBackend{}, in, out, radius, sigma_s, sigma_d);
}
void downsample_cpu(ImageView<const float> in, ImageView<float> out, float max_diff) {
  downsample(CpuBackend{}, in, out, max_diff);
}

}  // namespace rrg::kernel
