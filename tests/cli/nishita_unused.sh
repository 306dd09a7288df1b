#!/bin/sh
# The Nishita renderer's settings that its field of every order leaves without a use
# (src/render/nishita_plan.c, warn_unused): with "do" (the default) mc_kphotons, diffuse and the
# reference patterns' orders, ratio and paths change nothing, and a render that sets them says so
# on stderr; the shipped Fig. 7 scene sets none and warns of nothing; with "do": false the
# patterns' settings are in use and no warning names them. A scene's objects beside a cloud volume
# are pointed at the Harris renderer.
. "$(dirname "$0")/common.inc"
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}/scenes/nishita_fig07_a_sun65.json
run() { # ARGS...: the scene at 24 x 14, stderr into $T/err
    "$A" render "$S" --width 24 --height 14 --threads 2 -q -o "$T/n.png" "$@" 2>"$T/err"
    st=$?
    [ $st -eq 0 ] || bad "render $*: exit $st: $(cat "$T/err")"
}
run
[ ! -s "$T/err" ] && ok "the shipped scene warns of nothing" || bad "the shipped scene: $(cat "$T/err")"
run --nishita-mc 5
grep -q "mc_kphotons does nothing with do" "$T/err" && ok "--nishita-mc with do" || bad "--nishita-mc with do: $(cat "$T/err")"
run --nishita-diffuse
grep -q "diffuse does nothing with do" "$T/err" && ok "--nishita-diffuse with do" ||
    bad "--nishita-diffuse with do: $(cat "$T/err")"
run --nishita-orders 2
grep -q "orders, ratio and paths .* do nothing with do" "$T/err" && ok "--nishita-orders with do" ||
    bad "--nishita-orders with do: $(cat "$T/err")"
run -D nishita.do=false -D nishita.mc_delta_m=false --nishita-orders 2 --nishita-paths 64
grep -q "do nothing" "$T/err" && bad "the patterns' settings without do: $(cat "$T/err")" || ok "no warning without do"
run -D nishita.do=false -D nishita.mc_kphotons=1 --nishita-ratio 0.5
grep -q "orders, ratio and paths .* do nothing with mc_kphotons" "$T/err" && ok "--nishita-ratio with photons" ||
    bad "--nishita-ratio with photons: $(cat "$T/err")"
# a scene's objects with a cloud volume: the warning points at the renderer that draws both (Harris's),
# not at the path tracer, which refuses objects beside a volume
"$A" render "$(dirname "$S")/harris_aircraft.json" --renderer nishita --width 24 --height 14 --threads 2 -q \
    -o "$T/a.png" 2>"$T/err" || bad "harris_aircraft with nishita: $(cat "$T/err")"
grep -q "does not draw the scene's objects (the harris renderer draws objects" "$T/err" && ok "objects with a volume: harris named" ||
    bad "objects with a volume: $(cat "$T/err")"
exit $fail
