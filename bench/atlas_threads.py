#!/usr/bin/env python3
"""The atlas stage's time at a thread count: `irbake unwrap SCENE --threads N`, the median of --runs, appended
to bench/results/atlas_threads.csv with the machine's load and the unwrapped file's hash (the same for any
thread count).

usage (repository root, after building irbake):
  python3 bench/atlas_threads.py --scene ../shared/scenes/dabrovic_sponza/sponza.glb --threads 1 --runs 5
  --irbake PATH: the binary (default build/baker/irbake)
  --pin-cpu N: run on one CPU (taskset) instead of --threads, for a baker without the option
  --machine TEXT: what ran it (default: "<cores>-core <CPU model>")
  --baker COMMIT: the commit the binary was built from (default: this checkout's)
The CPU time is the whole unwrap process's (user + sys: loading, the atlas, writing).
"""
import argparse
import csv
import datetime
import hashlib
import json
import os
import resource
import statistics
import subprocess
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
CSV = os.path.join(HERE, "results", "atlas_threads.csv")
FIELDS = ["date", "machine", "baker", "scene", "charts", "threads", "runs", "median_atlas_s",
          "median_pack_s", "median_cpu_s", "median_wall_s", "load_average", "output_md5"]


def cpu_model():
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return "unknown CPU"


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def one_run(cmd, out, report):
    cpu0, t0 = children_cpu(), time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall, cpu = time.monotonic() - t0, children_cpu() - cpu0
    with open(report) as f:
        r = json.load(f)
    s = r["seconds"]
    # Older bakers report no total: their stages ran one after the other, so their sum is the stage's wall.
    atlas = s.get("total", sum(s.values()))
    with open(out, "rb") as f:
        digest = hashlib.md5(f.read()).hexdigest()[:12]
    return atlas, s["pack"], cpu, wall, digest, r


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", required=True)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--irbake", default="build/baker/irbake")
    p.add_argument("--pin-cpu", type=int)
    p.add_argument("--machine", default=f"{os.cpu_count()}-core {cpu_model()}")
    p.add_argument("--baker", help="the commit the binary was built from (default: this checkout's)")
    p.add_argument("--csv", default=CSV)
    a = p.parse_args()
    baker = a.baker or subprocess.run(["git", "-C", HERE, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    with tempfile.TemporaryDirectory() as tmp:
        out, report = os.path.join(tmp, "out.glb"), os.path.join(tmp, "report.json")
        cmd = [a.irbake, "unwrap", a.scene, "-o", out, "--report", report]
        if a.pin_cpu is not None:
            cmd = ["taskset", "-c", str(a.pin_cpu)] + cmd
        elif a.threads > 0:
            cmd += ["--threads", str(a.threads)]
        runs = [one_run(cmd, out, report) for _ in range(max(1, a.runs))]
    digests = sorted({r[4] for r in runs})
    last = runs[-1][5]
    row = {
        "date": datetime.date.today().isoformat(), "machine": a.machine, "baker": baker,
        "scene": os.path.splitext(os.path.basename(a.scene))[0],
        "charts": last["charts"]["total"], "threads": 1 if a.pin_cpu is not None else a.threads, "runs": len(runs),
        "median_atlas_s": f"{statistics.median(r[0] for r in runs):.3f}",
        "median_pack_s": f"{statistics.median(r[1] for r in runs):.3f}",
        "median_cpu_s": f"{statistics.median(r[2] for r in runs):.3f}",
        "median_wall_s": f"{statistics.median(r[3] for r in runs):.3f}",
        "load_average": f"{os.getloadavg()[0]:.2f}", "output_md5": " ".join(digests),
    }
    new = not os.path.exists(a.csv)
    with open(a.csv, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        if new:
            w.writeheader()
        w.writerow(row)
    print(row)


if __name__ == "__main__":
    main()
