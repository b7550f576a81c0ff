#pragma once
// Smooth closed camera paths: a uniform Catmull-Rom loop through hand-placed eye waypoints (C1),
// re-parameterised by arc length so the camera moves at constant speed, looking at a second
// Catmull-Rom loop of targets, with a small periodic bob and roll. Poses are T_wc in the OpenCV
// camera convention (x right, y down, z forward) in a z-up world.
#include <Eigen/Geometry>

#include <vector>

namespace rrg::synth {

struct Waypoint {
  Eigen::Vector3d eye;     // camera centre, world
  Eigen::Vector3d target;  // point looked at, world
};

struct CameraPathParams {
  double bob_amplitude = 0.01;     // metres, vertical
  double bob_wavelength = 1.3;     // metres of path per bob period
  double roll_amplitude_deg = 1.5; // degrees about the optical axis
  double roll_wavelength = 3.7;    // metres of path per roll period
};

class CameraPath {
 public:
  // Needs at least 3 waypoints; throws std::invalid_argument otherwise.
  explicit CameraPath(std::vector<Waypoint> waypoints, const CameraPathParams& params = {});

  double length() const { return total_; }  // loop length, metres
  // Pose after travelling s metres from the first waypoint (wraps around the loop).
  Eigen::Isometry3d pose_at(double s) const;
  // Eye and target at distance s (eye includes the bob).
  Eigen::Vector3d eye_at(double s) const;
  Eigen::Vector3d target_at(double s) const;
  // Spline parameter u in [0, n) at arc length s (exposed for tests).
  double parameter_at(double s) const;

 private:
  Eigen::Vector3d spline(const std::vector<Eigen::Vector3d>& pts, double u) const;
  Eigen::Vector3d spline_derivative(const std::vector<Eigen::Vector3d>& pts, double u) const;
  double speed(double u) const { return spline_derivative(eyes_, u).norm(); }
  double integrate(double u0, double u1) const;  // arc length between parameters (Gauss-Legendre)
  double wrap(double s) const;

  std::vector<Eigen::Vector3d> eyes_, targets_;
  CameraPathParams params_;
  std::vector<double> table_u_, table_s_;  // cumulative arc length at sample parameters
  double total_ = 0.0;
  double bob_wavelength_ = 1.0, roll_wavelength_ = 1.0;  // adjusted to divide the loop length
};

}  // namespace rrg::synth
