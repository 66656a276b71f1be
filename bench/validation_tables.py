#!/usr/bin/env python3
"""The tables of docs/validation.md, generated from the CSVs in bench/results/.

Each table sits in the document between `<!-- table:NAME -->` and `<!-- /table:NAME -->`. The rows are the
current ones: for every case, the latest run that used the default options (or the options the case names).

usage (repository root; standard-library Python 3 only):
  python3 bench/validation_tables.py --check docs/validation.md   # exit 1 and a diff when a table differs
  python3 bench/validation_tables.py --write docs/validation.md   # rewrite the tables in place
  python3 bench/validation_tables.py --print NAME                 # one table on stdout
  --results DIR: the CSV folder (default: bench/results beside this script)
"""
import argparse
import csv
import difflib
import io
import math
import os
import re
import statistics
import sys

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def read(name):
    with open(os.path.join(RESULTS, name), newline="") as f:
        return list(csv.DictReader(f))


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def pct(value, digits=2):
    return "" if value in ("", None) else f"{100.0 * float(value):.{digits}f}%"


def num(value, digits=2):
    return "" if value in ("", None) else f"{float(value):.{digits}f}"


def median(values):
    return statistics.median(float(v) for v in values)


# Options that describe the scene or the seed, not the bake's settings: rows with only these are default bakes.
SCENE_OPTIONS = ("--sky", "--sun", "--seed")


def default_options(options):
    tokens = options.split()
    return all(tokens[i] in SCENE_OPTIONS for i in range(0, len(tokens), 2))


def seed_of(options):
    tokens = options.split()
    return tokens[tokens.index("--seed") + 1] if "--seed" in tokens else "0"


def latest(rows, key):
    """The latest row (by date, then by file order) for every key, in the order keys first appear."""
    best = {}
    for r in rows:
        k = key(r)
        if k not in best or r["date"] >= best[k]["date"]:
            best[k] = r
    return list(best.values())


SCENES = {
    "cycles_cornell_published.csv": "Cornell published",
    "cycles_cornell_sample.csv": "Cornell sample",
    "cycles_mcguire_cornell.csv": "McGuire Cornell",
    "cycles_sponza_sun_x4.csv": "Sponza, sun",
    "cycles_sponza_sun_sky.csv": "Sponza, sun + sky",
    "cycles_sibenik_lamp.csv": "Sibenik, lamp",
    "cycles_sponza_sun_sky_tpu6.csv": "Sponza, sun + sky",
    "cycles_sponza_sun_sky_default.csv": "Sponza, sun + sky",
}


def cycles_rows(files, modes=("map", "view"), seeds=None):
    out = []
    for name in files:
        if not os.path.isfile(os.path.join(RESULTS, name)):  # a scene not yet measured
            continue
        rows = [r for r in read(name) if r["mode"] in modes and default_options(r["our_options"])]
        current = latest(rows, lambda r: (r["mode"], r["view"], seed_of(r["our_options"])))
        if seeds is not None:
            current = [r for r in current if seed_of(r["our_options"]) in seeds]
        for r in sorted(current, key=lambda r: (int(seed_of(r["our_options"])), r["mode"], r["view"])):
            view = "page 0" if r["mode"] == "map" else f"view {r['view']}"
            size = f"{int(r['texels']) / 1e3:.0f}k texels" if r["mode"] == "map" else f"{r['width']}×{r['height']}"
            out.append([SCENES[name], f"{r['mode']} ({size})", view, seed_of(r["our_options"]),
                        num(r["our_wall_s"], 1), num(r["mean_ratio"], 3), pct(r["rel_rmse_4"]),
                        pct(r["ref_noise_4"]), f"**{pct(r['rel_rmse_4_corrected'])}**",
                        pct(r["rel_rmse_4_with_edges"]), r["ref_spp"]])
    return table(["scene", "compared", "where", "seed", "our bake, wall (s)", "mean ours/Cycles",
                  "rel. RMSE 4×4", "Cycles' noise", "noise removed", "edges kept", "Cycles spp"], out)


def t_cycles_cornell():
    """Seed 0 of each box; every seed's figure is in the every-seed table."""
    return cycles_rows(["cycles_cornell_published.csv", "cycles_cornell_sample.csv", "cycles_mcguire_cornell.csv"],
                       seeds=("0",))


