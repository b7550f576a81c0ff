#pragma once
// A session's memory limits, as `rrg serve` sets them (--session-memory-mb, --session-device-mb;
// the totals over all sessions use the same type). Two measures of one SessionStatus:
//   memory  device + host bytes: what the session costs the machine;
//   device  device bytes alone: what it costs the GPU. With tsdf.stream_radius the TSDF's far
//           blocks move to host memory, so a streaming session stays within a device budget that
//           its whole map would exceed (docs/tsdf.md "Streaming in a session").
#include "core/slam/session.h"

#include <cstddef>
#include <string>

namespace rrg::server {

struct MemoryBudget {
  size_t memory = 0;  // bytes, device + host; 0 = no limit
  size_t device = 0;  // bytes, device alone; 0 = no limit

  bool any() const { return memory > 0 || device > 0; }
  // "" when `st` is within both limits, else what is over, with the numbers:
  // "N bytes (device + host), over the memory budget of M" / "N device bytes, over the device budget of M".
  std::string excess(const SessionStatus& st) const;
};

}  // namespace rrg::server
