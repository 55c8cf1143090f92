#pragma once
// The exit code of a command that failed (the rule is in app/command_line.h):
// 3 for an internal error, 2 for everything else (bad input, unwritable output).

#include <cstdio>

#include "base/error.h"

namespace app {

// Prints `e` ("file:line:column: message") to stderr and returns its exit code.
inline int ReportError(const base::Error& e) {
  std::fprintf(stderr, "%s\n", e.ToString().c_str());
  return e.code == base::ErrorCode::kInternal ? 3 : 2;
}

// `e` reported as an internal error (exit 3): a step that fails only through a
// fault of our own, whatever code the library gave it.
inline int ReportInternal(base::Error e) {
  e.code = base::ErrorCode::kInternal;
  return ReportError(e);
}

}  // namespace app
