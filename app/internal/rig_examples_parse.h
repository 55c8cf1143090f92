#pragma once
// The rig file parser's hook for a patch's `examples` and `pose_space` fields
// (app/rig_examples.h); only rig_file.cpp and rig_examples.cpp include this.

#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "app/rig_file.h"
#include "base/error.h"

namespace app::internal {

// Reads `examples` and `pose_space` of the patch object `patch` (field path
// `path`, e.g. "patches[0]") into out.examples / out.pose_space, checking
// types, ranges and unknown fields. Duplicate poses that are the same frame or
// the same joint angles are refused here, naming both examples; poses that are
// different but too close are refused when the RBF is fitted.
std::optional<base::Error> ParsePatchExamples(const std::string& file, const nlohmann::json& patch,
                                              const std::string& path, RigPatch& out);

}  // namespace app::internal
