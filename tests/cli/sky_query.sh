#!/bin/sh
# `atmos sky` end to end, checked against closed forms computed here (python3):
#  - Riley et al. 2004, Table 3: beta_sl = 5.8e-6, 1.35e-5, 3.31e-5 m^-1 at 680, 550,
#    440 nm; scale height 1/gamma = 8000 m (Eq. 9-10). Spectral mode: beta_sl =
#    1.35e-5 (550/lambda)^4 (docs/models.md).
#  - Transmittance of an exponential atmosphere (Eq. 11 from its definition): optical
#    depth from altitude y along p (p_y != 0) over K is beta_sl e^(-gamma y) (1 -
#    e^(-gamma p_y K)) / (gamma p_y); to space at the zenith from sea level this is
#    beta_sl / gamma; horizontally at sea level, beta_sl K.
#  - Sunlight (Eq. 12): E0 exp(-beta_sl / (gamma sin(sun elevation))) spread over the
#    0.5 deg disk's solid angle 2 pi (1 - cos 0.25 deg); E0 = ASTM G173-03 ETR averaged
#    over +-5 nm (data/astm_g173_solar_spectrum.csv, integrated here).
#  - Single scattering (Eq. 8) by direct numerical quadrature, for the zenith view.
#  - Flat-earth geometry: from 10 km looking 30 deg down, the ground is 10 km / sin 30 = 20 km away.
set -u

cli=${ATMOS_CLI:?ATMOS_CLI must name the atmos binary}
src=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR must name the source tree}
T=${ATMOS_TEST_TMP:-/tmp}/sky_query.$$
rm -rf "$T"
mkdir -p "$T" || exit 1
trap 'rm -rf "$T"' EXIT
fail=0

ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }

# q NAME ARGS... : atmos sky --json ARGS > $T/NAME.json; must exit 0 with empty stderr.
q() {
    name=$1
    shift
    "$cli" sky --json "$@" >"$T/$name.json" 2>"$T/$name.err"
    st=$?
    if [ "$st" -ne 0 ]; then bad "$name: exit $st"; sed 's/^/  stderr: /' "$T/$name.err" >&2; fi
}

q zenith45 --sun-elevation 45 --view-elevation 90 --view-azimuth 0
q spectral8 --sun-elevation 45 --view-elevation 90 --view-azimuth 0 --spectral 8
q horiz1000 --sun-elevation 30 --view-elevation 0 --view-azimuth 70 --distance 1000
q down10k --sun-elevation 45 --view-elevation -30 --view-azimuth 200 --altitude 10000
q sun5 --sun-elevation 5 --view-elevation 90 --view-azimuth 0
q sun20 --sun-elevation 20 --view-elevation 90 --view-azimuth 0
q sun60 --sun-elevation 60 --view-elevation 90 --view-azimuth 0
# Degenerate but valid geometry: level views, the view along the sun, the sun on the horizon.
q level --sun-elevation 30 --view-elevation 0 --view-azimuth 0
q level_high --sun-elevation 30 --view-elevation 0 --view-azimuth 90 --altitude 5000
q at_sun --sun-elevation 30 --sun-azimuth 120 --view-elevation 30 --view-azimuth 120
q at_sun_level --sun-elevation 0 --sun-azimuth 120 --view-elevation 0 --view-azimuth 120
q at_sun_spectral --sun-elevation 30 --sun-azimuth 120 --view-elevation 30 --view-azimuth 120 --spectral 16
q sun_horizon --sun-elevation 0 --view-elevation 10 --view-azimuth 0
q sun_below --sun-elevation -10 --view-elevation 10 --view-azimuth 0
q nadir --sun-elevation 45 --view-elevation -90 --view-azimuth 0 --altitude 3000
q nadir_ground --sun-elevation 45 --view-elevation -90 --view-azimuth 0
q tiny_up --sun-elevation 45 --view-elevation 1e-9 --view-azimuth 0
q tiny_down --sun-elevation 45 --view-elevation -1e-9 --view-azimuth 0 --altitude 100
# The homogeneous layer (docs/models.md): 1 km of uniform air seen 10 deg up from the ground.
q layer --sun-elevation 30 --view-elevation 10 --view-azimuth 90 --atmosphere homogeneous --thickness 1000
"$cli" sky --sun-elevation 30 --view-elevation 10 --view-azimuth 90 --atmosphere fog >/dev/null 2>&1
[ $? -eq 2 ] && ok "--atmosphere fog is a usage error" || bad "--atmosphere fog should exit 2"

