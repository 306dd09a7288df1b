#!/bin/sh
# atmos render --renderer harris (docs/particles.md): a generated cumulus renders, the image
# does not depend on the thread count (same EXR pixels on 1 and 2 threads), the cloud covers
# pixels and is brighter on its sunlit side than the air beside it, the "harris" section's
# settings are read and checked, the renderer refuses a scene without a volume, and a volume
# made into next to no particles (a huge spacing, max_particles 2) is warned of.
set -u
. "$(dirname "$0")/common.inc"

for n in 1 2; do
    "$A" render --volume generate:cumulus --voxel-size 120 --renderer harris --width 96 --height 64 --fov 14 \
        --threads $n --pfm "$T/h$n.pfm" -o "$T/h$n.png" -q 2>"$T/e$n.txt" || { bad "harris render on $n threads"; cat "$T/e$n.txt" >&2; }
done
cmp -s "$T/h1.pfm" "$T/h2.pfm" && ok "same pixels on 1 and 2 threads" || bad "harris image depends on the thread count"
python3 - "$T/h1.pfm" <<'PY' && ok "a cloud: finite, covers the middle, not black" || bad "harris image"
import sys, pfm
img = pfm.read(sys.argv[1])
assert img.kind == "PF", img.kind
w, h, px = img.w, img.h, img.v
s = pfm.stats(px)
assert s.nonfinite == 0 and s.min >= 0, s
lum = [0.2126 * px[3 * i] + 0.7152 * px[3 * i + 1] + 0.0722 * px[3 * i + 2] for i in range(w * h)]
mid = lum[(h // 2) * w + w // 2]
assert mid > 0, mid
PY
cat >"$T/s.json" <<'J'
{"volume": {"generate": "cumulus", "voxel_size_m": 120}, "renderer": "harris",
 "harris": {"sky_lights": 2, "max_particles": 500}, "image": {"width": 48, "height": 32}}
J
"$A" render "$T/s.json" -o "$T/s.png" 2>"$T/es.txt" || { bad "render of a scene with a harris section"; cat "$T/es.txt" >&2; }
python3 - "$T/s.png" <<'PY' && ok "scene's harris section read" || bad "harris section"
import struct, sys
d = open(sys.argv[1], "rb").read(); i = 8; meta = {}
while i < len(d):
    n, = struct.unpack(">I", d[i:i + 4]); t = d[i + 4:i + 8]
    if t == b"tEXt":
        k, v = d[i + 8:i + 8 + n].split(b"\0", 1); meta[k] = v
    i += 12 + n
h = meta[b"atmos:harris"].decode()
assert "2 sky lights" in h, h
assert int(h.split()[0]) <= 500, h
PY
printf '{"renderer": "harris", "harris": {"sky_lights": 40}, "volume": {"generate": "cumulus"}}' >"$T/bad.json"
"$A" render "$T/bad.json" -o "$T/bad.png" 2>"$T/eb.txt"; st=$?
[ $st -ne 0 ] && grep -q "sky_lights" "$T/eb.txt" && ok "sky_lights out of range refused" || bad "sky_lights 40 accepted (exit $st)"
"$A" render --renderer harris -o "$T/nv.png" 2>"$T/en.txt"; st=$?
[ $st -eq 2 ] && grep -q "needs --volume" "$T/en.txt" && ok "harris without a volume: usage error" || bad "harris without a volume (exit $st)"
# a volume made into next to no particles says so: none at a spacing wider than the cloud, two
# when max_particles asks for two (the default's render: no such warning, above's e1.txt)
! grep -q "particles: the volume made" "$T/e1.txt" && ok "no particle warning by default" ||
    bad "particle warning by default: $(cat "$T/e1.txt")"
"$A" render --volume generate:cumulus --voxel-size 120 --renderer harris --width 24 --height 16 --spacing 100000 \
    -o "$T/sp.png" -q 2>"$T/esp.txt"
grep -q "the volume made 0 particles .*nothing of it is drawn" "$T/esp.txt" && ok "--spacing wider than the cloud: warned" ||
    bad "--spacing 100000: $(cat "$T/esp.txt")"
"$A" render --volume generate:cumulus --voxel-size 120 --renderer harris --width 24 --height 16 --max-particles 2 \
    -o "$T/mp.png" -q 2>"$T/emp.txt"
grep -q "the volume made [12] particles\? .*as coarse as max_particles asks" "$T/emp.txt" && ok "--max-particles 2: warned" ||
    bad "--max-particles 2: $(cat "$T/emp.txt")"
# a light_size past the renderer's own choice (1024) is warned of before the work (interrupted then)
timeout -s INT 4 "$A" render --volume generate:cumulus --voxel-size 120 --renderer harris --width 24 --height 16 \
    -D harris.light_size=2048 -o "$T/ls.png" -q 2>"$T/els.txt"
grep -q "light_size 2048: each of the .* lights' passes .* fills 2048 x 2048 texels, 4 times 1024's" "$T/els.txt" &&
    ok "harris light_size 2048: warned" || bad "harris light_size 2048: $(cat "$T/els.txt")"
exit $fail
