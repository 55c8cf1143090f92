#!/usr/bin/env bash
# The robustness half of CI (issue 9), kept out of .ci/run until a full run of
# it has been timed and seen green on a 2-core machine: the whole suite under
# AddressSanitizer and UndefinedBehaviorSanitizer (dev preset), then bounded
# fuzzing of every parser.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

# Third-party libraries are not instrumented; leaks they keep for the process
# lifetime (OpenImageIO, OpenCV caches) are not ours, so leak checking is off
# here and left to the fuzzers, which run only our parsers.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cmake --preset dev
cmake --build --preset dev
ctest --preset dev

# Bounded fuzzing of every parser (clang + libFuzzer), 60 s per target.
unset ASAN_OPTIONS UBSAN_OPTIONS
bash scripts/setup_fuzz.sh
bash scripts/fuzz.sh "${FUZZ_SECONDS:-60}"
