"""vpds.sample_mesh / MeshSampler and `vpds sample --mesh`, checked independently of the library:
samples on their triangles, no pair in conflict, dense probes on every triangle covered."""
import importlib.util
import os
import subprocess
import sys

import numpy as np
import pytest
from scipy.spatial import cKDTree

import vpds
from vpds import analysis as C

trimesh = pytest.importorskip("trimesh")


def square(n=6, jitter=0.3, seed=0):
    """The unit square z = 0 as an irregular triangulation of n x n cells."""
    g = np.random.default_rng(seed)
    u = np.linspace(0, 1, n + 1)
    xy = np.stack(np.meshgrid(u, u, indexing="xy"), -1).reshape(-1, 2)
    inner = (xy > 0).all(1) & (xy < 1).all(1)
    xy[inner] += g.uniform(-jitter, jitter, (inner.sum(), 2)) / n
    v = np.column_stack([xy, np.zeros(len(xy))])
    f = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            f += [[a, b, d], [a, d, c]] if (i + j) % 2 else [[a, b, c], [b, d, c]]
    return v, np.array(f)


# barycentrics of a triangle's corners and edge midpoints, probed on every triangle
CORNERS_AND_MIDPOINTS = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [.5, .5, 0], [0, .5, .5], [.5, 0, .5]])


