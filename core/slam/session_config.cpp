#include "core/slam/session_config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rrg {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

[[noreturn]] void bad_value(const std::string& key, const std::string& text, const char* what) {
  throw std::invalid_argument("config " + key + ": '" + text + "' is not " + what);
}

float parse_float(const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  float v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size() || !std::isfinite(v))
    bad_value(key, text, "a finite number");
  return v;
}

int parse_int(const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  long long v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size() || v < INT32_MIN || v > INT32_MAX)
    bad_value(key, text, "an integer");
  return int(v);
}

bool parse_bool(const std::string& key, const std::string& text) {
  std::string t = trim(text);
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (t == "true" || t == "1" || t == "yes" || t == "on") return true;
  if (t == "false" || t == "0" || t == "no" || t == "off") return false;
  bad_value(key, text, "a boolean (true/false)");
}

std::string float_text(float v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

// Levenshtein distance, for "did you mean" suggestions.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

void walk_yaml(SessionConfig& c, const YAML::Node& node, const std::string& prefix, const std::string& file) {
  if (!node.IsMap()) throw std::runtime_error(file + ": expected a map at '" + (prefix.empty() ? "<top>" : prefix) + "'");
  for (const auto& kv : node) {
    const std::string key = prefix.empty() ? kv.first.as<std::string>() : prefix + "." + kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    if (v.IsMap()) {
      walk_yaml(c, v, key, file);
    } else if (v.IsSequence()) {  // lists: prompts
      std::string joined;
      for (const auto& item : v) joined += (joined.empty() ? "" : ",") + item.as<std::string>();
      set_config_value(c, key, joined);
    } else if (v.IsScalar()) {
      set_config_value(c, key, v.Scalar());
    } else if (!v.IsNull()) {
      throw std::runtime_error(file + ": unsupported value at '" + key + "'");
    }
  }
}

uint64_t parse_u64(const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  uint64_t v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size()) bad_value(key, text, "a non-negative integer");
  return v;
}

}  // namespace

void ConfigTable::f(const std::string& name, float& v, std::string help) {
  fields.push_back({prefix + name, std::move(help), [&v] { return float_text(v); },
                    [&v, n = prefix + name](const std::string& t) { v = parse_float(n, t); }});
}
void ConfigTable::i(const std::string& name, int& v, std::string help) {
  fields.push_back({prefix + name, std::move(help), [&v] { return std::to_string(v); },
                    [&v, n = prefix + name](const std::string& t) { v = parse_int(n, t); }});
}
void ConfigTable::i64(const std::string& name, int64_t& v, std::string help) {
  fields.push_back({prefix + name, std::move(help), [&v] { return std::to_string(v); },
                    [&v, n = prefix + name](const std::string& t) { v = parse_int(n, t); }});
}
void ConfigTable::u64(const std::string& name, uint64_t& v, std::string help) {
  fields.push_back({prefix + name, std::move(help), [&v] { return std::to_string(v); },
                    [&v, n = prefix + name](const std::string& t) { v = parse_u64(n, t); }});
}
void ConfigTable::b(const std::string& name, bool& v, std::string help) {
  fields.push_back({prefix + name, std::move(help), [&v] { return std::string(v ? "true" : "false"); },
                    [&v, n = prefix + name](const std::string& t) { v = parse_bool(n, t); }});
}
void ConfigTable::s(const std::string& name, std::string& v, std::string help) {
  fields.push_back({prefix + name, std::move(help), [&v] { return v; }, [&v](const std::string& t) { v = trim(t); }});
}
void ConfigTable::custom(const std::string& name, std::string help, std::function<std::string()> get,
                         std::function<void(const std::string&)> set) {
  fields.push_back({prefix + name, std::move(help), std::move(get), std::move(set)});
}

TrackingParams SessionConfig::tracking_params() const {
  TrackingParams t = tracking;
  t.icp.noise = planes.segmentation.noise;
  return t;
}

TsdfParams SessionConfig::tsdf_params() const {
  TsdfParams t = tsdf;
  t.noise = planes.segmentation.noise;
  return t;
}

MappingSchedule SessionConfig::schedule() const {
  return sync ? MappingSchedule::Sync : (live ? MappingSchedule::Live : MappingSchedule::Overlapped);
}

std::string to_string(MappingSchedule s) {
  switch (s) {
    case MappingSchedule::Sync: return "sync";
    case MappingSchedule::Overlapped: return "overlapped";
    case MappingSchedule::Live: return "live";
  }
  return "?";
}

