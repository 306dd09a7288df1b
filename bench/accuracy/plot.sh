#!/bin/sh
# Plots of bench/accuracy/run.sh's results: relative bias of each slice variant against the
# path tracer by optical depth and by scattering order (averaged over the cases with the sun
# behind the viewer, and in front of it), and a markdown table of the whole-image figures.
#   bench/accuracy/plot.sh [DIR]   (default docs/accuracy; reads DIR/results.csv)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
DIR=${1:-$here/../../docs/accuracy}
python3 - "$DIR" <<'PY'
import csv, json, math, os, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(d, "results.csv"))))
variants = ["eq25", "eq25_xi0", "eq25_xi4", "eq24", "low_albedo"]
for key, col in (("tau", "tau_bins"), ("order", "order_bins")):
    for sun in ("behind", "front"):
        # per variant and bin: pixel-weighted mean of the relative bias over the cases
        acc = {}
        for r in rows:
            if r["sun"] != sun or r["variant"] not in variants: continue
            for lo, n, rr, rb in json.loads(r[col]):
                if n and rb is not None and rb == rb:
                    a = acc.setdefault((r["variant"], lo), [0.0, 0.0, 0])
                    a[0] += n * rb; a[1] += n * rr; a[2] += n
        with open(os.path.join(d, "%s_%s.dat" % (key, sun)), "w") as f:
            los = sorted({lo for (_, lo) in acc})
            f.write("# %s_lo " % key + " ".join("%s_bias %s_rmse" % (v, v) for v in variants) + "\n")
            for lo in los:
                vals = []
                for v in variants:
                    a = acc.get((v, lo))
                    vals += ["%.5g %.5g" % (a[0] / a[2], a[1] / a[2]) if a else "nan nan"]
                f.write("%g %s\n" % (lo, " ".join(vals)))
with open(os.path.join(d, "table.md"), "w") as f:
    f.write("| case | sun | variant | rel. RMSE | rel. bias | s |\n|---|---|---|---|---|---|\n")
    for r in rows:
        f.write("| %s | %s | %s | %s | %s | %s |\n" % (r["case"], r["sun"], r["variant"],
                r["rel_rmse"] if r["variant"] != "path" else "–", r["bias_rel"] if r["variant"] != "path" else "–", r["seconds"]))
PY
for key in tau order; do
    if [ $key = tau ]; then xl="optical depth along the pixel's ray (bin start)"; else xl="mean scattering order of the light (bin start, path tracer)"; fi
    gnuplot <<GP
set terminal pngcairo size 900,420 font ",10"
set output "$DIR/error_by_$key.png"
set multiplot layout 1,2
set logscale x
set xlabel "$xl"
set ylabel "relative bias vs path tracer"
set yrange [-1:1]
set grid
set key bottom left
set title "sun behind the viewer"
plot for [i=0:4] "$DIR/${key}_behind.dat" using 1:(column(2+2*i)) with linespoints title word("eq25 eq25,xi=0 eq25,xi=0.032 eq24 low-albedo", i+1)
set title "sun in front (behind the cloud)"
plot for [i=0:4] "$DIR/${key}_front.dat" using 1:(column(2+2*i)) with linespoints title word("eq25 eq25,xi=0 eq25,xi=0.032 eq24 low-albedo", i+1)
unset multiplot
GP
done
echo "wrote $DIR/error_by_tau.png $DIR/error_by_order.png $DIR/table.md" >&2
