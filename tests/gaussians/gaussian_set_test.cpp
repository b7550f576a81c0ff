// Gaussian storage: host/device round trips, geometric growth without per-append reallocation,
// in-place pruning (also applied to side arrays), CPU/CUDA parity, and input errors.
#include "core/gaussians/gaussian_grads.h"
#include "core/gaussians/gaussian_set.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace rrg {
namespace {

// n Gaussians whose every field encodes its id, so moves can be traced.
GaussianHost tagged(int n, int degree, int first_id = 0) {
  GaussianHost g(degree);
  g.resize(size_t(n));
  const int K = g.sh_coeffs();
  for (int i = 0; i < n; ++i) {
    const float id = float(first_id + i);
    g.means[i] = {id, id + 0.5f, -id};
    g.log_scales[i] = Eigen::Vector3f::Constant(-id);
    g.quats[i] = {1.0f, id, 0, 0};
    g.logit_opacities[i] = id;
    for (int k = 0; k < K; ++k) g.sh[size_t(i) * K + k] = Eigen::Vector3f(id, float(k), id * k);
    g.plane_ids[i] = first_id + i;
  }
  return g;
}

void expect_consistent(const GaussianHost& h) {
  const int K = h.sh_coeffs();
  for (size_t i = 0; i < h.size(); ++i) {
    const float id = h.logit_opacities[i];
    ASSERT_EQ(h.means[i], Eigen::Vector3f(id, id + 0.5f, -id)) << i;
    ASSERT_EQ(h.log_scales[i].x(), -id);
    ASSERT_EQ(h.quats[i][1], id);
    ASSERT_EQ(h.plane_ids[i], int32_t(id));
    for (int k = 0; k < K; ++k) ASSERT_EQ(h.sh[i * K + k], Eigen::Vector3f(id, float(k), id * k));
  }
}

TEST(GaussianSet, RoundTripsThroughEveryDevice) {
  for (const Device& d : available_devices()) {
    SCOPED_TRACE(d.to_string());
    const GaussianHost h = tagged(37, 3);
    const GaussianSet s = GaussianSet::from_host(h, d);
    EXPECT_EQ(s.size(), 37u);
    EXPECT_EQ(s.sh_coeffs(), 16);
    const GaussianHost back = s.to_host();
    EXPECT_EQ(back.means, h.means);
    EXPECT_EQ(back.sh, h.sh);
    EXPECT_EQ(back.plane_ids, h.plane_ids);
  }
}

// copy() is a device-side copy: every field equal, and independent of the original afterwards.
TEST(GaussianSet, CopyIsEqualAndIndependentOnEveryDevice) {
  for (const Device& d : available_devices()) {
    SCOPED_TRACE(d.to_string());
    GaussianSet s = GaussianSet::from_host(tagged(37, 3), d);
    s.append(tagged(5, 3, 37));  // capacity above size: copy() takes size() Gaussians
    const GaussianSet c = s.copy();
    EXPECT_EQ(c.size(), 42u);
    EXPECT_EQ(c.sh_degree(), 3);
    EXPECT_EQ(c.device(), d);
    const GaussianHost want = s.to_host(), got = c.to_host();
    EXPECT_EQ(got.means, want.means);
    EXPECT_EQ(got.log_scales, want.log_scales);
    EXPECT_EQ(got.quats, want.quats);
    EXPECT_EQ(got.logit_opacities, want.logit_opacities);
    EXPECT_EQ(got.sh, want.sh);
    EXPECT_EQ(got.plane_ids, want.plane_ids);
    expect_consistent(got);
    std::vector<uint8_t> keep(s.size(), 0);  // empty the original: the copy keeps its Gaussians
    s.prune(keep);
    s.append(tagged(3, 3, 100));
    EXPECT_EQ(c.to_host().means, want.means);
    EXPECT_EQ(GaussianSet(2, d).copy().size(), 0u);
  }
}

// assign() copies into the set's own buffers while they are large enough (no new allocation), grows
// them when not, and refuses a source of another SH degree.
TEST(GaussianSet, AssignReusesCapacityOnEveryDevice) {
  for (const Device& d : available_devices()) {
    SCOPED_TRACE(d.to_string());
    GaussianSet dst = GaussianSet::from_host(tagged(50, 3, 500), d);
    const Eigen::Vector3f* storage = dst.means().data;
    const GaussianSet small = GaussianSet::from_host(tagged(20, 3), d);
    dst.assign(small);
    EXPECT_EQ(dst.size(), 20u);
    EXPECT_EQ(dst.capacity(), 50u);
    EXPECT_EQ(dst.means().data, storage);  // refilled in place
    GaussianHost got = dst.to_host();
    EXPECT_EQ(got.means, small.to_host().means);
    EXPECT_EQ(got.sh, small.to_host().sh);
    expect_consistent(got);
    const GaussianSet big = GaussianSet::from_host(tagged(80, 3, 1000), d);
    dst.assign(big);  // grows
    EXPECT_EQ(dst.size(), 80u);
    EXPECT_GE(dst.capacity(), 80u);
    got = dst.to_host();
    EXPECT_EQ(got.plane_ids, big.to_host().plane_ids);
    EXPECT_EQ(got.quats, big.to_host().quats);
    expect_consistent(got);
    dst.assign(dst);  // self: unchanged
    EXPECT_EQ(dst.to_host().means, got.means);
    EXPECT_THROW(dst.assign(GaussianSet(1, d)), std::invalid_argument);
    EXPECT_EQ(dst.size(), 80u);  // a refused assign leaves the set as it was
  }
}

TEST(GaussianSet, AppendGrowsGeometricallyAndKeepsStorageWithinCapacity) {
  GaussianSet s(1, Device::cpu());
  s.append(tagged(100, 1));
  EXPECT_EQ(s.capacity(), 100u);
  s.append(tagged(10, 1, 100));
  EXPECT_EQ(s.size(), 110u);
  EXPECT_EQ(s.capacity(), 150u);  // 1.5x
  const Eigen::Vector3f* before = s.means().data;
  s.append(tagged(40, 1, 110));   // fits: no reallocation
  EXPECT_EQ(s.means().data, before);
  EXPECT_EQ(s.capacity(), 150u);
  const GaussianHost h = s.to_host();
  ASSERT_EQ(h.size(), 150u);
  for (size_t i = 0; i < h.size(); ++i) ASSERT_EQ(h.logit_opacities[i], float(i));
  expect_consistent(h);
}

TEST(GaussianSet, PruneCompactsInPlaceOnEveryDevice) {
  const int n = 1000;
  std::vector<uint8_t> keep(n);
  for (int i = 0; i < n; ++i) keep[i] = (i % 3 != 0) && i != 998;
  const size_t kept = size_t(std::count(keep.begin(), keep.end(), 1));
  const auto survivors = test::expect_device_parity<float>(
      [&](const Device& d) {
        GaussianSet s = GaussianSet::from_host(tagged(n, 2), d);
        const Eigen::Vector3f* before = s.means().data;
        // a side array (e.g. an Adam moment) with one word per Gaussian = its id
        std::vector<float> side(n);
        for (int i = 0; i < n; ++i) side[i] = float(i);
        auto side_d = Buffer<float>::from_host(side, d);
        const Compaction c = s.prune(keep);
        apply_compaction(c, {reinterpret_cast<uint32_t*>(side_d.data()), n}, 1, d);
        EXPECT_EQ(s.size(), kept);
        EXPECT_EQ(c.new_size, kept);
        EXPECT_EQ(s.means().data, before);  // no reallocation
        const GaussianHost h = s.to_host();
        expect_consistent(h);
        const auto side_h = side_d.to_host();
        for (size_t i = 0; i < kept; ++i) EXPECT_EQ(side_h[i], h.logit_opacities[i]) << i;
        return h.logit_opacities;
      },
      0.0);
  std::vector<float> sorted = survivors, expect;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < n; ++i)
    if (keep[i]) expect.push_back(float(i));
  EXPECT_EQ(sorted, expect);
}

