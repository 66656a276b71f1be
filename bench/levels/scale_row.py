#!/usr/bin/env python3
"""scale_row.py: one row of bench/results/levels_scale.csv from a finished bake (or shards + merge).

  scale_row.py CSV --report R.json --time T.txt [--time T2.txt ...] --log L.txt [--log L2.txt ...]
               --scene NAME --blocks B --options "..." --run K --wall S --commit C --load-start A

--time: `/usr/bin/time -v` outputs (one per process: shards and merge give several; cpu_s adds them, peak_mib
takes the largest). --log: the bakes' logs; export_s adds their "(+ S s writing)". Writes the header when the
CSV is new; the column set is fixed (a stage the bake did not run reads 0).
"""
import argparse
import datetime
import json
import os
import re

STAGES = ["load", "atlas", "raytrace", "texels", "vpls", "vplImportance", "backend", "shadowEdges", "sky",
          "compensation", "compensationTrace", "finalGather", "errorEstimate", "shadowMask", "shadowMaskPost",
          "directional", "post", "probes", "bake"]
COLUMNS = (["date", "commit", "scene", "blocks", "triangles", "lights", "options", "run", "wall_s", "cpu_s",
            "peak_mib", "texels", "texels_valid", "texels_per_m", "pages"] + [s + "_s" for s in STAGES] +
           ["export_s", "load_avg_start", "load_avg_end"])


def time_v(path):
    """(user + system seconds, max resident MiB) from a `/usr/bin/time -v` output."""
    text = open(path).read()
    field = lambda name: float(re.search(re.escape(name) + r":\s*([0-9.]+)", text).group(1))
    return field("User time (seconds)") + field("System time (seconds)"), field("Maximum resident set size (kbytes)") / 1024.0


def writing_seconds(path):
    found = re.findall(r"\(\+ ([0-9.]+) s writing\)", open(path, errors="replace").read())
    return float(found[-1]) if found else 0.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--report", required=True)
    ap.add_argument("--time", action="append", required=True)
    ap.add_argument("--log", action="append", default=[])
    for name in ("scene", "blocks", "options", "run", "wall", "commit", "load-start"):
        ap.add_argument("--" + name, required=True)
    a = ap.parse_args()
    r = json.load(open(a.report))
    seconds = r["timings"]["seconds"]
    measured = [time_v(t) for t in a.time]
    pages = r["atlas"]["pages"]
    row = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%MZ"),
        "commit": a.commit, "scene": a.scene, "blocks": a.blocks, "triangles": r["scene"]["triangles"],
        "lights": r["scene"]["lights"], "options": '"%s"' % a.options, "run": a.run, "wall_s": a.wall,
        "cpu_s": round(sum(c for c, _ in measured), 1), "peak_mib": round(max(m for _, m in measured)),
        "texels": sum(p["width"] * p["height"] for p in pages), "texels_valid": r["texels"]["valid"],
        "texels_per_m": round(r["atlas"]["texelsPerUnit"], 2), "pages": len(pages),
        "export_s": round(sum(writing_seconds(l) for l in a.log), 2),
        "load_avg_start": a.load_start, "load_avg_end": round(os.getloadavg()[0], 2),
    }
    for s in STAGES:
        row[s + "_s"] = round(seconds.get(s, 0.0), 2)
    new = not os.path.exists(a.csv) or os.path.getsize(a.csv) == 0
    line = ",".join(str(row[c]) for c in COLUMNS)
    with open(a.csv, "a") as f:
        if new:
            f.write(",".join(COLUMNS) + "\n")
        f.write(line + "\n")
    print(line)


if __name__ == "__main__":
    main()
