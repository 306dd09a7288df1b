#!/bin/sh
# Sub-planes against none (docs/beams.md, "Planes and sub-planes"): Dobashi et al. 2002's Fig. 4
# scene rendered by the beam renderer with its settings, with a coarser and a finer epsilon,
# without sub-planes at plane spacings of 1.2, 0.3 and 0.1 m, and with interleaved sampling
# instead of sub-planes (2x2, 3x3), each against a reference of
# the same renderer converged far beyond them (epsilon 5e-4, up to 2048 sub-planes, planes
# 0.3 m apart, 2048-texel shadow map); per case the mean and the worst relative difference
# over the pixels above 1e-3 of the brightest. `atmos bench beams` times the same cases.
#
#   bench/beams/run.sh [--atmos BIN] [--out DIR]
set -eu
ATMOS=build/atmos
OUT=${TMPDIR:-/tmp}/atmos-beams
while [ $# -gt 0 ]; do
    case "$1" in
    --atmos) ATMOS=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    *) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
SCENE=scenes/dobashi_fig04_spotlight.json
mkdir -p "$OUT"
"$ATMOS" render "$SCENE" -q -D beams.epsilon=0.0005 -D beams.max_subplanes=2048 -D beams.plane_spacing_m=0.3 \
    -D beams.shadow_size=2048 --pfm "$OUT/reference.pfm" -o "$OUT/reference.png"
compare() {
    python3 - "$1" "$2" <<'PY'
import struct, sys
def read(path):
    with open(path, 'rb') as f:
        kind = f.readline().strip(); w, h = map(int, f.readline().split()); scale = float(f.readline())
        n = w * h * (3 if kind == b'PF' else 1)
        return struct.unpack(('<' if scale < 0 else '>') + '%df' % n, f.read(4 * n))
a, b = read(sys.argv[1]), read(sys.argv[2])
top = max(b); errs = [abs(x - y) / y for x, y in zip(a, b) if y > 1e-3 * top]
print('pixels=%d mean_rel=%.4f worst_rel=%.3f' % (len(errs), sum(errs) / len(errs), max(errs)))
PY
}
while read -r name args; do
    # shellcheck disable=SC2086
    "$ATMOS" render "$SCENE" -q $args --pfm "$OUT/$name.pfm" -o "$OUT/$name.png"
    echo "bench=beams_accuracy case=$name $(compare "$OUT/$name.pfm" "$OUT/reference.pfm")"
done <<'CASES'
scene_settings
epsilon_0.03 -D beams.epsilon=0.03
epsilon_0.003 -D beams.epsilon=0.003 -D beams.max_subplanes=256
no_subplanes_1.2m -D beams.max_subplanes=1
no_subplanes_0.3m -D beams.max_subplanes=1 -D beams.plane_spacing_m=0.3
no_subplanes_0.1m -D beams.max_subplanes=1 -D beams.plane_spacing_m=0.1
interleaved_2 -D beams.max_subplanes=1 -D beams.interleave=2
interleaved_3 -D beams.max_subplanes=1 -D beams.interleave=3
interleaved_3_0.3m -D beams.max_subplanes=1 -D beams.interleave=3 -D beams.plane_spacing_m=0.3
CASES
