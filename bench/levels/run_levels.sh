#!/usr/bin/env bash
# Real levels from ../shared/scenes with default options: wall time, peak memory, texels, VPLs, stage times.
# Appends rows to bench/results/levels.csv. From the repository root after a Release build:
#   bash bench/levels/run_levels.sh [IRBAKE] [RUNS]
# Sibenik gets one interior point light (2000 cd, 7 m above the nave floor) written into build/levels by
# add_point_light.py beside a link to its textures; nothing third-party is committed.
set -euo pipefail
IRBAKE=${1:-build/baker/irbake}
RUNS=${2:-3}
SHARED=../shared/scenes
CSV=bench/results/levels.csv
W=build/levels
[[ -d $SHARED ]] || { echo "run_levels: $SHARED not found (third-party scenes beside the repository)"; exit 0; }
mkdir -p $W
python3 bench/levels/add_point_light.py $SHARED/sibenik/sibenik.glb $W/sibenik_lamp.glb 0,-8,0 2000
ln -sfn "$(realpath $SHARED/sibenik/textures)" $W/textures
[[ -f $CSV ]] || echo "date,commit,scene,options,run,wall_s,peak_mib,texels_valid,texels_per_m,vpls,backend,atlas_s,texels_s,backend_s,sky_s,compensation_s,post_s,load_avg" > $CSV
commit=$(git log -1 --format=%h -- baker shaders CMakeLists.txt)
run() {  # name scene options...
  local name=$1 scene=$2; shift 2
  for r in $(seq 1 "$RUNS"); do
    local out=$W/out_$name
    local t0=$(date +%s.%N)
    "$IRBAKE" bake "$scene" -o "$out" --quiet "$@" > /dev/null
    local wall=$(python3 -c "import time,sys; print(round(time.time()-float(sys.argv[1]),2))" "$t0")
    python3 - "$out/report.json" "$name" "$*" "$r" "$wall" "$commit" >> $CSV <<'PY'
import json, sys, os, datetime
rep, name, opts, run, wall, commit = sys.argv[1:]
r = json.load(open(rep)); t = r["timings"]["seconds"]
g = lambda k: round(t.get(k, 0.0), 2)
print(",".join(str(x) for x in [datetime.date.today(), commit, name, '"%s"' % opts, run, wall,
      round(r["timings"]["memoryPeakMiB"]), r["texels"]["valid"], round(r["atlas"]["texelsPerUnit"], 2),
      r["vpls"]["count"], r["backend"], g("atlas"), g("texels"), g("backend"), g("sky"), g("compensation"),
      g("post"), os.getloadavg()[0]]))
PY
    tail -1 $CSV
  done
}
run sponza_sun $SHARED/dabrovic_sponza/sponza.glb --sun 0.35,-1,0.2,5
run sponza_sun_sky $SHARED/dabrovic_sponza/sponza.glb --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7
run sibenik_sky_lamp $W/sibenik_lamp.glb --sky 1,1,1
