#!/usr/bin/python3
"""Our bake against Blender Cycles, both ways: texel for texel in our atlas (MAP) and through the viewer (VIEW).

usage (from the repository root; Debian's /usr/bin/python3 with python3-numpy and python3-openimageio):
  /usr/bin/python3 bench/cycles/compare.py SCENE --name NAME [--opts "--vpls 4096" ...]
      [--maps --map-spp 1024 --map-ladder 4,16,64,256]
      [--views 0,1 --view-size 128x128 --view-spp 2048]
      [--irbake build/baker/irbake --irview build/runtime/irview] [--csv bench/results/cycles_NAME.csv]

For each option set (--opts, repeatable; "" = defaults) it runs `irbake bake SCENE -o WORK/NAME/<slug> OPTS`
(wall time measured around the process), then
  MAP   (--maps): Cycles bakes its irradiance/pi into our page 0 through cycles_bake.py --uv UVMap.001 at the
        page size. Reference = the mean of two bakes of spp/2 samples (seeds 1, 2); its noise = half their
        difference. Compared over texels Cycles covers (texel centre in a UV triangle, A = 1), minus the ring
        of covered texels next to an uncovered one (chart borders, where both bakers extrapolate), and hidden
        texels (Cycles below 2% of the mean, plus a 2-texel ring: under the blocks, above the light; our
        baker marks them invalid and fills them by dilation), in 4x4
        (and 8x8) texel bins with at least half their texels kept. The ladder (--map-ladder) bakes Cycles at
        each spp (seed 3) and scores it against the reference the same way: Cycles' time for an error.
  VIEW  (--views): cycles_render.py renders the input SCENE from glTF camera i at W x H (two renders of spp/2,
        seeds 1 and 2); irview renders our export at sW x sH, averaged sxs down (s = --view-supersample, 16:
        Cycles' pixels average the textures over their area, which irview's mipmapped lookups approach only
        when supersampled; column rel_rmse_4_ss4 is the same score at 4x). Pixels left out: emitters
        (either image above --emitter-cut in any channel, dilated by one pixel), background (both zero; with
        --sky R,G,B, Cycles renders through bench/cycles/cycles_render_sky.py and its sky pixels are background), and
        1-pixel edges: pixels whose `irview --view charts` colour at W x H differs from any 4-neighbour's
        (chart borders = silhouettes, creases, and seams inside flat regions; both pixels of a border).
        4x4 (8x8) pixel bins with at least half their pixels kept. Columns *_with_edges: the same with the
        edge pixels kept (emitters and background still out).
Figures: mean ratio ours/Cycles over kept pixels/texels; relative RMSE over bins = sqrt(mean (o-r)^2) /
sqrt(mean r^2) over bins and RGB channels; the reference's noise on the same bins (half the seeds'
difference); the error with that noise removed, sqrt(max(0, err^2 - noise^2)).

Every Cycles result is cached under --cache (default build/cycles-cache) by the SHA-256 of its inputs: the
scene file and the files it names (bin, images), the Cycles script, and the options. A re-run after the baker
changes re-runs only our bake (a map re-bakes Cycles only when our atlas changed). Every process runs under
`nice -n 15`.
"""
import argparse
import csv
import datetime
import hashlib
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import time

import numpy as np

try:
    import OpenImageIO as oiio
except ImportError:
    sys.exit("compare.py: needs OpenImageIO's python module (Debian: python3-openimageio; run with /usr/bin/python3)")

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
NICE = ["nice", "-n", "15"]
CSV_FIELDS = ["date", "commit", "scene", "mode", "view", "our_options", "our_wall_s", "our_bake_s", "texels",
              "width", "height", "kept", "mean_ratio", "rel_rmse_4", "rel_rmse_8", "ref_noise_4", "ref_noise_8",
              "rel_rmse_4_corrected", "kept_with_edges", "rel_rmse_4_with_edges", "ref_spp", "ref_s", "cycles_spp", "cycles_s", "cycles_total_s",
              "view_supersample", "rel_rmse_4_ss4"]


