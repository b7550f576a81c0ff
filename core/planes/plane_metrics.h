#pragma once
// Scores of plane segmentation and identification against the synthetic ground truth (planes/,
// planes.json; docs/planes.md "Evaluation").
//  - segmentation: ground-truth planes covering > 2% of the image, after grouping GT planes that
//    touch in the image and are coplanar within 2° / 2 cm (depth alone cannot see a border between
//    them: a poster on a wall, a rug on the floor), against detected planes covering > 2%. Each
//    detection belongs to the GT region holding most of its pixels and is correct when that is
//    more than half of them; a GT region is found when the correct detections belonging to it
//    cover more than half of it (a plane split by an occluder is found, two planes merged into
//    one detection lose the smaller). The strict one-to-one rule (IoU > 0.5) is reported too;
//  - id stability: per GT plane seen (> 2% of the image, at least half of its pixels labelled),
//    its global id in a frame is the majority canonical id over its pixels; stable when it equals
//    the plane's most frequent id in >= 95% of the frames it is seen;
//  - reflective identification: an accepted plane (L_ref) is right when the majority GT plane of
//    its pixels (over all identification frames) is reflective; a reflective GT plane is found
//    when its majority global id is accepted. Only GT planes seen in at least `min_frames`
//    identification frames count for recall.
#include "core/common/image.h"
#include "core/planes/plane_types.h"

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace rrg {

struct GtPlane {
  int id = 0;
  std::string name, category;
  Plane plane;              // world frame
  bool reflective = false;
};
// planes.json of the synthetic layout; throws std::runtime_error naming the file.
std::map<int, GtPlane> read_gt_planes(const std::filesystem::path& file);

struct SegmentationCounts {
  int64_t gt = 0, gt_matched = 0, detected = 0, detected_matched = 0;
  int64_t gt_matched_iou = 0, detected_matched_iou = 0;  // strict one-to-one IoU > 0.5
  std::vector<int> missed_gt;           // GT group representatives (> min_fraction) without a match
  std::vector<int> unmatched_detected;  // detected ids (> min_fraction) without a match
  double precision() const { return detected > 0 ? double(detected_matched) / double(detected) : 1.0; }
  double recall() const { return gt > 0 ? double(gt_matched) / double(gt) : 1.0; }
  double precision_iou() const { return detected > 0 ? double(detected_matched_iou) / double(detected) : 1.0; }
  double recall_iou() const { return gt > 0 ? double(gt_matched_iou) / double(gt) : 1.0; }
  void add(const SegmentationCounts& o);
};
SegmentationCounts score_segmentation(const LabelImage& detected, const LabelImage& gt,
                                      const std::map<int, GtPlane>& gt_planes, double min_fraction = 0.02,
                                      double min_iou = 0.5);

// GT plane ids of a frame grouped as score_segmentation does: id -> group representative.
std::map<int, int> group_coplanar_touching(const LabelImage& gt, const std::map<int, GtPlane>& gt_planes,
                                           float max_angle_deg = 2.0f, float max_offset = 0.02f);

struct IdStability {
  int planes = 0, stable = 0;        // GT planes seen; those with one id in >= 95% of their frames
  int64_t frames = 0, consistent = 0;  // (plane, frame) pairs; those with the plane's modal id
  // GT planes below 95 %: GT id -> canonical global id -> frames with that id (ordered by id).
  std::map<int, std::map<int, int>> unstable;
  std::map<int, int> majority_gt;  // canonical global id of an unstable plane -> GT id holding most of its pixels
  // Stable GT planes whose modal id holds mostly another GT plane's pixels (a bookshelf's back on its
  // wall's id: consistent, but another plane's): GT id -> (canonical id, the GT id holding most of it).
  std::map<int, std::pair<int, int>> on_other_id;
  double fraction() const { return frames > 0 ? double(consistent) / double(frames) : 1.0; }
};

struct ReflectiveScores {
  int accepted = 0, accepted_correct = 0;  // planes in L_ref; whose majority GT plane is reflective
  int gt_reflective = 0, gt_found = 0;     // reflective GT planes seen enough; found
  std::vector<std::string> accepted_names; // majority GT plane name of each accepted plane
  std::vector<std::string> missed_names;
  std::map<int, bool> counted;             // GT id of each reflective plane counted for recall -> found
  double precision() const { return accepted > 0 ? double(accepted_correct) / double(accepted) : 1.0; }
  double recall() const { return gt_reflective > 0 ? double(gt_found) / double(gt_reflective) : 1.0; }
};

// Accumulates global plane maps against GT plane maps, frame by frame.
class IdentificationScorer {
 public:
  explicit IdentificationScorer(double min_fraction = 0.02) : min_fraction_(min_fraction) {}
  void add(const LabelImage& gt, const Image<int32_t>& global_map);
  IdStability id_stability(const std::vector<int32_t>& remap) const;
  ReflectiveScores reflective(const std::vector<int32_t>& remap, const std::set<int>& accepted,
                              const std::map<int, GtPlane>& gt_planes, int min_frames) const;

 private:
  // canonical global id -> GT id -> pixels
  std::map<int, std::map<int, int64_t>> pixels_by_global(const std::vector<int32_t>& remap) const;
  double min_fraction_;
  std::vector<std::map<int, int>> frame_ids_;          // per frame: GT id -> majority raw global id
  std::map<std::pair<int, int>, int64_t> pixels_;      // (raw global id, GT id) -> pixels
  std::map<int, int> seen_frames_;                     // GT id -> frames covering > min_fraction
};

}  // namespace rrg
