#include "core/common/parallel_for.h"
#include "core/tsdf/tsdf_integrate_impl.h"

namespace rrg::kernel {

void fusion_pixels_cpu(const FusionPixelArgs& a) { fusion_pixels(CpuBackend{}, a); }
void integrate_cpu(const IntegrateArgs<Eigen::Vector3f>& a) { integrate(CpuBackend{}, a); }
void integrate_cpu(const IntegrateArgs<Rgb8>& a) { integrate(CpuBackend{}, a); }

}  // namespace rrg::kernel