def t_seed_spread():
    """bench/seed_spread.py: per scene and options, the latest run's seeds against each other."""
    rows = read("seed_spread.csv")
    summaries = latest([r for r in rows if r["seed"] == "all"], lambda r: (r["scene"], r["options"]))
    out = []
    for sm in summaries:
        per = [r for r in rows if r["seed"] != "all" and r["date"] == sm["date"] and r["scene"] == sm["scene"]
               and r["options"] == sm["options"]]
        ratios = [float(r["total_ratio"]) for r in per]
        noise = [float(r["seed_noise_4"]) for r in per]
        out.append([sm["scene"], f"`{sm['options']}`" if sm["options"] else "default", len(per),
                    f"{min(ratios):.4f} … {max(ratios):.4f}", f"**{pct(sm['spread'])}**", pct(sm["noise_rms"]),
                    pct(max(noise)), num(sm["wall_s"], 1), num(sm["load_1min"], 1)])
    return table(["scene", "options", "seeds", "total / seeds' mean", "spread of the total",
                  "seed noise 4×4, RMS", "worst seed", "median wall (s)", "1-min load (largest)"], out)


# Scenes whose map is scored against Cycles on every seed: (CSV, options without --seed, what the options mean).
EVERY_SEED = [
    ("cycles_cornell_sample.csv", "", "default"),
    ("cycles_cornell_published.csv", "", "default"),
    ("cycles_mcguire_cornell.csv", "", "default"),
    ("cycles_sponza_sun_sky_tpu6.csv", "--sky 0.4,0.5,0.7 --texels-per-unit 6", "sun + sky, 6 texels per metre"),
    ("cycles_sponza_sun_sky_default.csv", "--sky 0.4,0.5,0.7", "sun + sky, default density"),
]


def without_seed(options):
    tokens = options.split()
    if "--seed" in tokens:
        i = tokens.index("--seed")
        del tokens[i:i + 2]
    return " ".join(tokens)


def t_every_seed():
    """The map against Cycles' bake in our atlas for every seed of one baker: the latest commit with most seeds."""
    out = []
    for name, options, label in EVERY_SEED:
        if not os.path.isfile(os.path.join(RESULTS, name)):
            continue
        rows = [r for r in read(name) if r["mode"] == "map" and without_seed(r["our_options"]) == options]
        by_commit = {}
        for r in rows:
            by_commit.setdefault(r["commit"], []).append(r)
        if not by_commit:
            continue
        per_seed = {c: latest(rs, lambda r: seed_of(r["our_options"])) for c, rs in by_commit.items()}
        commit = max(per_seed, key=lambda c: (len(per_seed[c]), max(r["date"] for r in per_seed[c])))
        current = sorted(per_seed[commit], key=lambda r: int(seed_of(r["our_options"])))
        errors = [float(r["rel_rmse_4_corrected"]) for r in current]
        ratios = [float(r["mean_ratio"]) for r in current]
        scene = SCENES.get(name, name)
        out.append([scene, label, ", ".join(seed_of(r["our_options"]) for r in current),
                    " / ".join(pct(e) for e in errors), f"**{pct(max(errors))}**",
                    f"{min(ratios):.4f} … {max(ratios):.4f}", f"**{pct(max(ratios) - min(ratios))}**",
                    num(median(r["our_wall_s"] for r in current), 1), current[0]["ref_spp"]])
    return table(["scene", "options", "seeds", "rel. RMSE 4×4, noise removed, per seed", "worst seed",
                  "mean ours/Cycles", "spread of the mean", "median wall (s)", "Cycles spp"], out)


def t_cycles_sponza():
    return cycles_rows(["cycles_sponza_sun_x4.csv", "cycles_sponza_sun_sky.csv"])


def t_cycles_sibenik():
    return cycles_rows(["cycles_sibenik_lamp.csv"])


def t_cycles_ladder():
    out = []
    for name in ["cycles_cornell_sample.csv", "cycles_cornell_published.csv", "cycles_mcguire_cornell.csv",
                 "cycles_sponza_sun_x4.csv"]:
        rows = [r for r in read(name) if r["mode"] == "map-cycles"]
        for r in sorted(latest(rows, lambda r: r["cycles_spp"]), key=lambda r: int(r["cycles_spp"])):
            out.append([SCENES[name], r["cycles_spp"], num(r["cycles_s"], 1),
                        pct(r["rel_rmse_4_corrected"])])
    return table(["scene (map, our atlas)", "Cycles samples per texel", "Cycles' bake (s)",
                  "rel. RMSE 4×4, noise removed"], out)


