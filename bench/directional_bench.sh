#!/usr/bin/env bash
# Directional-map figures (docs/validation.md, "Directional maps"): a plain bake against --directional, alternating,
# RUNS pairs each, on the default Cornell bake (irbake samples) and the DamagedHelmet from ../shared/scenes
# with --sun (skipped with a message when absent). Per run: wall and CPU seconds (user + system, less
# sensitive to a shared machine's load), peak memory (/usr/bin/time), the backend and directional stage
# seconds, the backend used, and the bytes of the maps (EXR pages) → bench/results/directional.csv
# Usage: bench/directional_bench.sh BUILD_DIR [RUNS]
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:?BUILD_DIR}")
irbake="$build/baker/irbake"
runs="${2:-3}"
work="$build/bench_scratch/directional"
rm -rf "$work"
mkdir -p "$work" "$src/bench/results"
"$irbake" samples "$work/samples" --quiet
csv="$src/bench/results/directional.csv"
echo "scene,mode,run,backend,wall_s,cpu_s,peak_mib,backend_s,directional_s,exr_mib" > "$csv"

bake_once() {  # SCENE_LABEL SCENE MODE RUN [options...]
  local label="$1" scene="$2" mode="$3" run="$4"
  shift 4
  local out="$work/$label-$mode-$run" t0 t1
  t0=$(date +%s.%N)
  /usr/bin/time -f "%M %U %S" -o "$out.mem" "$irbake" bake "$scene" -o "$out" --quiet "$@" >/dev/null
  t1=$(date +%s.%N)
  read -r kb user sys < "$out.mem"
  python3 - "$csv" "$label" "$mode" "$run" "$t0" "$t1" "$kb" "$user" "$sys" "$out" <<'PY'
import json, os, sys, glob
csv, label, mode, run, t0, t1, kb, user, sys_s, out = sys.argv[1:]
r = json.load(open(os.path.join(out, "report.json")))
sec = r["timings"]["seconds"]
exr = sum(os.path.getsize(p) for p in glob.glob(os.path.join(out, "*.exr"))) / 2**20
with open(csv, "a") as f:
    f.write(f"{label},{mode},{run},{r['backend']},{float(t1)-float(t0):.3f},{float(user)+float(sys_s):.3f},"
            f"{int(kb)/1024:.1f},{sec.get('backend', 0):.3f},{sec.get('directional', 0):.3f},{exr:.2f}\n")
PY
  rm -rf "$out"
}

bench_scene() {  # LABEL SCENE [options...]
  local label="$1" scene="$2"
  shift 2
  for run in $(seq 1 "$runs"); do
    bake_once "$label" "$scene" plain "$run" "$@"
    bake_once "$label" "$scene" directional "$run" --directional "$@"
  done
}

bench_scene cornell "$work/samples/cornell_box.gltf"
helmet="$src/../shared/scenes/damaged_helmet/DamagedHelmet.gltf"
if [[ -f "$helmet" ]]; then
  bench_scene helmet "$helmet" --sun 0.3,-1,-0.4,3
else
  echo "note: $helmet absent: the helmet is skipped"
fi
# Medians per scene and mode.
python3 - "$csv" <<'PY'
import csv, statistics, sys, collections
rows = collections.defaultdict(list)
for r in csv.DictReader(open(sys.argv[1])):
    rows[(r["scene"], r["mode"])].append(r)
for (scene, mode), rs in sorted(rows.items()):
    med = lambda k: statistics.median(float(r[k]) for r in rs)
    print(f"{scene:8s} {mode:11s} backend {rs[0]['backend']:6s} wall {med('wall_s'):7.2f} s  cpu {med('cpu_s'):7.2f} s  "
          f"peak {med('peak_mib'):7.1f} MiB  directional stage {med('directional_s'):6.2f} s  EXR {med('exr_mib'):6.2f} MiB")
PY
