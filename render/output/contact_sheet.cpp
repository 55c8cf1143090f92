#include "render/output/contact_sheet.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace render {
namespace {

using base::ErrorCode;
using base::FileLoc;
using base::MakeError;

constexpr std::int64_t kMaxSheetPixels = std::int64_t{1} << 26;

base::Error SheetError(const std::string& what) {
  return base::InvalidArgument(FileLoc{}, "contact sheet: " + what);
}

// Image rows as an OpenCV matrix without a copy (4 floats per pixel).
cv::Mat Wrap(const Image& img) {
  return cv::Mat(img.height, img.width, CV_32FC4, const_cast<glm::vec4*>(img.rgba.data()));
}

}  // namespace

Result<ContactSheetLayout> ComputeContactSheetLayout(int num_frames, int frame_width,
                                                     int frame_height,
                                                     const ContactSheetOptions& o) {
  if (num_frames <= 0) return SheetError("expected at least one frame");
  if (frame_width <= 0 || frame_height <= 0) return SheetError("expected a non-empty frame size");
  if (o.columns < 1 || o.thumb_width < 8 || o.padding < 0 || o.label_height < 0) {
    return SheetError("expected columns >= 1, thumb_width >= 8, padding >= 0, label_height >= 0");
  }
  ContactSheetLayout l;
  l.columns = std::min(o.columns, num_frames);
  l.rows = (num_frames + l.columns - 1) / l.columns;
  l.thumb_width = o.thumb_width;
  l.thumb_height = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(o.thumb_width) * frame_height /
                                      frame_width)));
  const std::int64_t w = std::int64_t{l.columns} * l.thumb_width +
                         std::int64_t{l.columns + 1} * o.padding;
  const std::int64_t h = std::int64_t{l.rows} * (l.thumb_height + o.label_height) +
                         std::int64_t{l.rows + 1} * o.padding;
  if (w * h > kMaxSheetPixels) {
    return SheetError("sheet of " + std::to_string(w) + "x" + std::to_string(h) +
                      " pixels is too large (use fewer frames or smaller thumbnails)");
  }
  l.width = static_cast<int>(w);
  l.height = static_cast<int>(h);
  return l;
}

ContactSheetBuilder::~ContactSheetBuilder() = default;

Result<std::unique_ptr<ContactSheetBuilder>> ContactSheetBuilder::Create(
    int num_frames, int frame_width, int frame_height, const ContactSheetOptions& options) {
  Result<ContactSheetLayout> layout =
      ComputeContactSheetLayout(num_frames, frame_width, frame_height, options);
  if (!layout) return layout.error();
  std::unique_ptr<ContactSheetBuilder> b(new ContactSheetBuilder());
  b->options_ = options;
  b->layout_ = *layout;
  b->num_frames_ = num_frames;
  b->frame_width_ = frame_width;
  b->frame_height_ = frame_height;
  b->sheet_ = Image(layout->width, layout->height, options.background);
  return b;
}

Status ContactSheetBuilder::Add(const Image& frame, int frame_number) {
  if (added_ >= num_frames_) {
    return SheetError("more frames added than the " + std::to_string(num_frames_) + " announced");
  }
  if (frame.width != frame_width_ || frame.height != frame_height_ ||
      frame.rgba.size() != static_cast<std::size_t>(frame.width) *
                               static_cast<std::size_t>(frame.height)) {
    return SheetError("expected a " + std::to_string(frame_width_) + "x" +
                      std::to_string(frame_height_) + " frame, found " +
                      std::to_string(frame.width) + "x" + std::to_string(frame.height));
  }
  const ContactSheetLayout& l = layout_;
  const int col = added_ % l.columns;
  const int row = added_ / l.columns;
  const int x0 = options_.padding + col * (l.thumb_width + options_.padding);
  const int y0 = options_.padding + row * (l.thumb_height + options_.label_height + options_.padding);
  try {
    cv::Mat sheet = Wrap(sheet_);
    cv::Mat cell = sheet(cv::Rect(x0, y0, l.thumb_width, l.thumb_height));
    cv::resize(Wrap(frame), cell, cell.size(), 0.0, 0.0, cv::INTER_AREA);
    if (options_.label_height > 0) {
      const std::string text = std::to_string(frame_number);
      const int font = cv::FONT_HERSHEY_SIMPLEX;
      // Scale the glyphs to ~70% of the strip height.
      const double scale = 0.7 * options_.label_height / 22.0;
      int baseline = 0;
      const cv::Size size = cv::getTextSize(text, font, scale, 1, &baseline);
      const int tx = x0 + std::max(0, (l.thumb_width - size.width) / 2);
      const int ty = y0 + l.thumb_height + (options_.label_height + size.height) / 2;
      const glm::vec4& c = options_.text_color;
      cv::putText(sheet, text, cv::Point(tx, ty), font, scale, cv::Scalar(c.r, c.g, c.b, c.a), 1,
                  cv::LINE_AA);
    }
  } catch (const cv::Exception& e) {
    return MakeError(ErrorCode::kInternal, FileLoc{}, std::string("OpenCV: ") + e.what());
  }
  ++added_;
  return Status::Ok();
}

Result<Image> MakeContactSheet(std::span<const NumberedFrame> frames,
                               const ContactSheetOptions& options) {
  if (frames.empty() || frames[0].image == nullptr)
    return SheetError("expected at least one frame");
  Result<std::unique_ptr<ContactSheetBuilder>> builder = ContactSheetBuilder::Create(
      static_cast<int>(frames.size()), frames[0].image->width, frames[0].image->height, options);
  if (!builder) return builder.error();
  for (const NumberedFrame& f : frames) {
    if (f.image == nullptr) return SheetError("null frame");
    if (Status s = (*builder)->Add(*f.image, f.frame_number); !s) return s.error();
  }
  return (*builder)->sheet();
}

std::int64_t ContactSheetPick(int k, int count, std::int64_t num_frames) {
  if (count <= 1 || num_frames <= 1) return 0;
  const std::int64_t span = num_frames - 1, steps = count - 1;
  return (static_cast<std::int64_t>(k) * span + steps / 2) / steps;
}

int ContactSheetColumns(int num_frames, int max_columns) {
  max_columns = std::max(max_columns, 1);
  if (num_frames <= max_columns) return std::max(num_frames, 1);
  const int rows = (num_frames + max_columns - 1) / max_columns;
  return (num_frames + rows - 1) / rows;
}

}  // namespace render
