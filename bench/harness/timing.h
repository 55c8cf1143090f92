#pragma once
// The timing half of the bench harness (library patchskin_bench_harness),
// shared by `patchskin bench` (app/bench_command.h) and the Google Benchmark
// programs of bench/: the clocks, repeated runs of an operation, and one
// reported figure with its runs, median, min, max and reference (the ratio is
// median / reference). Header only, no dependency beyond the C++ library and
// POSIX clock_gettime; never Google Benchmark, so the shipped binary links it.
// Google Benchmark programs keep Google Benchmark's own timing and use these
// only for figures they compute beside it (a thread's CPU time inside one
// iteration, a median of their own repetitions).
//
// The other half, the scenes built from the app's character (the demo walk,
// the sample rigs, the 1280x720 bench frame), is app/bench_scenes.h: it needs
// patchskin_app, which links this library, so it lives in that library.

#include <time.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace bench {

// The calling thread's CPU time | elapsed time | CPU time of every thread of
// the process (work done, whatever the machine's load).
enum class Clock { kCpu, kWall, kProcess };

inline const char* ClockName(Clock c) {
  return c == Clock::kCpu ? "cpu" : c == Clock::kWall ? "wall" : "proc";
}

inline double Now(Clock c) {
  timespec ts{};
  clock_gettime(c == Clock::kCpu    ? CLOCK_THREAD_CPUTIME_ID
                : c == Clock::kWall ? CLOCK_MONOTONIC
                                    : CLOCK_PROCESS_CPUTIME_ID,
                &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Budget {
  int runs = 7;             // repetitions (median, min, max over them)
  double min_time_s = 0.3;  // each repetition lasts at least this long on its clock
};

// `items` / (seconds per call of `op`), once per repetition. The number of
// calls per repetition is calibrated first so that reading the clock (a system
// call for CPU time) stays out of sub-microsecond operations.
inline std::vector<double> Rates(const Budget& b, Clock clock, double items,
                                 const std::function<void()>& op) {
  std::int64_t batch = 1;
  double dt = 0.0;
  for (;;) {
    const double t0 = Now(clock);
    for (std::int64_t i = 0; i < batch; ++i) op();
    dt = Now(clock) - t0;
    if (dt >= b.min_time_s / 8.0 || batch >= (std::int64_t{1} << 30)) break;
    batch *= 2;
  }
  batch = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(static_cast<double>(batch) * b.min_time_s / std::max(dt, 1e-9)));
  std::vector<double> rates;
  for (int r = 0; r < b.runs; ++r) {
    const double t0 = Now(clock);
    for (std::int64_t i = 0; i < batch; ++i) op();
    rates.push_back(items * static_cast<double>(batch) / std::max(Now(clock) - t0, 1e-12));
  }
  return rates;
}

// One reported figure: a rate (or size) per repetition and what it compares to.
struct Row {
  std::string key;             // stable name (JSON key, first table column)
  std::string unit;
  Clock clock = Clock::kCpu;
  std::vector<double> runs;    // one value per repetition (one for sizes)
  double reference = 0.0;      // figure compared with; 0 = none
  std::string reference_name;  // "paper", "Assimp", ...
  std::string note;

  double Median() const {
    std::vector<double> v = runs;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  }
  // Median / reference; 0 when there is no reference.
  double Ratio() const { return reference > 0.0 ? Median() / reference : 0.0; }
  double Min() const { return runs.empty() ? 0.0 : *std::min_element(runs.begin(), runs.end()); }
  double Max() const { return runs.empty() ? 0.0 : *std::max_element(runs.begin(), runs.end()); }
};

}  // namespace bench
