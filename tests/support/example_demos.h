#pragma once
// The paper's example-shape demos as shipped in samples/data (issue 6): loads
// a demo rig with its motion on the mannequin, builds its patches and pose
// spaces, and evaluates a frame global only and with patches + examples.
// Shared by the figure tests (tests/app/example_demos_test.cpp) and the golden
// frames (tests/golden/example_demos_golden_test.cpp).

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/motion_source.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/rig_examples.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "app/rig_setup.h"
#include "support/data_paths.h"

namespace testsupport {

struct Demo {
  app::Rig rig;
  app::Character character;
  std::vector<deform::PatchSetup> patches;
  std::optional<deform::FramePipeline> global;   // the rig's global method alone
  std::optional<deform::FramePipeline> layered;  // + patches + example shapes
  app::RigPoseSpaces spaces;                  // notes: condition numbers
  std::string error;                          // set when loading failed
};

// Loads samples/data/<name>.json. Any failure is returned in Demo::error.
inline std::unique_ptr<Demo> LoadDemo(const std::string& name) {
  auto demo = std::make_unique<Demo>();
  auto fail = [&](const base::Error& e) {
    demo->error = e.ToString();
    return std::move(demo);
  };
  auto rig = app::LoadRig(SampleDataPath(name + ".json").string());
  if (!rig.ok()) return fail(rig.error());
  demo->rig = std::move(*rig);
  auto source = app::LoadMotionSource(demo->rig.motion, {.y_up = true});
  if (!source.ok()) return fail(source.error());
  auto character = app::MakeCharacter(std::move(*source), {}, app::RigBodyKind(demo->rig));
  if (!character.ok()) return fail(character.error());
  demo->character = std::move(*character);
  auto patches = app::BuildRigPatches(demo->rig, demo->character);
  if (!patches.ok()) return fail(patches.error());
  demo->patches = std::move(*patches);
  auto method = app::ParseGlobalMethod(demo->rig.global);
  if (!method.ok()) return fail(method.error());
  auto spaces = app::BuildRigPoseSpaces(demo->rig, demo->character, demo->patches, *method);
  if (!spaces.ok()) return fail(spaces.error());
  auto global = deform::FramePipeline::Create(demo->character, *method, 1);
  auto layered = deform::FramePipeline::Create(demo->character, *method, 1);
  if (!global.ok()) return fail(global.error());
  if (!layered.ok()) return fail(layered.error());
  if (base::Status s = layered->SetPatches(demo->patches); !s.ok()) return fail(s.error());
  if (base::Status s = layered->SetPoseSpaces(spaces->patches); !s.ok()) return fail(s.error());
  demo->spaces = std::move(*spaces);
  demo->global.emplace(std::move(*global));
  demo->layered.emplace(std::move(*layered));
  return demo;
}

// Position of joint `name` in an evaluated frame.
inline glm::dvec3 JointAt(const Demo& d, const deform::DeformedFrame& f, const std::string& name) {
  const int j = d.character.skeleton.FindJoint(name);
  return glm::dvec3(f.joint_positions.at(static_cast<std::size_t>(j)));
}

// Signed volume enclosed by the mesh (closed, outward-oriented components),
// sum over triangles of dot(a - o, cross(b - o, c - o)) / 6.
inline double MeshVolume(const std::vector<glm::vec3>& p, const std::vector<glm::uvec3>& tris,
                         const glm::dvec3& origin) {
  double v = 0.0;
  for (const glm::uvec3& t : tris) {
    const glm::dvec3 a = glm::dvec3(p[t.x]) - origin, b = glm::dvec3(p[t.y]) - origin,
                     c = glm::dvec3(p[t.z]) - origin;
    v += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return v;
}

// Largest extent of `vertices` from `origin` along the unit direction `dir`.
inline double Protrusion(const std::vector<glm::vec3>& p, const std::vector<int>& vertices,
                         const glm::dvec3& origin, const glm::dvec3& dir) {
  double best = -1e30;
  for (int v : vertices) best = std::max(best, glm::dot(glm::dvec3(p[static_cast<std::size_t>(v)]) - origin, dir));
  return best;
}

// Largest distance of `vertices` from the segment a -> b, over those whose
// projection falls within [t0, t1] of it.
inline double RadialExtent(const std::vector<glm::vec3>& p, const std::vector<int>& vertices,
                           const glm::dvec3& a, const glm::dvec3& b, double t0, double t1) {
  const glm::dvec3 axis = b - a;
  const double len2 = glm::dot(axis, axis);
  double best = 0.0;
  for (int v : vertices) {
    const glm::dvec3 q = glm::dvec3(p[static_cast<std::size_t>(v)]);
    const double t = glm::dot(q - a, axis) / len2;
    if (t < t0 || t > t1) continue;
    best = std::max(best, glm::length(q - (a + t * axis)));
  }
  return best;
}

// Curvature (1 / radius, model units) of the outside of a bend, as the
// circle centred at the joint that best fits the outer profile: in the bend
// plane (normal hat(cross(in_dir, out_dir))) through the joint, the profile
// radius r(phi) is the farthest of `vertices` within `slab` of the plane and
// 6 degrees of the direction at angle phi from the outer bisector
// hat(in_dir - out_dir); the result is 1 / mean r over phi = -50..50 degrees
// in steps of 10. A round knee keeps about 1 / (limb radius); linear blend
// skinning pulls the outside onto the chord between the bones, close to the
// joint: a sharp, much larger value. NaN when fewer than 5 directions have a
// vertex.
inline double BendCurvature(const std::vector<glm::vec3>& p, const std::vector<int>& vertices,
                            const glm::dvec3& joint, const glm::dvec3& in_dir,
                            const glm::dvec3& out_dir, double slab) {
  const glm::dvec3 n = glm::normalize(glm::cross(in_dir, out_dir));
  const glm::dvec3 b = glm::normalize(in_dir - out_dir);
  const glm::dvec3 t = glm::cross(n, b);
  double sum = 0.0;
  int count = 0;
  for (int deg = -50; deg <= 50; deg += 10) {
    double r = 0.0;
    for (int v : vertices) {
      const glm::dvec3 q = glm::dvec3(p[static_cast<std::size_t>(v)]) - joint;
      if (std::abs(glm::dot(q, n)) > slab) continue;
      const double ang = std::atan2(glm::dot(q, t), glm::dot(q, b));
      if (std::abs(ang - glm::radians(static_cast<double>(deg))) > glm::radians(6.0)) continue;
      r = std::max(r, std::hypot(glm::dot(q, t), glm::dot(q, b)));
    }
    if (r > 0.0) sum += r, ++count;
  }
  return count >= 5 ? count / sum : std::nan("");
}

}  // namespace testsupport
