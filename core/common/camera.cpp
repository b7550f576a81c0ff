#include "core/common/camera.h"

#include <cstdio>

namespace rrg {

std::string Intrinsics::to_string() const {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%dx%d fx=%.3f fy=%.3f cx=%.3f cy=%.3f", width, height, fx, fy,
                cx, cy);
  return buf;
}

}  // namespace rrg
