#!/usr/bin/env python3
"""What the relative RMSE of a render against the path tracer is made of (docs/accuracy.md,
"What the per-pixel error is made of").

    breakdown.py IMAGE.pfm REF.pfm TAU.pfm [REF2.pfm] [--json]

IMAGE: the render under test; REF: the path tracer's reference; TAU: the volume's optical depth
per pixel (atmos render --tau); REF2: a second reference rendered with another seed (optional:
the reference's own noise). IMAGE may be f times REF's size per axis (rendered with --width
and --height f times larger): it is box-filtered down, as the path tracer's samples spread
uniformly over each pixel. Over the volume's pixels (τ ≥ 0.01), all channels pooled as in
`atmos compare`, relative to the reference's mean there, it prints:

- the whole: relative RMSE, relative bias, and the RMSE left after the bias is taken out;
- by τ bin (0.01, 0.3, 1, 3, 10, 30): pixels, relative RMSE and bias within the bin, and the
  bin's share of the squared error;
- by spatial frequency: the relative RMSE after both images are blurred by a Gaussian of σ =
  1, 2, 4 px (normalised over the volume's pixels, so the sky does not bleed in), and the
  share of the squared error above each scale (the error minus its own blur);
- silhouette against interior: the pixels within 2 px of a pixel outside the volume, the rest;
- with REF2: the reference's own noise (the two references' mutual RMS / √2) at each blur, the
  RMSE with that noise taken out in quadrature, and the squared error split into the
  reference's noise, the bias, the shading above 4 px, the scales of 1-4 px and below 1 px.
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "shafts"))
from compare import read_pfm  # noqa: E402  (the PFM reader of the light-shaft bench)

TAU_EDGES = [0.01, 0.3, 1, 3, 10, 30, 1e30]
SIGMAS = [1, 2, 4]


def blur_pass(src, w, h, k, r, along_x):
    """One 1-D pass of the kernel k (radius r) over rows (along_x) or columns of src."""
    chans = len(src[0])
    out = [[0.0] * chans for _ in range(w * h)]
    for y in range(h):
        for x in range(w):
            acc = out[y * w + x]
            for i, kv in enumerate(k):
                xx, yy = (x + i - r, y) if along_x else (x, y + i - r)
                if 0 <= xx < w and 0 <= yy < h:
                    s = src[yy * w + xx]
                    for c in range(chans):
                        acc[c] += kv * s[c]
    return out


def blur(img, w, h, n, mask, sigma):
    """Gaussian blur of an n-channel image, normalised over the mask's pixels (outside: 0)."""
    r = int(math.ceil(3 * sigma))
    k = [math.exp(-0.5 * (i / sigma) ** 2) for i in range(-r, r + 1)]
    src = []
    for p in range(w * h):  # the channels and the mask's weight
        m = 1.0 if mask[p] else 0.0
        src.append([img[p * n + c] * m for c in range(n)] + [m])
    acc = blur_pass(blur_pass(src, w, h, k, r, True), w, h, k, r, False)
    out = [0.0] * (w * h * n)
    for p, a in enumerate(acc):
        if a[n] > 0:
            for c in range(n):
                out[p * n + c] = a[c] / a[n]
    return out


def stats(a, r, pixels, n):
    """Sum of squared differences, sum of differences, sum of |reference|, value count."""
    se = sd = sr = 0.0
    cnt = 0
    for p in pixels:
        for c in range(n):
            d = a[p * n + c] - r[p * n + c]
            se += d * d
            sd += d
            sr += abs(r[p * n + c])
            cnt += 1
    return se, sd, sr, cnt


def silhouette(mask, w, h, dist=2):
    edge = [False] * (w * h)
    for y in range(h):
        for x in range(w):
            if not mask[y * w + x]:
                continue
            for dy in range(-dist, dist + 1):
                for dx in range(-dist, dist + 1):
                    xx, yy = x + dx, y + dy
                    if not (0 <= xx < w and 0 <= yy < h) or not mask[yy * w + xx]:
                        edge[y * w + x] = True
    return edge


def breakdown(a, r, tau, w, h, n, tn, r2=None):
    mask = [tau[p * tn] >= TAU_EDGES[0] for p in range(w * h)]
    vol = [p for p in range(w * h) if mask[p]]
    se, sd, sr, cnt = stats(a, r, vol, n)
    mean = sr / cnt
    res = {"pixels": len(vol), "rel_rmse": math.sqrt(se / cnt) / mean, "rel_bias": sd / cnt / mean}
    res["rel_rmse_unbiased"] = math.sqrt(max(0.0, se / cnt - (sd / cnt) ** 2)) / mean
    noise = None
    if r2 is not None:
        nse = stats(r2, r, vol, n)[0]
        noise = math.sqrt(nse / cnt / 2) / mean
        res["ref_noise"] = noise
        res["rel_rmse_noise_free"] = math.sqrt(max(0.0, se / cnt - nse / cnt / 2)) / mean
    bins = []
    for lo, hi in zip(TAU_EDGES[:-1], TAU_EDGES[1:]):
        pix = [p for p in vol if lo <= tau[p * tn] < hi]
        if not pix:
            continue
        bse, bsd, bsr, bc = stats(a, r, pix, n)
        b = {"lo": lo, "pixels": len(pix), "rel_rmse": math.sqrt(bse / bc) / (bsr / bc),
             "rel_bias": bsd / bc / (bsr / bc), "share": bse / se,
             "bias_share": bsd * bsd / bc / se}
        if r2 is not None:
            b["ref_noise"] = math.sqrt(stats(r2, r, pix, n)[0] / bc / 2) / (bsr / bc)
        bins.append(b)
    res["tau_bins"] = bins
    err = [a[i] - r[i] for i in range(w * h * n)]
    scales = []
    for s in SIGMAS:
        ab, rb = blur(a, w, h, n, mask, s), blur(r, w, h, n, mask, s)
        eb = blur(err, w, h, n, mask, s)
        row = {"sigma": s, "rel_rmse": math.sqrt(stats(ab, rb, vol, n)[0] / cnt) / mean,
               "share_above": sum((err[p * n + c] - eb[p * n + c]) ** 2 for p in vol for c in range(n)) / se}
        if r2 is not None:
            r2b = blur(r2, w, h, n, mask, s)
            row["ref_noise"] = math.sqrt(stats(r2b, rb, vol, n)[0] / cnt / 2) / mean
        scales.append(row)
    res["blur"] = scales
    if r2 is not None:
        res["parts"] = parts(res)
    edge = silhouette(mask, w, h)
    for name, pix in (("silhouette", [p for p in vol if edge[p]]), ("interior", [p for p in vol if not edge[p]])):
        pse, psd, psr, pc = stats(a, r, pix, n)
        res[name] = {"pixels": len(pix), "rel_rmse": math.sqrt(pse / pc) / (psr / pc),
                     "rel_bias": psd / pc / (psr / pc), "share": pse / se}
    return res


