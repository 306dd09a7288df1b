#!/bin/sh
# What newcomers ran into, each now as the help and the docs say; the sections are numbered
# as the list of fixes they came in (docs: particles.md, volumes.md, clouds.md, sky.md).
. "$(dirname "$0")/common.inc"
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }
hasnt() { grep -qF -- "$2" "$T/err" && { bad "$1: '$2' in:"; sed 's/^/  /' "$T/err" >&2; } || ok "$1: no '$2'"; }
# pix FILE.pfm X Y: the mean of the first three channels of pixel (X, Y) (Y from the top)
pix() {
    python3 - "$@" <<'EOF'
import sys, pfm
v = pfm.pixel(pfm.read(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]))
print(sum(v) / len(v))
EOF
}
# within A B TOL: |A - B| <= TOL max(|A|, |B|)
within() { python3 -c "import sys; a, b = $1, $2; sys.exit(0 if abs(a - b) <= $3 * max(abs(a), abs(b)) else 1)"; }

# --- 1. Harris through every camera: a cumulus 4 km north of the eye, at its height (a coarse
# one, with an analytic phase function: no tables to build)
"$A" volume generate cumulus --seed 3 --voxel-size 200 -o "$T/cu.json" >/dev/null 2>&1 || bad "volume generate"
cat >"$T/h.json" <<EOF
{"image": {"width": 33, "height": 33}, "wavelengths": {"mode": "rgb"},
 "camera": {"type": "pinhole", "position_m": [0, 1800, 0], "look_at_m": [0, 1800, -4000], "fov_deg": 40},
 "sun": {"elevation_deg": 30, "azimuth_deg": 120},
 "volume": {"file": "$T/cu.json", "position_m": [0, 1800, -4000]},
 "particles": {"cloud": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.8}], "sigma_ext_m2": 6e-10}},
 "renderer": "harris", "harris": {"impostors": false, "sky_lights": 2}}
EOF
"$A" render "$T/h.json" --pfm "$T/pin.pfm" -q 2>"$T/err" || { bad "harris pinhole"; cat "$T/err" >&2; }
# the same camera (position, look-at, up) as a 180-degree fisheye and as an equirect
"$A" render "$T/h.json" -D camera.type=fisheye -D camera.fov_deg=180 --pfm "$T/fish.pfm" -q 2>"$T/err" ||
    { bad "harris fisheye"; cat "$T/err" >&2; }
"$A" render "$T/h.json" -D camera.type=equirect --width 65 --height 33 --pfm "$T/eq.pfm" -q 2>"$T/err" ||
    { bad "harris equirect"; cat "$T/err" >&2; }
grep -v '"volume"' "$T/h.json" | sed 's/"renderer": "harris", //' >"$T/hs.json" # the sky alone
"$A" render "$T/hs.json" --renderer sky -D camera.type=fisheye -D camera.fov_deg=180 --pfm "$T/sky.pfm" -q 2>"$T/err" ||
    { bad "sky fisheye"; cat "$T/err" >&2; }
if [ -s "$T/pin.pfm" ] && [ -s "$T/fish.pfm" ] && [ -s "$T/eq.pfm" ] && [ -s "$T/sky.pfm" ]; then
    p=$(pix "$T/pin.pfm" 16 16) f=$(pix "$T/fish.pfm" 16 16) e=$(pix "$T/eq.pfm" 32 16) s=$(pix "$T/sky.pfm" 16 16)
    within "$f" "$s" 0.2 && bad "fisheye: the cloud is missing (centre $f, the sky alone $s)" ||
        ok "fisheye: the cloud is drawn (centre $f, the sky alone $s)"
    # the same ray through the same splats: the wide cameras composite them in the order of
    # their distance from the eye, a pinhole in that of their depth along its axis (the axis
    # ray's own order), which puts some overlapping splats the other way round: 3.0 % here with
    # the diffuse light field (the default since 2026-12-06: the particles' colours differ more
    # from one to the next), 1.3 % without it (both in the distance order: the same value to all
    # digits)
    within "$f" "$e" 1e-6 && ok "fisheye's axis = equirect's north ($f, $e)" || bad "fisheye's axis $f, equirect's north $e"
    within "$f" "$p" 0.04 && ok "fisheye's axis = pinhole's within 4 % ($f, $p)" || bad "fisheye's axis $f, pinhole's $p"
fi

# --- 2. options that shape the PNG only, with no PNG written
"$A" render --width 8 --height 8 --tone reinhard --png-bits 16 --exr "$T/z.exr" -q 2>"$T/err" ||
    { bad "render --exr with --tone"; cat "$T/err" >&2; }
