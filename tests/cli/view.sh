#!/bin/sh
# atmos view (tools/view/, docs/viewer.md): the help lists every key; a headless scripted
# run records N frames (PNG + frames.csv with the documented columns); under Xvfb the
# window opens and closes cleanly, keys pushed through the window's event queue move the
# sun and the camera by the documented amounts (I: 20 degrees a second, W: the flight
# speed, a tap = 1/30 s), F12 saves EXR + PNG + a scene whose offline render (atmos render)
# has the same pixels; bad input is a usage error, not a crash.
set -u
A=${ATMOS_CLI:?ATMOS_CLI not set}
T=${ATMOS_TEST_TMP:-/tmp}/view.$$
rm -rf "$T"
mkdir -p "$T" || exit 1
trap 'rm -rf "$T"' EXIT
export XDG_CACHE_HOME="$T/cache"
fail=0
ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }

"$A" view --help >"$T/help.txt" 2>&1 || bad "view --help exits 0"
for k in W S A D E Q Left Right Up Down I K J L '\[' '\]' Z X = - O R V H F12 P Esc; do
    grep -q "^  $k " "$T/help.txt" || bad "help lists key $k"
done
ok "help lists the keys"

# headless, scripted (an orbit: the default scene's camera about the point it looks at)
"$A" view --headless --frames 3 --size 64x36 --record "$T/rec" >"$T/out.txt" 2>&1 || { bad "headless run"; cat "$T/out.txt" >&2; }
python3 - "$T/rec" <<'PY' && ok "headless record: 3 frames, csv columns" || bad "headless record"
import csv, os, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(d, "frames.csv"))))
assert len(rows) == 3, rows
for i, r in enumerate(rows):
    assert int(r["frame"]) == i and float(r["ms"]) > 0 and r["renderer"] == "sky" and r["impostor_updates"] == "0", r
    assert os.path.getsize(os.path.join(d, "frame_%05d.png" % i)) > 100
yaw = [float(r["yaw_deg"]) for r in rows]
assert abs((yaw[1] - yaw[0]) % 360 - 120) < 1e-6 and abs((yaw[2] - yaw[1]) % 360 - 120) < 1e-6, yaw
PY

# -q: no "preparing the ... renderer" line (it is said without -q)
"$A" view --headless --frames 1 --size 16x9 -q >"$T/q.txt" 2>&1 && ! grep -q "preparing" "$T/q.txt" &&
    grep -q "preparing the sky renderer" "$T/out.txt" && ok "-q: no preparing line" ||
    { bad "-q still says what it prepares"; cat "$T/q.txt" "$T/out.txt" >&2; }

# a second recording into the same folder is refused (its 2 frames would leave the first run's
# frame_00002.png among them), the earlier recording left as it was
"$A" view --headless --frames 2 --size 64x36 --record "$T/rec" >"$T/again.txt" 2>&1
st=$?
[ $st -eq 2 ] && grep -q "record .*rec: the folder holds an earlier recording" "$T/again.txt" &&
    [ "$(tail -n +2 "$T/rec/frames.csv" | wc -l)" -eq 3 ] && [ -s "$T/rec/frame_00002.png" ] &&
    ok "--record into a folder with an earlier recording: refused (exit 2), the recording kept" ||
    { bad "--record into an earlier recording: exit $st"; cat "$T/again.txt" >&2; }
mkdir -p "$T/other" && : >"$T/other/notes.txt" && : >"$T/other/frame.png"
# --record naming a file is refused before the renderer is prepared (no frame tried)
: >"$T/afile"
"$A" view --headless --frames 1 --size 32x18 --record "$T/afile" >"$T/file.txt" 2>&1
st=$?
[ $st -eq 2 ] && grep -q "record .*afile: not a folder" "$T/file.txt" && ! grep -q "frames.csv\|preparing" "$T/file.txt" &&
    [ ! -s "$T/afile" ] && ok "--record FILE: refused (exit 2) before a frame" ||
    { bad "--record FILE: exit $st"; cat "$T/file.txt" >&2; }
"$A" view --headless --frames 1 --size 32x18 --record "$T/other" >"$T/other.txt" 2>&1 && [ -s "$T/other/frame_00000.png" ] &&
    [ -f "$T/other/notes.txt" ] && ok "--record into a folder with other files: recorded, the files kept" ||
    { bad "--record into a folder with other files"; cat "$T/other.txt" >&2; }

# off a terminal the progress log speaks while a plan is made, not for each frame's renders (a log
# line every interval: 0 logs every report)
ATMOS_PROGRESS_INTERVAL=0 "$A" view --headless --frames 3 --size 32x18 >/dev/null 2>"$T/plog.txt"
[ $? -eq 0 ] && ! grep -q "^atmos: render sky:" "$T/plog.txt" && ok "no progress log for the frames' renders" ||
    { bad "frames' renders logged off a terminal"; cat "$T/plog.txt" >&2; }
