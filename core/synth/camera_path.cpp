#include "core/synth/camera_path.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rrg::synth {

using Eigen::Vector3d;

namespace {
constexpr int kSamplesPerSegment = 64;
constexpr double kPi = 3.14159265358979323846;
// 5-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr double kGlX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
constexpr double kGlW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                            0.2369268850561891};

double loop_wavelength(double total, double wanted) {
  return total / std::max(1.0, std::round(total / wanted));
}
}  // namespace

CameraPath::CameraPath(std::vector<Waypoint> waypoints, const CameraPathParams& params) : params_(params) {
  if (waypoints.size() < 3) throw std::invalid_argument("CameraPath: needs at least 3 waypoints");
  for (const Waypoint& w : waypoints) {
    if ((w.target - w.eye).norm() < 1e-3) throw std::invalid_argument("CameraPath: a waypoint looks at itself");
    eyes_.push_back(w.eye);
    targets_.push_back(w.target);
  }
  const int n = int(eyes_.size());
  table_u_.push_back(0.0);
  table_s_.push_back(0.0);
  for (int i = 0; i < n * kSamplesPerSegment; ++i) {
    const double u0 = double(i) / kSamplesPerSegment, u1 = double(i + 1) / kSamplesPerSegment;
    table_u_.push_back(u1);
    table_s_.push_back(table_s_.back() + integrate(u0, u1));
  }
  total_ = table_s_.back();
  if (!(total_ > 1e-6)) throw std::invalid_argument("CameraPath: waypoints do not span a path");
  bob_wavelength_ = loop_wavelength(total_, params_.bob_wavelength);
  roll_wavelength_ = loop_wavelength(total_, params_.roll_wavelength);
}

Vector3d CameraPath::spline(const std::vector<Vector3d>& p, double u) const {
  const int n = int(p.size());
  const double fl = std::floor(u);
  const double t = u - fl;
  const int i = ((int(fl) % n) + n) % n;
  const Vector3d& p0 = p[size_t((i + n - 1) % n)];
  const Vector3d& p1 = p[size_t(i)];
  const Vector3d& p2 = p[size_t((i + 1) % n)];
  const Vector3d& p3 = p[size_t((i + 2) % n)];
  // Uniform Catmull-Rom: passes through p1 (t=0) and p2 (t=1), C1 across segments.
  return 0.5 * (2.0 * p1 + (p2 - p0) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t * t +
                (3.0 * p1 - p0 - 3.0 * p2 + p3) * t * t * t);
}

Vector3d CameraPath::spline_derivative(const std::vector<Vector3d>& p, double u) const {
  const int n = int(p.size());
  const double fl = std::floor(u);
  const double t = u - fl;
  const int i = ((int(fl) % n) + n) % n;
  const Vector3d& p0 = p[size_t((i + n - 1) % n)];
  const Vector3d& p1 = p[size_t(i)];
  const Vector3d& p2 = p[size_t((i + 1) % n)];
  const Vector3d& p3 = p[size_t((i + 2) % n)];
  return 0.5 * ((p2 - p0) + 2.0 * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t +
                3.0 * (3.0 * p1 - p0 - 3.0 * p2 + p3) * t * t);
}

double CameraPath::integrate(double u0, double u1) const {
  const double half = 0.5 * (u1 - u0), mid = 0.5 * (u1 + u0);
  double sum = 0.0;
  for (int k = 0; k < 5; ++k) sum += kGlW[k] * speed(mid + half * kGlX[k]);
  return sum * half;
}

double CameraPath::wrap(double s) const {
  const double w = std::fmod(s, total_);
  return w < 0.0 ? w + total_ : w;
}

double CameraPath::parameter_at(double s_in) const {
  const double s = wrap(s_in);
  const auto it = std::upper_bound(table_s_.begin(), table_s_.end(), s);
  const size_t j = std::clamp<size_t>(size_t(it - table_s_.begin()), 1, table_s_.size() - 1) - 1;
  const double u_lo = table_u_[j], u_hi = table_u_[j + 1];
  // Newton on L(u) = s inside the sample interval, starting from linear interpolation.
  const double span = table_s_[j + 1] - table_s_[j];
  double u = span > 0.0 ? u_lo + (u_hi - u_lo) * (s - table_s_[j]) / span : u_lo;
  for (int iter = 0; iter < 4; ++iter) {
    const double f = table_s_[j] + integrate(u_lo, u) - s;
    const double v = speed(u);
    if (v <= 1e-12) break;
    u = std::clamp(u - f / v, u_lo, u_hi);
  }
  return u;
}

Vector3d CameraPath::eye_at(double s) const {
  Vector3d e = spline(eyes_, parameter_at(s));
  e.z() += params_.bob_amplitude * std::sin(2.0 * kPi * wrap(s) / bob_wavelength_);
  return e;
}

Vector3d CameraPath::target_at(double s) const { return spline(targets_, parameter_at(s)); }

Eigen::Isometry3d CameraPath::pose_at(double s) const {
  const Vector3d eye = eye_at(s), target = target_at(s);
  const Vector3d f = (target - eye).normalized();
  Vector3d right = f.cross(Vector3d::UnitZ());
  if (right.norm() < 1e-6) right = Vector3d::UnitX();  // looking straight up/down: any right works
  right.normalize();
  const Vector3d down = f.cross(right);
  Eigen::Matrix3d R;
  R.col(0) = right;
  R.col(1) = down;
  R.col(2) = f;
  const double roll = params_.roll_amplitude_deg * kPi / 180.0 * std::sin(2.0 * kPi * wrap(s) / roll_wavelength_ + 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R * Eigen::AngleAxisd(roll, Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = eye;
  return T;
}

}  // namespace rrg::synth
