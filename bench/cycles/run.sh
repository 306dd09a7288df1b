#!/bin/sh
# atmos's path tracer against Blender Cycles' CPU path tracer on the same scene
# (docs/cycles.md): the Disney cloud as a grey medium (bench/cycles/cloud.json) under a sun
# lamp, black background. For each variant (density scale) it renders
#   - a high-sample reference with each renderer,
#   - each renderer at several sample counts, timed,
# and compares every image with its own renderer's reference and with atmos's (the common
# reference), over the cloud's pixels (optical depth >= 0.01 from atmos render --tau).
#
#   bench/cycles/run.sh [OUT_DIR]        (default: out/cycles)
#
# Environment (defaults in brackets):
#   ATMOS [build/atmos]  BLENDER [blender]  THREADS [2]
#   VARIANTS ["thick:1 thin:0.1"]  name:density-scale pairs (thick: sigma_t 0.1 m^-1 per unit
#                                  density, optical depth up to 22; thin: up to 2.2)
#   SPPS ["1 4 16 64 256"]         sample counts of the timed runs (both renderers)
#   REF_ATMOS [2048] REF_CYCLES [1024]   reference sample counts
#   STEP_RATES ["0.25"] STEP_SPP [256]   extra Cycles runs (STEP_SPP samples) with a finer
#                                  ray-marching step (Volume Step Rate; 1 = Cycles' default),
#                                  against one at step rate 1 with the same samples and seed
#   SIZE [128]                     image width = height
#   VOXEL_SHIFT [-0.5]             moves the grid in Blender by this many voxels along each grid
#                                  axis: Blender 3.4 places VDB voxels half a voxel off OpenVDB's
#                                  (and atmos's) index-to-world transform (docs/cycles.md)
#   CHECK_SPP [64]                 samples of the transmittance check (a pure absorber in front
#                                  of a uniform background: geometry and optical depth)
# Needs Blender 3.x with Cycles (scripts/install-bench-deps.sh on Debian); exits with status 2
# without it. Not part of the test suite. About 25-40 minutes on 2 cores with the defaults.
# Results: OUT_DIR/results.csv, refs.csv, transmittance.csv, summary.md (also on stdout), and
# per variant the images, logs, difference heat maps and side_by_side.png.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
A=${ATMOS:-$root/build/atmos}
B=${BLENDER:-blender}
OUT=${1:-$root/out/cycles}
TH=${THREADS:-2}
VARIANTS=${VARIANTS:-"thick:1 thin:0.1"}
SPPS=${SPPS:-"1 4 16 64 256"}
REF_ATMOS=${REF_ATMOS:-2048}
REF_CYCLES=${REF_CYCLES:-1024}
STEP_RATES=${STEP_RATES:-0.25}
STEP_SPP=${STEP_SPP:-256}
SIZE=${SIZE:-128}
VOXEL_SHIFT=${VOXEL_SHIFT:--0.5}
CHECK_SPP=${CHECK_SPP:-64}
scene=$here/cloud.json

if ! command -v "$B" > /dev/null 2>&1; then
    echo "bench/cycles/run.sh: Blender not found ('$B'): install it (Debian: sh scripts/install-bench-deps.sh," >&2
    echo "  or apt-get install blender) or set BLENDER=/path/to/blender" >&2
    exit 2
fi
if [ ! -x "$A" ]; then
    echo "bench/cycles/run.sh: $A not found: build atmos first (make build)" >&2
    exit 2
fi
vdb=$(cd "$here" && python3 -c 'import json, os, sys; print(os.path.realpath(json.load(open(sys.argv[1]))["volume"]["file"]))' "$scene")
if [ ! -r "$vdb" ]; then
    echo "bench/cycles/run.sh: the Disney cloud is not at $vdb (see bench/accuracy/run.sh)" >&2
    exit 2
fi
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
"$B" --version 2>/dev/null | head -1 > "$OUT/versions.txt"
"$A" --version >> "$OUT/versions.txt" 2>&1 || true

now() { python3 -c 'import time; print("%.3f" % time.time())'; }
# atmos render's own timing (path tracing, without loading): "..., 1.234 s"
asecs() { sed -n 's/.*, \([0-9.]*\) s$/\1/p' "$1" | tail -1; }

