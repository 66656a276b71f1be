#!/usr/bin/python3
"""How many cells of a bake's probe grid have corners on both sides of the sun's shadow: each probe's own shadow
ray toward the sun (numpy ray casts over every triangle of the scene, probe_spheres.py), the 8 corners of each
cell compared. The size of a finer level of the sun's visibility where its shadow edge crosses the grid.

usage: /usr/bin/python3 bench/cycles/probe_sun_cells.py BAKE.gltf SCENE.glb   (Debian's python3 with numpy)
e.g.   ... build/cycles-work/probe_spheres/sponza/seed0/scene.gltf build/cycles-scenes/sponza_sun.glb
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402
import probe_spheres as ps  # noqa: E402


def main(bake, scene):
    doc, bufs = compare.load_gltf(bake)
    ext = doc["extensions"]["IRBAKE_light_probes"]
    offsets = ps.read_accessor(doc, bufs, ext["offsets"])
    origin, spacing, n = np.array(ext["origin"]), ext["spacing"], ext["counts"]
    tris, _ = ps.scene_triangles(scene)
    to_sun = -np.array(ps.SUN) / np.linalg.norm(ps.SUN)
    count = n[0] * n[1] * n[2]
    i = np.arange(count)
    ijk = np.stack([i % n[0], i // n[0] % n[1], i // (n[0] * n[1])], 1)
    lit = np.isinf(ps.ray_hits(tris, origin + spacing * ijk + offsets, np.repeat(to_sun[None], count, 0)))
    v = lit.reshape(n[2], n[1], n[0])
    corners = [v[a:v.shape[0] - 1 + a, b:v.shape[1] - 1 + b, c:v.shape[2] - 1 + c] for a in (0, 1) for b in (0, 1) for c in (0, 1)]
    stacked = np.stack(corners)
    mixed = int((stacked.any(0) & ~stacked.all(0)).sum())
    print(f"probes {count}, sunlit {int(lit.sum())}; cells {stacked[0].size}, across the sun's shadow edge {mixed}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
