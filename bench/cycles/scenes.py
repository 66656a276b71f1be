#!/usr/bin/python3
"""Scene builders for the Cycles comparison: glTF 2.0 scenes made from the shared third-party assets.

usage (from the repository root):
  /usr/bin/python3 bench/cycles/scenes.py mcguire OUTDIR   -> OUTDIR/mcguire_cornell.gltf + .bin
  /usr/bin/python3 bench/cycles/scenes.py cornell_published OUTDIR -> OUTDIR/cornell_published.gltf + .bin
  /usr/bin/python3 bench/cycles/scenes.py sponza  OUTDIR   -> OUTDIR/sponza_sun.glb (+ OUTDIR/textures link)
                                                           and OUTDIR/sponza_sun_x4.glb (+ OUTDIR/textures_x4/)
  /usr/bin/python3 bench/cycles/scenes.py sibenik OUTDIR   -> OUTDIR/sibenik/sibenik_lamp.glb (+ its textures link)
  /usr/bin/python3 bench/cycles/scenes.py all     OUTDIR

Inputs are read from ../shared/scenes (relative to the repository root; --shared overrides) and never copied
into git: write OUTDIR under build/. Standard library only, but for coplanar.py (numpy) on Sibenik.

mcguire: CornellBox-Original.obj/.mtl (McGuire archive) -> one glTF material per MTL material, base colour
  from Kd. The two blocks have Kd = 0 and Ks = 0.725 0.71 0.68 (a glossy white) in the MTL: irbake and our
  Cycles set-up are Lambertian only, so they become *diffuse* with that white (0.725, 0.71, 0.68). The light
  gets emissiveFactor = Ke / max(Ke) and KHR_materials_emissive_strength = max(Ke) (Ke = 17 12 4). Quads
  are split into two triangles (fan 0-1-2, 0-2-3; the OBJ's winding is kept, so the light faces down), no
  NORMAL (flat). Camera: the classic view into the open side, eye (0, 1, 3.94), target (0, 1, 0),
  yfov 39.3 degrees, aspect 1.
cornell_published: the Cornell box from the Cornell University Program of Computer Graphics' published data
  (geometry, reflectance and emission spectra; no input file: the data are in cornell_published.py, which
  states the source and the spectrum -> RGB conversion). Light 0.1 mm under the ceiling, facing down.
sponza: dabrovic_sponza/sponza.glb with KHR_materials_pbrSpecularGlossiness stripped (Blender 3.4 would
  build node trees from it that cycles_render.py cannot turn into Lambert; irbake ignores it), plus a
  KHR_lights_punctual directional light travelling along (0.35, -1, 0.2) normalised with intensity 5
  (= irradiance 5 W/m^2, as `irbake bake --sun 0.35,-1,0.2,5`), and four cameras (SPONZA_CAMERAS). The
  binary chunk is reused byte for byte; the images stay external: OUTDIR/textures links to the shared
  textures folder.
sponza_sun_x4.glb: the same scene whose images are OUTDIR/textures_x4/NAME.png, each shared texture upsampled
  4x by nearest neighbour (oiiotool --resample:interp=0, lossless PNG): the same texel values and means, so
  the same scene for irbake, but Cycles filters base-colour textures in sRGB space *before* decoding (a
  black/white checker renders 0.247 against glTF's linear mean 0.5; docs/validation.md), which darkens its
  albedo by 0.04-0.67% per Sponza texture; on the upsampled images that filtering acts only on the borders of
  4x4 blocks of equal texels. The accuracy figures against Cycles use this scene.
sibenik: sibenik/sibenik.glb, its BLEND glass made opaque, one 2000 cd point lamp in the nave, six cameras,
  and the 205 triangles (12.3 m^2: the pulpit's carpet, gallery floors) that a coincident triangle of the same
  plane already covers dropped, 78 partly covered ones cut to their rest (8.6 m^2 cut away; coplanar.py:
  Cycles renders such overlaps black).
"""
import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys

SUN_DIR = (0.35, -1.0, 0.2)
SUN_IRRADIANCE = 5.0

