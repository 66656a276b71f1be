#!/usr/bin/env bash
# Sponza's day and night scenarios on one atlas, in one GLB, in three.js with the slider (docs/export.md,
# "Scenarios and light groups"): bench/scenarios/day_night.py's grouped bake (12 lamps, --sun, --sky,
# --light-group day=sun,sky --light-group night=*, seed 0) and its `irbake relight --group night=0.5`, both given
# the "overview" camera of bench/cycles/scenes.py (320 × 200), and
#   - the grouped bake packed into one GLB by `irbake relight` without --group (its default scenario written again;
#     everything but the EXR pages inside), IRBAKE_lightmap_scenarios kept (gltf_transform_check.mjs scenarios);
#   - three.js (render_compare.mjs, irbake_lightmap_scenarios.js) on the GLB against irview: blended at day = 1,
#     night = 0.5 against the relit bake; at the default weights and unblended (--scenarios off) against the
#     grouped bake; blended at day = night = 1 against the relit bake must fail (the comparison can fail);
#   - the web viewer's sliders (scenario_slider_check.mjs, index.html): a slider for day, for night and the
#     day ⇄ night fade; the night slider moved to 0.5 against irview's relit bake, the fade moved to night alone
#     against irview's `irbake relight --group day=0` of the grouped bake;
#   - the Khronos validator on the GLB against the grouped bake (validate.mjs: no error, no new warning).
# Every drawing at exposure -4 EV (irview --exposure, the web viewer's &exposure=): at 0 EV the 12 lamps clip nearly
# the whole view to white, where a blend with wrong weights looks the same. Each against irview's: mean absolute
# difference over the whole image (8-bit sRGB), at most 2, as on the Cornell box (runtime/web/web_scenarios_test.sh)
# → appended to bench/results/sponza_scenarios_web.csv.
# Usage: bench/scenarios/sponza_scenarios_web.sh BUILD_DIR [GROUPED_DIR RELIT_DIR: day_night.py's grouped_0 and
#        relit_0, copied; without them both are baked here with day_night.py's options]
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=$(realpath "${1:?BUILD_DIR}")
irbake="$build/baker/irbake" irview="$build/runtime/irview" modules="$build/web" web="$src/runtime/web"
scene="$src/../shared/scenes/dabrovic_sponza/sponza.glb"
[[ -f "$scene" ]] || { echo "skipped: $scene absent"; exit 0; }
[[ -z ${2:-} || -n ${3:-} ]] || { echo "usage: $0 BUILD_DIR [GROUPED_DIR RELIT_DIR]: give both folders or neither"; exit 2; }
work="$build/bench_scratch/sponza_scenarios_web"
rm -rf "$work" && mkdir -p "$work" "$src/bench/results"
w=320 h=200 limit=2 ev=-4
seconds() { python3 -c 'import sys, time; print("%.2f" % (time.time() - float(sys.argv[1])))' "$1"; }
if [[ -n ${2:-} ]]; then
  cp -a "$2" "$work/grouped"
  cp -a "$3" "$work/relit"
else
  # day_night.py's lamps and bake options (its Debian python3 with numpy and OpenImageIO).
  /usr/bin/python3 - "$src/bench/scenarios" "$scene" "$work" > "$work/options.txt" <<'EOF'
import os, subprocess, sys
sys.path.insert(0, sys.argv[1])
import day_night as d
scene, work = sys.argv[2], sys.argv[3]
d.link_images(scene, work)
add = os.path.join(sys.argv[1], "..", "levels", "add_point_light.py")
subprocess.run(["python3", add, scene, os.path.join(work, "lamps.glb"), d.LAMPS, str(d.LAMP_CD), d.LAMP_RGB], check=True,
               stdout=subprocess.DEVNULL)
print(" ".join(d.SUN_SKY))
EOF
  "$irbake" bake "$work/lamps.glb" -o "$work/grouped" $(cat "$work/options.txt") --seed 0 --estimate-error \
    --light-group day=sun,sky --light-group 'night=*' --quiet > "$work/bake.log" 2>&1
  "$irbake" relight "$work/grouped/scene.gltf" --group night=0.5 -o "$work/relit/scene.gltf" > "$work/relight.log"
fi
python3 "$src/bench/cycles/add_sponza_camera.py" "$work/grouped/scene.gltf" $w $h
python3 "$src/bench/cycles/add_sponza_camera.py" "$work/relit/scene.gltf" $w $h

# One GLB: the grouped bake written again at its own weights, the camera with it.
glb="$work/glb/sponza_day_night.glb"
t0=$(date +%s.%N)
"$irbake" relight "$work/grouped/scene.gltf" -o "$glb" > "$work/pack.log"
pack_s=$(seconds "$t0")
glb_bytes=$(stat -c %s "$glb")
python3 - "$glb" <<'EOF'
import json, struct, sys
data = open(sys.argv[1], "rb").read()
doc = json.loads(data[20:20 + struct.unpack("<I", data[12:16])[0]])
ext = doc.get("extensions", {}).get("IRBAKE_lightmap_scenarios")
outside = [i.get("uri") for i in doc.get("images", []) if "bufferView" not in i] + [b["uri"] for b in doc["buffers"] if "uri" in b]
if not ext or outside or len(doc.get("cameras", [])) != 1:
    raise SystemExit("%s: IRBAKE_lightmap_scenarios %s, files outside it %s, %d cameras"
                     % (sys.argv[1], "kept" if ext else "lost", outside, len(doc.get("cameras", []))))
