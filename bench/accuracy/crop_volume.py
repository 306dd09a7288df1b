#!/usr/bin/env python3
"""The crop of docs/lightfield.md's diagnosis of the simulated cumulus ("The cells' medium in a
textured cloud", "Where the crop's 30 % goes"): the simulated volume's densest 48 x 96 x 48 voxels
in view, cut from the output of

    atmos simulate cumulus_field -o field.json --minutes 20 --grid 64 --seed 1 --refine 3 --detail 0.5

(the volume of scenes/simulated_cumulus.json) at voxels x 8..55, z 40..87, all heights, and
optionally box-smoothed: each pass a 3-voxel mean along x, then y, then z, the voxels outside the
crop counted as 0 (--passes 1: "smoothed once", --passes 2: "smoothed over about 5 voxels").
--scale sets the fields' scale in the description (0.1: "density x 0.1").

    python3 bench/accuracy/crop_volume.py field.json CROP            # CROP.json, CROP.cloud.raw, ...
    python3 bench/accuracy/crop_volume.py field.json CROP_S --passes 2
    python3 bench/accuracy/crop_volume.py field.json CROP_T --scale 0.1
"""
import argparse
import array
import json
import os


def read_field(desc_dir, field):
    a = array.array("f")
    with open(os.path.join(desc_dir, field["file"]), "rb") as f:
        a.frombytes(f.read())
    return a


def crop(a, dims, x0, z0, n):
    nx, ny, _ = dims
    out = array.array("f")
    for z in range(z0, z0 + n[2]):
        for y in range(n[1]):
            b = (z * ny + y) * nx + x0
            out.extend(a[b:b + n[0]])
    return out


def box_pass(v, n):
    """One 3-voxel mean along each axis in turn, outside the crop 0."""
    strides = (1, n[0], n[0] * n[1])
    for axis in range(3):
        out = array.array("f", bytes(4 * len(v)))
        s = strides[axis]
        for i in range(len(v)):
            c = (i // s) % n[axis]
            t = v[i]
            if c > 0:
                t += v[i - s]
            if c < n[axis] - 1:
                t += v[i + s]
            out[i] = t / 3.0
        v = out
    return v


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("field", help="atmos simulate's volume description (field.json)")
    ap.add_argument("name", help="output NAME: NAME.json and NAME.<field>.raw")
    ap.add_argument("--x0", type=int, default=8)
    ap.add_argument("--z0", type=int, default=40)
    ap.add_argument("--size", type=int, nargs=3, default=[48, 96, 48])
    ap.add_argument("--passes", type=int, default=0)
    ap.add_argument("--scale", type=float, default=1.0)
    args = ap.parse_args()
    with open(args.field) as f:
        desc = json.load(f)
    dims, vox = desc["dims"], desc["voxel_size_m"]
    n = args.size
    fields = []
    for field in desc["fields"]:
        v = crop(read_field(os.path.dirname(os.path.abspath(args.field)), field), dims, args.x0, args.z0, n)
        for _ in range(args.passes):
            v = box_pass(v, n)
        raw = "%s.%s.raw" % (os.path.basename(args.name), field["name"])
        with open(os.path.join(os.path.dirname(os.path.abspath(args.name)), raw), "wb") as f:
            v.tofile(f)
        fields.append({"name": field["name"], "particle": field["particle"], "file": raw,
                       "scale": field.get("scale", 1.0) * args.scale})
    o = desc["origin_m"]
    out = {"dims": n, "voxel_size_m": vox, "origin_m": [o[0] + args.x0 * vox, o[1], o[2] + args.z0 * vox],
           "periodic": False, "fields": fields}
    with open(args.name + ".json", "w") as f:
        json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
