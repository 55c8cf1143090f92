#include "deform/simd.h"

#include <atomic>

#include "deform/internal/cpu_features.h"

namespace deform {
namespace {

std::atomic<SimdLevel> g_simd_cap{SimdLevel::kAvx};

}  // namespace

void SetSimdCap(SimdLevel cap) { g_simd_cap.store(cap, std::memory_order_relaxed); }

SimdLevel SimdCap() { return g_simd_cap.load(std::memory_order_relaxed); }

bool UseAvx() { return SimdCap() == SimdLevel::kAvx && internal::CpuHasAvx(); }

}  // namespace deform
