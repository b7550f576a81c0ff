#include "server/service.h"

#include "client/lib/proto_convert.h"
#include "core/gaussians/gaussian_ply.h"
#include "core/gaussians/spz.h"
#include "core/io/draco_mesh.h"
#include "core/io/frame_codec.h"
#include "server/auth.h"
#include "server/status_error.h"
#include "server/view_encode.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace rrg::server {

namespace {

constexpr size_t kDefaultChunk = 1 << 20;
constexpr size_t kMaxChunk = 4 << 20;
constexpr int64_t kMaxRenderPixels = int64_t(4096) * 4096;

template <class F>
grpc::ServerUnaryReactor* unary(grpc::CallbackServerContext* ctx, const SessionManager& manager, const char* name, F&& f) {
  tag_server(ctx, manager);
  grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
  grpc::Status status = grpc::Status::OK;
  try {
    f();
  } catch (...) {
    status = status_of(std::current_exception());
    spdlog::debug("{}: {} ({})", name, status.error_message(), int(status.error_code()));
  }
  reactor->Finish(status);
  return reactor;
}

size_t chunk_size(uint32_t asked) { return asked == 0 ? kDefaultChunk : std::clamp<size_t>(asked, 1024, kMaxChunk); }

std::string ply_bytes(const GaussianHost& g, bool with_plane_ids) {
  // The PLY writer writes files; a private temporary file is the simplest bridge.
  const auto tmp = std::filesystem::temp_directory_path() / ("rrg-gaussians-" + random_hex(8) + ".ply");
  struct Remove {
    std::filesystem::path p;
    ~Remove() { std::error_code ec; std::filesystem::remove(p, ec); }
  } remove{tmp};
  write_gaussian_ply(tmp, g, with_plane_ids);
  std::ifstream f(tmp, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

}  // namespace

void tag_server(grpc::CallbackServerContext* ctx, const SessionManager& manager) {
  ctx->AddInitialMetadata("x-rrg-server", manager.options().server_name);
}

grpc::ServerUnaryReactor* SessionServiceImpl::Create(grpc::CallbackServerContext* ctx, const v1::CreateSessionRequest* req,
                                                     v1::CreateSessionResponse* resp) {
  return unary(ctx, manager_, "Create", [&] { *resp = manager_.create(*ctx, *req); });
}

grpc::ServerUnaryReactor* SessionServiceImpl::Get(grpc::CallbackServerContext* ctx, const v1::GetSessionRequest* req,
                                                  v1::SessionInfo* resp) {
  return unary(ctx, manager_, "Get", [&] { *resp = manager_.authorize(*ctx, req->session_id())->info(); });
}

grpc::ServerUnaryReactor* SessionServiceImpl::List(grpc::CallbackServerContext* ctx, const v1::ListSessionsRequest*,
                                                   v1::ListSessionsResponse* resp) {
  return unary(ctx, manager_, "List", [&] {
    manager_.require_admin(*ctx);
    for (const auto& s : manager_.list()) *resp->add_sessions() = s->info();
  });
}

grpc::ServerUnaryReactor* SessionServiceImpl::Close(grpc::CallbackServerContext* ctx, const v1::CloseSessionRequest* req,
                                                    v1::CloseSessionResponse* resp) {
  return unary(ctx, manager_, "Close", [&] {
    const auto s = manager_.authorize(*ctx, req->session_id());
    *resp = manager_.close(s->meta().id, req->save());
  });
}

grpc::ServerUnaryReactor* SessionServiceImpl::Save(grpc::CallbackServerContext* ctx, const v1::SaveSessionRequest* req,
                                                   v1::SaveSessionResponse* resp) {
  return unary(ctx, manager_, "Save", [&] { *resp = manager_.save(*manager_.authorize(*ctx, req->session_id())); });
}

grpc::ServerUnaryReactor* SessionServiceImpl::Load(grpc::CallbackServerContext* ctx, const v1::LoadSessionRequest* req,
                                                   v1::CreateSessionResponse* resp) {
  return unary(ctx, manager_, "Load", [&] {
    const std::string id = req->session_id().empty() ? session_header(*ctx) : req->session_id();
    *resp = manager_.load(*ctx, id);
  });
}

grpc::ServerUnaryReactor* SessionServiceImpl::Drain(grpc::CallbackServerContext* ctx, const v1::DrainRequest*,
                                                    v1::DrainResponse* resp) {
  return unary(ctx, manager_, "Drain", [&] {
    manager_.require_admin(*ctx);
    *resp = manager_.drain();
  });
}

grpc::ServerBidiReactor<v1::Frame, v1::FrameResult>* SessionServiceImpl::StreamFrames(grpc::CallbackServerContext* ctx) {
  return make_frame_stream(ctx, manager_, metrics_);
}

grpc::ServerUnaryReactor* SessionServiceImpl::RenderView(grpc::CallbackServerContext* ctx, const v1::RenderViewRequest* req,
                                                         v1::RenderViewResponse* resp) {
  return unary(ctx, manager_, "RenderView", [&] {
    const auto s = manager_.authorize(*ctx, req->session_id());
    if (!req->has_pose()) throw std::invalid_argument("pose: missing");
    const Eigen::Isometry3f T = service::from_proto(req->pose(), "pose");
    Intrinsics K = s->session().config().K;
    if (req->has_intrinsics()) {
      K = service::from_proto(req->intrinsics());
      io::validate_intrinsics(K);
      if (int64_t(K.width) * K.height > kMaxRenderPixels)
        throw std::invalid_argument("intrinsics: " + std::to_string(K.width) + "x" + std::to_string(K.height) +
                                    " is above the render limit of 4096x4096 pixels");
    }
    std::vector<v1::RenderPass> passes;
    for (int i = 0; i < req->passes_size(); ++i) {
      const auto p = v1::RenderPass(req->passes(i));
      if (p < v1::PASS_FINAL || p > v1::PASS_DEPTH)
        throw std::invalid_argument("passes[" + std::to_string(i) + "]: unknown pass " + std::to_string(int(p)));
      passes.push_back(p);
    }
    const uint64_t version = s->session().status().map_version;
    *resp = encode_view(s->session().render(K, T), passes);
    resp->set_map_version(version);
  });
}

grpc::ServerWriteReactor<v1::DataChunk>* SessionServiceImpl::GetMesh(grpc::CallbackServerContext* ctx,
                                                                     const v1::GetMeshRequest* req) {
  tag_server(ctx, manager_);
  try {
    const auto s = manager_.authorize(*ctx, req->session_id());
    v1::DataChunk header;
    header.set_map_version(s->session().status().map_version);
    const TriangleMesh mesh = s->session().mesh(req->since_version());
    header.set_count(mesh.vertices.size());
    header.set_triangles(mesh.triangles.size());
    std::string data;
    if (!mesh.triangles.empty()) {
      const std::vector<uint8_t> drc = io::encode_draco(mesh);
      data.assign(drc.begin(), drc.end());
    }
    return make_chunk_writer(std::move(data), chunk_size(req->chunk_bytes()), header);
  } catch (...) {
    return new FailedWriter<v1::DataChunk>(status_of(std::current_exception()));
  }
}

grpc::ServerWriteReactor<v1::DataChunk>* SessionServiceImpl::GetGaussians(grpc::CallbackServerContext* ctx,
                                                                          const v1::GetGaussiansRequest* req) {
  tag_server(ctx, manager_);
  try {
    const auto s = manager_.authorize(*ctx, req->session_id());
    const bool reflection = req->set() == v1::GetGaussiansRequest::REFLECTION;
    if (req->set() != v1::GetGaussiansRequest::SET_UNSPECIFIED && req->set() != v1::GetGaussiansRequest::BASE &&
        !reflection)
      throw std::invalid_argument("set: unknown value " + std::to_string(int(req->set())));
    const auto format = req->format();
    if (format != v1::GetGaussiansRequest::FORMAT_UNSPECIFIED && format != v1::GetGaussiansRequest::SPZ &&
        format != v1::GetGaussiansRequest::PLY)
      throw std::invalid_argument("format: unknown value " + std::to_string(int(format)));
    v1::DataChunk header;
    header.set_map_version(s->session().status().map_version);
    const GaussianHost g = reflection ? s->session().reflection_gaussians() : s->session().base_gaussians();
    header.set_count(g.size());
    std::string data;
    if (format == v1::GetGaussiansRequest::PLY) {
      data = ply_bytes(g, reflection);
    } else {
      const std::vector<uint8_t> spz = encode_spz(g);
      data.assign(spz.begin(), spz.end());
    }
    return make_chunk_writer(std::move(data), chunk_size(req->chunk_bytes()), header);
  } catch (...) {
    return new FailedWriter<v1::DataChunk>(status_of(std::current_exception()));
  }
}

grpc::ServerWriteReactor<v1::SessionEvent>* SessionServiceImpl::WatchSession(grpc::CallbackServerContext* ctx,
                                                                             const v1::WatchSessionRequest* req) {
  tag_server(ctx, manager_);
  try {
    return make_event_writer(manager_.authorize(*ctx, req->session_id()));
  } catch (...) {
    return new FailedWriter<v1::SessionEvent>(status_of(std::current_exception()));
  }
}

}  // namespace rrg::server
