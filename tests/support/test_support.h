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
// Runs `rrg <args>` (the freshly built binary) through the shell and captures its output.
CommandResult run_rrg(const std::string& args);

// Folder with small committed test inputs (tests/data).
std::filesystem::path test_data_dir();

}  // namespace rrg::test
