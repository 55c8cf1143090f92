// BVH reader: one in-memory file per dialect feature, the position-channel
// modes, unit and axis detection, and every real capture in shared/data.

#include "mocap/bvh_reader.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mocap/pose.h"
#include "support/data_paths.h"
#include "support/tolerances.h"

namespace {

using base::ErrorCode;
using mocap::BvhFile;
using mocap::BvhReadOptions;
using mocap::ChannelType;
using mocap::ParseBvh;

// Two joints, an end site, 6 + 3 channels, two frames.
constexpr const char* kSmall =
    "HIERARCHY\n"
    "ROOT Hips\n"
    "{\n"
    "  OFFSET 1 2 3\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    "  JOINT Chest\n"
    "  {\n"
    "    OFFSET 0 10 0\n"
    "    CHANNELS 3 Zrotation Yrotation Xrotation\n"
    "    End Site\n"
    "    {\n"
    "      OFFSET 0 5 0\n"
    "    }\n"
    "  }\n"
    "}\n"
    "MOTION\n"
    "Frames: 2\n"
    "Frame Time: 0.0333333\n"
    "0.5 90 -1 10 20 30 1 2 3\n"
    "1.5 91 -2 11 21 31 4 5 6\n";

BvhFile MustParse(const std::string& text, const BvhReadOptions& options = {}) {
  auto result = ParseBvh(text, "test.bvh", options);
  EXPECT_TRUE(result.ok()) << (result.ok() ? "" : result.error().ToString());
  if (!result.ok()) return {};
  return std::move(result).value();
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

void ExpectSameAsSmall(const BvhFile& file) {
  const BvhFile ref = MustParse(kSmall);
  EXPECT_EQ(file.skeleton.names, ref.skeleton.names);
  EXPECT_EQ(file.skeleton.parents, ref.skeleton.parents);
  ASSERT_EQ(file.motion.values.size(), ref.motion.values.size());
  for (std::size_t i = 0; i < ref.motion.values.size(); ++i)
    EXPECT_EQ(file.motion.values[i], ref.motion.values[i]);
}

TEST(BvhReader, ReadsSmallFile) {
  const BvhFile file = MustParse(kSmall);
  const mocap::Skeleton& s = file.skeleton;
  ASSERT_EQ(s.num_joints(), 2);
  EXPECT_EQ(s.names[0], "Hips");
  EXPECT_EQ(s.names[1], "Chest");
  EXPECT_EQ(s.parents[0], mocap::kNoParent);
  EXPECT_EQ(s.parents[1], 0);
  EXPECT_EQ(s.rest_translations[0], glm::vec3(1, 2, 3));
  EXPECT_EQ(s.rest_translations[1], glm::vec3(0, 10, 0));
  EXPECT_EQ(s.rest_rotations[1], glm::quat(1, 0, 0, 0));
  EXPECT_EQ(s.rest_scales[1], glm::vec3(1));
  ASSERT_EQ(s.end_sites.size(), 1u);
  EXPECT_EQ(s.end_sites[0].parent, 1);
  EXPECT_EQ(s.end_sites[0].name, "End Site");
  EXPECT_EQ(s.end_sites[0].offset, glm::vec3(0, 5, 0));
  EXPECT_EQ(s.num_channels, 9);
  EXPECT_EQ(s.channels[0].first, 0u);
  EXPECT_EQ(s.channels[0].count, 6);
  EXPECT_EQ(s.channels[0].types[3], ChannelType::kZRotation);
  EXPECT_EQ(s.channels[1].first, 6u);
  EXPECT_EQ(s.channels[1].types[0], ChannelType::kZRotation);
  EXPECT_EQ(s.channels[1].types[2], ChannelType::kXRotation);
  EXPECT_EQ(s.position_mode, mocap::PositionChannelMode::kReplaceOffset);
  EXPECT_EQ(s.info.source_file, "test.bvh");
  EXPECT_TRUE(s.Check().ok());
  EXPECT_EQ(file.motion.num_frames, 2);
  EXPECT_EQ(file.motion.num_channels, 9);
  EXPECT_EQ(file.motion.frame_time_s, 0.0333333);
  EXPECT_EQ(mocap::NominalFps(file.motion.frame_time_s), 30.0);
  EXPECT_EQ(file.motion.frame(1)[0], 1.5f);
  EXPECT_EQ(file.motion.frame(1)[8], 6.0f);
  EXPECT_TRUE(file.warnings.empty());
}

TEST(BvhReader, LineEndsAndBlanksDoNotMatter) {
  ExpectSameAsSmall(MustParse(Replace(kSmall, "\n", "\r\n")));
  ExpectSameAsSmall(MustParse(Replace(kSmall, "\n", "\r")));
  ExpectSameAsSmall(MustParse(Replace(Replace(kSmall, "\n", " \t\n\n"), " ", "\t ")));
  ExpectSameAsSmall(
      MustParse(std::string(kSmall).substr(0, std::string(kSmall).size() - 1)));  // no final LF
}

TEST(BvhReader, CrOnlyFileCountsLines) {
  const std::string text = Replace(Replace(kSmall, "\n", "\r"), "4 5 6", "4 5 x");
  auto result = ParseBvh(text, "cr.bvh");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().code, ErrorCode::kBadNumber);
  EXPECT_EQ(result.error().loc.line, 20);
  EXPECT_EQ(result.error().loc.column, 24);
}

TEST(BvhReader, KeywordsInAnyCase) {
  std::string text = Replace(kSmall, "HIERARCHY", "hierarchy");
  text = Replace(text, "JOINT", "Joint");
  text = Replace(text, "OFFSET", "offset");
  text = Replace(text, "CHANNELS", "channels");
  text = Replace(text, "End Site", "end site");
  text = Replace(text, "Xrotation", "XROTATION");
  text = Replace(text, "MOTION", "Motion");
  text = Replace(text, "Frames:", "FRAMES:");
  text = Replace(text, "Frame Time:", "frame time:");
  ExpectSameAsSmall(MustParse(text));
}

TEST(BvhReader, NamesWithSpacesAndOddCharacters) {
  std::string text = Replace(kSmall, "ROOT Hips", "ROOT  mixamorig:Hips.001 ");
  text = Replace(text, "JOINT Chest", "JOINT Upper Chest (L)");
  text = Replace(text, "End Site", "End Site Chest_End");
  const BvhFile file = MustParse(text);
  EXPECT_EQ(file.skeleton.names[0], "mixamorig:Hips.001");
  EXPECT_EQ(file.skeleton.names[1], "Upper Chest (L)");
  EXPECT_EQ(file.skeleton.end_sites[0].name, "Chest_End");
  EXPECT_EQ(file.skeleton.FindJoint("Upper Chest (L)"), 1);
}

// A name in Latin-1 bytes (0xE9 = e acute, 0xFF = y diaeresis) is not UTF-8: it is
// read as Latin-1 with a warning on its line; UTF-8 names (also 4-byte ones)
// pass unchanged.
TEST(BvhReader, Latin1NamesBecomeUtf8) {
  std::string text = Replace(kSmall, "JOINT Chest", "JOINT \xE9paule\xFF");
  text = Replace(text, "ROOT Hips", "ROOT H\xC3\xBC" "fte\xF0\x9F\xA6\xB4");
  const BvhFile file = MustParse(text);
  EXPECT_EQ(file.skeleton.names[0], "H\xC3\xBC" "fte\xF0\x9F\xA6\xB4");
  EXPECT_EQ(file.skeleton.names[1], "\xC3\xA9paule\xC3\xBF");
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0].loc.line, 6);
  EXPECT_NE(file.warnings[0].message.find("Latin-1"), std::string::npos);
  // Overlong, surrogate and truncated sequences are not UTF-8 either.
  for (const std::string bad : {"\xC0\xAF", "\xED\xA0\x80", "A\xE2\x82"}) {
    const BvhFile f = MustParse(Replace(kSmall, "JOINT Chest", "JOINT " + bad));
    EXPECT_EQ(f.warnings.size(), 1u) << bad;
  }
}

