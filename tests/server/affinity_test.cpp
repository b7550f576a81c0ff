// Session affinity and draining (issue #11, docs/deploy.md) against real `rrg serve` processes:
// the x-rrg-server reply header, client-proposed session ids (validated, ALREADY_EXISTS), the
// NOT_FOUND message naming the server, and Drain (RPC and SIGUSR1): health NOT_SERVING, Create
// UNAVAILABLE, every session saved to the shared folder and loadable, with its own token, on
// another server that then continues the trajectory exactly.
#include "client/lib/health_check.h"
#include "client/lib/proto_convert.h"
#include "tests/server/server_fixture.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <mutex>
#include <set>
#include <thread>

namespace rrg::test {
namespace {

using service::RpcError;
using service::SessionHandle;

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

service::HealthStatus health(const ServerProcess& s, const std::string& name) {
  return service::check_health(service::make_channel({s.address()}), name);
}

// Waits (the health updater runs every second) until `name` reports `want`, at most 5 s.
bool wait_health(const ServerProcess& s, const std::string& name, service::HealthStatus want) {
  for (int i = 0; i < 50; ++i) {
    if (health(s, name) == want) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

v1::CreateSessionRequest request_with_id(const std::string& id) {
  v1::CreateSessionRequest r = create_request();
  r.set_session_id(id);
  return r;
}

void expect_pose_equal_reference(const v1::FrameResult& r) {
  ASSERT_FALSE(r.has_error()) << r.error().message();
  const Eigen::Isometry3d T = service::from_proto(r.pose()).cast<double>();
  const Eigen::Isometry3d& R = reference_trajectory()[r.id()].T_wc;
  EXPECT_LT((T.translation() - R.translation()).norm(), 1e-4) << "frame " << r.id();
}

TEST(Affinity, EveryCallNamesTheServerInXRrgServer) {
  ServerProcess s({"--name", "alpha-1"});
  auto c = s.client();
  std::mutex m;
  std::multiset<std::string> servers;
  size_t calls = 0;
  c.set_server_observer([&](const std::string&, const std::string&, const std::string& server) {
    std::lock_guard lock(m);
    servers.insert(server);
    ++calls;
  });
  const auto r = c.create(create_request());
  const SessionHandle h{r.session_id(), r.token()};
  const auto results = stream_frames(c, h, 0, 3);
  EXPECT_EQ(results.size(), 3u);
  c.get(h);
  const auto mesh = c.mesh(h);
  EXPECT_EQ(mesh.server, "alpha-1");
  c.gaussians(h, v1::GetGaussiansRequest::SPZ);
  expect_status([&] { c.get({"snope0000000000000", h.token}); }, grpc::StatusCode::NOT_FOUND, "alpha-1");
  c.close(h);
  EXPECT_EQ(calls, 7u);
  EXPECT_EQ(servers.count("alpha-1"), calls) << "a call came back without x-rrg-server: alpha-1";
}

TEST(Affinity, ClientProposedSessionIdsAreValidatedAndUnique) {
  TempDir snaps("rrg-affinity-snaps");
  ServerProcess s({"--name", "beta"}, snaps.path());
  auto c = s.client();
  const auto r = c.create(request_with_id("robot-7-kitchen"));
  EXPECT_EQ(r.session_id(), "robot-7-kitchen");
  EXPECT_EQ(c.get({r.session_id(), r.token()}).session_id(), "robot-7-kitchen");
  expect_status([&] { c.create(request_with_id("robot-7-kitchen")); }, grpc::StatusCode::ALREADY_EXISTS, "taken");
  for (const std::string& bad : std::vector<std::string>{"abc", "Robot-7", "robot_7", "robot 7", std::string(65, 'a'), "rob/ot"})
    expect_status([&] { c.create(request_with_id(bad)); }, grpc::StatusCode::INVALID_ARGUMENT, "session_id");
  // The id may come from the x-rrg-session header alone; a header contradicting the field is refused.
  {
    grpc::ClientContext ctx;
    ctx.AddMetadata("x-rrg-session", "from-header-1");
    v1::CreateSessionResponse out;
    ASSERT_TRUE(c.stub().Create(&ctx, create_request(), &out).ok());
    EXPECT_EQ(out.session_id(), "from-header-1");
  }
  {
    grpc::ClientContext ctx;
    ctx.AddMetadata("x-rrg-session", "other-id-2");
    v1::CreateSessionResponse out;
    const grpc::Status st = c.stub().Create(&ctx, request_with_id("field-id-2"), &out);
    EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(st.error_message().find("x-rrg-session"), std::string::npos) << st.error_message();
  }
  // A saved (closed) session's id stays taken: creating over it would hide its snapshot.
  c.close({r.session_id(), r.token()}, true);
  expect_status([&] { c.create(request_with_id("robot-7-kitchen")); }, grpc::StatusCode::ALREADY_EXISTS, "Load");
  expect_status([&] { c.get({"robot-7-kitchen", r.token()}); }, grpc::StatusCode::NOT_FOUND,
                "server beta does not hold session robot-7-kitchen; it may be on another server or saved: Load it");
}

TEST(Drain, SavesEverySessionAndAnotherServerLoadsAndContinuesIt) {
  TempDir snaps("rrg-drain-snaps");
  ServerProcess a({"--name", "srv-a", "--admin-key", "drain-admin-key"}, snaps.path());
  ServerProcess b({"--name", "srv-b", "--admin-key", "drain-admin-key"}, snaps.path());
  auto ca = a.client();
  auto cb = b.client();
  constexpr size_t kSplit = 6;
  const auto r1 = ca.create(request_with_id("drain-one"));
  const auto r2 = ca.create(request_with_id("drain-two"));
  const SessionHandle h1{r1.session_id(), r1.token()}, h2{r2.session_id(), r2.token()};
  const auto first = stream_frames(ca, h1, 0, kSplit);
  stream_frames(ca, h2, 0, 2);
  const v1::SessionInfo before = ca.get(h1);
  const auto mesh_before = ca.mesh(h1);
  EXPECT_EQ(health(a, ""), service::HealthStatus::serving);
  EXPECT_EQ(health(a, "rrg.v1.SessionService"), service::HealthStatus::serving);

  expect_status([&] { ca.drain("wrong"); }, grpc::StatusCode::UNAUTHENTICATED, "admin");
  const v1::DrainResponse d = ca.drain("drain-admin-key");
  EXPECT_EQ(d.server(), "srv-a");
  EXPECT_EQ(std::set<std::string>(d.saved().begin(), d.saved().end()), (std::set<std::string>{"drain-one", "drain-two"}));
  EXPECT_EQ(d.failed_size(), 0);
  EXPECT_TRUE(wait_health(a, "", service::HealthStatus::not_serving));
  EXPECT_TRUE(wait_health(a, "rrg.v1.SessionService", service::HealthStatus::not_serving));
  EXPECT_EQ(health(a, "liveness"), service::HealthStatus::serving);  // drained, not dead
  expect_status([&] { ca.create(create_request()); }, grpc::StatusCode::UNAVAILABLE, "draining");
  expect_status([&] { ca.load("drain-one", h1.token); }, grpc::StatusCode::UNAVAILABLE, "draining");
  expect_status([&] { ca.get(h1); }, grpc::StatusCode::NOT_FOUND, "srv-a drained session drain-one");
  EXPECT_EQ(ca.list("drain-admin-key").sessions_size(), 0);
  EXPECT_NO_THROW(ca.drain("drain-admin-key"));  // idempotent

  // Server b shares the folder: the session's own token loads it there, map intact.
  const auto loaded = cb.load("drain-one", h1.token);
  EXPECT_EQ(loaded.token(), h1.token);
  const v1::SessionInfo after = cb.get(h1);
  EXPECT_EQ(after.frames(), before.frames());
  EXPECT_EQ(after.map_version(), before.map_version());
  EXPECT_EQ(after.tsdf_blocks(), before.tsdf_blocks());
  EXPECT_EQ(after.keyframes(), before.keyframes()) << "the snapshot keeps the tracker's keyframes";
  EXPECT_EQ(after.base_gaussians(), before.base_gaussians());
  EXPECT_EQ(after.reflection_gaussians(), before.reflection_gaussians());
  const auto mesh_after = cb.mesh(h1);
  EXPECT_EQ(mesh_after.server, "srv-b");
  EXPECT_EQ(mesh_after.count, mesh_before.count);
  EXPECT_EQ(mesh_after.data, mesh_before.data);
  // ... and the rest of the sequence continues it as if nothing happened.
  const auto rest = stream_frames(cb, h1, kSplit, wire_frames().size());
  ASSERT_EQ(rest.size(), wire_frames().size() - kSplit);
  for (const auto& r : first) expect_pose_equal_reference(r);
  double drift = 0;
  for (const auto& r : rest) {
    expect_pose_equal_reference(r);  // a v2 snapshot continues the uninterrupted trajectory
    if (r.has_error()) continue;
    drift = std::max(drift, (service::from_proto(r.pose()).cast<double>().translation() -
                             reference_trajectory()[r.id()].T_wc.translation()).norm());
  }
  std::printf("[drain] continued poses after load vs the uninterrupted run: max %.3f mm\n", drift * 1e3);
  EXPECT_EQ(cb.get(h1).frames(), wire_frames().size());
  expect_status([&] { cb.load("drain-two", "not-its-token"); }, grpc::StatusCode::UNAUTHENTICATED, "token");
  EXPECT_NO_THROW(cb.load("drain-two", "drain-admin-key"));
}

TEST(Drain, Sigusr1DrainsAndKeepsServingHealth) {
  TempDir snaps("rrg-usr1-snaps");
  ServerProcess a({"--name", "srv-u"}, snaps.path());
  auto c = a.client();
  const auto r = c.create(request_with_id("usr1-session"));
  stream_frames(c, {r.session_id(), r.token()}, 0, 2);
  a.signal(SIGUSR1);
  EXPECT_TRUE(wait_health(a, "", service::HealthStatus::not_serving));
  for (int i = 0; i < 100 && !std::filesystem::exists(snaps / "usr1-session.json"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_TRUE(std::filesystem::exists(snaps / "usr1-session.rrgsnap"));
  expect_status([&] { c.get({r.session_id(), r.token()}); }, grpc::StatusCode::NOT_FOUND, "drained");
  EXPECT_EQ(health(a, "liveness"), service::HealthStatus::serving);
  EXPECT_EQ(a.terminate(), 0);
}

}  // namespace
}  // namespace rrg::test
