#include "server/session_manager.h"

#include "client/lib/proto_convert.h"
#include "core/io/atomic_file.h"
#include "core/io/frame_codec.h"
#include "core/slam/session_config.h"
#include "server/auth.h"
#include "server/status_error.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <fstream>

namespace rrg::server {

namespace fs = std::filesystem;

namespace {

// A client-proposed id: [a-z0-9-]{4,64} (safe as a file name, a header and a hash key).
bool valid_proposed_id(const std::string& id) {
  if (id.size() < 4 || id.size() > 64) return false;
  for (char c : id)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-')) return false;
  return true;
}

bool valid_id(const std::string& id) {
  if (id.empty() || id.size() > 64) return false;
  for (char c : id)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') return false;
  return true;
}

// Config keys a client may not override: the camera comes from Create's intrinsics, the device and
// the remote segmenter from the server's own flags.
void check_override_key(const std::string& key) {
  if (key.rfind("camera.", 0) == 0)
    throw std::invalid_argument("config." + key + ": the camera is set by CreateSessionRequest.intrinsics");
  if (key == "device" || key == "remote_address")
    throw std::invalid_argument("config." + key + ": set by the server (rrg serve flags), not by clients");
}

SessionConfig make_config(const v1::CreateSessionRequest& r, const ManagerOptions& o) {
  SessionConfig c = o.defaults;
  c.K = service::from_proto(r.intrinsics());
  c.device = o.device;
  c.remote_address = o.segmenter_address;
  // A client that names the schedule (sync or live, either value) chooses it: the server's default
  // schedule is dropped first, so `sync=true` on a server that defaults to live runs sync.
  for (const auto& [key, value] : r.config())
    if (key == "sync" || key == "live") c.sync = c.live = false;
  for (const auto& [key, value] : r.config()) {
    check_override_key(key);
    try {
      set_config_value(c, key, value);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("config." + key + ": " + e.what());
    }
  }
  for (const auto& p : r.prompts()) c.prompts.push_back(p);
  for (const auto& [id, name] : r.categories()) {
    if (id > 65535) throw std::invalid_argument("categories: label id " + std::to_string(id) + " is above 65535");
    c.categories[uint16_t(id)] = name;
  }
  if (c.semantics == "remote" && c.remote_address.empty())
    throw std::invalid_argument("config.semantics: remote needs a segmenter, and this server has none (--segmenter)");
  c.validate();
  return c;
}

}  // namespace

SessionConfig make_server_defaults(const std::filesystem::path& yaml, const std::vector<std::string>& assignments) {
  SessionConfig c;
  const SessionConfig plain;
  if (!yaml.empty()) {
    try {
      load_config_yaml(c, yaml);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("--config: ") + e.what());
    }
  }
  const auto server_owned = [](const std::string& key) {
    if (key.rfind("camera.", 0) == 0)
      throw std::invalid_argument("--set " + key + ": each session's camera comes from its Create request's intrinsics");
    if (key == "device" || key == "remote_address")
      throw std::invalid_argument("--set " + key + ": set by rrg serve's " +
                                  std::string(key == "device" ? "--device" : "--segmenter"));
  };
  for (const std::string& a : assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0) throw std::invalid_argument("--set '" + a + "': not key=value");
    server_owned(a.substr(0, eq));
    try {
      apply_override(c, a);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("--set " + a + ": " + e.what());
    }
  }
  if (!yaml.empty() && (c.K.fx != plain.K.fx || c.K.fy != plain.K.fy || c.K.cx != plain.K.cx || c.K.cy != plain.K.cy ||
                        c.K.width != plain.K.width || c.K.height != plain.K.height))
    throw std::invalid_argument("--config " + yaml.string() + ": camera: each session's camera comes from its Create request's intrinsics");
  if (!yaml.empty() && (c.device != plain.device || c.remote_address != plain.remote_address))
    throw std::invalid_argument("--config " + yaml.string() + ": device and remote_address are set by rrg serve's --device and --segmenter");
  SessionConfig check = c;  // validated as a session's config, with a stand-in camera
  check.K = Intrinsics{525.0f, 525.0f, 319.5f, 239.5f, 640, 480};
  if (check.semantics == "remote") check.remote_address = "stand-in";  // the server checks --segmenter per Create
  try {
    check.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("session defaults (--config / --set): ") + e.what());
  }
  return c;
}

