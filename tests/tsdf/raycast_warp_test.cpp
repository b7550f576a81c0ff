// warp_plane_ids (raycast_warp.h): a raycast's plane-id map moved to another camera. Known answers
// on hand-made sources (nearest hit wins, footprint of a point between pixel centres), the same
// pose gives the source back, and one frame's motion agrees with a raycast at the new pose but
// for a pixel at the edges of the planes.
#include "core/tsdf/raycast_warp.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_raycast.h"
#include "tests/tsdf/analytic_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rrg {
namespace {

// A source raycast of n hits (depth > 0) at world points `p` with ids `ids`, as a 1-row image.
RaycastResult hand_source(const std::vector<Eigen::Vector3f>& p, const std::vector<int32_t>& ids,
                          const Device& device) {
  const int n = int(p.size());
  Image<float> depth(n, 1);
  Image<Eigen::Vector3f> vertices(n, 1);
  Image<int32_t> I(n, 1);
  for (int i = 0; i < n; ++i) {
    depth[size_t(i)] = p[size_t(i)].z();
    vertices[size_t(i)] = p[size_t(i)];
    I[size_t(i)] = ids[size_t(i)];
  }
  RaycastResult r;
  r.depth = DeviceImage<float>::from_host(depth, device);
  r.vertices = DeviceImage<Eigen::Vector3f>::from_host(vertices, device);
  r.plane_ids = DeviceImage<int32_t>::from_host(I, device);
  return r;
}

const Intrinsics k3x3{1.0f, 1.0f, 1.0f, 1.0f, 3, 3};  // pixel (u, v) sees the direction (u − 1, v − 1, 1)

TEST(RaycastWarp, TheNearestHitWinsWhateverItsIndex) {
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    for (const bool near_first : {true, false}) {
      // Both on the ray of pixel (1, 1); the far one also once more at index 2.
      const std::vector<Eigen::Vector3f> p = near_first
          ? std::vector<Eigen::Vector3f>{{0, 0, 1}, {0, 0, 2}, {0, 0, 2}}
          : std::vector<Eigen::Vector3f>{{0, 0, 2}, {0, 0, 2}, {0, 0, 1}};
      const std::vector<int32_t> ids = near_first ? std::vector<int32_t>{9, 7, 7} : std::vector<int32_t>{7, 7, 9};
      DeviceImage<int32_t> out;
      Buffer<uint64_t> z;
      warp_plane_ids(hand_source(p, ids, device), k3x3, Eigen::Isometry3f::Identity(), out, z);
      const Image<int32_t> I = out.to_host();
      for (int v = 0; v < 3; ++v)
        for (int u = 0; u < 3; ++u) EXPECT_EQ(I(u, v), u == 1 && v == 1 ? 9 : 0) << u << "," << v;
    }
  }
}

TEST(RaycastWarp, APointBetweenPixelCentresReachesTheCentresWithinOnePixel) {
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    DeviceImage<int32_t> out;
    Buffer<uint64_t> z;
    // (0.5, 0, 1) projects to (1.5, 1): pixels (1, 1) and (2, 1). (−0.5, −0.5, 1) to (0.5, 0.5):
    // the four pixels (0..1, 0..1). Both reach (1, 1) at the same depth; the lower index wins.
    warp_plane_ids(hand_source({{0.5f, 0, 1}, {-0.5f, -0.5f, 1}}, {4, 5}, device), k3x3, Eigen::Isometry3f::Identity(),
                   out, z);
    const Image<int32_t> I = out.to_host();
    const int expected[3][3] = {{5, 5, 0}, {5, 4, 4}, {0, 0, 0}};  // [v][u]
    for (int v = 0; v < 3; ++v)
      for (int u = 0; u < 3; ++u) EXPECT_EQ(I(u, v), expected[v][u]) << u << "," << v;
    // A point behind the camera or off the image writes nothing.
    warp_plane_ids(hand_source({{0, 0, -1}, {5, 0, 1}}, {4, 5}, device), k3x3, Eigen::Isometry3f::Identity(), out, z);
    const Image<int32_t> none = out.to_host();
    EXPECT_TRUE(std::all_of(none.data(), none.data() + none.size(), [](int32_t i) { return i == 0; }));
  }
}

