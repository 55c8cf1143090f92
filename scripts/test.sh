#!/usr/bin/env bash
# Sets up, builds (CI preset: Release, warnings as errors) and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/phase.sh
phase "setup" bash scripts/setup.sh
phase "release build" bash -c 'cmake --preset ci >/dev/null && cmake --build --preset ci'
phase "release tests" ctest --preset ci
