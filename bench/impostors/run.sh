#!/bin/sh
# Impostor error along a recorded flight (docs/particles.md, "Clouds and impostors"): the
# field of 120 cumuli flown with Harris's renderer with impostors at tolerance angles 0.15,
# 0.5 and 1 degree, and with every particle splatted every frame (the reference); per
# tolerance the frames' mean absolute difference from the reference (8-bit display values, as
# the viewer shows them, over all pixels and over the pixels the clouds change), the impostor
# updates per frame and the frame times (median and the slowest 1 %). Every out-of-date
# impostor is made each frame (--impostor-budget 0), and then at 0.15 degree with the viewer's
# budgets of 2 and 8 impostors a frame (rows "0.15/b2", "0.15/b8").
#
#   bench/impostors/run.sh [--atmos BIN] [--frames N] [--size WxH] [--out DIR]
set -eu
ATMOS=build/atmos
FRAMES=240
SIZE=640x360
OUT=${TMPDIR:-/tmp}/atmos-impostors
while [ $# -gt 0 ]; do
    case "$1" in
    --atmos) ATMOS=$2; shift 2 ;;
    --frames) FRAMES=$2; shift 2 ;;
    --size) SIZE=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    *) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
SCENE=scenes/harris_cloud_field.json
FLIGHT=scenes/flights/harris_cloud_field.json
rm -rf "$OUT"
mkdir -p "$OUT"
"$ATMOS" view "$SCENE" --script "$FLIGHT" --frames "$FRAMES" --size "$SIZE" --headless --record "$OUT/ref" \
    --no-impostors -q
for tol in 0.15 0.5 1; do
    "$ATMOS" view "$SCENE" --script "$FLIGHT" --frames "$FRAMES" --size "$SIZE" --headless --record "$OUT/t$tol" \
        --impostor-tolerance "$tol" --impostor-budget 0 -q
done
for b in 2 8; do
    "$ATMOS" view "$SCENE" --script "$FLIGHT" --frames "$FRAMES" --size "$SIZE" --headless --record "$OUT/t0.15/b$b" \
        --impostor-tolerance 0.15 --impostor-budget "$b" -q
done
python3 - "$OUT" "$FRAMES" <<'PY'
import csv, os, struct, sys, zlib
out, frames = sys.argv[1], int(sys.argv[2])
def pixels(p):
    d = open(p, "rb").read(); i = 8; idat = b""
    while i < len(d):
        n, = struct.unpack(">I", d[i:i + 4]); t = d[i + 4:i + 8]
        if t == b"IHDR": w, h, bd, ct = struct.unpack(">IIBB", d[i + 8:i + 18])
        if t == b"IDAT": idat += d[i + 8:i + 8 + n]
        i += 12 + n
    ch = {2: 3, 6: 4}[ct]; raw = zlib.decompress(idat); stride = w * ch; prev = bytearray(stride); o = 0; res = bytearray()
    for y in range(h):
        f = raw[o]; o += 1; line = bytearray(raw[o:o + stride]); o += stride
        for x in range(stride):
            a = line[x - ch] if x >= ch else 0; b = prev[x]; c = prev[x - ch] if x >= ch else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                pa = abs(b - c); pb = abs(a - c); pc = abs(a + b - 2 * c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else (b if pb <= pc else c))) & 255
        res += bytes(line[j] for j in range(stride) if j % ch < 3); prev = line
    return res
def times(d):
    rows = list(csv.DictReader(open(os.path.join(d, "frames.csv"))))
    ms = sorted(float(r["ms"]) for r in rows)
    return rows, ms[len(ms) // 2], ms[max(0, int(0.99 * len(ms)) - 1):][-1]
rows, med, slow = times(os.path.join(out, "ref"))
print("tolerance_deg,mean_abs_diff,max_frame_mean_abs_diff,updates_per_frame,median_ms,p99_ms")
print("none (every particle),0,0,0,%.1f,%.1f" % (med, slow))
step = max(1, frames // 24)
for tol in ("0.15", "0.5", "1", "0.15/b2", "0.15/b8"):
    d = os.path.join(out, "t" + tol)
    rows, med, slow = times(d)
    diffs = []
    for i in range(0, frames, step):
        a = pixels(os.path.join(d, "frame_%05d.png" % i)); b = pixels(os.path.join(out, "ref", "frame_%05d.png" % i))
        diffs.append(sum(abs(x - y) for x, y in zip(a, b)) / len(a))
    upd = sum(int(r["impostor_updates"]) for r in rows) / len(rows)
    print("%s,%.3f,%.3f,%.2f,%.1f,%.1f" % (tol, sum(diffs) / len(diffs), max(diffs), upd, med, slow))
PY
