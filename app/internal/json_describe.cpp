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

}  // namespace app