python3 - "$T" "$src" <<'EOF' || fail=1
import csv, json, math, sys
T, src = sys.argv[1], sys.argv[2]
failed = 0
def check(cond, msg):
    global failed
    if cond: print("ok: " + msg)
    else:
        print("FAIL: " + msg, file=sys.stderr)
        failed = 1
def rel(a, b): return abs(a - b) / abs(b)
def reject(c): raise ValueError("non-JSON constant " + c)
def load(name):
    text = open("%s/%s.json" % (T, name)).read()
    try:
        obj = json.loads(text, parse_constant=reject)  # NaN / Infinity are not JSON
    except ValueError as e:
        check(False, "%s: output is not strict JSON (%s): %r" % (name, e, text[:200]))
        return None
    check(isinstance(obj, dict), name + ": one JSON object")
    for k in ("wavelengths_nm", "inscatter", "transmittance", "sun"):
        check(k in obj, "%s: has key %s" % (name, k))
    n = len(obj.get("wavelengths_nm", []))
    for k in ("inscatter", "transmittance", "sun", "ground"):
        v = obj.get(k, [])
        check(len(v) == n, "%s: %s has %d values" % (name, k, n))
        check(all(isinstance(x, (int, float)) and math.isfinite(x) and x >= 0 for x in v),
              "%s: %s finite and >= 0: %r" % (name, k, v))
    tr = obj.get("transmittance", [])
    check(all(x <= 1 for x in tr), "%s: transmittance <= 1" % name)
    return obj

names = ["zenith45", "spectral8", "horiz1000", "down10k", "sun5", "sun20", "sun60", "level", "level_high",
         "at_sun", "at_sun_level", "at_sun_spectral", "sun_horizon", "sun_below", "nadir", "nadir_ground",
         "tiny_up", "tiny_down", "layer"]
R = {n: load(n) for n in names}
if any(v is None for v in R.values()): sys.exit(1)

BETA = [5.8e-6, 1.35e-5, 3.31e-5]  # Riley Table 3
H = 8000.0                         # 1/gamma
OMEGA = 2 * math.pi * (1 - math.cos(math.radians(0.25)))

z = R["zenith45"]
check(z["wavelengths_nm"] == [680, 550, 440], "rgb wavelengths are [680, 550, 440]")
for c in range(3):
    check(rel(z["transmittance"][c], math.exp(-BETA[c] * H)) < 1e-6,
          "zenith transmittance %d nm = exp(-beta_sl*8000): %r vs %r" % (z["wavelengths_nm"][c], z["transmittance"][c], math.exp(-BETA[c] * H)))
check(z["distance_m"] is None and z["hits_ground"] is False, "zenith: path to space")
check(z["inscatter"][2] > z["inscatter"][1] > z["inscatter"][0], "zenith sky is bluest at 440 nm: %r" % z["inscatter"])

s8 = R["spectral8"]
wl = s8["wavelengths_nm"]
check(len(wl) == 8 and all(380 <= w <= 780 for w in wl), "--spectral 8: 8 wavelengths in 380-780: %r" % wl)
check(all(a < b for a, b in zip(wl, wl[1:])), "--spectral 8: increasing")
for w, t in zip(wl, s8["transmittance"]):
    want = math.exp(-1.35e-5 * (550.0 / w) ** 4 * H)
    check(rel(t, want) < 1e-6, "spectral zenith transmittance at %g nm: %r vs lambda^-4 law %r" % (w, t, want))

