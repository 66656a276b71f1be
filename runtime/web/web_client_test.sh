#!/usr/bin/env bash
# Real-client test: bake the Cornell box, render it from its glTF camera with irview and
# with three.js in headless Chromium (runtime/web), and require a mean absolute difference ≤ 2 (8-bit).
# Usage (from ctest): web_client_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_browser_client "$modules" "$work"
bake_cornell_and_irview "$irbake" "$irview" "$work"
node "$here/render_compare.mjs" --modules "$modules" --scene "$work/bake/scene.gltf" --camera 0 --width $w --height $h \
  --reference "$work/irview.png" --out "$work/web.png" --max-mean-abs 2
