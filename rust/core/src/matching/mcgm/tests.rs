//! Unit tests of the MCGM channel: kernel properties, one-pixel-thick crossings, tracking of a
//! synthetic contour, GHT of a translated contour, and the sign and magnitude of a known
//! sub-pixel shift end to end.

use super::log::{log_filter, log_kernels};
use super::rtable::{build_rtable, ght_vote, ght_vote_rows, voters, RTable, RowIndex};
use super::tracking::{track, Segment};
use super::zerocross::{zero_crossings, ZC_H};
use super::*;

/// Smooth blob texture evaluated at `x + shift`: `right = blobs(shift)` gives `x_l - x_r = shift`.
fn blobs(w: usize, h: usize, shift: f32) -> Image {
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 40) as f32) / (1u64 << 24) as f32
    };
    let n = (w * h) / 150;
    let blobs: Vec<(f32, f32, f32, f32)> = (0..n)
        .map(|_| {
            (
                next() * (w as f32 + 40.0) - 20.0,
                next() * h as f32,
                2.0 + 4.0 * next(),
                next() - 0.5,
            )
        })
        .collect();
    let mut data = vec![0.5f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let xs = x as f32 + shift;
            let mut v = 0.5;
            for &(cx, cy, r, a) in &blobs {
                let d2 = (xs - cx).powi(2) + (y as f32 - cy).powi(2);
                if d2 < 16.0 * r * r {
                    v += 0.5 * a * (-d2 / (2.0 * r * r)).exp();
                }
            }
            data[y * w + x] = v.clamp(0.0, 1.0);
        }
    }
    Image::new(w, h, data).expect("valid image")
}

#[test]
fn log_kernel_sums_to_zero_and_flat_images_give_nothing() {
    for sigma in [1.0f32, 2.0, 4.0] {
        let (g, a) = log_kernels(sigma).unwrap();
        let (sg, sa): (f64, f64) = (
            g.iter().map(|&v| v as f64).sum(),
            a.iter().map(|&v| v as f64).sum(),
        );
        assert!(
            (2.0 * sa * sg).abs() < 1e-6,
            "sigma {sigma}: sum K = {}",
            2.0 * sa * sg
        );
        assert_eq!(g.len(), 2 * (4.0 * sigma).ceil() as usize + 1);
    }
    let flat = Image::filled(40, 30, 0.8).unwrap();
    let l = log_filter(&flat, 2.0).unwrap();
    assert!(l.iter().all(|v| v.abs() < 1e-5));
    let out = mcgm_match(&flat, &flat, &McgmParams::default()).expect("valid input");
    assert!(out.matches.is_empty());
}

#[test]
fn step_edge_gives_one_pixel_thick_crossing_at_the_edge() {
    // Vertical step between columns 19 and 20: the crossing lies at x = 19.5.
    let (w, h) = (40, 20);
    let data: Vec<f32> = (0..w * h)
        .map(|i| if i % w >= 20 { 0.8 } else { 0.2 })
        .collect();
    let img = Image::new(w, h, data).expect("valid image");
    let l = log_filter(&img, 1.0).unwrap();
    let zc = zero_crossings(&l, w, h).unwrap();
    let smax = zc.strength.iter().copied().fold(0.0f32, f32::max);
    for y in 2..h - 2 {
        // The truncated kernel's far tails add crossings of negligible strength.
        let xs: Vec<usize> = (0..w)
            .filter(|&x| zc.mark[y * w + x] & ZC_H != 0 && zc.strength[y * w + x] > 0.1 * smax)
            .collect();
        assert_eq!(xs.len(), 1, "row {y}: {xs:?}");
        let i = y * w + xs[0];
        assert!((zc.xsub[i] - 19.5).abs() < 1e-3, "xsub {}", zc.xsub[i]);
        // Dark to light along +x: the LoG goes from + to - so its gradient points to -x.
        assert!((zc.theta[i] - std::f32::consts::PI).abs() < 1e-3);
    }
    let curves = track(
        &zc,
        &tracking::TrackParams {
            min_len: 8,
            ..McgmParams::default().track
        },
    )
    .unwrap();
    // Interior rows only are marked; one straight segment covers them all.
    let long: Vec<_> = curves
        .segments
        .iter()
        .filter(|s| s.x_min == s.x_max)
        .collect();
    assert!(long
        .iter()
        .any(|s| s.pixels.len() == h - 2 && (19..=20).contains(&s.x_min)));
}

#[test]
fn ght_of_a_translated_contour_scores_one_at_the_translation() {
    let (w, h) = (120, 80);
    let l = blobs(w, h, 0.0);
    let p = McgmParams::default();
    let cl = channel_curves(&l, 2.0, 1, &p).unwrap();
    // The right contour is the left one moved by (-7, 0): its pixels q = p - (7, 0).
    let seg = cl
        .curves
        .segments
        .iter()
        .find(|s| s.pixels.len() >= 20 && s.x_min > 10)
        .expect("a long segment");
    let rt = build_rtable(seg, &cl.zc.theta, w, p.cand.n_bins).unwrap();
    let moved: Vec<u32> = seg.pixels.iter().map(|&i| i - 7).collect();
    let mut theta = cl.zc.theta.clone();
    for (&i, &j) in seg.pixels.iter().zip(&moved) {
        theta[j as usize] = cl.zc.theta[i as usize];
    }
    let mut acc = Vec::new();
    let g = ght_vote(
        &rt,
        seg.pixels.len(),
        &voters(&moved, &theta, w, 36).unwrap(),
        0,
        20,
        1,
        36,
        1,
        &mut acc,
    )
    .expect("votes");
    assert_eq!(g.score, 1.0);
    assert_eq!(g.peak as usize, seg.pixels.len());
    // The 3x3 centroid is pulled a little by coincidental votes of other pixel pairs.
    assert!((g.tx - 7.0).abs() < 0.5 && g.ty.abs() < 0.5, "{g:?}");
    let _ = h;
}

#[test]
fn ght_by_rows_equals_ght_by_bins() {
    // Every pair of a left and a right segment of two real-like channels, over several
    // windows, bands and bin tolerances: the row index gives the same votes, so the same peak,
    // score and translation, bit for bit.
    let (w, h) = (160, 100);
    let p = McgmParams::default();
    let cl = channel_curves(&blobs(w, h, 0.0), 1.0, 1, &p).unwrap();
    let cr = channel_curves(&blobs(w, h, 3.4), 1.0, 1, &p).unwrap();
    let (mut acc, mut acc2) = (Vec::new(), Vec::new());
    let mut compared = 0;
    for (a, rt) in cl.curves.segments.iter().zip(&cl.rtables).take(40) {
        let ix = RowIndex::new(rt).unwrap();
        for b in cr.curves.segments.iter().take(60) {
            let vb = voters(&b.pixels, &cr.zc.theta, w, 36).unwrap();
            for (lo, hi, dy, tol) in [(0, 16, 1, 1), (-5, 40, 0, 0), (2, 9, 2, 3)] {
                let want = ght_vote(rt, a.pixels.len(), &vb, lo, hi, dy, 36, tol, &mut acc);
                let got = ght_vote_rows(&ix, a.pixels.len(), &vb, lo, hi, dy, 36, tol, &mut acc2);
                assert_eq!(want, got);
                assert_eq!(acc, acc2);
                compared += usize::from(want.is_some());
            }
        }
    }
    assert!(compared > 100, "{compared} voting pairs");
    let _ = h;
}

#[test]
fn known_subpixel_shift_sign_and_magnitude() {
    for d in [2.3f32, 5.6] {
        let l = blobs(200, 150, 0.0);
        let r = blobs(200, 150, d); // right(x) = left(x + d): x_l - x_r = +d
        let p = McgmParams {
            d_max: 16,
            ..McgmParams::default()
        };
        let out = mcgm_match(&l, &r, &p).expect("valid input");
        assert!(out.matches.len() > 300, "{} matches", out.matches.len());
        let mut disp: Vec<f32> = out.matches.iter().map(|m| m.xl - m.xr).collect();
        disp.sort_by(f32::total_cmp);
        let med = disp[disp.len() / 2];
        assert!((med - d).abs() < 0.05, "d {d}: median {med}");
        let good = disp.iter().filter(|&&v| (v - d).abs() < 0.25).count();
        assert!(good as f32 > 0.95 * disp.len() as f32);
        assert!(out.matches.iter().all(|m| m.yl == m.yr));
    }
}

#[test]
fn bad_parameters_are_errors_not_panics() {
    let img = blobs(40, 30, 0.0);
    let bad = [
        McgmParams {
            d_min: 5,
            d_max: 2,
            ..McgmParams::default()
        },
        McgmParams {
            sigmas: vec![],
            ..McgmParams::default()
        },
        McgmParams {
            sigmas: vec![f32::NAN],
            ..McgmParams::default()
        },
    ];
    // Bin counts that would ask for terabytes (an abort, not an error) or overflow.
    let bins = [
        (MAX_THETA_BINS + 1, 1),
        (1_000_000_000_000, 1),
        (36, usize::MAX),
    ]
    .map(|(n_bins, vote_bin_tol)| {
        let mut p = McgmParams::default();
        p.cand.n_bins = n_bins;
        p.cand.vote_bin_tol = vote_bin_tol;
        p
    });
    // A band of 1e9 rows asked for 136 GB (an abort); a fill radius of i32::MAX overflowed the
    // window's arithmetic into an out-of-bounds index.
    let ranges = [
        (MAX_DY_BAND + 1, 1),
        (1_000_000_000, 1),
        (1, MAX_RADIUS + 1),
        (1, i32::MAX),
    ]
    .map(|(dy_band, fill_radius)| {
        let mut p = McgmParams::default();
        p.cand.dy_band = dy_band;
        p.fill_radius = fill_radius;
        p
    });
    for p in bad.into_iter().chain(bins).chain(ranges) {
        assert!(matches!(
            mcgm_match(&img, &img, &p),
            Err(CoreError::InvalidParameter { .. })
        ));
    }
    let other = blobs(41, 30, 0.0);
    assert!(matches!(
        mcgm_match(&img, &other, &McgmParams::default()),
        Err(CoreError::SizeMismatch { .. })
    ));
    // Tiny images: no crossings, no matches, no panic.
    // Strips 1 to 4 pixels wide or high (the half-resolution channel of a 3-pixel strip is 1
    // pixel wide): no interior to track, no error.
    for (w, h) in [
        (1, 40),
        (2, 40),
        (3, 40),
        (4, 40),
        (40, 1),
        (40, 2),
        (40, 3),
        (40, 4),
    ] {
        let img = Image {
            width: w,
            height: h,
            data: (0..w * h).map(|i| ((i * 37) % 11) as f32 / 11.0).collect(),
        };
        let out = mcgm_match(&img, &img, &McgmParams::default()).expect("valid");
        assert!(out.matches.is_empty(), "{w}x{h}");
        assert_eq!(
            image_curves(&img, &McgmParams::default())
                .expect("valid")
                .len(),
            3
        );
    }
    let tiny = Image::filled(2, 2, 0.3).unwrap();
    assert!(mcgm_match(&tiny, &tiny, &McgmParams::default())
        .expect("valid")
        .matches
        .is_empty());
}

/// The former implementation (frontier dilations): the reference of [`spread_prior`].
/// Nearest-valid fill of a NaN map up to `radius` px in chessboard distance (B.4.11's
/// distance-limited spread): `radius` synchronous 8-neighbour dilations, each new pixel taking
/// the value of its first valid neighbour in [`SPREAD_ORDER`] from the previous step.
fn spread_by_dilations(map: &[f32], w: usize, h: usize, radius: i32) -> Vec<f32> {
    let mut cur = map.to_vec();
    let mut front: Vec<usize> = (0..w * h).filter(|&i| cur[i].is_finite()).collect();
    let mut seen = vec![false; w * h];
    for _ in 0..radius {
        let mut next: Vec<usize> = Vec::new();
        for &i in &front {
            let (x, y) = ((i % w) as i32, (i / w) as i32);
            for &(dx, dy) in &SPREAD_ORDER {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w as i32 || ny >= h as i32 {
                    continue;
                }
                let q = ny as usize * w + nx as usize;
                if !cur[q].is_finite() && !seen[q] {
                    seen[q] = true;
                    next.push(q);
                }
            }
        }
        // Values from the previous step only (synchronous update).
        let vals: Vec<f32> = next
            .iter()
            .map(|&q| {
                let (x, y) = ((q % w) as i32, (q / w) as i32);
                SPREAD_ORDER
                    .iter()
                    .filter_map(|&(dx, dy)| {
                        let (nx, ny) = (x + dx, y + dy);
                        (nx >= 0 && ny >= 0 && nx < w as i32 && ny < h as i32)
                            .then(|| cur[ny as usize * w + nx as usize])
                    })
                    .find(|v| v.is_finite())
                    .unwrap_or(f32::NAN)
            })
            .collect();
        for (&q, v) in next.iter().zip(vals) {
            cur[q] = v;
        }
        if next.is_empty() {
            break;
        }
        front = next;
    }
    cur
}

#[test]
fn spread_prior_equals_the_dilations() {
    let mut rng = crate::matching::hopfield::network::SplitMix64::new(3);
    for &(w, h, density, radius) in &[
        (1, 1, 1, 3),
        (7, 5, 10, 2),
        (60, 40, 50, 4),
        (83, 61, 300, 9),
        (40, 30, 2000, 40),
        (50, 50, 0, 3),
    ] {
        let map: Vec<f32> = (0..w * h)
            .map(|_| {
                let r = rng.next_u64();
                if density > 0 && r.is_multiple_of(density) {
                    (r >> 40) as f32 / 1000.0
                } else if r % 97 == 1 {
                    f32::INFINITY
                } else {
                    f32::NAN
                }
            })
            .collect();
        let want = spread_by_dilations(&map, w, h, radius);
        let got = spread_prior(&map, w, h, radius).unwrap();
        let same = want
            .iter()
            .zip(&got)
            .all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()));
        assert!(same, "{w}x{h} density 1/{density} radius {radius}");
    }
}

