// ViewFrustum: the blocks a raycast may read. Known answers on an axis-aligned camera, and the
// property streaming relies on: a raycast with only the frustum's blocks resident is the raycast
// of the whole volume, bit for bit.
#include "core/common/device.h"
#include "core/tsdf/tsdf_raycast.h"
#include "core/tsdf/view_frustum.h"
#include "tests/tsdf/analytic_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace rrg {
namespace {

const Intrinsics kK{100.0f, 100.0f, 79.5f, 59.5f, 160, 120};

TsdfParams params() {
  TsdfParams p;
  p.voxel_size = 0.02f;
  p.truncation = 0.08f;
  p.min_depth = 0.1f;
  p.max_depth = 3.0f;
  return p;
}

// The block holding world point p.
Eigen::Vector3i block_at(const Eigen::Vector3f& p, float voxel) {
  return (p / (voxel * kBlockSide)).array().floor().cast<int>();
}

TEST(ViewFrustum, KeepsTheBlocksInViewAndTheMarginAroundIt) {
  const TsdfParams p = params();
  const ViewFrustum f(kK, Eigen::Isometry3f::Identity(), p);  // looking along +z
  const float s = p.voxel_size, block = s * kBlockSide;
  // margin: half the block diagonal + 3 voxels = 0.199 m at 2 cm voxels
  const float margin = (0.5f * std::sqrt(3.0f) * kBlockSide + 3.0f) * s;
  EXPECT_TRUE(f.may_read(block_at({0, 0, 1}, s)));
  EXPECT_TRUE(f.may_read(block_at({0, 0, 2.9f}, s)));
  EXPECT_FALSE(f.may_read(block_at({0, 0, -1}, s))) << "behind the camera";
  EXPECT_FALSE(f.may_read(block_at({0, 0, 3.0f + margin + block}, s))) << "beyond max_depth";
  EXPECT_TRUE(f.may_read(block_at({0, 0, 3.0f + 0.5f * margin - block}, s)));
  // The right image edge at z = 2 m: x = 2 (159.5 − 79.5) / 100 = 1.6 m.
  EXPECT_TRUE(f.may_read(block_at({1.55f, 0, 2}, s)));
  EXPECT_FALSE(f.may_read(block_at({1.6f + 1.2f * margin + block, 0, 2}, s)));
  EXPECT_FALSE(f.may_read(block_at({0, -1.2f - 1.2f * margin - block, 2}, s))) << "above the top edge";
  // Turned: the camera looking along −x (R maps camera z to world −x).
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::AngleAxisf(-0.5f * float(M_PI), Eigen::Vector3f::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3f(5, 0, 0);
  const ViewFrustum g(kK, T, p);
  ASSERT_TRUE((T.linear() * Eigen::Vector3f::UnitZ()).isApprox(-Eigen::Vector3f::UnitX()));
  EXPECT_TRUE(g.may_read(block_at({4, 0, 0}, s)));
  EXPECT_FALSE(g.may_read(block_at({6, 0, 0}, s)));
  EXPECT_FALSE(g.may_read(block_at({0, 0, 1}, s)));
}

template <class T>
bool same(const DeviceImage<T>& a, const DeviceImage<T>& b) {
  const Image<T> x = a.to_host(), y = b.to_host();
  return x.width() == y.width() && x.height() == y.height() &&
         std::memcmp(x.data(), y.data(), x.size() * sizeof(T)) == 0;
}

TEST(ViewFrustum, ARaycastWithOnlyItsBlocksResidentIsTheWholeVolumesRaycast) {
  const TsdfParams p = params();
  // Spheres all around the origin, fused from there in 8 directions.
  test::Scene scene;
  for (int k = 0; k < 6; ++k) {
    const float a = float(k) * float(M_PI) / 3.0f;
    scene.primitives.push_back({test::Primitive::Sphere, Eigen::Vector3f(1.5f * std::cos(a), 0.2f * float(k % 2), 1.5f * std::sin(a)),
                                Eigen::Vector3f(0.4f, 0, 0)});
  }
  std::vector<Eigen::Isometry3f> poses;
  for (int k = 0; k < 8; ++k) {
    const float a = float(k) * float(M_PI) / 4.0f;
    poses.push_back(test::look_at(Eigen::Vector3f::Zero(), Eigen::Vector3f(std::cos(a), 0.1f, std::sin(a))));
  }
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    TsdfVolume whole(p, device), part(p, device);
    test::fuse_scene(whole, scene, kK, poses);
    test::fuse_scene(part, scene, kK, poses);
    ASSERT_GT(whole.num_blocks(), 300);
    // The views: the fusion's, moved and tilted ones, and a wider, coarser camera.
    std::vector<std::pair<Intrinsics, Eigen::Isometry3f>> views;
    for (const auto& T : poses) views.emplace_back(kK, T);
    views.emplace_back(kK, test::look_at({0.3f, -0.2f, 0.1f}, {1.5f, 0.3f, 0.4f}));
    views.emplace_back(kK, test::look_at({-0.4f, 0.1f, 0.2f}, {-1.0f, 0.0f, -1.6f}));
    views.emplace_back(Intrinsics{30.0f, 30.0f, 39.5f, 29.5f, 80, 60}, test::look_at({0, 0, 0}, {0.2f, 0.0f, 1.0f}));
    int64_t left_out = 0;
    for (const auto& [K, T] : views) {
      part.stream_in_all();
      const ViewFrustum f(K, T, p);
      std::vector<Eigen::Vector3i> out;
      for (const Eigen::Vector3i& b : part.block_coords())
        if (!f.may_read(b)) out.push_back(b);
      part.stream_out(out);
      left_out += int64_t(out.size());
      const RaycastResult a = raycast(whole, K, T), b = raycast(part, K, T);
      const Image<float> depth = a.depth.to_host();
      int hits = 0;
      for (float d : depth.pixels()) hits += d > 0 ? 1 : 0;
      EXPECT_GT(hits, 100);
      EXPECT_TRUE(same(a.depth, b.depth));
      EXPECT_TRUE(same(a.vertices, b.vertices));
      EXPECT_TRUE(same(a.normals, b.normals));
      EXPECT_TRUE(same(a.colors, b.colors));
      EXPECT_TRUE(same(a.plane_ids, b.plane_ids));
      EXPECT_TRUE(same(a.reflection, b.reflection));
      EXPECT_TRUE(same(a.color_variance, b.color_variance));
    }
    // The frustum is not the whole volume: most views leave out most blocks.
    EXPECT_GT(left_out, int64_t(views.size()) * whole.num_blocks() / 3);
  }
}

}  // namespace
}  // namespace rrg
