"""The `vpds` command end to end: options, formats, errors, and the independent checks on what
it writes."""
import os
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
    n = int(next(line for line in ply if line.startswith("element vertex")).split()[-1])
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
    assert res.returncode == 2 and "unknown name y" in res.stderr
    res = vpds("sample", "--radius", "0", check=False)
    assert res.returncode == 2 and "desc.radius = 0" in res.stderr
    res = vpds("sample", "-o", str(tmp_path / "x.txt"), check=False)
    assert res.returncode == 2 and "unsupported extension '.txt'" in res.stderr


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
    assert res.returncode == 1 and "FAILED: maximality" in res.stdout
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


# -- the command line as a person uses it ---------------------------------------------------------

@pytest.mark.parametrize("args, message", [
    (["--sizing", "0.01 +", "--lipschitz", "0.1"], "--sizing '0.01 +': not a Python expression"),
    (["--sizing", "0.01 + foo(x[0])", "--lipschitz", "0.1"], "unknown name foo"),
    (["--sizing", "0.01 + x[5]", "--lipschitz", "0.1"], "does not evaluate"),
    (["--sizing", "0*x[0]", "--lipschitz", "0.1"], "gives r = 0.0 at x = 0.5"),
    (["--lo", "0,a"], "--lo '0,a': expected numbers"),
    (["--hi", "1,1,1"], "--hi '1,1,1' has 3 values for --dim 2"),
    (["--lo", "1", "--hi", "0"], "axis 0 has lo = 1 >= hi = 0"),
    (["--periodic", "7"], "axis 7 is not in 0..1"),
    (["--domain", "no-such.png"], "--domain no-such.png: no such file"),
    (["--sizing-exr", "no-such.exr"], "--sizing-exr no-such.exr: no such file"),
    (["-o", "out.vtk"], "unsupported extension '.vtk'"),
    (["-o", "no-such-dir/out.npz"], "directory no-such-dir does not exist"),
    (["--dim", "4", "-o", "out.ply"], ".ply holds up to 3 coordinates"),
    (["--tiles", "2,x", "-o", "t.zarr"], "--tiles '2,x': expected tile counts"),
])
def test_user_mistakes_are_one_line_with_status_2(tmp_path, args, message):
    res = subprocess.run([sys.executable, "-m", "vpds", "sample", *args, "--no-progress"],
                         capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 2, res.stdout + res.stderr
    assert message in res.stderr and "Traceback" not in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1, res.stderr
    assert not list(tmp_path.iterdir())  # refused before sampling: nothing written


def test_output_extension_is_refused_before_sampling(tmp_path):
    """A run that would take minutes is refused at once when its output cannot be written."""
    res = vpds("sample", "--radius", "0.0005", "-o", str(tmp_path / "x.txt"), "--no-progress",
               check=False)
    assert res.returncode == 2 and "samples in" not in res.stdout


def test_a_run_that_does_not_fit_is_refused_with_its_estimate():
    res = vpds("sample", "--radius", "2.6e-5", "--no-progress", check=False)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "about 1.0" in res.stderr and "e+09 samples" in res.stderr and "--force" in res.stderr


def test_estimate_is_close_to_the_count():
    x = vpds_engine(radius=0.01).fill_space()
    est = vpds_engine(radius=0.01).estimate()
    assert 0.85 < est.samples / len(x) < 1.15 and est.bytes > 0 and est.cells > 0
    ramp = lambda y: 0.01 + 0.1 * y[:, 0]  # noqa: E731
    x = vpds_engine(sizing=ramp, lipschitz=0.1).fill_space()
    assert 0.8 < vpds_engine(sizing=ramp, lipschitz=0.1).estimate().samples / len(x) < 1.2
    # at half the scale, about 4x as many
    assert 3.5 < vpds_engine(radius=0.01).estimate(0.5).samples / est.samples < 4.5


def test_a_memory_limit_refuses_before_the_run_and_changes_nothing():
    import vpds as v
    ref = vpds_engine(radius=0.01).fill_space()
    engine = vpds_engine(radius=0.01, memory_limit=100_000)
    with pytest.raises(MemoryError, match="memory limit of 100000 bytes"):
        engine.fill_space()
    assert len(engine.points) == 0
    engine = vpds_engine(radius=0.01, memory_limit=int(engine.estimate().bytes * 2))
    assert np.array_equal(engine.fill_space(), ref)
    with pytest.raises(ValueError, match="memory_limit = -1"):
        v.PoissonDisk(2, memory_limit=-1)


def vpds_engine(**kw):
    import vpds as v
    return v.PoissonDisk(2, rng=3, progress=False, **kw)


def test_help_documents_every_option_with_its_default_and_version():
    res = vpds("sample", "--help")
    text = " ".join(res.stdout.split())
    for option, default in [("--radius", "0.05"), ("--rule", "smaller"), ("--seed", "0"),
                            ("--inhibition", "1.0"), ("--domain-threshold", "0.5")]:
        assert option in text and f"(default: {default})" in text, option
    res = vpds("--version")
    assert res.stdout.startswith("vpds 1.") and "libvpds" in res.stdout and "C library" in res.stdout


def test_analyze_reads_what_sample_recorded(tmp_path):
    """Without flags, analyze checks against the run's own sizing, rule and box, and judges a
    stream by the stream's tolerance."""
    ramp = tmp_path / "ramp.npz"
    vpds("sample", "--sizing", "0.01 + 0.3*x[0]", "--lipschitz", "0.3", "--rule", "prior",
         "--lo", "0,-1", "--hi", "1,0", "--seed", "2", "-o", str(ramp), "--no-progress")
    res = vpds("analyze", str(ramp), check=False)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "rule prior" in res.stdout and "r = 0.01 + 0.3*x[0] (the file)" in res.stdout
    assert res.stdout.count(" passed  ") == 3 and "all guarantees hold" in res.stdout
    # a flag overrides the file: the bigger rule's empty disk does not hold for this output
    assert vpds("analyze", str(ramp), "--rule", "bigger", check=False).returncode == 1
    for name in ("s.csv", "s.ply", "s.npz"):
        out = tmp_path / name
        vpds("sample", "--stream", "500", "--seed", "1", "-o", str(out), "--no-progress")
        res = vpds("analyze", str(out), check=False)
        assert res.returncode == 0, res.stdout + res.stderr
        assert "within the stream's tolerance 1e-05" in res.stdout and "run: stream" in res.stdout


def test_analyze_says_what_it_did_not_check(tmp_path):
    """Radii that vary without r(x): empty disk checked, maximality and Table 1 not (exit 3)."""
    out = tmp_path / "ramp.npz"
    vpds("sample", "--sizing", "0.01 + 0.3*x[0]", "--lipschitz", "0.3", "-o", str(out),
         "--no-progress")
    z = dict(np.load(out))
    bare = tmp_path / "bare.npz"
    np.savez(bare, points=z["points"], radii=z["radii"], scales=z["scales"], fixed=z["fixed"])
    res = vpds("analyze", str(bare), check=False)
    assert res.returncode == 3, res.stdout
    assert "all guarantees hold" not in res.stdout and "not checked: maximality" in res.stdout
    assert "r(x) is unknown" in res.stdout and "-> OK" not in res.stdout
    res = vpds("analyze", str(tmp_path / "missing.npz"), check=False)
    assert res.returncode == 2 and "no such file" in res.stderr
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    res = vpds("analyze", str(tmp_path / "other.npz"), check=False)
    assert res.returncode == 2 and "no array 'points'" in res.stderr and "Traceback" not in res.stderr


def test_ctrl_c_exits_130_and_keeps_the_samples(tmp_path):
    """SIGINT mid-run: status 130, the samples so far written whole (renamed into place)."""
    import signal
    import time
    out = tmp_path / "big.npz"
    # SIG_DFL in the child, whatever the suite inherited (a background job ignores SIGINT)
    proc = subprocess.Popen([sys.executable, "-m", "vpds", "sample", "--radius", "0.0002",
                             "-o", str(out), "--no-progress"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(3)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stdout + stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    z = np.load(out)
    assert 0 < len(z["points"]) and [p.name for p in tmp_path.iterdir()] == ["big.npz"]
    res = vpds("analyze", str(out), check=False)
    assert res.returncode == 3 and "the run was interrupted" in res.stdout


def test_sample_and_help_without_scipy_or_matplotlib(tmp_path):
    """The package, its CLI and `vpds sample` need numpy and cffi alone; a plot or an analysis
    without their package is one line naming the pip install, status 2."""
    blocker = tmp_path / "sitecustomize.py"
    blocker.write_text(
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in ('scipy', 'matplotlib'):\n"
        "            raise ImportError(f'blocked: {name}')\n"
        "sys.meta_path.insert(0, Block())\n")
    env = dict(os.environ, PYTHONPATH=str(tmp_path))

    def run(*args):
        return subprocess.run([sys.executable, "-m", "vpds", *args], capture_output=True,
                              text=True, env=env, cwd=tmp_path)
    res = subprocess.run([sys.executable, "-c", "import vpds, vpds.cli, sys; "
                          "assert 'scipy' not in sys.modules and 'matplotlib' not in sys.modules"],
                         capture_output=True, text=True, env=env)
    assert res.returncode == 0, res.stderr
    assert run("--help").returncode == 0 and run("sample", "--help").returncode == 0
    res = run("sample", "--radius", "0.05", "-o", "a.npz", "--no-progress")
    assert res.returncode == 0 and (tmp_path / "a.npz").exists(), res.stderr
    res = run("sample", "--radius", "0.05", "--plot", "a.png", "--no-progress")
    assert res.returncode == 2 and "pip install matplotlib" in res.stderr
    assert "Traceback" not in res.stderr
    res = run("analyze", "a.npz")
    assert res.returncode == 2 and "pip install scipy" in res.stderr and "Traceback" not in res.stderr


# -- bad input: one line naming the option and the value, status 2, no traceback -------------------

def assert_usage_error(res, *names):
    """Status 2, one line on stderr naming each of `names`, no traceback."""
    assert res.returncode == 2, res.stdout + res.stderr
    assert "Traceback" not in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1, res.stderr
    for name in names:
        assert name in res.stderr, (name, res.stderr)


def run_in(tmp_path, *args, env=None):
    return subprocess.run([sys.executable, "-m", "vpds", *args], capture_output=True, text=True,
                          cwd=tmp_path, env=env)


@pytest.mark.parametrize("args, names", [
    (["--refine", "abc"], ["--refine 'abc'", "expected scales"]),
    (["--refine", "0.5,,0.4"], ["--refine '0.5,,0.4'"]),
    (["--refine", "-1"], ["--refine '-1'", "scale -1"]),
    (["--refine", "0.5,0.8"], ["--refine '0.5,0.8'", "above the one before"]),
    (["--sizing", "", "--lipschitz", "0.1"], ["--sizing ''", "empty"]),
    (["--stream", "10", "--refine", "0.5"], ["--stream with --refine"]),
    (["--stream", "-1"], ["--stream -1"]),
    (["--channel", "R"], ["--channel R", "without --sizing-exr"]),
    (["--exr-range", "0.01,0.05"], ["--exr-range 0.01,0.05", "without --sizing-exr"]),
    (["--workers", "2"], ["--workers 2", "without --tiles"]),
    (["--radius-max", "0.1"], ["--radius-max 0.1", "without --threads or --tiles"]),
    (["--lipschitz", "-1", "--sizing", "0.05 + 0*x[0]"], ["--lipschitz -1", ">= 0"]),
    (["--tiles", "-1", "-o", "t.zarr"], ["--tiles '-1'", ">= 1"]),
    (["--tiles", "2,0", "-o", "t.zarr"], ["--tiles '2,0'", ">= 1"]),
    (["--tiles", "100000", "-o", "t.zarr"], ["--tiles '100000'", "use fewer"]),
    (["--tiles", "2", "--periodic", "x", "-o", "t.zarr"], ["--periodic 'x'"]),
    (["--sizing", "0.01 + x[5]", "--lipschitz", "0.1", "--lo", "0,2", "--hi", "1,4"],
     ["--sizing", "the box centre, x = (0.5, 3)"]),
])
def test_option_values_are_named_when_refused(tmp_path, args, names):
    res = run_in(tmp_path, "sample", *args, "--no-progress")
    assert_usage_error(res, *names)
    assert "samples in" not in res.stdout and not list(tmp_path.iterdir())


def test_dim_help_says_what_the_library_accepts():
    from vpds import MAX_DIM
    text = " ".join(vpds("sample", "--help").stdout.split())
    assert f"dimension, 1 to {MAX_DIM}" in text


def test_stream_0_gives_an_empty_sampling(tmp_path):
    res = run_in(tmp_path, "sample", "--stream", "0", "-o", "s.npz", "--no-progress")
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith("0 samples in 2D")
    z = np.load(tmp_path / "s.npz")
    assert z["points"].shape == (0, 2)
    res = run_in(tmp_path, "analyze", "s.npz")
    assert_usage_error(res, "s.npz", "no points")


@pytest.mark.parametrize("name, content, names", [
    ("bad.wkt", "POLYGON((0 0, 1 0", ["--domain bad.wkt", "not a WKT polygon"]),
    ("empty.wkt", "", ["--domain empty.wkt", "not a WKT polygon"]),
    ("point.wkt", "POINT (0.5 0.5)", ["--domain point.wkt", "not a polygon"]),
    ("garbage.png", "garbage", ["--domain garbage.png", "cannot read it as an image"]),
    ("empty.png", "", ["--domain empty.png", "cannot read it as an image"]),
    ("foo.xyz", "x", ["--domain foo.xyz", ".xyz: not an image"]),
])
def test_a_domain_file_that_cannot_be_read_names_domain(tmp_path, name, content, names):
    if name.endswith(".wkt"):
        pytest.importorskip("shapely")
    else:
        pytest.importorskip("PIL")
    (tmp_path / name).write_text(content)
    res = run_in(tmp_path, "sample", "--domain", name, "--no-progress")
    assert_usage_error(res, *names)


def test_a_domain_mask_of_the_wrong_dimension_names_domain(tmp_path):
    np.save(tmp_path / "mask.npy", np.ones((4, 4, 4), bool))
    res = run_in(tmp_path, "sample", "--domain", "mask.npy", "--no-progress")
    assert_usage_error(res, "--domain mask.npy", "d = 2")


def test_a_corrupt_exr_names_sizing_exr(tmp_path):
    pytest.importorskip("OpenEXR")
    (tmp_path / "garbage.exr").write_text("garbage")
    res = run_in(tmp_path, "sample", "--sizing-exr", "garbage.exr", "--no-progress")
    assert_usage_error(res, "--sizing-exr garbage.exr", "not a readable OpenEXR file")


@pytest.mark.parametrize("where", ["sample", "analyze", "mesh"])
@pytest.mark.parametrize("plot, message", [("/nonexistent/x.png", "directory /nonexistent does not exist"),
                                           ("foo.txt", "unsupported extension '.txt'"),
                                           ("foo", "unsupported extension '(none)'")])
def test_a_plot_path_is_checked_before_sampling(tmp_path, where, plot, message):
    pytest.importorskip("matplotlib")
    if where == "analyze":
        np.save(tmp_path / "p.npy", np.random.default_rng(0).random((20, 2)))
        args = ["analyze", "p.npy", "--radius", "0.1"]
    elif where == "mesh":
        pytest.importorskip("trimesh")
        (tmp_path / "tet.obj").write_text(TETRAHEDRON)
        args = ["sample", "--mesh", "tet.obj", "--no-progress"]
    else:
        args = ["sample", "--no-progress"]
    res = run_in(tmp_path, *args, "--plot", plot)
    assert_usage_error(res, f"--plot {plot}", message)
    assert res.stdout == ""  # refused before any sampling or analysis


def test_an_unwritable_output_directory_is_refused_before_sampling(tmp_path):
    if not os.path.isdir("/proc"):
        pytest.skip("needs /proc, where no file can be created even by root")
    res = run_in(tmp_path, "sample", "-o", "/proc/a.npz", "--no-progress")
    assert_usage_error(res, "-o /proc/a.npz", "not writable")
    assert res.stdout == ""


def test_a_failed_write_is_one_line(tmp_path):
    """An OSError while writing (here: the target is a directory) is one line, no traceback,
    and leaves no temporary file behind."""
    (tmp_path / "out.npz").mkdir()
    res = run_in(tmp_path, "sample", "--radius", "0.1", "-o", "out.npz", "--no-progress")
    assert_usage_error(res, "-o out.npz", "cannot write it")
    assert "samples in" in res.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["out.npz"]


def blocking(tmp_path, *modules):
    """An environment in which importing `modules` fails, as when they are not installed."""
    (tmp_path / "sitecustomize.py").write_text(
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        f"        if name.split('.')[0] in {modules!r}:\n"
        "            raise ImportError(f'blocked: {name}')\n"
        "sys.meta_path.insert(0, Block())\n")
    return dict(os.environ, PYTHONPATH=str(tmp_path))


def test_missing_tiling_dependencies_are_one_line_naming_the_install(tmp_path):
    env = blocking(tmp_path, "zarr", "distributed", "dask", "cloudpickle")
    res = run_in(tmp_path, "sample", "--tiles", "2", "-o", "t.zarr", "--no-progress", env=env)
    assert_usage_error(res, "--tiles", "pip install", "zarr")
    res = run_in(tmp_path, "sample", "--threads", "2", "--sizing", "0.05+0*x[0]", "--lipschitz",
                 "0.1", "--radius-max", "0.05", "--no-progress", env=env)
    assert_usage_error(res, "--threads", "pip install cloudpickle")
    assert not (tmp_path / "t.zarr").exists()


@pytest.fixture(scope="module")
def sampled(tmp_path_factory):
    out = tmp_path_factory.mktemp("analyze") / "good.npz"
    vpds("sample", "--radius", "0.1", "--seed", "1", "-o", str(out), "--no-progress")
    return out


@pytest.mark.parametrize("flag, value", [("--coverage", "0"), ("--inhibition", "-1"),
                                         ("--lipschitz", "-1"), ("--radius", "-1"),
                                         ("--scale", "-1"), ("--scale", "nan"),
                                         ("--coverage", "inf")])
def test_analyze_refuses_a_flag_that_cannot_hold(sampled, flag, value):
    res = vpds("analyze", str(sampled), flag, value, check=False)
    assert_usage_error(res, f"{flag} {value}", "must be finite")
    assert res.stdout == ""  # no verdict


def test_analyze_refuses_points_it_cannot_check(tmp_path):
    np.save(tmp_path / "empty.npy", np.zeros((0, 2)))
    np.save(tmp_path / "nan.npy", np.full((5, 2), np.nan))
    res = run_in(tmp_path, "analyze", "empty.npy", "--radius", "0.05")
    assert_usage_error(res, "empty.npy", "no points")
    res = run_in(tmp_path, "analyze", "nan.npy", "--radius", "0.05")
    assert_usage_error(res, "nan.npy", "5 of 5 points", "non-finite")
    (tmp_path / "bad.csv").write_text("x0,x1\n0.1,0.2\n0.5,0.5\n")
    res = run_in(tmp_path, "analyze", "bad.csv")
    assert_usage_error(res, "bad.csv", "no column r", "--radius")
    assert ".npy" not in res.stderr


TETRAHEDRON = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


@pytest.mark.parametrize("args, names", [
    (["--refine", "abc"], ["--refine 'abc'"]),
    (["--refine", "0.5,,0.4"], ["--refine '0.5,,0.4'"]),
    (["--refine", "-1"], ["--refine '-1'"]),
    (["--threads", "2"], ["--threads", "not available with --mesh"]),
    (["--sizing", "", "--lipschitz", "0.1"], ["--sizing ''", "empty"]),
    (["--sizing", "0.1 + x[3]", "--lipschitz", "0.1"],
     ["--sizing", "the centre of the mesh's bounding box, x = 0.5 (3 coordinates"]),
])
def test_mesh_option_mistakes_name_the_option(tmp_path, args, names):
    pytest.importorskip("trimesh")
    (tmp_path / "tet.obj").write_text(TETRAHEDRON)
    res = run_in(tmp_path, "sample", "--mesh", "tet.obj", *args, "--no-progress")
    assert_usage_error(res, *names)
    assert "box centre" not in res.stderr


@pytest.mark.parametrize("where", ["sample", "mesh-run", "mesh-stream"])
def test_a_stream_or_mesh_run_that_cannot_fit_is_refused_with_its_figure(tmp_path, where):
    # the stream goes on to any count, and a mesh has no C estimate: both grew without end
    if where == "sample":
        args = ["sample", "--stream", "100000000000"]
    else:
        pytest.importorskip("trimesh")
        (tmp_path / "tet.obj").write_text(TETRAHEDRON)
        args = ["sample", "--mesh", "tet.obj"] + (["--radius", "1e-7"] if where == "mesh-run"
                                                  else ["--stream", "100000000000"])
    res = run_in(tmp_path, *args, "--no-progress", "-o", "out.npz")
    assert_usage_error(res, "samples", "need at least", "MiB")
    assert not (tmp_path / "out.npz").exists()
