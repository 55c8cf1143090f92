#include "render/raster/overlay.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace render {
namespace {

// A projected point: pixel coordinates (x right, y down) and 1/view depth.
struct ScreenPoint {
  glm::vec2 px;
  float inv_w;
};

ScreenPoint Project(const glm::vec4& clip, const Image& image) {
  const float inv_w = 1.0f / clip.w;
  return {{(clip.x * inv_w + 1.0f) * 0.5f * static_cast<float>(image.width),
           (1.0f - clip.y * inv_w) * 0.5f * static_cast<float>(image.height)},
          inv_w};
}

void Blend(Image& image, int x, int y, const glm::vec4& color, float coverage) {
  const float a = std::clamp(coverage, 0.0f, 1.0f) * color.a;
  if (a <= 0.0f) return;
  glm::vec4& dst = image.at(x, y);
  dst = glm::vec4(glm::vec3(dst) + (glm::vec3(color) - glm::vec3(dst)) * a,
                  dst.a + (1.0f - dst.a) * a);
}

bool PassesDepth(const Image& image, int x, int y, float view_depth) {
  if (image.depth.empty()) return true;
  return view_depth <= image.depth[image.index(x, y)] * (1.0f + kOverlayDepthBias);
}

// Draws one segment already clipped to w > 0.
void DrawSegment(const ScreenPoint& a, const ScreenPoint& b, const glm::vec4& color,
                 float width_px, bool depth_test, Image& image) {
  const float half = 0.5f * width_px;
  const float reach = half + 1.0f;
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min(a.px.x, b.px.x) - reach)));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min(a.px.y, b.px.y) - reach)));
  const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(std::max(a.px.x, b.px.x) + reach)));
  const int y1 = std::min(image.height - 1, static_cast<int>(std::ceil(std::max(a.px.y, b.px.y) + reach)));
  const glm::vec2 d = b.px - a.px;
  const float len2 = glm::dot(d, d);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const glm::vec2 p(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
      const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a.px, d) / len2, 0.0f, 1.0f) : 0.0f;
      const float dist = glm::length(p - (a.px + t * d));
      const float coverage = half + 0.5f - dist;
      if (coverage <= 0.0f) continue;
      if (depth_test) {
        const float inv_w = a.inv_w + (b.inv_w - a.inv_w) * t;
        if (!PassesDepth(image, x, y, 1.0f / inv_w)) continue;
      }
      Blend(image, x, y, color, coverage);
    }
  }
}

// Clips segment a-b to the near plane (z >= -w) and draws it.
void DrawClipSegment(glm::vec4 a, glm::vec4 b, const glm::vec4& color, float width_px,
                     bool depth_test, Image& image) {
  const float da = a.z + a.w, db = b.z + b.w;
  if (da < 0.0f && db < 0.0f) return;
  if (da < 0.0f) a = b + (a - b) * (db / (db - da));
  if (db < 0.0f) b = a + (b - a) * (da / (da - db));
  if (!(a.w > 0.0f) || !(b.w > 0.0f)) return;
  DrawSegment(Project(a, image), Project(b, image), color, width_px, depth_test, image);
}

}  // namespace

void AppendSkeletonLines(std::span<const glm::vec3> joint_positions,
                         std::span<const std::int16_t> parents, LineOverlay& out) {
  const std::size_t n = std::min(joint_positions.size(), parents.size());
  for (std::size_t j = 0; j < n; ++j) {
    const int parent = parents[j];
    if (parent < 0 || static_cast<std::size_t>(parent) >= joint_positions.size()) continue;
    out.endpoints.push_back(joint_positions[static_cast<std::size_t>(parent)]);
    out.endpoints.push_back(joint_positions[j]);
  }
}

void AppendControlNetLines(std::span<const glm::vec3> control_points, int rows, int cols,
                           LineOverlay& out) {
  if (rows <= 0 || cols <= 0 ||
      control_points.size() < static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols))
    return;
  auto at = [&](int r, int c) {
    return control_points[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) +
                          static_cast<std::size_t>(c)];
  };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (c + 1 < cols) {
        out.endpoints.push_back(at(r, c));
        out.endpoints.push_back(at(r, c + 1));
      }
      if (r + 1 < rows) {
        out.endpoints.push_back(at(r, c));
        out.endpoints.push_back(at(r + 1, c));
      }
    }
  }
}

