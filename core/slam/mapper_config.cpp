// MapperParams: validation and the named configuration fields ("mapping.<name>" in a session).
#include "core/slam/mapper.h"
#include "core/slam/session_config.h"

#include <stdexcept>
#include <string>

namespace rrg {

namespace {

float parse_f(const std::string& name, const std::string& text) {
  try {
    size_t used = 0;
    const float v = std::stof(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("mapping." + name + ": '" + text + "' is not a number");
}

long long parse_i(const std::string& name, const std::string& text) {
  try {
    size_t used = 0;
    const long long v = std::stoll(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("mapping." + name + ": '" + text + "' is not an integer");
}

bool parse_b(const std::string& name, const std::string& text) {
  if (text == "true" || text == "1" || text == "on" || text == "yes") return true;
  if (text == "false" || text == "0" || text == "off" || text == "no") return false;
  throw std::invalid_argument("mapping." + name + ": '" + text + "' is not true/false");
}

}  // namespace

void MapperParams::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("MapperParams: " + what); };
  if (iterations < 0) bad("iterations = " + std::to_string(iterations) + " < 0");
  if (n_local < 0) bad("n_local = " + std::to_string(n_local) + " < 0");
  if (n_global < 0) bad("n_global = " + std::to_string(n_global) + " < 0");
  if (sh_degree < 0 || sh_degree > 3) bad("sh_degree = " + std::to_string(sh_degree) + " outside [0, 3]");
  loss_weights().validate();
  densify.validate();
  prune_base.validate();
  prune_reflection.validate();
  adam_base.validate();
  adam_reflection.validate();
}

std::vector<ConfigField> mapper_config_fields(MapperParams& p) {
  std::vector<ConfigField> out;
  auto f = [&out](std::string name, float& v, std::string help) {
    out.push_back({name, std::move(help), [&v] { return std::to_string(v); },
                   [&v, name](const std::string& t) { v = parse_f(name, t); }});
  };
  auto i = [&out](std::string name, int& v, std::string help) {
    out.push_back({name, std::move(help), [&v] { return std::to_string(v); },
                   [&v, name](const std::string& t) { v = int(parse_i(name, t)); }});
  };
  auto b = [&out](std::string name, bool& v, std::string help) {
    out.push_back({name, std::move(help), [&v] { return std::string(v ? "true" : "false"); },
                   [&v, name](const std::string& t) { v = parse_b(name, t); }});
  };
  i("iterations", p.iterations, "optimisation iterations per mapping step");
  i("n_local", p.n_local, "N_local frames since the last step");
  i("n_global", p.n_global, "N_global random keyframes");
  f("lambda_ssim", p.lambda_ssim, "λ: weight of 1 − SSIM in L_color");
  f("lambda_depth", p.lambda_depth, "λ_d: depth L1 weight");
  f("lambda_sobel", p.lambda_sobel, "λ_g: ‖Sobel(C_r)‖₁ weight");
  i("sh_degree", p.sh_degree, "SH degree of the Gaussians (0-3)");
  out.push_back({"seed", "seed of keyframe sampling and densification", [&p] { return std::to_string(p.seed); },
                 [&p](const std::string& t) { p.seed = uint64_t(parse_i("seed", t)); }});
  b("reflections", p.reflections, "reflection Gaussians (false = base only)");
  f("densify.base_error", p.densify.base_error, "δ_b: colour error for base densification");
  f("densify.base_weight", p.densify.base_weight, "δ_w,b: base weight below which to densify");
  f("densify.reflection_error", p.densify.reflection_error, "δ_r: colour error for reflection densification");
  f("densify.variance", p.densify.variance, "δ_v: colour variance for reflection densification");
  f("densify.reflection_weight", p.densify.reflection_weight, "δ_w,r: reflection weight below which to densify");
  f("densify.sample_ratio", p.densify.sample_ratio, "fraction of candidate pixels that get Gaussians");
  i("densify.reflection_samples", p.densify.reflection_samples, "Gaussians per reflection sample along the ray");
  f("densify.reflection_near", p.densify.reflection_near, "first sample past the plane, metres");
  f("densify.reflection_far", p.densify.reflection_far, "last sample past the plane, metres");
  f("densify.max_init_scale", p.densify.max_init_scale, "cap of the initial scale, metres");
  f("prune.base.min_opacity", p.prune_base.min_opacity, "base: prune below this opacity");
  f("prune.base.min_scale", p.prune_base.min_scale, "base: prune below this scale, metres");
  f("prune.base.max_scale", p.prune_base.max_scale, "base: prune above this scale, metres");
  f("prune.reflection.min_opacity", p.prune_reflection.min_opacity, "reflection: prune below this opacity");
  f("prune.reflection.min_scale", p.prune_reflection.min_scale, "reflection: prune below this scale, metres");
  f("prune.reflection.max_scale", p.prune_reflection.max_scale, "reflection: prune above this scale, metres");
  for (auto [prefix, a] : {std::pair<const char*, AdamParams*>{"lr.base.", &p.adam_base}, {"lr.reflection.", &p.adam_reflection}}) {
    const std::string s = prefix;
    f(s + "position", a->lr.mean, "learning rate of the means");
    f(s + "scale", a->lr.log_scale, "learning rate of the log-scales");
    f(s + "opacity", a->lr.opacity, "learning rate of the logit opacities");
    f(s + "rotation", a->lr.rotation, "learning rate of the quaternions");
    f(s + "sh0", a->lr.sh0, "learning rate of SH band 0");
    f(s + "sh_rest", a->lr.sh_rest, "learning rate of the higher SH bands");
  }
  return out;
}

}  // namespace rrg