def t_equal_error_time():
    out = []
    for r in latest(read("equal_error_time.csv"), lambda r: r["scene"]):
        out.append([r["scene"], r["date"], num(r["our_wall_s_median"], 2), r["runs"],
                    r["cycles_spp"], num(r["cycles_bake_s"], 1), f"**{num(r['ratio'], 2)}×**", r["load_avg"]])
    return table(["scene", "date", "our bake, median wall (s)", "runs", "Cycles spp at our error",
                  "Cycles' bake (s)", "Cycles / ours", "load average"], out)


def t_speed_error():
    out = []
    for r in read("speed_error.csv"):
        out.append([r["scene"], r["triangles"], r["texels"], r["backend"], r["paths"], r["vpls"],
                    pct(r["relative_rmse"]), pct(r["relative_rmse_corrected"]), pct(r["relative_bias"]),
                    num(r["backend_s"], 2), num(r["compensation_s"], 2), r["interleave"]])
    return table(["scene", "triangles", "texels", "backend", "paths", "VPLs", "rel. RMSE", "noise removed",
                  "mean bias", "backend (s)", "compensation (s)", "interleave n"], out)


def slope(points):
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(e) for _, e in points]
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def t_convergence():
    series = {}
    for r in read("light_convergence.csv"):
        series.setdefault(r["series"], []).append((float(r["n"]), float(r["relative_rmse"])))
    out = []
    for name, points in series.items():
        points.sort()
        out.append([f"`{name}`", f"{points[0][0]:.0f}…{points[-1][0]:.0f}", pct(points[-1][1]), f"{slope(points):.2f}"])
    return table(["series", "N", "rel. RMSE at the largest N", "log-log slope"], out)


def t_light_timing():
    out = [[r["case"], r["vpls"], f"{int(r['pairs']) / 1e6:.2f} M", num(r["median_seconds"], 3),
            f"{float(r['pairs_per_second']) / 1e6:.1f} M"] for r in read("light_timing.csv")]
    return table(["case", "VPLs", "sample–VPL pairs", "median (s)", "pairs per second"], out)


def t_gl_stages():
    rows = read("gl_stages.csv")
    last = [r for r in rows if r["variant"] == rows[-1]["variant"] and r["load1"] == rows[-1]["load1"]]
    groups = {}
    for r in last:
        groups.setdefault((r["triangles"], r["texels"], r["vpls"], r["k"], r["face"]), []).append(r)
    out = []
    for (tri, texels, vpls, k, face), g in groups.items():
        out.append([tri, texels, vpls, k, face, len(g), num(median(r["shadow_ms_per_vpl"] for r in g), 1),
                    num(median(r["accumulate_ms_per_vpl"] for r in g), 1), num(g[0]["load1"], 1)])
    return table(["triangles", "texels", "VPLs", "VPLs per batch", "cube face", "runs", "shadow (ms per VPL)",
                  "accumulate (ms per VPL)", "load average"], out)


def t_levels():
    rows = read("levels.csv")
    last = {}
    for r in rows:
        k = r["scene"]
        if k not in last or (r["date"], rows.index(r)) >= (last[k][0], last[k][1]):
            last[k] = (r["date"], rows.index(r), r["commit"])
    out = []
    for scene, (date, _, commit) in last.items():
        g = [r for r in rows if r["scene"] == scene and r["commit"] == commit and r["date"] == date]
        r = g[0]
        out.append([scene, f"`{r['options']}`", date, r["backend"], len(g),
                    f"{int(r['texels_valid']) / 1e6:.2f} M", r["vpls"], num(median(x["wall_s"] for x in g), 1),
                    f"{median(x['peak_mib'] for x in g):.0f}", num(median(x["load_avg"] for x in g), 1)])
    return table(["scene", "options", "date", "backend (auto)", "runs", "texels", "VPLs",
                  "median wall (s)", "peak memory (MiB)", "load average"], out)


def t_levels_scale():
    """The level ladder (bench/levels/levels_scale.sh): per scene, the median of its latest commit's runs."""
    rows = read("levels_scale.csv")
    latest_commit = {}
    for r in rows:
        latest_commit[r["scene"]] = r["commit"]
    out = []
    for scene, c in latest_commit.items():
        g = [r for r in rows if r["scene"] == scene and r["commit"] == c]
        r = g[-1]
        m = lambda k: median(x[k] for x in g)
        out.append([scene, c, int(r["triangles"]), int(r["lights"]), f"{int(r['texels']) / 1e6:.2f} M", len(g),
                    num(m("cpu_s"), 0), num(m("wall_s"), 0), f"{m('peak_mib'):.0f}", num(m("shadowEdges_s"), 1),
                    num(m("probes_s"), 1), f"{num(m('load_avg_start'), 1)} / {num(m('load_avg_end'), 1)}"])
    return table(["scene", "commit", "triangles", "lights", "texels", "runs", "CPU (s)", "wall (s)", "peak (MiB)",
                  "shadow edges (s)", "probes (s)", "load start / end"], out)


