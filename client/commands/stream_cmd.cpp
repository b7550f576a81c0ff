// rrg stream: streams a dataset through the service (one or several sessions at once) and prints
// poses with their live error against ground truth, round-trip latency (p50 / p99) and frames/s.
// The session is configured as `rrg run` configures its in-process Session (semantics auto: label
// images when the dataset has them; the first frame's ground-truth pose as its pose prior), so
// the two give the same trajectory with config sync = true.
#include "client/commands/command.h"

#if RRG_WITH_GRPC
#include "client/commands/service_common.h"
#include "client/lib/frame_encode.h"
#include "client/lib/proto_convert.h"
#include "core/eval/trajectory_metrics.h"
#include "core/io/atomic_file.h"
#include "core/io/dataset.h"
#include "core/io/synth_layout.h"
#include "core/planes/semantic_labels.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

namespace rrg::cli {
namespace {

struct StreamCmdOptions {
  ServiceFlags service;
  std::string dataset, out, color = "png", depth = "rvl+zstd", semantics = "auto", name = "rrg stream";
  std::string session_id;  // proposed id (routable through a proxy hashing x-rrg-session); "" = random
  io::DatasetFlags flags;
  std::vector<std::string> set;
  size_t max_frames = 0;
  int sessions = 1, window = 4, queue = 0, progress = 10, create_retries = 5;
  bool realtime = false, preload = false, close = false, save = false, no_prior = false;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, size_t(p * double(v.size() - 1) + 0.5));
  return v[i];
}

struct SessionRun {
  service::SessionHandle handle;
  service::StreamSummary summary;
  io::Trajectory trajectory;
  std::string timings_csv;
  std::string error;
  uint64_t filled_frames = 0, filled_pixels = 0;  // the reflective fill (planes.fill)
};

// Create, retried on RESOURCE_EXHAUSTED (a full server: session count or memory budget) after a
// growing pause, up to --create-retries times. A random id is drawn afresh on each retry, so behind
// a proxy that hashes x-rrg-session (docs/deploy.md) the retry may land on another server; an id
// the user proposed is kept (it must stay routable to where it was asked for).
v1::CreateSessionResponse create_with_retries(service::ServiceClient& client, v1::CreateSessionRequest create,
                                              const StreamCmdOptions& o, const std::string& server) {
  for (int attempt = 0;; ++attempt) {
    try {
      return client.create(create);
    } catch (const service::RpcError& e) {
      if (e.code() != grpc::StatusCode::RESOURCE_EXHAUSTED || attempt >= o.create_retries) {
        if (e.code() == grpc::StatusCode::RESOURCE_EXHAUSTED && o.create_retries > 0)
          throw std::runtime_error(std::string(e.what()) + " (still full after " + std::to_string(o.create_retries) +
                                   " retries)");
        throw;
      }
      const auto pause = std::chrono::milliseconds(500 * (attempt + 1));
      spdlog::warn("stream: server {} is full ({}); retry {}/{} in {} ms", server.empty() ? o.service.server : server,
                   e.what(), attempt + 1, o.create_retries, pause.count());
      std::this_thread::sleep_for(pause);
      if (o.session_id.empty()) create.set_session_id(service::new_session_id());
    }
  }
}

void run_stream(const StreamCmdOptions& o) {
  const auto dataset = io::open_dataset(o.dataset, o.flags.to_options());
  const Intrinsics& K = dataset->intrinsics();
  const size_t n = o.max_frames > 0 ? std::min(dataset->size(), o.max_frames) : dataset->size();
  const bool has_labels = dataset->format() == io::DatasetFormat::Synth &&
                          std::filesystem::exists(io::synth_scene_file(dataset->root(), "categories.json"));
  std::string semantics = o.semantics == "auto" ? (has_labels ? "labels" : "none") : o.semantics;
  if (semantics == "labels" && !has_labels)
    throw std::invalid_argument("stream: --semantics labels needs a synthetic dataset with label images");

  service::WireEncoding enc;
  enc.color = io::parse_color_encoding(o.color);
  enc.depth = io::parse_depth_encoding(o.depth);
  const float depth_scale = dataset->depth_scale();

  v1::CreateSessionRequest create;
  *create.mutable_intrinsics() = service::to_proto(K);
  create.set_depth_scale(enc.depth == io::DepthEncoding::raw_f32 ? 1000.0f : depth_scale);
  create.set_name(o.name);
  create.set_queue_capacity(uint32_t(o.queue));
  (*create.mutable_config())["semantics"] = semantics;
  if (semantics == "labels")
    for (const auto& [id, cat] : read_category_table(io::synth_scene_file(dataset->root(), "categories.json")).names)
      (*create.mutable_categories())[id] = cat;
  for (const std::string& kv : o.set) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("stream: --set wants key=value, got '" + kv + "'");
    (*create.mutable_config())[kv.substr(0, eq)] = kv.substr(eq + 1);
  }

