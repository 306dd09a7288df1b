#!/bin/sh
# A saved view (F12, P; docs/viewer.md) of a scene whose files are relative to its folder (an
# OBJ mesh, a terrain's height map, a spot's stained-glass image) renders from any folder: the
# saved scene names them by absolute paths, as it does the volume's, and keeps "builtin:",
# "generate:" and "data:" as written. Saved into another folder, rendered from a third: the
# same pixels as the viewer's saved frame.
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1
mkdir -p sc/props sc/maps elsewhere
python3 - sc <<'PY' || bad "writing the scene's files"
import struct, sys, zlib
d = sys.argv[1]
def png(name, w, h, rows, colour, bits):  # rows: lists of samples
    raw = b"".join(b"\0" + b"".join(struct.pack(">H" if bits == 16 else "B", v) for v in r) for r in rows)
    chunk = lambda k, b: struct.pack(">I", len(b)) + k + b + struct.pack(">I", zlib.crc32(k + b) & 0xffffffff)
    open(name, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, bits, colour, 0, 0, 0))
                           + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
# a 4 x 4 stained glass: coloured panes, a black lead cross
g = [[(0, 0, 0) if x == 1 or y == 1 else ((255, 40, 40) if x < 1 else (40, 255, 40)) for x in range(4)] for y in range(4)]
png(d + "/maps/glass.png", 4, 4, [[c for p in r for c in p] for r in g], 2, 8)
# an 8 x 8 16-bit height map: a ridge
png(d + "/maps/hills.png", 8, 8, [[int(65535 * (1 - abs(x - 3.5) / 3.5)) for x in range(8)] for y in range(8)], 0, 16)
open(d + "/props/crate.obj", "w").write(
    "v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\nv -1 0 1\nv 1 0 1\nv 1 2 1\nv -1 2 1\n"
    "f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n")
PY
cat >sc/yard.json <<'JSON'
{"renderer": "beams", "wavelengths": {"mode": "rgb"}, "background": "black",
 "camera": {"type": "pinhole", "position_m": [14, 4, 14], "look_at_m": [0, 3, 0], "fov_deg": 60},
 "fog": {"extinction_per_m": 0.04, "scattering_per_m": 0.036, "g": 0.5},
 "lights": [{"type": "spot", "position_m": [0, 12, 0], "direction": [0, -1, 0], "cone_deg": 25, "edge_deg": 3,
             "intensity_w_sr": 20000, "range_m": 40, "image": "maps/glass.png"}],
 "objects": [{"mesh": "builtin:plane", "scale": 20, "albedo": 0.6},
             {"mesh": "props/crate.obj", "position_m": [2, 0, 1], "albedo": 0.7},
             {"terrain": "maps/hills.png", "size_m": 30, "height_m": 3, "position_m": [0, 0, -25]}]}
JSON
# a scripted still camera (the scene's), F12 at frame 1: saved into saves/, rendered from elsewhere/
printf '{"fps": 1, "keys": [{"t": 0, "position_m": [14, 4, 14], "look_at_m": [0, 3, 0]}, {"t": 1, "position_m": [14, 4, 14], "look_at_m": [0, 3, 0], "press": "save"}]}\n' >still.json
"$A" view sc/yard.json --headless --script still.json --size 40x24 --save-base saves/y >x1.txt 2>&1
st=$?
[ $st -eq 0 ] && [ -s saves/y_001.json ] && ok "the view saved (exit 0)" || { bad "the save: exit $st"; cat x1.txt >&2; exit 1; }
python3 - saves/y_001.json "$(pwd -P)/sc" <<'PY' && ok "the saved scene names its files by absolute paths, builtin: kept" ||
import json, sys
s, d = json.load(open(sys.argv[1])), sys.argv[2]
o = s["objects"]
assert o[0]["mesh"] == "builtin:plane", o[0]
assert o[1]["mesh"] == d + "/props/crate.obj", o[1]
assert o[2]["terrain"] == d + "/maps/hills.png", o[2]
assert s["lights"][0]["image"] == d + "/maps/glass.png", s["lights"][0]
PY
    { bad "the saved scene's paths:"; grep -E '"(mesh|terrain|image)"' saves/y_001.json >&2; }
(cd elsewhere && "$A" render ../saves/y_001.json -o off.png --exr off.exr >../x2.txt 2>&1) &&
    ok "the saved scene renders from a third folder" || { bad "the saved scene does not render from elsewhere"; cat x2.txt >&2; }
# the pixels: the PNGs' image data (their text chunks hold the render's time)
idat() {
    python3 - "$1" <<'PY'
import struct, sys, zlib
b, i, data = open(sys.argv[1], "rb").read(), 8, b""
while i < len(b):
    n, kind = struct.unpack(">I4s", b[i:i + 8])
    data += b[i + 8:i + 8 + n] if kind == b"IDAT" else b""
    i += 12 + n
print(zlib.crc32(zlib.decompress(data)))
PY
}
[ -s elsewhere/off.png ] && [ "$(idat saves/y_001.png)" = "$(idat elsewhere/off.png)" ] &&
    ok "the offline render's pixels are the saved frame's" || bad "the offline render differs from the saved frame"
"$A" compare saves/y_001.exr elsewhere/off.exr --json >cmp.json 2>&1
python3 -c 'import json, sys; c = json.load(open(sys.argv[1])); assert c["rel_rmse"] == 0, c' cmp.json &&
    ok "the offline EXR equals the saved EXR" || { bad "the EXRs differ:"; cat cmp.json >&2; }
exit $fail
