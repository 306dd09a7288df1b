#!/bin/sh
# A light inside a closed mesh lights nothing outside it: atmos render warns once (of the
# light and the object); a light outside the mesh, beside an open surface (a plane) or inside
# a box with a face missing is not warned of (docs/beams.md, "Meshes"); the beam renderer and
# the path tracer.
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1
# scene LIGHT_POSITION MESH: one point light, the mesh at (0, 8, 0) scaled by 3, a plane of 50 m below
scene() {
    cat <<JSON
{"image": {"width": 16, "height": 12}, "wavelengths": {"mode": "rgb"}, "background": "black", "renderer": "beams",
 "camera": {"type": "pinhole", "position_m": [0, 8, 40], "look_at_m": [0, 5, 0], "fov_deg": 50},
 "fog": {"extinction_per_m": 0.03, "scattering_per_m": 0.027, "g": 0.2},
 "lights": [{"type": "point", "position_m": [$1], "intensity_w_sr": 3000}],
 "objects": [{"mesh": "builtin:plane", "scale": 50}, {"mesh": "$2", "position_m": [0, 8, 0], "scale": 3}]}
JSON
}
# warned NAME FILE: exactly one warning of /lights/0 inside /objects/1
warned() {
    n=$(grep -c "warning: /lights/0 .* is inside /objects/1, a closed mesh" "$2")
    [ "$n" -eq 1 ] && ok "$1: warned once" || bad "$1: $n warnings in: $(cat "$2")"
}
quiet() { grep -q "inside" "$2" && bad "$1: warned: $(cat "$2")" || ok "$1: no warning"; }
# a unit cube's six faces as an OBJ file (12 triangles, facing out); open.obj without its top
cat >box.obj <<'OBJ'
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
OBJ
grep -v '^f 3 4 8$' box.obj | grep -v '^f 3 8 7$' >open.obj

scene "0, 8, 0" builtin:box | "$A" render - -o x.png 2>err1 || bad "render, a light in the box: $(cat err1)"
warned "a light at the built-in box's centre" err1
scene "1.5, 7, -1" builtin:sphere | "$A" render - -o x.png 2>err2 || bad "render, a light in the sphere"
warned "a light off the centre of the built-in sphere" err2
scene "0.3, 9, 0.4" box.obj | "$A" render - -o x.png 2>err3 || bad "render, a light in box.obj"
warned "a light in a closed OBJ box" err3
scene "0, 8, 0" builtin:box | "$A" render - --renderer path --spp 1 -o x.png 2>err8 || bad "path render: $(cat err8)"
warned "the path tracer, a light in the box" err8
scene "0, 20, 0" builtin:box | "$A" render - -o x.png 2>err4 || bad "render, a light above the box"
quiet "a light above the box (and above the plane)" err4
scene "2.9, 10.9, 2.9" builtin:sphere | "$A" render - -o x.png 2>err5 || bad "render, a light in the sphere's bounds"
quiet "a light within the sphere's bounds, outside it" err5
scene "0.3, 9, 0.4" open.obj | "$A" render - -o x.png 2>err6 || bad "render, a light in open.obj"
quiet "a light in a box with its top face missing" err6
scene "0, -5, 0" builtin:box | "$A" render - -o x.png 2>err7 || bad "render, a light under the plane"
quiet "a light under the plane (an open surface)" err7
exit $fail
