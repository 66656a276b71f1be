#!/usr/bin/env bash
# Babylon.js as a real client: bake the Cornell box (with --portable), render the bake from its glTF camera in
# headless Chromium with Babylon's glTF loader and our MOZ_lightmap extension (babylon_moz_lightmap.js), and
# require a mean absolute difference ≤ 2 (8-bit) against irview; then the portable GLB with Babylon's loader
# alone (no extension of ours): ≤ 3.
# Usage (from ctest): web_babylon_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_node_modules "$modules" @babylonjs/core @babylonjs/loaders
need_browser_client "$modules" "$work"
bake_cornell_and_irview "$irbake" "$irview" "$work" --portable "$work/portable.glb"
compare() { node "$here/render_compare.mjs" --client babylon --modules "$modules" --camera 0 --width $w --height $h \
              --reference "$work/irview.png" "$@"; }
compare --scene "$work/bake/scene.gltf" --out "$work/babylon.png" --max-mean-abs 2
compare --scene "$work/portable.glb" --plugin none --out "$work/babylon_portable.png" --max-mean-abs 3
