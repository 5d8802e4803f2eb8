// Peer: the npm package poisson-disk-sampling (Bridson) on [0, 1]^2 with minDistance r.
// usage: node peer.js RADIUS SEED [OUT] -> "n seconds"; OUT: the points as text, one per line
const PoissonDiskSampling = require('poisson-disk-sampling');
const r = parseFloat(process.argv[2]);
let s = parseInt(process.argv[3]) >>> 0;
const rng = () => { s = (s * 1664525 + 1013904223) >>> 0; return s / 4294967296; };
const t0 = process.hrtime.bigint();
const p = new PoissonDiskSampling({ shape: [1, 1], minDistance: r, maxDistance: 2 * r, tries: 30 }, rng);
const points = p.fill();
const seconds = Number(process.hrtime.bigint() - t0) / 1e9;
if (process.argv[4]) require('fs').writeFileSync(process.argv[4], points.map((q) => q.join(' ')).join('\n') + '\n');
console.log(points.length, seconds);