SessionManager::SessionManager(ManagerOptions options, Metrics& metrics) : options_(std::move(options)), metrics_(metrics) {
  if (!options_.snapshot_dir.empty()) fs::create_directories(options_.snapshot_dir);
  if (options_.idle_timeout_s > 0) reaper_ = std::thread([this] { reap_idle(); });
}

SessionManager::~SessionManager() {
  {
    std::lock_guard lock(reaper_mutex_);
    reaper_quit_ = true;
  }
  reaper_cv_.notify_all();
  if (reaper_.joinable()) reaper_.join();
}

SessionStatus SessionManager::used_bytes() const {
  SessionStatus used;
  for (const auto& [id, s] : sessions_) {
    const SessionStatus st = s->session().status();
    used.device_bytes += st.device_bytes;
    used.host_bytes += st.host_bytes;
  }
  return used;
}

// A Create / Load that reserved `id` (admit + reserved_ids_) is done: the session goes live, or,
// with `managed` null (construction failed), only the reservation is released.
void SessionManager::end_construction(const std::string& id, std::shared_ptr<ManagedSession> managed) {
  std::lock_guard lock(mutex_);
  reserved_ids_.erase(id);
  if (!managed) return;
  drained_.erase(id);
  sessions_[id] = std::move(managed);
}

void SessionManager::admit(size_t extra) const {
  const size_t n = sessions_.size() + reserved_ids_.size();
  if (n + extra > options_.max_sessions)
    throw exhausted("admission: the server already runs " + std::to_string(n) + " sessions (max " +
                    std::to_string(options_.max_sessions) + ")");
  if (!options_.total_budget.any()) return;
  // Every session may grow to its per-session budget, so that much is reserved per session.
  const SessionStatus st = used_bytes();
  const size_t sessions = sessions_.size() + reserved_ids_.size();
  const auto check = [&](const char* what, size_t used, size_t reserve, size_t total) {
    if (total == 0) return;
    const size_t reserved = std::max(used, sessions * reserve);
    if (reserved + reserve > total || used >= total)
      throw exhausted(std::string("admission: ") + what + ": " + std::to_string(reserved) + " bytes in use or reserved, a new "
                      "session reserves " + std::to_string(reserve) + ", total budget " + std::to_string(total));
  };
  check("memory budget", st.device_bytes + st.host_bytes, options_.session_budget.memory, options_.total_budget.memory);
  check("device budget", st.device_bytes, options_.session_budget.device, options_.total_budget.device);
}

bool SessionManager::has_capacity() const {
  if (draining_) return false;
  std::lock_guard lock(mutex_);
  try {
    admit(1);
    return true;
  } catch (const StatusError&) {
    return false;
  }
}

