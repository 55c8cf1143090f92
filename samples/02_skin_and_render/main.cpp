// Sample 02: build a mannequin for a capture's skeleton, skin it with SSD at
// one frame, and render that frame to a PNG.
// Usage: sample_02_skin_and_render FILE.bvh FRAME OUT.png

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "deform/body/mannequin.h"
#include "deform/global/skinning_job.h"
#include "mocap/bvh_reader.h"
#include "mocap/pose.h"
#include "render/camera.h"
#include "render/output/image_io.h"
#include "render/renderer.h"

namespace {

// Model matrices of every joint at a frame (or at rest when frame < 0).
std::vector<glm::mat4> Pose(const mocap::Skeleton& s, const mocap::Motion& m, int frame) {
  std::vector<mocap::JointTransform> locals(static_cast<std::size_t>(s.num_joints()));
  std::vector<glm::mat4> model(locals.size());
  if (frame < 0) {
    mocap::RestPose(s, locals);
  } else {
    (void)mocap::LocalPoseJob{&s, m.frame(frame), locals}.Run();
  }
  (void)mocap::LocalToModelJob{.parents = s.parents, .locals = locals, .model_from_joint = model}.Run();
  return model;
}

int Fail(const base::Error& e) {
  std::fprintf(stderr, "%s\n", e.ToString().c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s FILE.bvh FRAME OUT.png\n", argv[0]);
    return 1;
  }
  mocap::BvhReadOptions options;
  options.convert_to_y_up = true;  // render with Y up
  base::Result<mocap::BvhFile> file = mocap::ReadBvhFile(argv[1], options);
  if (!file.ok()) return Fail(file.error());
  const mocap::Skeleton& skeleton = file->skeleton;
  const mocap::Motion& motion = file->motion;
  const int frame = std::atoi(argv[2]);
  if (frame < 0 || frame >= motion.num_frames) {
    std::fprintf(stderr, "%s: error: frame %d is not in 0..%d\n", argv[1], frame, motion.num_frames - 1);
    return 2;
  }

  // A closed body with smooth weights, bound at the rest pose.
  base::Result<deform::SkinnedMesh> body =
      deform::BuildMannequin(skeleton, Pose(skeleton, motion, -1));
  if (!body.ok()) return Fail(body.error());

  // SSD: palette = model_from_joint * joint_from_bind, then one job over all vertices.
  std::vector<glm::mat4> palette(body->skin_joints.size());
  const std::vector<glm::mat4> model = Pose(skeleton, motion, frame);
  (void)deform::BuildSkinningPalette(model, *body, palette);
  std::vector<glm::vec3> positions(body->bind.positions.size());
  std::vector<glm::vec3> normals(positions.size());
  const base::JobStatus skinned = deform::SkinningJob{.model_from_bind = palette,
                                                      .influences = body->weights.influences,
                                                      .joint_indices = body->weights.joints,
                                                      .joint_weights = body->weights.weights,
                                                      .rest_positions = body->bind.positions,
                                                      .rest_normals = body->bind.normals,
                                                      .positions = positions,
                                                      .normals = normals}
                                      .Run();
  if (!skinned) {
    std::fprintf(stderr, "internal error: %s\n", skinned.what);
    return 3;
  }
  for (glm::vec3& n : normals) n = glm::normalize(n);  // blended normals are not unit length

  // Frame the body and render it.
  const render::SceneMesh mesh{.positions = positions, .normals = normals,
                               .triangles = body->bind.triangles};
  const render::Camera camera = render::FrameBounds(deform::ComputeBounds(positions), 35.0f,
                                                    16.0f / 9.0f, glm::vec3(-0.4f, -0.3f, -1.0f));
  render::RenderSettings settings;
  settings.width = 640;
  settings.height = 360;
  settings.supersample = 2;
  const render::Image image = render::Render(camera, {&mesh, 1}, {}, settings);
  const base::Status written = render::WriteImage(image, argv[3]);
  if (!written.ok()) return Fail(written.error());
  std::printf("wrote %s (%zu vertices, %zu triangles)\n", argv[3], positions.size(),
              body->bind.triangles.size());
  return 0;
}
