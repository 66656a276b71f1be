#!/usr/bin/env bash
# Real-client test of IRBAKE_light_probes: bake the Cornell box (probes on by default), drop a white sphere
# (albedo 1) lit by the probes into the same look-at view in irview (--probe-object, PNG) and in three.js
# (irbake_light_probes.js, ?probeObject=) and require the sphere's pixels to agree: mean absolute difference
# ≤ 1 (8-bit; what is left is the three.js sphere's tessellated normals and the two sRGB encoders' rounding).
# Then the page must refuse three corrupted grids (too-short accessors, a zero count, a NaN coefficient) naming
# the problem, and three bad exact emitters (the box's ceiling light is one: IRBAKE_light_probes.emitters). The
# same with a sun level (IRBAKE_light_probes.sun): the emissive square over a plane under a sun
# straight down, the sphere across the square's shadow edge in a refined cell, its sun shaded as an exact clamped
# cosine by both (L2 would put 3/32 of the sun on its equator); and refusals of a sun visibility SH that is not
# finite, unsorted cells and a negative sun irradiance. glTF-Transform optimize (meshopt) with runtime/web's config must keep
# the sun level's accessors bit for bit (gltf_transform_check.mjs survives) and its refusals of bad sun data,
# and the Khronos validator finds no error in the bake (validate.mjs); skipped when the CLI is not installed.
# A probe-lit object (the short block, extras.irbake.mode "probes") is shaded from the probes by both clients alike.
# Usage (from ctest): web_probes_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_browser_client "$modules" "$work"
"$irbake" samples "$work/samples" > "$work/samples.log"
"$irbake" bake "$work/samples/cornell_box.gltf" -o "$work/bake" --vpls 512 --texels-per-unit 60 --quiet > "$work/bake.log" 2>&1
fov=40 w=160 h=160
# irview's probe-lit sphere ($2: x,y,z,r) in scene $1 seen from $3 towards $4, and the three.js page's held to
# it (mean |difference| ≤ 1 of 255); leaves view=(...) set for the refusals that follow.
sphere_against_irview() {
  local scene=$1 sphere=$2 eye=$3 target=$4 name=$5
  "$irview" "$scene" --probe-object $sphere --eye $eye --target $target --fov $fov --width $w --height $h \
    --screenshot "$work/irview$name.png" > "$work/irview$name.log" 2>&1
  view=(--modules "$modules" --probe-object $sphere --eye $eye --target $target --fov $fov --width $w --height $h)
  node "$here/probe_compare.mjs" "${view[@]}" --scene "$scene" --reference "$work/irview$name.png" \
    --out "$work/web$name.png" --max-mean-abs 1
}
# three.js refuses SCENE with an Error whose message starts with TEXT.
refuses() { node "$here/probe_compare.mjs" "${view[@]}" --scene "$1" --expect-error "$2"; }
sphere_against_irview "$work/bake/scene.gltf" 0.2,0.4,0.2,0.08 0.25,0.42,-0.25 0.2,0.4,0.2 ""
node "$here/corrupt_probes.mjs" "$work/bake/scene.gltf"
refuses "$work/bake/scene_probe_counts.gltf" "IRBAKE_light_probes.coefficients: "
refuses "$work/bake/scene_probe_zero.gltf" "IRBAKE_light_probes.counts: 0 is not a whole number from 1 to 10^6"
refuses "$work/bake/scene_probe_nan.gltf" "IRBAKE_light_probes: probe 0 has a non-finite coefficient"
# The box's ceiling light is an exact emitter (IRBAKE_light_probes.emitters): the sphere above is lit by it so in
# both clients; each refuses a bad entry naming the field.
node -e "const e = JSON.parse(require('fs').readFileSync('$work/bake/scene.gltf')).extensions.IRBAKE_light_probes;
         if (!(e.emitters?.length === 1)) { console.error('the ceiling light is not an exact emitter'); process.exit(1); }"
refuses "$work/bake/scene_emitter_positions.gltf" "IRBAKE_light_probes.emitters[0].positions: accessor of componentType 5126 SCALAR, expected 5126 VEC3"
refuses "$work/bake/scene_emitter_radiance.gltf" "IRBAKE_light_probes.emitters[0].radiance: not finite"
refuses "$work/bake/scene_emitter_visibility.gltf" "IRBAKE_light_probes.emitters[0].visibility: "

# A probe-lit object (extras.irbake.mode "probes" on the short block): no map texels, its primitives marked
# extras.lightProbes, and lit by the probes (and the exact ceiling emitter) in both clients, which agree.
node -e "const fs = require('fs'), d = JSON.parse(fs.readFileSync('$work/samples/cornell_box.gltf'));
         d.nodes.find(n => n.name === 'short_block').extras = { irbake: { mode: 'probes' } };
         fs.writeFileSync('$work/samples/cornell_probe_lit.gltf', JSON.stringify(d));"