TEST(BvhReader, BraceOnTheNameLine) {
  std::string text = Replace(kSmall, "ROOT Hips\n{", "ROOT Hips {");
  text = Replace(text, "JOINT Chest\n  {", "JOINT Chest{");
  ExpectSameAsSmall(MustParse(text));
}

TEST(BvhReader, DuplicateNamesAreMadeUniqueWithAWarning) {
  const BvhFile file = MustParse(Replace(kSmall, "JOINT Chest", "JOINT Hips"));
  EXPECT_EQ(file.skeleton.names[0], "Hips");
  EXPECT_EQ(file.skeleton.names[1], "Hips_2");
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0].loc.line, 6);
  EXPECT_NE(file.warnings[0].message.find("Hips_2"), std::string::npos);
}

TEST(BvhReader, OneAndTwoRotationChannelsAndAnyOrder) {
  std::string text =
      Replace(kSmall, "CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 1 Yrotation");
  text = Replace(text, "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
                 "CHANNELS 4 Xrotation Zposition Yrotation Xposition");
  text = Replace(text, "0.5 90 -1 10 20 30 1 2 3", "1 2 3 4 5");
  text = Replace(text, "1.5 91 -2 11 21 31 4 5 6", "6 7 8 9 10");
  const BvhFile file = MustParse(text);
  EXPECT_EQ(file.skeleton.num_channels, 5);
  EXPECT_EQ(file.skeleton.channels[0].types[1], ChannelType::kZPosition);
  EXPECT_EQ(file.skeleton.channels[1].first, 4u);
  EXPECT_EQ(file.skeleton.channels[1].count, 1);
  EXPECT_EQ(file.motion.frame(1)[4], 10.0f);
}

