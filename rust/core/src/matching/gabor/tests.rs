use super::*;

/// Band-limited random texture (sum of sinusoids) sampled at `x + shift`: an exact sub-pixel shift.
fn texture(w: usize, h: usize, shift: f32, seed: u64) -> Image {
    let mut s = seed;
    let mut rnd = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 33) as f32) / (1u64 << 31) as f32
    };
    let comps: Vec<(f32, f32, f32, f32)> = (0..60)
        .map(|_| {
            let f = 0.03 + 0.3 * rnd();
            let th = std::f32::consts::PI * (rnd() - 0.5);
            (
                f * th.cos(),
                f * th.sin(),
                2.0 * std::f32::consts::PI * rnd(),
                0.5 + rnd(),
            )
        })
        .collect();
    let norm: f32 = comps.iter().map(|c| c.3).sum();
    let data = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 + shift, (i / w) as f32);
            let v: f32 = comps
                .iter()
                .map(|&(u, v, p, a)| a * (2.0 * std::f32::consts::PI * (u * x + v * y) + p).cos())
                .sum();
            0.5 + 0.4 * v / norm * 3.0
        })
        .map(|v: f32| v.clamp(0.0, 1.0))
        .collect();
    Image::new(w, h, data).unwrap()
}

fn median_of_finite(v: &[f32]) -> (f32, usize) {
    let mut f: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
    f.sort_by(|a, b| a.total_cmp(b));
    (f.get(f.len() / 2).copied().unwrap_or(f32::NAN), f.len())
}

#[test]
fn recovers_sign_and_magnitude_of_a_subpixel_shift() {
    for &d in &[2.3f32, 0.6, 7.75] {
        let left = texture(96, 64, 0.0, 7);
        // right(x) = left(x + d)
        let right = texture(96, 64, d, 7);
        let p = GaborParams {
            d_min: 0.0,
            d_max: 16.0,
            ..GaborParams::default()
        };
        let out = gabor_disparity(&left, &right, &p).unwrap();
        let (med, n) = median_of_finite(&out.disparity.data);
        assert!(n > 96 * 64 / 2, "density too low: {n}");
        assert!((med - d).abs() < 0.05, "d = {d}, median = {med}");
    }
}

#[test]
fn negative_range_is_supported() {
    let left = texture(96, 64, 0.0, 3);
    let right = texture(96, 64, -3.4, 3);
    let p = GaborParams {
        d_min: -8.0,
        d_max: 8.0,
        ..GaborParams::default()
    };
    let out = gabor_disparity(&left, &right, &p).unwrap();
    let (med, _) = median_of_finite(&out.disparity.data);
    assert!((med + 3.4).abs() < 0.05, "median = {med}");
}

#[test]
fn textureless_pair_gives_all_nan() {
    let a = Image::filled(64, 48, 0.5);
    let out = gabor_disparity(&a, &a, &GaborParams::default()).unwrap();
    assert!(out.disparity.data.iter().all(|v| v.is_nan()));
    assert!(out.confidence.data.iter().all(|&v| v == 0.0));
}

