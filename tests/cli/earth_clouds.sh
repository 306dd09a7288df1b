#!/bin/sh
# The Earth from space in scenes: a spherical atmosphere with a ground map and a cloud image
# (tiny PNGs made here) renders; atmos volume clouds writes the cloud layer as a volume whose
# densities give the layer's extinction; missing map files are refused naming the key.
set -eu
A=${ATMOS_CLI:?}
T=${ATMOS_TEST_TMP:-/tmp}
fail() { echo "earth_clouds.sh: FAIL: $*" >&2; exit 1; }

# 8 x 4 grey PNGs: the cloud image uniform at 153/255 (0.6), the ground map at 64/255
python3 - "$T" <<'PY'
import struct, sys, zlib
def png(path, v, w=8, h=4):
    raw = b"".join(b"\0" + bytes([v] * w) for _ in range(h))
    def chunk(t, d): return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
                           + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
png(sys.argv[1] + "/clouds.png", 153)
png(sys.argv[1] + "/ground.png", 64)
PY
cat > "$T/earth.json" <<'J'
{"image": {"width": 4, "height": 3}, "renderer": "sky",
 "camera": {"type": "pinhole", "position_m": [0, 2000000, 0], "look_at_m": [0, 0, -1000], "fov_deg": 30},
 "sun": {"elevation_deg": 50, "azimuth_deg": 200},
 "atmosphere": {"model": "spherical", "latitude_deg": 10, "longitude_deg": 20, "ground_map": "ground.png",
                "clouds": {"image": "clouds.png", "base_m": 2000, "top_m": 8000, "spheres": 2}}}
J
"$A" render "$T/earth.json" -o "$T/earth.png" > /dev/null 2>&1 || fail "render"
head -c 8 "$T/earth.png" | od -An -c | grep -q "P   N   G" || fail "not a PNG"
"$A" volume clouds "$T/earth.json" -o "$T/cv.json" --half-width 2000 --voxel-size 500 || fail "volume clouds"
"$A" volume info "$T/cv.json" --json > "$T/info.json" || fail "info"
python3 - "$T/info.json" <<'PY' || fail "volume contents"
import json, sys
d = json.load(open(sys.argv[1]))
f = d["fields"][0]
assert f["name"] == "cloud" and d["voxel_size_m"] == 500, d
# 0.6 decoded, above the cloud-free 0.04, inverted through the two-stream reflectance
# (g = 0.85), spread over the 6000 m layer, over the "cloud" preset's cross-section
# (Riley et al. 2004 Table 2: 6.28e-10 m^2)
b = ((0.6 + 0.055) / 1.055) ** 2.4
R = (b - 0.04) / 0.96
tau = 2 * R / (0.15 * (1 - R))
density = tau / 6000.0 / 6.28e-10
assert abs(f["max"] - density) <= 1e-4 * density, (f["max"], density)
PY
# a missing ground map: refused when the scene is loaded, naming the key
sed 's/ground.png/nosuch.png/' "$T/earth.json" > "$T/bad.json"
set +e
"$A" render "$T/bad.json" -o "$T/bad.png" 2> "$T/err.txt"; [ $? -eq 1 ] || fail "missing map exit"
grep -q "ground_map" "$T/err.txt" || fail "missing map message"
"$A" volume clouds "$T/bad.json" -o "$T/x.json" 2> /dev/null; [ $? -eq 1 ] || fail "volume clouds on a bad scene"
"$A" volume clouds; [ $? -eq 2 ] || fail "usage exit"
# a centre so far that the curved layer is too tall for a box: said so, not an int's overflow
"$A" volume clouds "$T/earth.json" -o "$T/far.json" --centre 1e12,0 --voxel-size 4000 2> "$T/err.txt"; [ $? -eq 1 ] || fail "far centre: exit"
grep -q "reaches so far round the Earth" "$T/err.txt" && ! grep -q -- "-2147483648" "$T/err.txt" || fail "far centre: $(cat "$T/err.txt")"
# -o naming the scene itself: refused before anything is written, the scene kept
cp "$T/earth.json" "$T/self.json"
"$A" volume clouds "$T/self.json" -o "$T/self.json" 2> "$T/err.txt"; [ $? -eq 2 ] || fail "-o over the scene: exit"
grep -q "refusing to overwrite an input" "$T/err.txt" && cmp -s "$T/self.json" "$T/earth.json" || fail "-o over the scene: $(cat "$T/err.txt")"
# too many voxels across: an option's mistake (exit 2, before the scene is read), with the count
# it would give and the bound, as volume generate's; the bound is in volume --help
"$A" volume clouds "$T/earth.json" -o "$T/x.json" --voxel-size 1 2> "$T/err.txt"; [ $? -eq 2 ] || fail "voxel count exit"
grep -qF "atmos volume: clouds: --half-width 20000 m in voxels of --voxel-size 1 m gives 40000 voxels across (allowed 1..8192)" \
    "$T/err.txt" || { cat "$T/err.txt" >&2; fail "voxel count message"; }
"$A" volume --help | grep -q "at most 8192 across" || fail "volume --help: the voxel bound"
exit 0