TEST(GaussianSet, PruneEverythingAndGrowAgain) {
  GaussianSet s = GaussianSet::from_host(tagged(5, 0), Device::cpu());
  s.prune(std::vector<uint8_t>(5, 0));
  EXPECT_EQ(s.size(), 0u);
  s.append(tagged(3, 0, 7));
  expect_consistent(s.to_host());
  EXPECT_EQ(s.to_host().plane_ids, (std::vector<int32_t>{7, 8, 9}));
}

// A batch of lower SH degree (densification's DC-only Gaussians) lands with its bands and zeros
// above them, after Gaussians that keep all of theirs; the same on every device.
TEST(GaussianSet, AppendPadsALowerDegreeBatchOnEveryDevice) {
  test::expect_device_parity<float>(
      [](const Device& d) {
        GaussianSet s(3, d);
        s.append(tagged(5, 3));
        GaussianHost dc = tagged(7, 0, 100);
        s.append(dc);
        s.append(tagged(2, 1, 200));
        const GaussianHost h = s.to_host();
        EXPECT_EQ(h.sh_degree, 3);
        EXPECT_EQ(h.size(), 14u);
        const int K = h.sh_coeffs();  // 16
        std::vector<float> out;
        for (size_t i = 0; i < h.size(); ++i) {
          const float id = h.logit_opacities[i];
          const int kept = i < 5 ? K : (i < 12 ? 1 : 4);  // bands of the batch it came in
          EXPECT_EQ(h.means[i], Eigen::Vector3f(id, id + 0.5f, -id)) << i;
          EXPECT_EQ(h.plane_ids[i], int32_t(id)) << i;
          for (int k = 0; k < K; ++k) {
            const Eigen::Vector3f want = k < kept ? Eigen::Vector3f(id, float(k), id * k) : Eigen::Vector3f::Zero();
            EXPECT_EQ(h.sh[i * size_t(K) + size_t(k)], want) << "Gaussian " << i << " coefficient " << k;
            out.insert(out.end(), {h.sh[i * size_t(K) + size_t(k)].x(), h.sh[i * size_t(K) + size_t(k)].y()});
          }
        }
        return out;
      },
      0.0);
}

