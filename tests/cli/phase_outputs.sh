#!/bin/sh
# `atmos phase`: its output and the rules between its options are checked before any work,
# as every command's (README: exit 2 for a usage error). Run by ctest with ATMOS_CLI = the
# atmos binary.
#  - --plot writes a PNG: another extension is a usage error naming .png, and nothing is
#    written; a missing scene file given too is not read first (the error is the usage one).
#  - --max-order goes with --orders: without it a usage error, before the scene is read.
#  - --plot into a folder that does not exist makes the folder (as render's outputs do).
. "$(dirname "$0")/common.inc"

# usage NAME WORD ARGS...: exit 2, stderr names WORD
usage() {
    name=$1 word=$2
    shift 2
    "$A" phase "$@" >"$T/out" 2>"$T/err"
    st=$?
    if [ "$st" -eq 2 ] && grep -q -- "$word" "$T/err"; then ok "$name"; else
        bad "$name: exit $st, stderr: $(cat "$T/err")"; fi
}

usage "--plot x.txt" ".png" air --plot "$T/air.txt" -q
[ ! -e "$T/air.txt" ] && ok "--plot x.txt wrote nothing" || bad "--plot x.txt wrote $T/air.txt"
usage "--plot x.txt before the scene is read" ".png" rain --plot "$T/r.txt" --scene "$T/missing.json"
usage "--max-order without --orders" "--orders" air --max-order 3
usage "--max-order without --orders before the scene is read" "--orders" rain --max-order 3 --scene "$T/missing.json"

if command -v gnuplot >/dev/null 2>&1; then
    "$A" phase air --plot "$T/new/sub/air.png" -q 2>"$T/err" && [ -s "$T/new/sub/air.png" ] &&
        ok "--plot makes a missing folder" || bad "--plot into a new folder: $(cat "$T/err")"
else
    echo "skip: gnuplot is not installed; --plot's folder not tested"
fi
exit $fail
