#!/bin/sh
# atmos view's preview while the sun moves (docs/viewer.md, "What a frame costs"): with
# --preview a scripted flight renders as an interactive session does. Frames 1-4 move the sun
# (20 degrees of azimuth): the slice renderer's preview (half resolution, fewer slices, no
# shadows on the air, the diffuse field of the sun before the move). Frame 5 has the sun where
# frame 4 left it: the first still frame, the full render, whose display values equal those of
# `atmos render` of the view saved at frame 8 (every value, not within a level). The last
# preview against that still frame (the same camera and sun) stays within the stated bound,
# and the preview frames are the same on one thread and on two.
. "$(dirname "$0")/common.inc"
DIFF=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}/bench/viewer/pngdiff.py
cd "$T" || exit 1

# a small cumulus in front of the camera, its shadow on the air on (the default), the diffuse
# field on (the default); a Henyey-Greenstein droplet lobe (no Mie tables in a fresh cache)
cat >scene.json <<'JSON'
{"camera": {"type": "pinhole", "position_m": [0, 500, 0], "look_at_m": [0, 1500, -4000], "fov_deg": 50},
 "volume": {"generate": "cumulus", "position_m": [0, 1200, -4000], "voxel_size_m": 150},
 "particles": {"cloud": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.85}], "sigma_ext_m2": 6e-10}},
 "renderer": "slice", "slice": {"slices": 96, "light_size": 64},
 "sun": {"elevation_deg": 30, "azimuth_deg": 150}}
JSON
cat >flight.json <<'JSON'
{"fps": 4, "keys": [{"t": 0, "position_m": [0, 500, 0], "look_at_m": [0, 1500, -4000],
                     "sun": {"elevation_deg": 30, "azimuth_deg": 150}},
                    {"t": 1, "position_m": [0, 500, 0], "look_at_m": [0, 1500, -4000],
                     "sun": {"elevation_deg": 30, "azimuth_deg": 170}},
                    {"t": 2, "position_m": [0, 500, 0], "look_at_m": [0, 1500, -4000],
                     "sun": {"elevation_deg": 30, "azimuth_deg": 170}, "press": "save"}]}
JSON
fly() { # DIR THREADS
    "$A" view scene.json --headless --preview --frames 9 --size 64x48 --script flight.json --record "$1" \
        --save-base "$1/shot" --threads "$2" >"$1.txt" 2>&1
}
fly rec 2
st=$?
[ $st -eq 0 ] && ok "9 frames with --preview, exit 0" || { bad "--preview: exit $st"; cat rec.txt >&2; exit 1; }
p=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "preview") c = i; next } { printf "%s", $c }' rec/frames.csv)
[ "$p" = "011110000" ] && ok "frames 1-4 (the sun moving) are previews, the others full ($p)" ||
    bad "the preview column: '$p', want 011110000"

# the first still frame is the full render: atmos render of the saved view, value for value
"$A" render rec/shot_001.json -o off.png >render.txt 2>&1 || { bad "atmos render of the saved view"; cat render.txt >&2; }
r=$(python3 "$DIFF" rec/frame_00005.png off.png)
echo "$r" | grep -q "identical=1 " && ok "the still frame after the move = atmos render's ($r)" ||
    bad "the still frame after the move differs from atmos render's ($r)"
r=$(python3 "$DIFF" rec/frame_00000.png rec/frame_00004.png)
echo "$r" | grep -q "identical=0 " && ok "the sun moved: frames 0 and 4 differ" || bad "frames 0 and 4: $r"

# the preview's error: frame 4 (the sun at 170 degrees, the field of 150) against the still
# frame 5 (the same view, the full render), in levels of 255: at most 3 on average (measured
# 2.0). At 64 x 48 the half-resolution eye buffer is 32 x 24: at the cloud's edges a pixel may
# take its neighbour's side, so the largest difference is bounded only by half the range
# (measured 98)
r=$(python3 "$DIFF" rec/frame_00004.png rec/frame_00005.png)
m=$(echo "$r" | sed 's/.*mean_difference=\([0-9.]*\).*/\1/')
w=$(echo "$r" | sed 's/.*largest_difference=\([0-9]*\).*/\1/')
if echo "$r" | grep -q "identical=0 " && awk -v m="$m" -v w="$w" 'BEGIN {exit !(m <= 3 && w <= 128)}'; then
    ok "the preview within 3 levels on average and 128 at most of the full render ($r)"
else
    bad "the preview against the full render: $r (want a difference, mean <= 3, largest <= 128)"
fi

# the same frames on one thread
fly rec1 1 || { bad "--threads 1: exit $?"; cat rec1.txt >&2; }
r=$(python3 "$DIFF" rec rec1)
echo "$r" | grep -q "^frames=9 identical=9 " && ok "the same 9 frames on one thread ($r)" || bad "one thread: $r"
exit $fail
