#include "server/http_api.h"

#include "client/lib/proto_convert.h"
#include "core/gaussians/spz.h"
#include "core/io/atomic_file.h"
#include "core/io/frame_codec.h"
#include "server/auth.h"
#include "server/mesh_chunks.h"
#include "server/status_error.h"
#include "server/view_encode.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#if RRG_WITH_HTTPLIB
#include <httplib.h>
#endif

#include <atomic>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace rrg::server {

std::filesystem::path default_viewer_dir() {
#ifdef RRG_SOURCE_DIR
  const std::filesystem::path dir = std::filesystem::path(RRG_SOURCE_DIR) / "web_viewer" / "dist";
  std::error_code ec;
  if (std::filesystem::is_regular_file(dir / "index.html", ec)) return dir;
#endif
  return {};
}

#if RRG_WITH_HTTPLIB

namespace {

using nlohmann::json;
constexpr int64_t kMaxRenderPixels = int64_t(4096) * 4096;

// An HTTP error with its status code; the message names the parameter.
struct HttpError : std::runtime_error {
  HttpError(int status, const std::string& m) : std::runtime_error(m), status(status) {}
  int status;
};

void send_json(httplib::Response& res, const json& j, int status = 200) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  res.set_content(j.dump(), "application/json");
}

// Runs a handler, turning every exception into a JSON error (never a crash).
template <class F>
httplib::Server::Handler guarded(F f) {
  return [f](const httplib::Request& req, httplib::Response& res) {
    try {
      f(req, res);
    } catch (const HttpError& e) {
      send_json(res, {{"error", e.what()}}, e.status);
    } catch (const std::invalid_argument& e) {
      send_json(res, {{"error", e.what()}}, 400);
    } catch (const StatusError& e) {
      const int status = e.code() == grpc::StatusCode::NOT_FOUND         ? 404
                         : e.code() == grpc::StatusCode::UNAUTHENTICATED ? 401
                         : e.code() == grpc::StatusCode::RESOURCE_EXHAUSTED ? 503
                                                                            : 500;
      send_json(res, {{"error", e.what()}}, status);
    } catch (const std::exception& e) {
      spdlog::warn("http: {} {}: {}", req.method, req.path, e.what());
      send_json(res, {{"error", std::string("internal: ") + e.what()}}, 500);
    }
  };
}

std::string token_of(const httplib::Request& req) {
  const std::string h = req.get_header_value("Authorization");
  if (h.rfind("Bearer ", 0) == 0) return h.substr(7);
  return req.get_param_value("token");
}

double parse_number(const std::string& s, const std::string& name) {
  double v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v))
    throw std::invalid_argument(name + ": '" + s + "' is not a finite number");
  return v;
}

// T_wc from "tx,ty,tz,qx,qy,qz,qw" (OpenCV camera axes, metres).
Eigen::Isometry3f parse_pose(const std::string& s) {
  std::vector<double> v;
  size_t start = 0;
  while (start <= s.size() && v.size() < 8) {
    const size_t comma = s.find(',', start);
    const size_t end = comma == std::string::npos ? s.size() : comma;
    v.push_back(parse_number(s.substr(start, end - start), "pose[" + std::to_string(v.size()) + "]"));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 7) throw std::invalid_argument("pose: expected 7 comma-separated numbers tx,ty,tz,qx,qy,qz,qw");
  v1::Pose p;
  p.set_tx(v[0]), p.set_ty(v[1]), p.set_tz(v[2]), p.set_qx(v[3]), p.set_qy(v[4]), p.set_qz(v[5]), p.set_qw(v[6]);
  return service::from_proto(p, "pose");
}

json pose_json(const v1::Pose& p) { return json::array({p.tx(), p.ty(), p.tz(), p.qx(), p.qy(), p.qz(), p.qw()}); }

const char* state_name(v1::TrackingState s) {
  switch (s) {
    case v1::TRACKING_OK: return "ok";
    case v1::TRACKING_DEGRADED: return "degraded";
    case v1::TRACKING_LOST: return "lost";
    default: return "unknown";
  }
}

json info_json(const v1::SessionInfo& i) {
  return {{"id", i.session_id()},
          {"name", i.name()},
          {"frames", i.frames()},
          {"fused", i.fused()},
          {"lost", i.lost()},
          {"last_frame_id", i.last_frame_id()},
          {"state", state_name(i.state())},
          {"pose", pose_json(i.pose())},
          {"map_version", i.map_version()},
          {"tsdf_blocks", i.tsdf_blocks()},
          {"tsdf_resident_blocks", i.tsdf_resident_blocks()},
          {"base_gaussians", i.base_gaussians()},
          {"reflection_gaussians", i.reflection_gaussians()},
          {"reflective_planes", std::vector<int>(i.reflective_planes().begin(), i.reflective_planes().end())},
          {"memory_bytes", i.device_bytes() + i.host_bytes()},
          {"device_bytes", i.device_bytes()},
          {"host_bytes", i.host_bytes()},
          {"frames_dropped", i.frames_dropped()},
          {"device", i.device()},
          {"intrinsics",
           {{"fx", i.intrinsics().fx()},
            {"fy", i.intrinsics().fy()},
            {"cx", i.intrinsics().cx()},
            {"cy", i.intrinsics().cy()},
            {"width", i.intrinsics().width()},
            {"height", i.intrinsics().height()}}}};
}

