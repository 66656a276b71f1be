#!/usr/bin/env bash
# Blender client test: bake the Cornell box, render it from its glTF camera with irview and with Blender's
# Cycles after importing through irbake_lightmap.py (float EXR pages, 8-bit PNG pages, from .gltf and .glb), and
# require a mean absolute difference (8-bit) ≤ 0.5 for the EXR pages and ≤ 1 for the PNG pages; Blender's
# importer alone must differ by ≥ 10. Skips (77) when Blender or its numpy is missing.
# Usage (from ctest): blender_test.sh IRBAKE IRVIEW WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" work="$3"
here="$(cd "$(dirname "$0")" && pwd)"
skip() { echo "SKIPPED: $*"; exit 77; }
command -v blender >/dev/null 2>&1 || skip "blender not found (scripts/install-deps.sh installs Debian blender)"
blender --background --factory-startup --python-expr "import numpy" >/dev/null 2>&1 \
  || skip "Blender's Python cannot import numpy, which its glTF importer needs (Debian python3-numpy)"
rm -rf "$work" && mkdir -p "$work"
"$irbake" samples "$work/samples" --quiet > "$work/samples.log"
w=320 h=320
for kind in gltf glb; do
  out="$work/bake" && scene="$out/scene.gltf"
  if [[ $kind == glb ]]; then out="$work/bake_glb/cornell.glb" && scene="$out"; fi
  "$irbake" bake "$work/samples/cornell_box.gltf" -o "$out" --vpls 512 --texels-per-unit 60 --quiet > "$work/bake_$kind.log" 2>&1
  "$irview" "$scene" --camera 0 --width $w --height $h --screenshot "$work/irview_$kind.png" > "$work/irview_$kind.log" 2>&1
  blender --background --factory-startup --python "$here/render_compare.py" -- --scene "$scene" \
    --reference "$work/irview_$kind.png" --out "$work/blender_$kind" --width $w --height $h \
    --max-mean-abs-exr 0.5 --max-mean-abs-png 1.0 --min-control-mean-abs 10 > "$work/blender_$kind.log" 2>&1 \
    || { status=$?; grep "render_compare\|Error\|Traceback" "$work/blender_$kind.log" || tail -20 "$work/blender_$kind.log"; exit $status; }
  grep "render_compare" "$work/blender_$kind.log" | sed "s/^/$kind: /"
done
