#!/bin/sh
# The viewer's CPU time a frame (docs/viewer.md): the CPU seconds (user + system) of a headless
# flight of N + 1 frames less those of 1 frame, over N, so that making the plan and the first
# frame's light passes are left out; steadier than wall times on a shared machine. The frames
# are not recorded, so their display values are the window's 8-bit ones.
#
#   bench/viewer/cpu.sh [--atmos BIN] [--cases "field field200k million inside slice slice_full"] [--frames N] [--opts "VIEW OPTIONS"]
# (slice: the preview frames of a moving sun, --preview; slice_full: full renders)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
ATMOS=$root/build/atmos
CASES="field inside slice"
N=48
OPTS=
while [ $# -gt 0 ]; do
    case "$1" in
    --atmos) ATMOS=$2; shift 2 ;;
    --cases) CASES=$2; shift 2 ;;
    --opts) OPTS=$2; shift 2 ;;
    --frames) N=$2; shift 2 ;;
    *) echo "cpu.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
cpu() { # scene flight size frames [extra options]
    scene=$1 flight=$2 size=$3 n=$4
    shift 4
    (cd "$root" && /usr/bin/time -f "%U %S" -o "$tmp" "$ATMOS" view "$scene" --script "$flight" --frames "$n" \
        --headless --size "$size" -q $OPTS "$@" >/dev/null 2>&1)
    awk '{print $1 + $2}' "$tmp"
}
for c in $CASES; do
    case "$c" in
    field) set -- scenes/harris_cloud_field.json scenes/flights/harris_cloud_field.json 1280x720 ;;
    field200k) set -- scenes/harris_cloud_field.json scenes/flights/harris_cloud_field.json 1280x720 --spacing 32.6 ;;
    million) set -- scenes/harris_cloud_field.json scenes/flights/harris_cloud_field.json 1280x720 --spacing 18.1 ;;
    inside) set -- scenes/harris_fly_through.json bench/viewer/inside_cumulus.json 1280x720 ;;
    slice) set -- scenes/fig14_interactive_storm.json bench/viewer/storm_sun.json 512x512 --preview ;;
    slice_full) set -- scenes/fig14_interactive_storm.json bench/viewer/storm_sun.json 512x512 ;;
    *) echo "cpu.sh: unknown case $c" >&2; exit 2 ;;
    esac
    scene=$1 flight=$2 size=$3
    shift 3
    load=$(cut -d' ' -f1 /proc/loadavg)
    one=$(cpu "$scene" "$flight" "$size" 1 "$@")
    all=$(cpu "$scene" "$flight" "$size" $((N + 1)) "$@")
    echo "case=$c frames=$N cpu_ms_per_frame=$(awk -v a="$all" -v b="$one" -v n="$N" 'BEGIN {printf "%.0f", (a - b) / n * 1000}') load=$load"
done
