"""The Python package against the CLI, published values and its own promises (docs/python.md).

Run by ctest (python.pytest) with PYTHONPATH=python, ATMOS_CLI = the atmos binary and
ATMOS_SOURCE_DIR = the checkout."""
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import atmos

CLI = os.environ.get("ATMOS_CLI", "atmos")
SRC = os.environ.get("ATMOS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cli"))
import pfm  # noqa: E402  (tests/cli/pfm.py, the PFM reader the CLI tests share)


def read_pfm(path):
    """A colour PFM read independently of the library (tests/cli/pfm.py), rows top to bottom."""
    img = pfm.read(path)
    assert img.kind == "PF" and len(img.payload) == 12 * img.w * img.h
    return np.array(img.v, dtype=np.float32).reshape(img.h, img.w, 3)[::-1]


def test_version_is_the_cli_version():
    out = subprocess.run([CLI, "--version"], capture_output=True, text=True, check=True).stdout
    assert out.split()[1] == atmos.version() == atmos.__version__


def test_render_equals_the_cli_pfm(tmp_path):
    img = atmos.render(atmos.Scene.default(), width=64, height=48)
    a = np.asarray(img)
    assert a.shape == (48, 64, 4) and a.dtype == np.float32
    pfm = tmp_path / "cli.pfm"
    subprocess.run([CLI, "render", "--width", "64", "--height", "48", "--pfm", str(pfm), "-o", str(tmp_path / "c.png")],
                   check=True, capture_output=True)
    cli = read_pfm(pfm)
    assert np.array_equal(a[..., :3], cli), f"max difference {np.abs(a[..., :3] - cli).max()}"
    assert np.all(a[..., :3] > 0)


def test_image_is_a_view_without_copy():
    img = atmos.render(width=8, height=6)
    a, b = np.asarray(img), np.asarray(img)
    assert np.shares_memory(a, b)
    a[0, 0, 0] = -1.0
    assert np.asarray(img)[0, 0, 0] == -1.0
    assert "8x6" in repr(img)
    with img:
        pass
    assert "closed" in repr(img)
    with pytest.raises(ValueError):
        np.asarray(img)


def test_scene_load_dict_and_overrides():
    s = atmos.Scene.load(os.path.join(SRC, "scenes", "fig11_cumulus_dawn.json"))
    assert s.with_(width=32, height=20).size == (32, 20)
    assert s.with_(image__width=40).size[0] == 40
    d = atmos.Scene.from_dict({"image": {"width": 12, "height": 10}, "sun": {"elevation_deg": 45, "azimuth_deg": 90}})
    assert d.size == (12, 10)


def test_errors_are_exceptions_with_status_and_message(tmp_path):
    with pytest.raises(atmos.AtmosError) as e:
        atmos.Scene.from_dict({"image": {"width": -3}})
    assert e.value.status == 1 and "/image/width" in e.value.message
    with pytest.raises(atmos.AtmosError) as e:
        atmos.Scene.load(tmp_path / "missing.json")
    assert e.value.status == 3  # ATMOS_E_IO
    with pytest.raises(atmos.AtmosError) as e:
        atmos.Scene.from_dict({"camera": {"fov_deg": 270}})
    assert "fov_deg" in e.value.message
    bad = np.ones((2, 2, 2), dtype=np.float32)
    bad[1, 0, 1] = -5
    with pytest.raises(atmos.AtmosError) as e:
        atmos.Volume.from_array(bad, 10.0)
    assert e.value.status == 1
    with pytest.raises(atmos.AtmosError):
        atmos.phase_table("no-such-particle")


def test_keyword_mistakes_are_named_as_keywords():
    """A mistake in a keyword argument is named as the caller wrote it, not as the CLI's -D."""
    with pytest.raises(atmos.AtmosError) as e:
        atmos.Scene.default().with_(width=-1)
    assert e.value.message.startswith("keyword argument width=-1 (on default): /image/width: must be in")
    with pytest.raises(atmos.AtmosError) as e:
        atmos.Scene.default().with_(height=9).with_(camera__fov_deg=500)
    assert e.value.message.startswith("keyword argument camera__fov_deg=500 (on default): /camera/fov_deg:")
    with pytest.raises(atmos.AtmosTypeError) as e:
        atmos.Scene.default().with_(renderer=3)
    assert e.value.message.startswith("keyword argument renderer=3 (on default): /renderer:")
    with pytest.raises(atmos.AtmosError) as e:
        atmos.render(atmos.Scene.default(), width=0)
    assert "keyword argument width=0" in e.value.message and "-D" not in e.value.message


