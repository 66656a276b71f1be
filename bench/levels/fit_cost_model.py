#!/usr/bin/env python3
"""fit_cost_model.py IRBAKE DIR... [--levels CSV [--levels-commit C]] [--hold-out NAME,...] [--write] [--accuracy CSV]:
calibrates the bake's cost model, and checks the binary's predictions against the measured bakes.

Each DIR is a measured bake as bench/levels/cost_bakes.py leaves it (report.json, measured.json); --levels adds
the rows of bench/results/levels_scale.csv whose towns bench/levels/town.py makes again (their density given
as measured, so the plan predicts the atlas they had). The inputs
of each are what `IRBAKE plan --json` predicts for the same scene and options (so the fit sees the model's
own features); the targets are the report's CPU seconds per stage (timings.cpuSeconds; for an older report,
each stage's wall time x the bake's CPU time / wall time), which take out a shared machine's load, and its peak
memory. Every stage is
fitted by non-negative least squares on relative errors. Prints the coefficients as the body of
calibratedCostCoefficients() (baker/pipeline/cost_model.cpp); --write pastes them there.

  python3 bench/levels/fit_cost_model.py build/baker/irbake build/calibration/* --hold-out town8_sunsky_preview

--accuracy CSV appends one row per run: the binary's own prediction (`plan --json`, the coefficients it was
built with) against the measured CPU seconds and peak memory, and the plan's own wall time.
"""
import argparse
import csv
import datetime
import itertools
import json
import os
import subprocess
import sys
import time

# stage -> (coefficient, feature) pairs, as predictCost combines them. A feature ending in "Traced" is the count
# times the ray pilot's cost per ray to the power rayCostExponent (inputs.rayCost), "Gl" and "Embree" split the VPL sum by its evaluator.
STAGES = {
    "load": [("loadPerTriangle", "triangles"), ("loadPerTexturePixel", "texturePixels")],
    "atlas": [("atlasPerTriangle", "triangles"), ("atlasPerPageTexel", "pageTexels")],
    "raytrace": [("raytracePerTriangle", "triangles")],
    "texels": [("texelsPerPageTexel", "pageTexels"), ("texelsPerTracedPageTexel", "pageTexelsTraced"),
               ("texelsPerTriangle", "triangles")],
    "vpls": [("vplsPerPath", "paths")],
    "vplImportance": [("importancePerTexelPath", "texelPaths")],
    "backend": [("backendFixed", "one"), ("backendGlFixed", "gl"), ("backendPerTexelPath", "texelPathsEmbree"),
                ("backendGlPerTexelPath", "texelPathsGl"), ("backendPerLightTexel", "lightTexels")],
    "shadowEdges": [("shadowEdgesPerLightRay", "lightRays")],
    "sky": [("skyPerRay", "skyRaysTraced")],
    "compensation": [("compensationPerRay", "compensationRaysTraced"), ("compensationPerTexel", "compensationTexels")],
    "finalGather": [("gatherPerRay", "gatherRaysTraced"), ("gatherPerTexel", "gatherTexels")],
    "post": [("postPerPageTexel", "pageTexels")],
    "probes": [("probesPerRay", "probeRayCountTraced"), ("probesPerProbeLight", "probeLightsTraced")],
    "write": [("writeFixed", "one"), ("writePerPageTexel", "pageTexels")],
}
MEMORY = [("memoryBaseMiB", "one"), ("memoryGlContextMiB", "gl"), ("memoryPerTriangle", "triangles"),
          ("memoryPerTexturePixel", "texturePixels"), ("memoryPerTexel", "texels"), ("memoryPerTexelPath", "texelPaths")]
# memoryPerPageTexel stays 0: the peak follows the texels the charts cover, not the estimate's page texels (which
# the charts of a large level fill only in part).
# Where no bake ran under little load, the share of the cores a bake keeps busy on an idle machine.
DEFAULT_PARALLEL_SHARE = 0.85


# The exponents of the pilot's cost per ray the fit tries (rayCostExponent): the one that fits best is kept.
RAY_COST_EXPONENTS = [1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5, 2.75, 3.0]


