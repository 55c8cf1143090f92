#!/usr/bin/env bash
# Installs every Debian package patchskin needs to build, test and benchmark,
# plus any package names given as arguments (scripts/setup_fuzz.sh adds the
# fuzzing toolchain that way). Skips apt entirely when all are present.
set -euo pipefail

packages=(
  cmake g++ make pkg-config
  libgtest-dev libgmock-dev libbenchmark-dev
  libglm-dev
  libtinygltf-dev nlohmann-json3-dev libstb-dev
  libopenimageio-dev openimageio-tools
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-videoio-dev
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev  # H.264 preview, x264 preset
  libcli11-dev
  libfast-float-dev
  libassimp-dev
  libtinyxml2-dev chromium  # the check tests read JUnit files and open the HTML report headless
  libopenvdb-dev libboost-dev libtbb-dev libeigen3-dev
  slurmctld slurmd slurm-client munge
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
