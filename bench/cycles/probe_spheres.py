#!/usr/bin/python3
"""Our irradiance probes against Blender Cycles on a small matte white sphere (albedo 1, Lambert).

usage (from the repository root; Debian's /usr/bin/python3 with python3-numpy and python3-openimageio):
  /usr/bin/python3 bench/cycles/probe_spheres.py [--scenes cornell,sponza] [--seeds 0,1,2,3,4]
      [--places arcade,gallery] [--spp 1024] [--size 96] [--ours irview|probe] [--cycles-sphere camera|scene] [--bake-opts "--probes 1"]
      [--irbake build/baker/irbake --irview build/runtime/irview]

For each scene (build/cycles-scenes from scenes.py: the McGuire Cornell box; Sponza with its sun and the sky
0.4,0.5,0.7) and each place (PLACES: a centre and radius R, away from walls, and a camera framing it):
  Cycles  a copy of the scene with one more node, a UV sphere (SPHERE_SEGMENTS x SPHERE_RINGS, smooth
          normals, baseColorFactor 1, metallic 0, roughness 1) at the place, seen by camera rays only
          (cycles_render_probe_object.py: what a probe-lit object is; --cycles-sphere scene: part of the scene,
          rendered by cycles_render.py or, with the sky, cycles_render_sky.py) from the place's camera at
          SIZE x SIZE, two halves of spp/2 (seeds 1, 2), cached by input checksum like compare.py (the key holds
          --cycles-dir as given: pass the path the cached renders were made with to reuse them).
  ours    `irbake bake SCENE --seed K` without the sphere (default options: probes auto), then
          `irview OUT/scene.gltf --probe-object X,Y,Z,R` from the same camera at 4x the size, averaged 4x4
          down (Cycles' pixels average their area; irview shades each point with the probes' blend at the centre
          and its gradient over the sphere, docs/export.md). With --ours probe: the same sphere shaded from
          `irbake probe OUT --at CENTRE --normal N` (a quadratic in N, E(N)/pi of an L2 probe, fitted to
          18 normals), evaluated at 4x4 sub-pixel normals: the centre's SH alone, without the gradient.
Pixels compared: the sphere's image disc from the camera (vertical fov, pixel centres, the image's row 0 at the
top), each pixel fully covered (8x8 sub-pixel rays) and so are its 8 neighbours (the silhouette's 1-pixel ring
is left out). Figures: ratio ours/Cycles of the summed RGB over the kept pixels, and on each quarter of the
disc (split at the projected centre, which is the image centre: the camera targets it); the reference's noise
= half the difference of its two halves over their mean. Diagnosis: `ratio_exact_direct` and
`worst_quarter_exact_direct` are the same figures with the L2 truncation of the direct light undone at each
surface point (the sun, times the sphere's sunlit share, and the emitters seen from the point, as exact clamped
cosines in place of their L2 parts; the emitters the probes export for exact shading, IRBAKE_light_probes.emitters,
are left out: the clients already shade them so): what is left is not the SH band limit. A bake whose probes have
a sun level (IRBAKE_light_probes.sun) already has its sun exact in irview's image (docs/units.md, "The sun shaded
exactly"), so there the sun is left out too (Sponza has no emitters: the columns equal the plain ones). `probe_sun_share`: the blend weight of the 8
probes around the centre whose own point sees the sun (a sun shadow edge between probes shows as a share below
`sunlit`; the bake fits each probe's sun over its cube, docs/units.md, so the blended sun may differ). Rows are appended to bench/results/probe_spheres.csv.
Every process runs under `nice -n 15`; Cycles with --threads 2.
"""
import argparse
import csv
import datetime
import json
import math
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402  (read_exr, gltf_files, load_gltf, cycles_cached, git_commit, run)

REPO = compare.REPO
NICE = compare.NICE
SPHERE_SEGMENTS, SPHERE_RINGS = 96, 48
SUN = (0.35, -1.0, 0.2)  # scenes.py SUN_DIR: the direction the sun's light travels
SUN_IRRADIANCE = 5.0  # scenes.py SUN_IRRADIANCE (W/m^2)
SPONZA_SKY = "0.4,0.5,0.7"