def t_light_cull():
    """bench/results/light_cull.csv: per scene at its latest texel count, --light-cull and --light-tail, the median
    CPU of its latest commit's runs, against the same town's sun and sky alone at about the same texels (within 5%),
    and the map's error against the brute-force bake (--light-cull 0)."""
    rows = read("light_cull.csv")
    latest = {}
    for r in rows:
        latest[r["scene"]] = r["texels"]
    rows = [r for r in rows if r["texels"] == latest[r["scene"]]]
    key = lambda r: (r["scene"], r["cull"], r.get("tail", "0") if r["cull"] != "0" else "0")
    keys = {}
    for r in rows:
        keys[key(r)] = r["commit"]
    cpu = {}
    for k, c in keys.items():
        g = [float(r["cpu_s"]) for r in rows if key(r) == k and r["commit"] == c and r["cpu_s"]]
        cpu[k] = (statistics.median(g), len(g)) if g else (None, 0)
    out = []
    for k, c in keys.items():
        scene, cull, tail = k
        r = [x for x in rows if key(x) == k and x["commit"] == c][-1]
        own, runs = cpu[k]
        town = re.match(r"town\d+", scene).group(0) + "sun"
        base = None
        if town in latest and abs(float(latest[town]) / float(r["texels"]) - 1.0) < 0.05:
            base = cpu.get((town, cull, tail), cpu.get((town, cull, "0"), (None, 0)))[0]
        ratio = f"{own / base:.2f}×" if own and base and not scene.endswith("sun") else ""
        out.append([scene, r["lamps"], r["range"] if r["range"] != "0" else "none", f"{float(r['texels']) / 1e6:.2f} M",
                    cull if cull != "0" else "off", tail if cull != "0" else "", c, runs,
                    num(own, 1) if own else "", ratio, pct(r["rel_rmse_vs_brute"])])
    return table(["scene", "lamps", "range (m)", "texels", "--light-cull", "--light-tail", "commit", "runs", "CPU (s)",
                  "CPU / sun + sky", "rel. RMSE vs brute force"], out)


def t_scenarios():
    """bench/scenarios/day_night.py: per pair, its latest commit's seeds: the binned difference against the
    root sum of squares of the two bakes' estimated errors; the relight's CPU against one bake of every light."""
    rows = read("scenarios.csv")
    last = rows[-1]["commit"]
    rows = [r for r in rows if r["commit"] == last]
    out = []
    for pair in dict.fromkeys(r["pair"] for r in rows if float(r["expected"]) > 0):
        g = [r for r in rows if r["pair"] == pair]
        expected = [float(r["expected"]) for r in g if float(r["expected"]) > 0]
        ratio = [float(r["ratio"]) for r in g if r["ratio"]]
        seeds = [int(r["seed"]) for r in g]
        span = seeds == list(range(seeds[0], seeds[0] + len(seeds))) and len(seeds) > 2
        out.append([pair.replace("_", " "), last, f"{seeds[0]}–{seeds[-1]}" if span else ", ".join(map(str, seeds)),
                    pct(median([float(r["rel_rmse_4"]) for r in g]), 3), pct(median(expected), 3) if expected else "",
                    num(max(ratio)) if ratio else ""])
    relight = median([float(r["relight_cpu_s"]) for r in rows])
    bake = median([float(r["all_cpu_s"]) for r in rows])
    grouped = median([float(r["grouped_cpu_s"]) for r in rows])
    return table(["pair", "commit", "seeds", "rel. RMSE, 4×4 bins", "estimates (RSS)", "worst ratio"], out) + \
        f"\n\nrelight: {relight:.2f} s CPU, {100 * relight / bake:.1f}% of one bake ({bake:.0f} s)"


def t_plan_accuracy():
    """bench/levels/plan_accuracy.sh: `irbake plan`'s prediction against the bake, the latest date's rows; a level
    ladder's runs of one scene (NAME_runK) as one row of their medians."""
    rows = read("plan_accuracy.csv")
    last = max(r["date"] for r in rows)
    groups = {}
    for r in rows:
        if r["date"] == last:
            groups.setdefault(re.sub(r"_run\d+$", "", r["scene"]), []).append(r)
    out = []
    for scene, g in groups.items():
        m = lambda k: median(float(x[k]) for x in g)
        runs = f" ({len(g)} runs)" if len(g) > 1 else ""
        out.append([scene + runs, g[0]["role"], num(m("plan_s"), 1), num(m("predicted_cpu_s"), 1),
                    num(m("measured_cpu_s"), 1), f"**{num(m('time_ratio'))}**", f"{m('predicted_mib'):.0f}",
                    f"{m('measured_mib'):.0f}", f"**{num(m('memory_ratio'))}**"])
    return table(["scene", "role", "plan (s)", "predicted CPU (s)", "measured CPU (s)", "time ratio",
                  "predicted peak (MiB)", "measured peak (MiB)", "memory ratio"], out)


