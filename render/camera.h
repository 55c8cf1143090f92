#pragma once
// Perspective camera, framing, a smoothed follow camera and turntable paths.
//
// Conventions (GLM, right-handed, OpenGL clip space): the camera looks down its
// view-space -Z axis with +Y up; clip = ClipFromView() * view, NDC x,y,z in
// [-1,1]; clip.w equals the view-space depth (distance along the view axis), so
// the rasterizer clips at w = near_plane. World units are whatever the scene uses.

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "deform/mesh.h"

namespace render {

struct Camera {
  glm::vec3 eye{0.0f, 0.0f, 5.0f};   // world-space position of the centre of projection
  glm::vec3 target{0.0f};            // world-space point the camera looks at (not == eye)
  glm::vec3 up{0.0f, 1.0f, 0.0f};    // world-space up hint (not parallel to target - eye)
  float fov_y_deg = 40.0f;           // full vertical field of view, degrees, in (0, 180)
  float near_plane = 0.05f;          // view-space distance of the near clip plane, > 0
  float far_plane = 1000.0f;         // view-space distance of the far plane, > near_plane
  float aspect = 16.0f / 9.0f;       // width / height of the image

  // World to view (look-at) matrix.
  glm::mat4 ViewFromWorld() const;
  // View to clip (OpenGL perspective, depth range [-1,1]).
  glm::mat4 ClipFromView() const;
  // ClipFromView() * ViewFromWorld().
  glm::mat4 ClipFromWorld() const;
  // Unit view direction (target - eye), world space.
  glm::vec3 Forward() const;
};

// Places a camera looking along `view_direction` (world space, from the eye
// towards the box; need not be unit) so the whole box fits in both the
// vertical and the horizontal field of view with `margin` (>= 1) of slack.
// The bounding sphere of the box is framed, so the box stays inside the view
// for any direction. near/far are set to bracket the sphere.
Camera FrameBounds(const deform::Bounds& bounds, float fov_y_deg, float aspect,
                   glm::vec3 view_direction, float margin = 1.1f);

// Critically damped smoothing of a per-frame target (e.g. a character's
// bounds centre). The camera at frame N depends only on centres
// [N - window_frames, N]: the filter restarts at rest on the first centre of
// that window and is stepped to N, so rendering frame N alone gives the same
// camera as rendering 0..N in order (chunked renders agree bit for bit).
struct FollowCamera {
  glm::vec3 offset{0.0f, 1.0f, 6.0f};  // eye - target, world space
  float fov_y_deg = 40.0f;             // as Camera
  float near_plane = 0.05f;            // as Camera
  float far_plane = 1000.0f;           // as Camera
  float aspect = 16.0f / 9.0f;         // as Camera
  float smoothing_time_s = 0.3f;       // time constant of the damped spring, > 0
  float frame_time_s = 1.0f / 30.0f;   // seconds between frames, > 0
  int window_frames = 60;              // how many previous frames the filter sees, >= 0

  // Smoothed target for `frame`; `centres` holds one world-space point per
  // frame (#F). frame is clamped into [0, #F-1]; an empty span gives (0,0,0).
  glm::vec3 SmoothedTarget(std::span<const glm::vec3> centres, int frame) const;
  // The camera for `frame`: target = SmoothedTarget, eye = target + offset.
  Camera At(std::span<const glm::vec3> centres, int frame) const;
};

// `n` cameras orbiting `target` at `distance` (> 0) and `elevation_deg` above
// the horizontal (XZ) plane, Y up. Frame k sits at azimuth 360*k/n degrees,
// starting on +Z and turning counter-clockwise seen from above (towards +X).
// fov/aspect use the Camera defaults; near/far bracket the orbit distance.
std::vector<Camera> TurntablePath(glm::vec3 target, float distance, float elevation_deg, int n);

}  // namespace render
