// Cost of getting a 1280x720 frame to disk: PNG at zlib levels 6 (default) and 1
// (preview), EXR uncompressed and zip, and the AsyncImageWriter with 2 workers,
// encode-only and end to end (a procedural "render" of each frame, then submit).
// Items are frames. Files go to the system temp folder.

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "render/output/async_writer.h"
#include "render/output/image_io.h"

namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 1280;
constexpr int kHeight = 720;

fs::path BenchDir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / "patchskin_image_io_bench";
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// A frame that compresses like a shaded render: smooth gradients, a shaded disc
// with a hard edge, flat background; `frame` moves the disc.
render::Image DrawFrame(int frame) {
  render::Image img(kWidth, kHeight);
  const float cx = 400.0f + 4.0f * static_cast<float>(frame % 100);
  const float cy = 360.0f;
  const float r = 250.0f;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const float u = static_cast<float>(x) / kWidth;
      const float v = static_cast<float>(y) / kHeight;
      glm::vec4 p(0.2f + 0.1f * u, 0.22f, 0.25f + 0.1f * v, 1.0f);
      const float dx = (static_cast<float>(x) - cx) / r;
      const float dy = (static_cast<float>(y) - cy) / r;
      const float d2 = dx * dx + dy * dy;
      if (d2 < 1.0f) {
        const float nz = std::sqrt(1.0f - d2);  // sphere normal z
        const float lambert = std::max(0.0f, 0.3f * -dx + 0.4f * -dy + 0.87f * nz);
        p = glm::vec4(0.8f * lambert, 0.6f * lambert, 0.5f * lambert, 1.0f);
      }
      img.at(x, y) = p;
    }
  }
  return img;
}

const render::Image& Frame() {
  static const render::Image frame = DrawFrame(0);
  return frame;
}

void WriteOne(benchmark::State& state, const std::string& name, const render::WriteOptions& o) {
  const std::string path = (BenchDir() / name).string();
  for (auto _ : state) {
    if (!render::WriteImage(Frame(), path, o)) state.SkipWithError("write failed");
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["bytes"] = static_cast<double>(fs::file_size(path));
}

// range(0): zlib level; range(1): 1 = libpng's adaptive row filter, 0 = none.
void BM_WritePng(benchmark::State& state) {
  render::WriteOptions o;
  o.png_compression = static_cast<int>(state.range(0));
  o.png_filter = state.range(1) == 1 ? render::PngFilter::kAdaptive : render::PngFilter::kNone;
  WriteOne(state, "frame.png", o);
}
BENCHMARK(BM_WritePng)
    ->ArgNames({"level", "adaptive"})
    ->Args({render::kPngCompressionDefault, 1})->Args({1, 1})
    ->Args({render::kPngCompressionDefault, 0})->Args({1, 0})->Args({0, 0})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteExr(benchmark::State& state) {
  render::WriteOptions o;
  o.exr_compression = state.range(0) == 0 ? "none" : "zip";
  WriteOne(state, "frame.exr", o);
}
BENCHMARK(BM_WriteExr)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DrawFrameOnly(benchmark::State& state) {
  int f = 0;
  for (auto _ : state) benchmark::DoNotOptimize(DrawFrame(f++));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DrawFrameOnly)->Unit(benchmark::kMillisecond)->UseRealTime();

// range(0): 0 = encode only (frames are copies of one image),
//           1 = end to end (each frame drawn, then submitted).
// range(1): workers (0 = synchronous WriteImage on the calling thread).
void BM_WriteSequencePng(benchmark::State& state) {
  constexpr int kFrames = 16;
  const bool draw = state.range(0) == 1;
  const int workers = static_cast<int>(state.range(1));
  render::WriteOptions o;  // preview PNG level
  for (auto _ : state) {
    if (workers == 0) {
      for (int f = 0; f < kFrames; ++f) {
        const render::Image img = draw ? DrawFrame(f) : Frame();
        const auto path = render::ExpandFramePattern((BenchDir() / "s_####.png").string(), f);
        if (!render::WriteImage(img, *path, o)) state.SkipWithError("write failed");
      }
    } else {
      render::AsyncImageWriter writer({.num_workers = workers, .max_in_flight = workers + 1});
      for (int f = 0; f < kFrames; ++f) {
        const auto path = render::ExpandFramePattern((BenchDir() / "a_####.png").string(), f);
        if (!writer.Submit(draw ? DrawFrame(f) : Frame(), *path, o)) {
          state.SkipWithError("submit failed");
        }
      }
      if (!writer.Finish()) state.SkipWithError("finish failed");
    }
  }
  state.SetItemsProcessed(state.iterations() * kFrames);
}
BENCHMARK(BM_WriteSequencePng)
    ->ArgNames({"draw", "workers"})
    ->Args({0, 0})->Args({0, 2})->Args({1, 0})->Args({1, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
