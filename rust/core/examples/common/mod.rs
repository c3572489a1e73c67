//! The pair loader shared by the profiling examples.

use stereovision_core::image::Image;

/// The pair `PREFIX_l.f32`, `PREFIX_r.f32` (raw little-endian float32 grey images written by
/// `benches/dump_grey.py`) and `MAX_DISPARITY`, from `args` = `[_, PREFIX, W, H, MAX_DISPARITY,
/// ..]`; prints `usage` and exits with 2 when they are missing.
pub fn load_pair(args: &[String], usage: &str) -> (Image, Image, usize) {
    if args.len() < 5 {
        eprintln!("usage: {usage}");
        std::process::exit(2);
    }
    let num = |i: usize| -> usize { args[i].parse().expect("a number") };
    let (w, h) = (num(2), num(3));
    let load = |side: &str| {
        let path = format!("{}_{side}.f32", args[1]);
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let v: Vec<f32> = bytes
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        Image::new(w, h, v).expect("a w x h float32 image")
    };
    (load("l"), load("r"), num(4))
}
