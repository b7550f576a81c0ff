#include "core/common/parallel_for_cuda.cuh"
#include "core/tsdf/tsdf_integrate_impl.h"

namespace rrg::kernel {

void fusion_pixels_cuda(const FusionPixelArgs& a) { fusion_pixels(CudaBackend{}, a); }
void integrate_cuda(const IntegrateArgs<Eigen::Vector3f>& a) {
  integrate(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}
void integrate_cuda(const IntegrateArgs<Rgb8>& a) {
  integrate(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
