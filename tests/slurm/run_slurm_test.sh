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
# rig instead of the default patch rig written below (e.g. an elastic rig).
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

# --- The rig: a patch on the mannequin's elbow, tiny frames ------------------
frames=0:7
chunk=2
rig=${PATCHSKIN_SLURM_RIG:-}
if [ -z "$rig" ]; then
  rig=$work/rig.json
  cat >"$rig" <<RIG
{
  "character": "mannequin",
  "motion": {"file": "$src/samples/data/bend.bvh"},
  "patches": [{"name": "left_elbow",
               "region": {"joint": "LeftForeArm", "radius": 14, "side": [0, 0, 1]},
               "grid": [4, 4], "sampling": [6, 6]}],
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
rm "$work/farm/f_0005.png"
timeout 120 sbatch --wait --quiet --array=2 "$work/farm/slurm/render_array.sbatch"
if ! cmp -s "$work/single/f_0005.png" "$work/farm/f_0005.png"; then
  echo "FAIL: re-running task 2 did not restore f_0005.png byte-identical"
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
echo "PASS: 8 frames from a 4-task Slurm array are byte-identical to one render"
rm -rf "$work"
