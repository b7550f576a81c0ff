#pragma once
// Storage for one set of 3D Gaussians on one device (paper §3.1): the base set G_b or the
// reflection set G_r = U_i G_i^r. Structure of arrays in the standard 3DGS parameterisation
// (DESIGN.md §4): mean p, log-scale log(s), rotation quaternion r = (w, x, y, z) (normalised when
// used), logit opacity (sigma = sigmoid), SH coefficients up to degree 3 (3DGS basis), and for G_r
// the reflective plane id l (>= 1; 0 = none, base Gaussians keep 0). Reflection Gaussians live in
// virtual space, behind their plane (DESIGN.md §4).
//
// Growth is geometric (append never reallocates while capacity lasts) and pruning compacts in
// place by moving tail Gaussians into the holes, so a per-frame densify/prune cycle does not
// reallocate. The moves are returned so per-Gaussian optimiser state can follow them.
#include "core/common/buffer.h"

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

namespace rrg {

// Number of SH coefficients per colour channel for a degree: (degree + 1)^2, i.e. 1, 4, 9, 16.
constexpr int sh_coeff_count(int degree) { return (degree + 1) * (degree + 1); }
inline constexpr int kMaxShDegree = 3;

// Host mirror of a GaussianSet: seeding, tests, I/O. sh holds size() * sh_coeff_count(sh_degree)
// RGB triples, Gaussian-major ([N, K, 3]); coefficient 0 is the DC term f_dc.
struct GaussianHost {
  int sh_degree = 0;
  std::vector<Eigen::Vector3f> means;       // [N, 3] world (virtual space for G_r), metres
  std::vector<Eigen::Vector3f> log_scales;  // [N, 3] log s
  std::vector<Eigen::Vector4f> quats;       // [N, 4] w, x, y, z (any norm > 0)
  std::vector<float> logit_opacities;       // [N]
  std::vector<Eigen::Vector3f> sh;          // [N, K, 3]
  std::vector<int32_t> plane_ids;           // [N] l; 0 for base Gaussians

  explicit GaussianHost(int degree = 0) : sh_degree(degree) {}
  size_t size() const { return means.size(); }
  int sh_coeffs() const { return sh_coeff_count(sh_degree); }
  // Resizes every array to n Gaussians (new ones zero, identity rotation).
  void resize(size_t n);
  // Throws std::invalid_argument naming the array whose length disagrees with means.
  void validate() const;
};

// Moves done by GaussianSet::prune: Gaussian src[j] now lives at dst[j]; new_size Gaussians remain.
struct Compaction {
  size_t old_size = 0;
  size_t new_size = 0;
  std::vector<int32_t> src, dst;
};

class GaussianSet {
 public:
  GaussianSet(int sh_degree, const Device& device, size_t capacity = 0);
  static GaussianSet from_host(const GaussianHost& host, const Device& device);
  GaussianHost to_host() const;
  // An independent copy on the same device (device to device; capacity = size()).
  GaussianSet copy() const;
  // Makes this set a copy of src (same SH degree and device), reusing this set's buffers when their
  // capacity suffices: a snapshot refreshed every mapping step allocates (and faults in) nothing new.
  void assign(const GaussianSet& src);

  size_t size() const { return size_; }
  size_t capacity() const { return capacity_; }
  int sh_degree() const { return sh_degree_; }
  int sh_coeffs() const { return sh_coeff_count(sh_degree_); }
  const Device& device() const { return device_; }

  // Ensures capacity >= n without changing size (one reallocation, contents kept).
  void reserve(size_t n);
  // Appends host Gaussians of this set's SH degree or a lower one (their higher bands are then zero:
  // new Gaussians start with only the bands they were made with, and the zeros are written on the
  // set's device rather than built and copied on the host); capacity grows by at least 1.5x when
  // exceeded.
  void append(const GaussianHost& batch);
  // Keeps Gaussian i iff keep[i] != 0 (keep.size() == size()); fills holes from the tail, no
  // reallocation; order of survivors is not preserved. Returns the moves made.
  Compaction prune(const std::vector<uint8_t>& keep);
  void clear() { size_ = 0; }
  // Relabels the plane ids l through an id -> canonical id table (GlobalPlaneTable::remap_table():
  // when the plane table merges two instances, the Gaussians of the absorbed one move to the one
  // that absorbed it). Ids the table does not cover, or maps to 0, stay. On the set's device.
  void remap_plane_ids(std::span<const int32_t> remap);

  // Views over the first size() Gaussians, on device().
  Span<Eigen::Vector3f> means() { return {means_.data(), int64_t(size_)}; }
  Span<Eigen::Vector3f> log_scales() { return {log_scales_.data(), int64_t(size_)}; }
  Span<Eigen::Vector4f> quats() { return {quats_.data(), int64_t(size_)}; }
  Span<float> logit_opacities() { return {logit_opacities_.data(), int64_t(size_)}; }
  Span<Eigen::Vector3f> sh() { return {sh_.data(), int64_t(size_) * sh_coeffs()}; }
  Span<int32_t> plane_ids() { return {plane_ids_.data(), int64_t(size_)}; }
  Span<const Eigen::Vector3f> means() const { return {means_.data(), int64_t(size_)}; }
  Span<const Eigen::Vector3f> log_scales() const { return {log_scales_.data(), int64_t(size_)}; }
  Span<const Eigen::Vector4f> quats() const { return {quats_.data(), int64_t(size_)}; }
  Span<const float> logit_opacities() const { return {logit_opacities_.data(), int64_t(size_)}; }
  Span<const Eigen::Vector3f> sh() const { return {sh_.data(), int64_t(size_) * sh_coeffs()}; }
  Span<const int32_t> plane_ids() const { return {plane_ids_.data(), int64_t(size_)}; }

 private:
  int sh_degree_;
  Device device_;
  size_t size_ = 0, capacity_ = 0;
  Buffer<Eigen::Vector3f> means_, log_scales_;
  Buffer<Eigen::Vector4f> quats_;
  Buffer<float> logit_opacities_;
  Buffer<Eigen::Vector3f> sh_;
  Buffer<int32_t> plane_ids_;
};

// Applies a Compaction to any per-Gaussian array of `words` 32-bit words per Gaussian (e.g. Adam
// moments laid out like a GaussianSet field), on the array's device.
void apply_compaction(const Compaction& c, Span<uint32_t> data, int words, const Device& device);

}  // namespace rrg