# Cycles' log: scene synchronisation ends at "Sample 0/N"; path tracing from there to
# "Finished" (Blender prints elapsed times at 10 ms resolution).
csecs() {
    python3 - "$1" <<'PY'
import re, sys
t0 = t1 = None
tot = "nan"
for line in open(sys.argv[1], errors="replace"):
    m = re.search(r"Time:(\d+):(\d+\.\d+) .*\| Sample 0/", line)
    if m and t0 is None: t0 = int(m.group(1)) * 60 + float(m.group(2))
    m = re.search(r"Time:(\d+):(\d+\.\d+) .*\| Finished", line)
    if m: t1 = int(m.group(1)) * 60 + float(m.group(2))
    m = re.match(r"cycles-timing: samples \d+ total_s ([0-9.]+)", line)
    if m: tot = m.group(1)
if t0 is None or t1 is None: sys.exit("no Cycles timing in " + sys.argv[1])
print("%.2f %.2f %s" % (t0, t1 - t0, tot))
PY
}

# rel_rmse and rel_bias over the cloud's pixels
cmp_cloud() {
    "$A" compare "$1" "$2" --by "$3" --edges 0.01,1e30 --json |
        python3 -c 'import json, sys; b = json.load(sys.stdin)["bins"][0]; print("%.5g %.5g" % (b["rel_rmse"], b["rel_bias"]))'
}

# Calibration: atmos's EXR values for a grey radiance of 1 in rgb mode (the Cycles lamp's
# colour, so that both images are in atmos's units), and where atmos puts the grid.
python3 - "$scene" "$vdb" "$OUT/cal.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
c = {"name": "calibration", "image": {"width": 4, "height": 4},
     "camera": {"type": "pinhole", "position_m": [0, 10, 0], "look_at_m": [0, 10, -10], "fov_deg": 1},
     "background": {"type": "uniform", "radiance": 1}, "wavelengths": s["wavelengths"],
     "renderer": "path", "path": {"spp": 1},
     "volume": {"file": sys.argv[2], "position_m": [0, 0, 1e5]}}
