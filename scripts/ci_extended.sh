#!/usr/bin/env bash
# The robustness half of CI (issue 9): the whole test suite under
# AddressSanitizer and UndefinedBehaviorSanitizer (scripts/test_sanitized.sh,
# asan preset: -O1 -g1), then bounded fuzzing of every parser (scripts/fuzz.sh,
# clang + libFuzzer; FUZZ_SECONDS per target, default 60). .ci/run calls it
# after the normal suite. Cost on the 2-core CI machine (CPU seconds / 2): the
# sanitizer build ~14 min, its ctest ~4-5 min, the fuzz build ~2.5 min plus
# 3 x 60 s of fuzzing; with the normal part (~10 min) about 36 minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/test_sanitized.sh
bash scripts/setup_fuzz.sh
# A fixed seed and at most FUZZ_RUNS inputs per target: the same inputs on every
# machine (5000 per target took 10-40 s on the 2-core VM under load).
FUZZ_RUNS="${FUZZ_RUNS:-5000}" bash scripts/fuzz.sh "${FUZZ_SECONDS:-60}"
