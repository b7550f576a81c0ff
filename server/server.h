#pragma once
// The whole server process behind `rrg serve`: gRPC (callback API) with the SessionService, the
// standard health service (overall status = serving; "rrg.v1.SessionService" = serving while a new
// session would be admitted), server reflection, TLS when a certificate and key are given, the
// maximum message size, the Prometheus endpoint, draining on SIGUSR1 (and the Drain RPC): health
// NOT_SERVING, sessions snapshotted and freed, the process stays up; and graceful shutdown on
// SIGINT / SIGTERM that drains, stops taking calls and exits. The health name "liveness" stays
// SERVING until exit (Kubernetes liveness probes; "" turns NOT_SERVING when draining).
#include "server/session_manager.h"

#include <filesystem>
#include <string>

namespace rrg::server {

struct ServerOptions {
  std::string address = "0.0.0.0:50051";  // host:port; port 0 = any free port
  std::filesystem::path port_file;        // written (atomically) with the bound port once serving
  std::filesystem::path tls_cert, tls_key;
  int max_message_bytes = 64 << 20;
  int metrics_port = -1;                  // -1 = no metrics endpoint, 0 = any free port
  std::filesystem::path metrics_port_file;  // written (atomically) with the bound metrics port
  double shutdown_grace_s = 5.0;          // in-flight calls get this long before being cancelled
  int http_port = -1;                     // browser viewer + HTTP API (http_api.h): -1 = off, 0 = any
  std::filesystem::path http_port_file;   // written (atomically) with the bound HTTP port
  std::filesystem::path viewer_dir;       // the built viewer (web_viewer/dist); empty = API only
  ManagerOptions manager;
};

// Serves until SIGINT or SIGTERM (SIGUSR1 drains and goes on), then shuts down gracefully.
// Returns the process exit code.
// Throws std::runtime_error for a port that cannot be bound or unreadable TLS files.
int run_server(const ServerOptions& options);

}  // namespace rrg::server