# The layer: transmittance exp(-beta L) over the L = 1000 / sin 10 deg inside it; the sun's
# light at the ground exp(-beta 1000 / sin 30 deg); in-scatter P E0 beta int_0^L e^{-beta c s} ds
# with c = 1 - sin 10 / sin 30, E0 from the sun's radiance and transmittance.
ly = R["layer"]
L = 1000 / math.sin(math.radians(10))
for c in range(3):
    check(rel(ly["transmittance"][c], math.exp(-BETA[c] * L)) < 1e-9,
          "layer transmittance %d nm = exp(-beta * 1000 / sin 10)" % ly["wavelengths_nm"][c])
    E0 = ly["sun"][c] * OMEGA / math.exp(-BETA[c] * 1000 / 0.5)
    mu = math.cos(math.radians(30)) * math.cos(math.radians(10)) * math.cos(math.radians(90 - 180)) + 0.5 * math.sin(math.radians(10))
    P = 3 / (16 * math.pi) * (1 + mu * mu)
    cc = 1 - math.sin(math.radians(10)) / 0.5
    want = P * E0 * BETA[c] * math.exp(-BETA[c] * 1000 / 0.5) * (1 - math.exp(-BETA[c] * cc * L)) / (BETA[c] * cc)
    check(rel(ly["inscatter"][c], want) < 1e-6, "layer in-scatter %d nm: %r vs closed form %r" % (ly["wavelengths_nm"][c], ly["inscatter"][c], want))

h = R["horiz1000"]
check(h["distance_m"] == 1000 and h["hits_ground"] is False, "--distance 1000: path of 1000 m, not ground")
for c in range(3):
    check(rel(h["transmittance"][c], math.exp(-BETA[c] * 1000)) < 1e-6,
          "horizontal 1 km transmittance %d nm = exp(-beta_sl*1000)" % h["wavelengths_nm"][c])

d = R["down10k"]
check(d["hits_ground"] is True, "10 km, -30 deg: hits the ground")
check(d["distance_m"] is not None and abs(d["distance_m"] - 20000) < 1e-6 * 20000, "10 km, -30 deg: distance 20000 m (%r)" % d["distance_m"])
for c in range(3):
    tau = BETA[c] * H * (1 - math.exp(-10000 / H)) / 0.5
    check(rel(d["transmittance"][c], math.exp(-tau)) < 1e-6, "slant transmittance to the ground %d nm" % d["wavelengths_nm"][c])
check(all(g > 0 for g in d["ground"]), "lit ground seen: %r" % d["ground"])

# The sun's disk radiance, from the ASTM table integrated here.
rows = [r for r in csv.reader(open(src + "/data/astm_g173_solar_spectrum.csv"))][2:]
swl = [float(r[0]) for r in rows]
se = [float(r[1]) for r in rows]
def etr_mean(lo, hi):
    s = 0.0
    for i in range(len(swl) - 1):
        if swl[i] >= lo and swl[i + 1] <= hi: s += 0.5 * (se[i] + se[i + 1]) * (swl[i + 1] - swl[i])
    return s / (hi - lo)
E0 = [etr_mean(l - 5, l + 5) for l in (680, 550, 440)]
for name, el in (("sun5", 5), ("sun20", 20), ("sun60", 60), ("zenith45", 45)):
    for c in range(3):
        want = E0[c] * math.exp(-BETA[c] * H / math.sin(math.radians(el))) / OMEGA
        check(rel(R[name]["sun"][c], want) < 1e-3, "%s: sun radiance %d nm %r vs E0 exp(-tau)/Omega %r" % (name, (680, 550, 440)[c], R[name]["sun"][c], want))
for c in range(3):
    check(R["sun5"]["sun"][c] < R["sun20"]["sun"][c] < R["sun60"]["sun"][c], "sun radiance grows with elevation, channel %d" % c)
rb = [R[n]["sun"][0] / R[n]["sun"][2] for n in ("sun5", "sun20", "sun60")]
check(rb[0] > rb[1] > rb[2], "sun red/blue falls as the sun rises: %r" % rb)

