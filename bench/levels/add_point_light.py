#!/usr/bin/env python3
"""Writes a copy of a GLB with KHR_lights_punctual point lights added (for bakes of third-party levels that
ship without lights, e.g. ../shared/scenes/sibenik: sky through the windows plus one interior lamp).
Usage: add_point_light.py IN.glb OUT.glb X,Y,Z[;X,Y,Z...] INTENSITY_CD [R,G,B]   (glTF units: metres, candela)
One position: the light is named "interior lamp"; several: "lamp 0", "lamp 1", ..."""
import json
import struct
import sys


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    src, dst = sys.argv[1], sys.argv[2]
    positions = [[float(v) for v in p.split(",")] for p in sys.argv[3].split(";") if p.strip()]
    intensity = float(sys.argv[4])
    color = [float(v) for v in sys.argv[5].split(",")] if len(sys.argv) > 5 else [1.0, 1.0, 1.0]
    data = open(src, "rb").read()
    magic, version, length = struct.unpack_from("<III", data, 0)
    if magic != 0x46546C67:
        sys.exit("%s: not a GLB" % src)
    jlen, jtype = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20:20 + jlen])
    rest = data[20 + jlen:]  # the BIN chunk, unchanged
    ext = doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {})
    lights = ext.setdefault("lights", [])
    for i, pos in enumerate(positions):
        name = "interior lamp" if len(positions) == 1 else "lamp %d" % i
        lights.append({"type": "point", "intensity": intensity, "color": color, "name": name})
        doc.setdefault("nodes", []).append({"name": name, "translation": pos,
                                            "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}})
        doc["scenes"][doc.get("scene", 0)].setdefault("nodes", []).append(len(doc["nodes"]) - 1)
    used = doc.setdefault("extensionsUsed", [])
    if "KHR_lights_punctual" not in used:
        used.append("KHR_lights_punctual")
    j = json.dumps(doc, separators=(",", ":")).encode()
    j += b" " * ((4 - len(j) % 4) % 4)
    out = struct.pack("<III", magic, version, 12 + 8 + len(j) + len(rest)) + struct.pack("<II", len(j), jtype) + j + rest
    with open(dst + ".tmp", "wb") as f:
        f.write(out)
    import os
    os.replace(dst + ".tmp", dst)


if __name__ == "__main__":
    main()