TEST(BvhReader, ExponentsSignsAndLeadingDots) {
  const BvhFile file = MustParse(
      Replace(kSmall, "0.5 90 -1 10 20 30 1 2 3", "+.5 9E1 -1e0 1.0e+1 +2e1 3e1 .1 -.2 -0"));
  const auto f = file.motion.frame(0);
  EXPECT_EQ(f[0], 0.5f);
  EXPECT_EQ(f[1], 90.0f);
  EXPECT_EQ(f[2], -1.0f);
  EXPECT_EQ(f[3], 10.0f);
  EXPECT_EQ(f[4], 20.0f);
  EXPECT_EQ(f[6], 0.1f);
  EXPECT_EQ(f[7], -0.2f);
}

TEST(BvhReader, FramesHeaderVariants) {
  ExpectSameAsSmall(MustParse(Replace(kSmall, "Frames: 2", "Frames:\t2")));
  ExpectSameAsSmall(MustParse(Replace(kSmall, "Frames: 2", "Frames:2")));
  ExpectSameAsSmall(MustParse(Replace(kSmall, "Frames: 2", "Frames : 2")));
  const BvhFile glued =
      MustParse(Replace(kSmall, "Frame Time: 0.0333333", "Frame Time:\t.0083333"));
  EXPECT_EQ(glued.motion.frame_time_s, 0.0083333);
  EXPECT_EQ(mocap::NominalFps(glued.motion.frame_time_s), 120.0);
}

TEST(BvhReader, MissingFrameTimeGetsDefaultAndWarning) {
  const BvhFile file = MustParse(Replace(kSmall, "Frame Time: 0.0333333\n", ""));
  EXPECT_EQ(file.motion.num_frames, 2);
  EXPECT_EQ(file.motion.frame_time_s, mocap::kDefaultBvhFrameTimeS);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0].loc.line, 18);
}

TEST(BvhReader, SeveralRoots) {
  const std::string second =
      "ROOT Prop\n{\n OFFSET 7 8 9\n CHANNELS 3 Xposition Yposition Zposition\n End Site\n {\n "
      "OFFSET 0 1 0\n }\n}\n"
      "MOTION";
  std::string text = Replace(kSmall, "MOTION", second);
  text = Replace(text, "30 1 2 3\n", "30 1 2 3 10 11 12\n");
  text = Replace(text, "31 4 5 6\n", "31 4 5 6 13 14 15\n");
  const BvhFile file = MustParse(text);
  ASSERT_EQ(file.skeleton.num_joints(), 3);
  EXPECT_EQ(file.skeleton.parents[2], mocap::kNoParent);
  EXPECT_EQ(file.skeleton.channels[2].first, 9u);
  EXPECT_EQ(file.skeleton.end_sites[1].parent, 2);
  EXPECT_EQ(file.motion.frame(1)[11], 15.0f);
}

TEST(BvhReader, ExtraDataLinesAreIgnoredWithAWarning) {
  const BvhFile file = MustParse(std::string(kSmall) + "\n9 9 9 9 9 9 9 9 9\n8 8\n");
  EXPECT_EQ(file.motion.num_frames, 2);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_EQ(file.warnings[0].loc.line, 22);
  EXPECT_NE(file.warnings[0].message.find("2 data line"), std::string::npos);
}

