#pragma once
// Helpers for writing presets: primitives by centre and size (metres, world frame z up), yaw in
// degrees, and furniture made of several primitives. Every add returns the primitive so a preset
// can adjust it; finish() seeds the textures from (seed, primitive index) and finalizes the scene.
#include "core/synth/scene.h"

#include <string>

namespace rrg::synth {

class SceneBuilder {
 public:
  SceneBuilder(std::string name, std::string description, uint32_t seed);

  uint16_t material(const Material& m);  // returns the material index
  // Material shorthands: a textured matte or reflective material, and an emitter.
  uint16_t material(const std::string& name, const Texture& texture, float f0 = 0.0f, float roughness = 0.0f);
  uint16_t emitter(const std::string& name, const Texture& texture, const Color& emission);

  // The room [0, size] with floor / walls / ceiling materials.
  Primitive& room(const Eigen::Vector3f& size, uint16_t floor, uint16_t walls, uint16_t ceiling);
  // Box by centre and full size, rotated by yaw degrees about z.
  Primitive& box(const std::string& name, const Eigen::Vector3f& centre, const Eigen::Vector3f& size,
                 uint16_t mat, Category cat, float yaw_deg = 0.0f);
  // Axis-aligned box by corners.
  Primitive& box_between(const std::string& name, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                         uint16_t mat, Category cat);
  // Rectangle of width x height centred at `centre`, facing `normal`, its height along `up`.
  Primitive& rect(const std::string& name, const Eigen::Vector3f& centre, const Eigen::Vector3f& normal,
                  const Eigen::Vector3f& up, float width, float height, uint16_t mat, Category cat);
  Primitive& sphere(const std::string& name, const Eigen::Vector3f& centre, float radius, uint16_t mat,
                    Category cat);
  // Vertical cylinder standing on `base` (centre of its bottom cap).
  Primitive& cylinder(const std::string& name, const Eigen::Vector3f& base, float radius, float height,
                      uint16_t mat, Category cat);
  void light(const Eigen::Vector3f& position, const Color& intensity, float falloff);

  // ---- furniture -----------------------------------------------------------------------------
  // Table: top of size (w, d, thickness) with its upper face at `height`, four round legs.
  void table(const std::string& name, const Eigen::Vector2f& centre_xy, const Eigen::Vector3f& top_size,
             float height, uint16_t top_mat, uint16_t leg_mat, Category cat, float yaw_deg = 0.0f);
  // Open bookshelf between corners lo..hi (axis-aligned) with `shelves` boards and rows of books;
  // the open side faces `open_dir` (one of +-x, +-y).
  void bookshelf(const std::string& name, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, int shelves,
                 const Eigen::Vector3f& open_dir, uint16_t board_mat, uint16_t book_mat);
  // Sofa / armchair facing `facing` (+-x or +-y), footprint lo..hi on the floor, seat and back.
  void sofa(const std::string& name, const Eigen::Vector2f& lo, const Eigen::Vector2f& hi,
            const Eigen::Vector2f& facing, uint16_t fabric, uint16_t cushion, Category cat);
  // Office chair: seat, back, stem and a round base; back on the side opposite `facing`.
  void chair(const std::string& name, const Eigen::Vector2f& centre, const Eigen::Vector2f& facing,
             uint16_t seat_mat, uint16_t frame_mat);
  // Floor lamp: base, pole, glowing shade sphere, and a point light just above the shade.
  void floor_lamp(const std::string& name, const Eigen::Vector2f& xy, float height, uint16_t metal,
                  uint16_t shade, const Color& light_intensity);
  // Potted plant: pot cylinder and a foliage sphere.
  void plant(const std::string& name, const Eigen::Vector2f& xy, float pot_radius, uint16_t pot, uint16_t leaves);

  Scene& scene() { return scene_; }
  // Seeds textures and finalizes; the builder is left empty.
  Scene finish();

 private:
  Primitive& add(Primitive p);
  Scene scene_;
  uint32_t seed_;
};

// Texture shorthand for presets: kind, three colours, scale and the kind's parameter.
inline Texture tex(TextureKind kind, Color a, Color b, Color c, float scale, float param = 0.004f) {
  return Texture{kind, a, b, c, scale, param};
}

// Materials the furnished presets (living_room, open_plan) share: a lamp shade and a ceiling panel
// that glow, terracotta pots, leaves and a wooden door. Registered in this order.
struct HomeMaterials {
  uint16_t lamp_shade, light_panel, terracotta, leaves, door;
};
HomeMaterials home_materials(SceneBuilder& b);

// Rotation about z by yaw degrees, as a world -> local matrix.
Eigen::Matrix3f yaw_world_to_local(float yaw_deg);

}  // namespace rrg::synth
