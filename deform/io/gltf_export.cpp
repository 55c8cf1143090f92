// glTF export: builds a tinygltf::Model that describes the file (accessors,
// buffer views, meshes, animation) while the binary data of every frame goes
// straight to an unnamed scratch file; Finish lets tinygltf serialize the JSON
// and assembles the .glb (header, JSON chunk, BIN chunk copied from the
// scratch file in blocks) under a temporary name, renamed into place.
// Debian's libtinygltf.so holds the implementation (see gltf_import.cpp).

#include "deform/io/gltf_export.h"

#include <tiny_gltf.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "deform/io/file_output.h"
#include "deform/internal/checks.h"

namespace deform {
namespace {

// Approximate JSON bytes each frame adds.
// Measured on written files: accessor ~100, buffer view ~55, mesh ~130, node
// ~50, sampler and channel ~85, target name ~20.
constexpr std::size_t kMorphJsonPerFrame = 2 * 100 + 2 * 55 + 20;
constexpr std::size_t kBakedJsonPerFrame = 4 * 100 + 4 * 55 + 130 + 50 + 85;
// Baked visibility keys per frame: up to 3 times and 3 scales.
constexpr std::size_t kBakedKeysPerFrame = 3 * 4 + 3 * 12;
// Fixed JSON (asset, scene, root node, base accessors).
constexpr std::size_t kFixedJson = 1200;
constexpr int kMaxFrames = 1000000;
// Bytes copied at a time from the scratch file into the .glb.
constexpr std::size_t kCopyBlock = std::size_t{1} << 20;
// A GLB's lengths are 32-bit.
constexpr std::uint64_t kMaxGlbBytes = 0xFFFFFFFFu;

base::Error GlbError(const std::string& what) {
  return base::InvalidArgument({"glb", 0, 0, {}}, what);
}

using internal::AllFinite;

std::string ErrnoText(int e) { return std::error_code(e, std::generic_category()).message(); }

void PutU32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out += static_cast<char>((v >> (8 * i)) & 0xFFu);
}

// An unnamed read-write file in `dir` (created, then unlinked at once, so it
// disappears when closed, even if the process dies). nullptr + errno on failure.
std::FILE* OpenScratch(const std::string& dir, std::string& error) {
  static std::atomic<int> counter{0};
  std::error_code ec;
  const std::filesystem::path folder = dir.empty() ? std::filesystem::temp_directory_path(ec) : std::filesystem::path(dir);
  const std::string name = (folder / (".patchskin-glb-" + std::to_string(::getpid()) + "-" +
                                      std::to_string(counter++) + ".bin"))
                               .string();
  std::FILE* f = std::fopen(name.c_str(), "w+b");
  if (f == nullptr) {
    error = "cannot create the scratch file '" + name + "': " + ErrnoText(errno);
    return nullptr;
  }
  std::remove(name.c_str());
  return f;
}

std::string FrameName(int k) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "frame_%04d", k);
  return buf;
}

}  // namespace

const char* GltfExportLayoutName(GltfExportLayout layout) {
  switch (layout) {
    case GltfExportLayout::kAuto: return "auto";
    case GltfExportLayout::kMorphTargets: return "morph";
    case GltfExportLayout::kBakedMeshes: return "baked";
  }
  return "?";
}

GltfExportEstimate EstimateGltfExportBytes(int num_vertices, int num_triangles, int num_frames,
                                           bool with_colors) {
  const auto v = static_cast<std::size_t>(std::max(0, num_vertices));
  const auto f = static_cast<std::size_t>(std::max(0, num_frames));
  const std::size_t shared = 12 * static_cast<std::size_t>(std::max(0, num_triangles)) +
                             (with_colors ? 12 * v : 0) + kFixedJson;
  GltfExportEstimate e;
  // Base (frame 0) + targets 1..F-1; target 0 is an all-zero accessor without data.
  e.morph_bytes = shared + 24 * v * f + 4 * f + 4 * f * f + kMorphJsonPerFrame * f;
  e.baked_bytes = shared + 24 * v * f + (kBakedKeysPerFrame + kBakedJsonPerFrame) * f;
  return e;
}

