// glTF import: the only file that sees tinygltf. tinygltf parses the JSON and
// the buffers; everything we use from its Model is checked here (indices,
// accessor bounds, component types, counts, finite values) before it is read,
// because tinygltf itself only partly validates.
//
// Debian's libtinygltf.so already holds the implementation (and links libstb
// for images), so TINYGLTF_IMPLEMENTATION is not defined here.

#include "deform/io/gltf_import.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <span>

#include "deform/io/internal/gltf_accessor.h"
#include "deform/io/internal/gltf_build.h"
#include "deform/io/internal/gltf_files.h"
#include "deform/io/internal/gltf_material.h"
#include "deform/io/internal/gltf_morph.h"
#include "deform/io/internal/gltf_view.h"

namespace deform {
namespace {

namespace fs = std::filesystem;
using base::ErrorCode;
using base::Result;
using internal::AccessorView;
using internal::ComponentBytes;
using internal::InsideFolder;
using internal::ReadFileBounded;

// ---------------------------------------------------------------------------
// Files and URIs.

struct FsContext {
  fs::path folder;
  std::size_t max_bytes = 0;
  std::string rejected;  // the last path refused for leaving the folder
};

bool ConfinedFileExists(const std::string& path, void* user) {
  auto* ctx = static_cast<FsContext*>(user);
  std::error_code ec;
  if (!InsideFolder(ctx->folder, path)) {
    // tinygltf also tries a missing file's name in other folders (the working
    // one): only a file that is there is a refusal, a missing one stays missing.
    if (fs::exists(path, ec)) ctx->rejected = path;
    return false;
  }
  return fs::is_regular_file(path, ec);
}

std::string NoExpand(const std::string& path, void*) { return path; }

bool ConfinedReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                           void* user) {
  auto* ctx = static_cast<FsContext*>(user);
  if (!InsideFolder(ctx->folder, path)) {
    ctx->rejected = path;
    if (err) *err += "refused to read '" + path + "': outside the model's folder\n";
    return false;
  }
  auto bytes = ReadFileBounded(path, ctx->max_bytes);
  if (!bytes.ok()) {
    if (err) *err += bytes.error().ToString() + "\n";
    return false;
  }
  *out = std::move(bytes).value();
  return true;
}

bool RefuseWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is disabled\n";
  return false;
}

// Keeps the bytes of data: URI and file images undecoded (GltfMaterialReader
// decodes the ones a material uses, with OpenImageIO). Buffer-view images are
// read later from the buffer, after checking the view's bounds.
bool CaptureImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                  const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && bytes != nullptr && size > 0) image->image.assign(bytes, bytes + size);
  return true;
}

void AddLines(const std::string& path, const std::string& text, std::vector<base::Warning>& out) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (!line.empty()) out.push_back({base::FileLoc{path, 0, 0, {}}, "tinygltf: " + line});
  }
}

std::string FirstLines(const std::string& text) {
  std::string out = text;
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  std::replace(out.begin(), out.end(), '\n', ';');
  return out;
}

// ---------------------------------------------------------------------------
// Accessors (checked in internal/gltf_view.cpp).

using internal::Indexed;

class Converter {
 public:
  Converter(const tinygltf::Model& model, const std::string& path)
      : m_(model), path_(path), materials_(model, path) {}

  base::Error Fail(ErrorCode code, std::string field, std::string message) const {
    return base::MakeError(code, {path_, 0, 0, std::move(field)}, std::move(message));
  }

  // `user` names the field holding the index, e.g. "skins[0].inverseBindMatrices".
  Result<AccessorView> View(int index, const std::string& user, int type,
                            std::initializer_list<int> component_types) const {
    return internal::CheckedView(m_, path_, index, user, type, component_types);
  }

  Result<std::vector<float>> Floats(const AccessorView& v, bool normalize) const {
    return internal::ReadFloats(v, normalize, path_);
  }
  Result<std::vector<std::uint32_t>> Uints(const AccessorView& v, std::uint64_t limit,
                                           const std::string& what) const {
    return internal::ReadUints(v, limit, what, path_);
  }

  Result<GltfModel> Run(const GltfReadOptions& options, std::vector<base::Warning> warnings);

 private:
  base::Status BuildSkeleton(int skin);
  base::Status ReadSkin(int skin);
  base::Status ReadMeshes(int skin);
  Result<glm::mat4> RestWorld(int node) const;
  base::Status ReadPrimitive(int mesh, int prim, int skin, int rigid_slot, bool& computed_normals);
  base::Status MergeMorphTargets(std::size_t num_vertices);
  base::Status ReadAnimations();
  void Warn(std::string field, std::string message) {
    out_.warnings.push_back({{path_, 0, 0, std::move(field)}, std::move(message)});
  }

  const tinygltf::Model& m_;
  std::string path_;
  GltfModel out_;
  std::vector<int> parent_;      // node -> parent node or -1
  std::vector<int> node_joint_;  // node -> skeleton joint or -1
  std::vector<int> joint_node_;  // skeleton joint -> node
  // No skin (GltfReadOptions::require_skin false): the mesh nodes, each a
  // "skin joint" its vertices are rigidly attached to.
  std::vector<int> rigid_nodes_;
  GltfReadOptions options_;
  // Per primitive before merging, so weights can be widened to 8 later.
  struct Part {
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::uvec3> triangles;
    std::vector<std::uint32_t> joints;  // #V x influences
    std::vector<float> weights;         // #V x influences
    int influences = 4;
    int mesh = -1;                      // the glTF mesh it came from
    internal::PrimitiveTargets targets;
    std::vector<glm::vec3> colors;      // #V linear albedo, or empty: the file gives none
    std::vector<glm::vec2> uvs;         // #V TEXCOORD_0, or empty
    // Per triangle, an index into out_.mesh.materials.materials or -1.
    std::vector<std::int32_t> triangle_material;
    // The albedo of a vertex without colours: white under a texture, else grey.
    glm::vec3 fill_color{0.0f};
    int prim = -1;  // the first glTF primitive read into it
  };
  // Primitives of one mesh with the same vertex accessors (an exporter's one
  // primitive per material) share their vertices instead of copying them.
  bool SharesVertices(const Part& into, const Part& from) const;
  static void MergeSharedPrimitive(Part& into, Part& from);
  static void AppendVertexCopies(Part& part, std::span<const std::uint32_t> sources);
  base::Status ReadMaterial(const tinygltf::Primitive& p, const std::string& at, bool has_uvs,
                            int& material_out);
  internal::GltfMaterialReader materials_;
  std::vector<int> material_slot_;  // 2 x file material + has TEXCOORD_0 -> out index, -1 not yet
  std::vector<Part> parts_;
  template <typename VertexView>
  base::Status ReadColors(const tinygltf::Primitive& p, int color_index,
                          const VertexView& vertex_view, Part& part);
  std::vector<int> mesh_first_target_;  // glTF mesh -> its first row in out_.morph, or -1
  std::vector<int> mesh_num_targets_;   // glTF mesh -> its target count, -1 when not imported
};

