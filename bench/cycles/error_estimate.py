#!/usr/bin/python3
"""The bake's estimated error (report.json estimatedError) against its error measured on Cycles' bake in our atlas.

usage (from the repository root, after compare.py --maps has cached Cycles' bake of the same atlas):
  /usr/bin/python3 bench/cycles/error_estimate.py SCENE --name NAME --map-spp 256 [--bake-lights] [--sky R,G,B]
      --bakes DIR [DIR ...] [--csv bench/results/error_estimate.csv]

Each DIR is an `irbake bake ... --estimate-error` output (scene.gltf, lightmap_0.exr, report.json). The score is
compare.py's MAP score on the same texels (covered, chart-border ring and hidden texels left out, 4x4 bins with
at least half their texels kept): rel_rmse_4, the reference's own noise and rel_rmse_4_corrected; the row adds
the estimate on the same kind of bins (the report's estimatedError.interior: the chart-border ring left out;
estimated_all_bins is the headline figure over every valid texel) and the ratio estimate / rel_rmse_4_corrected.
With two or more bakes (seeds of one atlas), a row in --seeds-csv: one bake's spread across the seeds on the
scored bins (what the estimate should match, without Cycles), the seeds' mean's systematic difference from
Cycles (both noises removed) and the share of its square in the worst 1% of bins (logged with their texels).
--score-only prints the score of any bakes of the atlas (no estimate needed), against Cycles or, with --halves
A B, against two of our own bakes (two seeds of `--backend reference`: our bias without Cycles' scene). Cycles runs (cached) exactly as compare.py runs it;
--map-grid 4 bakes it at 4x the atlas' size and averages back, so that its texel is the mean over the whole square as ours
(see grid_mean; name such rows NAME_grid4).
"""
import argparse
import csv
import datetime
import json
import math
import os
import sys
from types import SimpleNamespace

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402

FIELDS = ["date", "commit", "scene", "seed", "our_options", "texels", "estimated", "est_vpls", "est_compensation_rays",
          "est_gather_rays", "rel_rmse_4", "ref_noise_4", "rel_rmse_4_corrected", "ratio", "mean_ratio", "ref_spp",
          "our_bake_s", "load_1min", "estimate_bins", "estimated_all_bins"]

SEED_FIELDS = ["date", "commit", "scene", "seeds", "bins", "estimated_rms", "seed_noise", "systematic", "worst_bins",
               "worst_share", "systematic_without_worst", "measured_rms"]


def grid_mean(img, g):
    """A map baked at g x the atlas' size, back to the atlas: each texel the mean of its covered sub-texels (A = the
    covered share). Cycles' bake averages a texel over the middle half of its side only (Blender's texel
    differentials are half a texel) and on the triangle under its centre; at g = 4 and one sample per sub-texel
    (Cycles' first sample is the centre) a texel is a 4 x 4 grid of points over its whole square, as ours."""
    if g == 1:
        return img
    h, w = img.shape[0] // g, img.shape[1] // g
    blk = img[:h * g, :w * g].reshape(h, g, w, g, 4)
    cov = (blk[..., 3] > 0.5).astype(np.float64)
    n = cov.sum(axis=(1, 3))
    out = np.zeros((h, w, 4))
    out[..., :3] = (blk[..., :3] * cov[..., None]).sum(axis=(1, 3)) / np.maximum(n, 1)[..., None]
    out[..., 3] = (n >= g * g / 2).astype(np.float64)
    return out


