// The local multi-server test of issue #11: three `rrg serve` processes on loopback sharing one
// snapshot folder, behind Debian's nginx (grpc_pass, `hash $http_x_rrg_session consistent`).
// Twelve sessions stream the test sequence through nginx (sync mode, so poses are deterministic):
// every call of a session must reach the same server (x-rrg-server, and nginx's own access log),
// the sessions cover all three servers; then one server is drained, removed from the upstream
// (nginx -s reload), its sessions are loaded through nginx (they now hash to the others, the other
// sessions stay where they were), their maps are intact (Get counts, map version, identical Draco
// bytes) and streaming the rest of the sequence gives the in-process Session's trajectory.
#include "client/lib/proto_convert.h"
#include "tests/deploy/nginx_process.h"
#include "tests/server/server_fixture.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

namespace rrg::test {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using service::SessionHandle;

constexpr int kPerServer = 4;      // 3 servers x 4 = the 12 sessions of the issue
constexpr size_t kSplit = 8;       // frames streamed before the drain; the rest after the reload
const std::string kAdminKey = "deploy-test-admin-key";
// Found by this test: Session::save / Session::load (core/slam) did not keep the keyframes (a
// loaded session had 0 keyframes and its continued trajectory drifted, mm-level over 4 frames).
// Snapshot format v2 keeps the tracker's and the mapper's continuation state, so moved sessions
// are held to the same checks as the others; false reports those two checks instead of asserting.
constexpr bool kSnapshotKeepsKeyframes = true;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Which server answered each call of each session (the client's x-rrg-server observer).
struct CallLog {
  struct Call {
    std::string call, session, server;
    int phase;
  };
  std::mutex m;
  std::vector<Call> calls;
  int phase = 0;  // 0: before the drain, 1: after the reload
  service::ServerObserver observer() {
    return [this](const std::string& call, const std::string& session, const std::string& server) {
      std::lock_guard lock(m);
      calls.push_back({call, session, server, phase});
    };
  }
  // The servers that answered `session`'s calls in `phase`.
  std::set<std::string> servers(const std::string& session, int ph) {
    std::lock_guard lock(m);
    std::set<std::string> s;
    for (const auto& c : calls)
      if (c.session == session && c.phase == ph) s.insert(c.server);
    return s;
  }
};

// The server a session id hashes to now: a Get with a dummy token answers NOT_FOUND from there.
std::string route_of(const std::string& proxy, const std::string& id) {
  service::ServiceClient c(service::ChannelOptions{proxy});
  std::string server;
  c.set_server_observer([&](const std::string&, const std::string&, const std::string& s) { server = s; });
  try {
    c.get({id, "probe"});
  } catch (const service::RpcError& e) {
    if (e.code() != grpc::StatusCode::NOT_FOUND) throw;
  }
  return server;
}

struct MapState {
  v1::SessionInfo info;
  service::Blob mesh;
};

MapState map_state(service::ServiceClient& c, const SessionHandle& h) { return {c.get(h), c.mesh(h)}; }

void expect_same_map(const MapState& a, const MapState& b, const std::string& id, bool moved) {
  SCOPED_TRACE("session " + id);
  EXPECT_EQ(a.info.frames(), b.info.frames());
  EXPECT_EQ(a.info.map_version(), b.info.map_version());
  EXPECT_EQ(a.info.tsdf_blocks(), b.info.tsdf_blocks());
  if (!moved || kSnapshotKeepsKeyframes) EXPECT_EQ(a.info.keyframes(), b.info.keyframes());
  EXPECT_EQ(a.info.global_planes(), b.info.global_planes());
  EXPECT_EQ(a.info.base_gaussians(), b.info.base_gaussians());
  EXPECT_EQ(a.info.reflection_gaussians(), b.info.reflection_gaussians());
  EXPECT_EQ(a.mesh.count, b.mesh.count);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_TRUE(a.mesh.data == b.mesh.data) << "Draco bytes differ (" << a.mesh.data.size() << " vs "
                                          << b.mesh.data.size() << ")";
}

// Streams frames [begin, end) of every session at once and checks every pose against the
// in-process Session's (1e-4 m); for sessions in `relaxed` only that every frame is processed.
// Returns the largest position difference of the relaxed sessions (m).
double stream_all(service::ServiceClient& c, const std::vector<SessionHandle>& sessions, size_t begin, size_t end,
                  const std::set<std::string>& relaxed = {}) {
  double relaxed_max = 0;
  std::vector<std::vector<v1::FrameResult>> results(sessions.size());
  std::vector<std::thread> threads;
  for (size_t k = 0; k < sessions.size(); ++k)
    threads.emplace_back([&, k] { results[k] = stream_frames(c, sessions[k], begin, end, 2); });
  for (auto& t : threads) t.join();
  for (size_t k = 0; k < sessions.size(); ++k) {
    SCOPED_TRACE("session " + sessions[k].id);
    EXPECT_EQ(results[k].size(), end - begin);
    for (const auto& r : results[k]) {
      EXPECT_FALSE(r.has_error()) << r.error().message();
      EXPECT_FALSE(r.dropped());
      const Eigen::Isometry3d T = service::from_proto(r.pose()).cast<double>();
      const double err = (T.translation() - reference_trajectory()[r.id()].T_wc.translation()).norm();
      if (relaxed.count(sessions[k].id)) relaxed_max = std::max(relaxed_max, err);
      else EXPECT_LT(err, 1e-4) << "frame " << r.id();
    }
  }
  return relaxed_max;
}

TEST(MultiServer, SessionsStayOnTheirServerThroughNginxAndSurviveADrain) {
  const auto t_start = Clock::now();
  ASSERT_FALSE(find_nginx().empty()) << "nginx not found: run scripts/install_deps.sh (Debian package nginx)";
  (void)wire_frames();  // synthesise the sequence before the clock of the servers matters
  TempDir work("rrg-deploy");
  const fs::path snapshots = work / "snapshots";
  const std::vector<std::string> names = {"rrg-a", "rrg-b", "rrg-c"};
  std::vector<std::unique_ptr<ServerProcess>> servers;
  std::map<std::string, std::string> address_of;
  for (const auto& n : names) {
    servers.push_back(std::make_unique<ServerProcess>(
        std::vector<std::string>{"--name", n, "--admin-key", kAdminKey, "--max-sessions", "16"}, snapshots));
    address_of[n] = servers.back()->address();
  }
  auto upstreams = [&](const std::vector<std::string>& ns) {
    std::vector<std::string> v;
    for (const auto& n : ns) v.push_back(address_of.at(n));
    return v;
  };
  NginxProcess nginx(work / "nginx", upstreams(names));
  const std::string proxy = nginx.address();

  // Session ids as clients make them (random); probing the route picks four per server, so the
  // twelve cover all three whatever the ports (ketama points) of this run.
  std::map<std::string, std::string> home;  // session id -> server it hashes to
  std::map<std::string, int> per_server;
  int probes = 0;
  while (home.size() < names.size() * kPerServer && probes < 1000) {
    const std::string id = service::new_session_id();
    const std::string s = route_of(proxy, id);
    ++probes;
    ASSERT_TRUE(address_of.count(s)) << "probe answered by '" << s << "'";
    if (per_server[s] < kPerServer) {
      ++per_server[s];
      home[id] = s;
    }
  }
  ASSERT_EQ(home.size(), names.size() * kPerServer) << "after " << probes << " probes";

  CallLog log;
  service::ServiceClient client(service::ChannelOptions{proxy});
  client.set_server_observer(log.observer());
  std::vector<SessionHandle> sessions;
  for (const auto& [id, s] : home) {
    v1::CreateSessionRequest r = create_request();
    r.set_session_id(id);
    const auto resp = client.create(r);
    ASSERT_EQ(resp.session_id(), id);
    sessions.push_back({id, resp.token()});
  }
  stream_all(client, sessions, 0, kSplit);
  std::map<std::string, MapState> before;
  for (const auto& h : sessions) before[h.id] = map_state(client, h);
  for (const auto& h : sessions)
    EXPECT_EQ(log.servers(h.id, 0), std::set<std::string>{home[h.id]}) << "session " << h.id << " moved before the drain";

  // Drain rrg-a (directly: Drain acts on whichever server answers), take it out of the upstream.
  const std::string drained = "rrg-a";
  std::set<std::string> on_drained;
  for (const auto& [id, s] : home)
    if (s == drained) on_drained.insert(id);
  const auto t_drain = Clock::now();
  service::ServiceClient direct(service::ChannelOptions{address_of[drained]});
  const v1::DrainResponse d = direct.drain(kAdminKey);
  const double drain_s = seconds_since(t_drain);
  EXPECT_EQ(std::set<std::string>(d.saved().begin(), d.saved().end()), on_drained);
  EXPECT_EQ(d.failed_size(), 0);
  const auto t_reload = Clock::now();
  nginx.reload(upstreams({"rrg-b", "rrg-c"}));
  bool rerouted = false;  // the reload is asynchronous: wait until nginx's new workers answer
  while (!rerouted && seconds_since(t_reload) < 20) {
    rerouted = true;
    for (const auto& id : on_drained) rerouted = rerouted && route_of(proxy, id) != drained;
    if (!rerouted) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const double reload_s = seconds_since(t_reload);
  ASSERT_TRUE(rerouted) << "nginx still routes to " << drained << " 20 s after the reload:\n" << nginx.error_log();

  {
    std::lock_guard lock(log.m);
    log.phase = 1;
  }
  std::map<std::string, std::string> new_home;
  for (auto& h : sessions) {
    if (on_drained.count(h.id)) {
      const auto loaded = client.load(h.id, h.token);  // its own token, through nginx
      EXPECT_EQ(loaded.token(), h.token);
    }
    expect_same_map(before[h.id], map_state(client, h), h.id, on_drained.count(h.id) > 0);
  }
  const double moved_drift_m = stream_all(client, sessions, kSplit, wire_frames().size(),
                                          kSnapshotKeepsKeyframes ? std::set<std::string>{} : on_drained);
  for (const auto& h : sessions) {
    const v1::SessionInfo info = client.get(h);
    EXPECT_EQ(info.frames(), wire_frames().size());
    if (!on_drained.count(h.id) || kSnapshotKeepsKeyframes)
      EXPECT_EQ(info.map_version(), reference_session().status().map_version) << "session " << h.id;
    const auto after = log.servers(h.id, 1);
    ASSERT_EQ(after.size(), 1u) << "session " << h.id << " answered by " << after.size() << " servers after the reload";
    new_home[h.id] = *after.begin();
    if (on_drained.count(h.id)) EXPECT_NE(new_home[h.id], drained) << h.id;
    else EXPECT_EQ(new_home[h.id], home[h.id]) << "consistent hashing moved " << h.id << ", which was not drained";
  }

  // nginx's own view: every session's requests went to one upstream (two for the drained ones).
  std::map<std::string, std::set<std::string>> upstream_of;
  size_t log_lines = 0;
  std::istringstream access(nginx.access_log());
  for (std::string line; std::getline(access, line);) {
    std::istringstream ls(line);
    std::string id, upstream;
    ls >> id >> upstream;
    if (!home.count(id)) continue;
    ++log_lines;
    EXPECT_EQ(upstream.find(','), std::string::npos) << "nginx retried another upstream: " << line;
    upstream_of[id].insert(upstream);
  }
  for (const auto& [id, s] : home)
    EXPECT_EQ(upstream_of[id].size(), on_drained.count(id) ? 2u : 1u) << "session " << id << " in nginx's access log";

  std::map<std::string, int> after_count;
  for (const auto& [id, s] : new_home) ++after_count[s];
  size_t calls = 0;
  {
    std::lock_guard lock(log.m);
    calls = log.calls.size();
  }
  std::printf("[deploy] 3 servers + nginx: sessions per server before the drain: rrg-a %d, rrg-b %d, rrg-c %d "
              "(ids picked from %d probes); after: rrg-b %d, rrg-c %d\n", per_server["rrg-a"], per_server["rrg-b"],
              per_server["rrg-c"], probes, after_count["rrg-b"], after_count["rrg-c"]);
  std::printf("[deploy] calls checked: %zu client calls (x-rrg-server), %zu nginx access-log lines of the 12 sessions\n",
              calls, log_lines);
  std::printf("[deploy] drain of rrg-a: %.2f s (%d sessions saved); nginx reload until re-routed: %.2f s; "
              "test %.1f s\n", drain_s, d.saved_size(), reload_s, seconds_since(t_start));
  std::printf("[deploy] moved sessions' continued poses vs the uninterrupted run: max %.3f mm%s\n",
              moved_drift_m * 1e3, kSnapshotKeepsKeyframes ? "" : " (not asserted: snapshots drop keyframes)");
}

}  // namespace
}  // namespace rrg::test
