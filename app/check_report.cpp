#include "app/check_report.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "render/output/image_io.h"

namespace app {

std::string FormatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

namespace {

namespace fs = std::filesystem;

// Text for an XML/HTML attribute or element: the five special characters
// escaped, control characters other than tab and newline dropped.
std::string Escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char ch : s) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default:
        if (static_cast<unsigned char>(ch) >= 0x20 || ch == '\n' || ch == '\t') out += ch;
    }
  }
  return out;
}

std::string Base64(const std::string& bytes) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const auto b = [&](std::size_t k) {
      return k < bytes.size() ? static_cast<unsigned>(static_cast<unsigned char>(bytes[k])) : 0u;
    };
    const unsigned v = b(i) << 16 | b(i + 1) << 8 | b(i + 2);
    out += kDigits[v >> 18 & 63];
    out += kDigits[v >> 12 & 63];
    out += i + 1 < bytes.size() ? kDigits[v >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[v & 63] : '=';
  }
  return out;
}

// A PNG file as a data: URI, or empty when it cannot be read.
std::string DataUri(const std::string& path) {
  if (path.empty()) return {};
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return "data:image/png;base64," + Base64(bytes);
}

// Writes `text` to `path` under a temporary name, then renames it.
base::Status WriteAtomically(const std::string& path, const std::string& text) {
  const base::FileLoc loc{path, 0, 0, {}};
  std::error_code ec;
  const fs::path dir = fs::path(path).parent_path();
  if (!dir.empty()) fs::create_directories(dir, ec);
  const std::string temp = render::TemporaryPathFor(path);
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) {
      fs::remove(temp, ec);
      return base::MakeError(base::ErrorCode::kIo, loc, "cannot write the file");
    }
  }
  fs::rename(temp, path, ec);
  if (ec) {
    fs::remove(temp, ec);
    return base::MakeError(base::ErrorCode::kIo, loc, "cannot write the file: " + ec.message());
  }
  return base::Status::Ok();
}

const char* StatusClass(CaseStatus s) {
  switch (s) {
    case CaseStatus::kError: return "error";
    case CaseStatus::kFail: return "fail";
    case CaseStatus::kMissing: return "missing";
    case CaseStatus::kWarn: return "warn";
    case CaseStatus::kPass: return "pass";
  }
  return "?";
}

std::string FrameVerdict(const FrameCheck& f) {
  if (f.missing) return "no reference";
  if (!f.result) return "not compared";
  if (!f.result->same_size) return "FAILURE (size differs)";
  return render::VerdictName(f.result->verdict);
}

std::string FrameRow(const FrameCheck& f, bool worst) {
  std::ostringstream s;
  s << "<tr" << (worst ? " class=\"worst\"" : "") << "><td>" << f.number << "</td><td>"
    << Escape(FrameVerdict(f)) << "</td>";
  if (f.result) {
    const render::FileCompareResult& r = *f.result;
    const double over = r.num_pixels > 0 ? 100.0 * static_cast<double>(r.num_fail) /
                                               static_cast<double>(r.num_pixels)
                                         : 0.0;
    s << "<td>" << FormatNumber(r.max_error);
    if (r.max_error > 0.0) {
      s << " @ (" << r.max_x << ", " << r.max_y << ", "
        << Escape(r.channels[static_cast<std::size_t>(r.max_channel)]) << ")";
    }
    s << "</td><td>" << FormatNumber(r.mean_error) << "</td><td>" << FormatNumber(r.psnr_db)
      << "</td><td>" << r.num_fail << " (" << FormatNumber(over) << "%)</td>";
  } else {
    s << "<td colspan=\"4\"></td>";
  }
  s << "</tr>\n";
  return s.str();
}

// Displayed width: small frames at twice their size, at most 480 pixels.
int ShownWidth(const FrameCheck& f) {
  const int w = f.result ? f.result->width_a : 160;
  return std::min(480, w < 320 ? 2 * w : w);
}

