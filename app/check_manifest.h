#pragma once
// The manifest of `patchskin check`: a JSON file listing golden-image cases.
//
//   {
//     "references": "reference",             optional folder, default "reference"
//     "thresholds": {"fail": 0.004, ...},    optional, the default of every case
//     "cases": [
//       {"name": "walk_dqs",                 [A-Za-z0-9_.-], unique
//        "input": "walk.bvh",                BVH, glTF/GLB or rig (.json)
//        "options": "--size 160x90 --global dqs",   render's words (string or array)
//        "frames": "0:20:10",                 as --frames; optional (all)
//        "thresholds": {"fail": 0.01}}        optional, over the manifest's
//     ]
//   }
//
// Thresholds take idiff's names: fail, failpercent, hardfail, warn, warnpercent,
// hardwarn, allowfailures (defaults as idiff's). Paths (the references folder,
// inputs, --motion) are relative to the manifest's folder. `options` are parsed
// by the render command's own parser (app/render_command.h); --out, --frames,
// --overwrite, --resume and --stats are refused there (check sets them).
//
//   inputs:  the manifest file (at most 16 MiB)
//   outputs: CheckManifest, or an error naming the file, the field path
//            (e.g. "cases[2].options") or line and column, and what was expected

#include <string>
#include <vector>

#include "app/render_command.h"
#include "base/error.h"
#include "render/output/image_file_compare.h"

namespace app {

struct CheckCase {
  std::string name;
  std::string input;             // resolved against the manifest's folder
  RenderOptions render;          // parsed options; input, frames filled in, out left empty
  render::IdiffThresholds thresholds;
};

struct CheckManifest {
  std::string file;
  std::string references;        // resolved folder of reference frames (<references>/<case>/)
  std::vector<CheckCase> cases;
};

[[nodiscard]] base::Result<CheckManifest> ParseCheckManifest(const std::string& text,
                                                             const std::string& file);
[[nodiscard]] base::Result<CheckManifest> LoadCheckManifest(const std::string& path);

}  // namespace app
