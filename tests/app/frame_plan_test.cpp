// FramePlan::count() and At() (issue 8): a render walks its output frames one
// at a time instead of listing them, so they must be exactly the listed
// frames, for steps, resampling (--fps) and turntables; and an unlisted plan
// of an hour-long capture holds nothing per frame.

#include <gtest/gtest.h>

#include "app/frame_plan.h"
#include "mocap/motion.h"

namespace {

mocap::Motion TimingOnly(int num_frames, double frame_time_s) {
  mocap::Motion m;
  m.num_frames = num_frames;
  m.num_channels = 0;  // timing only
  m.frame_time_s = frame_time_s;
  return m;
}

TEST(FramePlan, AtGivesTheListedFrames) {
  const mocap::Motion motion = TimingOnly(1000, 1.0 / 120.0);
  const app::FramePlanOptions cases[] = {
      {.frames = ""},
      {.frames = "10:990:7"},
      {.frames = "5"},
      {.frames = "0:999:1000"},
      {.frames = ":100", .fps = 30.0},
      {.frames = "3", .turntable = true, .turntable_frames = 36},
  };
  for (const app::FramePlanOptions& o : cases) {
    const base::Result<app::FramePlan> listed = app::PlanFrames(motion, o);
    ASSERT_TRUE(listed.ok()) << listed.error().ToString();
    app::FramePlanOptions lazy = o;
    lazy.list_frames = false;
    const base::Result<app::FramePlan> walked = app::PlanFrames(motion, lazy);
    ASSERT_TRUE(walked.ok());
    EXPECT_TRUE(walked->frames.empty()) << o.frames;
    ASSERT_EQ(walked->count(), listed->frames.size()) << o.frames;
    ASSERT_EQ(listed->count(), listed->frames.size()) << o.frames;
    for (std::size_t i = 0; i < listed->frames.size(); ++i) {
      const app::OutputFrame a = walked->At(i), b = listed->frames[i];
      EXPECT_EQ(a.number, b.number) << o.frames << " frame " << i;
      EXPECT_EQ(a.time_s, b.time_s) << o.frames << " frame " << i;
      EXPECT_EQ(a.camera, b.camera) << o.frames << " frame " << i;
    }
  }
}

TEST(FramePlan, AnHourAt120FpsIsCountedNotListed) {
  const mocap::Motion motion = TimingOnly(432000, 1.0 / 120.0);
  const base::Result<app::FramePlan> plan =
      app::PlanFrames(motion, {.frames = "1:431999:2", .list_frames = false});
  ASSERT_TRUE(plan.ok());
  EXPECT_TRUE(plan->frames.empty());
  EXPECT_EQ(plan->count(), 216000u);  // 1, 3, ..., 431999
  const app::OutputFrame last = plan->At(plan->count() - 1);
  EXPECT_EQ(last.number, 431999);
  EXPECT_EQ(last.time_s, 431999 * (1.0 / 120.0));
}

}  // namespace