void SessionConfig::validate() const {
  if (!K.valid())
    throw std::invalid_argument("config intrinsics: need fx, fy > 0 and a positive image size (got " + K.to_string() + ")");
  if (K.width > 8192 || K.height > 8192)
    throw std::invalid_argument("config intrinsics: image size " + std::to_string(K.width) + "x" +
                                std::to_string(K.height) + " is larger than 8192");
  if (!(K.cx > -K.width && K.cx < 2.0f * K.width && K.cy > -K.height && K.cy < 2.0f * K.height))
    throw std::invalid_argument("config intrinsics: principal point (" + float_text(K.cx) + ", " + float_text(K.cy) +
                                ") is far outside the image");
  tsdf_params().validate();
  tracking_params().validate();
  planes.validate();
  mapping.validate();
  if (!(stream_radius >= 0.0f && std::isfinite(stream_radius)))
    throw std::invalid_argument("config tsdf.stream_radius: must be >= 0 metres (0: no streaming), got " +
                                float_text(stream_radius));
  if (plane_period < 1) throw std::invalid_argument("config plane_period: must be >= 1");
  if (mapping_period < 1) throw std::invalid_argument("config mapping_period: must be >= 1");
  if (final_steps < 0) throw std::invalid_argument("config final_steps: must be >= 0");
  if (!(live_step_scale >= 1.0f && live_step_scale <= 100.0f))
    throw std::invalid_argument("config live_step_scale: must be in [1, 100] (1: every live step runs mapping.iterations)");
  if (sync && live)
    throw std::invalid_argument("config sync and live: choose one (sync runs every step inline, live never waits for one)");
  if (semantics != "none" && semantics != "labels" && semantics != "remote")
    throw std::invalid_argument("config semantics: '" + semantics + "' is not none, labels or remote");
  if (semantics == "remote" && remote_address.empty())
    throw std::invalid_argument("config remote_address: semantics = remote needs a segmenter address");
}

