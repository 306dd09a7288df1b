#!/bin/sh
# atmos render's outputs are what their names say and are written all or none: the format
# by the extension, half-float EXRs without overflow, the variance EXR's channel names, the
# EXR header (render metadata, chromaticities, numbers as numbers), folders created, every
# output checked before rendering (and before a volume is read), no output written twice or
# over an input, no temporary left by SIGTERM, and one exposure over an animation.
set -u
A=${ATMOS_CLI:?ATMOS_CLI not set}
T=${ATMOS_TEST_TMP:-/tmp}/cli_outputs.$$
mkdir -p "$T"
export XDG_CACHE_HOME="$T/cache"
fail=0; pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*" >&2; fail=$((fail + 1)); }
S="--width 32 --height 16"
# A path-traced cloud of analytic particles (no optical table to build).
cat > "$T/path.json" <<'EOF'
{
  "image": {"width": 24, "height": 16},
  "sun": {"elevation_deg": 22, "azimuth_deg": 235},
  "particles": {"cloud": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.8}], "sigma_ext_m2": 6.28e-10}},
  "renderer": "path",
  "volume": {"generate": "cumulus"},
  "path": {"spp": 2}
}
EOF
P="$T/path.json"

# The header of an EXR as lines "name type value" (exr_header.py).
exr_header() { python3 "$(dirname "$0")/exr_header.py" "$1"; }

# 1. The writer by the extension; other extensions refused before rendering.
"$A" render -q $S -o "$T/o.exr" && ok || bad "-o x.exr"
[ "$(head -c 4 "$T/o.exr" | od -An -tx1 | tr -d ' ')" = "762f3101" ] && ok || bad "-o x.exr did not write an OpenEXR file"
"$A" render -q $S -o "$T/o.PFM" && ok || bad "-o x.PFM"
[ "$(head -c 3 "$T/o.PFM" | od -An -c | tr -d ' ')" = 'PF\n' ] && ok || bad "-o x.PFM did not write a PFM"
"$A" render -q $S -o "$T/o.png" && [ "$(head -c 4 "$T/o.png" | od -An -c | tr -d ' ')" = "211PNG" ] && ok || bad "-o x.png"
for name in o.jpg o.tiff noext; do
    "$A" render -q $S -o "$T/$name" 2>"$T/err"; rc=$?
    [ $rc -eq 2 ] && [ ! -e "$T/$name" ] && grep -q "extension" "$T/err" && ok || bad "-o $name: rc $rc, $(cat "$T/err")"
done
"$A" render -q $S --exr "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && [ ! -e "$T/x.png" ] && ok || bad "--exr x.png should exit 2"
"$A" render -q $S --pfm "$T/x.exr" 2>/dev/null; [ $? -eq 2 ] && [ ! -e "$T/x.exr" ] && ok || bad "--pfm x.exr should exit 2"

# 2. Half floats: the sun (~1e9 cd/m^2 in the float file) is clamped to 65504 with a
# warning, not stored as infinity.
"$A" render $S --exr "$T/f.exr" 2>/dev/null && "$A" render $S --exr "$T/h.exr" --exr-half 2>"$T/herr" && ok || bad "--exr-half"
grep -q "clamped to 65504" "$T/herr" && ok || bad "--exr-half: no warning about clamping ($(cat "$T/herr"))"
out=$("$A" compare "$T/h.exr" "$T/f.exr" --json 2>&1)
echo "$out" | grep -q '"nonfinite": 0[,}]' && ok || bad "--exr-half wrote non-finite values: $out"

