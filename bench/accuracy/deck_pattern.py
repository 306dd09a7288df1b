#!/usr/bin/env python3
"""The measure of docs/slice.md's "A thin, dense deck": a pattern's share of a flat, bright
region of an image. Over the box X0..X1 x Y0..Y1 (pixels, y from the top; the end excluded):
the mean absolute difference of the luminance (Rec. 709 weights of the linear sRGB) to its
3 x 3 box mean, relative to the mean luminance; and that mean (cd/m^2).

    atmos render --volume salem_wrf_d01_allvars_cropped.nc -o wrf.png --pfm wrf.pfm
    python3 bench/accuracy/deck_pattern.py wrf.pfm                  # the WRF deck's box
    python3 bench/accuracy/deck_pattern.py wrf.pfm --box 680,340,780,375

With --blocks CxR it prints instead the mean luminance of C x R blocks tiling the image (its
width and height divided evenly, the remainder left out), a row of blocks a line with its
largest mean over its least: how even a flat deck is at the scale of the light field's cells.
"""
import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "cli"))
import pfm  # noqa: E402  (tests/cli/pfm.py)


def luminance(img, x, y):
    p = pfm.pixel(img, x, y)
    return p[0] if img.c == 1 else 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]


def blocks(img, spec):
    try:
        c, r = (int(v) for v in spec.lower().split("x"))
    except ValueError:
        sys.exit("--blocks %s: expected CxR, e.g. 6x3" % spec)
    if not (1 <= c <= img.w and 1 <= r <= img.h):
        sys.exit("--blocks %s: not within the %dx%d image" % (spec, img.w, img.h))
    bw, bh = img.w // c, img.h // r
    for by in range(r):
        means = []
        for bx in range(c):
            s = sum(luminance(img, x, y) for y in range(by * bh, (by + 1) * bh)
                    for x in range(bx * bw, (bx + 1) * bw))
            means.append(s / (bw * bh))
        ratio = max(means) / min(means) if min(means) > 0 else float("inf")
        print(" ".join("%7.0f" % m for m in means) + "   max/min %.2f" % ratio)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("image", help="a PFM (atmos render --pfm)")
    ap.add_argument("--box", default="680,340,780,375",
                    help="X0,Y0,X1,Y1 (default: the WRF deck at 1280 x 720)")
    ap.add_argument("--blocks", help="CxR: the means of C x R blocks instead")
    a = ap.parse_args()
    img = pfm.read(a.image)
    if a.blocks:
        blocks(img, a.blocks)
        return
    x0, y0, x1, y1 = (int(v) for v in a.box.split(","))
    if not (1 <= x0 < x1 <= img.w - 1 and 1 <= y0 < y1 <= img.h - 1):
        sys.exit("%s: the box %s is not inside the %dx%d image's inner pixels"
                 % (a.image, a.box, img.w, img.h))
    L = {(x, y): luminance(img, x, y) for y in range(y0 - 1, y1 + 1) for x in range(x0 - 1, x1 + 1)}
    dev = total = 0.0
    for y in range(y0, y1):
        for x in range(x0, x1):
            box = sum(L[x + i, y + j] for j in (-1, 0, 1) for i in (-1, 0, 1)) / 9.0
            dev += abs(L[x, y] - box)
            total += L[x, y]
    n = (x1 - x0) * (y1 - y0)
    print("pattern %.2f %%  mean %.0f" % (100.0 * dev / total, total / n))


if __name__ == "__main__":
    main()
