"""What the `vpds` subcommands share: the usage error (one line, exit status 2) and the parsing
of option values that argparse cannot check alone (corners, axes, sizing expressions)."""
from __future__ import annotations

import ast
import math
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

from ._optional import require

if TYPE_CHECKING:  # for the annotation: vpds.domain loads the C extension
    from .domain import GeometryLike

__all__ = ["UsageError", "check_directory", "check_plot", "domain_from_file", "exr_range_arg",
           "floats_arg", "number_arg", "periodic_arg", "scales_arg", "sizing_from_expression",
           "EXPR_NAMES"]


class UsageError(Exception):
    """A user mistake on the command line: printed as one line, exit status 2."""


# names a --sizing expression may use, besides x (the coordinates, x[k] the k-th, shape (d, m))
EXPR_NAMES = {name: getattr(np, name) for name in (
    "sin", "cos", "tan", "exp", "log", "sqrt", "abs", "minimum", "maximum", "clip", "where",
    "hypot", "arctan2", "pi", "e", "linalg")}
EXPR_NAMES["np"] = np


def sizing_from_expression(expr: str, dim: int, option: str = "--sizing",
                           at: Optional[npt.ArrayLike] = None, where: str = "the box centre"
                           ) -> Callable[[npt.NDArray[np.float64]], npt.NDArray[np.float64]]:
    """r(x) from a numpy expression in x, where x[k] is the k-th coordinate of all points.
    An empty expression, a syntax error, an unknown name or a value that is not a radius at the
    probe point `at` (default: 0.5 on every axis), which `where` names, is a UsageError."""
    if not expr.strip():
        raise UsageError(f"{option} {expr!r}: empty; give r(x) as an expression in x, e.g. "
                         "'0.01 + 0.3*x[0]'")
    try:
        tree = ast.parse(expr, mode="eval")
    except SyntaxError as exc:
        raise UsageError(f"{option} {expr!r}: not a Python expression ({exc.msg} at column "
                         f"{exc.offset})") from None
    unknown = sorted({n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
                     - set(EXPR_NAMES) - {"x"})
    if unknown:
        raise UsageError(f"{option} {expr!r}: unknown name {', '.join(unknown)} (use x[0].."
                         f"x[{dim - 1}] and {', '.join(sorted(EXPR_NAMES))})")
    code = compile(tree, f"<{option}>", "eval")

    def sizing(points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        value = eval(code, {"__builtins__": {}}, dict(EXPR_NAMES, x=points.T))  # noqa: S307
        r: npt.NDArray[np.float64] = np.broadcast_to(np.asarray(value, dtype=np.float64), (len(points),)).copy()
        return r
    probe = np.full((1, dim), 0.5) if at is None else np.asarray(at, dtype=np.float64).reshape(1, dim)
    point = (f"{probe[0, 0]:g}" if np.all(probe == probe[0, 0])
             else "(" + ", ".join(f"{v:g}" for v in probe[0]) + ")")
    try:
        with np.errstate(all="ignore"):
            r = sizing(probe)
    except Exception as exc:  # noqa: BLE001 - the user's expression: reported as a usage error
        raise UsageError(f"{option} {expr!r} does not evaluate at {where}, x = {point} "
                         f"({dim} coordinates x[0]..x[{dim - 1}]): {type(exc).__name__}: {exc}") from None
    if not (math.isfinite(float(r[0])) and r[0] > 0):
        raise UsageError(f"{option} {expr!r} gives r = {float(r[0])!r} at x = {point} ({where}): "
                         "a radius must be finite and > 0")
    return sizing


def number_arg(value: Optional[float], option: str, *, minimum: float = 0.0, strict: bool = True
               ) -> None:
    """A numeric option that must be finite and > minimum (>= minimum when not strict);
    None (not given) passes."""
    if value is None:
        return
    if not math.isfinite(value) or value < minimum or (strict and value == minimum):
        raise UsageError(f"{option} {value:g}: must be finite and {'>' if strict else '>='} "
                         f"{minimum:g}")


def scales_arg(text: Optional[str], option: str = "--refine") -> list[float]:
    """--refine: comma-separated scales t, each finite, in (0, 1], none above the one before."""
    if text is None:
        return []
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise UsageError(f"{option} {text!r}: expected scales separated by commas, e.g. "
                         "0.8,0.5") from None
    for k, t in enumerate(values):
        if not (math.isfinite(t) and 0 < t <= 1):
            raise UsageError(f"{option} {text!r}: scale {t:g} must be finite and in (0, 1] "
                             "(the fill is at t = 1)")
        if k and t > values[k - 1]:
            raise UsageError(f"{option} {text!r}: scale {t:g} is above the one before it "
                             f"({values[k - 1]:g}); refinement goes to smaller scales")
    return values


def exr_range_arg(text: Optional[str]) -> Optional[list[float]]:
    """--exr-range LO,HI: two finite numbers with 0 < LO <= HI."""
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 2:
        raise UsageError(f"--exr-range {text!r}: expected LO,HI (two radii, e.g. 0.01,0.05)")
    if not (all(math.isfinite(v) for v in values) and 0 < values[0] <= values[1]):
        raise UsageError(f"--exr-range {text!r}: need finite 0 < LO <= HI")
    return values


def check_directory(path: Path, option: str) -> None:
    """The directory a file will be written into exists and a file can be created in it (a
    temporary one, removed at once: os.access says yes to root on a read-only file system)."""
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"{option} {path}: directory {parent} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".probe", dir=parent)
    except OSError as exc:
        raise UsageError(f"{option} {path}: directory {parent} is not writable "
                         f"({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(tmp)


def check_plot(path: Path, option: str = "--plot") -> None:
    """Refuse a plot path before sampling: matplotlib missing, a format it cannot write, a
    directory that is missing or not writable."""
    backend_bases = require("matplotlib.backend_bases", option, "matplotlib")
    formats = sorted(backend_bases.FigureCanvasBase.get_supported_filetypes())
    suffix = path.suffix.lower().lstrip(".")
    if suffix not in formats:
        raise UsageError(f"{option} {path}: unsupported extension {path.suffix or '(none)'!r}; "
                         f"use one matplotlib writes: .{', .'.join(formats)}")
    check_directory(path, option)


def floats_arg(text: Optional[str], dim: int, default: float, option: str) -> npt.NDArray[np.float64]:
    """--lo / --hi: one value for every axis, or `dim` comma-separated finite values."""
    if text is None:
        return np.full(dim, default)
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise UsageError(f"{option} {text!r}: expected numbers separated by commas") from None
    if not all(math.isfinite(v) for v in values):
        raise UsageError(f"{option} {text!r}: the values must be finite")
    if len(values) == 1:
        values = values * dim
    if len(values) != dim:
        raise UsageError(f"{option} {text!r} has {len(values)} values for --dim {dim}")
    return np.array(values)


def periodic_arg(text: Optional[str], dim: int) -> Optional[list[bool]]:
    """--periodic: comma-separated axis indices, or 'all'."""
    if not text:
        return None
    if text == "all":
        return [True] * dim
    try:
        axes = {int(a) for a in text.split(",")}
    except ValueError:
        raise UsageError(f"--periodic {text!r}: expected axis indices separated by commas, "
                         "or 'all'") from None
    bad = sorted(a for a in axes if not 0 <= a < dim)
    if bad:
        raise UsageError(f"--periodic {text!r}: axis {bad[0]} is not in 0..{dim - 1}")
    return [k in axes for k in range(dim)]


def check_unused_options(args: Any) -> None:
    """`vpds sample`'s options that only mean something with another one: refused without it,
    rather than silently ignored."""
    needs = [("channel", "--channel", args.sizing_exr is not None, "--sizing-exr"),
             ("exr_range", "--exr-range", args.sizing_exr is not None, "--sizing-exr"),
             ("workers", "--workers", args.tiles is not None, "--tiles"),
             ("address", "--address", args.tiles is not None, "--tiles"),
             ("overwrite", "--overwrite", args.tiles is not None, "--tiles"),
             ("radius_max", "--radius-max", args.tiles is not None or args.threads is not None,
              "--threads or --tiles")]
    for name, flag, ok, other in needs:
        value = getattr(args, name)
        if value not in (None, False) and not ok:
            shown = "" if value is True else f" {value}"
            raise UsageError(f"{flag}{shown} has no effect without {other}")


def domain_from_file(path: Path) -> Union[npt.NDArray[Any], GeometryLike, str]:
    """--domain FILE: an image (.png, .exr, ...: a mask over the box), a .npy array (a mask
    with one axis per dimension, or (m, 2) polygon vertices), or a .wkt polygon (shapely).
    A file that cannot be read as what its extension says is a UsageError naming --domain."""
    if not path.is_file():
        raise UsageError(f"--domain {path}: no such file")
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            array: npt.NDArray[Any] = np.load(path, allow_pickle=False)
            return array
        if suffix == ".wkt":
            wkt = require("shapely.wkt", "--domain .wkt", "shapely")
            errors = require("shapely.errors", "--domain .wkt", "shapely")
            try:
                polygon: GeometryLike = wkt.loads(path.read_text())
            except errors.ShapelyError as exc:
                raise UsageError(f"--domain {path}: not a WKT polygon ({exc})") from None
            return polygon
    except (OSError, ValueError) as exc:
        raise UsageError(f"--domain {path}: cannot read it: {exc}") from None
    # an image: read here once, so that a file no reader knows is named as --domain's
    if suffix == ".exr":
        require("OpenEXR", "--domain .exr", "OpenEXR")
        known = True
    else:
        image = require("PIL.Image", f"--domain {suffix or 'FILE'} (an image)", "Pillow")
        known = suffix in image.registered_extensions()
    from .domain import read_image
    try:
        read_image(path)
    except (OSError, ValueError, RuntimeError) as exc:  # PIL's UnidentifiedImageError is an OSError
        what = ("cannot read it as an image" if known else
                f"{suffix or 'no extension'}: not an image, a .npy mask or polygon, or a .wkt polygon")
        why = str(exc).removeprefix(f"{path}: ")
        raise UsageError(f"--domain {path}: {what} ({why})") from None
    return str(path)
