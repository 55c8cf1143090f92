#pragma once
// What `render` and `export` share: parsing of --size and --frames, the output
// frames' timing (which motion time each output frame evaluates) and the
// camera each output frame is seen from. Keeping these in one place is what
// makes an exported frame and its camera JSON match the rendered image.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/character.h"
#include "deform/pipeline/character.h"
#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"
#include "render/camera.h"
#include "render/camera_plan.h"

namespace app {

// kInvalidArgument naming the command-line option, e.g. "--frames: error: ...".
base::Error ArgError(const std::string& option, const std::string& message);

// The ranges commands share: --threads 0 (every core) .. 256; --fps 0 (the
// motion's own rate) .. 10000. An error naming the option, else nothing.
std::optional<base::Error> CheckThreads(int threads);
std::optional<base::Error> CheckFps(double fps);

// "WxH" with both sides in 16..16384.
base::Result<glm::ivec2> ParseSize(const std::string& text);

// --up: "y" or "z" (either case) -> that axis; "" -> empty (detect it).
base::Result<std::optional<mocap::UpAxis>> ParseUpAxis(const std::string& text);

// Output frames first..last (inclusive) every step.
struct FrameRange {
  int first = 0;
  int last = 0;   // inclusive
  int step = 1;   // >= 1
};

// "A:B[:STEP]" (A or B may be empty: 0 / the last frame; "A" alone is one
// frame) within 0..num_frames-1; empty text = all frames.
base::Result<FrameRange> ParseFrames(const std::string& text, int num_frames);

// Everything about one output frame that a frame loop needs.
struct OutputFrame {
  int number = 0;      // output frame number (names the file): start_number + frame or view
  double time_s = 0;   // motion time evaluated, seconds from the motion's first frame
  int camera = 0;      // turntable camera index, or the follow-camera frame
};

struct FramePlanOptions {
  std::string frames;         // --frames text, see ParseFrames
  double fps = 0.0;           // output frame rate; 0 = the motion's own (30 when unknown)
  bool turntable = false;     // frames are turntable views of range.first
  int turntable_frames = 36;  // views of a turntable
  // --start-number: the number of motion frame 0 (turntable: of the first
  // view), e.g. 1001 for pipelines that count from there; 0..kMaxStartNumber.
  int start_number = 0;
  // Fill FramePlan::frames. A render of every frame of an hour-long capture
  // has ~430,000 output frames; commands that walk the plan with count() and
  // At() (render) turn this off so the plan's memory stays constant.
  bool list_frames = true;
};

// The output frames of a command.
struct FramePlan {
  double frame_time_s = 1.0 / 30.0;  // seconds between output frame numbers
  int motion_frames = 1;             // output frames the motion spans (numbers 0..N-1)
  FrameRange range;                  // the parsed --frames
  bool turntable = false;            // frames are turntable views of range.first
  int turntable_frames = 0;          // views of the turntable (when turntable)
  int start_number = 0;              // added to every OutputFrame::number
  // In output order; time_s = number * frame_time_s. Empty when the plan was
  // made with list_frames = false; count() and At() work either way.
  std::vector<OutputFrame> frames;

  // Number of output frames (>= 1 for a plan PlanFrames returned).
  std::size_t count() const;
  // Output frame i (< count()), computed from the range: the same as frames[i].
  OutputFrame At(std::size_t i) const;
};

inline constexpr int kMaxStartNumber = 100'000'000;

// Errors: kInvalidArgument from ParseFrames, or --start-number outside 0..kMaxStartNumber.
base::Result<FramePlan> PlanFrames(const mocap::Motion& motion, const FramePlanOptions& options);

// Where the camera looks from and what it frames (render --camera, --azimuth,
// --elevation, --distance, --zoom, --look-at; a rig's render.camera object).
struct CameraSpec {
  std::string mode = "follow";       // follow | fixed | turntable
  float elevation_deg = 15.0f;       // above the horizontal, |e| <= render::kMaxElevationDeg
  // The eye's direction about +Y from the body's front (+Z), towards +X (its
  // left side at 90). None: front-left, atan(0.45) = 24.2 degrees.
  std::optional<float> azimuth_deg;
  float distance = 0.0f;             // > 0: eye-to-target distance, model units; 0: framed
  float zoom = 1.0f;                 // > 0: that distance divided by it
  // What is framed and followed: the whole body (look_joint < 0 and no
  // region), a joint's neighbourhood (a box a third of the body's largest
  // extent across), or a patch region's vertices (the region's largest extent
  // over the motion, with as much again around it).
  int look_joint = -1;
  std::vector<int> look_region;
};

// The cameras of `plan` as `spec` asks (render::CameraPlan), framing the
// character as its joints and skin hull place it (deform::BodyTracker; no body
// is deformed). The character must outlive the plan. Errors: kInvalidArgument
// naming --camera, --elevation, --azimuth, --distance, --zoom, --look-at or
// --frames; the tracker's errors.
base::Result<render::CameraPlan> PlanCameras(const deform::Character& character,
                                             const FramePlan& plan, const CameraSpec& spec,
                                             glm::ivec2 size);
// The same with the default aim, distance and azimuth.
base::Result<render::CameraPlan> PlanCameras(const deform::Character& character,
                                             const FramePlan& plan, const std::string& mode,
                                             float elevation_deg, glm::ivec2 size);

}  // namespace app
