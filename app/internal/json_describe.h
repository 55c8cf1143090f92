#pragma once
// The "found ..." part of the JSON readers' messages (rig files, their
// examples, check manifests): a short description of a value, at most 40
// characters, that never serializes a whole container. nlohmann's dump()
// recurses once per nesting level, and a file of 10^6 '[' would overflow the
// stack (found by fuzz/rig_fuzzer.cpp). Cost: O(40) for any value.

#include <string>

#include <nlohmann/json_fwd.hpp>

namespace app {

// "an object", "null", "an array [1,2]" (scalars only, cut short), "an array
// (3 items)" (when it holds containers), or the scalar as JSON, cut short.
std::string DescribeJson(const nlohmann::json& v);

}  // namespace app
