#pragma once
// Motion: the sampled channel values of a clip, one contiguous #F x #C float
// array (row-major: frame f's values are values[f * num_channels ...]) plus the
// frame time. Rotation channels are in degrees, as in BVH. The channel layout
// (which joint reads which float) lives in the Skeleton.

#include <cstddef>
#include <span>
#include <vector>

namespace mocap {

struct Motion {
  int num_frames = 0;
  int num_channels = 0;
  double frame_time_s = 1.0 / 30.0;  // exact value from the file
  std::vector<float> values;         // #F x #C

  double fps() const { return frame_time_s > 0.0 ? 1.0 / frame_time_s : 0.0; }
  double duration_s() const {
    return num_frames > 1 ? (num_frames - 1) * frame_time_s : 0.0;
  }
  std::span<const float> frame(int f) const {
    return {values.data() + static_cast<std::size_t>(f) * static_cast<std::size_t>(num_channels),
            static_cast<std::size_t>(num_channels)};
  }
  std::span<float> frame(int f) {
    return {values.data() + static_cast<std::size_t>(f) * static_cast<std::size_t>(num_channels),
            static_cast<std::size_t>(num_channels)};
  }
};

// A frame rate reported to the user: a frame time within 1e-3 (relative) of 1/N s
// for an integer N is reported as N fps (0.0333333 s -> 30, not 30.00003); the
// exact frame time is still used for timing.
double NominalFps(double frame_time_s);

}  // namespace mocap
