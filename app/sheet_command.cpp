#include "app/sheet_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "app/frame_plan.h"
#include "app/exit_code.h"
#include "render/output/contact_sheet.h"
#include "render/output/image_io.h"
#include "render/output/video_writer.h"

namespace app {
namespace {

// As render: at most this many frames on the sheet.
constexpr int kMaxSheetFrames = 24;
// Upper bound on frame numbers (ParseFrames needs a length).
constexpr int kMaxFrameNumber = 10'000'000;

// True for "A:B" or "A:B:STEP" with every part a non-empty run of digits: a sheet
// needs both ends of the range, which ParseFrames lets a render leave open.
bool IsClosedRange(const std::string& text) {
  int parts = 1;
  bool digit_in_part = false;
  for (const char c : text) {
    if (c == ':') {
      if (!digit_in_part) return false;
      ++parts;
      digit_in_part = false;
    } else if (c >= '0' && c <= '9') {
      digit_in_part = true;
    } else {
      return false;
    }
  }
  return digit_in_part && (parts == 2 || parts == 3);
}

}  // namespace

int RunSheet(const SheetOptions& o) {
  if (!IsClosedRange(o.frames)) {
    return ReportError(
        ArgError("--frames", "expected A:B[:STEP] with both ends, found '" + o.frames + "'"));
  }
  base::Result<FrameRange> range = ParseFrames(o.frames, kMaxFrameNumber);
  if (!range.ok()) return ReportError(range.error());
  if (!(o.fps > 0.0) || o.fps > 10000.0)
    return ReportError(ArgError("--fps", "expected 0 < fps <= 10000"));
  if (!render::HasFramePlaceholder(o.pattern)) {
    return ReportError(ArgError(
        "pattern",
        "the pattern '" + o.pattern + "' needs one frame placeholder such as #### or %04d"));
  }

  // Every frame must exist before anything is written.
  std::vector<std::pair<int, std::string>> frames;
  std::string first_missing;
  int missing = 0;
  for (int f = range->first; f <= range->last; f += range->step) {
    base::Result<std::string> path = render::ExpandFramePattern(o.pattern, f);
    if (!path.ok()) return ReportError(path.error());
    std::error_code ec;
    if (!std::filesystem::is_regular_file(*path, ec)) {
      if (missing++ == 0) first_missing = *path;
    }
    frames.emplace_back(f, std::move(*path));
  }
  if (missing > 0) {
    return ReportError(base::MakeError(base::ErrorCode::kIo, {first_missing, 0, 0, {}},
                                       "frame missing (" + std::to_string(missing) + " of " +
                                           std::to_string(frames.size()) +
                                           " frames are missing; render them first)"));
  }
  const std::filesystem::path dir = std::filesystem::path(frames.front().second).parent_path();
  const std::string sheet_path = (dir / "contact_sheet.png").string();
  const std::string video_path = (dir / "preview.mp4").string();
  if (!o.overwrite) {
    for (const auto& [skip, path] : {std::pair{o.no_sheet, sheet_path}, std::pair{o.no_video, video_path}}) {
      if (!skip && std::filesystem::exists(path)) {
        return ReportError(
            base::InvalidArgument({path, 0, 0, {}}, "exists; pass --overwrite to replace it"));
      }
    }
  }

  base::Result<render::Image> first = render::ReadImage(frames.front().second);
  if (!first.ok()) return ReportError(first.error());
  const int width = first->width, height = first->height;
  const int n = static_cast<int>(frames.size());
  const int sheet_count = std::min(kMaxSheetFrames, n);
  std::unique_ptr<render::ContactSheetBuilder> sheet;
  if (!o.no_sheet) {
    auto b = render::ContactSheetBuilder::Create(
        sheet_count, width, height, {.columns = render::ContactSheetColumns(sheet_count)});
    if (!b.ok()) return ReportError(b.error());
    sheet = std::move(*b);
  }
  std::unique_ptr<render::VideoWriter> video;
  if (!o.no_video) {
    auto v = render::VideoWriter::Open(video_path, width & ~1, height & ~1,
                                       {.fps = o.fps / range->step});
    if (!v.ok()) return ReportError(v.error());
    video = std::move(*v);
  }
  int next_sheet = 0;
  for (int i = 0; i < n && (sheet || video); ++i) {
    // The same frames as render's sheet: even steps, first and last included.
    const bool on_sheet = sheet && next_sheet < sheet_count &&
                          i == render::ContactSheetPick(next_sheet, sheet_count, n);
    if (!on_sheet && !video) continue;
    base::Result<render::Image> image =
        i == 0 ? std::move(first) : render::ReadImage(frames[static_cast<std::size_t>(i)].second);
    if (!image.ok()) return ReportError(image.error());
    if (image->width != width || image->height != height) {
      return ReportError(
          base::InvalidArgument({frames[static_cast<std::size_t>(i)].second, 0, 0, {}},
                                "expected " + std::to_string(width) + "x" + std::to_string(height) +
                                    " like the first frame, found " + std::to_string(image->width) +
                                    "x" + std::to_string(image->height)));
    }
    if (on_sheet) {
      const base::Status s = sheet->Add(*image, frames[static_cast<std::size_t>(i)].first);
      if (!s.ok()) return ReportError(s.error());
      ++next_sheet;
    }
    if (video) {
      const base::Status s = video->AddFrame(*image);
      if (!s.ok()) return ReportError(s.error());
    }
  }
  if (sheet) {
    const base::Status s = render::WriteImage(sheet->sheet(), sheet_path, {});
    if (!s.ok()) return ReportError(s.error());
    if (!o.quiet) std::printf("contact sheet: %s\n", sheet_path.c_str());
  }
  if (video) {
    const base::Status s = video->Close();
    if (!s.ok()) return ReportError(s.error());
    if (!o.quiet) {
      std::printf("video:         %s (%s)\n", video->path().c_str(),
                  render::VideoCodecName(video->codec()));
    }
  }
  return 0;
}

}  // namespace app
