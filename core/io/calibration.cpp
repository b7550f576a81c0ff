#include "core/io/calibration.h"

#include "core/io/image_io.h"
#include "core/io/text_parse.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace rrg::io {
namespace {

namespace fs = std::filesystem;

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open calibration file " + path.string());
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("calibration file " + path.string() + " is not valid JSON: " + e.what());
  }
}

double number(const nlohmann::json& obj, const char* key, const fs::path& path) {
  if (!obj.is_object() || !obj.contains(key) || !obj[key].is_number())
    throw std::runtime_error("calibration file " + path.string() + ": missing or non-numeric \"" + key + "\"");
  const double v = obj[key].get<double>();
  if (!std::isfinite(v)) throw std::runtime_error("calibration file " + path.string() + ": \"" + key + "\" is not finite");
  return v;
}

void check(const Intrinsics& k, const fs::path& path) {
  if (!k.valid())
    throw std::runtime_error("calibration file " + path.string() + " gives invalid intrinsics " + k.to_string() +
                             " (fx, fy, width, height must be > 0)");
}

std::optional<float> positive_scale(const nlohmann::json& obj, const char* key, const fs::path& path) {
  if (!obj.contains(key)) return std::nullopt;
  const double s = number(obj, key, path);
  if (!(s > 0)) throw std::runtime_error("calibration file " + path.string() + ": \"" + key + "\" must be > 0");
  return float(s);
}

}  // namespace

std::optional<Intrinsics> named_intrinsics(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  // fx, fy, cx, cy, width, height. TUM values from the TUM RGB-D benchmark's calibration page.
  static const std::map<std::string, Intrinsics> known = {
      {"freiburg1", {517.3f, 516.5f, 318.6f, 255.3f, 640, 480}},
      {"freiburg2", {520.9f, 521.0f, 325.1f, 249.7f, 640, 480}},
      {"freiburg3", {535.4f, 539.2f, 320.1f, 247.6f, 640, 480}},
      {"7scenes", {585.0f, 585.0f, 320.0f, 240.0f, 640, 480}},
      {"replica", {600.0f, 600.0f, 599.5f, 339.5f, 1200, 680}},
  };
  if (n.size() == 3 && n.starts_with("fr")) n = "freiburg" + n.substr(2);
  const auto it = known.find(n);
  if (it == known.end()) return std::nullopt;
  return it->second;
}

Calibration read_camera_json(const fs::path& path) {
  const nlohmann::json j = read_json(path);
  Calibration c;
  c.intrinsics.width = int(number(j, "width", path));
  c.intrinsics.height = int(number(j, "height", path));
  c.intrinsics.fx = float(number(j, "fx", path));
  c.intrinsics.fy = float(number(j, "fy", path));
  c.intrinsics.cx = float(number(j, "cx", path));
  c.intrinsics.cy = float(number(j, "cy", path));
  check(c.intrinsics, path);
  c.depth_scale = positive_scale(j, "depth_scale", path);
  return c;
}

Calibration read_cam_params_json(const fs::path& path) {
  const nlohmann::json j = read_json(path);
  if (!j.is_object() || !j.contains("camera"))
    throw std::runtime_error("calibration file " + path.string() + ": no \"camera\" object");
  const nlohmann::json& cam = j["camera"];
  Calibration c;
  c.intrinsics.width = int(number(cam, "w", path));
  c.intrinsics.height = int(number(cam, "h", path));
  c.intrinsics.fx = float(number(cam, "fx", path));
  c.intrinsics.fy = float(number(cam, "fy", path));
  c.intrinsics.cx = float(number(cam, "cx", path));
  c.intrinsics.cy = float(number(cam, "cy", path));
  check(c.intrinsics, path);
  c.depth_scale = positive_scale(cam, "scale", path);
  return c;
}

Intrinsics read_k_matrix_txt(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open calibration file " + path.string());
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  const auto fields = split_fields(s);
  if (fields.size() != 9)
    throw std::runtime_error("calibration file " + path.string() + ": expected a 3x3 matrix (9 numbers), got " +
                             std::to_string(fields.size()) + " fields");
  double k[9];
  for (int i = 0; i < 9; ++i) {
    const auto v = parse_double(fields[i]);
    if (!v || !std::isfinite(*v))
      throw std::runtime_error("calibration file " + path.string() + ": '" + std::string(fields[i]) + "' is not a number");
    k[i] = *v;
  }
  if (!(k[0] > 0 && k[4] > 0) || k[1] != 0 || k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1)
    throw std::runtime_error("calibration file " + path.string() +
                             " is not a pinhole K = [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > 0");
  Intrinsics in_k;
  in_k.fx = float(k[0]), in_k.cx = float(k[2]), in_k.fy = float(k[4]), in_k.cy = float(k[5]);
  return in_k;
}

Eigen::Vector2i image_size(const fs::path& path) {
  const ColorImage img = read_color(path);
  return {img.width(), img.height()};
}

}  // namespace rrg::io
