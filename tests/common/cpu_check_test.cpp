// The start-up CPU check (core/cpu_check.cpp): a program built for an x86-64-vN level refuses to
// run on a CPU without it, with a message and exit code 70, before any of its own code runs. The
// failing path is taken here with RRG_CPU_CHECK_FAIL=1 on this very test binary.
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace {

using rrg::test::CommandResult;

// This test binary again, running no test, with `env` set.
CommandResult run_self(const std::string& env) {
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  return rrg::test::run_shell(env + " '" + self + "' --gtest_filter=CpuCheck.NoSuchTest");
}

TEST(CpuCheck, ThisCpuRunsTheBuild) {
  const CommandResult r = run_self("RRG_CPU_CHECK_FAIL=0");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("this CPU lacks"), std::string::npos) << r.output;
}

TEST(CpuCheck, ACpuWithoutTheLevelGetsAMessageNotACrash) {
  const std::string level = RRG_CPU_LEVEL;
  if (level.empty()) GTEST_SKIP() << "built without an x86-64-vN level (RRG_CPU_ARCH): nothing is checked";
  const CommandResult r = run_self("RRG_CPU_CHECK_FAIL=1");
  EXPECT_EQ(r.exit_code, 70) << r.output;
  EXPECT_NE(r.output.find("built for " + level), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("-DRRG_CPU_ARCH="), std::string::npos) << r.output;
  // Nothing of the program itself ran: GoogleTest never printed its banner.
  EXPECT_EQ(r.output.find("Running"), std::string::npos) << r.output;
}

}  // namespace
