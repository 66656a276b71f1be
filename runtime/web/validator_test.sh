#!/usr/bin/env bash
# Khronos glTF-Validator on every kind of export: the baked Cornell box (.gltf + .bin +
# images), the same as one GLB, the same with --directional, a shadow-mask bake (.gltf and GLB), an indirect bake (its light records), `irbake unwrap` output, and the DamagedHelmet from ../shared baked with
# --sun (skipped with a message when absent). Each: 0 errors, no warning its input did not have, no
# UNUSED_OBJECT for a mesh or an accessor (runtime/web/validate.mjs).
# Usage (from ctest): validator_test.sh IRBAKE MODULES_DIR WORK_DIR SOURCE_DIR
set -euo pipefail
irbake="$1" modules="$2" work="$3" source="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_node_modules "$modules" gltf-validator
rm -rf "$work" && mkdir -p "$work"
validate() { node "$here/validate.mjs" --modules "$modules" --output "$1" --input "$2"; }
"$irbake" samples "$work/samples" > "$work/samples.log"
cornell="$work/samples/cornell_box.gltf"
"$irbake" bake "$cornell" -o "$work/cornell" --vpls 128 --texels-per-unit 60 --quiet > "$work/bake.log" 2>&1
validate "$work/cornell/scene.gltf" "$cornell"
"$irbake" bake "$cornell" -o "$work/glb/cornell.glb" --vpls 128 --texels-per-unit 60 --quiet >> "$work/bake.log" 2>&1
validate "$work/glb/cornell.glb" "$cornell"
# Directional maps: IRBAKE_lightmap_directional on the materials, in extensionsUsed only.
"$irbake" bake "$cornell" -o "$work/directional" --vpls 128 --texels-per-unit 60 --directional --quiet >> "$work/bake.log" 2>&1
validate "$work/directional/scene.gltf" "$cornell"
# Shadow masks: IRBAKE_shadowmask on the materials and the root, in extensionsUsed only; as .gltf and GLB.
wall="$work/samples/thin_wall.gltf"
"$irbake" bake "$wall" -o "$work/shadowmask" --vpls 128 --light-mode '*=shadowmask' --quiet >> "$work/bake.log" 2>&1
validate "$work/shadowmask/scene.gltf" "$wall"
"$irbake" bake "$wall" -o "$work/shadowmask_glb/wall.glb" --vpls 128 --light-mode '*=shadowmask' --quiet >> "$work/bake.log" 2>&1
validate "$work/shadowmask_glb/wall.glb" "$wall"
# Mixed-light records: an indirect KHR light (extras.irbake.mode) and an indirect --sun (root extras irbakeSun).
"$irbake" bake "$wall" -o "$work/indirect" --vpls 128 --sun 0.3,-1,-0.4,3 --light-mode '*=indirect' --quiet >> "$work/bake.log" 2>&1
grep -q '"irbakeSun"' "$work/indirect/scene.gltf" && grep -q '"mode": *"indirect"' "$work/indirect/scene.gltf" \
  || { echo "the indirect bake does not record its lights"; exit 1; }
validate "$work/indirect/scene.gltf" "$wall"
"$irbake" unwrap "$cornell" -o "$work/unwrap/cornell.gltf" > "$work/unwrap.log" 2>&1
validate "$work/unwrap/cornell.gltf" "$cornell"
helmet="$source/../shared/scenes/damaged_helmet/DamagedHelmet.gltf"
if [[ -f "$helmet" ]]; then
  "$irbake" bake "$helmet" -o "$work/helmet" --sun 0.3,-1,-0.4,3 --vpls 64 --texels-per-unit 100 --quiet >> "$work/bake.log" 2>&1
  validate "$work/helmet/scene.gltf" "$helmet"
else
  echo "note: $helmet absent: the helmet case is skipped"
fi
