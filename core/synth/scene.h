#pragma once
// A synthetic scene: materials, analytic primitives (one of them the room), point lights, and the
// tables derived from them (plane ids and equations, categories). finalize() assigns plane ids and
// builds the BVH; after that the scene is immutable and safe to share between threads.
#include "core/synth/bvh.h"
#include "core/synth/categories.h"
#include "core/synth/primitive.h"
#include "core/synth/texture.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace rrg::synth {

struct Material {
  std::string name;
  Texture texture;
  float f0 = 0.0f;         // Schlick reflectance at normal incidence in [0,1]; 0 = no reflection
  float roughness = 0.0f;  // reflection blur: radius of the jitter disc (tangent of the cone angle)
  Color emission = Color::Zero();  // emitted radiance (lamp shades, light panels)
};

struct PointLight {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Color intensity = Color::Ones();
  float falloff = 2.0f;  // metres: irradiance ~ I / (1 + (d / falloff)^2)
};

struct PlaneInfo {
  uint16_t id = 0;
  std::string name;
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // n.x + offset = 0; n points off the surface
  float offset = 0.0f;
  bool reflective = false;  // its material has F0 > 0
  Category category = Category::None;
};

struct CategoryInfo {
  Category id = Category::None;
  bool reflective = false;  // some surface of this category has F0 > 0
};

// Closest hit of a ray: parameter t along the (not necessarily unit) direction, primitive, face.
struct RayHit {
  float t = 0.0f;
  int prim = -1;
  int face = 0;
};

class Scene {
 public:
  std::string name;
  std::string description;
  std::vector<Material> materials;
  std::vector<Primitive> primitives;
  std::vector<PointLight> lights;
  Color ambient = Color::Constant(0.2f);  // uniform ambient irradiance
  float exposure = 1.0f;                  // tone mapping: 1 - exp(-exposure * C)

  // Validates, assigns plane ids to every planar face (in primitive order, from 1) and builds the
  // BVH. Throws std::invalid_argument naming the bad primitive. Call once after building.
  void finalize();
  bool finalized() const { return finalized_; }

  // Closest hit with t in [tmin, tmax); false when the ray leaves the scene.
  bool intersect(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float tmin, float tmax,
                 RayHit& hit) const;
  // True when anything is hit with t in [tmin, tmax) (shadow rays).
  bool occluded(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float tmin, float tmax) const;
  // True when p is inside the room (by margin) and at least margin away from every solid.
  bool is_free(const Eigen::Vector3f& p, float margin) const;

  const std::vector<PlaneInfo>& planes() const { return planes_; }  // planes_[i].id == i + 1
  // Categories present in the scene, ascending id, with their reflective flag.
  std::vector<CategoryInfo> categories() const;
  int room_index() const { return room_; }  // -1 when the scene has no room
  Aabb bounds() const;                      // of all primitives

 private:
  bool finalized_ = false;
  int room_ = -1;
  Bvh bvh_;
  std::vector<PlaneInfo> planes_;
};

}  // namespace rrg::synth
