#pragma once
// Helpers shared by every test binary: scratch folders and running the real `rrg` executable.
#include <filesystem>
#include <string>

namespace rrg::test {

// A fresh empty folder under the system temp dir, removed when the object dies.
class TempDir {
 public:
  explicit TempDir(const std::string& tag = "rrg");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};
// The freshly built `rrg` (compiled-in path; the environment variable RRG_CLI overrides it).
std::filesystem::path rrg_executable();
// Runs `rrg <args>` (rrg_executable()) through the shell and captures its output.
CommandResult run_rrg(const std::string& args);
// Runs a shell command line and captures its output the same way (exit code −1 when a signal
// ended it); `auto [rc, out] = run_shell(...)` reads both.
CommandResult run_shell(const std::string& command);

// `rrg <args>` started in the background (stdout and stderr to `log`), for tests that signal it.
class BackgroundRrg {
 public:
  BackgroundRrg(const std::string& args, const std::filesystem::path& log);
  ~BackgroundRrg();  // kills the process if it is still running
  BackgroundRrg(const BackgroundRrg&) = delete;
  BackgroundRrg& operator=(const BackgroundRrg&) = delete;
  // Waits (polling, up to timeout_s) until `log` contains `text`; false on timeout or exit.
  bool wait_for_output(const std::string& text, double timeout_s = 60.0);
  void signal(int sig);
  // Waits for the process; its exit code, or -1 when a signal ended it.
  int wait();

 private:
  int pid_ = -1, status_ = 0;
  bool exited_ = false;
  std::filesystem::path log_;
};

// Folder with small committed test inputs (tests/data; the environment variable RRG_TEST_DATA_DIR
// overrides it).
std::filesystem::path test_data_dir();

}  // namespace rrg::test
