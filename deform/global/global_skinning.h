#pragma once
// The global layer's methods (ALGORITHMS.md 2): skinning by blended matrices
// (SSD), by blended dual quaternions (DQS), or by sweeps along the body's
// chains (SWD).

namespace deform {

enum class GlobalMethod { kSsd, kDqs, kSwd };

// "ssd", "dqs" or "swd".
const char* GlobalMethodName(GlobalMethod method);

}  // namespace deform
