"""A Plan.render call that fails changes nothing: the frame the plan keeps between calls (camera,
sun, size, spp) is the one before it. It kept what the failed call had set, so that one bad size
made every later render fail with that size's message ("image size 0 x 0 ...")."""
import numpy as np
import pytest

import atmos


@pytest.mark.parametrize("bad", [dict(size=(0, 0)), dict(camera={"fov_deg": 500}),
                                 dict(camera={"position_m": [0, 900, 0], "fov_deg": 500}),
                                 dict(sun=(30, 90), size=(-1, 5)), dict(sun=(95, 0))])
def test_a_failed_render_leaves_the_plan_as_it_was(bad):
    with atmos.Plan(atmos.Scene.default().with_(width=8, height=6)) as p:
        before = np.asarray(p.render(sun=(20, 100))).copy()
        with pytest.raises((atmos.AtmosError, ValueError)) as e:
            p.render(**bad)
        if "size" not in bad:
            assert "image size" not in str(e.value)
        after = np.asarray(p.render())
        assert after.shape == (6, 8, 4)
        assert np.array_equal(after, before)
