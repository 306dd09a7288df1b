#!/bin/sh
# Relative paths of a scene read from standard input (`atmos render -`) are relative to the
# current folder (a scene file's are relative to its folder): a spot's window image found
# there renders; one that is not there is an error naming the scene key and the file, and
# saying where it was looked for; `atmos render --help` says so. A file given with -D
# (-D lights.0.image=win.png) is relative to the current folder too, whatever the scene
# file's folder.
. "$(dirname "$0")/common.inc"
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}
mkdir -p "$T/here" "$T/elsewhere" || exit 1

cp "$S/scenes/dobashi_fig09b_window.png" "$T/here/win.png" || exit 1
sed 's/"image": "[^"]*"/"image": "win.png"/' "$S/scenes/dobashi_fig09b_stained_glass.json" >"$T/scene.json"
grep -q '"image": "win.png"' "$T/scene.json" || bad "the scene's image key not found"

(cd "$T/here" && "$A" render - --width 24 --height 16 -q -o "$T/ok.png" <"$T/scene.json" 2>"$T/ok.err") &&
    [ -s "$T/ok.png" ] && ok "a window image relative to the current folder" || bad "render from here: $(cat "$T/ok.err")"

(cd "$T/elsewhere" && "$A" render - --width 24 --height 16 -q -o "$T/no.png" <"$T/scene.json" 2>"$T/no.err")
rc=$?
if [ $rc -eq 1 ] && grep -q "/lights/0/image: win.png: .*current folder" "$T/no.err" && [ ! -e "$T/no.png" ]; then
    ok "a missing window image names /lights/0/image and the file"
else
    bad "missing image (exit $rc): $(cat "$T/no.err")"
fi

# -D KEY=FILE names FILE from the current folder, not from the scene file's folder
cp "$T/scene.json" "$T/elsewhere/scene.json" || exit 1
(cd "$T/here" && "$A" render "$T/elsewhere/scene.json" -D lights.0.image=win.png --width 24 --height 16 -q \
    -o "$T/d.png" 2>"$T/d.err") && [ -s "$T/d.png" ] && ok "-D lights.0.image=FILE from the current folder" ||
    bad "-D image from here: $(cat "$T/d.err")"
(cd "$T/elsewhere" && "$A" render "$T/elsewhere/scene.json" -D 'lights.0.image="win.png"' --width 24 --height 16 \
    -q -o "$T/d2.png" 2>"$T/d2.err")
rc=$?
if [ $rc -ne 0 ] && grep -q "$T/elsewhere/win.png" "$T/d2.err"; then ok "a -D file missing from the current folder is named with it"
else bad "-D missing image (exit $rc): $(cat "$T/d2.err")"; fi

"$A" render --help >"$T/help.txt"
grep -q "standard input.*current folder\|current folder.*standard input" "$T/help.txt" &&
    ok "render --help says where a scene from standard input finds its files" || bad "render --help does not say it"
exit $fail