# (a small cloud of analytic particles: the droplets' Mie table took 20 s under the sanitizers)
printf '%s' '{"particles": {"cloud": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.85, "weight": 1}],
  "sigma_ext_m2": 2e-9, "albedo": 0.99}}, "volume": {"generate": "cumulus", "scale": 0.3}, "renderer": "harris"}' >"$T/hg.json"
ATMOS_PROGRESS_INTERVAL=0 "$A" view "$T/hg.json" --headless --frames 2 --size 16x9 >/dev/null 2>"$T/plog2.txt"
[ $? -eq 0 ] && grep -q "^atmos: phase cloud:" "$T/plog2.txt" && ok "the plan's making logged off a terminal" ||
    { bad "no progress log for the plan's making"; cat "$T/plog2.txt" >&2; }

# bad input: usage errors with a message
"$A" view --headless >/dev/null 2>"$T/e1.txt"; [ $? -eq 2 ] && grep -q "needs --frames N or --script" "$T/e1.txt" && ok "--headless alone refused" || bad "--headless alone"
"$A" view --frames 2 --headless --press Nope >/dev/null 2>"$T/e2.txt"; [ $? -eq 2 ] && grep -q "unknown key" "$T/e2.txt" && ok "unknown key refused" || bad "unknown key"
printf '{"keys": [{"t": 0, "position_m": [0, 1]}]}' >"$T/bad.json"
"$A" view --frames 2 --headless --script "$T/bad.json" >/dev/null 2>"$T/e3.txt"; [ $? -eq 2 ] && grep -q "/keys/0/position_m: expected an array of 3" "$T/e3.txt" && ok "bad script refused" || bad "bad script"

if ! command -v xvfb-run >/dev/null 2>&1; then
    bad "xvfb-run is missing (scripts/install-deps.sh installs xvfb and xauth)"
    exit 1
fi
cd "$T" || exit 1
# Under the sanitizer build (ctest asan.cli_view) leaks are checked in the headless runs above
# only: the window's system libraries (X11, GL) are loaded and unloaded by SDL2 and leave
# allocations LeakSanitizer cannot attribute; memory errors are still fatal here.
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
xvfb-run -a "$A" view --frames 3 --size 96x54 --record "$T/win" --press I,W,F12 --save-base "$T/shot" >"$T/xout.txt" 2>&1
st=$?
[ $st -eq 0 ] && ok "window opens, renders 3 frames, closes (exit 0)" || { bad "xvfb run: exit $st"; cat "$T/xout.txt" >&2; }
# (the status is atmos's own, written by the shell inside xvfb-run: atmos refuses before its
# window opens, and xvfb-run may then fail to clean up after its just-started server, exit 5)
rm -f "$T/xagain.st"
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" T_ST="$T/xagain.st" \
xvfb-run -a sh -c '"$0" "$@"; echo $? >"$T_ST"' "$A" view --frames 2 --size 96x54 --record "$T/win" \
    >"$T/xagain.txt" 2>&1
st=$(cat "$T/xagain.st" 2>/dev/null || echo none)
[ "$st" = 2 ] && grep -q "earlier recording (frame" "$T/xagain.txt" &&
    [ "$(tail -n +2 "$T/win/frames.csv" | wc -l)" -eq 3 ] && ok "in a window too, --record into an earlier recording is refused" ||
    { bad "xvfb: --record into an earlier recording: exit $st"; cat "$T/xagain.txt" >&2; }
python3 - "$T/win/frames.csv" <<'PY' && ok "keys move the sun and the camera as documented" || bad "keys"
import csv, math, sys
r = list(csv.DictReader(open(sys.argv[1])))
assert len(r) == 3, r
f = lambda i, k: float(r[i][k])
assert abs(f(1, "sun_elevation_deg") - f(0, "sun_elevation_deg") - 20.0 / 30) < 1e-3, r   # I: 20 deg/s, a tap
assert f(2, "sun_elevation_deg") == f(1, "sun_elevation_deg")
# W: the default scene's 100 m/s (a tenth of 1 km), a tap, towards the point the default camera
# looks at (1 km ahead of it), about which --frames orbits at a constant distance
y, p = math.radians(f(0, "yaw_deg")), math.radians(f(0, "pitch_deg"))
ahead = [math.cos(p) * math.sin(y), math.sin(p), -math.cos(p) * math.cos(y)]
c = [f(0, k) + 1000.0 * ahead[i] for i, k in enumerate(["x_m", "y_m", "z_m"])]
d = [math.dist([f(i, "x_m"), f(i, "y_m"), f(i, "z_m")], c) for i in range(3)]
assert abs(d[0] - 1000.0) < 1e-2 and abs(d[0] - d[1] - 100.0 / 30) < 1e-2 and abs(d[2] - d[1]) < 1e-2, d
PY
if [ -f "$T/shot_001.json" ] && [ -f "$T/shot_001.exr" ] && [ -f "$T/shot_001.png" ]; then
    ok "F12 saved EXR, PNG and JSON"
    "$A" render "$T/shot_001.json" --exr "$T/off.exr" -o "$T/off.png" >/dev/null 2>&1 || bad "offline render of the saved scene"
    "$A" compare "$T/shot_001.exr" "$T/off.exr" --json >"$T/cmp.json" 2>&1 || bad "compare"
    python3 - "$T/cmp.json" "$T/shot_001.png" "$T/off.png" <<'PY' && ok "saved frame = offline render (EXR and PNG pixels)" || bad "saved frame differs from the offline render"
