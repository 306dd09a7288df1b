#!/usr/bin/env python3
"""The sun's cone of an accuracy case (docs/accuracy.md, "The cirrus in front: the sun's cone").

    sun_cone.py [--angle ANGLE.pfm] SCENE.json REF.pfm TRUNCATE_DEG CONE_KEY.pfm [KEY.pfm MASKED.pfm]...

A reference truncated at θc (`atmos render --renderer path --truncate θc`) counts the scattering
of the forward peak within θc as unscattered: around the sun's disk seen through the volume it
has no aureole (flat at P(θc)) and the peak's light is in the disk's pixels instead. So its
pixels within θc + the disk's radius + half a pixel's diagonal of the sun's centre are not a
reference for anything: this script finds them and takes them out of the statistics.

The sun's centre is the centroid of REF's pixels brighter than a thousandth of its brightest,
when that pixel is brighter than 1000 times the image's median (the direct sun seen, through
thin cloud or none; otherwise there is no cone and every key is copied unchanged). The angle
between two pixels is the pinhole camera's (the scene's vertical `fov_deg`, default 60).

CONE_KEY.pfm: 0 on the disk's own pixels (within the disk's radius + half a diagonal), 1 on the
rest of the cone (the aureole the reference flattened), -1 elsewhere: `atmos compare --by
CONE_KEY.pfm --edges 0,0.5,1.5` gives the two separately. Each KEY.pfm (e.g. the --tau and
--order images) is written to MASKED.pfm with the cone's pixels set to -1, outside every bin
from 0 up. ANGLE.pfm: each pixel's angle from the sun's centre, degrees (-1 everywhere when the
disk is not seen), a key for `atmos compare --by ANGLE.pfm --edges 0,1,2,3,...`: the error by
ring. Prints the sun's pixel and the cone's pixel counts; exit status 0 either way.
"""
import json
import math
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "shafts"))
import compare as shafts_compare  # noqa: E402  (the PFM reader of the light-shaft bench)

SUN_RADIUS_DEG = 0.2665  # the sun's angular radius (atmos's disk)


def read_pfm(path):
    """(w, h, channels, values) in the file's own row order (the keys are written back in it)."""
    return shafts_compare.read_pfm(path, top_down=False)


def write_pfm(path, w, h, n, vals):
    with open(path, "wb") as f:
        f.write(b"PF\n" if n == 3 else b"Pf\n")
        f.write(b"%d %d\n-1.0\n" % (w, h))
        f.write(struct.pack("<%df" % len(vals), *vals))


def sun_pixel(w, h, n, ref):
    """The disk's centroid (x, y in the file's rows), or None when the direct sun is not seen."""
    lum = [sum(ref[p * n:p * n + n]) / n for p in range(w * h)]
    top = max(lum)
    if not (top > 1000 * sorted(lum)[len(lum) // 2]):
        return None
    sw = sx = sy = 0.0
    for p, v in enumerate(lum):
        if v > 1e-3 * top:
            sw += v
            sx += v * (p % w + 0.5)
            sy += v * (p // w + 0.5)
    return sx / sw, sy / sw


def main():
    args = sys.argv[1:]
    angle_path = None
    if args[:1] == ["--angle"] and len(args) > 1:
        angle_path, args = args[1], args[2:]
    if len(args) < 4 or len(args) % 2:
        sys.exit(__doc__)
    scene, ref_path, trunc, cone_path = args[0], args[1], float(args[2]), args[3]
    pairs = list(zip(args[4::2], args[5::2]))
    fov = json.load(open(scene)).get("camera", {}).get("fov_deg", 60)
    w, h, n, ref = read_pfm(ref_path)
    sun = sun_pixel(w, h, n, ref)
    f = (h / 2) / math.tan(math.radians(fov) / 2)  # the focal length in pixels
    disk = SUN_RADIUS_DEG + math.degrees(math.atan(math.sqrt(0.5) / f))
    cone = [-1.0] * (w * h)
    angle = [-1.0] * (w * h)
    if sun:
        s = (sun[0] - w / 2, sun[1] - h / 2, f)
        ns = math.sqrt(sum(c * c for c in s))
        for p in range(w * h):
            d = (p % w + 0.5 - w / 2, p // w + 0.5 - h / 2, f)
            cos = sum(a * b for a, b in zip(d, s)) / (ns * math.sqrt(sum(c * c for c in d)))
            a = angle[p] = math.degrees(math.acos(max(-1.0, min(1.0, cos))))
            if a <= disk:
                cone[p] = 0.0
            elif a <= disk + trunc:
                cone[p] = 1.0
    write_pfm(cone_path, w, h, 1, cone)
    if angle_path:
        write_pfm(angle_path, w, h, 1, angle)
    for key_path, out_path in pairs:
        kw, kh, kn, key = read_pfm(key_path)
        if (kw, kh) != (w, h):
            sys.exit("sun_cone.py: %s is %dx%d, the reference %dx%d" % (key_path, kw, kh, w, h))
        for p in range(w * h):
            if cone[p] >= 0:
                key[p * kn:p * kn + kn] = [-1.0] * kn
        write_pfm(out_path, w, h, kn, key)
    if sun:
        print("sun at pixel %.2f %.2f (from the top): the disk %d pixels (%.2f deg), the rest of the cone %d "
              "(%.2f deg)" % (sun[0], h - sun[1], cone.count(0.0), disk, cone.count(1.0), disk + trunc))
    else:
        print("the sun's disk is not seen: no cone")


if __name__ == "__main__":
    main()
