#pragma once
// When a session starts a Gaussian mapping step (paper §4.2: every N_o fused frames), by schedule:
//   Sync        inline, every N_o-th fused frame: deterministic (tests, the service's replays);
//   Overlapped  on the mapping thread, every N_o-th fused frame; when the step before is still
//               running there, pre-mapping waits for it, so every step of the paper's schedule runs
//               and the frame rate falls to what mapping allows;
//   Live        on the mapping thread, and pre-mapping never waits: at an N_o boundary a running
//               step is left alone, the frames stay queued, and the next step starts after the
//               first fused frame once it has ended, taking every queued frame (its N_local are
//               sampled evenly from all of them). Where mapping keeps up (the GPU) this is the
//               Overlapped schedule; where it does not (the CPU) tracking and fusion keep the
//               stream's pace and the map gets fewer steps (docs/slam.md, "Schedule").
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace rrg {

enum class MappingSchedule { Sync, Overlapped, Live };

std::string to_string(MappingSchedule s);

// Whether a step starts after a fused frame: `fused` frames fused so far, `queued` of them not yet
// handed to a step, `running` whether a step is still running on the mapping thread. `period` N_o >= 1.
inline bool mapping_due(MappingSchedule s, int period, int64_t fused, size_t queued, bool running) {
  if (s == MappingSchedule::Live) return queued >= size_t(period) && !running;
  return fused % period == 0;
}

// Live: a step's Adam iterations. The paper runs `iterations` per N_o fused frames (30 per 10). A
// live step that starts after `frames` fused frames since the one before (more than N_o where
// mapping cannot keep up: the CPU) runs that rate over them, up to `max_scale` times `iterations`;
// the bound keeps a step, and so the map's lag behind the camera, short. Where mapping keeps up
// (frames = N_o), or with max_scale 1, every step runs `iterations`. A longer step also spends a
// smaller share on its fixed part (the selected frames' pass-1 raycasts, densification): at 30
// iterations on the 2-core CPU that part is a fifth of the step (docs/slam.md, "Schedule").
inline int live_step_iterations(int iterations, int period, int64_t frames, double max_scale) {
  const double scale = std::clamp(double(frames) / double(std::max(period, 1)), 1.0, std::max(max_scale, 1.0));
  return int(std::lround(double(iterations) * scale));
}

// Live: the queue of frames waiting for the next step is bounded. A step uses of the frames since
// the step before only N_local sampled evenly over them, and the keyframes among them (kept for
// N_global): when more than kLiveQueueSteps · N_o are queued, every other non-keyframe is dropped
// (the newest kept), which halves their density and keeps them evenly spread. The frames are in
// the TSDF already; only their copies for the mapper go. Returns the positions to keep, in order;
// all of them when the queue is within the bound.
inline constexpr int kLiveQueueSteps = 4;

inline std::vector<size_t> thin_live_queue(const std::vector<bool>& keyframe, int period) {
  std::vector<size_t> keep;
  const size_t n = keyframe.size();
  if (n <= size_t(kLiveQueueSteps) * size_t(period)) {
    for (size_t i = 0; i < n; ++i) keep.push_back(i);
    return keep;
  }
  bool take = true;  // from the newest back: every other non-keyframe, the newest first
  for (size_t i = n; i-- > 0;) {
    if (keyframe[i]) {
      keep.push_back(i);
      continue;
    }
    if (take) keep.push_back(i);
    take = !take;
  }
  std::reverse(keep.begin(), keep.end());
  return keep;
}

}  // namespace rrg