# 3 and 4. The variance EXR (rgb): named channels and the render's metadata; every EXR
# carries the chromaticities and numbers as numbers.
"$A" render -q $P --rgb --exr "$T/p.exr" --variance "$T/v.exr" && ok || bad "path render --variance"
exr_header "$T/v.exr" > "$T/vh" || bad "variance EXR unreadable"
grep -q "^channels chlist variance.440nm,variance.550nm,variance.680nm,variance.Y$" "$T/vh" && ok || bad "variance channels: $(grep chlist "$T/vh")"
# no chromaticities: they describe R, G and B, which a variance file has not
grep -q "^chromaticities" "$T/vh" && bad "variance EXR has chromaticities" || ok
# one spelling: the --exr-layers variance layers are the --variance file's channels, spectral
# wavelengths as they are (386.25 nm, not 386 or 386.2), with OpenEXR's comma so that the
# layer stays "variance"
"$A" render -q $P --spectral 32 --exr "$T/ps.exr" --exr-layers variance --variance "$T/vs.exr" && ok || bad "spectral variance"
vs=$(exr_header "$T/vs.exr" | grep '^channels' | cut -d' ' -f3)
ls=$(exr_header "$T/ps.exr" | grep '^channels' | cut -d' ' -f3 | sed 's/^A,B,G,R,//')
[ -n "$vs" ] && [ "$vs" = "$ls" ] && ok || bad "variance names differ: file '$vs', layers '$ls'"
echo "$vs" | grep -q "variance.386,25nm,variance.398,75nm" && ok || bad "spectral variance names: $vs"
exr_header "$T/vs.exr" | grep -q '^atmos:units string variance of the mean.*W m^-2 sr^-1 nm^-1.*variance.Y in (cd/m^2)^2' \
    && ok || bad "variance file: units $(exr_header "$T/vs.exr" | grep '^atmos:units')"
exr_header "$T/ps.exr" | grep -q '^atmos:units string linear sRGB.*; variance.\*: variance of the mean' \
    && ok || bad "layered file: units $(exr_header "$T/ps.exr" | grep '^atmos:units')"
for key in "atmos:scene string" "atmos:renderer string path" "atmos:sun_elevation_deg double 22.0" \
    "atmos:sun_azimuth_deg double 235.0" "atmos:threads int" "atmos:version string" "atmos:wavelengths_nm string 680.0 550.0 440.0" \
    "atmos:atmosphere string"; do
    grep -q "^$key" "$T/vh" && ok || bad "variance EXR lacks '$key'"
done
for f in o.exr f.exr h.exr p.exr ps.exr; do
    exr_header "$T/$f" > "$T/hdr"
    grep -q "^chromaticities chromaticities 0.6400,0.3300,0.3000,0.6000,0.1500,0.0600,0.3127,0.3290$" "$T/hdr" \
        && ok || bad "$f: no Rec. 709 / D65 chromaticities"
done
exr_header "$T/p.exr" > "$T/hdr"
grep -q "^atmos:path_mean_rel_error double" "$T/hdr" && ok || bad "p.exr: error figure not a double"
grep -q "^atmos:render_seconds double" "$T/hdr" && ok || bad "p.exr: render time not a double"

# 5. Missing folders are created; an output that cannot be written fails the command
# before rendering, and no other output is written or replaced.
"$A" render -q $S -o "$T/new/sub/a.png" --exr "$T/new/b.exr" && [ -s "$T/new/sub/a.png" ] && [ -s "$T/new/b.exr" ] \
    && ok || bad "outputs in missing folders"
: > "$T/plain"
cp "$T/f.exr" "$T/keep.exr"
t0=$(date +%s)
"$A" render -q $P --spp 20000 --exr "$T/keep.exr" --pfm "$T/plain/x.pfm" 2>"$T/err"; rc=$?
t1=$(date +%s)
[ $rc -eq 1 ] && grep -q "plain" "$T/err" && ok || bad "an unwritable output: rc $rc, $(cat "$T/err")"
[ $((t1 - t0)) -le 5 ] && ok || bad "an unwritable output was found after $((t1 - t0)) s of rendering"
cmp -s "$T/keep.exr" "$T/f.exr" && ok || bad "the other output was replaced though the command failed"
# ... and before the scene and its volume are read: no framing line (a volume file without a
# camera is read and framed first), and the folders the check made are gone again.
"$A" volume generate cumulus -o "$T/cu.json" --voxel-size 200 >/dev/null 2>&1 || bad "volume generate"
"$A" render $S --volume "$T/cu.json" -o "$T/gone/sub/a.png" --pfm "$T/plain/x.pfm" 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && grep -q "plain" "$T/err" && ! grep -q "framing" "$T/err" && [ ! -e "$T/gone" ] && ok \
    || bad "an unwritable output beside a volume file: rc $rc, $(cat "$T/err"), $(ls -d "$T/gone" 2>&1)"
