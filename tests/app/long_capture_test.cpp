// Long captures (issue 8): `render` of a few frames of a capture of N frames
// needs memory that grows only with the motion data, and starts at once: no
// pass over every frame before the first image (the camera framing samples a
// bounded number of frames, the follow camera looks back a fixed window).
//
// Peak memory is the child's own VmHWM (render --stats), not wait4's
// ru_maxrss: a posix_spawn child starts from the test's address space, so
// its ru_maxrss includes the test process's peak (the generated capture's
// text and floats). The reader maps the file but gives
// each block of parsed text back (mocap::BvhReadOptions::block_bytes), and the
// render walks its output frames without listing them, so the bound per frame
// is the frame's floats (#C x 4 bytes); all else must be constant.

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/data_paths.h"
#include "support/long_capture.h"
#include "support/run_process.h"

namespace {

namespace fs = std::filesystem;

struct CaptureRun {
  int frames = 0;
  std::uintmax_t file_bytes = 0;
  int channels = 0;
  long max_rss_kb = 0;       // the child's VmHWM
  double first_frame_s = 0;  // the child's first frame, seconds from its start
  double cpu_s = 0.0;
};

CaptureRun RenderFirstFrames(const fs::path& dir, int frames) {
  CaptureRun m;
  m.frames = frames;
  char name[64];
  std::snprintf(name, sizeof(name), "long_%d.bvh", frames);
  const fs::path bvh = dir / name;
  m.channels = testsupport::WriteLongCapture(bvh.string(), frames);
  EXPECT_GT(m.channels, 0);
  m.file_bytes = fs::file_size(bvh);
  std::snprintf(name, sizeof(name), "f%d_####.png", frames);
  const fs::path pattern = dir / name;
  std::snprintf(name, sizeof(name), "f%d_0002.png", frames);
  const fs::path last = dir / name;
  std::snprintf(name, sizeof(name), "logs_%d", frames);
  const testsupport::ProcessResult r = testsupport::RunPatchskin(
      {"render", bvh.string(), "--frames", "0:2", "--size", "160x90", "--supersample", "1",
       "--threads", "1", "--quiet", "--no-video", "--no-sheet", "--overwrite", "--stats", "--out",
       pattern.string()},
      dir / name);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(last));
  double peak_mb = 0.0;
  const std::size_t stats = r.out.find("stats:");
  EXPECT_NE(stats, std::string::npos) << r.out;
  if (stats != std::string::npos) {
    EXPECT_EQ(std::sscanf(r.out.c_str() + stats, "stats: first frame after %lf s, peak memory %lf MB",
                          &m.first_frame_s, &peak_mb),
              2)
        << r.out;
  }
  m.max_rss_kb = static_cast<long>(peak_mb * 1e6 / 1024.0);
  m.cpu_s = r.cpu_s;
  std::printf(
      "capture of %7d frames (%6.1f MB text, %d channels): peak RSS %7.1f MB, first frame "
      "after %.2f s, CPU %.2f s\n",
      frames, static_cast<double>(m.file_bytes) / 1e6, m.channels, peak_mb, m.first_frame_s,
      m.cpu_s);
  return m;
}

TEST(LongCapture, PeakMemoryGrowsOnlyWithTheMotionDataAndTheFirstFrameComesAtOnce) {
  const fs::path dir = testsupport::TestOutputPath("long_capture/x").parent_path();
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<CaptureRun> runs;
  for (const int frames : {1000, 10000, 100000}) runs.push_back(RenderFirstFrames(dir, frames));
  ASSERT_EQ(runs.size(), 3u);
  const CaptureRun& small = runs.front();
  for (std::size_t i = 1; i < runs.size(); ++i) {
    const CaptureRun& big = runs[i];
    // Allowed growth: the extra frames' floats, plus what two parsing threads
    // hold besides them (a 4 MiB block of text each, given back once parsed,
    // and that block's floats until appended) and allocator slack: 12 MiB,
    // a constant, against 45 MB of text for 100,000 frames.
    const double extra_floats = 4.0 * big.channels * (big.frames - small.frames);
    const double bound_kb = extra_floats / 1024.0 + 12.0 * 1024.0;
    const double growth_kb = static_cast<double>(big.max_rss_kb - small.max_rss_kb);
    EXPECT_LE(growth_kb, bound_kb) << big.frames << " frames vs " << small.frames;
    RecordProperty("peak_rss_kb_" + std::to_string(big.frames), std::to_string(big.max_rss_kb));
  }
  // Start-up: parsing ~50 MB and three small frames, not a pass over 100,000
  // frames (each evaluation of the 20k-vertex body costs ~0.3 ms: 30 s).
  // Optimized builds only: a sanitized Debug build parses ~10x slower.
#ifdef NDEBUG
  EXPECT_LT(runs.back().cpu_s, 3.0);
#endif
}

}  // namespace
