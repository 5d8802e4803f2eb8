"""Maximal Poisson-disk sampling on triangle meshes (the C library's vpds_mesh_*).

    >>> import numpy as np, vpds
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    >>> f = np.array([[0, 1, 2], [1, 3, 2]])
    >>> s = vpds.sample_mesh(v, f, radius=0.05, rng=1)
    >>> s.points.shape[1], bool(s.maximal)
    (3, True)

The sampled set is the union of the triangles of positive area; distances are Euclidean in
R^3; conflicts and coverage follow the rule as in a box. A completed run is conflict-free,
maximal (every point of every triangle, edges included, covered) and bias-free (each sample
uniform by area over the free part of the surface when it is placed).
"""
from __future__ import annotations

from typing import Any, NamedTuple, Optional, Union

import numpy as np
import numpy.typing as npt

from ._args import number, room_for_samples
from ._callbacks import take, raise_failure
from ._core import RULES, STREAM_BATCH, _CHUNK, _algorithm_version
from ._errors import _raise, created
from ._scipy_compat import _seed_from
from ._typing import RngLike, SizingFunction
from ._vpds import ffi, lib

__all__ = ["MeshSamples", "sample_mesh", "MeshSampler"]

FloatArray = npt.NDArray[np.float64]
_MESH_ALGORITHM_FIRST = 3  # meshes came with algorithm version 3


class MeshSamples(NamedTuple):
    """Samples on a mesh, in insertion order."""
    points: FloatArray                  # (n, 3)
    faces: npt.NDArray[np.int64]        # (n,): the triangle of each sample (a row of `faces`)
    barycentrics: FloatArray            # (n, 3): weights of the triangle's vertices, summing to 1
    radii: FloatArray                   # (n,): r at each sample
    scales: FloatArray                  # (n,): the scale t each sample was placed at
    maximal: bool                       # the run completed: every point of the surface covered
    delta: float                        # 0, or the precision limit's largest piece left active


def _mesh_arrays(vertices: Any, faces: Any) -> tuple[FloatArray, npt.NDArray[np.uint32]]:
    """(n, 3) float64 vertices and (m, 3) uint32 faces, from arrays or a trimesh.Trimesh-like
    object (anything with .vertices and .faces)."""
    if faces is None and hasattr(vertices, "vertices") and hasattr(vertices, "faces"):
        vertices, faces = vertices.vertices, vertices.faces
    if faces is None:
        raise ValueError("faces: give the (m, 3) triangle indices, or pass a mesh object with "
                         ".vertices and .faces (a trimesh.Trimesh)")
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices: shape {v.shape}, expected (n, 3)")
    f_in = np.asarray(faces)
    if f_in.ndim != 2 or f_in.shape[1] != 3:
        raise ValueError(f"faces: shape {f_in.shape}, expected (m, 3)")
    if f_in.size and not np.issubdtype(f_in.dtype, np.integer):
        raise ValueError(f"faces: dtype {f_in.dtype}, expected integer vertex indices")
    if f_in.size and (f_in.min() < 0 or f_in.max() > np.iinfo(np.uint32).max):
        bad = int(np.argmax((f_in < 0).any(axis=1) | (f_in > np.iinfo(np.uint32).max).any(axis=1)))
        raise ValueError(f"faces: triangle {bad} = {f_in[bad].tolist()} has an index out of range "
                         f"(vertices: {len(v)})")
    return v, np.ascontiguousarray(f_in, dtype=np.uint32)


