// Known-answer geometry: analytic ray-primitive hits, z-depth of a wall, a mirror floor showing an
// object where mirror geometry puts it, and the BVH against brute force.
#include "core/synth/presets.h"
#include "core/synth/renderer.h"
#include "core/synth/scene_builder.h"
#include "tests/synth/synth_test_util.h"

#include <gtest/gtest.h>

#include <random>

namespace rrg::synth {
namespace {

using Eigen::Vector3f;
using test::flat;
using test::look_along;

float hit_t(const Primitive& p, const Vector3f& o, const Vector3f& d, int* face = nullptr) {
  float t = INFINITY;
  int f = -1;
  if (!intersect_primitive(p, o, d, 0.0f, t, f)) return -1.0f;
  if (face) *face = f;
  return t;
}

TEST(Intersect, AnalyticHitsOfEachPrimitive) {
  SceneBuilder b("t", "", 0);
  const auto m = b.material("m", flat(Color::Constant(0.5f)));
  const Primitive box = b.box("box", {0, 0, 0}, {2, 2, 2}, m, Category::Table);
  const Primitive rot = b.box("rot", {0, 0, 0}, {4, 1, 1}, m, Category::Table, 90.0f);  // long along y
  const Primitive sph = b.sphere("s", {0, 0, 0}, 1.5f, m, Category::Sculpture);
  const Primitive cyl = b.cylinder("c", {0, 0, -1}, 0.5f, 2.0f, m, Category::Lamp);
  const Primitive rect = b.rect("r", {0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 2.0f, 1.0f, m, Category::Rug);
  Primitive room = b.room({4, 4, 4}, m, m, m);

  int face = -1;
  EXPECT_FLOAT_EQ(hit_t(box, {-5, 0, 0}, {1, 0, 0}, &face), 4.0f);
  EXPECT_EQ(face, 0) << "-x face";
  EXPECT_FLOAT_EQ(hit_t(box, {0, 0, 7}, {0, 0, -2}, &face), 3.0f) << "non-unit direction: t in its units";
  EXPECT_EQ(face, 5) << "top face";
  EXPECT_LT(hit_t(box, {-5, 3, 0}, {1, 0, 0}), 0.0f) << "miss";
  // Rotated 90 degrees about z: 4 m long along world y, 1 m along x.
  EXPECT_FLOAT_EQ(hit_t(rot, {0, -5, 0}, {0, 1, 0}), 3.0f);
  EXPECT_FLOAT_EQ(hit_t(rot, {-5, 0, 0}, {1, 0, 0}), 4.5f);
  EXPECT_FLOAT_EQ(hit_t(sph, {0, -5, 0}, {0, 1, 0}), 3.5f);
  EXPECT_LT(hit_t(sph, {0, -5, 1.6f}, {0, 1, 0}), 0.0f);
  EXPECT_FLOAT_EQ(hit_t(cyl, {-3, 0, 0.5f}, {1, 0, 0}, &face), 2.5f);
  EXPECT_EQ(face, 0) << "curved side";
  EXPECT_FLOAT_EQ(hit_t(cyl, {0.2f, 0, 5}, {0, 0, -1}, &face), 4.0f);
  EXPECT_EQ(face, 5) << "top cap";
  EXPECT_LT(hit_t(cyl, {-3, 0, 1.5f}, {1, 0, 0}), 0.0f) << "above the cylinder";
  EXPECT_FLOAT_EQ(hit_t(rect, {0.9f, 0.4f, 2}, {0, 0, -1}), 2.0f);
  EXPECT_FLOAT_EQ(hit_t(rect, {0.9f, 0.4f, -2}, {0, 0, 1}), 2.0f) << "two-sided";
  EXPECT_LT(hit_t(rect, {0.9f, 0.6f, 2}, {0, 0, -1}), 0.0f) << "outside the 2 x 1 rectangle";
  // Room: seen from inside, the far wall; normal points into the room.
  EXPECT_FLOAT_EQ(hit_t(room, {1, 2, 2}, {1, 0, 0}, &face), 3.0f);
  EXPECT_EQ(face, 1);
  Vector3f n;
  Eigen::Vector2f uv, size;
  surface_at(room, 1, {4, 2, 2}, n, uv, size);
  EXPECT_TRUE(n.isApprox(Vector3f(-1, 0, 0)));
  surface_at(sph, 0, {0, -1.5f, 0}, n, uv, size);
  EXPECT_TRUE(n.isApprox(Vector3f(0, -1, 0)));
}

// Camera 5 m in front of a wall, looking straight at it: z-depth is exactly 5 at every pixel.
TEST(RenderGeometry, WallDepthIsAnalyticZEverywhere) {
  SceneBuilder b("wall", "", 0);
  const auto m = b.material("wall", flat(Color::Constant(0.6f)));
  b.room({6, 4, 3}, m, m, m);
  b.light({1, 2, 2.5f}, Color::Ones(), 2.0f);
  const Scene scene = b.finish();
  const Intrinsics K{200.0f, 200.0f, 31.5f, 23.5f, 64, 48};  // narrow: only the x = 6 wall in view
  for (float x0 : {1.0f, 2.5f, 4.75f}) {
    const RenderOutput out = render_view(scene, K, look_along({x0, 2.0f, 1.5f}, {1, 0, 0}));
    const float z = 6.0f - x0;
    const uint16_t wall_xp = scene.primitives[0].plane[1];
    ASSERT_EQ(scene.planes()[wall_xp - 1u].name, "wall_xp");
    for (int v = 0; v < K.height; ++v)
      for (int u = 0; u < K.width; ++u) {
        ASSERT_NEAR(out.depth(u, v), z, 4e-7f * z) << "pixel " << u << "," << v;
        ASSERT_EQ(out.labels(u, v), uint16_t(Category::Wall));
        ASSERT_EQ(out.planes(u, v), wall_xp);
        ASSERT_EQ(out.reflective(u, v), 0);
      }
  }
}

// A perfect mirror floor (F0 = 1) under a camera: the emissive red ball appears at the projection
// of its mirror image (z -> -z), while depth there is the floor's, and nowhere else is red.
TEST(RenderGeometry, MirrorFloorShowsObjectWhereMirrorGeometrySays) {
  SceneBuilder b("mirror_floor", "", 0);
  const auto black = b.material("black", flat(Color::Zero()));
  const auto mirror = b.material("mirror", flat(Color::Zero()), 1.0f, 0.0f);
  Material red;
  red.name = "red";
  red.texture = flat(Color::Zero());
  red.emission = Color(1.0f, 0.0f, 0.0f);
  const auto red_id = b.material(red);
  b.room({10, 10, 10}, mirror, black, black);
  const Vector3f ball(5.0f, 6.0f, 1.0f);
  b.sphere("ball", ball, 0.25f, red_id, Category::Sculpture);
  Scene scene = b.finish();
  scene.ambient = Color::Zero();

  const Intrinsics K{240.0f, 240.0f, 79.5f, 59.5f, 160, 120};
  const Vector3f eye(5.0f, 3.0f, 2.0f);
  const Eigen::Isometry3f T_wc = look_along(eye, Vector3f(5.2f, 6.0f, -1.0f) - eye);  // near the mirror image
  const RenderOutput out = render_view(scene, K, T_wc);

  const Vector3f virtual_ball(ball.x(), ball.y(), -ball.z());
  const Vector3f p_cam = T_wc.inverse() * virtual_ball;
  ASSERT_GT(p_cam.z(), 0.0f);
  const Eigen::Vector2f px = K.project(p_cam);
  const int u = int(std::lround(px.x())), v = int(std::lround(px.y()));
  ASSERT_TRUE(u >= 0 && u < K.width && v >= 0 && v < K.height);
  EXPECT_GT(out.color(u, v).x(), 0.5f) << "reflected red ball";
  EXPECT_LT(out.color(u, v).y(), 1e-6f);
  EXPECT_EQ(out.labels(u, v), uint16_t(Category::Floor)) << "the first surface is the floor";
  EXPECT_EQ(out.reflective(u, v), 1);
  // Depth is the floor's: the ray towards the virtual centre meets z = 0 two thirds of the way.
  const Vector3f floor_hit = eye + (virtual_ball - eye) * (eye.z() / (eye.z() - virtual_ball.z()));
  EXPECT_NEAR(out.depth(u, v), (T_wc.inverse() * floor_hit).z(), 0.01f);
  // The red blob is the mirror image's disc: centred on its projection (sub-pixel), with the area
  // of its angular radius, all on the floor; nothing else is red.
  const float radius_px = K.fx * 0.25f / p_cam.norm();
  double sx = 0.0, sy = 0.0, n = 0.0;
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x)
      if (out.color(x, y).x() > 0.1f) {
        ASSERT_EQ(out.labels(x, y), uint16_t(Category::Floor)) << "only the reflection is in view";
        sx += x;
        sy += y;
        n += 1.0;
      }
  ASSERT_GT(n, 0.0);
  EXPECT_NEAR(sx / n, px.x(), 0.5);
  EXPECT_NEAR(sy / n, px.y(), 0.5);
  const double area = 3.14159 * radius_px * radius_px;
  EXPECT_NEAR(n, area, 0.15 * area);
}

// Rough reflections are jittered by a hash of the world hit point only: the same surface point seen
// along the same line from two camera positions (two different pixels / frames) gets the same
// radiance (a jitter keyed on pixel or frame would fail this).
TEST(RenderGeometry, RoughReflectionDependsOnTheWorldPointNotTheView) {
  const SceneSpec spec = make_preset("living_room", 0);
  const RenderParams params;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  int same = 0, total = 0;
  for (int i = 0; i < 200; ++i) {
    const Vector3f floor_point(0.8f + 3.4f * U(rng), 1.0f + 2.0f * U(rng), 0.0f);
    const Vector3f eye(0.5f + 4.0f * U(rng), 0.5f + 3.0f * U(rng), 1.2f + 0.6f * U(rng));
    const Vector3f d = floor_point - eye;
    RayHit hit;
    if (!spec.scene.intersect(eye, d, 0.0f, INFINITY, hit) || hit.t < 0.999f) continue;  // occluded
    if (spec.scene.primitives[size_t(hit.prim)].category[size_t(hit.face)] != Category::Floor) continue;
    ++total;
    const Color near = trace_radiance(spec.scene, eye + 0.4f * d, 0.6f * d, params);
    const Color far = trace_radiance(spec.scene, eye, d, params);
    same += (near - far).cwiseAbs().maxCoeff() < 1e-5f;
  }
  ASSERT_GT(total, 50);
  EXPECT_GE(same, total - 1) << "view-independent jitter";
}

TEST(Bvh, MatchesBruteForceOnEveryPreset) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (const PresetInfo& info : preset_list()) {
    const SceneSpec spec = make_preset(info.name, 3);
    const Scene& scene = spec.scene;
    for (int i = 0; i < 3000; ++i) {
      const Vector3f o(0.2f + 4.6f * U(rng), 0.2f + 3.6f * U(rng), 0.1f + 2.5f * U(rng));
      const Vector3f d = Vector3f(U(rng) - 0.5f, U(rng) - 0.5f, U(rng) - 0.5f).normalized();
      RayHit hit;
      const bool found = scene.intersect(o, d, 0.0f, INFINITY, hit);
      float best = INFINITY;
      int best_prim = -1;
      for (size_t k = 0; k < scene.primitives.size(); ++k) {
        int f = 0;
        if (intersect_primitive(scene.primitives[k], o, d, 0.0f, best, f)) best_prim = int(k);
      }
      ASSERT_EQ(found, best_prim >= 0);
      if (found) {
        ASSERT_FLOAT_EQ(hit.t, best) << info.name << " ray " << i;
        // Coincident surfaces may tie; the BVH must at least report a primitive at that distance.
        if (hit.prim != best_prim) {
          float t2 = INFINITY;
          int f = 0;
          ASSERT_TRUE(intersect_primitive(scene.primitives[size_t(hit.prim)], o, d, 0.0f, t2, f));
          ASSERT_FLOAT_EQ(t2, best);
        }
        const bool occ = scene.occluded(o, d, 0.0f, best * 0.999f);
        ASSERT_FALSE(occ) << "nothing before the closest hit";
        ASSERT_TRUE(scene.occluded(o, d, 0.0f, best * 1.001f + 1e-5f));
      }
    }
  }
}

TEST(Scene, FinalizeAssignsPlanesToPlanarFacesOnlyAndRejectsBadInput) {
  SceneBuilder b("planes", "", 0);
  const auto m = b.material("m", flat(Color::Constant(0.5f)), 0.3f, 0.0f);
  b.room({5, 4, 3}, m, m, m);
  b.box("box", {1, 1, 0.5f}, {1, 1, 1}, m, Category::Table);
  b.sphere("ball", {3, 3, 1}, 0.3f, m, Category::Sculpture);
  b.cylinder("post", {3, 1, 0}, 0.1f, 1.0f, m, Category::Lamp);
  const Scene s = b.finish();
  // 6 room faces + 6 box faces + 0 sphere + 2 caps.
  ASSERT_EQ(s.planes().size(), 14u);
  for (size_t i = 0; i < s.planes().size(); ++i) {
    EXPECT_EQ(s.planes()[i].id, i + 1);
    EXPECT_TRUE(s.planes()[i].reflective);
    EXPECT_NEAR(s.planes()[i].normal.norm(), 1.0f, 1e-6f);
  }
  EXPECT_EQ(s.planes()[4].name, "floor");
  EXPECT_TRUE(s.planes()[4].normal.isApprox(Vector3f::UnitZ()));
  EXPECT_EQ(s.planes()[11].name, "box_top");
  EXPECT_NEAR(s.planes()[11].offset, -1.0f, 1e-6f) << "top at z = 1: n.x + b = 0";
  EXPECT_EQ(s.primitives[2].plane[0], 0) << "sphere: curved, no plane";
  EXPECT_EQ(s.primitives[3].plane[0], 0) << "cylinder side: curved";
  EXPECT_EQ(s.primitives[3].plane[5], 14);

  SceneBuilder bad("bad", "", 0);
  bad.material("m", flat(Color::Ones()));
  bad.box("flat", {0, 0, 0}, {1, 0, 1}, 0, Category::Table);
  try {
    bad.finish();
    FAIL() << "zero-size box accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'flat'"), std::string::npos) << e.what();
  }
  SceneBuilder bad_mat("bad", "", 0);
  bad_mat.box("b", {0, 0, 0}, {1, 1, 1}, 3, Category::Table);
  EXPECT_THROW(bad_mat.finish(), std::invalid_argument);
  SceneBuilder bad_f0("bad", "", 0);
  bad_f0.box("b", {0, 0, 0}, {1, 1, 1}, bad_f0.material("m", flat(Color::Ones()), 1.5f), Category::Table);
  EXPECT_THROW(bad_f0.finish(), std::invalid_argument);
}

}  // namespace
}  // namespace rrg::synth