"$A" render $S --volume "$T/missing.vdb" --exr "$T/plain/x.exr" 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && grep -q "plain" "$T/err" && ! grep -q "missing" "$T/err" && ok \
    || bad "an unwritable output told after a missing volume: rc $rc, $(cat "$T/err")"
mkdir "$T/adir.pfm"
"$A" render -q $S --pfm "$T/adir.pfm" --exr "$T/keep.exr" 2>/dev/null; [ $? -ne 0 ] && cmp -s "$T/keep.exr" "$T/f.exr" \
    && ok || bad "an output that is a folder"

# A write that fails after rendering (a file size limit: the small half-float EXR fits, the
# PFM does not) replaces none of the outputs and leaves no temporary.
mkdir -p "$T/fs"
"$A" render -q --width 128 --height 128 --exr "$T/fs/keep.exr" --exr-half && cp "$T/fs/keep.exr" "$T/fs/keep0.exr" \
    && ok || bad "render keep.exr"
sh -c 'trap "" XFSZ; ulimit -f 100; exec "$@"' sh "$A" render -q --width 128 --height 128 --sun-elevation 40 \
    --exr "$T/fs/keep.exr" --exr-half --pfm "$T/fs/new.pfm" 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && grep -q "new.pfm" "$T/err" && ok || bad "a failed write: rc $rc, $(cat "$T/err")"
cmp -s "$T/fs/keep.exr" "$T/fs/keep0.exr" && ok || bad "the EXR was replaced though the PFM failed"
[ "$(ls "$T/fs")" = "$(printf 'keep.exr\nkeep0.exr')" ] && ok || bad "a failed write left: $(ls "$T/fs")"

# 6. No output twice, none over an input.
"$A" render -q $S -o "$T/d.pfm" --pfm "$T/../$(basename "$T")/./d.pfm" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "same file" "$T/err" && [ ! -e "$T/d.pfm" ] && ok || bad "the same PFM twice: rc $rc"
"$A" render -q $P --pfm "$T/d.pfm" --tau "$T/d.pfm" 2>/dev/null; [ $? -eq 2 ] && [ ! -e "$T/d.pfm" ] && ok || bad "--pfm X --tau X"
"$A" render -q $S -o "$T/d.exr" --exr "$T/d.exr" 2>/dev/null; [ $? -eq 2 ] && ok || bad "-o X.exr --exr X.exr"
# the files a scene reads are inputs too: a light's image and a height map (the beams scenes)
SRC=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}
cp "$SRC/scenes/dobashi_fig09b_window.png" "$T/win.png"; cp "$T/win.png" "$T/win0.png"; cp "$T/win.png" "$T/hm.png"
"$A" render -q "$SRC/scenes/dobashi_fig09b_stained_glass.json" $S -D "lights.0.image=$T/win.png" -o "$T/win.png" 2>"$T/err"
[ $? -eq 2 ] && grep -q "refusing to overwrite an input" "$T/err" && cmp -s "$T/win.png" "$T/win0.png" && ok ||
    bad "-o over the light's image: $(cat "$T/err")"
"$A" render -q "$SRC/scenes/dobashi_fig04_spotlight.json" $S -D "objects.1={\"terrain\": \"$T/hm.png\", \"size_m\": 30, \"height_m\": 3}" \
    --pfm "$T/x.pfm" -o "$T/hm.png" 2>"$T/err"
