#include "core/gaussians/densify.h"

#include <parallel/algorithm>  // __gnu_parallel::sort (OpenMP)

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

namespace rrg {

namespace {

constexpr float kShC0 = 0.28209479177387814f;  // SH band 0: c = C0 · f_dc + 0.5

uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Uniform in [0, 1) from (seed, pixel index).
float pixel_uniform(uint64_t seed, int64_t pixel) {
  return float(splitmix64(seed ^ splitmix64(uint64_t(pixel))) >> 40) / float(1ull << 24);
}

float color_error(const Color& a, const Color& b) { return (a - b).cwiseAbs().sum() / 3.0f; }

void check_image(const auto* im, const Intrinsics& K, const char* name) {
  if (!im) throw std::invalid_argument(std::string("densify: ") + name + " is missing");
  if (im->width() != K.width || im->height() != K.height)
    throw std::invalid_argument(std::string("densify: ") + name + " is " + std::to_string(im->width()) + "x" +
                                std::to_string(im->height()) + ", intrinsics are " + K.to_string());
}

// Normal of the observed surface at (x, y) in the camera frame from central differences of the
// back-projected depth, facing the camera; the reversed viewing ray where it cannot be computed.
Eigen::Vector3f depth_normal(const DepthImage& D, const Intrinsics& K, int x, int y) {
  const Eigen::Vector3f ray = K.unproject(float(x), float(y), 1.0f).normalized();
  if (x <= 0 || y <= 0 || x >= D.width() - 1 || y >= D.height() - 1) return -ray;
  const float zl = D(x - 1, y), zr = D(x + 1, y), zu = D(x, y - 1), zd = D(x, y + 1);
  if (!(zl > 0 && zr > 0 && zu > 0 && zd > 0)) return -ray;
  const Eigen::Vector3f l = K.unproject(float(x - 1), float(y), zl), r = K.unproject(float(x + 1), float(y), zr);
  const Eigen::Vector3f u = K.unproject(float(x), float(y - 1), zu), d = K.unproject(float(x), float(y + 1), zd);
  Eigen::Vector3f n = (r - l).cross(d - u);
  if (!(n.norm() > 0)) return -ray;
  n.normalize();
  return n.dot(ray) > 0 ? Eigen::Vector3f(-n) : n;
}

// Cell of p in the grid of side `cap`, and its key: 21 bits per axis (wraps every 2^21 cells, 21 km
// at 1 cm).
Eigen::Vector3i cell_of(const Eigen::Vector3f& p, float cap) { return (p / cap).array().floor().cast<int>(); }
uint64_t cell_key(const Eigen::Vector3i& c) {
  return (uint64_t(uint32_t(c.x()) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(c.y()) & 0x1FFFFF) << 21) |
         uint64_t(uint32_t(c.z()) & 0x1FFFFF);
}

// The 27 cells around a point's own, nearest first (own, 6 faces, 12 edges, 8 corners).
std::array<Eigen::Vector3i, 27> cells_nearest_first() {
  std::array<Eigen::Vector3i, 27> out;
  int k = 0;
  for (int order = 0; order <= 3; ++order)
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (std::abs(dx) + std::abs(dy) + std::abs(dz) == order) out[size_t(k++)] = Eigen::Vector3i(dx, dy, dz);
  return out;
}

// The points of each occupied cell: a run [begin, end) of the cell-sorted order, found through an
// open-addressing table keyed by cell (keys use 63 bits, so ~0 marks an empty slot). `starts`: where
// each cell's run begins in `sorted`, then sorted.size().
class CellRuns {
 public:
  CellRuns(std::span<const std::pair<uint64_t, int32_t>> sorted, std::span<const uint32_t> starts) {
    const size_t cells = starts.size() - 1;
    size_t size = 16;
    while (size < 2 * cells) size *= 2;
    mask_ = size - 1;
    slots_.assign(size, Slot{});
    for (size_t c = 0; c < cells; ++c) {
      const uint64_t key = sorted[starts[c]].first;
      size_t h = splitmix64(key) & mask_;
      while (slots_[h].key != kEmpty) h = (h + 1) & mask_;
      slots_[h] = {key, starts[c], starts[c + 1]};
    }
  }
  // [begin, end) of the cell's points; an empty range when the cell holds none.
  std::pair<uint32_t, uint32_t> find(uint64_t key) const {
    for (size_t h = splitmix64(key) & mask_;; h = (h + 1) & mask_) {
      const Slot& s = slots_[h];
      if (s.key == key) return {s.begin, s.end};
      if (s.key == kEmpty) return {0, 0};
    }
  }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t(0);
  struct Slot {
    uint64_t key = kEmpty;
    uint32_t begin = 0, end = 0;
  };
  std::vector<Slot> slots_;
  size_t mask_ = 0;
};

// sqrt(mean squared distance to the 3 nearest other points), neighbours beyond `cap` counted as cap.
// The points are sorted by grid cell (side cap), so the 27 cells around a point's own are runs of
// the sorted copy, and the queries go in that order (neighbouring queries read the same runs). A
// cell is skipped when its box lies no nearer than the third-nearest point found so far (nearest
// cells first): the result is that of the full search, for any number of threads.
std::vector<float> knn3_scale(std::span<const Eigen::Vector3f> pts, float cap) {
  const int64_t n = int64_t(pts.size());
  std::vector<float> out(pts.size());
  if (n == 0) return out;
  if (n > int64_t(std::numeric_limits<int32_t>::max()))
    throw std::invalid_argument("densify: " + std::to_string(n) + " new points in one call, more than 2^31");
  std::vector<std::pair<uint64_t, int32_t>> sorted(pts.size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < n; ++i) sorted[size_t(i)] = {cell_key(cell_of(pts[size_t(i)], cap)), int32_t(i)};
  __gnu_parallel::sort(sorted.begin(), sorted.end());  // (cell, index): unique, so one order for any threads
  std::vector<Eigen::Vector3f> sorted_pts(pts.size());
#pragma omp parallel for schedule(static)
  for (int64_t k = 0; k < n; ++k) sorted_pts[size_t(k)] = pts[size_t(sorted[size_t(k)].second)];
  std::vector<uint32_t> cell_starts;  // where each occupied cell's run begins in `sorted`, then n
  for (int64_t k = 0; k < n; ++k)
    if (k == 0 || sorted[size_t(k)].first != sorted[size_t(k) - 1].first) cell_starts.push_back(uint32_t(k));
  cell_starts.push_back(uint32_t(n));
  const CellRuns runs(sorted, cell_starts);
  static const std::array<Eigen::Vector3i, 27> kCells = cells_nearest_first();
  const float cap2 = cap * cap;
  const int64_t cells = int64_t(cell_starts.size()) - 1;
#pragma omp parallel for schedule(dynamic, 256)
  for (int64_t cell = 0; cell < cells; ++cell) {
    // the 27 neighbouring runs, looked up once for all the points of this cell
    const uint32_t first = cell_starts[size_t(cell)], last = cell_starts[size_t(cell) + 1];
    const Eigen::Vector3i c = cell_of(sorted_pts[first], cap);
    std::array<std::pair<uint32_t, uint32_t>, 27> ranges;
    for (size_t i = 0; i < kCells.size(); ++i) ranges[i] = runs.find(cell_key(c + kCells[i]));
    for (uint32_t k = first; k < last; ++k) {
      const Eigen::Vector3f& p = sorted_pts[k];
      const Eigen::Vector3f f = p / cap - c.cast<float>();  // position inside the own cell, [0, 1]^3
      float best[3] = {cap2, cap2, cap2};                    // ascending
      for (size_t i = 0; i < kCells.size(); ++i) {
        // squared distance from p to the neighbouring cell's box, a little short (never skips a
        // point that could count: rounding is far below the 1e-4 relative margin)
        const Eigen::Vector3i& d = kCells[i];
        float box2 = 0.0f;
        for (int a = 0; a < 3; ++a) {
          const float gap = d[a] < 0 ? f[a] : (d[a] > 0 ? 1.0f - f[a] : 0.0f);
          box2 += gap * gap;
        }
        if (box2 * cap2 * (1.0f - 1e-4f) >= best[2]) continue;
        for (uint32_t j = ranges[i].first; j < ranges[i].second; ++j) {
          if (j == k) continue;
          const float d2 = (sorted_pts[j] - p).squaredNorm();
          if (d2 >= best[2]) continue;
          if (d2 < best[1]) {
            best[2] = best[1];
            if (d2 < best[0]) {
              best[1] = best[0];
              best[0] = d2;
            } else {
              best[1] = d2;
            }
          } else {
            best[2] = d2;
          }
        }
      }
      out[size_t(sorted[k].second)] = std::sqrt((best[0] + best[1] + best[2]) / 3.0f);
    }
  }
  return out;
}

// The Gaussians each pixel of an image makes (count(x, y) >= 0, evaluated once per pixel, rows in
// parallel) and where each pixel's first one goes in the row-major concatenation: the output order
// of a plain loop over the pixels, for any number of threads.
class PixelRuns {
 public:
  template <class Count>
  PixelRuns(const Intrinsics& K, Count&& count)
      : width_(K.width), height_(K.height), count_(size_t(K.width) * size_t(K.height)), row_start_(size_t(K.height) + 1, 0) {
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height_; ++y) {
      int64_t row = 0;
      for (int x = 0; x < width_; ++x) {
        const int c = count(x, y);
        count_[size_t(y) * size_t(width_) + size_t(x)] = c;
        row += c;
      }
      row_start_[size_t(y) + 1] = row;
    }
    for (int y = 0; y < height_; ++y) row_start_[size_t(y) + 1] += row_start_[size_t(y)];
  }
  int64_t total() const { return row_start_.back(); }
  // f(x, y, first) for every pixel that makes Gaussians; rows in parallel.
  template <class F>
  void for_each(F&& f) const {
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height_; ++y) {
      int64_t k = row_start_[size_t(y)];
      for (int x = 0; x < width_; ++x) {
        const int c = count_[size_t(y) * size_t(width_) + size_t(x)];
        if (c == 0) continue;
        f(x, y, k);
        k += c;
      }
    }
  }

