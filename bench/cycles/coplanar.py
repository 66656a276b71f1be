#!/usr/bin/python3
"""Coincident triangles in a level: find them, and drop those another triangle already covers.

Why: where two triangles lie in the same plane, facing the same way, one on top of the other (Sibenik's pulpit
carpet and gallery floors, about 21 m^2), Cycles shades the overlap black. Every ray that leaves one triangle
hits its twin at distance ~0 (Cycles skips only the primitive it starts on), so the direct light is shadowed and
each bounce lands on the twin again. irbake offsets its rays and sees one lit surface, which is what a level
artist means by it. A reference that renders the overlap black is wrong there, and the light that should
bounce off it is missing around it (docs/accuracy.md, session 19). The bench scenes drop, from each plane, the
triangles whose whole area earlier triangles of the same plane already cover: the surface stays where it was,
once. Partial overlaps are kept and counted.

Used by scenes.py (numpy; the rest of scenes.py is standard library). Also a tool:
  /usr/bin/python3 bench/cycles/coplanar.py SCENE.glb|.gltf     -> prints the coincident area, changes nothing
"""
import json
import os
import struct
import sys

import numpy as np

COMPONENT = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
PLANE_TOL = 1e-5   # metres and normal components: planes that agree to this are one (a 0.1 mm gap is not)
COVERED = 0.98     # a triangle is dropped when this share of its sample points lies inside earlier ones
LATTICE = 8        # sample points: the centres of an 8x8 barycentric lattice (36 points), no randomness


def read_accessor(doc, binchunk, i):
    a = doc["accessors"][i]
    bv = doc["bufferViews"][a["bufferView"]]
    dt = np.dtype(COMPONENT[a["componentType"]])
    n = WIDTH[a["type"]]
    off = bv.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = bv.get("byteStride", dt.itemsize * n)
    raw = np.frombuffer(binchunk, np.uint8, stride * (a["count"] - 1) + dt.itemsize * n, off)
    rows = np.lib.stride_tricks.as_strided(raw, (a["count"], dt.itemsize * n), (stride, 1))
    return np.ascontiguousarray(rows).view(dt).reshape(a["count"], n)


