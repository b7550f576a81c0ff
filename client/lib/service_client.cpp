#include "client/lib/service_client.h"

#include <condition_variable>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <random>
#include <thread>

namespace rrg::service {

namespace {
using Clock = std::chrono::steady_clock;

std::string code_name(grpc::StatusCode c) {
  switch (c) {
    case grpc::StatusCode::OK: return "OK";
    case grpc::StatusCode::CANCELLED: return "CANCELLED";
    case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS: return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED: return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION: return "FAILED_PRECONDITION";
    case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
    case grpc::StatusCode::UNAUTHENTICATED: return "UNAUTHENTICATED";
    case grpc::StatusCode::INTERNAL: return "INTERNAL";
    case grpc::StatusCode::DATA_LOSS: return "DATA_LOSS";
    default: return "code " + std::to_string(int(c));
  }
}

void check(const std::string& call, const grpc::Status& s) {
  if (!s.ok()) throw RpcError(call, s);
}

std::unique_ptr<grpc::ClientContext> bearer_context(const std::string& token) {
  auto ctx = std::make_unique<grpc::ClientContext>();
  if (!token.empty()) ctx->AddMetadata("authorization", "Bearer " + token);
  return ctx;
}
}  // namespace

std::string new_session_id() {
  std::random_device rd;
  std::uniform_int_distribution<int> digit(0, 15);
  std::string id = "s";
  for (int i = 0; i < 16; ++i) id += "0123456789abcdef"[digit(rd)];
  return id;
}

RpcError::RpcError(const std::string& call, const grpc::Status& s)
    : std::runtime_error(call + ": " + code_name(s.error_code()) + ": " + s.error_message()), code_(s.error_code()) {}

std::shared_ptr<grpc::Channel> make_channel(const ChannelOptions& o) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(o.max_message_bytes);
  args.SetMaxSendMessageSize(o.max_message_bytes);
  std::shared_ptr<grpc::ChannelCredentials> creds;
  if (o.tls_ca_file.empty()) {
    creds = grpc::InsecureChannelCredentials();
  } else {
    std::ifstream f(o.tls_ca_file, std::ios::binary);
    if (!f) throw std::runtime_error("client: cannot read the TLS root certificate " + o.tls_ca_file);
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs.assign(std::istreambuf_iterator<char>(f), {});
    creds = grpc::SslCredentials(ssl);
  }
  return grpc::CreateCustomChannel(o.address, creds, args);
}

ServiceClient::ServiceClient(const ChannelOptions& o) : ServiceClient(make_channel(o)) {}
ServiceClient::ServiceClient(std::shared_ptr<grpc::Channel> channel)
    : channel_(std::move(channel)), stub_(v1::SessionService::NewStub(channel_)) {}

std::unique_ptr<grpc::ClientContext> ServiceClient::context(const SessionHandle& s) {
  auto ctx = bearer_context(s.token);
  if (!s.id.empty()) ctx->AddMetadata("x-rrg-session", s.id);
  return ctx;
}

std::string ServiceClient::server_of(const grpc::ClientContext& ctx) {
  for (const auto* md : {&ctx.GetServerInitialMetadata(), &ctx.GetServerTrailingMetadata()}) {
    const auto it = md->find("x-rrg-server");
    if (it != md->end()) return std::string(it->second.data(), it->second.size());
  }
  return {};
}

std::string ServiceClient::observe(const std::string& call, const std::string& session,
                                   const grpc::ClientContext& ctx) const {
  std::string server = server_of(ctx);
  if (observer_) observer_(call, session, server);
  return server;
}

template <class Request, class Response>
Response ServiceClient::unary(const char* call, const std::string& session, grpc::ClientContext& ctx,
                              grpc::Status (v1::SessionService::Stub::*method)(grpc::ClientContext*, const Request&,
                                                                               Response*),
                              const Request& request) {
  Response out;
  const grpc::Status st = ((*stub_).*method)(&ctx, request, &out);
  observe(call, session, ctx);
  check(call, st);
  return out;
}

v1::CreateSessionResponse ServiceClient::create(const v1::CreateSessionRequest& request) {
  grpc::ClientContext ctx;
  if (!request.session_id().empty()) ctx.AddMetadata("x-rrg-session", request.session_id());
  v1::CreateSessionResponse out;
  const grpc::Status st = stub_->Create(&ctx, request, &out);
  observe("Create", st.ok() ? out.session_id() : request.session_id(), ctx);
  check("Create", st);
  return out;
}

v1::SessionInfo ServiceClient::get(const SessionHandle& s) {
  auto ctx = context(s);
  v1::GetSessionRequest r;
  r.set_session_id(s.id);
  return unary("Get", s.id, *ctx, &v1::SessionService::Stub::Get, r);
}

v1::ListSessionsResponse ServiceClient::list(const std::string& admin_key) {
  auto ctx = bearer_context(admin_key);
  return unary("List", "", *ctx, &v1::SessionService::Stub::List, v1::ListSessionsRequest{});
}

v1::DrainResponse ServiceClient::drain(const std::string& admin_key) {
  auto ctx = bearer_context(admin_key);
  return unary("Drain", "", *ctx, &v1::SessionService::Stub::Drain, v1::DrainRequest{});
}

v1::CloseSessionResponse ServiceClient::close(const SessionHandle& s, bool save) {
  auto ctx = context(s);
  v1::CloseSessionRequest r;
  r.set_session_id(s.id);
  r.set_save(save);
  return unary("Close", s.id, *ctx, &v1::SessionService::Stub::Close, r);
}

