"""PoissonDisk(workers=N) and `vpds sample --threads N`: the tiled process on threads. The
tiling decides the points (the same bytes for every worker count, those of vpds.tiling's run of
the same tiles), every guarantee holds across the seams, workers=1 stays the serial process,
and what the tiled process does not offer is refused with a message."""
import re
import subprocess
import sys

import numpy as np
import pytest

import vpds
from vpds import analysis as C
from vpds._tiled import auto_tiles
from vpds.tiling import Tiling, TilingSpec


def fill(**kw):
    kw.setdefault("progress", False)
    return vpds.PoissonDisk(**kw).fill_space()


@pytest.mark.parametrize("kw", [
    dict(d=2, radius=0.004, rng=3),  # "auto": 3 x 3 tiles
    dict(d=2, radius=0.02, rng=4, inhibition=0.5, rule="bigger", tiles=4),
    dict(d=3, radius=0.06, rng=5, periodic=[True, False, True], tiles=(2, 3, 4)),
    dict(d=2, sizing=np.linspace(0.01, 0.04, 9)[:, None] * np.ones((9, 9)), rule="prior", rng=6,
         tiles=(5, 3)),
])
def test_every_worker_count_gives_the_same_bytes(kw):
    two = vpds.PoissonDisk(workers=2, progress=False, **kw)
    ref = two.fill_space()
    assert two.stats["threads"] == 2
    for workers in (3, -1):
        assert np.array_equal(fill(workers=workers, **kw), ref)
    kw.setdefault("tiles", "auto")
    one = vpds.PoissonDisk(progress=False, **kw)  # one thread, the same tiling
    assert np.array_equal(one.fill_space(), ref)
    assert one.stats["threads"] == 1 and one.stats["tiles"] > 1
    del kw["tiles"]
    serial = fill(**kw)
    assert len(serial) > 100 and not np.array_equal(serial, ref)  # another process
    assert np.array_equal(serial, fill(workers=1, **kw))


def test_the_points_are_the_tilings_and_hold_every_guarantee():
    kw = dict(d=2, radius=0.003, rng=11, inhibition=0.6, rule="smaller")
    engine = vpds.PoissonDisk(workers=2, progress=False, **kw)
    x = engine.fill_space()
    r = engine.radii
    tiles = auto_tiles(engine.l_bounds, engine.u_bounds, None, 0.003)
    assert tiles == (5, 5) and engine.stats["tiles"] == 25
    spec = TilingSpec.make(2, tiles, radius=0.003, inhibition=0.6, rule="smaller", rng=11)
    tx, tr, _ = Tiling(spec).run(workers=1)
    assert np.array_equal(x, tx) and np.array_equal(r, tr)
    assert np.all(engine.scales == 1) and not engine.fixed.any()
    # conflict-free at R_f, covered at R_c, across every seam
    assert C.empty_disk_violations(x, r, "smaller", 0.6, 0.0) == 0
    sizing = C.sizing_named("const", 0.003)
    assert C.check_maximal(x, r, "smaller", 1.0, sizing, np.zeros(2), np.ones(2)).gaps == 0


def test_auto_tiles_come_from_the_box_and_the_margin_only():
    lo, hi = np.zeros(2), np.array([1.0, 0.5])
    assert auto_tiles(lo, hi, None, 0.001) == (15, 7)  # sides of about 64 margins
    assert auto_tiles(lo, hi, [False, True], 0.001) == (15, 6)  # even on a periodic axis
    assert auto_tiles(np.zeros(3), np.ones(3), None, 0.02) == (4, 4, 4)
    assert auto_tiles(lo, hi, None, 0.4) == (1, 1)
    with pytest.raises(ValueError, match="periodic axis 1 .* shorter than two margins"):
        auto_tiles(lo, hi, [False, True], 0.3)


def test_what_the_tiled_process_does_not_offer_is_refused():
    engine = vpds.PoissonDisk(2, radius=0.05, workers=2, progress=False)
    for call, name in ((lambda: engine.random(10), "random(10)"), (lambda: engine.refine(0.5), "refine"),
                       (lambda: next(engine.stream()), "stream"),
                       (lambda: engine.progressive(5), "progressive"),
                       (lambda: engine.add_points([[0.5, 0.5]]), "add_points"),
                       (lambda: engine.fast_forward(3), "random(3)")):
        with pytest.raises(ValueError, match=re.escape(name) + ".*samples by tiles.*workers=1"):
            call()
    x = engine.random(float("inf"))  # fill_space, as scipy spells it
    assert len(x) > 100 and len(engine.fill_space()) == 0 and engine.num_generated == len(x)
    engine.reset()
    assert np.array_equal(engine.fill_space(), x)
    for bad in (0, -2, 1.5, True, "2"):
        with pytest.raises(ValueError, match="workers = .*must be an int >= 1, or -1"):
            vpds.PoissonDisk(2, workers=bad)
    with pytest.raises(ValueError, match="does not take domain, fixed_points"):
        vpds.PoissonDisk(2, workers=2, domain=lambda p: np.linalg.norm(p - 0.5, axis=1) - 0.3,
                         fixed_points=[[0.5, 0.5]])
    with pytest.raises(ValueError, match="does not take memory_limit"):
        vpds.PoissonDisk(2, tiles=4, memory_limit=1 << 30)
    with pytest.raises(ValueError, match="tilings have at most 8 axes"):
        vpds.PoissonDisk(9, radius=1.0, workers=2)
    with pytest.raises(ValueError, match="tiles = 'some'"):
        vpds.PoissonDisk(2, tiles="some").fill_space()
    with pytest.raises(ValueError, match="radius_max"):
        vpds.PoissonDisk(2, sizing=lambda p: 0.02 + 0.0 * p[:, 0], lipschitz=0.1,
                         workers=2).fill_space()


