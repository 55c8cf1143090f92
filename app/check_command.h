#pragma once
// `patchskin check MANIFEST`: golden-image testing for users. Renders every case
// of a manifest (app/check_manifest.h) through the render command itself
// (RunRender, so the frames are byte-identical to `patchskin render` with the
// same words), compares each frame with <references>/<case>/<frame file> as
// `compare` does (idiff's rule; a frame whose size differs always fails), prints
// one line per case and a summary, and writes an HTML report and, with --junit,
// a JUnit XML file (app/check_report.h).
//
//   patchskin check MANIFEST [--out DIR] [--references DIR] [--html FILE]
//                            [--junit FILE] [--update | --update-all] [--threads N]
//
// New frames go to DIR/<case>/frame_####.png (default out/check/<manifest name>),
// differences to DIR/<case>/diff_####.png, the report to DIR/report.html.
// --update copies the new frames of every case that did not pass (failure,
// warning, missing reference) over its references, --update-all those of every
// case; each updated case says how many files it replaced and added.
// Cases render one after another, each on --threads workers (0 = all cores).
// Exit codes: 0 every case passed (or was updated), 1 warnings only, 2 a failure
// or a missing reference, 4 an error (bad manifest or option, a render that
// failed, an unreadable reference).

#include <string>

namespace app {

struct CheckOptions {
  std::string manifest;
  std::string out;         // empty: out/check/<manifest stem>
  std::string references;  // empty: the manifest's
  std::string html;        // empty: <out>/report.html
  std::string junit;       // empty: none
  bool update = false;
  bool update_all = false;
  int threads = 0;
};

inline constexpr int kCheckPass = 0;
inline constexpr int kCheckWarning = 1;
inline constexpr int kCheckFail = 2;
inline constexpr int kCheckError = 4;

int RunCheck(const CheckOptions& options);

}  // namespace app
