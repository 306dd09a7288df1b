#!/bin/sh
# atmos bench slice (docs/performance.md, "The slice renderer"): a small generated cumulus from
# its file alone (--file-only: the generated storm left out), --json. Checked (python3): one
# object, for the file, with the density scale asked for and the discrete-ordinates field; the
# sun-moving frames warm-started by default (warm_field 1) take fewer of the field's sweeps than
# the plan's first, cold frame, and with --cold-field (warm_field 0) as many as it; without
# --density-scale a file's values are taken as 1e8 m^-3 a unit (the Disney cloud's scenes);
# --file-only without --file is a usage error. --field-ratio: one line, the field's frames and
# none's in turns, both CPU times positive, the ratio their quotient and the frames' median ratio
# finite; with --no-diffuse a usage error.
. "$(dirname "$0")/common.inc"

"$A" volume generate cumulus -o "$T/cu.json" --voxel-size 100 >/dev/null || bad "volume generate"
run() { # OUT ARGS...: the bench on the cumulus, its JSON into OUT
    out=$1
    shift
    "$A" bench slice --file "$T/cu.json" --file-only --size 32 --repeat 1 --threads 2 --json "$@" >"$out" 2>"$T/err.txt"
    st=$?
    [ $st -eq 0 ] && ok "bench slice $* exits 0" || { bad "bench slice $*: exit $st"; cat "$T/err.txt" >&2; }
}
run "$T/warm.json" --density-scale 1
run "$T/cold.json" --density-scale 1 --cold-field
run "$T/default.json" --no-diffuse
python3 - "$T/warm.json" "$T/cold.json" "$T/default.json" <<'PY' && ok "bench slice figures" || bad "bench slice figures"
import json, math, sys
def one(path):
    rows = [json.loads(l) for l in open(path) if l.strip()]
    assert len(rows) == 1, rows  # the storm left out
    r = rows[0]
    assert r["bench"] == "slice" and r["case"] == "cu.json" and r["size"] == 32, r
    for k in ("fps_camera_moving", "fps_sun_moving", "cpu_ms_camera_moving", "cpu_ms_sun_moving", "field_ms"):
        assert math.isfinite(r[k]) and r[k] >= 0, (k, r)
    return r
warm, cold, default = (one(p) for p in sys.argv[1:])
assert warm["density_scale"] == 1 and warm["warm_field"] == 1 and warm["field"] == "do", warm
assert cold["density_scale"] == 1 and cold["warm_field"] == 0, cold
assert 0 < warm["field_sweeps"] < warm["field_cold_sweeps"], warm
assert cold["field_sweeps"] == cold["field_cold_sweeps"] > 0, cold
assert default["density_scale"] == 1e8 and default["field"] == "none" and default["field_sweeps"] == 0, default
PY
run "$T/ratio.json" --density-scale 1e7 --field-ratio
python3 - "$T/ratio.json" <<'PY' && ok "bench slice --field-ratio figures" || bad "bench slice --field-ratio figures"
import json, math, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
assert len(rows) == 1, rows
r = rows[0]
assert r["bench"] == "slice_field_ratio" and r["case"] == "cu.json" and r["field"] == "do", r
assert r["frames"] == 8 and r["warm_field"] == 1 and r["density_scale"] == 1e7, r
assert r["cpu_ms_field"] > 0 and r["cpu_ms_none"] > 0, r
assert abs(r["ratio"] - r["cpu_ms_field"] / r["cpu_ms_none"]) < 1e-3 * r["ratio"], r
assert math.isfinite(r["ratio_median"]) and r["ratio_median"] > 0, r
PY
"$A" bench slice --file "$T/cu.json" --field-ratio --no-diffuse >/dev/null 2>"$T/bad.err"
[ $? -eq 2 ] && grep -q -- "--field-ratio" "$T/bad.err" && ok "--field-ratio with --no-diffuse is a usage error" ||
    bad "--field-ratio with --no-diffuse should exit 2"
"$A" bench slice --file-only >/dev/null 2>"$T/bad.err"
[ $? -eq 2 ] && grep -q -- "--file" "$T/bad.err" && ok "--file-only without --file is a usage error" ||
    bad "--file-only without --file should exit 2"
exit $fail
