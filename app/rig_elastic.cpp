#include "app/internal/rig_elastic_parse.h"

#include <cmath>
#include <sstream>

#include <nlohmann/json.hpp>

namespace app {
namespace {

using nlohmann::json;

// The parsing context of one "elastic" object: messages in the form of
// rig_file.cpp's ("r.json: patches[0].elastic.gain: error: expected ...").
struct ElasticCtx {
  const std::string& file;
  const std::string& path;

  std::string Field(const std::string& key) const { return path + "." + key; }
  base::Error Fail(const std::string& field, const std::string& message) const {
    return base::InvalidArgument({file, 0, 0, field}, message);
  }
  base::Error Expected(const std::string& field, const std::string& what, const json& found) const {
    std::string s = found.dump();
    if (s.size() > 40) s = s.substr(0, 37) + "...";
    if (found.is_object()) s = "an object";
    if (found.is_array()) s = "an array " + s;
    return Fail(field, "expected " + what + ", found " + s);
  }

  // `key` (when present) as a number in [lo, hi].
  std::optional<base::Error> Number(const json& obj, const char* key, double lo, double hi,
                                    double& out) const {
    if (!obj.contains(key)) return std::nullopt;
    const json& v = obj[key];
    std::ostringstream range;
    range << "a number in " << lo << ".." << hi;
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo ||
        v.get<double>() > hi) {
      return Expected(Field(key), range.str(), v);
    }
    out = v.get<double>();
    return std::nullopt;
  }
  std::optional<base::Error> Number(const json& obj, const char* key, double lo, double hi,
                                    float& out) const {
    double d = out;
    if (auto e = Number(obj, key, lo, hi, d)) return e;
    out = static_cast<float>(d);
    return std::nullopt;
  }
};

}  // namespace

float UnitsPerMetre(const std::string& detected_units, float rest_height) {
  if (detected_units == "m") return 1.0f;
  if (detected_units == "inch") return 39.37f;
  if (detected_units == "cm") return 100.0f;
  constexpr float kHumanHeightM = 1.7f;
  return rest_height > 0.0f ? rest_height / kHumanHeightM : 100.0f;
}

std::optional<base::Error> ParseRigElastic(const json& v, const std::string& file,
                                           const std::string& path, int grid_u, int grid_v,
                                           RigElastic& out) {
  const ElasticCtx c{file, path};
  static constexpr const char* kFields[] = {
      "joint",          "mass",          "frequency_hz",     "damping_ratio",
      "structural_ratio", "shear_ratio", "bending_ratio",    "spring_damping_s",
      "time_step_s",    "gain",          "gravity",          "preroll_s",
      "max_displacement", "max_acceleration_mps2", "units_per_metre", "cutoff_hz",
      "force_model"};
  if (!v.is_object()) return c.Expected(path, "an object", v);
  for (const auto& [key, value] : v.items()) {
    bool known = false;
    for (const char* f : kFields) known = known || key == f;
    if (!known) {
      std::string list;
      for (const char* f : kFields) list += std::string(list.empty() ? "" : ", ") + f;
      return c.Fail(c.Field(key), "unknown field (expected one of: " + list + ")");
    }
  }
  if (grid_u > 16 || grid_v > 16) {
    return c.Fail(path, "expected a grid of at most 16x16 control points for an elastic patch, "
                        "found " + std::to_string(grid_u) + "x" + std::to_string(grid_v));
  }
  RigElastic e;
  deform::MassSpringParams& p = e.params;
  if (v.contains("joint")) {
    if (!v["joint"].is_string() || v["joint"].get<std::string>().empty()) {
      return c.Expected(c.Field("joint"), "a non-empty string", v["joint"]);
    }
    e.joint = v["joint"].get<std::string>();
  }
  if (auto err = c.Number(v, "mass", 1e-3, 1e3, p.mass)) return err;
  if (auto err = c.Number(v, "frequency_hz", 0.1, 30, p.frequency_hz)) return err;
  if (auto err = c.Number(v, "damping_ratio", 0, 10, p.damping_ratio)) return err;
  if (auto err = c.Number(v, "structural_ratio", 0, 100, p.structural_ratio)) return err;
  if (auto err = c.Number(v, "shear_ratio", 0, 100, p.shear_ratio)) return err;
  if (auto err = c.Number(v, "bending_ratio", 0, 100, p.bending_ratio)) return err;
  if (auto err = c.Number(v, "spring_damping_s", 0, 0.1, p.spring_damping_s)) return err;
  if (auto err = c.Number(v, "time_step_s", 1e-4, 0.05, p.time_step_s)) return err;
  if (auto err = c.Number(v, "gain", 0, 100, p.gain)) return err;
  if (v.contains("gravity")) {
    if (!v["gravity"].is_boolean()) return c.Expected(c.Field("gravity"), "true or false", v["gravity"]);
    p.gravity = v["gravity"].get<bool>();
  }
  if (auto err = c.Number(v, "preroll_s", 0, 60, p.preroll_s)) return err;
  if (auto err = c.Number(v, "max_displacement", 0, 1e6, p.max_displacement)) return err;
  if (auto err = c.Number(v, "max_acceleration_mps2", 1, 1e5, p.max_acceleration_mps2)) return err;
  if (auto err = c.Number(v, "units_per_metre", 0, 1e6, e.units_per_metre)) return err;
  if (auto err = c.Number(v, "cutoff_hz", 0, 1000, e.cutoff_hz)) return err;
  if (v.contains("force_model")) {
    const json& f = v["force_model"];
    if (!f.is_string() || (f.get<std::string>() != "linear" && f.get<std::string>() != "length")) {
      return c.Expected(c.Field("force_model"), "one of \"linear\", \"length\"", f);
    }
    p.force_model = f.get<std::string>() == "linear" ? deform::SpringForceModel::kLinear
                                                     : deform::SpringForceModel::kLength;
  }
  out = std::move(e);
  return std::nullopt;
}

}  // namespace app
