"""PFM images for the tests, read independently of the library (the format: a line "PF" for
three channels or "Pf" for one, a line "W H", a line with the scale, whose sign gives the byte
order, < 0 little endian, then W H C 4-byte floats, rows bottom to top).

The CLI tests import it as `import pfm` (common.inc puts tests/cli on PYTHONPATH):
  img = pfm.read(path)      img.w, img.h, img.c, img.scale, img.v (the floats in file order),
                            img.payload (the bytes after the header; at least W H C 4)
  pfm.pixel(img, x, y)      the c values of pixel (x, y), y counted from the top
  pfm.stats(values)         count, non-finite count, min, max, sum (NaN-free when nonfinite 0)
"""
import math
import struct
from collections import namedtuple

Pfm = namedtuple("Pfm", "kind w h c scale v payload")


def read(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind not in (b"PF", b"Pf"):
            raise ValueError("%s: not a PFM (first line %r)" % (path, kind))
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        payload = f.read()
    c = 3 if kind == b"PF" else 1
    n = w * h * c
    if len(payload) < 4 * n:
        raise ValueError("%s: %d bytes of pixels, %d expected" % (path, len(payload), 4 * n))
    v = struct.unpack(("<" if scale < 0 else ">") + "%df" % n, payload[: 4 * n])
    return Pfm(kind.decode(), w, h, c, scale, v, payload)


def pixel(img, x, y):
    at = ((img.h - 1 - y) * img.w + x) * img.c
    return img.v[at:at + img.c]


Stats = namedtuple("Stats", "count nonfinite min max sum")


def stats(values):
    finite = [x for x in values if math.isfinite(x)]
    return Stats(len(values), len(values) - len(finite), min(finite, default=math.nan),
                 max(finite, default=math.nan), math.fsum(finite))
