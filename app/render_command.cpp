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

#include "app/auto_rig.h"
#include "app/character_motion.h"
#include "app/demo_data.h"
#include "app/frame_plan.h"
#include "app/frame_render.h"
#include "app/motion_source.h"
#include "app/output_guard.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/progress.h"
#include "app/rig_examples.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "app/exit_code.h"
#include "render/output/async_writer.h"
#include "render/camera.h"
#include "render/output/contact_sheet.h"
#include "render/output/image_io.h"
#include "render/raster/overlay.h"
#include "render/renderer.h"
#include "render/output/serial_task_queue.h"
#include "render/output/stored_image.h"
#include "render/output/video_writer.h"

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

// One body of a comparison: a global method, with or without the rig's patch layer.
struct BodySpec {
  deform::GlobalMethod method = deform::GlobalMethod::kSsd;
  bool patches = false;
  std::string Label() const {
    return std::string(deform::GlobalMethodName(method)) + (patches ? " + patches" : "");
  }
};

// "ssd", "dqs+patches", "swd + patches": a method and whether the patch layer is on.
base::Result<BodySpec> ParseBodySpec(std::string text, const std::string& option) {
  std::erase(text, ' ');
  BodySpec spec;
  const std::string suffix = "+patches";
  if (text.size() > suffix.size() && text.ends_with(suffix)) {
    spec.patches = true;
    text.resize(text.size() - suffix.size());
  }
  base::Result<deform::GlobalMethod> method = ParseGlobalMethod(text);
  if (!method.ok()) {
    return ArgError(option, "expected ssd, dqs or swd, optionally with +patches, found '" + text + "'");
  }
  spec.method = *method;
  return spec;
}

enum class View { kOne, kCompare, kWipe };

struct TwoBodies {
  View view = View::kOne;
  BodySpec sides[2];
};

// What a render shows: --compare or --wipe (--split) when given, else a rig's
// render settings (a rig with patches compares its global method alone with
// the same method and its patches, side by side, unless it asks for a wipe
// or "split": false), else one body.
base::Result<TwoBodies> ChooseTwoBodies(const RenderOptions& o, const Rig* rig,
                                        deform::GlobalMethod global) {
  const bool has_layers = rig != nullptr && !rig->patches.empty();
  TwoBodies two;
  std::string pair_text, option = "--compare";
  if (o.compare) {
    two.view = View::kCompare;
    pair_text = *o.compare;
  } else if (o.wipe) {
    two.view = View::kWipe;
    pair_text = *o.wipe;
    option = "--wipe";
  } else if (has_layers && rig->render.split) {
    two.view = rig->render.wipe ? View::kWipe : View::kCompare;
    pair_text = rig->render.compare;
    option = "render.compare";
  } else {
    return two;
  }
  std::vector<std::string> pair = SplitList(pair_text);
  if (pair.empty()) {
    const std::string g = deform::GlobalMethodName(global);
    pair = has_layers
               ? std::vector<std::string>{g, g + "+patches"}
               : std::vector<std::string>{"ssd", global == deform::GlobalMethod::kSsd ? "dqs" : g};
  }
  // Errors name the option, or the rig file and its field.
  const auto fail = [&](base::Error e) {
    if (option == "render.compare") e.loc = {rig->file, 0, 0, option};
    return e;
  };
  if (pair.size() != 2) return fail(ArgError(option, "expected A,B such as ssd,ssd+patches"));
  for (int i = 0; i < 2; ++i) {
    base::Result<BodySpec> side = ParseBodySpec(pair[static_cast<std::size_t>(i)], option);
    if (!side.ok()) return fail(std::move(side).error());
    if (side->patches && !has_layers) {
      return fail(ArgError(option, "'" + pair[static_cast<std::size_t>(i)] +
                                       "' needs a rig file with patches as the input"));
    }
    two.sides[i] = *side;
  }
  // A wipe of two methods on a rig with patches (the old --split): the right
  // half gets the patches.
  if (two.view == View::kWipe && has_layers && !two.sides[0].patches && !two.sides[1].patches) {
    two.sides[1].patches = true;
  }
  return two;
}

