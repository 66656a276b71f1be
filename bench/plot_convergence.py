#!/usr/bin/python3
"""Log-log convergence plot from light_convergence_bench's CSV (series,n,relative_rmse).

usage: python3 bench/plot_convergence.py bench/results/light_convergence.csv docs/convergence.png
Fits the log-log slope of each series (least squares) and prints it; the legend shows it too.
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")  # headless
import matplotlib.pyplot as plt  # noqa: E402

LABELS = {
    "vpl_halton": "VPLs, Keller's quasi-random walk (Halton)",
    "vpl_random": "VPLs at random points (RMS of 8 sets)",
    "reference_spp": "reference path tracer (paths per texel)",
}


def slope(ns, errs):
    xs = [math.log(n) for n in ns]
    ys = [math.log(e) for e in errs]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxy = sum((x - mx) * (y - my) for x, y in zip(xs, ys))
    sxx = sum((x - mx) ** 2 for x in xs)
    return sxy / sxx


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    series = {}
    with open(sys.argv[1], newline="") as f:
        for row in csv.DictReader(f):
            series.setdefault(row["series"], []).append((int(row["n"]), float(row["relative_rmse"])))
    fig, ax = plt.subplots(figsize=(7, 4.8), dpi=120)
    for name, points in series.items():
        points.sort()
        ns, errs = [p[0] for p in points], [p[1] for p in points]
        s = slope(ns, errs)
        print(f"{name}: slope {s:.3f}")
        ax.loglog(ns, errs, marker="o", label=f"{LABELS.get(name, name)}: slope {s:.2f}")
    ax.axhline(0.01, color="grey", linestyle=":", linewidth=1)
    ax.set_xlabel("N (VPLs, or paths per texel for the reference)")
    ax.set_ylabel("relative RMSE vs closed form")
    ax.set_title("Square emitter over a parallel plane: error against N")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    tmp = sys.argv[2] + ".tmp.png"
    fig.savefig(tmp)
    os.replace(tmp, sys.argv[2])  # no half-written plot under the final name
    return 0


if __name__ == "__main__":
    sys.exit(main())