def t_memory():
    rows = read("memory.csv")
    label = rows[-1]["label"]
    out = [[r["case"], r["triangles"], r["texels"], r["runs"], num(r["peak_rss_mib"], 0), num(r["bake_peak_mib"], 0)]
           for r in rows if r["label"] == label]
    return table(["case", "triangles", "texels", "runs", "peak RSS (MiB)", "bake's own peak (MiB)"], out)


def gpu_table(name):
    rows = read(name)
    out = []
    for r in latest([dict(r, date=f"{int(r['run']):06d}") for r in rows], lambda r: r["tag"]):
        out.append([r["tag"], r["run"], r["backend"], r["asked"], r["threads"], r["triangles"], r["vpls"],
                    num(r["bake_s"], 2), num(r["backend_s"], 2), num(r["compensation_s"], 2), r["peak_mib"]])
    return table(["case", "run", "backend", "asked", "CPU threads", "triangles", "VPLs", "bake (s)", "backend (s)",
                  "compensation (s)", "peak (MiB)"], out)


def gpu_h100():
    return gpu_table("gpu_h100.csv")


def gpu_h200():
    return gpu_table("gpu_h200.csv")


def t_slurm():
    rows = read("slurm_scaling.csv")
    out = []
    for shards in dict.fromkeys(r["shards"] for r in rows):
        g = [r for r in rows if r["shards"] == shards]
        out.append(["one machine" if shards == "0" else shards, len(g), num(median(r["array_wall_s"] for r in g), 1),
                    num(median(r["merge_wall_s"] for r in g), 1), num(median(r["total_wall_s"] for r in g), 1),
                    "yes" if all(r["identical_to_one_machine"] == "yes" for r in g) else "**no**",
                    num(median(r["load1"] for r in g), 1)])
    return table(["shards", "rounds", "array, median wall (s)", "merge (s)", "total (s)",
                  "bytes identical to one machine", "load average"], out)


ESTIMATE_SCENES = {"cornell_sample": "Cornell sample", "cornell_published": "Cornell published", "mcguire_cornell": "McGuire Cornell", "corner": "corner (sample)",
                   "contacts": "contacts (sample)", "sponza_sun_sky": "Sponza, sun + sky",
                   "sponza_sun_sky_grid4": "Sponza, sun + sky; Cycles 4×4 points per texel", "sibenik_lamp": "Sibenik, lamp",
                   "sibenik_lamp_grid4": "Sibenik, lamp; Cycles 4×4 points per texel"}


def t_error_estimate():
    """Per scene and options, the latest run of each seed summarised: the estimate against the measured error."""
    rows = latest(read("error_estimate.csv"), lambda r: (r["scene"], r["our_options"], r["seed"]))
    out = []
    for key in dict.fromkeys((r["scene"], r["our_options"]) for r in rows):
        group = [r for r in rows if (r["scene"], r["our_options"]) == key]
        opts = " ".join(key[1].replace("--estimate-error true", "").split())
        rms = lambda k: math.sqrt(sum(float(r[k]) ** 2 for r in group) / len(group))
        out.append([ESTIMATE_SCENES.get(key[0], key[0]), f"`{opts}`" if opts else "default", len(group),
                    f"{int(group[0]['texels']) / 1e3:.0f}k", f"**{pct(rms('estimated'))}**",
                    pct(rms("rel_rmse_4")), pct(group[0]["ref_noise_4"]), f"**{pct(rms('rel_rmse_4_corrected'))}**",
                    f"**{num(rms('estimated') / rms('rel_rmse_4_corrected'), 2)}**", group[0]["ref_spp"]])
    return table(["scene", "options", "seeds", "texels", "estimate (interior bins), RMS", "measured, RMS",
                  "Cycles' noise", "measured, noise removed, RMS", "estimate / measured", "Cycles spp"], out)


