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
"$A" render -q --width 8 --height 8 --pfm "$T/small.pfm" || bad "render small"
"$A" compare "$T/small.pfm" "$T/a.pfm" 2>/dev/null; [ $? -eq 1 ] && ok || bad "size mismatch should exit 1"
"$A" compare "$T/a.pfm" 2>/dev/null; [ $? -eq 2 ] && ok || bad "one file should exit 2"
"$A" compare "$T/nope.exr" "$T/a.pfm" 2>/dev/null; [ $? -eq 1 ] && ok || bad "missing file should exit 1"
rm -rf "$T"
echo "compare: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
