#pragma once
// Service metrics in the Prometheus text exposition format (version 0.0.4): counters of frames,
// drops and rejections, per-stage latency histograms (milliseconds, from the session's own stage
// timers), frames/s over the last 10 s, and the gauges the session manager reports (sessions,
// memory). The HTTP endpoint (MetricsHttpServer) serves GET /metrics.
#include "core/slam/session.h"

#include <atomic>
#include <array>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace rrg::server {

class Metrics {
 public:
  Metrics();
  void frame_processed(const StageTimes& t, double queue_ms, double round_trip_ms);
  void frame_dropped() { dropped_++; }
  void frame_rejected() { rejected_++; }
  void session_created() { created_++; }
  double frames_per_second() const;  // completed frames over the last 10 s
  // Text of every metric; `gauges` appends the manager's gauges (already formatted lines).
  std::string prometheus_text(const std::string& gauges) const;

 private:
  struct Histogram {
    static constexpr std::array<double, 12> bounds{0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 5000};
    std::array<uint64_t, bounds.size() + 1> counts{};
    double sum = 0;
    uint64_t count = 0;
    void observe(double v);
  };
  mutable std::mutex m_;
  std::array<Histogram, 11> stages_;  // decode raycast preprocess icp orb fuse identify mapping total queue server
  mutable std::deque<std::chrono::steady_clock::time_point> recent_;
  std::atomic<uint64_t> frames_{0}, dropped_{0}, rejected_{0}, created_{0};
};

// GET /metrics on 0.0.0.0:port in its own thread (cpp-httplib). Throws std::runtime_error when the
// port cannot be bound or the build has no cpp-httplib.
class MetricsHttpServer {
 public:
  MetricsHttpServer(int port, std::function<std::string()> text);
  ~MetricsHttpServer();
  int port() const { return port_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
};

}  // namespace rrg::server
