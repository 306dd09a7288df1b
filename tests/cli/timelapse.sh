#!/bin/sh
# A time-lapse of a simulated cloud (docs/clouds.md, "Time-lapse"): "animation": {"minutes_end"}
# carries one simulation from frame to frame; each frame equals a single render of the scene at
# that frame's minutes, byte for byte; the cloud changes between frames; minutes_end without a
# simulated volume is refused by name.
. "$(dirname "$0")/common.inc"
# analytic particle types in the place of the presets' (no optics tables to build)
cat >"$T/s.json" <<EOF
{"image": {"width": 32, "height": 18}, "wavelengths": {"mode": "rgb"}, "renderer": "slice",
 "camera": {"type": "pinhole", "position_m": [0, 400, 0], "view": {"elevation_deg": 12, "azimuth_deg": 0}, "fov_deg": 55},
 "sun": {"elevation_deg": 35, "azimuth_deg": 120},
 "particles": {"cloud": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.85, "weight": 1}], "sigma_ext_m2": 2e-10},
               "rain": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.9, "weight": 1}], "sigma_ext_m2": 2e-6}},
 "volume": {"simulate": {"preset": "towering_cumulus", "minutes": 9, "grid": 16, "seed": 1}, "position_m": [0, 0, -12000]},
 "slice": {"slices": 64, "light_size": 64},
 "animation": {"frames": 3, "minutes_end": 12}}
EOF
"$A" render "$T/s.json" --pfm "$T/t.pfm" -q 2>"$T/err" || { bad "time-lapse render"; cat "$T/err" >&2; }
for i in 1 2 3; do [ -s "$T/t_000$i.pfm" ] && ok "frame $i written" || bad "frame $i missing"; done
"$A" render "$T/s.json" -D animation.frames=0 -D volume.simulate.minutes=12 --pfm "$T/alone.pfm" -q 2>"$T/err" ||
    { bad "single render at 12 minutes"; cat "$T/err" >&2; }
cmp -s "$T/t_0003.pfm" "$T/alone.pfm" && ok "frame 3 = a single render at 12 minutes, byte for byte" ||
    bad "frame 3 differs from a single render at 12 minutes"
"$A" render "$T/s.json" -D animation.frames=0 -D volume.simulate.minutes=10.5 --pfm "$T/mid.pfm" -q 2>/dev/null
cmp -s "$T/t_0002.pfm" "$T/mid.pfm" && ok "frame 2 = a single render at 10.5 minutes" || bad "frame 2 differs"
cmp -s "$T/t_0001.pfm" "$T/t_0003.pfm" && bad "the cloud did not change from 9 to 12 minutes" || ok "the cloud grew"
# a generated volume has no time to lapse
sed 's/"simulate": {"preset": "towering_cumulus", "minutes": 9, "grid": 16, "seed": 1}/"generate": "cumulus"/' \
    "$T/s.json" >"$T/g.json"
"$A" render "$T/g.json" -o "$T/g.png" -q 2>"$T/err"
rc=$?
[ $rc -ne 0 ] && grep -q "minutes_end" "$T/err" && grep -q "simulated volume" "$T/err" && ok "minutes_end refused without a simulation" ||
    { bad "minutes_end with a generated volume: exit $rc"; cat "$T/err" >&2; }
[ ! -e "$T/g.png" ] && ok "nothing written" || bad "g.png written"
exit $fail
