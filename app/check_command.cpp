#include "app/check_command.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <regex>

#include "app/check_manifest.h"
#include "app/check_report.h"
#include "app/render_command.h"
#include "render/output/image_compare.h"
#include "render/output/image_io.h"

namespace app {
namespace {

namespace fs = std::filesystem;

int Error(const base::Error& e) {
  std::fprintf(stderr, "%s\n", e.ToString().c_str());
  return kCheckError;
}

// Sends this process's stderr to a temporary file while alive; Text() returns
// what was written. The render reports its errors there, and check puts them in
// its reports (and passes them on to the real stderr).
class StderrCapture {
 public:
  StderrCapture() {
    std::fflush(stderr);
    file_ = std::tmpfile();
    saved_ = dup(2);
    if (file_ != nullptr && saved_ >= 0) dup2(fileno(file_), 2);
  }
  ~StderrCapture() { Restore(); if (file_ != nullptr) std::fclose(file_); }
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;

  std::string Text() {
    Restore();
    std::string text;
    if (file_ == nullptr) return text;
    std::rewind(file_);
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof(buf), file_)) > 0;) text.append(buf, n);
    return text;
  }

 private:
  void Restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    dup2(saved_, 2);
    close(saved_);
    saved_ = -1;
  }
  std::FILE* file_ = nullptr;
  int saved_ = -1;
};

// Removes the frames and differences a previous check left in `dir`.
void ClearCaseFolder(const fs::path& dir) {
  static const std::regex kOwn(R"((frame|diff)_-?\d+\.png)");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (std::regex_match(e.path().filename().string(), kOwn)) fs::remove(e.path(), ec);
  }
}

// The frames in `dir`, by number.
std::vector<std::pair<int, fs::path>> ListFrames(const fs::path& dir) {
  static const std::regex kFrame(R"(frame_(-?\d+)\.png)");
  std::vector<std::pair<int, fs::path>> frames;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (std::regex_match(name, m, kFrame)) frames.emplace_back(std::stoi(m[1].str()), e.path());
  }
  std::sort(frames.begin(), frames.end());
  return frames;
}

// Severity of a frame, for picking the one to show: failure, missing, warning, pass.
int FrameSeverity(const FrameCheck& f) {
  if (f.missing) return 2;
  if (!f.result) return 0;
  if (!f.result->same_size || f.result->verdict == render::CompareVerdict::kFailure) return 3;
  return f.result->verdict == render::CompareVerdict::kWarning ? 1 : 0;
}

// Writes the amplified |new - reference| of a frame (colour, sRGB values),
// scaled so the largest difference is near white (x1 .. x1000).
void WriteDiff(FrameCheck& f, const fs::path& dir) {
  base::Result<render::Image> a = render::ReadImage(f.new_path);
  base::Result<render::Image> b = render::ReadImage(f.ref_path);
  if (!a.ok() || !b.ok()) return;
  const double max_error = f.result ? f.result->max_error : 0.0;
  f.diff_scale = static_cast<float>(std::clamp(max_error > 0.0 ? 1.0 / max_error : 1.0, 1.0, 1000.0));
  base::Result<render::Image> diff = render::MakeDiffImage(*a, *b, f.diff_scale);
  if (!diff.ok()) return;
  char name[32];
  std::snprintf(name, sizeof(name), "diff_%04d.png", f.number);
  const std::string path = (dir / name).string();
  if (render::WriteImage(*diff, path, {}).ok()) f.diff_path = path;
}

