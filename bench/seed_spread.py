#!/usr/bin/python3
"""How much a bake depends on its walk seed: bakes of one scene at seeds 0..K-1, compared with each other.

usage (repository root; Debian's /usr/bin/python3 with python3-numpy and python3-openimageio):
  /usr/bin/python3 bench/seed_spread.py SCENE --name NAME [--seeds 5] [--opts "..."] [--irbake build/baker/irbake]

Every bake writes page 0 (one-page scenes: the Cornell boxes). Over the texels every bake covers, less the ring
next to an uncovered texel and the texels below 2% of the mean (as bench/cycles/compare.py keeps them):
  total ratio    each seed's sum over the seeds' mean sum: against any common reference (Cycles' bake in this
                 atlas) the mean ratio ours/reference moves by exactly this factor from seed to seed, so its
                 spread (largest - smallest) is the spread of compare.py's mean ratio over seeds;
  seed noise     per seed, the relative RMS over 4x4-texel bins and RGB of (seed - mean of the other seeds'
                 maps), times sqrt((K-1)/K): one bake's noise from the walk and the seeded rays, the part of
                 its error against a reference that changes with the seed (bias excluded).
Rows (one per seed, and a summary row with seed "all") are appended to bench/results/seed_spread.csv.
"""
import argparse
import datetime
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "cycles"))
import compare  # noqa: E402  (read_exr, bin_means, erode_cover, run, git_commit)

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
FIELDS = ["date", "commit", "scene", "options", "seed", "wall_s", "load_1min", "texels_kept", "total_ratio",
          "seed_noise_4", "spread", "noise_rms"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--name", required=True)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--opts", default="", help="irbake bake options besides --seed")
    ap.add_argument("--irbake", default=os.path.join(REPO, "build", "baker", "irbake"))
    ap.add_argument("--work", default=os.path.join(REPO, "build", "seed-spread"))
    ap.add_argument("--csv", default=os.path.join(REPO, "bench", "results", "seed_spread.csv"))
    args = ap.parse_args()
    if args.seeds < 3:
        sys.exit("seed_spread.py: --seeds must be at least 3")
    maps, walls, loads = [], [], []
    for seed in range(args.seeds):
        out = os.path.join(args.work, args.name, compare.slug(args.opts), "seed%d" % seed)
        os.makedirs(out, exist_ok=True)
        loads.append(os.getloadavg()[0])
        t0 = time.time()
        compare.run(compare.NICE + [args.irbake, "bake", args.scene, "-o", out, "--seed", str(seed), "--quiet",
                                    "--no-gltf"] + args.opts.split(), out + ".log")
        walls.append(time.time() - t0)
        maps.append(compare.read_exr(os.path.join(out, "lightmap_0.exr"))[..., :3])
        print("seed %d: %.1f s wall (1-min load before: %.1f)" % (seed, walls[-1], loads[-1]), flush=True)
    stack = np.stack(maps)
    cov = np.all(stack.sum(axis=3) > 0, axis=0)
    lum = stack.mean(axis=(0, 3))
    mask = compare.erode_cover(cov) & (lum >= 0.02 * lum[cov].mean())
    totals = np.array([m[mask].sum() for m in maps])
    ratio = totals / totals.mean()
    k = args.seeds
    bins = [compare.bin_means(m, mask, 4) for m in maps]
    rms = np.sqrt(np.mean(np.mean(bins, axis=0) ** 2))
    noise = []
    for i in range(k):
        others = np.mean([bins[j] for j in range(k) if j != i], axis=0)
        # Var(x_i - mean of the others) = s^2 (1 + 1/(k-1)) = s^2 k/(k-1): one bake's noise s.
        noise.append(float(np.sqrt(np.mean((bins[i] - others) ** 2)) / rms * np.sqrt((k - 1) / k)))
    commit = compare.git_commit(args.irbake)
    date = datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%MZ")
    rows = [{"date": date, "commit": commit, "scene": args.name, "options": args.opts.strip(), "seed": i,
             "wall_s": round(walls[i], 2), "load_1min": round(loads[i], 2), "texels_kept": int(mask.sum()),
             "total_ratio": round(float(ratio[i]), 5), "seed_noise_4": round(noise[i], 5)} for i in range(k)]
    rows.append({"date": date, "commit": commit, "scene": args.name, "options": args.opts.strip(), "seed": "all",
                 "wall_s": round(float(np.median(walls)), 2), "load_1min": round(max(loads), 2),
                 "texels_kept": int(mask.sum()), "spread": round(float(ratio.max() - ratio.min()), 5),
                 "noise_rms": round(float(np.sqrt(np.mean(np.square(noise)))), 5)})
    print("total ratio %s: spread %.2f%%; seed noise 4x4 %s (RMS %.2f%%)" % (
        " ".join("%.4f" % r for r in ratio), 100 * (ratio.max() - ratio.min()),
        " ".join("%.2f%%" % (100 * n) for n in noise), 100 * rows[-1]["noise_rms"]))
    compare.append_csv_rows(args.csv, FIELDS, rows)


if __name__ == "__main__":
    main()