// The label at a frame's bottom left: "frame N", a timecode HH:MM:SS:FF (or
// HH:MM:SS.mmm when the frame rate is not a whole number), or nothing.
std::string FrameLabel(const std::string& kind, int number, double frame_time_s) {
  if (kind == "none") return "";
  if (kind == "frame") return "frame " + std::to_string(number);
  const double fps = 1.0 / frame_time_s;
  const long long whole_fps = std::llround(fps);
  char text[40];
  if (whole_fps > 0 && std::abs(fps - static_cast<double>(whole_fps)) < 1e-6) {
    const long long s = number / whole_fps, f = number % whole_fps;
    std::snprintf(text, sizeof(text), "%02lld:%02lld:%02lld:%02lld", s / 3600, s / 60 % 60, s % 60, f);
  } else {
    const long long ms = std::llround(number * frame_time_s * 1000.0);
    std::snprintf(text, sizeof(text), "%02lld:%02lld:%02lld.%03lld", ms / 3600000, ms / 60000 % 60,
                  ms / 1000 % 60, ms % 1000);
  }
  return text;
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

// A rig file (docs/rig-file.md), or the rig --layer auto makes, when the
// input is one: its settings fill in what the command line left out (an option
// given wins). No rig: nothing changes.
base::Result<std::optional<Rig>> TakeRenderRig(RenderOptions& o) {
  std::optional<Rig> rig;
  if (!o.layer.empty()) {
    // --layer auto: the rig `patchskin rig auto` would write, used as if read.
    base::Result<Rig> made = AutoRigForCommand(o.layer, o.input, o.motion, o.body, o.up, o.quiet);
    if (!made.ok()) return std::move(made).error();
    rig = std::move(*made);
    o.given.erase("--body");  // the rig names the body now
    o.body = "generated";
  } else if (std::filesystem::path(o.input).extension() == ".json") {
    base::Result<Rig> loaded = LoadRig(o.input);
    if (!loaded.ok()) return std::move(loaded).error();
    rig = std::move(*loaded);
  }
  if (rig) {
    // The rig sets what the command line leaves out; an option given wins.
    ApplyRigSettings(*rig, o);
    const auto given = [&o](const char* name) { return o.given.count(name) > 0; };
    if (!given("--azimuth") && rig->render.azimuth_deg) o.azimuth_deg = rig->render.azimuth_deg;
    if (!given("--elevation") && rig->render.elevation_deg) o.elevation_deg = *rig->render.elevation_deg;
    if (!given("--distance")) o.distance = rig->render.distance;
    if (!given("--zoom")) o.zoom = rig->render.zoom;
    if (!given("--look-at")) o.look_at = rig->render.look_at;
    if (!given("--overlay")) {
      o.overlay.clear();
      for (const std::string& item : rig->render.overlays) o.overlay += item + ",";
    }
    if (!given("--out") || o.out.empty()) o.out = rig->render.output;
  }
  return rig;
}

// The --overlay items asked for.
struct Overlays {
  bool skeleton = false, wire = false, patches = false, delta = false;
};

// The render options' ranges and names (kInvalidArgument naming the option);
// the overlays they ask for.
base::Result<Overlays> CheckRenderOptions(const RenderOptions& o, glm::ivec2 size) {
  if (o.supersample != 1 && o.supersample != 2 && o.supersample != 4) {
    return ArgError("--supersample", "expected 1, 2 or 4, found " + std::to_string(o.supersample));
  }
  if (std::int64_t{size.x} * size.y * o.supersample * o.supersample > kMaxFrameSamples) {
    return ArgError("--size", "expected at most " + std::to_string(kMaxFrameSamples) +
                                  " samples per frame (width x height x supersample^2), found " +
                                  o.size + " at supersample " + std::to_string(o.supersample));
  }
  if (o.aa != "ssaa" && o.aa != "msaa") {
    return ArgError("--aa", "expected ssaa or msaa, found '" + o.aa + "'");
  }
  if (o.shadows != "on" && o.shadows != "off") {
    return ArgError("--shadows", "expected on or off, found '" + o.shadows + "'");
  }
  if (o.textures != "on" && o.textures != "off") {
    return ArgError("--textures", "expected on or off, found '" + o.textures + "'");
  }
  if (o.resolve != "box" && o.resolve != "tent") {
    return ArgError("--resolve", "expected box or tent, found '" + o.resolve + "'");
  }
  if (o.resolve == "tent" && o.supersample > 1 &&
      std::int64_t{size.x} * size.y * o.supersample * o.supersample > kMaxTentSamples) {
    return ArgError("--resolve", "a tent resolve keeps every sample: expected at most " +
                                     std::to_string(kMaxTentSamples) +
                                     " samples per frame, found " + o.size + " at supersample " +
                                     std::to_string(o.supersample));
  }
  if (o.png_compression < 0 || o.png_compression > 9) {
    return ArgError("--png-compression", "expected 0..9");
  }
  if (o.camera != "follow" && o.camera != "fixed" && o.camera != "turntable") {
    return ArgError("--camera", "expected follow, fixed or turntable, found '" + o.camera + "'");
  }
  if (o.turntable_frames < 1 || o.turntable_frames > 100000) {
    return ArgError("--turntable-frames", "expected 1..100000");
  }
  if (const auto bad = CheckThreads(o.threads)) return *bad;
  if (const auto bad = CheckFps(o.fps)) return *bad;
  Overlays overlays;
  for (const std::string& item : SplitList(o.overlay)) {
    if (item == "skeleton")
      overlays.skeleton = true;
    else if (item == "wire" || item == "wireframe")
      overlays.wire = true;
    else if (item == "patches")
      overlays.patches = true;
    else if (item == "delta")
      overlays.delta = true;
    else {
      return ArgError("--overlay",
                      "expected skeleton, wire, patches or delta, found '" + item + "'");
    }
  }
  if (o.label != "none" && o.label != "frame" && o.label != "timecode") {
    return ArgError("--label", "expected none, frame or timecode, found '" + o.label + "'");
  }
  if (o.background != "gradient" && o.background != "transparent") {
    return ArgError("--background",
                    "expected gradient or transparent, found '" + o.background + "'");
  }
  return overlays;
}

// The body to render: a rig file names its body ("character"); a glTF body
// is the character and the BVH input its --motion (o.input and o.motion are
// set so). Errors name --body.
base::Result<BodyKind> ResolveRenderBody(RenderOptions& o, const Rig* rig) {
  BodyKind body_kind = BodyKind::kGenerated;
  const std::string body_ext = std::filesystem::path(o.body).extension().string();
  if (body_ext == ".glb" || body_ext == ".gltf") {
    if (rig || !o.motion.empty()) {
      return ArgError(
          "--body",
          "a glTF/GLB body takes a BVH INPUT as its motion; not with a rig file or --motion");
    }
    o.motion = o.input.empty() ? std::string() : o.input;
    if (o.motion.empty())
      return ArgError("--body", "a glTF/GLB body needs a BVH INPUT to drive it");
    o.input = o.body;
  } else {
    const base::Result<BodyKind> kind = ParseBodyKind(o.body);
    if (!kind.ok()) return kind.error();
    body_kind = rig ? RigBodyKind(*rig) : *kind;
    if (rig && o.given.count("--body") > 0 && *kind != body_kind) {
      return ArgError("--body",
                      "the rig file names its body (\"character\"); expected " +
                          std::string(body_kind == BodyKind::kTubes ? "tubes" : "generated") +
                          " or no --body with this rig");
    }
  }
  return body_kind;
}

// The renderer's settings the options ask for (ground_y is the caller's).
render::RenderSettings MakeRenderSettings(const RenderOptions& o, glm::ivec2 size,
                                          const std::string& pattern) {
  render::RenderSettings settings;
  settings.width = size.x;
  settings.height = size.y;
  settings.supersample = o.supersample;
  settings.resolve =
      o.resolve == "tent" ? render::ResolveFilter::kTent : render::ResolveFilter::kBox;
  settings.antialias =
      o.aa == "ssaa" ? render::AntiAlias::kSupersample : render::AntiAlias::kMultisample;
  settings.shadows = o.shadows == "on";
  settings.threads = o.threads;
  settings.ground_at_scene_min = false;
  settings.background.transparent = o.background == "transparent";
  // Only EXR frames store depth (their Z channel); the renderer still keeps it
  // internally while it draws depth-tested overlays.
  const base::Result<render::ImageFormat> format = render::ImageFormatFromPath(pattern);
  settings.write_depth = format.ok() && *format == render::ImageFormat::kExr;
  return settings;
}

// The pipelines of a render: one body (the rig's layers on it when it has
// patches), or the two bodies of a comparison, each with the layers when its
// side asks for them; the layers' notes go to stderr unless --quiet.
struct RenderBodies {
  std::optional<deform::FramePipeline> left;   // the only body, or the left one
  std::optional<deform::FramePipeline> right;  // the right body of a comparison
};

base::Result<RenderBodies> MakeRenderBodies(const RenderOptions& o, const Rig* rig,
                                            const Character& ch, const TwoBodies& two,
                                            deform::GlobalMethod method) {
  const bool has_layers = rig && !rig->patches.empty();
  const BodySpec sides[2] = {two.view != View::kOne ? two.sides[0] : BodySpec{method, has_layers},
                             two.sides[1]};
  RenderBodies bodies;
  for (int side = 0; side < (two.view != View::kOne ? 2 : 1); ++side) {
    base::Result<deform::FramePipeline> p =
        deform::FramePipeline::Create(ch, sides[side].method, o.threads);
    if (!p.ok()) return std::move(p).error();
    if (sides[side].patches) {
      // The layers (patches, example shapes, elastic), set up as `export` sets them up.
      std::vector<std::string> notes;
      if (base::Status s = ApplyRigLayers(*rig, ch, *p, &notes); !s.ok()) return s.error();
      if (!o.quiet) {
        for (const std::string& note : notes) std::fprintf(stderr, "%s\n", note.c_str());
      }
    }
    (side == 0 ? bodies.left : bodies.right).emplace(std::move(*p));
  }
  return bodies;
}

// The frame file pattern (--out, else default_folder/frame_####.png),
// checked, with every output the render will write registered in `guard`
// (frames, contact sheet, preview video). Errors name --out or --background,
// or are the guard's (an existing output without --overwrite or --resume).
base::Result<std::string> PlanRenderOutputs(const RenderOptions& o,
                                            const std::string& default_folder,
                                            const FramePlan& plan, OutputGuard& guard) {
  const std::string pattern = o.out.empty() ? default_folder + "/frame_####.png" : o.out;
  if (!render::HasFramePlaceholder(pattern)) {
    return ArgError(
        "--out", "the pattern '" + pattern + "' needs one frame placeholder such as #### or %04d");
  }
  if (o.background == "transparent") {
    const base::Result<render::ImageFormat> format = render::ImageFormatFromPath(pattern);
    if (format.ok() && *format == render::ImageFormat::kJpeg) {
      return ArgError("--background",
                      "transparent needs frames with alpha (PNG, EXR or TIFF), found the JPEG "
                      "pattern '" +
                          pattern + "'");
    }
  }
  const auto frame_path = [&pattern, &plan](std::size_t i) {
    return render::ExpandFramePattern(pattern, plan.At(i).number);
  };
  const base::Result<std::string> first_path = frame_path(0);
  if (!first_path.ok()) return first_path.error();
  const std::filesystem::path dir = std::filesystem::path(*first_path).parent_path();
  std::vector<std::string> others;
  if (!o.no_sheet) others.push_back((dir / "contact_sheet.png").string());
  if (!o.no_video) others.push_back((dir / "preview.mp4").string());
  const base::Status planned = guard.Plan(plan.count(), frame_path, others);
  if (!planned.ok()) return planned.error();
  return pattern;
}

// The output frames (app/frame_plan.h). When the range came from the rig file
// (`typed`, the options as typed, gave none), errors name it and its field, not --frames.
base::Result<FramePlan> PlanRenderFrames(const RenderOptions& typed, const RenderOptions& o,
                                         const Rig* rig, const Character& ch) {
  base::Result<FramePlan> plan = PlanFrames(ch.motion, {.frames = o.frames,
                                                        .fps = o.fps,
                                                        .turntable = o.camera == "turntable",
                                                        .turntable_frames = o.turntable_frames,
                                                        .start_number = o.start_number,
                                                        .list_frames = false});
  if (!plan.ok() && rig && typed.frames.empty() && !rig->render.frames.empty()) {
    base::Error e = plan.error();
    e.loc = {rig->file, 0, 0, "render.frames"};
    return e;
  }
  return plan;
}

// The colours of the patch layer's overlays: patches tints every region (both
// bodies); delta colours each body with patches by its displacement from the
// same method alone, evaluated by a global-only pipeline per such body.
class RenderOverlayColors {
 public:
  // Errors: an overlay without a rig with patches (naming --overlay), those of
  // BuildRigPatches and of the global-only pipelines.
  static base::Result<RenderOverlayColors> Create(const Overlays& overlays, const Rig* rig,
                                                  const Character& ch, const RenderBodies& bodies,
                                                  int threads) {
    if ((overlays.patches || overlays.delta) && (!rig || rig->patches.empty())) {
      return ArgError("--overlay", std::string(overlays.delta ? "delta" : "patches") +
                                       " needs a rig file with patches as the input");
    }
    RenderOverlayColors out;
    out.delta_on_ = overlays.delta;
    if (overlays.patches) {
      base::Result<std::vector<deform::PatchSetup>> patches = BuildRigPatches(*rig, ch);
      if (!patches.ok()) return patches.error();
      out.tint_ = PatchTint(*patches, ch.mesh.bind.num_vertices(), ch.mesh.bind.colors);
    }
    for (int side = 0; side < 2 && overlays.delta; ++side) {
      const deform::FramePipeline* body = side == 0      ? &*bodies.left
                                          : bodies.right ? &*bodies.right
                                                         : nullptr;
      if (body == nullptr || body->num_patches() == 0) continue;
      base::Result<deform::FramePipeline> base =
          deform::FramePipeline::Create(ch, body->method(), threads);
      if (!base.ok()) return base.error();
      out.delta_[side].base.emplace(std::move(*base));
    }
    return out;
  }

  // With the delta overlay, evaluates the global-only bodies at `time_s` and
  // colours the layered ones (`right` unused without one) on a scale shared
  // by both: 1, 2 or 5 x 10^k above the frame's largest displacement (the
  // frame alone decides it). Returns the colour bar's scale, 0 without it.
  base::Result<float> Paint(double time_s, const deform::DeformedFrame& left,
                            const deform::DeformedFrame& right) {
    if (!delta_on_) return 0.0f;
    float scale = 0.0f;
    for (int b = 0; b < 2; ++b) {
      if (!delta_[b].base) continue;
      const base::Status s = delta_[b].base->Evaluate(time_s, delta_[b].base_frame);
      if (!s.ok()) return s.error();
      const deform::DeformedFrame& layered = b == 0 ? left : right;
      for (std::size_t v = 0; v < layered.positions.size(); ++v) {
        scale =
            std::max(scale, glm::length(layered.positions[v] - delta_[b].base_frame.positions[v]));
      }
    }
    scale = NiceScale(scale);
    for (int b = 0; b < 2; ++b) {
      if (!delta_[b].base) continue;
      DisplacementColors(delta_[b].base_frame.positions, (b == 0 ? left : right).positions, scale,
                         delta_[b].colors);
    }
    return scale;
  }

  // The albedo of body `side` (0 left or only, 1 right): #V, or empty for the mesh's own.
  std::span<const glm::vec3> colors(int side) const {
    return delta_[side].base ? std::span<const glm::vec3>(delta_[side].colors)
                             : std::span<const glm::vec3>(tint_);
  }

 private:
  struct DeltaBody {
    std::optional<deform::FramePipeline> base;  // the same method without the layer
    deform::DeformedFrame base_frame;
    std::vector<glm::vec3> colors;
  };
  bool delta_on_ = false;
  std::vector<glm::vec3> tint_;  // empty without the patches overlay
  DeltaBody delta_[2];
};

// The camera of every output frame, framed on the --framing range when given
// (so the chunks of one render frame the body alike).
base::Result<render::CameraPlan> PlanRenderCameras(const RenderOptions& o, const Rig* rig,
                                                   const Character& ch, const FramePlan& plan,
                                                   glm::ivec2 size, bool side_by_side) {
  base::Result<FramePlan> framing = plan;
  if (!o.framing.empty() && o.camera != "turntable") {
    framing = PlanFrames(ch.motion, {.frames = o.framing, .fps = o.fps,
                                     .start_number = o.start_number, .list_frames = false});
    if (!framing.ok()) return ArgError("--framing", framing.error().message);
    if (plan.range.first < framing->range.first || plan.range.last > framing->range.last) {
      return ArgError("--framing", "expected a range holding every output frame (" +
                                       std::to_string(plan.range.first) + ".." +
                                       std::to_string(plan.range.last) + "), found '" + o.framing +
                                       "'");
    }
  }
  CameraSpec camera_spec;
  camera_spec.mode = o.camera;
  camera_spec.elevation_deg = o.elevation_deg;
  camera_spec.azimuth_deg = o.azimuth_deg;
  camera_spec.distance = o.distance;
  camera_spec.zoom = o.zoom;
  if (base::Status s = ResolveLookAt(o.look_at, rig, ch, camera_spec); !s.ok()) {
    base::Error e = s.error();
    if (rig && o.given.count("--look-at") == 0) e.loc = {rig->file, 0, 0, "render.camera.look_at"};
    return e;
  }
  // Side by side, every body is framed in its own half of the frame.
  const glm::ivec2 view_size = side_by_side ? glm::ivec2(size.x / 2, size.y) : size;
  return PlanCameras(ch, *framing, camera_spec, view_size);
}

// Where a render's frames go: their files through the image writer, and the
// contact sheet and the preview video, fed in order on the side queue.
struct RenderOutputs {
  std::string pattern;            // the frame files' (PlanRenderOutputs)
  std::filesystem::path out_dir;  // the sheet's and the video's folder
  std::size_t num_frames = 0;
  render::RenderSettings settings;
  render::Renderer renderer, right_renderer;
  render::AsyncImageWriter writer{{.num_workers = 2, .max_in_flight = 4}};
  render::WriteOptions write_options;
  int sheet_count = 0, next_sheet = 0;  // the sheet's thumbnails, and those added so far
  std::unique_ptr<render::ContactSheetBuilder> sheet;  // null with --no-sheet
  std::unique_ptr<render::VideoWriter> video;          // null with --no-video or when it failed
  std::optional<render::ImageFormat> frame_format;     // the frame files' (none: unknown)
  render::Image image, right_image;  // the frame drawn, and DrawCharacterFrame's scratch
  // The sheet and the H.264 preview take frames in order on their own thread,
  // so encoding the video overlaps rendering the next frame (each task holds
  // its own copy of the frame; at most two are pending). Last, so it stops
  // before the members its tasks use go.
  render::SerialTaskQueue side{{.max_queued = 2}};

  // True when the frame files store 8-bit sRGB exactly (PNG, 8-bit TIFF): a
  // frame is then encoded once, and its bytes feed the file, the sheet and
  // the video, which would otherwise each convert it again.
  bool EncodesOnce() const {
    return frame_format == render::ImageFormat::kPng ||
           (frame_format == render::ImageFormat::kTiff && write_options.tiff_bits == 8);
  }

  // Output frame i (file number `number`) to the sheet and the video, on the
  // side queue: its linear values, or the bytes of its 8-bit file.
  base::Status Feed(std::size_t i, int number, std::shared_ptr<const render::Image> img,
                    bool read_back) {
    if (!sheet && !video) return base::Status::Ok();
    return side.Submit([this, i, number, img = std::move(img), read_back] {
      return FeedSheetAndVideo(i, number, *img, read_back);
    });
  }
  base::Status Feed(std::size_t i, int number, std::shared_ptr<const render::Srgb8Image> bytes) {
    if (!sheet && !video) return base::Status::Ok();
    return side.Submit([this, i, number, bytes = std::move(bytes)] {
      if (IsSheetFrame(i)) {
        // The bytes decoded are what a read back file gives (AsStored).
        if (base::Status st = sheet->Add(render::DecodeSrgb8(*bytes), number); !st.ok()) return st;
        ++next_sheet;
      }
      return video ? video->AddFrame(*bytes) : base::Status::Ok();
    });
  }

  // A frame --resume skips: its finished file on disk feeds the sheet and the video.
  base::Status FeedFinishedFrame(std::size_t i, int number) {
    if (!sheet && !video) return base::Status::Ok();
    const base::Result<std::string> done_path = render::ExpandFramePattern(pattern, number);
    if (!done_path.ok()) return done_path.error();
    base::Result<render::Image> done = render::ReadImage(*done_path);
    if (!done.ok()) return done.error();
    return Feed(i, number, std::make_shared<const render::Image>(std::move(*done)),
                /*read_back=*/true);
  }

 private:
  // The sheet gets every frame as its file will read back (render/output/stored_image.h),
  // so a --resume that rebuilds it from finished frames on disk gives the same
  // bytes; formats whose round trip is not modelled (JPEG) use the frame as is.
  bool IsSheetFrame(std::size_t i) const {
    return sheet && next_sheet < sheet_count &&
           static_cast<std::int64_t>(i) ==
               render::ContactSheetPick(next_sheet, sheet_count,
                                        static_cast<std::int64_t>(num_frames));
  }

  base::Status FeedSheetAndVideo(std::size_t i, int number, const render::Image& img,
                                 bool read_back) {
    if (IsSheetFrame(i)) {
      const render::Image* thumb_source = &img;
      base::Result<render::Image> stored = render::Image();
      if (!read_back && frame_format) {
        stored = render::AsStored(img, *frame_format, write_options);
        if (stored.ok()) thumb_source = &*stored;
      }
      if (base::Status st = sheet->Add(*thumb_source, number); !st.ok()) return st;
      ++next_sheet;
    }
    if (video) return video->AddFrame(img);
    return base::Status::Ok();
  }
};

// Opens `out` for the frames of `pattern` before anything renders: their
// folder (created, and refused when it cannot be written), the sheet and the video.
base::Status OpenRenderOutputs(const RenderOptions& o, const Rig* rig, glm::ivec2 size,
                               const FramePlan& plan, const std::string& pattern, float ground_y,
                               RenderOutputs& out) {
  out.pattern = pattern;
  {
    const base::Result<std::string> first = render::ExpandFramePattern(pattern, plan.At(0).number);
    if (!first.ok()) return first.error();
    const base::Status writable = PrepareOutputFolder(std::filesystem::path(*first).parent_path());
    if (!writable.ok()) return writable;
  }
  out.out_dir = std::filesystem::path(*render::ExpandFramePattern(pattern, 0)).parent_path();
  out.num_frames = plan.count();
  out.settings = MakeRenderSettings(o, size, pattern);
  out.settings.ground_y = ground_y;
  out.write_options.png_compression = o.png_compression;
  out.write_options.source_file = o.input.empty() ? "demo_walk.bvh (built in)"
                                  : rig           ? rig->file
                                                  : o.input;
  out.sheet_count = std::min<int>(kMaxSheetFrames, static_cast<int>(out.num_frames));
  if (!o.no_sheet) {
    auto b = render::ContactSheetBuilder::Create(
        out.sheet_count, size.x, size.y, {.columns = render::ContactSheetColumns(out.sheet_count)});
    if (!b.ok()) return b.error();
    out.sheet = std::move(*b);
  }
  if (!o.no_video) {
    const double video_fps =
        o.camera == "turntable" ? 24.0 : 1.0 / (plan.frame_time_s * plan.range.step);
    auto v = render::VideoWriter::Open((out.out_dir / "preview.mp4").string(), size.x & ~1,
                                       size.y & ~1, {.fps = video_fps});
    // The video is a preview: a render never fails over it (a warning, no video).
    if (v.ok()) {
      out.video = std::move(*v);
    } else {
      const base::Warning w{v.error().loc, v.error().message + "; no preview video"};
      std::fprintf(stderr, "%s\n", w.ToString().c_str());
    }
  }
  const base::Result<render::ImageFormat> frame_format = render::ImageFormatFromPath(pattern);
  if (frame_format.ok()) out.frame_format = *frame_format;
  return base::Status::Ok();
}

// What every frame of a render reads, set up before the first one.
struct RenderScene {
  const RenderOptions& o;
  const Rig* rig;  // null without a rig file
  const Character& ch;
  const FramePlan& plan;
  const TwoBodies& two;
  const Overlays& overlays;
  RenderBodies& bodies;
  RenderOverlayColors& colors;
  const render::CameraPlan& cameras;
  deform::DeformedFrame frame{}, right_frame{};  // the bodies at the current frame
};

// How far the frame loop got, for the progress bar, --stats and an interruption's message.
struct RenderTally {
  Progress progress;
  std::chrono::steady_clock::time_point started;  // when the command started
  int frames_done = 0;                            // --resume's skipped frames count as done
  int last_done_number = -1;                      // the file number of the last frame rendered
  double first_frame_s = -1.0;  // --stats: when the first frame went to the writer
};

// How output frame `of` is drawn: the overlays, its label and the bodies' colours.
FrameDrawOptions RenderFrameDraw(const RenderScene& scene, const OutputFrame& of,
                                 float color_bar_scale) {
  const bool turntable = scene.o.camera == "turntable";
  // A turntable's frames all show one motion frame: the label names it and the view.
  const int label_number = turntable ? scene.o.start_number + scene.plan.range.first : of.number;
  std::string frame_text = FrameLabel(scene.o.label, label_number, scene.plan.frame_time_s);
  if (turntable && !frame_text.empty()) frame_text += "  view " + std::to_string(of.camera);
  const bool two = scene.bodies.right.has_value();
  return {.skeleton = scene.overlays.skeleton,
          .wireframe = scene.overlays.wire,
          .frame_number = label_number,
          .frame_text = frame_text,
          .left_label = two ? scene.two.sides[0].Label() : "",
          .right_label = two ? scene.two.sides[1].Label() : "",
          .side_by_side = scene.two.view == View::kCompare,
          .left_colors = scene.colors.colors(0),
          .right_colors = scene.colors.colors(1),
          .color_bar_scale = color_bar_scale,
          .textures = scene.o.textures == "on"};
}

// Output frame i: the bodies evaluated, then drawn and handed to the writer
// and the side queue, or, when --resume skips it, its file fed to the side queue.
base::Status RenderOutputFrame(std::size_t i, RenderScene& scene, const OutputGuard& guard,
                               RenderOutputs& out, RenderTally& tally) {
  const OutputFrame of = scene.plan.At(i);
  // Skipped frames are still evaluated: a pipeline that carries state from
  // frame to frame (the elastic layer) must see every frame to give a
  // resumed range the same result.
  base::Status s = scene.bodies.left->Evaluate(of.time_s, scene.frame);
  if (!s.ok()) return s;
  if (scene.bodies.right) {
    s = scene.bodies.right->Evaluate(of.time_s, scene.right_frame);
    if (!s.ok()) return s;
  }
  if (guard.skip(i)) return out.FeedFinishedFrame(i, of.number);
  const render::Camera camera = scene.cameras.At(of.camera);
  const base::Result<float> bar_scale =
      scene.colors.Paint(of.time_s, scene.frame, scene.right_frame);
  if (!bar_scale.ok()) return bar_scale.error();
  s = DrawCharacterFrame(scene.ch, scene.frame, scene.bodies.right ? &scene.right_frame : nullptr,
                         camera, out.settings, RenderFrameDraw(scene, of, *bar_scale), out.renderer,
                         out.right_renderer, out.right_image, out.image);
  if (!s.ok()) return s;
  const base::Result<std::string> path = render::ExpandFramePattern(out.pattern, of.number);
  if (!path.ok()) return path.error();
  out.write_options.frame = of.number;
  if (out.EncodesOnce()) {
    // One sRGB encoding feeds all three outputs; the next frame renders into
    // the same linear buffers.
    auto bytes = std::make_shared<render::Srgb8Image>();
    render::EncodeSrgb8(out.image, bytes.get());
    s = out.Feed(i, of.number, bytes);
    if (s.ok()) s = out.writer.Submit(std::move(bytes), *path, out.write_options);
  } else {
    s = out.Feed(i, of.number, std::make_shared<const render::Image>(out.image),
                 /*read_back=*/false);
    // The frame moves to the writer; the next one renders into the buffers
    // of one already written (when there is one), so no frame-sized buffer is
    // copied, allocated or first touched per frame.
    if (s.ok()) s = out.writer.Submit(std::move(out.image), *path, out.write_options);
    if (s.ok()) out.image = out.writer.TakeSpareImage();
  }
  if (!s.ok()) return s;
  ++tally.frames_done;
  if (tally.first_frame_s < 0.0) {
    tally.first_frame_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - tally.started).count();
  }
  tally.last_done_number = of.number;
  tally.progress.Step(of.number);
  return base::Status::Ok();
}

