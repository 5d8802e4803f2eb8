"""`vpds analyze FILE`: check a sampling against the guarantees its run promises, and say which
were checked, which held, and which could not be checked and why.

What the run promised is read from the file (`vpds sample` records its parameters, see
vpds.files); flags override. Exit status: 0 when every applicable check ran and held, 1 when one
failed, 3 when none failed but some could not run (the verdict says which and why)."""
from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, Callable, Optional

import numpy as np
import numpy.typing as npt

from ._core import RULES
from ._optional import require
from .cli_common import UsageError, check_plot, domain_from_file, floats_arg, number_arg, sizing_from_expression
from .files import Record, read_points

if TYPE_CHECKING:  # for the annotations: vpds.analysis needs scipy, imported when run
    from .analysis import Sizing

EXIT_FAILED, EXIT_UNCHECKED = 1, 3


@dataclass
class Check:
    name: str
    status: str   # "passed", "FAILED" or "not checked"
    detail: str


@dataclass
class Params:
    """What the run promised: from the flags, else the file, else the defaults."""
    dim: int
    lo: npt.NDArray[np.float64]
    hi: npt.NDArray[np.float64]
    rule: str
    inhibition: float
    coverage: float
    periodic: Optional[list[bool]]
    scale: float
    tolerance: float        # relative: the stream's t is an upper bound (VPDS_STREAM_TOLERANCE)
    mode: str
    sizing: Optional[Sizing]  # None: radii vary and r(x) is unknown
    sizing_note: str
    domain: Optional[str]
    domain_threshold: float


def _sizing(args: argparse.Namespace, rec: Record, meta: dict[str, Any], dim: int,
            lo: npt.NDArray[np.float64], hi: npt.NDArray[np.float64], analysis: ModuleType
            ) -> tuple[Optional[Sizing], str]:
    """The sizing r(x) and L to check against, and where they came from."""
    expr = args.sizing if args.sizing is not None else (meta.get("sizing") if args.radius is None else None)
    if expr is not None:
        lip = args.lipschitz if args.lipschitz is not None else meta.get("lipschitz")
        if lip is None:
            raise UsageError(f"--sizing {expr!r} needs --lipschitz (the file does not record it)")
        src = "--sizing" if args.sizing is not None else "the file"
        return analysis.Sizing(sizing_from_expression(expr, dim), float(lip)), f"r = {expr} ({src})"
    if args.radius is not None:
        return analysis.sizing_named("const", args.radius), f"radius {args.radius} (--radius)"
    if "sizing_grid" in rec.arrays and meta.get("lipschitz") is not None:
        interp = require("scipy.interpolate", "vpds analyze", "scipy")
        values = np.asarray(rec.arrays["sizing_grid"], dtype=np.float64)
        axes = tuple(np.linspace(a, b, m) for a, b, m in zip(lo, hi, values.shape))
        grid = interp.RegularGridInterpolator(axes, values, method="linear")
        return (analysis.Sizing(lambda y: grid(np.clip(y, lo, hi)), float(meta["lipschitz"])),
                f"the sizing grid the run used ({meta.get('sizing_exr', 'an image')})")
    if meta.get("radius") is not None:
        return analysis.sizing_named("const", float(meta["radius"])), f"radius {meta['radius']} (the file)"
    r = rec.radii
    if r is not None and len(r) and np.all(r == r[0]):
        return analysis.sizing_named("const", float(r[0])), f"radius {r[0]} (every sample's r)"
    return None, "unknown (radii vary; the file does not record r(x): give --sizing and --lipschitz)"


