#include "app/render_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <vector>

#include "app/character_motion.h"
#include "app/demo_data.h"
#include "app/frame_plan.h"
#include "app/frame_render.h"
#include "app/motion_source.h"
#include "app/output_guard.h"
#include "app/pipeline.h"
#include "app/progress.h"
#include "app/rig_examples.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "render/async_writer.h"
#include "render/camera.h"
#include "render/contact_sheet.h"
#include "render/image_io.h"
#include "render/overlay.h"
#include "render/renderer.h"
#include "render/serial_task_queue.h"
#include "render/stored_image.h"
#include "render/video_writer.h"

namespace app {
namespace {

constexpr int kMaxSheetFrames = 24;
// Most samples per frame (width * height * supersample^2): 8K UHD at 2x2 fits;
// beyond it the sample buffers alone would take several GiB.
constexpr std::int64_t kMaxFrameSamples = std::int64_t{1} << 27;
// A tent resolve holds the frame's samples (16 bytes each): 1920x1080 or
// 3840x2160 at 2x2 fit (33 million samples, 530 MB).
constexpr std::int64_t kMaxTentSamples = 40'000'000;

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}


void AddOutputFlags(CLI::App& cmd, RenderOptions& o) {
  cmd.add_flag("--overwrite", o.overwrite, "Replace existing frames, contact sheet and video");
  cmd.add_flag("--resume", o.resume,
               "Keep the frames that exist (an interrupted render), render the missing ones");
}

}  // namespace

CLI::App* AddRenderCommand(CLI::App& parent, RenderOptions& o) {
  CLI::App* cmd = parent.add_subcommand(
      "render", "Render a capture (BVH on a mannequin) or a glTF animation to image frames");
  cmd->add_option("input", o.input, "BVH, glTF or GLB file, or a rig (.json); none = the built-in demo");
  cmd->add_option("--frames", o.frames, "A:B[:STEP] output frames, inclusive (default all)");
  cmd->add_option("--fps", o.fps, "Output frame rate; the motion is resampled (default: its own)");
  cmd->add_option("--size", o.size, "Image size WxH")->capture_default_str();
  cmd->add_option("--out", o.out,
                  "Output pattern; #### is the frame number, the extension picks the format "
                  "(png, exr, tif, jpg). Default out/<name>/frame_####.png");
  cmd->add_option("--global", o.global, "Global skinning: ssd, dqs or swd")->capture_default_str();
  cmd->add_option("--camera", o.camera, "follow, fixed or turntable")->capture_default_str();
  cmd->add_option("--turntable-frames", o.turntable_frames, "Images in a turntable")
      ->capture_default_str();
  cmd->add_option("--elevation", o.elevation_deg, "Camera elevation in degrees")
      ->capture_default_str();
  cmd->add_option("--overlay", o.overlay, "Comma list: skeleton, wire");
  cmd->add_option("--split", o.split,
                  "Left half one method, right half another (LEFT,RIGHT); default ssd,<global>")
      ->expected(0, 1)
      ->default_str("");
  cmd->add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
  cmd->add_option("--supersample", o.supersample, "Anti-aliasing samples per axis: 1, 2 or 4")
      ->capture_default_str();
  cmd->add_option("--resolve", o.resolve,
                  "Supersample filter: box (the pixel's own samples) or tent (radius one pixel, softer)")
      ->capture_default_str();
  cmd->add_option("--png-compression", o.png_compression, "PNG zlib level 0..9")
      ->capture_default_str();
  cmd->add_flag("--no-sheet", o.no_sheet, "Do not write the contact sheet");
  cmd->add_flag("--no-video", o.no_video, "Do not write the preview video");
  cmd->add_flag("--quiet", o.quiet, "No progress output");
  cmd->add_flag("--stats", o.stats,
                "Print when the first frame was ready and the peak memory (long captures)");
  cmd->add_option("--framing", o.framing,
                  "A:B[:STEP] frames the camera framing looks at (default: the output frames; "
                  "chunks of one render pass the whole range)");
  cmd->add_option("--motion", o.motion,
                  "BVH motion driving a glTF INPUT (joints matched by name; see README)");
  cmd->add_option("--body", o.body,
                  "Body of a BVH INPUT: generated, tubes, or a glTF/GLB character it drives")
      ->capture_default_str();
  AddOutputFlags(*cmd, o);
  // Which options were given: with a rig file they override its settings.
  cmd->callback([&o, cmd] {
    for (const CLI::Option* opt : cmd->get_options()) {
      if (opt->count() > 0) o.given.insert(opt->get_name());
    }
  });
  return cmd;
}

