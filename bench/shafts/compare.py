#!/usr/bin/env python3
"""The air pixels of a slice render against the path tracer's (docs/slice.md, "Light shafts").

    compare.py SLICE.pfm SLICE_OFF.pfm PATH.pfm TAU.pfm [ROWS]

SLICE.pfm and SLICE_OFF.pfm: the slice renderer with and without "air_shadows"; PATH.pfm:
the path tracer; TAU.pfm: the volume's optical depth per pixel (atmos render --tau). The air
pixels are those the volume does not cover (tau < 1e-3), in the image's first ROWS rows
(default all: give the rows above the horizon to leave out the ground, which the slice
renderer does not shadow); the shadowed ones are those where the shadow takes more than 1 %
of the unshadowed light. Prints, for both slice renders, the mean relative difference to
the path tracer over the shadowed air pixels and over all air pixels, per channel averaged:
signed (the bias) and absolute (which includes the path tracer's noise)."""
import struct
import sys


def read_pfm(path, top_down=True):
    """(w, h, channels, values): rows top to bottom, or in the file's own order (bottom to top)
    with top_down False."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        n = 3 if kind == b"PF" else 1
        data = f.read()
    end = "<" if scale < 0 else ">"
    vals = struct.unpack(end + "%df" % (w * h * n), data[: 4 * w * h * n])
    if not top_down:
        return w, h, n, list(vals)
    # PFM rows run bottom to top: turn them top to bottom
    rows = [vals[(h - 1 - y) * w * n:(h - y) * w * n] for y in range(h)]
    return w, h, n, [v for r in rows for v in r]


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    rows = int(sys.argv[5]) if len(sys.argv) > 5 else None
    w, h, n, on = read_pfm(sys.argv[1])
    _, _, _, off = read_pfm(sys.argv[2])
    _, _, _, ref = read_pfm(sys.argv[3])
    _, _, _, tau = read_pfm(sys.argv[4])
    tn = len(tau) // (w * h)
    air, shad = [], []
    for p in range(w * h):
        if rows is not None and p // w >= rows:
            continue
        if tau[p * tn] >= 1e-3:
            continue
        air.append(p)
        lum_off = sum(off[p * 3:p * 3 + 3])
        if lum_off > 0 and (lum_off - sum(on[p * 3:p * 3 + 3])) > 0.01 * lum_off:
            shad.append(p)

    def stats(img, pix):
        bias = absd = 0.0
        for p in pix:
            for c in range(3):
                r = ref[p * 3 + c]
                d = (img[p * 3 + c] - r) / r if r > 0 else 0.0
                bias += d / 3
                absd += abs(d) / 3
        m = max(1, len(pix))
        return 100 * bias / m, 100 * absd / m

    print("air pixels %d, shadowed (the shadow takes > 1 %%) %d" % (len(air), len(shad)))
    for name, img in (("slice, air_shadows on ", on), ("slice, air_shadows off", off)):
        b1, a1 = stats(img, shad)
        b2, a2 = stats(img, air)
        print("%s: shadowed air: mean relative difference %+.2f %%, mean |relative difference| %.2f %%;"
              " all air: %+.2f %%, %.2f %%" % (name, b1, a1, b2, a2))


if __name__ == "__main__":
    main()