# name, centre (glTF world, metres), radius, camera direction from the centre, camera distance, vertical fov.
# The McGuire box is 2 m wide (floor y = 0, ceiling 1.99, open at z = +1); Sponza's court is about 20 x 10 m.
PLACES = {
    "cornell": [
        ("centre", (0.0, 0.95, 0.35), 0.1, (0.25, 0.3, 1.0), 0.5, 38.0),
        ("low_left", (-0.55, 0.35, 0.55), 0.1, (0.25, 0.3, 1.0), 0.5, 38.0),
        ("high_back_right", (0.45, 1.45, -0.45), 0.1, (0.25, 0.3, 1.0), 0.5, 38.0),
    ],
    "sponza": [
        ("court_sun", (2.0, 1.5, 1.6), 0.4, (-0.4, 0.25, -1.0), 2.0, 38.0),
        ("arcade", (-4.0, 1.5, 4.6), 0.4, (1.0, 0.2, -0.3), 2.0, 38.0),
        ("gallery", (2.0, 7.0, -4.6), 0.4, (-1.0, 0.15, 0.35), 2.0, 38.0),
    ],
}
SCENES = {  # scene file under --scenes-dir, irbake options, Cycles sky
    "cornell": ("mcguire_cornell.gltf", "", ""),
    "sponza": ("sponza_sun.glb", "--sky " + SPONZA_SKY, SPONZA_SKY),
}
CSV_FIELDS = ["date", "commit", "scene", "place", "centre", "radius", "sunlit", "probe_sun_share", "clearance", "eye", "fov", "size",
              "our_seed", "our_options", "ours", "cycles_sphere", "kept", "ratio", "q_upper_left", "q_upper_right", "q_lower_left", "q_lower_right",
              "worst_quarter", "ratio_exact_direct", "worst_quarter_exact_direct", "cycles_mean", "ref_spp", "ref_noise", "ref_noise_quarter_max", "cycles_s"]


def log(*a):
    print("probe_spheres:", *a, flush=True)


# ---------------------------------------------------------------- scene geometry (numpy)
def node_matrix(n):
    if "matrix" in n:
        return np.array(n["matrix"], dtype=np.float64).reshape(4, 4).T
    t = np.array(n.get("translation", [0, 0, 0]), dtype=np.float64)
    x, y, z, w = n.get("rotation", [0, 0, 0, 1])
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * np.array(n.get("scale", [1, 1, 1]))[None, :]
    m[:3, 3] = t
    return m


def read_accessor(doc, bufs, i):
    a = doc["accessors"][i]
    v = doc["bufferViews"][a["bufferView"]]
    dt = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}[a["componentType"]]
    comps = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
    item = np.dtype(dt).itemsize * comps
    stride = v.get("byteStride", item)
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    raw = bufs[v.get("buffer", 0)]
    rows = np.ndarray((a["count"],), dtype=np.dtype((np.void, item)), buffer=raw, offset=start, strides=(stride,))
    return np.frombuffer(rows.tobytes(), dtype=dt).reshape(a["count"], comps)


