#!/usr/bin/python3
"""Rows of bench/results/gpu_profile_h200.csv from bench/gpu/device_profile.sh's results: every stage's wall
time, the backend stage's parts (GL context, blocks, evaluator calls, maps with the
punctual lights' call), the GL backend's own split (CPU wall and GPU elapsed per pass kind), the process wall time and the GPU
memory peak of each bake.

usage: python3 bench/gpu/profile_csv.py PROFILE_DIR LABEL COMMIT [--header] >> bench/results/gpu_profile_h200.csv
PROFILE_DIR is the unpacked profile_LABEL folder (TAG/report.json, TAG.log, gpumem.txt, walls.txt).
"""
import json
import os
import re
import sys

STAGES = ("load", "atlas", "texels", "sky", "vplImportance", "vpls", "backend", "compensation", "finalGather",
          "shadowEdges", "probes", "post")
PARTS = ("context", "blocks", "evaluate", "maps", "direct")
GL = ("setupSeconds", "geometrySeconds", "shadowSeconds", "accumulateSeconds", "foldSeconds", "contactSeconds",
      "readSeconds", "gpuShadowSeconds", "gpuAccumulateSeconds", "gpuFoldSeconds")
COLUMNS = ("label,commit,tag,scene,backend,threads,triangles,vpls,texels_valid,interleave_classes,wall_s,bake_s,"
           + ",".join(s + "_s" for s in STAGES) + ",other_s,"
           + ",".join("backend_" + p + "_s" for p in PARTS) + ","
           + ",".join("gl_" + re.sub(r"Seconds$", "_s", g) for g in GL)
           + ",gl_calls,contact_fraction,cube_face,host_peak_mib,gpu_peak_mib")


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    folder, label, commit = sys.argv[1:4]
    if "--header" in sys.argv:
        print(COLUMNS)
    walls, gpu = {}, {}
    for line in open(os.path.join(folder, "walls.txt")) if os.path.exists(os.path.join(folder, "walls.txt")) else []:
        m = re.match(r"(\S+) rc=0 wall=([\d.]+)", line)
        if m:
            walls[m.group(1)] = float(m.group(2))
    for line in open(os.path.join(folder, "gpumem.txt")):
        m = re.match(r"(\S+) gpu_mem_peak_mib=(\d+)", line)
        if m:
            gpu[m.group(1)] = int(m.group(2))
    for tag in sorted(os.listdir(folder)):
        p = os.path.join(folder, tag, "report.json")
        if not os.path.isfile(p):
            continue
        r = json.load(open(p))
        t = r["timings"]
        sec, glt, g = t["seconds"], t.get("gl", {}), r.get("gl", {})
        other = sec["bake"] - sum(sec.get(s, 0.0) for s in STAGES)
        vals = [label, commit, tag, tag.split("_")[0], r["backend"], 16, r["scene"]["triangles"], r["vpls"]["count"],
                r["texels"]["valid"], r.get("interleave", {}).get("classes", 1), walls.get(tag, ""),
                round(sec["bake"], 3)]
        vals += [round(sec.get(s, 0.0), 3) for s in STAGES] + [round(other, 3)]
        parts = t.get("backendParts", {})
        vals += [round(parts[p], 3) if p in parts else "" for p in PARTS]
        vals += [round(glt.get(k, 0.0), 3) for k in GL]
        vals += [glt.get("calls", ""), round(g.get("contactFraction", 0.0), 4), g.get("cubeFaceSize", ""),
                 round(t["memoryPeakMiB"]), gpu.get(tag, "")]
        print(",".join(str(v) for v in vals))


if __name__ == "__main__":
    main()
