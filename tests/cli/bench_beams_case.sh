#!/bin/sh
# atmos bench beams --case NAME (docs/beams.md, "Speed"): only the named case runs (one line,
# its scene= name), from a --file scene too; a name no case has is a usage error (exit 2)
# naming it. Outside the source tree without --file, the error says to run it from the source
# tree or pass --file.
. "$(dirname "$0")/common.inc"
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}

"$A" bench beams --file "$S/scenes/dobashi_fig04_spotlight.json" --case dobashi_fig04_no_subplanes --repeat 1 \
    --threads 1 >"$T/out.txt" 2>"$T/err.txt"
st=$?
[ $st -eq 0 ] && ok "bench beams --case exits 0" || { bad "bench beams --case: exit $st"; cat "$T/err.txt" >&2; }
[ "$(grep -c '^bench=beams ' "$T/out.txt")" -eq 1 ] && grep -q ' scene=dobashi_fig04_no_subplanes .* fps=' "$T/out.txt" \
    && ok "one line, the named case" || { bad "bench beams --case: not one line of that case"; cat "$T/out.txt" >&2; }
"$A" bench beams --file "$S/scenes/dobashi_fig04_spotlight.json" --case no_such_case --repeat 1 >"$T/out2.txt" 2>"$T/err2.txt"
st=$?
[ $st -eq 2 ] && grep -q "no_such_case" "$T/err2.txt" && [ ! -s "$T/out2.txt" ] && ok "an unknown case is a usage error" \
    || { bad "bench beams --case no_such_case: exit $st"; cat "$T/err2.txt" >&2; }
(cd "$T" && "$A" bench beams --repeat 1 --threads 1 >"$T/out3.txt" 2>"$T/err3.txt")
st=$?
[ $st -eq 1 ] && grep -q "run it from the source tree, or pass --file SCENE" "$T/err3.txt" \
    && ok "outside the source tree: the error says where the scenes are read and --file" \
    || { bad "bench beams outside the source tree: exit $st"; cat "$T/err3.txt" >&2; }
exit $fail
