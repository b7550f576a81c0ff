#pragma once
// The server's sessions: creation with admission control (max sessions, per-session and total
// memory budgets -> RESOURCE_EXHAUSTED with the reason), lookup with bearer-token auth, Close,
// Save / Load to the snapshot folder (Session::save plus a JSON sidecar of the service's own
// metadata, both written atomically), the idle timeout (snapshot, then free) and the final
// snapshot of every session at shutdown, and draining (issue #11): refuse new sessions, snapshot
// and free every session, and remember which were drained so later calls say where they went.
#include "core/common/device.h"
#include "core/slam/session_config.h"
#include "rrg/v1/service.pb.h"
#include "server/managed_session.h"
#include "server/memory_budget.h"
#include "server/metrics.h"

#include <grpcpp/server_context.h>

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace rrg::server {

struct ManagerOptions {
  size_t max_sessions = 16;
  MemoryBudget session_budget;       // per session (server/memory_budget.h); 0 = none
  MemoryBudget total_budget;         // over all sessions; each session reserves session_budget of it
  size_t default_queue = 8;          // frame queue capacity when Create asks for 0
  size_t max_queue = 256;
  std::filesystem::path snapshot_dir;  // empty = Save / Load / idle snapshots unavailable
  double idle_timeout_s = 0;         // 0 = never
  Device device;                     // where sessions run
  std::string admin_key;             // empty = no admin key
  std::string segmenter_address;     // for sessions whose config asks for semantics = remote
  std::string server_name = "rrg";   // named in errors and sent as x-rrg-server (rrg serve --name)
  // Every session's base config (rrg serve --config / --set); a Create's overrides apply on top,
  // and a Create naming `sync` or `live` chooses the schedule itself (make_server_defaults).
  SessionConfig defaults;
};

// The base config of the server's sessions: the YAML file (when given), then the key=value
// assignments, as `rrg run` reads them. The camera (each Create's intrinsics), the device
// (--device) and the segmenter (--segmenter) are the server's own and refused here; the rest is
// validated as a session's would be (with a stand-in camera). std::invalid_argument naming the
// key or the file otherwise.
SessionConfig make_server_defaults(const std::filesystem::path& yaml, const std::vector<std::string>& assignments);

class SessionManager {
 public:
  SessionManager(ManagerOptions options, Metrics& metrics);
  ~SessionManager();  // stops the idle reaper; sessions are freed without snapshots (see shutdown)

  // The id is request.session_id, else the x-rrg-session header, else a random one; a proposed
  // id must match [a-z0-9-]{4,64} and be neither live nor saved (ALREADY_EXISTS).
  // UNAVAILABLE while draining.
  v1::CreateSessionResponse create(const grpc::ServerContextBase& ctx, const v1::CreateSessionRequest& request);
  // The session `id` (or the x-rrg-session header when id is empty) if the call's bearer token is
  // its token or the admin key. NOT_FOUND / UNAUTHENTICATED / INVALID_ARGUMENT (no id) otherwise.
  std::shared_ptr<ManagedSession> authorize(const grpc::ServerContextBase& ctx, const std::string& id) const;
  // UNAUTHENTICATED unless the call carries the admin key (a no-op when none is configured).
  void require_admin(const grpc::ServerContextBase& ctx) const;

  std::vector<std::shared_ptr<ManagedSession>> list() const;
  v1::CloseSessionResponse close(const std::string& id, bool save);
  v1::SaveSessionResponse save(ManagedSession& s);
  // Auth: the admin key, or the token the session had when saved (which is then kept).
  v1::CreateSessionResponse load(const grpc::ServerContextBase& ctx, const std::string& id);

  size_t size() const;
  bool has_capacity() const;   // a Create would pass the session-count and memory checks now
  std::string gauges() const;  // Prometheus lines: sessions, memory, queues
  // Snapshots (when a snapshot folder is set) and frees every session; queued frames are processed.
  void shutdown();
  // From now on Create / Load answer UNAVAILABLE and has_capacity() is false; then every session
  // is snapshotted (queued frames processed first) and freed. Calls on a drained session get
  // NOT_FOUND saying it was drained and can be loaded elsewhere. Idempotent.
  v1::DrainResponse drain();
  bool draining() const { return draining_.load(); }
  const ManagerOptions& options() const { return options_; }

 private:
  std::shared_ptr<ManagedSession> find(const std::string& id) const;
  void admit(size_t extra_sessions) const;  // throws RESOURCE_EXHAUSTED; caller holds mutex_
  SessionStatus used_bytes() const;         // device_bytes and host_bytes summed; caller holds mutex_
  std::filesystem::path snapshot_file(const std::string& id) const;
  std::filesystem::path meta_file(const std::string& id) const;
  void write_meta(const ManagedSession& s) const;
  void reap_idle();
  void end_construction(const std::string& id, std::shared_ptr<ManagedSession> managed);

  ManagerOptions options_;
  Metrics& metrics_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<ManagedSession>> sessions_;
  std::map<std::string, bool> drained_;  // id -> snapshot written
  std::set<std::string> reserved_ids_;   // ids of sessions admitted and being constructed (Create / Load)
  std::atomic<bool> draining_{false};
  std::mutex drain_mutex_;  // one drain at a time

  std::mutex reaper_mutex_;
  std::condition_variable reaper_cv_;
  bool reaper_quit_ = false;
  std::thread reaper_;
};

}  // namespace rrg::server
