//! Stage timings of the MCGM channel on a real pair (raw float32 grey images from
//! `benches/dump_grey.py`): `cargo run --release --example mcgm_profile -- PREFIX W H D [fingerprint | whole=N]`
//! (`fingerprint`: match count and a hash of every match, to check that a change leaves the
//! output bit-identical).

mod common;

use std::time::Instant;

use stereovision_core::matching::mcgm::{image_curves, mcgm_match, McgmParams};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (l, r, d) = common::load_pair(
        &args,
        "mcgm_profile PREFIX W H MAX_DISPARITY [fingerprint | whole=N]",
    );
    let p = McgmParams {
        d_max: d,
        ..McgmParams::default()
    };
    if let Some(n) = args.get(5).and_then(|a| a.strip_prefix("whole=")) {
        for _ in 0..n.parse::<usize>().expect("a run count") {
            mcgm_match(&l, &r, &p).expect("valid input");
        }
        return;
    }
    if args.get(5).map(String::as_str) == Some("fingerprint") {
        use std::hash::{Hash, Hasher};
        let out = mcgm_match(&l, &r, &p).expect("valid input");
        let mut hash = std::collections::hash_map::DefaultHasher::new();
        for m in &out.matches {
            [m.xl, m.yl, m.xr, m.yr, m.score]
                .map(f32::to_bits)
                .hash(&mut hash);
            m.channel.hash(&mut hash);
        }
        let per: Vec<usize> = out.channels.iter().map(|c| c.matches.len()).collect();
        println!(
            "matches {} per channel {per:?} combined {} after sides {} hash {:016x}",
            out.matches.len(),
            out.n_combined,
            out.n_sides,
            hash.finish()
        );
        return;
    }
    let ms = |s: Instant| s.elapsed().as_secs_f64() * 1e3;
    let (mut curves, mut whole) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..7 {
        let s = Instant::now();
        image_curves(&l, &p).expect("valid");
        curves = curves.min(ms(s));
        let s = Instant::now();
        mcgm_match(&l, &r, &p).expect("valid input");
        whole = whole.min(ms(s));
    }
    println!("one image's curves {curves:.2}  whole matcher {whole:.2}  (ms, min of 7)");
}
