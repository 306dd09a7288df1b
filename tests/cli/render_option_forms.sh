#!/bin/sh
# Every renderer option that `atmos render --help` lists (the slice, path, nishita, harris and
# beams sections) must reach the scene exactly as its -D form does: for each one, a tiny
# scene rendered with the option and with `-D SECTION.KEY=VALUE` gives the same PFM bytes.
# The expected -D form of each flag is written out here (not taken from the tables the CLI is
# made from), and a flag in --help that this list lacks is a failure, so a new option cannot
# go untested. Options that change a tiny image must also differ from the default render, so
# an option that does nothing is caught even when its -D form does nothing either.
. "$(dirname "$0")/common.inc"
S=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}

# A 12^3 ball of dense air (raw float32 + sidecar: optical depth about 1 across) for the
# volume renderers; air, not cloud droplets, whose phase tables would take seconds to make.
python3 - "$T" <<'PY' || exit 1
import struct, sys
n = 12
vals = []
for z in range(n):
    for y in range(n):
        for x in range(n):
            r = ((x - 5.5) ** 2 + (y - 5.5) ** 2 + (z - 5.5) ** 2) ** 0.5
            vals.append(5e27 if r < 5 else 0.0)
open(sys.argv[1] + "/v.raw", "wb").write(struct.pack("<%df" % len(vals), *vals))
open(sys.argv[1] + "/v.json", "w").write('{"file": "v.raw", "dims": [12, 12, 12], "voxel_size_m": 40, "particle": "air"}')
PY

# The base command of each renderer: tiny images, one thread (Nishita's: the paper's method, its
# default do field off, orders 1-2 on a coarse light field, a tenth of the time).
base() {
    case $1 in
    beams) echo "$S/scenes/dobashi_fig04_spotlight.json --width 24 --height 36" ;;
    nishita) echo "--volume $T/v.json --renderer nishita --width 10 --height 8 -D nishita.orders=2 -D nishita.cells=4 -D nishita.paths=4 -D nishita.do=false -D nishita.mc_delta_m=false" ;;
    *) echo "--volume $T/v.json --renderer $1 --width 10 --height 8" ;;
    esac
}

# flag (with its argument) | the -D form | renderer | "same" if a tiny image may not show it
# (a budget never reached, orders beyond what a thin ball scatters, order-3 paths with orders
# 2, impostors smaller anyway, a diffuse field faded out in a thin ball, the slice renderer's
# default field chosen again)
cat >"$T/table" <<'EOF'
--slices 16|slice.slices=16|slice|
--light-size 16|slice.light_size=16|slice|
--xi 0.5|slice.xi=0.5|slice|
--eq24|slice.update=eq24|slice|
--low-albedo|slice.low_albedo=true|slice|
--grid-max-dim 8|slice.grid_max_dim=8|slice|
--eye-scale 0.5|slice.eye_scale=0.5|slice|
--edge-aa 0|slice.edge_aa=0|slice|
--max-order 1|slice.max_order=1|slice|same
--slice-p1|slice.field=p1|slice|
--no-diffuse|slice.diffuse=false|slice|
--slice-do|slice.do=true|slice|same
--no-air-shadows|slice.air_shadows=false|slice|
--spp 3|path.spp=3|path|
--time-budget 1000|path.time_budget_s=1000|path|same
--seed 7|path.seed=7|path|
--max-depth 1|path.max_depth=1|path|
--truncate 5|path.truncate_deg=5|path|
--no-sky-nee|path.sky_nee=false|path|
--no-forced|path.forced=false|path|
--no-aureole|path.aureole=false|path|same
--no-roulette|path.roulette=false|path|same
--nishita-orders 1|nishita.orders=1|nishita|
--nishita-ratio 0.5|nishita.ratio=0.5|nishita|
--nishita-paths 8|nishita.paths=8|nishita|same
--nishita-cells 5|nishita.cells=5|nishita|
--no-nishita-sky|nishita.sky=false|nishita|
--nishita-step 100|nishita.step_pct=100|nishita|
--nishita-diffuse|nishita.diffuse=true|nishita|same
--nishita-mc 1|nishita.mc_kphotons=1|nishita|
--nishita-mc-cell 2|nishita.mc_cell=2|nishita|same
--nishita-mc-lmax 2|nishita.mc_lmax=2|nishita|same
--nishita-mc-delta-m|nishita.mc_delta_m=true|nishita|same
--nishita-do|nishita.do=true|nishita|
--nishita-mc-dm-clip|nishita.mc_dm_clip=true|nishita|same
--nishita-edge-aa 0|nishita.edge_aa=0|nishita|
--spacing 100|harris.spacing_m=100|harris|
--max-particles 10|harris.max_particles=10|harris|
--sky-lights 0|harris.sky_lights=0|harris|
--harris-light-size 16|harris.light_size=16|harris|
--no-impostors|harris.impostors=false|harris|same
--impostor-tolerance 5|harris.impostor_tolerance_deg=5|harris|same
--impostor-max-res 16|harris.impostor_max_res=16|harris|same
--no-harris-diffuse|harris.diffuse=false|harris|same
--plane-spacing 0.5|beams.plane_spacing_m=0.5|beams|
--beams-epsilon 0.1|beams.epsilon=0.1|beams|
--max-subplanes 1|beams.max_subplanes=1|beams|
--shadow-size 16|beams.shadow_size=16|beams|
--beams-sun|beams.sun=true|beams|
--interleave 2|beams.interleave=2|beams|
--screen-step 1|beams.screen_step=1|beams|
--exact-shadows|beams.exact_shadows=true|beams|same
EOF

