#include "deform/global/skinning_job.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <glm/gtc/type_ptr.hpp>

#if defined(__SSE2__) && !defined(PATCHSKIN_SCALAR_SKINNING)
#include <emmintrin.h>
#define PATCHSKIN_SKINNING_SSE2 1
#if defined(__GNUC__) && defined(__x86_64__) && !defined(PATCHSKIN_NO_AVX_SKINNING)
#include <immintrin.h>

#include "deform/simd.h"
#define PATCHSKIN_SKINNING_AVX 1
#endif
#endif

namespace deform {
namespace {

using base::JobStatus;

#if defined(PATCHSKIN_SKINNING_SSE2)

inline void Store3(glm::vec3& out, __m128 v) {
  _mm_storel_pi(reinterpret_cast<__m64*>(&out.x), v);  // x, y
  _mm_store_ss(&out.z, _mm_movehl_ps(v, v));           // z
}

// Writes x, y, z of `v` to out[i]. Except at the last vertex of the span, one
// 16-byte store is used: its fourth float lands on out[i + 1].x, which this
// same loop overwrites next, so nothing outside the span is ever touched.
inline void StoreVertex(glm::vec3* out, std::size_t i, std::size_t n, __m128 v) {
  if (i + 1 < n) {
    _mm_storeu_ps(&out[i].x, v);
  } else {
    Store3(out[i], v);
  }
}

// kN influences, with or without normals. The blended matrix lives in four
// SSE registers (one column each, the w lane unused); adding the influences in
// slot order makes an identity palette reproduce the input exactly.
template <int kN, bool kNormals>
void SkinSpan(const SkinningJob& job) {
  const float* palette = glm::value_ptr(job.model_from_bind[0]);
  const std::uint16_t* indices = job.joint_indices.data();
  const float* weights = job.joint_weights.data();
  const std::size_t n = job.rest_positions.size();
  // Locals, not job fields: the stores below could alias the job as far as the
  // compiler knows, which would reload every span pointer per vertex.
  const glm::vec3* rest_positions = job.rest_positions.data();
  const glm::vec3* rest_normals = job.rest_normals.data();
  glm::vec3* out_positions = job.positions.data();
  glm::vec3* out_normals = job.normals.data();
  for (std::size_t v = 0; v < n; ++v, indices += kN, weights += kN) {
    const float* m = palette + 16 * static_cast<std::size_t>(indices[0]);
    __m128 w = _mm_set1_ps(weights[0]);
    __m128 c0 = _mm_mul_ps(_mm_loadu_ps(m + 0), w);
    __m128 c1 = _mm_mul_ps(_mm_loadu_ps(m + 4), w);
    __m128 c2 = _mm_mul_ps(_mm_loadu_ps(m + 8), w);
    __m128 c3 = _mm_mul_ps(_mm_loadu_ps(m + 12), w);
    for (int i = 1; i < kN; ++i) {
      m = palette + 16 * static_cast<std::size_t>(indices[i]);
      w = _mm_set1_ps(weights[i]);
      c0 = _mm_add_ps(c0, _mm_mul_ps(_mm_loadu_ps(m + 0), w));
      c1 = _mm_add_ps(c1, _mm_mul_ps(_mm_loadu_ps(m + 4), w));
      c2 = _mm_add_ps(c2, _mm_mul_ps(_mm_loadu_ps(m + 8), w));
      c3 = _mm_add_ps(c3, _mm_mul_ps(_mm_loadu_ps(m + 12), w));
    }
    const glm::vec3& p = rest_positions[v];
    const __m128 out_p = _mm_add_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(c0, _mm_set1_ps(p.x)), _mm_mul_ps(c1, _mm_set1_ps(p.y))),
                   _mm_mul_ps(c2, _mm_set1_ps(p.z))),
        c3);
    StoreVertex(out_positions, v, n, out_p);
    if constexpr (kNormals) {
      const glm::vec3& nr = rest_normals[v];
      const __m128 out_n = _mm_add_ps(
          _mm_add_ps(_mm_mul_ps(c0, _mm_set1_ps(nr.x)), _mm_mul_ps(c1, _mm_set1_ps(nr.y))),
          _mm_mul_ps(c2, _mm_set1_ps(nr.z)));
      StoreVertex(out_normals, v, n, out_n);
    }
  }
}

