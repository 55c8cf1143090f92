#pragma once
// What the app tests check of a command they refuse: its exit code and that it
// left no output behind.

#include <gtest/gtest.h>

#include <filesystem>

#include "support/data_paths.h"

namespace testsupport {

// The exit code of a command refused for its input or its arguments.
inline constexpr int kExitBadInput = 2;

// Where the current test points a command's output: TestDir()/out.
inline std::filesystem::path OutDir() { return TestDir() / "out"; }

// Fails the test for every file under OutDir().
inline void ExpectNoOutput() {
  if (!std::filesystem::exists(OutDir())) return;
  for (const auto& e : std::filesystem::recursive_directory_iterator(OutDir())) {
    ADD_FAILURE() << "unexpected output " << e.path();
  }
}

}  // namespace testsupport
