#include "core/planes/plane_eval.h"

#include "core/io/dataset.h"
#include "core/io/synth_layout.h"
#include "core/planes/exposure_gain.h"
#include "core/planes/semantic_labels.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_raycast.h"
#include "core/tsdf/tsdf_volume.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>
#include <stdexcept>

namespace rrg {

std::unique_ptr<SemanticCue> make_semantic_cue(const std::string& name, const std::filesystem::path& dataset,
                                               const std::vector<std::string>& prompts,
                                               const std::string& remote_address) {
  if (name == "none") return make_no_semantics();
  if (name == "labels") return make_label_semantics(read_category_table(io::synth_scene_file(dataset, "categories.json")), prompts);
  if (name == "remote") {
    RemoteSegmenterOptions o;
    o.address = remote_address;
    o.prompts = prompts;
    return make_remote_semantics(o);
  }
  throw std::invalid_argument("unknown semantics '" + name + "' (none, labels, remote)");
}

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void accumulate(IdentificationTimings& sum, const IdentificationTimings& t) {
  sum.segment_ms += t.segment_ms;
  sum.associate_ms += t.associate_ms;
  sum.semantic_ms += t.semantic_ms;
  sum.verify_ms += t.verify_ms;
  sum.total_ms += t.total_ms;
}

IdentificationTimings divided(IdentificationTimings t, double n) {
  if (n <= 0) return t;
  t.segment_ms /= n, t.associate_ms /= n, t.semantic_ms /= n, t.verify_ms /= n, t.total_ms /= n;
  return t;
}

double mask_iou(const MaskImage& a, const MaskImage& b) {
  int64_t inter = 0, uni = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    inter += (a[i] && b[i]) ? 1 : 0;
    uni += (a[i] || b[i]) ? 1 : 0;
  }
  return uni > 0 ? double(inter) / double(uni) : -1.0;
}

}  // namespace

