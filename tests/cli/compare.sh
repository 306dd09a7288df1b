#!/bin/sh
# atmos compare: identical images compare to zero, different ones do not; heat map is a
# PNG; bad input gives the documented exit codes.
set -u
A=${ATMOS_CLI:?ATMOS_CLI not set}
T=${ATMOS_TEST_TMP:-/tmp}/cli_compare.$$
mkdir -p "$T"
fail=0; pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*" >&2; fail=$((fail + 1)); }

"$A" render -q --width 48 --height 24 --pfm "$T/a.pfm" --exr "$T/a.exr" || bad "render a"
"$A" render -q --width 48 --height 24 --sun-elevation 40 --pfm "$T/b.pfm" || bad "render b"
out=$("$A" compare "$T/a.pfm" "$T/a.exr" --json) || bad "compare identical"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rmse"] == 0 and d["bias"] == [0, 0, 0], d' && ok || bad "identical images: $out"
out=$("$A" compare "$T/b.pfm" "$T/a.pfm" --json --heatmap "$T/h.png") || bad "compare different"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rmse"] > 0 and d["rel_rmse"] > 0 and len(d["bias"]) == 3, d' && ok || bad "different images: $out"
python3 -c 'import sys; assert open(sys.argv[1],"rb").read(8) == b"\x89PNG\r\n\x1a\n"' "$T/h.png" && ok || bad "heat map is not a PNG"
# a heat map into a folder that does not exist: the folder is made, as render's outputs'
"$A" compare "$T/b.pfm" "$T/a.pfm" --heatmap "$T/new/sub/h.png" >/dev/null 2>"$T/err" && [ -s "$T/new/sub/h.png" ] && ok ||
    bad "--heatmap into a new folder: $(cat "$T/err")"
"$A" render -q --width 8 --height 8 --pfm "$T/small.pfm" || bad "render small"
"$A" compare "$T/small.pfm" "$T/a.pfm" 2>"$T/err"; [ $? -eq 1 ] && ok || bad "size mismatch should exit 1"
# the message names both files and their sizes
grep -q "small.pfm is 8x8, .*a.pfm [0-9]*x[0-9]*: the image and the reference must be the same size" "$T/err" && ok ||
    bad "size mismatch message: $(cat "$T/err")"
"$A" compare "$T/a.pfm" 2>/dev/null; [ $? -eq 2 ] && ok || bad "one file should exit 2"
"$A" compare "$T/nope.exr" "$T/a.pfm" 2>/dev/null; [ $? -eq 1 ] && ok || bad "missing file should exit 1"

# A comparison is a test oracle: broken images must fail it loudly.
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}
EXR="python3 $S/tests/tools/write_exr.py"
# pfm FILE HEADER_LINE_END VALUE...: a 2 x 2 RGB PFM (12 values, little-endian, bottom row
# first as the format stores it; the EXRs below list the top row first)
pfm() {
    python3 -c 'import struct,sys; e=sys.argv[2].encode().decode("unicode_escape").encode()
v=[float(x) for x in sys.argv[3:]]
open(sys.argv[1],"wb").write(b"PF"+e+b"2 2"+e+b"-1.0"+e+struct.pack("<12f",*v))' "$@"
}
V="1 2 3 4 5 6 7 8 9 10 11 12"
pfm "$T/ref.pfm" '\n' $V
pfm "$T/nan.pfm" '\n' nan nan nan nan nan nan nan nan nan nan nan nan
out=$("$A" compare "$T/nan.pfm" "$T/ref.pfm" --json 2>"$T/err"); rc=$?
[ $rc -eq 1 ] && ok || bad "all-NaN image against its reference: exit $rc, expected 1 ($out)"
grep -q "12 samples are NaN or infinite (12 in" "$T/err" && ok || bad "all-NaN: no count in the error: $(cat "$T/err")"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rmse"] is None and d["nonfinite_image"] == 12 and d["nonfinite_reference"] == 0, d' \
    && ok || bad "all-NaN: statistics $out"
