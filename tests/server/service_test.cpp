// The service end to end against the real `rrg serve` on loopback: trajectories equal to an
// in-process Session's, four sessions at once, Draco / SPZ / PLY downloads that decode to the
// session's counts, renders, watch events, and save -> kill -9 -> load.
#include "client/lib/proto_convert.h"
#include "core/gaussians/spz.h"
#include "core/io/draco_mesh.h"
#include "core/io/frame_codec.h"
#include "tests/server/server_fixture.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <atomic>
#include <mutex>
#include <thread>

namespace rrg::test {
namespace {

using service::SessionHandle;

ServerProcess& shared_server() {
  static ServerProcess server({"--queue", "8"});
  return server;
}

SessionHandle create(service::ServiceClient& c) {
  const auto r = c.create(create_request());
  return {r.session_id(), r.token()};
}

// Every processed frame's pose equals the in-process Session's within 1e-4 m (and 1e-4 rad).
void expect_reference_trajectory(const std::vector<v1::FrameResult>& results, size_t begin = 0) {
  const io::Trajectory& ref = reference_trajectory();
  for (size_t k = 0; k < results.size(); ++k) {
    const auto& r = results[k];
    SCOPED_TRACE("frame " + std::to_string(r.id()));
    ASSERT_FALSE(r.has_error()) << r.error().message();
    ASSERT_FALSE(r.dropped());
    ASSERT_EQ(r.id(), begin + k);
    const Eigen::Isometry3d T = service::from_proto(r.pose()).cast<double>();
    const Eigen::Isometry3d& R = ref[r.id()].T_wc;
    EXPECT_LT((T.translation() - R.translation()).norm(), 1e-4);
    EXPECT_LT(Eigen::AngleAxisd(T.rotation().transpose() * R.rotation()).angle(), 1e-4);
    EXPECT_EQ(r.filled_pixels(), 0u);  // the glass has depth in this sequence: nothing to fill
  }
}

TEST(Service, StreamGivesTheInProcessSessionsTrajectory) {
  auto c = shared_server().client();
  const SessionHandle h = create(c);
  const auto results = stream_frames(c, h, 0, wire_frames().size());
  ASSERT_EQ(results.size(), wire_frames().size());
  expect_reference_trajectory(results);
  const v1::SessionInfo info = c.get(h);
  EXPECT_EQ(info.frames(), wire_frames().size());
  EXPECT_EQ(info.frames_dropped(), 0u);
  EXPECT_EQ(info.map_version(), reference_session().status().map_version);
  c.close(h);
}

// A sensor that loses the mirror's depth: the session fills it from the wall around the mirror
// (labels sent with the frames) and each FrameResult says how many pixels, and how many it kept
// out of ORB, as the in-process Session does on the same frames.
// rrg serve --set: every session's base config, under each Create's overrides; a Create naming sync
// or live chooses the schedule itself. Bad defaults stop the server before it binds, naming the key.
TEST(Service, ServerDefaultsApplyUnderEachCreatesOverrides) {
  ServerProcess server({"--set", "live=true", "--set", "mapping.iterations=2"});
  auto c = server.client();
  const auto schedule_of = [&](const std::map<std::string, std::string>& edits, const std::vector<std::string>& drop) {
    v1::CreateSessionRequest r = create_request();  // sync=true among its overrides
    for (const std::string& k : drop) r.mutable_config()->erase(k);
    for (const auto& [k, v] : edits) (*r.mutable_config())[k] = v;
    const auto created = c.create(r);
    return std::pair{SessionHandle{created.session_id(), created.token()}, created.info().schedule()};
  };
  const auto [live, live_schedule] = schedule_of({}, {"sync"});
  EXPECT_EQ(live_schedule, "live");  // the server's default
  EXPECT_EQ(schedule_of({}, {}).second, "sync");  // the client's sync=true replaces it
  EXPECT_EQ(schedule_of({{"live", "false"}}, {"sync"}).second, "overlapped");
  {  // a server without defaults
    auto plain = shared_server().client();
    v1::CreateSessionRequest r = create_request();
    r.mutable_config()->erase("sync");
    const auto created = plain.create(r);
    EXPECT_EQ(created.info().schedule(), "overlapped");
    plain.close({created.session_id(), created.token()});
  }
  // The live session maps and answers every frame.
  const auto results = stream_frames(c, live, 0, wire_frames().size());
  ASSERT_EQ(results.size(), wire_frames().size());
  for (const auto& r : results) EXPECT_FALSE(r.has_error() || r.dropped()) << r.id();
  const v1::SessionInfo info = c.get(live);
  EXPECT_EQ(info.frames(), wire_frames().size());
  EXPECT_EQ(info.schedule(), "live");
  EXPECT_GE(info.mapping_steps(), 1u);

  const auto refused = [](const std::string& args, const std::string& mention) {
    const auto [rc, out] = run_shell("timeout 60 " + rrg_executable().string() +
                                     " serve --address 127.0.0.1:0 --device cpu " + args + " 2>&1");
    EXPECT_NE(rc, 0) << args;
    EXPECT_NE(rc, 124) << args << ": it served";
    EXPECT_NE(out.find(mention), std::string::npos) << args << ": " << out;
  };
  refused("--set camera.fx=500", "camera.fx");
  refused("--set device=cuda", "--device");
  refused("--set tsdf.voxel_sise=0.01", "tsdf.voxel_sise");
  refused("--set tsdf.voxel_size=-1", "voxel");
  refused("--set sync=true --set live=true", "choose one");
}

TEST(Service, FramesReportTheDepthFilledOnALostMirror) {
  TempDir dir("rrg-lost-mirror");
  const auto synth = run_rrg("synth --preset mirror_room --frames 6 --width 160 --height 120 --novel 0 --threads 2 "
                             "--mirror-depth invalid --out " + dir.path().string());
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const v1::CreateSessionRequest req = create_request(dir.path());
  const std::vector<v1::Frame> frames = encode_sequence(dir.path());
  const std::vector<FrameReport> expected = process_in_process(req, frames);
  auto c = shared_server().client();
  const auto created = c.create(req);
  const SessionHandle h{created.session_id(), created.token()};
  std::vector<v1::FrameResult> results;
  std::mutex m;
  size_t next = 0;
  const auto sum = c.stream(
      h, [&]() -> std::optional<v1::Frame> { return next < frames.size() ? std::optional(frames[next++]) : std::nullopt; },
      [&](const v1::FrameResult& r, double) {
        std::lock_guard lock(m);
        results.push_back(r);
      },
      service::StreamOptions{});
  ASSERT_TRUE(sum.status.ok()) << sum.status.error_message();
  ASSERT_EQ(results.size(), frames.size());
  uint64_t filled = 0, masked = 0;
  for (const auto& r : results) {
    ASSERT_FALSE(r.has_error()) << r.error().message();
    EXPECT_EQ(int64_t(r.filled_pixels()), expected[r.id()].filled_pixels) << "frame " << r.id();
    EXPECT_EQ(int64_t(r.tracking_mask_pixels()), expected[r.id()].tracking_mask_pixels) << "frame " << r.id();
    filled += r.filled_pixels();
    masked += r.tracking_mask_pixels();
  }
  EXPECT_GT(filled, 1000u) << "nothing filled on a mirror without depth";
  EXPECT_GT(masked, 1000u) << "the mirror's plane, a candidate with an open vote, is not kept out of ORB";
  c.close(h);
}

TEST(Service, FourSessionsStreamAtOnceEachCorrect) {
  auto c = shared_server().client();
  std::vector<SessionHandle> hs;
  for (int k = 0; k < 4; ++k) hs.push_back(create(c));
  std::vector<std::vector<v1::FrameResult>> results(4);
  std::vector<std::thread> threads;
  for (int k = 0; k < 4; ++k)
    threads.emplace_back([&, k] {
      auto ck = shared_server().client();  // one channel per client, as separate devices would
      results[k] = stream_frames(ck, hs[k], 0, wire_frames().size());
    });
  for (auto& t : threads) t.join();
  for (int k = 0; k < 4; ++k) {
    SCOPED_TRACE("session " + std::to_string(k));
    ASSERT_EQ(results[k].size(), wire_frames().size());
    expect_reference_trajectory(results[k]);
    EXPECT_EQ(c.get(hs[k]).frames(), wire_frames().size());
  }
  const auto list = c.list();
  EXPECT_GE(list.sessions_size(), 4);
  for (const auto& h : hs) c.close(h);
}

// A session created with tsdf.stream_radius keeps most of its TSDF in host memory and still
// gives the in-process (non-streaming) session's poses, block count and mesh.
TEST(Service, AStreamingSessionGivesTheSameMapWithFewerBlocksResident) {
  auto c = shared_server().client();
  auto req = create_request();
  (*req.mutable_config())["tsdf.stream_radius"] = "0.5";
  const auto r = c.create(req);
  const SessionHandle h{r.session_id(), r.token()};
  const auto results = stream_frames(c, h, 0, wire_frames().size());
  expect_reference_trajectory(results);
  const Session& ref = reference_session();
  const v1::SessionInfo info = c.get(h);
  EXPECT_EQ(info.tsdf_blocks(), uint64_t(ref.status().tsdf_blocks));
  EXPECT_LT(info.tsdf_resident_blocks(), info.tsdf_blocks() / 2);
  EXPECT_GT(info.host_bytes(), 0u);
  const service::Blob mesh = c.mesh(h);
  const TriangleMesh ref_mesh = ref.mesh();
  EXPECT_EQ(mesh.triangles, ref_mesh.triangles.size());
  EXPECT_EQ(mesh.count, ref_mesh.vertices.size());
  EXPECT_EQ(c.get(h).tsdf_resident_blocks(), info.tsdf_resident_blocks()) << "the mesh left blocks resident";
  c.close(h);
}

TEST(Service, MeshAndGaussiansDecodeToTheSessionsCounts) {
  auto c = shared_server().client();
  const SessionHandle h = create(c);
  stream_frames(c, h, 0, wire_frames().size());
  const Session& ref = reference_session();

  const service::Blob mesh = c.mesh(h);
  const TriangleMesh ref_mesh = ref.mesh();
  ASSERT_GT(ref_mesh.triangles.size(), 0u);
  EXPECT_EQ(mesh.triangles, ref_mesh.triangles.size());
  EXPECT_EQ(mesh.count, ref_mesh.vertices.size());
  const TriangleMesh decoded = io::decode_draco(io::byte_span(mesh.data));
  EXPECT_EQ(decoded.triangles.size(), ref_mesh.triangles.size());  // Draco keeps the face count

  const service::Blob spz = c.gaussians(h, v1::GetGaussiansRequest::SPZ, v1::GetGaussiansRequest::BASE);
  const GaussianHost base = decode_spz(std::vector<uint8_t>(spz.data.begin(), spz.data.end()));
  ASSERT_GT(ref.base_gaussians().size(), 0u);
  EXPECT_EQ(base.size(), ref.base_gaussians().size());
  EXPECT_EQ(spz.count, base.size());
  const service::Blob refl = c.gaussians(h, v1::GetGaussiansRequest::SPZ, v1::GetGaussiansRequest::REFLECTION);
  EXPECT_EQ(decode_spz(std::vector<uint8_t>(refl.data.begin(), refl.data.end())).size(),
            ref.reflection_gaussians().size());
  const service::Blob ply = c.gaussians(h, v1::GetGaussiansRequest::PLY, v1::GetGaussiansRequest::BASE);
  EXPECT_NE(ply.data.find("element vertex " + std::to_string(base.size()) + "\n"), std::string::npos);
  std::printf("[ mesh %zu vertices / %zu triangles, %zu Draco bytes; %zu base + %zu reflection Gaussians ]\n",
              size_t(mesh.count), size_t(mesh.triangles), mesh.data.size(), base.size(),
              ref.reflection_gaussians().size());
  c.close(h);
}

TEST(Service, RenderViewAndWatchEvents) {
  auto c = shared_server().client();
  const SessionHandle h = create(c);
  std::atomic<int> poses{0}, maps{0};
  std::thread watcher([&] {
    auto cw = shared_server().client();
    cw.watch(h, [&](const v1::SessionEvent& e) {
      if (e.has_pose()) poses++;
      if (e.has_map()) maps++;
      return poses < 4;
    }, std::chrono::seconds(120));
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the watch is subscribed
  stream_frames(c, h, 0, 4);
  watcher.join();
  EXPECT_EQ(poses.load(), 4);
  EXPECT_GE(maps.load(), 1);

  v1::RenderViewRequest r;
  *r.mutable_pose() = c.get(h).pose();
  for (auto p : {v1::PASS_FINAL, v1::PASS_BASE, v1::PASS_REFLECTION, v1::PASS_MASK, v1::PASS_DEPTH}) r.add_passes(p);
  const auto view = c.render(h, r);
  ASSERT_EQ(view.images_size(), 5);
  for (const auto& img : view.images()) {
    const cv::Mat m = cv::imdecode(cv::Mat(1, int(img.png().size()), CV_8U, const_cast<char*>(img.png().data())),
                                   cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(m.empty());
    EXPECT_EQ(m.cols, 160);
    EXPECT_EQ(m.rows, 120);
    if (img.pass() == v1::PASS_DEPTH) {
      EXPECT_EQ(m.depth(), CV_16U);  // millimetres
      double lo = 0, hi = 0;
      cv::minMaxLoc(m, &lo, &hi);
      EXPECT_GT(hi, 100.0);  // a surface beyond 10 cm is seen
    }
    if (img.pass() == v1::PASS_MASK) EXPECT_EQ(m.channels(), 1);
  }
  // A frame can ask for its view (rendered at its pose after processing).
  v1::Frame f = wire_frames()[4];
  f.add_render(v1::PASS_FINAL);
  f.add_render(v1::PASS_DEPTH);
  bool sent = false;
  std::vector<v1::FrameResult> got;
  c.stream(h, [&]() -> std::optional<v1::Frame> { return sent ? std::nullopt : (sent = true, std::optional(f)); },
           [&](const v1::FrameResult& fr, double) { got.push_back(fr); });
  ASSERT_EQ(got.size(), 1u);
  ASSERT_EQ(got[0].view().images_size(), 2);
  EXPECT_EQ(got[0].view().images(1).pass(), v1::PASS_DEPTH);
  EXPECT_GT(got[0].view().images(0).png().size(), 100u);

  // Bad render intrinsics are refused, naming the field.
  v1::RenderViewRequest bad = r;
  bad.mutable_intrinsics()->set_fx(-1);
  bad.mutable_intrinsics()->set_width(160);
  bad.mutable_intrinsics()->set_height(120);
  try {
    c.render(h, bad);
    ADD_FAILURE() << "negative fx accepted";
  } catch (const service::RpcError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(std::string(e.what()).find("intrinsics"), std::string::npos) << e.what();
  }
  c.close(h);
}

TEST(Service, SaveKillNineLoadRestoresTheMap) {
  TempDir snaps("rrg-snaps");
  service::Blob mesh_before, spz_before;
  v1::SessionInfo before;
  SessionHandle h;
  {
    ServerProcess server({}, snaps.path());
    auto c = server.client();
    h = create(c);
    stream_frames(c, h, 0, wire_frames().size());
    const auto saved = c.save(h);
    EXPECT_EQ(saved.frames(), wire_frames().size());
    before = c.get(h);
    mesh_before = c.mesh(h);
    spz_before = c.gaussians(h, v1::GetGaussiansRequest::SPZ);
    server.kill9();
  }
  ServerProcess server({}, snaps.path());
  auto c = server.client();
  try {
    c.load(h.id, "not-the-token");
    ADD_FAILURE() << "load with a wrong token accepted";
  } catch (const service::RpcError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  const auto loaded = c.load(h.id, h.token);
  EXPECT_EQ(loaded.session_id(), h.id);
  EXPECT_EQ(loaded.token(), h.token);  // the session's own token keeps working
  const v1::SessionInfo after = c.get(h);
  EXPECT_EQ(after.frames(), before.frames());
  EXPECT_EQ(after.map_version(), before.map_version());
  EXPECT_EQ(after.last_frame_id(), before.last_frame_id());
  EXPECT_EQ(after.base_gaussians(), before.base_gaussians());
  EXPECT_EQ(after.reflection_gaussians(), before.reflection_gaussians());
  const auto pa = service::from_proto(after.pose()), pb = service::from_proto(before.pose());
  EXPECT_LT((pa.translation() - pb.translation()).norm(), 1e-6);
  // The same map: the same mesh and Gaussian counts, the same SPZ bytes.
  const service::Blob mesh_after = c.mesh(h), spz_after = c.gaussians(h, v1::GetGaussiansRequest::SPZ);
  EXPECT_EQ(mesh_after.count, mesh_before.count);
  EXPECT_EQ(mesh_after.triangles, mesh_before.triangles);
  EXPECT_GT(mesh_after.triangles, 0u);
  EXPECT_EQ(spz_after.count, spz_before.count);
  EXPECT_TRUE(spz_after.data == spz_before.data) << "SPZ bytes differ after load";
  EXPECT_TRUE(mesh_after.data == mesh_before.data) << "Draco bytes differ after load";
  std::printf("[ after load: mesh %zu/%zu vertices/triangles, Draco bytes %s; %zu Gaussians ]\n", size_t(mesh_after.count),
              size_t(mesh_after.triangles), mesh_after.data == mesh_before.data ? "identical" : "differ",
              size_t(spz_after.count));
  try {
    c.load(h.id, h.token);
    ADD_FAILURE() << "loading a live session accepted";
  } catch (const service::RpcError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::ALREADY_EXISTS);
  }
  // Graceful shutdown snapshots every session and exits 0.
  EXPECT_EQ(server.terminate(), 0);
}

TEST(Service, IdleSessionsAreSnapshottedThenFreed) {
  TempDir snaps("rrg-idle");
  ServerProcess server({"--idle-timeout", "1"}, snaps.path());
  auto c = server.client();
  const SessionHandle h = create(c);
  stream_frames(c, h, 0, 2);
  const auto t0 = std::chrono::steady_clock::now();
  bool freed = false;
  while (!freed && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(30)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1200));  // no calls meanwhile
    try {
      c.get(h);
    } catch (const service::RpcError& e) {
      EXPECT_EQ(e.code(), grpc::StatusCode::NOT_FOUND);
      freed = true;
    }
  }
  ASSERT_TRUE(freed) << server.log();
  const auto loaded = c.load(h.id, h.token);
  EXPECT_EQ(loaded.info().frames(), 2u);
  EXPECT_EQ(loaded.info().last_frame_id(), 1);
}

}  // namespace
}  // namespace rrg::test