def probes(v, f, per_unit_area, rng):
    """Corners, edge midpoints and area-uniform random points of every triangle: the points,
    their triangles and barycentrics."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    faces, bary = [], []
    for k in range(len(f)):
        m = max(3, int(area[k] * per_unit_area))
        s, t = rng.random(m), rng.random(m)
        flip = s + t > 1
        s[flip], t[flip] = 1 - s[flip], 1 - t[flip]
        bk = np.concatenate([CORNERS_AND_MIDPOINTS, np.column_stack([1 - s - t, s, t])])
        faces.append(np.full(len(bk), k))
        bary.append(bk)
    faces, bary = np.concatenate(faces), np.concatenate(bary)
    return np.einsum("nk,nkd->nd", bary, v[f[faces]]), faces, bary


def check_guarantees(v, f, s, radius_at, rule="smaller", t=1.0, r_max=None):
    assert len(s.points) > 0 and s.maximal and s.delta == 0
    # on the triangle its face and barycentrics name
    rebuilt = np.einsum("nk,nkd->nd", s.barycentrics, v[f[s.faces]])
    np.testing.assert_allclose(rebuilt, s.points, atol=1e-12)
    np.testing.assert_allclose(s.barycentrics.sum(1), 1, atol=1e-12)
    assert (s.barycentrics >= -1e-12).all()
    np.testing.assert_allclose(s.radii, radius_at(s.points, s.faces, s.barycentrics), rtol=1e-12)
    # conflict-free (each later sample against the earlier ones, at its own scale)
    r_max = r_max or s.radii.max()
    tree = cKDTree(s.points)
    for i, j in tree.query_pairs(t * r_max + 1e-12, output_type="ndarray"):
        i, j = min(i, j), max(i, j)
        f_ij = s.scales[j] * C.rule_f(rule, s.radii[i:i + 1], s.radii[j:j + 1])[0]
        assert np.linalg.norm(s.points[i] - s.points[j]) >= f_ij * (1 - 1e-12)
    # maximal: every probe within t * f of a sample
    y, y_face, y_bary = probes(v, f, 4.0 / (t * s.radii.min()) ** 2, np.random.default_rng(5))
    near = tree.query_ball_point(y, t * r_max * (1 + 1e-9))
    ry = radius_at(y, y_face, y_bary)
    for k, idx in enumerate(near):
        idx = np.asarray(idx, dtype=int)
        assert len(idx), f"probe {y[k]} has no sample within reach"
        d = np.linalg.norm(s.points[idx] - y[k], axis=1)
        assert (d <= t * C.rule_f(rule, s.radii[idx], np.full(len(idx), ry[k])) * (1 + 1e-9)).any()


def const(r):
    return lambda x, faces, bary: np.full(len(x), r)


def test_square_is_maximal_and_conflict_free():
    v, f = square()
    s = vpds.sample_mesh(v, f, radius=0.04, rng=3)
    assert np.all(s.points[:, 2] == 0) and s.points[:, :2].min() >= 0 and s.points[:, :2].max() <= 1
    check_guarantees(v, f, s, const(0.04))


def test_trimesh_object_and_its_arrays_give_the_same_samples():
    m = trimesh.creation.icosphere(subdivisions=3)
    a = vpds.sample_mesh(m, radius=0.1, rng=7)
    b = vpds.sample_mesh(np.asarray(m.vertices), np.asarray(m.faces), radius=0.1, rng=7)
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.faces, b.faces)
    check_guarantees(np.asarray(m.vertices), np.asarray(m.faces), a, const(0.1))
    c = vpds.sample_mesh(m, radius=0.1, rng=8)
    assert len(c.points) != len(a.points) or not np.array_equal(c.points, a.points)


@pytest.mark.parametrize("rule", sorted(vpds.RULES))
def test_vertex_radii_under_every_rule(rule):
    m = trimesh.creation.icosphere(subdivisions=3)
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    vr = 0.08 + 0.03 * v[:, 2]

    def radius_at(x, faces, bary):
        return np.einsum("nk,nk->n", bary, vr[f[faces]])

    s = vpds.sample_mesh(m, vertex_radii=vr, rule=rule, rng=1)
    check_guarantees(v, f, s, radius_at, rule=rule, r_max=vr.max())


def test_sizing_callable_and_refinement():
    v, f = square(4)
    s = vpds.sample_mesh(v, f, sizing=lambda x: 0.05 + 0.03 * x[:, 0], lipschitz=0.03, rng=2, t=0.5)
    assert np.all(s.scales == 0.5)
    check_guarantees(v, f, s, lambda x, *_: 0.05 + 0.03 * x[:, 0], t=0.5, r_max=0.08)
    m = vpds.MeshSampler(v, f, radius=0.1, rng=2).run()
    n1 = len(m.samples.points)
    m.refine(0.5)
    s2 = m.samples
    assert len(s2.points) > 2 * n1 and np.all(s2.scales[:n1] == 1) and np.all(s2.scales[n1:] == 0.5)
    check_guarantees(v, f, s2, const(0.1), t=0.5)
    with pytest.raises(vpds.VpdsValueError, match="below the current scale"):
        m.refine(0.7)


def test_exactly_n_points_from_the_stream():
    m = trimesh.creation.icosphere(subdivisions=2)
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    s = vpds.sample_mesh(m, radius=0.2, n=150, rng=3)
    assert len(s.points) == 150 and s.scales[0] == np.inf and np.all(np.diff(s.scales) <= 0)
    np.testing.assert_allclose(np.einsum("nk,nkd->nd", s.barycentrics, v[f[s.faces]]), s.points, atol=1e-12)
    # each prefix: the samples before k cover the surface at t_k, and none is closer than t_k r
    y, _, _ = probes(v, f, 2000.0, np.random.default_rng(2))
    for k in (10, 60, 149):
        d, _ = cKDTree(s.points[:k]).query(y)
        assert d.max() <= s.scales[k] * 0.2 * (1 + 1e-9)
        dd, _ = cKDTree(s.points[:k + 1]).query(s.points[:k + 1], k=2)
        assert dd[:, 1].min() >= s.scales[k] * 0.2 * (1 - vpds.STREAM_TOLERANCE)
    again = vpds.MeshSampler(m, radius=0.2, rng=3)
    again.progressive(60)
    np.testing.assert_array_equal(again.progressive(150).points, s.points)
    # runs and the stream mix: a run after it has nothing to add (maximal at its last scale), a
    # refine goes below that scale, and a stream continues a run at scales up to the run's
    assert len(again.run().samples.points) == 150
    t_last = float(s.scales[-1])
    refined = again.refine(0.8 * t_last).samples
    assert len(refined.points) > 150 and refined.maximal
    d, _ = cKDTree(refined.points).query(y)
    assert d.max() <= 0.8 * t_last * 0.2 * (1 + 1e-9)
    ran = vpds.MeshSampler(m, radius=0.2, rng=3).run()
    n_run = len(ran.samples.points)
    more = ran.progressive(n_run + 20)
    assert len(more.points) == n_run + 20
    assert np.all(more.scales[n_run:] <= 1) and np.all(np.diff(more.scales[n_run:]) <= 0)
    dd, _ = cKDTree(more.points).query(more.points, k=2)
    assert dd[:, 1].min() >= more.scales[-1] * 0.2 * (1 - vpds.STREAM_TOLERANCE)
    with pytest.raises(ValueError, match="give one"):
        vpds.sample_mesh(m, n=10, t=0.5)


def test_algorithm_version_pins_the_mesh_stream():
    """Version 7 changed how the stream on a mesh splits its pieces (in two at the longest edge,
    where 3-6 split in four): pinning 6 keeps the older points; runs are the same under both.
    Versions 8 to 11 changed only boxes: a mesh gives the points of 7."""
    m = trimesh.creation.icosphere(subdivisions=2)
    current = vpds.sample_mesh(m, radius=0.2, n=80, rng=3)
    np.testing.assert_array_equal(vpds.sample_mesh(m, radius=0.2, n=80, rng=3, algorithm_version=7).points,
                                  current.points)
    pinned = vpds.sample_mesh(m, radius=0.2, n=80, rng=3, algorithm_version=6)
    assert not np.array_equal(pinned.points, current.points)
    for version in (3, 4, 5):
        np.testing.assert_array_equal(
            vpds.sample_mesh(m, radius=0.2, n=80, rng=3, algorithm_version=version).points, pinned.points)
    np.testing.assert_array_equal(vpds.sample_mesh(m, radius=0.2, rng=3, algorithm_version=6).points,
                                  vpds.sample_mesh(m, radius=0.2, rng=3).points)
    np.testing.assert_array_equal(vpds.sample_mesh(m, radius=0.2, n=80, rng=3, algorithm_version=8).points,
                                  current.points)
    np.testing.assert_array_equal(vpds.sample_mesh(m, radius=0.2, n=80, rng=3, algorithm_version=9).points,
                                  current.points)
    np.testing.assert_array_equal(vpds.sample_mesh(m, radius=0.2, n=80, rng=3, algorithm_version=12).points,
                                  current.points)
    np.testing.assert_array_equal(vpds.sample_mesh(m, radius=0.2, n=80, rng=3, algorithm_version=13).points,
                                  current.points)
    for bad in (2, 14, -1, 1.5, True):
        with pytest.raises(ValueError, match=r"algorithm_version = .*versions 3\.\.13"):
            vpds.sample_mesh(m, algorithm_version=bad)


def bunny_scan():
    """The Stanford bunny as scanned and reconstructed (50,000 vertices, 99,785 triangles, in
    millimetres, open where the scanner saw nothing): the PLY file pymeshfix ships (a test
    requirement; its file is read with trimesh, the package is never imported)."""
    spec = importlib.util.find_spec("pymeshfix")
    if spec is None or not spec.submodule_search_locations:
        pytest.skip("the scanned mesh comes with pymeshfix: pip install pymeshfix")
    path = os.path.join(list(spec.submodule_search_locations)[0], "examples", "StanfordBunny.ply")
    m = trimesh.load(path, process=False)
    return np.asarray(m.vertices, dtype=float), np.asarray(m.faces)


def face_probes(v, f, rng, per_face=3):
    """Every triangle's corners and edge midpoints and per_face area-uniform points, vectorised."""
    s, t = rng.random((len(f), per_face)), rng.random((len(f), per_face))
    flip = s + t > 1
    s[flip], t[flip] = 1 - s[flip], 1 - t[flip]
    bary = np.concatenate([np.broadcast_to(CORNERS_AND_MIDPOINTS, (len(f), 6, 3)),
                           np.stack([1 - s - t, s, t], -1)], axis=1)
    return np.einsum("fpk,fkd->fpd", bary, v[f]).reshape(-1, 3)


