#!/usr/bin/env bash
# Mixed-lighting cost (docs/validation.md, "Mixed lighting"): Sponza (../shared/scenes) with --sun and --sky
# baked as usual, with the sun indirect and with the sun in a shadow mask, alternating, RUNS rounds. Per run:
# wall and CPU seconds (user + system: less sensitive to a shared machine's load), the report's bake, backend,
# shadow-mask and shadow-mask post seconds, map and mask pages and their EXR bytes, the 1-minute load average
# at the end → bench/results/mixed_lighting.csv
# How the clients show such a bake against the full one: bench/mixed_lighting_clients.sh.
# Usage: bench/mixed_lighting_bench.sh BUILD_DIR [RUNS]
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:?BUILD_DIR}")
irbake="$build/baker/irbake"
runs="${2:-3}"
scene="$src/../shared/scenes/dabrovic_sponza/sponza.glb"
[[ -f "$scene" ]] || { echo "skipped: $scene absent"; exit 0; }
work="$build/bench_scratch/mixed_lighting"
rm -rf "$work" && mkdir -p "$work" "$src/bench/results"
csv="$src/bench/results/mixed_lighting.csv"
echo "scene,mode,run,wall_s,cpu_s,bake_s,backend_s,shadow_mask_s,shadow_mask_post_s,map_pages,mask_pages,map_exr_mib,mask_exr_mib,load_1min" > "$csv"
for run in $(seq 1 "$runs"); do
  for mode in baked indirect shadowmask; do
    out="$work/$mode-$run" flag=()
    [[ $mode != baked ]] && flag=(--light-mode "sun=$mode")
    t0=$(date +%s.%N)
    /usr/bin/time -f "%U %S" -o "$out.cpu" "$irbake" bake "$scene" -o "$out" --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7 \
      "${flag[@]}" --quiet > /dev/null
    t1=$(date +%s.%N)
    python3 - "$csv" "$mode" "$run" "$t0" "$t1" "$out" <<'PY'
import glob, json, os, sys
csv, mode, run, t0, t1, out = sys.argv[1:]
user, system = map(float, open(out + ".cpu").read().split())
s = json.load(open(os.path.join(out, "report.json")))["timings"]["seconds"]
maps = [f for f in glob.glob(os.path.join(out, "lightmap_*.exr")) if "_shadowmask" not in f]
masks = glob.glob(os.path.join(out, "lightmap_*_shadowmask.exr"))
mib = lambda files: sum(os.path.getsize(f) for f in files) / 2**20
row = ["sponza_sun_sky", mode, run, f"{float(t1) - float(t0):.2f}", f"{user + system:.2f}", f"{s['bake']:.2f}",
       f"{s.get('backend', 0):.2f}", f"{s.get('shadowMask', 0):.2f}", f"{s.get('shadowMaskPost', 0):.2f}", len(maps),
       len(masks), f"{mib(maps):.1f}", f"{mib(masks):.1f}", open("/proc/loadavg").read().split()[0]]
open(csv, "a").write(",".join(map(str, row)) + "\n")
PY
  done
done
cat "$csv"
