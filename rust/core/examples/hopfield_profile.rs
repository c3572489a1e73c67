//! Stage timings and an output fingerprint of the Hopfield channel on a real pair, for
//! profiling (`docs/hopfield.md`, "Reproduce"). The pair comes as raw little-endian float32
//! grey images written by `benches/dump_grey.py`:
//!
//! ```text
//! python benches/dump_grey.py middlebury2006/cloth3 /tmp/cloth3     # prints W H D
//! cargo run --release --example hopfield_profile -- /tmp/cloth3 626 555 96
//! cargo run --release --example hopfield_profile -- /tmp/cloth3 626 555 96 fingerprint
//! cargo run --release --example hopfield_profile -- /tmp/cloth3 626 555 96 whole=60
//! ```
//!
//! Timing mode prints the minimum of 9 runs of each public stage (ms; the least disturbed by
//! other load on a shared machine) with the current rayon
//! thread count (`RAYON_NUM_THREADS`); `fingerprint` prints the match count, the number of
//! weights, the sweeps, a hash of every match and one of the energy trace (to check that a change
//! leaves the output bit-identical); `whole=N` runs the matcher N times and nothing else (for
//! `perf record`).

mod common;

use std::hash::{Hash, Hasher};
use std::time::Instant;

use stereovision_core::matching::hopfield::{
    candidate_neurons, hopfield_match, initial_state, interest_points, run_dynamics,
    HopfieldParams, Network, Weights,
};

fn min_ms(v: Vec<f64>) -> f64 {
    v.into_iter().fold(f64::INFINITY, f64::min)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (l, r, d) = common::load_pair(
        &args,
        "hopfield_profile PREFIX W H MAX_DISPARITY [fingerprint | whole=N]",
    );
    let p = HopfieldParams {
        d_max: d,
        ..HopfieldParams::default()
    };
    let ms = |s: Instant| s.elapsed().as_secs_f64() * 1e3;
    if args.get(5).map(String::as_str) == Some("fingerprint") {
        let out = hopfield_match(&l, &r, &p).expect("valid input");
        let mut hash = std::collections::hash_map::DefaultHasher::new();
        for m in &out.matches {
            [m.xl, m.yl, m.xr, m.yr, m.score]
                .map(f32::to_bits)
                .hash(&mut hash);
        }
        let mut e_hash = std::collections::hash_map::DefaultHasher::new();
        out.energy_trace
            .iter()
            .for_each(|e| e.to_bits().hash(&mut e_hash));
        println!(
            "matches {} weights {} sweeps {} match hash {:016x} energy hash {:016x}",
            out.matches.len(),
            out.n_weights,
            out.sweeps,
            hash.finish(),
            e_hash.finish()
        );
        return;
    }
    if let Some(n) = args.get(5).and_then(|a| a.strip_prefix("whole=")) {
        let n: usize = n.parse().expect("a run count");
        for _ in 0..n {
            hopfield_match(&l, &r, &p).expect("valid input");
        }
        return;
    }
    let mut t = [(); 6].map(|_| Vec::new());
    for _ in 0..9 {
        let s = Instant::now();
        interest_points(&l, &p.interest).expect("memory");
        t[0].push(ms(s));
        let s = Instant::now();
        let (_, neurons) = candidate_neurons(&l, &r, &p).expect("valid input");
        t[1].push(ms(s));
        let s = Instant::now();
        let net = Network::new(&neurons, &p.weights).expect("valid input");
        t[2].push(ms(s));
        let input: Vec<f64> = neurons
            .iter()
            .map(|n| (p.weights.d * n.sim - p.weights.theta) as f64)
            .collect();
        let init = initial_state(&neurons, &p);
        let s = Instant::now();
        net.initial_input(&init, &input).expect("valid input");
        t[5].push(ms(s));
        let s = Instant::now();
        run_dynamics(&net, &input, &init, p.seed, p.max_sweeps).expect("valid input");
        t[3].push(ms(s));
        let s = Instant::now();
        hopfield_match(&l, &r, &p).expect("valid input");
        t[4].push(ms(s));
    }
    let [a, b, c, e, f, g] = t.map(min_ms);
    println!(
        "interest {a:.2}  candidates (incl. interest) {b:.2}  network {c:.2}  dynamics {e:.2} (initial input {g:.2})  \
         whole matcher {f:.2}  (ms, min of 9)"
    );
}