struct GltfSequenceWriter::Impl {
  // The description of the file; buffers[0].data stays empty (the bytes are in
  // `scratch`, bin_bytes of them).
  tinygltf::Model model;
  std::FILE* scratch = nullptr;
  std::uint64_t bin_bytes = 0;
  std::string write_error;  // the first failed scratch write, or empty
  GltfExportOptions options;
  GltfExportLayout layout = GltfExportLayout::kMorphTargets;
  int num_vertices = 0;
  int num_frames = 0;
  int added = 0;
  bool finished = false;
  // One primitive per material group: its indices accessor and material (-1 none).
  std::vector<std::pair<int, int>> groups;
  int colors_accessor = -1;
  int uvs_accessor = -1;
  std::vector<glm::vec3> base_positions;  // morph: frame 0
  std::vector<glm::vec3> base_normals;    // morph: frame 0
  std::vector<glm::vec3> delta;           // morph: scratch, #V
  std::vector<std::map<std::string, int>> frame_attributes;  // per frame: accessors added
  std::vector<float> camera_translations;  // 3 per AddCameraFrame call
  std::vector<float> camera_rotations;     // 4 per call: x, y, z, w (glTF's order)

  ~Impl() {
    if (scratch != nullptr) std::fclose(scratch);
  }

  // Appends raw bytes to the scratch file; the first failure is kept.
  void Append(const void* data, std::size_t bytes) {
    if (!write_error.empty() || bytes == 0) return;
    if (std::fwrite(data, 1, bytes, scratch) != bytes) {
      write_error = "writing the scratch file failed: " + ErrnoText(errno);
      return;
    }
    bin_bytes += bytes;
  }

  // Appends raw bytes as a buffer view (4-byte aligned); returns its index.
  int AddView(const void* data, std::size_t bytes, int target) {
    static constexpr unsigned char kZeros[4] = {0, 0, 0, 0};
    Append(kZeros, static_cast<std::size_t>((4 - bin_bytes % 4) % 4));
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = static_cast<std::size_t>(bin_bytes);
    view.byteLength = bytes;
    view.target = target;
    Append(data, bytes);
    model.bufferViews.push_back(std::move(view));
    return static_cast<int>(model.bufferViews.size()) - 1;
  }

  base::Status WriteGlb(const std::string& path);

  int AddAccessor(int view, int component, int type, std::size_t count,
                  std::vector<double> min = {}, std::vector<double> max = {}) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.byteOffset = 0;
    a.componentType = component;
    a.type = type;
    a.count = count;
    a.minValues = std::move(min);
    a.maxValues = std::move(max);
    model.accessors.push_back(std::move(a));
    return static_cast<int>(model.accessors.size()) - 1;
  }

  int AddVec3(std::span<const glm::vec3> v, bool with_bounds, int target) {
    const int view = AddView(v.data(), v.size_bytes(), target);
    std::vector<double> lo, hi;
    if (with_bounds) {
      glm::vec3 mn(0.0f), mx(0.0f);
      if (!v.empty()) mn = mx = v[0];
      for (const glm::vec3& p : v) {
        mn = glm::min(mn, p);
        mx = glm::max(mx, p);
      }
      lo = {mn.x, mn.y, mn.z};
      hi = {mx.x, mx.y, mx.z};
    }
    return AddAccessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, v.size(),
                       std::move(lo), std::move(hi));
  }

  int AddFloats(std::span<const float> v, int type, std::size_t count, bool with_bounds) {
    const int view = AddView(v.data(), v.size_bytes(), -1);
    std::vector<double> lo, hi;
    if (with_bounds && !v.empty()) {
      float mn = v[0], mx = v[0];
      for (float x : v) {
        mn = std::min(mn, x);
        mx = std::max(mx, x);
      }
      lo = {mn};
      hi = {mx};
    }
    return AddAccessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, type, count, std::move(lo),
                       std::move(hi));
  }

  float KeyTime(int k) const { return static_cast<float>(k * options.frame_time_s); }

  std::vector<tinygltf::Primitive> Primitives(const std::map<std::string, int>& attributes) const {
    std::vector<tinygltf::Primitive> out;
    for (const auto& [indices, material] : groups) {
      tinygltf::Primitive prim;
      prim.attributes = attributes;
      if (colors_accessor >= 0) prim.attributes["COLOR_0"] = colors_accessor;
      if (uvs_accessor >= 0) prim.attributes["TEXCOORD_0"] = uvs_accessor;
      prim.indices = indices;
      prim.material = material;
      prim.mode = TINYGLTF_MODE_TRIANGLES;
      out.push_back(std::move(prim));
    }
    return out;
  }

  void AddTriangles(std::span<const glm::uvec3> triangles, const MeshMaterials* materials);
  void AddMaterials(const MeshMaterials& materials);

  void FinishMorph();
  void FinishBaked();
  void AddCamera(tinygltf::Animation& anim);
};

