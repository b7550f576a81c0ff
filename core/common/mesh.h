#pragma once
// Triangle meshes (ground truth from core/synth, marching cubes from core/tsdf) and the per-vertex
// attributes we carry: colour and plane id.
#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace rrg {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;   // world frame, metres
  std::vector<Eigen::Vector3f> colors;     // optional, [0,1], one per vertex
  std::vector<Eigen::Vector3f> normals;    // optional, one per vertex
  std::vector<int32_t> plane_ids;          // optional, one per vertex, 0 = none
  std::vector<Eigen::Vector3i> triangles;  // vertex indices

  bool empty() const { return vertices.empty(); }
  // Throws std::runtime_error naming the problem when an attribute array has the wrong length or a
  // triangle indexes outside the vertex array.
  void validate() const;
};

}  // namespace rrg
