"""A plan shared by threads and closed at awkward moments, and arguments the C side would have
misread: each once a crash, a lost message or a silent misreading (docs/python.md)."""
import threading

import numpy as np
import pytest

import atmos

SMALL = atmos.Scene.default().with_(width=16, height=12)


def test_threads_take_turns_on_one_plan():
    """Two threads rendering one plan at two sizes: the calls take turns (the path tracer's plan
    had corrupted the heap), and each image is the size its call asked for."""
    scene = SMALL.with_(volume__generate="cumulus", volume__voxel_size_m=400, renderer="path", path__spp=1)
    plan = atmos.Plan(scene)
    shapes, errors = [], []

    def run(size):
        try:
            for _ in range(3):
                shapes.append((size, plan.render(size=size, sun=(20, 100)).numpy().shape))
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=run, args=(s,)) for s in ((16, 12), (8, 24))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert len(shapes) == 6 and all(shape[:2] == (h, w) for (w, h), shape in shapes)
    plan.close()


def test_close_from_the_progress_callback_waits_for_the_render():
    plan = atmos.Plan(SMALL)
    img = plan.render(sun=(10, 20), progress=lambda stage, f: plan.close() or True)
    assert img.numpy().shape[:2] == (12, 16)
    assert repr(plan) == "<atmos.Plan closed>"
    with pytest.raises(ValueError, match="closed"):
        plan.render()


def test_close_from_another_thread_waits_for_the_render():
    plan = atmos.Plan(SMALL)
    started, done = threading.Event(), []

    def loop():
        try:
            for _ in range(50):
                plan.render(sun=(20, 30), progress=lambda s, f: started.set() or True)
                done.append(1)
        except ValueError:  # the plan closed between two renders
            pass

    t = threading.Thread(target=loop)
    t.start()
    started.wait(30)
    plan.close()
    t.join()
    assert done and repr(plan) == "<atmos.Plan closed>"


def test_a_plans_error_is_told_in_any_thread():
    plan = atmos.Plan(SMALL)
    said = []

    def run():
        try:
            plan.render(size=(0, 0))
        except atmos.AtmosError as e:
            said.append(e.message)

    t = threading.Thread(target=run)
    t.start()
    t.join()
    assert said and "at least 1" in said[0]


def test_a_callback_whose_answer_cannot_be_told_true_or_false_stops_the_render():
    with pytest.raises(ValueError, match="ambiguous"):
        atmos.render(SMALL, progress=lambda s, f: np.array([1, 0]))


@pytest.mark.parametrize("call, kind, words", [
    (lambda: atmos.sky_radiance(SMALL, [0, 1, 0], position_m=[0, 10]), TypeError, "3 numbers"),
    (lambda: atmos.Volume.from_array(np.ones((2, 2, 2)), 1.0, origin_m=(0, 0)), TypeError, "3 numbers"),
    (lambda: atmos.Volume.from_array({"cl\0oud": np.ones((2, 2, 2))}, 1.0), ValueError, "NUL"),
    (lambda: atmos.Volume.load("v.json\0x"), ValueError, "NUL"),
    (lambda: atmos.Scene.load("s.json\0x"), ValueError, "NUL"),
    (lambda: atmos.phase_table("air", 0), ValueError, r"\[1, 128\]"),
    (lambda: atmos.phase_table("air", 2.7), ValueError, "whole number"),
    (lambda: atmos.refractive_index("water", -550), ValueError, "> 0"),
    (lambda: atmos.Plan(SMALL).render(camera={"fov_deg": 0}), ValueError, "fov_deg: must be > 0"),
    (lambda: atmos.Plan(SMALL).render(camera={"up": [0, 0, 0]}), ValueError, "must not be zero"),
    (lambda: atmos.Plan(SMALL).render(spp=0), ValueError, r"\[1, 1000000\]"),
    (lambda: atmos.mie(None, 10), TypeError, "refractive index"),
    (lambda: atmos.mie("1.33", 10), TypeError, "refractive index"),
    (lambda: atmos.sky_radiance(None, [0, 1, 0]), TypeError, "atmos.Scene"),
    (lambda: atmos.Volume.from_array(np.ones((2, 2, 2)), 1.0).to_array(True), TypeError, "a name or an index"),
    (lambda: atmos.Volume.from_array(np.ones((2, 2, 2)), 1.0).to_array(1.7), TypeError, "a name or an index"),
])
def test_arguments_the_library_would_misread_are_refused(call, kind, words):
    with pytest.raises(kind, match=words):
        call()


def test_a_volume_given_to_the_sky_renderer_is_said_of_the_volume():
    vol = atmos.Volume.from_array(np.full((4, 4, 4), 1e8, np.float32), 100.0)
    with pytest.raises(atmos.AtmosError) as e:
        atmos.render(SMALL, volume=vol, renderer="sky")
    assert e.value.message.startswith("the volume given: ") and "volume__generate" not in e.value.message


def test_a_volume_closes_once_no_open_plan_draws_it():
    vol = atmos.Volume.from_array(np.full((4, 4, 4), 1e8, np.float32), 100.0)
    plan = atmos.Plan(SMALL, vol)
    with pytest.raises(ValueError, match="close the plan first"):
        vol.close()
    plan.close()
    vol.close()
    assert repr(vol) == "<atmos.Volume closed>"
    with pytest.raises(ValueError, match="closed"):
        vol.shape
    with atmos.Volume.from_array(np.ones((2, 2, 2)), 1.0) as v:
        assert v.shape == (2, 2, 2)
    assert v._ptr is None
