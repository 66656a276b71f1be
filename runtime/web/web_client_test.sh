#!/usr/bin/env bash
# Real-client test: bake the Cornell box, render it from its glTF camera with irview and
# with three.js in headless Chromium (runtime/web), and require a mean absolute difference ≤ 2 (8-bit).
# Then an older bake's copy of it (MOZ_lightmap without the units marker, intensity × texel = irradiance/π): three.js
# must show it as irview shows the bake (≤ 2), and irview must read its PNG as it reads the marked one's (the float
# pages left out of both; mean absolute difference ≤ 0.5). Another tool's copy (generator not irbake, no marker,
# the intensity as written) is read per MOZ_lightmap's specification: the same two checks.
# Usage (from ctest): web_client_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_browser_client "$modules" "$work"
bake_cornell_and_irview "$irbake" "$irview" "$work"
node "$here/render_compare.mjs" --modules "$modules" --scene "$work/bake/scene.gltf" --camera 0 --width $w --height $h \
  --reference "$work/irview.png" --out "$work/web.png" --max-mean-abs 2
python3 - "$work/bake/scene.gltf" <<'PY'
import json, math, sys
path = sys.argv[1]
doc = json.load(open(path))
def write(name, d):
    json.dump(d, open(path.replace(".gltf", "_%s.gltf" % name), "w"))
older = json.loads(json.dumps(doc))
for m in older["materials"]:
    ext = m.get("extensions", {}).get("MOZ_lightmap")
    if ext:
        del ext["extras"]["irbake"]
        ext["intensity"] = ext["intensity"] / math.pi
write("older", older)
other = json.loads(json.dumps(doc))  # another tool's: no marker, intensity as the specification says
other["asset"]["generator"] = "another exporter"
for m in other["materials"]:
    ext = m.get("extensions", {}).get("MOZ_lightmap")
    if ext:
        del ext["extras"]["irbake"]
write("other_tool", other)
for name, d in [("png", doc), ("older_png", older), ("other_tool_png", other)]:
    d = json.loads(json.dumps(d))
    del d["extras"]["lightmapPages"]
    write(name, d)
PY
node "$here/render_compare.mjs" --modules "$modules" --scene "$work/bake/scene_older.gltf" --camera 0 --width $w --height $h \
  --reference "$work/irview.png" --out "$work/web_older.png" --max-mean-abs 2
node "$here/render_compare.mjs" --modules "$modules" --scene "$work/bake/scene_other_tool.gltf" --camera 0 --width $w \
  --height $h --reference "$work/irview.png" --out "$work/web_other_tool.png" --max-mean-abs 2
for name in png older_png other_tool_png; do
  "$irview" "$work/bake/scene_$name.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview_$name.png" \
    > "$work/irview_$name.log" 2>&1
done
for name in older_png other_tool_png; do
  diff=$(oiiotool "$work/irview_png.png" "$work/irview_$name.png" --diff --fail 1 --hardfail 1 2>&1 || true)
  mean=$(awk '/Mean error/ { print $4 }' <<< "$diff")
  [[ -z "$mean" ]] && grep -qx "PASS" <<< "$diff" && mean=0  # identical images: oiiotool prints no figures
  echo "irview, PNG of the bake against $name: mean absolute difference ${mean:-?} (of 1)"
  awk -v m="${mean:-1}" 'BEGIN { exit !(m * 255 <= 0.5) }' || { echo "irview reads $name differently: $diff"; exit 1; }
done
