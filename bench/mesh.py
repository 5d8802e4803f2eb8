"""`make bench`, surfaces: libvpds beside the mesh samplers users reach for, on the same mesh and
radius, one core, and what each output is.

Peers from PyPI, installed here into the project's environment when missing: Open3D
(`TriangleMesh.sample_points_poisson_disk`, sample elimination from 5x candidates: it takes a
count, given libvpds's), point-cloud-utils (`sample_mesh_poisson_disk`, by radius) and libigl
(`igl.blue_noise`, by radius). For every output: samples/s, the pairs closer than the radius
(conflicts), and the fraction of dense probes (area-uniform on the surface) farther than the
radius from every sample (left uncovered: room for another point). A maximal conflict-free
sampling has 0 and 0. Then exactly n points, the count the peers take (`exactly_n`). Also the
time per sample of a 2D box run of similar count (`bench uniform 2 R`) beside the flat square as
a mesh (`bench mesh square R`).

usage: python bench/mesh.py [--quick]
"""
from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
QUICK = "--quick" in sys.argv
PEERS = {"open3d": "open3d", "point_cloud_utils": "point-cloud-utils", "igl": "libigl"}


# shared libraries a peer's wheel expects from the system (Debian package names)
SYSTEM_LIBS = {"open3d": ["libusb-1.0-0", "libgomp1"]}


def ensure(module: str) -> Optional[Any]:
    try:
        return __import__(module)
    except ImportError:
        pass
    try:
        subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--disable-pip-version-check",
                        PEERS[module]], check=True, capture_output=True, text=True)
        try:
            return __import__(module)
        except ImportError:
            if module not in SYSTEM_LIBS:
                raise
            sudo = [] if subprocess.run(["id", "-u"], capture_output=True, text=True).stdout.strip() == "0" else ["sudo"]
            subprocess.run(sudo + ["apt-get", "install", "-y", "-q", *SYSTEM_LIBS[module]], check=True,
                           capture_output=True, text=True)
            return __import__(module)
    except Exception as exc:  # noqa: BLE001 - a peer that cannot install is reported, not fatal
        print(f"{PEERS[module]} unavailable: {str(exc).splitlines()[0] if str(exc) else exc}")
        return None


def surface_probes(v: np.ndarray, f: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    k = rng.choice(len(f), size=n, p=area / area.sum())
    s, t = rng.random(n), rng.random(n)
    flip = s + t > 1
    s[flip], t[flip] = 1 - s[flip], 1 - t[flip]
    return a[k] + s[:, None] * (b[k] - a[k]) + t[:, None] * (c[k] - a[k])


def judge(points: np.ndarray, probes: np.ndarray, radius: float) -> tuple[int, float, float]:
    """Pairs closer than the radius, uncovered probe fraction, min distance / radius."""
    from scipy.spatial import cKDTree
    tree = cKDTree(points)
    close = len(tree.query_pairs(radius * (1 - 1e-9)))
    d, _ = tree.query(probes)
    dmin, _ = tree.query(points, k=2)
    return close, float(np.mean(d > radius)), float(dmin[:, 1].min() / radius)


def timed(fn: Callable[[], np.ndarray]) -> tuple[np.ndarray, float]:
    t0 = time.perf_counter()
    out = fn()
    return np.asarray(out, dtype=np.float64), time.perf_counter() - t0


def bench_tool(*args: Any) -> tuple[int, float]:
    out = subprocess.run([str(ROOT / "build" / "bench" / "bench"), *map(str, args)], check=True,
                         capture_output=True, text=True).stdout.split()
    return int(out[1]), float(out[2])


def exactly_n(v: np.ndarray, f: np.ndarray, probes: np.ndarray, pcu: Any, o3d: Any, n: int) -> None:
    """Exactly n points on the mesh, the count peers take: libvpds's stream (`sample_mesh(n=)`)
    beside Open3D and point-cloud-utils asked for n. For each: the smallest distance between two
    points and the largest distance from a probe to its nearest point (the gap a further point
    could fill); their ratio is at most 1 for the stream (each prefix is covered at its scale and
    conflict-free at it), and the larger the smallest distance the more evenly n points spread."""
    import vpds
    from scipy.spatial import cKDTree
    print(f"exactly {n:,d} points (the stream; peers asked for the count):")

    def row(name: str, pts: np.ndarray, sec: float) -> None:
        tree = cKDTree(pts)
        dmin = float(tree.query(pts, k=2)[0][:, 1].min())
        gap = float(tree.query(probes)[0].max())
        print(f"  {name:34s} n={len(pts):>7,d} {sec:8.3f} s {len(pts) / sec:>10,.0f}/s  smallest distance "
              f"{dmin:.5f}  largest gap {gap:.5f}  gap/distance {gap / dmin:5.3f}", flush=True)

    pts, sec = timed(lambda: vpds.sample_mesh(v, f, radius=1.0, n=n, rng=1).points)
    row("libvpds sample_mesh(n=)", pts, sec)
    if pcu is not None:
        def run_pcu() -> np.ndarray:
            fi, bc = pcu.sample_mesh_poisson_disk(v, f.astype(np.int32), num_samples=n)
            return pcu.interpolate_barycentric_coords(f.astype(np.int32), fi, bc, v)
        pts, sec = timed(run_pcu)
        row("point-cloud-utils (num_samples)", pts, sec)
    if o3d is not None:
        m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f.astype(np.int32)))
        if hasattr(o3d.utility, "random"):
            o3d.utility.random.seed(1)
        pts, sec = timed(lambda: np.asarray(m.sample_points_poisson_disk(number_of_points=n).points))
        row("Open3D sample_points_poisson_disk", pts, sec)


