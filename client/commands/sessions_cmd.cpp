// rrg sessions | save | load | drain | health: list a server's sessions, snapshot one, restore one,
// drain a server (docs/deploy.md), ask its health service (the container HEALTHCHECK).
#include "client/commands/command.h"

#if RRG_WITH_GRPC
#include "client/commands/service_common.h"
#include "client/lib/health_check.h"
#include "client/lib/proto_convert.h"

#include <cstdio>
#include <cstdlib>
#include <memory>

namespace rrg::cli {

namespace {
std::string admin_key_or_env(const std::string& flag) {
  if (!flag.empty()) return flag;
  const char* env = std::getenv("RRG_ADMIN_KEY");
  return env ? env : "";
}
}  // namespace

void register_session_commands(CLI::App& app) {
  {
    auto* cmd = app.add_subcommand("sessions", "list the sessions of a server");
    auto f = std::make_shared<ServiceFlags>();
    auto admin = std::make_shared<std::string>();
    f->add(*cmd, false);
    cmd->add_option("--admin-key", *admin, "the server's admin key (default: $RRG_ADMIN_KEY)");
    cmd->callback([=] {
      const auto list = f->client().list(admin_key_or_env(*admin));
      std::printf("%-18s %-20s %8s %8s %8s %-10s %10s %10s %12s %8s\n", "session", "name", "frames", "dropped", "state",
                  "schedule", "map", "gaussians", "memory MiB", "idle s");
      for (const auto& s : list.sessions())
        std::printf("%-18s %-20s %8llu %8llu %8s %-10s %10llu %10llu %12.1f %8.1f\n", s.session_id().c_str(),
                    s.name().substr(0, 20).c_str(), (unsigned long long)s.frames(),
                    (unsigned long long)s.frames_dropped(), service::to_string(s.state()).c_str(), s.schedule().c_str(),
                    (unsigned long long)s.map_version(),
                    (unsigned long long)(s.base_gaussians() + s.reflection_gaussians()),
                    double(s.device_bytes() + s.host_bytes()) / (1024.0 * 1024.0), s.idle_seconds());
    });
  }
  {
    auto* cmd = app.add_subcommand("drain", "drain a server: refuse new sessions, snapshot and free every session");
    auto f = std::make_shared<ServiceFlags>();
    auto admin = std::make_shared<std::string>();
    f->add(*cmd, false);
    cmd->add_option("--admin-key", *admin, "the server's admin key (default: $RRG_ADMIN_KEY)");
    cmd->callback([=] {
      // Address the server itself (not a proxy): Drain acts on whichever server answers.
      const auto r = f->client().drain(admin_key_or_env(*admin));
      std::printf("server %s drained: %d sessions saved, %d failed\n", r.server().c_str(), r.saved_size(), r.failed_size());
      for (const auto& id : r.saved()) std::printf("saved %s\n", id.c_str());
      for (const auto& e : r.failed()) std::printf("FAILED %s\n", e.c_str());
      if (r.failed_size() > 0) throw std::runtime_error("drain: " + std::to_string(r.failed_size()) + " sessions not saved");
    });
  }
  {
    auto* cmd = app.add_subcommand("health", "grpc.health.v1 check of a server; exit code 1 unless SERVING");
    auto f = std::make_shared<ServiceFlags>();
    auto name = std::make_shared<std::string>();
    auto timeout = std::make_shared<double>(5);
    f->add(*cmd, false);
    cmd->add_option("--service", *name, "service name: \"\" (the server), rrg.v1.SessionService (admission), liveness");
    cmd->add_option("--timeout", *timeout, "seconds")->capture_default_str();
    cmd->callback([=] {
      const auto st = service::check_health(service::make_channel({f->server, f->tls_ca}), *name,
                                            std::chrono::milliseconds(int64_t(*timeout * 1000.0)));
      std::printf("%s\n", service::to_string(st));
      if (st != service::HealthStatus::serving) throw std::runtime_error("health: " + std::string(service::to_string(st)));
    });
  }
  {
    auto* cmd = app.add_subcommand("save", "snapshot a live session into the server's snapshot folder");
    auto f = std::make_shared<ServiceFlags>();
    f->add(*cmd, true);
    cmd->callback([=] {
      const auto r = f->client().save(f->handle());
      std::printf("saved %s: %llu frames, map version %llu, %llu bytes\n", r.snapshot().c_str(),
                  (unsigned long long)r.frames(), (unsigned long long)r.map_version(), (unsigned long long)r.bytes());
    });
  }
  {
    auto* cmd = app.add_subcommand("load", "restore a saved session (its token, or the admin key as --token)");
    auto f = std::make_shared<ServiceFlags>();
    f->add(*cmd, true);
    cmd->callback([=] {
      const auto h = f->handle();
      const auto r = f->client().load(h.id, h.token);
      std::printf("loaded %s: %llu frames, map version %llu; token %s\n", r.session_id().c_str(),
                  (unsigned long long)r.info().frames(), (unsigned long long)r.info().map_version(), r.token().c_str());
    });
  }
}

}  // namespace rrg::cli
#else
namespace rrg::cli {
void register_session_commands(CLI::App& app) {
  for (const char* name : {"sessions", "save", "load", "drain", "health"})
    app.add_subcommand(name, "service client (not in this build)")->callback([] {
      throw std::runtime_error("this build has no gRPC (install libgrpc++-dev protobuf-compiler-grpc, rebuild)");
    });
}
}  // namespace rrg::cli
#endif
