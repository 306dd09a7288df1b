#!/usr/bin/env python3
"""Writes scenes/dobashi_fig09b_window.png: the stained-glass window of
scenes/dobashi_fig09b_stained_glass.json (a lancet of coloured panes between dark lead
lines, a rose at its top), 64 x 64 sRGB texels spanning the spot's cone. Only the standard
library: PNG rows deflated by zlib."""
import math
import os
import struct
import zlib

N = 64
PANES = [(0.85, 0.10, 0.08), (0.10, 0.25, 0.85), (0.95, 0.75, 0.15), (0.15, 0.65, 0.25), (0.60, 0.15, 0.70)]


def texel(x, y):
    """sRGB colour at (x, y) in [-1, 1]^2, y up; black where the window is opaque."""
    half_w, bottom, spring = 0.42, -0.92, 0.35  # the lancet: straight sides up to spring, then a pointed arch
    if abs(x) > half_w or y < bottom:
        return (0, 0, 0)
    if y > spring:  # two arcs of radius 2 half_w centred on the opposite side
        r = 2 * half_w
        if math.hypot(abs(x) + half_w, y - spring) > r:
            return (0, 0, 0)
    rose = math.hypot(x, y - 0.62)
    if rose < 0.22:  # the rose: six petals round a gold centre
        if rose < 0.07:
            return PANES[2]
        if abs(rose - 0.07) < 0.02:
            return (0, 0, 0)
        petal = int(((math.atan2(y - 0.62, x) + math.pi) / (2 * math.pi)) * 6) % 6
        return PANES[(petal % 2) * 4]
    if abs(rose - 0.22) < 0.025:
        return (0, 0, 0)
    # the panes: a grid of leaded diamonds below the rose
    u, v = (x + y) / 0.21, (x - y) / 0.21
    fu, fv = u - math.floor(u), v - math.floor(v)
    if min(fu, 1 - fu, fv, 1 - fv) < 0.08:
        return (0, 0, 0)
    return PANES[(int(math.floor(u)) * 3 + int(math.floor(v)) * 2) % len(PANES)]


def main():
    rows = b""
    for j in range(N):
        rows += b"\x00"
        for i in range(N):
            c = texel((i + 0.5) / N * 2 - 1, 1 - (j + 0.5) / N * 2)
            rows += bytes(int(round(255 * v)) for v in c)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", N, N, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b"")
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "dobashi_fig09b_window.png")
    with open(out, "wb") as f:
        f.write(png)


if __name__ == "__main__":
    main()
