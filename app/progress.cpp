#include "app/progress.h"

#include <unistd.h>

#include <algorithm>

namespace app {

Progress::Progress(std::string label, int total_frames, bool quiet)
    : label_(std::move(label)),
      total_(std::max(total_frames, 1)),
      quiet_(quiet),
      tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_) {}

void Progress::Step(int frame) {
  ++done_;
  if (quiet_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double since_print = std::chrono::duration<double>(now - last_print_).count();
  const double fps = elapsed > 0.0 ? done_ / elapsed : 0.0;
  const double left = fps > 0.0 ? (total_ - done_) / fps : 0.0;
  if (tty_) {
    if (since_print < 0.1 && done_ < total_) return;
    constexpr int kBarWidth = 30;
    const int filled = kBarWidth * done_ / total_;
    std::fprintf(stderr, "\r%s [%s%s] %d/%d frames  %.1f fps  %.0f s left ", label_.c_str(),
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kBarWidth - filled), ' ').c_str(), done_,
                 total_, fps, left);
    std::fflush(stderr);
  } else {
    if (since_print < 5.0 && done_ < total_ && done_ != 1) return;
    std::fprintf(stderr, "%s: frame %d (%d/%d), %.1f fps, %.0f s left\n", label_.c_str(), frame,
                 done_, total_, fps, left);
  }
  last_print_ = now;
}

void Progress::Finish() {
  if (quiet_) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (tty_) std::fputc('\n', stderr);
  std::fprintf(stderr, "%s: %d frames in %.2f s (%.1f fps)\n", label_.c_str(), done_, elapsed,
               elapsed > 0.0 ? done_ / elapsed : 0.0);
}

}  // namespace app