def test_volume_round_trip_and_render():
    rng = np.random.default_rng(7)
    a = (rng.random((6, 5, 4)) * 2e8).astype(np.float32)
    a[a < 5e7] = 0
    v = atmos.Volume.from_array({"cloud": a, "rain": (a * 1e-5, "rain")}, 25.0, origin_m=(-50, 1000, -2000))
    assert v.shape == (6, 5, 4) and v.fields == {"cloud": "cloud", "rain": "rain"}
    assert np.array_equal(v.to_array("cloud"), a)
    assert np.allclose(v.to_array(1), (a * 1e-5).astype(np.float32), rtol=1e-6)
    # A dense box seen against a black background covers the pixels of its silhouette only.
    box = atmos.Volume.from_array(np.full((8, 8, 8), 3e8, dtype=np.float32), 25.0, origin_m=(-100, 900, -1100))
    scene = atmos.Scene.from_dict({"image": {"width": 32, "height": 32}, "background": "black",
                                   "camera": {"position_m": [0, 1000, 0], "look_at_m": [0, 1000, -1000], "fov_deg": 20},
                                   "sun": {"elevation_deg": 30, "azimuth_deg": 180}})
    for renderer in ("slice", "path"):
        img = np.asarray(atmos.render(scene, volume=box, renderer=renderer, spp=4))
        lum = img[..., :3].sum(axis=-1)
        assert lum[16, 16] > 0, renderer
        assert lum[1, 1] == 0, renderer  # black background, outside the box's silhouette


def test_mie_against_rayleigh_limit_and_extinction_paradox():
    m = complex(1.5, 0.0)
    x = 0.01
    r = atmos.mie(m, x)
    k = (m * m - 1) / (m * m + 2)
    assert r["qsca"] == pytest.approx(8 / 3 * x**4 * abs(k) ** 2, rel=1e-3)  # Bohren & Huffman Eq. 5.8
    big = atmos.mie(atmos.refractive_index("water", 550), 2000.0)
    assert big["qext"] == pytest.approx(2.0, abs=0.02)
    amp = atmos.mie(m, 3.0, cos_theta=np.array([[1.0, 0.0], [-0.5, -1.0]]))
    assert amp["s1"].shape == (2, 2) and amp["s1"][0, 0] == pytest.approx(amp["s2"][0, 0])  # S1 = S2 forward


def test_phase_table_is_normalised():
    t = atmos.phase_table("cloud", fast=True)
    th = np.radians(t["theta_deg"])
    for k in range(len(t["nm"])):
        p = t["phase"][k]
        f = 2 * np.pi * p * np.sin(th)
        norm = np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(th))
        g = np.sum(0.5 * ((f * np.cos(th))[1:] + (f * np.cos(th))[:-1]) * np.diff(th))
        assert norm == pytest.approx(1.0, abs=2e-3)
        assert g == pytest.approx(t["g"][k], abs=2e-3)


def test_sky_radiance_is_vectorised_and_symmetric_about_the_sun():
    scene = atmos.Scene.from_dict({"sun": {"elevation_deg": 30, "azimuth_deg": 120}})
    az = np.array([[120 - 40, 120 + 40], [120 - 90, 120 + 90]])
    L = atmos.sky_radiance(scene, atmos.directions(np.full(az.shape, 20.0), az))
    assert L.shape == (2, 2, 3)
    assert np.allclose(L[:, 0], L[:, 1], rtol=1e-9)
    assert np.all(L > 0)
    with pytest.raises(ValueError):
        atmos.sky_radiance(scene, np.zeros((1, 3)))


def test_plan_frames_equal_one_call_renders():
    base = atmos.Scene.load(os.path.join(SRC, "scenes", "fig11_cumulus_dawn.json")).with_(width=40, height=24)
    with atmos.Plan(base) as plan:
        moved = np.asarray(plan.render(sun=(25, 200))).copy()
        again = np.asarray(plan.render(sun=(25, 200)))
    one = np.asarray(atmos.render(base.with_(sun__elevation_deg=25, sun__azimuth_deg=200)))
    assert np.array_equal(moved, again)
    assert np.array_equal(moved, one)


