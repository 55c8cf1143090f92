#include "deform/io/gltf_mesh_sampler.h"

#include <algorithm>
#include <cmath>

#include "deform/global/skinning_job.h"
#include "base/check.h"

namespace deform {
namespace {

// Writes the value of `channel` at time t (a float, as the keys are) into
// out[0 .. num_targets). Same rules as the TRS channels (gltf_animation.cpp).
void EvaluateWeights(const GltfWeightsChannel& channel, float t, std::span<float> out) {
  const auto w = static_cast<std::size_t>(channel.num_targets);
  const bool cubic = channel.interpolation == GltfInterpolation::kCubicSpline;
  const std::size_t key_stride = cubic ? 3 * w : w;
  const std::size_t value_offset = cubic ? w : 0;  // skip the in-tangent
  auto key = [&](std::size_t k, std::size_t offset) {
    return channel.values.data() + k * key_stride + offset;
  };
  auto copy_key = [&](std::size_t k) { std::copy_n(key(k, value_offset), w, out.begin()); };
  const std::vector<float>& times = channel.times_s;
  const std::size_t n = times.size();
  if (n == 1 || !(t > times.front())) return copy_key(0);  // a NaN time too
  if (t >= times.back()) return copy_key(n - 1);
  const auto k1 = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const std::size_t k = k1 - 1;  // times[k] <= t < times[k1]
  const double dt = static_cast<double>(times[k1]) - times[k];
  if (channel.interpolation == GltfInterpolation::kStep || dt <= 0.0) return copy_key(k);
  const double s = std::clamp((static_cast<double>(t) - times[k]) / dt, 0.0, 1.0);
  if (!cubic) {
    const float* a = key(k, 0);
    const float* b = key(k1, 0);
    for (std::size_t i = 0; i < w; ++i) out[i] = static_cast<float>(a[i] + s * (b[i] - a[i]));
    return;
  }
  const double s2 = s * s;
  const double s3 = s2 * s;
  const float* v0 = key(k, w);      // value at k
  const float* b0 = key(k, 2 * w);  // out-tangent at k
  const float* a1 = key(k1, 0);     // in-tangent at k+1
  const float* v1 = key(k1, w);     // value at k+1
  for (std::size_t i = 0; i < w; ++i) {
    out[i] = static_cast<float>((2 * s3 - 3 * s2 + 1) * v0[i] + (s3 - 2 * s2 + s) * dt * b0[i] +
                                (-2 * s3 + 3 * s2) * v1[i] + (s3 - s2) * dt * a1[i]);
  }
}

base::Error ModelError(const GltfModel& model, const std::string& what) {
  return base::InvalidArgument({model.skeleton.info.source_file, 0, 0, {}}, what);
}

}  // namespace

void SampleGltfMorphWeights(const GltfModel& model, int animation, double t_s, std::span<float> weights) {
  PATCHSKIN_CHECK(animation >= -1 && animation < static_cast<int>(model.animations.size()));
  PATCHSKIN_CHECK(weights.size() == static_cast<std::size_t>(model.morph.num_targets));
  std::copy(model.morph.default_weights.begin(), model.morph.default_weights.end(), weights.begin());
  if (animation < 0) return;
  const auto t = static_cast<float>(t_s);
  for (const GltfWeightsChannel& c : model.animations[static_cast<std::size_t>(animation)].weights_channels) {
    EvaluateWeights(c, t, weights.subspan(static_cast<std::size_t>(c.first_target),
                                          static_cast<std::size_t>(c.num_targets)));
  }
}

GltfMeshSampler::GltfMeshSampler(const GltfModel& model) : model_(&model) {
  const auto nv = model.mesh.bind.positions.size();
  const auto nj = static_cast<std::size_t>(model.skeleton.num_joints());
  weights_.resize(static_cast<std::size_t>(model.morph.num_targets));
  morphed_positions_.resize(nv);
  morphed_normals_.resize(nv);
  locals_.resize(nj);
  model_from_joint_.resize(nj);
  palette_.resize(model.mesh.skin_joints.size());
}

base::Result<GltfMeshSampler> GltfMeshSampler::Create(const GltfModel& model) {
  const base::Status weights =
      CheckSkinWeights(model.mesh.weights, static_cast<int>(model.mesh.skin_joints.size()),
                       model.mesh.bind.num_vertices());
  if (!weights.ok()) {
    base::Error e = weights.error();
    if (e.loc.file.empty()) e.loc.file = model.skeleton.info.source_file;
    return e;
  }
  const std::size_t expected =
      static_cast<std::size_t>(model.morph.num_targets) * model.mesh.bind.positions.size();
  if (model.morph.position_deltas.size() != expected ||
      (!model.morph.normal_deltas.empty() && model.morph.normal_deltas.size() != expected) ||
      model.morph.default_weights.size() != static_cast<std::size_t>(model.morph.num_targets)) {
    return ModelError(model, "morph target arrays do not match the vertex and target counts");
  }
  return GltfMeshSampler(model);
}

base::Status GltfMeshSampler::Sample(int animation, double t_s, std::span<glm::vec3> positions,
                                     std::span<glm::vec3> normals) {
  const GltfModel& m = *model_;
  const std::size_t nv = morphed_positions_.size();
  if (animation < -1 || animation >= static_cast<int>(m.animations.size())) {
    return ModelError(m, "animation " + std::to_string(animation) + " requested, the model has " +
                             std::to_string(m.animations.size()));
  }
  if (positions.size() != nv || normals.size() != nv) {
    return ModelError(m, "expected " + std::to_string(nv) + " positions and normals");
  }
  // 1-2. Morph in bind space; targets with weight 0 add nothing and are skipped.
  SampleGltfMorphWeights(m, animation, t_s, weights_);
  std::copy(m.mesh.bind.positions.begin(), m.mesh.bind.positions.end(), morphed_positions_.begin());
  const bool has_normals = !m.mesh.bind.normals.empty();
  if (has_normals) std::copy(m.mesh.bind.normals.begin(), m.mesh.bind.normals.end(), morphed_normals_.begin());
  for (std::size_t k = 0; k < weights_.size(); ++k) {
    const float w = weights_[k];
    if (w == 0.0f) continue;
    const glm::vec3* dp = m.morph.position_deltas.data() + k * nv;
    for (std::size_t v = 0; v < nv; ++v) morphed_positions_[v] += w * dp[v];
    if (has_normals && !m.morph.normal_deltas.empty()) {
      const glm::vec3* dn = m.morph.normal_deltas.data() + k * nv;
      for (std::size_t v = 0; v < nv; ++v) morphed_normals_[v] += w * dn[v];
    }
  }
  // 3. Joint matrices.
  if (animation >= 0 && !m.skeleton.parents.empty()) {
    SampleGltfAnimation(m, animation, t_s, locals_);
  } else {
    mocap::RestPose(m.skeleton, locals_);
  }
  base::JobStatus s =
      mocap::LocalToModelJob{
          .parents = m.skeleton.parents, .locals = locals_, .model_from_joint = model_from_joint_}
          .Run();
  if (s) s = BuildSkinningPalette(model_from_joint_, m.mesh, palette_);
  // 4. Skinning.
  if (s) {
    s = SkinningJob{.model_from_bind = palette_,
                    .influences = m.mesh.weights.influences,
                    .joint_indices = m.mesh.weights.joints,
                    .joint_weights = m.mesh.weights.weights,
                    .rest_positions = morphed_positions_,
                    .rest_normals = has_normals ? std::span<const glm::vec3>(morphed_normals_)
                                                : std::span<const glm::vec3>(),
                    .positions = positions,
                    .normals = normals}
            .Run();
  }
  if (!s) {
    return base::MakeError(base::ErrorCode::kInternal, {m.skeleton.info.source_file, 0, 0, {}},
                           std::string("glTF sampling refused to run: ") + s.what);
  }
  // 5. Unit normals (computed from the skinned mesh when the file has none).
  if (!has_normals) {
    ComputeVertexNormals(positions, m.mesh.bind.triangles, normals);
  } else {
    for (glm::vec3& n : normals) {
      const float len = glm::length(n);
      if (len > 0.0f) n /= len;
    }
  }
  return base::Status::Ok();
}

}  // namespace deform
