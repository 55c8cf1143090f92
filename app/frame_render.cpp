#include "app/frame_render.h"

#include <utility>

#include "render/overlay.h"

namespace app {
namespace {

void AddSkeleton(const DeformedFrame& f, const mocap::Skeleton& s, render::Overlays& o) {
  render::LineOverlay bones;
  bones.depth_test = false;
  render::AppendSkeletonLines(f.joint_positions, s.parents, bones);
  o.lines.push_back(std::move(bones));
  render::PointOverlay joints;
  joints.points = f.joint_positions;
  joints.depth_test = false;
  o.points.push_back(std::move(joints));
}

// Copies the right half of `right` over `left`, and draws a divider.
void ComposeSplit(const render::Image& right, render::Image& left) {
  const int mid = left.width / 2;
  for (int y = 0; y < left.height; ++y) {
    for (int x = mid; x < left.width; ++x) left.at(x, y) = right.at(x, y);
    left.at(mid, y) = glm::vec4(1.0f);
    if (mid > 0) left.at(mid - 1, y) = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  }
}

// Copies `half` into columns x0.. of `into` (colour, and depth when both have it).
void PasteHalf(const render::Image& half, int x0, render::Image& into) {
  for (int y = 0; y < half.height; ++y) {
    for (int x = 0; x < half.width; ++x) {
      into.at(x0 + x, y) = half.at(x, y);
      if (!into.depth.empty() && !half.depth.empty()) {
        into.depth[into.index(x0 + x, y)] = half.depth[half.index(x, y)];
      }
    }
  }
}

void DrawDivider(render::Image& image) {
  const int mid = image.width / 2;
  for (int y = 0; y < image.height; ++y) {
    image.at(mid, y) = glm::vec4(1.0f);
    if (mid > 0) image.at(mid - 1, y) = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  }
}

mocap::Status DrawOne(const Character& ch, const DeformedFrame& f, const render::Camera& camera,
                      const render::RenderSettings& settings, const FrameDrawOptions& o,
                      const std::string& label, int label_x, bool frame_label,
                      render::Renderer& r, render::Image& into) {
  const deform::Mesh& bind = ch.mesh.bind;
  render::SceneMesh body{.positions = f.positions, .normals = f.normals,
                         .triangles = bind.triangles, .vertex_colors = bind.colors};
  render::Overlays overlays;
  if (o.skeleton) AddSkeleton(f, ch.skeleton, overlays);
  overlays.wireframe = o.wireframe;
  if (frame_label) {
    overlays.text.push_back({.text = "frame " + std::to_string(o.frame_number),
                             .origin_px = {10, settings.height - 12}});
  }
  if (!label.empty()) overlays.text.push_back({.text = label, .origin_px = {label_x, 30}});
  const mocap::JobStatus js = r.Render(camera, {&body, 1}, overlays, settings, into);
  if (!js) {
    return mocap::MakeError(mocap::ErrorCode::kInternal, {ch.source, 0, 0, {}},
                            std::string("renderer refused the frame: ") + js.what);
  }
  return mocap::Status::Ok();
}

}  // namespace

mocap::Status DrawCharacterFrame(const Character& character, const DeformedFrame& frame,
                                 const DeformedFrame* right, const render::Camera& camera,
                                 const render::RenderSettings& settings,
                                 const FrameDrawOptions& options, render::Renderer& renderer,
                                 render::Renderer& right_renderer, render::Image& scratch,
                                 render::Image& into) {
  if (right == nullptr) {
    return DrawOne(character, frame, camera, settings, options, "", 0, true, renderer, into);
  }
  if (options.side_by_side) {
    // Each body whole in its own half: two renders of half the width, pasted.
    render::RenderSettings half = settings;
    half.width = settings.width / 2;
    mocap::Status s = DrawOne(character, frame, camera, half, options, options.left_label, 10,
                              true, renderer, scratch);
    if (!s.ok()) return s;
    if (into.width != settings.width || into.height != settings.height) {
      into = render::Image(settings.width, settings.height);
    }
    into.depth.resize(scratch.depth.empty() ? 0 : into.rgba.size());
    PasteHalf(scratch, 0, into);
    half.width = settings.width - settings.width / 2;
    s = DrawOne(character, *right, camera, half, options, options.right_label, 10, false,
                right_renderer, scratch);
    if (!s.ok()) return s;
    PasteHalf(scratch, settings.width / 2, into);
    DrawDivider(into);
    return mocap::Status::Ok();
  }
  mocap::Status s = DrawOne(character, frame, camera, settings, options, options.left_label, 10,
                            true, renderer, into);
  if (!s.ok()) return s;
  s = DrawOne(character, *right, camera, settings, options, options.right_label,
              settings.width / 2 + 10, true, right_renderer, scratch);
  if (!s.ok()) return s;
  ComposeSplit(scratch, into);
  return mocap::Status::Ok();
}

}  // namespace app
