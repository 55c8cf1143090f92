#include "app/motion_source.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

#include "mocap/bvh_reader.h"
#include "mocap/channel_use.h"

namespace app {
namespace {

std::string LowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

mocap::BvhReadOptions BvhOptions(const MotionSourceOptions& options) {
  mocap::BvhReadOptions bvh;
  bvh.scale = options.scale;
  bvh.convert_to_y_up = options.y_up;
  bvh.up_axis = options.up;
  bvh.position_mode = options.add_position_to_offset ? mocap::PositionChannelMode::kAddToOffset
                                                     : mocap::PositionChannelMode::kReplaceOffset;
  bvh.allow_short_motion = options.allow_short_motion;
  return bvh;
}

MotionSource FromBvh(mocap::BvhFile&& file) {
  MotionSource out;
  out.format = "bvh";
  out.skeleton = std::move(file.skeleton);
  out.motion = std::move(file.motion);
  out.warnings = std::move(file.warnings);
  return out;
}

}  // namespace

base::Result<MotionSource> LoadBvhText(std::string_view text, const std::string& name,
                                       const MotionSourceOptions& options) {
  base::Result<mocap::BvhFile> file = mocap::ParseBvh(text, name, BvhOptions(options));
  if (!file.ok()) return std::move(file).error();
  return FromBvh(std::move(*file));
}

base::Result<MotionSource> LoadMotionSource(const std::string& path,
                                            const MotionSourceOptions& options) {
  const base::FileLoc loc{path, 0, 0, {}};
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    return base::MakeError(base::ErrorCode::kIo, loc, "no such file");
  }
  if (std::filesystem::is_directory(status)) {
    return base::MakeError(base::ErrorCode::kIo, loc,
                           "expected a BVH, glTF or GLB file, found a directory");
  }
  const std::string ext = LowerExtension(path);
  MotionSource out;
  if (ext == ".bvh") {
    base::Result<mocap::BvhFile> file = mocap::ReadBvhFile(path, BvhOptions(options));
    if (!file.ok()) return std::move(file).error();
    return FromBvh(std::move(*file));
  }
  if (ext == ".gltf" || ext == ".glb") {
    deform::GltfReadOptions read;
    read.require_skin = options.require_skin;
    base::Result<deform::GltfModel> model = deform::ReadGltf(path, read);
    if (!model.ok()) return std::move(model).error();
    out.format = ext.substr(1);
    out.warnings = model->warnings;
    out.skeleton = model->skeleton;
    if (model->animations.empty()) {
      out.motion.num_channels = out.skeleton.num_channels;
      out.warnings.push_back({loc, "the model has no animation; using its rest pose"});
    } else {
      if (options.animation < 0 ||
          options.animation >= static_cast<int>(model->animations.size())) {
        return base::InvalidArgument(loc, "animation " + std::to_string(options.animation) +
                                              " does not exist (the file has " +
                                              std::to_string(model->animations.size()) + ")");
      }
      base::Result<mocap::Motion> motion =
          deform::AnimationToMotion(*model, options.animation, options.frame_time_s);
      if (!motion.ok()) return std::move(motion).error();
      out.motion = std::move(*motion);
    }
    out.skeleton.channel_use = mocap::ChannelUse(out.skeleton, out.motion);
    out.mesh_vertices = model->mesh.bind.num_vertices();
    out.mesh_triangles = model->mesh.bind.num_triangles();
    out.gltf = std::move(*model);
    return out;
  }
  return base::MakeError(base::ErrorCode::kUnsupported, loc,
                         "expected a .bvh, .gltf or .glb file, found extension '" + ext + "'");
}

}  // namespace app