class MeshSampler:
    """A mesh and its samples, refined in place: run() to maximal at t = 1, refine(t) to a
    smaller scale. The arrays are copied by the library at construction."""

    def __init__(self, vertices: Any, faces: Any = None, *, radius: float = 0.05,
                 sizing: Optional[SizingFunction] = None, vertex_radii: Optional[npt.ArrayLike] = None,
                 lipschitz: Optional[float] = None, rule: str = "smaller", inhibition: float = 1.0,
                 coverage: float = 1.0, rng: RngLike = None,
                 algorithm_version: Optional[int] = None) -> None:
        v, f = _mesh_arrays(vertices, faces)
        if rule not in RULES:
            raise ValueError(f"rule = {rule!r}: one of {sorted(RULES)}")
        self.d = 3  # what the sizing callback's owner tells it: points of R^3
        self._callback_error: Optional[BaseException] = None
        self._sizing_fn = sizing
        self.rule = rule
        desc = ffi.new("vpds_mesh_desc *", lib.vpds_default_mesh_desc())
        self._keep: list[Any] = [v, f]
        desc.vertices = ffi.cast("const double *", ffi.from_buffer(v))
        desc.n_vertices = len(v)
        desc.triangles = ffi.cast("const uint32_t *", ffi.from_buffer(f))
        desc.n_triangles = len(f)
        desc.radius = number("radius", radius, " (radii that vary: vertex_radii= or sizing=)")
        if vertex_radii is not None:
            vr = np.ascontiguousarray(vertex_radii, dtype=np.float64)
            if vr.shape != (len(v),):
                raise ValueError(f"vertex_radii: shape {vr.shape}, expected ({len(v)},): one radius per vertex")
            self._keep.append(vr)
            self._largest_radius = float(np.max(vr)) if len(vr) else desc.radius
            desc.vertex_radii = ffi.cast("const double *", ffi.from_buffer(vr))
        if sizing is not None:
            if not callable(sizing):
                raise ValueError(f"sizing: a callable r(x) of (m, 3) points, not {type(sizing).__name__} "
                                 "(a constant is `radius`, per-vertex values `vertex_radii`)")
            self._handle = ffi.new_handle(self)
            desc.sizing_batch = lib.vpds_py_sizing_batch
            desc.sizing_user = self._handle
        if lipschitz is not None:
            desc.lipschitz = number("lipschitz", lipschitz)
            if not desc.lipschitz >= 0:  # -1 would read as the C library's "not given"
                raise ValueError(f"lipschitz = {lipschitz!r}: must be >= 0")
        desc.rule = RULES[rule]
        desc.inhibition = number("inhibition", inhibition)
        desc.coverage = number("coverage", coverage)
        desc.seed = _seed_from(rng)
        desc.algorithm_version = _algorithm_version(algorithm_version, _MESH_ALGORITHM_FIRST)
        self._m = created(lib.vpds_mesh_validate, lib.vpds_mesh_create, lib.vpds_mesh_destroy,
                          "vpds_mesh", desc)
        self.n_faces = len(f)
        # the surface's area and its largest radius bound a maximal run's count from below
        self._area = float(0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]),
                                                axis=1).sum()) if len(f) else 0.0
        if vertex_radii is None:
            self._largest_radius = None if sizing is not None else desc.radius
        self._coverage = desc.coverage

    def _check(self, st: int) -> int:
        cause = take(self, "_callback_error")
        if st < 0 or cause is not None:
            message = ffi.string(lib.vpds_mesh_last_error(self._m)).decode()
            if cause is None:
                _raise(st, message)
            raise_failure(st, message, cause, "sizing")
        return st

    def _drive(self, call: Any) -> None:
        """Call in chunks of work until done: Ctrl-C stops between chunks, state kept."""
        lib.vpds_mesh_set_budget(self._m, _CHUNK)
        while self._check(call()) == lib.VPDS_PAUSED:
            pass

    def _room(self, what: str, t: float) -> None:
        """Refuse, before it starts, a run at scale t whose samples cannot fit in memory: every
        point of the surface lies within t * coverage * r of one, so a maximal set holds at least
        area / (pi (t coverage r)^2) of them (r the largest radius; a sizing callable's is not
        known: no check)."""
        if self._largest_radius is None or not (t > 0) or not np.isfinite(self._area):
            return
        reach = t * self._coverage * self._largest_radius
        if reach > 0:
            room_for_samples(what, self._area / (np.pi * reach * reach), 3,
                             why=" (at least: the surface's area over pi (t coverage r)^2)")

    def run(self) -> "MeshSampler":
        """Sample to maximal at scale 1."""
        self._room("run()", 1.0)
        self._drive(lambda: lib.vpds_mesh_run(self._m))
        return self

    def refine(self, t: float) -> "MeshSampler":
        """Add samples until maximal at the scale t (below the current one; before any run, the
        first scale)."""
        t = number("t", t)
        self._room(f"refine({t})", t)
        self._drive(lambda: lib.vpds_mesh_refine(self._m, t))
        return self

    def progressive(self, n: int) -> MeshSamples:
        """Continue the stream to n samples in all (the first ones stay): each prefix is
        conflict-free and maximal at its own scale, so the n points are evenly spread at the
        last one's t (the farthest point of the surface in the rule's scaled distance, each in
        turn; the first uniform by area). After a run the stream continues from its samples,
        at scales up to the run's; after the stream, `refine(t)` goes below its last scale."""
        if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 0:
            raise ValueError(f"n = {n!r}: must be an int >= 0")
        room_for_samples(f"progressive(n={n})", n, 3)
        got = ffi.new("size_t *")
        while int(lib.vpds_mesh_count(self._m)) < n:
            # batches of vpds_mesh_next_n, so Ctrl-C stops between them
            left = n - int(lib.vpds_mesh_count(self._m))
            if self._check(lib.vpds_mesh_next_n(self._m, min(left, STREAM_BATCH), 0.0, ffi.NULL, ffi.NULL,
                                                got)) == lib.VPDS_STREAM_END:
                break
        return self.samples

    @property
    def samples(self) -> MeshSamples:
        n = int(lib.vpds_mesh_count(self._m))
        st = lib.vpds_mesh_get_stats(self._m)

        def arr(ptr: Any, k: int, dtype: Any) -> Any:
            if n == 0:
                return np.empty((0, k) if k > 1 else (0,), dtype=dtype)
            a = np.frombuffer(ffi.buffer(ptr, n * k * np.dtype(dtype).itemsize), dtype=dtype).copy()
            return a.reshape(n, k) if k > 1 else a

        return MeshSamples(points=arr(lib.vpds_mesh_points(self._m), 3, np.float64),
                           faces=arr(lib.vpds_mesh_faces(self._m), 1, np.uint32).astype(np.int64),
                           barycentrics=arr(lib.vpds_mesh_barycentrics(self._m), 3, np.float64),
                           radii=arr(lib.vpds_mesh_radii(self._m), 1, np.float64),
                           scales=arr(lib.vpds_mesh_scales(self._m), 1, np.float64),
                           maximal=bool(st.maximal), delta=float(st.delta))


