#pragma once
// rrg.v1.SessionService on gRPC's callback API. Unary calls run on gRPC's callback threads and
// call into the SessionManager; StreamFrames feeds each session's worker queue and writes the
// results back in order; GetMesh / GetGaussians stream one encoded file in chunks; WatchSession
// forwards a session's events. Every handler maps exceptions to statuses (status_error.h) and
// names the answering server in the initial metadata `x-rrg-server` (what proxy tests check).
#include "rrg/v1/service.grpc.pb.h"
#include "server/metrics.h"
#include "server/session_manager.h"

namespace rrg::server {

class SessionServiceImpl final : public v1::SessionService::CallbackService {
 public:
  SessionServiceImpl(SessionManager& manager, Metrics& metrics) : manager_(manager), metrics_(metrics) {}

  grpc::ServerUnaryReactor* Create(grpc::CallbackServerContext* ctx, const v1::CreateSessionRequest* req,
                                   v1::CreateSessionResponse* resp) override;
  grpc::ServerUnaryReactor* Get(grpc::CallbackServerContext* ctx, const v1::GetSessionRequest* req,
                                v1::SessionInfo* resp) override;
  grpc::ServerUnaryReactor* List(grpc::CallbackServerContext* ctx, const v1::ListSessionsRequest* req,
                                 v1::ListSessionsResponse* resp) override;
  grpc::ServerUnaryReactor* Close(grpc::CallbackServerContext* ctx, const v1::CloseSessionRequest* req,
                                  v1::CloseSessionResponse* resp) override;
  grpc::ServerUnaryReactor* Save(grpc::CallbackServerContext* ctx, const v1::SaveSessionRequest* req,
                                 v1::SaveSessionResponse* resp) override;
  grpc::ServerUnaryReactor* Load(grpc::CallbackServerContext* ctx, const v1::LoadSessionRequest* req,
                                 v1::CreateSessionResponse* resp) override;
  grpc::ServerUnaryReactor* Drain(grpc::CallbackServerContext* ctx, const v1::DrainRequest* req,
                                  v1::DrainResponse* resp) override;
  grpc::ServerBidiReactor<v1::Frame, v1::FrameResult>* StreamFrames(grpc::CallbackServerContext* ctx) override;
  grpc::ServerUnaryReactor* RenderView(grpc::CallbackServerContext* ctx, const v1::RenderViewRequest* req,
                                       v1::RenderViewResponse* resp) override;
  grpc::ServerWriteReactor<v1::DataChunk>* GetMesh(grpc::CallbackServerContext* ctx,
                                                   const v1::GetMeshRequest* req) override;
  grpc::ServerWriteReactor<v1::DataChunk>* GetGaussians(grpc::CallbackServerContext* ctx,
                                                        const v1::GetGaussiansRequest* req) override;
  grpc::ServerWriteReactor<v1::SessionEvent>* WatchSession(grpc::CallbackServerContext* ctx,
                                                           const v1::WatchSessionRequest* req) override;

 private:
  SessionManager& manager_;
  Metrics& metrics_;
};

// Adds `x-rrg-server: <server name>` to the call's initial metadata (before anything is sent).
void tag_server(grpc::CallbackServerContext* ctx, const SessionManager& manager);

// The reactor of one StreamFrames call (server/frame_stream.cpp).
grpc::ServerBidiReactor<v1::Frame, v1::FrameResult>* make_frame_stream(grpc::CallbackServerContext* ctx,
                                                                       SessionManager& manager, Metrics& metrics);
// Reactors of the server-streaming calls (server/stream_writers.cpp).
grpc::ServerWriteReactor<v1::DataChunk>* make_chunk_writer(std::string data, size_t chunk_bytes, const v1::DataChunk& header);
grpc::ServerWriteReactor<v1::SessionEvent>* make_event_writer(std::shared_ptr<ManagedSession> session);

// A server-streaming call that fails before writing anything.
template <class T>
class FailedWriter final : public grpc::ServerWriteReactor<T> {
 public:
  explicit FailedWriter(const grpc::Status& status) { this->Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace rrg::server
