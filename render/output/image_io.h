#pragma once
// Reading and writing frame files. OpenImageIO does the encoding; it appears only
// in image_io.cpp. The format follows the file's extension:
//
//   .png          8-bit sRGB RGBA, zlib level WriteOptions::png_compression
//   .exr          half RGBA (linear), plus a float "Z" channel from Image::depth
//                 when it is present and WriteOptions::exr_write_depth is set
//   .tif / .tiff  8- or 16-bit sRGB RGBA (WriteOptions::tiff_bits)
//   .jpg / .jpeg  8-bit sRGB RGB (alpha dropped), quality WriteOptions::jpeg_quality
//
// Writing is atomic: the encoder writes "<dir>/.<name>.tmp-<pid>" and the file
// is renamed to its final name only once complete, so no half-written frame ever
// exists under the final name; on any failure the temporary file is removed and
// the final name is left untouched.
//
// Colour: Image holds linear RGB; 8/16-bit files store sRGB-encoded values
// (IEC 61966-2-1 transfer curve, below), float files store linear values.
// Alpha is never encoded. Alpha is straight (not premultiplied) in every format;
// EXR channels hold the Image values unchanged (OpenEXR's convention would be
// premultiplied; keeping them straight makes the round trip lossless but for half
// precision, and our frames are opaque but for edge coverage).

#include <cstdint>
#include <string>

#include "base/error.h"
#include "render/image.h"

