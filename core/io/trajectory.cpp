// TUM trajectory text files: "t tx ty tz qx qy qz qw" per line, '#' comments, blank lines ignored.
#include "core/io/trajectory.h"

#include "core/io/atomic_file.h"
#include "core/io/text_parse.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

namespace rrg::io {

Trajectory read_tum_trajectory(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open trajectory file " + path.string());
  Trajectory trajectory;
  std::string line;
  for (size_t line_no = 1; std::getline(in, line); ++line_no) {
    const auto tokens = split_fields(line);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    auto fail = [&](const std::string& why) {
      throw std::runtime_error(path.string() + ":" + std::to_string(line_no) + ": " + why);
    };
    if (tokens.size() != 8)
      fail("expected 8 numbers 't tx ty tz qx qy qz qw', got " + std::to_string(tokens.size()) + " fields");
    double v[8];
    for (int k = 0; k < 8; ++k) {
      const auto parsed = parse_double(tokens[k]);
      if (!parsed || !std::isfinite(*parsed)) fail(std::string(tokens[k]).append(" is not a finite number"));
      v[k] = *parsed;
    }
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);  // (w, x, y, z)
    const double norm = q.norm();
    if (norm < 0.9 || norm > 1.1) fail("quaternion norm " + std::to_string(norm) + " is not 1");
    q.normalize();
    StampedPose pose;
    pose.timestamp = v[0];
    pose.T_wc.linear() = q.toRotationMatrix();
    pose.T_wc.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    trajectory.push_back(pose);
  }
  if (in.bad()) throw std::runtime_error("error reading trajectory file " + path.string());
  return trajectory;
}

void write_tum_trajectory(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::string text = "# timestamp tx ty tz qx qy qz qw (T_wc, metres, seconds)\n";
  char buf[256];
  for (const StampedPose& p : trajectory) {
    Eigen::Quaterniond q(p.T_wc.rotation());
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // canonical sign: qw >= 0
    const Eigen::Vector3d t = p.T_wc.translation();
    if (!std::isfinite(p.timestamp) || !t.allFinite() || !q.coeffs().allFinite())
      throw std::invalid_argument("trajectory for " + path.string() + " has a non-finite pose at t=" +
                                  std::to_string(p.timestamp));
    std::snprintf(buf, sizeof(buf), "%.6f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", p.timestamp, t.x(), t.y(),
                  t.z(), q.x(), q.y(), q.z(), q.w());
    text += buf;
  }
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::trunc);
    if (!out) throw std::runtime_error("cannot create " + tmp.string());
    out << text;
    out.close();
    if (!out) throw std::runtime_error("error writing trajectory file " + path.string());
  });
}

}  // namespace rrg::io
