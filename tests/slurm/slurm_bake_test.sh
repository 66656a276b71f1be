#!/usr/bin/env bash
# A single-node Slurm on localhost (scripts/slurm/local-cluster.sh: munged + slurmctld + slurmd,
# configuration generated into the build folder) bakes the Cornell box in 4 shards with
# scripts/slurm/bake.sh; the merged outputs must equal the bake on one machine byte for byte.
# Skips (77) when not root or Slurm/munge are missing. The daemons are stopped on any exit (trap).
# Usage: slurm_bake_test.sh IRBAKE SOURCE_DIR WORK_DIR
set -euo pipefail
irbake=$(realpath "$1") src=$(realpath "$2") work="$3"

if [[ $(id -u) -ne 0 ]]; then echo "SKIP: needs root (slurmd runs jobs as root here, without systemd)"; exit 77; fi
for tool in munged mungekey slurmctld slurmd sbatch sinfo; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool not installed (scripts/install-deps.sh installs slurm-wlm and munge)"; exit 77; }
done

rm -rf "$work"
mkdir -p "$work"
work=$(realpath "$work")
source "$src/scripts/slurm/local-cluster.sh"
trap 'local_cluster_stop "$work/cluster"' EXIT
local_cluster_start "$work/cluster" || { echo "FAIL: the local Slurm did not start"; exit 1; }

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