def t_error_estimate_seeds():
    """The seeds of each error_estimate scene together (bench/cycles/error_estimate.py --seeds-csv)."""
    rows = latest(read("error_estimate_seeds.csv"), lambda r: r["scene"])
    out = []
    for r in rows:
        est, spread, sys_, meas = (float(r[k]) for k in ("estimated_rms", "seed_noise", "systematic", "measured_rms"))
        out.append([ESTIMATE_SCENES.get(r["scene"], r["scene"]), r["seeds"], r["bins"], pct(est),
                    pct(spread), f"**{num(est / spread, 2)}**", pct(sys_), f"{r['worst_bins']}: {pct(r['worst_share'], 0)}",
                    pct(r["systematic_without_worst"]), pct(meas), f"**{num(math.sqrt(est ** 2 + sys_ ** 2) / meas, 2)}**"])
    return table(["scene", "seeds", "bins scored", "estimate, RMS over seeds", "one bake's spread over the seeds",
                  "estimate / spread", "systematic against Cycles", "worst 1% of bins: share of its square",
                  "systematic without them", "measured, noise removed, RMS", "√(estimate² + systematic²) / measured"], out)


def t_vpl_blocks():
    rows = read("vpl_blocks.csv")
    out = []
    for binary in dict.fromkeys(r["binary"] for r in rows):
        g = [r for r in rows if r["binary"] == binary]
        out.append([binary, len(g), num(median(r["wall_s"] for r in g), 2), num(median(r["cpu_s"] for r in g), 2),
                    f"{median(r['peak_mib'] for r in g):.0f}", num(median(r["backend_s"] for r in g), 2)])
    return table(["irbake", "runs", "median wall (s)", "CPU (s)", "peak (MiB)", "backend (s)"], out)


def t_directional():
    rows = read("directional.csv")
    out = []
    for key in dict.fromkeys((r["scene"], r["mode"]) for r in rows):
        g = [r for r in rows if (r["scene"], r["mode"]) == key]
        out.append([key[0], key[1], g[0]["backend"], len(g), num(median(r["wall_s"] for r in g), 2),
                    num(median(r["cpu_s"] for r in g), 2), f"{median(r['peak_mib'] for r in g):.0f}",
                    num(median(r["backend_s"] for r in g), 2), num(median(r["directional_s"] for r in g), 2),
                    num(g[0]["exr_mib"], 1)])
    return table(["scene", "bake", "backend", "runs", "median wall (s)", "CPU (s)", "peak (MiB)", "backend (s)",
                  "directional stage (s)", "EXR pages (MiB)"], out)


def t_probe_spheres():
    """A white sphere lit by our probes in a default bake (irview --probe-object) against Cycles
    (bench/cycles/probe_spheres.py): per scene, place and Cycles' sphere, the latest row of each seed."""
    rows = latest([r for r in read("probe_spheres.csv") if r["our_options"] == "" and r["ours"] == "irview"],
                  lambda r: (r["scene"], r["place"], r["cycles_sphere"], r["our_seed"]))
    out = []
    for key in sorted(dict.fromkeys((r["scene"], r["cycles_sphere"], r["place"]) for r in rows)):
        g = [r for r in rows if (r["scene"], r["cycles_sphere"], r["place"]) == key]
        ratios = [float(r["ratio"]) for r in g]
        worst = max(float(r["worst_quarter"]) for r in g)
        ok = sum(abs(float(r["ratio"]) - 1) <= 0.03 and float(r["worst_quarter"]) <= 0.05 for r in g)
        r = g[0]
        out.append([r["scene"], r["place"], r["centre"], r["radius"], num(r["sunlit"], 2), r["cycles_sphere"], len(g),
                    f"**{min(ratios):.3f} … {max(ratios):.3f}**", pct(worst, 1), f"{ok} of {len(g)}",
                    pct(r["ref_noise"]), r["ref_spp"]])
    return table(["scene", "place", "centre (m)", "R (m)", "sunlit", "Cycles' sphere", "seeds", "ours/Cycles",
                  "worst quarter, worst seed", "seeds within 3% / 5%", "Cycles' noise", "Cycles spp"], out)


def t_export_meshes():
    out = [[r["meshes"], r["input"], r["materials"], r["runs"], num(r["seconds_median"], 3), num(r["seconds_min"], 3),
            num(r["seconds_max"], 3)] for r in read("export_meshes.csv")]
    return table(["meshes", "input document", "materials", "runs", "median (s)", "min (s)", "max (s)"], out)