// Rest TRS of a node; a matrix is decomposed (shear dropped with a warning).
Result<mocap::JointTransform> NodeTransform(const tinygltf::Node& n, const std::string& at,
                                            const Converter& cv, bool& dropped_shear) {
  mocap::JointTransform t;
  auto finite = [](const std::vector<double>& v) {
    // Finite after conversion to float too: runtime math is in float.
    return std::all_of(v.begin(), v.end(),
                       [](double x) { return std::abs(x) <= std::numeric_limits<float>::max(); });
  };
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16 || !finite(n.matrix)) {
      return cv.Fail(ErrorCode::kNonFinite, at + ".matrix", "expected 16 finite numbers");
    }
    glm::dmat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[static_cast<std::size_t>(c * 4 + r)];
    return internal::DecomposeMatrix(m, &dropped_shear);
  }
  if (!finite(n.translation) || !finite(n.rotation) || !finite(n.scale)) {
    return cv.Fail(ErrorCode::kNonFinite, at, "non-finite translation, rotation or scale");
  }
  if (n.translation.size() == 3)
    t.translation = glm::vec3(glm::dvec3(n.translation[0], n.translation[1], n.translation[2]));
  if (n.scale.size() == 3) t.scale = glm::vec3(glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
  if (n.rotation.size() == 4) {
    const glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
    if (glm::length(q) < 1e-6) return cv.Fail(ErrorCode::kNonFinite, at + ".rotation", "zero quaternion");
    t.rotation = glm::quat(glm::normalize(q));
  }
  return t;
}

base::Status Converter::BuildSkeleton(int skin) {
  const auto num_nodes = static_cast<int>(m_.nodes.size());
  std::vector<int> parent(static_cast<std::size_t>(num_nodes), -1);
  for (int n = 0; n < num_nodes; ++n) {
    for (int c : m_.nodes[static_cast<std::size_t>(n)].children) {
      const std::string at = Indexed("nodes", n) + ".children";
      if (c < 0 || c >= num_nodes)
        return Fail(ErrorCode::kNotFound, at, "child " + std::to_string(c) + " out of range");
      if (c == n || parent[static_cast<std::size_t>(c)] != -1) {
        return Fail(ErrorCode::kSyntax, at,
                    "node " + std::to_string(c) + " has more than one parent (or is its own)");
      }
      parent[static_cast<std::size_t>(c)] = n;
    }
  }
  parent_ = parent;
  // The nodes the skeleton must reach: the skin's joints, or (no skin) the mesh nodes.
  std::vector<int> leaves;
  if (skin >= 0) {
    leaves = m_.skins[static_cast<std::size_t>(skin)].joints;
  } else {
    for (int n = 0; n < num_nodes; ++n) {
      const tinygltf::Node& node = m_.nodes[static_cast<std::size_t>(n)];
      if (node.mesh >= 0 && node.skin < 0) rigid_nodes_.push_back(n);
    }
    if (rigid_nodes_.empty()) return Fail(ErrorCode::kNotFound, "nodes", "no node holds a mesh");
    leaves = rigid_nodes_;
  }
  std::vector<char> needed(static_cast<std::size_t>(num_nodes), 0);
  for (std::size_t k = 0; k < leaves.size(); ++k) {
    int n = leaves[k];
    if (n < 0 || n >= num_nodes) {
      return Fail(ErrorCode::kNotFound, Indexed("skins", skin) + ".joints[" + std::to_string(k) + "]",
                  "node " + std::to_string(n) + " out of range");
    }
    for (int steps = 0; n != -1; n = parent[static_cast<std::size_t>(n)], ++steps) {
      if (steps > num_nodes) return Fail(ErrorCode::kSyntax, "nodes", "the node hierarchy has a cycle");
      needed[static_cast<std::size_t>(n)] = 1;
    }
  }
  mocap::Skeleton& sk = out_.skeleton;
  node_joint_.assign(static_cast<std::size_t>(num_nodes), -1);
  std::vector<int> stack;
  for (int r = num_nodes - 1; r >= 0; --r)
    if (parent[static_cast<std::size_t>(r)] == -1 && needed[static_cast<std::size_t>(r)]) stack.push_back(r);
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    if (static_cast<int>(joint_node_.size()) >= mocap::kMaxJoints) {
      return Fail(ErrorCode::kLimitExceeded, "nodes",
                  "more than " + std::to_string(mocap::kMaxJoints) + " joints");
    }
    const tinygltf::Node& node = m_.nodes[static_cast<std::size_t>(n)];
    bool dropped_shear = false;
    auto rest = NodeTransform(node, Indexed("nodes", n), *this, dropped_shear);
    if (!rest.ok()) return std::move(rest).error();
    if (dropped_shear) {
      Warn(Indexed("nodes", n) + ".matrix",
           "shear dropped when decomposing into translation, rotation, scale");
    }
    std::string name = node.name.empty() ? "node_" + std::to_string(n) : node.name;
    if (sk.FindJoint(name) >= 0) name += "_" + std::to_string(n);  // names must be unique
    sk.names.push_back(name);
    node_joint_[static_cast<std::size_t>(n)] = static_cast<int>(joint_node_.size());
    joint_node_.push_back(n);
    const int p = parent[static_cast<std::size_t>(n)];
    sk.parents.push_back(
        static_cast<std::int16_t>(p == -1 ? mocap::kNoParent : node_joint_[static_cast<std::size_t>(p)]));
    sk.rest_translations.push_back(rest->translation);
    sk.rest_rotations.push_back(rest->rotation);
    sk.rest_scales.push_back(rest->scale);
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
      if (needed[static_cast<std::size_t>(*it)]) stack.push_back(*it);
  }
  sk.info.source_file = path_;
  sk.info.detected_units = std::string("m");  // = "m" trips GCC 12 -Wrestrict
  for (int j : leaves) out_.mesh.skin_joints.push_back(node_joint_[static_cast<std::size_t>(j)]);
  return base::Status::Ok();
}

