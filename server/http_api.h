#pragma once
// The browser viewer's HTTP side (issue #10, docs/viewer.md), on its own port beside gRPC
// (cpp-httplib, its own threads): the built viewer as static files, and a small JSON / binary API
// over the same sessions and tokens as the gRPC service:
//   GET /api/sessions                           list (admin key when one is configured)
//   GET /api/sessions/{id}                      info, with axes and units
//   GET /api/sessions/{id}/mesh/chunks          mesh chunks {key, version, etag, bytes?}
//   GET /api/sessions/{id}/mesh/chunk/{key}.drc Draco of one chunk (ETag, If-None-Match -> 304)
//   GET /api/sessions/{id}/gaussians.spz        base Gaussians as SPZ (ETag, 304)
//   GET /api/sessions/{id}/events               server-sent events: hello, pose, map, closed
//   GET /api/sessions/{id}/render               PNG of one pass for a given camera
// Tokens: `Authorization: Bearer T` or `?token=T` (EventSource cannot set headers). Bad input is a
// 4xx with {"error": "<parameter>: ..."}.
#include "server/session_manager.h"

#include <filesystem>
#include <memory>

namespace rrg::server {

struct HttpApiOptions {
  int port = -1;                      // -1 = off, 0 = any free port
  std::filesystem::path port_file;    // written (atomically) with the bound port
  std::filesystem::path viewer_dir;   // the built viewer (web_viewer/dist); empty = API only
};

class HttpApiServer {
 public:
  // Binds 0.0.0.0:port and serves in its own threads. Throws std::runtime_error when the port
  // cannot be bound or the build has no cpp-httplib.
  HttpApiServer(const HttpApiOptions& options, SessionManager& manager);
  ~HttpApiServer();  // ends event streams, stops serving
  int port() const { return port_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
};

// The viewer folder `rrg serve` uses without --viewer-dir: web_viewer/dist of the source tree
// the binary was built from, when it exists; else empty.
std::filesystem::path default_viewer_dir();

}  // namespace rrg::server
