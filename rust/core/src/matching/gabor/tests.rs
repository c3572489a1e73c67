use super::*;

/// The tests' channels: frequency 1/4, 1.5 octaves of bandwidth, a round envelope; one
/// per orientation in degrees.
fn channels(orientations_deg: &[f32]) -> Vec<filter::Channel> {
    orientations_deg
        .iter()
        .map(|&t| filter::Channel::new(0.25, t, 1.5, 1.0).unwrap())
        .collect()
}

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
fn a_texture_of_one_grey_level_is_matched() {
    // The absolute amplitude floor (AMP_ABS_FLOOR) sits between a constant image's numerical
    // noise and the response to one grey level (1/255) of texture: such a faint texture, here
    // rescaled to a standard deviation of 1/255, is still dense and exact. A floor of 1e-3
    // survived the tests.
    let faint = |img: Image| {
        let n = img.data.len() as f32;
        let mean = img.data.iter().sum::<f32>() / n;
        let sd = (img.data.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / n).sqrt();
        let data = img
            .data
            .iter()
            .map(|v| 0.5 + (v - mean) / sd / 255.0)
            .collect();
        Image::new(img.width, img.height, data).unwrap()
    };
    let d = 2.3f32;
    let (left, right) = (faint(texture(96, 64, 0.0, 7)), faint(texture(96, 64, d, 7)));
    let p = GaborParams {
        d_min: 0.0,
        d_max: 16.0,
        ..GaborParams::default()
    };
    let out = gabor_disparity(&left, &right, &p).unwrap();
    let (med, n) = median_of_finite(&out.disparity.data);
    assert!(n > 96 * 64 * 3 / 4, "density too low: {n}");
    assert!((med - d).abs() < 0.05, "median = {med}");
}

#[test]
fn textureless_pair_gives_all_nan() {
    let a = Image::filled(64, 48, 0.5).unwrap();
    let out = gabor_disparity(&a, &a, &GaborParams::default()).unwrap();
    assert!(out.disparity.data.iter().all(|v| v.is_nan()));
    assert!(out.confidence.data.iter().all(|&v| v == 0.0));
}

