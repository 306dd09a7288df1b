#!/usr/bin/env python3
"""The angle between each pixel's ray and the sun, over the volume's pixels, as a PFM for
`atmos compare --by` (docs/lightfield.md, "The Nishita renderer's edge pixels").

    sun_angle.py SCENE.json TAU.pfm OUT.pfm [SUN_AZIMUTH]

SCENE: an accuracy case (its pinhole camera, position_m and look_at_m, vertical fov_deg, and its
sun's elevation_deg; SUN_AZIMUTH, degrees clockwise from north, as run.sh's --sun-azimuth, else
the scene's); TAU: the volume's optical depth per pixel (atmos render --tau), which gives the
image's size. OUT holds the angle in degrees where the optical depth is >= 0.01 and -1 elsewhere,
so that e.g. `--by OUT.pfm --edges 0,3,1e30` splits the volume's pixels within 3 degrees of the
sun (where a reference rendered with `--truncate 3` has none of the forward peak's light) from
the rest. North is -z, east +x, up +y.
"""
import json
import math
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "shafts"))
from compare import read_pfm  # noqa: E402


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    scene = json.load(open(sys.argv[1]))
    w, h, _, tau = read_pfm(sys.argv[2])
    tn = len(tau) // (w * h)
    cam, sun = scene["camera"], scene["sun"]
    el = math.radians(sun["elevation_deg"])
    az = math.radians(float(sys.argv[4]) if len(sys.argv) > 4 else sun["azimuth_deg"])
    s = (math.cos(el) * math.sin(az), math.sin(el), -math.cos(el) * math.cos(az))
    f = unit([b - a for a, b in zip(cam["position_m"], cam["look_at_m"])])
    r = unit([-f[2], 0.0, f[0]])  # f x up
    u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
    t = math.tan(math.radians(cam.get("fov_deg", 60)) / 2)
    out = []
    for p in range(w * h):
        x, y = p % w, p // w
        sx, sy = (2 * (x + 0.5) / w - 1) * t * w / h, (1 - 2 * (y + 0.5) / h) * t
        d = unit([f[i] + sx * r[i] + sy * u[i] for i in range(3)])
        c = max(-1.0, min(1.0, sum(d[i] * s[i] for i in range(3))))
        out.append(math.degrees(math.acos(c)) if tau[p * tn] >= 0.01 else -1.0)
    with open(sys.argv[3], "wb") as fo:  # PFM rows run bottom to top
        fo.write(b"Pf\n%d %d\n-1.0\n" % (w, h))
        for y in range(h - 1, -1, -1):
            fo.write(struct.pack("<%df" % w, *out[y * w:(y + 1) * w]))


if __name__ == "__main__":
    main()
