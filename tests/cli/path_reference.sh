#!/bin/sh
# atmos render --renderer path over a planet without a volume: the Monte Carlo reference sky
# (docs/sky.md, "The reference"). The same bytes on 1 and 2 threads; finite, lit sky and ground;
# all orders of scattering bring more light than the first alone (--max-depth 1).
set -u
. "$(dirname "$0")/common.inc"
cat > "$T/s.json" <<'JSON'
{"name": "reference sky", "image": {"width": 16, "height": 8},
 "camera": {"type": "equirect", "position_m": [0, 100, 0]},
 "sun": {"elevation_deg": 20.0, "azimuth_deg": 180.0},
 "atmosphere": {"model": "spherical", "ground_albedo": 0.3},
 "renderer": "path", "path": {"spp": 8}}
JSON
"$A" render -q "$T/s.json" --threads 1 --pfm "$T/a.pfm" && ok || bad "render, 1 thread"
"$A" render -q "$T/s.json" --threads 2 --pfm "$T/b.pfm" && ok || bad "render, 2 threads"
cmp -s "$T/a.pfm" "$T/b.pfm" && ok || bad "1 and 2 threads differ"
"$A" render -q "$T/s.json" --threads 2 --max-depth 1 --pfm "$T/c.pfm" && ok || bad "render --max-depth 1"
python3 - "$T/a.pfm" "$T/c.pfm" <<'PY' && ok || bad "image check"
import sys, pfm
def rgb(p):
    i = pfm.read(p)
    assert i.c == 3, i.kind
    return i.w, i.h, i.v
w, h, a = rgb(sys.argv[1])
_, _, c = rgb(sys.argv[2])
assert (w, h) == (16, 8)
s = pfm.stats(a + c)
assert s.nonfinite == 0 and s.min >= 0, "bad pixel values"
# PFM rows run bottom to top: rows 0-3 look down (the ground), 4-7 up (the sky)
ground = sum(a[: w * 4 * 3]); sky = sum(a[w * 4 * 3:])
assert ground > 0 and sky > 0, (ground, sky)
assert sum(a) > 1.05 * sum(c), (sum(a), sum(c))
PY
echo "path_reference: $pass passed"
[ "$fail" -eq 0 ]
