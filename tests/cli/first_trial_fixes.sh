#!/bin/sh
# What a new user's first trial of the CLI ran into, each now as the help and docs say:
#  1. --density-scale multiplies the scene's volume density_scale (does not replace it);
#     -D volume.density_scale=V still sets the value itself;
#  2. -q hides the progress and status lines, not the warnings (a nearly invisible volume);
#  3. an animation numbers the --tau optical-depth map as it numbers the other outputs;
#  4. render's --view-elevation takes [-90, 90]: a nadir view from orbit, and a volume framed
#     from straight above, render, and -90 is the limit of -89.95 (the same image top);
#  5. a one-sample path render says its relative error is n/a, not 0.00 %;
#  6. atmos volume info|slice|stats take --time-index N as atmos render does (--time N kept);
#  7. a raw volume file or its JSON sidecar given as a scene: the hint names the sidecar;
#  8. atmos compare given a PNG says that it is not an HDR input.
. "$(dirname "$0")/common.inc"
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }
hasnt() { grep -qF -- "$2" "$T/err" && { bad "$1: '$2' in:"; sed 's/^/  /' "$T/err" >&2; } || ok "$1: no '$2'"; }

"$A" volume generate cumulus -o "$T/v.json" --voxel-size 200 >/dev/null 2>&1 || bad "volume generate"
# an analytic particle (no Mie table to build): sigma_ext 6e-10 m^2, a cloud droplet's
P='particles.cloud={"kind":"analytic","lobes":[{"type":"hg","g":0.8}],"sigma_ext_m2":6e-10}'
small="--width 16 --height 9 --renderer path --spp 1"

# --- 1. --density-scale is a factor on the scene's density_scale: the optical depth of a
# scene at 4 with --density-scale 0.5 is the one of the same scene at 2 (tau is linear in
# the densities, so the same file), and differs from the scene at 0.5
scene() { printf '{"volume": {"file": "%s", "density_scale": %s}}' "$T/v.json" "$1" >"$T/s$1.json"; }
scene 4; scene 2; scene 0.5
for s in 4:0.5:a 2::b 0.5::c; do
    ds=$(echo "$s" | cut -d: -f1) f=$(echo "$s" | cut -d: -f2) n=$(echo "$s" | cut -d: -f3)
    # shellcheck disable=SC2086
    "$A" render "$T/s$ds.json" -D "$P" $small ${f:+--density-scale $f} --pfm "$T/i$n.pfm" --tau "$T/t$n.pfm" -q \
        2>"$T/err" || { bad "render at density_scale $ds ${f:+x $f}"; cat "$T/err" >&2; }
done
cmp -s "$T/ta.pfm" "$T/tb.pfm" && ok "scene 4 with --density-scale 0.5 = scene 2 (same optical depth)" ||
    bad "scene 4 with --density-scale 0.5 is not the scene at 2"
cmp -s "$T/ta.pfm" "$T/tc.pfm" && bad "--density-scale 0.5 replaced the scene's 4 by 0.5" || ok "not the scene at 0.5"
# -D volume.density_scale sets the value: -D ...=2 on the scene at 4 = the scene at 2
# shellcheck disable=SC2086
"$A" render "$T/s4.json" -D "$P" -D volume.density_scale=2 $small --pfm "$T/id.pfm" --tau "$T/td.pfm" -q 2>"$T/err" ||
    { bad "-D volume.density_scale=2"; cat "$T/err" >&2; }
cmp -s "$T/td.pfm" "$T/tb.pfm" && ok "-D volume.density_scale=2 sets 2" || bad "-D volume.density_scale=2 is not the scene at 2"

# --- 2. -q keeps the warnings, drops the status lines
# shellcheck disable=SC2086
"$A" render --volume "$T/v.json" -D "$P" $small --density-scale 1e-9 -q --pfm "$T/q.pfm" >/dev/null 2>"$T/err" ||
    bad "-q render of a thin volume"
has "-q, thin volume" "nearly invisible"
hasnt "-q" "wrote"
hasnt "-q" "no camera given"

# --- 3. an animation's optical depth maps are numbered per frame
# shellcheck disable=SC2086
"$A" render --volume "$T/v.json" -D "$P" $small --frames 2 --sun-elevation-end 20 --pfm "$T/an/f.pfm" \
    --tau "$T/an/t.pfm" -q 2>"$T/err" || { bad "animation with --tau"; cat "$T/err" >&2; }
for n in 0001 0002; do
    [ -s "$T/an/t_$n.pfm" ] && ok "frame $n's optical depth t_$n.pfm" || bad "no t_$n.pfm (have: $(ls "$T/an" | tr '\n' ' '))"
done
[ ! -e "$T/an/t.pfm" ] && ok "no un-numbered t.pfm" || bad "an un-numbered t.pfm was written"
# the camera does not move: both frames' maps are the same
cmp -s "$T/an/t_0001.pfm" "$T/an/t_0002.pfm" && ok "the two frames' optical depths agree" || bad "frames' tau differ"

# --- 4. --view-elevation in [-90, 90]: nadir from orbit, a volume framed from above
sky="-D atmosphere.model=spherical --altitude 400000 --width 16 --height 16 --view-azimuth 30"
# shellcheck disable=SC2086
"$A" render $sky --view-elevation -90 --pfm "$T/n90.pfm" -q 2>"$T/err" && ok "nadir view from 400 km (exit 0)" ||
    { bad "--view-elevation -90 refused"; cat "$T/err" >&2; }
