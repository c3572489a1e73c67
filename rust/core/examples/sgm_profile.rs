//! Timing and an output fingerprint of the census semi-global matcher on a real pair, for
//! profiling (`docs/architecture.md` names the kernels). The pair comes as raw little-endian
//! float32 grey images written by `benches/dump_grey.py`:
//!
//! ```text
//! python benches/dump_grey.py middlebury2006/cloth3 /tmp/cloth3     # prints W H D
//! cargo run --release --example sgm_profile -- /tmp/cloth3 626 555 96            # min of 15
//! cargo run --release --example sgm_profile -- /tmp/cloth3 626 555 96 whole=60   # for perf
//! cargo run --release --example sgm_profile -- /tmp/cloth3 626 555 96 paths=3    # one pass
//! ```
//!
//! Prints the minimum wall time of the runs (ms; the least disturbed by other load on a shared
//! machine) with the current rayon thread count (`RAYON_NUM_THREADS`), the number of pixels
//! with a value and a hash of every output bit (to check that a change leaves the output
//! bit-identical).

mod common;

use std::hash::{Hash, Hasher};
use std::time::Instant;

use stereovision_core::matching::sgm::{sgm_disparity, SgmParams};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (l, r, d) = common::load_pair(
        &args,
        "sgm_profile PREFIX W H MAX_DISPARITY [whole=N] [paths=8|3]",
    );
    let opt = |key: &str| {
        args.iter()
            .skip(5)
            .find_map(|a| a.strip_prefix(key).map(|v| v.parse::<usize>().expect(key)))
    };
    let runs = opt("whole=").unwrap_or(15);
    let p = SgmParams {
        paths: opt("paths=").map_or(8, |v| v as u8),
        ..SgmParams::default()
    };
    let mut best = f64::INFINITY;
    let mut out = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        out = sgm_disparity(l.view(), r.view(), 0, d as i32, &p).expect("valid input");
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
    }
    let mut hash = std::collections::hash_map::DefaultHasher::new();
    out.iter().for_each(|v| v.to_bits().hash(&mut hash));
    let valid = out.iter().filter(|v| v.is_finite()).count();
    println!(
        "sgm {:.2} ms (min of {runs}, {} threads), {valid} pixels with a value, hash {:016x}",
        best,
        rayon::current_num_threads(),
        hash.finish()
    );
}
