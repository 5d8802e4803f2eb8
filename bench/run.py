"""`make bench`: libvpds beside its peers on the same workloads, as ratios, in one run.

`--quick`: smaller workloads; `--stream`: only the continuous-stream rows.

Peers come from the registries and are installed here, into build/bench: scipy's
qmc.PoissonDisk (PyPI), the npm package poisson-disk-sampling, the Rust crate fast_poisson (all
three Bridson-style, biased samplers) and the Rust crate poisson 0.10.1 in its "Ebeida" mode (after
Ebeida et al. 2012, the maximal sampler's design). Each peer's output is measured for what it is
beside its time: its smallest distance between two points against the minimum distance asked,
and the share of random probes with room for another point (farther than that distance from
every point: 0 for a maximal set). The floor is drawing the same number of uniform random points
with libvpds's own generator. Times are wall-clock seconds of one run on this machine, one core.
Memory beside a peer is each process's peak resident memory per sample (os.wait4's rusage), the
bench program's for libvpds.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "build" / "bench"
QUICK = "--quick" in sys.argv


def sh(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw).stdout


def install_peers() -> dict[str, object]:
    peers: dict[str, object] = {}
    OUT.mkdir(parents=True, exist_ok=True)
    try:
        sh([sys.executable, "-m", "pip", "install", "-q", "--disable-pip-version-check", "scipy"])
        peers["scipy"] = True
    except Exception as e:  # noqa: BLE001
        print("scipy unavailable:", e)
    node_dir = OUT / "node"
    try:
        node_dir.mkdir(exist_ok=True)
        for f in ("package.json", "peer.js"):
            shutil.copy(ROOT / "bench" / "peers" / "node" / f, node_dir / f)
        sh(["npm", "install", "--no-audit", "--no-fund", "--silent"], cwd=node_dir)
        peers["npm"] = node_dir / "peer.js"
    except Exception as e:  # noqa: BLE001
        print("npm peer unavailable:", e)
    cargo = shutil.which("cargo") or str(Path.home() / ".cargo" / "bin" / "cargo")
    try:
        env = dict(os.environ, CARGO_TARGET_DIR=str(OUT / "rust"))
        sh([cargo, "build", "--release", "-q"], cwd=ROOT / "bench" / "peers" / "rust", env=env)
        peers["rust"] = OUT / "rust" / "release" / "vpds-bench-fast-poisson"
        peers["ebeida"] = OUT / "rust" / "release" / "ebeida"
    except Exception as e:  # noqa: BLE001
        print("fast_poisson and poisson (crates) unavailable:", e)
    return peers


def sh_rss(cmd: list[str]) -> tuple[str, int]:
    """sh, and the command's own peak resident memory in bytes (its rusage, from os.wait4)."""
    with open(OUT / "stderr.txt", "w") as err:
        p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=err, text=True)
        assert p.stdout is not None
        out = p.stdout.read()
        _, status, usage = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode:
        raise subprocess.CalledProcessError(p.returncode, cmd, out)
    return out, usage.ru_maxrss * 1024


def vpds(*args) -> tuple[int, float, int]:
    out = sh([str(OUT / "bench"), *map(str, args)]).split()
    return int(out[1]), float(out[2]), int(out[3])


def vpds_rss(*args) -> tuple[int, float, int, int]:
    """vpds, and the bench process's peak resident memory: what a peer's is compared with."""
    text, rss = sh_rss([str(OUT / "bench"), *map(str, args)])
    out = text.split()
    return int(out[1]), float(out[2]), int(out[3]), rss


PROBES = 200_000


def output_quality(points, r: float, dim: int) -> str:
    """What a sampler's output is: its smallest pairwise distance over r (>= 1: no conflict) and
    the share of PROBES uniform probes of the unit box farther than r from every point, where
    another point would fit (0 for a maximal set; a probe's resolution is 1/PROBES)."""
    import numpy as np
    from scipy.spatial import cKDTree
    pts = np.asarray(points, dtype=float).reshape(-1, dim)
    tree = cKDTree(pts)
    nearest, _ = tree.query(pts, k=2)
    probes = np.random.default_rng(12345).random((PROBES, dim))
    gap, _ = tree.query(probes, k=1)
    free = gap >= r
    room = float(np.mean(free))
    upper = float(np.mean(np.any(probes[free] > 1 - r, axis=1))) if free.any() else 0.0
    return (f"   output: {len(pts):,d} points, smallest distance {nearest[:, 1].min() / r:.4f} r, "
            f"room for another point at {100 * room:.3f}% of {PROBES:,d} probes"
            + (" (maximal: none)" if room == 0 else
               f" ({100 * upper:.0f}% of those within r of an upper face)"))


