#!/usr/bin/env bash
# The clients refuse what irview refuses (plugin_refusals.mjs): a small Cornell-box bake with probes, broken
# copies of its MOZ_lightmap and IRBAKE_light_probes (among them grids no bake writes: a spacing outside
# 0.01 … 1e9 m, an origin or far corner beyond 1e9 m, a probe moved 2 spacings), each refused by irview (exit 5),
# three.js and Babylon.js (MOZ_lightmap only) with the same message; the bake as written and without texCoord or
# intensity (defaults 1) loads in all three, a probe moved exactly one spacing in irview and three.js.
# Usage (from ctest): web_refusals_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_node_modules "$modules" @babylonjs/core @babylonjs/loaders
need_browser_client "$modules" "$work"
"$irbake" samples "$work/samples" > "$work/samples.log"
"$irbake" bake "$work/samples/cornell_box.gltf" -o "$work/bake" --vpls 64 --texels-per-unit 20 --quiet > "$work/bake.log" 2>&1
node "$here/plugin_refusals.mjs" --modules "$modules" --irview "$irview" --scene "$work/bake/scene.gltf"
