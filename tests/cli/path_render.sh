#!/bin/sh
# atmos render --renderer path through the CLI: a tiny image of a generated cumulus, the same
# bytes for 1 and 2 threads (also with --truncate and each --no-* switch), the --variance and --order outputs,
# --time-budget, bad values.
set -u
. "$(dirname "$0")/common.inc"
P="--renderer path --volume generate:cumulus --width 24 --height 16 --spp 4"

"$A" render -q $P --threads 1 --pfm "$T/a.pfm" && ok || bad "path render, 1 thread"
"$A" render -q $P --threads 2 --pfm "$T/b.pfm" --variance "$T/var.exr" --order "$T/order.pfm" \
    && ok || bad "path render, 2 threads, --variance --order"
cmp -s "$T/a.pfm" "$T/b.pfm" && ok || bad "1 and 2 threads differ"
# --truncate: thread-independent too; --truncate 0 is the exact default
"$A" render -q $P --threads 1 --truncate 3 --pfm "$T/c.pfm" && ok || bad "path render --truncate 3, 1 thread"
"$A" render -q $P --threads 2 --truncate 3 --pfm "$T/d.pfm" && ok || bad "path render --truncate 3, 2 threads"
cmp -s "$T/c.pfm" "$T/d.pfm" && ok || bad "--truncate: 1 and 2 threads differ"
cmp -s "$T/a.pfm" "$T/c.pfm" && bad "--truncate 3 changed nothing" || ok
"$A" render -q $P --threads 2 --truncate 0 --pfm "$T/e.pfm" && ok || bad "path render --truncate 0"
cmp -s "$T/a.pfm" "$T/e.pfm" && ok || bad "--truncate 0 differs from the default"
# the --no-* switches: each changes the image (another estimator), each stays thread-independent
for sw in --no-sky-nee --no-forced --no-aureole; do
    "$A" render -q $P --threads 1 $sw --pfm "$T/s1.pfm" && ok || bad "path render $sw, 1 thread"
    "$A" render -q $P --threads 2 $sw --pfm "$T/s2.pfm" && ok || bad "path render $sw, 2 threads"
    cmp -s "$T/s1.pfm" "$T/s2.pfm" && ok || bad "$sw: 1 and 2 threads differ"
    cmp -s "$T/a.pfm" "$T/s1.pfm" && bad "$sw changed nothing" || ok
    "$A" render -q $sw -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "$sw without --renderer path should exit 2"
done
[ -s "$T/var.exr" ] && ok || bad "--variance file not written"
python3 - "$T/b.pfm" "$T/order.pfm" <<'PY' && ok || bad "image / order check"
import sys, pfm
def finite_nonneg(v):
    s = pfm.stats(v)
    return s.nonfinite == 0 and s.min >= 0
i = pfm.read(sys.argv[1]); w, h, c, img = i.w, i.h, i.c, i.v
assert (w, h, c) == (24, 16, 3), (w, h, c)
assert finite_nonneg(img), "bad pixel values"
i = pfm.read(sys.argv[2]); w, h, c, o = i.w, i.h, i.c, i.v
assert (w, h, c) == (24, 16, 1), (w, h, c)
assert finite_nonneg(o), "bad order values"
# the sky pixels carry light that never met the volume (order 0); the cloud's carry more
assert min(o) == 0 and max(o) >= 1, (min(o), max(o))
PY
# --time-budget: stops when the budget runs out (tests/cli/path_run.sh: inside a pass)
"$A" render $P --spp 1000000 --time-budget 0.2 --threads 2 --pfm "$T/t.pfm" 2> "$T/t.log" && ok || bad "--time-budget"
grep -q "path: [0-9]* spp" "$T/t.log" && ! grep -q "path: 1000000 spp" "$T/t.log" && ok || bad "--time-budget did not stop early"
# bad values: usage errors exit 2
for args in "--spp 0" "--spp 1000001" "--time-budget -1" "--seed x" "--seed 9007199254740993" "--threads 0" "--truncate 21" "--truncate -1"; do
    "$A" render -q $P $args -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "'$args' should exit 2"
done
"$A" render -q --order "$T/o.pfm" -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--order without --renderer path should exit 2"
"$A" render -q --variance "$T/v.exr" -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--variance without --renderer path should exit 2"
"$A" render -q --truncate 3 -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--truncate without --renderer path should exit 2"
rm -rf "$T"
echo "path_render: $pass passed"
[ "$fail" -eq 0 ]
