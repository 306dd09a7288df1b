#!/bin/sh
# atmos bench slice --aerial (docs/performance.md, "Aerial perspective"): a small generated
# cumulus under Riley's sky and the spherical one, --json. Checked (python3): one object per
# model and motion, finite figures, 0 <= aerial_share <= atmosphere_share <= 1 and the shares
# equal to the printed times' ratios, no sunlight work while only the camera moves and some
# when the sun moves, Riley's frame equal to the per-pixel one but for the passes' rounding
# (< 1e-5), the spherical sky's through its aerial-perspective volume within 1 % of the
# per-pixel air (and not identical to it: the volume is in use); an unknown model is a
# usage error.
. "$(dirname "$0")/common.inc"

"$A" volume generate cumulus -o "$T/cu.json" --voxel-size 100 >/dev/null || bad "volume generate"
"$A" bench slice --aerial --file "$T/cu.json" --density-scale 1 --size 48 --repeat 1 --threads 2 --json \
    >"$T/out.json" 2>"$T/err.txt"
st=$?
[ $st -eq 0 ] && ok "bench slice --aerial exits 0" || { bad "bench slice --aerial: exit $st"; cat "$T/err.txt" >&2; }
python3 - "$T/out.json" <<'PY' && ok "bench slice --aerial figures" || bad "bench slice --aerial figures"
import json, math, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
assert sorted((r["model"], r["motion"]) for r in rows) == [("riley", "camera"), ("riley", "sun"),
                                                          ("spherical", "camera"), ("spherical", "sun")], rows
for r in rows:
    assert r["bench"] == "slice" and r["case"] == "aerial" and r["size"] == 48 and r["frames"] == 8, r
    for k in ("ms_per_frame", "sky_ms", "aerial_ms", "sunlight_ms", "aerial_share", "atmosphere_share",
              "frame_rms_rel", "frame_max_rel"):
        assert math.isfinite(r[k]) and r[k] >= 0, (k, r)
    assert r["ms_per_frame"] > 0
    assert r["aerial_share"] <= r["atmosphere_share"] <= 1.0 + 1e-9, r
    f = r["ms_per_frame"]
    assert abs(r["aerial_share"] - (r["aerial_ms"] + r["sunlight_ms"]) / f) < 2e-3, r
    assert abs(r["atmosphere_share"] - (r["sky_ms"] + r["aerial_ms"] + r["sunlight_ms"]) / f) < 2e-3, r
    if r["motion"] == "camera":
        assert r["sunlight_ms"] == 0, r
    else:
        assert r["sunlight_ms"] > 0, r
    assert r["frame_rms_rel"] <= r["frame_max_rel"], r
    if r["model"] == "riley":
        assert r["frame_max_rel"] < 1e-5, r
    else:
        assert 0 < r["frame_max_rel"] < 1e-2, r
PY
"$A" bench slice --aerial --models riley,sky >/dev/null 2>"$T/bad.err"
[ $? -eq 2 ] && grep -q -- "--models" "$T/bad.err" && ok "--models sky is a usage error naming --models" ||
    bad "--models sky should exit 2 naming --models"
exit $fail
