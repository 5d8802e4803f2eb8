"""Tiled sampling (vpds.distributed): the guarantees across seams checked whole by the
independent checkers of vpds.analysis, the same bytes for 1, 2 and 4 Dask workers and for other
task orders, a killed worker and an interrupted run resumed to the same bytes, grids read per
tile equal to the same grid in memory, and the seam statistics the README claims."""
from __future__ import annotations

import os
import signal
from pathlib import Path

import subprocess
import sys

import numpy as np
import pytest
from scipy import stats

import vpds
from vpds import analysis as A
from vpds import distributed as D
from vpds.tiling import Tiling, TilingSpec

pytest.importorskip("distributed")
pytest.importorskip("zarr")


def wave(y: np.ndarray) -> np.ndarray:
    return 0.03 + 0.01 * np.sin(6.0 * y[:, 0]) * np.cos(5.0 * y[:, 1])


WAVE_L = 0.01 * np.hypot(6.0, 5.0)


def all_bytes(store: D.TileStore) -> list[bytes]:
    """Every stored array of every tile, as bytes (the comparison the issue asks for)."""
    out = []
    for k in range(store.count):
        x, r, t = store.read(k)
        out += [x.tobytes(), r.tobytes(), t.tobytes()]
    return out


def checked(store: D.TileStore, rule: str, sizing: A.Sizing, lo, hi, *, inhibition=1.0,
            coverage=1.0, periodic=None) -> int:
    """Conflict-free in the run's order (phase, tile, insertion) and maximal: the whole union."""
    assert not store.missing()
    x, r, _ = store.to_numpy("insertion")
    assert len(x) > 50
    assert A.empty_disk_violations(x, r, rule, inhibition, sizing.lipschitz, periodic=periodic,
                                   lo=np.asarray(lo), hi=np.asarray(hi)) == 0
    rep = A.check_maximal(x, r, rule, coverage, sizing, np.asarray(lo, float), np.asarray(hi, float),
                          probes=20_000, periodic=periodic)
    assert rep.gaps == 0 and rep.unresolved_bound <= 1e-6, rep
    return len(x)


# -- the guarantees across seams, checked whole ------------------------------------------------

@pytest.mark.parametrize("rule", ["prior", "current", "bigger", "smaller"])
def test_seams_conflict_free_and_maximal_every_rule(tmp_path, rule):
    lo, hi = (0.0, 0.0), (1.0, 0.8)
    spec = TilingSpec.make(2, (4, 3), u_bounds=hi, sizing=wave, lipschitz=WAVE_L, radius_max=0.04,
                           rule=rule, rng=11)
    store = D.run_local(tmp_path / "s.zarr", spec)
    checked(store, rule, A.Sizing(wave, WAVE_L), lo, hi)
    # the Table 1 Delaunay bounds follow from the two properties, so they hold across seams too
    x, r, _ = store.to_numpy()
    sizing = A.Sizing(wave, WAVE_L)
    rep = A.check_delaunay(x, r, rule, WAVE_L, np.array(lo), np.array(hi), sizing)
    assert rep.triangles > 500
    assert rep.min_angle_deg >= rep.angle_bound_deg, rep
    assert rep.edge_min_ratio >= rep.edge_min_bound * (1 - 1e-12), rep
    assert rep.edge_max_ratio <= rep.edge_max_bound, rep
    assert rep.circumradius_ratio <= rep.circumradius_bound * (1 + 1e-12), rep


def test_seams_periodic_two_radii_and_3d(tmp_path):
    per = (True, True)
    spec = TilingSpec.make(2, (4, 2), u_bounds=(1.0, 0.8), radius=0.03, periodic=per, rng=2)
    checked(D.run_local(tmp_path / "p.zarr", spec), "smaller",
            A.Sizing(lambda y: np.full(len(y), 0.03), 0.0), (0, 0), (1.0, 0.8), periodic=per)
    spec = TilingSpec.make(2, (3, 3), radius=0.03, inhibition=0.5, coverage=1.0, rng=3)
    checked(D.run_local(tmp_path / "two.zarr", spec), "smaller",
            A.Sizing(lambda y: np.full(len(y), 0.03), 0.0), (0, 0), (1, 1), inhibition=0.5)
    spec = TilingSpec.make(3, (2, 2, 2), radius=0.08, rng=4)
    checked(D.run_local(tmp_path / "3d.zarr", spec), "smaller",
            A.Sizing(lambda y: np.full(len(y), 0.08), 0.0), (0, 0, 0), (1, 1, 1))


