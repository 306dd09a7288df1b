#!/bin/sh
# atmos render's --lat and --lon are degrees in [-90, 90] and [-180, 180] for every scene, a
# usage error naming the option otherwise (as atmos sun's). Over a round planet they set the
# atmosphere's place, which no scene rule checked on the way: --lon 200 rendered, --lat 95 failed
# in the library with exit 1 and a range of [-360, 360] naming neither option.
. "$(dirname "$0")/common.inc"
check() { # the option the message must name, then the arguments
    want=$1
    shift
    "$A" render "$@" --width 4 --height 4 -q -o "$T/x.png" 2>"$T/err"
    rc=$?
    [ $rc -eq 2 ] && grep -q -- "$want: expected degrees in" "$T/err" && [ ! -e "$T/x.png" ] &&
        ok "$*: exit 2 naming $want" || { bad "$*: exit $rc"; cat "$T/err" >&2; }
}
check --lon --atmosphere spherical --lat 10 --lon 200
check --lat --atmosphere spherical --lat 95 --lon 0
check --lat --atmosphere dobashi --lat -90.5 --lon 0
check --lon --lat 10 --lon -180.5 --time 2026-06-21T12:00:00Z
# the limits themselves are places
"$A" render --lat -90 --lon 180 --time 2026-06-21T12:00:00Z --width 4 --height 4 -q -o "$T/p.png" 2>"$T/err" &&
    [ -s "$T/p.png" ] && ok "--lat -90 --lon 180 renders" || { bad "--lat -90 --lon 180"; cat "$T/err" >&2; }
exit $fail
