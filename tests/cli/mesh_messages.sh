#!/bin/sh
# A mesh or terrain file that cannot be read is named by its scene key with the system's
# reason and, for a relative path, where it was looked for (as a light's image is); an OBJ
# file's wrong face (or a face of fewer than 3 vertices, or a line that is no OBJ statement) says
# what is wrong, as written, and on which line; another kind of file is not an OBJ file; a folder is
# a folder (a mesh's or a terrain's); a comment after a face is a comment; call, csh, indents and a final ^Z are OBJ's.
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1
mesh_scene() { # mesh_scene MESH TERRAIN
    cat <<JSON
{"image": {"width": 16, "height": 12}, "wavelengths": {"mode": "rgb"}, "background": "black", "renderer": "beams",
 "camera": {"type": "pinhole", "position_m": [0, 8, 40], "look_at_m": [0, 5, 0], "fov_deg": 50},
 "fog": {"extinction_per_m": 0.03, "scattering_per_m": 0.027, "g": 0.2},
 "lights": [{"type": "point", "position_m": [0, 20, 0], "intensity_w_sr": 3000}],
 "objects": [{"mesh": "$1", "position_m": [0, 8, 0]}, {"terrain": "$2", "size_m": 60, "height_m": 3}]}
JSON
}
# check NAME FILE-OR-STDIN PATTERN...: the render fails and its message holds every pattern
check() {
    name=$1 err=$2
    shift 2
    for p in "$@"; do grep -q -- "$p" "$err" || { bad "$name: no '$p' in: $(cat "$err")"; return; }; done
    ok "$name"
}
mesh_scene nobox.obj generate:ridges | "$A" render - -o x.png -q 2>err1
check "a missing mesh from standard input" err1 "/objects/0/mesh" "nobox.obj" "No such file" "relative path"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >ok.obj
mesh_scene ok.obj nohills.png | "$A" render - -o x.png -q 2>err2
check "a missing terrain" err2 "/objects/1/terrain" "nohills.png" "No such file" "relative path"
mesh_scene ok.obj generate:ridges >s.json
# obj_check NAME TEXT LABEL PATTERN...: TEXT (printf's escapes) as NAME.obj, the scene's mesh;
# the render's message must hold every PATTERN
obj_check() {
    n=$1 text=$2 label=$3
    shift 3
    printf "$text" >"$n.obj"
    "$A" render s.json -D objects.0.mesh="$n.obj" -o x.png -q 2>"err_$n"
    check "$label" "err_$n" "$@"
}
obj_check junk 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 abc\n' "a face vertex that is not a number" "/objects/0/mesh" "line 4" "'abc'" \
    "not a number"
