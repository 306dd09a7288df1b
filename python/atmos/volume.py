"""Volumes: from NumPy arrays and files, back to NumPy arrays."""
import os
import weakref

import numpy as np

from atmos._core import Owned, check, context, ffi, lib, number


def _text(where: str, value) -> bytes:
    """A name or path for the library: a str (or path), without NUL (C would stop there)."""
    text = os.fspath(value) if isinstance(value, os.PathLike) else value
    if not isinstance(text, str):
        raise TypeError(f"atmos: {where}: expected a string, got {type(value).__name__} {value!r}")
    if "\0" in text:
        raise ValueError(f"atmos: {where}: {text!r} holds a NUL character")
    return text.encode()


class Volume(Owned):
    """A volume of number densities (m^-3), one or more fields each with its particle type.

    Arrays are indexed ``[z, y, x]`` (C order, x fastest, as the library stores them); voxels
    are cubes of ``voxel_size_m`` with the corner of voxel (0, 0, 0) at ``origin_m`` (world
    frame: x east, y up, z south; metres). ``close()`` (or ``with``) frees it at once, refused
    while a plan that draws it is open."""

    def __init__(self, ptr):
        self._ptr = ffi.gc(ptr, lib.atmos_volume_destroy)
        self._plans = weakref.WeakSet()  # the plans drawing it (atmos.Plan(scene, volume=...))

    def close(self) -> None:
        if any(p._ptr is not None for p in self._plans):
            raise ValueError("atmos.Volume.close: a plan still draws this volume: close the plan first")
        Owned.close(self)

    def _live(self):
        if self._ptr is None:
            raise ValueError("atmos.Volume: the volume was closed")
        return self._ptr

    @classmethod
    def from_array(cls, fields, voxel_size_m: float, origin_m=(0.0, 0.0, 0.0)) -> "Volume":
        """fields: one array (a "cloud" field of cloud droplets) or a dict {name: array} or
        {name: (array, particle)}, all of one shape (nz, ny, nx); values finite and >= 0.
        The library copies the values (zeros allocate nothing)."""
        if not isinstance(fields, dict):
            fields = {"cloud": fields}
        arrays = {}
        for name, v in fields.items():
            arr, particle = v if isinstance(v, tuple) else (v, name)
            arrays[name] = (np.ascontiguousarray(arr, dtype=np.float32), particle)
        shapes = {a.shape for a, _ in arrays.values()}
        if len(shapes) != 1 or len(next(iter(shapes))) != 3:
            raise ValueError(f"atmos.Volume.from_array: fields must be 3-D arrays of one shape, got {sorted(shapes)}")
        nz, ny, nx = next(iter(shapes))
        ctx = context()
        desc = ffi.new("atmos_volume_desc *")
        desc.dims = [nx, ny, nz]
        desc.voxel_size_m = number("Volume.from_array: voxel_size_m", voxel_size_m)
        if isinstance(origin_m, (str, bytes)) or not hasattr(origin_m, "__len__") or len(origin_m) != 3:
            raise TypeError(f"atmos: Volume.from_array: origin_m: expected 3 numbers, got {origin_m!r}")
        desc.origin_m = [number(f"Volume.from_array: origin_m[{i}]", v) for i, v in enumerate(origin_m)]
        p = ffi.new("atmos_volume **")
        check(lib.atmos_volume_create(ctx, desc, p), ctx)
        vol = cls(p[0])
        for name, (arr, particle) in arrays.items():
            idx = ffi.new("int *")
            check(lib.atmos_volume_add_field(ctx, vol._ptr, _text("Volume.from_array: a field's name", name),
                                             _text(f"Volume.from_array: field {name!r}'s particle", particle), idx), ctx)
            data = ffi.from_buffer("float[]", arr)
            check(lib.atmos_volume_set_dense(ctx, vol._ptr, idx[0], [0, 0, 0], [nx, ny, nz], data, 1.0), ctx)
        check(lib.atmos_volume_finalize(ctx, vol._ptr), ctx)
        return vol

    @classmethod
    def load(cls, path) -> "Volume":
        """Reads .vdb, .nvdb, WRF/CM1 .nc or raw .json with the readers' defaults."""
        ctx = context()
        p = ffi.new("atmos_volume **")
        check(lib.atmos_volume_load(ctx, _text("Volume.load: path", path), ffi.NULL, p), ctx)
        return cls(p[0])

    @property
    def fields(self) -> dict:
        """{name: particle type} of every field."""
        ptr = self._live()
        n = lib.atmos_volume_field_count(ptr)
        return {ffi.string(lib.atmos_volume_field_name(ptr, i)).decode():
                ffi.string(lib.atmos_volume_field_particle(ptr, i)).decode() for i in range(n)}

    @property
    def shape(self):
        d = lib.atmos_volume_get_desc(self._live())
        return (d.dims[2], d.dims[1], d.dims[0])

    @property
    def voxel_size_m(self) -> float:
        return lib.atmos_volume_get_desc(self._live()).voxel_size_m

    @property
    def origin_m(self):
        return tuple(lib.atmos_volume_get_desc(self._live()).origin_m)

    def to_array(self, field: str | int = 0) -> np.ndarray:
        """A field's densities at the voxel centres as a new (nz, ny, nx) float32 array."""
        names = list(self.fields)
        if isinstance(field, bool) or not isinstance(field, (str, int, np.integer)):
            raise TypeError(f"atmos: Volume.to_array: field: expected a name or an index, got {type(field).__name__} {field!r}")
        i = names.index(field) if isinstance(field, str) and field in names else (-1 if isinstance(field, str) else int(field))
        if not 0 <= i < len(names):
            raise KeyError(f"atmos.Volume: no field {field!r}; fields: {names}")
        out = np.empty(self.shape, dtype=np.float32)
        lib.atmos_py_volume_dense(self._live(), i, ffi.from_buffer("float[]", out))
        return out

    def __repr__(self):
        if self._ptr is None:
            return "<atmos.Volume closed>"
        nz, ny, nx = self.shape
        return f"<atmos.Volume {nx}x{ny}x{nz} voxels of {self.voxel_size_m:g} m, fields {self.fields}>"
