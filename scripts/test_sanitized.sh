#!/usr/bin/env bash
# The whole test suite under AddressSanitizer and UndefinedBehaviorSanitizer:
# the `asan` preset (build/asan: clang -O1 -g1, every library and test
# instrumented, the fuzz targets built alongside, no benchmarks), then ctest.
# -O1 instead of -O0 keeps the heavy tests (golden renders, the 90-frame
# interrupted render) affordable on a 2-core CI machine. The tests that only
# time, measure peak memory, run a long capture or start a cluster (the `asan`
# test preset's exclude list: label slurm, and ElasticPipeline.TenThousand*,
# *LongCapture.*, ExportMemory.*, BenchCommand.*) run in the Release suite only:
# the sanitizers find nothing there that the short runs of the same code miss.
# So do the two sweeps of every capture in ../shared/data (CapturePose.
# FollowCameraKeepsEveryRealCapture*, GeneratedBodyOfCaptures.*: a minute and a
# half of CPU under ASan), which check framing and body geometry; the same
# loaders, bodies and cameras run sanitized on real files in other tests. And two
# byte-equality checks of whole renders (ElasticPipeline.ChunkedRenderGivesTheSame
# Bytes*, AutoRig.RigRecordsTheUpAxis*: 30 s of CPU under ASan) whose render
# paths ChunkedRender.* and AutoRig.RigFileRenders* run sanitized.
#
# Any report fails the run: ASan aborts on the first error, UBSan halts
# (-fno-sanitize-recover), and a child `patchskin` the app tests start inherits
# these options. Leak checking is off: OpenImageIO and OpenCV keep caches for
# the process lifetime that LeakSanitizer reports; the fuzzers (scripts/fuzz.sh)
# check leaks in our parsers, which use neither.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/phase.sh
if [ -z "${PATCHSKIN_SANITIZER_SETUP_DONE:-}" ]; then bash scripts/setup_fuzz.sh; fi
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
phase "sanitizer build" bash -c 'cmake --preset asan >/dev/null && cmake --build --preset asan'
phase "sanitizer tests" ctest --preset asan