# name, eye, target, yfov (degrees); glTF frame (Y up). Every level camera: aspect 1.6 (160x100 renders).
SPONZA_CAMERAS = [
    ("overview", (-9.5, 5.0, 0.0), (8.0, 2.5, 0.0), 65.0),
    ("arcade", (-8.5, 1.6, 4.6), (6.0, 2.2, 4.6), 55.0),
    ("arches", (-2.0, 1.4, -4.2), (1.5, 5.0, -5.6), 65.0),
    ("gallery", (-9.0, 7.0, -4.8), (8.0, 6.5, -4.2), 55.0),
]
VIEW_ASPECT = 1.6

# Sibenik for the Cycles comparison: the interior lamp of bench/levels (2000 cd, 7 m above the nave floor) and
# no sky; its two BLEND glass materials made opaque, since Cycles' importer passes BLEND light untinted where
# irbake tints it by the base colour (docs/units.md): the comparison is of the estimator, not of the glass.
SIBENIK_LAMP = ((0.0, -8.0, 0.0), 2000.0)
SIBENIK_CAMERAS = [
    ("choir", (14.0, -12.5, 0.0), (-6.0, -15.3, 0.0), 60.0),
    ("aisle", (-14.0, -12.0, 5.0), (6.0, -14.0, -4.0), 60.0),
    ("across", (0.0, -14.0, 6.5), (0.0, -10.0, -8.0), 60.0),
    # The pulpit's landing and parapet, where the coincident carpet triangles were (coplanar.py).
    ("landing", (4.6, -12.2, 0.3), (4.1, -14.16, -0.35), 60.0),
    ("parapet", (4.6, -13.6, 0.85), (4.2, -13.95, -0.69), 60.0),
    ("pulpit", (8.0, -11.0, 3.0), (4.2, -14.0, -0.5), 60.0),
]


def fail(msg):
    sys.exit("scenes.py: " + msg)


def shared_dir(args):
    d = args.shared or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "scenes")
    d = os.path.normpath(d)
    if not os.path.isdir(d):
        fail("shared scenes not found at %s (expected ../shared/scenes beside the repository; --shared DIR)" % d)
    return d


def norm(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def look_at_quat(eye, target, up=(0.0, 1.0, 0.0)):
    """Rotation (x, y, z, w) taking the glTF camera frame (looks along -Z, +Y up) to look from eye at target."""
    f = norm(tuple(t - e for t, e in zip(target, eye)))
    z = tuple(-x for x in f)
    x = norm(cross(up, z))
    y = cross(z, x)
    m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]  # columns = camera axes
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        return ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s)
    if m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        return (0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
    if m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        return ((m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
    s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
    return ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s)


def rotation_to(direction):
    """Quaternion (x, y, z, w) rotating -Z (a glTF light's direction) onto `direction`."""
    d = norm(direction)
    a = (0.0, 0.0, -1.0)
    c = cross(a, d)
    w = 1.0 + sum(p * q for p, q in zip(a, d))
    if w < 1e-9:
        return (1.0, 0.0, 0.0, 0.0)
    n = math.sqrt(c[0] ** 2 + c[1] ** 2 + c[2] ** 2 + w * w)
    return (c[0] / n, c[1] / n, c[2] / n, w / n)


def write_atomic(path, data):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def lambert_material(name, kd, ke=(0, 0, 0), note=None):
    """A glTF material: base colour kd; an emitter when ke > 0 (factor ke / max(ke), strength max(ke))."""
    mat = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(kd) + [1.0], "metallicFactor": 0.0,
                                                   "roughnessFactor": 1.0}}
    if note:
        mat["extras"] = {"note": note}
    if max(ke) > 0:
        s = max(ke)
        mat["emissiveFactor"] = [k / s for k in ke]
        mat["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": s}}
    return mat


