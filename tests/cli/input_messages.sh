#!/bin/sh
# Inputs a new user gets wrong, and the messages that tell them what to do:
#  - a file that is not an image given as an Earth map: the message names the scene key, the
#    path and the formats read (PNG, JPEG), not the image library's "Read Error" (a PNG cut
#    short: "truncated"); a scene file's
#    cloud image that cannot be read: the scene file too; an image given as the scene: said so;
#  - -D volume.KEY=VALUE together with --volume FILE: applies to that file, as the option of
#    the same meaning does (-D volume.density_unit=per_m3 == --density-unit per_m3);
#  - --volume with a -D naming another volume source: refused, both named, nothing written;
#  - fog or lights given to the slice renderer: a warning that it does not draw them; objects
#    too, but not to Harris's renderer, which draws them;
#  - a beam scene without a sun: the status line names its lights, not an unused sun;
#  - an all-zero volume: said to be empty, not told to raise --density-scale;
#  - a -D that leaves a valid scene file invalid through another key (fog.extinction_per_m below
#    the file's scattering) or that cannot be placed (lights.1 in a scene of one light): a usage
#    error (exit 2) saying the file alone is valid; a broken file with a harmless -D stays exit 1.
. "$(dirname "$0")/common.inc"
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }

# --- a text file as the ground map
echo "not an image" >"$T/notes.txt"
"$A" render -D atmosphere.model=spherical -D "atmosphere.ground_map=$T/notes.txt" --width 8 --height 8 \
    -o "$T/g.png" >/dev/null 2>"$T/err"
st=$?
[ $st -ne 0 ] && ok "a text ground map is refused (exit $st)" || bad "a text ground map was accepted"
has "text ground map" "/atmosphere/ground_map"
has "text ground map" "notes.txt"
has "text ground map" "PNG or JPEG"
grep -q "Read Error" "$T/err" && bad "the message is libpng's 'Read Error'" || ok "no bare 'Read Error'"
# a truncated PNG still names the key
printf '\211PNG\r\n\032\n' >"$T/cut.png"
"$A" render -D atmosphere.model=spherical -D "atmosphere.night_lights=$T/cut.png" --width 8 --height 8 \
    -o "$T/g.png" >/dev/null 2>"$T/err"
[ $? -ne 0 ] && ok "a truncated PNG map is refused" || bad "a truncated PNG map was accepted"
has "truncated PNG map" "/atmosphere/night_lights"
has "truncated PNG map" "truncated: the PNG file ends before its image does"
# a scene file's cloud image or world file that cannot be read: the message names the scene file
# too, as it does for a missing one (a truncated JPEG, a PNG cut short, a folder)
printf '\377\330\377\340\000\020JFIF\000' >"$T/cut.jpg"
mkdir -p "$T/sc/folder.png"
cp "$T/cut.png" "$T/sc/cut.png"; cp "$T/cut.jpg" "$T/sc/cut.jpg"
for img in cut.jpg cut.png folder.png; do
    printf '{"atmosphere": {"model": "spherical", "clouds": {"image": "%s", "base_m": 2000, "top_m": 8000}},
 "image": {"width": 8, "height": 8}}\n' "$img" >"$T/sc/clouds.json"
    "$A" render "$T/sc/clouds.json" -o "$T/g.png" >/dev/null 2>"$T/err"
    [ $? -eq 1 ] && ok "cloud image $img refused (exit 1)" || bad "cloud image $img: not exit 1"
    has "cloud image $img" "sc/clouds.json: /atmosphere/clouds/image: "
    has "cloud image $img" "$img"
done

# --- an image given as the scene: said what it is (not "malformed JSON: control character"),
# exit 2, no output
"$A" render -q --width 8 --height 8 --exr "$T/img.exr" -o "$T/img.png" 2>/dev/null || bad "render img.exr"
for img in img.exr img.png; do
    "$A" render "$T/$img" -o "$T/as_scene.png" >/dev/null 2>"$T/err"
    st=$?
    [ $st -eq 2 ] && [ ! -e "$T/as_scene.png" ] && ok "$img as the scene refused (exit 2)" || bad "$img as the scene: exit $st"
    has "$img as the scene" "image, not a scene"
    [ "$img" = img.exr ] && has "$img as the scene" "is an OpenEXR image"