// Events of one /events connection: filled by the session's worker (never blocks), drained by the
// connection's thread.
struct EventFeed {
  std::mutex m;
  std::condition_variable cv;
  std::deque<std::string> queue;
  bool closed = false;

  void push(std::string text, bool last) {
    {
      std::lock_guard lock(m);
      if (queue.size() >= 512) queue.pop_front();  // a stalled client loses the oldest events
      queue.push_back(std::move(text));
      closed = closed || last;
    }
    cv.notify_one();
  }
};

std::string sse(const char* event, const json& data) { return std::string("event: ") + event + "\ndata: " + data.dump() + "\n\n"; }

std::string event_text(const v1::SessionEvent& e) {
  if (e.has_pose())
    return sse("pose", {{"frame", e.pose().frame_id()},
                        {"timestamp", e.pose().timestamp()},
                        {"pose", pose_json(e.pose().pose())},
                        {"state", state_name(e.pose().state())}});
  if (e.has_map())
    return sse("map", {{"map_version", e.map().map_version()},
                       {"base_gaussians", e.map().base_gaussians()},
                       {"reflection_gaussians", e.map().reflection_gaussians()}});
  return sse("closed", json::object());
}

v1::RenderPass parse_pass(const std::string& s) {
  if (s.empty() || s == "final") return v1::PASS_FINAL;
  if (s == "base") return v1::PASS_BASE;
  if (s == "reflection") return v1::PASS_REFLECTION;
  if (s == "mask") return v1::PASS_MASK;
  throw std::invalid_argument("pass: '" + s + "' is not one of final, base, reflection, mask");
}

}  // namespace

struct HttpApiServer::Impl {
  SessionManager& manager;
  httplib::Server http;
  std::thread thread;
  std::atomic<bool> stopping{false};
  std::mutex chunks_mutex;
  std::map<std::string, std::shared_ptr<MeshChunks>> chunks;  // per session id

  explicit Impl(SessionManager& m) : manager(m) {}

  std::shared_ptr<ManagedSession> session(const httplib::Request& req) {
    const std::string id = req.matches[1];
    std::shared_ptr<ManagedSession> found;
    for (auto& s : manager.list())
      if (s->meta().id == id) found = s;
    if (!found) throw HttpError(404, "session: no session " + id);
    const std::string token = token_of(req);
    const std::string& admin = manager.options().admin_key;
    const bool ok = !token.empty() && (constant_time_equal(sha256_hex(token), found->meta().token_sha256) ||
                                       (!admin.empty() && constant_time_equal(token, admin)));
    if (!ok) throw HttpError(401, token.empty() ? "token: missing (Authorization: Bearer T or ?token=T)"
                                                : "token: not valid for session " + id);
    found->touch();
    return found;
  }

  std::shared_ptr<MeshChunks> chunks_of(const std::string& id) {
    std::lock_guard lock(chunks_mutex);
    // forget sessions that are gone
    const auto live = manager.list();
    for (auto it = chunks.begin(); it != chunks.end();) {
      bool alive = false;
      for (const auto& s : live) alive = alive || s->meta().id == it->first;
      it = alive ? std::next(it) : chunks.erase(it);
    }
    auto& c = chunks[id];
    if (!c) c = std::make_shared<MeshChunks>();
    return c;
  }

  void routes();
  void events(const httplib::Request& req, httplib::Response& res);
  void render(const httplib::Request& req, httplib::Response& res);
};

