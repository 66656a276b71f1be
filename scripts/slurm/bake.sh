#!/usr/bin/env bash
# Bakes one scene on a Slurm cluster: a job array of N shard bakes (irbake bake --shard K/N) and a merge
# job that runs once all of them succeeded (--dependency=afterok). The outputs equal the bake on one
# machine byte for byte (docs/distributed.md).
#
# Usage: scripts/slurm/bake.sh SCENE -o OUTDIR --shards N [sbatch options...] [-- irbake bake options...]
#   SCENE, OUTDIR  on a filesystem every node sees (the shards write OUTDIR/shards/K, the merge OUTDIR)
#   --shards N     number of array tasks (1..1000)
#   --irbake PATH  the irbake binary the nodes run (default: irbake on PATH, else this checkout's build)
#   --wait         wait for the merge job and exit with its status
#   sbatch options go to both jobs (e.g. --partition=bake --time=2:00:00 --cpus-per-task=16); the bake
#   options after "--" go to every shard (e.g. -- --vpls 16384 --backend embree).
# A shard bakes with --resume: when Slurm requeues it after a lost node, it continues from its checkpoint.
# Prints the array job id and the merge job id.
set -euo pipefail

usage() { sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
scene="" out="" shards="" irbake="" wait=0
sbatch_args=() bake_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    -o|--output) out="${2:?-o needs OUTDIR}"; shift 2 ;;
    --shards) shards="${2:?--shards needs N}"; shift 2 ;;
    --irbake) irbake="${2:?--irbake needs PATH}"; shift 2 ;;
    --wait) wait=1; shift ;;
    -h|--help) usage ;;
    --) shift; bake_args=("$@"); break ;;
    -*) sbatch_args+=("$1"); shift ;;
    *) if [[ -z "$scene" ]]; then scene="$1"; else sbatch_args+=("$1"); fi; shift ;;
  esac
done
[[ -n "$scene" && -n "$out" && -n "$shards" ]] || { echo "bake.sh: needs SCENE, -o OUTDIR and --shards N" >&2; usage; }
[[ "$shards" =~ ^[0-9]+$ && "$shards" -ge 1 && "$shards" -le 1000 ]] || { echo "bake.sh: --shards must be 1..1000 (got '$shards')" >&2; exit 2; }
[[ -f "$scene" ]] || { echo "bake.sh: $scene: no such scene" >&2; exit 3; }
if [[ -z "$irbake" ]]; then
  irbake=$(command -v irbake || true)
  [[ -n "$irbake" ]] || irbake="$(cd "$(dirname "$0")/../.." && pwd)/build/baker/irbake"
fi
[[ -x "$irbake" ]] || { echo "bake.sh: $irbake is not an irbake binary (give --irbake PATH)" >&2; exit 3; }
command -v sbatch >/dev/null || { echo "bake.sh: sbatch not found (is this a Slurm submit host?)" >&2; exit 3; }

# Absolute paths: the jobs run on other nodes, from whatever folder Slurm starts them in.
scene=$(realpath "$scene")
irbake=$(realpath "$irbake")
mkdir -p "$out/shards"
out=$(realpath "$out")
quoted_args=""
[[ ${#bake_args[@]} -gt 0 ]] && quoted_args=$(printf ' %q' "${bake_args[@]}")

# Each task: its own folder (a bake locks its output folder), its share, resumable.
array_id=$(sbatch --parsable --job-name=irbake-shard --array="1-$shards" \
  --output="$out/shards/slurm-%A_%a.out" "${sbatch_args[@]+"${sbatch_args[@]}"}" \
  --wrap="exec $(printf '%q' "$irbake") bake $(printf '%q' "$scene") -o $(printf '%q' "$out/shards")/\$SLURM_ARRAY_TASK_ID --shard \$SLURM_ARRAY_TASK_ID/$shards --resume --quiet$quoted_args")
array_id=${array_id%%;*}

shard_dirs=""
for ((k = 1; k <= shards; ++k)); do shard_dirs+=" $(printf '%q' "$out/shards/$k")"; done
merge_flags=()
[[ $wait -eq 1 ]] && merge_flags+=(--wait)
merge_id=$(sbatch --parsable --job-name=irbake-merge --dependency="afterok:$array_id" --kill-on-invalid-dep=yes \
  --output="$out/shards/slurm-merge-%j.out" "${sbatch_args[@]+"${sbatch_args[@]}"}" "${merge_flags[@]+"${merge_flags[@]}"}" \
  --wrap="exec $(printf '%q' "$irbake") merge$shard_dirs -o $(printf '%q' "$out") --quiet")
merge_id=${merge_id%%;*}
echo "shards: job array $array_id (1-$shards), merge: job $merge_id -> $out"