#[test]
fn bad_parameters_are_errors() {
    let a = Image::filled(16, 16, 0.5);
    let bad = [
        GaborParams {
            d_max: 0.0,
            ..GaborParams::default()
        },
        GaborParams {
            d_min: f32::NAN,
            ..GaborParams::default()
        },
        GaborParams {
            freq: 0.7,
            ..GaborParams::default()
        },
        GaborParams {
            freq: 1e-9, // an envelope of 10^9 px: refused, not allocated
            ..GaborParams::default()
        },
        GaborParams {
            bandwidth_oct: 0.06,
            freq: 0.01,
            ..GaborParams::default()
        },
        GaborParams {
            orientations_deg: vec![],
            ..GaborParams::default()
        },
        GaborParams {
            orientations_deg: vec![90.0],
            ..GaborParams::default()
        },
        GaborParams {
            n_levels: Some(0),
            ..GaborParams::default()
        },
        GaborParams {
            conf_min: 2.0,
            ..GaborParams::default()
        },
        // A range no image has: it allocated 4 bytes per disparity and aborted the process.
        GaborParams {
            d_min: -1e12,
            ..GaborParams::default()
        },
        GaborParams {
            d_max: MAX_RANGE + 1.0,
            ..GaborParams::default()
        },
    ];
    for p in bad {
        assert!(
            matches!(
                gabor_disparity(&a, &a, &p),
                Err(CoreError::InvalidParameter { .. })
            ),
            "{p:?}"
        );
    }
    // Each radius check names its own parameter (both said `research_radius`).
    for (p, name) in [
        (
            GaborParams {
                research_radius: 17,
                ..GaborParams::default()
            },
            "research_radius",
        ),
        (
            GaborParams {
                search_pool_radius: 17,
                ..GaborParams::default()
            },
            "search_pool_radius",
        ),
    ] {
        match gabor_disparity(&a, &a, &p) {
            Err(CoreError::InvalidParameter { name: got, reason }) => {
                assert_eq!(got, name);
                assert_eq!(reason, "must be <= 16 px, got 17");
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    let b = Image::filled(17, 16, 0.5);
    assert!(matches!(
        gabor_disparity(&a, &b, &GaborParams::default()),
        Err(CoreError::SizeMismatch { .. })
    ));
}

#[test]
fn tiny_images_do_not_panic() {
    for (w, h) in [(1, 1), (2, 1), (1, 5), (3, 3), (9, 2)] {
        let a = texture(w, h, 0.0, 1);
        let b = texture(w, h, 0.5, 1);
        let out = gabor_disparity(&a, &b, &GaborParams::default()).unwrap();
        assert_eq!(out.disparity.data.len(), w * h);
    }
}

/// Manual timing probe: `SV_GABOR_TIMING=1 cargo test --release -- --ignored --nocapture probe`.
#[test]
#[ignore]
fn probe_timing() {
    let left = texture(626, 555, 0.0, 5);
    let right = texture(626, 555, 9.5, 5);
    let p = GaborParams {
        d_max: 96.0,
        lr_check: false,
        ..GaborParams::default()
    };
    for _ in 0..3 {
        let t = std::time::Instant::now();
        let _ = gabor_disparity(&left, &right, &p).unwrap();
        eprintln!("total {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    }
}

#[test]
fn speckle_removal_drops_only_small_regions() {
    // 12 x 8 map: a 12 x 6 plane at 5.0 (72 px), a 2 x 2 blob at 9.0 inside a NaN band, and a
    // ramp row whose 1 px steps stay one region.
    let (w, h) = (12, 8);
    let mut d = vec![5.0f32; w * h];
    for x in 0..w {
        d[6 * w + x] = f32::NAN;
        d[7 * w + x] = x as f32;
    }
    for (x, y) in [(3, 2), (4, 2), (3, 3), (4, 3)] {
        d[y * w + x] = 9.0;
    }
    post::remove_speckles(&mut d, w, h, 10, 1.0).unwrap();
    assert!(
        d[2 * w + 3].is_nan() && d[3 * w + 4].is_nan(),
        "4 px blob removed"
    );
    assert_eq!(d[0], 5.0, "68 px plane kept");
    assert!(d[7 * w..].iter().all(|v| v.is_finite()), "12 px ramp kept");
    assert!(d[6 * w..7 * w].iter().all(|v| v.is_nan()));
}

#[test]
fn parallel_speckle_labelling_equals_the_flood_fill() {
    // Random maps (values 0.8 px apart, so only neighbouring levels join; NaN holes) of several sizes: regions of all
    // shapes cross the 32-row band boundaries. The banded union-find must drop exactly the
    // pixels the sequential flood fill drops.
    let mut seed = 12345u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 33) as u32
    };
    for &(w, h, min_size) in &[
        (97usize, 83usize, 20usize),
        (64, 130, 100),
        (5, 70, 3),
        (200, 33, 50),
    ] {
        let mut d = vec![0f32; w * h];
        for v in d.iter_mut() {
            let r = rnd();
            *v = if r % 7 == 0 {
                f32::NAN
            } else {
                (r % 6) as f32 * 0.8
            };
        }
        let mut a = d.clone();
        let mut b = d.clone();
        post::remove_speckles(&mut a, w, h, min_size, 1.0).unwrap();
        post::remove_speckles_flood(&mut b, w, h, min_size, 1.0);
        let dropped = a
            .iter()
            .zip(&d)
            .filter(|(x, y)| x.is_nan() && y.is_finite())
            .count();
        let kept = a.iter().filter(|x| x.is_finite()).count();
        assert!(
            dropped > 0 && kept > 0,
            "{w}x{h}: {dropped} dropped, {kept} kept"
        );
        assert!(
            a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{w}x{h}: banded labelling differs from the flood fill"
        );
    }
}

#[test]
fn fused_search_row_equals_the_generic_one() {
    // Widths with and without an 8-pixel tail, 1 and 3 channels, the re-search (-3..=3) and a
    // top-level range (0..=20), on base maps with smooth runs, jumps and shifts that leave the
    // image: the AVX2 kernel must give the generic kernel's output bit for bit.
    for &(w, h) in &[(61usize, 9usize), (64, 5), (13, 3)] {
        let (left, right) = (texture(w, h, 0.0, 3), texture(w, h, 4.3, 3));
        for n_or in [1usize, 3] {
            let chans: Vec<_> = DEFAULT_ORIENTATIONS[..n_or]
                .iter()
                .map(|&t| filter::Channel::new(0.25, t, 1.5, 1.0).unwrap())
                .collect();
            let ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
            let rd = level_data(&right.data, w, h, &chans, 1.25, true).unwrap();
            let base: Vec<f32> = (0..w * h)
                .map(|i| {
                    let x = (i % w) as f32;
                    match (i / 7) % 4 {
                        0 => 4.3 + 0.01 * x,
                        1 => 4.0 + ((i * 13) % 9) as f32 * 0.7,
                        2 => x + 2.5, // shifted out of the image on the left
                        _ => -3.2,    // ... and on the right
                    }
                })
                .collect();
            for offs in [(-3..=3).collect::<Vec<i32>>(), (0..=20).collect()] {
                let offs: Vec<f32> = offs.into_iter().map(|k| k as f32).collect();
                let a = search::search_impl(&ld, &rd, &base, &offs, 0, true).unwrap();
                let b = search::search_impl(&ld, &rd, &base, &offs, 0, false).unwrap();
                let same = a
                    .iter()
                    .zip(b.iter())
                    .all(|(p, q)| p.to_bits() == q.to_bits());
                assert!(same, "{w}x{h}, {n_or} channel(s), {} offsets", offs.len());
                let moved = a.iter().zip(&base).filter(|(p, q)| p != q).count();
                assert!(moved > 0, "the search moves some pixels");
            }
        }
    }
}

#[test]
fn validity_row_applies_the_lr_check_rule() {
    // Random left/right maps (NaN, out-of-row matches, near and far agreement): the fused row
    // pass must keep exactly the pixels that lr_check, the confidence and the range test keep.
    let (w, h) = (53usize, 7usize);
    let mut seed = 99u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as f32) / (1u64 << 31) as f32
    };
    let mut dl: Vec<f32> = (0..w * h).map(|_| -3.0 + 20.0 * rnd()).collect();
    dl[5] = f32::NAN;
    dl[17] = 60.0;
    let dr: Vec<f32> = (0..w * h).map(|i| dl[i] + 3.0 * (rnd() - 0.5)).collect();
    let conf: Vec<f32> = (0..w * h).map(|_| rnd()).collect();
    let ok = post::lr_check(&dl, &dr, w, h, 1.0).unwrap();
    let mirrored = post::flip_x(&dr, w, h).unwrap();
    let mut kept = 0;
    for y in 0..h {
        let row = y * w..(y + 1) * w;
        let mut d = dl[row.clone()].to_vec();
        post::validity_row(&mut d, &conf[row.clone()], &mirrored[row.clone()], 0.3, 1.0);
        for (x, &v) in d.iter().enumerate() {
            let i = y * w + x;
            let s = x as f32 - dl[i];
            let want = ok[i] && conf[i] >= 0.3 && s >= 0.0 && s <= (w - 1) as f32;
            assert_eq!(v.is_finite(), want, "pixel ({x}, {y})");
            if want {
                assert_eq!(v, dl[i]);
                kept += 1;
            }
        }
    }
    assert!(kept > 20 && kept < w * h / 2, "{kept} kept");
}

#[test]
fn percentile_of_two_equals_the_plain_selection() {
    // Squared amplitudes over many octaves, exact zeros, ties, and uneven halves: the
    // histogram selection must return the very element the plain selection returns.
    let mut seed = 7u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as f32) / (1u64 << 31) as f32
    };
    for &(na, nb) in &[
        (1000usize, 3000usize),
        (1, 0),
        (0, 5),
        (20000, 7),
        (333, 333),
    ] {
        let mut v = |n: usize| -> Vec<f32> {
            (0..n)
                .map(|i| match i % 13 {
                    0 => 0.0,
                    1 => 0.25,
                    _ => (rnd() * 30.0 - 20.0).exp2(),
                })
                .collect()
        };
        let (a, b) = (v(na), v(nb));
        for q in [0.0f32, 0.05, 0.5, 0.95, 1.0] {
            let mut all: Vec<f32> = a.iter().chain(&b).copied().collect();
            let want = level::percentile(&all, q);
            let got = level::percentile_of_two(&a, &b, q);
            assert_eq!(got.to_bits(), want.to_bits(), "{na}+{nb} at q {q}");
            all.clear();
        }
    }
    assert_eq!(level::percentile_of_two(&[], &[], 0.95), 0.0);
}

