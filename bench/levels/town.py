#!/usr/bin/env python3
"""town.py OUT.glb [options]: a game-style level, generated the way levels are built.

N x N blocks of four buildings each; the buildings are instances (nodes) of eight shared box meshes, walls cut
into cells of --cell metres, turned by quarter turns. A ground plane covers the town; street lamps stand along
the streets, each a shared post mesh and a KHR_lights_punctual point light at its top, with `range` unless
--no-range. Sun and sky are the bake's options (--sun, --sky), not part of the file. --camera adds a glTF camera
(irview's --camera 0). Deterministic for a seed.

  python3 bench/levels/town.py build/levels/town16.glb --blocks 16 --lamps 1000
"""
import argparse
import json
import math
import random
import struct

BLOCK = 40.0   # block edge, metres
STREET = 12.0  # street width between blocks
PITCH = BLOCK + STREET


class Buffer:
    """One binary buffer with its views and accessors."""

    def __init__(self):
        self.data = bytearray()
        self.views, self.accessors = [], []

    def add(self, fmt, values, count, type_, component, target, bounds=None):
        while len(self.data) % 4:
            self.data.append(0)
        blob = struct.pack("<%d%s" % (len(values), fmt), *values)
        self.views.append({"buffer": 0, "byteOffset": len(self.data), "byteLength": len(blob), "target": target})
        self.data += blob
        acc = {"bufferView": len(self.views) - 1, "componentType": component, "count": count, "type": type_}
        if bounds:
            acc["min"], acc["max"] = bounds
        self.accessors.append(acc)
        return len(self.accessors) - 1


def box_mesh(sx, sy, sz, cell, top=True):
    """An open-bottom box from (-sx/2, 0, -sz/2) to (sx/2, sy, sz/2), each face cut into cells of about `cell`
    metres, outward normals, counter-clockwise seen from outside."""
    pos, nrm, idx = [], [], []

    def face(origin, u, v, n, nu, nv):
        base = len(pos) // 3
        for j in range(nv + 1):
            for i in range(nu + 1):
                p = [origin[k] + u[k] * i / nu + v[k] * j / nv for k in range(3)]
                pos.extend(p)
                nrm.extend(n)
        for j in range(nv):
            for i in range(nu):
                a = base + j * (nu + 1) + i
                b, c, d = a + 1, a + nu + 1, a + nu + 2
                idx.extend((a, b, d, a, d, c))

    hx, hz = sx / 2, sz / 2
    cells = lambda length: max(1, round(length / cell))
    face([-hx, 0, hz], [sx, 0, 0], [0, sy, 0], [0, 0, 1], cells(sx), cells(sy))      # +z
    face([hx, 0, -hz], [-sx, 0, 0], [0, sy, 0], [0, 0, -1], cells(sx), cells(sy))    # -z
    face([hx, 0, hz], [0, 0, -sz], [0, sy, 0], [1, 0, 0], cells(sz), cells(sy))      # +x
    face([-hx, 0, -hz], [0, 0, sz], [0, sy, 0], [-1, 0, 0], cells(sz), cells(sy))    # -x
    if top:
        face([-hx, sy, hz], [sx, 0, 0], [0, 0, -sz], [0, 1, 0], cells(sx), cells(sz))  # roof
    return pos, nrm, idx


def add_mesh(buf, meshes, name, geometry, material):
    pos, nrm, idx = geometry
    n = len(pos) // 3
    lo = [min(pos[k::3]) for k in range(3)]
    hi = [max(pos[k::3]) for k in range(3)]
    p = buf.add("f", pos, n, "VEC3", 5126, 34962, (lo, hi))
    q = buf.add("f", nrm, n, "VEC3", 5126, 34962)
    i = buf.add("I", idx, len(idx), "SCALAR", 5125, 34963)
    meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": p, "NORMAL": q}, "indices": i,
                                                  "material": material}]})
    return len(meshes) - 1, len(idx) // 3


