#!/usr/bin/env bash
# A single-node Slurm on localhost for tests and benchmarks: munged, slurmctld and slurmd with their
# configuration, sockets, state and logs under one folder (nothing in /etc or /run). Source it, then:
#   local_cluster_start DIR   # exports SLURM_CONF; returns non-zero when the node does not come up
#   local_cluster_stop DIR    # stops the three daemons it started, by their pid files
# Needs root (slurmd runs the jobs; Slurm 22.05 without systemd) and slurm-wlm + munge installed.

local_cluster_stop() {
  local dir="$1" pidfile
  # Jobs first: a job step outlives slurmd (slurmstepd), and would go on writing into the folder.
  if [[ -s "$dir/slurmctld.pid" ]]; then
    SLURM_CONF="$dir/slurm.conf" scancel --full --user=root 2>/dev/null || true
    sleep 1
  fi
  for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [[ -s "$pidfile" ]] && kill "$(cat "$pidfile")" 2>/dev/null || true
  done
  sleep 1
  for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [[ -s "$pidfile" ]] && kill -9 "$(cat "$pidfile")" 2>/dev/null || true
    rm -f "$pidfile"
  done
}

local_cluster_start() {
  local dir="$1"
  mkdir -p "$dir"/{munge,state,spool}
  chmod 755 "$dir"
  chmod 711 "$dir/munge"
  # munged with its socket here (/run/munge does not exist); --force: it runs as root.
  [[ -f "$dir/munge/munge.key" ]] || mungekey --create --keyfile="$dir/munge/munge.key"
  munged --force --socket="$dir/munge/munge.sock" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed" || return 1
  # Ports from the pid: two runs on one machine (parallel CI jobs, other engineers) do not meet.
  local port=$((20000 + ($$ % 20000) * 2)) node
  node=$(hostname -s)
  cat > "$dir/slurm.conf" <<CONF
ClusterName=irbakelocal
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.sock
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$dir/slurm.conf"
  slurmctld -f "$SLURM_CONF" || return 1
  slurmd -f "$SLURM_CONF" || return 1
  local _
  for _ in $(seq 1 60); do
    sinfo -h -o %t 2>/dev/null | grep -q idle && return 0
    sleep 1
  done
  echo "local-cluster: the node never became idle; see $dir/slurmctld.log and $dir/slurmd.log" >&2
  return 1
}
