// SerialTaskQueue: order, the bound on pending tasks, errors.

#include "render/output/serial_task_queue.h"

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace {

TEST(SerialTaskQueue, RunsTasksOneAtATimeInSubmissionOrder) {
  std::vector<int> order;  // touched only by the worker, read after Finish
  std::atomic<int> running{0};
  std::atomic<int> overlap{0};
  render::SerialTaskQueue queue({.max_queued = 3});
  for (int i = 0; i < 50; ++i) {
    ASSERT_TRUE(queue.Submit([&, i] {
      if (running.fetch_add(1) != 0) overlap.fetch_add(1);
      if (i % 7 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      order.push_back(i);
      running.fetch_sub(1);
      return base::Status::Ok();
    }).ok());
  }
  ASSERT_TRUE(queue.Finish().ok());
  ASSERT_EQ(order.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(order[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(overlap.load(), 0);
  EXPECT_LE(queue.peak_pending(), 3);
  EXPECT_GE(queue.peak_pending(), 1);
}

TEST(SerialTaskQueue, SubmitBlocksWhileTheQueueIsFull) {
  std::atomic<bool> release{false};
  render::SerialTaskQueue queue({.max_queued = 2});
  const auto wait = [&] {
    while (!release.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return base::Status::Ok();
  };
  ASSERT_TRUE(queue.Submit(wait).ok());
  ASSERT_TRUE(queue.Submit(wait).ok());
  std::atomic<bool> third_queued{false};
  std::thread submitter([&] {
    EXPECT_TRUE(queue.Submit([] { return base::Status::Ok(); }).ok());
    third_queued = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(third_queued.load());  // two pending: the third waits for a slot
  release = true;
  submitter.join();
  EXPECT_TRUE(third_queued.load());
  ASSERT_TRUE(queue.Finish().ok());
  EXPECT_EQ(queue.peak_pending(), 2);
}

TEST(SerialTaskQueue, FirstErrorStopsLaterTasksAndIsReturnedByFinish) {
  std::atomic<int> ran{0};
  render::SerialTaskQueue queue({.max_queued = 1});
  base::Status last = base::Status::Ok();
  for (int i = 0; i < 10 && last.ok(); ++i) {
    last = queue.Submit([&, i]() -> base::Status {
      ran.fetch_add(1);
      if (i == 3)
        return base::MakeError(base::ErrorCode::kIo, {"video.mp4", 0, 0, {}}, "disk full");
      return base::Status::Ok();
    });
  }
  // With one slot, the submission after task 3 fails waits until task 3 ran.
  ASSERT_FALSE(last.ok());
  EXPECT_EQ(last.error().code, base::ErrorCode::kIo);
  const base::Status finished = queue.Finish();
  ASSERT_FALSE(finished.ok());
  EXPECT_NE(finished.error().ToString().find("disk full"), std::string::npos);
  EXPECT_EQ(ran.load(), 4);  // tasks 0..3; nothing after the failure ran
  EXPECT_FALSE(queue.Submit([] { return base::Status::Ok(); }).ok());  // after Finish
}

}  // namespace
