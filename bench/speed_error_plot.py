#!/usr/bin/python3
"""Time against error, log-log, from speed_error_bench's CSV (one line per scene and backend).

usage: python3 bench/speed_error_plot.py bench/results/speed_error.csv docs/performance.png [BEFORE.csv]
BEFORE.csv (optional, e.g. bench/results/speed_error_session1.csv) is drawn dashed and faded: the
estimator of an earlier version on the same scenes.
x: backend seconds (the VPL evaluation: GL or Embree), y: relative RMSE against the reference with the
reference's own noise removed (column relative_rmse_corrected). Points are labelled with N (paths).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")  # headless
import matplotlib.pyplot as plt  # noqa: E402


def load(src):
    series = {}
    for r in csv.DictReader(open(src)):
        if not r["relative_rmse_corrected"]:
            continue  # timing-only rows (no reference)
        series.setdefault((r["scene"], r["backend"]), []).append(r)
    return series


def main(src, dst, before=None):
    fig, ax = plt.subplots(figsize=(8, 5.5))
    markers = {"gl": "o", "embree": "s"}
    sets = [(load(src), "-", 1.0, "")]
    if before:
        sets.append((load(before), "--", 0.35, " (before)"))
    for series, style, alpha, suffix in sets:
        for (scene, backend), rs in sorted(series.items()):
            rs.sort(key=lambda r: int(r["paths"]))
            xs = [float(r["backend_s"]) for r in rs]
            ys = [max(float(r["relative_rmse_corrected"]), 1e-4) for r in rs]
            ax.plot(xs, ys, style, marker=markers.get(backend, "x"), alpha=alpha, label=f"{scene}, {backend}{suffix}")
            if not suffix:
                for r, x, y in zip(rs, xs, ys):
                    ax.annotate(r["paths"], (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("backend time (s, wall clock)")
    ax.set_ylabel("relative RMSE vs reference (noise-corrected)")
    ax.set_title("Speed against error (labels: N light paths)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(dst, dpi=120)
    print("wrote", dst)


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    main(*sys.argv[1:])
