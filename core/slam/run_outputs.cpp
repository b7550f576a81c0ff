#include "core/slam/run_outputs.h"

#include "core/io/atomic_file.h"
#include "core/io/draco_mesh.h"
#include "core/io/image_io.h"
#include "core/io/ply.h"
#include "core/gaussians/gaussian_ply.h"
#include "core/gaussians/spz.h"

#include <cstdio>
#include <fstream>

namespace rrg {
namespace {

ColorImage mask_image(const MaskImage& m) {
  ColorImage c(m.width(), m.height(), Color::Zero());
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x)
      if (m(x, y)) c(x, y) = Color::Ones();
  return c;
}

void write_bytes(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  io::write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!f) throw std::runtime_error("cannot write " + path.string());
  });
}

}  // namespace

void RunOutputs::render(const std::string& name, const SessionView& v, const ColorImage* gt) {
  if (out_.empty() || !renders_) return;
  const auto dir = out_ / "renders";
  std::filesystem::create_directories(dir);
  io::write_color_png(dir / (name + "_C.png"), v.C);
  io::write_color_png(dir / (name + "_C_b.png"), v.C_b);
  io::write_color_png(dir / (name + "_RC_r.png"), v.RC_r);
  io::write_color_png(dir / (name + "_R.png"), mask_image(v.R));
  io::write_depth_png(dir / (name + "_depth.png"), v.depth, 1000.0f);
  if (gt) io::write_color_png(dir / (name + "_gt.png"), *gt);
}

void RunOutputs::decomposition(size_t frame, const SessionView& v, const ColorImage& gt) {
  if (out_.empty()) return;
  const auto dir = out_ / "decomposition";
  std::filesystem::create_directories(dir);
  char prefix[32];
  std::snprintf(prefix, sizeof(prefix), "frame_%06zu_", frame);
  io::write_color_png(dir / (std::string(prefix) + "C_b.png"), v.C_b);
  io::write_color_png(dir / (std::string(prefix) + "R.png"), mask_image(v.R));
  io::write_color_png(dir / (std::string(prefix) + "RC_r.png"), v.RC_r);
  io::write_color_png(dir / (std::string(prefix) + "C.png"), v.C);
  io::write_color_png(dir / (std::string(prefix) + "gt.png"), gt);
}

void RunOutputs::mesh(const TriangleMesh& mesh) {
  if (out_.empty()) return;
  io::write_ply_mesh(out_ / "mesh.ply", mesh);
  write_bytes(out_ / "mesh.drc", io::encode_draco(mesh));
}

void RunOutputs::gaussians(const GaussianHost& base, const GaussianHost& reflection,
                           const std::vector<ReflectivePlane>& planes) {
  if (out_.empty()) return;
  write_gaussian_ply(out_ / "gaussians_base.ply", base);
  write_reflection_ply(out_ / "gaussians_reflection.ply", reflection, planes);
  write_bytes(out_ / "gaussians_base.spz", encode_spz(base));
  write_bytes(out_ / "gaussians_reflection.spz", encode_spz(reflection));
}

}  // namespace rrg