def test_gil_is_released_while_rendering():
    scene = atmos.Scene.load(os.path.join(SRC, "scenes", "fig11_cumulus_dawn.json")).with_(width=160, height=90)
    atmos.render(scene)  # tables cached
    count, done = [0], threading.Event()

    def spin():
        while not done.is_set():
            count[0] += 1

    t = threading.Thread(target=spin)
    t.start()
    before = count[0]
    atmos.render(scene)
    during = count[0] - before
    done.set()
    t.join()
    assert during > 1000, f"the other thread ran {during} steps during the render"


def test_two_threads_render_concurrently_and_agree():
    scene = atmos.Scene.default().with_(width=48, height=32)
    ref = np.asarray(atmos.render(scene)).copy()
    out, errors = [None, None], []

    def work(i):
        try:
            out[i] = np.asarray(atmos.render(scene)).copy()
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    ts = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert not errors
    assert np.array_equal(out[0], ref) and np.array_equal(out[1], ref)


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_no_leak_over_1000_renders():
    scene = atmos.Scene.default().with_(width=16, height=12)
    for _ in range(50):
        atmos.render(scene)
    before = rss_bytes()
    for _ in range(1000):
        img = atmos.render(scene)
        np.asarray(img).sum()
    grown = rss_bytes() - before
    assert grown < 8 << 20, f"resident memory grew by {grown / 2**20:.1f} MiB over 1000 renders"


