#!/bin/sh
# atmos view keeps the scene's camera (docs/viewer.md, "Cameras"): the shipped fisheye and
# equirectangular scenes open headless and record their frames, each the same image as
# `atmos render` makes of the scene (every display value within one level of 255), and a
# fisheye's corners, outside its circle, stay empty (a pinhole would fill them with sky).
# The slice renderer draws pinhole cameras only: switched to it, the viewer shows a 120°
# pinhole looking the same way, says so once, and a save (F12) writes that camera, whose
# offline render has the same pixels.
. "$(dirname "$0")/common.inc"
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}/scenes
cd "$T" || exit 1

# PNG_A PNG_B [corners]: the largest difference of two 8-bit PNGs' values; "corners": also
# the largest value of A's four corner pixels (RGB).
cat >png.py <<'PY'
import struct, sys, zlib
def png(path):
    d = open(path, "rb").read(); i = 8; idat = b""
    while i < len(d):
        n, = struct.unpack(">I", d[i:i + 4]); t = d[i + 4:i + 8]; c = d[i + 8:i + 8 + n]
        if t == b"IHDR": w, h, bd, ct = struct.unpack(">IIBB", c[:10])
        if t == b"IDAT": idat += c
        i += 12 + n
    assert bd == 8, bd
    bpp = {0: 1, 2: 3, 4: 2, 6: 4}[ct]
    raw = zlib.decompress(idat); s = w * bpp; prev = bytearray(s); rows = []; p = 0
    for y in range(h):
        f = raw[p]; ln = bytearray(raw[p + 1:p + 1 + s]); p += 1 + s
        for x in range(s):
            a = ln[x - bpp] if x >= bpp else 0; b = prev[x]; c = prev[x - bpp] if x >= bpp else 0
            if f == 1: ln[x] = (ln[x] + a) & 255
            elif f == 2: ln[x] = (ln[x] + b) & 255
            elif f == 3: ln[x] = (ln[x] + (a + b) // 2) & 255
            elif f == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                ln[x] = (ln[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(ln)); prev = ln
    return w, h, bpp, rows
wa, ha, ba, A = png(sys.argv[1]); wb, hb, bb, B = png(sys.argv[2])
assert (wa, ha) == (wb, hb), ((wa, ha), (wb, hb))
rgb = lambda r, x, bpp: r[x * bpp:x * bpp + 3]
diff = max(abs(p - q) for y in range(ha) for x in range(wa) for p, q in zip(rgb(A[y], x, ba), rgb(B[y], x, bb)))
mean = sum(sum(rgb(A[y], x, ba)) for y in range(ha) for x in range(wa)) / (3.0 * wa * ha)
out = "diff=%d mean=%.1f" % (diff, mean)
if len(sys.argv) > 3:
    out += " corners=%d" % max(max(rgb(A[y], x, ba)) for y in (0, ha - 1) for x in (0, wa - 1))
print(out)
PY

# NAME SIZE CORNERS SCENE_ARGS...: one headless frame recorded, compared with atmos render
same_as_render() {
    name=$1 w=${2%x*} h=${2#*x} corners=$3
    shift 3
    rm -rf rec
    "$A" view "$@" --headless --frames 1 --size "${w}x$h" --record rec >view.txt 2>&1
    st=$?
    rows=$( [ -f rec/frames.csv ] && tail -n +2 rec/frames.csv | wc -l || echo 0)
    if [ $st -ne 0 ] || [ "$rows" -ne 1 ] || [ ! -s rec/frame_00000.png ]; then
        bad "$name: exit $st, $rows recorded frame(s)"
        sed 's/^/  /' view.txt >&2
        return
    fi
    ok "$name opens headless and records its frame"
    "$A" render "$@" --width "$w" --height "$h" -o off.png >render.txt 2>&1 || { bad "$name: atmos render"; cat render.txt >&2; return; }
    r=$(python3 png.py rec/frame_00000.png off.png $corners) || { bad "$name: comparing the PNGs"; return; }
    d=$(echo "$r" | sed 's/.*diff=\([0-9]*\).*/\1/')
    [ "$d" -le 1 ] && ok "$name: the viewer's frame is atmos render's ($r)" || bad "$name: differs from atmos render ($r)"
    case $corners in
    corners)
        c=$(echo "$r" | sed 's/.*corners=\([0-9]*\).*/\1/')
        [ "$c" -eq 0 ] && ok "$name: the corners outside the fisheye's circle are empty" ||
            bad "$name: corners $c: not a fisheye";;
    esac
}
same_as_render "sunset_fisheye.json" 64x64 corners "$S/sunset_fisheye.json"
same_as_render "clear_noon_fisheye.json" 48x48 corners "$S/clear_noon_fisheye.json"
same_as_render "sunrise_equirect.json" 64x32 "" "$S/sunrise_equirect.json"
same_as_render "--camera fisheye" 48x48 corners --camera fisheye

# A volume's frame 0 is framed as atmos render frames it (the scene's camera, not one aimed at
# the volume's centre), for a generated volume given on the command line and for a scene's
# (Harris's field, its camera pitched 4 degrees up); the sun's columns of frames.csv give the
# sun that lights them
same_as_render "--volume generate:cumulus" 64x36 "" --volume generate:cumulus
python3 - rec/frames.csv <<'PY' && ok "frames.csv: the sun of a sunlit volume" || bad "frames.csv: the sunlit volume's sun"
import csv, sys
r = list(csv.DictReader(open(sys.argv[1])))
assert abs(float(r[0]["sun_elevation_deg"]) - 22) < 1e-3 and abs(float(r[0]["sun_azimuth_deg"]) - 235) < 1e-3, r
PY
# its --frames orbit: the scene's camera turned about the vertical through the cloud's centre,
# 90 degrees a frame, its pitch and height kept, its distance from that vertical too
rm -rf orb
"$A" view --volume generate:cumulus --headless --frames 4 --size 16x9 --record orb >orb.txt 2>&1 ||
    { bad "--volume generate:cumulus --frames 4"; cat orb.txt >&2; }
python3 - orb/frames.csv <<'PY' && ok "--frames 4 with a volume: the scene's camera turned about it, pitch kept" ||
import csv, math, sys
r = list(csv.DictReader(open(sys.argv[1])))
assert len(r) == 4, r
g = lambda x, k: float(x[k])
assert abs(g(r[0], "pitch_deg") - 1) < 1e-3, r[0]   # atmos render's camera: 1 degree up
for a, b in zip(r, r[1:]):
    assert abs((g(b, "yaw_deg") - g(a, "yaw_deg")) % 360 - 90) < 1e-3, (a, b)
    assert g(b, "pitch_deg") == g(a, "pitch_deg") and g(b, "y_m") == g(a, "y_m"), (a, b)
# the centre on the vertical where the lines of sight of frames 0 and 2 (opposite) meet
p = [(g(x, "x_m"), g(x, "z_m")) for x in r]
c = ((p[0][0] + p[2][0]) / 2, (p[0][1] + p[2][1]) / 2)
d = [math.dist(q, c) for q in p]
assert max(d) - min(d) < 1e-3 * max(d) and max(d) > 100, d
PY
    bad "--frames 4 with a volume: not a turn of the scene's camera about the volume"
same_as_render "harris_cloud_field.json" 64x36 "" "$S/harris_cloud_field.json"
python3 - rec/frames.csv <<'PY' && ok "harris_cloud_field.json: frame 0 pitched 4 degrees up" || bad "harris_cloud_field.json: frame 0's pitch"
import csv, sys
r = list(csv.DictReader(open(sys.argv[1])))
assert abs(float(r[0]["pitch_deg"]) - 4) < 0.01, r
PY
# a beam scene lit by its lamps only (atmos render: "lit by its 1 light and no sun"): no sun
# in frames.csv either (docs/viewer.md: the sun's columns are empty)
same_as_render "dobashi_fig04_spotlight.json" 64x36 "" "$S/dobashi_fig04_spotlight.json"
python3 - rec/frames.csv <<'PY' && ok "frames.csv: no sun for a scene lit by its lamps only" || bad "frames.csv: a sun for a scene without one"
import csv, sys
r = list(csv.DictReader(open(sys.argv[1])))
assert r[0]["sun_elevation_deg"] == "" and r[0]["sun_azimuth_deg"] == "", r
PY

# A fisheye with a volume: path, sky, then the slice renderer, which draws pinholes only
# (the renderer key pressed by a flight at frames 1 and 2; F12 at frame 3). The droplets' phase
# function is a Henyey-Greenstein lobe: no Mie tables to make in the test's fresh cache.
cat >fish.json <<'JSON'
{"camera": {"type": "fisheye", "position_m": [0, 2, 0], "fov_deg": 180},
 "volume": {"generate": "cumulus", "position_m": [0, 1500, -1500], "voxel_size_m": 200},
 "particles": {"cloud": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.85}], "sigma_ext_m2": 6e-10}},
 "renderer": "path", "path": {"spp": 1},
 "sun": {"elevation_deg": 40, "azimuth_deg": 180}}
