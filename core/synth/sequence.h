#pragma once
// `rrg synth` as a library call: plans the camera poses of a preset (training trajectory and
// held-out novel views) and writes the whole synthetic RGB-D sequence (layout in docs/synth.md).
#include "core/common/camera.h"
#include "core/io/trajectory.h"
#include "core/synth/depth_noise.h"
#include "core/synth/presets.h"
#include "core/synth/renderer.h"

#include <filesystem>
#include <string>

namespace rrg::synth {

inline constexpr float kDepthScale = 5000.0f;     // depth PNG units per metre (TUM)
inline constexpr const char* kGeneratorVersion = "1.0";

// Depth on F0 > 0.5 surfaces: the surface, 0, or the mirrored point behind the glass.
enum class MirrorDepth { Surface, Invalid, Virtual };
MirrorDepth parse_mirror_depth(const std::string& text);  // "surface" | "invalid" | "virtual", else throws
const char* to_string(MirrorDepth m);

struct SynthParams {
  std::string preset = "living_room";
  std::filesystem::path out;
  int frames = 300;
  int width = 320, height = 240;
  double fps = 30.0;
  double speed = 0.3;      // metres per second along the loop
  uint32_t seed = 0;       // textures, start point on the loop, novel perturbations, noise
  int novel = 25;          // held-out views in out/novel
  bool noise = false;      // Kinect-like depth noise and edge dropouts
  MirrorDepth mirror_depth = MirrorDepth::Surface;
  bool exposure = false;   // auto-exposure drift on the frames' colour (core/synth/exposure.h)
  int threads = 0;         // 0 = all cores; never changes the output
  bool overwrite = false;  // allow writing into a non-empty out folder
  bool write_mesh = true;
  float mesh_max_edge = 0.025f;
  RenderParams render;     // threads is taken from `threads`
};

// Throws std::invalid_argument naming the bad parameter (sizes outside 1..8192, frames <= 0, ...).
void validate(const SynthParams& params);

// Pinhole intrinsics used for a width x height sequence: fx = fy = 0.8 width (64 degrees
// horizontal field of view), cx = (w - 1) / 2, cy = (h - 1) / 2.
Intrinsics default_intrinsics(int width, int height);

struct SequencePlan {
  Intrinsics K;
  double start_offset = 0.0;  // metres along the loop where frame 0 is
  io::Trajectory frames;      // t_i = i / fps
  io::Trajectory novel;       // held-out poses near the trajectory
};
// Camera path of a preset (its loop through the waypoints).
CameraPath make_camera_path(const SceneSpec& spec);
// Poses of every frame and novel view; pure function of (spec, params).
SequencePlan plan_sequence(const SceneSpec& spec, const CameraPath& path, const SynthParams& params);

struct SynthStats {
  int frames = 0, novel = 0;
  double render_seconds = 0.0;  // wall time of ray tracing (+ depth noise) of all views
  double total_seconds = 0.0;   // wall time of everything, including PNG/PLY/JSON writing
  double render_cpu_seconds = 0.0;  // process CPU time (all threads) while rendering
  double total_cpu_seconds = 0.0;   // process CPU time of the whole call
};

// Writes the sequence to params.out. Throws std::runtime_error when out is a non-empty folder
// and overwrite is off, or on any I/O error (every file is written atomically).
SynthStats generate_sequence(const SynthParams& params);

}  // namespace rrg::synth
