#pragma once
// `patchskin rig auto CAPTURE [--body B] [--out rig.json]`: the rig that
// `render CAPTURE --layer auto` uses (app/auto_rig.h), written as an editable
// rig file (app/rig_writer.h) to stdout or --out; the placement notes go to
// stderr. Exit codes as every command (app/command_line.h).

#include <string>

namespace app {

struct RigCommandOptions {
  std::string capture;             // BVH capture
  std::string body = "generated";  // generated | tubes | a glTF/GLB character the capture drives
  std::string up;                  // --up y|z; empty = detected
  std::string out;                 // rig file; empty = stdout
  bool quiet = false;
};

int RunRigAuto(const RigCommandOptions& o);

}  // namespace app
