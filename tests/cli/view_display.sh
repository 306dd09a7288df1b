#!/bin/sh
# atmos view without a display (docs/viewer.md, "Scripted and headless"): with neither
# DISPLAY nor WAYLAND_DISPLAY set, SDL2 falls back to its "offscreen" video driver, which
# opens an invisible window; the viewer refuses it at once (exit 1) with the hint of
# --headless --frames N and xvfb-run, leaves no frames.csv behind, and --headless still runs.
# An explicit SDL_VIDEODRIVER=offscreen is the user's choice and is kept.
. "$(dirname "$0")/common.inc"
cd "$T" || exit 1
nodisplay() { env -u DISPLAY -u WAYLAND_DISPLAY -u SDL_VIDEODRIVER "$@"; }

t0=$(date +%s)
nodisplay timeout 10 "$A" view --size 64x36 --record rec >out.txt 2>err.txt
st=$?
dt=$(( $(date +%s) - t0 ))
[ $st -eq 1 ] && ok "no display: exit 1 in ${dt} s" || { bad "no display: exit $st after ${dt} s (124: it kept running)"; cat err.txt >&2; }
grep -q "atmos view: .*no display" err.txt && grep -q -- "--headless --frames N" err.txt && grep -q "xvfb-run" err.txt &&
    ok "the message points to --headless --frames N and xvfb-run" || { bad "the message:"; sed 's/^/  /' err.txt >&2; }
[ ! -f rec/frames.csv ] && ok "no frames.csv left behind" || bad "a frames.csv was left: $(wc -l <rec/frames.csv) line(s)"

# --frames alone (no --headless) is refused the same way
nodisplay timeout 20 "$A" view --size 64x36 --frames 2 >/dev/null 2>err2.txt
st=$?
[ $st -eq 1 ] && grep -q -- "--headless" err2.txt && ok "--frames without a display: exit 1" || { bad "--frames without a display: exit $st"; cat err2.txt >&2; }

# headless needs no display
nodisplay timeout 60 "$A" view --headless --frames 2 --size 32x18 --record hl >/dev/null 2>err3.txt
st=$?
[ $st -eq 0 ] && [ "$(tail -n +2 hl/frames.csv | wc -l)" -eq 2 ] && ok "--headless without a display: 2 frames" ||
    { bad "--headless without a display: exit $st"; cat err3.txt >&2; }

# an explicit offscreen driver is kept (frames rendered, exit 0)
env -u DISPLAY -u WAYLAND_DISPLAY SDL_VIDEODRIVER=offscreen timeout 60 "$A" view --frames 2 --size 32x18 --record os \
    >/dev/null 2>err4.txt
st=$?
[ $st -eq 0 ] && [ "$(tail -n +2 os/frames.csv | wc -l)" -eq 2 ] && ok "SDL_VIDEODRIVER=offscreen asked for: 2 frames" ||
    { bad "SDL_VIDEODRIVER=offscreen: exit $st"; cat err4.txt >&2; }
exit $fail
