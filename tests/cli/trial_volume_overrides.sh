#!/bin/sh
# What the trial of 2026-12-05 ran into (overrides, volumes), each now as the docs say:
#  1. a -D that sets volume.file to a missing file is blamed on the override (naming the scene
#     file it applies to), not on the scene file, which has no such key (scene-format.md);
#     the same without a scene file, and a scene from standard input keeps its
#     "standard input:" prefix for a file key's error;
#     a -D object's file key is from the current folder; two -D volume sources are refused;
#  2. a volume placed wholly below the ground warns (as a too-thin one does); one above does not;
#  3. a wide domain framed with no camera lies over the origin, its camera's height told over
#     the round planet.
. "$(dirname "$0")/common.inc"
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }
hasnt() { grep -qF -- "$2" "$T/err" && { bad "$1: '$2' in:"; sed 's/^/  /' "$T/err" >&2; } || ok "$1: no '$2'"; }
small="--width 16 --height 9 --renderer path --spp 1"

# --- 1. -D volume.file=MISSING blamed on the override
printf '{"name": "t"}\n' >"$T/s.json"
(cd "$T" && "$A" render s.json -D volume.file=nothere.vdb -o "$T/e.png") 2>"$T/err"
st=$?
[ $st -eq 1 ] && ok "a missing -D volume.file: exit 1" || bad "a missing -D volume.file: exit $st"
has "-D volume.file on a scene" "atmos render: -D volume.file="
has "-D volume.file on a scene" "nothere.vdb\" (on s.json): /volume/file: "
hasnt "-D volume.file on a scene" "atmos render: s.json: /volume/file"
(cd "$T" && "$A" render -D volume.file=nothere.vdb -o "$T/e.png") 2>"$T/err"
has "-D volume.file alone" "nothere.vdb\": /volume/file: "
printf '{"volume": {"file": "nothere.vdb"}}\n' | (cd "$T" && "$A" render - -o "$T/e.png") 2>"$T/err"
has "a file key from standard input" "atmos render: standard input: /volume/file: nothere.vdb: cannot open"

# a file key inside an object a -D sets is from the current folder too, and named as the -D
(cd "$T" && "$A" render s.json -D 'volume={"file": "nothere.vdb"}' -o "$T/e.png") 2>"$T/err"
has "-D volume={file} on a scene" "(on s.json): /volume/file: $(cd "$T" && pwd -P)/nothere.vdb: cannot open"
# two -D naming volume sources of two kinds: refused, as in a scene file (not the last taken)
(cd "$T" && "$A" render s.json -D volume.file=nothere.vdb -D volume.generate=cumulus -o "$T/e.png") 2>"$T/err"
has "-D volume.file and -D volume.generate" "/volume: \"file\" and \"generate\" exclude each other"

# --- 2. a volume wholly below the ground warns; above it, no such warning
"$A" volume generate cumulus -o "$T/v.json" --voxel-size 200 >/dev/null 2>&1 || bad "volume generate"
P='particles.cloud={"kind":"analytic","lobes":[{"type":"hg","g":0.8}],"sigma_ext_m2":6e-10}'
# shellcheck disable=SC2086
"$A" render --volume "$T/v.json" -D "$P" -D 'volume.position_m=[0,-30000,-6000]' $small -q --pfm "$T/u.pfm" \
    2>"$T/err" || { bad "render below the ground"; cat "$T/err" >&2; }
has "a volume below the ground" "below the ground: its box spans -30000 to"
# placed by --volume-position, the warning names it as well as the scene's key
# shellcheck disable=SC2086
"$A" render --volume "$T/v.json" -D "$P" --volume-position 0,-30000,-6000 $small -q --pfm "$T/u.pfm" \
    2>"$T/err" || { bad "render below the ground (--volume-position)"; cat "$T/err" >&2; }
has "a volume below the ground, --volume-position" "or --volume-position on the command line"
# shellcheck disable=SC2086
"$A" render --volume "$T/v.json" -D "$P" -D 'volume.position_m=[0,1000,-6000]' $small -q --pfm "$T/a.pfm" \
    2>"$T/err" || { bad "render above the ground"; cat "$T/err" >&2; }
hasnt "a volume above the ground" "below the ground"
# --- 3. a wide domain framed with no camera: the box over the origin, where the round planet's
# ground is at y = 0, and the camera's height said over the round planet (it was the box
# 3 widths away, its clouds tens of km above the curved ground, and the camera's y said)
python3 - "$T" <<'PY'
import struct, sys
vals = [1e8 if 8 <= x < 24 and 8 <= z < 24 else 0.0 for z in range(32) for y in range(2) for x in range(32)]
open(sys.argv[1] + "/wide.raw", "wb").write(struct.pack("<%df" % len(vals), *vals))
open(sys.argv[1] + "/wide.json", "w").write('{"file": "wide.raw", "dims": [32, 2, 32], "voxel_size_m": 10000, '
                                             '"origin_m": [0, 5000, 0]}')
PY
"$A" render --volume "$T/wide.json" --view-elevation -30 --width 16 --height 9 --slices 16 -o "$T/w.png" 2>"$T/err" \
    || { bad "render the wide domain"; cat "$T/err" >&2; }
python3 - "$T/err" <<'PY' && ok "wide domain: over the origin, the camera's height over the sphere" || bad "wide domain framing"
import re, sys, math
t = open(sys.argv[1]).read()
p = [float(v) for v in re.search(r"from \((-?\d+), (-?\d+), (-?\d+)\) m looking at \((-?\d+), (-?\d+), (-?\d+)\)", t).groups()]
up = float(re.search(r"the camera is (\d+) km up", t).group(1))
R = 6360e3
ok = abs(p[3]) < 1 and abs(p[5]) < 1 and abs((math.hypot(math.hypot(p[0], p[2]), p[1] + R) - R) / 1e3 - up) <= 1
sys.exit(0 if ok else (print(t, file=sys.stderr) or 1))
PY
exit $fail
