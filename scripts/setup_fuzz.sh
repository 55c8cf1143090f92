#!/usr/bin/env bash
# Installs what the fuzz build needs beyond scripts/setup.sh: clang and its
# compiler-rt (libFuzzer, ASan, UBSan runtimes). Skips apt when present.
set -euo pipefail
packages=(clang libclang-rt-14-dev)
missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup_fuzz: all ${#packages[@]} packages present"
  exit 0
fi
echo "setup_fuzz: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
