#!/usr/bin/env bash
# Our default bake against Cycles' bake at the same error, timed back to back in one run on this machine:
#   bash bench/cycles/equal_error_time.sh SCENE.gltf CYCLES_SPP [RUNS]
# CYCLES_SPP: the samples per texel Cycles needs for our error (log-log interpolation of the ladder that
# compare.py --map-ladder scores; docs/validation.md). Prints our median wall time, Cycles' bake-call time
# (cycles_bake.py BAKE_TIME_S, Blender start and import excluded) and the ratio; appends to
# bench/results/equal_error_time.csv.
# A scene whose light is the file's own lights plus a sky (Sponza): SKY=R,G,B BAKE_OPTS="--sky R,G,B" bakes it
# with Cycles' --bake-lights script, which keeps direct light in the map as ours does; LABEL names the row (commas become semicolons).
set -euo pipefail
SCENE=$1; SPP=$2; RUNS=${3:-3}
IRBAKE=${IRBAKE:-build/baker/irbake}
CYCLES_DIR=../shared/tools/cycles
read -r -a BAKE_ARGS <<< "${BAKE_OPTS:-}"
CYCLES_SCRIPT=(--python "$CYCLES_DIR/cycles_bake.py" --)
[[ -n ${SKY:-} ]] && CYCLES_SCRIPT=(--python bench/cycles/cycles_bake_lights.py -- --cycles-dir "$CYCLES_DIR" --sky "$SKY")
OUT=build/equal-error/$(basename "${SCENE%.*}")
mkdir -p "$OUT"
walls=()
for r in $(seq 1 "$RUNS"); do
  t0=$(date +%s.%N)
  "$IRBAKE" bake "$SCENE" -o "$OUT/ours" --quiet "${BAKE_ARGS[@]}" > /dev/null
  walls+=("$(python3 -c "import time,sys; print(time.time()-float(sys.argv[1]))" "$t0")")
done
ours=$(printf '%s\n' "${walls[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
read -r W H < <(python3 -c "import json,sys; p=json.load(open(sys.argv[1]))['atlas']['pages'][0]; print(p['width'], p['height'])" "$OUT/ours/report.json")
cyc=$(blender -b --factory-startup "${CYCLES_SCRIPT[@]}" --scene "$OUT/ours/scene.gltf" \
      --uv UVMap.001 --width "$W" --height "$H" --spp "$SPP" --seed 11 --max-bounces 64 --out "$OUT/cycles.exr" 2>&1 |
      awk '/^BAKE_TIME_S/ {print $2}')
load=$(cut -d' ' -f1 /proc/loadavg)
ratio=$(python3 -c "import sys; print(round(float(sys.argv[2])/float(sys.argv[1]),2))" "$ours" "$cyc")
LABEL=${LABEL:-$(basename "$SCENE")}; LABEL=${LABEL//,/;}  # a CSV field
echo "$LABEL: ours ${ours} s (median of $RUNS), Cycles ${SPP} spp ${cyc} s, Cycles/ours ${ratio}x, load ${load}"
CSV=bench/results/equal_error_time.csv
[[ -f $CSV ]] || echo "date,commit,scene,our_wall_s_median,runs,cycles_spp,cycles_bake_s,ratio,load_avg" > $CSV
echo "$(date +%F),$(git log -1 --format=%h -- baker shaders),$LABEL,$ours,$RUNS,$SPP,$cyc,$ratio,$load" >> $CSV
