#include "deform/body/generated_body.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

#include "deform/body/body_chains.h"
#include "deform/global/skinning_job.h"

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

// Part of every cache key: bump it whenever the generated shape, mesh or
// weights change, so that no cached body from an older build is read back.
constexpr std::uint32_t kCacheVersion = 3;
constexpr char kMagic[8] = {'p', 's', 'b', 'o', 'd', 'y', '0', '1'};

// FNV-1a over raw bytes.
class Hasher {
 public:
  template <typename T>
  void Add(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    AddBytes(&value, sizeof(T));
  }
  void AddBytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) hash_ = (hash_ ^ p[i]) * 0x100000001b3ull;
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ull;
};

template <typename T>
void Write(std::ofstream& f, const std::vector<T>& v) {
  const auto n = static_cast<std::uint64_t>(v.size());
  f.write(reinterpret_cast<const char*>(&n), sizeof(n));
  f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
}

template <typename T>
bool Read(std::ifstream& f, std::vector<T>& v, std::uint64_t limit) {
  std::uint64_t n = 0;
  if (!f.read(reinterpret_cast<char*>(&n), sizeof(n)) || n > limit) return false;
  v.resize(static_cast<std::size_t>(n));
  return static_cast<bool>(f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T))));
}

bool ReadCache(const std::filesystem::path& file, std::uint64_t key, int num_joints, SkinnedMesh& out) {
  std::ifstream f(file, std::ios::binary);
  if (!f) return false;
  char magic[8];
  std::uint64_t stored = 0;
  if (!f.read(magic, sizeof(magic)) || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) return false;
  if (!f.read(reinterpret_cast<char*>(&stored), sizeof(stored)) || stored != key) return false;
  constexpr std::uint64_t kLimit = 1u << 24;
  std::int32_t influences = 0;
  if (!f.read(reinterpret_cast<char*>(&influences), sizeof(influences)) || influences < 1 ||
      influences > kMaxInfluences) {
    return false;
  }
  SkinnedMesh m;
  m.weights.influences = influences;
  if (!Read(f, m.bind.positions, kLimit) || !Read(f, m.bind.normals, kLimit) || !Read(f, m.bind.triangles, kLimit) ||
      !Read(f, m.weights.joints, kLimit) || !Read(f, m.weights.weights, kLimit) || !Read(f, m.skin_joints, kLimit) ||
      !Read(f, m.joint_from_bind, kLimit)) {
    return false;
  }
  const std::size_t nv = m.bind.positions.size();
  if (!m.bind.Check().ok() || m.weights.joints.size() != nv * static_cast<std::size_t>(influences) ||
      m.weights.weights.size() != m.weights.joints.size() || m.skin_joints.size() != m.joint_from_bind.size()) {
    return false;
  }
  for (const std::uint16_t j : m.weights.joints) {
    if (j >= m.skin_joints.size()) return false;
  }
  for (const int j : m.skin_joints) {
    if (j < 0 || j >= num_joints) return false;
  }
  out = std::move(m);
  return true;
}

void WriteCache(const std::filesystem::path& folder, const std::filesystem::path& file, std::uint64_t key,
                const SkinnedMesh& m) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) return;
  // A name of its own per writer, so concurrent renders never share a half-written file.
  static std::atomic<unsigned> serial{0};
  const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
  std::filesystem::path tmp = file;
  tmp += ".tmp" + std::to_string(stamp) + "-" + std::to_string(serial++);
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) return;
    f.write(kMagic, sizeof(kMagic));
    f.write(reinterpret_cast<const char*>(&key), sizeof(key));
    const auto influences = static_cast<std::int32_t>(m.weights.influences);
    f.write(reinterpret_cast<const char*>(&influences), sizeof(influences));
    Write(f, m.bind.positions);
    Write(f, m.bind.normals);
    Write(f, m.bind.triangles);
    Write(f, m.weights.joints);
    Write(f, m.weights.weights);
    Write(f, m.skin_joints);
    Write(f, m.joint_from_bind);
    if (!f) {
      f.close();
      std::filesystem::remove(tmp, ec);
      return;
    }
  }
  std::filesystem::rename(tmp, file, ec);
  if (ec) std::filesystem::remove(tmp, ec);
}

}  // namespace

