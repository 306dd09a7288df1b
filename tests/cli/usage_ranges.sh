#!/bin/sh
# Every azimuth option takes degrees in [0, 360), as the scene file's azimuth keys do, and says
# so in its --help line: render --sun-azimuth -30 was refused naming the JSON path, while
# render --view-azimuth 400 and sky --sun-azimuth 400 / --view-azimuth -180 were wrapped
# silently. Mistakes in the options are usage errors (exit 2) naming the option: --time-end
# with a sun given by angles, volume generate --scale out of [0.05, 20] (now in volume --help)
# (and render --volume-scale for a generated volume) and simulate --grid/--refine past the voxel
# limit exited 1.
. "$(dirname "$0")/common.inc"
S=${ATMOS_SOURCE_DIR:-.}
usage() { # what the message must say, then the command
    want=$1
    shift
    "$A" "$@" 2>"$T/err" >/dev/null
    rc=$?
    [ $rc -eq 2 ] && grep -q -- "$want" "$T/err" && [ ! -e "$T/x.png" ] && [ ! -e "$T/v.json" ] &&
        ok "$*: exit 2, '$want'" || { bad "$*: exit $rc"; cat "$T/err" >&2; }
}
R="--width 4 --height 4 -q -o $T/x.png"
AZ="expected degrees in \[0, 360)"
usage "--sun-azimuth: $AZ" render --sun-azimuth -30 $R
usage "--sun-azimuth: $AZ" render --sun-azimuth 360 $R
usage "--view-azimuth: $AZ" render --view-azimuth 400 $R
usage "--view-azimuth: $AZ" render --view-azimuth -20 $R
usage "--sun-azimuth-end: $AZ" render --frames 2 --sun-azimuth-end 400 $R
SKY="sky --sun-elevation 30 --view-elevation 10"
usage "--sun-azimuth: $AZ" $SKY --sun-azimuth 400 --view-azimuth 0
usage "--view-azimuth: $AZ" $SKY --sun-azimuth 180 --view-azimuth -180
# the range's ends: 0 and just under 360 are azimuths
"$A" render --sun-azimuth 0 --view-azimuth 359.9 $R 2>"$T/err" && [ -s "$T/x.png" ] &&
    ok "render azimuths 0 and 359.9" || { bad "render azimuths 0 and 359.9"; cat "$T/err" >&2; }
rm -f "$T/x.png"
"$A" $SKY --sun-azimuth 0 --view-azimuth 359.9 >/dev/null 2>"$T/err" && ok "sky azimuths 0 and 359.9" ||
    { bad "sky azimuths 0 and 359.9"; cat "$T/err" >&2; }
# the scene file's keys agree
usage "/sun/azimuth_deg: must be in \[0, 360)" render -D sun.azimuth_deg=400 $R
# each azimuth help line states the range
for cmd in render sky; do
    "$A" $cmd --help >"$T/help"
    for o in --sun-azimuth --view-azimuth; do
        grep -q -- "^ *$o [Aa] .*\[0, 360)" "$T/help" && ok "$cmd --help: $o's range" || bad "$cmd --help: $o has no range"
    done
done
"$A" render --help | grep -q -- "--sun-azimuth-end A .*\[0, 360)" && ok "render --help: --sun-azimuth-end's range" ||
    bad "render --help: --sun-azimuth-end has no range"

# a sun's end in the other form than the sun's
usage "--time-end: needs a sun given by time" render "$S/scenes/dobashi_fig11_sunrise_from_space.json" \
    --time-end 2026-06-21T12:00:00Z $R
usage "--time-end: needs a sun given by time" render --sun-elevation 10 --frames 2 --time-end 2026-06-21T12:00:00Z $R
usage "--sun-elevation-end/--sun-azimuth-end: need a sun given by angles" render --time 2026-06-21T12:00:00Z \
    --lat 40 --lon -105 --frames 2 --sun-elevation-end 10 $R
# volume generate --scale
usage "--scale: expected a factor in \[0.05, 20\], got 1000" volume generate cumulus --scale 1000 -o "$T/v.json"
usage "--volume-scale: expected a factor in \[0.05, 20\], got 0.01" volume generate cumulus --volume-scale 0.01 \
    -o "$T/v.json"
usage "--volume-scale: expected a factor in \[0.05, 20\] for a generated volume, got 50" render \
    --volume generate:cumulus --volume-scale 50 $R
"$A" volume --help | grep -q -- "--scale.*\[0.05, 20\]" && ok "volume --help: --scale's range" ||
    bad "volume --help: --scale has no range"
# simulate past the voxel limit: refused before the run, no folder or file left
usage "--grid 512 --refine 4: refine 4 makes" simulate cumulus_field --grid 512 --refine 4 -q -o "$T/sim/c.json"
[ ! -e "$T/sim" ] && ok "simulate: no folder left" || bad "simulate: $T/sim left"
# a number that is none (nan, a word) is one usage error, said once: the range's message came after
# the parse's as a second error
once() { # the option's name, then the command
    name=$1
    shift
    "$A" "$@" 2>"$T/err" >/dev/null
    rc=$?
    [ $rc -eq 2 ] && [ "$(grep -c "^atmos .*: $name: " "$T/err")" -eq 1 ] && grep -q -- "$name: expected a finite number" "$T/err" &&
        ok "$*: one message" || { bad "$*: exit $rc, not one message"; cat "$T/err" >&2; }
}
once --density-scale render --volume generate:cumulus --density-scale nan $R
once --fov render --fov inf $R
once --thickness render --thickness abc $R
once --voxel-size volume info --voxel-size q "$S/scenes/simulated_cumulus.json"
once --thickness sky --thickness zz -o "$T/x.png"
once --budget bench sky --budget nan
# a volume framed with no camera in a field of view so narrow that the camera would stand beyond the
# scene's 1e8 m: a usage error naming --fov, not the position the framing made
"$A" volume generate cumulus -o "$T/vol/cu.json" --voxel-size 200 >/dev/null || bad "volume generate"
usage "a field of view of 1e-09 degrees puts the camera" render --volume "$T/vol/cu.json" --fov 1e-9 $R
grep -q -- "wider --fov" "$T/err" && ! grep -q "position_m" "$T/err" && ok || bad "--fov 1e-9: $(cat "$T/err")"
exit $fail
