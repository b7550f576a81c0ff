// Dataset readers: TUM association known answer, lazy opening and missing files, 7-Scenes on the
// committed real frames, Replica and synth layouts built here, detection, and calibration parsing.
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/io/synth_layout.h"
#include "core/io/trajectory.h"
#include "core/io/tum_association.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

namespace rrg::io {
namespace {

namespace fs = std::filesystem;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}
#define EXPECT_CONTAINS(text, fragment) EXPECT_NE(std::string(text).find(fragment), std::string::npos) << (text)

// Colour with a per-frame marker in red, depth of `metres` everywhere but pixel (0,0) = invalid.
void write_frame(const fs::path& color, const fs::path& depth, float marker, float metres, float scale, int w = 8,
                 int h = 6) {
  write_color_png(color, ColorImage(w, h, Color(marker, 0.5f, 0.25f)));
  DepthImage d(w, h, metres);
  d[0] = 0.0f;
  write_depth_png(depth, d, scale);
}

Eigen::Isometry3d pose(double angle, double tx) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(tx, 2.0, -1.0);
  return T;
}

// The hand-built TUM association case (see AssociationKnownAnswer): rgb r0..r4, depth d0..d4.
const double kRgb[] = {10.000, 10.100, 10.200, 10.212, 10.900};
const double kDepth[] = {10.005, 10.108, 10.186, 10.209, 10.400};

TEST(TumAssociation, KnownAnswerIsGreedyBySmallestDifference) {
  // Candidates under 0.02 s: r0-d0 .005, r1-d1 .008, r2-d2 .014, r2-d3 .009, r3-d3 .003.
  // Greedy takes r3-d3 first, so r2 (whose nearest depth is d3) gets d2; r4 has no partner.
  const auto m = associate_stamps(kRgb, kDepth, 0.02);
  const std::vector<std::pair<size_t, size_t>> expected = {{0, 0}, {1, 1}, {2, 2}, {3, 3}};
  EXPECT_EQ(m, expected);
  // Shuffled depth order gives the same stamps; indices follow the input order.
  const double shuffled[] = {10.209, 10.400, 10.005, 10.186, 10.108};
  const auto s = associate_stamps(kRgb, shuffled, 0.02);
  const std::vector<std::pair<size_t, size_t>> expected_s = {{0, 2}, {1, 4}, {2, 3}, {3, 0}};
  EXPECT_EQ(s, expected_s);
  EXPECT_TRUE(associate_stamps(kRgb, kDepth, 0.001).empty());
  const double sorted[] = {1.0, 2.0, 3.0};
  EXPECT_EQ(nearest_stamp(sorted, 2.4, 0.5), 1u);
  EXPECT_EQ(nearest_stamp(sorted, 2.6, 0.5), 2u);
  EXPECT_FALSE(nearest_stamp(sorted, 3.6, 0.5));
}

// A TUM folder with the association case above, a camera.json-free name and groundtruth.txt.
fs::path make_tum(const test::TempDir& dir, const std::string& name = "rgbd_dataset_freiburg2_mini") {
  const fs::path root = dir / name;
  std::ofstream rgb_txt, depth_txt;
  fs::create_directories(root);
  rgb_txt.open(root / "rgb.txt");
  depth_txt.open(root / "depth.txt");
  rgb_txt << "# color images\n# file: 'mini'\n# timestamp filename\n";
  depth_txt << "# depth maps\n";
  for (int i = 0; i < 5; ++i) {
    char rn[64], dn[64];
    std::snprintf(rn, sizeof(rn), "rgb/%.6f.png", kRgb[i]);
    std::snprintf(dn, sizeof(dn), "depth/%.6f.png", kDepth[i]);
    rgb_txt << std::fixed << kRgb[i] << " " << rn << "\n";
    depth_txt << std::fixed << kDepth[i] << " " << dn << "\n";
    write_frame(root / rn, root / dn, 0.1f * float(i), 1.0f + 0.5f * float(i), 5000.0f, 640, 480);
  }
  // GT at 10.000 (A), 10.150 (B), 10.205 (C): r0 -> A, r1 none (0.05 s away), r2 -> C, r3 -> C.
  write_tum_trajectory(root / "groundtruth.txt", {{10.150, pose(0.2, 2.0)}, {10.000, pose(0.1, 1.0)},
                                                  {10.205, pose(0.3, 3.0)}});
  return root;
}

