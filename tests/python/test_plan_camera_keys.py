"""Plan.render refuses an unknown camera key (it ignored it), as a scene refuses an unknown
key, and a sun elevation outside [-90, 90] (it wrapped it past the pole: 1000 rendered a sun
at -80 degrees), as a scene's sun.elevation_deg, and an azimuth outside [0, 360) (it wrapped
it), as a scene's sun.azimuth_deg and the CLI's azimuth options."""
import pytest

import atmos


def test_plan_render_refuses_an_unknown_camera_key():
    with atmos.Plan(atmos.Scene.default().with_(width=8, height=6)) as p:
        with pytest.raises(ValueError, match="camera: unknown key 'zoom'"):
            p.render(camera={"zoom": 2})
        assert p.render(camera={"fov_deg": 40}).shape[:2] == (6, 8)


def test_plan_render_refuses_a_sun_elevation_outside_the_sky():
    with atmos.Plan(atmos.Scene.default().with_(width=8, height=6)) as p:
        for el in (95, 1000, -90.5):
            with pytest.raises(ValueError, match="sun elevation_deg: .* is not in \\[-90, 90\\]"):
                p.render(sun=(el, 0))
        for el in (-90, 90, 30):
            img = p.render(sun=(el, 200))
            assert abs(float(img.meta["sun_elevation_deg"]) - el) < 1e-6


def test_plan_render_refuses_a_sun_azimuth_outside_0_360():
    with atmos.Plan(atmos.Scene.default().with_(width=8, height=6)) as p:
        for az in (-30, 360, 400):
            with pytest.raises(ValueError, match="sun azimuth_deg: .* is not in \\[0, 360\\)"):
                p.render(sun=(30, az))
        for az in (0, 359.5):
            img = p.render(sun=(30, az))
            assert abs(float(img.meta["sun_azimuth_deg"]) - az) < 1e-6
