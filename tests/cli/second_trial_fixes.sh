#!/bin/sh
# What a second new user's trial (real data, long renders, --help) ran into:
#  1. a truncated netCDF-4 (HDF5) file is named as truncated, with the size its superblock
#     promises; an empty .nc file is named empty;
#  2. render --time with a bare number (a time index) points to --time-index;
#  3. an interrupted render says "interrupted" on a line of its own and removes the output
#     folders it created and left empty; the exit status stays 130 (SIGINT) / 143 (SIGTERM);
#  4. the default voxel chosen for a small classic WRF file draws no warning of its own;
#  5. the auto-framed camera above the flat-earth model's range switches to the spherical one;
#  6. table builds off a terminal log progress lines;
#  7. volume takes render's option names (--particle, --volume-scale, --density-scale); the
#     --help texts: one --eye-scale range, simulate's -q, the renderers' cameras, every
#     command's exit statuses;
#  8. every `atmos render` command in README.md and docs/ uses only options render --help lists.
. "$(dirname "$0")/common.inc"
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }
hasnt() { grep -qF -- "$2" "$T/err" && { bad "$1: '$2' in:"; sed 's/^/  /' "$T/err" >&2; } || ok "$1: no '$2'"; }
DATA=${ATMOS_SHARED_DATA:-${ATMOS_SOURCE_DIR:-.}/../shared/data}/real

# --- 1. truncated netCDF-4 and empty files. A hand-made HDF5 superblock (version 2, 8-byte
# offsets and lengths) whose end-of-file address is 4096, in a file of 48 bytes: the format
# (HDF5 file format specification, "Superblock", versions 2 and 3) says the file is 4096 bytes.
python3 - "$T/cut.nc" <<'PY'
import struct, sys
sb = b"\x89HDF\r\n\x1a\n" + bytes([2, 8, 8, 0]) + struct.pack("<qqqq", 0, -1, 4096, 48) + b"\0" * 4
open(sys.argv[1], "wb").write(sb)
PY
"$A" volume info "$T/cut.nc" 2>"$T/err"; rc=$?
[ $rc -ne 0 ] && ok "truncated HDF5 refused" || bad "truncated HDF5 accepted"
has "truncated HDF5" "$T/cut.nc: truncated"
has "truncated HDF5" "4096"
: >"$T/empty.nc"
"$A" volume info "$T/empty.nc" 2>"$T/err"; [ $? -ne 0 ] && ok "empty file refused" || bad "empty file accepted"
has "empty file" "$T/empty.nc: the file is empty"
WRF=$DATA/salem_wrf_d01_allvars_cropped.nc
if [ -f "$WRF" ]; then
    for n in 2000 500000 985000; do
        head -c $n "$WRF" >"$T/wrf_cut.nc"
        "$A" volume info "$T/wrf_cut.nc" 2>"$T/err"
        has "WRF file cut at $n bytes" "truncated"
        hasnt "WRF file cut at $n bytes" "HDF error"
    done
    # a damaged file (not truncated): the HDF error says that the file is damaged
    python3 - "$WRF" "$T/wrf_bad.nc" <<'PY'
import sys
b = bytearray(open(sys.argv[1], "rb").read())
b[48:56] = b"\xff" * 8
open(sys.argv[2], "wb").write(b)
PY
    "$A" volume info "$T/wrf_bad.nc" 2>"$T/err"
    has "damaged WRF file" "damaged"
else
    echo "skip: no $WRF"
fi

# --- 2. render --time 3 (volume's --time N is a time index): the hint names --time-index 3
"$A" render --volume generate:cumulus --time 3 --width 8 --height 8 -o "$T/x.png" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && ok "render --time 3: usage error" || bad "render --time 3: rc $rc"
has "render --time 3" "--time-index 3"
hasnt "render --time 3" "--lat"

# --- 3. an interrupted render: "interrupted" on a line of its own, the folders it made and left
# empty removed (a folder that was there stays), the signal's exit status
slow="--renderer path --spp 1000000 --width 32 --height 18"
mkdir "$T/was"
# shellcheck disable=SC2086
timeout --preserve-status -s INT 8 "$A" render $slow -o "$T/was/new1/new2/a.png" 2>"$T/err"; rc=$?
[ $rc -eq 130 ] && ok "SIGINT: exit status 130" || { bad "SIGINT: exit status $rc"; cat "$T/err" >&2; }
grep -qx "atmos render: interrupted" "$T/err" && ok "SIGINT: 'interrupted' line" || { bad "SIGINT: no line"; cat "$T/err" >&2; }
# (6.) off a terminal the 8 s render logged its progress (a line every 5 s; was every 60 s)
grep -q "^atmos: render path: [0-9]* %, [0-9.]* s elapsed$" "$T/err" && ok "a progress line in 8 s off a terminal" \
    || { bad "no progress line in 8 s off a terminal"; cat "$T/err" >&2; }
