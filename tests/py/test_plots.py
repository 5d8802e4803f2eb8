"""The pictures (vpds/plots.py): what a reader of `vpds sample --plot` and `vpds analyze --plot`
relies on, checked on the matplotlib Figure objects (labels, colour range, panels, ranges) and
on the PNG written."""
import struct

import numpy as np
import pytest

pytest.importorskip("matplotlib")
import vpds  # noqa: E402
from vpds import plots  # noqa: E402


def _sample(dim, radius=0.05, sizing=None, lipschitz=None, seed=1, rule="smaller"):
    engine = vpds.PoissonDisk(dim, radius=radius, sizing=sizing, lipschitz=lipschitz, rule=rule,
                              rng=seed, progress=False)
    engine.fill_space()
    return engine.points, engine.radii


@pytest.fixture(scope="module")
def ramp():
    """The paper's Figure 1: r = 0.001 + 0.3 x on the unit square (dense near x = 0)."""
    return _sample(2, sizing=lambda p: 0.001 + 0.3 * p[:, 0], lipschitz=0.3, seed=2024)


@pytest.fixture(scope="module")
def uniform():
    return _sample(2, radius=0.05)


def _data_axes(fig):
    return [a for a in fig.axes if a.get_label() != "<colorbar>"]


def _colour_bars(fig):
    return [a for a in fig.axes if a.get_label() == "<colorbar>"]


def _png_size(path):
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def _rectangles(ax):
    """(x, y, width, height) of the rectangles drawn on ax (an inset indicator's, whether
    matplotlib gives an InsetIndicator (3.10+) or a bare Rectangle patch)."""
    for child in ax.get_children():
        rect = getattr(child, "rectangle", child)
        if type(rect).__name__ == "Rectangle" and rect is not ax.patch:
            yield rect.get_x(), rect.get_y(), rect.get_width(), rect.get_height()


def _scatter_offsets(ax):
    """The dots of ax (its scatter PathCollections; the disks are an EllipseCollection)."""
    from matplotlib.collections import PathCollection
    chunks = [c.get_offsets() for c in ax.collections if isinstance(c, PathCollection)]
    return np.concatenate(chunks) if chunks else np.zeros((0, 2))


def test_the_png_has_the_figure_size(tmp_path, ramp):
    x, r = ramp
    path = tmp_path / "p.png"
    plots.plot_points(path, x, r, np.zeros(2), np.ones(2), "ramp")  # the CLI's call
    fig = plots.points_figure(x, r, np.zeros(2), np.ones(2), "ramp")
    w, h = fig.get_size_inches() * 150
    assert _png_size(path) == (round(w), round(h))
    assert 1000 <= round(w) <= 3000 and 600 <= round(h) <= 1500


def test_axes_are_labelled_with_the_coordinates(ramp):
    x, r = ramp
    fig = plots.points_figure(x, r, np.zeros(2), np.ones(2), "ramp")
    for ax in _data_axes(fig):
        assert ax.get_xlabel() == "x[0]" and ax.get_ylabel() == "x[1]"
        assert ax.get_title()
    assert "ramp" in fig.get_suptitle()


def test_the_colour_bar_is_labelled_r_and_spans_the_radii(ramp):
    x, r = ramp
    fig = plots.points_figure(x, r, np.zeros(2), np.ones(2), "ramp")
    (bar,) = _colour_bars(fig)
    assert bar.get_ylabel() == "r"
    lo, hi = bar.get_ylim()
    assert lo <= r.min() * (1 + 1e-12) and hi >= r.max() * (1 - 1e-12)
    assert bar.get_yscale() == "log"  # r spans 0.001..0.3
    # the dots carry the colour: the smallest and the largest radius are drawn differently
    main = _data_axes(fig)[0]
    dots = [c for c in main.collections if type(c).__name__ == "PathCollection"]
    colours = np.unique(np.round(np.concatenate([c.get_facecolors() for c in dots]), 3), axis=0)
    assert len(colours) > 10


def test_a_narrow_range_of_radii_has_a_linear_colour_bar():
    rng = np.random.default_rng(0)
    x = rng.random((400, 2))
    r = 0.02 + 0.01 * x[:, 1]
    fig = plots.points_figure(x, r, np.zeros(2), np.ones(2), "")
    (bar,) = _colour_bars(fig)
    assert bar.get_yscale() == "linear"
    lo, hi = bar.get_ylim()
    assert lo <= r.min() and hi >= r.max()


def test_one_radius_has_no_colour_bar_and_says_r(uniform):
    x, r = uniform
    fig = plots.points_figure(x, r, np.zeros(2), np.ones(2), "uniform")
    assert _colour_bars(fig) == []
    (ax,) = _data_axes(fig)  # sparse: no zoom panel
    assert "r = 0.05 for all" in ax.get_title()


