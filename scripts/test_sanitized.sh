#!/usr/bin/env bash
# The whole test suite under AddressSanitizer and UndefinedBehaviorSanitizer:
# the `asan` preset (build/asan: -O1 -g1, every library and test instrumented,
# no benchmarks), then ctest. -O1 instead of the dev preset's -O0 keeps the
# heavy tests (golden renders, the 90-frame interrupted render) affordable on
# a 2-core CI machine. Peak-memory tests skip themselves under ASan
# (tests/support/sanitizer.h); a test that cannot run here would carry the
# label `no_sanitizer` with its reason in tests/CMakeLists.txt (none does).
#
# Any report fails the run: ASan aborts on the first error, UBSan halts
# (-fno-sanitize-recover), and a child `patchskin` the app tests start inherits
# these options. Leak checking is off: OpenImageIO and OpenCV keep caches for
# the process lifetime that LeakSanitizer reports; the fuzzers (scripts/fuzz.sh)
# check leaks in our parsers, which use neither.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cmake --preset asan
cmake --build --preset asan
ctest --preset asan
