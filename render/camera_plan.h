#pragma once
// The camera of every output frame of a motion: "follow" (a smoothed follow
// camera framing the body's largest extent), "fixed" (one camera framing the
// bounds of the whole motion) or "turntable" (an orbit of one moment). The plan
// sees the body only through a BodySampler: its bounds and the point to follow
// at a time, which the caller computes as it likes (from joint positions, or a
// skinned body).
//
// Nothing here depends on which frames are asked for beyond the frame itself, so
// a render split into chunks gets the same cameras and ground as one whole render:
// - framing (extent, fixed bounds, ground height) samples at most
//   kFramingSamples frames spread evenly over the WHOLE motion;
// - the follow camera of frame f reads the look points of frames
//   max(0, f - window) .. f only (FollowCamera), sampled on demand and kept in a
//   sliding window: constant memory, and the first frame needs at most
//   window + 1 samples however long the capture. The smoothed target lags a fast
//   body; it is pulled toward frame f's bounds just far enough that their corners
//   project within kFollowFrameLimit of the image centre (normalised device
//   coordinates). Framing puts a centred body inside that limit, so the pull
//   always succeeds.
// Cost: Create samples the body kFramingSamples times (+1 for a turntable); At
// samples each frame of a follow camera's window once when frames ascend.

#include <functional>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "deform/mesh.h"
#include "render/camera.h"

namespace render {

// Vertical field of view of every planned camera, degrees.
inline constexpr float kFovYDeg = 35.0f;
// Largest camera elevation, degrees either way (at 90 the look-at degenerates).
inline constexpr float kMaxElevationDeg = 89.0f;

enum class CameraMode { kFollow, kFixed, kTurntable };

// What is framed and followed: the whole body, a joint's neighbourhood (a box a
// third of the body's largest extent across), or a region (its largest extent
// over the motion, with as much again around it).
enum class CameraAim { kBody, kJoint, kRegion };

struct CameraSettings {
  CameraMode mode = CameraMode::kFollow;
  float elevation_deg = 15.0f;  // above the horizontal, |e| <= kMaxElevationDeg
  // The eye's direction about +Y from the body's front (+Z), towards +X (its
  // left side at 90). None: front-left, atan(0.45) = 24.2 degrees.
  std::optional<float> azimuth_deg{};
  float distance = 0.0f;  // > 0: eye-to-target distance, model units; 0: framed
  float zoom = 1.0f;      // > 0: that distance divided by it
  CameraAim aim = CameraAim::kBody;
  glm::ivec2 size{1280, 720};  // image, pixels
};

// The body at one time, world space.
struct BodySample {
  deform::Bounds bounds;       // the whole body
  glm::vec3 look_point{0.0f};  // followed: a joint, a region's centroid, or bounds' centre
  deform::Bounds look_bounds;  // the aimed-at region (CameraAim::kRegion), else empty
};
// Fills `out` with the body at time_s (seconds from the motion's start).
using BodySampler = std::function<base::Status(double time_s, BodySample& out)>;

// Which frames exist: output frame f is at f * frame_time_s, 0 <= f < motion_frames.
struct CameraTimes {
  double frame_time_s = 1.0 / 30.0;
  int motion_frames = 1;
  double turntable_time_s = 0.0;  // the moment a turntable orbits
  int turntable_views = 36;
};

class CameraPlan {
 public:
  // Output frames of the whole motion sampled for framing and ground height.
  static constexpr int kFramingSamples = 64;
  // Follow: the body's bounding box stays within this |x|, |y| (NDC, 1 = the
  // frame's edge) whenever the camera's framing allows it.
  static constexpr float kFollowFrameLimit = 0.9f;

  // Settings must be in range (the caller names its options in errors):
  // kInvalidArgument otherwise. The sampler's errors are returned as they are.
  static base::Result<CameraPlan> Create(BodySampler sampler, const CameraSettings& settings,
                                         const CameraTimes& times);

  // The camera of output frame `frame` (follow, fixed) or of turntable view
  // `frame`. Follow: samples the frames of its window not seen yet. Not
  // thread-safe (a cache is updated).
  Camera At(int frame) const;
  // Lowest point of the sampled frames (world Y): where a ground goes.
  float ground_y() const { return ground_y_; }

 private:
  void KeepInFrame(const deform::Bounds& box, Camera& camera) const;

  CameraMode mode_ = CameraMode::kFollow;
  bool whole_body_ = true;
  BodySampler sampler_;
  std::vector<Camera> turntable_;
  Camera fixed_;
  FollowCamera follow_;
  double frame_time_s_ = 1.0 / 30.0;
  mutable std::vector<glm::vec3> centres_;     // follow: look points of frames centre_base_..
  mutable std::vector<deform::Bounds> boxes_;  // follow: their bounds
  mutable int centre_base_ = 0;
  float ground_y_ = 0.0f;
};

}  // namespace render
