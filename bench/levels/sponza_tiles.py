#!/usr/bin/env python3
"""sponza_tiles.py IN.glb OUT.glb [--n 3] [--gap G]: an n x n tiling of a GLB scene through nodes.

The default scene's node hierarchy is repeated n*n times under one node per tile, each tile offset on the
ground plane (x, z; +Y up) by the scene's bounding box plus a gap. Meshes, materials, images, textures and the
binary chunk are shared, not copied: the output differs from the input only in its nodes and scenes. Images
the input names by relative URI are reached through a symbolic link beside the output (first path component,
e.g. `textures/`), so nothing third-party is copied.

  python3 bench/levels/sponza_tiles.py ../shared/scenes/dabrovic_sponza/sponza.glb build/levels/sponza3x3.glb
"""
import argparse
import json
import os
import struct

GLB_MAGIC, CHUNK_JSON, CHUNK_BIN = 0x46546C67, 0x4E4F534A, 0x004E4942


def read_glb(path):
    data = open(path, "rb").read()
    magic, version, _ = struct.unpack_from("<III", data, 0)
    if magic != GLB_MAGIC or version != 2:
        raise SystemExit("sponza_tiles: %s is not a GLB 2.0 file" % path)
    doc, binary, at = None, None, 12
    while at < len(data):
        length, kind = struct.unpack_from("<II", data, at)
        chunk = data[at + 8:at + 8 + length]
        if kind == CHUNK_JSON:
            doc = json.loads(chunk)
        elif kind == CHUNK_BIN:
            binary = chunk
        at += 8 + length
    if doc is None:
        raise SystemExit("sponza_tiles: %s has no JSON chunk" % path)
    return doc, binary


def write_glb(path, doc, binary):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), CHUNK_JSON) + text
    if binary is not None:
        binary = binary + b"\0" * (-len(binary) % 4)
        chunks += struct.pack("<II", len(binary), CHUNK_BIN) + binary
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(struct.pack("<III", GLB_MAGIC, 2, 12 + len(chunks)) + chunks)
    os.replace(tmp, path)


def mat_mul(a, b):
    """4x4 column-major product a * b."""
    return [sum(a[k * 4 + r] * b[c * 4 + k] for k in range(4)) for c in range(4) for r in range(4)]


def local_matrix(node):
    if "matrix" in node:
        return list(node["matrix"])
    t = node.get("translation", [0, 0, 0])
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    s = node.get("scale", [1, 1, 1])
    r = [1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
         2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
         2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)]
    return [r[0] * s[0], r[1] * s[0], r[2] * s[0], 0, r[3] * s[1], r[4] * s[1], r[5] * s[1], 0,
            r[6] * s[2], r[7] * s[2], r[8] * s[2], 0, t[0], t[1], t[2], 1]


def scene_bounds(doc, roots):
    """World-space box of every mesh's POSITION min/max corners under the given root nodes."""
    lo, hi = [float("inf")] * 3, [float("-inf")] * 3
    identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    stack = [(n, identity) for n in roots]
    while stack:
        index, parent = stack.pop()
        node = doc["nodes"][index]
        world = mat_mul(parent, local_matrix(node))
        if "mesh" in node:
            for prim in doc["meshes"][node["mesh"]]["primitives"]:
                acc = doc["accessors"][prim["attributes"]["POSITION"]]
                a, b = acc["min"], acc["max"]
                for cx in (a[0], b[0]):
                    for cy in (a[1], b[1]):
                        for cz in (a[2], b[2]):
                            p = [world[r] * cx + world[4 + r] * cy + world[8 + r] * cz + world[12 + r] for r in range(3)]
                            lo = [min(lo[k], p[k]) for k in range(3)]
                            hi = [max(hi[k], p[k]) for k in range(3)]
        stack.extend((c, world) for c in node.get("children", []))
    return lo, hi


def triangle_count(doc, roots):
    count, stack = 0, list(roots)
    while stack:
        node = doc["nodes"][stack.pop()]
        if "mesh" in node:
            for prim in doc["meshes"][node["mesh"]]["primitives"]:
                if "indices" in prim:
                    count += doc["accessors"][prim["indices"]]["count"] // 3
                else:
                    count += doc["accessors"][prim["attributes"]["POSITION"]]["count"] // 3
        stack.extend(node.get("children", []))
    return count


def tile(doc, n, gap):
    """Repeats the default scene's hierarchy n*n times; returns the new document and the tile pitch."""
    scene = doc["scenes"][doc.get("scene", 0)]
    roots = scene["nodes"]
    lo, hi = scene_bounds(doc, roots)
    if gap is None:
        gap = 0.1 * max(hi[0] - lo[0], hi[2] - lo[2])
    pitch = (hi[0] - lo[0] + gap, hi[2] - lo[2] + gap)
    source = doc["nodes"]
    nodes, tiles = [], []
    for i in range(n):
        for j in range(n):
            base = len(nodes) + 1  # the tile node comes first, its copy of the hierarchy after it
            remap = lambda k: base + k
            tile_node = {"name": "tile_%d_%d" % (i, j), "translation": [i * pitch[0], 0.0, j * pitch[1]],
                         "children": [remap(r) for r in roots]}
            nodes.append(tile_node)
            for node in source:
                copy = dict(node)
                if "children" in node:
                    copy["children"] = [remap(c) for c in node["children"]]
                nodes.append(copy)
            tiles.append(len(nodes) - len(source) - 1)
    out = dict(doc)
    out["nodes"] = nodes
    out["scenes"] = [{"name": "tiles_%dx%d" % (n, n), "nodes": tiles}]
    out["scene"] = 0
    return out, pitch


def link_resources(doc, src, dst):
    """Symbolic links beside the output to the folders the input's relative image and buffer URIs start in."""
    src_dir, dst_dir = os.path.dirname(os.path.abspath(src)), os.path.dirname(os.path.abspath(dst))
    if src_dir == dst_dir:
        return
    heads = set()
    for item in doc.get("images", []) + doc.get("buffers", []):
        uri = item.get("uri", "")
        if uri and not uri.startswith("data:") and "://" not in uri and not os.path.isabs(uri):
            heads.add(uri.split("/")[0])
    for head in sorted(heads):
        target, link = os.path.join(src_dir, head), os.path.join(dst_dir, head)
        if os.path.islink(link):
            os.remove(link)
        if not os.path.exists(link):
            os.symlink(os.path.realpath(target), link)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("input", help="input .glb")
    ap.add_argument("output", help="output .glb")
    ap.add_argument("--n", type=int, default=3, help="tiles per side (default 3)")
    ap.add_argument("--gap", type=float, default=None, help="gap between tiles in scene units (default: 10%% "
                    "of the larger horizontal extent)")
    args = ap.parse_args()
    if args.n < 1:
        raise SystemExit("sponza_tiles: --n must be at least 1")
    doc, binary = read_glb(args.input)
    out, pitch = tile(doc, args.n, args.gap)
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    write_glb(args.output, out, binary)
    link_resources(doc, args.input, args.output)
    tris = triangle_count(out, out["scenes"][0]["nodes"])
    print("%s: %dx%d tiles, pitch %.2f x %.2f, %d triangles, %d nodes" %
          (args.output, args.n, args.n, pitch[0], pitch[1], tris, len(out["nodes"])))


if __name__ == "__main__":
    main()
