#include "app/rig_file.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/internal/json_describe.h"
#include "app/internal/rig_elastic_parse.h"
#include "app/internal/rig_examples_parse.h"
#include "app/output_guard.h"

namespace app {
namespace {

using nlohmann::json;

// Parsing context: the file name and the error to return.
std::string Join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

// Checks `obj` is an object with only `allowed` keys.
std::optional<base::Error> CheckObject(const JsonFile& c, const json& obj, const std::string& path,
                                       std::initializer_list<const char*> allowed) {
  return c.Keys(obj, path, allowed, "rig");
}

std::optional<base::Error> GetNumber(const JsonFile& c, const json& v, const std::string& path,
                                     double lo, double hi, double& out) {
  std::ostringstream range;
  range << "a number in " << lo << ".." << hi;
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo ||
      v.get<double>() > hi) {
    return c.Expected(path, range.str(), v);
  }
  out = v.get<double>();
  return std::nullopt;
}

std::optional<base::Error> GetFloat(const JsonFile& c, const json& v, const std::string& path,
                                    double lo, double hi, float& out) {
  double d = 0.0;
  if (auto e = GetNumber(c, v, path, lo, hi, d)) return e;
  out = static_cast<float>(d);
  return std::nullopt;
}

std::optional<base::Error> GetString(const JsonFile& c, const json& v, const std::string& path,
                                     std::string& out) {
  if (!v.is_string() || v.get<std::string>().empty()) return c.Expected(path, "a non-empty string", v);
  out = v.get<std::string>();
  return std::nullopt;
}

std::optional<base::Error> GetChoice(const JsonFile& c, const json& v, const std::string& path,
                                     std::initializer_list<const char*> choices, std::string& out) {
  std::string list;
  bool ok = false;
  for (const char* ch : choices) {
    list += std::string(list.empty() ? "" : ", ") + '"' + ch + '"';
    ok = ok || (v.is_string() && v.get<std::string>() == ch);
  }
  if (!ok) return c.Expected(path, "one of " + list, v);
  out = v.get<std::string>();
  return std::nullopt;
}

std::optional<base::Error> GetIntPair(const JsonFile& c, const json& v, const std::string& path,
                                      int lo, int hi, glm::ivec2& out) {
  const std::string what =
      "an array of two integers in " + std::to_string(lo) + ".." + std::to_string(hi);
  if (!v.is_array() || v.size() != 2 || !v[0].is_number_integer() || !v[1].is_number_integer()) {
    return c.Expected(path, what, v);
  }
  const auto a = v[0].get<long long>(), b = v[1].get<long long>();
  if (a < lo || a > hi || b < lo || b > hi) return c.Expected(path, what, v);
  out = {static_cast<int>(a), static_cast<int>(b)};
  return std::nullopt;
}

template <int N>
std::optional<base::Error> GetFloats(const JsonFile& c, const json& v, const std::string& path,
                                     double lo, double hi, glm::vec<N, float>& out) {
  std::ostringstream what;
  what << "an array of " << N << " numbers in " << lo << ".." << hi;
  if (!v.is_array() || v.size() != N) return c.Expected(path, what.str(), v);
  for (int i = 0; i < N; ++i) {
    const json& e = v[static_cast<std::size_t>(i)];
    if (!e.is_number() || !std::isfinite(e.get<double>()) || e.get<double>() < lo ||
        e.get<double>() > hi) {
      return c.Expected(path, what.str(), v);
    }
    out[i] = e.get<float>();
  }
  return std::nullopt;
}

std::string Resolve(const std::string& rig_file, const std::string& path) {
  const std::filesystem::path p(path);
  if (p.is_absolute()) return path;
  return (std::filesystem::path(rig_file).parent_path() / p).lexically_normal().string();
}

std::optional<base::Error> ParseRegion(const JsonFile& c, const json& v, const std::string& path,
                                       RigRegion& r) {
  if (auto e = CheckObject(c, v, path, {"joint", "radius", "side", "half_angle_deg",
                                        "min_bone_weight", "vertices", "view", "rect"})) {
    return e;
  }
  const int kinds = static_cast<int>(v.contains("joint")) + static_cast<int>(v.contains("vertices")) +
                    static_cast<int>(v.contains("view"));
  if (kinds != 1) {
    return c.Fail(path, "expected exactly one of \"joint\" (with \"radius\"), \"vertices\" or "
                        "\"view\" (with \"rect\")");
  }
  if (v.contains("joint")) {
    r.kind = RigRegion::Kind::kJoint;
    if (auto e = GetString(c, v["joint"], path + ".joint", r.joint)) return e;
    if (!v.contains("radius")) return c.Fail(path + ".radius", "missing (model units, > 0)");
    if (auto e = GetFloat(c, v["radius"], path + ".radius", 1e-6, 1e6, r.radius)) return e;
    if (v.contains("side")) {
      if (auto e = GetFloats<3>(c, v["side"], path + ".side", -1e6, 1e6, r.side)) return e;
    }
    if (v.contains("half_angle_deg")) {
      if (auto e = GetFloat(c, v["half_angle_deg"], path + ".half_angle_deg", 1, 180,
                            r.half_angle_deg)) {
        return e;
      }
    }
    if (v.contains("min_bone_weight")) {
      if (auto e = GetFloat(c, v["min_bone_weight"], path + ".min_bone_weight", 0.01, 1,
                            r.min_bone_weight)) {
        return e;
      }
    }
    for (const char* other : {"vertices", "view", "rect"}) {
      if (v.contains(other)) return c.Fail(Join(path, other), "not allowed with \"joint\"");
    }
  } else if (v.contains("vertices")) {
    r.kind = RigRegion::Kind::kVertices;
    const json& list = v["vertices"];
    if (!list.is_array() || list.size() < 3) {
      return c.Expected(path + ".vertices", "an array of at least 3 vertex indices", list);
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (!list[i].is_number_integer() || list[i].get<long long>() < 0 ||
          list[i].get<long long>() > 100000000) {
        return c.Expected(path + ".vertices[" + std::to_string(i) + "]",
                          "a vertex index (integer >= 0)", list[i]);
      }
      r.vertices.push_back(list[i].get<int>());
    }
    for (const char* other : {"radius", "side", "half_angle_deg", "min_bone_weight", "rect"}) {
      if (v.contains(other)) return c.Fail(Join(path, other), "not allowed with \"vertices\"");
    }
  } else {
    r.kind = RigRegion::Kind::kScreen;
    if (auto e = GetChoice(c, v["view"], path + ".view", {"front", "back", "left", "right"},
                           r.view)) {
      return e;
    }
    if (!v.contains("rect")) return c.Fail(path + ".rect", "missing ([x0, y0, x1, y1] in 0..1)");
    if (auto e = GetFloats<4>(c, v["rect"], path + ".rect", 0, 1, r.rect)) return e;
    if (!(r.rect.x < r.rect.z && r.rect.y < r.rect.w)) {
      return c.Expected(path + ".rect", "x0 < x1 and y0 < y1", v["rect"]);
    }
  }
  return std::nullopt;
}

std::optional<base::Error> ParsePatch(const JsonFile& c, const json& v, const std::string& path,
                                      RigPatch& p) {
  if (auto e = CheckObject(c, v, path, {"name", "region", "parametrization", "sampling", "grid",
                                        "border_width", "examples", "pose_space", "elastic"})) {
    return e;
  }
  if (!v.contains("name")) return c.Fail(path + ".name", "missing (a non-empty string)");
  if (auto e = GetString(c, v["name"], path + ".name", p.name)) return e;
  if (!v.contains("region")) return c.Fail(path + ".region", "missing (an object)");
  if (auto e = ParseRegion(c, v["region"], path + ".region", p.region)) return e;
  if (v.contains("parametrization")) {
    std::string kind;
    if (auto e = GetChoice(c, v["parametrization"], path + ".parametrization",
                           {"cylinder", "plane"}, kind)) {
      return e;
    }
    p.cylinder = kind == "cylinder";
  }
  if (v.contains("grid")) {
    if (auto e = GetIntPair(c, v["grid"], path + ".grid", 4, 64, p.grid)) return e;
  }
  if (v.contains("sampling")) {
    if (auto e = GetIntPair(c, v["sampling"], path + ".sampling", 4, 256, p.sampling)) return e;
  }
  if (p.sampling.x < p.grid.x || p.sampling.y < p.grid.y) {
    return c.Fail(path + ".sampling", "expected at least the grid (" + std::to_string(p.grid.x) +
                                          "x" + std::to_string(p.grid.y) + ") each way, found " +
                                          std::to_string(p.sampling.x) + "x" +
                                          std::to_string(p.sampling.y));
  }
  if (v.contains("border_width")) {
    if (auto e = GetFloat(c, v["border_width"], path + ".border_width", 0, 0.5, p.border_width)) {
      return e;
    }
  }
  if (v.contains("elastic")) {
    p.elastic.emplace();
    if (auto e = ParseRigElastic(v["elastic"], c.file, Join(path, "elastic"), p.grid.x, p.grid.y,
                                 *p.elastic)) {
      return e;
    }
  }
  return internal::ParsePatchExamples(c.file, v, path, p);
}

// render.camera: a mode string, or an object of the mode and the view.
std::optional<base::Error> ParseCamera(const JsonFile& c, const json& v, RigRender& r) {
  const std::initializer_list<const char*> modes = {"follow", "fixed", "turntable"};
  if (v.is_string()) return GetChoice(c, v, "render.camera", modes, r.camera);
  if (auto e = CheckObject(c, v, "render.camera",
                           {"mode", "azimuth", "elevation", "distance", "zoom", "look_at"})) {
    return e;
  }
  if (v.contains("mode")) {
    if (auto e = GetChoice(c, v["mode"], "render.camera.mode", modes, r.camera)) return e;
  }
  float value = 0.0f;
  if (v.contains("azimuth")) {
    if (auto e = GetFloat(c, v["azimuth"], "render.camera.azimuth", -3600, 3600, value)) return e;
    r.azimuth_deg = value;
  }
  if (v.contains("elevation")) {
    if (auto e = GetFloat(c, v["elevation"], "render.camera.elevation", -89, 89, value)) return e;
    r.elevation_deg = value;
  }
  if (v.contains("distance")) {
    if (auto e = GetFloat(c, v["distance"], "render.camera.distance", 0, 1e9, r.distance)) return e;
  }
  if (v.contains("zoom")) {
    if (auto e = GetFloat(c, v["zoom"], "render.camera.zoom", 1e-3, 1000, r.zoom)) return e;
  }
  if (v.contains("look_at")) {
    if (auto e = GetString(c, v["look_at"], "render.camera.look_at", r.look_at)) return e;
  }
  return std::nullopt;
}

std::optional<base::Error> ParseRender(const JsonFile& c, const json& v, RigRender& r) {
  if (auto e = CheckObject(c, v, "render",
                           {"size", "camera", "overlays", "split", "compare", "wipe", "output",
                            "frames"})) {
    return e;
  }
  if (v.contains("size")) {
    if (auto e = GetIntPair(c, v["size"], "render.size", 16, 16384, r.size)) return e;
  }
  if (v.contains("camera")) {
    if (auto e = ParseCamera(c, v["camera"], r)) return e;
  }
  if (v.contains("overlays")) {
    const json& list = v["overlays"];
    if (!list.is_array()) return c.Expected("render.overlays", "an array of strings", list);
    for (std::size_t i = 0; i < list.size(); ++i) {
      std::string item;
      if (auto e = GetChoice(c, list[i], "render.overlays[" + std::to_string(i) + "]",
                             {"skeleton", "wire", "patches", "delta"}, item)) {
        return e;
      }
      r.overlays.push_back(item);
    }
  }
  if (v.contains("split")) {
    if (!v["split"].is_boolean()) return c.Expected("render.split", "true or false", v["split"]);
    r.split = v["split"].get<bool>();
  }
  if (v.contains("compare")) {
    if (auto e = GetString(c, v["compare"], "render.compare", r.compare)) return e;
  }
  if (v.contains("wipe")) {
    if (!v["wipe"].is_boolean()) return c.Expected("render.wipe", "true or false", v["wipe"]);
    r.wipe = v["wipe"].get<bool>();
  }
  if (v.contains("output")) {
    if (auto e = GetString(c, v["output"], "render.output", r.output)) return e;
    // A pattern from a file may not leave the rig's folder (no "..", not absolute).
    const base::Status confined = CheckRigOutputPattern(r.output, {c.file, 0, 0, "render.output"});
    if (!confined.ok()) return confined.error();
    r.output = Resolve(c.file, r.output);
  }
  if (v.contains("frames")) {
    if (auto e = GetString(c, v["frames"], "render.frames", r.frames)) return e;
  }
  return std::nullopt;
}

}  // namespace

