#include "deform/patch/patch_layer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "deform/global/skinning_job.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

using internal::InvalidArgument;

// The region's own parameters in binding order are not needed: BindPatch takes
// them in region order.
std::vector<glm::dvec2> RegionUv(const RegionParametrization& param) { return param.uv; }

}  // namespace

float BorderWeight(float u, float v, float width) {
  if (!(width > 0.0f)) return 1.0f;
  const float m = std::min(std::min(u, 1.0f - u), std::min(v, 1.0f - v));
  const float y = std::clamp(m / width, 0.0f, 1.0f);
  return y * y * (3.0f - 2.0f * y);  // smoothstep
}

SkinWeights ControlPointWeights(const SkinnedMesh& mesh, const BSplineSurface& surface,
                                const PatchBinding& binding, std::span<const int> region,
                                int influences) {
  const int nu = surface.num_u(), nv = surface.num_v();
  const auto nc = static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv);
  const std::size_t ns = mesh.skin_joints.size();
  const int k = mesh.weights.influences;
  std::vector<double> acc(nc * ns, 0.0);  // #C x #S weighted sums
  std::vector<double> denom(nc, 0.0);     // #C sum of basis values
  const int p = surface.degree_u(), q = surface.degree_v();
  double bu[kMaxSplineDegree + 1], bv[kMaxSplineDegree + 1];
  for (std::size_t r = 0; r < binding.size(); ++r) {
    const double u = binding.u[r], v = binding.v[r];
    const int su = FindSpan(surface.knots_u(), nu, p, u);
    const int sv = FindSpan(surface.knots_v(), nv, q, v);
    BasisFuns(surface.knots_u(), su, p, u, std::span<double>(bu, static_cast<std::size_t>(p + 1)));
    BasisFuns(surface.knots_v(), sv, q, v, std::span<double>(bv, static_cast<std::size_t>(q + 1)));
    const auto vert = static_cast<std::size_t>(binding.vertex[r]);
    for (int a = 0; a <= p; ++a) {
      for (int b = 0; b <= q; ++b) {
        const double basis = bu[a] * bv[b];
        if (basis == 0.0) continue;
        const auto c = static_cast<std::size_t>((su - p + a) * nv + (sv - q + b));
        denom[c] += basis;
        for (int i = 0; i < k; ++i) {
          const std::size_t slot = vert * static_cast<std::size_t>(k) + static_cast<std::size_t>(i);
          const std::size_t s = mesh.weights.joints[slot];
          if (s < ns) acc[c * ns + s] += basis * mesh.weights.weights[slot];
        }
      }
    }
  }
  SkinWeights out;
  out.influences = influences;
  out.joints.assign(nc * static_cast<std::size_t>(influences), 0);
  out.weights.assign(nc * static_cast<std::size_t>(influences), 0.0f);
  const std::vector<double> gu = GrevilleAbscissae(surface.knots_u(), nu, p);
  const std::vector<double> gv = GrevilleAbscissae(surface.knots_v(), nv, q);
  std::vector<std::pair<double, int>> order(ns);
  for (std::size_t c = 0; c < nc; ++c) {
    std::vector<double> w(acc.begin() + static_cast<std::ptrdiff_t>(c * ns),
                          acc.begin() + static_cast<std::ptrdiff_t>((c + 1) * ns));
    if (denom[c] < 1e-6) {
      // Too few bound vertices under this control point: copy the weights of
      // the region vertex nearest the surface point under it.
      const glm::dvec3 target = surface.Evaluate(gu[c / static_cast<std::size_t>(nv)],
                                                 gv[c % static_cast<std::size_t>(nv)]);
      double best = 1e300;
      std::size_t best_v = 0;
      for (const int rv : region) {
        const double d2 = glm::dot(glm::dvec3(mesh.bind.positions[static_cast<std::size_t>(rv)]) -
                                       target,
                                   glm::dvec3(mesh.bind.positions[static_cast<std::size_t>(rv)]) -
                                       target);
        if (d2 < best) best = d2, best_v = static_cast<std::size_t>(rv);
      }
      std::fill(w.begin(), w.end(), 0.0);
      for (int i = 0; i < k; ++i) {
        const std::size_t slot = best_v * static_cast<std::size_t>(k) + static_cast<std::size_t>(i);
        const std::size_t s = mesh.weights.joints[slot];
        if (s < ns) w[s] += mesh.weights.weights[slot];
      }
    }
    for (std::size_t s = 0; s < ns; ++s) order[s] = {w[s], static_cast<int>(s)};
    // Largest first; ties by joint index so the result is deterministic.
    std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    for (int i = 0; i < influences && static_cast<std::size_t>(i) < ns; ++i) {
      const std::size_t slot = c * static_cast<std::size_t>(influences) + static_cast<std::size_t>(i);
      out.joints[slot] = static_cast<std::uint16_t>(order[static_cast<std::size_t>(i)].second);
      out.weights[slot] = static_cast<float>(order[static_cast<std::size_t>(i)].first);
    }
  }
  NormalizeSkinWeights(out);
  return out;
}