#[test]
fn bad_parameters_are_errors() {
    let a = Image::filled(16, 16, 0.5).unwrap();
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
    let b = Image::filled(17, 16, 0.5).unwrap();
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

/// Run by [`speckle_tables_too_large_to_allocate_are_an_error`] in a child process: a
/// 4096x2048 map where no two neighbours join (one label a pixel) under an address-space limit
/// of 14 bytes a pixel more than is mapped. The label image and the bands' parents and counts
/// (12 bytes a pixel) fit; the merged parents (4 more) do not.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of speckle_tables_too_large_to_allocate_are_an_error"]
fn speckle_tables_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let (w, h) = (4096usize, 2048usize);
    let mut d: Vec<f32> = (0..w * h)
        .map(|i| ((i % w + 2 * (i / w)) % 5) as f32 * 10.0)
        .collect();
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + 14 * w * h);
    match post::remove_speckles(&mut d, w, h, 2, 1.0) {
        Ok(()) => println!("child: filtered {}", d[0]),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn speckle_tables_too_large_to_allocate_are_an_error() {
    // The merged union-find tables (parents, counts, sizes, roots: up to 4 bytes a pixel each)
    // grew by extend and were allocated with vec!/collect: a failed allocation aborted the
    // process (SIGABRT) instead of returning OutOfMemory.
    let stdout = crate::segment::tests::run_oom_child(
        "matching::gabor::tests::speckle_tables_under_a_memory_limit",
    );
    let want = "child: error: out of memory: the speckle filter's label tables needs 32.00 MiB \
                (33554432 bytes)";
    assert!(stdout.contains(want), "{want} not in {stdout}");
}

/// Run by [`speckle_band_labels_too_large_to_allocate_are_an_error`] in a child process: the
/// map of [`speckle_tables_under_a_memory_limit`] under a limit of the label image (4 bytes a
/// pixel) and 256 KiB more than is mapped: the first band's labels (one a pixel, 512 KiB) do
/// not fit.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of speckle_band_labels_too_large_to_allocate_are_an_error"]
fn speckle_band_labels_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let (w, h) = (4096usize, 2048usize);
    let mut d: Vec<f32> = (0..w * h)
        .map(|i| ((i % w + 2 * (i / w)) % 5) as f32 * 10.0)
        .collect();
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(
        crate::segment::tests::vm_size() + 4 * w * h + (256 << 10),
    );
    match post::remove_speckles(&mut d, w, h, 2, 1.0) {
        Ok(()) => println!("child: filtered {}", d[0]),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn speckle_band_labels_too_large_to_allocate_are_an_error() {
    // Each band's union-find parents grew by push in the labelling loop: a failed allocation
    // aborted the process (SIGABRT) instead of returning OutOfMemory.
    let stdout = crate::segment::tests::run_oom_child(
        "matching::gabor::tests::speckle_band_labels_under_a_memory_limit",
    );
    let want = "child: error: out of memory: the speckle filter's band labels needs 524288 bytes";
    assert!(stdout.contains(want), "{want} not in {stdout}");
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
            let chans = channels(&DEFAULT_ORIENTATIONS[..n_or]);
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
    let chans = channels(&DEFAULT_ORIENTATIONS[..3]);
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

/// The search by its definition (module docs of `search`), in f64: per pixel, the first offset
/// maximising the box-pooled `sum 2 Re(y_l conj y_r) / sum (|y_l|^2 + |y_r|^2)` (terms zero where
/// `floor(x - base + 0.5) - o` leaves the row; box clamped to the image). Returns the choice and
/// its lead over the best other candidate value (ties within rounding are not compared).
fn direct_search(
    l: &level::LevelData,
    r: &level::LevelData,
    base: &[f32],
    offs: &[f32],
    p: usize,
) -> (Vec<f32>, Vec<f64>) {
    let (w, h) = (l.w, l.h);
    let term = |x: usize, y: usize, o: f32| -> (f64, f64) {
        let s = (x as f32 - base[y * w + x] + 0.5).floor() - o;
        if !(s >= 0.0 && s <= (w - 1) as f32) {
            return (0.0, 0.0);
        }
        let (s, ro) = (s as usize, level::SUBROWS * y * w);
        let mut num = 0f64;
        for (lc, rc) in l.chan.iter().zip(&r.chan) {
            num += lc[ro + 4 * w + x] as f64 * rc[ro + 4 * w + s] as f64
                + lc[ro + 5 * w + x] as f64 * rc[ro + 5 * w + s] as f64;
        }
        (
            2.0 * num,
            l.energy[y * w + x] as f64 + r.energy[y * w + s] as f64,
        )
    };
    let (mut out, mut lead) = (base.to_vec(), vec![f64::INFINITY; w * h]);
    let p = p as isize;
    for y in 0..h {
        for x in 0..w {
            let e: Vec<f64> = offs
                .iter()
                .map(|&o| {
                    let (mut n, mut d) = (0f64, 0f64);
                    for dy in -p..=p {
                        for dx in -p..=p {
                            let yy = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                            let xx = (x as isize + dx).clamp(0, w as isize - 1) as usize;
                            let (a, b) = term(xx, yy, o);
                            n += a;
                            d += b;
                        }
                    }
                    if d > 0.0 {
                        n / d
                    } else {
                        0.0
                    }
                })
                .collect();
            let k = (0..e.len()).fold(0, |k, i| if e[i] > e[k] { i } else { k });
            out[y * w + x] = base[y * w + x] + offs[k];
            // Every candidate off the row: exact zeros, and the first offset stays.
            lead[y * w + x] = if e.iter().all(|&v| v == 0.0) {
                f64::INFINITY
            } else {
                (0..e.len())
                    .filter(|&i| i != k)
                    .map(|i| e[k] - e[i])
                    .fold(f64::INFINITY, f64::min)
            };
        }
    }
    (out, lead)
}

#[test]
fn search_equals_its_definition_pooled_or_not() {
    // 45 x 37: two 32-row bands (pooled rows at the band boundary and the image's last row),
    // three channels, base maps with smooth runs, jumps and shifts that leave the image, the
    // re-search offsets and a top-level range; both kernels of the unpooled search.
    let (w, h) = (45usize, 37usize);
    let (left, right) = (texture(w, h, 0.0, 5), texture(w, h, 3.4, 5));
    let chans = channels(&DEFAULT_ORIENTATIONS);
    let ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
    let rd = level_data(&right.data, w, h, &chans, 1.25, true).unwrap();
    let base: Vec<f32> = (0..w * h)
        .map(|i| {
            let x = (i % w) as f32;
            match (i / 11) % 5 {
                0 => 3.4 + 0.01 * x,
                1 => 2.0 + ((i * 13) % 9) as f32 * 0.7,
                2 => x - 0.4,  // the re-search reaches past the left edge
                3 => -2.2,     // ... and past the right one
                _ => x + 20.0, // every candidate off the row
            }
        })
        .collect();
    for offs in [(-3..=3).collect::<Vec<i32>>(), (0..=9).collect()] {
        let offs: Vec<f32> = offs.into_iter().map(|k| k as f32).collect();
        for pool in [0usize, 1, 2] {
            let (want, lead) = direct_search(&ld, &rd, &base, &offs, pool);
            let fused = [true, false];
            for &allow in if pool == 0 { &fused[..] } else { &fused[..1] } {
                let got = search::search_impl(&ld, &rd, &base, &offs, pool, allow).unwrap();
                let mut compared = 0;
                for i in 0..w * h {
                    if lead[i] > 1e-5 {
                        compared += 1;
                        assert_eq!(
                            got[i],
                            want[i],
                            "pool {pool} fused {allow} offsets {offs:?} pixel ({}, {})",
                            i % w,
                            i / w
                        );
                    }
                }
                assert!(compared > w * h * 9 / 10, "{compared} compared");
            }
        }
    }
}

#[test]
fn median5_is_the_5x1_median_of_the_1x5_medians() {
    // Clamped borders both ways; few distinct values, so ties too.
    let (w, h) = (23usize, 9usize);
    let src: Vec<f32> = (0..w * h).map(|i| ((i * 7919) % 13) as f32 * 0.5).collect();
    let out = post::median5(&src, w, h).unwrap();
    let med = |mut v: [f32; 5]| {
        v.sort_by(|a, b| a.total_cmp(b));
        v[2]
    };
    let at = |x: isize, y: isize| {
        let (x, y) = (x.clamp(0, w as isize - 1), y.clamp(0, h as isize - 1));
        src[y as usize * w + x as usize]
    };
    for y in 0..h as isize {
        for x in 0..w as isize {
            let row = |yy: isize| med(std::array::from_fn(|k| at(x + k as isize - 2, yy)));
            let want = med(std::array::from_fn(|k| row(y + k as isize - 2)));
            assert_eq!(out[y as usize * w + x as usize], want, "({x}, {y})");
        }
    }
}

#[test]
fn upsample_is_bilinear_at_half_the_coordinates() {
    // Fine pixel (x, y) reads the coarse map at (x / 2, y / 2), clamped to the coarse image;
    // fine sizes 2n - 1, 2n, beyond (columns and rows past the last coarse sample) and below.
    let (sw, sh) = (5usize, 4usize);
    let src: Vec<f32> = (0..sw * sh).map(|i| ((i * 37) % 11) as f32 - 3.0).collect();
    for (w, h) in [(9usize, 7usize), (10, 8), (13, 11), (7, 5)] {
        for scale in [1.0f32, 2.0] {
            let out = post::upsample(&src, sw, sh, w, h, scale).unwrap();
            for y in 0..h {
                for x in 0..w {
                    let (fx, fy) = (
                        (x as f64 / 2.0).min((sw - 1) as f64),
                        (y as f64 / 2.0).min((sh - 1) as f64),
                    );
                    let (x0, y0) = (fx.floor() as usize, fy.floor() as usize);
                    let (x1, y1) = ((x0 + 1).min(sw - 1), (y0 + 1).min(sh - 1));
                    let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
                    let s = |xx: usize, yy: usize| src[yy * sw + xx] as f64;
                    let a = s(x0, y0) + tx * (s(x1, y0) - s(x0, y0));
                    let b = s(x0, y1) + tx * (s(x1, y1) - s(x0, y1));
                    let want = scale as f64 * (a + ty * (b - a));
                    let got = out[y * w + x] as f64;
                    assert!(
                        (got - want).abs() < 1e-6,
                        "{w}x{h} ({x}, {y}): {got} vs {want}"
                    );
                }
            }
        }
    }
}

#[test]
fn normalized_conv_divides_the_blurred_products_by_the_blurred_confidence() {
    // cbar = G * c, dbar = G * (c d) / cbar (0 where cbar <= 1e-6), reflect-101 borders; the
    // right part has a confidence too small to divide by.
    let (w, h, sigma) = (21usize, 6usize, 1.2f32);
    let d: Vec<f32> = (0..w * h)
        .map(|i| ((i * 31) % 17) as f32 * 0.25 - 2.0)
        .collect();
    let c: Vec<f32> = (0..w * h)
        .map(|i| {
            if i % w >= 15 {
                1e-9
            } else {
                ((i * 7) % 5) as f32 * 0.2
            }
        })
        .collect();
    let d: Vec<f32> = d
        .iter()
        .enumerate()
        .map(|(i, &v)| if i % w >= 15 { 1e6 } else { v })
        .collect();
    let (dbar, cbar) = post::normalized_conv(&d, &c, w, h, sigma).unwrap();
    let g = filter::gaussian_taps(sigma, filter::radius_for(sigma));
    let r = (g.len() / 2) as isize;
    let blur = |f: &dyn Fn(usize) -> f64, x: usize, y: usize| {
        let mut s = 0f64;
        for (i, gy) in g.iter().enumerate() {
            for (j, gx) in g.iter().enumerate() {
                let yy = filter::mirror(y as isize + i as isize - r, h);
                let xx = filter::mirror(x as isize + j as isize - r, w);
                s += *gy as f64 * *gx as f64 * f(yy * w + xx);
            }
        }
        s
    };
    for y in 0..h {
        for x in 0..w {
            let cb = blur(&|i| c[i] as f64, x, y);
            let num = blur(&|i| c[i] as f64 * d[i] as f64, x, y);
            let want = if cb > 1e-6 { num / cb } else { 0.0 };
            let i = y * w + x;
            assert!((cbar[i] as f64 - cb).abs() < 1e-6, "cbar ({x}, {y})");
            assert!(
                (dbar[i] as f64 - want).abs() < 1e-5 * (1.0 + want.abs()),
                "dbar ({x}, {y}): {} vs {want}",
                dbar[i]
            );
        }
    }
}

#[test]
fn update_max_and_flip_helpers() {
    // apply_update: only where cbar >= conf_min (equal counts), clamped to [lo, hi].
    let mut disp = vec![0.0f32, 0.0, 0.0, 1.0];
    post::apply_update(
        &mut disp,
        &[1.0, 5.0, -5.0, 0.5],
        &[0.2, 0.1, 0.15, 0.9],
        0.15,
        -1.0,
        2.0,
        2,
    );
    assert_eq!(disp, vec![1.0, 0.0, -1.0, 1.5]);
    let mut m = vec![1.0f32, 5.0, -2.0];
    post::max_into(&mut m, &[3.0, 2.0, -1.0]);
    assert_eq!(m, vec![3.0, 5.0, -1.0]);
    assert_eq!(
        post::flip_x(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 3, 2).unwrap(),
        vec![3.0, 2.0, 1.0, 6.0, 5.0, 4.0]
    );
}

#[test]
fn speckle_size_and_range_limits_are_inclusive_where_opencv_s_are() {
    // A region of exactly min_size pixels stays (only smaller ones go), and neighbours exactly
    // max_diff apart join.
    let (w, h) = (6usize, 3usize);
    let mut d = vec![f32::NAN; w * h];
    // 4 px region at 1.0 / 1.5 (0.5 apart: one region with max_diff 0.5), and a 3 px one.
    for (x, v) in [(0, 1.0), (1, 1.5), (2, 1.0), (3, 1.5)] {
        d[x] = v;
    }
    for x in 0..3 {
        d[2 * w + x] = 7.0;
    }
    post::remove_speckles(&mut d, w, h, 4, 0.5).unwrap();
    assert_eq!(&d[..4], &[1.0, 1.5, 1.0, 1.5]);
    assert!(d[2 * w..2 * w + 3].iter().all(|v| v.is_nan()));
}

#[test]
fn validity_and_lr_check_on_a_hand_made_row() {
    // x - d at 0 and at w - 1 (both inside), a confidence equal to conf_min (kept), right
    // values exactly tol away (kept), 1.2 px away (dropped) and a low confidence (dropped).
    let w = 5;
    let dl = [0.0f32, 1.0, -2.0, 2.5, 4.0];
    let dr = [0.0f32, 3.7, 7.0, 7.0, -2.5];
    assert_eq!(
        post::lr_check(&dl, &dr, w, 1, 1.0).unwrap(),
        vec![true, true, true, false, false]
    );
    let mut d = dl.to_vec();
    let mirrored = post::flip_x(&dr, w, 1).unwrap();
    post::validity_row(&mut d, &[0.5, 0.3, 0.5, 0.5, 0.29], &mirrored, 0.3, 1.0);
    assert_eq!(&d[..3], &[0.0, 1.0, -2.0]);
    assert!(d[3].is_nan() && d[4].is_nan());
}

#[test]
fn level_data_holds_the_responses_demodulated_and_their_frequency_phasors() {
    // Per channel and pixel: y = the filter bank's response (bit for bit), the left's
    // beta = exp(-j k.x) y, the right's baseband exp(-j k.x) (y + c L), the phasor
    // f = y(x+1) conj y(x) + y(x) conj y(x-1) (columns clamped), the energy sum_c |y_c|^2 and
    // every third |y|^2 as the percentile sample.
    let (w, h) = (29usize, 7usize);
    let img = texture(w, h, 0.0, 11);
    let chans = channels(&DEFAULT_ORIENTATIONS);
    let fb = filter::filter_bank(&img.data, w, h, &chans).unwrap();
    for right in [false, true] {
        let ld = level_data(&img.data, w, h, &chans, 1.25, right).unwrap();
        let mut energy = vec![0f64; w * h];
        for (ci, c) in chans.iter().enumerate() {
            let ch = &ld.chan[ci];
            let (yre, yim) = (&fb.re[ci], &fb.im[ci]);
            for y in 0..h {
                let o = level::SUBROWS * y * w;
                for x in 0..w {
                    let i = y * w + x;
                    assert_eq!(ch[o + 4 * w + x].to_bits(), yre[i].to_bits());
                    assert_eq!(ch[o + 5 * w + x].to_bits(), yim[i].to_bits());
                    let (mut pr, mut pi) = (yre[i] as f64, yim[i] as f64);
                    if right {
                        pr += (c.dc[0] * fb.lowpass[i]) as f64;
                        pi += (c.dc[1] * fb.lowpass[i]) as f64;
                    }
                    let a = -(c.kx as f64 * x as f64 + c.ky as f64 * y as f64);
                    let (qr, qi) = (a.cos(), a.sin());
                    let (br, bi) = (pr * qr - pi * qi, pr * qi + pi * qr);
                    let tol = 1e-5 * (1.0 + pr.hypot(pi));
                    assert!(
                        (ch[o + x] as f64 - br).abs() < tol,
                        "re ch {ci} ({x}, {y}) right {right}"
                    );
                    assert!(
                        (ch[o + w + x] as f64 - bi).abs() < tol,
                        "im ch {ci} ({x}, {y}) right {right}"
                    );
                    let yv = |xx: usize| (yre[y * w + xx] as f64, yim[y * w + xx] as f64);
                    let (a0, a1, a2) = (yv(x.saturating_sub(1)), yv(x), yv((x + 1).min(w - 1)));
                    let fr = a2.0 * a1.0 + a2.1 * a1.1 + a1.0 * a0.0 + a1.1 * a0.1;
                    let fi = a2.1 * a1.0 - a2.0 * a1.1 + a1.1 * a0.0 - a1.0 * a0.1;
                    assert!(
                        (ch[o + 2 * w + x] as f64 - fr).abs() < 1e-5,
                        "f re ch {ci} ({x}, {y})"
                    );
                    assert!(
                        (ch[o + 3 * w + x] as f64 - fi).abs() < 1e-5,
                        "f im ch {ci} ({x}, {y})"
                    );
                    energy[i] += a1.0 * a1.0 + a1.1 * a1.1;
                }
            }
            let want: Vec<f32> = yre
                .iter()
                .zip(yim)
                .step_by(3)
                .map(|(a, b)| a * a + b * b)
                .collect();
            assert_eq!(ld.amp2_samples[ci], want);
        }
        for (i, (&got, want)) in ld.energy.iter().zip(&energy).enumerate() {
            assert!((got as f64 - want).abs() < 1e-5, "energy {i}");
        }
    }
}

/// Checks every stability bit of a textured level at `tau` against the Fleet-Jepson test;
/// returns the bits set, the bits clear, and those clear by the frequency bound alone (inside
/// the `tau / sigma_x` disk, below `k0 / 2`).
fn check_stability_bits(tau: f32) -> (usize, usize, usize) {
    // Bit c where |psi - j k0| <= tau / sigma_x and Im psi >= k0 / 2, with Im psi = arg f and
    // Re psi = (ln |y(x+1)|^2 - ln |y(x-1)|^2) / 4; never on the first and last columns.
    let (w, h) = (40usize, 6usize);
    let img = texture(w, h, 0.0, 21);
    // Three channels: each has its own bit.
    let chans = channels(&DEFAULT_ORIENTATIONS);
    let ld = level_data(&img.data, w, h, &chans, tau, false).unwrap();
    let (mut set, mut clear, mut freq_only) = (0, 0, 0);
    for (ci, c) in chans.iter().enumerate() {
        let lim = (tau / c.sigma_x) as f64;
        for y in 0..h {
            let o = level::SUBROWS * y * w;
            let ch = &ld.chan[ci];
            let amp2 = |x: usize| {
                let (a, b) = (ch[o + 4 * w + x] as f64, ch[o + 5 * w + x] as f64);
                a * a + b * b
            };
            for x in 0..w {
                let bit = ld.stable[y * w + x] >> ci & 1 == 1;
                if x == 0 || x == w - 1 {
                    assert!(!bit, "border ({x}, {y})");
                    continue;
                }
                let im = (ch[o + 3 * w + x] as f64).atan2(ch[o + 2 * w + x] as f64);
                let re = 0.25 * ((amp2(x + 1) + 1e-30).ln() - (amp2(x - 1) + 1e-30).ln());
                let dk = im - c.kx as f64;
                let r = (re * re + dk * dk).sqrt();
                let kmin = 0.5 * c.kx as f64;
                // Skip pixels within rounding of either threshold.
                if (r - lim).abs() < 1e-3 || (im - kmin).abs() < 1e-3 {
                    continue;
                }
                let want = r <= lim && im >= kmin;
                assert_eq!(
                    bit, want,
                    "channel {ci} ({x}, {y}): r {r} lim {lim} im {im}"
                );
                if want {
                    set += 1;
                } else {
                    clear += 1;
                    freq_only += usize::from(r <= lim);
                }
            }
        }
    }
    (set, clear, freq_only)
}

#[test]
fn stability_bits_follow_the_fleet_jepson_test() {
    let (set, clear, _) = check_stability_bits(0.6);
    assert!(set > 20 && clear > 20, "{set} set, {clear} clear");
}

#[test]
fn stability_needs_half_the_tuned_frequency_inside_a_wide_disk() {
    // At tau 0.6 the disk (radius tau / sigma_x) lies above k0 / 2 in every channel, so the
    // frequency bound decides nothing there; at tau 3 the disk reaches below it (and below 0:
    // a negative local frequency) and the bound alone must clear those pixels.
    let (set, clear, freq_only) = check_stability_bits(3.0);
    assert!(set > 20 && clear > 20, "{set} set, {clear} clear");
    assert!(
        freq_only > 5,
        "{freq_only} pixels cleared by the frequency bound alone"
    );
}

#[test]
fn newton_step_equals_its_definition() {
    // Per pixel and channel, the right data read at s = x - d (linear interpolation of the
    // baseband, the lowpass and the frequency phasor between columns min(floor s, w - 2) and the
    // next; stability of the left pixel and of the right one at round(s), none where s leaves
    // the row), rotated back by exp(-j kx d) less the zero-DC term; then
    // z = y_r conj beta_l, m = 2 |z| / (|beta_l|^2 + |y_r|^2) where usable, k = arg(f_l + f_r)
    // and delta = sum m k dphi / sum m k^2, clamped to pi / max kx, c = mean m. In f64 with
    // libm; pixels within rounding of a threshold are skipped.
    let (w, h) = (31usize, 6usize);
    let (left, right) = (texture(w, h, 0.0, 8), texture(w, h, 2.6, 8));
    let chans = channels(&DEFAULT_ORIENTATIONS);
    let ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
    let rd = level_data(&right.data, w, h, &chans, 1.25, true).unwrap();
    let cc = level::chan_consts(&chans, &ld, &rd, 0.4);
    // Near the truth, off by up to 1.9 px, and shifted out of the row at both ends.
    let disp: Vec<f32> = (0..w * h)
        .map(|i| match i % w {
            x if x < 2 => 3.0,
            x if x >= 29 => -1.5,
            x => 2.6 + 1.9 * ((x * 7 % 5) as f32 - 2.0) / 2.0,
        })
        .collect();
    let (delta, conf) = level::newton_step(&ld, &rd, &cc, &disp).unwrap();
    let max_delta = cc
        .iter()
        .map(|c| std::f64::consts::PI / c.kx as f64)
        .fold(f64::INFINITY, f64::min);
    let lerp = |v: &[f32], i: usize, t: f64| v[i] as f64 + t * (v[i + 1] as f64 - v[i] as f64);
    let (mut checked, mut moved) = (0, 0);
    for y in 0..h {
        'px: for x in 0..w {
            let i = y * w + x;
            let d = disp[i] as f64;
            let s = x as f64 - d;
            let inside = s >= 0.0 && s <= (w - 1) as f64;
            let sc = s.clamp(0.0, (w - 1) as f64);
            let i0 = (sc.floor() as usize).min(w - 2);
            let t = sc - i0 as f64;
            let near = sc.round() as usize;
            let o = level::SUBROWS * y * w;
            let lp = lerp(&rd.lowpass[y * w..(y + 1) * w], i0, t);
            let (mut num, mut den, mut csum) = (0f64, 0f64, 0f64);
            for (ci, c) in cc.iter().enumerate() {
                let (lc, rc) = (&ld.chan[ci], &rd.chan[ci]);
                let sub = |k: usize| &rc[o + k * w..o + (k + 1) * w];
                let (br, bi) = (lerp(sub(0), i0, t), lerp(sub(1), i0, t));
                let (gr, gi) = (lerp(sub(2), i0, t), lerp(sub(3), i0, t));
                let a = c.kx as f64 * d;
                let (wr, wi) = (br * a.cos() + bi * a.sin(), bi * a.cos() - br * a.sin());
                let q = -(c.kx as f64 * x as f64 + c.ky as f64 * y as f64);
                let (dr, di) = (c.dc[0] as f64 * lp, c.dc[1] as f64 * lp);
                let (yr, yi) = (
                    wr - (dr * q.cos() - di * q.sin()),
                    wi - (dr * q.sin() + di * q.cos()),
                );
                let (lr, li) = (lc[o + x] as f64, lc[o + w + x] as f64);
                let (zr, zi) = (yr * lr + yi * li, yi * lr - yr * li);
                let (pl, pw) = (lr * lr + li * li, yr * yr + yi * yi);
                let k = (lc[o + 3 * w + x] as f64 + gi).atan2(lc[o + 2 * w + x] as f64 + gr);
                let stable = inside
                    && (ld.stable[i] >> ci) & 1 == 1
                    && (rd.stable[y * w + near] >> ci) & 1 == 1;
                let (amp, kmin) = (pl.min(pw), 0.5 * c.kx as f64);
                if stable
                    && ((amp - c.thr2 as f64).abs() < 1e-4 * c.thr2 as f64
                        || (k - kmin).abs() < 1e-3
                        || zi.atan2(zr).abs() > 3.1)
                {
                    continue 'px;
                }
                if stable && amp >= c.thr2 as f64 && k >= kmin {
                    let m = 2.0 * zr.hypot(zi) / (pl + pw);
                    num += m * k * zi.atan2(zr);
                    den += m * k * k;
                    csum += m;
                }
            }
            let want = if den > 0.0 { num / den } else { 0.0 }.clamp(-max_delta, max_delta);
            let want_c = csum / cc.len() as f64;
            assert!(
                (delta[i] as f64 - want).abs() < 1e-3,
                "delta ({x}, {y}): {} vs {want}",
                delta[i]
            );
            assert!(
                (conf[i] as f64 - want_c).abs() < 1e-4,
                "conf ({x}, {y}): {} vs {want_c}",
                conf[i]
            );
            checked += 1;
            moved += usize::from(want != 0.0);
        }
    }
    assert!(
        checked > w * h * 8 / 10 && moved > w * h / 2,
        "{checked} checked, {moved} moved"
    );
}

#[test]
fn amplitude_thresholds_are_relative_to_the_95th_percentile() {
    // thr = max(amp_rel * P95(|y|) over both images' samples, AMP_ABS_FLOOR), stored squared;
    // +-60 degrees share a kx slot.
    let (w, h) = (30usize, 8usize);
    let (left, right) = (texture(w, h, 0.0, 4), texture(w, h, 1.0, 4));
    let chans = channels(&DEFAULT_ORIENTATIONS);
    let ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
    let rd = level_data(&right.data, w, h, &chans, 1.25, true).unwrap();
    let cc = level::chan_consts(&chans, &ld, &rd, 0.3);
    for (ci, c) in cc.iter().enumerate() {
        let all: Vec<f32> = ld.amp2_samples[ci]
            .iter()
            .chain(&rd.amp2_samples[ci])
            .copied()
            .collect();
        let thr = 0.3 * level::percentile(&all, 0.95).sqrt();
        assert!(thr > level::AMP_ABS_FLOOR);
        assert_eq!(c.thr2, thr * thr, "channel {ci}");
    }
    assert_eq!(
        cc.iter().map(|c| c.kx_slot).collect::<Vec<_>>(),
        vec![0, 1, 1]
    );
    // A flat pair: the absolute floor.
    let flat = vec![0.5f32; w * h];
    let lf = level_data(&flat, w, h, &chans, 1.25, false).unwrap();
    let rf = level_data(&flat, w, h, &chans, 1.25, true).unwrap();
    let floor2 = level::AMP_ABS_FLOOR * level::AMP_ABS_FLOOR;
    assert!(level::chan_consts(&chans, &lf, &rf, 0.3)
        .iter()
        .all(|c| c.thr2 == floor2));
}

#[test]
fn every_parameter_bound_is_checked_and_named() {
    // Just outside each bound: refused, naming the parameter; the bound itself: accepted.
    let d = GaborParams::default;
    let refused = [
        (
            GaborParams {
                orientations_deg: vec![0.0; 9],
                ..d()
            },
            "orientations_deg",
        ),
        (
            GaborParams {
                n_levels: Some(11),
                ..d()
            },
            "n_levels",
        ),
        (
            GaborParams {
                iters_per_level: 21,
                ..d()
            },
            "iters_per_level",
        ),
        (
            GaborParams {
                iters_finest: 21,
                ..d()
            },
            "iters_per_level",
        ),
        (
            GaborParams {
                orientations_finest: 0,
                ..d()
            },
            "orientations_finest",
        ),
        (
            GaborParams {
                lr_coarse_levels: 5,
                ..d()
            },
            "lr_coarse_levels",
        ),
        (
            GaborParams {
                amp_rel_thresh: 1.01,
                ..d()
            },
            "amp_rel_thresh",
        ),
        (
            GaborParams {
                amp_rel_thresh: -0.01,
                ..d()
            },
            "amp_rel_thresh",
        ),
        (
            GaborParams {
                conf_min: f32::NAN,
                ..d()
            },
            "conf_min",
        ),
        (
            GaborParams {
                stability_tau: 0.0,
                ..d()
            },
            "stability_tau",
        ),
        (
            GaborParams {
                stability_tau: f32::INFINITY,
                ..d()
            },
            "stability_tau",
        ),
        (
            GaborParams {
                smooth_sigma: Some(16.5),
                ..d()
            },
            "smooth_sigma",
        ),
        (
            GaborParams {
                smooth_sigma: Some(0.0),
                ..d()
            },
            "smooth_sigma",
        ),
        (
            GaborParams {
                lr_tol: -0.1,
                ..d()
            },
            "lr_tol",
        ),
        (
            GaborParams {
                speckle_range: -0.1,
                ..d()
            },
            "speckle_range",
        ),
    ];
    for (p, name) in refused {
        match p.validate() {
            Err(CoreError::InvalidParameter { name: got, .. }) => assert_eq!(got, name, "{p:?}"),
            other => panic!("{name}: {other:?}"),
        }
    }
    let accepted = [
        GaborParams {
            d_min: -MAX_RANGE / 2.0,
            d_max: MAX_RANGE / 2.0,
            ..d()
        },
        GaborParams {
            orientations_deg: vec![0.0; 8],
            n_levels: Some(10),
            iters_per_level: 20,
            iters_finest: 20,
            orientations_finest: 1,
            lr_coarse_levels: 4,
            research_radius: 16,
            search_pool_radius: 16,
            ..d()
        },
        GaborParams {
            amp_rel_thresh: 0.0,
            conf_min: 1.0,
            smooth_sigma: Some(16.0),
            lr_tol: 0.0,
            speckle_range: 0.0,
            ..d()
        },
        GaborParams {
            amp_rel_thresh: 1.0,
            conf_min: 0.0,
            ..d()
        },
    ];
    for p in accepted {
        assert!(p.validate().is_ok(), "{p:?}");
    }
}

#[test]
fn pyramid_depth_follows_the_capture_range_and_the_top_level_size() {
    // Defaults (F = 1/4, range 64): the top level's half-wavelength 2^(L-1) / (2 F) reaches half
    // the range (32 px) at L = 5, if the top level stays >= 32 px wide and >= 16 px high.
    let p = GaborParams::default();
    assert_eq!(p.levels_for(1000, 600), 5);
    assert_eq!(p.levels_for(512, 256), 5);
    assert_eq!(p.levels_for(511, 600), 4, "511 >> 4 = 31 px wide");
    assert_eq!(p.levels_for(200, 600), 3, "200 >> 3 = 25 px wide");
    assert_eq!(p.levels_for(1000, 100), 3, "100 >> 3 = 12 px high");
    assert_eq!(p.levels_for(40, 20), 1);
    // F = 0.1: 5 px, 10, 20, then 40 >= 32.
    let p = GaborParams { freq: 0.1, ..p };
    assert_eq!(p.levels_for(1000, 600), 4);
    // A range of 2 px (half 1 <= 2 px): one level; the widest range: capped at 10 levels.
    let narrow = GaborParams {
        d_max: 2.0,
        ..GaborParams::default()
    };
    assert_eq!(narrow.levels_for(1000, 600), 1);
    let wide = GaborParams {
        d_max: 8000.0,
        ..GaborParams::default()
    };
    assert_eq!(wide.levels_for(40_000, 20_000), 10);
    // An explicit depth is taken as is.
    let fixed = GaborParams {
        n_levels: Some(3),
        ..GaborParams::default()
    };
    assert_eq!(fixed.levels_for(40, 20), 3);
}

/// A pair with a background at 2.3 px and a 30 x 24 block at 6 px (occlusions at its sides).
fn two_plane_pair(w: usize, h: usize) -> (Image, Image) {
    let (bl, br) = (texture(w, h, 0.0, 31), texture(w, h, 2.3, 31));
    let (fl, fr) = (texture(w, h, 0.0, 32), texture(w, h, 6.0, 32));
    let (mut left, mut right) = (bl.clone(), br.clone());
    for y in 20..44 {
        for x in 30..60 {
            left.data[y * w + x] = fl.data[y * w + x];
            right.data[y * w + x - 6] = fr.data[y * w + x - 6];
        }
    }
    (left, right)
}

#[test]
fn gabor_disparity_composes_the_two_directions_the_lr_check_and_the_speckle_filter() {
    // The output equals its definition from the two one-direction runs: the right-reference run
    // on the mirrored, swapped pair (light parameters with lr_light; stopping lr_coarse_levels
    // above full resolution), lr_check with lr_tol, conf >= conf_min, x - d inside the row, the
    // speckle filter with its size and range, and the confidence (clamped) only where a
    // disparity is left.
    let (w, h) = (96usize, 64usize);
    let (left, right) = two_plane_pair(w, h);
    let chans_of = |p: &GaborParams| p.channels().unwrap();
    let base = GaborParams {
        d_max: 16.0,
        ..GaborParams::default()
    };
    let cases = [
        (
            GaborParams {
                lr_tol: 0.5,
                speckle_size: 150,
                ..base.clone()
            },
            None,
        ),
        (
            GaborParams {
                orientations_deg: vec![0.0, 30.0, -30.0, 60.0, -60.0],
                orientations_finest: 5,
                iters_finest: 2,
                lr_coarse_levels: 0,
                lr_light: true,
                conf_min: 0.3,
                speckle_range: 0.5,
                ..base.clone()
            },
            Some((3, 1, false)),
        ),
        (
            GaborParams {
                lr_check: false,
                speckle_size: 30,
                ..base.clone()
            },
            None,
        ),
    ];
    for (p, light) in cases {
        let chans = chans_of(&p);
        let fwd = one_direction(&left.data, &right.data, w, h, &p, &chans, 0).unwrap();
        let (mut want, conf) = (fwd.disp.to_vec(), fwd.conf.to_vec());
        let ok = if p.lr_check {
            let back = match light {
                Some((of, it, rf)) => GaborParams {
                    orientations_finest: of,
                    iters_finest: it,
                    research_finest: rf,
                    ..p.clone()
                },
                None => p.clone(),
            };
            let (fl, fr) = (
                post::flip_x(&right.data, w, h).unwrap(),
                post::flip_x(&left.data, w, h).unwrap(),
            );
            let bwd = one_direction(&fl, &fr, w, h, &back, &chans, p.lr_coarse_levels).unwrap();
            let dr = post::flip_x(&bwd.disp, w, h).unwrap();
            post::lr_check(&want, &dr, w, h, p.lr_tol).unwrap()
        } else {
            vec![true; w * h]
        };
        let mut lr_dropped = 0;
        for i in 0..w * h {
            let s = (i % w) as f32 - want[i];
            let kept = conf[i] >= p.conf_min && s >= 0.0 && s <= (w - 1) as f32;
            lr_dropped += usize::from(kept && !ok[i]);
            if !(kept && ok[i]) {
                want[i] = f32::NAN;
            }
        }
        let before = want.iter().filter(|v| v.is_finite()).count();
        post::remove_speckles(&mut want, w, h, p.speckle_size, p.speckle_range).unwrap();
        let after = want.iter().filter(|v| v.is_finite()).count();
        let want_conf: Vec<f32> = want
            .iter()
            .zip(&conf)
            .map(|(d, c)| {
                if d.is_finite() {
                    c.clamp(0.0, 1.0)
                } else {
                    0.0
                }
            })
            .collect();
        let out = gabor_disparity(&left, &right, &p).unwrap();
        let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same(&out.disparity.data, &want), "disparity, {p:?}");
        assert!(same(&out.confidence.data, &want_conf), "confidence, {p:?}");
        // Not vacuous: the check and the filter each drop pixels, and most survive.
        assert!(
            (lr_dropped > 0) == p.lr_check && after < before && after > w * h / 3,
            "{lr_dropped} dropped by the LR check, {before} -> {after} by the speckle filter"
        );
    }
}

#[test]
fn a_one_level_image_still_gets_its_coarse_right_reference_run() {
    // 40 x 20: one automatic level, yet the right-reference run stops one level above full
    // resolution (lr_coarse_levels = 1): it builds that level anyway, so pixels survive.
    let (left, right) = (texture(40, 20, 0.0, 9), texture(40, 20, 2.3, 9));
    let p = GaborParams {
        d_max: 8.0,
        ..GaborParams::default()
    };
    assert_eq!(p.levels_for(40, 20), 1);
    let out = gabor_disparity(&left, &right, &p).unwrap();
    let (med, n) = median_of_finite(&out.disparity.data);
    assert!(
        n > 40 * 20 / 2 && (med - 2.3).abs() < 0.1,
        "{n} px, median {med}"
    );
}

#[test]
fn search_takes_non_consecutive_offsets() {
    // The fused kernel needs consecutive integer offsets; any other list goes to the generic
    // kernel, which follows the definition.
    let (w, h) = (45usize, 9usize);
    let (left, right) = (texture(w, h, 0.0, 5), texture(w, h, 3.4, 5));
    let chans = channels(&DEFAULT_ORIENTATIONS);
    let ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
    let rd = level_data(&right.data, w, h, &chans, 1.25, true).unwrap();
    let base: Vec<f32> = (0..w * h)
        .map(|i| 0.3 + ((i * 13) % 7) as f32 * 0.5)
        .collect();
    for offs in [vec![0.0f32, 2.0, 5.0], vec![4.0, 1.0, 3.0, 0.0]] {
        let (want, lead) = direct_search(&ld, &rd, &base, &offs, 0);
        let got = search::search(&ld, &rd, &base, &offs, 0).unwrap();
        let mut compared = 0;
        for i in (0..w * h).filter(|&i| lead[i] > 1e-5) {
            assert_eq!(got[i], want[i], "offsets {offs:?} pixel {i}");
            compared += 1;
        }
        assert!(compared > w * h * 9 / 10, "{compared} compared");
    }
}

#[test]
fn full_resolution_without_steps_is_the_upsampled_half_resolution_map() {
    // With iters_finest = 0 the full-resolution level only up-samples (disparity x 2, confidence
    // x 1), re-searches +-research_radius when research_finest, and clamps to the scaled range
    // +-1 px: the run stopping one level above full resolution, then up-sampled, gives the rest.
    let (w, h) = (96usize, 64usize);
    let (left, right) = two_plane_pair(w, h);
    let base = GaborParams {
        d_max: 16.0,
        iters_finest: 0,
        lr_check: false,
        ..GaborParams::default()
    };
    let chans = base.channels().unwrap();
    let coarse = one_direction(&left.data, &right.data, w, h, &base, &chans, 1).unwrap();
    let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    let (lo, hi) = (base.d_min - 1.0, base.d_max + 1.0);
    for research in [false, true] {
        let p = GaborParams {
            research_finest: research,
            ..base.clone()
        };
        let fine = one_direction(&left.data, &right.data, w, h, &p, &chans, 0).unwrap();
        let mut want = coarse.disp.to_vec();
        if research {
            let c0 = &chans[..p.orientations_finest];
            let ld = level_data(&left.data, w, h, c0, p.stability_tau, false).unwrap();
            let rd = level_data(&right.data, w, h, c0, p.stability_tau, true).unwrap();
            let offs: Vec<f32> = (-3..=3).map(|k| k as f32).collect();
            want = search::search(&ld, &rd, &want, &offs, 0).unwrap().to_vec();
        }
        want.iter_mut().for_each(|d| *d = d.clamp(lo, hi));
        assert!(same(&fine.disp, &want), "disparity, research {research}");
        assert!(
            same(&fine.conf, &coarse.conf),
            "confidence, research {research}"
        );
        let moved = want
            .iter()
            .zip(coarse.disp.iter())
            .filter(|(a, b)| a != b)
            .count();
        assert!((moved > 0) == research, "{moved} moved");
    }
}

#[test]
fn channel_bounds_are_exclusive_or_inclusive_as_documented() {
    // freq in (0, 0.5), bandwidth in (0.05, 4], aspect in (0.1, 10], |theta| < 90; each refusal
    // names its parameter.
    let refused = [
        (0.5, 0.0, 1.5, 1.0, "freq"),
        (0.25, 0.0, 4.01, 1.0, "bandwidth_oct"),
        (0.25, 0.0, 0.05, 1.0, "bandwidth_oct"),
        (0.25, 0.0, 1.5, 0.1, "aspect"),
        (0.25, 0.0, 1.5, 10.01, "aspect"),
        (0.25, -90.0, 1.5, 1.0, "orientations_deg"),
    ];
    for (f, t, b, a, name) in refused {
        match filter::Channel::new(f, t, b, a) {
            Err(CoreError::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
            other => panic!("{name}: {other:?}"),
        }
    }
    for (f, t, b, a) in [
        (0.49, 89.9, 4.0, 1.0),
        (0.25, -89.9, 0.06, 1.0),
        (0.25, 0.0, 1.5, 10.0),
        (0.25, 0.0, 1.5, 0.11),
    ] {
        assert!(filter::Channel::new(f, t, b, a).is_ok(), "{f} {t} {b} {a}");
    }
}

#[test]
fn one_direction_is_the_top_search_then_the_newton_steps_by_their_definition() {
    // A range of non-integer ends and an elongated envelope: the top level searches every whole offset from
    // d_min * scale to ceil((d_max - d_min) * scale) above it, clamps to the scaled range +-1 px;
    // a Newton step is newton_step, normalised convolution with the envelope's sigma_x, the
    // update where cbar >= conf_min, the 5 x 5 median, and the confidence max(0, cbar).
    let (w, h) = (96usize, 64usize);
    let (left, right) = two_plane_pair(w, h);
    let base = GaborParams {
        d_min: -2.5,
        d_max: 9.7,
        // sigma_x != sigma_y: the smoothing uses sigma_x.
        aspect: 1.5,
        n_levels: Some(1),
        iters_per_level: 0,
        iters_finest: 0,
        research_finest: false,
        lr_check: false,
        ..GaborParams::default()
    };
    let chans = base.channels().unwrap();
    let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    let top = |img_l: &[f32], img_r: &[f32], lw, lh, scale: f32, cs: &[filter::Channel]| {
        let ld = level_data(img_l, lw, lh, cs, base.stability_tau, false).unwrap();
        let rd = level_data(img_r, lw, lh, cs, base.stability_tau, true).unwrap();
        let n = ((base.d_max - base.d_min) * scale).ceil() as usize;
        let offs: Vec<f32> = (0..=n).map(|k| k as f32).collect();
        let init = vec![base.d_min * scale; lw * lh];
        let (lo, hi) = (base.d_min * scale - 1.0, base.d_max * scale + 1.0);
        let mut d = search::search(&ld, &rd, &init, &offs, 0).unwrap().to_vec();
        d.iter_mut().for_each(|v| *v = v.clamp(lo, hi));
        (d, ld, rd)
    };
    // One level, no step: the search alone (full resolution uses the first orientation).
    let (d0, ld, rd) = top(&left.data, &right.data, w, h, 1.0, &chans[..1]);
    let got = one_direction(&left.data, &right.data, w, h, &base, &chans, 0).unwrap();
    assert!(same(&got.disp, &d0) && got.conf.iter().all(|&c| c == 0.0));
    // One Newton step.
    let p = GaborParams {
        iters_finest: 1,
        ..base.clone()
    };
    let cc = chan_consts(&chans[..1], &ld, &rd, p.amp_rel_thresh);
    let (delta, c) = newton_step(&ld, &rd, &cc, &d0).unwrap();
    let (dbar, cbar) = post::normalized_conv(&delta, &c, w, h, chans[0].sigma_x).unwrap();
    let mut d1 = d0.clone();
    post::apply_update(&mut d1, &dbar, &cbar, p.conf_min, -3.5, 10.7, w);
    let d1 = post::median5(&d1, w, h).unwrap();
    let got = one_direction(&left.data, &right.data, w, h, &p, &chans, 0).unwrap();
    assert!(same(&got.disp, &d1), "after a Newton step");
    let conf: Vec<f32> = cbar.iter().map(|&v| v.max(0.0)).collect();
    assert!(same(&got.conf, &conf));
    assert!(d1.iter().zip(&d0).filter(|(a, b)| a != b).count() > w * h / 2);
    // Two levels, no step: the half-resolution search (all orientations) up-sampled.
    let p = GaborParams {
        n_levels: Some(2),
        ..base.clone()
    };
    let (l1, w1, h1) = filter::pyr_down(&left.data, w, h).unwrap();
    let (r1, _, _) = filter::pyr_down(&right.data, w, h).unwrap();
    let (dh, _, _) = top(&l1, &r1, w1, h1, 0.5, &chans);
    let mut want = post::upsample(&dh, w1, h1, w, h, 2.0).unwrap().to_vec();
    want.iter_mut().for_each(|v| *v = v.clamp(-3.5, 10.7));
    let got = one_direction(&left.data, &right.data, w, h, &p, &chans, 0).unwrap();
    assert!(same(&got.disp, &want), "two levels");
}

#[test]
fn newton_step_gives_no_weight_below_half_the_tuned_frequency() {
    // Both pixels marked stable and far above the amplitude floor, so the joint local frequency
    // k = arg(f_l + f_r) alone decides (A.5 step 3e: k_x >= k0 / 2). The left phasors forced to
    // a frequency of 0.45 k0 (dominating the right's): no weight and no update anywhere; forced
    // to k0 itself: the pixels inside the row weigh in.
    let (w, h) = (31usize, 4usize);
    let (left, right) = (texture(w, h, 0.0, 8), texture(w, h, 0.6, 8));
    let chans = channels(&[0.0]);
    let mut ld = level_data(&left.data, w, h, &chans, 1.25, false).unwrap();
    let mut rd = level_data(&right.data, w, h, &chans, 1.25, true).unwrap();
    ld.stable.iter_mut().for_each(|s| *s = 1);
    rd.stable.iter_mut().for_each(|s| *s = 1);
    let cc = level::chan_consts(&chans, &ld, &rd, 0.0);
    let disp = vec![0.6f32; w * h];
    let k0 = cc[0].kx;
    let mut step_at = |k: f32| {
        for y in 0..h {
            let o = level::SUBROWS * y * w;
            for x in 0..w {
                ld.chan[0][o + 2 * w + x] = 1e6 * k.cos();
                ld.chan[0][o + 3 * w + x] = 1e6 * k.sin();
            }
        }
        level::newton_step(&ld, &rd, &cc, &disp).unwrap()
    };
    let (delta, conf) = step_at(0.45 * k0);
    assert!(conf.iter().all(|&c| c == 0.0), "weight below k0 / 2");
    assert!(delta.iter().all(|&d| d == 0.0), "update below k0 / 2");
    let (_, conf) = step_at(k0);
    let weighed = conf.iter().filter(|&&c| c > 0.5).count();
    assert!(
        weighed > w * h * 3 / 4,
        "{weighed} of {} pixels weigh in at k0",
        w * h
    );
}
