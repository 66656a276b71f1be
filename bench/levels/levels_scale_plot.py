#!/usr/bin/python3
"""Time per stage and peak memory against texels x triangles, from levels_scale.sh's CSV.

usage: python3 bench/levels/levels_scale_plot.py bench/results/levels_scale.csv docs/levels_scale.png
One point per one-machine bake (the latest run of each scene name; shards + merge rows are left out), log-log;
lines join the town ladder, open squares are the lamp series and Sponza.
Left: the seconds of each stage that takes at least 2% of some bake (backend includes its shadow edges,
compensation its trace), and the CPU seconds of the whole process.
Right: peak resident memory. The dotted line has slope 1 (time or memory proportional to texels x
triangles). Prints each stage's log-log slope against triangles, texels and texels x lights over the town
ladder (town4 ... town32): a slope above 1 grows faster than linear in that measure of the level's size.
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")  # headless
import matplotlib.pyplot as plt  # noqa: E402

STAGES = ["atlas", "texels", "vpls", "backend", "shadowEdges", "sky", "compensation", "finalGather", "probes",
          "post", "export"]
TOWNS = ("town4", "town8", "town16", "town32")


def slope(xs, ys):
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y > 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else float("nan")


def latest(rows):
    best = {}
    for r in rows:
        if "--shard" in r["options"]:
            continue
        if r["scene"] not in best or r["date"] >= best[r["scene"]]["date"]:
            best[r["scene"]] = r
    return sorted(best.values(), key=lambda r: int(r["texels"]) * int(r["triangles"]))


def main(src, dst):
    rows = latest(list(csv.DictReader(open(src))))
    if not rows:
        sys.exit("levels_scale_plot: no one-machine rows in " + src)
    size = [int(r["texels"]) * int(r["triangles"]) for r in rows]
    town = [i for i, r in enumerate(rows) if r["scene"] in TOWNS]
    rest = [i for i, r in enumerate(rows) if r["scene"] not in TOWNS]
    pick = lambda values, idx: [values[i] for i in idx]
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(14, 5.5))
    shown = [s for s in STAGES if any(float(r[s + "_s"]) >= 0.02 * float(r["wall_s"]) for r in rows)]
    for s in shown:
        ys = [max(float(r[s + "_s"]), 1e-2) for r in rows]
        color = ax.plot(pick(size, town), pick(ys, town), "o-", label=s)[0].get_color()
        ax.plot(pick(size, rest), pick(ys, rest), "s", color=color, mfc="none")
    cpu = [float(r["cpu_s"]) for r in rows]
    ax.plot(pick(size, town), pick(cpu, town), "k^--", label="CPU seconds (process)")
    ax.plot(pick(size, rest), pick(cpu, rest), "k^", mfc="none")
    for r, x, y in zip(rows, size, cpu):
        ax.annotate(r["scene"], (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ref = [cpu[0] * x / size[0] for x in size]
    ax.plot(size, ref, "k:", alpha=0.4, label="slope 1")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("atlas texels × triangles")
    ax.set_ylabel("seconds (wall clock per stage; CPU for the process)")
    ax.set_title("Time per stage")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    mem = [float(r["peak_mib"]) for r in rows]
    ax2.plot(size, mem, "o-", label="peak resident memory")
    for r, x, y in zip(rows, size, mem):
        ax2.annotate(r["scene"], (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax2.plot(size, [mem[0] * x / size[0] for x in size], "k:", alpha=0.4, label="slope 1")
    ax2.axhline(16384, color="r", ls="--", alpha=0.5, label="16 GiB")
    ax2.set_xscale("log")
    ax2.set_yscale("log")
    ax2.set_xlabel("atlas texels × triangles")
    ax2.set_ylabel("MiB")
    ax2.set_title("Peak memory")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    print("wrote", dst)
    towns = [r for r in rows if r["scene"] in TOWNS]
    if len(towns) >= 2:
        tris = [int(r["triangles"]) for r in towns]
        tex = [int(r["texels"]) for r in towns]
        lit = [int(r["texels"]) * int(r["lights"]) for r in towns]
        print("log-log slope over %s: stage: against triangles / texels / texels x lights" %
              " ".join(r["scene"] for r in towns))
        for s in STAGES + ["cpu", "peak_mib"]:
            col = s if s == "peak_mib" else s + "_s"
            ys = [float(r[col]) for r in towns]
            print("  %-13s %5.2f / %5.2f / %5.2f" % (s, slope(tris, ys), slope(tex, ys), slope(lit, ys)))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
