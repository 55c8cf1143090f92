#pragma once
// Readers for what `patchskin export` writes, written independently of the
// writers: an OBJ parser (v / vn / f lines) and a glb evaluator that loads the
// file with tinygltf and evaluates its animation at a time the way a viewer
// does (node scale channels, morph weights channels, LINEAR or STEP samplers).
// Test-only; header-only (tinygltf's implementation is in libtinygltf.so).

#include <tiny_gltf.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace testsupport {

struct ParsedObj {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::uvec3> triangles;      // 0-based
  std::vector<glm::uvec3> normal_indices; // 0-based, when faces are "a//n"
  std::string error;                      // non-empty when parsing failed
};

inline ParsedObj ParseObjFile(const std::string& path) {
  ParsedObj r;
  std::ifstream in(path);
  if (!in) {
    r.error = "cannot open " + path;
    return r;
  }
  auto read_float = [](const std::string& tok, float& out) {
    const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), out);
    return res.ec == std::errc() && res.ptr == tok.data() + tok.size();
  };
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#' || tag == "o") continue;
    if (tag == "v" || tag == "vn") {
      glm::vec3 v;
      std::string tok;
      for (int c = 0; c < 3; ++c) {
        if (!(ls >> tok) || !read_float(tok, v[c])) {
          r.error = path + ":" + std::to_string(line_no) + ": bad number";
          return r;
        }
      }
      (tag == "v" ? r.positions : r.normals).push_back(v);
    } else if (tag == "f") {
      glm::uvec3 tri, nrm{0};
      bool has_normals = false;
      for (int c = 0; c < 3; ++c) {
        std::string tok;
        if (!(ls >> tok)) {
          r.error = path + ":" + std::to_string(line_no) + ": short face";
          return r;
        }
        const std::size_t slash = tok.find("//");
        tri[c] = static_cast<unsigned>(std::stoul(tok.substr(0, slash))) - 1;
        if (slash != std::string::npos) {
          nrm[c] = static_cast<unsigned>(std::stoul(tok.substr(slash + 2))) - 1;
          has_normals = true;
        }
      }
      r.triangles.push_back(tri);
      if (has_normals) r.normal_indices.push_back(nrm);
    } else {
      r.error = path + ":" + std::to_string(line_no) + ": unexpected '" + tag + "'";
      return r;
    }
  }
  return r;
}

// Floats of an accessor (tightly packed views only, as the exporter writes).
inline std::vector<float> GlbFloats(const tinygltf::Model& m, int accessor) {
  const tinygltf::Accessor& a = m.accessors[static_cast<std::size_t>(accessor)];
  const std::size_t n = a.count * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(
                                      static_cast<std::uint32_t>(a.type)));
  std::vector<float> out(n, 0.0f);
  if (a.bufferView < 0) return out;  // no buffer view: zeros (glTF 2.0, "Accessors")
  const tinygltf::BufferView& v = m.bufferViews[static_cast<std::size_t>(a.bufferView)];
  const tinygltf::Buffer& b = m.buffers[static_cast<std::size_t>(v.buffer)];
  std::memcpy(out.data(), b.data.data() + v.byteOffset + a.byteOffset, n * sizeof(float));
  return out;
}

inline std::vector<glm::vec3> GlbVec3(const tinygltf::Model& m, int accessor) {
  const std::vector<float> f = GlbFloats(m, accessor);
  std::vector<glm::vec3> out(f.size() / 3);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
  return out;
}

// Value (width floats) of a sampler at time t; times compared in float, as
// the file stores them.
inline std::vector<float> SampleGlbSampler(const tinygltf::Model& m,
                                           const tinygltf::AnimationSampler& s, int width,
                                           double t) {
  const std::vector<float> times = GlbFloats(m, s.input);
  const std::vector<float> values = GlbFloats(m, s.output);
  const auto w = static_cast<std::size_t>(width);
  const float tf = static_cast<float>(t);
  auto key = [&](std::size_t k) {
    return std::vector<float>(values.begin() + static_cast<std::ptrdiff_t>(k * w),
                              values.begin() + static_cast<std::ptrdiff_t>((k + 1) * w));
  };
  if (tf <= times.front()) return key(0);
  if (tf >= times.back()) return key(times.size() - 1);
  std::size_t k = 0;
  while (k + 1 < times.size() && times[k + 1] <= tf) ++k;
  if (s.interpolation == "STEP") return key(k);
  const float u = (tf - times[k]) / (times[k + 1] - times[k]);
  std::vector<float> a = key(k), b = key(k + 1);
  for (std::size_t i = 0; i < w; ++i) a[i] = a[i] + u * (b[i] - a[i]);
  return a;
}

struct GlbFrame {
  std::vector<glm::vec3> positions;  // of the visible mesh, morphs applied
  std::vector<glm::vec3> normals;    // same, not renormalized
  int visible_meshes = 0;            // meshes whose node scale is non-zero
};

// Evaluates the file's first animation at time t.
inline GlbFrame EvaluateGlb(const tinygltf::Model& m, double t) {
  GlbFrame out;
  const tinygltf::Animation* anim = m.animations.empty() ? nullptr : &m.animations[0];
  auto channel = [&](int node, const std::string& path) -> const tinygltf::AnimationSampler* {
    if (!anim) return nullptr;
    for (const tinygltf::AnimationChannel& c : anim->channels) {
      if (c.target_node == node && c.target_path == path) {
        return &anim->samplers[static_cast<std::size_t>(c.sampler)];
      }
    }
    return nullptr;
  };
  std::vector<std::pair<int, float>> stack;  // node, parent scale
  for (int n : m.scenes[0].nodes) stack.push_back({n, 1.0f});
  while (!stack.empty()) {
    const auto [n, parent_scale] = stack.back();
    stack.pop_back();
    const tinygltf::Node& node = m.nodes[static_cast<std::size_t>(n)];
    float scale = node.scale.empty() ? 1.0f : static_cast<float>(node.scale[0]);
    if (const auto* s = channel(n, "scale")) scale = SampleGlbSampler(m, *s, 3, t)[0];
    scale *= parent_scale;
    for (int c : node.children) stack.push_back({c, scale});
    if (node.mesh < 0 || scale == 0.0f) continue;
    ++out.visible_meshes;
    const tinygltf::Mesh& mesh = m.meshes[static_cast<std::size_t>(node.mesh)];
    const tinygltf::Primitive& prim = mesh.primitives[0];
    out.positions = GlbVec3(m, prim.attributes.at("POSITION"));
    out.normals = GlbVec3(m, prim.attributes.at("NORMAL"));
    std::vector<float> weights(mesh.weights.begin(), mesh.weights.end());
    if (const auto* s = channel(n, "weights")) {
      weights = SampleGlbSampler(m, *s, static_cast<int>(prim.targets.size()), t);
    }
    for (std::size_t k = 0; k < prim.targets.size(); ++k) {
      if (weights[k] == 0.0f) continue;
      const std::vector<glm::vec3> dp = GlbVec3(m, prim.targets[k].at("POSITION"));
      const std::vector<glm::vec3> dn = GlbVec3(m, prim.targets[k].at("NORMAL"));
      for (std::size_t i = 0; i < dp.size(); ++i) {
        out.positions[i] += weights[k] * dp[i];
        out.normals[i] += weights[k] * dn[i];
      }
    }
  }
  return out;
}

inline bool LoadGlb(const std::string& path, tinygltf::Model& model, std::string& message) {
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool ok = loader.LoadBinaryFromFile(&model, &err, &warn, path);
  message = err + warn;
  return ok && err.empty();
}

}  // namespace testsupport
