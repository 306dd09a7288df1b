#!/bin/sh
# Volume settings that would change nothing are said, not silently dropped:
#  - a time index with a volume file that has no time steps (not NetCDF) is refused;
#  - a volume too thin to see (its peak extinction times its box's diagonal, a bound on any
#    ray's optical depth across it, under 0.01) renders with a warning that names the peak
#    extinction and optical depth and the density unit / scale options; a visible one
#    gets no such warning;
#  - a scene's "particle" (a volume file's field type) does not carry over to the cloud
#    droplets of a volume --volume generate:… puts in its place (the same image as without it).
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
# a file source's particle type does not become a generated cloud's droplets: the same image as
# with no particle given; --particle given again is used
printf '{"volume": {"file": "%s", "particle": "ice"}}\n' "$T/v.json" >"$T/ps.json"
printf '{"volume": {"file": "%s"}}\n' "$T/v.json" >"$T/p0.json"
gen="--volume generate:cumulus --voxel-size 400 --width 16 --height 9 --renderer path --spp 1 --threads 1"
for s in ps p0; do
    # shellcheck disable=SC2086
    "$A" render "$T/$s.json" $gen -D "$P" --pfm "$T/$s.pfm" >/dev/null 2>"$T/err" || { bad "$s.json:"; cat "$T/err" >&2; }
done
cmp -s "$T/ps.pfm" "$T/p0.pfm" && ok "--volume generate: the file's particle dropped (the same image)" ||
    bad "--volume generate kept the file's particle (another image)"
# shellcheck disable=SC2086
"$A" render "$T/ps.json" $gen -D "$P" --particle no_such_particle --pfm "$T/ps2.pfm" >/dev/null 2>"$T/err" &&
    bad "--particle given again was not used" || has "--particle given again" "no_such_particle"
exit $fail
