//! Criterion benches of the MCGM channel: the separable LoG, zero crossings, curve tracking,
//! the R-tables of one image's curves and the GHT candidate votes against the other image's,
//! one image's curves over all channels, the whole matcher and B.8's occlusion filters, at
//! three image sizes (synthetic
//! smooth-texture pairs with a known 6 px shift, so the benches need no data files).
//! Throughput is pixels per second.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use stereovision_core::matching::mcgm::{
    channel_curves, edge_filters, graph::candidates, image_curves, log::log_filter, mcgm_match,
    rtable::build_rtable, tracking::track, zerocross::zero_crossings, McgmParams,
};
use stereovision_core::Image;

/// Image sizes (width, height): Middlebury 2003, Middlebury 2006 / ETH3D, KITTI-like.
const SIZES: [(usize, usize); 3] = [(450, 375), (640, 480), (1242, 375)];
/// Disparity shift of the synthetic right image (px) and the searched range.
const SHIFT: usize = 6;
const D_MAX: usize = 64;

/// Smooth random texture (3x3 box blur of hashed noise, twice), deterministic.
fn texture(w: usize, h: usize) -> Vec<f32> {
    let mut s: u64 = 0x1234_5678;
    let (pw, ph) = (w + 8, h + 8);
    let mut noise = vec![0.0f32; pw * ph];
    for v in noise.iter_mut() {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *v = ((s >> 40) as f32) / (1u64 << 24) as f32;
    }
    let blur = |src: &[f32], sw: usize, sh: usize| -> Vec<f32> {
        let mut out = vec![0.0f32; (sw - 2) * (sh - 2)];
        for y in 0..sh - 2 {
            for x in 0..sw - 2 {
                let mut acc = 0.0;
                for dy in 0..3 {
                    for dx in 0..3 {
                        acc += src[(y + dy) * sw + x + dx];
                    }
                }
                out[y * (sw - 2) + x] = acc / 9.0;
            }
        }
        out
    };
    let once = blur(&noise, pw, ph);
    let twice = blur(&once, pw - 2, ph - 2);
    let tw = pw - 4;
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (y, x)))
        .map(|(y, x)| twice[y * tw + x])
        .collect()
}

fn pair(w: usize, h: usize) -> (Image, Image) {
    let base = texture(w + SHIFT, h);
    let l: Vec<f32> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (y, x)))
        .map(|(y, x)| base[y * (w + SHIFT) + x + SHIFT])
        .collect();
    // right(x) = left(x + SHIFT) where defined: x_l - x_r = SHIFT.
    let r: Vec<f32> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (y, x)))
        .map(|(y, x)| l[y * w + (x + SHIFT).min(w - 1)])
        .collect();
    (
        Image::new(w, h, l).expect("valid image"),
        Image::new(w, h, r).expect("valid image"),
    )
}

fn bench(c: &mut Criterion) {
    let p = McgmParams {
        d_max: D_MAX,
        ..McgmParams::default()
    };
    let mut g = c.benchmark_group("mcgm");
    g.sample_size(10).measurement_time(Duration::from_secs(2));
    for &(w, h) in &SIZES {
        let (l, r) = pair(w, h);
        g.throughput(Throughput::Elements((w * h) as u64));
        let id = format!("{w}x{h}");
        for sigma in [1.0f32, 2.0] {
            g.bench_with_input(
                BenchmarkId::new(format!("log_sigma{sigma}"), &id),
                &l,
                |b, l| b.iter(|| log_filter(l, sigma)),
            );
        }
        let lg = log_filter(&l, 1.0).expect("memory");
        g.bench_function(BenchmarkId::new("zero_crossings", &id), |b| {
            b.iter(|| zero_crossings(&lg, w, h))
        });
        let zc = zero_crossings(&lg, w, h).expect("memory");
        g.bench_function(BenchmarkId::new("track", &id), |b| {
            b.iter(|| track(&zc, &p.track))
        });
        // R-tables (B.4 step 6) of the finest channel's segments, then the GHT votes of every
        // left segment against the right segments in its rows over the whole range (step 8).
        let cl = channel_curves(&l, p.sigmas[p.sigmas.len() - 1], 1, &p).expect("memory");
        let cr = channel_curves(&r, p.sigmas[p.sigmas.len() - 1], 1, &p).expect("memory");
        g.bench_function(BenchmarkId::new("rtables", &id), |b| {
            b.iter(|| {
                cl.curves
                    .segments
                    .iter()
                    .map(|s| build_rtable(s, &cl.zc.theta, w, p.cand.n_bins))
                    .collect::<Vec<_>>()
            })
        });
        let window = vec![Some((0, D_MAX as i32)); cl.curves.segments.len()];
        g.bench_function(BenchmarkId::new("ght_candidates", &id), |b| {
            b.iter(|| {
                candidates(
                    &cl.curves.segments,
                    &cl.rtables,
                    &cr.curves.segments,
                    &cr.zc.theta,
                    w,
                    h,
                    &window,
                    &p.cand,
                )
                .expect("valid input")
            })
        });
        g.bench_function(BenchmarkId::new("image_curves", &id), |b| {
            b.iter(|| image_curves(&l, &p).expect("valid input"))
        });
        g.bench_function(BenchmarkId::new("mcgm_match", &id), |b| {
            b.iter(|| mcgm_match(&l, &r, &p).expect("valid input"))
        });
        // B.8's occlusion filters (both-sides check with its other-disparity scan, the
        // discontinuity filter) on the finest channel's matches.
        let out = mcgm_match(&l, &r, &p).expect("valid input");
        let fine: Vec<_> = out
            .channels
            .iter()
            .filter(|c| c.scale == 1)
            .flat_map(|c| c.matches.iter().copied())
            .collect();
        g.bench_function(BenchmarkId::new("edge_filters", &id), |b| {
            b.iter(|| edge_filters(&l, &r, &fine, &p.filters, (0, D_MAX as i32)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
