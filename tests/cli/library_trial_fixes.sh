#!/bin/sh
# What a trial of the library, the sky models and Harris's renderer found in the CLI:
#  1. atmos sky --altitude takes what a scene's camera y takes, [0, 1e8] m (it took 2e8,
#     which atmos render refuses);
#  2. a round model with "aerosol": "none" warns that turbidity and visibility_km set nothing
#     (as the flat models warn about the keys they do not read); without them, no warning;
#  3. Harris's --spacing is made of whole voxels: a spacing under the voxel, or not a multiple
#     of it, says what the cells are; a multiple (and 0, the automatic spacing) says nothing.
. "$(dirname "$0")/common.inc"
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }
hasnt() { grep -qF -- "$2" "$T/err" && { bad "$1: '$2' in:"; sed 's/^/  /' "$T/err" >&2; } || ok "$1: no '$2'"; }

# --- 1
"$A" sky --sun-elevation 10 --view-elevation 0 --view-azimuth 0 --altitude 2e8 >/dev/null 2>"$T/err"
[ $? -eq 2 ] && ok "sky --altitude 2e8 is a usage error" || bad "sky --altitude 2e8 accepted"
has "sky --altitude 2e8" "must be in [0, 100000000]"
"$A" sky --sun-elevation 10 --view-elevation -90 --view-azimuth 0 --altitude 1e8 --model riley >/dev/null 2>"$T/err" \
    && ok "sky --altitude 1e8 (the bound) answers" || { bad "sky --altitude 1e8:"; cat "$T/err" >&2; }

# --- 2
small="--width 8 --height 6 -D atmosphere.model=dobashi -D atmosphere.aerosol=none"
# shellcheck disable=SC2086
"$A" render $small -D atmosphere.turbidity=5 -D atmosphere.visibility_km=20 --pfm "$T/a.pfm" 2>"$T/err" \
    || bad "render with turbidity and aerosol none"
has "aerosol none with turbidity and visibility" "visibility_km and turbidity set nothing"
# shellcheck disable=SC2086
"$A" render $small --pfm "$T/b.pfm" 2>"$T/err" || bad "render with aerosol none"
hasnt "aerosol none alone" "set nothing"

# --- 3
"$A" volume generate cumulus -o "$T/v.json" --voxel-size 200 >/dev/null 2>&1 || bad "volume generate"
hr="render --volume $T/v.json --renderer harris --width 8 --height 6 --pfm $T/h.pfm"
# shellcheck disable=SC2086
"$A" $hr --spacing 20 2>"$T/err" || bad "harris --spacing 20"
has "spacing under the voxel" "a spacing of 20 m is below the volume's voxel (200 m): the cells are 200 m (1 voxel)"
# shellcheck disable=SC2086
"$A" $hr --spacing 300 2>"$T/err" || bad "harris --spacing 300"
has "spacing between voxels" "is not a multiple of the volume's voxel (200 m): the cells are 400 m (2 voxels)"
for s in 400 0; do
    # shellcheck disable=SC2086
    "$A" $hr --spacing $s 2>"$T/err" || bad "harris --spacing $s"
    hasnt "spacing $s" "a spacing of"
done
exit $fail