std::vector<float> BorderWeights(const PatchBinding& binding,
                                 std::span<const glm::uvec3> triangles, int num_vertices,
                                 float width) {
  const std::size_t nb = binding.size();
  std::vector<float> out(nb, 1.0f);
  if (!(width > 0.0f)) return out;
  // Record of each mesh vertex, -1 when unbound.
  std::vector<int> record(static_cast<std::size_t>(std::max(0, num_vertices)), -1);
  for (std::size_t r = 0; r < nb; ++r) record[static_cast<std::size_t>(binding.vertex[r])] = static_cast<int>(r);
  // Boundary records: bound vertices sharing a triangle with an unbound one.
  std::vector<char> boundary(nb, 0);
  for (const glm::uvec3& t : triangles) {
    const int a = record[t.x], b = record[t.y], c = record[t.z];
    const bool any_out = a < 0 || b < 0 || c < 0;
    if (!any_out) continue;
    for (const int r : {a, b, c}) {
      if (r >= 0) boundary[static_cast<std::size_t>(r)] = 1;
    }
  }
  std::vector<glm::vec2> edge;
  for (std::size_t r = 0; r < nb; ++r) {
    if (boundary[r]) edge.emplace_back(binding.u[r], binding.v[r]);
  }
  for (std::size_t r = 0; r < nb; ++r) {
    const glm::vec2 uv(binding.u[r], binding.v[r]);
    float m = std::min(std::min(uv.x, 1.0f - uv.x), std::min(uv.y, 1.0f - uv.y));
    for (const glm::vec2& e : edge) m = std::min(m, glm::length(uv - e));
    const float y = std::clamp(m / width, 0.0f, 1.0f);
    out[r] = y * y * (3.0f - 2.0f * y);
  }
  return out;
}

