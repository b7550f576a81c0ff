// `rrg synth` end to end through the real executable: the output layout, the files' contents read
// back with core/io, geometry consistency of the written planes, determinism across --threads, and
// the error cases.
#include "core/common/camera.h"
#include "core/io/image_io.h"
#include "core/io/ply.h"
#include "core/io/trajectory.h"
#include "core/synth/exposure.h"
#include "tests/support/test_support.h"

#include <nlohmann/json.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace rrg::synth {
namespace {

namespace fs = std::filesystem;
using rrg::test::run_rrg;
using rrg::test::TempDir;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
nlohmann::json read_json(const fs::path& p) { return nlohmann::json::parse(slurp(p)); }
std::vector<std::string> data_lines(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  std::string line;
  int comments = 0;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') ++comments;
    else if (!line.empty()) out.push_back(line);
  }
  EXPECT_EQ(comments, 3) << p;
  return out;
}

void expect_view_folder(const fs::path& root, size_t n, int w, int h) {
  for (const char* f : {"rgb.txt", "depth.txt", "groundtruth.txt", "camera.json", "planes.json", "categories.json"})
    EXPECT_TRUE(fs::is_regular_file(root / f)) << root / f;
  const auto rgb = data_lines(root / "rgb.txt"), depth = data_lines(root / "depth.txt");
  ASSERT_EQ(rgb.size(), n);
  ASSERT_EQ(depth.size(), n);
  const io::Trajectory gt = io::read_tum_trajectory(root / "groundtruth.txt");
  ASSERT_EQ(gt.size(), n);
  for (size_t i = 0; i < n; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", i);
    char ts[32];
    std::snprintf(ts, sizeof(ts), "%.6f", gt[i].timestamp);
    EXPECT_EQ(rgb[i], std::string(ts) + " rgb/" + name);
    EXPECT_EQ(depth[i], std::string(ts) + " depth/" + name);
    const ColorImage c = io::read_color(root / "rgb" / name);
    EXPECT_EQ(c.width(), w);
    EXPECT_EQ(c.height(), h);
    EXPECT_EQ(io::read_depth(root / "depth" / name, 5000.0f).width(), w);
    EXPECT_EQ(io::read_labels(root / "labels" / name).height(), h);
    EXPECT_EQ(io::read_labels(root / "planes" / name).width(), w);
    EXPECT_EQ(io::read_mask(root / "reflection" / name).width(), w);
  }
}

