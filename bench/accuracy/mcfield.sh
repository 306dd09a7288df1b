#!/bin/sh
# The floor of a per-cell light field (docs/lightfield.md, "A Monte Carlo field"): in a vacuum
# (no sky, no ground: the field's photons come from the sun alone), the path tracer's reference
# (seeds 1 and 2, the second for its noise), the slice renderer with its diffuse (P1) field, and
# the Nishita renderer's exact first order plus the Monte Carlo field of the orders >= 2, each
# split by bench/accuracy/breakdown.py against the reference.
#
#   bench/accuracy/mcfield.sh OUT_DIR
#
# Environment: ATMOS (default build/atmos), SPP (the references', default 256), CASES (default
# "disney cumulus"), KPHOTONS (thousands of photons per wavelength, default 2000), CELL (the
# field's cell edge in render voxels, default 4), LMAX (-1: toward the view's centre; 0-3:
# spherical harmonics), DELTA_M (1: with LMAX >= 0, the delta-M scaled field), DM_CLIP (1: with
# DELTA_M, the photons sample the scaled phase exactly, --nishita-mc-dm-clip), DO (1: with LMAX >= 0,
# the field solved by discrete ordinates, --nishita-do, not by photons), SLICE_DO (1: instead of the
# Nishita renderer, the slice renderer with that field, --slice-do: its first order delta-M scaled;
# LMAX, DELTA_M, DO, KPHOTONS ignored; EYE_SCALE: its --eye-scale, 2 antialiased), TAG (the variant's
# file name, default mcCELL_LMAX, dm appended with DELTA_M, dmc with DM_CLIP; doCELL_LMAX with DO;
# sdoCELL with SLICE_DO, aa appended with EYE_SCALE 2), THREADS,
# REUSE (1: keep the references already in OUT_DIR). Writes OUT_DIR/CASE_SUN.TAG.bd.txt and the field's CPU
# time (user+system, s) in OUT_DIR/CASE_SUN.TAG.cpu.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
A=${ATMOS:-$root/build/atmos}
OUT=${1:?usage: mcfield.sh OUT_DIR}
SPP=${SPP:-256}
CASES=${CASES:-"disney cumulus"}
K=${KPHOTONS:-2000}
CELL=${CELL:-4}
LMAX=${LMAX:--1}
DM=$([ "${DELTA_M:-0}" = 1 ] && echo "--nishita-mc-delta-m" || echo "")
DO=$([ "${DO:-0}" = 1 ] && echo "--nishita-do" || echo "")
OFF="$([ -z "$DM" ] && echo "-D nishita.mc_delta_m=false") $([ -z "$DO" ] && echo "-D nishita.do=false")" # both on by default
DMC=$([ -n "$DM" ] && [ "${DM_CLIP:-0}" = 1 ] && echo "--nishita-mc-dm-clip" || echo "")
if [ "${SLICE_DO:-0}" = 1 ]; then
    TAG=${TAG:-sdo$CELL$([ "${EYE_SCALE:-1}" = 2 ] && echo aa || echo "")}
    R="--slice-do -D nishita.mc_cell=$CELL${EYE_SCALE:+ --eye-scale $EYE_SCALE}"
else
    TAG=${TAG:-$([ -n "$DO" ] && echo do || echo mc)${CELL}_$LMAX${DM:+dm}${DMC:+c}}
    R="--renderer nishita --nishita-orders 1 --no-nishita-sky --nishita-mc $K --nishita-mc-cell $CELL \
--nishita-mc-lmax $LMAX $DM $DMC $DO $OFF"
fi
TH=${THREADS:+--threads $THREADS}
mkdir -p "$OUT"
for c in $CASES; do
    scene="$here/$c.json"
    for sun in behind front; do
        if [ "$sun" = behind ]; then az=180; else az=0; fi
        b="$OUT/${c}_$sun"
        V="$A render $scene $TH --sun-azimuth $az -D background=black"
        for seed in 1 2; do
            s=$([ $seed = 1 ] && echo "" || echo 2)
            if [ "${REUSE:-0}" != 1 ] || [ ! -s "$b.vpath$s.pfm" ]; then
                $V --renderer path --spp "$SPP" --truncate 3 --seed $seed --pfm "$b.vpath$s.pfm" --tau "$b.tau.pfm" \
                    -o "$b.vpath$s.png" 2> "$b.vpath$s.log"
            fi
        done
        if [ ! -s "$b.p1.pfm" ]; then
            $V --slice-p1 --pfm "$b.p1.pfm" -o "$b.p1.png" 2> "$b.p1.log"
            python3 "$here/breakdown.py" "$b.p1.pfm" "$b.vpath.pfm" "$b.tau.pfm" "$b.vpath2.pfm" > "$b.p1.bd.txt"
        fi
        /usr/bin/time -f %U+%S -o "$b.$TAG.cpu" $V $R --pfm "$b.$TAG.pfm" -o "$b.$TAG.png" 2> "$b.$TAG.log"
        python3 "$here/breakdown.py" "$b.$TAG.pfm" "$b.vpath.pfm" "$b.tau.pfm" "$b.vpath2.pfm" > "$b.$TAG.bd.txt"
        echo "== $c, sun $sun, $TAG: $(head -2 "$b.$TAG.bd.txt" | tr '\n' ' ') cpu $(cat "$b.$TAG.cpu") s" >&2
    done
done