# Every renderer option of --help is in the table.
"$A" render --help >"$T/help" || bad "render --help"
sed -n '/^Slice renderer (/,/^Animation (/p' "$T/help" | sed -n 's/^      \(--[a-z0-9-]*\).*/\1/p' >"$T/flags"
[ -s "$T/flags" ] || bad "no renderer options found in render --help"
while read -r flag; do
    grep -q -- "^$flag[ |]" "$T/table" || bad "$flag is in render --help but not checked here"
done <"$T/flags"

render() { # OUT ARGS...: one render to OUT.pfm
    out=$1
    shift
    # shellcheck disable=SC2046
    "$A" render "$@" --threads 1 -q --pfm "$out.pfm" 2>"$out.err" || { bad "atmos render $*"; cat "$out.err" >&2; }
}

for r in slice path nishita harris beams; do
    # shellcheck disable=SC2046
    render "$T/default_$r" $(base $r)
done
i=0
while IFS='|' read -r opt define r same; do
    i=$((i + 1))
    # shellcheck disable=SC2046,SC2086
    render "$T/opt$i" $(base $r) $opt
    # shellcheck disable=SC2046
    render "$T/def$i" $(base $r) -D "$define"
    if cmp -s "$T/opt$i.pfm" "$T/def$i.pfm"; then ok "$opt = -D $define"; else bad "$opt renders differently from -D $define"; fi
    if [ -z "$same" ] && cmp -s "$T/opt$i.pfm" "$T/default_$r.pfm"; then bad "$opt changes nothing in the image"; fi
done <"$T/table"

# --exposure auto on a scene with a manual EV: the -D form's exposure, not that EV taken as
# a compensation of +9 stops (which turned Fig. 4's beam white).
png_scale() { # the exposure scale a PNG's metadata records
    png_text "$1" atmos:exposure_scale
}
# shellcheck disable=SC2046
"$A" render $(base beams) --exposure auto -q -o "$T/auto_opt.png" || bad "render --exposure auto"
# shellcheck disable=SC2046
"$A" render $(base beams) -D output.exposure=auto -q -o "$T/auto_def.png" || bad "render -D output.exposure=auto"
a=$(png_scale "$T/auto_opt.png") b=$(png_scale "$T/auto_def.png")
if [ -n "$a" ] && [ "$a" = "$b" ]; then ok "--exposure auto = -D output.exposure=auto (scale $a)"; else bad "--exposure auto scale $a, -D form $b"; fi
# an option that does nothing on its own says so
# shellcheck disable=SC2046
"$A" render $(base nishita) -q --nishita-mc 1 --nishita-mc-delta-m -o "$T/dm.png" 2>"$T/dm.err" || bad "render --nishita-mc-delta-m"
grep -q "mc_delta_m does nothing" "$T/dm.err" && ok "--nishita-mc-delta-m with photons toward the view alone warns" ||
    bad "no warning: $(cat "$T/dm.err")"
# shellcheck disable=SC2046
"$A" render $(base nishita) -q --nishita-mc-dm-clip -o "$T/clip.png" 2>"$T/clip.err" || bad "render --nishita-mc-dm-clip"
grep -q "mc_dm_clip does nothing without mc_delta_m" "$T/clip.err" && ok "--nishita-mc-dm-clip without delta-M warns" ||
    bad "no warning: $(cat "$T/clip.err")"
exit $fail
