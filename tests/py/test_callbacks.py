"""Exceptions from Python callables (sizing and domain) inside a C run: the exception comes out
of the Python call as itself (ValueError, KeyboardInterrupt, anything), at once, with the
sampler as a pause leaves it (its samples a prefix of an uninterrupted run's); calling again,
with the callable behaving, gives exactly the points of the uninterrupted run. Also an exception
that escapes the callback's body (Ctrl-C at its first instruction), and a real SIGINT."""
import itertools
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

vpds = pytest.importorskip("vpds")

N_RANDOM, N_STREAM, T_REFINE = 60, 40, 0.6


class Flaky:
    """A sizing or domain callable that counts its calls and raises `exc` at call `fail_at`."""

    def __init__(self, kind):
        self.kind = kind
        self.calls = 0
        self.fail_at = None
        self.exc = ValueError

    def __call__(self, x):
        self.calls += 1
        if self.calls == self.fail_at:
            raise self.exc(f"raised at call {self.calls}")
        if self.kind == "sizing":
            return 0.02 + 0.05 * x[:, 0]
        return np.hypot(x[:, 0] - 0.5, x[:, 1] - 0.5) - 0.42


def make(fn):
    if fn.kind == "sizing":
        return vpds.PoissonDisk(2, sizing=fn, lipschitz=0.05, rng=3, progress=False)
    return vpds.PoissonDisk(2, radius=0.05, domain=fn, rng=3, progress=False)


def prepare(method, engine):
    if method == "refine":
        engine.fill_space()


def call(method, engine, streamed):
    """The method's result; the stream's points are appended to `streamed` as they come."""
    if method == "fill_space":
        return engine.fill_space()
    if method == "random":
        return engine.random(N_RANDOM)
    if method == "refine":
        return engine.refine(T_REFINE)
    if method == "progressive":
        return engine.progressive(N_STREAM).points
    for x, _ in itertools.islice(engine.stream(), N_STREAM - len(streamed)):
        streamed.append(x)
    return np.array(streamed)


METHODS = ["fill_space", "random", "refine", "stream", "progressive"]