def _params(args: argparse.Namespace, rec: Record, analysis: ModuleType) -> Params:
    meta, dim = rec.meta, rec.points.shape[1]
    pick: Callable[[Any, str, Any], Any] = (
        lambda flag, key, default: flag if flag is not None else meta.get(key, default))
    lo = floats_arg(args.lo, dim, 0.0, "--lo") if args.lo else np.asarray(meta.get("lo", [0.0] * dim), dtype=np.float64)
    hi = floats_arg(args.hi, dim, 1.0, "--hi") if args.hi else np.asarray(meta.get("hi", [1.0] * dim), dtype=np.float64)
    if lo.shape != (dim,) or hi.shape != (dim,):
        raise UsageError(f"{args.file}: the recorded box has {lo.size} axes for {dim}D points")
    t = rec.scales
    finite = t[np.isfinite(t)] if t is not None else np.empty(0)
    scale = args.scale if args.scale is not None else (float(finite.min()) if len(finite) else 1.0)
    sizing, note = _sizing(args, rec, meta, dim, lo, hi, analysis)
    rule = pick(args.rule, "rule", "smaller")
    if rule not in RULES:
        raise UsageError(f"{args.file}: recorded rule {rule!r} is not one of {sorted(RULES)}")
    factors = {}
    for key in ("inhibition", "coverage"):  # a flag is checked in cmd_analyze; this is the file's
        value = float(pick(getattr(args, key), key, 1.0))
        if not (math.isfinite(value) and value > 0):
            raise UsageError(f"{args.file}: recorded {key} {value!r} is not finite and > 0 "
                             f"(give --{key})")
        factors[key] = value
    if not (math.isfinite(scale) and scale > 0):
        raise UsageError(f"{args.file}: its smallest scale t = {scale!r} is not > 0 (give --scale)")
    return Params(dim, lo, hi, rule, factors["inhibition"],
                  factors["coverage"], meta.get("periodic"), scale,
                  float(meta.get("stream_tolerance", 0.0)), str(meta.get("mode", "unknown")),
                  sizing, note, meta.get("domain"), float(meta.get("domain_threshold") or 0.5))


def _empty_disk(rec: Record, p: Params, analysis: ModuleType) -> Check:
    x, r = rec.points, rec.radii
    t = rec.scales if rec.scales is not None else np.full(len(x), p.scale)
    lip = p.sizing.lipschitz if p.sizing is not None else math.inf
    bad = analysis.conflicts_at_insertion_scales(x, r, t, p.rule, p.inhibition, lip, p.tolerance,
                                                 periodic=p.periodic, lo=p.lo, hi=p.hi)
    tol = f", within the stream's tolerance {p.tolerance:g}" if p.tolerance else ""
    return Check("empty disk (Eq. 10, insertion order, each pair at its later sample's t"
                 f"{tol})", "passed" if bad == 0 else "FAILED", f"{bad} conflicting pairs")


def _maximal(rec: Record, p: Params, analysis: ModuleType) -> Check:
    name = f"maximality at t = {p.scale:g}"
    if p.sizing is None:
        return Check(name, "not checked", "r(x) is unknown: give --sizing and --lipschitz")
    s_c = p.scale * p.coverage
    if p.domain is not None:
        return _maximal_in_domain(rec, p, analysis, name, s_c, p.domain, p.sizing)
    try:
        rep = analysis.check_maximal(rec.points, rec.radii, p.rule, s_c, p.sizing, p.lo, p.hi,
                                     periodic=p.periodic)
    except RuntimeError as exc:  # the branch-and-bound's box budget: too large to decide here
        return Check(name, "not checked", f"{exc} (too many points for the exhaustive search)")
    ok = rep.gaps == 0 and rep.probes_max_rel <= 1e-9
    return Check(name + " (branch-and-bound over the box, and probes)",
                 "passed" if ok else "FAILED", f"{rep.gaps} uncovered points, {rep.boxes} boxes")


def _maximal_in_domain(rec: Record, p: Params, analysis: ModuleType, name: str, s_c: float,
                       domain: str, sizing: Sizing) -> Check:
    """Probes of the domain only: the branch-and-bound covers boxes, not a domain's boundary.
    `domain` and `sizing` are p's, known here (not None)."""
    from .domain import as_domain
    dom = as_domain(domain_from_file(Path(domain)), p.dim, p.lo, p.hi, p.domain_threshold)
    rng = np.random.default_rng(0)
    y = p.lo + (p.hi - p.lo) * rng.random((200_000, p.dim))
    y = y[dom(y) <= 0]
    ry = sizing.fn(y)
    tree = require("scipy.spatial", "vpds analyze", "scipy").cKDTree(rec.points)
    g = analysis.coverage_margin(y, tree, rec.points, rec.radii, p.rule, s_c, ry, exact=True)
    gaps = int(np.count_nonzero(g > 1e-9 * ry))
    if gaps:
        return Check(name, "FAILED", f"{gaps} of {len(y)} probes of the domain uncovered")
    return Check(name, "not checked", f"only by {len(y)} random probes of the domain (all "
                 "covered): no exhaustive search inside a domain's boundary")


