#!/bin/sh
# atmos render --renderer path finishes on time and says how noisy it is: a render whose
# passes are far longer than its --time-budget (the generated cumulus at density scale 1e6,
# once minutes for a few pixels) stops within the budget and, off a terminal, logs its
# progress; the final report gives the noise over the volume's pixels (mean, median, 90th
# percentile) and atmos bench path --json carries them; absurd voxel sizes are refused.
set -u
A=${ATMOS_CLI:?ATMOS_CLI not set}
T=${ATMOS_TEST_TMP:-/tmp}/cli_path_run.$$
mkdir -p "$T"
export XDG_CACHE_HOME="$T/cache"
fail=0; pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*" >&2; fail=$((fail + 1)); }

# the render's own time (the first report line ends in ", X s rendering"), without the table builds
render_s() { sed -n 's/^atmos render: .*, \([0-9.]*\) s rendering$/\1/p' "$1" | head -n 1; }

# A budget inside a pass: 6 s on passes that would take minutes; stderr is a file, so
# progress comes as log lines (ATMOS_PROGRESS_INTERVAL asks for one every 2 s).
ATMOS_PROGRESS_INTERVAL=2 "$A" render --renderer path --volume generate:cumulus --density-scale 1e6 --width 64 --height 48 --spp 100000 \
    --time-budget 6 --threads 2 --pfm "$T/b.pfm" 2> "$T/b.log" && ok || bad "render with --time-budget 6"
s=$(render_s "$T/b.log")
python3 -c "import sys; sys.exit(0 if 0 < float('$s') < 7.5 else 1)" 2>/dev/null && ok \
    || { bad "--time-budget 6 took ${s:-?} s"; cat "$T/b.log" >&2; }
grep -q "^atmos: render path: [0-9]* %, [0-9.]* s elapsed$" "$T/b.log" && ok || bad "no progress log line off a terminal"
grep -q "path: [0-9]* spp" "$T/b.log" && ok || bad "no sample count reported"

# The noise over the volume's pixels: in the sky the air's many quiet pixels dilute the mean
# over all pixels, the volume's figure is larger.
"$A" render --renderer path --volume generate:cumulus --width 32 --height 24 --spp 8 --threads 2 \
    --pfm "$T/n.pfm" 2> "$T/n.log" && ok || bad "noise render"
line=$(grep "over the volume's" "$T/n.log")
[ -n "$line" ] && ok || { bad "no noise figure over the volume's pixels"; cat "$T/n.log" >&2; }
echo "$line" | python3 -c "
import re, sys
l = sys.stdin.read()
m = re.search(r\"volume's (\d+) pixels: mean ([\d.]+) %, median ([\d.]+) %, 90th percentile ([\d.]+) % \(over all pixels: mean ([\d.]+) %\)\", l)
n, mean, med, p90, allp = int(m.group(1)), *map(float, m.group(2, 3, 4, 5))
assert 0 < n < 32 * 24, n
assert med <= p90 and mean > allp, (mean, med, p90, allp)
" && ok || bad "noise figures: $line"

# atmos bench path --json: the same figures
"$A" bench path --size 16 --spp 2 --threads 2 --json > "$T/bench.json" 2> /dev/null && ok || bad "bench path --json"
python3 - "$T/bench.json" <<'PY' && ok || bad "bench path --json lacks the volume's noise figures"
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
assert len(rows) == 2
for r in rows:
    for k in ("volume_pixels", "volume_rel_se_mean", "volume_rel_se_median", "volume_rel_se_p90", "cut_paths"):
        assert k in r, k
    assert r["volume_pixels"] > 0 and r["volume_rel_se_median"] <= r["volume_rel_se_p90"]
PY

# A single path that outlasts the budget (a camera under a rain shaft of optical depth in the
# millions, paths of thousands of events each of long walks; seconds per path) is abandoned at
# the deadline: the render ends near its budget, not after its longest path (15 s before).
cat > "$T/long.json" <<'JSON'
{"image": {"width": 16, "height": 12, "samples_per_pixel": 1},
 "camera": {"type": "equirect", "position_m": [-5953.6219744415648, 13.710115345816162, 5026.646176666618]},
 "sun": {"elevation_deg": -14.585043855712811, "azimuth_deg": 207.4115460471096},
 "atmosphere": {"kind": "riley", "scale_height_m": 67257.401662335935, "beta_sl_550_per_m": 1.2017748696823234e-09,
                "ground_albedo": 0.22123431345868116, "sun_diameter_deg": 0.00040070294075110041,
                "thickness_m": 102292.23768252868},
 "background": "black",
 "wavelengths": {"mode": "spectral", "samples": 4},
 "volume": {"generate": "rain_shaft", "density_scale": 71460663.272414625, "scale": 18.75186476761688, "seed": 29,
            "voxel_size_m": 795.19312773420427, "position_m": [518.56998484100177, 1013.7912071135919, -2800.3390559747882]},
 "particles": {"rain": {"kind": "analytic", "lobes": [{"type": "hg", "g": 0.88, "weight": 1}], "sigma_ext_m2": 6e-6}},
 "renderer": "path", "path": {"spp": 2, "time_budget_s": 0.5, "seed": 18}}
JSON
"$A" render "$T/long.json" --threads 2 --pfm "$T/long.pfm" 2> "$T/long.log" && ok || bad "render of a path longer than its budget"
s=$(render_s "$T/long.log")
python3 -c "import sys; sys.exit(0 if 0 < float('$s') < 3.0 else 1)" 2>/dev/null && ok \
    || { bad "a 0.5 s budget with paths longer than it took ${s:-?} s"; cat "$T/long.log" >&2; }

# Voxel sizes outside 1e-6..1e5 m are refused, naming the voxel size (a raw sidecar here).
printf '\000\000\200\077' > "$T/v.raw"
for vs in 1e20 1e-9; do
    printf '{"file": "v.raw", "dims": [1, 1, 1], "voxel_size_m": %s}\n' "$vs" > "$T/v.json"
    "$A" volume info "$T/v.json" > /dev/null 2> "$T/v.log"
    rc=$?
    [ $rc -eq 1 ] && grep -q "voxel size" "$T/v.log" && ok || bad "voxel size $vs: exit $rc, $(cat "$T/v.log")"
done
printf '{"file": "v.raw", "dims": [1, 1, 1], "voxel_size_m": 1e5}\n' > "$T/v.json"
"$A" volume info "$T/v.json" > /dev/null 2>&1 && ok || bad "voxel size 1e5 refused"

rm -rf "$T"
echo "path_run: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
