"""OpenEXR sizing images: files written with the OpenEXR package (float and half channels), and
what the sampler sees of them (orientation, mapping of pixel values to radii, errors)."""
import os
import subprocess
import sys

import numpy as np
import pytest

OpenEXR = pytest.importorskip("OpenEXR")
import vpds  # noqa: E402


def write_exr(path, channels):
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {k: OpenEXR.Channel(v) for k, v in channels.items()}).write(str(path))


def bilinear(img_rows_top_down, pts, lo, hi):
    """The image as the sampler should see it: row 0 at the top, bilinear between pixels."""
    from scipy.interpolate import RegularGridInterpolator
    h, w = img_rows_top_down.shape
    xs = np.linspace(lo[0], hi[0], w)
    ys = np.linspace(lo[1], hi[1], h)
    f = RegularGridInterpolator((ys, xs), img_rows_top_down[::-1, :])
    return f(pts[:, ::-1])


@pytest.mark.parametrize("dtype", [np.float32, np.float16])
def test_pixel_values_are_radii_with_the_image_orientation(tmp_path, dtype):
    h, w = 20, 30
    yy, xx = np.mgrid[0:h, 0:w]
    # brighter to the right and towards the top of the image: r grows with x and y
    img = (0.01 + 0.02 * xx / (w - 1) + 0.01 * (h - 1 - yy) / (h - 1)).astype(dtype)
    path = tmp_path / "r.exr"
    write_exr(path, {"Y": img, "other": np.ones_like(img)})
    lo, hi = np.array([1.0, 2.0]), np.array([2.0, 3.5])
    engine = vpds.PoissonDisk(2, sizing=str(path), l_bounds=lo, u_bounds=hi, rng=1, progress=False)
    x = engine.fill_space()
    expected = bilinear(img.astype(np.float64), x, lo, hi)
    np.testing.assert_allclose(engine.radii, expected, rtol=1e-12)
    assert engine.radii[x[:, 0] > 1.8].mean() > engine.radii[x[:, 0] < 1.2].mean()
    assert engine.radii[x[:, 1] > 3.3].mean() > engine.radii[x[:, 1] < 2.2].mean()


def test_value_range_mapping_and_channel_choice(tmp_path):
    img = np.tile(np.linspace(-0.5, 1.5, 25, dtype=np.float32), (10, 1))
    path = tmp_path / "g.exr"
    write_exr(path, {"R": img, "G": np.zeros_like(img)})
    engine = vpds.PoissonDisk(2, sizing=path, sizing_channel="R", sizing_range=(0.02, 0.06),
                              rng=2, progress=False)
    x = engine.fill_space()
    mapped = 0.02 + 0.04 * np.clip(img.astype(np.float64), 0, 1)
    np.testing.assert_allclose(engine.radii, bilinear(mapped, x, np.zeros(2), np.ones(2)), rtol=1e-12)
    assert engine.radii.min() >= 0.02 * (1 - 1e-12) and engine.radii.max() <= 0.06 * (1 + 1e-12)
    with pytest.raises(ValueError, match="no channel 'Q'"):
        vpds.PoissonDisk(2, sizing=path, sizing_channel="Q")
    with pytest.raises(ValueError, match="choose one"):
        two = tmp_path / "two.exr"
        write_exr(two, {"A": img, "B": img})
        vpds.PoissonDisk(2, sizing=two)


def test_bad_images(tmp_path):
    neg = tmp_path / "neg.exr"
    write_exr(neg, {"Y": -np.ones((4, 4), np.float32)})
    with pytest.raises(vpds.VpdsValueError, match="radii must be finite and > 0"):
        vpds.PoissonDisk(2, sizing=neg)
    nan = tmp_path / "nan.exr"
    write_exr(nan, {"Y": np.full((4, 4), np.nan, np.float32)})
    with pytest.raises(ValueError, match="non-finite"):
        vpds.PoissonDisk(2, sizing=nan)
    ok = tmp_path / "ok.exr"
    write_exr(ok, {"Y": np.full((4, 4), 0.1, np.float32)})
    with pytest.raises(ValueError, match="2D box"):
        vpds.PoissonDisk(3, sizing=ok)


def test_cli_sizing_exr_smoothed_for_l(tmp_path):
    img = np.zeros((32, 32), np.float32)
    img[:, 16:] = 1.0  # a step: far too steep for any rule until smoothed
    path = tmp_path / "step.exr"
    write_exr(path, {"Y": img})
    out = tmp_path / "s.npz"
    res = subprocess.run([sys.executable, "-m", "vpds", "sample", "--sizing-exr", str(path),
                          "--exr-range", "0.01,0.05", "--rule", "prior", "--no-progress"],
                         capture_output=True, text=True)
    assert res.returncode == 2 and "limit 0.5" in res.stderr
    res = subprocess.run([sys.executable, "-m", "vpds", "sample", "--sizing-exr", str(path),
                          "--exr-range", "0.01,0.05", "--lipschitz", "0.3", "--rule", "prior",
                          "-o", str(out), "--no-progress"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert "smoothed for L = 0.3" in res.stdout
    z = np.load(out)
    assert z["radii"].min() >= 0.01 * (1 - 1e-12) and z["radii"].max() <= 0.05 * (1 + 1e-12)


def cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "vpds", "sample", *args, "--no-progress"],
                          capture_output=True, text=True, cwd=cwd)


