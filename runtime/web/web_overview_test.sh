#!/usr/bin/env bash
# The web viewer on a scene without cameras (docs/export.md, "Checked by real clients"): the sample
# textured_plane (a checker-textured plane under a point light, no camera) baked. irview without --camera shows its overview; three.js (viewer.js) with no camera asked for
# must show the same view (overview_camera.js): mean absolute difference ≤ 2 (8-bit) against irview's
# screenshot, and its result must say it used the overview. Asked for camera 0, the page must refuse, as irview
# refuses --camera 0 there.
# Usage (from ctest): web_overview_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_browser_client "$modules" "$work"
"$irbake" samples "$work/samples" > "$work/samples.log"
"$irbake" bake "$work/samples/textured_plane.gltf" -o "$work/bake" --vpls 256 --texels-per-unit 60 --quiet > "$work/bake.log" 2>&1
node -e 'const d = JSON.parse(require("fs").readFileSync(process.argv[1]));
  if (d.cameras?.length) { console.log("FAIL: the sample has a camera"); process.exit(1); }' "$work/bake/scene.gltf"
w=320 h=240
"$irview" "$work/bake/scene.gltf" --width $w --height $h --screenshot "$work/irview.png" > "$work/irview.log" 2>&1
result=$(node "$here/render_compare.mjs" --modules "$modules" --scene "$work/bake/scene.gltf" --width $w --height $h \
  --reference "$work/irview.png" --out "$work/web.png" --max-mean-abs 2)
echo "$result"
[[ $result == *'"overview":true'* ]] || { echo "FAIL: the viewer did not use the overview"; exit 1; }
if node "$here/render_compare.mjs" --modules "$modules" --scene "$work/bake/scene.gltf" --camera 0 --width $w --height $h \
     --reference "$work/irview.png" --out "$work/web_camera0.png" > "$work/camera0.log" 2>&1; then
  echo "FAIL: camera 0 of a scene without cameras was shown"; exit 1
fi
grep -q "no camera 0" "$work/camera0.log" || { echo "FAIL: no 'no camera 0' refusal in:"; cat "$work/camera0.log"; exit 1; }
echo "camera 0 refused: $(grep -o 'no camera 0[^\\]*' "$work/camera0.log" | head -1)"