// The case's status, worst frame and one-line summary from its compared frames.
void Judge(int unrendered, CaseCheck& c) {
  int worst_severity = -1;
  double worst_error = -1.0;
  int missing = 0, failing = 0, warning = 0;
  for (std::size_t i = 0; i < c.frames.size(); ++i) {
    const FrameCheck& f = c.frames[i];
    const int sev = FrameSeverity(f);
    missing += sev == 2;
    failing += sev == 3;
    warning += sev == 1;
    const double err = f.result ? f.result->max_error : 0.0;
    if (sev > worst_severity || (sev == worst_severity && err > worst_error)) {
      worst_severity = sev;
      worst_error = err;
      c.worst = static_cast<int>(i);
    }
  }
  const std::string n = std::to_string(c.frames.size());
  c.status = failing > 0   ? CaseStatus::kFail
             : missing > 0 ? CaseStatus::kMissing
             : warning > 0 ? CaseStatus::kWarn
                           : CaseStatus::kPass;
  const FrameCheck& w = c.frames[static_cast<std::size_t>(c.worst)];
  std::string s = n + " frames";
  if (missing > 0) s += ", " + std::to_string(missing) + " without a reference";
  if (failing > 0) s += ", " + std::to_string(failing) + " failing";
  if (warning > 0) s += ", " + std::to_string(warning) + " with warnings";
  if (unrendered > 0) s += " (" + std::to_string(unrendered) + " reference frames not rendered)";
  if (w.result) {
    const render::FileCompareResult& r = *w.result;
    if (r.max_error == 0.0) {
      s += (c.frames.size() > 1 ? ", all identical" : ", identical");
    } else {
      s += "; worst frame " + std::to_string(w.number) + ": max error " +
           FormatNumber(r.max_error) + " @ (" + std::to_string(r.max_x) + ", " +
           std::to_string(r.max_y) + ", " + r.channels[static_cast<std::size_t>(r.max_channel)] +
           "), " +
           FormatNumber(100.0 * static_cast<double>(r.num_fail) /
                        static_cast<double>(r.num_pixels)) +
           "% pixels over " + FormatNumber(c.thresholds.fail);
    }
    if (!r.same_size) {
      s += "; size " + std::to_string(r.width_a) + "x" + std::to_string(r.height_a) +
           ", reference " + std::to_string(r.width_b) + "x" + std::to_string(r.height_b);
    }
  }
  c.summary = s;
}

// Compares the rendered frames of a case with its references.
void CompareCase(const fs::path& new_dir, const fs::path& ref_dir, CaseCheck& c) {
  for (const auto& [number, path] : ListFrames(new_dir)) {
    FrameCheck f;
    f.number = number;
    f.new_path = path.string();
    f.ref_path = (ref_dir / path.filename()).string();
    std::error_code ec;
    if (!fs::exists(f.ref_path, ec)) {
      f.missing = true;
    } else {
      base::Result<render::FileCompareResult> r =
          render::CompareImageFiles(f.new_path, f.ref_path, c.thresholds);
      if (!r.ok()) {
        c.status = CaseStatus::kError;
        c.error += r.error().ToString() + "\n";
      } else {
        f.result = std::move(*r);
        if (FrameSeverity(f) > 0) WriteDiff(f, new_dir);
      }
    }
    c.frames.push_back(std::move(f));
  }
  if (c.status == CaseStatus::kError) {
    c.summary = "cannot compare: " + c.error.substr(0, c.error.find('\n'));
    return;
  }
  if (c.frames.empty()) {
    c.status = CaseStatus::kError;
    c.summary = "the render wrote no frame";
    return;
  }
  // References of frames the case no longer renders are named, not compared.
  int unrendered = 0;
  for (const auto& [number, path] : ListFrames(ref_dir)) {
    unrendered += !fs::exists(new_dir / path.filename());
  }
  Judge(unrendered, c);
}

// Copies the case's new frames over its references (each atomically).
base::Status UpdateReferences(const fs::path& ref_dir, CaseCheck& c) {
  std::error_code ec;
  fs::create_directories(ref_dir, ec);
  for (const FrameCheck& f : c.frames) {
    const fs::path target = ref_dir / fs::path(f.new_path).filename();
    const bool existed = fs::exists(target, ec);
    const std::string temp = render::TemporaryPathFor(target.string());
    fs::copy_file(f.new_path, temp, fs::copy_options::overwrite_existing, ec);
    if (!ec) fs::rename(temp, target, ec);
    if (ec) {
      fs::remove(temp, ec);
      return base::MakeError(base::ErrorCode::kIo, {target.string(), 0, 0, {}},
                             "cannot write the reference: " + ec.message());
    }
    ++(existed ? c.replaced : c.added);
  }
  c.updated = true;
  return base::Status::Ok();
}

