#pragma once
// The one switch over deform's SIMD kernels (x86-64): each kernel takes the
// widest instruction set the CPU reports, up to a process-wide cap. Every path
// gives the same bits, so the cap only lets tests and benchmarks compare the
// paths on one machine; no job takes an instruction-set option.

namespace deform {

enum class SimdLevel { kBaseline, kAvx };  // kBaseline: SSE2 on x86-64, else scalar

// Caps the level kernels may use from now on (default: kAvx). Set it before
// running jobs, not while they run.
void SetSimdCap(SimdLevel cap);
SimdLevel SimdCap();

// True when kernels may use AVX: the CPU has it and the cap allows it.
bool UseAvx();

}  // namespace deform
