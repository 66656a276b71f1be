#!/usr/bin/python3
"""Markdown tables from bench/cycles/compare.py's CSVs (the latest run of each scene, mode, view, options).

usage: /usr/bin/python3 bench/cycles/table.py bench/results/cycles_*.csv

Prints (1) ours against Cycles per scene, mode and view; (2) Cycles' spp ladder; (3) for maps, Cycles' bake
time at our error: the samples per texel Cycles needs for our bake's noise-corrected error (log-log
interpolation of its ladder's (spp, error); "~" = extrapolated along the nearest two points) times the
median cost of one sample per texel over all Cycles bakes of that page (ladder and reference halves: single
timings swing 2x with the shared machine's load); the last column interpolates the ladder's own timings.
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


def spp_at(ladder, err):
    """Samples per texel Cycles needs for `err`: log-log interpolation of its ladder's (spp, error)."""
    pts = sorted((int(r["cycles_spp"]), float(r["rel_rmse_4_corrected"])) for r in ladder)
    pts = [p for p in pts if p[1] > 0]
    if len(pts) < 2:
        return None, ""
    for (s0, e0), (s1, e1) in zip(pts, pts[1:]):
        if e1 <= err <= e0:
            f = (math.log(err) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(s0) + f * (math.log(s1) - math.log(s0))), ""
    (s0, e0), (s1, e1) = (pts[0], pts[1]) if err > pts[0][1] else (pts[-2], pts[-1])
    f = (math.log(err) - math.log(e0)) / (math.log(e1) - math.log(e0))
    return math.exp(math.log(s0) + f * (math.log(s1) - math.log(s0))), "~"


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
    print("| scene | our options | our bake, wall (s) | our error (4×4, noise removed) | Cycles spp for it | "
          "Cycles s per spp (median) | Cycles' bake at that error (s) | Cycles time / ours | ladder interpolation (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r["mode"] != "map":
            continue
        ladder = [c for c in rows if c["mode"] == "map-cycles" and c["scene"] == r["scene"]]
        err = float(r["rel_rmse_4_corrected"])
        spp, mark = spp_at(ladder, err)
        t, mark2 = time_at(ladder, err)
        if spp is None:
            continue
        # every Cycles bake of this page, ladder and reference halves: the median cost of one sample per texel
        per = sorted([float(c["cycles_s"]) / int(c["cycles_spp"]) for c in ladder] +
                     [float(r["ref_s"]) / int(r["ref_spp"])] * 2)
        med = per[len(per) // 2] if len(per) % 2 else 0.5 * (per[len(per) // 2 - 1] + per[len(per) // 2])
        print("| %s | %s | %s | %s | %s%.0f | %.2f | %s%.1f | %s%.2f× | %s%.1f |" % (
            r["scene"], r["our_options"] or "default", r["our_wall_s"], pct(err), mark, spp, med, mark, spp * med,
            mark, spp * med / float(r["our_wall_s"]), mark2, t))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
