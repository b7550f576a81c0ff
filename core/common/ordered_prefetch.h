#pragma once
// Items 0..n-1 of a sequence produced ahead of their consumer on background threads and handed out
// in order (`rrg run` decodes the next frames while the session processes this one). At most
// `ahead` items are produced beyond the last one taken, so memory stays bounded. An exception
// thrown while producing item i is rethrown by the next() that would return item i, not earlier:
// the items before it are still processed, as with a plain loop. The destructor stops the threads
// (each finishes the item it is producing) and joins them.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

namespace rrg {

template <class T>
class OrderedPrefetch {
 public:
  using Produce = std::function<T(size_t)>;

  // produce(i) must be callable from several threads at once (threads >= 1, ahead >= 1).
  OrderedPrefetch(Produce produce, size_t n, size_t ahead, size_t threads)
      : produce_(std::move(produce)), n_(n), ahead_(ahead), slots_(ahead) {
    if (ahead == 0 || threads == 0) throw std::invalid_argument("OrderedPrefetch: ahead and threads must be >= 1");
    for (size_t t = 0; t < threads; ++t) workers_.emplace_back([this] { work(); });
  }
  ~OrderedPrefetch() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    for (std::thread& w : workers_) w.join();
  }
  OrderedPrefetch(const OrderedPrefetch&) = delete;
  OrderedPrefetch& operator=(const OrderedPrefetch&) = delete;

  // The next item in order (waits for it); rethrows the exception its production threw. Throws
  // std::out_of_range after the n-th item.
  T next() {
    std::unique_lock lock(mutex_);
    if (taken_ >= n_) throw std::out_of_range("OrderedPrefetch: all " + std::to_string(n_) + " items taken");
    Slot& s = slots_[taken_ % ahead_];
    const auto t0 = std::chrono::steady_clock::now();
    cv_.wait(lock, [&] { return s.ready; });
    wait_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    s.ready = false;
    ++taken_;
    std::optional<T> item = std::move(s.item);
    const std::exception_ptr error = s.error;
    s.item.reset();
    s.error = nullptr;
    lock.unlock();
    cv_.notify_all();  // a slot is free: a worker may start the next item
    if (error) std::rethrow_exception(error);
    return std::move(*item);
  }

  // Milliseconds next() has waited in all, and the producers have spent producing (all threads).
  double wait_ms() const {
    std::lock_guard lock(mutex_);
    return wait_ms_;
  }
  double produce_ms() const {
    std::lock_guard lock(mutex_);
    return produce_ms_;
  }

 private:
  struct Slot {
    bool ready = false;
    std::optional<T> item;
    std::exception_ptr error;
  };

  void work() {
    std::unique_lock lock(mutex_);
    for (;;) {
      cv_.wait(lock, [&] { return stop_ || (started_ < n_ && started_ < taken_ + ahead_); });
      if (stop_) return;
      const size_t i = started_++;
      lock.unlock();
      std::optional<T> item;
      std::exception_ptr error;
      const auto t0 = std::chrono::steady_clock::now();
      try {
        item.emplace(produce_(i));
      } catch (...) {
        error = std::current_exception();
      }
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      lock.lock();
      Slot& s = slots_[i % ahead_];  // free: item i - ahead was taken before i was started
      s.item = std::move(item);
      s.error = error;
      s.ready = true;
      produce_ms_ += ms;
      cv_.notify_all();
    }
  }

  Produce produce_;
  const size_t n_, ahead_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Slot> slots_;
  size_t started_ = 0, taken_ = 0;
  bool stop_ = false;
  double wait_ms_ = 0, produce_ms_ = 0;
  std::vector<std::thread> workers_;  // last: started after every other member exists
};

}  // namespace rrg
