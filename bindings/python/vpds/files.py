"""The files `vpds sample` writes and `vpds analyze` reads, with what analysis needs to know.

Every format but .npy carries the run's parameters as JSON (`meta`: dim, lo, hi, rule, radius
or sizing, lipschitz, inhibition, coverage, periodic, domain, mode and tolerance): in .npz an
array `meta`, in .csv a last line `# vpds {...}` (pandas: comment="#"), in .ply a `comment vpds {...}` line, in a
Zarr tile store the root attribute `vpds_cli`. Files are written to a temporary name beside the
target and renamed, so an interrupted write never leaves half a file."""
from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO, Callable, Mapping, Optional, cast

import numpy as np
import numpy.typing as npt

from .cli_common import UsageError, check_directory

__all__ = ["Record", "OUTPUT_SUFFIXES", "check_output", "write_points", "read_points"]

OUTPUT_SUFFIXES = (".npy", ".npz", ".csv", ".ply")


@dataclass
class Record:
    """A sampling read back: points (n, d), radii, scales t and fixed flags (None when the file
    has none), the run's parameters, and arrays they refer to (a sizing grid)."""
    points: npt.NDArray[np.float64]
    radii: Optional[npt.NDArray[np.float64]]
    scales: Optional[npt.NDArray[np.float64]]
    fixed: Optional[npt.NDArray[np.bool_]]
    meta: dict[str, Any] = field(default_factory=dict)
    arrays: dict[str, npt.NDArray[Any]] = field(default_factory=dict)


def check_output(path: Path, dim: int) -> None:
    """Refuse an output path before sampling: a suffix we cannot write, a directory that is
    missing or where no file can be created."""
    suffix = path.suffix.lower()
    if suffix not in OUTPUT_SUFFIXES:
        raise UsageError(f"-o {path}: unsupported extension {suffix or '(none)'!r}; use "
                         f"{', '.join(OUTPUT_SUFFIXES)} (or .zarr with --tiles)")
    if suffix == ".ply" and dim > 3:
        raise UsageError(f"-o {path}: .ply holds up to 3 coordinates, --dim is {dim}")
    check_directory(path, "-o")