TEST(BvhReader, ShortMotionIsAnErrorUnlessAllowed) {
  const std::string text = Replace(kSmall, "Frames: 2", "Frames: 5");
  auto strict = ParseBvh(text, "short.bvh");
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.error().code, ErrorCode::kCountMismatch);
  EXPECT_NE(strict.error().message.find("declares 5 frames"), std::string::npos);
  EXPECT_NE(strict.error().message.find("holds 2"), std::string::npos);
  BvhReadOptions options;
  options.allow_short_motion = true;
  const BvhFile file = MustParse(text, options);
  EXPECT_EQ(file.motion.num_frames, 2);
  EXPECT_EQ(file.motion.values.size(), 18u);
  EXPECT_EQ(file.warnings.size(), 1u);
}

TEST(BvhReader, ZeroFramesAndZeroChannels) {
  const BvhFile none = MustParse(
      "HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 3\nFrame Time: 0.1\n");
  EXPECT_EQ(none.motion.num_frames, 3);
  EXPECT_EQ(none.motion.num_channels, 0);
  const BvhFile empty = MustParse(Replace(kSmall, "Frames: 2", "Frames: 0"));
  EXPECT_EQ(empty.motion.num_frames, 0);
  EXPECT_EQ(empty.warnings.size(), 1u);  // the two lines are extra
}

// The root's local translation in both modes, with a non-zero root OFFSET.
TEST(BvhReader, PositionChannelModes) {
  for (const auto mode :
       {mocap::PositionChannelMode::kReplaceOffset, mocap::PositionChannelMode::kAddToOffset}) {
    BvhReadOptions options;
    options.position_mode = mode;
    const BvhFile file = MustParse(kSmall, options);
    EXPECT_EQ(file.skeleton.position_mode, mode);
    std::vector<mocap::JointTransform> locals(2);
    const mocap::LocalPoseJob job{&file.skeleton, file.motion.frame(1), locals};
    ASSERT_TRUE(job.Run().ok());
    const glm::vec3 channels(1.5f, 91.0f, -2.0f);
    const glm::vec3 expected = mode == mocap::PositionChannelMode::kReplaceOffset
                                   ? channels
                                   : channels + glm::vec3(1, 2, 3);
    EXPECT_NEAR(glm::length(locals[0].translation - expected), 0.0f, testsupport::kFloatTol);
    EXPECT_EQ(locals[1].translation, glm::vec3(0, 10, 0));  // no position channels: OFFSET
  }
}

TEST(BvhReader, DetectsUnitsAndScales) {
  // 2 + 10 + 5 = 17 units tall; make it 170 (cm) by scaling the text's offsets.
  std::string text = Replace(kSmall, "OFFSET 0 10 0", "OFFSET 0 100 0");
  text = Replace(text, "OFFSET 0 5 0", "OFFSET 0 70 0");
  const BvhFile cm = MustParse(text);
  EXPECT_EQ(cm.skeleton.info.detected_units, "cm");
  EXPECT_EQ(cm.skeleton.info.up_axis, mocap::UpAxis::kY);
  EXPECT_NEAR(cm.skeleton.info.rest_height, 170.0f, testsupport::kPositionTol);
  BvhReadOptions options;
  options.scale = 0.0f;
  const BvhFile m = MustParse(text, options);
  EXPECT_EQ(m.skeleton.info.scale_applied, 0.01f);
  EXPECT_NEAR(m.skeleton.info.rest_height, 1.7f, testsupport::kFloatTol);
  EXPECT_NEAR(m.skeleton.rest_translations[1].y, 1.0f, testsupport::kFloatTol);
  EXPECT_NEAR(m.motion.frame(0)[1], 0.9f, testsupport::kFloatTol);  // Yposition scaled
  EXPECT_EQ(m.motion.frame(0)[3], 10.0f);                           // rotation untouched
  EXPECT_STREQ(mocap::DetectUnits(1.8f), "m");
  EXPECT_STREQ(mocap::DetectUnits(68.0f), "inch");
  EXPECT_STREQ(mocap::DetectUnits(25.7f), "unknown");
  options.scale = -1.0f;
  auto bad = ParseBvh(text, "t.bvh", options);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidArgument);
}

