#!/bin/sh
# atmos view --press (docs/viewer.md): the keys act at the second frame, in a window (through
# its event queue) and headless (on the state) alike; script names are accepted as key names;
# a press that cannot act is refused or said, never dropped. And --frames N without a volume
# orbits the camera about the point it looks at (it used to pan in place, away from it).
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1

# headless: I raises the sun by a tap's worth (20 degrees a second for 1/30 s) at frame 1
for k in I sun_up; do
    "$A" view --headless --frames 3 --size 16x9 --press "$k" --record "r_$k" >"$T/o_$k.txt" 2>&1
    st=$?
    python3 - "r_$k/frames.csv" <<'PY' && ok "--headless --press $k: exit $st, the sun 20/30 degrees higher at frame 1" || { bad "--headless --press $k (exit $st)"; cat "$T/o_$k.txt" >&2; }
import csv, sys
r = list(csv.DictReader(open(sys.argv[1])))
e = [float(x["sun_elevation_deg"]) for x in r]
assert len(e) == 3 and abs(e[1] - e[0] - 20.0 / 30) < 1e-3 and e[2] == e[1], e
PY
done

# headless F12: saved at frame 1
"$A" view --headless --frames 2 --size 16x9 --press F12 --save-base hs/v >"$T/o_s.txt" 2>&1
st=$?
[ $st -eq 0 ] && [ -s hs/v_001.json ] && [ -s hs/v_001.exr ] && [ ! -e hs/v_002.json ] &&
    ok "--headless --press F12: one save" || { bad "--headless --press F12 (exit $st)"; cat "$T/o_s.txt" >&2; }

# a session too short for the second frame: refused before any work, with a usage error
"$A" view --headless --frames 1 --size 16x9 --press F12 --save-base one/v >/dev/null 2>"$T/e1.txt"
st=$?
[ $st -eq 2 ] && grep -q "atmos view: --press" "$T/e1.txt" && [ ! -e one ] &&
    ok "--frames 1 --press: exit 2, said" || { bad "--frames 1 --press: exit $st"; cat "$T/e1.txt" >&2; }

# an unknown name: exit 2
"$A" view --headless --frames 2 --size 16x9 --press nope >/dev/null 2>"$T/e2.txt"
st=$?
[ $st -eq 2 ] && grep -q "unknown key" "$T/e2.txt" && ok "--press nope: exit 2" || bad "--press nope: exit $st"

# --frames without a volume: an orbit about the camera's look-at point (the spotlight scene's
# [0, 9, 0]): every frame at the same distance from it, looking at it
cat >orbit.json <<'JSON'
{"camera": {"type": "pinhole", "position_m": [0, 7, 32], "look_at_m": [0, 9, 0], "fov_deg": 55}}
JSON
"$A" view orbit.json --headless --frames 5 --size 16x9 --record orb >"$T/o_o.txt" 2>&1
st=$?
python3 - orb/frames.csv <<'PY' && ok "--frames 5 without a volume orbits the look-at point (exit $st)" || { bad "--frames without a volume (exit $st)"; cat "$T/o_o.txt" >&2; }
import csv, math, sys
r = list(csv.DictReader(open(sys.argv[1])))
assert len(r) == 5, r
c = [0.0, 9.0, 0.0]
d0 = math.dist([0, 7, 32], c)
yaws = set()
for x in r:
    p = [float(x["x_m"]), float(x["y_m"]), float(x["z_m"])]
    assert abs(math.dist(p, c) - d0) < 0.01 * d0, (p, d0)
    yaw, pitch = math.radians(float(x["yaw_deg"])), math.radians(float(x["pitch_deg"]))
    f = [math.cos(pitch) * math.sin(yaw), math.sin(pitch), -math.cos(pitch) * math.cos(yaw)]
    t = [p[i] + math.dist(p, c) * f[i] for i in range(3)]   # where the view points at that distance
    assert math.dist(t, c) < 0.01 * d0, (x, t)
    yaws.add(round(float(x["yaw_deg"])))
assert len(yaws) == 5, yaws   # it does go round
PY

# a sun key on a scene the renderer lights by its lamps only (Dobashi's spotlight, the beam
# renderer without a sun): said, naming the key and why, not taken in silence
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}
"$A" view "$S/scenes/dobashi_fig04_spotlight.json" --headless --frames 2 --size 16x9 --press sun_up,forward \
    --record r_lamp >o_lamp.txt 2>&1
