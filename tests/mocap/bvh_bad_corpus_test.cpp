// The malformed BVH corpus (tests/data/bvh/bad): every file fails with exactly
// the documented error code, line and column, and never crashes or allocates
// from a declared count. The table below matches the folder's README.md.

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"
#include "support/data_paths.h"

namespace {

using base::ErrorCode;

struct BadCase {
  const char* file;
  ErrorCode code;
  int line;
  int column;
};

constexpr BadCase kCases[] = {
    {"empty.bvh", ErrorCode::kSyntax, 1, 1},
    {"no_hierarchy.bvh", ErrorCode::kSyntax, 1, 1},
    {"no_root.bvh", ErrorCode::kSyntax, 2, 1},
    {"root_without_name.bvh", ErrorCode::kSyntax, 2, 5},
    {"missing_open_brace.bvh", ErrorCode::kSyntax, 3, 2},
    {"missing_close_brace.bvh", ErrorCode::kSyntax, 15, 1},
    {"truncated_hierarchy.bvh", ErrorCode::kSyntax, 10, 1},
    {"offset_not_number.bvh", ErrorCode::kBadNumber, 8, 12},
    {"offset_nan.bvh", ErrorCode::kNonFinite, 4, 11},
    {"offset_missing_value.bvh", ErrorCode::kBadNumber, 5, 2},
    {"channels_count_too_big.bvh", ErrorCode::kBadChannel, 9, 12},
    {"channels_count_not_number.bvh", ErrorCode::kBadNumber, 9, 12},
    {"channels_negative.bvh", ErrorCode::kBadChannel, 9, 12},
    {"bad_channel_name.bvh", ErrorCode::kBadChannel, 9, 24},
    {"duplicate_channel.bvh", ErrorCode::kBadChannel, 9, 34},
    {"too_few_channel_names.bvh", ErrorCode::kBadChannel, 10, 3},
    {"channels_after_child.bvh", ErrorCode::kSyntax, 14, 2},
    {"second_offset.bvh", ErrorCode::kSyntax, 5, 2},
    {"joint_without_offset.bvh", ErrorCode::kSyntax, 13, 2},
    {"end_site_misspelled.bvh", ErrorCode::kSyntax, 10, 7},
    {"end_site_with_channels.bvh", ErrorCode::kSyntax, 13, 4},
    {"unknown_keyword.bvh", ErrorCode::kSyntax, 5, 2},
    {"depth_limit.bvh", ErrorCode::kLimitExceeded, 1026, 1},
    {"no_motion.bvh", ErrorCode::kSyntax, 16, 1},
    {"frames_missing.bvh", ErrorCode::kSyntax, 17, 1},
    {"frames_not_number.bvh", ErrorCode::kBadNumber, 17, 9},
    {"frames_negative.bvh", ErrorCode::kBadNumber, 17, 9},
    {"frames_absurd.bvh", ErrorCode::kLimitExceeded, 17, 9},
    {"frames_huge_declared.bvh", ErrorCode::kCountMismatch, 22, 1},
    {"fewer_frames.bvh", ErrorCode::kCountMismatch, 22, 1},
    {"frame_time_zero.bvh", ErrorCode::kBadNumber, 18, 13},
    {"frame_time_text.bvh", ErrorCode::kBadNumber, 18, 13},
    {"frame_time_inf.bvh", ErrorCode::kNonFinite, 18, 13},
    {"short_line.bvh", ErrorCode::kCountMismatch, 20, 17},
    {"long_line.bvh", ErrorCode::kCountMismatch, 20, 20},
    {"value_not_number.bvh", ErrorCode::kBadNumber, 21, 10},
    {"value_nan.bvh", ErrorCode::kNonFinite, 19, 3},
    {"value_inf.bvh", ErrorCode::kNonFinite, 19, 6},
    {"value_overflow.bvh", ErrorCode::kNonFinite, 19, 3},
    {"value_trailing_garbage.bvh", ErrorCode::kBadNumber, 20, 18},
    {"value_comma_decimal.bvh", ErrorCode::kBadNumber, 19, 3},
    {"value_double_sign.bvh", ErrorCode::kBadNumber, 19, 1},
    {"truncated_motion.bvh", ErrorCode::kCountMismatch, 21, 11},
};

class BvhBadCorpus : public testing::TestWithParam<BadCase> {};

TEST_P(BvhBadCorpus, FailsWithDocumentedCodeAndLocation) {
  const BadCase& c = GetParam();
  const std::string path = testsupport::TestDataPath(std::string("bvh/bad/") + c.file).string();
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  auto result = mocap::ReadBvhFile(path);
  ASSERT_FALSE(result.ok()) << c.file << " loaded but should fail";
  const base::Error& e = result.error();
  EXPECT_EQ(base::ErrorCodeName(e.code), base::ErrorCodeName(c.code)) << e.ToString();
  EXPECT_EQ(e.loc.line, c.line) << e.ToString();
  EXPECT_EQ(e.loc.column, c.column) << e.ToString();
  EXPECT_EQ(e.loc.file, path);
  EXPECT_FALSE(e.message.empty());
  // The formatted message starts "path:line:col: error: ".
  EXPECT_EQ(
      e.ToString().rfind(
          path + ":" + std::to_string(c.line) + ":" + std::to_string(c.column) + ": error: ", 0),
      0u)
      << e.ToString();
}

INSTANTIATE_TEST_SUITE_P(Corpus, BvhBadCorpus, testing::ValuesIn(kCases),
                         [](const testing::TestParamInfo<BadCase>& param_info) {
                           std::string name = param_info.param.file;
                           name = name.substr(0, name.find('.'));
                           return name;
                         });

// Every .bvh in the folder is in the table and in README.md, and vice versa.
TEST(BvhBadCorpusIndex, FolderTableAndReadmeAgree) {
  std::set<std::string> in_table;
  for (const BadCase& c : kCases) in_table.insert(c.file);
  EXPECT_GE(in_table.size(), 30u);
  std::set<std::string> in_folder;
  for (const auto& entry :
       std::filesystem::directory_iterator(testsupport::TestDataPath("bvh/bad"))) {
    if (entry.path().extension() == ".bvh") in_folder.insert(entry.path().filename().string());
  }
  EXPECT_EQ(in_table, in_folder);
  std::ifstream readme(testsupport::TestDataPath("bvh/bad/README.md"));
  ASSERT_TRUE(readme.good());
  const std::string text((std::istreambuf_iterator<char>(readme)),
                         std::istreambuf_iterator<char>());
  for (const BadCase& c : kCases) {
    const std::string row = std::string("| `") + c.file + "` |";
    const std::size_t at = text.find(row);
    ASSERT_NE(at, std::string::npos) << c.file << " has no README row";
    const std::string line = text.substr(at, text.find('\n', at) - at);
    const std::string tail = " | " + std::string(base::ErrorCodeName(c.code)) + " | " +
                             std::to_string(c.line) + ":" + std::to_string(c.column) + " |";
    EXPECT_EQ(line.substr(line.size() - tail.size()), tail) << line;
  }
}

// The huge declared count is answered without a huge allocation: the file is
// tiny, so at most a handful of frames can be reserved (checked by ASan builds
// and by the fact that 2e9 x 9 floats would need 72 GB).
TEST(BvhBadCorpusIndex, HugeDeclaredCountLoadsWhatIsThereWhenAllowed) {
  mocap::BvhReadOptions options;
  options.allow_short_motion = true;
  auto result = mocap::ReadBvhFile(
      testsupport::TestDataPath("bvh/bad/frames_huge_declared.bvh").string(), options);
  ASSERT_TRUE(result.ok()) << result.error().ToString();
  EXPECT_EQ(result->motion.num_frames, 3);
  EXPECT_LE(result->motion.values.capacity(), 9u * 32u);
  ASSERT_EQ(result->warnings.size(), 1u);
}

}  // namespace
