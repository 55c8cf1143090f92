#include "app/internal/json_describe.h"

#include <nlohmann/json.hpp>

namespace app {
namespace {

using nlohmann::json;

constexpr std::size_t kMaxDescribed = 40;

std::string DescribeScalar(const json& v) {
  std::string s = v.dump();  // a scalar: no recursion
  if (s.size() > kMaxDescribed) s = s.substr(0, kMaxDescribed - 3) + "...";
  return s;
}

}  // namespace

std::string DescribeJson(const json& v) {
  switch (v.type()) {
    case json::value_t::object: return "an object";
    case json::value_t::null: return "null";
    case json::value_t::array: {
      // "[a,b,c]" for an array of scalars, cut short like the scalars; only
      // the size of an array that holds containers.
      std::string s = "[";
      for (const json& e : v) {
        if (e.is_array() || e.is_object()) {
          return "an array (" + std::to_string(v.size()) + (v.size() == 1 ? " item)" : " items)");
        }
        if (s.size() > 1) s += ',';
        s += e.dump();
        if (s.size() > kMaxDescribed) return "an array " + s.substr(0, kMaxDescribed - 3) + "...";
      }
      return "an array " + s + "]";
    }
    default: return DescribeScalar(v);
  }
}

base::Error JsonFile::Fail(const std::string& path, const std::string& message,
                           base::ErrorCode code) const {
  return base::MakeError(code, {file, 0, 0, path}, message);
}

base::Error JsonFile::Expected(const std::string& path, const std::string& what,
                               const json& found) const {
  return Fail(path, "expected " + what + ", found " + DescribeJson(found));
}

std::optional<base::Error> JsonFile::Keys(const json& obj, const std::string& path,
                                          std::initializer_list<const char*> allowed,
                                          const char* whole) const {
  if (!obj.is_object()) return Expected(path.empty() ? whole : path, "an object", obj);
  for (const auto& [key, value] : obj.items()) {
    bool known = false;
    for (const char* a : allowed) known = known || key == a;
    if (known) continue;
    std::string list;
    for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
    return Fail(path.empty() ? key : path + "." + key,
                "unknown field (expected one of: " + list + ")");
  }
  return std::nullopt;
}

}  // namespace app