namespace render {

using base::Result;
using base::Status;

// The file formats WriteImage knows, chosen by extension (case-insensitive).
enum class ImageFormat { kPng, kExr, kTiff, kJpeg };

// The format for a path's extension, or kUnsupported naming the extension.
[[nodiscard]] Result<ImageFormat> ImageFormatFromPath(const std::string& path);

// sRGB transfer function (IEC 61966-2-1), on one value. Inputs outside [0, 1]
// are clamped first. LinearToSrgb(SrgbToLinear(c)) == c within float round-off.
float LinearToSrgb(float linear);   // linear light in [0,1] -> encoded value in [0,1]
float SrgbToLinear(float encoded);  // encoded value in [0,1] -> linear light in [0,1]

// 8-bit quantization: round(255 * LinearToSrgb(linear)). NaN maps to 0.
std::uint8_t LinearToSrgb8(float linear);
// Exact inverse on the 256 codes: LinearToSrgb8(Srgb8ToLinear(c)) == c for every c.
// Uses a 256-entry table computed once (thread-safe).
float Srgb8ToLinear(std::uint8_t code);

// PNG zlib levels. CPU time per 1280x720 frame (bench/image_io_bench.cpp, shaded
// test frame): level 6 + adaptive filter 89 ms / 104 kB; level 6 + no filter 33 ms /
// 109 kB; level 1 + no filter 26 ms / 183 kB, the preview default. Golden
// references use 9 (small files in git).
inline constexpr int kPngCompressionPreview = 1;
inline constexpr int kPngCompressionDefault = 6;

// PNG row filters (libpng's flags). kNone skips filtering: on rendered frames
// (flat and smoothly shaded areas) it costs about half the time of kAdaptive at
// level 1 and a third at level 6, for files 5-15% larger; kAdaptive is libpng's
// default (tries all five per row).
enum class PngFilter : int {
  kNone = 0x08,
  kSub = 0x10,
  kUp = 0x20,
  kAverage = 0x40,
  kPaeth = 0x80,
  kAdaptive = 0xF8,
};

struct WriteOptions {
  // PNG zlib level, 0 (none) .. 9 (smallest, slowest).
  int png_compression = kPngCompressionPreview;
  // PNG row filter (see PngFilter).
  PngFilter png_filter = PngFilter::kNone;
  // JPEG quality 1..100.
  int jpeg_quality = 90;
  // TIFF sample depth, 8 or 16.
  int tiff_bits = 8;
  // EXR compression as OpenEXR names it: "none", "zip", "zips", "piz", "rle", ...
  // "none" writes fastest (~13 ms per 1280x720 frame) but files are ~7 MB.
  std::string exr_compression = "zip";
  // EXR only: add a float "Z" channel from Image::depth (ignored when depth is empty).
  bool exr_write_depth = true;
  // Metadata. "Software" is always "patchskin <version>"; "ImageDescription" is
  // "frame <frame>, source <file>" (all formats); PNG and EXR also get the
  // "patchskin:frame" / "patchskin:source" attributes (TIFF drops unknown tags).
  int frame = -1;           // stored as string "patchskin:frame" when >= 0
  std::string source_file;  // stored as "patchskin:source" when not empty
};

// Writes `image` to `path` in the format of its extension, atomically (see top).
// Errors: kInvalidArgument (empty or inconsistent image, option out of range),
// kUnsupported (extension), kIo (encoder or rename failed; message from OIIO / the OS).
[[nodiscard]] Status WriteImage(const Image& image, const std::string& path,
                                const WriteOptions& options = {});

// The bytes an 8-bit file (PNG, 8-bit TIFF, JPEG but for its alpha) stores
// for `image`: LinearToSrgb8 of each colour channel, alpha rounded to
// 0..255 (NaN: 0). Reuses out's buffer. Linear in the pixels.
void EncodeSrgb8(const Image& image, Srgb8Image* out);

// The image ReadImage returns for a file holding `image`'s bytes: colour by
// Srgb8ToLinear, alpha as OpenImageIO converts the 8-bit code. No depth.
Image DecodeSrgb8(const Srgb8Image& image);

// WriteImage of a frame already encoded: for .png, 8-bit .tif and .jpg,
// WriteImage(frame) and WriteImage(EncodeSrgb8(frame)) write the same bytes. Errors as WriteImage;
// kInvalidArgument also for .exr and 16-bit TIFF, which need the linear values.
[[nodiscard]] Status WriteImage(const Srgb8Image& image, const std::string& path,
                                const WriteOptions& options = {});

// The temporary name WriteImage uses for `final_path`: "<dir>/.<name>.tmp-<pid>",
// followed by `suffix` (the video writer keeps the container's extension there).
std::string TemporaryPathFor(const std::string& final_path, const std::string& suffix = "");

// What ReadImage found in the file (for deciding how to compare it).
struct ReadInfo {
  bool srgb_encoded = false;  // integer samples converted from sRGB to linear
  int bits = 0;               // bits per sample in the file (8, 16, 32; 16 for half)
  int channels = 0;           // channels in the file
  std::string format_name;    // OpenImageIO's format name, e.g. "png", "openexr"
};

// Largest image ReadImage accepts, in pixels x file channels (guards allocations
// from a bad header: the decode buffer is 4 bytes per sample, so at most 1 GiB).
inline constexpr std::int64_t kMaxReadSamples = std::int64_t{1} << 28;

// Reads any file OpenImageIO reads into a linear RGBA Image. Integer-sample files
// are taken as sRGB-encoded and converted to linear (alpha is not converted);
// float/half files are taken as linear. 1 channel -> grey, 2 -> grey + alpha,
// 3 -> alpha 1. A channel named "Z" (EXR) fills Image::depth.
// Errors: kIo (missing/unreadable), kUnsupported (0 or > 64 channels, volumes),
// kLimitExceeded (more than kMaxReadSamples samples).
[[nodiscard]] Result<Image> ReadImage(const std::string& path, ReadInfo* info = nullptr);

// Expands the frame placeholder in an output pattern: a run of '#' becomes the
// frame number zero-padded to the run's length ("f_####.png", 7 -> "f_0007.png");
// "%0Nd" / "%d" work as in printf. Negative frames keep their '-' sign.
// Errors: kInvalidArgument when the pattern has no placeholder or more than one.
[[nodiscard]] Result<std::string> ExpandFramePattern(const std::string& pattern, int frame);

// True when `pattern` holds exactly one frame placeholder (see ExpandFramePattern).
bool HasFramePlaceholder(const std::string& pattern);

}  // namespace render
