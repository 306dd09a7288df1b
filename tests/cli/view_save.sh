#!/bin/sh
# atmos view's saved frames and messages (docs/viewer.md): F12 with --save-base in a folder
# that does not exist yet creates it (as atmos render does for its outputs); a save that
# cannot be written prints why and the session goes on (every frame still rendered, exit
# 0); the scene options' errors are the viewer's ("atmos view: ...", "Try 'atmos view
# --help'"), never atmos render's.
. "$(dirname "$0")/common.inc"

# the scene options' errors, headless: the viewer's name, not atmos render's
msg() { # NAME WANT_STATUS TEXT ARGS...
    name=$1 want=$2 text=$3
    shift 3
    "$A" view --headless --frames 1 --size 16x9 "$@" >/dev/null 2>"$T/err"
    st=$?
    if [ $st -eq "$want" ] && grep -qF -- "$text" "$T/err" && ! grep -q "atmos render" "$T/err"; then
        ok "$name: exit $st, '$text'"
    else
        bad "$name: exit $st (want $want), stderr:"
        sed 's/^/  /' "$T/err" >&2
    fi
}
msg "bad --renderer" 2 "atmos view: --renderer: expected" --renderer nope
msg "bad --renderer's help hint" 2 "Try 'atmos view --help'" --renderer nope
msg "bad -D" 2 "atmos view: -D: /camera/fov_deg" -D camera.fov_deg=500
msg "volume file options on a generated volume" 2 "atmos view: --grids" --volume generate:cumulus --grids a
msg "a missing scene file" 1 "atmos view: " "$T/no_such_scene.json"
msg "bad --screen-layer-px" 2 "atmos view: --screen-layer-px: expected 0 (off)" --screen-layer-px 0.5

if ! command -v xvfb-run >/dev/null 2>&1; then
    bad "xvfb-run is missing (scripts/install-deps.sh installs xvfb and xauth)"
    exit 1
fi
cd "$T" || exit 1
run_view() { # OUT ARGS...: 3 frames under Xvfb, F12 pressed at the second
    out=$1
    shift
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
    xvfb-run -a "$A" view --frames 3 --size 48x27 --press F12 "$@" >"$out" 2>&1
}

# a save into a folder that does not exist: made
run_view "$T/x1.txt" --save-base saved/halo
st=$?
[ $st -eq 0 ] && ok "--save-base saved/halo: exit 0" || { bad "--save-base saved/halo: exit $st"; cat "$T/x1.txt" >&2; }
for e in exr png json; do
    [ -s "saved/halo_001.$e" ] && ok "saved/halo_001.$e written" || bad "no saved/halo_001.$e"
done

# a save that fails (a file where the folder should be): said, and the session goes on
: >blocker
run_view "$T/x2.txt" --save-base blocker/halo --record rec
st=$?
[ $st -eq 0 ] && ok "a failed save does not end the session (exit 0)" || bad "a failed save: exit $st"
grep -q "atmos view: .*blocker" "$T/x2.txt" && ok "the failed save is reported" || { bad "no message for the failed save"; cat "$T/x2.txt" >&2; }
[ -s rec/frame_00002.png ] && ok "all 3 frames rendered after the failed save" || bad "the session stopped after the failed save"
exit $fail
