#include "render/output/serial_task_queue.h"

#include <algorithm>
#include <utility>

namespace render {

SerialTaskQueue::SerialTaskQueue(SerialTaskQueueOptions options) : options_(options) {
  options_.max_queued = std::max(options_.max_queued, 1);
  worker_ = std::thread([this] { WorkerLoop(); });
}

SerialTaskQueue::~SerialTaskQueue() { (void)Finish(); }

base::Status SerialTaskQueue::Submit(Task task) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (finished_) {
    return base::InvalidArgument("task submitted after the queue finished");
  }
  slot_free_.wait(lock, [&] { return pending_ < options_.max_queued || first_error_; });
  if (first_error_) return *first_error_;
  queue_.push_back(std::move(task));
  ++pending_;
  peak_pending_ = std::max(peak_pending_, pending_);
  work_ready_.notify_one();
  return base::Status::Ok();
}

base::Status SerialTaskQueue::Finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!finished_) {
      finished_ = true;
      stopping_ = true;
      work_ready_.notify_all();
    }
  }
  if (worker_.joinable()) worker_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  if (first_error_) return *first_error_;
  return base::Status::Ok();
}

int SerialTaskQueue::peak_pending() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return peak_pending_;
}

void SerialTaskQueue::WorkerLoop() {
  for (;;) {
    Task task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_ready_.wait(lock, [&] { return !queue_.empty() || stopping_; });
      if (queue_.empty()) return;  // stopping and drained
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    // After a failure the remaining tasks are dropped, not run: they would
    // feed an encoder that is already in error.
    bool failed;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      failed = first_error_.has_value();
    }
    base::Status status = failed ? base::Status::Ok() : task();
    task = nullptr;  // release what the task holds (a frame) before freeing its slot
    std::lock_guard<std::mutex> lock(mutex_);
    if (!status.ok() && !first_error_) first_error_ = status.error();
    --pending_;
    slot_free_.notify_all();
  }
}

}  // namespace render