def cycles_halves(args, out):
    """Cycles' two cached half bakes of out's atlas and the texels the map score keeps."""
    rep = json.load(open(os.path.join(out, "report.json")))
    pages = rep["atlas"]["pages"]
    if len(pages) != 1:
        compare.fail("%s: %d pages (the map comparison needs one)" % (out, len(pages)))
    w, h = pages[0]["width"], pages[0]["height"]
    scene = os.path.join(out, "scene.gltf")
    g = args.map_grid
    base = ["--uv", "UVMap.001", "--width", str(g * w), "--height", str(g * h), "--max-bounces", str(args.max_bounces)]
    if args.bake_lights:
        base += ["--cycles-dir", args.cycles_dir]
        if args.sky:
            base += ["--sky", args.sky]
    half = max(1, args.map_spp // 2)
    sub = max(1, half // (g * g))  # samples per sub-texel: the same samples per texel
    kf = [compare.export_key_file(scene, out)]
    refs = [compare.cycles_cached(args, args.bake_script, scene, base + ["--spp", str(sub), "--seed", str(s)], "map.exr", kf)
            for s in (1, 2)]
    a, b = (grid_mean(compare.read_exr(r[0]), g) for r in refs)
    cov = (a[..., 3] > 0.5) & (b[..., 3] > 0.5)
    lum = (a[..., :3] + b[..., :3]).mean(axis=2)
    hidden = cov & (lum < args.hidden_cut * lum[cov].mean())
    for _ in range(2):
        hidden = ~compare.erode_cover(~hidden)
    mask = compare.erode_cover(cov) & ~hidden
    return rep, a, b, mask, 2 * sub * g * g


def score_only(args):
    """--score-only: each bake's map score on Cycles' kept texels, against Cycles' halves or, with --halves,
    against two of our own bakes of the same atlas (e.g. two seeds of --backend reference); no estimate needed."""
    for out in args.bakes:
        _, a, b, mask, _ = cycles_halves(args, out)
        if args.halves:
            a, b = (compare.read_exr(os.path.join(d, "lightmap_0.exr")) for d in args.halves)
        ours = compare.read_exr(os.path.join(out, "lightmap_0.exr"))[..., :3]
        s = compare.score(ours, a[..., :3], b[..., :3], mask)
        compare.log("%s against %s: %.2f%%, the halves' noise %.2f%%, noise removed %.2f%%, mean ratio %.4f" % (
            out, " and ".join(args.halves) if args.halves else "Cycles", 100 * s["rel_rmse_4"], 100 * s["ref_noise_4"],
            100 * s["rel_rmse_4_corrected"], s["mean_ratio"]))


def score_bake(args, out):
    rep, a, b, mask, spp = cycles_halves(args, out)
    ours = compare.read_exr(os.path.join(out, "lightmap_0.exr"))[..., :3]
    s = compare.score(ours, a[..., :3], b[..., :3], mask)
    e = rep.get("estimatedError")
    if e is None:
        compare.fail("%s: no estimatedError in the report (bake with --estimate-error)" % out)
    # The figure on the bins this score keeps (chart-border ring left out) where the report has it.
    scored = e.get("interior", e)
    return rep, s, e, scored, spp, (ours, a[..., :3], b[..., :3], mask)


def across_seeds(args, maps, rows):
    """Bakes of several seeds on one atlas: their spread (the noise the estimate should see, on the scored
    bins) and the mean's systematic difference from Cycles (both noises removed), and how much of that
    difference's square the worst bins carry. Returns one CSV row; logs the worst bins."""
    _, a, b, mask = maps[0]
    ours = np.stack([compare.bin_means(m[0], mask, 4) for m in maps])
    ref, ra, rb = compare.bin_means(0.5 * (a + b), mask, 4), compare.bin_means(a, mask, 4), compare.bin_means(b, mask, 4)
    rms = np.sqrt(np.mean(ref ** 2))
    n = len(maps)
    seed_var = ours.var(axis=0, ddof=1)                    # per bin and channel: one bake's variance
    ref_var = (ra - rb) ** 2 / 4                            # Cycles' two halves: its mean's variance
    excess = ((ours.mean(axis=0) - ref) ** 2 - seed_var / n - ref_var).sum(axis=1)  # per bin, unbiased
    systematic2 = excess.mean() / 3
    order = np.argsort(-excess)
    top = max(1, len(excess) // 100)
    share = excess[order[:top]].sum() / excess.sum() if excess.sum() > 0 else float("nan")
    without = max(0.0, excess[order[top:]].sum() / 3 / len(excess))
    est = math.sqrt(sum(float(r["estimated"]) ** 2 for r in rows) / len(rows))
    row = {"date": rows[0]["date"], "commit": rows[0]["commit"], "scene": args.name, "seeds": n, "bins": len(excess),
           "estimated_rms": est, "seed_noise": math.sqrt(seed_var.mean()) / rms,
           "systematic": math.sqrt(max(systematic2, 0.0)) / rms, "worst_bins": top, "worst_share": share,
           "systematic_without_worst": math.sqrt(without) / rms,
           "measured_rms": math.sqrt(sum(float(r["rel_rmse_4_corrected"]) ** 2 for r in rows) / len(rows))}
    compare.log("%s over %d seeds (%d bins): one bake's spread %.2f%% (estimate RMS %.2f%%), systematic %.2f%%, "
                "the worst %d bins carry %.0f%% of its square (%.2f%% without them)" % (
                    args.name, n, len(excess), 100 * row["seed_noise"], 100 * est, 100 * row["systematic"], top,
                    100 * share, 100 * row["systematic_without_worst"]))
    h, w = (mask.shape[0] // 4) * 4, (mask.shape[1] // 4) * 4
    cnt = mask[:h, :w].reshape(h // 4, 4, w // 4, 4).sum(axis=(1, 3))
    where = np.argwhere(cnt >= 8)
    for i in order[:min(top, 5)]:
        y, x = where[i]
        compare.log("  bin at texels x %d-%d, y %d-%d: ours/Cycles %.3f, %.1f%% of the systematic square" % (
            4 * x, 4 * x + 3, 4 * y, 4 * y + 3, ours.mean(axis=0)[i].sum() / ref[i].sum(), 100 * excess[i] / excess.sum()))
    return row


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
    ap.add_argument("--map-grid", type=int, default=1, help="Cycles bakes the atlas at N x its size, 1 sample per "
                    "sub-texel when --map-spp allows, averaged back: a texel over its whole square (see grid_mean)")
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--cycles-dir", default=os.path.join(compare.REPO, "..", "shared", "tools", "cycles"))
    ap.add_argument("--cache", default=os.path.join(compare.REPO, "build", "cycles-cache"))
    ap.add_argument("--irbake", default=os.path.join(compare.REPO, "build", "baker", "irbake"))
    ap.add_argument("--csv", default=os.path.join(compare.REPO, "bench", "results", "error_estimate.csv"))
    ap.add_argument("--score-only", action="store_true", help="print each bake's map score, write no row")
    ap.add_argument("--halves", nargs=2, metavar="DIR", help="with --score-only: score against these two bakes")
    ap.add_argument("--seeds-csv", default=os.path.join(compare.REPO, "bench", "results", "error_estimate_seeds.csv"))
    args = ap.parse_args()
    args.bake_script = os.path.join(args.cycles_dir, "cycles_bake.py")
    if args.bake_lights:
        args.bake_script = os.path.join(compare.REPO, "bench", "cycles", "cycles_bake_lights.py")
    if args.score_only:
        return score_only(args)
    rows, maps = [], []
    for out in args.bakes:
        rep, s, e, scored, spp, m = score_bake(args, out)
        maps.append(m)
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
    if len(maps) >= 2:
        row = across_seeds(args, maps, rows)
        new = not os.path.isfile(args.seeds_csv)
        with open(args.seeds_csv, "a", newline="") as f:
            wr = csv.DictWriter(f, fieldnames=SEED_FIELDS)
            if new:
                wr.writeheader()
            wr.writerow({k: (round(v, 5) if isinstance(v, float) else v) for k, v in row.items()})


if __name__ == "__main__":
    main()
