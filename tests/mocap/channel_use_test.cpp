// ChannelUse: which joints the motion rotates, and which it pulls away from
// their parents by position channels (positioning links, not bones).

#include "mocap/channel_use.h"

#include <string>

#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"

namespace {

// A root on the floor (rotation channels declared, always zero) holding hips
// that walk 60 cm away and bob; a spine whose position channels repeat its
// offset with a 0.2 cm solve noise and whose rotation turns by 0.0005 degrees
// only (printing noise); a head that nods; an IK target that follows a foot.
constexpr char kBvh[] = R"(HIERARCHY
ROOT Root
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Hips
  {
    OFFSET 0 95 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    JOINT Spine
    {
      OFFSET 0 40 0
      CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
      JOINT Head
      {
        OFFSET 0 40 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0 20 0
        }
      }
    }
  }
  JOINT IkFoot
  {
    OFFSET 10 5 0
    CHANNELS 3 Xposition Yposition Zposition
    End Site
    {
      OFFSET 0 0 10
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0 0 0 0 0 0  0 95 0 0 0 0  0 40 0 0 0 0  0 0 0  10 5 0
0 0 0 0 0 0  0 97 30 0 0 0  0 40.2 0 0 0.0005 0  0 10 0  10 5 25
0 0 0 0 0 0  0 95 60 0 0 0  0 39.9 0 0 0 0  0 -10 0  10 5 55
)";

TEST(ChannelUse, TellsRotationsAndPositioningLinksApart) {
  mocap::BvhReadOptions read;
  read.scale = 1.0f;
  base::Result<mocap::BvhFile> file = mocap::ParseBvh(kBvh, "use.bvh", read);
  ASSERT_TRUE(file.ok()) << file.error().ToString();
  const mocap::Skeleton& s = file->skeleton;
  const std::vector<std::uint8_t> use = mocap::ChannelUse(s, file->motion);
  ASSERT_EQ(use.size(), static_cast<std::size_t>(s.num_joints()));
  const auto flags = [&](const char* name) { return use[static_cast<std::size_t>(s.FindJoint(name))]; };
  EXPECT_EQ(flags("Root"), 0) << "declared rotations that never change, and no travel";
  EXPECT_EQ(flags("Hips"), mocap::kJointStretches) << "60 cm of travel on a 95 cm link";
  EXPECT_EQ(flags("Spine"), 0) << "0.3 cm of solve noise is a bone; 0.0005 degrees is no turn";
  EXPECT_EQ(flags("Head"), mocap::kJointRotates);
  EXPECT_EQ(flags("IkFoot"), mocap::kJointStretches);
}

TEST(ChannelUse, EmptyWhenTheMotionDoesNotFitTheSkeleton) {
  mocap::BvhReadOptions read;
  read.scale = 1.0f;
  base::Result<mocap::BvhFile> file = mocap::ParseBvh(kBvh, "use.bvh", read);
  ASSERT_TRUE(file.ok());
  mocap::Motion other = file->motion;
  other.num_channels -= 1;
  EXPECT_TRUE(mocap::ChannelUse(file->skeleton, other).empty());
  mocap::Motion none;
  none.num_channels = file->skeleton.num_channels;
  const std::vector<std::uint8_t> still = mocap::ChannelUse(file->skeleton, none);
  ASSERT_EQ(still.size(), static_cast<std::size_t>(file->skeleton.num_joints()));
  for (std::uint8_t u : still) EXPECT_EQ(u, 0) << "no frames: nothing moves";
}

}  // namespace
