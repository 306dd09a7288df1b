#!/bin/sh
# atmos volume: generate -> info --json (parsed and checked) -> slice PNG; usage errors.
set -eu
A=${ATMOS_CLI:?}
T=${ATMOS_TEST_TMP:-/tmp}
fail() { echo "volume.sh: FAIL: $*" >&2; exit 1; }

"$A" volume --help | grep -q "generate PRESET" || fail "help"
"$A" volume generate rain_shaft -o "$T/rs.json" --seed 3 --voxel-size 100 || fail "generate"
[ -f "$T/rs.json" ] && [ -f "$T/rs.cloud.raw" ] && [ -f "$T/rs.rain.raw" ] || fail "files not written"
ls "$T" | grep -q tmp && fail "temporary file left behind"
"$A" volume info "$T/rs.json" --json > "$T/info.json" || fail "info"
python3 - "$T/info.json" <<'PY' || fail "info --json contents"
import json, sys
d = json.load(open(sys.argv[1]))
names = [f["name"] for f in d["fields"]]
assert names == ["cloud", "rain"], names
for f in d["fields"]:
    assert f["active_voxels"] > 0 and 0 < f["min"] <= f["max"], f
    lo, hi = f["bounds_m"]
    assert len(lo) == 3 and all(a < b for a, b in zip(lo, hi)), f
cloud, rain = d["fields"]
assert abs(cloud["max"] - 1e8) < 1e3, cloud["max"]
assert rain["bounds_m"][0][1] < cloud["bounds_m"][0][1], "rain must reach below the cloud base"
assert d["voxel_size_m"] == 100 and d["memory_bytes"] > 0
PY
"$A" volume info "$T/rs.json" | grep -q "field cloud" || fail "info text"
"$A" volume slice "$T/rs.json" --axis z --field rain -o "$T/slice.png" || fail "slice"
head -c 8 "$T/slice.png" | od -An -c | grep -q "P   N   G" || fail "slice is not a PNG"
# into a folder that does not exist: the folder is made, as render's outputs'
"$A" volume slice "$T/rs.json" --axis z -o "$T/new/sub/slice.png" && [ -s "$T/new/sub/slice.png" ] || fail "slice into a new folder"
# same seed, same bytes
"$A" volume generate rain_shaft -o "$T/rs2.json" --seed 3 --voxel-size 100
cmp -s "$T/rs.cloud.raw" "$T/rs2.cloud.raw" || fail "not deterministic"
# errors: usage 2, runtime 1
set +e
"$A" volume generate nosuch -o "$T/x.json" 2> "$T/err.txt"; [ $? -eq 2 ] || fail "unknown preset exit"
grep -q "harris_field" "$T/err.txt" || fail "unknown preset: the known ones (Harris's too) not named: $(cat "$T/err.txt")"
for ext in vdb nvdb png; do # only a raw volume with its JSON sidecar is written
    rm -f "$T/x.$ext"
    "$A" volume generate cumulus -o "$T/x.$ext" 2> "$T/err.txt"; [ $? -eq 2 ] || fail "-o x.$ext exit"
    grep -q "writes only a raw volume" "$T/err.txt" || fail "-o x.$ext message: $(cat "$T/err.txt")"
    [ -e "$T/x.$ext" ] && fail "-o x.$ext: a file was written"
done
"$A" volume slice "$T/rs.json" --axis w -o "$T/s.png"; [ $? -eq 2 ] || fail "bad axis exit"
"$A" volume info; [ $? -eq 2 ] || fail "missing file exit"
"$A" volume info "$T/does_not_exist.json"; [ $? -eq 1 ] || fail "missing file exit"
"$A" volume info "$ATMOS_SOURCE_DIR/tests/crashers/volume/truncated_raw.json" 2> "$T/err.txt"; [ $? -eq 1 ] || fail "crasher exit"
grep -q "truncated" "$T/err.txt" || fail "crasher message"
# a scene file given as a volume: said to be a scene, not a sidecar with an unknown key
"$A" volume info "$ATMOS_SOURCE_DIR/scenes/disney_cloud_sunset.json" 2> "$T/err.txt"; [ $? -eq 1 ] || fail "scene as a volume exit"
grep -q "disney_cloud_sunset.json: a scene file (it has \"" "$T/err.txt" || fail "scene as a volume message: $(cat "$T/err.txt")"
grep -q "unknown key" "$T/err.txt" && fail "scene as a volume: an unknown key: $(cat "$T/err.txt")"
"$A" volume slice "$T/rs.json" --axis z --field snow -o "$T/s.png" 2>/dev/null; [ $? -eq 1 ] || fail "missing field exit"
# damaged OpenVDB files: refused with exit 1 and a message naming the file (when the reader is built)
C="$ATMOS_SOURCE_DIR/tests/crashers/volume"
"$A" volume info "$C/truncated_uncompressed.vdb" 2> "$T/err.txt"; rc=$?
if ! grep -q "cannot read OpenVDB files" "$T/err.txt"; then
    [ $rc -eq 1 ] || fail "truncated vdb exit $rc"
    grep -q "truncated_uncompressed.vdb: truncated: grid 'density' ends at byte" "$T/err.txt" || fail "truncated vdb message"
    "$A" volume info "$C/dragon_blosc_overflow.vdb" 2> "$T/err.txt"; rc=$?
    [ $rc -eq 1 ] || fail "damaged vdb exit $rc (the library's crash must not reach the command)"
    grep -q "dragon_blosc_overflow.vdb: " "$T/err.txt" || fail "damaged vdb message"
fi
set -e
echo "volume.sh: ok"