def t_atlas():
    out = []
    for r in read("atlas.csv"):
        out.append([r["scene"], r["triangles"], r["charts"], f"{r['page_w']}×{r['page_h']}", pct(r["centre_util"], 1),
                    f"{float(r['stretch_p5']):.2f}…{float(r['stretch_p95']):.2f}", r["overlapping_texels"],
                    r["flipped"], num(r["median_s"], 2), r["xatlas_charts"], pct(r["xatlas_util"], 1),
                    num(r["xatlas_s"], 2), r["target"]])
    return table(["scene", "triangles", "charts", "page", "utilisation", "area stretch p5…p95", "overlaps",
                  "flipped", "median (s)", "xatlas charts", "xatlas utilisation", "xatlas (s)", "target"], out)


def t_atlas_threads():
    """The atlas stage by thread count (bench/atlas_threads.py): the latest row of each machine, scene and thread
    count."""
    rows = latest(read("atlas_threads.csv"), lambda r: (r["machine"], r["scene"], r["threads"]))
    out = [[r["machine"], r["scene"], r["charts"], r["threads"], r["runs"], num(r["median_atlas_s"], 2),
            num(r["median_pack_s"], 2), num(r["median_cpu_s"], 2), r["load_average"], f"`{r['output_md5']}`"]
           for r in rows]
    return table(["machine", "scene", "charts", "threads", "runs", "atlas median (s)", "of it packing (s)",
                  "process CPU (s)", "load (1 min)", "unwrapped file (md5)"], out)


def t_viewer():
    with open(os.path.join(RESULTS, "viewer_bench.csv")) as f:
        lines = f.read().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("name,"))
    out = []
    for r in csv.DictReader(io.StringIO("\n".join(lines[start:]))):
        if r["name"].endswith("_median"):
            out.append([r["name"].split("/")[0].replace("BM_", ""), r["triangles"], r["fragments"],
                        num(r["real_time"], 1), num(r["cpu_ms_per_frame"], 1)])
    return table(["frame", "triangles", "fragments", "median wall (ms)", "CPU (ms per frame)"], out)


def t_gallery_walk():
    rows = read("gallery_walk.csv")
    last = {}
    for r in rows:
        last[(r["options"], r["seed"])] = r
    out = []
    for options in dict.fromkeys(k[0] for k in last):
        g = [r for k, r in last.items() if k[0] == options]
        ratios = [float(r["mean_ratio"]) for r in g]
        out.append([f"`{options}`" if options else "default (auto split)", len(g),
                    f"{min(ratios):.3f}…{max(ratios):.3f}", pct(median(r["rel_rmse_4"] for r in g)),
                    pct(max(float(r["rel_rmse_4"]) for r in g))])
    return table(["walk", "seeds", "mean ratio, ours/converged", "rel. RMSE 4×4, median", "worst seed"], out)


def t_compressed_inputs():
    """Per scene, each glTF-Transform variant's bake against the plain input's (tests/compressed): irbake diff's
    relative RMSE, then irview's MAD (of 255) on the input's albedo view / on the bake."""
    rows = latest(read("compressed_inputs.csv"), lambda r: (r["scene"], r["variant"]))
    out = []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        cells = {r["variant"]: f"{pct(r['relative_rmse']) or 'new atlas'}; {num(r['input_mad'], 1)}/{num(r['bake_mad'], 1)}"
                 for r in rows if r["scene"] == scene}
        out.append([scene] + [cells.get(v, "") for v in ("meshopt", "draco", "quantize")])
    return table(["scene", "meshopt", "draco", "quantize"], out)


# The Cycles comparison behind each timed preset case: (scene, options) of quality_presets.csv -> the compare.py
# CSV, its mode (map: page 0; view: every view, summarised by their mean) and the options compare.py gave
# besides --quality (the same scene as the timed one, its light in the file or on the command line).
PRESET_ERRORS = {
    ("cornell_sample", ""): ("cycles_cornell_sample.csv", "map", ""),
    ("sponza_sun_sky", "--sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7"): ("cycles_sponza_sun_sky.csv", "view", "--sky 0.4,0.5,0.7"),
}


def preset_errors(name, mode, base):
    """preset -> the latest row of each view (or the map) for that preset's options."""
    found = {}
    for r in read(name):
        if r["mode"] != mode or not r["our_options"].startswith(base):
            continue
        rest = r["our_options"][len(base):].split()
        preset = "default" if not rest else rest[1] if rest[:1] == ["--quality"] and len(rest) == 2 else None
        if preset:
            views = found.setdefault(preset, {})
            if r["view"] not in views or r["date"] >= views[r["view"]]["date"]:
                views[r["view"]] = r
    return {p: [v[k] for k in sorted(v)] for p, v in found.items()}


