#!/usr/bin/python3
"""The white furnace's corners and edges at the command's defaults: the sample cube at albedo 0.9 and Le 0.1
(exact map 1 everywhere) baked on each backend; prints and appends to bench/results/furnace_corners.csv the
covered texels' worst |map - 1|, its 99th percentile and the texels over 3%.

  /usr/bin/python3 bench/furnace_corners.py build/baker/irbake [--backends embree,gl] [-- extra bake options]

The bake runs with --no-dilate, so the texels no chart covers stay 0 and are left out (dilation never changes a
covered texel, and the closed cube has no seams to stitch)."""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio


def furnace(irbake, folder):
    subprocess.run([irbake, "samples", folder], check=True, stdout=subprocess.DEVNULL)
    path = os.path.join(folder, "furnace.gltf")
    doc = json.load(open(path))
    for m in doc["materials"]:
        m.setdefault("pbrMetallicRoughness", {})["baseColorFactor"] = [0.9, 0.9, 0.9, 1.0]
        m["emissiveFactor"] = [0.1, 0.1, 0.1]
    out = os.path.join(folder, "furnace_rho09.gltf")
    json.dump(doc, open(out, "w"))
    return out


def score(folder):
    dev = []
    for name in sorted(os.listdir(folder)):
        if name.startswith("lightmap_") and name.endswith(".exr"):
            px = oiio.ImageBuf(os.path.join(folder, name)).get_pixels(oiio.FLOAT).mean(axis=2)
            dev.append(np.abs(px[px > 0] - 1.0))
    d = np.sort(np.concatenate(dev))
    return len(d), d[-1], d[len(d) * 99 // 100], int((d > 0.03).sum())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("irbake")
    ap.add_argument("--backends", default="embree,gl")
    ap.add_argument("--csv", default=os.path.join(os.path.dirname(__file__), "results", "furnace_corners.csv"))
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    a = ap.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    a.extra = extra
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    with tempfile.TemporaryDirectory() as tmp:
        scene = furnace(a.irbake, tmp)
        for backend in a.backends.split(","):
            out = os.path.join(tmp, backend)
            subprocess.run([a.irbake, "bake", scene, "-o", out, "--backend", backend, "--quiet", "--no-gltf",
                            "--probes", "off", "--no-dilate"] + a.extra, check=True)
            texels, worst, p99, over = score(out)
            load = os.getloadavg()[0]
            print(f"{backend}: {texels} texels, worst {100 * worst:.2f}%, p99 {100 * p99:.2f}%, {over} over 3% (load {load:.1f})")
            new = not os.path.exists(a.csv)
            with open(a.csv, "a", newline="") as f:
                w = csv.writer(f)
                if new:
                    w.writerow(["commit", "backend", "options", "texels", "worst", "p99", "over_3pct", "load_1min"])
                w.writerow([commit, backend, " ".join(a.extra) or "default", texels, f"{worst:.5f}", f"{p99:.5f}", over, f"{load:.1f}"])


if __name__ == "__main__":
    sys.exit(main())
