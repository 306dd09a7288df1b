#!/bin/sh
# What the per-pixel error of docs/accuracy.md is made of ("What the per-pixel error is made
# of"): for each case and sun of a run.sh output directory, a second path-traced reference with
# another seed (its noise), the slice variant rendered SS times larger per axis and box-filtered
# down (the path tracer's pixel filter), and breakdown.py on both against the first reference.
#
#   bench/accuracy/breakdown.sh OUT_DIR      (after bench/accuracy/run.sh OUT_DIR)
#
# Environment: ATMOS (default build/atmos), SPP (the second reference's samples per pixel: give
# run.sh's, default 256), TRUNCATE (default 3, as run.sh), SEED (the second reference's seed,
# default 2), CASES (default "cumulus disney"), VARIANT (default diffuse: OUT_DIR/CASE_SUN.VARIANT.pfm
# must exist), SS (default 4; 1: no supersampled image), THREADS. Writes OUT_DIR/breakdown.txt.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
A=${ATMOS:-$root/build/atmos}
OUT=${1:?usage: breakdown.sh OUT_DIR}
SPP=${SPP:-256}
TRUNCATE=${TRUNCATE:-3}
SEED=${SEED:-2}
CASES=${CASES:-"cumulus disney"}
V=${VARIANT:-diffuse}
SS=${SS:-4}
TH=${THREADS:+--threads $THREADS}
txt="$OUT/breakdown.txt"
: > "$txt"
for c in $CASES; do
    scene="$here/$c.json"
    for sun in behind front; do
        if [ "$sun" = behind ]; then az=180; else az=0; fi
        base="$OUT/${c}_$sun"
        if [ ! -s "$base.path$SEED.pfm" ]; then
            "$A" render "$scene" $TH --sun-azimuth $az --renderer path --spp "$SPP" --truncate "$TRUNCATE" \
                --seed "$SEED" --pfm "$base.path$SEED.pfm" -o "$base.path$SEED.png" 2> "$base.path$SEED.log"
        fi
        echo "== $c, sun $sun, $V" >> "$txt"
        python3 "$here/breakdown.py" "$base.$V.pfm" "$base.path.pfm" "$base.tau.pfm" "$base.path$SEED.pfm" >> "$txt"
        if [ "$SS" -gt 1 ]; then
            # the scene's size times SS: the same camera, SS x SS rays per reference pixel
            w=$(python3 -c "import json; print(json.load(open('$scene'))['image']['width'] * $SS)")
            h=$(python3 -c "import json; print(json.load(open('$scene'))['image']['height'] * $SS)")
            opts=""
            case $V in
            eq25) opts="--no-diffuse" ;;
            diffuse) opts="--slice-p1" ;;
            diffuse_xi0) opts="--slice-p1 --xi 0" ;;
            esac
            "$A" render "$scene" $TH --sun-azimuth $az $opts --width "$w" --height "$h" \
                --pfm "$base.$V.ss$SS.pfm" -o "$base.$V.ss$SS.png" 2> "$base.$V.ss$SS.log"
            echo "== $c, sun $sun, $V rendered ${SS}x per axis and box-filtered" >> "$txt"
            python3 "$here/breakdown.py" "$base.$V.ss$SS.pfm" "$base.path.pfm" "$base.tau.pfm" "$base.path$SEED.pfm" >> "$txt"
        fi
    done
done
echo "wrote $txt" >&2
