// Long captures with an ELASTIC rig (issue 8): the elastic layer keeps the
// kinematics of its driving joints only (#F x #D, 124 B each, plus a transient
// #F x #D x 64 B of matrices while they are computed), so `render` of a few
// frames of a capture of N frames grows only with the motion's floats and
// that compact table. Before, it held #F x #J x (64 + 64 + 124) B (~6 KB a
// frame for 25 joints). Peak memory is the child's own VmHWM (render --stats),
// as in long_capture_test.cpp.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/sanitizer.h"
#include "support/data_paths.h"
#include "support/long_capture.h"
#include "support/run_process.h"

namespace {

namespace fs = std::filesystem;

struct ElasticRun {
  int frames = 0;
  int channels = 0;
  double peak_mb = 0.0;
};

// belly_jump.json's elastic belly patch on the generated walk of `frames` frames.
ElasticRun RenderElastic(const fs::path& dir, int frames) {
  ElasticRun m;
  m.frames = frames;
  const std::string tag = std::to_string(frames);
  const fs::path bvh = dir / ("long_" + tag + ".bvh");
  m.channels = testsupport::WriteLongCapture(bvh.string(), frames);
  EXPECT_GT(m.channels, 0);
  const fs::path rig = dir / ("belly_" + tag + ".json");
  {
    std::ofstream out(rig);
    out << R"({"character": "mannequin", "motion": {"file": ")" << bvh.filename().string()
        << R"("}, "global": "ssd", "patches": [{"name": "belly",
  "region": {"joint": "Spine1", "radius": 16, "side": [0, 0, 1], "half_angle_deg": 70},
  "parametrization": "cylinder", "sampling": [10, 10], "grid": [6, 6], "border_width": 0.15,
  "elastic": {"frequency_hz": 4, "damping_ratio": 0.15, "max_displacement": 8}}],
  "render": {"camera": "fixed", "split": true}})";
  }
  const fs::path pattern = dir / ("e" + tag + "_####.png");
  const testsupport::ProcessResult r = testsupport::RunPatchskin(
      {"render", rig.string(), "--frames", "0:2", "--size", "160x90", "--supersample", "1",
       "--threads", "1", "--quiet", "--no-video", "--no-sheet", "--overwrite", "--stats", "--out",
       pattern.string()},
      dir / ("logs_" + tag));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / ("e" + tag + "_0002.png")));
  const std::size_t stats = r.out.find("stats:");
  EXPECT_NE(stats, std::string::npos) << r.out;
  double first_s = 0.0;
  if (stats != std::string::npos) {
    EXPECT_EQ(std::sscanf(r.out.c_str() + stats,
                          "stats: first frame after %lf s, peak memory %lf MB", &first_s,
                          &m.peak_mb),
              2)
        << r.out;
  }
  std::printf("elastic rig, capture of %7d frames (%d channels): peak RSS %7.1f MB\n", frames,
              m.channels, m.peak_mb);
  return m;
}

TEST(ElasticLongCapture, PeakMemoryGrowsOnlyWithTheMotionDataAndTheDrivingJointsTable) {
  PATCHSKIN_SKIP_MEMORY_BOUND_UNDER_ASAN();
  const fs::path dir = testsupport::TestOutputPath("elastic_long_capture/x").parent_path();
  fs::remove_all(dir);
  fs::create_directories(dir);
  const ElasticRun small = RenderElastic(dir, 1000);
  for (const int frames : {10000, 100000}) {
    const ElasticRun big = RenderElastic(dir, frames);
    // Allowed growth per extra frame: its floats (#C x 4 B) and one driving
    // joint's compact kinematics while they are built (smoothed matrix 64 B +
    // JointKinematics 124 B); plus the reader's and allocator's constant
    // (12 MiB, as in long_capture_test.cpp).
    constexpr double kDrivingJoints = 1.0;
    const double per_frame = 4.0 * big.channels + kDrivingJoints * (64.0 + 124.0);
    const double bound_mb = (per_frame * (big.frames - small.frames) + 12.0 * 1048576.0) / 1e6;
    EXPECT_LE(big.peak_mb - small.peak_mb, bound_mb) << big.frames << " vs " << small.frames;
    RecordProperty("elastic_peak_mb_" + std::to_string(big.frames), std::to_string(big.peak_mb));
  }
}

}  // namespace
