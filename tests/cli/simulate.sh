#!/bin/sh
# `atmos simulate` end to end: usage errors exit 2 with a message and write nothing; a small
# run writes the sidecar and one raw file per field (cloud, rain) whose sizes match the grid,
# with cloud in it; the same seed gives the same bytes with 1, 2 and 3 threads; -o names only
# a .json sidecar; a run too short for cloud warns; atmos bench simulate prints its line.
# Run by ctest with ATMOS_CLI = path of the atmos binary.
set -u

cli=${ATMOS_CLI:?ATMOS_CLI must name the atmos binary}
fail=0
dir=${ATMOS_TEST_TMP:-/tmp}/cli_simulate.$$
mkdir -p "$dir"
trap 'rm -rf "$dir"' EXIT

ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }

usage() { # expect exit 2, a message naming $1, no output file
    want=$1; shift
    timeout 30 "$cli" simulate "$@" >"$dir/out" 2>"$dir/err" # a usage error comes at once
    rc=$?
    if [ $rc -eq 2 ] && grep -q -- "$want" "$dir/err" && [ ! -e "$dir/x.json" ]; then ok "simulate $*: $want"
    else bad "simulate $*: exit $rc, stderr: $(cat "$dir/err")"; fi
}
usage "unknown preset 'cirrus'" cirrus -o "$dir/x.json"
usage "which preset" -o "$dir/x.json"
usage "missing -o" cumulus_field
usage "--grid" cumulus_field --grid 8 -o "$dir/x.json"
usage "--minutes" cumulus_field --minutes 0 -o "$dir/x.json"
usage "--minutes" cumulus_field --minutes abc -o "$dir/x.json"
usage "--seed" cumulus_field --seed -1 -o "$dir/x.json"
usage "unknown or incomplete option" cumulus_field --bogus -o "$dir/x.json"
"$cli" simulate --help | grep -q "towering_cumulus" && ok "--help lists the presets" || bad "--help"
# an output it cannot write is refused before any work: a 512-cell grid for 600 minutes would
# take hours, so a quick exit shows nothing was computed
for ext in vdb nvdb png raw; do
    usage "writes only a raw volume" stratocumulus --grid 512 --minutes 600 --quiet -o "$dir/x.$ext"
    [ -e "$dir/x.$ext" ] && bad "-o x.$ext: a file was written"
done
"$cli" simulate --help > "$dir/help"
missing=""
for p in cumulus_field towering_cumulus cumulonimbus stratocumulus; do
    grep -q "$p.*first cloud after" "$dir/help" || missing="$missing $p"
done
[ -z "$missing" ] && ok "--help gives each preset's first-cloud time" || bad "--help: no first-cloud time for$missing"

# a run too short for any cloud: the files are written, with a warning on stderr that the volume
# is empty and what to do about it; a run with cloud gives no such warning
if "$cli" simulate towering_cumulus --grid 16 --minutes 0.5 --quiet -o "$dir/e.json" 2>"$dir/err"; then
    if grep -q "empty" "$dir/err" && grep -q -- "--minutes" "$dir/err" && [ -e "$dir/e.json" ]; then
        ok "an empty volume is reported"
    else bad "no warning for an empty volume: $(cat "$dir/err")"; fi
else bad "short run failed: $(cat "$dir/err")"; fi

# stratocumulus starts with its deck: a 16-cell grid, half a minute
for t in 1 2 3; do
    if "$cli" simulate stratocumulus --grid 16 --minutes 0.5 --threads $t --quiet -o "$dir/s$t.json" 2>"$dir/err"; then
        ok "run with $t threads"
    else bad "run with $t threads: $(cat "$dir/err")"; fi
done
python3 - "$dir" <<'PY' && ok "sidecar, raw sizes, cloud present" || bad "output files"
import json, os, struct, sys
d = sys.argv[1]
j = json.load(open(os.path.join(d, "s1.json")))
text = json.dumps(j)
assert "cloud" in text and "rain" in text, text
dims = j["dims"]
n = dims[0] * dims[1] * dims[2]
raws = sorted(f for f in os.listdir(d) if f.startswith("s1") and f.endswith(".raw"))
assert len(raws) == 2, raws
for r in raws:
    assert os.path.getsize(os.path.join(d, r)) == 4 * n, (r, os.path.getsize(os.path.join(d, r)), n)
cloud = [f for f in raws if "cloud" in f][0]
v = struct.unpack("<%df" % n, open(os.path.join(d, cloud), "rb").read())
assert max(v) > 1e6, max(v)
PY
grep -q "empty" "$dir/err" && bad "stratocumulus (a deck from the start) reported empty: $(cat "$dir/err")"
for f in "$dir"/s1*.raw; do
    for t in 2 3; do
        g="$dir/s$t${f#"$dir"/s1}"
        cmp -s "$f" "$g" || bad "1 and $t threads differ: $(basename "$f")"
    done
done
[ $fail -eq 0 ] && ok "1, 2 and 3 threads give the same raw files"

# atmos bench simulate: one machine-readable line with the figures
if "$cli" bench simulate --size 16 --repeat 2 --threads 2 >"$dir/bench" 2>"$dir/err" &&
    grep -Eq '^bench=simulate preset=towering_cumulus grid=16 cells=16x16x16 threads=2 steps=2 ms_per_step=[0-9.]+ best_ms=[0-9.]+ cpu_ms_per_step=[0-9.]+ load=' "$dir/bench"; then
    ok "bench simulate"
else bad "bench simulate: $(cat "$dir/bench" "$dir/err")"; fi
# a grid the simulation does not take is a usage error (exit 2) naming its range
"$cli" bench simulate --size 1000 >"$dir/bench" 2>"$dir/err"
st=$?
[ $st -eq 2 ] && grep -q "16, 512" "$dir/err" && ok "bench simulate --size 1000: usage error" ||
    bad "bench simulate --size 1000: exit $st, $(cat "$dir/err")"
exit $fail