[ -d "$T/was" ] && [ ! -e "$T/was/new1" ] && ok "SIGINT: the new empty folders removed, the old kept" \
    || bad "SIGINT: folders: $(find "$T/was")"
# on a terminal (script(1)) the progress bar's line is ended before the "interrupted" line
if command -v script >/dev/null 2>&1; then
    ATMOS_PROGRESS_DELAY=0 script -qec "timeout --preserve-status -s INT 6 '$A' render $slow -o '$T/tty/a.png'" \
        /dev/null >"$T/tty.txt" 2>&1
    python3 - "$T/tty.txt" <<'PY' && ok "on a terminal: the bar's line ended first" || bad "on a terminal: not on a line of its own"
import sys
d = open(sys.argv[1], "rb").read()
i = d.find(b"atmos render: interrupted")
# (timeout signals the process, then its group: two threads' handlers once wrote "atmos atmos")
sys.exit(0 if i > 0 and d[i - 1:i] == b"\n" and b"ETA" in d[:i] and d.count(b"interrupted") == 1 else 1)
PY
else
    echo "skip: script(1) not installed"
fi
# an animation (40 frames of about 1-2 s, far from done at 6 s): none of its frames is written,
# and the line says so
timeout --preserve-status -s TERM 6 "$A" render --frames 40 --sun-elevation 10 --sun-elevation-end 30 --renderer path \
    --spp 3000 --width 32 --height 18 -q -o "$T/anim/a.png" 2>"$T/err"; rc=$?
[ $rc -eq 143 ] && ok "SIGTERM: exit status 143" || { bad "SIGTERM: exit status $rc"; cat "$T/err" >&2; }
grep -qE "^atmos render: interrupted: no frame written \([0-9]+ finished frames? discarded" "$T/err" \
    && ok "SIGTERM: the animation's line" || { bad "SIGTERM: no animation line"; cat "$T/err" >&2; }
[ ! -e "$T/anim" ] && ok "SIGTERM: no folder left" || bad "SIGTERM: left $(find "$T/anim")"

# --- 4. a small classic WRF file (CDF-1, 4 x 3 columns, 5 levels of 500 m): the default voxel
# leaves at least 8 voxels over the model's 2500 m (no warning of its own making); a voxel the
# user gives that is too coarse is still warned of
wrf5() {
    python3 - "$1" "$2" <<'PY'
import math, struct, sys
i32 = lambda v: struct.pack(">i", v)
def name(s):
    b = s.encode()
    return i32(len(b)) + b + b"\0" * (-len(b) % 4)
NX, NY, NZ = 4, 3, 5
zs = [500.0 * k for k in range(NZ + 1)]
dims = [("Time", 0), ("west_east", NX), ("south_north", NY), ("bottom_top", NZ), ("bottom_top_stag", NZ + 1)]
mass, stag = [0, 3, 2, 1], [0, 4, 2, 1]
def f(fn, nz): return [fn(k) for k in range(nz) for j in range(NY) for i in range(NX)]
zm = [(zs[k] + zs[k + 1]) / 2 for k in range(NZ)]
vs = [("P", mass, f(lambda k: 0.0, NZ)), ("PB", mass, f(lambda k: 1e5 * math.exp(-zm[k] / 8000), NZ)),
      ("T", mass, f(lambda k: 0.0, NZ)), ("QVAPOR", mass, f(lambda k: 0.005, NZ)),
      ("QCLOUD", mass, f(lambda k: 1e-4 if k in (1, 2) else 0.0, NZ)),
      ("PH", stag, f(lambda k: 0.0, NZ + 1)), ("PHB", stag, f(lambda k: 9.81 * zs[k], NZ + 1))]
h = b"CDF\x01" + i32(1) + i32(0x0A) + i32(len(dims)) + b"".join(name(n) + i32(l) for n, l in dims)
h += i32(0x0C) + i32(2) + b"".join(name(n) + i32(5) + i32(1) + struct.pack(">f", float(sys.argv[2])) for n in ("DX", "DY"))
def vh(begins):
    return i32(0x0B) + i32(len(vs)) + b"".join(name(n) + i32(len(d)) + b"".join(i32(x) for x in d) + i32(0) + i32(0)
                                             + i32(5) + i32(4 * len(v)) + i32(b) for (n, d, v), b in zip(vs, begins))
off, begins = len(h + vh([0] * len(vs))), []
for n, d, v in vs: begins.append(off); off += 4 * len(v)
open(sys.argv[1], "wb").write(h + vh(begins) + b"".join(struct.pack(">%df" % len(v), *v) for n, d, v in vs))
PY
}
wrf5 "$T/wrf5.nc" 1000
"$A" volume info "$T/wrf5.nc" >"$T/out" 2>"$T/err" && ok "small WRF file read" || { bad "small WRF file"; cat "$T/err" >&2; }
hasnt "small WRF file, default voxel" "choose a smaller voxel"
v=$(sed -n 's/.* voxels of \([0-9.]*\) m.*/\1/p' "$T/out" | head -1)
python3 -c "import sys; sys.exit(0 if 0 < float('$v') <= 2500 / 8 else 1)" && ok "default voxel $v m <= 2500/8 m" \
    || bad "default voxel '$v' m: fewer than 8 over 2500 m"
