#!/bin/sh
# atmos simulate checks every file it will write (the .json sidecar and each NAME.FIELD.raw)
# before the run, and writes all or none: a folder in the way of one field's file fails at
# once (no simulation run, no other field's file left); NAME.JSON names its raw files as
# NAME.json does.
. "$(dirname "$0")/common.inc"
mkdir -p "$T/o/x.rain.raw"
"$A" simulate cumulus_field -o "$T/o/x.json" --grid 16 --minutes 3 -q 2>"$T/err"
rc=$?
[ $rc -eq 1 ] && grep -q "x.rain.raw" "$T/err" && grep -q "folder" "$T/err" && ok "a folder in the way of x.rain.raw refused" ||
    { bad "x.rain.raw a folder: exit $rc"; cat "$T/err" >&2; }
[ "$(ls "$T/o")" = "x.rain.raw" ] && ok "nothing else written" || bad "left: $(ls "$T/o" | tr '\n' ' ')"
# --ice: the ice field's file is checked too
mkdir -p "$T/o/i.ice.raw"
"$A" simulate cumulus_field -o "$T/o/i.json" --grid 16 --minutes 3 --ice -q 2>"$T/err"
rc=$?
[ $rc -eq 1 ] && grep -q "i.ice.raw" "$T/err" && [ ! -e "$T/o/i.cloud.raw" ] && [ ! -e "$T/o/i.json" ] &&
    ok "--ice: a folder in the way of i.ice.raw refused, nothing written" || { bad "--ice: exit $rc"; cat "$T/err" >&2; }
# the sidecar itself a folder: refused before the run (no progress, no state)
mkdir -p "$T/o/y.json"
"$A" simulate cumulus_field -o "$T/o/y.json" --grid 16 --minutes 3 2>"$T/err"
rc=$?
[ $rc -eq 1 ] && grep -q "y.json" "$T/err" && ! grep -q "wrote\|%" "$T/err" && [ ! -e "$T/o/y.cloud.raw" ] &&
    ok "-o a folder refused before the run" || { bad "-o a folder: exit $rc"; cat "$T/err" >&2; }
# NAME.JSON: raw files NAME.FIELD.raw, as for NAME.json
"$A" simulate stratocumulus --grid 16 --minutes 0.5 -o "$T/s.JSON" -q 2>"$T/err" || { bad "s.JSON"; cat "$T/err" >&2; }
[ -s "$T/s.cloud.raw" ] && [ ! -e "$T/s.JSON.cloud.raw" ] && ok "s.JSON writes s.cloud.raw" || bad "s.JSON's raw names: $(ls "$T")"
# a grid past the 64 M voxels: refused at once (a usage error naming --grid), the command named
# once, the limit in --help
"$A" simulate cumulonimbus --grid 512 -o "$T/cb.json" -q 2>"$T/err"
rc=$?
[ $rc -eq 2 ] && grep -q -- "--grid 512: .*64 M" "$T/err" && ! grep -q "simulate: simulate:" "$T/err" && [ ! -e "$T/cb.json" ] &&
    ok "--grid 512 for cumulonimbus refused, the prefix once" || { bad "--grid 512: exit $rc"; cat "$T/err" >&2; }
"$A" simulate --help | grep -A6 -- "--grid N" | grep -q "64 M" && ok "--help states --grid's limit" || bad "--grid's limit not in --help"
# stratocumulus at --grid 16: 8 levels of 400 m (the floor of 8 levels), and --help says so
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["dims"] == [16, 8, 16] and abs(d["voxel_size_m"] - 400) < 1e-9, d' \
    "$T/s.JSON" && ok "stratocumulus at grid 16: 16 x 8 x 16 cells of 400 m" || bad "stratocumulus at grid 16: $(cat "$T/s.JSON")"
"$A" simulate --help | grep -A4 -- "--grid N" | grep -q "at least 8 levels" && ok "--help states the 8 levels" ||
    bad "--help silent on the 8 levels"
# a missing folder is made and kept for the volume (README: atmos simulate cumulus_field -o
# sim/cf.json); it used to be made for the check and removed again before the run, whose
# write then failed after the whole simulation ("sim/cf.cloud.raw.staged: cannot create")
"$A" simulate stratocumulus --grid 16 --minutes 0.5 -o "$T/new/deep/s.json" -q 2>"$T/err"
rc=$?
[ $rc -eq 0 ] && [ -s "$T/new/deep/s.json" ] && [ -s "$T/new/deep/s.cloud.raw" ] && [ -s "$T/new/deep/s.rain.raw" ] &&
    [ "$(ls -A "$T/new/deep" | wc -l)" -eq 3 ] && ok "-o into missing folders: made, the volume there, no staging file left" ||
    { bad "-o into missing folders: exit $rc, files: $(ls -A "$T/new/deep" 2>&1 | tr '\n' ' ')"; cat "$T/err" >&2; }
# a run that fails after the check (the voxel limit, found when the simulation is made) leaves no
# folder of those it made
"$A" simulate cumulonimbus --grid 512 --refine 4 -o "$T/gone/a/x.json" -q 2>"$T/err"
rc=$?
[ $rc -eq 2 ] && [ ! -e "$T/gone" ] && ok "a failed run removes the folders it made" || bad "failed run: exit $rc, $(ls -R "$T/gone" 2>&1)"
exit $fail