// The camera node, keyed at every frame's time: its samplers and channels join the
// deformation's animation, so viewers play both together.
void GltfSequenceWriter::Impl::AddCamera(tinygltf::Animation& anim) {
  if (!options.camera) return;
  tinygltf::Camera camera;
  camera.type = "perspective";
  camera.name = "camera";
  camera.perspective.yfov = options.camera->yfov_rad;
  camera.perspective.aspectRatio = options.camera->aspect;
  camera.perspective.znear = options.camera->znear;
  camera.perspective.zfar = options.camera->zfar;
  model.cameras.push_back(std::move(camera));
  tinygltf::Node node;
  node.name = "camera";
  node.camera = static_cast<int>(model.cameras.size()) - 1;
  node.translation.assign(camera_translations.begin(), camera_translations.begin() + 3);
  node.rotation.assign(camera_rotations.begin(), camera_rotations.begin() + 4);
  model.nodes.push_back(std::move(node));
  const int index = static_cast<int>(model.nodes.size()) - 1;
  model.scenes[0].nodes.push_back(index);

  const auto f = static_cast<std::size_t>(num_frames);
  std::vector<float> times(f);
  for (std::size_t k = 0; k < f; ++k) times[k] = KeyTime(static_cast<int>(k));
  const int input = AddFloats(times, TINYGLTF_TYPE_SCALAR, f, true);
  const auto channel = [&](const std::vector<float>& values, int type, const char* path) {
    tinygltf::AnimationSampler sampler;
    sampler.input = input;
    sampler.output = AddFloats(values, type, f, false);
    sampler.interpolation = "LINEAR";
    anim.samplers.push_back(std::move(sampler));
    tinygltf::AnimationChannel c;
    c.sampler = static_cast<int>(anim.samplers.size()) - 1;
    c.target_node = index;
    c.target_path = path;
    anim.channels.push_back(std::move(c));
  };
  channel(camera_translations, TINYGLTF_TYPE_VEC3, "translation");
  channel(camera_rotations, TINYGLTF_TYPE_VEC4, "rotation");
}

void GltfSequenceWriter::Impl::FinishMorph() {
  tinygltf::Mesh mesh;
  mesh.name = options.mesh_name;
  for (tinygltf::Primitive& prim : Primitives(frame_attributes[0])) {
    prim.targets.assign(frame_attributes.begin() + 1, frame_attributes.end());
    mesh.primitives.push_back(std::move(prim));
  }
  mesh.weights.assign(static_cast<std::size_t>(num_frames), 0.0);
  mesh.weights[0] = 1.0;
  tinygltf::Value::Array names;
  for (int k = 0; k < num_frames; ++k) names.emplace_back(FrameName(k));
  tinygltf::Value::Object extras;
  extras["targetNames"] = tinygltf::Value(names);
  mesh.extras = tinygltf::Value(extras);
  model.meshes.push_back(std::move(mesh));

  tinygltf::Node node;
  node.name = options.mesh_name;
  node.mesh = 0;
  model.nodes.push_back(std::move(node));
  model.scenes[0].nodes = {0};

  const auto f = static_cast<std::size_t>(num_frames);
  std::vector<float> times(f);
  for (std::size_t k = 0; k < f; ++k) times[k] = KeyTime(static_cast<int>(k));
  tinygltf::AnimationSampler sampler;
  sampler.input = AddFloats(times, TINYGLTF_TYPE_SCALAR, f, true);
  // The #F x #F weights (key k: 1 for target k, 0 for the others) are
  // written one key at a time: memory stays #F, not #F^2.
  const int weights_view = AddView(nullptr, 0, -1);
  std::vector<float> row(f, 0.0f);
  for (std::size_t k = 0; k < f; ++k) {
    row[k] = 1.0f;
    Append(row.data(), f * sizeof(float));
    row[k] = 0.0f;
  }
  model.bufferViews[static_cast<std::size_t>(weights_view)].byteLength = f * f * sizeof(float);
  sampler.output = AddAccessor(weights_view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, f * f);
  sampler.interpolation = options.step_interpolation ? "STEP" : "LINEAR";
  tinygltf::AnimationChannel channel;
  channel.sampler = 0;
  channel.target_node = 0;
  channel.target_path = "weights";
  tinygltf::Animation anim;
  anim.name = "deformation";
  anim.samplers.push_back(std::move(sampler));
  anim.channels.push_back(std::move(channel));
  AddCamera(anim);
  model.animations.push_back(std::move(anim));
}