def test_dense_variable_radii_get_a_zoom_showing_points_with_disks(ramp):
    from matplotlib.collections import EllipseCollection
    x, r = ramp
    fig = plots.points_figure(x, r, np.zeros(2), np.ones(2), "ramp")
    axes = _data_axes(fig)
    assert len(axes) >= 2
    zoom = axes[-1]
    assert "zoom" in zoom.get_title()
    (x0, x1), (y0, y1) = zoom.get_xlim(), zoom.get_ylim()
    assert 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1
    assert (x1 - x0) <= 0.25 and x0 < 0.01  # a small window where the radii are smallest
    inside = np.all((x >= (x0, y0)) & (x <= (x1, y1)), axis=1)
    assert 30 <= inside.sum() <= 1000  # few enough to see one by one
    assert any(isinstance(c, EllipseCollection) for c in zoom.collections)  # their disks
    # every point of the window is drawn in the zoom
    shown = _scatter_offsets(zoom)
    assert np.all(np.isin(x[inside, 0], shown[:, 0]))
    # and the window is marked on the whole picture
    assert any(np.allclose(b, (x0, y0, x1 - x0, y1 - y0)) for b in _rectangles(axes[0]))


def test_a_sparse_sampling_has_no_zoom_and_zoom_can_be_forced(uniform):
    x, r = uniform
    assert len(_data_axes(plots.points_figure(x, r, np.zeros(2), np.ones(2), ""))) == 1
    forced = plots.points_figure(x, r * np.linspace(1, 2, len(r)), np.zeros(2), np.ones(2), "",
                                 zoom=False)
    assert len(_data_axes(forced)) == 1


def test_disks_are_drawn_for_small_n_only(uniform):
    from matplotlib.collections import EllipseCollection
    x, r = uniform
    fig = plots.points_figure(x, r, np.zeros(2), np.ones(2), "")
    (disks,) = [c for c in _data_axes(fig)[0].collections if isinstance(c, EllipseCollection)]
    assert len(disks.get_offsets()) == len(x)
    rng = np.random.default_rng(1)
    big = rng.random((plots.MAX_DISKS + 1, 2))
    fig = plots.points_figure(big, np.full(len(big), 0.004), np.zeros(2), np.ones(2), "",
                              zoom=False)
    assert not any(isinstance(c, EllipseCollection) for c in _data_axes(fig)[0].collections)


def test_many_points_are_all_drawn_in_a_few_single_colour_scatters():
    rng = np.random.default_rng(2)
    x = rng.random((200_000, 2))
    r = 0.00015 + 0.015 * x[:, 0]
    fig = plots.points_figure(x, r, np.zeros(2), np.ones(2), "", zoom=False)
    from matplotlib.collections import PathCollection
    dots = [c for c in _data_axes(fig)[0].collections if isinstance(c, PathCollection)]
    assert sum(len(c.get_offsets()) for c in dots) == len(x)
    assert len(dots) <= 64 * 8
    assert all(len(c.get_facecolors()) == 1 and c.get_rasterized() for c in dots)


def test_3d_shows_a_slice_with_fewer_points_than_the_input():
    x, r = _sample(3, radius=0.1, seed=4)
    fig = plots.points_figure(x, r, np.zeros(3), np.ones(3), "3d")
    main = _data_axes(fig)[0]
    assert main.get_title().startswith("slice x[2] = 0.5")
    cut = np.abs(x[:, 2] - 0.5) < r
    shown = _scatter_offsets(main)
    assert 0 < len(shown) == cut.sum() < len(x)
    assert f"the {cut.sum()} of {len(x)} balls" in main.get_title()
    # the disks are the balls' cross-sections with the slice
    from matplotlib.collections import EllipseCollection
    (disks,) = [c for c in main.collections if isinstance(c, EllipseCollection)]
    widths = np.sort(disks.get_widths() if hasattr(disks, "get_widths") else 2 * disks._widths) / 2
    expected = np.sort(np.sqrt(r[cut] ** 2 - (x[cut, 2] - 0.5) ** 2))
    np.testing.assert_allclose(widths, expected, rtol=1e-9)
    assert main.get_xlabel() == "x[0]" and main.get_ylabel() == "x[1]"


def test_4d_slices_through_the_middle_of_the_other_axes():
    rng = np.random.default_rng(5)
    x = rng.random((3000, 4))
    r = np.full(len(x), 0.15)
    fig = plots.points_figure(x, r, np.zeros(4), np.ones(4), "4d")
    main = _data_axes(fig)[0]
    assert "x[2] = 0.5, x[3] = 0.5" in main.get_title() and "hyperballs" in main.get_title()
    cut = ((x[:, 2:] - 0.5) ** 2).sum(axis=1) < r ** 2
    assert len(_scatter_offsets(main)) == cut.sum() < len(x)


def test_1d_is_a_strip_with_a_labelled_axis(tmp_path):
    x, r = _sample(1, sizing=lambda p: 0.002 + 0.05 * p[:, 0], lipschitz=0.05)
    path = tmp_path / "s.png"
    plots.plot_points(path, x, r, np.zeros(1), np.ones(1), "1d")
    w, h = _png_size(path)
    assert w > 2 * h  # a strip
    fig = plots.points_figure(x, r, np.zeros(1), np.ones(1), "1d")
    axes = _data_axes(fig)
    for ax in axes:
        assert ax.get_xlabel() == "x[0]" and list(ax.get_yticks()) == []
    assert axes[0].get_xlim() == (0.0, 1.0)
    assert _colour_bars(fig)[0].get_ylabel() == "r"


