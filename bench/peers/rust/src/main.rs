// Peer: the fast_poisson crate (Bridson's algorithm) on [0, 1]^d with radius r.
// usage: vpds-bench-fast-poisson DIM RADIUS SEED -> "n seconds"
use fast_poisson::Poisson;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dim: usize = args[1].parse().unwrap();
    let radius: f64 = args[2].parse().unwrap();
    let seed: u64 = args[3].parse().unwrap();
    let start = Instant::now();
    let n = match dim {
        2 => Poisson::<2>::new().with_dimensions([1.0, 1.0], radius).with_seed(seed).generate().len(),
        3 => Poisson::<3>::new().with_dimensions([1.0; 3], radius).with_seed(seed).generate().len(),
        4 => Poisson::<4>::new().with_dimensions([1.0; 4], radius).with_seed(seed).generate().len(),
        6 => Poisson::<6>::new().with_dimensions([1.0; 6], radius).with_seed(seed).generate().len(),
        _ => panic!("dim"),
    };
    println!("{} {}", n, start.elapsed().as_secs_f64());
}
