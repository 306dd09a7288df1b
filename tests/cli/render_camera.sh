#!/bin/sh
# The camera and the scene from the command line (issue 13): --position/--look-at and
# --view-elevation/--view-azimuth give the same view when they name the same direction;
# --fov equals -D camera.fov_deg; -D reaches any key with the file's rules; '-' reads the
# scene from standard input; the default output is named after the scene file.
set -u
. "$(dirname "$0")/common.inc"
S="-q --width 24 --height 16 --threads 1"

# the same view, two ways: north and 10 degrees up from 1000 m
"$A" render $S --position 0,1000,0 --look-at 0,1176.3269807,-1000 --pfm "$T/a.pfm" && ok || bad "--position --look-at"
"$A" render $S --position 0,1000,0 --view-elevation 10 --view-azimuth 0 --pfm "$T/b.pfm" && ok || bad "--view-*"
python3 - "$T/a.pfm" "$T/b.pfm" <<'PY' && ok || bad "--look-at and --view-elevation/--view-azimuth differ"
import sys, pfm
a, b = pfm.read(sys.argv[1]).v, pfm.read(sys.argv[2]).v
assert max(abs(x - y) / max(abs(x), 1e-30) for x, y in zip(a, b)) < 1e-3
PY
# looking up and looking down are different views: the zenith sky is bluer than the ground
"$A" render $S --view-elevation 60 --pfm "$T/up.pfm" && "$A" render $S --view-elevation -60 --pfm "$T/down.pfm" \
    && ok || bad "--view-elevation +-60"
python3 - "$T/up.pfm" "$T/down.pfm" <<'PY' && ok || bad "looking up is not bluer than looking down"
import sys, pfm
def ratio(p):
    v = pfm.read(p).v
    return sum(v[2::3]) / sum(v[0::3])
assert ratio(sys.argv[1]) > 1.2 * ratio(sys.argv[2]), (ratio(sys.argv[1]), ratio(sys.argv[2]))
PY
# --position names the altitude too: with --altitude it is refused, not silently one of the two
"$A" render $S --altitude 5000 --position 0,500,0 -o "$T/x.png" 2> "$T/err.txt"; [ $? -eq 2 ] \
    && grep -q "exclude each other" "$T/err.txt" && ok || bad "--altitude with --position not refused"
# --fov and -D camera.fov_deg (dotted) and -D /camera/fov_deg (pointer) are the same
"$A" render $S --fov 30 --pfm "$T/f1.pfm" && "$A" render $S -D camera.fov_deg=30 --pfm "$T/f2.pfm" \
    && "$A" render $S -D /camera/fov_deg=30 --pfm "$T/f3.pfm" && ok || bad "--fov / -D"
cmp -s "$T/f1.pfm" "$T/f2.pfm" && cmp -s "$T/f1.pfm" "$T/f3.pfm" && ok || bad "--fov 30 and -D camera.fov_deg=30 differ"
cmp -s "$T/f1.pfm" "$T/a.pfm" && bad "--fov changed nothing" || ok
# -D values meet the file's rules and messages; a path must lead into the scene
"$A" render $S -D camera.fov_deg=500 -o "$T/x.png" 2> "$T/err.txt"; [ $? -eq 2 ] && grep -q "/camera/fov_deg" "$T/err.txt" \
    && ok || bad "-D camera.fov_deg=500 not refused with its pointer"
"$A" render $S -D nokey=1 -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "-D nokey=1 accepted"
"$A" render $S -D camera.fov_deg -o "$T/x.png" 2>/dev/null; [ $? -eq 2 ] && ok || bad "-D without = accepted"
# a bare word is a string: -D renderer=path switches the renderer (path needs no volume)
"$A" render $S -D renderer=path -D path.spp=1 --pfm "$T/p.pfm" 2> "$T/err.txt" && ok || bad "-D renderer=path: $(cat "$T/err.txt")"
# a scene from standard input, named after its "name"; a file's output after the file
cd "$T" || exit 1
echo '{"name": "piped sky", "image": {"width": 12, "height": 8}}' | "$A" render -q - && [ -f "piped_sky.png" ] && ok \
    || bad "scene from standard input"
echo '{"name": "not the file name", "image": {"width": 12, "height": 8}}' > "$T/evening.json"
"$A" render -q "$T/evening.json" && [ -f "$T/evening.png" ] && ok || bad "default output not named after the scene file"
rm -rf "$T"
echo "render_camera.sh: $pass passed"
[ $fail -eq 0 ]
