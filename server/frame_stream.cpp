// StreamFrames: one bidirectional call. Frames are decoded on gRPC's thread as they arrive and
// queued on the session's worker; results (from the worker, or from here for rejected frames) are
// written back one at a time in the order they are produced. The call ends OK once the client has
// half-closed and every queued frame has its result written.
#include "server/auth.h"
#include "server/service.h"
#include "server/status_error.h"

#include <spdlog/spdlog.h>

#include <deque>
#include <mutex>

namespace rrg::server {

namespace {

class FrameStream;

// The worker's handle on a stream: forwards results until the stream is gone.
class StreamSink final : public ResultSink {
 public:
  explicit StreamSink(FrameStream* s) : stream_(s) {}
  void deliver(v1::FrameResult r) override;
  void detach() {
    std::lock_guard lock(m_);
    stream_ = nullptr;
  }

 private:
  std::recursive_mutex m_;
  FrameStream* stream_;
};

class FrameStream final : public grpc::ServerBidiReactor<v1::Frame, v1::FrameResult> {
 public:
  FrameStream(grpc::CallbackServerContext* ctx, SessionManager& manager, Metrics& metrics)
      : ctx_(ctx), manager_(manager), metrics_(metrics), sink_(std::make_shared<StreamSink>(this)) {
    tag_server(ctx, manager);
    const std::string header = session_header(*ctx);
    if (!header.empty()) {
      try {
        attach(header);
      } catch (...) {
        finish(status_of(std::current_exception()));
        return;
      }
    }
    StartRead(&in_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client half-closed (or went away)
      {
        std::lock_guard lock(m_);
        reads_done_ = true;
      }
      pump();
      return;
    }
    if (!session_) {
      try {
        attach(in_.session_id());
      } catch (...) {
        finish(status_of(std::current_exception()));
        return;
      }
    }
    handle(in_);
    StartRead(&in_);
  }

  void OnWriteDone(bool ok) override {
    {
      std::lock_guard lock(m_);
      writing_ = false;
    }
    if (!ok) {
      finish(grpc::Status(grpc::StatusCode::CANCELLED, "client went away"));
      return;
    }
    pump();
  }

  void OnCancel() override { finish(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled")); }

  void OnDone() override {
    sink_->detach();
    if (session_) session_->stream_attached(-1);
    delete this;
  }

  // A result for the client. from_queue: it answers a frame this stream queued.
  void push(v1::FrameResult r, bool from_queue) {
    {
      std::lock_guard lock(m_);
      if (from_queue) --outstanding_;
      if (!finished_) out_.push_back(std::move(r));
    }
    pump();
  }

 private:
  void attach(const std::string& id) {
    session_ = manager_.authorize(*ctx_, id);
    session_->stream_attached(+1);
    spdlog::debug("session {}: frame stream opened from {}", session_->meta().id, ctx_->peer());
  }

  void reject(const v1::Frame& f, const grpc::Status& st) {
    metrics_.frame_rejected();
    v1::FrameResult r;
    r.set_id(f.id());
    r.set_timestamp(f.timestamp());
    r.mutable_error()->set_code(int(st.error_code()));
    r.mutable_error()->set_message(st.error_message());
    r.set_frames_dropped(session_->frames_dropped());
    spdlog::info("session {}: frame {} rejected: {}", session_->meta().id, f.id(), st.error_message());
    push(std::move(r), false);
  }

  void handle(const v1::Frame& f) {
    if (!f.session_id().empty() && f.session_id() != session_->meta().id) {
      reject(f, {grpc::StatusCode::INVALID_ARGUMENT,
                 "session_id: '" + f.session_id() + "' but this stream belongs to " + session_->meta().id});
      return;
    }
    DecodedFrame decoded;
    try {
      decoded = decode_frame(f, session_->session().config().K, session_->meta().depth_scale);
    } catch (...) {
      reject(f, status_of(std::current_exception()));
      return;
    }
    {
      std::lock_guard lock(m_);
      ++outstanding_;
    }
    try {
      session_->enqueue(std::move(decoded), sink_);
    } catch (...) {
      {
        std::lock_guard lock(m_);
        --outstanding_;
      }
      reject(f, status_of(std::current_exception()));
    }
  }

  // Starts the next write, or finishes when everything is written.
  void pump() {
    bool write = false, done = false;
    {
      std::lock_guard lock(m_);
      if (finished_ || writing_) return;
      if (!out_.empty()) {
        current_ = std::move(out_.front());
        out_.pop_front();
        writing_ = write = true;
      } else if (reads_done_ && outstanding_ == 0) {
        finished_ = done = true;
      }
    }
    if (write) StartWrite(&current_);
    if (done) Finish(grpc::Status::OK);
  }

  void finish(const grpc::Status& st) {
    {
      std::lock_guard lock(m_);
      if (finished_) return;
      finished_ = true;
    }
    Finish(st);
  }

  grpc::CallbackServerContext* ctx_;
  SessionManager& manager_;
  Metrics& metrics_;
  std::shared_ptr<StreamSink> sink_;
  std::shared_ptr<ManagedSession> session_;
  v1::Frame in_;

  std::mutex m_;
  std::deque<v1::FrameResult> out_;
  v1::FrameResult current_;
  int64_t outstanding_ = 0;
  bool reads_done_ = false, writing_ = false, finished_ = false;
};

void StreamSink::deliver(v1::FrameResult r) {
  std::lock_guard lock(m_);
  if (stream_) stream_->push(std::move(r), true);
}

}  // namespace

grpc::ServerBidiReactor<v1::Frame, v1::FrameResult>* make_frame_stream(grpc::CallbackServerContext* ctx,
                                                                       SessionManager& manager, Metrics& metrics) {
  return new FrameStream(ctx, manager, metrics);
}

}  // namespace rrg::server
