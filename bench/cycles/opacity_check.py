# The transmittance check of bench/cycles/run.sh, in Blender's Python (which reads OpenEXR):
#
#   blender -b --factory-startup -noaudio -P opacity_check.py -- ATMOS.exr CYCLES.exr TAU.pfm
#
# Both images show a pure absorber in front of a background of radiance 1, so each pixel is
# the background times the transmittance T. Over the pixels with optical depth >= 0.01 (TAU,
# from atmos render --tau) it prints, on a line "opacity-check: ...", comma-separated: the
# pixel count, atmos's mean opacity 1 - T, the RMS and the mean of the difference of the
# opacities (Cycles - atmos) relative to that mean, and the shift (in pixels, x right, y down)
# that best explains the difference: the least-squares fit of the difference by the image
# gradient, c(x) ~ a(x - s).
import sys

import bpy
import numpy as np


def exr(path):
    im = bpy.data.images.load(path)
    w, h = im.size
    a = np.array(im.pixels[:], dtype=np.float64).reshape(h, w, im.channels)[::-1, :, :3]
    return a


def pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        d = np.fromfile(f, dtype="<f4" if scale < 0 else ">f4")
    return d.reshape(h, w, 3 if kind == b"PF" else 1)[::-1, :, 0]


args = sys.argv[sys.argv.index("--") + 1:]
a, c, tau = exr(args[0]), exr(args[1]), pfm(args[2])
bg = a[0, 0]  # the corner sees the background (checked below)
Ta, Tc = (a / bg)[..., 1], (c / bg)[..., 1]
m = tau >= 0.01
if m[0, 0] or not m.any():
    sys.exit("opacity_check.py: the image corner must see the background, and some pixels the volume")
oa, oc = 1 - Ta[m], 1 - Tc[m]
mean = oa.mean()
d = oc - oa
gy, gx = np.gradient(Ta)
s, *_ = np.linalg.lstsq(np.stack([gx[m], gy[m]], 1), (Tc - Ta)[m], rcond=None)
print("opacity-check: %d,%.5f,%.5f,%.5f,%.3f,%.3f" % (m.sum(), mean, np.sqrt((d ** 2).mean()) / mean,
      d.mean() / mean, -s[0], -s[1]), flush=True)