def test_cli_exr_layers_and_metadata(tmp_path):
    """atmos render --exr-layers: one EXR with the image, the optical depth and the
    transmittance, and the metadata that says how it was made."""
    scene = os.path.join(SRC, "scenes", "fig11_cumulus_dawn.json")
    exr, tau, pfm = tmp_path / "l.exr", tmp_path / "tau.pfm", tmp_path / "l.pfm"
    subprocess.run([CLI, "render", scene, "--width", "40", "--height", "24", "-q", "--exr", str(exr), "--pfm", str(pfm),
                    "--tau", str(tau), "--exr-layers", "tau,transmittance"], check=True, capture_output=True)
    img = atmos.read_exr(exr)
    assert img.channels == ["R", "G", "B", "A", "tau.Y", "transmittance.Y"]
    a = np.asarray(img)
    assert np.array_equal(a[..., :3], read_pfm(pfm))
    t = np.frombuffer(open(tau, "rb").read().split(b"\n", 3)[3], dtype="<f4").reshape(24, 40)[::-1]
    assert np.array_equal(a[..., 4], t) and t.max() > 1
    assert np.allclose(a[..., 5], np.exp(-t), rtol=1e-6, atol=0)
    assert img.meta["atmos:scene_json"] == open(scene).read()
    assert img.meta["atmos:command"].startswith("atmos render ") and "--exr-layers" in img.meta["atmos:command"]
    assert img.meta["atmos:camera"].startswith("pinhole at (")
    bad = subprocess.run([CLI, "render", scene, "--width", "8", "--height", "6", "--exr", str(exr), "--exr-layers", "nope"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "nope" in bad.stderr
    # a scene on standard input is read once: rendered, and carried in the metadata
    text = '{"image": {"width": 12, "height": 8}, "sun": {"elevation_deg": 20}}'
    subprocess.run([CLI, "render", "-", "-q", "--exr", str(exr)], input=text, text=True, check=True)
    img = atmos.read_exr(exr)
    assert img.meta["atmos:scene_json"] == text and np.asarray(img).shape == (8, 12, 4)


def test_volume_file_without_camera_is_framed_as_the_cli_frames_it(tmp_path):
    vol = tmp_path / "cu.json"
    subprocess.run([CLI, "volume", "generate", "cumulus", "-o", str(vol), "--voxel-size", "60"], check=True,
                   capture_output=True)
    scene_path = tmp_path / "s.json"
    scene_path.write_text('{"image": {"width": 48, "height": 32}, "volume": {"file": "cu.json"}}')
    pfm = tmp_path / "cli.pfm"
    subprocess.run([CLI, "render", str(scene_path), "-q", "--pfm", str(pfm), "-o", str(tmp_path / "c.png")], check=True,
                   capture_output=True)
    scene = atmos.Scene.load(scene_path)
    a = np.asarray(atmos.render(scene))
    cli = read_pfm(pfm)
    assert np.array_equal(a[..., :3], cli)
    assert a[16, 24, 3] > 0.5  # the cloud is in the middle of the frame
    with atmos.Plan(scene) as plan:
        assert np.array_equal(np.asarray(plan.render())[..., :3], cli)


def test_numpy_values_and_wrong_types():
    s = atmos.Scene.default().with_(width=np.int64(20), height=np.int32(10), sun_elevation_deg=np.float32(12),
                                    camera__position_m=np.array([0.0, 900.0, 0.0]))
    assert s.size == (20, 10)
    assert atmos.Scene.from_dict({"image": {"width": np.int64(8), "height": 6}}).size == (8, 6)
    assert s.wavelengths_nm == [680.0, 550.0, 440.0]
    assert atmos.render(s).meta["wavelengths_nm"] == s.wavelengths_nm
    with pytest.raises(TypeError):
        atmos.render("scene.json")
    with pytest.raises(KeyError):
        atmos.Volume.from_array(np.ones((2, 2, 2)), 1.0).to_array("nope")
    with pytest.raises(ValueError, match="not finite"):
        atmos.sky_radiance(s, np.array([[np.nan, 1.0, 0.0]]))
    with pytest.raises(ValueError, match=".exr"):
        atmos.render(s).write_exr("x.png")


def test_non_finite_and_wrong_type_arguments_are_named():
    # NaN and infinities are not finite numbers (JSON has none: json.dumps wrote them as bare
    # words, which the library read as strings: "expected a number, got a string")
    s = atmos.Scene.default()
    with pytest.raises(ValueError, match=r"sun\.elevation_deg: nan is not a finite number"):
        s.with_(sun_elevation_deg=float("nan"))
    with pytest.raises(ValueError, match=r"camera\.fov_deg: inf is not a finite number"):
        s.with_(camera__fov_deg=np.float64("inf"))
    with pytest.raises(ValueError, match=r"camera\.position_m\[1\]: -inf is not a finite number"):
        s.with_(camera__position_m=np.array([0.0, -np.inf, 0.0]))
    with pytest.raises(ValueError, match=r"image\.width: nan is not a finite number"):
        atmos.Scene.from_dict({"image": {"width": float("nan")}})
    with pytest.raises(TypeError, match=r"camera\.fov_deg: expected a JSON value .*got object"):
        s.with_(camera__fov_deg=object())
    # a string where a number goes is still the library's "got a string", naming the key
    with pytest.raises(atmos.AtmosError, match="fov_deg"):
        s.with_(camera__fov_deg="wide")
    # the plan's frame and the other numeric arguments: the type's name, or not finite
    p = atmos.Plan(s.with_(width=8, height=6))
    with pytest.raises(TypeError, match="camera fov_deg: expected a number, got str 'wide'"):
        p.render(camera={"fov_deg": "wide"})
    with pytest.raises(ValueError, match=r"sun \(elevation_deg, azimuth_deg\)\[0\]: inf is not a finite number"):
        p.render(sun=(float("inf"), 10))
    with pytest.raises(ValueError, match="spp: nan is not a finite number"):
        p.render(spp=float("nan"))
    with pytest.raises(TypeError, match="size .*expected 2 numbers"):
        p.render(size=8)
    with pytest.raises(TypeError, match="got bool"):
        p.render(camera={"fov_deg": True})
    with pytest.raises(TypeError, match="voxel_size_m: expected a number, got str"):
        atmos.Volume.from_array(np.ones((2, 2, 2)), "1")
    with pytest.raises(ValueError, match=r"origin_m\[2\]: nan is not a finite number"):
        atmos.Volume.from_array(np.ones((2, 2, 2)), 1.0, origin_m=(0, 0, float("nan")))
    with pytest.raises(ValueError, match="nm: nan is not a finite number"):
        atmos.refractive_index("water", float("nan"))
    assert p.render(camera={"fov_deg": np.float32(50)}, size=(np.int64(8), 6)).shape[:2] == (6, 8)
