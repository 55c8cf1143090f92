// libFuzzer target: the glTF import (deform::ReadGltfFromMemory) on arbitrary
// bytes, as .gltf JSON or, when they start with "glTF", as a GLB container;
// then, when the model loads, every animation sampled into a Motion.
// The file name points into a folder that does not exist, so external URIs
// fail to read and the fuzzer never touches the disk; data: URIs and the GLB
// binary chunk are the buffers it can reach.

#include <cstddef>
#include <cstdint>
#include <span>

#include "deform/io/gltf_import.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  deform::GltfReadOptions options;
  options.max_file_bytes = std::size_t{1} << 24;  // keep each run small and fast
  base::Result<deform::GltfModel> model =
      deform::ReadGltfFromMemory(std::span<const unsigned char>(data, size),
                                 "/nonexistent-patchskin-fuzz/model.gltf", options);
  if (!model.ok()) {
    (void)model.error().ToString();
    return 0;
  }
  for (int a = 0; a < static_cast<int>(model->animations.size()); ++a) {
    // A fixed 1/30 s step bounds the frames by the animation's duration, which
    // AnimationToMotion itself bounds (10^7 frames); keep runs short instead.
    if (model->animations[static_cast<std::size_t>(a)].duration_s > 60.0) continue;
    base::Result<mocap::Motion> motion = deform::AnimationToMotion(*model, a, 1.0 / 30.0);
    (void)motion.ok();
  }
  return 0;
}