def lamp_spots(blocks, count, rng):
    """`count` spots along the streets' kerbs, spread evenly over their length (deterministic)."""
    span = blocks * PITCH - STREET
    lines = []  # kerb lines: (x0, z0, x1, z1)
    for k in range(blocks - 1):
        c = (k + 1) * PITCH - STREET / 2 - span / 2
        for side in (-1, 1):
            off = c + side * (STREET / 2 - 1.0)
            lines.append((off, -span / 2, off, span / 2))
            lines.append((-span / 2, off, span / 2, off))
    if not lines:  # a single block: lamps around it
        h = span / 2 + 2.0
        lines = [(-h, -h, h, -h), (h, -h, h, h), (h, h, -h, h), (-h, h, -h, -h)]
    total = sum(math.hypot(x1 - x0, z1 - z0) for x0, z0, x1, z1 in lines)
    step = total / max(count, 1)
    spots, walked, t = [], 0.0, step * rng.uniform(0.2, 0.8)
    for x0, z0, x1, z1 in lines:
        length = math.hypot(x1 - x0, z1 - z0)
        while t <= walked + length and len(spots) < count:
            f = (t - walked) / length
            spots.append((x0 + (x1 - x0) * f, z0 + (z1 - z0) * f))
            t += step
        walked += length
    return spots


def build(args):
    rng = random.Random(args.seed)
    buf, meshes, nodes = Buffer(), [], []
    materials = [{"name": n, "pbrMetallicRoughness": {"baseColorFactor": c + [1.0], "metallicFactor": 0.0,
                                                      "roughnessFactor": 0.9}}
                 for n, c in (("plaster", [0.75, 0.7, 0.62]), ("brick", [0.55, 0.3, 0.22]),
                              ("concrete", [0.6, 0.6, 0.6]), ("ground", [0.35, 0.35, 0.33]),
                              ("metal", [0.2, 0.2, 0.22]))]
    triangles = 0
    span = args.blocks * PITCH - STREET
    ground_cells = max(1, args.blocks * 2)
    gi, gt = add_mesh(buf, meshes, "ground", ground_mesh(span + 2 * STREET, ground_cells), 3)
    nodes.append({"name": "ground", "mesh": gi})
    triangles += gt
    kinds = []
    for k in range(8):  # eight shared buildings: footprint 10-16 m, 6-30 m tall
        sx, sz = rng.uniform(10, 16), rng.uniform(10, 16)
        sy = rng.choice((6.0, 9.0, 12.0, 15.0, 21.0, 30.0))
        mi, mt = add_mesh(buf, meshes, "building_%d" % k, box_mesh(sx, sy, sz, args.cell), k % 3)
        kinds.append((mi, mt))
    post, post_tris = add_mesh(buf, meshes, "lamp_post", box_mesh(0.2, 5.0, 0.2, 5.0), 4)
    for bz in range(args.blocks):
        for bx in range(args.blocks):
            cx = bx * PITCH + BLOCK / 2 - span / 2
            cz = bz * PITCH + BLOCK / 2 - span / 2
            for q, (ox, oz) in enumerate(((-1, -1), (1, -1), (-1, 1), (1, 1))):
                mi, mt = kinds[rng.randrange(8)]
                turn = rng.randrange(4) * math.pi / 4  # quarter turns: half-angle of the quaternion
                nodes.append({"name": "b%d_%d_%d" % (bx, bz, q), "mesh": mi,
                              "translation": [cx + ox * BLOCK / 4, 0.0, cz + oz * BLOCK / 4],
                              "rotation": [0.0, math.sin(turn), 0.0, math.cos(turn)]})
                triangles += mt
    lights = []
    for i, (x, z) in enumerate(lamp_spots(args.blocks, args.lamps, rng)):
        light = {"type": "point", "name": "lamp_%d" % i, "color": [1.0, 0.78, 0.55], "intensity": args.intensity}
        if args.range > 0:
            light["range"] = args.range
        triangles += post_tris
        if args.no_lights:
            nodes.append({"name": "lamp_%d" % i, "mesh": post, "translation": [x, 0.0, z]})
            continue
        lights.append(light)
        nodes.append({"name": "lamp_%d" % i, "mesh": post, "translation": [x, 0.0, z],
                      "children": [len(nodes) + 1]})
        nodes.append({"name": "lamp_%d_light" % i, "translation": [0.0, 5.3, 0.0],
                      "extensions": {"KHR_lights_punctual": {"light": i}}})
    cameras = []
    if args.camera:
        eye, target = args.camera[:3], args.camera[3:]
        nodes.append({"name": "camera", "camera": 0, "translation": eye, "rotation": look_rotation(eye, target)})
        cameras.append({"type": "perspective", "perspective": {"yfov": math.radians(args.fov), "znear": 0.1}})
    roots = [i for i, n in enumerate(nodes) if not n["name"].endswith("_light")]
    doc = {"asset": {"version": "2.0", "generator": "irbake bench/levels/town.py"},
           "scene": 0, "scenes": [{"nodes": roots}], "nodes": nodes, "meshes": meshes, "materials": materials,
           "accessors": buf.accessors, "bufferViews": buf.views, "buffers": [{"byteLength": len(buf.data)}]}
    if cameras:
        doc["cameras"] = cameras
    if lights:
        doc["extensionsUsed"] = ["KHR_lights_punctual"]
        doc["extensions"] = {"KHR_lights_punctual": {"lights": lights}}
    return doc, bytes(buf.data), triangles, len(lights)