def scene_triangles(path):
    """Every triangle of the default scene in world space, (T, 3, 3), and its emission (T, 3): emissiveFactor
    times KHR_materials_emissive_strength."""
    doc, bufs = compare.load_gltf(path)
    tris, emission = [], []

    def emitted(p):
        if "material" not in p:
            return np.zeros(3)
        m = doc["materials"][p["material"]]
        strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        return np.array(m.get("emissiveFactor", [0, 0, 0]), dtype=np.float64) * strength

    def visit(i, parent):
        n = doc["nodes"][i]
        m = parent @ node_matrix(n)
        if "mesh" in n:
            for p in doc["meshes"][n["mesh"]]["primitives"]:
                if p.get("mode", 4) != 4:
                    continue
                pos = read_accessor(doc, bufs, p["attributes"]["POSITION"]).astype(np.float64)
                pos = pos @ m[:3, :3].T + m[:3, 3]
                idx = (read_accessor(doc, bufs, p["indices"]).ravel() if "indices" in p
                       else np.arange(len(pos))).astype(np.int64)
                tris.append(pos[idx.reshape(-1, 3)])
                emission.append(np.repeat(emitted(p)[None], len(idx) // 3, 0))
        for c in n.get("children", []):
            visit(c, m)
    for r in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        visit(r, np.eye(4))
    return np.concatenate(tris), np.concatenate(emission)


def ray_hits(tris, origins, dirs, tmax=np.inf):
    """Nearest hit distance along each ray (inf: none), Moeller-Trumbore over every triangle, in chunks."""
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    best = np.full(len(origins), np.inf)
    for k in range(len(origins)):
        o, d = origins[k], dirs[k]
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = o - tris[:, 0]
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = (q @ d) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6) & (t < tmax)
        if hit.any():
            best[k] = t[hit].min()
    return best


def fibonacci_dirs(n):
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = i * math.pi * (3 - math.sqrt(5))
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def place_checks(tris, centre, radius, eye):
    """Clearance (nearest geometry along 256 directions, minus R), the sunlit share of the sphere's sun-facing
    half (64 points, shadow rays to the sun), and whether the camera sees the centre."""
    c = np.array(centre)
    dirs = fibonacci_dirs(256)
    clearance = float(ray_hits(tris, np.repeat(c[None], len(dirs), 0), dirs).min() - radius)
    to_sun = -np.array(SUN) / np.linalg.norm(SUN)
    n = fibonacci_dirs(128)
    n = n[n @ to_sun > 0.05]
    pts = c + radius * n
    sunlit = float(np.isinf(ray_hits(tris, pts, np.repeat(to_sun[None], len(pts), 0))).mean())
    d = c - np.array(eye)
    dist = np.linalg.norm(d)
    seen = bool(ray_hits(tris, np.array(eye)[None], (d / dist)[None], dist - radius)[0] == np.inf)
    return clearance, sunlit, seen


# ---------------------------------------------------------------- the scene with the sphere
def sphere_mesh(centre, radius):
    th = np.linspace(0, math.pi, SPHERE_RINGS + 1)
    ph = np.linspace(0, 2 * math.pi, SPHERE_SEGMENTS + 1)
    t, p = np.meshgrid(th, ph, indexing="ij")
    n = np.stack([np.sin(t) * np.cos(p), np.cos(t), -np.sin(t) * np.sin(p)], axis=-1).reshape(-1, 3)
    pos = np.array(centre) + radius * n
    w = SPHERE_SEGMENTS + 1
    idx = []
    for i in range(SPHERE_RINGS):
        for j in range(SPHERE_SEGMENTS):
            a, b, c, d = i * w + j, i * w + j + 1, (i + 1) * w + j, (i + 1) * w + j + 1
            if i > 0:
                idx.append((a, c, b))
            if i < SPHERE_RINGS - 1:
                idx.append((b, c, d))
    return pos.astype(np.float32), n.astype(np.float32), np.array(idx, dtype=np.uint32)


def write_sphere_scene(src, out, centre, radius):
    """src plus a node with the white sphere, as a GLB beside src (so relative image URIs still resolve)."""
    doc, bufs = compare.load_gltf(src)
    doc = json.loads(json.dumps(doc))
    blob = b""
    for v in doc.get("bufferViews", []):  # one buffer: every view re-based into the concatenation
        offset = sum(len(b) + (-len(b)) % 4 for b in bufs[:v.get("buffer", 0)])
        v["byteOffset"] = v.get("byteOffset", 0) + offset
        v["buffer"] = 0
    for b in bufs:
        blob += b + b"\0" * ((-len(b)) % 4)
    pos, nrm, idx = sphere_mesh(centre, radius)
    views = []
    for arr, target in ((pos, 34962), (nrm, 34962), (idx, 34963)):
        data = arr.tobytes()
        views.append(len(doc["bufferViews"]))
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob += data + b"\0" * ((-len(data)) % 4)
    acc = len(doc["accessors"])
    doc["accessors"] += [
        {"bufferView": views[0], "componentType": 5126, "count": len(pos), "type": "VEC3",
         "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
        {"bufferView": views[1], "componentType": 5126, "count": len(nrm), "type": "VEC3"},
        {"bufferView": views[2], "componentType": 5125, "count": idx.size, "type": "SCALAR"}]
    doc.setdefault("materials", []).append({"name": "probe_sphere_white", "pbrMetallicRoughness": {
        "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    doc.setdefault("meshes", []).append({"name": "probe_sphere", "primitives": [{
        "attributes": {"POSITION": acc, "NORMAL": acc + 1}, "indices": acc + 2,
        "material": len(doc["materials"]) - 1}]})
    doc["nodes"].append({"name": "probe_sphere", "mesh": len(doc["meshes"]) - 1})
    doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)
    doc["buffers"] = [{"byteLength": len(blob)}]
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import scenes
    scenes.write_glb(out, doc, blob)
    return out