// Every output frame in order, until SIGINT or SIGTERM arrives (app/output_guard.h).
base::Status RenderFrames(RenderScene& scene, const OutputGuard& guard, RenderOutputs& out,
                          RenderTally& tally) {
  for (std::size_t i = 0; i < out.num_frames; ++i) {
    if (guard.interrupted()) break;
    if (base::Status s = RenderOutputFrame(i, scene, guard, out, tally); !s.ok()) return s;
  }
  return base::Status::Ok();
}

// The elastic layer says when it had to limit anything (ALGORITHMS.md 6).
void WarnRenderElasticLimits(const RenderBodies& bodies, const Rig* rig,
                             const std::string& source_file) {
  for (const deform::FramePipeline* p : {&*bodies.left, bodies.right ? &*bodies.right : nullptr}) {
    if (p == nullptr) continue;
    for (const deform::ElasticPatchReport& r : p->elastic_report()) {
      if (r.counters.any_limit() == 0) continue;
      std::fprintf(stderr,
                   "%s: warning: elastic patch \"%s\" was limited: %lld acceleration clamps, "
                   "%lld displacement clamps, %lld non-finite inputs, %lld non-finite resets\n",
                   source_file.c_str(),
                   rig ? rig->patches[static_cast<std::size_t>(r.patch)].name.c_str() : "?",
                   static_cast<long long>(r.counters.acceleration_clamps),
                   static_cast<long long>(r.counters.displacement_clamps),
                   static_cast<long long>(r.counters.non_finite_inputs),
                   static_cast<long long>(r.counters.non_finite_resets));
    }
  }
}

