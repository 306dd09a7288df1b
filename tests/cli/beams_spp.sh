#!/bin/sh
# The beam renderer honours --spp N as n x n rays a pixel, n = round(sqrt(N)) (docs/beams.md,
# "Antialiasing"): --spp 16 equals a render at 4 times the width and height box-filtered down
# (the filter done here, independently), --spp 1 is the default image, and the antialiased
# image differs from it.
. "$(dirname "$0")/common.inc"
S="${ATMOS_SOURCE_DIR:-$(dirname "$0")/../..}/scenes/dobashi_fig04_spotlight.json"
"$A" render "$S" --width 30 --height 45 --pfm "$T/one.pfm" -q 2>"$T/err" || { bad "default render"; cat "$T/err" >&2; }
"$A" render "$S" --width 30 --height 45 --spp 1 --pfm "$T/spp1.pfm" -q 2>"$T/err" || bad "--spp 1"
cmp -s "$T/one.pfm" "$T/spp1.pfm" && ok "--spp 1 is the default image" || bad "--spp 1 differs from the default"
"$A" render "$S" --width 30 --height 45 --spp 16 --pfm "$T/spp16.pfm" -q 2>"$T/err" || { bad "--spp 16"; cat "$T/err" >&2; }
"$A" render "$S" --width 120 --height 180 --pfm "$T/big.pfm" -q 2>"$T/err" || bad "the 4x render"
python3 - "$T/big.pfm" "$T/spp16.pfm" "$T/one.pfm" <<'PY' && ok "--spp 16 = the 4x render box-filtered 4 x 4" || bad "--spp 16 is not the 4 x 4 box filter"
import sys, pfm
def pfm4(p):
    i = pfm.read(p)
    return i.w, i.h, i.c, i.v
W, H, C, big = pfm4(sys.argv[1]); w, h, c, aa = pfm4(sys.argv[2]); _, _, _, one = pfm4(sys.argv[3])
assert (W, H) == (4 * w, 4 * h) and C == c
worst, diff1 = 0.0, 0.0
for y in range(h):
    for x in range(w):
        for k in range(c):
            m = sum(big[((4 * y + j) * W + 4 * x + i) * c + k] for j in range(4) for i in range(4)) / 16
            a = aa[(y * w + x) * c + k]
            worst = max(worst, abs(a - m) / max(abs(m), 1e-3))
            diff1 = max(diff1, abs(one[(y * w + x) * c + k] - a) / max(abs(a), 1e-3))
print('largest relative difference to the box filter %.3g, to one ray a pixel %.3g' % (worst, diff1))
assert worst < 1e-5 and diff1 > 1e-2
PY
# --help and the renderer's docs say so
"$A" render --help | grep -q "n x n rays a pixel" && ok "--help tells the beams' --spp" || bad "--help silent on the beams' --spp"
exit $fail
