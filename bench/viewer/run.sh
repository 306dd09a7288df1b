#!/bin/sh
# The viewer's frame rates (docs/viewer.md, issue 16's benchmark goals): recorded flights played
# headless, one line per case with the median frame and the slowest 1 % as frames a second.
#
#   bench/viewer/run.sh [--atmos BIN] [--cases "field field200k field_turn field_snap million inside slice slice_full"] [--frames N] [--out DIR]
#                       [--opts "VIEW OPTIONS"]  (atmos view options for every case, e.g. "--screen-layer-px 0")
#
# The cases (1280x720 unless said):
#   field    scenes/harris_cloud_field.json (120 clouds, 100 911 particles; 99 101 before the
#            fractal outlines) along
#            scenes/flights/harris_cloud_field.json, 480 frames; goal 60 fps
#   field200k  the same field with particles 32.6 m apart (--spacing 32.6: 207 584 particles;
#            before the fractal outlines --spacing 35.5 gave 207 030),
#            480 frames: issue 16's ">= 100 clouds / >= 200 000 particles"; goal 60 fps
#   field_turn  the same field, the eye at its centre turning round once in 10 s
#            (bench/viewer/field_turn.json), 240 frames: clouds never seen come into view
#            every frame (the impostors made for the first time)
#   field_snap  the same eye turning 90 degrees in 0.25 s three times, 2 s apart
#            (bench/viewer/field_snap.json), 192 frames: many clouds first seen at once
#   million  the same field with particles 18.1 m apart (--spacing 18.1: 1 198 644 particles;
#            before the fractal outlines --spacing 19.7 gave 1 209 835),
#            240 frames; goal 20 fps
#   inside   scenes/harris_fly_through.json's cumulus, the eye inside it all along
#            (bench/viewer/inside_cumulus.json), 240 frames; goal 30 fps
#   slice    scenes/fig14_interactive_storm.json at 512x512, the sun moving every frame
#            (bench/viewer/storm_sun.json), 120 frames, rendered as an interactive session
#            renders a moving sun (--preview: the slice renderer's preview); goal 10 fps
#   slice_full  the same flight with every frame the full render (no --preview)
#   aircraft scenes/harris_aircraft.json (an aircraft inside a cumulus: impostor splitting)
#            along scenes/flights/harris_aircraft.json, 120 frames
#   aircraft_none  the same cumulus and flight without the aircraft (what splitting costs)
# ms is frames.csv's: a frame's wall time with the conversion to display values, without
# writing its PNG. The first frame (the light passes, a plan's first use) is reported on its
# own (first_ms) and left out of the percentiles. fps_1pct_low: 1000 / the mean of the slowest
# 1 % of the other frames (at least one). cpu_s: the run's CPU time (user + system, with making
# the plan), steadier than wall times on a shared machine. load: the 1-minute load average
# before the case.
#
# Last figures: on the idle machine before the round that left the plan's copy of moving frames
# out (docs/viewer.md, "Where the field's frame goes"): field 36.9 fps median, 1 % low 12.6, first
# frame 1.4 s; million 10.4 fps, 1 % low 5.7, first 9.9 s; inside 50 fps. After it, only on the
# loaded machine (load 6.5-8.5, OMP_WAIT_POLICY=passive, --frames 120 / 36): field 13.7 / 23.4
# fps median (before 12.8 / 11.8 in the same minutes), million 2.9 / 4.7 (before 2.7 / 1.8).
# The round that put a light pass's wavelengths through one sweep and the splats' rows in vector
# loops (docs/viewer.md), in turns at load 6.5-11, --frames 120 / 120 / 36 / 60, before -> after:
# field200k 4.1 -> 8.0 fps median in the quieter round (1 % low 2.3 -> 3.2; run's CPU 24.2 ->
# 19.8 s, first frame 7.9 -> 3.8 s), field 5.1 -> 7.1 (CPU 18.5 -> 16.3 s), million 1.6 -> 2.2
# (CPU 34.3 -> 24.7 s), inside the same (CPU 8.9 / 8.9 s). Not measured idle.
# The impostors never made held to the budget (coarse stand-ins), in turns at load 2.7-3.9:
# field_snap's 1 % low 27.2 / 23.1 -> 33.7 / 26.7 fps; field and field200k unchanged (docs/viewer.md).
# Impostors no finer than their particles (docs/viewer.md), in turns at load 2.9-3.6,
# OMP_WAIT_POLICY=passive, --frames 120: field200k 15.5 / 15.3 -> 19.7 / 18.6 fps median (1 % low
# 7.8 / 8.0 -> 10.0 / 10.3, run's CPU 13.7 / 13.5 -> 12.1 / 12.1 s); field 26.0 / 26.3 -> 31.2 /
# 28.9 fps (1 % low 17.6 / 15.4 -> 22.4 / 21.7); field_snap the same CPU.
# A splat's rows only within its cut (docs/viewer.md), the same images: one thread's CPU a
# field200k frame 38 / 39 -> 30 / 31 ms (bench/viewer/cpu.sh, load 5); wall times at load 4-8 scatter.
# Harris's diffuse light field the default (2026-12-06, docs/viewer.md, "Harris's diffuse light
# field in the viewer"): in turns old / new at load 12-20, --frames 120 (million 48), the same
# fps within the noise (field 1.4 / 1.4, field200k 1.6 / 1.7, inside 1.5 / 1.8, million 3.0 /
# 1.9); the first frame takes the field's cold solve (inside 0.7 -> 2.3 s); bench/viewer/cpu.sh
# field200k 93, 96 -> 101, 89 ms a frame, million 113, 126, 118 -> 138, 128, 100.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
ATMOS=$root/build/atmos
CASES="field field200k field_turn field_snap million inside slice slice_full aircraft aircraft_none"
FRAMES=
OPTS=
OUT=${TMPDIR:-/tmp}/atmos-viewer-bench
while [ $# -gt 0 ]; do
    case "$1" in
    --atmos) ATMOS=$2; shift 2 ;;
    --cases) CASES=$2; shift 2 ;;
    --opts) OPTS=$2; shift 2 ;;
    --frames) FRAMES=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    *) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
