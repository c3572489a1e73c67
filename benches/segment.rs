//! Criterion bench of the fused map's plane fill and edge step: equal-colour segments (`k = 0`,
//! and the quantised regions the fill uses), Felzenszwalb segments (`k = 300`), the per-segment
//! plane fits, the whole fill (`fill_planes`: two passes of two cuts each), the fattened-edge
//! marks (`edges::fattened`), the colour side and row rules (`fill`) and the Gabor matcher's
//! speckle filter (`remove_speckles`), at 640x480 on a synthetic image of quantised blocks and a
//! slanted map with a hole every 5th pixel (and a raised square for the edges, raised single
//! pixels for the speckles).
//! Throughput is pixels per second.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use stereovision_core::edges::{fattened, FattenParams};
use stereovision_core::fill::{row_fill, side_fill};
use stereovision_core::matching::gabor::post::remove_speckles;
use stereovision_core::segment::{fill_planes, graph_segments, plane_fill, quantised_regions};

fn bench_segment(c: &mut Criterion) {
    let (w, h) = (640usize, 480usize);
    // Blocks of 8x6 pixels with 3 channels of pseudo-random bins: many small segments, like the
    // quantised image of a textured scene.
    let img: Vec<f32> = (0..w * h * 3)
        .map(|i| {
            let p = i / 3;
            let block = (p % w) / 8 + 97 * ((p / w) / 6);
            ((block * 2_654_435_761usize + i % 3 * 40_503) >> 7) as f32 % 4.0
        })
        .collect();
    let disp: Vec<f32> = (0..w * h)
        .map(|p| {
            if p % 5 == 0 {
                f32::NAN
            } else {
                10.0 + 0.05 * (p % w) as f32 + 0.02 * (p / w) as f32
            }
        })
        .collect();
    let mut g = c.benchmark_group("segment_640x480");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements((w * h) as u64));
    g.bench_function("equal_regions", |b| {
        b.iter(|| graph_segments(&img, w, h, 3, 0.0, 1).unwrap())
    });
    let img_u8: Vec<u8> = img.iter().map(|&v| (v * 16.0) as u8).collect();
    g.bench_function("quantised_regions", |b| {
        b.iter(|| quantised_regions(&img_u8, w, h, 3, 16, 0).unwrap())
    });
    g.bench_function("felzenszwalb_k300", |b| {
        b.iter(|| graph_segments(&img, w, h, 3, 300.0, 20).unwrap())
    });
    let labels = graph_segments(&img, w, h, 3, 0.0, 1).unwrap();
    g.bench_function("plane_fill", |b| {
        b.iter(|| {
            let mut d = disp.clone();
            plane_fill(&mut d, &labels, w, 50, 1.0, 0.0, 100.0).unwrap()
        })
    });
    g.bench_function("fill_planes", |b| {
        b.iter(|| {
            let mut d = disp.clone();
            fill_planes(&mut d, &img_u8, w, 3, &[(16, 50), (24, 200)], 0.7).unwrap();
            d
        })
    });
    // A square raised by 8 px whose left and top edges are carried 3 px past the image's.
    let grey: Vec<f32> = (0..w * h)
        .map(|p| {
            let (x, y) = (p % w, p / w);
            if (200..400).contains(&x) && (150..300).contains(&y) {
                0.8
            } else {
                0.2 + 0.001 * (x % 7) as f32
            }
        })
        .collect();
    let raised: Vec<f32> = disp
        .iter()
        .enumerate()
        .map(|(p, &v)| {
            let (x, y) = (p % w, p / w);
            if (197..400).contains(&x) && (147..300).contains(&y) {
                v + 8.0
            } else {
                v
            }
        })
        .collect();
    let fp = FattenParams {
        radius: 3,
        ratio: 2.0,
        jump: 2.0,
    };
    g.bench_function("fattened", |b| {
        b.iter(|| fattened(&raised, &grey, w, h, &fp).unwrap())
    });
    // The fill's last two steps on the raised map: the colour side rule (its holes next to the
    // square's left edge have a nearer left side half the time) and the reference row rule.
    let lab: Vec<f32> = grey
        .iter()
        .flat_map(|&v| [v * 255.0, 128.0, 128.0])
        .collect();
    g.bench_function("side_fill", |b| {
        b.iter(|| {
            let mut d = raised.clone();
            side_fill(&mut d, &lab, w, 5.0);
            d
        })
    });
    g.bench_function("row_fill", |b| {
        b.iter(|| {
            let mut d = raised.clone();
            row_fill(&mut d, w);
            d
        })
    });
    // About one pixel in 8 raised off its neighbours: a label of its own each (the per-band
    // label tables grow to ~1/8 of the band), removed at the default size and range.
    let speckled: Vec<f32> = disp
        .iter()
        .enumerate()
        .map(|(p, &v)| {
            if (p.wrapping_mul(2_654_435_761) >> 13) % 8 == 0 {
                v + 20.0
            } else {
                v
            }
        })
        .collect();
    g.bench_function("remove_speckles", |b| {
        b.iter(|| {
            let mut d = speckled.clone();
            remove_speckles(&mut d, w, h, 100, 1.0).unwrap();
            d
        })
    });
    g.finish();
}

criterion_group!(benches, bench_segment);
criterion_main!(benches);
