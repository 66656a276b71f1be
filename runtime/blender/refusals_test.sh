#!/usr/bin/env bash
# The Blender add-on refuses what irview refuses: broken copies of a small Cornell-box bake's MOZ_lightmap (an
# intensity of -1, "NaN", null or 1e39, a texture the file lacks, texCoord 0) each make
# `irbake_lightmap.py SCENE` exit 5 with irview's message naming the material, and irview exits 5 with the same
# message; the map is not wired. A MOZ_lightmap without texCoord (default 1) is wired to TEXCOORD_1 (UV map
# UVMap.001), one without intensity at intensity 1, an older bake's (generator irbake, no units marker) at its
# intensity as written and another tool's (no marker) at intensity / pi (wiring_check.py). Skips (77) without Blender or its numpy.
# Usage (from ctest): refusals_test.sh IRBAKE IRVIEW WORK_DIR
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/blender_tests_common.sh"
"$irbake" samples "$work/samples" --quiet > "$work/samples.log"
"$irbake" bake "$work/samples/cornell_box.gltf" -o "$work/bake" --vpls 64 --texels-per-unit 20 --probes off --quiet \
  > "$work/bake.log" 2>&1
# Writes bake/scene_CASE.gltf for each case and prints "CASE<TAB>expected message" for the refused ones.
python3 - "$work/bake/scene.gltf" > "$work/cases.tsv" <<'PY'
import json, sys
path = sys.argv[1]
doc = json.load(open(path))
m = next(i for i, mat in enumerate(doc["materials"]) if "MOZ_lightmap" in mat.get("extensions", {}))
name = doc["materials"][m].get("name")
what = "material %d%s: MOZ_lightmap" % (m, " ('%s')" % name if name else "")
def variant(case, key, value):
    d = json.loads(json.dumps(doc))
    ext = d["materials"][m]["extensions"]["MOZ_lightmap"]
    if value is KeyError:
        del ext[key]
    else:
        ext[key] = value
    json.dump(d, open(path.replace(".gltf", "_%s.gltf" % case), "w"))
for case, key, value, message in [
        ("intensity_negative", "intensity", -1, "intensity -1 must be a finite number ≥ 0"),
        ("intensity_nan", "intensity", "NaN", 'intensity "NaN" must be a finite number ≥ 0'),
        ("intensity_null", "intensity", None, "intensity null must be a finite number ≥ 0"),
        ("intensity_overflow", "intensity", 1e39, "intensity 1e+39 must be a finite number ≥ 0"),
        ("texture_missing", "index", 99, "names texture 99, which does not exist (the file has %d)" % len(doc["textures"])),
        ("texcoord_zero", "texCoord", 0, "texCoord 0, but light maps use TEXCOORD_1")]:
    variant(case, key, value)
    print("%s\t%s %s" % (case, what, message))
variant("no_texcoord", "texCoord", KeyError)
variant("no_intensity", "intensity", KeyError)
# An older bake: no units marker, its intensity the range of irradiance/pi (the written intensity / pi).
old = json.loads(json.dumps(doc))
ext = old["materials"][m]["extensions"]["MOZ_lightmap"]
del ext["extras"]["irbake"]
ext["intensity"] = ext["intensity"] / 3.141592653589793
json.dump(old, open(path.replace(".gltf", "_unmarked.gltf"), "w"))
# Another tool's file: no marker, generator not irbake, read per MOZ_lightmap's specification.
other = json.loads(json.dumps(doc))
del other["materials"][m]["extensions"]["MOZ_lightmap"]["extras"]["irbake"]
other["asset"]["generator"] = "another exporter"
json.dump(other, open(path.replace(".gltf", "_other_tool.gltf"), "w"))
PY
failures=0
while IFS=$'\t' read -r case message; do
  scene="$work/bake/scene_$case.gltf"
  status=0
  blender --background --factory-startup --python "$here/irbake_lightmap.py" -- "$scene" --empty \
    > "$work/blender_$case.log" 2>&1 || status=$?
  view_status=0
  "$irview" "$scene" --width 16 --height 16 --screenshot "$work/irview_$case.png" > "$work/irview_$case.log" 2>&1 \
    || view_status=$?
  for client in blender irview; do
    s=$([[ $client == blender ]] && echo $status || echo $view_status)
    if [[ $s -ne 5 ]] || ! grep -qF "$message" "$work/${client}_$case.log"; then
      echo "$client $case: exit $s, expected 5 and '$message':"; tail -5 "$work/${client}_$case.log"; failures=$((failures + 1))
    else
      echo "$client $case: refused (exit 5): $message"
    fi
  done
done < "$work/cases.tsv"
blender --background --factory-startup --python "$here/wiring_check.py" -- "$work/bake/scene.gltf" \
  "$work/bake/scene_no_texcoord.gltf" "$work/bake/scene_no_intensity.gltf" "$work/bake/scene_intensity_negative.gltf" "$work/bake/scene_unmarked.gltf" \
  "$work/bake/scene_other_tool.gltf" \
  > "$work/wiring.log" 2>&1 || { echo "wiring_check failed:"; tail -20 "$work/wiring.log"; failures=$((failures + 1)); }
grep "wiring_check" "$work/wiring.log" || true
[[ $failures -eq 0 ]]
