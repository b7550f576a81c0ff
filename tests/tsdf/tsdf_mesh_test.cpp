// Marching cubes on the TSDF: area and closure of a sphere, orientation, welding, device parity,
// and the generated case table.
#include "core/tsdf/marching_cubes_table.h"
#include "core/tsdf/tsdf_mesh.h"
#include "tests/support/parity.h"
#include "tests/tsdf/analytic_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <stdexcept>
#include <tuple>

namespace rrg {
namespace {

const Intrinsics kK{150.0f, 150.0f, 79.5f, 59.5f, 160, 120};
const Eigen::Vector3f kC(0.02f, -0.03f, 0.01f);
constexpr float kR = 0.25f;

TsdfVolume fused_sphere(const Device& device) {
  TsdfParams p;
  p.voxel_size = 0.01f;
  p.truncation = 0.04f;
  TsdfVolume v(p, device);
  test::fuse_scene(v, test::sphere_scene(kC, kR), kK, test::cameras_around(kC, 0.9f), Color(0.2f, 0.6f, 0.4f));
  return v;
}

double area(const TriangleMesh& m) {
  double a = 0;
  for (const auto& t : m.triangles)
    a += 0.5 * double((m.vertices[size_t(t.y())] - m.vertices[size_t(t.x())])
                          .cross(m.vertices[size_t(t.z())] - m.vertices[size_t(t.x())]).norm());
  return a;
}

TEST(TsdfMesh, SphereHasTheRightAreaIsClosedAndFacesOutwards) {
  const TsdfVolume v = fused_sphere(Device::cpu());
  const TriangleMesh m = extract_mesh(v);
  m.validate();
  ASSERT_GT(m.triangles.size(), 1000u);
  const double expected = 4.0 * std::numbers::pi * kR * kR;
  EXPECT_NEAR(area(m) / expected, 1.0, 0.02) << "area " << area(m) << " vs 4πr² " << expected;
  // Closed and welded: every undirected edge is shared by exactly two triangles, once each way.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, count] : directed) {
    ASSERT_EQ(count, 1) << "edge " << e.first << "-" << e.second << " used twice in one direction";
    ASSERT_EQ(directed.count({e.second, e.first}), 1u) << "open edge " << e.first << "-" << e.second;
  }
  size_t outward = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3f a = m.vertices[size_t(t.x())], b = m.vertices[size_t(t.y())], c = m.vertices[size_t(t.z())];
    outward += (b - a).cross(c - a).dot((a + b + c) / 3.0f - kC) > 0.0f;
  }
  EXPECT_EQ(outward, m.triangles.size());
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    ASSERT_NEAR((m.vertices[i] - kC).norm(), kR, 0.003f);
    ASSERT_LT((m.colors[i] - Eigen::Vector3f(0.2f, 0.6f, 0.4f)).norm(), 1e-3f);
    ASSERT_EQ(m.plane_ids[i], 0);
  }
}

TEST(TsdfMesh, BlocksMeshedSeparatelyWeldToTheWholeMesh) {
  const TsdfVolume v = fused_sphere(Device::cpu());
  const TriangleMesh whole = extract_mesh(v);
  const auto coords = v.block_coords();
  size_t triangles = 0, vertices = 0;
  double parts = 0;
  for (size_t i = 0; i < coords.size(); i += 64) {  // meshed in groups of blocks
    const std::vector<Eigen::Vector3i> group(coords.begin() + long(i), coords.begin() + long(std::min(coords.size(), i + 64)));
    const TriangleMesh m = extract_mesh(v, group);
    triangles += m.triangles.size();
    vertices += m.vertices.size();
    parts += area(m);
  }
  EXPECT_EQ(triangles, whole.triangles.size());
  EXPECT_GT(vertices, whole.vertices.size());  // group borders are not welded across groups
  EXPECT_NEAR(parts, area(whole), 1e-6 * area(whole));
}

// CPU and CUDA give the same mesh: the same triangles, and vertices within 0.2 mm. The back ends'
// compilers contract multiply-adds differently, so a voxel whose nearest pixel lies exactly at x.5
// may fuse the neighbouring pixel on one of them (tsdf_fusion_test.cpp allows 0.5 % of the voxels
// to differ for that reason); the vertices on that voxel's edges then move by a fraction of the
// pixel's footprint over the voxel's weight: at most 0.1 % of the vertices may differ by more than
// 0.2 mm (H200, 2026-12-04: 3 coordinates, up to 0.28 mm), none by more than 1 mm (a tenth of a voxel).
TEST(TsdfMesh, SameMeshOnEveryDevice) {
  test::report_cuda_parity_status();
  const TriangleMesh cpu = extract_mesh(fused_sphere(Device::cpu()));
  ASSERT_GT(cpu.vertices.size(), 1000u);
  for (const Device& device : available_devices()) {
    if (device.is_cpu()) continue;
    SCOPED_TRACE(device.to_string());
    const TriangleMesh gpu = extract_mesh(fused_sphere(device));
    ASSERT_EQ(gpu.vertices.size(), cpu.vertices.size());
    ASSERT_EQ(gpu.triangles.size(), cpu.triangles.size());
    size_t triangles_differ = 0, vertices_differ = 0;
    float worst = 0.0f;
    for (size_t i = 0; i < cpu.triangles.size(); ++i) triangles_differ += cpu.triangles[i] != gpu.triangles[i];
    for (size_t i = 0; i < cpu.vertices.size(); ++i) {
      const float d = (cpu.vertices[i] - gpu.vertices[i]).cwiseAbs().maxCoeff();
      vertices_differ += d > 2e-4f;
      worst = std::max(worst, d);
    }
    std::cout << "[parity] mesh: " << vertices_differ << " of " << cpu.vertices.size()
              << " vertices differ by more than 0.2 mm, largest " << worst * 1e3f << " mm\n";
    EXPECT_EQ(triangles_differ, 0u);
    EXPECT_LE(vertices_differ, cpu.vertices.size() / 1000);
    EXPECT_LE(worst, 1e-3f);
  }
}