PlaneEvalReport run_plane_eval(const PlaneEvalOptions& options) {
  if (options.semantics.empty()) throw std::invalid_argument("planes eval: no semantics given");
  if (options.period < 1) throw std::invalid_argument("planes eval: period must be >= 1");
  const auto dataset = io::open_dataset(options.dataset);
  const Intrinsics K = dataset->intrinsics();
  const auto gt_planes = read_gt_planes(io::synth_scene_file(options.dataset, "planes.json"));
  size_t frames = options.max_frames > 0 ? std::min(options.max_frames, dataset->size()) : dataset->size();

  std::vector<PlaneIdentifier> identifiers;
  std::vector<IdentificationScorer> scorers;
  for (const std::string& s : options.semantics) {
    identifiers.emplace_back(options.params, make_semantic_cue(s, options.dataset, options.prompts, options.remote_address));
    scorers.emplace_back(options.min_fraction);
  }
  std::vector<IdentificationTimings> time_sums(identifiers.size());
  std::vector<double> iou_sums(identifiers.size(), 0.0);
  std::vector<int> iou_counts(identifiers.size(), 0);
  const bool needs_labels = std::find(options.semantics.begin(), options.semantics.end(), "labels") != options.semantics.end();

  TsdfParams tp;
  tp.voxel_size = options.voxel_size;
  tp.truncation = std::max(tp.truncation, 4.0f * options.voxel_size);
  std::optional<TsdfVolume> volume;
  if (options.fuse) volume.emplace(tp, options.device);

  ObservedVariance observed(K, tp.truncation);
  PlaneEvalReport report;
  double fuse_ms = 0, raycast_ms = 0, fill_ms = 0;
  size_t raycasts = 0, fills = 0;
  for (size_t k = 0; k < frames; ++k) {
    io::Frame frame = dataset->load(k);
    if (!frame.T_wc_gt) throw std::runtime_error("planes eval: frame " + std::to_string(k) + " has no ground-truth pose");
    const Eigen::Isometry3f T_wc = frame.T_wc_gt->cast<float>();
    const bool identify = k % size_t(options.period) == 0;
    DeviceImage<int32_t> plane_ids;
    DeviceImage<uint8_t> mask;
    std::vector<int32_t> remap;
    float exposure_gain = 1.0f;  // as the session estimates it (core/planes/exposure_gain.h)
    // The depth the sensor lost on reflective masks, filled as the session does (planes.fill) with
    // the first cue's masks, which every cue's segmentation of this frame then sees.
    const SemanticCue& cue = identifiers[0].cue();
    const bool fill = options.params.fill.enabled && !cue.every_plane_is_candidate() &&
                      (identify || cue.masks_with_every_frame());
    LabelImage labels;
    if (needs_labels && (identify || fill)) labels = io::read_synth_labels(options.dataset, k);
    std::optional<std::vector<SemanticMask>> masks;
    if (fill) {
      IdentificationFrame f{&frame.depth, &frame.color, needs_labels ? &labels : nullptr, K, T_wc, int64_t(k)};
      masks = identifiers[0].semantic_masks(f);
      const auto t0 = std::chrono::steady_clock::now();
      const ReflectiveFillResult filled = fill_reflective_depth(frame.depth, *masks, K, options.params.fill_params());
      add_glass_beyond(filled, *masks);  // as the session's identification frames do
      for (const ReflectiveFillMask& m : filled.masks)
        spdlog::debug("frame {}: {}", k, describe(m));
      report.filled_pixels += filled.pixels;
      fill_ms += ms_since(t0);
      ++fills;
    }
    if (identify) {
      Image<float> cvar(K.width, K.height, 0.0f);
      if (volume) {
        const auto t0 = std::chrono::steady_clock::now();
        const bool exposure = options.params.exposure_compensation;
        const RaycastResult rc = raycast(*volume, K, T_wc, {}, {.color = exposure, .reflection = true, .normals = false});
        cvar = rc.color_variance.to_host();
        if (exposure) exposure_gain = estimate_exposure_gain(frame.color, frame.depth, rc, tp.truncation).gain;
        raycast_ms += ms_since(t0);
        ++raycasts;
      }
      const LabelImage gt = io::read_synth_planes(options.dataset, k);
      const MaskImage gt_reflection = io::read_synth_reflection(options.dataset, k);
      observed.add(T_wc, frame.depth, frame.color, gt);
      IdentificationFrame f{&frame.depth, &frame.color, needs_labels ? &labels : nullptr, K, T_wc, int64_t(k),
                            options.fuse ? options.voxel_size : 0.0f};
      for (size_t c = 0; c < identifiers.size(); ++c) {
        f.masks = c == 0 && masks ? &*masks : nullptr;
        IdentificationResult r = identifiers[c].identify(f, cvar);
        accumulate(time_sums[c], r.timings);
        for (const PlaneVerdict& v : r.planes)
          spdlog::debug("frame {} {}: plane {} ({} px, '{}') candidate {} C_var>δ_v {:.3f} mean {:.4f} reflective {} accepted {}", k,
                        options.semantics[c], v.global_id, v.pixels, v.label, v.candidate, v.variance_fraction, v.variance_mean,
                        v.reflective_now, v.accepted);
        scorers[c].add(gt, r.global_map);
        if (const double iou = mask_iou(r.reflection_mask, gt_reflection); iou >= 0) iou_sums[c] += iou, ++iou_counts[c];
        if (c == 0) {
          report.segmentation.add(score_segmentation(r.segmentation.labels, gt, gt_planes, options.min_fraction));
          if (volume) {
            Image<int32_t> ids = r.global_map;
            plane_ids = DeviceImage<int32_t>::from_host(ids, volume->device());
            mask = DeviceImage<uint8_t>::from_host(r.reflection_mask, volume->device());
            remap = r.remap;
          }
        }
      }
      ++report.windows;
    }
    if (volume) {
      const auto t0 = std::chrono::steady_clock::now();
      const auto depth = DeviceImage<float>::from_host(frame.depth, volume->device());
      const auto color = DeviceImage<Color>::from_host(frame.color, volume->device());
      ReflectionObservation obs{&plane_ids, &mask, remap, exposure_gain};
      integrate(*volume, depth, color, K, T_wc, identify ? &obs : nullptr);
      fuse_ms += ms_since(t0);
    }
    if ((k + 1) % 50 == 0 || k + 1 == frames)
      spdlog::info("planes eval: frame {}/{}, {} global planes, L_ref {} ({})", k + 1, frames,
                   identifiers[0].table().live_ids().size(), identifiers[0].vote().lookup_table().size(),
                   options.semantics[0]);
    if (k + 1 < frames && options.stop && options.stop()) {
      spdlog::warn("planes eval: stopped after frame {} of {}; scoring those frames", k + 1, frames);
      frames = k + 1;
      report.interrupted = true;
    }
  }
  report.frames = frames;
  report.fuse_ms = frames > 0 ? fuse_ms / double(frames) : 0;
  report.raycast_ms = raycasts > 0 ? raycast_ms / double(raycasts) : 0;
  report.fill_ms = fills > 0 ? fill_ms / double(fills) : 0;
  report.global_planes = int(identifiers[0].table().live_ids().size());
  report.ids = scorers[0].id_stability(identifiers[0].table().remap_table());
  std::set<int> reflective_ids;
  for (const auto& [id, g] : gt_planes)
    if (g.reflective) reflective_ids.insert(id);
  const auto shown = observed.stats(reflective_ids, options.params.variance_threshold);
  for (const auto& [id, v] : shown)
    report.observed.push_back({id, gt_planes.at(id).name, v, v.verifiable(options.params.area_threshold)});
  for (size_t c = 0; c < identifiers.size(); ++c) {
    PlaneEvalCueReport cr;
    cr.semantics = options.semantics[c];
    cr.reflective = scorers[c].reflective(identifiers[c].table().remap_table(), identifiers[c].vote().lookup_table(),
                                          gt_planes, options.params.vote.min_reflective);
    for (const auto& [id, found] : cr.reflective.counted) {
      const auto o = shown.find(id);
      if (o == shown.end() || !o->second.verifiable(options.params.area_threshold)) continue;
      ++cr.gt_verifiable;
      cr.gt_verifiable_found += found ? 1 : 0;
    }
    cr.mean_ms = divided(time_sums[c], double(report.windows));
    cr.mean_mask_iou = iou_counts[c] > 0 ? iou_sums[c] / iou_counts[c] : 0.0;
    report.cues.push_back(cr);
  }
  return report;
}

}  // namespace rrg
