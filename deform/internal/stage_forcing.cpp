#include "deform/internal/stage_forcing.h"

#include <algorithm>
#include <cstddef>

#include <glm/gtc/quaternion.hpp>

namespace deform::internal {
namespace {

// Four floats, one per frame (SSE2, the x86-64 baseline).
typedef float F4 __attribute__((vector_size(16)));
typedef int I4 __attribute__((vector_size(16)));

inline F4 Splat(float x) { return F4{x, x, x, x}; }

// Lane l of each field is frame l's value.
struct Frames4 {
  F4 qw, qx, qy, qz;  // rotation R
  F4 a[3];            // R^T o''
  F4 w[3];            // angular velocity
  F4 al[3];           // angular acceleration
};

Frames4 Gather(const DrivingFrame* f) {
  Frames4 g;
  for (int l = 0; l < 4; ++l) {
    g.qw[l] = f[l].rotation.w;
    g.qx[l] = f[l].rotation.x;
    g.qy[l] = f[l].rotation.y;
    g.qz[l] = f[l].rotation.z;
    for (int c = 0; c < 3; ++c) {
      g.a[c][l] = f[l].linear_acceleration[c];
      g.w[c][l] = f[l].angular_velocity[c];
      g.al[c][l] = f[l].angular_acceleration[c];
    }
  }
  return g;
}

// StageCoefficientsOf for four frames; `count` (1..4) of them are written.
void Four(const DrivingFrame* frames, int count, const ForcingConstants& k,
          StageCoefficients* out) {
  const Frames4 f = Gather(frames);
  // common = -gam a + u, per component (glm: scalar * vec3, then + vec3).
  const F4 neg_gain = Splat(-k.gain);
  F4 common[3];
  for (int c = 0; c < 3; ++c) common[c] = neg_gain * f.a[c] + Splat(k.user_acceleration[c]);
  if (k.gravity) {
    // glm::normalize(q): len = sqrt((w w + x x) + (y y + z z)); identity if
    // len <= 0, else each component times 1 / len.
    const F4 dot = (f.qw * f.qw + f.qx * f.qx) + (f.qy * f.qy + f.qz * f.qz);
    const F4 len = __builtin_ia32_sqrtps(dot);
    const F4 one_over = Splat(1.0f) / len;
    const I4 degenerate = len <= Splat(0.0f);
    const F4 nw = degenerate ? Splat(1.0f) : f.qw * one_over;
    const F4 nx = degenerate ? Splat(0.0f) : f.qx * one_over;
    const F4 ny = degenerate ? Splat(0.0f) : f.qy * one_over;
    const F4 nz = degenerate ? Splat(0.0f) : f.qz * one_over;
    // glm::conjugate, then quat * vec3: uv = q_xyz x v, uuv = q_xyz x uv,
    // v + ((uv * q_w) + uuv) * 2.
    const F4 qx = -nx, qy = -ny, qz = -nz, qw = nw;
    const F4 vx = Splat(k.gravity_model.x), vy = Splat(k.gravity_model.y),
             vz = Splat(k.gravity_model.z);
    const F4 uvx = qy * vz - vy * qz, uvy = qz * vx - vz * qx, uvz = qx * vy - vx * qy;
    const F4 uuvx = qy * uvz - uvy * qz, uuvy = qz * uvx - uvz * qx, uuvz = qx * uvy - uvx * qy;
    const F4 two = Splat(2.0f);
    const F4 rotated[3] = {vx + ((uvx * qw) + uuvx) * two, vy + ((uvy * qw) + uuvy) * two,
                           vz + ((uvz * qw) + uuvz) * two};
    for (int c = 0; c < 3; ++c) common[c] = common[c] + (rotated[c] - Splat(k.gravity_bind[c]));
  }
  // mx = -gam (skew(al) + w w^T - ww I), mv = (-2 gam) skew(w), entry by entry
  // as the scalar loop (zeros of the skew matrices included: 0 + -0 is +0).
  const F4 zero = Splat(0.0f);
  const F4 ww = (f.w[0] * f.w[0] + f.w[1] * f.w[1]) + f.w[2] * f.w[2];
  const F4 skew_al[3][3] = {{zero, -f.al[2], f.al[1]}, {f.al[2], zero, -f.al[0]},
                            {-f.al[1], f.al[0], zero}};
  const F4 skew_w[3][3] = {{zero, -f.w[2], f.w[1]}, {f.w[2], zero, -f.w[0]},
                           {-f.w[1], f.w[0], zero}};
  const F4 mv_scale = Splat(-2.0f * k.gain);
  F4 mx[3][3], mv[3][3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const F4 w2 = f.w[r] * f.w[c] - (r == c ? ww : zero);
      mx[r][c] = neg_gain * (skew_al[r][c] + w2);
      mv[r][c] = mv_scale * skew_w[r][c];
    }
  }
  for (int l = 0; l < count; ++l) {
    StageCoefficients& o = out[l];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        o.mx[r][c] = mx[r][c][l];
        o.mv[r][c] = mv[r][c][l];
      }
      o.common[r] = common[r][l];
    }
  }
}

}  // namespace

StageCoefficients StageCoefficientsOf(const DrivingFrame& d, const ForcingConstants& k) {
  glm::vec3 common = -k.gain * d.linear_acceleration + k.user_acceleration;
  if (k.gravity) common += glm::conjugate(glm::normalize(d.rotation)) * k.gravity_model - k.gravity_bind;
  StageCoefficients m;
  const glm::vec3 w = d.angular_velocity, al = d.angular_acceleration;
  const float ww = glm::dot(w, w);
  const float skew_al[3][3] = {{0, -al.z, al.y}, {al.z, 0, -al.x}, {-al.y, al.x, 0}};
  const float skew_w[3][3] = {{0, -w.z, w.y}, {w.z, 0, -w.x}, {-w.y, w.x, 0}};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const float w2 = w[r] * w[c] - (r == c ? ww : 0.0f);  // [w]x^2 = w w^T - |w|^2 I
      m.mx[r][c] = -k.gain * (skew_al[r][c] + w2);
      m.mv[r][c] = -2.0f * k.gain * skew_w[r][c];
    }
    m.common[r] = common[r];
  }
  return m;
}

void StageCoefficientsOfEach(std::span<const DrivingFrame> frames, const ForcingConstants& k,
                             std::span<StageCoefficients> out) {
  const std::size_t n = std::min(frames.size(), out.size());
  for (std::size_t i = 0; i < n; i += 4) {
    const int count = static_cast<int>(std::min<std::size_t>(4, n - i));
    if (count == 4) {
      Four(frames.data() + i, 4, k, out.data() + i);
    } else {  // the last few: pad the lanes with the last frame, keep `count`
      DrivingFrame padded[4];
      for (int l = 0; l < 4; ++l) padded[l] = frames[i + static_cast<std::size_t>(std::min(l, count - 1))];
      Four(padded, count, k, out.data() + i);
    }
  }
}

}  // namespace deform::internal