st=$?
[ $st -eq 0 ] && grep -q -- "--press sun_up: changes nothing: the beams renderer lights this scene without the sun" o_lamp.txt &&
    ! grep -q -- "--press forward" o_lamp.txt && ok "--press sun_up on a lamp-only scene: said why (exit $st)" ||
    { bad "--press sun_up on a lamp-only scene (exit $st)"; cat o_lamp.txt >&2; }

# atmos render's outputs, its image size and --mpi are refused, not ignored (the viewer writes
# with F12 and --record, its size is --size)
n=0
for opt in "-o x.png" "--exr x.exr" "--pfm x.pfm" "--width 100" "--height 50"; do
    n=$((n + 1))
    # shellcheck disable=SC2086
    "$A" view --headless --frames 2 --size 16x9 --record "r_opt$n" $opt >o_opt.txt 2>&1
    st=$?
    [ $st -eq 2 ] && grep -q "atmos render's; the viewer's frame is --size WxH" o_opt.txt && [ ! -e x.png ] && [ ! -e x.exr ] &&
        ok "view $opt refused (exit 2)" || { bad "view $opt: exit $st"; cat o_opt.txt >&2; }
done

# --record into missing folders: made, as atmos render's outputs' folders; one that cannot be
# made: said, naming the folder
"$A" view --headless --frames 2 --size 16x9 --record new/sub/rec >o_rec.txt 2>&1 && [ -s new/sub/rec/frames.csv ] &&
    ok "--record new/sub/rec: the folders made" || { bad "--record new/sub/rec"; cat o_rec.txt >&2; }
"$A" view --headless --frames 2 --size 16x9 --record /proc/no/rec >o_rec.txt 2>&1
st=$?
[ $st -eq 1 ] && grep -q "record /proc/no/rec/frames.csv: cannot create the folder /proc/no" o_rec.txt &&
    ok "--record in a folder that cannot be made: said (exit 1)" || { bad "--record /proc/no/rec: exit $st"; cat o_rec.txt >&2; }
# a --record path too long for its frames' names: refused (exit 2), no folder made (it used to be
# cut short, and a folder other than the one named made)
long=long; for i in 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16; do long="$long/$(printf '%0250d' "$i")"; done
long="$long/$(printf '%060d' 17)" # 4081 bytes: its frame_00000.png 4097
"$A" view --headless --frames 2 --size 16x9 --record "$long" >o_long.txt 2>&1
st=$?
[ $st -eq 2 ] && grep -q "record long/0*\.\.\.: the path is too long" o_long.txt && [ ! -e long ] &&
    ok "--record with a path too long: refused (exit 2), nothing made" || { bad "--record too long: exit $st"; head -c 600 o_long.txt >&2; }

# a flight that moves the sun over such a scene: said once
cat >lamp_flight.json <<'EOF2'
{"fps": 24, "keys": [{"t": 0, "position_m": [0, 7, 32], "look_at_m": [0, 3, 0]},
                     {"t": 0.05, "position_m": [0, 7, 30], "look_at_m": [0, 3, 0], "sun": {"elevation_deg": 30, "azimuth_deg": 90}}]}
EOF2
"$A" view "$S/scenes/dobashi_fig04_spotlight.json" --headless --script lamp_flight.json --size 16x9 --record r_lampfl \
    >o_lampfl.txt 2>&1
st=$?
[ $st -eq 0 ] && [ "$(grep -c 'changes nothing' o_lampfl.txt)" -eq 1 ] &&
    grep -q -- "--script lamp_flight.json: the flight's sun: changes nothing: the beams renderer" o_lampfl.txt &&
    ok "a flight's sun on a lamp-only scene: said once (exit $st)" || { bad "a flight's sun on a lamp-only scene (exit $st)"; cat o_lampfl.txt >&2; }
# ... but not when the flight presses R first (the path renderer, lit by the lamp alone, then the
# sky renderer, lit by the sun)
cat >r_flight.json <<'EOF2'
{"fps": 24, "keys": [{"t": 0, "position_m": [0, 7, 32], "look_at_m": [0, 3, 0], "press": "renderer"},
                     {"t": 0.05, "position_m": [0, 7, 30], "look_at_m": [0, 3, 0], "sun": {"elevation_deg": 30, "azimuth_deg": 90}}]}
EOF2
"$A" view "$S/scenes/dobashi_fig04_spotlight.json" --renderer path --spp 1 --headless --script r_flight.json --size 16x9 \
    >o_rfl.txt 2>&1
st=$?
[ $st -eq 0 ] && ! grep -q 'changes nothing' o_rfl.txt && ok "a flight's sun after its R key: not said (exit $st)" ||
    { bad "a flight's sun after its R key (exit $st)"; cat o_rfl.txt >&2; }
exit $fail