def look_rotation(eye, target):
    """The unit quaternion (x, y, z, w) that turns a glTF camera (looking down its -z, +y up) at `eye` towards
    `target`, its right vector kept level."""
    f = [t - e for e, t in zip(eye, target)]
    n = math.sqrt(sum(c * c for c in f))
    f = [c / n for c in f]
    r = [-f[2], 0.0, f[0]]  # forward x up(0, 1, 0)
    rn = math.sqrt(r[0] ** 2 + r[2] ** 2)
    if rn < 1e-9:
        raise ValueError("--camera: the view may not be vertical")
    r = [c / rn for c in r]
    u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]  # right x forward
    b = [-c for c in f]  # the camera's +z
    m = [[r[0], u[0], b[0]], [r[1], u[1], b[1]], [r[2], u[2], b[2]]]  # columns: the camera's axes
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 2.0 * math.sqrt(trace + 1.0)
        return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0] * 4
    q[i] = 0.25 * s
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return q


def ground_mesh(size, cells):
    pos, nrm, idx = [], [], []
    h = size / 2
    for j in range(cells + 1):
        for i in range(cells + 1):
            pos.extend((-h + size * i / cells, 0.0, -h + size * j / cells))
            nrm.extend((0.0, 1.0, 0.0))
    for j in range(cells):
        for i in range(cells):
            a = j * (cells + 1) + i
            b, c, d = a + 1, a + cells + 1, a + cells + 2
            idx.extend((a, c, b, b, c, d))  # counter-clockwise seen from +y
    return pos, nrm, idx


def write_glb(path, doc, binary):
    while len(binary) % 4:
        binary += b"\0"
    doc["buffers"][0]["byteLength"] = len(binary)
    text = json.dumps(doc, separators=(",", ":")).encode()
    while len(text) % 4:
        text += b" "
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(binary)))
        f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
        f.write(struct.pack("<II", len(binary), 0x004E4942) + binary)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", help="output .glb")
    ap.add_argument("--blocks", type=int, default=8, help="blocks per side (default 8)")
    ap.add_argument("--lamps", type=int, default=0, help="street lamps (default 0)")
    ap.add_argument("--range", type=float, default=15.0, help="lamp range in metres; 0: none (default 15)")
    ap.add_argument("--intensity", type=float, default=400.0, help="lamp intensity in candela (default 400)")
    ap.add_argument("--cell", type=float, default=3.0, help="wall cell edge in metres (default 3)")
    ap.add_argument("--no-lights", action="store_true",
                    help="lamp posts without their point lights: the same geometry, lit by --sun/--sky alone")
    ap.add_argument("--seed", type=int, default=1, help="layout seed (default 1)")
    ap.add_argument("--camera", type=str, default="", metavar="EX,EY,EZ,TX,TY,TZ",
                    help="add a glTF camera at EX,EY,EZ looking at TX,TY,TZ (metres)")
    ap.add_argument("--fov", type=float, default=50.0, help="the camera's vertical field of view in degrees (default 50)")
    args = ap.parse_args()
    if args.blocks < 1 or args.lamps < 0 or args.cell <= 0:
        ap.error("--blocks must be at least 1, --lamps at least 0, --cell positive")
    if args.camera:
        try:
            args.camera = [float(v) for v in args.camera.split(",")]
        except ValueError:
            args.camera = []
        if len(args.camera) != 6 or not all(math.isfinite(v) for v in args.camera):
            ap.error("--camera needs six finite numbers EX,EY,EZ,TX,TY,TZ")
        if math.hypot(args.camera[3] - args.camera[0], args.camera[5] - args.camera[2]) < 1e-6:
            ap.error("--camera: the view may not be vertical (the eye above or below the target)")
    if not 0.0 < args.fov < 180.0:
        ap.error("--fov must lie between 0 and 180 degrees")
    doc, binary, triangles, lamps = build(args)
    write_glb(args.out, doc, binary)
    print("%s: %d blocks, %d triangles, %d lamps" % (args.out, args.blocks ** 2, triangles, lamps))


if __name__ == "__main__":
    main()
