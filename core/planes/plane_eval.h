#pragma once
// The evaluation driver of reflective plane identification on a posed RGB-D sequence with
// ground-truth planes (our synthetic layout): fuses every frame with its ground-truth pose into an
// augmented TSDF (core/tsdf), and every N_p frames raycasts C_var at the frame's pose, runs one
// identification step per semantic cue, and feeds the first cue's global plane map, remap table and
// predicted reflection mask back into fusion as the ReflectionObservation of that frame. Scores
// segmentation, id stability and reflective identification against planes/ and planes.json.
#include "core/common/device.h"
#include "core/planes/observed_variance.h"
#include "core/planes/plane_identification.h"
#include "core/planes/plane_metrics.h"
#include "core/planes/remote_segmenter.h"

#include <filesystem>
#include <string>
#include <functional>
#include <vector>

namespace rrg {

struct PlaneEvalOptions {
  std::filesystem::path dataset;                    // synthetic layout folder
  std::vector<std::string> semantics = {"labels"};  // cues: none | labels | remote (first feeds fusion)
  std::vector<std::string> prompts = default_prompts();
  std::string remote_address;                       // for "remote"
  int period = 10;                                  // N_p
  size_t max_frames = 0;                            // 0 = all
  bool fuse = true;                                 // false: no TSDF (C_var = 0; segmentation / ids only)
  float voxel_size = 0.02f;                         // TSDF voxel for the evaluation, metres
  Device device = Device::cpu();                    // TSDF device
  IdentificationParams params;
  double min_fraction = 0.02;                       // planes covering > 2% of the image
  std::function<bool()> stop;                       // polled after each frame: true ends the run early (scored over the frames done)
};

struct PlaneEvalCueReport {
  std::string semantics;
  ReflectiveScores reflective;
  // Recall over the reflective GT planes that count for `reflective.recall()` and whose input shows
  // the variance the check needs (PlaneEvalReport::observed): found / verifiable.
  int gt_verifiable = 0, gt_verifiable_found = 0;
  double verifiable_recall() const { return gt_verifiable > 0 ? double(gt_verifiable_found) / gt_verifiable : 1.0; }
  IdentificationTimings mean_ms;   // per identification step
  double mean_mask_iou = 0;        // predicted reflection mask vs GT reflection mask, mean over steps with either non-empty
};

struct PlaneEvalReport {
  size_t frames = 0, windows = 0;
  bool interrupted = false;         // options.stop ended it before the last frame
  SegmentationCounts segmentation;  // over identification frames (first cue's segmentation)
  IdStability ids;
  std::vector<PlaneEvalCueReport> cues;
  // Per reflective GT plane seen in the identification frames: the temporal variance its input
  // shows (core/planes/observed_variance.h, δ_v and δ_area of the params, depth tolerance = the TSDF
  // truncation), and whether it is verifiable (fraction above δ_v > δ_area).
  struct Observed {
    int id = 0;
    std::string name;
    PlaneObservedVariance variance;
    bool verifiable = false;
  };
  std::vector<Observed> observed;
  int global_planes = 0;            // live instances at the end
  double fuse_ms = 0, raycast_ms = 0;  // means per fused frame / per raycast
  int64_t filled_pixels = 0;           // depth pixels filled on reflective masks (planes.fill), all frames
  double fill_ms = 0;                  // mean per frame the fill ran on (the cue's masks excluded)
};

// Throws std::runtime_error naming what is missing (folder, planes.json, labels/ for "labels").
PlaneEvalReport run_plane_eval(const PlaneEvalOptions& options);

// Builds a cue by name for a dataset folder (categories.json for "labels").
std::unique_ptr<SemanticCue> make_semantic_cue(const std::string& name, const std::filesystem::path& dataset,
                                               const std::vector<std::string>& prompts,
                                               const std::string& remote_address);

}  // namespace rrg