// A Z-up copy of kSmall: every offset and channel rotated by +90 degrees about X.
TEST(BvhReader, ZUpIsDetectedAndConvertedToTheSamePoses) {
  const BvhFile y_up = MustParse(kSmall);
  std::string text = Replace(kSmall, "OFFSET 1 2 3", "OFFSET 1 -3 2");
  text = Replace(text, "OFFSET 0 10 0", "OFFSET 0 0 10");
  text = Replace(text, "OFFSET 0 5 0", "OFFSET 0 0 5");
  text = Replace(text, "Xposition Yposition Zposition Zrotation Xrotation Yrotation",
                 "Xposition Zposition Yposition Yrotation Xrotation Zrotation");
  text = Replace(text, "Zrotation Yrotation Xrotation\n", "Yrotation Zrotation Xrotation\n");
  // Ypos' = -Zpos, Zpos' = Ypos; Yrot' = -Zrot... written so that converting gives kSmall back.
  text = Replace(text, "0.5 90 -1 10 20 30 1 2 3", "0.5 90 1 -10 20 30 -1 2 3");
  text = Replace(text, "1.5 91 -2 11 21 31 4 5 6", "1.5 91 2 -11 21 31 -4 5 6");
  const BvhFile z_up = MustParse(text);
  EXPECT_EQ(z_up.skeleton.info.up_axis, mocap::UpAxis::kZ);
  BvhReadOptions options;
  options.convert_to_y_up = true;
  const BvhFile converted = MustParse(text, options);
  EXPECT_EQ(converted.skeleton.info.up_axis, mocap::UpAxis::kY);
  for (int f = 0; f < 2; ++f) {
    std::vector<mocap::JointTransform> a(2), b(2);
    std::vector<glm::mat4> ma(2), mb(2);
    ASSERT_TRUE((mocap::LocalPoseJob{&y_up.skeleton, y_up.motion.frame(f), a}.Run().ok()));
    ASSERT_TRUE(
        (mocap::LocalPoseJob{&converted.skeleton, converted.motion.frame(f), b}.Run().ok()));
    ASSERT_TRUE((mocap::LocalToModelJob{y_up.skeleton.parents, a, glm::mat4(1.0f), ma}.Run().ok()));
    ASSERT_TRUE(
        (mocap::LocalToModelJob{converted.skeleton.parents, b, glm::mat4(1.0f), mb}.Run().ok()));
    for (int j = 0; j < 2; ++j) {
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r)
          EXPECT_NEAR(ma[j][c][r], mb[j][c][r], testsupport::kPositionTol);
      }
    }
  }
}

TEST(BvhReader, JointAndDepthLimitsAreOptions) {
  BvhReadOptions options;
  options.max_joints = 1;
  auto joints = ParseBvh(kSmall, "t.bvh", options);
  ASSERT_FALSE(joints.ok());
  EXPECT_EQ(joints.error().code, ErrorCode::kLimitExceeded);
  EXPECT_EQ(joints.error().loc.line, 6);
  EXPECT_EQ(joints.error().loc.column, 3);
  options = {};
  options.max_depth = 1;
  auto depth = ParseBvh(kSmall, "t.bvh", options);
  ASSERT_FALSE(depth.ok());
  EXPECT_EQ(depth.error().code, ErrorCode::kLimitExceeded);
  EXPECT_EQ(depth.error().loc.line, 6);
}

TEST(BvhReader, SkipsUtf8ByteOrderMark) {
  std::string text(kSmall);
  text.insert(0, "\xEF\xBB\xBF");
  ExpectSameAsSmall(MustParse(text));
}

// Random byte edits and truncations never crash: each gives a file or an error
// with a location inside the text.
TEST(BvhReader, MutatedInputsGiveAResultOrALocatedError) {
  const std::string base = kSmall;
  std::mt19937 rng(42);
  const char kBytes[] = "{}:.-+eE0123456789 \t\r\nXZrotationOFFSETJOINTEnd";
  int failures = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string text = base;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % text.size();
      switch (rng() % 3) {
        case 0:
          text[at] = kBytes[rng() % (sizeof(kBytes) - 1)];
          break;
        case 1: {  // delete up to 8 bytes (not erase(): GCC 12 warns falsely with -Wrestrict)
          std::string cut = text.substr(0, at);
          cut.append(text, std::min(text.size(), at + 1 + rng() % 8), std::string::npos);
          text.swap(cut);
          break;
        }
        default:
          text.resize(at);
          break;
      }
      if (text.empty()) text.push_back('H');
    }
    auto result = ParseBvh(text, "fuzz.bvh");
    if (result.ok()) {
      EXPECT_TRUE(result->skeleton.Check().ok());
      EXPECT_EQ(result->motion.values.size(),
                static_cast<std::size_t>(result->motion.num_frames) *
                    static_cast<std::size_t>(result->motion.num_channels));
      continue;
    }
    ++failures;
    EXPECT_GE(result.error().loc.line, 1) << result.error().ToString();
    EXPECT_GE(result.error().loc.column, 1) << result.error().ToString();
  }
  EXPECT_GT(failures, 1000);  // most edits break the file
}

