#!/usr/bin/python3
"""Coincident triangles in a level: find them; drop those earlier ones cover, cut those partly covered.

Why: where two triangles lie in the same plane, facing the same way, one on top of the other (Sibenik's pulpit
carpet and gallery floors, about 21 m^2), Cycles shades the overlap black. Every ray that leaves one triangle
hits its twin at distance ~0 (Cycles skips only the primitive it starts on), so the direct light is shadowed and
each bounce lands on the twin again. irbake offsets its rays and sees one lit surface, which is what a level
artist means by it. A reference that renders the overlap black is wrong there, and the light that should
bounce off it is missing around it (docs/validation.md, "Sibenik"). The bench scenes keep, in each plane, the
first triangle over any spot: later triangles that earlier ones cover are dropped, those partly covered are cut
to their uncovered rest (convex pieces, fan-triangulated, new vertices interpolated). The surface stays where it
was, once.

Used by scenes.py (numpy; the rest of scenes.py is standard library). Also a tool:
  /usr/bin/python3 bench/cycles/coplanar.py SCENE.glb|.gltf     -> prints the coincident area, changes nothing
"""
import json
import os
import sys

import numpy as np

COMPONENT = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
PLANE_TOL = 1e-5   # metres and normal components: planes that agree to this are one (a 0.1 mm gap is not)
COVERED = 0.98     # a triangle is dropped when earlier ones cover this share of its area


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


def _clip(poly, a, b, keep_left):
    """The part of a convex 2D polygon (list of points) left (or right) of the line a->b."""
    out = []
    d = [((b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0])) * (1 if keep_left else -1) for q in poly]
    for i, q in enumerate(poly):
        r, dq, dr = poly[(i + 1) % len(poly)], d[i], d[(i + 1) % len(poly)]
        if dq >= 0:
            out.append(q)
        if (dq >= 0) != (dr >= 0):
            t = dq / (dq - dr)
            out.append((q[0] + t * (r[0] - q[0]), q[1] + t * (r[1] - q[1])))
    return out


def _area(poly):
    n = len(poly)
    return 0.5 * abs(sum(poly[i][0] * poly[(i + 1) % n][1] - poly[(i + 1) % n][0] * poly[i][1]
                         for i in range(n))) if n > 2 else 0.0


def _subtract(poly, tri, tol):
    """Convex polygon minus a triangle (both 2D): the polygon itself where they share less than tol of area
    (neighbours that only touch must not cut it up), else up to three convex pieces, one per edge."""
    ccw = (tri[1][0] - tri[0][0]) * (tri[2][1] - tri[0][1]) - (tri[1][1] - tri[0][1]) * (tri[2][0] - tri[0][0]) > 0
    inside = poly
    for v in range(3):
        inside = _clip(inside, tri[v], tri[(v + 1) % 3], ccw)
        if len(inside) < 3:
            return [poly]
    if _area(inside) <= tol:
        return [poly]
    pieces, rest = [], poly
    for v in range(3):
        a, b = tri[v], tri[(v + 1) % 3]
        outside = _clip(rest, a, b, not ccw)
        if _area(outside) > tol:
            pieces.append(outside)
        rest = _clip(rest, a, b, ccw)
        if _area(rest) <= tol:
            break
    return pieces


def coincident(tris):
    """For triangles (n,3,3) in world space, earlier ones first: which to drop (earlier triangles of the same
    plane, facing the same way, cover it) and, for those partly covered, the uncovered rest as triangles in
    barycentric coordinates of the original (a dict index -> (k,3,3) weights). Returns (drop, rest, area)."""
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    nrm = np.cross(e1, e2)
    area = 0.5 * np.linalg.norm(nrm, axis=1)
    ok = area > 1e-10
    nrm[ok] /= (2 * area[ok])[:, None]
    off = (nrm * tris[:, 0]).sum(axis=1)
    key = np.round(np.column_stack([nrm, off]) / PLANE_TOL).astype(np.int64)
    drop = np.zeros(len(tris), bool)
    rest = {}
    order = np.lexsort(key.T[::-1])
    ks = key[order]
    starts = np.flatnonzero(np.r_[True, np.any(ks[1:] != ks[:-1], axis=1)])
    ends = np.r_[starts[1:], len(order)]
    for s, e in zip(starts, ends):
        ids = np.sort(order[s:e])
        ids = ids[ok[ids]]
        if len(ids) < 2:
            continue
        ax = [k for k in range(3) if k != int(np.argmax(np.abs(nrm[ids[0]])))]  # the plane seen along its normal
        t2 = tris[ids][:, :, ax]                                                    # (m,3,2)
        lo, hi = t2.min(axis=1) - PLANE_TOL, t2.max(axis=1) + PLANE_TOL
        kept = []                                                                   # 2D triangles already there
        klo, khi = np.empty((0, 2)), np.empty((0, 2))
        for a, j in enumerate(ids):
            if len(kept) != len(klo):                                               # bounds of the new ones
                new = np.array(kept[len(klo):])
                klo, khi = np.vstack([klo, new.min(axis=1)]), np.vstack([khi, new.max(axis=1)])
            tri = [tuple(v) for v in t2[a]]
            whole = _area(tri)
            tol = 1e-6 * whole
            polys = [tri]
            for q in np.flatnonzero(np.all(klo <= hi[a], axis=1) & np.all(khi >= lo[a], axis=1)):
                polys = [piece for poly in polys for piece in _subtract(poly, [tuple(v) for v in kept[q]], tol)]
                if not polys:
                    break
            left = sum(_area(poly) for poly in polys) / max(whole, 1e-30)
            if left <= 1.0 - COVERED:
                drop[j] = True
                continue
            if left >= 1.0 - 1e-4:
                kept.append(t2[a])
                continue
            # Partly covered: keep the uncovered pieces, fan-triangulated, in barycentrics of the original.
            m = np.column_stack([t2[a][1] - t2[a][0], t2[a][2] - t2[a][0]])
            bary = []
            for poly in polys:
                uv = np.linalg.solve(m, (np.array(poly) - t2[a][0]).T).T               # (p,2)
                w = np.column_stack([1 - uv.sum(axis=1), uv])
                for k in range(1, len(poly) - 1):
                    if _area([poly[0], poly[k], poly[k + 1]]) > tol:
                        bary.append(np.stack([w[0], w[k], w[k + 1]]))
                        kept.append(np.array([poly[0], poly[k], poly[k + 1]]))
            rest[j] = np.array(bary).reshape(-1, 3, 3)
    return drop, rest, area