def test_rgb_images_give_their_components_as_channels(tmp_path):
    """OpenEXR's Python API reads R, G, B (A) as one grouped channel 'RGB' ('RGBA'): R, G, B
    and A are still the channels a user names, and R is the default after Y."""
    from vpds.exr import read_channel
    ones = np.ones((6, 8), np.float32)
    rgb = tmp_path / "rgb.exr"
    write_exr(rgb, {"R": 0.02 * ones, "G": 0.03 * ones, "B": 0.04 * ones})
    rgba = tmp_path / "rgba.exr"
    write_exr(rgba, {"RGBA": np.stack([0.02 * ones, 0.03 * ones, 0.04 * ones, 0.05 * ones], axis=-1)})
    for path in (rgb, rgba):
        assert np.all(read_channel(path) == np.float32(0.02))
        assert np.all(read_channel(path, "G") == np.float32(0.03))
        assert np.all(read_channel(path, "B") == np.float32(0.04))
    assert np.all(read_channel(rgba, "A") == np.float32(0.05))
    with pytest.raises(ValueError, match=r"no channel 'A'; it has \['B', 'G', 'R'\]"):
        read_channel(rgb, "A")
    for channel, r in ((None, 0.02), ("B", 0.04)):
        out = tmp_path / f"{channel}.npz"
        res = cli("--sizing-exr", str(rgb), *(["--channel", channel] if channel else []),
                  "-o", str(out))
        assert res.returncode == 0, res.stderr
        np.testing.assert_allclose(np.load(out)["radii"], np.float32(r))


def test_cli_unknown_channel_names_channel_and_the_components(tmp_path):
    ones = np.ones((6, 8), np.float32)
    rgb = tmp_path / "rgb.exr"
    write_exr(rgb, {"R": 0.02 * ones, "G": 0.03 * ones, "B": 0.04 * ones})
    res = cli("--sizing-exr", str(rgb), "--channel", "Q")
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "--channel Q" in res.stderr and "['B', 'G', 'R']" in res.stderr


def test_a_corrupt_file_is_a_value_error_naming_it(tmp_path):
    bad = tmp_path / "bad.exr"
    bad.write_bytes(b"not an exr")
    with pytest.raises(ValueError, match="bad.exr: not a readable OpenEXR file"):
        vpds.PoissonDisk(2, sizing=bad)


@pytest.mark.parametrize("value", ["0.01", "a,b", "0.01,0.02,0.03", "0.05,0.01", "0,0.1"])
def test_cli_exr_range_needs_lo_hi(tmp_path, value):
    path = tmp_path / "y.exr"
    write_exr(path, {"Y": np.full((4, 4), 0.5, np.float32)})
    res = cli("--sizing-exr", str(path), "--exr-range", value)
    assert res.returncode == 2 and "Traceback" not in res.stderr, res.stderr
    assert f"--exr-range {value!r}" in res.stderr and "LO" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


def test_cli_without_openexr_names_the_install(tmp_path):
    path = tmp_path / "y.exr"
    write_exr(path, {"Y": np.full((4, 4), 0.05, np.float32)})
    (tmp_path / "sitecustomize.py").write_text(
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] == 'OpenEXR':\n"
        "            raise ImportError(f'blocked: {name}')\n"
        "sys.meta_path.insert(0, Block())\n")
    env = dict(os.environ, PYTHONPATH=str(tmp_path))
    for option in ("--sizing-exr", "--domain"):
        res = subprocess.run([sys.executable, "-m", "vpds", "sample", option, str(path),
                              "--no-progress"], capture_output=True, text=True, env=env)
        assert res.returncode == 2 and "Traceback" not in res.stderr, res.stderr
        assert option in res.stderr and "pip install OpenEXR" in res.stderr
    res = subprocess.run([sys.executable, "-m", "vpds", "sample", "--tiles", "2", "--sizing-exr",
                          str(path), "-o", str(tmp_path / "t.zarr"), "--no-progress"],
                         capture_output=True, text=True, env=env)
    assert res.returncode == 2 and "Traceback" not in res.stderr, res.stderr
    assert "--sizing-exr" in res.stderr and "pip install OpenEXR" in res.stderr
