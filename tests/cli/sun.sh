#!/bin/sh
# `atmos sun` end to end. Run by ctest with ATMOS_CLI = path of the atmos binary.
# Reference values (also used in tests/unit/test_sunpos.c):
#  - Reda & Andreas, Solar Position Algorithm for Solar Radiation Applications,
#    NREL/TP-560-34302, Table A5.1: 2003-10-17 12:30:30 UTC-7, lat 39.742476,
#    lon -105.1786: elevation without refraction e0 = 39.872046 deg (topocentric;
#    ours is geocentric, ~0.002 deg higher), azimuth 194.340241 deg.
#  - Meeus, Astronomical Algorithms 2nd ed., Ex. 25.a: 1992 Oct 13.0, apparent
#    declination -7.78507 deg.
set -u

cli=${ATMOS_CLI:?ATMOS_CLI must name the atmos binary}
fail=0
tmp=${ATMOS_TEST_TMP:-/tmp}/cli_sun.$$
trap 'rm -f "$tmp.out" "$tmp.err"' EXIT

ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }

# check_json NAME EXPECTED_KEY=VALUE... : stdout in $tmp.out must be exactly one
# JSON object whose listed keys are within 0.01 of the given values.
check_json() {
    name=$1
    shift
    if python3 -c '
import json, math, sys
text = open(sys.argv[1]).read()
obj = json.loads(text)  # raises on anything but exactly one JSON value
assert isinstance(obj, dict), "not an object"
for key in ("elevation_deg", "azimuth_deg"):
    assert key in obj, "missing " + key
for k, v in obj.items():
    assert isinstance(v, (int, float)) and math.isfinite(v), "%s not a finite number" % k
for spec in sys.argv[2:]:
    key, want = spec.split("=")
    got = obj[key]
    if abs(got - float(want)) > 0.01:
        sys.exit("%s = %r, expected %s +- 0.01" % (key, got, want))
' "$tmp.out" "$@"; then ok "$name"; else bad "$name"; fi
}

# expect_status NAME STATUS ARGS... : runs `atmos sun ARGS` and checks the exit status.
expect_status() {
    name=$1 want=$2
    shift 2
    "$cli" sun "$@" >"$tmp.out" 2>"$tmp.err"
    st=$?
    if [ "$st" -eq "$want" ]; then ok "$name (exit $st)"; else bad "$name: exit $st, expected $want"; cat "$tmp.err" >&2; fi
}

# NREL SPA example, geometric elevation.
expect_status "spa --json" 0 --time 2003-10-17T12:30:30-07:00 --lat 39.742476 --lon -105.1786 \
    --no-refraction --json
check_json "spa values" elevation_deg=39.872046 azimuth_deg=194.340241

# With refraction the sun is higher, azimuth unchanged.
expect_status "spa --json refracted" 0 --time 2003-10-17T12:30:30-07:00 --lat 39.742476 \
    --lon -105.1786 --json
check_json "spa refracted" elevation_deg=39.888378 azimuth_deg=194.340241

# Meeus Ex. 25.a declination (same instant in UTC; the place does not matter).
expect_status "meeus --json" 0 --time 1992-10-13T00:00:00Z --lat 0 --lon 0 --json
check_json "meeus declination" declination_deg=-7.78507

# Human-readable output mentions the quantities.
expect_status "plain output" 0 --time 2026-06-21T12:00:00Z --lat 40 --lon -105
for word in elevation azimuth declination "equation of time"; do
    if grep -q "$word" "$tmp.out"; then ok "plain output has '$word'"; else bad "plain output lacks '$word'"; fi
done

expect_status "--help" 0 --help
if grep -q -- "--time" "$tmp.out"; then ok "--help prints usage"; else bad "--help printed no usage"; fi

# Bad input: exit 2, a message on stderr, nothing on stdout.
usage_case() {
    name=$1
    shift
    expect_status "$name" 2 "$@"
    if [ -s "$tmp.err" ]; then ok "$name: message on stderr"; else bad "$name: no message on stderr"; fi
    if [ -s "$tmp.out" ]; then bad "$name: wrote to stdout"; fi
}
usage_case "impossible date" --time 2026-02-30T00:00:00Z --lat 40 --lon -105 --json
usage_case "month 13" --time 2026-13-01T00:00Z --lat 40 --lon -105
usage_case "missing zone" --time 2026-06-21T12:00 --lat 40 --lon -105
usage_case "space separator" --time "2026-06-21 12:00" --lat 40 --lon -105
usage_case "latitude out of range" --time 2026-06-21T12:00:00Z --lat 91 --lon 0
usage_case "longitude out of range" --time 2026-06-21T12:00:00Z --lat 0 --lon 181
usage_case "year out of range" --time 1700-06-21T12:00:00Z --lat 0 --lon 0
usage_case "not a number" --time 2026-06-21T12:00:00Z --lat abc --lon 0
usage_case "missing --time" --lat 40 --lon -105
usage_case "missing --lon" --time 2026-06-21T12:00:00Z --lat 40
usage_case "missing value" --time 2026-06-21T12:00:00Z --lat 40 --lon
usage_case "unknown option" --time 2026-06-21T12:00:00Z --lat 40 --lon 0 --bogus

exit $fail
