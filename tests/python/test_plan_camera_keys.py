"""Plan.render refuses an unknown camera key (it ignored it), as a scene refuses an unknown
key."""
import pytest

import atmos


def test_plan_render_refuses_an_unknown_camera_key():
    with atmos.Plan(atmos.Scene.default().with_(width=8, height=6)) as p:
        with pytest.raises(ValueError, match="camera: unknown key 'zoom'"):
            p.render(camera={"zoom": 2})
        assert p.render(camera={"fov_deg": 40}).shape[:2] == (6, 8)
