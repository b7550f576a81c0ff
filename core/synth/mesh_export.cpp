#include "core/synth/mesh_export.h"

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace rrg::synth {

using Eigen::Vector2f;
using Eigen::Vector3f;

namespace {

constexpr float kPi = 3.14159265f;
constexpr int kFaceAxes[3][2] = {{1, 2}, {0, 2}, {0, 1}};

class MeshWriter {
 public:
  MeshWriter(const Scene& scene, TriangleMesh& mesh) : scene_(scene), mesh_(mesh) {}

  // Appends a vertex at local point l of primitive p (face f), colour from the face texture.
  int vertex(const Primitive& p, int f, const Vector3f& l, const Vector3f& n_local, const Vector2f& uv,
             const Vector2f& size) {
    mesh_.vertices.push_back(p.R.transpose() * l + p.center);
    mesh_.normals.push_back((p.R.transpose() * n_local).normalized());
    const Material& m = scene_.materials[p.material[size_t(f)]];
    const Color albedo = eval_texture(m.texture, uv, size, p.seed);
    mesh_.colors.push_back(albedo.array().pow(1.0f / 2.2f).matrix());
    mesh_.plane_ids.push_back(int32_t(p.plane[size_t(f)]));
    return int(mesh_.vertices.size() - 1);
  }
  // Two triangles for the quad (a, b, c, d) in order, wound so the normal follows `flip`.
  void quad(int a, int b, int c, int d, bool flip) {
    if (!flip) {
      mesh_.triangles.emplace_back(a, b, c);
      mesh_.triangles.emplace_back(a, c, d);
    } else {
      mesh_.triangles.emplace_back(a, c, b);
      mesh_.triangles.emplace_back(a, d, c);
    }
  }

  void planar_face(const Primitive& p, int f, float edge) {
    const int axis = f / 2, a1 = kFaceAxes[axis][0], a2 = kFaceAxes[axis][1];
    const float sign = (f & 1) ? 1.0f : -1.0f;
    Vector3f n_local = Vector3f::Zero();
    n_local[axis] = p.kind == PrimitiveKind::Room ? -sign : sign;
    const float h1 = p.half[a1], h2 = p.half[a2];
    const int n1 = std::max(1, int(std::ceil(2.0f * h1 / edge))), n2 = std::max(1, int(std::ceil(2.0f * h2 / edge)));
    const Vector2f size(2.0f * h1, 2.0f * h2);
    const int base = int(mesh_.vertices.size());
    for (int j = 0; j <= n2; ++j)
      for (int i = 0; i <= n1; ++i) {
        Vector3f l = Vector3f::Zero();
        l[axis] = p.kind == PrimitiveKind::Rect ? 0.0f : sign * p.half[axis];
        l[a1] = -h1 + size.x() * float(i) / float(n1);
        l[a2] = -h2 + size.y() * float(j) / float(n2);
        vertex(p, f, l, n_local, {l[a1] + h1, l[a2] + h2}, size);
      }
    // (e_a1 x e_a2) . n decides the winding.
    Vector3f e1 = Vector3f::Zero(), e2 = Vector3f::Zero();
    e1[a1] = 1.0f;
    e2[a2] = 1.0f;
    const bool flip = e1.cross(e2).dot(n_local) < 0.0f;
    for (int j = 0; j < n2; ++j)
      for (int i = 0; i < n1; ++i) {
        const int v00 = base + j * (n1 + 1) + i;
        quad(v00, v00 + 1, v00 + n1 + 2, v00 + n1 + 1, flip);
      }
  }

  void sphere(const Primitive& p, float edge) {
    const float r = p.half.x();
    const int np = std::max(16, int(std::ceil(2.0f * kPi * r / edge))), nt = std::max(8, int(std::ceil(kPi * r / edge)));
    const Vector2f size(2.0f * kPi * r, kPi * r);
    const int base = int(mesh_.vertices.size());
    for (int j = 0; j <= nt; ++j) {
      const float theta = kPi * float(j) / float(nt);
      for (int i = 0; i <= np; ++i) {
        const float phi = -kPi + 2.0f * kPi * float(i) / float(np);
        const Vector3f n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        vertex(p, 0, n * r, n, {(phi + kPi) * r, theta * r}, size);
      }
    }
    for (int j = 0; j < nt; ++j)
      for (int i = 0; i < np; ++i) {
        const int v00 = base + j * (np + 1) + i;
        quad(v00, v00 + np + 1, v00 + np + 2, v00 + 1, false);
      }
  }

  void cylinder(const Primitive& p, float edge) {
    const float r = p.half.x(), hz = p.half.z();
    const int np = std::max(16, int(std::ceil(2.0f * kPi * r / edge))), nz = std::max(1, int(std::ceil(2.0f * hz / edge)));
    const Vector2f side_size(2.0f * kPi * r, 2.0f * hz);
    int base = int(mesh_.vertices.size());
    for (int j = 0; j <= nz; ++j)
      for (int i = 0; i <= np; ++i) {
        const float phi = -kPi + 2.0f * kPi * float(i) / float(np), z = -hz + 2.0f * hz * float(j) / float(nz);
        const Vector3f n(std::cos(phi), std::sin(phi), 0.0f);
        vertex(p, 0, Vector3f(r * n.x(), r * n.y(), z), n, {(phi + kPi) * r, z + hz}, side_size);
      }
    for (int j = 0; j < nz; ++j)
      for (int i = 0; i < np; ++i) {
        const int v00 = base + j * (np + 1) + i;
        quad(v00, v00 + 1, v00 + np + 2, v00 + np + 1, false);
      }
    // Caps: concentric rings around a centre vertex.
    const int nr = std::max(1, int(std::ceil(r / edge)));
    const Vector2f cap_size(2.0f * r, 2.0f * r);
    for (int f : {4, 5}) {
      const float z = f == 5 ? hz : -hz;
      const Vector3f n(0, 0, f == 5 ? 1.0f : -1.0f);
      const int centre = vertex(p, f, Vector3f(0, 0, z), n, {r, r}, cap_size);
      base = int(mesh_.vertices.size());
      for (int k = 1; k <= nr; ++k)
        for (int i = 0; i < np; ++i) {
          const float rr = r * float(k) / float(nr), phi = 2.0f * kPi * float(i) / float(np);
          const float x = rr * std::cos(phi), y = rr * std::sin(phi);
          vertex(p, f, Vector3f(x, y, z), n, {x + r, y + r}, cap_size);
        }
      const bool flip = f == 4;
      for (int i = 0; i < np; ++i) {
        const int a = base + i, b = base + (i + 1) % np;
        if (!flip) mesh_.triangles.emplace_back(centre, a, b);
        else mesh_.triangles.emplace_back(centre, b, a);
      }
      for (int k = 1; k < nr; ++k)
        for (int i = 0; i < np; ++i) {
          const int a = base + (k - 1) * np + i, b = base + (k - 1) * np + (i + 1) % np;
          quad(a, a + np, b + np, b, flip);
        }
    }
  }

 private:
  const Scene& scene_;
  TriangleMesh& mesh_;
};

}  // namespace

TriangleMesh scene_mesh(const Scene& scene, const MeshExportParams& params) {
  if (!(params.max_edge > 0.0f)) throw std::invalid_argument("scene_mesh: max_edge must be > 0");
  if (!scene.finalized()) throw std::invalid_argument("scene_mesh: scene '" + scene.name + "' is not finalized");
  TriangleMesh mesh;
  MeshWriter writer(scene, mesh);
  for (const Primitive& p : scene.primitives) {
    switch (p.kind) {
      case PrimitiveKind::Box:
      case PrimitiveKind::Room:
        for (int f = 0; f < 6; ++f) writer.planar_face(p, f, params.max_edge);
        break;
      case PrimitiveKind::Rect: writer.planar_face(p, 5, params.max_edge); break;
      case PrimitiveKind::Sphere: writer.sphere(p, params.max_edge); break;
      case PrimitiveKind::Cylinder: writer.cylinder(p, params.max_edge); break;
    }
  }
  return mesh;
}

}  // namespace rrg::synth
