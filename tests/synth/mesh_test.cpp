// Ground-truth mesh export: known vertex / triangle counts, outward winding, vertices on their
// surfaces with the right plane ids, and a bounded size for the presets.
#include "core/synth/mesh_export.h"
#include "core/synth/presets.h"
#include "core/synth/scene_builder.h"
#include "tests/synth/synth_test_util.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace rrg::synth {
namespace {

TEST(MeshExport, UnitBoxKnownCountsWindingAndPlanes) {
  SceneBuilder b("box", "", 0);
  const auto m = b.material("m", test::flat(Color::Constant(0.5f)));
  b.box("cube", {1, 2, 3}, {1, 1, 1}, m, Category::Table);
  const Scene s = b.finish();
  const TriangleMesh mesh = scene_mesh(s, {0.5f});
  mesh.validate();
  EXPECT_EQ(mesh.vertices.size(), 6u * 9u) << "each face a 2 x 2 grid";
  EXPECT_EQ(mesh.triangles.size(), 6u * 8u);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f a = mesh.vertices[size_t(t[0])], bb = mesh.vertices[size_t(t[1])], c = mesh.vertices[size_t(t[2])];
    const Eigen::Vector3f n = (bb - a).cross(c - a);
    EXPECT_GT(n.dot(mesh.normals[size_t(t[0])]), 0.0f) << "counter-clockwise seen from outside";
    EXPECT_GT(n.dot(a - Eigen::Vector3f(1, 2, 3)), 0.0f) << "normal points away from the centre";
  }
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const PlaneInfo& p = s.planes()[size_t(mesh.plane_ids[i]) - 1];
    EXPECT_NEAR(p.normal.dot(mesh.vertices[i]) + p.offset, 0.0f, 1e-5f) << "vertex on its face plane";
  }
  EXPECT_THROW(scene_mesh(s, {0.0f}), std::invalid_argument);
}

TEST(MeshExport, CurvedPrimitivesHaveNoPlaneOnTheirSidesAndCloseUp) {
  SceneBuilder b("round", "", 0);
  const auto m = b.material("m", test::flat(Color::Constant(0.5f)));
  b.sphere("ball", {0, 0, 0}, 0.5f, m, Category::Sculpture);
  b.cylinder("post", {2, 0, 0}, 0.2f, 1.0f, m, Category::Lamp);
  const Scene s = b.finish();
  const TriangleMesh mesh = scene_mesh(s, {0.05f});
  mesh.validate();
  // Outward winding everywhere; vertices on the analytic surfaces.
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f a = mesh.vertices[size_t(t[0])], bb = mesh.vertices[size_t(t[1])], c = mesh.vertices[size_t(t[2])];
    const Eigen::Vector3f n = (bb - a).cross(c - a);
    if (n.norm() < 1e-9f) continue;  // pole slivers of the sphere
    const Eigen::Vector3f centroid = (a + bb + c) / 3.0f;
    const Eigen::Vector3f centre = centroid.x() < 1.0f ? Eigen::Vector3f(0, 0, 0) : Eigen::Vector3f(2, 0, 0.5f);
    EXPECT_GT(n.dot(centroid - centre), 0.0f);
  }
  size_t capped = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& v = mesh.vertices[i];
    if (v.x() < 1.0f) {
      EXPECT_NEAR(v.norm(), 0.5f, 1e-5f);
      EXPECT_EQ(mesh.plane_ids[i], 0);
    } else if (mesh.plane_ids[i] != 0) {
      ++capped;
      EXPECT_TRUE(std::abs(v.z()) < 1e-6f || std::abs(v.z() - 1.0f) < 1e-6f) << "cap vertex";
    }
  }
  EXPECT_GT(capped, 0u);
}

TEST(MeshExport, PresetMeshesAreBoundedAndCoverEveryPlane) {
  for (const PresetInfo& info : preset_list()) {
    const SceneSpec spec = make_preset(info.name, 0);
    const TriangleMesh mesh = scene_mesh(spec.scene);
    mesh.validate();
    // Binary PLY: 12 + 12 + 3 + 4 bytes per vertex, 13 per triangle. A flat face on a grid of
    // max_edge e has 1 / e² vertices and 2 / e² triangles per m², 57 / e² bytes (91 kB at 2.5 cm);
    // small parts and curved shapes add some: at most twice that per m² of surface, and well under
    // 100 MB for the largest preset (open_plan, 108 m² of floor).
    const double bytes = 31.0 * double(mesh.vertices.size()) + 13.0 * double(mesh.triangles.size());
    double area = 0.0;
    for (const auto& t : mesh.triangles)
      area += 0.5 * double((mesh.vertices[size_t(t.y())] - mesh.vertices[size_t(t.x())])
                               .cross(mesh.vertices[size_t(t.z())] - mesh.vertices[size_t(t.x())]).norm());
    const double e = double(MeshExportParams{}.max_edge);
    std::printf("%s: %.1f MB, %.0f m² of surface, %.1f kB/m²\n", info.name.c_str(), bytes / 1e6, area, bytes / area / 1e3);
    EXPECT_LT(bytes / area, 2.0 * 57.0 / (e * e)) << info.name;
    EXPECT_LT(bytes, 100e6) << info.name;
    std::vector<bool> seen(spec.scene.planes().size() + 1, false);
    for (int32_t id : mesh.plane_ids) seen[size_t(id)] = true;
    for (size_t id = 1; id < seen.size(); ++id) EXPECT_TRUE(seen[id]) << info.name << " plane " << id;
  }
}

}  // namespace
}  // namespace rrg::synth