"$A" compare "$T/ref.pfm" "$T/nan.pfm" >/dev/null 2>&1; [ $? -eq 1 ] && ok || bad "NaN reference should exit 1"
# A CRLF header reads the same pixels as an LF one.
pfm "$T/crlf.pfm" '\r\n' $V
out=$("$A" compare "$T/crlf.pfm" "$T/ref.pfm" --json) || bad "compare CRLF PFM"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rmse"] == 0, d' && ok || bad "CRLF PFM differs: $out"
# EXR channels are paired by name: R,G,B plus a depth channel Z (stored B,G,R,Z), and R,G,B
# given in another order, both equal the reference.
$EXR "$T/rgbz.exr" 2 2 Z:float:9 G:float:8,11,2,5 B:half:9,12,3,6 R:float:7,10,1,4 || bad "write rgbz.exr"
out=$("$A" compare "$T/rgbz.exr" "$T/ref.pfm" --json) || bad "compare R,G,B,Z EXR"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rmse"] == 0 and d["channels"] == ["R","G","B"], d' \
    && ok || bad "R,G,B,Z EXR against the same RGB: $out"
# One layer's channels (as multi-layer files name them) pair with plain R,G,B.
$EXR "$T/layer.exr" 2 2 view.A:half:1 view.B:half:9,12,3,6 view.G:float:8,11,2,5 view.R:float:7,10,1,4 || bad "write layer.exr"
out=$("$A" compare "$T/layer.exr" "$T/ref.pfm" --json) || bad "compare layered EXR"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rmse"] == 0 and d["channels"] == ["view.R","view.G","view.B"], d' \
    && ok || bad "layered EXR against the same RGB: $out"
# UINT channels are compared by value, not as float bit patterns.
$EXR "$T/uint.exr" 2 2 R:uint:7,10,1,4 G:uint:8,11,2,5 B:uint:9,12,3,6 || bad "write uint.exr"
out=$("$A" compare "$T/uint.exr" "$T/ref.pfm" --json) || bad "compare UINT EXR"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rmse"] == 0, d' && ok || bad "UINT EXR against the same values: $out"
# Channels that do not pair by name are an error, not a positional guess.
$EXR "$T/xyz.exr" 2 2 X:float:1 Y:float:2 Z:float:3 || bad "write xyz.exr"
"$A" compare "$T/xyz.exr" "$T/ref.pfm" >/dev/null 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && grep -q "do not pair by name" "$T/err" && ok || bad "X,Y,Z against R,G,B: exit $rc, $(cat "$T/err")"

# An all-zero reference has no relative figure: null in JSON, never a number (-1), as the
# text's inf; every value parses as JSON. --edges without --by is warned of.
pfm "$T/zero.pfm" '\n' 0 0 0 0 0 0 0 0 0 0 0 0
pfm "$T/one.pfm" '\n' 1 1 1 1 1 1 1 1 1 1 1 1
out=$("$A" compare "$T/one.pfm" "$T/zero.pfm" --json) || bad "compare against zeros"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rel_rmse"] is None and d["rmse"] == 1 and d["rel_rmse_per_channel"] == [None]*3, d' \
    && ok || bad "an all-zero reference: rel_rmse not null: $out"
"$A" compare "$T/one.pfm" "$T/zero.pfm" | grep -q "all .* inf" && ok || bad "the text's rel_rmse for an all-zero reference"
"$A" compare "$T/one.pfm" "$T/zero.pfm" --edges 1,2 >/dev/null 2>"$T/err"; rc=$?
[ $rc -eq 0 ] && grep -q "edges.*without --by" "$T/err" && ok || bad "--edges without --by: exit $rc, $(cat "$T/err")"

# The heat map's white is at most 10 times the 99th percentile of the pixels' differences:
# one far-off pixel among 100 off by 10 % does not set it (it saturates at 1), so the rest
# are not black.
python3 -c 'import struct,sys
for name, v in ((sys.argv[1], [1.0] * 300), (sys.argv[2], [1.1] * 297 + [1000.0] * 3)):
    open(name, "wb").write(b"PF\n10 10\n-1.0\n" + struct.pack("<300f", *v))' "$T/h_ref.pfm" "$T/h_img.pfm"
out=$("$A" compare "$T/h_img.pfm" "$T/h_ref.pfm" --heatmap "$T/hh.png") || bad "compare with one far-off pixel"
echo "$out" | grep -q "white = 1 relative" && ok || bad "the heat map's white with one far-off pixel: $out"

