#include "app/output_guard.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace app {
namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void OnStopSignal(int signal) {
  if (g_signal != 0) {
    // Second signal: the user means it. Default action, re-raised.
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  g_signal = signal;
}

const char* SignalName(int signal) {
  switch (signal) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return "a signal";
  }
}

bool HasDotDot(const std::string& pattern) {
  std::size_t start = 0;
  while (start <= pattern.size()) {
    std::size_t end = pattern.find_first_of("/\\", start);
    if (end == std::string::npos) end = pattern.size();
    if (pattern.compare(start, end - start, "..") == 0 && end - start == 2) return true;
    start = end + 1;
  }
  return false;
}

}  // namespace

struct OutputGuard::SavedHandlers {
  struct sigaction int_action {};
  struct sigaction term_action {};
};

base::Status CheckRigOutputPattern(const std::string& pattern, const base::FileLoc& where) {
  const auto refuse = [&](const std::string& why) -> base::Status {
    return base::InvalidArgument(
        where, "expected a relative path inside the rig's output folder, found '" + pattern +
                   "' (" + why + ")");
  };
  if (pattern.empty()) return refuse("empty");
  if (pattern.front() == '/' || pattern.front() == '\\') return refuse("an absolute path");
  if (pattern.size() >= 2 && pattern[1] == ':') return refuse("a drive letter");
  if (pattern.front() == '~') return refuse("a home-folder path");
  if (HasDotDot(pattern)) return refuse("a '..' component");
  return base::Status::Ok();
}

OutputGuard::OutputGuard(OutputGuardOptions options)
    : options_(options), saved_(new SavedHandlers) {
  g_signal = 0;
  struct sigaction action {};
  action.sa_handler = &OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // blocking writes and waits go on; the loop polls the flag
  sigaction(SIGINT, &action, &saved_->int_action);
  sigaction(SIGTERM, &action, &saved_->term_action);
}

OutputGuard::~OutputGuard() {
  sigaction(SIGINT, &saved_->int_action, nullptr);
  sigaction(SIGTERM, &saved_->term_action, nullptr);
  delete saved_;
}

base::Status OutputGuard::Plan(const std::vector<std::string>& frame_paths,
                               const std::vector<std::string>& other_paths) {
  return Plan(
      frame_paths.size(),
      [&frame_paths](std::size_t i) -> base::Result<std::string> { return frame_paths[i]; },
      other_paths);
}

base::Status OutputGuard::Plan(
    std::size_t num_frames, const std::function<base::Result<std::string>(std::size_t)>& frame_path,
    const std::vector<std::string>& other_paths) {
  skip_.assign(num_frames, false);
  num_skipped_ = 0;
  int existing = 0;
  std::string first_existing;
  const auto check = [&](const std::string& path, bool is_frame, std::size_t i) -> base::Status {
    std::error_code ec;
    const auto status = std::filesystem::symlink_status(path, ec);
    if (ec || !std::filesystem::exists(status)) return base::Status::Ok();
    if (!std::filesystem::is_regular_file(status)) {
      return base::MakeError(base::ErrorCode::kIo, {path, 0, 0, {}},
                             "expected an image file or nothing at this output path, found "
                             "something else (a folder or a link)");
    }
    if (is_frame && options_.resume) {
      skip_[i] = true;
      ++num_skipped_;
      return base::Status::Ok();
    }
    if (first_existing.empty()) first_existing = path;
    ++existing;
    return base::Status::Ok();
  };
  for (std::size_t i = 0; i < num_frames; ++i) {
    base::Result<std::string> path = frame_path(i);
    if (!path.ok()) return path.error();
    if (base::Status s = check(*path, true, i); !s) return s;
  }
  if (!options_.resume) {
    for (const std::string& p : other_paths) {
      if (base::Status s = check(p, false, 0); !s) return s;
    }
  }
  if (existing > 0 && !options_.overwrite) {
    return base::InvalidArgument(
        {first_existing, 0, 0, {}},
        "output file exists (" + std::to_string(existing) + " of this render's " +
            std::to_string(num_frames + other_paths.size()) +
            " outputs do); expected a free output path: pass --overwrite to replace them or "
            "--resume to render only the missing frames");
  }
  return base::Status::Ok();
}

bool OutputGuard::interrupted() const { return g_signal != 0; }

int OutputGuard::signal_number() const { return static_cast<int>(g_signal); }

std::string OutputGuard::StopMessage(int last_done_number, int frames_done, int frames_total,
                                     std::string_view next) const {
  std::string m = std::string("interrupted by ") + SignalName(signal_number());
  if (frames_done == 0) {
    m += " before any frame was complete";
  } else {
    m += " after frame " + std::to_string(last_done_number) + ": " + std::to_string(frames_done) +
         " of " + std::to_string(frames_total) + " frames are complete";
  }
  m += "; ";
  m += next.empty() ? "run the same command with --resume to render the other " +
                          std::to_string(frames_total - frames_done)
                    : std::string(next);
  return m;
}

const char* OutputGuard::signal_name() const {
  return signal_number() == 0 ? "no signal" : SignalName(signal_number());
}

base::Status PrepareOutputFolder(const std::filesystem::path& dir) {
  const std::filesystem::path folder = dir.empty() ? std::filesystem::path(".") : dir;
  const base::FileLoc loc{folder.string(), 0, 0, {}};
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) {
    const std::string reason = ec == std::errc::permission_denied ? "permission denied: "
                               : ec == std::errc::read_only_file_system ? "read-only file system: "
                                                                        : "";
    return base::MakeError(base::ErrorCode::kIo, loc,
                           reason + "cannot create the output folder: " + ec.message());
  }
  const std::string probe = (folder / (".patchskin-probe-" + std::to_string(::getpid()))).string();
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    const int err = errno;
    const std::string reason = err == EACCES || err == EPERM ? "permission denied"
                               : err == EROFS                ? "read-only file system"
                                                             : std::strerror(err);
    return base::MakeError(base::ErrorCode::kIo, loc,
                           reason + ": cannot write in the output folder");
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return base::Status::Ok();
}

void OutputGuard::SimulateSignal(int signal) { g_signal = signal; }

}  // namespace app