 private:
  int width_, height_;
  std::vector<int32_t> count_;
  std::vector<int64_t> row_start_;
};

}  // namespace

void DensifyParams::validate() const {
  auto check = [](bool ok, const char* name, float v) {
    if (!ok) throw std::invalid_argument(std::string("DensifyParams: bad ") + name + " = " + std::to_string(v));
  };
  check(base_error >= 0, "base_error", base_error);
  check(base_weight > 0, "base_weight", base_weight);
  check(reflection_error >= 0, "reflection_error", reflection_error);
  check(variance >= 0, "variance", variance);
  check(reflection_weight > 0, "reflection_weight", reflection_weight);
  check(sample_ratio >= 0 && sample_ratio <= 1, "sample_ratio", sample_ratio);
  check(reflection_samples >= 1, "reflection_samples", float(reflection_samples));
  check(reflection_near >= 0 && reflection_far >= reflection_near, "reflection_near/far", reflection_near);
  check(max_init_scale > 0, "max_init_scale", max_init_scale);
  check(base_min_init_scale > 0 && base_min_init_scale <= max_init_scale, "base_min_init_scale", base_min_init_scale);
  check(reflection_max_init_scale > 0, "reflection_max_init_scale", reflection_max_init_scale);
  check(reflection_min_init_scale > 0 && reflection_min_init_scale <= reflection_max_init_scale,
        "reflection_min_init_scale", reflection_min_init_scale);
  check(flatten > 0 && flatten <= 1, "flatten", flatten);
  check(init_opacity > 0 && init_opacity < 1, "init_opacity", init_opacity);
  check(reflection_sample_opacity >= 0 && reflection_sample_opacity < 1, "reflection_sample_opacity",
        reflection_sample_opacity);
}