mkdir -p "$OUT"

run_case() { # name scene flight frames size [extra options]
    name=$1 scene=$2 flight=$3 n=${FRAMES:-$4} size=$5
    shift 5
    load=$(cut -d' ' -f1 /proc/loadavg)
    rm -rf "$OUT/$name"
    (cd "$root" && /usr/bin/time -f "%U %S" -o "$OUT/$name.cpu" "$ATMOS" view "$scene" --script "$flight" \
        --frames "$n" --headless --size "$size" --record "$OUT/$name" -q $OPTS "$@")
    python3 - "$OUT/$name/frames.csv" "$name" "$size" "$load" "$OUT/$name.cpu" <<'PY'
import csv, sys
cpu = sum(float(x) for x in open(sys.argv[5]).read().split()[-2:])
rows = list(csv.DictReader(open(sys.argv[1])))
ms = [float(r["ms"]) for r in rows]
rest = sorted(ms[1:]) or ms
med = rest[len(rest) // 2] if len(rest) % 2 else 0.5 * (rest[len(rest) // 2 - 1] + rest[len(rest) // 2])
k = max(1, len(rest) // 100)
low = sum(rest[-k:]) / k
upd = sum(float(r["impostor_updates"]) for r in rows[1:]) / max(1, len(rows) - 1)
print("case=%s frames=%d size=%s ms_median=%.1f fps_median=%.1f fps_1pct_low=%.1f first_ms=%.0f "
      "impostor_updates=%.1f cpu_s=%.1f load=%s" % (sys.argv[2], len(rows), sys.argv[3], med, 1000 / med, 1000 / low,
                                                   ms[0], upd, cpu, sys.argv[4]))
PY
}

for c in $CASES; do
    case "$c" in
    field) run_case field scenes/harris_cloud_field.json scenes/flights/harris_cloud_field.json 480 1280x720 ;;
    field200k) run_case field200k scenes/harris_cloud_field.json scenes/flights/harris_cloud_field.json 480 1280x720 \
        --spacing 32.6 ;;
    field_turn) run_case field_turn scenes/harris_cloud_field.json bench/viewer/field_turn.json 240 1280x720 ;;
    field_snap) run_case field_snap scenes/harris_cloud_field.json bench/viewer/field_snap.json 192 1280x720 ;;
    million) run_case million scenes/harris_cloud_field.json scenes/flights/harris_cloud_field.json 240 1280x720 \
        --spacing 18.1 ;;
    inside) run_case inside scenes/harris_fly_through.json bench/viewer/inside_cumulus.json 240 1280x720 ;;
    slice) run_case slice scenes/fig14_interactive_storm.json bench/viewer/storm_sun.json 120 512x512 --preview ;;
    slice_full) run_case slice_full scenes/fig14_interactive_storm.json bench/viewer/storm_sun.json 120 512x512 ;;
    aircraft) run_case aircraft scenes/harris_aircraft.json scenes/flights/harris_aircraft.json 120 1280x720 ;;
    aircraft_none)
        python3 -c 'import json, sys; s = json.load(open(sys.argv[1])); del s["objects"]; json.dump(s, open(sys.argv[2], "w"))' \
            "$root/scenes/harris_aircraft.json" "$OUT/harris_no_aircraft.json"
        run_case aircraft_none "$OUT/harris_no_aircraft.json" scenes/flights/harris_aircraft.json 120 1280x720 ;;
    *) echo "run.sh: unknown case $c" >&2; exit 2 ;;
    esac
done
