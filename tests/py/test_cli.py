"""The `vpds` command end to end: options, formats, errors, and the independent checks on what
it writes."""
import subprocess
import sys

import numpy as np
import pytest

from vpds import analysis as C

pytest.importorskip("vpds")


def vpds(*args, check=True):
    return subprocess.run([sys.executable, "-m", "vpds", *args], capture_output=True, text=True,
                          check=check)


def test_sample_csv_with_a_sizing_expression(tmp_path):
    out = tmp_path / "ramp.csv"
    res = vpds("sample", "--sizing", "0.001 + 0.3*x[0]", "--lipschitz", "0.3", "--rule", "bigger",
               "--seed", "3", "-o", str(out), "--no-progress")
    assert "maximal: True" in res.stdout
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    header = out.read_text().splitlines()[0]
    assert header == "x0,x1,r,t,fixed"
    x, r, t = table[:, :2], table[:, 2], table[:, 3]
    np.testing.assert_allclose(r, 0.001 + 0.3 * x[:, 0], rtol=1e-15)
    assert np.all(t == 1)
    sizing = C.sizing_named("ramp")
    assert C.empty_disk_violations(x, r, "bigger", 1.0, 0.3) == 0
    assert C.check_maximal(x, r, "bigger", 1.0, sizing, np.zeros(2), np.ones(2)).gaps == 0


def test_sample_formats_and_refine(tmp_path):
    vpds("sample", "--dim", "3", "--radius", "0.1", "--lo", "-1", "--hi", "1,1,0", "--seed", "1",
         "--refine", "0.8,0.6", "-o", str(tmp_path / "a.npz"), "--no-progress")
    z = np.load(tmp_path / "a.npz")
    x, t = z["points"], z["scales"]
    assert x.shape[1] == 3 and np.all(x >= -1) and np.all(x[:, 2] <= 0)
    assert set(np.unique(t)) == {1.0, 0.8, 0.6}
    assert np.all(np.diff(t) <= 0)  # scales never increase along the insertion order
    vpds("sample", "--radius", "0.05", "--seed", "1", "-o", str(tmp_path / "b.npy"), "--no-progress")
    assert np.load(tmp_path / "b.npy").shape[1] == 2
    vpds("sample", "--radius", "0.05", "--seed", "1", "-o", str(tmp_path / "b.ply"), "--no-progress")
    ply = (tmp_path / "b.ply").read_text().splitlines()
    n = int(ply[3].split()[-1])
    assert ply[0] == "ply" and "property double radius" in ply and "property double t" in ply
    body = np.loadtxt(ply[ply.index("end_header") + 1:])
    assert body.shape == (n, 5) and np.all(body[:, 2] == 0) and np.all(body[:, 3] == 0.05)
    np.testing.assert_array_equal(body[:, :2], np.load(tmp_path / "b.npy"))


def test_plot_writes_a_png(tmp_path):
    pytest.importorskip("matplotlib")
    vpds("sample", "--radius", "0.08", "--plot", str(tmp_path / "p.png"), "--no-progress")
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_errors_exit_non_zero_with_the_c_message(tmp_path):
    res = vpds("sample", "--sizing", "0.01 + 0.3*x[0]", check=False)
    assert res.returncode == 2 and "desc.lipschitz is required" in res.stderr
    res = vpds("sample", "--radius", "-1", check=False)
    assert res.returncode == 2 and "desc.radius = -1" in res.stderr
    res = vpds("sample", "--sizing", "0.01 + y", "--lipschitz", "0.1", check=False)
    assert res.returncode != 0 and "does not evaluate" in res.stderr
    res = vpds("sample", "--radius", "0", check=False)
    assert res.returncode == 2 and "desc.radius = 0" in res.stderr
    res = vpds("sample", "-o", str(tmp_path / "x.txt"), check=False)
    assert res.returncode != 0 and ".npy, .npz, .csv or .ply" in res.stderr


def test_analyze_passes_a_sampling_and_fails_a_corrupted_one(tmp_path):
    pytest.importorskip("matplotlib")
    good = tmp_path / "good.npz"
    vpds("sample", "--sizing", "0.01 + 0.02*x[0]", "--lipschitz", "0.02", "--rule", "current",
         "--seed", "2", "-o", str(good), "--no-progress")
    res = vpds("analyze", str(good), "--rule", "current", "--sizing", "0.01 + 0.02*x[0]",
               "--lipschitz", "0.02", "--plot", str(tmp_path / "a.png"), check=False)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "all guarantees hold" in res.stdout and "min angle" in res.stdout
    assert (tmp_path / "a.png").read_bytes()[:4] == b"\x89PNG"
    z = dict(np.load(good))
    gap = tmp_path / "gap.npz"
    np.savez(gap, points=np.delete(z["points"], 10, axis=0), radii=np.delete(z["radii"], 10),
             scales=np.delete(z["scales"], 10), fixed=np.delete(z["fixed"], 10))
    res = vpds("analyze", str(gap), "--rule", "current", "--sizing", "0.01 + 0.02*x[0]",
               "--lipschitz", "0.02", check=False)
    assert res.returncode == 1 and "maximality" in res.stdout and "FAIL" in res.stdout
    close = tmp_path / "close.npz"
    p = np.vstack([z["points"], z["points"][:1] + 0.001])
    np.savez(close, points=p, radii=0.01 + 0.02 * p[:, 0], scales=np.ones(len(p)),
             fixed=np.zeros(len(p), bool))
    res = vpds("analyze", str(close), "--rule", "current", "--sizing", "0.01 + 0.02*x[0]",
               "--lipschitz", "0.02", check=False)
    assert res.returncode == 1 and "empty disk" in res.stdout.split("FAILED")[-1]


def test_spectrum_shows_blue_noise():
    """A maximal sampling has little power at low frequencies, uniform random points do not."""
    import vpds as v
    x = v.PoissonDisk(2, radius=0.02, rng=1, progress=False).fill_space()
    sp = C.spectrum(x, np.zeros(2), np.ones(2))
    ring = np.sqrt(len(x))
    low = sp.radial_mean[sp.radii < 0.4 * ring].mean()
    white = C.spectrum(np.random.default_rng(0).random((len(x), 2)), np.zeros(2), np.ones(2))
    assert low < 0.3 and 0.7 < white.radial_mean.mean() < 1.3
    assert np.all(sp.power >= 0) and sp.power[len(sp.frequencies) // 2, len(sp.frequencies) // 2] == 0