float DensifyParams::reflection_sample_alpha() const {
  if (reflection_sample_opacity > 0) return reflection_sample_opacity;
  return 1.0f - std::pow(1.0f - init_opacity, 1.0f / float(reflection_samples));
}

GaussianHost init_gaussians(std::span<const Eigen::Vector3f> points, std::span<const Eigen::Vector3f> normals,
                            std::span<const Color> colors, std::span<const int32_t> plane_ids,
                            std::span<const float> opacities, const DensifyParams& params, float min_init_scale,
                            float max_init_scale, int sh_degree) {
  const size_t n = points.size();
  if (normals.size() != n || colors.size() != n || plane_ids.size() != n || opacities.size() != n)
    throw std::invalid_argument("init_gaussians: points, normals, colours, plane ids and opacities differ in length");
  for (const float o : opacities)
    if (!(o > 0.0f && o < 1.0f))
      throw std::invalid_argument("init_gaussians: opacity " + std::to_string(o) + " is outside (0, 1)");
  GaussianHost h(sh_degree);
  h.resize(n);
  const std::vector<float> s = knn3_scale(points, max_init_scale);
  const int K = h.sh_coeffs();
#pragma omp parallel for schedule(static)
  for (size_t i = 0; i < n; ++i) {
    const float si = std::clamp(s[i], min_init_scale, max_init_scale);
    h.means[i] = points[i];
    h.log_scales[i] = Eigen::Vector3f(std::log(si), std::log(si), std::log(si * params.flatten));
    const Eigen::Quaternionf q = Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), normals[i]);
    h.quats[i] = Eigen::Vector4f(q.w(), q.x(), q.y(), q.z());
    h.logit_opacities[i] = std::log(opacities[i] / (1.0f - opacities[i]));
    h.sh[i * size_t(K)] = (colors[i] - Color::Constant(0.5f)) / kShC0;
    h.plane_ids[i] = plane_ids[i];
  }
  return h;
}

