// Peer: the fast_poisson crate (Bridson's algorithm) on [0, 1]^d with radius r.
// usage: vpds-bench-fast-poisson DIM RADIUS SEED [OUT] -> "n seconds"; OUT: the points as text
use fast_poisson::Poisson;
use std::time::Instant;

// The points as rows, and the seconds the generator took (the copy into rows is not timed)
fn points<const D: usize>(radius: f64, seed: u64) -> (Vec<Vec<f64>>, f64) {
    let start = Instant::now();
    let p = Poisson::<D>::new().with_dimensions([1.0; D], radius).with_seed(seed).generate();
    let seconds = start.elapsed().as_secs_f64();
    (p.iter().map(|x| x.to_vec()).collect(), seconds)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dim: usize = args[1].parse().unwrap();
    let radius: f64 = args[2].parse().unwrap();
    let seed: u64 = args[3].parse().unwrap();
    let (pts, seconds) = match dim {
        2 => points::<2>(radius, seed),
        3 => points::<3>(radius, seed),
        4 => points::<4>(radius, seed),
        6 => points::<6>(radius, seed),
        _ => panic!("dim"),
    };
    if let Some(path) = args.get(4) {
        vpds_bench_fast_poisson::write_points(path, &pts);
    }
    println!("{} {}", pts.len(), seconds);
}
