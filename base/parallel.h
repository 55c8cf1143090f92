#pragma once
// Fork-join loops for the jobs that split their work: the renderer's tiles and
// bands, the frame pipeline's vertex ranges. Work items are independent and each
// writes only its own outputs, so results never depend on the thread count.
//
// The threads come from one process-wide pool, started on first use and grown
// to the largest count asked for (at most kMaxPoolThreads), so a frame does not
// start and join threads for every stage. A call made while the pool is busy
// (from another thread, or from inside a loop) or asking for more threads runs
// on threads started for it alone: slower, never blocked.

#include <algorithm>
#include <atomic>
#include <functional>

namespace base {

inline constexpr int kMaxPoolThreads = 64;

// Resolves 0 (or less) to the hardware thread count; always >= 1.
int ResolveThreads(int threads);

// Calls fn(t) for t in [0, threads) concurrently (t = 0 on the calling thread)
// and returns when every call has returned. threads <= 1 calls fn(0) only.
void RunOnThreads(int threads, const std::function<void(int)>& fn);

// Calls fn(item, thread) for item in [0, count) on up to `threads` threads,
// items handed out one at a time as threads come free (which thread takes
// which item varies from run to run).
template <class Fn>
void ParallelForDynamic(int count, int threads, Fn&& fn) {
  std::atomic<int> next{0};
  RunOnThreads(std::min(threads, std::max(count, 1)), [&](int thread) {
    for (int i = next.fetch_add(1); i < count; i = next.fetch_add(1)) fn(i, thread);
  });
}

}  // namespace base