base::Result<PatchSetup> BuildPatchSetup(const SkinnedMesh& mesh, std::span<const int> region,
                                         const PatchOptions& options) {
  if (options.grid_u < 4 || options.grid_v < 4 || options.grid_u > 64 || options.grid_v > 64) {
    return InvalidArgument("patch grid must be 4..64 control points each way, found " +
                           std::to_string(options.grid_u) + "x" + std::to_string(options.grid_v));
  }
  if (options.samples_u < options.grid_u || options.samples_v < options.grid_v ||
      options.samples_u > 256 || options.samples_v > 256) {
    return InvalidArgument(
        "patch sampling must be at least the grid and at most 256 each way, found " +
        std::to_string(options.samples_u) + "x" + std::to_string(options.samples_v));
  }
  if (!(options.border_width >= 0.0f && options.border_width <= 0.5f)) {
    return InvalidArgument("patch border width must be in [0, 0.5] (parameter units)");
  }
  PatchSetup out;
  out.region.assign(region.begin(), region.end());
  const Mesh& bind = mesh.bind;
  base::Result<RegionParametrization> param =
      options.parametrization == RegionParametrization::Kind::kCylinder
          ? ParametrizeCylinder(bind.positions, region, bind.triangles, options.axis_origin,
                                options.axis_direction)
          : ParametrizePlane(bind.positions, region, bind.triangles, options.axis_direction);
  if (!param.ok()) return std::move(param).error();
  out.param = std::move(*param);
  const std::vector<double> us = UniformParameters(options.samples_u);
  const std::vector<double> vs = UniformParameters(options.samples_v);
  base::Result<PatchSamples> samples =
      SampleRegion(bind.positions, bind.triangles, out.param, us, vs);
  if (!samples.ok()) return std::move(samples).error();
  base::Result<PatchFit> fit = FitSurface(
      *samples, {.num_u = options.grid_u, .num_v = options.grid_v, .smoothing = options.smoothing});
  if (!fit.ok()) return std::move(fit).error();
  out.fit = std::move(*fit);
  OrientNormal(out.fit.surface, out.param);
  const std::vector<glm::dvec2> region_uv = RegionUv(out.param);
  base::Result<BindResult> bound = BindPatch(out.fit.surface, bind.positions, region, region_uv);
  if (!bound.ok()) return std::move(bound).error();
  out.bound = std::move(*bound);
  out.rest_control = ControlPointsAsFloat(out.fit.surface);
  out.control_weights =
      ControlPointWeights(mesh, out.fit.surface, out.bound.binding, out.region, 4);
  out.border_weight = BorderWeights(out.bound.binding, bind.triangles, bind.num_vertices(),
                                    options.border_width);
  return out;
}

base::JobStatus CarryControlPointsJob::Validate() const {
  using S = base::JobStatus;
  if (patch == nullptr) return {S::kMissingInput, "no patch"};
  if (pose.model_from_bind.empty() && pose.dual_quats.empty()) {
    return {S::kMissingInput, "no SSD or DQS palette"};
  }
  if (control.size() != patch->rest_control.size()) {
    return {S::kSizeMismatch, "control output is not #M x #N"};
  }
  return {};
}

base::JobStatus CarryControlPointsJob::Run() const {
  const base::JobStatus s = Validate();
  if (!s) return s;
  return SkinPoints(pose, patch->control_weights, patch->rest_control, {}, 0, patch->num_control(),
                    control, {});
}

void PatchLayerScratch::Prepare(std::span<const PatchSetup> patches, int num_vertices) {
  std::size_t max_c = 0, max_b = 0;
  for (const PatchSetup& p : patches) {
    max_c = std::max(max_c, p.rest_control.size());
    max_b = std::max(max_b, p.bound.binding.size());
  }
  control.resize(max_c);
  rebuilt.resize(max_b);
  reference_rebuilt.resize(max_b);
  delta_sum.assign(static_cast<std::size_t>(std::max(0, num_vertices)), glm::vec3(0.0f));
  beta_sum.assign(static_cast<std::size_t>(std::max(0, num_vertices)), 0.0f);
}

