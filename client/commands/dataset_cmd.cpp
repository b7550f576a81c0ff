// rrg dataset info PATH: what a dataset folder holds, as text or JSON (docs/datasets.md).
#include "client/commands/command.h"
#include "core/io/dataset.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <string>

namespace rrg::cli {
namespace {

struct InfoOptions {
  std::string path;
  io::DatasetFlags flags;
  bool json = false;
};

struct DepthStats {
  double valid_fraction = 0.0;
  float min = 0.0f, max = 0.0f;  // metres over valid pixels; 0 when none
};

DepthStats depth_stats(const DepthImage& depth) {
  DepthStats s;
  size_t valid = 0;
  float lo = std::numeric_limits<float>::max(), hi = 0.0f;
  for (const float d : depth.pixels())
    if (d > 0.0f) {
      ++valid;
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  if (valid > 0) s.valid_fraction = double(valid) / double(depth.size()), s.min = lo, s.max = hi;
  return s;
}

void run_info(const InfoOptions& o) {
  const std::unique_ptr<io::Dataset> ds = io::open_dataset(o.path, o.flags.to_options());
  const io::Frame first = ds->load(0);
  const double t_end = ds->size() > 1 ? ds->load(ds->size() - 1).timestamp : first.timestamp;
  const DepthStats s = depth_stats(first.depth);
  const size_t gt_frames = ds->ground_truth().size();
  const Intrinsics& K = ds->intrinsics();
  if (o.json) {
    nlohmann::json j;
    j["path"] = ds->root().string();
    j["format"] = io::to_string(ds->format());
    j["frames"] = ds->size();
    j["intrinsics"] = {{"width", K.width}, {"height", K.height}, {"fx", K.fx},
                       {"fy", K.fy},       {"cx", K.cx},         {"cy", K.cy}};
    j["depth_scale"] = ds->depth_scale();
    j["ground_truth"] = ds->has_ground_truth();
    j["ground_truth_frames"] = gt_frames;
    j["time_span"] = {{"start", first.timestamp}, {"end", t_end}, {"duration", t_end - first.timestamp}};
    j["first_frame"] = {{"color", first.color_path.string()},
                        {"depth", first.depth_path.string()},
                        {"valid_depth_fraction", s.valid_fraction},
                        {"depth_min", s.min},
                        {"depth_max", s.max}};
    std::cout << j.dump(2) << "\n";
    return;
  }
  char line[256];
  std::cout << "path:          " << ds->root().string() << "\n"
            << "format:        " << io::to_string(ds->format()) << "\n"
            << "frames:        " << ds->size() << "\n"
            << "intrinsics:    " << K.to_string() << "\n";
  std::snprintf(line, sizeof(line), "depth scale:   %g units/m\n", double(ds->depth_scale()));
  std::cout << line;
  std::cout << "ground truth:  "
            << (ds->has_ground_truth() ? "yes (" + std::to_string(gt_frames) + " of " + std::to_string(ds->size()) +
                                             " frames)"
                                       : std::string("no"))
            << "\n";
  std::snprintf(line, sizeof(line), "time span:     %.6f .. %.6f s (%.3f s)\n", first.timestamp, t_end,
                t_end - first.timestamp);
  std::cout << line;
  std::snprintf(line, sizeof(line), "first frame:   valid depth %.1f %%, range %.3f .. %.3f m\n",
                100.0 * s.valid_fraction, double(s.min), double(s.max));
  std::cout << line;
}

}  // namespace

void register_dataset_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("dataset", "inspect RGB-D dataset folders (TUM, 7-Scenes, Replica, synth)");
  cmd->require_subcommand(1);
  auto opts = std::make_shared<InfoOptions>();
  auto* info = cmd->add_subcommand(
      "info", "print format, frame count, intrinsics, depth scale, ground truth, time span and first-frame depth");
  info->add_option("path", opts->path, "dataset folder")->required();
  io::add_dataset_flags(*info, opts->flags);
  info->add_flag("--json", opts->json, "print JSON instead of text");
  info->callback([opts] { run_info(*opts); });
}

}  // namespace rrg::cli