def features(inputs, exponent=1.0):
    f = dict(inputs)
    f["one"] = 1.0
    f.setdefault("texturePixels", 0.0)
    f["texelPaths"] = f["texels"] * f["paths"]
    f["lightRays"] = f["lightTexels"] * f["shadowEdgeRays"] if f["punctualLights"] > 0 else 0.0
    f["compensationTexels"] = f["texels"] if f["compensationRays"] > 0 else 0.0
    f["gatherTexels"] = f["texels"] if f["gatherRays"] > 0 else 0.0
    f["probeRayCount"] = f["probes"] * f["probeRays"]
    f.setdefault("probeLights", f["probes"] * f["punctualLights"])
    f["gl"] = f.get("glBackend", 0.0)
    f["texelPathsGl"] = f["texelPaths"] * f["gl"]
    f["texelPathsEmbree"] = f["texelPaths"] * (1.0 - f["gl"])
    scale = f.get("rayCost", 1.0) ** exponent
    for name in ("pageTexels", "skyRays", "compensationRays", "gatherRays", "probeRayCount", "probeLights"):
        f[name + "Traced"] = f[name] * scale
    return f


def solve(rows, targets):
    """Least squares of rows . x = targets by the normal equations (Gaussian elimination); None if singular."""
    n = len(rows[0])
    a = [[sum(r[i] * r[j] for r in rows) for j in range(n)] + [sum(r[i] * t for r, t in zip(rows, targets))] for i in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(a[r][c]))
        if abs(a[p][c]) < 1e-300:
            return None
        a[c], a[p] = a[p], a[c]
        for r in range(n):
            if r != c:
                k = a[r][c] / a[c][c]
                a[r] = [x - k * y for x, y in zip(a[r], a[c])]
    return [a[i][n] / a[i][i] for i in range(n)]


def nnls(rows, targets):
    """Non-negative least squares on relative errors: the best non-negative solution over subsets of columns."""
    n = len(rows[0])
    weighted = [([x / t for x in r], 1.0) for r, t in zip(rows, targets) if t > 0]
    best, best_err = [0.0] * n, float("inf")
    for k in range(1, n + 1):
        for cols in itertools.combinations(range(n), k):
            sub = [[r[c] for c in cols] for r, _ in weighted]
            if not any(any(x != 0 for x in r) for r in sub):
                continue
            x = solve(sub, [t for _, t in weighted])
            if x is None or any(v < 0 for v in x):
                continue
            full = [0.0] * n
            for c, v in zip(cols, x):
                full[c] = v
            err = sum((sum(a * b for a, b in zip(r, full)) - t) ** 2 for r, t in weighted)
            if err < best_err:
                best, best_err = full, err
    return best


def run_plan(irbake, scene, options):
    t0 = time.time()
    out = subprocess.run([irbake, "plan", scene, "--json"] + options, check=True, capture_output=True, text=True).stdout
    return json.loads(out), time.time() - t0


def make_run(irbake, measured, seconds, memory, cpu_seconds=None):
    """measured: name, scene, options, wall_s, cpu_s, cores, load_before; seconds: the stages' wall seconds;
    cpu_seconds: their CPU seconds where the report has them (timings.cpuSeconds), else each stage's wall time x the
    bake's CPU time / wall time."""
    plan, plan_s = run_plan(irbake, measured["scene"], measured["options"])
    cpu_per_wall = measured["cpu_s"] / measured["wall_s"]  # the process's busy cores, whatever the load
    if cpu_seconds:
        cpu = {stage: cpu_seconds.get(stage, 0.0) for stage in STAGES}
    else:
        cpu = {stage: seconds.get(stage, 0.0) * cpu_per_wall for stage in STAGES}
    return {"name": measured["name"], "measured": measured, "features": features(plan["inputs"]), "cpu": cpu,
            "memory": memory, "plan": plan, "plan_s": plan_s}


def load(irbake, folder):
    measured = json.load(open(os.path.join(folder, "measured.json")))
    report = json.load(open(os.path.join(folder, "report.json")))
    seconds = dict(report["timings"]["seconds"])
    seconds["write"] = max(0.0, measured["wall_s"] - seconds.get("bake", 0.0) - seconds.get("load", 0.0))
    cpu_seconds = dict(report["timings"].get("cpuSeconds", {}))
    if cpu_seconds:  # the rest of the process: its start, the plan, the outputs, the exit
        cpu_seconds["write"] = max(0.0, measured["cpu_s"] - cpu_seconds.get("bake", 0.0) - cpu_seconds.get("load", 0.0))
    run = make_run(irbake, measured, seconds, report["timings"]["memoryPeakMiB"], cpu_seconds)
    run["density"] = report["atlas"]["texelsPerUnit"]
    return run


