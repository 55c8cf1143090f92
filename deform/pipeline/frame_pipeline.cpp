#include "deform/pipeline/frame_pipeline.h"

#include <algorithm>
#include <array>
#include <limits>
#include <optional>
#include <string>

#include "base/parallel.h"
#include "deform/global/skinning_job.h"
#include "mocap/pose.h"
#include "mocap/sampling.h"

namespace deform {
namespace {

inline constexpr int kMaxThreads = 64;

// Runs fn(chunk, begin, end) over [0, n) split into `threads` contiguous ranges
// (chunk = 0..threads-1). The jobs give the same bits for any split, so the
// thread count never changes the output.
template <typename Fn>
void ParallelRanges(int n, int threads, Fn&& fn) {
  threads = std::clamp(threads, 1, kMaxThreads);
  if (threads == 1 || n < 4096) {
    fn(0, 0, n);
    return;
  }
  const int chunk = (n + threads - 1) / threads;
  base::RunOnThreads(threads, [&](int t) {
    const int begin = std::min(n, t * chunk);
    const int end = std::min(n, begin + chunk);
    if (begin < end) fn(t, begin, end);
  });
}

// For each control point of `patch`, the region vertex nearest it in the bind
// mesh (-1 if the region has none): with SWD a control point follows the sweeps
// of the body part its surface approximates (ALGORITHMS.md 2.3).
std::vector<int> NearestRegionVertices(const PatchSetup& patch, const Mesh& bind) {
  std::vector<int> nearest(patch.rest_control.size(), -1);
  for (std::size_t i = 0; i < nearest.size(); ++i) {
    float best = std::numeric_limits<float>::max();
    for (const int v : patch.region) {
      if (v < 0 || v >= bind.num_vertices()) continue;
      const glm::vec3 d = bind.positions[static_cast<std::size_t>(v)] - patch.rest_control[i];
      if (glm::dot(d, d) < best) best = glm::dot(d, d), nearest[i] = v;
    }
  }
  return nearest;
}

// Unit normals of the global result, as every variant gets them: the skinned
// normals normalized (or, without bind normals, the mesh's geometric normals).
void GlobalNormals(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles,
                   bool has_normals, std::span<glm::vec3> normals) {
  if (!has_normals) {
    ComputeVertexNormals(positions, triangles, normals);
    return;
  }
  for (glm::vec3& n : normals) {
    const float len = glm::length(n);
    n = len > 0.0f ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
  }
}

// Turns the global normals by what the patch layer changed in the surface: n +=
// geometric(layered) - geometric(global), renormalized. A vertex whose one-ring
// the layer left alone gets exactly the global normal, so the two sides of a
// comparison shade alike everywhere outside the patch regions.
void AddLayerNormals(std::span<const glm::vec3> global_geometric,
                     std::span<const glm::vec3> layered_geometric, std::span<glm::vec3> normals) {
  for (std::size_t v = 0; v < normals.size(); ++v) {
    const glm::vec3 change = layered_geometric[v] - global_geometric[v];
    if (change == glm::vec3(0.0f)) continue;
    const glm::vec3 n = normals[v] + change;
    const float len = glm::length(n);
    if (len > 0.0f)
      normals[v] = n / len;
    else
      normals[v] = layered_geometric[v];
  }
}

}  // namespace

struct FramePipeline::Impl {
  const Character* character = nullptr;
  int threads = 1;
  CharacterPose pose;
  std::optional<GlobalSkinning> global;
  // The patch layer (empty: global only).
  std::vector<PatchSetup> patches;
  std::vector<SkinBoundPoints> control_points;  // per patch, bound like the skin
  std::vector<std::vector<glm::vec3>> carried;  // per patch, #M x #N
  std::vector<std::span<const glm::vec3>> carried_views;
  // Per patch, the control points as the global layer alone carries them (G):
  // the layer adds P(Q) - P(G), so without local displacements it is the identity.
  std::vector<std::vector<glm::vec3>> reference;
  std::vector<std::span<const glm::vec3>> reference_views;
  PatchLayerScratch patch_scratch;
  // Normals with patches (#V each): the global positions and the geometric
  // normals of them and of the layered mesh (LayerNormals).
  std::vector<glm::vec3> global_positions, global_geometric, layered_geometric;
  std::unique_ptr<ElasticLayer> elastic;             // null: no elastic patches
  std::vector<std::vector<glm::vec3>> displacement;  // per patch, empty or #M x #N (model)
  std::vector<std::span<const glm::vec3>> displacement_views;
  // Example shapes (empty: none): per patch, and scratch for the largest.
  std::vector<PatchPoseSpace> pose_spaces;
  std::vector<float> pose_features;       // max #X
  std::vector<glm::vec3> pose_ds;         // max #M x #N, dS in the local frames
  std::vector<glm::quat> pose_rotations;  // max #M x #N, A
};

FramePipeline::FramePipeline(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FramePipeline::FramePipeline(FramePipeline&&) noexcept = default;
FramePipeline& FramePipeline::operator=(FramePipeline&&) noexcept = default;
FramePipeline::~FramePipeline() = default;

GlobalMethod FramePipeline::method() const { return impl_->global->method(); }
const Character& FramePipeline::character() const { return *impl_->character; }
int FramePipeline::threads() const { return impl_->threads; }

int FramePipeline::num_patches() const { return static_cast<int>(impl_->patches.size()); }

base::Status FramePipeline::SetPatches(std::vector<PatchSetup> patches) {
  Impl& m = *impl_;
  std::vector<SkinBoundPoints> control_points;
  for (std::size_t p = 0; p < patches.size(); ++p) {
    const PatchSetup& patch = patches[p];
    const std::vector<int> guides = m.global->method() == GlobalMethod::kSwd
                                        ? NearestRegionVertices(patch, m.character->mesh.bind)
                                        : std::vector<int>();
    base::Result<SkinBoundPoints> bound =
        m.global->BindPoints(patch.rest_control, patch.control_weights, guides);
    if (!bound.ok()) {
      base::Error e = std::move(bound).error();
      e.loc.file = m.character->source;
      e.message = "patch " + std::to_string(p) + ": " + e.message;
      return e;
    }
    control_points.push_back(std::move(*bound));
  }
  // The bindings refer to the patches' rest points and weights, whose storage
  // moves with the vector.
  m.patches = std::move(patches);
  m.control_points = std::move(control_points);
  m.carried.assign(m.patches.size(), {});
  m.reference.assign(m.patches.size(), {});
  m.carried_views.clear();
  m.reference_views.clear();
  for (std::size_t k = 0; k < m.patches.size(); ++k) {
    m.carried[k].resize(m.patches[k].rest_control.size());
    m.reference[k].resize(m.patches[k].rest_control.size());
    m.carried_views.emplace_back(m.carried[k]);
    m.reference_views.emplace_back(m.reference[k]);
  }
  const auto nv = static_cast<std::size_t>(m.character->mesh.bind.num_vertices());
  for (auto* v : {&m.global_positions, &m.global_geometric, &m.layered_geometric}) {
    v->assign(m.patches.empty() ? 0 : nv, glm::vec3(0.0f));
  }
  m.patch_scratch.Prepare(m.patches, m.character->mesh.bind.num_vertices());
  m.elastic.reset();
  m.displacement.assign(m.patches.size(), {});
  m.displacement_views.assign(m.patches.size(), {});
  m.pose_spaces.clear();
  return base::Status::Ok();
}

base::Status FramePipeline::SetElastic(std::vector<ElasticPatchSpec> specs) {
  Impl& m = *impl_;
  auto layer = ElasticLayer::Create(*m.character, m.patches, std::move(specs));
  if (!layer.ok()) return std::move(layer).error();
  m.elastic = std::move(*layer);
  return base::Status::Ok();
}

std::vector<ElasticPatchReport> FramePipeline::elastic_report() const {
  return impl_->elastic ? impl_->elastic->Report() : std::vector<ElasticPatchReport>();
}

base::Status FramePipeline::SetPoseSpaces(std::vector<PatchPoseSpace> spaces) {
  Impl& m = *impl_;
  const base::FileLoc loc{m.character->source, 0, 0, {}};
  if (!spaces.empty() && spaces.size() != m.patches.size()) {
    return base::InvalidArgument(loc, "expected one pose space per patch (" +
                                          std::to_string(m.patches.size()) + "), found " +
                                          std::to_string(spaces.size()));
  }
  std::size_t max_x = 0, max_c = 0;
  for (std::size_t p = 0; p < spaces.size(); ++p) {
    if (!spaces[p].active()) continue;
    if (m.global->method() == GlobalMethod::kSwd) {
      // The frames A that carry dS (ALGORITHMS.md 4.3) are defined here for
      // SSD and DQS only; refuse rather than drop the examples silently.
      return base::MakeError(base::ErrorCode::kUnsupported, loc,
                             "example shapes need global ssd or dqs (not available with swd yet)");
    }
    const RbfModel& model = spaces[p].model;
    const int dim = PoseFeatureDimension(m.character->skeleton, spaces[p].features);
    if (model.dimension != dim || model.num_values != 3 * m.patches[p].num_control()) {
      return base::InvalidArgument(loc, "pose space " + std::to_string(p) +
                                            " does not fit its patch (features or control points)");
    }
    max_x = std::max(max_x, static_cast<std::size_t>(dim));
    max_c = std::max(max_c, m.patches[p].rest_control.size());
  }
  m.pose_spaces = std::move(spaces);
  m.pose_features.resize(max_x);
  m.pose_ds.resize(max_c);
  m.pose_rotations.resize(max_c);
  return base::Status::Ok();
}

// Q = G + A dS(theta) for patch p, in place on its carried control points.
base::JobStatus FramePipeline::AddExampleShapes(Impl& m, std::size_t p) {
  const PatchPoseSpace& space = m.pose_spaces[p];
  const std::size_t nc = m.patches[p].rest_control.size();
  const std::span<float> features =
      std::span<float>(m.pose_features).first(static_cast<std::size_t>(space.model.dimension));
  const std::span<glm::vec3> ds = std::span<glm::vec3>(m.pose_ds).first(nc);
  const std::span<glm::quat> rotations = std::span<glm::quat>(m.pose_rotations).first(nc);
  if (!ComputePoseFeatures(m.character->skeleton, space.features, m.pose.locals, features).ok()) {
    return {base::JobStatus::kSizeMismatch, "pose features"};
  }
  base::JobStatus s =
      PoseSpaceJob{.model = &space.model, .features = features, .displacement = ds}.Run();
  if (!s) return s;
  s = PatchControlRotations(m.patches[p], m.global->palettes(), rotations, ds);
  if (!s) return s;
  return PoseSpaceApplyJob{
      .global = m.carried[p], .rotations = rotations, .displacement = ds, .control = m.carried[p]}
      .Run();
}

base::Result<FramePipeline> FramePipeline::Create(const Character& character, GlobalMethod method,
                                                  int threads) {
  const base::Status weights =
      CheckSkinWeights(character.mesh.weights, static_cast<int>(character.mesh.skin_joints.size()),
                       character.mesh.bind.num_vertices());
  if (!weights.ok()) return weights.error();
  std::vector<glm::mat4> bind;  // SWD builds its sweeps in the bind pose
  if (method == GlobalMethod::kSwd) {
    base::Result<std::vector<glm::mat4>> model = BindModelFromJoint(character);
    if (!model.ok()) return std::move(model).error();
    bind = std::move(*model);
  }
  base::Result<GlobalSkinning> global =
      GlobalSkinning::Create(method, character.skeleton, bind, character.mesh);
  if (!global.ok()) {
    base::Error e = std::move(global).error();
    if (e.loc.file.empty()) e.loc.file = character.source;
    return e;
  }
  auto impl = std::make_unique<Impl>();
  impl->character = &character;
  impl->global = std::move(*global);
  impl->threads = base::ResolveThreads(threads);
  return FramePipeline(std::move(impl));
}

base::Status FramePipeline::Evaluate(double time_s, DeformedFrame& out) {
  Impl& m = *impl_;
  const Character& c = *m.character;
  const SkinnedMesh& mesh = c.mesh;
  if (base::Status sampled = m.pose.Sample(c, time_s); !sampled.ok()) return sampled;
  base::JobStatus s = m.global->Pose(m.pose.model_from_joint);
  if (!s) return StageError(c, s, "global pose");

  const int nv = mesh.bind.num_vertices();
  out.positions.resize(static_cast<std::size_t>(nv));
  out.normals.resize(static_cast<std::size_t>(nv));
  const bool has_normals = !mesh.bind.normals.empty();
  std::array<base::JobStatus, kMaxThreads> results{};
  ParallelRanges(nv, m.threads, [&](int chunk, int begin, int end) {
    results[static_cast<std::size_t>(chunk)] =
        m.global->SkinVertices(begin, end, out.positions, out.normals);
  });
  for (const base::JobStatus& r : results) {
    if (!r) return StageError(c, r, GlobalMethodName(m.global->method()));
  }
  if (!m.patches.empty()) {
    // Patch layer: carry the control points like skin vertices, add the
    // example shapes dS (in the frames the control points move with) and the
    // elastic displacements dE, rebuild and blend.
    for (std::size_t p = 0; p < m.patches.size(); ++p) {
      s = m.global->CarryPoints(m.control_points[p], m.carried[p]);
      if (!s) return StageError(c, s, "patch control points");
      std::copy(m.carried[p].begin(), m.carried[p].end(), m.reference[p].begin());
      if (p < m.pose_spaces.size() && m.pose_spaces[p].active()) {
        s = AddExampleShapes(m, p);
        if (!s) return StageError(c, s, "pose space");
      }
    }
    std::span<const std::span<const glm::vec3>> displacements;
    if (m.elastic) {
      // dE: the mass-spring networks advanced to this frame's time (state carried).
      const base::Status advanced =
          m.elastic->Advance(time_s, m.pose.model_from_joint, m.displacement);
      if (!advanced.ok()) return advanced;
      for (std::size_t p = 0; p < m.patches.size(); ++p)
        m.displacement_views[p] = m.displacement[p];
      displacements = m.displacement_views;
    }
    std::copy(out.positions.begin(), out.positions.end(), m.global_positions.begin());
    const base::Status layered = ApplyPatchLayer(m.patches, m.carried_views, displacements,
                                                 m.patch_scratch, out.positions, m.reference_views);
    if (!layered.ok()) return layered;
  }
  // Normals (one way for every variant): without bind normals the final
  // surface's geometric normals; with them the skinned normals, turned by the
  // layer's change of the geometric normals where the layer moved the surface.
  GlobalNormals(out.positions, mesh.bind.triangles, has_normals, out.normals);
  if (!m.patches.empty() && has_normals) {
    ComputeVertexNormals(m.global_positions, mesh.bind.triangles, m.global_geometric);
    ComputeVertexNormals(out.positions, mesh.bind.triangles, m.layered_geometric);
    AddLayerNormals(m.global_geometric, m.layered_geometric, out.normals);
  }
  out.joint_positions.resize(m.pose.model_from_joint.size());
  for (std::size_t j = 0; j < m.pose.model_from_joint.size(); ++j) {
    out.joint_positions[j] = glm::vec3(m.pose.model_from_joint[j][3]);
  }
  out.bounds = ComputeBounds(out.positions);
  return base::Status::Ok();
}

}  // namespace deform