  // Frames on the wire (encoded once when --preload, else as they are sent).
  const auto encode = [&](size_t i) {
    const io::Frame f = dataset->load(i);
    std::optional<LabelImage> labels;
    if (semantics == "labels") labels = io::read_synth_labels(dataset->root(), i);
    std::optional<Eigen::Isometry3f> prior;
    if (!o.no_prior && i == 0 && f.T_wc_gt) prior = f.T_wc_gt->cast<float>();
    return service::encode_frame(i, f.timestamp, f.color, f.depth, depth_scale, enc, labels, prior);
  };
  std::vector<v1::Frame> preloaded;
  if (o.preload)
    for (size_t i = 0; i < n; ++i) preloaded.push_back(encode(i));
  const io::Trajectory gt = dataset->has_ground_truth() ? dataset->ground_truth() : io::Trajectory{};
  std::map<double, Eigen::Vector3d> gt_at;  // by timestamp, for the live error
  for (const auto& p : gt) gt_at[p.timestamp] = p.T_wc.translation();

  service::ServiceClient client = o.service.client();
  std::vector<SessionRun> runs(size_t(std::max(1, o.sessions)));
  for (size_t k = 0; k < runs.size(); ++k) {
    // The id is chosen here so the Create already carries it in x-rrg-session (docs/deploy.md).
    if (o.session_id.empty()) create.set_session_id(service::new_session_id());
    else create.set_session_id(runs.size() == 1 ? o.session_id : o.session_id + "-" + std::to_string(k));
    std::string server;
    client.set_server_observer([&](const std::string&, const std::string&, const std::string& name) { server = name; });
    const auto r = create_with_retries(client, create, o, server);
    runs[k].handle = {r.session_id(), r.token()};
    spdlog::info("stream: session {} on server {} via {} ({}, {} mapping)", r.session_id(), server.empty() ? "?" : server,
                 o.service.server, r.info().device(), r.info().schedule());
  }
  client.set_server_observer(nullptr);
  std::mutex print_mutex;
  const auto stream_one = [&](size_t k) {
    SessionRun& run = runs[k];
    size_t next_index = 0;
    const auto wall0 = std::chrono::steady_clock::now();
    const double ts0 = n > 0 ? dataset->load(0).timestamp : 0.0;
    service::StreamOptions so;
    so.window = o.window;
    if (o.realtime)
      so.before_send = [&](uint64_t id) {
        const double due = (o.preload ? preloaded[id].timestamp() : dataset->load(id).timestamp) - ts0;
        std::this_thread::sleep_until(wall0 + std::chrono::duration<double>(due));
      };
    run.timings_csv = "frame,state,round_trip_ms,queue_ms,decode_ms,process_ms,icp_ms,orb_ms,fuse_ms,identify_ms,mapping_ms\n";
    run.summary = client.stream(
        run.handle,
        [&]() -> std::optional<v1::Frame> {
          if (next_index >= n) return std::nullopt;
          const size_t i = next_index++;
          return o.preload ? preloaded[i] : encode(i);
        },
        [&](const v1::FrameResult& r, double rtt) {
          if (r.has_error()) {
            std::lock_guard lock(print_mutex);
            spdlog::warn("stream: frame {} rejected: {}", r.id(), r.error().message());
            return;
          }
          if (r.dropped()) return;
          const Eigen::Isometry3f T = service::from_proto(r.pose());
          run.trajectory.push_back({r.timestamp(), T.cast<double>()});
          if (r.filled_pixels() > 0) {
            ++run.filled_frames;
            run.filled_pixels += r.filled_pixels();
          }
          const auto& t = r.timings();
          run.timings_csv += fmt::format("{},{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f}\n", r.id(),
                                         service::to_string(r.state()), rtt, t.queue(), t.decode(), t.total(), t.icp(),
                                         t.orb(), t.fuse(), t.identify(), t.mapping());
          if (k == 0 && o.progress > 0 && (r.id() % uint64_t(o.progress) == 0 || r.id() + 1 == n)) {
            std::string err;
            const auto it = gt_at.find(r.timestamp());
            if (it != gt_at.end())
              err = fmt::format(", error {:.2f} cm", (T.translation().cast<double>() - it->second).norm() * 100.0);
            std::lock_guard lock(print_mutex);
            spdlog::info("stream: frame {}/{}: {}, round trip {:.1f} ms, dropped so far {}{}", r.id() + 1, n,
                         service::to_string(r.state()), rtt, r.frames_dropped(), err);
          }
        },
        so);
  };
  std::vector<std::thread> threads;
  for (size_t k = 0; k < runs.size(); ++k)
    threads.emplace_back([&, k] {
      try {
        stream_one(k);
      } catch (const std::exception& e) {
        runs[k].error = e.what();
      }
    });
  for (auto& t : threads) t.join();

