#include "core/synth/scene_builder.h"

#include "core/synth/hash.h"

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace rrg::synth {

using Eigen::Vector2f;
using Eigen::Vector3f;

namespace {
constexpr float kDeg = 3.14159265f / 180.0f;
template <class T>
std::array<T, 6> all6(T v) {
  return {v, v, v, v, v, v};
}
}  // namespace

Eigen::Matrix3f yaw_world_to_local(float yaw_deg) {
  return Eigen::AngleAxisf(yaw_deg * kDeg, Vector3f::UnitZ()).toRotationMatrix().transpose();
}

SceneBuilder::SceneBuilder(std::string name, std::string description, uint32_t seed) : seed_(seed) {
  scene_.name = std::move(name);
  scene_.description = std::move(description);
}

uint16_t SceneBuilder::material(const Material& m) {
  if (scene_.materials.size() >= 65535) throw std::invalid_argument("SceneBuilder: too many materials");
  scene_.materials.push_back(m);
  return uint16_t(scene_.materials.size() - 1);
}

uint16_t SceneBuilder::material(const std::string& name, const Texture& texture, float f0, float roughness) {
  Material m;
  m.name = name;
  m.texture = texture;
  m.f0 = f0;
  m.roughness = roughness;
  return material(m);
}

uint16_t SceneBuilder::emitter(const std::string& name, const Texture& texture, const Color& emission) {
  Material m;
  m.name = name;
  m.texture = texture;
  m.emission = emission;
  return material(m);
}

Primitive& SceneBuilder::add(Primitive p) {
  scene_.primitives.push_back(std::move(p));
  return scene_.primitives.back();
}

Primitive& SceneBuilder::room(const Vector3f& size, uint16_t floor, uint16_t walls, uint16_t ceiling) {
  Primitive p;
  p.kind = PrimitiveKind::Room;
  p.name = "room";
  p.center = size * 0.5f;
  p.half = size * 0.5f;
  p.material = {walls, walls, walls, walls, floor, ceiling};
  p.category = {Category::Wall, Category::Wall, Category::Wall, Category::Wall, Category::Floor, Category::Ceiling};
  return add(std::move(p));
}

Primitive& SceneBuilder::box(const std::string& name, const Vector3f& centre, const Vector3f& size, uint16_t mat,
                             Category cat, float yaw_deg) {
  Primitive p;
  p.kind = PrimitiveKind::Box;
  p.name = name;
  p.center = centre;
  p.half = size * 0.5f;
  p.R = yaw_world_to_local(yaw_deg);
  p.material = all6(mat);
  p.category = all6(cat);
  return add(std::move(p));
}

Primitive& SceneBuilder::box_between(const std::string& name, const Vector3f& lo, const Vector3f& hi, uint16_t mat,
                                     Category cat) {
  return box(name, (lo + hi) * 0.5f, hi - lo, mat, cat);
}

Primitive& SceneBuilder::rect(const std::string& name, const Vector3f& centre, const Vector3f& normal,
                              const Vector3f& up, float width, float height, uint16_t mat, Category cat) {
  const Vector3f n = normal.normalized();
  const Vector3f u = (up - up.dot(n) * n).normalized();
  const Vector3f right = u.cross(n);
  Primitive p;
  p.kind = PrimitiveKind::Rect;
  p.name = name;
  p.center = centre;
  p.half = {width * 0.5f, height * 0.5f, 0.0f};
  p.R.row(0) = right;
  p.R.row(1) = u;
  p.R.row(2) = n;
  p.material = all6(mat);
  p.category = all6(cat);
  return add(std::move(p));
}

Primitive& SceneBuilder::sphere(const std::string& name, const Vector3f& centre, float radius, uint16_t mat,
                                Category cat) {
  Primitive p;
  p.kind = PrimitiveKind::Sphere;
  p.name = name;
  p.center = centre;
  p.half = Vector3f::Constant(radius);
  p.material = all6(mat);
  p.category = all6(cat);
  return add(std::move(p));
}

Primitive& SceneBuilder::cylinder(const std::string& name, const Vector3f& base, float radius, float height,
                                  uint16_t mat, Category cat) {
  Primitive p;
  p.kind = PrimitiveKind::Cylinder;
  p.name = name;
  p.center = base + Vector3f(0, 0, height * 0.5f);
  p.half = {radius, radius, height * 0.5f};
  p.material = all6(mat);
  p.category = all6(cat);
  return add(std::move(p));
}

void SceneBuilder::light(const Vector3f& position, const Color& intensity, float falloff) {
  scene_.lights.push_back({position, intensity, falloff});
}

void SceneBuilder::table(const std::string& name, const Vector2f& c, const Vector3f& top, float height,
                         uint16_t top_mat, uint16_t leg_mat, Category cat, float yaw_deg) {
  box(name + "_top", {c.x(), c.y(), height - top.z() * 0.5f}, top, top_mat, cat, yaw_deg);
  const Eigen::Matrix2f rot = Eigen::Rotation2Df(yaw_deg * kDeg).toRotationMatrix();
  const float leg_r = 0.025f, inset = 0.07f;
  int k = 0;
  for (float sx : {-1.0f, 1.0f})
    for (float sy : {-1.0f, 1.0f}) {
      const Vector2f off = rot * Vector2f(sx * (top.x() * 0.5f - inset), sy * (top.y() * 0.5f - inset));
      cylinder(name + "_leg" + std::to_string(k++), {c.x() + off.x(), c.y() + off.y(), 0.0f}, leg_r,
               height - top.z(), leg_mat, cat);
    }
}

void SceneBuilder::bookshelf(const std::string& name, const Vector3f& lo, const Vector3f& hi, int shelves,
                             const Vector3f& open_dir, uint16_t board_mat, uint16_t book_mat) {
  const int depth_axis = std::abs(open_dir.x()) > 0.5f ? 0 : 1, lat = 1 - depth_axis;
  const bool open_positive = open_dir[depth_axis] > 0.0f;
  const float t = 0.025f;
  auto slab = [&](const std::string& part, float d0, float d1, float l0, float l1, float z0, float z1,
                  uint16_t mat, Category cat) {
    Vector3f a, b;
    a[depth_axis] = d0; b[depth_axis] = d1;
    a[lat] = l0; b[lat] = l1;
    a.z() = z0; b.z() = z1;
    box_between(name + "_" + part, a, b, mat, cat);
  };
  const float d_lo = lo[depth_axis], d_hi = hi[depth_axis], l_lo = lo[lat], l_hi = hi[lat];
  // Back panel on the closed side, sides, bottom/top and boards.
  if (open_positive) slab("back", d_lo, d_lo + t, l_lo, l_hi, lo.z(), hi.z(), board_mat, Category::Shelf);
  else slab("back", d_hi - t, d_hi, l_lo, l_hi, lo.z(), hi.z(), board_mat, Category::Shelf);
  slab("side0", d_lo, d_hi, l_lo, l_lo + t, lo.z(), hi.z(), board_mat, Category::Shelf);
  slab("side1", d_lo, d_hi, l_hi - t, l_hi, lo.z(), hi.z(), board_mat, Category::Shelf);
  const float step = (hi.z() - lo.z() - t) / float(shelves + 1);
  const float in0 = open_positive ? d_lo + t : d_lo + 0.02f, in1 = open_positive ? d_hi - 0.02f : d_hi - t;
  for (int s = 0; s <= shelves + 1; ++s) {
    const float z = lo.z() + float(s) * step;
    slab("board" + std::to_string(s), d_lo, d_hi, l_lo + t, l_hi - t, z, z + t, board_mat, Category::Shelf);
    if (s > shelves) break;
    // A row of books on this board, leaving a gap whose position varies per shelf.
    const uint32_t h = hash3(seed_, uint32_t(s), 0x600du);
    const float bh = std::min(step - t - 0.03f, 0.18f + 0.1f * unit_float(h));
    const float gap0 = l_lo + t + (l_hi - l_lo - 2 * t) * (0.45f + 0.3f * unit_float(hash_u32(h)));
    const float book_d = std::min(0.22f, in1 - in0 - 0.02f);
    const float b0 = open_positive ? in0 : in1 - book_d, b1 = b0 + book_d;
    slab("books" + std::to_string(s) + "a", b0, b1, l_lo + t + 0.01f, gap0, z + t, z + t + bh, book_mat, Category::Books);
    slab("books" + std::to_string(s) + "b", b0, b1, gap0 + 0.12f, l_hi - t - 0.01f, z + t, z + t + bh * 0.85f,
         book_mat, Category::Books);
  }
}

void SceneBuilder::sofa(const std::string& name, const Vector2f& lo, const Vector2f& hi, const Vector2f& facing,
                        uint16_t fabric, uint16_t cushion, Category cat) {
  const int d = std::abs(facing.x()) > 0.5f ? 0 : 1, l = 1 - d;
  const bool pos = facing[d] > 0.0f;
  auto part = [&](const std::string& n, float d0, float d1, float l0, float l1, float z0, float z1, uint16_t m) {
    Vector3f a, b;
    a[d] = d0; b[d] = d1;
    a[l] = l0; b[l] = l1;
    a.z() = z0; b.z() = z1;
    box_between(name + "_" + n, a, b, m, cat);
  };
  const float back_t = 0.22f, arm_t = 0.18f;
  const float b0 = pos ? lo[d] : hi[d] - back_t, b1 = b0 + back_t;  // back band
  const float s0 = pos ? b1 : lo[d], s1 = pos ? hi[d] : b0;          // seat band
  part("base", lo[d], hi[d], lo[l] + arm_t, hi[l] - arm_t, 0.05f, 0.40f, fabric);
  part("back", b0, b1, lo[l] + arm_t, hi[l] - arm_t, 0.40f, 0.88f, fabric);
  part("arm0", lo[d], hi[d], lo[l], lo[l] + arm_t, 0.05f, 0.62f, fabric);
  part("arm1", lo[d], hi[d], hi[l] - arm_t, hi[l], 0.05f, 0.62f, fabric);
  const float inner0 = lo[l] + arm_t, inner1 = hi[l] - arm_t;
  const int n = (inner1 - inner0) > 1.2f ? 2 : 1;
  for (int i = 0; i < n; ++i) {
    const float c0 = inner0 + (inner1 - inner0) * float(i) / float(n) + 0.01f;
    const float c1 = inner0 + (inner1 - inner0) * float(i + 1) / float(n) - 0.01f;
    part("cushion" + std::to_string(i), s0 + (pos ? 0.0f : 0.02f), s1 - (pos ? 0.02f : 0.0f), c0, c1, 0.40f, 0.52f,
         cushion);
  }
}

void SceneBuilder::chair(const std::string& name, const Vector2f& c, const Vector2f& facing, uint16_t seat_mat,
                         uint16_t frame_mat) {
  const Vector2f f = facing.normalized();
  box(name + "_seat", {c.x(), c.y(), 0.47f}, {0.46f, 0.46f, 0.07f}, seat_mat, Category::Chair);
  const Vector2f back = c - f * 0.22f;
  const float yaw = std::atan2(f.y(), f.x()) / kDeg;
  box(name + "_back", {back.x(), back.y(), 0.78f}, {0.05f, 0.44f, 0.46f}, seat_mat, Category::Chair, yaw);
  cylinder(name + "_stem", {c.x(), c.y(), 0.06f}, 0.025f, 0.38f, frame_mat, Category::Chair);
  cylinder(name + "_base", {c.x(), c.y(), 0.0f}, 0.27f, 0.06f, frame_mat, Category::Chair);
}

void SceneBuilder::floor_lamp(const std::string& name, const Vector2f& xy, float height, uint16_t metal,
                              uint16_t shade, const Color& light_intensity) {
  cylinder(name + "_base", {xy.x(), xy.y(), 0.0f}, 0.16f, 0.03f, metal, Category::Lamp);
  cylinder(name + "_pole", {xy.x(), xy.y(), 0.03f}, 0.015f, height - 0.25f, metal, Category::Lamp);
  sphere(name + "_shade", {xy.x(), xy.y(), height - 0.1f}, 0.17f, shade, Category::Lamp);
  light({xy.x(), xy.y(), height + 0.15f}, light_intensity, 1.5f);
}

void SceneBuilder::plant(const std::string& name, const Vector2f& xy, float r, uint16_t pot, uint16_t leaves) {
  cylinder(name + "_pot", {xy.x(), xy.y(), 0.0f}, r, 2.0f * r, pot, Category::Plant);
  sphere(name + "_leaves", {xy.x(), xy.y(), 2.0f * r + 1.3f * r}, 1.5f * r, leaves, Category::Plant);
}

HomeMaterials home_materials(SceneBuilder& b) {
  const Color Z = Color::Zero();
  HomeMaterials m{};
  m.lamp_shade = b.emitter("lamp_shade", tex(TextureKind::Fabric, srgb(250, 235, 200), srgb(240, 220, 180), Z, 0.1f),
                           srgb(255, 220, 160) * 0.9f);
  m.light_panel = b.emitter("light_panel", tex(TextureKind::Solid, srgb(250, 250, 245), Z, Z, 0.1f),
                            Color(1.2f, 1.15f, 1.05f));
  m.terracotta = b.material("terracotta", tex(TextureKind::Plaster, srgb(180, 90, 50), Z, Z, 0.2f));
  m.leaves = b.material("leaves", tex(TextureKind::Leaves, srgb(40, 110, 40), srgb(20, 60, 25), Z, 0.1f));
  m.door = b.material("door", tex(TextureKind::Wood, srgb(200, 180, 150), srgb(170, 150, 120), srgb(90, 80, 60), 0.9f));
  return m;
}

Scene SceneBuilder::finish() {
  for (size_t i = 0; i < scene_.primitives.size(); ++i)
    scene_.primitives[i].seed = hash3(seed_, uint32_t(i), 0x5eedu);
  scene_.finalize();
  Scene out = std::move(scene_);
  scene_ = Scene{};
  return out;
}

}  // namespace rrg::synth
