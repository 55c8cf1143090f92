#include "app/farm_command.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

#include "app/frame_plan.h"
#include "app/motion_source.h"
#include "app/rig_file.h"
#include "app/exit_code.h"
#include "render/output/image_io.h"

extern char** environ;

namespace app {
namespace {

namespace fs = std::filesystem;

// Single-quotes `s` for sh unless it only holds characters sh leaves alone.
std::string Quote(const std::string& s) {
  bool plain = !s.empty();
  for (const char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '/' || c == ':' || c == '=' || c == '+' ||
                    c == '-' || c == ',' || c == '@' || c == '%';
    plain = plain && ok;
  }
  if (plain) return s;
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string Absolute(const std::string& path) {
  return fs::absolute(fs::path(path)).lexically_normal().string();
}

// Writes `text` to `path` under a temporary name, then renames it.
base::Status WriteText(const fs::path& path, const std::string& text, bool executable) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "." + string.
  std::string name = ".";
  name += path.filename().string();
  name += ".tmp-" + std::to_string(::getpid());
  const fs::path tmp = path.parent_path() / name;
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out.flush()) {
      return base::MakeError(base::ErrorCode::kIo, {path.string(), 0, 0, {}},
                             "cannot write the file");
    }
  }
  std::error_code ec;
  if (executable) {
    fs::permissions(tmp, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                    fs::perm_options::add, ec);
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return base::MakeError(base::ErrorCode::kIo, {path.string(), 0, 0, {}},
                           "cannot write the file: " + ec.message());
  }
  return base::Status::Ok();
}

// Options farm sets on every render call itself.
constexpr const char* kReservedRenderOptions[] = {"--frames", "--out", "--framing", "--fps",
                                                  "--motion", "--resume", "--overwrite",
                                                  "--no-sheet", "--no-video"};

std::string FramesText(int first, int last, int step) {
  return std::to_string(first) + ":" + std::to_string(last) + ":" + std::to_string(step);
}

}  // namespace