base::Result<SkinnedMesh> BuildGeneratedBody(const mocap::Skeleton& skeleton,
                                             std::span<const glm::mat4> rest_model_from_joint,
                                             const GeneratedBodyOptions& o) {
  base::Result<ImplicitBody> shape = BuildImplicitBody(skeleton, rest_model_from_joint, o.shape);
  if (!shape.ok()) return std::move(shape).error();
  base::Result<Mesh> mesh = MeshImplicitBody(*shape, o.mesh);
  if (!mesh.ok()) return std::move(mesh).error();
  const ImplicitBody& body = *shape;
  base::Result<BoneHeatWeights> heat = ComputeBoneHeatWeights(
      *mesh, body.bones(), [&body](const glm::vec3& p) { return body.Distance(p); }, body.size(),
      o.weights);
  if (!heat.ok()) return std::move(heat).error();

  SkinnedMesh out;
  const int nj = skeleton.num_joints();
  std::vector<int> skin_of(static_cast<std::size_t>(nj), -1);
  for (const int j : heat->joints) {
    if (j >= 0) skin_of[static_cast<std::size_t>(j)] = 0;
  }
  for (int j = 0; j < nj; ++j) {
    if (skin_of[static_cast<std::size_t>(j)] < 0) continue;
    skin_of[static_cast<std::size_t>(j)] = static_cast<int>(out.skin_joints.size());
    out.skin_joints.push_back(j);
    out.joint_from_bind.push_back(glm::inverse(rest_model_from_joint[static_cast<std::size_t>(j)]));
  }
  const auto m = static_cast<std::size_t>(heat->influences);
  const std::size_t nv = mesh->positions.size();
  out.weights.influences = 4;
  out.weights.joints.assign(nv * 4, 0);
  out.weights.weights.assign(nv * 4, 0.0f);
  for (std::size_t v = 0; v < nv; ++v) {
    // Unused slots repeat the first joint with weight 0.
    const int first = skin_of[static_cast<std::size_t>(heat->joints[v * m])];
    for (std::size_t s = 0; s < 4; ++s) {
      const int j = s < m ? heat->joints[v * m + s] : -1;
      out.weights.joints[v * 4 + s] = static_cast<std::uint16_t>(j >= 0 ? skin_of[static_cast<std::size_t>(j)] : first);
      out.weights.weights[v * 4 + s] = j >= 0 ? heat->weights[v * m + s] : 0.0f;
    }
  }
  NormalizeSkinWeights(out.weights);
  out.bind = std::move(*mesh);
  return out;
}

std::uint64_t GeneratedBodyKey(const mocap::Skeleton& skeleton, std::span<const glm::mat4> rest_model_from_joint,
                               const GeneratedBodyOptions& o) {
  Hasher h;
  h.Add(kCacheVersion);
  h.Add(skeleton.num_joints());
  for (const auto p : skeleton.parents) h.Add(p);
  h.Add(skeleton.info.up_axis);
  h.Add(skeleton.end_sites.size());
  for (const mocap::EndSite& e : skeleton.end_sites) h.Add(e.parent), h.Add(e.offset);
  // Which joints are body: the only thing the channels and the motion's use of
  // them change (so captures of one skeleton share a body whatever they do).
  base::Result<std::vector<std::uint8_t>> body =
      BodyPartJoints(skeleton, rest_model_from_joint, o.shape.min_branch_extent);
  if (body.ok()) {
    for (const std::uint8_t b : *body) h.Add(b);
  }
  h.Add(rest_model_from_joint.size());
  for (const glm::mat4& m : rest_model_from_joint) h.Add(m);
  h.Add(o.shape.min_branch_extent), h.Add(o.shape.blend), h.Add(o.shape.radius_scale);
  h.Add(o.mesh.voxels_per_size), h.Add(o.mesh.band_voxels), h.Add(o.mesh.adaptivity);
  h.Add(o.mesh.smoothing_passes), h.Add(o.mesh.max_triangles);
  h.Add(o.weights.heat), h.Add(o.weights.max_influences), h.Add(o.weights.inside_tolerance);
  return h.value();
}

std::filesystem::path BodyCacheFolder() {
  if (const char* dir = std::getenv("PATCHSKIN_CACHE_DIR")) {
    if (std::string(dir) == "off" || std::string(dir).empty()) return {};
    return dir;
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && xdg[0] != '\0') {
    return std::filesystem::path(xdg) / "patchskin";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && home[0] != '\0') {
    return std::filesystem::path(home) / ".cache" / "patchskin";
  }
  return {};
}

base::Result<SkinnedMesh> BuildGeneratedBodyCached(const mocap::Skeleton& skeleton,
                                                   std::span<const glm::mat4> rest_model_from_joint,
                                                   const GeneratedBodyOptions& options,
                                                   const std::filesystem::path& folder,
                                                   bool* from_cache) {
  if (from_cache != nullptr) *from_cache = false;
  if (folder.empty() || rest_model_from_joint.size() != static_cast<std::size_t>(skeleton.num_joints())) {
    return BuildGeneratedBody(skeleton, rest_model_from_joint, options);
  }
  const std::uint64_t key = GeneratedBodyKey(skeleton, rest_model_from_joint, options);
  char name[40];
  std::snprintf(name, sizeof(name), "body-%016llx.bin", static_cast<unsigned long long>(key));
  const std::filesystem::path file = folder / name;
  SkinnedMesh cached;
  if (ReadCache(file, key, skeleton.num_joints(), cached)) {
    if (from_cache != nullptr) *from_cache = true;
    return cached;
  }
  base::Result<SkinnedMesh> body = BuildGeneratedBody(skeleton, rest_model_from_joint, options);
  if (body.ok()) WriteCache(folder, file, key, *body);
  return body;
}

}  // namespace deform
