#!/usr/bin/python3
"""Re-baking one light group (--only-group) against a full grouped bake, on the town level.

usage (from the repository root):
  python3 bench/scenarios/only_group.py [--irbake build/baker/irbake] [--work build/scenarios/only_group]
      [--blocks 4] [--lamps 60] [--texels-per-unit 5] [--csv bench/results/only_group.csv]

The town (bench/levels/town.py) is baked with two groups, day = --sun and --sky, street = the lamps (`*`): the
earlier bake. Then one lamp's intensity is doubled in the glTF and the edited level is baked
  only   --only-group street --atlas-from the earlier bake, seed 1: the lamps alone, day carried over;
  full   every group (--atlas-from the earlier bake, for the same atlas), seed 0;
  seed1  as full, seed 1: two full bakes' difference, the noise baseline.
CPU seconds are /usr/bin/time -v's user + system of each command. Errors are `irbake diff --json`'s relativeRmse
of the default maps (area-weighted over the folders' pages): only against full, and seed1 against full.
"""
import argparse
import csv
import datetime
import json
import os
import struct
import subprocess

GROUPS = ["--sun", "0.35,-1,0.2,5", "--sky", "0.4,0.5,0.7", "--light-group", "day=sun,sky", "--light-group", "street=*"]


def timed(cmd, log):
    """Runs cmd under /usr/bin/time -v; returns its CPU seconds (user + system)."""
    with open(log, "w") as out:
        subprocess.run(["/usr/bin/time", "-v"] + cmd, check=True, stdout=out, stderr=out)
    cpu = 0.0
    for line in open(log):
        line = line.strip()
        if line.startswith("User time (seconds):") or line.startswith("System time (seconds):"):
            cpu += float(line.split(":")[1])
    return cpu


def edit_glb(src, dst, light, factor):
    """Copies a GLB with KHR_lights_punctual light `light`'s intensity times factor."""
    data = open(src, "rb").read()
    length, kind = struct.unpack_from("<II", data, 12)
    assert kind == 0x4E4F534A, "the first chunk of a GLB is its JSON"
    doc = json.loads(data[20:20 + length])
    lamp = doc["extensions"]["KHR_lights_punctual"]["lights"][light]
    lamp["intensity"] = lamp.get("intensity", 1.0) * factor
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + length:]
    with open(dst, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + len(rest)))
        f.write(struct.pack("<II", len(text), 0x4E4F534A) + text + rest)


def relative_rmse(irbake, a, b):
    out = subprocess.run([irbake, "diff", "--json", a, b], check=True, capture_output=True, text=True).stdout
    return json.loads(out)["relativeRmse"]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--irbake", default="build/baker/irbake")
    p.add_argument("--work", default="build/scenarios/only_group")
    p.add_argument("--blocks", type=int, default=4)
    p.add_argument("--lamps", type=int, default=60)
    p.add_argument("--texels-per-unit", default="5")
    p.add_argument("--csv", default="bench/results/only_group.csv")
    a = p.parse_args()
    w = a.work
    os.makedirs(w, exist_ok=True)
    town, edited = os.path.join(w, "town.glb"), os.path.join(w, "town_edited.glb")
    subprocess.run(["python3", "bench/levels/town.py", town, "--blocks", str(a.blocks), "--lamps", str(a.lamps)], check=True)
    edit_glb(town, edited, 0, 2.0)
    bake = [a.irbake, "bake", "--quiet"]
    earlier = os.path.join(w, "earlier")
    timed(bake + [town, "-o", earlier, "--texels-per-unit", a.texels_per_unit] + GROUPS, os.path.join(w, "earlier.log"))
    on_atlas = ["--atlas-from", os.path.join(earlier, "scene.gltf")]
    runs = {"only": ["--only-group", "street", "--seed", "1"], "full": ["--seed", "0"], "seed1": ["--seed", "1"]}
    cpu = {}
    for name, more in runs.items():
        cpu[name] = timed(bake + [edited, "-o", os.path.join(w, name)] + GROUPS + on_atlas + more, os.path.join(w, name + ".log"))
    full = os.path.join(w, "full")
    vs_full = relative_rmse(a.irbake, os.path.join(w, "only"), full)
    baseline = relative_rmse(a.irbake, os.path.join(w, "seed1"), full)
    report = json.load(open(os.path.join(full, "report.json")))
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    row = {"date": datetime.date.today().isoformat(), "commit": commit,
           "scene": "town%d_%dlamps_tpu%s" % (a.blocks, a.lamps, a.texels_per_unit), "texels": report["texels"]["total"],
           "full_cpu_s": round(cpu["full"], 2), "only_cpu_s": round(cpu["only"], 2),
           "ratio": round(cpu["only"] / cpu["full"], 4), "rel_rmse_vs_full": round(vs_full, 6),
           "rel_rmse_seed_baseline": round(baseline, 6)}
    print(json.dumps(row))
    new = not os.path.exists(a.csv)
    with open(a.csv, "a", newline="") as f:
        out = csv.DictWriter(f, fieldnames=list(row))
        if new:
            out.writeheader()
        out.writerow(row)


if __name__ == "__main__":
    main()