# --exclude-above L: a sun's disc (one pixel of 1e9, 0.1 % off) would make the RMSE ~5.8e5;
# left out, the other three pixels, each channel 0.1 above the reference, give an RMSE and a
# bias of 0.1 exactly, and the count left out is printed. A bad value is a usage error.
pfm "$T/sun_ref.pfm" '\n' 1 2 3 4 5 6 7 8 9 1e9 1e9 1e9
pfm "$T/sun_img.pfm" '\n' 1.1 2.1 3.1 4.1 5.1 6.1 7.1 8.1 9.1 1.001e9 1.001e9 1.001e9
out=$("$A" compare "$T/sun_img.pfm" "$T/sun_ref.pfm" --json) || bad "compare with a sun"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["rmse"] > 1e5 and "excluded" not in d, d' \
    && ok || bad "without --exclude-above the sun is in the RMSE: $out"
out=$("$A" compare "$T/sun_img.pfm" "$T/sun_ref.pfm" --exclude-above 1e5 --json) || bad "compare --exclude-above"
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin)
assert abs(d["rmse"] - 0.1) < 1e-6 and all(abs(b - 0.1) < 1e-6 for b in d["bias"]) and d["excluded"] == 1, d
assert d["worst_rmse"] < 0.11, d' && ok || bad "--exclude-above 1e5 leaves the sun out: $out"
out=$("$A" compare "$T/sun_img.pfm" "$T/sun_ref.pfm" --exclude-above 1e5) || bad "compare --exclude-above (text)"
echo "$out" | grep -q "excluded: 1 pixels above 100000 (--exclude-above)" && ok || bad "--exclude-above's line: $out"
"$A" compare "$T/sun_img.pfm" "$T/sun_ref.pfm" --exclude-above -3 >/dev/null 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "exclude-above: expected a radiance > 0" "$T/err" && ok || bad "--exclude-above -3: exit $rc"

# An infinity is not a bright sun: a pixel left out for its other channels' values still counts
# it (the comparison fails on it), and every pixel left out fails the comparison (nothing was
# compared).
pfm "$T/inf_img.pfm" '\n' 1.1 2.1 3.1 4.1 5.1 6.1 7.1 8.1 9.1 inf 1.001e9 1.001e9
out=$("$A" compare "$T/inf_img.pfm" "$T/sun_ref.pfm" --exclude-above 1e5 --json 2>"$T/err"); rc=$?
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["excluded"] == 1 and d["nonfinite_image"] == 1, d' \
    && [ $rc -eq 1 ] && grep -q "1 samples are NaN or infinite (1 in .*; 1 of them in pixels left out by --exclude-above)" "$T/err" && ok ||
    bad "--exclude-above with an infinity: exit $rc, $out, $(cat "$T/err")"
"$A" compare "$T/sun_img.pfm" "$T/sun_ref.pfm" --exclude-above 0.5 >"$T/out" 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && grep -q "every pixel is above 0.5 (--exclude-above): nothing was compared" "$T/err" && ok ||
    bad "--exclude-above below every pixel: exit $rc, $(cat "$T/err")"
# every pixel left out: no worst region (said so), null in --json
grep -q "^worst region: none (every pixel was excluded by --exclude-above)$" "$T/out" && ok ||
    bad "--exclude-above below every pixel: the worst region line: $(cat "$T/out")"
out=$("$A" compare "$T/sun_img.pfm" "$T/sun_ref.pfm" --exclude-above 0.5 --json 2>/dev/null)
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["worst_region"] is None and d["worst_rmse"] is None, d' \
    && ok || bad "--exclude-above below every pixel: --json $out"
# a pixel left out for one channel (R above L) is out of every channel's figures, its NaN (G)
# still counted: R's RMSE is the other pixels' 0.1, not the excluded pixel's 2e5
pfm "$T/nan_g.pfm" '\n' 1.1 2.1 3.1 4.1 5.1 6.1 7.1 8.1 9.1 2e5 nan 12.1
out=$("$A" compare "$T/nan_g.pfm" "$T/ref.pfm" --exclude-above 1e5 --json 2>"$T/err"); rc=$?
echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["excluded"] == 1 and d["nonfinite_image"] == 1 and max(d["rmse_per_channel"]) < 0.11 and d["worst_rmse"] < 0.11, d' \
    && [ $rc -eq 1 ] && ok || bad "--exclude-above, a pixel above L in R with a NaN in G: exit $rc, $out"

rm -rf "$T"
echo "compare: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
