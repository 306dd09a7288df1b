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
# (analytic particle types: no optics tables to build)
cat >"$T/tl.json" <<EOF2
{"image": {"width": 16, "height": 9}, "wavelengths": {"mode": "rgb"}, "renderer": "slice",
 "camera": {"type": "pinhole", "position_m": [0, 400, 0], "view": {"elevation_deg": 12, "azimuth_deg": 0}, "fov_deg": 55},
 "particles": {"cloud": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.85, "weight": 1}], "sigma_ext_m2": 2e-10},
               "rain": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.9, "weight": 1}], "sigma_ext_m2": 2e-6}},
 "volume": {"simulate": {"preset": "towering_cumulus", "minutes": 4, "grid": 16, "seed": 1}, "position_m": [0, 0, -12000]},
 "slice": {"slices": 32, "light_size": 32}, "animation": {"frames": 2, "minutes_end": 6}}
EOF2
"$A" render "$T/tl.json" --pfm "$T/t.pfm" 2>"$T/err" || { bad "time-lapse"; cat "$T/err" >&2; }
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
