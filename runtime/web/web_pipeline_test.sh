#!/usr/bin/env bash
# glTF-Transform keeps the bake (docs/export.md, "Optimisers"): `gltf-transform optimize` with
# gltf-transform.config.mjs, --simplify false and WebP texture compression (docs/export.md's command) on
#   - the Cornell box (as web_client_test.sh bakes it) and the same with --directional;
#   - the normal-mapped plane of make_directional_scene.mjs with --directional: optimize with its default
#     simplify must refuse (the plane's grid simplifies), with --simplify false it must pass; then README.md's
#     command, read from README.md and run as written from the source folder (only in.gltf and out.glb replaced);
#   - the DamagedHelmet from ../shared with --directional (skipped with a message when absent).
# Each output: every MOZ_lightmap / IRBAKE_lightmap_directional, every TEXCOORD_1 and (Cornell) the
# IRBAKE_light_probes grid with its accessors' values survives with the bake's
# numbers and triangle count (gltf_transform_check.mjs survives); three.js renders it (render_compare.mjs)
# within a mean absolute difference of 3 (8-bit) of irview on the original bake; the Khronos validator finds
# no error and no new warning (validate.mjs). Then the module's refusals of bad input and output
# (gltf_transform_check.mjs refusals).
# Usage (from ctest): web_pipeline_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR SOURCE_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4" source="$5"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_node_modules "$modules" @gltf-transform/cli @gltf-transform/core @gltf-transform/extensions @gltf-transform/functions \
  meshoptimizer gltf-validator
need_browser_client "$modules" "$work"
gltf_transform="$modules/node_modules/.bin/gltf-transform"
[[ -x "$gltf_transform" ]] || skip "$gltf_transform missing (run scripts/install-web-deps.sh BUILD_DIR)"
config="$here/gltf-transform.config.mjs"
size() { stat -c %s "$1"; }
# The bake as a client loads it: every file of its folder but the float EXR pages and report.json.
bake_size() { local d="$1" n=0 f; for f in "$d"/*; do [[ $f == *.exr || $f == */report.json ]] || n=$((n + $(size "$f"))); done; echo $n; }
optimize() {  # input glTF, output GLB, optimize options...
  local in="$1" out="$2"; shift 2
  "$gltf_transform" optimize "$in" "$out" --texture-compress webp --simplify false "$@" --config "$config" >> "$work/gltf-transform.log" 2>&1
  echo "== $(basename "$out"): $(bake_size "$(dirname "$in")") bytes (glTF, bin, images) -> $(size "$out") bytes"
}
survives() { node "$here/gltf_transform_check.mjs" survives --modules "$modules" --input "$1" --output "$2" "${@:3}"; }
compare() {  # scene, irview reference, out png, size, render_compare options...
  local scene="$1" ref="$2" out="$3" px="$4"; shift 4
  node "$here/render_compare.mjs" --modules "$modules" --scene "$scene" --camera 0 --width "$px" --height "$px" \
    --reference "$ref" --out "$out" --max-mean-abs 3 "$@"
}
validate() { node "$here/validate.mjs" --modules "$modules" --output "$1" --input "$2"; }

"$irbake" samples "$work/samples" > "$work/samples.log"
cornell="$work/samples/cornell_box.gltf"
for kind in plain directional; do
  flag=""; [[ $kind == directional ]] && flag="--directional"
  "$irbake" bake "$cornell" -o "$work/cornell_$kind" --vpls 512 --texels-per-unit 120 $flag --quiet >> "$work/bake.log" 2>&1
  "$irview" "$work/cornell_$kind/scene.gltf" --camera 0 --width 320 --height 320 \
    --screenshot "$work/cornell_${kind}_irview.png" >> "$work/irview.log" 2>&1
  optimize "$work/cornell_$kind/scene.gltf" "$work/cornell_$kind.glb"
  survives "$work/cornell_$kind/scene.gltf" "$work/cornell_$kind.glb" $flag --probes
  compare "$work/cornell_$kind.glb" "$work/cornell_${kind}_irview.png" "$work/cornell_${kind}_web.png" 320
  validate "$work/cornell_$kind.glb" "$work/cornell_$kind/scene.gltf"
done

