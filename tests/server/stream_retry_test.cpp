// `rrg stream` against a full server: a Create that gets RESOURCE_EXHAUSTED is retried with a new id
// after a pause (--create-retries), so a slot freed meanwhile is taken; with no retries left the
// command fails naming the status. Real `rrg serve` and `rrg stream` processes on loopback.
#include "tests/server/server_fixture.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <thread>

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

  // The held session closes while the stream waits between retries: the stream gets the slot.
  auto streamed = std::async(std::launch::async, [&] { return run_rrg(stream_args(s, 20)); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  c.close({held.session_id(), held.token()});
  const CommandResult ok = streamed.get();
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_NE(ok.output.find("is full"), std::string::npos) << ok.output;  // it did wait for the slot
}

}  // namespace
}  // namespace rrg::test
