// Block-wise reading of the frame data (BvhReadOptions::block_bytes, issue 8):
// wherever the blocks are cut, on either path (two threads or sequential,
// in-memory text or a mapped file whose pages are given back as they are
// parsed), the motion is the same to the bit and every error names the same
// line, column and frame; and reading a file holds its floats plus a few
// blocks, not its text.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "mocap/bvh_reader.h"
#include "mocap/bvh_writer.h"
#include "support/long_capture.h"
#include "support/data_paths.h"

namespace {

namespace fs = std::filesystem;

// A 120 fps walk of `frames` frames as BVH text (testsupport::LongCaptureText).
std::string WalkText(int frames) {
  std::string text = testsupport::LongCaptureText(frames);
  EXPECT_FALSE(text.empty());
  return text;
}

mocap::BvhReadOptions Blocks(std::size_t block_bytes, bool two_threads) {
  mocap::BvhReadOptions o;
  o.block_bytes = block_bytes;
  o.parallel_min_bytes = two_threads ? 1 : std::numeric_limits<std::size_t>::max();
  return o;
}

// The reference: one sequential pass over in-memory text in one block.
base::Result<mocap::BvhFile> Reference(const std::string& text, const std::string& name) {
  return mocap::ParseBvh(text, name, Blocks(std::numeric_limits<std::size_t>::max(), false));
}

// First byte of the frame data: just after the "Frame Time:" line.
std::size_t FrameDataStart(const std::string& text) {
  const std::size_t at = text.find("Frame Time:");
  EXPECT_NE(at, std::string::npos);
  return text.find('\n', at) + 1;
}

void ExpectSameMotion(const mocap::BvhFile& a, const mocap::BvhFile& b, const std::string& what) {
  ASSERT_EQ(a.motion.num_frames, b.motion.num_frames) << what;
  ASSERT_EQ(a.motion.values.size(), b.motion.values.size()) << what;
  for (std::size_t i = 0; i < a.motion.values.size(); ++i) {
    ASSERT_EQ(std::bit_cast<std::uint32_t>(a.motion.values[i]),
              std::bit_cast<std::uint32_t>(b.motion.values[i]))
        << what << ", value " << i;
  }
  ASSERT_EQ(a.warnings.size(), b.warnings.size()) << what;
  for (std::size_t i = 0; i < a.warnings.size(); ++i) {
    EXPECT_EQ(a.warnings[i].ToString(), b.warnings[i].ToString()) << what;
  }
}

fs::path WriteFile(const std::string& name, const std::string& text) {
  const fs::path path = testsupport::TestOutputPath("bvh_block_read/" + name);
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(BvhBlockRead, EveryBlockSizeGivesTheSameMotion) {
  // Six frames (~2.7 kB of frame data): block sizes from one byte (a block per
  // line) to past the end (one block) cut the data at every position.
  const std::string text = WalkText(6);
  const auto ref = Reference(text, "walk.bvh");
  ASSERT_TRUE(ref.ok()) << ref.error().ToString();
  ASSERT_EQ(ref->motion.num_frames, 6);
  const std::size_t data_bytes = text.size() - FrameDataStart(text);
  for (std::size_t block = 0; block <= data_bytes + 1; ++block) {
    for (const bool two_threads : {true, false}) {
      const auto got = mocap::ParseBvh(text, "walk.bvh", Blocks(block, two_threads));
      ASSERT_TRUE(got.ok()) << got.error().ToString();
      ExpectSameMotion(*got, *ref,
                       "block " + std::to_string(block) + (two_threads ? ", two threads" : ""));
    }
  }
}

TEST(BvhBlockRead, BlankLinesAndCrLfAtBlockEdgesAreHandled) {
  // Windows line ends and blank (or blank-looking) lines between frames: a cut
  // between '\r' and '\n' or inside a run of blank lines must not make or lose a frame.
  std::string text = WalkText(5);
  const std::size_t start = FrameDataStart(text);
  std::string data = text.substr(start), crlf;
  for (const char c : data) crlf += c == '\n' ? std::string("\r\n \t\r\n\n") : std::string(1, c);
  text = text.substr(0, start) + crlf;
  const auto ref = Reference(text, "crlf.bvh");
  ASSERT_TRUE(ref.ok()) << ref.error().ToString();
  ASSERT_EQ(ref->motion.num_frames, 5);
  for (std::size_t block = 1; block <= crlf.size() + 1; ++block) {
    const auto got = mocap::ParseBvh(text, "crlf.bvh", Blocks(block, true));
    ASSERT_TRUE(got.ok()) << got.error().ToString();
    ExpectSameMotion(*got, *ref, "block " + std::to_string(block));
  }
}

TEST(BvhBlockRead, ErrorsAcrossABlockBoundaryNameTheRightLine) {
  // A bad number and a short line in frame 4, for every block size that cuts
  // the data before, inside or after that line: the message is the
  // sequential one-block pass's, which names the line counted here.
  const std::string text = WalkText(8);
  const std::size_t start = FrameDataStart(text);
  std::size_t line4 = start;  // start of frame 4's line
  for (int k = 0; k < 3; ++k) line4 = text.find('\n', line4) + 1;
  const std::size_t target = text.find(' ', line4 + 40);  // a separator inside frame 4
  const int expected_line = 1 + static_cast<int>(std::count(text.begin(),
                                                            text.begin() + static_cast<long>(target),
                                                            '\n'));
  struct Case {
    std::string with;
    std::string needle;
  };
  for (const Case& c : {Case{" x", "expected a number for value"},
                        Case{"\n", "expected 75 values in frame 4, found"}}) {
    std::string bad = text;
    bad.replace(target, 1, c.with);
    const auto ref = Reference(bad, "bad.bvh");
    ASSERT_FALSE(ref.ok());
    const std::string message = ref.error().ToString();
    EXPECT_NE(message.find("bad.bvh:" + std::to_string(expected_line) + ":"), std::string::npos)
        << message;
    EXPECT_NE(message.find(c.needle), std::string::npos) << message;
    const fs::path file = WriteFile("bad.bvh", bad);
    for (std::size_t block = 1; block <= bad.size() - start + 1; block += 7) {
      for (const bool two_threads : {true, false}) {
        const auto got = mocap::ParseBvh(bad, "bad.bvh", Blocks(block, two_threads));
        ASSERT_FALSE(got.ok());
        EXPECT_EQ(got.error().ToString(), message) << "block " << block;
        // The mapped file, its pages given back block by block: the same text.
        const auto read = mocap::ReadBvhFile(file.string(), Blocks(block, two_threads));
        ASSERT_FALSE(read.ok());
        EXPECT_EQ(read.error().ToString(), file.string() + message.substr(7))
            << "block " << block;
      }
    }
  }
}

TEST(BvhBlockRead, AMappedFileGivesTheSameMotionWhateverTheBlocks) {
  // ~90 kB of frame data, ~22 pages: blocks smaller than, equal to and larger
  // than a page, so pages are given back while the other thread (or the next
  // line) still reads their neighbours.
  const std::string text = WalkText(200);
  const auto ref = Reference(text, "walk.bvh");
  ASSERT_TRUE(ref.ok());
  const fs::path file = WriteFile("walk200.bvh", text);
  for (const std::size_t block : {std::size_t{1}, std::size_t{333}, std::size_t{4095},
                                  std::size_t{4096}, std::size_t{4097}, std::size_t{20000},
                                  std::size_t{1} << 20}) {
    for (const bool two_threads : {true, false}) {
      const auto got = mocap::ReadBvhFile(file.string(), Blocks(block, two_threads));
      ASSERT_TRUE(got.ok()) << got.error().ToString();
      ExpectSameMotion(*got, *ref, "block " + std::to_string(block));
    }
  }
}

// Peak resident memory of this process in KiB (VmHWM), 0 when unknown.
long PeakRssKb() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6));
  }
  return 0;
}

