#include "app/bench_long_capture.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "mocap/bvh_writer.h"
#include "tools/synthetic.h"

extern char** environ;

namespace app::bench {
namespace {

using ::bench::Clock;
using ::bench::Now;

namespace fs = std::filesystem;

// Writes the walk cut to exactly `frames` frames; returns its channel count, 0 on failure.
int WriteCapture(const fs::path& path, int frames) {
  const mocap::Skeleton skeleton = synthetic::MakeHumanoidSkeleton();
  synthetic::WalkOptions walk;
  walk.frame_time_s = 1.0 / 120.0;
  walk.num_cycles = frames / 120 + 1;  // one cycle per second: 120 frames
  base::Result<mocap::Motion> motion = synthetic::MakeWalkMotion(skeleton, walk);
  if (!motion.ok() || motion->num_frames < frames) return 0;
  motion->num_frames = frames;
  motion->values.resize(static_cast<std::size_t>(frames) *
                        static_cast<std::size_t>(motion->num_channels));
  if (!mocap::WriteBvhFile(path.string(), skeleton, *motion).ok()) return 0;
  return motion->num_channels;
}

struct ChildRun {
  int exit_code = -1;        // -1: did not start or ended by a signal
  double wall_s = 0.0;       // spawn to exit
  double peak_mb = 0.0;      // the child's own VmHWM (render --stats)
  double first_frame_s = 0;  // the child's first frame, from its start (render --stats)
};

// Runs this executable with `args`, stdout and stderr to files in `dir`.
ChildRun RunSelf(const std::vector<std::string>& args, const fs::path& dir) {
  ChildRun run;
  std::vector<std::string> all{"/proc/self/exe"};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string out = (dir / "stdout.txt").string(), err = (dir / "stderr.txt").string();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const double t0 = Now(Clock::kWall);
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return run;
  // Not wait4's ru_maxrss: a posix_spawn child (vfork) starts from the
  // parent's address space, so its maximum includes this process's own peak.
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return run;
  run.wall_s = Now(Clock::kWall) - t0;
  if (WIFEXITED(status)) run.exit_code = WEXITSTATUS(status);
  std::ifstream stats(out);
  for (std::string line; std::getline(stats, line);) {
    if (std::sscanf(line.c_str(), "stats: first frame after %lf s, peak memory %lf MB",
                    &run.first_frame_s, &run.peak_mb) == 2) {
      break;
    }
  }
  if (run.exit_code == 0 && run.peak_mb <= 0.0) {
    std::fprintf(stderr, "bench: the long capture render printed no stats line\n");
    run.exit_code = -1;
  }
  if (run.exit_code != 0) {
    std::ifstream in(err);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    std::fprintf(stderr, "bench: long capture render failed (exit %d): %s\n", run.exit_code,
                 text.c_str());
  }
  return run;
}

std::string Fixed(double value, int decimals) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

std::string Mb(double bytes) { return Fixed(bytes / 1e6, 1); }

}  // namespace

void AddLongCaptureRows(bool quick, std::vector<Row>& rows, bool* failed) {
  std::error_code ec;
  const fs::path dir = fs::temp_directory_path(ec) /
                       ("patchskin_bench_long_" + std::to_string(static_cast<long>(getpid())));
  fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  std::vector<int> counts{1000, 10000, 100000};
  if (!quick) counts.push_back(430000);
  struct Measured {
    int frames;
    int channels;
    double peak_mb;
  };
  std::vector<Measured> done;
  for (const int frames : counts) {
    const fs::path bvh = dir / ("long_" + std::to_string(frames) + ".bvh");
    const int channels = WriteCapture(bvh, frames);
    if (channels == 0) {
      *failed = true;
      continue;
    }
    const double text_bytes = static_cast<double>(fs::file_size(bvh, ec));
    const double float_bytes = 4.0 * channels * frames;
    const ChildRun run = RunSelf({"render", bvh.string(), "--frames", "0:0", "--size", "160x90",
                                  "--supersample", "1", "--threads", "1", "--quiet", "--no-video",
                                  "--no-sheet", "--overwrite", "--stats", "--out",
                                  (dir / "frame_####.png").string()},
                                 dir);
    fs::remove(bvh, ec);
    if (run.exit_code != 0) {
      *failed = true;
      continue;
    }
    const std::string n = std::to_string(frames);
    rows.push_back({"long_capture_" + n + "_peak_rss", "MB", Clock::kWall, {run.peak_mb}, 0.0, "",
                    "render --frames 0:0 of " + n + " frames: text " + Mb(text_bytes) +
                        " MB, floats " + Mb(float_bytes) + " MB"});
    rows.push_back({"long_capture_" + n + "_start", "s", Clock::kWall, {run.first_frame_s}, 0.0, "",
                    "first frame ready (load, framing, render); whole child " +
                        Fixed(run.wall_s, 2) + " s"});
    done.push_back({frames, channels, run.peak_mb});
  }
  if (done.size() >= 2) {
    const Measured& a = done.front();
    const Measured& b = done.back();
    const double per_frame = (b.peak_mb - a.peak_mb) * 1e6 / static_cast<double>(b.frames - a.frames);
    rows.push_back({"long_capture_growth_per_frame", "bytes", Clock::kWall, {per_frame},
                    4.0 * b.channels, "floats",
                    "peak memory per extra frame, " + std::to_string(a.frames) + " -> " +
                        std::to_string(b.frames) + " frames"});
  }
  fs::remove_all(dir, ec);
}

}  // namespace app::bench
