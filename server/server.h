#pragma once
// The whole server process behind `rrg serve`: gRPC (callback API) with the SessionService, the
// standard health service (overall status = serving; "rrg.v1.SessionService" = serving while a new
// session would be admitted), server reflection, TLS when a certificate and key are given, the
// maximum message size, the Prometheus endpoint, and graceful shutdown on SIGINT / SIGTERM that
// stops taking calls and snapshots every session.
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
  double shutdown_grace_s = 5.0;          // in-flight calls get this long before being cancelled
  ManagerOptions manager;
};

// Serves until SIGINT or SIGTERM, then shuts down gracefully. Returns the process exit code.
// Throws std::runtime_error for a port that cannot be bound or unreadable TLS files.
int run_server(const ServerOptions& options);

}  // namespace rrg::server