# shellcheck disable=SC2086
"$A" render $sky --view-elevation -89.95 --pfm "$T/n89.pfm" -q 2>"$T/err" || bad "--view-elevation -89.95"
# the same view turned by 0.05 deg: the image's top must not jump (relative RMSE well under 1 %)
if [ -s "$T/n90.pfm" ] && [ -s "$T/n89.pfm" ]; then
    rr=$("$A" compare "$T/n90.pfm" "$T/n89.pfm" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["rel_rmse"])' 2>/dev/null)
    python3 -c "import sys; sys.exit(0 if float('$rr') < 0.01 else 1)" 2>/dev/null &&
        ok "-90 is the limit of -89.95 (relative RMSE $rr)" || bad "-90 and -89.95 differ: relative RMSE '$rr'"
fi
# shellcheck disable=SC2086
"$A" render $sky --view-elevation 90 --pfm "$T/z90.pfm" -q 2>"$T/err" && ok "zenith view (exit 0)" || bad "--view-elevation 90 refused"
# shellcheck disable=SC2086
"$A" render $sky --view-elevation -90.5 --pfm "$T/x.pfm" -q 2>"$T/err"
[ $? -eq 2 ] && ok "--view-elevation -90.5 is a usage error" || bad "--view-elevation -90.5 not a usage error"
# shellcheck disable=SC2086
"$A" render --volume "$T/v.json" -D "$P" $small --view-elevation -90 --pfm "$T/vn.pfm" 2>"$T/err" ||
    { bad "a volume framed from straight above"; cat "$T/err" >&2; }
has "volume framed from above" "no camera given"

# --- 5. one sample per pixel: no error estimate
# shellcheck disable=SC2086
"$A" render --volume "$T/v.json" -D "$P" $small --pfm "$T/s1.pfm" 2>"$T/err" || bad "--spp 1 render"
has "--spp 1" "n/a (1 sample per pixel)"
hasnt "--spp 1" "0.00 %"

# --- 6. --time-index for the volume commands (a raw volume has one time: 0 reads, 2 is refused)
"$A" volume info "$T/v.json" --time-index 0 >/dev/null 2>"$T/err" && ok "volume info --time-index 0" ||
    { bad "volume info --time-index 0"; cat "$T/err" >&2; }
"$A" volume info "$T/v.json" --time 0 >/dev/null 2>"$T/err" && ok "volume info --time 0 (kept)" || bad "volume info --time 0"
"$A" volume info "$T/v.json" --time-index 2 >/dev/null 2>"$T/err"
[ $? -ne 0 ] && ok "volume info --time-index 2 on a raw volume refused" || bad "volume info --time-index 2 accepted"
has "--time-index 2" "time index"
"$A" volume slice "$T/v.json" --axis y --time-index 0 -o "$T/sl.png" >/dev/null 2>"$T/err" && ok "volume slice --time-index 0" ||
    { bad "volume slice --time-index 0"; cat "$T/err" >&2; }
"$A" volume --help 2>&1 | grep -q -- "--time-index N" && ok "volume --help names --time-index" || bad "volume --help: no --time-index"

# --- 7. a raw file or its sidecar given as the scene
"$A" render "$T/v.cloud.raw" -o "$T/r.png" >/dev/null 2>"$T/err"
[ $? -eq 2 ] && ok "a raw file as the scene: usage error" || bad "a raw file as the scene: not exit 2"
has "raw as scene" "--volume $T/v.json"
"$A" render "$T/v.json" -o "$T/r.png" >/dev/null 2>"$T/err"
[ $? -eq 2 ] && ok "a sidecar as the scene: usage error" || bad "a sidecar as the scene: not exit 2"
has "sidecar as scene" "is a volume file"
has "sidecar as scene" "--volume $T/v.json"
hasnt "sidecar as scene" "unknown key"
# the hint's command works
# shellcheck disable=SC2086
"$A" render --volume "$T/v.json" -D "$P" $small --pfm "$T/h.pfm" -q 2>"$T/err" && ok "the hint's command renders" || bad "the hint's command fails"
cp "$T/v.cloud.raw" "$T/lone.raw"
"$A" render "$T/lone.raw" -o "$T/r.png" >/dev/null 2>"$T/err"
has "raw without a sidecar" "sidecar"
[ ! -e "$T/r.png" ] && ok "nothing written" || bad "an image was written"

# --- 8. compare given a PNG
"$A" render --volume "$T/v.json" -D "$P" $small -o "$T/c.png" --pfm "$T/c.pfm" -q 2>"$T/err" || bad "render for compare"
"$A" compare "$T/c.png" "$T/c.pfm" >/dev/null 2>"$T/err"
[ $? -ne 0 ] && ok "compare PNG PFM refused" || bad "compare PNG PFM accepted"
has "compare a PNG" "not an HDR input"
has "compare a PNG" ".pfm"
hasnt "compare a PNG" "not a readable OpenEXR"

# --- 9. -o X.exr takes --exr-layers when there is no --exr; a PNG output alone still refuses them
"$A" render --volume "$T/v.json" $small --exr-layers tau,transmittance -o "$T/l.exr" -q 2>"$T/err" ||
    { bad "-o X.exr with --exr-layers"; cat "$T/err" >&2; }
grep -aq "transmittance.Y" "$T/l.exr" 2>/dev/null && grep -aq "tau.Y" "$T/l.exr" && ok "-o X.exr holds the layers" ||
    bad "-o X.exr without the layers"
"$A" render --volume "$T/v.json" $small --exr-layers tau -o "$T/l.png" >/dev/null 2>"$T/err"
[ $? -eq 2 ] && ok "--exr-layers with a PNG output alone: usage error" || bad "--exr-layers with a PNG output accepted"
has "--exr-layers without an EXR" "-o FILE.exr"
exit $fail
