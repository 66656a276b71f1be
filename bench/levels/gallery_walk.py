#!/usr/bin/python3
"""Sponza's upper gallery (camera 3) against our own converged reference, over walk seeds: how the walk's
random numbers and its split change the light that reaches the gallery (docs/units.md). Writes
bench/results/gallery_walk.csv.

usage (repository root, after a Release build; needs ../shared/scenes and python3-openimageio):
  /usr/bin/python3 bench/levels/gallery_walk.py [--seeds 0,1,2,3,4,5] [--opts "" --opts "--walk-split 1" ...]

The scene is bench/cycles/scenes.py's Sponza with its sun (built if missing) plus --sky 0.4,0.5,0.7, baked
at 4 texels/m so that one bake takes seconds. The reference is the path-traced backend at 2048 paths per
texel sample on the same atlas (about 6 min on 2 cores; cached in build/gallery-walk/reference). Each bake
is rendered by irview from camera 3 at 640x400 and averaged to 160x100, like the reference; figures: mean
ratio over the view, relative RMSE on 4x4 and 10x10 pixel bins, and the ratio on the gallery's left wall
(10x10 bins, columns 0-7). Rows go to bench/results/gallery_walk.csv.
"""
import argparse
import csv
import os
import subprocess
import sys

import numpy as np

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(REPO, "bench", "cycles"))
from compare import read_exr  # noqa: E402

SKY = "0.4,0.5,0.7"
W, H = 160, 100


def bake_and_render(irbake, irview, scene, out, opts):
    os.makedirs(out, exist_ok=True)
    cmd = [irbake, "bake", scene, "-o", out, "--sky", SKY, "--texels-per-unit", "4", "--quiet"] + opts
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    shot = os.path.join(out, "view3_x4.exr")
    subprocess.run([irview, os.path.join(out, "scene.gltf"), "--camera", "3", "--screenshot", shot, "--width",
                    str(4 * W), "--height", str(4 * H)], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return read_exr(shot)[..., :3].reshape(H, 4, W, 4, 3).mean(axis=(1, 3))


def bins(x, b):
    return x[:H // b * b, :W // b * b].reshape(H // b, b, W // b, b, 3).mean(axis=(1, 3))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0,1,2,3,4,5")
    ap.add_argument("--opts", action="append", help='irbake bake options ("" = defaults), repeatable')
    ap.add_argument("--irbake", default=os.path.join(REPO, "build", "baker", "irbake"))
    ap.add_argument("--irview", default=os.path.join(REPO, "build", "runtime", "irview"))
    ap.add_argument("--work", default=os.path.join(REPO, "build", "gallery-walk"))
    ap.add_argument("--csv", default=os.path.join(REPO, "bench", "results", "gallery_walk.csv"))
    args = ap.parse_args()
    scene = os.path.join(REPO, "build", "cycles-scenes", "sponza_sun.glb")
    if not os.path.isfile(scene):
        subprocess.run(["/usr/bin/python3", os.path.join(REPO, "bench", "cycles", "scenes.py"), "sponza",
                        os.path.dirname(scene)], check=True)
    ref_dir = os.path.join(args.work, "reference")
    ref_shot = os.path.join(ref_dir, "view3_x4.exr")
    if os.path.isfile(ref_shot):
        ref = read_exr(ref_shot)[..., :3].reshape(H, 4, W, 4, 3).mean(axis=(1, 3))
    else:
        print("gallery_walk: baking the reference (2048 paths per texel sample)", flush=True)
        ref = bake_and_render(args.irbake, args.irview, scene, ref_dir, ["--backend", "reference", "--spp", "2048"])
    rb4, rb10 = bins(ref, 4), bins(ref, 10)
    new = not os.path.isfile(args.csv)
    with open(args.csv, "a", newline="") as f:
        w = csv.writer(f)
        if new:
            w.writerow(["options", "seed", "mean_ratio", "rel_rmse_4", "rel_rmse_10", "left_wall_ratio"])
        for opts in args.opts or [""]:
            walls = []
            for seed in [int(s) for s in args.seeds.split(",")]:
                out = os.path.join(args.work, "bake")
                o = bake_and_render(args.irbake, args.irview, scene, out, opts.split() + ["--seed", str(seed)])
                ob4, ob10 = bins(o, 4), bins(o, 10)
                e4 = np.sqrt(np.mean((ob4 - rb4) ** 2)) / np.sqrt(np.mean(rb4 ** 2))
                e10 = np.sqrt(np.mean((ob10 - rb10) ** 2)) / np.sqrt(np.mean(rb10 ** 2))
                wall = ob10.mean(-1)[:, :8].sum() / rb10.mean(-1)[:, :8].sum()
                walls.append(wall)
                w.writerow([opts, seed, "%.4f" % (o.sum() / ref.sum()), "%.4f" % e4, "%.4f" % e10, "%.4f" % wall])
                print("gallery_walk: %-30s seed %d: mean %.4f, 4x4 %.2f%%, 10x10 %.2f%%, left wall %.3f" % (
                    opts or "default", seed, o.sum() / ref.sum(), 100 * e4, 100 * e10, wall), flush=True)
            print("gallery_walk: %-30s left wall over %d seeds: mean %.3f, sd %.3f" % (
                opts or "default", len(walls), np.mean(walls), np.std(walls)), flush=True)


if __name__ == "__main__":
    main()
