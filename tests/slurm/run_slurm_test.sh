#!/usr/bin/env bash
# The Slurm job-array render test (ctest label "slurm"): starts a single-node
# Slurm cluster on localhost (tests/slurm/slurm_cluster.sh: munged with its own
# key, slurmctld, slurmd, all children of this script, state in a temporary
# folder), renders a rig as a 4-task job array with `patchskin farm slurm
# --submit --wait`, and checks that the frames are byte-identical to one
# `patchskin render` of the whole range; then deletes a frame, re-runs that
# one task with the same script, and checks the frame comes back identical;
# and that a failing task makes `farm --wait` exit 3.
# Every daemon is stopped by its PID and the cluster folder wiped on exit.
#
# usage: run_slurm_test.sh PATCHSKIN_BINARY SOURCE_DIR WORK_DIR
# Exit 77 (ctest: skipped) when the Slurm or munge binaries are missing or
# when not run as root (the test cluster runs jobs as SlurmUser=root).
#
# The rig is one variable: PATCHSKIN_SLURM_RIG=path/to/rig.json renders that
# rig instead of the default elastic rig written below.
set -euo pipefail

bin=$(readlink -f "$1")
src=$(readlink -f "$2")
work=$3
here=$(cd "$(dirname "$0")" && pwd)
source "$here/slurm_cluster.sh"

if ! missing=$(slurm_cluster_have_binaries); then
  echo "SKIP: $missing not found (apt-get install slurmctld slurmd slurm-client munge)"
  exit 77
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: the test cluster runs as root (SlurmUser=root); run as root"
  exit 77
fi

rm -rf "$work"
mkdir -p "$work"
cluster=$(mktemp -d /tmp/patchskin-slurm.XXXXXX)
trap 'slurm_cluster_stop; rm -rf "$cluster"' EXIT

# --- The rig: an elastic belly patch on the mannequin's jump, tiny frames -----
# Frames 40..47 are the landing, where the belly's mass-spring state matters:
# every chunk after the first must arrive at the same state as the whole render
# (the layer simulates from the motion's start, app/elastic_layer.h).
frames=40:47
chunk=2
rig=${PATCHSKIN_SLURM_RIG:-}
if [ -z "$rig" ]; then
  rig=$work/rig.json
  cat >"$rig" <<RIG
{
  "character": "mannequin",
  "motion": {"file": "$src/samples/data/jump.bvh"},
  "patches": [{"name": "belly",
               "region": {"joint": "Spine1", "radius": 16, "side": [0, 0, 1], "half_angle_deg": 70},
               "grid": [6, 6], "sampling": [10, 10], "border_width": 0.15,
               "elastic": {"frequency_hz": 4, "damping_ratio": 0.15, "max_displacement": 8}}],
  "render": {"size": [160, 90], "camera": "follow"}
}
RIG
fi

# --- The reference: one render of the whole range -----------------------------
"$bin" render "$rig" --frames "$frames" --out "$work/single/f_####.png" --no-video --no-sheet --quiet

# --- The cluster and the job array ----------------------------------------------
t0=$(date +%s.%N)
slurm_cluster_start "$cluster"
t1=$(date +%s.%N)
echo "slurm: cluster up in $(awk "BEGIN {printf \"%.1f\", $t1 - $t0}") s"
sinfo

cd "$work"
timeout 180 "$bin" farm slurm "$rig" --frames "$frames" --chunk "$chunk" \
  --out "$work/farm/f_####.png" --partition debug --sbatch-arg=--time=00:10:00 --submit --wait
t2=$(date +%s.%N)
echo "slurm: 4-task array and sheet job done in $(awk "BEGIN {printf \"%.1f\", $t2 - $t1}") s"

fail=0
for f in "$work"/single/f_*.png; do
  name=$(basename "$f")
  if ! cmp -s "$f" "$work/farm/$name"; then
    echo "FAIL: $work/farm/$name differs from the single render (or is missing)"
    fail=1
  fi
done
n_single=$(ls "$work"/single/f_*.png | wc -l)
n_farm=$(ls "$work"/farm/f_*.png | wc -l)
if [ "$n_single" -ne 8 ] || [ "$n_farm" -ne 8 ]; then
  echo "FAIL: expected 8 frames from each, found $n_single single and $n_farm from the array"
  fail=1
fi
for f in contact_sheet.png preview.mp4; do
  [ -s "$work/farm/$f" ] || { echo "FAIL: the sheet job did not write $f"; fail=1; }
done
if ls -A "$work/farm" | grep -q '^\.'; then
  echo "FAIL: temporary files left: $(ls -A "$work/farm" | grep '^\.')"
  fail=1
fi

# --- A lost chunk is finished by re-running its task with the same script ----
rm "$work/farm/f_0045.png"
timeout 120 sbatch --wait --quiet --array=2 "$work/farm/slurm/render_array.sbatch"
if ! cmp -s "$work/single/f_0045.png" "$work/farm/f_0045.png"; then
  echo "FAIL: re-running task 2 did not restore f_0045.png byte-identical"
  fail=1
fi

# --- A failing task: the sheet job never runs and farm --wait says so (exit 3) --
set +e
timeout 120 "$bin" farm slurm "$rig" --frames 0:3 --chunk 4 --out "$work/broken/f_####.png" \
  --submit --wait -- --supersample 3 2>"$work/broken.err"
code=$?
set -e
if [ "$code" -ne 3 ] || ! grep -q "the jobs did not finish: 4 of 4 frames missing" "$work/broken.err"; then
  echo "FAIL: a failing task gave exit $code (expected 3): $(cat "$work/broken.err")"
  fail=1
fi

if [ "$fail" -ne 0 ]; then
  echo "--- task logs"; tail -n 5 "$work"/farm/slurm/logs/* || true
  exit 1
fi
echo "PASS: 8 frames of an elastic rig from a 4-task Slurm array are byte-identical to one render"
rm -rf "$work"