"$A" volume info "$T/wrf5.nc" --voxel-size 500 >/dev/null 2>"$T/err"
has "small WRF file, --voxel-size 500" "choose a smaller voxel"

# --- 5. no atmosphere and no camera given, a volume framed from above the flat-earth model's
# range (a WRF domain of 400 x 300 km): the spherical model, said in a line, no warning of an
# endless plane; --atmosphere riley keeps the flat model (and its warning)
wrf5 "$T/wide.nc" 100000
P='particles.cloud={"kind":"analytic","lobes":[{"type":"hg","g":0.8}],"sigma_ext_m2":6e-10}'
"$A" render --volume "$T/wide.nc" -D "$P" --width 8 --height 8 --slices 8 -o "$T/wide.png" 2>"$T/err" \
    && ok "wide WRF render" || { bad "wide WRF render"; cat "$T/err" >&2; }
hasnt "wide WRF, no atmosphere given" "endless plane"
has "wide WRF, no atmosphere given" "using the spherical atmosphere model"
"$A" render --volume "$T/wide.nc" -D "$P" --atmosphere riley --width 8 --height 8 --slices 8 -o "$T/wide.png" \
    2>"$T/err" && ok "wide WRF render, riley" || { bad "wide WRF render, riley"; cat "$T/err" >&2; }
has "wide WRF, --atmosphere riley" "endless plane"
hasnt "wide WRF, --atmosphere riley" "using the spherical"

# --- 6. off a terminal, with no ATMOS_PROGRESS_INTERVAL, a long first render (the cloud's phase
# tables built, the cache empty) logs a line every few seconds (5), whatever its stages last:
# a run of over 12 s has at least two lines
t0=$(date +%s)
"$A" render --volume generate:cumulus --width 16 --height 9 --slices 16 -o "$T/cu.png" 2>"$T/err" \
    || { bad "cumulus render"; cat "$T/err" >&2; }
wall=$(( $(date +%s) - t0 ))
lines=$(grep -c "^atmos: .*: [0-9]* %, [0-9.]* s elapsed$" "$T/err")
if [ "$wall" -gt 12 ]; then
    [ "$lines" -ge 2 ] && ok "progress log: $lines lines in $wall s" || { bad "progress log: $lines lines in $wall s"; cat "$T/err" >&2; }
else
    echo "skip: the render took $wall s (too short to need a progress line); $lines lines"
fi

# --- 7. atmos volume takes render's names: the same numbers as its own
"$A" volume generate cumulus --voxel-size 200 --scale 0.5 -o "$T/g1.json" >/dev/null 2>&1
"$A" volume generate cumulus --voxel-size 200 --volume-scale 0.5 -o "$T/g2.json" >/dev/null 2>"$T/err" \
    && ok "generate --volume-scale" || { bad "generate --volume-scale"; cat "$T/err" >&2; }
"$A" volume info "$T/g1.json" --as rain --scale 3 --length-scale 2 >"$T/own" 2>&1
"$A" volume info "$T/g2.json" --particle rain --density-scale 3 --volume-scale 2 >"$T/render" 2>"$T/err" \
    && ok "info --particle --density-scale --volume-scale" || { bad "info with render's names"; cat "$T/err" >&2; }
