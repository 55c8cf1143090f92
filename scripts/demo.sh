#!/usr/bin/env bash
# Sets up, builds the patchskin command (Release) and runs the built-in demo:
# frames, a contact sheet and a preview video under out/demo/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$root/build/demo" -DCMAKE_BUILD_TYPE=Release -DPATCHSKIN_BUILD_TESTS=OFF \
  -DPATCHSKIN_BUILD_SAMPLES=OFF >/dev/null
cmake --build "$root/build/demo" --target patchskin -j 2
# No arguments: the built-in demo (a walk on the generated body) to out/demo/
# under the current directory, replacing an earlier run's frames so the command
# can be repeated: SSD alone on the left, SSD + the patch layer placed from the
# skeleton (--layer auto) on the right, coloured by how far the layer moves the
# skin. Any arguments are passed to patchskin instead.
if [ $# -eq 0 ]; then set -- render --layer auto --overlay delta --overwrite; fi
"$root/build/demo/app/patchskin" "$@"
