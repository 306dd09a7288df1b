#!/usr/bin/env python3
"""The measure of docs/slice.md's "A thin, dense deck": a pattern's share of a flat, bright
region of an image. Over the box X0..X1 x Y0..Y1 (pixels, y from the top; the end excluded):
the mean absolute difference of the luminance (Rec. 709 weights of the linear sRGB) to its
3 x 3 box mean, relative to the mean luminance; and that mean (cd/m^2).

    atmos render --volume salem_wrf_d01_allvars_cropped.nc -o wrf.png --pfm wrf.pfm
    python3 bench/accuracy/deck_pattern.py wrf.pfm                  # the WRF deck's box
    python3 bench/accuracy/deck_pattern.py wrf.pfm --box 680,340,780,375
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("image", help="a PFM (atmos render --pfm)")
    ap.add_argument("--box", default="680,340,780,375",
                    help="X0,Y0,X1,Y1 (default: the WRF deck at 1280 x 720)")
    a = ap.parse_args()
    img = pfm.read(a.image)
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
