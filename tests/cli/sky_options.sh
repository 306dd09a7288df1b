#!/bin/sh
# `atmos sky`: options that do not apply are refused, and --table list says which models
# keep tables. Run by ctest with ATMOS_CLI = the atmos binary.
#  - --thickness belongs to --model homogeneous: with riley, dobashi or spherical it is a
#    usage error (exit 2) naming homogeneous, as `atmos render` refuses another renderer's
#    options; with homogeneous it changes the result (1 km vs 8 km of air).
#  - -o belongs to --table; the view options (--sun-elevation ..., --json) do not apply to
#    --table: usage errors naming the option.
#  - --table list without --model (the default, riley, keeps none) names the models that keep
#    tables and their tables; with --model spherical one name per line; a table of another
#    model is refused naming the model that keeps it, before any table is built.
. "$(dirname "$0")/common.inc"
cli=$A

view="--sun-elevation 30 --view-elevation 10 --view-azimuth 90"

# expect_usage NAME WORD ARGS...: exit 2, nothing on stdout, stderr names WORD
expect_usage() {
    name=$1 word=$2
    shift 2
    "$cli" sky "$@" >"$T/out" 2>"$T/err"
    st=$?
    if [ "$st" -eq 2 ] && [ ! -s "$T/out" ] && grep -q -- "$word" "$T/err"; then
        ok "$name"
    else
        bad "$name: exit $st, stderr: $(cat "$T/err"), stdout: $(head -c 200 "$T/out")"
    fi
}

# shellcheck disable=SC2086
{
    expect_usage "--thickness with the default model" homogeneous $view --thickness 100
    expect_usage "--thickness with --model riley" homogeneous $view --model riley --thickness 100
    expect_usage "--thickness with --atmosphere spherical" homogeneous $view --atmosphere spherical --thickness 100
    expect_usage "--thickness with --model dobashi" homogeneous $view --thickness 100 --model dobashi
    expect_usage "-o without --table" "--table" $view -o "$T/x.exr"
    expect_usage "--sun-elevation with --table" "--sun-elevation" --model spherical --table transmittance -o "$T/t.exr" --sun-elevation 30
    expect_usage "--json with --table" "--json" --model spherical --table list --json
    expect_usage "--view-azimuth with --table" "--view-azimuth" --table list --view-azimuth 3
    # a table of another model: named with the model that keeps it, nothing written
    expect_usage "a spherical table without --model" "spherical" --table transmittance -o "$T/t.exr"
    expect_usage "a dobashi table with --model spherical" "dobashi" --model spherical --table plane_mie -o "$T/t.exr"
    [ ! -e "$T/t.exr" ] && ok "no file written" || bad "a refused --table wrote $T/t.exr"

    # --thickness with its model: accepted and it matters (the optical depth of 1 km vs 8 km)
    "$cli" sky --json $view --model homogeneous --thickness 1000 >"$T/thin.json" 2>"$T/err" &&
        "$cli" sky --json $view --model homogeneous >"$T/thick.json" 2>>"$T/err" &&
        python3 -c '
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert all(x > y for x, y in zip(a["transmittance"], b["transmittance"])), (a, b)
' "$T/thin.json" "$T/thick.json" && ok "--thickness with --model homogeneous thins the layer" ||
        bad "--model homogeneous --thickness: $(cat "$T/err")"
}

# --table list without --model: which models keep tables, and theirs
"$cli" sky --table list >"$T/list" 2>"$T/err"
st=$?
if [ "$st" -eq 0 ] && grep -q '^riley.*no tables' "$T/list" && grep -q '^homogeneous.*no tables' "$T/list" &&
    grep -q '^spherical: .*transmittance' "$T/list" && grep -q '^dobashi: .*sun_attenuation' "$T/list"; then
    ok "--table list names the models that keep tables"
else
    bad "--table list: exit $st: $(cat "$T/list" "$T/err")"
fi
# with a model that keeps tables: one name per line, nothing else
"$cli" sky --model dobashi --table list >"$T/list" 2>"$T/err"
if [ "$(cat "$T/list")" = "sun_attenuation
plane_rayleigh
plane_mie
plane_attenuation" ]; then ok "--model dobashi --table list: one name per line"; else bad "dobashi list: $(cat "$T/list" "$T/err")"; fi
# with a model that keeps none: says so and names the ones that do
"$cli" sky --model homogeneous --table list >"$T/list" 2>"$T/err"
grep -q 'homogeneous.*no tables' "$T/list" "$T/err" && grep -q 'spherical' "$T/list" "$T/err" &&
    ok "--model homogeneous --table list says it keeps none" || bad "homogeneous list: $(cat "$T/list" "$T/err")"

# -o into a folder that does not exist: the folder is made, as render's outputs'
"$cli" sky --model dobashi --table sun_attenuation -o "$T/new/sub/t.pfm" >"$T/out" 2>"$T/err" && [ -s "$T/new/sub/t.pfm" ] &&
    ok "--table -o into a new folder" || bad "--table -o into a new folder: $(cat "$T/err")"

# a table as EXR: channels "<table>.<nm>nm" (not "440.00nm", which OpenEXR reads as channel
# "00nm" of layer "440"), its units in atmos:units, no chromaticities (it is not an RGB image)
"$cli" sky --model dobashi --table sun_attenuation -o "$T/gl.exr" >"$T/out" 2>"$T/err" &&
    python3 "$(dirname "$0")/exr_header.py" "$T/gl.exr" >"$T/hdr" || bad "--table -o x.exr: $(cat "$T/err")"
grep -q '^channels chlist sun_attenuation.440nm,sun_attenuation.550nm,sun_attenuation.680nm$' "$T/hdr" &&
    ok "--table EXR: channels named <table>.<nm>nm" || bad "--table EXR channels: $(grep '^channels' "$T/hdr")"
grep -q '^atmos:units string 1: g_l' "$T/hdr" && ok "--table EXR: units" || bad "--table EXR units: $(grep -c units "$T/hdr")"
grep -q '^chromaticities' "$T/hdr" && bad "--table EXR has chromaticities" || ok "--table EXR: no chromaticities"

# the help says what --table list does
"$cli" sky --help >"$T/help" 2>&1
grep -q 'table list' "$T/help" && grep -q 'goes with' "$T/help" && ok "help" || bad "help: $(cat "$T/help")"
exit $fail