def peer_points(cmd: list[str], dim: int) -> tuple[int, float, object, int]:
    """Runs a peer that writes its points to the file named last: (n, seconds, points, its peak
    resident memory in bytes)."""
    import numpy as np
    path = OUT / "peer_points.txt"
    text, rss = sh_rss([*cmd, str(path)])
    out = text.split()
    pts = np.loadtxt(path, ndmin=2).reshape(-1, dim)
    path.unlink()
    return int(out[0]), float(out[1]), pts, rss


def versus(n: int, sec: float, rss: int, pn: int, ps: float, prss: int) -> str:
    """libvpds against a peer on the same workload: samples per second and peak resident bytes
    per sample (whole processes), as ratios."""
    return (f"libvpds/peer samples-per-second: {(n / sec) / (pn / ps):.2f}; peak RSS per sample "
            f"{rss / n:.0f} B against {prss / pn:.0f} B: {(rss / n) / (prss / pn):.2f}")


def vpds_points(dim: int, r: float):
    """libvpds's own output at the bench's seed, through the Python binding (the same C run)."""
    import vpds as lib
    return lib.PoissonDisk(dim, radius=r, seed=1, progress=False).fill_space()


def radius_for(n: float, dim: int) -> float:
    """Radius of a maximal uniform set of about n points in [0,1]^dim (measured densities)."""
    density = {2: 0.697, 3: 95396 * 0.02 ** 3, 6: 663 * 0.45 ** 6}[dim]
    return (density / n) ** (1.0 / dim)


