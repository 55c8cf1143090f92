// Newton's polar iteration (deform/shapes/polar_rotation.h) on real blends: every
// control point of the shoulder demo's patch (samples/data/shoulder.json, 9x6,
// three bones for most points) at every 3rd frame of shoulder.bvh. The
// iteration accepts every blend and agrees with the SVD.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "deform/shapes/direct_manipulation.h"
#include "deform/shapes/polar_rotation.h"
#include "deform/global/skinning_job.h"
#include "mocap/pose.h"
#include "support/example_demos.h"
#include "support/tolerances.h"

namespace {

float QuatDistance(const glm::quat& a, const glm::quat& b) {
  const glm::quat s = glm::dot(a, b) < 0.0f ? -b : b;
  return glm::length(glm::vec4(a.x - s.x, a.y - s.y, a.z - s.z, a.w - s.w));
}

TEST(PolarShoulder, NewtonMatchesTheSvdOnTheDemoBlends) {
  const std::unique_ptr<testsupport::Demo> demo = testsupport::LoadDemo("shoulder");
  ASSERT_TRUE(demo->error.empty()) << demo->error;
  const app::Character& ch = demo->character;
  const deform::SkinWeights& w = demo->patches[0].control_weights;
  const auto k = static_cast<std::size_t>(w.influences);
  const std::size_t nc = w.joints.size() / k;
  const auto nj = static_cast<std::size_t>(ch.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(nj), palette(ch.mesh.skin_joints.size());
  // All blends of three or more bones over the frames, in control point order.
  std::vector<glm::dmat3> blends;
  for (int frame = 0; frame < ch.motion.num_frames; frame += 3) {
    ASSERT_TRUE((mocap::LocalPoseJob{&ch.skeleton, ch.motion.frame(frame), locals}.Run()));
    ASSERT_TRUE((mocap::LocalToModelJob{.parents = ch.skeleton.parents, .locals = locals,
                                        .model_from_joint = model}.Run()));
    ASSERT_TRUE(deform::BuildSkinningPalette(model, ch.mesh, palette));
    for (std::size_t c = 0; c < nc; ++c) {
      int bones = 0;
      glm::dmat3 blend(0.0);
      for (std::size_t i = 0; i < k; ++i) {
        const float wi = w.weights[c * k + i];
        if (wi == 0.0f) continue;
        ++bones;
        blend += static_cast<double>(wi) * glm::dmat3(glm::mat3(palette[w.joints[c * k + i]]));
      }
      if (bones >= 3) blends.push_back(blend);
    }
  }
  const std::size_t n = blends.size();
  ASSERT_GT(n, 30u * 40u);  // 36 control points, 50+ frames
  for (std::size_t i = 0; i < n; ++i) {
    glm::dmat3 newton;
    ASSERT_TRUE(deform::PolarRotationNewton(blends[i], newton)) << i;  // none is degenerate
    const glm::quat q = glm::normalize(glm::quat(glm::quat_cast(newton)));
    const glm::quat svd(glm::quat_cast(deform::PolarRotationSvd(blends[i])));
    EXPECT_LT(QuatDistance(q, svd), testsupport::kRotationTol) << i;
  }
  std::printf("%zu shoulder blends, all by the Newton iteration\n", n);
}

}  // namespace