#if defined(PATCHSKIN_SKINNING_AVX)
// The same computation with the influence blend two columns at a time in
// 256-bit registers. Every lane sees the same multiplies and adds in the same
// order as SkinSpan, so both paths give identical bits. Compiled for AVX with
// a function attribute and chosen at run time, so the build stays portable.
template <int kN, bool kNormals>
__attribute__((target("avx"))) void SkinSpanAvx(const SkinningJob& job) {
  const float* palette = glm::value_ptr(job.model_from_bind[0]);
  const std::uint16_t* indices = job.joint_indices.data();
  const float* weights = job.joint_weights.data();
  const std::size_t n = job.rest_positions.size();
  // Locals, not job fields: the stores below could alias the job as far as the
  // compiler knows, which would reload every span pointer per vertex.
  const glm::vec3* rest_positions = job.rest_positions.data();
  const glm::vec3* rest_normals = job.rest_normals.data();
  glm::vec3* out_positions = job.positions.data();
  glm::vec3* out_normals = job.normals.data();
  for (std::size_t v = 0; v < n; ++v, indices += kN, weights += kN) {
    const float* m = palette + 16 * static_cast<std::size_t>(indices[0]);
    __m256 w = _mm256_set1_ps(weights[0]);
    __m256 c01 = _mm256_mul_ps(_mm256_loadu_ps(m + 0), w);
    __m256 c23 = _mm256_mul_ps(_mm256_loadu_ps(m + 8), w);
    for (int i = 1; i < kN; ++i) {
      m = palette + 16 * static_cast<std::size_t>(indices[i]);
      w = _mm256_set1_ps(weights[i]);
      c01 = _mm256_add_ps(c01, _mm256_mul_ps(_mm256_loadu_ps(m + 0), w));
      c23 = _mm256_add_ps(c23, _mm256_mul_ps(_mm256_loadu_ps(m + 8), w));
    }
    const __m128 c0 = _mm256_castps256_ps128(c01);
    const __m128 c1 = _mm256_extractf128_ps(c01, 1);
    const __m128 c2 = _mm256_castps256_ps128(c23);
    const __m128 c3 = _mm256_extractf128_ps(c23, 1);
    const glm::vec3& p = rest_positions[v];
    const __m128 out_p = _mm_add_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(c0, _mm_set1_ps(p.x)), _mm_mul_ps(c1, _mm_set1_ps(p.y))),
                   _mm_mul_ps(c2, _mm_set1_ps(p.z))),
        c3);
    StoreVertex(out_positions, v, n, out_p);
    if constexpr (kNormals) {
      const glm::vec3& nr = rest_normals[v];
      const __m128 out_n = _mm_add_ps(
          _mm_add_ps(_mm_mul_ps(c0, _mm_set1_ps(nr.x)), _mm_mul_ps(c1, _mm_set1_ps(nr.y))),
          _mm_mul_ps(c2, _mm_set1_ps(nr.z)));
      StoreVertex(out_normals, v, n, out_n);
    }
  }
}

#endif

#else  // portable scalar loop, same order of operations as the SSE2 one

template <int kN, bool kNormals>
void SkinSpan(const SkinningJob& job) {
  const std::uint16_t* indices = job.joint_indices.data();
  const float* weights = job.joint_weights.data();
  const std::size_t n = job.rest_positions.size();
  const glm::vec3* rest_positions = job.rest_positions.data();
  const glm::vec3* rest_normals = job.rest_normals.data();
  for (std::size_t v = 0; v < n; ++v, indices += kN, weights += kN) {
    float c[12];
    const glm::mat4& m0 = job.model_from_bind[indices[0]];
    for (int col = 0; col < 4; ++col) {
      for (int row = 0; row < 3; ++row) c[col * 3 + row] = m0[col][row] * weights[0];
    }
    for (int i = 1; i < kN; ++i) {
      const glm::mat4& m = job.model_from_bind[indices[i]];
      for (int col = 0; col < 4; ++col) {
        for (int row = 0; row < 3; ++row) c[col * 3 + row] += m[col][row] * weights[i];
      }
    }
    const glm::vec3& p = rest_positions[v];
    for (int row = 0; row < 3; ++row) {
      job.positions[v][row] = c[row] * p.x + c[3 + row] * p.y + c[6 + row] * p.z + c[9 + row];
    }
    if constexpr (kNormals) {
      const glm::vec3& nr = rest_normals[v];
      for (int row = 0; row < 3; ++row) {
        job.normals[v][row] = c[row] * nr.x + c[3 + row] * nr.y + c[6 + row] * nr.z;
      }
    }
  }
}

