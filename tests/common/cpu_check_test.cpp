// The start-up CPU check (core/cpu_check.cpp): a program built for an x86-64-vN level refuses to
// run on a CPU without it, with a message and exit code 70, before any of its own code runs. The
// failing path is taken here with RRG_CPU_CHECK_FAIL=1 on this very test binary.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>

namespace {

struct Result {
  int exit_code = -1;
  std::string output;
};

Result run_self(const std::string& env) {
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const std::string cmd = env + " '" + self + "' --gtest_filter=CpuCheck.NoSuchTest 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed: " + cmd);
  Result r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

TEST(CpuCheck, ThisCpuRunsTheBuild) {
  const Result r = run_self("RRG_CPU_CHECK_FAIL=0");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("this CPU lacks"), std::string::npos) << r.output;
}

TEST(CpuCheck, ACpuWithoutTheLevelGetsAMessageNotACrash) {
  const std::string level = RRG_CPU_LEVEL;
  if (level.empty()) GTEST_SKIP() << "built without an x86-64-vN level (RRG_CPU_ARCH): nothing is checked";
  const Result r = run_self("RRG_CPU_CHECK_FAIL=1");
  EXPECT_EQ(r.exit_code, 70) << r.output;
  EXPECT_NE(r.output.find("built for " + level), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("-DRRG_CPU_ARCH="), std::string::npos) << r.output;
  // Nothing of the program itself ran: GoogleTest never printed its banner.
  EXPECT_EQ(r.output.find("Running"), std::string::npos) << r.output;
}

}  // namespace
