#pragma once
// Debian's nginx as a test process: run as the current user with its own prefix, config, pid,
// logs and temp folders in a scratch directory, from the template deploy/nginx/rrg-local.conf.in
// (a gRPC proxy hashing on x-rrg-session over a list of upstream servers).
#include "tests/support/test_support.h"  // run_shell

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace rrg::test {

// The nginx binary ($RRG_NGINX, else nginx on the PATH, /usr/sbin/nginx); "" when there is none.
std::string find_nginx();
// deploy/nginx/rrg-local.conf.in with its placeholders filled.
std::string render_nginx_conf(const std::filesystem::path& prefix, const std::string& listen,
                              const std::vector<std::string>& servers);
// A free loopback TCP port (bound and released; nginx cannot write a port file).
int free_port();

class NginxProcess {
 public:
  // Writes the config for `servers` (host:port), checks it with `nginx -t`, starts nginx
  // (daemon off) and waits until its port accepts connections. Throws with nginx's output.
  NginxProcess(const std::filesystem::path& prefix, const std::vector<std::string>& servers);
  ~NginxProcess();  // SIGQUIT (graceful), then SIGKILL after 5 s
  NginxProcess(const NginxProcess&) = delete;
  NginxProcess& operator=(const NginxProcess&) = delete;

  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  // Rewrites the config with `servers` and runs `nginx -s reload`; throws when it fails.
  void reload(const std::vector<std::string>& servers);
  std::string access_log() const;
  std::string error_log() const;

 private:
  void write_conf(const std::vector<std::string>& servers);
  std::string nginx_, conf_;
  std::filesystem::path prefix_;
  pid_t pid_ = -1;
  int port_ = 0;
};

}  // namespace rrg::test
