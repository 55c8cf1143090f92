#pragma once
// A test fixture shared by the direct-manipulation and example-shape tests: a
// half tube (MakeTube) fitted with a 9 x 10 bicubic patch (cylinder map, 18 x 20
// samples), and a skin pushed 0.1 outward (so d != 0 and the normal matters)
// bound to it.

#include <optional>
#include <vector>

#include "deform/patch/bspline.h"
#include "deform/patch/patch_binding.h"
#include "deform/patch/patch_fit.h"
#include "support/patch_meshes.h"

namespace testsupport {

struct BoundTube {
  deform::Mesh tube;
  std::vector<int> region;         // every tube vertex
  deform::BSplineSurface surface;  // the fitted 9 x 10 patch, normal facing out
  std::vector<glm::vec3> skin;     // tube vertices pushed 0.1 outward
  deform::PatchBinding binding;    // skin bound to surface
};

// Empty when any step (map, sampling, fit, binding) fails.
inline std::optional<BoundTube> MakeBoundTube() {
  BoundTube t;
  t.tube = MakeTube(40, 30, 2.0f, 180.0f, 5.0f);
  t.region = AllVertices(t.tube);
  auto param = deform::ParametrizeCylinder(t.tube.positions, t.region, t.tube.triangles,
                                           glm::dvec3(0.0), glm::dvec3(0, 0, 1));
  if (!param.ok()) return std::nullopt;
  auto samples = deform::SampleRegion(t.tube.positions, t.tube.triangles, *param,
                                      deform::UniformParameters(18), deform::UniformParameters(20));
  if (!samples.ok()) return std::nullopt;
  auto fit = deform::FitSurface(*samples, {.num_u = 9, .num_v = 10});
  if (!fit.ok()) return std::nullopt;
  deform::OrientNormal(fit->surface, *param);
  t.surface = fit->surface;
  t.skin = t.tube.positions;
  for (glm::vec3& p : t.skin) p += 0.1f * glm::normalize(glm::vec3(p.x, p.y, 0.0f));
  auto bound = deform::BindPatch(t.surface, t.skin, t.region, param->uv);
  if (!bound.ok()) return std::nullopt;
  t.binding = bound->binding;
  return t;
}

}  // namespace testsupport
