#pragma once
// `patchskin sheet PATTERN --frames A:B[:STEP]`: builds the contact sheet and
// the preview video of frames that already exist (rendered in chunks, e.g. by
// a Slurm job array, see app/farm_command.h), exactly as `render` would have
// built them in one run: the same up-to-24 frames on the sheet, the video at
// the output frame rate divided by STEP. Writes `contact_sheet.png` and
// `preview.mp4` next to the frames (under a temporary name, then renamed).

#include <string>

namespace app {

struct SheetOptions {
  std::string pattern;       // frame pattern with #### (or %04d), as given to render --out
  std::string frames;        // "A:B[:STEP]", both ends required
  double fps = 30.0;         // the render's output frame rate (frames per second, > 0)
  bool no_sheet = false;     // skip the contact sheet
  bool no_video = false;     // skip the preview video
  bool overwrite = false;    // replace an existing sheet / video (else refuse)
  bool quiet = false;
};

// Exit code: 0 ok; 2 bad input (a frame missing, named with the count of
// missing frames; an existing sheet or video without --overwrite; an
// unreadable frame or frames of different sizes); 3 internal error. Nothing is
// written when a frame is missing.
int RunSheet(const SheetOptions& options);

}  // namespace app
