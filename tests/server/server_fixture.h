#pragma once
// Helpers of the service's integration tests: the real `rrg serve` as a child process on a
// loopback port, the tiny synthetic sequence every test streams (made once per test binary), the
// frames as the client sends them, and the reference trajectory of an in-process Session fed the
// very same decoded frames.
#include "client/lib/service_client.h"
#include "core/io/trajectory.h"
#include "core/slam/session.h"
#include "rrg/v1/service.pb.h"

#include <sys/types.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace rrg::test {

class ServerProcess {
 public:
  // Starts `rrg serve --address 127.0.0.1:0 --device cpu <extra args>` and waits until it serves.
  explicit ServerProcess(const std::vector<std::string>& extra_args = {}, const std::filesystem::path& snapshot_dir = {});
  ~ServerProcess();  // SIGKILL if still running
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  service::ServiceClient client() const { return service::ServiceClient(service::ChannelOptions{address()}); }
  void kill9();            // crash it
  int terminate();         // SIGTERM, wait; returns the exit status
  void signal(int sig);    // sends a signal, does not wait (SIGUSR1: drain)
  std::string log() const; // its stderr so far

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  std::filesystem::path dir_, log_;
};

// The sequence: 160x120 mirror_room, kFrames frames, generated once under the temp folder.
inline constexpr int kFrames = 12;
const std::filesystem::path& sequence_dir();
// Create request for the sequence (camera, depth scale, label categories) with the test config:
// sync = true (deterministic), 1 cm voxels and short mapping so the tests stay fast on 2 cores.
v1::CreateSessionRequest create_request();
v1::CreateSessionRequest create_request(const std::filesystem::path& dir);  // for another synth sequence
// The sequence's frames as sent on the wire (PNG colour, RVL+zstd depth, PNG labels, frame 0
// with its ground-truth pose prior); n = 0: all.
const std::vector<v1::Frame>& wire_frames();
std::vector<v1::Frame> encode_sequence(const std::filesystem::path& dir);  // the same for another sequence
// An in-process Session made from a create request, fed `frames` through the server's decoder:
// its report of every frame (and the session itself in *keep when given).
std::vector<FrameReport> process_in_process(const v1::CreateSessionRequest& req, const std::vector<v1::Frame>& frames,
                                            std::unique_ptr<Session>* keep = nullptr);
// The in-process Session's trajectory on the same frames (decoded by the server's own decoder).
const io::Trajectory& reference_trajectory();
// The in-process Session after those frames (for counts).
const Session& reference_session();

// Streams frames [begin, end) of wire_frames() and returns the results in order.
std::vector<v1::FrameResult> stream_frames(service::ServiceClient& c, const service::SessionHandle& h, size_t begin,
                                           size_t end, int window = 4);

}  // namespace rrg::test