CLI::App* AddTurntableCommand(CLI::App& parent, RenderOptions& o) {
  CLI::App* cmd = parent.add_subcommand(
      "turntable", "One frame of the motion, the camera orbiting it (render --camera turntable)");
  cmd->add_option("input", o.input, "BVH, glTF or GLB file; none = the built-in demo");
  cmd->add_option("--frames", o.frames, "The motion frame to show (default 0)");
  cmd->add_option("--turntable-frames", o.turntable_frames, "Images in the orbit")
      ->capture_default_str();
  cmd->add_option("--elevation", o.elevation_deg, "Camera elevation in degrees")
      ->capture_default_str();
  cmd->add_option("--size", o.size, "Image size WxH")->capture_default_str();
  cmd->add_option("--out", o.out, "Output pattern (default out/<name>_turntable/frame_####.png)");
  cmd->add_option("--global", o.global, "Global skinning: ssd, dqs or swd")->capture_default_str();
  cmd->add_option("--overlay", o.overlay, "Comma list: skeleton, wire");
  cmd->add_option("--threads", o.threads, "Worker threads (0 = all cores)");
  cmd->add_option("--supersample", o.supersample, "Anti-aliasing samples per axis: 1, 2 or 4");
  cmd->add_option("--resolve", o.resolve, "Supersample filter: box or tent");
  cmd->add_flag("--no-sheet", o.no_sheet, "Do not write the contact sheet");
  cmd->add_flag("--no-video", o.no_video, "Do not write the preview video");
  cmd->add_flag("--quiet", o.quiet, "No progress output");
  AddOutputFlags(*cmd, o);
  cmd->callback([&o] { o.camera = "turntable"; });
  return cmd;
}

namespace {

int Fail(const mocap::Error& e) {
  std::fprintf(stderr, "%s\n", e.ToString().c_str());
  return e.code == mocap::ErrorCode::kInternal ? 3 : 2;
}

// This process's peak resident memory in MB (VmHWM of /proc/self/status), 0 if unknown.
double PeakResidentMb() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return 0.0;
  char line[256];
  long kb = 0;
  while (std::fgets(line, sizeof(line), f) != nullptr) {
    if (std::sscanf(line, "VmHWM: %ld kB", &kb) == 1) break;
  }
  std::fclose(f);
  return static_cast<double>(kb) * 1024.0 / 1e6;
}

}  // namespace