void GltfSequenceWriter::Impl::FinishBaked() {
  tinygltf::Node root;
  root.name = options.mesh_name;
  model.nodes.push_back(std::move(root));
  tinygltf::Animation anim;
  anim.name = "deformation";
  for (int k = 0; k < num_frames; ++k) {
    tinygltf::Mesh mesh;
    mesh.name = options.mesh_name + "_" + FrameName(k);
    mesh.primitives = Primitives(frame_attributes[static_cast<std::size_t>(k)]);
    model.meshes.push_back(std::move(mesh));
    tinygltf::Node node;
    node.name = FrameName(k);
    node.mesh = k;
    node.scale = k == 0 ? std::vector<double>{1, 1, 1} : std::vector<double>{0, 0, 0};
    model.nodes.push_back(std::move(node));
    const int node_index = static_cast<int>(model.nodes.size()) - 1;
    model.nodes[0].children.push_back(node_index);

    // Hidden before key k (if k > 0), shown at key k, hidden from key k+1.
    std::vector<float> times;
    std::vector<float> scales;
    if (k > 0) {
      times.push_back(0.0f);
      scales.insert(scales.end(), {0.0f, 0.0f, 0.0f});
    }
    times.push_back(KeyTime(k));
    scales.insert(scales.end(), {1.0f, 1.0f, 1.0f});
    if (k + 1 < num_frames) {
      times.push_back(KeyTime(k + 1));
      scales.insert(scales.end(), {0.0f, 0.0f, 0.0f});
    }
    tinygltf::AnimationSampler sampler;
    sampler.input = AddFloats(times, TINYGLTF_TYPE_SCALAR, times.size(), true);
    sampler.output = AddFloats(scales, TINYGLTF_TYPE_VEC3, times.size(), false);
    sampler.interpolation = "STEP";
    anim.samplers.push_back(std::move(sampler));
    tinygltf::AnimationChannel channel;
    channel.sampler = static_cast<int>(anim.samplers.size()) - 1;
    channel.target_node = node_index;
    channel.target_path = "scale";
    anim.channels.push_back(std::move(channel));
  }
  model.scenes[0].nodes = {0};
  AddCamera(anim);
  model.animations.push_back(std::move(anim));
}

