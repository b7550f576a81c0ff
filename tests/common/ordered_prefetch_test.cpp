// OrderedPrefetch: items in order from several producer threads, a bounded look-ahead, errors at
// their own item, and a destructor that stops with items never taken.
#include "core/common/ordered_prefetch.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

namespace rrg {
namespace {

// Uneven production times, so that later items often finish before earlier ones.
void jitter(size_t i) { std::this_thread::sleep_for(std::chrono::microseconds((i * 7919) % 5 * 300)); }

TEST(OrderedPrefetch, HandsOutEveryItemInOrderFromSeveralThreads) {
  for (const size_t threads : {1, 2, 4})
    for (const size_t ahead : {1, 3, 8}) {
      SCOPED_TRACE("threads " + std::to_string(threads) + " ahead " + std::to_string(ahead));
      OrderedPrefetch<std::string> p(
          [](size_t i) {
            jitter(i);
            return "item " + std::to_string(i);
          },
          40, ahead, threads);
      for (size_t i = 0; i < 40; ++i) EXPECT_EQ(p.next(), "item " + std::to_string(i));
      EXPECT_THROW(p.next(), std::out_of_range);
    }
}

TEST(OrderedPrefetch, NeverProducesMoreThanAheadBeyondTheLastTaken) {
  constexpr size_t kAhead = 3;
  std::atomic<size_t> taken{0}, worst{0};
  OrderedPrefetch<size_t> p(
      [&](size_t i) {
        const size_t beyond = i - taken.load();  // items started past the last one taken
        size_t w = worst.load();
        while (beyond > w && !worst.compare_exchange_weak(w, beyond)) {}
        jitter(i);
        return i;
      },
      30, kAhead, 4);
  for (size_t i = 0; i < 30; ++i) {
    std::this_thread::sleep_for(std::chrono::microseconds(500));  // a slow consumer: producers run ahead
    EXPECT_EQ(p.next(), i);
    taken = i + 1;
  }
  // Item k + ahead may start once next() has handed out item k, a moment before this loop counts
  // it as taken: the furthest seen is ahead, and a slow consumer lets the producers get that far.
  EXPECT_LE(worst.load(), kAhead);
  EXPECT_GE(worst.load(), kAhead - 1);
}

TEST(OrderedPrefetch, AnErrorSurfacesAtItsOwnItemAndLaterItemsStillCome) {
  OrderedPrefetch<int> p(
      [](size_t i) {
        jitter(i);
        if (i == 5) throw std::runtime_error("frame 5 is unreadable");
        return int(i);
      },
      10, 4, 3);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(p.next(), i);
  try {
    p.next();
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "frame 5 is unreadable");
  }
  for (int i = 6; i < 10; ++i) EXPECT_EQ(p.next(), i);
}

TEST(OrderedPrefetch, StopsWithItemsNeverTaken) {
  std::atomic<size_t> produced{0};
  {
    OrderedPrefetch<int> p(
        [&](size_t i) {
          ++produced;
          return int(i);
        },
        1000, 4, 2);
    EXPECT_EQ(p.next(), 0);
    EXPECT_EQ(p.next(), 1);
  }  // the destructor must not wait for (or produce) the other 998
  EXPECT_LE(produced.load(), 2u + 4u);
}

TEST(OrderedPrefetch, CountsTheTimeProducedAndWaited) {
  OrderedPrefetch<int> p(
      [](size_t i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        return int(i);
      },
      5, 2, 1);
  for (int i = 0; i < 5; ++i) p.next();
  EXPECT_GE(p.produce_ms(), 5 * 2.0);
  EXPECT_GT(p.wait_ms(), 0.0);  // the first item cannot have been ready at once
}

TEST(OrderedPrefetch, RejectsZeroThreadsOrLookAhead) {
  const auto produce = [](size_t i) { return int(i); };
  EXPECT_THROW(OrderedPrefetch<int>(produce, 3, 0, 1), std::invalid_argument);
  EXPECT_THROW(OrderedPrefetch<int>(produce, 3, 1, 0), std::invalid_argument);
}

}  // namespace
}  // namespace rrg
