#!/bin/sh
# atmos view --record interrupted (docs/viewer.md, "Interrupting a recording"): SIGINT or SIGTERM
# while a flight is recorded ends the session with "atmos view: interrupted" and the signal's
# status (130, 143); every frame recorded so far has its PNG and its whole line in frames.csv
# (flushed per frame), no line is cut and no writer's temporary (frame_NNNNN.png.tmpPID) is
# left. A flight longer than the 10000000 frames a session plays is refused (without --frames).
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1

# a long flight at 1000 fps (a million frames): it is still recording when signalled
printf '{"fps": 1000, "keys": [{"t": 0, "position_m": [0, 1000, 2000], "look_at_m": [0, 1500, -4000]},\n' >long.json
printf ' {"t": 1000, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000]}]}\n' >>long.json

# SIG: the signal; WANT: the exit status
interrupt() {
    sig=$1 want=$2 dir=rec_$1
    "$A" view --headless --script long.json --size 16x9 --renderer sky --record "$dir" >"out_$sig.txt" 2>&1 &
    pid=$!
    n=0 # until 5 frames are recorded (at most 120 s: the first frame prepares the renderer)
    while [ ! -e "$dir/frame_00005.png" ] && [ $n -lt 1200 ] && kill -0 $pid 2>/dev/null; do
        sleep 0.1
        n=$((n + 1))
    done
    kill -s "$sig" $pid
    n=0 # a viewer that ignores the signal is stopped after 20 s
    while kill -0 $pid 2>/dev/null && [ $n -lt 200 ]; do sleep 0.1; n=$((n + 1)); done
    kill -0 $pid 2>/dev/null && { kill -s KILL $pid; bad "SIG$sig: the viewer went on recording"; }
    wait $pid
    st=$?
    [ $st -eq "$want" ] && ok "SIG$sig: exit $st" || { bad "SIG$sig: exit $st (want $want)"; cat "out_$sig.txt" >&2; }
    grep -qx "atmos view: interrupted" "out_$sig.txt" && ok "SIG$sig: 'atmos view: interrupted'" ||
        { bad "SIG$sig: no 'atmos view: interrupted' line:"; cat "out_$sig.txt" >&2; }
    tmp=$(ls "$dir" | grep -c 'tmp')
    [ "$tmp" -eq 0 ] && ok "SIG$sig: no temporary file left" || bad "SIG$sig: left $(ls "$dir" | grep tmp)"
    pngs=$(ls "$dir" | grep -c '^frame_[0-9]*\.png$')
    # every line whole: the header's 13 columns, a newline at the end; one line per PNG
    python3 - "$dir/frames.csv" "$pngs" <<'PY' && ok "SIG$sig: frames.csv holds a whole line for each of the $pngs PNGs" ||
import sys
text = open(sys.argv[1]).read()
lines = text.split("\n")
assert text.endswith("\n"), "the last line is cut: %r" % lines[-1]
rows = [l.split(",") for l in lines[:-1]]
assert all(len(r) == 13 for r in rows), [r for r in rows if len(r) != 13]
assert [int(r[0]) for r in rows[1:]] == list(range(len(rows) - 1)), "frame numbers"
assert len(rows) - 1 == int(sys.argv[2]) >= 5, (len(rows) - 1, sys.argv[2])
PY
        { bad "SIG$sig: frames.csv ($(wc -c <"$dir/frames.csv" 2>/dev/null) bytes) and the $pngs PNGs disagree"; }
}
interrupt INT 130
interrupt TERM 143

# the frame cap: a flight of 1e7 s at 1000 fps (1e10 frames) refused before any work; with
# --frames it plays those
printf '{"fps": 1000, "keys": [{"t": 0, "position_m": [0, 1000, 2000], "look_at_m": [0, 1500, -4000]},\n' >huge.json
printf ' {"t": 1e7, "position_m": [0, 1000, 0], "look_at_m": [0, 1500, -4000]}]}\n' >>huge.json
"$A" view --headless --script huge.json --size 16x9 --renderer sky --record rec_huge >out_huge.txt 2>&1
st=$?
[ $st -eq 2 ] && grep -q "more than the 10000000 frames a session plays" out_huge.txt && [ ! -e rec_huge/frame_00000.png ] &&
    ok "a flight of 1e10 frames: refused (exit 2)" || { bad "a flight of 1e10 frames: exit $st"; cat out_huge.txt >&2; }
"$A" view --headless --script huge.json --frames 2 --size 16x9 --renderer sky >out_huge2.txt 2>&1 &&
    ok "the same flight with --frames 2: played" || { bad "the long flight with --frames 2 refused"; cat out_huge2.txt >&2; }
exit $fail