# ---------------------------------------------------------------- camera, mask and our shading
def camera_rays(eye, target, fov, size, sub):
    """Unit directions through sub x sub points per pixel (H*sub, W*sub, 3): up = +Y, vertical fov, row 0 at
    the top, as cycles_render.py and irview build their cameras."""
    f = np.array(target, float) - np.array(eye, float)
    f /= np.linalg.norm(f)
    r = np.cross(f, [0.0, 1.0, 0.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    n = size * sub
    s = (np.arange(n) + 0.5) / n * 2 - 1
    th = math.tan(math.radians(fov) / 2)
    x, y = np.meshgrid(s * th, -s * th)
    d = f[None, None] + x[..., None] * r[None, None] + y[..., None] * u[None, None]
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def sphere_hits(eye, dirs, centre, radius):
    """Hit mask and unit normals of the rays against the sphere."""
    oc = np.array(eye, float) - np.array(centre, float)
    b = dirs @ oc
    disc = b * b - (oc @ oc - radius * radius)
    hit = disc > 0
    t = -b - np.sqrt(np.maximum(disc, 0))
    p = np.array(eye, float) + t[..., None] * dirs
    return hit, (p - np.array(centre, float)) / radius


def kept_mask(eye, target, fov, size, centre, radius):
    sub = 8
    hit, _ = sphere_hits(eye, camera_rays(eye, target, fov, size, sub), centre, radius)
    full = hit.reshape(size, sub, size, sub).all(axis=(1, 3))
    keep = full.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            keep &= np.roll(np.roll(full, dy, 0), dx, 1)
    return keep


def quarters(size):
    c = np.arange(size) + 0.5 - size / 2
    x, y = np.meshgrid(c, c)  # y grows downwards (rows)
    return {"q_upper_left": (x < 0) & (y < 0), "q_upper_right": (x > 0) & (y < 0),
            "q_lower_left": (x < 0) & (y > 0), "q_lower_right": (x > 0) & (y > 0)}


def probe_quadratic(args, gltf, centre):
    """E(n)/pi at the centre as the L2 quadratic fitted to `irbake probe` at 18 normals (3 x 9 coefficients)."""
    ns = [v for a in np.eye(3) for v in (a, -a)]
    for i, j in ((0, 1), (1, 2), (0, 2)):
        for si in (1, -1):
            for sj in (1, -1):
                v = np.zeros(3)
                v[i], v[j] = si, sj
                ns.append(v / math.sqrt(2))
    ns = np.array(ns)
    vals = []
    for n in ns:
        r = subprocess.run(NICE + [args.irbake, "probe", gltf, "--at", ",".join("%.6g" % x for x in centre),
                                   "--normal", ",".join("%.6g" % x for x in n)], capture_output=True, text=True)
        if r.returncode != 0:
            compare.fail("irbake probe failed: " + r.stdout + r.stderr)
        vals.append(json.loads(r.stdout)["value"])
    basis = sh_basis(ns)
    coef, res, rank, _ = np.linalg.lstsq(basis, np.array(vals), rcond=None)
    fit = np.abs(basis @ coef - np.array(vals)).max() / max(np.abs(vals).max(), 1e-30)
    if rank < 9 or fit > 1e-3:
        log("warning: irbake probe at %s is not an L2 quadratic (rank %d, residual %.2g)" % (centre, rank, fit))
    return coef


def sh_basis(n):
    x, y, z = n[..., 0], n[..., 1], n[..., 2]
    return np.stack([np.ones_like(x), x, y, z, x * y, y * z, x * z, 3 * z * z - 1, x * x - y * y], axis=-1)


def ours_from_probe(args, gltf, eye, target, fov, size, centre, radius):
    coef = probe_quadratic(args, gltf, centre)
    sub = 4
    hit, n = sphere_hits(eye, camera_rays(eye, target, fov, size, sub), centre, radius)
    img = np.where(hit[..., None], sh_basis(n) @ coef, 0.0)
    return img.reshape(size, sub, size, sub, 3).mean(axis=(1, 3))


def sun_light(centre, sunlit, has_sun):
    """The sun as a delta (unit direction, RGB weight: E(n) = w max(n.l, 0)) times the sphere's sunlit share; none
    without a sun."""
    if not (has_sun and sunlit > 0):
        return np.zeros((0, 3)), np.zeros((0, 3))
    return -np.array(SUN)[None] / np.linalg.norm(SUN), np.full((1, 3), SUN_IRRADIANCE * sunlit)


def emitter_points(tris, emission, per_side=24):
    """Points on the emitting triangles (front faces): positions, unit normals, RGB power weights Le x area."""
    pts, nrm, wts = [], [], []
    i, j = np.meshgrid(np.arange(per_side), np.arange(per_side), indexing="ij")
    keep = i + j < per_side  # a barycentric grid of sub-triangle centres, equal areas
    u, v = ((i + 1 / 3) / per_side)[keep], ((j + 1 / 3) / per_side)[keep]
    for k in np.flatnonzero(emission.max(axis=1) > 0):
        a, e1, e2 = tris[k, 0], tris[k, 1] - tris[k, 0], tris[k, 2] - tris[k, 0]
        c = np.cross(e1, e2)
        area = 0.5 * np.linalg.norm(c)
        pts.append(a + u[:, None] * e1 + v[:, None] * e2)
        nrm.append(np.repeat((c / np.linalg.norm(c))[None], len(u), 0))
        wts.append(np.repeat(emission[k][None] * area / len(u), len(u), 0))
    if not pts:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3))
    return np.concatenate(pts), np.concatenate(nrm), np.concatenate(wts)


