#!/usr/bin/env bash
# Specular-glossiness materials through the export and the Blender add-on (docs/export.md, "Blender"): the Cornell
# box sample with every material rewritten as KHR_materials_pbrSpecularGlossiness (its base colour as the diffuse
# factor, no metal-rough fallback; the white one also with a specular-glossiness texture), baked. The export must
# carry no specular-glossiness left, and the Khronos validator must find no error and no warning the input did not
# have (validate.mjs; skipped with a message without node or the gltf-validator module). Then the add-on imports it
# in Blender: every material with MOZ_lightmap wired, and Cycles against irview from the glTF camera within the
# Cornell box's limits of blender_test.sh (EXR ≤ 0.5, PNG ≤ 1; the importer alone ≥ 10). Skips (77) without
# Blender or its numpy.
# Usage (from ctest): spec_gloss_test.sh IRBAKE IRVIEW WORK_DIR MODULES_DIR
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/blender_tests_common.sh"
modules="$4"
"$irbake" samples "$work/samples" --quiet > "$work/samples.log"
# A 4×4 specular-glossiness texture: specular (0.2, 0.3, 0.4), glossiness 0.5 in alpha.
oiiotool --pattern constant:color=0.2,0.3,0.4,0.5 4x4 4 -d uint8 -o "$work/samples/specgloss.png"
python3 - "$work/samples/cornell_box.gltf" "$work/samples/cornell_spec_gloss.gltf" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
doc.setdefault("images", []).append({"uri": "specgloss.png"})
doc.setdefault("textures", []).append({"source": len(doc["images"]) - 1})
for m in doc["materials"]:
    pbr = m.pop("pbrMetallicRoughness", {})
    sg = {"diffuseFactor": pbr.get("baseColorFactor", [1, 1, 1, 1]), "specularFactor": [0.04, 0.04, 0.04],
          "glossinessFactor": 0.3}
    if m.get("name") == "white":
        sg["specularGlossinessTexture"] = {"index": len(doc["textures"]) - 1}
    m.setdefault("extensions", {})["KHR_materials_pbrSpecularGlossiness"] = sg
doc.setdefault("extensionsUsed", []).append("KHR_materials_pbrSpecularGlossiness")
json.dump(doc, open(sys.argv[2], "w"))
PY
"$irbake" bake "$work/samples/cornell_spec_gloss.gltf" -o "$work/bake" --vpls 512 --texels-per-unit 60 --quiet > "$work/bake.log" 2>&1
scene="$work/bake/scene.gltf"
python3 - "$scene" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
text = json.dumps(doc)
assert "KHR_materials_pbrSpecularGlossiness" not in text, "specular-glossiness left in the export"
for m in doc["materials"]:
    ext = m.get("extensions", {})
    assert "KHR_materials_specular" in ext and "KHR_materials_ior" in ext, "material %s not converted" % m.get("name")
print("spec_gloss: %d materials converted to metal-rough" % len(doc["materials"]))
PY
if command -v node >/dev/null 2>&1 && [[ -d "$modules/node_modules/gltf-validator" ]]; then
  node "$here/../web/validate.mjs" --modules "$modules" --output "$scene" --input "$work/samples/cornell_spec_gloss.gltf"
else
  echo "note: node or $modules/node_modules/gltf-validator missing: the validator step is skipped"
fi
w=320 h=320
"$irview" "$scene" --camera 0 --width $w --height $h --screenshot "$work/irview.png" > "$work/irview.log" 2>&1
status=0
blender --background --factory-startup --python "$here/render_compare.py" -- --scene "$scene" \
  --reference "$work/irview.png" --out "$work/blender" --width $w --height $h \
  --max-mean-abs-exr 0.5 --max-mean-abs-png 1.0 --min-control-mean-abs 10 > "$work/blender.log" 2>&1 || status=$?
grep "render_compare" "$work/blender.log" || tail -20 "$work/blender.log"
python3 - "$scene" "$work/blender/results.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
mapped = sorted(m["name"] for m in doc["materials"] if "MOZ_lightmap" in m.get("extensions", {}))
results = json.load(open(sys.argv[2]))
for variant in ("exr", "png"):
    wired = results[variant]["wiredMaterials"]
    if len(wired) != len(mapped):
        raise SystemExit("spec_gloss: %s: the add-on wired %d of %d light-mapped materials (%s)" % (variant, len(wired), len(mapped), wired))
print("spec_gloss: the add-on wired all %d light-mapped materials (EXR and PNG)" % len(mapped))
PY
exit $status
