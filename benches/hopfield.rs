//! Criterion benches of the Hopfield channel: the interest operator, the candidate search
//! (interest points + row ZNCC), the weight construction, the network sweeps and the whole
//! matcher, at three image sizes (synthetic textured pairs with a known 6 px shift, so the
//! benches need no data files). Throughput is pixels per second.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use stereovision_core::matching::hopfield::{
    candidate_neurons, hopfield_match, initial_state, interest_points, run_dynamics,
    HopfieldParams, InterestParams, Network,
};
use stereovision_core::Image;

/// Image sizes (width, height): Middlebury 2003, Middlebury 2006 / ETH3D, KITTI-like.
const SIZES: [(usize, usize); 3] = [(450, 375), (640, 480), (1242, 375)];
/// Disparity shift of the synthetic right image (px) and the searched range.
const SHIFT: usize = 6;
const D_MAX: usize = 64;

/// Smooth random texture (sum of a few hashed gradients), deterministic.
fn texture(w: usize, h: usize) -> Vec<f32> {
    let mut s: u64 = 0x1234_5678;
    let mut noise = vec![0.0f32; (w + 8) * (h + 8)];
    for v in noise.iter_mut() {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *v = ((s >> 40) as f32) / (1u64 << 24) as f32;
    }
    // 3x3 box blur: texture with corners at several scales.
    let mut out = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut acc = 0.0;
            for dy in 0..3 {
                for dx in 0..3 {
                    acc += noise[(y + dy) * (w + 8) + x + dx];
                }
            }
            out[y * w + x] = acc / 9.0;
        }
    }
    out
}

fn pair(w: usize, h: usize) -> (Image, Image) {
    let base = texture(w + SHIFT, h);
    let mut l = vec![0.0f32; w * h];
    let mut r = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            l[y * w + x] = base[y * (w + SHIFT) + x + SHIFT];
        }
    }
    // right(x) = left(x + SHIFT) where defined: x_l - x_r = SHIFT.
    for y in 0..h {
        for x in 0..w {
            let src = (x + SHIFT).min(w - 1);
            r[y * w + x] = l[y * w + src];
        }
    }
    (
        Image::new(w, h, l).expect("valid image"),
        Image::new(w, h, r).expect("valid image"),
    )
}

fn bench(c: &mut Criterion) {
    let p = HopfieldParams {
        d_max: D_MAX,
        ..HopfieldParams::default()
    };
    let mut g = c.benchmark_group("hopfield");
    g.sample_size(10).measurement_time(Duration::from_secs(2));
    for &(w, h) in &SIZES {
        let (l, r) = pair(w, h);
        g.throughput(Throughput::Elements((w * h) as u64));
        let id = format!("{w}x{h}");
        g.bench_with_input(BenchmarkId::new("interest_points", &id), &l, |b, l| {
            b.iter(|| interest_points(l, &InterestParams::default()))
        });
        g.bench_with_input(
            BenchmarkId::new("candidates", &id),
            &(&l, &r),
            |b, (l, r)| b.iter(|| candidate_neurons(*l, *r, &p).expect("valid input")),
        );
        let (_, neurons) = candidate_neurons(&l, &r, &p).expect("valid input");
        let net = Network::new(&neurons, &p.weights).expect("valid input");
        let input: Vec<f64> = neurons
            .iter()
            .map(|n| (p.weights.d * n.sim - p.weights.theta) as f64)
            .collect();
        let init = initial_state(&neurons, &p);
        // The implicit network: its set-up, then the dynamics (the initial net inputs from
        // every row, then the sweeps, each flip re-reading its row).
        g.bench_function(BenchmarkId::new("network", &id), |b| {
            b.iter(|| Network::new(&neurons, &p.weights).expect("valid input"))
        });
        g.bench_function(BenchmarkId::new("network_dynamics", &id), |b| {
            b.iter(|| run_dynamics(&net, &input, &init, 0, p.max_sweeps).expect("valid input"))
        });
        g.bench_function(BenchmarkId::new("hopfield_match", &id), |b| {
            b.iter(|| hopfield_match(&l, &r, &p).expect("valid input"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
