#include "core/tracking/tracker_state_io.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace rrg {
namespace {

// cv::KeyPoint as its plain fields (it is not trivially copyable on every OpenCV version).
struct KeyPointRecord {
  float x, y, size, angle, response;
  int32_t octave, class_id;
};

void put_keyframe(io::ByteWriter& w, const Keyframe& k) {
  const size_t n = k.keypoints.size();
  if (k.points_world.size() != n || size_t(k.descriptors.rows) != n || (n > 0 && k.descriptors.cols != 32) ||
      (n > 0 && k.descriptors.type() != CV_8U))
    throw std::invalid_argument("tracker state: keyframe " + std::to_string(k.id) +
                                " has inconsistent keypoints, descriptors and points");
  w.put<int32_t>(k.id);
  w.put<uint64_t>(k.frame_index);
  io::put_pose(w, k.T_wc);
  std::vector<KeyPointRecord> kps(n);
  for (size_t i = 0; i < n; ++i) {
    const cv::KeyPoint& p = k.keypoints[i];
    kps[i] = {p.pt.x, p.pt.y, p.size, p.angle, p.response, p.octave, p.class_id};
  }
  w.put_vector(kps);
  std::vector<uint8_t> desc(n * 32);
  for (size_t i = 0; i < n; ++i) std::memcpy(desc.data() + 32 * i, k.descriptors.ptr<uint8_t>(int(i)), 32);
  w.put_vector(desc);
  std::vector<float> xyz(3 * n);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) xyz[3 * i + c] = k.points_world[i][c];
  w.put_vector(xyz);
}

Keyframe get_keyframe(io::ByteReader& r) {
  Keyframe k;
  k.id = r.get<int32_t>();
  k.frame_index = size_t(r.get<uint64_t>());
  k.T_wc = io::get_pose(r);
  const auto kps = r.get_vector<KeyPointRecord>();
  const auto desc = r.get_vector<uint8_t>();
  const auto xyz = r.get_vector<float>();
  const size_t n = kps.size();
  if (desc.size() != 32 * n || xyz.size() != 3 * n)
    throw std::runtime_error(r.what() + ": tracker keyframe " + std::to_string(k.id) + " has " + std::to_string(n) +
                             " keypoints but " + std::to_string(desc.size()) + " descriptor bytes and " +
                             std::to_string(xyz.size()) + " point coordinates");
  for (size_t i = 0; i < n; ++i) k.points_world.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  k.keypoints.reserve(n);
  for (const KeyPointRecord& p : kps)
    k.keypoints.emplace_back(cv::Point2f(p.x, p.y), p.size, p.angle, p.response, p.octave, p.class_id);
  k.descriptors.create(int(n), 32, CV_8U);
  for (size_t i = 0; i < n; ++i) std::memcpy(k.descriptors.ptr<uint8_t>(int(i)), desc.data() + 32 * i, 32);
  return k;
}

}  // namespace

void write_tracker_state(io::ByteWriter& w, const TrackerState& s) {
  w.put<uint8_t>(s.started);
  io::put_pose(w, s.T_initial);
  io::put_pose(w, s.T_prev);
  io::put_pose(w, s.velocity);
  w.put<int32_t>(int32_t(s.state));
  w.put<int32_t>(s.next_keyframe_id);
  w.put<uint64_t>(s.keyframes.size());
  for (const Keyframe& k : s.keyframes) put_keyframe(w, k);
}

TrackerState read_tracker_state(io::ByteReader& r) {
  TrackerState s;
  s.started = r.get<uint8_t>() != 0;
  s.T_initial = io::get_pose(r);
  s.T_prev = io::get_pose(r);
  s.velocity = io::get_pose(r);
  const int32_t state = r.get<int32_t>();
  if (state < 0 || state > int32_t(TrackingState::Lost))
    throw std::runtime_error(r.what() + ": bad tracking state " + std::to_string(state));
  s.state = TrackingState(state);
  s.next_keyframe_id = r.get<int32_t>();
  const auto n = r.get<uint64_t>();
  if (n > r.remaining()) throw std::runtime_error(r.what() + ": corrupt tracker keyframe count");
  for (uint64_t i = 0; i < n; ++i) s.keyframes.push_back(get_keyframe(r));
  return s;
}

}  // namespace rrg