def sample_mesh(vertices: Any, faces: Any = None, *, radius: float = 0.05,
                sizing: Optional[SizingFunction] = None, vertex_radii: Optional[npt.ArrayLike] = None,
                lipschitz: Optional[float] = None, rule: str = "smaller", inhibition: float = 1.0,
                coverage: float = 1.0, rng: RngLike = None, t: Union[float, int] = 1.0,
                n: Optional[int] = None, algorithm_version: Optional[int] = None) -> MeshSamples:
    """A maximal Poisson-disk sampling of a triangle mesh.

    vertices, faces: (n, 3) coordinates and (m, 3) vertex indices, or a trimesh.Trimesh (or any
    object with .vertices and .faces) as `vertices`. The radius: `radius` (a constant),
    `vertex_radii` (one per vertex, linear over each triangle) or `sizing` (a vectorised r(x)
    of (k, 3) points, with its `lipschitz`). rule, inhibition, coverage as for PoissonDisk (this
    version needs inhibition == coverage). rng: an int seed (the C seed) or a numpy Generator.
    t: the scale (1: the radius itself). n: exactly n points instead, evenly spread: the first n
    samples of the stream on the surface (`scales` then says the scale each prefix reaches; the
    radius sets only the shape of the spacing, r relative to itself). algorithm_version: pin the
    points a seed gives (3..vpds.ALGORITHM_VERSION; None: the current one; 7 changed the
    stream's points, so `n=` differs from 6).
    """
    m = MeshSampler(vertices, faces, radius=radius, sizing=sizing, vertex_radii=vertex_radii,
                    lipschitz=lipschitz, rule=rule, inhibition=inhibition, coverage=coverage, rng=rng,
                    algorithm_version=algorithm_version)
    t = number("t", t)
    if n is not None:
        if t != 1.0:
            raise ValueError(f"n = {n} with t = {t}: give one (n points from the stream, or a run at t)")
        return m.progressive(n)
    if float(t) == 1.0:
        m.run()
    else:
        m.refine(float(t))
    return m.samples
