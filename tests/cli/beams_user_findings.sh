#!/bin/sh
# A new user's findings in the beam renderer mended (docs/beams.md):
#  - a hemispherical spot (cone_deg + edge_deg = 90, a ceiling lamp) lights the fog smoothly
#    above and below the light's plane: no pixel of the fog it lights is black, and the beam
#    renderer's image agrees with the path tracer's single scattering (--max-depth 1);
#  - one far vertex stretching the sun's shadow map is warned of, naming the object and the
#    texel size; the same scene without it is not;
#  - an image whose estimated memory exceeds the machine's is refused at once with the estimate
#    and the options that lower it (16384 x 16384 of 128 wavelengths: ~440 GB); a small one is not
#    warned of;
#  - a point light without range_m reaches where its airlight falls to 1e-3 of its value 1 m from
#    it: no glowing ball with a hard edge, the image within 5 % of the path tracer's single
#    scattering (the former default, 100 m, gave 0.45 of it, 0.1 at the image's edges);
#  - the example scene of docs/scene-format.md's `beams` section (its camera was missing, so
#    it rendered black) shows the beam: light in the image's top third (the cone below the lamp)
#    and in its bottom third (the lit floor), over 5 % of the pixels in all (about 11 %).
#  - a spot of cone_deg 0 and edge_deg 0 (a valid value: its image is black) is warned of;
#  - a light's image of more than 4096 x 4096 texels (a small file that inflates to gigabytes)
#    is refused from its header, naming its size, before it is decoded.
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1
cat >hemi.json <<'JSON'
{"image": {"width": 40, "height": 30}, "camera": {"type": "pinhole", "position_m": [8, 2, 8], "look_at_m": [0, 3, 0], "fov_deg": 60},
 "wavelengths": {"mode": "rgb"}, "background": "black", "renderer": "beams",
 "fog": {"extinction_per_m": 0.04, "scattering_per_m": 0.036, "g": 0.5},
 "lights": [{"type": "spot", "position_m": [0, 12, 0], "direction": [0, -1, 0], "cone_deg": 85, "edge_deg": 5,
             "intensity_w_sr": 20000, "range_m": 50}],
 "objects": [{"mesh": "builtin:plane", "position_m": [0, 0, 0], "scale": 15, "albedo": 0.6}]}
JSON
"$A" render hemi.json -o b.pfm -q 2>e1 || bad "beams, cone 85 + edge 5: $(cat e1)"
"$A" render hemi.json --renderer path --max-depth 1 --spp 64 --seed 3 -o p.pfm -q 2>e2 || bad "path: $(cat e2)"
python3 - b.pfm p.pfm <<'PY' && ok "cone 85 + edge 5: no black pixel, beams within 10 % of the path tracer" || bad "cone 85 + edge 5"
import sys, pfm
b, p = pfm.read(sys.argv[1]), pfm.read(sys.argv[2])
zeros = sum(1 for v in b.v[1::3] if v <= 0)
sb, sp = sum(b.v[1::3]), sum(p.v[1::3])
print("beams black pixels %d, beams / path (green mean) %.4f" % (zeros, sb / sp))
sys.exit(0 if zeros == 0 and abs(sb / sp - 1) < 0.10 else 1)
PY
# the sun's map: a terrain and a box; the box with one far triangle (x = 1e7 m)
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n' >near.obj
cp near.obj far.obj
printf 'v 1e7 0 0\nv 1e7 1 0\nv 1e7 0 1\nf -3 -2 -1\n' >>far.obj
sun_scene() {
    cat <<JSON
{"image": {"width": 24, "height": 16}, "camera": {"type": "pinhole", "position_m": [0, 1500, 2500], "look_at_m": [0, 600, 0], "fov_deg": 55},
 "sun": {"elevation_deg": 12, "azimuth_deg": 250}, "renderer": "beams", "beams": {"sun": true, "shadow_size": 512},
 "fog": {"visibility_m": 6000, "height_m": 800},
 "objects": [{"terrain": "generate:ridges", "size_m": 6000, "height_m": 1200, "samples": 65}, {"mesh": "$1", "position_m": [0, 900, 0], "scale": 6}]}
JSON
}
sun_scene far.obj | "$A" render - -o x.png 2>w1 || bad "the far triangle: $(cat w1)"
grep -q "warning: the sun's 512x512 shadow map has texels of .* set by the bounds of /objects/1" w1 &&
    ok "a far vertex: the sun's map warned of, naming /objects/1" || bad "no warning of the far vertex: $(cat w1)"
sun_scene near.obj | "$A" render - -o x.png 2>w2 || bad "near: $(cat w2)"
grep -q "shadow map" w2 && bad "warned without the far vertex: $(cat w2)" || ok "no warning without it"
# the memory: refused before anything is allocated (a second, not the minutes of swapping)
"$A" render hemi.json -D 'wavelengths={"mode":"spectral","samples":128}' --width 16384 --height 16384 -o big.png -q 2>m1 &&
    bad "a 16384^2 image of 128 wavelengths rendered" || true
grep -q "needs about .* GB (1624 bytes a pixel), more than the .* GB of memory it may have, .*--width" m1 &&
    ok "a 16384^2 image of 128 wavelengths refused with its estimate" || bad "no refusal: $(cat m1)"
