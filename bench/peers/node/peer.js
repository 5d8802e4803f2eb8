// Peer: the npm package poisson-disk-sampling (Bridson) on [0, 1]^2 with minDistance r.
// usage: node peer.js RADIUS SEED -> "n seconds"
const PoissonDiskSampling = require('poisson-disk-sampling');
const r = parseFloat(process.argv[2]);
let s = parseInt(process.argv[3]) >>> 0;
const rng = () => { s = (s * 1664525 + 1013904223) >>> 0; return s / 4294967296; };
const t0 = process.hrtime.bigint();
const p = new PoissonDiskSampling({ shape: [1, 1], minDistance: r, maxDistance: 2 * r, tries: 30 }, rng);
const n = p.fill().length;
console.log(n, Number(process.hrtime.bigint() - t0) / 1e9);
