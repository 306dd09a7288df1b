"""The sky as a function: radiance over arrays of view directions."""
import numpy as np

from atmos._core import check, context, ffi, lib, number
from atmos.scene import Scene


def directions(elevation_deg, azimuth_deg) -> np.ndarray:
    """Unit vectors (..., 3) in the world frame (x east, y up, z south) from elevations above
    the horizon and azimuths clockwise from north, in degrees (arrays broadcast)."""
    e, a = np.broadcast_arrays(np.radians(elevation_deg), np.radians(azimuth_deg))
    return np.stack([np.cos(e) * np.sin(a), np.sin(e), -np.cos(e) * np.cos(a)], axis=-1)


def sky_radiance(scene: Scene, dirs, position_m=None) -> np.ndarray:
    """What the scene's atmosphere shows (the air's in-scatter, the lit ground, the sun's disk)
    along each direction of dirs (..., 3), seen from position_m (default: the scene's camera),
    under the scene's sun: radiance (..., K) in W m^-2 sr^-1 nm^-1 at the scene's K
    wavelengths. Clouds of a volume are not included (render for those)."""
    if not isinstance(scene, Scene):
        raise TypeError(f"atmos: sky_radiance: expected an atmos.Scene, got {type(scene).__name__}")
    d = np.ascontiguousarray(dirs, dtype=np.float64)
    if d.shape[-1] != 3:
        raise ValueError(f"atmos.sky_radiance: directions must have shape (..., 3), got {d.shape}")
    if not np.all(np.isfinite(d)):
        raise ValueError("atmos.sky_radiance: a direction is not finite (NaN or infinity)")
    norm = np.linalg.norm(d, axis=-1, keepdims=True)
    if not np.all(norm > 0):
        raise ValueError("atmos.sky_radiance: a direction has zero length")
    d = np.ascontiguousarray(d / norm)
    s = scene._struct()
    if position_m is not None and (isinstance(position_m, (str, bytes)) or not hasattr(position_m, "__len__")
                                   or len(position_m) != 3):
        raise TypeError(f"atmos: sky_radiance: position_m: expected 3 numbers (x, y, z m), got {position_m!r}")
    pos = list(position_m) if position_m is not None else list(s.camera.position)
    n = d.size // 3
    ctx = context()
    wl = ffi.new("atmos_wavelengths *")
    check(lib.atmos_scene_wavelengths(ctx, s, wl), ctx)
    out = np.empty((n, wl.count), dtype=np.float64)
    count = ffi.new("int *")
    check(lib.atmos_py_sky_radiance(ctx, s, [number(f"sky_radiance: position_m[{i}]", v) for i, v in enumerate(pos)], ffi.from_buffer("double[]", d), n,
                                    ffi.from_buffer("double[]", out), count), ctx)
    return out.reshape(d.shape[:-1] + (wl.count,))