def write_polygon_scene(out, stem, groups, materials, camera, generator):
    """OUT/stem.gltf + .bin: one mesh per (name, polygons, material index) group, each polygon a triangle
    fan over its own corners (its winding kept, no NORMAL: flat); camera = (eye, target, yfov degrees)."""
    blob, accessors, views, meshes, nodes = bytearray(), [], [], [], []
    for name, polys, mat in groups:
        pos, ind = [], []
        for poly in polys:
            b = len(pos)
            pos += poly
            for k in range(1, len(poly) - 1):
                ind += [b, b + k, b + k + 1]
        off = len(blob)
        for p in pos:
            blob += struct.pack("<3f", *p)
        views.append({"buffer": 0, "byteOffset": off, "byteLength": 12 * len(pos), "target": 34962})
        lo = [min(p[i] for p in pos) for i in range(3)]
        hi = [max(p[i] for p in pos) for i in range(3)]
        accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(pos), "type": "VEC3",
                          "min": lo, "max": hi})
        off = len(blob)
        for j in ind:
            blob += struct.pack("<H", j)
        blob += b"\0" * ((4 - len(blob) % 4) % 4)
        views.append({"buffer": 0, "byteOffset": off, "byteLength": 2 * len(ind), "target": 34963})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": len(ind), "type": "SCALAR"})
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                     "indices": len(accessors) - 1, "material": mat, "mode": 4}]})
        nodes.append({"name": name, "mesh": len(meshes) - 1})
    eye, target, yfov = camera
    nodes.append({"name": "camera", "camera": 0, "translation": list(eye), "rotation": list(look_at_quat(eye, target))})
    doc = {
        "asset": {"version": "2.0", "generator": generator},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes,
        "materials": materials, "accessors": accessors, "bufferViews": views,
        "buffers": [{"uri": stem + ".bin", "byteLength": len(blob)}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": math.radians(yfov), "aspectRatio": 1.0,
                                                             "znear": 0.01, "zfar": 100.0}}],
    }
    os.makedirs(out, exist_ok=True)
    write_atomic(os.path.join(out, stem + ".bin"), bytes(blob))
    path = os.path.join(out, stem + ".gltf")
    write_atomic(path, json.dumps(doc, indent=1).encode())
    print("wrote", path, "(%d triangles, %d materials)" % (sum(len(p) - 2 for _, g, _ in groups for p in g),
                                                          len(materials)))
    return path


def parse_mtl(path):
    mats, cur = {}, None
    for line in open(path):
        t = line.split("#")[0].split()
        if not t:
            continue
        if t[0] == "newmtl":
            cur = mats.setdefault(t[1], {})
        elif cur is not None and t[0] in ("Kd", "Ks", "Ke"):
            cur[t[0]] = tuple(float(x) for x in t[1:4])
    return mats


def build_mcguire(shared, out):
    src = os.path.join(shared, "cornell_box")
    obj, mtl = os.path.join(src, "CornellBox-Original.obj"), os.path.join(src, "CornellBox-Original.mtl")
    for p in (obj, mtl):
        if not os.path.isfile(p):
            fail("missing %s" % p)
    mats = parse_mtl(mtl)
    verts, groups, order, cur = [], {}, [], None
    for line in open(obj):
        t = line.split("#")[0].split()
        if not t:
            continue
        if t[0] == "v":
            verts.append(tuple(float(x) for x in t[1:4]))
        elif t[0] == "usemtl":
            cur = t[1]
            if cur not in groups:
                groups[cur] = []
                order.append(cur)
        elif t[0] == "f":
            idx = [int(x.split("/")[0]) for x in t[1:]]
            idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
            groups[cur].append([verts[i] for i in idx])  # one polygon, its corners shared by its triangles
    materials = []
    for name in order:
        m = mats.get(name)
        if m is None:
            fail("%s: material %r not in %s" % (obj, name, mtl))
        kd = m.get("Kd", (0, 0, 0))
        note = None
        if max(kd) == 0 and max(m.get("Ks", (0, 0, 0))) > 0:
            kd, note = m["Ks"], "MTL Kd = 0, Ks = %s: made diffuse with the Ks white" % (m["Ks"],)
        materials.append(lambert_material(name, kd, m.get("Ke", (0, 0, 0)), note))
    path = write_polygon_scene(out, "mcguire_cornell", [(name, groups[name], i) for i, name in enumerate(order)], materials,
                               ((0.0, 1.0, 3.94), (0.0, 1.0, 0.0), 39.3),
                               "irbake bench/cycles/scenes.py (from CornellBox-Original.obj)")
    return path


