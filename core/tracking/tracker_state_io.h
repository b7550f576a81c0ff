#pragma once
// Binary form of a TrackerState inside a session snapshot (core/slam/session_snapshot.cpp):
// flags, the carried poses (exact floats), the next keyframe id and every ORB keyframe (keypoints,
// 32-byte descriptors, world points). Reading throws std::runtime_error naming the reader's
// `what` on a truncated or inconsistent record.
#include "core/io/byte_stream.h"
#include "core/tracking/tracker.h"

namespace rrg {

void write_tracker_state(io::ByteWriter& w, const TrackerState& state);
TrackerState read_tracker_state(io::ByteReader& r);

}  // namespace rrg
