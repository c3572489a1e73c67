//! Timing and an output fingerprint of the plane fill (`segment::fill_planes`, `depth_map`'s
//! fill before the row rule) on a real map, for profiling. The inputs are raw files:
//! `PREFIX_disp.f32` (little-endian float32 `(H, W)` disparity, NaN = hole) and `PREFIX_img.u8`
//! (the blurred `(H, W, 3)` left image as `matching.planes` passes it):
//!
//! ```text
//! cargo run --release --example fill_profile -- /tmp/teddyH 900 750            # min of 15
//! cargo run --release --example fill_profile -- /tmp/teddyH 900 750 whole=60   # for perf
//! ```
//!
//! Prints the minimum wall time (ms) with the current rayon thread count, the number of pixels
//! with a value after the fill and a hash of every output bit.

use std::hash::{Hash, Hasher};
use std::time::Instant;

use stereovision_core::segment::fill_planes;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: fill_profile PREFIX W H [whole=N]");
        std::process::exit(2);
    }
    let (w, h): (usize, usize) = (args[2].parse().expect("W"), args[3].parse().expect("H"));
    let read = |suffix: &str| {
        let path = format!("{}_{suffix}", args[1]);
        std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
    };
    let disp: Vec<f32> = read("disp.f32")
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let img = read("img.u8");
    assert_eq!((disp.len(), img.len()), (w * h, w * h * 3), "sizes");
    let runs = args
        .get(4)
        .and_then(|a| a.strip_prefix("whole="))
        .map_or(15, |n| n.parse().expect("whole=N"));
    let mut best = f64::INFINITY;
    let mut out = Vec::new();
    for _ in 0..runs {
        let mut d = disp.clone();
        let t = Instant::now();
        fill_planes(&mut d, &img, w, 3, &[(16, 50), (24, 200)], 0.7).unwrap();
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        out = d;
    }
    let mut hash = std::collections::hash_map::DefaultHasher::new();
    out.iter().for_each(|v| v.to_bits().hash(&mut hash));
    let valid = out.iter().filter(|v| v.is_finite()).count();
    println!(
        "fill_planes {best:.2} ms (min of {runs}, {} threads), {valid} pixels with a value, hash {:016x}",
        rayon::current_num_threads(),
        hash.finish()
    );
}