@pytest.mark.parametrize("sizing", ["grid", "callable"])
def test_tiling_run_on_threads_is_run_tile_over_the_order_and_the_dask_run(tmp_path, sizing):
    """The C library's threads (vpds_tiling_run) give the bytes of the tiles run one by one,
    for any number of workers, and the points of the Dask path's store."""
    if sizing == "grid":
        g = np.linspace(0.02, 0.05, 9)[:, None] * np.ones((1, 7))
        spec = TilingSpec.make(2, (4, 3), u_bounds=(1.0, 0.8), sizing=g, rng=5)
    else:
        spec = TilingSpec.make(2, (4, 3), u_bounds=(1.0, 0.8), sizing=wave, lipschitz=WAVE_L,
                               radius_max=0.04, rng=5)
    tg = Tiling(spec)
    done: dict[int, tuple] = {}
    for tile in tg.order():
        x, r, _ = tg.run_tile(tile, {k: done[k] for k in tg.deps(tile)})
        done[tile] = (x, r)
    ref = np.concatenate([done[k][0] for k in tg.order()])
    for workers in (1, 2, 3, -1):
        x, r, tiles = tg.run(workers=workers)
        assert x.shape == ref.shape and np.array_equal(x, ref), workers
        assert list(dict.fromkeys(tiles.tolist())) == [k for k in tg.order() if len(done[k][0])]
    store = D.run_local(tmp_path / "t.zarr", spec)
    xs, _, _ = store.to_numpy()
    assert np.array_equal(np.unique(xs, axis=0), np.unique(ref, axis=0))
    with pytest.raises(ValueError, match="workers = 0"):
        tg.run(workers=0)


@pytest.mark.parametrize("case", ["periodic wave", "two radii", "3d"])
def test_rims_give_the_bytes_of_whole_tiles(case):
    """A tile's rim (Tiling.rim: its samples within the margin of its faces) is all a later tile
    takes from it: run_tile given rims makes the bytes it makes given whole tiles, across
    periodic wraps too, and the rims are a small part of the tiles."""
    if case == "periodic wave":
        spec = TilingSpec.make(2, (4, 4), sizing=wave, lipschitz=WAVE_L, radius_max=0.04,
                               periodic=(True, True), rule="bigger", rng=11)
    elif case == "two radii":
        spec = TilingSpec.make(2, (5, 3), u_bounds=(1.0, 0.6), radius=0.02, inhibition=0.5, rng=12)
    else:
        spec = TilingSpec.make(3, (3, 4, 2), radius=0.06, periodic=(False, True, True), rng=13)
    tg = Tiling(spec)
    whole: dict[int, tuple] = {}
    rims: dict[int, tuple] = {}
    kept = total = 0
    for tile in tg.order():
        x, r, t = tg.run_tile(tile, {k: whole[k] for k in tg.deps(tile)})
        xr, rr, tr = tg.run_tile(tile, {k: rims[k] for k in tg.deps(tile)})
        assert x.tobytes() == xr.tobytes() and r.tobytes() == rr.tobytes() and t.tobytes() == tr.tobytes(), tile
        whole[tile] = (x, r)
        rims[tile] = tg.rim(tile, x, r)
        kept, total = kept + len(rims[tile][0]), total + len(x)
    assert 0 < kept < 0.8 * total, (kept, total)