def test_a_python_sizing_runs_on_the_calling_thread_with_the_same_points():
    kw = dict(d=2, sizing=lambda p: 0.01 + 0.03 * p[:, 0], lipschitz=0.03, radius_max=0.04,
              rule="smaller", rng=8)
    engine = vpds.PoissonDisk(workers=2, progress=False, **kw)
    x = engine.fill_space()
    assert engine.stats["threads"] == 1 and len(x) > 200  # the callable kept it serial
    assert np.array_equal(fill(workers=3, **kw), x)
    assert C.empty_disk_violations(x, engine.radii, "smaller", 1.0, 0.03) == 0


def vpds_cli(*args):
    return subprocess.run([sys.executable, "-m", "vpds", *args], capture_output=True, text=True)


def test_cli_threads(tmp_path):
    out = tmp_path / "t.npz"
    res = vpds_cli("sample", "--radius", "0.02", "--seed", "4", "--threads", "2", "-o", str(out),
                   "--no-progress")
    assert res.returncode == 0 and "maximal: True" in res.stdout
    assert np.array_equal(np.load(out)["points"], fill(d=2, radius=0.02, rng=4, workers=2))
    res = vpds_cli("analyze", str(out))
    assert res.returncode == 0 and "all guarantees hold" in res.stdout
    for args, message in ((["--threads", "0"], "--threads 0: must be >= 1, or -1"),
                          (["--threads", "2", "--stream", "5"], "--stream is not available with --threads"),
                          (["--threads", "2", "--sizing", "0.02+0.01*x[0]", "--lipschitz", "0.01"],
                           "needs --radius-max"),
                          (["--threads", "2", "--tiles", "2", "-o", str(tmp_path / "a.zarr")],
                           "--threads is not available with --tiles")):
        res = vpds_cli("sample", *args, "--no-progress")
        assert res.returncode == 2 and message in res.stderr and "Traceback" not in res.stderr


def test_tiling_run_reports_progress_and_stops_on_an_exception():
    """Tiling.run works in C calls of at most 16 tiles per thread: progress(done, total) after
    each, growing to the total; an exception raised there (Ctrl-C is a KeyboardInterrupt) stops
    the run at once, and a new run gives the bytes of an uninterrupted one."""
    spec = TilingSpec.make(2, (12, 12), radius=0.004, rng=21)
    tiling = Tiling(spec)
    ref = tiling.run(workers=2)
    seen = []
    x = tiling.run(workers=2, progress=lambda done, total: seen.append((done, total)))
    assert all(np.array_equal(a, b) for a, b in zip(x, ref))
    done = [d for d, _ in seen]
    assert {t for _, t in seen} == {144} and done[-1] == 144
    assert all(0 < b - a <= 32 for a, b in zip([0] + done, done)), done
    assert len(seen) >= 144 // 32

    calls = []

    def interrupt(done, total):
        calls.append(done)
        if len(calls) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        tiling.run(workers=1, progress=interrupt)
    assert calls == [16, 32]  # stopped after the second call of 16 tiles
    again = tiling.run(workers=1)
    assert all(np.array_equal(a, b) for a, b in zip(again, ref))


def test_a_tiled_fill_shows_its_tiles_on_the_progress_bar(monkeypatch):
    tqdm_auto = pytest.importorskip("tqdm.auto")
    bars = []

    class Bar:
        def __init__(self, **kw):
            self.kw, self.n, self.closed = kw, 0, False
            bars.append(self)

        def update(self, k):
            self.n += k

        def close(self):
            self.closed = True

    monkeypatch.setattr(tqdm_auto, "tqdm", Bar)
    x = vpds.PoissonDisk(2, radius=0.01, rng=2, workers=2, tiles=6, progress=True).fill_space()
    assert np.array_equal(x, fill(d=2, radius=0.01, rng=2, workers=2, tiles=6))
    assert len(bars) == 1 and bars[0].kw["total"] == 36 and bars[0].n == 36 and bars[0].closed