TEST(RaycastWarp, ASourceWithoutVerticesOrPlaneIdsIsRejected) {
  const RaycastResult empty;
  DeviceImage<int32_t> out;
  Buffer<uint64_t> z;
  EXPECT_THROW(warp_plane_ids(empty, k3x3, Eigen::Isometry3f::Identity(), out, z), std::invalid_argument);
  RaycastResult no_ids = hand_source({{0, 0, 1}}, {1}, Device::cpu());
  no_ids.plane_ids = DeviceImage<int32_t>();
  EXPECT_THROW(warp_plane_ids(no_ids, k3x3, Eigen::Isometry3f::Identity(), out, z), std::invalid_argument);
  EXPECT_THROW(warp_plane_ids(hand_source({{0, 0, 1}}, {1}, Device::cpu()), Intrinsics{}, Eigen::Isometry3f::Identity(),
                              out, z),
               std::invalid_argument);
}

// A floor (id 1) and a wall (id 2) behind a sphere (id 0), fused with their plane ids from a few
// views, then raycast at T0 and at T1 (2 cm and 1.5° away, more than a frame of hand-held motion
// at 30 Hz): the warp of T0's map to T1 against T1's raycast.
constexpr float kFloorY = 0.5f, kWallZ = 2.0f;

test::Scene room() {
  test::Scene s;
  s.primitives.push_back({test::Primitive::Plane, {0, -1, 0}, {-kFloorY, 0, 0}});  // y <= 0.5 free (y down)
  s.primitives.push_back({test::Primitive::Plane, {0, 0, -1}, {-kWallZ, 0, 0}});   // z <= 2 free
  s.primitives.push_back({test::Primitive::Sphere, {0.1f, 0.25f, 1.4f}, {0.2f, 0, 0}});
  return s;
}

Image<int32_t> true_ids(const DepthImage& depth, const Intrinsics& K, const Eigen::Isometry3f& T) {
  Image<int32_t> ids(K.width, K.height, 0);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      if (!(depth(u, v) > 0)) continue;
      const Eigen::Vector3f p = T * K.unproject(float(u), float(v), depth(u, v));
      if (std::abs(p.y() - kFloorY) < 1e-3f) ids(u, v) = 1;
      else if (std::abs(p.z() - kWallZ) < 1e-3f) ids(u, v) = 2;
    }
  return ids;
}