#endif

template <int kN>
void SkinDispatchNormals(const SkinningJob& job) {
#if defined(PATCHSKIN_SKINNING_AVX)
  if (UseAvx()) {
    if (job.rest_normals.empty()) {
      SkinSpanAvx<kN, false>(job);
    } else {
      SkinSpanAvx<kN, true>(job);
    }
    return;
  }
#endif
  if (job.rest_normals.empty()) {
    SkinSpan<kN, false>(job);
  } else {
    SkinSpan<kN, true>(job);
  }
}

}  // namespace

const char* SkinningSimdPath() {
#if defined(PATCHSKIN_SKINNING_AVX)
  if (UseAvx()) return "avx";
#endif
#if defined(PATCHSKIN_SKINNING_SSE2)
  return "sse2";
#else
  return "scalar";
#endif
}

JobStatus SkinningJob::Validate() const {
  if (influences < 1 || influences > kMaxInfluences) {
    return {JobStatus::kOutOfRange, "influences must be in 1..kMaxInfluences"};
  }
  const std::size_t n = rest_positions.size();
  const std::size_t per_vertex = static_cast<std::size_t>(influences);
  if (n > 0 && model_from_bind.empty()) {
    return {JobStatus::kMissingInput, "model_from_bind palette is empty"};
  }
  if (joint_indices.size() != n * per_vertex) {
    return {JobStatus::kSizeMismatch, "joint_indices must hold #V x influences entries"};
  }
  if (joint_weights.size() != n * per_vertex) {
    return {JobStatus::kSizeMismatch, "joint_weights must hold #V x influences entries"};
  }
  if (positions.size() != n) {
    return {JobStatus::kSizeMismatch, "positions must have #V entries"};
  }
  if (!rest_normals.empty()) {
    if (normals.empty()) return {JobStatus::kMissingOutput, "rest_normals set without normals"};
    if (rest_normals.size() != n || normals.size() != n) {
      return {JobStatus::kSizeMismatch, "rest_normals and normals must have #V entries"};
    }
  }
  return base::kJobOk;
}

JobStatus SkinningJob::Run() const {
  const JobStatus status = Validate();
  if (!status.ok() || rest_positions.empty()) return status;
  switch (influences) {
    case 1: SkinDispatchNormals<1>(*this); break;
    case 2: SkinDispatchNormals<2>(*this); break;
    case 3: SkinDispatchNormals<3>(*this); break;
    case 4: SkinDispatchNormals<4>(*this); break;
    case 5: SkinDispatchNormals<5>(*this); break;
    case 6: SkinDispatchNormals<6>(*this); break;
    case 7: SkinDispatchNormals<7>(*this); break;
    default: SkinDispatchNormals<8>(*this); break;
  }
  return base::kJobOk;
}

JobStatus BuildSkinningPalette(std::span<const glm::mat4> model_from_joint,
                               const SkinnedMesh& mesh, std::span<glm::mat4> model_from_bind) {
  const std::size_t s = mesh.skin_joints.size();
  if (mesh.joint_from_bind.size() != s || model_from_bind.size() != s) {
    return {JobStatus::kSizeMismatch, "palette, skin_joints and joint_from_bind must have #S entries"};
  }
  for (std::size_t i = 0; i < s; ++i) {
    const int j = mesh.skin_joints[i];
    if (j < 0 || static_cast<std::size_t>(j) >= model_from_joint.size()) {
      return {JobStatus::kOutOfRange, "a skin joint is not an index into model_from_joint"};
    }
    model_from_bind[i] = model_from_joint[static_cast<std::size_t>(j)] * mesh.joint_from_bind[i];
  }
  return base::kJobOk;
}

