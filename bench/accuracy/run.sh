#!/bin/sh
# The accuracy report of docs/accuracy.md: the slice renderer (Riley et al. 2004 §4.2-§5)
# in several variants, and Harris's particle renderer (harris: the sun and six sky lights;
# harris_sun: the sun alone), against the path tracer as reference, on four volumes with the sun
# behind the viewer and in front of it. Errors are split by the optical depth along each
# pixel's ray (atmos render --tau, atmos compare --by).
#
#   bench/accuracy/run.sh [OUT_DIR]      (default: docs/accuracy)
#
# Environment: ATMOS (the binary, default build/atmos), SPP (path samples per pixel,
# default 1024), TRUNCATE (the path tracer's forward-peak cut, degrees, default 3; 0 = exact),
# CASES (default "cumulus cirrus rain disney"; also harris_cumulus, Harris's particle cumulus),
# VARIANTS (default all of the slice variants below; "nishita": the Nishita renderer as the paper
# wrote it (its do field, the default since 2026-12-07, off), "harris",
# "harris_sun": Harris's (with the diffuse light field, its default since 2026-12-06), the
# Nishita renderer with that field, "nishita_diffuse", Harris's forward shading alone (Harris
# 2002, its default before), "harris_forward", "harris_sun_forward"; "diffuse": the P1 field, --slice-p1; "diffuse_aa": the
# same with four eye rays per pixel, antialiased; "slice_do", "slice_do_aa": the slice renderer with
# the discrete-ordinates field, one (--edge-aa 0) and four eye rays per pixel; "slice_do_edge": the
# same with four rays only at the volume's edges, --edge-aa $EDGE_AA (0.05: the default renderer); "nishita_do": the Nishita renderer with that field,
# its sky's light the field's inflow, "nishita_do_nosky" the same without: not in the default list), THREADS, REUSE (1: keep the reference images
# already in OUT_DIR, e.g. to compare a new build's variants against the same references).
# Where the sun's disk is seen (the cirrus in front) the truncated reference has no aureole within
# TRUNCATE degrees of it (sun_cone.py): those pixels, the disk's and its cone's, are left out of
# every figure and reported apart (cone_bins), against OUT_DIR/<case>_<sun>.path_exact.pfm, an
# untruncated reference (--truncate 0), when there is one.
# The Disney case reads ../shared/data/real/wdas_cloud_sixteenth.vdb beside the checkout.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
A=${ATMOS:-$root/build/atmos}
OUT=${1:-$root/docs/accuracy}
SPP=${SPP:-1024}
TRUNCATE=${TRUNCATE:-3}
CASES=${CASES:-"cumulus cirrus rain disney"}
VARIANTS=${VARIANTS:-"eq25 eq25_xi0 eq25_xi4 eq24 low_albedo diffuse diffuse_xi0"}
TH=${THREADS:+--threads $THREADS}
mkdir -p "$OUT"
csv="$OUT/results.csv"
# rel_rmse, bias_rel: over the volume's pixels (optical depth >= 0.01), relative to the
# reference's mean there; tau_bins, order_bins: [bin start, pixels, rel_rmse, rel_bias] per bin
# cone_bins: the same for the sun's disk's pixels and the rest of its cone ([] when the disk is not seen)
echo "case,sun,variant,seconds,rel_rmse,bias_rel,tau_bins,order_bins,cone_bins" > "$csv"

# Seconds rendering and writing, from atmos render's own timing line
# ("atmos render: ... s in all: ... s for the scene, ..., 1.234 s rendering and writing").
secs() { if [ -f "$1" ]; then sed -n 's/.*, \([0-9.]*\) s rendering and writing$/\1/p' "$1" | tail -1; fi; }