def read_glb(path):
    data = open(path, "rb").read()
    magic, version, length = struct.unpack("<III", data[:12])
    if magic != 0x46546C67 or version != 2:
        fail("%s: not a glTF 2.0 binary" % path)
    jl, jt = struct.unpack("<II", data[12:20])
    doc = json.loads(data[20:20 + jl])
    rest = data[20 + jl:]
    binchunk = b""
    if len(rest) >= 8:
        bl, bt = struct.unpack("<II", rest[:8])
        binchunk = rest[8:8 + bl]
    return doc, binchunk


def write_glb(path, doc, binchunk):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * ((4 - len(js) % 4) % 4)
    binchunk = binchunk + b"\0" * ((4 - len(binchunk) % 4) % 4)
    total = 12 + 8 + len(js) + (8 + len(binchunk) if binchunk else 0)
    out = struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(js), 0x4E4F534A) + js
    if binchunk:
        out += struct.pack("<II", len(binchunk), 0x004E4942) + binchunk
    write_atomic(path, out)


def read_level(shared, folder, name):
    """The level's GLB without KHR_materials_pbrSpecularGlossiness (neither renderer uses it), its root nodes."""
    src = os.path.join(shared, folder)
    glb = os.path.join(src, name)
    if not os.path.isfile(glb):
        fail("missing %s" % glb)
    doc, binchunk = read_glb(glb)
    for m in doc.get("materials", []):
        m.get("extensions", {}).pop("KHR_materials_pbrSpecularGlossiness", None)
        if "extensions" in m and not m["extensions"]:
            del m["extensions"]
    used = [e for e in doc.get("extensionsUsed", []) if e != "KHR_materials_pbrSpecularGlossiness"]
    used.append("KHR_lights_punctual")
    doc["extensionsUsed"] = used
    return src, doc, binchunk, doc["scenes"][doc.get("scene", 0)]["nodes"]


