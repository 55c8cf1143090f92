#include "app/rig_writer.h"

#include <charconv>
#include <filesystem>

#include <nlohmann/json.hpp>

namespace app {
namespace {

// The shortest decimal that reads back to this float.
std::string Num(float x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), x);
  return std::string(buf, r.ptr);
}

std::string Vec(glm::vec3 v) { return "[" + Num(v.x) + ", " + Num(v.y) + ", " + Num(v.z) + "]"; }
std::string Pair(glm::ivec2 v) {
  std::string s = "[";
  s += std::to_string(v.x);
  s += ", ";
  s += std::to_string(v.y);
  s += "]";
  return s;
}
std::string Str(const std::string& s) { return nlohmann::json(s).dump(); }

std::string RelativePath(const std::string& path, const std::string& folder) {
  namespace fs = std::filesystem;
  if (fs::path(path).is_absolute()) return fs::path(path).lexically_normal().generic_string();
  const fs::path abs = fs::absolute(path).lexically_normal();
  const fs::path base = fs::absolute(folder.empty() ? "." : folder).lexically_normal();
  const fs::path rel = abs.lexically_relative(base);
  return rel.empty() ? abs.generic_string() : rel.generic_string();
}

std::string Region(const RigRegion& r) {
  std::string s = "{";
  switch (r.kind) {
    case RigRegion::Kind::kJoint:
      s += "\"joint\": " + Str(r.joint) + ", \"radius\": " + Num(r.radius);
      if (r.side != glm::vec3(0.0f)) s += ", \"side\": " + Vec(r.side);
      if (r.half_angle_deg != 120.0f) s += ", \"half_angle_deg\": " + Num(r.half_angle_deg);
      if (r.min_bone_weight != 0.5f) s += ", \"min_bone_weight\": " + Num(r.min_bone_weight);
      break;
    case RigRegion::Kind::kVertices: {
      s += "\"vertices\": [";
      for (std::size_t i = 0; i < r.vertices.size(); ++i) {
        if (i > 0) s += ", ";
        s += std::to_string(r.vertices[i]);
      }
      s += "]";
      break;
    }
    case RigRegion::Kind::kScreen:
      s += "\"view\": " + Str(r.view) + ", \"rect\": [" + Num(r.rect.x) + ", " + Num(r.rect.y) +
           ", " + Num(r.rect.z) + ", " + Num(r.rect.w) + "]";
      break;
  }
  return s + "}";
}

// The elastic fields that differ from the defaults of an empty object.
std::string Elastic(const RigElastic& e) {
  const RigElastic d;
  const deform::MassSpringParams &p = e.params, &q = d.params;
  std::string s;
  const auto add = [&s](const char* key, const std::string& value) {
    s += std::string(s.empty() ? "" : ", ") + "\"" + key + "\": " + value;
  };
  if (!e.joint.empty()) add("joint", Str(e.joint));
  if (p.mass != q.mass) add("mass", Num(p.mass));
  if (p.frequency_hz != q.frequency_hz) add("frequency_hz", Num(p.frequency_hz));
  if (p.damping_ratio != q.damping_ratio) add("damping_ratio", Num(p.damping_ratio));
  if (p.structural_ratio != q.structural_ratio) add("structural_ratio", Num(p.structural_ratio));
  if (p.shear_ratio != q.shear_ratio) add("shear_ratio", Num(p.shear_ratio));
  if (p.bending_ratio != q.bending_ratio) add("bending_ratio", Num(p.bending_ratio));
  if (p.spring_damping_s != q.spring_damping_s) add("spring_damping_s", Num(p.spring_damping_s));
  if (p.time_step_s != q.time_step_s) add("time_step_s", nlohmann::json(p.time_step_s).dump());
  if (p.gain != q.gain) add("gain", Num(p.gain));
  if (p.gravity != q.gravity) add("gravity", p.gravity ? "true" : "false");
  if (p.preroll_s != q.preroll_s) add("preroll_s", nlohmann::json(p.preroll_s).dump());
  if (p.max_displacement != q.max_displacement) add("max_displacement", Num(p.max_displacement));
  if (p.max_acceleration_mps2 != q.max_acceleration_mps2) {
    add("max_acceleration_mps2", Num(p.max_acceleration_mps2));
  }
  if (e.units_per_metre != d.units_per_metre) add("units_per_metre", Num(e.units_per_metre));
  if (e.cutoff_hz != d.cutoff_hz) add("cutoff_hz", nlohmann::json(e.cutoff_hz).dump());
  if (p.force_model != q.force_model) {
    add("force_model", p.force_model == deform::SpringForceModel::kLength ? "\"length\"" : "\"linear\"");
  }
  return "{" + s + "}";
}

