#!/usr/bin/python3
"""Markdown tables from bench/cycles/compare.py's CSVs (the latest run of each scene, mode, view, options).

usage: /usr/bin/python3 bench/cycles/table.py bench/results/cycles_*.csv

Prints (1) ours against Cycles per scene, mode and view; (2) for maps, Cycles' bake time at our error: the
Cycles spp ladder's (time, noise-corrected error) points interpolated log-log at our bake's corrected error
(extrapolated along the last two points, marked "~", when our error lies outside the ladder).
"""
import csv
import math
import sys


def pct(x):
    return "%.2f%%" % (100 * float(x))


def latest(rows, key):
    out = {}
    for r in rows:
        out[key(r)] = r  # later rows win
    return list(out.values())


def time_at(ladder, err):
    pts = sorted((float(r["rel_rmse_4_corrected"]), float(r["cycles_s"]), int(r["cycles_spp"])) for r in ladder)
    pts = [p for p in pts if p[0] > 0]
    if len(pts) < 2 or err <= 0:
        return None, ""
    # error falls with time: walk from the most accurate
    for (e0, t0, _), (e1, t1, _) in zip(pts, pts[1:]):
        if e0 <= err <= e1:
            f = (math.log(err) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))), ""
    (e0, t0, _), (e1, t1, _) = (pts[0], pts[1]) if err < pts[0][0] else (pts[-2], pts[-1])
    f = (math.log(err) - math.log(e0)) / (math.log(e1) - math.log(e0))
    return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))), "~"


def main(paths):
    rows = [r for p in paths for r in csv.DictReader(open(p))]
    rows = latest(rows, lambda r: (r["scene"], r["mode"], r["view"], r["our_options"], r["cycles_spp"]))
    print("| scene | mode | view | our options | our time (s) | mean ratio | rel. RMSE 4×4 | 8×8 | Cycles noise 4×4 | "
          "4×4, noise removed | 4×4 with edges | Cycles spp | commit |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r["mode"] == "map-cycles":
            continue
        print("| %s | %s | %s | %s | %s | %.4f | %s | %s | %s | %s | %s | %s | %s |" % (
            r["scene"], r["mode"], r["view"], r["our_options"] or "default", r["our_wall_s"], float(r["mean_ratio"]),
            pct(r["rel_rmse_4"]), pct(r["rel_rmse_8"]), pct(r["ref_noise_4"]), pct(r["rel_rmse_4_corrected"]),
            pct(r["rel_rmse_4_with_edges"]) if r.get("rel_rmse_4_with_edges") else "", r["ref_spp"], r["commit"]))
    print()
    print("| scene | Cycles spp | Cycles bake (s) | rel. RMSE 4×4 vs reference | noise removed | mean ratio |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        if r["mode"] == "map-cycles":
            print("| %s | %s | %s | %s | %s | %.4f |" % (r["scene"], r["cycles_spp"], r["cycles_s"], pct(r["rel_rmse_4"]),
                                                      pct(r["rel_rmse_4_corrected"]), float(r["mean_ratio"])))
    print()
    print("| scene | our options | our bake, wall (s) | our error (4×4, noise removed) | Cycles' bake at that error (s) | ratio |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        if r["mode"] != "map":
            continue
        ladder = [c for c in rows if c["mode"] == "map-cycles" and c["scene"] == r["scene"]]
        t, mark = time_at(ladder, float(r["rel_rmse_4_corrected"]))
        if t is None:
            continue
        print("| %s | %s | %s | %s | %s%.1f | %s%.2f× |" % (r["scene"], r["our_options"] or "default", r["our_wall_s"],
                                                       pct(r["rel_rmse_4_corrected"]), mark, t, mark,
                                                       t / float(r["our_wall_s"])))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
