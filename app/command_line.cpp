// The command line: each subcommand's options (CLI11), the parse, and the
// dispatch to the commands' Run functions. No algorithm lives here.

#include "app/command_line.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "app/bench_command.h"
#include "app/check_command.h"
#include "app/compare_command.h"
#include "app/elastic_command.h"
#include "app/export_command.h"
#include "app/farm_command.h"
#include "app/inspect_command.h"
#include "app/render_command.h"
#include "app/rig_command.h"
#include "app/sheet_command.h"

namespace app {
namespace {

constexpr int kUsageError = 2;  // the same code as a bad value or a bad input file

CLI::App* AddInspectCommand(CLI::App& parent, InspectOptions& options) {
  CLI::App* cmd = parent.add_subcommand("inspect", "Print a capture's skeleton, timing and poses");
  cmd->add_option("file", options.file, "BVH, glTF or GLB file")->required();
  cmd->add_option("--frame", options.frame,
                  "Also print world joint positions at this frame (0-based)");
  cmd->add_flag("--json", options.json, "Print one JSON document (schema in docs/command-line.md)");
  cmd->add_flag("--artifacts", options.artifacts,
                "Print collapse (elbow/knee bent 90/120/150 deg) and candy-wrapper (hand "
                "twisted 90/180 deg) figures of SSD, DQS and SWD on the file's body");
  cmd->add_option("--scale", options.scale,
                  "Multiply lengths by this factor (0: convert detected units to metres)");
  cmd->add_flag("--y-up", options.y_up, "Rotate a Z-up capture to Y-up");
  cmd->add_option(
      "--up", options.up,
      "The BVH's up axis, y or z, when detection picks the wrong one (default: detected)");
  cmd->add_flag("--add-position-to-offset", options.add_position_to_offset,
                "BVH position channels add to OFFSET (three.js) instead of replacing it");
  cmd->add_flag(
      "--allow-short", options.allow_short,
      "BVH with fewer frames than 'Frames:' declares: load those present (with a warning)");
  cmd->add_option(
      "--motion", options.motion,
      "Print how this BVH motion's joints drive the glTF FILE's (as render --motion does)");
  cmd->add_option("--joint-map", options.joint_map,
                  "JSON {\"glTF joint\": \"BVH joint\" or null} overriding the matched joints")
      ->needs("--motion");
  return cmd;
}

void AddOutputFlags(CLI::App& cmd, RenderOptions& o) {
  cmd.add_flag("--overwrite", o.overwrite, "Replace existing frames, contact sheet and video");
  cmd.add_flag("--resume", o.resume,
               "Keep the frames that exist (an interrupted render), render the missing ones");
  cmd.add_option(
      "--up", o.up,
      "The BVH's up axis, y or z, when detection picks the wrong one (default: detected)");
  cmd.add_option("--start-number", o.start_number,
                 "File number of motion frame 0 (turntable: of the first view), e.g. 1001")
      ->capture_default_str();
}

// Records which options were given: with a rig file they override its settings.
void RecordGivenOptions(CLI::App* cmd, std::set<std::string>& given) {
  for (const CLI::Option* opt : cmd->get_options()) {
    if (opt->count() > 0) given.insert(opt->get_name());
  }
}

CLI::App* AddRenderCommand(CLI::App& parent, RenderOptions& o) {
  CLI::App* cmd = parent.add_subcommand(
      "render", "Render a capture (BVH on a mannequin) or a glTF animation to image frames");
  cmd->add_option("input", o.input,
                  "BVH, glTF or GLB file, or a rig (.json); none = the built-in demo");
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
  cmd->add_option("--azimuth", o.azimuth_deg,
                  "Camera azimuth in degrees about the vertical from the body's front (90: its "
                  "left side; default front-left, 24)");
  cmd->add_option("--distance", o.distance,
                  "Camera distance to what it frames, model units (0: framed)")
      ->capture_default_str();
  cmd->add_option("--zoom", o.zoom, "Camera distance divided by this")->capture_default_str();
  cmd->add_option(
      "--look-at", o.look_at,
      "Frame and follow a joint's neighbourhood (JOINT) or a patch region (patch:NAME)");
  cmd->add_option("--overlay", o.overlay, "Comma list: skeleton, wire");
  cmd->add_option("--label", o.label, "Text at the bottom left: none, frame or timecode")
      ->capture_default_str();
  cmd->add_option("--background", o.background,
                  "gradient, or transparent: alpha 0 off the body and ground (PNG, EXR, TIFF)")
      ->capture_default_str();
  cmd->add_option("--compare", o.compare,
                  "Two whole bodies side by side, A,B such as ssd,ssd+patches (default for rigs "
                  "with patches: <global>,<global>+patches)")
      ->expected(0, 1)
      ->default_str("");
  cmd->add_option(
         "--wipe,--split", o.wipe,
         "One view, left half A, right half B (A,B as for --compare; default ssd,<global>)")
      ->expected(0, 1)
      ->default_str("");
  cmd->add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
  cmd->add_option("--supersample", o.supersample, "Anti-aliasing samples per axis: 1, 2 or 4")
      ->capture_default_str();
  cmd->add_option(
         "--resolve", o.resolve,
         "Supersample filter: box (the pixel's own samples) or tent (radius one pixel, softer)")
      ->capture_default_str();
  cmd->add_option("--aa", o.aa,
                  "How samples are shaded: msaa (once per pixel inside one triangle or the "
                  "ground; edge pixels per sample) or ssaa (every sample)")
      ->capture_default_str();
  cmd->add_option(
         "--shadows", o.shadows,
         "The key light's cast shadow on the ground and the body: on or off (only the soft "
         "contact blob under the body)")
      ->capture_default_str();
  cmd->add_option("--textures", o.textures,
                  "A glTF character's base colour textures: on or off (its colours alone)")
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
  cmd->add_option(
      "--motion", o.motion,
      "BVH motion driving a glTF INPUT (joints matched by body topology; docs/retargeting.md)");
  cmd->add_option(
      "--joint-map", o.joint_map,
      "JSON {\"glTF joint\": \"BVH joint\" or null} overriding the matched joints (with --motion)");
  cmd->add_option("--body", o.body,
                  "Body of a BVH INPUT: generated, tubes, or a glTF/GLB character it drives")
      ->capture_default_str();
  cmd->add_option("--layer", o.layer,
                  "auto: place the paper's patches (elbows, knees, shoulders, hips, elastic belly "
                  "and jowl) from the skeleton, as `patchskin rig auto` writes them");
  AddOutputFlags(*cmd, o);
  cmd->callback([&o, cmd] { RecordGivenOptions(cmd, o.given); });
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
  cmd->add_option("--aa", o.aa, "Sample shading: msaa or ssaa");
  cmd->add_option("--shadows", o.shadows, "Cast shadow on the ground and the body: on or off");
  cmd->add_flag("--no-sheet", o.no_sheet, "Do not write the contact sheet");
  cmd->add_flag("--no-video", o.no_video, "Do not write the preview video");
  cmd->add_flag("--quiet", o.quiet, "No progress output");
  cmd->add_option("--layer", o.layer, "auto: the patch layer placed from the skeleton (as render)");
  AddOutputFlags(*cmd, o);
  // A turntable of a rig keeps the rig's settings except those given here,
  // and is a turntable whatever camera the rig asks for.
  cmd->callback([&o, cmd] {
    RecordGivenOptions(cmd, o.given);
    o.camera = "turntable";
    o.given.insert("--camera");
  });
  return cmd;
}

CLI::App* AddExportCommand(CLI::App& parent, ExportOptions& o) {
  CLI::App* cmd = parent.add_subcommand(
      "export", "Write the deformed mesh of every frame as an OBJ sequence or one glTF (.glb)");
  cmd->add_option("input", o.input,
                  "BVH, glTF or GLB file, or a rig (.json); none = the built-in demo");
  cmd->add_option("--frames", o.frames, "A:B[:STEP] output frames, inclusive (default all)");
  cmd->add_option("--fps", o.fps, "Output frame rate; the motion is resampled (default: its own)");
  cmd->add_option("--out", o.out,
                  "mesh_####.obj (one OBJ per frame, #### = frame number) or FILE.glb "
                  "(default out/<name>_export/mesh_####.obj)");
  cmd->add_option("--global", o.global, "Global skinning: ssd, dqs or swd")->capture_default_str();
  cmd->add_option("--body", o.body, "Body of a BVH INPUT: generated or tubes (as render)")
      ->capture_default_str();
  cmd->add_option("--layout", o.layout, ".glb: auto (smaller), morph or baked")
      ->capture_default_str();
  cmd->add_flag("--step", o.step, ".glb: hold each frame (STEP) instead of blending (LINEAR)");
  cmd->add_flag("--with-camera", o.with_camera,
                "Also write camera_####.json per frame: the camera render would use (a .glb also "
                "carries it as an animated camera node)");
  cmd->add_option("--camera", o.camera, "Camera for --with-camera: follow or fixed")
      ->capture_default_str();
  cmd->add_option("--size", o.size, "Image size for --with-camera, WxH")->capture_default_str();
  cmd->add_option("--elevation", o.elevation_deg, "Camera elevation in degrees")
      ->capture_default_str();
  cmd->add_option(
      "--motion", o.motion,
      "BVH motion driving a glTF INPUT (joints matched by body topology), as for render");
  cmd->add_option(
      "--joint-map", o.joint_map,
      "JSON {\"glTF joint\": \"BVH joint\" or null} overriding the matched joints (with --motion)");
  cmd->add_option("--scale", o.scale,
                  "Multiply positions (and the camera JSON's lengths) by this, e.g. 0.01 for a "
                  "capture in centimetres to metres; 0: the detected units to metres, as inspect")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
  cmd->add_option(
      "--up", o.up,
      "The BVH's up axis, y or z, when detection picks the wrong one (default: detected)");
  cmd->add_option("--start-number", o.start_number,
                  "File number of motion frame 0 (OBJ meshes, camera JSON), e.g. 1001")
      ->capture_default_str();
  cmd->add_flag("--quiet", o.quiet, "No progress output");
  cmd->add_flag("--resume", o.resume,
                "OBJ sequence: keep the frame files already written (each is whole) and write "
                "the missing ones; every frame is still evaluated in order");
  cmd->add_option("--layer", o.layer,
                  "auto: the patch layer placed from the skeleton (as render --layer auto)");
  cmd->callback([&o, cmd] { RecordGivenOptions(cmd, o.given); });
  return cmd;
}

CLI::App* AddCompareCommand(CLI::App& parent, CompareCommandOptions* o) {
  CLI::App* cmd = parent.add_subcommand(
      "compare",
      "Compare two images as OpenImageIO's idiff: exit 0 pass, 1 warning, 2 failure, 4 error");
  cmd->add_option("A", o->image_a, "first image")->required();
  cmd->add_option("B", o->image_b, "second image (the reference)")->required();
  const auto threshold = [cmd](const char* name, float& value, const char* what) {
    cmd->add_option(name, value, what)->capture_default_str()->check(CLI::NonNegativeNumber);
  };
  threshold("--fail", o->fail, "per-value difference that makes a pixel fail (also -fail)");
  threshold("--failpercent", o->fail_percent,
            "percent of pixels allowed to fail (also -failpercent)");
  threshold("--hardfail", o->hard_fail,
            "fail if any value differs more than this (also -hardfail)");
  threshold("--warn", o->warn, "per-value difference that makes a pixel warn (also -warn)");
  threshold("--warnpercent", o->warn_percent,
            "percent of pixels allowed to warn (also -warnpercent)");
  threshold("--hardwarn", o->hard_warn,
            "warn if any value differs more than this (also -hardwarn)");
  cmd->add_option("--allowfailures", o->allow_failures,
                  "this many pixels may fail by any amount (also -allowfailures)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--diff", o->diff_path, "write the amplified difference image here");
  cmd->add_option("--scale", o->diff_scale, "amplification of the difference image")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  return cmd;
}

CLI::App* AddCheckCommand(CLI::App& parent, CheckOptions* o) {
  CLI::App* cmd = parent.add_subcommand(
      "check",
      "Render a manifest's cases and compare them with reference frames: exit 0 pass, 1 warnings, "
      "2 failure, 4 error");
  cmd->add_option("manifest", o->manifest,
                  "JSON manifest of cases (see docs/command-line.md#check)")
      ->required();
  cmd->add_option("--out", o->out, "Folder of the new frames (default out/check/<manifest name>)");
  cmd->add_option("--references", o->references,
                  "Folder of the reference frames (default: the manifest's, next to it)");
  cmd->add_option("--html", o->html, "HTML report (default <out>/report.html)");
  cmd->add_option("--junit", o->junit, "Also write a JUnit XML file for CI");
  CLI::Option* update = cmd->add_flag(
      "--update", o->update, "Write the new frames of the cases that did not pass as references");
  cmd->add_flag("--update-all", o->update_all, "Write the new frames of every case as references")
      ->excludes(update);
  cmd->add_option("--threads", o->threads, "Worker threads of each render (0 = all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 256));
  return cmd;
}

CLI::App* AddElasticCommand(CLI::App& parent, ElasticOptions& o) {
  CLI::App* cmd = parent.add_subcommand(
      "elastic", "Simulate an elastic patch driven by a joint and plot its response (PNG)");
  cmd->add_option("file", o.file, "BVH or glTF motion (default: the built-in synthetic jump)");
  cmd->add_option("--joint", o.joint, "Driving joint")->capture_default_str();
  cmd->add_option("--out", o.out, "Output PNG")->capture_default_str();
  cmd->add_option("--grid", o.grid, "Control points per side (3..16)")->capture_default_str();
  cmd->add_option("--spacing-m", o.spacing_m, "Control-point spacing, metres")
      ->capture_default_str();
  cmd->add_option("--frequency", o.frequency_hz, "Slowest-mode frequency f0, Hz")
      ->capture_default_str();
  cmd->add_option("--damping", o.damping_ratio, "Damping ratio z0")->capture_default_str();
  cmd->add_option("--gain", o.gain, "Inertial gain")->capture_default_str();
  cmd->add_option("--preroll", o.preroll_s, "Seconds simulated before the first frame")
      ->capture_default_str();
  cmd->add_option("--cutoff-hz", o.cutoff_hz, "Low-pass of the joint paths (0 = off)")
      ->capture_default_str();
  cmd->add_option("--scale", o.scale, "File length factor (0 = detected units to metres)")
      ->capture_default_str();
  cmd->add_option("--units-per-metre", o.units_per_metre,
                  "Model units per metre (0 = 1 for files, 100 for the built-in jump)");
  return cmd;
}

CLI::App* AddSheetCommand(CLI::App& parent, SheetOptions& o) {
  CLI::App* cmd = parent.add_subcommand(
      "sheet", "Build the contact sheet and preview video from frames already rendered");
  cmd->add_option("pattern", o.pattern, "Frame pattern, as given to render --out (#### = number)")
      ->required();
  cmd->add_option("--frames", o.frames, "A:B[:STEP] the rendered frames, inclusive")->required();
  cmd->add_option("--fps", o.fps, "The render's output frame rate")->capture_default_str();
  cmd->add_flag("--no-sheet", o.no_sheet, "Do not write the contact sheet");
  cmd->add_flag("--no-video", o.no_video, "Do not write the preview video");
  cmd->add_flag("--overwrite", o.overwrite, "Replace an existing contact sheet and video");
  cmd->add_flag("--quiet", o.quiet, "Print nothing on success");
  return cmd;
}

CLI::App* AddFarmCommand(CLI::App& parent, FarmOptions& o) {
  CLI::App* farm = parent.add_subcommand("farm", "Render on a cluster scheduler (Slurm)");
  farm->require_subcommand(1, 1);
  CLI::App* cmd = farm->add_subcommand(
      "slurm", "Write (and with --submit, submit) a Slurm job array rendering chunks of frames");
  cmd->add_option("input", o.input, "BVH, glTF or GLB file, or a rig (.json)")->required();
  cmd->add_option("render_args", o.render_args,
                  "After --: render options passed to every chunk (e.g. -- --camera fixed)");
  cmd->add_option("--chunk", o.chunk, "Output frames per array task")->required();
  cmd->add_option("--frames", o.frames, "A:B[:STEP] output frames, inclusive (default: all)");
  cmd->add_option("--fps", o.fps, "Output frame rate (default: the motion's)");
  cmd->add_option("--out", o.out,
                  "Frame pattern, as for render (default out/<name>/frame_####.png)");
  cmd->add_option("--motion", o.motion, "BVH motion driving a glTF INPUT, as for render");
  cmd->add_option("--partition", o.partition, "Slurm partition (default: the cluster's)");
  cmd->add_option(
         "--sbatch-arg", o.sbatch_args,
         "An extra sbatch option for both jobs, e.g. --sbatch-arg=--time=01:00:00 (repeatable)")
      ->allow_extra_args(false);  // one value per use, so "--" still starts the render options
  cmd->add_option("--script-dir", o.script_dir,
                  "Where the scripts go (default: <frames folder>/slurm)");
  cmd->add_option("--job-name", o.job_name, "Slurm job name (default: patchskin-<input name>)");
  cmd->add_flag("--submit", o.submit,
                "Submit with sbatch (default: print the scripts and the command)");
  cmd->add_flag("--wait", o.wait,
                "With --submit: return when the last job has ended (sbatch --wait)");
  return farm;
}

CLI::App* AddRigCommand(CLI::App& parent, RigCommandOptions& o) {
  CLI::App* rig = parent.add_subcommand("rig", "Make rig files");
  rig->require_subcommand(1, 1);
  CLI::App* cmd = rig->add_subcommand(
      "auto", "The rig of --layer auto for a capture, as an editable rig file (stdout or --out)");
  cmd->add_option("capture", o.capture, "BVH capture")->required();
  cmd->add_option("--body", o.body, "generated, tubes, or a glTF/GLB character the capture drives")
      ->capture_default_str();
  cmd->add_option("--up", o.up, "The BVH's up axis, y or z (default: detected)");
  cmd->add_option("--out", o.out, "Rig file to write (default: stdout)");
  cmd->add_flag("--quiet", o.quiet, "No notes on stderr");
  return cmd;
}

CLI::App* AddBenchCommand(CLI::App& parent, BenchOptions& o) {
  CLI::App* cmd = parent.add_subcommand(
      "bench", "Measure the paper's Table 1 and every speed figure (run in a Release build)");
  cmd->add_flag("--quick", o.quick, "A few short runs (seconds); figures are rough");
  cmd->add_option("--json", o.json, "Also write the figures as JSON to this file");
  cmd->add_option("--threads", o.threads, "Workers of the end-to-end row (0 = all cores)")
      ->capture_default_str();
  cmd->add_option("--data", o.data_dir, "Shared data folder (for bvh/cmu_cgspeed/01_01.bvh)");
  cmd->add_flag("--allow-debug", o.allow_debug, "Run even in a non-Release build");
  return cmd;
}

}  // namespace

int RunCommandLine(int argc, char** argv) {
  CLI::App root{"patchskin: motion-capture driven layered skinning and software rendering"};
  root.set_version_flag("--version", std::string("patchskin 0.1.0"));
  root.require_subcommand(0, 1);

  InspectOptions inspect_options;
  CLI::App* inspect = AddInspectCommand(root, inspect_options);
  RenderOptions render_options;
  CLI::App* render = AddRenderCommand(root, render_options);
  RenderOptions turntable_options;
  turntable_options.camera = "turntable";
  CLI::App* turntable = AddTurntableCommand(root, turntable_options);
  ExportOptions export_options;
  CLI::App* export_cmd = AddExportCommand(root, export_options);
  CompareCommandOptions compare_options;
  CLI::App* compare = AddCompareCommand(root, &compare_options);
  CheckOptions check_options;
  CLI::App* check = AddCheckCommand(root, &check_options);
  ElasticOptions elastic_options;
  CLI::App* elastic = AddElasticCommand(root, elastic_options);
  SheetOptions sheet_options;
  CLI::App* sheet = AddSheetCommand(root, sheet_options);
  FarmOptions farm_options;
  CLI::App* farm = AddFarmCommand(root, farm_options);
  RigCommandOptions rig_options;
  CLI::App* rig_auto = AddRigCommand(root, rig_options);
  BenchOptions bench_options;
  CLI::App* bench = AddBenchCommand(root, bench_options);

  // idiff's single-dash spellings (-fail ...) become CLI11's (--fail).
  std::vector<std::string> args(argv, argv + argc);
  NormalizeIdiffSpelling(args);
  std::vector<char*> arg_ptrs;
  for (std::string& a : args) arg_ptrs.push_back(a.data());
  try {
    root.parse(argc, arg_ptrs.data());
  } catch (const CLI::ParseError& e) {
    const int code = root.exit(e);
    if (code == 0) return 0;
    // compare follows idiff: 1 means a warning, so its usage errors are 4.
    if (compare->parsed()) return kCompareError;
    return check->parsed() ? kCheckError : kUsageError;
  }
  try {
    if (inspect->parsed()) return RunInspect(inspect_options);
    if (render->parsed()) return RunRender(render_options);
    if (turntable->parsed()) return RunRender(turntable_options);
    if (compare->parsed()) return RunCompareCommand(compare_options);
    if (check->parsed()) return RunCheck(check_options);
    if (export_cmd->parsed()) return RunExport(export_options);
    if (elastic->parsed()) return RunElastic(elastic_options);
    if (sheet->parsed()) return RunSheet(sheet_options);
    if (farm->parsed()) return RunFarm(farm_options);
    if (bench->parsed()) return RunBench(bench_options);
    if (rig_auto->parsed()) return RunRigAuto(rig_options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "patchskin: internal error: %s\n", e.what());
    return 3;
  }
  std::fputs(root.help().c_str(), stdout);
  return 0;
}

std::optional<std::string> ParseRenderWords(const std::string& input,
                                            const std::vector<std::string>& words,
                                            RenderOptions& out) {
  CLI::App root;
  AddRenderCommand(root, out);
  std::vector<std::string> args{"render", input};
  args.insert(args.end(), words.begin(), words.end());
  std::reverse(args.begin(), args.end());  // CLI11 takes the vector last word first
  try {
    root.parse(args);
  } catch (const CLI::CallForHelp&) {
    return std::string("render option --help is not a render setting");
  } catch (const CLI::ParseError& e) {
    return std::string("render options: ") + e.what();
  }
  return std::nullopt;
}

}  // namespace app
