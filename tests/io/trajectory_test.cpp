// TUM trajectories: round trip to 1e-9, comment handling, errors naming file and line.
#include "core/io/trajectory.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <fstream>

namespace rrg::io {
namespace {

TEST(Trajectory, RoundTripWithin1e9) {
  test::TempDir dir("io-traj");
  Trajectory traj;
  for (int i = 0; i < 20; ++i) {
    StampedPose p;
    p.timestamp = 1305031102.175304 + 0.033333 * i;  // 6 decimals survive
    p.T_wc.linear() = (Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d(1, 2, 3).normalized()) *
                       Eigen::AngleAxisd(-2.9 + 0.1 * i, Eigen::Vector3d::UnitZ()))
                          .toRotationMatrix();
    p.T_wc.translation() = Eigen::Vector3d(0.123456789 * i, -4.5 + i, 1e-3 * i * i);
    traj.push_back(p);
  }
  write_tum_trajectory(dir / "t.txt", traj);
  const Trajectory back = read_tum_trajectory(dir / "t.txt");
  ASSERT_EQ(back.size(), traj.size());
  for (size_t i = 0; i < traj.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, traj[i].timestamp, 1e-6);
    EXPECT_LE((back[i].T_wc.translation() - traj[i].T_wc.translation()).norm(), 1e-9) << i;
    EXPECT_LE((back[i].T_wc.linear() - traj[i].T_wc.linear()).cwiseAbs().maxCoeff(), 1e-9) << i;
  }
}

TEST(Trajectory, ReadsKnownAnswerWithComments) {
  test::TempDir dir("io-traj");
  std::ofstream(dir / "gt.txt") << "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n\n"
                                << "1.5 1 2 3 0 0 0 1\n"
                                << "2.0 0 0 0 0 0 0.7071067811865476 0.7071067811865476\n"
                                << "2.5,0,0,0,0,0,0,2.0\n";  // commas as associate.py; |q| = 2 -> error
  try {
    read_tum_trajectory(dir / "gt.txt");
    FAIL() << "non-unit quaternion accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("gt.txt:6"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("quaternion"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "gt.txt") << "1.5 1 2 3 0 0 0 1\n2.0 0 0 0 0 0 0.7071067811865476 0.7071067811865476\n"
                                << "2.5 0 0 0 0 0 0 1.05\n";  // slightly off: normalised
  const Trajectory t = read_tum_trajectory(dir / "gt.txt");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0].timestamp, 1.5);
  EXPECT_TRUE(t[0].T_wc.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  // 90 degrees about z: camera x axis -> world y.
  EXPECT_LE((t[1].T_wc.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_LE((t[2].T_wc.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(Trajectory, MalformedLineNamesLineNumber) {
  test::TempDir dir("io-traj");
  std::ofstream(dir / "bad.txt") << "# header\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n";
  try {
    read_tum_trajectory(dir / "bad.txt");
    FAIL() << "7-field line accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:3"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "bad2.txt") << "1 0 0 x0 0 0 0 1\n";
  try {
    read_tum_trajectory(dir / "bad2.txt");
    FAIL() << "non-number accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad2.txt:1: x0"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_tum_trajectory(dir / "missing.txt"), std::runtime_error);
}

TEST(Trajectory, NonFinitePoseIsNotWritten) {
  test::TempDir dir("io-traj");
  Trajectory t(1);
  t[0].T_wc.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_tum_trajectory(dir / "t.txt", t), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "t.txt"));
}

}  // namespace
}  // namespace rrg::io
