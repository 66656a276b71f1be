#!/usr/bin/env python3
"""gather_outliers.py IRBAKE SCENE OUTROOT [--csv bench/results/gather_outliers.csv]: the final gather's outliers.

Bakes SCENE (the night town of bench/levels/town_night.sh) as that script does, with --gather-outliers 0 (no
texel held) and 4 (the default), and writes one row per bake: the final gather's seconds,
the report's outlierTexels and outlierFraction, and, against the unheld bake's map, the ratio of the mean
luminance and how many valid texels stand more than 10% / 25% above the other bake's (the unheld bake's bright
squares show as texels above the held one's; the held bake's wide spread as a few texels slightly above).

  python3 bench/levels/town.py build/levels/town_night/town3_night.glb --blocks 3 --lamps 24 --range 15
  python3 bench/levels/gather_outliers.py build/baker/irbake build/levels/town_night/town3_night.glb /tmp/outliers
"""
import argparse
import array
import csv
import datetime
import json
import os
import struct
import subprocess

FIELDS = ["date", "commit", "scene", "gather_outliers", "final_gather_s", "outlier_texels", "outlier_fraction",
          "mean_vs_unheld", "texels", "above_other_10pct", "above_other_25pct"]
BAKE = ["--quality", "preview", "--sky", "0.02,0.03,0.06", "--probes", "off", "--quiet"]


def read_exr(path):
    """Mean of R, G, B per pixel of an uncompressed float scanline EXR (the maps irbake writes)."""
    with open(path, "rb") as f:
        d = f.read()
    i, attrs = 8, {}
    while d[i] != 0:
        n = d.index(b"\0", i); name = d[i:n].decode(); i = n + 1
        n = d.index(b"\0", i); i = n + 1
        size = struct.unpack_from("<i", d, i)[0]; i += 4
        attrs[name] = d[i:i + size]; i += size
    i += 1
    x0, y0, x1, y1 = struct.unpack("<4i", attrs["dataWindow"])
    if attrs["compression"][0] != 0:
        raise SystemExit(f"{path}: compressed EXR (this reader takes uncompressed ones)")
    names, j, ch = [], 0, attrs["channels"]
    while ch[j] != 0:
        n = ch.index(b"\0", j); names.append(ch[j:n].decode()); j = n + 1 + 16
    w, h = x1 - x0 + 1, y1 - y0 + 1
    lum = array.array("f")
    for o in struct.unpack_from(f"<{h}Q", d, i):
        size = struct.unpack_from("<i", d, o + 4)[0]
        row = array.array("f"); row.frombytes(d[o + 8:o + 8 + size])
        r, g, b = (row[names.index(c) * w:(names.index(c) + 1) * w] for c in "RGB")
        lum.extend((r[x] + g[x] + b[x]) / 3 for x in range(w))
    return lum


def compare(a, b):
    """Σa / Σb over texels lit in either, the count of those, and of a > 1.10 b and a > 1.25 b."""
    sa = sb = 0.0; n = up10 = up25 = 0
    for va, vb in zip(a, b):
        if va <= 0 and vb <= 0:
            continue
        sa += va; sb += vb; n += 1
        up10 += va > 1.10 * vb; up25 += va > 1.25 * vb
    return sa / sb, n, up10, up25


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("irbake"); p.add_argument("scene"); p.add_argument("outroot")
    p.add_argument("--csv", default="bench/results/gather_outliers.csv")
    a = p.parse_args()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    bakes = []
    for ratio in ["0", "4"]:
        out = os.path.join(a.outroot, "outliers_" + ratio)
        subprocess.run([a.irbake, "bake", a.scene, "-o", out] + BAKE + ["--gather-outliers", ratio], check=True)
        with open(os.path.join(out, "report.json")) as f:
            report = json.load(f)
        bakes.append((ratio, report, read_exr(os.path.join(out, "lightmap_0.exr"))))
    unheld = bakes[0][2]
    rows = []
    for k, (ratio, report, lum) in enumerate(bakes):
        mean, n, up10, up25 = compare(lum, unheld)
        other = bakes[1 - k][2]
        _, _, up10, up25 = compare(lum, other)
        g = report.get("finalGather", {})
        rows.append({"date": datetime.date.today().isoformat(), "commit": commit, "scene": os.path.basename(a.scene),
                     "gather_outliers": ratio, "final_gather_s": f"{report['timings']['seconds']['finalGather']:.2f}",
                     "outlier_texels": g.get("outlierTexels", 0), "outlier_fraction": f"{g.get('outlierFraction', 0):.5f}",
                     "mean_vs_unheld": f"{mean:.5f}", "texels": n, "above_other_10pct": up10, "above_other_25pct": up25})
    new = not os.path.exists(a.csv)
    with open(a.csv, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        if new:
            w.writeheader()
        w.writerows(rows)
    for r in rows:
        print(r)


if __name__ == "__main__":
    main()
