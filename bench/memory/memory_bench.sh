#!/usr/bin/env bash
# Peak resident memory of `irbake bake` per triangle and per texel (docs/validation.md, "Memory").
# Usage: bench/memory/memory_bench.sh IRBAKE WORKDIR CSV [RUNS] [LABEL]
#   Two series, each varying one size with the other held: a flat grid (grid_scene.py) of 0.5M and
#   2M triangles at 5 texels/m (254k texels both), and the Cornell box sample (32 triangles) at 800
#   and 1600 texels/m (1.38M and 5.89M texels). Embree backend, 64 light paths (the peak does not
#   depend on the VPL count), default everything else. Peak = /usr/bin/time's maximum resident set
#   of the whole process (load, bake, export), median of RUNS (default 3). Appends one CSV row per
#   case; the per-triangle and per-texel figures are the slopes between the two sizes of a series.
set -euo pipefail
irbake=$(realpath "$1"); work=$2; csv=$(realpath -m "$3"); runs=${4:-3}; label=${5:-$(git -C "$(dirname "$0")" rev-parse --short HEAD)}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"; cd "$work"
[[ -f grid500.gltf ]] || python3 "$here/grid_scene.py" 500 grid500.gltf >/dev/null
[[ -f grid1000.gltf ]] || python3 "$here/grid_scene.py" 1000 grid1000.gltf >/dev/null
[[ -f samples/cornell_box.gltf ]] || "$irbake" samples samples --quiet
[[ -f "$csv" ]] || echo "label,case,scene,triangles,texels,runs,peak_rss_mib,bake_peak_mib" > "$csv"

measure() {  # NAME SCENE TEXELS_PER_UNIT
  local name=$1 scene=$2 tpu=$3 peaks=() bakes=()
  for ((r = 0; r < runs; ++r)); do
    rm -rf "out_$name"
    /usr/bin/time -v "$irbake" bake "$scene" -o "out_$name" --texels-per-unit "$tpu" --vpls 64 --backend embree \
      --quiet 2>"time_$name.txt" >/dev/null
    peaks+=("$(awk '/Maximum resident/ {print $6}' "time_$name.txt")")
    bakes+=("$(python3 -c "import json; print(json.load(open('out_$name/report.json'))['timings']['memoryPeakMiB'])")")
  done
  python3 - "$label" "$name" "$scene" "$runs" "out_$name/report.json" "${peaks[*]}" "${bakes[*]}" >>"$csv" <<'PY'
import json, statistics, sys
label, name, scene, runs, report, peaks, bakes = sys.argv[1:]
r = json.load(open(report))
peak = statistics.median(int(p) for p in peaks.split()) / 1024
bake = statistics.median(float(b) for b in bakes.split())
print(f"{label},{name},{scene},{r['scene']['triangles']},{r['texels']['total']},{runs},{peak:.1f},{bake:.1f}")
PY
  tail -1 "$csv"
}

measure grid_0.5M grid500.gltf 5
measure grid_2M grid1000.gltf 5
measure cornell_1.4M_texels samples/cornell_box.gltf 800
measure cornell_5.9M_texels samples/cornell_box.gltf 1600
