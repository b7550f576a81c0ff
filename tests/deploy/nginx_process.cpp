#include "tests/deploy/nginx_process.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <grp.h>
#include <netinet/in.h>
#include <pwd.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace rrg::test {

namespace fs = std::filesystem;

namespace {
std::string read_text(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void replace_all(std::string& s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
}

bool port_open(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(uint16_t(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0;
  ::close(fd);
  return ok;
}
}  // namespace

std::string find_nginx() {
  if (const char* env = std::getenv("RRG_NGINX")) return env;
  for (const char* p : {"/usr/sbin/nginx", "/usr/bin/nginx", "/usr/local/sbin/nginx"})
    if (fs::exists(p)) return p;
  const auto [rc, out] = run_shell("command -v nginx");
  return rc == 0 ? out.substr(0, out.find('\n')) : "";
}

int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof(a);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    ::close(fd);
    throw std::runtime_error("free_port: cannot bind a loopback port");
  }
  ::close(fd);
  return ntohs(a.sin_port);
}

std::string render_nginx_conf(const fs::path& prefix, const std::string& listen, const std::vector<std::string>& servers) {
  std::string conf = read_text(fs::path(RRG_SOURCE_DIR) / "deploy/nginx/rrg-local.conf.in");
  if (conf.empty()) throw std::runtime_error("cannot read deploy/nginx/rrg-local.conf.in");
  // As root, nginx would hand its workers to `nobody`, who cannot write the scratch folders.
  std::string user_line;
  if (::geteuid() == 0) {
    const passwd* pw = ::getpwuid(::geteuid());
    const group* gr = ::getgrgid(::getegid());
    if (pw && gr) user_line = std::string("user ") + pw->pw_name + " " + gr->gr_name + ";";
  }
  std::string list;
  for (const auto& s : servers) list += "server " + s + ";\n    ";
  replace_all(conf, "@USER_LINE@", user_line);
  replace_all(conf, "@PREFIX@", prefix.string());
  replace_all(conf, "@LISTEN@", listen);
  replace_all(conf, "@SERVERS@", list);
  return conf;
}

NginxProcess::NginxProcess(const fs::path& prefix, const std::vector<std::string>& servers) : prefix_(prefix) {
  nginx_ = find_nginx();
  if (nginx_.empty()) throw std::runtime_error("nginx not found (scripts/install_deps.sh installs Debian's nginx)");
  conf_ = (prefix_ / "nginx.conf").string();
  fs::create_directories(prefix_);
  port_ = free_port();
  write_conf(servers);
  const auto [rc, out] = run_shell(nginx_ + " -p " + prefix_.string() + " -c " + conf_ + " -t");
  if (rc != 0) throw std::runtime_error("nginx -t failed:\n" + out);
  std::vector<std::string> args = {nginx_, "-p", prefix_.string(), "-c", conf_};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string log = (prefix_ / "stderr.log").string();
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawnattr_t attr;  // its own process group, so master and workers can be killed together
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  const int spawn_rc = posix_spawn(&pid_, nginx_.c_str(), &fa, &attr, argv.data(), environ);
  posix_spawnattr_destroy(&attr);
  posix_spawn_file_actions_destroy(&fa);
  if (spawn_rc != 0) throw std::runtime_error("cannot start " + nginx_);
  for (int i = 0; i < 200; ++i) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw std::runtime_error("nginx exited at start:\n" + read_text(log) + error_log());
    }
    if (port_open(port_)) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  const std::string errors = error_log();
  ::kill(-pid_, SIGKILL);
  int status = 0;
  ::waitpid(pid_, &status, 0);
  pid_ = -1;
  throw std::runtime_error("nginx did not listen on " + address() + " within 5 s:\n" + errors);
}

NginxProcess::~NginxProcess() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGQUIT);
  for (int i = 0; i < 100; ++i) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::kill(-pid_, SIGKILL);  // the whole group: master and workers
  int status = 0;
  ::waitpid(pid_, &status, 0);
}

void NginxProcess::write_conf(const std::vector<std::string>& servers) {
  std::ofstream(conf_) << render_nginx_conf(prefix_, "127.0.0.1:" + std::to_string(port_), servers);
  for (const char* d : {"client_body", "proxy", "fastcgi", "uwsgi", "scgi"}) fs::create_directories(prefix_ / d);
}

void NginxProcess::reload(const std::vector<std::string>& servers) {
  write_conf(servers);
  const auto [rc, out] = run_shell(nginx_ + " -p " + prefix_.string() + " -c " + conf_ + " -s reload");
  if (rc != 0) throw std::runtime_error("nginx -s reload failed:\n" + out + error_log());
}

std::string NginxProcess::access_log() const { return read_text(prefix_ / "access.log"); }
std::string NginxProcess::error_log() const { return read_text(prefix_ / "error.log"); }

}  // namespace rrg::test
