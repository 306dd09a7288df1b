#!/bin/sh
# `atmos mie` end to end. Run by ctest with ATMOS_CLI = path of the atmos binary.
# Reference: Wiscombe's MIEV0 test case 7 (MVTstNew.f, BLOCK DATA CHEKMI; also in
# tests/data/mie_reference.csv): m = 0.75, x = 10: Q_ext = Q_sca = 2.232265,
# g = 0.8964724, S1(0) = 55.80662 - 9.758097i, S2(90) = -0.5148748 - 0.7027288i,
# S1(180) = -1.078568 - 0.03608807i.
set -u

cli=${ATMOS_CLI:?ATMOS_CLI must name the atmos binary}
fail=0
tmp=${ATMOS_TEST_TMP:-/tmp}/cli_mie.$$
trap 'rm -f "$tmp.out" "$tmp.err"' EXIT

ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }

# --json must be exactly one object with the documented keys and Wiscombe's numbers
if "$cli" mie --m 0.75,0 --x 10 --angles 0,90,180 --json >"$tmp.out" 2>"$tmp.err" &&
   python3 -c '
import json, math, sys
obj = json.loads(open(sys.argv[1]).read())
assert sorted(obj) == sorted(["qext", "qsca", "qback", "g", "angles_deg", "s1", "s2"]), sorted(obj)
assert obj["angles_deg"] == [0, 90, 180]
assert len(obj["s1"]) == 3 and len(obj["s2"]) == 3 and all(len(p) == 2 for p in obj["s1"] + obj["s2"])
def near(got, want, rel=1e-6):
    assert abs(got - want) <= rel * abs(want), (got, want)
near(obj["qext"], 2.232265); near(obj["qsca"], 2.232265); near(obj["g"], 0.8964724)
s1, s2 = obj["s1"], obj["s2"]
near(s1[0][0], 55.80662); near(s1[0][1], -9.758097)
near(s2[1][0], -0.5148748); near(s2[1][1], -0.7027288)
near(s1[2][0], -1.078568); near(s1[2][1], -0.03608807)
# Q_back = 4 |S(180)|^2 / x^2 and the optical theorem Q_ext = 4 Re S(0) / x^2
near(obj["qback"], 4 * (s1[2][0] ** 2 + s1[2][1] ** 2) / 100)
near(obj["qext"], 4 * s1[0][0] / 100)
' "$tmp.out"; then ok "json, Wiscombe case 7"; else bad "json, Wiscombe case 7"; cat "$tmp.err" >&2; fi

# a tiny sphere (the user report: g = -9.8e-4, Q_abs = -2.3e-41): the Rayleigh limit with its
# first corrections (BH 5.1): Q_sca = 8/3 x^4 K^2, g = x^2 (m^2+3)(m^2+2) / (15 (2m^2+3)), no absorption
if "$cli" mie --m 1.33,0 --x 1e-6 --json >"$tmp.out" 2>"$tmp.err" &&
   python3 -c '
import json, sys
o = json.loads(open(sys.argv[1]).read())
m2, x = 1.33 ** 2, 1e-6
K = (m2 - 1) / (m2 + 2)
assert abs(o["qsca"] / (8 / 3 * x ** 4 * K * K) - 1) < 1e-9, o["qsca"]
assert abs(o["g"] / (x * x * (m2 + 3) * (m2 + 2) / (15 * (2 * m2 + 3))) - 1) < 1e-9, o["g"]
assert o["qext"] == o["qsca"], (o["qext"], o["qsca"])
' "$tmp.out" && "$cli" mie --m 1.33,0 --x 1e-6 | grep -q '^Q_abs  = 0$'; then ok "x = 1e-6: Rayleigh limit, g > 0, Q_abs = 0"; else bad "x = 1e-6"; cat "$tmp.out" "$tmp.err" >&2; fi

# default angles: 0, 30, ..., 180 in the human-readable table
if "$cli" mie --m 1.33,-1e-5 --x 100 >"$tmp.out" 2>"$tmp.err" && [ "$(grep -c '^ *[0-9.]* *[-0-9]' "$tmp.out")" -ge 7 ] &&
   grep -q 'Q_ext  = 2.1013' "$tmp.out"; then ok "text output"; else bad "text output"; cat "$tmp.out" >&2; fi

# --help exits 0 and prints usage
if "$cli" mie --help >"$tmp.out" 2>&1 && grep -q '^Usage: atmos mie' "$tmp.out"; then ok "--help"; else bad "--help"; fi

# bad input: exit status 2 with a message naming the problem
expect_usage() {
    name=$1
    shift
    "$cli" mie "$@" >"$tmp.out" 2>"$tmp.err"
    rc=$?
    if [ "$rc" -eq 2 ] && [ -s "$tmp.err" ]; then ok "$name"; else bad "$name (exit $rc)"; fi
}
expect_usage "missing --x" --m 1.33,0
expect_usage "missing --m" --x 10
expect_usage "one-number --m" --m 1.33 --x 10
expect_usage "text --x" --m 1.33,0 --x ten
expect_usage "x = 0" --m 1.33,0 --x 0
expect_usage "x too large" --m 1.33,0 --x 2e5
expect_usage "gain medium" --m 1.33,0.1 --x 10
expect_usage "angle > 180" --m 1.33,0 --x 10 --angles 0,200
expect_usage "empty angle" --m 1.33,0 --x 10 --angles 0,,30
expect_usage "unknown option" --m 1.33,0 --x 10 --frobnicate
if grep -q 'frobnicate' "$tmp.err"; then ok "message names the option"; else bad "message names the option"; fi

exit $fail