"$irbake" bake "$work/samples/cornell_probe_lit.gltf" -o "$work/probe_lit" --vpls 512 --texels-per-unit 60 --quiet \
  > "$work/probe_lit.log" 2>&1
node -e "const d = JSON.parse(require('fs').readFileSync('$work/probe_lit/scene.gltf'));
         const p = d.meshes[d.nodes.find(n => n.name === 'short_block').mesh].primitives[0];
         if (p.extras?.lightProbes !== true || p.attributes.TEXCOORD_1 !== undefined) {
           console.error('the short block is not exported as a probe-lit object'); process.exit(1); }"
"$irview" "$work/probe_lit/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_probe_lit.png" \
  > "$work/irview_probe_lit.log" 2>&1
node "$here/render_compare.mjs" --modules "$modules" --scene "$work/probe_lit/scene.gltf" --camera 0 --width $w --height $h \
  --reference "$work/irview_probe_lit.png" --out "$work/web_probe_lit.png" --max-mean-abs 2 --min-probe-lit 1

# The sun level (with --directional, which gltf_transform_check.mjs refusals needs): probes every 0.5 m,
# x = ..., 0.25, 0.75, ...; the shadow edge x = 0.5 crosses that cell.
"$irbake" bake "$work/samples/quad_over_plane.gltf" -o "$work/sun" --vpls 256 --texels-per-unit 20 --sun 0,-1,0,3 --directional \
  --probes 0.5 --probe-box=-2,0.05,-2,2,0.95,2 --quiet > "$work/sun.log" 2>&1
node -e "const e = JSON.parse(require('fs').readFileSync('$work/sun/scene.gltf')).extensions.IRBAKE_light_probes;
         if (!e.sun) { console.error('no sun level in the bake'); process.exit(1); }"
sphere_against_irview "$work/sun/scene.gltf" 0.55,0.5,0,0.08 0.85,0.6,-0.3 0.55,0.5,0 _sun
node "$here/corrupt_probes.mjs" "$work/sun/scene.gltf"
refuses "$work/sun/scene_sun_nan.gltf" "IRBAKE_light_probes.sun.sh: a non-finite coefficient"
refuses "$work/sun/scene_sun_cells.gltf" "IRBAKE_light_probes.sun.cells: not in ascending order at element 1"
refuses "$work/sun/scene_sun_irradiance.gltf" "IRBAKE_light_probes.sun.irradiance: negative"

# A sun level without refined cells (`cells` and `fine` omitted, as the bake writes it where the sun's shadow
# crosses no cell): both clients read it, the sun still exact, and agree.
node -e "const fs = require('fs'), d = JSON.parse(fs.readFileSync('$work/sun/scene.gltf'));
         delete d.extensions.IRBAKE_light_probes.sun.cells; delete d.extensions.IRBAKE_light_probes.sun.fine;
         fs.writeFileSync('$work/sun/scene_uncut.gltf', JSON.stringify(d));"
sphere_against_irview "$work/sun/scene_uncut.gltf" 0.55,0.5,0,0.08 0.85,0.6,-0.3 0.55,0.5,0 _uncut

gltf_transform="$modules/node_modules/.bin/gltf-transform"
if [[ -x "$gltf_transform" && -d "$modules/node_modules/gltf-validator" ]]; then
  "$gltf_transform" optimize "$work/sun/scene.gltf" "$work/sun_opt.glb" --config "$here/gltf-transform.config.mjs" \
    > "$work/gltf-transform.log" 2>&1
  node "$here/gltf_transform_check.mjs" survives --modules "$modules" --input "$work/sun/scene.gltf" \
    --output "$work/sun_opt.glb" --probes
  node "$here/gltf_transform_check.mjs" refusals --modules "$modules" --input "$work/sun/scene.gltf"
  node "$here/validate.mjs" --modules "$modules" --output "$work/sun/scene.gltf"
  # Without cells: optimize keeps the sun level as it is (its two dropped accessors pruned) and the result validates.
  "$gltf_transform" optimize "$work/sun/scene_uncut.gltf" "$work/uncut_opt.glb" --config "$here/gltf-transform.config.mjs" \
    >> "$work/gltf-transform.log" 2>&1
  node "$here/gltf_transform_check.mjs" survives --modules "$modules" --input "$work/sun/scene_uncut.gltf" \
    --output "$work/uncut_opt.glb" --probes
  node "$here/validate.mjs" --modules "$modules" --output "$work/uncut_opt.glb"
else
  echo "glTF-Transform or gltf-validator not installed: the sun level's optimiser and validator checks skipped"
fi