done
has "img.png as the scene" "is a PNG image"
# PFM files with each header the PFM reader takes (LF, CRLF, a space after the magic)
printf 'PF\n1 1\n-1\n\0\0\0\0\0\0\0\0\0\0\0\0' >"$T/lf.pfm"
printf 'PF\r\n1 1\r\n-1\n\0\0\0\0\0\0\0\0\0\0\0\0' >"$T/crlf.pfm"
printf 'Pf 1 1 -1\n\0\0\0\0' >"$T/sp.pfm"
for img in lf.pfm crlf.pfm sp.pfm; do
    "$A" compare "$T/$img" "$T/$img" >/dev/null 2>"$T/err" || { bad "$img: not a PFM the reader takes"; cat "$T/err" >&2; }
    "$A" render "$T/$img" -o "$T/as_scene.png" >/dev/null 2>"$T/err"
    st=$?
    [ $st -eq 2 ] && [ ! -e "$T/as_scene.png" ] && ok "$img as the scene refused (exit 2)" || bad "$img as the scene: exit $st"
    has "$img as the scene" "is a PFM image, not a scene"
done

# --- -D volume.* with --volume FILE
"$A" volume generate cumulus -o "$T/v.json" --voxel-size 200 >/dev/null 2>&1 || bad "volume generate"
P='particles.cloud={"kind":"analytic","lobes":[{"type":"hg","g":0.8}],"sigma_ext_m2":6e-10}'
common="--volume $T/v.json --width 16 --height 9 --renderer path --spp 2"
# shellcheck disable=SC2086
"$A" render $common -D "$P" --density-unit per_m3 --pfm "$T/opt.pfm" >/dev/null 2>"$T/err" || { bad "--density-unit per_m3"; cat "$T/err" >&2; }
# shellcheck disable=SC2086
"$A" render $common -D "$P" -D volume.density_unit=per_m3 --pfm "$T/def.pfm" >/dev/null 2>"$T/err"
st=$?
[ $st -eq 0 ] && ok "-D volume.density_unit=per_m3 with --volume (exit 0)" || { bad "-D volume.density_unit with --volume: exit $st"; cat "$T/err" >&2; }
cmp -s "$T/opt.pfm" "$T/def.pfm" && ok "-D volume.density_unit = --density-unit (same pixels)" || bad "-D volume.density_unit and --density-unit differ"
# shellcheck disable=SC2086
"$A" render $common -D "$P" -D volume.density_scale=1e-3 --pfm "$T/ds.pfm" >/dev/null 2>"$T/err"
st=$?
[ $st -eq 0 ] && ok "-D volume.density_scale with --volume (exit 0)" || { bad "-D volume.density_scale with --volume: exit $st"; cat "$T/err" >&2; }
# a scene with a generated volume (and its seed): --volume FILE replaces it, -D volume.KEY
# applies to the file, and the generator's seed goes with the generator
printf '{"volume": {"generate": "cumulus", "seed": 3}}' >"$T/gen.json"
# shellcheck disable=SC2086
"$A" render "$T/gen.json" $common -D "$P" -D volume.density_unit=per_m3 --pfm "$T/gen.pfm" >/dev/null 2>"$T/err"
st=$?
[ $st -eq 0 ] && ok "scene with a generated volume, --volume FILE -D volume.density_unit (exit 0)" || { bad "generated scene + --volume FILE + -D volume.density_unit: exit $st"; cat "$T/err" >&2; }

# --- --volume with a -D that names another source: refused, both named
"$A" render --volume "$T/v.json" -D volume.generate=cirrus --width 8 --height 8 -o "$T/two.png" >/dev/null 2>"$T/err"
st=$?
[ $st -ne 0 ] && ok "--volume FILE with -D volume.generate is refused (exit $st)" || bad "--volume FILE with -D volume.generate was accepted"
has "two volume sources" "volume.generate=cirrus"
has "two volume sources" "give one of them"
[ ! -e "$T/two.png" ] && ok "no image written for two sources" || bad "an image was written for two sources"