TEST(TumDataset, OpensLazilyAssociatesAndLoads) {
  test::TempDir dir("io-tum");
  const fs::path root = make_tum(dir);
  const auto ds = open_dataset(root);
  EXPECT_EQ(ds->format(), DatasetFormat::Tum);
  ASSERT_EQ(ds->size(), 4u);
  EXPECT_FLOAT_EQ(ds->intrinsics().fx, 520.9f);  // freiburg2 from the folder name
  EXPECT_FLOAT_EQ(ds->intrinsics().cy, 249.7f);
  EXPECT_EQ(ds->intrinsics().width, 640);
  EXPECT_EQ(ds->depth_scale(), 5000.0f);
  ASSERT_TRUE(ds->has_ground_truth());
  const Trajectory gt = ds->ground_truth();
  ASSERT_EQ(gt.size(), 3u);
  EXPECT_EQ(gt[0].timestamp, 10.0);
  EXPECT_EQ(gt[1].timestamp, 10.2);
  const Frame f2 = ds->load(2);
  EXPECT_EQ(f2.timestamp, 10.2);
  EXPECT_EQ(f2.depth_path.filename(), "10.186000.png");  // r2 got d2, not its nearest d3
  EXPECT_NEAR(f2.depth(5, 5), 2.0f, 0.5f / 5000.0f);
  EXPECT_EQ(f2.depth(0, 0), 0.0f);
  EXPECT_NEAR(f2.color(3, 3).x(), 0.2f, 0.5f / 255.0f);
  ASSERT_TRUE(f2.T_wc_gt);
  EXPECT_TRUE(f2.T_wc_gt->isApprox(pose(0.3, 3.0), 1e-9));
  EXPECT_FALSE(ds->load(1).T_wc_gt);  // nearest GT stamp is 0.05 s away
  EXPECT_THROW(ds->load(4), std::out_of_range);

  // camera.json replaces the freiburg guess and the default depth scale.
  std::ofstream(root / "camera.json") << R"({"width":640,"height":480,"fx":500,"fy":501,"cx":319.5,"cy":239.5,)"
                                      << R"("depth_scale":2500})";
  const auto ds2 = open_dataset(root);
  EXPECT_FLOAT_EQ(ds2->intrinsics().fy, 501.0f);
  EXPECT_EQ(ds2->depth_scale(), 2500.0f);
  EXPECT_NEAR(ds2->load(2).depth(5, 5), 4.0f, 1e-3f);
}

TEST(TumDataset, MissingListedFileIsNamed) {
  test::TempDir dir("io-tum");
  const fs::path root = make_tum(dir);
  fs::remove(root / "depth/10.108000.png");
  const std::string msg = error_of([&] { open_dataset(root); });
  EXPECT_CONTAINS(msg, "depth/10.108000.png");
  EXPECT_CONTAINS(msg, "missing");
}

TEST(TumDataset, NoCalibrationAsksForIntrinsics) {
  test::TempDir dir("io-tum");
  const fs::path root = make_tum(dir, "my_sequence");
  EXPECT_CONTAINS(error_of([&] { open_dataset(root); }), "--intrinsics");
  DatasetOptions o;
  o.intrinsics = parse_intrinsics("525,525,319.5,239.5");
  o.depth_scale = 1000.0f;
  const auto ds = open_dataset(root, o);
  EXPECT_EQ(ds->intrinsics().width, 640);  // from the first colour image
  EXPECT_EQ(ds->depth_scale(), 1000.0f);
  EXPECT_NEAR(ds->load(0).depth(1, 1), 5.0f, 1e-3f);  // 1 m stored at 5000/m read at 1000/m
}

TEST(TumDataset, SizeMismatchNamesBothFiles) {
  test::TempDir dir("io-tum");
  const fs::path root = make_tum(dir);
  write_depth_png(root / "depth/10.005000.png", DepthImage(320, 240, 1.0f), 5000.0f);
  const auto ds = open_dataset(root);
  const std::string msg = error_of([&] { ds->load(0); });
  EXPECT_CONTAINS(msg, "rgb/10.000000.png");
  EXPECT_CONTAINS(msg, "depth/10.005000.png");
}