TEST(BvhReader, MissingFileIsAnIoError) {
  auto result = mocap::ReadBvhFile("/nonexistent/walk.bvh");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().code, ErrorCode::kIo);
  EXPECT_EQ(result.error().loc.file, "/nonexistent/walk.bvh");
  auto folder = mocap::ReadBvhFile(testsupport::TestDataPath("bvh").string());
  ASSERT_FALSE(folder.ok());
  EXPECT_EQ(folder.error().code, ErrorCode::kIo);
}

// Real captures: counts from shared/data/SOURCES.md, values of the first and
// last frame against an independent strtof split of the text.
struct SharedCase {
  const char* path;
  int joints;
  int end_sites;
  int frames;
  double fps;
  const char* units;  // what DetectUnits should say
};

std::vector<float> SplitLine(const std::string& line) {
  std::vector<float> values;
  std::istringstream in(line);
  std::string word;
  while (in >> word) values.push_back(std::strtof(word.c_str(), nullptr));
  return values;
}

class SharedBvh : public testing::TestWithParam<SharedCase> {};

TEST_P(SharedBvh, LoadsWithDocumentedCountsAndValues) {
  const SharedCase& c = GetParam();
  const auto path = testsupport::SharedDataPath(c.path);
  PATCHSKIN_REQUIRE_SHARED_FILE(path);
  auto result = mocap::ReadBvhFile(path.string());
  ASSERT_TRUE(result.ok()) << result.error().ToString();
  const BvhFile& file = *result;
  EXPECT_EQ(file.skeleton.num_joints(), c.joints);
  EXPECT_EQ(static_cast<int>(file.skeleton.end_sites.size()), c.end_sites);
  EXPECT_EQ(file.motion.num_frames, c.frames);
  EXPECT_EQ(mocap::NominalFps(file.motion.frame_time_s), c.fps);
  EXPECT_EQ(file.skeleton.info.detected_units, c.units);
  EXPECT_EQ(file.skeleton.info.up_axis, mocap::UpAxis::kY);  // all eight are Y-up
  EXPECT_TRUE(file.warnings.empty());
  EXPECT_TRUE(file.skeleton.Check().ok());

  std::ifstream in(path);
  std::string line;
  std::vector<std::string> data;
  bool in_data = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (in_data && line.find_first_not_of(" \t") != std::string::npos) data.push_back(line);
    if (line.find("Frame Time") != std::string::npos) in_data = true;
  }
  ASSERT_EQ(static_cast<int>(data.size()), c.frames);
  for (const int f : {0, c.frames / 2, c.frames - 1}) {
    const std::vector<float> expected = SplitLine(data[static_cast<std::size_t>(f)]);
    const auto got = file.motion.frame(f);
    ASSERT_EQ(expected.size(), got.size());
    for (std::size_t k = 0; k < got.size(); ++k)
      EXPECT_EQ(got[k], expected[k]) << "frame " << f << " value " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(
    SharedData, SharedBvh,
    testing::Values(
        SharedCase{"bvh/cmu_cgspeed/01_01.bvh", 31, 7, 2752, 120, "unknown"},
        SharedCase{"bvh/cmu_cgspeed/01_03.bvh", 31, 7, 4511, 120, "unknown"},
        SharedCase{"bvh/bandai_namco/dataset-1_walk_normal_001.bvh", 22, 5, 195, 30, "cm"},
        SharedCase{"bvh/bandai_namco/dataset-2_run_active_034.bvh", 22, 5, 75, 30, "cm"},
        SharedCase{"bvh/lafan1_resolved/Geno_bind.bvh", 75, 21, 2, 60, "cm"},
        SharedCase{"bvh/lafan1_resolved/Geno_stance.bvh", 75, 21, 2, 60, "cm"},
        SharedCase{"bvh/bvh_python/test_mocapbank.bvh", 19, 5, 455, 30, "cm"},
        SharedCase{"bvh/bvh_python/test_freebvh.bvh", 55, 15, 69, 30, "cm"}));

}  // namespace
