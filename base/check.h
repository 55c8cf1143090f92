#pragma once
// Internal invariants (never for untrusted input: that gets a Result).
// PATCHSKIN_CHECK is always on and cheap; PATCHSKIN_DCHECK only in debug builds.
// On failure they print the condition, file and line to stderr and abort.

#include <cstdio>
#include <cstdlib>

#define PATCHSKIN_CHECK(cond)                                                                \
  do {                                                                                       \
    if (!(cond)) {                                                                           \
      std::fprintf(stderr, "%s:%d: internal check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                          \
    }                                                                                        \
  } while (false)

#ifdef NDEBUG
#define PATCHSKIN_DCHECK(cond) \
  do {                         \
  } while (false)
#else
#define PATCHSKIN_DCHECK(cond) PATCHSKIN_CHECK(cond)
#endif
