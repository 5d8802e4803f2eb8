// What the two peer binaries share: writing their points for the bench's checks of what each
// output is (bench/run.py reads them back).
use std::io::Write;

/// The points as text, one per line, coordinates separated by spaces.
pub fn write_points(path: &str, points: &[Vec<f64>]) {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for p in points {
        let line: Vec<String> = p.iter().map(|c| format!("{:e}", c)).collect();
        writeln!(out, "{}", line.join(" ")).unwrap();
    }
}