[ -e big.png ] && bad "the refused image was written"
# the same bound from the address-space limit (ulimit -v, 3 GB): 2048^2 of 128 wavelengths (6.8 GB)
# refused whatever the machine has
(ulimit -v 3000000 && "$A" render hemi.json -D 'wavelengths={"mode":"spectral","samples":128}' --width 2048 \
    --height 2048 -o big2.png -q) 2>m3 && bad "a 2048^2 image of 128 wavelengths rendered under ulimit -v 3 GB" || true
grep -q "more than the 3.1 GB of memory it may have, the process's address-space limit (ulimit -v)" m3 &&
    ok "the address-space limit bounds the estimate" || bad "no refusal under ulimit -v: $(cat m3)"
"$A" render hemi.json --width 64 --height 48 -o small.png 2>m2 || bad "a small image: $(cat m2)"
grep -q "needs about" m2 && bad "a small image warned of: $(cat m2)" || ok "a small image: no word of memory"
# a point light's default reach: 1e5 W/sr, fog 0.002 /m, seen from 400 m
cat >pt.json <<'JSON'
{"image": {"width": 64, "height": 40}, "camera": {"type": "pinhole", "position_m": [0, 30, 400], "look_at_m": [0, 30, 0], "fov_deg": 60},
 "background": "black", "renderer": "beams", "wavelengths": {"mode": "rgb"}, "fog": {"extinction_per_m": 0.002},
 "lights": [{"type": "point", "position_m": [0, 30, 0], "intensity_w_sr": 100000}], "objects": [{"mesh": "builtin:plane", "scale": 1000}]}
JSON
"$A" render pt.json -o ptb.pfm -q 2>r1 || bad "beams, a point light's default reach: $(cat r1)"
"$A" render pt.json --renderer path --max-depth 1 --spp 32 --seed 5 -o ptp.pfm -q 2>r2 || bad "path: $(cat r2)"
python3 - ptb.pfm ptp.pfm <<'PY' && ok "a point light's default reach: beams within 5 % of the path tracer, 15 % at the edges" || bad "default reach"
import sys, pfm
b, p = pfm.read(sys.argv[1]), pfm.read(sys.argv[2])
g, r, w = b.v[1::3], p.v[1::3], b.w
edge = lambda v: sum(v[i] for i in range(len(v)) if i % w < w // 8 or i % w >= w - w // 8)
m, e = sum(g) / sum(r), edge(g) / edge(r)
print("beams / path: mean %.4f, the outer eighths %.4f" % (m, e))
sys.exit(0 if abs(m - 1) < 0.05 and abs(e - 1) < 0.15 else 1)
PY
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}
python3 - "$S/docs/scene-format.md" >doc.json <<'PY' || bad "no json block in scene-format.md's beams section"
import sys, re
text = open(sys.argv[1], encoding="utf-8").read()
sec = text.split("\n## `beams`", 1)[1].split("\n## ", 1)[0]
m = re.search(r"```json\n(.*?)```", sec, re.S)
sys.exit(1) if not m else print(m.group(1))
PY
"$A" render doc.json --width 48 --height 32 -o doc.pfm -q 2>d1 || bad "the docs' beams example: $(cat d1)"
python3 - doc.pfm <<'PY' && ok "the docs' beams example shows its beam and the floor" || bad "the docs' beams example"
import sys, pfm
b = pfm.read(sys.argv[1])
g, w, h = b.v[1::3], b.w, b.h
lit = sum(1 for v in g if v > 0) / len(g)
band = lambda y0, y1: sum(1 for i in range(y0 * w, y1 * w) if g[i] > 0)
# pfm rows run bottom to top
top, bottom = band(h - h // 3, h), band(0, h // 3)
print("pixels with light: %.3f; in the top third %d, the bottom third %d" % (lit, top, bottom))
sys.exit(0 if lit > 0.05 and top > 0 and bottom > 0 else 1)
PY
"$A" render "$S/scenes/dobashi_fig04_spotlight.json" --width 12 --height 18 -D lights.0.cone_deg=0 \
    -D lights.0.edge_deg=0 -o z.pfm -q 2>z.err || bad "a spot of no angle: $(cat z.err)"
grep -q "/lights/0: a spot of cone_deg 0 and edge_deg 0 lights nothing" z.err && ok "a spot of no angle is warned of" ||
    bad "a spot of no angle: no warning ($(cat z.err))"
# a 4097 x 4096 image, 50 kB of zeros: refused from its header in well under a second
"${ATMOS_PYTHON:-python3}" - <<'PY' || bad "writing the big image"
import struct, zlib
w, h = 4097, 4096
raw = (b'\x00' * (1 + 3 * w)) * h
chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
open('huge.png', 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0)) +
                             chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))
PY
"$A" render "$S/scenes/dobashi_fig09b_stained_glass.json" --width 12 --height 8 -D lights.0.image="$T/huge.png" -o h.png -q 2>h.err
[ $? -eq 1 ] && grep -q "4097 x 4096 texels; a light's image may have at most" h.err && [ ! -e h.png ] &&
    ok "a huge light image refused" || bad "a huge light image: $(cat h.err)"
exit $fail
