#!/usr/bin/env bash
# The robustness half of CI (issue 9): the whole test suite under
# AddressSanitizer and UndefinedBehaviorSanitizer (scripts/test_sanitized.sh,
# asan preset: -O1 -g1), then bounded fuzzing of every parser (scripts/fuzz.sh,
# clang + libFuzzer; FUZZ_SECONDS per target, default 60). Kept out of .ci/run
# until a full run of it has been timed on an idle 2-core machine (the budget
# of .ci/run is 45 minutes, the normal part takes 6-7) and seen green.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/test_sanitized.sh
bash scripts/setup_fuzz.sh
bash scripts/fuzz.sh "${FUZZ_SECONDS:-60}"