# The plane's 4 × 4 grid: the default optimize simplifies it, which must be refused with no file written.
node "$here/make_directional_scene.mjs" "$work/plane_in" > /dev/null
"$irbake" bake "$work/plane_in/plane.gltf" -o "$work/plane" --directional --vpls 256 --texels-per-unit 16 --quiet >> "$work/bake.log" 2>&1
if "$gltf_transform" optimize "$work/plane/scene.gltf" "$work/plane_simplified.glb" --config "$config" > "$work/simplify.log" 2>&1; then
  echo "FAIL: optimize simplified the light-mapped plane without refusing"; exit 1
fi
grep -q "the geometry was simplified" "$work/simplify.log" || { echo "FAIL: no simplify refusal in:"; cat "$work/simplify.log"; exit 1; }
[[ ! -e "$work/plane_simplified.glb" ]] || { echo "FAIL: the refused optimize left $work/plane_simplified.glb"; exit 1; }
echo "== plane: optimize with simplify refused: $(grep -o 'light-mapped triangles [0-9]* → [0-9]*' "$work/simplify.log")"
"$irview" "$work/plane/scene.gltf" --camera 0 --width 256 --height 256 --screenshot "$work/plane_irview.png" >> "$work/irview.log" 2>&1
optimize "$work/plane/scene.gltf" "$work/plane.glb"
survives "$work/plane/scene.gltf" "$work/plane.glb" --directional
compare "$work/plane.glb" "$work/plane_irview.png" "$work/plane_web.png" 256 --min-directional 1
validate "$work/plane.glb" "$work/plane/scene.gltf"
# README.md's command as written ("Ship it"), from the source folder, on the plane its simplify would break.
readme=$(grep -o 'gltf-transform optimize in\.gltf out\.glb[^`]*' "$source/README.md" | head -1)
[[ -n $readme ]] || { echo "FAIL: no 'gltf-transform optimize in.gltf out.glb …' command in README.md"; exit 1; }
read -ra words <<< "${readme#gltf-transform }"
for i in "${!words[@]}"; do
  [[ ${words[$i]} == in.gltf ]] && words[$i]="$work/plane/scene.gltf"
  [[ ${words[$i]} == out.glb ]] && words[$i]="$work/plane_readme.glb"
done
echo "== README.md: gltf-transform ${words[*]}"
(cd "$source" && "$gltf_transform" "${words[@]}") > "$work/readme.log" 2>&1 \
  || { echo "FAIL: README.md's command failed:"; cat "$work/readme.log"; exit 1; }
survives "$work/plane/scene.gltf" "$work/plane_readme.glb" --directional
compare "$work/plane_readme.glb" "$work/plane_irview.png" "$work/plane_readme_web.png" 256 --min-directional 1
validate "$work/plane_readme.glb" "$work/plane/scene.gltf"

node "$here/gltf_transform_check.mjs" refusals --modules "$modules" --input "$work/cornell_directional/scene.gltf"

helmet="$source/../shared/scenes/damaged_helmet/DamagedHelmet.gltf"
if [[ -f "$helmet" ]]; then
  "$irbake" bake "$helmet" -o "$work/helmet" --sun 0.3,-1,-0.4,3 --vpls 64 --texels-per-unit 100 --directional --quiet >> "$work/bake.log" 2>&1
  # The helmet has no camera: one 3 m in front of it (+z, looking down -z) for both renderers.
  node -e 'const fs = require("fs"), f = process.argv[1], d = JSON.parse(fs.readFileSync(f));
    d.cameras = [{ type: "perspective", perspective: { yfov: 0.8, znear: 0.05 } }];
    d.nodes.push({ name: "front", camera: 0, translation: [0, 0, 3] });
    d.scenes[d.scene ?? 0].nodes.push(d.nodes.length - 1);
    fs.writeFileSync(f, JSON.stringify(d));' "$work/helmet/scene.gltf"
  "$irview" "$work/helmet/scene.gltf" --camera 0 --width 320 --height 320 --screenshot "$work/helmet_irview.png" >> "$work/irview.log" 2>&1
  optimize "$work/helmet/scene.gltf" "$work/helmet.glb"
  survives "$work/helmet/scene.gltf" "$work/helmet.glb" --directional
  compare "$work/helmet.glb" "$work/helmet_irview.png" "$work/helmet_web.png" 320 --min-directional 1
  validate "$work/helmet.glb" "$work/helmet/scene.gltf"
else
  echo "note: $helmet absent: the helmet case is skipped"
fi
