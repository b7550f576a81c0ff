// Dataset options from the command line: format names, --intrinsics parsing, the shared flags.
#include "core/io/calibration.h"
#include "core/io/dataset.h"
#include "core/io/text_parse.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <stdexcept>

namespace rrg::io {

namespace {
constexpr const char* kIntrinsicsForms =
    "expected fx,fy,cx,cy (four numbers, fx and fy > 0) or one of freiburg1|freiburg2|freiburg3 (fr1|fr2|fr3), "
    "7scenes, replica";
}

DatasetFormat parse_dataset_format(const std::string& name) {
  if (name == "auto") return DatasetFormat::Auto;
  if (name == "tum") return DatasetFormat::Tum;
  if (name == "7scenes" || name == "3dmatch") return DatasetFormat::SevenScenes;
  if (name == "replica") return DatasetFormat::Replica;
  if (name == "synth") return DatasetFormat::Synth;
  throw std::invalid_argument("unknown dataset format '" + name + "' (expected auto|tum|7scenes|replica|synth)");
}

std::string to_string(DatasetFormat format) {
  switch (format) {
    case DatasetFormat::Auto: return "auto";
    case DatasetFormat::Tum: return "tum";
    case DatasetFormat::SevenScenes: return "7scenes";
    case DatasetFormat::Replica: return "replica";
    case DatasetFormat::Synth: return "synth";
  }
  return "unknown";
}

Intrinsics parse_intrinsics(const std::string& text) {
  if (const auto named = named_intrinsics(text)) return *named;
  const auto fields = split_fields(text);
  if (fields.size() != 4) throw std::invalid_argument("invalid intrinsics '" + text + "': " + kIntrinsicsForms);
  float v[4];
  for (int k = 0; k < 4; ++k) {
    const auto d = parse_double(fields[k]);
    if (!d || !std::isfinite(*d)) throw std::invalid_argument("invalid intrinsics '" + text + "': " + kIntrinsicsForms);
    v[k] = float(*d);
  }
  if (!(v[0] > 0 && v[1] > 0)) throw std::invalid_argument("invalid intrinsics '" + text + "': " + kIntrinsicsForms);
  Intrinsics K;
  K.fx = v[0], K.fy = v[1], K.cx = v[2], K.cy = v[3];
  return K;  // width/height 0: filled from the first image
}

DatasetOptions DatasetFlags::to_options() const {
  DatasetOptions o;
  try {
    o.format = parse_dataset_format(format);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--format: ") + e.what());
  }
  if (!intrinsics.empty()) {
    try {
      o.intrinsics = parse_intrinsics(intrinsics);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--intrinsics: ") + e.what());
    }
  }
  if (depth_scale != 0.0f) {
    if (!(depth_scale > 0.0f) || !std::isfinite(depth_scale))
      throw std::invalid_argument("--depth-scale must be > 0 (stored depth units per metre), got " +
                                  std::to_string(depth_scale));
    o.depth_scale = depth_scale;
  }
  return o;
}

void add_dataset_flags(CLI::App& app, DatasetFlags& flags) {
  app.add_option("--format", flags.format, "dataset layout: auto|tum|7scenes|replica|synth")
      ->check(CLI::IsMember({"auto", "tum", "7scenes", "3dmatch", "replica", "synth"}))
      ->capture_default_str();
  app.add_option("--intrinsics", flags.intrinsics,
                 "fx,fy,cx,cy or freiburg1|freiburg2|freiburg3|7scenes|replica; used when the folder has no "
                 "calibration file");
  app.add_option("--depth-scale", flags.depth_scale,
                 "stored depth units per metre (TUM 5000, 7-Scenes 1000, Replica 6553.5); used when the folder's "
                 "calibration file gives none");
}

}  // namespace rrg::io
