#!/usr/bin/env bash
# glTF-Transform keeps the shadow masks (docs/export.md, "IRBAKE_shadowmask"): a shadow-mask bake of the
# thin-wall sample read, pruned, deduplicated and written with gltf_transform_irbake.mjs keeps every material's
# mask and the root's light → channel map; bad masks are refused naming the material (gltf_transform_check.mjs
# shadowmask). Usage (from ctest): web_shadowmask_test.sh IRBAKE MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" modules="$2" work="$3"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_node_modules "$modules" @gltf-transform/core
rm -rf "$work" && mkdir -p "$work"
"$irbake" samples "$work/samples" > "$work/samples.log"
"$irbake" bake "$work/samples/thin_wall.gltf" -o "$work/wall" --vpls 128 --light-mode '*=shadowmask' --quiet > "$work/bake.log" 2>&1
node "$here/gltf_transform_check.mjs" shadowmask --modules "$modules" --input "$work/wall/scene.gltf"
