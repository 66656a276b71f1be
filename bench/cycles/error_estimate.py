#!/usr/bin/python3
"""The bake's estimated error (report.json estimatedError) against its error measured on Cycles' bake in our atlas.

usage (from the repository root, after compare.py --maps has cached Cycles' bake of the same atlas):
  /usr/bin/python3 bench/cycles/error_estimate.py SCENE --name NAME --map-spp 256 [--bake-lights] [--sky R,G,B]
      --bakes DIR [DIR ...] [--csv bench/results/error_estimate.csv]

Each DIR is an `irbake bake ... --estimate-error` output (scene.gltf, lightmap_0.exr, report.json). The score is
compare.py's MAP score on the same texels (covered, chart-border ring and hidden texels left out, 4x4 bins with
at least half their texels kept): rel_rmse_4, the reference's own noise and rel_rmse_4_corrected; the row adds
the estimate on the same kind of bins (the report's estimatedError.interior: the chart-border ring left out;
estimated_all_bins is the headline figure over every valid texel) and the ratio estimate / rel_rmse_4_corrected. Cycles runs (cached) exactly as compare.py runs it.
"""
import argparse
import csv
import datetime
import json
import os
import sys
from types import SimpleNamespace

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402

FIELDS = ["date", "commit", "scene", "seed", "our_options", "texels", "estimated", "est_vpls", "est_compensation_rays",
          "est_gather_rays", "rel_rmse_4", "ref_noise_4", "rel_rmse_4_corrected", "ratio", "mean_ratio", "ref_spp",
          "our_bake_s", "load_1min", "estimate_bins", "estimated_all_bins"]


def score_bake(args, out):
    rep = json.load(open(os.path.join(out, "report.json")))
    pages = rep["atlas"]["pages"]
    if len(pages) != 1:
        compare.fail("%s: %d pages (the map comparison needs one)" % (out, len(pages)))
    w, h = pages[0]["width"], pages[0]["height"]
    scene = os.path.join(out, "scene.gltf")
    base = ["--uv", "UVMap.001", "--width", str(w), "--height", str(h), "--max-bounces", str(args.max_bounces)]
    if args.bake_lights:
        base += ["--cycles-dir", args.cycles_dir]
        if args.sky:
            base += ["--sky", args.sky]
    half = max(1, args.map_spp // 2)
    kf = [compare.export_key_file(scene, out)]
    refs = [compare.cycles_cached(args, args.bake_script, scene, base + ["--spp", str(half), "--seed", str(s)], "map.exr", kf)
            for s in (1, 2)]
    a, b = compare.read_exr(refs[0][0]), compare.read_exr(refs[1][0])
    cov = (a[..., 3] > 0.5) & (b[..., 3] > 0.5)
    lum = (a[..., :3] + b[..., :3]).mean(axis=2)
    hidden = cov & (lum < args.hidden_cut * lum[cov].mean())
    for _ in range(2):
        hidden = ~compare.erode_cover(~hidden)
    mask = compare.erode_cover(cov) & ~hidden
    ours = compare.read_exr(os.path.join(out, "lightmap_0.exr"))[..., :3]
    s = compare.score(ours, a[..., :3], b[..., :3], mask)
    e = rep.get("estimatedError")
    if e is None:
        compare.fail("%s: no estimatedError in the report (bake with --estimate-error)" % out)
    # The figure on the bins this score keeps (chart-border ring left out) where the report has it.
    scored = e.get("interior", e)
    return rep, s, e, scored, 2 * half


def main():
    ap = argparse.ArgumentParser(description="estimated against measured error (see the header)")
    ap.add_argument("scene")
    ap.add_argument("--name", required=True)
    ap.add_argument("--bakes", nargs="+", required=True)
    ap.add_argument("--map-spp", type=int, default=256)
    ap.add_argument("--bake-lights", action="store_true")
    ap.add_argument("--sky", default="")
    ap.add_argument("--max-bounces", type=int, default=64)
    ap.add_argument("--hidden-cut", type=float, default=0.02)
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--cycles-dir", default=os.path.join(compare.REPO, "..", "shared", "tools", "cycles"))
    ap.add_argument("--cache", default=os.path.join(compare.REPO, "build", "cycles-cache"))
    ap.add_argument("--irbake", default=os.path.join(compare.REPO, "build", "baker", "irbake"))
    ap.add_argument("--csv", default=os.path.join(compare.REPO, "bench", "results", "error_estimate.csv"))
    args = ap.parse_args()
    args.bake_script = os.path.join(args.cycles_dir, "cycles_bake.py")
    if args.bake_lights:
        args.bake_script = os.path.join(compare.REPO, "bench", "cycles", "cycles_bake_lights.py")
    rows = []
    for out in args.bakes:
        rep, s, e, scored, spp = score_bake(args, out)
        br = scored.get("breakdown", {})
        corrected = s["rel_rmse_4_corrected"]
        opts = rep.get("options", {})
        row = {"date": datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%MZ"), "commit": compare.git_commit(args.irbake),
               "scene": args.name, "seed": opts.get("seed", "0"),
               "our_options": " ".join("--%s %s" % (k, v) for k, v in sorted(opts.items()) if k != "seed"),
               "texels": rep["texels"]["valid"], "estimated": scored["relative"], "est_vpls": br.get("vpls", ""),
               "est_compensation_rays": br.get("compensationRays", ""), "est_gather_rays": br.get("finalGatherRays", br.get("compensationAndGatherRays", "")),
               "rel_rmse_4": s["rel_rmse_4"], "ref_noise_4": s["ref_noise_4"], "rel_rmse_4_corrected": corrected,
               "ratio": scored["relative"] / corrected if corrected > 0 else "", "mean_ratio": s["mean_ratio"], "ref_spp": spp,
               "our_bake_s": rep["timings"]["seconds"]["bake"], "load_1min": open("/proc/loadavg").read().split()[0],
               "estimate_bins": "interior" if "interior" in e else "valid", "estimated_all_bins": e["relative"]}
        rows.append(row)
        compare.log("%s seed %s: estimated %.2f%%, measured %.2f%% (corrected %.2f%%, ref noise %.2f%%), ratio %.2f" % (
            args.name, row["seed"], 100 * scored["relative"], 100 * s["rel_rmse_4"], 100 * corrected, 100 * s["ref_noise_4"],
            row["ratio"] if row["ratio"] != "" else float("nan")))
    new = not os.path.isfile(args.csv)
    with open(args.csv, "a", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=FIELDS)
        if new:
            wr.writeheader()
        for r in rows:
            wr.writerow({k: (round(v, 5) if isinstance(v, float) else v) for k, v in r.items()})
    compare.log("appended %d row(s) to %s" % (len(rows), args.csv))


if __name__ == "__main__":
    main()
