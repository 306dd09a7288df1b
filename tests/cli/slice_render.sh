#!/bin/sh
# atmos render --volume: the slicing renderer through the CLI. A generated cumulus placed in
# front of the camera must change the image where it stands and leave the sky elsewhere.
set -u
. "$(dirname "$0")/common.inc"

"$A" render -q --width 64 --height 36 --pfm "$T/sky.pfm" || bad "sky render"
"$A" render -q --width 64 --height 36 --volume generate:cumulus --slices 64 --pfm "$T/cloud.pfm" --threads 2 \
    && ok || bad "slice render"
"$A" render -q --width 64 --height 36 --volume generate:cumulus --slices 64 --pfm "$T/cloud1.pfm" --threads 1 \
    && ok || bad "slice render, 1 thread"
cmp -s "$T/cloud.pfm" "$T/cloud1.pfm" && ok || bad "1 and 2 threads differ"
# more threads than the do field solves wavelengths in parallel (64 at most): the same bytes
"$A" render -q --width 16 --height 9 --volume generate:cumulus --pfm "$T/t65.pfm" --threads 65 &&
    "$A" render -q --width 16 --height 9 --volume generate:cumulus --pfm "$T/t1.pfm" --threads 1 &&
    cmp -s "$T/t65.pfm" "$T/t1.pfm" && ok "65 threads" || bad "65 threads: failed or not 1 thread's bytes"
python3 - "$T/sky.pfm" "$T/cloud.pfm" <<'PY' && ok || bad "cloud image check"
import sys, pfm
def rgb(p):
    i = pfm.read(p)
    assert i.c == 3, i.kind
    return i.w, i.h, i.v
w, h, a = rgb(sys.argv[1]); _, _, b = rgb(sys.argv[2])
assert pfm.stats(b).nonfinite == 0, "non-finite values"
px = lambda v, x, y: v[((h - 1 - y) * w + x) * 3:((h - 1 - y) * w + x) * 3 + 3]
# the cloud stands near the image centre, just above the horizon; the corners are sky
changed = sum(1 for x in range(24, 40) for y in range(8, 18) if abs(px(a, x, y)[1] - px(b, x, y)[1]) > 0.02 * px(a, x, y)[1])
same = all(abs(px(a, x, y)[1] - px(b, x, y)[1]) <= 1e-3 * px(a, x, y)[1] for (x, y) in [(1, 1), (62, 1), (1, 34), (62, 34)])
assert changed > 10, "cloud not visible: %d pixels changed" % changed
assert same, "corners changed"
PY
# with the do field (--slice-do) the settings it leaves without a use are refused, named by option
# and key; xi 0 (what the field does) is taken
for o in "--xi 0.5" --eq24 --low-albedo --no-diffuse; do
    # shellcheck disable=SC2086
    "$A" render -q --width 16 --height 9 --volume generate:cumulus --slice-do $o -o "$T/do.png" 2>"$T/do.txt"
    st=$?
    f=${o%% *}
    [ $st -eq 2 ] && grep -q -- "($f) does nothing with the do field" "$T/do.txt" && [ ! -e "$T/do.png" ] &&
        ok "--slice-do $o refused" || { bad "--slice-do $o: exit $st"; cat "$T/do.txt" >&2; }
done
printf '{"renderer": "slice", "volume": {"generate": "cumulus"}, "slice": {"do": true, "xi": 0.2}}\n' >"$T/do.json"
"$A" render -q "$T/do.json" --width 16 --height 9 -o "$T/do.png" 2>"$T/do.txt"
[ $? -eq 1 ] && grep -q "do.json: /slice/xi: (--xi) does nothing" "$T/do.txt" && ok "a scene's do with xi refused" ||
    { bad "a scene's do with xi"; cat "$T/do.txt" >&2; }
# the field: do by default (the image's atmos:slice metadata names its delta-M beam), p1 with
# --slice-p1 or a setting of Riley's path (xi, update), none with --no-diffuse; contradictions
# refused. The do field and the P1 field draw different images.
meta() { # the PNG's atmos:slice text
    png_text "$1" atmos:slice
}
for f in "do:" "p1:--slice-p1" "p1:--xi 0.02" "p1:--eq24" "none:--no-diffuse" "do:--slice-do"; do
    o=${f#*:}
    # shellcheck disable=SC2086
    "$A" render -q --width 16 --height 9 --volume generate:cumulus --slices 32 $o -o "$T/f.png" 2>"$T/f.txt" ||
        { bad "render $o"; cat "$T/f.txt" >&2; continue; }
    m=$(meta "$T/f.png")
    case ${f%%:*} in
    do) echo "$m" | grep -q "delta-M beam" ;;
    p1) echo "$m" | grep -q "diffuse field" && ! echo "$m" | grep -q "delta-M" ;;
    none) ! echo "$m" | grep -q "diffuse field\|delta-M" ;;
    esac && ok "field ${f%%:*} for '$o'" || bad "field for '$o': $m"
done
for o in "--slice-do --slice-p1" "--no-diffuse --slice-p1" "--slice-do -D slice.field=none"; do
    # shellcheck disable=SC2086
    "$A" render -q --width 16 --height 9 --volume generate:cumulus $o -o "$T/c.png" 2>"$T/c.txt"
    st=$?
    [ $st -eq 2 ] && grep -q "contradicts \"field\"" "$T/c.txt" && [ ! -e "$T/c.png" ] && ok "$o refused" ||
        { bad "$o: exit $st"; cat "$T/c.txt" >&2; }
