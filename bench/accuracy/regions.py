#!/usr/bin/env python3
"""Where the squared error of a render against the path tracer lies, by image region, with the
reference's own noise taken out per region (docs/accuracy.md, "The cumulus in front: where the
RMSE is").

    regions.py IMAGE.pfm REF.pfm TAU.pfm REF2.pfm [--ratio K] [--order ORDER.pfm]
               [--toward X,Y] [--signature A.pfm B.pfm]

IMAGE: the render under test; REF: the path tracer's reference; TAU: the optical depth per pixel
(atmos render --tau); REF2: a second reference of another seed with K times fewer samples per
pixel than REF (--ratio, default 1): REF's noise variance per pixel is taken as
(REF2 - REF)^2 / (1 + K). Over the volume's pixels (tau >= 0.01), all channels pooled, it prints
per region: pixels, the region's share of the squared error (SE) and of the SE with the noise
taken out, its relative bias and the points of the whole bias it makes, its noise-free relative
RMSE, and the share of the whole noise-free SE that its bias alone explains. Regions: the
distance to the nearest pixel outside the volume (1, 2, 3, 4-5, >= 6 px); with --toward, the
rim facing the image point X,Y (e.g. the sun's; the volume ends within 3 px toward it) and the
rest; the tau bins, each split at the silhouette (distance <= 2); with --order, the path
tracer's mean scattering order (atmos render --order).

--signature A B: how much of the error's pattern is that of the difference A - B (two renders
that differ in one setting): the correlation of the two over the volume's pixels, both
averaged over 3 x 3 pixels (the reference's noise mostly averaged out), the least-squares
factor k of error ~ k (A - B) and the share of the averaged error's energy it explains.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from breakdown import TAU_EDGES, read_pfm  # noqa: E402  (the same PFM reader and tau bins)

ORDER_EDGES = [0, 1.5, 3, 6, 12, 25, 1e30]


def sky_distance(mask, w, h, far=6):
    """Per volume pixel: the Chebyshev distance to the nearest pixel outside the volume (or
    the image), capped at far."""
    dist = {}
    for p in range(w * h):
        if not mask[p]:
            continue
        x, y, d = p % w, p // w, far
        for r in range(1, far):
            ring = [(x + dx, y + dy) for dy in range(-r, r + 1) for dx in range(-r, r + 1)
                    if max(abs(dx), abs(dy)) == r]
            if any(not (0 <= xx < w and 0 <= yy < h) or not mask[yy * w + xx] for xx, yy in ring):
                d = r
                break
        dist[p] = d
    return dist


def facing(mask, w, h, p, to, reach=3):
    """Whether the volume ends within reach pixels from p toward the image point to."""
    x, y = p % w, p // w
    dx, dy = to[0] - x, to[1] - y
    ln = math.hypot(dx, dy) or 1.0
    for s in range(1, reach + 1):
        xx, yy = int(round(x + dx / ln * s)), int(round(y + dy / ln * s))
        if not (0 <= xx < w and 0 <= yy < h) or not mask[yy * w + xx]:
            return True
    return False


def luma(img, n, p):
    return sum(img[p * n + c] for c in range(n)) / n


def signature(a, r, s1, s2, vol, w, n):
    """Correlation of the 3 x 3-averaged error a - r with the averaged s1 - s2, the factor k
    and the share of the averaged error's energy that k (s1 - s2) explains."""
    vs = set(vol)

    def avg(f):
        out = {}
        for p in vol:
            q = [p + dy * w + dx for dy in (-1, 0, 1) for dx in (-1, 0, 1) if p + dy * w + dx in vs]
            out[p] = sum(f(i) for i in q) / len(q)
        return out
    e = avg(lambda p: luma(a, n, p) - luma(r, n, p))
    d = avg(lambda p: luma(s1, n, p) - luma(s2, n, p))
    me, md = sum(e.values()) / len(e), sum(d.values()) / len(d)
    cov = sum((e[p] - me) * (d[p] - md) for p in vol)
    corr = cov / math.sqrt(sum((e[p] - me) ** 2 for p in vol) * sum((d[p] - md) ** 2 for p in vol))
    k = sum(e[p] * d[p] for p in vol) / sum(d[p] ** 2 for p in vol)
    left = sum((e[p] - k * d[p]) ** 2 for p in vol) / sum(e[p] ** 2 for p in vol)
    return corr, k, 1 - left


