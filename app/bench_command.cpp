#include "app/bench_command.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#ifdef PATCHSKIN_HAVE_ASSIMP
#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#endif

#include "app/bench_auto_layer.h"
#include "app/bench_elastic_share.h"
#include "app/bench_long_capture.h"
#include "app/bench_scenes.h"
#include "app/bench_table1.h"
#include "bench/harness/timing.h"
#include "app/frame_plan.h"
#include "app/frame_render.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/exit_code.h"
#include "base/parallel.h"
#include "deform/patch/patch_binding.h"
#include "deform/global/skinning_job.h"
#include "mocap/bvh_reader.h"
#include "mocap/bvh_writer.h"
#include "tools/synthetic.h"
#include "render/output/async_writer.h"
#include "render/output/contact_sheet.h"
#include "render/output/serial_task_queue.h"
#include "render/output/video_writer.h"
#include "render/output/image_io.h"

#ifndef PATCHSKIN_BUILD_TYPE
#define PATCHSKIN_BUILD_TYPE "unknown"
#endif
#ifndef PATCHSKIN_DATA_DIR
#define PATCHSKIN_DATA_DIR ""
#endif

namespace app {
namespace {

using ::bench::Budget;
using ::bench::Clock;
using ::bench::ClockName;
using ::bench::Now;
using ::bench::Rates;
using ::bench::Row;
using bench::Table1Row;

// ------------------------------------------------------------ workloads ---

std::string GeneratedBvh(int frames) {
  const mocap::Skeleton skel = synthetic::MakeHumanoidSkeleton();
  synthetic::WalkOptions walk;
  walk.frame_time_s = 1.0 / 120.0;
  walk.num_cycles = std::max(1, frames / 120);
  const base::Result<mocap::Motion> motion = synthetic::MakeWalkMotion(skel, walk);
  if (!motion.ok()) return {};
  base::Result<std::string> text = mocap::FormatBvh(skel, *motion);
  return text.ok() ? std::move(*text) : std::string();
}

Row BvhParseRow(const std::string& key, const std::string& text, const std::string& name,
                const Budget& b, bool& failed) {
  const double mb = static_cast<double>(text.size()) * 1e-6;
  Row row{key, "MB/s", Clock::kCpu, {}, 0.0, "", name};
  row.runs = Rates(b, Clock::kCpu, mb, [&] {
    failed |= !mocap::ParseBvh(text, name).ok();
  });
  char note[128];
  std::snprintf(note, sizeof(note), " (%.2f MB)", mb);
  row.note += note;
  return row;
}

// 100k vertices, 4 influences, 60 joints, positions + normals.
struct SsdFixture {
  static constexpr int kVertices = 100000;
  static constexpr int kJoints = 60;
  std::vector<glm::vec3> rest_p, rest_n, out_p, out_n;
  deform::SkinWeights weights;
  std::vector<glm::mat4> palette;

  SsdFixture() {
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::uniform_int_distribution<int> near(0, 3);
    weights.influences = 4;
    for (int v = 0; v < kVertices; ++v) {
      rest_p.emplace_back(u(rng), u(rng), u(rng));
      rest_n.push_back(glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + 1e-3f));
      const int base = (v * kJoints) / kVertices;  // neighbouring vertices share joints
      for (int i = 0; i < 4; ++i) {
        weights.joints.push_back(static_cast<std::uint16_t>((base + near(rng)) % kJoints));
        weights.weights.push_back(0.1f + 0.5f * (u(rng) + 1.0f));
      }
    }
    deform::NormalizeSkinWeights(weights);
    for (int j = 0; j < kJoints; ++j) {
      const glm::vec3 axis = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + 1e-3f);
      palette.push_back(glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(u(rng), u(rng), u(rng))),
                                    u(rng), axis));
    }
    out_p.resize(kVertices);
    out_n.resize(kVertices);
  }

  // Vertices [b, e).
  bool Skin(std::size_t b, std::size_t e) {
    const std::size_t n = e - b;
    return deform::SkinningJob{.model_from_bind = palette, .influences = 4,
                               .joint_indices = std::span<const std::uint16_t>(weights.joints).subspan(4 * b, 4 * n),
                               .joint_weights = std::span<const float>(weights.weights).subspan(4 * b, 4 * n),
                               .rest_positions = std::span<const glm::vec3>(rest_p).subspan(b, n),
                               .rest_normals = std::span<const glm::vec3>(rest_n).subspan(b, n),
                               .positions = std::span<glm::vec3>(out_p).subspan(b, n),
                               .normals = std::span<glm::vec3>(out_n).subspan(b, n)}
        .Run()
        .ok();
  }
};

