#!/bin/sh
# `atmos sky --model dobashi|spherical --json` (the same keys as Riley's, sensible values) and
# `atmos bench sky-accuracy --quick` (docs/sky-accuracy.md). Checked here (python3):
#  - JSON: the keys of the riley output, finite and >= 0 values, transmittance in (0, 1];
#    the zenith sky bluest at 440 nm with the sun 45 degrees high (Rayleigh's lambda^-4);
#    from 10 km and from 36 000 km straight down the ground is 10 km and 36 000 km away (the
#    observer stands above the ground's point under the origin); --spectral 8 gives 8 values;
#    an unknown model is a usage error (exit 2) naming --model.
#  - the harness: exit 0, its files, every reference finite and >= 0, each relative error
#    recomputed from the CSV's own columns, Riley's flat earth n/a from 36 000 km and dark
#    (-100 %) with the sun 6 degrees below the horizon while the reference's twilight sky is
#    lit, and the same figures with 1 and 2 threads.
set -u
. "$(dirname "$0")/common.inc"
cli=$A

q() {
    name=$1
    shift
    "$cli" sky --json "$@" >"$T/$name.json" 2>"$T/$name.err"
    st=$?
    if [ "$st" -ne 0 ]; then bad "$name: exit $st"; sed 's/^/  stderr: /' "$T/$name.err" >&2; fi
}

q riley --sun-elevation 45 --view-elevation 90 --view-azimuth 0
for m in dobashi spherical; do
    q ${m}_zenith --model $m --sun-elevation 45 --view-elevation 90 --view-azimuth 0
    q ${m}_nadir10 --model $m --sun-elevation 45 --view-elevation -90 --view-azimuth 0 --altitude 10000
    q ${m}_geo --model $m --sun-elevation 30 --view-elevation -90 --view-azimuth 0 --altitude 36000000
    q ${m}_twilight --model $m --sun-elevation -6 --view-elevation 20 --view-azimuth 180
    q ${m}_spectral --model $m --sun-elevation 20 --view-elevation 10 --view-azimuth 90 --spectral 8
done
"$cli" sky --model flat --sun-elevation 30 --view-elevation 10 --view-azimuth 90 >/dev/null 2>"$T/flat.err"
[ $? -eq 2 ] && grep -q -- "--model" "$T/flat.err" && ok "--model flat is a usage error naming --model" ||
    bad "--model flat should exit 2 naming --model"

"$cli" bench sky-accuracy --quick --paths 256 --threads 2 --out "$T/acc" >"$T/acc.txt" 2>"$T/acc.err"
st=$?
[ $st -eq 0 ] && ok "bench sky-accuracy --quick exits 0" || { bad "bench sky-accuracy --quick: exit $st"; cat "$T/acc.err" >&2; }
"$cli" bench sky-accuracy --quick --paths 256 --threads 1 --models riley,spherical --out "$T/acc1" >/dev/null 2>&1 ||
    bad "bench sky-accuracy --threads 1 failed"
"$cli" bench sky-accuracy --quick --models riley,sky >/dev/null 2>"$T/bad.err"
[ $? -eq 2 ] && grep -q -- "--models" "$T/bad.err" && ok "--models sky is a usage error" || bad "--models sky should exit 2"
for f in table.md results.csv summary.csv error_map_riley.png error_map_dobashi.png error_map_spherical.png; do
    [ -s "$T/acc/$f" ] && ok "wrote $f" || bad "missing $f"
done
grep -q '^| ground | +45° |' "$T/acc.txt" && ok "the table has the ground, +45° row" || bad "no ground +45° row in the table"

python3 - "$T" <<'EOF' || fail=1
import csv, json, math, sys
T = sys.argv[1]
failed = 0
def check(cond, msg):
    global failed
    if cond: print("ok: " + msg)
    else:
        print("FAIL: " + msg, file=sys.stderr)
        failed = 1
def reject(c): raise ValueError("non-JSON constant " + c)
def load(name):
    return json.loads(open("%s/%s.json" % (T, name)).read(), parse_constant=reject)

keys = set(load("riley").keys())
for m in ("dobashi", "spherical"):
    for v in ("zenith", "nadir10", "geo", "twilight", "spectral"):
        o = load("%s_%s" % (m, v))
        check(set(o.keys()) == keys, "%s %s: the same keys as riley" % (m, v))
        n = len(o["wavelengths_nm"])
        for k in ("inscatter", "transmittance", "sun", "ground"):
            check(len(o[k]) == n and all(math.isfinite(x) and x >= 0 for x in o[k]), "%s %s: %s finite, >= 0" % (m, v, k))
        check(all(0 < t <= 1 for t in o["transmittance"]), "%s %s: transmittance in (0, 1]" % (m, v))
    z = load(m + "_zenith")
    check(z["inscatter"][2] > z["inscatter"][1] > z["inscatter"][0] > 0, "%s: zenith sky bluest at 440 nm: %r" % (m, z["inscatter"]))
    check(z["distance_m"] is None and z["hits_ground"] is False, "%s: zenith view reaches space" % m)
    for v, d in (("nadir10", 1e4), ("geo", 3.6e7)):
        o = load(m + "_" + v)
        check(o["hits_ground"] is True and abs(o["distance_m"] - d) < 1e-6 * d, "%s %s: ground %g m away: %r" % (m, v, d, o["distance_m"]))
        check(o["ground"][1] > 0, "%s %s: the lit ground is seen" % (m, v))
    check(len(load(m + "_spectral")["wavelengths_nm"]) == 8, "%s --spectral 8: 8 wavelengths" % m)

