#!/usr/bin/env bash
# Installs what the fuzz build needs beyond the usual packages: clang and its
# compiler-rt (libFuzzer, ASan, UBSan runtimes). Skips apt when present.
set -euo pipefail
exec bash "$(dirname "$0")/setup.sh" clang libclang-rt-14-dev
