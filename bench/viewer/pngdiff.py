#!/usr/bin/env python3
"""The 8-bit display values of two recorded flights (atmos view --record DIR), frame by frame:
the frames whose pixels are identical, the largest difference in levels of 255, the share of
values that differ, the mean difference (levels, over every colour value of every frame), the
largest frame's mean and the differences 99 % and 99.9 % of the values do not exceed. Two PNG
files instead of two folders compare those two images. Metadata (the PNGs' text chunks) and
alpha are ignored.

    bench/viewer/pngdiff.py DIR_A DIR_B
    bench/viewer/pngdiff.py A.png B.png
"""
import glob, os, struct, sys, zlib

try:
    import numpy as np
except ImportError:
    np = None


def pixels(path):
    data = open(path, "rb").read()
    i, idat = 8, b""
    while i < len(data):
        n, = struct.unpack(">I", data[i:i + 4])
        kind = data[i + 4:i + 8]
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", data[i + 8:i + 18])
        elif kind == b"IDAT":
            idat += data[i + 8:i + 8 + n]
        i += 12 + n
    bpp = {2: 3, 6: 4}[ctype] * depth // 8
    raw, stride = zlib.decompress(idat), w * bpp
    out, prev, o = bytearray(), bytearray(stride), 0
    for _ in range(h):
        f, line = raw[o], bytearray(raw[o + 1:o + 1 + stride])
        o += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out += line
        prev = line
    if bpp == 4 * depth // 8:  # RGBA: the colour values only
        del out[3::4]
    return out


same = worst = differ = total = dsum = 0
frame_mean = 0.0
hist = [0] * 256
if os.path.isdir(sys.argv[1]):
    pairs = [(fa, os.path.join(sys.argv[2], os.path.basename(fa)))
             for fa in sorted(glob.glob(os.path.join(sys.argv[1], "frame_*.png")))]
else:
    pairs = [(sys.argv[1], sys.argv[2])]
for fa, fb in pairs:
    a, b = pixels(fa), pixels(fb)
    if len(a) != len(b):
        sys.exit("pngdiff: %s and %s differ in size" % (fa, fb))
    if np:  # the same counts, faster
        d = np.abs(np.frombuffer(bytes(a), np.uint8).astype(np.int16) - np.frombuffer(bytes(b), np.uint8))
        h = np.bincount(d, minlength=256)
        m, fs = int(d.max()), int(d.sum())
        hist = [x + int(y) for x, y in zip(hist, h)]
        hist[0] = 0
    else:
        d = [abs(x - y) for x, y in zip(a, b)]
        m, fs = max(d), sum(d)
        for v in range(1, m + 1):
            hist[v] += d.count(v)
    dsum += fs
    frame_mean = max(frame_mean, fs / max(1, len(d)))
    same += m == 0
    worst = max(worst, m)
    total += len(d)
differ = sum(hist)


def pct(q):  # the difference that q of the values do not exceed
    left = (1 - q) * total
    for v in range(255, -1, -1):
        left -= hist[v]
        if left < 0:
            return v
    return 0


print("frames=%d identical=%d largest_difference=%d differing_values=%.2g mean_difference=%.3f "
      "largest_frame_mean=%.3f p99=%d p99.9=%d" % (len(pairs), same, worst, differ / max(1, total),
                                                   dsum / max(1, total), frame_mean, pct(0.99), pct(0.999)))