v1::SaveSessionResponse ServiceClient::save(const SessionHandle& s) {
  auto ctx = context(s);
  v1::SaveSessionRequest r;
  r.set_session_id(s.id);
  return unary("Save", s.id, *ctx, &v1::SessionService::Stub::Save, r);
}

v1::CreateSessionResponse ServiceClient::load(const std::string& id, const std::string& token) {
  auto ctx = bearer_context(token);
  ctx->AddMetadata("x-rrg-session", id);
  v1::LoadSessionRequest r;
  r.set_session_id(id);
  return unary("Load", id, *ctx, &v1::SessionService::Stub::Load, r);
}

v1::RenderViewResponse ServiceClient::render(const SessionHandle& s, v1::RenderViewRequest request) {
  auto ctx = context(s);
  if (request.session_id().empty()) request.set_session_id(s.id);
  return unary("RenderView", s.id, *ctx, &v1::SessionService::Stub::RenderView, request);
}

Blob ServiceClient::fetch(const std::string& call, const std::string& session, grpc::ClientContext& ctx,
                          std::unique_ptr<grpc::ClientReader<v1::DataChunk>> reader) {
  Blob b;
  v1::DataChunk c;
  while (reader->Read(&c)) {
    if (c.offset() != b.data.size())
      throw std::runtime_error(call + ": chunk at offset " + std::to_string(c.offset()) + ", expected " +
                               std::to_string(b.data.size()));
    b.data += c.data();
    b.map_version = c.map_version();
    b.count = c.count();
    b.triangles = c.triangles();
  }
  const grpc::Status st = reader->Finish();
  b.server = observe(call, session, ctx);
  check(call, st);
  return b;
}

Blob ServiceClient::mesh(const SessionHandle& s, uint64_t since_version) {
  auto ctx = context(s);
  v1::GetMeshRequest r;
  r.set_session_id(s.id);
  r.set_since_version(since_version);
  return fetch("GetMesh", s.id, *ctx, stub_->GetMesh(ctx.get(), r));
}

Blob ServiceClient::gaussians(const SessionHandle& s, v1::GetGaussiansRequest::Format format,
                              v1::GetGaussiansRequest::Set set) {
  auto ctx = context(s);
  v1::GetGaussiansRequest r;
  r.set_session_id(s.id);
  r.set_format(format);
  r.set_set(set);
  return fetch("GetGaussians", s.id, *ctx, stub_->GetGaussians(ctx.get(), r));
}

StreamSummary ServiceClient::stream(const SessionHandle& s, const std::function<std::optional<v1::Frame>()>& next,
                                    const std::function<void(const v1::FrameResult&, double)>& on_result,
                                    const StreamOptions& options) {
  auto ctx = context(s);
  auto rw = stub_->StreamFrames(ctx.get());
  StreamSummary sum;
  std::mutex m;
  std::condition_variable cv;
  std::map<uint64_t, Clock::time_point> sent_at;
  int in_flight = 0;
  bool reader_done = false;
  const int window = std::max(1, options.window);

  const auto t0 = Clock::now();
  std::thread reader([&] {
    v1::FrameResult r;
    while (rw->Read(&r)) {
      double rtt = 0;
      {
        std::lock_guard lock(m);
        const auto it = sent_at.find(r.id());
        if (it != sent_at.end()) {
          rtt = std::chrono::duration<double, std::milli>(Clock::now() - it->second).count();
          sent_at.erase(it);
        }
        ++sum.results;
        if (r.dropped()) ++sum.dropped;
        else if (r.has_error()) ++sum.rejected;
        else sum.round_trip_ms.push_back(rtt);
        --in_flight;
      }
      cv.notify_all();
      on_result(r, r.dropped() || r.has_error() ? 0.0 : rtt);
    }
    std::lock_guard lock(m);
    reader_done = true;
    cv.notify_all();
  });

  while (true) {
    std::optional<v1::Frame> f = next();
    if (!f) break;
    {
      std::unique_lock lock(m);
      cv.wait(lock, [&] { return in_flight < window || reader_done; });
      if (reader_done) break;
    }
    if (options.before_send) options.before_send(f->id());
    {
      std::lock_guard lock(m);
      sent_at[f->id()] = Clock::now();
      ++in_flight;
    }
    if (!rw->Write(*f)) break;  // the call ended; Finish() says why
    ++sum.sent;
  }
  rw->WritesDone();
  reader.join();
  sum.status = rw->Finish();
  sum.server = observe("StreamFrames", s.id, *ctx);
  sum.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return sum;
}

grpc::Status ServiceClient::watch(const SessionHandle& s, const std::function<bool(const v1::SessionEvent&)>& on_event,
                                  std::chrono::milliseconds timeout) {
  auto ctx = context(s);
  ctx->set_deadline(std::chrono::system_clock::now() + timeout);
  v1::WatchSessionRequest r;
  r.set_session_id(s.id);
  auto reader = stub_->WatchSession(ctx.get(), r);
  v1::SessionEvent e;
  while (reader->Read(&e)) {
    if (!on_event(e)) {
      ctx->TryCancel();
      break;
    }
  }
  const grpc::Status st = reader->Finish();
  observe("WatchSession", s.id, *ctx);
  return st;
}

}  // namespace rrg::service