  std::vector<double> all_rtt;
  double total_frames = 0, max_wall = 0;
  for (size_t k = 0; k < runs.size(); ++k) {
    SessionRun& run = runs[k];
    if (!run.error.empty()) throw std::runtime_error("stream: session " + run.handle.id + ": " + run.error);
    if (!run.summary.status.ok())
      throw std::runtime_error("stream: session " + run.handle.id + ": " + run.summary.status.error_message());
    const auto& s = run.summary;
    all_rtt.insert(all_rtt.end(), s.round_trip_ms.begin(), s.round_trip_ms.end());
    total_frames += double(s.round_trip_ms.size());
    max_wall = std::max(max_wall, s.wall_s);
    std::printf("session %s: server %s: %zu frames sent, %zu processed, %zu dropped, %zu rejected; %.2f frames/s; round trip "
                "p50 %.1f ms, p99 %.1f ms (window %d)\n", run.handle.id.c_str(), s.server.empty() ? "?" : s.server.c_str(), s.sent, s.round_trip_ms.size(),
                s.dropped, s.rejected, double(s.round_trip_ms.size()) / s.wall_s, percentile(s.round_trip_ms, 0.5),
                percentile(s.round_trip_ms, 0.99), o.window);
    if (run.filled_frames > 0)
      std::printf("session %s: reflective fill: %llu frames, %llu depth pixels filled on reflective masks\n",
                  run.handle.id.c_str(), (unsigned long long)run.filled_frames, (unsigned long long)run.filled_pixels);
    if (!gt.empty() && run.trajectory.size() >= 3) {
      const auto m = eval::evaluate_trajectory(run.trajectory, gt);
      std::printf("session %s: ATE RMSE %.3f cm (rigid SE(3) Umeyama alignment, %zu poses; unaligned %.3f cm)\n",
                  run.handle.id.c_str(), m.ate.rmse_cm, m.ate.matched, m.ate.rmse_unaligned_cm);
    }
    if (!o.out.empty()) {
      const std::filesystem::path dir(o.out);
      const std::string suffix = k == 0 ? "" : "_" + std::to_string(k);
      io::write_tum_trajectory(dir / ("trajectory" + suffix + ".txt"), run.trajectory);
      io::write_atomically(dir / ("timings" + suffix + ".csv"), [&](const std::filesystem::path& tmp) {
        std::ofstream(tmp) << run.timings_csv;
      });
    }
    if (o.close || o.save) {
      client.close(run.handle, o.save);
    } else {
      std::printf("session %s token %s (still open: rrg mesh/gaussians/render --server %s --session %s --token ...)\n",
                  run.handle.id.c_str(), run.handle.token.c_str(), o.service.server.c_str(), run.handle.id.c_str());
    }
  }
  if (runs.size() > 1)
    std::printf("all %zu sessions: %.2f frames/s in total; round trip p50 %.1f ms, p99 %.1f ms\n", runs.size(),
                total_frames / max_wall, percentile(all_rtt, 0.5), percentile(all_rtt, 0.99));
}

}  // namespace

