#!/bin/sh
# `atmos phase` and `atmos cache` end to end. Run by ctest with ATMOS_CLI = the atmos
# binary and ATMOS_TEST_TMP = a scratch directory. XDG_CACHE_HOME points into the
# scratch directory so the test never writes to the user's ~/.cache.
set -u

cli=${ATMOS_CLI:?ATMOS_CLI must name the atmos binary}
scratch=${ATMOS_TEST_TMP:-/tmp}/cli_phase.$$
mkdir -p "$scratch"
XDG_CACHE_HOME=$scratch/xdg
export XDG_CACHE_HOME
fail=0
trap 'rm -rf "$scratch"' EXIT
out=$scratch/out err=$scratch/err

ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }

# expect_status NAME STATUS ARGS... : runs `atmos ARGS` and checks the exit status.
expect_status() {
    name=$1 want=$2
    shift 2
    "$cli" "$@" >"$out" 2>"$err"
    st=$?
    if [ "$st" -eq "$want" ]; then ok "$name (exit $st)"; else bad "$name: exit $st, expected $want"; cat "$err" >&2; fi
}

# The preset list names every preset.
expect_status "phase lists presets" 0 phase
for p in air cloud rain ice snow; do
    if grep -q "^ *$p " "$out"; then ok "list has $p"; else bad "list lacks $p"; fi
done

# CSV of air: exact header, and every column integrates to 1 over the sphere
# (trapezoid 2 pi int P sin(theta) dtheta), and equals Rayleigh 3/(16 pi)(1 + cos^2).
expect_status "phase air --csv" 0 phase air --csv --quiet
if [ "$(head -n 1 "$out")" = "theta_deg,680,550,440" ]; then ok "csv header"; else bad "csv header is '$(head -n 1 "$out")'"; fi
check_csv() {
    python3 - "$1" "$2" <<'PY'
import csv, math, sys
rows = list(csv.reader(open(sys.argv[1])))
header, data = rows[0], [[float(x) for x in r] for r in rows[1:]]
ncol = len(header) - 1
assert ncol == int(sys.argv[2]), "expected %s wavelength columns, got %d" % (sys.argv[2], ncol)
assert len(data) > 1000, "only %d rows" % len(data)
th = [math.radians(r[0]) for r in data]
assert abs(th[0]) < 1e-12 and abs(th[-1] - math.pi) < 1e-9, "grid does not span 0-180"
assert all(b > a for a, b in zip(th, th[1:])), "theta not increasing"
for c in range(1, ncol + 1):
    P = [r[c] for r in data]
    assert all(math.isfinite(p) and p >= 0 for p in P), "column %d has a bad value" % c
    s = sum(0.5 * (P[i] * math.sin(th[i]) + P[i + 1] * math.sin(th[i + 1])) * (th[i + 1] - th[i])
            for i in range(len(th) - 1))
    s *= 2 * math.pi
    assert abs(s - 1) < 1e-4, "column %s integrates to %.8f" % (header[c], s)
PY
}
if check_csv "$out" 3; then ok "air csv integrates to 1"; else bad "air csv normalisation"; fi
if python3 - "$out" <<'PY'
import csv, math, sys
rows = list(csv.reader(open(sys.argv[1])))[1:]
worst = max(abs(float(r[1]) / (3 / (16 * math.pi) * (1 + math.cos(math.radians(float(r[0]))) ** 2)) - 1) for r in rows)
sys.exit(0 if worst < 1e-6 else "max rel error vs Rayleigh %g" % worst)
PY
then ok "air csv is Rayleigh (Riley Eq. 1)"; else bad "air csv differs from Rayleigh"; fi

# Spectral wavelengths: N columns at the bin centres, no trailing zeros.
expect_status "phase air spectral:4" 0 phase air --csv --wavelengths spectral:4 --quiet
if [ "$(head -n 1 "$out")" = "theta_deg,430,530,630,730" ]; then ok "spectral header"; else bad "spectral header is '$(head -n 1 "$out")'"; fi
if check_csv "$out" 4; then ok "spectral csv integrates to 1"; else bad "spectral csv normalisation"; fi

# The first run filled the cache under XDG_CACHE_HOME; the summary says so the next time.
expect_status "cache path" 0 cache path
if [ "$(cat "$out")" = "$XDG_CACHE_HOME/atmos" ]; then ok "cache path follows XDG_CACHE_HOME"; else bad "cache path is '$(cat "$out")'"; fi
n=$(ls "$XDG_CACHE_HOME/atmos" 2>/dev/null | grep -c '\.atmoscache$')
if [ "$n" -ge 2 ]; then ok "tables cached ($n entries)"; else bad "expected cache entries, found $n"; fi
expect_status "phase air summary" 0 phase air
if grep -q "from the cache" "$out" && grep -q "sigma_ext" "$out"; then ok "summary from the cache"; else bad "summary: $(cat "$out")"; fi
# --no-cache writes nothing new and does not read.
"$cli" cache clear >/dev/null 2>&1
expect_status "phase air --no-cache" 0 phase air --no-cache
n=$(ls "$XDG_CACHE_HOME/atmos" 2>/dev/null | grep -c '\.atmoscache$')
if [ "$n" -eq 0 ] && ! grep -q "from the cache" "$out"; then ok "--no-cache"; else bad "--no-cache left $n entries"; fi
# A corrupt entry: warned on stderr, rebuilt, exit 0.
"$cli" phase air --quiet >/dev/null 2>&1
entry=$(ls "$XDG_CACHE_HOME"/atmos/*.atmoscache 2>/dev/null | head -n 1)
if [ -n "$entry" ]; then
    printf 'garbage' | dd of="$entry" bs=1 seek=0 conv=notrunc 2>/dev/null
    expect_status "corrupt cache entry" 0 phase air
    if grep -q "warning: cache:.*atmoscache" "$err"; then ok "corrupt entry reported"; else bad "no warning about the corrupt entry"; fi
else
    bad "no cache entry to corrupt"
fi
expect_status "cache clear" 0 cache clear
if grep -q "removed" "$out"; then ok "cache clear reports"; else bad "cache clear printed '$(cat "$out")'"; fi

# Bad input: exit 2, a message naming the known presets, nothing on stdout.
expect_status "unknown preset" 2 phase no-such-preset
if grep -q "air" "$err" && grep -q "snow" "$err"; then ok "message names the presets"; else bad "message: $(cat "$err")"; fi
if [ -s "$out" ]; then bad "unknown preset wrote to stdout"; fi
expect_status "bad --wavelengths" 2 phase air --wavelengths spectral:0
expect_status "bad --wavelengths word" 2 phase air --wavelengths purple
expect_status "unknown option" 2 phase air --frobnicate
expect_status "cache bad action" 2 cache nuke
expect_status "--help" 0 phase --help

# --plot: a PNG (8-byte signature), written through a temporary name.
if command -v gnuplot >/dev/null 2>&1; then
    expect_status "phase air --plot" 0 phase air --plot "$scratch/air.png" --quiet
    sig=$(od -An -tx1 -N8 "$scratch/air.png" 2>/dev/null | tr -d ' \n')
    if [ "$sig" = "89504e470d0a1a0a" ]; then ok "--plot wrote a PNG"; else bad "--plot: signature '$sig'"; fi
    if ls "$scratch"/air.png.tmp* >/dev/null 2>&1; then bad "--plot left a temporary file"; else ok "no temporary left"; fi
else
    echo "skip: gnuplot is not installed; --plot not tested (Debian: gnuplot-nox)"
    expect_status "phase --plot without gnuplot" 1 phase air --plot "$scratch/air.png" --quiet
fi

exit $fail