v1::CreateSessionResponse SessionManager::create(const grpc::ServerContextBase& ctx, const v1::CreateSessionRequest& r) {
  if (draining_)
    throw StatusError(grpc::StatusCode::UNAVAILABLE, "create: server " + options_.server_name +
                                                         " is draining; create the session on another server");
  const std::string header = session_header(ctx);
  if (!r.session_id().empty() && !header.empty() && header != r.session_id())
    throw std::invalid_argument("session_id: '" + r.session_id() + "' but the x-rrg-session header says '" + header + "'");
  const std::string proposed = r.session_id().empty() ? header : r.session_id();
  if (!proposed.empty() && !valid_proposed_id(proposed))
    throw std::invalid_argument("session_id: '" + proposed + "' must be 4 to 64 characters of [a-z0-9-]");
  if (!r.has_intrinsics()) throw std::invalid_argument("intrinsics: missing");
  io::validate_intrinsics(service::from_proto(r.intrinsics()));
  const float depth_scale = r.depth_scale() == 0.0f ? 1000.0f : r.depth_scale();
  io::validate_depth_scale(depth_scale);
  const size_t queue = r.queue_capacity() == 0 ? options_.default_queue : r.queue_capacity();
  if (queue > options_.max_queue)
    throw std::invalid_argument("queue_capacity: " + std::to_string(queue) + " is above the server's maximum " +
                                std::to_string(options_.max_queue));
  if (r.name().size() > 256) throw std::invalid_argument("name: longer than 256 characters");
  SessionConfig config = make_config(r, options_);

  const std::string id = proposed.empty() ? new_session_id() : proposed;
  {
    std::lock_guard lock(mutex_);
    if (sessions_.count(id) || reserved_ids_.count(id))
      throw StatusError(grpc::StatusCode::ALREADY_EXISTS, "session_id: " + id + " is taken (live on server " +
                                                              options_.server_name + ")");
    if (!options_.snapshot_dir.empty() && fs::exists(meta_file(id)))
      throw StatusError(grpc::StatusCode::ALREADY_EXISTS, "session_id: " + id +
                                                              " is taken (saved in the snapshot folder: Load it, or choose another id)");
    admit(1);
    reserved_ids_.insert(id);
  }
  std::shared_ptr<ManagedSession> managed;
  v1::CreateSessionResponse out;
  try {
    auto session = std::make_unique<Session>(std::move(config));
    if (const std::string over = options_.session_budget.excess(session->status()); !over.empty())
      throw exhausted("admission: a new session takes " + over + " per session");
    SessionMeta meta;
    meta.id = id;
    meta.name = r.name();
    const std::string token = new_token();
    meta.token_sha256 = sha256_hex(token);
    meta.depth_scale = depth_scale;
    meta.queue_capacity = queue;
    meta.budget = options_.session_budget;
    managed = std::make_shared<ManagedSession>(std::move(meta), std::move(session), metrics_);
    out.set_session_id(managed->meta().id);
    out.set_token(token);
  } catch (...) {
    end_construction(id, nullptr);
    throw;
  }
  end_construction(id, managed);
  metrics_.session_created();
  *out.mutable_info() = managed->info();
  spdlog::info("session {} created: '{}', {}x{}, device {}, queue {}", out.session_id(), r.name(),
               r.intrinsics().width(), r.intrinsics().height(), out.info().device(), managed->meta().queue_capacity);
  return out;
}

std::shared_ptr<ManagedSession> SessionManager::find(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = sessions_.find(id);
  if (it != sessions_.end()) return it->second;
  const auto d = drained_.find(id);
  if (d != drained_.end())
    throw not_found("not found: server " + options_.server_name + " drained session " + id +
                    (d->second ? " and saved it to the snapshot folder: Load it on another server sharing that folder"
                               : " but could not save it (see the server's log)"));
  throw not_found("not found: server " + options_.server_name + " does not hold session " + id +
                  "; it may be on another server or saved: Load it");
}

std::shared_ptr<ManagedSession> SessionManager::authorize(const grpc::ServerContextBase& ctx,
                                                          const std::string& request_id) const {
  const std::string id = request_id.empty() ? session_header(ctx) : request_id;
  if (id.empty()) throw std::invalid_argument("session_id: missing (set the field or the x-rrg-session header)");
  const auto token = bearer_token(ctx);
  if (!token) throw unauthenticated("authorization: missing 'Bearer <token>' metadata");
  auto s = find(id);
  const bool admin = !options_.admin_key.empty() && constant_time_equal(*token, options_.admin_key);
  if (!admin && !constant_time_equal(sha256_hex(*token), s->meta().token_sha256))
    throw unauthenticated("authorization: wrong token for session " + id);
  s->touch();
  return s;
}

void SessionManager::require_admin(const grpc::ServerContextBase& ctx) const {
  if (options_.admin_key.empty()) return;
  const auto token = bearer_token(ctx);
  if (!token || !constant_time_equal(*token, options_.admin_key))
    throw unauthenticated("authorization: this call needs the admin key");
}

std::vector<std::shared_ptr<ManagedSession>> SessionManager::list() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<ManagedSession>> v;
  for (const auto& [id, s] : sessions_) v.push_back(s);
  return v;
}

size_t SessionManager::size() const {
  std::lock_guard lock(mutex_);
  return sessions_.size();
}

fs::path SessionManager::snapshot_file(const std::string& id) const { return options_.snapshot_dir / (id + ".rrgsnap"); }
fs::path SessionManager::meta_file(const std::string& id) const { return options_.snapshot_dir / (id + ".json"); }

