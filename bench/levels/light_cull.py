#!/usr/bin/env python3
"""light_cull.py IRBAKE OUTROOT CASE... [--runs N] [--csv bench/results/light_cull.csv]: the lamp targets.

Each CASE is NAME=SCENE.glb:LAMPS:RANGE:CULL[:TAIL] (CULL: --light-cull's fraction, 0 = brute force; TAIL:
--light-tail's draws per texel, the binary's default when left out). Every case is
baked at --quality preview with --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7, each run under /usr/bin/time -v (CPU =
user + sys), and one row per run goes into the CSV: the wall and CPU seconds, the report's seconds per stage,
the load average when it started, and, for a culled case whose brute-force twin (same scene, CULL 0) was baked
before it, `irbake diff`'s relative RMSE against that twin's first run.

  python3 bench/levels/town.py build/levels/town16.glb --blocks 16 --lamps 1000
  python3 bench/levels/light_cull.py build/baker/irbake /tmp/cull town16=build/levels/town16.glb:1000:15:0.01
"""
import argparse
import csv
import datetime
import json
import os
import re
import subprocess

FIELDS = ["date", "commit", "scene", "lamps", "range", "cull", "tail", "run", "wall_s", "cpu_s", "texels", "stage_seconds",
          "load_avg", "rel_rmse_vs_brute"]
BAKE = ["--quality", "preview", "--sun", "0.35,-1,0.2,5", "--sky", "0.4,0.5,0.7", "--quiet"]


def timed_bake(irbake, scene, out, cull, tail, tpu):
    cmd = ["/usr/bin/time", "-v", irbake, "bake", scene, "-o", out, "--light-cull", str(cull)] + BAKE
    if tail != "":
        cmd += ["--light-tail", tail]
    if tpu:
        cmd += ["--texels-per-unit", str(tpu)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit("bake failed: %s\n%s" % (" ".join(cmd), p.stderr[-2000:]))
    get = lambda key: float(re.search(re.escape(key) + r":\s*([0-9.]+)", p.stderr).group(1))
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\):\s*([0-9:.]+)", p.stderr).group(1)
    seconds = 0.0
    for part in wall.split(":"):
        seconds = seconds * 60.0 + float(part)
    return seconds, get("User time (seconds)") + get("System time (seconds)")


def rel_rmse(irbake, a, b):
    p = subprocess.run([irbake, "diff", "--json", a, b], capture_output=True, text=True, check=True)
    figures = json.loads(p.stdout)
    for key in ("relativeRmse", "relative_rmse", "relRmse"):
        if key in figures:
            return figures[key]
    return figures


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("irbake")
    ap.add_argument("outroot")
    ap.add_argument("cases", nargs="+")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--texels-per-unit", type=float, default=0.0,
                    help="one density for every case (the sun-only town has no lamp posts, so fewer triangles)")
    ap.add_argument("--csv", default="bench/results/light_cull.csv")
    ap.add_argument("--brute", action="append", default=[], metavar="SCENE=DIR",
                    help="an earlier brute-force bake of SCENE (its output folder) to measure the error against")
    args = ap.parse_args()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    new = not os.path.exists(args.csv)
    brute = dict(b.split("=", 1) for b in args.brute)
    with open(args.csv, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        if new:
            w.writeheader()
        for case in args.cases:
            name, spec = case.split("=", 1)
            parts = spec.split(":")
            scene, lamps, rng, cull = parts[:4]
            tail = parts[4] if len(parts) > 4 else ""
            for run in range(1, args.runs + 1):
                out = os.path.join(args.outroot, "%s-cull%s-tail%s-run%d" % (name, cull, tail or "d", run))
                load = os.getloadavg()[0]
                wall, cpu = timed_bake(args.irbake, scene, out, cull, tail, args.texels_per_unit)
                report = json.load(open(os.path.join(out, "report.json")))
                if tail == "":
                    tail = str(report.get("lightTail", {}).get("samples", ""))
                stages = report["timings"]["seconds"]
                if float(cull) == 0.0 and run == 1:
                    brute[scene] = out
                err = ""
                if float(cull) > 0.0 and scene in brute:
                    err = rel_rmse(args.irbake, out, brute[scene])
                w.writerow({"date": datetime.date.today().isoformat(), "commit": commit, "scene": name,
                            "lamps": lamps, "range": rng, "cull": cull, "tail": tail, "run": run, "wall_s": "%.1f" % wall,
                            "cpu_s": "%.1f" % cpu, "texels": report.get("texels", {}).get("valid", ""),
                            "stage_seconds": ";".join("%s=%.1f" % (k, v) for k, v in sorted(stages.items())),
                            "load_avg": "%.2f" % load, "rel_rmse_vs_brute": err})
                f.flush()
                print("%s cull %s tail %s run %d: wall %.1f s, cpu %.1f s, load %.1f %s" % (name, cull, tail, run, wall, cpu, load,
                                                                                  err))


if __name__ == "__main__":
    main()
