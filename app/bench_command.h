#pragma once
// `patchskin bench [--quick] [--json FILE] [--threads N]`: every speed figure the
// project tracks, measured in one command on workloads built in memory (no
// input files needed), printed as a table and optionally written as JSON.
//
// Table 1 of Lee, Kim and Yoon (2009), row for row on our own equivalents
// (generated tube regions with the paper's control grids and vertex counts):
//   elbow+biceps  9x10, ~1150 bound vertices, pose-space RBF from 5 examples
//   shoulder      9x6,  ~1350 bound vertices, pose-space RBF from 5 examples
//   abdomen       5x5,  ~55 vertices, mass-spring simulation (h = 1/240 s, 30 fps)
//   face          7x7,  ~250 vertices, mass-spring simulation
// with patch updates per second (RBF: dS and Q = G + A dS; simulation: one
// 30 fps output frame), vertex rebuilds per second and the total (one update
// plus one rebuild) per second, each beside the paper's figure and the ratio.
//
// Then: BVH parse MB/s (a generated capture, the CMU file 01_01.bvh when the
// shared data folder is present, Assimp's BVH importer when built with it),
// SSD vertices per second (100k vertices, 4 influences, 1 and 2 threads),
// rasterizer frames per second of the demo body at 1280x720 and 1920x1080,
// PNG encode time, end-to-end frames per second of the demo (pipeline, follow
// camera, render, PNG writing), bytes per bound vertex and peak memory.
//
// Every figure is the median of repeated runs, with min and max. Single-thread
// figures use the thread's CPU time (steady on a shared machine); figures that
// use several threads use wall-clock time (the end-to-end row also per CPU
// second of all the process's threads, which load does not inflate). The
// header names the CPU, cores, load average, build type and compiler. A build without NDEBUG (not Release)
// is refused unless --allow-debug is given (its figures mean nothing).
//
// Exit codes: 0 ok, 1 usage, 2 bad argument or unwritable --json, 3 internal.

#include <string>

namespace app {

struct BenchOptions {
  bool quick = false;        // few short repetitions (a smoke run, seconds); else ~1 minute
  std::string json;          // also write the figures here as JSON; empty = none
  int threads = 0;           // workers of the multi-threaded rows (end to end); 0 = all cores
  std::string data_dir;      // shared data folder (for the CMU row); empty = build default
  bool allow_debug = false;  // run even in a non-Release build
};

// Runs every measurement, prints the table to stdout; returns the exit code.
int RunBench(const BenchOptions& options);

}  // namespace app