sed 's/g[12]\.json//' "$T/own" >"$T/own2"; sed 's/g[12]\.json//' "$T/render" >"$T/render2"
[ -s "$T/own2" ] && cmp -s "$T/own2" "$T/render2" && ok "render's names read as volume's own" \
    || { bad "render's names differ:"; diff "$T/own" "$T/render" >&2; }
# render's name keeps render's bound (0, 100]: a factor that render refuses is refused here too
"$A" volume info "$T/g1.json" --volume-scale 500 >/dev/null 2>"$T/err"; [ $? -eq 2 ] \
    && ok "info --volume-scale 500 refused as render refuses it" || bad "info --volume-scale 500 accepted"
# a density factor beyond the scene's bound: a usage error naming the option, not the library's
# "set_dense: scale ... got inf"
"$A" volume info "$T/g1.json" --scale 1e300 >/dev/null 2>"$T/err"; [ $? -eq 2 ] && grep -q -- "--scale: expected a factor in (0, 1e30]" "$T/err" \
    && ok "info --scale 1e300 refused" || bad "info --scale 1e300: $(cat "$T/err")"
"$A" volume info "$T/g1.json" --grids density,density >/dev/null 2>"$T/err"; [ $? -eq 1 ] && grep -q "grids: 'density' is named twice" "$T/err" \
    && ok "a grid named twice said so" || bad "--grids density,density: $(cat "$T/err")"
# the help texts
"$A" render --help >"$T/err"
hasnt "render --help" "[> 0, 2]"
has "render --help, --camera" "slice and beams renderers take pinhole only"
"$A" simulate --help >"$T/err"
has "simulate --help" "-q, --quiet"
for c in render sky sun mie phase volume simulate view compare cache bench; do
    "$A" $c --help >"$T/err" 2>&1
    has "$c --help" "Exit status: 0 success, 1 runtime error, 2 usage error."
    awk 'length > 100 { exit 1 }' "$T/err" && ok "$c --help within 100 columns" || bad "$c --help: a line over 100 columns"
done

# --- 8. the docs' render commands (a command continued with a backslash included) take only
# the options of atmos render --help
"$A" render --help >"$T/help"
python3 - "$T/help" "${ATMOS_SOURCE_DIR:?}" >"$T/err" <<'PY'
import glob, re, sys
opts = set(re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", open(sys.argv[1]).read()))
root = sys.argv[2]
for f in [root + "/README.md"] + sorted(glob.glob(root + "/docs/*.md")):
    lines = open(f, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        m = re.search(r"atmos render\b", lines[i])
        j = i
        if m:
            cmd = lines[i][m.start():]
            while cmd.rstrip().endswith("\\") and j + 1 < len(lines):
                j += 1
                cmd = cmd.rstrip()[:-1] + " " + lines[j]
            cmd = re.split(r"`|\||;|#|&&", cmd)[0]  # the command alone, not what follows it
            for o in re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", cmd):
                if o not in opts:
                    print("%s:%d: %s" % (f[len(root) + 1:], i + 1, o))
        i = j + 1
PY
[ -s "$T/err" ] && { bad "docs' render commands with options render --help does not list:"; cat "$T/err" >&2; } \
    || ok "the docs' render commands use render --help's options"

# a value refused by the scene's check names the option that sets it, not only its JSON path
"$A" render -q --volume generate:cumulus --eye-scale 1.5 -o "$T/es.png" 2>"$T/err"; st=$?
[ $st -eq 2 ] && grep -q "/slice/eye_scale" "$T/err" && grep -q "the option --eye-scale sets it" "$T/err" \
    && ok "a refused setting names its option" || { bad "refused setting (exit $st)"; cat "$T/err" >&2; }
# a render that fails after its outputs' folders were made (the plan: a mesh that is not there)
# leaves none of the folders it made
printf '{"renderer": "beams", "image": {"width": 16, "height": 8}, "lights": [{"type": "point", "position_m": [0, 5, 0]}], "objects": [{"mesh": "%s/none.obj"}]}' "$T" >"$T/nomesh.json"
"$A" render -q "$T/nomesh.json" -o "$T/made/sub/x.png" 2>"$T/err"; st=$?
[ $st -eq 1 ] && [ ! -e "$T/made" ] && ok "a failed render removes the folders it made" \
    || { bad "failed render (exit $st) left $(ls -d "$T/made" 2>/dev/null)"; cat "$T/err" >&2; }
exit $fail
