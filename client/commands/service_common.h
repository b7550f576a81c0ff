#pragma once
// Flags shared by the commands that talk to the service (rrg stream, render, mesh, gaussians,
// sessions, save, load): where the server is and which session. Tokens come from --token or the
// RRG_TOKEN environment variable (so they need not appear in shell history).
#include "client/lib/service_client.h"

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace rrg::cli {

struct ServiceFlags {
  std::string server = "localhost:50051";
  std::string tls_ca;
  std::string session, token;

  void add(CLI::App& app, bool with_session) {
    app.add_option("--server", server, "service address HOST:PORT")->capture_default_str();
    app.add_option("--tls-ca", tls_ca, "PEM root certificate: connect with TLS");
    if (with_session) {
      app.add_option("--session", session, "session id")->required();
      app.add_option("--token", token, "the session's bearer token (default: $RRG_TOKEN)");
    }
  }
  service::ServiceClient client() const { return service::ServiceClient(service::ChannelOptions{server, tls_ca}); }
  service::SessionHandle handle() const {
    std::string t = token;
    if (t.empty())
      if (const char* env = std::getenv("RRG_TOKEN")) t = env;
    if (t.empty()) throw std::invalid_argument("--token (or RRG_TOKEN) is required");
    return {session, t};
  }
};

}  // namespace rrg::cli