GaussianHost densify_base(const DensifyView& v, const DensifyParams& p, int sh_degree, uint64_t seed,
                          std::span<const ReflectivePlane> reflective) {
  p.validate();
  check_image(v.C_gt, v.K, "C_gt");
  check_image(v.D_gt, v.K, "D_gt");
  check_image(v.C, v.K, "C");
  check_image(v.W_b, v.K, "W_b");
  const bool leave = p.base_leaves_reflections && !reflective.empty();
  std::unordered_set<int32_t> reflective_ids;
  if (leave) {
    check_image(v.R, v.K, "R");
    if (p.reflection_variance_gate) check_image(v.C_var, v.K, "C_var");
    check_image(v.I, v.K, "I");
    for (const ReflectivePlane& pl : reflective) reflective_ids.insert(pl.id);
  }
  const auto candidate = [&](int x, int y) {
    const float z = (*v.D_gt)(x, y);
    if (!(z > 0)) return false;
    if (!(color_error((*v.C_gt)(x, y), (*v.C)(x, y)) > p.base_error && (*v.W_b)(x, y) < p.base_weight)) return false;
    if (leave && (*v.R)(x, y) != 0 && (!p.reflection_variance_gate || (*v.C_var)(x, y) > p.variance) &&
        reflective_ids.count((*v.I)(x, y)) > 0)
      return false;
    return pixel_uniform(seed, int64_t(y) * v.K.width + x) < p.sample_ratio;
  };
  const PixelRuns runs(v.K, [&](int x, int y) { return candidate(x, y) ? 1 : 0; });
  std::vector<Eigen::Vector3f> pts(runs.total()), nrm(runs.total());
  std::vector<Color> col(runs.total());
  const Eigen::Matrix3f R_wc = v.T_wc.linear();
  runs.for_each([&](int x, int y, int64_t k) {
    const float z = (*v.D_gt)(x, y);
    pts[size_t(k)] = v.T_wc * v.K.unproject(float(x), float(y), z);
    nrm[size_t(k)] = R_wc * depth_normal(*v.D_gt, v.K, x, y);
    col[size_t(k)] = (*v.C_gt)(x, y);
  });
  const std::vector<int32_t> ids(pts.size(), 0);
  const std::vector<float> opacities(pts.size(), p.init_opacity);
  return init_gaussians(pts, nrm, col, ids, opacities, p, p.base_min_init_scale, p.max_init_scale, sh_degree);
}

