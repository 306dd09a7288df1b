#!/bin/sh
# What the trial of 2026-12-05 ran into (overrides, volumes), each now as the docs say:
#  1. a -D that sets volume.file to a missing file is blamed on the override (naming the scene
#     file it applies to), not on the scene file, which has no such key (scene-format.md);
#     the same without a scene file, and a scene from standard input keeps its
#     "standard input:" prefix for a file key's error;
#  2. a volume placed wholly below the ground warns (as a too-thin one does); one above does not.
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
exit $fail