TEST(SevenScenes, CommittedMiniLoads) {
  const fs::path root = test::test_data_dir() / "7scenes_mini";
  const auto ds = open_dataset(root);
  EXPECT_EQ(ds->format(), DatasetFormat::SevenScenes);
  ASSERT_EQ(ds->size(), 3u);
  EXPECT_EQ(ds->intrinsics().width, 640);
  EXPECT_EQ(ds->intrinsics().height, 480);
  EXPECT_EQ(ds->intrinsics().fx, 585.0f);
  EXPECT_EQ(ds->intrinsics().cy, 240.0f);
  EXPECT_EQ(ds->depth_scale(), 1000.0f);
  const Frame f = ds->load(1);
  EXPECT_NEAR(f.timestamp, 1.0 / 30.0, 1e-12);
  std::vector<float> valid;
  for (const float d : f.depth.pixels())
    if (d > 0) valid.push_back(d);
  ASSERT_GT(valid.size(), f.depth.size() / 2);
  std::sort(valid.begin(), valid.end());
  EXPECT_GE(valid.front(), 0.3f);
  EXPECT_LE(valid.back(), 8.0f);
  const float median = valid[valid.size() / 2];
  EXPECT_GT(median, 0.5f);
  EXPECT_LT(median, 5.0f);
  // The pose equals the 4x4 in the file up to re-orthonormalisation (the file rotation is off by ~1e-4).
  std::ifstream in(root / "frame-000001.pose.txt");
  Eigen::Matrix4d T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) in >> T(r, c);
  ASSERT_TRUE(f.T_wc_gt);
  EXPECT_LE((f.T_wc_gt->matrix() - T).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_EQ(f.T_wc_gt->translation(), (T.topRightCorner<3, 1>()));
  EXPECT_EQ(ds->ground_truth().size(), 3u);
}

