// The remote semantic cue against the real rrg_test_segmenter process (tests/planes/segmenter_server),
// spawned on a free loopback port. Built only when gRPC is (RRG_SEGMENTER_SERVER is its path).
#ifdef RRG_SEGMENTER_SERVER
#include "core/planes/remote_segmenter.h"

#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <csignal>
#include <cstdio>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace rrg {
namespace {

// The server as a child process; its first stdout line says the port. Killed on destruction.
class ServerProcess {
 public:
  explicit ServerProcess(const std::string& extra_args = "") {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      close(fds[1]);
      const std::string cmd = std::string("exec ") + RRG_SEGMENTER_SERVER + " --port 0 " + extra_args;
      execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    FILE* out = fdopen(fds[0], "r");
    char line[256] = {0};
    if (!out || !std::fgets(line, sizeof(line), out)) throw std::runtime_error("test segmenter did not start");
    std::fclose(out);
    const std::string s(line);
    const auto colon = s.rfind(':');
    address_ = "127.0.0.1:" + std::to_string(std::stoi(s.substr(colon + 1)));
  }
  ~ServerProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
  }
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;
  const std::string& address() const { return address_; }

 private:
  pid_t pid_ = -1;
  std::string address_;
};

TEST(RemoteSegmenter, MasksFromTheServerProcess) {
  ASSERT_TRUE(remote_segmenter_available());
  ServerProcess server;
  RemoteSegmenterOptions o;
  o.address = server.address();
  o.prompts = {"red", "tv", "blue"};
  auto cue = make_remote_semantics(o);
  EXPECT_EQ(cue->name(), "remote");
  // 8x4: left half red, right half blue, one white pixel.
  ColorImage c(8, 4, Color(1, 0, 0));
  for (int v = 0; v < 4; ++v)
    for (int u = 4; u < 8; ++u) c(u, v) = Color(0, 0, 1);
  c(0, 0) = Color(1, 1, 1);
  const auto masks = cue->segment({&c, nullptr, 0});
  ASSERT_EQ(masks.size(), 2u);  // "tv" has no pixels
  EXPECT_EQ(masks[0].label, "red");
  EXPECT_EQ(masks[1].label, "blue");
  EXPECT_FLOAT_EQ(masks[0].score, 0.9f);
  EXPECT_TRUE(masks[0].reflective);
  for (int v = 0; v < 4; ++v)
    for (int u = 0; u < 8; ++u) {
      EXPECT_EQ(masks[0].mask(u, v), (u < 4 && !(u == 0 && v == 0)) ? 1 : 0) << u << "," << v;
      EXPECT_EQ(masks[1].mask(u, v), u >= 4 ? 1 : 0);
    }
}

TEST(RemoteSegmenter, ServerErrorsReachTheCaller) {
  ServerProcess server;
  RemoteSegmenterOptions o;
  o.address = server.address();
  o.prompts = {"red"};
  auto cue = make_remote_semantics(o);
  const ColorImage empty;
  try {
    cue->segment({&empty, nullptr, 0});  // 0x0 image: INVALID_ARGUMENT
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("RGB8"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(server.address()), std::string::npos) << e.what();
  }
}

// The segmenter serves the sequence's label images; the mirror's glass has no depth, so the remote
// cue's mirror mask (the first cue's masks fill the depth, planes.fill) must come back for any
// pixel to be filled. (Until 2026-12-05 the test server served no category in this mode, and this
// test, which only checked that the run finished, passed.)
TEST(RemoteSegmenter, EvalEndToEndThroughTheCli) {
  test::TempDir dir("planes_remote");
  const auto seq = (dir.path() / "seq").string();
  auto r = test::run_rrg("synth --preset mirror_room --frames 2 --width 160 --height 120 --novel 0 --mirror-depth invalid --out " +
                         seq);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ServerProcess server("--labels " + seq);
  r = test::run_rrg("planes eval --dataset " + seq + " --semantics remote,labels --period 1 --no-fuse --json --remote " +
                    server.address());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  ASSERT_EQ(j["cues"].size(), 2u);
  EXPECT_EQ(j["cues"][0]["semantics"], "remote");
  EXPECT_GT(j["filled_pixels"].get<int64_t>(), 2 * 160 * 120 / 20) << "the remote cue returned no mirror mask";
}

}  // namespace
}  // namespace rrg
#endif
