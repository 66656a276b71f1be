#!/usr/bin/env python3
"""grid_scene.py N OUT.gltf [SIZE]: a flat SIZE x SIZE m grid (default 100) of N x N quads (2 N^2
triangles) on y = 0 with per-vertex normals, a white Lambertian material, and a point light 20 m
above its centre; written as OUT.gltf + OUT.bin. The memory bench's "many triangles, few texels"
scene: one planar chart, so the atlas costs little and the peak follows the triangle count."""
import array
import json
import os
import sys


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    n = int(sys.argv[1])
    out = sys.argv[2]
    size = float(sys.argv[3]) if len(sys.argv) == 4 else 100.0
    verts = (n + 1) * (n + 1)
    pos = array.array("f")
    step = size / n
    for j in range(n + 1):
        z = -size / 2 + j * step
        row = []
        for i in range(n + 1):
            row += (-size / 2 + i * step, 0.0, z)
        pos.extend(row)
    nrm = array.array("f", (0.0, 1.0, 0.0)) * verts
    idx = array.array("I")
    for j in range(n):
        row = []
        a0 = j * (n + 1)
        for i in range(n):
            a, b = a0 + i, a0 + i + 1
            c, d = a + n + 1, b + n + 1
            row += (a, c, b, b, c, d)  # counter-clockwise seen from +y
        idx.extend(row)
    blobs = [pos.tobytes(), nrm.tobytes(), idx.tobytes()]
    views, offset = [], 0
    for k, blob in enumerate(blobs):
        view = {"buffer": 0, "byteOffset": offset, "byteLength": len(blob)}
        view["target"] = 34963 if k == 2 else 34962
        views.append(view)
        offset += len(blob)
    bin_name = os.path.splitext(os.path.basename(out))[0] + ".bin"
    half = size / 2
    doc = {
        "asset": {"version": "2.0", "generator": "irbake bench/memory/grid_scene.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"translation": [0, 20, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 20000.0}]}},
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": verts, "type": "VEC3",
             "min": [-half, 0.0, -half], "max": [half, 0.0, half]},
            {"bufferView": 1, "componentType": 5126, "count": verts, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": 6 * n * n, "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"uri": bin_name, "byteLength": offset}],
    }
    with open(os.path.join(os.path.dirname(out) or ".", bin_name), "wb") as f:
        for blob in blobs:
            f.write(blob)
    with open(out, "w") as f:
        json.dump(doc, f)
    print(f"{out}: {2 * n * n} triangles, {verts} vertices, {offset} bytes of buffer")


if __name__ == "__main__":
    main()
