#!/usr/bin/env python3
"""Time and peak memory of each --quality preset on one scene: RUNS bakes each, the median wall time and the
largest peak memory (report.json) appended to bench/results/quality_presets.csv. The error of each preset against
Cycles comes from bench/cycles/compare.py (--opts "--quality NAME"); docs/validation.md joins the two.

usage: quality_presets.py IRBAKE SCENE NAME [RUNS] [--quiet-load L] [--max-wait-minutes M] [-- EXTRA BAKE OPTIONS]

On a shared machine every run waits until the 1-minute load average is below L (default 1.5; checked every
60 s, at most M minutes in all, default 40; then it runs anyway). Columns: load_before_runs, the largest
1-minute load average as a run started (other work on the machine); load_average, the one after the preset's
runs (the bakes' own threads included)."""
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


class QuietMachine:
    """Waits for the 1-minute load average to fall below a threshold, within one budget for the whole bench."""

    def __init__(self, threshold, budget_s):
        self.threshold, self.deadline = threshold, time.monotonic() + budget_s

    def wait(self):
        while os.getloadavg()[0] >= self.threshold and time.monotonic() < self.deadline:
            print(f"quality_presets: load {os.getloadavg()[0]:.2f} >= {self.threshold}: waiting 60 s", flush=True)
            time.sleep(60)
        return os.getloadavg()[0]


def take(args, name, default):
    if name in args:
        i = args.index(name)
        value = args[i + 1]
        del args[i:i + 2]
        return value
    return default


def main():
    args = sys.argv[1:]
    extra = []
    if "--" in args:
        extra = args[args.index("--") + 1:]
        args = args[:args.index("--")]
    quiet = QuietMachine(float(take(args, "--quiet-load", "1.5")), 60.0 * float(take(args, "--max-wait-minutes", "40")))
    if len(args) < 3:
        sys.exit(__doc__)
    irbake, scene, name = args[:3]
    runs = int(args[3]) if len(args) > 3 else 3
    here = os.path.dirname(os.path.abspath(__file__))
    commit = subprocess.run(["git", "-C", here, "rev-parse", "--short=7", "HEAD"], capture_output=True, text=True).stdout.strip()
    rows = []
    for preset in PRESETS:
        walls, memory, texels, load_before = [], 0.0, 0, 0.0
        for _ in range(runs):
            load_before = max(load_before, quiet.wait())
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
                     "load_average": f"{os.getloadavg()[0]:.2f}", "load_before_runs": f"{load_before:.2f}"})
        print(rows[-1], flush=True)
    path = os.path.join(here, "results", "quality_presets.csv")
    old = list(csv.DictReader(open(path, newline=""))) if os.path.exists(path) else []
    fields = list(dict.fromkeys([k for r in old for k in r] + list(rows[0].keys())))
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:  # rewritten whole: older rows may lack newer columns
        writer = csv.DictWriter(f, fieldnames=fields, lineterminator="\n")
        writer.writeheader()
        writer.writerows(old + rows)
    os.replace(tmp, path)


if __name__ == "__main__":
    main()
