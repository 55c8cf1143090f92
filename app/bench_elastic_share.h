#pragma once
// The elastic layer's share of a frame, for `patchskin bench`: the demo walk
// on the mannequin with two elastic patches (a 6x6 belly driven by Spine1, a
// 5x5 jowl driven by Head, the sample rigs' parameters), 30 fps. Per frame, on
// the thread's CPU clock: the layered pipeline's Evaluate (both networks
// included), the render at 1280x720 with 2x2 samples on one thread, and the
// PNG write (level 1): the end-to-end frame; and a second deform::ElasticLayer
// advancing copies of the two networks to the same time: the elastic layer
// alone. Row elastic_share_two_patches: elastic / end-to-end, in percent, one
// value per repetition of `frames` frames (the requirement: at most 1 %).

#include <vector>

#include "bench/harness/timing.h"

namespace app::bench {

using ::bench::Budget;
using ::bench::Row;

// Appends the row; sets *failed when a step refuses to run (its error printed).
void AddElasticShareRow(const Budget& b, int frames, std::vector<Row>& rows, bool* failed);

}  // namespace app::bench
