#!/usr/bin/env bash
# The distributed-bake figures (docs/validation.md, "Distributed bakes"), on the default Cornell bake (irbake samples; irbake bake cornell_box.gltf):
#  1. what the exact block sums cost: a baseline irbake (before them) and this one, alternating, 3 pairs,
#     plus this one checkpointing after every VPL block → bench/results/vpl_blocks.csv
#  2. scaling on a single-node Slurm on localhost (scripts/slurm/local-cluster.sh, as root): the bake
#     outside Slurm (shards 0), then 1, 2 and 4 shards: wall time of the job array (submission to the
#     last partial) and of the merge job (last partial to report) → bench/results/slurm_scaling.csv
# RUNS = 0 skips part 1 (and keeps its CSV).
# Usage: bench/distributed_bench.sh BUILD_DIR [BASELINE_IRBAKE] [RUNS]
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:?BUILD_DIR}")
irbake="$build/baker/irbake"
baseline="${2:-}"
runs="${3:-3}"
work="$build/bench_scratch/distributed"
rm -rf "$work"
mkdir -p "$work" "$src/bench/results"
"$irbake" samples "$work/samples" --quiet
scene="$work/samples/cornell_box.gltf"

# A bake's wall time, CPU time (user + system: less sensitive to a shared machine's load) and peak memory
# (/usr/bin/time), and its backend seconds (report).
timed_bake() {  # LABEL RUN BINARY OUT [options...]
  local label="$1" run="$2" bin="$3" out="$4"
  shift 4
  local t0 t1
  t0=$(date +%s.%N)
  /usr/bin/time -f "%M %U %S" -o "$out.mem" "$bin" bake "$scene" -o "$out" --quiet "$@" >/dev/null
  t1=$(date +%s.%N)
  python3 - "$label" "$run" "$t0" "$t1" "$out" <<'PY'
import json, sys
label, run, t0, t1, out = sys.argv[1:]
r = json.load(open(out + "/report.json"))
mem_kb, user, system = open(out + ".mem").read().split()[-3:]
mem = int(mem_kb) / 1024
cpu = float(user) + float(system)
load = open("/proc/loadavg").read().split()[0]
print(f"{label},{run},{float(t1) - float(t0):.2f},{cpu:.2f},{mem:.0f},{r['timings']['seconds']['backend']:.2f},{r['interleave'].get('vplBlocks', '')},{load}")
PY
}

csv="$src/bench/results/vpl_blocks.csv"
[[ "$runs" -gt 0 ]] && echo "binary,run,wall_s,cpu_s,peak_mib,backend_s,vpl_blocks,load1" > "$csv"
for run in $(seq 1 "$runs"); do
  [[ -n "$baseline" ]] && timed_bake baseline "$run" "$baseline" "$work/base_$run" >> "$csv"
  timed_bake blocks "$run" "$irbake" "$work/blocks_$run" >> "$csv"
  timed_bake blocks_checkpoint_every_block "$run" "$irbake" "$work/ckpt_$run" --checkpoint-seconds 0 >> "$csv"
done
[[ -n "$baseline" && "$runs" -gt 0 ]] && "$irbake" diff "$work/blocks_1" "$work/base_1" | sed 's/^/blocks vs baseline: /'
[[ "$runs" -gt 0 ]] && cat "$csv"

if [[ $(id -u) -ne 0 ]] || ! command -v slurmd >/dev/null; then
  echo "slurm scaling: skipped (needs root and slurm-wlm + munge)"
  exit 0
fi
source "$src/scripts/slurm/local-cluster.sh"
trap 'local_cluster_stop "$work/cluster"' EXIT
local_cluster_start "$work/cluster"
scaling="$src/bench/results/slurm_scaling.csv"
echo "round,shards,array_wall_s,merge_wall_s,total_wall_s,identical_to_one_machine,load1" > "$scaling"
# Rounds of every configuration in turn, so a change in the machine's load hits them alike (quote medians).
for round in $(seq 1 "${SLURM_ROUNDS:-3}"); do
  # The one-machine bake outside Slurm (shards = 0): the bytes to match and the time to compare with.
  rm -rf "$work/one"
  t0=$(date +%s.%N)
  "$irbake" bake "$scene" -o "$work/one" --quiet >/dev/null
  awk -v r="$round" -v a="$t0" -v b="$(date +%s.%N)" -v l="$(cut -d' ' -f1 /proc/loadavg)" \
    'BEGIN { printf "%d,0,%.2f,0,%.2f,yes,%s\n", r, b - a, b - a, l }' >> "$scaling"
  for n in 1 2 4; do
    out="$work/slurm_$n"
    rm -rf "$out"
    t0=$(date +%s.%N)
    bash "$src/scripts/slurm/bake.sh" "$scene" -o "$out" --shards "$n" --irbake "$irbake" >/dev/null
    # The array is done when every partial is there; the merge when its report is.
    until [[ $(ls "$out"/shards/*/partial_*.vplsum 2>/dev/null | wc -l) -eq $n ]]; do
      sleep 0.2
      # A failed shard: its log says why, and the merge was cancelled.
      if grep -qs "error" "$out"/shards/slurm-*.out; then cat "$out"/shards/slurm-*.out >&2; exit 1; fi
    done
    t1=$(date +%s.%N)
    until [[ -f "$out/report.json" ]]; do sleep 0.2; done
    t2=$(date +%s.%N)
    same=yes
    for f in lightmap_0.exr scene.gltf scene.bin lightmap_0.png; do cmp -s "$out/$f" "$work/one/$f" || same=no; done
    awk -v r="$round" -v n="$n" -v a="$t0" -v b="$t1" -v c="$t2" -v s="$same" -v l="$(cut -d' ' -f1 /proc/loadavg)" \
      'BEGIN { printf "%d,%d,%.2f,%.2f,%.2f,%s,%s\n", r, n, b - a, c - b, c - a, s, l }' >> "$scaling"
  done
done
cat "$scaling"
