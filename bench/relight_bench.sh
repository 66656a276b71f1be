#!/usr/bin/env bash
# irbake relight against the bake it relights (docs/guide.md, "Relight"): Sponza (../shared/scenes) with one
# interior lamp (bench/levels/add_point_light.py), --sun and --sky, baked with two light groups (day = sun, sky;
# lamp = the rest; probes every metre), then relit RUNS times to a .gltf and a .glb with other weights. Per run: wall and CPU
# seconds (user + system), pages, texels summed and the 1-minute load average → bench/results/relight.csv
# Usage: bench/relight_bench.sh BUILD_DIR [RUNS]
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:?BUILD_DIR}")
irbake="$build/baker/irbake"
runs="${2:-3}"
scene="$src/../shared/scenes/dabrovic_sponza/sponza.glb"
[[ -f "$scene" ]] || { echo "skipped: $scene absent"; exit 0; }
work="$build/bench_scratch/relight"
rm -rf "$work" && mkdir -p "$work" "$src/bench/results"
csv="$src/bench/results/relight.csv"
python3 "$src/bench/levels/add_point_light.py" "$scene" "$work/sponza_lamp.glb" 0,3,0 200 1,0.85,0.6
ln -s "$(dirname "$scene")/textures" "$work/textures"  # the GLB names its textures beside it
echo "scene,what,run,wall_s,cpu_s,pages,texels,load_1min" > "$csv"
timed() {  # what, run, output folder, command...
  local what="$1" run="$2" out="$3"; shift 3
  local t0 t1
  t0=$(date +%s.%N)
  /usr/bin/time -f "%U %S" -o "$work/$what-$run.cpu" "$@" > "$work/$what-$run.log"
  t1=$(date +%s.%N)
  python3 - "$csv" "$what" "$run" "$t0" "$t1" "$work/$what-$run.cpu" "$out" <<'PY'
import glob, os, sys
csv, what, run, t0, t1, cpu, out = sys.argv[1:]
user, system = map(float, open(cpu).read().split())
pages = [f for f in glob.glob(os.path.join(out, "lightmap_*.exr")) if os.path.basename(f).count("_") == 1]
texels = sum(os.path.getsize(f) for f in glob.glob(os.path.join(out, "lightmap_*_*.exr"))) // 12  # about: float RGB
row = ["sponza_lamp_sun_sky", what, run, f"{float(t1) - float(t0):.2f}", f"{user + system:.2f}", len(pages), texels,
       open("/proc/loadavg").read().split()[0]]
open(csv, "a").write(",".join(map(str, row)) + "\n")
PY
}
timed bake_two_groups 1 "$work/grouped" "$irbake" bake "$work/sponza_lamp.glb" -o "$work/grouped" --sun 0.35,-1,0.2,5 \
  --sky 0.4,0.5,0.7 --probes 1 --light-group day=sun,sky --light-group 'lamp=*' --quiet
for run in $(seq 1 "$runs"); do
  rm -rf "$work/relit" "$work/relit_glb"
  timed relight_gltf "$run" "$work/relit" "$irbake" relight "$work/grouped/scene.gltf" --group day=0.2 --group lamp=1,0.8,0.6 \
    -o "$work/relit/scene.gltf"
  timed relight_glb "$run" "$work/relit_glb" "$irbake" relight "$work/grouped/scene.gltf" --group day=0.2 --group lamp=1,0.8,0.6 \
    -o "$work/relit_glb/scene.glb"
done
cat "$csv"
