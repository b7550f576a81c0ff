#include "tests/support/test_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <thread>

namespace rrg::test {

TempDir::TempDir(const std::string& tag) {
  static std::atomic<int> counter{0};
  path_ = std::filesystem::temp_directory_path() /
          (tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

namespace {
// A compiled-in path, unless the environment variable `name` names another (test binaries carried
// to another machine, e.g. the GPU bundle of scripts/gpu_checks.sh, where the build tree is absent).
std::filesystem::path overridable(const char* name, const char* compiled_in) {
  const char* env = std::getenv(name);
  return env && *env ? std::filesystem::path(env) : std::filesystem::path(compiled_in);
}

// "<rrg> args" for the shell; throws when the executable is not built.
std::string rrg_command(const std::string& args) {
  const std::filesystem::path cli = rrg_executable();
  if (!std::filesystem::exists(cli))
    throw std::runtime_error("the rrg executable is not built: " + cli.string() + " (RRG_CLI overrides the path)");
  return cli.string() + " " + args;
}
}  // namespace

std::filesystem::path rrg_executable() { return overridable("RRG_CLI", RRG_CLI); }

CommandResult run_rrg(const std::string& args) { return run_shell(rrg_command(args)); }

CommandResult run_shell(const std::string& command) {
  const std::string cmd = command + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed for: " + cmd);
  CommandResult result;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

BackgroundRrg::BackgroundRrg(const std::string& args, const std::filesystem::path& log) : log_(log) {
  const std::string cmd = "exec " + rrg_command(args) + " > '" + log.string() + "' 2>&1";
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork failed for: " + cmd);
  if (pid_ == 0) {  // the child becomes `sh -c "exec rrg ..."`, i.e. rrg itself with the redirections
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
}

BackgroundRrg::~BackgroundRrg() {
  if (pid_ > 0 && !exited_) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
}

bool BackgroundRrg::wait_for_output(const std::string& text, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    std::ifstream f(log_);
    const std::string content((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    if (content.find(text) != std::string::npos) return true;
    if (::waitpid(pid_, &status_, WNOHANG) == pid_) {
      exited_ = true;
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

void BackgroundRrg::signal(int sig) {
  if (!exited_) ::kill(pid_, sig);
}

int BackgroundRrg::wait() {
  if (!exited_) {
    if (::waitpid(pid_, &status_, 0) != pid_) return -1;
    exited_ = true;
  }
  return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1;
}

std::filesystem::path test_data_dir() { return overridable("RRG_TEST_DATA_DIR", RRG_TEST_DATA_DIR); }

}  // namespace rrg::test
