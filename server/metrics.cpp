#include "server/metrics.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#if RRG_WITH_HTTPLIB
#include <httplib.h>
#endif

#include <stdexcept>

namespace rrg::server {

namespace {
constexpr const char* kStageNames[] = {"decode", "raycast", "preprocess", "icp", "orb", "fuse",
                                       "identify", "mapping", "process", "queue", "round_trip"};
constexpr double kWindowS = 10.0;
}  // namespace

void Metrics::Histogram::observe(double v) {
  size_t i = 0;
  while (i < bounds.size() && v > bounds[i]) ++i;
  counts[i]++;
  sum += v;
  count++;
}

Metrics::Metrics() = default;

void Metrics::frame_processed(const StageTimes& t, double queue_ms, double round_trip_ms) {
  frames_++;
  const double v[] = {t.decode, t.raycast, t.preprocess, t.icp, t.orb, t.fuse, t.identify, t.mapping, t.total,
                      queue_ms, round_trip_ms};
  std::lock_guard lock(m_);
  for (size_t i = 0; i < stages_.size(); ++i) stages_[i].observe(v[i]);
  const auto now = std::chrono::steady_clock::now();
  recent_.push_back(now);
  while (!recent_.empty() && std::chrono::duration<double>(now - recent_.front()).count() > kWindowS)
    recent_.pop_front();
}

double Metrics::frames_per_second() const {
  std::lock_guard lock(m_);
  const auto now = std::chrono::steady_clock::now();
  while (!recent_.empty() && std::chrono::duration<double>(now - recent_.front()).count() > kWindowS)
    recent_.pop_front();
  return double(recent_.size()) / kWindowS;
}

std::string Metrics::prometheus_text(const std::string& gauges) const {
  std::string s;
  s += "# HELP rrg_frames_total Frames processed by all sessions.\n# TYPE rrg_frames_total counter\n";
  s += fmt::format("rrg_frames_total {}\n", frames_.load());
  s += "# HELP rrg_frames_dropped_total Frames dropped unprocessed because a session's queue was full.\n"
       "# TYPE rrg_frames_dropped_total counter\n";
  s += fmt::format("rrg_frames_dropped_total {}\n", dropped_.load());
  s += "# HELP rrg_frames_rejected_total Frames refused as invalid.\n# TYPE rrg_frames_rejected_total counter\n";
  s += fmt::format("rrg_frames_rejected_total {}\n", rejected_.load());
  s += "# HELP rrg_sessions_created_total Sessions created or loaded.\n# TYPE rrg_sessions_created_total counter\n";
  s += fmt::format("rrg_sessions_created_total {}\n", created_.load());
  s += "# HELP rrg_frames_per_second Frames processed per second over the last 10 s.\n"
       "# TYPE rrg_frames_per_second gauge\n";
  s += fmt::format("rrg_frames_per_second {:.3f}\n", frames_per_second());
  s += "# HELP rrg_stage_latency_ms Per-frame stage latency in milliseconds.\n"
       "# TYPE rrg_stage_latency_ms histogram\n";
  std::lock_guard lock(m_);
  for (size_t i = 0; i < stages_.size(); ++i) {
    const Histogram& h = stages_[i];
    uint64_t cum = 0;
    for (size_t b = 0; b < Histogram::bounds.size(); ++b) {
      cum += h.counts[b];
      s += fmt::format("rrg_stage_latency_ms_bucket{{stage=\"{}\",le=\"{}\"}} {}\n", kStageNames[i],
                       Histogram::bounds[b], cum);
    }
    cum += h.counts.back();
    s += fmt::format("rrg_stage_latency_ms_bucket{{stage=\"{}\",le=\"+Inf\"}} {}\n", kStageNames[i], cum);
    s += fmt::format("rrg_stage_latency_ms_sum{{stage=\"{}\"}} {:.3f}\n", kStageNames[i], h.sum);
    s += fmt::format("rrg_stage_latency_ms_count{{stage=\"{}\"}} {}\n", kStageNames[i], h.count);
  }
  s += gauges;
  return s;
}

#if RRG_WITH_HTTPLIB
struct MetricsHttpServer::Impl {
  httplib::Server http;
  std::thread thread;
};

MetricsHttpServer::MetricsHttpServer(int port, std::function<std::string()> text) : impl_(std::make_unique<Impl>()) {
  impl_->http.Get("/metrics", [text](const httplib::Request&, httplib::Response& res) {
    res.set_content(text(), "text/plain; version=0.0.4");
  });
  if (port == 0) {
    port_ = impl_->http.bind_to_any_port("0.0.0.0");
  } else {
    port_ = impl_->http.bind_to_port("0.0.0.0", port) ? port : -1;
  }
  if (port_ <= 0) throw std::runtime_error("metrics: cannot bind port " + std::to_string(port));
  impl_->thread = std::thread([this] { impl_->http.listen_after_bind(); });
  spdlog::info("metrics: Prometheus text on http://0.0.0.0:{}/metrics", port_);
}

MetricsHttpServer::~MetricsHttpServer() {
  impl_->http.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}
#else
struct MetricsHttpServer::Impl {};
MetricsHttpServer::MetricsHttpServer(int, std::function<std::string()>) {
  throw std::runtime_error("metrics: this build has no cpp-httplib (install libcpp-httplib-dev and rebuild)");
}
MetricsHttpServer::~MetricsHttpServer() = default;
#endif

}  // namespace rrg::server