def parts(res):
    """The squared error split, in shares of it: the reference's noise; the bias; the rest of
    what is left after a blur of 4 px (low-frequency shading); the scales of 1-4 px; those
    below 1 px. Each blurred RMSE has the blurred reference's noise taken out in quadrature."""
    total = res["rel_rmse"] ** 2
    b = {s["sigma"]: max(0.0, s["rel_rmse"] ** 2 - s["ref_noise"] ** 2) for s in res["blur"]}
    clean = res["rel_rmse_noise_free"] ** 2
    return {"noise": res["ref_noise"] ** 2 / total, "bias": res["rel_bias"] ** 2 / total,
            "above_4px": max(0.0, b[4] - res["rel_bias"] ** 2) / total, "px_1_4": max(0.0, b[1] - b[4]) / total,
            "below_1px": max(0.0, clean - b[1]) / total}


def report(res):
    out = ["pixels %d  rel RMSE %.3f  bias %+.1f %%  RMSE without the bias %.3f"
           % (res["pixels"], res["rel_rmse"], 100 * res["rel_bias"], res["rel_rmse_unbiased"])]
    if "ref_noise" in res:
        out.append("reference noise %.3f  RMSE with it taken out %.3f" % (res["ref_noise"], res["rel_rmse_noise_free"]))
    out.append("tau bin   pixels  rel RMSE  bias    share of SE  (of which bias²)" +
               ("  ref noise" if "ref_noise" in res else ""))
    for b in res["tau_bins"]:
        out.append("%-8g  %6d  %8.3f  %+5.1f %%  %6.1f %%     %6.1f %%" %
                   (b["lo"], b["pixels"], b["rel_rmse"], 100 * b["rel_bias"], 100 * b["share"], 100 * b["bias_share"]) +
                   ("         %.3f" % b["ref_noise"] if "ref_noise" in b else ""))
    out.append("blur sigma  rel RMSE  SE share above the scale" + ("  ref noise" if "ref_noise" in res else ""))
    for s in res["blur"]:
        out.append("%4d px     %8.3f  %6.1f %%" % (s["sigma"], s["rel_rmse"], 100 * s["share_above"]) +
                   ("                   %.3f" % s["ref_noise"] if "ref_noise" in s else ""))
    if "parts" in res:
        q = res["parts"]
        out.append("share of SE: ref noise %.0f %%, bias %.0f %%, > 4 px %.0f %%, 1-4 px %.0f %%, < 1 px %.0f %%"
                   % tuple(100 * q[k] for k in ("noise", "bias", "above_4px", "px_1_4", "below_1px")))
    for name in ("silhouette", "interior"):
        e = res[name]
        out.append("%-10s  pixels %5d  rel RMSE %.3f  bias %+.1f %%  share of SE %.1f %%"
                   % (name, e["pixels"], e["rel_rmse"], 100 * e["rel_bias"], 100 * e["share"]))
    return "\n".join(out)


def downsample(img, w, h, n, f):
    """The mean of each f x f block: an image rendered f times larger, box-filtered over each
    pixel of the reference as the path tracer's samples (uniform over the pixel) are."""
    W, H = w // f, h // f
    out = [0.0] * (W * H * n)
    for y in range(h):
        for x in range(w):
            o = ((y // f) * W + x // f) * n
            for c in range(n):
                out[o + c] += img[(y * w + x) * n + c] / (f * f)
    return out


def main():
    args = [x for x in sys.argv[1:] if x != "--json"]
    if len(args) < 3:
        sys.exit(__doc__)
    w, h, n, a = read_pfm(args[0])
    w2, h2, n2, r = read_pfm(args[1])
    if w != w2 and w % w2 == 0 and h == h2 * (w // w2):
        a, w, h = downsample(a, w, h, n, w // w2), w2, h2
    w3, h3, n3, tau = read_pfm(args[2])
    if (w, h, n) != (w2, h2, n2) or (w, h) != (w3, h3):
        sys.exit("breakdown: image, reference and tau sizes differ")
    r2 = read_pfm(args[3])[3] if len(args) > 3 else None
    res = breakdown(a, r, tau, w, h, n, n3, r2)
    print(json.dumps(res, indent=1) if "--json" in sys.argv else report(res))


if __name__ == "__main__":
    main()
