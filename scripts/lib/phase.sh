# Sourced by the build scripts: `phase NAME COMMAND...` runs COMMAND and records
# how long it took. With PHASE_LOG set (.ci/run sets it), each phase appends a
# line "NAME<TAB>SECONDS" there, so the caller can print every phase's time at
# the end; a phase that fails still records its time before the script exits.
phase() {
  local name="$1"
  shift
  local start=$SECONDS status=0
  "$@" || status=$?
  local took=$((SECONDS - start))
  echo "phase: $name took ${took}s"
  if [ -n "${PHASE_LOG:-}" ]; then printf '%s\t%s\n' "$name" "$took" >> "$PHASE_LOG"; fi
  return $status
}