std::vector<ConfigField> config_fields(SessionConfig& c) {
  ConfigTable t;
  // camera
  t.f("camera.fx", c.K.fx, "focal length x, pixels");
  t.f("camera.fy", c.K.fy, "focal length y, pixels");
  t.f("camera.cx", c.K.cx, "principal point x, pixels");
  t.f("camera.cy", c.K.cy, "principal point y, pixels");
  t.i("camera.width", c.K.width, "image width, pixels");
  t.i("camera.height", c.K.height, "image height, pixels");
  t.custom("device", "cpu | cuda | cuda:N | auto", [&c] { return c.device.to_string(); },
           [&c](const std::string& v) { c.device = parse_device(trim(v)); });
  // schedule (paper §4)
  t.i("plane_period", c.plane_period, "N_p: plane identification every N_p frames");
  t.i("mapping_period", c.mapping_period, "N_o: Gaussian mapping step every N_o frames");
  t.i("final_steps", c.final_steps, "extra mapping steps over the keyframes at the end");
  t.b("sync", c.sync, "run mapping inline (deterministic) instead of on the mapping thread");
  t.b("live", c.live, "overlapped mapping that pre-mapping never waits for: a step starts once N_o frames are queued and none runs");
  t.f("live_step_scale", c.live_step_scale,
      "live: a step runs mapping.iterations per mapping_period frames it covers, at most this many times mapping.iterations");
  t.b("gt_poses", c.gt_poses, "use the frames' given poses (mapping only)");
  t.s("semantics", c.semantics, "semantic cue: none | labels | remote");
  t.s("remote_address", c.remote_address, "rrg.v1.Segmenter address (semantics = remote)");
  t.custom("prompts", "reflective categories, comma separated (empty = the paper's)",
           [&c] {
             std::string s;
             for (const auto& p : c.prompts) s += (s.empty() ? "" : ",") + p;
             return s;
           },
           [&c](const std::string& v) { c.prompts = parse_prompt_list(v); });
  // TSDF (§3.1, §4.1.4)
  t.f("tsdf.voxel_size", c.tsdf.voxel_size, "voxel size s, metres");
  t.f("tsdf.truncation", c.tsdf.truncation, "truncation ε, metres");
  t.f("tsdf.band_sigmas", c.tsdf.band_sigmas,
      "k of the truncation band max(ε, k σ_n(d)), σ_n from planes.segmentation.noise_*; 0: ε at every depth");
  t.i("tsdf.max_weight", c.tsdf.max_weight, "W_max");
  t.i("tsdf.reflection_window", c.tsdf.reflection_window, "W of the reflection strength average");
  t.f("tsdf.min_depth", c.tsdf.min_depth, "ignore depth below, metres");
  t.f("tsdf.max_depth", c.tsdf.max_depth, "ignore depth beyond, metres");
  t.i64("tsdf.initial_blocks", c.tsdf.initial_blocks, "initial hash / pool size, blocks");
  t.f("tsdf.stream_radius", c.stream_radius,
      "after each frame, TSDF blocks farther than this from the camera go to host memory, metres; 0: never");
  // tracking (§4.1.2)
  t.custom("tracking.mode", "icp | icp+orb | icp+orb+mask", [&c] { return to_string(c.tracking.mode); },
           [&c](const std::string& v) { c.tracking.mode = parse_tracking_mode(trim(v)); });
  t.b("tracking.preprocess.bilateral", c.tracking.preprocess.bilateral, "bilateral depth filter");
  t.i("tracking.preprocess.levels", c.tracking.preprocess.levels, "pyramid levels");
  t.i("tracking.icp.iterations0", c.tracking.icp.iterations[0], "ICP iterations, finest level");
  t.i("tracking.icp.iterations1", c.tracking.icp.iterations[1], "ICP iterations, level 1");
  t.i("tracking.icp.iterations2", c.tracking.icp.iterations[2], "ICP iterations, level 2");
  t.f("tracking.icp.max_distance_m", c.tracking.icp.max_distance_m, "ICP pair distance limit, metres");
  t.f("tracking.icp.max_normal_angle_deg", c.tracking.icp.max_normal_angle_deg, "ICP normal angle limit");
  t.f("tracking.icp.min_agreement", c.tracking.icp.min_agreement, "share of pixels agreeing with the model below which ICP failed");
  t.f("tracking.icp.ok_agreement", c.tracking.icp.ok_agreement, "below (and above min_agreement): tracking degraded");
  t.f("tracking.icp.agreement_sigmas", c.tracking.icp.agreement_sigmas, "a pair agrees when |r| <= max(huber δ, k σ_n(z))");
  t.f("tracking.icp.huber_delta_m", c.tracking.icp.huber_delta_m,
      "ICP Huber threshold, metres (on residuals scaled to the reference depth's noise)");
  t.b("tracking.icp.noise_weighting", c.tracking.icp.noise_weighting,
      "weigh ICP pairs by the sensor noise σ_n(z) (planes.segmentation.noise_*) at their depth");
  t.f("tracking.icp.model_sigma_m", c.tracking.icp.model_sigma_m,
      "σ_m of the model surface added in quadrature to σ_n(z) in ICP's noise weights, metres; 0: the sensor's alone");
  t.f("tracking.icp.noise_reference_depth_m", c.tracking.icp.noise_reference_depth_m,
      "depth where a pair's noise weight is 1 and Huber sees its residual unscaled, metres");
  t.i("tracking.orb.features", c.tracking.orb.features, "ORB features per frame");
  t.i("tracking.orb.min_inliers", c.tracking.orb.min_inliers, "BA inliers needed to accept ORB refinement");
  t.f("tracking.orb.icp_prior_scale", c.tracking.orb.icp_prior_scale,
      "s of the ICP prior s JᵀJ/σ² in ORB's bundle adjustment and its consistency gate (0 = none)");
  t.f("tracking.orb.max_depth_range", c.tracking.orb.max_depth_range,
      "a keypoint whose window's depths span more than this fraction of its depth keeps no depth (0 = off)");
  t.f("tracking.orb.mask_threshold", c.tracking.orb.mask_threshold, "R^track = mean RGB of C_r > this");
  t.i("tracking.orb.mask_downsample", c.tracking.orb.mask_downsample,
      "render the tracking mask at 1/f of the frame's width and height (1 = full)");
  t.b("tracking.orb.mask_warp", c.tracking.orb.mask_warp,
      "the tracking mask's plane ids warped from the ICP model's raycast (false: a raycast at the ICP pose)");
  t.b("tracking.orb.mask_unmodelled", c.tracking.orb.mask_unmodelled,
      "also mask the planes whose reflection is not modelled yet (open semantic candidates, accepted planes without G_r)");
  t.f("tracking.keyframes.delta_angle_deg", c.tracking.keyframes.delta_angle_deg, "keyframe rotation, degrees");
  t.f("tracking.keyframes.delta_move_m", c.tracking.keyframes.delta_move_m, "keyframe translation, metres");
  // planes (§4.1.3)
  t.f("planes.variance_threshold", c.planes.variance_threshold, "δ_v on C_var");
  t.f("planes.area_threshold", c.planes.area_threshold, "δ_area");
  t.f("planes.variance_border_voxels", c.planes.variance_border_voxels,
      "pixels this many TSDF voxels from a plane's border are left out of the variance check");
  t.i("planes.variance_border_pixels", c.planes.variance_border_pixels,
      "... plus this many pixels (the fusion's nearest-pixel footprint)");
  t.b("planes.variance_skip_color_edges", c.planes.variance_skip_color_edges,
      "pixels as near to a colour edge of the input (step > 2 sqrt(delta_v)) are left out too");
  t.b("planes.exposure_compensation", c.planes.exposure_compensation,
      "the variance statistic takes each identification frame's intensity over its exposure gain against the map");
  t.b("planes.fill.enabled", c.planes.fill.enabled,
      "fill the depth the sensor lost on reflective masks from the plane around them (labels / remote cues)");
  t.b("planes.fill.carry", c.planes.fill.carry,
      "later frames fill what is still lost on the surfaces earlier fills found (frames without masks, masks that fail)");
  t.f("planes.fill.min_missing", c.planes.fill.min_missing,
      "fill a mask when this share of its pixels has no depth or depth behind that plane");
  t.f("planes.fill.min_inlier_ratio", c.planes.fill.min_inlier_ratio, "share of the ring around the mask on one plane");
  t.f("planes.fill.min_region_share", c.planes.fill.min_region_share,
      "a mask failing the ring's test takes a carried surface's plane when this share of it lies on that surface");
  t.b("planes.fill.grow_beyond_mask", c.planes.fill.grow_beyond_mask,
      "fill the glass a mask stops short of: ring pixels behind the plane that connect to the mask");
  t.i("planes.fill.min_sides", c.planes.fill.min_sides, "sides of the mask's bounding box that plane must be seen on");
  t.i("planes.vote.windows", c.planes.vote.windows, "vote history, windows");
  t.i("planes.vote.min_reflective", c.planes.vote.min_reflective, "windows needed to accept");
  t.f("planes.segmentation.noise_a", c.planes.segmentation.noise.a, "sensor noise σ_n = a + b (z − z0)², a in metres");
  t.f("planes.segmentation.noise_b", c.planes.segmentation.noise.b, "sensor noise σ_n, b in 1/m");
  t.f("planes.segmentation.noise_z0", c.planes.segmentation.noise.z0, "sensor noise σ_n, z0 in metres");
  t.f("planes.segmentation.planar_sigmas", c.planes.segmentation.planar_sigmas, "cell fit RMS bound in σ_n");
  t.f("planes.segmentation.sigma_min", c.planes.segmentation.sigma_min, "σ_min, metres");
  t.f("planes.segmentation.sigma_k", c.planes.segmentation.sigma_k, "k_σ, 1/m");
  t.f("planes.table.max_normal_angle_deg", c.planes.table.max_normal_angle_deg, "association normal limit");
  t.f("planes.table.max_distance", c.planes.table.max_distance, "association distance limit, metres");
  // mapping (§4.2)
  t.prefix = "mapping.";
  add_mapper_config_fields(t, c.mapping);
  return t.fields;
}

