#pragma once
// Triangle meshes and skin weights: the types every deformation job reads and
// writes, and the only deform types the render module needs.
//
// Arrays are separate (structure of arrays): #V positions, #V normals, #T
// triangles. Positions are in model space, in the units of the skeleton that
// drives them.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"

namespace deform {

// Maximum influences per vertex the skinning jobs support (4 or 8 are used).
inline constexpr int kMaxInfluences = 8;
// Albedo of a vertex whose file gives no colour while others of its mesh have one
// (the renderer's grey for a mesh without colours, render::SceneMesh::base_color).
inline constexpr glm::vec3 kDefaultAlbedo{0.75f, 0.72f, 0.68f};

struct Mesh {
  std::vector<glm::vec3> positions;   // #V, model space
  std::vector<glm::vec3> normals;     // #V unit normals, or empty (then computed on demand)
  std::vector<glm::uvec3> triangles;  // #T, counter-clockwise seen from outside
  std::vector<glm::vec3> colors;      // #V linear RGB in [0,1], or empty (default material)
  std::vector<glm::vec2> uvs;         // #V texture coordinates (glTF TEXCOORD_0), or empty

  int num_vertices() const { return static_cast<int>(positions.size()); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
  // Sizes agree, indices in range, values finite.
  base::Status Check() const;
};

// How a texture coordinate outside [0, 1] is mapped back (glTF 2.0 sampler wrap modes).
enum class TextureWrap : std::uint8_t { kRepeat, kClampToEdge, kMirroredRepeat };

// A decoded colour texture. Texel (x, y) is rgb[3 * (y * width + x)]; row 0 is
// the first row of the file, which glTF puts at v = 0 (texel centres at
// u = (x + 0.5) / width, v = (y + 0.5) / height).
struct TextureImage {
  int width = 0, height = 0;
  std::vector<float> rgb;            // width x height x 3, linear RGB in [0, 1]
  // The file's bytes as read (PNG or JPEG) and their MIME type, so an export
  // can embed the image unchanged; empty when the texture was made in memory.
  std::vector<unsigned char> encoded;
  std::string mime_type;
};

// The base colour of a group of triangles (glTF pbrMetallicRoughness).
// Albedo = base_color_factor x texture(uv) x vertex colour; importers fold the
// factor into Mesh::colors already (see gltf_import.h), so renderers multiply
// the texture by the vertex colour only.
struct Material {
  glm::vec3 base_color_factor{1.0f};  // linear RGB
  int texture = -1;                   // index into MeshMaterials::images, -1: none
  TextureWrap wrap_s = TextureWrap::kRepeat;  // along u
  TextureWrap wrap_t = TextureWrap::kRepeat;  // along v
  std::string name;
};

// The materials of a mesh. Images are shared (copying a mesh does not copy texels).
struct MeshMaterials {
  std::vector<Material> materials;
  std::vector<std::shared_ptr<const TextureImage>> images;
  std::vector<std::int32_t> triangle_material;  // #T index into materials, -1: none; or empty

  bool textured() const {
    for (const Material& m : materials)
      if (m.texture >= 0) return true;
    return false;
  }
};

// Per-vertex skin weights with a fixed number of influences per vertex
// (ozz fixes the count per SkinningJob). Unused slots have weight 0.
struct SkinWeights {
  int influences = 4;                  // 1..kMaxInfluences
  std::vector<std::uint16_t> joints;   // #V x influences, indices into the skin's joints
  std::vector<float> weights;          // #V x influences, >= 0, each row sums to 1

  int num_vertices() const {
    return influences > 0 ? static_cast<int>(weights.size()) / influences : 0;
  }
};

// A mesh bound to a skeleton: the bind-pose mesh, its weights, and which
// skeleton joint each skin joint is, with the inverse bind matrices
// (bind_from_joint maps model-space bind positions into the joint's frame).
// Where a generated body's vertex came from: the body chain whose tube holds it
// (index into BuildBodyChains' chains, deform/body/body_chains.h) and its ring's chain
// coordinate u = k + t (on bone k, points k -> k+1, t in [0, 1]; caps carry their end
// ring's u). chain = -1: not on a tube (the mannequin's head).
struct BodyChainCoord {
  int chain = -1;
  float u = 0.0f;
};

struct SkinnedMesh {
  Mesh bind;
  SkinWeights weights;
  std::vector<int> skin_joints;             // #S skeleton joint index of each skin joint
  std::vector<glm::mat4> joint_from_bind;   // #S inverse bind matrices
  // #V, or empty (a mesh not generated from the skeleton, e.g. glTF): filled by
  // BuildMannequin, for the SWD rig to bind each tube to the chain it was made from
  // (SwdRigOptions::vertex_chains). Valid only for that skeleton in that bind pose.
  std::vector<BodyChainCoord> body_chain_coords;
  // Materials of the bind triangles (empty for generated bodies).
  MeshMaterials materials;
};

// Area-weighted vertex normals of `positions` over `triangles` (zero-area
// triangles contribute nothing; isolated vertices get (0,0,1)).
void ComputeVertexNormals(std::span<const glm::vec3> positions,
                          std::span<const glm::uvec3> triangles, std::span<glm::vec3> normals);

// True when `triangles` close every surface they bound (each directed edge once,
// its reverse once) with outward winding (counter-clockwise seen from outside,
// positive enclosed volume); false for an open or inconsistent mesh.
// Cost: O(#T log #T), allocates 3 #T edges.
bool IsClosedOutward(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles);

// Axis-aligned bounds of a point set; min > max when empty.
struct Bounds {
  glm::vec3 min{1e30f};
  glm::vec3 max{-1e30f};
  void Extend(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  bool empty() const { return min.x > max.x; }
  glm::vec3 center() const { return 0.5f * (min + max); }
  glm::vec3 size() const { return max - min; }
};
Bounds ComputeBounds(std::span<const glm::vec3> points);

}  // namespace deform