def _table1(rec: Record, p: Params, analysis: ModuleType) -> Optional[Check]:
    if p.dim != 2 or len(rec.points) < 3:
        return None
    name = "Delaunay bounds (Table 1)"
    if p.sizing is None:
        return Check(name, "not checked", "r(x) and L are unknown: give --sizing and --lipschitz")
    if p.domain is not None or p.periodic:
        return Check(name, "not checked", "the triangles near a domain's boundary or a periodic "
                     "seam are not bounded by it, and no filter for them is implemented")
    if p.inhibition != p.coverage:
        if p.sizing.lipschitz != 0:
            return Check("Delaunay bounds (Prop. 4.1-4.2)", "not checked",
                         "two radii with a varying r: no bound implemented")
        assert rec.radii is not None  # cmd_analyze fills in the radii a file lacks
        rep = analysis.check_delaunay_two_radii(rec.points, float(rec.radii[0]), p.scale,
                                                p.inhibition * (1 - p.tolerance), p.coverage,
                                                p.lo, p.hi)
        bad = rep.violations()
        return Check("Delaunay bounds (Prop. 4.1-4.2)", "FAILED" if bad else "passed",
                     "; ".join(bad) or f"{rep.triangles} interior triangles")
    s = p.scale * p.coverage
    rep = analysis.check_delaunay(rec.points, rec.radii, p.rule, s * p.sizing.lipschitz, p.lo, p.hi)
    slack = 1e-12 + p.tolerance
    emin, emax = rep.edge_min_bound * s, rep.edge_max_bound * s
    ok = (rep.min_angle_deg >= rep.angle_bound_deg * (1 - slack) and
          rep.edge_min_ratio >= emin * (1 - slack) and rep.edge_max_ratio <= emax * (1 + slack))
    return Check(name, "passed" if ok else "FAILED",
                 f"{rep.triangles} interior triangles: min angle {rep.min_angle_deg:.2f} deg (>= "
                 f"{rep.angle_bound_deg:.2f}), edge / r(x) in [{rep.edge_min_ratio:.3f}, "
                 f"{rep.edge_max_ratio:.3f}] (bounds [{emin:.3f}, {emax:.3f}])")


def _check_flags(args: argparse.Namespace) -> None:
    """The numeric flags: each a usage error naming it when it cannot mean what it says."""
    if args.sizing is not None and not args.sizing.strip():
        raise UsageError(f"--sizing {args.sizing!r}: empty; give r(x) as an expression in x")
    number_arg(args.radius, "--radius")
    number_arg(args.lipschitz, "--lipschitz", strict=False)
    number_arg(args.inhibition, "--inhibition")
    number_arg(args.coverage, "--coverage")
    number_arg(args.scale, "--scale")


# why a file has no radii, by its format
_NO_RADII = {".npy": "a .npy holds points only", ".csv": "no column r",
             ".npz": "no array 'radii'", ".ply": "no radius property"}


def _check_points(rec: Record, path: Path) -> None:
    """Points (and radii) the checks can use: at least one, all finite (radii > 0)."""
    n = len(rec.points)
    if n == 0:
        raise UsageError(f"{path}: no points in it: nothing to analyze")
    bad = int(np.count_nonzero(~np.all(np.isfinite(rec.points), axis=1)))
    if bad:
        raise UsageError(f"{path}: {bad} of {n} points have a non-finite coordinate (NaN or inf)")
    if rec.radii is not None:
        r = np.asarray(rec.radii, dtype=np.float64)
        bad = int(np.count_nonzero(~(np.isfinite(r) & (r > 0))))
        if bad:
            raise UsageError(f"{path}: {bad} of {n} radii are not finite and > 0")


