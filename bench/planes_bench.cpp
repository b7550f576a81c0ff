// Reflective plane identification at 640x480 on the CPU (like CAPE): segmentation, association
// into the global plane table, and a whole identification step (labels cue, C_var given). The
// scene is analytic: a room corner (floor, two walls) with a table top and a box, seen from a
// camera sliding sideways so association sees a moving view. Reports ms per call.
#include "core/planes/plane_identification.h"
#include "core/planes/semantic_labels.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <limits>
#include <vector>

namespace {

struct BenchFrame {
  rrg::Intrinsics K{525.0f, 525.0f, 319.5f, 239.5f, 640, 480};
  rrg::DepthImage depth;
  rrg::ColorImage color;
  rrg::LabelImage labels;
  rrg::Image<float> cvar;
};

// Camera looks along +z; y down. Planes (camera frame): floor y = 1.2, back wall z = 4, side wall
// x = -1.8, table top y = 0.45 for |x| < 0.5, 2 < z < 3, box front z = 2.5 for 0.8 < x < 1.4, y > 0.2.
BenchFrame make_frame() {
  BenchFrame f;
  f.depth = rrg::DepthImage(640, 480, 0.0f);
  f.color = rrg::ColorImage(640, 480, rrg::Color(0.5f, 0.5f, 0.5f));
  f.labels = rrg::LabelImage(640, 480, 0);
  f.cvar = rrg::Image<float>(640, 480, 0.0f);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) {
      const Eigen::Vector3f r((u - 319.5f) / 525.0f, (v - 239.5f) / 525.0f, 1.0f);
      float best = std::numeric_limits<float>::infinity();
      uint16_t label = 0;
      auto hit = [&](float z, uint16_t l, bool inside) {
        if (inside && z > 0.1f && z < best) best = z, label = l;
      };
      if (r.y() > 1e-6f) hit(1.2f / r.y(), 1, true);                  // floor
      hit(4.0f, 2, true);                                             // back wall
      if (r.x() < -1e-6f) hit(-1.8f / r.x(), 2, true);                // side wall
      if (r.y() > 1e-6f) {
        const float z = 0.45f / r.y();
        hit(z, 3, std::abs(r.x() * z) < 0.5f && z > 2.0f && z < 3.0f);  // table top
      }
      hit(2.5f, 4, r.x() * 2.5f > 0.8f && r.x() * 2.5f < 1.4f && r.y() * 2.5f > 0.2f);  // box
      if (std::isfinite(best)) {
        f.depth(u, v) = best;
        f.labels(u, v) = label;
        if (label == 1 && u % 8 == 0) f.cvar(u, v) = 0.05f;
      }
    }
  return f;
}

rrg::CategoryTable categories() {
  rrg::CategoryTable t;
  t.names = {{1, "floor"}, {2, "wall"}, {3, "table"}, {4, "closet"}};
  return t;
}

void BM_SegmentPlanes(benchmark::State& state) {
  const BenchFrame f = make_frame();
  size_t planes = 0;
  for (auto _ : state) {
    const auto seg = rrg::segment_planes(f.depth, f.K);
    planes = seg.planes.size();
    benchmark::DoNotOptimize(seg.labels.data());
  }
  state.counters["planes"] = double(planes);
}

void BM_AssociatePlanes(benchmark::State& state) {
  const BenchFrame f = make_frame();
  const auto seg = rrg::segment_planes(f.depth, f.K);
  rrg::GlobalPlaneTable table;
  int64_t frame = 0;
  for (auto _ : state) {
    Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
    T.translation().x() = 0.01f * float(frame % 50);
    const auto obs = table.observe(seg, f.depth, f.K, T);
    const auto a = table.associate(obs, frame * 10);
    benchmark::DoNotOptimize(table.global_map(seg.labels, a).data());
    ++frame;
  }
  state.counters["global_planes"] = double(table.live_ids().size());
}

void BM_IdentifyStep(benchmark::State& state) {
  const BenchFrame f = make_frame();
  rrg::PlaneIdentifier id({}, rrg::make_label_semantics(categories(), rrg::paper_prompts()));
  int64_t frame = 0;
  for (auto _ : state) {
    Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
    T.translation().x() = 0.01f * float(frame % 50);
    const auto r = id.identify({&f.depth, &f.color, &f.labels, f.K, T, frame * 10}, f.cvar);
    benchmark::DoNotOptimize(r.reflection_mask.data());
    ++frame;
  }
  state.counters["L_ref"] = double(id.vote().lookup_table().size());
}

BENCHMARK(BM_SegmentPlanes)->Name("planes_segment_640x480/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AssociatePlanes)->Name("planes_associate_640x480/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_IdentifyStep)->Name("planes_identify_640x480/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
