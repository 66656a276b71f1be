#!/usr/bin/env bash
# The clients by hand on Sponza (docs/validation.md, "Export"): Sponza (../shared/scenes) baked with
# --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7, given the "overview" camera of bench/cycles/scenes.py (320 × 200), and
#   - the Khronos validator on the bake against the input (validate.mjs: no error, no new warning);
#   - README.md's glTF-Transform command, read from README.md and run as written from the source folder (in.gltf
#     and out.glb replaced), its output drawn by three.js (runtime/web, meshopt decoded);
#   - the Blender add-on (runtime/blender/irbake_lightmap.py, Cycles; render_compare.py) with the float EXR pages
#     and with the PNG pages, every material wired; Blender's importer alone as the control. 16 samples spread
#     over each pixel: irview filters Sponza's fine stone textures through their mip maps (the pixel's footprint),
#     which one Cycles sample at the pixel centre aliases instead;
#   - the web viewer without a camera against irview's overview of the camera-less bake.
# Each drawing against irview's of the bake: mean absolute difference over the whole image (8-bit sRGB), at most
# 3.5 → bench/results/sponza_clients.csv.
# Usage: bench/sponza_clients.sh BUILD_DIR [BAKE_DIR: an existing bake of Sponza with those options, copied]
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:?BUILD_DIR}")
irbake="$build/baker/irbake" irview="$build/runtime/irview" modules="$build/web"
gltf_transform="$modules/node_modules/.bin/gltf-transform"
scene="$src/../shared/scenes/dabrovic_sponza/sponza.glb"
[[ -f "$scene" ]] || { echo "skipped: $scene absent"; exit 0; }
work="$build/bench_scratch/sponza_clients"
rm -rf "$work" && mkdir -p "$work" "$src/bench/results"
w=320 h=200 limit=3.5
bake_options="--sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7"
if [[ -n ${2:-} ]]; then
  cp -a "$2" "$work/bake"
else
  "$irbake" bake "$scene" -o "$work/bake" $bake_options --quiet > "$work/bake.log" 2>&1
fi
mad() { python3 -c 'import json, sys; print("%.3f" % json.loads(sys.argv[1])["meanAbs"])' "$1"; }

# The camera-less bake first: the web viewer's overview against irview's.
"$irview" "$work/bake/scene.gltf" --width $w --height $h --screenshot "$work/irview_overview.png" > "$work/irview.log" 2>&1
overview=$(node "$src/runtime/web/render_compare.mjs" --modules "$modules" --scene "$work/bake/scene.gltf" --width $w \
  --height $h --reference "$work/irview_overview.png" --out "$work/web_overview.png" --max-mean-abs $limit)

validation=$(node "$src/runtime/web/validate.mjs" --modules "$modules" --output "$work/bake/scene.gltf" --input "$scene")
python3 "$src/bench/cycles/add_sponza_camera.py" "$work/bake/scene.gltf" "$w" "$h"
"$irview" "$work/bake/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview.png" >> "$work/irview.log" 2>&1

readme=$(grep -o 'gltf-transform optimize in\.gltf out\.glb[^`]*' "$src/README.md" | head -1)
[[ -n $readme ]] || { echo "no 'gltf-transform optimize in.gltf out.glb …' command in README.md"; exit 1; }
read -ra words <<< "${readme#gltf-transform }"
for i in "${!words[@]}"; do
  [[ ${words[$i]} == in.gltf ]] && words[$i]="$work/bake/scene.gltf"
  [[ ${words[$i]} == out.glb ]] && words[$i]="$work/optimized.glb"
done
(cd "$src" && "$gltf_transform" "${words[@]}") > "$work/gltf-transform.log" 2>&1
optimized=$(node "$src/runtime/web/render_compare.mjs" --modules "$modules" --scene "$work/optimized.glb" --camera 0 \
  --width $w --height $h --reference "$work/irview.png" --out "$work/web_optimized.png" --max-mean-abs $limit)

blender --background --factory-startup --python "$src/runtime/blender/render_compare.py" -- --scene "$work/bake/scene.gltf" \
  --reference "$work/irview.png" --out "$work/blender" --width $w --height $h --samples 16 --max-mean-abs-exr $limit \
  --max-mean-abs-png $limit --min-control-mean-abs 10 > "$work/blender.log" 2>&1 || { grep render_compare "$work/blender.log"; exit 1; }
materials=$(python3 -c 'import json, sys; print(sum("MOZ_lightmap" in m.get("extensions", {}) for m in json.load(open(sys.argv[1]))["materials"]))' \
  "$work/bake/scene.gltf")  # the light-mapped ones
blender_row() {  # variant → "mad,wired"
  python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))[sys.argv[2]]; print("%.3f,%d" % (r["meanAbs"], len(r["wiredMaterials"])))' \
    "$work/blender/results.json" "$1"
}
IFS=, read -r exr_mad exr_wired <<< "$(blender_row exr)"
IFS=, read -r png_mad png_wired <<< "$(blender_row png)"
IFS=, read -r control_mad control_wired <<< "$(blender_row control)"
[[ $exr_wired == "$materials" && $png_wired == "$materials" ]] \
  || { echo "the add-on wired $exr_wired (EXR) and $png_wired (PNG) of $materials light-mapped materials"; exit 1; }
warnings=$(python3 -c 'import json, sys; r = json.loads(sys.argv[1]); print("%d errors %d warnings %d infos (input %d / %d / %d)" % (r["errors"], r["warnings"], r["infos"], r["input"]["errors"], r["input"]["warnings"], r["input"]["infos"]))' "$validation")

csv="$src/bench/results/sponza_clients.csv"
echo "scene,camera,width,height,client,reference,mad_8bit,limit,materials_wired,validator,command,load_1min" > "$csv"
cmd="bash bench/sponza_clients.sh build"
load=$(cut -d' ' -f1 /proc/loadavg)
row() { echo "sponza_sun_sky,$1,$w,$h,$2,$3,$4,$limit,$5,$warnings,$cmd,$load" >> "$csv"; }
row "none (irview overview)" "three.js viewer without a camera (overview_camera.js)" "irview overview" "$(mad "$overview")" ""
row "scenes.py overview" "three.js on README.md's gltf-transform optimize output" "irview on the bake" "$(mad "$optimized")" ""
row "scenes.py overview" "Blender irbake_lightmap.py (float EXR pages; Cycles 16 samples a pixel)" "irview on the bake" "$exr_mad" "$exr_wired of $materials"
row "scenes.py overview" "Blender irbake_lightmap.py (PNG pages; Cycles 16 samples a pixel)" "irview on the bake" "$png_mad" "$png_wired of $materials"
row "scenes.py overview" "Blender importer alone (control: must differ)" "irview on the bake" "$control_mad" "$control_wired of $materials"
echo "README.md: gltf-transform ${words[*]}: $(stat -c %s "$work/optimized.glb") bytes"
cat "$csv"