void HttpApiServer::Impl::routes() {
  http.Get("/api/sessions", guarded([this](const httplib::Request& req, httplib::Response& res) {
    const std::string& admin = manager.options().admin_key;
    if (!admin.empty() && !constant_time_equal(token_of(req), admin))
      throw HttpError(401, "token: the session list needs the admin key");
    json list = json::array();
    for (const auto& s : manager.list()) list.push_back(info_json(s->info()));
    send_json(res, {{"sessions", list}});
  }));
  http.Get(R"(/api/sessions/([^/]+))", guarded([this](const httplib::Request& req, httplib::Response& res) {
    json j = info_json(session(req)->info());
    j["units"] = "metres";
    j["axes"] = {{"camera", "OpenCV: x right, y down, z forward (the viewing direction)"},
                 {"pose", "T_wc: camera -> world, [tx, ty, tz, qx, qy, qz, qw]"},
                 {"world", "the session's world frame: the first frame's pose prior, else the first camera"}};
    j["mesh_chunk_blocks"] = kChunkBlocks;
    send_json(res, j);
  }));
  http.Get(R"(/api/sessions/([^/]+)/mesh/chunks)", guarded([this](const httplib::Request& req, httplib::Response& res) {
    const auto s = session(req);
    json list = json::array();
    for (const MeshChunkInfo& c : chunks_of(s->meta().id)->list(s->session())) {
      json j = {{"key", c.key}, {"version", c.version}, {"etag", c.etag}};
      if (c.bytes) j["bytes"] = *c.bytes;
      list.push_back(j);
    }
    send_json(res, {{"map_version", s->session().status().map_version}, {"chunks", list}});
  }));
  http.Get(R"(/api/sessions/([^/]+)/mesh/chunk/([^/]+)\.drc)",
           guarded([this](const httplib::Request& req, httplib::Response& res) {
             const auto s = session(req);
             MeshChunkData d;
             try {
               d = chunks_of(s->meta().id)->get(s->session(), req.matches[2]);
             } catch (const std::out_of_range& e) {
               throw HttpError(404, std::string("key: ") + e.what());
             }
             res.set_header("ETag", d.etag);
             res.set_header("Cache-Control", "no-cache");
             if (req.get_header_value("If-None-Match") == d.etag) {
               res.status = 304;
               return;
             }
             if (d.drc->empty()) {
               res.status = 204;  // the chunk's blocks hold no surface yet
               return;
             }
             res.set_content(reinterpret_cast<const char*>(d.drc->data()), d.drc->size(), "application/octet-stream");
           }));
  http.Get(R"(/api/sessions/([^/]+)/gaussians\.spz)", guarded([this](const httplib::Request& req, httplib::Response& res) {
    const auto s = session(req);
    // The Gaussians change only at mapping steps (the map version also bumps on every fusion).
    const SessionStatus st = s->session().status();
    const std::string etag = fmt::format("\"g{}-{}\"", st.mapping.steps, st.mapping.base_gaussians);
    res.set_header("ETag", etag);
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Map-Version", std::to_string(st.map_version));
    if (req.get_header_value("If-None-Match") == etag) {
      res.status = 304;
      return;
    }
    const GaussianHost g = s->session().base_gaussians();
    res.set_header("X-Gaussians", std::to_string(g.size()));
    if (g.size() == 0) {
      res.status = 204;
      return;
    }
    const std::vector<uint8_t> spz = encode_spz(g);
    res.set_content(reinterpret_cast<const char*>(spz.data()), spz.size(), "application/octet-stream");
  }));
  http.Get(R"(/api/sessions/([^/]+)/events)",
           guarded([this](const httplib::Request& req, httplib::Response& res) { events(req, res); }));
  http.Get(R"(/api/sessions/([^/]+)/render)",
           guarded([this](const httplib::Request& req, httplib::Response& res) { render(req, res); }));
  http.Get(R"(/api/.*)", [](const httplib::Request& req, httplib::Response& res) {
    send_json(res, {{"error", "path: no API route " + req.path}}, 404);
  });
}

void HttpApiServer::Impl::events(const httplib::Request& req, httplib::Response& res) {
  const auto s = session(req);
  auto feed = std::make_shared<EventFeed>();
  const SessionStatus st = s->session().status();
  feed->push(sse("hello", {{"frames", st.frames},
                           {"pose", pose_json(service::to_proto(st.T_wc))},
                           {"map_version", st.map_version},
                           {"base_gaussians", st.mapping.base_gaussians}}),
             false);
  const uint64_t sub = s->subscribe([feed](const v1::SessionEvent& e) {
    feed->push(event_text(e), e.event_case() == v1::SessionEvent::kClosed);
  });
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Accel-Buffering", "no");
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, feed](size_t, httplib::DataSink& sink) {
        std::deque<std::string> out;
        bool closed = false;
        {
          std::unique_lock lock(feed->m);
          feed->cv.wait_for(lock, std::chrono::seconds(1), [&] { return !feed->queue.empty() || feed->closed; });
          out.swap(feed->queue);
          closed = feed->closed;
        }
        if (out.empty() && !closed) out.push_back(": keep-alive\n\n");
        for (const std::string& text : out)
          if (!sink.write(text.data(), text.size())) return false;  // the client went away
        if (closed || stopping) sink.done();
        return true;
      },
      [s, sub](bool) { s->unsubscribe(sub); });
}