def test_a_scanned_mesh_is_maximal_and_conflict_free():
    v, f = bunny_scan()
    assert f.shape == (99785, 3)
    r = 1.0  # the bunny is about 50 mm across: some 4,000 samples
    s = vpds.sample_mesh(v, f, radius=r, rng=11)
    assert s.maximal and s.delta == 0 and len(s.points) > 3000
    np.testing.assert_allclose(np.einsum("nk,nkd->nd", s.barycentrics, v[f[s.faces]]), s.points,
                               atol=1e-10)
    tree = cKDTree(s.points)
    assert not tree.query_pairs(r * (1 - 1e-12)), "two samples closer than r"
    # about 900,000 probes: every corner and edge midpoint of the scan, and points inside
    d, _ = tree.query(face_probes(v, f, np.random.default_rng(4)))
    assert d.max() <= r * (1 + 1e-9), f"a probe lies {d.max()} from the nearest sample"
    # and exactly n evenly spread points from the stream, each prefix covering the scan at its t
    n = vpds.sample_mesh(v, f, radius=r, n=300, rng=11)
    assert len(n.points) == 300 and np.all(np.diff(n.scales[1:]) <= 0)
    y = face_probes(v, f, np.random.default_rng(5), per_face=1)
    for k in (50, 299):
        d, _ = cKDTree(n.points[:k]).query(y)
        assert d.max() <= n.scales[k] * r * (1 + 1e-9)
        dd, _ = cKDTree(n.points[:k + 1]).query(n.points[:k + 1], k=2)
        assert dd[:, 1].min() >= n.scales[k] * r * (1 - vpds.STREAM_TOLERANCE)


