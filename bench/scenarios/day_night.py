#!/usr/bin/python3
"""Day and night scenarios of one level on one atlas, against separate full bakes, and relight against a re-bake.

usage (from the repository root; Debian's /usr/bin/python3 with python3-numpy and python3-openimageio):
  /usr/bin/python3 bench/scenarios/day_night.py [--scene ../shared/scenes/dabrovic_sponza/sponza.glb]
      [--irbake build/baker/irbake] [--work build/scenarios] [--seeds 0,1,2,3,4] [--csv bench/results/scenarios.csv]

The level gets 12 warm lamps (bench/levels/add_point_light.py) in its court. Per seed s, at default options with
--estimate-error:
  grouped  `--sun --sky --light-group day=sun,sky --light-group night=*`: the day and night layers and their sum;
  day      the level without lamps, sun and sky, on the grouped bake's atlas (--atlas-from), seed s + 100;
  night    the lamps alone on that atlas, seed s + 100;
  all      every light together, no groups, on that atlas, seed s + 100;
  dimmed   the lamps at half intensity with sun and sky, on that atlas, seed s + 100;
  all2     as all, seed s + 200: two ungrouped bakes' difference, the baseline the other pairs compare with;
  relight  `irbake relight` of the grouped bake with night = 0.5 (against dimmed) and at day = night = 1 (against
           the grouped bake's own maps: the same numbers).
Each pair is scored as relative RMS over 4x4-texel bins of the EXR pages (texels either bake covers, bins at least
half covered), as the bakes' estimatedError is; two independent bakes differ by about the root sum of squares
of their estimates, the `expected` column, so `ratio` near 1 means each is within its estimated error. Every bake
runs with --no-dilate, so the texels it covers are the ones it computed, as the estimate's bins hold: the
dilation fills the padding from the chart borders' texels, the noisiest, and a score over it is about twice the
estimate on Sponza (docs/units.md, "Estimated error").
"""
import argparse
import csv
import datetime
import json
import math
import os
import subprocess
import time

import numpy as np
import OpenImageIO as oiio

SUN_SKY = ["--sun", "0.35,-1,0.2,5", "--sky", "0.4,0.5,0.7"]
LAMPS = ";".join("%g,2.0,%g" % (x, z) for x in (-10, -6, -2, 2, 6, 10) for z in (-2.5, 2.5))
LAMP_CD, LAMP_RGB = 150.0, "1.0,0.75,0.45"


def run(cmd):
    """Runs a command; returns (wall seconds, child CPU seconds)."""
    t0, c0 = time.time(), os.times()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    c1 = os.times()
    return time.time() - t0, (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)


def exr(path):
    img = oiio.ImageBuf(path)
    return img.get_pixels(oiio.FLOAT)[:, :, :3].mean(axis=2)


