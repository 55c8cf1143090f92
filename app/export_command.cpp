#include "app/export_command.h"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/character_motion.h"
#include "app/frame_plan.h"
#include "app/motion_source.h"
#include "app/output_guard.h"
#include "app/character.h"
#include "deform/pipeline/frame_pipeline.h"
#include "app/progress.h"
#include "app/auto_rig.h"
#include "app/rig_file.h"
#include "app/rig_setup.h"
#include "app/exit_code.h"
#include "deform/io/file_output.h"
#include "deform/io/gltf_export.h"
#include "deform/io/obj_writer.h"
#include "mocap/bvh_reader.h"
#include "render/output/image_io.h"

namespace app {
namespace {

// The OBJ sequence's material library, written once next to the frames.
struct ObjMaterials {
  std::string library;             // file name of the .mtl in the output folder, or empty
  std::vector<std::string> names;  // per material
};

// materials.mtl and each texture's image as read (texture_K.png / .jpg) in
// `folder`: map_Kd names the image, Kd the base colour factor.
base::Result<ObjMaterials> WriteObjMaterialFiles(const deform::MeshMaterials& materials,
                                                 const std::filesystem::path& folder) {
  ObjMaterials out;
  out.library = "materials.mtl";
  std::vector<glm::vec3> diffuse;
  std::vector<std::string> files;
  for (std::size_t k = 0; k < materials.materials.size(); ++k) {
    const deform::Material& m = materials.materials[k];
    out.names.push_back("material_" + std::to_string(k));
    diffuse.push_back(m.base_color_factor);
    std::string file;
    if (m.texture >= 0 && static_cast<std::size_t>(m.texture) < materials.images.size() &&
        !materials.images[static_cast<std::size_t>(m.texture)]->encoded.empty()) {
      const deform::TextureImage& image = *materials.images[static_cast<std::size_t>(m.texture)];
      file = "texture_" + std::to_string(m.texture) + (image.mime_type == "image/jpeg" ? ".jpg" : ".png");
      const std::string_view bytes(reinterpret_cast<const char*>(image.encoded.data()), image.encoded.size());
      if (base::Status s = deform::WriteFileAtomic((folder / file).string(), bytes); !s)
        return s.error();
    }
    files.push_back(file);
  }
  if (base::Status s =
          deform::WriteObjMaterials((folder / out.library).string(), out.names, diffuse, files);
      !s) {
    return s.error();
  }
  return out;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

nlohmann::json Vec3(const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

nlohmann::json ColumnMajor(const glm::mat4& m) {
  nlohmann::json a = nlohmann::json::array();
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) a.push_back(m[c][r]);
  }
  return a;
}

base::Result<deform::GltfExportLayout> ParseLayout(const std::string& text) {
  if (text == "auto") return deform::GltfExportLayout::kAuto;
  if (text == "morph") return deform::GltfExportLayout::kMorphTargets;
  if (text == "baked") return deform::GltfExportLayout::kBakedMeshes;
  return ArgError("--layout", "expected auto, morph or baked, found '" + text + "'");
}

}  // namespace

std::string CameraJson(const render::Camera& camera, glm::ivec2 size, float ground_y, int frame,
                       double time_s) {
  nlohmann::ordered_json j;
  j["frame"] = frame;
  j["time_s"] = time_s;
  j["width"] = size.x;
  j["height"] = size.y;
  j["aspect"] = camera.aspect;
  j["fov_y_deg"] = camera.fov_y_deg;
  j["near"] = camera.near_plane;
  j["far"] = camera.far_plane;
  j["eye"] = Vec3(camera.eye);
  j["target"] = Vec3(camera.target);
  j["up"] = Vec3(camera.up);
  j["ground_y"] = ground_y;
  j["view"] = ColumnMajor(camera.ViewFromWorld());
  j["projection"] = ColumnMajor(camera.ClipFromView());
  return j.dump(2) + "\n";
}

int RunExport(const ExportOptions& options) {
  // --- A rig file sets the inputs, the method and the layers, as for render ---
  ExportOptions o = options;
  std::optional<Rig> rig;
  if (!o.layer.empty()) {
    // --layer auto: the rig `patchskin rig auto` writes, used as if read.
    base::Result<Rig> made = AutoRigForCommand(o.layer, o.input, o.motion, o.body, o.up, o.quiet);
    if (!made.ok()) return ReportError(made.error());
    rig = std::move(*made);
  } else if (Lower(std::filesystem::path(o.input).extension().string()) == ".json") {
    base::Result<Rig> loaded = LoadRig(o.input);
    if (!loaded.ok()) return ReportError(loaded.error());
    rig = std::move(*loaded);
  }
  if (rig) {
    ApplyRigSettings(*rig, o);
    // The camera JSON has no orbit: a turntable rig's export follows the body.
    if (o.given.count("--camera") == 0 && o.camera == "turntable") o.camera = "follow";
  }

  // --- Arguments -------------------------------------------------------------
  const base::Result<glm::ivec2> size = ParseSize(o.size);
  if (!size.ok()) return ReportError(size.error());
  if (o.camera != "follow" && o.camera != "fixed") {
    return ReportError(ArgError("--camera", "expected follow or fixed, found '" + o.camera + "'"));
  }
  if (const auto bad = CheckThreads(o.threads)) return ReportError(*bad);
  if (const auto bad = CheckFps(o.fps)) return ReportError(*bad);
  if (!(o.scale == 0.0f || (o.scale >= 1e-6f && o.scale <= 1e6f))) {
    return ReportError(ArgError(
        "--scale", "expected 0 (detected units to metres) or a factor in 1e-6..1e6, found " +
                       std::to_string(o.scale)));
  }
  const base::Result<deform::GlobalMethod> method = ParseGlobalMethod(o.global);
  if (!method.ok()) return ReportError(method.error());
  const base::Result<deform::GltfExportLayout> layout = ParseLayout(o.layout);
  if (!layout.ok()) return ReportError(layout.error());

  // --- Input (as render) --------------------------------------------------------
  const bool demo = o.input.empty();
  const std::string name = demo  ? "demo"
                           : rig ? std::filesystem::path(rig->file).stem().string()
                                 : std::filesystem::path(o.input).stem().string();
  const base::Result<std::optional<mocap::UpAxis>> up = ParseUpAxis(o.up);
  if (!up.ok()) return ReportError(up.error());
  const base::Result<BodyKind> body = ParseBodyKind(o.body);
  if (!body.ok()) return ReportError(body.error());
  // A rig names its own body: its example edits may name that body's vertices.
  base::Result<Character> character = LoadCommandCharacter(
      o.input, o.motion, o.quiet, *up, o.joint_map, nullptr, rig ? RigBodyKind(*rig) : *body);
  if (!character.ok()) return ReportError(character.error());
  const Character& ch = *character;
  if (o.scale == 0.0f) {  // as inspect --scale 0: the detected units to metres
    const float metres = mocap::MetresPerUnit(ch.skeleton.info.detected_units);
    if (!(metres > 0.0f) && !o.quiet) {
      std::fprintf(stderr, "%s: warning: units not recognised; --scale 0 left lengths as they are\n",
                   ch.source.c_str());
    }
    o.scale = metres > 0.0f ? metres : 1.0f;
  }
  base::Result<FramePlan> plan = PlanFrames(
      ch.motion,
      {.frames = o.frames, .fps = o.fps, .start_number = o.start_number, .list_frames = false});
  if (!plan.ok()) return ReportError(plan.error());

  const std::string out = o.out.empty() ? "out/" + name + "_export/mesh_####.obj" : o.out;
  const std::string ext = Lower(std::filesystem::path(out).extension().string());
  const bool glb = ext == ".glb";
  if (!glb && ext != ".obj") {
    return ReportError(
        ArgError("--out", "expected a .obj pattern or a .glb file, found '" + out + "'"));
  }
  if (glb && o.resume) {
    return ReportError(ArgError("--resume",
                                "expected an OBJ sequence: a .glb is written whole at the end, "
                                "so an interrupted one has nothing to resume"));
  }
  if (!glb && !render::HasFramePlaceholder(out)) {
    return ReportError(ArgError(
        "--out", "the OBJ pattern '" + out + "' needs one frame placeholder such as #### or %04d"));
  }
  const std::filesystem::path out_dir =
      glb ? std::filesystem::path(out).parent_path()
          : std::filesystem::path(*render::ExpandFramePattern(out, 0)).parent_path();
  if (base::Status s = PrepareOutputFolder(out_dir); !s) return ReportError(s.error());

  // --- Pipeline and cameras ----------------------------------------------------------
  // The layered result: with a rig, every layer it asks for (render draws the
  // same pipeline, or its right half when the rig splits the view).
  base::Result<deform::FramePipeline> pipeline =
      deform::FramePipeline::Create(ch, *method, o.threads);
  if (!pipeline.ok()) return ReportError(pipeline.error());
  if (rig) {
    if (base::Status s = ApplyRigLayers(*rig, ch, *pipeline); !s) return ReportError(s.error());
  }
  // The camera plan is built whether or not it is written: its framing
  // pre-pass evaluates the pipeline, as render's does before its frame loop,
  // so a pipeline that carries state between frames (the elastic layer) sees
  // the same sequence of evaluations here as there.
  base::Result<render::CameraPlan> camera_plan =
      PlanCameras(pipeline->character(), *plan, o.camera, o.elevation_deg, *size);
  if (!camera_plan.ok()) return ReportError(camera_plan.error());
  const render::CameraPlan* cameras = o.with_camera ? &*camera_plan : nullptr;
  std::optional<deform::GltfSequenceWriter> gltf;
  const deform::Mesh& bind = ch.mesh.bind;
  if (glb) {
    deform::GltfExportOptions go;
    go.frame_time_s = plan->frame_time_s * plan->range.step;
    go.layout = *layout;
    go.step_interpolation = o.step;
    go.generator = "patchskin export (" + std::string(deform::GlobalMethodName(*method)) + ")";
    go.scratch_dir = out_dir.empty() ? "." : out_dir.string();
    if (cameras) {  // the lens is the same at every frame; the scale moves the planes with the scene
      const render::Camera first = cameras->At(plan->At(0).camera);
      go.camera = deform::GltfCameraLens{.yfov_rad = glm::radians(first.fov_y_deg),
                                         .aspect = first.aspect,
                                         .znear = first.near_plane * o.scale,
                                         .zfar = first.far_plane * o.scale};
    }
    const deform::MeshMaterials& materials = ch.mesh.materials;
    const deform::GltfExportSurface surface{
        .uvs = bind.uvs, .materials = materials.materials.empty() ? nullptr : &materials};
    base::Result<deform::GltfSequenceWriter> w =
        deform::GltfSequenceWriter::Create(bind.triangles, bind.colors, bind.num_vertices(),
                                           static_cast<int>(plan->count()), go, surface);
    if (!w.ok()) return ReportError(w.error());
    gltf.emplace(std::move(*w));
  }

  // --- The frame loop: one frame in memory (OBJ) ---------------------------------------
  // Every planned frame is evaluated in order by the one pipeline, as render
  // does, so state carried from frame to frame (the elastic layer) is the same.
  Progress progress(demo ? "export demo" : "export " + name, static_cast<int>(plan->count()),
                    o.quiet);
  deform::DeformedFrame frame;
  std::vector<glm::vec3> scaled;  // --scale: the positions written (#V, reused)
  deform::ObjSequenceWriter obj;
  ObjMaterials obj_materials;
  if (!glb && !ch.mesh.materials.materials.empty()) {
    base::Result<ObjMaterials> written = WriteObjMaterialFiles(ch.mesh.materials, out_dir);
    if (!written.ok()) return ReportError(written.error());
    obj_materials = std::move(*written);
  }
  const std::string source = demo ? "demo_walk.bvh (built in)" : rig ? rig->file : o.input;
  // Frames are computed one at a time (plan->At): an export of every frame of
  // an hour-long capture holds no per-frame list (issue 8).
  // Ctrl-C (SIGINT) or SIGTERM stops between frames, as in render: the frames
  // written stay complete, the .glb (written only at the end) is not started.
  // Existing files are replaced, or with --resume the frames already written
  // are kept (files appear only whole, renamed into place).
  OutputGuard guard({.overwrite = true, .resume = o.resume});
  if (!glb) {
    const base::Status planned = guard.Plan(
        plan->count(),
        [&](std::size_t i) { return render::ExpandFramePattern(out, plan->At(i).number); }, {});
    if (!planned.ok()) return ReportError(planned.error());
  }
  int frames_done = 0;
  int last_done_number = -1;
  for (std::size_t index = 0; index < plan->count(); ++index) {
    if (guard.interrupted()) break;
    const OutputFrame of = plan->At(index);
    base::Status s = pipeline->Evaluate(of.time_s, frame);
    if (!s.ok()) return ReportError(s.error());
    std::span<const glm::vec3> positions = frame.positions;
    if (o.scale != 1.0f) {
      scaled.resize(frame.positions.size());
      for (std::size_t i = 0; i < scaled.size(); ++i) scaled[i] = frame.positions[i] * o.scale;
      positions = scaled;
    }
    if (gltf) {
      s = gltf->AddFrame(positions, frame.normals);
    } else if (guard.skip(index)) {
      // Written by an earlier run: evaluated above all the same, for the state
      // one frame hands the next (the elastic layer).
    } else {
      const base::Result<std::string> path = render::ExpandFramePattern(out, of.number);
      if (!path.ok()) return ReportError(path.error());
      char comment[160];
      std::snprintf(comment, sizeof(comment), "frame %d, t = %.6f s, %s skinning", of.number,
                    of.time_s, deform::GlobalMethodName(*method));
      s = obj.Write({.positions = positions, .normals = frame.normals,
                     .triangles = bind.triangles,
                     .comment = "patchskin export of " + source + "\n" + comment,
                     .uvs = bind.uvs,
                     .material_library = obj_materials.library,
                     .material_names = obj_materials.names,
                     .triangle_material = obj_materials.names.empty()
                                              ? std::span<const std::int32_t>()
                                              : std::span<const std::int32_t>(ch.mesh.materials.triangle_material)},
                    *path);
    }
    if (!s.ok()) return ReportError(s.error());
    if (cameras) {
      char file[32];
      std::snprintf(file, sizeof(file), "camera_%04d.json", of.number);
      // Scaling the scene and the camera's lengths together gives the same picture.
      render::Camera camera = cameras->At(of.camera);
      camera.eye *= o.scale;
      camera.target *= o.scale;
      camera.near_plane *= o.scale;
      camera.far_plane *= o.scale;
      if (gltf) {  // the camera node: world position and world-from-view rotation
        const glm::quat rotation = glm::quat_cast(glm::transpose(glm::mat3(camera.ViewFromWorld())));
        if (s = gltf->AddCameraFrame(camera.eye, rotation); !s.ok()) return ReportError(s.error());
      }
      s = deform::WriteFileAtomic((out_dir / file).string(),
                                  CameraJson(camera, *size, cameras->ground_y() * o.scale,
                                             of.number, of.time_s));
      if (!s.ok()) return ReportError(s.error());
    }
    progress.Step(of.number);
    ++frames_done;
    last_done_number = of.number;
  }
  if (guard.interrupted()) {
    progress.Finish();
    const int total = static_cast<int>(plan->count());
    const std::string next =
        glb ? "the .glb was not written; run the same command again to export it"
            : "run the same command with --resume to write the other " + std::to_string(total - frames_done);
    std::fprintf(stderr, "%s: %s\n", out.c_str(),
                 guard.StopMessage(last_done_number, frames_done, total, next).c_str());
    return guard.exit_code();
  }
  if (gltf) {
    if (base::Status s = gltf->Finish(out); !s) return ReportError(s.error());
  }
  progress.Finish();
  if (glb) {
    std::printf("glb:     %s (%zu frames, %s layout)\n", out.c_str(), plan->count(),
                deform::GltfExportLayoutName(gltf->layout()));
  } else if (guard.num_skipped() > 0) {
    std::printf("obj:     %s (%zu frames, %d kept from an earlier run)\n", out.c_str(), plan->count(),
                guard.num_skipped());
  } else {
    std::printf("obj:     %s (%zu frames)\n", out.c_str(), plan->count());
  }
  if (cameras) std::printf("cameras: %s\n", (out_dir / "camera_####.json").string().c_str());
  return 0;
}

}  // namespace app