#[test]
fn the_envelope_is_bounded() {
    use super::filter::{sigma_from_bandwidth, Channel, MAX_ENVELOPE_SIGMA};
    // the smallest frequency whose envelope fits, and just below it
    let f = sigma_from_bandwidth(1.0, 1.5) / MAX_ENVELOPE_SIGMA;
    assert!(Channel::new(f * 1.001, 0.0, 1.5, 1.0).is_ok());
    let err = Channel::new(f * 0.999, 0.0, 1.5, 1.0)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("freq") && err.contains("at most 64 px"),
        "{err}"
    );
    // the aspect stretches the envelope along x
    assert!(Channel::new(0.25, 0.0, 1.5, 10.0).is_ok());
    assert!(Channel::new(0.03, 0.0, 1.5, 10.0).is_err());
}

#[test]
fn fused_search_survives_shifts_beyond_i32() {
    // A disparity range far off the image (d_min = +-3e10 passes validation: finite, range
    // <= MAX_RANGE) puts every shifted position at i32::MIN / i32::MAX. The window test of the
    // fused kernel computed `first - o` and `base + reach` in i32: they overflowed (a panic in
    // debug builds, in release a wrapped `base` that passed the test and a load ~8 GiB off the
    // row). Every candidate is outside the image: both kernels keep the first offset.
    let (w, h) = (24usize, 3usize);
    let (left, right) = (texture(w, h, 0.0, 3), texture(w, h, 4.3, 3));
    let chans = [filter::Channel::new(0.25, DEFAULT_ORIENTATIONS[0], 1.5, 1.0).unwrap()];
    let ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
    let rd = level_data(&right.data, w, h, &chans, 1.25, true).unwrap();
    for d in [3e10f32, -3e10, 2.2e9, -2.2e9] {
        let base = vec![d; w * h];
        for offs in [(0..=20).collect::<Vec<i32>>(), (-9..=9).collect()] {
            let offs: Vec<f32> = offs.into_iter().map(|k| k as f32).collect();
            let a = search::search_impl(&ld, &rd, &base, &offs, 0, true).unwrap();
            let b = search::search_impl(&ld, &rd, &base, &offs, 0, false).unwrap();
            let first = d + offs[0];
            assert!(
                a.iter().all(|&v| v.to_bits() == first.to_bits()),
                "fused, d = {d}"
            );
            assert!(
                b.iter().all(|&v| v.to_bits() == first.to_bits()),
                "generic, d = {d}"
            );
        }
    }
}

