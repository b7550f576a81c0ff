#include "core/common/mesh.h"

#include <stdexcept>
#include <string>

namespace rrg {

void TriangleMesh::validate() const {
  const size_t n = vertices.size();
  auto check = [n](size_t m, const char* what) {
    if (m != 0 && m != n)
      throw std::runtime_error(std::string("mesh: ") + what + " has " + std::to_string(m) +
                               " entries for " + std::to_string(n) + " vertices");
  };
  check(colors.size(), "colors");
  check(normals.size(), "normals");
  check(plane_ids.size(), "plane_ids");
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (triangles[t][k] < 0 || size_t(triangles[t][k]) >= n)
        throw std::runtime_error("mesh: triangle " + std::to_string(t) + " indexes vertex " +
                                 std::to_string(triangles[t][k]) + " of " + std::to_string(n));
}

}  // namespace rrg