// After the frame loop: the exit code, once every frame handed to the writer
// is finished (so none is left half-written) and the sheet and video are written.
int FinishRender(const RenderScene& scene, const OutputGuard& guard, RenderOutputs& out,
                 RenderTally& tally) {
  base::Status s = out.writer.Finish();
  if (!s.ok()) return ReportError(s.error());
  s = out.side.Finish();
  if (!s.ok()) return ReportError(s.error());
  tally.progress.Finish();
  if (guard.interrupted()) {
    // The sheet and the video would be partial: the video writer's destructor
    // removes its temporary file; --resume rebuilds both.
    std::fprintf(stderr, "%s: %s\n", out.pattern.c_str(),
                 guard
                     .StopMessage(tally.last_done_number, tally.frames_done,
                                  static_cast<int>(out.num_frames))
                     .c_str());
    return guard.exit_code();
  }
  WarnRenderElasticLimits(scene.bodies, scene.rig, out.write_options.source_file);
  if (scene.o.print_outputs) {
    std::printf("frames:        %s (%zu)\n", out.pattern.c_str(), out.num_frames);
  }
  if (out.sheet) {
    const std::string sheet_path = (out.out_dir / "contact_sheet.png").string();
    s = render::WriteImage(out.sheet->sheet(), sheet_path, {});
    if (!s.ok()) return ReportError(s.error());
    std::printf("contact sheet: %s\n", sheet_path.c_str());
  }
  if (out.video) {
    s = out.video->Close();
    if (!s.ok()) return ReportError(s.error());
    std::printf("video:         %s (%s)\n", out.video->path().c_str(),
                render::VideoCodecName(out.video->codec()));
  }
  if (scene.o.stats) {
    std::printf("stats:         first frame after %.3f s, peak memory %.1f MB\n",
                tally.first_frame_s, PeakResidentMb());
  }
  return 0;
}

}  // namespace

