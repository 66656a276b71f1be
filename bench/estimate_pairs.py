#!/usr/bin/python3
"""Bakes of one scene at several seeds, each pair's difference against the root sum of squares of their estimates.

usage (repository root; Debian's /usr/bin/python3 with python3-numpy and python3-openimageio):
  /usr/bin/python3 bench/estimate_pairs.py --name NAME BAKE_FOLDER... [--csv bench/results/estimate_pairs.csv]
      [--label TEXT]

Each folder holds one bake (lightmap_<page>.exr and report.json) of the same scene and options at its own seed,
made with --estimate-error, e.g. for the Sponza row:
  for s in 0 1 2 3 4; do build/baker/irbake bake ../shared/scenes/dabrovic_sponza/sponza.glb -o build/pairs/s$s \\
      --quality preview --sun 0.35,-1,0.2,5 --estimate-error --seed $s --no-gltf --no-dilate; done
Every pair is scored as bench/scenarios/day_night.py scores its pairs (relative RMS over 4x4-texel bins of the
texels either bake covers, bins at least half covered) and divided by hypot(e1, e2) of the bakes' estimatedError:
near 1 when each bake's figure holds its seed-to-seed noise. Baked with --no-dilate the covered texels are the
valid ones, as the estimate's bins hold; without it the dilation's padding is scored as well (docs/units.md,
"Estimated error"). One row per pair and a summary row ("all": the RMS of the pairs' ratios) are appended.
"""
import argparse
import datetime
import itertools
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenarios"))
import day_night  # noqa: E402  (pages, score)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "cycles"))
import compare  # noqa: E402  (append_csv_rows)

FIELDS = ["date", "commit", "scene", "label", "pair", "seeds", "rel_rmse_4", "expected", "ratio"]


def bake_info(folder):
    r = json.load(open(os.path.join(folder, "report.json")))
    return r["vpls"]["seed"], r["estimatedError"]["relative"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folders", nargs="+")
    ap.add_argument("--name", required=True)
    ap.add_argument("--label", default="", help="what the bakes were made with (the options besides --seed)")
    ap.add_argument("--csv", default="bench/results/estimate_pairs.csv")
    args = ap.parse_args()
    if len(args.folders) < 2:
        sys.exit("estimate_pairs.py: give at least two bake folders")
    info = [bake_info(f) for f in args.folders]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    date = datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%MZ")
    rows, ratios = [], []
    for (i, a), (j, b) in itertools.combinations(enumerate(args.folders), 2):
        err = day_night.score(day_night.pages(a), day_night.pages(b))
        expected = math.hypot(info[i][1], info[j][1])
        ratios.append(err / expected)
        rows.append({"date": date, "commit": commit, "scene": args.name, "label": args.label, "pair": "%d-%d" % (i, j),
                     "seeds": "%d,%d" % (info[i][0], info[j][0]), "rel_rmse_4": "%.5f" % err,
                     "expected": "%.5f" % expected, "ratio": "%.3f" % ratios[-1]})
        print("seeds %d and %d: %.4f against %.4f expected, ratio %.3f" % (info[i][0], info[j][0], err, expected,
                                                                            ratios[-1]))
    rms = math.sqrt(sum(r * r for r in ratios) / len(ratios))
    rows.append({"date": date, "commit": commit, "scene": args.name, "label": args.label, "pair": "all",
                 "seeds": ",".join(str(x[0]) for x in info), "ratio": "%.3f" % rms})
    print("ratio %.3f-%.3f over %d pairs, RMS %.3f" % (min(ratios), max(ratios), len(ratios), rms))
    compare.append_csv_rows(args.csv, FIELDS, rows)


if __name__ == "__main__":
    main()
