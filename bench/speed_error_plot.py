#!/usr/bin/python3
"""Time against error, log-log, from speed_error_bench's CSV (one line per scene and backend).

usage: python3 bench/speed_error_plot.py bench/results/speed_error.csv docs/performance.png [BEFORE.csv]
                                         [--cycles bench/results/cycles_X.csv ...]
BEFORE.csv (optional, e.g. bench/results/speed_error_gl_fixed_faces.csv) is drawn dashed and faded: an
earlier estimator or backend on the same scenes.
x: backend seconds (the VPL evaluation: GL or Embree), y: relative RMSE against the reference with the
reference's own noise removed (column relative_rmse_corrected). Points are labelled with N (paths).
--cycles (bench/cycles/compare.py's CSVs) adds a second panel: the error against Blender Cycles baked into
our own atlas (4x4-texel bins, Cycles' own noise removed: rel_rmse_4_corrected) against wall-clock time,
for our whole bake (irbake process, labelled with its options) and for Cycles' bake call at each spp of
its ladder (mode map-cycles, labelled with spp), both from one run on one machine.
"""
import argparse
import csv

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


def cycles_panel(ax, paths):
    for path in paths:
        rows = [r for r in csv.DictReader(open(path)) if r["mode"] in ("map", "map-cycles")]
        if not rows:
            continue
        last = rows[-1]["date"]  # the latest run only: one run, one machine
        scene = rows[-1]["scene"]
        rows = [r for r in rows if r["date"][:13] == last[:13]]
        ours = [r for r in rows if r["mode"] == "map"]
        cyc = sorted((r for r in rows if r["mode"] == "map-cycles"), key=lambda r: int(r["cycles_spp"]))
        if ours:
            xs = [float(r["our_wall_s"]) for r in ours]
            ys = [max(float(r["rel_rmse_4_corrected"]), 1e-4) for r in ours]
            line = ax.plot(xs, ys, "o", label=f"{scene}: irbake ({ours[0]['commit']})")[0]
            for r, x, y in zip(ours, xs, ys):
                ax.annotate(r["our_options"] or "default", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
            color = line.get_color()
        else:
            color = None
        if cyc:
            xs = [float(r["cycles_s"]) for r in cyc]
            ys = [max(float(r["rel_rmse_4_corrected"]), 1e-4) for r in cyc]
            ax.plot(xs, ys, "--", marker="^", color=color, label=f"{scene}: Cycles bake")
            for r, x, y in zip(cyc, xs, ys):
                ax.annotate(r["cycles_spp"] + " spp", (x, y), textcoords="offset points", xytext=(4, -9), fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall-clock time (s): our whole bake / Cycles' bake call")
    ax.set_ylabel("relative RMSE vs Cycles (4x4-texel bins, its noise removed)")
    ax.set_title("Against Blender Cycles, in our atlas")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)


def main(src, dst, before=None, cycles=None):
    if cycles:
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(14, 5.5))
        cycles_panel(ax2, cycles)
    else:
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
    ap = argparse.ArgumentParser(usage=__doc__)
    ap.add_argument("src")
    ap.add_argument("dst")
    ap.add_argument("before", nargs="?")
    ap.add_argument("--cycles", nargs="+", default=[])
    a = ap.parse_args()
    main(a.src, a.dst, a.before, a.cycles)