@pytest.mark.parametrize("where", ["first", "middle"])
@pytest.mark.parametrize("exc", [ValueError, KeyboardInterrupt])
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("kind", ["sizing", "domain"])
def test_a_raising_callable_stops_the_run_and_a_retry_continues(kind, method, exc, where):
    counter = Flaky(kind)
    ref_engine = make(counter)
    prepare(method, ref_engine)
    before = counter.calls
    ref = call(method, ref_engine, [])
    during = counter.calls - before
    ref_points = ref_engine.points
    assert during > 4 and len(ref) > 20

    flaky = Flaky(kind)
    engine = make(flaky)
    prepare(method, engine)
    count_before = len(engine.points)
    flaky.fail_at = flaky.calls + (1 if where == "first" else during // 2)
    flaky.exc = exc
    streamed = []
    with pytest.raises(exc, match=f"raised at call {flaky.fail_at}") as info:
        call(method, engine, streamed)
    assert type(info.value) is exc  # itself, not a VpdsError wrapping it
    assert flaky.calls == flaky.fail_at  # stopped at once: no Python call after it
    partial = engine.points
    if method == "progressive":  # a stream of its own: this sampler is not changed
        np.testing.assert_array_equal(partial, ref_points)
    else:
        assert count_before <= len(partial) <= len(ref_points)
        np.testing.assert_array_equal(partial, ref_points[:len(partial)])
        if where == "first":
            assert len(partial) == count_before
        else:
            assert len(partial) < len(ref_points) or method == "random"

    flaky.fail_at = None
    np.testing.assert_array_equal(call(method, engine, streamed), ref)
    got = engine.points
    if method == "random":  # runs in chunks past n: the sampler may hold more or fewer
        m = min(len(got), len(ref_points))
        got, ref_points = got[:m], ref_points[:m]
    np.testing.assert_array_equal(got, ref_points)
    np.testing.assert_array_equal(engine.scales[:len(got)], ref_engine.scales[:len(got)])


@pytest.mark.parametrize("method", ["fill_space", "stream"])
@pytest.mark.parametrize("kind", ["sizing", "domain"])
def test_failures_again_and_again_still_give_the_uninterrupted_points(kind, method):
    """A callable raising every few calls (a batched sizing is called less often than a
    domain, one point at a time), each failure followed by a retry (after a retry that
    failed where the last one did, the next failure comes twice as late, so that a step needing
    many calls can finish): the points of a run that never failed. The stream once lost them
    (a region popped and pushed back changed the order of regions of equal keys)."""
    def run(every):
        flaky = Flaky(kind)
        engine = make(flaky)
        got, failures, gap, last = [], 0, every, -1
        flaky.fail_at = every or None
        while True:
            try:
                if method == "fill_space":
                    got.append(engine.fill_space())
                    return np.concatenate(got), engine.points, failures
                for x, _ in itertools.islice(engine.stream(), N_STREAM + 20 - len(got)):
                    got.append(x)
                return np.array(got), engine.points, failures
            except ValueError:
                failures += 1
                now = len(engine.points)
                gap = 2 * gap if now == last else every
                last = now
                flaky.fail_at = flaky.calls + gap
    ref, ref_points, _ = run(0)
    got, points, failures = run(3 if kind == "sizing" else 13)
    assert failures > 10
    np.testing.assert_array_equal(got, ref)
    np.testing.assert_array_equal(points, ref_points)


def test_a_raised_exception_says_where_it_came_from():
    flaky = Flaky("domain")
    flaky.fail_at = 30
    with pytest.raises(ValueError) as info:
        make(flaky).fill_space()
    assert not isinstance(info.value, vpds.VpdsError)
    if sys.version_info >= (3, 11):
        assert "domain callable" in info.value.__notes__[-1]
        assert "VPDS_ERR_DOMAIN" in info.value.__notes__[-1]


@pytest.mark.parametrize("kind", ["sizing", "domain"])
def test_an_exception_escaping_the_callback_body_is_not_lost(kind, capfd):
    """Ctrl-C delivered at the callback's first instruction, before its `try` (simulated by a
    trace function raising on the call event): cffi's onerror keeps it for the binding instead
    of printing "Exception ignored" and returning success with unwritten radii."""
    from vpds import _core, domain
    code = (_core.vpds_py_sizing_batch if kind == "sizing" else domain.vpds_py_domain).__code__
    counter = Flaky(kind)
    ref_engine = make(counter)
    ref = ref_engine.fill_space()
    k = counter.calls // 2
    seen = [0]

    def tracer(frame, event, arg):
        if event == "call" and frame.f_code is code:
            seen[0] += 1
            if seen[0] == k:
                raise KeyboardInterrupt
        return None

    engine = make(Flaky(kind))
    sys.settrace(tracer)
    try:
        with pytest.raises(KeyboardInterrupt):
            engine.fill_space()
    finally:
        sys.settrace(None)
    assert seen[0] == k  # the callback did not run again after it
    err = capfd.readouterr().err
    assert "Exception ignored" not in err and "KeyboardInterrupt" not in err
    partial = engine.points
    assert 0 < len(partial) < len(ref)
    np.testing.assert_array_equal(partial, ref[:len(partial)])
    np.testing.assert_array_equal(engine.fill_space(), ref)


def test_after_a_failure_the_callback_fails_fast():
    """Until the binding has taken the exception, the callback answers failure without calling
    the Python callable (no more Python work inside the same C call)."""
    from vpds._vpds import ffi, lib
    flaky = Flaky("sizing")
    engine = make(flaky)
    x = ffi.new("double[]", [0.5, 0.5, 0.25, 0.75])
    r = ffi.new("double[]", 2)
    assert lib.vpds_py_sizing_batch(x, 2, r, engine._handle) == 0 and flaky.calls == 1
    assert list(r) == [0.045, 0.0325]
    engine._callback_error = KeyboardInterrupt()
    assert lib.vpds_py_sizing_batch(x, 2, r, engine._handle) == 1 and flaky.calls == 1
    dom = Flaky("domain")
    d_engine = make(dom)
    assert lib.vpds_py_domain(x, d_engine._domain.user) == -0.42 and dom.calls == 1
    d_engine._domain.error = ValueError()
    assert np.isnan(lib.vpds_py_domain(x, d_engine._domain.user)) and dom.calls == 1


def test_tiles_raise_the_callable_exception_and_a_retry_gives_the_same_tile():
    from vpds.tiling import Tiling, TilingSpec
    flaky = Flaky("sizing")
    spec = TilingSpec.make(2, (2, 2), sizing=flaky, lipschitz=0.05, radius_max=0.07, rng=5)
    tiling = Tiling(spec)
    tile = next(k for k in tiling.order() if not tiling.deps(k))
    start = flaky.calls
    ref = tiling.run_tile(tile, {})
    flaky.fail_at = flaky.calls + (flaky.calls - start) // 2
    flaky.exc = KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        tiling.run_tile(tile, {})
    flaky.fail_at = None
    for a, b in zip(tiling.run_tile(tile, {}), ref):
        np.testing.assert_array_equal(a, b)


CHILD = textwrap.dedent("""
    import sys, time
    import numpy as np
    import vpds

    slow = sys.argv[1] == "slow"
    started = [False]

    def sizing(x):
        if not started[0]:
            started[0] = True
            print("started", flush=True)
        if slow:
            time.sleep(0.002)
        return 1e-6 + 0.1 * x[:, 0]

    engine = vpds.PoissonDisk(2, sizing=sizing, lipschitz=0.1, rng=1, progress=False)
    try:
        engine.fill_space()
    except KeyboardInterrupt:
        x, r = engine.points, engine.radii
        print("interrupted", len(x), flush=True)
        # the partial samples are valid: a prefix of the run's, conflict-free (smaller rule)
        from scipy.spatial import cKDTree
        near = cKDTree(x).query_ball_point(x, r)  # a conflict is closer than min(r_i, r_j)
        bad = sum(1 for i, js in enumerate(near) for j in js if j != i and
                  np.linalg.norm(x[i] - x[j]) < min(r[i], r[j]) * (1 - 1e-12))
        print("conflicts", bad, flush=True)
        sys.exit(0)
    print("finished", flush=True)
""")


@pytest.mark.parametrize("sizing", ["fast", "fast", "fast", "slow"])
def test_sigint_during_a_python_sizing_raises_keyboardinterrupt(tmp_path, sizing):
    """A real Ctrl-C: the signal lands while C code or the callable runs, and comes out as
    KeyboardInterrupt from fill_space, with nothing printed and no false VPDS_ERR_LIPSCHITZ
    (before: "Exception ignored from cffi callback" and a garbage radius, 3 runs of 3)."""
    script = tmp_path / "child.py"
    script.write_text(CHILD)
    # SIG_DFL in the child: a suite started in the background (SIGINT ignored, inherited)
    # would otherwise give a child that Python leaves without its Ctrl-C handler
    proc = subprocess.Popen([sys.executable, str(script), sizing], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        assert proc.stdout.readline().strip() == "started"
        time.sleep(0.5)
        os.kill(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert "Exception ignored" not in err and "LIPSCHITZ" not in err + out, err
    assert proc.returncode == 0, err
    lines = out.split("\n")
    assert lines[0].startswith("interrupted "), out
    assert int(lines[0].split()[1]) > 0
    assert "conflicts 0" in lines, out
