#!/usr/bin/env bash
# MOZ_lightmap read from its specification alone: bake the Cornell box, render it from its glTF camera with irview
# and with three.js in headless Chromium through spec_reader.html (plain GLTFLoader, material.lightMap from the
# extension's texture, lightMap.channel = 1, lightMapIntensity = intensity, none of irbake's plugins), with the
# loader's MeshStandardMaterial and with Lambert, and require a mean absolute difference ≤ 2 (8-bit) for each.
# Then the specification's unlit rule, colour = baseColor × lightmapLinear × intensity: the bake's light-mapped
# materials without emission made unlit (KHR_materials_unlit) with the intensity an exporter writes for them
# (without the PBR π), read by the same page (GLTFLoader's MeshBasicMaterial with the light map), ≤ 2 against
# irview; and the portable GLB (--portable: what our unlit output holds) rendered by plain three.js, ≤ 2 against
# that unlit render.
# Then the same on Sponza (../shared/scenes) baked with --sun and --sky, seen from bench/cycles/scenes.py's
# overview camera (320 × 200); that part is skipped with a message when the scene is absent.
# Usage (from ctest): web_spec_reader_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_browser_client "$modules" "$work"
bake_cornell_and_irview "$irbake" "$irview" "$work" --portable
for standard in 1 0; do
  node "$here/render_compare.mjs" --modules "$modules" --client spec --standard $standard --scene "$work/bake/scene.gltf" \
    --camera 0 --width $w --height $h --reference "$work/irview.png" --out "$work/spec_$standard.png" --max-mean-abs 2
done
python3 - "$work/bake/scene.gltf" "$work/bake/scene_unlit.gltf" <<'PY'
import json, math, sys
doc = json.load(open(sys.argv[1]))
unlit = 0
for m in doc.get("materials", []):
    ext = m.setdefault("extensions", {})
    if "MOZ_lightmap" not in ext or any(m.get("emissiveFactor", [0, 0, 0])):
        continue  # an emitter keeps its PBR material: the unlit rule has no emission
    ext["KHR_materials_unlit"] = {}
    ext["MOZ_lightmap"]["intensity"] = ext["MOZ_lightmap"].get("intensity", 1.0) / math.pi
    unlit += 1
if unlit == 0:
    sys.exit("no light-mapped material without emission to make unlit")
doc["extensionsUsed"] = sorted(set(doc.get("extensionsUsed", [])) | {"KHR_materials_unlit"})
json.dump(doc, open(sys.argv[2], "w"))
print(f"{unlit} materials made unlit")
PY
node "$here/render_compare.mjs" --modules "$modules" --client spec --scene "$work/bake/scene_unlit.gltf" \
  --camera 0 --width $w --height $h --reference "$work/irview.png" --out "$work/spec_unlit.png" --max-mean-abs 2
node "$here/render_compare.mjs" --modules "$modules" --plugin none --scene "$work/bake/portable.glb" \
  --camera 0 --width $w --height $h --reference "$work/spec_unlit.png" --out "$work/portable_vs_unlit.png" --max-mean-abs 2
src="$(cd "$here/../.." && pwd)"
sponza="$src/../shared/scenes/dabrovic_sponza/sponza.glb"
if [[ ! -f "$sponza" ]]; then echo "Sponza part skipped: $sponza absent"; exit 0; fi
"$irbake" bake "$sponza" -o "$work/sponza" --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7 --quiet > "$work/sponza.log" 2>&1
w=320 h=200
python3 "$src/bench/cycles/add_sponza_camera.py" "$work/sponza/scene.gltf" "$w" "$h"
"$irview" "$work/sponza/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/sponza_irview.png" \
  > "$work/sponza_irview.log" 2>&1
for standard in 1 0; do
  node "$here/render_compare.mjs" --modules "$modules" --client spec --standard $standard --scene "$work/sponza/scene.gltf" \
    --camera 0 --width $w --height $h --reference "$work/sponza_irview.png" --out "$work/sponza_spec_$standard.png" \
    --max-mean-abs 2
done