def main() -> None:
    import trimesh
    import vpds
    sub, radius = (4, 0.03) if QUICK else (5, 0.01)
    mesh = trimesh.creation.icosphere(subdivisions=sub)
    v, f = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
    probes = surface_probes(v, f, 50_000 if QUICK else 400_000, np.random.default_rng(1))
    print(f"mesh: unit icosphere, {len(f)} triangles; radius {radius} (minimum distance)")
    rows = []

    def row(name: str, pts: np.ndarray, sec: float, note: str = "") -> None:
        close, uncovered, dmin = judge(pts, probes, radius)
        rows.append((name, len(pts), sec))
        print(f"{name:34s} n={len(pts):>8,d} {sec:8.3f} s {len(pts) / sec:>11,.0f}/s  "
              f"pairs < r: {close:>6d}  uncovered: {100 * uncovered:6.2f}%  min dist/r: {dmin:5.3f}  {note}",
              flush=True)

    pts, sec = timed(lambda: vpds.sample_mesh(v, f, radius=radius, rng=1).points)
    row("libvpds sample_mesh", pts, sec, "maximal")
    n_vpds, t_vpds = len(pts), sec
    pcu = ensure("point_cloud_utils")
    if pcu is not None:
        def run_pcu() -> np.ndarray:
            fi, bc = pcu.sample_mesh_poisson_disk(v, f.astype(np.int32), num_samples=-1, radius=radius)
            return pcu.interpolate_barycentric_coords(f.astype(np.int32), fi, bc, v)
        pts, sec = timed(run_pcu)
        row("point-cloud-utils (by radius)", pts, sec)
    igl = ensure("igl")
    if igl is not None:
        pts, sec = timed(lambda: igl.blue_noise(v, f, radius)[2])
        row("libigl blue_noise (by radius)", pts, sec)
    o3d = ensure("open3d")
    if o3d is not None:
        m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f.astype(np.int32)))
        if hasattr(o3d.utility, "random"):
            o3d.utility.random.seed(1)  # its seed is global: the call takes none
        pts, sec = timed(lambda: np.asarray(m.sample_points_poisson_disk(number_of_points=n_vpds).points))
        row("Open3D sample_points_poisson_disk", pts, sec, f"(asked for libvpds's {n_vpds} points)")
    peers = [(name, n, s) for name, n, s in rows[1:]]
    if peers:
        name, n, s = max(peers, key=lambda p: p[1] / p[2])
        print(f"libvpds / fastest peer ({name}) samples per second: {(n_vpds / t_vpds) / (n / s):.2f}")
    exactly_n(v, f, probes, pcu, o3d, 5_000 if QUICK else 20_000)
    r_sq = 0.004 if QUICK else 0.002
    n_m, t_m = bench_tool("mesh", "square", r_sq)
    n_b, t_b = bench_tool("uniform", 2, r_sq)
    print(f"flat unit square as 2 triangles, r = {r_sq}: {n_m} samples in {t_m:.3f} s; the 2D box: {n_b} in "
          f"{t_b:.3f} s; time per sample mesh/box: {(t_m / n_m) / (t_b / n_b):.2f}")


if __name__ == "__main__":
    main()