# levels_scale.sh's towns: blocks, lamps, town.py's further options.
TOWNS = {"town4": (4, 32, []), "town8": (8, 128, []), "town16": (16, 512, []), "town32": (32, 2000, ["--cell", "2.2"]),
         "lamps_range": (16, 1000, []), "lamps_norange": (16, 1000, ["--range", "0"])}


def town_scene(name):
    blocks, lamps, extra = TOWNS[name]
    path = os.path.join("build", "levels", "ladder_%s.glb" % name)
    if not os.path.exists(path):
        subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__), "town.py"), path, "--blocks", str(blocks),
                        "--lamps", str(lamps)] + extra, check=True, stdout=subprocess.DEVNULL)
    return path


def load_levels(irbake, path, commit=""):
    runs = []
    for row in csv.DictReader(open(path)):
        if row["scene"] not in TOWNS or "--shard" in row["options"] or (commit and row["commit"] != commit):
            continue
        options = row["options"].split()
        if "--texels-per-unit" not in options:  # the density the bake had, so the plan predicts its atlas
            options += ["--texels-per-unit", row["texels_per_m"]]
        measured = {"name": "%s_run%s" % (row["scene"], row["run"]), "scene": town_scene(row["scene"]), "options": options,
                    "wall_s": float(row["wall_s"]), "cpu_s": float(row["cpu_s"]), "cores": 2,
                    "load_before": float(row["load_avg_start"]), "load_after": float(row["load_avg_end"])}
        seconds = {k[:-2]: float(v) for k, v in row.items() if k.endswith("_s") and v not in ("", None)}
        seconds["write"] = seconds.get("export", 0.0)
        runs.append(make_run(irbake, measured, seconds, float(row["peak_mib"])))
        runs[-1]["density"] = float(row["texels_per_m"])
    return runs


def fit_stages(runs):
    coefficients = {}
    for stage, terms in STAGES.items():
        rows, targets = [], []
        for r in runs:
            row = [r["features"].get(feature, 0.0) for _, feature in terms]
            if stage == "vplImportance" and r["features"]["gatherRays"] <= 0:
                continue
            if any(row) and r["cpu"][stage] > 0:
                rows.append(row)
                targets.append(r["cpu"][stage])
        x = nnls(rows, targets) if rows else [0.0] * len(terms)
        coefficients.update({name: v for (name, _), v in zip(terms, x)})
    rows = [[r["features"][f] for _, f in MEMORY] for r in runs]
    coefficients.update({name: v for (name, _), v in zip(MEMORY, nnls(rows, [r["memory"] for r in runs]))})
    coefficients["memoryPerPageTexel"] = 0.0
    quiet = [r["measured"]["cpu_s"] / (r["measured"]["wall_s"] * r["measured"]["cores"]) for r in runs
             if r["measured"]["load_before"] < r["measured"]["cores"] + 0.5]
    coefficients["parallelShare"] = min(1.0, max(quiet)) if quiet else DEFAULT_PARALLEL_SHARE
    return coefficients


def fit(runs):
    """Every stage at each exponent of the pilot's cost per ray; keeps the exponent whose predicted CPU seconds (the
    stages' sum) come closest to the measured, in relative error over the runs, and sets the runs' features to it."""
    best, best_err = None, float("inf")
    for k in RAY_COST_EXPONENTS:
        for r in runs:
            r["features"] = features(r["plan"]["inputs"], k)
        c = fit_stages(runs)
        err = sum((predict(c, r["features"])[0] / sum(r["cpu"].values()) - 1.0) ** 2 for r in runs)
        if err < best_err:
            best, best_err = dict(c, rayCostExponent=k), err
    for r in runs:
        r["features"] = features(r["plan"]["inputs"], best["rayCostExponent"])
    return best


def predict(c, f):
    cpu = sum(c[name] * f.get(feature, 0.0) for terms in STAGES.values() for name, feature in terms)
    memory = sum(c[name] * f[feature] for name, feature in MEMORY)
    return cpu, memory