json.dump(c, open(sys.argv[3], "w"))
PY
"$A" render "$OUT/cal.json" -q --threads "$TH" --pfm "$OUT/cal.pfm"
rgb=$(python3 - "$OUT/cal.pfm" <<'PY'
import struct, sys
f = open(sys.argv[1], "rb")
assert f.readline().strip() == b"PF"
f.readline()
e = "<" if float(f.readline()) < 0 else ">"
r, g, b = struct.unpack(e + "3f", f.read(12))
print("%.9g,%.9g,%.9g" % (r, g, b))
PY
)
offset=$("$A" volume info "$vdb" --json | python3 -c '
import json, sys
i = json.load(sys.stdin); s = json.load(open(sys.argv[1]))
lo, hi = i["grid_bounds_m"]; p = s["volume"]["position_m"]
print("%.9g,%.9g,%.9g" % (p[0] - 0.5 * (lo[0] + hi[0]), p[1] - lo[1], p[2] - 0.5 * (lo[2] + hi[2])))' "$scene")
vsize=$("$A" volume info "$vdb" --json | python3 -c 'import json, sys; print(json.load(sys.stdin)["voxel_size_m"])')
echo "calibration: rgb of a grey radiance 1 = $rgb; grid offset (atmos frame) = $offset; voxel $vsize m" |
    tee "$OUT/calibration.txt" >&2
# The transmittance check's scene: a pure absorber (albedo ~0) in a uniform background of 1.
python3 - "$scene" "$vdb" "$OUT/transmittance.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s.pop("_comment", None)
s["background"] = {"type": "uniform", "radiance": 1}
s["particles"]["cloud"]["albedo"] = 1e-9
s["volume"]["file"] = sys.argv[2]
json.dump(s, open(sys.argv[3], "w"))
PY

cycles() { # density samples seed step-rate out-stem [more options]
    t0=$(now)
    c_o=$5
    "$B" -b --factory-startup -noaudio -t "$TH" -P "$here/cycles_scene.py" -- --scene "$scene" --vdb "$vdb" \
        --offset "$offset" --rgb-scale "$rgb" --density-scale "$1" --samples "$2" --seed "$3" \
        --step-rate "$4" --threads "$TH" --width "$SIZE" --height "$SIZE" --out "$5.exr" \
        --voxel-size "$vsize" --voxel-shift "${CSHIFT:-$VOXEL_SHIFT}" ${6:+--mode "$6"} > "$c_o.log" 2>&1 ||
        { echo "Blender failed, see $c_o.log" >&2; tail -20 "$c_o.log" >&2; kill $$; exit 1; }
    t1=$(now)
    echo "$(csecs "$c_o.log") $(python3 -c "print('%.2f' % ($t1 - $t0))")"
}
atmos_r() { # density spp seed out-stem [more options]
    d=$1 n=$2 s=$3 o=$4
    shift 4
    t0=$(now)
    "$A" render "$scene" --threads "$TH" --width "$SIZE" --height "$SIZE" --density-scale "$d" --spp "$n" --seed "$s" \
        --exr "$o.exr" "$@" 2> "$o.log"
    t1=$(now)
    echo "$(asecs "$o.log") $(python3 -c "print('%.2f' % ($t1 - $t0))")"
}

res="$OUT/results.csv"
refs="$OUT/refs.csv"
# seconds: path tracing alone (atmos: its render time; Cycles: from sample 0 to the end);
# render_call_s: Cycles' bpy.ops.render.render (scene sync, path tracing, EXR write);
# total_s: the atmos render / Blender process, wall time (Blender's start-up included)
echo "variant,renderer,step_rate,spp,seconds,sync_s,render_call_s,total_s,rel_rmse_own,rel_bias_own,rel_rmse_common,rel_bias_common" > "$res"
echo "variant,image,step_rate,spp,rel_rmse_vs_atmos_ref,rel_bias_vs_atmos_ref,bins" > "$refs"
chk="$OUT/transmittance.csv"
echo "variant,voxel_shift,samples,pixels,mean_1_minus_T_atmos,rel_rmse_1_minus_T,rel_bias_1_minus_T,shift_x_px,shift_y_px" > "$chk"
for v in $VARIANTS; do
    name=${v%%:*}
    dens=${v#*:}
    d="$OUT/$name"
    mkdir -p "$d"
    echo "== $name (density scale $dens)" >&2
    # Transmittance check: atmos (albedo 1e-9, delta tracking) against Cycles (a pure
    # absorber), both in front of a background of 1: errors of the opacity 1 - T over the
    # cloud's pixels, without and with the voxel shift.
    "$A" render "$OUT/transmittance.json" --threads "$TH" --width "$SIZE" --height "$SIZE" --density-scale "$dens" \
        --spp "$CHECK_SPP" --seed 7 --exr "$d/trans_atmos.exr" --tau "$d/tau.pfm" -q
    for sh in 0 $VOXEL_SHIFT; do
        CSHIFT=$sh cycles "$dens" "$CHECK_SPP" 7 1 "$d/trans_cycles_$sh" transmittance > /dev/null
        r=$("$B" -b --factory-startup -noaudio -P "$here/opacity_check.py" -- "$d/trans_atmos.exr" \
            "$d/trans_cycles_$sh.exr" "$d/tau.pfm" 2>&1 | sed -n 's/^opacity-check: //p')
        echo "$name,$sh,$CHECK_SPP,$r" >> "$chk"
        echo "   transmittance check, voxel shift $sh: pixels, mean 1 - T, its rel. RMSE and bias, image shift: $r" >&2
    done
    set -- $(atmos_r "$dens" "$REF_ATMOS" 1000 "$d/atmos_ref" --variance "$d/atmos_ref.var.exr" -o "$d/atmos_ref.png")
    echo "$name,atmos,,$REF_ATMOS,$1,,,$2,0,0,0,0" >> "$res"
    echo "   atmos reference, $REF_ATMOS spp: $1 s" >&2
    set -- $(cycles "$dens" "$REF_CYCLES" 1000 1 "$d/cycles_ref")
    echo "   Cycles reference, $REF_CYCLES samples: $2 s (sync $1 s)" >&2
    echo "$name,cycles,1,$REF_CYCLES,$2,$1,$3,$4,0,0,$(cmp_cloud "$d/cycles_ref.exr" "$d/atmos_ref.exr" "$d/tau.pfm" | tr ' ' ,)" >> "$res"
    if [ -n "$STEP_RATES" ]; then
        set -- $(cycles "$dens" "$STEP_SPP" 1000 1 "$d/cycles_step1")
        echo "   Cycles, step rate 1, $STEP_SPP samples: $2 s" >&2
        echo "$name,cycles,1,$STEP_SPP,$2,$1,$3,$4,,,$(cmp_cloud "$d/cycles_step1.exr" "$d/atmos_ref.exr" "$d/tau.pfm" | tr ' ' ,)" >> "$res"
    fi
    for sr in $STEP_RATES; do
        set -- $(cycles "$dens" "$STEP_SPP" 1000 "$sr" "$d/cycles_step$sr")
        echo "   Cycles, step rate $sr, $STEP_SPP samples: $2 s" >&2
        echo "$name,cycles,$sr,$STEP_SPP,$2,$1,$3,$4,,,$(cmp_cloud "$d/cycles_step$sr.exr" "$d/atmos_ref.exr" "$d/tau.pfm" | tr ' ' ,)" >> "$res"
    done
    # the Cycles images against atmos's reference, by optical depth
    for img in cycles_ref ${STEP_RATES:+cycles_step1} $(for sr in $STEP_RATES; do echo cycles_step$sr; done); do
        sr=1 n=$STEP_SPP
        case $img in cycles_ref) n=$REF_CYCLES ;; cycles_step*) sr=${img#cycles_step} ;; esac
        "$A" compare "$d/$img.exr" "$d/atmos_ref.exr" --by "$d/tau.pfm" --edges 0.01,0.3,1,3,10,1e30 --json \
            --heatmap "$d/$img.diff.png" > "$d/$img.json"
        python3 - "$d/$img.json" "$name" "$img" "$sr" "$n" "$(cmp_cloud "$d/$img.exr" "$d/atmos_ref.exr" "$d/tau.pfm")" >> "$refs" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
rr, rb = sys.argv[6].split()
bins = [[b["lo"], b["pixels"], round(b["rel_rmse"], 5), round(b["rel_bias"], 5)] for b in j["bins"]
        if b["pixels"] and b["rel_rmse"] is not None]
print('%s,%s,%s,%s,%s,%s,"%s"' % (sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5], rr, rb, json.dumps(bins)))
PY
    done
    for n in $SPPS; do
        set -- $(atmos_r "$dens" "$n" 1 "$d/atmos_$n")
        echo "$name,atmos,,$n,$1,,,$2,$(cmp_cloud "$d/atmos_$n.exr" "$d/atmos_ref.exr" "$d/tau.pfm" | tr ' ' ,),$(cmp_cloud "$d/atmos_$n.exr" "$d/atmos_ref.exr" "$d/tau.pfm" | tr ' ' ,)" >> "$res"
        echo "   atmos $n spp: $1 s" >&2
        set -- $(cycles "$dens" "$n" 1 1 "$d/cycles_$n")
        echo "$name,cycles,1,$n,$2,$1,$3,$4,$(cmp_cloud "$d/cycles_$n.exr" "$d/cycles_ref.exr" "$d/tau.pfm" | tr ' ' ,),$(cmp_cloud "$d/cycles_$n.exr" "$d/atmos_ref.exr" "$d/tau.pfm" | tr ' ' ,)" >> "$res"
        echo "   Cycles $n samples: $2 s (sync $1 s)" >&2
    done
    # atmos's and Cycles' references side by side (one exposure)
    "$B" -b --factory-startup -noaudio -P "$here/side_by_side.py" -- "$d/side_by_side.png" "$d/atmos_ref.exr" \
        "$d/cycles_ref.exr" > /dev/null 2>&1 || echo "side_by_side.py failed" >&2
done
python3 "$here/summary.py" "$res" "$refs" $((SIZE * SIZE)) "$chk" | tee "$OUT/summary.md"
echo "wrote $res and $refs" >&2
