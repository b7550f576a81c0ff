#pragma once
// The files `rrg run` writes besides metrics: renders (lossless PNG), decomposition images, the
// mesh (PLY + Draco) and the Gaussians (3DGS PLY + SPZ v3, base and reflection). Every file is
// written atomically. With an empty folder nothing is written (tests).
#include "core/common/mesh.h"
#include "core/gaussians/gaussian_set.h"
#include "core/slam/session.h"

#include <filesystem>
#include <string>
#include <vector>

namespace rrg {

class RunOutputs {
 public:
  RunOutputs(std::filesystem::path out, bool renders) : out_(std::move(out)), renders_(renders) {}
  // renders/<name>_{C,C_b,RC_r,R,depth}.png (+ _gt.png when gt is given); depth 16-bit, mm.
  void render(const std::string& name, const SessionView& view, const ColorImage* gt);
  // decomposition/frame_NNNNNN_{C_b,R,RC_r,C,gt}.png
  void decomposition(size_t frame, const SessionView& view, const ColorImage& gt);
  // mesh.ply, mesh.drc
  void mesh(const TriangleMesh& mesh);
  // gaussians_base.{ply,spz}, gaussians_reflection.{ply,spz} + gaussians_reflection.planes.json
  void gaussians(const GaussianHost& base, const GaussianHost& reflection, const std::vector<ReflectivePlane>& planes);

 private:
  std::filesystem::path out_;
  bool renders_;
};

}  // namespace rrg