def node_matrices(doc):
    """World matrix of every node reached from the default scene (node index -> list of 4x4)."""
    out = {}

    def local(n):
        if "matrix" in n:
            return np.array(n["matrix"], np.float64).reshape(4, 4).T
        x, y, z, w = n.get("rotation", [0.0, 0.0, 0.0, 1.0])
        r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                      [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                      [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
        m = np.eye(4)
        m[:3, :3] = r @ np.diag(n.get("scale", [1.0, 1.0, 1.0]))
        m[:3, 3] = n.get("translation", [0.0, 0.0, 0.0])
        return m

    def walk(i, parent):
        m = parent @ local(doc["nodes"][i])
        out.setdefault(i, []).append(m)
        for c in doc["nodes"][i].get("children", []):
            walk(c, m)

    for r in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        walk(r, np.eye(4))
    return out


def world_triangles(doc, binchunk):
    """[(mesh, primitive, indices (n,3), triangles (n,3,3) in world space)] for meshes placed exactly once;
    a mesh placed by several nodes is left alone (dropping its triangles would change every placement)."""
    placed = {}
    for i, ms in node_matrices(doc).items():
        mesh = doc["nodes"][i].get("mesh")
        if mesh is not None:
            placed.setdefault(mesh, []).extend(ms)
    out = []
    for mesh, ms in sorted(placed.items()):
        if len(ms) != 1:
            continue
        for p, prim in enumerate(doc["meshes"][mesh]["primitives"]):
            if prim.get("mode", 4) != 4 or "indices" not in prim:
                continue
            pos = read_accessor(doc, binchunk, prim["attributes"]["POSITION"]).astype(np.float64)
            pos = pos @ ms[0][:3, :3].T + ms[0][:3, 3]
            idx = read_accessor(doc, binchunk, prim["indices"]).reshape(-1, 3).astype(np.int64)
            out.append((mesh, p, idx, pos[idx]))
    return out


def lattice():
    k = LATTICE
    pts = [((i + 1.0 / 3) / k, (j + 1.0 / 3) / k) for i in range(k) for j in range(k - i)]
    pts += [((i + 2.0 / 3) / k, (j + 2.0 / 3) / k) for i in range(k) for j in range(k - i - 1)]
    return np.array(pts)


def coincident(tris):
    """For triangles (n,3,3): a drop flag per triangle (covered by earlier ones in its plane) and the area of
    the partial overlaps that stay (m^2, estimated on the sample points)."""
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    nrm = np.cross(e1, e2)
    area = 0.5 * np.linalg.norm(nrm, axis=1)
    ok = area > 1e-10
    nrm[ok] /= (2 * area[ok])[:, None]
    off = (nrm * tris[:, 0]).sum(axis=1)
    key = np.round(np.column_stack([nrm, off]) / PLANE_TOL).astype(np.int64)
    drop = np.zeros(len(tris), bool)
    partial = 0.0
    uv = lattice()
    order = np.lexsort(key.T[::-1])
    ks = key[order]
    starts = np.flatnonzero(np.r_[True, np.any(ks[1:] != ks[:-1], axis=1)])
    ends = np.r_[starts[1:], len(order)]
    for s, e in zip(starts, ends):
        if e - s < 2:
            continue
        ids = np.sort(order[s:e])
        ids = ids[ok[ids]]
        if len(ids) < 2:
            continue
        lo, hi = tris[ids].min(axis=1) - PLANE_TOL, tris[ids].max(axis=1) + PLANE_TOL
        n = nrm[ids[0]]
        kept = []
        for a, j in enumerate(ids):
            cand = [b for b in kept if np.all(lo[b] <= hi[a]) and np.all(hi[b] >= lo[a])]
            if cand:
                pts = tris[j, 0] + uv[:, :1] * e1[j] + uv[:, 1:] * e2[j]
                c = tris[ids[cand]]                                             # (k,3,3)
                inside = np.ones((len(cand), len(pts)), bool)
                for v in range(3):
                    edge = c[:, (v + 1) % 3] - c[:, v]                          # (k,3)
                    rel = pts[None, :, :] - c[:, v][:, None, :]                 # (k,p,3)
                    inside &= (np.cross(edge[:, None, :], rel) @ n) >= -1e-9
                share = inside.any(axis=0).mean()
                if share >= COVERED:
                    drop[j] = True
                    continue
                partial += share * area[j]
            kept.append(a)
    return drop, partial, area


def drop_covered(doc, binchunk):
    """Rewrite the index buffers without the covered triangles; returns (binchunk, dropped, dropped m^2,
    partial overlap m^2 left)."""
    prims = world_triangles(doc, binchunk)
    if not prims:
        return binchunk, 0, 0.0, 0.0
    tris = np.concatenate([t for _, _, _, t in prims])
    drop, partial, area = coincident(tris)
    out = bytearray(binchunk)
    first = 0
    for mesh, p, idx, t in prims:
        d = drop[first:first + len(idx)]
        first += len(idx)
        if not d.any():
            continue
        keep = idx[~d].astype(np.uint32).ravel()
        out += b"\0" * ((4 - len(out) % 4) % 4)
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(out), "byteLength": keep.nbytes,
                                   "target": 34963})
        out += keep.tobytes()
        doc["accessors"].append({"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5125,
                                 "count": int(keep.size), "type": "SCALAR"})
        doc["meshes"][mesh]["primitives"][p]["indices"] = len(doc["accessors"]) - 1
    doc["buffers"][0]["byteLength"] = len(out)
    return bytes(out), int(drop.sum()), float(area[drop].sum()), partial


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    if path.endswith(".glb"):
        data = open(path, "rb").read()
        jl = struct.unpack("<I", data[12:16])[0]
        doc = json.loads(data[20:20 + jl])
        binchunk = data[20 + jl + 8:]
    else:
        doc = json.load(open(path))
        binchunk = open(os.path.join(os.path.dirname(path), doc["buffers"][0]["uri"]), "rb").read()
    prims = world_triangles(doc, binchunk)
    tris = np.concatenate([t for _, _, _, t in prims])
    drop, partial, area = coincident(tris)
    print("%s: %d triangles, %d covered by earlier coincident ones (%.2f m^2), partial overlaps %.2f m^2"
          % (path, len(tris), drop.sum(), area[drop].sum(), partial))


if __name__ == "__main__":
    main()