print("GLB: %d bytes, %d images inside, layers %s, EXR pages beside it: %s"
      % (len(data), len(doc["images"]), [l["name"] for l in ext["layers"]], sorted({e for l in ext["layers"] for e in l.get("exr", [])})))
EOF
node "$web/gltf_transform_check.mjs" scenarios --modules "$modules" --input "$work/grouped/scene.gltf" --output "$glb"
"$irbake" relight "$work/grouped/scene.gltf" --group day=0 -o "$work/night_only/scene.gltf" > "$work/night_only.log"

for bake in grouped relit night_only; do
  "$irview" "$work/$bake/scene.gltf" --camera 0 --width $w --height $h --exposure $ev --screenshot "$work/irview_$bake.png" >> "$work/irview.log" 2>&1
done

csv="$src/bench/results/sponza_scenarios_web.csv"
[[ -f "$csv" ]] || echo "date,commit,comparison,exposure_ev,mean_abs,limit,glb_bytes,seconds" > "$csv"
date=$(date -u +%F) commit=$(git -C "$(dirname "$(realpath "$irbake")")" log -1 --format=%h 2>/dev/null || echo unknown)
row() { echo "$date,$commit,$1,$ev,$2,$3,$glb_bytes,$4" >> "$csv"; echo "$1: $2 (limit $3, $4 s)"; }
mad() { python3 -c 'import json, sys; print("%.3f" % json.loads(sys.argv[1].splitlines()[0])["meanAbs"])' "$1"; }
compare() {  # what, scene or --image, reference, out, limit, render_compare options... → a row
  local what="$1" scene="$2" ref="$3" out="$4" max="$5" t0 result; shift 5
  t0=$(date +%s.%N)
  if [[ $scene == --image ]]; then
    result=$(node "$web/render_compare.mjs" --modules "$modules" --image "$out" --reference "$ref" --out "${out%.png}_compared.png" \
      --max-mean-abs "$max" "$@")
  else
    result=$(node "$web/render_compare.mjs" --modules "$modules" --scene "$scene" --camera 0 --width $w --height $h --exposure $ev \
      --reference "$ref" --out "$out" --max-mean-abs "$max" "$@")
  fi
  row "$what" "$(mad "$result")" "$max" "$(seconds "$t0")"
}
compare "three.js GLB blended day=1 night=0.5 vs irview relit night=0.5" "$glb" "$work/irview_relit.png" "$work/web_blend_relit.png" \
  $limit --weights 'day=1;night=0.5' --min-blended 1
compare "three.js GLB blended at its default weights vs irview grouped" "$glb" "$work/irview_grouped.png" "$work/web_blend_default.png" \
  $limit --min-blended 1
compare "three.js GLB --scenarios off vs irview grouped" "$glb" "$work/irview_grouped.png" "$work/web_unblended.png" $limit --scenarios off
t0=$(date +%s.%N)
if result=$(node "$web/render_compare.mjs" --modules "$modules" --scene "$glb" --camera 0 --width $w --height $h --exposure $ev --weights 'day=1;night=1' \
  --reference "$work/irview_relit.png" --out "$work/web_blend_full.png" --max-mean-abs $limit 2> "$work/full.log"); then
  echo "the blend at day = night = 1 matched the relit bake at night = 0.5: the comparison cannot fail"; exit 1
fi
grep -q 'mean absolute difference' "$work/full.log" || { cat "$work/full.log"; exit 1; }  # failed by the limit alone
row "three.js GLB blended day=1 night=1 vs irview relit night=0.5 (must differ)" "$(mad "$result")" ">$limit" "$(seconds "$t0")"

t0=$(date +%s.%N)
node "$web/scenario_slider_check.mjs" --modules "$modules" --scene "$glb" --camera 0 --width $w --height $h --exposure $ev --layers day,night \
  --set night=0.5 --out-set "$work/slider_night_half.png" --out-fade "$work/slider_night_only.png" | tee "$work/slider.json"
slider_s=$(seconds "$t0")
change() { python3 -c 'import json, sys; print("%.3f" % json.load(open(sys.argv[1]))[sys.argv[2]]["meanAbs"])' "$work/slider.json" "$1"; }
row "viewer slider night moved to 0.5: canvas change from load (at least 1)" "$(change afterSet)" ">=1" "$slider_s"
row "viewer slider day-night fade moved to night: canvas change from load (at least 1)" "$(change afterFade)" ">=1" "$slider_s"
compare "viewer slider night at 0.5 vs irview relit night=0.5" --image "$work/irview_relit.png" "$work/slider_night_half.png" $limit
compare "viewer slider fade at night vs irview relit day=0" --image "$work/irview_night_only.png" "$work/slider_night_only.png" $limit

validation=$(node "$web/validate.mjs" --modules "$modules" --output "$glb" --input "$work/grouped/scene.gltf")
echo "validator: $validation"
echo "GLB $glb: $glb_bytes bytes, packed by irbake relight in $pack_s s"
