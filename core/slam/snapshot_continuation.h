#pragma once
// The continuation section of a session snapshot (format v2, core/slam/session_snapshot.cpp):
// everything besides the map that the next frames read, so a loaded session continues exactly as
// the uninterrupted one would:
//   the tracker's state (ORB keyframes, next keyframe id, T_{k−1}, the constant-velocity motion),
//   the mapper's state (step counter, stored keyframes and frames since the last step, both sets'
//   Adam moments and step counts),
//   the session's fused frames not yet handed to the mapper (with their keyframe flags),
//   the reflective fill's carried surfaces (section v2; a v1 section has none),
//   the planes whose reflection vote is open, kept out of the tracking mask's features (v3).
// Frames are stored in the mapper's compact form (8-bit colour: zstd; 1/5000 m depth: RVL+zstd),
// Adam moments as byte planes + zstd: all bit-exact.
#include "core/io/byte_stream.h"
#include "core/planes/reflective_fill.h"
#include "core/slam/mapper.h"
#include "core/tracking/tracker.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace rrg {

struct ContinuationState {
  TrackerState tracker;
  MapperState mapper;
  std::vector<CompactFrame> pending;     // fused, not yet given to the mapper
  std::vector<uint8_t> pending_keyframe;  // one flag per pending frame
  std::vector<FillRegion> fill_regions;   // planes.fill.carry: what frames without masks fill from
  std::vector<int32_t> undecided_planes;  // semantic candidates with an open vote (tracking.orb.mask_unmodelled)
};

std::vector<uint8_t> write_continuation(const ContinuationState& state);
// Throws std::runtime_error("<what>: ...") on a truncated or corrupt section.
ContinuationState read_continuation(std::span<const uint8_t> bytes, const std::string& what);

}  // namespace rrg
