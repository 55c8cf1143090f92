#include "app/check_manifest.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/command_line.h"
#include "app/internal/json_describe.h"

namespace app {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr std::uintmax_t kMaxManifestBytes = 16u << 20;
constexpr std::size_t kMaxCases = 10000;

std::string Resolve(const std::string& manifest, const std::string& path) {
  const fs::path p(path);
  if (p.is_absolute()) return path;
  return (fs::path(manifest).parent_path() / p).lexically_normal().string();
}

std::optional<base::Error> CheckKeys(const JsonFile& c, const json& obj, const std::string& path,
                                     std::initializer_list<const char*> allowed) {
  return c.Keys(obj, path, allowed, "manifest");
}

std::optional<base::Error> ParseThresholds(const JsonFile& c, const json& v,
                                           const std::string& path, render::IdiffThresholds& t) {
  if (auto e = CheckKeys(c, v, path,
                         {"fail", "failpercent", "hardfail", "warn", "warnpercent", "hardwarn",
                          "allowfailures"})) {
    return e;
  }
  const auto number = [&](const char* key, float& out, double hi) -> std::optional<base::Error> {
    if (!v.contains(key)) return std::nullopt;
    const json& x = v[key];
    if (!x.is_number() || !(x.get<double>() >= 0.0) || x.get<double>() > hi) {
      std::ostringstream what;
      what << "a number in 0.." << hi;
      return c.Expected(path + "." + key, what.str(), x);
    }
    out = static_cast<float>(x.get<double>());
    return std::nullopt;
  };
  if (auto e = number("fail", t.fail, 1e30)) return e;
  if (auto e = number("failpercent", t.fail_percent, 100)) return e;
  if (auto e = number("hardfail", t.hard_fail, 1e30)) return e;
  if (auto e = number("warn", t.warn, 1e30)) return e;
  if (auto e = number("warnpercent", t.warn_percent, 100)) return e;
  if (auto e = number("hardwarn", t.hard_warn, 1e30)) return e;
  if (v.contains("allowfailures")) {
    const json& x = v["allowfailures"];
    if (!x.is_number_integer() || x.get<long long>() < 0) {
      return c.Expected(path + ".allowfailures", "a non-negative integer", x);
    }
    t.allow_failures = x.get<long long>();
  }
  return std::nullopt;
}

bool ValidName(const std::string& name) {
  if (name.empty() || name.size() > 100 || name == "." || name == "..") return false;
  for (char ch : name) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '_' || ch == '-' || ch == '.';
    if (!ok) return false;
  }
  return true;
}

// The render command's words of a case, split on white space (a string) or as listed.
std::optional<base::Error> OptionWords(const JsonFile& c, const json& v, const std::string& path,
                                       std::vector<std::string>& words) {
  if (v.is_string()) {
    std::istringstream in(v.get<std::string>());
    for (std::string w; in >> w;) words.push_back(w);
    return std::nullopt;
  }
  if (!v.is_array()) return c.Expected(path, "a string or an array of strings", v);
  for (const json& w : v) {
    if (!w.is_string()) return c.Expected(path, "a string or an array of strings", v);
    words.push_back(w.get<std::string>());
  }
  return std::nullopt;
}

// Parses `words` with the render command's parser into `out`.
std::optional<base::Error> ParseCaseOptions(const JsonFile& c, const std::string& path,
                                            const std::string& input,
                                            const std::vector<std::string>& words,
                                            RenderOptions& out) {
  if (std::optional<std::string> bad = app::ParseRenderWords(input, words, out))
    return c.Fail(path, *bad);
  for (const char* refused : {"--out", "--frames", "--overwrite", "--resume", "--stats", "--help"}) {
    if (out.given.count(refused) > 0) {
      return c.Fail(path, std::string("render option ") + refused +
                              " is set by check (use the case's \"frames\" for frames)");
    }
  }
  return std::nullopt;
}

