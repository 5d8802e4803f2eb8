"""Empty-disk, maximality and Table 1 bounds of the library's output, checked independently."""
import numpy as np
import pytest

from vpds import analysis as C

UNIFORM = [(1, 0.002, 1.0), (2, 0.02, 1.0), (3, 0.08, 1.0), (4, 0.2, 1.0), (5, 0.3, 1.0),
           (6, 0.45, 0.8)]


def assert_valid(x, r, rule, sizing, lo, hi):
    d = x.shape[1]
    assert len(x) > 0
    assert np.all((x >= lo) & (x <= hi)), "samples outside the box"
    np.testing.assert_allclose(r, sizing.fn(x), rtol=1e-12, err_msg="r(x) stored != sizing")
    assert C.empty_disk_violations(x, r, rule, 1.0, sizing.lipschitz) == 0
    rep = C.check_maximal(x, r, rule, 1.0, sizing, np.full(d, lo), np.full(d, hi))
    assert rep.gaps == 0, f"uncovered point near {rep.worst_gap}"
    assert rep.unresolved_bound <= 1e-7
    assert rep.probes_max_rel <= 1e-9


@pytest.mark.parametrize("dim,radius,hi", UNIFORM)
def test_uniform_every_dimension(sample, dim, radius, hi):
    x, r, t = sample(dim, "smaller", "const", radius, 11 + dim, 0.0, hi)
    assert_valid(x, r, "smaller", C.sizing_named("const", radius), 0.0, hi)
    assert np.all(t == 1.0)


@pytest.mark.parametrize("rule", C.RULES)
@pytest.mark.parametrize("dim,lo,hi", [(2, 0.0, 1.0), (3, 0.02, 0.32)])
def test_linear_ramp(sample, rule, dim, lo, hi):
    x, r, _ = sample(dim, rule, "ramp", 0.0, 5, lo, hi)
    assert_valid(x, r, rule, C.sizing_named("ramp"), lo, hi)


@pytest.mark.parametrize("rule", C.RULES)
@pytest.mark.parametrize("dim,lo,hi", [(2, 0.5, 0.6), (3, 0.535, 0.539)])
def test_radial_figure10(sample, rule, dim, lo, hi):
    """r between 0.00015 and 0.015, L = 0.373: boxes that cross a ring of the smallest radius."""
    x, r, _ = sample(dim, rule, "radial", 0.0, 9, lo, hi)
    sizing = C.sizing_named("radial")
    assert r.min() < 0.0002 and r.max() > 1.5 * r.min()  # reaches the thinnest ring
    assert_valid(x, r, rule, sizing, lo, hi)


@pytest.mark.parametrize("rule", C.RULES)
def test_weighted_process_is_valid(sample, rule):
    """Eq. 12's process changes where samples go, not the empty-disk or maximality promises."""
    x, r, _ = sample(2, rule, "mild", 0.0, 4, 0.0, 1.0, 0, 1)
    assert_valid(x, r, rule, C.sizing_named("mild"), 0.0, 1.0)


@pytest.mark.parametrize("rule", C.RULES)
@pytest.mark.parametrize("sizing_name,lo,hi", [("ramp", 0.0, 1.0), ("radial", 0.4, 0.6)])
def test_table1_delaunay_bounds(sample, rule, sizing_name, lo, hi):
    x, r, _ = sample(2, rule, sizing_name, 0.0, 3, lo, hi)
    sizing = C.sizing_named(sizing_name)
    rep = C.check_delaunay(x, r, rule, sizing.lipschitz, np.full(2, lo), np.full(2, hi), sizing)
    assert rep.triangles > 1000
    assert rep.min_angle_deg >= rep.angle_bound_deg, rep
    assert rep.edge_min_ratio >= rep.edge_min_bound * (1 - 1e-12), rep
    assert rep.edge_max_ratio <= rep.edge_max_bound, rep
    assert rep.circumradius_ratio <= rep.circumradius_bound * (1 + 1e-12), rep


def test_uniform_delaunay_30_degrees(sample):
    radius = 0.01
    x, r, _ = sample(2, "smaller", "const", radius, 1, 0.0, 1.0)
    rep = C.check_delaunay(x, r, "smaller", 0.0, np.zeros(2), np.ones(2))
    assert rep.min_angle_deg >= 30.0 - 1e-9
    assert rep.edge_min_ratio >= 1 - 1e-12 and rep.edge_max_ratio <= 2.0


def test_checker_detects_a_gap_and_a_conflict(sample):
    """The checks above can fail: one sample removed leaves a gap; one added makes a conflict."""
    x, r, _ = sample(2, "smaller", "ramp", 0.0, 2, 0.0, 1.0)
    sizing = C.sizing_named("ramp")
    keep = np.ones(len(x), bool)
    keep[len(x) // 2] = False
    rep = C.check_maximal(x[keep], r[keep], "smaller", 1.0, sizing, np.zeros(2), np.ones(2))
    assert rep.gaps > 0
    y = x[5] + 0.1 * r[5]
    x2 = np.vstack([x, y])
    r2 = np.append(r, sizing.fn(y[None, :]))
    assert C.empty_disk_violations(x2, r2, "smaller", 1.0, sizing.lipschitz) >= 1
