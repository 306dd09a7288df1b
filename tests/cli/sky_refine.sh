#!/bin/sh
# `atmos bench sky-accuracy --refine FILE --refine-above X` (docs/sky-accuracy.md, "Re-measuring
# the worst views"), on the quick grid with the production sky only. Checked here (python3):
#  - the seed scheme is kept: with every view picked and no batch beyond the first
#    (--max-paths = --paths), each view's reference is the previous run's to the digit;
#  - with a threshold, exactly the views of FILE above it get more walks (a smaller standard
#    error), every other view keeps FILE's reference, walks and error;
#  - with --refine-sigmas K, also the views within K standard errors of the threshold;
#  - the report lists the picked views; the same figures with 1 and 2 threads;
#  - a FILE that does not fit the run (another grid, another wavelength set, no rows, not a
#    CSV, missing) is refused with a clear message, before any walk.
. "$(dirname "$0")/common.inc"
cli=$A

acc() { "$cli" bench sky-accuracy --quick --models spherical --paths 128 "$@"; }

acc --threads 2 --out "$T/a" >/dev/null 2>"$T/a.err" || { bad "first run failed"; cat "$T/a.err" >&2; exit 1; }
# the median |error of Y| as the threshold: about half the views picked
X=$(python3 -c "
import csv, sys
e = sorted(abs(float(r['rel_err_Y'])) for r in csv.DictReader(open(sys.argv[1])))
print(e[len(e) // 2])" "$T/a/results.csv")
acc --threads 2 --refine "$T/a/results.csv" --refine-above 0 --max-paths 128 --target-se 1e-4 \
    --out "$T/same" >"$T/same.txt" 2>"$T/same.err" || { bad "--refine-above 0 failed"; cat "$T/same.err" >&2; }
acc --threads 2 --refine "$T/a/results.csv" --refine-above "$X" --target-se 0.002 --max-paths 1024 \
    --out "$T/b" >"$T/b.txt" 2>"$T/b.err" || { bad "--refine-above $X failed"; cat "$T/b.err" >&2; }
acc --threads 1 --refine "$T/a/results.csv" --refine-above "$X" --target-se 0.002 --max-paths 1024 \
    --out "$T/b1" >/dev/null 2>&1 || bad "--refine with 1 thread failed"
acc --threads 2 --refine "$T/a/results.csv" --refine-above "$X" --refine-sigmas 1 --target-se 0.002 --max-paths 256 \
    --out "$T/c" >/dev/null 2>&1 || bad "--refine-sigmas 1 failed"
grep -q "Views measured again" "$T/b.txt" && ok "the report lists the views measured again" ||
    bad "no list of the views measured again"

python3 - "$T" "$X" <<'EOF' || fail=1
import csv, sys
T, X = sys.argv[1], float(sys.argv[2])
failed = 0
def check(cond, msg):
    global failed
    if cond: print("ok: " + msg)
    else:
        print("FAIL: " + msg, file=sys.stderr)
        failed = 1
def rows(d):
    return {(r["altitude_m"], r["sun_elevation_deg"], r["view_zenith_deg"], r["view_azimuth_from_sun_deg"]): r
            for r in csv.DictReader(open("%s/%s/results.csv" % (T, d)))}
a, same, b, b1 = rows("a"), rows("same"), rows("b"), rows("b1")
check(len(a) == 28 and set(a) == set(same) == set(b), "the same 28 views in every run")
check(all(same[k]["ref_Y"] == a[k]["ref_Y"] and same[k]["ref_680"] == a[k]["ref_680"] for k in a),
      "every view measured again from its first batch: the previous reference to the digit (its own seed)")
picked = [k for k in a if abs(float(a[k]["rel_err_Y"])) > X]
kept = [k for k in a if k not in picked]
check(0 < len(picked) < len(a), "%d of %d views above the threshold %g" % (len(picked), len(a), X))
# (a standard error from 128 walks is itself noisy: most, not all, shrink)
shrunk = sum(float(b[k]["ref_Y_se"]) < float(a[k]["ref_Y_se"]) for k in picked)
check(all(int(b[k]["paths"]) > 128 for k in picked) and 2 * shrunk > len(picked),
      "the picked views got more walks, most a smaller standard error (%d of %d)" % (shrunk, len(picked)))
def close(x, y, tol):
    return abs(float(x) - float(y)) <= tol * max(1e-30, abs(float(y)))
check(all(b[k]["paths"] == "128" and close(b[k]["ref_Y"], a[k]["ref_Y"], 1e-8) and
          abs(float(b[k]["rel_err_Y"]) - float(a[k]["rel_err_Y"])) < 1e-7 for k in kept),
      "the other views keep the previous reference (to the CSV's 9 digits), walks and error")
check(all(b[k]["ref_Y"] == b1[k]["ref_Y"] and b[k]["paths"] == b1[k]["paths"] for k in b),
      "the same figures with 1 and 2 threads")
text = open(T + "/b.txt").read()
listed = text[text.find("Views measured again"):].splitlines() if "Views measured again" in text else []
n = sum(1 for line in listed if line.startswith("| ") and not line.startswith("| altitude"))
check(n == len(picked), "the list has one row per picked view (%d, %d picked)" % (n, len(picked)))
# --refine-sigmas K: also the views whose error could pass X within K standard errors (relative
# to the errors' denominator, max(Y, 1e-3 x the block's largest Y))
c = rows("c")
bmax = {}
for k in a:
    bmax[k[:2]] = max(bmax.get(k[:2], 0.0), float(a[k]["ref_Y"]))
def could(k):
    den = max(float(a[k]["ref_Y"]), 1e-3 * bmax[k[:2]])
    return abs(float(a[k]["rel_err_Y"])) + (float(a[k]["ref_Y_se"]) / den if den > 0 else 0) > X
wide = [k for k in a if could(k)]
check(len(wide) > len(picked) and all((c[k]["paths"] != "128") == (k in wide) for k in a),
      "--refine-sigmas 1: %d views measured again, the %d within a standard error of the threshold too" % (len(wide), len(wide) - len(picked)))
sys.exit(failed)
EOF

# files that do not fit the run: refused before any walk (a usage error naming --refine)
head -1 "$T/a/results.csv" >"$T/empty.csv"
printf 'a,b\n1,2\n' >"$T/junk.csv"
refused() {
    name=$1 want=$2
    shift 2
    "$cli" bench sky-accuracy --models spherical --paths 128 "$@" >/dev/null 2>"$T/$name.err"
    st=$?
    [ $st -eq "$want" ] && grep -q -- "--refine" "$T/$name.err" && ok "$name refused (exit $st): $(head -1 "$T/$name.err")" ||
        bad "$name: exit $st, $(cat "$T/$name.err")"
}
refused "another grid" 2 --refine "$T/a/results.csv" --altitudes 100
refused "other wavelengths" 2 --quick --spectral 4 --refine "$T/a/results.csv"
refused "no rows" 2 --quick --refine "$T/empty.csv"
refused "not a results.csv" 2 --quick --refine "$T/junk.csv"
refused "a missing file" 1 --quick --refine "$T/none.csv"
"$cli" bench sky-accuracy --quick --refine "$T/a/results.csv" --refine-above -1 >/dev/null 2>"$T/neg.err"
[ $? -eq 2 ] && grep -q -- "--refine-above" "$T/neg.err" && ok "--refine-above -1 is a usage error" ||
    bad "--refine-above -1 should exit 2"
"$cli" bench sky-accuracy --quick --refine "$T/a/results.csv" --refine-sigmas -1 >/dev/null 2>"$T/negs.err"
[ $? -eq 2 ] && grep -q -- "--refine-sigmas" "$T/negs.err" && ok "--refine-sigmas -1 is a usage error" ||
    bad "--refine-sigmas -1 should exit 2"
"$cli" bench sky-accuracy --quick --refine-above 0.02 >/dev/null 2>"$T/alone.err"
[ $? -eq 2 ] && grep -q -- "--refine FILE" "$T/alone.err" && ok "--refine-above without --refine is a usage error" ||
    bad "--refine-above without --refine should exit 2"
exit $fail
