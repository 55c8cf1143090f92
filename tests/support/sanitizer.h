#pragma once
// Tests that bound a process's peak memory skip under AddressSanitizer: its
// allocator keeps freed blocks in a quarantine (256 MB by default) and pads every
// block with redzones, so resident memory says nothing about what the code holds.
// The normal build runs them.

#include <gtest/gtest.h>

#if defined(__SANITIZE_ADDRESS__)
#define PATCHSKIN_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PATCHSKIN_UNDER_ASAN 1
#endif
#endif

#ifdef PATCHSKIN_UNDER_ASAN
#define PATCHSKIN_SKIP_MEMORY_BOUND_UNDER_ASAN() \
  GTEST_SKIP() << "peak-memory bound not checked under AddressSanitizer (quarantine and redzones)"
#else
#define PATCHSKIN_SKIP_MEMORY_BOUND_UNDER_ASAN() static_cast<void>(0)
#endif
