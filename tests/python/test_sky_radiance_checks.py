"""sky_radiance from an observer inside the planet: it crashed the interpreter; now the
library's check (atmos_atmosphere_check_ray) refuses it."""
import numpy as np
import pytest

import atmos


def test_sky_radiance_refuses_an_observer_inside_the_planet():
    s = atmos.Scene.from_dict({"atmosphere": {"model": "spherical"}})
    d = atmos.directions([90, -90], [0, 0])
    for pos in [(0, -6360000, 0), (0, -1000, 0)]:
        with pytest.raises(atmos.AtmosError, match="inside the planet") as e:
            atmos.sky_radiance(s, d, position_m=pos)
        assert e.value.status == 1
    L = atmos.sky_radiance(s, d, position_m=(0, 0, 0))
    assert np.all(np.isfinite(L)) and np.all(L > 0)
    flat = atmos.Scene.from_dict({"atmosphere": {"model": "riley"}})
    with pytest.raises(atmos.AtmosError, match="below the ground"):
        atmos.sky_radiance(flat, d, position_m=(0, -50, 0))
