// BVH writer: round trips through ParseBvh keep the skeleton and the exact
// values, on a small file, on generated random values and on the real captures.

#include "mocap/bvh_writer.h"

#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"
#include "support/data_paths.h"

namespace {

using mocap::BvhFile;

void ExpectSame(const BvhFile& a, const BvhFile& b) {
  const mocap::Skeleton& s = a.skeleton;
  const mocap::Skeleton& t = b.skeleton;
  EXPECT_EQ(s.names, t.names);
  EXPECT_EQ(s.parents, t.parents);
  EXPECT_EQ(s.rest_translations, t.rest_translations);
  ASSERT_EQ(s.channels.size(), t.channels.size());
  for (std::size_t j = 0; j < s.channels.size(); ++j) {
    EXPECT_EQ(s.channels[j].first, t.channels[j].first);
    EXPECT_EQ(s.channels[j].count, t.channels[j].count);
    EXPECT_EQ(s.channels[j].types, t.channels[j].types);
  }
  ASSERT_EQ(s.end_sites.size(), t.end_sites.size());
  for (std::size_t e = 0; e < s.end_sites.size(); ++e) {
    EXPECT_EQ(s.end_sites[e].parent, t.end_sites[e].parent);
    EXPECT_EQ(s.end_sites[e].offset, t.end_sites[e].offset);
    EXPECT_EQ(s.end_sites[e].name, t.end_sites[e].name);
  }
  EXPECT_EQ(a.motion.num_frames, b.motion.num_frames);
  EXPECT_EQ(a.motion.frame_time_s, b.motion.frame_time_s);
  EXPECT_EQ(a.motion.values, b.motion.values);  // bit-identical floats
}

BvhFile RoundTrip(const BvhFile& file) {
  auto text = mocap::FormatBvh(file.skeleton, file.motion);
  EXPECT_TRUE(text.ok()) << (text.ok() ? "" : text.error().ToString());
  if (!text.ok()) return {};
  auto again = mocap::ParseBvh(*text, "written.bvh");
  EXPECT_TRUE(again.ok()) << (again.ok() ? "" : again.error().ToString());
  if (!again.ok()) return {};
  return std::move(again).value();
}

constexpr const char* kTwoRoots =
    "HIERARCHY\nROOT Hips\n{\n OFFSET 1 2 3\n CHANNELS 6 Xposition Yposition Zposition Zrotation "
    "Xrotation Yrotation\n"
    " JOINT Left Leg:1\n {\n  OFFSET 0.1 -40.25 1e-7\n  CHANNELS 2 Xrotation Zrotation\n"
    "  End Site Toe\n  {\n   OFFSET 0 -3 1\n  }\n }\n JOINT Spine\n {\n  OFFSET 0 10 0\n  CHANNELS "
    "0\n"
    "  End Site\n  {\n   OFFSET 0 5 0\n  }\n }\n}\n"
    "ROOT Prop\n{\n OFFSET 0 0 0\n CHANNELS 1 Yrotation\n}\n"
    "MOTION\nFrames: 2\nFrame Time: 0.0083333\n"
    "0.123456789 -1e-5 3 4 5 6 7 8 9\n1 2 3 4 5 6 7 8 -0.000001\n";

TEST(BvhWriter, RoundTripKeepsSkeletonAndValues) {
  auto file = mocap::ParseBvh(kTwoRoots, "two.bvh");
  ASSERT_TRUE(file.ok()) << file.error().ToString();
  ExpectSame(*file, RoundTrip(*file));
}

TEST(BvhWriter, RoundTripOfRandomValuesIsExact) {
  auto file = mocap::ParseBvh(kTwoRoots, "two.bvh");
  ASSERT_TRUE(file.ok());
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> angle(-360.0f, 360.0f);
  std::uniform_int_distribution<int> exponent(-20, 20);
  file->motion.num_frames = 50;
  file->motion.values.resize(50 * 9);
  for (float& v : file->motion.values) v = std::ldexp(angle(rng), exponent(rng));
  ExpectSame(*file, RoundTrip(*file));
}

// A breadth-first joint order (A, B, C, D with D under B) is written depth-first
// (A, B, D, C), and the motion columns move with their joints.
TEST(BvhWriter, ReordersJointsAndColumnsDepthFirst) {
  mocap::Skeleton s;
  s.names = {"A", "B", "C", "D"};
  s.parents = {mocap::kNoParent, 0, 0, 1};
  s.rest_translations = {glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)};
  s.rest_rotations.assign(4, glm::quat(1, 0, 0, 0));
  s.rest_scales.assign(4, glm::vec3(1));
  s.channels.resize(4);
  for (std::size_t j = 0; j < 4; ++j) {
    s.channels[j].first = static_cast<std::uint32_t>(j);
    s.channels[j].count = 1;
    s.channels[j].types[0] = mocap::ChannelType::kZRotation;
  }
  s.num_channels = 4;
  mocap::Motion m;
  m.num_frames = 2;
  m.num_channels = 4;
  m.values = {10, 20, 30, 40, 11, 21, 31, 41};
  auto text = mocap::FormatBvh(s, m);
  ASSERT_TRUE(text.ok()) << text.error().ToString();
  auto back = mocap::ParseBvh(*text, "w.bvh");
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->skeleton.names, (std::vector<std::string>{"A", "B", "D", "C"}));
  EXPECT_EQ(back->skeleton.parents, (std::vector<std::int16_t>{mocap::kNoParent, 0, 1, 0}));
  EXPECT_EQ(back->skeleton.rest_translations[2], glm::vec3(0, 0, 1));
  EXPECT_EQ(back->motion.values, (std::vector<float>{10, 20, 40, 30, 11, 21, 41, 31}));
}

