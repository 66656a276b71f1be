#!/usr/bin/env python3
"""cost_bakes.py IRBAKE OUTROOT NAME SCENE [bake options...]: one calibration bake for the cost model.

Bakes SCENE into OUTROOT/NAME, then writes OUTROOT/NAME/measured.json beside its report.json: the wall and CPU
seconds of the bake process (CPU from getrusage of the child), the machine's cores and its load average before
and after. fit_cost_model.py and plan_accuracy.sh read these folders.

  python3 bench/levels/cost_bakes.py build/baker/irbake build/calibration town4 build/levels/town4.glb --sun 0.35,-1,0.2,5
"""
import json
import os
import resource
import subprocess
import sys
import time


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    irbake, root, name, scene = sys.argv[1:5]
    options = sys.argv[5:]
    out = os.path.join(root, name)
    os.makedirs(out, exist_ok=True)
    load_before = os.getloadavg()[0]
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.time()
    subprocess.run([irbake, "bake", scene, "-o", out, "--quiet"] + options, check=True, stdout=subprocess.DEVNULL)
    wall = time.time() - t0
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    measured = {"name": name, "scene": os.path.abspath(scene), "options": options, "wall_s": round(wall, 3),
                "cpu_s": round(cpu, 3), "cores": os.cpu_count(), "load_before": load_before,
                "load_after": os.getloadavg()[0], "peak_mib": round(cpu1.ru_maxrss / 1024.0, 1)}
    with open(os.path.join(out, "measured.json"), "w") as f:
        json.dump(measured, f, indent=1)
    print(json.dumps(measured))


if __name__ == "__main__":
    main()
