#pragma once
// Depth that the sensor lost on a reflective surface, restored from the semantic cue and the
// surface around it. Structured-light and time-of-flight sensors return no depth on a mirror or
// on glass, or the depth of the mirrored scene behind it; the TSDF then has a hole there (or the
// virtual room), segmentation finds no plane and §4.1.3 never gets to verify one. Before
// identification and fusion, each reflective mask of the cue whose pixels have largely no depth,
// or depth behind the surface around it, is filled with the plane that the valid depth in a ring
// just outside the mask lies on (the wall or frame a mirror hangs in), provided that ring is
// planar and surrounds the mask, and the mask's own depth is not that surface (a floor whose ring
// is the foot of the walls around it fits a plane off the floor). Pixels in front of that plane (an
// occluder, the mirror's own frame) keep their depth. A departure from the paper, which assumes
// depth on its planes (docs/planes.md "Mirrors without depth").
#include "core/common/camera.h"
#include "core/common/depth_noise_model.h"
#include "core/common/image.h"
#include "core/planes/plane_footprint.h"
#include "core/planes/plane_types.h"
#include "core/planes/semantic_cue.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace rrg {

struct ReflectiveFillParams {
  bool enabled = true;
  // The surfaces that fills with masks found (FillRegion below) fill, at the tracked pose, what is
  // still lost in their footprints on every later frame: frames that get no masks (the `remote`
  // cue between identification frames), and masks that fail their test or that the segmenter missed.
  bool carry = true;
  // A mask is filled when at least this share of its pixels has no depth or depth behind the ring's
  // plane: a mirror the sensor saw has next to none (edge dropouts), a lost one most of its area.
  float min_missing = 0.25f;
  int64_t min_mask_pixels = 64;  // smaller masks are left alone
  // Ring: the pixels within max(min_ring_px, ring_fraction · mask bbox diagonal) outside the mask.
  float ring_fraction = 0.04f;
  int min_ring_px = 3;
  int64_t min_ring_points = 48;  // valid ring pixels needed for a fit
  // A ring point is on the plane within max(min_tolerance, inlier_sigmas σ_n(z)), σ_n the sensor's
  // axial noise a + b (z − z0)² (Kinect v1, Nguyen et al. 2012, as plane segmentation uses). The
  // same tolerance decides "behind the plane".
  float inlier_sigmas = 3.0f;
  float min_tolerance = 0.01f;
  DepthNoiseModel noise;         // IdentificationParams::fill_params() sets segmentation's
  // Planarity: at least this share of the valid ring points on the plane. (Counting occluders in
  // front of the plane and the glass beyond a short mask as neither for nor against it, tried, let
  // wrong planes through: the office's and living_room's floor masks were filled from furniture.)
  float min_inlier_ratio = 0.6f;
  // The inliers must lie on at least min_sides of the four sides of the mask's bounding box, each
  // holding min_side_share of them. Two sides, adjacent (an L) or opposite (two strips), fix a
  // plane across the mask; one strip leaves it free to tilt about the strip, and a fill from it
  // would be an extrapolation. Two, not three: a mirror cut by the image's border is seen on two.
  int min_sides = 2;
  float min_side_share = 0.05f;
  // A segmenter's mask may stop short of the glass. Once a mask is filled, the ring pixels whose
  // depth lies behind the plane and that connect to the mask through such pixels (4-neighbours,
  // within the ring) are the glass beyond it, and are filled as well. Pixels without depth there are
  // left as they are (nothing is fused from them either way).
  bool grow_beyond_mask = true;
  // A mask that fails the ring's test on a frame may take the plane of a carried region (carry) of
  // its label when more than this share of its pixels meet that region's footprint: a surface found
  // before, which the mask shows again (fill_failed_masks_from_regions).
  float min_region_share = 0.5f;
  // A mask at least 1 − min_missing of whose pixels have depth on one plane that is the ring's
  // surface by the global plane table's geometric filter (the supplement's 10° and 0.1 m;
  // fill_params() takes the table's) is a surface the sensor kept, and is left alone, whatever the
  // ring's plane says of it (own_surface_plane in the .cpp: the distance bound widens to the
  // ring's width plus the inlier tolerance where that is more).
  float same_surface_angle_deg = 10.0f;
  float same_surface_distance = 0.1f;
  float max_ray_angle_deg = 80.0f;  // no fill where a ray meets the plane more obliquely
  int ransac_iterations = 128;      // deterministic (fixed seed)
  float max_depth = 10.0f;          // filled depths beyond this are left out, metres