def main() -> None:
    peers = install_peers()
    rows = []

    def row(name, n, sec, mem=None, note=""):
        rows.append((name, n, sec, mem, note))
        per = f"{n / sec:,.0f}/s" if sec > 0 else "-"
        print(f"{name:44s} n={n:>10,d}  {sec:9.3f} s  {per:>14s}  "
              f"{'' if mem is None else f'{mem / n:6.1f} B/sample'}  {note}", flush=True)

    # 2D uniform, about a million samples (fewer with --quick)
    n_target = 1e5 if QUICK else 1e6
    r = radius_for(n_target, 2)
    n, sec, mem, rss = vpds_rss("uniform", 2, r)
    row(f"libvpds 2D uniform r={r:.6f} (maximal)", n, sec, mem, note=f"peak RSS {rss / n:.0f} B/sample")
    base_rate = n / sec
    fn, fsec, _ = vpds("floor", n, 2)
    row("floor: same count of uniform points", fn, fsec, note=f"libvpds is {sec / fsec:.0f}x the floor")
    print(output_quality(vpds_points(2, r), r, 2), flush=True)
    if "npm" in peers:
        pn, ps, pts, prss = peer_points(["node", str(peers["npm"]), repr(r), "1"], 2)
        row("npm poisson-disk-sampling (not maximal)", pn, ps, note=versus(n, sec, rss, pn, ps, prss))
        print(output_quality(pts, r, 2), flush=True)
    if "rust" in peers:
        pn, ps, pts, prss = peer_points([str(peers["rust"]), "2", repr(r), "1"], 2)
        row("crate fast_poisson (not maximal)", pn, ps, note=versus(n, sec, rss, pn, ps, prss))
        print(output_quality(pts, r, 2), flush=True)
    if "ebeida" in peers:  # its radius is half the minimum distance: the binary passes r / 2
        pn, ps, pts, prss = peer_points([str(peers["ebeida"]), "2", repr(r), "1"], 2)
        row("crate poisson 0.10.1, Ebeida mode", pn, ps, note=versus(n, sec, rss, pn, ps, prss))
        print(output_quality(pts, r, 2), flush=True)
    if "scipy" in peers:
        # scipy is too slow for a million: compare on a smaller workload, both sides
        rs = radius_for(2e4, 2)
        from scipy.stats import qmc
        t0 = time.perf_counter()
        pts = qmc.PoissonDisk(2, radius=rs, rng=1).fill_space()
        ss = time.perf_counter() - t0
        vn, vs, _ = vpds("uniform", 2, rs)
        row(f"libvpds 2D uniform r={rs:.5f}", vn, vs)
        row("scipy qmc.PoissonDisk.fill_space (not maximal)", len(pts), ss,
            note=f"libvpds/peer samples-per-second: {(vn / vs) / (len(pts) / ss):.1f}")
        print(output_quality(pts, rs, 2), flush=True)

    # variable radii: the paper's ramp, each rule, beside the uniform time per sample
    for rule in ("prior", "current", "bigger", "smaller"):
        n, sec, mem = vpds("ramp", rule)
        row(f"libvpds ramp 0.001+0.3x on 1x400, {rule}", n, sec, mem,
            note=f"time/sample = {(sec / n) * base_rate:.2f}x uniform")

    # growth of time per sample with n
    sizes = [1e4, 1e5, 1e6] if QUICK else [1e4, 1e5, 1e6, 1e7]
    per = []
    for target in sizes:
        n, sec, mem = vpds("uniform", 2, radius_for(target, 2))
        per.append(sec / n)
        row(f"libvpds 2D uniform, n ~ {target:.0e}", n, sec, mem,
            note=f"time/sample = {per[-1] / per[0]:.2f}x that at 1e4")

    # 3D and 6D uniform
    n, sec, mem = vpds("uniform", 3, radius_for(1e5 if QUICK else 1e6, 3))
    row("libvpds 3D uniform", n, sec, mem)
    if "rust" in peers and not QUICK:
        text, prss = sh_rss([str(peers["rust"]), "3", repr(radius_for(1e5, 3)), "1"])
        out = text.split()
        vn, vs, _, vrss = vpds_rss("uniform", 3, radius_for(1e5, 3))
        row("libvpds 3D uniform (1e5)", vn, vs)
        row("crate fast_poisson 3D (1e5)", int(out[0]), float(out[1]),
            note=versus(vn, vs, vrss, int(out[0]), float(out[1]), prss))
    if "ebeida" in peers:  # about 1,000 samples/s in 3D: 1e4 samples (3e3 with --quick)
        r3 = radius_for(3e3 if QUICK else 1e4, 3)
        vn, vs, _, vrss = vpds_rss("uniform", 3, r3)
        row(f"libvpds 3D uniform r={r3:.4f}", vn, vs)
        print(output_quality(vpds_points(3, r3), r3, 3), flush=True)
        pn, ps, pts, prss = peer_points([str(peers["ebeida"]), "3", repr(r3), "1"], 3)
        row("crate poisson 0.10.1 3D, Ebeida mode", pn, ps, note=versus(vn, vs, vrss, pn, ps, prss))
        print(output_quality(pts, r3, 3), flush=True)
    # 4D (the high-dimension issue's yardstick: r = 0.06, about 7.5e4 samples; 0.1 with --quick)
    r4 = 0.1 if QUICK else 0.06
    n, sec, mem = vpds("uniform", 4, r4)
    row(f"libvpds 4D uniform r={r4} (maximal)", n, sec, mem)
    if "rust" in peers:
        out = sh([str(peers["rust"]), "4", repr(r4), "1"]).split()
        row(f"crate fast_poisson 4D r={r4} (not maximal)", int(out[0]), float(out[1]),
            note=f"libvpds/peer samples-per-second: {(n / sec) / (int(out[0]) / float(out[1])):.2f}")
    n, sec, mem = vpds("uniform", 6, radius_for(3e3 if QUICK else 1e4, 6))
    row("libvpds 6D uniform (maximal)", n, sec, mem)
    # 5D, 7D and 8D (issue 16: 5D at 8,000 samples/s; 10^4 samples in 5 minutes in 7D and 8D,
    # out of reach today: these radii give a few hundred to 9,000 samples in seconds)
    for dim, rd in ((5, 0.25 if QUICK else 0.18), (7, 0.6), (8, 0.8)):
        n, sec, mem = vpds("uniform", dim, rd)
        row(f"libvpds {dim}D uniform r={rd} (maximal)", n, sec, mem)

    # two radii (Section 3): the exact dart test beside one radius at the same inhibition
    n1, s1, _ = vpds("uniform", 2, 0.005)
    n, sec, mem = vpds("tworadii", 2, 0.01, 0.5)
    row("libvpds 2D two radii R_f=0.5 R_c, r=0.01", n, sec, mem,
        note=f"time/sample = {(sec / n) / (s1 / n1):.1f}x one radius r=0.005")
    # two radii with a variable radius in 3D (a fuzz input's workload): the coverage search of
    # version 6 (what it learns, and the sub-boxes each cell keeps) beside version 3's (the same
    # points) and beside one radius on that box (issue 14's target: 3x per sample)
    n, sec, mem = vpds("tworamp3", 6)
    n3, s3, _ = vpds("tworamp3", 3)
    n1, s1, _ = vpds("tworamp3", 6, 1)
    row("libvpds 3D two radii, ramp, periodic (version 6)", n, sec, mem,
        note=f"time = {sec / s3:.2f}x version 3's ({n3} samples, {s3:.2f} s); "
             f"time/sample = {(sec / n) / (s1 / n1):.1f}x one radius ({n1} samples)")
    # a domain: the annulus 0.2 <= |x - c| <= 0.45 by its signed distance, beside the full box
    r_a = 0.001 if QUICK else 0.0005
    n, sec, mem = vpds("annulus", r_a)
    nb, sb, _ = vpds("uniform", 2, r_a)
    row(f"libvpds 2D annulus (domain callback), r={r_a}", n, sec, mem,
        note=f"time/sample = {(sec / n) / (sb / nb):.2f}x the full box ({nb / sb:,.0f}/s)")
    thread_rows(row)
    stream_rows()