has "--tone, --png-bits, no PNG" "--tone, --png-bits"
has "--tone, --png-bits, no PNG" "no PNG is written"
"$A" render --width 8 --height 8 --tone reinhard --png-bits 16 -o "$T/z.png" --exr "$T/z2.exr" -q 2>"$T/err" ||
    bad "render -o PNG with --tone"
hasnt "-o PNG with --tone" "no PNG is written"
"$A" render --width 8 --height 8 --exposure 12 --pfm "$T/z.pfm" -q 2>"$T/err" || bad "render --pfm --exposure"
has "--exposure, no PNG" "--exposure"
# --exr-half with no EXR written: said, as --tone is; with one, not
"$A" render --width 8 --height 8 --exr-half --pfm "$T/z.pfm" -q 2>"$T/err" || bad "render --pfm --exr-half"
has "--exr-half, no EXR" "--exr-half: it shapes the EXR image only"
"$A" render --width 8 --height 8 --exr-half -o "$T/h.exr" -q 2>"$T/err" || bad "render -o EXR --exr-half"
hasnt "--exr-half with -o FILE.exr" "--exr-half"
# --exr-layers with no volume names the layers asked for only
"$A" render --width 8 --height 8 --exr-layers tau --exr "$T/z.exr" -q 2>"$T/err" && bad "--exr-layers tau, no volume: exit 0"
has "--exr-layers tau, no volume" "--exr-layers tau: it needs a volume"
hasnt "--exr-layers tau, no volume" "transmittance"
# --exr-layers variance without the path tracer names the layer asked for only
"$A" render --width 8 --height 8 --exr-layers variance --exr "$T/z.exr" -q 2>"$T/err" && bad "--exr-layers variance, sky: exit 0"
has "--exr-layers variance, sky" "--exr-layers variance: it is the path tracer's (--renderer path)"
hasnt "--exr-layers variance, sky" "order"
# a word for an integer setting names the range, as a number outside it does
"$A" render --nishita-orders x --width 8 --height 8 -o "$T/n.png" -q 2>"$T/err" && bad "--nishita-orders x: exit 0"
has "--nishita-orders x" "--nishita-orders: expected an integer in [1, 3], got 'x'"
# and so does one for a real-valued setting
"$A" render --xi x --width 8 --height 8 -o "$T/n.png" -q 2>"$T/err" && bad "--xi x: exit 0"
has "--xi x" "--xi: expected a value in [0, 100] sr^-1, got 'x'"
# an output whose temporary cannot be made: said of the output, not naming the output as the temporary
"$A" volume slice "$T/cu.json" --axis x -o /proc/atmos_slice.png 2>"$T/err" && bad "volume slice into /proc: exit 0"
has "volume slice into /proc" "/proc/atmos_slice.png: cannot create a temporary file beside it"
hasnt "volume slice into /proc" "temporary file /proc"

# --- 3. an output's format checked before the inputs are read: a missing volume is not
# what is reported
"$A" render --volume "$T/missing.vdb" -o "$T/x.jpg" 2>"$T/err"
[ $? -eq 2 ] && ok "render -o x.jpg: a usage error" || bad "render -o x.jpg: not a usage error"
has "render -o x.jpg" "x.jpg"
hasnt "render -o x.jpg" "missing.vdb"
"$A" volume slice "$T/missing.json" --axis z -o "$T/s.jpg" 2>"$T/err"
[ $? -eq 2 ] && ok "volume slice -o s.jpg: a usage error" || bad "volume slice -o s.jpg: not a usage error"
has "volume slice -o s.jpg" ".png"
hasnt "volume slice -o s.jpg" "missing.json"
"$A" volume stats "$T/missing.json" --mask-png "$T/m.jpg" 2>"$T/err"
[ $? -eq 2 ] && ok "volume stats --mask-png m.jpg: a usage error" || bad "volume stats --mask-png m.jpg: not a usage error"
hasnt "volume stats --mask-png m.jpg" "missing.json"

# --- 4. an empty slice: raw volumes of 8 x 4 x 8 voxels, all zero, and with one voxel set
python3 - "$T" <<'EOF'
import json, struct, sys
t = sys.argv[1]
for name, at in (("zero", None), ("corner", (0, 0, 0))):
    v = [0.0] * (8 * 4 * 8)
    if at:
        v[at[0] + 8 * (at[1] + 4 * at[2])] = 1e8
    open(f"{t}/{name}.raw", "wb").write(struct.pack("<%df" % len(v), *v))
    json.dump({"file": f"{name}.raw", "dims": [8, 4, 8], "voxel_size_m": 100, "origin_m": [0, 0, 0]},
              open(f"{t}/{name}.json", "w"))
