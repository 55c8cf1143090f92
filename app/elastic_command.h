#pragma once
// `patchskin elastic [FILE] [--joint NAME] [--out plot.png] ...`: simulates one
// elastic patch (ALGORITHMS.md 6) driven by a joint of a capture (default: the
// built-in synthetic jump, driven by its hips) and writes a PNG plot of the
// patch centre's displacement beside the driving acceleration, so the response
// can be seen without reading numbers. Prints the peak displacement, the step
// the network ran at and every limit the simulation had to apply.

#include <string>

namespace app {

struct ElasticOptions {
  std::string file;              // BVH or glTF; empty = the synthetic jump (cm)
  std::string joint = "Hips";    // driving joint
  std::string out = "out/elastic.png";
  int grid = 5;                  // M = N control points, 3..16
  float spacing_m = 0.06f;       // control-point spacing of the flat test patch (metres)
  float frequency_hz = 3.0f;     // f0
  float damping_ratio = 0.15f;   // z0
  float gain = 1.0f;             // gam
  double preroll_s = 0.0;
  double cutoff_hz = 10.0;       // low-pass of the joint trajectories before differencing; 0 = off
  float scale = 0.0f;            // file length factor; 0 = detected units to metres
  float units_per_metre = 0.0f;  // 0 = 1 for files (after scaling), 100 for the built-in jump
};

// Returns the exit code (0 ok, 2 bad input, 3 internal); errors go to stderr.
int RunElastic(const ElasticOptions& options);

}  // namespace app