bool IsBuiltInBody(const std::string& character) {
  return character == "generated" || character == "tubes" || character == "mannequin";
}

base::Result<Rig> ParseRig(const std::string& text, const std::string& file) {
  const JsonFile c{file};
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    // Byte offset -> line and column.
    int line = 1, column = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') ++line, column = 1;
      else ++column;
    }
    // "[json.exception.parse_error.101] parse error at line 1, column 27: <what>";
    // the position is ours, the rest may itself hold ": " ("last read: '...'").
    std::string what = e.what();
    const auto at = what.find("column ");
    const auto colon = what.find(": ", at == std::string::npos ? 0 : at);
    if (colon != std::string::npos) what = what.substr(colon + 2);
    return base::MakeError(base::ErrorCode::kSyntax, {file, line, column, {}},
                           "invalid JSON: " + what);
  } catch (const json::exception& e) {
    // A number too large for a double (out_of_range 406, "number overflow
    // parsing '1e999'") carries no position: point at the first occurrence of
    // the token the message quotes. (Found writing fuzz/rig_fuzzer.cpp: the
    // exception used to escape and end the process in std::terminate.)
    std::string what = e.what();
    const auto colon = what.rfind("] ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    int line = 0, column = 0;
    const auto quote = what.find('\''), end_quote = what.rfind('\'');
    if (quote != std::string::npos && end_quote > quote + 1) {
      const std::size_t at = text.find(what.substr(quote + 1, end_quote - quote - 1));
      if (at != std::string::npos) {
        line = column = 1;
        for (std::size_t i = 0; i < at; ++i) {
          if (text[i] == '\n') ++line, column = 1;
          else ++column;
        }
      }
    }
    return base::MakeError(base::ErrorCode::kSyntax, {file, line, column, {}},
                           "invalid JSON: " + what);
  }
  if (auto e = CheckObject(c, doc, "", {"character", "motion", "global", "patches", "render"})) {
    return *e;
  }
  Rig rig;
  rig.file = file;
  if (!doc.contains("character")) return c.Fail("character", "missing (\"generated\", \"tubes\" or a glTF file)");
  if (auto e = GetString(c, doc["character"], "character", rig.character)) return *e;
  if (!IsBuiltInBody(rig.character)) rig.character = Resolve(file, rig.character);
  if (doc.contains("motion")) {
    const json& m = doc["motion"];
    if (auto e = CheckObject(c, m, "motion", {"file", "fps", "joint_map", "up"})) return *e;
    if (!m.contains("file")) return c.Fail("motion.file", "missing (a BVH file)");
    if (auto e = GetString(c, m["file"], "motion.file", rig.motion)) return *e;
    rig.motion = Resolve(file, rig.motion);
    if (m.contains("joint_map")) {
      if (auto e = GetString(c, m["joint_map"], "motion.joint_map", rig.joint_map)) return *e;
      rig.joint_map = Resolve(file, rig.joint_map);
    }
    if (m.contains("up")) {
      if (auto e = GetString(c, m["up"], "motion.up", rig.up)) return *e;
      if (rig.up != "y" && rig.up != "z") return c.Fail("motion.up", "expected \"y\" or \"z\", found \"" + rig.up + "\"");
    }
    if (m.contains("fps")) {
      if (auto e = GetNumber(c, m["fps"], "motion.fps", 0, 10000, rig.fps)) return *e;
    }
  } else if (IsBuiltInBody(rig.character)) {
    return c.Fail("motion", "missing (a generated body needs a BVH motion: {\"file\": ...})");
  }
  if (doc.contains("global")) {
    if (auto e = GetChoice(c, doc["global"], "global", {"ssd", "dqs", "swd"}, rig.global)) return *e;
  }
  if (doc.contains("patches")) {
    const json& list = doc["patches"];
    if (!list.is_array()) return c.Expected("patches", "an array of patch objects", list);
    if (list.size() > 64) return c.Fail("patches", "expected at most 64 patches");
    for (std::size_t i = 0; i < list.size(); ++i) {
      RigPatch p;
      if (auto e = ParsePatch(c, list[i], "patches[" + std::to_string(i) + "]", p)) return *e;
      for (const RigPatch& q : rig.patches) {
        if (q.name == p.name) {
          return c.Fail("patches[" + std::to_string(i) + "].name",
                        "expected a unique name, found \"" + p.name + "\" twice");
        }
      }
      rig.patches.push_back(std::move(p));
    }
  }
  if (doc.contains("render")) {
    if (auto e = ParseRender(c, doc["render"], rig.render)) return *e;
  }
  return rig;
}

