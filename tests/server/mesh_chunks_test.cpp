// The browser viewer's mesh chunks (server/mesh_chunks.h, docs/viewer.md): the chunks together
// are the whole mesh (no triangle lost or doubled at chunk borders), a chunk whose ETag did not
// change after more frames has exactly the mesh a fresh extraction gives, and chunk keys parse
// strictly.
#include "core/io/dataset.h"
#include "core/io/draco_mesh.h"
#include "core/slam/runner.h"
#include "core/slam/session.h"
#include "server/mesh_chunks.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <map>

namespace rrg::server {
namespace {

TEST(MeshChunks, KeysParseStrictly) {
  EXPECT_EQ(MeshChunks::parse_key("1_2_3"), Eigen::Vector3i(1, 2, 3));
  EXPECT_EQ(MeshChunks::parse_key("-1_0_-5"), Eigen::Vector3i(-1, 0, -5));
  EXPECT_EQ(MeshChunks::key_of({-1, 0, -5}), "-1_0_-5");
  for (const char* bad : {"", "1_2", "1_2_3_", "a_b_c", "1__2_3", "1_2_3x", "+1_2_3", "1 _2_3", "99999999999_0_0"})
    EXPECT_FALSE(MeshChunks::parse_key(bad)) << bad;
}

class MeshChunksSession : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::run_rrg("synth --preset mirror_room --frames 8 --width 160 --height 120 --novel 0 --out " +
                                 (dir_.path() / "seq").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    dataset_ = io::open_dataset(dir_.path() / "seq");
    session_ = std::make_unique<Session>(config());
  }
  SessionConfig config() const {
    SessionConfig c;
    c.K = dataset_->intrinsics();
    c.tsdf.voxel_size = 0.02f;  // a coarse map keeps the CPU test fast
    c.tsdf.truncation = 0.08f;
    c.semantics = "none";
    c.gt_poses = true;
    c.sync = true;
    c.mapping.iterations = 2;
    return c;
  }
  // patch_only: depth only in a 12x12-pixel window at the centre, so the frame fuses a small region.
  void process(size_t i, bool patch_only = false) { process(*session_, i, patch_only); }
  void process(Session& session, size_t i, bool patch_only = false) {
    io::Frame f = dataset_->load(i);
    const Eigen::Isometry3f T_wc = f.T_wc_gt->cast<float>();
    SessionFrame s = to_session_frame(std::move(f));
    if (patch_only)
      for (int y = 0; y < s.depth.height(); ++y)
        for (int x = 0; x < s.depth.width(); ++x)
          if (std::abs(x - s.depth.width() / 2) > 6 || std::abs(y - s.depth.height() / 2) > 6) s.depth(x, y) = 0;
    s.pose = T_wc;
    session.process(s);
  }
  // key -> (etag, Draco bytes) of every chunk
  static std::map<std::string, std::pair<std::string, std::vector<uint8_t>>> all(MeshChunks& chunks, const Session& s) {
    std::map<std::string, std::pair<std::string, std::vector<uint8_t>>> out;
    for (const MeshChunkInfo& c : chunks.list(s)) {
      const MeshChunkData d = chunks.get(s, c.key);
      EXPECT_EQ(d.etag, c.etag) << c.key;
      out[c.key] = {d.etag, *d.drc};
    }
    return out;
  }

  test::TempDir dir_{"mesh_chunks"};
  std::unique_ptr<io::Dataset> dataset_;
  std::unique_ptr<Session> session_;
};

TEST_F(MeshChunksSession, ChunksAreTheWholeMeshAndUnchangedEtagsMeanUnchangedMeshes) {
  for (size_t i = 0; i < 3; ++i) process(i);
  MeshChunks chunks;
  const auto first = all(chunks, *session_);
  ASSERT_GT(first.size(), 1u);
  size_t triangles = 0;
  for (const auto& [key, c] : first)
    if (!c.second.empty()) triangles += io::decode_draco(c.second).triangles.size();
  // Every cube belongs to exactly one block and every block to one chunk: the same triangle count
  // as the whole-volume extraction (Draco keeps the face count).
  EXPECT_EQ(triangles, session_->mesh().triangles.size());

  // No new frame: same ETags, served from the cache.
  const auto again = all(chunks, *session_);
  for (const auto& [key, c] : first) EXPECT_EQ(again.at(key).first, c.first) << key;
  EXPECT_THROW(chunks.get(*session_, "1_2"), std::invalid_argument);
  EXPECT_THROW(chunks.get(*session_, "100000_0_0"), std::out_of_range);

  // A frame that fuses a small region: a chunk that kept its ETag has exactly the bytes a fresh
  // table encodes now.
  process(3, true);
  const auto later = all(chunks, *session_);
  MeshChunks fresh;
  const auto now = all(fresh, *session_);
  ASSERT_EQ(later.size(), now.size());
  size_t kept = 0, changed = 0;
  for (const auto& [key, c] : later) {
    const auto it = first.find(key);
    if (it != first.end() && it->second.first == c.first) {
      ++kept;
      EXPECT_EQ(c.second, now.at(key).second) << "chunk " << key << " kept its ETag but its mesh changed";
    } else {
      ++changed;
    }
  }
  EXPECT_GT(changed, 0u);  // the new frame fused somewhere
  EXPECT_GT(kept, 0u);     // ... but not everywhere
  std::printf("[mesh chunks] %zu chunks: %zu kept their ETag, %zu changed or new\n", later.size(), kept, changed);
}

// A session that streams its TSDF (tsdf.stream_radius) serves the same chunks, ETags and bytes,
// as one that holds every block, after the first frames and after one more: the chunks of blocks
// in host memory are listed and meshed too, and reading them leaves them there.
TEST_F(MeshChunksSession, AStreamedSessionServesTheSameChunks) {
  SessionConfig c = config();
  c.stream_radius = 0.5f;  // less than the distance to any wall: nearly every block goes out
  Session streamed(c);
  MeshChunks held_chunks, streamed_chunks;
  for (size_t i = 0; i < 8; ++i) {
    process(i, i == 7);
    process(streamed, i, i == 7);
    if (i != 5 && i != 7) continue;
    const SessionStatus st = streamed.status();
    ASSERT_LT(st.resident_blocks, st.tsdf_blocks / 2) << "too little was streamed out to test anything";
    const auto a = all(held_chunks, *session_), b = all(streamed_chunks, streamed);
    ASSERT_GT(a.size(), 1u);
    ASSERT_EQ(a.size(), b.size());
    for (const auto& [key, chunk] : a) {
      ASSERT_TRUE(b.count(key)) << key;
      EXPECT_EQ(b.at(key).first, chunk.first) << key;
      EXPECT_EQ(b.at(key).second, chunk.second) << "chunk " << key << " meshed differently";
    }
    EXPECT_EQ(streamed.status().resident_blocks, st.resident_blocks) << "serving chunks left blocks resident";
  }
}

}  // namespace
}  // namespace rrg::server
