#pragma once
// Progress of a frame loop: on a terminal a single self-rewriting bar with the
// frame count, frames per second and time left; otherwise (logs, CI) a plain
// line every few seconds. --quiet silences it.

#include <chrono>
#include <cstdio>
#include <string>

namespace app {

class Progress {
 public:
  Progress(std::string label, int total_frames, bool quiet);
  // Call after each finished frame (frame = its number, for plain lines).
  void Step(int frame);
  // Ends the bar (newline) and prints a summary line unless quiet.
  void Finish();

 private:
  std::string label_;
  int total_ = 0;
  int done_ = 0;
  bool quiet_ = false;
  bool tty_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_print_;
};

}  // namespace app