// Two threads each skin their half `batch` times; wall-clock rate per run.
std::vector<double> SsdTwoThreads(SsdFixture& f, const Budget& b, bool& failed) {
  const std::size_t half = SsdFixture::kVertices / 2;
  const auto run = [&](std::int64_t batch) {
    bool bad0 = false, bad1 = false;
    const double t0 = Now(Clock::kWall);
    std::thread other([&] {
      for (std::int64_t i = 0; i < batch; ++i) bad1 |= !f.Skin(half, SsdFixture::kVertices);
    });
    for (std::int64_t i = 0; i < batch; ++i) bad0 |= !f.Skin(0, half);
    other.join();
    failed |= bad0 || bad1;
    return Now(Clock::kWall) - t0;
  };
  std::int64_t batch = 1;
  double dt = run(batch);
  while (dt < b.min_time_s / 8.0) dt = run(batch *= 2);
  batch = std::max<std::int64_t>(1, static_cast<std::int64_t>(static_cast<double>(batch) * b.min_time_s / dt));
  std::vector<double> rates;
  for (int r = 0; r < b.runs; ++r) {
    rates.push_back(static_cast<double>(SsdFixture::kVertices) * static_cast<double>(batch) / run(batch));
  }
  return rates;
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      return colon == std::string::npos ? line : line.substr(colon + 2);
    }
  }
  return "unknown CPU";
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  if (!(in >> a >> b >> c)) return "unknown";
  char text[64];
  std::snprintf(text, sizeof(text), "%.2f %.2f %.2f", a, b, c);
  return text;
}

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

void PrintRow(const Row& r) {
  std::printf("%-30s %12.4g %12.4g %12.4g  %-10s %-4s", r.key.c_str(), r.Median(), r.Min(), r.Max(),
              r.unit.c_str(), ClockName(r.clock));
  if (r.reference > 0.0) {
    std::printf(" %10.4g %8.1fx", r.reference, r.Ratio());
  } else {
    std::printf(" %10s %9s", "-", "-");
  }
  std::printf("  %s\n", r.note.c_str());
}

nlohmann::json RowJson(const Row& r) {
  nlohmann::json j = {{"median", r.Median()}, {"min", r.Min()},   {"max", r.Max()},
                      {"unit", r.unit},       {"clock", ClockName(r.clock)},
                      {"runs", r.runs},       {"note", r.note}};
  if (r.reference > 0.0) {
    j[r.reference_name] = r.reference;
    j["ratio"] = r.Ratio();
  }
  return j;
}

}  // namespace

