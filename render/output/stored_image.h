#pragma once
// What a frame looks like after a round trip through its file: the values
// render::ReadImage returns for an image render::WriteImage stored, computed
// without the file. A resumed render (app/output_guard.h, --resume) rebuilds
// its contact sheet from the finished frames it reads back; feeding the sheet
// these values in an uninterrupted render too makes both sheets byte-identical.
//
//   PNG, 8-bit TIFF  colour: Srgb8ToLinear(LinearToSrgb8(c)); alpha: its 8-bit
//                    code as OpenImageIO converts it to float; depth dropped
//   EXR              colour and alpha through half precision (OpenImageIO's
//                    conversion); depth kept (stored as float)
//   JPEG, 16-bit TIFF  kUnsupported: JPEG is lossy and 16-bit codes go through
//                    a different curve; callers keep the image as it is.

#include "base/error.h"
#include "render/image.h"
#include "render/output/image_io.h"

namespace render {

// The image ReadImage would return after WriteImage(image, path, options) for
// a path of `format`. Errors: kUnsupported (see above).
[[nodiscard]] Result<Image> AsStored(const Image& image, ImageFormat format,
                                     const WriteOptions& options = {});

}  // namespace render