def direct_l2_residual(eye, target, fov, size, centre, radius, dirs, weights, emitters):
    """What the L2 band limit takes from the sphere's direct light, per pixel (2x2 sub-pixel points): at each surface
    point p with normal n, the exact E(p, n)/pi minus its L2 part, for the sun (the deltas dirs, weights) and the
    emitters seen from p itself (their points' solid angles at p, unoccluded); a delta of weight w along l gives
    w max(c, 0) exactly and w (3/32 + c/2 + 15c^2/32) in L2, c = n.l (the clamped cosine's Legendre series to
    l = 2). The probes' field already follows the light's change across the sphere, so this is the band limit alone."""
    sub = 2
    hit, n = sphere_hits(eye, camera_rays(eye, target, fov, size, sub), centre, radius)
    n = n.reshape(-1, 3)
    p = np.array(centre, float) + radius * n

    def clamped_minus_l2(c):
        return np.maximum(c, 0) - (3 / 32 + c / 2 + 15 * c * c / 32)
    out = clamped_minus_l2(n @ dirs.T) @ weights if len(dirs) else np.zeros((len(n), 3))
    q, qn, qw = emitters
    for k in range(0, len(q), 64):
        d = q[None, k:k + 64] - p[:, None]
        r = np.sqrt(np.einsum("ijk,ijk->ij", d, d))
        cos_q = np.maximum(np.einsum("ijk,jk->ij", d, -qn[k:k + 64]), 0) / r
        c = np.einsum("ijk,ik->ij", d, n) / r
        out += (clamped_minus_l2(c) * cos_q / (r * r)) @ qw[k:k + 64]
    out = np.where(hit.reshape(-1, 1), out / math.pi, 0.0)
    return out.reshape(size, sub, size, sub, 3).mean(axis=(1, 3))


