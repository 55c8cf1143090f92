// The two-half parse of large frame data (BvhReadOptions::parallel_min_bytes)
// must give exactly what the sequential pass gives: the same values to the
// bit on a clean file, and the same error or warning, word for word, when
// something is wrong in either half (it falls back to the sequential pass).

#include <cstdint>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"
#include "mocap/bvh_writer.h"
#include "support/long_capture.h"

namespace {

// A 120 fps walk of `frames` frames as BVH text (testsupport::LongCaptureText).
std::string WalkText(int frames) {
  std::string text = testsupport::LongCaptureText(frames);
  EXPECT_FALSE(text.empty());
  return text;
}

mocap::BvhReadOptions Halves() {
  mocap::BvhReadOptions o;
  o.parallel_min_bytes = 1;  // every file with frame data takes the two-half path
  return o;
}

mocap::BvhReadOptions Sequential() {
  mocap::BvhReadOptions o;
  o.parallel_min_bytes = std::numeric_limits<std::size_t>::max();
  return o;
}

// Replaces the first occurrence of `what` after byte `from` of the text.
std::string Edit(std::string text, std::size_t from, const std::string& what,
                 const std::string& with) {
  const std::size_t at = text.find(what, from);
  EXPECT_NE(at, std::string::npos);
  return text.replace(at, what.size(), with);
}

TEST(BvhParallelRead, HalvesGiveTheSequentialValuesToTheBit) {
  for (const int frames : {1, 2, 3, 1000}) {
    const std::string text = WalkText(frames);
    const auto a = mocap::ParseBvh(text, "walk.bvh", Halves());
    const auto b = mocap::ParseBvh(text, "walk.bvh", Sequential());
    ASSERT_TRUE(a.ok()) << a.error().ToString();
    ASSERT_TRUE(b.ok()) << b.error().ToString();
    EXPECT_EQ(a->motion.num_frames, frames);
    EXPECT_EQ(a->motion.num_frames, b->motion.num_frames);
    ASSERT_EQ(a->motion.values.size(), b->motion.values.size());
    for (std::size_t i = 0; i < a->motion.values.size(); ++i) {
      ASSERT_EQ(std::bit_cast<std::uint32_t>(a->motion.values[i]),
                std::bit_cast<std::uint32_t>(b->motion.values[i]))
          << "value " << i << " of " << frames << " frames";
    }
    EXPECT_EQ(a->warnings.size(), b->warnings.size());
  }
}

TEST(BvhParallelRead, TheDefaultThresholdTakesLargeFilesInHalves) {
  // ~10 MB of frame data: above the 8 MiB default, so the default options
  // parse it in halves; the result equals the sequential pass.
  const std::string text = WalkText(20000);
  ASSERT_GT(text.size(), std::size_t{8} << 20);
  const auto a = mocap::ParseBvh(text, "long.bvh");
  const auto b = mocap::ParseBvh(text, "long.bvh", Sequential());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->motion.num_frames, 20000);
  EXPECT_TRUE(a->motion.values == b->motion.values);
}

TEST(BvhParallelRead, ErrorsInEitherHalfMatchTheSequentialMessage) {
  const std::string text = WalkText(1000);
  const std::size_t motion = text.find("Frame Time");
  ASSERT_NE(motion, std::string::npos);
  // A bad number early (first half) and late (second half), a short line in the
  // second half: each message names the same line, column and frame.
  for (const std::size_t from : {motion + 100, motion + (text.size() - motion) * 3 / 4}) {
    for (const auto& [what, with] : {std::pair<std::string, std::string>{" ", " x"},
                                     std::pair<std::string, std::string>{" ", "\n"}}) {
      const std::string bad = Edit(text, from, what, with);
      const auto a = mocap::ParseBvh(bad, "bad.bvh", Halves());
      const auto b = mocap::ParseBvh(bad, "bad.bvh", Sequential());
      ASSERT_FALSE(b.ok());
      ASSERT_FALSE(a.ok());
      EXPECT_EQ(a.error().ToString(), b.error().ToString());
    }
  }
}

TEST(BvhParallelRead, ShortAndLongFilesMatchTheSequentialPass) {
  const std::string text = WalkText(1000);
  // Fewer frames than declared: the same error; with allow_short_motion the
  // same frames and warning.
  const std::string short_text = Edit(text, 0, "Frames: 1000", "Frames: 1001");
  auto ha = Halves(), sa = Sequential();
  EXPECT_EQ(mocap::ParseBvh(short_text, "s.bvh", ha).error().ToString(),
            mocap::ParseBvh(short_text, "s.bvh", sa).error().ToString());
  ha.allow_short_motion = sa.allow_short_motion = true;
  const auto a = mocap::ParseBvh(short_text, "s.bvh", ha);
  const auto b = mocap::ParseBvh(short_text, "s.bvh", sa);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->motion.num_frames, 1000);
  ASSERT_EQ(a->warnings.size(), b->warnings.size());
  EXPECT_EQ(a->warnings.back().ToString(), b->warnings.back().ToString());
  // More data lines than declared: the declared frames and the same warning.
  const std::string long_text = Edit(text, 0, "Frames: 1000", "Frames: 999");
  const auto c = mocap::ParseBvh(long_text, "l.bvh", Halves());
  const auto d = mocap::ParseBvh(long_text, "l.bvh", Sequential());
  ASSERT_TRUE(c.ok() && d.ok());
  EXPECT_EQ(c->motion.num_frames, 999);
  EXPECT_TRUE(c->motion.values == d->motion.values);
  ASSERT_EQ(c->warnings.size(), d->warnings.size());
  EXPECT_EQ(c->warnings.back().ToString(), d->warnings.back().ToString());
}

}  // namespace