int RunBench(const BenchOptions& o) {
  if (const auto bad = CheckThreads(o.threads)) return ReportError(*bad);
#ifndef NDEBUG
  std::fprintf(stderr,
               "bench: WARNING: this is not a Release build (%s, assertions on); its figures are "
               "meaningless. Build with -DCMAKE_BUILD_TYPE=Release.\n",
               PATCHSKIN_BUILD_TYPE);
  if (!o.allow_debug) return 2;  // cannot run as given (README: exit codes)
  const bool release = false;
#else
  const bool release = true;
#endif
  const Budget budget = o.quick ? Budget{3, 0.02} : Budget{7, 0.3};
  const int threads = base::ResolveThreads(o.threads);
  bool failed = false;

  // --- Header -----------------------------------------------------------------
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  const std::string cpu = CpuModel();
  const unsigned cores = std::thread::hardware_concurrency();
  const std::string load = LoadAverage();
  std::printf("patchskin bench%s, %s\n", o.quick ? " --quick" : "", date);
  std::printf("machine: %s, %u cores, load average %s\n", cpu.c_str(), cores, load.c_str());
  std::printf("build:   %s%s, %s %s\n", PATCHSKIN_BUILD_TYPE, release ? "" : " (NOT RELEASE)",
#ifdef __clang__
              "clang",
#else
              "GCC",
#endif
              __VERSION__);
  std::printf("figures: median, min, max of %d runs; cpu = the thread's CPU time, wall = elapsed\n\n",
              budget.runs);

  // --- Table 1 --------------------------------------------------------------------
  std::vector<Table1Row> table1;
  for (const bench::PatchCase& c : bench::kPatches) {
    base::Result<Table1Row> row = bench::MeasurePatch(c, budget);
    if (!row.ok()) return ReportError(row.error());
    table1.push_back(std::move(*row));
  }
  std::printf("%-30s %12s %12s %12s  %-10s %-4s %10s %9s  %s\n", "Table 1 (per patch)", "median",
              "min", "max", "unit", "clk", "paper", "ratio", "note");
  for (const Table1Row& t : table1) {
    PrintRow(t.update);
    PrintRow(t.rebuild);
    PrintRow(t.total);
  }

  // --- Other figures ----------------------------------------------------------------
  std::vector<Row> rows;
  const std::string generated = GeneratedBvh(o.quick ? 1200 : 12000);
  if (generated.empty()) {
    return ReportError(base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}},
                                       "could not generate the BVH workload"));
  }
  rows.push_back(BvhParseRow("bvh_parse_generated", generated, "generated walk, 120 fps", budget, failed));
  const std::string data_dir = o.data_dir.empty() ? PATCHSKIN_DATA_DIR : o.data_dir;
  const std::filesystem::path cmu = std::filesystem::path(data_dir) / "bvh/cmu_cgspeed/01_01.bvh";
  std::error_code ec;
  if (!data_dir.empty() && std::filesystem::is_regular_file(cmu, ec)) {
    std::ifstream in(cmu, std::ios::binary);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    rows.push_back(BvhParseRow("bvh_parse_cmu_01_01", text, "CMU 01_01.bvh", budget, failed));
  } else {
    std::fprintf(stderr, "bench: %s not found; the CMU parse row is skipped\n", cmu.string().c_str());
  }
#ifdef PATCHSKIN_HAVE_ASSIMP
  {
    Row assimp{"bvh_parse_assimp", "MB/s", Clock::kCpu, {}, 0.0, "", "Assimp's BVH importer, generated walk"};
    const Budget once{std::min(budget.runs, 3), budget.min_time_s};
    assimp.runs = Rates(once, Clock::kCpu, static_cast<double>(generated.size()) * 1e-6, [&] {
      Assimp::Importer importer;
      failed |= importer.ReadFileFromMemory(generated.data(), generated.size(), 0, "bvh") == nullptr;
    });
    rows.front().reference = assimp.Median();
    rows.front().reference_name = "Assimp";
    rows.push_back(std::move(assimp));
  }