std::string Render(const RigRender& r, const std::string& folder) {
  std::string s = "{\"size\": " + Pair(r.size);
  std::string camera = "{\"mode\": " + Str(r.camera);
  if (r.azimuth_deg) camera += ", \"azimuth\": " + Num(*r.azimuth_deg);
  if (r.elevation_deg) camera += ", \"elevation\": " + Num(*r.elevation_deg);
  if (r.distance != 0.0f) camera += ", \"distance\": " + Num(r.distance);
  if (r.zoom != 1.0f) camera += ", \"zoom\": " + Num(r.zoom);
  if (!r.look_at.empty()) camera += ", \"look_at\": " + Str(r.look_at);
  s += ", \"camera\": " + camera + "}";
  if (!r.overlays.empty()) {
    s += ", \"overlays\": [";
    for (std::size_t i = 0; i < r.overlays.size(); ++i) s += (i ? ", " : "") + Str(r.overlays[i]);
    s += "]";
  }
  s += std::string(", \"split\": ") + (r.split ? "true" : "false");
  if (!r.compare.empty()) s += ", \"compare\": " + Str(r.compare);
  if (r.wipe) s += ", \"wipe\": true";
  if (!r.output.empty()) s += ", \"output\": " + Str(RelativePath(r.output, folder));
  if (!r.frames.empty()) s += ", \"frames\": " + Str(r.frames);
  return s + "}";
}

}  // namespace

base::Result<std::string> WriteRigJson(const Rig& rig, const std::string& folder) {
  std::string s = "{\n";
  s += "  \"character\": " +
       Str(IsBuiltInBody(rig.character) ? rig.character : RelativePath(rig.character, folder)) + ",\n";
  if (!rig.motion.empty()) {
    s += "  \"motion\": {\"file\": " + Str(RelativePath(rig.motion, folder));
    if (rig.fps != 0.0) s += ", \"fps\": " + nlohmann::json(rig.fps).dump();
    if (!rig.joint_map.empty()) s += ", \"joint_map\": " + Str(RelativePath(rig.joint_map, folder));
    if (!rig.up.empty()) s += ", \"up\": " + Str(rig.up);
    s += "},\n";
  }
  s += "  \"global\": " + Str(rig.global) + ",\n";
  s += "  \"patches\": [";
  for (std::size_t i = 0; i < rig.patches.size(); ++i) {
    const RigPatch& p = rig.patches[i];
    for (const RigExample& e : p.examples) {
      if (!e.edits.empty() || e.pose.frame < 0 || e.auto_kind.empty()) {
        return base::MakeError(
            base::ErrorCode::kUnsupported,
            {rig.file, 0, 0, "patches[" + std::to_string(i) + "].examples"},
            "only computed examples at a frame are written (no edits, no joint angles)");
      }
    }
    s += std::string(i ? "," : "") + "\n    {\"name\": " + Str(p.name) + ",\n";
    s += "     \"region\": " + Region(p.region) + ",\n";
    s += std::string("     \"parametrization\": ") + (p.cylinder ? "\"cylinder\"" : "\"plane\"") +
         ", \"grid\": " + Pair(p.grid) + ", \"sampling\": " + Pair(p.sampling) +
         ", \"border_width\": " + Num(p.border_width);
    if (p.elastic) s += ",\n     \"elastic\": " + Elastic(*p.elastic);
    if (!p.examples.empty()) {
      s += ",\n     \"examples\": [";
      for (std::size_t k = 0; k < p.examples.size(); ++k) {
        if (k > 0) s += ", ";
        s += "{\"pose\": {\"frame\": " + std::to_string(p.examples[k].pose.frame) +
             "}, \"auto\": " + Str(p.examples[k].auto_kind) + "}";
      }
      s += "]";
    }
    s += "}";
  }
  s += rig.patches.empty() ? "],\n" : "\n  ],\n";
  s += "  \"render\": " + Render(rig.render, folder) + "\n}\n";
  return s;
}

}  // namespace app