long CurrentRssKb() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return 0;
}

TEST(BvhBlockRead, ReadingAFileHoldsItsFloatsNotItsText) {
  // 60,000 frames: ~27 MB of text, 18 MB of floats. With the pages given back
  // per 4 MiB block (the default), the peak grows by the floats plus what the
  // two threads hold on the side (a block's text and its floats, under 4 MiB,
  // each) and 4 MiB of allocator slack.
  const fs::path file = WriteFile("walk60k.bvh", WalkText(60000));
  const double text_kb = static_cast<double>(fs::file_size(file)) / 1024.0;
  {
    // Linux resets the peak (VmHWM) to the current RSS when "5" is written here.
    std::ofstream reset("/proc/self/clear_refs");
    if (!(reset << "5" << std::flush)) GTEST_SKIP() << "cannot reset the peak RSS here";
  }
  const long before_kb = CurrentRssKb();
  if (before_kb == 0 || PeakRssKb() == 0) GTEST_SKIP() << "no /proc/self/status";
  const auto got = mocap::ReadBvhFile(file.string());
  ASSERT_TRUE(got.ok()) << got.error().ToString();
  const double floats_kb = static_cast<double>(got->motion.values.size() * sizeof(float)) / 1024.0;
  const double growth_kb = static_cast<double>(PeakRssKb() - before_kb);
  const double blocks_kb = 2.0 * (4096.0 + 4096.0) + 4096.0;
  std::printf("text %.0f KiB, floats %.0f KiB, peak growth %.0f KiB\n", text_kb, floats_kb,
              growth_kb);
  // Without the pages given back the growth was ~59 MB here (text + floats
  // + blocks), above this bound.
  EXPECT_LE(growth_kb, floats_kb + blocks_kb);
}

}  // namespace
