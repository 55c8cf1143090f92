// The elastic layer's compact driving kinematics (issue 8): only the driving
// joints' columns are computed and kept (#F x #D instead of #F x #J), and they
// are the same floats as the matching entries of the full table, with and
// without the low-pass, for a real rig's driving joint and for several joints
// in any order.

#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "deform/pipeline/elastic_layer.h"
#include "mocap/kinematics.h"
#include "app/rig_file.h"
#include "app/rig_patches.h"
#include "support/elastic_rig.h"

namespace {

// Same bits: the smoothing and the differences are per joint column, so
// restricting the columns must not change a single float.
bool SameBits(const mocap::JointKinematics& a, const mocap::JointKinematics& b) {
  return std::memcmp(&a, &b, sizeof(a)) == 0;
}

void ExpectCompactEqualsFull(const app::Character& c, const std::vector<int>& joints,
                             double cutoff_hz) {
  const std::size_t nj = static_cast<std::size_t>(c.skeleton.num_joints());
  const std::size_t nf = static_cast<std::size_t>(c.motion.num_frames);
  auto full = mocap::ComputeKinematics(c.skeleton, c.motion, cutoff_hz, c.world_from_model);
  auto compact =
      mocap::ComputeKinematicsOf(c.skeleton, c.motion, joints, cutoff_hz, c.world_from_model);
  ASSERT_TRUE(full.ok()) << full.error().ToString();
  ASSERT_TRUE(compact.ok()) << compact.error().ToString();
  ASSERT_EQ(full->size(), nf * nj);
  ASSERT_EQ(compact->size(), nf * joints.size());
  int differing = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    for (std::size_t d = 0; d < joints.size(); ++d) {
      const std::size_t j = static_cast<std::size_t>(joints[d]);
      if (!SameBits((*compact)[f * joints.size() + d], (*full)[f * nj + j])) ++differing;
    }
  }
  EXPECT_EQ(differing, 0) << "cutoff " << cutoff_hz << " Hz";
}

TEST(ElasticKinematics, CompactTableEqualsTheFullTableRowsOfTheDrivingJoints) {
  testsupport::RigPipeline l = testsupport::LoadSampleRig("belly_jump.json");
  ASSERT_FALSE(HasFailure());
  const app::Character& c = *l.character;
  auto patches = app::BuildRigPatches(l.rig, c);
  ASSERT_TRUE(patches.ok()) << patches.error().ToString();
  auto specs = app::ResolveRigElastic(l.rig, c, *patches);
  ASSERT_TRUE(specs.ok()) << specs.error().ToString();
  ASSERT_EQ(specs->size(), 1u);
  const deform::ElasticPatchSpec& spec = specs->front();
  // The rig's own driving joint at its cutoff, and unsmoothed.
  ExpectCompactEqualsFull(c, {spec.joint}, spec.cutoff_hz);
  ExpectCompactEqualsFull(c, {spec.joint}, 0.0);
  // Several columns in a scrambled order, the root and the last joint among them.
  const int last = c.skeleton.num_joints() - 1;
  ExpectCompactEqualsFull(c, {last, spec.joint, 0, last / 2}, spec.cutoff_hz);
  ExpectCompactEqualsFull(c, {last, spec.joint, 0, last / 2}, 0.0);
}

TEST(ElasticKinematics, ChunkedModelMatricesCoverMotionsLongerThanOneChunk) {
  // More frames than one chunk of model matrices (256), and not a multiple.
  testsupport::RigPipeline l = testsupport::LoadSampleRig("belly_jump.json");
  ASSERT_FALSE(HasFailure());
  app::Character& c = *l.character;
  mocap::Motion m = c.motion;
  const std::size_t nc = static_cast<std::size_t>(m.num_channels);
  const int base = m.num_frames;
  while (m.num_frames < 700) {  // the clip played forward then backward, repeatedly
    const int f = m.num_frames % (2 * base);
    const int src = f < base ? f : 2 * base - 1 - f;
    m.values.insert(m.values.end(), m.values.begin() + static_cast<std::ptrdiff_t>(src * nc),
                    m.values.begin() + static_cast<std::ptrdiff_t>((src + 1) * nc));
    ++m.num_frames;
  }
  c.motion = m;
  ExpectCompactEqualsFull(c, {2, 1}, 10.0);
}

TEST(ElasticKinematics, RefusesAnEmptyRepeatedOrOutOfRangeJointList) {
  testsupport::RigPipeline l = testsupport::LoadSampleRig("belly_jump.json");
  ASSERT_FALSE(HasFailure());
  const app::Character& c = *l.character;
  const int nj = c.skeleton.num_joints();
  for (const std::vector<int>& joints :
       {std::vector<int>{}, std::vector<int>{1, 1}, std::vector<int>{nj}, std::vector<int>{-1}}) {
    auto k = mocap::ComputeKinematicsOf(c.skeleton, c.motion, joints, 10.0);
    ASSERT_FALSE(k.ok());
    EXPECT_EQ(k.error().code, base::ErrorCode::kInvalidArgument);
    EXPECT_NE(k.error().message.find("joint"), std::string::npos) << k.error().message;
  }
}

}  // namespace