def bin_means(a, b, bin_size=4):
    """Per bin_size² bin of texels either bake covers (either nonzero), at least half covered: both means."""
    covered = (a > 0) | (b > 0)
    h, w = (a.shape[0] // bin_size) * bin_size, (a.shape[1] // bin_size) * bin_size

    def bins(x):
        return x[:h, :w].reshape(h // bin_size, bin_size, w // bin_size, bin_size).sum(axis=(1, 3))
    count = bins(covered.astype(np.float64))
    keep = count >= bin_size * bin_size / 2
    return bins(np.where(covered, a, 0.0))[keep] / count[keep], bins(np.where(covered, b, 0.0))[keep] / count[keep]


def pages(folder, suffix=""):
    names = sorted(n for n in os.listdir(folder) if n.startswith("lightmap_") and n.endswith(suffix + ".exr")
                   and n[len("lightmap_"):-len(suffix + ".exr")].isdigit())
    return [os.path.join(folder, n) for n in names]


def score(cand, ref):
    """Relative RMS of cand - ref over the 4x4 bins of every page."""
    if len(cand) != len(ref) or not cand:
        raise SystemExit("day_night: %d pages against %d" % (len(cand), len(ref)))
    means = [bin_means(exr(c), exr(r)) for c, r in zip(cand, ref)]
    ma, mb = np.concatenate([m[0] for m in means]), np.concatenate([m[1] for m in means])
    return float(np.sqrt(np.mean((ma - mb) ** 2)) / np.sqrt(np.mean(mb ** 2)))


def estimated(folder, group=None):
    r = json.load(open(os.path.join(folder, "report.json")))
    if group is not None:
        return next(g for g in r["lightGroups"] if g["name"] == group)["estimatedError"]["relative"]
    return r["estimatedError"]["relative"]


def link_images(scene, work):
    """The copies with lamps sit in `work`: the folders of the scene's external images are linked beside them."""
    data = open(scene, "rb").read()
    doc = json.loads(data[20:20 + int.from_bytes(data[12:16], "little")])
    for top in {img["uri"].split("/")[0] for img in doc.get("images", []) if "/" in img.get("uri", "")}:
        link = os.path.join(work, top)
        if not os.path.lexists(link):
            os.symlink(os.path.abspath(os.path.join(os.path.dirname(scene), top)), link)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="../shared/scenes/dabrovic_sponza/sponza.glb")
    ap.add_argument("--irbake", default="build/baker/irbake")
    ap.add_argument("--work", default="build/scenarios")
    ap.add_argument("--seeds", default="0,1,2,3,4")
    ap.add_argument("--csv", default="bench/results/scenarios.csv")
    ap.add_argument("--commit", help="the commit of the irbake binary (default: this checkout's HEAD)")
    args = ap.parse_args()
    if not os.path.exists(args.scene):
        raise SystemExit("day_night: %s is absent (../shared/scenes)" % args.scene)
    os.makedirs(args.work, exist_ok=True)
    w = args.work
    lamps, dimmed = os.path.join(w, "lamps.glb"), os.path.join(w, "lamps_dimmed.glb")
    link_images(args.scene, w)
    add = os.path.join(os.path.dirname(__file__), "..", "levels", "add_point_light.py")
    subprocess.run(["python3", add, args.scene, lamps, LAMPS, str(LAMP_CD), LAMP_RGB], check=True)
    subprocess.run(["python3", add, args.scene, dimmed, LAMPS, str(LAMP_CD / 2), LAMP_RGB], check=True)
    commit = args.commit or subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                           text=True).stdout.strip()
    rows = []
    for seed in [int(s) for s in args.seeds.split(",")]:
        d = lambda name: os.path.join(w, "%s_%d" % (name, seed))
        scored = ["--estimate-error", "--no-dilate"]
        g_wall, g_cpu = run([args.irbake, "bake", lamps, "-o", d("grouped"), *SUN_SKY, "--seed", str(seed), *scored,
                             "--light-group", "day=sun,sky", "--light-group", "night=*"])
        atlas = ["--atlas-from", os.path.join(d("grouped"), "scene.gltf"), "--seed", str(seed + 100), *scored]
        run([args.irbake, "bake", args.scene, "-o", d("day"), *SUN_SKY, *atlas])
        run([args.irbake, "bake", lamps, "-o", d("night"), *atlas])
        a_wall, a_cpu = run([args.irbake, "bake", lamps, "-o", d("all"), *SUN_SKY, *atlas])
        run([args.irbake, "bake", dimmed, "-o", d("dimmed"), *SUN_SKY, *atlas])
        run([args.irbake, "bake", lamps, "-o", d("all2"), *SUN_SKY, *atlas[:2], "--seed", str(seed + 200), *scored])
        r_wall, r_cpu = run([args.irbake, "relight", os.path.join(d("grouped"), "scene.gltf"), "--group", "night=0.5",
                             "-o", os.path.join(d("relit"), "scene.gltf")])
        run([args.irbake, "relight", os.path.join(d("grouped"), "scene.gltf"), "--group", "night=1", "--group",
             "day=1", "-o", os.path.join(d("relit_same"), "scene.gltf")])
        g = d("grouped")
        pairs = [
            ("day_layer_vs_day", pages(g, "_day"), pages(d("day")), estimated(g, "day"), estimated(d("day"))),
            ("night_layer_vs_night", pages(g, "_night"), pages(d("night")), estimated(g, "night"),
             estimated(d("night"))),
            ("sum_vs_all", pages(g), pages(d("all")), estimated(g), estimated(d("all"))),
            ("all_vs_all_another_seed", pages(d("all")), pages(d("all2")), estimated(d("all")), estimated(d("all2"))),
            ("relight_night_half_vs_dimmed", pages(d("relit")), pages(d("dimmed")), estimated(g), estimated(d("dimmed"))),
            ("relight_unchanged_vs_grouped", pages(d("relit_same")), pages(g), 0.0, 0.0),
        ]
        for name, cand, ref, e1, e2 in pairs:
            err = score(cand, ref)
            expected = math.hypot(e1, e2)
            rows.append({"date": datetime.date.today().isoformat(), "commit": commit, "scene": "sponza_day_night",
                         "seed": seed, "pair": name, "rel_rmse_4": "%.5f" % err, "expected": "%.5f" % expected,
                         "ratio": "%.3f" % (err / expected) if expected > 0 else "",
                         "grouped_wall_s": "%.1f" % g_wall, "grouped_cpu_s": "%.1f" % g_cpu,
                         "all_wall_s": "%.1f" % a_wall, "all_cpu_s": "%.1f" % a_cpu,
                         "relight_wall_s": "%.2f" % r_wall, "relight_cpu_s": "%.2f" % r_cpu})
            print(rows[-1], flush=True)
    new = not os.path.exists(args.csv)
    with open(args.csv, "a", newline="") as f:
        out = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        if new:
            out.writeheader()
        out.writerows(rows)


if __name__ == "__main__":
    main()