def thread_rows(row) -> None:
    """vpds_tiling_run on 1 and 2 threads beside one vpds_run of the same box and radius: the
    speed-up of threads (the tiling's seams cost the one-thread overhead)."""
    cases = [(2, radius_for(1e5 if QUICK else 1e6, 2), 16), (3, radius_for(1e4 if QUICK else 1e5, 3), 4)]
    for dim, r, per_axis in cases:
        n, sec, _ = vpds("uniform", dim, r)
        for threads in (1, 2):
            tn, ts, _ = vpds("threads", dim, r, per_axis, threads)
            row(f"libvpds {dim}D uniform, {per_axis}^{dim} tiles, {threads} thread(s)", tn, ts,
                note=f"speed-up over one vpds_run ({n:,d} samples in {sec:.2f} s): {sec / ts:.2f}x")
    if not QUICK:  # Figure 1's ramp on the 1 x 400 box, 1 x 20 tiles (tiles="auto"'s sides)
        n, sec, _ = vpds("ramp", "smaller")
        for threads in (1, 2):
            tn, ts, _ = vpds("rampthreads", "smaller", 1, 20, threads)
            row(f"libvpds ramp 1x400 (smaller), 1x20 tiles, {threads} thread(s)", tn, ts,
                note=f"speed-up over one vpds_run ({n:,d} samples in {sec:.2f} s): {sec / ts:.2f}x")


def fps_peer(dim: int, n: int) -> str:
    """The PyPI package fpsample (QuickFPS: bucket farthest-point sampling over a kd-tree, Rust)
    picking n points from a cloud of 10 n uniform candidates: what users reach for instead of a
    continuous farthest-point stream (its farthest points are the cloud's, not the box's)."""
    try:
        sh([sys.executable, "-m", "pip", "install", "-q", "--disable-pip-version-check",
            "--only-binary=:all:", "fpsample>=0.3"])
        import fpsample  # type: ignore[import-not-found]
        import numpy as np
    except Exception as e:  # noqa: BLE001
        return f"fpsample unavailable: {e}"
    cloud = np.random.default_rng(1).random((10 * n, dim))
    start = time.perf_counter()
    fpsample.bucket_fps_kdline_sampling(cloud, n, h=7, start_idx=0)
    sec = time.perf_counter() - start
    return f"fpsample bucket FPS ({n:,d} of {10 * n:,d} candidates): {sec:.2f} s, {n / sec:,.0f} samples/s"


