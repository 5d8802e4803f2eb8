#!/usr/bin/env bash
# make demo: the paper's Figure 1 with each rule (C example: CSVs; the vpds command: PNGs), and
# Figure 10's radial sizing on a quarter of its square (PNG and .npz), from a fresh clone.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
# the project's environment, where make demo installed the package with its demo extras
PY=${2:-$BUILD/venv/bin/python}
mkdir -p out
start=$(date +%s)
echo "== the C example: $BUILD/demo/figure1 (r = 0.001 + 0.3x, each rule)"
"$BUILD/demo/figure1" out
echo "== the vpds command"
for rule in prior current bigger smaller; do
  "$PY" -m vpds sample --sizing "0.001 + 0.3*x[0]" --lipschitz 0.3 --rule "$rule" --seed 2024 \
    -o "out/figure1_$rule.npz" --plot "out/figure1_$rule.png" --no-progress
  # the guarantees, checked independently of the C code against the rule and sizing the file
  # records (exit status 1 if one fails, 3 if one could not be checked)
  "$PY" -m vpds analyze "out/figure1_$rule.npz" | tail -1
done
"$PY" -m vpds sample --lo 0.5 --hi 1 --rule bigger --seed 1 --lipschitz 0.3733 --no-progress \
  --sizing "0.015 + (0.00015 - 0.015)*abs(sin(8*pi*sqrt((x[0]-0.5)**2 + (x[1]-0.5)**2)))" \
  -o out/figure10_quarter.npz --plot out/figure10_quarter.png
echo "== an image-driven sizing: out/sizing.exr (written here with the OpenEXR package)"
"$PY" - <<'PY'
import numpy as np, OpenEXR
h, w = 128, 128
y, x = np.mgrid[0:h, 0:w] / 127.0
# dark (small radii) on a ring and in two dots, bright elsewhere
img = np.clip(np.abs(np.hypot(x - 0.5, y - 0.5) - 0.32) / 0.2, 0, 1)
for cx in (0.38, 0.62):
    img = np.minimum(img, np.clip(np.hypot(x - cx, y - 0.4) / 0.12, 0, 1))
OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
             {"Y": OpenEXR.Channel(img.astype(np.float32))}).write("out/sizing.exr")
PY
"$PY" -m vpds sample --sizing-exr out/sizing.exr --exr-range 0.003,0.03 --lipschitz 0.3 \
  --seed 1 -o out/image.npz --plot out/image.png --no-progress
echo "== a shaped domain: a star with a round hole painted in out/shape.png, maximal up to its edge"
"$PY" - <<'PY'
import math
from PIL import Image, ImageDraw
im = Image.new("L", (512, 512), 0)
draw = ImageDraw.Draw(im)
star = [(256 + (230 if k % 2 == 0 else 100) * math.sin(k * math.pi / 5),
         256 - (230 if k % 2 == 0 else 100) * math.cos(k * math.pi / 5)) for k in range(10)]
draw.polygon(star, fill=255)
draw.ellipse((206, 206, 306, 306), fill=0)
im.save("out/shape.png")
PY
"$PY" -m vpds sample --domain out/shape.png --sizing "0.004 + 0.012*x[1]" --lipschitz 0.012 \
  --seed 3 -o out/domain.npz --plot out/domain.png --no-progress
echo "== a surface: a torus mesh with radii per vertex, maximal on every triangle -> out/mesh.png"
"$PY" - <<'PY'
import numpy as np, vpds
from scipy.spatial import cKDTree
from vpds.plots import plot_mesh
# the torus (R = 1, r = 0.35) as 96 x 32 quads split in two; r = 0.012 on the inner side, 0.04 outside
nu, nv = 96, 32
u, w = np.meshgrid(2 * np.pi * np.arange(nu) / nu, 2 * np.pi * np.arange(nv) / nv, indexing="ij")
v = np.stack([(1 + 0.35 * np.cos(w)) * np.cos(u), (1 + 0.35 * np.cos(w)) * np.sin(u), 0.35 * np.sin(w)], -1).reshape(-1, 3)
idx = np.arange(nu * nv).reshape(nu, nv)
a, b = idx, np.roll(idx, -1, 0)
c, d = np.roll(idx, -1, 1), np.roll(np.roll(idx, -1, 0), -1, 1)
f = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
radii = 0.026 + 0.014 * np.cos(w).reshape(-1)
s = vpds.sample_mesh(v, f, vertex_radii=radii, rng=5)
# independent checks: on the surface, and no two samples closer than the smaller of their radii
assert np.allclose(np.einsum("nk,nkd->nd", s.barycentrics, v[f[s.faces]]), s.points, atol=1e-12)
pairs = cKDTree(s.points).query_pairs(radii.max(), output_type="ndarray")
gap = np.linalg.norm(s.points[pairs[:, 0]] - s.points[pairs[:, 1]], axis=1)
assert (gap >= np.minimum(s.radii[pairs[:, 0]], s.radii[pairs[:, 1]]) * (1 - 1e-12)).all()
np.savez("out/mesh.npz", vertices=v, faces=f, points=s.points, face=s.faces, barycentrics=s.barycentrics, radii=s.radii)
plot_mesh("out/mesh.png", v, f, s.points, f"{len(s.points)} samples on a torus of {len(f)} triangles, "
          f"r from vertex radii {radii.min():.3f}-{radii.max():.3f}, maximal: {s.maximal}", radii=s.radii)
print(f"mesh: {len(s.points)} samples, maximal {s.maximal}, conflict-free (checked)")
PY
echo "demo: wrote out/figure1_<rule>.csv and .png, out/figure10_quarter.npz and .png, out/image.npz and .png, out/domain.npz and .png, out/mesh.npz and .png in $(( $(date +%s) - start )) s"
