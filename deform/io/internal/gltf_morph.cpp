#include "deform/io/internal/gltf_morph.h"

#include <tiny_gltf.h>

#include <cmath>
#include <limits>

#include "deform/io/internal/gltf_view.h"

namespace deform::internal {
namespace {

using base::ErrorCode;
using base::Result;

}  // namespace

Result<PrimitiveTargets> ReadPrimitiveTargets(const tinygltf::Model& m, const std::string& path,
                                              int mesh, int prim, std::size_t num_vertices,
                                              std::size_t max_values,
                                              std::vector<base::Warning>& warnings) {
  const tinygltf::Primitive& p =
      m.meshes[static_cast<std::size_t>(mesh)].primitives[static_cast<std::size_t>(prim)];
  const std::string at = Indexed("meshes", mesh) + ".primitives[" + std::to_string(prim) + "].targets";
  PrimitiveTargets out;
  if (p.targets.empty()) return out;
  const std::size_t k_count = p.targets.size();
  if (num_vertices != 0 && k_count > max_values / num_vertices) {
    return GltfError(path, ErrorCode::kLimitExceeded, at,
                     std::to_string(k_count) + " targets x " + std::to_string(num_vertices) +
                         " vertices exceed the limit of " + std::to_string(max_values) +
                         " morph deltas");
  }
  out.num_targets = static_cast<int>(k_count);
  out.positions.assign(k_count * num_vertices, glm::vec3(0.0f));
  for (std::size_t k = 0; k < k_count; ++k) {
    const std::string tat = at + "[" + std::to_string(k) + "]";
    for (const auto& [name, accessor] : p.targets[k]) {
      if (name != "POSITION" && name != "NORMAL") {
        warnings.push_back({{path, 0, 0, tat + "." + name}, "morph attribute not imported"});
        continue;
      }
      const std::string field = tat + "." + name;
      if (accessor >= 0 && accessor < static_cast<int>(m.accessors.size()) &&
          m.accessors[static_cast<std::size_t>(accessor)].count != num_vertices) {
        return GltfError(path, ErrorCode::kCountMismatch, Indexed("accessors", accessor) + ".count",
                         "expected " + std::to_string(num_vertices) + " (the POSITION count) for " +
                             field + ", found " +
                             std::to_string(m.accessors[static_cast<std::size_t>(accessor)].count));
      }
      auto values = ReadFloatsAllowingSparse(m, path, accessor, field, TINYGLTF_TYPE_VEC3,
                                             {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
      if (!values.ok()) return std::move(values).error();
      std::vector<glm::vec3>& dst = name == "POSITION" ? out.positions : out.normals;
      if (dst.empty()) dst.assign(k_count * num_vertices, glm::vec3(0.0f));  // first NORMAL seen
      for (std::size_t v = 0; v < num_vertices; ++v) {
        dst[k * num_vertices + v] = {(*values)[3 * v], (*values)[3 * v + 1], (*values)[3 * v + 2]};
      }
    }
  }
  return out;
}

Result<std::vector<float>> ReadDefaultWeights(const tinygltf::Model& m, const std::string& path, int mesh,
                                              int num_targets) {
  const std::vector<double>& w = m.meshes[static_cast<std::size_t>(mesh)].weights;
  const std::string at = Indexed("meshes", mesh) + ".weights";
  std::vector<float> out(static_cast<std::size_t>(num_targets), 0.0f);
  if (w.empty()) return out;
  if (w.size() != out.size()) {
    return GltfError(path, ErrorCode::kCountMismatch, at,
                     "expected " + std::to_string(num_targets) +
                         " weights (one per morph target), found " + std::to_string(w.size()));
  }
  for (std::size_t k = 0; k < w.size(); ++k) {
    if (!(std::abs(w[k]) <= std::numeric_limits<float>::max())) {
      return GltfError(path, ErrorCode::kNonFinite, at,
                       "weight " + std::to_string(k) + " is not finite");
    }
    out[k] = static_cast<float>(w[k]);
  }
  return out;
}

Result<GltfWeightsChannel> ReadWeightsSampler(const tinygltf::Model& m, const std::string& path,
                                              int animation, int sampler, int num_targets) {
  const tinygltf::AnimationSampler& s =
      m.animations[static_cast<std::size_t>(animation)].samplers[static_cast<std::size_t>(sampler)];
  const std::string sat = Indexed("animations", animation) + ".samplers[" + std::to_string(sampler) + "]";
  GltfWeightsChannel out;
  out.num_targets = num_targets;
  if (s.interpolation == "LINEAR" || s.interpolation.empty()) {
    out.interpolation = GltfInterpolation::kLinear;
  } else if (s.interpolation == "STEP") {
    out.interpolation = GltfInterpolation::kStep;
  } else if (s.interpolation == "CUBICSPLINE") {
    out.interpolation = GltfInterpolation::kCubicSpline;
  } else {
    return GltfError(path, ErrorCode::kUnsupported, sat + ".interpolation",
                     "unknown interpolation '" + s.interpolation + "'");
  }
  auto in_view = CheckedView(m, path, s.input, sat + ".input", TINYGLTF_TYPE_SCALAR,
                             {TINYGLTF_COMPONENT_TYPE_FLOAT});
  if (!in_view.ok()) return std::move(in_view).error();
  auto out_view = CheckedView(m, path, s.output, sat + ".output", TINYGLTF_TYPE_SCALAR,
                              {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
  if (!out_view.ok()) return std::move(out_view).error();
  const std::size_t keys = in_view->count;
  const std::size_t per_key =
      (out.interpolation == GltfInterpolation::kCubicSpline ? 3 : 1) * static_cast<std::size_t>(num_targets);
  if (keys == 0)
    return GltfError(path, ErrorCode::kCountMismatch, Indexed("accessors", s.input) + ".count",
                     "no keys");
  if (out_view->count / per_key != keys || out_view->count % per_key != 0) {
    return GltfError(path, ErrorCode::kCountMismatch, Indexed("accessors", s.output) + ".count",
                     "expected " + std::to_string(keys) + " keys x " + std::to_string(per_key) +
                         " weights = " + std::to_string(keys * per_key) + " outputs, found " +
                         std::to_string(out_view->count));
  }
  auto times = ReadFloats(*in_view, false, path);
  if (!times.ok()) return std::move(times).error();
  for (std::size_t k = 0; k < keys; ++k) {
    if ((*times)[k] < 0.0f || (k > 0 && (*times)[k] < (*times)[k - 1])) {
      return GltfError(path, ErrorCode::kBadNumber, Indexed("accessors", s.input),
                       "key times must be >= 0 and non-decreasing; element " + std::to_string(k) +
                           " is " + std::to_string((*times)[k]));
    }
  }
  auto values = ReadFloats(*out_view, true, path);
  if (!values.ok()) return std::move(values).error();
  out.times_s = std::move(times).value();
  out.values = std::move(values).value();
  return out;
}

}  // namespace deform::internal
