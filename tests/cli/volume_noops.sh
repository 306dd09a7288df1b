#!/bin/sh
# Volume settings that would change nothing are said, not silently dropped:
#  - a time index with a volume file that has no time steps (not NetCDF) is refused;
#  - a volume too thin to see (its peak extinction times its box's diagonal, a bound on any
#    ray's optical depth across it, under 0.01) renders with a warning that names the peak
#    extinction and optical depth and the density unit / scale options; a visible one
#    gets no such warning.
. "$(dirname "$0")/common.inc"
has() { grep -qF -- "$2" "$T/err" && ok "$1: names '$2'" || { bad "$1: no '$2' in:"; sed 's/^/  /' "$T/err" >&2; }; }

"$A" volume generate cumulus -o "$T/v.json" --voxel-size 200 >/dev/null 2>&1 || bad "volume generate"
# an analytic particle (no Mie table to build): sigma_ext 6e-10 m^2, a cloud droplet's
P='particles.cloud={"kind":"analytic","lobes":[{"type":"hg","g":0.8}],"sigma_ext_m2":6e-10}'
common="--volume $T/v.json --width 16 --height 9 --renderer path --spp 1"

# shellcheck disable=SC2086
"$A" render $common -D "$P" --time-index 2 --pfm "$T/t.pfm" >/dev/null 2>"$T/err"
st=$?
[ $st -ne 0 ] && ok "--time-index 2 with a raw volume refused (exit $st)" || bad "--time-index 2 with a raw volume accepted"
has "--time-index" "time index"
has "--time-index" "NetCDF"
[ -e "$T/t.pfm" ] && bad "an image was written anyway" || ok "no image written"
# shellcheck disable=SC2086
"$A" render $common -D "$P" --time-index 0 --pfm "$T/t0.pfm" >/dev/null 2>"$T/err" && ok "--time-index 0 (the one time) accepted" || bad "--time-index 0 refused"

# shellcheck disable=SC2086
"$A" render $common -D "$P" --density-scale 1e-9 --pfm "$T/thin.pfm" >/dev/null 2>"$T/err"
st=$?
[ $st -eq 0 ] && ok "a near-invisible volume still renders (exit 0)" || bad "thin volume: exit $st"
has "thin volume" "warning"
has "thin volume" "peak extinction"
has "thin volume" "optical depth"
has "thin volume" "--density-unit"
has "thin volume" "--density-scale"
# shellcheck disable=SC2086
"$A" render $common -D "$P" --pfm "$T/thick.pfm" >/dev/null 2>"$T/err"
grep -q "peak extinction" "$T/err" && bad "a visible volume got the warning" || ok "no warning for a visible volume"
exit $fail
