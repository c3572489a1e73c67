//! Criterion bench of the census semi-global matcher (census, cost volume, 8-path aggregation,
//! selection; and the one-pass 3-path variant, `paths_3/...`) at two image sizes and two
//! disparity ranges, on a textured synthetic pair with a
//! slanted disparity. Throughput is cost-volume cells (pixels x levels) per second.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use stereovision_core::matching::sgm::{sgm_disparity, SgmParams};
use stereovision_core::ImageView;

fn pair(w: usize, h: usize) -> (Vec<f32>, Vec<f32>) {
    let tex = |x: f32, y: f32| {
        0.5 + 0.2 * (0.7 * x).sin() * (0.3 * y).cos() + 0.15 * (0.23 * x + 0.41 * y).sin()
    };
    let mut l = vec![0f32; w * h];
    let mut r = vec![0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let dd = 8.3 + 20.0 * y as f32 / h as f32;
            l[y * w + x] = tex(x as f32, y as f32);
            r[y * w + x] = tex(x as f32 + dd, y as f32);
        }
    }
    (l, r)
}

fn bench_sgm(c: &mut Criterion) {
    let mut g = c.benchmark_group("sgm_disparity");
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    for paths in [8u8, 3] {
        let p = SgmParams {
            paths,
            ..SgmParams::default()
        };
        let prefix = if paths == 8 { "" } else { "paths_3/" };
        for ((w, h), d) in [((320, 240), 64), ((640, 480), 64), ((640, 480), 128)] {
            let (l, r) = pair(w, h);
            let lv = ImageView::new(w, h, &l).unwrap();
            let rv = ImageView::new(w, h, &r).unwrap();
            g.throughput(Throughput::Elements((w * h * d) as u64));
            g.bench_with_input(
                BenchmarkId::from_parameter(format!("{prefix}{w}x{h}xD{d}")),
                &(),
                |b, _| b.iter(|| sgm_disparity(lv, rv, 0, d as i32 - 1, &p).unwrap()),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, bench_sgm);
criterion_main!(benches);