JSON
cat >flight.json <<'JSON'
{"fps": 1, "keys": [{"t": 0, "position_m": [0, 2, 0], "look_at_m": [0, 1000, 0]},
                    {"t": 1, "position_m": [0, 2, 0], "look_at_m": [0, 1000, 0], "press": "renderer"},
                    {"t": 2, "position_m": [0, 2, 0], "look_at_m": [0, 1000, 0], "press": "renderer"},
                    {"t": 3, "position_m": [0, 2, 0], "look_at_m": [0, 1000, 0], "press": "save"}]}
JSON
rm -rf rec
"$A" view fish.json --headless --frames 5 --size 32x32 --script flight.json --record rec --save-base shot \
    >fish.txt 2>&1
st=$?
[ $st -eq 0 ] && ok "fisheye with a volume: 5 frames, exit 0" || { bad "fisheye with a volume: exit $st"; cat fish.txt >&2; }
r=$(cut -d, -f3 rec/frames.csv 2>/dev/null | tr '\n' ' ')
[ "$r" = "renderer path sky slice slice slice " ] && ok "renderers: $r" || bad "renderers: '$r'"
n=$(grep -c "shown as a 120-degree pinhole" fish.txt)
[ "$n" -eq 1 ] && ok "the pinhole in place of the fisheye is said once" || { bad "said $n times"; cat fish.txt >&2; }
python3 - shot_001.json <<'PY' && ok "the saved slice frame's camera: a 120-degree pinhole looking up" || bad "the saved camera"
import json, math, sys
c = json.load(open(sys.argv[1]))["camera"]
assert c["type"] == "pinhole" and c["fov_deg"] == 120, c
d = [a - b for a, b in zip(c["look_at_m"], c["position_m"])]
assert d[1] / math.hypot(*d) > 0.9999, d
PY
if [ -f shot_001.exr ]; then
    "$A" render shot_001.json --exr off.exr >/dev/null 2>&1 || bad "offline render of the saved slice frame"
    "$A" compare shot_001.exr off.exr --json >cmp.json 2>&1 || bad "compare"
    python3 -c "import json,sys; c=json.load(open('cmp.json')); assert c['rmse'] == 0, c" &&
        ok "the saved slice frame = its offline render" || bad "the saved slice frame differs from its offline render"
fi

exit $fail
