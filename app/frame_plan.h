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
#include "deform/pipeline/frame_pipeline.h"
#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"
#include "render/camera.h"

namespace app {

// Vertical field of view of every render camera, degrees.
inline constexpr float kFovYDeg = 35.0f;
// Largest camera elevation (--elevation), degrees either way.
inline constexpr float kMaxElevationDeg = 89.0f;

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
  float elevation_deg = 15.0f;       // above the horizontal, |e| <= kMaxElevationDeg
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

// The camera of every output frame, as `render` uses it: "follow" (a smoothed
// follow camera framing the body's largest extent), "fixed" (one camera
// framing the bounds of the whole motion) or "turntable" (an orbit of the
// first frame of the range).
//
// Nothing here depends on the requested frame range beyond the frame being
// asked for, so a render split into chunks (--frames 0:9, 10:19, ...) gets the
// same cameras and ground as one whole render:
// - framing (extent, fixed bounds, ground height) samples at most
//   kFramingSamples output frames spread evenly over the WHOLE motion
//   (deterministic, independent of --frames);
// - the follow camera of frame f reads the bounds centres of frames
//   max(0, f - window) .. f only (render::FollowCamera), evaluated on demand and
//   kept in a sliding window, so memory is constant and the first frame needs
//   at most window + 1 evaluations, however long the capture. The smoothed
//   target lags a fast body (a running dog); it is pulled toward frame f's
//   bounds centre just far enough that the corners of frame f's bounding box
//   project within kFollowFrameLimit of the image centre (normalised device
//   coordinates), so the body stays in the frame with a margin. Framing puts a
//   centred body inside that limit, so the pull always succeeds.
// Bodies are evaluated with a private global-only SSD pipeline of the same
// character (patches and the elastic layer move the surface by a few
// percent of the body; the caller's pipeline and its state are never touched).
class CameraPlan {
 public:
  // Output frames of the whole motion sampled for framing and ground height.
  static constexpr int kFramingSamples = 64;
  // Follow: the body's bounding box stays within this |x|, |y| (NDC, 1 = the
  // frame's edge) whenever the camera's framing allows it.
  static constexpr float kFollowFrameLimit = 0.9f;

  // mode: follow | fixed | turntable; elevation in degrees, |e| <= kMaxElevationDeg
  // (else kInvalidArgument naming --elevation); size in pixels.
  // `pipeline` only supplies the character and thread count; it must outlive
  // nothing here (the character must outlive the CameraPlan).
  // Errors: kInvalidArgument (mode), and the pipeline's errors.
  static base::Result<CameraPlan> Create(deform::FramePipeline& pipeline, const FramePlan& plan,
                                         const std::string& mode, float elevation_deg,
                                         glm::ivec2 size);
  // The same with every camera setting (CameraSpec); kInvalidArgument naming
  // --azimuth, --distance, --zoom or --look-at for values out of range.
  static base::Result<CameraPlan> Create(deform::FramePipeline& pipeline, const FramePlan& plan,
                                         const CameraSpec& spec, glm::ivec2 size);

  // The camera of `frame` (one of the plan's frames). Follow: evaluates the
  // frames of its window not seen yet, so ascending frames cost one body
  // evaluation each. Not thread-safe (a cache is updated).
  render::Camera At(const OutputFrame& frame) const;
  // Lowest point of the sampled frames (world Y): where render draws the ground.
  float ground_y() const { return ground_y_; }

 private:
  // Follow: pulls `camera` (target and eye together) toward the centre of
  // `box` until the box projects within kFollowFrameLimit (see above).
  void KeepInFrame(const deform::Bounds& box, render::Camera& camera) const;

  // The point the camera follows in `f`: the look-at joint, the look-at
  // region's centroid, or the bounds centre.
  glm::vec3 LookPoint(const deform::DeformedFrame& f) const;
  std::string mode_;
  std::vector<render::Camera> turntable_;
  render::Camera fixed_;
  render::FollowCamera follow_;
  double frame_time_s_ = 1.0 / 30.0;           // output frame f is at f * frame_time_s_
  std::unique_ptr<deform::FramePipeline> tracker_;  // global-only SSD body for bounds
  mutable std::vector<glm::vec3> centres_;     // follow: bounds centres of frames centre_base_..
  mutable std::vector<deform::Bounds> boxes_;  // follow: their bounds
  mutable int centre_base_ = 0;
  mutable deform::DeformedFrame scratch_;
  float ground_y_ = 0.0f;
  int look_joint_ = -1;
  std::vector<int> look_region_;
};

}  // namespace app
