// Parsing of a rig patch's `examples` and `pose_space` (docs/rig-file.md),
// apart from app/rig_examples.cpp's building so the rig reader (patchskin_rig)
// needs neither the deformation nor the renderer.
#include "app/internal/rig_examples_parse.h"

#include <cmath>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/internal/json_describe.h"
#include "app/rig_file.h"

namespace app {
namespace {

using nlohmann::json;

// Most examples per patch and edits per example a rig may hold (the RBF takes
// at most deform::kMaxRbfCentres centres; edits beyond the free control points
// cannot all be met anyway).
constexpr std::size_t kMaxExamples = 64;
constexpr std::size_t kMaxEdits = 256;
// Largest |component| of a move (model units) and of a joint angle (degrees).
constexpr double kMaxMove = 1e6;
constexpr double kMaxAngleDeg = 360.0;
// Range of a brush edit's radius, in the patch's (u, v) units.
constexpr double kMinBrushRadius = 0.01;
constexpr double kMaxBrushRadius = 2.0;

bool NumberIn(const json& v, double lo, double hi) {
  return v.is_number() && std::isfinite(v.get<double>()) && v.get<double>() >= lo &&
         v.get<double>() <= hi;
}

std::optional<base::Error> GetVec(const JsonFile& c, const json& v, const std::string& path,
                                  std::size_t n, double lo, double hi, double* out) {
  std::ostringstream what;
  what << "an array of " << n << " numbers in " << lo << ".." << hi;
  if (!v.is_array() || v.size() != n) return c.Expected(path, what.str(), v);
  for (std::size_t i = 0; i < n; ++i) {
    if (!NumberIn(v[i], lo, hi)) return c.Expected(path, what.str(), v);
    out[i] = v[i].get<double>();
  }
  return std::nullopt;
}

std::optional<base::Error> ParsePose(const JsonFile& c, const json& v, const std::string& path,
                                     RigExamplePose& pose) {
  if (auto e = c.Keys(v, path, {"frame", "joints"})) return e;
  if (v.contains("frame") == v.contains("joints")) {
    return c.Fail(path, "expected exactly one of \"frame\" (a frame of the motion) or \"joints\" "
                        "(joint name -> [x, y, z] degrees)");
  }
  if (v.contains("frame")) {
    const json& f = v["frame"];
    if (!f.is_number_integer() || f.get<long long>() < 0 || f.get<long long>() > 100000000) {
      return c.Expected(path + ".frame", "a frame index (integer >= 0)", f);
    }
    pose.frame = f.get<int>();
    return std::nullopt;
  }
  const json& joints = v["joints"];
  if (!joints.is_object() || joints.empty()) {
    return c.Expected(path + ".joints", "an object of joint name -> [x, y, z] degrees", joints);
  }
  for (const auto& [name, angles] : joints.items()) {
    double a[3];
    if (auto e = GetVec(c, angles, path + ".joints." + name, 3, -kMaxAngleDeg, kMaxAngleDeg, a)) {
      return e;
    }
    pose.joints.emplace_back(name, glm::vec3(glm::dvec3(a[0], a[1], a[2])));
  }
  return std::nullopt;
}

std::optional<base::Error> ParseEdit(const JsonFile& c, const json& v, const std::string& path,
                                     RigEdit& edit) {
  if (auto e = c.Keys(v, path, {"vertex", "point", "move", "frame", "radius"})) return e;
  edit.path = path;
  if (v.contains("vertex") == v.contains("point")) {
    return c.Fail(path, "expected exactly one of \"vertex\" (a mesh vertex index) or \"point\" "
                        "([u, v] on the patch)");
  }
  if (v.contains("vertex")) {
    const json& i = v["vertex"];
    if (!i.is_number_integer() || i.get<long long>() < 0 || i.get<long long>() > 100000000) {
      return c.Expected(path + ".vertex", "a vertex index (integer >= 0)", i);
    }
    edit.vertex = i.get<int>();
  } else {
    double uv[2];
    if (auto e = GetVec(c, v["point"], path + ".point", 2, 0.0, 1.0, uv)) return e;
    edit.point = {uv[0], uv[1]};
  }
  if (!v.contains("move")) return c.Fail(path + ".move", "missing ([dx, dy, dz] model units)");
  double m[3];
  if (auto e = GetVec(c, v["move"], path + ".move", 3, -kMaxMove, kMaxMove, m)) return e;
  edit.move = {m[0], m[1], m[2]};
  if (v.contains("frame")) {
    const json& f = v["frame"];
    if (!f.is_string() || (f.get<std::string>() != "bind" && f.get<std::string>() != "world")) {
      return c.Expected(path + ".frame", "\"bind\" or \"world\"", f);
    }
    edit.world = f.get<std::string>() == "world";
  }
  if (v.contains("radius")) {
    // Parameter units of the patch's (u, v) square: a brush (issue 26).
    if (!NumberIn(v["radius"], kMinBrushRadius, kMaxBrushRadius)) {
      return c.Expected(path + ".radius", "a brush radius in 0.01..2 ((u, v) units)", v["radius"]);
    }
    edit.radius = v["radius"].get<double>();
  }
  return std::nullopt;
}

std::optional<base::Error> ParsePoseSpace(const JsonFile& c, const json& v, const std::string& path,
                                          RigPoseSpace& ps) {
  if (auto e = c.Keys(v, path, {"features", "kernel", "kappa", "width", "joints"})) return e;
  auto choice = [&](const char* key, std::initializer_list<const char*> options,
                    std::string& out) -> std::optional<base::Error> {
    if (!v.contains(key)) return std::nullopt;
    std::string list;
    bool found = false;
    for (const char* o : options) {
      list += std::string(list.empty() ? "" : ", ") + '"' + o + '"';
      if (v[key].is_string() && v[key].get<std::string>() == o) {
        out = o;
        found = true;
      }
    }
    if (!found) return c.Expected(path + "." + key, "one of " + list, v[key]);
    return std::nullopt;
  };
  if (auto e = choice("features", {"euler", "rotvec", "swingtwist"}, ps.features)) return e;
  if (auto e = choice("kernel", {"gaussian", "inverse-multiquadric", "multiquadric", "polyharmonic3"},
                      ps.kernel)) {
    return e;
  }
  if (v.contains("kappa")) {
    if (!NumberIn(v["kappa"], 1e-3, 10.0) || v["kappa"].get<double>() <= 0.0) {
      return c.Expected(path + ".kappa", "a number in 0.001..10", v["kappa"]);
    }
    ps.kappa = v["kappa"].get<double>();
  }
  if (v.contains("width")) {
    if (!NumberIn(v["width"], 0.0, 100.0)) {
      return c.Expected(path + ".width", "a number in 0..100 (radians; 0 = automatic)", v["width"]);
    }
    ps.width = v["width"].get<double>();
  }
  if (v.contains("joints")) {
    const json& list = v["joints"];
    if (!list.is_array() || list.empty()) {
      return c.Expected(path + ".joints", "a non-empty array of joint names", list);
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (!list[i].is_string() || list[i].get<std::string>().empty()) {
        return c.Expected(path + ".joints[" + std::to_string(i) + "]", "a joint name", list[i]);
      }
      ps.joints.push_back(list[i].get<std::string>());
    }
  }
  return std::nullopt;
}

bool SamePose(const RigExamplePose& a, const RigExamplePose& b) {
  return a.frame == b.frame && a.joints == b.joints;
}

}  // namespace

namespace internal {

std::optional<base::Error> ParsePatchExamples(const std::string& file, const json& patch,
                                              const std::string& path, RigPatch& out) {
  const JsonFile c{file};
  if (patch.contains("pose_space")) {
    if (auto e = ParsePoseSpace(c, patch["pose_space"], path + ".pose_space", out.pose_space)) {
      return e;
    }
  }
  if (!patch.contains("examples")) return std::nullopt;
  const json& list = patch["examples"];
  const std::string lpath = path + ".examples";
  if (!list.is_array()) return c.Expected(lpath, "an array of examples", list);
  if (list.size() > kMaxExamples) {
    return c.Fail(lpath, "expected at most " + std::to_string(kMaxExamples) + " examples, found " +
                             std::to_string(list.size()));
  }
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string epath = lpath + "[" + std::to_string(k) + "]";
    const json& ex = list[k];
    if (auto e = c.Keys(ex, epath, {"pose", "edits", "auto"})) return e;
    RigExample example;
    example.path = epath;
    if (!ex.contains("pose")) return c.Fail(epath + ".pose", "missing ({\"frame\": N} or {\"joints\": {...}})");
    if (auto e = ParsePose(c, ex["pose"], epath + ".pose", example.pose)) return e;
    if (ex.contains("auto")) {
      const json& a = ex["auto"];
      if (!a.is_string() || (a.get<std::string>() != "volume" && a.get<std::string>() != "rest")) {
        return c.Expected(epath + ".auto", "\"volume\" or \"rest\"", a);
      }
      example.auto_kind = a.get<std::string>();
    }
    if (!ex.contains("edits") && !example.auto_kind.empty()) {
      for (const RigExample& other : out.examples) {
        if (SamePose(other.pose, example.pose)) {
          return c.Fail(epath + ".pose", "duplicates the pose of " + other.path +
                                             " (one example per pose: merge their edits)");
        }
      }
      out.examples.push_back(std::move(example));
      continue;
    }
    if (!ex.contains("edits")) {
      return c.Fail(epath + ".edits", "missing (an array of edits, or \"auto\": \"volume\" | \"rest\")");
    }
    const json& edits = ex["edits"];
    if (!edits.is_array() || edits.empty() || edits.size() > kMaxEdits) {
      return c.Expected(epath + ".edits", "an array of 1.." + std::to_string(kMaxEdits) + " edits",
                        edits);
    }
    for (std::size_t i = 0; i < edits.size(); ++i) {
      RigEdit edit;
      if (auto e = ParseEdit(c, edits[i], epath + ".edits[" + std::to_string(i) + "]", edit)) {
        return e;
      }
      example.edits.push_back(std::move(edit));
    }
    for (const RigExample& other : out.examples) {
      if (SamePose(other.pose, example.pose)) {
        return c.Fail(epath + ".pose", "duplicates the pose of " + other.path +
                                           " (one example per pose: merge their edits)");
      }
    }
    out.examples.push_back(std::move(example));
  }
  return std::nullopt;
}

}  // namespace internal

}  // namespace app
