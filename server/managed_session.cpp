#include "server/managed_session.h"

#include "client/lib/proto_convert.h"
#include "core/slam/mapping_schedule.h"
#include "server/status_error.h"
#include "server/view_encode.h"

#include <spdlog/spdlog.h>

#include <stdexcept>

namespace rrg::server {

namespace {
using Clock = std::chrono::steady_clock;
int64_t now_ns() { return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count(); }
double ms_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

void fill_timings(v1::StageTimings* t, const StageTimes& s, double queue_ms) {
  t->set_decode(s.decode);
  t->set_raycast(s.raycast);
  t->set_preprocess(s.preprocess);
  t->set_icp(s.icp);
  t->set_orb(s.orb);
  t->set_fuse(s.fuse);
  t->set_identify(s.identify);
  t->set_mapping(s.mapping);
  t->set_total(s.total);
  t->set_queue(queue_ms);
}
}  // namespace

ManagedSession::ManagedSession(SessionMeta meta, std::unique_ptr<Session> session, Metrics& metrics,
                               uint64_t frames_dropped)
    : meta_(std::move(meta)), session_(std::move(session)), metrics_(metrics), dropped_(frames_dropped) {
  const SessionStatus st = session_->status();
  last_queued_id_ = st.last_index;
  last_map_version_ = st.map_version;
  touch();
  worker_ = std::thread([this] { loop(); });
}

ManagedSession::~ManagedSession() { stop(false); }

void ManagedSession::set_token_sha256(std::string sha) {
  std::lock_guard lock(queue_mutex_);
  meta_.token_sha256 = std::move(sha);
}

void ManagedSession::touch() { last_activity_ns_ = now_ns(); }

double ManagedSession::idle_seconds() const { return double(now_ns() - last_activity_ns_.load()) * 1e-9; }

bool ManagedSession::busy() const {
  std::lock_guard lock(queue_mutex_);
  return processing_ || !queue_.empty() || streams_.load() > 0;
}

v1::FrameResult ManagedSession::dropped_result(const Item& item) const {
  v1::FrameResult r;
  r.set_id(uint64_t(item.frame.frame.index));
  r.set_timestamp(item.frame.frame.timestamp);
  r.set_dropped(true);
  r.set_frames_dropped(dropped_.load());
  r.set_note("dropped: the session's frame queue was full");
  return r;
}

void ManagedSession::enqueue(DecodedFrame frame, std::shared_ptr<ResultSink> sink) {
  touch();
  std::optional<Item> evicted;
  {
    std::lock_guard lock(queue_mutex_);
    if (stopping_) throw StatusError(grpc::StatusCode::UNAVAILABLE, "session " + meta_.id + " is closing");
    if (!over_budget_.empty()) throw exhausted(over_budget_);
    const int64_t id = frame.frame.index;
    if (id <= last_queued_id_)
      throw std::invalid_argument("id: " + std::to_string(id) + " is not above the last frame id " +
                                  std::to_string(last_queued_id_) + " of session " + meta_.id);
    last_queued_id_ = id;
    if (queue_.size() >= meta_.queue_capacity) {
      evicted = std::move(queue_.front());
      queue_.pop_front();
      dropped_++;
    }
    queue_.push_back({std::move(frame), std::move(sink), Clock::now()});
  }
  queue_cv_.notify_one();
  if (evicted) {
    metrics_.frame_dropped();
    spdlog::debug("session {}: queue full, dropped frame {}", meta_.id, evicted->frame.frame.index);
    evicted->sink->deliver(dropped_result(*evicted));
  }
}

void ManagedSession::loop() {
  for (;;) {
    Item item;
    {
      std::unique_lock lock(queue_mutex_);
      queue_cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty() || (stopping_ && !drain_)) break;
      item = std::move(queue_.front());
      queue_.pop_front();
      processing_ = true;
    }
    run_one(item);
    {
      std::lock_guard lock(queue_mutex_);
      processing_ = false;
    }
    queue_cv_.notify_all();
  }
  // Frames left when stopping without draining are reported as dropped.
  std::deque<Item> left;
  {
    std::lock_guard lock(queue_mutex_);
    left.swap(queue_);
  }
  for (Item& it : left) {
    dropped_++;
    metrics_.frame_dropped();
    it.sink->deliver(dropped_result(it));
  }
}