base::Status Converter::ReadSkin(int skin) {
  if (skin < 0) {  // rigid attachment: bind space is each mesh's own space
    out_.mesh.joint_from_bind.assign(rigid_nodes_.size(), glm::mat4(1.0f));
    return base::Status::Ok();
  }
  const tinygltf::Skin& s = m_.skins[static_cast<std::size_t>(skin)];
  const std::size_t n = s.joints.size();
  out_.mesh.joint_from_bind.assign(n, glm::mat4(1.0f));
  if (s.inverseBindMatrices < 0) return base::Status::Ok();
  const std::string at = Indexed("skins", skin) + ".inverseBindMatrices";
  auto view = View(s.inverseBindMatrices, at, TINYGLTF_TYPE_MAT4, {TINYGLTF_COMPONENT_TYPE_FLOAT});
  if (!view.ok()) return std::move(view).error();
  if (view->count < n) {
    return Fail(ErrorCode::kCountMismatch, Indexed("accessors", s.inverseBindMatrices) + ".count",
                "expected at least " + std::to_string(n) + " matrices (one per skin joint), found " +
                    std::to_string(view->count));
  }
  auto values = Floats(*view, false);
  if (!values.ok()) return std::move(values).error();
  for (std::size_t k = 0; k < n; ++k)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        out_.mesh.joint_from_bind[k][c][r] = (*values)[k * 16 + static_cast<std::size_t>(c * 4 + r)];
  return base::Status::Ok();
}