void SessionManager::write_meta(const ManagedSession& s) const {
  const SessionMeta& m = s.meta();
  nlohmann::json j = {{"format", "rrg-service-session"}, {"version", 1},        {"id", m.id},
                      {"name", m.name},                  {"token_sha256", m.token_sha256},
                      {"depth_scale", m.depth_scale},    {"queue_capacity", m.queue_capacity},
                      {"frames_dropped", s.frames_dropped()}};
  io::write_atomically(meta_file(m.id), [&](const fs::path& tmp) {
    std::ofstream f(tmp);
    f << j.dump(2) << "\n";
    if (!f) throw std::runtime_error("save: cannot write " + tmp.string());
  });
}

v1::SaveSessionResponse SessionManager::save(ManagedSession& s) {
  if (options_.snapshot_dir.empty())
    throw StatusError(grpc::StatusCode::FAILED_PRECONDITION, "save: the server has no snapshot folder (--snapshot-dir)");
  v1::SaveSessionResponse out;
  s.with_worker_paused([&](Session& session) {
    session.flush();
    session.save(snapshot_file(s.meta().id));
    write_meta(s);
    const SessionStatus st = session.status();
    out.set_map_version(st.map_version);
    out.set_frames(uint64_t(st.frames));
  });
  out.set_snapshot(s.meta().id);
  out.set_bytes(fs::file_size(snapshot_file(s.meta().id)));
  spdlog::info("session {} saved: {} frames, map version {}, {} bytes", s.meta().id, out.frames(), out.map_version(),
               out.bytes());
  return out;
}

v1::CloseSessionResponse SessionManager::close(const std::string& id, bool save_first) {
  auto s = find(id);
  s->stop(true);
  if (save_first) save(*s);
  v1::CloseSessionResponse out;
  *out.mutable_info() = s->info();
  {
    std::lock_guard lock(mutex_);
    sessions_.erase(id);
  }
  spdlog::info("session {} closed{}", id, save_first ? " (saved)" : "");
  return out;
}

v1::CreateSessionResponse SessionManager::load(const grpc::ServerContextBase& ctx, const std::string& id) {
  if (!valid_id(id)) throw std::invalid_argument("session_id: '" + id + "' is not a session id");
  if (options_.snapshot_dir.empty())
    throw StatusError(grpc::StatusCode::FAILED_PRECONDITION, "load: the server has no snapshot folder (--snapshot-dir)");
  if (!fs::exists(meta_file(id)) || !fs::exists(snapshot_file(id))) throw not_found("load: no snapshot of session " + id);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(std::ifstream(meta_file(id)));
  } catch (const std::exception& e) {
    throw StatusError(grpc::StatusCode::DATA_LOSS, "load: " + meta_file(id).string() + ": " + e.what());
  }
  const auto token = bearer_token(ctx);
  if (!token) throw unauthenticated("authorization: missing 'Bearer <token>' metadata");
  const bool admin = !options_.admin_key.empty() && constant_time_equal(*token, options_.admin_key);
  const std::string saved_sha = j.value("token_sha256", "");
  if (!admin && !constant_time_equal(sha256_hex(*token), saved_sha))
    throw unauthenticated("authorization: wrong token for session " + id);
  {
    std::lock_guard lock(mutex_);
    if (draining_)
      throw StatusError(grpc::StatusCode::UNAVAILABLE, "load: server " + options_.server_name +
                                                           " is draining; load the session on another server");
    if (sessions_.count(id) || reserved_ids_.count(id))
      throw StatusError(grpc::StatusCode::ALREADY_EXISTS, "load: session " + id + " is live on server " + options_.server_name);
    admit(1);
    reserved_ids_.insert(id);
  }
  v1::CreateSessionResponse out;
  std::shared_ptr<ManagedSession> managed;
  try {
    auto session = Session::load(snapshot_file(id));
    if (const std::string over = options_.session_budget.excess(session->status()); !over.empty())
      throw exhausted("load: session " + id + " takes " + over + " per session");
    SessionMeta meta;
    meta.id = id;
    meta.name = j.value("name", "");
    meta.depth_scale = j.value("depth_scale", 1000.0f);
    meta.queue_capacity = j.value("queue_capacity", options_.default_queue);
    meta.budget = options_.session_budget;
    // The session's own token keeps working; an admin load issues a new one.
    const std::string new_tok = admin ? new_token() : *token;
    meta.token_sha256 = sha256_hex(new_tok);
    managed = std::make_shared<ManagedSession>(std::move(meta), std::move(session), metrics_,
                                               j.value("frames_dropped", uint64_t(0)));
    if (admin) write_meta(*managed);
    out.set_session_id(id);
    out.set_token(new_tok);
  } catch (...) {
    end_construction(id, nullptr);
    throw;
  }
  end_construction(id, managed);
  metrics_.session_created();
  *out.mutable_info() = managed->info();
  spdlog::info("session {} loaded: {} frames, map version {}", id, out.info().frames(), out.info().map_version());
  return out;
}

