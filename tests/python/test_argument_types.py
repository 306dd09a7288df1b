"""Scene values of the wrong type raise TypeError, as docs/python.md says (they raised only
AtmosError): atmos.AtmosTypeError is both."""
import pytest

import atmos


def test_scene_values_of_the_wrong_type_raise_type_error():
    cases = [lambda: atmos.Scene.default().with_(camera__fov_deg="wide"),
             lambda: atmos.Scene.from_dict({"camera": {"fov_deg": "wide"}}),
             lambda: atmos.Scene.default().with_(width="big")]
    for make in cases:
        with pytest.raises(TypeError, match="expected an? (number|integer), got a string") as e:
            make().size
        assert isinstance(e.value, atmos.AtmosError) and e.value.status == 1
    with pytest.raises(atmos.AtmosError) as e:  # a bad value of the right type stays an AtmosError
        atmos.Scene.from_dict({"camera": {"fov_deg": -5}}).size
    assert not isinstance(e.value, TypeError)
