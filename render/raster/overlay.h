#pragma once
// Overlays drawn over a rendered Image at output resolution: lines (bones,
// control nets, wireframe), points (joints, control points) and text. Lines
// and points can be depth tested against Image::depth (view depth); they are
// anti-aliased by their distance to the pixel centre and blended over the
// image. Drawing is single-threaded and in call order, so it is deterministic.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/image.h"

namespace render {

// Segments given as consecutive endpoint pairs.
struct LineOverlay {
  std::vector<glm::vec3> endpoints;    // 2 * #L world-space points: (a0, b0, a1, b1, ...)
  glm::vec4 color{1.0f, 0.8f, 0.2f, 1.0f};  // linear RGB + opacity
  float width_px = 2.0f;               // full width in output pixels, > 0
  bool depth_test = true;              // hide parts behind the rendered surface
};

struct PointOverlay {
  std::vector<glm::vec3> points;       // #P world-space points
  glm::vec4 color{1.0f, 0.3f, 0.2f, 1.0f};
  float radius_px = 3.5f;              // disc radius in output pixels, > 0
  bool depth_test = true;
};

struct TextOverlay {
  std::string text;                    // ASCII; drawn with OpenCV's Hershey simplex font
  glm::ivec2 origin_px{10, 30};        // bottom-left of the first character, pixels from top-left
  glm::vec4 color{1.0f, 1.0f, 1.0f, 1.0f};
  double scale = 0.8;                  // OpenCV font scale
  int thickness = 1;                   // stroke thickness, pixels
};

struct Overlays {
  std::vector<LineOverlay> lines;      // skeleton bones, control nets, ...
  std::vector<PointOverlay> points;    // joints, control points, ...
  bool wireframe = false;              // draw every scene triangle's edges
  glm::vec4 wireframe_color{0.05f, 0.05f, 0.05f, 0.45f};
  float wireframe_width_px = 1.0f;
  bool wireframe_depth_test = true;
  std::vector<TextOverlay> text;       // frame numbers, labels
};

// Depth-test slack: an overlay fragment at view depth d passes when
// d <= surface_depth * (1 + kOverlayDepthBias), so lines on a surface show.
inline constexpr float kOverlayDepthBias = 3e-3f;

// Bone segments (joint -> parent) for every joint with a parent (#J positions,
// parents[j] < 0 for roots). Appends to `out.endpoints`.
void AppendSkeletonLines(std::span<const glm::vec3> joint_positions,
                         std::span<const std::int16_t> parents, LineOverlay& out);

// The edges of a rows x cols control net stored row-major (#rows*cols
// points): every point joined to its right and lower neighbour.
void AppendControlNetLines(std::span<const glm::vec3> control_points, int rows, int cols,
                           LineOverlay& out);

// Draws `lines` into `image` (depth used when present and requested).
void DrawLines(const glm::mat4& clip_from_world, const LineOverlay& lines, Image& image);
void DrawPoints(const glm::mat4& clip_from_world, const PointOverlay& points, Image& image);
// Wireframe edges shorter than kWireFadeStartPx on screen are not drawn; up
// to kWireFullPx they fade in (a dense mesh seen small stays readable).
inline constexpr float kWireFadeStartPx = 3.0f;
inline constexpr float kWireFullPx = 10.0f;

// Edges of `triangles` over `positions` (#V world), each edge once, faded by
// its length on screen (kWireFadeStartPx, kWireFullPx); cost O(T log T).
void DrawWireframe(const glm::mat4& clip_from_world, std::span<const glm::vec3> positions,
                   std::span<const glm::uvec3> triangles, glm::vec4 color, float width_px,
                   bool depth_test, Image& image);
void DrawText(const TextOverlay& text, Image& image);

}  // namespace render