base::Result<Rig> LoadRig(const std::string& path) {
  const base::FileLoc loc{path, 0, 0, {}};
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    return base::MakeError(base::ErrorCode::kIo, loc, "no such file");
  }
  if (std::filesystem::is_directory(status)) {
    return base::MakeError(base::ErrorCode::kIo, loc, "expected a rig file, found a directory");
  }
  if (!std::filesystem::is_regular_file(status)) {
    return base::MakeError(base::ErrorCode::kIo, loc, "expected a rig file, found a special file");
  }
  // Checked before reading, so a huge file is never loaded into memory.
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec)
    return base::MakeError(base::ErrorCode::kIo, loc, "cannot read the rig file: " + ec.message());
  if (bytes > kMaxRigFileBytes) {
    return base::MakeError(
        base::ErrorCode::kLimitExceeded, loc,
        "expected a rig file of at most 16 MiB, found " + std::to_string(bytes) + " bytes");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return base::MakeError(base::ErrorCode::kIo, loc, "cannot open the rig file");
  std::string text(static_cast<std::size_t>(bytes), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (!in || in.gcount() != static_cast<std::streamsize>(text.size())) {
    return base::MakeError(base::ErrorCode::kIo, loc, "cannot read the rig file");
  }
  return ParseRig(text, path);
}

}  // namespace app
