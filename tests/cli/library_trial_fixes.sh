#!/bin/sh
# What a trial of the library, the sky models and Harris's renderer found in the CLI:
#  1. atmos sky --altitude takes what a scene's camera y takes, [0, 1e8] m (it took 2e8,
#     which atmos render refuses);
#  2. a round model with "aerosol": "none" warns that turbidity and visibility_km set nothing
#     (as the flat models warn about the keys they do not read); without them, no warning.
. "$(dirname "$0")/common.inc"
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }
hasnt() { grep -qF -- "$2" "$T/err" && { bad "$1: '$2' in:"; sed 's/^/  /' "$T/err" >&2; } || ok "$1: no '$2'"; }

# --- 1
"$A" sky --sun-elevation 10 --view-elevation 0 --view-azimuth 0 --altitude 2e8 >/dev/null 2>"$T/err"
[ $? -eq 2 ] && ok "sky --altitude 2e8 is a usage error" || bad "sky --altitude 2e8 accepted"
has "sky --altitude 2e8" "must be in [0, 100000000]"
"$A" sky --sun-elevation 10 --view-elevation -90 --view-azimuth 0 --altitude 1e8 --model riley >/dev/null 2>"$T/err" \
    && ok "sky --altitude 1e8 (the bound) answers" || { bad "sky --altitude 1e8:"; cat "$T/err" >&2; }

# --- 2
small="--width 8 --height 6 -D atmosphere.model=dobashi -D atmosphere.aerosol=none"
# shellcheck disable=SC2086
"$A" render $small -D atmosphere.turbidity=5 -D atmosphere.visibility_km=20 --pfm "$T/a.pfm" 2>"$T/err" \
    || bad "render with turbidity and aerosol none"
has "aerosol none with turbidity and visibility" "visibility_km and turbidity set nothing"
# shellcheck disable=SC2086
"$A" render $small --pfm "$T/b.pfm" 2>"$T/err" || bad "render with aerosol none"
hasnt "aerosol none alone" "set nothing"
exit $fail
