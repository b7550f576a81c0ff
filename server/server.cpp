#include "server/server.h"

#include "core/io/atomic_file.h"
#include "server/http_api.h"
#include "server/metrics.h"
#include "server/service.h"

#include <grpcpp/ext/health_check_service_server_builder_option.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server.h>
#include <grpcpp/server_builder.h>
#if RRG_WITH_REFLECTION
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#endif
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <fstream>
#include <iterator>
#include <pthread.h>
#include <thread>

namespace rrg::server {

namespace {

std::string read_file(const std::filesystem::path& p, const char* what) {
  std::ifstream f(p, std::ios::binary);
  if (!f) throw std::runtime_error(std::string("serve: cannot read the TLS ") + what + " " + p.string());
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::shared_ptr<grpc::ServerCredentials> credentials(const ServerOptions& o) {
  if (o.tls_cert.empty() != o.tls_key.empty())
    throw std::invalid_argument("serve: --tls-cert and --tls-key go together");
  if (o.tls_cert.empty()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({read_file(o.tls_key, "key"), read_file(o.tls_cert, "certificate")});
  return grpc::SslServerCredentials(ssl);
}

}  // namespace

int run_server(const ServerOptions& o) {
  // SIGINT / SIGTERM are taken by sigwait below; block them before any thread starts.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  Metrics metrics;
  SessionManager manager(o.manager, metrics);
  SessionServiceImpl service(manager, metrics);

  grpc::EnableDefaultHealthCheckService(true);
#if RRG_WITH_REFLECTION
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
#endif
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(o.address, credentials(o), &port);
  builder.RegisterService(&service);
  builder.SetMaxReceiveMessageSize(o.max_message_bytes);
  builder.SetMaxSendMessageSize(o.max_message_bytes);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) throw std::runtime_error("serve: cannot listen on " + o.address);

  std::unique_ptr<MetricsHttpServer> http;
  if (o.metrics_port >= 0)
    http = std::make_unique<MetricsHttpServer>(o.metrics_port, [&] { return metrics.prometheus_text(manager.gauges()); });
  if (http && !o.metrics_port_file.empty())
    io::write_atomically(o.metrics_port_file, [&](const std::filesystem::path& tmp) {
      std::ofstream(tmp) << http->port() << "\n";
    });
  std::unique_ptr<HttpApiServer> http_api;
  if (o.http_port >= 0) http_api = std::make_unique<HttpApiServer>(HttpApiOptions{o.http_port, o.http_port_file, o.viewer_dir}, manager);

  grpc::HealthCheckServiceInterface* health = server->GetHealthCheckService();
  const std::string service_name = v1::SessionService::service_full_name();
  health->SetServingStatus(true);
  health->SetServingStatus(service_name, manager.has_capacity());
  health->SetServingStatus("liveness", true);
  std::atomic<bool> stopping{false};
  std::thread health_updater([&] {  // capacity changes as sessions come and go; draining is final
    while (!stopping) {
      health->SetServingStatus(service_name, manager.has_capacity());
      if (manager.draining()) health->SetServingStatus("", false);
      for (int i = 0; i < 10 && !stopping; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });

  if (!o.port_file.empty())
    io::write_atomically(o.port_file, [&](const std::filesystem::path& tmp) {
      std::ofstream(tmp) << port << "\n";
    });
  spdlog::info("serve: server {} listening on port {} ({}; max message {} bytes; {} sessions max; snapshots {}{}{})", o.manager.server_name, port,
               o.tls_cert.empty() ? "insecure" : "TLS", o.max_message_bytes, o.manager.max_sessions,
               o.manager.snapshot_dir.empty() ? "off" : o.manager.snapshot_dir.string(),
               o.manager.admin_key.empty() ? "" : "; admin key set",
#if RRG_WITH_REFLECTION
               "; reflection on"
#else
               "; reflection unavailable"
#endif
  );

  int sig = 0;
  std::thread drainer;
  while (true) {
    sigwait(&signals, &sig);
    if (sig != SIGUSR1) break;
    spdlog::info("serve: SIGUSR1 received, draining");
    health->SetServingStatus("", false);
    health->SetServingStatus(service_name, false);
    if (!drainer.joinable()) drainer = std::thread([&manager] { manager.drain(); });  // sigwait stays responsive
  }
  spdlog::info("serve: {} received, shutting down", sig == SIGINT ? "SIGINT" : "SIGTERM");
  health->SetServingStatus("", false);
  health->SetServingStatus(service_name, false);
  manager.drain();  // new calls on the sessions now say they were drained, not "not found"
  if (drainer.joinable()) drainer.join();
  stopping = true;
  health_updater.join();
  health->Shutdown();  // health checks now answer NOT_SERVING
  const auto deadline = std::chrono::system_clock::now() +
                        std::chrono::milliseconds(int64_t(o.shutdown_grace_s * 1000.0));
  // New calls are refused from here; sessions are drained and snapshotted while the calls in
  // flight finish (closing a session also ends its watchers), then a second pass catches a
  // session created by a call that was already running.
  http_api.reset();  // ends the viewer's event streams
  std::thread stopper([&] { server->Shutdown(deadline); });
  manager.shutdown();
  stopper.join();
  manager.shutdown();
  http.reset();
  server->Wait();
  spdlog::info("serve: stopped");
  return 0;
}

}  // namespace rrg::server
