// Stage 1: frame-to-model point-to-plane ICP (core/tracking/icp.h) on an analytic scene.
#include "core/tracking/icp.h"
#include "core/tracking/preprocess.h"
#include "core/tracking/se3.h"
#include "tests/support/parity.h"
#include "tests/tracking/box_scene.h"

#include <gtest/gtest.h>

#include <cmath>

#include <numbers>

namespace rrg {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Scene {
  Intrinsics K = test::test_intrinsics(160, 120);
  Eigen::Isometry3f T_ref = test::look_at({-0.5f, -0.4f, -0.3f}, {2.0f, 1.0f, 0.8f});
  Eigen::Isometry3f T_true;  // the new frame: T_ref moved by a known rigid motion
  test::BoxRender model, frame;
  Scene() {
    Eigen::Isometry3f delta = Eigen::Isometry3f::Identity();
    delta.rotate(Eigen::AngleAxisf(float(2.0 * kDeg), Eigen::Vector3f(0.3f, 1.0f, -0.2f).normalized()));
    delta.translation() = Eigen::Vector3f(0.03f, -0.02f, 0.025f);
    T_true = T_ref * delta;
    model = test::render_box(K, T_ref);
    frame = test::render_box(K, T_true);
  }
};

struct DeviceModel {
  DeviceImage<Eigen::Vector3f> vertices, normals;
  IcpModel view(const Intrinsics& K, const Eigen::Isometry3f& T) const { return {&vertices, &normals, K, T}; }
};

DeviceModel upload_model(const test::BoxRender& r, const Device& device) {
  return {DeviceImage<Eigen::Vector3f>::from_host(r.vertices, device), DeviceImage<Eigen::Vector3f>::from_host(r.normals, device)};
}

PreprocessParams no_filter() {
  PreprocessParams p;
  p.bilateral = false;  // exact synthetic depth
  return p;
}

TEST(Icp, RecoversKnownRigidMotionToSubMillimetre) {
  const Scene s;
  const DeviceModel model = upload_model(s.model, Device::cpu());
  const FramePyramid pyr = build_pyramid(DeviceImage<float>::from_host(s.frame.depth, Device::cpu()), s.K, no_filter());
  IcpParams params;
  params.iterations[0] = 20;
  params.iterations[1] = 10;
  params.iterations[2] = 10;
  const IcpResult r = icp_align(pyr, model.view(s.K, s.T_ref), s.T_ref, params);
  const double dt = translation_distance(r.T_wc.cast<double>(), s.T_true.cast<double>());
  const double dr = rotation_distance(r.T_wc.cast<double>(), s.T_true.cast<double>());
  EXPECT_LT(dt, 1e-3) << "translation error " << dt * 1e3 << " mm";
  EXPECT_LT(dr, 0.1 * kDeg) << "rotation error " << dr / kDeg << " deg";
  // the start was really off: 4.4 cm and 2 degrees
  EXPECT_GT(translation_distance(s.T_ref.cast<double>(), s.T_true.cast<double>()), 0.04);
  EXPECT_TRUE(r.converged);
  EXPECT_FALSE(r.diverged);
  EXPECT_GT(r.inlier_ratio, 0.9f);
  EXPECT_LT(r.rmse_m, 1e-3f);
  EXPECT_GT(r.condition, 0.0f);
}

TEST(Icp, NoModelOverlapGivesNoInliers) {
  const Scene s;
  test::BoxRender empty = s.model;
  for (auto& v : empty.normals.pixels()) v.setZero();
  const DeviceModel model = upload_model(empty, Device::cpu());
  const FramePyramid pyr = build_pyramid(DeviceImage<float>::from_host(s.frame.depth, Device::cpu()), s.K, no_filter());
  const IcpResult r = icp_align(pyr, model.view(s.K, s.T_ref), s.T_ref, IcpParams{});
  EXPECT_EQ(r.inliers, 0);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_GT(r.valid, 10000);
  EXPECT_EQ(r.inlier_ratio, 0.0f);
}

TEST(Icp, SystemAtTruePoseHasZeroResidualAndKnownCount) {
  // At the true pose every associated pair lies on its plane: Jᵀr = 0 and r = 0.
  const Scene s;
  const DeviceModel model = upload_model(s.model, Device::cpu());
  const FramePyramid pyr = build_pyramid(DeviceImage<float>::from_host(s.model.depth, Device::cpu()), s.K, no_filter());
  const kernel::IcpSystem sys = reduce_icp_system(pyr.levels[0].maps, model.view(s.K, s.T_ref), s.T_ref, IcpParams{});
  EXPECT_GT(sys.inliers, 0.9 * sys.valid);
  EXPECT_LT(sys.r2 / sys.inliers, 1e-10);
  for (double g : sys.jtr) EXPECT_NEAR(g, 0.0, 1e-3);
  Eigen::Matrix<double, 6, 1> xi;
  ASSERT_TRUE(solve_icp_step(sys, xi));
  EXPECT_LT(xi.norm(), 1e-5);
}

// One pair by hand: a source point 3 m in front of the camera and its model point on a plane facing
// it, r metres behind. With noise weighting the pair's weight is s² with s = σ_n(1 m) / σ_n(3 m)
// = 0.001884 / 0.014044, and Huber sees r s instead of r.
kernel::IcpSystem one_pair(float r, bool weighting, float model_sigma = 0.0f,
                           const Eigen::Vector3f& src_normal = Eigen::Vector3f(0, 0, -1)) {
  IcpParams params;
  params.noise_weighting = weighting;
  params.model_sigma_m = model_sigma;
  Image<Eigen::Vector3f> src_v(1, 1, Eigen::Vector3f(0, 0, 3)), src_n(1, 1, src_normal);
  Image<Eigen::Vector3f> mod_v(1, 1, Eigen::Vector3f(0, 0, 3 + r)), mod_n(1, 1, Eigen::Vector3f(0, 0, -1));
  const VertexNormalMaps source{DeviceImage<Eigen::Vector3f>::from_host(src_v, Device::cpu()),
                                DeviceImage<Eigen::Vector3f>::from_host(src_n, Device::cpu())};
  const DeviceImage<Eigen::Vector3f> mv = DeviceImage<Eigen::Vector3f>::from_host(mod_v, Device::cpu());
  const DeviceImage<Eigen::Vector3f> mn = DeviceImage<Eigen::Vector3f>::from_host(mod_n, Device::cpu());
  Intrinsics K;
  K.width = K.height = 1;
  K.fx = K.fy = 1.0f;
  K.cx = K.cy = 0.0f;
  return reduce_icp_system(source, IcpModel{&mv, &mn, K, Eigen::Isometry3f::Identity()}, Eigen::Isometry3f::Identity(), params);
}

TEST(Icp, NoiseWeightingScalesAPairByTheSensorNoiseAtItsDepth) {
  const DepthNoiseModel noise;
  const double s = double(noise.sigma(1.0f)) / double(noise.sigma(3.0f));
  ASSERT_NEAR(s, 0.001884 / 0.014044, 1e-5);
  // Inside Huber's quadratic zone: weight 1 without, s² with. J = [m, p × m] with m = (0, 0, −1)
  // and p × m = 0: the only entries are J_z = −1, so Σ w JᵀJ is w at (2, 2), jtj[11] of the
  // row-major upper triangle, and Σ w Jᵀr is −w r at index 2 (r = (p − q)·m = the offset).
  const kernel::IcpSystem off = one_pair(0.002f, false), on = one_pair(0.002f, true);
  ASSERT_EQ(off.inliers, 1.0);
  ASSERT_EQ(on.inliers, 1.0);
  EXPECT_NEAR(off.jtj[11], 1.0, 1e-6);
  EXPECT_NEAR(on.jtj[11], s * s, 1e-6);
  EXPECT_NEAR(off.jtr[2], -0.002, 1e-7);
  EXPECT_NEAR(on.jtr[2], -s * s * 0.002, 1e-7);
  EXPECT_NEAR(on.r2, 0.002 * 0.002, 1e-9);        // the RMSE stays in metres
  EXPECT_NEAR(on.r2_ref, (0.002 * s) * (0.002 * s), 1e-10);
  // Past Huber's threshold (r = 9 cm, r s = 1.2 cm > δ): δ / r without, s δ / r with.
  const kernel::IcpSystem off9 = one_pair(0.09f, false), on9 = one_pair(0.09f, true);
  EXPECT_NEAR(off9.jtj[11], 0.01 / 0.09, 1e-5);
  EXPECT_NEAR(on9.jtj[11], s * 0.01 / 0.09, 1e-5);
  // A residual of 5 cm at 3 m is 6.7 mm at the reference noise: still quadratic with weighting.
  EXPECT_NEAR(one_pair(0.05f, true).jtj[11], s * s, 1e-6);
  EXPECT_NEAR(one_pair(0.05f, false).jtj[11], 0.01 / 0.05, 1e-5);
}

// The tracking state's measure: a pair agrees with the model when |r| <= max(δ, 3 σ_n(z)),
// 4.2 cm at 3 m, whatever its normals; the solver's inliers pass the normal test instead, whatever
// their residual within max_distance.
TEST(Icp, AgreementCountsThePairsTheNoiseExplainsWhateverTheirNormals) {
  const DepthNoiseModel noise;
  ASSERT_NEAR(3.0 * noise.sigma(3.0f), 0.0421, 1e-4);
  const Eigen::Vector3f tilted = Eigen::Vector3f(0, 1, -1).normalized();  // 45°: fails the 30° test
  for (const bool weighting : {false, true}) {
    SCOPED_TRACE(weighting ? "noise weighting" : "no weighting");
    const kernel::IcpSystem close = one_pair(0.03f, weighting), far = one_pair(0.05f, weighting);
    const kernel::IcpSystem close_tilted = one_pair(0.03f, weighting, 0.0f, tilted);
    EXPECT_EQ(close.agree, 1.0);
    EXPECT_EQ(close.inliers, 1.0);
    EXPECT_EQ(far.agree, 0.0);  // 5 cm > 4.2 cm
    EXPECT_EQ(far.inliers, 1.0);
    EXPECT_EQ(close_tilted.agree, 1.0);
    EXPECT_EQ(close_tilted.inliers, 0.0);
    EXPECT_EQ(close_tilted.valid, 1.0);
    EXPECT_EQ(one_pair(0.15f, weighting).agree, 0.0);  // beyond max_distance: no pair at all
  }
}

// With a model term σ_m the pair's scale is s = sqrt(σ_n(1 m)² + σ_m²) / sqrt(σ_n(3 m)² + σ_m²):
// 4 mm lifts the 3 m pair's weight from 0.018 to 0.12 of a 1 m pair's.
TEST(Icp, AModelTermAddsToTheSensorNoiseInQuadrature) {
  const DepthNoiseModel noise;
  const double a = noise.sigma(1.0f), b = noise.sigma(3.0f), m = 0.004;
  const double s = std::sqrt(a * a + m * m) / std::sqrt(b * b + m * m);
  const kernel::IcpSystem on = one_pair(0.002f, true, 0.004f);
  ASSERT_EQ(on.inliers, 1.0);
  EXPECT_NEAR(on.jtj[11], s * s, 1e-6);
  EXPECT_GT(s * s, 5.0 * (a / b) * (a / b));
  EXPECT_NEAR(on.jtr[2], -s * s * 0.002, 1e-7);
  EXPECT_NEAR(on.r2_ref, (0.002 * s) * (0.002 * s), 1e-10);
  // 0 is the sensor's noise alone, bit for bit; without noise weighting the term does nothing.
  const kernel::IcpSystem zero = one_pair(0.002f, true, 0.0f), plain = one_pair(0.002f, true);
  EXPECT_EQ(zero.jtj[11], plain.jtj[11]);
  EXPECT_EQ(one_pair(0.002f, false, 0.004f).jtj[11], one_pair(0.002f, false).jtj[11]);
}

TEST(Icp, RejectsModelOnAnotherDeviceOrWrongSize) {
  const Scene s;
  const DeviceModel model = upload_model(s.model, Device::cpu());
  const FramePyramid pyr = build_pyramid(DeviceImage<float>::from_host(s.frame.depth, Device::cpu()), s.K, no_filter());
  IcpModel bad = model.view(test::test_intrinsics(80, 60), s.T_ref);
  EXPECT_THROW(reduce_icp_system(pyr.levels[0].maps, bad, s.T_ref, IcpParams{}), std::invalid_argument);
  IcpModel none;
  EXPECT_THROW(reduce_icp_system(pyr.levels[0].maps, none, s.T_ref, IcpParams{}), std::invalid_argument);
}

// The reduced 6x6 system (21 + 6 + 4 numbers: JᵀJ, Jᵀr, r2, r2_ref, inliers, valid) at a perturbed
// pose, on every device.
std::vector<double> reduced_system(const Device& device, const IcpParams& params) {
  const Scene s;
  const DeviceModel model = upload_model(s.model, device);
  // Bilateral off: its expf rounds differently on the GPU, and a few ulps there flip the pyramid's
  // discontinuity test for some pixels at levels 1-2, which is not what this test is about (the
  // filter's own parity is Preprocess.PyramidDeviceParity). The pyramid itself runs on the device.
  const FramePyramid pyr = build_pyramid(DeviceImage<float>::from_host(s.frame.depth, device), s.K, no_filter());
  std::vector<double> out;
  for (const PyramidLevel& level : pyr.levels) {
    const kernel::IcpSystem sys = reduce_icp_system(level.maps, model.view(s.K, s.T_ref), s.T_ref, params);
    out.insert(out.end(), sys.jtj, sys.jtj + 21);
    out.insert(out.end(), sys.jtr, sys.jtr + 6);
    out.push_back(sys.r2);
    out.push_back(sys.r2_ref);  // the ORB prior's σ (noise weighting, on by default)
    out.push_back(sys.inliers);
    out.push_back(sys.valid);
    out.push_back(sys.agree);
  }
  return out;
}

std::vector<double> default_system(const Device& device) { return reduced_system(device, IcpParams{}); }

TEST(Icp, ReducedSystemWithAModelTermDeviceParity) {
  IcpParams params;
  params.model_sigma_m = 0.004f;
  const std::vector<double> cpu = test::expect_device_parity<double>(
      [&](const Device& d) { return reduced_system(d, params); }, 1e-4, 1e-4);
  const std::vector<double> plain = default_system(Device::cpu());
  ASSERT_EQ(cpu.size(), plain.size());
  EXPECT_NE(cpu[11], plain[11]) << "the term changed no weight";
}

TEST(Icp, ReducedSystemDeviceParity) {
  const std::vector<double> cpu = test::expect_device_parity<double>(default_system, 1e-4, 1e-4);
  ASSERT_EQ(cpu.size(), 96u);
  EXPECT_GT(cpu[30], 1000.0);  // level 0 has thousands of valid pixels
  EXPECT_GT(cpu[29], 100.0);   // and inliers
  EXPECT_GT(cpu[31], 100.0);   // and pairs agreeing with the model (the frame is off T_ref: fewer)
  EXPECT_GT(cpu[28], 0.0);     // r2_ref: weighted residuals
  EXPECT_NE(cpu[28], cpu[27]); // scaled to the reference depth's noise, not r2 itself
}

// What the reduced system is for: the Gauss-Newton step ξ it solves to, per level, on every
// device. The association rounds û with exactly rounded operations (icp_device.h) so the sums
// should match bit for bit up to summation order; if a pixel still lands on the other side of a
// rounding tie, it pairs with the neighbouring model pixel on the same surface and moves ξ by a
// fraction ~1/N of a pixel footprint. The tolerance is ICP's convergence threshold (1e-4 m and
// 1e-4 rad): differences below the step at which ICP stops iterating cannot change its result.
std::vector<double> solved_steps(const Device& device) {
  const Scene s;
  const DeviceModel model = upload_model(s.model, device);
  const FramePyramid pyr = build_pyramid(DeviceImage<float>::from_host(s.frame.depth, device), s.K, no_filter());
  std::vector<double> out;
  for (const PyramidLevel& level : pyr.levels) {
    const kernel::IcpSystem sys = reduce_icp_system(level.maps, model.view(s.K, s.T_ref), s.T_ref, IcpParams{});
    Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
    EXPECT_TRUE(solve_icp_step(sys, xi));
    out.insert(out.end(), xi.data(), xi.data() + 6);
  }
  return out;
}

TEST(Icp, SolvedStepDeviceParity) {
  const IcpParams defaults;
  const std::vector<double> cpu = test::expect_device_parity<double>(solved_steps, defaults.converge_translation_m);
  ASSERT_EQ(cpu.size(), 18u);
  // The step is a real one (the frame is 4.4 cm / 2° away), far above the tolerance.
  const Eigen::Map<const Eigen::Matrix<double, 6, 1>> level0(cpu.data());
  EXPECT_GT(level0.norm(), 0.01);
}

}  // namespace
}  // namespace rrg
