#!/bin/sh
# scenes/harris_aircraft.json (docs/particles.md, impostor splitting): the scene renders with its
# aircraft, its flight plays headless and is recorded (the first frame makes the split cloud's
# two impostors), the render's metadata names the split, and a broken mesh is refused with a
# message naming it.
set -u
A=${ATMOS_CLI:?ATMOS_CLI not set}
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}
T=${ATMOS_TEST_TMP:-/tmp}/harris_aircraft.$$
rm -rf "$T"
mkdir -p "$T" || exit 1
trap 'rm -rf "$T"' EXIT
fail=0
ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }

"$A" render "$S/scenes/harris_aircraft.json" --width 160 --height 90 --sky-lights 2 -o "$T/a.png" -q 2>"$T/e.txt" \
    || { bad "render of harris_aircraft.json"; cat "$T/e.txt" >&2; }
python3 - "$T/a.png" <<'PY' && ok "rendered; the metadata names the split cloud" || bad "harris_aircraft metadata"
import struct, sys
d = open(sys.argv[1], "rb").read(); i = 8; meta = {}
while i < len(d):
    n, = struct.unpack(">I", d[i:i + 4]); t = d[i + 4:i + 8]
    if t == b"tEXt":
        k, v = d[i + 8:i + 8 + n].split(b"\0", 1); meta[k] = v
    i += 12 + n
h = meta[b"atmos:harris"].decode()
assert "1 objects, 1 clouds split" in h, h
PY
"$A" view "$S/scenes/harris_aircraft.json" --script "$S/scenes/flights/harris_aircraft.json" --frames 3 --headless \
    --size 96x54 --record "$T/rec" -q 2>"$T/ev.txt" || { bad "recorded flight"; cat "$T/ev.txt" >&2; }
python3 - "$T/rec/frames.csv" <<'PY' && ok "flight recorded: 3 frames, the split's two impostors made first" || bad "flight record"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 3, rows
assert rows[0]["renderer"] == "harris" and int(rows[0]["impostor_updates"]) == 2, rows[0]
PY
[ -s "$T/rec/frame_00002.png" ] && ok "frames written" || bad "no frame PNG"
printf 'v 0 0 0\nv 1 0 0\nf 1 2 7\n' >"$T/broken.obj"
python3 -c 'import json, sys; s = json.load(open(sys.argv[1])); s["objects"][0]["mesh"] = sys.argv[2]; json.dump(s, open(sys.argv[3], "w"))' \
    "$S/scenes/harris_aircraft.json" "$T/broken.obj" "$T/broken.json"
"$A" render "$T/broken.json" --width 32 --height 18 -o "$T/b.png" 2>"$T/eb.txt"; st=$?
[ $st -ne 0 ] && grep -q "broken.obj" "$T/eb.txt" && [ ! -e "$T/b.png" ] && ok "a broken OBJ refused, no image" \
    || bad "broken OBJ (exit $st)"
exit $fail
