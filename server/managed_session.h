#pragma once
// One live session inside the server: the core Session, the worker thread that alone calls
// Session::process() (DESIGN.md §1), and the bounded frame queue in front of it. When the queue is
// full the OLDEST unprocessed frame is dropped (its stream gets a FrameResult with dropped = true)
// so a slow session never grows memory and always works on the freshest frames; every FrameResult
// carries the session's frames_dropped. Results go back to the stream that sent the frame (a
// ResultSink); pose and map-version events go to every watcher.
#include "core/slam/session.h"
#include "rrg/v1/service.pb.h"
#include "server/frame_decode.h"
#include "server/memory_budget.h"
#include "server/metrics.h"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace rrg::server {

// What the service keeps about a session beside the core Session (and writes beside its snapshot).
struct SessionMeta {
  std::string id, name;
  std::string token_sha256;   // the bearer token's SHA-256 (the token itself is never stored)
  float depth_scale = 1000.0f;
  size_t queue_capacity = 8;
  MemoryBudget budget;        // the server's per-session limits (a session over them refuses frames)
};

// Receives the FrameResults of the frames one stream sent. deliver() is called from the worker
// thread (and from the stream's own thread for rejected frames).
class ResultSink {
 public:
  virtual ~ResultSink() = default;
  virtual void deliver(v1::FrameResult result) = 0;
};

class ManagedSession {
 public:
  ManagedSession(SessionMeta meta, std::unique_ptr<Session> session, Metrics& metrics, uint64_t frames_dropped = 0);
  ~ManagedSession();  // stop(false)
  ManagedSession(const ManagedSession&) = delete;
  ManagedSession& operator=(const ManagedSession&) = delete;

  const SessionMeta& meta() const { return meta_; }
  const Session& session() const { return *session_; }
  void set_token_sha256(std::string sha);

  // Queues a decoded frame. Throws std::invalid_argument("id: ...") when the id is not above the
  // last queued one, StatusError(RESOURCE_EXHAUSTED) over the memory budget, StatusError
  // (UNAVAILABLE) when the session is closing. A full queue drops its oldest frame first.
  void enqueue(DecodedFrame frame, std::shared_ptr<ResultSink> sink);

  // Runs f with the worker paused between frames (snapshots, Close).
  void with_worker_paused(const std::function<void(Session&)>& f);
  // Stops the worker: processes what is queued first when drain, else drops it (reported).
  void stop(bool drain);

  v1::SessionInfo info() const;
  uint64_t frames_dropped() const { return dropped_.load(); }
  void touch();                  // a call used the session now
  double idle_seconds() const;   // since the last call / frame
  bool busy() const;             // frames queued or being processed, or a stream attached
  void stream_attached(int delta) { streams_ += delta; }

  // Events (pose per frame, map version when it changes, closed at the end) to `f` until
  // unsubscribe() returns; f runs on the worker thread and must not block.
  uint64_t subscribe(std::function<void(const v1::SessionEvent&)> f);
  void unsubscribe(uint64_t id);

 private:
  struct Item {
    DecodedFrame frame;
    std::shared_ptr<ResultSink> sink;
    std::chrono::steady_clock::time_point queued;
  };
  void loop();
  void run_one(Item& item);
  void emit(const v1::SessionEvent& e);
  v1::FrameResult dropped_result(const Item& item) const;

  SessionMeta meta_;
  std::unique_ptr<Session> session_;
  Metrics& metrics_;

  mutable std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<Item> queue_;
  int64_t last_queued_id_ = -1;
  bool processing_ = false, stopping_ = false, drain_ = true;
  std::string over_budget_;  // reason, once the memory budget is exceeded

  std::mutex process_mutex_;  // held while a frame is processed; pauses the worker for snapshots
  std::atomic<uint64_t> dropped_{0};
  std::atomic<int> streams_{0};
  std::atomic<int64_t> last_activity_ns_{0};
  uint64_t last_map_version_ = 0;

  mutable std::mutex listeners_mutex_;
  std::map<uint64_t, std::function<void(const v1::SessionEvent&)>> listeners_;
  uint64_t next_listener_ = 1;

  std::thread worker_;
};

}  // namespace rrg::server