void SessionManager::reap_idle() {
  const auto period = std::chrono::duration<double>(std::clamp(options_.idle_timeout_s / 4.0, 0.05, 1.0));
  std::unique_lock lock(reaper_mutex_);
  while (!reaper_cv_.wait_for(lock, period, [&] { return reaper_quit_; })) {
    for (const auto& s : list()) {
      if (s->busy() || s->idle_seconds() < options_.idle_timeout_s) continue;
      spdlog::info("session {} idle for {:.1f} s: {}", s->meta().id, s->idle_seconds(),
                   options_.snapshot_dir.empty() ? "freeing it (no snapshot folder)" : "snapshot, then free");
      try {
        close(s->meta().id, !options_.snapshot_dir.empty());
      } catch (const std::exception& e) {
        spdlog::error("session {}: idle close failed: {}", s->meta().id, e.what());
      }
    }
  }
}

void SessionManager::shutdown() {
  for (const auto& s : list()) {
    try {
      close(s->meta().id, !options_.snapshot_dir.empty());
    } catch (const std::exception& e) {
      spdlog::error("session {}: shutdown snapshot failed: {}", s->meta().id, e.what());
    }
  }
}

v1::DrainResponse SessionManager::drain() {
  std::lock_guard drain_lock(drain_mutex_);
  draining_ = true;
  v1::DrainResponse out;
  out.set_server(options_.server_name);
  // A Create / Load admitted just before draining_ was set may still be constructing its session.
  for (int i = 0; i < 600; ++i) {
    {
      std::lock_guard lock(mutex_);
      if (reserved_ids_.empty()) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  for (const auto& s : list()) {
    const std::string id = s->meta().id;
    {
      std::lock_guard lock(mutex_);
      drained_[id] = true;  // read only once the session has left sessions_
    }
    try {
      const bool can_save = !options_.snapshot_dir.empty();
      close(id, can_save);  // queued frames are processed first
      if (can_save) {
        out.add_saved(id);
      } else {
        out.add_failed(id + ": not saved: the server has no snapshot folder (--snapshot-dir)");
        std::lock_guard lock(mutex_);
        drained_[id] = false;
      }
    } catch (const std::exception& e) {
      out.add_failed(id + ": " + e.what());
      spdlog::error("drain: session {}: snapshot failed: {}; freeing it", id, e.what());
      std::lock_guard lock(mutex_);
      drained_[id] = false;
      sessions_.erase(id);
    }
  }
  spdlog::info("drain: server {} drained: {} sessions saved, {} failed", options_.server_name, out.saved_size(),
               out.failed_size());
  return out;
}

std::string SessionManager::gauges() const {
  std::string s;
  size_t device = 0, host = 0, queued = 0;
  size_t n = 0;
  for (const auto& m : list()) {
    const v1::SessionInfo i = m->info();
    device += i.device_bytes();
    host += i.host_bytes();
    queued += i.queue_depth();
    ++n;
  }
  s += "# HELP rrg_sessions Live sessions.\n# TYPE rrg_sessions gauge\n";
  s += "rrg_sessions " + std::to_string(n) + "\n";
  s += "# HELP rrg_sessions_max Session limit.\n# TYPE rrg_sessions_max gauge\n";
  s += "rrg_sessions_max " + std::to_string(options_.max_sessions) + "\n";
  s += "# HELP rrg_memory_bytes Memory used by all sessions.\n# TYPE rrg_memory_bytes gauge\n";
  s += "rrg_memory_bytes{kind=\"device\"} " + std::to_string(device) + "\n";
  s += "rrg_memory_bytes{kind=\"host\"} " + std::to_string(host) + "\n";
  s += "# HELP rrg_queued_frames Frames waiting in session queues.\n# TYPE rrg_queued_frames gauge\n";
  s += "rrg_queued_frames " + std::to_string(queued) + "\n";
  return s;
}

}  // namespace rrg::server
