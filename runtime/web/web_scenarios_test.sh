#!/usr/bin/env bash
# Real-client test of light groups (docs/export.md, "Scenarios and light groups"): the Cornell box baked with two
# groups, `day` (a sun through the open front) and `lamp` (its emissive ceiling), and `irbake relight` of that bake
# at day = lamp = 0.5. three.js (irbake_lightmap_scenarios.js) blends the grouped bake's layers at run time:
#   - the relit file without the blend (its own maps, as any MOZ_lightmap client) against irview's screenshot of
#     it: mean absolute difference ≤ 2 (8-bit);
#   - the grouped bake blended at 0.5/0.5 against that render of the relit file: ≤ 2;
#   - the blend at the default weights (1, 1) against the grouped bake's own maps without the blend: ≤ 2;
#   - the blend at (1, 1) against the relit file must fail (the comparison can fail);
#   - the viewer's sliders (scenario_slider_check.mjs on index.html): a slider for day, for lamp and the day ⇄ lamp
#     fade; day and lamp moved to 0.5 draw the blend at 0.5/0.5 (≤ 0.5 from it), the fade moved to the lamp alone
#     changes the canvas;
#   - a layer intensity of -1 and a weight naming no layer are refused, naming the field;
#   - `gltf-transform optimize` (gltf-transform.config.mjs, WebP) keeps IRBAKE_lightmap_scenarios
#     (gltf_transform_check.mjs scenarios), and the optimised file blended at 0.5/0.5 is ≤ 3 from the relit render;
#   - the Khronos validator finds no error and no new warning in the grouped bake, the relit file and the optimised
#     one (validate.mjs: the layers' textures show as unused infos, their accessors are accepted).
# Skips (77) when this irbake has no --light-group, or without node, Chromium or the node modules.
# Usage (from ctest): web_scenarios_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_node_modules "$modules" @gltf-transform/cli @gltf-transform/core @gltf-transform/extensions @gltf-transform/functions \
  meshoptimizer gltf-validator
need_browser_client "$modules" "$work"
[[ $("$irbake" bake --help-all) == *--light-group* ]] || skip "this irbake bakes no light groups (no --light-group)"
w=320 h=320
"$irbake" samples "$work/samples" > "$work/samples.log"
"$irbake" bake "$work/samples/cornell_box.gltf" -o "$work/grouped" --vpls 512 --texels-per-unit 120 \
  --sun 0.2,-0.5,1,3 --probes 0.06 --light-group day=sun --light-group lamp=emissive --quiet > "$work/bake.log" 2>&1
"$irbake" relight "$work/grouped/scene.gltf" --group day=0.5 --group lamp=0.5 -o "$work/relit/scene.gltf" > "$work/relight.log"
"$irview" "$work/relit/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_relit.png" > "$work/irview.log" 2>&1
"$irview" "$work/grouped/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_grouped.png" >> "$work/irview.log" 2>&1
compare() {  # scene, reference, out, max mean abs, render_compare options...
  local scene="$1" ref="$2" out="$3" max="$4"; shift 4
  echo "== $(basename "$out" .png)"
  node "$here/render_compare.mjs" --modules "$modules" --scene "$scene" --camera 0 --width $w --height $h \
    --reference "$ref" --out "$out" --max-mean-abs "$max" "$@"
}
compare "$work/relit/scene.gltf" "$work/irview_relit.png" "$work/web_relit.png" 2 --scenarios off
compare "$work/grouped/scene.gltf" "$work/web_relit.png" "$work/web_blend_half.png" 2 --weights 'day=0.5;lamp=0.5' --min-blended 1
compare "$work/grouped/scene.gltf" "$work/irview_grouped.png" "$work/web_grouped.png" 2 --scenarios off
compare "$work/grouped/scene.gltf" "$work/web_grouped.png" "$work/web_blend_default.png" 2 --min-blended 1
if compare "$work/grouped/scene.gltf" "$work/web_relit.png" "$work/web_blend_full.png" 2 --weights 'day=1;lamp=1' \
  > "$work/full.log" 2>&1; then
  echo "the blend at (1, 1) matched the relit file at 0.5/0.5: the comparison cannot fail"; cat "$work/full.log"; exit 1
fi
grep -o 'mean absolute difference [0-9.]*' "$work/full.log"
node "$here/scenario_slider_check.mjs" --modules "$modules" --scene "$work/grouped/scene.gltf" --camera 0 --width $w --height $h \
  --layers day,lamp --set 'day=0.5;lamp=0.5' --out-set "$work/slider_half.png" --out-fade "$work/slider_lamp.png"
node "$here/render_compare.mjs" --modules "$modules" --image "$work/slider_half.png" --reference "$work/web_blend_half.png" \
  --out "$work/slider_half_compared.png" --max-mean-abs 0.5
# Bad data: a layer intensity of -1; a weight for a layer the file lacks.
node -e '
const fs = require("fs"); const [src, dst] = process.argv.slice(1);
const g = JSON.parse(fs.readFileSync(src, "utf8")); g.extensions.IRBAKE_lightmap_scenarios.layers[1].intensity[0] = -1;
fs.writeFileSync(dst, JSON.stringify(g));' "$work/grouped/scene.gltf" "$work/grouped/bad_intensity.gltf"
refused() {  # log, expected message, what
  grep -qF "$2" "$1" || { echo "$3: not refused with '$2'"; cat "$1"; exit 1; }
  echo "$3 refused: $2"
}
if compare "$work/grouped/bad_intensity.gltf" "$work/web_grouped.png" "$work/web_bad.png" 2 > "$work/bad.log" 2>&1; then
  echo "a layer intensity of -1 was accepted"; exit 1
fi
refused "$work/bad.log" 'IRBAKE_lightmap_scenarios.layers[1].intensity: [-1' 'intensity -1'
if compare "$work/grouped/scene.gltf" "$work/web_grouped.png" "$work/web_bad.png" 2 --weights 'night=1' > "$work/bad_weight.log" 2>&1; then
  echo "a weight for a layer the file lacks was accepted"; exit 1
fi
refused "$work/bad_weight.log" "IRBAKE_lightmap_scenarios: no layer 'night'" 'weight of a missing layer'
# glTF-Transform keeps the extension; the validator on every file.
"$modules/node_modules/.bin/gltf-transform" optimize "$work/grouped/scene.gltf" "$work/optimized.glb" --texture-compress webp \
  --simplify false --config "$here/gltf-transform.config.mjs" > "$work/gltf-transform.log" 2>&1
node "$here/gltf_transform_check.mjs" scenarios --modules "$modules" --input "$work/grouped/scene.gltf" --output "$work/optimized.glb"
compare "$work/optimized.glb" "$work/web_relit.png" "$work/web_optimized_half.png" 3 --weights 'day=0.5;lamp=0.5' --min-blended 1
node "$here/validate.mjs" --modules "$modules" --output "$work/grouped/scene.gltf" --input "$work/samples/cornell_box.gltf"
node "$here/validate.mjs" --modules "$modules" --output "$work/relit/scene.gltf" --input "$work/grouped/scene.gltf"
node "$here/validate.mjs" --modules "$modules" --output "$work/optimized.glb" --input "$work/grouped/scene.gltf"
