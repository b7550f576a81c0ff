#include "tests/tsdf/analytic_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rrg::test {

float Scene::sdf(const Eigen::Vector3f& p) const {
  float best = std::numeric_limits<float>::infinity();
  for (const Primitive& s : primitives) {
    float d = 0;
    if (s.kind == Primitive::Sphere) {
      d = (p - s.a).norm() - s.b.x();
    } else if (s.kind == Primitive::Box) {
      const Eigen::Vector3f q = (p - s.a).cwiseAbs() - s.b;
      d = q.cwiseMax(0.0f).norm() + std::min(q.maxCoeff(), 0.0f);
    } else {
      d = s.a.dot(p) - s.b.x();
    }
    best = std::min(best, d);
  }
  return best;
}

float Scene::depth_at(const Intrinsics& K, const Eigen::Isometry3f& T_wc, float x, float y) const {
  const Eigen::Vector3f o = T_wc.translation();
  const Eigen::Vector3f d = T_wc.linear() * K.unproject(x, y, 1.0f);  // unit z in the camera frame
  float best = std::numeric_limits<float>::infinity();
  for (const Primitive& s : primitives) {
    float t = -1;
    if (s.kind == Primitive::Sphere) {
      const Eigen::Vector3f oc = o - s.a;
      const float A = d.squaredNorm(), B = 2 * oc.dot(d), C = oc.squaredNorm() - s.b.x() * s.b.x();
      const float disc = B * B - 4 * A * C;
      if (disc >= 0) t = (-B - std::sqrt(disc)) / (2 * A);
    } else if (s.kind == Primitive::Box) {
      float t0 = -std::numeric_limits<float>::infinity(), t1 = std::numeric_limits<float>::infinity();
      for (int k = 0; k < 3; ++k) {
        const float lo = s.a[k] - s.b[k], hi = s.a[k] + s.b[k];
        if (std::abs(d[k]) < 1e-12f) {
          if (o[k] < lo || o[k] > hi) t0 = std::numeric_limits<float>::infinity();
          continue;
        }
        float ta = (lo - o[k]) / d[k], tb = (hi - o[k]) / d[k];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
      }
      if (t0 <= t1) t = t0;
    } else {
      const float den = s.a.dot(d);
      if (std::abs(den) > 1e-9f) t = (s.b.x() - s.a.dot(o)) / den;
    }
    if (t > 0 && t < best) best = t;
  }
  return std::isfinite(best) ? best : 0.0f;
}

DepthImage Scene::render_depth(const Intrinsics& K, const Eigen::Isometry3f& T_wc) const {
  DepthImage depth(K.width, K.height);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) depth(x, y) = depth_at(K, T_wc, float(x), float(y));
  return depth;
}

Scene sphere_scene(const Eigen::Vector3f& centre, float radius) {
  return Scene{{Primitive{Primitive::Sphere, centre, Eigen::Vector3f(radius, 0, 0)}}};
}

Eigen::Isometry3f look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target, const Eigen::Vector3f& up) {
  const Eigen::Vector3f z = (target - eye).normalized();
  Eigen::Vector3f x = z.cross(up);
  if (x.norm() < 1e-4f) x = z.cross(Eigen::Vector3f(1, 0, 0));
  x.normalize();
  const Eigen::Vector3f y = z.cross(x);
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

std::vector<Eigen::Isometry3f> cameras_around(const Eigen::Vector3f& target, float dist) {
  std::vector<Eigen::Vector3f> dirs;
  for (int k = 0; k < 3; ++k)
    for (int s : {-1, 1}) {
      Eigen::Vector3f d = Eigen::Vector3f::Zero();
      d[k] = float(s);
      dirs.push_back(d);
    }
  for (int sx : {-1, 1})
    for (int sy : {-1, 1})
      for (int sz : {-1, 1}) dirs.push_back(Eigen::Vector3f(float(sx), float(sy), float(sz)).normalized());
  std::vector<Eigen::Isometry3f> out;
  for (const auto& d : dirs) out.push_back(look_at(target + dist * d, target));
  return out;
}

}  // namespace rrg::test

#include "core/tsdf/tsdf_integrate.h"

namespace rrg::test {

void fuse_scene(TsdfVolume& volume, const Scene& scene, const Intrinsics& K,
                const std::vector<Eigen::Isometry3f>& poses, const Color& color) {
  const ColorImage c(K.width, K.height, color);
  const auto c_d = DeviceImage<Color>::from_host(c, volume.device());
  for (const auto& T : poses) {
    const auto d = DeviceImage<float>::from_host(scene.render_depth(K, T), volume.device());
    integrate(volume, d, c_d, K, T);
  }
}

std::vector<float> flatten_voxels(const TsdfVolume& volume) {
  std::vector<float> out;
  for (const BlockData& b : volume.read_all_blocks()) {
    out.insert(out.end(), {float(b.coord.x()), float(b.coord.y()), float(b.coord.z())});
    for (const Voxel& v : b.voxels)
      out.insert(out.end(), {float(v.tsdf), float(v.weight), float(v.rgb[0]), float(v.rgb[1]), float(v.rgb[2]),
                             float(v.n), v.mu, v.m2, float(v.r), float(v.plane)});
  }
  return out;
}

}  // namespace rrg::test
