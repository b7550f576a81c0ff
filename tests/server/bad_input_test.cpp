// Bad input, auth, admission and the bounded queue, against the real `rrg serve`: every bad
// input gets INVALID_ARGUMENT naming the field and the session keeps working.
#include "client/lib/frame_encode.h"
#include "client/lib/proto_convert.h"
#include "tests/server/server_fixture.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <grpcpp/generic/generic_stub.h>

#include <future>
#include <thread>

#include <cmath>
#include <cstring>
#include <limits>
#include <set>

namespace rrg::test {
namespace {

using service::RpcError;
using service::SessionHandle;

ServerProcess& server() {
  static ServerProcess s({"--admin-key", "admin-secret", "--max-message-mb", "1"});
  return s;
}

template <class F>
void expect_status(F&& f, grpc::StatusCode code, const std::string& mention) {
  try {
    f();
    ADD_FAILURE() << "no error (expected code " << int(code) << " mentioning '" << mention << "')";
  } catch (const RpcError& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
  }
}

TEST(BadInput, CreateRefusesAbsurdIntrinsicsAndConfig) {
  auto c = server().client();
  auto bad = [&](auto edit, const std::string& field) {
    v1::CreateSessionRequest r = create_request();
    edit(r);
    expect_status([&] { c.create(r); }, grpc::StatusCode::INVALID_ARGUMENT, field);
  };
  bad([](auto& r) { r.clear_intrinsics(); }, "intrinsics");
  bad([](auto& r) { r.mutable_intrinsics()->set_fx(0); }, "intrinsics");
  bad([](auto& r) { r.mutable_intrinsics()->set_fy(-5); }, "intrinsics");
  bad([](auto& r) { r.mutable_intrinsics()->set_fx(std::numeric_limits<float>::quiet_NaN()); }, "intrinsics");
  bad([](auto& r) { r.mutable_intrinsics()->set_fx(1.0f); }, "intrinsics");  // ~178 degree field of view
  bad([](auto& r) { r.mutable_intrinsics()->set_width(0); }, "intrinsics");
  bad([](auto& r) { r.mutable_intrinsics()->set_width(100000); }, "intrinsics");
  bad([](auto& r) { r.mutable_intrinsics()->set_cx(5000); }, "intrinsics");
  bad([](auto& r) { r.set_depth_scale(-1); }, "depth");
  bad([](auto& r) { (*r.mutable_config())["tsdf.voxel_sise"] = "0.01"; }, "config.tsdf.voxel_sise");
  bad([](auto& r) { (*r.mutable_config())["tsdf.voxel_size"] = "abc"; }, "config.tsdf.voxel_size");
  bad([](auto& r) { (*r.mutable_config())["camera.fx"] = "100"; }, "config.camera.fx");
  bad([](auto& r) { (*r.mutable_config())["remote_address"] = "evil:1"; }, "config.remote_address");
  bad([](auto& r) { r.set_queue_capacity(100000); }, "queue_capacity");
}

TEST(BadInput, EveryBadFrameIsRefusedNamingTheFieldAndTheSessionContinues) {
  auto c = server().client();
  const auto cr = c.create(create_request());
  const SessionHandle h{cr.session_id(), cr.token()};
  const auto& good = wire_frames();
  const int W = 160, H = 120;

  std::vector<std::pair<v1::Frame, std::string>> cases;  // frame, field the error must name
  auto with = [&](uint64_t id, auto edit, const std::string& field) {
    v1::Frame f = good[1];
    f.set_id(id);
    edit(f);
    cases.emplace_back(f, field);
  };
  with(1, [&](v1::Frame& f) {
    f.mutable_color()->set_encoding(v1::ColorData::COLOR_RAW_RGB8);
    f.mutable_color()->set_data(std::string(size_t(W * H * 3 - 7), '\x10'));
  }, "color");  // wrong size
  with(1, [&](v1::Frame& f) { f.mutable_color()->set_encoding(v1::ColorData::Encoding(42)); }, "color.encoding");
  with(1, [&](v1::Frame& f) { f.mutable_depth()->set_encoding(v1::DepthData::DEPTH_ENCODING_UNSPECIFIED); },
       "depth.encoding");
  with(1, [&](v1::Frame& f) {
    std::string png = f.color().data();
    png.resize(png.size() / 2);  // truncated PNG
    f.mutable_color()->set_data(png);
  }, "color");
  with(1, [&](v1::Frame& f) {
    f.mutable_color()->set_encoding(v1::ColorData::COLOR_JPEG);
    f.mutable_color()->set_data("\xff\xd8\xff\xe0 this is not a JPEG");
  }, "color");
  with(1, [&](v1::Frame& f) {  // a PNG of the wrong size
    const auto png = io::encode_color(ColorImage(W / 2, H / 2, Color(0.5f, 0.5f, 0.5f)), io::ColorEncoding::png);
    f.mutable_color()->set_data(std::string(png.begin(), png.end()));
  }, "color");
  with(1, [&](v1::Frame& f) {  // corrupt RVL+zstd
    std::string d = f.depth().data();
    for (size_t i = d.size() / 2; i < d.size(); ++i) d[i] = char(d[i] ^ 0x5a);
    f.mutable_depth()->set_data(d);
  }, "depth");
  with(1, [&](v1::Frame& f) {  // NaN depth (raw float32 metres)
    std::vector<float> d(size_t(W * H), 1.5f);
    d[17] = std::numeric_limits<float>::quiet_NaN();
    f.mutable_depth()->set_encoding(v1::DepthData::DEPTH_RAW_F32);
    f.mutable_depth()->set_data(std::string(reinterpret_cast<const char*>(d.data()), d.size() * 4));
  }, "depth");
  with(1, [&](v1::Frame& f) {  // negative depth
    std::vector<float> d(size_t(W * H), 1.5f);
    d[5] = -2.0f;
    f.mutable_depth()->set_encoding(v1::DepthData::DEPTH_RAW_F32);
    f.mutable_depth()->set_data(std::string(reinterpret_cast<const char*>(d.data()), d.size() * 4));
  }, "depth");
  with(1, [&](v1::Frame& f) { f.mutable_depth()->set_data(std::string(10 * W * H * 2, '\0')); }, "depth.data");  // oversize
  with(1, [&](v1::Frame& f) { f.mutable_depth()->clear_data(); }, "depth.data");
  with(1, [&](v1::Frame& f) { f.clear_color(); }, "color");
  with(1, [&](v1::Frame& f) { f.mutable_pose_prior()->set_qw(std::nan("")); }, "pose_prior");
  with(1, [&](v1::Frame& f) { f.set_timestamp(std::numeric_limits<double>::infinity()); }, "timestamp");
  with(1, [&](v1::Frame& f) { f.add_render(v1::RenderPass(77)); }, "render");
  with(1, [&](v1::Frame& f) { f.set_session_id("someone-else"); }, "session_id");

  // Frame 0 (good), every bad frame, frame 0 again (out of order), then frame 1 (good).
  std::vector<v1::Frame> frames = {good[0]};
  for (const auto& [f, field] : cases) frames.push_back(f);
  frames.push_back(good[0]);
  frames.push_back(good[1]);
  std::vector<v1::FrameResult> results;
  size_t i = 0;
  service::StreamOptions so;
  so.window = 1;
  const auto sum = c.stream(h, [&]() -> std::optional<v1::Frame> {
    return i < frames.size() ? std::optional(frames[i++]) : std::nullopt;
  }, [&](const v1::FrameResult& r, double) { results.push_back(r); }, so);
  ASSERT_TRUE(sum.status.ok()) << sum.status.error_message();
  ASSERT_EQ(results.size(), frames.size());
  EXPECT_FALSE(results.front().has_error()) << results.front().error().message();
  for (size_t k = 0; k < cases.size(); ++k) {
    const auto& r = results[k + 1];
    SCOPED_TRACE("case " + std::to_string(k) + " (" + cases[k].second + ")");
    ASSERT_TRUE(r.has_error());
    EXPECT_EQ(r.error().code(), int(grpc::StatusCode::INVALID_ARGUMENT));
    EXPECT_EQ(r.error().message().rfind(cases[k].second, 0), 0u) << r.error().message();
  }
  const auto& ooo = results[results.size() - 2];
  ASSERT_TRUE(ooo.has_error());
  EXPECT_EQ(ooo.error().code(), int(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_EQ(ooo.error().message().rfind("id", 0), 0u) << ooo.error().message();
  EXPECT_FALSE(results.back().has_error()) << results.back().error().message();
  EXPECT_EQ(results.back().id(), 1u);
  EXPECT_EQ(c.get(h).frames(), 2u);  // the session went on

  // A message over the server's maximum size (1 MiB here) ends that stream with
  // RESOURCE_EXHAUSTED (gRPC's own check); the session keeps working on a new stream.
  v1::Frame huge = good[2];
  huge.mutable_color()->set_data(std::string(2 << 20, 'x'));
  size_t sent = 0;
  const auto big = c.stream(h, [&]() -> std::optional<v1::Frame> {
    return sent++ == 0 ? std::optional(huge) : std::nullopt;
  }, [](const v1::FrameResult&, double) {}, so);
  EXPECT_EQ(big.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << big.status.error_message();
  const auto after = stream_frames(c, h, 2, 3);
  ASSERT_EQ(after.size(), 1u);
  EXPECT_FALSE(after[0].has_error()) << after[0].error().message();
  EXPECT_EQ(c.get(h).frames(), 3u);
  c.close(h);
}

TEST(Auth, MissingWrongAndForeignTokensAreRejected) {
  auto c = server().client();
  const auto a = c.create(create_request());
  const auto b = c.create(create_request());
  const SessionHandle ha{a.session_id(), a.token()}, hb{b.session_id(), b.token()};
  expect_status([&] { c.get({ha.id, ""}); }, grpc::StatusCode::UNAUTHENTICATED, "authorization");
  expect_status([&] { c.get({ha.id, "wrong"}); }, grpc::StatusCode::UNAUTHENTICATED, "authorization");
  expect_status([&] { c.get({ha.id, hb.token}); }, grpc::StatusCode::UNAUTHENTICATED, "authorization");
  expect_status([&] { c.get({"s0000000000000000", ha.token}); }, grpc::StatusCode::NOT_FOUND, "not found");
  expect_status([&] { c.mesh({ha.id, "wrong"}); }, grpc::StatusCode::UNAUTHENTICATED, "authorization");
  expect_status([&] { c.close({ha.id, "wrong"}); }, grpc::StatusCode::UNAUTHENTICATED, "authorization");
  EXPECT_EQ(c.get(ha).session_id(), ha.id);
  EXPECT_EQ(c.get({ha.id, "admin-secret"}).session_id(), ha.id);  // the admin key works everywhere
  // The stream checks the token before taking frames.
  size_t n = 0;
  const auto sum = c.stream({ha.id, "wrong"}, [&]() -> std::optional<v1::Frame> {
    return n++ == 0 ? std::optional(wire_frames()[0]) : std::nullopt;
  }, [](const v1::FrameResult&, double) {});
  EXPECT_EQ(sum.status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(c.get(ha).frames(), 0u);
  // List needs the admin key on this server.
  expect_status([&] { c.list(); }, grpc::StatusCode::UNAUTHENTICATED, "admin");
  expect_status([&] { c.list("nope"); }, grpc::StatusCode::UNAUTHENTICATED, "admin");
  EXPECT_GE(c.list("admin-secret").sessions_size(), 2);
  c.close(ha);
  c.close(hb);
  expect_status([&] { c.get(ha); }, grpc::StatusCode::NOT_FOUND, "not found");
}

// grpc.health.v1.Health/Check through the generic stub (no generated health code needed):
// request field 1 = service name; response field 1 = status (1 SERVING, 2 NOT_SERVING).
int health_status(const std::string& address, const std::string& service_name) {
  grpc::GenericStub stub(service::make_channel({address}));
  grpc::ClientContext ctx;
  std::string req;
  if (!service_name.empty()) req = std::string("\x0a") + char(service_name.size()) + service_name;
  grpc::Slice slice(req);
  grpc::ByteBuffer in(&slice, 1), out;
  std::promise<grpc::Status> done;
  stub.UnaryCall(&ctx, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &in, &out,
                 [&](grpc::Status st) { done.set_value(st); });
  const grpc::Status st = done.get_future().get();
  if (!st.ok()) return -int(st.error_code());
  std::vector<grpc::Slice> slices;
  (void)out.Dump(&slices);
  std::string bytes;
  for (const auto& sl : slices) bytes.append(reinterpret_cast<const char*>(sl.begin()), sl.size());
  return bytes.size() >= 2 && bytes[0] == '\x08' ? int(bytes[1]) : 0;  // empty message = UNKNOWN (0)
}

TEST(Admission, SessionCountAndMemoryBudgetsGiveResourceExhausted) {
  {
    ServerProcess s({"--max-sessions", "1"});
    auto c = s.client();
    EXPECT_EQ(health_status(s.address(), ""), 1);
    EXPECT_EQ(health_status(s.address(), "rrg.v1.SessionService"), 1);  // capacity left
    const auto a = c.create(create_request());
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the health updater runs every second
    EXPECT_EQ(health_status(s.address(), "rrg.v1.SessionService"), 2);  // full: NOT_SERVING
    EXPECT_EQ(health_status(s.address(), ""), 1);
    expect_status([&] { c.create(create_request()); }, grpc::StatusCode::RESOURCE_EXHAUSTED, "max 1");
    c.close({a.session_id(), a.token()});
    EXPECT_NO_THROW(c.create(create_request()));  // the slot is free again
  }
  {
    ServerProcess s({"--session-memory-mb", "0.01"});  // 10 KiB: no session fits
    auto c = s.client();
    expect_status([&] { c.create(create_request()); }, grpc::StatusCode::RESOURCE_EXHAUSTED, "budget");
  }
  {
    ServerProcess s({"--session-memory-mb", "512", "--total-memory-mb", "1000"});  // room for one reservation
    auto c = s.client();
    EXPECT_NO_THROW(c.create(create_request()));
    expect_status([&] { c.create(create_request()); }, grpc::StatusCode::RESOURCE_EXHAUSTED, "memory budget");
  }
}

// --session-device-mb counts device memory alone. A session whose TSDF streams its far blocks to
// the host (tsdf.stream_radius) loads within a device budget that the same map held whole
// exceeds; the latter is refused and its snapshot left as it was. A session growing over the
// budget refuses its next frame, naming the device budget.
TEST(Admission, ADeviceBudgetLeavesOutTheBlocksATsdfStreamsToTheHost) {
  TempDir snaps("rrg-device-budget");
  auto whole_req = create_request();
  whole_req.set_session_id("whole-map");
  auto streamed_req = whole_req;
  streamed_req.set_session_id("streamed-map");
  (*streamed_req.mutable_config())["tsdf.stream_radius"] = "0.5";
  std::map<std::string, std::string> tokens;
  {
    ServerProcess s({}, snaps.path());
    auto c = s.client();
    for (const auto* req : {&whole_req, &streamed_req}) {
      const auto cr = c.create(*req);
      tokens[cr.session_id()] = cr.token();
      stream_frames(c, {cr.session_id(), cr.token()}, 0, wire_frames().size());
      c.close({cr.session_id(), cr.token()}, true);
    }
  }
  // What each takes once loaded (the server loads the same files the same way).
  const SessionStatus whole = Session::load(snaps.path() / "whole-map.rrgsnap")->status();
  const SessionStatus streamed = Session::load(snaps.path() / "streamed-map.rrgsnap")->status();
  ASSERT_GT(streamed.host_bytes, 0u);
  ASSERT_LT(streamed.device_bytes, whole.device_bytes * 3 / 4) << "too little was streamed out to test anything";
  const size_t budget = streamed.device_bytes + (whole.device_bytes - streamed.device_bytes) / 2;
  // A memory budget (device + host) of that size would refuse both.
  ASSERT_GT(streamed.device_bytes + streamed.host_bytes, budget);
  char mib[64];
  std::snprintf(mib, sizeof(mib), "%.6f", double(budget) / (1024.0 * 1024.0));

  ServerProcess s({"--session-device-mb", mib}, snaps.path());
  auto c = s.client();
  const auto snapshot_bytes = [&] { return std::filesystem::file_size(snaps.path() / "whole-map.rrgsnap"); };
  const auto size_before = snapshot_bytes();
  expect_status([&] { c.load("whole-map", tokens["whole-map"]); }, grpc::StatusCode::RESOURCE_EXHAUSTED, "device budget");
  EXPECT_EQ(snapshot_bytes(), size_before) << "a refused load touched the snapshot";
  const auto loaded = c.load("streamed-map", tokens["streamed-map"]);
  const SessionHandle h{loaded.session_id(), tokens["streamed-map"]};
  EXPECT_LE(loaded.info().device_bytes(), budget);
  EXPECT_EQ(loaded.info().host_bytes(), streamed.host_bytes);
  EXPECT_EQ(loaded.info().tsdf_resident_blocks(), uint64_t(streamed.resident_blocks));
  // Frames go on: this small room is all in view, so the next frame brings every block back and
  // the session grows over its budget; the frame after that is refused.
  v1::FrameResult last;
  uint64_t id = wire_frames().back().id();
  for (int k = 0; k < 2; ++k) {
    v1::Frame f = wire_frames()[wire_frames().size() - 2 + size_t(k)];
    f.set_id(++id);
    f.clear_pose_prior();
    c.stream(h, [&, sent = false]() mutable -> std::optional<v1::Frame> {
          if (sent) return std::nullopt;
          sent = true;
          return f;
        },
        [&](const v1::FrameResult& r, double) { last = r; });
    if (k == 0) {
      EXPECT_FALSE(last.has_error()) << last.error().message();
      EXPECT_GT(c.get(h).device_bytes(), budget);
    }
  }
  ASSERT_TRUE(last.has_error()) << "a session over its device budget took a frame";
  EXPECT_EQ(last.error().code(), int(grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_NE(last.error().message().find("device budget"), std::string::npos) << last.error().message();

  // Admission: each session reserves its device budget out of the total.
  ServerProcess t({"--session-device-mb", "512", "--total-device-mb", "1000"});
  auto ct = t.client();
  EXPECT_NO_THROW(ct.create(create_request()));
  expect_status([&] { ct.create(create_request()); }, grpc::StatusCode::RESOURCE_EXHAUSTED, "device budget");
  ServerProcess u({"--session-device-mb", "0.01"});  // 10 KiB: no session fits
  auto cu = u.client();
  expect_status([&] { cu.create(create_request()); }, grpc::StatusCode::RESOURCE_EXHAUSTED, "device budget");
}

TEST(Queue, AFullQueueDropsTheOldestFrameAndSaysSo) {
  auto c = server().client();
  v1::CreateSessionRequest req = create_request();
  req.set_queue_capacity(1);
  const auto cr = c.create(req);
  const SessionHandle h{cr.session_id(), cr.token()};
  // All frames at once: the worker takes one, the queue holds one, the rest push older ones out.
  const auto results = stream_frames(c, h, 0, 8, 8);
  ASSERT_EQ(results.size(), 8u);
  uint64_t dropped = 0, last_reported = 0;
  std::set<uint64_t> ids;
  for (const auto& r : results) {
    EXPECT_FALSE(r.has_error()) << r.error().message();
    if (r.dropped()) ++dropped;
    EXPECT_GE(r.frames_dropped(), last_reported);  // never decreases
    last_reported = r.frames_dropped();
    ids.insert(r.id());
  }
  EXPECT_EQ(ids.size(), 8u);  // every frame answered exactly once
  EXPECT_GT(dropped, 0u);
  EXPECT_FALSE(results.back().dropped());  // the newest frame is always processed
  const auto info = c.get(h);
  EXPECT_EQ(info.frames_dropped(), dropped);
  EXPECT_EQ(info.frames() + dropped, 8u);
  c.close(h);
}

}  // namespace
}  // namespace rrg::test
