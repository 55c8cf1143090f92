#pragma once
// The paper's Table 1 (Lee, Kim, Yoon 2009) on our own equivalents, for
// `patchskin bench`: per patch, the patch update (pose-space RBF, or one
// 30 fps frame of the mass-spring simulation), the rebuild of its bound
// vertices, and the total (one update + one rebuild), each per second of the
// thread's CPU time. Regions are generated open tubes (200 degrees of a
// cylinder, radius 4, height 20) with the paper's vertex counts, fitted and
// bound as the rig's patches are (deform/patch/patch_fit.h, deform/patch/patch_binding.h).

#include "bench/harness/timing.h"
#include "base/error.h"

namespace app::bench {

using ::bench::Budget;
using ::bench::Row;

// The paper's Table 1 (Core 2, 2.4 GHz); 0 where our sources do not give it.
struct PatchCase {
  const char* name;        // row name: elbow, shoulder, abdomen, face
  int m, n;                // control grid
  int around, along;       // tube vertices: around x along ~ the paper's vertex count
  bool simulated;          // update = mass-spring step (else the pose-space RBF)
  double paper_update, paper_rebuild, paper_total;  // the paper, per second; 0 = not given
};
inline constexpr PatchCase kPatches[] = {
    {"elbow", 9, 10, 46, 25, false, 3195.0, 688.0, 581.0},
    {"shoulder", 9, 6, 54, 25, false, 5348.0, 660.0, 532.0},
    {"abdomen", 5, 5, 11, 5, true, 1122.0, 0.0, 0.0},
    {"face", 7, 7, 25, 10, true, 400.0, 0.0, 0.0},
};

// One measured patch: its bound vertex count and three figures.
struct Table1Row {
  const PatchCase* patch = nullptr;
  int bound = 0;
  Row update, rebuild, total;
};

// Fits and binds the patch of `c`, then measures its update and rebuild
// `b.runs` times. Errors: the fitting and binding errors; kInternal when a job
// refuses to run.
base::Result<Table1Row> MeasurePatch(const PatchCase& c, const Budget& b);

}  // namespace app::bench