std::string Figure(const std::string& uri, const std::string& caption, int width,
                   const std::string& cls = "") {
  if (uri.empty()) return {};
  return "<figure><img" + (cls.empty() ? "" : " class=\"" + cls + "\"") + " style=\"width:" +
         std::to_string(width) + "px\" src=\"" + uri + "\" alt=\"" + Escape(caption) +
         "\"><figcaption>" + Escape(caption) + "</figcaption></figure>\n";
}

std::string CaseSection(const CaseCheck& c) {
  std::ostringstream s;
  s << "<section class=\"case status-" << StatusClass(c.status) << "\" id=\"case-" << Escape(c.name)
    << "\">\n<h2>" << CaseStatusName(c.status) << " &middot; " << Escape(c.name) << "</h2>\n<p>"
    << Escape(c.summary);
  if (c.updated) {
    s << " &mdash; references updated: " << c.replaced << " replaced, " << c.added << " added";
  }
  s << "</p>\n";
  if (!c.error.empty()) s << "<pre>" << Escape(c.error) << "</pre>\n";
  if (c.worst >= 0) {
    const FrameCheck& f = c.frames[static_cast<std::size_t>(c.worst)];
    const int w = ShownWidth(f);
    const std::string ref = f.missing ? "" : DataUri(f.ref_path);
    const std::string neu = DataUri(f.new_path);
    const std::string frame = " (frame " + std::to_string(f.number) + ")";
    s << "<div class=\"images\">\n"
      << Figure(ref, "reference" + frame, w) << Figure(neu, "new" + frame, w)
      << Figure(DataUri(f.diff_path), "difference x" + FormatNumber(f.diff_scale), w);
    if (!ref.empty() && !neu.empty()) {
      // The new frame over the reference, uncovered from the slider's position on.
      s << "<figure><div class=\"swipe\"><img style=\"width:" << w << "px\" src=\"" << ref
        << "\" alt=\"reference\"><img class=\"new\" style=\"width:" << w << "px\" src=\"" << neu
        << "\" alt=\"new\"></div><input type=\"range\" min=\"0\" max=\"100\" value=\"50\" "
           "style=\"width:"
        << w
        << "px\" oninput=\"this.previousElementSibling.lastElementChild.style.clipPath="
           "'inset(0 0 0 '+this.value+'%)'\"><figcaption>slider: reference (left) | new "
           "(right)</figcaption></figure>\n";
    }
    s << "</div>\n";
  }
  if (!c.frames.empty()) {
    s << "<table><tr><th>frame</th><th>verdict</th><th>max error</th><th>mean error</th>"
         "<th>PSNR dB</th><th>pixels over fail</th></tr>\n";
    for (std::size_t i = 0; i < c.frames.size(); ++i) {
      s << FrameRow(c.frames[i], static_cast<int>(i) == c.worst);
    }
    s << "</table>\n";
  }
  s << "</section>\n";
  return s.str();
}

