#include "core/eval/surface_sampling.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rrg::eval {
namespace {

// SplitMix64 (Steele et al. 2014): tiny, fast, and the same sequence everywhere.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)

 private:
  uint64_t state_;
};

double triangle_area(const TriangleMesh& mesh, const Eigen::Vector3i& f) {
  const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>();
  const Eigen::Vector3d b = mesh.vertices[f[1]].cast<double>();
  const Eigen::Vector3d c = mesh.vertices[f[2]].cast<double>();
  return 0.5 * (b - a).cross(c - a).norm();
}

}  // namespace

double surface_area(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const auto& f : mesh.triangles) area += triangle_area(mesh, f);
  return area;
}

OrientedSamples sample_surface_oriented(const TriangleMesh& mesh, size_t n, uint64_t seed) {
  try {
    mesh.validate();
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(std::string("sample_surface: ") + e.what());
  }
  if (mesh.vertices.empty()) throw std::invalid_argument("sample_surface: mesh has no vertices");

  // Cumulative areas: triangle k is chosen when u·A falls in [cdf[k-1], cdf[k]).
  std::vector<double> cdf(mesh.triangles.size());
  double total = 0.0;
  for (size_t k = 0; k < mesh.triangles.size(); ++k) cdf[k] = (total += triangle_area(mesh, mesh.triangles[k]));
  if (!(total > 0.0) || !std::isfinite(total)) return {mesh.vertices, {}};

  SplitMix64 rng(seed);
  OrientedSamples out;
  out.points.resize(n);
  out.normals.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double u = rng.uniform() * total;
    const size_t k = std::min(size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()), cdf.size() - 1);
    const Eigen::Vector3i& f = mesh.triangles[k];
    const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>(), b = mesh.vertices[f[1]].cast<double>(),
                          c = mesh.vertices[f[2]].cast<double>();
    const double s = std::sqrt(rng.uniform()), r2 = rng.uniform();
    out.points[i] = ((1.0 - s) * a + s * (1.0 - r2) * b + s * r2 * c).cast<float>();
    out.normals[i] = (b - a).cross(c - a).normalized().cast<float>();  // area > 0: the triangle was drawn
  }
  return out;
}

std::vector<Eigen::Vector3f> sample_surface(const TriangleMesh& mesh, size_t n, uint64_t seed) {
  return sample_surface_oriented(mesh, n, seed).points;
}

}  // namespace rrg::eval