done
printf '{"renderer": "slice", "volume": {"generate": "cumulus"}, "slice": {"field": "p1", "diffuse": false}}\n' >"$T/pf.json"
"$A" render -q "$T/pf.json" --width 16 --height 9 -o "$T/pf.png" 2>"$T/pf.txt"
[ $? -eq 1 ] && grep -q "pf.json: /slice/diffuse: (--no-diffuse) contradicts" "$T/pf.txt" && ok "a scene's p1 without diffuse refused" ||
    { bad "a scene's p1 without diffuse"; cat "$T/pf.txt" >&2; }
"$A" render -q --width 32 --height 18 --volume generate:cumulus --slices 32 --pfm "$T/fdo.pfm" || bad "render do"
"$A" render -q --width 32 --height 18 --volume generate:cumulus --slices 32 --slice-p1 --pfm "$T/fp1.pfm" || bad "render p1"
cmp -s "$T/fdo.pfm" "$T/fp1.pfm" && bad "the do and the p1 field draw the same image" || ok "do and p1 differ"
# another renderer reads none of the slice settings: a leftover do with xi is no error there
printf '{"renderer": "nishita", "volume": {"generate": "cumulus"}, "slice": {"do": true, "xi": 0.2}}\n' >"$T/don.json"
"$A" render -q "$T/don.json" --width 16 --height 9 -o "$T/don.png" 2>"$T/don.txt" && ok "do with xi under nishita: renders" ||
    { bad "do with xi under nishita refused"; cat "$T/don.txt" >&2; }

# --tau: the optical-depth key image, positive where the cloud is; compare --by splits by it
# (one eye ray per pixel: with --edge-aa a pixel whose centre ray misses the volume may hold it)
"$A" render -q --width 64 --height 36 --volume generate:cumulus --slices 64 --eq24 --pfm "$T/eq24.pfm" \
    --tau "$T/tau.pfm" --edge-aa 0 --threads 2 && ok || bad "render --eq24 --tau"
"$A" render -q --width 64 --height 36 --volume generate:cumulus --slices 64 --pfm "$T/cloud0.pfm" --edge-aa 0 \
    --threads 2 && ok || bad "render --edge-aa 0"
"$A" compare "$T/eq24.pfm" "$T/cloud0.pfm" --by "$T/tau.pfm" --edges 0,0.001,1,1000 --json > "$T/bins.json" && ok || bad "compare --by"
python3 - "$T/bins.json" "$T/tau.pfm" <<'PY' && ok || bad "tau image / bins check"
import json, sys, pfm
j = json.load(open(sys.argv[1]))
b = j["bins"]
assert [x["lo"] for x in b] == [0, 0.001, 1], b
assert b[0]["pixels"] > 0 and b[0]["rel_rmse"] == 0, b[0]   # no volume on the ray: identical
assert b[1]["pixels"] + b[2]["pixels"] > 10, b
i = pfm.read(sys.argv[2])
assert i.kind == "Pf", i.kind                                   # one channel
v = i.v
assert min(v) == 0 and max(v) > 1, (min(v), max(v))
PY
"$A" compare "$T/eq24.pfm" "$T/cloud.pfm" --by "$T/tau.pfm" --edges 1,0 >/dev/null 2>&1; [ $? -eq 2 ] && ok || bad "descending --edges should exit 2"
"$A" render -q --tau "$T/t.pfm" -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--tau without a volume should exit 2"
"$A" render -q --renderer slice -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--renderer slice without --volume should exit 2"
# --eye-scale: 1 is the default image exactly; 0.5 renders (1 and 2 threads identical); out of range is a usage error
"$A" render -q --width 64 --height 36 --volume generate:cumulus --slices 64 --pfm "$T/e1.pfm" --threads 2 \
    --eye-scale 1 && cmp -s "$T/e1.pfm" "$T/cloud.pfm" && ok || bad "--eye-scale 1 differs from the default"
"$A" render -q --width 64 --height 36 --volume generate:cumulus --slices 64 --pfm "$T/eh2.pfm" --threads 2 \
    --eye-scale 0.5 && "$A" render -q --width 64 --height 36 --volume generate:cumulus --slices 64 \
    --pfm "$T/eh1.pfm" --threads 1 --eye-scale 0.5 && cmp -s "$T/eh1.pfm" "$T/eh2.pfm" && ok || bad "--eye-scale 0.5"
"$A" render -q --volume generate:cumulus --eye-scale 1.5 -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--eye-scale 1.5 should exit 2"
"$A" render -q --volume generate:nope -o "$T/x.png" 2>/dev/null; [ $? -eq 1 ] && ok || bad "unknown generator should exit 1"
# an eye_scale that leaves a buffer of a pixel or two for the image says so; a half-size one does not
"$A" render -q --volume generate:cumulus --voxel-size 120 --width 48 --height 32 --eye-scale 0.01 -o "$T/es.png" \
    2>"$T/es.err" && grep -q "eye_scale 0.01 makes an eye buffer of 1 x 1 for the 48 x 32 image" "$T/es.err" && ok ||
    bad "--eye-scale 0.01: $(cat "$T/es.err")"
"$A" render -q --volume generate:cumulus --voxel-size 120 --width 48 --height 32 --eye-scale 0.5 -o "$T/es.png" \
    2>"$T/es.err" && ! grep -q "eye buffer" "$T/es.err" && ok || bad "--eye-scale 0.5: $(cat "$T/es.err")"
# a light buffer that costs more than a gigabyte is warned of before the work (interrupted then)
timeout -s INT 4 "$A" render -q --volume generate:cumulus --voxel-size 200 --width 16 --height 16 --light-size 4096 \
    -o "$T/ls.png" 2>"$T/ls.err"
grep -q "light_size 4096 takes about 1.2 GB for the light buffers" "$T/ls.err" && ok || bad "--light-size 4096: $(cat "$T/ls.err")"
rm -rf "$T"
echo "slice_render: $pass passed"
[ "$fail" -eq 0 ]
