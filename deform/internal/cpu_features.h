#pragma once
// Run-time CPU feature checks for the SIMD paths chosen at run time (x86-64,
// GCC or Clang); each asks the CPU once per process.

namespace deform::internal {

inline bool CpuHasAvx() {
  static const bool has = __builtin_cpu_supports("avx");
  return has;
}

}  // namespace deform::internal