TEST(SynthCli, WritesEveryListedFileConsistently) {
  TempDir tmp("synth-cli");
  const fs::path out = tmp / "seq";
  const auto r = run_rrg("synth --preset living_room --frames 5 --width 64 --height 48 --novel 2 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frames/s"), std::string::npos) << r.output;
  expect_view_folder(out, 5, 64, 48);
  expect_view_folder(out / "novel", 2, 64, 48);
  for (const char* f : {"mesh_gt.ply", "scene.json"}) EXPECT_TRUE(fs::is_regular_file(out / f)) << f;

  const io::Trajectory gt = io::read_tum_trajectory(out / "groundtruth.txt");
  for (size_t i = 0; i < gt.size(); ++i) EXPECT_NEAR(gt[i].timestamp, double(i) / 30.0, 1e-6);
  const auto cam = read_json(out / "camera.json");
  EXPECT_EQ(cam["width"], 64);
  EXPECT_EQ(cam["height"], 48);
  EXPECT_FLOAT_EQ(cam["fx"].get<float>(), 0.8f * 64.0f);
  EXPECT_FLOAT_EQ(cam["cx"].get<float>(), 31.5f);
  EXPECT_FLOAT_EQ(cam["cy"].get<float>(), 23.5f);
  EXPECT_EQ(cam["depth_scale"], 5000);
  const auto scene = read_json(out / "scene.json");
  EXPECT_EQ(scene["preset"], "living_room");
  EXPECT_EQ(scene["parameters"]["frames"], 5);
  EXPECT_TRUE(scene.contains("generator_version"));
  bool floor_reflective = false;
  const auto categories = read_json(out / "categories.json");
  for (const auto& c : categories["categories"])
    if (c["name"] == "floor") floor_reflective = c["reflective"].get<bool>();
  EXPECT_TRUE(floor_reflective);

  // Written plane ids against planes.json: unproject the 16-bit depth with camera.json and the
  // ground-truth pose; each point lies on its plane within 1 mm (depth is quantised to 0.2 mm).
  const auto planes = read_json(out / "planes.json")["planes"];
  const Intrinsics K{cam["fx"].get<float>(), cam["fy"].get<float>(), cam["cx"].get<float>(), cam["cy"].get<float>(), 64, 48};
  size_t checked = 0, reflective_px = 0;
  for (size_t i = 0; i < gt.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", i);
    const DepthImage depth = io::read_depth(out / "depth" / name, 5000.0f);
    const LabelImage ids = io::read_labels(out / "planes" / name);
    const MaskImage refl = io::read_mask(out / "reflection" / name);
    for (int v = 0; v < 48; ++v)
      for (int u = 0; u < 64; ++u) {
        reflective_px += refl(u, v);
        const uint16_t id = ids(u, v);
        if (id == 0 || depth(u, v) <= 0.0f) continue;
        const auto& pl = planes[id - 1u];
        ASSERT_EQ(pl["id"], id);
        const Eigen::Vector3d x = gt[i].T_wc * K.unproject(float(u), float(v), depth(u, v)).cast<double>();
        const Eigen::Vector3d n(pl["normal"][0].get<double>(), pl["normal"][1].get<double>(), pl["normal"][2].get<double>());
        ASSERT_LT(std::abs(n.dot(x) + pl["offset"].get<double>()), 1e-3) << pl["name"] << " frame " << i;
        EXPECT_EQ(refl(u, v), pl["reflective"].get<bool>() ? 1 : 0);
        ++checked;
      }
  }
  EXPECT_GT(checked, 5u * 64u * 48u * 8u / 10u);
  EXPECT_GT(reflective_px, 0u);

  const TriangleMesh mesh = io::read_ply_mesh(out / "mesh_gt.ply");
  EXPECT_GT(mesh.vertices.size(), 10000u);
  EXPECT_EQ(mesh.plane_ids.size(), mesh.vertices.size());
  EXPECT_EQ(mesh.colors.size(), mesh.vertices.size());

  // Non-empty output folder: refused without --overwrite (nothing written), accepted with it.
  const std::string before = slurp(out / "rgb.txt");
  const auto again = run_rrg("synth --preset office --frames 2 --width 32 --height 24 --novel 0 --out " + out.string());
  EXPECT_EQ(again.exit_code, 1) << again.output;
  EXPECT_NE(again.output.find("--overwrite"), std::string::npos) << again.output;
  EXPECT_EQ(slurp(out / "rgb.txt"), before);
  const auto over = run_rrg("synth --preset office --frames 2 --width 32 --height 24 --novel 0 --overwrite --out " +
                            out.string());
  EXPECT_EQ(over.exit_code, 0) << over.output;
  EXPECT_EQ(data_lines(out / "rgb.txt").size(), 2u);
  EXPECT_EQ(read_json(out / "scene.json")["preset"], "office");
}