#[cfg(target_arch = "x86_64")]
#[test]
fn both_sides_avx2_blocks_equal_the_portable_sums() {
    // Random rows and windows: at a threshold equal to a lane's portable value the lane does
    // not fit better, one ulp above it does; the AVX2 blocks must agree on every lane, so
    // their sums are the portable ones bit for bit.
    if !crate::simd::has_avx2() {
        return;
    }
    let mut rng = crate::matching::hopfield::network::SplitMix64::new(11);
    let mut unit = || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
    let r: Vec<f32> = (0..4000).map(|_| unit()).collect();
    for trial in 0..20 {
        let els: Vec<(usize, f32, f32)> =
            (0..28).map(|e| (e * 100 + trial, unit(), unit())).collect();
        let n = els.len() as f32;
        for mean_free in [false, true] {
            let sums = sads_scalar::<32>(&r, &els, 3, n, mean_free);
            for (t, &s) in sums.iter().enumerate() {
                let v = s / n + 0.01;
                for (here, want) in [(v, false), (v.next_up(), true)] {
                    let m = unsafe {
                        sads_fit_mask_avx2::<32>(&r, &els, 3, n, mean_free, (here, 0.01))
                    };
                    assert_eq!((m >> t) & 1 == 1, want, "trial {trial} lane {t}");
                    let m8 = unsafe {
                        sads_fit_mask_avx2::<8>(&r, &els, 3 + t / 8 * 8, n, mean_free, (here, 0.01))
                    };
                    assert_eq!((m8 >> (t % 8)) & 1 == 1, want, "trial {trial} lane {t} (8)");
                }
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[test]
fn both_sides_avx2_masks_equal_the_portable_ones_at_the_row_ends() {
    // Rows of J + 1 ..= J + 40 samples, 1..=9 elements whose J + 1 samples start at 0 (the
    // left end) and end at the row's last sample (the right end), every start in between:
    // the AVX2 masks (8 and 32 lanes) against the portable sums' masks, thresholds at and one
    // ulp above each lane's value.
    if !crate::simd::has_avx2() {
        return;
    }
    fn check<const J: usize>(r: &[f32], els: &[(usize, f32, f32)], j0: usize, what: &str) {
        let n = els.len() as f32;
        for mean_free in [false, true] {
            let sums = sads_scalar::<J>(r, els, j0, n, mean_free);
            for (t, &s) in sums.iter().enumerate() {
                let v = s / n + 0.01;
                for here in [v, v.next_up()] {
                    let want = sums
                        .iter()
                        .enumerate()
                        .fold(0u32, |m, (q, &a)| m | (u32::from(a / n + 0.01 < here) << q));
                    let m =
                        unsafe { sads_fit_mask_avx2::<J>(r, els, j0, n, mean_free, (here, 0.01)) };
                    assert_eq!(m, want, "{what} lane {t} mean_free {mean_free}");
                }
            }
        }
    }
    let mut rng = crate::matching::hopfield::network::SplitMix64::new(5);
    let mut unit = || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
    // Element e reads r[o_e + j0 ..= o_e + j0 + J]: element 0 from `start` (the row's end at the
    // largest start), element 1 from j0 (the row's start when j0 = 0), the others in between.
    let mut els_at = |start: usize, j0: usize, n_els: usize| -> Vec<(usize, f32, f32)> {
        (0..n_els)
            .map(|e| {
                let o = match e {
                    0 => start - j0,
                    1 => 0,
                    _ => (e * 7) % (start - j0 + 1),
                };
                (o, unit(), unit())
            })
            .collect()
    };
    for len in 33..=72usize {
        let r: Vec<f32> = (0..len)
            .map(|i| ((i * 7919) % 257) as f32 / 256.0)
            .collect();
        for n_els in [1usize, 2, 9] {
            for start in 0..=len - 33 {
                let j0 = start.min(2);
                let els = els_at(start, j0, n_els);
                check::<32>(&r, &els, j0, &format!("J 32 len {len} start {start}"));
            }
            for start in 0..=len - 9 {
                let j0 = start.min(3);
                let els = els_at(start, j0, n_els);
                check::<8>(&r, &els, j0, &format!("J 8 len {len} start {start}"));
            }
        }
    }
}

/// Every lane's mean absolute deviation of one half-window, as [`half_better`] defines it
/// (the portable sums, no bound): `(k, value)` for the `k` in `ks` whose samples lie inside
/// the row and `|k| > 1`.
fn lane_mads(
    left: &Image,
    right: &Image,
    at: (i32, i32, i32, f32),
    side: i32,
    geom: (i32, i32, i32),
    mean_free: bool,
    ks: (i32, i32),
) -> Vec<(i32, f32)> {
    let (base, _, (k_lo, k_hi)) = window_bases(at, side, geom, ks, right.width);
    let mut els = Vec::new();
    window_elements(left, right.width, at, side, geom, (&base, k_hi), &mut els);
    let n = els.len() as f32;
    (k_lo..=k_hi)
        .filter(|k| k.abs() > 1)
        .map(|k| {
            let j = (k_hi - k) as usize;
            (
                k,
                sads_scalar::<1>(&right.data, &els, j, n, mean_free)[0] / n,
            )
        })
        .collect()
}

/// Asserts that [`SidesBound`] leaves every lane open whose exact value (`lane_mads`) is at
/// most the threshold: the bound never exceeds the value beyond half_better's rounding slack.
#[allow(clippy::too_many_arguments)]
fn bound_keeps_every_lane(
    left: &Image,
    right: &Image,
    at: (i32, i32, i32, f32),
    side: i32,
    geom: (i32, i32, i32),
    mean_free: bool,
    ks: (i32, i32),
    scratch: &mut SidesScratch,
) -> usize {
    let (base, b_range, (k_lo, k_hi)) = window_bases(at, side, geom, ks, right.width);
    let nk = (k_hi - k_lo + 1) as usize;
    let bound = SidesBound::new(
        left,
        right,
        at,
        side,
        geom,
        (k_hi, nk),
        (&base, b_range),
        scratch,
    );
    let slack = 1e-4 * (1.0 + scratch.scale);
    let values = lane_mads(left, right, at, side, geom, mean_free, ks);
    for &(k, v) in &values {
        let j = (k_hi - k) as usize;
        let bits = bound.open_lanes(
            &scratch.rows,
            &mut scratch.tb,
            j / 8 * 8,
            mean_free,
            v + slack,
        );
        assert!(
            bits >> (j % 8) & 1 == 1,
            "lane k = {k} (value {v}) ruled out: {at:?} {geom:?}"
        );
    }
    values.len()
}

#[test]
fn both_sides_bound_never_rules_out_the_best_other_disparity() {
    // half_better sums only the lanes its lower bound leaves open: every lane whose exact value
    // is at most a threshold must stay open at that threshold. And with `here` one ulp above
    // the best other disparity's value (+ margin) that lane fits better and must be found; at
    // the value itself nothing fits better. Smooth and noisy pairs, grey levels in [0, 1] and
    // in [0, 255], both polarities of the window, with and without the mean removed.
    let (w, h) = (160, 40);
    let mut rng = crate::matching::hopfield::network::SplitMix64::new(5);
    let mut unit = || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
    let noise: Vec<f32> = (0..w * h).map(|_| unit()).collect();
    let pairs = [
        (blobs(w, h, 0.0), blobs(w, h, 7.3)),
        (
            Image::new(w, h, noise.clone()).unwrap(),
            Image::new(w, h, noise.iter().map(|v| 0.9 * v + 0.05).collect()).unwrap(),
        ),
    ];
    let mut checked = 0;
    for (l, r) in &pairs {
        for scale in [1.0f32, 255.0] {
            let l = Image::new(w, h, l.data.iter().map(|v| v * scale).collect()).unwrap();
            let r = Image::new(w, h, r.data.iter().map(|v| v * scale).collect()).unwrap();
            let mut scratch = SidesScratch {
                scale,
                ..SidesScratch::default()
            };
            for (t, geom) in [(1, 4, 3), (2, 7, 3), (1, 16, 1)].into_iter().enumerate() {
                for mean_free in [false, true] {
                    for side in [-1, 1] {
                        let at = (60 + 13 * t as i32, 20, 20, 7.3 + 0.37 * t as f32);
                        let ks = (-7, 40);
                        let v = lane_mads(&l, &r, at, side, geom, mean_free, ks);
                        let best = v.iter().map(|p| p.1).fold(f32::INFINITY, f32::min);
                        let lanes = bound_keeps_every_lane(
                            &l,
                            &r,
                            at,
                            side,
                            geom,
                            mean_free,
                            ks,
                            &mut scratch,
                        );
                        assert_eq!(lanes, v.len());
                        for margin in [0.0f32, 0.01 * scale] {
                            let fits = (best + margin).next_up();
                            let args = (at, side, geom, mean_free, ks);
                            let run = |here: f32, s: &mut SidesScratch| {
                                let (at, side, geom, mean_free, ks) = args;
                                half_better(
                                    &l,
                                    &r,
                                    at,
                                    side,
                                    geom,
                                    mean_free,
                                    ks,
                                    (here, margin),
                                    s,
                                )
                            };
                            assert!(
                                run(fits, &mut scratch),
                                "{geom:?} {mean_free} {side} x{scale}"
                            );
                            assert!(!run(best + margin, &mut scratch), "{geom:?} {mean_free}");
                            checked += 1;
                        }
                    }
                }
            }
        }
    }
    assert_eq!(checked, 2 * 2 * 3 * 2 * 2 * 2);

    // A window whose right bases skip a pixel: x - d rounds differently on either side of 512
    // (at d = 7 + 2e-5 the columns 517..=522 have bases 509, 510, 511, 513, 514, 515).
    // Smooth texture shifted by the disparity: small values on many lanes, which a bound that
    // mixed up the columns would exceed.
    let w = 640;
    let (l, r) = (blobs(w, h, 0.0), blobs(w, h, 7.0));
    let d = 7.0f32 + 2e-5;
    let bases: Vec<i32> = (517..=522).map(|x| (x as f32 - d).floor() as i32).collect();
    assert_eq!(bases, [509, 510, 511, 513, 514, 515]);
    let mut scratch = SidesScratch {
        scale: 1.0,
        ..SidesScratch::default()
    };
    for mean_free in [false, true] {
        let (at, geom, ks) = ((515, 20, 20, d), (2, 7, 3), (-7, 60));
        let v = lane_mads(&l, &r, at, 1, geom, mean_free, ks);
        assert!(bound_keeps_every_lane(&l, &r, at, 1, geom, mean_free, ks, &mut scratch) > 50);
        let best = v.iter().map(|p| p.1).fold(f32::INFINITY, f32::min);
        let run = |here: f32, s: &mut SidesScratch| {
            half_better(&l, &r, at, 1, geom, mean_free, ks, (here, 0.0), s)
        };
        assert!(
            run(best.next_up(), &mut scratch),
            "skipped base, mean_free {mean_free}"
        );
        assert!(
            !run(best, &mut scratch),
            "skipped base, mean_free {mean_free}"
        );
    }
}

#[test]
fn both_sides_any_open_equals_the_block_scan_of_open_lanes() {
    // half_better's early `false` (no lane open) against the rule its block scan applies: some
    // lane j in 0..nk with `k = k_hi - j` outside -1..=1 and `acc[j] / n < open_below`. Every
    // lane count up to 3 blocks, the near lanes at either end, inside and outside the range;
    // thresholds one ulp above and at a lane's quotient; NaN and infinite sums.
    let mut rng = crate::matching::hopfield::network::SplitMix64::new(17);
    let mut unit = || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
    let (mut opened, mut closed) = (0, 0);
    for n in [1.0f32, 28.0, 3.0] {
        let bound = SidesBound {
            nc: 1,
            cols: [(0, 0.0, 0.0, 0.0); MAX_SIDES_WIDTH],
            ltot: 0.0,
            rows: (1.0, 0.0),
            n,
            shared_weight: true,
        };
        for nk in 1..=24usize {
            let acc: Vec<f32> = (0..nk)
                .map(|_| match (unit() * 10.0) as u32 {
                    0 => f32::NAN,
                    1 => f32::INFINITY,
                    _ => unit() * 50.0,
                })
                .collect();
            for k_hi in -3..=nk as i32 + 3 {
                for j in 0..nk {
                    for below in [(acc[j] / n).next_up(), acc[j] / n, f32::NAN] {
                        let want = (0..nk)
                            .any(|t| !(-1..=1).contains(&(k_hi - t as i32)) && acc[t] / n < below);
                        let got = bound.any_open(&acc, k_hi, below);
                        assert_eq!(got, want, "n {n} nk {nk} k_hi {k_hi} j {j} {below}");
                        if got {
                            opened += 1;
                        } else {
                            closed += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(
        opened > 1000 && closed > 1000,
        "{opened} open, {closed} closed"
    );
}

#[test]
fn knn_graph_equals_the_brute_force_neighbours() {
    // Random centroids, some repeated and some on a lattice (exact distance ties), several
    // densities and radii: the ring search gives the brute-force k nearest within r_max
    // (ties by id), symmetrised.
    let mut rng = crate::matching::hopfield::network::SplitMix64::new(5);
    let mut unit = || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
    for &(n, size, k, r_max) in &[
        (300usize, 200.0f32, 6usize, 60.0f32),
        (2000, 900.0, 6, 60.0),
        (500, 100.0, 3, 7.5),
        (40, 1000.0, 6, 60.0),
        (1, 10.0, 6, 60.0),
    ] {
        let mut cs: Vec<(f32, f32)> = (0..n)
            .map(|i| match i % 5 {
                0 => ((i % 37) as f32 * 4.0, (i / 37) as f32 * 4.0),
                _ => (unit() * size, unit() * size),
            })
            .collect();
        if n > 10 {
            cs[7] = cs[3];
        }
        let segs: Vec<Segment> = cs
            .iter()
            .map(|&c| Segment {
                pixels: vec![0],
                centroid: c,
                x_min: 0,
                x_max: 0,
                y_min: 0,
                y_max: 0,
                mean_theta: 0.0,
            })
            .collect();
        let got = graph::knn_graph(&segs, k, r_max).unwrap();
        let mut want: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (i, &(x, y)) in cs.iter().enumerate() {
            let mut d: Vec<(f32, u32)> = cs
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(j, &(u, v))| (((u - x) * (u - x) + (v - y) * (v - y)).sqrt(), j as u32))
                .filter(|&(dd, _)| dd <= r_max)
                .collect();
            d.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(_, j) in d.iter().take(k) {
                want[i].push(j);
                want[j as usize].push(i as u32);
            }
        }
        for a in want.iter_mut() {
            a.sort_unstable();
            a.dedup();
        }
        assert_eq!(got, want, "n {n} size {size} k {k} r_max {r_max}");
    }
}

/// `wrap_angle` maps a difference of two angles in `[0, 2 pi)` to `(-pi, pi]`: -pi becomes pi
/// (a `<` for the lower end's `<=` survived the tests: every caller takes the absolute value).
#[test]
fn wrap_angle_range_is_open_below_and_closed_above() {
    use std::f64::consts::{PI, TAU};
    assert_eq!(tracking::wrap_angle(-PI), PI);
    assert_eq!(tracking::wrap_angle(PI), PI);
    assert_eq!(tracking::wrap_angle(0.0), 0.0);
    assert_eq!(tracking::wrap_angle(1.5 * PI), 1.5 * PI - TAU);
    assert_eq!(tracking::wrap_angle(-1.5 * PI), TAU - 1.5 * PI);
}

#[test]
fn orientation_bin_equals_the_floor_of_the_quotient() {
    // Every f32 in [0, 2 pi) 997 ulps apart, and every f32 within 64 ulps of each bin edge:
    // the product form gives the bin of the rounded f64 quotient.
    use std::f64::consts::TAU;
    let want = |t: f32, n: usize| ((t as f64 * n as f64 / TAU) as usize) % n;
    for n in [3usize, 36, 72, 1000, 1 << 20, (1 << 20) + 1] {
        let mut t = 0.0f32;
        while (t as f64) < TAU {
            assert_eq!(rtable::theta_bin(t, n), want(t, n), "theta {t} n {n}");
            t = f32::from_bits(t.to_bits() + 997);
        }
        for b in 1..n.min(5000) {
            let edge = (b as f64 * TAU / n as f64) as f32;
            for k in -64i32..=64 {
                let t = f32::from_bits((edge.to_bits() as i32 + k) as u32);
                assert_eq!(rtable::theta_bin(t, n), want(t, n), "theta {t} n {n}");
            }
        }
    }
}

#[test]
fn area_check_keeps_the_true_disparity_and_rejects_one_pixel_off() {
    let d = 4.4f32;
    let (l, r) = (blobs(200, 150, 0.0), blobs(200, 150, d));
    let at = |x: f32, y: f32, dd: f32| Match {
        xl: x,
        yl: y,
        xr: x - dd,
        yr: y,
        score: 0.0,
        channel: 0,
    };
    let (mut kept, mut off_kept, mut n) = (0, 0, 0);
    for y in (10..140).step_by(7) {
        for x in (20..190).step_by(5) {
            let (x, y) = (x as f32 + 0.3, y as f32);
            n += 1;
            kept += usize::from(area_ok(&l, &r, &at(x, y, d), 0.5));
            off_kept += usize::from(area_ok(&l, &r, &at(x, y, d + 1.0), 0.5));
        }
    }
    assert!(kept as f32 > 0.9 * n as f32, "{kept} of {n}");
    assert!((off_kept as f32) < 0.05 * n as f32, "{off_kept} of {n}");
    // Windows leaving the image, and flat windows, have no ZNCC: rejected.
    assert!(!area_ok(&l, &r, &at(2.0, 50.0, 0.0), 0.5));
    // The best of the five at either end is no peak: rejected (2 px off either way).
    for dd in [d - 2.0, d + 2.0] {
        let n_kept = (20..190)
            .step_by(5)
            .filter(|&x| area_ok(&l, &r, &at(x as f32 + 0.3, 70.0, dd), 0.5))
            .count();
        assert!(n_kept <= 1, "{dd}: {n_kept}");
    }
    let flat = Image::filled(200, 150, 0.5).unwrap();
    assert!(!area_ok(&flat, &flat, &at(100.0, 50.0, 0.0), 0.5));
}

/// Equal ZNCCs: the area check's best is the first of them. Columns alternating 0, 1 (period
/// 2) at d = 4.6: disparities 4 and 6 both fit exactly (ZNCC 1, 3, 5 and 7 -1); the first, 4,
/// is 0.6 px off (kept at tol 1), the last, 6, 1.4 px off (rejected).
#[test]
fn area_check_takes_the_first_of_equal_peaks() {
    let stripes = Image::new(40, 20, (0..40 * 20).map(|i| (i % 2) as f32).collect()).unwrap();
    let m = match_at(20.0, 10.0, 4.6);
    assert!(area_ok(&stripes, &stripes, &m, 1.0));
    assert!(!area_ok(&stripes, &stripes, &m, 0.5));
}

#[test]
fn repeated_correspondences_are_dropped_keeping_the_first() {
    let m = |xl: f32, xr: f32, score: f32| Match {
        xl,
        yl: 3.0,
        xr,
        yr: 3.0,
        score,
        channel: 0,
    };
    let mut ms = vec![
        m(5.5, 1.0, 1.0),
        m(7.0, 2.0, 2.0),
        m(5.5, 1.0, 3.0),
        m(5.5, 1.5, 4.0),
        m(7.0, 2.0, 5.0),
    ];
    drop_repeats(&mut ms).unwrap();
    let scores: Vec<f32> = ms.iter().map(|m| m.score).collect();
    assert_eq!(scores, [1.0, 2.0, 4.0]);
}

/// `edge_filters` (called directly, as `_core.mcgm_filter` does) checks its parameters like
/// `mcgm_match`: a `sides_width` of 0 or -1 indexed past the column table (a panic).
#[test]
fn edge_filters_check_their_parameters() {
    let (l, r) = (blobs(64, 40, 0.0), blobs(64, 40, 3.0));
    let ms = [Match {
        xl: 30.0,
        yl: 20.0,
        xr: 27.0,
        yr: 20.0,
        score: 1.0,
        channel: 0,
    }];
    let ok = FilterParams::default();
    assert!(edge_filters(&l, &r, &ms, &ok, (0, 16)).is_ok());
    for bad in [
        FilterParams {
            sides_width: -1,
            ..ok
        },
        FilterParams {
            sides_width: 0,
            ..ok
        },
        FilterParams {
            sides_width: 17,
            ..ok
        },
        FilterParams {
            sides_height: 0,
            ..ok
        },
        FilterParams { disc_dx: -1, ..ok },
        FilterParams {
            sides_mad: f32::NAN,
            ..ok
        },
        FilterParams {
            sides_best_margin: -1.0,
            ..ok
        },
        FilterParams {
            sides_best_margin: f32::NAN,
            ..ok
        },
    ] {
        let err = edge_filters(&l, &r, &ms, &bad, (0, 16)).unwrap_err();
        assert!(matches!(err, CoreError::InvalidParameter { .. }), "{err}");
    }
}

/// A deterministic generator of `[0, 1)` floats for the scalar-reference tests below.
fn unit_rng(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 40) as f32) / (1u64 << 24) as f32
    }
}

#[test]
fn log_kernels_and_reflect_have_the_specified_values() {
    use super::log::{radius_for, reflect};
    // Radius ceil(4 sigma), at least 1.
    assert_eq!(radius_for(1.0), 4);
    assert_eq!(radius_for(0.6), 3);
    assert_eq!(radius_for(0.1), 1);
    // g(t) = exp(-t^2 / 2 sigma^2); a = (t^2 / sigma^2 - 1) g / (2 pi sigma^2), made zero-mean
    // by subtracting g sum(a) / sum(g).
    let sigma = 1.5f64;
    let (g, a) = log_kernels(sigma as f32).unwrap();
    let r = 6isize;
    assert_eq!(g.len(), 13);
    let gw: Vec<f64> = (-r..=r)
        .map(|t| (-((t * t) as f64) / (2.0 * sigma * sigma)).exp())
        .collect();
    let aw: Vec<f64> = (-r..=r)
        .zip(&gw)
        .map(|(t, gv)| {
            ((t * t) as f64 / (sigma * sigma) - 1.0) * gv
                / (2.0 * std::f64::consts::PI * sigma * sigma)
        })
        .collect();
    let (sa, sg): (f64, f64) = (aw.iter().sum(), gw.iter().sum());
    for k in 0..13 {
        assert!((g[k] as f64 - gw[k]).abs() < 1e-7, "g[{k}]");
        let want = aw[k] - gw[k] * sa / sg;
        assert!((a[k] as f64 - want).abs() < 1e-8, "a[{k}] {} {want}", a[k]);
    }
    // Reflect-101: the edge pixel is not repeated; folds again past the far end.
    let want5 = [
        (-1, 1),
        (-4, 4),
        (5, 3),
        (8, 0),
        (-5, 3),
        (9, 1),
        (13, 3),
        (2, 2),
    ];
    for (i, want) in want5 {
        assert_eq!(reflect(i, 5), want, "reflect({i}, 5)");
    }
    for i in [-3, 0, 4] {
        assert_eq!(reflect(i, 1), 0);
    }
}

#[test]
fn log_filter_equals_the_direct_2d_convolution() {
    // K(x, y) = a(x) g(y) + g(x) a(y) over reflect-101 borders, summed in f64 directly: non-square
    // images, one smaller than the kernel (folded borders).
    use super::log::reflect;
    for &(w, h, sigma) in &[(13usize, 7usize, 1.0f32), (5, 9, 2.0), (9, 4, 0.7)] {
        let mut rnd = unit_rng(w as u64 * 31 + h as u64);
        let img = Image::new(w, h, (0..w * h).map(|_| rnd()).collect()).unwrap();
        let (g, a) = log_kernels(sigma).unwrap();
        let r = (g.len() / 2) as isize;
        let got = log_filter(&img, sigma).unwrap();
        for y in 0..h {
            for x in 0..w {
                let mut s = 0.0f64;
                for j in -r..=r {
                    for i in -r..=r {
                        let k = a[(i + r) as usize] as f64 * g[(j + r) as usize] as f64
                            + g[(i + r) as usize] as f64 * a[(j + r) as usize] as f64;
                        let v = img.at(reflect(x as isize + i, w), reflect(y as isize + j, h));
                        s += k * v as f64;
                    }
                }
                let d = (got[y * w + x] as f64 - s).abs();
                assert!(
                    d < 1e-6,
                    "{w}x{h} sigma {sigma} ({x}, {y}): {} vs {s}",
                    got[y * w + x]
                );
            }
        }
    }
}

#[test]
fn decimate2_averages_each_2x2_block() {
    use super::log::decimate2;
    // v = x + 10 y: block (i, j) averages to (2i + 0.5) + 10 (2j + 0.5).
    let img = Image::new(
        5,
        5,
        (0..25).map(|k| (k % 5 + 10 * (k / 5)) as f32).collect(),
    )
    .unwrap();
    let d = decimate2(&img).unwrap();
    assert_eq!((d.width, d.height), (2, 2));
    assert_eq!(d.data, [5.5, 7.5, 25.5, 27.5]);
    // One row or column: the missing partner is the last one (clamped), size at least 1.
    let strip = Image::new(5, 1, vec![1.0, 3.0, 5.0, 7.0, 9.0]).unwrap();
    let d = decimate2(&strip).unwrap();
    assert_eq!((d.width, d.height, d.data.clone()), (2, 1, vec![2.0, 6.0]));
    let d = decimate2(&Image::new(1, 1, vec![0.25]).unwrap()).unwrap();
    assert_eq!((d.width, d.height, d.data.clone()), (1, 1, vec![0.25]));
}

/// The zero-crossing rule of algorithms.md B.4 written out pixel by pixel (no compaction):
/// the reference of [`zero_crossings`].
pub(super) fn zero_crossings_reference(l: &[f32], w: usize, h: usize) -> ZeroCrossings {
    use super::zerocross::ZC_V;
    use std::f32::consts::TAU;
    let n = w * h;
    let (mut mark, mut xsub) = (vec![0u8; n], vec![f32::NAN; n]);
    let inside = |x: usize, y: usize| x >= 1 && y >= 1 && x + 1 < w && y + 1 < h;
    for y in 0..h {
        for x in 0..w - 1 {
            let (a, b) = (l[y * w + x], l[y * w + x + 1]);
            let (px, pos) = if a * b < 0.0 {
                let px = if a.abs() <= b.abs() { x } else { x + 1 };
                (px, x as f32 + a / (a - b))
            } else if a == 0.0 && x >= 1 && l[y * w + x - 1] * b < 0.0 {
                (x, x as f32)
            } else {
                continue;
            };
            if !inside(px, y) {
                continue;
            }
            let i = y * w + px;
            if mark[i] & ZC_H == 0 || (pos - px as f32).abs() < (xsub[i] - px as f32).abs() {
                xsub[i] = pos;
            }
            mark[i] |= ZC_H;
        }
    }
    for y in 0..h - 1 {
        for x in 0..w {
            let (a, b) = (l[y * w + x], l[(y + 1) * w + x]);
            let py = if a * b < 0.0 {
                if a.abs() <= b.abs() {
                    y
                } else {
                    y + 1
                }
            } else if a == 0.0 && y >= 1 && l[(y - 1) * w + x] * b < 0.0 {
                y
            } else {
                continue;
            };
            if inside(x, py) {
                mark[py * w + x] |= ZC_V;
            }
        }
    }
    let (mut strength, mut theta) = (vec![0.0f32; n], vec![0.0f32; n]);
    for i in 0..n {
        if mark[i] == 0 {
            continue;
        }
        let x = i % w;
        let gx = 0.5 * (l[i + 1] - l[i - 1]);
        let gy = 0.5 * (l[i + w] - l[i - w]);
        let st = (gx * gx + gy * gy).sqrt();
        // The floor written out: the constant itself is under test.
        if st < 1e-5 {
            mark[i] = 0;
            xsub[i] = f32::NAN;
            continue;
        }
        // NaN as f32::NAN's bits, whatever the operations left (the channel's rule).
        strength[i] = if st.is_nan() { f32::NAN } else { st };
        let t = gy.atan2(gx);
        theta[i] = if t < 0.0 { (t + TAU) % TAU } else { t };
        if mark[i] & ZC_H == 0 {
            xsub[i] = if l[i - 1] * l[i] < 0.0 {
                x as f32 - 1.0 + l[i - 1] / (l[i - 1] - l[i])
            } else if l[i] * l[i + 1] < 0.0 {
                x as f32 + l[i] / (l[i] - l[i + 1])
            } else if gx != 0.0 && (l[i] / gx).abs() <= 1.0 {
                x as f32 - l[i] / gx
            } else {
                x as f32
            };
        }
    }
    ZeroCrossings {
        width: w,
        height: h,
        mark,
        xsub,
        strength,
        theta,
    }
}

#[test]
fn zero_crossings_equal_the_pixel_by_pixel_rule() {
    // Values from a few levels (exact zeros, equal magnitudes: the tie rules), a band of tiny
    // values (crossings on either side of MIN_STRENGTH) and smooth fields (sub-pixel positions, Newton
    // steps), on non-square images: every plane equal, bit for bit.
    use std::f32::consts::TAU;
    let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(u, v)| u.to_bits() == v.to_bits());
    for (seed, &(w, h)) in [(23usize, 17usize), (17, 23), (40, 30), (3, 9), (9, 3)]
        .iter()
        .enumerate()
    {
        let mut rnd = unit_rng(seed as u64 + 7);
        let fields: [Vec<f32>; 3] = [
            (0..w * h)
                .map(|_| ((rnd() * 5.0) as i32 - 2) as f32)
                .collect(),
            (0..w * h)
                .map(|i| {
                    let v = ((rnd() * 5.0) as i32 - 2) as f32;
                    if (1..=3).contains(&((i / w) % 6)) {
                        v * 1e-5
                    } else {
                        v * (0.5 + rnd())
                    }
                })
                .collect(),
            (0..w * h)
                .map(|i| {
                    let (x, y) = ((i % w) as f32, (i / w) as f32);
                    (0.7 * x + 0.3 * y).sin()
                        + 0.4 * (0.5 * y - 0.9 * x).cos()
                        + 0.05 * (rnd() - 0.5)
                })
                .collect(),
        ];
        for l in &fields {
            let got = zero_crossings(l, w, h).unwrap();
            let want = zero_crossings_reference(l, w, h);
            assert_eq!(got.mark, want.mark, "{w}x{h}");
            assert!(same(&got.xsub, &want.xsub), "{w}x{h} xsub");
            assert!(same(&got.strength, &want.strength), "{w}x{h} strength");
            assert!(same(&got.theta, &want.theta), "{w}x{h} theta");
            assert!(got.theta.iter().all(|&t| (0.0..TAU).contains(&t)));
        }
    }
    // A normal just below the +x axis: atan2 is a tiny negative angle, and t + 2 pi rounds to
    // 2 pi; the direction is 0, not 2 pi (the range is [0, 2 pi)).
    let (w, h) = (3, 3);
    let l = [0.0, 1e-7, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let zc = zero_crossings(&l, w, h).unwrap();
    assert_eq!(zc.mark[4], ZC_H);
    assert_eq!(zc.theta[4], 0.0);
}

/// The seed threshold written out plainly (a full sort): the reference of
/// [`tracking::high_threshold`]. The marked strengths sorted by their bit patterns, the value
/// at `floor(q (n - 1))` clamped to the list; 0 when nothing is marked. `zero_crossings` marks
/// strengths >= MIN_STRENGTH > 0 only, where the bit patterns order as the values do; strengths
/// it never gives (negative ones, -0, NaN of either sign) order by their bits as the kernel's
/// buckets do (-NaN last, not first as in `total_cmp`).
pub(super) fn high_threshold_reference(zc: &ZeroCrossings, q: f32) -> f32 {
    let mut marked: Vec<f32> = zc.marked().map(|i| zc.strength[i]).collect();
    marked.sort_by_key(|s| s.to_bits());
    if marked.is_empty() {
        return 0.0;
    }
    let k = ((q as f64) * (marked.len() - 1) as f64).floor() as usize;
    marked[k.min(marked.len() - 1)]
}

/// Hysteresis tracking written out plainly (full sorts, a neighbour loop with branches): the
/// reference of [`track`].
pub(super) fn track_reference(zc: &ZeroCrossings, p: &tracking::TrackParams) -> tracking::Curves {
    use std::f64::consts::{PI, TAU};
    let (w, h) = (zc.width, zc.height);
    let t_high = high_threshold_reference(zc, p.high_quantile);
    let t_low = p.low_ratio * t_high;
    let interior = |i: usize| i % w >= 1 && i / w >= 1 && i % w + 1 < w && i / w + 1 < h;
    let mut free: Vec<bool> = (0..w * h)
        .map(|i| interior(i) && zc.mark[i] != 0 && zc.strength[i] >= t_low && zc.strength[i] > 0.0)
        .collect();
    let mut seeds: Vec<usize> = (0..w * h)
        .filter(|&i| free[i] && zc.strength[i] >= t_high)
        .collect();
    seeds.sort_by(|&a, &b| zc.strength[b].total_cmp(&zc.strength[a]).then(a.cmp(&b)));
    let tangent = |i: usize| {
        let t = zc.theta[i] as f64;
        (-t.sin(), t.cos())
    };
    let turn = |d: f64| {
        let d = if d > PI {
            d - TAU
        } else if d <= -PI {
            d + TAU
        } else {
            d
        };
        d.abs()
    };
    let max_turn = (p.max_turn_deg as f64).to_radians();
    let steps = [
        (-1, -1),
        (0, -1),
        (1, -1),
        (-1, 0),
        (1, 0),
        (-1, 1),
        (0, 1),
        (1, 1),
    ];
    let grow = |start: usize, sign: f64, free: &mut Vec<bool>| {
        let mut out = Vec::new();
        let (mut cur, t0) = (start, tangent(start));
        let mut dir = (sign * t0.0, sign * t0.1);
        loop {
            let mut best: Option<(f64, f32, usize, i64, i64)> = None;
            for &(dx, dy) in &steps {
                let q = ((cur / w) as i64 + dy) as usize * w + ((cur % w) as i64 + dx) as usize;
                let dot =
                    (dx as f64 * dir.0 + dy as f64 * dir.1) / ((dx * dx + dy * dy) as f64).sqrt();
                // Forward half-plane only: a NaN projection (a NaN normal of either sign) is
                // not in it.
                let forward = dot > 0.0;
                if !free[q]
                    || !forward
                    || turn(zc.theta[q] as f64 - zc.theta[cur] as f64) >= max_turn
                {
                    continue;
                }
                let s = zc.strength[q];
                if best.is_none_or(|b| dot > b.0 || (dot == b.0 && s > b.1)) {
                    best = Some((dot, s, q, dx, dy));
                }
            }
            let Some((_, _, q, dx, dy)) = best else { break };
            free[q] = false;
            let t = tangent(q);
            let sgn = if t.0 * dx as f64 + t.1 * dy as f64 >= 0.0 {
                1.0
            } else {
                -1.0
            };
            dir = (sgn * t.0, sgn * t.1);
            out.push(q);
            cur = q;
        }
        out
    };
    let mut labels = vec![-1i32; w * h];
    let mut segments = Vec::new();
    for s in seeds {
        if !free[s] {
            continue;
        }
        free[s] = false;
        let fwd = grow(s, 1.0, &mut free);
        let bwd = grow(s, -1.0, &mut free);
        if 1 + fwd.len() + bwd.len() < p.min_len {
            continue;
        }
        let pixels: Vec<u32> = bwd
            .iter()
            .rev()
            .chain([s].iter())
            .chain(&fwd)
            .map(|&i| i as u32)
            .collect();
        let (mut sx, mut sy, mut sc, mut ss) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for &i in &pixels {
            let i = i as usize;
            labels[i] = segments.len() as i32;
            sx += (i % w) as f64;
            sy += (i / w) as f64;
            sc += (zc.theta[i] as f64).cos();
            ss += (zc.theta[i] as f64).sin();
        }
        let xs = pixels.iter().map(|&i| (i as usize % w) as i32);
        let ys = pixels.iter().map(|&i| (i as usize / w) as i32);
        let m = ss.atan2(sc);
        let k = pixels.len() as f64;
        segments.push(Segment {
            centroid: ((sx / k) as f32, (sy / k) as f32),
            x_min: xs.clone().min().unwrap(),
            x_max: xs.max().unwrap(),
            y_min: ys.clone().min().unwrap(),
            y_max: ys.max().unwrap(),
            mean_theta: (if m < 0.0 { m + TAU } else { m }) as f32 % std::f32::consts::TAU,
            pixels,
        });
    }
    tracking::Curves {
        segments,
        labels,
        t_high,
        t_low,
    }
}

#[test]
fn track_equals_the_plain_hysteresis_tracker() {
    // Crossings of real-like LoG responses, and synthetic ones (random marks, strengths on a
    // few levels: ties of the seed order and of the step choice; smooth or random normals),
    // under several thresholds: the same segments, labels and thresholds.
    let base = McgmParams::default().track;
    let params = [
        base,
        tracking::TrackParams { min_len: 1, ..base },
        tracking::TrackParams {
            high_quantile: 0.9,
            low_ratio: 1.0,
            max_turn_deg: 30.0,
            min_len: 3,
        },
        tracking::TrackParams {
            high_quantile: 0.2,
            low_ratio: 0.1,
            max_turn_deg: 90.0,
            min_len: 2,
        },
    ];
    let mut zcs = Vec::new();
    for (sigma, shift) in [(1.0f32, 0.0f32), (2.0, 1.3)] {
        let img = blobs(70, 50, shift);
        zcs.push(zero_crossings(&log_filter(&img, sigma).unwrap(), 70, 50).unwrap());
    }
    for (seed, &(w, h)) in [(31usize, 23usize), (12, 40)].iter().enumerate() {
        let mut rnd = unit_rng(seed as u64 + 99);
        for mode in 0..3 {
            let n = w * h;
            let mark: Vec<u8> = (0..n).map(|_| u8::from(rnd() < 0.55)).collect();
            let strength: Vec<f32> = (0..n)
                .map(|i| {
                    if mark[i] != 0 {
                        1e-5 * (1 + (rnd() * 4.0) as i32) as f32
                    } else {
                        0.0
                    }
                })
                .collect();
            let theta: Vec<f32> = (0..n)
                .map(|i| {
                    let (x, y) = ((i % w) as f32, (i / w) as f32);
                    // Smooth, random, or mostly exactly 0 (tangent (-0, 1): exact ties of
                    // the step projections and a zero tangent-step product).
                    let t = match mode {
                        0 => 0.3 * x - 0.2 * y + 0.4 * rnd(),
                        1 => std::f32::consts::TAU * rnd(),
                        _ => [0.0, 0.0, 0.0, 0.5, 5.9][(rnd() * 5.0) as usize],
                    };
                    t.rem_euclid(std::f32::consts::TAU)
                })
                .collect();
            let xsub = (0..n)
                .map(|i| {
                    if mark[i] != 0 {
                        (i % w) as f32
                    } else {
                        f32::NAN
                    }
                })
                .collect();
            zcs.push(ZeroCrossings {
                width: w,
                height: h,
                mark,
                xsub,
                strength,
                theta,
            });
        }
    }
    let mut n_segments = 0;
    for zc in &zcs {
        for p in &params {
            let got = track(zc, p).unwrap();
            let want = track_reference(zc, p);
            assert_eq!(got.t_high, want.t_high);
            assert_eq!(got.t_low, want.t_low);
            assert_eq!(
                got.segments, want.segments,
                "{}x{} {p:?}",
                zc.width, zc.height
            );
            assert_eq!(got.labels, want.labels);
            n_segments += got.segments.len();
        }
    }
    // No crossing: no seed, thresholds 0.
    let none = ZeroCrossings {
        width: 5,
        height: 5,
        mark: vec![0; 25],
        xsub: vec![f32::NAN; 25],
        strength: vec![0.0; 25],
        theta: vec![0.0; 25],
    };
    let got = track(&none, &base).unwrap();
    assert_eq!((got.t_high, got.t_low, got.segments.len()), (0.0, 0.0, 0));
    assert!(n_segments > 200, "{n_segments} segments");
}

/// The GHT of algorithms.md B.4.8 by brute force: every pixel pair within `tol` orientation bins
/// (circularly) votes for `t = p - q`; the first maximum (ty, then tx ascending), its 3x3
/// vote-weighted centroid, the peak over the longer segment.
#[allow(clippy::too_many_arguments)]
fn ght_reference(
    a: &[(i32, i32, usize)],
    b: &[(i32, i32, usize)],
    lo: i32,
    hi: i32,
    dy: i32,
    n_bins: usize,
    tol: usize,
) -> Option<rtable::Ght> {
    if hi < lo || a.is_empty() || b.is_empty() {
        return None;
    }
    let (nx, ny) = ((hi - lo + 1) as usize, (2 * dy + 1) as usize);
    let mut acc = vec![0u32; nx * ny];
    for &(px, py, pb) in a {
        for &(qx, qy, qb) in b {
            let d = pb.abs_diff(qb);
            let (tx, ty) = (px - qx, py - qy);
            if d.min(n_bins - d) <= tol && (lo..=hi).contains(&tx) && ty.abs() <= dy {
                acc[(ty + dy) as usize * nx + (tx - lo) as usize] += 1;
            }
        }
    }
    let best = *acc.iter().max().unwrap();
    if best == 0 {
        return None;
    }
    let bi = acc.iter().position(|&v| v == best).unwrap();
    let (cx, cy) = ((bi % nx) as i32, (bi / nx) as i32);
    let (mut sw, mut sx, mut sy) = (0.0f64, 0.0f64, 0.0f64);
    for yy in cy - 1..=cy + 1 {
        for xx in cx - 1..=cx + 1 {
            if yy < 0 || xx < 0 || yy >= ny as i32 || xx >= nx as i32 {
                continue;
            }
            let v = acc[yy as usize * nx + xx as usize] as f64;
            sw += v;
            sx += v * (xx + lo) as f64;
            sy += v * (yy - dy) as f64;
        }
    }
    Some(rtable::Ght {
        score: best as f32 / a.len().max(b.len()) as f32,
        tx: (sx / sw) as f32,
        ty: (sy / sw) as f32,
        peak: best,
    })
}

#[test]
fn ght_and_rtable_equal_the_brute_force_vote() {
    // Random pixel sets with orientations on few bins (many votes, ties of the peak), windows
    // cut at either side, bands, tolerances up to half the bins; both kernels.
    let w = 50usize;
    let mut rnd = unit_rng(4242);
    let mut compared = 0;
    for trial in 0..300 {
        let n_bins = [5usize, 8, 36][trial % 3];
        let seg = |n: usize, rnd: &mut dyn FnMut() -> f32| -> (Vec<u32>, Vec<f32>) {
            let pix: Vec<u32> = (0..n)
                .map(|_| ((rnd() * 12.0) as usize * w + (rnd() * 30.0) as usize + 10) as u32)
                .collect();
            let th: Vec<f32> = (0..n)
                .map(|_| {
                    ((rnd() * n_bins as f32).floor() + 0.5) * std::f32::consts::TAU / n_bins as f32
                })
                .collect();
            (pix, th)
        };
        let (pa, ta) = seg(1 + (rnd() * 15.0) as usize, &mut rnd);
        let (pb, tb) = seg((rnd() * 15.0) as usize, &mut rnd);
        let mut theta = vec![0.0f32; w * 20];
        let mut theta_b = vec![0.0f32; w * 20];
        for (&i, &t) in pa.iter().zip(&ta) {
            theta[i as usize] = t;
        }
        for (&i, &t) in pb.iter().zip(&tb) {
            theta_b[i as usize] = t;
        }
        // Distinct pixels (a segment visits each once), theta as stored.
        let dedup = |p: &[u32]| {
            let mut seen = std::collections::HashSet::new();
            p.iter()
                .copied()
                .filter(|&i| seen.insert(i))
                .collect::<Vec<u32>>()
        };
        let (pa, pb) = (dedup(&pa), dedup(&pb));
        let xy = |i: u32| ((i as usize % w) as i32, (i as usize / w) as i32);
        let cx = pa.iter().map(|&i| xy(i).0 as f32).sum::<f32>() / pa.len() as f32;
        let cy = pa.iter().map(|&i| xy(i).1 as f32).sum::<f32>() / pa.len() as f32;
        let sa = Segment {
            pixels: pa.clone(),
            centroid: (cx, cy),
            x_min: 0,
            x_max: 0,
            y_min: 0,
            y_max: 0,
            mean_theta: 0.0,
        };
        let rt = build_rtable(&sa, &theta, w, n_bins).unwrap();
        // The R-table: bins in order, each bin's pixels in segment order, r = c - p.
        let bin = |t: f32| rtable::theta_bin(t, n_bins);
        let mut k = 0;
        for b in 0..n_bins {
            assert_eq!(rt.offsets[b] as usize, k);
            for &i in pa.iter().filter(|&&i| bin(theta[i as usize]) == b) {
                let (x, y) = xy(i);
                assert_eq!(rt.px[k], (x, y));
                assert_eq!(rt.vecs[k], (cx - x as f32, cy - y as f32));
                k += 1;
            }
        }
        assert_eq!(rt.offsets[n_bins] as usize, pa.len());
        let va: Vec<(i32, i32, usize)> = pa
            .iter()
            .map(|&i| (xy(i).0, xy(i).1, bin(theta[i as usize])))
            .collect();
        let vb: Vec<(i32, i32, usize)> = pb
            .iter()
            .map(|&i| (xy(i).0, xy(i).1, bin(theta_b[i as usize])))
            .collect();
        let voters_b = voters(&pb, &theta_b, w, n_bins).unwrap();
        let ix = RowIndex::new(&rt).unwrap();
        let lo = (rnd() * 40.0) as i32 - 25;
        let hi = lo + (rnd() * 30.0) as i32 - 3;
        let dy = (rnd() * 3.0) as i32;
        let tol = (rnd() * ((n_bins - 1) / 2 + 1) as f32) as usize;
        let want = ght_reference(&va, &vb, lo, hi, dy, n_bins, tol);
        let mut acc = Vec::new();
        let got = ght_vote(&rt, pa.len(), &voters_b, lo, hi, dy, n_bins, tol, &mut acc);
        assert_eq!(got, want, "trial {trial} ght_vote");
        let got = ght_vote_rows(&ix, pa.len(), &voters_b, lo, hi, dy, n_bins, tol, &mut acc);
        assert_eq!(got, want, "trial {trial} ght_vote_rows");
        compared += usize::from(want.is_some());
    }
    assert!(compared > 100, "{compared}");
}

#[test]
fn candidates_equal_the_gated_brute_force_search() {
    // Every left-right segment pair of two real-like channels, gated as B.4.7 says (rows within
    // the band overlapping half the shorter extent, mean normals within the tolerance, centroid
    // offset within the window widened by half the wider segment, length ratio), scored by the
    // brute-force GHT; best k_cand per left segment, best first (ties by right id).
    let (w, h) = (140, 90);
    let p = McgmParams::default();
    let cl = channel_curves(&blobs(w, h, 0.0), 1.0, 1, &p).unwrap();
    let cr = channel_curves(&blobs(w, h, 4.6), 1.0, 1, &p).unwrap();
    let (ls, rs) = (&cl.curves.segments, &cr.curves.segments);
    let mut rnd = unit_rng(77);
    let window: Vec<Option<(i32, i32)>> = (0..ls.len())
        .map(|i| {
            (i % 7 != 3).then(|| {
                let lo = (rnd() * 10.0) as i32 - 2;
                (lo, lo + 2 + (rnd() * 14.0) as i32)
            })
        })
        .collect();
    for cp in [
        p.cand,
        graph::CandParams {
            dy_band: 0,
            vote_bin_tol: 1,
            ght_min_score: 0.6,
            k_cand: 2,
            seg_theta_tol_deg: 20.0,
            ..p.cand
        },
        graph::CandParams {
            dy_band: 3,
            ght_min_score: 0.2,
            k_cand: 100,
            ..p.cand
        },
    ] {
        let rts: Vec<_> = ls
            .iter()
            .map(|s| build_rtable(s, &cl.zc.theta, w, cp.n_bins).unwrap())
            .collect();
        let got = graph::candidates(ls, &rts, rs, &cr.zc.theta, w, h, &window, &cp).unwrap();
        let bins = |s: &Segment, theta: &[f32]| -> Vec<(i32, i32, usize)> {
            s.pixels
                .iter()
                .map(|&i| {
                    (
                        (i as usize % w) as i32,
                        (i as usize / w) as i32,
                        rtable::theta_bin(theta[i as usize], cp.n_bins),
                    )
                })
                .collect()
        };
        let mut want = Vec::new();
        for (ia, a) in ls.iter().enumerate() {
            let Some((lo, hi)) = window[ia] else { continue };
            let va = bins(a, &cl.zc.theta);
            let mut out = Vec::new();
            for (ib, b) in rs.iter().enumerate() {
                let (y0, y1) = (
                    (a.y_min - cp.dy_band).max(0),
                    (a.y_max + cp.dy_band).min(h as i32 - 1),
                );
                let ov = y1.min(b.y_max) - y0.max(b.y_min) + 1;
                let (ea, eb) = (a.y_max - a.y_min + 1, b.y_max - b.y_min + 1);
                let dth = tracking::wrap_angle(a.mean_theta as f64 - b.mean_theta as f64).abs();
                let slack = 0.5 * (a.x_max - a.x_min + 1).max(b.x_max - b.x_min + 1) as f32;
                let dc = a.centroid.0 - b.centroid.0;
                let (la, lb) = (a.pixels.len() as f32, b.pixels.len() as f32);
                if ov < 1
                    || dth >= (cp.seg_theta_tol_deg as f64).to_radians()
                    || (ov as f32) < 0.5 * ea.min(eb) as f32
                    || dc < lo as f32 - slack
                    || dc > hi as f32 + slack
                    || la.min(lb) / la.max(lb) < cp.ght_min_score
                {
                    continue;
                }
                let vb = bins(b, &cr.zc.theta);
                let Some(g) =
                    ght_reference(&va, &vb, lo, hi, cp.dy_band, cp.n_bins, cp.vote_bin_tol)
                else {
                    continue;
                };
                if g.score >= cp.ght_min_score {
                    out.push(graph::Candidate {
                        left: ia as u32,
                        right: ib as u32,
                        score: g.score,
                        tx: g.tx,
                        ty: g.ty,
                    });
                }
            }
            out.sort_by(|x, y| y.score.total_cmp(&x.score).then(x.right.cmp(&y.right)));
            out.truncate(cp.k_cand);
            want.extend(out);
        }
        assert_eq!(got, want, "{cp:?}");
        assert!(got.len() > 8, "{} candidates", got.len());
    }
}

#[test]
fn association_weights_and_the_resolution_follow_the_definitions() {
    // Weights: -B between candidates sharing a left or a right segment; between candidates of
    // adjacent left segments (different right ones) A C_ab / sqrt(deg A deg B) with
    // C_ab = 2 / (1 + exp(slope (g - g0))) - 1, g = |t_a - t_b| / max(1, |c_A - c_B|).
    let seg = |cx: f32, cy: f32| Segment {
        pixels: vec![0],
        centroid: (cx, cy),
        x_min: 0,
        x_max: 0,
        y_min: 0,
        y_max: 0,
        mean_theta: 0.0,
    };
    let left = [seg(0.0, 0.0), seg(3.0, 4.0), seg(0.5, 0.0), seg(40.0, 0.0)];
    let adj: Vec<Vec<u32>> = vec![vec![1, 2], vec![0], vec![0], vec![]];
    let c = |l: u32, r: u32, score: f32, tx: f32, ty: f32| graph::Candidate {
        left: l,
        right: r,
        score,
        tx,
        ty,
    };
    let cands = [
        c(0, 0, 0.9, 5.0, 0.0),
        c(0, 1, 0.8, 2.0, 0.0),
        c(1, 2, 0.95, 5.5, 0.5),
        c(1, 1, 0.5, 9.0, 0.0),
        c(2, 3, 0.7, 5.2, 0.0),
        c(3, 0, 0.95, 5.0, 0.0),
    ];
    let sp = SolverParams {
        a: 1.3,
        b: 1.7,
        dg_0: 0.4,
        dg_slope: 8.0,
        ..McgmParams::default().solver
    };
    let csr = graph::association_weights(&cands, &left, &adj, 4, &sp).unwrap();
    let compat = |ia: usize, ib: usize| {
        let (a, b) = (&cands[ia], &cands[ib]);
        let (sa, sb) = (&left[a.left as usize], &left[b.left as usize]);
        let dist = ((sa.centroid.0 - sb.centroid.0).powi(2)
            + (sa.centroid.1 - sb.centroid.1).powi(2))
        .sqrt()
        .max(1.0);
        let g = ((a.tx - b.tx).powi(2) + (a.ty - b.ty).powi(2)).sqrt() / dist;
        let deg = |i: u32| adj[i as usize].len() as f32;
        sp.a / (deg(a.left) * deg(b.left)).sqrt()
            * (2.0 / (1.0 + (sp.dg_slope * (g - sp.dg_0)).exp()) - 1.0)
    };
    let mut want: Vec<Vec<(u32, f32)>> = vec![Vec::new(); cands.len()];
    for ia in 0..cands.len() {
        for ib in 0..cands.len() {
            let (a, b) = (&cands[ia], &cands[ib]);
            if ia == ib {
                continue;
            }
            if a.left == b.left || a.right == b.right {
                want[ia].push((ib as u32, -sp.b));
            } else if adj[a.left as usize].contains(&b.left) {
                want[ia].push((ib as u32, compat(ia, ib)));
            }
        }
    }
    let got: Vec<Vec<(u32, f32)>> = (0..cands.len())
        .map(|a| {
            let (idx, val) = csr.row(a);
            idx.iter().copied().zip(val.iter().copied()).collect()
        })
        .collect();
    assert_eq!(got, want);
    // The resolution: with no weights every candidate with D score > theta ends on; each left
    // segment keeps its highest net input (= D score - theta), then each right segment.
    let empty = crate::matching::hopfield::Csr {
        indptr: vec![0; cands.len() + 1],
        indices: vec![],
        data: vec![],
    };
    let sol = graph::solve(&cands, &empty, 4, &sp).unwrap();
    assert_eq!(sol.state, [1, 1, 1, 1, 1, 1]);
    // Left 0: c0 (0.9); left 1: c2 (0.95); left 2: c4; left 3: c5, which takes right 0 from
    // c0 (0.95 > 0.9).
    assert_eq!(sol.chosen, [2, 4, 5]);
    // D score below theta: off, not chosen.
    let low = [c(0, 0, 0.25, 1.0, 0.0), c(1, 1, 0.9, 1.0, 0.0)];
    let empty2 = crate::matching::hopfield::Csr {
        indptr: vec![0; 3],
        indices: vec![],
        data: vec![],
    };
    let sol = graph::solve(&low, &empty2, 2, &sp).unwrap();
    assert_eq!((sol.state, sol.chosen), (vec![0, 1], vec![1]));
    // Net inputs with weights: a single weight lifts c1 above c0 on left 0.
    let lift = crate::matching::hopfield::Csr {
        indptr: vec![0, 0, 1, 1, 1, 1, 2],
        indices: vec![5, 1],
        data: vec![0.5, 0.5],
    };
    let sol = graph::solve(&cands, &lift, 4, &sp).unwrap();
    assert_eq!(sol.state, [1, 1, 1, 1, 1, 1]);
    assert_eq!(sol.chosen, [1, 2, 4, 5]);
    // Equal net inputs: the lower index.
    let tie = [
        c(0, 0, 0.8, 1.0, 0.0),
        c(0, 1, 0.8, 1.0, 0.0),
        c(1, 1, 0.8, 1.0, 0.0),
    ];
    let empty3 = crate::matching::hopfield::Csr {
        indptr: vec![0; 4],
        indices: vec![],
        data: vec![],
    };
    assert_eq!(graph::solve(&tie, &empty3, 2, &sp).unwrap().chosen, [0, 2]);
    // ... whatever order the left segments' groups come in: left 1's group first, its
    // candidate 0 ties left 0's candidate 1 on right 0 and is kept (the first one the
    // right-segment pass meets, left 0's, was kept with the index rule dropped).
    let swapped = [c(1, 0, 0.8, 1.0, 0.0), c(0, 0, 0.8, 1.0, 0.0)];
    assert_eq!(graph::solve(&swapped, &empty2, 2, &sp).unwrap().chosen, [0]);
    // The preset (each left segment's best candidate on) is a stable state of mutually
    // inhibiting pairs: the network stays there (from all off, the visiting order decides).
    let pairs: Vec<graph::Candidate> = (0..8u32)
        .flat_map(|i| [c(i, 2 * i, 0.9, 1.0, 0.0), c(i, 2 * i + 1, 0.85, 1.0, 0.0)])
        .collect();
    let segs: Vec<Segment> = (0..8).map(|i| seg(100.0 * i as f32, 0.0)).collect();
    let w8 = graph::association_weights(&pairs, &segs, &vec![Vec::new(); 8], 16, &sp).unwrap();
    let sol = graph::solve(&pairs, &w8, 8, &sp).unwrap();
    assert_eq!(sol.state, [1, 0].repeat(8));
    assert_eq!(sol.chosen, (0..8).map(|i| 2 * i).collect::<Vec<usize>>());
}

#[test]
fn candidates_reach_across_the_band_and_the_wider_segment_slack() {
    // Hand-built segments (normals along +x, theta 0): a horizontal left segment and its copy
    // two rows higher (dy_band 2) at disparity 3; a slanted 4-column-wide left segment and a
    // 1-column right one whose centroids differ by 4.2, past the window [0, 3] but within
    // half the wider segment (2 px).
    let (w, h) = (60usize, 40usize);
    let theta = vec![0.0f32; w * h];
    let mk = |pix: Vec<(usize, usize)>| {
        let n = pix.len() as f32;
        let xs = pix.iter().map(|p| p.0 as i32);
        let ys = pix.iter().map(|p| p.1 as i32);
        Segment {
            centroid: (
                pix.iter().map(|p| p.0 as f32).sum::<f32>() / n,
                pix.iter().map(|p| p.1 as f32).sum::<f32>() / n,
            ),
            x_min: xs.clone().min().unwrap(),
            x_max: xs.max().unwrap(),
            y_min: ys.clone().min().unwrap(),
            y_max: ys.max().unwrap(),
            mean_theta: 0.0,
            pixels: pix.iter().map(|&(x, y)| (y * w + x) as u32).collect(),
        }
    };
    let cp = graph::CandParams {
        dy_band: 2,
        ght_min_score: 0.2,
        ..McgmParams::default().cand
    };
    let run = |a: Segment, b: &[Segment], win: (i32, i32), cp: &graph::CandParams| {
        let rt = build_rtable(&a, &theta, w, cp.n_bins).unwrap();
        graph::candidates(&[a], &[rt], b, &theta, w, h, &[Some(win)], cp).unwrap()
    };
    let a = mk((20..26).map(|x| (x, 10)).collect());
    // Right 0 two rows higher, right 1 on the same row at disparity 5: both score 1.
    let b = [
        mk((17..23).map(|x| (x, 8)).collect()),
        mk((15..21).map(|x| (x, 10)).collect()),
    ];
    let got = run(a.clone(), &b, (0, 8), &cp);
    assert_eq!(got.len(), 2);
    assert_eq!((got[0].right, got[1].right), (0, 1));
    // Peak at t = (3, 2); the 3x3 centroid is pulled toward the rows around it.
    assert_eq!((got[0].score, got[1].score), (1.0, 1.0));
    assert!(got[0].ty > 1.0, "{:?}", got[0]);
    // Equal scores: the lower right id is kept first.
    let one = graph::CandParams { k_cand: 1, ..cp };
    let got = run(a.clone(), &b, (0, 8), &one);
    assert_eq!((got.len(), got[0].right), (1, 0));
    // ... also when the right segments are met out of id order (the one spanning the band's
    // first row before the ones starting below it): right 1 two rows higher, right 0 on the row.
    let b = [b[1].clone(), b[0].clone()];
    let got = run(a.clone(), &b, (0, 8), &cp);
    assert_eq!((got[0].right, got[1].right), (0, 1));
    let got = run(a, &b, (0, 8), &one);
    assert_eq!((got.len(), got[0].right), (1, 0));
    let a = mk((0..10).map(|k| (20 + k / 3, 10 + k)).collect());
    let b = [mk((10..20).map(|y| (17, y)).collect())];
    assert!((a.centroid.0 - b[0].centroid.0 - 4.2).abs() < 1e-5);
    // Peak 3 of 10 pixels: a score of 0.3 passes a threshold of 0.3 (inclusive).
    let at = graph::CandParams {
        ght_min_score: 0.3,
        ..cp
    };
    let got = run(a, &b, (0, 3), &at);
    assert_eq!(got.len(), 1);
    assert_eq!(got[0].score, 0.3);
}

/// One match at `(xl, yl)` of disparity `d` on the same row.
fn match_at(xl: f32, yl: f32, d: f32) -> Match {
    Match {
        xl,
        yl,
        xr: xl - d,
        yr: yl,
        score: 1.0,
        channel: 0,
    }
}

/// The both-sides check's half-windows are columns `xi +- (gap + 1 ..= gap + width)` of the
/// rounded left x and rows `yl +- height / 2`, inside the image; a MAD equal to `sides_mad`
/// passes. On flat images a match passes unless one window column is brightened.
#[test]
fn both_sides_windows_have_the_specified_columns_rows_and_limit() {
    let (w, h) = (40, 30);
    let f = FilterParams {
        sides_best: false,
        disc: false,
        zncc_check: false,
        ..FilterParams::default()
    };
    let kept = |left: &Image, m: Match, f: &FilterParams| {
        let r = Image::filled(w, h, 0.5).unwrap();
        edge_filters(left, &r, &[m], f, (0, 16)).unwrap().0[0]
    };
    let flat = Image::filled(w, h, 0.5).unwrap();
    // Column `c` of rows 12..=18 brightened by 0.4: a mean-free MAD of 2 * 0.4 * 5 / 36.
    let bright = |c: usize| {
        let mut img = Image::filled(w, h, 0.5).unwrap();
        for y in 12..=18 {
            img.data[y * w + c] = 0.9;
        }
        img
    };
    let m = match_at(20.0, 15.0, 0.0);
    for (c, expect) in [
        (19, true), // the skipped gap column
        (21, true),
        (18, false), // the first window column
        (22, false),
        (13, false), // the last window column
        (27, false),
        (12, true), // just outside
        (28, true),
    ] {
        assert_eq!(kept(&bright(c), m, &f), expect, "column {c}");
    }
    // xl 20.6 rounds to 21: columns 23..=28 on the right.
    assert!(!kept(&bright(28), match_at(20.6, 15.0, 0.0), &f));
    assert!(kept(&bright(22), match_at(20.6, 15.0, 0.0), &f));
    // A MAD of exactly sides_mad (0 here) passes.
    let f0 = FilterParams {
        sides_mad: 0.0,
        ..f
    };
    assert!(kept(&flat, m, &f0));
    // Rows yl +- 3 and columns xi +- 7 must lie inside the image.
    for (x, y, expect) in [
        (20.0, 3.0, true),
        (20.0, 2.0, false),
        (20.0, 26.0, true),
        (20.0, 27.0, false),
        (7.0, 15.0, true),
        (6.0, 15.0, false),
        (32.0, 15.0, true),
        (33.0, 15.0, false),
    ] {
        assert_eq!(kept(&flat, match_at(x, y, 0.0), &f), expect, "({x}, {y})");
    }
    // The left rows alone leaving the image.
    let low = Match {
        yr: 26.0,
        ..match_at(20.0, 27.0, 0.0)
    };
    assert!(!kept(&flat, low, &f));
}

#[test]
fn median_lower_takes_the_lower_middle_value() {
    assert_eq!(median_lower(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.0));
    assert_eq!(median_lower(&mut [5.0, 1.0, 3.0]), Some(3.0));
    assert_eq!(median_lower(&mut []), None);
}

/// `sides_best` compares only the disparities `d + k` (integer `k`, `|k| > 1`) inside the
/// searched range: noise shifted by 3 px, a match at 5.5 with range 4..=6 has nothing to
/// compare (3.5 lies below 4) and is kept; with range 3..=6 it finds 3.5 better.
#[test]
fn both_sides_best_compares_only_disparities_inside_the_range() {
    let (w, h) = (60, 30);
    let mut next = unit_rng(7);
    let l: Vec<f32> = (0..w * h).map(|_| next()).collect();
    let r: Vec<f32> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            l[y * w + (x + 3).min(w - 1)]
        })
        .collect();
    let (l, r) = (Image::new(w, h, l).unwrap(), Image::new(w, h, r).unwrap());
    let f = FilterParams {
        sides_mad: 1.0,
        disc: false,
        zncc_check: false,
        ..FilterParams::default()
    };
    for x in [20.0f32, 25.0, 30.0] {
        let m = [match_at(x, 15.0, 5.5)];
        assert!(edge_filters(&l, &r, &m, &f, (4, 6)).unwrap().0[0], "{x}");
        assert!(!edge_filters(&l, &r, &m, &f, (3, 6)).unwrap().0[0], "{x}");
    }
}

/// The discontinuity filter drops both matches of a pair within +- disc_dx columns and
/// +- disc_dy rows whose disparities differ by more than (not exactly) disc_tol.
#[test]
fn discontinuity_filter_neighbourhood_and_tolerance() {
    let img = Image::filled(40, 30, 0.5).unwrap();
    let f = FilterParams {
        sides: false,
        zncc_check: false,
        ..FilterParams::default()
    };
    let base = match_at(20.0, 15.0, 5.0);
    for (x, y, d, expect) in [
        (26.0, 15.0, 6.0, [true, true]), // a difference of exactly disc_tol
        (26.0, 15.0, 6.5, [false, false]),
        (14.0, 15.0, 6.5, [false, false]),
        (27.0, 15.0, 7.0, [true, true]), // disc_dx + 1 columns away
        (13.0, 15.0, 7.0, [true, true]),
        (20.0, 17.0, 6.5, [false, false]),
        (20.0, 13.0, 6.5, [false, false]),
        (20.0, 18.0, 6.5, [true, true]), // disc_dy + 1 rows away
        (20.0, 12.0, 6.5, [true, true]),
    ] {
        let ms = [base, match_at(x, y, d)];
        let (keep, counts) = edge_filters(&img, &img, &ms, &f, (0, 16)).unwrap();
        assert_eq!(keep, expect, "({x}, {y}) d {d}");
        assert_eq!(counts.disc, expect.iter().filter(|&&k| k).count());
    }
}

/// Window sizes near i32::MAX (the binding takes any i32 >= 0) act as the whole image: a
/// `disc_dx` / `disc_dy` of i32::MAX wrapped `x + disc_dx` negative (every match kept; a panic
/// in a debug build), and a `sides_gap` near it wrapped the half-window's outer column
/// negative and indexed far outside the image (a panic, `_core.mcgm_match`'s "internal error").
#[test]
fn huge_filter_windows_are_the_whole_image() {
    let img = Image::filled(40, 30, 0.5).unwrap();
    let f = FilterParams {
        sides: false,
        zncc_check: false,
        ..FilterParams::default()
    };
    let base = match_at(20.0, 15.0, 5.0);
    for (dx, dy, x, y, expect) in [
        (i32::MAX, 2, 2.0, 15.0, [false, false]),
        (40, 2, 2.0, 15.0, [false, false]),
        (i32::MAX, 2, 2.0, 16.0, [false, false]),
        (i32::MAX, 0, 2.0, 16.0, [true, true]),
        (6, i32::MAX, 20.0, 1.0, [false, false]),
        (6, 30, 20.0, 1.0, [false, false]),
        (i32::MAX, i32::MAX, 38.0, 28.0, [false, false]),
        (0, i32::MAX, 21.0, 28.0, [true, true]),
    ] {
        let g = FilterParams {
            disc_dx: dx,
            disc_dy: dy,
            ..f
        };
        let ms = [base, match_at(x, y, 7.0)];
        let (keep, counts) = edge_filters(&img, &img, &ms, &g, (0, 16)).unwrap();
        assert_eq!(keep, expect, "disc_dx {dx} disc_dy {dy}: ({x}, {y})");
        assert_eq!(counts.disc, expect.iter().filter(|&&k| k).count());
    }
    // No half-window of `sides_gap + 1 ..= sides_gap + sides_width` columns fits: nothing kept.
    let (l, r) = (blobs(64, 40, 0.0), blobs(64, 40, 3.0));
    let ms: Vec<Match> = (0..64).map(|x| match_at(x as f32, 20.0, 0.0)).collect();
    let sides = FilterParams {
        sides_mad: 1.0,
        sides_best: false,
        disc: false,
        zncc_check: false,
        ..FilterParams::default()
    };
    for gap in [i32::MAX, i32::MAX - 5, i32::MAX - 6, 1 << 30, 64] {
        let g = FilterParams {
            sides_gap: gap,
            ..sides
        };
        let (keep, _) = edge_filters(&l, &r, &ms, &g, (0, 16)).unwrap();
        assert!(keep.iter().all(|&k| !k), "sides_gap {gap}");
    }
    // ... and the limit itself still keeps what fits.
    let (keep, _) = edge_filters(&l, &r, &ms, &sides, (0, 16)).unwrap();
    assert!(keep.iter().any(|&k| k));
}

/// `ght_min_score` is a GHT score's threshold, [0, 1]: above 1 no candidate passed and the
/// matcher gave 0 matches without a word; 1 itself is a threshold some pair can meet.
#[test]
fn ght_min_score_above_1_is_refused() {
    let (l, r) = (blobs(90, 60, 0.0), blobs(90, 60, 3.0));
    let with = |score: f32| McgmParams {
        cand: graph::CandParams {
            ght_min_score: score,
            ..McgmParams::default().cand
        },
        ..McgmParams::default()
    };
    for bad in [1.01f32, 2.0, 40.0] {
        let err = mcgm_match(&l, &r, &with(bad)).unwrap_err();
        assert!(
            matches!(&err, CoreError::InvalidParameter { name, .. } if *name == "ght_min_score"),
            "{bad}: {err}"
        );
    }
    assert!(mcgm_match(&l, &r, &with(1.0)).is_ok());
}

/// `horiz_skip_deg` is an angle to the horizontal, [0, 90]: beyond 90 its sine came round
/// again (180 skipped nothing, as 0; 2**32 and 1e30 whatever their sine gave).
#[test]
fn horiz_skip_deg_beyond_90_is_refused() {
    let (l, r) = (blobs(90, 60, 0.0), blobs(90, 60, 3.0));
    for bad in [90.5f32, 180.0, 4_294_967_296.0, 1e30] {
        let p = McgmParams {
            horiz_skip_deg: bad,
            ..McgmParams::default()
        };
        let err = mcgm_match(&l, &r, &p).unwrap_err();
        assert!(
            matches!(&err, CoreError::InvalidParameter { name, .. } if *name == "horiz_skip_deg"),
            "{bad}: {err}"
        );
    }
    // 90 skips every tangent but the exactly vertical ones; 0 skips none.
    let at = |deg: f32| {
        let p = McgmParams {
            horiz_skip_deg: deg,
            ..McgmParams::default()
        };
        mcgm_match(&l, &r, &p).unwrap().n_combined
    };
    let (none, some, all) = (at(0.0), at(20.0), at(90.0));
    assert!(none > some && some > all, "{none} {some} {all}");
}

/// A segment's disparity window: the lower median of the prior at its pixels' centres in
/// full-resolution pixels (`2 x + 1` at half resolution), divided by the scale, floor / ceil
/// of `+- width`, clipped to the channel's range.
#[test]
fn windows_equal_the_lower_median_of_the_prior_at_pixel_centres() {
    let p = McgmParams::default();
    let half = blobs(60, 45, 0.0);
    let cc = channel_curves(&half, 2.0, 2, &p).unwrap();
    assert!(cc.curves.segments.len() > 5);
    let (fw, fh) = (120, 90);
    let map: Vec<f32> = (0..fw * fh)
        .map(|i| 20.0 + ((i % fw * 7 + i / fw * 13) % 23) as f32 * 0.37)
        .collect();
    let sp = SpreadPrior::new(&map, fw, fh, 0).unwrap();
    let width = CHANNEL_WIDTH_SIGMAS * 2.0;
    let got = windows(&cc, Some(&sp), fw, width, 0, 40).unwrap();
    let mut n_even = 0;
    for (seg, g) in cc.curves.segments.iter().zip(&got) {
        let mut v: Vec<f32> = seg
            .pixels
            .iter()
            .map(|&i| {
                let (x, y) = (i as usize % 60, i as usize / 60);
                map[(2 * y + 1) * fw + 2 * x + 1] / 2.0
            })
            .collect();
        v.sort_by(f32::total_cmp);
        n_even += usize::from(v.len().is_multiple_of(2));
        let med = v[(v.len() - 1) / 2];
        let want = ((med - width).floor() as i32, (med + width).ceil() as i32);
        assert_eq!(*g, Some(want));
    }
    assert!(n_even > 0);
}

#[test]
fn channel_geometry_and_track_lengths_follow_sigma() {
    let p = McgmParams::default();
    assert_eq!(channel_geometry(4.0, &p), (2.0, 2));
    assert_eq!(channel_geometry(3.9, &p), (3.9, 1));
    // max(min_len 8, ceil(4 sigma)).
    assert_eq!(p.track_params(2.3).min_len, 10);
    assert_eq!(p.track_params(1.0).min_len, 8);
}

/// End to end: the half-resolution channel is a prior only (its full range `0..=ceil(15 / 2)`,
/// its matches at pixel centres `2 y + 0.5`); the next channel's windows come from that prior
/// spread by `ceil(4 * 4)` px; matches of different channels on a row are > fill_radius apart.
#[test]
fn channel_prior_and_combination_follow_the_definitions() {
    let (l, r) = (blobs(200, 150, 0.0), blobs(200, 150, 3.3));
    let p = McgmParams {
        d_max: 15,
        ..McgmParams::default()
    };
    let out = mcgm_match(&l, &r, &p).unwrap();
    let c0 = &out.channels[0];
    assert_eq!(c0.scale, 2);
    assert!(!c0.windows.is_empty() && c0.windows.iter().all(|w| *w == Some((0, 8))));
    assert!(!c0.matches.is_empty());
    assert!(c0.matches.iter().all(|m| m.yl.fract() == 0.5));
    assert!(out.matches.iter().all(|m| m.channel != 0));
    // Channel 1's windows from channel 0's matches.
    let (fw, fh) = (200, 150);
    let mut map = vec![f32::NAN; fw * fh];
    for m in &c0.matches {
        map[m.yl.round() as usize * fw + m.xl.round() as usize] = m.xl - m.xr;
    }
    let sp = SpreadPrior::new(&map, fw, fh, 16).unwrap();
    let cc = &image_curves(&l, &p).unwrap()[1];
    let want = windows(cc, Some(&sp), fw, p.prior_width_sigmas * cc.sigma, 0, 15).unwrap();
    assert_eq!(out.channels[1].windows, want);
    // Combination: no two channels' matches within fill_radius on a row.
    let mut by_row: std::collections::HashMap<i32, Vec<(i32, u8)>> = Default::default();
    for m in &out.matches {
        by_row
            .entry(m.yl.round() as i32)
            .or_default()
            .push((m.xl.round() as i32, m.channel));
    }
    let mut n_mixed = 0;
    for row in by_row.values() {
        for a in row {
            for b in row {
                if a.1 != b.1 {
                    n_mixed += 1;
                    assert!((a.0 - b.0).abs() > p.fill_radius, "{a:?} {b:?}");
                }
            }
        }
    }
    assert!(n_mixed > 0);
}

/// B.4.12: a left curve pixel takes the right segment's crossing on its row nearest to
/// `x - tx`, only within half a channel width (`sqrt 2 sigma`). Right shifted by 2.2 px: with
/// `tx` = 2.2 most pixels find their crossing, with `tx` = 0 none of those 2.2 px away counts.
#[test]
fn decompose_searches_half_a_channel_width_around_the_translation() {
    let p = McgmParams::default();
    let lc = channel_curves(&blobs(100, 80, 0.0), 1.0, 1, &p).unwrap();
    let rc = channel_curves(&blobs(100, 80, 2.2), 1.0, 1, &p).unwrap();
    let half = 0.5 * CHANNEL_WIDTH_SIGMAS;
    for tx in [2.2f32, 0.0] {
        let cands: Vec<Candidate> = (0..lc.curves.segments.len())
            .flat_map(|i| {
                (0..rc.curves.segments.len()).map(move |j| Candidate {
                    left: i as u32,
                    right: j as u32,
                    score: 1.0,
                    tx,
                    ty: 0.0,
                })
            })
            .collect();
        let chosen: Vec<usize> = (0..cands.len()).collect();
        let ms = decompose(&lc, &rc, &cands, &chosen, p.horiz_skip_deg, 2).unwrap();
        assert!(ms.iter().all(|m| m.yl == m.yr && m.channel == 2));
        assert!(
            ms.iter().all(|m| (m.xr - (m.xl - tx)).abs() <= half),
            "tx {tx}"
        );
        if tx > 0.0 {
            let near = ms
                .iter()
                .filter(|m| (m.xl - m.xr - 2.2).abs() < 0.3)
                .count();
            assert!(near > 100, "{near}");
        }
    }
}

/// Crossings of a `w x h` plane: `(x, y, theta)` marked with strength 1, nothing else.
fn crossings_at(w: usize, h: usize, marks: &[(usize, usize, f32)]) -> ZeroCrossings {
    let n = w * h;
    let mut zc = ZeroCrossings {
        width: w,
        height: h,
        mark: vec![0; n],
        xsub: vec![f32::NAN; n],
        strength: vec![0.0; n],
        theta: vec![0.0; n],
    };
    for &(x, y, t) in marks {
        let i = y * w + x;
        zc.mark[i] = ZC_H;
        zc.xsub[i] = x as f32;
        zc.strength[i] = 1.0;
        zc.theta[i] = t;
    }
    zc
}

/// B.4 step 5: a curve continues only to a neighbour whose normal turned by less than
/// `max_turn_deg` (strictly); a 3-px-wide image still has its interior column tracked; a
/// segment's mean normal lies in `[0, 2 pi)` even where `atan2 + 2 pi` rounds up to `2 pi`.
#[test]
fn track_turn_bound_is_strict_narrow_images_track_and_mean_theta_stays_below_tau() {
    use std::f32::consts::TAU;
    let p = tracking::TrackParams {
        high_quantile: 0.0,
        low_ratio: 1.0,
        max_turn_deg: 30.0,
        min_len: 1,
    };
    // A vertical line (normal along +x) in the only interior column of a 3 x 6 image.
    let line: Vec<(usize, usize, f32)> = (1..5).map(|y| (1, y, 0.0)).collect();
    let c = track(&crossings_at(3, 6, &line), &p).unwrap();
    assert_eq!(c.segments.len(), 1);
    assert_eq!(c.segments[0].pixels, vec![4, 7, 10, 13]);
    // The same line with max_turn 0: no turn is below it, every pixel is its own segment.
    let c0 = track(
        &crossings_at(3, 6, &line),
        &tracking::TrackParams {
            max_turn_deg: 0.0,
            ..p
        },
    )
    .unwrap();
    assert_eq!(c0.segments.len(), 4);
    assert!(c0.segments.iter().all(|s| s.pixels.len() == 1));
    // Normals just below 2 pi and just above 0: the circular mean is a tiny negative angle,
    // whose + 2 pi rounds to 2 pi in f32; the direction is 0.
    let below = f32::from_bits(TAU.to_bits() - 1); // 2 pi - 3.0e-7
    let c = track(&crossings_at(5, 6, &[(2, 2, below), (2, 3, 2.5e-7)]), &p).unwrap();
    assert_eq!(c.segments.len(), 1);
    assert_eq!(c.segments[0].pixels.len(), 2);
    assert_eq!(c.segments[0].mean_theta, 0.0);
}

/// A vertical segment of the pixels `(x, y0..y0 + n)` (normals along +x) in a `w`-wide image.
fn vertical_segment(w: usize, x: usize, y0: usize, n: usize) -> Segment {
    Segment {
        pixels: (y0..y0 + n).map(|y| (y * w + x) as u32).collect(),
        centroid: (x as f32, y0 as f32 + 0.5 * (n - 1) as f32),
        x_min: x as i32,
        x_max: x as i32,
        y_min: y0 as i32,
        y_max: (y0 + n - 1) as i32,
        mean_theta: 0.0,
    }
}

/// B.4.7 bounds: a pair whose length ratio equals `ght_min_score` is scored (its GHT peak can
/// still reach the minimum, and here does: 2 of 4 pixels), and the mean normals must differ by
/// less than `seg_theta_tol_deg` (strictly: with 0 nothing is a candidate).
#[test]
fn candidates_length_ratio_bound_is_inclusive_and_normal_bound_strict() {
    let (w, h) = (20, 8);
    let theta = vec![0.0f32; w * h];
    let left = [vertical_segment(w, 12, 3, 2)];
    let right = [vertical_segment(w, 10, 2, 4)];
    let cp = graph::CandParams {
        seg_theta_tol_deg: 30.0,
        dy_band: 1,
        n_bins: 8,
        vote_bin_tol: 0,
        ght_min_score: 0.5,
        k_cand: 4,
    };
    let rts = [build_rtable(&left[0], &theta, w, cp.n_bins).unwrap()];
    let window = [Some((0, 5))];
    let got = graph::candidates(&left, &rts, &right, &theta, w, h, &window, &cp).unwrap();
    assert_eq!(got.len(), 1);
    assert_eq!((got[0].score, got[0].tx), (0.5, 2.0));
    let strict = graph::CandParams {
        seg_theta_tol_deg: 0.0,
        ..cp
    };
    assert!(
        graph::candidates(&left, &rts, &right, &theta, w, h, &window, &strict)
            .unwrap()
            .is_empty()
    );
}

/// B.4.12's search of the right crossing on one row, on hand-made curves (sigma 1, full
/// resolution): the window starts at `floor(x - tx - half)` (a crossing in that pixel can be
/// within `half`), a crossing exactly `half` away counts, and of two equally near the first
/// (leftmost) is taken.
#[test]
fn decompose_window_bounds_and_ties() {
    let (w, h) = (20, 5);
    // Curves whose crossings (x, y, sub-pixel x) all belong to segment 0.
    let curves_of = |marks: &[(usize, usize, f32)]| -> ChannelCurves {
        let mut zc = crossings_at(
            w,
            h,
            &marks.iter().map(|m| (m.0, m.1, 0.0)).collect::<Vec<_>>(),
        );
        let mut labels = vec![-1; w * h];
        for &(x, y, xs) in marks {
            zc.xsub[y * w + x] = xs;
            labels[y * w + x] = 0;
        }
        ChannelCurves {
            sigma: 1.0,
            scale: 1,
            width: w,
            height: h,
            log: vec![0.0; w * h],
            zc,
            curves: tracking::Curves {
                segments: vec![vertical_segment(w, marks[0].0, marks[0].1, 1)],
                labels,
                t_high: 1.0,
                t_low: 1.0,
            },
            rtables: Vec::new(),
        }
    };
    let left = curves_of(&[(10, 2, 10.0)]);
    let half = 0.5 * CHANNEL_WIDTH_SIGMAS;
    let xr = |right: &[(usize, usize, f32)], tx: f32| -> Vec<f32> {
        let c = Candidate {
            left: 0,
            right: 0,
            score: 1.0,
            tx,
            ty: 0.0,
        };
        let ms = decompose(&left, &curves_of(right), &[c], &[0], 20.0, 0).unwrap();
        ms.iter().map(|m| m.xr).collect()
    };
    // Target 8: the window starts at floor(8 - 1.41) = 6, whose crossing 6.6 is 1.4 away.
    assert_eq!(xr(&[(6, 2, 6.6)], 2.0), [6.6]);
    // Two crossings 0.5 either side of the target: the left one.
    assert_eq!(xr(&[(7, 2, 7.5), (8, 2, 8.5)], 2.0), [7.5]);
    // Target 0, a crossing exactly half a channel width away.
    assert_eq!(xr(&[(1, 2, half)], 10.0), [half]);
}

/// A half-resolution channel searches `floor(d_min / 2)..=ceil(d_max / 2)` channel pixels: an
/// odd `d_min` rounds down, not up (the first channel has no prior: every window is that range).
#[test]
fn half_resolution_range_rounds_outward() {
    let img = blobs(60, 40, 0.0);
    let p = McgmParams {
        sigmas: vec![4.0],
        d_min: 3,
        d_max: 9,
        ..McgmParams::default()
    };
    let out = mcgm_match(&img, &blobs(60, 40, 4.0), &p).unwrap();
    let ch = &out.channels[0];
    assert_eq!(ch.scale, 2);
    assert!(!ch.windows.is_empty());
    assert!(ch.windows.iter().all(|&w| w == Some((1, 5))));
}

/// The discontinuity filter drops a match whose rounded left pixel lies outside the image (it
/// has no neighbourhood to check), after the both-sides step counted it.
#[test]
fn discontinuity_filter_drops_matches_outside_the_image() {
    let img = Image::filled(40, 30, 0.5).unwrap();
    let f = FilterParams {
        sides: false,
        zncc_check: false,
        ..FilterParams::default()
    };
    let ms = [
        match_at(-0.6, 15.0, 5.0),
        match_at(39.6, 15.0, 5.0),
        match_at(20.0, 29.5, 5.0),
        match_at(20.0, 15.0, 5.0),
    ];
    let (keep, counts) = edge_filters(&img, &img, &ms, &f, (0, 16)).unwrap();
    assert_eq!(keep, [false, false, false, true]);
    assert_eq!((counts.sides, counts.disc), (4, 1));
}

/// Run by [`association_weights_too_large_to_allocate_are_an_error`] in a child process: 3000
/// candidates of one left segment (each inhibits the 2999 others: 9 M weights, 8 bytes each
/// in the rows, whose capacities take 32 KiB a row) under an address-space limit of the rows
/// and 54 MiB more than is mapped. The matrix's indices (36 MB) fit; its data does not.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of association_weights_too_large_to_allocate_are_an_error"]
fn association_weights_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let n = 3000u32;
    let cands: Vec<graph::Candidate> = (0..n)
        .map(|r| graph::Candidate {
            left: 0,
            right: r,
            score: 1.0,
            tx: 0.0,
            ty: 0.0,
        })
        .collect();
    let left = [Segment {
        pixels: vec![0],
        centroid: (0.0, 0.0),
        x_min: 0,
        x_max: 0,
        y_min: 0,
        y_max: 0,
        mean_theta: 0.0,
    }];
    let sp = McgmParams::default().solver;
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(
        crate::segment::tests::vm_size() + n as usize * (32 << 10) + (54 << 20),
    );
    match graph::association_weights(&cands, &left, &[Vec::new()], n as usize, &sp) {
        Ok(csr) => println!("child: weights {}", csr.nnz()),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn association_weights_too_large_to_allocate_are_an_error() {
    // The matrix's indices and data grew by push (8 bytes a weight, the largest N-sized
    // tables of the channel): a failed allocation aborted the process (SIGABRT) instead of
    // returning OutOfMemory.
    let stdout = crate::segment::tests::run_oom_child(
        "matching::mcgm::tests::association_weights_under_a_memory_limit",
    );
    let want = "child: error: out of memory: the MCGM matcher's association weights needs \
                34.32 MiB (35988000 bytes)";
    assert!(stdout.contains(want), "{want} not in {stdout}");
}

/// The LoG as computed before the row pass copied the row (every padded pixel by `reflect`)
/// and the column pass read row slices: the same operations in the same order, scalar.
fn log_filter_per_pixel_reflect(img: &Image, sigma: f32) -> Vec<f32> {
    use super::log::reflect;
    let (w, h) = img.size();
    let (g, a) = log_kernels(sigma).unwrap();
    let r = g.len() / 2;
    let (mut hg, mut ha) = (vec![0.0f32; w * h], vec![0.0f32; w * h]);
    for y in 0..h {
        let src = &img.data[y * w..(y + 1) * w];
        let p: Vec<f32> = (-(r as isize)..(w + r) as isize)
            .map(|i| src[reflect(i, w)])
            .collect();
        for x in 0..w {
            let (mut og, mut oa) = (g[r] * p[r + x], a[r] * p[r + x]);
            for j in 1..=r {
                let s = p[r - j + x] + p[r + j + x];
                og += g[r + j] * s;
                oa += a[r + j] * s;
            }
            hg[y * w + x] = og;
            ha[y * w + x] = oa;
        }
    }
    let mut out = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut o = g[r] * ha[y * w + x] + a[r] * hg[y * w + x];
            for j in 1..=r as isize {
                let lo = reflect(y as isize - j, h) * w + x;
                let hi = reflect(y as isize + j, h) * w + x;
                o += g[r + j as usize] * (ha[lo] + ha[hi]);
                o += a[r + j as usize] * (hg[lo] + hg[hi]);
            }
            out[y * w + x] = o;
        }
    }
    out
}

#[test]
fn log_filter_is_bit_identical_to_per_pixel_reflect_padding_on_tiny_and_odd_images() {
    // The scenes never reach these: 1-pixel images, rows and columns shorter than the kernel
    // radius (borders folded several times), odd widths, widths not a multiple of the vector.
    for &(w, h) in &[
        (1usize, 1usize),
        (1, 6),
        (6, 1),
        (2, 2),
        (2, 9),
        (3, 5),
        (5, 3),
        (7, 1),
        (13, 2),
        (17, 11),
        (33, 7),
    ] {
        let mut rnd = unit_rng(w as u64 * 131 + h as u64);
        let img = Image::new(w, h, (0..w * h).map(|_| 255.0 * rnd()).collect()).unwrap();
        for sigma in [0.1f32, 0.7, 1.0, 2.0, 3.3] {
            let got = log_filter(&img, sigma).unwrap();
            let want = log_filter_per_pixel_reflect(&img, sigma);
            for (i, (g, v)) in got.iter().zip(&want).enumerate() {
                assert_eq!(g.to_bits(), v.to_bits(), "{w}x{h} sigma {sigma} pixel {i}");
            }
        }
    }
}

/// [`half_mad`] as before its differences were stored: each difference computed in both
/// passes.
#[allow(clippy::too_many_arguments)]
fn half_mad_twice(
    left: &Image,
    right: &Image,
    (xi, yl, yr, d): (i32, i32, i32, f32),
    side: i32,
    (inner, outer, hh): (i32, i32, i32),
    mean_free: bool,
) -> f32 {
    let n = ((outer - inner + 1) * (2 * hh + 1)) as f32;
    let diff = |ly: usize, ry: usize, k: i32| {
        let x = xi + side * k;
        let pos = x as f32 - d;
        let x0 = (pos.floor() as usize).min(right.width - 1);
        let x1 = (x0 + 1).min(right.width - 1);
        let f = pos - x0 as f32;
        let row = &right.data[ry * right.width..(ry + 1) * right.width];
        left.at(x as usize, ly) - (row[x0] + f * (row[x1] - row[x0]))
    };
    let mut offset = 0.0f32;
    if mean_free {
        for dy in -hh..=hh {
            for k in inner..=outer {
                offset += diff((yl + dy) as usize, (yr + dy) as usize, k);
            }
        }
        offset /= n;
    }
    let mut sad = 0.0f32;
    for dy in -hh..=hh {
        for k in inner..=outer {
            sad += (diff((yl + dy) as usize, (yr + dy) as usize, k) - offset).abs();
        }
    }
    sad / n
}

#[test]
fn half_mad_with_stored_differences_is_bit_identical_and_keeps_nothing_stale() {
    // One scratch buffer through windows of every width and height, largest first then small
    // (a stale difference of the previous window would change the sums), windows touching the
    // image's edges, disparities putting the right samples on the last column (clamped).
    let (w, h) = (40usize, 12usize);
    let mut rnd = unit_rng(11);
    let l = Image::new(w, h, (0..w * h).map(|_| 255.0 * rnd()).collect()).unwrap();
    let r = Image::new(w, h, (0..w * h).map(|_| 255.0 * rnd()).collect()).unwrap();
    let mut diffs = vec![f32::NAN; 3];
    let mut checked = 0;
    for hh in [5, 0, 2, 1] {
        for width in [16, 1, 7, 2] {
            for gap in [0, 2] {
                let (inner, outer) = (gap + 1, gap + width);
                for side in [-1, 1] {
                    for (xi, d) in [
                        (outer, 0.0f32),
                        (outer, 0.25),
                        (w as i32 - 1 - outer, 0.0),
                        (w as i32 - 1 - outer, -0.75),
                        (20, 3.6),
                        (outer + 2, 1.999),
                    ] {
                        let (yl, yr) = (hh, h as i32 - 1 - hh);
                        for mean_free in [false, true] {
                            let at = (xi, yl, yr, d);
                            let geom = (inner, outer, hh);
                            let got =
                                half_mad(&l, &r, xi, yl, yr, d, side, geom, mean_free, &mut diffs);
                            let want = half_mad_twice(&l, &r, at, side, geom, mean_free);
                            assert_eq!(got.to_bits(), want.to_bits(), "{at:?} {geom:?} {side}");
                            checked += 1;
                        }
                    }
                }
            }
        }
    }
    assert_eq!(checked, 4 * 4 * 2 * 2 * 6 * 2);
}

/// [`SidesBound::open_lanes`] as before its sums were stored: each column's interpolated sums
/// computed in both passes, the bits set one compare at a time.
fn open_lanes_twice(
    b: &SidesBound,
    vs: (&[f32], &[f32]),
    j0: usize,
    mean_free: bool,
    open_below: f32,
) -> u32 {
    let acc = bound_sums_twice(b, vs, j0, mean_free);
    acc.iter().enumerate().fold(0u32, |bits, (t, &a)| {
        bits | (u32::from(a / b.n < open_below) << t)
    })
}

/// The bound's sums of the lanes `j0..j0 + 8` as [`open_lanes_twice`] adds them (columns in
/// order, the mean pass first).
fn bound_sums_twice(
    b: &SidesBound,
    (v_top, v_bot): (&[f32], &[f32]),
    j0: usize,
    mean_free: bool,
) -> [f32; 8] {
    let interp = |v: &[f32], o: usize, f: f32| -> [f32; 8] {
        let v = &v[o + j0..o + j0 + 9];
        std::array::from_fn(|t| v[t] + f * (v[t + 1] - v[t]))
    };
    let cols = &b.cols[..b.nc];
    let mut m = [0.0f32; 8];
    if mean_free {
        for &(o, f, _, _) in cols {
            let (t, bt) = (interp(v_top, o, f), interp(v_bot, o, f));
            for q in 0..8 {
                m[q] += t[q] + bt[q];
            }
        }
        for q in &mut m {
            *q = (b.ltot - *q) / b.n;
        }
    }
    let (wt, wb) = b.rows;
    let mut acc = [0.0f32; 8];
    for &(o, f, lt, lb) in cols {
        let (t, bt) = (interp(v_top, o, f), interp(v_bot, o, f));
        for q in 0..8 {
            acc[q] += (lt - t[q] - wt * m[q]).abs() + (lb - bt[q] - wb * m[q]).abs();
        }
    }
    acc
}

#[test]
fn half_sums_planes_give_each_windows_own_sums_bit_for_bit() {
    // The edge filters' column sums of both images against the sums each window makes of its
    // own rows: the bound's column sums (left) and right row sums, and half_better's answers,
    // bit for bit. Grey values of mixed magnitudes and signs (and signed zeros), so that any
    // other order or grouping of the additions would round differently somewhere.
    let (w, h) = (80usize, 23usize);
    let mut st = 0x2545_f491_4f6c_dd1du64;
    let mut grey = || {
        st ^= st << 13;
        st ^= st >> 7;
        st ^= st << 17;
        let m = [1e-3f32, 0.37, 1.0, 97.0, 1e3][(st % 5) as usize];
        match st >> 61 {
            0 => -0.0,
            1 => 0.0,
            _ => m * ((st >> 40) as f32 / (1u64 << 24) as f32 - 0.3),
        }
    };
    let l = Image::new(w, h, (0..w * h).map(|_| grey()).collect()).unwrap();
    let r = Image::new(w, h, (0..w * h).map(|_| grey()).collect()).unwrap();
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let mut checked = 0;
    for hh in [0, 1, 3, 5] {
        let planes = [
            HalfSums::new(&l, hh).unwrap(),
            HalfSums::new(&r, hh).unwrap(),
        ];
        let mut with = SidesScratch {
            scale: 1e3,
            sums: Some(Arc::new(planes)),
            ..SidesScratch::default()
        };
        let mut own = SidesScratch {
            scale: 1e3,
            ..SidesScratch::default()
        };
        for (inner, outer) in [(1, 6), (2, 2), (1, 16)] {
            let geom = (inner, outer, hh);
            // First and last rows a window fits on, rows between; straddling weights too.
            for (yl, yr) in [(hh, hh), (h as i32 - 1 - hh, h as i32 - 1 - hh), (11, 12)] {
                for (xi, d) in [(38, 5.3f32), (40, 11.0), (30, 2e-5)] {
                    let at = (xi, yl, yr, d);
                    for side in [-1, 1] {
                        let ks = (-6, 9);
                        let (base, b_range, (k_lo, k_hi)) = window_bases(at, side, geom, ks, w);
                        assert!(k_hi >= k_lo, "{geom:?} {at:?} {side}");
                        let nk = (k_hi - k_lo + 1) as usize;
                        let kb = (k_hi, nk);
                        let bb = (&base, b_range);
                        let a = SidesBound::new(&l, &r, at, side, geom, kb, bb, &mut with);
                        let b = SidesBound::new(&l, &r, at, side, geom, kb, bb, &mut own);
                        let what = format!("hh {hh} {geom:?} {at:?} side {side}");
                        for (ca, cb) in a.cols.iter().zip(&b.cols) {
                            assert_eq!(ca.0, cb.0, "{what}");
                            assert_eq!(
                                bits(&[ca.1, ca.2, ca.3]),
                                bits(&[cb.1, cb.2, cb.3]),
                                "{what}"
                            );
                        }
                        assert_eq!(a.ltot.to_bits(), b.ltot.to_bits(), "{what}");
                        assert_eq!(bits(&with.rows.v_top), bits(&own.rows.v_top), "{what}");
                        assert_eq!(bits(&with.rows.v_bot), bits(&own.rows.v_bot), "{what}");
                        for mean_free in [false, true] {
                            for here in [0.0f32, 0.5, 5.0, 50.0, f32::INFINITY] {
                                let args = (at, side, geom, mean_free, ks, (here, 0.0));
                                let run = |s: &mut SidesScratch| {
                                    let (at, side, geom, mean_free, ks, lim) = args;
                                    half_better(&l, &r, at, side, geom, mean_free, ks, lim, s)
                                };
                                assert_eq!(run(&mut with), run(&mut own), "{what} {here}");
                            }
                        }
                        checked += 1;
                    }
                }
            }
        }
    }
    assert_eq!(checked, 4 * 3 * 3 * 3 * 2);
}

#[test]
fn open_lanes_with_stored_sums_is_bit_identical_and_keeps_nothing_stale() {
    // Every block of lanes (the last one partial: lane counts not a multiple of 8), windows of
    // 16 columns then 1 (a stale column sum of the wider window would enter the narrow one's),
    // thresholds around each lane's bound so that both bit values occur.
    let (w, h) = (96usize, 16usize);
    let (l, r) = (blobs(w, h, 0.0), blobs(w, h, 5.3));
    let mut scratch = SidesScratch {
        scale: 1.0,
        ..SidesScratch::default()
    };
    for e in scratch.tb.iter_mut() {
        *e = ([f32::NAN; 8], [f32::NAN; 8]);
    }
    let (mut ones, mut zeros) = (0u32, 0u32);
    // Windows whose columns share one interpolation weight (half_better then sums every lane
    // at once from the window's interpolated sums) and windows whose `x - d` straddles 64,
    // where the weight's rounding differs between columns (each column interpolated on its
    // own, block by block).
    let mut shared = [0u32; 2];
    for (geom, at) in [(1, 16, 3), (1, 1, 0), (3, 9, 2), (1, 2, 1)]
        .into_iter()
        .flat_map(|g| [(g, (45, 8, 8, 5.3f32)), (g, (63, 8, 8, 2e-5f32))])
    {
        for side in [-1, 1] {
            for ks in [(-7, 40), (-3, 13), (-2, 6)] {
                let (base, b_range, (k_lo, k_hi)) = window_bases(at, side, geom, ks, w);
                assert!(k_hi >= k_lo, "{geom:?} {side} {ks:?}");
                let nk = (k_hi - k_lo + 1) as usize;
                let bound = SidesBound::new(
                    &l,
                    &r,
                    at,
                    side,
                    geom,
                    (k_hi, nk),
                    (&base, b_range),
                    &mut scratch,
                );
                shared[usize::from(bound.shared_weight)] += 1;
                for mean_free in [false, true] {
                    if bound.shared_weight {
                        bound.lane_sums(&mut scratch.rows, nk.div_ceil(8) * 8, mean_free);
                    }
                    for j0 in (0..nk).step_by(8) {
                        if bound.shared_weight {
                            // The sums themselves, bit for bit (the thresholds below see a
                            // change of order or of a term only where it crosses one).
                            let vs = (&scratch.rows.v_top[..], &scratch.rows.v_bot[..]);
                            let want = bound_sums_twice(&bound, vs, j0, mean_free);
                            for (t, a) in want.iter().enumerate().take(nk - j0) {
                                assert_eq!(
                                    scratch.rows.lane_acc[j0 + t].to_bits(),
                                    a.to_bits(),
                                    "{geom:?} {side} {ks:?} lane {} {mean_free}",
                                    j0 + t
                                );
                            }
                        }
                        for open_below in [0.0f32, 0.02, 0.05, 0.1, 0.2, f32::INFINITY] {
                            let vs = (&scratch.rows.v_top[..], &scratch.rows.v_bot[..]);
                            let want = open_lanes_twice(&bound, vs, j0, mean_free, open_below);
                            let got = bound.open_lanes(
                                &scratch.rows,
                                &mut scratch.tb,
                                j0,
                                mean_free,
                                open_below,
                            );
                            assert_eq!(got, want, "{geom:?} {side} {ks:?} {j0} {mean_free}");
                            if bound.shared_weight {
                                // half_better's path: every lane's sums at once, then a block.
                                let mut acc = [0.0f32; 8];
                                acc.copy_from_slice(&scratch.rows.lane_acc[j0..j0 + 8]);
                                let all = bound.lane_bits(&acc, open_below);
                                assert_eq!(all, want, "{geom:?} {side} {ks:?} {j0} {mean_free}");
                            }
                            ones += got.count_ones();
                            zeros += got.count_zeros();
                        }
                    }
                }
            }
        }
    }
    assert!(ones > 100 && zeros > 100, "{ones} {zeros}");
    assert!(shared[0] >= 6 && shared[1] >= 24, "{shared:?}");
}

/// Run by [`an_rtable_too_large_to_allocate_is_an_error`] in a child process: one segment of
/// 2^21 pixels under an address-space limit of 24 MiB more than is mapped: its orientation
/// bins (16 MiB) fit, its vectors (16 MiB more) do not.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of an_rtable_too_large_to_allocate_is_an_error"]
fn rtable_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let n = 1u32 << 21;
    let seg = Segment {
        pixels: (0..n).collect(),
        centroid: (1024.0, 512.0),
        x_min: 0,
        x_max: 2047,
        y_min: 0,
        y_max: 1023,
        mean_theta: 0.0,
    };
    let theta = vec![1.0f32; n as usize];
    crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (24 << 20));
    match build_rtable(&seg, &theta, 2048, 16) {
        Ok(rt) => println!("child: {} entries", rt.px.len()),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn an_rtable_too_large_to_allocate_is_an_error() {
    // build_rtable allocated its bins, vectors and pixels (24 bytes a segment pixel) with
    // collect/vec!: a failed allocation aborted the process (SIGABRT) instead of returning
    // OutOfMemory.
    let stdout =
        crate::segment::tests::run_oom_child("matching::mcgm::tests::rtable_under_a_memory_limit");
    let want = "child: error: out of memory: an R-table of the MCGM matcher needs 16.00 MiB \
                (16777216 bytes)";
    assert!(stdout.contains(want), "{want} not in {stdout}");
}

/// Run by [`graph_buffers_too_large_to_allocate_are_an_error`] in a child process, one case
/// (`SV_MCGM_OOM_CASE`) under an address-space limit of 64 MiB more than is mapped: a buffer
/// of the candidate search or the graphs that grows with the image or the segments, 256-384
/// MiB each.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of graph_buffers_too_large_to_allocate_are_an_error"]
fn graph_buffers_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let seg = |pixels: Vec<u32>, c: (f32, f32)| Segment {
        pixels,
        centroid: c,
        x_min: 0,
        x_max: 0,
        y_min: 0,
        y_max: 0,
        mean_theta: 0.0,
    };
    let case = std::env::var("SV_MCGM_OOM_CASE").unwrap();
    let cp = McgmParams::default().cand;
    let sp = McgmParams::default().solver;
    // Inputs built before the limit: 2^23 pixels of one segment (32 MiB), two far centroids.
    let long = [seg(vec![0; 1 << 23], (0.0, 0.0))];
    let far = [seg(vec![0], (0.0, 0.0)), seg(vec![0], (8191.0, 8191.0))];
    let rt = RTable {
        offsets: vec![0, 2],
        vecs: vec![(0.0, 0.0); 2],
        px: vec![(0, 0), (0, 1 << 26)],
    };
    let cand = [graph::Candidate {
        left: 0,
        right: 0,
        score: 1.0,
        tx: 0.0,
        ty: 0.0,
    }];
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (64 << 20));
    let r = match case.as_str() {
        // Per row of the image (24 bytes a row: 2^24 rows).
        "rows" => graph::candidates(&[], &[], &[], &[0.0], 1, 1 << 24, &[], &cp).map(|c| c.len()),
        // 12 bytes a pixel of a right segment.
        "voters" => voters(&long[0].pixels, &[0.0], 1, 36).map(|v| v.len()),
        // 4 bytes a row the R-table spans.
        "row_index" => RowIndex::new(&rt).map(|_| 1),
        // 4 bytes a grid cell: 8192 x 8192 cells of 1 px (r_max 4).
        "grid" => graph::knn_graph(&far, 1, 4.0).map(|a| a.len()),
        // 24 bytes a right segment (2^24).
        "by_right" => {
            graph::association_weights(&cand, &long, &[Vec::new()], 1 << 24, &sp).map(|c| c.nnz())
        }
        other => panic!("no case {other}"),
    };
    match r {
        Ok(n) => println!("child: {case} {n}"),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn graph_buffers_too_large_to_allocate_are_an_error() {
    // The right segments' row lists, their voters, a left segment's row index, the k-NN grid
    // and the candidates per segment were allocated with vec!/collect/push: a failed
    // allocation aborted the process (SIGABRT) instead of returning OutOfMemory.
    for (case, want) in [
        (
            "rows",
            "the MCGM matcher's right segments by row needs 384.00 MiB (402653184 bytes)",
        ),
        (
            "voters",
            "the MCGM matcher's GHT voters needs 96.00 MiB (100663296 bytes)",
        ),
        (
            "row_index",
            "an R-table's row index of the MCGM matcher needs 256.00 MiB (268435464 bytes)",
        ),
        (
            "grid",
            "the MCGM matcher's centroid grid needs 256.00 MiB (268435460 bytes)",
        ),
        (
            "by_right",
            "the MCGM matcher's candidates per segment needs 384.00 MiB (402653184 bytes)",
        ),
    ] {
        let stdout = crate::segment::tests::run_oom_child_with(
            "matching::mcgm::tests::graph_buffers_under_a_memory_limit",
            Some(("SV_MCGM_OOM_CASE", case)),
        );
        let want = format!("child: error: out of memory: {want}");
        assert!(stdout.contains(&want), "{case}: {want} not in {stdout}");
    }
}

/// Run by [`segment_lists_too_large_to_allocate_are_an_error`] in a child process, one case
/// (`SV_MCGM_OOM_CASE`) under an address-space limit a little above what is mapped: a list kept
/// per segment, per candidate or per chosen pair whose length grows with a curve or with the
/// segments, larger than the room left.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of segment_lists_too_large_to_allocate_are_an_error"]
fn segment_lists_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let seg = |pixels: Vec<u32>| Segment {
        pixels,
        centroid: (0.0, 0.0),
        x_min: 0,
        x_max: 0,
        y_min: 0,
        y_max: 0,
        mean_theta: 0.0,
    };
    let case = std::env::var("SV_MCGM_OOM_CASE").unwrap();
    let p = McgmParams::default();
    let limit = |extra: usize| {
        rayon::join(|| (), || ()); // the pool's thread started before the limit
        crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + extra);
    };
    let r = match case.as_str() {
        // 2^20 candidates of one segment pair: each one's row lists the others twice (16 MiB);
        // the rows' list (24 MiB) and the candidates per segment (8 MiB) fit, a few rows do not.
        "weights_row" => {
            let cand = graph::Candidate {
                left: 0,
                right: 0,
                score: 1.0,
                tx: 0.0,
                ty: 0.0,
            };
            let cands = vec![cand; 1 << 20];
            let left = [seg(vec![0])];
            limit(64 << 20);
            graph::association_weights(&cands, &left, &[Vec::new()], 1, &p.solver).map(|c| c.nnz())
        }
        // 2^20 segments at one centroid: the adjacency, centroids, nearest lists and grid
        // (60 bytes a segment) fit, the points within r_max of one (8 bytes each) do not.
        "nearest" => {
            let segs: Vec<Segment> = (0..1 << 20).map(|_| seg(vec![0])).collect();
            limit((60 << 20) + (2 << 20));
            graph::knn_graph(&segs, 1, 4.0).map(|a| a.len())
        }
        // A segment of 2^23 pixels: its prior values (32 MiB) do not fit in 16 MiB.
        "windows" => {
            let mut cc = channel_curves(&blobs(60, 45, 0.0), 2.0, 1, &p).unwrap();
            cc.curves.segments.push(seg(vec![0; 1 << 23]));
            let map = vec![20.0f32; 60 * 45];
            let sp = SpreadPrior::new(&map, 60, 45, 0).unwrap();
            limit(16 << 20);
            windows(&cc, Some(&sp), 60, 4.0, 0, 40).map(|w| w.len())
        }
        // A chosen pair whose left segment lists one matching pixel 2^20 times: its matches
        // (24 MiB) do not fit in 16 MiB.
        "decompose" => {
            let mut l = channel_curves(&blobs(60, 45, 0.0), 2.0, 1, &p).unwrap();
            let mut r = l.clone();
            l.curves.segments = vec![seg(vec![0; 1 << 20])];
            (l.zc.theta[0], l.zc.xsub[0]) = (0.0, 0.0);
            (r.curves.labels[0], r.zc.xsub[0]) = (0, 0.0);
            let cand = graph::Candidate {
                left: 0,
                right: 0,
                score: 1.0,
                tx: 0.0,
                ty: 0.0,
            };
            limit(16 << 20);
            decompose(&l, &r, &[cand], &[0], p.horiz_skip_deg, 0).map(|m| m.len())
        }
        other => panic!("no case {other}"),
    };
    match r {
        Ok(n) => println!("child: {case} {n}"),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn segment_lists_too_large_to_allocate_are_an_error() {
    // An association-weight row per candidate, the points near a segment's centroid in the
    // k-NN search, a segment's prior values for its window and a chosen pair's matches were
    // allocated with push/collect/with_capacity: a failed allocation aborted the process
    // (SIGABRT) instead of returning OutOfMemory.
    for (case, want) in [
        (
            "weights_row",
            "the MCGM matcher's association weights needs 8.00 MiB (8388616 bytes)",
        ),
        // (Where `d` fails depends on the room the heap left: its size is not asserted.)
        ("nearest", "the MCGM matcher's nearest segments needs "),
        (
            "windows",
            "the MCGM matcher's disparity windows needs 32.00 MiB (33554432 bytes)",
        ),
        (
            "decompose",
            "the MCGM matcher's curve matches needs 12.00 MiB (12582936 bytes)",
        ),
    ] {
        let stdout = crate::segment::tests::run_oom_child_with(
            "matching::mcgm::tests::segment_lists_under_a_memory_limit",
            Some(("SV_MCGM_OOM_CASE", case)),
        );
        let want = format!("child: error: out of memory: {want}");
        assert!(stdout.contains(&want), "{case}: {want} not in {stdout}");
    }
}

/// Run by [`match_and_row_lists_too_large_to_allocate_are_an_error`] in a child process, one
/// case (`SV_MCGM_OOM_CASE`) under an address-space limit a little above what is mapped: a
/// list that grows with the matches, the right segments or an image row, larger than the room
/// left while the buffers before it fit.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of match_and_row_lists_too_large_to_allocate_are_an_error"]
fn match_and_row_lists_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let case = std::env::var("SV_MCGM_OOM_CASE").unwrap();
    let limit = |extra: usize| {
        rayon::join(|| (), || ()); // the pool's thread started before the limit
        crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + extra);
    };
    let r = match case.as_str() {
        // 2^21 matches (48 MiB, built before the limit): their raster-order keys (16 bytes
        // each, 32 MiB) do not fit in 16 MiB.
        "edge_filters" => {
            let m = Match {
                xl: 1.0,
                yl: 1.0,
                xr: 0.0,
                yr: 1.0,
                score: 1.0,
                channel: 0,
            };
            let ms = vec![m; 1 << 21];
            let img = blobs(16, 16, 0.0);
            let f = McgmParams::default().filters;
            limit(16 << 20);
            edge_filters(&img, &img, &ms, &f, (0, 8)).map(|(k, _)| k.len())
        }
        // The same matches under 36 MiB: their raster-order keys (32 MiB) fit, the index
        // list taken from them (4 bytes a match, 8 MiB) does not. 252451a took it by a
        // `collect` it called in place: (u64, u32) to u32 changes the alignment, so it was a
        // new allocation, unchecked (SIGABRT).
        "edge_filters_order" => {
            let m = Match {
                xl: 1.0,
                yl: 1.0,
                xr: 0.0,
                yr: 1.0,
                score: 1.0,
                channel: 0,
            };
            let ms = vec![m; 1 << 21];
            let img = blobs(16, 16, 0.0);
            let f = McgmParams::default().filters;
            limit(36 << 20);
            edge_filters(&img, &img, &ms, &f, (0, 8)).map(|(k, _)| k.len())
        }
        // 2^20 right segments with no pixels (56 MiB, before the limit): the row lists fit
        // in 16 MiB, their list of voters (24 bytes a segment, 24 MiB) does not.
        "voters_list" => {
            let seg = Segment {
                pixels: Vec::new(),
                centroid: (0.0, 0.0),
                x_min: 0,
                x_max: 0,
                y_min: 0,
                y_max: 0,
                mean_theta: 0.0,
            };
            let right = vec![seg; 1 << 20];
            let cp = McgmParams::default().cand;
            limit(16 << 20);
            graph::candidates(&[], &[], &right, &[0.0], 1, 1, &[], &cp).map(|c| c.len())
        }
        // A 2^22 x 1 image (16 MiB, before the limit): the two row-pass planes (32 MiB) fit
        // in 40 MiB, a row's padded copy (16 MiB more) does not.
        "log_row" => {
            let img = Image {
                width: 1 << 22,
                height: 1,
                data: vec![0.5; 1 << 22],
            };
            limit(40 << 20);
            log_filter(&img, 1.0).map(|l| l.len())
        }
        // A 2^22 x 3 LoG (48 MiB, before the limit): the four maps (156 MiB) fit in 164 MiB,
        // a band's candidate columns (16 MiB more) do not.
        "zc_row" => {
            let (w, h) = (1usize << 22, 3);
            let l: Vec<f32> = (0..w * h)
                .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
                .collect();
            limit(164 << 20);
            zero_crossings(&l, w, h).map(|z| z.mark.len())
        }
        other => panic!("no case {other}"),
    };
    match r {
        Ok(n) => println!("child: {case} {n}"),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn match_and_row_lists_too_large_to_allocate_are_an_error() {
    // edge_filters' per-match lists, the candidate search's list of voters per right segment,
    // the LoG's padded row and the zero crossings' row scratch were vec!/collect/
    // with_capacity: a failed allocation aborted the process (SIGABRT).
    for (case, want) in [
        (
            "edge_filters",
            "the MCGM matcher's edge-filter lists needs 32.00 MiB (33554432 bytes)",
        ),
        (
            "edge_filters_order",
            "the MCGM matcher's edge-filter lists needs 8.00 MiB (8388608 bytes)",
        ),
        (
            "voters_list",
            "the MCGM matcher's voters per right segment needs 24.00 MiB (25165824 bytes)",
        ),
        (
            "log_row",
            "a LoG row of the MCGM matcher needs 16.00 MiB (16777248 bytes)",
        ),
        (
            "zc_row",
            "a zero-crossing row buffer of the MCGM matcher needs 16.00 MiB (16777220 bytes)",
        ),
    ] {
        let stdout = crate::segment::tests::run_oom_child_with(
            "matching::mcgm::tests::match_and_row_lists_under_a_memory_limit",
            Some(("SV_MCGM_OOM_CASE", case)),
        );
        let want = format!("child: error: out of memory: {want}");
        assert!(stdout.contains(&want), "{case}: {want} not in {stdout}");
    }
}

// SAFETY: five f32 and a u8 (and padding): all-zero bits are a valid match.
#[cfg(target_os = "linux")]
unsafe impl crate::alloc::ZeroBits for Match {}

#[cfg(target_os = "linux")]
#[test]
fn edge_filters_refuses_more_matches_than_32_bit_numbers_reach() {
    // It numbers matches in u32 (raster order, the rows' items): past u32::MAX they wrapped
    // (and the binding's mcgm_filter reaches it directly). Refused from the count before any
    // list is built; the matches are a never-touched mapping (96 GiB, reserving nothing).
    let n = MAX_FILTER_MATCHES + 1;
    let Some(mut ms) = crate::segment::tests::Unbacked::<Match>::new(n) else {
        eprintln!("skipped: the system maps no 96 GiB without reserving it");
        return;
    };
    let img = blobs(16, 16, 0.0);
    let f = McgmParams::default().filters;
    assert_eq!(
        edge_filters(&img, &img, ms.slice(), &f, (0, 8)).map(|_| ()),
        Err(CoreError::param(
            "matches",
            "4294967296 matches: at most 4294967295 (they are numbered in 32 bits)"
        ))
    );
}

#[cfg(target_os = "linux")]
#[test]
fn rtables_and_voters_refuse_positions_past_i32() {
    // Both turn a pixel number into an i32 column and row with no check (public: a Rust
    // caller reaches them alone): on the old code pixel 2^31 of a 1-wide image came back on
    // row -2^31, Ok. `theta` is a never-touched mapping (8 GiB, reserving nothing).
    let n = (1usize << 31) + 1;
    let Some(mut theta) = crate::segment::tests::Unbacked::<f32>::new(n) else {
        eprintln!("skipped: the system maps no 8 GiB without reserving it");
        return;
    };
    let theta = theta.slice();
    let seg = Segment {
        pixels: vec![1 << 31],
        centroid: (0.0, 0.0),
        x_min: 0,
        x_max: 0,
        y_min: 0,
        y_max: 0,
        mean_theta: 0.0,
    };
    for (w, h) in [(1, n), (n, 1)] {
        let too_large = Err(CoreError::TooLarge {
            width: w,
            height: h,
            max_pixels: crate::image::MAX_PIXELS,
        });
        assert_eq!(voters(&seg.pixels, theta, w, 36).map(|_| ()), too_large);
        assert_eq!(build_rtable(&seg, theta, w, 36).map(|_| ()), too_large);
    }
    // Within the limit (MAX_SIDE rows): the last pixel on row 2^31 - 2.
    let last = [(1u32 << 31) - 2];
    let v = voters(&last, &theta[..crate::image::MAX_SIDE], 1, 36).unwrap();
    assert_eq!(v, [(0, i32::MAX - 1, 0)]);
}

#[test]
fn log_filter_refuses_a_sigma_outside_its_range() {
    // Unchecked for a Rust caller: inf emptied the kernels and panicked indexing them, 0 and
    // NaN gave a NaN map (Ok), a negative sigma ran on a 3-tap kernel, 1e9 sized the kernels
    // past memory (an abort).
    let img = blobs(20, 10, 0.0);
    for sigma in [f32::INFINITY, 0.0, -1.0, f32::NAN, 1e9, 64.001] {
        assert_eq!(
            log_filter(&img, sigma),
            Err(CoreError::param(
                "sigma",
                format!("must lie in (0, 64] px, got {sigma}")
            )),
            "{sigma}"
        );
    }
    // The ends of the range still filter (a half-resolution channel goes below 0.3).
    for sigma in [0.1, 64.0] {
        assert_eq!(log_filter(&img, sigma).unwrap().len(), 200);
    }
}

#[test]
fn log_kernels_refuse_a_sigma_outside_their_range() {
    // Public, unchecked for a Rust caller: 0 and NaN gave NaN kernels, inf empty ones (a
    // caller indexing the centre tap panicked), 1e9 sized them past memory (an abort).
    for sigma in [f32::INFINITY, 0.0, -1.0, f32::NAN, 1e9, 64.001] {
        assert_eq!(
            log_kernels(sigma),
            Err(CoreError::param(
                "sigma",
                format!("must lie in (0, 64] px, got {sigma}")
            )),
            "{sigma}"
        );
    }
    // The ends of the range: radius ceil(4 sigma), at least 1.
    assert_eq!(log_kernels(0.1).unwrap().0.len(), 3);
    assert_eq!(log_kernels(64.0).unwrap().1.len(), 513);
}

#[test]
fn rtables_and_voters_of_a_zero_width_or_zero_bins_are_errors_or_empty() {
    // `% w` and `% n_bins` divided by zero (a panic) for a segment with pixels.
    let seg = Segment {
        pixels: vec![0, 2],
        centroid: (1.0, 0.0),
        x_min: 0,
        x_max: 2,
        y_min: 0,
        y_max: 0,
        mean_theta: 0.0,
    };
    let theta = [0.0f32, 1.0, 2.0];
    let zero_w = Err(CoreError::param(
        "w",
        "must be at least 1 for 2 pixels, got 0",
    ));
    assert_eq!(voters(&seg.pixels, &theta, 0, 36).map(|_| ()), zero_w);
    assert_eq!(build_rtable(&seg, &theta, 0, 36).map(|_| ()), zero_w);
    let zero_bins = Err(CoreError::param(
        "n_bins",
        "must be at least 1 for 2 pixels, got 0",
    ));
    assert_eq!(voters(&seg.pixels, &theta, 3, 0).map(|_| ()), zero_bins);
    assert_eq!(build_rtable(&seg, &theta, 3, 0).map(|_| ()), zero_bins);
    // No pixel (a 0-wide image has none): empty results, as before.
    let empty = Segment {
        pixels: vec![],
        ..seg.clone()
    };
    assert_eq!(voters(&[], &[], 0, 0).unwrap(), []);
    let rt = build_rtable(&empty, &[], 0, 4).unwrap();
    assert_eq!((rt.offsets, rt.vecs.len(), rt.px.len()), (vec![0; 5], 0, 0));
    assert_eq!(build_rtable(&empty, &[], 0, 0).unwrap().offsets, [0]);
    // Width 1 and a single bin still work: pixel 2 is (0, 2), all in bin 0.
    assert_eq!(
        voters(&seg.pixels, &theta, 1, 1).unwrap(),
        [(0, 0, 0), (0, 2, 0)]
    );
}

#[test]
fn rtables_and_voters_refuse_a_pixel_past_theta() {
    // `theta[i]` of a pixel index past the image panicked (index out of bounds).
    let seg = Segment {
        pixels: vec![0, 5, 2],
        centroid: (1.0, 0.0),
        x_min: 0,
        x_max: 2,
        y_min: 0,
        y_max: 1,
        mean_theta: 0.0,
    };
    let theta = [0.0f32, 1.0, 2.0, 3.0];
    let past = Err(CoreError::param(
        "pixels",
        "index 5 is past the image's 4 pixels (theta)",
    ));
    assert_eq!(voters(&seg.pixels, &theta, 2, 36).map(|_| ()), past);
    assert_eq!(build_rtable(&seg, &theta, 2, 36).map(|_| ()), past);
    // The last pixel (index 3 of 4) is still taken: (1, 1) in bin floor(36 * 3 / 2 pi) = 17.
    assert_eq!(voters(&[3], &theta, 2, 36).unwrap(), [(1, 1, 17)]);
    let last = Segment {
        pixels: vec![3],
        ..seg.clone()
    };
    assert_eq!(build_rtable(&last, &theta, 2, 36).unwrap().px, [(1, 1)]);
}