base::Status Converter::ReadPrimitive(int mesh, int prim, int skin, int rigid_slot,
                                      bool& computed_normals) {
  const tinygltf::Primitive& p =
      m_.meshes[static_cast<std::size_t>(mesh)].primitives[static_cast<std::size_t>(prim)];
  const std::string at = Indexed("meshes", mesh) + ".primitives[" + std::to_string(prim) + "]";
  if (p.mode != TINYGLTF_MODE_TRIANGLES) {
    Warn(at + ".mode", "only triangle lists are imported; primitive skipped");
    return base::Status::Ok();
  }
  auto attribute = [&](const char* name) {
    const auto it = p.attributes.find(name);
    return it == p.attributes.end() ? -1 : it->second;
  };
  const int position_index = attribute("POSITION");
  if (position_index < 0) return Fail(ErrorCode::kNotFound, at + ".attributes.POSITION", "missing");
  auto pos_view =
      View(position_index, at + ".attributes.POSITION", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
  if (!pos_view.ok()) return std::move(pos_view).error();
  const std::size_t num_vertices = pos_view->count;
  if (num_vertices >= std::numeric_limits<std::uint32_t>::max()) {
    return Fail(ErrorCode::kLimitExceeded, Indexed("accessors", position_index) + ".count",
                "too many vertices");
  }
  // An attribute accessor with exactly one element per vertex.
  auto vertex_view = [&](int index, const std::string& name, int type,
                         std::initializer_list<int> types) -> Result<AccessorView> {
    auto v = View(index, at + ".attributes." + name, type, types);
    if (v.ok() && v->count != num_vertices) {
      return Fail(ErrorCode::kCountMismatch, Indexed("accessors", index) + ".count",
                  "expected " + std::to_string(num_vertices) + " (the POSITION count) for " + name +
                      ", found " + std::to_string(v->count));
    }
    return v;
  };
  Part part;
  auto positions = Floats(*pos_view, false);
  if (!positions.ok()) return std::move(positions).error();
  part.positions.resize(num_vertices);
  for (std::size_t v = 0; v < num_vertices; ++v) {
    part.positions[v] = glm::vec3((*positions)[3 * v], (*positions)[3 * v + 1], (*positions)[3 * v + 2]);
  }

  part.mesh = mesh;
  auto targets = internal::ReadPrimitiveTargets(m_, path_, mesh, prim, num_vertices,
                                                options_.max_morph_values, out_.warnings);
  if (!targets.ok()) return std::move(targets).error();
  part.targets = std::move(targets).value();

  const std::uint64_t num_skin_joints = skin >= 0 ? m_.skins[static_cast<std::size_t>(skin)].joints.size() : 0;
  const int sets = skin < 0 ? 0 : attribute("JOINTS_1") >= 0 || attribute("WEIGHTS_1") >= 0 ? 2 : 1;
  part.influences = 4 * std::max(sets, 1);
  part.joints.assign(num_vertices * static_cast<std::size_t>(part.influences), 0);
  part.weights.assign(num_vertices * static_cast<std::size_t>(part.influences), 0.0f);
  if (skin < 0) {  // rigid: every vertex follows its node, weight 1 in slot 0
    for (std::size_t v = 0; v < num_vertices; ++v) {
      part.joints[v * 4] = static_cast<std::uint32_t>(rigid_slot);
      part.weights[v * 4] = 1.0f;
    }
  }
  for (int set = 0; set < sets; ++set) {
    const std::string jname = "JOINTS_" + std::to_string(set);
    const std::string wname = "WEIGHTS_" + std::to_string(set);
    const int ji = attribute(jname.c_str());
    const int wi = attribute(wname.c_str());
    if (ji < 0)
      return Fail(ErrorCode::kNotFound, at + ".attributes." + jname, "missing (needed by a skinned mesh)");
    if (wi < 0)
      return Fail(ErrorCode::kNotFound, at + ".attributes." + wname, "missing (needed by a skinned mesh)");
    auto jv = vertex_view(ji, jname, TINYGLTF_TYPE_VEC4,
                          {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (!jv.ok()) return std::move(jv).error();
    auto wv = vertex_view(wi, wname, TINYGLTF_TYPE_VEC4,
                          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (!wv.ok()) return std::move(wv).error();
    auto joints = Uints(*jv, num_skin_joints, "joint index");
    if (!joints.ok()) return std::move(joints).error();
    auto weights = Floats(*wv, true);
    if (!weights.ok()) return std::move(weights).error();
    for (std::size_t v = 0; v < num_vertices; ++v) {
      for (std::size_t k = 0; k < 4; ++k) {
        const float w = (*weights)[v * 4 + k];
        if (w < -1e-6f) {
          return Fail(ErrorCode::kBadNumber, Indexed("accessors", wi),
                      "negative weight " + std::to_string(w) + " at vertex " + std::to_string(v));
        }
        const std::size_t slot =
            v * static_cast<std::size_t>(part.influences) + static_cast<std::size_t>(set * 4) + k;
        part.joints[slot] = (*joints)[v * 4 + k];
        part.weights[slot] = std::max(w, 0.0f);
      }
    }
  }
  const int unweighted = internal::NormalizeWeightRows(part.weights, part.influences);
  if (unweighted > 0) {
    Warn(at + ".attributes.WEIGHTS_0",
         std::to_string(unweighted) + " vertices have zero total weight; bound to their first joint");
  }

  const int index_accessor = p.indices;
  std::vector<std::uint32_t> indices;
  if (index_accessor >= 0) {
    auto iv = View(index_accessor, at + ".indices", TINYGLTF_TYPE_SCALAR,
                   {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
    if (!iv.ok()) return std::move(iv).error();
    auto read = Uints(*iv, num_vertices, "index");
    if (!read.ok()) return std::move(read).error();
    indices = std::move(read).value();
  } else {
    indices.resize(num_vertices);
    for (std::size_t i = 0; i < num_vertices; ++i) indices[i] = static_cast<std::uint32_t>(i);
  }
  if (indices.size() % 3 != 0) {
    return Fail(
        ErrorCode::kCountMismatch,
        index_accessor >= 0 ? Indexed("accessors", index_accessor) + ".count" : at + ".attributes.POSITION",
        "a triangle list needs a multiple of 3 indices, found " + std::to_string(indices.size()));
  }
  for (std::size_t i = 0; i < indices.size(); i += 3)
    part.triangles.emplace_back(indices[i], indices[i + 1], indices[i + 2]);

  const int normal_index = attribute("NORMAL");
  part.normals.resize(num_vertices);
  if (normal_index >= 0) {
    auto nv = vertex_view(normal_index, "NORMAL", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
    if (!nv.ok()) return std::move(nv).error();
    auto normals = Floats(*nv, false);
    if (!normals.ok()) return std::move(normals).error();
    for (std::size_t v = 0; v < num_vertices; ++v) {
      const glm::vec3 n((*normals)[v * 3], (*normals)[v * 3 + 1], (*normals)[v * 3 + 2]);
      const float len = glm::length(n);
      part.normals[v] = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
    }
  } else {
    ComputeVertexNormals(part.positions, part.triangles, part.normals);
    computed_normals = true;
  }
  if (auto st = ReadColors(p, attribute("COLOR_0"), vertex_view, part); !st) return st;
  if (const int uv_index = attribute("TEXCOORD_0"); uv_index >= 0) {
    auto view = vertex_view(uv_index, "TEXCOORD_0", TINYGLTF_TYPE_VEC2,
                            {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (!view.ok()) return std::move(view).error();
    if (view->component_type != TINYGLTF_COMPONENT_TYPE_FLOAT &&
        !m_.accessors[static_cast<std::size_t>(uv_index)].normalized) {
      return Fail(ErrorCode::kUnsupported, Indexed("accessors", uv_index) + ".normalized",
                  "integer TEXCOORD_0 must be normalized (glTF 2.0, meshes)");
    }
    auto uvs = Floats(*view, true);
    if (!uvs.ok()) return std::move(uvs).error();
    part.uvs.resize(num_vertices);
    for (std::size_t v = 0; v < num_vertices; ++v) part.uvs[v] = glm::vec2((*uvs)[2 * v], (*uvs)[2 * v + 1]);
  }
  int material = -1;
  if (auto st = ReadMaterial(p, at, !part.uvs.empty(), material); !st) return st;
  part.triangle_material.assign(part.triangles.size(), material);
  const bool textured = material >= 0 &&
                        out_.mesh.materials.materials[static_cast<std::size_t>(material)].texture >= 0;
  part.fill_color = textured ? glm::vec3(1.0f) : kDefaultAlbedo;
  part.prim = prim;
  for (Part& earlier : parts_) {
    if (SharesVertices(earlier, part)) {
      MergeSharedPrimitive(earlier, part);
      return base::Status::Ok();
    }
  }
  parts_.push_back(std::move(part));
  return base::Status::Ok();
}

bool Converter::SharesVertices(const Part& into, const Part& from) const {
  if (into.mesh != from.mesh) return false;
  const auto& prims = m_.meshes[static_cast<std::size_t>(from.mesh)].primitives;
  const tinygltf::Primitive& a = prims[static_cast<std::size_t>(into.prim)];
  const tinygltf::Primitive& b = prims[static_cast<std::size_t>(from.prim)];
  // Computed normals depend on each primitive's own triangles: not shared.
  return a.attributes == b.attributes && a.targets == b.targets && a.attributes.count("NORMAL") != 0;
}

// Appends `from`'s triangles to `into`, which holds the same vertices. A vertex
// both use with different colours (two materials' factors) is copied, morph
// deltas included, so each corner keeps its material's albedo.
void Converter::MergeSharedPrimitive(Part& into, Part& from) {
  const std::size_t nv = into.positions.size();
  const auto colour = [](const Part& part, std::size_t v) {
    return part.colors.empty() ? part.fill_color : part.colors[v];
  };
  if (!(into.colors.empty() && from.colors.empty() && into.fill_color == from.fill_color)) {
    std::vector<std::uint8_t> used(nv, 0);
    for (const glm::uvec3& t : into.triangles) used[t.x] = used[t.y] = used[t.z] = 1;
    if (into.colors.empty()) into.colors.assign(nv, into.fill_color);
    std::vector<std::uint32_t> copies;  // source vertex of each copy, in order
    std::vector<std::uint32_t> copy_of(nv, std::numeric_limits<std::uint32_t>::max());
    for (glm::uvec3& t : from.triangles) {
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = t[c];
        const glm::vec3 want = colour(from, v);
        if (used[v] == 0) {  // only `from` uses it: its colour
          into.colors[v] = want;
          used[v] = 1;
        } else if (into.colors[v] != want) {
          if (copy_of[v] == std::numeric_limits<std::uint32_t>::max()) {
            copy_of[v] = static_cast<std::uint32_t>(nv + copies.size());
            copies.push_back(v);
            into.colors.push_back(want);
          }
          t[c] = copy_of[v];
        }
      }
    }
    AppendVertexCopies(into, copies);
  }
  into.triangles.insert(into.triangles.end(), from.triangles.begin(), from.triangles.end());
  into.triangle_material.insert(into.triangle_material.end(), from.triangle_material.begin(),
                                from.triangle_material.end());
}

// Appends copies of `sources` to every per-vertex array of `part` but its
// colours (set by the caller), morph deltas included.
void Converter::AppendVertexCopies(Part& part, std::span<const std::uint32_t> sources) {
  if (sources.empty()) return;
  const std::size_t nv = part.positions.size();
  const auto k = static_cast<std::size_t>(part.influences);
  for (const std::uint32_t v : sources) {
    part.positions.push_back(part.positions[v]);
    part.normals.push_back(part.normals[v]);
    if (!part.uvs.empty()) part.uvs.push_back(part.uvs[v]);
    for (std::size_t i = 0; i < k; ++i) {
      part.joints.push_back(part.joints[v * k + i]);
      part.weights.push_back(part.weights[v * k + i]);
    }
  }
  const auto widen = [&](std::vector<glm::vec3>& deltas) {  // #K x #V rows, each row grows
    if (deltas.empty()) return;
    std::vector<glm::vec3> out;
    out.reserve(static_cast<std::size_t>(part.targets.num_targets) * part.positions.size());
    for (std::size_t t = 0; t < static_cast<std::size_t>(part.targets.num_targets); ++t) {
      const auto row = deltas.begin() + static_cast<std::ptrdiff_t>(t * nv);
      out.insert(out.end(), row, row + static_cast<std::ptrdiff_t>(nv));
      for (const std::uint32_t v : sources) out.push_back(row[v]);
    }
    deltas = std::move(out);
  };
  widen(part.targets.positions);
  widen(part.targets.normals);
}

// The primitive's albedo: COLOR_0 (linear RGB, alpha dropped) times the material's
// baseColorFactor. A factor of all ones without COLOR_0 leaves the part without
// colours, so the renderer's grey stands in (tinygltf cannot tell an omitted factor
// from an explicit white one).
template <typename VertexView>
base::Status Converter::ReadColors(const tinygltf::Primitive& p, int color_index,
                                   const VertexView& vertex_view, Part& part) {
  glm::vec3 factor(1.0f);
  if (p.material >= 0 && p.material < static_cast<int>(m_.materials.size())) {
    const std::vector<double>& f =
        m_.materials[static_cast<std::size_t>(p.material)].pbrMetallicRoughness.baseColorFactor;
    if (f.size() >= 3) factor = glm::vec3(static_cast<float>(f[0]), static_cast<float>(f[1]), static_cast<float>(f[2]));
    if (!std::isfinite(factor.x) || !std::isfinite(factor.y) || !std::isfinite(factor.z)) {
      return Fail(ErrorCode::kNonFinite, Indexed("materials", p.material) + ".pbrMetallicRoughness.baseColorFactor",
                  "expected finite numbers");
    }
    factor = glm::clamp(factor, 0.0f, 1.0f);
  }
  const std::size_t n = part.positions.size();
  if (color_index < 0) {
    if (factor != glm::vec3(1.0f)) part.colors.assign(n, factor);
    return base::Status::Ok();
  }
  auto view = vertex_view(color_index, "COLOR_0", TINYGLTF_TYPE_VEC3,
                          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
  if (!view.ok()) {  // COLOR_0 may also be RGBA
    view = vertex_view(color_index, "COLOR_0", TINYGLTF_TYPE_VEC4,
                       {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                        TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
  }
  if (!view.ok()) return std::move(view).error();
  auto values = Floats(*view, true);
  if (!values.ok()) return std::move(values).error();
  const auto stride = static_cast<std::size_t>(view->components);
  part.colors.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    const glm::vec3 c((*values)[v * stride], (*values)[v * stride + 1], (*values)[v * stride + 2]);
    part.colors[v] = glm::clamp(c, 0.0f, 1.0f) * factor;
  }
  return base::Status::Ok();
}

// The primitive's material, imported once per file material (and per
// with/without TEXCOORD_0: a texture needs them).
base::Status Converter::ReadMaterial(const tinygltf::Primitive& p, const std::string& at,
                                     bool has_uvs, int& material_out) {
  if (p.material < 0) return base::Status::Ok();
  if (p.material < static_cast<int>(m_.materials.size())) {
    material_slot_.resize(2 * m_.materials.size(), -1);
    const int cached = material_slot_[static_cast<std::size_t>(2 * p.material + (has_uvs ? 1 : 0))];
    if (cached >= 0) {
      material_out = cached;
      return base::Status::Ok();
    }
  }
  auto material = materials_.Read(p.material, has_uvs, at, out_.warnings);
  if (!material.ok()) return std::move(material).error();
  MeshMaterials& out = out_.mesh.materials;
  material_out = static_cast<int>(out.materials.size());
  out.materials.push_back(std::move(material).value());
  material_slot_[static_cast<std::size_t>(2 * p.material + (has_uvs ? 1 : 0))] = material_out;
  return base::Status::Ok();
}

// Rest-pose model_from_node through the node's whole ancestor chain.
Result<glm::mat4> Converter::RestWorld(int node) const {
  glm::mat4 world(1.0f);
  int steps = 0;
  for (int n = node; n != -1; n = parent_[static_cast<std::size_t>(n)]) {
    if (++steps > static_cast<int>(m_.nodes.size()))
      return Fail(ErrorCode::kSyntax, "nodes", "the node hierarchy has a cycle");
    bool dropped_shear = false;
    auto local =
        NodeTransform(m_.nodes[static_cast<std::size_t>(n)], Indexed("nodes", n), *this, dropped_shear);
    if (!local.ok()) return std::move(local).error();
    world = local->ToMatrix() * world;
  }
  return world;
}

base::Status Converter::ReadMeshes(int skin) {
  std::vector<char> used(m_.meshes.size(), 0);
  bool computed_normals = false;
  for (std::size_t n = 0; n < m_.nodes.size(); ++n) {
    const tinygltf::Node& node = m_.nodes[n];
    if (node.mesh < 0) continue;
    const std::string at = Indexed("nodes", static_cast<int>(n));
    if (node.mesh >= static_cast<int>(m_.meshes.size())) {
      return Fail(ErrorCode::kNotFound, at + ".mesh", "mesh " + std::to_string(node.mesh) + " out of range");
    }
    if (node.skin != skin) {
      Warn(at, node.skin < 0 ? "mesh without a skin ignored" : "mesh bound to another skin ignored");
      continue;
    }
    if (used[static_cast<std::size_t>(node.mesh)]) {
      Warn(at + ".mesh", "mesh already imported through another node; not duplicated");
      continue;
    }
    used[static_cast<std::size_t>(node.mesh)] = 1;
    auto world = RestWorld(static_cast<int>(n));
    if (!world.ok()) return std::move(world).error();
    if (parts_.empty()) {
      out_.model_from_bind = *world;
    } else if (*world != out_.model_from_bind) {
      Warn(at, "skinned mesh nodes with different transforms; model_from_bind is the first one's");
    }
    const auto& prims = m_.meshes[static_cast<std::size_t>(node.mesh)].primitives;
    int rigid_slot = -1;
    if (skin < 0) {
      rigid_slot = static_cast<int>(std::find(rigid_nodes_.begin(), rigid_nodes_.end(), static_cast<int>(n)) -
                                    rigid_nodes_.begin());
    }
    for (std::size_t p = 0; p < prims.size(); ++p) {
      if (auto st = ReadPrimitive(node.mesh, static_cast<int>(p), skin, rigid_slot, computed_normals); !st) {
        return st;
      }
    }
  }
  if (parts_.empty()) {
    return Fail(ErrorCode::kNotFound, skin >= 0 ? Indexed("skins", skin) : std::string("meshes"),
                skin >= 0 ? "no triangle primitive of a node uses this skin" : "no triangle primitive");
  }
  if (computed_normals) Warn("", "some primitives have no NORMAL; normals were computed");
  int influences = 4;
  for (const Part& part : parts_) influences = std::max(influences, part.influences);
  std::size_t total_vertices = 0;
  for (const Part& part : parts_) total_vertices += part.positions.size();
  if (auto st = MergeMorphTargets(total_vertices); !st) return st;
  SkinnedMesh& mesh = out_.mesh;
  mesh.weights.influences = influences;
  // Colours for all vertices when any part has them; the others get the grey
  // the renderer uses for a mesh without colours.
  const bool any_colors =
      std::any_of(parts_.begin(), parts_.end(), [](const Part& part) { return !part.colors.empty(); });
  const bool any_uvs =
      std::any_of(parts_.begin(), parts_.end(), [](const Part& part) { return !part.uvs.empty(); });
  const bool any_material = std::any_of(parts_.begin(), parts_.end(), [](const Part& part) {
    return std::any_of(part.triangle_material.begin(), part.triangle_material.end(),
                       [](std::int32_t k) { return k >= 0; });
  });
  MeshMaterials& materials = mesh.materials;
  materials.images = std::move(materials_.images());
  for (const Part& part : parts_) {
    if (any_uvs) {
      if (part.uvs.empty()) {
        mesh.bind.uvs.insert(mesh.bind.uvs.end(), part.positions.size(), glm::vec2(0.0f));
      } else {
        mesh.bind.uvs.insert(mesh.bind.uvs.end(), part.uvs.begin(), part.uvs.end());
      }
    }
    if (any_material) {
      materials.triangle_material.insert(materials.triangle_material.end(), part.triangle_material.begin(),
                                         part.triangle_material.end());
    }
    if (any_colors) {
      if (part.colors.empty()) {
        // A textured part's albedo is its texture (times a white factor), not the grey.
        mesh.bind.colors.insert(mesh.bind.colors.end(), part.positions.size(), part.fill_color);
      } else {
        mesh.bind.colors.insert(mesh.bind.colors.end(), part.colors.begin(), part.colors.end());
      }
    }
    const auto base = static_cast<std::uint32_t>(mesh.bind.positions.size());
    if (part.positions.size() > std::numeric_limits<std::uint32_t>::max() - base) {
      return Fail(ErrorCode::kLimitExceeded, "meshes", "more than 2^32 vertices in total");
    }
    mesh.bind.positions.insert(mesh.bind.positions.end(), part.positions.begin(), part.positions.end());
    mesh.bind.normals.insert(mesh.bind.normals.end(), part.normals.begin(), part.normals.end());
    for (const glm::uvec3& t : part.triangles) mesh.bind.triangles.push_back(t + glm::uvec3(base));
    for (std::size_t v = 0; v < part.positions.size(); ++v) {
      for (int k = 0; k < influences; ++k) {
        const bool present = k < part.influences;
        const std::size_t src = v * static_cast<std::size_t>(part.influences) + static_cast<std::size_t>(k);
        mesh.weights.joints.push_back(present ? static_cast<std::uint16_t>(part.joints[src])
                                              : std::uint16_t{0});
        mesh.weights.weights.push_back(present ? part.weights[src] : 0.0f);
      }
    }
  }
  parts_.clear();
  return base::Status::Ok();
}

// Concatenates the targets of every morphed glTF mesh into out_.morph (each
// mesh's targets once, zero on other meshes' vertices).
base::Status Converter::MergeMorphTargets(std::size_t num_vertices) {
  GltfMorphTargets& morph = out_.morph;
  mesh_first_target_.assign(m_.meshes.size(), -1);
  mesh_num_targets_.assign(m_.meshes.size(), -1);
  std::vector<int>& mesh_targets = mesh_num_targets_;
  std::vector<std::size_t> part_base;
  std::size_t base = 0;
  bool any_normals = false;
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    const Part& part = parts_[i];
    part_base.push_back(base);
    base += part.positions.size();
    const auto mesh = static_cast<std::size_t>(part.mesh);
    if (mesh_targets[mesh] < 0) {
      mesh_targets[mesh] = part.targets.num_targets;
      if (part.targets.num_targets > 0) {
        mesh_first_target_[mesh] = morph.num_targets;
        morph.num_targets += part.targets.num_targets;
        auto weights = internal::ReadDefaultWeights(m_, path_, part.mesh, part.targets.num_targets);
        if (!weights.ok()) return std::move(weights).error();
        morph.default_weights.insert(morph.default_weights.end(), weights->begin(), weights->end());
      }
    } else if (mesh_targets[mesh] != part.targets.num_targets) {
      return Fail(ErrorCode::kCountMismatch, Indexed("meshes", part.mesh) + ".primitives",
                  "every primitive of a mesh needs the same number of morph targets; found " +
                      std::to_string(mesh_targets[mesh]) + " and " + std::to_string(part.targets.num_targets));
    }
    any_normals = any_normals || !part.targets.normals.empty();
  }
  if (morph.num_targets == 0) return base::Status::Ok();
  const auto k_total = static_cast<std::size_t>(morph.num_targets);
  if (num_vertices != 0 && k_total > options_.max_morph_values / num_vertices) {
    return Fail(ErrorCode::kLimitExceeded, "meshes",
                std::to_string(k_total) + " morph targets x " + std::to_string(num_vertices) +
                    " vertices exceed the limit of " + std::to_string(options_.max_morph_values) +
                    " morph deltas");
  }
  morph.position_deltas.assign(k_total * num_vertices, glm::vec3(0.0f));
  if (any_normals) morph.normal_deltas.assign(k_total * num_vertices, glm::vec3(0.0f));
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    Part& part = parts_[i];
    if (part.targets.num_targets == 0) continue;
    const auto first = static_cast<std::size_t>(mesh_first_target_[static_cast<std::size_t>(part.mesh)]);
    const std::size_t nv = part.positions.size();
    for (std::size_t k = 0; k < static_cast<std::size_t>(part.targets.num_targets); ++k) {
      const std::size_t dst = (first + k) * num_vertices + part_base[i];
      std::copy_n(part.targets.positions.begin() + static_cast<std::ptrdiff_t>(k * nv), nv,
                  morph.position_deltas.begin() + static_cast<std::ptrdiff_t>(dst));
      if (!part.targets.normals.empty()) {
        std::copy_n(part.targets.normals.begin() + static_cast<std::ptrdiff_t>(k * nv), nv,
                    morph.normal_deltas.begin() + static_cast<std::ptrdiff_t>(dst));
      }
    }
    part.targets = {};  // free as we go
  }
  return base::Status::Ok();
}

base::Status Converter::ReadAnimations() {
  mocap::Skeleton& sk = out_.skeleton;
  std::vector<std::array<bool, 3>> driven(static_cast<std::size_t>(sk.num_joints()), {false, false, false});
  for (std::size_t a = 0; a < m_.animations.size(); ++a) {
    const tinygltf::Animation& src = m_.animations[a];
    const std::string at = Indexed("animations", static_cast<int>(a));
    GltfAnimation anim;
    anim.name = src.name.empty() ? "animation_" + std::to_string(a) : src.name;
    for (std::size_t c = 0; c < src.channels.size(); ++c) {
      const tinygltf::AnimationChannel& ch = src.channels[c];
      const std::string cat = at + ".channels[" + std::to_string(c) + "]";
      if (ch.sampler < 0 || ch.sampler >= static_cast<int>(src.samplers.size())) {
        return Fail(ErrorCode::kNotFound, cat + ".sampler",
                    "sampler " + std::to_string(ch.sampler) + " out of range");
      }
      if (ch.target_node < 0 || ch.target_node >= static_cast<int>(m_.nodes.size())) {
        return Fail(ErrorCode::kNotFound, cat + ".target.node",
                    "node " + std::to_string(ch.target_node) + " out of range");
      }
      if (ch.target_path == "weights") {
        const tinygltf::Node& node = m_.nodes[static_cast<std::size_t>(ch.target_node)];
        const int first = node.mesh >= 0 && node.mesh < static_cast<int>(mesh_first_target_.size())
                              ? mesh_first_target_[static_cast<std::size_t>(node.mesh)]
                              : -1;
        if (first < 0) {
          Warn(cat + ".target.node", "not an imported mesh with morph targets; weights channel ignored");
          continue;
        }
        const int count = mesh_num_targets_[static_cast<std::size_t>(node.mesh)];
        auto weights = internal::ReadWeightsSampler(m_, path_, static_cast<int>(a), ch.sampler, count);
        if (!weights.ok()) return std::move(weights).error();
        weights->first_target = first;
        anim.duration_s = std::max(anim.duration_s, static_cast<double>(weights->times_s.back()));
        anim.weights_channels.push_back(std::move(weights).value());
        continue;
      }
      GltfChannel out;
      if (ch.target_path == "translation")
        out.path = GltfPath::kTranslation;
      else if (ch.target_path == "rotation")
        out.path = GltfPath::kRotation;
      else if (ch.target_path == "scale")
        out.path = GltfPath::kScale;
      else {
        Warn(cat + ".target.path", "'" + ch.target_path + "' is not imported");
        continue;
      }
      out.joint = node_joint_[static_cast<std::size_t>(ch.target_node)];
      if (out.joint < 0) {
        Warn(cat + ".target.node", "node is not part of the skeleton; channel ignored");
        continue;
      }
      const tinygltf::AnimationSampler& s = src.samplers[static_cast<std::size_t>(ch.sampler)];
      const std::string sat = at + ".samplers[" + std::to_string(ch.sampler) + "]";
      if (s.interpolation == "LINEAR" || s.interpolation.empty())
        out.interpolation = GltfInterpolation::kLinear;
      else if (s.interpolation == "STEP")
        out.interpolation = GltfInterpolation::kStep;
      else if (s.interpolation == "CUBICSPLINE")
        out.interpolation = GltfInterpolation::kCubicSpline;
      else
        return Fail(ErrorCode::kUnsupported, sat + ".interpolation",
                    "unknown interpolation '" + s.interpolation + "'");
      auto in_view = View(s.input, sat + ".input", TINYGLTF_TYPE_SCALAR, {TINYGLTF_COMPONENT_TYPE_FLOAT});
      if (!in_view.ok()) return std::move(in_view).error();
      const bool rotation = out.path == GltfPath::kRotation;
      auto out_view =
          rotation ? View(s.output, sat + ".output", TINYGLTF_TYPE_VEC4,
                          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT})
                   : View(s.output, sat + ".output", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
      if (!out_view.ok()) return std::move(out_view).error();
      const std::size_t keys = in_view->count;
      const std::size_t per_key = out.interpolation == GltfInterpolation::kCubicSpline ? 3 : 1;
      if (keys == 0)
        return Fail(ErrorCode::kCountMismatch, Indexed("accessors", s.input) + ".count", "no keys");
      if (out_view->count != keys * per_key) {
        return Fail(ErrorCode::kCountMismatch, Indexed("accessors", s.output) + ".count",
                    "expected " + std::to_string(keys * per_key) + " outputs for " + std::to_string(keys) +
                        " keys, found " + std::to_string(out_view->count));
      }
      auto times = Floats(*in_view, false);
      if (!times.ok()) return std::move(times).error();
      for (std::size_t k = 0; k < keys; ++k) {
        if ((*times)[k] < 0.0f || (k > 0 && (*times)[k] < (*times)[k - 1])) {
          return Fail(ErrorCode::kBadNumber, Indexed("accessors", s.input),
                      "key times must be >= 0 and non-decreasing; element " + std::to_string(k) + " is " +
                          std::to_string((*times)[k]));
        }
      }
      auto values = Floats(*out_view, true);
      if (!values.ok()) return std::move(values).error();
      out.times_s = std::move(times).value();
      out.values = std::move(values).value();
      if (rotation && out.interpolation != GltfInterpolation::kCubicSpline) {
        for (std::size_t k = 0; k < keys; ++k) {
          float* q = out.values.data() + k * 4;
          const float len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
          if (len < 1e-6f)
            return Fail(ErrorCode::kBadNumber, Indexed("accessors", s.output),
                        "zero quaternion at key " + std::to_string(k));
          for (int i = 0; i < 4; ++i) q[i] /= len;
        }
      }
      anim.duration_s = std::max(anim.duration_s, static_cast<double>(out.times_s.back()));
      driven[static_cast<std::size_t>(out.joint)][static_cast<std::size_t>(out.path)] = true;
      anim.channels.push_back(std::move(out));
    }
    out_.animations.push_back(std::move(anim));
  }
  internal::AssignChannelLayout(driven, sk);
  return base::Status::Ok();
}

Result<GltfModel> Converter::Run(const GltfReadOptions& options,
                                 std::vector<base::Warning> warnings) {
  out_.warnings = std::move(warnings);
  options_ = options;
  for (const std::string& ext : m_.extensionsRequired) {
    if (ext.rfind("KHR_materials_", 0) != 0 && ext.rfind("KHR_texture_", 0) != 0) {
      return Fail(ErrorCode::kUnsupported, "extensionsRequired",
                  "required extension '" + ext + "' is not supported");
    }
  }
  if (m_.skins.empty() && options.require_skin) {
    return Fail(ErrorCode::kNotFound, "skins", "the file has no skin");
  }
  const int skin = m_.skins.empty() ? -1 : options.skin;  // -1: rigid mesh nodes
  if (!m_.skins.empty() && (options.skin < 0 || options.skin >= static_cast<int>(m_.skins.size()))) {
    return Fail(ErrorCode::kInvalidArgument, "skins",
                "skin " + std::to_string(options.skin) + " requested, the file has " +
                    std::to_string(m_.skins.size()));
  }
  if (auto st = BuildSkeleton(skin); !st) return st.error();
  if (auto st = ReadSkin(skin); !st) return st.error();
  if (auto st = ReadMeshes(skin); !st) return st.error();
  if (auto st = ReadAnimations(); !st) return st.error();
  if (auto st = out_.skeleton.Check(); !st) return st.error();
  if (auto st = out_.mesh.bind.Check(); !st) {
    base::Error e = st.error();
    e.loc.file = path_;
    return e;
  }
  out_.skeleton.info.rest_height = internal::RestHeight(out_.skeleton);
  return std::move(out_);
}

Result<GltfModel> ConvertGltf(const tinygltf::Model& model, const std::string& path,
                              const GltfReadOptions& options, std::vector<base::Warning> warnings) {
  try {
    return Converter(model, path).Run(options, std::move(warnings));
  } catch (const std::exception& e) {
    return base::MakeError(ErrorCode::kInternal, base::FileLoc{path, 0, 0, {}},
                           std::string("unexpected exception: ") + e.what());
  }
}
}  // namespace

Result<GltfModel> ReadGltf(const std::string& path, const GltfReadOptions& options) {
  auto bytes = ReadFileBounded(path, options.max_file_bytes);
  if (!bytes.ok()) return std::move(bytes).error();
  return ReadGltfFromMemory(bytes.value(), path, options);
}

Result<GltfModel> ReadGltfFromMemory(std::span<const unsigned char> bytes, const std::string& path,
                                     const GltfReadOptions& options) {
  if (bytes.size() > options.max_file_bytes) {
    return base::MakeError(ErrorCode::kLimitExceeded, base::FileLoc{path, 0, 0, {}},
                           "file has " + std::to_string(bytes.size()) +
                               " bytes, more than the limit of " +
                               std::to_string(options.max_file_bytes));
  }
  const std::vector<unsigned char> data(bytes.begin(), bytes.end());
  const bool is_glb = data.size() >= 4 && std::memcmp(data.data(), "glTF", 4) == 0;
  std::string json_text;
  if (is_glb) {
    auto json = internal::GlbJson(path, data);
    if (!json.ok()) return std::move(json).error();
    json_text = std::move(json).value();
  } else {
    json_text.assign(reinterpret_cast<const char*>(data.data()), data.size());
  }
  if (base::Status uris = internal::CheckUris(path, json_text); !uris) return uris.error();
  if (data.size() > std::numeric_limits<unsigned int>::max()) {
    return base::MakeError(ErrorCode::kLimitExceeded, base::FileLoc{path, 0, 0, {}},
                           "file larger than 4 GiB");
  }

  FsContext fs_context;
  fs_context.folder = fs::path(path).parent_path();
  if (fs_context.folder.empty()) fs_context.folder = ".";
  fs_context.max_bytes = options.max_file_bytes;
  tinygltf::FsCallbacks callbacks{&ConfinedFileExists, &NoExpand, &ConfinedReadWholeFile, &RefuseWrite,
                                  &fs_context};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(callbacks);
  loader.SetImageLoader(&CaptureImage, nullptr);
  tinygltf::Model model;
  std::string err;
  std::string warn;
  bool loaded = false;
  const std::string base_dir = fs_context.folder.string();
  try {
    if (is_glb) {
      loaded = loader.LoadBinaryFromMemory(&model, &err, &warn, data.data(),
                                           static_cast<unsigned int>(data.size()), base_dir);
    } else {
      loaded = loader.LoadASCIIFromString(&model, &err, &warn, json_text.data(),
                                          static_cast<unsigned int>(json_text.size()), base_dir);
    }
  } catch (const std::exception& e) {
    return base::MakeError(ErrorCode::kSyntax, base::FileLoc{path, 0, 0, {}},
                           std::string("tinygltf: ") + e.what());
  }
  std::vector<base::Warning> warnings;
  AddLines(path, warn, warnings);
  if (!fs_context.rejected.empty()) {
    return base::MakeError(
        ErrorCode::kUnsupported, base::FileLoc{path, 0, 0, {}},
        "refused to read '" + fs_context.rejected + "': it resolves outside the model's folder");
  }
  if (!loaded) {
    return base::MakeError(
        ErrorCode::kSyntax, base::FileLoc{path, 0, 0, {}},
        "tinygltf: " + (err.empty() ? std::string("load failed") : FirstLines(err)));
  }
  if (!err.empty()) AddLines(path, err, warnings);
  return ConvertGltf(model, path, options, std::move(warnings));
}

}  // namespace deform