def main():
    args, opts, i = [], {}, 1
    while i < len(sys.argv):
        a = sys.argv[i]
        if a in ("--ratio", "--order", "--toward"):
            opts[a], i = sys.argv[i + 1], i + 2
        elif a == "--signature":
            opts[a], i = sys.argv[i + 1:i + 3], i + 3
        else:
            args.append(a)
            i += 1
    if len(args) != 4:
        sys.exit(__doc__)
    w, h, n, a = read_pfm(args[0])
    r, r2 = read_pfm(args[1])[3], read_pfm(args[3])[3]
    tn, tau = read_pfm(args[2])[2:]
    K = float(opts.get("--ratio", 1))
    mask = [tau[p * tn] >= TAU_EDGES[0] for p in range(w * h)]
    vol = [p for p in range(w * h) if mask[p]]
    cnt = len(vol) * n
    mean = sum(r[p * n + c] for p in vol for c in range(n)) / cnt

    def st(pix):
        se = sum((a[p * n + c] - r[p * n + c]) ** 2 for p in pix for c in range(n))
        ns = sum((r2[p * n + c] - r[p * n + c]) ** 2 for p in pix for c in range(n)) / (1 + K)
        sd = sum(a[p * n + c] - r[p * n + c] for p in pix for c in range(n))
        sr = sum(r[p * n + c] for p in pix for c in range(n))
        return se, ns, sd, sr
    se, ns, sd, _ = st(vol)
    print("pixels %d  rel RMSE %.3f  the reference's noise %.3f  RMSE without it %.3f  bias %+.1f %%"
          % (len(vol), math.sqrt(se / cnt) / mean, math.sqrt(ns / cnt) / mean,
             math.sqrt(max(0.0, se - ns) / cnt) / mean, 100 * sd / cnt / mean))
    print("%-22s %6s %8s %10s %8s %9s %8s %9s" % ("region", "pixels", "SE", "SE-noise", "bias", "bias pt",
                                                 "RMSE-nf", "bias² of"))

    def row(name, pix):
        if not pix:
            return
        rse, rns, rsd, rsr = st(pix)
        m = len(pix) * n
        print("%-22s %6d %7.1f%% %9.1f%% %+7.1f%% %+9.2f %8.3f %8.1f%%"
              % (name, len(pix), 100 * rse / se, 100 * (rse - rns) / (se - ns), 100 * rsd / rsr, 100 * rsd / cnt / mean,
                 math.sqrt(max(0.0, rse - rns) / m) / (rsr / m), 100 * rsd * rsd / m / (se - ns)))
    dist = sky_distance(mask, w, h)
    for lo, hi, name in ((1, 1, "1 px from the sky"), (2, 2, "2 px"), (3, 3, "3 px"), (4, 5, "4-5 px"),
                         (6, 6, ">= 6 px")):
        row(name, [p for p in vol if lo <= dist[p] <= hi])
    if "--toward" in opts:
        to = [float(v) for v in opts["--toward"].split(",")]
        rim = {p for p in vol if facing(mask, w, h, p, to)}
        row("rim toward X,Y", sorted(rim))
        row("the rest", [p for p in vol if p not in rim])
    for lo, hi in zip(TAU_EDGES[:-1], TAU_EDGES[1:]):
        row("tau %g, silhouette" % lo, [p for p in vol if lo <= tau[p * tn] < hi and dist[p] <= 2])
        row("tau %g, inside" % lo, [p for p in vol if lo <= tau[p * tn] < hi and dist[p] > 2])
    if "--order" in opts:
        on, o = read_pfm(opts["--order"])[2:]
        for lo, hi in zip(ORDER_EDGES[:-1], ORDER_EDGES[1:]):
            row("order %g-%g" % (lo, hi), [p for p in vol if lo <= o[p * on] < hi])
    if "--signature" in opts:
        s1, s2 = (read_pfm(f)[3] for f in opts["--signature"])
        corr, k, share = signature(a, r, s1, s2, vol, w, n)
        print("signature: correlation %.3f (3 x 3 averages), error ~ %.3f (A - B) explains %.0f %% of its energy"
              % (corr, k, 100 * share))


if __name__ == "__main__":
    main()
