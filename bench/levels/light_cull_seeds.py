#!/usr/bin/python3
"""light_cull_seeds.py IRBAKE OUTROOT SCENE [--seeds 0,1,2,3,4]: the culled bake against brute force, per seed.

For each seed the scene is baked twice with the same options and seed: brute force (--light-cull 0, every light
whole in every stage) and culled (--light-cull 0.01, the default: lights without range cut at their reach, the
rest sampled back by the light tail). `irbake diff --json` of the two (relative RMSE and mean bias over the
valid texels, weighted by surface area) goes into bench/results/light_cull_seeds.csv, one row per seed. A brute
force bake already in OUTROOT (report.json present, same options and seed) is kept unless --rebake.

  python3 bench/levels/town.py /tmp/town16r0.glb --blocks 16 --lamps 1000 --range 0
  /usr/bin/python3 bench/levels/light_cull_seeds.py build/baker/irbake /tmp/seeds /tmp/town16r0.glb --name town16r0
"""
import argparse
import datetime
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cycles"))
import compare  # noqa: E402  (append_csv_rows)

FIELDS = ["date", "commit", "scene", "texels", "seed", "cull", "rel_rmse_vs_brute", "rel_bias_vs_brute", "options"]
OPTIONS = ["--quality", "preview", "--sun", "0.35,-1,0.2,5", "--sky", "0.4,0.5,0.7", "--texels-per-unit", "0.7"]


def bake(irbake, scene, out, cull, seed, rebake):
    options = OPTIONS + ["--light-cull", str(cull), "--seed", str(seed)]
    report = os.path.join(out, "report.json")
    if not rebake and os.path.isfile(report):
        return json.load(open(report))
    subprocess.run([irbake, "bake", scene, "-o", out, "--quiet"] + options, check=True)
    return json.load(open(report))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("irbake")
    ap.add_argument("outroot")
    ap.add_argument("scene")
    ap.add_argument("--name", default="town16r0")
    ap.add_argument("--seeds", default="0,1,2,3,4")
    ap.add_argument("--cull", type=float, default=0.01)
    ap.add_argument("--rebake", action="store_true", help="bake brute force again even where a bake is there")
    ap.add_argument("--csv", default="bench/results/light_cull_seeds.csv")
    args = ap.parse_args()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    rows = []
    for seed in [int(s) for s in args.seeds.split(",")]:
        brute = os.path.join(args.outroot, "brute-seed%d" % seed)
        culled = os.path.join(args.outroot, "culled-seed%d" % seed)
        bake(args.irbake, args.scene, brute, 0, seed, args.rebake)
        bake(args.irbake, args.scene, culled, args.cull, seed, True)
        p = subprocess.run([args.irbake, "diff", "--json", culled, brute], capture_output=True, text=True, check=True)
        figures = json.loads(p.stdout)
        rows.append({"date": datetime.date.today().isoformat(), "commit": commit, "scene": args.name,
                     "texels": figures["texels"], "seed": seed, "cull": args.cull,
                     "rel_rmse_vs_brute": "%.5f" % figures["relativeRmse"],
                     "rel_bias_vs_brute": "%.5f" % figures["relativeBias"],
                     "options": " ".join(OPTIONS + ["--light-cull", str(args.cull)]) + " (brute force: 0)"})
        print("seed %d: %.3f%% relative RMSE, %.3f%% relative bias" % (seed, 100 * figures["relativeRmse"],
                                                                       100 * figures["relativeBias"]))
    compare.append_csv_rows(args.csv, FIELDS, rows)


if __name__ == "__main__":
    main()
