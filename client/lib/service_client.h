#pragma once
// The C++ client of rrg.v1.SessionService (proto/rrg/v1/service.proto): channels (insecure or
// TLS), one method per unary call, mesh / Gaussian downloads reassembled from their chunks, and a
// frame stream that keeps a window of frames in flight and measures each frame's round trip.
// Failed calls throw RpcError carrying the gRPC status code. Every call on a session carries its
// id in the `x-rrg-session` header (Create and Load too, when the id is known), which proxies hash
// on for session affinity; the answering server's `x-rrg-server` reply header goes to an optional
// observer (docs/deploy.md).
#include "rrg/v1/service.grpc.pb.h"

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace rrg::service {

class RpcError : public std::runtime_error {
 public:
  RpcError(const std::string& call, const grpc::Status& s);
  grpc::StatusCode code() const { return code_; }

 private:
  grpc::StatusCode code_;
};

struct ChannelOptions {
  std::string address = "localhost:50051";
  std::string tls_ca_file;     // PEM root certificate(s); empty = insecure channel
  int max_message_bytes = 64 << 20;
};
std::shared_ptr<grpc::Channel> make_channel(const ChannelOptions& options);

// A fresh client-side session id ("s" + 16 random hex digits), valid as CreateSessionRequest.session_id.
std::string new_session_id();

// A session as a client knows it: id and bearer token.
struct SessionHandle {
  std::string id, token;
};

// An encoded file fetched in chunks (Draco mesh, SPZ / PLY Gaussians).
struct Blob {
  std::string data;
  uint64_t map_version = 0, count = 0, triangles = 0;
  std::string server;  // x-rrg-server of the answer
};

struct StreamOptions {
  int window = 4;  // frames in flight (keep it below the session's queue capacity to never drop)
  // Called before each frame is sent (pacing at the dataset's rate); may sleep.
  std::function<void(uint64_t frame_id)> before_send;
};

struct StreamSummary {
  size_t sent = 0, results = 0, dropped = 0, rejected = 0;
  double wall_s = 0;
  std::vector<double> round_trip_ms;  // per processed frame: send -> result
  grpc::Status status;
  std::string server;  // x-rrg-server of the answer
};

// Told, after every call, which server answered it (x-rrg-server; "" when the reply had none).
using ServerObserver = std::function<void(const std::string& call, const std::string& session, const std::string& server)>;

class ServiceClient {
 public:
  explicit ServiceClient(const ChannelOptions& options);
  explicit ServiceClient(std::shared_ptr<grpc::Channel> channel);

  // With request.session_id set, the id also goes in the x-rrg-session header.
  v1::CreateSessionResponse create(const v1::CreateSessionRequest& request);
  v1::SessionInfo get(const SessionHandle& s);
  v1::ListSessionsResponse list(const std::string& admin_key = "");
  v1::CloseSessionResponse close(const SessionHandle& s, bool save = false);
  v1::SaveSessionResponse save(const SessionHandle& s);
  v1::CreateSessionResponse load(const std::string& id, const std::string& token);
  // Admin: drain the server this channel reaches (address it directly, not through a proxy).
  v1::DrainResponse drain(const std::string& admin_key = "");
  v1::RenderViewResponse render(const SessionHandle& s, v1::RenderViewRequest request);
  Blob mesh(const SessionHandle& s, uint64_t since_version = 0);
  Blob gaussians(const SessionHandle& s, v1::GetGaussiansRequest::Format format,
                 v1::GetGaussiansRequest::Set set = v1::GetGaussiansRequest::BASE);

  // Streams frames from `next` (nullopt = end) and hands every result to `on_result` (on a reader
  // thread) with its round trip in ms (0 for dropped / rejected frames). Returns when the server
  // has answered every frame and ended the call.
  StreamSummary stream(const SessionHandle& s, const std::function<std::optional<v1::Frame>()>& next,
                       const std::function<void(const v1::FrameResult&, double round_trip_ms)>& on_result,
                       const StreamOptions& options = {});
  // Forwards events until on_event returns false, the session closes, or the deadline passes.
  grpc::Status watch(const SessionHandle& s, const std::function<bool(const v1::SessionEvent&)>& on_event,
                     std::chrono::milliseconds timeout = std::chrono::hours(24));

  v1::SessionService::Stub& stub() { return *stub_; }
  // Calls the observer after every call of this client (from the calling thread). Set it before
  // sharing the client between threads.
  void set_server_observer(ServerObserver observer) { observer_ = std::move(observer); }
  // The x-rrg-server header of a finished call ("" when absent).
  static std::string server_of(const grpc::ClientContext& ctx);
  // A context carrying `authorization: Bearer <token>` and `x-rrg-session: <id>`.
  static std::unique_ptr<grpc::ClientContext> context(const SessionHandle& s);

 private:
  Blob fetch(const std::string& call, const std::string& session, grpc::ClientContext& ctx,
             std::unique_ptr<grpc::ClientReader<v1::DataChunk>> reader);
  // Tells the observer; returns the server's name.
  std::string observe(const std::string& call, const std::string& session, const grpc::ClientContext& ctx) const;
  // One unary call of the stub (Stub::*method): runs it, tells the observer, throws RpcError unless OK.
  template <class Request, class Response>
  Response unary(const char* call, const std::string& session, grpc::ClientContext& ctx,
                 grpc::Status (v1::SessionService::Stub::*method)(grpc::ClientContext*, const Request&, Response*),
                 const Request& request);
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::SessionService::Stub> stub_;
  ServerObserver observer_;
};

}  // namespace rrg::service