#endif

  SsdFixture ssd;
  rows.push_back({"ssd_1_thread", "vertices/s", Clock::kCpu,
                  Rates(budget, Clock::kCpu, SsdFixture::kVertices,
                        [&] { failed |= !ssd.Skin(0, SsdFixture::kVertices); }),
                  0.0, "", "100k vertices, 4 influences, positions + normals"});
  rows.push_back({"ssd_2_threads", "vertices/s", Clock::kWall, SsdTwoThreads(ssd, budget, failed), 0.0,
                  "", "two halves on two threads"});

  // The demo body (the walk on the generated mannequin).
  base::Result<Character> character = bench::LoadDemoCharacter();
  if (!character.ok()) return ReportError(character.error());
  const Character& ch = *character;
  const int e2e_frames = o.quick ? 4 : 24;
  base::Result<FramePlan> plan =
      PlanFrames(ch.motion, {.frames = "0:" + std::to_string(e2e_frames - 1)});
  if (!plan.ok()) return ReportError(plan.error());
  base::Result<deform::FramePipeline> pipeline =
      deform::FramePipeline::Create(ch, deform::GlobalMethod::kSsd, threads);
  if (!pipeline.ok()) return ReportError(pipeline.error());
  base::Result<render::CameraPlan> cameras =
      PlanCameras(pipeline->character(), *plan, "follow", 15.0f, {1280, 720});
  if (!cameras.ok()) return ReportError(cameras.error());
  deform::DeformedFrame frame;
  if (base::Status s = pipeline->Evaluate(0.0, frame); !s.ok()) return ReportError(s.error());
  render::Renderer renderer, right_renderer;
  render::Image image, scratch;
  const auto draw_settings = [&](int w, int h, int ss, int nthreads) {
    render::RenderSettings s;
    s.width = w;
    s.height = h;
    s.supersample = ss;
    s.threads = nthreads;
    s.ground_at_scene_min = false;
    s.ground_y = cameras->ground_y();
    return s;
  };
  const std::string triangles = std::to_string(ch.mesh.bind.num_triangles()) + " triangles";
  for (const glm::ivec2 size : {glm::ivec2(1280, 720), glm::ivec2(1920, 1080)}) {
    const render::RenderSettings s = draw_settings(size.x, size.y, 1, 1);
    render::Camera camera = cameras->At(plan->frames.front().camera);
    camera.aspect = static_cast<float>(size.x) / static_cast<float>(size.y);
    rows.push_back({"raster_fps_" + std::to_string(size.x) + "x" + std::to_string(size.y), "frames/s",
                    Clock::kCpu, Rates(budget, Clock::kCpu, 1.0, [&] {
                      failed |= !DrawCharacterFrame(ch, frame, nullptr, camera, s, {}, renderer,
                                                    right_renderer, scratch, image)
                                     .ok();
                    }),
                    0.0, "", "demo body, " + triangles + ", 1 thread, no supersampling"});
  }

  // The key light's shadow map: the default render (1280x720, 2x2 msaa,
  // all threads) of the same posed frames with shadows off (the baseline) and
  // on, alternating, per CPU second of all threads (insensitive to load).
  {
    const int n = o.quick ? 2 : 8;
    std::vector<deform::DeformedFrame> posed(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const double t = plan->frames[static_cast<std::size_t>(i % e2e_frames)].time_s;
      if (base::Status s = pipeline->Evaluate(t, posed[static_cast<std::size_t>(i)]); !s.ok())
        return ReportError(s.error());
    }
    const auto render_all = [&](bool shadows) {
      render::RenderSettings s = draw_settings(1280, 720, 2, threads);
      s.antialias = render::AntiAlias::kMultisample;
      s.shadows = shadows;
      const double c0 = Now(Clock::kProcess);
      for (int i = 0; i < n; ++i) {
        const OutputFrame& of = plan->frames[static_cast<std::size_t>(i % e2e_frames)];
        failed |= !DrawCharacterFrame(ch, posed[static_cast<std::size_t>(i)], nullptr,
                                      cameras->At(of.camera), s, {}, renderer, right_renderer,
                                      scratch, image)
                       .ok();
      }
      return std::max(Now(Clock::kProcess) - c0, 1e-9);
    };
    const std::string note = std::to_string(n) + " demo frames, 1280x720, 2x2 msaa, " +
                             std::to_string(threads) + " threads, render only";
    Row off{"render_shadows_off_fps", "frames/s", Clock::kProcess, {}, 0.0, "", note + ", --shadows off"};
    Row on{"render_shadows_on_fps", "frames/s", Clock::kProcess, {}, 0.0, "shadows off",
           "the same with the key light's shadow map (--shadows on)"};
    Row share{"shadow_frame_share", "%", Clock::kProcess, {}, 0.0, "",
              "(on - off) / on time, each repetition's pair (goal <= 15)"};
    for (int r = 0; r < (o.quick ? 1 : 5); ++r) {
      const double t_off = render_all(false), t_on = render_all(true);
      off.runs.push_back(n / t_off);
      on.runs.push_back(n / t_on);
      share.runs.push_back(100.0 * (t_on - t_off) / t_on);
    }
    on.reference = off.Median();
    rows.push_back(std::move(off));
    rows.push_back(std::move(on));
    rows.push_back(std::move(share));
  }

  // End to end: pipeline, follow camera, render at the command's defaults
  // (1280x720, 2x2 supersampling), PNG level 1 through the async writer.
  const std::filesystem::path out_dir =
      std::filesystem::temp_directory_path() / ("patchskin_bench_" + std::to_string(getpid()));
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    return ReportError(base::MakeError(base::ErrorCode::kIo, {out_dir.string(), 0, 0, {}},
                                       "cannot create a temporary folder: " + ec.message()));
  }
  render::RenderSettings e2e_settings = draw_settings(1280, 720, 2, threads);
  e2e_settings.antialias = render::AntiAlias::kMultisample;  // the render command's default
  render::WriteOptions png;
  png.png_compression = 1;
  Row e2e{"demo_end_to_end_fps",
          "frames/s",
          Clock::kWall,
          {},
          0.0,
          "",
          std::to_string(e2e_frames) + " demo frames, 1280x720, 2x2 msaa, PNG level 1, " +
              std::to_string(threads) + " threads"};
  Row e2e_cpu{"demo_end_to_end_per_cpu_s", "frames/s", Clock::kProcess, {}, 0.0, "",
              "the same frames per CPU second of all threads (insensitive to load)"};
  for (int r = 0; r < (o.quick ? 1 : 3); ++r) {
    const double t0 = Now(Clock::kWall), c0 = Now(Clock::kProcess);
    render::AsyncImageWriter writer({.num_workers = 2, .max_in_flight = 4});
    for (const OutputFrame& of : plan->frames) {
      base::Status s = pipeline->Evaluate(of.time_s, frame);
      if (s.ok()) {
        FrameDrawOptions draw;
        draw.frame_number = of.number;
        s = DrawCharacterFrame(ch, frame, nullptr, cameras->At(of.camera), e2e_settings, draw,
                               renderer, right_renderer, scratch, image);
      }
      if (s.ok()) {
        char name[32];
        std::snprintf(name, sizeof(name), "frame_%04d.png", of.number);
        s = writer.Submit(image, (out_dir / name).string(), png);
      }
      if (!s.ok()) return ReportError(s.error());
    }
    if (base::Status s = writer.Finish(); !s.ok()) return ReportError(s.error());
    e2e.runs.push_back(e2e_frames / std::max(Now(Clock::kWall) - t0, 1e-9));
    e2e_cpu.runs.push_back(e2e_frames / std::max(Now(Clock::kProcess) - c0, 1e-9));
  }
  // The default render's outputs (PNG frames, H.264 preview, contact sheet),
  // wired as the render command wires them: each frame sRGB-encoded once, the
  // PNGs on the async writer's two workers, video and sheet in frame order on
  // a side thread. `next(i)` gives frame i: either rendered now, or one rendered
  // before (encode only). Returns the wall-clock seconds, or < 0 on a failure.
  const int out_frames = o.quick ? 4 : 12;
  const auto run_outputs = [&](const std::function<const render::Image*(int)>& next) {
    const double t0 = Now(Clock::kWall);
    render::AsyncImageWriter writer({.num_workers = 2, .max_in_flight = 4});
    auto sheet = render::ContactSheetBuilder::Create(
        out_frames, 1280, 720, {.columns = render::ContactSheetColumns(out_frames)});
    auto video = render::VideoWriter::Open((out_dir / "preview.mp4").string(), 1280, 720, {.fps = 30.0});
    if (!sheet.ok() || !video.ok()) return -1.0;
    render::SerialTaskQueue side({.max_queued = 2});
    for (int i = 0; i < out_frames; ++i) {
      const render::Image* img = next(i);
      if (img == nullptr) return -1.0;
      auto bytes = std::make_shared<render::Srgb8Image>();
      render::EncodeSrgb8(*img, bytes.get());
      char name[32];
      std::snprintf(name, sizeof(name), "frame_%04d.png", i);
      base::Status s = side.Submit([&, i, bytes] {
        if (base::Status st = (*sheet)->Add(render::DecodeSrgb8(*bytes), i); !st.ok()) return st;
        return (*video)->AddFrame(*bytes);
      });
      if (s.ok()) s = writer.Submit(std::move(bytes), (out_dir / name).string(), png);
      if (!s.ok()) return -1.0;
    }
    if (!side.Finish().ok() || !writer.Finish().ok() || !(*video)->Close().ok()) return -1.0;
    if (!render::WriteImage((*sheet)->sheet(), (out_dir / "sheet.png").string(), {}).ok())
      return -1.0;
    return Now(Clock::kWall) - t0;
  };
  render::Image drawn;
  const auto render_frame = [&](render::AntiAlias aa) {
    return [&, aa](int i) -> const render::Image* {
      const OutputFrame& of = plan->frames[static_cast<std::size_t>(i % e2e_frames)];
      if (!pipeline->Evaluate(of.time_s, frame).ok()) return nullptr;
      render::RenderSettings settings = e2e_settings;
      settings.antialias = aa;
      FrameDrawOptions draw;
      draw.frame_number = of.number;
      const base::Status s =
          DrawCharacterFrame(ch, frame, nullptr, cameras->At(of.camera), settings, draw, renderer,
                             right_renderer, scratch, drawn);
      return s.ok() ? &drawn : nullptr;
    };
  };
  std::vector<render::Image> rendered(static_cast<std::size_t>(out_frames));
  for (int i = 0; i < out_frames; ++i) {
    const render::Image* img = render_frame(render::AntiAlias::kMultisample)(i);
    if (img == nullptr) {
      return ReportError(base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}},
                                         "a default-render frame failed"));
    }
    rendered[static_cast<std::size_t>(i)] = *img;
  }
  const std::string outputs_note = std::to_string(out_frames) + " demo frames, 1280x720, PNG level 1 + H.264 + sheet, " +
                                   std::to_string(threads) + " threads";
  Row msaa_row{"default_render_fps",
               "frames/s",
               Clock::kWall,
               {},
               0.0,
               "2x2 ssaa",
               outputs_note + ", 2x2 multisampling (the default); reference: the ssaa row"};
  Row ssaa_row{"default_render_ssaa_fps",
               "frames/s",
               Clock::kWall,
               {},
               0.0,
               "",
               "the same with --aa ssaa (every sample shaded, the default before 2026-11-30)"};
  Row encode_row{"encode_only_fps", "frames/s", Clock::kWall, {}, 0.0, "",
                 "the same outputs of those frames already in memory (no render)"};
  Row bound_row{"encode_bound_ratio", "ratio", Clock::kWall, {}, 0.0, "",
                "default render time / encode-only time, each repetition's pair (goal <= 1.3)"};
  for (int r = 0; r < (o.quick ? 1 : 5); ++r) {
    const double t_encode =
        run_outputs([&](int i) { return &rendered[static_cast<std::size_t>(i)]; });
    const double t_ssaa = run_outputs(render_frame(render::AntiAlias::kSupersample));
    const double t_msaa = run_outputs(render_frame(render::AntiAlias::kMultisample));
    if (t_encode <= 0.0 || t_ssaa <= 0.0 || t_msaa <= 0.0) {
      return ReportError(base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}},
                                         "the default-render outputs failed"));
    }
    encode_row.runs.push_back(out_frames / t_encode);
    ssaa_row.runs.push_back(out_frames / t_ssaa);
    msaa_row.runs.push_back(out_frames / t_msaa);
    bound_row.runs.push_back(t_msaa / t_encode);
  }
  msaa_row.reference = ssaa_row.Median();
  rendered.clear();
  const std::string png_path = (out_dir / "encode.png").string();
  Row encode{"png_encode_fps", "frames/s", Clock::kCpu, {}, 0.0, "",
             "one 1280x720 frame, level 1, no filter (encode + write only)"};
  encode.runs = Rates({std::min(budget.runs, 5), budget.min_time_s}, Clock::kCpu, 1.0,
                      [&] { failed |= !render::WriteImage(image, png_path, png).ok(); });
  std::filesystem::remove_all(out_dir, ec);
  rows.push_back(std::move(e2e));
  rows.push_back(std::move(e2e_cpu));
  rows.push_back(std::move(encode));
  rows.push_back(std::move(msaa_row));
  rows.push_back(std::move(ssaa_row));
  rows.push_back(std::move(encode_row));
  rows.push_back(std::move(bound_row));
  bench::AddElasticShareRow({std::min(budget.runs, 5), 0.0}, o.quick ? 8 : 30, rows, &failed);
  bench::AddAutoLayerRows({std::min(budget.runs, 5), 0.0}, o.quick ? 8 : 30, rows, &failed);
  rows.push_back({"bytes_per_bound_vertex", "bytes", Clock::kCpu,
                  {static_cast<double>(deform::PatchBinding::kStoredBytesPerVertex)}, 0.0, "",
                  "stored; the rebuild reads " +
                      std::to_string(deform::PatchBinding::kRebuildBytesPerVertex)});
  rows.push_back({"peak_memory", "MB", Clock::kCpu, {PeakRssMb()}, 0.0, "",
                  "getrusage ru_maxrss of this process"});
  bench::AddLongCaptureRows(o.quick, rows, &failed);
  if (failed) {
    return ReportError(base::MakeError(base::ErrorCode::kInternal, {"bench", 0, 0, {}},
                                       "a measured operation failed"));
  }

  std::printf("\n%-30s %12s %12s %12s  %-10s %-4s %10s %9s  %s\n", "figure", "median", "min", "max",
              "unit", "clk", "reference", "ratio", "note");
  for (const Row& r : rows) PrintRow(r);

  if (!o.json.empty()) {
    nlohmann::json j;
    j["header"] = {{"date", date},        {"cpu", cpu},          {"cores", cores},
                   {"load_average", load}, {"build_type", PATCHSKIN_BUILD_TYPE},
                   {"release", release},  {"compiler", __VERSION__}, {"quick", o.quick},
                   {"runs", budget.runs}};
    nlohmann::json t1 = nlohmann::json::array();
    for (const Table1Row& t : table1) {
      t1.push_back({{"patch", t.patch->name},
                    {"grid", std::to_string(t.patch->m) + "x" + std::to_string(t.patch->n)},
                    {"bound_vertices", t.bound},
                    {"update_kind", t.patch->simulated ? "simulation" : "rbf"},
                    {"update_per_s", RowJson(t.update)},
                    {"rebuild_per_s", RowJson(t.rebuild)},
                    {"total_per_s", RowJson(t.total)}});
    }
    j["table1"] = t1;
    for (const Row& r : rows) j["figures"][r.key] = RowJson(r);
    const std::string tmp = o.json + ".tmp";
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out << j.dump(2) << "\n";
      if (!out) {
        return ReportError(base::MakeError(base::ErrorCode::kIo, {o.json, 0, 0, {}},
                                           "cannot write the JSON file"));
      }
    }
    std::filesystem::rename(tmp, o.json, ec);
    if (ec) {
      return ReportError(base::MakeError(base::ErrorCode::kIo, {o.json, 0, 0, {}}, ec.message()));
    }
    std::printf("\njson: %s\n", o.json.c_str());
  }
  return 0;
}

}  // namespace app
