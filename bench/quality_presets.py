#!/usr/bin/env python3
"""Time and peak memory of each --quality preset on one scene: RUNS bakes each, the median wall time and the
largest peak memory (report.json) appended to bench/results/quality_presets.csv. The error of each preset against
Cycles comes from bench/cycles/compare.py (--opts "--quality NAME"); docs/validation.md joins the two.

usage: quality_presets.py IRBAKE SCENE NAME [RUNS] [-- EXTRA BAKE OPTIONS]"""
import csv
import datetime
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

PRESETS = ["preview", "default", "high", "production"]


def main():
    args = sys.argv[1:]
    extra = []
    if "--" in args:
        extra = args[args.index("--") + 1:]
        args = args[:args.index("--")]
    if len(args) < 3:
        sys.exit(__doc__)
    irbake, scene, name = args[:3]
    runs = int(args[3]) if len(args) > 3 else 3
    here = os.path.dirname(os.path.abspath(__file__))
    commit = subprocess.run(["git", "-C", here, "rev-parse", "--short=7", "HEAD"], capture_output=True, text=True).stdout.strip()
    rows = []
    for preset in PRESETS:
        walls, memory, texels = [], 0.0, 0
        for _ in range(runs):
            with tempfile.TemporaryDirectory() as out:
                start = time.monotonic()
                subprocess.run([irbake, "bake", scene, "-o", out, "--quality", preset, "--quiet"] + extra, check=True,
                               stdout=subprocess.DEVNULL)
                walls.append(time.monotonic() - start)
                with open(os.path.join(out, "report.json")) as f:
                    report = json.load(f)
                memory = max(memory, report["timings"]["memoryPeakMiB"])
                texels = sum(p["width"] * p["height"] for p in report["atlas"]["pages"])
        rows.append({"date": datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%MZ"), "commit": commit, "scene": name,
                     "options": " ".join(extra), "preset": preset, "runs": runs, "page_texels": texels,
                     "median_wall_s": f"{statistics.median(walls):.2f}", "peak_memory_mib": f"{memory:.0f}",
                     "load_average": f"{os.getloadavg()[0]:.2f}"})
        print(rows[-1])
    path = os.path.join(here, "results", "quality_presets.csv")
    new = not os.path.exists(path)
    with open(path, "a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()), lineterminator="\n")
        if new:
            writer.writeheader()
        writer.writerows(rows)


if __name__ == "__main__":
    main()
