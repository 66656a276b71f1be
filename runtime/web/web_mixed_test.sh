#!/usr/bin/env bash
# Real-client test of mixed lighting (docs/export.md, "Mixed lights"): the Cornell box sample with its light
# made a point light (make_mixed_cornell.mjs) baked twice with the same seed, fully baked and in shadowmask
# mode. three.js in headless Chromium shades the shadowmask bake with its own point light (physical units)
# times the mask channel (irbake_shadowmask.js); irview shows the full bake. Mean absolute difference over
# the whole 320 × 320 image (8-bit sRGB, nothing excluded) ≤ 3. Without the real-time light (the map alone)
# the difference is far larger, so a client that dropped the light fails. Bad data: a mask channel out of
# range is refused by the plugin naming the entry. The same lamp with a range of 0.6 m (its edge crosses the
# floor and the walls' lower halves) baked both ways: three.js (three's distance = range, decay 2) against the
# full bake, and irview's shadowmask screenshot against it, each with mean absolute difference ≤ 2 over the
# region around the edge: the pixels where the full bake with the range differs from the one without by 8 or
# more (where the window dims the lamp, and beyond the range). A range that is no positive number is refused.
# Usage (from ctest): web_mixed_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_browser_client "$modules" "$work"
w=320 h=320
"$irbake" samples "$work/samples" > "$work/samples.log"
node "$here/make_mixed_cornell.mjs" "$work/samples/cornell_box.gltf" "$work/samples/cornell_point.gltf" > /dev/null
bake() {  # output folder, bake options...
  local out="$1"; shift
  "$irbake" bake "$work/samples/cornell_point.gltf" -o "$work/$out" --vpls 512 --texels-per-unit 120 "$@" --quiet \
    >> "$work/bake.log" 2>&1
}
bake baked
bake mask --light-mode 'lamp=shadowmask'
"$irview" "$work/baked/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_baked.png" > "$work/irview.log" 2>&1
"$irview" "$work/mask/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_mask.png" >> "$work/irview.log" 2>&1
compare() {  # scene, reference, out, max mean abs, render_compare options...
  local scene="$1" ref="$2" out="$3" max="$4"; shift 4
  echo "== $(basename "$out" .png)"
  node "$here/render_compare.mjs" --modules "$modules" --scene "$scene" --camera 0 --width $w --height $h \
    --reference "$ref" --out "$out" --max-mean-abs "$max" "$@"
}
compare "$work/mask/scene.gltf" "$work/irview_baked.png" "$work/web_mask_vs_baked.png" 3 --min-runtime-lights 1 --min-masked 1
compare "$work/mask/scene.gltf" "$work/irview_mask.png" "$work/web_mask_vs_irview_mask.png" 3 --min-runtime-lights 1 --min-masked 1
# The map alone (the light's direct term left out) must not pass.
if compare "$work/mask/scene.gltf" "$work/irview_baked.png" "$work/web_nolight.png" 3 --plugin moz-only > "$work/nolight.log" 2>&1; then
  echo "the shadowmask bake without its real-time light matched the full bake: the comparison cannot fail"; cat "$work/nolight.log"; exit 1
fi
grep -o 'mean absolute difference [0-9.]*' "$work/nolight.log"
# The lamp with a range.
node "$here/make_mixed_cornell.mjs" "$work/samples/cornell_box.gltf" "$work/samples/cornell_range.gltf" --range 0.6 > /dev/null
bake_range() {  # output folder, bake options...
  local out="$1"; shift
  "$irbake" bake "$work/samples/cornell_range.gltf" -o "$work/$out" --vpls 512 --texels-per-unit 120 "$@" --quiet \
    >> "$work/bake.log" 2>&1
}
bake_range range_baked
bake_range range_mask --light-mode 'lamp=shadowmask'
"$irview" "$work/range_baked/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_range_baked.png" >> "$work/irview.log" 2>&1
"$irview" "$work/range_mask/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_range_mask.png" >> "$work/irview.log" 2>&1
edge=(--region-a "$work/irview_range_baked.png" --region-b "$work/irview_baked.png" --region-min 8 --min-region-pixels 5000)
compare "$work/range_mask/scene.gltf" "$work/irview_range_baked.png" "$work/web_range_mask_vs_baked.png" 2 \
  --min-runtime-lights 1 --min-masked 1 "${edge[@]}"
echo "== irview_range_mask_vs_baked"
node "$here/render_compare.mjs" --modules "$modules" --image "$work/irview_range_mask.png" --width $w --height $h \
  --reference "$work/irview_range_baked.png" --out "$work/irview_range_mask_vs_baked.png" --max-mean-abs 2 "${edge[@]}"
# The map alone there (the lamp's direct term left out) must not pass.
if compare "$work/range_mask/scene.gltf" "$work/irview_range_baked.png" "$work/web_range_nolight.png" 2 --plugin moz-only \
  "${edge[@]}" > "$work/range_nolight.log" 2>&1; then
  echo "the ranged shadowmask bake without its real-time light matched the full bake: the comparison cannot fail"
  cat "$work/range_nolight.log"; exit 1
fi
grep -o 'mean absolute difference [0-9.]*' "$work/range_nolight.log"
# Bad data: channel 7 in the root map.
node -e '
const fs = require("fs"); const [src, dst] = process.argv.slice(1);
const g = JSON.parse(fs.readFileSync(src, "utf8")); g.extensions.IRBAKE_shadowmask.lights[0].channel = 7;
fs.writeFileSync(dst, JSON.stringify(g));' "$work/mask/scene.gltf" "$work/mask/bad_channel.gltf"
if compare "$work/mask/bad_channel.gltf" "$work/irview_baked.png" "$work/web_bad.png" 3 > "$work/bad.log" 2>&1; then
  echo "a mask channel of 7 was accepted"; exit 1
fi
grep -q 'IRBAKE_shadowmask.lights\[0\]: channel must be an integer 0..3' "$work/bad.log" || { cat "$work/bad.log"; exit 1; }
echo "bad channel refused: $(grep -o 'IRBAKE_shadowmask.lights\[0\]: channel[^\\]*' "$work/bad.log" | head -1)"
# Bad data: a range that is no positive number on a light left to the client.
node -e '
const fs = require("fs"); const [src, dst] = process.argv.slice(1);
const g = JSON.parse(fs.readFileSync(src, "utf8")); g.extensions.KHR_lights_punctual.lights[0].range = -1;
fs.writeFileSync(dst, JSON.stringify(g));' "$work/range_mask/scene.gltf" "$work/range_mask/bad_range.gltf"
if compare "$work/range_mask/bad_range.gltf" "$work/irview_range_baked.png" "$work/web_bad_range.png" 3 > "$work/bad_range.log" 2>&1; then
  echo "a range of -1 was accepted"; exit 1
fi
grep -q 'KHR_lights_punctual.lights\[0\]: range must be a number > 0' "$work/bad_range.log" || { cat "$work/bad_range.log"; exit 1; }
echo "bad range refused: $(grep -o 'KHR_lights_punctual.lights\[0\]: range[^\\]*' "$work/bad_range.log" | head -1)"
