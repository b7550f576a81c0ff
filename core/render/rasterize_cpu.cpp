#include "core/common/parallel_for.h"
#include "core/render/rasterize_impl.h"

namespace rrg::kernel {

void base_fwd_cpu(BaseFwdArgs a) { base_fwd(CpuBackend{}, a); }

void base_bwd_cpu(BaseBwdArgs a) { base_bwd(CpuBackend{}, a); }

void refl_fwd_cpu(ReflFwdArgs a) { refl_fwd(CpuBackend{}, a); }

void refl_bwd_cpu(ReflBwdArgs a) { refl_bwd(CpuBackend{}, a); }

void composite_cpu(ImageView<const Eigen::Vector3f> C_b, ImageView<const float> R,
                   ImageView<const Eigen::Vector3f> C_r, ImageView<Eigen::Vector3f> C) {
  composite(CpuBackend{}, C_b, R, C_r, C);
}

void composite_bwd_cpu(ImageView<const Eigen::Vector3f> v_C, ImageView<const float> R,
                       ImageView<const Eigen::Vector3f> v_C_r_extra, bool has_extra,
                       ImageView<Eigen::Vector3f> v_C_r) {
  composite_bwd(CpuBackend{}, v_C, R, v_C_r_extra, has_extra, v_C_r);
}

void mask_group_cpu(ImageView<const int32_t> I, int32_t plane, ImageView<const Eigen::Vector3f> C_k,
                    ImageView<const float> W_k, ImageView<Eigen::Vector3f> C_r, ImageView<float> W_r) {
  mask_group(CpuBackend{}, I, plane, C_k, W_k, C_r, W_r);
}

}  // namespace rrg::kernel