obj_check neg 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -5\n' "a negative index out of range, as written" "line 4" "vertex -5" "3 vertices"
obj_check big 'v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\nf 1 2 9\n' "a positive index past the file's vertices" "line 5" "vertex 9" "has 3"
obj_check zero 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n' "vertex 0" "line 4" "vertex 0"
mkdir dir.obj
"$A" render s.json -D objects.0.mesh=dir.obj -o x.png -q 2>err7
check "a folder" err7 "/objects/0/mesh" "folder"
mkdir dir.tif
"$A" render s.json -D objects.1.terrain=dir.tif -o x.png -q 2>err7t
check "a folder as the terrain" err7t "/objects/1/terrain" "dir.tif" "it is a folder, not a file"
# a terrain whose max_triangles leaves no cell: said of max_triangles, not of a stride never set
"$A" render --width 33 --height 33 -o h.png -q 2>/dev/null || bad "a height map"
"$A" render s.json -D objects.1.terrain=h.png -D objects.1.max_triangles=1 -o x.png -q 2>err9
check "max_triangles 1" err9 "/objects/1/terrain" "max_triangles 1"
grep -q "stride" err9 && bad "max_triangles 1 spoken of as a stride: $(cat err9)"
# a height map scaled beyond 1e8 m: said of the terrain and its height_scale, not of "mesh: vertex N"
"$A" render --width 9 --height 9 --png-bits 16 --exposure 20 -o h16.png -q 2>/dev/null || bad "a 16-bit height map"
"$A" render s.json -D objects.1.terrain=h16.png -D objects.1.height_m=0 -D objects.1.height_scale=1e5 -o x.png -q 2>err9b
check "a height map scaled beyond 1e8 m" err9b "/objects/1/terrain" "h16.png" "height_scale 100000" "beyond 1e8 m"
# a height map cut short in rows a stride passes over: its last row is read too, so the cut is said
"${ATMOS_PYTHON:-python3}" - <<'PY' || bad "writing the cut height map"
import random, struct, zlib
random.seed(7)
w, h = 4000, 50  # max_triangles 1000: a stride of 18, rows 0, 18, 36 kept, the last (49) passed over
z = zlib.compressobj()  # each row flushed, so that the rows before a cut decode
data = b''.join(z.compress(b'\x00' + random.randbytes(2 * w)) + z.flush(zlib.Z_SYNC_FLUSH) for _ in range(h)) + z.flush()
chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 16, 0, 0, 0, 0)) + chunk(b'IDAT', data)
open('cut.png', 'wb').write(png[:len(png) * 90 // 100])  # rows 45 on cut
PY
"$A" render s.json -D objects.1.terrain=cut.png -D objects.1.max_triangles=1000 -o x.png -q 2>err9c
check "a height map cut in its last rows" err9c "/objects/1/terrain" "cut.png" "the last"
"$A" render s.json -o x.png -q 2>err8 && ok "the good mesh renders" || bad "the good mesh: $(cat err8)"
# comments after a line's content are comments ('#' to the end of the line), not vertex indices
printf '# a triangle\nv 0 0 0 # origin\nv 1 0 0\nv 0 1 0\nf 1 2 3 # tri\nf 1 2 3#again\n' >comment.obj
"$A" render s.json -D objects.0.mesh=comment.obj -o x.png -q 2>err10 && [ ! -s err10 ] &&
    ok "an OBJ file with comments after faces and vertices" || bad "comments after a face: $(cat err10)"
# a truncated file (its last face cut to two vertices), a word that is no OBJ statement and an
# image given as a mesh: errors naming the line, not a mesh of fewer faces or "no triangles"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 4 1' >cut.obj
"$A" render s.json -D objects.0.mesh=cut.obj -o x.png -q 2>err11
check "a face of two vertices (a truncated file)" err11 "/objects/0/mesh" "line 6" "3 or more vertices" "has 2"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nfx 1 2 3\nf 1 2 3\n' >word.obj
"$A" render s.json -D objects.0.mesh=word.obj -o x.png -q 2>err12
check "a line that is no OBJ statement" err12 "/objects/0/mesh" "line 4" "'fx' is not an OBJ statement"
# the spec's call and csh statements, indented lines and a DOS end-of-file mark (^Z) after the
# last line are a valid file's; an indented face is checked as any other
printf 'v 0 0 0\r\nv 1 0 0\r\n  v 0 1 0\r\ncsh echo\r\ncall other.obj\r\n\tf 1 2 3\r\n\032' >dos.obj
"$A" render s.json -D objects.0.mesh=dos.obj -o x.png -q 2>err14 && [ ! -s err14 ] &&
    ok "call, csh, indented lines and a final ^Z: read" || bad "call, csh, indents, ^Z: $(cat err14)"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n  f 3 1\n' >icut.obj
"$A" render s.json -D objects.0.mesh=icut.obj -o x.png -q 2>err15
check "an indented face of two vertices" err15 "line 5" "3 or more vertices" "has 2"
printf '\211PNG\r\n\032\n\000\000\000\rIHDR' >pic.obj
"$A" render s.json -D objects.0.mesh=pic.obj -o x.png -q 2>err13
check "a PNG given as a mesh" err13 "/objects/0/mesh" "not an OBJ file" "PNG"
grep -q "no triangles" err13 && bad "a PNG spoken of as a mesh without triangles: $(cat err13)"
# a bad terrain set by -D is the define's, not the scene file's; one the file sets is the file's
printf 'garbage' >bad.png
"$A" render s.json -D objects.1.terrain=bad.png -o x.png -q 2>errd1
check "a bad terrain set by -D" errd1 "/objects/1/terrain" "(set by -D objects.1.terrain=" "not by the scene file"
"$A" render s.json -D '/objects/1={"terrain": "bad.png", "size_m": 60, "height_m": 3}' -o x.png -q 2>errd2
check "a bad terrain in an object set by -D" errd2 "/objects/1/terrain" "(set by -D /objects/1={"
mesh_scene ok.obj bad.png >sbad.json
"$A" render sbad.json -D objects.1.albedo=0.3 -o x.png -q 2>errd3
check "a bad terrain in the scene file, -D elsewhere" errd3 "/objects/1/terrain"
grep -q "set by -D" errd3 && bad "the scene file's bad terrain blamed on a -D: $(cat errd3)" || ok "the scene file's terrain not blamed on -D"
# a mesh whose vertices pass 1e8 m only once placed (position, scale): the object, the file and
# "after position and scale"; the same in the path tracer
"$A" render s.json -D objects.0.position_m=[0,0,9.99e7] -D objects.0.scale=1e6 -D objects.0.mesh=builtin:sphere \
    -o x.png -q 2>errp1
check "a built-in sphere placed beyond 1e8 m" errp1 "/objects/0/mesh" "builtin:sphere" "after position and scale"
"$A" render s.json -D objects.0.scale=1e6 -D objects.0.position_m=[9.99e7,0,0] --renderer path --spp 1 -o x.png -q 2>errp2
check "an OBJ scaled beyond 1e8 m, the path tracer" errp2 "/objects/0/mesh" "ok.obj" "after position and scale"
# old Mac line endings (CR alone: the reader splits them, the first pass did not, so a cut last
# face passed) and a hexadecimal coordinate (strtod reads 0x10 as 16, the reader as 0): refused
obj_check cr 'v 0 0 0\rv 1 0 0\rv 0 1 0\rv 0 0 1\rf 1 2 3\rf 4 1' "old Mac line endings" "/objects/0/mesh" "line 1" \
    "carriage return without a line feed"
obj_check hex 'v 0x10 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' "a hexadecimal coordinate" "/objects/0/mesh" "line 1" \
    "three finite decimal numbers"
printf 'v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n' >crlf.obj
"$A" render s.json -D objects.0.mesh=crlf.obj -o x.png -q 2>errcrlf && ok "CRLF line endings read" || bad "CRLF: $(cat errcrlf)"
exit $fail
