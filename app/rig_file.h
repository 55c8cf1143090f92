#pragma once
// Rig files: a JSON document saying what to deform and how (DESIGN.md "The rig
// file"; every field is documented in docs/rig-file.md).
//
//   {
//     "character": "generated" | "tubes" | "body.glb",
//     "motion":    {"file": "bend.bvh", "fps": 0, "joint_map": "map.json"},
//     "global":    "ssd" | "dqs" | "swd",
//     "patches":   [{"name": "left_elbow",
//                    "region": {"joint": "LeftForeArm", "radius": 14, ...},
//                    "parametrization": "cylinder", "sampling": [8, 8], "grid": [6, 6],
//                    "border_width": 0.1}],
//     "render":    {"size": [640, 360], "camera": "follow", "split": true, ...}
//   }
//
// Parsing checks types, ranges and unknown fields and resolves paths against
// the rig file's folder; it does not load the character or the motion (joint
// names are checked when the patches are built). Errors name the file, the
// field path (e.g. "patches[1].grid") and what was expected:
//   rig.json: error: patches[1].grid: expected an array of two integers in 4..64, found "6x6"
// `examples` and `pose_space` per patch are parsed by app/rig_examples.cpp
// (types in app/rig_examples.h); `elastic` by app/rig_elastic.cpp.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/rig_elastic.h"
#include "app/rig_examples.h"
#include "base/error.h"

namespace app {

// How a patch's region is chosen (ALGORITHMS.md 3.1); exactly one kind.
struct RigRegion {
  enum class Kind { kJoint, kVertices, kScreen };
  Kind kind = Kind::kJoint;
  // kJoint: vertices within `radius` of the joint's bind position, weighted to
  // the bones meeting there (the joint and its parent), optionally one side.
  std::string joint;                 // skeleton joint name
  float radius = 0.0f;               // model units, > 0
  glm::vec3 side{0.0f};              // model-space direction, or zero (every side)
  float half_angle_deg = 120.0f;     // in (0, 180]; used with `side`
  float min_bone_weight = 0.5f;      // in (0, 1]
  // kVertices: mesh vertex indices.
  std::vector<int> vertices;
  // kScreen: a rectangle in a named view (the paper's sketch).
  std::string view;                  // "front", "back", "left", "right"
  glm::vec4 rect{0.0f};              // x0, y0, x1, y1 in [0,1] of the view, y down
};

struct RigPatch {
  std::string name;
  RigRegion region;
  bool cylinder = true;              // parametrization: "cylinder" (true) or "plane"
  glm::ivec2 sampling{8, 8};         // S x T, each 4..256 and >= the grid
  glm::ivec2 grid{6, 6};             // M x N, each 4..64
  float border_width = 0.1f;         // parameter units, [0, 0.5]
  std::optional<RigElastic> elastic; // the elastic layer (mass-spring dE); none = no dE
  std::vector<RigExample> examples;  // example shapes (app/rig_examples.h); empty = none
  RigPoseSpace pose_space;           // how the examples are interpolated over theta
};

struct RigRender {
  glm::ivec2 size{640, 360};         // pixels, 16..16384
  // "camera": "follow" | "fixed" | "turntable", or an object with "mode" (that
  // string) and the fields below (as --azimuth, --elevation, --distance,
  // --zoom, --look-at).
  std::string camera = "follow";     // follow | fixed | turntable
  std::optional<float> azimuth_deg;  // -3600..3600
  std::optional<float> elevation_deg;  // -89..89
  float distance = 0.0f;             // >= 0, model units; 0 = framed
  float zoom = 1.0f;                 // (0, 1000]
  std::string look_at;               // joint name or "patch:NAME"; empty = the whole body
  std::vector<std::string> overlays; // skeleton, wire
  bool split = true;                 // with patches: two bodies (global only | + patches); false: one
  std::string compare;               // "A,B" as --compare (e.g. "ssd,dqs+patches"); empty = default
  bool wipe = false;                 // the two bodies as a wipe, not side by side
  std::string output;                // frame pattern (resolved), empty = out/<rig>/frame_####.png
  std::string frames;                // "A:B[:STEP]", empty = all
};

struct Rig {
  std::string file;                  // the rig file as given
  std::string character;             // a built-in body (IsBuiltInBody) or a resolved glTF/GLB path
  std::string motion;                // resolved BVH path; empty = the glTF's animation
  std::string joint_map;             // resolved joint map (JSON) for a glTF character; empty = none
  double fps = 0.0;                  // output frame rate, 0 = the motion's own
  std::string up;                    // "y" | "z": the BVH's up axis (as --up); empty = detected
  std::string global = "ssd";        // ssd | dqs | swd
  std::vector<RigPatch> patches;
  RigRender render;
};

// "generated" (the smooth body built from the motion's skeleton), "tubes" or
// its older name "mannequin" (the tube body whose vertex indices older rigs
// name): a body made from the motion rather than a file.
bool IsBuiltInBody(const std::string& character);

// Largest rig file LoadRig reads (rigs are a few kB; this only bounds memory).
inline constexpr std::uintmax_t kMaxRigFileBytes = std::uintmax_t{1} << 24;

// Parses rig JSON text; `file` names it in messages and its folder resolves
// relative paths.
base::Result<Rig> ParseRig(const std::string& text, const std::string& file);
// Reads and parses a rig file: kIo when it is missing, a directory or cannot
// be read, kLimitExceeded above kMaxRigFileBytes (checked before reading).
base::Result<Rig> LoadRig(const std::string& path);

}  // namespace app
