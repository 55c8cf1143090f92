#include "render/camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace render {

glm::mat4 Camera::ViewFromWorld() const { return glm::lookAtRH(eye, target, up); }

glm::mat4 Camera::ClipFromView() const {
  return glm::perspectiveRH_NO(glm::radians(fov_y_deg), aspect, near_plane, far_plane);
}

glm::mat4 Camera::ClipFromWorld() const { return ClipFromView() * ViewFromWorld(); }

glm::vec3 Camera::Forward() const { return glm::normalize(target - eye); }

Camera FrameBounds(const deform::Bounds& bounds, float fov_y_deg, float aspect,
                   glm::vec3 view_direction, float margin) {
  Camera camera;
  camera.fov_y_deg = fov_y_deg;
  camera.aspect = aspect;
  const glm::vec3 centre = bounds.empty() ? glm::vec3(0.0f) : bounds.center();
  const float radius =
      bounds.empty() ? 1.0f : std::max(0.5f * glm::length(bounds.size()), 1e-4f);
  // The narrower of the two fields of view decides the distance.
  const float half_fov_y = 0.5f * glm::radians(fov_y_deg);
  const float half_fov_x = std::atan(std::tan(half_fov_y) * aspect);
  const float half_fov = std::min(half_fov_y, half_fov_x);
  const float distance = std::max(margin, 1.0f) * radius / std::sin(half_fov);
  glm::vec3 dir = glm::length(view_direction) > 0.0f ? glm::normalize(view_direction)
                                                      : glm::vec3(0.0f, 0.0f, -1.0f);
  camera.target = centre;
  camera.eye = centre - dir * distance;
  camera.up = std::abs(dir.y) > 0.999f ? glm::vec3(0.0f, 0.0f, -1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
  camera.near_plane = std::max((distance - radius) * 0.5f, distance * 1e-3f);
  camera.far_plane = distance + 4.0f * radius;
  return camera;
}

glm::vec3 FollowCamera::SmoothedTarget(std::span<const glm::vec3> centres, int frame) const {
  if (centres.empty()) return glm::vec3(0.0f);
  const int last = static_cast<int>(centres.size()) - 1;
  frame = std::clamp(frame, 0, last);
  const int first = std::max(0, frame - std::max(window_frames, 0));
  // Critically damped spring x'' = -w^2 (x - goal) - 2 w x', stepped with the
  // exact solution for a goal held constant over each frame.
  const float omega = 2.0f / std::max(smoothing_time_s, 1e-6f);
  const float dt = std::max(frame_time_s, 0.0f);
  const float e = std::exp(-omega * dt);
  glm::vec3 x = centres[static_cast<std::size_t>(first)];
  glm::vec3 v(0.0f);
  for (int f = first + 1; f <= frame; ++f) {
    const glm::vec3 goal = centres[static_cast<std::size_t>(f)];
    const glm::vec3 d = x - goal;
    const glm::vec3 temp = (v + omega * d) * dt;
    v = (v - omega * temp) * e;
    x = goal + (d + temp) * e;
  }
  return x;
}

Camera FollowCamera::At(std::span<const glm::vec3> centres, int frame) const {
  Camera camera;
  camera.target = SmoothedTarget(centres, frame);
  camera.eye = camera.target + offset;
  camera.fov_y_deg = fov_y_deg;
  camera.near_plane = near_plane;
  camera.far_plane = far_plane;
  camera.aspect = aspect;
  return camera;
}

std::vector<Camera> TurntablePath(glm::vec3 target, float distance, float elevation_deg, int n) {
  std::vector<Camera> path;
  if (n <= 0) return path;
  path.reserve(static_cast<std::size_t>(n));
  const float elevation = glm::radians(elevation_deg);
  for (int k = 0; k < n; ++k) {
    const double azimuth = 2.0 * 3.14159265358979323846 * k / n;
    const float s = static_cast<float>(std::sin(azimuth));
    const float c = static_cast<float>(std::cos(azimuth));
    Camera camera;
    camera.target = target;
    camera.eye = target + distance * glm::vec3(std::cos(elevation) * s, std::sin(elevation),
                                                std::cos(elevation) * c);
    camera.near_plane = std::max(distance * 0.01f, 1e-4f);
    camera.far_plane = distance * 10.0f;
    path.push_back(camera);
  }
  return path;
}

}  // namespace render
