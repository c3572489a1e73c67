//! Criterion benches of the Gabor channel: the filter bank and the full disparity kernel at three
//! image sizes, on a synthetic band-limited texture shifted by a known disparity. Throughput is
//! reported in pixels per second (`Throughput::Elements(width * height)`). Sample counts are kept
//! small so `cargo bench` finishes in a few minutes on 2 cores.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use stereovision_core::matching::gabor::{filter, gabor_disparity, GaborParams};
use stereovision_core::Image;

const SIZES: [(usize, usize); 3] = [(320, 240), (640, 480), (1280, 720)];
/// Disparity of the synthetic pair and the searched range (px).
const SHIFT: f32 = 7.3;
const D_MAX: f32 = 64.0;

/// Sum of random oblique sinusoids sampled at `x + shift` (an exact sub-pixel shift).
fn texture(w: usize, h: usize, shift: f32) -> Image {
    let mut s = 0x2545_f491_4f6c_dd1d_u64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let comps: Vec<[f32; 4]> = (0..24)
        .map(|_| {
            let f = 0.02 + 0.25 * rnd();
            let th = std::f32::consts::PI * (rnd() - 0.5);
            [
                f * th.cos(),
                f * th.sin(),
                std::f32::consts::TAU * rnd(),
                0.5 + rnd(),
            ]
        })
        .collect();
    let norm: f32 = comps.iter().map(|c| c[3]).sum();
    let data = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 + shift, (i / w) as f32);
            let v: f32 = comps
                .iter()
                .map(|c| c[3] * (std::f32::consts::TAU * (c[0] * x + c[1] * y) + c[2]).cos())
                .sum();
            (0.5 + 1.2 * v / norm).clamp(0.0, 1.0)
        })
        .collect();
    Image {
        width: w,
        height: h,
        data,
    }
}

fn bench_filter_bank(c: &mut Criterion) {
    let p = GaborParams::default();
    let chans = match p.channels() {
        Ok(ch) => ch,
        Err(e) => panic!("default channels are valid: {e}"),
    };
    let mut g = c.benchmark_group("gabor_filter_bank");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    for (w, h) in SIZES {
        let img = texture(w, h, 0.0);
        g.throughput(Throughput::Elements((w * h) as u64));
        g.bench_with_input(
            BenchmarkId::from_parameter(format!("{w}x{h}")),
            &img,
            |b, img| b.iter(|| filter::filter_bank(&img.data, img.width, img.height, &chans)),
        );
    }
    g.finish();
}

fn bench_disparity(c: &mut Criterion) {
    let p = GaborParams {
        d_max: D_MAX,
        ..GaborParams::default()
    };
    let mut g = c.benchmark_group("gabor_disparity_lr");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    for (w, h) in SIZES {
        let left = texture(w, h, 0.0);
        let right = texture(w, h, SHIFT);
        g.throughput(Throughput::Elements((w * h) as u64));
        g.bench_with_input(
            BenchmarkId::from_parameter(format!("{w}x{h}")),
            &(left, right),
            |b, (l, r)| b.iter(|| gabor_disparity(l, r, &p)),
        );
    }
    g.finish();
}

criterion_group!(benches, bench_filter_bank, bench_disparity);
criterion_main!(benches);
