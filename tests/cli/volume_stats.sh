#!/bin/sh
# atmos volume stats: the shape statistics of a raw volume with three known discs of cloud
# (count, fraction, areas in the per-cloud CSV), --kv keys, the mask PNG, a generated preset
# measured from its file and from generate: alike, and usage and runtime errors.
. "$(dirname "$0")/common.inc"

# 64 x 6 x 64 voxels of 100 m: discs of radius 5, 8 and 12 voxels, cloud in layers 1..3
python3 - "$T" <<'PY' || bad "writing the test volume"
import json, struct, sys
t = sys.argv[1]
nx, ny, nz = 64, 6, 64
discs = [(12.3, 14.2, 5), (40.1, 15.6, 8), (30.4, 44.8, 12)]
v = [0.0] * (nx * ny * nz)
cols = 0
for k in range(nz):
    for i in range(nx):
        if any((i - x) ** 2 + (k - z) ** 2 <= r * r for x, z, r in discs):
            cols += 1
            for j in (1, 2, 3):
                v[(k * ny + j) * nx + i] = 1e8
open(t + "/d.cloud.raw", "wb").write(struct.pack("<%df" % len(v), *v))
json.dump({"dims": [nx, ny, nz], "voxel_size_m": 100, "origin_m": [0, 0, 0],
           "fields": [{"name": "cloud", "particle": "cloud", "file": "d.cloud.raw"}]}, open(t + "/d.json", "w"))
open(t + "/cols", "w").write(str(cols))
PY
"$A" volume stats "$T/d.json" --kv --csv "$T/d.csv" --mask-png "$T/d.png" >"$T/kv" 2>"$T/err" || bad "stats of the disc volume: $(cat "$T/err")"
kv() { sed -n "s/^$1=//p" "$T/kv"; }
[ "$(kv clouds)" = 3 ] && ok "three clouds" || bad "clouds=$(kv clouds), expected 3"
[ "$(kv edge_clouds)" = 0 ] && [ "$(kv connectivity)" = 4 ] && [ "$(kv threshold_tau)" = 1 ] && ok "defaults reported" ||
    bad "edge clouds, connectivity or threshold wrong"
python3 - "$T" <<'PY' && ok "fraction, areas and D of the discs" || bad "fraction, areas or D of the discs"
import csv, math, sys
t = sys.argv[1]
kv = dict(l.strip().split("=", 1) for l in open(t + "/kv"))
cols = int(open(t + "/cols").read())
assert abs(float(kv["cloud_fraction"]) - cols / 4096) < 1e-6, kv["cloud_fraction"]
rows = list(csv.DictReader(open(t + "/d.csv")))
assert len(rows) == 3
areas = sorted(float(r["area_m2"]) for r in rows)
for a, r in zip(areas, (5, 8, 12)):
    h = math.sqrt(0.5)
    assert math.pi * (r - h) ** 2 * 1e4 <= a <= math.pi * (r + h) ** 2 * 1e4, (a, r)
assert abs(float(kv["D"]) - 1) < 0.1, kv["D"]
for r in rows:
    assert abs(float(r["base_m"]) - (100 + 100 * 0.1 / 6.28)) < 0.5 and float(r["base_sd_m"]) < 1e-3, r
PY
head -c 8 "$T/d.png" | od -An -c | grep -q "P   N   G" && ok "mask PNG" || bad "the mask is not a PNG"
"$A" volume stats "$T/d.json" | grep -q "perimeter-area dimension D" && ok "readable summary" || bad "summary"

# a generated preset: from its file and from generate: alike
"$A" volume generate cumulus_field -o "$T/g.json" >/dev/null 2>&1 || bad "generate"
"$A" volume stats "$T/g.json" --kv >"$T/g1" 2>&1 && "$A" volume stats generate:cumulus_field --kv >"$T/g2" 2>&1 &&
    cmp -s "$T/g1" "$T/g2" && ok "a file and generate: give the same statistics" || bad "file and generate: differ"

# outputs into folders not made yet: made, as atmos render makes them
"$A" volume stats "$T/d.json" --mask-png "$T/new/sub/m.png" --csv "$T/new/c.csv" >/dev/null 2>"$T/e" &&
    [ -s "$T/new/sub/m.png" ] && [ -s "$T/new/c.csv" ] && ok "--mask-png and --csv into new folders" ||
    bad "outputs into new folders: $(cat "$T/e")"

# errors
"$A" volume stats >/dev/null 2>&1; [ $? -eq 2 ] && ok "no source: usage error" || bad "no source"
"$A" volume stats "$T/d.json" --threshold -1 >/dev/null 2>&1; [ $? -eq 2 ] && ok "negative threshold" || bad "negative threshold"
"$A" volume stats "$T/d.json" --connectivity 6 >/dev/null 2>&1; [ $? -eq 2 ] && ok "connectivity 6" || bad "connectivity 6"
"$A" volume stats "$T/d.json" --size-range 5,2 >/dev/null 2>&1; [ $? -eq 2 ] && ok "bad size range" || bad "bad size range"
"$A" volume stats "$T/none.json" >/dev/null 2>&1; [ $? -eq 1 ] && ok "missing file: runtime error" || bad "missing file"
"$A" volume stats generate:nope >/dev/null 2>"$T/e"; [ $? -eq 1 ] && grep -q cumulus "$T/e" && grep -q harris_field "$T/e" && ok "unknown preset named with the known ones" ||
    bad "unknown preset: $(cat "$T/e")"
