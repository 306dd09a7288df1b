#!/bin/sh
# The render's status lines and warnings say what was done: the path tracer at --max-depth 1 estimates the
# single scattering along each ray and samples no further event, and says so rather than
# "0 scattering events"; a time-lapse's frames each give their simulated minutes.
. "$(dirname "$0")/common.inc"
S="${ATMOS_SOURCE_DIR:-$(dirname "$0")/../..}/scenes"
"$A" render "$S/dobashi_fig04_spotlight.json" --renderer path --max-depth 1 --spp 2 --width 20 --height 30 \
    --pfm "$T/p.pfm" 2>"$T/err" || { bad "path render"; cat "$T/err" >&2; }
grep -q "path: 2 spp, single scattering (max depth 1" "$T/err" && ! grep -q " 0 scattering events" "$T/err" &&
    ok "--max-depth 1: single scattering said" || { bad "--max-depth 1's status"; cat "$T/err" >&2; }
"$A" render "$S/dobashi_fig04_spotlight.json" --renderer path --max-depth 3 --spp 2 --width 20 --height 30 \
    --pfm "$T/p.pfm" 2>"$T/err" || bad "path render, depth 3"
grep -Eq "path: 2 spp, [1-9][0-9]* scattering events" "$T/err" && ok "--max-depth 3: the events counted" ||
    { bad "--max-depth 3's status"; cat "$T/err" >&2; }
"$A" render "$S/simulated_cumulus_timelapse.json" --width 16 --height 9 -D volume.simulate.grid=16 -D animation.frames=2 \
    -D animation.minutes_end=6 --pfm "$T/t.pfm" 2>"$T/err" || { bad "time-lapse"; cat "$T/err" >&2; }
grep -q "cloud at 4 minutes" "$T/err" && grep -q "cloud at 6 minutes" "$T/err" && ok "each frame's minutes said" ||
    { bad "the time-lapse's minutes"; cat "$T/err" >&2; }
# a sun animation of a scene the sun does not light (beams without "beams": {"sun"}, black
# behind): warned that every frame is the same; the default scene's (a sky) is not
"$A" render "$S/dobashi_fig04_spotlight.json" --frames 2 --sun-elevation-end 5 --width 16 --height 24 \
    --pfm "$T/b.pfm" -q 2>"$T/err" || bad "the beams animation"
grep -q "warning: .*sun lights nothing" "$T/err" && ok "a sun animation lighting nothing warned of" ||
    { bad "no warning for a sun animation lighting nothing"; cat "$T/err" >&2; }
"$A" render --frames 2 --sun-elevation-end 5 --width 16 --height 9 --pfm "$T/d.pfm" -q 2>"$T/err" || bad "the sky animation"
[ ! -s "$T/err" ] && ok "no warning for the sky's" || { bad "a warning for the sky's animation"; cat "$T/err" >&2; }
exit $fail
