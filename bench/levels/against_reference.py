#!/usr/bin/python3
"""A bake against our reference backend on the same atlas, in 4×4 (and 8×8) texel bins, page 0.

usage: /usr/bin/python3 bench/levels/against_reference.py OURS_DIR REF_A_DIR REF_B_DIR
REF_A and REF_B: two `--backend reference` bakes with different --seed (their half-difference is the
reference's own noise, removed from the error as in bench/cycles/compare.py). Texels compared: those
non-zero in both references (the dilation ring included: there both bakes copy their neighbours).
Prints the mean ratio, the relative RMSE over bins, the reference's noise and the error with it removed.
"""
import os
import sys

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cycles"))
from compare import bin_means as bins  # noqa: E402  (the same 4×4 / 8×8 binning as the Cycles comparison)


def page(d):
    buf = oiio.ImageBuf(d.rstrip("/") + "/lightmap_0.exr")
    if buf.has_error:
        sys.exit("against_reference.py: %s: %s" % (d, buf.geterror()))
    return buf.get_pixels(oiio.FLOAT)[..., :3].astype(np.float64)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    ours, a, b = (page(d) for d in sys.argv[1:])
    if not (ours.shape == a.shape == b.shape):
        sys.exit("against_reference.py: the pages differ in size (not the same atlas)")
    mask = (a.max(axis=2) > 0) & (b.max(axis=2) > 0)
    ref = 0.5 * (a + b)
    print("texels %d, mean ratio %.4f" % (mask.sum(), ours[mask].sum() / ref[mask].sum()))
    for s in (4, 8):
        o, r, ra, rb = (bins(x, mask, s) for x in (ours, ref, a, b))
        rms = np.sqrt(np.mean(r ** 2))
        err = np.sqrt(np.mean((o - r) ** 2)) / rms
        noise = 0.5 * np.sqrt(np.mean((ra - rb) ** 2)) / rms
        print("%dx%d bins: relative RMSE %.2f%%, reference noise %.2f%%, noise removed %.2f%%" % (
            s, s, 100 * err, 100 * noise, 100 * np.sqrt(max(0.0, err ** 2 - noise ** 2))))


if __name__ == "__main__":
    main()
