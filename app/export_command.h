#pragma once
// `patchskin export [INPUT] --out PATTERN`: the deformed mesh of every output
// frame as geometry other tools open, evaluated by the same deform::FramePipeline,
// frame plan and options as `render` (so frame N of an export is exactly the
// mesh `render` draws as frame N). A rig file (.json) as input sets the
// motion or character, the global method, fps, frames, camera and size as it
// does for render, and its layers (patches, ...) go on the pipeline
// (app/rig_setup.h): the export is the layered mesh, i.e. the right half of a
// split render. Outputs:
//   * --out ending in .obj (with a #### placeholder): one OBJ per frame
//     (deform/io/obj_writer.h), written as the frames are evaluated; one frame is
//     held in memory whatever the frame count;
//   * --out ending in .glb: one glTF 2.0 file with the deformation as a
//     morph-target animation or baked per-frame meshes (deform/io/gltf_export.h).
// --with-camera also writes camera_####.json per frame next to the output: the
// camera `render` would use for that frame (see CameraJson).

#include <set>
#include <string>

#include <glm/glm.hpp>

#include "render/camera.h"

namespace app {

struct ExportOptions {
  std::string input;              // BVH, glTF/GLB or rig .json; empty = built-in demo
  std::string motion;             // BVH driving a glTF input (as render --motion); empty = its own
  std::string joint_map;          // JSON joint map overriding the matched joints; empty = none
  std::string frames;             // "A:B[:STEP]", inclusive, in output frames; empty = all
  double fps = 0.0;               // output frame rate; 0 = the capture's own
  std::string out;                // .obj pattern with ####, or a .glb path;
                                  // empty = out/<name>_export/mesh_####.obj
  std::string global = "ssd";     // ssd | dqs | swd
  std::string body = "generated"; // body of a BVH input: generated | tubes (as render; a rig: tubes)
  std::string layer;              // "auto": the patch layer placed from the skeleton; empty = none
  std::string layout = "auto";    // .glb: auto | morph | baked
  bool step = false;              // .glb morph weights: STEP instead of LINEAR
  bool with_camera = false;       // also write camera_####.json per frame
  std::string camera = "follow";  // follow | fixed (as render)
  std::string size = "1280x720";  // image size the camera JSON is for
  float elevation_deg = 15.0f;    // camera elevation (as render)
  float scale = 1.0f;             // factor on positions and the camera JSON's lengths
                                  // (eye, target, near, far, ground_y), 1e-6..1e6;
                                  // e.g. 0.01: a capture in cm exported in metres
  int threads = 0;                // 0 = hardware concurrency
  bool quiet = false;
  bool resume = false;            // OBJ: keep the frame files already written, write the others
  int start_number = 0;           // file number of motion frame 0 (OBJ and camera JSON)
  std::string up;                 // --up y|z: a BVH's up axis; empty = detected
  // Long names ("--size") of the options given on the command line, filled by
  // the parser: with a rig file they win over its settings (ApplyRigSettings).
  std::set<std::string> given;
};

// Runs an export. Exit code: 0 ok, 2 bad input, 3 internal error, 128 + signal
// when SIGINT or SIGTERM stopped it (no .glb then; the OBJ files written are complete).
int RunExport(const ExportOptions& options);

// The camera JSON of one frame (one object, keys in this order):
//   frame, time_s, width, height, aspect, fov_y_deg, near, far,
//   eye [x,y,z], target [x,y,z], up [x,y,z] (world space),
//   ground_y (world Y of the ground plane render draws under the body),
//   view: world->view matrix, projection: view->clip matrix (OpenGL clip
//   space, depth -1..1), both 16 numbers in column-major order (element
//   (row r, column c) at index 4c + r, as glm and glTF store matrices).
std::string CameraJson(const render::Camera& camera, glm::ivec2 size, float ground_y, int frame,
                       double time_s);

}  // namespace app