namespace {

using ReflectionPassed = std::array<int64_t, 7>;  // on plane, R = 1, wrong, varying, uncovered, sampled, at virtual depth

// The per-pixel tests of reflection densification, in order (DensifyParams): the pixel's plane (its
// unit equation) when (x, y) passes them all, else null. `passed` (when given) counts the pixels
// left after each test (the debug log shows where candidates are lost).
class ReflectionTests {
 public:
  ReflectionTests(const DensifyView& v, std::span<const ReflectivePlane> planes, const DensifyParams& p, uint64_t seed)
      : v_(v), p_(p), seed_(seed), by_id_(unit_planes_by_id(planes, "densify_reflection")) {
    p.validate();
    check_image(v.C_gt, v.K, "C_gt");
    check_image(v.C, v.K, "C");
    check_image(v.C_b, v.K, "C_b");
    check_image(v.W_r, v.K, "W_r");
    check_image(v.R, v.K, "R");
    if (p.reflection_variance_gate) check_image(v.C_var, v.K, "C_var");
    check_image(v.I, v.K, "I");
  }

  const Eigen::Vector4f* operator()(int x, int y, ReflectionPassed* passed) const {
    const int32_t id = (*v_.I)(x, y);
    const auto it = id > 0 ? by_id_.find(id) : by_id_.end();
    if (it == by_id_.end()) return nullptr;
    const auto pass = [&](int stage) {
      if (passed) ++(*passed)[size_t(stage)];
    };
    pass(0);
    if ((*v_.R)(x, y) == 0) return nullptr;
    pass(1);
    if (!(color_error((*v_.C_gt)(x, y), (*v_.C)(x, y)) > p_.reflection_error)) return nullptr;
    pass(2);
    if (p_.reflection_variance_gate && !((*v_.C_var)(x, y) > p_.variance)) return nullptr;
    pass(3);
    if (!((*v_.W_r)(x, y) < p_.reflection_weight)) return nullptr;
    pass(4);
    if (!(pixel_uniform(seed_, int64_t(y) * v_.K.width + x) < p_.sample_ratio)) return nullptr;
    pass(5);
    return &it->second;
  }

 private:
  const DensifyView& v_;
  const DensifyParams& p_;
  uint64_t seed_;
  std::unordered_map<int32_t, Eigen::Vector4f> by_id_;
};

}  // namespace

MaskImage reflection_candidates(const DensifyView& v, std::span<const ReflectivePlane> planes, const DensifyParams& p,
                                uint64_t seed) {
  const ReflectionTests tests(v, planes, p, seed);
  MaskImage out(v.K.width, v.K.height, uint8_t(0));
#pragma omp parallel for schedule(static)
  for (int y = 0; y < v.K.height; ++y)
    for (int x = 0; x < v.K.width; ++x) out(x, y) = tests(x, y, nullptr) != nullptr;
  return out;
}

