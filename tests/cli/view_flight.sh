#!/bin/sh
# atmos view --script (docs/viewer.md, "Scripted and headless"): every script name `view --help`
# lists either acts in a flight as its key does (a flight pressing it at frame 1 records what
# `--press` of the same key records) or is refused with the reason; a flight file is checked as
# strictly as a scene file (unknown keys named with the allowed ones, a bad press's value shown,
# a JSON syntax error's line:column, a missing file's system reason before any work); a flight
# without --frames stops at its last key frame (headless, and a window under xvfb-run); frame i
# is at t = i / fps, so --frames D fps + 1 reaches the last key; --size is read as render --width.
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1

# a scene whose sun follows a time and place (the time keys act), and two flights of 1 s at
# 2 fps: one pressing NAME at t = 0.5 (frame 1), one pressing nothing
cat >tod.json <<'JSON'
{"sun": {"time": "2026-06-21T12:00:00+02:00", "latitude_deg": 48.1, "longitude_deg": 11.6}}
JSON
flight() { # $1: the second key's extra members
    printf '{"fps": 2, "keys": [{"t": 0, "position_m": [0, 1000, 2000], "look_at_m": [0, 1500, -4000]},\n'
    printf ' {"t": 0.5, "position_m": [0, 1000, 1000], "look_at_m": [0, 1500, -4000]%s},\n' "$1"
    printf ' {"t": 1, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000]}]}\n'
}
flight "" >plain.json
# the csv without its wall time, the frames' and a save's pixels (their PNGs' IDAT chunks: the
# text chunks hold the frame's wall time) and the files made
digest() {
    cut -d, -f1,3- "$1/frames.csv"; ls "$1"
    python3 - "$1"/*.png <<'PY'
import struct, sys, zlib
for name in sys.argv[1:]:
    b, i, data = open(name, "rb").read(), 8, b""
    while i < len(b):
        n, kind = struct.unpack(">I4s", b[i:i + 8])
        data += b[i + 8:i + 8 + n] if kind == b"IDAT" else b""
        i += 12 + n
    print(name.split("/")[-1], zlib.crc32(zlib.decompress(data)))
PY
}

names=$("$A" view --help | sed -n '/^Script names of the keys/,/^[^ ]/p' | grep -E '^  [a-z_]+(, [a-z_]+)*,?$' |
    tr ',' ' ')
[ "$(echo $names | wc -w)" -ge 20 ] && ok "view --help lists $(echo $names | wc -w) script names" ||
    bad "view --help's script names: '$names'"
acted=0 refused=0
for n in $names; do
    flight ", \"press\": \"$n\"" >"f_$n.json"
    "$A" view tod.json --headless --script "f_$n.json" --frames 3 --size 16x9 --record "s_$n" \
        --save-base "s_$n/v" >"o_s_$n.txt" 2>&1
    st=$?
    if [ $st -eq 2 ] && grep -q "/keys/1/press: \"$n\" cannot act in a flight" "o_s_$n.txt"; then
        case $n in forward|back|left|right|up|down|look_*|orbit) refused=$((refused + 1)) ;;
            *) bad "press $n refused"; cat "o_s_$n.txt" >&2 ;; esac
        continue
    fi
    "$A" view tod.json --headless --script plain.json --frames 3 --size 16x9 --press "$n" --record "p_$n" \
        --save-base "p_$n/v" >"o_p_$n.txt" 2>&1
    [ $st -eq 0 ] && [ "$(digest "s_$n")" = "$(digest "p_$n")" ] && acted=$((acted + 1)) ||
        { bad "\"press\": \"$n\" in a flight (exit $st) does not do what --press $n does"; cat "o_s_$n.txt" >&2; }
done
[ $refused -eq 11 ] && ok "$acted names act in a flight as their keys do; the camera's $refused are refused" ||
    bad "$refused names refused (expected the camera's 11)"

# the sun's keys act (not a no-op): sun_up raises the sun by a tap's 20/30 degree at frame 1
python3 - s_sun_up/frames.csv <<'PY' && ok "\"press\": \"sun_up\" raises the sun 2/3 degree" || bad "sun_up in a flight"
import csv, sys
e = [float(r["sun_elevation_deg"]) for r in csv.DictReader(open(sys.argv[1]))]
assert len(e) == 3 and abs(e[1] - e[0] - 20.0 / 30) < 1e-3 and e[2] == e[1], e
PY
# a flight whose key frames set the sun: its sun's and time's keys are refused, with the reason
flight ', "press": "sun_up", "sun": {"elevation_deg": 20, "azimuth_deg": 200}' >sunkeyed.json
"$A" view --headless --script sunkeyed.json --frames 3 --size 16x9 >/dev/null 2>e_sk.txt
[ $? -eq 2 ] && grep -q '"sun_up" cannot act in a flight: its key frames set the sun' e_sk.txt &&
    ok "sun_up with key frames that set the sun: refused" || { bad "sun-keyed sun_up"; cat e_sk.txt >&2; }
# the time's keys in a scene without a time: refused before the renderer is prepared
"$A" view --headless --script f_time_forward.json --frames 3 --size 16x9 >/dev/null 2>e_tf.txt
[ $? -eq 2 ] && grep -q '/keys/1/press: "time_forward" needs a scene whose sun follows a date' e_tf.txt &&
    ! grep -q preparing e_tf.txt && ok "time_forward without a time: refused before any work" ||
    { bad "time_forward without a time"; cat e_tf.txt >&2; }

# strict flight files: each mistake exit 2, named by its JSON pointer, as a scene's
check() { # $1: file, $2: the text expected in the message
    "$A" view --headless --script "$1" --frames 3 --size 16x9 >/dev/null 2>"e_$1.txt"
    st=$?
    [ $st -eq 2 ] && grep -qF -- "$2" "e_$1.txt" && ! grep -q preparing "e_$1.txt" && ok "$1: $2" ||
        { bad "$1 (exit $st), expected: $2"; cat "e_$1.txt" >&2; }
}
sed 's/"fps"/"fsp"/' plain.json >fsp.json
check fsp.json "fsp.json: /fsp: unknown key (allowed: fps, keys)"
sed 's/}]}$/}], "speed": 2}/' plain.json >speed.json
check speed.json "/speed: unknown key (allowed: fps, keys)"
flight ', "fov_deg": 30' >fov.json
check fov.json "/keys/1/fov_deg: unknown key (allowed: t, position_m, look_at_m, sun, press)"
sed '2s/look_at_m/lookat_m/' plain.json >lookat.json
check lookat.json "/keys/1/lookat_m: unknown key"
flight ', "press": "sun_upp"' >upp.json
check upp.json '/keys/1/press: must be one of sun_up, sun_down, sun_left, sun_right, time_back'
check upp.json 'got "sun_upp"'
flight ', "sun": {"elevation": 20, "azimuth_deg": 200}' >sunkey.json
check sunkey.json "/keys/1/sun/elevation: unknown key (allowed: elevation_deg, azimuth_deg)"
flight ', "press": "save", "press": "quit"' >dup.json
check dup.json "/keys/1/press: duplicate key"
# a missing comma at line 2 (after the first key's "t": 0): the scene reader's message and position
sed '1s/"t": 0,/"t": 0/' plain.json >syntax.json
col=$(python3 -c 'import sys; l = open(sys.argv[1]).read().split("\n")[0]; print(l.index("\"t\": 0") + 8)' syntax.json)
check syntax.json "syntax.json:1:$col: malformed JSON near '\"position_m\""
head -c 60 plain.json >cut.json
check cut.json "cut.json:1:61: malformed JSON: unexpected end of input"
# a key whose camera looks at its own position: refused as the scene reader refuses it
printf '{"keys": [{"t": 0, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000]},\n {"t": 0.5, "position_m": [0, 5, 0], "look_at_m": [0, 5, 0]}]}\n' >same.json
check same.json "same.json: /keys/1/look_at_m: must differ from position_m"
# a negative time: refused (frame i is at t = i / fps >= 0; such a flight would never end)
printf '{"keys": [{"t": -5, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000]}]}\n' >neg.json
check neg.json "/keys/0/t: must be >= 0, got -5"
# a missing file: the system's reason, before the scene or the renderer is prepared (exit 1)
"$A" view --headless --script nope.json --frames 3 --size 16x9 >/dev/null 2>e_nope.txt
[ $? -eq 1 ] && grep -q "atmos view: --script nope.json: cannot open: No such file or directory" e_nope.txt &&
    ! grep -q preparing e_nope.txt && ok "a missing flight: its reason, before any work (exit 1)" ||
    { bad "a missing flight"; cat e_nope.txt >&2; }

# keys without "sun" between keys with one: the sun interpolated between the keys that give one
# (the azimuth along the shorter arc, through north), held before the first and after the last
printf '{"fps": 4, "keys": [{"t": 0, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000]},
 {"t": 0.25, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000], "sun": {"elevation_deg": 10, "azimuth_deg": 350}},
 {"t": 0.5, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000]},
 {"t": 0.75, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000], "sun": {"elevation_deg": 30, "azimuth_deg": 30}},
 {"t": 1, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000]}]}\n' >mixed.json
"$A" view --headless --script mixed.json --size 16x9 --record mx >o_mx.txt 2>&1 &&
python3 - mx/frames.csv <<'PY' && ok "keys without a sun: interpolated between the keys with one, held outside" ||
import csv, sys
r = [(float(x["sun_elevation_deg"]), float(x["sun_azimuth_deg"])) for x in csv.DictReader(open(sys.argv[1]))]
want = [(10, 350), (10, 350), (20, 10), (30, 30), (30, 30)]
assert len(r) == 5 and all(abs(a - c) < 1e-3 and abs(b - d) < 1e-3 for (a, b), (c, d) in zip(r, want)), r
PY
    { bad "keys without a sun among keys with one"; cat o_mx.txt mx/frames.csv >&2; }

# without --frames a flight stops at its last key frame: 1 s at 2 fps is 3 frames (t = 0, 0.5, 1),
# the last at the last key's camera; 1.2 s at 2 fps is 4 (t = 1.5 holds the last key)
last_at() { # $1: folder, $2: frames, $3: z of the last key
    python3 - "$1/frames.csv" "$2" "$3" <<'PY'
import csv, sys
r = list(csv.DictReader(open(sys.argv[1])))
assert len(r) == int(sys.argv[2]), len(r)
assert abs(float(r[-1]["z_m"]) - float(sys.argv[3])) < 1e-3 and float(r[-2]["z_m"]) > float(sys.argv[3]), r[-2:]
PY
}
timeout 120 "$A" view --headless --script plain.json --size 16x9 --record nf >o_nf.txt 2>&1
st=$?
[ $st -eq 0 ] && last_at nf 3 0 && ok "--headless --script without --frames: 3 frames, the last at the last key" ||
    { bad "--headless --script without --frames (exit $st)"; cat o_nf.txt >&2; }
sed 's/"t": 1,/"t": 1.2,/' plain.json >long.json
timeout 120 "$A" view --headless --script long.json --size 16x9 --record nl >o_nl.txt 2>&1
[ $? -eq 0 ] && last_at nl 4 0 && ok "a 1.2 s flight at 2 fps: 4 frames" || { bad "1.2 s flight"; cat o_nl.txt >&2; }
# --frames D fps + 1 = 3 reaches the last key; --frames D fps = 2 stops at t = 0.5
"$A" view --headless --script plain.json --frames 3 --size 16x9 --record f3 >/dev/null 2>&1 && last_at f3 3 0 &&
    "$A" view --headless --script plain.json --frames 2 --size 16x9 --record f2 >/dev/null 2>&1 && last_at f2 2 1000 &&
    ok "--frames D fps + 1 ends at the last key (frame i at t = i / fps)" || bad "--frames and the last key"
if command -v xvfb-run >/dev/null 2>&1; then
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
    timeout 60 xvfb-run -a "$A" view --script plain.json --size 16x9 --record win >o_win.txt 2>&1
    st=$?
    [ $st -eq 0 ] && last_at win 3 0 && ok "a window without --frames closes after the last key frame" ||
        { bad "a window's flight without --frames (exit $st)"; cat o_win.txt >&2; }
else
    ok "skipped: the window's flight (no xvfb-run; scripts/install-deps.sh installs xvfb and xauth)"
fi

# --size: each number read as render --width's
for s in 64x36junk 64x x36 64 0x9 16x8193; do
    "$A" view --size "$s" --headless --frames 1 >/dev/null 2>"e_size.txt"
    st=$?
    [ $st -eq 2 ] && grep -q "atmos view: --size" e_size.txt && ok "--size $s: exit 2" ||
        { bad "--size $s: exit $st"; cat e_size.txt >&2; }
done
grep -qF "expected an integer in [1, 8192], got '36junk'" e_size.txt 2>/dev/null ||
    "$A" view --size 64x36junk --headless --frames 1 2>&1 | grep -qF "expected an integer in [1, 8192], got '36junk'" &&
    ok "--size 64x36junk: the message of render --width's" || bad "--size 64x36junk's message"
exit $fail