void register_stream_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("stream", "stream a dataset through the service and report poses, latency, frames/s");
  auto o = std::make_shared<StreamCmdOptions>();
  o->service.add(*cmd, false);
  cmd->add_option("--dataset", o->dataset, "dataset folder")->required();
  io::add_dataset_flags(*cmd, o->flags);
  cmd->add_option("--out", o->out, "write trajectory.txt (TUM) and timings.csv here");
  cmd->add_option("--color", o->color, "colour encoding: png | jpeg | raw")->capture_default_str();
  cmd->add_option("--depth", o->depth, "depth encoding: rvl+zstd | rvl | png | raw | raw_f32")->capture_default_str();
  cmd->add_option("--semantics", o->semantics, "auto | labels | none (auto: labels when the dataset has them)")->capture_default_str();
  cmd->add_option("--set", o->set, "session config override key=value (repeatable), e.g. sync=true");
  cmd->add_option("--max-frames", o->max_frames, "stream at most this many frames");
  cmd->add_option("--sessions", o->sessions, "stream the dataset through this many sessions at once")->capture_default_str();
  cmd->add_option("--window", o->window, "frames in flight per session (1 = lock-step)")->capture_default_str();
  cmd->add_option("--queue", o->queue, "server-side frame queue capacity (0 = server default)");
  cmd->add_option("--name", o->name, "session name");
  cmd->add_option("--session-id", o->session_id,
                  "propose the session id, [a-z0-9-]{4,64} (with --sessions N: ID-0 ... ID-N-1; default: random)");
  cmd->add_option("--create-retries", o->create_retries,
                  "retries of a Create that finds the server full (RESOURCE_EXHAUSTED), pausing 0.5 s, 1 s, ...; "
                  "a random session id is drawn afresh each time")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--progress", o->progress, "log every N-th frame (0 = never)")->capture_default_str();
  cmd->add_flag("--realtime", o->realtime, "send at the dataset's frame rate (default: as fast as possible)");
  cmd->add_flag("--preload", o->preload, "encode every frame before streaming (benchmarks)");
  cmd->add_flag("--close", o->close, "close the session(s) at the end");
  cmd->add_flag("--save", o->save, "snapshot and close the session(s) at the end");
  cmd->add_flag("--no-pose-prior", o->no_prior, "do not send the first frame's ground-truth pose");
  cmd->callback([o] { run_stream(*o); });
}

}  // namespace rrg::cli
#else
namespace rrg::cli {
void register_stream_command(CLI::App& app) {
  app.add_subcommand("stream", "stream a dataset through the service (not in this build)")->callback([] {
    throw std::runtime_error("stream: this build has no gRPC (install libgrpc++-dev protobuf-compiler-grpc, rebuild)");
  });
}
}  // namespace rrg::cli
#endif