void ManagedSession::run_one(Item& item) {
  const auto t_start = Clock::now();
  const double queue_ms = ms_between(item.queued, t_start);
  v1::FrameResult r;
  r.set_id(uint64_t(item.frame.frame.index));
  r.set_timestamp(item.frame.frame.timestamp);
  try {
    std::lock_guard lock(process_mutex_);
    FrameReport report = session_->process(item.frame.frame);
    report.times.decode = item.frame.decode_ms;
    r.mutable_pose()->CopyFrom(service::to_proto(report.T_wc));
    r.set_state(service::to_proto(report.state));
    fill_timings(r.mutable_timings(), report.times, queue_ms);
    r.set_map_version(report.map_version);
    r.set_fused(report.fused);
    r.set_note(report.note);
    r.set_filled_pixels(uint32_t(report.filled_pixels));
    r.set_tracking_mask_pixels(uint32_t(report.tracking_mask_pixels));
    if (!item.frame.render.empty()) {
      const SessionView view = session_->render(session_->config().K, report.T_wc);
      *r.mutable_view() = encode_view(view, item.frame.render);
      r.mutable_view()->set_map_version(report.map_version);
    }
    const SessionStatus st = session_->status();
    if (const std::string over = meta_.budget.excess(st); !over.empty()) {
      std::lock_guard qlock(queue_mutex_);
      over_budget_ = "session " + meta_.id + " uses " + over;
      spdlog::warn("{}", over_budget_);
    }
    metrics_.frame_processed(report.times, queue_ms, item.frame.decode_ms + ms_between(item.queued, Clock::now()));

    v1::SessionEvent pose;
    pose.mutable_pose()->set_frame_id(r.id());
    pose.mutable_pose()->set_timestamp(r.timestamp());
    *pose.mutable_pose()->mutable_pose() = r.pose();
    pose.mutable_pose()->set_state(r.state());
    emit(pose);
    if (st.map_version != last_map_version_) {
      last_map_version_ = st.map_version;
      v1::SessionEvent map;
      map.mutable_map()->set_map_version(st.map_version);
      map.mutable_map()->set_base_gaussians(uint64_t(st.mapping.base_gaussians));
      map.mutable_map()->set_reflection_gaussians(uint64_t(st.mapping.reflection_gaussians));
      emit(map);
    }
  } catch (const std::invalid_argument& e) {  // the session refused the frame and is unchanged
    metrics_.frame_rejected();
    r.mutable_error()->set_code(int(grpc::StatusCode::INVALID_ARGUMENT));
    r.mutable_error()->set_message(e.what());
  } catch (const std::exception& e) {
    spdlog::error("session {}: frame {} failed: {}", meta_.id, r.id(), e.what());
    r.mutable_error()->set_code(int(grpc::StatusCode::INTERNAL));
    r.mutable_error()->set_message(e.what());
  }
  r.set_frames_dropped(dropped_.load());
  touch();
  item.sink->deliver(std::move(r));
}

void ManagedSession::with_worker_paused(const std::function<void(Session&)>& f) {
  std::lock_guard lock(process_mutex_);
  f(*session_);
}

void ManagedSession::stop(bool drain) {
  {
    std::lock_guard lock(queue_mutex_);
    if (stopping_) return;
    stopping_ = true;
    drain_ = drain;
  }
  queue_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  v1::SessionEvent closed;
  closed.set_closed(true);
  emit(closed);
}

void ManagedSession::emit(const v1::SessionEvent& e) {
  std::lock_guard lock(listeners_mutex_);
  for (auto& [id, f] : listeners_) f(e);
}

uint64_t ManagedSession::subscribe(std::function<void(const v1::SessionEvent&)> f) {
  std::lock_guard lock(listeners_mutex_);
  const uint64_t id = next_listener_++;
  listeners_.emplace(id, std::move(f));
  return id;
}

void ManagedSession::unsubscribe(uint64_t id) {
  std::lock_guard lock(listeners_mutex_);
  listeners_.erase(id);
}

v1::SessionInfo ManagedSession::info() const {
  const SessionStatus st = session_->status();
  v1::SessionInfo i;
  i.set_session_id(meta_.id);
  i.set_name(meta_.name);
  *i.mutable_intrinsics() = service::to_proto(session_->config().K);
  i.set_depth_scale(meta_.depth_scale);
  i.set_frames(uint64_t(st.frames));
  i.set_fused(uint64_t(st.fused));
  i.set_lost(uint64_t(st.lost));
  i.set_last_frame_id(st.last_index);
  i.set_state(service::to_proto(st.state));
  *i.mutable_pose() = service::to_proto(st.T_wc);
  i.set_map_version(st.map_version);
  i.set_tsdf_blocks(uint64_t(st.tsdf_blocks));
  i.set_tsdf_resident_blocks(uint64_t(st.resident_blocks));
  i.set_keyframes(uint64_t(st.keyframes));
  i.set_global_planes(uint64_t(st.global_planes));
  for (int p : st.reflective_planes) i.add_reflective_planes(p);
  i.set_base_gaussians(uint64_t(st.mapping.base_gaussians));
  i.set_reflection_gaussians(uint64_t(st.mapping.reflection_gaussians));
  i.set_mapping_steps(uint64_t(st.mapping.steps));
  i.set_device_bytes(st.device_bytes);
  i.set_host_bytes(st.host_bytes);
  i.set_frames_dropped(dropped_.load());
  {
    std::lock_guard lock(queue_mutex_);
    i.set_queue_depth(uint32_t(queue_.size()));
  }
  i.set_queue_capacity(uint32_t(meta_.queue_capacity));
  i.set_idle_seconds(idle_seconds());
  i.set_device(session_->config().device.to_string());
  i.set_schedule(to_string(session_->config().schedule()));
  return i;
}

}  // namespace rrg::server