def cmd_analyze(args: argparse.Namespace) -> int:
    analysis = require("vpds.analysis", "vpds analyze", "scipy")
    _check_flags(args)
    if args.plot:
        check_plot(Path(args.plot))  # before the analysis, not after
    path = Path(args.file)
    rec = read_points(path)
    _check_points(rec, path)
    if rec.radii is None:
        if args.radius is None and args.sizing is None:
            why = _NO_RADII.get(path.suffix.lower(), "none recorded")
            raise UsageError(f"{args.file}: the file has no radii ({why}): "
                             "give --radius or --sizing with --lipschitz")
        fn = (sizing_from_expression(args.sizing, rec.points.shape[1]) if args.sizing is not None
              else (lambda y: np.full(len(y), args.radius)))
        rec.radii = fn(rec.points)
        _check_points(rec, path)
    p = _params(args, rec, analysis)
    n = len(rec.points)
    print(f"{n} points in {p.dim}D, rule {p.rule}, {p.sizing_note}, scale t = {p.scale:g}, "
          f"inhibition {p.inhibition:g}, coverage {p.coverage:g}, run: {p.mode}"
          + (", periodic" if p.periodic else "") + (f", domain {p.domain}" if p.domain else ""))
    checks = [_empty_disk(rec, p, analysis)]
    if rec.meta.get("complete") is False:
        checks.append(Check("maximality", "not checked", "the run was interrupted: the file "
                            "holds the samples before the interrupt, not a maximal set"))
    else:
        checks.append(_maximal(rec, p, analysis))
    t1 = _table1(rec, p, analysis) if rec.meta.get("complete") is not False else None
    if t1 is not None:
        checks.append(t1)
    for c in checks:
        print(f"  {c.status:>11}  {c.name}: {c.detail}")
    if args.plot:
        from .plots import plot_analysis
        report = None
        if t1 is not None and t1.status != "not checked":
            report = analysis.check_delaunay(rec.points, rec.radii, p.rule, 0.0, p.lo, p.hi)
        lip = p.sizing.lipschitz if p.sizing is not None else 0.0
        try:
            plot_analysis(Path(args.plot), rec.points, rec.radii, p.lo, p.hi, report, p.rule,
                          p.scale * lip, p.scale)
        except OSError as exc:
            raise UsageError(f"--plot {args.plot}: cannot write it: {exc.strerror or exc}") from None
        print(f"wrote {args.plot}")
    return _verdict(checks)


def _verdict(checks: list[Check]) -> int:
    failed = [c.name for c in checks if c.status == "FAILED"]
    unchecked = [c.name for c in checks if c.status == "not checked"]
    if failed:
        print("FAILED: " + "; ".join(failed))
        return EXIT_FAILED
    if unchecked:
        print(f"{len(checks) - len(unchecked)} of {len(checks)} checks passed; not checked: "
              + "; ".join(unchecked))
        return EXIT_UNCHECKED
    print(f"all guarantees hold ({len(checks)} of {len(checks)} checks passed)")
    return 0


def add_analyze_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser],
                       fmt: type[argparse.HelpFormatter]) -> None:
    a = sub.add_parser("analyze", formatter_class=fmt, help="check a sampling's guarantees and "
                       "plot its spectrum (needs scipy)", description=__doc__)
    a.add_argument("file", help=".npz, .npy, .csv, .ply or a .zarr tile store, as `vpds sample` "
                   "writes them")
    a.add_argument("--rule", choices=sorted(RULES), help="the rule (default: the file's, else smaller)")
    a.add_argument("--radius", type=float, help="constant radius (default: the file's)")
    a.add_argument("--sizing", help="r(x) as a numpy expression in x (default: the file's)")
    a.add_argument("--lipschitz", type=float, help="L of r (default: the file's)")
    a.add_argument("--inhibition", type=float, help="R_f factor (default: the file's, else 1)")
    a.add_argument("--coverage", type=float, help="R_c factor (default: the file's, else 1)")
    a.add_argument("--lo", help="lower corner (default: the file's, else 0)")
    a.add_argument("--hi", help="upper corner (default: the file's, else 1)")
    a.add_argument("--scale", type=float, help="the scale t to check at (default: the file's "
                   "smallest finite t, else 1)")
    a.add_argument("--plot", help="write the analysis picture: .png, .pdf, .svg, ... (the "
                   "formats matplotlib writes; needs matplotlib)")
    a.set_defaults(func=cmd_analyze)