[ $? -eq 2 ] && grep -q "refusing to overwrite an input" "$T/err" && cmp -s "$T/hm.png" "$T/win0.png" && [ ! -e "$T/x.pfm" ] && ok ||
    bad "-o over the height map: $(cat "$T/err")"
# a raw volume's data file, which its sidecar names (here data.exr), is an input too: render and
# volume slice refuse it as an output and leave it whole
"$A" volume generate cumulus -o "$T/cu.json" --voxel-size 200 >/dev/null || bad "volume generate"
rawf=$(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["fields"][0]["file"])' "$T/cu.json")
cp "$T/$rawf" "$T/data.exr"; cp "$T/data.exr" "$T/data0.exr"; cp "$T/data.exr" "$T/slice.png"
sed "s|\"$rawf\"|\"data.exr\"|" "$T/cu.json" >"$T/side.json"
sed "s|\"$rawf\"|\"slice.png\"|" "$T/cu.json" >"$T/side2.json"
"$A" render -q --volume "$T/side.json" $S --exr "$T/data.exr" 2>"$T/err"
[ $? -eq 2 ] && grep -q "refusing to overwrite an input" "$T/err" && cmp -s "$T/data.exr" "$T/data0.exr" && ok ||
    bad "--exr over the volume's raw data: $(cat "$T/err")"
"$A" volume slice "$T/side2.json" --axis z -o "$T/slice.png" 2>"$T/err"
[ $? -eq 2 ] && grep -q "refusing to overwrite an input" "$T/err" && cmp -s "$T/slice.png" "$T/data0.exr" && ok ||
    bad "volume slice -o over the volume's raw data: $(cat "$T/err")"
ln -s "$T/f.exr" "$T/link.exr"
"$A" render -q $S --exr "$T/link.exr" -o "$T/f.exr" 2>/dev/null; [ $? -eq 2 ] && ok || bad "an output and a link to it"
cp "$T/f.exr" "$T/ref.exr"
"$A" render -q $S --pfm "$T/a.pfm" && ok || bad "render a.pfm"
cp "$T/a.pfm" "$T/a0.pfm"
ln -s a.pfm "$T/heat.png"
"$A" compare "$T/f.exr" "$T/a.pfm" --heatmap "$T/heat.png" >/dev/null 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && cmp -s "$T/a.pfm" "$T/a0.pfm" && ok || bad "compare --heatmap over its reference: rc $rc, $(cat "$T/err")"
"$A" compare "$T/f.exr" "$T/a.pfm" --heatmap "$T/a.pfm" >/dev/null 2>&1; [ $? -eq 2 ] && cmp -s "$T/a.pfm" "$T/a0.pfm" \
    && ok || bad "compare A B --heatmap B"
cp "$T/f.exr" "$T/f2.exr"
"$A" compare "$T/f.exr" "$T/f2.exr" --heatmap "$T/fine.png" >/dev/null && [ -s "$T/fine.png" ] && ok || bad "compare --heatmap"

# 6b. An output that another user owns in a sticky folder (as /tmp) cannot be renamed onto: said
# before the render, nothing written (it had failed after the render, the other outputs renamed).
# Only as root, where another user can be taken on (setpriv).
if [ "$(id -u)" = 0 ] && command -v setpriv >/dev/null 2>&1; then
    mkdir "$T/sticky" && chmod 1777 "$T/sticky" && echo old >"$T/sticky/b.pfm"
    chmod o+x "$T" 2>/dev/null
    as_nobody() { setpriv --reuid=65534 --regid=65534 --clear-groups "$@"; }
    if as_nobody "$A" --version >/dev/null 2>&1 && as_nobody test -w "$T/sticky"; then
        as_nobody "$A" render -q $S -o "$T/sticky/a.png" --pfm "$T/sticky/b.pfm" 2>"$T/err"; rc=$?
        [ $rc -eq 1 ] && grep -q "another user" "$T/err" && [ ! -e "$T/sticky/a.png" ] && [ "$(cat "$T/sticky/b.pfm")" = old ] &&
            ok || bad "another user's output in a sticky folder: rc $rc, $(cat "$T/err"), left: $(ls "$T/sticky")"
    fi