def test_tile_store_written_directly_reads_back_through_zarr(tmp_path, monkeypatch):
    """TileStore.write lays out Zarr v3 arrays itself (no zarr round trips): zarr reads them back
    whole, over several chunks, and an empty tile."""
    import zarr
    from vpds import tilestore
    store = D.TileStore.create(tmp_path / "s.zarr", {"d": 2}, "token", [0, 1, 2])
    rng = np.random.default_rng(3)
    x, r, t = rng.random((23, 2)), rng.random(23), rng.random(23)
    monkeypatch.setattr(tilestore, "_ROWS_PER_CHUNK", 7)
    store.write(1, x, r, t)
    store.write(2, np.empty((0, 2)), np.empty(0), np.empty(0))
    monkeypatch.setattr(tilestore, "_ROWS_PER_CHUNK", 1 << 20)
    store.write(0, x[::-1], r[::-1], t[::-1])
    a = zarr.open_array(str(tmp_path / "s.zarr" / "tiles" / "1" / "points"), mode="r")
    assert a.chunks == (7, 2) and np.array_equal(a[...], x)
    got = D.TileStore(tmp_path / "s.zarr").read(1)
    assert all(np.array_equal(u, v) for u, v in zip(got, (x, r, t)))
    assert np.array_equal(D.TileStore(tmp_path / "s.zarr").read(0)[0], x[::-1])
    empty = D.TileStore(tmp_path / "s.zarr").read(2)
    assert empty[0].shape == (0, 2) and empty[1].shape == (0,)
    assert [store.tile_count(k) for k in range(3)] == [23, 23, 0] and not store.missing()
    assert zarr.open_group(str(tmp_path / "s.zarr" / "tiles" / "1"), mode="r").attrs["phase"] == 1


def test_default_tiles_follow_the_box_and_the_radii():
    """tiles=None: about TILE_SAMPLES estimated samples a tile (at least MIN_TILES tiles while
    each holds MIN_TILE_SAMPLES), near-cubic tiles, even counts on periodic axes, thinned until
    the C tiling accepts them; the same arguments give the same tiles."""
    from vpds import tiling as T
    big = TilingSpec.make(2, None, radius=0.0003, rng=1)
    n = T.estimated_samples(big)
    assert n > 20 * T.TILE_SAMPLES
    assert 0.5 * T.TILE_SAMPLES < n / np.prod(big.tiles) < 2 * T.TILE_SAMPLES, big.tiles
    assert big.tiles[0] == big.tiles[1] and TilingSpec.make(2, None, radius=0.0003, rng=9).tiles == big.tiles
    mid = TilingSpec.make(2, None, radius=0.001)  # 7e5 samples: the floor of MIN_TILES tiles
    assert np.prod(mid.tiles) >= T.MIN_TILES and mid.tiles[0] == mid.tiles[1]
    small = TilingSpec.make(2, None, radius=0.05)
    assert small.tiles == (1, 1)
    long = TilingSpec.make(2, None, radius=0.001, u_bounds=(1.0, 40.0))
    assert long.tiles[1] > 20 * long.tiles[0], long.tiles
    per = TilingSpec.make(3, None, radius=0.004, periodic=(True, False, True))
    assert per.tiles[0] % 2 == 0 and per.tiles[2] % 2 == 0 and min(per.tiles) >= 2
    thin = TilingSpec.make(2, None, radius=0.0004, u_bounds=(1.0, 0.001))  # 5,000 samples: one tile
    assert thin.tiles == (1, 1)
    slab = TilingSpec.make(3, None, radius=0.0004, u_bounds=(1.0, 1.0, 0.001))  # the thin axis gets 1
    assert slab.tiles[2] == 1 and slab.tiles[0] == slab.tiles[1]
    assert 0.5 * T.TILE_SAMPLES < T.estimated_samples(slab) / np.prod(slab.tiles) < 2 * T.TILE_SAMPLES
    with pytest.raises(vpds.VpdsValueError, match=r"periodic\[1\]: the side 0.5"):  # the C message
        TilingSpec.make(2, None, radius=0.3, u_bounds=(1.0, 0.5), periodic=(False, True))


