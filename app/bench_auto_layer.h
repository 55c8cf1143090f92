#pragma once
// What `--layer auto` costs, for `patchskin bench`, on the demo walk (the
// generated body of its skeleton), measured in one run beside its own baseline:
//   auto_layer_setup_s: BuildAutoRig (placement, bend scan, region checks) plus
//     ApplyRigLayers (patch fits, elastic networks), seconds on the CPU clock;
//     the requirement: at most 1 s for a 30-joint capture.
//   auto_layer_overhead: the end-to-end frame (Evaluate, one body drawn at
//     1280x720 with 2x2 samples on one thread, PNG level 1) with the auto rig's
//     layers against the same frames with the global method alone, in percent,
//     one value per repetition of `frames` frames, the two timed alternately;
//     the requirement: at most 30 %.
//   auto_layer_rebuild_share: those patches' PatchRebuildJob calls (two per
//     patch and frame, as the layer makes them) timed on their own, as a
//     percentage of the layered end-to-end frame; the limit of 1 % is where
//     SIMD code in the rebuild would have to pay for itself end to end.

#include <vector>

#include "bench/harness/timing.h"

namespace app::bench {

using ::bench::Budget;
using ::bench::Row;

// Appends the three rows; sets *failed when a step refuses to run (error printed).
void AddAutoLayerRows(const Budget& b, int frames, std::vector<Row>& rows, bool* failed);

}  // namespace app::bench
