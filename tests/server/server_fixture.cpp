#include "tests/server/server_fixture.h"

#include "client/lib/frame_encode.h"
#include "client/lib/proto_convert.h"
#include "core/io/dataset.h"
#include "core/io/synth_layout.h"
#include "core/planes/semantic_labels.h"
#include "core/slam/session_config.h"
#include "server/frame_decode.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <csignal>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

extern char** environ;

namespace rrg::test {

namespace fs = std::filesystem;

namespace {
const std::map<std::string, std::string> kTestConfig = {
    {"sync", "true"}, {"tsdf.voxel_size", "0.01"}, {"mapping_period", "4"}, {"plane_period", "4"},
    {"mapping.iterations", "5"}};

fs::path unique_dir(const std::string& tag) {
  static int n = 0;
  const fs::path d = fs::temp_directory_path() / ("rrg-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
}  // namespace

ServerProcess::ServerProcess(const std::vector<std::string>& extra, const fs::path& snapshot_dir) {
  dir_ = unique_dir("serve");
  log_ = dir_ / "serve.log";
  const fs::path port_file = dir_ / "port";
  std::vector<std::string> args = {test::rrg_executable().string(), "serve", "--address", "127.0.0.1:0", "--device", "cpu",
                                   "--port-file", port_file.string()};
  if (!snapshot_dir.empty()) args.insert(args.end(), {"--snapshot-dir", snapshot_dir.string()});
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log_.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, log_.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  const int rc = posix_spawn(&pid_, args[0].c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error("cannot start " + args[0]);
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw std::runtime_error("rrg serve exited at start:\n" + log());
    }
    std::ifstream f(port_file);
    if (f >> port_ && port_ > 0) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  throw std::runtime_error("rrg serve did not start within 60 s:\n" + log());
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) kill9();
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

void ServerProcess::kill9() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
}

int ServerProcess::terminate() {
  if (pid_ <= 0) return -1;
  ::kill(pid_, SIGTERM);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

void ServerProcess::signal(int sig) {
  if (pid_ > 0) ::kill(pid_, sig);
}

std::string ServerProcess::log() const {
  std::ifstream f(log_);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

const fs::path& sequence_dir() {
  static const TempDir root("rrg-seq");  // removed at exit
  static const fs::path dir = [] {
    const fs::path d = root.path() / "mirror_room";
    const auto r = run_rrg("synth --preset mirror_room --frames " + std::to_string(kFrames) +
                           " --width 160 --height 120 --novel 0 --threads 2 --out " + d.string());
    if (r.exit_code != 0) throw std::runtime_error("rrg synth failed:\n" + r.output);
    return d;
  }();
  return dir;
}

v1::CreateSessionRequest create_request() { return create_request(sequence_dir()); }

v1::CreateSessionRequest create_request(const fs::path& dir) {
  const auto ds = io::open_dataset(dir);
  v1::CreateSessionRequest r;
  *r.mutable_intrinsics() = service::to_proto(ds->intrinsics());
  r.set_depth_scale(ds->depth_scale());
  r.set_name("test");
  for (const auto& [k, v] : kTestConfig) (*r.mutable_config())[k] = v;
  (*r.mutable_config())["semantics"] = "labels";
  for (const auto& [id, name] : read_category_table(io::synth_scene_file(dir, "categories.json")).names)
    (*r.mutable_categories())[id] = name;
  return r;
}

const std::vector<v1::Frame>& wire_frames() {
  static const std::vector<v1::Frame> frames = encode_sequence(sequence_dir());
  return frames;
}

std::vector<v1::Frame> encode_sequence(const fs::path& dir) {
  const auto ds = io::open_dataset(dir);
  std::vector<v1::Frame> v;
  for (size_t i = 0; i < ds->size(); ++i) {
    const io::Frame f = ds->load(i);
    std::optional<Eigen::Isometry3f> prior;
    if (i == 0 && f.T_wc_gt) prior = f.T_wc_gt->cast<float>();
    v.push_back(service::encode_frame(i, f.timestamp, f.color, f.depth, ds->depth_scale(), {},
                                      io::read_synth_labels(dir, i), prior));
  }
  return v;
}

std::vector<FrameReport> process_in_process(const v1::CreateSessionRequest& req, const std::vector<v1::Frame>& frames,
                                            std::unique_ptr<Session>* keep) {
  SessionConfig c;
  c.K = service::from_proto(req.intrinsics());
  for (const auto& [k, v] : req.config()) set_config_value(c, k, v);
  for (const auto& [id, name] : req.categories()) c.categories[uint16_t(id)] = name;
  auto session = std::make_unique<Session>(c);
  std::vector<FrameReport> reports;
  for (const auto& f : frames) reports.push_back(session->process(server::decode_frame(f, c.K, req.depth_scale()).frame));
  if (keep) *keep = std::move(session);
  return reports;
}

namespace {
struct Reference {
  std::unique_ptr<Session> session;
  io::Trajectory trajectory;
};
const Reference& reference() {
  static const Reference ref = [] {
    Reference r;
    for (const FrameReport& rep : process_in_process(create_request(), wire_frames(), &r.session))
      r.trajectory.push_back({rep.timestamp, rep.T_wc.cast<double>()});
    return r;
  }();
  return ref;
}
}  // namespace

const io::Trajectory& reference_trajectory() { return reference().trajectory; }
const Session& reference_session() { return *reference().session; }

std::vector<v1::FrameResult> stream_frames(service::ServiceClient& c, const service::SessionHandle& h, size_t begin,
                                           size_t end, int window) {
  std::vector<v1::FrameResult> out;
  std::mutex m;
  size_t i = begin;
  service::StreamOptions o;
  o.window = window;
  const auto sum = c.stream(
      h, [&]() -> std::optional<v1::Frame> { return i < end ? std::optional(wire_frames()[i++]) : std::nullopt; },
      [&](const v1::FrameResult& r, double) {
        std::lock_guard lock(m);
        out.push_back(r);
      },
      o);
  EXPECT_TRUE(sum.status.ok()) << sum.status.error_message();
  return out;
}

}  // namespace rrg::test
