#pragma once
// `patchskin farm slurm INPUT --chunk N [--frames A:B[:STEP]] [--out PATTERN]
//  [--partition P] [--sbatch-arg ARG]... [--script-dir DIR] [--submit [--wait]]
//  [-- RENDER OPTIONS...]`: renders a capture on a Slurm cluster as a job array.
//
// Writes two batch scripts into the script folder (default: `slurm/` beside the
// frames) and a `submit.sh` that submits them:
//   render_array.sbatch  a job array, one task per chunk of N output frames;
//                        task k runs `patchskin render INPUT --frames F:L:STEP
//                        --framing A:B:STEP --out PATTERN --resume --no-sheet
//                        --no-video` for its chunk (F = A + k*N*STEP), so frames go
//                        straight to their final names (written, then renamed)
//                        and a failed or pre-empted task re-run with the same
//                        command finishes its chunk with the same bytes.
//   sheet.sbatch         once every task succeeded (--dependency=afterok on the
//                        array): `patchskin sheet` builds the contact sheet and
//                        preview video from the frames.
// Every path in the scripts is absolute (jobs may start in another folder).
// Without --submit it prints the scripts and the command to submit them; with
// --submit it runs sbatch itself (and with --wait blocks until the sheet job
// has ended, like `sbatch --wait`, then checks that every frame and the
// contact sheet exist: sbatch --wait reports success for a sheet job that was
// cancelled because a task failed). The frame range and frame rate come from
// the input (a BVH, glTF or rig file), read once here. There is no simulation
// cache to build first: every chunk simulates from the motion's start.

#include <string>
#include <vector>

namespace app {

struct FarmOptions {
  std::string input;                     // BVH, glTF/GLB or rig (.json); required
  std::string frames;                    // "A:B[:STEP]"; empty = the rig's, else all
  double fps = 0.0;                      // output frame rate passed to render; 0 = the input's
  int chunk = 0;                         // output frames per task, >= 1 (required)
  std::string out;                       // frame pattern; empty = the rig's, else out/<name>/frame_####.png
  std::string partition;                 // Slurm partition; empty = the cluster's default
  std::vector<std::string> sbatch_args;  // extra #SBATCH lines (e.g. "--time=01:00:00")
  std::string script_dir;                // empty = <frames folder>/slurm
  std::string job_name;                  // empty = patchskin-<input name>
  std::string motion;                    // passed to render --motion
  std::vector<std::string> render_args;  // after "--": passed to every render call
  bool submit = false;                   // run sbatch (else print)
  bool wait = false;                     // with --submit: wait for the sheet job to end
};

// Exit code: 0 ok (with --wait: every job succeeded), 1 usage, 2 bad input
// (input, range, chunk, render options that farm sets itself), 3 when sbatch
// cannot be run or refuses, or (with --wait) a frame or the contact sheet is
// missing when the jobs have ended.
int RunFarm(const FarmOptions& options);

// The texts RunFarm writes into the script folder.
struct FarmScripts {
  std::string render_array;   // render_array.sbatch
  std::string sheet;          // sheet.sbatch
  std::string submit;         // submit.sh
  int num_tasks = 0;          // array size
};

}  // namespace app
