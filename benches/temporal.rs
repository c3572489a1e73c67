//! Criterion bench of the temporal filter's per-pixel passes (`stereovision_core::temporal`):
//! the grey difference of a BGR frame and its running mean, and the mean's update, at 640x480
//! and 1280x720 on a synthetic noisy frame. Throughput is pixels per second.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use stereovision_core::temporal::{grey_difference, running_mean};

const SIZES: [(usize, usize); 2] = [(640, 480), (1280, 720)];

fn bench_temporal(c: &mut Criterion) {
    let mut g = c.benchmark_group("temporal");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    for (w, h) in SIZES {
        let n = w * h;
        // A gradient with a deterministic "noise" of +-7 levels; the mean is the gradient.
        let mean: Vec<f32> = (0..n * 3)
            .map(|i| ((i / 3) % w) as f32 * 0.3 + 20.0)
            .collect();
        let frame: Vec<u8> = mean
            .iter()
            .enumerate()
            .map(|(i, &m)| (m + ((i * 7919) % 15) as f32 - 7.0) as u8)
            .collect();
        let count: Vec<u8> = (0..n).map(|i| (i % 8 + 1) as u8).collect();
        let diff = grey_difference(&frame, &mean, n, 3).unwrap();
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(
            BenchmarkId::new("grey_difference", format!("{w}x{h}")),
            &n,
            |b, &n| b.iter(|| grey_difference(&frame, &mean, n, 3).unwrap()),
        );
        g.bench_with_input(
            BenchmarkId::new("running_mean", format!("{w}x{h}")),
            &n,
            |b, _| {
                // In place: each iteration starts from a fresh copy of the state (not timed).
                b.iter_batched(
                    || (mean.clone(), count.clone()),
                    |(mut m, mut k)| {
                        running_mean(&frame, &mut m, &mut k, &diff, 3, 15.0, 8).unwrap()
                    },
                    criterion::BatchSize::LargeInput,
                )
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench_temporal);
criterion_main!(benches);