void HttpApiServer::Impl::render(const httplib::Request& req, httplib::Response& res) {
  const auto s = session(req);
  if (!req.has_param("pose")) throw std::invalid_argument("pose: missing (tx,ty,tz,qx,qy,qz,qw of T_wc)");
  const Eigen::Isometry3f T = parse_pose(req.get_param_value("pose"));
  Intrinsics K = s->session().config().K;
  const bool custom = req.has_param("fx") || req.has_param("fy") || req.has_param("w") || req.has_param("h");
  if (custom) {
    for (const char* p : {"fx", "fy", "w", "h"})
      if (!req.has_param(p)) throw std::invalid_argument(std::string(p) + ": missing (fx, fy, w, h go together)");
    const double w = parse_number(req.get_param_value("w"), "w"), h = parse_number(req.get_param_value("h"), "h");
    if (w != std::floor(w) || h != std::floor(h) || w < 1 || h < 1 || w > 4096 || h > 4096)
      throw std::invalid_argument("w, h: must be whole numbers of pixels in 1..4096");
    K.width = int(w);
    K.height = int(h);
    K.fx = float(parse_number(req.get_param_value("fx"), "fx"));
    K.fy = float(parse_number(req.get_param_value("fy"), "fy"));
    K.cx = req.has_param("cx") ? float(parse_number(req.get_param_value("cx"), "cx")) : float(w) / 2;
    K.cy = req.has_param("cy") ? float(parse_number(req.get_param_value("cy"), "cy")) : float(h) / 2;
    io::validate_intrinsics(K);
    if (int64_t(K.width) * K.height > kMaxRenderPixels) throw std::invalid_argument("w, h: above 4096x4096 pixels");
  }
  const std::string pass_name = req.has_param("pass") ? req.get_param_value("pass") : req.get_param_value("passes");
  const v1::RenderPass pass = parse_pass(pass_name);
  const uint64_t version = s->session().status().map_version;
  const v1::RenderViewResponse view = encode_view(s->session().render(K, T), {pass});
  if (view.images_size() != 1) throw std::runtime_error("render: no image for the pass");
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Map-Version", std::to_string(version));
  res.set_content(view.images(0).png(), "image/png");
}

HttpApiServer::HttpApiServer(const HttpApiOptions& o, SessionManager& manager)
    : impl_(std::make_unique<Impl>(manager)) {
  Impl& m = *impl_;
  // Event streams hold a thread each: a larger pool than httplib's default (cpp-httplib's API
  // takes ownership of a raw pointer here).
  m.http.new_task_queue = [] { return new httplib::ThreadPool(32); };
  for (const auto& [ext, type] : std::initializer_list<std::pair<const char*, const char*>>{
           {"html", "text/html; charset=utf-8"}, {"js", "text/javascript"}, {"mjs", "text/javascript"},
           {"css", "text/css"}, {"json", "application/json"}, {"wasm", "application/wasm"},
           {"png", "image/png"}, {"svg", "image/svg+xml"}, {"map", "application/json"}})
    m.http.set_file_extension_and_mimetype_mapping(ext, type);
  if (!o.viewer_dir.empty()) {
    if (!m.http.set_mount_point("/", o.viewer_dir.string(), {{"Cache-Control", "no-cache"}}))
      throw std::runtime_error("http: --viewer-dir " + o.viewer_dir.string() + " is not a folder");
  } else {
    m.http.Get("/", [](const httplib::Request&, httplib::Response& res) {
      res.set_content("<!doctype html><title>rrg</title><p>The viewer is not built: run <code>npm ci &amp;&amp; "
                      "npm run build</code> in web_viewer/ and pass <code>--viewer-dir web_viewer/dist</code>.",
                      "text/html; charset=utf-8");
    });
  }
  m.routes();
  port_ = o.port == 0 ? m.http.bind_to_any_port("0.0.0.0") : (m.http.bind_to_port("0.0.0.0", o.port) ? o.port : -1);
  if (port_ <= 0) throw std::runtime_error("http: cannot bind port " + std::to_string(o.port));
  m.thread = std::thread([&m] { m.http.listen_after_bind(); });
  if (!o.port_file.empty())
    io::write_atomically(o.port_file, [&](const std::filesystem::path& tmp) { std::ofstream(tmp) << port_ << "\n"; });
  spdlog::info("http: viewer and API on http://0.0.0.0:{}/ (viewer {})", port_,
               o.viewer_dir.empty() ? "not built" : o.viewer_dir.string());
}

HttpApiServer::~HttpApiServer() {
  impl_->stopping = true;  // event streams end within a second
  impl_->http.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

#else

struct HttpApiServer::Impl {};
HttpApiServer::HttpApiServer(const HttpApiOptions&, SessionManager&) {
  throw std::runtime_error("http: this build has no cpp-httplib (install libcpp-httplib-dev and rebuild)");
}
HttpApiServer::~HttpApiServer() = default;

#endif

}  // namespace rrg::server
