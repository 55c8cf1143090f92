// PatchRebuildJob (ALGORITHMS.md 3.6): p = s(u,v) + d n(u,v) from the stored
// basis values and a 4x4 block of control points.
//
// The per-record arithmetic is one template, instantiated for float (scalar
// path) and for 8-lane GCC vectors compiled with AVX. Both perform the same
// IEEE operations in the same order (no FMA: -ffp-contract=off and no "fma"
// target), so every record's result is bit-identical whichever path, batch
// or thread computed it.

#include <algorithm>
#include <cmath>
#include <cstring>

#include <immintrin.h>

#include "deform/simd.h"
#include "deform/patch/patch_binding.h"

// The 8-lane helpers pass vectors by value, but all of them are internal and
// always inlined into AVX functions, so no call crosses the ABI GCC warns about.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace deform {
namespace {

typedef float V8 __attribute__((vector_size(32)));

template <typename V>
[[gnu::always_inline]] inline V Splat(float x) {
  if constexpr (sizeof(V) == sizeof(float)) {
    return x;
  } else {
    return x - V{};  // vector - scalar broadcasts; x - (+0) is x, even for -0
  }
}

// Derivatives of the four cubic basis functions of span k at u, from the
// span's constants t (layout in MakeSpanTable, patch_binding.cpp). With
// a = u_{k+1}-u, b = u-u_k, c = u-u_{k-1}, e = u_{k+2}-u the degree-2 values
// are N_{k-2,2} = a^2 r1 r2a, N_{k-1,2} = ac r1 r2a + be r1 r2b,
// N_{k,2} = b^2 r1 r2b, and N'_{i,3} = 3/(u_{i+3}-u_i) N_{i,2} - 3/(u_{i+4}-u_{i+1}) N_{i+1,2};
// the constant products are folded into t[4..7] (8 multiplies per direction).
template <typename V>
[[gnu::always_inline]] inline void DerivBasis(const V& u, const float* t, V* out) {
  const V a = Splat<V>(t[2]) - u;                                      // u_{k+1} - u
  const V b = u - Splat<V>(t[1]);                                      // u - u_k
  const V c = u - Splat<V>(t[0]);                                      // u - u_{k-1}
  const V e = Splat<V>(t[3]) - u;                                      // u_{k+2} - u
  const V c0 = (a * a) * Splat<V>(t[4]);                               // 3/(u_{k+1}-u_{k-2}) N_{k-2,2}
  const V c1 = (a * c) * Splat<V>(t[5]) + (b * e) * Splat<V>(t[6]);  // 3/(u_{k+2}-u_{k-1}) N_{k-1,2}
  const V c2 = (b * b) * Splat<V>(t[7]);                               // 3/(u_{k+3}-u_k) N_{k,2}
  out[0] = -c0;
  out[1] = c0 - c1;
  out[2] = c1 - c2;
  out[3] = c2;
}

// Inputs of one record (or 8 records sharing a span).
template <typename V>
struct RecordIn {
  V u, v, d, nu0, nu1, nu2, nv0, nv1, nv2;
};

// Surface point s and unnormalized normal c = cross(s_u, s_v).
template <typename V>
struct RecordOut {
  V sx, sy, sz, cx, cy, cz, len2;
};

template <typename V>
[[gnu::always_inline]] inline void EvaluateRecord(const RecordIn<V>& in, const float* tu,
                                                  const float* tv, const glm::vec3* q, int stride,
                                                  RecordOut<V>& out) {
  const V one = Splat<V>(1.0f);
  const V nu[4] = {in.nu0, in.nu1, in.nu2, ((one - in.nu0) - in.nu1) - in.nu2};
  const V nv[4] = {in.nv0, in.nv1, in.nv2, ((one - in.nv0) - in.nv1) - in.nv2};
  V dnu[4], dnv[4];
  DerivBasis(in.u, tu, dnu);
  DerivBasis(in.v, tv, dnv);
  V s[3] = {Splat<V>(0.0f), Splat<V>(0.0f), Splat<V>(0.0f)};
  V su[3] = {s[0], s[0], s[0]};
  V sv[3] = {s[0], s[0], s[0]};
#pragma GCC unroll 4
  for (int a = 0; a < 4; ++a) {
    const glm::vec3* row = q + a * stride;
#pragma GCC unroll 3
    for (int k = 0; k < 3; ++k) {
      V r = nv[0] * Splat<V>(row[0][k]);     // sum_b Nv[b] Q[a][b]
      V rv = dnv[0] * Splat<V>(row[0][k]);   // sum_b Nv'[b] Q[a][b]
#pragma GCC unroll 3
      for (int b = 1; b < 4; ++b) {
        const V qb = Splat<V>(row[b][k]);
        r = r + nv[b] * qb;
        rv = rv + dnv[b] * qb;
      }
      s[k] = s[k] + nu[a] * r;
      su[k] = su[k] + dnu[a] * r;
      sv[k] = sv[k] + nu[a] * rv;
    }
  }
  out.sx = s[0];
  out.sy = s[1];
  out.sz = s[2];
  out.cx = su[1] * sv[2] - su[2] * sv[1];
  out.cy = su[2] * sv[0] - su[0] * sv[2];
  out.cz = su[0] * sv[1] - su[1] * sv[0];
  out.len2 = (out.cx * out.cx + out.cy * out.cy) + out.cz * out.cz;
}

// Squared length below which the normal is taken as zero (degenerate patch).
constexpr float kTinyLen2 = 1e-30f;

void RunOne(const PatchRebuildJob& job, size_t i) {
  const PatchBindingView& b = job.bindings;
  const int i0 = b.first[i] & 0xff, j0 = b.first[i] >> 8;
  const RecordIn<float> in{b.u[i],   b.v[i],   b.d[i],   b.nu0[i], b.nu1[i],
                           b.nu2[i], b.nv0[i], b.nv1[i], b.nv2[i]};
  RecordOut<float> out;
  EvaluateRecord(in, &b.span_table_u[static_cast<size_t>(i0) * kSpanTableStride],
                 &b.span_table_v[static_cast<size_t>(j0) * kSpanTableStride],
                 &job.control[static_cast<size_t>(i0) * b.num_v + j0], b.num_v, out);
  const float len2 = out.len2 > kTinyLen2 ? out.len2 : kTinyLen2;
  const float scale = b.sigma / std::sqrt(len2);
  const float nx = out.cx * scale, ny = out.cy * scale, nz = out.cz * scale;
  job.positions[i] = glm::vec3(out.sx + in.d * nx, out.sy + in.d * ny, out.sz + in.d * nz);
  if (!job.normals.empty()) job.normals[i] = glm::vec3(nx, ny, nz);
}

[[gnu::target("avx")]] inline V8 Load8(const float* p) {
  V8 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

// Lanes of a short run: records i .. i+count-1, the last one repeated.
[[gnu::target("avx")]] inline V8 LoadPadded(std::span<const float> a, size_t i, size_t count) {
  alignas(32) float tmp[8];
  for (size_t l = 0; l < 8; ++l) tmp[l] = a[i + (l < count ? l : count - 1)];
  return Load8(tmp);
}

// Writes 8 points given as x, y, z lanes to 8 consecutive glm::vec3 (24
// floats) with a shuffle transpose instead of 24 lane extracts.
[[gnu::target("avx")]] inline void StoreAos8(const V8& x, const V8& y, const V8& z, float* out) {
  const __m256 rxy = _mm256_shuffle_ps(__m256(x), __m256(y), _MM_SHUFFLE(2, 0, 2, 0));  // x0 x2 y0 y2
  const __m256 ryz = _mm256_shuffle_ps(__m256(y), __m256(z), _MM_SHUFFLE(3, 1, 3, 1));  // y1 y3 z1 z3
  const __m256 rzx = _mm256_shuffle_ps(__m256(z), __m256(x), _MM_SHUFFLE(3, 1, 2, 0));  // z0 z2 x1 x3
  const __m256 r03 = _mm256_shuffle_ps(rxy, rzx, _MM_SHUFFLE(2, 0, 2, 0));  // x0 y0 z0 x1
  const __m256 r14 = _mm256_shuffle_ps(ryz, rxy, _MM_SHUFFLE(3, 1, 2, 0));  // y1 z1 x2 y2
  const __m256 r25 = _mm256_shuffle_ps(rzx, ryz, _MM_SHUFFLE(3, 1, 3, 1));  // z2 x3 y3 z3
  _mm256_storeu_ps(out, _mm256_permute2f128_ps(r03, r14, 0x20));
  _mm256_storeu_ps(out + 8, _mm256_permute2f128_ps(r25, r03, 0x30));
  _mm256_storeu_ps(out + 16, _mm256_permute2f128_ps(r14, r25, 0x31));
}

// `count` (1..8) consecutive records that share one span, in 8 lanes.
[[gnu::target("avx")]] void RunBatch(const PatchRebuildJob& job, size_t i, size_t count) {
  const PatchBindingView& b = job.bindings;
  const int i0 = b.first[i] & 0xff, j0 = b.first[i] >> 8;
  RecordIn<V8> in;
  if (count == 8) {
    in = {Load8(&b.u[i]),   Load8(&b.v[i]),   Load8(&b.d[i]),   Load8(&b.nu0[i]), Load8(&b.nu1[i]),
          Load8(&b.nu2[i]), Load8(&b.nv0[i]), Load8(&b.nv1[i]), Load8(&b.nv2[i])};
  } else {
    in = {LoadPadded(b.u, i, count),   LoadPadded(b.v, i, count),   LoadPadded(b.d, i, count),
          LoadPadded(b.nu0, i, count), LoadPadded(b.nu1, i, count), LoadPadded(b.nu2, i, count),
          LoadPadded(b.nv0, i, count), LoadPadded(b.nv1, i, count), LoadPadded(b.nv2, i, count)};
  }
  RecordOut<V8> out;
  EvaluateRecord(in, &b.span_table_u[static_cast<size_t>(i0) * kSpanTableStride],
                 &b.span_table_v[static_cast<size_t>(j0) * kSpanTableStride],
                 &job.control[static_cast<size_t>(i0) * b.num_v + j0], b.num_v, out);
  const V8 tiny = Splat<V8>(kTinyLen2);
  const V8 len2 = out.len2 > tiny ? out.len2 : tiny;
  const V8 scale = Splat<V8>(b.sigma) / V8(_mm256_sqrt_ps(__m256(len2)));
  const V8 nx = out.cx * scale, ny = out.cy * scale, nz = out.cz * scale;
  const V8 px = out.sx + in.d * nx, py = out.sy + in.d * ny, pz = out.sz + in.d * nz;
  const bool normals = !job.normals.empty();
  if (count == 8) {
    StoreAos8(px, py, pz, &job.positions[i].x);
    if (normals) StoreAos8(nx, ny, nz, &job.normals[i].x);
    return;
  }
  glm::vec3 tmp[8];
  StoreAos8(px, py, pz, &tmp[0].x);
  for (size_t l = 0; l < count; ++l) job.positions[i + l] = tmp[l];
  if (normals) {
    StoreAos8(nx, ny, nz, &tmp[0].x);
    for (size_t l = 0; l < count; ++l) job.normals[i + l] = tmp[l];
  }
}

// Runs shorter than this go through the scalar path (same results, less work).
constexpr size_t kMinBatch = 3;

}  // namespace

base::JobStatus PatchRebuildJob::Validate() const {
  using base::JobStatus;
  const PatchBindingView& b = bindings;
  if (b.num_u < 4 || b.num_v < 4 || b.num_u > 256 || b.num_v > 256) {
    return {JobStatus::kOutOfRange, "control grid must be 4..256 points each way"};
  }
  if (control.size() != static_cast<size_t>(b.num_u) * static_cast<size_t>(b.num_v)) {
    return {JobStatus::kSizeMismatch, "control must hold num_u x num_v points"};
  }
  if (b.span_table_u.size() != static_cast<size_t>(b.num_u - 3) * kSpanTableStride ||
      b.span_table_v.size() != static_cast<size_t>(b.num_v - 3) * kSpanTableStride) {
    return {JobStatus::kSizeMismatch, "span tables must hold (M-3) and (N-3) entries"};
  }
  const size_t n = b.size();
  if (b.u.size() != n || b.v.size() != n || b.nu0.size() != n || b.nu1.size() != n ||
      b.nu2.size() != n || b.nv0.size() != n || b.nv1.size() != n || b.nv2.size() != n ||
      b.first.size() != n) {
    return {JobStatus::kSizeMismatch, "binding record arrays differ in length"};
  }
  if (positions.size() != n) return {JobStatus::kSizeMismatch, "positions must hold #B points"};
  if (!normals.empty() && normals.size() != n) {
    return {JobStatus::kSizeMismatch, "normals must be empty or hold #B normals"};
  }
  if (b.sigma != 1.0f && b.sigma != -1.0f) return {JobStatus::kOutOfRange, "sigma must be +1 or -1"};
  return base::kJobOk;
}

base::JobStatus PatchRebuildJob::Run() const {
  if (const base::JobStatus st = Validate(); !st) return st;
  const size_t n = bindings.size();
  const bool simd = UseAvx();  // deform/simd.h: the CPU has it and the cap allows it
  const std::uint16_t* first = bindings.first.data();
  size_t i = 0;
  while (i < n) {
    size_t end = i + 1;  // the run of records sharing i's span
    while (end < n && first[end] == first[i]) ++end;
    const size_t run = end - i;
    if (!simd || run < kMinBatch) {
      for (size_t k = i; k < end; ++k) RunOne(*this, k);
    } else if (run < 8) {
      RunBatch(*this, i, run);
    } else {
      // Full batches, the last one overlapping the previous so that no lane
      // is wasted; overlapped records are recomputed to identical values.
      for (size_t k = i; k < end; k += 8) RunBatch(*this, std::min(k, end - 8), 8);
    }
    i = end;
  }
  return base::kJobOk;
}

}  // namespace deform