rows = list(csv.DictReader(open(T + "/acc/results.csv")))
check(len(rows) > 0, "results.csv has rows")
check(all(math.isfinite(float(r["ref_Y"])) and float(r["ref_Y"]) >= 0 for r in rows), "every reference Y finite and >= 0")
# relative errors from the CSV's own columns: (model - ref) / max(ref, 1e-3 * block max)
bmax = {}
for r in rows:
    key = (r["model"], r["altitude_m"], r["sun_elevation_deg"])
    bmax[key] = max(bmax.get(key, 0.0), float(r["ref_Y"]))
errs = 0
for r in rows:
    key = (r["model"], r["altitude_m"], r["sun_elevation_deg"])
    m, ref, e = float(r["model_Y"]), float(r["ref_Y"]), float(r["rel_err_Y"])
    if math.isnan(m):
        continue
    want = (m - ref) / max(ref, 1e-3 * bmax[key])
    errs += abs(want - e) > 1e-4 * max(1.0, abs(want))
check(errs == 0, "rel_err_Y = (model - ref) / max(ref, 1e-3 max) on every row (%d differ)" % errs)
geo = [r for r in rows if r["model"] == "riley" and r["altitude_m"] == "36000000"]
check(len(geo) > 0 and all(math.isnan(float(r["model_Y"])) for r in geo), "riley n/a from 36 000 km")
summ = {(r["model"], r["altitude_m"], r["sun_elevation_deg"]): r for r in csv.DictReader(open(T + "/acc/summary.csv"))}
tw = summ[("riley", "0", "-6")]
check(abs(float(tw["worst_Y"]) + 1) < 1e-9, "riley at the ground, sun -6: worst -100 %% (got %s)" % tw["worst_Y"])
lit = [r for r in rows if r["altitude_m"] == "0" and r["sun_elevation_deg"] == "-6" and r["class"] == "sky"]
check(any(float(r["ref_Y"]) > 0 for r in lit), "the reference's twilight sky is lit at -6")
check(summ[("riley", "36000000", "45")]["views"] == "0", "summary: riley from 36 000 km counts no views")
one = {(r["model"], r["altitude_m"], r["sun_elevation_deg"], r["view_zenith_deg"], r["view_azimuth_from_sun_deg"]): r
       for r in csv.DictReader(open(T + "/acc1/results.csv"))}
same = all(one[k]["ref_Y"] == r["ref_Y"] and one[k]["model_Y"] == r["model_Y"]
           for r in rows if r["model"] in ("riley", "spherical")
           for k in [(r["model"], r["altitude_m"], r["sun_elevation_deg"], r["view_zenith_deg"], r["view_azimuth_from_sun_deg"])])
check(same, "the same figures with 1 and 2 threads")
sys.exit(failed)
EOF
for f in "$T"/acc/*.png; do
    head -c 8 "$f" | od -An -c | grep -q 'P   N   G' && ok "$(basename "$f") is a PNG" || bad "$(basename "$f") is not a PNG"
done
# the look-up tables: listed, written, refused by name
"$cli" sky --model spherical --table list >"$T/tables.txt" 2>&1 && grep -qx transmittance "$T/tables.txt" &&
    grep -qx multiple_scattering "$T/tables.txt" && ok "sky --table list names the spherical tables" ||
    bad "sky --table list: $(cat "$T/tables.txt")"
# the higher orders' 4-D scattering density as an image: 24 x 10 (gamma, psi) nodes across, 16 x 40
# (altitude, sun) nodes down, positive and finite (a PFM's header, then its floats)
"$cli" sky --model spherical --table higher_orders_aerosols -o "$T/j.pfm" >/dev/null 2>&1 &&
    [ "$(sed -n 2p "$T/j.pfm")" = "240 640" ] &&
    python3 -c "
import sys, pfm
i = pfm.read(sys.argv[1]); s = pfm.stats(i.v)
sys.exit(0 if (i.w, i.h, i.c) == (240, 640, 3) and s.nonfinite == 0 and s.min > 0 and s.max > 10 * s.min else 1)
" "$T/j.pfm" && ok "sky --table higher_orders_aerosols writes J_ms's 240 x 640 image, positive and finite" ||
    bad "sky --table higher_orders_aerosols"
"$cli" sky --model dobashi --table sun_attenuation -o "$T/gl.png" >/dev/null 2>&1 &&
    head -c 8 "$T/gl.png" | od -An -c | grep -q 'P   N   G' && ok "sky --table sun_attenuation -o x.png writes a PNG" ||
    bad "sky --table sun_attenuation -o x.png"
"$cli" sky --model spherical --table nope -o "$T/x.exr" >/dev/null 2>"$T/nope.err"
st=$?
[ $st -ne 0 ] && grep -q "transmittance" "$T/nope.err" && [ ! -e "$T/x.exr" ] && ok "an unknown table is refused, naming the known ones" ||
    bad "unknown table: exit $st, $(cat "$T/nope.err")"
exit $fail
