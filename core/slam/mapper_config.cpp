// MapperParams: validation and the named configuration fields ("mapping.<name>" in a session).
#include "core/slam/mapper.h"
#include "core/slam/session_config.h"

#include <stdexcept>
#include <string>

namespace rrg {

void MapperParams::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("MapperParams: " + what); };
  if (iterations < 0) bad("iterations = " + std::to_string(iterations) + " < 0");
  if (n_local < 0) bad("n_local = " + std::to_string(n_local) + " < 0");
  if (n_global < 0) bad("n_global = " + std::to_string(n_global) + " < 0");
  if (sh_degree < 0 || sh_degree > 3) bad("sh_degree = " + std::to_string(sh_degree) + " outside [0, 3]");
  loss_weights().validate();
  densify.validate();
  reflection_stereo.validate();
  prune_base.validate();
  prune_reflection.validate();
  adam_base.validate();
  adam_reflection.validate();
}

void add_mapper_config_fields(ConfigTable& t, MapperParams& p) {
  t.i("iterations", p.iterations, "optimisation iterations per mapping step");
  t.i("n_local", p.n_local, "N_local frames since the last step");
  t.i("n_global", p.n_global, "N_global random keyframes");
  t.f("lambda_ssim", p.lambda_ssim, "λ: weight of 1 − SSIM in L_color");
  t.f("lambda_depth", p.lambda_depth, "λ_d: depth L1 weight");
  t.f("lambda_sobel", p.lambda_sobel, "λ_g: ‖Sobel(C_r)‖₁ weight");
  t.f("lambda_reflective_base", p.lambda_reflective_base,
      "λ_rb (ours): weight of mean(R·C_b), the base under a reflection (0 = the paper's loss)");
  t.i("sh_degree", p.sh_degree, "SH degree of the Gaussians (0-3)");
  t.u64("seed", p.seed, "seed of keyframe sampling and densification");
  t.b("reflections", p.reflections, "reflection Gaussians (false = base only)");
  t.f("densify.base_error", p.densify.base_error, "δ_b: colour error for base densification");
  t.f("densify.base_weight", p.densify.base_weight, "δ_w,b: base weight below which to densify");
  t.f("densify.reflection_error", p.densify.reflection_error, "δ_r: colour error for reflection densification");
  t.f("densify.variance", p.densify.variance, "δ_v: colour variance for reflection densification (with the gate)");
  t.b("densify.reflection_variance_gate", p.densify.reflection_variance_gate,
      "the paper's per-pixel C_var > δ_v test for new reflection Gaussians (off: R = 1 on an accepted plane suffices)");
  t.f("densify.reflection_weight", p.densify.reflection_weight, "δ_w,r: reflection weight below which to densify");
  t.f("densify.sample_ratio", p.densify.sample_ratio, "fraction of candidate pixels that get Gaussians");
  t.i("densify.reflection_samples", p.densify.reflection_samples, "Gaussians per reflection sample along the ray");
  t.f("densify.reflection_sample_opacity", p.densify.reflection_sample_opacity,
      "opacity of each Gaussian along a reflection ray (0: the S together as opaque as one new Gaussian)");
  t.f("densify.reflection_near", p.densify.reflection_near, "first sample past the plane, metres");
  t.f("densify.reflection_far", p.densify.reflection_far, "last sample past the plane, metres");
  t.f("densify.max_init_scale", p.densify.max_init_scale, "cap of the initial scale, metres");
  t.f("densify.reflection_max_init_scale", p.densify.reflection_max_init_scale,
      "cap of a reflection Gaussian's initial scale, metres");
  t.f("densify.reflection_min_init_scale", p.densify.reflection_min_init_scale,
      "floor of a reflection Gaussian's initial scale, metres");
  t.b("densify.base_leaves_reflections", p.densify.base_leaves_reflections,
      "no base Gaussians where the reflection set may densify (R = 1, C_var > δ_v on a reflective plane)");
  t.b("densify.reflection_mirrored_depth", p.densify.reflection_mirrored_depth,
      "reflection Gaussians at the mirrored TSDF surface instead of samples 2-8 m past the plane");
  t.b("densify.reflection_stereo_depth", p.densify.reflection_stereo_depth,
      "reflection Gaussians at the most photo-consistent depth behind the plane (a plane sweep over the step's frames)");
  t.f("reflection_stereo.near", p.reflection_stereo.near, "plane sweep: nearest virtual depth past the plane, metres");
  t.f("reflection_stereo.far", p.reflection_stereo.far, "plane sweep: farthest virtual depth past the plane, metres");
  t.i("reflection_stereo.max_hypotheses", p.reflection_stereo.max_hypotheses, "plane sweep: most depths per pixel");
  t.i("reflection_stereo.max_views", p.reflection_stereo.max_views, "plane sweep: other frames compared per frame");
  t.i("reflection_stereo.patch_radius", p.reflection_stereo.patch_radius, "plane sweep: patch radius, pixels");
  t.b("densify.reflection_residual_color", p.densify.reflection_residual_color,
      "reflection colour from max(C_gt − C_b, 0) instead of C_gt");
  t.f("prune.base.min_opacity", p.prune_base.min_opacity, "base: prune below this opacity");
  t.f("prune.base.min_scale", p.prune_base.min_scale, "base: prune below this scale, metres");
  t.f("prune.base.max_scale", p.prune_base.max_scale, "base: prune above this scale, metres");
  t.f("prune.reflection.min_opacity", p.prune_reflection.min_opacity, "reflection: prune below this opacity");
  t.f("prune.reflection.min_scale", p.prune_reflection.min_scale, "reflection: prune below this scale, metres");
  t.f("prune.reflection.max_scale", p.prune_reflection.max_scale, "reflection: prune above this scale, metres");
  for (auto [prefix, a] : {std::pair<const char*, AdamParams*>{"lr.base.", &p.adam_base}, {"lr.reflection.", &p.adam_reflection}}) {
    const std::string s = prefix;
    t.f(s + "position", a->lr.mean, "learning rate of the means");
    t.f(s + "scale", a->lr.log_scale, "learning rate of the log-scales");
    t.f(s + "opacity", a->lr.opacity, "learning rate of the logit opacities");
    t.f(s + "rotation", a->lr.rotation, "learning rate of the quaternions");
    t.f(s + "sh0", a->lr.sh0, "learning rate of SH band 0");
    t.f(s + "sh_rest", a->lr.sh_rest, "learning rate of the higher SH bands");
  }
}

}  // namespace rrg
