#include "tests/tracking/box_scene.h"

#include <cmath>
#include <limits>

namespace rrg::test {
namespace {

struct Plane {
  Eigen::Vector3f n;  // unit normal pointing into the room
  float d;            // n·x + d = 0
};

// Six walls of [-2, 2]³ and a slab tilted about two axes near the +x wall.
const Plane kPlanes[] = {
    {{1, 0, 0}, 2},  {{-1, 0, 0}, 2}, {{0, 1, 0}, 2}, {{0, -1, 0}, 2}, {{0, 0, 1}, 2}, {{0, 0, -1}, 2},
};

}  // namespace

BoxRender render_box(const Intrinsics& K, const Eigen::Isometry3f& T_wc) {
  BoxRender r{DepthImage(K.width, K.height, 0.0f), Image<Eigen::Vector3f>(K.width, K.height, Eigen::Vector3f::Zero()),
              Image<Eigen::Vector3f>(K.width, K.height, Eigen::Vector3f::Zero())};
  const Eigen::Vector3f o = T_wc.translation();
  // Tilted plane: normal (-0.8, 0.36, 0.48), through (1.2, 0, 0): a "ramp" in front of the +x wall.
  const Eigen::Vector3f tn = Eigen::Vector3f(-0.8f, 0.36f, 0.48f).normalized();
  const float td = -tn.dot(Eigen::Vector3f(1.2f, 0.0f, 0.0f));
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      const Eigen::Vector3f d_c((float(x) - K.cx) / K.fx, (float(y) - K.cy) / K.fy, 1.0f);
      const Eigen::Vector3f d = T_wc.linear() * d_c;
      float best = std::numeric_limits<float>::infinity();
      Eigen::Vector3f best_n = Eigen::Vector3f::Zero();
      for (const Plane& p : kPlanes) {
        const float den = p.n.dot(d);
        if (den >= -1e-6f) continue;  // only walls facing the ray
        const float t = -(p.n.dot(o) + p.d) / den;
        if (t > 0 && t < best) best = t, best_n = p.n;
      }
      const float den = tn.dot(d);
      if (std::abs(den) > 1e-6f) {
        const float t = -(tn.dot(o) + td) / den;
        const Eigen::Vector3f q = o + t * d;
        // the slab is a 1.2 m x 1.2 m patch around (1.2, 0, 0)
        if (t > 0 && t < best && std::abs(q.y()) < 0.6f && std::abs(q.z()) < 0.6f)
          best = t, best_n = den < 0 ? tn : Eigen::Vector3f(-tn);
      }
      if (!std::isfinite(best)) continue;
      r.depth(x, y) = best;  // d_c has unit z, so t is the depth
      r.vertices(x, y) = o + best * d;
      r.normals(x, y) = best_n;
    }
  return r;
}

Eigen::Isometry3f look_at(const Eigen::Vector3f& position, const Eigen::Vector3f& target) {
  const Eigen::Vector3f z = (target - position).normalized();
  Eigen::Vector3f x = z.cross(Eigen::Vector3f::UnitZ());
  if (x.norm() < 1e-4f) x = Eigen::Vector3f::UnitX();
  x.normalize();
  const Eigen::Vector3f y = z.cross(x);
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = position;
  return T;
}

Intrinsics test_intrinsics(int width, int height) {
  const float f = 0.5f * float(width) / std::tan(30.0f * 3.14159265f / 180.0f);
  return {f, f, 0.5f * float(width - 1), 0.5f * float(height - 1), width, height};
}

}  // namespace rrg::test