void DrawLines(const glm::mat4& clip_from_world, const LineOverlay& lines, Image& image) {
  for (std::size_t i = 0; i + 1 < lines.endpoints.size(); i += 2) {
    DrawClipSegment(clip_from_world * glm::vec4(lines.endpoints[i], 1.0f),
                    clip_from_world * glm::vec4(lines.endpoints[i + 1], 1.0f), lines.color,
                    lines.width_px, lines.depth_test, image);
  }
}

void DrawPoints(const glm::mat4& clip_from_world, const PointOverlay& points, Image& image) {
  for (const glm::vec3& point : points.points) {
    const glm::vec4 clip = clip_from_world * glm::vec4(point, 1.0f);
    if (clip.z + clip.w < 0.0f || !(clip.w > 0.0f)) continue;
    const ScreenPoint s = Project(clip, image);
    const float reach = points.radius_px + 1.0f;
    const int x0 = std::max(0, static_cast<int>(std::floor(s.px.x - reach)));
    const int y0 = std::max(0, static_cast<int>(std::floor(s.px.y - reach)));
    const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(s.px.x + reach)));
    const int y1 = std::min(image.height - 1, static_cast<int>(std::ceil(s.px.y + reach)));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const glm::vec2 p(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
        const float coverage = points.radius_px + 0.5f - glm::length(p - s.px);
        if (coverage <= 0.0f) continue;
        if (points.depth_test && !PassesDepth(image, x, y, clip.w)) continue;
        Blend(image, x, y, points.color, coverage);
      }
    }
  }
}

void DrawWireframe(const glm::mat4& clip_from_world, std::span<const glm::vec3> positions,
                   std::span<const glm::uvec3> triangles, glm::vec4 color, float width_px,
                   bool depth_test, Image& image) {
  // Each edge once (a shared edge drawn twice would be twice as dark), in a
  // fixed order (sorted vertex pairs) so the blend is deterministic.
  std::vector<std::uint64_t> edges;
  edges.reserve(triangles.size() * 3);
  for (const glm::uvec3& t : triangles) {
    if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size()) continue;
    const std::uint32_t v[3] = {t.x, t.y, t.z};
    for (int i = 0; i < 3; ++i) {
      const std::uint64_t a = std::min(v[i], v[(i + 1) % 3]), b = std::max(v[i], v[(i + 1) % 3]);
      edges.push_back(a << 32 | b);
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const std::uint64_t e : edges) {
    glm::vec4 a = clip_from_world * glm::vec4(positions[e >> 32], 1.0f);
    glm::vec4 b = clip_from_world * glm::vec4(positions[e & 0xffffffffu], 1.0f);
    // Edges a few pixels long fade out: on a dense mesh seen small they would
    // cover the surface (the body turned black); longer ones keep `color`.
    glm::vec4 faded = color;
    if (a.w > 0.0f && b.w > 0.0f) {
      const float length_px = glm::length(Project(a, image).px - Project(b, image).px);
      faded.a *= std::clamp((length_px - kWireFadeStartPx) / (kWireFullPx - kWireFadeStartPx),
                            0.0f, 1.0f);
      if (faded.a <= 0.0f) continue;
    }
    DrawClipSegment(a, b, faded, width_px, depth_test, image);
  }
}

void DrawText(const TextOverlay& text, Image& image) {
  if (image.width <= 0 || image.height <= 0 || text.text.empty()) return;
  try {
    cv::Mat view(image.height, image.width, CV_32FC4, image.rgba.data());
    cv::putText(view, text.text, cv::Point(text.origin_px.x, text.origin_px.y),
                cv::FONT_HERSHEY_SIMPLEX, text.scale,
                cv::Scalar(text.color.r, text.color.g, text.color.b, text.color.a),
                std::max(text.thickness, 1), cv::LINE_8);
  } catch (const cv::Exception&) {
    // Text is decoration: a failure to draw it leaves the image as it was.
  }
}

}  // namespace render
