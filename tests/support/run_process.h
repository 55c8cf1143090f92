#pragma once
// Runs the built `patchskin` (PATCHSKIN_BINARY), or another program (idiff,
// chromium: FindProgram looks it up on PATH), as a child process for the app
// tests: arguments passed as a vector (no shell quoting), stdout and stderr
// captured into files, exit code returned. StartPatchskin leaves it running so
// a test can signal it.

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "support/data_paths.h"

extern char** environ;

namespace testsupport {

struct ProcessResult {
  int exit_code = -1;  // the child's exit status; -1 when a signal ended it
  int term_signal = 0; // the signal that ended it, or 0
  long max_rss_kb = 0;  // the child's peak resident set (getrusage ru_maxrss, KiB)
  double cpu_s = 0.0;   // the child's user + system CPU time, seconds
  std::string out;
  std::string err;

  // The first line of stderr (without the newline).
  std::string FirstErrLine() const { return err.substr(0, err.find('\n')); }
};

inline std::string SlurpFile(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A started child: its pid and where its output goes.
struct RunningProcess {
  pid_t pid = -1;
  std::filesystem::path out, err;
};

// Starts `program` (a path) with `args`, stdout/stderr to `log_dir`/{stdout,stderr}.txt.
inline RunningProcess StartProgram(const std::string& program, const std::vector<std::string>& args,
                                   const std::filesystem::path& log_dir) {
  RunningProcess p;
  std::filesystem::create_directories(log_dir);
  p.out = log_dir / "stdout.txt";
  p.err = log_dir / "stderr.txt";
  std::vector<std::string> all{program};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, p.out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, p.err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (posix_spawn(&p.pid, argv[0], &actions, nullptr, argv.data(), environ) != 0) p.pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  return p;
}

// Starts PATCHSKIN_BINARY with `args`, stdout/stderr to `log_dir`/{stdout,stderr}.txt.
inline RunningProcess StartPatchskin(const std::vector<std::string>& args,
                                     const std::filesystem::path& log_dir) {
  return StartProgram(PATCHSKIN_BINARY, args, log_dir);
}

// The full path of `name` found on PATH, or empty when it is not installed.
inline std::string FindProgram(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::string dirs = path != nullptr ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::filesystem::path candidate =
        std::filesystem::path(dirs.substr(start, end - start)) / name;
    if (end > start && access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return {};
}

inline ProcessResult WaitFor(const RunningProcess& p) {
  ProcessResult r;
  if (p.pid <= 0) return r;
  int status = 0;
  rusage usage{};
  wait4(p.pid, &status, 0, &usage);
  r.max_rss_kb = usage.ru_maxrss;
  r.cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
            1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.term_signal = WTERMSIG(status);
  r.out = SlurpFile(p.out);
  r.err = SlurpFile(p.err);
  return r;
}

inline ProcessResult RunProgram(const std::string& program, const std::vector<std::string>& args,
                                const std::filesystem::path& log_dir) {
  return WaitFor(StartProgram(program, args, log_dir));
}

inline ProcessResult RunPatchskin(const std::vector<std::string>& args,
                                  const std::filesystem::path& log_dir) {
  return WaitFor(StartPatchskin(args, log_dir));
}

// The same, logging to the current test's own folder (TestDir()/logs).
inline ProcessResult RunPatchskin(const std::vector<std::string>& args) {
  return RunPatchskin(args, TestDir() / "logs");
}

// Runs `patchskin ARGS` through /bin/sh, so `args` is one line that may quote
// paths ('...'); stdout and stderr go to `log_dir`/{stdout,stderr}.txt.
inline ProcessResult RunPatchskinLine(const std::string& args,
                                      const std::filesystem::path& log_dir) {
  return RunProgram("/bin/sh", {"-c", std::string("'") + PATCHSKIN_BINARY + "' " + args}, log_dir);
}

}  // namespace testsupport