def has_sun_level(gltf):
    """Whether the bake's probes carry a sun level, whose sun the clients shade as an exact clamped cosine."""
    with open(gltf) as f:
        return "sun" in json.load(f).get("extensions", {}).get("IRBAKE_light_probes", {})


def shaded_exactly(gltf, tris):
    """Per scene triangle: True where the probes export it among their exact emitters (IRBAKE_light_probes.emitters,
    matched by centroid): the clients already shade its direct light exactly, so the diagnosis leaves it out."""
    doc, bufs = compare.load_gltf(gltf)
    emitters = doc.get("extensions", {}).get("IRBAKE_light_probes", {}).get("emitters", [])
    if not emitters:
        return np.zeros(len(tris), bool)
    exact = np.concatenate([read_accessor(doc, bufs, e["positions"]).astype(np.float64).reshape(-1, 3, 3).mean(axis=1)
                            for e in emitters])
    centroids = tris.mean(axis=1)
    d = np.linalg.norm(centroids[:, None] - exact[None], axis=2)
    return d.min(axis=1) < 1e-4


def probe_sun_share(gltf, tris, centre):
    """The trilinear weight (valid probes, renormalised, as irview blends them) of the 8 probes around the centre
    whose baked position (grid point + offset) sees the sun: the sun's share the blended probe carries."""
    doc, bufs = compare.load_gltf(gltf)
    ext = doc["extensions"]["IRBAKE_light_probes"]
    origin, spacing, counts = np.array(ext["origin"]), float(ext["spacing"]), ext["counts"]
    offsets = read_accessor(doc, bufs, ext["offsets"]).astype(np.float64)
    valid = read_accessor(doc, bufs, ext["valid"]).ravel()
    g = np.clip((np.array(centre) - origin) / spacing, 0, np.maximum(np.array(counts) - 1.000001, 0))
    base, f = np.floor(g).astype(int), g - np.floor(g)
    to_sun = -np.array(SUN) / np.linalg.norm(SUN)
    pts, wts = [], []
    for corner in np.ndindex(2, 2, 2):
        ijk = np.minimum(base + corner, np.array(counts) - 1)
        index = ijk[0] + counts[0] * (ijk[1] + counts[1] * ijk[2])
        w = np.prod(np.where(np.array(corner) == 1, f, 1 - f))
        if valid[index] > 0.5 and w > 0:
            pts.append(origin + spacing * ijk + offsets[index])
            wts.append(w)
    lit = np.isinf(ray_hits(tris, np.array(pts), np.repeat(to_sun[None], len(pts), 0)))
    return float(np.dot(wts, lit) / np.sum(wts))


def ours_from_irview(args, gltf, eye, target, fov, size, centre, radius, path):
    ss = 4
    compare.run(NICE + [args.irview, gltf, "--probe-object", ",".join("%.6g" % x for x in tuple(centre) + (radius,)),
                        "--eye=" + ",".join("%.6g" % x for x in eye), "--target=" + ",".join("%.6g" % x for x in target),
                        "--fov", "%.6g" % fov, "--width", str(ss * size), "--height", str(ss * size),
                        "--screenshot", path], path + ".log")
    return compare.read_exr(path)[..., :3].reshape(size, ss, size, ss, 3).mean(axis=(1, 3))


# ---------------------------------------------------------------- driver
def our_bake(args, scene, opts, seed, out):
    if args.reuse_bakes and os.path.isfile(os.path.join(out, "scene.gltf")):
        log("reusing", out)
        return
    if os.path.isdir(out):
        subprocess.run(["rm", "-rf", out], check=True)
    os.makedirs(out)
    cmd = NICE + [args.irbake, "bake", scene, "-o", out, "--seed", str(seed)] + opts.split()
    log("ours:", " ".join(cmd[3:]))
    compare.run(cmd, out + ".log")


