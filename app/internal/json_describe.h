#pragma once
// What the JSON readers (rig files, their examples, check manifests) share:
// the "found ..." part of their messages, a short description of a value, at
// most 40 characters, that never serializes a whole container (nlohmann's dump()
// recurses once per nesting level, and a file of 10^6 '[' would overflow the
// stack: found by fuzz/rig_fuzzer.cpp; cost O(40) for any value), and the
// errors that name the file and the field's path.

#include <initializer_list>
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "base/error.h"

namespace app {

// "an object", "null", "an array [1,2]" (scalars only, cut short), "an array
// (3 items)" (when it holds containers), or the scalar as JSON, cut short.
std::string DescribeJson(const nlohmann::json& v);

// The JSON file being read: its errors carry the file name and the field's
// path ("examples[2].pose"), with no line (the parser's own errors have one).
struct JsonFile {
  std::string file;

  base::Error Fail(const std::string& path, const std::string& message,
                   base::ErrorCode code = base::ErrorCode::kInvalidArgument) const;
  // "expected <what>, found <DescribeJson(found)>".
  base::Error Expected(const std::string& path, const std::string& what,
                       const nlohmann::json& found) const;
  // `obj` must be an object whose keys are all in `allowed`. `whole` names the
  // object in the message when `path` is empty (the file's top level).
  std::optional<base::Error> Keys(const nlohmann::json& obj, const std::string& path,
                                  std::initializer_list<const char*> allowed,
                                  const char* whole = "") const;
};

}  // namespace app
