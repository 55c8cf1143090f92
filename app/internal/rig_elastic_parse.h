#pragma once
// The parser of a patch's "elastic" object (app/rig_elastic.h), shared by
// rig_file.cpp; internal because it takes the JSON library's type.

#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "app/rig_elastic.h"
#include "base/error.h"

namespace app {

// Parses `value` (the "elastic" object of a patch whose grid is `grid_u` x
// `grid_v`) into `out`. `path` is the field path ("patches[0].elastic"). Errors
// (kInvalidArgument) name file, field path and what was expected; a grid larger
// than 16 x 16 is refused at `path` (the network's limit).
std::optional<base::Error> ParseRigElastic(const nlohmann::json& value, const std::string& file,
                                           const std::string& path, int grid_u, int grid_v,
                                           RigElastic& out);

}  // namespace app
