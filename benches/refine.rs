//! Criterion bench of the refinement stage (sub-pixel re-measurement and two fill passes) at
//! three image sizes, on a textured synthetic pair with a slanted disparity and a start map that
//! is rounded to whole pixels and has every 5th row-run of 40 pixels missing. Throughput is
//! pixels per second.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use stereovision_core::refine::{refine_disparity, RefineParams};
use stereovision_core::ImageView;

const SIZES: [(usize, usize); 3] = [(320, 240), (640, 480), (1280, 720)];

fn pair(w: usize, h: usize) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let tex = |x: f32, y: f32| {
        0.5 + 0.2 * (0.7 * x).sin() * (0.3 * y).cos() + 0.15 * (0.23 * x + 0.41 * y).sin()
    };
    let mut l = vec![0f32; w * h];
    let mut r = vec![0f32; w * h];
    let mut d = vec![0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let dd = 8.3 + 20.0 * y as f32 / h as f32;
            let i = y * w + x;
            l[i] = tex(x as f32, y as f32);
            r[i] = tex(x as f32 + dd, y as f32);
            d[i] = if (i / 40).is_multiple_of(5) {
                f32::NAN
            } else {
                dd.round()
            };
        }
    }
    (l, r, d)
}

fn bench_refine(c: &mut Criterion) {
    let mut g = c.benchmark_group("refine_disparity");
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    let p = RefineParams::default();
    for (w, h) in SIZES {
        let (l, r, d) = pair(w, h);
        let conf = vec![0.5f32; w * h];
        let lv = ImageView::new(w, h, &l).unwrap();
        let rv = ImageView::new(w, h, &r).unwrap();
        g.throughput(Throughput::Elements((w * h) as u64));
        g.bench_with_input(
            BenchmarkId::from_parameter(format!("{w}x{h}")),
            &(),
            |b, _| b.iter(|| refine_disparity(lv, rv, &d, &conf, 0.0, 64.0, &p).unwrap()),
        );
    }
    g.finish();
}

criterion_group!(benches, bench_refine);
criterion_main!(benches);