def test_refused_tilings_name_the_argument(tmp_path):
    with pytest.raises(vpds.VpdsValueError, match=r"tiles\[0\] = 3: a periodic axis needs an even"):
        TilingSpec.make(2, (3, 4), radius=0.02, periodic=(True, False))
    with pytest.raises(vpds.VpdsValueError, match=r"tiles\[1\] = 50: the tile side 0.02 is below the margin"):
        TilingSpec.make(2, (4, 50), radius=0.03)
    with pytest.raises(vpds.VpdsValueError, match="radius_max"):
        TilingSpec.make(2, (2, 2), sizing=wave, lipschitz=WAVE_L)
    spec = TilingSpec.make(2, (2, 2), radius=0.05, rng=1)
    D.run_local(tmp_path / "a.zarr", spec)
    other = TilingSpec.make(2, (2, 2), radius=0.05, rng=2)
    with pytest.raises(ValueError, match="holds another run.*seed"):
        D.run_local(tmp_path / "a.zarr", other)
    with pytest.raises(ValueError, match=r"tile 3 \(phase 3\) needs tiles \[0, 1, 2\] first"):
        D.run_local(tmp_path / "b.zarr", spec, order=[3])


# -- the same bytes whatever the workers and the order -------------------------------------------

@pytest.fixture(scope="module")
def cluster():
    from distributed import Client, LocalCluster
    c = LocalCluster(n_workers=4, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = Client(c)
    yield c, client
    client.close()
    try:
        c.close()
    except KeyError:  # dask's bookkeeping of a worker it restarted; the cluster is closed
        pass


ARGS = dict(u_bounds=(1.0, 0.9), sizing=wave, lipschitz=WAVE_L, radius_max=0.04, rule="bigger", rng=7)


def test_one_two_four_workers_and_two_orders_same_bytes(tmp_path, cluster):
    c, client = cluster
    ref_spec = TilingSpec.make(2, (4, 4), **ARGS)
    tiling = Tiling(ref_spec)
    # order 1: by phase, tiles descending within a phase, in this process (no Dask)
    reverse = sorted(range(tiling.count), key=lambda k: (tiling.phase(k), -k))
    ref = all_bytes(D.run_local(tmp_path / "ref.zarr", ref_spec, order=reverse))
    # order 2: depth first, each tile right after its own cone (an engine's on-demand order)
    order, done = [], set()
    for k in range(tiling.count - 1, -1, -1):
        for j in tiling.cone(k) + [k]:
            if j not in done:
                order.append(j)
                done.add(j)
    assert order != reverse
    assert all_bytes(D.run_local(tmp_path / "lazy.zarr", ref_spec, order=order)) == ref
    for n in (4, 2, 1):
        c.scale(n)
        client.wait_for_workers(n)
        while len(client.scheduler_info()["workers"]) != n:
            client.sync(lambda: __import__("asyncio").sleep(0.1))
        store = D.sample(tmp_path / f"w{n}.zarr", 2, (4, 4), client=client, progress=False, **ARGS)
        assert all_bytes(store) == ref, f"{n} workers gave other bytes"
    c.scale(4)
    client.wait_for_workers(4)


@pytest.fixture
def own_cluster():
    """A cluster of its own for the test that kills a worker: the shared one stays clean."""
    from distributed import Client, LocalCluster
    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = Client(c)
    yield c, client
    client.close()
    try:
        c.close()
    except KeyError:  # dask's bookkeeping of the worker we killed (its old address), not ours
        pass


def test_killed_worker_and_interrupt_then_resume(tmp_path, own_cluster):
    c, client = own_cluster
    args = dict(ARGS, sizing=None, radius=0.004, rule="smaller")
    args.pop("lipschitz"), args.pop("radius_max")
    ref = all_bytes(D.run_local(tmp_path / "ref.zarr", TilingSpec.make(2, (6, 6), **args)))
    pids = client.run(os.getpid)
    victim = next(iter(pids.values()))
    seen = []

    class Stop(Exception):
        pass

    def on_tile(tile, n):
        seen.append(tile)
        if len(seen) == 3:
            os.kill(victim, signal.SIGKILL)  # a real worker process dies mid-run
        if len(seen) == 14:
            raise Stop  # like Ctrl-C: the client stops waiting, some tiles are written

    path = tmp_path / "run.zarr"
    with pytest.raises(Stop):
        D.sample(path, 2, (6, 6), client=client, progress=False, on_tile=on_tile, **args)
    store = D.TileStore(path)
    assert 14 <= 36 - len(store.missing()) < 36
    assert victim not in client.run(os.getpid).values()  # the nanny started a new process
    again = []
    store = D.sample(path, 2, (6, 6), client=client, progress=False,
                     on_tile=lambda k, n: again.append(k), **args)
    assert not store.missing()
    assert len(again) < 36 - 13  # the tiles written before the stop were not run again
    assert all_bytes(store) == ref


# -- a grid read per tile ------------------------------------------------------------------------

def test_grid_per_tile_equals_grid_in_memory(tmp_path):
    u = np.linspace(0, 1, 61)[:, None]
    v = np.linspace(0, 1, 47)[None, :]
    grid = 0.02 + 0.01 * u ** 2 + 0.005 * np.sin(4 * v)
    np.save(tmp_path / "g.npy", grid)
    mem = TilingSpec.make(2, (4, 3), sizing=grid, rng=5)
    per = TilingSpec.make(2, (4, 3), sizing=D.GridSource(tmp_path / "g.npy", (0, 0), (1, 1)), rng=5)
    a = all_bytes(D.run_local(tmp_path / "mem.zarr", mem))
    b = all_bytes(D.run_local(tmp_path / "per.zarr", per))
    assert a == b
    assert sum(len(s) for s in a[0::3]) > 1000
    # an OpenEXR image, read in strips of scanlines, against the same image in memory
    OpenEXR = pytest.importorskip("OpenEXR")
    from vpds.exr import sizing_grid_from_exr
    px = (0.3 + 0.4 * np.outer(np.linspace(0, 1, 40), np.linspace(1, 0, 50))).astype(np.float32)
    with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                      {"Y": px}) as f:
        f.write(str(tmp_path / "s.exr"))
    whole = sizing_grid_from_exr(tmp_path / "s.exr", (0, 0), (1, 1), radius_range=(0.02, 0.04))
    src = D.GridSource(tmp_path / "s.exr", (0, 0), (1, 1), radius_range=(0.02, 0.04))
    assert src.shape == whole.values.shape
    assert src.stats() == (whole.lipschitz, whole.values.min(), whole.values.max())
    a = all_bytes(D.run_local(tmp_path / "em.zarr", TilingSpec.make(2, (3, 3), sizing=whole.values, rng=6)))
    b = all_bytes(D.run_local(tmp_path / "ep.zarr", TilingSpec.make(2, (3, 3), sizing=src, rng=6)))
    assert a == b