def accuracy_rows(runs, held, path):
    new = not os.path.exists(path)
    with open(path, "a", newline="") as f:
        w = csv.writer(f)
        if new:
            w.writerow(["date", "scene", "options", "role", "triangles", "plan_s", "predicted_s", "predicted_cpu_s",
                        "measured_cpu_s", "measured_wall_s", "idle_wall_s", "time_ratio", "predicted_mib", "measured_mib",
                        "memory_ratio", "cores", "load_before", "load_after"])
        for r in runs:
            p, m = r["plan"]["prediction"], r["measured"]
            share = p["cpuSeconds"] / (p["seconds"] * r["plan"]["inputs"]["cores"]) if p["seconds"] > 0 else 1.0
            w.writerow([datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%MZ"), r["name"], " ".join(m["options"]),
                        "hold-out" if r["name"] in held else "fitted", int(r["plan"]["inputs"]["triangles"]),
                        round(r["plan_s"], 2), round(p["seconds"], 2), round(p["cpuSeconds"], 2), m["cpu_s"], m["wall_s"],
                        round(m["cpu_s"] / (m["cores"] * share), 2), round(p["cpuSeconds"] / m["cpu_s"], 3),
                        round(p["memoryPeakMiB"]), round(r["memory"]), round(p["memoryPeakMiB"] / r["memory"], 3),
                        m["cores"], round(m["load_before"], 2), round(m.get("load_after", 0.0), 2)])


def initialiser(c):
    lines = ["  // fit_cost_model.py: begin"]
    for name in ([n for terms in STAGES.values() for n, _ in terms] + ["parallelShare", "rayCostExponent"] +
                 [n for n, _ in MEMORY] + ["memoryPerPageTexel"]):
        lines.append("  c.%s = %.6g;" % (name, c[name]))
    lines.append("  // fit_cost_model.py: end")
    return "\n".join(lines)


def write(c, path):
    text = open(path).read()
    begin = text.index("  // fit_cost_model.py: begin")
    end = text.index("  // fit_cost_model.py: end") + len("  // fit_cost_model.py: end")
    open(path, "w").write(text[:begin] + initialiser(c) + text[end:])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("irbake")
    ap.add_argument("folders", nargs="+")
    ap.add_argument("--hold-out", default="", help="comma-separated run names checked but not fitted")
    ap.add_argument("--write", action="store_true", help="paste the coefficients into baker/pipeline/cost_model.cpp")
    ap.add_argument("--levels", help="bench/results/levels_scale.csv: its towns' rows as more runs")
    ap.add_argument("--levels-commit", default="", help="only the --levels rows measured at this commit")
    ap.add_argument("--accuracy", help="append the binary's predictions against the runs to this CSV")
    a = ap.parse_args()
    held = set(filter(None, a.hold_out.split(",")))
    runs = [load(a.irbake, f) for f in a.folders if os.path.exists(os.path.join(f, "measured.json"))]
    if a.levels:
        runs += load_levels(a.irbake, a.levels, a.levels_commit)
    # A run whose atlas the plan does not predict (the density rule differs from the bake's) teaches nothing.
    for r in [r for r in runs if abs(r["plan"]["atlas"]["texelsPerMetre"] / r["density"] - 1.0) > 0.02]:
        print("# %s left out: the plan predicts %.3g texels per metre, the bake had %.3g" %
              (r["name"], r["plan"]["atlas"]["texelsPerMetre"], r["density"]), file=sys.stderr)
    runs = [r for r in runs if abs(r["plan"]["atlas"]["texelsPerMetre"] / r["density"] - 1.0) <= 0.02]
    if a.accuracy:
        accuracy_rows(runs, held, a.accuracy)
    c = fit([r for r in runs if r["name"] not in held])
    for r in runs:  # the held-out runs too, at the fitted exponent
        r["features"] = features(r["plan"]["inputs"], c["rayCostExponent"])
    print(initialiser(c))
    for r in runs:
        cpu, memory = predict(c, r["features"])
        m = r["measured"]
        print("# %-26s %s cpu %.1f s predicted %.1f (%.2f), peak %.0f MiB predicted %.0f (%.2f)" %
              (r["name"], "hold-out" if r["name"] in held else "fitted  ", m["cpu_s"], cpu, cpu / m["cpu_s"],
               r["memory"], memory, memory / r["memory"]), file=sys.stderr)
    if a.write:
        write(c, os.path.join(os.path.dirname(__file__), "..", "..", "baker", "pipeline", "cost_model.cpp"))


if __name__ == "__main__":
    main()