def _append(out, doc, data, ctype, typ, target):
    out += b"\0" * ((4 - len(out) % 4) % 4)
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(out), "byteLength": data.nbytes, "target": target})
    out += data.tobytes()
    acc = {"bufferView": len(doc["bufferViews"]) - 1, "componentType": ctype, "count": int(data.shape[0]),
           "type": typ}
    if typ == "VEC3" and data.dtype == np.float32:
        acc["min"], acc["max"] = data.min(axis=0).tolist(), data.max(axis=0).tolist()
    doc["accessors"].append(acc)
    return len(doc["accessors"]) - 1


def drop_covered(doc, binchunk):
    """Rewrite the primitives without what earlier coincident triangles cover: whole triangles dropped, partly
    covered ones cut to their uncovered rest (new vertices interpolated; primitives with non-float attributes
    only lose whole triangles). Returns (binchunk, dropped, dropped m^2, cut, cut-away m^2)."""
    prims = world_triangles(doc, binchunk)
    if not prims:
        return binchunk, 0, 0.0, 0, 0.0
    tris = np.concatenate([t for _, _, _, t in prims])
    drop, rest, area = coincident(tris)
    out = bytearray(binchunk)
    first, cut, cut_m2 = 0, 0, 0.0
    for mesh, p, idx, t in prims:
        n = len(idx)
        d = drop[first:first + n]
        r = {j - first: w for j, w in rest.items() if first <= j < first + n}
        base = first
        first += n
        if not d.any() and not r:
            continue
        prim = doc["meshes"][mesh]["primitives"][p]
        attrs = {name: read_accessor(doc, binchunk, i) for name, i in prim["attributes"].items()}
        if any(a.dtype != np.float32 for a in attrs.values()):
            r = {}
        nvert = len(next(iter(attrs.values())))
        keep = ~d
        keep[list(r)] = False
        tri_idx = [idx[keep]]
        if r:
            new = {name: [] for name in attrs}
            for j, w in r.items():
                flat = w.reshape(-1, 3)                                              # (3k,3) weights
                for name, a in attrs.items():
                    v = flat @ a[idx[j]].astype(np.float64)
                    if name == "NORMAL":
                        v /= np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-20)
                    new[name].append(v)
                tri_idx.append((nvert + np.arange(len(flat))).reshape(-1, 3))
                nvert += len(flat)
                uv = w[:, :, 1:]
                e, f = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
                cut += 1
                cut_m2 += area[base + j] * (1.0 - np.abs(e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0]).sum())
            for name, a in attrs.items():
                full = np.concatenate([a.astype(np.float32)] + [np.asarray(x, np.float32) for x in new[name]])
                typ = doc["accessors"][prim["attributes"][name]]["type"]
                prim["attributes"][name] = _append(out, doc, full, 5126, typ, 34962)
        prim["indices"] = _append(out, doc, np.concatenate(tri_idx).astype(np.uint32).ravel(), 5125, "SCALAR", 34963)
    doc["buffers"][0]["byteLength"] = len(out)
    return bytes(out), int(drop.sum()), float(area[drop].sum()), cut, cut_m2


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    if path.endswith(".glb"):
        from scenes import read_glb  # scenes.py imports this module only inside build_sibenik
        doc, binchunk = read_glb(path)
    else:
        doc = json.load(open(path))
        binchunk = open(os.path.join(os.path.dirname(path), doc["buffers"][0]["uri"]), "rb").read()
    prims = world_triangles(doc, binchunk)
    tris = np.concatenate([t for _, _, _, t in prims])
    drop, rest, area = coincident(tris)
    print("%s: %d triangles, %d covered by earlier coincident ones (%.2f m^2), %d partly covered (their area %.2f m^2)"
          % (path, len(tris), drop.sum(), area[drop].sum(), len(rest), sum(area[j] for j in rest)))


if __name__ == "__main__":
    main()
