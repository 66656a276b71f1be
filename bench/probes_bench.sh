#!/usr/bin/env bash
# Cost of the irradiance probes on Sponza (sun + sky): the same bake to a GLB with the default probes and with
# --probes off, alternating, RUNS times; appends one row per pair to bench/results/probes.csv (the probe stage's
# and the whole bake's seconds from report.json "timings", both GLBs' sizes, the load average before the pair;
# OPTIONS, more irbake options for the bake with probes, e.g. "--probe-volume-fit 3").
# Usage: bench/probes_bench.sh IRBAKE [RUNS] [WORK] [OPTIONS]   (skips with a message when the scene is absent)
set -euo pipefail
irbake="$1" runs="${2:-2}" work="${3:-/tmp/irbake_probes_bench}" options="${4:-}"
here="$(cd "$(dirname "$0")" && pwd)"
scene="$here/../../shared/scenes/dabrovic_sponza/sponza.glb"
[[ -f "$scene" ]] || { echo "skipped: $scene absent"; exit 0; }
csv="$here/results/probes.csv"
[[ -f "$csv" ]] || echo "date,commit,scene,probes,valid,spacing,probe_s,bake_s,glb_bytes,glb_bytes_off,load,options" > "$csv"
commit="$(git -C "$here/.." rev-parse --short=12 HEAD)"
for run in $(seq 1 "$runs"); do
  load="$(cut -d' ' -f1 /proc/loadavg)"
  for mode in on off; do
    read -r -a extra <<< "$options"; [[ $mode == off ]] && extra=(--probes off)
    rm -rf "$work/$mode"
    "$irbake" bake "$scene" -o "$work/$mode/sponza.glb" --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7 "${extra[@]}" --quiet
  done
  python3 - "$work" "$commit" "$load" "$options" >> "$csv" <<'PY'
import datetime, json, os, sys
work, commit, load, options = sys.argv[1:5]
r = json.load(open(os.path.join(work, "on", "report.json")))
t, p = r["timings"]["seconds"], r["probes"]
size = lambda m: os.path.getsize(os.path.join(work, m, "sponza.glb"))
print(f"{datetime.date.today()},{commit},sponza_sun_sky,{p['count']},{p['valid']},{p['spacing']:.3f},"
      f"{t['probes']:.3f},{t['bake']:.2f},{size('on')},{size('off')},{load},{options}")
PY
  tail -1 "$csv"
done