  float tolerance(float z) const;   // max(min_tolerance, inlier_sigmas σ_n(z))
  void validate() const;            // throws std::invalid_argument naming the field
};

// What happened to one reflective mask.
struct ReflectiveFillMask {
  std::string label;
  size_t mask_index = 0;      // in the masks given (fill_reflective_depth)
  int64_t pixels = 0;         // mask pixels
  int64_t missing = 0;        // without depth or behind the plane (0 when no plane was fitted)
  int64_t filled = 0;         // pixels written (the mask's and beyond)
  std::vector<int32_t> beyond;  // pixels filled outside the mask (v · width + u): glass it stopped short of
  int64_t ring_points = 0;    // valid ring pixels
  int64_t in_front = 0;       // ring points in front of the plane (occluders)
  int64_t behind = 0;         // ring points behind it
  float inlier_ratio = 0.0f;  // of the ring points, on the plane
  int sides = 0;              // sides of the mask's bounding box the inliers cover
  Plane plane;                // camera frame, facing the camera (d > 0), when fitted
  bool fitted = false;
  bool from_region = false;   // the plane is a carried region's (fill_failed_masks_from_regions)
  bool own_surface = false;   // the plane is the mask's own depth's, the ring's surface, on 1 − min_missing of it
  bool kept = false;          // the sensor kept the surface (too little lost, or own_surface): not filled
  std::string skipped;        // why nothing was written ("" when filled)
};

// One line on what happened to a mask, for logs: "floor mask, 9000 px, 12 missing (of its own
// depth's plane): the sensor kept the surface".
std::string describe(const ReflectiveFillMask& mask);

struct ReflectiveFillResult {
  std::vector<ReflectiveFillMask> masks;  // one per reflective mask, in the cue's order
  MaskImage filled;                       // 1 where depth was written; the frame's size
  int64_t pixels = 0;                     // pixels written in all
};

// Fills `depth` (metres, 0 = invalid) in place from the reflective masks among `masks`. Throws
// std::invalid_argument when a mask's size or K's differs from the depth's, or for bad params.
ReflectiveFillResult fill_reflective_depth(DepthImage& depth, std::span<const SemanticMask> masks, const Intrinsics& K,
                                           const ReflectiveFillParams& params);

// Adds to each mask the glass its fill found beyond it (ReflectiveFillMask::beyond), so that the
// identification that reads these masks counts it in the predicted reflection mask (R). `masks` are
// the masks the fill was given; throws std::invalid_argument when they are not.
void add_glass_beyond(const ReflectiveFillResult& result, std::span<SemanticMask> masks);

// What a fill leaves for later frames (ReflectiveFillParams::carry): each filled mask's surface in
// the world frame, its plane and the footprint (a grid of `cell` metres on the plane,
// plane_footprint.h) of the mask's pixels on it.
struct FillRegion {
  std::string label;
  Plane plane;  // world frame
  Footprint footprint;
};

// The regions of the masks `result` filled from their rings, seen from T_wc (camera to world) with
// K. A mask filled from a region (from_region) leaves none: that region stays as it was, with the
// footprint a mask that passed the ring's test gave it.
std::vector<FillRegion> fill_regions(const ReflectiveFillResult& result, std::span<const SemanticMask> masks,
                                     const Intrinsics& K, const Eigen::Isometry3f& T_wc, float cell = 0.05f);

