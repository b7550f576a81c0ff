#pragma once
// One reflective plane identification step (paper §4.1.3), run every N_p = 10 frames:
//   CAPE-class segmentation -> global plane table (I_k^g) -> semantic cue (candidates: each plane's
//   largest-overlap mask, reflective label) -> colour-variance verification on the raycast C_var
//   (fraction of the plane's pixels with C_var > δ_v = 0.01 above δ_area = 0.05) -> 5-window vote
//   (L_ref) -> predicted reflection mask (the semantic masks of confirmed planes; their plane
//   masks with the `none` cue).
// C_var comes from the TSDF raycast of the same pose (core/tsdf/tsdf_raycast.h) and is a plain
// input here. CPU only, like CAPE.
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/planes/global_plane_table.h"
#include "core/planes/plane_segmentation.h"
#include "core/planes/reflective_fill.h"
#include "core/planes/reflective_vote.h"
#include "core/planes/semantic_cue.h"

#include <Eigen/Geometry>

#include <memory>
#include <set>
#include <string>
#include <vector>

namespace rrg {

struct PlaneStateIo;

struct IdentificationParams {
  PlaneSegmentationParams segmentation;
  GlobalPlaneParams table;
  ReflectiveVoteParams vote;
  float variance_threshold = 0.01f;  // δ_v on C_var
  float area_threshold = 0.05f;      // δ_area: fraction of the plane's pixels above δ_v
  float min_mask_overlap = 0.3f;     // a plane takes its largest-overlap mask only when the mask
                                     // covers at least this fraction of the plane's pixels
  // Pixels closer than this many TSDF voxels (IdentificationFrame::voxel_size, measured on the
  // image at the pixel's depth) to the border of their plane, or of the reflective mask being
  // checked, are left out of the variance check: the trilinear C_var of a raycast mixes voxels
  // across a border, so a thin matte plane beside a mirror (its frame) would otherwise inherit the
  // mirror's variance, and a colour edge (a whiteboard's rim on a wall) aliases into variance.
  float variance_border_voxels = 2.0f;
  // Plus this many pixels: fusion gives a voxel the colour of the pixel its centre projects to in
  // each frame (nearest pixel: up to half a pixel off), the tracked poses are off by up to about a
  // pixel footprint (ATE 0.3-0.5 cm, a pixel spans ~1 cm at 2.5 m at 320x240), and this frame's
  // border is itself quantised to half a pixel: about two pixels (of the same camera, at similar
  // range) on which a voxel near a border may take the other side's colour. The voxel term alone
  // is 1-2 pixels at 0.5 cm voxels and 320x240, and a mirror frame's bars (8 cm) passed the
  // variance check in 9 of 10 accepted planes; with 1 extra pixel 3 of 4 (docs/planes.md).
  int variance_border_pixels = 2;
  // Colour edges are borders too: where the input colour C_k steps by more than 2√δ_v in intensity
  // between neighbouring pixels of one plane, the pixels within the same radius are left out. A
  // voxel whose observations fall on either side of such a step (pixel quantisation, pose error,
  // colour-depth misregistration, texture finer than a voxel) reaches a variance of step² / 4 > δ_v
  // with nothing reflected: marker strokes on a whiteboard, book spines, printed texture. A
  // reflection moves with the view, so its variance is not confined to the current frame's edges.
  bool variance_skip_color_edges = true;
  // Exposure: fusion divides an identification frame's intensity by its gain against the map's
  // colour before the Welford update, so that auto-exposure is not taken for view dependence
  // (core/planes/exposure_gain.h; the callers that fuse apply it). false = the paper's statistic.
  bool exposure_compensation = true;
  // Depth the sensor lost on reflective masks, filled before identification and fusion
  // (reflective_fill.h; the callers that fuse apply it). Its sensor noise is segmentation's.
  ReflectiveFillParams fill;
  ReflectiveFillParams fill_params() const;  // fill with segmentation's noise model and the table's same-surface filter
  // "Same surface" for the fill's carried regions: the plane table's geometric filter and overlap.
  RegionMatch region_match() const;
  void validate() const;             // throws std::invalid_argument
};

struct IdentificationFrame {
  const DepthImage* depth = nullptr;      // D_k, metres
  const ColorImage* color = nullptr;      // C_k
  const LabelImage* labels = nullptr;     // optional per-pixel categories (labels cue)
  Intrinsics K;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  int64_t index = 0;                      // frame index
  float voxel_size = 0;                   // TSDF voxel behind C_var, metres (0 = no border erosion)
  // The cue's masks of this frame when the caller has them already (semantic_masks(), e.g. for
  // the depth fill); null: identify() asks the cue.
  const std::vector<SemanticMask>* masks = nullptr;
};

struct PlaneVerdict {
  int global_id = 0;             // canonical
  int64_t pixels = 0;            // in this frame's I_k^g
  std::string label;             // associated mask's label ("" when none)
  bool candidate = false;        // reflective-plane candidate (geometric + semantic cue)
  float variance_fraction = 0;   // fraction of its pixels with C_var > δ_v
  float variance_mean = 0;       // mean C_var over its pixels (for logs)
  bool reflective_now = false;   // passed the variance check in this window
  bool accepted = false;         // in L_ref after this window
};

struct IdentificationTimings {
  double segment_ms = 0, associate_ms = 0, semantic_ms = 0, verify_ms = 0, total_ms = 0;
};

struct IdentificationResult {
  PlaneSegmentation segmentation;    // local planes and map
  FrameAssociation association;
  Image<int32_t> global_map;         // I_k^g, canonical global ids, 0 = none
  std::vector<PlaneVerdict> planes;  // one per global plane present in the frame
  MaskImage reflection_mask;         // predicted reflection mask (0 / 1)
  std::vector<int32_t> remap;        // id -> canonical id, for TSDF fusion and raycast
  IdentificationTimings timings;
};

// The planes whose reflection is open after a window: semantic candidates (a reflective
// category's mask is theirs) that are not in L_ref, have fewer than `vote.params().windows` windows
// of history, and can still be accepted within them (reflective so far + windows to come >=
// min_reflective: with the paper's 4 of 5, two non-reflective windows decide). The planes `window`
// saw are decided by its verdicts; the others of `previous` (the last window's set) stay while
// their vote stays open, under their canonical ids (`table`: merges). Empty when every plane is a
// candidate (the `none` cue: candidacy carries no evidence).
// The session keeps these planes out of the tracking mask's features until the vote decides
// (docs/tracking.md "Reflections not modelled yet").
std::set<int> undecided_candidates(const std::set<int>& previous, const IdentificationResult& window,
                                   const ReflectiveVote& vote, const GlobalPlaneTable& table,
                                   bool every_plane_is_candidate);

class PlaneIdentifier {
 public:
  // Throws std::invalid_argument for bad params or a null cue.
  PlaneIdentifier(const IdentificationParams& params, std::unique_ptr<SemanticCue> cue);

  // One step. color_variance is C_var at the frame's pose (K's size; pixels without a surface 0).
  IdentificationResult identify(const IdentificationFrame& frame, const Image<float>& color_variance);
  // The semantic cue's masks of a frame (colour, labels and index are read), checked against the
  // depth's size. Throws std::runtime_error naming the cue when they differ.
  std::vector<SemanticMask> semantic_masks(const IdentificationFrame& frame);

  const GlobalPlaneTable& table() const { return table_; }
  const ReflectiveVote& vote() const { return vote_; }
  const SemanticCue& cue() const { return *cue_; }
  const IdentificationParams& params() const { return params_; }
  int64_t windows() const { return window_; }

 private:
  friend struct PlaneStateIo;  // snapshots (plane_state_io.h)
  IdentificationParams params_;
  std::unique_ptr<SemanticCue> cue_;
  GlobalPlaneTable table_;
  ReflectiveVote vote_;
  int64_t window_ = 0;
};

}  // namespace rrg
