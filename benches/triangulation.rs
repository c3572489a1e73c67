//! Criterion bench of the rectified depth kernel (depth and its sigma from a disparity map) at
//! three image sizes, on a synthetic map with holes. Throughput is pixels per second.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use stereovision_core::triangulation::{depth_rectified, SigmaModel};

const SIZES: [(usize, usize); 3] = [(640, 480), (1280, 720), (1920, 1080)];

fn bench_depth(c: &mut Criterion) {
    let model = SigmaModel {
        s0: 0.74,
        slope: -0.52,
        s_min: 0.2,
        s_fill: 0.67,
    };
    let mut g = c.benchmark_group("depth_rectified");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    for (w, h) in SIZES {
        // A slanted plane of disparities 5..45 px with every 7th pixel a hole (NaN).
        let disp: Vec<f32> = (0..w * h)
            .map(|i| {
                if i % 7 == 0 {
                    f32::NAN
                } else {
                    5.0 + 40.0 * (i % w) as f32 / w as f32
                }
            })
            .collect();
        let conf: Vec<f32> = (0..w * h).map(|i| (i % 11) as f32 / 10.0).collect();
        g.throughput(Throughput::Elements((w * h) as u64));
        g.bench_with_input(
            BenchmarkId::from_parameter(format!("{w}x{h}")),
            &(w, h),
            |b, &(w, h)| b.iter(|| depth_rectified(&disp, &conf, w, h, 50.0, 2.0, model).unwrap()),
        );
    }
    g.finish();
}

criterion_group!(benches, bench_depth);
criterion_main!(benches);
