// The fork-join pool (base/parallel.h): every index runs once and concurrently,
// the pool's threads are reused, and calls it cannot take (nested, from two
// threads at once, more threads than the pool holds) still finish.

#include "base/parallel.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace {

// Waits until `count` threads have arrived, or fails after 10 s (a loop that
// ran its indices one after another would never get them all here at once).
class Rendezvous {
 public:
  explicit Rendezvous(int count) : count_(count) {}
  bool Arrive() {
    arrived_.fetch_add(1);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (arrived_.load() < count_) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::yield();
    }
    return true;
  }

 private:
  int count_;
  std::atomic<int> arrived_{0};
};

TEST(Parallel, EveryIndexRunsOnceAndAllAtOnce) {
  for (int threads : {1, 2, 3, 8}) {
    std::vector<std::atomic<int>> calls(static_cast<std::size_t>(threads));
    Rendezvous all(threads);
    std::atomic<int> late{0};
    base::RunOnThreads(threads, [&](int t) {
      calls[static_cast<std::size_t>(t)].fetch_add(1);
      if (!all.Arrive()) late.fetch_add(1);
    });
    for (int t = 0; t < threads; ++t) EXPECT_EQ(calls[static_cast<std::size_t>(t)].load(), 1);
    EXPECT_EQ(late.load(), 0) << threads << " threads did not run concurrently";
  }
}

TEST(Parallel, IndexZeroRunsOnTheCaller) {
  std::thread::id zero;
  base::RunOnThreads(4, [&](int t) {
    if (t == 0) zero = std::this_thread::get_id();
  });
  EXPECT_EQ(zero, std::this_thread::get_id());
}

TEST(Parallel, ThePoolsThreadsAreReused) {
  auto ids_of_a_call = [] {
    std::mutex m;
    std::set<std::thread::id> ids;
    base::RunOnThreads(4, [&](int t) {
      if (t == 0) return;
      std::lock_guard<std::mutex> lock(m);
      ids.insert(std::this_thread::get_id());
    });
    return ids;
  };
  const std::set<std::thread::id> first = ids_of_a_call();
  ASSERT_EQ(first.size(), 3u);
  EXPECT_EQ(ids_of_a_call(), first);  // threads started per call would have new ids
}

TEST(Parallel, ANestedCallFinishes) {
  std::atomic<int> inner{0};
  base::RunOnThreads(3, [&](int) { base::RunOnThreads(3, [&](int) { inner.fetch_add(1); }); });
  EXPECT_EQ(inner.load(), 9);
}

TEST(Parallel, CallsFromTwoThreadsAtOnceBothFinish) {
  std::atomic<long> sum_a{0}, sum_b{0};
  auto run = [](std::atomic<long>& sum) {
    for (int round = 0; round < 200; ++round) {
      base::ParallelForDynamic(64, 4, [&](int i, int) { sum.fetch_add(i); });
    }
  };
  std::thread other([&] { run(sum_b); });
  run(sum_a);
  other.join();
  EXPECT_EQ(sum_a.load(), 200L * (63 * 64 / 2));
  EXPECT_EQ(sum_b.load(), 200L * (63 * 64 / 2));
}

TEST(Parallel, MoreThreadsThanThePoolHolds) {
  const int threads = base::kMaxPoolThreads + 3;
  std::vector<std::atomic<int>> calls(static_cast<std::size_t>(threads));
  base::RunOnThreads(threads, [&](int t) { calls[static_cast<std::size_t>(t)].fetch_add(1); });
  for (int t = 0; t < threads; ++t) EXPECT_EQ(calls[static_cast<std::size_t>(t)].load(), 1);
}

TEST(Parallel, DynamicLoopCoversEveryItemOnce) {
  for (int count : {0, 1, 5, 1000}) {
    std::vector<std::atomic<int>> seen(static_cast<std::size_t>(count));
    std::atomic<int> bad_thread{0};
    base::ParallelForDynamic(count, 3, [&](int i, int thread) {
      seen[static_cast<std::size_t>(i)].fetch_add(1);
      if (thread < 0 || thread >= 3) bad_thread.fetch_add(1);
    });
    for (int i = 0; i < count; ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)].load(), 1) << i;
    EXPECT_EQ(bad_thread.load(), 0);
  }
}

TEST(Parallel, TheCallersExceptionArrivesAfterTheOthersFinish) {
  std::atomic<int> finished{0};
  EXPECT_THROW(base::RunOnThreads(3,
                                  [&](int t) {
                                    if (t == 0) throw std::runtime_error("index 0");
                                    std::this_thread::sleep_for(std::chrono::milliseconds(20));
                                    finished.fetch_add(1);
                                  }),
               std::runtime_error);
  EXPECT_EQ(finished.load(), 2);
  // The pool takes the next job as usual.
  std::atomic<int> calls{0};
  base::RunOnThreads(3, [&](int) { calls.fetch_add(1); });
  EXPECT_EQ(calls.load(), 3);
}

TEST(Parallel, ResolveThreads) {
  EXPECT_GE(base::ResolveThreads(0), 1);
  EXPECT_GE(base::ResolveThreads(-2), 1);
  EXPECT_EQ(base::ResolveThreads(5), 5);
}

}  // namespace