def t_quality_presets():
    """Each --quality preset: time and memory (quality_presets.py) beside its error against Cycles (compare.py):
    the map's, or the mean over the views with each view's in brackets."""
    timing = latest(read("quality_presets.csv"), lambda r: (r["scene"], r["options"], r["preset"]))
    errors = {case: preset_errors(*source) for case, source in PRESET_ERRORS.items()}
    out = []
    for t in timing:
        e = errors.get((t["scene"], t["options"]), {}).get(t["preset"], [])
        compared, error, ratio = "", "", ""
        if len(e) == 1:
            compared, error, ratio = "map", f"**{pct(e[0]['rel_rmse_4_corrected'])}**", num(e[0]["mean_ratio"], 3)
        elif e:
            values = [float(r["rel_rmse_4_corrected"]) for r in e]
            ratios = [float(r["mean_ratio"]) for r in e]
            compared = "views " + " / ".join(r["view"] for r in e)
            error = f"**{pct(statistics.fmean(values))}** ({' / '.join(f'{100 * v:.2f}' for v in values)}%)"
            ratio = f"{min(ratios):.3f}…{max(ratios):.3f}"
        out.append([t["scene"], f"`{t['options']}`" if t["options"] else "", f"`{t['preset']}`",
                    f"{int(t['page_texels']) / 1e3:.0f}k", t["runs"], t["median_wall_s"], t["peak_memory_mib"],
                    t.get("load_before_runs") or "", t["load_average"], compared, error, ratio])
    return table(["scene", "options", "preset", "page texels", "runs", "median wall (s)", "peak memory (MiB)",
                  "load before runs", "load after", "compared with Cycles", "rel. RMSE 4×4, noise removed",
                  "mean ours/Cycles"], out)


def gather_outliers():
    rows = latest(read("gather_outliers.csv"), lambda r: (r["scene"], r["gather_outliers"]))
    return table(["scene", "`--gather-outliers`", "final gather (s)", "texels held", "light moved", "mean / unheld",
                  "texels > 1.10× / > 1.25× the other bake's"],
                 [[r["scene"], r["gather_outliers"], r["final_gather_s"], r["outlier_texels"], pct(r["outlier_fraction"]),
                   num(r["mean_vs_unheld"], 4), f"{r['above_other_10pct']} / {r['above_other_25pct']}"] for r in rows])


TABLES = {name[2:]: fn for name, fn in globals().items() if name.startswith("t_")}
# Tables not in docs/validation.md (its size limit): --print renders them, --check does not ask for them.
UNPLACED = {"gpu_h100": gpu_h100, "gpu_h200": gpu_h200, "gather_outliers": gather_outliers}
MARKER = re.compile(r"<!-- table:([a-z0-9_]+) -->\n(.*?)<!-- /table:\1 -->", re.S)


def render(doc):
    known = {**TABLES, **UNPLACED}
    missing = [name for name in TABLES if f"<!-- table:{name} -->" not in doc]
    unknown = [m.group(1) for m in MARKER.finditer(doc) if m.group(1) not in known]
    new = MARKER.sub(lambda m: f"<!-- table:{m.group(1)} -->\n{known[m.group(1)]()}\n<!-- /table:{m.group(1)} -->"
                     if m.group(1) in known else m.group(0), doc)
    return new, missing, unknown


def main():
    global RESULTS
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--check", metavar="DOC")
    g.add_argument("--write", metavar="DOC")
    g.add_argument("--print", metavar="NAME", choices=sorted(TABLES) + sorted(UNPLACED))
    p.add_argument("--results", default=RESULTS)
    a = p.parse_args()
    RESULTS = a.results
    if a.print:
        print({**TABLES, **UNPLACED}[a.print]())
        return 0
    path = a.check or a.write
    with open(path, encoding="utf-8") as f:
        doc = f.read()
    new, missing, unknown = render(doc)
    for name in missing:
        print(f"{path}: no <!-- table:{name} --> block", file=sys.stderr)
    for name in unknown:
        print(f"{path}: unknown table '{name}'", file=sys.stderr)
    if a.write:
        if new != doc:
            tmp = path + ".tmp"
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(new)
            os.replace(tmp, path)
        return 1 if missing or unknown else 0
    if new != doc:
        sys.stdout.writelines(difflib.unified_diff(doc.splitlines(True), new.splitlines(True), path,
                                                   path + " (generated from " + RESULTS + ")"))
        print(f"{path}: tables differ from the CSVs; run: python3 bench/validation_tables.py --write {path}",
              file=sys.stderr)
        return 1
    return 1 if missing or unknown else 0


if __name__ == "__main__":
    sys.exit(main())