base::Status ApplyPatchLayer(std::span<const PatchSetup> patches,
                             std::span<const std::span<const glm::vec3>> carried,
                             std::span<const std::span<const glm::vec3>> displacements,
                             PatchLayerScratch& scratch, std::span<glm::vec3> positions,
                             std::span<const std::span<const glm::vec3>> reference) {
  if (carried.size() != patches.size()) {
    return InvalidArgument("patch layer: one carried control grid per patch is required");
  }
  if (!reference.empty() && reference.size() != patches.size()) {
    return InvalidArgument("patch layer: reference grids must be empty or one per patch");
  }
  if (!displacements.empty() && displacements.size() != patches.size()) {
    return InvalidArgument("patch layer: displacements must be empty or one per patch");
  }
  const std::size_t nv = positions.size();
  for (std::size_t k = 0; k < patches.size(); ++k) {
    const PatchSetup& p = patches[k];
    if (carried[k].size() != p.rest_control.size()) {
      return InvalidArgument("patch layer: carried control grid " + std::to_string(k) +
                             " is not #M x #N");
    }
    if (!displacements.empty() && !displacements[k].empty() &&
        displacements[k].size() != p.rest_control.size()) {
      return InvalidArgument("patch layer: displacement " + std::to_string(k) + " is not #M x #N");
    }
    if (!reference.empty() && reference[k].size() != p.rest_control.size()) {
      return InvalidArgument("patch layer: reference grid " + std::to_string(k) +
                             " is not #M x #N");
    }
    for (const int v : p.bound.binding.vertex) {
      if (v < 0 || static_cast<std::size_t>(v) >= nv) {
        return InvalidArgument("patch layer: patch " + std::to_string(k) +
                               " binds a vertex past #V");
      }
    }
  }
  if (scratch.delta_sum.size() != nv) scratch.Prepare(patches, static_cast<int>(nv));
  for (std::size_t k = 0; k < patches.size(); ++k) {
    const PatchSetup& p = patches[k];
    const std::size_t nc = p.rest_control.size(), nb = p.bound.binding.size();
    if (scratch.control.size() < nc || scratch.rebuilt.size() < nb ||
        scratch.reference_rebuilt.size() < nb) {
      scratch.Prepare(patches, static_cast<int>(nv));
    }
    const std::span<glm::vec3> q(scratch.control.data(), nc);
    const std::span<const glm::vec3> dq =
        displacements.empty() ? std::span<const glm::vec3>() : displacements[k];
    for (std::size_t c = 0; c < nc; ++c) q[c] = dq.empty() ? carried[k][c] : carried[k][c] + dq[c];
    const std::span<glm::vec3> rebuilt(scratch.rebuilt.data(), nb);
    const base::JobStatus s =
        PatchRebuildJob{.control = q, .bindings = p.bound.binding.view(), .positions = rebuilt}
            .Run();
    if (!s) return InvalidArgument(std::string("patch layer: rebuild refused: ") + s.what);
    // Relative: the rebuild of the reference grid stands in for G, so only what
    // the displacements change reaches the mesh (the same grid gives exactly 0).
    const std::span<glm::vec3> base(scratch.reference_rebuilt.data(), reference.empty() ? 0 : nb);
    if (!reference.empty()) {
      const base::JobStatus r =
          PatchRebuildJob{
              .control = reference[k], .bindings = p.bound.binding.view(), .positions = base}
              .Run();
      if (!r) return InvalidArgument(std::string("patch layer: rebuild refused: ") + r.what);
    }
    for (std::size_t r = 0; r < nb; ++r) {
      const auto v = static_cast<std::size_t>(p.bound.binding.vertex[r]);
      const float beta = p.border_weight[r];
      scratch.delta_sum[v] += beta * (rebuilt[r] - (base.empty() ? positions[v] : base[r]));
      scratch.beta_sum[v] += beta;
    }
  }
  // Blend (3.8) and clear the touched accumulators for the next frame.
  for (const PatchSetup& p : patches) {
    for (const int vi : p.bound.binding.vertex) {
      const auto v = static_cast<std::size_t>(vi);
      const float total = scratch.beta_sum[v];
      if (total < 0.0f) continue;  // already applied (overlap)
      positions[v] += scratch.delta_sum[v] / std::max(1.0f, total);
      scratch.delta_sum[v] = glm::vec3(0.0f);
      scratch.beta_sum[v] = -1.0f;  // mark as done
    }
  }
  for (const PatchSetup& p : patches) {
    for (const int vi : p.bound.binding.vertex) scratch.beta_sum[static_cast<std::size_t>(vi)] = 0.0f;
  }
  return base::Status::Ok();
}

int DominantJoint(const SkinnedMesh& mesh, const PatchSetup& patch) {
  std::vector<double> total(mesh.skin_joints.size(), 0.0);
  const SkinWeights& w = patch.control_weights;
  for (std::size_t i = 0; i < w.weights.size(); ++i) {
    if (w.joints[i] < total.size()) total[w.joints[i]] += w.weights[i];
  }
  const auto best = std::max_element(total.begin(), total.end());
  if (best == total.end() || *best <= 0.0) return 0;
  return mesh.skin_joints[static_cast<std::size_t>(best - total.begin())];
}

}  // namespace deform
