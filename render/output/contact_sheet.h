#pragma once
// Contact sheet: a grid of downscaled frames, each with its frame number written
// under it, for a quick look at a whole sequence in one picture.
//
// Layout (all in pixels; n frames, c = min(columns, n) columns, r = ceil(n / c) rows):
//   cell      = thumb_width x (thumb_height + label_height)
//   width     = c * thumb_width + (c + 1) * padding
//   height    = r * (thumb_height + label_height) + (r + 1) * padding
// thumb_height keeps the frames' aspect: round(thumb_width * frame_h / frame_w).
// Frames fill the grid row by row in the order added. Thumbnails are area-averaged
// in linear light (OpenCV INTER_AREA); labels are drawn with cv::putText.
//
// The builder downsizes each frame as it is added, so a long sequence costs one
// thumbnail per frame, not one frame.

#include <cstdint>
#include <memory>
#include <span>

#include "base/error.h"
#include "render/image.h"

namespace render {

using base::Result;
using base::Status;

struct ContactSheetOptions {
  int columns = 6;          // >= 1
  int thumb_width = 192;    // pixels, >= 8
  int padding = 6;          // pixels between and around cells, >= 0
  int label_height = 20;    // pixels of label strip under each thumbnail, >= 0 (0: no labels)
  glm::vec4 background{0.05f, 0.05f, 0.05f, 1.0f};  // linear RGBA
  glm::vec4 text_color{1.0f, 1.0f, 1.0f, 1.0f};     // linear RGBA
};

// Sheet size for `num_frames` frames of frame_width x frame_height (see layout).
struct ContactSheetLayout {
  int columns = 0;
  int rows = 0;
  int thumb_width = 0;
  int thumb_height = 0;
  int width = 0;   // whole sheet
  int height = 0;
};
[[nodiscard]] Result<ContactSheetLayout> ComputeContactSheetLayout(
    int num_frames, int frame_width, int frame_height, const ContactSheetOptions& options);

class ContactSheetBuilder {
 public:
  // All frames must be frame_width x frame_height. Errors: kInvalidArgument for
  // option values out of range, a non-positive count or size, or a sheet over 2^26 pixels.
  [[nodiscard]] static Result<std::unique_ptr<ContactSheetBuilder>> Create(
      int num_frames, int frame_width, int frame_height, const ContactSheetOptions& options = {});
  ~ContactSheetBuilder();

  // Puts `frame` into the next cell, labelled `frame_number`. Errors: wrong size,
  // more frames than announced.
  [[nodiscard]] Status Add(const Image& frame, int frame_number);

  // The sheet so far (cells not yet filled show the background).
  const Image& sheet() const { return sheet_; }
  const ContactSheetLayout& layout() const { return layout_; }
  int frames_added() const { return added_; }

 private:
  ContactSheetBuilder() = default;
  ContactSheetOptions options_;
  ContactSheetLayout layout_;
  int num_frames_ = 0;
  int frame_width_ = 0;
  int frame_height_ = 0;
  int added_ = 0;
  Image sheet_;
};

// Which frames a sheet of `count` thumbnails shows out of `num_frames` (in
// order): the k-th (0 <= k < count) is round(k (num_frames - 1) / (count - 1)),
// even steps from the first frame to the last, both included. count <=
// num_frames keeps the picks distinct and increasing.
std::int64_t ContactSheetPick(int k, int count, std::int64_t num_frames);

// Columns for `num_frames` thumbnails, at most `max_columns`: as few rows as
// that allows, filled as evenly as possible (10 frames: 2 rows of 5, not 6 + 4).
int ContactSheetColumns(int num_frames, int max_columns = 6);

// One frame for MakeContactSheet.
struct NumberedFrame {
  const Image* image = nullptr;  // not owned, not null
  int frame_number = 0;
};

// Whole sheet in one call (all frames the same size).
[[nodiscard]] Result<Image> MakeContactSheet(std::span<const NumberedFrame> frames,
                                             const ContactSheetOptions& options = {});

}  // namespace render
