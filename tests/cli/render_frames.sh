#!/bin/sh
# atmos render --frames: animations with the sun moving. Numbered outputs (PNG, PFM), each
# frame identical to a single render with that frame's sun (angles and time), a scene's
# "animation" section, the volume renderer across frames, usage errors, and an interrupted
# run that leaves only whole files.
set -u
A=${ATMOS_CLI:?ATMOS_CLI not set}
T=${ATMOS_TEST_TMP:-/tmp}/cli_frames.$$
mkdir -p "$T/a" "$T/b" "$T/c"
export XDG_CACHE_HOME="$T/cache"
fail=0; pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*" >&2; fail=$((fail + 1)); }

# 1. The sky, sun by angles: 3 frames from 20 deg / 240 deg to 2 deg / 260 deg.
"$A" render -q --width 32 --height 18 --sun-elevation 20 --sun-azimuth 240 --frames 3 \
    --sun-elevation-end 2 --sun-azimuth-end 260 -o "$T/a/sky.png" --pfm "$T/a/sky.pfm" && ok || bad "angle animation"
for i in 1 2 3; do
    [ -s "$T/a/sky_000$i.png" ] && [ -s "$T/a/sky_000$i.pfm" ] && ok || bad "frame $i missing"
done
[ ! -e "$T/a/sky_0004.png" ] && [ ! -e "$T/a/sky.png" ] && ok || bad "unexpected outputs: $(ls "$T/a")"
"$A" render -q --width 32 --height 18 --sun-elevation 11 --sun-azimuth 250 --pfm "$T/a/mid.pfm" && ok || bad "single render"
cmp -s "$T/a/sky_0002.pfm" "$T/a/mid.pfm" && ok || bad "frame 2 is not the render with the halfway sun (11 / 250)"
cmp -s "$T/a/sky_0001.pfm" "$T/a/sky_0003.pfm" && bad "first and last frames are identical" || ok

# 2. A scene with an "animation" (sun by time) and a volume: the slice renderer builds its
# optics once; an analytic particle named "cloud" replaces the preset so no Mie table is built.
cat > "$T/b/scene.json" <<'EOF'
{
  "image": {"width": 48, "height": 27},
  "camera": {"type": "pinhole", "position_m": [0, 1500, 3000], "look_at_m": [0, 1600, 0], "fov_deg": 40},
  "sun": {"time": "2026-06-21T13:00:00Z", "latitude_deg": 40, "longitude_deg": -105},
  "particles": {"cloud": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.8}], "sigma_ext_m2": 6.28e-10}},
  "renderer": "slice",
  "volume": {"generate": "cumulus", "position_m": [0, 980, 0]},
  "slice": {"slices": 32, "light_size": 64},
  "animation": {"frames": 3, "time_end": "2026-06-21T15:00:00Z"}
}
EOF
"$A" render "$T/b/scene.json" --pfm "$T/b/cu.pfm" 2> "$T/b/log" && ok || { bad "scene animation"; cat "$T/b/log" >&2; }
grep -q "frame 1/3" "$T/b/log" && grep -q "frame 3/3" "$T/b/log" && ok || bad "no per-frame progress lines"
grep -q "3 frames" "$T/b/log" && ok || bad "no summary line"
[ -s "$T/b/cu_0001.pfm" ] && [ -s "$T/b/cu_0003.pfm" ] && ok || bad "scene frames missing"
"$A" render -q "$T/b/scene.json" --frames 1 --time 2026-06-21T14:00:00Z --lat 40 --lon -105 --pfm "$T/b/one.pfm" \
    && ok || bad "single frame at 14:00"
[ -s "$T/b/one.pfm" ] && ok || bad "--frames 1 should write the name as given"
cmp -s "$T/b/cu_0002.pfm" "$T/b/one.pfm" && ok || bad "frame 2 is not the render at 14:00"
# --time-end overrides the scene's end.
"$A" render -q "$T/b/scene.json" --frames 2 --time-end 2026-06-21T14:00:00Z --pfm "$T/b/ov.pfm" && ok || bad "--time-end"
cmp -s "$T/b/ov_0002.pfm" "$T/b/one.pfm" && ok || bad "--time-end 14:00: last frame differs from the render at 14:00"

# 3. Errors.
"$A" render -q --time-end 2026-06-21T14:00:00Z -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--time-end without --frames should exit 2"
"$A" render -q --frames 2 --time-end 2026-06-21T14:00:00Z -o "$T/x.png" 2> "$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--time-end: needs a sun given by time" "$T/err" && ok || bad "--time-end with an angle sun: rc $rc, $(cat "$T/err")"
"$A" render -q --frames 2 -o "$T/x.png" 2> "$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "need an end" "$T/err" && ok || bad "--frames 2 without an end: rc $rc, $(cat "$T/err")"
"$A" render -q --frames 0 -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--frames 0 should exit 2"
"$A" render -q --frames 2 --time-end 2026-02-30T00:00:00Z --time 2026-06-21T12:00:00Z --lat 0 --lon 0 -o "$T/x.png" 2>/dev/null
[ $? -eq 2 ] && ok || bad "an impossible --time-end should exit 2"
[ -z "$(ls "$T" | grep '^x')" ] && ok || bad "a failed run wrote $(ls "$T" | grep '^x')"

# 4. Interrupted: SIGINT during a long animation, once frame 2 is made, leaves no frame (an
# animation's files go in place together when every frame is made) and no temporaries.
"$A" render --width 320 --height 180 --spp 4 --frames 400 --sun-elevation-end 80 -o "$T/c/f.png" 2>"$T/c.err" &
pid=$!
n=0
while ! grep -q "made .*f_0002.png" "$T/c.err" && [ $n -lt 600 ] && kill -0 $pid 2>/dev/null; do
    sleep 0.05; n=$((n + 1))
done
grep -q "made .*f_0002.png" "$T/c.err" && ok || bad "frame 2 was never reported made: nothing interrupted"
kill -INT $pid 2>/dev/null
wait $pid; rc=$?
[ $rc -ne 0 ] && ok || bad "an interrupted run should fail (rc $rc)"
[ -z "$(ls "$T/c" | grep tmp)" ] && ok || bad "temporaries left: $(ls "$T/c" | grep tmp)"
[ -z "$(ls "$T/c" | grep '^f_')" ] && ok || bad "frames put in place by an interrupted run: $(ls "$T/c" | head -3)"
python3 - "$T/c" <<'PY' && ok || bad "a frame file is not a whole PNG"
import os, sys
d = sys.argv[1]
for f in os.listdir(d):
    b = open(os.path.join(d, f), "rb").read()
    assert b[:8] == b"\x89PNG\r\n\x1a\n" and b[-12:-4] == b"\x00\x00\x00\x00IEND", f
PY

# A later frame's output that cannot be written (a folder by its name) fails before any frame
# is rendered: nothing written.
mkdir -p "$T/late/f_0003.png"
"$A" render --width 16 --height 8 --frames 4 --sun-elevation 5 --sun-elevation-end 20 -q -o "$T/late/f.png" \
    2>"$T/late.err"
st=$?
if [ $st -eq 1 ] && grep -q "frame 3" "$T/late.err" && [ ! -e "$T/late/f_0001.png" ]; then ok; else
    bad "a later frame's bad output: exit $st, $(cat "$T/late.err")"; fi

rm -rf "$T"
echo "render_frames: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