// The plane table merged instances 3 -> 1 and 5 -> 3 -> 1 (remap holds canonical ids); 7 is its own
// canonical id, 9 lies beyond the table, 2 maps to 0 (unknown): those keep their ids, as does 0.
TEST(GaussianSet, RemapPlaneIdsFollowsTheTablesMergesOnEveryDevice) {
  test::expect_device_parity<int32_t>(
      [](const Device& d) {
        GaussianHost h = tagged(7, 0);
        h.plane_ids = {0, 1, 3, 5, 7, 9, 2};
        GaussianSet s = GaussianSet::from_host(h, d);
        const std::vector<int32_t> remap = {0, 1, 0, 1, 4, 1, 6, 7};
        s.remap_plane_ids(remap);
        const GaussianHost out = s.to_host();
        EXPECT_EQ(out.plane_ids, (std::vector<int32_t>{0, 1, 1, 1, 7, 9, 2}));
        EXPECT_EQ(out.means, h.means);  // only the ids move
        s.remap_plane_ids({});          // an empty table changes nothing
        EXPECT_EQ(s.to_host().plane_ids, out.plane_ids);
        return out.plane_ids;
      },
      0.0);
}

TEST(GaussianSet, BadInputsAreNamed) {
  GaussianSet s(1, Device::cpu());
  GaussianHost h = tagged(4, 1);
  h.sh.pop_back();
  try {
    s.append(h);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sh has 15 entries, expected 16"), std::string::npos) << e.what();
  }
  EXPECT_THROW(s.append(tagged(2, 3)), std::invalid_argument);  // a batch of higher degree than the set
  s.append(tagged(2, 1));
  EXPECT_THROW(s.prune({1}), std::invalid_argument);
  EXPECT_THROW(GaussianSet(4, Device::cpu()), std::invalid_argument);
  EXPECT_EQ(s.size(), 2u);  // failed calls changed nothing
}

TEST(GaussianGrads, ResetZeroesToTheSetLayout) {
  GaussianGrads g;
  g.reset(7, 9, Device::cpu());
  EXPECT_EQ(g.v_sh.size(), 63u);
  EXPECT_EQ(g.v_quats.size(), 7u);
  for (const auto& q : g.v_quats.to_host()) EXPECT_TRUE(q.isZero());
}

}  // namespace
}  // namespace rrg
