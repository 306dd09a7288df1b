#!/bin/sh
# The beam renderer against the path tracer (docs/beams.md, "Against the path tracer"):
# Dobashi et al. 2002's Fig. 4 scene at its 300x450, single scattering, the path tracer's
# converged image (8192 samples a pixel, --max-depth 1) as the reference; the beam renderer
# as it renders (one ray through each pixel's centre) and with each pixel the mean of 4 x 4
# rays (a 1200x1800 render box-filtered), which is what a path-traced pixel averages; per case
# the mean and the worst relative difference over the samples above 1e-3 of the brightest
# (as bench/beams/run.sh). Then all orders of scattering against single scattering at
# 150x225 (512 samples a pixel). The path tracer takes about half an hour on two busy cores.
#
#   bench/beams/against_path.sh [--atmos BIN] [--out DIR]
set -eu
ATMOS=build/atmos
OUT=${TMPDIR:-/tmp}/atmos-beams-path
while [ $# -gt 0 ]; do
    case "$1" in
    --atmos) ATMOS=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    *) echo "against_path.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
SCENE=scenes/dobashi_fig04_spotlight.json
mkdir -p "$OUT"
[ -f "$OUT/path_single.pfm" ] || "$ATMOS" render "$SCENE" -q --renderer path --max-depth 1 --spp 8192 \
    --pfm "$OUT/path_single.pfm" -o "$OUT/path_single.png"
[ -f "$OUT/path_all_150.pfm" ] || "$ATMOS" render "$SCENE" -q --renderer path --max-depth 0 --spp 512 \
    --width 150 --height 225 --pfm "$OUT/path_all_150.pfm" -o "$OUT/path_all_150.png"
"$ATMOS" render "$SCENE" -q --pfm "$OUT/beams.pfm" -o "$OUT/beams.png"
"$ATMOS" render "$SCENE" -q --width 1200 --height 1800 --pfm "$OUT/beams_1200.pfm"
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
    return W, H, [sum(v[((y * k + j) * w + x * k + i) * 3 + c] for j in range(k) for i in range(k)) / (k * k)
                  for y in range(H) for x in range(W) for c in range(3)]
def compare(name, a, b):
    top = max(b[2]); errs = [abs(x - y) / y for x, y in zip(a[2], b[2]) if y > 1e-3 * top]
    print('bench=beams_vs_path case=%s pixels=%d mean_rel=%.4f worst_rel=%.3f' % (name, len(errs), sum(errs) / len(errs), max(errs)))
ref = read(out + '/path_single.pfm')
compare('beams_pixel_centres', read(out + '/beams.pfm'), ref)
compare('beams_4x4_per_pixel', boxed(read(out + '/beams_1200.pfm'), 4), ref)
single, multi = boxed(ref, 2), read(out + '/path_all_150.pfm')
top = max(single[2])
lit = [i for i, y in enumerate(single[2]) if y > 1e-3 * top]
dark = [i for i, y in enumerate(single[2]) if y <= 1e-3 * top]
ratio = sum(multi[2][i] for i in lit) / sum(single[2][i] for i in lit)
print('bench=beams_vs_path case=all_orders_over_single lit_samples=%d ratio=%.3f whole_image=%.3f dark_share=%.3f'
      % (len(lit), ratio, sum(multi[2]) / sum(single[2]), sum(multi[2][i] for i in dark) / sum(multi[2])))
PY
