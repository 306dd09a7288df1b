#!/bin/sh
# What a game/flight-sim developer's trial (scene files, the C API, time of day) ran into:
#  1. "particle" on a generated volume names its cloud droplets' type (it was ignored, then
#     refused: Fig. 4's glory scene did not render), on a simulated one it is refused, and an
#     unknown particle name names /volume/particle, as /fog/particle does;
#  2. a day animation with the locked exposure locks on the frame with the highest sun (a
#     night first frame had burnt the day frames white), and an animation's automatic
#     exposure stops at a camera's limit (animation.exposure_limit_ev, EV100 -2): a
#     night frame stays dark, exposed per frame or locked;
#  4. a missing volume file names the scene file and /volume/file, and a relative path of a
#     scene file says it was taken from the scene's folder (not "from the current folder");
#  5. a -D key the scene does not know is said to come from -D; --time's year range is a
#     usage error (2) as its other mistakes; the example slice_volume refuses --sun abc;
#  6. render --help's --lat/--lon give their unit, sign and the years.
. "$(dirname "$0")/common.inc"
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }
hasnt() { grep -qF -- "$2" "$T/err" && { bad "$1: '$2' in:"; sed 's/^/  /' "$T/err" >&2; } || ok "$1: no '$2'"; }

# --- 1. "particle" on a generated volume and an unknown particle on a volume file.
scene() { printf '{"image": {"width": 16, "height": 9}, "volume": %s}\n' "$1" >"$T/s.json"; }
scene '{"generate": "cumulus", "particle": "hail"}'
"$A" render "$T/s.json" -o "$T/x.png" 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && ok "generate + unknown particle refused" || bad "generate + unknown particle: rc $rc"
has "generate + unknown particle" "/volume/particle: 'hail' is neither"
scene '{"generate": "cumulus", "particle": "ice", "voxel_size_m": 400}'
"$A" render "$T/s.json" -o "$T/x.png" -q 2>"$T/err"; rc=$?
[ $rc -eq 0 ] && ok "generate + a known particle renders" || { bad "generate + particle ice: rc $rc"; cat "$T/err" >&2; }
scene '{"simulate": {"preset": "stratocumulus"}, "particle": "ice"}'
"$A" render "$T/s.json" -o "$T/x.png" 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && ok "simulate + particle refused" || bad "simulate + particle: rc $rc"
has "simulate + particle" "\"particle\" does not apply to a simulated volume"
"$A" volume generate cumulus -o "$T/v/v.json" --voxel-size 400 >/dev/null 2>"$T/err" || bad "volume generate"
scene '{"file": "v/v.json", "particle": "hail"}'
"$A" render "$T/s.json" -o "$T/x.png" 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && ok "file + unknown particle refused" || bad "file + unknown particle: rc $rc"
has "file + unknown particle" "/volume/particle"
has "file + unknown particle" "'hail'"

# --- 2. A day in three frames (Munich, midsummer: midnight, noon, midnight) at a tiny size.
day() {
    "$A" render -q --time 2026-06-21T00:00:00+02:00 --time-end 2026-06-22T00:00:00+02:00 --frames 3 \
        --lat 48.1 --lon 11.6 --width 32 --height 18 "$@" 2>"$T/err"
}
day -o "$T/lk/d.png" && ok "day, locked" || { bad "day, locked"; cat "$T/err" >&2; }
day -o "$T/pf/d.png" --exposure-per-frame -D atmosphere.model=spherical && ok "day, per frame" ||
    { bad "day, per frame"; cat "$T/err" >&2; }
day -o "$T/ls/d.png" -D atmosphere.model=spherical && ok "day, spherical, locked" ||
    { bad "day, spherical, locked"; cat "$T/err" >&2; }
"$A" render -q --time 2026-06-21T00:00:00+02:00 --lat 48.1 --lon 11.6 --width 32 --height 18 \
    -D atmosphere.model=spherical -o "$T/night.png" 2>"$T/err" && ok "midnight alone" || bad "midnight alone"
python3 - "$T" <<'PY' && ok "the day's exposures" || bad "the day's exposures"
import sys, png
t = sys.argv[1]
for run in ("lk", "ls", "pf"):
    m = [png.mean("%s/%s/d_%04d.png" % (t, run, k)) for k in (1, 2, 3)]
    w = [png.white("%s/%s/d_%04d.png" % (t, run, k)) for k in (1, 2, 3)]
    print(run, "means", ["%.1f" % v for v in m], "white", ["%.2f" % v for v in w])
    assert w[1] < 0.05, "%s: the noon frame is burnt white (%.0f %% of it)" % (run, 100 * w[1])
    assert 40 < m[1] < 230, "%s: the noon frame's mean %.1f" % (run, m[1])
    # midnight, the sun 18.5 degrees down: dark, at most a faint glow (a night sky, no dusk)
    assert m[0] < 20 and m[2] < 20, "%s: a night frame is not dark: %.1f %.1f" % (run, m[0], m[2])
# a single render keeps its own automatic exposure (the limit is an animation's)
assert png.mean(t + "/night.png") > png.mean(t + "/pf/d_0001.png"), "the single night render is limited too"
PY
printf '{"sun": {"time": "2026-06-21T00:00:00+02:00", "latitude_deg": 48.1, "longitude_deg": 11.6},
 "animation": {"frames": 3, "time_end": "2026-06-22T00:00:00+02:00", "exposure_limit_ev": -20}}\n' >"$T/day.json"
