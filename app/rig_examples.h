#pragma once
// Example shapes in rig files (issue 6; docs/rig-file.md, "Example shapes":
// patch fields `examples` and `pose_space`):
//
//   "examples": [{"pose": {"frame": 45} | {"joints": {"LeftForeArm": [0, -90, 0]}},
//                 "edits": [{"vertex": 812, "move": [0, 0, 1.5]},
//                           {"point": [0.5, 0.4], "move": [0, 0.8, 0], "frame": "world"},
//                           {"point": [0.5, 0.5], "move": [0, 0, 2], "radius": 0.3}]}],
//   "pose_space": {"features": "rotvec", "kernel": "gaussian", "kappa": 1, "width": 0,
//                  "joints": ["LeftArm", "LeftForeArm"]}
//
// The rig file parser (rig_file.cpp) fills RigPatch::examples and
// RigPatch::pose_space through app/internal/rig_examples_parse.h; this header
// turns them into each patch's fitted pose space on a loaded character
// (deform/shapes/example_shapes.h, deform/shapes/pose_space.h).

#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"

namespace deform {
struct PatchSetup;
struct PatchPoseSpace;
enum class GlobalMethod;
}  // namespace deform

namespace app {

struct Character;
struct Rig;

// One edit at an example pose (deform::ExampleEdit).
struct RigEdit {
  int vertex = -1;             // mesh vertex index, or -1 when `point` is used
  glm::dvec2 point{-1.0};      // (u, v) in [0,1]^2 of a surface point, when vertex < 0
  glm::dvec3 move{0.0};        // model units
  bool world = false;          // "frame": "world"; default "bind" (turns with the body)
  double radius = 0.0;         // "radius": > 0 a brush (deform/shapes/brush_edit.h); 0 none
  std::string path;            // field path, e.g. "patches[0].examples[1].edits[0]"
};

// The pose of an example: a frame of the rig's motion, or explicit joint
// angles (every other joint at its rest rotation, the root at rest).
struct RigExamplePose {
  int frame = -1;  // >= 0: frame index of the motion (before any --fps resampling)
  // Otherwise: joint name -> rotation angles about the joint's X, Y and Z axes
  // (degrees), composed in the joint's own channel order (ZXY when it has no
  // Euler channels), relative to its rest rotation. Sorted by joint name (the JSON reader
  // keeps object keys sorted).
  std::vector<std::pair<std::string, glm::vec3>> joints;
};

struct RigExample {
  RigExamplePose pose;
  // "auto": computed correction (deform/shapes/corrective_example.h):
  // "volume" (region volume back to bind), "rest" (toward the bind shape
  // carried by the driving bone), or empty (none). Edits then move the
  // corrected shape further.
  std::string auto_kind;
  std::vector<RigEdit> edits;  // solved together; at least one unless auto_kind is set
  std::string path;            // "patches[i].examples[k]"
};

// How theta is built and interpolated for one patch (ALGORITHMS.md 5).
struct RigPoseSpace {
  std::string features = "rotvec";   // euler (the paper's) | rotvec | swingtwist
  std::string kernel = "gaussian";   // gaussian | inverse-multiquadric | multiquadric | polyharmonic3
  double kappa = 1.0;                // sig = kappa x mean nearest-neighbour distance, (0, 10]
  double width = 0.0;                // > 0: explicit sig in feature units (radians)
  std::vector<std::string> joints;   // empty: the joints that weight the patch's control points
};

// The fitted pose spaces of a rig's patches and what the fits reported.
struct RigPoseSpaces {
  std::vector<deform::PatchPoseSpace> patches;  // one per rig patch; inactive without examples
  std::vector<std::string> notes;               // per patch with examples: count, condition
  std::vector<base::Warning> warnings;          // ill-conditioning, unsatisfied edits
};

// Sculpts every example of every patch at its pose with `method`'s global
// layer (SSD or DQS; SWD patches are refused by the pipeline) and fits the
// RBFs. `patches` are BuildRigPatches' result for the same rig and character.
// Errors name the rig file and the field path: unknown joints
// (kNotFound), a frame out of range, edits the patch cannot take (a vertex
// not bound to it, on its faded border), duplicate poses (naming both
// examples), a feature spec over kMaxPoseFeatures.
base::Result<RigPoseSpaces> BuildRigPoseSpaces(const Rig& rig, const Character& character,
                                               const std::vector<deform::PatchSetup>& patches,
                                               deform::GlobalMethod method);

}  // namespace app