void set_config_value(SessionConfig& c, const std::string& key, const std::string& value) {
  auto fields = config_fields(c);
  const std::string k = trim(key);
  for (ConfigField& f : fields)
    if (f.name == k) return f.set(value);
  std::vector<std::pair<size_t, std::string>> near;
  for (const ConfigField& f : fields) near.emplace_back(edit_distance(k, f.name), f.name);
  std::sort(near.begin(), near.end());
  std::string hint;
  for (size_t i = 0; i < near.size() && i < 3; ++i) hint += (i ? ", " : "") + near[i].second;
  throw std::invalid_argument("config: unknown key '" + k + "' (closest: " + hint + ")");
}

void apply_override(SessionConfig& c, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("config override '" + assignment + "' is not key=value");
  set_config_value(c, assignment.substr(0, eq), assignment.substr(eq + 1));
}

void load_config_yaml(SessionConfig& c, const std::filesystem::path& file) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("config " + file.string() + ": " + e.what());
  }
  if (root.IsNull()) return;  // empty file: defaults
  try {
    walk_yaml(c, root, "", file.string());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("config " + file.string() + ": " + e.what());
  }
}

std::string config_to_yaml(SessionConfig& c) {
  // The dotted names as a tree, in table order, emitted as nested block maps.
  struct Tree {
    std::vector<std::pair<std::string, Tree>> children;
    std::string value;
    Tree& child(const std::string& name) {
      for (auto& [n, t] : children)
        if (n == name) return t;
      return children.emplace_back(name, Tree{}).second;
    }
  };
  Tree root;
  for (const ConfigField& f : config_fields(c)) {
    Tree* t = &root;
    std::stringstream ss(f.name);
    for (std::string part; std::getline(ss, part, '.');) t = &t->child(part);
    t->value = f.get();
  }
  YAML::Emitter out;
  const std::function<void(const Tree&)> emit = [&](const Tree& t) {
    out << YAML::BeginMap;
    for (const auto& [name, child] : t.children) {
      out << YAML::Key << name << YAML::Value;
      if (child.children.empty()) out << YAML::DoubleQuoted << child.value;
      else emit(child);
    }
    out << YAML::EndMap;
  };
  emit(root);
  return std::string(out.c_str()) + "\n";
}

}  // namespace rrg
