#!/usr/bin/env bash
# Sets up, builds the patchskin command (Release) and runs the built-in demo.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$root/build/release" -DCMAKE_BUILD_TYPE=Release -DPATCHSKIN_BUILD_TESTS=OFF \
  -DPATCHSKIN_BUILD_SAMPLES=OFF >/dev/null
cmake --build "$root/build/release" --target patchskin -j 2
"$root/build/release/app/patchskin" "$@"
