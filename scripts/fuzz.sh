#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (build/fuzz) and runs each for a
# bounded time: scripts/fuzz.sh [seconds per target, default 60] [target...]
#
# Seeds: the corpora each target lists in fuzz/CMakeLists.txt, plus the shared
# captures (../shared/data, read in place, never copied) when present. New
# inputs the fuzzer finds go to build/fuzz/corpus/<target>/ (not the repo).
# A crash, leak, hang (> 10 s per input) or allocation over 1 GiB stops the
# run, leaves the input in build/fuzz/artifacts/<target>/ and fails this
# script; fix the bug and copy the input to fuzz/corpus/<target>/ so the
# ctest replay keeps it fixed.
#
# FUZZ_SEED (optional) fixes libFuzzer's seed; CI derives it from the commit, so
# each commit explores new inputs (the corpora themselves are replayed by the
# fuzz_replay_* tests) and a failure can be reproduced with the printed seed.
# FUZZ_RUNS (optional) also caps the number of inputs per target.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
build="${FUZZ_BUILD:-build/fuzz}"
shared_data="${PATCHSKIN_DATA_DIR:-$(pwd)/../shared/data}"

if ! command -v clang++ >/dev/null; then
  echo "fuzz: clang++ not found (apt-get install clang libclang-rt-14-dev)" >&2
  exit 1
fi
# FUZZ_BUILD names an already configured fuzz build (CI's build/asan, which
# holds the sanitizer test suites too); otherwise a fuzz-only build is made.
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DPATCHSKIN_BUILD_FUZZ=ON -DPATCHSKIN_BUILD_TESTS=OFF -DPATCHSKIN_BUILD_SAMPLES=OFF >/dev/null
fi
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(cut -f1 "$build/fuzz_targets.txt")
fi
cmake --build "$build" -j2 --target "${targets[@]/#/fuzz_}"

status=0
for t in "${targets[@]}"; do
  seeds=$(grep -P "^$t\t" "$build/fuzz_targets.txt" | cut -f2 | tr ',' ' ')
  case "$t" in
    bvh) [ -d "$shared_data/bvh" ] && seeds="$seeds $shared_data/bvh" ;;
    gltf) [ -d "$shared_data/gltf" ] && seeds="$seeds $shared_data/gltf" ;;
  esac
  work="$build/corpus/$t"
  artifacts="$build/artifacts/$t/"
  mkdir -p "$work" "$artifacts"
  echo "fuzz: $t for ${seconds}s, seed ${FUZZ_SEED:-random} (corpora: $seeds)"
  # shellcheck disable=SC2086
  runs=()
  if [ -n "${FUZZ_SEED:-}" ]; then runs+=(-seed="$FUZZ_SEED"); fi
  if [ -n "${FUZZ_RUNS:-}" ]; then runs+=(-runs="$FUZZ_RUNS"); fi
  if ! "$build/fuzz/fuzz_$t" "${runs[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -malloc_limit_mb=1024 -max_len=1048576 -print_final_stats=1 \
      -artifact_prefix="$artifacts" "$work" $seeds > "$build/fuzz_$t.log" 2>&1; then
    echo "fuzz: $t FAILED; input in $artifacts, log $build/fuzz_$t.log" >&2
    grep -E "ERROR|SUMMARY|Test unit written" "$build/fuzz_$t.log" | head -20 >&2 || true
    status=1
  else
    grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb|^#[0-9]+.*DONE" \
      "$build/fuzz_$t.log" | sed "s/^/fuzz: $t: /" || true
  fi
done
exit $status
