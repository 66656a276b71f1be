#!/usr/bin/env bash
# Real-client test of directional light maps: a generated normal-mapped plane under a point light
# (make_directional_scene.mjs) baked with --directional, rendered with irview and with three.js in headless
# Chromium (runtime/web, moz_lightmap.js). Mean absolute differences (8-bit sRGB, 256 × 256):
#   - web SH against irview reading the same 8-bit L1 PNGs (its L1 EXRs removed): ≤ 0.5;
#   - web SH against irview's default (float L1 EXR pages): ≤ 1.5 (the PNGs' code 128 decodes to +0.0039·scale,
#     not 0: a small bias, docs/export.md);
#   - the same with TANGENT given instead of generated tangents: ≤ 1.5;
#   - the same with TEXCOORD_0 mirrored at the plane's middle line (its vertices shared by both halves; both
#     viewers split them the MikkTSpace way): ≤ 1.5;
#   - web lightmap=l0 against irview --lightmap-mode l0: ≤ 0.5.
# A web viewer that ignored the extension (shows L0) differs from irview's SH render by 21.4, one with the
# bitangent flipped by 21.5 (measured): both fail.
# Usage (from ctest): web_directional_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_browser_client "$modules" "$work"
w=256 h=256
bake() {  # input folder, output folder, [--tangent | --mirror]
  node "$here/make_directional_scene.mjs" "$work/$1" ${3:-} > /dev/null
  "$irbake" bake "$work/$1/plane.gltf" -o "$work/$2" --directional --vpls 256 --texels-per-unit 16 --quiet >> "$work/bake.log" 2>&1
}
shot() {  # scene, png, irview options...
  local scene="$1" png="$2"; shift 2
  "$irview" "$scene" --camera 0 --width $w --height $h --screenshot "$png" "$@" >> "$work/irview.log" 2>&1
}
compare() {  # scene, reference, out, max mean abs, render_compare options...
  local scene="$1" ref="$2" out="$3" max="$4"; shift 4
  echo "== $(basename "$out" .png)"
  node "$here/render_compare.mjs" --modules "$modules" --scene "$scene" --camera 0 --width $w --height $h \
    --reference "$ref" --out "$out" --max-mean-abs "$max" "$@"
}
bake in bake
bake in_tangent bake_tangent --tangent
bake in_mirror bake_mirror --mirror
shot "$work/bake/scene.gltf" "$work/irview_sh.png"
shot "$work/bake/scene.gltf" "$work/irview_l0.png" --lightmap-mode l0
shot "$work/bake_tangent/scene.gltf" "$work/irview_tangent_sh.png"
shot "$work/bake_mirror/scene.gltf" "$work/irview_mirror_sh.png"
cp -r "$work/bake" "$work/bake_png" && rm "$work"/bake_png/lightmap_0_l1[xyz].exr
shot "$work/bake_png/scene.gltf" "$work/irview_png_sh.png"

compare "$work/bake_png/scene.gltf" "$work/irview_png_sh.png" "$work/web_sh_vs_png.png" 0.5 --min-directional 1
compare "$work/bake/scene.gltf" "$work/irview_sh.png" "$work/web_sh.png" 1.5 --min-directional 1
compare "$work/bake_tangent/scene.gltf" "$work/irview_tangent_sh.png" "$work/web_tangent_sh.png" 1.5 --min-directional 1
compare "$work/bake_mirror/scene.gltf" "$work/irview_mirror_sh.png" "$work/web_mirror_sh.png" 1.5 --min-directional 1
compare "$work/bake/scene.gltf" "$work/irview_l0.png" "$work/web_l0.png" 0.5 --lightmap l0
