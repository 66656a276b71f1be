#!/usr/bin/env bash
# Issue 14: a single-node Slurm on localhost (munged + slurmctld + slurmd, configuration generated into
# the build folder) bakes the Cornell box in 4 shards with scripts/slurm/bake.sh; the merged outputs
# must equal the bake on one machine byte for byte. Skips (77) when not root or Slurm/munge are missing.
# Every daemon it starts is stopped on exit (trap), by the pid it recorded.
# Usage: slurm_bake_test.sh IRBAKE SOURCE_DIR WORK_DIR
set -euo pipefail
irbake=$(realpath "$1") src=$(realpath "$2") work="$3"

if [[ $(id -u) -ne 0 ]]; then echo "SKIP: needs root (slurmd runs jobs as root here, without systemd)"; exit 77; fi
for tool in munged mungekey slurmctld slurmd sbatch sinfo squeue; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool not installed (scripts/install-deps.sh installs slurm-wlm and munge)"; exit 77; }
done

rm -rf "$work"
mkdir -p "$work"/{munge,state,spool,out}
work=$(realpath "$work")
chmod 755 "$work"
chmod 711 "$work/munge"
pids=()
cleanup() {
  local pidfile
  for pidfile in "$work/slurmd.pid" "$work/slurmctld.pid" "$work/munge/munged.pid"; do
    [[ -s "$pidfile" ]] && kill "$(cat "$pidfile")" 2>/dev/null || true
  done
  sleep 1
  for pidfile in "$work/slurmd.pid" "$work/slurmctld.pid" "$work/munge/munged.pid"; do
    [[ -s "$pidfile" ]] && kill -9 "$(cat "$pidfile")" 2>/dev/null || true
  done
}
trap cleanup EXIT

# munged with its socket under the build folder (/run/munge does not exist here); --force: as root.
mungekey --create --keyfile="$work/munge/munge.key"
munged --force --socket="$work/munge/munge.sock" --key-file="$work/munge/munge.key" \
  --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" --seed-file="$work/munge/munged.seed"

# Ports from the pid: two test runs on one machine (parallel CI jobs) do not meet.
port=$((20000 + ($$ % 20000) * 2))
node=$(hostname -s)
cat > "$work/slurm.conf" <<CONF
ClusterName=irbaketest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/munge.sock
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=irbaketest Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 1 60); do
  sinfo -h -o %t 2>/dev/null | grep -q idle && break
  sleep 1
done
sinfo -h -o %t | grep -q idle || { echo "FAIL: the node never became idle"; tail -20 "$work/slurmctld.log" "$work/slurmd.log"; exit 1; }

"$irbake" samples "$work/samples" --quiet
scene="$work/samples/cornell_box.gltf"
options=(--vpls 256 --texels-per-unit 40 --seed 3 --vpl-block 32 --backend gl)
"$irbake" bake "$scene" -o "$work/one" "${options[@]}" --quiet >/dev/null

start=$(date +%s.%N)
timeout 900 bash "$src/scripts/slurm/bake.sh" "$scene" -o "$work/out" --shards 4 --irbake "$irbake" --wait \
  --time=30 -- "${options[@]}" || { echo "FAIL: the Slurm bake failed"; tail -n 20 "$work"/out/shards/slurm-*.out; exit 1; }
echo "Slurm bake (4 shards + merge): $(awk "BEGIN { print $(date +%s.%N) - $start }") s"

status=0
for f in lightmap_0.exr scene.gltf scene.bin lightmap_0.png; do
  if cmp -s "$work/one/$f" "$work/out/$f"; then echo "same bytes: $f"; else echo "FAIL: $f differs from the one-machine bake"; status=1; fi
done
for k in 1 2 3 4; do
  [[ -f "$work/out/shards/$k/partial_${k}_of_4.vplsum" ]] || { echo "FAIL: share $k missing"; status=1; }
done
exit $status
