#!/usr/bin/env bash
# Real-client test of IRBAKE_light_probes: bake the Cornell box (probes on by default), drop a white sphere
# (albedo 1) lit by the probes into the same look-at view in irview (--probe-object, PNG) and in three.js
# (irbake_light_probes.js, ?probeObject=) and require the sphere's pixels to agree: mean absolute difference
# ≤ 1 (8-bit; what is left is the three.js sphere's tessellated normals and the two sRGB encoders' rounding).
# Then the page must refuse three corrupted grids (too-short accessors, a zero count, a NaN coefficient) naming
# the problem.
# Usage (from ctest): web_probes_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_browser_client "$modules" "$work"
"$irbake" samples "$work/samples" > "$work/samples.log"
"$irbake" bake "$work/samples/cornell_box.gltf" -o "$work/bake" --vpls 512 --texels-per-unit 60 --quiet > "$work/bake.log" 2>&1
sphere=0.2,0.4,0.2,0.08 eye=0.25,0.42,-0.25 target=0.2,0.4,0.2 fov=40 w=160 h=160
"$irview" "$work/bake/scene.gltf" --probe-object $sphere --eye $eye --target $target --fov $fov --width $w --height $h \
  --screenshot "$work/irview.png" > "$work/irview.log" 2>&1
view=(--modules "$modules" --probe-object $sphere --eye $eye --target $target --fov $fov --width $w --height $h)
node "$here/probe_compare.mjs" "${view[@]}" --scene "$work/bake/scene.gltf" --reference "$work/irview.png" \
  --out "$work/web.png" --max-mean-abs 1
node "$here/corrupt_probes.mjs" "$work/bake/scene.gltf"
node "$here/probe_compare.mjs" "${view[@]}" --scene "$work/bake/scene_probe_counts.gltf" \
  --expect-error "IRBAKE_light_probes.coefficients: "
node "$here/probe_compare.mjs" "${view[@]}" --scene "$work/bake/scene_probe_zero.gltf" \
  --expect-error "IRBAKE_light_probes.counts: 0 is not a whole number from 1 to 10^6"
node "$here/probe_compare.mjs" "${view[@]}" --scene "$work/bake/scene_probe_nan.gltf" \
  --expect-error "IRBAKE_light_probes: probe 0 has a non-finite coefficient"