def add_light(doc, root, light, node):
    """One KHR_lights_punctual light (the level's only one) on a new root node."""
    doc["extensions"] = {"KHR_lights_punctual": {"lights": [light]}}
    node["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    doc["nodes"].append(node)
    root.append(len(doc["nodes"]) - 1)


def add_cameras(doc, root, cameras):
    doc["cameras"] = []
    for name, eye, target, fov in cameras:
        doc["cameras"].append({"name": name, "type": "perspective", "perspective": {
            "yfov": math.radians(fov), "aspectRatio": VIEW_ASPECT, "znear": 0.05, "zfar": 200.0}})
        doc["nodes"].append({"name": "camera_" + name, "camera": len(doc["cameras"]) - 1, "translation": list(eye),
                             "rotation": list(look_at_quat(eye, target))})
        root.append(len(doc["nodes"]) - 1)


def write_level(src, out, name, doc, binchunk, generated):
    """OUT/name beside OUT/textures, a link to the level's own textures folder."""
    doc["asset"]["generator"] = doc["asset"].get("generator", "") + " + irbake bench/cycles/scenes.py (%s)" % generated
    os.makedirs(out, exist_ok=True)
    link = os.path.join(out, "textures")
    if os.path.islink(link):
        os.remove(link)
    if not os.path.exists(link):
        os.symlink(os.path.abspath(os.path.join(src, "textures")), link)
    path = os.path.join(out, name)
    write_glb(path, doc, binchunk)
    return path


def upsample_textures(src, out, doc, scale, folder):
    """Point the images at OUT/folder/NAME.png, each the level's texture upsampled `scale` x by nearest neighbour."""
    oiiotool = shutil.which("oiiotool")
    if not oiiotool:
        fail("oiiotool not found (Debian package openimageio-tools)")
    os.makedirs(os.path.join(out, folder), exist_ok=True)
    for img in doc.get("images", []):
        uri = img.get("uri", "")
        if not uri or uri.startswith("data:"):
            fail("image without an external uri: %s" % img)
        name = os.path.splitext(os.path.basename(uri.replace("%20", " ")))[0] + ".png"
        dst = os.path.join(out, folder, name)
        if not os.path.isfile(dst):
            tmp = dst + ".tmp.png"
            subprocess.run([oiiotool, os.path.join(src, uri.replace("%20", " ")), "--resample:interp=0",
                            "%d%%" % (100 * scale), "-o", tmp], check=True)
            os.replace(tmp, dst)
        img["uri"] = folder + "/" + name
        img.pop("mimeType", None)


def build_cornell_published(out):
    import cornell_published as cp  # the published data and its RGB conversion
    parts, mats = cp.scene_parts()
    names = list(dict.fromkeys(m for _, m, _ in parts))
    materials = [lambert_material(m, mats[m][0], mats[m][1]) for m in names]
    for m in materials:
        m["extras"] = {"note": "Cornell Box Data spectra -> linear sRGB (bench/cycles/cornell_published.py)"}
    groups = [(name, polys, names.index(m)) for name, m, polys in parts]
    path = write_polygon_scene(out, "cornell_published", groups, materials, cp.camera(),
                               "irbake bench/cycles/scenes.py (Cornell Box Data, Cornell University PCG)")
    return path


def build_sponza(shared, out):
    src, doc, binchunk, root = read_level(shared, "dabrovic_sponza", "sponza.glb")
    add_light(doc, root, {"type": "directional", "name": "sun", "intensity": SUN_IRRADIANCE, "color": [1.0, 1.0, 1.0]},
              {"name": "sun", "rotation": list(rotation_to(SUN_DIR))})
    add_cameras(doc, root, SPONZA_CAMERAS)
    path = write_level(src, out, "sponza_sun.glb", doc, binchunk, "sun, cameras")
    print("wrote", path, "(%d cameras, sun along %s, E = %g W/m^2)" % (len(SPONZA_CAMERAS), SUN_DIR, SUN_IRRADIANCE))
    upsample_textures(src, out, doc, 4, "textures_x4")
    x4 = os.path.join(out, "sponza_sun_x4.glb")
    write_glb(x4, doc, binchunk)
    print("wrote", x4, "(the same, textures upsampled 4x by nearest neighbour into textures_x4/)")
    return path


def build_sibenik(shared, out):
    src, doc, binchunk, root = read_level(shared, "sibenik", "sibenik.glb")
    for m in doc.get("materials", []):
        if m.get("alphaMode") == "BLEND":
            del m["alphaMode"]
            m.setdefault("pbrMetallicRoughness", {}).setdefault("baseColorFactor", [1.0, 1.0, 1.0, 1.0])[3] = 1.0
    # Coincident triangles (the pulpit's carpet, gallery floors) render black in Cycles (coplanar.py): drop
    # those that earlier ones of the same plane cover, cut the partly covered ones to their rest.
    import coplanar  # numpy, so imported here: the other scenes need the standard library only
    binchunk, dropped, dropped_m2, cut, cut_m2 = coplanar.drop_covered(doc, binchunk)
    print("sibenik: dropped %d coincident triangles (%.2f m^2) that others cover; cut %d partly covered ones "
          "(%.2f m^2 cut away)" % (dropped, dropped_m2, cut, cut_m2))
    pos, cd = SIBENIK_LAMP
    add_light(doc, root, {"type": "point", "name": "interior lamp", "intensity": cd, "color": [1.0, 1.0, 1.0]},
              {"name": "interior lamp", "translation": list(pos)})
    add_cameras(doc, root, SIBENIK_CAMERAS)
    # A folder of its own: its textures link is not Sponza's.
    path = write_level(src, os.path.join(out, "sibenik"), "sibenik_lamp.glb", doc, binchunk, "lamp, cameras, opaque glass")
    print("wrote", path, "(%d cameras, %g cd lamp at %s, glass opaque)" % (len(SIBENIK_CAMERAS), cd, pos))
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("which", choices=["mcguire", "cornell_published", "sponza", "sibenik", "all"])
    ap.add_argument("outdir")
    ap.add_argument("--shared", help="shared scenes folder (default: ../shared/scenes from the repository root)")
    args = ap.parse_args()
    if args.which in ("cornell_published", "all"):
        build_cornell_published(args.outdir)
        if args.which == "cornell_published":
            return
    shared = shared_dir(args)
    if args.which in ("mcguire", "all"):
        build_mcguire(shared, args.outdir)
    if args.which in ("sponza", "all"):
        build_sponza(shared, args.outdir)
    if args.which in ("sibenik", "all"):
        build_sibenik(shared, args.outdir)


if __name__ == "__main__":
    main()
