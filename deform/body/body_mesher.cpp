#include "deform/body/body_mesher.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>

namespace deform {
namespace {

using base::ErrorCode;
using base::MakeError;

constexpr double kMaxVoxelTests = 40e6;

void InitializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

struct Box {
  openvdb::Coord lo, hi;
};

// Voxel index range of a primitive's box grown by `grow` (model units).
Box VoxelBox(const BodyPrimitive& s, double h, double grow) {
  const auto lo = [&](float v) { return static_cast<int>(std::floor((static_cast<double>(v) - grow) / h)); };
  const auto hi = [&](float v) { return static_cast<int>(std::ceil((static_cast<double>(v) + grow) / h)); };
  return {openvdb::Coord(lo(s.box_min.x), lo(s.box_min.y), lo(s.box_min.z)),
          openvdb::Coord(hi(s.box_max.x), hi(s.box_max.y), hi(s.box_max.z))};
}

double VoxelTests(const ImplicitBody& body, double h, double grow) {
  double total = 0.0;
  for (const BodyPrimitive& s : body.primitives()) {
    const Box b = VoxelBox(s, h, grow);
    total += static_cast<double>(b.hi.x() - b.lo.x() + 1) * static_cast<double>(b.hi.y() - b.lo.y() + 1) *
             static_cast<double>(b.hi.z() - b.lo.z() + 1);
  }
  return total;
}

openvdb::FloatGrid::Ptr SampleLevelSet(const ImplicitBody& body, double h, float band) {
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(band);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(h));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  openvdb::FloatGrid::Accessor acc = grid->getAccessor();
  // Candidates: the smooth union u lies between d_min - k/4 and d_min (d_min: the nearest
  // primitive's distance), so every voxel with |u| < band has some primitive with
  // -band < d < band + k/4.
  const float inner = -band;
  const float outer = band + 0.25f * body.max_blend();
  for (const BodyPrimitive& s : body.primitives()) {
    const Box b = VoxelBox(s, h, outer);
    for (int x = b.lo.x(); x <= b.hi.x(); ++x) {
      for (int y = b.lo.y(); y <= b.hi.y(); ++y) {
        for (int z = b.lo.z(); z <= b.hi.z(); ++z) {
          const glm::vec3 p(static_cast<float>(x * h), static_cast<float>(y * h), static_cast<float>(z * h));
          const float d = PrimitiveDistance(s, p);
          if (d < outer && d > inner) acc.setValueOn(openvdb::Coord(x, y, z), 0.0f);
        }
      }
    }
  }
  std::vector<openvdb::Coord> active;
  active.reserve(grid->activeVoxelCount());
  for (auto it = grid->tree().cbeginValueOn(); it; ++it) active.push_back(it.getCoord());
  for (const openvdb::Coord& c : active) {
    const glm::vec3 p(static_cast<float>(c.x() * h), static_cast<float>(c.y() * h), static_cast<float>(c.z() * h));
    // Every touched voxel stays active (clamped to the band): the flood fill below
    // takes signs from active voxels only, and a leaf without one would be filled from
    // its first voxel, possibly an untouched (outside-valued) one deep inside.
    acc.setValue(c, std::clamp(body.Distance(p), -band, band));
  }
  openvdb::tools::signedFloodFill(grid->tree());
  openvdb::tools::pruneLevelSet(grid->tree());
  return grid;
}

int FindRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

// Keeps the triangles of the connected piece with the most triangles (ties: the one
// holding the lowest vertex index) and drops unreferenced points.
void KeepLargestPiece(Mesh& mesh) {
  const std::size_t nv = mesh.positions.size();
  std::vector<int> parent(nv);
  std::iota(parent.begin(), parent.end(), 0);
  for (const glm::uvec3& t : mesh.triangles) {
    const int a = FindRoot(parent, static_cast<int>(t.x));
    const int b = FindRoot(parent, static_cast<int>(t.y));
    const int c = FindRoot(parent, static_cast<int>(t.z));
    parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    const int ab = FindRoot(parent, std::min(a, b));
    parent[static_cast<std::size_t>(std::max(ab, c))] = std::min(ab, c);
  }
  std::vector<int> count(nv, 0);
  for (const glm::uvec3& t : mesh.triangles) ++count[static_cast<std::size_t>(FindRoot(parent, static_cast<int>(t.x)))];
  const auto best = static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
  std::vector<glm::uvec3> kept;
  std::vector<std::int64_t> remap(nv, -1);
  std::vector<glm::vec3> positions;
  for (const glm::uvec3& t : mesh.triangles) {
    if (FindRoot(parent, static_cast<int>(t.x)) != best) continue;
    glm::uvec3 u;
    for (int i = 0; i < 3; ++i) {
      std::int64_t& r = remap[t[i]];
      if (r < 0) r = static_cast<std::int64_t>(positions.size()), positions.push_back(mesh.positions[t[i]]);
      u[i] = static_cast<std::uint32_t>(r);
    }
    kept.push_back(u);
  }
  mesh.positions = std::move(positions);
  mesh.triangles = std::move(kept);
}

// Meshes the body at voxel size h: level set, optional smoothing, volumeToMesh, quads
// split along their shorter diagonal.
base::Result<Mesh> MeshAtVoxelSize(const ImplicitBody& implicit, double h,
                                   const BodyMeshOptions& o) {
  const auto band = static_cast<float>(o.band_voxels * h);
  openvdb::FloatGrid::Ptr grid = SampleLevelSet(implicit, h, band);
  if (o.smoothing_passes > 0) {
    openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*grid);
    for (int i = 0; i < o.smoothing_passes; ++i) filter.meanCurvature();
  }

  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, points, tris, quads, 0.0, static_cast<double>(o.adaptivity));
  if (tris.size() + 2 * quads.size() > 4 * static_cast<std::size_t>(o.max_triangles)) {  // before a re-mesh
    return MakeError(ErrorCode::kLimitExceeded, {},
                     "the body mesh has " + std::to_string(tris.size() + 2 * quads.size()) +
                         " triangles, more than " + std::to_string(o.max_triangles));
  }
  Mesh mesh;
  mesh.positions.reserve(points.size());
  for (const openvdb::Vec3s& p : points) mesh.positions.emplace_back(p.x(), p.y(), p.z());
  mesh.triangles.reserve(tris.size() + 2 * quads.size());
  for (const openvdb::Vec3I& t : tris) mesh.triangles.emplace_back(t.x(), t.y(), t.z());
  const auto at = [&mesh](unsigned i) { return mesh.positions[i]; };
  for (const openvdb::Vec4I& q : quads) {
    if (glm::distance(at(q[0]), at(q[2])) <= glm::distance(at(q[1]), at(q[3]))) {
      mesh.triangles.emplace_back(q[0], q[1], q[2]);
      mesh.triangles.emplace_back(q[0], q[2], q[3]);
    } else {
      mesh.triangles.emplace_back(q[0], q[1], q[3]);
      mesh.triangles.emplace_back(q[1], q[2], q[3]);
    }
  }
  if (mesh.triangles.empty()) {
    return base::InvalidArgument("the implicit body has no surface at this voxel size");
  }
  return mesh;
}

}  // namespace

