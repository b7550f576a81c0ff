#include "core/synth/depth_noise.h"

#include "core/common/depth_noise_model.h"
#include "core/synth/hash.h"

#include <cmath>
#include <stdexcept>

namespace rrg::synth {

float kinect_sigma(float z) { return DepthNoiseModel{}.sigma(z); }

void apply_depth_noise(DepthImage& depth, const Image<uint16_t>& material, const Scene& scene,
                       const DepthNoiseParams& params, uint32_t frame, uint32_t seed) {
  if (!depth.same_size(material)) throw std::invalid_argument("apply_depth_noise: depth and material sizes differ");
  const int w = depth.width(), h = depth.height();
  const DepthImage clean = depth;  // edges are judged on the noise-free depth
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      float& z = depth(u, v);
      if (z <= 0.0f) continue;
      const uint32_t key = hash4(uint32_t(u), uint32_t(v), frame, seed);
      const uint16_t m = material(u, v);
      if (params.invalid_on_mirrors && m > 0 && scene.materials[m - 1u].f0 > params.mirror_f0) {
        z = 0.0f;
        continue;
      }
      if (params.edge_dropout) {
        float jump = 0.0f;
        const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
        for (int k = 0; k < 4; ++k) {
          const int x = u + du[k], y = v + dv[k];
          if (x < 0 || y < 0 || x >= w || y >= h) continue;
          const float zn = clean(x, y);
          jump = std::max(jump, zn <= 0.0f ? z : std::abs(zn - clean(u, v)));
        }
        if (jump > params.edge_jump * clean(u, v) &&
            unit_float(hash_combine(key, 0xd40bu)) < params.edge_drop_probability) {
          z = 0.0f;
          continue;
        }
      }
      if (params.gaussian) z = std::max(0.0f, z + kinect_sigma(z) * gaussian_from_hash(key));
    }
}

}  // namespace rrg::synth