fi

# 7. SIGTERM while the outputs are written leaves no temporary and no partial output.
mkdir "$T/sig"
"$A" render -q $P --width 512 --height 512 --spp 1 --spectral 16 \
    --variance "$T/sig/v.exr" --order "$T/sig/o.pfm" --tau "$T/sig/t.pfm" --pfm "$T/sig/p.pfm" 2>/dev/null &
pid=$!
n=0
while [ -z "$(ls "$T/sig" | grep tmp)" ] && [ $n -lt 1200 ] && kill -0 $pid 2>/dev/null; do sleep 0.02; n=$((n + 1)); done
kill -TERM $pid 2>/dev/null
wait $pid; rc=$?
[ $rc -ne 0 ] && ok || bad "a terminated run should fail (rc $rc)"
[ -z "$(ls "$T/sig")" ] && ok || bad "SIGTERM left: $(ls "$T/sig")"

# 8. One exposure over an animation: the sun setting from 12 to -1 degrees makes each
# frame darker than the one before (mean display value of the PNGs); per frame on request.
"$A" render -q --width 48 --height 27 --frames 5 --sun-elevation 12 --sun-elevation-end -1 -o "$T/an/s.png" \
    && ok || bad "animation"
"$A" render -q --width 48 --height 27 --frames 5 --sun-elevation 12 --sun-elevation-end -1 -o "$T/pf/s.png" \
    --exposure-per-frame && ok || bad "animation --exposure-per-frame"
"$A" render -q --width 48 --height 27 --sun-elevation 12 -o "$T/pk/s.png" -D animation.frames=5 \
    -D animation.elevation_end_deg=-1 -D animation.exposure=per_frame && ok || bad "animation, the scene's exposure per_frame"
"$A" render -q --width 48 --height 27 --sun-elevation 12 -o "$T/one.png" && ok || bad "single render"
# (the here-document's text starts on the line after the one with <<: bad on that line too)
PYTHONPATH=$(cd "$(dirname "$0")" && pwd) python3 - "$T/an" "$T/pf" "$T/one.png" "$T/pk" <<'PY' && ok || bad "exposure over the animation"
import os, sys
from png import mean  # tests/cli/png.py
locked = [mean(os.path.join(sys.argv[1], "s_%04d.png" % k)) for k in range(1, 6)]
free = [mean(os.path.join(sys.argv[2], "s_%04d.png" % k)) for k in range(1, 6)]
print("locked", ["%.1f" % m for m in locked], "per frame", ["%.1f" % m for m in free])
assert all(b < a for a, b in zip(locked, locked[1:])), "not darker frame by frame"
# The scene's mean luminance falls to a fifth from frame 1 (12 deg) to frame 4 (2.25 deg):
# with one exposure the display falls clearly too (per-frame exposure keeps it at ~0.94).
assert locked[3] < 0.75 * locked[0], "frame 4 is nearly as bright as frame 1: re-exposed"
assert mean(sys.argv[3]) == locked[0] == free[0], "the first frame is not exposed as a single render"
assert free[3] > 1.5 * locked[3], "--exposure-per-frame does not re-expose"
# The scene's key "animation": {"exposure": "per_frame"} is the option's scene form.
keyed = [mean(os.path.join(sys.argv[4], "s_%04d.png" % k)) for k in range(1, 6)]
assert keyed == free, "animation.exposure=per_frame differs from --exposure-per-frame: %s" % keyed
PY

rm -rf "$T"
echo "render_outputs: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
