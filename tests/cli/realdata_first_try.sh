#!/bin/sh
# Real data on the first try (issue 13): a volume file given as the scene is refused with
# the --volume hint; a VDB cloud's 0..1 values become a cloud and the default camera frames
# it; the WRF file's default render shows its clouds; options of another renderer are
# refused; the render reports the plan's time, and progress goes to a log off a terminal.
set -u
. "$(dirname "$0")/common.inc"
DATA=${ATMOS_SHARED_DATA:-${ATMOS_SOURCE_DIR:-.}/../shared/data}/real

# The fraction of pixels whose optical depth exceeds a threshold, from a 1-channel PFM.
coverage() {
    python3 - "$1" "$2" <<'PY'
import sys, pfm
v = pfm.read(sys.argv[1]).v
print("%.4f" % (sum(1 for x in v if x > float(sys.argv[2])) / len(v)))
PY
}
at_least() { python3 -c "import sys; sys.exit(0 if float('$1') >= float('$2') else 1)"; }

# 1. a volume file where a scene goes: exit 2, and the message says what to type
printf ' BDV\0\0\0\0' > "$T/cloud.vdb"
"$A" render "$T/cloud.vdb" -o "$T/x.png" 2> "$T/err.txt"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--volume $T/cloud.vdb" "$T/err.txt" && ok || bad "volume file as scene: rc $rc, $(cat "$T/err.txt")"
printf ' BDV\0\0\0\0' > "$T/cloud_no_extension"
"$A" render "$T/cloud_no_extension" -o "$T/x.png" 2> "$T/err.txt"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--volume" "$T/err.txt" && ok || bad "VDB magic as scene: rc $rc"

# 2. the options of another renderer are refused, whichever renderer it is
"$A" render -q --width 8 --height 8 --eq24 -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--eq24 with sky accepted"
"$A" render -q --width 8 --height 8 --truncate 3 -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--truncate with sky accepted"
"$A" render -q --width 8 --height 8 --time-index 2 -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "--time-index without a volume accepted"
"$A" render -q --width 8 --height 8 --volume generate:cumulus --density-unit g_m3 -o "$T/x.png" 2>/dev/null
[ $? -eq 2 ] && ok || bad "--density-unit with a generated volume accepted"

# 3. the time of the plan (tables) is reported, and progress lines go to a log
ATMOS_PROGRESS_INTERVAL=0 "$A" render --width 16 --height 9 -o "$T/sky.png" 2> "$T/log.txt" && ok || bad "sky render"
grep -q "s for the scene, the volume and the optics tables" "$T/log.txt" && ok || bad "no plan time: $(cat "$T/log.txt")"
grep -q "^atmos: render sky: .* %, .* s elapsed" "$T/log.txt" && ok || bad "no progress line off a terminal"

# 4. the Disney cloud: a cloud at a cloud's altitude, framed by the default camera
if [ -f "$DATA/wdas_cloud_sixteenth.vdb" ]; then
    "$A" render -q --volume "$DATA/wdas_cloud_sixteenth.vdb" --width 64 --height 36 --slices 64 \
        --tau "$T/disney_tau.pfm" -o "$T/disney.png" && ok || bad "Disney cloud render"
    c=$(coverage "$T/disney_tau.pfm" 1)
    at_least "$c" 0.03 && ok || bad "Disney cloud: only $c of the pixels have tau > 1"
    # an old scene's density scale on a fraction is a warning naming the unit to give
    "$A" render --volume "$DATA/wdas_cloud_sixteenth.vdb" --density-scale 1e8 --width 16 --height 9 --slices 16 \
        -o "$T/d8.png" 2> "$T/err.txt" && grep -q "density_unit.*per_m3" "$T/err.txt" && ok \
        || bad "no warning for --density-scale 1e8 on a 0..1 VDB"
    # --voxel-size applies to a VDB file (the file's 3.33 m voxel replaced)
    "$A" volume info "$DATA/wdas_cloud_sixteenth.vdb" --voxel-size 25 | grep -q "voxels of 25 m" && ok \
        || bad "volume info --voxel-size 25 on a VDB"
else
    echo "realdata_first_try.sh: wdas_cloud_sixteenth.vdb not found: skipped"
fi

# 5. the WRF file: the default placement, camera and voxel show the domain's clouds (the
#    cloud water only: the ice and snow tables would take minutes to build in a fresh cache)
if [ -f "$DATA/salem_wrf_d01_allvars_cropped.nc" ]; then
    "$A" render -q --volume "$DATA/salem_wrf_d01_allvars_cropped.nc" --grids QCLOUD --width 64 --height 36 --slices 64 \
        --tau "$T/wrf_tau.pfm" -o "$T/wrf.png" && ok || bad "WRF render"
    c=$(coverage "$T/wrf_tau.pfm" 0.01)
    at_least "$c" 0.02 && ok || bad "WRF: only $c of the pixels have tau > 0.01"
    "$A" render -q --volume "$DATA/salem_wrf_d01_allvars_cropped.nc" --time-index 3 --grids QCLOUD --width 32 \
        --height 18 --slices 32 --tau "$T/wrf3.pfm" -o "$T/wrf3.png" && ok || bad "WRF --time-index --grids"
else
    echo "realdata_first_try.sh: salem_wrf_d01_allvars_cropped.nc not found: skipped"
fi

rm -rf "$T"
echo "realdata_first_try.sh: $pass passed"
[ $fail -eq 0 ]
