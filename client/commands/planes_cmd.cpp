// rrg planes: reflective plane identification (core/planes).
//   rrg planes segment  CAPE-class plane segmentation of a dataset's depth maps: per-frame plane
//                       tables, optional local plane maps (16-bit PNG), scores against planes/ when
//                       the dataset has them, milliseconds per call.
//   rrg planes eval     the whole identification (TSDF fusion with ground-truth poses, C_var,
//                       global plane table, semantic cue, 5-window vote) on a synthetic sequence,
//                       scored against planes.json.
#include "client/commands/command.h"
#include "client/commands/stop_on_signal.h"
#include "core/common/device.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/io/synth_layout.h"
#include "core/planes/plane_eval.h"
#include "core/planes/plane_segmentation.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

namespace rrg::cli {
namespace {

struct SegmentOptions {
  std::string dataset, out;
  io::DatasetFlags flags;
  int every = 1, max_frames = 0, cell = 0;
  bool json = false;
};

void run_segment(const SegmentOptions& o) {
  if (o.every < 1) throw std::invalid_argument("planes segment: --every must be >= 1");
  const auto dataset = io::open_dataset(o.dataset, o.flags.to_options());
  const Intrinsics& K = dataset->intrinsics();
  PlaneSegmentationParams params;
  params.cell_size = o.cell;
  params.validate();
  const std::filesystem::path planes_json = io::synth_scene_file(o.dataset, "planes.json");
  const bool scored = std::filesystem::exists(planes_json);
  std::map<int, GtPlane> gt_planes;
  if (scored) gt_planes = read_gt_planes(planes_json);
  if (!o.out.empty()) std::filesystem::create_directories(o.out);
  spdlog::info("planes segment: {} ({} frames, {}x{}), {}", o.dataset, dataset->size(), K.width, K.height, params.to_string());

  SegmentationCounts counts;
  double total_ms = 0, cpu_ms = 0;  // wall time, and CPU time of all threads (std::clock)
  size_t done = 0;
  nlohmann::json frames = nlohmann::json::array();
  for (size_t i = 0; i < dataset->size(); i += size_t(o.every)) {
    if (o.max_frames > 0 && done >= size_t(o.max_frames)) break;
    const io::Frame frame = dataset->load(i);
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    const PlaneSegmentation seg = segment_planes(frame.depth, K, params);
    total_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    cpu_ms += 1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC;
    ++done;
    nlohmann::json jf = {{"frame", i}, {"planes", nlohmann::json::array()}};
    for (const LocalPlane& p : seg.planes)
      jf["planes"].push_back({{"id", p.id}, {"normal", {p.plane.n.x(), p.plane.n.y(), p.plane.n.z()}},
                              {"offset", p.plane.d}, {"pixels", p.pixels}, {"rms", p.rms}});
    if (scored) {
      const SegmentationCounts c = score_segmentation(seg.labels, io::read_synth_planes(o.dataset, i), gt_planes);
      counts.add(c);
      for (int g : c.missed_gt)
        spdlog::debug("frame {}: missed GT plane {} ({})", i, g, gt_planes.count(g) ? gt_planes.at(g).name : "?");
      for (int d : c.unmatched_detected) {
        const LocalPlane& p = seg.planes[size_t(d - 1)];
        spdlog::debug("frame {}: unmatched plane {} ({} px, n {:.2f} {:.2f} {:.2f}, b {:.3f})", i, d, p.pixels,
                      p.plane.n.x(), p.plane.n.y(), p.plane.n.z(), p.plane.d);
      }
      jf["gt"] = c.gt, jf["gt_matched"] = c.gt_matched, jf["detected"] = c.detected, jf["detected_matched"] = c.detected_matched;
    }
    frames.push_back(jf);
    if (!o.out.empty()) {
      char name[32];
      std::snprintf(name, sizeof(name), "%06zu.png", i);
      io::write_labels_png(std::filesystem::path(o.out) / name, seg.labels);
    }
    if (done % 50 == 0) spdlog::info("planes segment: {} frames", done);
  }
  const double mean_ms = done > 0 ? total_ms / double(done) : 0.0;
  const double mean_cpu_ms = done > 0 ? cpu_ms / double(done) : 0.0;
  if (o.json) {
    nlohmann::json j = {{"frames", frames}, {"mean_ms", mean_ms}, {"mean_cpu_ms", mean_cpu_ms}, {"width", K.width}, {"height", K.height}};
    if (scored) {
      j["precision"] = counts.precision(), j["recall"] = counts.recall();
      j["precision_iou"] = counts.precision_iou(), j["recall_iou"] = counts.recall_iou();
    }
    std::cout << j.dump(1) << "\n";
    return;
  }
  for (const auto& jf : frames)
    std::printf("frame %6zu: %zu planes\n", jf["frame"].get<size_t>(), jf["planes"].size());
  std::printf("segmentation: %zu frames at %dx%d, %.2f ms per call (wall), %.2f ms CPU time (all threads)\n", done,
              K.width, K.height, mean_ms, mean_cpu_ms);
  if (scored)
  {
    std::printf("planes > 2%% of the image: precision %.3f (%lld/%lld), recall %.3f (%lld/%lld)\n", counts.precision(),
                (long long)counts.detected_matched, (long long)counts.detected, counts.recall(),
                (long long)counts.gt_matched, (long long)counts.gt);
    std::printf("strict one-to-one IoU > 0.5: precision %.3f recall %.3f\n", counts.precision_iou(), counts.recall_iou());
  }
}

struct EvalOptions {
  std::string dataset, semantics = "labels", prompts, remote, device = "cpu";
  int period = 10, max_frames = 0;
  float voxel = 0.02f, delta_v = 0.01f, delta_area = 0.05f, border_voxels = IdentificationParams{}.variance_border_voxels;
  int border_pixels = IdentificationParams{}.variance_border_pixels;
  bool no_fuse = false, json = false, no_color_edges = false, no_exposure = false, no_fill = false;
};

void run_eval(const EvalOptions& o) {
  PlaneEvalOptions e;
  e.dataset = o.dataset;
  e.semantics = parse_prompt_list(o.semantics);
  if (!o.prompts.empty()) e.prompts = parse_prompt_list(o.prompts);
  e.remote_address = o.remote;
  e.period = o.period;
  e.max_frames = size_t(std::max(0, o.max_frames));
  e.fuse = !o.no_fuse;
  e.voxel_size = o.voxel;
  e.device = parse_device(o.device);
  e.params.variance_threshold = o.delta_v;
  e.params.area_threshold = o.delta_area;
  e.params.variance_border_voxels = o.border_voxels;
  e.params.variance_border_pixels = o.border_pixels;
  e.params.variance_skip_color_edges = !o.no_color_edges;
  e.params.exposure_compensation = !o.no_exposure;
  e.params.fill.enabled = !o.no_fill;
  spdlog::info("planes eval: {} semantics {} period {} voxel {} m on {}, δ_v {} δ_area {}", o.dataset, o.semantics,
               o.period, o.voxel, e.device.to_string(), o.delta_v, o.delta_area);
  const StopOnSignal signals;  // Ctrl-C: stop after the current frame and score the frames done
  e.stop = [&signals] { return signals.signal() != 0; };
  const PlaneEvalReport r = run_plane_eval(e);
  nlohmann::json j = {{"frames", r.frames}, {"windows", r.windows}, {"global_planes", r.global_planes},
                      {"segmentation", {{"precision", r.segmentation.precision()}, {"recall", r.segmentation.recall()},
                                        {"precision_iou", r.segmentation.precision_iou()},
                                        {"recall_iou", r.segmentation.recall_iou()},
                                        {"gt", r.segmentation.gt}, {"detected", r.segmentation.detected}}},
                      {"id_stability", {{"planes", r.ids.planes}, {"stable", r.ids.stable}, {"frame_fraction", r.ids.fraction()}}},
                      {"fuse_ms", r.fuse_ms}, {"raycast_ms", r.raycast_ms}, {"filled_pixels", r.filled_pixels}, {"fill_ms", r.fill_ms}, {"cues", nlohmann::json::array()}};
  for (const auto& [g, h] : r.ids.unstable)
    for (const auto& [id, n] : h) j["id_stability"]["unstable"][std::to_string(g)][std::to_string(id)] = n;
  for (const auto& [g, held] : r.ids.on_other_id)
    j["id_stability"]["on_other_id"][std::to_string(g)] = {{"id", held.first}, {"mostly_gt", held.second}};
  for (const auto& c : r.cues)
    j["cues"].push_back({{"semantics", c.semantics}, {"precision", c.reflective.precision()}, {"recall", c.reflective.recall()},
                         {"accepted", c.reflective.accepted}, {"accepted_correct", c.reflective.accepted_correct},
                         {"gt_reflective", c.reflective.gt_reflective}, {"gt_found", c.reflective.gt_found},
                         {"accepted_planes", c.reflective.accepted_names}, {"missed_planes", c.reflective.missed_names},
                         {"gt_verifiable", c.gt_verifiable}, {"gt_verifiable_found", c.gt_verifiable_found},
                         {"verifiable_recall", c.verifiable_recall()},
                         {"mask_iou", c.mean_mask_iou},
                         {"ms", {{"segment", c.mean_ms.segment_ms}, {"associate", c.mean_ms.associate_ms},
                                 {"semantic", c.mean_ms.semantic_ms}, {"verify", c.mean_ms.verify_ms},
                                 {"identify", c.mean_ms.total_ms}}}});
  j["observed_variance"] = nlohmann::json::array();
  for (const auto& ob : r.observed)
    j["observed_variance"].push_back({{"id", ob.id}, {"name", ob.name}, {"points", ob.variance.points},
                                      {"fraction_above", ob.variance.fraction_above}, {"median", ob.variance.median},
                                      {"mean", ob.variance.mean}, {"mean_rgb", ob.variance.mean_rgb},
                                      {"verifiable", ob.verifiable}});
  if (r.interrupted) j["interrupted"] = true;
  if (o.json) {
    std::cout << j.dump(1) << "\n";
    if (r.interrupted) throw ExitWith{signals.exit_code()};
    return;
  }
  std::printf("frames %zu, identification windows %zu, live global planes %d\n", r.frames, r.windows, r.global_planes);
  std::printf("segmentation (planes > 2%%): precision %.3f recall %.3f (%lld GT, %lld detected); strict IoU: %.3f / %.3f\n",
              r.segmentation.precision(), r.segmentation.recall(), (long long)r.segmentation.gt,
              (long long)r.segmentation.detected, r.segmentation.precision_iou(), r.segmentation.recall_iou());
  std::printf("global ids: %d/%d GT planes keep one id in >= 95%% of their frames; %.3f of (plane, frame) pairs\n",
              r.ids.stable, r.ids.planes, r.ids.fraction());
  for (const auto& [g, h] : r.ids.unstable) {
    std::string ids;
    for (const auto& [id, n] : h) {
      const auto m = r.ids.majority_gt.find(id);
      ids += " " + std::to_string(id) + ":" + std::to_string(n) +
             (m != r.ids.majority_gt.end() ? " (mostly GT " + std::to_string(m->second) + ")" : "");
    }
    std::printf("  unstable GT plane %d: global id:frames%s\n", g, ids.c_str());
  }
  for (const auto& [g, held] : r.ids.on_other_id)
    std::printf("  stable on another plane's id: GT plane %d keeps id %d (mostly GT %d)\n", g, held.first, held.second);
  std::printf("variance the input shows on reflective GT planes (identification frames, ground truth; "
              "verifiable: > %.3g of the points above %.3g):\n", e.params.area_threshold, e.params.variance_threshold);
  for (const auto& ob : r.observed)
    std::printf("  %-24s GT %3d: %.3f of %lld points above, median %.4f, mean %.4f (RGB %.4f)%s\n",
                ob.name.c_str(), ob.id, ob.variance.fraction_above, (long long)ob.variance.points, ob.variance.median,
                ob.variance.mean, ob.variance.mean_rgb,
                ob.verifiable ? "" : "  (not verifiable)");
  for (const auto& c : r.cues) {
    std::printf("semantics %-7s reflective planes: precision %.3f (%d/%d) recall %.3f (%d/%d), mask IoU %.3f\n",
                c.semantics.c_str(), c.reflective.precision(), c.reflective.accepted_correct, c.reflective.accepted,
                c.reflective.recall(), c.reflective.gt_found, c.reflective.gt_reflective, c.mean_mask_iou);
    for (const auto& n : c.reflective.accepted_names) std::printf("  accepted: %s\n", n.c_str());
    for (const auto& n : c.reflective.missed_names) std::printf("  missed:   %s\n", n.c_str());
    if (c.gt_verifiable > 0)
      std::printf("  recall over the verifiable planes: %.3f (%d/%d)\n", c.verifiable_recall(), c.gt_verifiable_found,
                  c.gt_verifiable);
    else
      std::printf("  recall over the verifiable planes: none of the %d is verifiable\n", c.reflective.gt_reflective);
    std::printf("  ms per step: segment %.2f associate %.2f semantic %.2f verify %.2f identify %.2f\n", c.mean_ms.segment_ms,
                c.mean_ms.associate_ms, c.mean_ms.semantic_ms, c.mean_ms.verify_ms, c.mean_ms.total_ms);
  }
  std::printf("TSDF: fuse %.2f ms per frame, raycast %.2f ms per step\n", r.fuse_ms, r.raycast_ms);
  if (r.filled_pixels > 0)
    std::printf("depth filled on reflective masks (planes.fill): %lld pixels over the run, %.2f ms per frame\n",
                (long long)r.filled_pixels, r.fill_ms);
  if (r.interrupted) signals.finish_interrupted(r.frames);
}

}  // namespace

void register_planes_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("planes", "Reflective plane identification: CAPE-class segmentation, global planes, cues");
  cmd->require_subcommand(1);

