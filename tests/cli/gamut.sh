#!/bin/sh
# The HDR files atmos render writes hold no negative RGB component (docs/colour.md): a
# spectral render of the sun 2 degrees above the horizon, looked at with a narrow field so
# its disc fills the frame, gave blue components of -1.3e7 (a red beyond the sRGB gamut);
# its PFM and EXR (the same pixels) must be >= 0 everywhere, and the PFM is gamut-mapped,
# not clipped to nothing: the disc is not black.
. "$(dirname "$0")/common.inc"

"$A" render --spectral 16 --sun-elevation 2 --sun-azimuth 250 --view-elevation 2 --view-azimuth 250 --fov 2 \
    --width 16 --height 16 --pfm "$T/s.pfm" --exr "$T/s.exr" -o "$T/s.png" >/dev/null 2>"$T/err" ||
    { bad "low-sun spectral render"; cat "$T/err" >&2; }
python3 - "$T/s.pfm" <<'PY' && ok "no negative component in the PFM; the sun's disc is bright" || bad "negative components in the PFM"
import sys, pfm
img = pfm.read(sys.argv[1])
assert img.kind == "PF", img.kind
a = img.v
neg = [i // 3 for i, v in enumerate(a) if v < 0]
print("pixels with a negative component:", len(set(neg)), "min", min(a))
assert not neg
assert max(a[0::3]) > 1e3, max(a[0::3])   # the sun's disc kept its light
PY
"$A" compare "$T/s.exr" "$T/s.pfm" --json >"$T/cmp.json" 2>&1 || bad "compare EXR with PFM"
python3 - "$T/cmp.json" <<'PY' && ok "the EXR holds the PFM's pixels" || bad "the EXR differs from the PFM"
import json, sys
c = json.load(open(sys.argv[1]))
assert c["rmse"] == 0 and c["nonfinite"] == 0, c
PY
exit $fail
