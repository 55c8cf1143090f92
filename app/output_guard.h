#pragma once
// Safe outputs for a render (issue 9): what may be written, what is already
// there, and what to do when the user interrupts.
//
// - Existing files are never replaced by accident: Plan() refuses a render
//   whose frames (or other outputs such as the contact sheet) already exist,
//   before anything is rendered, unless --overwrite or --resume was given.
// - --resume skips the frames whose final file exists. A frame file only ever
//   exists under its final name when complete (render::WriteImage writes a
//   temporary file and renames it), so an existing file is a finished frame.
// - SIGINT / SIGTERM only set a flag while the guard lives: the frame loop
//   checks interrupted() before each frame, stops, lets the image writer
//   finish the frames already handed to it (so no temporary file is left and
//   every final name is a complete frame), and reports where it stopped
//   (StopMessage) with exit code 128 + signal. A second signal ends the
//   process at once (the default action), for a writer that hangs.
// - Output patterns that come from a rig file may not leave the folder they
//   are relative to: CheckRigOutputPattern refuses absolute paths and ".."
//   components. Patterns typed on the command line (--out) are the user's
//   own choice and are not restricted.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error.h"

namespace app {

// Refuses an output pattern read from a rig file when it is absolute, starts
// with "~", or has a ".." component (either separator); `where` names the
// rig file and field, e.g. {"walk.rig.json", 0, 0, "render.output"}.
// kInvalidArgument: "expected a relative path inside the rig's output folder,
// found '../x/####.png' (a '..' component)".
[[nodiscard]] base::Status CheckRigOutputPattern(const std::string& pattern,
                                                 const base::FileLoc& where);

// Creates `dir` (and its parents) when missing and checks that a file can be
// created in it, by creating and removing an empty hidden one, so a render or
// export that cannot write stops before any work with kIo "permission denied:
// cannot write in the output folder" naming the folder (or "cannot create the
// output folder: ..." with the system's reason). An empty `dir` is the
// current folder.
[[nodiscard]] base::Status PrepareOutputFolder(const std::filesystem::path& dir);

struct OutputGuardOptions {
  bool overwrite = false;  // --overwrite: replace existing outputs
  bool resume = false;     // --resume: keep existing frames, render the others
};

// One render's output bookkeeping. Not copyable: it owns the signal handlers
// (installed by the constructor, the previous ones restored by the
// destructor). One guard at a time per process.
class OutputGuard {
 public:
  explicit OutputGuard(OutputGuardOptions options);
  ~OutputGuard();
  OutputGuard(const OutputGuard&) = delete;
  OutputGuard& operator=(const OutputGuard&) = delete;

  // Decides, for the final paths of the frames in render order (#frames) and
  // the other files the render writes (sheet, video; overwritten by --resume
  // too, since they are rebuilt from every frame), which frames to render.
  // Error kInvalidArgument naming the first existing file, how many exist,
  // and the two options, when outputs exist without --overwrite / --resume;
  // kIo when a path exists but is not a regular file (a folder named like a
  // frame). Call before rendering anything.
  [[nodiscard]] base::Status Plan(const std::vector<std::string>& frame_paths,
                                  const std::vector<std::string>& other_paths);
  // The same for `num_frames` frames whose paths frame_path(i) gives one at a
  // time (an error from it is returned as is), so a render of ~430,000 frames
  // holds no list of their names: memory is one bit per frame.
  [[nodiscard]] base::Status Plan(
      std::size_t num_frames,
      const std::function<base::Result<std::string>(std::size_t)>& frame_path,
      const std::vector<std::string>& other_paths);

  // After Plan: true when frame i (index into frame_paths) is already done
  // and --resume skips it.
  bool skip(std::size_t i) const { return i < skip_.size() && skip_[i]; }
  int num_skipped() const { return num_skipped_; }

  // True once SIGINT or SIGTERM arrived (async-signal-safe flag).
  bool interrupted() const;
  // The signal that interrupted (SIGINT, SIGTERM) or 0.
  int signal_number() const;
  // "SIGINT", "SIGTERM", or "no signal".
  const char* signal_name() const;
  // 128 + signal, the shell's convention for a process ended by a signal.
  int exit_code() const { return 128 + signal_number(); }
  // "interrupted by SIGINT after frame 11: 12 of 48 frames are complete; run
  // the same command with --resume to render the other 36". last_done_number
  // is the file number of the last frame done (ignored when frames_done is 0);
  // `next`, when given, replaces the advice after the semicolon.
  std::string StopMessage(int last_done_number, int frames_done, int frames_total,
                          std::string_view next = {}) const;

  // Test hook: behaves as if `signal` had arrived.
  static void SimulateSignal(int signal);

 private:
  OutputGuardOptions options_;
  std::vector<bool> skip_;
  int num_skipped_ = 0;
  struct SavedHandlers;
  SavedHandlers* saved_ = nullptr;
};

}  // namespace app
