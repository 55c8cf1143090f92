#!/usr/bin/env bash
# The robustness half of CI: one clang build (the `asan` preset: -O1 -g1,
# AddressSanitizer + UndefinedBehaviorSanitizer, libFuzzer coverage) that holds
# both the whole test suite and the fuzz targets, so the code is compiled once
# for both. Then the suite under the sanitizers (scripts/test_sanitized.sh; the
# tests that only time, measure peak memory or start a cluster run in the
# Release suite only) and 10 s of fuzzing per parser with a
# seed taken from the commit (scripts/fuzz.sh), so every commit tries new inputs.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/phase.sh
phase "sanitizer setup" bash scripts/setup_fuzz.sh
export PATCHSKIN_SANITIZER_SETUP_DONE=1
bash scripts/test_sanitized.sh
seed=$((16#$(git rev-parse --short=7 HEAD 2>/dev/null || echo 1)))
phase "fuzzing" env FUZZ_BUILD=build/asan FUZZ_SEED="${FUZZ_SEED:-$seed}" \
  bash scripts/fuzz.sh "${FUZZ_SECONDS:-10}"