// The carried regions after a fill with masks: each fresh region replaces the carried ones of the
// same surface, and the others stay, so that a mask failing its test on a later frame (a segmenter's
// mask short of the glass or over its frame) still finds the surface an earlier mask found. Same
// surface: the same label, normals within max_normal_angle_deg and each plane's footprint centre
// within max_distance of the other plane (the global plane table's geometric filter), and more than
// min_overlap of the carried footprint's cells on the fresh one (one-cell dilation). The defaults are
// GlobalPlaneParams'; a session takes its table's (IdentificationParams::region_match()).
struct RegionMatch {
  float max_normal_angle_deg = 10.0f;
  float max_distance = 0.1f;
  float min_overlap = 0.05f;
};
bool same_surface(const FillRegion& carried, const FillRegion& fresh, const RegionMatch& match = {});
// Returns how many of the carried regions stayed: they come first, the fresh ones after them.
size_t merge_fill_regions(std::vector<FillRegion>& carried, std::vector<FillRegion> fresh, const RegionMatch& match = {});

// Fills `depth` from regions at pose T_wc: a pixel whose ray meets a region's plane from its front,
// within its footprint dilated by one cell, and that has no depth or depth behind the plane takes
// the plane's depth (the same tolerance and angle limit as fill_reflective_depth). One record per
// region in the result (pixels, missing and filled: the pixels it wrote).
ReflectiveFillResult fill_from_regions(DepthImage& depth, std::span<const FillRegion> regions, const Intrinsics& K,
                                       const Eigen::Isometry3f& T_wc, const ReflectiveFillParams& params);

// Removes the carried regions that this frame's masks refute, and returns how many: a mask the
// sensor kept (ReflectiveFillMask::kept: its depth is a surface, not lost) more than
// min_region_share of whose pixels meet the footprint of a region of its label, where at least
// min_missing of those would be lost against the region's plane (the region would write over them)
// and their median distance behind it is within the fill's one-surface bound (max(0.1 m, the
// mask's ring width + the inlier tolerance), own_surface_plane): the region misplaces the surface
// the sensor sees. Farther behind, the mask sees through the region's glass and the region stands.
// A region from a wrong fill is then not carried over every later frame. Call it before
// fill_failed_masks_from_regions and fill_from_regions. `depth` is the frame's depth the masks were
// tested on; throws std::invalid_argument when the sizes differ or the masks are not the fill's.
size_t drop_refuted_regions(std::vector<FillRegion>& regions, const ReflectiveFillResult& result,
                            std::span<const SemanticMask> masks, const DepthImage& depth, const Intrinsics& K,
                            const Eigen::Isometry3f& T_wc, const ReflectiveFillParams& params);

// The masks `result` left unfilled (a ring that is not planar, seen on too few sides, a surface the
// ring and the mask agree on inside glass seen through, ...) filled
// from the carried regions at pose T_wc: a mask more than min_region_share of whose pixels meet the
// footprint (dilated by one cell) of a region of its label takes that region's plane, and is filled
// as fill_reflective_depth fills from a fitted plane (min_missing, the glass beyond it). Their
// records in `result` are updated (plane, from_region, filled, beyond; skipped cleared), as are
// result.filled and result.pixels; the pixels written are set in `written` too, and counted in the
// return value. Throws std::invalid_argument when the sizes differ or the masks are not the fill's.
int64_t fill_failed_masks_from_regions(DepthImage& depth, ReflectiveFillResult& result,
                                       std::span<const SemanticMask> masks, std::span<const FillRegion> regions,
                                       const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                                       const ReflectiveFillParams& params, MaskImage& written);

// Writes the filled pixels of `from` into `to` (the same fill applied to another copy of the
// frame's depth, e.g. the tracker's filtered one). Throws std::invalid_argument on size mismatch.
void copy_filled_depth(const DepthImage& from, const MaskImage& filled, DepthImage& to);

}  // namespace rrg
