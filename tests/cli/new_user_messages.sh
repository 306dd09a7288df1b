#!/bin/sh
# Messages a new user met (2026-12-06), each as the docs say: a 0-byte PNG (a spot's image, a
# terrain) is an "empty file", not a truncated one; a UTF-16 scene is told to be saved as
# UTF-8; a scene that the options alone leave without lights for the beams renderer is a usage
# error (2) whether --renderer or -D did it, one whose file has none is a runtime error (1);
# --exposure-per-frame on a single frame warns that it changes nothing; a headless scripted
# view whose save fails ends with a non-zero status.
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1
# CHECK NAME WANT_STATUS TEXT ARGS...: atmos ARGS exits WANT_STATUS and says TEXT
check() {
    name=$1 want=$2 text=$3
    shift 3
    "$A" "$@" >out.txt 2>err.txt
    st=$?
    if [ $st -eq "$want" ] && grep -qF -- "$text" err.txt; then
        ok "$name: exit $st, '$text'"
    else
        bad "$name: exit $st (want $want and '$text'):"
        sed 's/^/  /' err.txt >&2
    fi
}

: >zero.png
lamp='{"type": "spot", "position_m": [0, 12, 0], "direction": [0, -1, 0], "cone_deg": 20, "intensity_w_sr": 2e4, "range_m": 40'
cat >img.json <<JSON
{"renderer": "beams", "wavelengths": {"mode": "rgb"}, "background": "black", "fog": {"extinction_per_m": 0.04},
 "camera": {"position_m": [8, 2, 8], "look_at_m": [0, 3, 0]}, "lights": [$lamp, "image": "zero.png"}],
 "objects": [{"mesh": "builtin:plane", "scale": 15}]}
JSON
check "a 0-byte spot image" 1 "zero.png: empty file (0 bytes)" render img.json --width 16 --height 9 -o a.png
grep -q "truncated" err.txt && bad "a 0-byte spot image said to be truncated" || ok "a 0-byte spot image: not 'truncated'"
cat >terr.json <<JSON
{"renderer": "beams", "wavelengths": {"mode": "rgb"}, "background": "black", "fog": {"extinction_per_m": 0.04},
 "camera": {"position_m": [8, 2, 8], "look_at_m": [0, 3, 0]}, "lights": [$lamp}],
 "objects": [{"terrain": "zero.png", "size_m": 30, "height_m": 3}]}
JSON
check "a 0-byte terrain" 1 "zero.png: empty file (0 bytes)" render terr.json --width 16 --height 9 -o a.png

# UTF-16 scenes, either byte order, with their byte order mark
python3 -c '
import codecs
t = "{\"name\": \"utf16\"}\n"
open("le.json", "wb").write(codecs.BOM_UTF16_LE + t.encode("utf-16-le"))
open("be.json", "wb").write(codecs.BOM_UTF16_BE + t.encode("utf-16-be"))'
check "a UTF-16LE scene" 1 "UTF-16: save the scene as UTF-8" render le.json -o a.png
check "a UTF-16BE scene" 1 "UTF-16: save the scene as UTF-8" render be.json -o a.png

# no lights for the beams renderer: the options' doing (2) or the scene file's (1)
cat >lit.json <<JSON
{"renderer": "beams", "wavelengths": {"mode": "rgb"}, "background": "black", "fog": {"extinction_per_m": 0.04},
 "camera": {"position_m": [8, 2, 8], "look_at_m": [0, 3, 0]}, "lights": [$lamp}]}
JSON
printf '{"name": "dark"}\n' >dark.json
printf '{"renderer": "beams", "camera": {"position_m": [8, 2, 8], "look_at_m": [0, 3, 0]}}\n' >darkbeams.json
check "--renderer beams, no scene" 2 "the scene has neither" render --renderer beams -o a.png
check "-D lights=[] on a lit beams scene" 2 "the scene has neither" render lit.json -D 'lights=[]' -o a.png
check "--renderer beams on a scene without lights" 2 "the scene has neither" render dark.json --renderer beams -o a.png
check "a beams scene file without lights" 1 "the scene has neither" render darkbeams.json -o a.png

# --exposure-per-frame without an animation: a warning, the render goes on
check "--exposure-per-frame on one frame" 0 "--exposure-per-frame: changes nothing" \
    render --renderer sky --width 16 --height 9 --exposure-per-frame -o a.png

# a headless scripted session whose save cannot be written: every frame, then exit 1
: >blocker
check "a failed save, headless" 1 "the frame was not saved" \
    view --headless --frames 3 --size 16x9 --renderer sky --press save --save-base blocker/v --record rec
[ -s rec/frame_00002.png ] && ok "all 3 frames recorded after the failed save" || bad "the session stopped after the failed save"
# a save whose scene file cannot be written (a folder of its name) leaves none of its three files
mkdir -p part/v_001.json
check "a save whose scene cannot be written" 1 "cannot write part/v_001.json" \
    view --headless --frames 2 --size 16x9 --renderer sky --press save --save-base part/v
[ ! -e part/v_001.exr ] && [ ! -e part/v_001.png ] && ok "no image left of the failed save" \
    || bad "the failed save left $(ls part)"
exit $fail
