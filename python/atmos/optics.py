"""Optics as arrays: Lorenz-Mie scattering by one sphere, particle phase tables."""
import numpy as np

from atmos._core import check, context, ffi, lib, number


def refractive_index(material: str, nm: float) -> complex:
    """Complex refractive index of "water" or "ice" at a wavelength in nm (imaginary part <= 0)."""
    f = {"water": lib.atmos_refractive_index_water, "ice": lib.atmos_refractive_index_ice}.get(material)
    if f is None:
        raise ValueError(f"atmos.refractive_index: material must be 'water' or 'ice', got {material!r}")
    wl = number("refractive_index: nm", nm)
    if not wl > 0:  # the tables' ends stand for wavelengths beyond them (clamped), not for these
        raise ValueError(f"atmos: refractive_index: nm: a wavelength must be > 0, got {wl:g}")
    m = f(wl)
    return complex(m.re, m.im)


def mie(m: complex, x: float, cos_theta=None) -> dict:
    """Lorenz-Mie scattering by a homogeneous sphere of size parameter x = 2 pi r / lambda and
    relative refractive index m (imaginary part <= 0): the efficiencies qext, qsca, qback, the
    asymmetry parameter g, and with cos_theta (an array of cosines) the amplitudes s1, s2 as
    complex arrays of its shape."""
    import numbers
    if isinstance(m, bool) or not isinstance(m, numbers.Complex):
        raise TypeError(f"atmos: mie: m: expected a (complex) refractive index, got {type(m).__name__} {m!r}")
    m = complex(m)
    mu = np.ascontiguousarray(np.atleast_1d(cos_theta if cos_theta is not None else []), dtype=np.float64)
    n = mu.size
    s1 = ffi.new("atmos_complex[]", max(n, 1))
    s2 = ffi.new("atmos_complex[]", max(n, 1))
    res = ffi.new("atmos_mie_result *")
    ctx = context()
    check(lib.atmos_mie(ctx, {"re": m.real, "im": m.imag}, number("mie: x", x), n, ffi.from_buffer("double[]", mu) if n else ffi.NULL,
                        s1, s2, res), ctx)
    out = {"qext": res.qext, "qsca": res.qsca, "qback": res.qback, "g": res.g, "terms": res.terms}
    if cos_theta is not None:
        c1 = np.frombuffer(ffi.buffer(s1, 16 * n), dtype=np.complex128).copy()
        c2 = np.frombuffer(ffi.buffer(s2, 16 * n), dtype=np.complex128).copy()
        shape = np.shape(cos_theta)
        out["s1"], out["s2"] = c1.reshape(shape), c2.reshape(shape)
    return out


def phase_table(preset: str = "cloud", wavelengths_nm=None, fast: bool = False) -> dict:
    """A particle preset's phase function at the rgb wavelengths (or N spectral samples with
    wavelengths_nm=N): {"theta_deg": (M,), "phase": (K, M) per steradian, normalised over the
    sphere, "nm": (K,), "g", "sigma_ext_m2", "albedo": (K,)}. Built once, then read from
    the disk cache."""
    ctx = context()
    part = ffi.new("atmos_particle_desc *")
    if not isinstance(preset, str) or "\0" in preset:
        raise TypeError(f"atmos: phase_table: preset: expected a name, got {preset!r}")
    check(lib.atmos_py_particle_fast(ctx, preset.encode(), 1 if fast else 0, part), ctx)
    wl = ffi.new("atmos_wavelengths *")
    if wavelengths_nm is None:
        lib.atmos_wavelengths_rgb(wl)
    else:
        n = number("phase_table: wavelengths_nm (a count of spectral samples)", wavelengths_nm, integer=True)
        if not 1 <= n <= 128:  # ATMOS_MAX_WAVELENGTHS; the call takes no context to say so
            raise ValueError(f"atmos: phase_table: wavelengths_nm: expected a count in [1, 128], got {n}")
        lib.atmos_wavelengths_spectral(n, wl)
    p = ffi.new("atmos_phase_table **")
    check(lib.atmos_phase_table_build(ctx, part, wl, ffi.NULL, p), ctx)
    t = ffi.gc(p[0], lib.atmos_phase_table_destroy)
    theta = ffi.new("const double **")
    m = lib.atmos_phase_grid(theta)
    k = lib.atmos_phase_table_wavelength_count(t)
    out = {
        "theta_deg": np.frombuffer(ffi.buffer(theta[0], 8 * m), dtype=np.float64).copy(),
        "phase": np.array([np.frombuffer(ffi.buffer(lib.atmos_phase_table_values(t, i), 8 * m), dtype=np.float64)
                           for i in range(k)]),
        "nm": np.array([lib.atmos_phase_table_wavelength_nm(t, i) for i in range(k)]),
        "g": np.array([lib.atmos_phase_table_g(t, i) for i in range(k)]),
        "sigma_ext_m2": np.array([lib.atmos_phase_table_sigma_ext(t, i) for i in range(k)]),
        "albedo": np.array([lib.atmos_phase_table_albedo(t, i) for i in range(k)]),
    }
    ffi.release(t)
    return out
