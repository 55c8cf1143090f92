#!/usr/bin/env bash
# A throw-away single-node Slurm cluster on localhost, for tests: munged with
# its own key, slurmctld and slurmd, all children of the calling shell, with
# every file (config, state, spool, logs, sockets) under one folder.
#
# Source this file, then:
#   slurm_cluster_start DIR   # wipes DIR, starts the daemons, waits for the node to be idle;
#                             # exports SLURM_CONF for sbatch/sinfo/squeue
#   slurm_cluster_stop        # stops every daemon it started, by PID, and wipes DIR
# Needs root (SlurmUser=root) and Debian's slurmctld, slurmd, slurm-client and munge.

SLURM_CLUSTER_DIR=""
SLURM_CLUSTER_PIDS=()

slurm_cluster_have_binaries() {
  local b
  for b in munged mungekey slurmctld slurmd sbatch sinfo squeue; do
    if ! command -v "$b" >/dev/null 2>&1 && [ ! -x "/usr/sbin/$b" ]; then
      echo "$b"
      return 1
    fi
  done
  return 0
}

# A random TCP port in 20000..59999 that nothing on localhost accepts
# connections on (bash's /dev/tcp; no python needed). A race with another
# program taking it meanwhile is unlikely, and start-up then fails loudly.
_slurm_free_port() {
  local port i
  for ((i = 0; i < 100; i++)); do
    port=$((20000 + RANDOM % 40000))
    if ! (: </dev/tcp/127.0.0.1/"$port") 2>/dev/null; then
      echo "$port"
      return 0
    fi
  done
  return 1
}

_slurm_log_tail() {
  local f
  for f in "$SLURM_CLUSTER_DIR"/log/*.log; do
    [ -f "$f" ] || continue
    echo "--- $f (last 20 lines)" >&2
    tail -n 20 "$f" >&2
  done
}

# Waits up to $2 seconds for command $1 to succeed.
_slurm_wait_for() {
  local cmd=$1 seconds=$2 i
  for ((i = 0; i < seconds * 10; i++)); do
    if eval "$cmd" >/dev/null 2>&1; then return 0; fi
    sleep 0.1
  done
  return 1
}

slurm_cluster_start() {
  local dir=$1
  export PATH="$PATH:/usr/sbin"
  SLURM_CLUSTER_DIR=$dir
  rm -rf "$dir"
  mkdir -p "$dir"/{munge,state,spool,log,run}
  chmod 700 "$dir" "$dir"/munge

  # munge: own key, own socket, nothing under /etc or /run.
  mungekey --create --keyfile="$dir/munge/munge.key" >/dev/null
  chmod 400 "$dir/munge/munge.key"
  local socket="$dir/munge/munge.socket"
  munged --foreground --force --socket="$socket" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/run/munged.pid" --seed-file="$dir/munge/munged.seed" \
    --log-file="$dir/log/munged.log" >>"$dir/log/munged.out" 2>&1 &
  SLURM_CLUSTER_PIDS+=($!)
  if ! _slurm_wait_for "[ -S '$socket' ]" 10; then
    echo "slurm_cluster: munged did not start" >&2
    _slurm_log_tail
    return 1
  fi

  local ctld_port slurmd_port
  ctld_port=$(_slurm_free_port)
  slurmd_port=$(_slurm_free_port)
  while [ "$slurmd_port" = "$ctld_port" ]; do slurmd_port=$(_slurm_free_port); done
  cat >"$dir/slurm.conf" <<CONF
ClusterName=patchskintest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool/%n
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
SchedulerType=sched/backfill
SlurmctldTimeout=30
SlurmdTimeout=30
MinJobAge=300
NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 RealMemory=256 State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$dir/slurm.conf"

  slurmctld -D -i -f "$SLURM_CONF" >>"$dir/log/slurmctld.out" 2>&1 &
  SLURM_CLUSTER_PIDS+=($!)
  slurmd -D -N localhost -f "$SLURM_CONF" >>"$dir/log/slurmd.out" 2>&1 &
  SLURM_CLUSTER_PIDS+=($!)

  if ! _slurm_wait_for "sinfo -h -N -o '%t' | grep -qx idle" 30; then
    echo "slurm_cluster: the node did not become idle within 30 s" >&2
    sinfo -N -l >&2 || true
    _slurm_log_tail
    return 1
  fi
  return 0
}

slurm_cluster_stop() {
  local pid i
  # Stop in reverse start order (slurmd, slurmctld, munged), each by its PID.
  for ((i = ${#SLURM_CLUSTER_PIDS[@]} - 1; i >= 0; i--)); do
    pid=${SLURM_CLUSTER_PIDS[$i]}
    kill -TERM "$pid" 2>/dev/null || continue
    for _ in $(seq 50); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -KILL "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
  done
  SLURM_CLUSTER_PIDS=()
  if [ -n "$SLURM_CLUSTER_DIR" ]; then rm -rf "$SLURM_CLUSTER_DIR"; fi
  SLURM_CLUSTER_DIR=""
}