for c in $CASES; do
    scene="$here/$c.json"
    for sun in behind front; do
        # The camera looks north in every case: the sun in the south is behind it.
        if [ "$sun" = behind ]; then az=180; else az=0; fi
        base="$OUT/${c}_$sun"
        echo "== $c, sun $sun" >&2
        if [ "${REUSE:-0}" = 1 ] && [ -s "$base.path.pfm" ] && [ -s "$base.tau.pfm" ] && [ -s "$base.order.pfm" ]; then
            echo "   (reusing $base.path.pfm)" >&2
        else
            "$A" render "$scene" $TH --sun-azimuth $az --renderer path --spp "$SPP" --truncate "$TRUNCATE" --pfm "$base.path.pfm" \
                --variance "$base.path.var.exr" --order "$base.order.pfm" --tau "$base.tau.pfm" -o "$base.path.png" \
                2> "$base.path.log"
        fi
        echo "$c,$sun,path,$(secs "$base.path.log"),0,0,[],[],[]" >> "$csv"
        # the keys without the sun's cone (unchanged when the disk is not seen), the cone's own key
        python3 "$here/sun_cone.py" "$scene" "$base.path.pfm" "$TRUNCATE" "$base.cone.pfm" \
            "$base.tau.pfm" "$base.tau_nosun.pfm" "$base.order.pfm" "$base.order_nosun.pfm" >&2
        cref="$base.path.pfm"
        if [ -s "$base.path_exact.pfm" ]; then cref="$base.path_exact.pfm"; fi
        for v in $VARIANTS; do
            case $v in
            eq25) opts="--no-diffuse" ;;
            eq25_xi0) opts="--no-diffuse --xi 0" ;;
            eq25_xi4) opts="--no-diffuse --xi 0.0318" ;;
            eq24) opts="--no-diffuse --eq24" ;;
            low_albedo) opts="--low-albedo" ;;
            diffuse) opts="--slice-p1" ;;
            diffuse_xi0) opts="--slice-p1 --xi 0" ;;
            diffuse_aa) opts="--slice-p1 --eye-scale 2" ;;
            slice_do) opts="--slice-do --edge-aa 0" ;;
            slice_do_aa) opts="--slice-do --eye-scale 2" ;;
            slice_do_edge) opts="--slice-do --edge-aa ${EDGE_AA:-0.05}" ;;
            nishita_do) opts="--renderer nishita --nishita-mc-lmax 3 --nishita-mc-delta-m --nishita-do" ;;
            nishita_do_nosky) opts="--renderer nishita --nishita-mc-lmax 3 --nishita-mc-delta-m --nishita-do \
--no-nishita-sky" ;;
            nishita) opts="--renderer nishita -D nishita.do=false -D nishita.mc_delta_m=false" ;; # as written
            harris) opts="--renderer harris" ;;
            harris_sun) opts="--renderer harris --sky-lights 0" ;;
            nishita_diffuse) opts="--renderer nishita --nishita-diffuse -D nishita.do=false -D nishita.mc_delta_m=false" ;;
            harris_forward) opts="--renderer harris --no-harris-diffuse" ;;
            harris_sun_forward) opts="--renderer harris --sky-lights 0 --no-harris-diffuse" ;;
            esac
            "$A" render "$scene" $TH --sun-azimuth $az $opts --pfm "$base.$v.pfm" -o "$base.$v.png" 2> "$base.$v.log"
            "$A" compare "$base.$v.pfm" "$base.path.pfm" --by "$base.tau_nosun.pfm" --edges 0.01,0.3,1,3,10,30,100,1e30 \
                --heatmap "$base.$v.diff.png" --json > "$base.$v.json"
            "$A" compare "$base.$v.pfm" "$base.path.pfm" --by "$base.order_nosun.pfm" --edges 0.5,1.5,3,6,12,25,50,1000 \
                --json > "$base.$v.order.json"
            # the volume's pixels only (optical depth >= 0.01): the sky and the sun's disk are not the question
            "$A" compare "$base.$v.pfm" "$base.path.pfm" --by "$base.tau_nosun.pfm" --edges 0.01,1e30 \
                --json > "$base.$v.vol.json"
            "$A" compare "$base.$v.pfm" "$cref" --by "$base.cone.pfm" --edges 0,0.5,1.5 --json > "$base.$v.cone.json"
            python3 - "$base.$v.json" "$base.$v.order.json" "$base.$v.vol.json" "$c" "$sun" "$v" "$(secs "$base.$v.log")" \
                "$base.$v.cone.json" \
                >> "$csv" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
o = json.load(open(sys.argv[2]))
v = json.load(open(sys.argv[3]))["bins"][0]
bins = lambda d: [[b["lo"], b["pixels"], b["rel_rmse"], b["rel_bias"]] for b in d["bins"]]
cb = [b for b in bins(json.load(open(sys.argv[8]))) if b[1]]
print("%s,%s,%s,%s,%.5g,%.5g,\"%s\",\"%s\",\"%s\"" % (sys.argv[4], sys.argv[5], sys.argv[6], sys.argv[7], v["rel_rmse"],
      v["rel_bias"], json.dumps(bins(j)), json.dumps(bins(o)), json.dumps(cb)))
PY
        done
    done
done
echo "wrote $csv" >&2
