#pragma once
// `patchskin inspect FILE [--frame N] [--json]`: the skeleton tree with its
// channels, frame count, frame time, duration, detected units and up axis; with
// --frame, every joint's world position and rotation at that frame, in the
// file's own units and axes unless --scale / --y-up ask otherwise. The JSON
// schema is documented in docs/command-line.md ("inspect --json"). With --artifacts it
// prints the collapse and candy-wrapper figures of SSD, DQS and SWD on the
// file's body (deform/global/rig_artifacts.h) instead.

#include <optional>
#include <string>

namespace app {

struct InspectOptions {
  std::string file;
  std::optional<int> frame;       // 0-based frame index
  bool json = false;
  bool artifacts = false;         // print SSD/DQS/SWD artifact figures instead
  float scale = 1.0f;             // 0 = automatic (detected units to metres)
  bool y_up = false;              // rotate a Z-up file to Y-up
  std::string up;                 // --up y|z: the file's up axis; empty = detected
  bool add_position_to_offset = false;
  bool allow_short = false;       // load the complete frames of a file with fewer than declared
  std::string motion;             // BVH driving the glTF `file`: print the joint matching instead
  std::string joint_map;          // with `motion`: JSON overrides (as render --joint-map)
};

// Runs it. Returns the process exit code (0 ok, 2 bad input); errors go to stderr.
int RunInspect(const InspectOptions& options);

}  // namespace app