// The index accessors: all triangles in one group, or (several materials) one
// group per material in order of first use.
void GltfSequenceWriter::Impl::AddTriangles(std::span<const glm::uvec3> triangles,
                                            const MeshMaterials* materials) {
  std::vector<std::int32_t> order;  // materials in order of first use
  const bool per_triangle = materials != nullptr && !materials->triangle_material.empty();
  if (per_triangle) {
    for (const std::int32_t k : materials->triangle_material)
      if (std::find(order.begin(), order.end(), k) == order.end()) order.push_back(k);
  } else {
    order.push_back(materials != nullptr && materials->materials.size() == 1 ? 0 : -1);
  }
  std::vector<glm::uvec3> group;
  for (const std::int32_t k : order) {
    std::span<const glm::uvec3> tris = triangles;
    if (order.size() > 1) {
      group.clear();
      for (std::size_t t = 0; t < triangles.size(); ++t)
        if (materials->triangle_material[t] == k) group.push_back(triangles[t]);
      tris = group;
    }
    const int view = AddView(tris.data(), tris.size_bytes(), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    groups.emplace_back(AddAccessor(view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                    tris.size() * 3),
                        k);
  }
}

// glTF materials, textures, samplers and embedded images, in the same order
// as `materials` (so the groups' material indices carry over).
void GltfSequenceWriter::Impl::AddMaterials(const MeshMaterials& materials) {
  auto wrap = [](TextureWrap w) {
    switch (w) {
      case TextureWrap::kClampToEdge: return TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      case TextureWrap::kMirroredRepeat: return TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
      default: return TINYGLTF_TEXTURE_WRAP_REPEAT;
    }
  };
  std::vector<int> image_of(materials.images.size(), -1);
  for (const Material& src : materials.materials) {
    tinygltf::Material m;
    m.name = src.name;
    const glm::vec3 f = src.base_color_factor;
    m.pbrMetallicRoughness.baseColorFactor = {f.x, f.y, f.z, 1.0};
    m.pbrMetallicRoughness.metallicFactor = 0.0;  // the renderer's diffuse look
    if (src.texture >= 0) {
      int& image = image_of[static_cast<std::size_t>(src.texture)];
      if (image < 0) {
        const TextureImage& img = *materials.images[static_cast<std::size_t>(src.texture)];
        tinygltf::Image out;
        out.bufferView = AddView(img.encoded.data(), img.encoded.size(), -1);
        out.mimeType = img.mime_type;
        model.images.push_back(std::move(out));
        image = static_cast<int>(model.images.size()) - 1;
      }
      tinygltf::Sampler sampler;
      sampler.wrapS = wrap(src.wrap_s);
      sampler.wrapT = wrap(src.wrap_t);
      model.samplers.push_back(std::move(sampler));
      tinygltf::Texture texture;
      texture.source = image;
      texture.sampler = static_cast<int>(model.samplers.size()) - 1;
      model.textures.push_back(std::move(texture));
      m.pbrMetallicRoughness.baseColorTexture.index = static_cast<int>(model.textures.size()) - 1;
    }
    model.materials.push_back(std::move(m));
  }
}

GltfSequenceWriter::GltfSequenceWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GltfSequenceWriter::GltfSequenceWriter(GltfSequenceWriter&&) noexcept = default;
GltfSequenceWriter& GltfSequenceWriter::operator=(GltfSequenceWriter&&) noexcept = default;
GltfSequenceWriter::~GltfSequenceWriter() = default;

GltfExportLayout GltfSequenceWriter::layout() const { return impl_->layout; }
int GltfSequenceWriter::frames_added() const { return impl_->added; }

base::Result<GltfSequenceWriter> GltfSequenceWriter::Create(std::span<const glm::uvec3> triangles,
                                                            std::span<const glm::vec3> colors,
                                                            int num_vertices, int num_frames,
                                                            const GltfExportOptions& options,
                                                            const GltfExportSurface& surface) {
  if (num_vertices < 1) return GlbError("the mesh has no vertices");
  if (num_frames < 1 || num_frames > kMaxFrames) {
    return GlbError("expected 1.." + std::to_string(kMaxFrames) + " frames, found " +
                    std::to_string(num_frames));
  }
  if (!(options.frame_time_s > 0.0) || !std::isfinite(options.frame_time_s)) {
    return GlbError("the frame time must be a positive number of seconds");
  }
  if (const std::optional<GltfCameraLens>& lens = options.camera) {
    const bool ok = lens->yfov_rad > 0.0f && lens->yfov_rad < 3.14159f && lens->aspect > 0.0f &&
                    std::isfinite(lens->aspect) && lens->znear > 0.0f && lens->zfar > lens->znear &&
                    std::isfinite(lens->zfar);
    if (!ok)
      return GlbError("camera lens: expected 0 < yfov < pi, aspect > 0 and 0 < znear < zfar");
  }
  const auto nv = static_cast<std::size_t>(num_vertices);
  if (!colors.empty() && colors.size() != nv) {
    return GlbError("colors must be empty or one per vertex");
  }
  if (!AllFinite(colors)) return GlbError("colors must be finite");
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const glm::uvec3& tri = triangles[t];
    if (tri.x >= nv || tri.y >= nv || tri.z >= nv) {
      return GlbError("triangle " + std::to_string(t) + " has a vertex index outside 0.." +
                      std::to_string(nv) + "-1");
    }
  }

  if (!surface.uvs.empty() && surface.uvs.size() != nv)
    return GlbError("uvs must be empty or one per vertex");
  for (const glm::vec2& uv : surface.uvs) {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return GlbError("uvs must be finite");
  }
  const MeshMaterials* materials = surface.materials;
  if (materials != nullptr) {
    const auto num_materials = static_cast<std::int32_t>(materials->materials.size());
    if (!materials->triangle_material.empty() && materials->triangle_material.size() != triangles.size()) {
      return GlbError("triangle_material must be empty or one per triangle");
    }
    for (const std::int32_t k : materials->triangle_material) {
      if (k < -1 || k >= num_materials)
        return GlbError("triangle material " + std::to_string(k) + " out of range");
    }
    for (const Material& m : materials->materials) {
      if (m.texture < 0) continue;
      if (static_cast<std::size_t>(m.texture) >= materials->images.size() ||
          !materials->images[static_cast<std::size_t>(m.texture)] ||
          materials->images[static_cast<std::size_t>(m.texture)]->encoded.empty()) {
        return GlbError("material '" + m.name + "': its texture has no encoded image to embed");
      }
      if (surface.uvs.empty()) return GlbError("a textured material needs uvs");
    }
  }

  auto impl = std::make_unique<Impl>();
  std::string scratch_error;
  impl->scratch = OpenScratch(options.scratch_dir, scratch_error);
  if (impl->scratch == nullptr) {
    return base::MakeError(base::ErrorCode::kIo, {options.scratch_dir, 0, 0, {}}, scratch_error);
  }
  impl->options = options;
  impl->num_vertices = num_vertices;
  impl->num_frames = num_frames;
  impl->layout = options.layout;
  if (impl->layout == GltfExportLayout::kAuto) {
    const GltfExportEstimate e = EstimateGltfExportBytes(
        num_vertices, static_cast<int>(triangles.size()), num_frames, !colors.empty());
    impl->layout = e.baked_bytes < e.morph_bytes ? GltfExportLayout::kBakedMeshes
                                                  : GltfExportLayout::kMorphTargets;
  }
  tinygltf::Model& m = impl->model;
  m.asset.version = "2.0";
  m.asset.generator = options.generator;
  m.buffers.resize(1);
  m.scenes.resize(1);
  m.defaultScene = 0;
  impl->AddTriangles(triangles, materials);
  if (materials != nullptr) impl->AddMaterials(*materials);
  if (!colors.empty()) {
    // COLOR_0 x baseColorFactor is the albedo: divide the factor back out.
    std::vector<glm::vec3> stored(colors.begin(), colors.end());
    if (materials != nullptr && !materials->materials.empty()) {
      std::vector<std::int32_t> vertex_material(nv, -1);
      for (std::size_t t = 0; t < triangles.size(); ++t) {
        const std::int32_t k = materials->triangle_material.empty() ? 0 : materials->triangle_material[t];
        for (int c = 0; c < 3; ++c)
          if (vertex_material[triangles[t][c]] < 0) vertex_material[triangles[t][c]] = k;
      }
      for (std::size_t v = 0; v < nv; ++v) {
        if (vertex_material[v] < 0) continue;
        const glm::vec3 f = materials->materials[static_cast<std::size_t>(vertex_material[v])].base_color_factor;
        for (int c = 0; c < 3; ++c) stored[v][c] = f[c] > 0.0f ? std::min(stored[v][c] / f[c], 1.0f) : 0.0f;
      }
    }
    const bool all_white = std::all_of(stored.begin(), stored.end(), [](const glm::vec3& c) { return c == glm::vec3(1.0f); });
    if (!all_white || materials == nullptr) {
      impl->colors_accessor = impl->AddVec3(stored, false, TINYGLTF_TARGET_ARRAY_BUFFER);
    }
  }
  if (!surface.uvs.empty()) {
    const int view = impl->AddView(surface.uvs.data(), surface.uvs.size_bytes(), TINYGLTF_TARGET_ARRAY_BUFFER);
    impl->uvs_accessor = impl->AddAccessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, nv);
  }
  return GltfSequenceWriter(std::move(impl));
}

