// Whole-frame properties of the presets: thread-count determinism, reflective fractions,
// label / plane images consistent with the plane equations, the depth noise model.
#include "core/synth/depth_noise.h"
#include "core/synth/presets.h"
#include "core/synth/renderer.h"
#include "core/synth/scene_builder.h"
#include "core/synth/sequence.h"

#include <gtest/gtest.h>

#include <cstring>

namespace rrg::synth {
namespace {

template <class T>
bool same_bytes(const Image<T>& a, const Image<T>& b) {
  return a.same_size(b) && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

struct PresetFixture {
  SceneSpec spec;
  CameraPath path;
  explicit PresetFixture(const std::string& name) : spec(make_preset(name, 0)), path(make_camera_path(spec)) {}
  Eigen::Isometry3f pose(double fraction) const { return path.pose_at(fraction * path.length()).cast<float>(); }
};

TEST(Render, BitIdenticalForAnyThreadCount) {
  const PresetFixture f("living_room");
  const Intrinsics K = default_intrinsics(96, 72);
  RenderParams p1, p2, p3;
  p1.threads = 1;
  p2.threads = 2;
  p3.threads = 3;
  for (double at : {0.1, 0.55}) {
    const RenderOutput a = render_view(f.spec.scene, K, f.pose(at), p1);
    const RenderOutput b = render_view(f.spec.scene, K, f.pose(at), p2);
    const RenderOutput c = render_view(f.spec.scene, K, f.pose(at), p3);
    EXPECT_TRUE(same_bytes(a.color, b.color) && same_bytes(a.color, c.color));
    EXPECT_TRUE(same_bytes(a.depth, b.depth) && same_bytes(a.depth, c.depth));
    EXPECT_TRUE(same_bytes(a.labels, b.labels) && same_bytes(a.planes, c.planes));
    EXPECT_TRUE(same_bytes(a.reflective, c.reflective));
  }
}

TEST(Render, ReflectiveFractionPerPreset) {
  const Intrinsics K = default_intrinsics(64, 48);
  for (const PresetInfo& info : preset_list()) {
    const PresetFixture f(info.name);
    size_t reflective = 0, total = 0, hit = 0;
    for (int i = 0; i < 6; ++i) {
      const RenderOutput out = render_view(f.spec.scene, K, f.pose(i / 6.0));
      for (size_t k = 0; k < out.reflective.size(); ++k) {
        reflective += out.reflective[k];
        hit += out.depth[k] > 0.0f;
        ++total;
      }
    }
    EXPECT_EQ(hit, total) << info.name << ": a closed room covers every pixel";
    const double frac = double(reflective) / double(total);
    if (info.name == "office") {
      EXPECT_EQ(reflective, 0u) << "office is the matte control";
    } else {
      EXPECT_GT(frac, 0.15) << info.name << " should have a substantial reflective fraction";
    }
  }
}

TEST(Render, MirrorRoomSeesTheMirrorAndItsDepthIsTheSurface) {
  const PresetFixture f("mirror_room");
  const Intrinsics K = default_intrinsics(64, 48);
  const RenderOutput out = render_view(f.spec.scene, K, f.pose(0.0));  // first waypoint faces the mirror
  size_t mirror = 0;
  for (size_t k = 0; k < out.labels.size(); ++k) mirror += out.labels[k] == uint16_t(Category::Mirror);
  EXPECT_GT(mirror, out.labels.size() / 4);
}

// Every pixel with a plane id, unprojected with its depth and pose, lies on that plane (1 mm), and
// its semantic label is the plane's category.
TEST(Render, PlaneIdsAndLabelsAgreeWithPlaneEquations) {
  const Intrinsics K = default_intrinsics(80, 60);
  for (const PresetInfo& info : preset_list()) {
    const PresetFixture f(info.name);
    size_t planar = 0, curved = 0;
    for (double at : {0.05, 0.38, 0.71}) {
      const Eigen::Isometry3f T = f.pose(at);
      const RenderOutput out = render_view(f.spec.scene, K, T);
      for (int v = 0; v < K.height; ++v)
        for (int u = 0; u < K.width; ++u) {
          const uint16_t id = out.planes(u, v);
          if (id == 0) {
            ++curved;
            continue;
          }
          ++planar;
          ASSERT_LE(id, f.spec.scene.planes().size());
          const PlaneInfo& pl = f.spec.scene.planes()[id - 1u];
          const Eigen::Vector3f x = T * K.unproject(float(u), float(v), out.depth(u, v));
          ASSERT_LT(std::abs(pl.normal.dot(x) + pl.offset), 1e-3f) << info.name << " pixel " << u << "," << v
                                                                  << " plane " << pl.name;
          ASSERT_EQ(out.labels(u, v), uint16_t(pl.category)) << pl.name;
          ASSERT_EQ(out.reflective(u, v), pl.reflective ? 1 : 0) << pl.name;
        }
    }
    EXPECT_GT(planar, 10 * curved) << info.name << ": rooms are mostly planar";
  }
}

TEST(DepthNoise, KinectSigmaStatisticsAndDeterminism) {
  EXPECT_FLOAT_EQ(kinect_sigma(0.4f), 0.0012f);
  EXPECT_NEAR(kinect_sigma(2.0f), 0.0012f + 0.0019f * 2.56f, 1e-7f);
  SceneBuilder b("n", "", 0);
  b.material("matte", Texture{});
  b.material("mirror", Texture{}, 0.9f);
  const Scene scene = b.finish();
  DepthImage depth(200, 100, 2.0f);
  Image<uint16_t> material(200, 100, 1);
  DepthNoiseParams p;
  p.gaussian = true;
  DepthImage a = depth, c = depth;
  apply_depth_noise(a, material, scene, p, 3, 0);
  apply_depth_noise(c, material, scene, p, 3, 0);
  EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size() * sizeof(float)), 0) << "deterministic";
  DepthImage other = depth;
  apply_depth_noise(other, material, scene, p, 4, 0);
  EXPECT_NE(std::memcmp(a.data(), other.data(), a.size() * sizeof(float)), 0) << "another frame, other noise";
  double m = 0.0, s = 0.0;
  for (float z : a.pixels()) m += z;
  m /= double(a.size());
  for (float z : a.pixels()) s += (z - m) * (z - m);
  s = std::sqrt(s / double(a.size()));
  EXPECT_NEAR(m, 2.0, 3e-4);
  EXPECT_NEAR(s, kinect_sigma(2.0f), 0.1 * kinect_sigma(2.0f));

  // Mirrors invalid, edges dropped (about half of the pixels next to a 1 m step).
  for (int v = 0; v < 100; ++v)
    for (int u = 0; u < 200; ++u) {
      depth(u, v) = u < 100 ? 1.0f : 2.0f;
      material(u, v) = v < 50 ? 1 : 2;
    }
  DepthNoiseParams q;
  q.invalid_on_mirrors = true;
  q.edge_dropout = true;
  DepthImage d = depth;
  apply_depth_noise(d, material, scene, q, 0, 0);
  int dropped = 0;
  for (int v = 0; v < 100; ++v)
    for (int u = 0; u < 200; ++u) {
      if (v >= 50) ASSERT_EQ(d(u, v), 0.0f) << "mirror pixel";
      else if (u == 99 || u == 100) dropped += d(u, v) == 0.0f;
      else ASSERT_EQ(d(u, v), depth(u, v)) << "away from edges nothing changes";
    }
  EXPECT_GT(dropped, 25);
  EXPECT_LT(dropped, 75);
}

}  // namespace
}  // namespace rrg::synth