import json, struct, sys, zlib
c = json.load(open(sys.argv[1]))
assert c["rmse"] == 0 and c["nonfinite"] == 0, c
def pixels(p):
    d = open(p, "rb").read(); i = 8; idat = b""
    while i < len(d):
        n, = struct.unpack(">I", d[i:i + 4]); t = d[i + 4:i + 8]
        if t == b"IDAT": idat += d[i + 8:i + 8 + n]
        if t == b"IHDR": hdr = d[i + 8:i + 8 + n]
        i += 12 + n
    return hdr, zlib.decompress(idat)
assert pixels(sys.argv[2]) == pixels(sys.argv[3])
PY
else
    bad "F12 saved EXR, PNG and JSON"
fi

# the eye inside a cumulus of Harris's renderer: the viewer's frames draw the cloud's near
# particles in coarser layers (--screen-layer-px; 2 pixels so that they are used at this size),
# a save (F12) at full quality: the offline render of the saved scene has the same pixels (its
# droplets analytic, as above)
python3 - "$ATMOS_SOURCE_DIR/scenes/harris_fly_through.json" "$T/inside.json" "$T/hg.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["particles"] = json.load(open(sys.argv[3]))["particles"]
s["camera"] = {"type": "pinhole", "position_m": [0, 1700, 0], "look_at_m": [2000, 1750, 0], "fov_deg": 60}
s["harris"]["sky_lights"] = 0
json.dump(s, open(sys.argv[2], "w"))
PY
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
xvfb-run -a "$A" view "$T/inside.json" --frames 2 --size 160x90 --screen-layer-px 2 --press F12 \
    --save-base "$T/in" >"$T/inout.txt" 2>&1 || { bad "inside the cumulus: exit $?"; cat "$T/inout.txt" >&2; }
if [ -f "$T/in_001.json" ] && [ -f "$T/in_001.exr" ]; then
    "$A" render "$T/in_001.json" --exr "$T/inoff.exr" >/dev/null 2>&1 || bad "offline render of the saved inside scene"
    "$A" compare "$T/in_001.exr" "$T/inoff.exr" --json >"$T/incmp.json" 2>&1 || bad "compare inside"
    python3 -c 'import json, sys; c = json.load(open(sys.argv[1])); assert c["rmse"] == 0 and c["nonfinite"] == 0, c' \
        "$T/incmp.json" && ok "inside a cumulus: saved frame = offline render (EXR pixels)" ||
        bad "inside a cumulus: the saved frame differs from the offline render"
else
    bad "inside a cumulus: F12 saved no EXR and JSON"
fi

# a sun key after R, in a window (where --press only queues the keys): judged by the renderer R
# gives, not the one at the start (the spotlight scene without a volume: the path renderer, lit
# by its lamp without the sun, then R: the sky renderer, lit by the sun); before R it is said
S="$ATMOS_SOURCE_DIR/scenes/dobashi_fig04_spotlight.json"
for keys in R,sun_up sun_up,R; do
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
    xvfb-run -a "$A" view "$S" --renderer path --spp 1 --frames 2 --size 16x9 --press "$keys" >"$T/rk.txt" 2>&1 ||
        { bad "--press $keys in a window: exit $?"; cat "$T/rk.txt" >&2; }
    n=$(grep -c -- "--press sun_up: changes nothing: the path renderer" "$T/rk.txt")
    [ "$keys" = R,sun_up ] && want=0 || want=1
    [ "$n" -eq "$want" ] && ok "--press $keys in a window: 'changes nothing' said $want time(s)" ||
        { bad "--press $keys in a window: 'changes nothing' said $n times"; cat "$T/rk.txt" >&2; }
done
exit $fail