base::Status GltfSequenceWriter::AddFrame(std::span<const glm::vec3> positions,
                                          std::span<const glm::vec3> normals) {
  Impl& m = *impl_;
  const auto nv = static_cast<std::size_t>(m.num_vertices);
  if (m.finished) return GlbError("the file was already written");
  if (m.added >= m.num_frames) {
    return GlbError("more frames than the " + std::to_string(m.num_frames) + " announced");
  }
  if (positions.size() != nv || normals.size() != nv) {
    return GlbError("frame " + std::to_string(m.added) + ": expected " + std::to_string(nv) +
                    " positions and normals, found " + std::to_string(positions.size()) + " and " +
                    std::to_string(normals.size()));
  }
  if (!AllFinite(positions) || !AllFinite(normals)) {
    return GlbError("frame " + std::to_string(m.added) + ": positions and normals must be finite");
  }
  if (!m.write_error.empty()) {
    return base::MakeError(base::ErrorCode::kIo, {m.options.scratch_dir, 0, 0, {}}, m.write_error);
  }
  std::map<std::string, int> attributes;
  if (m.layout == GltfExportLayout::kBakedMeshes) {
    attributes["POSITION"] = m.AddVec3(positions, true, TINYGLTF_TARGET_ARRAY_BUFFER);
    attributes["NORMAL"] = m.AddVec3(normals, false, TINYGLTF_TARGET_ARRAY_BUFFER);
    m.frame_attributes.push_back(std::move(attributes));
  } else {
    if (m.added == 0) {
      m.base_positions.assign(positions.begin(), positions.end());
      m.base_normals.assign(normals.begin(), normals.end());
      attributes["POSITION"] = m.AddVec3(positions, true, TINYGLTF_TARGET_ARRAY_BUFFER);
      attributes["NORMAL"] = m.AddVec3(normals, false, TINYGLTF_TARGET_ARRAY_BUFFER);
      m.frame_attributes.push_back(std::move(attributes));
      // Target 0 (frame 0 itself) is all zero: accessors without a buffer view
      // are zeros by the specification, so it costs no data.
      attributes.clear();
      attributes["POSITION"] = m.AddAccessor(-1, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                                             nv, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
      attributes["NORMAL"] =
          m.AddAccessor(-1, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
      m.frame_attributes.push_back(std::move(attributes));
      ++m.added;
      return base::Status::Ok();
    }
    m.delta.resize(nv);
    for (std::size_t i = 0; i < nv; ++i) m.delta[i] = positions[i] - m.base_positions[i];
    attributes["POSITION"] = m.AddVec3(m.delta, true, TINYGLTF_TARGET_ARRAY_BUFFER);
    for (std::size_t i = 0; i < nv; ++i) m.delta[i] = normals[i] - m.base_normals[i];
    attributes["NORMAL"] = m.AddVec3(m.delta, false, TINYGLTF_TARGET_ARRAY_BUFFER);
    m.frame_attributes.push_back(std::move(attributes));
  }
  ++m.added;
  return base::Status::Ok();
}

base::Status GltfSequenceWriter::AddCameraFrame(const glm::vec3& eye,
                                                const glm::quat& world_from_camera) {
  Impl& m = *impl_;
  if (m.finished) return GlbError("the file was already written");
  if (!m.options.camera) return GlbError("a camera pose without a camera lens in the options");
  const std::size_t poses = m.camera_translations.size() / 3;
  if (poses >= static_cast<std::size_t>(m.num_frames)) {
    return GlbError("more camera poses than the " + std::to_string(m.num_frames) +
                    " frames announced");
  }
  const glm::quat q = glm::normalize(world_from_camera);
  const bool finite = AllFinite(std::span<const glm::vec3>(&eye, 1)) && std::isfinite(q.x) && std::isfinite(q.y) &&
                      std::isfinite(q.z) && std::isfinite(q.w);
  if (!finite)
    return GlbError("camera pose " + std::to_string(poses) +
                    ": expected finite values and a non-zero rotation");
  m.camera_translations.insert(m.camera_translations.end(), {eye.x, eye.y, eye.z});
  m.camera_rotations.insert(m.camera_rotations.end(), {q.x, q.y, q.z, q.w});
  return base::Status::Ok();
}

base::Status GltfSequenceWriter::Finish(const std::string& path) {
  Impl& m = *impl_;
  if (m.finished) return GlbError("the file was already written");
  if (m.added != m.num_frames) {
    return base::InvalidArgument({path, 0, 0, {}}, "expected " + std::to_string(m.num_frames) +
                                                       " frames, " + std::to_string(m.added) +
                                                       " were added");
  }
  if (m.options.camera && m.camera_translations.size() / 3 != static_cast<std::size_t>(m.num_frames)) {
    return base::InvalidArgument(
        {path, 0, 0, {}}, "expected " + std::to_string(m.num_frames) + " camera poses, " +
                              std::to_string(m.camera_translations.size() / 3) + " were added");
  }
  m.finished = true;  // the model is consumed below, whatever the outcome
  if (m.layout == GltfExportLayout::kBakedMeshes) {
    m.FinishBaked();
  } else {
    m.FinishMorph();
  }
  m.model.buffers[0].name = "geometry";
  base::Status s = m.WriteGlb(path);
  std::fclose(m.scratch);  // the scratch file disappears with it
  m.scratch = nullptr;
  return s;
}

base::Status GltfSequenceWriter::Impl::WriteGlb(const std::string& path) {
  auto io_error = [&](const std::string& why) {
    return base::MakeError(base::ErrorCode::kIo, {path, 0, 0, {}}, why);
  };
  if (!write_error.empty()) return io_error(write_error);
  if (std::fflush(scratch) != 0) return io_error("writing the scratch file failed: " + ErrnoText(errno));
  // tinygltf writes the JSON (every property but the buffer's bytes, which it
  // sees as empty); the buffer's real length is set afterwards.
  std::ostringstream glb;
  tinygltf::TinyGLTF gltf;
  if (!gltf.WriteGltfSceneToStream(&model, glb, false, true)) {
    return io_error("tinygltf could not serialize the model");
  }
  std::string json;
  {
    const std::string tiny = std::move(glb).str();
    std::uint32_t json_length = 0;
    if (tiny.size() >= 20) std::memcpy(&json_length, tiny.data() + 12, 4);  // GLB and x86 are little-endian
    if (tiny.size() < 20 || json_length > tiny.size() - 20) return io_error("tinygltf wrote no JSON chunk");
    json.assign(tiny, 20, json_length);
  }
  // tinygltf's JSON object keys are sorted and compact, so the buffer reads
  // exactly as below; patching the text avoids a second copy of the document
  // (which grows with the frame count). Anything else is parsed and patched.
  const std::string empty_buffer = "{\"byteLength\":0,\"name\":\"geometry\"}";
  const std::size_t at = json.find(empty_buffer);
  if (at != std::string::npos && json.find(empty_buffer, at + 1) == std::string::npos) {
    json.replace(at, empty_buffer.size(),
                 "{\"byteLength\":" + std::to_string(bin_bytes) + ",\"name\":\"geometry\"}");
  } else {
    nlohmann::json doc = nlohmann::json::parse(json, nullptr, false);
    if (doc.is_discarded() || !doc.contains("buffers")) return io_error("tinygltf wrote unreadable JSON");
    doc["buffers"][0]["byteLength"] = bin_bytes;
    json = doc.dump();
  }
  // The description is no longer needed: free it before the copy.
  model = tinygltf::Model();
  frame_attributes = {};
  json.append((4 - json.size() % 4) % 4, ' ');  // chunks are 4-byte aligned: JSON pads with spaces
  const std::uint64_t bin_padded = bin_bytes + (4 - bin_bytes % 4) % 4;
  const std::uint64_t total = 12 + 8 + json.size() + (bin_bytes > 0 ? 8 + bin_padded : 0);
  if (total > kMaxGlbBytes) {
    return base::MakeError(base::ErrorCode::kLimitExceeded, {path, 0, 0, {}},
                           "the .glb would have " + std::to_string(total) +
                               " bytes; the format holds at most 4 GiB (export fewer frames)");
  }
  std::string head = "glTF";
  PutU32(head, 2);
  PutU32(head, static_cast<std::uint32_t>(total));
  PutU32(head, static_cast<std::uint32_t>(json.size()));
  PutU32(head, 0x4E4F534Au);  // "JSON"
  head += json;
  if (bin_bytes > 0) {
    PutU32(head, static_cast<std::uint32_t>(bin_padded));
    PutU32(head, 0x004E4942u);  // "BIN\0"
  }

  const std::string temp = TemporaryOutputPath(path);
  std::FILE* out = std::fopen(temp.c_str(), "wb");
  if (out == nullptr) return io_error("cannot create '" + temp + "': " + ErrnoText(errno));
  bool ok = std::fwrite(head.data(), 1, head.size(), out) == head.size();
  std::vector<unsigned char> block(static_cast<std::size_t>(std::min<std::uint64_t>(kCopyBlock, bin_bytes)));
  ok = ok && std::fseek(scratch, 0, SEEK_SET) == 0;
  for (std::uint64_t left = bin_bytes; ok && left > 0;) {
    const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(left, block.size()));
    ok = std::fread(block.data(), 1, n, scratch) == n && std::fwrite(block.data(), 1, n, out) == n;
    left -= n;
  }
  static constexpr unsigned char kZeros[4] = {0, 0, 0, 0};
  const auto pad = static_cast<std::size_t>(bin_padded - bin_bytes);
  ok = ok && std::fwrite(kZeros, 1, pad, out) == pad;
  const int write_errno = errno;
  ok = std::fclose(out) == 0 && ok;
  std::error_code ec;
  if (!ok) {
    std::filesystem::remove(temp, ec);
    return io_error("writing failed: " + ErrnoText(write_errno));
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    return io_error("cannot rename the finished temporary file into place: " + ec.message());
  }
  return base::Status::Ok();
}

}  // namespace deform
