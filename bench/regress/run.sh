#!/bin/sh
# Renders a fixed set of cases with one atmos binary into a folder, so that two builds
# (before and after a change that must not change images) can be compared byte for byte:
#
#   bench/regress/run.sh BIN OUT_DIR              render every case with BIN into OUT_DIR
#   bench/regress/run.sh --compare DIR_A DIR_B    per PFM: identical, or the largest
#                                                 relative difference (atmos compare)
#
# The cases: the built-in default scene, every scenes/*.json (first frame, at most 320
# pixels wide), the accuracy cases of bench/accuracy (sun behind and in front; slice
# renderer in five variants, path tracer at 8 spp exact and truncated with its variance
# and order images), and a few more settings (spectral, eye_scale 0.5, sky-only path,
# vacuum backgrounds). Every case writes a PFM (linear sRGB floats) and a PNG; only the
# PFMs are compared (PNG and EXR files carry the render time in their metadata).
# Scenes whose volume file is missing are skipped (listed). THREADS sets --threads.
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)

if [ "${1:-}" = "--compare" ]; then
    A=$2 B=$3
    BIN=${ATMOS:-$root/build/atmos}
    same=0 diff=0 missing=0
    for f in "$A"/*.pfm; do
        [ -e "$f" ] || continue
        n=$(basename "$f")
        if [ ! -e "$B/$n" ]; then echo "missing  $n"; missing=$((missing + 1)); continue; fi
        if cmp -s "$f" "$B/$n"; then same=$((same + 1)); continue; fi
        diff=$((diff + 1))
        case "$n" in
        *.pfm) echo "differs  $n  $("$BIN" compare "$B/$n" "$f" --json 2>/dev/null | tr -d '\n' | sed 's/  */ /g' | cut -c1-200)" ;;
        *) echo "differs  $n" ;;
        esac
    done
    echo "identical: $same  different: $diff  missing: $missing"
    [ "$diff" = 0 ] && [ "$missing" = 0 ]
    exit $?
fi

BIN=$1
OUT=$2
TH=${THREADS:+--threads $THREADS}
mkdir -p "$OUT"
log="$OUT/log.txt"
: > "$log"
run() { # name, then render arguments
    name=$1; shift
    "$BIN" render "$@" $TH -q --pfm "$OUT/$name.pfm" -o "$OUT/$name.png" >> "$log" 2>&1 || echo "FAILED $name" | tee -a "$log"
}

run default
for s in "$root"/scenes/*.json; do
    n=$(basename "$s" .json)
    size=$(python3 - "$s" <<'PY'
import json, os, sys
s = json.load(open(sys.argv[1]))
img = s.get("image", {})
w, h = img.get("width", 1280), img.get("height", 720)
if w > 320:
    w, h = 320, max(1, round(h * 320 / w))
f = (s.get("volume") or {}).get("file")
if f and not os.path.exists(os.path.join(os.path.dirname(sys.argv[1]), f)):
    print("missing")
else:
    print(w, h)
PY
)
    if [ "$size" = missing ]; then echo "skipped $n (volume file missing)" | tee -a "$log"; continue; fi
    set -- $size
    run "scene_$n" "$s" --frames 1 --width "$1" --height "$2"
done
for c in cumulus cirrus rain disney; do
    sc="$root/bench/accuracy/$c.json"
    if [ "$c" = disney ] && [ ! -e "$root/../shared/data/real/wdas_cloud_sixteenth.vdb" ]; then continue; fi
    for az in 180 0; do
        b="acc_${c}_$az"
        run "$b.eq25" "$sc" --sun-azimuth $az
        run "$b.xi0" "$sc" --sun-azimuth $az --xi 0
        run "$b.xi4" "$sc" --sun-azimuth $az --xi 0.0318
        run "$b.eq24" "$sc" --sun-azimuth $az --eq24
        run "$b.lowalb" "$sc" --sun-azimuth $az --low-albedo
        run "$b.path" "$sc" --sun-azimuth $az --renderer path --spp 8 --variance "$OUT/$b.path.var.exr" \
            --order "$OUT/$b.path.order.pfm" --tau "$OUT/$b.tau.pfm"
        run "$b.pathtr" "$sc" --sun-azimuth $az --renderer path --spp 8 --truncate 3
    done
done
cu="$root/bench/accuracy/cumulus.json"
run x_spectral "$cu" --spectral 16
run x_eyescale "$cu" --eye-scale 0.5 --width 250 --height 170
run x_path_spectral "$cu" --renderer path --spp 4 --spectral 12
run x_path_nosky "$cu" --renderer path --spp 8 --no-sky-nee --no-forced --no-aureole
run x_sky_fisheye --camera fisheye --width 128 --height 128 --spp 2
run x_sky_equirect --camera equirect --width 192 --height 96 --sun-elevation 3
run x_sky_alt --altitude 9000 --width 160 --height 90 --spectral 8
run x_fig10_path "$root/scenes/fig10_storm_uniform.json" --renderer path --spp 4 --width 96 --height 54
run x_frames "$root/scenes/fig01_cirrus_sunrise.json" --frames 3 --width 128 --height 72
echo "wrote $OUT" >&2
