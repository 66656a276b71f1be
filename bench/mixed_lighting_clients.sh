#!/usr/bin/env bash
# Mixed lighting in the clients (docs/validation.md, "Mixed lighting"): Sponza (../shared/scenes) with
# --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7 baked twice with the same seed, fully baked and with the sun in
# shadowmask mode; both exports get the "overview" camera of bench/cycles/scenes.py. irview renders both
# (320 × 200); three.js in headless Chromium (runtime/web) renders the shadowmask bake with its own real-time
# sun × the mask. Mean absolute differences over the whole image (8-bit sRGB, nothing excluded) against irview's
# full bake → bench/results/mixed_lighting_clients.csv, and the three screenshots → docs/images/.
# Usage: bench/mixed_lighting_clients.sh BUILD_DIR
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:?BUILD_DIR}")
irbake="$build/baker/irbake" irview="$build/runtime/irview" modules="$build/web"
scene="$src/../shared/scenes/dabrovic_sponza/sponza.glb"
[[ -f "$scene" ]] || { echo "skipped: $scene absent"; exit 0; }
work="$build/bench_scratch/mixed_lighting_clients"
rm -rf "$work" && mkdir -p "$work" "$src/bench/results" "$src/docs/images"
w=320 h=200
for mode in baked shadowmask; do
  flag=()
  [[ $mode != baked ]] && flag=(--light-mode "sun=$mode")
  "$irbake" bake "$scene" -o "$work/$mode" --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7 "${flag[@]}" --quiet > "$work/$mode.log" 2>&1
  python3 "$src/bench/cycles/add_sponza_camera.py" "$work/$mode/scene.gltf" "$w" "$h"
  "$irview" "$work/$mode/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_$mode.png" > "$work/irview_$mode.log" 2>&1
done
irview_mad=$(python3 - "$work/irview_shadowmask.png" "$work/irview_baked.png" <<'PY'
import subprocess, sys
out = subprocess.run(["oiiotool", sys.argv[1], sys.argv[2], "--diff"], capture_output=True, text=True).stdout
mean = [l for l in out.splitlines() if "Mean error" in l][0].split("=")[1]
print(f"{float(mean) * 255:.3f}")
PY
)
web=$(node "$src/runtime/web/render_compare.mjs" --modules "$modules" --scene "$work/shadowmask/scene.gltf" --camera 0 \
  --width $w --height $h --reference "$work/irview_baked.png" --out "$work/web_shadowmask.png" --max-mean-abs 3 \
  --min-runtime-lights 1 --min-masked 1)
web_mad=$(python3 -c 'import json, sys; print("%.3f" % json.loads(sys.argv[1])["meanAbs"])' "$web")
csv="$src/bench/results/mixed_lighting_clients.csv"
echo "scene,camera,width,height,render,reference,mad_8bit,command,load_1min" > "$csv"
cmd="bash bench/mixed_lighting_clients.sh build"
load=$(cut -d' ' -f1 /proc/loadavg)
echo "sponza_sun_sky,overview,$w,$h,irview shadowmask bake (sun real time x mask),irview full bake,$irview_mad,$cmd,$load" >> "$csv"
echo "sponza_sun_sky,overview,$w,$h,three.js shadowmask bake (sun real time x mask),irview full bake,$web_mad,$cmd,$load" >> "$csv"
cp "$work/irview_baked.png" "$src/docs/images/mixed_sponza_irview_baked.png"
cp "$work/irview_shadowmask.png" "$src/docs/images/mixed_sponza_irview_shadowmask.png"
oiiotool "$work/web_shadowmask.png" --ch R,G,B -o "$src/docs/images/mixed_sponza_threejs_shadowmask.png"  # no alpha: smaller
cat "$csv"