def test_bad_input_is_named():
    v, f = square(2)
    with pytest.raises(vpds.VpdsValueError, match="triangle 1 corner 2 is vertex 99"):
        vpds.sample_mesh(v, np.array([[0, 1, 2], [0, 1, 99]]))
    with pytest.raises(ValueError, match=r"faces: shape \(3,\)"):
        vpds.sample_mesh(v, np.array([0, 1, 2]))
    with pytest.raises(ValueError, match="has an index out of range"):
        vpds.sample_mesh(v, np.array([[0, 1, -1]]))
    with pytest.raises(ValueError, match="one radius per vertex"):
        vpds.sample_mesh(v, f, vertex_radii=[0.1, 0.2])
    bad = v.copy()
    bad[4, 0] = np.nan
    with pytest.raises(vpds.VpdsValueError, match="vertex 4 coordinate 0"):
        vpds.sample_mesh(bad, f)
    with pytest.raises(vpds.VpdsValueError, match="all 2 triangles are degenerate"):
        vpds.sample_mesh(v, np.array([[0, 0, 1], [2, 2, 2]]))
    with pytest.raises(vpds.VpdsUnsupportedError, match="two radii"):
        vpds.sample_mesh(v, f, inhibition=0.5)
    with pytest.raises(vpds.VpdsSizingError, match="sizing returned"):
        vpds.sample_mesh(v, f, sizing=lambda x: np.where(x[:, 0] > 0.5, np.nan, 0.1), lipschitz=0.1)
    with pytest.raises(ZeroDivisionError):
        vpds.sample_mesh(v, f, sizing=lambda x: 1 / 0, lipschitz=0.1)


def vpds_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "vpds", *args], capture_output=True, text=True, cwd=cwd)


def test_cli_samples_a_mesh_file_into_ply(tmp_path):
    trimesh.creation.torus(1.0, 0.3).export(tmp_path / "torus.stl")
    res = vpds_cli("sample", "--mesh", "torus.stl", "--radius", "0.08", "--seed", "4", "-o", "s.ply",
                   "--plot", "s.png", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "maximal: True" in res.stdout
    head, body = (tmp_path / "s.ply").read_text().split("end_header\n")
    assert "property int face" in head and "property double b2" in head
    table = np.loadtxt(body.splitlines(), ndmin=2)
    m = trimesh.load(tmp_path / "torus.stl", force="mesh", process=False)
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    face = table[:, 5].astype(int)
    rebuilt = np.einsum("nk,nkd->nd", table[:, 6:9], v[f[face]])
    np.testing.assert_allclose(rebuilt, table[:, :3], atol=1e-9)
    assert (tmp_path / "s.png").stat().st_size > 10_000
    api = vpds.sample_mesh(v, f, radius=0.08, rng=4)
    np.testing.assert_allclose(api.points, table[:, :3], rtol=0, atol=0)


def test_cli_streams_exactly_n_points_on_a_mesh(tmp_path):
    trimesh.creation.icosphere(subdivisions=2).export(tmp_path / "ball.stl")
    res = vpds_cli("sample", "--mesh", "ball.stl", "--radius", "0.2", "--seed", "3", "--stream", "57",
                   "-o", "s.ply", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith("57 samples on ball.stl")
    head, body = (tmp_path / "s.ply").read_text().split("end_header\n")
    table = np.loadtxt(body.splitlines(), ndmin=2)
    m = trimesh.load(tmp_path / "ball.stl", force="mesh", process=False)
    api = vpds.sample_mesh(m, radius=0.2, n=57, rng=3)
    np.testing.assert_allclose(api.points, table[:, :3], rtol=0, atol=0)


@pytest.mark.parametrize("args, message", [
    (["--mesh", "no-such.obj"], "--mesh no-such.obj: no such file"),
    (["--mesh", "m.stl", "--stream", "5", "--refine", "0.5"], "--stream with --refine"),
    (["--mesh", "m.stl", "--periodic", "0"], "--periodic is not available with --mesh"),
    (["--mesh", "m.stl", "--dim", "3"], "--dim is not available with --mesh"),
    (["--mesh", "m.stl", "--radius", "-1"], "desc.radius = -1"),
    (["--mesh", "m.stl", "-o", "out.vtk"], "unsupported extension '.vtk'"),
])
def test_cli_mesh_mistakes_are_one_line(tmp_path, args, message):
    trimesh.creation.box().export(tmp_path / "m.stl")
    res = vpds_cli("sample", *args, cwd=tmp_path)
    assert res.returncode == 2 and message in res.stderr and "Traceback" not in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


def test_cli_mesh_without_trimesh_names_the_install(tmp_path):
    code = ("import sys; sys.modules['trimesh'] = None; from vpds.cli import main; "
            "sys.exit(main(['sample', '--mesh', 'x.obj']))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 2 and "pip install trimesh" in res.stderr and "Traceback" not in res.stderr
