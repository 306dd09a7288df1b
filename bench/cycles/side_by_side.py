# One PNG with two or more linear EXR images side by side, at one common exposure (the
# first image's 99th percentile of luminance maps to 0.9 before a x/(1+x) curve), sRGB
# encoded. Runs in Blender's Python (which reads OpenEXR):
#
#   blender -b --factory-startup -noaudio -P side_by_side.py -- OUT.png A.exr B.exr ...
import sys

import bpy
import numpy as np

args = sys.argv[sys.argv.index("--") + 1:]
out, files = args[0], args[1:]
imgs = []
for f in files:
    im = bpy.data.images.load(f)
    w, h = im.size
    a = np.array(im.pixels[:], dtype=np.float32).reshape(h, w, im.channels)[:, :, :3]
    imgs.append(np.nan_to_num(a))
Y = imgs[0] @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
k = 0.9 / max(float(np.percentile(Y[Y > 0], 99)) if (Y > 0).any() else 1.0, 1e-30)
gap = np.ones((imgs[0].shape[0], 2, 3), dtype=np.float32)
row = []
for i, a in enumerate(imgs):
    x = a * k
    x = x / (1.0 + x)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(np.maximum(x, 0), 1 / 2.4) - 0.055)
    row += ([gap] if i else []) + [np.clip(x, 0, 1)]
rgb = np.concatenate(row, axis=1)
h, w, _ = rgb.shape
o = bpy.data.images.new("out", w, h, alpha=True, float_buffer=False)
o.pixels[:] = np.concatenate([rgb, np.ones((h, w, 1), dtype=np.float32)], axis=2).ravel().tolist()
o.filepath_raw = out
o.file_format = "PNG"
o.save()