EOF
"$A" volume slice "$T/zero.json" --axis z -o "$T/zs.png" 2>"$T/err" || bad "slice of an all-zero field"
has "all-zero slice" "is empty"
"$A" volume slice "$T/corner.json" --axis z --at 0.9 -o "$T/cs.png" 2>"$T/err" || bad "slice missing the density"
has "slice missing the density" "holds none"
"$A" volume slice "$T/corner.json" --axis z --at 0 -o "$T/c0.png" 2>"$T/err" || bad "slice through the density"
hasnt "slice through the density" "warning"

# --- 5. periodic sides kept through a file: a 16 x 4 x 16 cloud layer with one cloud across
# the x edge (columns 0-1 and 14-15, rows 6-9)
python3 - "$T" <<'EOF'
import json, struct, sys
t = sys.argv[1]
v = [0.0] * (16 * 4 * 16)
for k in range(6, 10):
    for i in (0, 1, 14, 15):
        for j in range(1, 3):
            v[i + 16 * (j + 4 * k)] = 1e9
open(f"{t}/edge.raw", "wb").write(struct.pack("<%df" % len(v), *v))
for name, per in (("edge", False), ("edge_p", True)):
    d = {"file": "edge.raw", "dims": [16, 4, 16], "voxel_size_m": 100, "origin_m": [0, 0, 0]}
    if per:
        d["periodic"] = True
    json.dump(d, open(f"{t}/{name}.json", "w"))
EOF
stats() { "$A" volume stats "$@" --kv --min-pixels 1 2>"$T/err"; }
stats "$T/edge_p.json" >"$T/sp" || { bad "stats of a periodic sidecar"; cat "$T/err" >&2; }
stats "$T/edge.json" --periodic >"$T/sP" || bad "stats --periodic"
stats "$T/edge.json" >"$T/sn" || bad "stats of a sidecar without periodic"
cmp -s "$T/sp" "$T/sP" && ok "a sidecar's \"periodic\": true = --periodic" || bad "the sidecar's periodic was not read"
cmp -s "$T/sp" "$T/sn" && bad "periodic and non-periodic stats agree (the test cannot tell)" || ok "non-periodic differs"
stats "$T/edge_p.json" --no-periodic >"$T/spn" || bad "stats --no-periodic"
cmp -s "$T/spn" "$T/sn" && ok "--no-periodic overrides the sidecar" || bad "--no-periodic did not override the sidecar"
printf '{"file": "edge.raw", "dims": [16, 4, 16], "voxel_size_m": 100, "periodic": "yes"}' >"$T/bad.json"
"$A" volume info "$T/bad.json" >/dev/null 2>"$T/err" && bad "\"periodic\": \"yes\" accepted" || has "periodic: yes" "periodic: expected true or false"
if "$A" simulate stratocumulus --grid 16 --minutes 0.5 --quiet -o "$T/sim.json" 2>"$T/err"; then
    grep -q '"periodic":[[:space:]]*true' "$T/sim.json" && ok "simulate -o writes \"periodic\": true" ||
        { bad "no periodic in the simulation's sidecar:"; cat "$T/sim.json" >&2; }
    "$A" volume info "$T/sim.json" >"$T/err" 2>&1 && has "volume info of a simulation" "periodic"
else
    bad "simulate"; cat "$T/err" >&2
fi
"$A" volume generate cumulus --voxel-size 200 -o "$T/gen.json" >/dev/null 2>&1 || bad "volume generate"
grep -q periodic "$T/gen.json" && bad "a generated volume's sidecar says periodic" || ok "a generated volume is not periodic"

