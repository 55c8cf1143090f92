// AsyncImageWriter: same bytes as synchronous writing, error reporting, Finish.

#include "render/output/async_writer.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <chrono>
#include <thread>
#include <string>

#include <gtest/gtest.h>

#include "support/data_paths.h"

namespace render {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  fs::path dir = testsupport::TestOutputPath("async_writer/" + name + "/x").parent_path();
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Image Frame(int f) {
  Image img(48, 32);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      img.at(x, y) = glm::vec4(static_cast<float>((x + f) % 48) / 47.0f,
                               static_cast<float>(y) / 31.0f, static_cast<float>(f) / 20.0f, 1.0f);
    }
  }
  return img;
}

std::string Bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Files <prefix>0.png .. of frames 0..n-1 hold what WriteImage writes of them.
void ExpectWrittenAsWriteImage(const fs::path& dir, const std::string& prefix, int n,
                               WriteOptions o) {
  for (int f = 0; f < n; ++f) {
    o.frame = f;
    const fs::path sync = dir / ("sync_" + std::to_string(f) + ".png");
    ASSERT_TRUE(WriteImage(Frame(f), sync.string(), o));
    EXPECT_EQ(Bytes(dir / (prefix + std::to_string(f) + ".png")), Bytes(sync)) << f;
  }
}

TEST(AsyncImageWriter, WritesTheSameBytesAsWriteImage) {
  const fs::path dir = FreshDir("bytes");
  constexpr int kFrames = 12;
  WriteOptions o;
  {
    AsyncImageWriter writer({.num_workers = 2, .max_in_flight = 3});
    for (int f = 0; f < kFrames; ++f) {
      o.frame = f;
      const std::string path = (dir / ("async_" + std::to_string(f) + ".png")).string();
      ASSERT_TRUE(writer.Submit(Frame(f), path, o));
    }
    ASSERT_TRUE(writer.Finish());
    EXPECT_EQ(writer.frames_written(), kFrames);
    EXPECT_LE(writer.peak_in_flight(), 3) << "memory stays bounded";
    EXPECT_GE(writer.peak_in_flight(), 1);
  }
  ExpectWrittenAsWriteImage(dir, "async_", kFrames, o);
}

// Frames encoded once (shared with the video and the sheet in a render) are
// written as the linear frames are; a missing frame is refused.
TEST(AsyncImageWriter, WritesEncodedFramesAsTheLinearOnes) {
  const fs::path dir = FreshDir("encoded");
  constexpr int kFrames = 6;
  WriteOptions o;
  {
    AsyncImageWriter writer({.num_workers = 2, .max_in_flight = 2});
    for (int f = 0; f < kFrames; ++f) {
      auto bytes = std::make_shared<Srgb8Image>();
      EncodeSrgb8(Frame(f), bytes.get());
      o.frame = f;
      ASSERT_TRUE(writer.Submit(std::move(bytes),
                                (dir / ("enc_" + std::to_string(f) + ".png")).string(), o));
    }
    EXPECT_FALSE(
        writer.Submit(std::shared_ptr<const Srgb8Image>(), (dir / "none.png").string(), o));
    ASSERT_TRUE(writer.Finish());
    EXPECT_EQ(writer.frames_written(), kFrames);
    EXPECT_EQ(writer.TakeSpareImage().rgba.capacity(), 0u)
        << "encoded frames leave no linear buffers";
  }
  ExpectWrittenAsWriteImage(dir, "enc_", kFrames, o);
  EXPECT_FALSE(fs::exists(dir / "none.png"));
}

TEST(AsyncImageWriter, RaisesTooSmallLimits) {
  const fs::path dir = FreshDir("limits");
  AsyncImageWriter writer({.num_workers = 0, .max_in_flight = 0});
  for (int f = 0; f < 4; ++f) {
    ASSERT_TRUE(writer.Submit(Frame(f), *ExpandFramePattern((dir / "f#.png").string(), f)));
  }
  ASSERT_TRUE(writer.Finish());
  EXPECT_EQ(writer.frames_written(), 4);
  EXPECT_EQ(writer.peak_in_flight(), 1) << "one worker, one frame in flight";
}

TEST(AsyncImageWriter, ReportsAFailedFrameOnFinish) {
  const fs::path dir = FreshDir("finish_error");
  AsyncImageWriter writer({.num_workers = 2, .max_in_flight = 2});
  ASSERT_TRUE(writer.Submit(Frame(0), (dir / "a.png").string()));
  ASSERT_TRUE(writer.Submit(Frame(1), (dir / "missing" / "b.png").string()));
  const Status s = writer.Finish();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, base::ErrorCode::kIo);
  EXPECT_NE(s.error().ToString().find("b.png"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "a.png")) << "the good frame is still written";
  EXPECT_FALSE(writer.Finish().ok()) << "Finish keeps returning the error";
  EXPECT_FALSE(writer.Submit(Frame(2), (dir / "c.png").string()).ok()) << "closed";
}

TEST(AsyncImageWriter, LaterSubmitReturnsTheErrorAndStops) {
  const fs::path dir = FreshDir("submit_error");
  AsyncImageWriter writer({.num_workers = 1, .max_in_flight = 1});
  ASSERT_TRUE(writer.Submit(Frame(0), (dir / "missing" / "a.png").string()));
  // With one frame in flight at most, the second Submit waits for the first to
  // finish, so it must see its error.
  const Status s = writer.Submit(Frame(1), (dir / "b.png").string());
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().ToString().find("a.png"), std::string::npos);
  EXPECT_FALSE(writer.Finish().ok());
  EXPECT_FALSE(fs::exists(dir / "b.png")) << "nothing is queued after an error";
  EXPECT_EQ(writer.frames_written(), 0);
}

TEST(AsyncImageWriter, HandsBackAWrittenFramesBuffersForReuse) {
  const fs::path dir = FreshDir("spare");
  AsyncImageWriter writer({.num_workers = 1, .max_in_flight = 2});
  EXPECT_TRUE(writer.TakeSpareImage().rgba.empty()) << "nothing written yet";
  ASSERT_TRUE(writer.Submit(Frame(0), (dir / "a.png").string()));
  // Wait (bounded) for the worker to finish the frame.
  for (int i = 0; i < 2000 && writer.frames_written() < 1; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(writer.frames_written(), 1);
  const Image spare = writer.TakeSpareImage();
  EXPECT_GE(spare.rgba.capacity(), std::size_t{48 * 32}) << "the frame's buffer came back";
  EXPECT_TRUE(writer.TakeSpareImage().rgba.empty()) << "each buffer is handed out once";
  ASSERT_TRUE(writer.Finish());
  // The spare did not change what was written.
  const fs::path sync = dir / "sync.png";
  ASSERT_TRUE(WriteImage(Frame(0), sync.string()));
  EXPECT_EQ(Bytes(dir / "a.png"), Bytes(sync));
}

}  // namespace
}  // namespace render
