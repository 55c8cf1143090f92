#pragma once
// `patchskin render [INPUT]`: renders a capture (BVH, on a generated mannequin)
// or a glTF character's animation to an image sequence, with a contact sheet
// and a preview video. Without INPUT it renders the built-in demo (a walk the
// project generated, samples/data/demo_walk.bvh, compiled into the binary) to
// out/demo/. `patchskin turntable` is `render --camera turntable`.

#include <optional>
#include <set>
#include <string>

namespace app {

struct RenderOptions {
  std::string input;                  // empty = built-in demo
  std::string frames;                 // "A:B[:STEP]", inclusive, in output frames; empty = all
  double fps = 0.0;                   // output frame rate; 0 = the capture's own
  std::string size = "1280x720";      // WxH
  std::string out;                    // pattern with ####; empty = out/<name>/frame_####.png
  std::string global = "ssd";         // ssd | dqs | swd
  std::string camera = "follow";      // follow | fixed | turntable
  int turntable_frames = 36;          // images of a turntable
  float elevation_deg = 15.0f;        // camera elevation, degrees
  std::optional<float> azimuth_deg;   // camera azimuth from the body's front; none = front-left
  float distance = 0.0f;              // eye-to-target distance, model units; 0 = framed
  float zoom = 1.0f;                  // the distance divided by this
  std::string look_at;                // joint name or "patch:NAME"; empty = the whole body
  std::string overlay;                // comma list: skeleton, wire
  std::string label = "frame";        // none | frame | timecode: the text at the bottom left
  std::string background = "gradient";  // gradient | transparent (alpha 0 off the body and ground)
  // Two bodies in one frame, "A,B" ("" = the default pair); each side is a
  // global method, "+patches" for the rig's patch layer (e.g. "ssd,ssd+patches").
  std::optional<std::string> compare;  // side by side, each body in its own half
  std::optional<std::string> wipe;     // one view, left half A, right half B (also --split)
  int threads = 0;                    // 0 = hardware concurrency
  int supersample = 2;                // 1, 2 or 4 samples per axis
  std::string resolve = "box";        // box | tent: how the samples of a pixel are filtered
  std::string aa = "msaa";            // msaa | ssaa: shade once per whole pixel, or every sample
  std::string shadows = "on";         // on | off: the key light's cast shadow (ground and body)
  std::string textures = "on";        // on | off: a glTF character's base colour textures
  int png_compression = 1;            // zlib level for PNG frames
  bool no_sheet = false;
  bool no_video = false;
  bool quiet = false;
  // --stats: after the render, print to stdout when the first frame was handed
  // to the writer (seconds since the command started) and the process's peak
  // resident memory (VmHWM, which, unlike a parent's wait4 ru_maxrss of a
  // spawned child, never includes the parent's memory).
  bool stats = false;
  bool overwrite = false;             // replace existing outputs (else refuse before rendering)
  bool resume = false;                // keep existing frames, render the missing ones
  int start_number = 0;               // file number of motion frame 0 (turntable: of view 0)
  std::string up;                     // --up y|z: a BVH's up axis; empty = detected
  // "A:B[:STEP]": the frames the camera framing and the ground height are
  // computed from; empty = the output frames. Chunks of one render (farm)
  // pass the whole range so every chunk frames the body the same way.
  std::string framing;
  std::string motion;                 // BVH driving a glTF INPUT (retargeted by topology); empty = its own
  std::string joint_map;              // JSON joint map overriding the matched joints; empty = none
  // The body of a BVH INPUT: "generated" (one smooth skin, deform/body/), "tubes" (the
  // mannequin rig files name vertices of; a rig file always uses it), or a glTF/GLB
  // character that the BVH then drives as with --motion.
  std::string body = "generated";
  std::string layer;                  // "auto": the patch layer placed from the skeleton; empty = none
  // Long names ("--size") of the options given on the command line, filled by
  // the parser: with a rig file, these win over the rig's render settings.
  std::set<std::string> given;
  // false: no summary lines on stdout (`check` renders cases and reports itself).
  bool print_outputs = true;
};

// Runs a render. Exit code: 0 ok, 2 bad input (also: outputs exist without
// --overwrite / --resume), 3 internal error, 128 + signal when SIGINT or
// SIGTERM stopped it (the frames written so far are complete; see
// app/output_guard.h).
int RunRender(const RenderOptions& options);

}  // namespace app