int RunFarm(const FarmOptions& o) {
  if (o.chunk < 1 || o.chunk > 1000000)
    return ReportError(ArgError("--chunk", "expected 1..1000000 frames per task"));
  if (o.wait && !o.submit) return ReportError(ArgError("--wait", "only with --submit"));
  for (const std::string& a : o.render_args) {
    for (const char* reserved : kReservedRenderOptions) {
      if (a == reserved || a.rfind(std::string(reserved) + "=", 0) == 0) {
        return ReportError(
            ArgError(a, "farm sets this render option itself; give it to farm (or leave it out)"));
      }
    }
  }

  // --- What to render: the input's motion decides the frames and their rate ---
  std::string motion_path = o.motion.empty() ? o.input : o.motion;
  std::string frames_text = o.frames, pattern = o.out, name = fs::path(o.input).stem().string();
  double fps = o.fps;
  if (fs::path(o.input).extension() == ".json") {
    base::Result<Rig> rig = LoadRig(o.input);
    if (!rig.ok()) return ReportError(rig.error());
    if (o.motion.empty()) motion_path = rig->motion.empty() ? rig->character : rig->motion;
    if (frames_text.empty()) frames_text = rig->render.frames;
    if (pattern.empty()) pattern = rig->render.output;
    if (fps <= 0.0) fps = rig->fps;
  }
  if (const auto bad = CheckFps(fps)) return ReportError(*bad);
  MotionSourceOptions load;
  load.y_up = true;
  base::Result<MotionSource> src = LoadMotionSource(motion_path, load);
  if (!src.ok()) return ReportError(src.error());
  base::Result<FramePlan> plan = PlanFrames(src->motion, {.frames = frames_text, .fps = fps});
  if (!plan.ok()) return ReportError(plan.error());
  const FrameRange range = plan->range;
  const int num_frames = static_cast<int>(plan->frames.size());
  const int num_tasks = (num_frames + o.chunk - 1) / o.chunk;

  if (pattern.empty()) pattern = "out/" + name + "/frame_####.png";
  if (!render::HasFramePlaceholder(pattern)) {
    return ReportError(ArgError(
        "--out", "the pattern '" + pattern + "' needs one frame placeholder such as #### or %04d"));
  }
  pattern = Absolute(pattern);
  const base::Result<std::string> first_frame = render::ExpandFramePattern(pattern, range.first);
  if (!first_frame.ok()) return ReportError(first_frame.error());
  const fs::path frames_dir = fs::path(*first_frame).parent_path();
  const fs::path script_dir = o.script_dir.empty() ? frames_dir / "slurm" : fs::path(Absolute(o.script_dir));
  const std::string job_name = o.job_name.empty() ? "patchskin-" + name : o.job_name;
  std::error_code ec;
  const std::string exe = fs::read_symlink("/proc/self/exe", ec).string();
  if (ec) {
    return ReportError(base::MakeError(base::ErrorCode::kInternal, {"/proc/self/exe", 0, 0, {}},
                                       "cannot find the patchskin binary: " + ec.message()));
  }
  char rate[64];
  std::snprintf(rate, sizeof rate, "%.17g", 1.0 / plan->frame_time_s);

  // --- The scripts ------------------------------------------------------------
  auto header = [&](std::ostringstream& s, const std::string& job, const std::string& log) {
    s << "#SBATCH --job-name=" << Quote(job) << "\n";
    s << "#SBATCH --output=" << Quote((script_dir / "logs" / log).string()) << "\n";
    if (!o.partition.empty()) s << "#SBATCH --partition=" << Quote(o.partition) << "\n";
    for (const std::string& a : o.sbatch_args) s << "#SBATCH " << a << "\n";
  };
  FarmScripts scripts;
  scripts.num_tasks = num_tasks;
  {
    std::ostringstream s;
    s << "#!/bin/sh\n"
      << "# Written by `patchskin farm slurm`: renders " << o.input << " frames "
      << FramesText(range.first, range.last, range.step) << " (" << num_frames << " frames) as "
      << num_tasks << " tasks of up to " << o.chunk << " frames.\n"
      << "# Task k renders frames A + k*" << o.chunk << "*STEP onwards. Frames are written under a\n"
      << "# temporary name and renamed, and --resume keeps the finished ones, so a failed or\n"
      << "# pre-empted task is finished by running it again: sbatch --array=k " << (script_dir / "render_array.sbatch").string() << "\n"
      << "#SBATCH --array=0-" << num_tasks - 1 << "\n";
    header(s, job_name, "render_%A_%a.log");
    s << "set -eu\n"
      << "task=${SLURM_ARRAY_TASK_ID:?run this script with sbatch as a job array}\n"
      << "first=$((" << range.first << " + task * " << o.chunk << " * " << range.step << "))\n"
      << "last=$((first + " << o.chunk - 1 << " * " << range.step << "))\n"
      << "if [ \"$last\" -gt " << range.last << " ]; then last=" << range.last << "; fi\n"
      << "exec " << Quote(exe) << " render " << Quote(Absolute(o.input))
      << " --frames \"$first:$last:" << range.step << "\" --framing "
      << FramesText(range.first, range.last, range.step) << " --out " << Quote(pattern)
      << " --resume --no-sheet --no-video --quiet";
    if (o.fps > 0.0) s << " --fps " << rate;
    if (!o.motion.empty()) s << " --motion " << Quote(Absolute(o.motion));
    for (const std::string& a : o.render_args) s << " " << Quote(a);
    s << "\n";
    scripts.render_array = s.str();
  }
  {
    std::ostringstream s;
    s << "#!/bin/sh\n"
      << "# Written by `patchskin farm slurm`: the contact sheet and preview video, once every\n"
      << "# task of render_array.sbatch has succeeded (submit.sh adds --dependency=afterok).\n";
    header(s, job_name + "-sheet", "sheet_%j.log");
    s << "set -eu\n"
      << "exec " << Quote(exe) << " sheet " << Quote(pattern) << " --frames "
      << FramesText(range.first, range.last, range.step) << " --fps " << rate << " --overwrite\n";
    scripts.sheet = s.str();
  }
  {
    const std::string array_script = Quote((script_dir / "render_array.sbatch").string());
    const std::string sheet_script = Quote((script_dir / "sheet.sbatch").string());
    std::ostringstream s;
    s << "#!/bin/sh\n"
      << "# Written by `patchskin farm slurm`: submits the render array, then the contact\n"
      << "# sheet job that waits for every task to succeed. Extra arguments (e.g. --wait)\n"
      << "# go to the sheet job's sbatch. Safe to run again: finished frames are kept.\n"
      << "set -eu\n"
      << "array=$(sbatch --parsable " << array_script << ")\n"
      << "array=${array%%;*}\n"
      << "echo \"render array: job $array (" << num_tasks << " tasks)\"\n"
      << "echo \"sheet: job after $array succeeds\"\n"
      << "sbatch --parsable --dependency=afterok:$array --kill-on-invalid-dep=yes \"$@\" "
      << sheet_script << "\n";
    scripts.submit = s.str();
  }

  fs::create_directories(script_dir / "logs", ec);
  if (ec) {
    return ReportError(base::MakeError(base::ErrorCode::kIo, {script_dir.string(), 0, 0, {}},
                                       "cannot create the script folder: " + ec.message()));
  }
  for (const auto& [file, text, executable] :
       {std::tuple{"render_array.sbatch", &scripts.render_array, false},
        std::tuple{"sheet.sbatch", &scripts.sheet, false},
        std::tuple{"submit.sh", &scripts.submit, true}}) {
    const base::Status s = WriteText(script_dir / file, *text, executable);
    if (!s.ok()) return ReportError(s.error());
  }
  const std::string submit_path = (script_dir / "submit.sh").string();
  if (!o.submit) {
    std::printf("# %s\n%s\n# %s\n%s\n# %s\n%s\n# submit with:\nsh %s\n",
                (script_dir / "render_array.sbatch").c_str(), scripts.render_array.c_str(),
                (script_dir / "sheet.sbatch").c_str(), scripts.sheet.c_str(), submit_path.c_str(),
                scripts.submit.c_str(), Quote(submit_path).c_str());
    return 0;
  }
  std::fflush(stdout);
  std::vector<std::string> args{"/bin/sh", submit_path};
  if (o.wait) args.push_back("--wait");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, "/bin/sh", nullptr, nullptr, argv.data(), environ) != 0) {
    return ReportError(
        base::MakeError(base::ErrorCode::kIo, {submit_path, 0, 0, {}}, "cannot run /bin/sh"));
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "%s: error: submitting failed (exit %d)%s%s\n", submit_path.c_str(),
                 WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                 o.wait ? " or a job did not succeed; see the logs in " : "",
                 o.wait ? (script_dir / "logs").c_str() : "");
    return 3;
  }
  if (!o.wait) return 0;
  // sbatch --wait returns 0 for a sheet job that never ran (cancelled because
  // a task failed), so success is judged by the outputs: every frame and the
  // contact sheet.
  int missing = 0;
  std::string first_missing;
  for (const OutputFrame& f : plan->frames) {
    const base::Result<std::string> p = render::ExpandFramePattern(pattern, f.number);
    if (p.ok() && fs::is_regular_file(*p, ec)) continue;
    if (missing++ == 0) first_missing = p.ok() ? *p : pattern;
  }
  const fs::path sheet_path = frames_dir / "contact_sheet.png";
  if (missing > 0 || !fs::is_regular_file(sheet_path, ec)) {
    std::fprintf(stderr, "%s: error: the jobs did not finish: %d of %d frames missing%s; see the logs in %s\n",
                 missing > 0 ? first_missing.c_str() : sheet_path.c_str(), missing, num_frames,
                 missing > 0 ? "" : ", no contact sheet", (script_dir / "logs").c_str());
    return 3;
  }
  return 0;
}

}  // namespace app