GaussianHost densify_reflection(const DensifyView& v, std::span<const ReflectivePlane> planes, const DensifyParams& p,
                                int sh_degree, uint64_t seed) {
  const ReflectionTests tests(v, planes, p, seed);
  // One of the S samples along a ray: the sample opacity (together as opaque as one new Gaussian);
  // a Gaussian at the virtual surface (mirrored or plane sweep): the base's initial opacity.
  const float sample_alpha = p.reflection_sample_alpha();
  const Eigen::Vector3f o = v.T_wc.translation();
  const Eigen::Matrix3f R_wc = v.T_wc.linear();
  const int S = p.reflection_samples;
  const bool virtual_depth = (p.reflection_mirrored_depth || p.reflection_stereo_depth) && v.virtual_depth != nullptr;
  if (virtual_depth) check_image(v.virtual_depth, v.K, "virtual_depth");

  // What one pixel makes: nothing, one Gaussian at the virtual surface X, or S samples along the
  // ray past the ray–plane intersection `hit`.
  struct Sample {
    int count = 0;  // Gaussians: 0, 1 (at X) or S
    bool at_virtual = false;
    int32_t id = 0;
    Eigen::Vector3f n, dir, hit, X;
    Color c;
  };
  using Passed = ReflectionPassed;
  const auto sample = [&](int x, int y, Passed* passed) {
    Sample s;
    const Eigen::Vector4f* plane = tests(x, y, passed);
    if (!plane) return s;
    const int32_t id = (*v.I)(x, y);
    s.dir = (R_wc * v.K.unproject(float(x), float(y), 1.0f)).normalized();
    s.n = plane->head<3>();
    const float denom = s.n.dot(s.dir);
    if (std::abs(denom) < 1e-6f) return s;
    const float t = -(s.n.dot(o) + plane->w()) / denom;
    if (!(t > 0)) return s;
    s.id = id;
    s.hit = o + t * s.dir;
    s.c = p.reflection_residual_color ? Color(((*v.C_gt)(x, y) - (*v.C_b)(x, y)).cwiseMax(0.0f)) : Color((*v.C_gt)(x, y));
    if (virtual_depth) {
      // One Gaussian at the virtual surface when it lies behind the plane (the camera's side of
      // the plane has the opposite sign).
      const float z = (*v.virtual_depth)(x, y);
      s.X = v.T_wc * v.K.unproject(float(x), float(y), z);
      const float side_cam = s.n.dot(o) + plane->w(), side_X = s.n.dot(s.X) + plane->w();
      if (z > 0 && side_cam * side_X < 0) {
        if (passed) ++(*passed)[6];
        s.at_virtual = true;
        s.count = 1;
        return s;
      }
    }
    s.count = S;
    return s;
  };

  std::vector<Passed> passed_by_row(size_t(v.K.height), Passed{});
  const PixelRuns runs(v.K, [&](int x, int y) { return sample(x, y, &passed_by_row[size_t(y)]).count; });
  const size_t n = size_t(runs.total());
  std::vector<Eigen::Vector3f> pts(n), nrm(n);
  std::vector<Color> col(n);
  std::vector<int32_t> ids(n);
  std::vector<float> opacities(n);
  runs.for_each([&](int x, int y, int64_t k0) {
    const Sample s = sample(x, y, nullptr);
    for (int j = 0; j < s.count; ++j) {
      const size_t k = size_t(k0 + j);
      if (s.at_virtual) {
        pts[k] = s.X, opacities[k] = p.init_opacity;
      } else {
        const float d = S == 1 ? p.reflection_near
                               : p.reflection_near + (p.reflection_far - p.reflection_near) * float(j) / float(S - 1);
        pts[k] = s.hit + d * s.dir, opacities[k] = sample_alpha;
      }
      nrm[k] = s.n, col[k] = s.c, ids[k] = s.id;
    }
  });
  Passed passed{};
  for (const Passed& r : passed_by_row)
    for (size_t i = 0; i < passed.size(); ++i) passed[i] += r[i];
  spdlog::debug("densify_reflection: {} reflective plane(s); pixels on them {}, with R = 1 {}, error > {} {}, "
                "C_var > {} {}, W_r < {} {}, sampled {} ({} at a virtual depth)",
                planes.size(), passed[0], passed[1], p.reflection_error, passed[2], p.variance, passed[3],
                p.reflection_weight, passed[4], passed[5], passed[6]);
  return init_gaussians(pts, nrm, col, ids, opacities, p, p.reflection_min_init_scale, p.reflection_max_init_scale,
                        sh_degree);
}

}  // namespace rrg
