# How irbake_lightmap.py wires one material's MOZ_lightmap (the first material that has one), read from the node
# tree after an import of the PNG pages: the UV map its image node reads and the scale to irradiance/pi it
# multiplies by. The scenes given: the bake as written (TEXCOORD_1, intensity / pi: the units marker says
# intensity x texel is the irradiance), a copy without texCoord (MOZ_lightmap's default set 1: UVMap.001), one
# without intensity (1 / pi), one with intensity -1 (refused: the material left as imported, one refusal
# recorded), an older bake's without the marker (generator irbake: its intensity as written), and another tool's
# without the marker (MOZ_lightmap's own rule: intensity / pi). Exits 1 naming what differs.
#   blender --background --factory-startup --python wiring_check.py -- BAKE.gltf NO_TEXCOORD.gltf NO_INTENSITY.gltf NEGATIVE.gltf UNMARKED.gltf OTHER_TOOL.gltf
import json
import math
import os
import sys

import bpy

sys.dont_write_bytecode = True  # no __pycache__ in the source folder: tests write only under build/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import irbake_lightmap  # noqa: E402  (the add-on beside this file)


def wiring(scene):
    """(glTF material name, {"uv_map", "intensity"} or None when not wired, refusals) after importing scene."""
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    for material in list(bpy.data.materials):
        bpy.data.materials.remove(material)
    doc = json.load(open(scene))
    name = next(m["name"] for m in doc["materials"] if "MOZ_lightmap" in m.get("extensions", {}))
    if irbake_lightmap.import_gltf(os.path.abspath(scene), prefer_exr=False) != {"FINISHED"}:
        raise SystemExit("wiring_check: %s: the import failed" % scene)
    material = next(m for m in bpy.data.materials if m.name == name or m.name.startswith(name + "."))
    refused = list(getattr(irbake_lightmap, "refusals", []))  # an add-on without the list refuses nothing
    if "irbake_lightmap" not in material:
        return name, None, refused
    nodes = material.node_tree.nodes
    uv = next(n for n in nodes if n.type == "UVMAP")
    scale = next(n for n in nodes if n.label == "light-map intensity")
    return name, {"uv_map": uv.uv_map, "intensity": scale.inputs["Scale"].default_value}, refused


arguments = sys.argv[sys.argv.index("--") + 1:]
baked, no_texcoord, no_intensity, negative, unmarked, other_tool = arguments


def first_intensity(scene):
    doc = json.load(open(scene))
    return next(m["extensions"]["MOZ_lightmap"]["intensity"] for m in doc["materials"]
                if "MOZ_lightmap" in m.get("extensions", {}))


intensity = first_intensity(baked)
expected = [(baked, {"uv_map": "UVMap.001", "intensity": intensity / math.pi}),
            (no_texcoord, {"uv_map": "UVMap.001", "intensity": intensity / math.pi}),
            (no_intensity, {"uv_map": "UVMap.001", "intensity": 1.0 / math.pi}),
            (negative, None),
            (unmarked, {"uv_map": "UVMap.001", "intensity": first_intensity(unmarked)}),
            (other_tool, {"uv_map": "UVMap.001", "intensity": first_intensity(other_tool) / math.pi})]
errors = []
for scene, want in expected:
    name, got, refused = wiring(scene)
    if got is not None and want is not None:
        same = got["uv_map"] == want["uv_map"] and abs(got["intensity"] - want["intensity"]) <= 1e-6 * max(1.0, want["intensity"])
    else:
        same = got == want and len(refused) == 1
    print("wiring_check: %s: material %r: %s%s" % (os.path.basename(scene), name, got or "not wired",
                                                  ", refused: %s" % refused[0] if refused else ""))
    if not same:
        errors.append("%s: got %s, expected %s" % (os.path.basename(scene), got, want or "not wired, one refusal"))
for e in errors:
    print("wiring_check: " + e)
sys.exit(1 if errors else 0)