def python_progressive(dim: int, n: int, c_seconds: float) -> str:
    """Python's progressive(n) on the stream's workload (radius 1, equal radii): the events
    come from C in batches (vpds_next_n), so its time per sample is the C stream's."""
    import vpds as lib
    start = time.perf_counter()
    res = lib.PoissonDisk(dim, radius=1.0, rng=1, progress=False).progressive(n, inhibition=None)
    sec = time.perf_counter() - start
    return (f"Python progressive({n:,d}): {sec:.2f} s, {len(res.points) / sec:,.0f} samples/s, "
            f"{sec / c_seconds:.2f}x the C stream's time")


def stream_rows() -> None:
    """The continuous stream (vpds_next) from empty: samples/s and the per-sample cost along n,
    beside a maximal run of about as many samples and beside a farthest-point sampler of a
    candidate cloud from PyPI (no registry package streams a continuous farthest-point order)."""
    for dim, n_total in ((2, 1e4 if QUICK else 1e6), (3, 3e3 if QUICK else 1e5)):
        steps = 10
        lines = sh([str(OUT / "bench"), "stream", str(dim), "1", f"{n_total:g}", str(steps)])
        pts = [ln.split() for ln in lines.splitlines()]
        n, total, mem = int(pts[-1][1]), float(pts[-1][2]), int(pts[-1][3])
        t_last = float(pts[-1][5])
        costs = [float(p[4]) / (n / steps) * 1e6 for p in pts]
        rn, rsec, _ = vpds("uniform", dim, t_last)
        print(f"libvpds {dim}D stream from empty, {n:,d} calls of vpds_next: {total:.2f} s, "
              f"{n / total:,.0f} samples/s, {mem / n:.0f} B/sample at the end; "
              f"a maximal run at its last scale: {rn:,d} samples at {rn / rsec:,.0f}/s "
              f"(stream/run time per sample {(total / n) / (rsec / rn):.1f}x)", flush=True)
        print("   us/sample per tenth of the stream: " + " ".join(f"{c:.0f}" for c in costs),
              flush=True)
        print("   beside " + fps_peer(dim, n), flush=True)
        print("   " + python_progressive(dim, n, total), flush=True)
        print("   " + two_radii_stream(dim, n, total), flush=True)
    ramp_streams(2e3 if QUICK else 2e4)


def stream_seconds(args: list[str]) -> float:
    """The total time of a `bench stream`-style command (its last line's third field)."""
    return float(sh([str(OUT / "bench"), *args]).splitlines()[-1].split()[2])


def two_radii_stream(dim: int, n: int, one_radius_seconds: float) -> str:
    """The stream with R_f = 0.5 R_c (what progressive(n) uses) against R_f = R_c, per sample
    (target 1.5x in 2D)."""
    sec = stream_seconds(["stream", str(dim), "1", str(n), "1", "0", "0.5"])
    return (f"two radii R_f = 0.5 R_c: {sec:.2f} s, {sec / one_radius_seconds:.2f}x the time per "
            f"sample of R_f = R_c")


def ramp_streams(n: float) -> None:
    """The stream with the ramp r = 0.001 + 0.3 x on the unit square under each rule against a
    constant radius r = 0.001, the same number of calls (target 2x per sample)."""
    uniform = stream_seconds(["stream", "2", "0.001", f"{n:g}", "1"])
    for rule in ("smaller", "prior", "bigger", "current"):
        sec = stream_seconds(["streamramp", rule, f"{n:g}", "1"])
        print(f"libvpds 2D stream, ramp r = 0.001 + 0.3 x ({rule}), {n:,.0f} calls: {sec:.2f} s, "
              f"{sec / uniform:.1f}x the time per sample of r = 0.001 ({uniform:.3f} s)", flush=True)


if __name__ == "__main__":
    if "--stream" in sys.argv:  # only the stream rows (no peers needed)
        stream_rows()
    else:
        main()
