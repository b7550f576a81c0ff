#include "core/synth/preview.h"

#include "core/synth/hash.h"

#include <algorithm>

namespace rrg::synth {

namespace {
// Smooth ramp from warm (t = 0) to cool (t = 1).
Color ramp(float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  return {std::clamp(1.5f - 2.0f * t, 0.0f, 1.0f), std::clamp(1.0f - 2.0f * std::abs(t - 0.45f), 0.0f, 1.0f),
          std::clamp(2.0f * t - 0.3f, 0.0f, 1.0f)};
}
}  // namespace

ColorImage contact_sheet(const RenderOutput& view) {
  const int w = view.color.width(), h = view.color.height();
  ColorImage sheet(2 * w, 2 * h, Color::Zero());
  float zmax = 0.0f;
  for (float z : view.depth.pixels()) zmax = std::max(zmax, z);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const Color& c = view.color(u, v);
      sheet(u, v) = c;
      const float z = view.depth(u, v);
      sheet(w + u, v) = z > 0.0f ? ramp(z / std::max(zmax, 1e-6f)) : Color::Zero();
      sheet(u, h + v) = view.reflective(u, v) ? Color(0.2f + 0.8f * c.x(), 0.9f, 0.9f) : Color(c * 0.3f);
      const uint16_t id = view.planes(u, v);
      const uint32_t hh = hash_u32(id * 7919u + 1u);
      sheet(w + u, h + v) = id == 0 ? Color::Zero()
                                    : Color(0.25f + 0.75f * unit_float(hh), 0.25f + 0.75f * unit_float(hash_u32(hh)),
                                            0.25f + 0.75f * unit_float(hash_u32(hh + 1)));
    }
  return sheet;
}

}  // namespace rrg::synth