std::optional<base::Error> ParseCase(const JsonFile& c, const json& v, const std::string& path,
                                     const render::IdiffThresholds& defaults, CheckCase& out) {
  if (auto e = CheckKeys(c, v, path, {"name", "input", "options", "frames", "thresholds"})) return e;
  if (!v.contains("name") || !v["name"].is_string() || !ValidName(v["name"].get<std::string>())) {
    return c.Expected(path + ".name", "a name of letters, digits, '_', '-' and '.'",
                      v.contains("name") ? v["name"] : json());
  }
  out.name = v["name"].get<std::string>();
  if (!v.contains("input") || !v["input"].is_string() || v["input"].get<std::string>().empty()) {
    return c.Expected(path + ".input", "a BVH, glTF or rig file", v.contains("input") ? v["input"] : json());
  }
  out.input = Resolve(c.file, v["input"].get<std::string>());
  std::vector<std::string> words;
  if (v.contains("options")) {
    if (auto e = OptionWords(c, v["options"], path + ".options", words)) return e;
  }
  if (auto e = ParseCaseOptions(c, path + ".options", out.input, words, out.render)) return e;
  if (!out.render.motion.empty()) out.render.motion = Resolve(c.file, out.render.motion);
  if (v.contains("frames")) {
    if (!v["frames"].is_string()) return c.Expected(path + ".frames", "a range \"A:B[:STEP]\"", v["frames"]);
    out.render.frames = v["frames"].get<std::string>();
    out.render.given.insert("--frames");
  }
  out.thresholds = defaults;
  if (v.contains("thresholds")) {
    if (auto e = ParseThresholds(c, v["thresholds"], path + ".thresholds", out.thresholds)) return e;
  }
  return std::nullopt;
}

base::Error JsonError(const std::string& file, const std::string& text, const json::exception& e,
                      std::size_t byte) {
  int line = 1, column = 1;
  for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') ++line, column = 1;
    else ++column;
  }
  std::string what = e.what();
  const auto bracket = what.find("] ");
  if (bracket != std::string::npos) what = what.substr(bracket + 2);
  return base::MakeError(base::ErrorCode::kSyntax,
                         {file, byte > 0 ? line : 0, byte > 0 ? column : 0, {}},
                         "invalid JSON: " + what);
}

}  // namespace

base::Result<CheckManifest> ParseCheckManifest(const std::string& text, const std::string& file) {
  const JsonFile c{file};
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    return JsonError(file, text, e, e.byte);
  } catch (const json::exception& e) {
    return JsonError(file, text, e, 0);
  }
  if (!doc.is_object()) return c.Expected("manifest", "an object", doc);
  if (auto e = CheckKeys(c, doc, "", {"references", "thresholds", "cases"})) return *e;
  CheckManifest m;
  m.file = file;
  m.references = Resolve(file, "reference");
  if (doc.contains("references")) {
    if (!doc["references"].is_string() || doc["references"].get<std::string>().empty()) {
      return c.Expected("references", "a folder name", doc["references"]);
    }
    m.references = Resolve(file, doc["references"].get<std::string>());
  }
  render::IdiffThresholds defaults;
  if (doc.contains("thresholds")) {
    if (auto e = ParseThresholds(c, doc["thresholds"], "thresholds", defaults)) return *e;
  }
  if (!doc.contains("cases") || !doc["cases"].is_array() || doc["cases"].empty()) {
    return c.Expected("cases", "a non-empty array of cases", doc.contains("cases") ? doc["cases"] : json());
  }
  if (doc["cases"].size() > kMaxCases) return c.Fail("cases", "expected at most 10000 cases");
  for (std::size_t i = 0; i < doc["cases"].size(); ++i) {
    const std::string path = "cases[" + std::to_string(i) + "]";
    CheckCase cs;
    if (auto e = ParseCase(c, doc["cases"][i], path, defaults, cs)) return *e;
    for (const CheckCase& other : m.cases) {
      if (other.name == cs.name) {
        return c.Fail(path + ".name", "expected a unique name, found \"" + cs.name + "\" twice");
      }
    }
    m.cases.push_back(std::move(cs));
  }
  return m;
}

base::Result<CheckManifest> LoadCheckManifest(const std::string& path) {
  const base::FileLoc loc{path, 0, 0, {}};
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return base::MakeError(base::ErrorCode::kIo, loc, "no such manifest file");
  const std::uintmax_t bytes = fs::file_size(path, ec);
  if (ec)
    return base::MakeError(base::ErrorCode::kIo, loc, "cannot read the manifest: " + ec.message());
  if (bytes > kMaxManifestBytes) {
    return base::MakeError(
        base::ErrorCode::kLimitExceeded, loc,
        "expected a manifest of at most 16 MiB, found " + std::to_string(bytes) + " bytes");
  }
  std::ifstream in(path, std::ios::binary);
  std::string text(static_cast<std::size_t>(bytes), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (!in) return base::MakeError(base::ErrorCode::kIo, loc, "cannot read the manifest");
  return ParseCheckManifest(text, path);
}

}  // namespace app