base::Status CheckSkinWeights(const SkinWeights& weights, int num_skin_joints, int num_vertices) {
  using base::ErrorCode;
  using base::MakeError;
  if (weights.influences < 1 || weights.influences > kMaxInfluences) {
    return base::InvalidArgument("skin weights have " + std::to_string(weights.influences) +
                                 " influences per vertex, expected 1.." +
                                 std::to_string(kMaxInfluences));
  }
  const std::size_t k = static_cast<std::size_t>(weights.influences);
  if (weights.weights.size() % k != 0 || weights.joints.size() != weights.weights.size()) {
    return MakeError(ErrorCode::kCountMismatch, {},
                     "skin weights hold " + std::to_string(weights.weights.size()) + " weights and " +
                         std::to_string(weights.joints.size()) + " joint indices, expected #V x " +
                         std::to_string(k) + " of each");
  }
  const std::size_t nv = weights.weights.size() / k;
  if (num_vertices >= 0 && nv != static_cast<std::size_t>(num_vertices)) {
    return MakeError(ErrorCode::kCountMismatch, {},
                     "skin weights cover " + std::to_string(nv) + " vertices, expected " +
                         std::to_string(num_vertices));
  }
  for (std::size_t v = 0; v < nv; ++v) {
    double sum = 0.0;
    for (std::size_t i = 0; i < k; ++i) {
      const float w = weights.weights[v * k + i];
      if (!std::isfinite(w) || w < 0.0f) {
        return base::InvalidArgument("vertex " + std::to_string(v) +
                                     " has a negative or non-finite weight");
      }
      if (weights.joints[v * k + i] >= num_skin_joints) {
        return base::InvalidArgument("vertex " + std::to_string(v) + " names skin joint " +
                                     std::to_string(weights.joints[v * k + i]) + ", expected < " +
                                     std::to_string(num_skin_joints));
      }
      sum += w;
    }
    if (std::abs(sum - 1.0) > 1e-4) {
      return base::InvalidArgument("weights of vertex " + std::to_string(v) + " sum to " +
                                   std::to_string(sum) + ", expected 1");
    }
  }
  return base::Status::Ok();
}

void NormalizeSkinWeights(SkinWeights& weights) {
  const int k = weights.influences;
  if (k < 1 || k > kMaxInfluences) return;
  const std::size_t nv = weights.weights.size() / static_cast<std::size_t>(k);
  for (std::size_t v = 0; v < nv; ++v) {
    float* w = weights.weights.data() + v * static_cast<std::size_t>(k);
    std::uint16_t* j = weights.joints.data() + v * static_cast<std::size_t>(k);
    // Largest first (a stable insertion sort keeps ties in slot order).
    for (int a = 1; a < k; ++a) {
      for (int b = a; b > 0 && w[b] > w[b - 1]; --b) {
        std::swap(w[b], w[b - 1]);
        std::swap(j[b], j[b - 1]);
      }
    }
    double total = 0.0;
    for (int i = 0; i < k; ++i) total += w[i];
    if (!(total > 0.0) || !std::isfinite(total)) {
      for (int i = 0; i < k; ++i) w[i] = i == 0 ? 1.0f : 0.0f;
      continue;
    }
    int last = 0;  // last non-zero slot after scaling
    for (int i = 0; i < k; ++i) {
      w[i] = static_cast<float>(w[i] / total);
      if (w[i] > 0.0f) last = i;
    }
    // The last non-zero weight takes 1 minus the float sum of the ones before
    // it, added in slot order as the jobs add them. Sorted, that partial sum is
    // in [0.5, 1], so the subtraction is exact (Sterbenz) and so is the total.
    float partial = 0.0f;
    for (int i = 0; i < last; ++i) partial += w[i];
    w[last] = last == 0 ? 1.0f : std::max(1.0f - partial, 0.0f);
  }
}

}  // namespace deform