// Renders one case into `new_dir` with the render command; false on failure
// (the render's messages in c.error).
bool RenderCase(const CheckCase& cs, const fs::path& new_dir, int threads, CaseCheck& c) {
  ClearCaseFolder(new_dir);
  RenderOptions o = cs.render;
  o.out = (new_dir / "frame_####.png").string();
  o.given.insert("--out");
  o.overwrite = true;
  o.no_sheet = o.no_video = o.quiet = true;
  o.print_outputs = false;
  if (o.given.count("--threads") == 0) o.threads = threads;
  int code = 0;
  std::string messages;
  {
    StderrCapture capture;
    code = RunRender(o);
    messages = capture.Text();
  }
  std::fputs(messages.c_str(), stderr);
  if (code == 0) return true;
  c.status = CaseStatus::kError;
  c.error = messages;
  const std::string first = messages.substr(0, messages.find('\n'));
  c.summary = "the render failed (exit " + std::to_string(code) + ")" + (first.empty() ? "" : ": " + first);
  return false;
}

void PrintCaseLine(const CaseCheck& c, std::size_t name_width) {
  std::string line = c.summary;
  if (c.updated) {
    line += " -> references updated (" + std::to_string(c.replaced) + " replaced, " +
            std::to_string(c.added) + " added)";
  }
  std::printf("%-8s %-*s  %s\n", CaseStatusName(c.status), static_cast<int>(name_width),
              c.name.c_str(), line.c_str());
  std::fflush(stdout);
}

}  // namespace

int RunCheck(const CheckOptions& options) {
  base::Result<CheckManifest> manifest = LoadCheckManifest(options.manifest);
  if (!manifest.ok()) return Error(manifest.error());
  const fs::path out = options.out.empty()
                           ? fs::path("out/check") / fs::path(options.manifest).stem()
                           : fs::path(options.out);
  CheckRun run;
  run.manifest = options.manifest;
  run.references = options.references.empty() ? manifest->references : options.references;
  std::size_t name_width = 4;
  for (const CheckCase& cs : manifest->cases) name_width = std::max(name_width, cs.name.size());

  int exit_code = kCheckPass;
  for (const CheckCase& cs : manifest->cases) {
    CaseCheck c;
    c.name = cs.name;
    c.thresholds = cs.thresholds;
    const fs::path new_dir = out / cs.name;
    const fs::path ref_dir = fs::path(run.references) / cs.name;
    std::error_code ec;
    fs::create_directories(new_dir, ec);
    if (RenderCase(cs, new_dir, options.threads, c)) CompareCase(new_dir, ref_dir, c);
    const bool differs = c.status != CaseStatus::kPass && c.status != CaseStatus::kError;
    if (c.status != CaseStatus::kError && (options.update_all || (options.update && differs))) {
      if (base::Status s = UpdateReferences(ref_dir, c); !s.ok()) {
        c.status = CaseStatus::kError;
        c.error = s.error().ToString();
        c.summary = "cannot update the references: " + c.error;
      }
    }
    PrintCaseLine(c, name_width);
    const int code = c.status == CaseStatus::kError                  ? kCheckError
                     : c.updated || c.status == CaseStatus::kPass   ? kCheckPass
                     : c.status == CaseStatus::kWarn                ? kCheckWarning
                                                                    : kCheckFail;
    exit_code = std::max(exit_code, code);
    run.cases.push_back(std::move(c));
  }

  int counts[5] = {0, 0, 0, 0, 0};
  int updated = 0;
  for (const CaseCheck& c : run.cases) {
    ++counts[static_cast<int>(c.status)];
    updated += c.updated;
  }
  std::printf("check: %zu cases: %d passed, %d failed, %d with warnings, %d missing references, "
              "%d errors",
              run.cases.size(), counts[4], counts[1], counts[3], counts[2], counts[0]);
  if (updated > 0) std::printf("; %d updated in %s", updated, run.references.c_str());
  std::printf("\n");
  const std::string html = options.html.empty() ? (out / "report.html").string() : options.html;
  if (base::Status s = WriteCheckHtml(run, html); !s.ok()) return Error(s.error());
  std::printf("report: %s\n", html.c_str());
  if (!options.junit.empty()) {
    if (base::Status s = WriteCheckJUnit(run, options.junit); !s.ok()) return Error(s.error());
    std::printf("junit:  %s\n", options.junit.c_str());
  }
  return exit_code;
}

}  // namespace app
