// `rrg stream` against a full server: a Create that gets RESOURCE_EXHAUSTED is retried with a new id
// after a pause (--create-retries), so a slot freed meanwhile is taken; with no retries left the
// command fails naming the status. Real `rrg serve` and `rrg stream` processes on loopback.
#include "tests/server/server_fixture.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

namespace rrg::test {
namespace {

std::string stream_args(const ServerProcess& s, int retries) {
  return "stream --server " + s.address() + " --dataset " + sequence_dir().string() +
         " --max-frames 2 --close --progress 0 --create-retries " + std::to_string(retries);
}

TEST(StreamRetry, AFullServerFailsWithoutRetriesAndIsRetriedUntilASlotFrees) {
  ServerProcess s({"--max-sessions", "1"});
  auto c = s.client();
  const auto held = c.create(create_request());

  const CommandResult none = run_rrg(stream_args(s, 0));
  EXPECT_NE(none.exit_code, 0);
  EXPECT_NE(none.output.find("RESOURCE_EXHAUSTED"), std::string::npos) << none.output;

  const CommandResult still = run_rrg(stream_args(s, 1));
  EXPECT_NE(still.exit_code, 0);
  EXPECT_NE(still.output.find("still full after 1 retries"), std::string::npos) << still.output;

  // The held session closes while the stream waits between retries: the stream gets the slot. It
  // is closed once the stream has logged its first refusal, not after a fixed pause (on a loaded
  // machine the process may take longer than any pause to start, and would then find the slot free).
  TempDir dir("stream_retry");
  BackgroundRrg streamed(stream_args(s, 20), dir / "log.txt");
  ASSERT_TRUE(streamed.wait_for_output("is full")) << "the stream never found the server full";
  c.close({held.session_id(), held.token()});
  EXPECT_EQ(streamed.wait(), 0);
  std::ifstream log(dir / "log.txt");
  const std::string out((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(out.find("frames sent"), std::string::npos) << out;  // it streamed once the slot was free
}

}  // namespace
}  // namespace rrg::test