# -- seam statistics (README: which properties hold across seams) ---------------------------------

def _tiled_1d(seed: int, r: float) -> tuple[np.ndarray, np.ndarray]:
    t = Tiling(TilingSpec.make(1, (2,), radius=r, rng=seed))
    x0, r0, _ = t.run_tile(0, {})
    x1, _, _ = t.run_tile(1, {0: (x0, r0)})
    return x0[:, 0], x1[:, 0]


def test_seam_sample_is_uniform_within_its_tile():
    """Claim: each sample of a later-phase tile is drawn uniformly from the free part of its core
    given everything placed before it. The first sample of tile 1 of [0, 1] (core [0.5, 1]) must
    be uniform over [max(0.5, m + r), 1], m the point of tile 0 nearest the seam."""
    r, u = 0.01, []
    for seed in range(3000):
        x0, x1 = _tiled_1d(seed, r)
        start = max(0.5, x0.max() + r)
        u.append((x1[0] - start) / (1.0 - start))
    assert stats.kstest(u, "uniform").pvalue > 1e-3


def test_seam_profile_differs_from_one_run_but_not_away_from_it():
    """Claim: the tiled process is not the whole-box process near a seam (tile 0 fills up to
    its face before tile 1 starts: a peak of density just before the seam, a deficit just
    after), and is indistinguishable from it a few radii away."""
    r, n = 0.01, 4000
    tiled = [np.concatenate(_tiled_1d(s, r)) for s in range(n)]
    whole = [vpds.PoissonDisk(1, radius=r, rng=10**6 + s, progress=False).fill_space()[:, 0]
             for s in range(n)]
    edges = np.linspace(-2 * r, 2 * r, 17)

    def p_value(centre: float) -> float:
        a = np.histogram(np.concatenate(tiled) - centre, edges)[0]
        b = np.histogram(np.concatenate(whole) - centre, edges)[0]
        return stats.chi2_contingency(np.vstack([a, b]))[1]
    assert p_value(0.5) < 1e-12
    assert p_value(0.25) > 1e-3