#[test]
fn fused_search_equals_the_generic_one_on_every_size() {
    // Widths 1..=70 and around 128, heights 1..=5, offset ranges around the 8- and 16-sample
    // window loads; base maps whose shifted positions sit at the left border (j0 = 0), at the
    // right one (j0 = w - 1), in smooth runs, in runs of spread 14 (two loads) and 16+ (the
    // gather), per 8-pixel chunk and per row. Bit equality with the generic kernel.
    let chans = [filter::Channel::new(0.25, DEFAULT_ORIENTATIONS[0], 1.5, 1.0).unwrap()];
    let offsets: [(i32, i32); 9] = [
        (0, 0),
        (0, 7),
        (0, 8),
        (-4, 4),
        (-8, 8),
        (0, 15),
        (-1, 16),
        (-17, 17),
        (0, 33),
    ];
    for w in (1..=70usize).chain([127, 128, 129]) {
        for h in 1..=5usize {
            let (left, right) = (texture(w, h, 0.0, 5), texture(w, h, 2.7, 5));
            let ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
            let rd = level_data(&right.data, w, h, &chans, 1.25, true).unwrap();
            let base: Vec<f32> = (0..w * h)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    let xf = x as f32;
                    match (y + x / 8) % 6 {
                        0 => xf,                      // j0 = 0
                        1 => xf - (w as f32 - 1.0),   // j0 = w - 1
                        2 => 0.5 * xf + 1.3,          // spread 3-4
                        3 => -xf - 2.2,               // spread 14
                        4 => -2.0 * xf,               // spread 21: gather
                        _ => 3.7 + 0.01 * (y as f32), // constant
                    }
                })
                .collect();
            for &(lo, hi) in &offsets {
                let offs: Vec<f32> = (lo..=hi).map(|k| k as f32).collect();
                let a = search::search_impl(&ld, &rd, &base, &offs, 0, true).unwrap();
                let b = search::search_impl(&ld, &rd, &base, &offs, 0, false).unwrap();
                let same = a
                    .iter()
                    .zip(b.iter())
                    .all(|(p, q)| p.to_bits() == q.to_bits());
                assert!(same, "{w}x{h}, offsets {lo}..={hi}");
            }
        }
    }
}

#[test]
fn fused_search_reads_only_the_channels_both_levels_have() {
    // `search` is public: levels filtered with different channel counts were zipped by the
    // generic kernel, while the fused one read the right level's channel list unchecked
    // (`get_unchecked`) for every left channel. Both now use the channels both levels have.
    let (w, h) = (37usize, 4usize);
    let (left, right) = (texture(w, h, 0.0, 3), texture(w, h, 2.0, 3));
    let chans: Vec<_> = DEFAULT_ORIENTATIONS[..3]
        .iter()
        .map(|&t| filter::Channel::new(0.25, t, 1.5, 1.0).unwrap())
        .collect();
    let ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
    let rd = level_data(&right.data, w, h, &chans[..1], 1.25, true).unwrap();
    let base = vec![1.5f32; w * h];
    let offs: Vec<f32> = (0..=6).map(|k| k as f32).collect();
    let a = search::search_impl(&ld, &rd, &base, &offs, 0, true).unwrap();
    let b = search::search_impl(&ld, &rd, &base, &offs, 0, false).unwrap();
    assert!(a
        .iter()
        .zip(b.iter())
        .all(|(p, q)| p.to_bits() == q.to_bits()));
}
