// Peer: the poisson crate's "Ebeida" algorithm (a maximal-by-design sampler after Ebeida et al.
// 2012) on [0, 1]^d at the minimum distance r; the crate's radius is half the minimum distance.
// usage: ebeida DIM MIN_DISTANCE SEED [OUT] -> "n seconds"; OUT: the points as text, one per line
use poisson::{algorithm, Builder, Type};
use rand::rngs::SmallRng;
use rand::SeedableRng;
use std::time::Instant;

// One run at dimension $dim with the crate's vector type $v: the points as rows, and the
// seconds the generator took (the copy into rows is not timed)
macro_rules! run {
    ($v:ty, $dim:expr, $radius:expr, $seed:expr) => {{
        let start = Instant::now();
        let rng = SmallRng::seed_from_u64($seed);
        let points = Builder::<f64, $v>::with_radius($radius, Type::Normal).build(rng, algorithm::Ebeida).generate();
        let seconds = start.elapsed().as_secs_f64();
        (points.iter().map(|p| (0..$dim).map(|k| p[k]).collect::<Vec<f64>>()).collect::<Vec<_>>(), seconds)
    }};
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dim: usize = args[1].parse().unwrap();
    let min_distance: f64 = args[2].parse().unwrap();
    let seed: u64 = args[3].parse().unwrap();
    let (points, seconds) = match dim {
        2 => run!(nalgebra::Vector2<f64>, 2, 0.5 * min_distance, seed),
        3 => run!(nalgebra::Vector3<f64>, 3, 0.5 * min_distance, seed),
        4 => run!(nalgebra::Vector4<f64>, 4, 0.5 * min_distance, seed),
        _ => panic!("dim must be 2, 3 or 4"),
    };
    if let Some(path) = args.get(4) {
        vpds_bench_fast_poisson::write_points(path, &points);
    }
    println!("{} {}", points.len(), seconds);
}