def test_cli_tiles(tmp_path, cluster, capsys):
    from vpds.cli import main
    _, client = cluster
    out = tmp_path / "cli.zarr"
    argv = ["sample", "--tiles", "3,2", "--hi", "1,0.8", "--radius", "0.03", "--seed", "4",
            "-o", str(out), "--address", client.scheduler.address, "--no-progress"]
    assert main(argv) == 0
    assert "samples in 2D over 6 tiles (3, 2)" in capsys.readouterr().out
    ref = D.run_local(tmp_path / "ref.zarr", TilingSpec.make(2, (3, 2), u_bounds=(1, 0.8), radius=0.03, rng=4))
    assert all_bytes(D.TileStore(out)) == all_bytes(ref)
    assert main(argv[:-3] + ["--address", client.scheduler.address, "--seed", "5"]) == 2
    assert "holds another run (different seed)" in capsys.readouterr().err
    assert main(["sample", "--tiles", "2", "--sizing", "0.02 + 0*x[0]", "--lipschitz", "0.1",
                 "-o", str(tmp_path / "x.zarr")]) == 2
    assert "needs --radius-max" in capsys.readouterr().err
    # vpds analyze reads the store and checks the union in its insertion order
    res = subprocess.run([sys.executable, "-m", "vpds", "analyze", str(out)], capture_output=True,
                         text=True)
    assert res.returncode == 0 and "all guarantees hold" in res.stdout, res.stdout + res.stderr
    assert "run: tiles" in res.stdout and "radius 0.03" in res.stdout
    # --tiles auto: the layout of tiles=None, resumed as the same run
    auto = ["sample", "--tiles", "auto", "--radius", "0.004", "-o", str(tmp_path / "auto.zarr"),
            "--address", client.scheduler.address, "--no-progress"]
    tiles = TilingSpec.make(2, None, radius=0.004).tiles
    assert main(auto) == 0 and f"over {int(np.prod(tiles))} tiles {tiles}" in capsys.readouterr().out
    assert main(auto) == 0 and f"tiles {tiles}" in capsys.readouterr().out
    assert main(["sample", "--tiles", "many", "-o", str(tmp_path / "m.zarr")]) == 2
    assert "--tiles 'many': expected tile counts separated by commas, or auto" in capsys.readouterr().err


def test_sizing_file_with_array_bounds(tmp_path):
    """A sizing given as a file path with the bounds as numpy arrays (which have no truth value)
    samples the box those bounds give."""
    np.save(tmp_path / "g.npy", np.full((9, 7), 0.05))
    store = D.sample(tmp_path / "a.zarr", 2, 2, sizing=str(tmp_path / "g.npy"),
                     l_bounds=np.array([0.0, 0.0]), u_bounds=np.array([2.0, 1.0]), rng=3,
                     n_workers=1, progress=False)
    x = store.to_numpy()[0]
    assert len(x) > 100 and x[:, 0].max() > 1.5 and x[:, 0].max() <= 2.0