std::vector<Eigen::Vector3i> sorted_coords(std::vector<Eigen::Vector3i> c) {
  std::sort(c.begin(), c.end(), [](const auto& a, const auto& b) { return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z()); });
  return c;
}

void expect_same_mesh(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  EXPECT_TRUE(a.vertices == b.vertices);
  EXPECT_TRUE(a.colors == b.colors);
  EXPECT_TRUE(a.plane_ids == b.plane_ids);
  EXPECT_TRUE(a.triangles == b.triangles);
}

// A map larger than the device holds: the blocks streamed out to host memory are meshed in slabs
// of consecutive block x without the pool ever holding more than the budget, into the very mesh of
// the whole volume; the blocks resident before are resident after.
TEST(TsdfMesh, StreamedExtractionMeshesEveryBlockWithinTheBudget) {
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    const TsdfVolume full = fused_sphere(device);
    const TriangleMesh whole = extract_mesh(full);
    const std::vector<BlockData> blocks = full.read_all_blocks();  // sorted by coordinate
    // The budget: a sixth of the map, and at least the largest layer of block x with its +x layer.
    std::map<int, size_t> layer;
    for (const BlockData& b : blocks) ++layer[b.coord.x()];
    size_t budget = blocks.size() / 6;
    for (const auto& [x, n] : layer) budget = std::max(budget, n + (layer.count(x + 1) ? layer[x + 1] : 0));
    ASSERT_LT(2 * budget, blocks.size());
    // A volume whose pool never held more than the budget: a budget's worth of blocks inserted at
    // a time, the previous ones streamed out first; the last group stays resident.
    TsdfParams p = full.params();
    p.initial_blocks = 1;
    TsdfVolume v(p, device);
    for (size_t i = 0; i < blocks.size(); i += budget) {
      v.stream_out(v.block_coords());
      v.insert_blocks(std::span(blocks).subspan(i, std::min(budget, blocks.size() - i)));
    }
    ASSERT_GT(v.num_host_blocks(), 0);
    const auto resident = sorted_coords(v.block_coords());
    const size_t device_bytes = v.memory().device_bytes;

    expect_same_mesh(extract_mesh_streamed(v, int64_t(budget)), whole);
    EXPECT_EQ(v.memory().device_bytes, device_bytes);  // neither the pool nor the hash grew
    EXPECT_EQ(sorted_coords(v.block_coords()), resident);
    EXPECT_EQ(size_t(v.num_blocks() + v.num_host_blocks()), blocks.size());
    // A budget below one layer meshes a layer and its +x neighbour at a time: the same mesh.
    expect_same_mesh(extract_mesh_streamed(v, 1), whole);
    EXPECT_EQ(sorted_coords(v.block_coords()), resident);
    EXPECT_THROW(extract_mesh_streamed(v, 0), std::invalid_argument);
  }
}

TEST(TsdfMesh, CaseTableIsClosedAndComplete) {
  const auto& table = mc::triangle_table();
  const auto triangles = [&](int m) {
    int n = 0;
    while (table[size_t(m * mc::kStride + 3 * n)] >= 0) ++n;
    return n;
  };
  EXPECT_EQ(triangles(0), 0);
  EXPECT_EQ(triangles(255), 0);
  for (int c = 0; c < 8; ++c) {
    EXPECT_EQ(triangles(1 << c), 1) << "one corner inside";
    EXPECT_EQ(triangles(255 ^ (1 << c)), 1) << "one corner outside";
  }
  EXPECT_EQ(triangles(0b00001111), 2);  // a face's four corners: one quad
  for (int m = 1; m < 255; ++m) {
    // every triangle edge crosses the surface: its two corners differ
    for (int k = 0; table[size_t(m * mc::kStride + k)] >= 0; ++k) {
      const int e = table[size_t(m * mc::kStride + k)];
      const Eigen::Vector3i a = mc::edge_origin(e);
      Eigen::Vector3i b = a;
      b[mc::edge_axis(e)] = 1;
      const int ca = a.x() + 2 * a.y() + 4 * a.z(), cb = b.x() + 2 * b.y() + 4 * b.z();
      ASSERT_NE((m >> ca) & 1, (m >> cb) & 1) << "case " << m << " edge " << e;
    }
  }
}

TEST(TsdfMesh, EmptyVolumeGivesAnEmptyMesh) {
  TsdfVolume v(TsdfParams{}, Device::cpu());
  EXPECT_TRUE(extract_mesh(v).triangles.empty());
}

}  // namespace
}  // namespace rrg
