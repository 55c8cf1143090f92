#pragma once
// Long captures in bounded memory (issue 8), for `patchskin bench`: captures
// of 1,000, 10,000 and 100,000 frames (and 430,000, an hour at 120 fps,
// unless --quick) are generated into a temporary folder (the synthetic
// humanoid walk of tools/synthetic.h, 75 channels, ~450 bytes of text a
// frame), and each is rendered by a child `patchskin render FILE --frames 0:0
// --size 160x90 --supersample 1 --threads 1 --stats` (this executable,
// /proc/self/exe), which prints its own figures. Rows per capture:
//   long_capture_<N>_peak_rss    the child's peak resident memory (its VmHWM),
//                                MB; the note gives the text and the motion
//                                floats (#F x #C x 4 bytes) in MB
//   long_capture_<N>_start       seconds from the child's start until its first
//                                frame went to the writer (load, framing, render)
// and long_capture_growth_per_frame: bytes of peak memory per extra frame
// between the smallest and the largest capture, beside the floats' 4 x #C
// bytes (the figure the issue bounds).

#include <string>
#include <vector>

#include "bench/harness/timing.h"

namespace app::bench {

using ::bench::Row;

// Appends the rows above to `rows`; sets *failed when a capture cannot be
// written or a child render does not exit with 0 (its stderr is printed).
// `quick` leaves out the 430,000-frame capture.
void AddLongCaptureRows(bool quick, std::vector<Row>& rows, bool* failed);

}  // namespace app::bench