def test_empty_and_single_point_pictures_are_written(tmp_path):
    for d in (1, 2, 3):
        plots.plot_points(tmp_path / f"e{d}.png", np.zeros((0, d)), np.zeros(0), np.zeros(d),
                          np.ones(d), "none")
        plots.plot_points(tmp_path / f"o{d}.png", np.full((1, d), 0.5), np.full(1, 0.1),
                          np.zeros(d), np.ones(d), "one")
        assert _png_size(tmp_path / f"e{d}.png")[0] > 0 and _png_size(tmp_path / f"o{d}.png")[0] > 0


# -- the analysis sheet ----------------------------------------------------------------------------


def _analysis(x, r, rule="smaller", lipschitz=0.3):
    analysis = pytest.importorskip("vpds.analysis")
    report = analysis.check_delaunay(x, r, rule, lipschitz, np.zeros(2), np.ones(2))
    return plots.analysis_figure(x, r, np.zeros(2), np.ones(2), report, rule, lipschitz, 1.0)


@pytest.fixture(scope="module")
def ramp_sheet(ramp):
    x, r = ramp
    return _analysis(x, r)


def _axes_titled(fig, start):
    (ax,) = [a for a in _data_axes(fig) if a.get_title().startswith(start)]
    return ax


def test_the_anisotropy_range_contains_the_data_for_variable_radii(ramp_sheet):
    ax = _axes_titled(ramp_sheet, "anisotropy")
    y = ax.lines[0].get_ydata()
    y = y[np.isfinite(y)]
    assert y.max() > 10  # outside the old fixed -20..10 dB: the test would catch a fixed range
    lo, hi = ax.get_ylim()
    assert lo < y.min() and hi > y.max()
    assert "dB" in ax.get_ylabel() and ax.get_xlabel().startswith("|f|")


def test_the_analysis_sheet_has_labelled_panels_and_the_bounds_in_range(ramp, ramp_sheet, tmp_path):
    x, r = ramp
    analysis = pytest.importorskip("vpds.analysis")
    report = analysis.check_delaunay(x, r, "smaller", 0.3, np.zeros(2), np.ones(2))
    path = tmp_path / "a.png"
    plots.plot_analysis(path, x, r, np.zeros(2), np.ones(2), report, "smaller", 0.3, 1.0)  # the CLI's call
    fig = ramp_sheet
    w, h = fig.get_size_inches() * 110
    assert _png_size(path) == (round(w), round(h))
    for ax in _data_axes(fig):
        assert ax.get_xlabel() and ax.get_ylabel(), ax.get_title()
    e_min, e_max, sin_min = analysis.table1_bounds("smaller", 0.3)
    angle = _axes_titled(fig, "Delaunay minimum angle")
    lo, hi = angle.get_xlim()
    assert lo < np.degrees(np.arcsin(sin_min)) < hi
    edges = _axes_titled(fig, "Delaunay edge length")
    lo, hi = edges.get_xlim()
    assert lo < e_min < e_max < hi
    assert [a.get_ylabel() for a in _colour_bars(fig)] == ["r", "log10 power"]
    radial = _axes_titled(fig, "radial mean power")
    assert radial.get_yscale() == "log"  # the density gradient's low frequencies: > 20x the rest


def test_a_uniform_sheet_keeps_a_linear_radial_power(uniform):
    x, r = uniform
    fig = _analysis(x, r, lipschitz=0.0)
    assert _axes_titled(fig, "radial mean power").get_yscale() == "linear"
    ax = _axes_titled(fig, "anisotropy")
    y = ax.lines[0].get_ydata()
    lo, hi = ax.get_ylim()
    assert lo < np.nanmin(y) and hi > np.nanmax(y[np.isfinite(y)])


def test_3d_and_1d_sheets_say_what_they_leave_out():
    x, r = _sample(3, radius=0.12, seed=2)
    fig = plots.analysis_figure(x, r, np.zeros(3), np.ones(3), None, "smaller", 0.0, 1.0)
    texts = [t.get_text() for a in fig.axes for t in a.texts]
    assert any("2D only" in t for t in texts)
    assert _data_axes(fig)[0].get_title().startswith("slice x[2] = 0.5")
    x1, r1 = _sample(1, sizing=lambda p: 0.01 + 0.05 * p[:, 0], lipschitz=0.05)
    fig = plots.analysis_figure(x1, r1, np.zeros(1), np.ones(1), None, "smaller", 0.05, 1.0)
    strip, gaps = _data_axes(fig)
    assert strip.get_xlabel() == "x[0]" and gaps.get_title().startswith("gap to the next point")
    assert sum(p.get_height() for p in gaps.patches) == len(x1) - 1