"$A" volume stats "$T/d.json" --field rain >/dev/null 2>"$T/e"; [ $? -eq 1 ] && grep -q "no field" "$T/e" && ok "--field rain: no such field" ||
    bad "--field rain"

# no cloud above the threshold: said, not NaN and an inverted size range
"$A" volume stats "$T/d.json" --threshold 1e9 >"$T/o" 2>&1 && grep -q "nothing to fit" "$T/o" && ! grep -q nan "$T/o" &&
    ok "no clouds: nothing to fit, no NaN" || bad "no clouds: $(cat "$T/o")"
# one cloud to fit (--min-pixels 300 keeps the largest disc), a size range with one cloud: too few
# clouds said in words, no NaN (both printed "nan +- nan")
"$A" volume stats "$T/d.json" --min-pixels 300 >"$T/o" 2>&1 && grep -q "dimension: too few clouds to fit (1 of" "$T/o" &&
    grep -q "size distribution: too few clouds to fit (0 in" "$T/o" && ! grep -qi nan "$T/o" &&
    ok "one cloud to fit: too few clouds, no NaN" || bad "one cloud to fit: $(cat "$T/o")"
"$A" volume stats "$T/d.json" --size-range 2000,2500 >"$T/o" 2>&1 && grep -q "size distribution: too few clouds to fit (1 in" "$T/o" &&
    grep -q "dimension D = 1.0" "$T/o" && ! grep -qi nan "$T/o" && ok "one cloud in the size range: too few, no NaN" ||
    bad "one cloud in the size range: $(cat "$T/o")"
"$A" volume stats "$T/d.json" --threshold 1e9 --kv >"$T/o" 2>&1 && grep -q "^size_min_m=nan" "$T/o" && grep -q "^size_clouds=0" "$T/o" &&
    ok "no clouds: --kv size range nan" || bad "no clouds --kv: $(grep size_m "$T/o")"
"$A" volume --help | grep -q -- "--kv prints key=value lines" && "$A" volume --help | grep -q "nan where a fit has too few clouds" &&
    ok "volume --help says --kv's nan" || bad "volume --help does not say when --kv prints nan"
# reading options reach the file: --scale 0.5 halves every optical depth (the discs have tau between 10 and 20:
# clouds at --threshold 10 read as they are, none read at half)
"$A" volume stats "$T/d.json" --threshold 10 --kv >"$T/o" 2>&1 && [ "$(sed -n 's/^clouds=//p' "$T/o")" = 3 ] &&
    "$A" volume stats "$T/d.json" --threshold 10 --scale 0.5 --kv >"$T/o" 2>&1 && [ "$(sed -n 's/^clouds=//p' "$T/o")" = 0 ] &&
    ok "--scale reads the file scaled" || bad "--scale: $(cat "$T/o")"
# options that would do nothing, and a source twice: usage errors naming them
"$A" volume stats "$T/d.json" "$T/d.json" >/dev/null 2>"$T/e"; [ $? -eq 2 ] && grep -q "given twice" "$T/e" && ok "a source twice" || bad "a source twice"
"$A" volume stats "$T/d.json" --minutes 3 >/dev/null 2>"$T/e"; [ $? -eq 2 ] && grep -q -- "--minutes" "$T/e" && ok "--minutes on a file" || bad "--minutes on a file"
"$A" volume stats "$T/d.json" --seeds 3 >/dev/null 2>"$T/e"; [ $? -eq 2 ] && grep -q -- "--seeds" "$T/e" && ok "--seeds on a file" || bad "--seeds on a file"
"$A" volume stats generate:cumulus --time 2 >/dev/null 2>"$T/e"; [ $? -eq 2 ] && grep -q "reading options" "$T/e" && ok "--time on a generator" || bad "--time on a generator"
# outputs written all or none, never over an input: --csv naming the volume is refused and the
# volume kept; a failing second source leaves neither the csv nor the mask behind
cp "$T/d.json" "$T/keep.json"
"$A" volume stats "$T/d.json" --csv "$T/d.json" >/dev/null 2>"$T/e"; [ $? -eq 2 ] && grep -q "refusing to overwrite an input" "$T/e" &&
    cmp -s "$T/d.json" "$T/keep.json" && ok "--csv over the input refused, the input kept" || bad "--csv over the input: $(cat "$T/e")"
cp "$T/d.cloud.raw" "$T/keep.raw"
"$A" volume stats "$T/d.json" --csv "$T/d.cloud.raw" >/dev/null 2>"$T/e"; [ $? -eq 2 ] && grep -q "refusing to overwrite an input" "$T/e" &&
    cmp -s "$T/d.cloud.raw" "$T/keep.raw" && ok "--csv over the sidecar's data file refused" || bad "--csv over the data file: $(cat "$T/e")"
printf 'not a volume' >"$T/junk.vdb"
"$A" volume stats "$T/d.json" "$T/junk.vdb" --csv "$T/part.csv" --mask-png "$T/part.png" >/dev/null 2>"$T/e"; [ $? -eq 1 ] &&
    [ ! -e "$T/part.csv" ] && [ ! -e "$T/part.png" ] && [ -z "$(ls "$T" | grep -F .tmp)" ] && ok "a failed source: no output left" ||
    bad "a failed source left: $(ls "$T")"
"$A" volume stats "$T/d.json" --csv "$T/out/s.csv" --mask-png "$T/out/s.png" >/dev/null 2>"$T/e" && [ -s "$T/out/s.csv" ] &&
    [ -s "$T/out/s.png" ] && ok "--csv and --mask-png written" || bad "--csv and --mask-png: $(cat "$T/e")"
exit $fail
