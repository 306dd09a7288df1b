"""Tables for docs/cycles.md from bench/cycles/run.sh's results.csv and refs.csv.

    python3 bench/cycles/summary.py OUT/results.csv OUT/refs.csv PIXELS [OUT/transmittance.csv]

Errors are over the cloud's pixels (optical depth >= 0.01). "own" compares an image with its
own renderer's high-sample reference; that reference's noise is taken out assuming the two are
independent and the variance falls as 1/samples: e^2 = e_measured^2 N_ref / (N_ref + n).
"common" compares with atmos's reference (for Cycles: noise and any systematic difference).
"""
import csv
import json
import math
import sys


def num(s):
    return float(s) if s not in ("", None) else None


def interp_time(rows, target, key):
    """Seconds at which the error `key` falls to `target`: log-log interpolation between the
    two sweep points around it, or extrapolation (at most 10x in time) from the nearest two.
    Returns (seconds, extrapolated) or None."""
    pts = sorted((r["seconds"], r[key]) for r in rows if r[key] and r[key] > 0 and r["seconds"] > 0)
    if len(pts) < 2:
        return None
    for i in range(len(pts) - 1):
        (t0, e0), (t1, e1) = pts[i], pts[i + 1]
        if e1 <= target <= e0 or i == len(pts) - 2 or (i == 0 and target > e0):
            if e0 == e1:
                return None
            s = math.log(e1 / e0) / math.log(t1 / t0)  # slope of log e against log t
            if s >= 0:
                return None
            t = t0 * math.exp(math.log(target / e0) / s)
            if t > 10 * pts[-1][0] or t < pts[0][0] / 10:
                return None
            return t, not (pts[0][0] <= t <= pts[-1][0])
    return None


def interp_err(rows, t, key):
    pts = sorted((r["seconds"], r[key]) for r in rows if r[key] and r[key] > 0 and r["seconds"] > 0)
    if len(pts) < 2 or t > 10 * pts[-1][0] or t < pts[0][0] / 10:
        return None
    for i in range(len(pts) - 1):
        (t0, e0), (t1, e1) = pts[i], pts[i + 1]
        if t0 <= t <= t1 or i == len(pts) - 2 or (i == 0 and t < t0):
            s = math.log(e1 / e0) / math.log(t1 / t0)
            return e0 * math.exp(s * math.log(t / t0))
    return None


def main():
    res = list(csv.DictReader(open(sys.argv[1])))
    refs = list(csv.DictReader(open(sys.argv[2]))) if len(sys.argv) > 2 else []
    pixels = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    chk = list(csv.DictReader(open(sys.argv[4]))) if len(sys.argv) > 4 else []
    if chk:
        print("Transmittance check (pure absorber before a background of 1; opacity 1 - T over the "
              "cloud's pixels; shift: of the Cycles image against atmos's, pixels):\n")
        print("| variant | voxel shift in Blender | samples | pixels | mean 1 - T (atmos) | rel. RMSE | "
              "rel. bias | shift x | shift y |")
        print("|---|---|---|---|---|---|---|---|---|")
        for r in chk:
            print("| %s | %s | %s | %s | %s | %.4f | %+.3f %% | %s | %s |" % (
                r["variant"], r["voxel_shift"], r["samples"], r["pixels"], r["mean_1_minus_T_atmos"],
                float(r["rel_rmse_1_minus_T"]), 100 * float(r["rel_bias_1_minus_T"]), r["shift_x_px"],
                r["shift_y_px"]))
    variants = []
    for r in res:
        if r["variant"] not in variants:
            variants.append(r["variant"])
    for v in variants:
        rows = [r for r in res if r["variant"] == v]
        ref_n = {r["renderer"]: int(r["spp"]) for r in rows if r["rel_rmse_own"] == "0"}
        print("\n### %s\n" % v)
        print("References: atmos %d spp, Cycles %d samples. Cycles against atmos's reference, "
              "over the cloud's pixels and by optical depth:\n" % (ref_n.get("atmos", 0), ref_n.get("cycles", 0)))
        print("| Cycles image | step rate | samples | rel. RMSE | rel. bias | by optical depth: [from, pixels, rel. RMSE, rel. bias] |")
        print("|---|---|---|---|---|---|")
        for r in refs:
            if r["variant"] != v:
                continue
            bins = json.loads(r["bins"])
            b = "; ".join("%g: %d, %.3f, %+.2f %%" % (x[0], x[1], x[2], 100 * x[3]) for x in bins)
            print("| %s | %s | %s | %.4f | %+.2f %% | %s |" % (r["image"], r["step_rate"], r["spp"],
                  float(r["rel_rmse_vs_atmos_ref"]), 100 * float(r["rel_bias_vs_atmos_ref"]), b))
        sweep = []
        for r in rows:
            if r["rel_rmse_own"] in ("0", ""):
                continue
            n = int(r["spp"])
            d = {"renderer": r["renderer"], "spp": n, "seconds": float(r["seconds"]),
                 "sync": num(r["sync_s"]), "call": num(r["render_call_s"]), "total": num(r["total_s"]),
                 "own_meas": float(r["rel_rmse_own"]), "common": float(r["rel_rmse_common"]),
                 "bias": float(r["rel_bias_common"])}
            N = ref_n.get(r["renderer"])
            d["own"] = d["own_meas"] * math.sqrt(N / (N + n)) if N else d["own_meas"]
            sweep.append(d)
        print("\nTimed runs (seconds: path tracing only; sync: Cycles' scene synchronisation; total: "
              "the whole process, for Cycles Blender's start-up and EXR writing included):\n")
        print("| renderer | samples/pixel | seconds | sync s | total s | paths/s | rel. RMSE, own ref. | "
              "rel. RMSE x sqrt(s) | rel. RMSE, atmos ref. | rel. bias, atmos ref. |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for d in sweep:
            print("| %s | %d | %.2f | %s | %s | %s | %.4f | %.3f | %.4f | %+.2f %% |" % (
                d["renderer"], d["spp"], d["seconds"], "%.2f" % d["sync"] if d["sync"] is not None else "",
                "%.2f" % d["total"] if d["total"] else "",
                "%.3g" % (pixels * d["spp"] / d["seconds"]) if d["seconds"] > 0 and pixels else "", d["own"],
                d["own"] * math.sqrt(d["seconds"]), d["common"], 100 * d["bias"]))
        print("\n(paths/s: camera samples per second, pixels x samples per pixel / seconds.)\n")
        print("| error (rel. RMSE) | atmos: seconds to reach it | Cycles: seconds (own ref.) | Cycles: seconds (atmos ref.) |")
        print("|---|---|---|---|")
        a = [d for d in sweep if d["renderer"] == "atmos"]
        c = [d for d in sweep if d["renderer"] == "cycles"]
        for e in (1.0, 0.5, 0.3):
            ta, tc, tcc = interp_time(a, e, "own"), interp_time(c, e, "own"), interp_time(c, e, "common")
            f = lambda t: ("~%.3g (extrapolated)" if t[1] else "%.3g") % t[0] if t else "-"
            print("| %g | %s | %s | %s |" % (e, f(ta), f(tc), f(tcc)))
        print("\n| equal time | atmos rel. RMSE | Cycles rel. RMSE (own ref.) |")
        print("|---|---|---|")
        for t in (1, 10, 60):
            ea, ec = interp_err(a, t, "own"), interp_err(c, t, "own")
            print("| %g s | %s | %s |" % (t, "%.3g" % ea if ea else "-", "%.3g" % ec if ec else "-"))


main()
