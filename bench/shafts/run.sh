#!/bin/sh
# The crepuscular-rays scene with the slice renderer (shadows on the air on and off) and the
# path tracer at a small size, and the air pixels compared (docs/slice.md, "Light shafts").
#
#   bench/shafts/run.sh [--atmos BIN] [--out DIR] [--spp N]
#
# Defaults: BIN = build/atmos, DIR = a temporary folder (kept, printed), N = 128. 160x90
# pixels; the path tracer takes about two minutes on two cores. The images' first 70 rows
# look above the horizon.
set -eu
ATMOS=build/atmos
OUT=
SPP=128
while [ $# -gt 0 ]; do
    case "$1" in
    --atmos) ATMOS=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --spp) SPP=$2; shift 2 ;;
    *) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
[ -n "$OUT" ] || OUT=$(mktemp -d)
mkdir -p "$OUT"
SCENE=scenes/crepuscular_rays.json
SIZE="--width 160 --height 90"
EV="--exposure 13.9"
"$ATMOS" render $SCENE $SIZE $EV --pfm "$OUT/slice.pfm" -o "$OUT/slice.png" --tau "$OUT/tau.pfm"
"$ATMOS" render $SCENE $SIZE $EV --no-air-shadows --pfm "$OUT/slice_off.pfm" -o "$OUT/slice_off.png"
"$ATMOS" render $SCENE $SIZE $EV --renderer path --spp "$SPP" --pfm "$OUT/path.pfm" -o "$OUT/path.png"
python3 "$(dirname "$0")/compare.py" "$OUT/slice.pfm" "$OUT/slice_off.pfm" "$OUT/path.pfm" "$OUT/tau.pfm" 70
echo "images in $OUT"
