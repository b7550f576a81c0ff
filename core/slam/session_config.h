#pragma once
// Everything a session is configured with, with the paper's defaults (DESIGN.md §5), and one table
// of named fields ("tsdf.voxel_size", "mapping.iterations", ...) through which YAML files, command
// line overrides (--set key=value) and the service's config overrides all set it. YAML files are
// nested maps whose paths are the field names ("tsdf: {voxel_size: 0.01}").
#include "core/common/camera.h"
#include "core/common/device.h"
#include "core/planes/plane_identification.h"
#include "core/slam/mapper.h"
#include "core/slam/mapping_schedule.h"
#include "core/tracking/tracking_params.h"
#include "core/tsdf/tsdf_params.h"

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace rrg {

struct SessionConfig {
  Intrinsics K;                        // camera (width, height, fx, fy, cx, cy); required
  Device device;                       // CPU unless chosen
  TsdfParams tsdf;
  float stream_radius = 0.0f;          // tsdf.stream_radius: TSDF blocks farther from the camera go to
                                       // host memory after each frame, metres; 0 = never (docs/tsdf.md)
  TrackingParams tracking;
  IdentificationParams planes;
  MapperParams mapping;

  int plane_period = 10;               // N_p: plane identification every N_p frames
  int mapping_period = 10;             // N_o: a Gaussian mapping step every N_o frames
  int final_steps = 0;                 // extra mapping steps over the keyframes at finish()
  bool sync = false;                   // run mapping steps inline (deterministic) instead of overlapped
  bool live = false;                   // overlapped without waiting for a running step (mapping_schedule.h)
  float live_step_scale = 2.0f;        // live: a step's iterations follow the frames it covers, up to this
                                       // many times mapping.iterations (live_step_iterations); 1 = always those
  bool gt_poses = false;               // take SessionFrame::pose as the pose (mapping only, no tracking)
  std::string semantics = "labels";    // semantic cue: none | labels | remote
  std::string remote_address;          // rrg.v1.Segmenter address for semantics = remote
  std::vector<std::string> prompts;    // reflective categories; empty = the paper's prompts
  std::map<uint16_t, std::string> categories;  // label id -> name for semantics = labels

  // Throws std::invalid_argument naming the first bad field (intrinsics included).
  void validate() const;
  // `tracking` with the sensor's noise model, planes.segmentation.noise (one sensor: ICP's noise
  // weighting and plane segmentation assume the same σ_n(z)).
  TrackingParams tracking_params() const;
  // `tsdf` with the same sensor noise model for its truncation band ε(d) = max(ε, k σ_n(d)).
  TsdfParams tsdf_params() const;
  MappingSchedule schedule() const;  // sync -> Sync, live -> Live, else Overlapped
};

// One named field of SessionConfig, typed by its text form.
struct ConfigField {
  std::string name;                    // dotted path, e.g. "tracking.icp.max_distance_m"
  std::string help;
  std::function<std::string()> get;    // current value as text
  std::function<void(const std::string&)> set;  // parses text; throws std::invalid_argument
};

// Builds field tables with one text form for every type (floats to 9 significant digits, so a
// learning rate of 1.6e-4 survives a YAML round trip) and parse errors that name the field.
struct ConfigTable {
  std::vector<ConfigField> fields;
  std::string prefix;  // prepended to every name ("mapping.")
  void f(const std::string& name, float& v, std::string help);
  void i(const std::string& name, int& v, std::string help);
  void i64(const std::string& name, int64_t& v, std::string help);
  void u64(const std::string& name, uint64_t& v, std::string help);
  void b(const std::string& name, bool& v, std::string help);
  void s(const std::string& name, std::string& v, std::string help);
  void custom(const std::string& name, std::string help, std::function<std::string()> get,
              std::function<void(const std::string&)> set);
};

// The table of every configurable field of c (pointers into c: keep c alive while using it).
std::vector<ConfigField> config_fields(SessionConfig& c);

// Sets one field from "value" text; throws std::invalid_argument for an unknown key (with the
// closest known names) or a value that does not parse.
void set_config_value(SessionConfig& c, const std::string& key, const std::string& value);
// "key=value" form of set_config_value.
void apply_override(SessionConfig& c, const std::string& assignment);
// Reads a YAML file of nested maps into c (unknown keys are errors; throws std::runtime_error
// naming the file for an unreadable file or bad YAML).
void load_config_yaml(SessionConfig& c, const std::filesystem::path& file);
// Every field as nested YAML (what a run actually used).
std::string config_to_yaml(SessionConfig& c);

}  // namespace rrg