  auto seg = std::make_shared<SegmentOptions>();
  auto* s = cmd->add_subcommand("segment", "Segment planes in a dataset's depth maps (scores against planes/ when present)");
  s->add_option("--dataset", seg->dataset, "dataset folder")->required();
  io::add_dataset_flags(*s, seg->flags);
  s->add_option("--every", seg->every, "segment every N-th frame")->capture_default_str();
  s->add_option("--frames", seg->max_frames, "at most this many frames (0 = all)")->capture_default_str();
  s->add_option("--cell", seg->cell, "cell size in pixels (0 = width / 40)")->capture_default_str();
  s->add_option("--out", seg->out, "write local plane maps (16-bit PNG, 0 = none) to this folder");
  s->add_flag("--json", seg->json, "print JSON instead of a table");
  s->callback([seg] { run_segment(*seg); });

  auto ev = std::make_shared<EvalOptions>();
  auto* e = cmd->add_subcommand("eval", "Run and score reflective plane identification on a synthetic sequence");
  e->add_option("--dataset", ev->dataset, "synthetic layout folder (rrg synth)")->required();
  e->add_option("--semantics", ev->semantics, "cues, comma-separated: none, labels, remote (the first feeds fusion)")
      ->capture_default_str();
  e->add_option("--prompts", ev->prompts, "reflective categories / text prompts, comma-separated (default: the paper's)");
  e->add_option("--remote", ev->remote, "rrg.v1.Segmenter address host:port for --semantics remote");
  e->add_option("--period", ev->period, "N_p: identify every N frames")->capture_default_str();
  e->add_option("--frames", ev->max_frames, "at most this many frames (0 = all)")->capture_default_str();
  e->add_option("--voxel", ev->voxel, "TSDF voxel size, metres")->capture_default_str();
  e->add_option("--device", ev->device, "TSDF device: cpu, cuda, cuda:N, auto")->capture_default_str();
  e->add_option("--delta-v", ev->delta_v, "δ_v: C_var threshold of the variance check")->capture_default_str();
  e->add_option("--delta-area", ev->delta_area, "δ_area: fraction of a plane's pixels above δ_v")->capture_default_str();
  e->add_option("--border-voxels", ev->border_voxels,
                "leave pixels this many TSDF voxels from a plane's border out of the variance check (0 = none)")
      ->capture_default_str();
  e->add_option("--border-pixels", ev->border_pixels, "... plus this many pixels (the fusion's nearest-pixel footprint)")
      ->capture_default_str()
      ->check(CLI::Range(0, 16));
  e->add_flag("--no-color-edges", ev->no_color_edges,
              "keep pixels near colour edges of the input in the variance check")
      ->capture_default_str();
  e->add_flag("--no-exposure", ev->no_exposure,
              "fuse the frames' intensity into C_var as it is, without their exposure gain against the map")
      ->capture_default_str();
  e->add_flag("--no-fill", ev->no_fill,
              "leave the depth the sensor lost on reflective masks unfilled (planes.fill; the first cue's masks fill it)")
      ->capture_default_str();
  e->add_flag("--no-fuse", ev->no_fuse, "no TSDF (C_var = 0): segmentation and global ids only");
  e->add_flag("--json", ev->json, "print JSON instead of a table");
  e->callback([ev] { run_eval(*ev); });
}

}  // namespace rrg::cli