# --- 7. --lat/--lon over a round planet: a map white in the north and black in the south,
# seen straight down from 2000 km over 30 N and over 30 S at the equinox's noon at 0 E (the
# sun 60 degrees high at both): the ground turns under the camera, so the two differ by the
# map's contrast; before, only the sun moved and the two saw the same ground
python3 - "$T/map.png" <<'EOF'
import struct, sys, zlib
w, h = 16, 8
rows = b"".join(b"\0" + bytes([255 if y < h // 2 else 0] * (3 * w)) for y in range(h))
def chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
       chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
open(sys.argv[1], "wb").write(png)
EOF
round="-D atmosphere.model=dobashi -D atmosphere.ground_map=$T/map.png --position 0,2000000,0 --view-elevation -90
  --view-azimuth 0 --fov 10 --width 9 --height 9 --time 2026-03-20T12:07:00Z"
# shellcheck disable=SC2086
"$A" render $round --lat 30 --lon 0 --pfm "$T/n.pfm" 2>"$T/err" || { bad "round planet at 30 N"; cat "$T/err" >&2; }
en=$(sed -n 's/.*sun at \([-0-9.]*\) deg elevation.*/\1/p' "$T/err")
# shellcheck disable=SC2086
"$A" render $round --lat -30 --lon 0 --pfm "$T/s.pfm" 2>"$T/err" || { bad "round planet at 30 S"; cat "$T/err" >&2; }
es=$(sed -n 's/.*sun at \([-0-9.]*\) deg elevation.*/\1/p' "$T/err")
if [ -s "$T/n.pfm" ] && [ -s "$T/s.pfm" ]; then
    within "${en:-0}" 60 0.02 && within "${es:-0}" 60 0.02 && ok "the sun 60 deg high at 30 N and 30 S ($en, $es)" ||
        bad "the sun at 30 N: '$en', at 30 S: '$es' (60 expected)"
    n=$(pix "$T/n.pfm" 4 4) s=$(pix "$T/s.pfm" 4 4)
    python3 -c "import sys; sys.exit(0 if $n > 4 * $s else 1)" && ok "--lat turns the map: white north $n, black south $s" ||
        bad "--lat did not turn the map: 30 N $n, 30 S $s"
fi
# --time alone over a round planet: at the atmosphere's place (30 N, 0 E), as --lat 30 --lon 0
# shellcheck disable=SC2086
"$A" render $round -D atmosphere.latitude_deg=30 --pfm "$T/t.pfm" 2>"$T/err" || { bad "--time alone, round planet"; cat "$T/err" >&2; }
[ -s "$T/t.pfm" ] && cmp -s "$T/t.pfm" "$T/n.pfm" && ok "--time alone = --time --lat 30 --lon 0 at the atmosphere's 30 N" ||
    bad "--time alone over a round planet differs from --lat 30 --lon 0"
# a flat sky still wants the place
"$A" render --time 2026-03-20T12:00:00Z --width 8 --height 8 --pfm "$T/f.pfm" 2>"$T/err"
[ $? -eq 2 ] && ok "--time alone over a flat sky: a usage error" || bad "--time alone over a flat sky accepted"
has "--time alone, flat" "go together"
"$A" render --help >"$T/err"
has "render --help" "turn the Earth's map under the camera"

# --- 8. the flat models do not use the round ones' air: said, not silently ignored
"$A" render -D atmosphere.aerosol=desert -D atmosphere.visibility_km=1 -D atmosphere.ozone=false --width 8 --height 8 \
    -o "$T/r.png" -q 2>"$T/err" || bad "riley with aerosol settings"
has "riley ignores the round planet's air" "does not use aerosol, visibility_km and ozone"
"$A" render -D atmosphere.model=spherical -D atmosphere.aerosol=desert --renderer sky --width 8 --height 8 \
    -o "$T/s.png" -q 2>"$T/err" || bad "spherical with aerosol settings"
hasnt "spherical uses its aerosol" "does not use"
"$A" render --width 8 --height 8 -o "$T/d.png" -q 2>"$T/err" || bad "the default scene"
hasnt "the default scene" "does not use"

# the flat sky from space says the planet is elsewhere
"$A" render --altitude 400000 --view-elevation -30 --width 8 --height 8 -o "$T/f.png" -q 2>"$T/err" || bad "riley from 400 km"
has "riley from 400 km" "flat earth"
"$A" render --altitude 4000 --width 8 --height 8 -o "$T/f.png" -q 2>"$T/err" || bad "riley from 4 km"
hasnt "riley from 4 km" "flat earth"

# --- 9. a number that does not parse points to --help, as the other usage errors do
for bad_opt in "--grid 15" "--minutes abc" "--threads 0"; do
    # shellcheck disable=SC2086
    "$A" simulate towering_cumulus $bad_opt -o "$T/x.json" 2>"$T/err"
    [ $? -eq 2 ] && ok "simulate $bad_opt: a usage error" || bad "simulate $bad_opt: not a usage error"
    has "simulate $bad_opt" "Try 'atmos simulate --help'."
done

# --- 10. --atmosphere names every model a scene's "atmosphere": {"model"} may: each renders,
# the spherical ones a different sky from the flat one, and from orbit without the flat-earth note
for m in riley homogeneous dobashi spherical; do
    "$A" render --atmosphere "$m" --width 8 --height 6 --pfm "$T/air_$m.pfm" -q 2>"$T/err" \
        && ok "render --atmosphere $m" || { bad "render --atmosphere $m:"; sed 's/^/  /' "$T/err" >&2; }
done
for m in dobashi spherical; do
    cmp -s "$T/air_riley.pfm" "$T/air_$m.pfm" && bad "--atmosphere $m: the same sky as riley" \
        || ok "--atmosphere $m: its own sky"
done
"$A" render --atmosphere spherical --altitude 400000 --view-elevation -30 --width 8 --height 8 -o "$T/f.png" -q \
    2>"$T/err" || bad "spherical from 400 km"
hasnt "spherical from 400 km" "flat earth"
"$A" render --atmosphere fog --width 8 --height 6 -o "$T/f.png" -q 2>"$T/err"
[ $? -eq 2 ] && ok "--atmosphere fog: a usage error" || bad "--atmosphere fog: not a usage error"
has "--atmosphere fog" "dobashi"
# --thickness goes with the homogeneous layer; with another model it would do nothing
"$A" render --atmosphere spherical --thickness 200 --width 8 --height 6 -o "$T/f.png" -q 2>"$T/err"
[ $? -eq 2 ] && ok "--thickness with spherical: a usage error" || bad "--thickness with spherical: not a usage error"
has "--thickness with spherical" "homogeneous"
"$A" render --atmosphere homogeneous --thickness 200 --width 8 --height 6 -o "$T/f.png" -q 2>"$T/err" \
    && ok "--thickness with homogeneous" || bad "--thickness with homogeneous: $(cat "$T/err")"

# volume generate: a folder where one of its raw files goes is refused before anything is
# written (it had left the other fields' raw files and a staged one, no sidecar)
mkdir -p "$T/gen/g.ice.raw"
"$A" volume generate storm --voxel-size 600 -q -o "$T/gen/g.json" 2>"$T/err"; st=$?  # -q as every command takes it
[ $st -eq 1 ] && grep -q "g.ice.raw: exists and is a folder" "$T/err" && [ "$(ls "$T/gen")" = g.ice.raw ] \
    && ok "generate: a folder in the way" || bad "generate: a folder in the way: exit $st, left $(ls "$T/gen"), $(cat "$T/err")"

# a seed past 2^64 - 1 refused (it had been clamped to 2^64 - 1 without a word)
for c in "simulate stratocumulus --grid 16 --minutes 1" "volume generate cumulus"; do
    "$A" $c --seed 18446744073709551616 -o "$T/seed.json" 2>"$T/err"; st=$?
    [ $st -eq 2 ] && grep -q -- "--seed: expected an integer in \[0, 18446744073709551615\]" "$T/err" && [ ! -e "$T/seed.json" ] \
        && ok "$c --seed 2^64" || bad "$c --seed 2^64: exit $st, $(cat "$T/err")"
done

# volume generate interrupted while it writes: its staged raw files go with it (they had been
# left, hundreds of MB); the signal is sent once the first staged file shows (no signal, and no
# check, when the write is over before it is seen)
mkdir -p "$T/int"
"$A" volume generate storm --voxel-size 40 -o "$T/int/v.json" 2>/dev/null &
pid=$!
n=0
while [ $n -lt 600 ] && kill -0 $pid 2>/dev/null && [ -z "$(ls "$T/int" | grep -F .staged)" ]; do sleep 0.02; n=$((n + 1)); done
if [ -n "$(ls "$T/int" | grep -F .staged)" ] && kill -INT $pid 2>/dev/null; then
    wait $pid
    [ -z "$(ls "$T/int" | grep -F .staged)" ] && ok "generate interrupted: no staged file left" || bad "generate interrupted left: $(ls "$T/int")"
else
    wait $pid
fi

# a hexadecimal number for a real option refused, as for an integer option (it had been read as 16)
"$A" render --sun-elevation 0x10 --width 8 --height 8 -o "$T/hex.png" 2>"$T/err"; st=$?
[ $st -eq 2 ] && grep -q -- "--sun-elevation: expected a finite number, got '0x10'" "$T/err" && ok "--sun-elevation 0x10" ||
    bad "--sun-elevation 0x10: exit $st, $(cat "$T/err")"

exit $fail