TEST(BvhWriter, RejectsWhatBvhCannotHold) {
  auto file = mocap::ParseBvh(kTwoRoots, "two.bvh");
  ASSERT_TRUE(file.ok());
  mocap::BvhFile quat = *file;
  quat.skeleton.channels[1].types[0] = mocap::ChannelType::kQuatX;
  auto a = mocap::FormatBvh(quat.skeleton, quat.motion);
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.error().code, base::ErrorCode::kUnsupported);
  mocap::BvhFile named = *file;
  named.skeleton.names[0] = "bad{name";
  auto b = mocap::FormatBvh(named.skeleton, named.motion);
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error().code, base::ErrorCode::kUnsupported);
  mocap::BvhFile sized = *file;
  sized.motion.values.pop_back();
  auto c = mocap::FormatBvh(sized.skeleton, sized.motion);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().code, base::ErrorCode::kInvalidArgument);
}

TEST(BvhWriter, WritesFileAtomically) {
  auto file = mocap::ParseBvh(kTwoRoots, "two.bvh");
  ASSERT_TRUE(file.ok());
  const auto path = testsupport::TestOutputPath("bvh/written.bvh");
  ASSERT_TRUE(mocap::WriteBvhFile(path.string(), file->skeleton, file->motion).ok());
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
  auto back = mocap::ReadBvhFile(path.string());
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  ExpectSame(*file, *back);
  const base::Status bad =
      mocap::WriteBvhFile("/nonexistent/dir/x.bvh", file->skeleton, file->motion);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, base::ErrorCode::kIo);
}

TEST(BvhWriter, RealCapturesRoundTrip) {
  for (const char* name :
       {"bvh/cmu_cgspeed/01_01.bvh", "bvh/bandai_namco/dataset-1_walk_normal_001.bvh",
        "bvh/lafan1_resolved/Geno_bind.bvh", "bvh/bvh_python/test_mocapbank.bvh"}) {
    const auto path = testsupport::SharedDataPath(name);
    PATCHSKIN_REQUIRE_SHARED_FILE(path);
    auto file = mocap::ReadBvhFile(path.string());
    ASSERT_TRUE(file.ok()) << file.error().ToString();
    SCOPED_TRACE(name);
    ExpectSame(*file, RoundTrip(*file));
  }
}

}  // namespace