TEST(SevenScenes, LayoutErrors) {
  test::TempDir dir("io-7s");
  write_frame(dir / "frame-000000.color.png", dir / "frame-000000.depth.png", 0.5f, 2.0f, 1000.0f);
  write_color_png(dir / "frame-000001.color.png", ColorImage(8, 6, Color::Zero()));  // no depth
  EXPECT_CONTAINS(error_of([&] { open_dataset(dir.path()); }), "frame-000001.depth.png");
  fs::remove(dir / "frame-000001.color.png");
  // No camera-intrinsics.txt: the named 7scenes calibration, which is 640x480.
  const auto ds = open_dataset(dir.path());
  EXPECT_EQ(ds->intrinsics().fx, 585.0f);
  EXPECT_FALSE(ds->has_ground_truth());
  EXPECT_CONTAINS(error_of([&] { ds->load(0); }), "intrinsics are for 640x480");
  // 65535 is "no reading" in 7-Scenes.
  DepthImage d(8, 6, 1.5f);
  d[3] = 65535.0f / 1000.0f;
  write_depth_png(dir / "frame-000000.depth.png", d, 1000.0f);
  std::ofstream(dir / "camera-intrinsics.txt") << "600 0 3.5\n0 600 2.5\n0 0 1\n";
  std::ofstream(dir / "frame-000000.pose.txt") << "1 0 0 0\n0 1 0 0\n0 0 2 0\n0 0 0 1\n";  // not rigid
  EXPECT_CONTAINS(error_of([&] { open_dataset(dir.path()); }), "frame-000000.pose.txt");
  std::ofstream(dir / "frame-000000.pose.txt") << "0 -1 0 1\n1 0 0 2\n0 0 1 3\n0 0 0 1\n";
  const auto ds2 = open_dataset(dir.path());
  EXPECT_EQ(ds2->intrinsics().fx, 600.0f);
  const Frame f = ds2->load(0);
  EXPECT_EQ(f.depth[3], 0.0f);
  EXPECT_FLOAT_EQ(f.depth[4], 1.5f);
  EXPECT_TRUE(f.T_wc_gt->translation().isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST(Replica, NiceSlamLayoutLoads) {
  test::TempDir dir("io-replica");
  const fs::path root = dir / "office0";
  std::ofstream traj;
  fs::create_directories(root / "results");
  traj.open(root / "traj.txt");
  for (int i = 0; i < 3; ++i) {
    char c[64], d[64];
    std::snprintf(c, sizeof(c), "results/frame%06d.png", i);
    std::snprintf(d, sizeof(d), "results/depth%06d.png", i);
    write_frame(root / c, root / d, 0.1f * float(i), 0.7f + float(i), 6553.5f);
    const Eigen::Matrix4d T = pose(0.1 * i, double(i)).matrix();
    for (int k = 0; k < 16; ++k) traj << T(k / 4, k % 4) << (k == 15 ? "\n" : " ");
  }
  traj.close();
  std::ofstream(dir / "cam_params.json")
      << R"({"camera":{"w":8,"h":6,"fx":300.0,"fy":301.0,"cx":3.5,"cy":2.5,"scale":6553.5}})";
  const auto ds = open_dataset(root);
  EXPECT_EQ(ds->format(), DatasetFormat::Replica);
  ASSERT_EQ(ds->size(), 3u);
  EXPECT_EQ(ds->depth_scale(), 6553.5f);
  EXPECT_EQ(ds->intrinsics().fy, 301.0f);  // cam_params.json from the parent folder
  const Frame f = ds->load(2);
  EXPECT_NEAR(f.depth(4, 4), 2.7f, 0.5f / 6553.5f + 1e-6f);
  EXPECT_NEAR(f.timestamp, 2.0 / 30.0, 1e-12);
  EXPECT_TRUE(f.T_wc_gt->isApprox(pose(0.2, 2.0), 1e-5));
  // Without cam_params.json: the options' intrinsics, default scale 6553.5, size from the image.
  fs::remove(dir / "cam_params.json");
  DatasetOptions o;
  o.intrinsics = parse_intrinsics("4,4,3.5,2.5");
  const auto ds2 = open_dataset(root, o);
  EXPECT_EQ(ds2->intrinsics().width, 8);
  EXPECT_EQ(ds2->depth_scale(), 6553.5f);
  // A missing depth image is named.
  fs::remove(root / "results/depth000001.png");
  EXPECT_CONTAINS(error_of([&] { open_dataset(root, o); }), "depth000001.png");
}

TEST(Synth, LayoutReadsAsTumWithExtras) {
  test::TempDir dir("io-synth");
  const fs::path root = dir / "scene";
  fs::create_directories(root);
  std::ofstream rgb(root / "rgb.txt"), depth(root / "depth.txt"), gt(root / "groundtruth.txt");
  rgb << "# color images\n# timestamp filename\n";
  depth << "# depth maps\n# timestamp filename\n";
  gt << "# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i < 3; ++i) {
    char name[32], t[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    std::snprintf(t, sizeof(t), "%.6f", i / 30.0);
    rgb << t << " rgb/" << name << "\n";
    depth << t << " depth/" << name << "\n";
    gt << t << " " << i << " 0 0 0 0 0 1\n";
    write_frame(root / "rgb" / name, root / "depth" / name, 0.3f, 1.25f, 5000.0f, 4, 3);
    LabelImage labels(4, 3, uint16_t(7 + i));
    write_labels_png(synth_extra_path(root, "labels", size_t(i)), labels);
    MaskImage refl(4, 3);
    refl[1] = 1;
    write_mask_png(synth_extra_path(root, "reflection", size_t(i)), refl);
  }
  rgb.close(), depth.close(), gt.close();
  std::ofstream(root / "camera.json") << R"({"width":4,"height":3,"fx":2,"fy":2,"cx":1.5,"cy":1,"depth_scale":5000})";
  std::ofstream(root / "scene.json") << "{}";
  const auto ds = open_dataset(root);
  EXPECT_EQ(ds->format(), DatasetFormat::Synth);
  ASSERT_EQ(ds->size(), 3u);
  EXPECT_EQ(ds->intrinsics().cx, 1.5f);
  const Frame f = ds->load(2);
  EXPECT_NEAR(f.timestamp, 0.066667, 1e-9);
  EXPECT_TRUE(f.T_wc_gt->translation().isApprox(Eigen::Vector3d(2, 0, 0)));
  EXPECT_EQ(synth_extra_path(root, "reflection", 2), root / "reflection" / "000002.png");
  EXPECT_EQ(read_synth_labels(root, 2)[5], 9);
  EXPECT_EQ(read_synth_reflection(root, 0)[1], 1);
  EXPECT_CONTAINS(error_of([&] { read_synth_planes(root, 0); }), "planes/000000.png");
  EXPECT_THROW(synth_extra_path(root, "normals", 0), std::invalid_argument);
  EXPECT_EQ(synth_scene_file(root, "mesh_gt.ply"), root / "mesh_gt.ply");
}

TEST(Detection, EachLayoutAndEmpty) {
  test::TempDir dir("io-detect");
  auto touch = [](const fs::path& p) {
    fs::create_directories(p.parent_path());
    std::ofstream(p) << "";
  };
  touch(dir / "s/scene.json"), touch(dir / "s/rgb.txt"), touch(dir / "s/depth.txt");
  touch(dir / "t/rgb.txt"), touch(dir / "t/depth.txt");
  touch(dir / "r/results/frame000000.jpg"), touch(dir / "r/traj.txt");
  touch(dir / "7/frame-000000.pose.txt");
  touch(dir / "3/frame-000000.color.png");
  fs::create_directories(dir / "empty");
  EXPECT_EQ(detect_dataset_format(dir / "s"), DatasetFormat::Synth);
  EXPECT_EQ(detect_dataset_format(dir / "t"), DatasetFormat::Tum);
  EXPECT_EQ(detect_dataset_format(dir / "r"), DatasetFormat::Replica);
  EXPECT_EQ(detect_dataset_format(dir / "7"), DatasetFormat::SevenScenes);
  EXPECT_EQ(detect_dataset_format(dir / "3"), DatasetFormat::SevenScenes);
  const std::string msg = error_of([&] { detect_dataset_format(dir / "empty"); });
  for (const char* what : {"scene.json", "rgb.txt", "traj.txt", "frame-*.color.*"}) EXPECT_CONTAINS(msg, what);
  EXPECT_CONTAINS(error_of([&] { open_dataset(dir / "nowhere"); }), "not found");
  EXPECT_CONTAINS(error_of([&] { open_dataset(dir / "t"); }), "no rgb.txt / depth.txt pairs");
}

TEST(Calibration, ParseIntrinsicsNamesValuesErrors) {
  const Intrinsics fr1 = parse_intrinsics("freiburg1");
  EXPECT_EQ(fr1.fx, 517.3f);
  EXPECT_EQ(fr1.cy, 255.3f);
  EXPECT_EQ(fr1.width, 640);
  EXPECT_EQ(parse_intrinsics("fr3").fy, 539.2f);
  EXPECT_EQ(parse_intrinsics("FR2").cx, 325.1f);
  EXPECT_EQ(parse_intrinsics("7scenes").fx, 585.0f);
  const Intrinsics rep = parse_intrinsics("replica");
  EXPECT_EQ(rep.width, 1200);
  EXPECT_EQ(rep.cy, 339.5f);
  const Intrinsics k = parse_intrinsics("525.5, 524,319.5,239.25");
  EXPECT_EQ(k.fx, 525.5f);
  EXPECT_EQ(k.cy, 239.25f);
  EXPECT_EQ(k.width, 0);
  for (const char* bad : {"", "kinect", "1,2,3", "1,2,3,4,5", "0,1,2,3", "a,b,c,d", "-5,5,1,1"}) {
    try {
      parse_intrinsics(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_CONTAINS(e.what(), "'" + std::string(bad) + "'");
      EXPECT_CONTAINS(e.what(), "fx,fy,cx,cy");
      EXPECT_CONTAINS(e.what(), "freiburg1");
    }
  }
  DatasetFlags flags;
  flags.intrinsics = "nope";
  EXPECT_CONTAINS(error_of([&] { flags.to_options(); }), "--intrinsics");
  flags.intrinsics = "fr1";
  flags.depth_scale = -1.0f;
  EXPECT_CONTAINS(error_of([&] { flags.to_options(); }), "--depth-scale");
  flags.depth_scale = 1000.0f;
  flags.format = "replica";
  const DatasetOptions o = flags.to_options();
  EXPECT_EQ(o.format, DatasetFormat::Replica);
  EXPECT_EQ(*o.depth_scale, 1000.0f);
  EXPECT_EQ(o.intrinsics->fx, 517.3f);
  flags.format = "kitti";
  EXPECT_CONTAINS(error_of([&] { flags.to_options(); }), "--format");
  for (auto f : {DatasetFormat::Auto, DatasetFormat::Tum, DatasetFormat::SevenScenes, DatasetFormat::Replica,
                 DatasetFormat::Synth})
    EXPECT_EQ(parse_dataset_format(to_string(f)), f);
}

}  // namespace
}  // namespace rrg::io
