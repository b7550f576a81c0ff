// rrg synth: renders a synthetic reflective RGB-D sequence (core/synth) into a folder.
#include "client/commands/command.h"
#include "core/io/image_io.h"
#include "core/synth/presets.h"
#include "core/synth/preview.h"
#include "core/synth/sequence.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

namespace rrg::cli {

namespace {

struct SynthOptions {
  synth::SynthParams params;
  std::string out;
  std::string mirror_depth = "surface";
  std::string preview;
  bool list = false;
};

// Renders the first frame of the planned trajectory as a contact sheet (no sequence written).
void write_preview(const SynthOptions& o) {
  synth::SynthParams p = o.params;
  p.out = o.preview;  // validate() wants an output; the sheet is the only file written
  p.frames = std::max(p.frames, 1);
  synth::validate(p);
  const synth::SceneSpec spec = synth::make_preset(p.preset, p.seed);
  const synth::CameraPath path = synth::make_camera_path(spec);
  const synth::SequencePlan plan = synth::plan_sequence(spec, path, p);
  synth::RenderParams rp = p.render;
  rp.threads = p.threads;
  const synth::RenderOutput view = synth::render_view(spec.scene, plan.K, plan.frames[0].T_wc.cast<float>(), rp);
  io::write_color_png(o.preview, synth::contact_sheet(view), 1);
  spdlog::info("synth: preview of {} frame 0 written to {}", p.preset, o.preview);
}

void run_synth(SynthOptions& o) {
  if (o.list) {
    for (const synth::PresetInfo& p : synth::preset_list()) std::printf("%-12s %s\n", p.name.c_str(), p.description.c_str());
    return;
  }
  if (!o.preview.empty()) return write_preview(o);
  if (o.out.empty()) throw std::invalid_argument("synth: --out DIR is required (or --list)");
  o.params.out = o.out;
  o.params.mirror_depth = synth::parse_mirror_depth(o.mirror_depth);
  const synth::SynthStats s = synth::generate_sequence(o.params);
  const int views = s.frames + s.novel;
  spdlog::info("synth: wrote {} frames + {} novel views to {} in {:.2f} s: rendering {:.1f} frames/s, total {:.1f} frames/s "
               "(incl. writing); CPU {:.1f} ms per view rendering, {:.1f} ms in total",
               s.frames, s.novel, o.out, s.total_seconds, double(views) / std::max(s.render_seconds, 1e-9),
               double(views) / std::max(s.total_seconds, 1e-9), 1e3 * s.render_cpu_seconds / views,
               1e3 * s.total_cpu_seconds / views);
}

}  // namespace

void register_synth_command(CLI::App& app) {
  auto opt = std::make_shared<SynthOptions>();
  synth::SynthParams& p = opt->params;
  auto* cmd = app.add_subcommand("synth", "Render a synthetic reflective RGB-D sequence (RIRD-Syn stand-in)");
  cmd->add_flag("--list", opt->list, "list the presets and exit");
  cmd->add_option("--preview", opt->preview, "write a contact sheet (colour, depth, reflection, planes) of frame 0 to "
                                             "this PNG instead of a sequence");
  cmd->add_option("--preset", p.preset, "scene preset: " + synth::preset_names())->capture_default_str();
  cmd->add_option("--out", opt->out, "output folder (TUM layout plus labels, planes, mesh; see docs/synth.md)");
  cmd->add_option("--frames", p.frames, "number of frames")->capture_default_str();
  cmd->add_option("--width", p.width, "image width")->capture_default_str();
  cmd->add_option("--height", p.height, "image height")->capture_default_str();
  cmd->add_option("--fps", p.fps, "frames per second (timestamps i / fps)")->capture_default_str();
  cmd->add_option("--speed", p.speed, "camera speed along the loop, m/s")->capture_default_str();
  cmd->add_option("--seed", p.seed, "seed: textures, start point, novel-view offsets, noise")->capture_default_str();
  cmd->add_option("--novel", p.novel, "held-out novel views written to OUT/novel")->capture_default_str();
  cmd->add_flag("--noise", p.noise, "Kinect-like depth noise and edge dropouts (deterministic)");
  cmd->add_flag("--exposure", p.exposure, "auto-exposure: the frames' colour drifts by a gain within [1/1.35, 1.35] (deterministic)");
  cmd->add_option("--mirror-depth", opt->mirror_depth, "depth on mirrors (F0 > 0.5): surface | invalid (none) | virtual (the mirrored point behind the glass)")
      ->capture_default_str();
  cmd->add_option("--threads", p.threads, "render threads (0 = all cores; output does not depend on it)")
      ->capture_default_str();
  cmd->add_flag("--overwrite", p.overwrite, "write into a non-empty output folder");
  cmd->callback([opt] { run_synth(*opt); });
}

}  // namespace rrg::cli