def log(*a):
    print("compare:", *a, flush=True)


def fail(msg):
    sys.exit("compare.py: " + msg)


def read_exr(path):
    buf = oiio.ImageBuf(path)
    if buf.has_error:
        fail("%s: %s" % (path, buf.geterror()))
    px = buf.get_pixels(oiio.FLOAT)
    if px is None or px.size == 0:
        fail("%s: no pixels" % path)
    return np.asarray(px, dtype=np.float64)


def gltf_files(scene):
    """The scene file and every external file it names (buffers, images)."""
    files = [scene]
    data = open(scene, "rb").read()
    if data[:4] == b"glTF":
        jl = struct.unpack("<I", data[12:16])[0]
        doc = json.loads(data[20:20 + jl])
    else:
        doc = json.loads(data)
    base = os.path.dirname(scene)
    for item in doc.get("buffers", []) + doc.get("images", []):
        uri = item.get("uri")
        if uri and not uri.startswith("data:"):
            files.append(os.path.join(base, uri.replace("%20", " ")))
    return files


def digest(files, extra):
    h = hashlib.sha256()
    for f in files:
        h.update(os.path.basename(f).encode())
        with open(f, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
    h.update(json.dumps(extra, sort_keys=True).encode())
    return h.hexdigest()[:24]


def load_gltf(path):
    data = open(path, "rb").read()
    base = os.path.dirname(path)
    if data[:4] == b"glTF":
        jl = struct.unpack("<I", data[12:16])[0]
        doc = json.loads(data[20:20 + jl])
        rest = data[20 + jl:]
        bufs = [rest[8:8 + struct.unpack("<I", rest[:4])[0]]] if len(rest) >= 8 else []
    else:
        doc = json.loads(data)
        bufs = [open(os.path.join(base, b["uri"]), "rb").read() for b in doc.get("buffers", [])]
    return doc, bufs


def export_key_file(scene, workdir):
    """Our export minus the light map: every accessor's bytes (positions, both UV sets, indices), the
    materials without MOZ_lightmap, every image but the light-map pages, the lights and cameras. Two bakes
    with the same atlas share one Cycles map bake, whatever their VPL options."""
    doc, bufs = load_gltf(scene)
    h = hashlib.sha256()
    # The irradiance probes (IRBAKE_light_probes: its JSON and accessors) are read from the map, Cycles never
    # sees them: left out, so bakes of other seeds share the reference.
    probes = doc.get("extensions", {}).get("IRBAKE_light_probes", {})
    probe_accessors = {probes.get(k) for k in ("coefficients", "offsets", "valid")} - {None}

    def view_bytes(i):
        v = doc["bufferViews"][i]
        return bufs[v.get("buffer", 0)][v.get("byteOffset", 0):v.get("byteOffset", 0) + v["byteLength"]]
    for i, a in enumerate(doc.get("accessors", [])):
        if i in probe_accessors:
            continue
        h.update(json.dumps(a, sort_keys=True).encode())
        if "bufferView" in a:
            h.update(view_bytes(a["bufferView"]))
    for im in doc.get("images", []):
        if str(im.get("name", "")).startswith("lightmap_"):
            continue
        if "bufferView" in im:
            h.update(view_bytes(im["bufferView"]))
        elif "uri" in im:
            h.update(open(os.path.join(os.path.dirname(scene), im["uri"]), "rb").read())
    mats = json.loads(json.dumps(doc.get("materials", [])))
    for m in mats:
        m.get("extensions", {}).pop("MOZ_lightmap", None)
    extensions = {k: v for k, v in doc.get("extensions", {}).items() if k != "IRBAKE_light_probes"}
    h.update(json.dumps([mats, doc.get("meshes"), doc.get("nodes"), extensions, doc.get("cameras")],
                        sort_keys=True).encode())
    key = os.path.join(workdir, "export.key")
    with open(key, "w") as f:
        f.write(h.hexdigest())
    return key


def run(cmd, logpath):
    t0 = time.time()
    with open(logpath, "w") as lf:
        r = subprocess.run(cmd, stdout=lf, stderr=subprocess.STDOUT)
    dt = time.time() - t0
    if r.returncode != 0:
        fail("%s failed (exit %d); log: %s" % (" ".join(cmd[:6]), r.returncode, logpath))
    return dt


def cycles_cached(args, script, scene, opts, out_name, key_files=None):
    """Run a Cycles script once per input checksum; return (exr path, sidecar json)."""
    key = digest((key_files or gltf_files(scene)) + [script], {"script": os.path.basename(script), "opts": opts})
    d = os.path.join(args.cache, key)
    exr = os.path.join(d, out_name)
    if os.path.isfile(exr) and os.path.isfile(exr + ".json"):
        log("cached", exr, " ".join(opts))
        return exr, json.load(open(exr + ".json"))
    os.makedirs(d, exist_ok=True)
    tmp = exr + ".partial.exr"
    cmd = NICE + [args.blender, "-b", "--factory-startup", "--python", script, "--", "--scene", scene, "--out", tmp] + opts
    log("Cycles:", os.path.basename(script), " ".join(opts))
    wall = run(cmd, exr + ".log")
    meta = json.load(open(tmp + ".json"))
    meta["wall_s"] = wall
    with open(exr + ".json.tmp", "w") as f:
        json.dump(meta, f, indent=1)
    os.replace(tmp, exr)
    os.remove(tmp + ".json")
    os.replace(exr + ".json.tmp", exr + ".json")
    return exr, meta


def bin_means(img, mask, b):
    h, w = (img.shape[0] // b) * b, (img.shape[1] // b) * b
    m = mask[:h, :w].astype(np.float64)
    s = (img[:h, :w] * m[..., None]).reshape(h // b, b, w // b, b, 3).sum(axis=(1, 3))
    n = m.reshape(h // b, b, w // b, b).sum(axis=(1, 3))
    keep = n >= b * b / 2
    return s[keep] / n[keep][:, None]


def score(ours, ref_a, ref_b, mask):
    """Figures of ours against the mean of two independent reference halves, on kept pixels."""
    ref = 0.5 * (ref_a + ref_b)
    out = {"kept": int(mask.sum()), "mean_ratio": float((ours[mask]).sum() / max((ref[mask]).sum(), 1e-30))}
    for b in (4, 8):
        o, r = bin_means(ours, mask, b), bin_means(ref, mask, b)
        a, c = bin_means(ref_a, mask, b), bin_means(ref_b, mask, b)
        rms = np.sqrt(np.mean(r ** 2))
        out["rel_rmse_%d" % b] = float(np.sqrt(np.mean((o - r) ** 2)) / rms)
        out["ref_noise_%d" % b] = float(0.5 * np.sqrt(np.mean((a - c) ** 2)) / rms)
    out["rel_rmse_4_corrected"] = float(np.sqrt(max(0.0, out["rel_rmse_4"] ** 2 - out["ref_noise_4"] ** 2)))
    return out


def append_csv_rows(path, fields, rows):
    """Appends rows to the CSV at path (its header `fields`), rewriting it through a temp name."""
    old = list(csv.DictReader(open(path))) if os.path.isfile(path) else []
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in old + rows:
            w.writerow(r)
    os.replace(tmp, path)
    print("appended %d rows to %s" % (len(rows), path))


def git_commit(irbake):
    """The last commit that touched the baker's sources in the checkout irbake was built in (bench-only
    commits after it do not change the binary), with +dirty when those sources have local changes."""
    src = ["baker", "runtime", "shaders", "samples", "CMakeLists.txt", "cmake"]
    try:
        d = os.path.dirname(os.path.abspath(irbake))
        top = subprocess.run(["git", "-C", d, "rev-parse", "--show-toplevel"], capture_output=True,
                             text=True).stdout.strip() or REPO
        paths = [p for p in src if os.path.exists(os.path.join(top, p))]
        c = subprocess.run(["git", "-C", top, "log", "-1", "--format=%h", "--"] + paths, capture_output=True,
                           text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", top, "status", "--porcelain", "--untracked-files=no", "--"] + paths,
                               capture_output=True, text=True).stdout.strip()
        return c + ("+dirty" if dirty else "")
    except OSError:
        return ""


def slug(opts):
    s = re.sub(r"[^A-Za-z0-9.,=-]+", "_", opts.strip()).strip("_-")
    return s or "default"


def our_bake(args, opts):
    out = os.path.join(args.work, args.name, slug(opts))
    if os.path.isdir(out):
        shutil.rmtree(out)
    os.makedirs(out)
    cmd = NICE + [args.irbake, "bake", args.scene, "-o", out] + opts.split()
    log("ours:", " ".join(cmd[3:]))
    wall = run(cmd, out + ".log")
    rep = json.load(open(os.path.join(out, "report.json")))
    return out, wall, rep


def erode_cover(cov):
    e = cov.copy()
    e[1:, :] &= cov[:-1, :]
    e[:-1, :] &= cov[1:, :]
    e[:, 1:] &= cov[:, :-1]
    e[:, :-1] &= cov[:, 1:]
    return e


def map_mode(args, out, rep, row, rows):
    pages = rep["atlas"]["pages"]
    if len(pages) != 1:
        log("MAP skipped: %d pages (cycles_bake.py bakes one page with every primitive on it)" % len(pages))
        return
    w, h = pages[0]["width"], pages[0]["height"]
    scene = os.path.join(out, "scene.gltf")
    base = ["--uv", "UVMap.001", "--width", str(w), "--height", str(h), "--max-bounces", str(args.max_bounces)]
    if args.bake_lights:
        base += ["--cycles-dir", args.cycles_dir]
        if args.sky:  # the world gets the sky's radiance (cycles_bake_lights.py --sky)
            base += ["--sky", args.sky]
    half = max(1, args.map_spp // 2)
    kf = [export_key_file(scene, out)]
    refs = [cycles_cached(args, args.bake_script, scene, base + ["--spp", str(half), "--seed", str(s)], "map.exr", kf)
            for s in (1, 2)]
    a, b = read_exr(refs[0][0]), read_exr(refs[1][0])
    cov = (a[..., 3] > 0.5) & (b[..., 3] > 0.5)
    # Hidden texels (under a block resting on the floor, the ceiling above the light): our baker marks them
    # invalid and fills them by dilation, Cycles finds them dark. Left out: texels where Cycles' sum of both
    # halves is below --hidden-cut of the mean over covered texels, with a 2-texel ring around them.
    lum = (a[..., :3] + b[..., :3]).mean(axis=2)
    hidden = cov & (lum < args.hidden_cut * lum[cov].mean())
    for _ in range(2):
        hidden = ~erode_cover(~hidden)
    mask = erode_cover(cov) & ~hidden
    log("MAP texels: covered %d, hidden %d, kept %d" % (cov.sum(), (hidden & cov).sum(), mask.sum()))
    ours = read_exr(os.path.join(out, "lightmap_0.exr"))[..., :3]
    if ours.shape[:2] != a.shape[:2]:
        fail("page size mismatch: ours %s, Cycles %s" % (ours.shape, a.shape))
    a, b = a[..., :3], b[..., :3]
    ref_s = sum(r[1].get("bake_time_s", 0.0) for r in refs)
    s = score(ours, a, b, mask)
    if args.save_diff:
        ratio = np.where(mask[..., None], ours / np.maximum(0.5 * (a + b), 1e-6), 0.0)
        oiio.ImageBuf(np.ascontiguousarray(ratio.astype(np.float32))).write(os.path.join(out, "map_ratio.exr"))
    rows.append(dict(row, mode="map", view="page0", width=w, height=h, ref_spp=2 * half, ref_s=round(ref_s, 2), **s))
    log("MAP %s: mean ratio %.4f, binned 4x4 %.2f%% (8x8 %.2f%%), ref noise %.2f%%" % (
        row["our_options"] or "default", s["mean_ratio"], 100 * s["rel_rmse_4"], 100 * s["rel_rmse_8"],
        100 * s["ref_noise_4"]))
    if args.map_ladder and not args.ladder_done:
        args.ladder_done = True
        for spp in [int(x) for x in args.map_ladder.split(",")]:
            exr, meta = cycles_cached(args, args.bake_script, scene, base + ["--spp", str(spp), "--seed", "3"], "map.exr",
                                      kf)
            c = read_exr(exr)[..., :3]
            sc = score(c, a, b, mask)
            rows.append(dict(row, mode="map-cycles", view="page0", our_options="", our_wall_s="", our_bake_s="",
                             width=w, height=h, ref_spp=2 * half, ref_s=round(ref_s, 2), cycles_spp=spp,
                             cycles_s=round(meta.get("bake_time_s", 0.0), 2),
                             cycles_total_s=round(meta.get("total_time_s", 0.0), 2), **sc))
            log("MAP Cycles %d spp: %.1f s, binned 4x4 %.2f%% (corrected %.2f%%), mean ratio %.4f" % (
                spp, meta.get("bake_time_s", 0.0), 100 * sc["rel_rmse_4"], 100 * sc["rel_rmse_4_corrected"], sc["mean_ratio"]))


def view_mode(args, out, row, rows):
    w, h = [int(x) for x in args.view_size.split("x")]
    for v in [int(x) for x in args.views.split(",")]:
        base = ["--camera-index", str(v), "--width", str(w), "--height", str(h), "--max-bounces", str(args.max_bounces)]
        half = max(1, args.view_spp // 2)
        script = args.render_script
        if args.sky:  # our wrapper: the shared script with the world set to the sky's radiance
            script = os.path.join(REPO, "bench", "cycles", "cycles_render_sky.py")
            base += ["--sky", args.sky, "--cycles-dir", args.cycles_dir]
        refs = [cycles_cached(args, script, args.scene, base + ["--spp", str(half), "--seed", str(s)],
                              "view.exr", key_files=gltf_files(args.scene) + [args.render_script] if args.sky else None)
                for s in (1, 2)]
        a, b = read_exr(refs[0][0])[..., :3], read_exr(refs[1][0])[..., :3]
        ss = args.view_supersample
        big = os.path.join(out, "view%d_x%d.exr" % (v, ss))
        small = os.path.join(out, "view%d_x4.exr" % v)
        charts = os.path.join(out, "view%d_charts.exr" % v)
        for path, f in ((big, ss), (small, 4)):
            run(NICE + [args.irview, os.path.join(out, "scene.gltf"), "--camera", str(v), "--screenshot", path,
                        "--width", str(f * w), "--height", str(f * h)], path + ".log")
        run(NICE + [args.irview, os.path.join(out, "scene.gltf"), "--camera", str(v), "--view", "charts",
                    "--screenshot", charts, "--width", str(w), "--height", str(h)], charts + ".log")
        ours = read_exr(big)[..., :3].reshape(h, ss, w, ss, 3).mean(axis=(1, 3))
        ours4 = read_exr(small)[..., :3].reshape(h, 4, w, 4, 3).mean(axis=(1, 3))
        if ss != 4:
            os.remove(big)  # the 16x render is large; the 4x render stays for a look
        ch = read_exr(charts)[..., :3]
        edge = np.zeros((h, w), bool)
        d0 = np.any(np.abs(ch[1:] - ch[:-1]) > 1e-4, axis=2)
        d1 = np.any(np.abs(ch[:, 1:] - ch[:, :-1]) > 1e-4, axis=2)
        edge[1:] |= d0
        edge[:-1] |= d0
        edge[:, 1:] |= d1
        edge[:, :-1] |= d1
        emit = (ours.max(axis=2) > args.emitter_cut) | (a.max(axis=2) > args.emitter_cut) | (b.max(axis=2) > args.emitter_cut)
        e2 = emit.copy()
        e2[1:] |= emit[:-1]
        e2[:-1] |= emit[1:]
        e2[:, 1:] |= emit[:, :-1]
        e2[:, :-1] |= emit[:, 1:]
        empty = (ours.max(axis=2) <= 0) & (a.max(axis=2) <= 0) & (b.max(axis=2) <= 0)
        if args.sky:  # background: Cycles' camera rays that miss return exactly the sky's radiance
            sky = np.array([float(x) for x in args.sky.split(",")])
            empty |= np.all(np.abs(a - sky) < 1e-5, axis=2) & np.all(np.abs(b - sky) < 1e-5, axis=2)
        mask = ~(edge | e2 | empty)
        s = score(ours, a, b, mask)
        s_all = score(ours, a, b, ~(e2 | empty))  # edges kept: how much the edge rule matters
        s["kept_with_edges"], s["rel_rmse_4_with_edges"] = s_all["kept"], s_all["rel_rmse_4"]
        s["view_supersample"], s["rel_rmse_4_ss4"] = ss, score(ours4, a, b, mask)["rel_rmse_4"]
        ref_s = sum(r[1].get("render_time_s", 0.0) for r in refs)
        rows.append(dict(row, mode="view", view=str(v), width=w, height=h, ref_spp=2 * half, ref_s=round(ref_s, 2), **s))
        log("VIEW %d %s: mean ratio %.4f, binned 4x4 %.2f%% (8x8 %.2f%%; irview at 4x: %.2f%%), ref noise %.2f%%; "
            "kept %d/%d px (edges %d, emitters %d, empty %d)" % (
                v, row["our_options"] or "default", s["mean_ratio"], 100 * s["rel_rmse_4"], 100 * s["rel_rmse_8"],
                100 * s["rel_rmse_4_ss4"], 100 * s["ref_noise_4"], s["kept"], w * h, edge.sum(), e2.sum(), empty.sum()))
        if args.save_diff:
            ratio = np.where(mask[..., None], ours / np.maximum(0.5 * (a + b), 1e-6), 0.0)
            oiio.ImageBuf(np.ascontiguousarray(ratio.astype(np.float32))).write(os.path.join(out, "view%d_ratio.exr" % v))


def main():
    ap = argparse.ArgumentParser(description="our bake against Blender Cycles (see the header)")
    ap.add_argument("scene")
    ap.add_argument("--name", required=True)
    ap.add_argument("--opts", action="append", help='irbake bake options, one set per flag ("" = defaults)')
    ap.add_argument("--irbake", default=os.path.join(REPO, "build", "baker", "irbake"))
    ap.add_argument("--irview", default=os.path.join(REPO, "build", "runtime", "irview"))
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--cycles-dir", default=os.path.join(REPO, "..", "shared", "tools", "cycles"))
    ap.add_argument("--work", default=os.path.join(REPO, "build", "cycles-work"))
    ap.add_argument("--cache", default=os.path.join(REPO, "build", "cycles-cache"))
    ap.add_argument("--maps", action="store_true")
    ap.add_argument("--map-spp", type=int, default=1024, help="reference samples per texel (two halves)")
    ap.add_argument("--bake-lights", action="store_true",
                    help="maps: bake through cycles_bake_lights.py, which keeps the punctual lights (a sun-lit level)")
    ap.add_argument("--map-ladder", default="", help="Cycles bakes scored against the reference, e.g. 4,16,64,256")
    ap.add_argument("--views", default="", help="glTF camera indices, e.g. 0,1,2")
    ap.add_argument("--view-size", default="128x128")
    ap.add_argument("--view-spp", type=int, default=2048, help="reference samples per pixel (two halves)")
    ap.add_argument("--view-supersample", type=int, default=16,
                    help="irview renders s x the size, averaged s x s down (textures: Cycles averages pixel areas)")
    ap.add_argument("--max-bounces", type=int, default=64)
    ap.add_argument("--emitter-cut", type=float, default=3.0, help="radiance above which a pixel is an emitter")
    ap.add_argument("--hidden-cut", type=float, default=0.02,
                    help="maps: covered texels darker than this fraction of the mean in Cycles are hidden (left out)")
    ap.add_argument("--sky", default="", help="views (and maps with --bake-lights): Cycles' world = this uniform "
                    "radiance R,G,B (as irbake --sky; put --sky in --opts too); sky pixels are left out as background")
    ap.add_argument("--save-diff", action="store_true", help="write view<i>_ratio.exr (ours/Cycles) beside our bake")
    ap.add_argument("--csv", help="append rows here (default bench/results/cycles_NAME.csv)")
    args = ap.parse_args()
    args.ladder_done = False
    for p, what in ((args.scene, "scene"), (args.irbake, "irbake"), (args.irview, "irview")):
        if not os.path.isfile(p):
            fail("%s not found: %s" % (what, p))
    args.render_script = os.path.join(args.cycles_dir, "cycles_render.py")
    args.bake_script = os.path.join(args.cycles_dir, "cycles_bake.py")
    if args.bake_lights:
        args.bake_script = os.path.join(REPO, "bench", "cycles", "cycles_bake_lights.py")
    if not os.path.isfile(args.render_script):
        fail("Cycles scripts not found in %s (--cycles-dir)" % args.cycles_dir)
    if shutil.which(args.blender) is None:
        fail("blender not found (Debian: apt-get install blender python3-numpy)")
    args.csv = args.csv or os.path.join(REPO, "bench", "results", "cycles_%s.csv" % args.name)
    commit = git_commit(args.irbake)
    rows = []
    for opts in args.opts or [""]:
        out, wall, rep = our_bake(args, opts)
        row = {"date": datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%MZ"), "commit": commit,
               "scene": args.name, "our_options": opts.strip(), "our_wall_s": round(wall, 2),
               "our_bake_s": round(rep.get("timings", rep)["seconds"]["bake"], 2), "texels": rep["texels"]["valid"]}
        log("ours %s: %.2f s wall (bake %.2f s), %d valid texels, pages %s" % (
            opts or "default", wall, rep.get("timings", rep)["seconds"]["bake"], rep["texels"]["valid"], rep["atlas"]["pages"]))
        if args.maps:
            map_mode(args, out, rep, row, rows)
        if args.views:
            view_mode(args, out, row, rows)
    os.makedirs(os.path.dirname(os.path.abspath(args.csv)), exist_ok=True)
    old = list(csv.DictReader(open(args.csv))) if os.path.isfile(args.csv) else []
    tmp = args.csv + ".tmp"
    with open(tmp, "w", newline="") as f:  # rewritten whole: an older file may lack newer columns
        wr = csv.DictWriter(f, fieldnames=CSV_FIELDS, extrasaction="ignore", lineterminator="\n")
        wr.writeheader()
        for r in old:
            wr.writerow(r)
        for r in rows:
            wr.writerow({k: (round(v, 5) if isinstance(v, float) else v) for k, v in r.items()})
    os.replace(tmp, args.csv)
    log("appended %d row(s) to %s" % (len(rows), args.csv))


if __name__ == "__main__":
    main()
