#!/bin/sh
# The beam renderer against the path tracer (docs/beams.md, "Against the path tracer"):
# Dobashi et al. 2002's Fig. 4 scene at its 300x450, single scattering, the path tracer's
# converged image (8192 samples a pixel, --max-depth 1) as the reference; the beam renderer
# as it renders (one ray through each pixel's centre) and with each pixel the mean of 4 x 4
# and of 8 x 8 rays (renders 4 and 8 times the size, box-filtered), which is what a
# path-traced pixel averages; per case the mean and the worst relative difference over the
# samples above 1e-3 of the brightest
# (as bench/beams/run.sh). Then all orders of scattering against single scattering at
# half the size in each direction (512 samples a pixel). The path tracer takes about half an
# hour on two busy cores. --scene, --size and --spp compare another scene the same way (the
# studio of Fig. 9(a): --scene scenes/dobashi_fig09a_studio.json --size 240x160 --spp 4096).
#
#   bench/beams/against_path.sh [--atmos BIN] [--out DIR] [--scene FILE] [--size WxH] [--spp N]
set -eu
ATMOS=build/atmos
OUT=
SCENE=scenes/dobashi_fig04_spotlight.json
SIZE=300x450
SPP=8192
while [ $# -gt 0 ]; do
    case "$1" in
    --atmos) ATMOS=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --scene) SCENE=$2; shift 2 ;;
    --size) SIZE=$2; shift 2 ;;
    --spp) SPP=$2; shift 2 ;;
    *) echo "against_path.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
W=${SIZE%x*} H=${SIZE#*x}
case "$W$H" in *[!0-9]*|"") echo "against_path.sh: --size wants WxH, got $SIZE" >&2; exit 2 ;; esac
[ -n "$OUT" ] || OUT=${TMPDIR:-/tmp}/atmos-beams-path-$(basename "$SCENE" .json)-${SIZE}-$SPP
mkdir -p "$OUT"
R="-q --width $W --height $H"
# shellcheck disable=SC2086
[ -f "$OUT/path_single.pfm" ] || "$ATMOS" render "$SCENE" $R --renderer path --max-depth 1 --spp "$SPP" \
    --pfm "$OUT/path_single.pfm" -o "$OUT/path_single.png"
[ -f "$OUT/path_all_half.pfm" ] || "$ATMOS" render "$SCENE" -q --renderer path --max-depth 0 --spp 512 \
    --width $((W / 2)) --height $((H / 2)) --pfm "$OUT/path_all_half.pfm" -o "$OUT/path_all_half.png"
# shellcheck disable=SC2086
"$ATMOS" render "$SCENE" $R --pfm "$OUT/beams.pfm" -o "$OUT/beams.png"
"$ATMOS" render "$SCENE" -q --width $((4 * W)) --height $((4 * H)) --pfm "$OUT/beams_4x.pfm"
"$ATMOS" render "$SCENE" -q --width $((8 * W)) --height $((8 * H)) --pfm "$OUT/beams_8x.pfm"
python3 - "$OUT" <<'PY'
import struct, sys
out = sys.argv[1]
def read(path):
    with open(path, 'rb') as f:
        kind = f.readline().strip(); w, h = map(int, f.readline().split()); scale = float(f.readline())
        n = w * h * (3 if kind == b'PF' else 1)
        return w, h, struct.unpack(('<' if scale < 0 else '>') + '%df' % n, f.read(4 * n))
def boxed(img, k):  # each k x k block of an RGB image averaged
    w, h, v = img
    W, H = w // k, h // k
    out = [0.0] * (W * H * 3)
    for y in range(H * k):
        for x in range(W * k):
            a, b = (y * w + x) * 3, ((y // k) * W + x // k) * 3
            for c in range(3):
                out[b + c] += v[a + c]
    return W, H, [q / (k * k) for q in out]
def compare(name, a, b):
    top = max(b[2]); errs = [abs(x - y) / y for x, y in zip(a[2], b[2]) if y > 1e-3 * top]
    print('bench=beams_vs_path case=%s pixels=%d mean_rel=%.4f worst_rel=%.3f' % (name, len(errs), sum(errs) / len(errs), max(errs)))
ref = read(out + '/path_single.pfm')
compare('beams_pixel_centres', read(out + '/beams.pfm'), ref)
compare('beams_4x4_per_pixel', boxed(read(out + '/beams_4x.pfm'), 4), ref)
compare('beams_8x8_per_pixel', boxed(read(out + '/beams_8x.pfm'), 8), ref)
single, multi = boxed(ref, 2), read(out + '/path_all_half.pfm')
top = max(single[2])
lit = [i for i, y in enumerate(single[2]) if y > 1e-3 * top]
dark = [i for i, y in enumerate(single[2]) if y <= 1e-3 * top]
ratio = sum(multi[2][i] for i in lit) / sum(single[2][i] for i in lit)
print('bench=beams_vs_path case=all_orders_over_single lit_samples=%d ratio=%.3f whole_image=%.3f dark_share=%.3f'
      % (len(lit), ratio, sum(multi[2]) / sum(single[2]), sum(multi[2][i] for i in dark) / sum(multi[2])))
PY
