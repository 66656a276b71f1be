#!/usr/bin/env bash
# Blender client test: bake a scene, render it from its glTF camera with irview and with Blender's Cycles after
# importing through irbake_lightmap.py (float EXR pages, then 8-bit PNG pages), and bound the mean absolute
# difference (8-bit); Blender's importer alone must differ by ≥ 10. Scenes: the Cornell box as .gltf and .glb
# (EXR ≤ 0.5, PNG ≤ 1), and the textured plane seen from a camera added here (base-colour texture × map; ≤ 2:
# Cycles filters the magnified 8-bit sRGB checker before decoding it, irview after). Skips (77) without
# Blender or its numpy.
# Usage (from ctest): blender_test.sh IRBAKE IRVIEW WORK_DIR
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/blender_tests_common.sh"
"$irbake" samples "$work/samples" --quiet > "$work/samples.log"
# The textured plane has no camera: one 2 m above it, looking straight down (-90° about x).
python3 - "$work/samples/textured_plane.gltf" "$work/samples/textured_plane_camera.gltf" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.9, "aspectRatio": 1.0, "znear": 0.01}}]
doc["nodes"].append({"name": "camera", "camera": 0, "translation": [0.3, 2.0, 0.4],
                     "rotation": [-0.70710678, 0.0, 0.0, 0.70710678]})
doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)
json.dump(doc, open(sys.argv[2], "w"))
PY

w=320 h=320
# run_case NAME INPUT BAKE_OUTPUT SCENE EXR_LIMIT PNG_LIMIT
run_case() {
  local name="$1" input="$2" out="$3" scene="$4" exr_limit="$5" png_limit="$6"
  "$irbake" bake "$input" -o "$out" --vpls 512 --texels-per-unit 60 --quiet > "$work/bake_$name.log" 2>&1
  "$irview" "$scene" --camera 0 --width $w --height $h --screenshot "$work/irview_$name.png" > "$work/irview_$name.log" 2>&1
  local status=0
  blender --background --factory-startup --python "$here/render_compare.py" -- --scene "$scene" \
    --reference "$work/irview_$name.png" --out "$work/blender_$name" --width $w --height $h \
    --max-mean-abs-exr "$exr_limit" --max-mean-abs-png "$png_limit" --min-control-mean-abs 10 \
    > "$work/blender_$name.log" 2>&1 || status=$?
  grep "render_compare" "$work/blender_$name.log" | sed "s/^/$name: /" || tail -20 "$work/blender_$name.log"
  return $status
}
run_case cornell_gltf "$work/samples/cornell_box.gltf" "$work/cornell" "$work/cornell/scene.gltf" 0.5 1.0
run_case cornell_glb "$work/samples/cornell_box.gltf" "$work/cornell_glb/cornell.glb" "$work/cornell_glb/cornell.glb" 0.5 1.0
run_case textured "$work/samples/textured_plane_camera.gltf" "$work/textured" "$work/textured/scene.gltf" 2.0 2.0
