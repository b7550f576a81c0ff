// rrg serve: the gRPC reconstruction service (server/, docs/service.md).
#include "client/commands/command.h"

#if RRG_WITH_GRPC
#include "core/common/device.h"
#include "server/http_api.h"
#include "server/server.h"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <cstdlib>
#include <memory>

namespace rrg::cli {

void register_serve_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("serve", "run the gRPC reconstruction service (docs/service.md)");
  auto o = std::make_shared<server::ServerOptions>();
  auto device = std::make_shared<std::string>("auto");
  auto max_message_mb = std::make_shared<double>(64);
  auto session_mb = std::make_shared<double>(0), total_mb = std::make_shared<double>(0);
  auto session_device_mb = std::make_shared<double>(0), total_device_mb = std::make_shared<double>(0);
  auto log_json = std::make_shared<bool>(false);
  auto max_sessions = std::make_shared<size_t>(16), queue = std::make_shared<size_t>(8);
  cmd->add_option("--address", o->address, "listen address HOST:PORT (port 0: any free port)")->capture_default_str();
  auto name = std::make_shared<std::string>();
  cmd->add_option("--name", *name, "server name sent as x-rrg-server and used in errors (default: host name)");
  cmd->add_option("--port-file", o->port_file, "write the bound port to this file once serving");
  cmd->add_option("--device", *device, "cpu | cuda | cuda:N | auto: where sessions run")->capture_default_str();
  cmd->add_option("--max-sessions", *max_sessions, "admission: live sessions at most")->capture_default_str();
  cmd->add_option("--session-memory-mb", *session_mb, "admission: memory budget per session, MiB (0 = none)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--total-memory-mb", *total_mb, "admission: memory budget of all sessions, MiB (0 = none)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--session-device-mb", *session_device_mb,
                  "admission: device memory budget per session, MiB (0 = none); host memory a session's "
                  "TSDF streams to (tsdf.stream_radius) does not count")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--total-device-mb", *total_device_mb, "admission: device memory budget of all sessions, MiB (0 = none)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--queue", *queue, "default frame queue capacity per session")->capture_default_str();
  cmd->add_option("--snapshot-dir", o->manager.snapshot_dir, "folder for Save / Load / idle and shutdown snapshots");
  cmd->add_option("--idle-timeout", o->manager.idle_timeout_s, "seconds without calls before a session is snapshotted and freed (0 = never)");
  cmd->add_option("--admin-key", o->manager.admin_key, "admin bearer key for List / Load (default: $RRG_ADMIN_KEY)");
  cmd->add_option("--segmenter", o->manager.segmenter_address, "rrg.v1.Segmenter address for semantics = remote");
  cmd->add_option("--tls-cert", o->tls_cert, "PEM certificate chain: serve TLS");
  cmd->add_option("--tls-key", o->tls_key, "PEM private key for --tls-cert");
  cmd->add_option("--max-message-mb", *max_message_mb, "largest message accepted or sent, MiB")->capture_default_str();
  cmd->add_option("--metrics-port", o->metrics_port, "Prometheus text endpoint port (-1 = off, 0 = any)")->capture_default_str();
  cmd->add_option("--metrics-port-file", o->metrics_port_file, "write the bound metrics port to this file once serving");
  cmd->add_option("--shutdown-grace", o->shutdown_grace_s, "seconds in-flight calls get at shutdown")->capture_default_str();
  cmd->add_option("--http-port", o->http_port, "browser viewer + HTTP API port (-1 = off, 0 = any; docs/viewer.md)")->capture_default_str();
  cmd->add_option("--http-port-file", o->http_port_file, "write the bound HTTP port to this file once serving");
  cmd->add_option("--viewer-dir", o->viewer_dir, "the built viewer (default: web_viewer/dist of the source tree, if built)");
  cmd->add_flag("--log-json", *log_json, "one JSON object per log line (time, level, message)");
  auto config = std::make_shared<std::string>();
  auto sets = std::make_shared<std::vector<std::string>>();
  cmd->add_option("--config", *config, "YAML file of session defaults (as rrg run --config); Create overrides apply on top")
      ->check(CLI::ExistingFile);
  cmd->add_option("--set", *sets, "session default key=value (repeatable), e.g. live=true on a CPU server; "
                                  "a Create naming sync or live chooses the schedule itself");
  cmd->callback([=] {
    if (*log_json) spdlog::set_pattern(R"({"time":"%Y-%m-%dT%H:%M:%S.%f%z","level":"%l","thread":%t,"msg":"%v"})");
    server::ServerOptions opts = *o;
    opts.manager.server_name = *name;
    if (opts.manager.server_name.empty()) {
      char host[256] = {};
      opts.manager.server_name = ::gethostname(host, sizeof(host) - 1) == 0 && host[0] != '\0' ? host : "rrg";
    }
    opts.manager.device = parse_device(*device);
    opts.manager.defaults = server::make_server_defaults(*config, *sets);  // refused before anything binds
    opts.manager.max_sessions = *max_sessions;
    opts.manager.default_queue = *queue;
    const auto bytes = [](double mib) { return size_t(mib * 1024.0 * 1024.0); };
    opts.manager.session_budget = {.memory = bytes(*session_mb), .device = bytes(*session_device_mb)};
    opts.manager.total_budget = {.memory = bytes(*total_mb), .device = bytes(*total_device_mb)};
    opts.max_message_bytes = int(*max_message_mb * 1024.0 * 1024.0);
    if (opts.viewer_dir.empty()) opts.viewer_dir = server::default_viewer_dir();
    if (opts.manager.admin_key.empty())
      if (const char* env = std::getenv("RRG_ADMIN_KEY")) opts.manager.admin_key = env;
    server::run_server(opts);
  });
}

}  // namespace rrg::cli
#else
namespace rrg::cli {
void register_serve_command(CLI::App& app) {
  app.add_subcommand("serve", "run the gRPC reconstruction service (not in this build)")->callback([] {
    throw std::runtime_error("serve: this build has no gRPC (install libgrpc++-dev protobuf-compiler-grpc, rebuild)");
  });
}
}  // namespace rrg::cli
#endif
