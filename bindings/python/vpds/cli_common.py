"""What the `vpds` subcommands share: the usage error (one line, exit status 2) and the parsing
of option values that argparse cannot check alone (corners, axes, sizing expressions)."""
from __future__ import annotations

import ast
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

from ._optional import require

if TYPE_CHECKING:  # for the annotation: vpds.domain loads the C extension
    from .domain import GeometryLike

__all__ = ["UsageError", "domain_from_file", "floats_arg", "periodic_arg", "sizing_from_expression", "EXPR_NAMES"]


class UsageError(Exception):
    """A user mistake on the command line: printed as one line, exit status 2."""


# names a --sizing expression may use, besides x (the coordinates, x[k] the k-th, shape (d, m))
EXPR_NAMES = {name: getattr(np, name) for name in (
    "sin", "cos", "tan", "exp", "log", "sqrt", "abs", "minimum", "maximum", "clip", "where",
    "hypot", "arctan2", "pi", "e", "linalg")}
EXPR_NAMES["np"] = np


def sizing_from_expression(expr: str, dim: int, option: str = "--sizing"
                           ) -> Callable[[npt.NDArray[np.float64]], npt.NDArray[np.float64]]:
    """r(x) from a numpy expression in x, where x[k] is the k-th coordinate of all points.
    A syntax error, an unknown name or a value that is not a radius is a UsageError."""
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
    probe = np.full((1, dim), 0.5)
    try:
        with np.errstate(all="ignore"):
            r = sizing(probe)
    except Exception as exc:  # noqa: BLE001 - the user's expression: reported as a usage error
        raise UsageError(f"{option} {expr!r} does not evaluate at the box centre's "
                         f"coordinates in {dim}D: {type(exc).__name__}: {exc}") from None
    if not (math.isfinite(float(r[0])) and r[0] > 0):
        raise UsageError(f"{option} {expr!r} gives r = {float(r[0])!r} at x = 0.5: a radius "
                         "must be finite and > 0")
    return sizing


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


def domain_from_file(path: Path) -> Union[npt.NDArray[Any], GeometryLike, str]:
    """--domain FILE: an image (.png, .exr, ...: a mask over the box), a .npy array (a mask
    with one axis per dimension, or (m, 2) polygon vertices), or a .wkt polygon (shapely)."""
    if not path.is_file():
        raise UsageError(f"--domain {path}: no such file")
    try:
        if path.suffix.lower() == ".npy":
            array: npt.NDArray[Any] = np.load(path, allow_pickle=False)
            return array
        if path.suffix.lower() == ".wkt":
            polygon: GeometryLike = require("shapely.wkt", "--domain .wkt", "shapely").loads(path.read_text())
            return polygon
    except (OSError, ValueError) as exc:
        raise UsageError(f"--domain {path}: cannot read it: {exc}") from None
    return str(path)
