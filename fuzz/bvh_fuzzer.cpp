// libFuzzer target: mocap::ParseBvh on arbitrary bytes, then, when the file
// parses, the same text with unit detection and Z-up conversion, and a pose
// of the first and last frames (the data a parse accepts must be usable).
// Whatever the input, the parser must return a Result: no crash, no hang, no
// allocation beyond what the text's size allows (libFuzzer's -rss_limit_mb and
// -malloc_limit_mb catch the last).

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "mocap/bvh_reader.h"
#include "mocap/pose.h"

namespace {

void PoseFrame(const mocap::BvhFile& file, int frame) {
  const auto nj = static_cast<std::size_t>(file.skeleton.num_joints());
  std::vector<mocap::JointTransform> locals(nj);
  std::vector<glm::mat4> model(nj);
  if (file.motion.num_frames > 0) {
    (void)mocap::LocalPoseJob{&file.skeleton, file.motion.frame(frame), locals}.Run();
  } else {
    mocap::RestPose(file.skeleton, locals);
  }
  (void)mocap::LocalToModelJob{
      .parents = file.skeleton.parents, .locals = locals, .model_from_joint = model}
      .Run();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  base::Result<mocap::BvhFile> file = mocap::ParseBvh(text, "fuzz.bvh");
  if (!file.ok()) {
    (void)file.error().ToString();
    return 0;
  }
  PoseFrame(*file, 0);
  if (file->motion.num_frames > 1) PoseFrame(*file, file->motion.num_frames - 1);
  mocap::BvhReadOptions options;
  options.scale = 0.0f;
  options.convert_to_y_up = true;
  options.position_mode = mocap::PositionChannelMode::kAddToOffset;
  base::Result<mocap::BvhFile> converted = mocap::ParseBvh(text, "fuzz.bvh", options);
  if (converted.ok()) PoseFrame(*converted, 0);
  return 0;
}