day "$T/day.json" -o "$T/lm/d.png" --exposure-per-frame -D atmosphere.model=spherical &&
    ok "a scene sets the limit" || { bad "animation.exposure_limit_ev"; cat "$T/err" >&2; }
python3 - "$T" <<'PY' && ok "a lower limit: a brighter night" || bad "animation.exposure_limit_ev -20"
import sys, png
t = sys.argv[1]
assert png.mean(t + "/lm/d_0001.png") > 2 * png.mean(t + "/pf/d_0001.png") + 1
PY

# a locked exposure over frames whose sun keeps its height (it turns in azimuth alone): frame
# 1's, not called the highest sun's
printf '{"image": {"width": 16, "height": 9}, "sun": {"elevation_deg": 30, "azimuth_deg": 180},
 "animation": {"frames": 2, "azimuth_end_deg": 200}}\n' >"$T/still.json"
"$A" render "$T/still.json" -o "$T/still/s.png" 2>"$T/err" || bad "a still sun's animation"
has "a still sun's locked exposure" "exposure locked at frame 1's"
hasnt "a still sun's locked exposure" "the highest sun"

# --- 4. A missing volume file, a missing mesh: the scene file, the key, the folder.
mkdir -p "$T/sub"
printf '{"image": {"width": 16, "height": 9}, "volume": {"file": "nope/cloud.vdb"}}\n' >"$T/sub/vol.json"
(cd "$T" && "$A" render sub/vol.json -o x.png 2>"$T/err"); rc=$?
[ $rc -ne 0 ] && ok "missing volume file refused" || bad "missing volume file: rc 0"
has "missing volume file" "sub/vol.json: /volume/file"
has "missing volume file" "(resolved against the scene's folder sub/; the scene wrote nope/cloud.vdb)"
hasnt "missing volume file" "from the current folder"
printf '{"renderer": "beams", "image": {"width": 16, "height": 9}, "fog": {"visibility_m": 300},
 "lights": [{"type": "spot", "position_m": [0, 20, 0], "cone_deg": 14, "intensity_w_sr": 2000}],
 "objects": [{"mesh": "meshes/plane.obj"}]}\n' >"$T/sub/mesh.json"
(cd "$T" && "$A" render sub/mesh.json -o x.png 2>"$T/err"); rc=$?
[ $rc -ne 0 ] && ok "missing mesh refused" || bad "missing mesh: rc 0"
has "missing mesh" "/objects/0/mesh"
has "missing mesh" "(resolved against the scene's folder sub/; the scene wrote meshes/plane.obj)"
hasnt "missing mesh" "from the current folder"
(cd "$T/sub" && "$A" render - -o "$T/x.png" <mesh.json 2>"$T/err"); rc=$?
has "missing mesh, a scene from standard input" "from the current folder"

# --- 5. -D's key, --time's year, slice_volume --sun abc.
printf '{"image": {"width": 16, "height": 9}}\n' >"$T/b.json"
"$A" render "$T/b.json" -D camera.fovv_deg=30 -o "$T/x.png" 2>"$T/err"; rc=$?
[ $rc -ne 0 ] && ok "-D unknown key refused" || bad "-D unknown key accepted"
has "-D unknown key" "-D camera.fovv_deg=30"
has "-D unknown key" "/camera/fovv_deg"
"$A" render -D camera.fovv_deg=30 -o "$T/x.png" 2>"$T/err"
has "-D unknown key, no scene file" "atmos render: -D camera.fovv_deg=30: /camera/fovv_deg"
"$A" render "$T/b.json" -D camera.fov_deg=300 -o "$T/x.png" 2>"$T/err"
has "-D out of range" "-D camera.fov_deg=300"
printf '{"image": {"width": 16, "height": 9}, "camera": {"fovv_deg": 30}}\n' >"$T/c.json"
"$A" render "$T/c.json" -D camera.fov_deg=30 -o "$T/x.png" 2>"$T/err"
hasnt "the file's own unknown key" "-D"
for y in 1700 2300; do
    "$A" render --time $y-06-21T12:00:00Z --lat 48 --lon 11 -o "$T/x.png" 2>"$T/err"; rc=$?
    [ $rc -eq 2 ] && ok "--time year $y: usage error" || bad "--time year $y: rc $rc"
    has "--time year $y" "[1800, 2200]"
done
"$A" render --time 2026-06-21T12:00:00Z --time-end 2300-01-01T00:00:00Z --frames 2 --lat 48 --lon 11 \
    -o "$T/x.png" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && ok "--time-end year 2300: usage error" || bad "--time-end year 2300: rc $rc"
SV=$(dirname "$A")/examples/slice_volume
if [ -x "$SV" ]; then
    (cd "$T" && "$SV" --sun abc --size 8 8 -o "$T/sv.png" 2>"$T/err"); rc=$?
    [ $rc -eq 2 ] && ok "slice_volume --sun abc refused" || bad "slice_volume --sun abc: rc $rc"
    [ ! -f "$T/sv.png" ] && ok "slice_volume --sun abc: no image" || bad "slice_volume --sun abc wrote an image"
fi

# --- 6. render --help: --lat/--lon in degrees, north and east positive, the years.
"$A" render --help >"$T/err"
has "render --help" "degrees north"
has "render --help" "east (south and west negative)"
has "render --help" "1800-2200"
has "render --help" "animation.exposure_limit_ev"
exit $fail
