"""`vpds sample --mesh FILE`: a maximal sampling of a triangle mesh's surface (vpds.mesh), the
mesh read through trimesh (OBJ, PLY, STL, OFF, GLB, ...). The box options that have a meaning
on a surface keep it (--radius, --sizing in x = (x0, x1, x2) with --lipschitz, --rule,
--coverage, --refine, --stream N: exactly N points from the stream on the surface, --seed, -o,
--plot); the others are refused."""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ._optional import require
from .cli_common import UsageError, check_plot, number_arg, scales_arg, sizing_from_expression
from .files import check_output, write_points

# box-only options and the defaults that mean "not given"
_BOX_ONLY = {"periodic": None, "domain": None, "sizing_exr": None, "lo": None, "hi": None,
             "tiles": None, "threads": None}


def add_mesh_arguments(s: argparse.ArgumentParser) -> None:
    g = s.add_argument_group("surfaces (vpds.mesh, needs trimesh)")
    g.add_argument("--mesh", help="sample the surface of a triangle mesh file (OBJ, PLY, STL, ... "
                   "read by trimesh) instead of a box; -o .ply gets the face index and barycentrics")


def _load(path: Path) -> tuple[np.ndarray, np.ndarray]:
    trimesh = require("trimesh", "--mesh", "trimesh")
    if not path.is_file():
        raise UsageError(f"--mesh {path}: no such file")
    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for a bad file
        raise UsageError(f"--mesh {path}: trimesh cannot read it as a triangle mesh ({exc})") from None
    faces = np.asarray(getattr(mesh, "faces", np.empty((0, 3))))
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        raise UsageError(f"--mesh {path}: no triangles in it")
    return np.asarray(mesh.vertices, dtype=np.float64), faces


def cmd_sample_mesh(args: argparse.Namespace) -> int:
    from .mesh import MeshSampler
    for name, unset in _BOX_ONLY.items():
        if getattr(args, name, unset) != unset:
            raise UsageError(f"--{name.replace('_', '-')} is not available with --mesh")
    if args.dim != 2:
        raise UsageError("--dim is not available with --mesh (a surface in 3D)")
    if args.stream is not None and args.stream < 0:
        raise UsageError(f"--stream {args.stream}: must be >= 0")
    if args.stream is not None and args.refine is not None:
        raise UsageError("--stream with --refine: the stream gives the points and their scales; "
                         "use one or the other")
    if args.output:
        check_output(Path(args.output), 3)
    if args.plot:
        check_plot(Path(args.plot))  # before sampling, not after
    refine = scales_arg(args.refine)
    number_arg(args.lipschitz, "--lipschitz", strict=False)
    vertices, faces = _load(Path(args.mesh))
    sizing = None
    if args.sizing is not None:  # probed at the centre of the mesh's bounding box
        centre = (vertices.min(axis=0) + vertices.max(axis=0)) / 2
        sizing = sizing_from_expression(args.sizing, 3, at=centre,
                                        where="the centre of the mesh's bounding box")
    sampler = MeshSampler(vertices, faces, radius=args.radius, sizing=sizing, lipschitz=args.lipschitz,
                          rule=args.rule, inhibition=args.inhibition, coverage=args.coverage,
                          rng=args.seed)
    t0 = time.perf_counter()
    if args.stream is not None:
        sampler.progressive(args.stream)  # exactly N points, each prefix maximal at its scale
    else:
        sampler.run()
        for t in refine:
            sampler.refine(t)
    seconds = time.perf_counter() - t0
    s = sampler.samples
    what = f"r = {args.sizing}" if args.sizing is not None else f"radius {args.radius}"
    print(f"{len(s.points)} samples on {args.mesh} ({len(faces)} triangles; {what}, rule {args.rule}, "
          f"seed {args.seed}) in {seconds:.3f} s; maximal: {s.maximal}")
    if args.output:
        from . import STREAM_TOLERANCE
        meta = dict(mesh=str(args.mesh), rule=args.rule, seed=args.seed, coverage=args.coverage,
                    inhibition=args.inhibition, refine=refine, complete=True,
                    mode="stream" if args.stream is not None else "refine" if refine else "run",
                    **({"stream_tolerance": STREAM_TOLERANCE} if args.stream is not None else {}),
                    **({"sizing": args.sizing, "lipschitz": args.lipschitz} if args.sizing is not None
                       else {"radius": args.radius}))
        try:
            write_points(Path(args.output), s.points, s.radii, s.scales, np.zeros(len(s.points), bool),
                         meta, columns={"face": s.faces, "b0": s.barycentrics[:, 0],
                                        "b1": s.barycentrics[:, 1], "b2": s.barycentrics[:, 2]})
        except OSError as exc:
            raise UsageError(f"-o {args.output}: cannot write it: {exc.strerror or exc}") from None
        print(f"wrote {args.output}")
    if args.plot:
        from .plots import plot_mesh
        try:
            plot_mesh(Path(args.plot), vertices, faces, s.points,
                      f"{len(s.points)} samples on {Path(args.mesh).name}, {what}, rule {args.rule}",
                      radii=s.radii)
        except OSError as exc:
            raise UsageError(f"--plot {args.plot}: cannot write it: {exc.strerror or exc}") from None
        print(f"wrote {args.plot}")
    return 0
