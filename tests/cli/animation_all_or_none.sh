#!/bin/sh
# An animation's frames are written all or none (README, "Every output is checked before
# rendering"): a run interrupted after its first frame leaves the frames of the run before it
# untouched, byte for byte, and no temporary; SIGHUP and SIGXFSZ clean up as SIGINT does; a
# time-lapse that would run backwards is refused by its key before anything is rendered.
. "$(dirname "$0")/common.inc"
# the old set: 2 frames, quick
"$A" render --frames 2 --sun-elevation 20 --sun-elevation-end 5 --width 48 --height 27 -o "$T/a.png" -q 2>"$T/err" ||
    { bad "first animation"; cat "$T/err" >&2; }
cp "$T/a_0001.png" "$T/old1.png" && cp "$T/a_0002.png" "$T/old2.png" || bad "no frames from the first run"
# The new set, slow frames (the path tracer, one thread), interrupted once frame 1 is reported.
# wait_for FILE TEXT: up to 60 s until FILE holds TEXT.
wait_for() {
    i=0
    while ! grep -q "$2" "$1" 2>/dev/null && [ $i -lt 1200 ]; do sleep 0.05; i=$((i + 1)); done
    grep -q "$2" "$1" 2>/dev/null
}
"$A" render --frames 2 --sun-elevation 40 --sun-elevation-end 10 --width 64 --height 36 --renderer path \
    --spp 4096 --threads 1 -o "$T/a.png" 2>"$T/err2" &
pid=$!
wait_for "$T/err2" "made .*a_0001.png" || bad "frame 1 was never reported: nothing interrupted"
kill -INT $pid
wait $pid
rc=$?
[ $rc -ne 0 ] && ok "interrupted (exit $rc)" || bad "the run ended 0 before its interruption"
cmp -s "$T/a_0001.png" "$T/old1.png" && cmp -s "$T/a_0002.png" "$T/old2.png" &&
    ok "both old frames untouched after an interrupted animation" || bad "a mixed set of old and new frames"
ls "$T" | grep -q tmp && { bad "temporaries left"; ls "$T" >&2; } || ok "no temporary left"
# SIGHUP and SIGXFSZ during a render remove its staging files as SIGINT does
for sig in HUP XFSZ; do
    "$A" render --renderer path --spp 4096 --threads 1 --width 64 --height 36 -o "$T/h.png" --pfm "$T/h.pfm" \
        2>"$T/err3" &
    pid=$!
    i=0
    while ! ls "$T" | grep -q 'h.pfm.tmp' && [ $i -lt 1200 ]; do sleep 0.05; i=$((i + 1)); done
    ls "$T" | grep -q 'h.pfm.tmp' || bad "SIG$sig: the render never staged its files: nothing interrupted"
    sleep 0.3
    kill -$sig $pid
    wait $pid
    ls "$T" | grep -q '^h\.' && { bad "SIG$sig left files"; ls "$T" >&2; } || ok "SIG$sig: nothing left"
done
# a time-lapse running backwards: refused by its key, nothing rendered or written
S="${ATMOS_SOURCE_DIR:-$(dirname "$0")/../..}/scenes/simulated_cumulus_timelapse.json"
"$A" render "$S" --width 48 --height 27 -D volume.simulate.grid=16 -D animation.frames=3 -D animation.minutes_end=2 \
    -o "$T/back.png" 2>"$T/err4"
rc=$?
[ $rc -ne 0 ] && grep -q "/animation/minutes_end" "$T/err4" && ! grep -q "frame 1/" "$T/err4" &&
    ok "a backwards time-lapse refused by /animation/minutes_end before rendering" ||
    { bad "backwards time-lapse: exit $rc"; cat "$T/err4" >&2; }
ls "$T" | grep -q back && bad "a backwards time-lapse wrote files" || ok "nothing written for it"
# --frames 1 with an end for the sun: the first frame, as named (--help)
"$A" render --frames 1 --sun-elevation 12 --sun-elevation-end -1 --width 32 --height 18 -o "$T/one.png" -q 2>"$T/err5" &&
    [ -s "$T/one.png" ] && ok "--frames 1 renders the first frame as named" || { bad "--frames 1"; cat "$T/err5" >&2; }
exit $fail