# Single scattering at the zenith (Eq. 8), by quadrature in u = exp(-gamma t):
# L = P(theta) E0 (beta/gamma) int_0^1 exp(-beta/gamma (1-u) - beta u/(gamma l_y)) du.
ly = math.sin(math.radians(45))
P = 3 / (16 * math.pi) * (1 + ly * ly)  # Riley Eq. 1, cos(theta) = l_y for a zenith view
for c in range(3):
    b, N = BETA[c], 20000
    s = sum(math.exp(-b * H * (1 - (i + 0.5) / N) - b * H * ((i + 0.5) / N) / ly) for i in range(N)) / N
    want = P * E0[c] * b * H * s
    check(rel(z["inscatter"][c], want) < 1e-4, "zenith in-scatter %d nm = quadrature of Eq. 8: %r vs %r" % ((680, 550, 440)[c], z["inscatter"][c], want))

# Degenerate views: finite (checked in load) and sensible.
check(R["level"]["distance_m"] is None and all(x == 0 for x in R["level"]["transmittance"]),
      "level view from the ground: endless path, transmittance 0: %r" % R["level"]["transmittance"])
check(all(x > 0 for x in R["level"]["inscatter"]), "level view: positive in-scatter")
check(all(x > 0 for x in R["level_high"]["inscatter"]), "level view at 5 km: positive in-scatter")
check(all(x > 0 for x in R["at_sun"]["inscatter"]) and all(x > 0 for x in R["at_sun_spectral"]["inscatter"]),
      "view == sun direction: positive in-scatter")
check(all(x == 0 for x in R["sun_below"]["inscatter"]) and all(x == 0 for x in R["sun_below"]["sun"]),
      "sun below the horizon (flat earth): no light")
check(all(x == 0 for x in R["sun_horizon"]["sun"]), "sun on the horizon: no direct sun")
check(R["nadir"]["hits_ground"] is True and abs(R["nadir"]["distance_m"] - 3000) < 1e-6, "nadir from 3 km: ground at 3000 m")
for c in range(3):
    up, dn = R["tiny_up"]["inscatter"][c], R["zenith45"]["inscatter"][c]
    check(up > dn, "near-horizontal view brighter than the zenith, channel %d" % c)
sys.exit(failed)
EOF

# Bad input: exit 2 with a message naming the option, nothing on stdout.
usage_case() {
    name=$1 opt=$2
    shift 2
    "$cli" sky "$@" >"$T/out" 2>"$T/err"
    st=$?
    if [ "$st" -eq 2 ]; then ok "$name (exit 2)"; else bad "$name: exit $st, expected 2"; fi
    if grep -qF -- "$opt" "$T/err"; then ok "$name: message names $opt"; else bad "$name: message lacks $opt: $(cat "$T/err")"; fi
    if [ -s "$T/out" ]; then bad "$name: wrote to stdout"; fi
}
usage_case "sun elevation 100" --sun-elevation --sun-elevation 100 --view-elevation 10 --view-azimuth 0
usage_case "missing --view-azimuth" --view-azimuth --sun-elevation 10 --view-elevation 10
usage_case "missing --sun-elevation" --sun-elevation --view-elevation 10 --view-azimuth 0
usage_case "altitude -5" --altitude --sun-elevation 10 --view-elevation 10 --view-azimuth 0 --altitude -5
usage_case "distance 0" --distance --sun-elevation 10 --view-elevation 10 --view-azimuth 0 --distance 0
usage_case "view elevation nan" --view-elevation --sun-elevation 10 --view-elevation nan --view-azimuth 0
usage_case "view azimuth inf" --view-azimuth --sun-elevation 10 --view-elevation 10 --view-azimuth inf
usage_case "spectral 0" --spectral --sun-elevation 10 --view-elevation 10 --view-azimuth 0 --spectral 0
usage_case "albedo 2" --albedo --sun-elevation 10 --view-elevation 10 --view-azimuth 0 --albedo 2

exit $fail
