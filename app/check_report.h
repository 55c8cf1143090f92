#pragma once
// The results of `patchskin check` and the two files written from them: an HTML
// page for people and a JUnit XML file for CI test reporters.
//
// HTML (WriteCheckHtml): one self-contained page (no network, no external file:
// images are data: URIs of the PNG files, a line of inline script drives the
// slider). Cases in order of severity (errors, failures, missing references,
// warnings, passes), then manifest order; each shows, for its worst frame, the
// reference, the new frame, the amplified difference and a slider between
// reference and new, and a table of every frame's figures.
// JUnit (WriteCheckJUnit): one <testsuite> named after the manifest, one
// <testcase> per case; failures and missing references are <failure>, errors
// <error>, warnings pass with a <system-out> note. No times are written, so the
// same results give the same bytes.
// Both are written atomically (a temporary name, renamed when complete).
// Cost: the page holds every shown PNG base64-encoded (4/3 of its bytes).

#include <optional>
#include <string>
#include <vector>

#include "base/error.h"
#include "render/output/image_file_compare.h"

namespace app {

// Severity order: the most severe first (the report's order).
enum class CaseStatus { kError = 0, kFail = 1, kMissing = 2, kWarn = 3, kPass = 4 };

const char* CaseStatusName(CaseStatus s);  // "ERROR", "FAIL", "MISSING", "WARN", "PASS"

struct FrameCheck {
  int number = 0;
  std::string new_path;     // the rendered frame
  std::string ref_path;     // its reference (may not exist)
  std::string diff_path;    // amplified difference image, empty when none was written
  float diff_scale = 1.0f;  // its amplification
  bool missing = false;     // no reference file
  std::optional<render::FileCompareResult> result;  // when compared
};

struct CaseCheck {
  std::string name;
  CaseStatus status = CaseStatus::kPass;
  std::string summary;           // the one-line description after the name
  std::string error;             // ERROR: what went wrong (render's stderr, unreadable file)
  std::vector<FrameCheck> frames;
  int worst = -1;                // index into frames of the frame shown, -1 when none
  render::IdiffThresholds thresholds;
  bool updated = false;          // --update wrote its frames as references
  int replaced = 0, added = 0;   // reference files replaced / created by the update
};

struct CheckRun {
  std::string manifest;          // as given
  std::string references;        // the reference folder
  std::vector<CaseCheck> cases;  // manifest order
};

// Cases in report order (severity, then manifest order), as indices.
std::vector<std::size_t> ReportOrder(const CheckRun& run);

// A number as the reports print it (printf %g).
std::string FormatNumber(double v);

[[nodiscard]] base::Status WriteCheckHtml(const CheckRun& run, const std::string& path);
[[nodiscard]] base::Status WriteCheckJUnit(const CheckRun& run, const std::string& path);

}  // namespace app
