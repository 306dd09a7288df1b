"""A frame's sun from a time of day, the scene's animation frames, and a progress callback that
can cancel (docs/python.md): the images against the CLI's `atmos render --time` and
`--frames` PFMs, bit for bit; the callback's reports and its cancellation."""
import datetime
import os
import subprocess
import sys

import numpy as np
import pytest

import atmos

CLI = os.environ.get("ATMOS_CLI", "atmos")
SRC = os.environ.get("ATMOS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_atmos import read_pfm  # noqa: E402

# a flat sky with the sun by time over Munich, and a round planet's sky with the sun by angles
BY_TIME = ('{"image": {"width": 32, "height": 20}, '
           '"sun": {"time": "2026-06-21T06:00Z", "latitude_deg": 48.1, "longitude_deg": 11.6}}')
ROUND = ('{"image": {"width": 24, "height": 16}, "atmosphere": {"model": "spherical"}, '
         '"sun": {"elevation_deg": 10, "azimuth_deg": 100}}')


def cli_pfm(tmp_path, text, *args):
    """The CLI's PFM of the scene text (on standard input) with args; one file, or a frame's."""
    out = tmp_path / "cli.pfm"
    subprocess.run([CLI, "render", "-", "-q", "--pfm", str(out), "-o", str(tmp_path / "cli.png"), *args],
                   input=text, text=True, check=True, capture_output=True)
    return out


def rgb(img):
    return np.asarray(img)[..., :3].copy()


@pytest.mark.parametrize("text", [BY_TIME, ROUND], ids=["place-of-the-sun", "round-planet"])
def test_a_time_renders_what_the_cli_renders_for_it(tmp_path, text):
    when = "2026-06-21T12:00Z"
    cli = read_pfm(cli_pfm(tmp_path, text, "--time", when))
    scene = atmos.Scene.from_json(text)
    one = atmos.render(scene, time=when)
    assert np.array_equal(rgb(one), cli), f"max difference {np.abs(rgb(one) - cli).max()}"
    with atmos.Plan(scene) as plan:
        first = rgb(plan.render())
        assert not np.array_equal(first, cli)  # the scene's own sun is elsewhere
        assert np.array_equal(rgb(plan.render(time=when)), cli)
        noon = datetime.datetime(2026, 6, 21, 14, 0, tzinfo=datetime.timezone(datetime.timedelta(hours=2)))
        assert np.array_equal(rgb(plan.render(time=noon)), cli)  # an aware datetime, the same instant
        assert np.array_equal(rgb(plan.render()), cli)  # the sun stays where the last frame put it
        assert np.array_equal(rgb(plan.render(time="2026-06-21T06:00Z")), rgb(atmos.render(scene, time="2026-06-21T06:00Z")))


@pytest.mark.parametrize("animation", ['"time_end": "2026-06-21T16:00Z"', None], ids=["by-time", "by-angles"])
def test_animation_frames_are_the_cli_frames(tmp_path, animation):
    if animation:
        text = BY_TIME[:-1] + ', "animation": {"frames": 3, ' + animation + "}}"
    else:
        text = ('{"image": {"width": 24, "height": 16}, "sun": {"elevation_deg": 40, "azimuth_deg": 350}, '
                '"animation": {"frames": 3, "elevation_end_deg": 5, "azimuth_end_deg": 30}}')
    cli_pfm(tmp_path, text)
    cli = [read_pfm(tmp_path / f"cli_{i:04d}.pfm") for i in (1, 2, 3)]
    assert not np.array_equal(cli[0], cli[2])
    scene = atmos.Scene.from_json(text)
    with atmos.Plan(scene) as plan:
        assert plan.frame_count == 3
        frames = [rgb(img) for img in plan.frames()]
        assert np.array_equal(rgb(plan.render(frame=1)), cli[1])
    for i in range(3):
        assert np.array_equal(frames[i], cli[i]), f"frame {i}: max difference {np.abs(frames[i] - cli[i]).max()}"
        assert np.array_equal(rgb(atmos.render(scene, frame=i)), cli[i])
    with pytest.raises(atmos.AtmosError, match="out of range"):
        atmos.render(scene, frame=3)


@pytest.mark.parametrize("when, kind, words", [
    ("2026-02-30T12:00Z", atmos.AtmosError, "2026-02-30"),
    ("3000-01-01T00:00Z", atmos.AtmosError, "3000"),
    ("noon", atmos.AtmosError, "noon"),
    (1200, TypeError, "expected a string"),
    (datetime.datetime(2026, 6, 21, 12), ValueError, "time zone"),
])
def test_an_absurd_time_raises_a_clear_error_and_changes_nothing(when, kind, words):
    scene = atmos.Scene.from_json(BY_TIME)
    with pytest.raises(kind, match=words) as e:
        atmos.render(scene, time=when)
    assert "time" in str(e.value)
    with atmos.Plan(scene) as plan:
        before = rgb(plan.render(time="2026-06-21T09:00Z"))
        with pytest.raises(kind, match=words):
            plan.render(time=when)
        assert np.array_equal(rgb(plan.render()), before)


def test_a_time_needs_a_place_and_excludes_angles():
    flat = atmos.Scene.default().with_(width=8, height=6)
    with pytest.raises(ValueError, match="no place for the sun"):
        atmos.render(flat, time="2026-06-21T12:00Z")
    with atmos.Plan(atmos.Scene.from_json(BY_TIME)) as plan:
        with pytest.raises(ValueError, match="exclude each other"):
            plan.render(sun=(20, 100), time="2026-06-21T12:00Z")


# a small cloud drawn by the slice renderer, which reports each batch of slices and can stop between them
SLICE = ('{"image": {"width": 24, "height": 16}, "renderer": "slice", '
         '"volume": {"generate": "cumulus", "voxel_size_m": 100}}')


def test_progress_reports_increasing_fractions_per_stage():
    scene = atmos.Scene.from_json(SLICE)
    seen = []
    img = rgb(atmos.render(scene, progress=lambda stage, f: seen.append((stage, f))))
    stages = {}
    for stage, f in seen:
        assert 0.0 <= f <= 1.0
        assert f >= stages.get(stage, 0.0), f"{stage}: {f} after {stages[stage]}"
        stages[stage] = f
    assert stages.get("render slice") == 1.0, seen
    assert [s for s, _ in seen].count("render slice") > 2
    assert np.array_equal(img, rgb(atmos.render(scene)))  # a callback changes nothing


def test_a_callback_returning_false_cancels_and_one_raising_cancels_with_its_exception():
    scene = atmos.Scene.from_json(SLICE)
    full = rgb(atmos.render(scene))
    seen = []

    def stop_in_the_render(stage, f):
        seen.append((stage, f))
        return stage != "render slice"

    with pytest.raises(atmos.Cancelled) as e:
        atmos.render(scene, progress=stop_in_the_render)
    assert e.value.status == 7 and "cancelled" in e.value.message and "returned False" in e.value.message
    assert seen[-1][0] == "render slice" and seen[-1][1] < 1.0  # stopped at its first report: no more calls
    assert [s for s, _ in seen].count("render slice") == 1

    class Stop(Exception):
        pass

    def fail(stage, f):
        if stage == "render slice":
            raise Stop("enough")

    with pytest.raises(Stop, match="enough"):
        atmos.render(scene, progress=fail)
    with atmos.Plan(scene) as plan:
        first = rgb(plan.render(sun=(20, 100)))
        with pytest.raises(atmos.Cancelled):
            plan.render(sun=(30, 120), progress=lambda stage, f: False)
        assert np.array_equal(rgb(plan.render()), first)  # the cancelled frame changed nothing
        assert np.array_equal(rgb(plan.render(sun=(30, 120))), rgb(atmos.render(scene, sun_elevation_deg=30,
                                                                                 sun_azimuth_deg=120)))
    assert np.array_equal(rgb(atmos.render(scene)), full)  # nothing left behind in the thread's context
    with pytest.raises(TypeError, match="callable"):
        atmos.render(scene, progress="yes")


def test_each_thread_gets_its_own_calls_reports():
    """The callback is the calling thread's: two threads rendering at once, one with a callback
    and one without, and two with their own callbacks, each callback hears its own thread only."""
    import threading
    scene = atmos.Scene.from_json(SLICE)
    heard, errors = {0: set(), 1: set()}, []

    def work(i, with_callback):
        try:
            me = threading.get_ident()
            cb = (lambda stage, f: heard[i].add(threading.get_ident() == me)) if with_callback else None
            atmos.render(scene, progress=cb)
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    for second in (False, True):
        heard[0].clear(), heard[1].clear()
        ts = [threading.Thread(target=work, args=(0, True)), threading.Thread(target=work, args=(1, second))]
        for t in ts:
            t.start()
        for t in ts:
            t.join()
        assert not errors
        assert heard[0] == {True} and heard[1] == ({True} if second else set())
