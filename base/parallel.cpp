#include "base/parallel.h"

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace base {
namespace {

// Starts `threads - 1` threads for one call and joins them (the fallback).
void RunOnNewThreads(int threads, const std::function<void(int)>& fn) {
  std::vector<std::thread> started;
  started.reserve(static_cast<std::size_t>(threads - 1));
  for (int t = 1; t < threads; ++t) started.emplace_back([&fn, t] { fn(t); });
  try {
    fn(0);
  } catch (...) {
    for (std::thread& th : started) th.join();
    throw;
  }
  for (std::thread& th : started) th.join();
}

// Workers 1..n wait for a job; a job is published by bumping `generation_`,
// and worker t runs it when t < the job's thread count. One job at a time.
class Pool {
 public:
  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& w : workers_) w.join();
  }

  // False (and nothing run) when another job holds the pool.
  bool TryRun(int threads, const std::function<void(int)>& fn) {
    std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
    if (!busy.owns_lock()) return false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // A worker starts knowing the current generation, so it waits for the
      // job published below rather than missing it.
      while (static_cast<int>(workers_.size()) < threads - 1) {
        const int index = static_cast<int>(workers_.size()) + 1;
        workers_.emplace_back([this, index, seen = generation_] { Work(index, seen); });
      }
      job_ = &fn;
      job_threads_ = threads;
      pending_ = threads - 1;
      ++generation_;
    }
    wake_.notify_all();
    std::exception_ptr failure;
    try {
      fn(0);
    } catch (...) {
      failure = std::current_exception();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
    job_ = nullptr;
    lock.unlock();
    if (failure) std::rethrow_exception(failure);
    return true;
  }

 private:
  void Work(int index, std::uint64_t seen) {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      if (index >= job_threads_) continue;
      const std::function<void(int)>* job = job_;
      lock.unlock();
      (*job)(index);  // an exception here ends the process, as in a std::thread
      lock.lock();
      if (--pending_ == 0) done_.notify_one();
    }
  }

  std::mutex busy_;   // held by the caller for a whole job
  std::mutex mutex_;  // guards the fields below
  std::condition_variable wake_, done_;
  std::vector<std::thread> workers_;
  const std::function<void(int)>* job_ = nullptr;
  int job_threads_ = 0;
  int pending_ = 0;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
};

Pool& SharedPool() {
  static Pool pool;
  return pool;
}

}  // namespace

int ResolveThreads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

void RunOnThreads(int threads, const std::function<void(int)>& fn) {
  if (threads <= 1) {
    fn(0);
    return;
  }
  if (threads <= kMaxPoolThreads && SharedPool().TryRun(threads, fn)) return;
  RunOnNewThreads(threads, fn);
}

}  // namespace base