def _atomic(path: Path, write: Callable[[BinaryIO], None]) -> None:
    """write(file object) into a temporary file beside `path`, then rename it over `path`."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent or ".")
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 is not what a plain open would give
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def write_points(path: Path, x: npt.NDArray[np.float64], r: npt.NDArray[np.float64],
                 t: npt.NDArray[np.float64], fixed: npt.NDArray[np.bool_],
                 meta: Optional[dict[str, Any]] = None,
                 arrays: Optional[dict[str, npt.NDArray[Any]]] = None,
                 columns: Optional[dict[str, npt.NDArray[Any]]] = None) -> None:
    """Samples x (n, d) with r, t and fixed (n,) as .npy: the points; .npz: points, radii, scales,
    fixed, meta (and `arrays`); .csv: x0.., r, t, fixed; .ply: x, y, z (zero-padded below 3D),
    radius and t as vertex properties. `columns`: more per-sample values (n,) by name, in .npz
    as arrays, in .csv as columns and in .ply as properties (int for an integer array)."""
    cols = columns or {}
    suffix = path.suffix.lower()
    n, d = x.shape
    info = json.dumps(meta or {}, sort_keys=True)
    if suffix == ".npy":
        _atomic(path, lambda f: np.save(f, x))
    elif suffix == ".npz":
        # Any: savez's annotations would have **extra hold its allow_pickle flag too
        extra: dict[str, Any] = {f"meta_{k}": v for k, v in (arrays or {}).items()}
        extra.update(cols)
        _atomic(path, lambda f: np.savez(f, points=x, radii=r, scales=t, fixed=fixed,
                                         meta=np.array(info), **extra))
    elif suffix == ".csv":
        header = ",".join([f"x{k}" for k in range(d)] + ["r", "t", "fixed"] + list(cols))
        table = np.column_stack([x, r, t, fixed.astype(float)] + [np.asarray(c, float) for c in cols.values()])
        # the parameters last, as a comment: readers that skip the header row still work
        _atomic(path, lambda f: np.savetxt(f, table, delimiter=",", header=header, comments="",
                                           footer=f"# vpds {info}", fmt="%.17g"))
    elif suffix == ".ply":
        xyz = np.zeros((n, 3))
        xyz[:, :d] = x

        def ply(f: BinaryIO) -> None:
            f.write(b"ply\nformat ascii 1.0\ncomment libvpds sample\n")
            f.write(f"comment vpds {info}\n".encode())
            props = "".join(f"property {'int' if np.issubdtype(np.asarray(c).dtype, np.integer) else 'double'}"
                            f" {name}\n" for name, c in cols.items())
            f.write(f"element vertex {n}\nproperty double x\nproperty double y\n"
                    f"property double z\nproperty double radius\nproperty double t\n{props}"
                    "end_header\n".encode())
            np.savetxt(f, np.column_stack([xyz, r, t] + [np.asarray(c, float) for c in cols.values()]),
                       fmt="%.17g")
        _atomic(path, ply)
    else:
        raise UsageError(f"-o {path}: use {', '.join(OUTPUT_SUFFIXES)}")


def _meta(text: str, path: Path) -> dict[str, Any]:
    try:
        value = json.loads(text)
    except ValueError:
        raise UsageError(f"{path}: its vpds parameters are not valid JSON") from None
    return value if isinstance(value, dict) else {}


def read_points(path: Path) -> Record:
    """A Record from .npz, .npy, .csv, .ply as `vpds sample` writes them, or a .zarr store."""
    if path.suffix.lower() == ".zarr" or (path / "zarr.json").exists():
        return _read_zarr(path)
    if not path.exists():
        raise UsageError(f"{path}: no such file")
    suffix = path.suffix.lower()
    try:
        if suffix == ".npz":
            return _read_npz(path)
        if suffix == ".npy":
            x = np.load(path, allow_pickle=False)
            return Record(_points(x, path), None, None, None)
        if suffix == ".csv":
            return _read_csv(path)
        if suffix == ".ply":
            return _read_ply(path)
    except (OSError, ValueError, KeyError, IndexError) as exc:
        if isinstance(exc, UsageError):
            raise
        raise UsageError(f"{path}: cannot read it as {suffix}: {exc}") from None
    raise UsageError(f"{path}: use .npz, .npy, .csv, .ply or a .zarr store")


def _points(x: npt.NDArray[Any], path: Path) -> npt.NDArray[np.float64]:
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] < 1:
        raise UsageError(f"{path}: points have shape {x.shape}; expected (n, d)")
    return x


def _read_npz(path: Path) -> Record:
    z = np.load(path, allow_pickle=False)
    if "points" not in z.files:
        raise UsageError(f"{path}: no array 'points' (it has {', '.join(z.files) or 'none'}); "
                         "vpds sample -o FILE.npz writes points, radii, scales, fixed")
    x = _points(z["points"], path)
    get = {k: (z[k] if k in z.files else None) for k in ("radii", "scales", "fixed")}
    for k, v in get.items():
        if v is not None and v.shape != (len(x),):
            raise UsageError(f"{path}: array {k!r} has shape {v.shape} for {len(x)} points")
    meta = _meta(str(z["meta"]), path) if "meta" in z.files else {}
    arrays = {k[5:]: z[k] for k in z.files if k.startswith("meta_")}
    return Record(x, get["radii"], get["scales"],
                  None if get["fixed"] is None else get["fixed"].astype(bool), meta, arrays)


def _read_csv(path: Path) -> Record:
    lines = path.read_text().splitlines()
    meta = next((_meta(line[7:], path) for line in lines if line.startswith("# vpds ")), {})
    lines = [line for line in lines if not line.startswith("#")]
    if not lines:
        raise UsageError(f"{path}: empty")
    header = lines[0].split(",")
    table = np.atleast_2d(np.loadtxt(lines[1:], delimiter=",", ndmin=2)) if len(lines) > 1 \
        else np.empty((0, len(header)))
    dims = [i for i, h in enumerate(header) if h in ("x", "y", "z") or (h[:1] == "x" and h[1:].isdigit())]
    if not dims:
        raise UsageError(f"{path}: no coordinate columns (x0, x1, ... as vpds sample writes)")
    col = {h: i for i, h in enumerate(header)}
    pick: Callable[[str], Optional[npt.NDArray[np.float64]]] = (lambda h: table[:, col[h]] if h in col else None)
    fixed = pick("fixed")
    return Record(table[:, dims], pick("r"), pick("t"), None if fixed is None else fixed != 0, meta)


def _read_ply(path: Path) -> Record:
    lines = path.read_text().splitlines()
    if "end_header" not in lines:
        raise UsageError(f"{path}: not a PLY file (no end_header)")
    head = lines[:lines.index("end_header")]
    meta = next((_meta(h[len("comment vpds "):], path) for h in head
                 if h.startswith("comment vpds ")), {})
    body = np.atleast_2d(np.loadtxt(lines[lines.index("end_header") + 1:], ndmin=2))
    d = int(meta.get("dim", 0)) or (max([k for k in range(3) if np.any(body[:, k] != 0)] or [0]) + 1)
    return Record(body[:, :d], body[:, 3], body[:, 4], None, meta)


def _read_zarr(path: Path) -> Record:
    from ._optional import require
    require("zarr", "reading a tile store", "zarr")
    from .tilestore import TileStore
    try:
        store = TileStore(path)
    except (OSError, ValueError, KeyError) as exc:
        raise UsageError(f"{path}: not a readable vpds tile store: {exc}") from None
    missing = store.missing()
    if missing:
        raise UsageError(f"{path}: {len(missing)} of {store.count} tiles are not complete "
                         "(resume the run first)")
    x, r, t = store.to_numpy("insertion")
    import zarr
    # the `vpds sample --tiles` record: a JSON object (cli_tiles.py writes it)
    meta = dict(cast(Mapping[str, Any], zarr.open_group(str(path), mode="r").attrs.get("vpds_cli", {})))
    params = store.params  # what the tiling itself recorded (a callable sizing only by kind)
    meta.setdefault("dim", params["d"])
    meta.setdefault("lo", params["l_bounds"])
    meta.setdefault("hi", params["u_bounds"])
    if params.get("sizing") == "radius":
        meta.setdefault("radius", params["radius"])
    for key in ("rule", "inhibition", "coverage", "lipschitz", "periodic"):
        if key not in meta and params.get(key) is not None:
            meta[key] = params[key]
    meta.setdefault("mode", "tiles")
    return Record(x, r, t, np.zeros(len(x), dtype=bool), meta)
