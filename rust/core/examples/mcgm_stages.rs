//! Single-image stage timings of the MCGM channel on a real pair (raw float32 grey images from
//! `benches/dump_grey.py`), one thread or more as `RAYON_NUM_THREADS` says:
//! `cargo run --release --example mcgm_stages -- PREFIX W H D [curves | filters | graph | count]`.
//!
//! - `curves` (default): LoG, zero crossings, tracking and R-tables of the left image per
//!   channel (minimum of 9 runs);
//! - `filters`: B.8's occlusion filters on the full-resolution channels' matches of the pair,
//!   whole and split into the discontinuity filter and the both-sides check's own fit;
//! - `graph`: the k-NN segment graph of the finest channel's left segments;
//! - `count`: marked crossings, tracking candidates and the pixels kept in segments.

mod common;

use std::time::Instant;

use stereovision_core::image::Image;
use stereovision_core::matching::mcgm::{
    channel_curves, edge_filters, graph::knn_graph, log, mcgm_match, rtable, tracking, zerocross,
    FilterParams, McgmParams,
};

/// Minimum wall time of `runs` calls (ms).
fn best_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    (0..runs)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

fn curves(l: &Image, p: &McgmParams) {
    let half = log::decimate2(l).expect("memory");
    for (sig, img) in [(1.0f32, l), (2.0, l), (2.0, &half)] {
        let (w, h) = img.size();
        let lg = log::log_filter(img, sig).expect("memory");
        let zc = zerocross::zero_crossings(&lg, w, h).expect("memory");
        let tp = p.track_params(sig);
        let c = tracking::track(&zc, &tp).expect("memory");
        let t_log = best_ms(9, || drop(log::log_filter(img, sig)));
        let t_zc = best_ms(9, || drop(zerocross::zero_crossings(&lg, w, h)));
        let t_track = best_ms(9, || drop(tracking::track(&zc, &tp)));
        let t_rt = best_ms(9, || {
            for s in &c.segments {
                drop(rtable::build_rtable(s, &zc.theta, w, p.cand.n_bins));
            }
        });
        println!(
            "sigma {sig} {w}x{h}: log {t_log:.2} zc {t_zc:.2} track {t_track:.2} rtab {t_rt:.2} ms"
        );
    }
}

fn filters(l: &Image, r: &Image, p: &McgmParams, d: usize) {
    let out = mcgm_match(l, r, p).expect("valid input");
    let all: Vec<_> = out
        .channels
        .iter()
        .filter(|c| c.scale == 1)
        .flat_map(|c| c.matches.iter().copied())
        .collect();
    let range = (0, d as i32);
    let (keep, _) = edge_filters(l, r, &all, &p.filters, range).expect("valid input");
    let kept = keep.iter().filter(|&&k| k).count();
    let t = best_ms(15, || drop(edge_filters(l, r, &all, &p.filters, range)));
    println!("filters on {} matches: {t:.2} ms, kept {kept}", all.len());
    for (name, f) in [
        (
            "discontinuity filter only",
            FilterParams {
                sides: false,
                ..p.filters
            },
        ),
        (
            "both-sides own fit only",
            FilterParams {
                sides_best: false,
                disc: false,
                ..p.filters
            },
        ),
    ] {
        let t = best_ms(15, || drop(edge_filters(l, r, &all, &f, range)));
        println!("  {name}: {t:.2} ms");
    }
}

fn graph(l: &Image, p: &McgmParams) {
    let cc = channel_curves(l, 1.0, 1, p).expect("memory");
    let segs = &cc.curves.segments;
    let edges: usize = knn_graph(segs, p.knn, p.r_graph)
        .expect("memory")
        .iter()
        .map(Vec::len)
        .sum();
    let t = best_ms(9, || drop(knn_graph(segs, p.knn, p.r_graph)));
    println!(
        "k-NN graph of {} segments: {t:.2} ms ({edges} directed edges)",
        segs.len()
    );
}

fn count(l: &Image, p: &McgmParams) {
    let (w, h) = l.size();
    for sig in [1.0f32, 2.0] {
        let zc = zerocross::zero_crossings(&log::log_filter(l, sig).expect("memory"), w, h)
            .expect("memory");
        let t_low = p.track.low_ratio
            * tracking::high_threshold(&zc, p.track.high_quantile).expect("memory");
        let marked = zc.mark.iter().filter(|&&m| m != 0).count();
        let free = zc
            .strength
            .iter()
            .zip(&zc.mark)
            .filter(|&(&s, &m)| m != 0 && s >= t_low)
            .count();
        let tp = p.track_params(sig);
        let c = tracking::track(&zc, &tp).expect("memory");
        let kept: usize = c.segments.iter().map(|s| s.pixels.len()).sum();
        println!(
            "sigma {sig}: marked {marked}, candidates {free}, in {} segments {kept}",
            c.segments.len()
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (l, r, d) = common::load_pair(
        &args,
        "mcgm_stages PREFIX W H MAX_DISPARITY [curves | filters | graph | count]",
    );
    let p = McgmParams {
        d_max: d,
        ..McgmParams::default()
    };
    match args.get(5).map(String::as_str).unwrap_or("curves") {
        "curves" => curves(&l, &p),
        "filters" => filters(&l, &r, &p, d),
        "graph" => graph(&l, &p),
        "count" => count(&l, &p),
        other => eprintln!("unknown mode {other:?}: curves, filters, graph or count"),
    }
}
