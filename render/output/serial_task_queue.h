#pragma once
// SerialTaskQueue: runs tasks one at a time, in the order they were submitted,
// on one background thread. `render` uses it for the preview video and the
// contact sheet, whose encoders must see frames in order, so that they run
// while the next frame renders instead of on the render loop's thread.
//
//   render::SerialTaskQueue side({.max_queued = 2});
//   auto frame = std::make_shared<const render::Image>(image);
//   if (Status s = side.Submit([&video, frame] { return video->AddFrame(*frame); }); !s) ...
//   if (Status s = side.Finish(); !s) ...
//
// Memory is bounded: Submit blocks while max_queued tasks wait or run. Errors:
// the first failing task's error is returned by the next Submit (which then
// queues nothing more: later tasks never run) and by Finish. A task must not
// call Submit on its own queue.

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "base/error.h"

namespace render {

struct SerialTaskQueueOptions {
  int max_queued = 2;  // tasks waiting or running at once, >= 1 (smaller values are raised to 1)
};

class SerialTaskQueue {
 public:
  using Task = std::function<base::Status()>;

  explicit SerialTaskQueue(SerialTaskQueueOptions options = {});
  ~SerialTaskQueue();  // Finish(); an error not yet returned is dropped
  SerialTaskQueue(const SerialTaskQueue&) = delete;
  SerialTaskQueue& operator=(const SerialTaskQueue&) = delete;

  // Queues `task`; blocks while max_queued tasks are pending. Returns the first
  // error of an earlier task (and then drops `task`), or an error after Finish.
  [[nodiscard]] base::Status Submit(Task task);

  // Runs every queued task (until one fails), stops the thread and returns the
  // first error or Ok. Calling it again returns the same status.
  [[nodiscard]] base::Status Finish();

  // Most tasks pending at once so far (<= max_queued; thread-safe).
  int peak_pending() const;

 private:
  void WorkerLoop();

  SerialTaskQueueOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable work_ready_;  // a task was queued or stopping_ was set
  std::condition_variable slot_free_;   // pending_ dropped or an error was recorded
  std::deque<Task> queue_;
  int pending_ = 0;  // queued + running
  int peak_pending_ = 0;
  bool stopping_ = false;
  bool finished_ = false;
  std::optional<base::Error> first_error_;
  std::thread worker_;
};

}  // namespace render