constexpr const char* kStyle = R"(<style>
body{font:14px sans-serif;margin:0;background:#f2f2f2;color:#222}
header{background:#3a3a3a;color:#fff;padding:8px 16px}
header h1{font-size:18px;margin:4px 0}
section.case{background:#fff;margin:12px 16px;border:1px solid #bbb}
section.case h2{margin:0;padding:6px 12px;color:#fff;font-size:16px}
section.case p,section.case pre{margin:6px 12px}
.status-error h2,.status-fail h2{background:#c62828}
.status-missing h2{background:#6a1b9a}
.status-warn h2{background:#e68a00}
.status-pass h2{background:#2e7d32}
.images{display:flex;flex-wrap:wrap;gap:10px;padding:6px 12px}
figure{margin:0}
figcaption{font-size:12px;color:#555}
img{display:block;image-rendering:pixelated}
.swipe{position:relative}
.swipe img.new{position:absolute;left:0;top:0;clip-path:inset(0 0 0 50%)}
table{border-collapse:collapse;margin:6px 12px 10px}
td,th{border:1px solid #ccc;padding:2px 8px;text-align:left;font-size:13px}
tr.worst{background:#fff3c4}
</style>)";

}  // namespace

const char* CaseStatusName(CaseStatus s) {
  switch (s) {
    case CaseStatus::kError: return "ERROR";
    case CaseStatus::kFail: return "FAIL";
    case CaseStatus::kMissing: return "MISSING";
    case CaseStatus::kWarn: return "WARN";
    case CaseStatus::kPass: return "PASS";
  }
  return "?";
}

std::vector<std::size_t> ReportOrder(const CheckRun& run) {
  std::vector<std::size_t> order(run.cases.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&run](std::size_t a, std::size_t b) {
    return static_cast<int>(run.cases[a].status) < static_cast<int>(run.cases[b].status);
  });
  return order;
}

base::Status WriteCheckHtml(const CheckRun& run, const std::string& path) {
  int counts[5] = {0, 0, 0, 0, 0};
  for (const CaseCheck& c : run.cases) ++counts[static_cast<int>(c.status)];
  std::ostringstream s;
  s << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>patchskin check: "
    << Escape(run.manifest) << "</title>\n"
    << kStyle << "\n</head><body>\n<header><h1>patchskin check " << Escape(run.manifest)
    << "</h1>\n<p>" << run.cases.size() << " cases: " << counts[4] << " passed, " << counts[1]
    << " failed, " << counts[3] << " with warnings, " << counts[2] << " missing references, "
    << counts[0] << " errors. References: " << Escape(run.references) << "</p></header>\n";
  for (std::size_t i : ReportOrder(run)) s << CaseSection(run.cases[i]);
  s << "</body></html>\n";
  return WriteAtomically(path, s.str());
}

base::Status WriteCheckJUnit(const CheckRun& run, const std::string& path) {
  int failures = 0, errors = 0;
  for (const CaseCheck& c : run.cases) {
    if (c.status == CaseStatus::kError) ++errors;
    if (c.status == CaseStatus::kFail || c.status == CaseStatus::kMissing) ++failures;
  }
  const std::string suite = fs::path(run.manifest).stem().string();
  std::ostringstream s;
  const std::string counts = " tests=\"" + std::to_string(run.cases.size()) + "\" failures=\"" +
                             std::to_string(failures) + "\" errors=\"" + std::to_string(errors) +
                             "\" skipped=\"0\"";
  s << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"patchskin check\"" << counts
    << ">\n  <testsuite name=\"" << Escape(suite) << "\"" << counts << ">\n";
  for (const CaseCheck& c : run.cases) {
    s << "    <testcase classname=\"patchskin.check." << Escape(suite) << "\" name=\""
      << Escape(c.name) << "\"";
    std::string details;
    for (const FrameCheck& f : c.frames) {
      details += "frame " + std::to_string(f.number) + ": " + FrameVerdict(f);
      if (f.result) details += ", max error " + FormatNumber(f.result->max_error);
      details += "\n";
    }
    switch (c.status) {
      case CaseStatus::kPass:
        s << "/>\n";
        break;
      case CaseStatus::kWarn:
        s << ">\n      <system-out>" << Escape("WARNING: " + c.summary + "\n" + details)
          << "</system-out>\n    </testcase>\n";
        break;
      case CaseStatus::kFail:
      case CaseStatus::kMissing:
        s << ">\n      <failure type=\""
          << (c.status == CaseStatus::kFail ? "ImageDifference" : "MissingReference")
          << "\" message=\"" << Escape(c.summary) << "\">" << Escape(details)
          << "</failure>\n    </testcase>\n";
        break;
      case CaseStatus::kError:
        s << ">\n      <error type=\"CheckError\" message=\"" << Escape(c.summary) << "\">"
          << Escape(c.error) << "</error>\n    </testcase>\n";
        break;
    }
  }
  s << "  </testsuite>\n</testsuites>\n";
  return WriteAtomically(path, s.str());
}

}  // namespace app
