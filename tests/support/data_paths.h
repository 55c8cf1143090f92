#pragma once
// Where tests find their inputs. TEST_DATA_DIR is tests/data (small inputs the
// project made); SHARED_DATA_DIR is ../shared/data (real captures, not in the
// repo). Tests that need the shared data skip with a clear message without it.

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace testsupport {

inline std::filesystem::path TestDataPath(const std::string& relative) {
  return std::filesystem::path(TEST_DATA_DIR) / relative;
}

inline std::filesystem::path SharedDataPath(const std::string& relative) {
  return std::filesystem::path(SHARED_DATA_DIR) / relative;
}

// A file of samples/data (the motions and rigs the demos use).
inline std::filesystem::path SampleDataPath(const std::string& name) {
  return (std::filesystem::path(TEST_DATA_DIR) / ".." / ".." / "samples" / "data" / name)
      .lexically_normal();
}

// This test's own output folder, TEST_OUTPUT_DIR/<folder>/<suite>_<test>/, with
// an empty logs/ in it: emptied the first time a test asks for it and kept for
// the rest of that test (a failed test leaves its files to look at).
inline std::filesystem::path TestDir(const std::string& folder) {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path d = std::filesystem::path(TEST_OUTPUT_DIR) / folder /
                                  (std::string(info->test_suite_name()) + "_" + info->name());
  static std::string cleaned;
  if (cleaned != d.string()) {
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d / "logs");
    cleaned = d.string();
  }
  return d;
}

// TEST_OUTPUT_DIR/<relative>/, emptied: a fresh folder for one test's files.
inline std::filesystem::path FreshOutputDir(const std::string& relative) {
  const std::filesystem::path d = std::filesystem::path(TEST_OUTPUT_DIR) / relative;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// The same, in a folder named after the test's suite.
inline std::filesystem::path TestDir() {
  return TestDir(::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name());
}

// The regular files of `folder`, sorted by name (none when it does not exist).
inline std::vector<std::filesystem::path> FilesIn(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> out;
  if (!std::filesystem::exists(folder)) return out;
  for (const auto& e : std::filesystem::directory_iterator(folder)) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

inline bool HaveSharedData() { return std::filesystem::is_directory(SHARED_DATA_DIR); }

// A folder under the build tree for files a test writes (created on demand).
inline std::filesystem::path TestOutputPath(const std::string& relative) {
  std::filesystem::path p = std::filesystem::path(TEST_OUTPUT_DIR) / relative;
  std::filesystem::create_directories(p.parent_path());
  return p;
}

}  // namespace testsupport

// Skips the current test when a file of ../shared/data is missing.
#define PATCHSKIN_REQUIRE_SHARED_FILE(path)                                              \
  do {                                                                                   \
    if (!std::filesystem::exists(path)) {                                                \
      GTEST_SKIP() << "shared data file " << (path)                                      \
                   << " is absent (set PATCHSKIN_DATA_DIR to ../shared/data to run this)"; \
    }                                                                                    \
  } while (false)
