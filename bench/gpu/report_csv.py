#!/usr/bin/python3
"""Rows of bench/results/gpu_*.csv from a device run's results folder (bench/gpu/README.md, step 3).

usage: python3 bench/gpu/report_csv.py RESULTS_DIR RUN [--header] [--scenes] >> bench/results/gpu_KIND.csv
RESULTS_DIR holds one folder per bake (TAG/report.json, as device_run.sh and device_scenes.sh write them);
RUN numbers the device call. The report does not hold the thread count; it comes from the tag: device_run.sh
tags SCENE_BACKEND_REPEAT (16 threads) and SCENE_BACKEND_2cpu_REPEAT (2), device_scenes.sh (--scenes)
SCENE_BACKEND_THREADS[_EXTRA].
"""
import json
import os
import sys

COLUMNS = ("run,tag,scene,backend,asked,threads,triangles,vpls,texels_valid,bake_s,backend_s,compensation_s,"
           "gather_s,peak_mib,gl_setup_s,gl_shadow_s,gl_fold_s,gl_contact_s,contact_fraction,cube_face")


def threads(tag, scenes):
    if "_2cpu" in tag:
        return 2
    parts = tag.split("_")
    if scenes and len(parts) > 2 and parts[2].isdigit():
        return int(parts[2])
    return 16


def row(run, tag, r, scenes):
    t, g = r["timings"], r.get("gl", {})
    sec, glt = t["seconds"], t.get("gl", {})
    gl = r["backend"] == "gl"
    f = lambda v: "%.4g" % v if isinstance(v, float) else str(v)
    vals = [run, tag, tag.split("_")[0], r["backend"], r["backendChoice"]["asked"], threads(tag, scenes),
            r["scene"]["triangles"], r["vpls"]["count"], r["texels"]["valid"], round(sec["bake"], 2),
            round(sec["backend"], 2), round(sec.get("compensation", 0.0), 2), round(sec.get("finalGather", 0.0), 2),
            round(t["memoryPeakMiB"]), round(glt.get("setupSeconds", 0.0), 2), round(glt.get("shadowSeconds", 0.0), 2),
            round(glt.get("foldSeconds", 0.0), 2), round(glt.get("contactSeconds", 0.0), 2),
            round(g.get("contactFraction", 0.0), 4), g.get("cubeFaceSize", "") if gl else ""]
    return ",".join(f(v) for v in vals)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    results, run = sys.argv[1], sys.argv[2]
    if "--header" in sys.argv:
        print(COLUMNS)
    for tag in sorted(os.listdir(results)):
        p = os.path.join(results, tag, "report.json")
        if os.path.isfile(p):
            try:
                print(row(run, tag, json.load(open(p)), "--scenes" in sys.argv))
            except (KeyError, ValueError) as e:
                sys.exit("report_csv: %s: %s" % (p, e))


if __name__ == "__main__":
    main()