int RunRender(const RenderOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  double first_frame_s = -1.0;  // --stats: when the first frame went to the writer
  // --- A rig file (README "Rig files") sets the inputs and render settings ---
  RenderOptions o = options;
  std::optional<Rig> rig;
  const bool cli_split = o.split.has_value();
  if (std::filesystem::path(o.input).extension() == ".json") {
    mocap::Result<Rig> loaded = LoadRig(o.input);
    if (!loaded.ok()) return Fail(loaded.error());
    rig = std::move(*loaded);
    // The rig sets what the command line leaves out; an option given wins.
    const auto given = [&o](const char* name) { return o.given.count(name) > 0; };
    o.input = rig->character == "mannequin" ? rig->motion : rig->character;
    if (rig->character != "mannequin" && !rig->motion.empty() && !given("--motion")) {
      o.motion = rig->motion;
    }
    if (!given("--global")) o.global = rig->global;
    if (!given("--fps")) o.fps = rig->fps;
    if (!given("--size")) {
      o.size = std::to_string(rig->render.size.x) + "x" + std::to_string(rig->render.size.y);
    }
    if (!given("--camera")) o.camera = rig->render.camera;
    if (!given("--overlay")) {
      o.overlay.clear();
      for (const std::string& item : rig->render.overlays) o.overlay += item + ",";
    }
    if (!given("--out") || o.out.empty()) o.out = rig->render.output;
    if (!given("--frames") || o.frames.empty()) o.frames = rig->render.frames;
    // Without --split the rig's split is global only | global + patches (below).
    if (!given("--split")) o.split.reset();
  }

  // --- Arguments -------------------------------------------------------------
  const mocap::Result<glm::ivec2> size = ParseSize(o.size);
  if (!size.ok()) return Fail(size.error());
  if (o.supersample != 1 && o.supersample != 2 && o.supersample != 4) {
    return Fail(ArgError("--supersample", "expected 1, 2 or 4, found " + std::to_string(o.supersample)));
  }
  if (std::int64_t{size->x} * size->y * o.supersample * o.supersample > kMaxFrameSamples) {
    return Fail(ArgError("--size", "expected at most " + std::to_string(kMaxFrameSamples) +
                                       " samples per frame (width x height x supersample^2), found " +
                                       o.size + " at supersample " + std::to_string(o.supersample)));
  }
  if (o.resolve != "box" && o.resolve != "tent") {
    return Fail(ArgError("--resolve", "expected box or tent, found '" + o.resolve + "'"));
  }
  if (o.resolve == "tent" && o.supersample > 1 &&
      std::int64_t{size->x} * size->y * o.supersample * o.supersample > kMaxTentSamples) {
    return Fail(ArgError("--resolve", "a tent resolve keeps every sample: expected at most " +
                                          std::to_string(kMaxTentSamples) +
                                          " samples per frame, found " + o.size +
                                          " at supersample " + std::to_string(o.supersample)));
  }
  if (o.png_compression < 0 || o.png_compression > 9) {
    return Fail(ArgError("--png-compression", "expected 0..9"));
  }
  if (o.camera != "follow" && o.camera != "fixed" && o.camera != "turntable") {
    return Fail(ArgError("--camera", "expected follow, fixed or turntable, found '" + o.camera + "'"));
  }
  if (o.turntable_frames < 1 || o.turntable_frames > 100000) {
    return Fail(ArgError("--turntable-frames", "expected 1..100000"));
  }
  if (o.threads < 0 || o.threads > 256) return Fail(ArgError("--threads", "expected 0..256"));
  if (!(o.fps >= 0.0) || o.fps > 10000.0) return Fail(ArgError("--fps", "expected 0 < fps <= 10000"));
  bool overlay_skeleton = false, overlay_wire = false;
  for (const std::string& item : SplitList(o.overlay)) {
    if (item == "skeleton") overlay_skeleton = true;
    else if (item == "wire" || item == "wireframe") overlay_wire = true;
    else return Fail(ArgError("--overlay", "expected skeleton or wire, found '" + item + "'"));
  }
  const mocap::Result<GlobalMethod> method = ParseGlobalMethod(o.global);
  if (!method.ok()) return Fail(method.error());
  std::optional<GlobalMethod> split_left, split_right;
  if (o.split) {
    std::vector<std::string> pair = SplitList(*o.split);
    if (pair.empty()) pair = {"ssd", *method == GlobalMethod::kSsd ? "dqs" : o.global};
    if (pair.size() != 2) return Fail(ArgError("--split", "expected LEFT,RIGHT such as ssd,dqs"));
    const auto l = ParseGlobalMethod(pair[0]);
    const auto r = ParseGlobalMethod(pair[1]);
    if (!l.ok()) return Fail(l.error());
    if (!r.ok()) return Fail(r.error());
    split_left = *l;
    split_right = *r;
  }

  // --- Body: a rig file names vertices of the tube mannequin; a glTF body is the
  // character and the BVH input its --motion.
  BodyKind body = BodyKind::kGenerated;
  const std::string body_ext = std::filesystem::path(o.body).extension().string();
  if (body_ext == ".glb" || body_ext == ".gltf") {
    if (rig || !o.motion.empty()) {
      return Fail(ArgError("--body", "a glTF/GLB body takes a BVH INPUT as its motion; not with a rig file or --motion"));
    }
    o.motion = o.input.empty() ? std::string() : o.input;
    if (o.motion.empty()) return Fail(ArgError("--body", "a glTF/GLB body needs a BVH INPUT to drive it"));
    o.input = o.body;
  } else {
    const mocap::Result<BodyKind> kind = ParseBodyKind(o.body);
    if (!kind.ok()) return Fail(kind.error());
    body = rig ? BodyKind::kTubes : *kind;
    if (rig && o.given.count("--body") > 0 && *kind != BodyKind::kTubes) {
      return Fail(ArgError("--body", "rig files name vertices of the tube body; expected tubes with a rig"));
    }
  }

  // --- Input -----------------------------------------------------------------
  const bool demo = o.input.empty();
  const std::string name = demo  ? "demo"
                           : rig ? std::filesystem::path(rig->file).stem().string()
                                 : std::filesystem::path(o.input).stem().string();
  mocap::Result<Character> character = LoadCommandCharacter(o.input, o.motion, o.quiet, body);
  if (!character.ok()) return Fail(character.error());
  const Character& ch = *character;

  const bool turntable = o.camera == "turntable";
  mocap::Result<FramePlan> plan = PlanFrames(
      ch.motion, {.frames = o.frames, .fps = o.fps, .turntable = turntable,
                  .turntable_frames = o.turntable_frames, .list_frames = false});
  if (!plan.ok()) {
    if (rig && options.frames.empty() && !rig->render.frames.empty()) {
      // The range came from the rig file: name it and its field, not --frames.
      mocap::Error e = plan.error();
      e.loc = {rig->file, 0, 0, "render.frames"};
      return Fail(e);
    }
    return Fail(plan.error());
  }
  const double frame_time = plan->frame_time_s;
  // The output frames are computed one at a time (plan->At): a render of
  // every frame of an hour-long capture holds no per-frame list (issue 8).
  const std::size_t num_frames = plan->count();

  std::string pattern = o.out;
  if (pattern.empty()) pattern = "out/" + name + (turntable ? "_turntable" : "") + "/frame_####.png";
  if (!render::HasFramePlaceholder(pattern)) {
    return Fail(ArgError("--out", "the pattern '" + pattern +
                                      "' needs one frame placeholder such as #### or %04d"));
  }
  // Existing outputs are refused (or, with --resume, skipped) before anything renders.
  OutputGuard guard({.overwrite = o.overwrite, .resume = o.resume});
  {
    const auto frame_path = [&pattern, &plan](std::size_t i) {
      return render::ExpandFramePattern(pattern, plan->At(i).number);
    };
    const mocap::Result<std::string> first_path = frame_path(0);
    if (!first_path.ok()) return Fail(first_path.error());
    const std::filesystem::path dir = std::filesystem::path(*first_path).parent_path();
    std::vector<std::string> others;
    if (!o.no_sheet) others.push_back((dir / "contact_sheet.png").string());
    if (!o.no_video) others.push_back((dir / "preview.mp4").string());
    const mocap::Status planned = guard.Plan(num_frames, frame_path, others);
    if (!planned.ok()) return Fail(planned.error());
  }

  // --- Pipelines ---------------------------------------------------------------
  // --split on the command line turns a rig's split on (global only | patches).
  const bool has_layers = rig && !rig->patches.empty();
  const bool rig_split = has_layers && (rig->render.split || cli_split);
  if (rig_split && !o.split) split_left = split_right = *method;
  const GlobalMethod main_method = split_left ? *split_left : *method;
  mocap::Result<FramePipeline> pipeline = FramePipeline::Create(ch, main_method, o.threads);
  if (!pipeline.ok()) return Fail(pipeline.error());
  std::optional<FramePipeline> right_pipeline;
  if (split_right) {
    mocap::Result<FramePipeline> p = FramePipeline::Create(ch, *split_right, o.threads);
    if (!p.ok()) return Fail(p.error());
    right_pipeline.emplace(std::move(*p));
  }
  if (has_layers) {
    // Split: the left half stays global only, the right half gets the layers
    // (patches, example shapes, elastic), set up as `export` sets them up.
    FramePipeline& layered = right_pipeline ? *right_pipeline : *pipeline;
    std::vector<std::string> notes;
    if (mocap::Status s = ApplyRigLayers(*rig, ch, layered, &notes); !s.ok()) return Fail(s.error());
    if (!o.quiet) {
      for (const std::string& note : notes) std::fprintf(stderr, "%s\n", note.c_str());
    }
  }
  const std::string right_label =
      !right_pipeline ? ""
      : right_pipeline->num_patches() > 0
          ? std::string(GlobalMethodName(right_pipeline->method())) + " + patches"
          : GlobalMethodName(right_pipeline->method());

  // --- Framing (app/frame_plan.h) ------------------------------------------------
  DeformedFrame frame, right_frame;
  mocap::Result<FramePlan> framing = plan;
  if (!o.framing.empty() && !turntable) {
    framing = PlanFrames(ch.motion, {.frames = o.framing, .fps = o.fps, .list_frames = false});
    if (!framing.ok()) return Fail(ArgError("--framing", framing.error().message));
    if (plan->range.first < framing->range.first || plan->range.last > framing->range.last) {
      return Fail(ArgError("--framing", "expected a range holding every output frame (" +
                                            std::to_string(plan->range.first) + ".." +
                                            std::to_string(plan->range.last) + "), found '" +
                                            o.framing + "'"));
    }
  }
  mocap::Result<CameraPlan> cameras = CameraPlan::Create(*pipeline, *framing, o.camera,
                                                         o.elevation_deg, *size);
  if (!cameras.ok()) return Fail(cameras.error());
  const float ground_y = cameras->ground_y();

  // --- Outputs -------------------------------------------------------------------
  {
    const mocap::Result<std::string> first = render::ExpandFramePattern(pattern, plan->At(0).number);
    if (!first.ok()) return Fail(first.error());
    const std::filesystem::path dir = std::filesystem::path(*first).parent_path();
    std::error_code ec;
    if (!dir.empty()) std::filesystem::create_directories(dir, ec);
    if (ec) {
      return Fail(mocap::MakeError(mocap::ErrorCode::kIo, {dir.string(), 0, 0, {}},
                                   "cannot create the output folder: " + ec.message()));
    }
  }
  const std::filesystem::path out_dir =
      std::filesystem::path(*render::ExpandFramePattern(pattern, 0)).parent_path();
  render::RenderSettings settings;
  settings.width = size->x;
  settings.height = size->y;
  settings.supersample = o.supersample;
  settings.resolve = o.resolve == "tent" ? render::ResolveFilter::kTent : render::ResolveFilter::kBox;
  settings.threads = o.threads;
  settings.ground_at_scene_min = false;
  settings.ground_y = ground_y;
  // Only EXR frames store depth (their Z channel); the renderer still keeps it
  // internally while it draws depth-tested overlays.
  {
    const mocap::Result<render::ImageFormat> format = render::ImageFormatFromPath(pattern);
    settings.write_depth = format.ok() && *format == render::ImageFormat::kExr;
  }
  render::Renderer renderer;
  render::Renderer right_renderer;
  render::AsyncImageWriter writer({.num_workers = 2, .max_in_flight = 4});
  render::WriteOptions write_options;
  write_options.png_compression = o.png_compression;
  write_options.source_file = demo ? "demo_walk.bvh (built in)" : rig ? rig->file : o.input;

  const int sheet_count = std::min<int>(kMaxSheetFrames, static_cast<int>(num_frames));
  std::unique_ptr<render::ContactSheetBuilder> sheet;
  if (!o.no_sheet) {
    auto b = render::ContactSheetBuilder::Create(sheet_count, size->x, size->y);
    if (!b.ok()) return Fail(b.error());
    sheet = std::move(*b);
  }
  std::unique_ptr<render::VideoWriter> video;
  if (!o.no_video) {
    const double video_fps = turntable ? 24.0 : 1.0 / (frame_time * plan->range.step);
    auto v = render::VideoWriter::Open((out_dir / "preview.mp4").string(), size->x & ~1,
                                       size->y & ~1, {.fps = video_fps});
    if (!v.ok()) return Fail(v.error());
    video = std::move(*v);
  }

  // --- The frame loop -------------------------------------------------------------
  Progress progress(demo ? "render demo" : "render " + name, static_cast<int>(num_frames), o.quiet);
  render::Image image, right_image;
  int next_sheet = 0;
  // The sheet gets every frame as its file will read back (render/stored_image.h),
  // so a --resume that rebuilds it from finished frames on disk gives the same
  // bytes; formats whose round trip is not modelled (JPEG) use the frame as is.
  const mocap::Result<render::ImageFormat> frame_format = render::ImageFormatFromPath(pattern);
  auto feed_sheet_and_video = [&](std::size_t i, int number, const render::Image& img,
                                  bool read_back) {
    if (sheet && next_sheet < sheet_count &&
        i == num_frames * static_cast<std::size_t>(next_sheet) / static_cast<std::size_t>(sheet_count)) {
      const render::Image* thumb_source = &img;
      mocap::Result<render::Image> stored = render::Image();
      if (!read_back && frame_format.ok()) {
        stored = render::AsStored(img, *frame_format, write_options);
        if (stored.ok()) thumb_source = &*stored;
      }
      if (mocap::Status st = sheet->Add(*thumb_source, number); !st.ok()) return st;
      ++next_sheet;
    }
    if (video) return video->AddFrame(img);
    return mocap::Status::Ok();
  };
  // The sheet and the H.264 preview take frames in order on their own thread,
  // so encoding the video overlaps rendering the next frame (each task holds
  // its own copy of the frame; at most two are pending).
  render::SerialTaskQueue side({.max_queued = 2});
  auto feed_async = [&](std::size_t i, int number, std::shared_ptr<const render::Image> img,
                        bool read_back) {
    if (!sheet && !video) return mocap::Status::Ok();
    return side.Submit([&feed_sheet_and_video, i, number, img = std::move(img), read_back] {
      return feed_sheet_and_video(i, number, *img, read_back);
    });
  };
  int frames_done = guard.num_skipped();
  int last_done_number = -1;
  for (std::size_t i = 0; i < num_frames; ++i) {
    if (guard.interrupted()) break;
    const OutputFrame of = plan->At(i);
    // Skipped frames are still evaluated: a pipeline that carries state from
    // frame to frame (the elastic layer) must see every frame to give a
    // resumed range the same result.
    mocap::Status s = pipeline->Evaluate(of.time_s, frame);
    if (!s.ok()) return Fail(s.error());
    if (right_pipeline) {
      s = right_pipeline->Evaluate(of.time_s, right_frame);
      if (!s.ok()) return Fail(s.error());
    }
    if (guard.skip(i)) {
      // Resumed: the finished frame on disk feeds the sheet and the video.
      if (!sheet && !video) continue;
      const mocap::Result<std::string> done_path = render::ExpandFramePattern(pattern, of.number);
      if (!done_path.ok()) return Fail(done_path.error());
      mocap::Result<render::Image> done = render::ReadImage(*done_path);
      if (!done.ok()) return Fail(done.error());
      s = feed_async(i, of.number, std::make_shared<const render::Image>(std::move(*done)),
                     /*read_back=*/true);
      if (!s.ok()) return Fail(s.error());
      continue;
    }
    const render::Camera camera = cameras->At(of);
    const FrameDrawOptions draw{.skeleton = overlay_skeleton,
                                .wireframe = overlay_wire,
                                .frame_number = of.number,
                                .left_label = right_pipeline ? GlobalMethodName(main_method) : "",
                                .right_label = right_pipeline ? right_label : ""};
    s = DrawCharacterFrame(ch, frame, right_pipeline ? &right_frame : nullptr, camera, settings,
                           draw, renderer, right_renderer, right_image, image);
    if (!s.ok()) return Fail(s.error());
    s = feed_async(i, of.number, std::make_shared<const render::Image>(image), /*read_back=*/false);
    if (!s.ok()) return Fail(s.error());
    const mocap::Result<std::string> path = render::ExpandFramePattern(pattern, of.number);
    if (!path.ok()) return Fail(path.error());
    write_options.frame = of.number;
    // The frame moves to the writer; the next one renders into the buffers
    // of one already written (when there is one), so no frame-sized buffer is
    // copied, allocated or first touched per frame.
    s = writer.Submit(std::move(image), *path, write_options);
    if (!s.ok()) return Fail(s.error());
    image = writer.TakeSpareImage();
    ++frames_done;
    if (first_frame_s < 0.0) {
      first_frame_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    }
    last_done_number = of.number;
    progress.Step(of.number);
  }
  // Every frame handed to the writer is finished (so none is left half-written).
  mocap::Status s = writer.Finish();
  if (!s.ok()) return Fail(s.error());
  s = side.Finish();
  if (!s.ok()) return Fail(s.error());
  progress.Finish();
  if (guard.interrupted()) {
    // The sheet and the video would be partial: the video writer's destructor
    // removes its temporary file; --resume rebuilds both.
    std::fprintf(stderr, "%s: %s\n", pattern.c_str(),
                 guard.StopMessage(last_done_number, frames_done, static_cast<int>(num_frames))
                     .c_str());
    return guard.exit_code();
  }
  // The elastic layer says when it had to limit anything (ALGORITHMS.md 6).
  for (const FramePipeline* p : {&*pipeline, right_pipeline ? &*right_pipeline : nullptr}) {
    if (p == nullptr) continue;
    for (const ElasticPatchReport& r : p->elastic_report()) {
      if (r.counters.any_limit() == 0) continue;
      std::fprintf(stderr,
                   "%s: warning: elastic patch \"%s\" was limited: %lld acceleration clamps, "
                   "%lld displacement clamps, %lld non-finite inputs, %lld non-finite resets\n",
                   write_options.source_file.c_str(),
                   rig ? rig->patches[static_cast<std::size_t>(r.patch)].name.c_str() : "?",
                   static_cast<long long>(r.counters.acceleration_clamps),
                   static_cast<long long>(r.counters.displacement_clamps),
                   static_cast<long long>(r.counters.non_finite_inputs),
                   static_cast<long long>(r.counters.non_finite_resets));
    }
  }
  std::printf("frames:        %s (%zu)\n", pattern.c_str(), num_frames);
  if (sheet) {
    const std::string sheet_path = (out_dir / "contact_sheet.png").string();
    s = render::WriteImage(sheet->sheet(), sheet_path, {});
    if (!s.ok()) return Fail(s.error());
    std::printf("contact sheet: %s\n", sheet_path.c_str());
  }
  if (video) {
    s = video->Close();
    if (!s.ok()) return Fail(s.error());
    std::printf("video:         %s (%s)\n", video->path().c_str(), render::VideoCodecName(video->codec()));
  }
  if (o.stats) {
    std::printf("stats:         first frame after %.3f s, peak memory %.1f MB\n", first_frame_s,
                PeakResidentMb());
  }
  return 0;
}

}  // namespace app