TEST(RaycastWarp, OneFramesMotionAgreesWithARaycastButAtThePlanesEdges) {
  const Intrinsics K{120.0f, 120.0f, 79.5f, 59.5f, 160, 120};
  const test::Scene scene = room();
  const Eigen::Isometry3f T0 = test::look_at({0, 0, 0}, {0, 0.3f, 2.0f});
  Eigen::Isometry3f T1 = T0;
  T1.translate(Eigen::Vector3f(0.02f, -0.005f, 0.01f));
  T1.rotate(Eigen::AngleAxisf(1.5f * float(M_PI) / 180.0f, Eigen::Vector3f(0.3f, 1.0f, 0.1f).normalized()));
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    TsdfParams params;
    params.voxel_size = 0.01f;
    params.truncation = 0.04f;
    params.max_depth = 4.0f;
    TsdfVolume volume(params, device);
    for (const Eigen::Vector3f eye : {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0.1f, -0.05f, 0.05f),
                                      Eigen::Vector3f(-0.1f, 0.02f, -0.05f), Eigen::Vector3f(0.03f, 0.05f, 0.1f)}) {
      const Eigen::Isometry3f T = test::look_at(eye, {0, 0.3f, 2.0f});
      const DepthImage depth = scene.render_depth(K, T);
      const auto d = DeviceImage<float>::from_host(depth, device);
      const auto c = DeviceImage<Color>::from_host(ColorImage(K.width, K.height, Color(0.5f, 0.5f, 0.5f)), device);
      const auto ids = DeviceImage<int32_t>::from_host(true_ids(depth, K, T), device);
      const auto mask = DeviceImage<uint8_t>::from_host(MaskImage(K.width, K.height, 0), device);
      const ReflectionObservation obs{&ids, &mask, {}};
      integrate(volume, d, c, K, T, &obs);
    }
    const RaycastOutputs outputs{.color = false, .reflection = true, .normals = true};
    const RaycastResult at0 = raycast(volume, K, T0, {}, outputs);
    const RaycastResult at1 = raycast(volume, K, T1, {}, outputs);
    DeviceImage<int32_t> warped;
    Buffer<uint64_t> z;

    // The same camera: the source's map, pixel for pixel.
    warp_plane_ids(at0, K, T0, warped, z);
    const Image<int32_t> same = warped.to_host(), I0 = at0.plane_ids.to_host();
    EXPECT_TRUE(std::equal(same.data(), same.data() + same.size(), I0.data()));
    int64_t floor = 0, wall = 0;
    for (const int32_t i : I0.pixels()) floor += i == 1, wall += i == 2;
    EXPECT_GT(floor, 2000);
    EXPECT_GT(wall, 2000);

    // T1, from an exact source (the analytic depth, points and ids at T0; no voxel's nearest id
    // in the way): where the warp and the exact ids at T1 differ, the warp is a pixel off at an
    // edge (an exact pixel of the warped id among the 3 x 3 around), or T0 did not see T1's
    // point (outside T0's image or behind a nearer surface there). Few pixels either way.
    RaycastResult exact0;
    {
      const DepthImage d0 = scene.render_depth(K, T0);
      Image<Eigen::Vector3f> p0(K.width, K.height, Eigen::Vector3f::Zero());
      for (int v = 0; v < K.height; ++v)
        for (int u = 0; u < K.width; ++u)
          if (d0(u, v) > 0) p0(u, v) = T0 * K.unproject(float(u), float(v), d0(u, v));
      exact0.depth = DeviceImage<float>::from_host(d0, device);
      exact0.vertices = DeviceImage<Eigen::Vector3f>::from_host(p0, device);
      exact0.plane_ids = DeviceImage<int32_t>::from_host(true_ids(d0, K, T0), device);
    }
    warp_plane_ids(exact0, K, T1, warped, z);
    const Image<int32_t> W = warped.to_host();
    const DepthImage d0 = scene.render_depth(K, T0), d1 = scene.render_depth(K, T1);
    const Image<int32_t> I1 = true_ids(d1, K, T1), E0 = true_ids(d0, K, T0);
    // Pixels seen from T0 where `map` differs from the exact ids at T1, and those of them with no
    // exact pixel of their id among the 3 x 3 around.
    const auto misplaced = [&](const Image<int32_t>& map, int64_t& off_by_more) {
      int64_t n = 0;
      off_by_more = 0;
      for (int v = 0; v < K.height; ++v)
        for (int u = 0; u < K.width; ++u) {
          if (map(u, v) == I1(u, v)) continue;
          if (d1(u, v) > 0) {  // T1's point hidden from T0?
            const Eigen::Vector3f q = T0.inverse() * (T1 * K.unproject(float(u), float(v), d1(u, v)));
            const Eigen::Vector2f uv = K.project(q);
            const int x = int(std::lround(uv.x())), y = int(std::lround(uv.y()));
            if (q.z() <= 0 || x < 0 || y < 0 || x >= K.width || y >= K.height || d0(x, y) < q.z() - 0.01f) continue;
          }
          ++n;
          bool near = false;
          for (int dv = -1; dv <= 1; ++dv)
            for (int du = -1; du <= 1; ++du)
              near = near || (u + du >= 0 && v + dv >= 0 && u + du < K.width && v + dv < K.height &&
                              I1(u + du, v + dv) == map(u, v));
          off_by_more += near ? 0 : 1;
        }
      return n;
    };
    int64_t warp_far = 0, still_far = 0;
    const int64_t warp_off = misplaced(W, warp_far), still_off = misplaced(E0, still_far);
    EXPECT_EQ(warp_far, 0);
    EXPECT_LT(double(warp_off) / double(K.width * K.height), 0.002) << warp_off;
    // The motion is large enough to tell: T0's own map is off at T1 by more than a pixel.
    EXPECT_GT(still_off, 10 * std::max<int64_t>(warp_off, 1));
    EXPECT_GT(still_far, 100);
  }
}

}  // namespace
}  // namespace rrg