base::Result<Mesh> MeshImplicitBody(const ImplicitBody& body, const BodyMeshOptions& o) {
  if (!(o.voxels_per_size >= 32.0f && o.voxels_per_size <= 512.0f) || !(o.band_voxels >= 2.0f && o.band_voxels <= 6.0f) ||
      !(o.adaptivity >= 0.0f && o.adaptivity <= 1.0f) || o.smoothing_passes < 0 || o.smoothing_passes > 8 ||
      o.max_triangles < 1000) {
    return base::InvalidArgument(
        "body mesh options out of range (voxels_per_size 32..512, band_voxels 2..6, "
        "adaptivity 0..1, smoothing_passes 0..8, max_triangles >= 1000)");
  }
  if (body.primitives().empty() || !(body.size() > 0.0f)) {
    return base::InvalidArgument("the implicit body is empty");
  }
  InitializeOpenVdb();
  // The skeleton's scale sets the voxel; a body whose parts are huge next to S (joints
  // kilometres apart) coarsens it until the band fits the budget.
  double h = static_cast<double>(body.size()) / static_cast<double>(o.voxels_per_size);
  for (int tries = 0; VoxelTests(body, h, o.band_voxels * h + 0.25 * body.max_blend()) > kMaxVoxelTests; ++tries) {
    if (tries == 6) {
      return MakeError(ErrorCode::kLimitExceeded, {},
                       "the body's parts span too many voxels to mesh (more than " +
                           std::to_string(static_cast<long long>(kMaxVoxelTests)) + " voxel tests)");
    }
    h *= 1.25;
  }
  base::Result<Mesh> meshed = MeshAtVoxelSize(body, h, o);
  if (!meshed.ok()) return meshed;
  // Aim at the triangle budget: one more pass at the voxel size that scales the count
  // to the target (triangles go as 1 / h^2) when the first is more than 40 % off.
  if (o.target_triangles > 0) {
    const double ratio = static_cast<double>(meshed->num_triangles()) / static_cast<double>(o.target_triangles);
    if (ratio > 1.4 || ratio < 1.0 / 1.4) {
      const double h2 = h * std::sqrt(ratio);
      if (VoxelTests(body, h2, o.band_voxels * h2 + 0.25 * body.max_blend()) <= kMaxVoxelTests) {
        meshed = MeshAtVoxelSize(body, h2, o);
        if (!meshed.ok()) return meshed;
      }
    }
  }
  Mesh& mesh = *meshed;
  if (mesh.num_triangles() > o.max_triangles) {
    return MakeError(ErrorCode::kLimitExceeded, {},
                     "the body mesh has " + std::to_string(mesh.num_triangles()) + " triangles, more than " +
                         std::to_string(o.max_triangles));
  }
  const auto at = [&mesh](unsigned i) { return mesh.positions[i]; };
  KeepLargestPiece(mesh);
  // Outward orientation: the enclosed volume must be positive.
  double volume = 0.0;
  const glm::dvec3 origin(at(0));
  for (const glm::uvec3& t : mesh.triangles) {
    volume += glm::dot(glm::dvec3(at(t.x)) - origin,
                       glm::cross(glm::dvec3(at(t.y)) - origin, glm::dvec3(at(t.z)) - origin));
  }
  if (volume < 0.0) {
    for (glm::uvec3& t : mesh.triangles) std::swap(t.y, t.z);
  }
  mesh.normals.resize(mesh.positions.size());
  ComputeVertexNormals(mesh.positions, mesh.triangles, mesh.normals);
  return meshed;
}

}  // namespace deform