# --- the fog and lights given to the slice renderer: drawn without them, and told so
"$A" render --volume "$T/v.json" -D 'fog={"visibility_m":500}' --width 8 --height 8 -o "$T/fog.png" >/dev/null 2>"$T/err" ||
    { bad "slice render with a fog"; cat "$T/err" >&2; }
has "fog on the slice renderer" "slice renderer does not draw the scene's fog"
"$A" render --volume "$T/v.json" --width 8 --height 8 -o "$T/nofog.png" >/dev/null 2>"$T/err"
grep -q "does not draw" "$T/err" && bad "a warning without fog or lights" || ok "no warning without fog or lights"
# objects: Harris's renderer draws them (its impostors split at them), the slice renderer does not
O='objects=[{"mesh":"builtin:sphere","position_m":[0,1500,0],"scale":100}]'
"$A" render --volume "$T/v.json" -D "$O" --renderer harris --width 8 --height 8 -o "$T/ho.png" >/dev/null 2>"$T/err" ||
    { bad "harris render with objects"; cat "$T/err" >&2; }
grep -q "does not draw" "$T/err" && bad "harris is told it does not draw its objects" || ok "no warning: harris draws objects"
"$A" render --volume "$T/v.json" -D "$O" --width 8 --height 8 -o "$T/so.png" >/dev/null 2>"$T/err" ||
    { bad "slice render with objects"; cat "$T/err" >&2; }
has "objects on the slice renderer" "slice renderer does not draw the scene's objects"

# --- a beam scene without a sun says what lights it, not where the unused sun stands
"$A" render "$S/scenes/searchlights_fog.json" --width 24 --height 16 -o "$T/sl.png" >/dev/null 2>"$T/err" ||
    { bad "searchlights render"; cat "$T/err" >&2; }
has "searchlights status" "lit by its 7 lights and no sun"
grep -q "sun at" "$T/err" && bad "the searchlights' status names a sun" || ok "the searchlights' status names no sun"

# --- an all-zero volume: said to be empty, not told to raise a density scale that cannot help
python3 -c "
import json, struct
open('$T/z.cloud.raw', 'wb').write(struct.pack('<512f', *([0.0] * 512)))
json.dump({'dims': [8, 8, 8], 'voxel_size_m': 100, 'origin_m': [0, 0, 0],
           'fields': [{'name': 'cloud', 'particle': 'cloud', 'file': 'z.cloud.raw'}]}, open('$T/z.json', 'w'))
" || bad "writing the empty volume"
"$A" render --volume "$T/z.json" --width 8 --height 8 -o "$T/z.png" >/dev/null 2>"$T/err" ||
    { bad "render of an empty volume"; cat "$T/err" >&2; }
has "empty volume" "empty: every value is 0"
grep -q "raise --density-scale" "$T/err" && bad "an empty volume is told to raise --density-scale" ||
    ok "an empty volume is not told to raise --density-scale"
F4="$S/scenes/dobashi_fig04_spotlight.json"
for d in fog.extinction_per_m=0.01 lights.1.cone_deg=5; do
    "$A" render "$F4" --width 8 --height 8 -q -D "$d" -o "$T/d.png" 2>"$T/err"; st=$?
    [ $st -eq 2 ] && grep -q "the scene file alone is valid: the -D override -D $d made it so" "$T/err" && [ ! -e "$T/d.png" ] &&
        ok "-D $d: a usage error" || bad "-D $d: exit $st, $(cat "$T/err")"
done
printf '{"renderer": "beams", "fog": {"extinction_per_m": 0.01, "scattering_per_m": 0.02}}' >"$T/broken.json"
"$A" render "$T/broken.json" --width 8 --height 8 -q -D fog.g=0.5 -o "$T/d.png" 2>"$T/err"; st=$?
[ $st -eq 1 ] && ! grep -q "alone is valid" "$T/err" && ok "a broken file with a -D: exit 1" || bad "a broken file with a -D: exit $st"
exit $fail
