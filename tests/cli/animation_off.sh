#!/bin/sh
# "animation": {"frames": 0} is a single image (include/atmos/scene.h, docs/scene-format.md):
# accepted in a scene file and by -D, which so turns a scene's animation off; the output is
# the one file named, without a frame number.
. "$(dirname "$0")/common.inc"

cat >"$T/anim.json" <<'JSON'
{"image": {"width": 12, "height": 8}, "sun": {"elevation_deg": 10, "azimuth_deg": 250},
 "animation": {"frames": 3, "elevation_end_deg": 2}}
JSON
"$A" render "$T/anim.json" -D animation.frames=0 --pfm "$T/one.pfm" >/dev/null 2>"$T/err"
st=$?
[ $st -eq 0 ] && ok "-D animation.frames=0 accepted" || { bad "-D animation.frames=0: exit $st"; cat "$T/err" >&2; }
[ -s "$T/one.pfm" ] && ! ls "$T"/one_0*.pfm >/dev/null 2>&1 && ok "one image, no frame numbers" || bad "not a single image"
"$A" render "$T/anim.json" --frames 1 --pfm "$T/first.pfm" >/dev/null 2>&1 || bad "--frames 1"
cmp -s "$T/one.pfm" "$T/first.pfm" && ok "frames 0 renders the scene's sun (= --frames 1)" || bad "frames 0 differs from --frames 1"
printf '{"image": {"width": 12, "height": 8}, "animation": {"frames": 0}}' >"$T/zero.json"
"$A" render "$T/zero.json" --pfm "$T/z.pfm" >/dev/null 2>"$T/err" && ok "a scene file with frames 0" || { bad "frames 0 in a file"; cat "$T/err" >&2; }
"$A" render "$T/anim.json" -D animation.frames=-1 --pfm "$T/n.pfm" >/dev/null 2>"$T/err"
[ $? -ne 0 ] && grep -q "\[0, 100000\]" "$T/err" && ok "frames -1 refused, range [0, 100000]" || { bad "frames -1"; cat "$T/err" >&2; }
exit $fail