int RunRender(const RenderOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  RenderOptions o = options;
  const base::Result<std::optional<Rig>> loaded_rig = TakeRenderRig(o);
  if (!loaded_rig.ok()) return ReportError(loaded_rig.error());
  const Rig* rig = *loaded_rig ? &**loaded_rig : nullptr;
  const base::Result<glm::ivec2> size = ParseSize(o.size);
  if (!size.ok()) return ReportError(size.error());
  const base::Result<Overlays> overlays = CheckRenderOptions(o, *size);
  if (!overlays.ok()) return ReportError(overlays.error());
  const base::Result<deform::GlobalMethod> method = ParseGlobalMethod(o.global);
  if (!method.ok()) return ReportError(method.error());
  const base::Result<TwoBodies> two = ChooseTwoBodies(o, rig, *method);
  if (!two.ok()) return ReportError(two.error());
  const base::Result<BodyKind> body_kind = ResolveRenderBody(o, rig);
  if (!body_kind.ok()) return ReportError(body_kind.error());

  // --- Input and the output frames ---------------------------------------------
  const std::string name = o.input.empty() ? "demo"
                           : rig           ? std::filesystem::path(rig->file).stem().string()
                                           : std::filesystem::path(o.input).stem().string();
  const base::Result<std::optional<mocap::UpAxis>> up = ParseUpAxis(o.up);
  if (!up.ok()) return ReportError(up.error());
  const base::Result<Character> character =
      LoadCommandCharacter(o.input, o.motion, o.quiet, *up, o.joint_map, nullptr, *body_kind);
  if (!character.ok()) return ReportError(character.error());
  const Character& ch = *character;
  // The output frames are computed one at a time (plan->At): a render of
  // every frame of an hour-long capture holds no per-frame list (issue 8).
  const base::Result<FramePlan> plan = PlanRenderFrames(options, o, rig, ch);
  if (!plan.ok()) return ReportError(plan.error());
  // Existing outputs are refused (or, with --resume, skipped) before anything renders.
  OutputGuard guard({.overwrite = o.overwrite, .resume = o.resume});
  const bool turntable = o.camera == "turntable";
  const base::Result<std::string> pattern =
      PlanRenderOutputs(o, "out/" + name + (turntable ? "_turntable" : ""), *plan, guard);
  if (!pattern.ok()) return ReportError(pattern.error());

  // --- The bodies (one, or the two of a comparison), their colours, the cameras ---
  base::Result<RenderBodies> bodies = MakeRenderBodies(o, rig, ch, *two, *method);
  if (!bodies.ok()) return ReportError(bodies.error());
  base::Result<RenderOverlayColors> colors =
      RenderOverlayColors::Create(*overlays, rig, ch, *bodies, o.threads);
  if (!colors.ok()) return ReportError(colors.error());
  const base::Result<render::CameraPlan> cameras =
      PlanRenderCameras(o, rig, ch, *plan, *size, two->view == View::kCompare);
  if (!cameras.ok()) return ReportError(cameras.error());

  // --- Outputs, the frame loop and the finish -----------------------------------
  RenderOutputs outputs;
  base::Status s = OpenRenderOutputs(o, rig, *size, *plan, *pattern, cameras->ground_y(), outputs);
  if (!s.ok()) return ReportError(s.error());
  RenderScene scene{.o = o,
                    .rig = rig,
                    .ch = ch,
                    .plan = *plan,
                    .two = *two,
                    .overlays = *overlays,
                    .bodies = *bodies,
                    .colors = *colors,
                    .cameras = *cameras};
  RenderTally tally{
      .progress = Progress("render " + name, static_cast<int>(outputs.num_frames), o.quiet),
      .started = started,
      .frames_done = guard.num_skipped()};
  s = RenderFrames(scene, guard, outputs, tally);
  if (!s.ok()) return ReportError(s.error());
  return FinishRender(scene, guard, outputs, tally);
}

}  // namespace app