TEST(SynthCli, SameBytesWhateverTheThreadCountAndNoiseIsDeterministic) {
  TempDir tmp("synth-threads");
  const std::string common = "synth --preset mirror_room --frames 2 --width 48 --height 36 --novel 1 --noise --seed 3 ";
  ASSERT_EQ(run_rrg(common + "--threads 1 --out " + (tmp / "a").string()).exit_code, 0);
  ASSERT_EQ(run_rrg(common + "--threads 2 --out " + (tmp / "b").string()).exit_code, 0);
  for (const char* f : {"rgb/000001.png", "depth/000001.png", "labels/000000.png", "planes/000001.png",
                        "reflection/000001.png", "novel/rgb/000000.png", "novel/depth/000000.png", "groundtruth.txt",
                        "novel/groundtruth.txt", "mesh_gt.ply", "scene.json"})
    EXPECT_EQ(slurp(tmp / "a" / f), slurp(tmp / "b" / f)) << f;
  // --mirror-depth invalid zeroes the mirror's depth.
  const auto r = run_rrg("synth --preset mirror_room --frames 1 --width 48 --height 36 --novel 0 --mirror-depth invalid --out " +
                         (tmp / "c").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const DepthImage d = io::read_depth(tmp / "c" / "depth" / "000000.png", 5000.0f);
  const LabelImage labels = io::read_labels(tmp / "c" / "labels" / "000000.png");
  const nlohmann::json cats = read_json(tmp / "c" / "categories.json");
  int mirror_id = -1;
  for (const auto& c : cats["categories"])
    if (c["name"] == "mirror") mirror_id = c["id"];
  ASSERT_GT(mirror_id, 0);
  size_t mirror_px = 0, zero_px = 0;
  for (size_t k = 0; k < d.size(); ++k) {
    zero_px += d[k] == 0.0f;
    mirror_px += labels[k] == mirror_id;
  }
  EXPECT_GT(mirror_px, 0u);
  EXPECT_GT(zero_px, mirror_px / 2) << "the mirror glass (most of the mirror category) has no depth";
  // --mirror-depth virtual: the glass reports the mirrored room behind it, farther than the glass
  // (the surface depth of frame 0 of run a, same pose), everything else as with surface depth.
  const auto v = run_rrg("synth --preset mirror_room --frames 1 --width 48 --height 36 --novel 0 --mirror-depth virtual --out " +
                         (tmp / "v").string());
  ASSERT_EQ(v.exit_code, 0) << v.output;
  const auto s = run_rrg("synth --preset mirror_room --frames 1 --width 48 --height 36 --novel 0 --out " + (tmp / "s").string());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const DepthImage virt = io::read_depth(tmp / "v" / "depth" / "000000.png", 5000.0f);
  const DepthImage surf = io::read_depth(tmp / "s" / "depth" / "000000.png", 5000.0f);
  size_t behind = 0, same_elsewhere = 0, elsewhere = 0;
  for (size_t k = 0; k < d.size(); ++k) {
    if (d[k] == 0.0f && surf[k] > 0.0f) {  // the glass (zeroed by invalid)
      behind += virt[k] > surf[k] + 0.3f;
    } else {
      ++elsewhere;
      same_elsewhere += virt[k] == surf[k];
    }
  }
  EXPECT_GT(behind, zero_px * 9 / 10) << "the glass reports the room behind it";
  EXPECT_EQ(same_elsewhere, elsewhere) << "only the glass changes";
  EXPECT_EQ(slurp(tmp / "v" / "rgb" / "000000.png"), slurp(tmp / "s" / "rgb" / "000000.png"));
  EXPECT_EQ(read_json(tmp / "v" / "scene.json")["parameters"]["mirror_depth"], "virtual");
}

// --exposure scales each frame's colour by the gain of its timestamp (clipped to 1, then 8-bit)
// and leaves depth and the held-out views alone.
TEST(SynthCli, ExposureScalesTheFramesColourOnly) {
  TempDir tmp("synth-exposure");
  const std::string common = "synth --preset office --frames 40 --width 40 --height 30 --novel 1 --seed 5 ";
  ASSERT_EQ(run_rrg(common + "--out " + (tmp / "a").string()).exit_code, 0);
  ASSERT_EQ(run_rrg(common + "--exposure --out " + (tmp / "b").string()).exit_code, 0);
  EXPECT_EQ(read_json(tmp / "b" / "scene.json")["parameters"]["exposure"], true);
  EXPECT_EQ(read_json(tmp / "a" / "scene.json")["parameters"]["exposure"], false);
  for (const char* f : {"depth/000017.png", "novel/rgb/000000.png", "groundtruth.txt"})
    EXPECT_EQ(slurp(tmp / "a" / f), slurp(tmp / "b" / f)) << f;
  const io::Trajectory gt = io::read_tum_trajectory(tmp / "a" / "groundtruth.txt");
  float lo = 2.0f, hi = 0.0f;
  for (size_t i = 0; i < gt.size(); i += 13) {
    char name[32];
    std::snprintf(name, sizeof(name), "rgb/%06zu.png", i);
    const ColorImage a = io::read_color(tmp / "a" / name), b = io::read_color(tmp / "b" / name);
    const float g = exposure_gain(gt[i].timestamp, 5);
    lo = std::min(lo, g);
    hi = std::max(hi, g);
    for (size_t k = 0; k < a.size(); ++k)
      for (int c = 0; c < 3; ++c)  // both rounded to 8 bits: a's rounding is scaled by g
        ASSERT_NEAR(b[k][c], std::min(1.0f, g * a[k][c]), (0.5f + 0.5f * g) / 255.0f + 1e-6f) << name;
  }
  EXPECT_GE(lo, 1.0f / 1.35f - 1e-6f);
  EXPECT_LE(hi, 1.35f + 1e-6f);
  EXPECT_GT(hi / lo, 1.2f);  // 40 frames at 30 fps span enough of the drift to matter
}

TEST(SynthCli, ErrorsAndList) {
  TempDir tmp("synth-err");
  const auto bad = run_rrg("synth --preset kitchen --frames 2 --out " + (tmp / "x").string());
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("unknown preset 'kitchen'"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("living_room, mirror_room, office, open_plan"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(tmp / "x")) << "nothing written on a bad preset";
  const auto zero = run_rrg("synth --frames 0 --out " + (tmp / "y").string());
  EXPECT_EQ(zero.exit_code, 1);
  EXPECT_NE(zero.output.find("--frames must be > 0"), std::string::npos) << zero.output;
  const auto huge = run_rrg("synth --frames 1 --width 9000 --out " + (tmp / "y").string());
  EXPECT_EQ(huge.exit_code, 1);
  EXPECT_NE(huge.output.find("image size"), std::string::npos) << huge.output;
  const auto mirror = run_rrg("synth --frames 1 --mirror-depth glass --out " + (tmp / "y").string());
  EXPECT_EQ(mirror.exit_code, 1);
  EXPECT_NE(mirror.output.find("--mirror-depth"), std::string::npos) << mirror.output;
  const auto no_out = run_rrg("synth --frames 1");
  EXPECT_EQ(no_out.exit_code, 1);
  EXPECT_NE(no_out.output.find("--out"), std::string::npos) << no_out.output;
  const auto usage = run_rrg("synth --frames abc --out " + (tmp / "y").string());
  EXPECT_NE(usage.exit_code, 0) << "CLI11 usage error";
  EXPECT_NE(usage.exit_code, 1) << "usage errors are CLI11's, not the command's";
  // --preview writes a 2 x 2 contact sheet of frame 0 and nothing else.
  const auto preview = run_rrg("synth --preset mirror_room --width 40 --height 30 --preview " + (tmp / "p.png").string());
  ASSERT_EQ(preview.exit_code, 0) << preview.output;
  const ColorImage sheet = io::read_color(tmp / "p.png");
  EXPECT_EQ(sheet.width(), 80);
  EXPECT_EQ(sheet.height(), 60);
  const auto list = run_rrg("synth --list");
  EXPECT_EQ(list.exit_code, 0);
  for (const char* p : {"living_room", "mirror_room", "office"}) EXPECT_NE(list.output.find(p), std::string::npos);
}

}  // namespace
}  // namespace rrg::synth