def cycles_pair(args, sphere_scene, sky, eye, target, fov, camera_only=False):
    script = args.render_script
    base = ["--eye=" + ",".join("%.6g" % x for x in eye), "--target=" + ",".join("%.6g" % x for x in target),
            "--fov", "%.6g" % fov, "--width", str(args.size), "--height", str(args.size),
            "--max-bounces", "64", "--threads", "2"]
    key = None
    if camera_only:  # the sphere seen by camera rays only: what a probe-lit object is
        script = os.path.join(REPO, "bench", "cycles", "cycles_render_probe_object.py")
        base += ["--object", "probe_sphere", "--cycles-dir", args.cycles_dir] + (["--sky", sky] if sky else [])
        key = compare.gltf_files(sphere_scene) + [args.render_script]
    elif sky:
        script = os.path.join(REPO, "bench", "cycles", "cycles_render_sky.py")
        base += ["--sky", sky, "--cycles-dir", args.cycles_dir]
        key = compare.gltf_files(sphere_scene) + [args.render_script]
    half = max(1, args.spp // 2)
    return [compare.cycles_cached(args, script, sphere_scene, base + ["--spp", str(half), "--seed", str(s)],
                                  "sphere.exr", key_files=key) for s in (1, 2)]


def figures(ours, a, b, keep, size):
    ref = 0.5 * (a + b)
    out = {"kept": int(keep.sum()), "ratio": ours[keep].sum() / ref[keep].sum(), "cycles_mean": ref[keep].mean(),
           "ref_noise": abs(a[keep].sum() - b[keep].sum()) / (a[keep].sum() + b[keep].sum())}
    qn = []
    for name, q in quarters(size).items():
        m = keep & q
        out[name] = ours[m].sum() / ref[m].sum()
        qn.append(abs(a[m].sum() - b[m].sum()) / (a[m].sum() + b[m].sum()))
    out["ref_noise_quarter_max"] = max(qn)
    out["worst_quarter"] = max(abs(out[k] - 1) for k in quarters(size))
    return out


def run_scene(args, name, rows):
    file, opts, sky = SCENES[name]
    scene = os.path.join(args.scenes_dir, file)
    if not os.path.isfile(scene):
        compare.fail("%s not found: build it with bench/cycles/scenes.py" % scene)
    tris, emission = scene_triangles(scene)
    commit = compare.git_commit(args.irbake)
    opts = (opts + " " + args.bake_opts).strip()
    work = os.path.join(args.work, name + ("_" + compare.slug(args.bake_opts) if args.bake_opts else ""))
    for seed in ([] if args.cycles_only else args.seed_list):
        our_bake(args, scene, opts, seed, os.path.join(work, "seed%d" % seed))
    for place, centre, radius, view, dist, fov in PLACES[name]:
        if args.places and place not in args.places.split(","):
            continue
        v = np.array(view) / np.linalg.norm(view)
        eye = tuple(np.array(centre) + dist * v)
        clearance, sunlit, seen = place_checks(tris, centre, radius, eye)
        log("%s/%s: clearance %.2f m (R %.2f), sunlit %.2f, camera sees it: %s" % (name, place, clearance, radius,
                                                                                   sunlit, seen))
        if not seen or clearance < radius:
            compare.fail("%s/%s: the camera does not see the sphere or it is within R of geometry" % (name, place))
        sphere_scene = write_sphere_scene(scene, os.path.join(os.path.dirname(scene), "probe_sphere_%s_%s.glb" % (
            name, place)), centre, radius)
        refs = cycles_pair(args, sphere_scene, sky, eye, centre, fov, args.cycles_sphere == "camera")
        a, b = (compare.read_exr(r[0])[..., :3] for r in refs)
        keep = kept_mask(eye, centre, fov, args.size, centre, radius)
        residuals = {}
        for seed in ([] if args.cycles_only else args.seed_list):
            out = os.path.join(work, "seed%d" % seed)
            gltf = os.path.join(out, "scene.gltf")
            exact = shaded_exactly(gltf, tris)
            # The emitters the probes left to exact shading, and the sun of a sun level in irview's image: nothing to undo.
            sun_exact = args.ours == "irview" and has_sun_level(gltf)
            key = (exact.tobytes(), sun_exact)
            if key not in residuals:
                residuals[key] = direct_l2_residual(
                    eye, centre, fov, args.size, centre, radius,
                    *sun_light(centre, sunlit, name == "sponza" and not sun_exact),
                    emitter_points(tris, np.where(exact[:, None], 0.0, emission)))
            residual = residuals[key]
            if args.ours == "irview":
                ours = ours_from_irview(args, gltf, eye, centre, fov, args.size, centre, radius,
                                        os.path.join(out, "sphere_%s.exr" % place))
            else:
                ours = ours_from_probe(args, gltf, eye, centre, fov, args.size, centre, radius)
            f = figures(ours, a, b, keep, args.size)
            if name == "sponza":
                f["probe_sun_share"] = probe_sun_share(gltf, tris, centre)
            fs = figures(ours + residual, a, b, keep, args.size)
            f["ratio_exact_direct"], f["worst_quarter_exact_direct"] = fs["ratio"], fs["worst_quarter"]
            row = {"date": datetime.date.today().isoformat(), "commit": commit, "scene": name, "place": place,
                   "centre": " ".join("%g" % x for x in centre), "radius": radius, "sunlit": round(sunlit, 3),
                   "clearance": round(clearance, 3), "eye": " ".join("%.4g" % x for x in eye), "fov": fov,
                   "size": args.size, "our_seed": seed, "our_options": args.bake_opts, "ours": args.ours, "cycles_sphere": args.cycles_sphere, "ref_spp": 2 * max(1, args.spp // 2),
                   "cycles_s": round(sum(r[1].get("render_time_s", r[1].get("wall_s", 0.0)) for r in refs), 1)}
            row.update({k: (round(float(v), 5) if isinstance(v, (float, np.floating)) else v) for k, v in f.items()})
            rows.append(row)
            log("%s/%s seed %d (%s): ratio %.4f, quarters %s, Cycles noise %.4f (quarters %.4f)" % (
                name, place, seed, args.ours, f["ratio"], " ".join("%.4f" % f[q] for q in quarters(args.size)),
                f["ref_noise"], f["ref_noise_quarter_max"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="cornell,sponza")
    ap.add_argument("--seeds", default="0", help="our bake's --seed values, e.g. 0,1,2,3,4")
    ap.add_argument("--places", default="", help="only these places, e.g. arcade,gallery (default: every one)")
    ap.add_argument("--spp", type=int, default=1024, help="Cycles samples per pixel (two halves)")
    ap.add_argument("--size", type=int, default=96, help="image width and height (pixels)")
    ap.add_argument("--ours", choices=["irview", "probe"], default="irview")
    ap.add_argument("--cycles-sphere", choices=["scene", "camera"], default="camera",
                    help="Cycles' sphere: seen by camera rays only (cycles_render_probe_object.py; the default: a "
                         "probe-lit object neither shadows the scene nor gets its own light back), or part of the "
                         "scene (it shadows and lights its surroundings)")
    ap.add_argument("--bake-opts", default="", help='more irbake bake options, e.g. "--probes 1" (own work folder)')
    ap.add_argument("--cycles-only", action="store_true", help="only the Cycles renders (to fill the cache)")
    ap.add_argument("--reuse-bakes", action="store_true", help="keep our bakes already in --work")
    ap.add_argument("--irbake", default=os.path.join(REPO, "build", "baker", "irbake"))
    ap.add_argument("--irview", default=os.path.join(REPO, "build", "runtime", "irview"))
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--cycles-dir", default=os.path.join(REPO, "..", "shared", "tools", "cycles"))
    ap.add_argument("--scenes-dir", default=os.path.join(REPO, "build", "cycles-scenes"))
    ap.add_argument("--work", default=os.path.join(REPO, "build", "cycles-work", "probe_spheres"))
    ap.add_argument("--cache", default=os.path.join(REPO, "build", "cycles-cache"))
    ap.add_argument("--csv", default=os.path.join(REPO, "bench", "results", "probe_spheres.csv"))
    args = ap.parse_args()
    args.seed_list = [int(s) for s in args.seeds.split(",")]
    args.render_script = os.path.join(args.cycles_dir, "cycles_render.py")
    rows = []
    for name in args.scenes.split(","):
        run_scene(args, name, rows)
    new = not os.path.isfile(args.csv)
    with open(args.csv, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS)
        if new:
            w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in CSV_FIELDS})
    log("appended %d rows to %s" % (len(rows), args.csv))


if __name__ == "__main__":
    main()
