#pragma once
// Minimal fork-join helpers over std::thread. Work items are independent and
// each writes only its own outputs, so results never depend on the thread count.

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace render::internal {

// Resolves 0 to the hardware thread count; always >= 1.
inline int ResolveThreads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

// Calls fn(thread_index) on `threads` threads (the caller's thread is index 0).
template <class Fn>
void RunOnThreads(int threads, Fn&& fn) {
  if (threads <= 1) {
    fn(0);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(threads - 1));
  for (int t = 1; t < threads; ++t) pool.emplace_back([&fn, t] { fn(t); });
  fn(0);
  for (std::thread& th : pool) th.join();
}

// Calls fn(item, thread_index) for item in [0, count), items handed out
// dynamically; the assignment of items to threads is not deterministic.
template <class Fn>
void ParallelForDynamic(int count, int threads, Fn&& fn) {
  std::atomic<int> next{0};
  RunOnThreads(std::min(threads, std::max(count, 1)), [&](int thread) {
    for (int i = next.fetch_add(1); i < count; i = next.fetch_add(1)) fn(i, thread);
  });
}

}  // namespace render::internal
