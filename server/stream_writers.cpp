// The server-streaming reactors: one encoded file in chunks (GetMesh, GetGaussians) and a
// session's event feed (WatchSession).
#include "server/service.h"

#include <spdlog/spdlog.h>

#include <deque>
#include <mutex>

namespace rrg::server {

namespace {

class ChunkWriter final : public grpc::ServerWriteReactor<v1::DataChunk> {
 public:
  ChunkWriter(std::string data, size_t chunk_bytes, const v1::DataChunk& header)
      : data_(std::move(data)), chunk_(chunk_bytes), header_(header) {
    header_.set_total_bytes(data_.size());
    next();
  }
  void OnWriteDone(bool ok) override {
    if (!ok) {
      Finish(grpc::Status(grpc::StatusCode::CANCELLED, "client went away"));
      return;
    }
    next();
  }
  void OnDone() override { delete this; }

 private:
  void next() {
    if (started_ && offset_ >= data_.size()) {
      Finish(grpc::Status::OK);
      return;
    }
    started_ = true;
    out_ = header_;
    out_.set_offset(offset_);
    const size_t n = std::min(chunk_, data_.size() - offset_);
    out_.set_data(data_.substr(offset_, n));
    offset_ += n;
    StartWrite(&out_);
  }
  std::string data_;
  size_t chunk_, offset_ = 0;
  bool started_ = false;
  v1::DataChunk header_, out_;
};

class EventWriter final : public grpc::ServerWriteReactor<v1::SessionEvent> {
 public:
  explicit EventWriter(std::shared_ptr<ManagedSession> s) : session_(std::move(s)) {
    listener_ = session_->subscribe([this](const v1::SessionEvent& e) { push(e); });
  }
  void OnWriteDone(bool ok) override {
    bool finish = false, write_next = false;
    {
      std::lock_guard lock(m_);
      if (!ok) {
        finish = !finished_;
        finished_ = true;
      } else if (queue_.empty()) {
        writing_ = false;
        finish = closed_ && !finished_;
        if (finish) finished_ = true;
      } else if (!finished_) {
        current_ = std::move(queue_.front());
        queue_.pop_front();
        write_next = true;
      }
    }
    if (finish)
      Finish(ok ? grpc::Status::OK : grpc::Status(grpc::StatusCode::CANCELLED, "client went away"));
    else if (write_next)
      StartWrite(&current_);
  }
  void OnCancel() override {
    {
      std::lock_guard lock(m_);
      if (finished_) return;
      finished_ = true;
    }
    Finish(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled"));
  }
  void OnDone() override {
    session_->unsubscribe(listener_);
    delete this;
  }

 private:
  void push(const v1::SessionEvent& e) {  // on the session's worker thread
    bool start = false;
    {
      std::lock_guard lock(m_);
      if (finished_ || closed_) return;
      if (e.has_closed()) closed_ = true;
      if (queue_.size() >= 1024) queue_.pop_front();  // a stalled watcher never grows memory
      queue_.push_back(e);
      if (!writing_) {
        writing_ = start = true;
        current_ = std::move(queue_.front());
        queue_.pop_front();
      }
    }
    if (start) StartWrite(&current_);
  }

  std::shared_ptr<ManagedSession> session_;
  uint64_t listener_ = 0;
  std::mutex m_;
  std::deque<v1::SessionEvent> queue_;
  v1::SessionEvent current_;
  bool writing_ = false, closed_ = false, finished_ = false;
};

}  // namespace

grpc::ServerWriteReactor<v1::DataChunk>* make_chunk_writer(std::string data, size_t chunk_bytes,
                                                           const v1::DataChunk& header) {
  return new ChunkWriter(std::move(data), std::max<size_t>(chunk_bytes, 1024), header);
}

grpc::ServerWriteReactor<v1::SessionEvent>* make_event_writer(std::shared_ptr<ManagedSession> session) {
  return new EventWriter(std::move(session));
}

}  // namespace rrg::server
