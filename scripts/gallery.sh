#!/bin/sh
# Renders every example scene to a PNG and prints a Markdown table of what was rendered and
# how long it took.
#
#   scripts/gallery.sh [--atmos BIN] [--out DIR] [--max-width W] [--repeat N] [SCENE.json ...]
#
# Defaults: BIN = build/atmos, DIR = docs/images, W = 640, every scenes/*.json. Each scene is
# rendered at its own size, scaled down (keeping its aspect) when it is wider than W, to
# DIR/<scene file name>.png. An animated scene is rendered as its first frame (--frames 1).
# Columns: the render time atmos reports itself (the renderer, optics tables from the cache
# included) and the wall time of the whole command (volume generation or loading, cold
# tables and the PNG included); with --repeat N each scene is rendered N times and the fastest
# run is reported (on a shared machine). Scenes whose volume file is missing are listed, not
# rendered.
# Needs python3 (reads the scene files' JSON).
set -u
ATMOS=build/atmos
OUT=docs/images
MAXW=640
REPEAT=1
while [ $# -gt 0 ]; do
    case "$1" in
    --atmos) ATMOS=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --max-width) MAXW=$2; shift 2 ;;
    --repeat) REPEAT=$2; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --) shift; break ;;
    -*) echo "gallery.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
    esac
done
[ $# -eq 0 ] && set -- scenes/*.json
[ -x "$ATMOS" ] || { echo "gallery.sh: $ATMOS not found (build first: make build)" >&2; exit 1; }
command -v python3 >/dev/null || { echo "gallery.sh: needs python3" >&2; exit 1; }
mkdir -p "$OUT"
now() { date +%s.%N; }

echo "| scene | figure | size | renderer | render s | wall s |"
echo "|---|---|---|---|---|---|"
status=0
for scene in "$@"; do
    name=$(basename "$scene" .json)
    # One line of facts from the scene: width height renderer slices figure volume-file-or-"-"
    info=$(python3 - "$scene" "$MAXW" <<'PY'
import json, os, re, sys
path, maxw = sys.argv[1], int(sys.argv[2])
s = json.load(open(path))
img = s.get("image", {})
w, h = img.get("width", 1280), img.get("height", 720)
if w > maxw:
    w, h = maxw, max(1, round(h * maxw / w))
vol = s.get("volume")
renderer = s.get("renderer", "slice" if vol else "sky")
if renderer == "slice":
    renderer = "slice, %d slices" % s.get("slice", {}).get("slices", 256)
m = re.match(r"Riley et al\. 2004, (Figs?\. [0-9]+(?:(?:, | and |-)[0-9]+)*)", s.get("_comment", ""))
fig = m.group(1) if m else "-"
f = vol.get("file") if vol else None
if f and f.startswith("data:"):  # the data folder (docs/scene-format.md)
    f = os.path.join(os.environ.get("ATMOS_DATA") or os.path.join(os.path.dirname(os.path.abspath(path)), "..", "..", "shared", "data"), f[5:])
elif f and not f.startswith(("generate:", "simulate:")) and not os.path.isabs(f):
    f = os.path.join(os.path.dirname(path), f)
print("%d\t%d\t%s\t%s\t%s" % (w, h, renderer, fig, f or "-"))
PY
) || { echo "| $name | (unreadable scene) | | | | |"; status=1; continue; }
    w=$(printf '%s' "$info" | cut -f1); h=$(printf '%s' "$info" | cut -f2)
    renderer=$(printf '%s' "$info" | cut -f3); fig=$(printf '%s' "$info" | cut -f4)
    vfile=$(printf '%s' "$info" | cut -f5)
    if [ "$vfile" != "-" ] && [ ! -e "$vfile" ]; then
        echo "| $name | $fig | ${w}×${h} | $renderer | (volume file missing) | |"
        continue
    fi
    log=$(mktemp)
    best=""; bestwall=""; failed=0; i=0
    while [ $i -lt "$REPEAT" ]; do
        i=$((i + 1))
        t0=$(now)
        if ! "$ATMOS" render "$scene" --frames 1 --width "$w" --height "$h" -o "$OUT/$name.png" 2> "$log"; then
            failed=1
            break
        fi
        t1=$(now)
        secs=$(sed -n 's/^atmos render: .*, \([0-9.]*\) s rendering$/\1/p' "$log" | tail -n 1)
        wall=$(python3 -c "print('%.1f' % ($t1 - $t0))")
        if [ -z "$best" ] || python3 -c "import sys; sys.exit(0 if float('${secs:-1e9}') < float('$best') else 1)"; then
            best=${secs:-?}; bestwall=$wall
        fi
    done
    if [ $failed -eq 0 ]; then
        echo "| $name | $fig | ${w}×${h} | $renderer | $best | $bestwall |"
    else
        echo "| $name | $fig | ${w}×${h} | $renderer | failed: $(tail -n 1 "$log") | |"
        status=1
    fi
    rm -f "$log"
done
exit $status
