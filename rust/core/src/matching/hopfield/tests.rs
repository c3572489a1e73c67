use super::network::SplitMix64;
use super::*;
use crate::image::Image;

/// Smooth deterministic texture (3x3 box of hashed noise), `w x h`.
fn texture(w: usize, h: usize, seed: u64) -> Vec<f32> {
    let mut rng = SplitMix64::new(seed);
    let noise: Vec<f32> = (0..(w + 2) * (h + 2))
        .map(|_| (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32)
        .collect();
    let mut out = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut acc = 0.0;
            for dy in 0..3 {
                for dx in 0..3 {
                    acc += noise[(y + dy) * (w + 2) + x + dx];
                }
            }
            out[y * w + x] = acc / 9.0;
        }
    }
    out
}

/// `right(x) = left(x + shift)`: every left point at `x` matches `x - shift`.
fn shifted_pair(w: usize, h: usize, shift: usize) -> (Image, Image) {
    let base = texture(w + shift, h, 11);
    let left: Vec<f32> = (0..w * h)
        .map(|i| base[(i / w) * (w + shift) + i % w])
        .collect();
    let right: Vec<f32> = (0..w * h)
        .map(|i| base[(i / w) * (w + shift) + i % w + shift])
        .collect();
    (
        Image::new(w, h, left).expect("valid"),
        Image::new(w, h, right).expect("valid"),
    )
}

fn params(d_max: usize) -> HopfieldParams {
    HopfieldParams {
        d_max,
        ..HopfieldParams::default()
    }
}

#[test]
fn integer_shift_is_recovered_exactly() {
    let (l, r) = shifted_pair(120, 90, 7);
    let out = hopfield_match(&l, &r, &params(16)).expect("valid input");
    assert!(out.matches.len() > 300, "{} matches", out.matches.len());
    // A parabola through three ZNCC samples is not centred on an exact integer peak when the
    // window's autocorrelation is asymmetric: each match within 0.25 px, on average within 0.05.
    let mut sum = 0.0;
    for m in &out.matches {
        let e = (m.xl - m.xr - 7.0).abs();
        assert!(e < 0.25, "{m:?}");
        assert_eq!(m.yl, m.yr);
        sum += e;
    }
    assert!(sum / (out.matches.len() as f32) < 0.05);
    assert!(out.converged);
}

#[test]
fn energy_is_monotone_and_weights_symmetric() {
    let (l, r) = shifted_pair(100, 80, 4);
    let p = params(16);
    let (_, neurons) = candidate_neurons(&l, &r, &p).expect("valid input");
    let csr = build_weights(&neurons, &p.weights);
    // Symmetry: T_ab == T_ba for every stored entry.
    for a in 0..csr.n() {
        let (idx, val) = csr.row(a);
        for (&b, &t) in idx.iter().zip(val) {
            let (bi, bv) = csr.row(b as usize);
            let back = bi.iter().position(|&x| x as usize == a).map(|k| bv[k]);
            assert_eq!(back, Some(t), "T[{a}][{b}]");
        }
    }
    // Start from everything off: the dynamics must switch neurons on, never raising E.
    let input: Vec<f64> = neurons.iter().map(|n| (n.sim - 0.6) as f64).collect();
    let init = vec![0u8; neurons.len()];
    let d = run_dynamics(&csr, &input, &init, 3, 100);
    assert!(d.converged && d.sweeps >= 2, "{d:?}");
    assert!(d.energy_trace[1] < d.energy_trace[0]);
    for w in d.energy_trace.windows(2) {
        assert!(w[1] <= w[0] + 1e-9 * w[0].abs(), "{:?}", d.energy_trace);
    }
}

#[test]
fn seeded_order_is_reproducible() {
    let mut a = SplitMix64::new(5);
    let mut b = SplitMix64::new(5);
    let mut va: Vec<u32> = (0..50).collect();
    let mut vb = va.clone();
    a.shuffle(&mut va);
    b.shuffle(&mut vb);
    assert_eq!(va, vb);
    let mut sorted = va.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, (0..50).collect::<Vec<u32>>());
    assert_ne!(va, (0..50).collect::<Vec<u32>>());
}

#[test]
fn textureless_and_tiny_images_give_no_matches() {
    let flat = Image::filled(60, 40, 0.5);
    let out = hopfield_match(&flat, &flat, &params(8)).expect("valid input");
    assert!(out.matches.is_empty());
    assert_eq!(out.energy_trace, vec![0.0]);
    let tiny = Image::new(4, 4, vec![0.1; 16]).expect("valid");
    assert!(hopfield_match(&tiny, &tiny, &params(2))
        .expect("valid input")
        .matches
        .is_empty());
}

#[test]
fn bad_parameters_are_errors() {
    let (l, r) = shifted_pair(40, 30, 2);
    let mut p = params(8);
    p.d_min = 9;
    assert!(matches!(
        hopfield_match(&l, &r, &p),
        Err(CoreError::InvalidParameter { .. })
    ));
    let p = HopfieldParams {
        s_min: f32::NAN,
        ..params(8)
    };
    assert!(hopfield_match(&l, &r, &p).is_err());
    // A window beyond any image (1e9 px ran for minutes).
    for half in [0, MAX_NBR_HALF + 1, 1_000_000_000] {
        let mut p = params(8);
        p.weights.nbr_half = half;
        assert!(matches!(
            hopfield_match(&l, &r, &p),
            Err(CoreError::InvalidParameter { .. })
        ));
    }
    // A NaN or negative edge slack / centre tolerance, a share outside [0, 1]: no matches at
    // all (or the sparse rule off) without a word, before these were checked.
    for (margin, tol, share) in [
        (f32::NAN, 0.05, 0.8),
        (-1.0, 0.05, 0.8),
        (0.0, -1.0, 0.8),
        (0.0, f32::NAN, 0.8),
        (0.0, 0.05, f32::NAN),
        (0.0, 0.05, 1.5),
    ] {
        let p = HopfieldParams {
            edge_margin: margin,
            centre_tol: tol,
            agree_share: share,
            ..params(8)
        };
        assert!(matches!(
            hopfield_match(&l, &r, &p),
            Err(CoreError::InvalidParameter { .. })
        ));
    }
    let small = Image::filled(20, 30, 0.5);
    assert!(matches!(
        hopfield_match(&l, &small, &params(8)),
        Err(CoreError::SizeMismatch { .. })
    ));
}

#[test]
fn moravec_corner_and_edges() {
    let mut data = vec![0.0f32; 30 * 30];
    for y in 15..30 {
        for x in 15..30 {
            data[y * 30 + x] = 1.0;
        }
    }
    let img = Image::new(30, 30, data).expect("valid");
    let m = moravec(&img).unwrap();
    assert!(m[15 * 30 + 15] > 0.0);
    assert_eq!(m[25 * 30 + 15], 0.0); // vertical edge: the vertical direction sees nothing
    let pts = interest_points(&img, &InterestParams::default()).unwrap();
    assert!(pts
        .iter()
        .any(|p| p.x.abs_diff(15) <= 2 && p.y.abs_diff(15) <= 2));
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let (l, r) = shifted_pair(300, 200, 9);
    let p = params(32);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
            .install(|| {
                let out = hopfield_match(&l, &r, &p).expect("valid input");
                let (_, neurons) = candidate_neurons(&l, &r, &p).expect("valid input");
                let csr = build_weights(&neurons, &p.weights);
                (
                    out,
                    csr.indptr,
                    csr.indices,
                    csr.data,
                    interest_points(&l, &p.interest).unwrap(),
                )
            })
    };
    let (a, b) = (run(1), run(3));
    assert!(a.0.matches.len() > 500, "{} matches", a.0.matches.len());
    assert_eq!(a.0, b.0);
    assert_eq!((a.1, a.2, a.3), (b.1, b.2, b.3));
    assert_eq!(a.4, b.4);
}

#[test]
fn csr_rows_hold_every_pair_of_the_window_once() {
    // Brute force over all neuron pairs: the entries build_weights must store.
    let (l, r) = shifted_pair(120, 90, 5);
    let p = params(16);
    let (_, neurons) = candidate_neurons(&l, &r, &p).expect("valid input");
    let csr = build_weights(&neurons, &p.weights);
    let half = p.weights.nbr_half;
    for (a, na) in neurons.iter().enumerate() {
        let (idx, _) = csr.row(a);
        let mut got: Vec<u32> = idx.to_vec();
        got.sort_unstable();
        let want: Vec<u32> = (0..neurons.len() as u32)
            .filter(|&b| {
                let nb = &neurons[b as usize];
                let same_point = nb.point == na.point;
                let same_right = (nb.xr, nb.yr) == (na.xr, na.yr);
                let near = (nb.xl - na.xl).abs() <= half && (nb.yl - na.yl).abs() <= half;
                b as usize != a && (same_point || same_right || near)
            })
            .collect();
        assert_eq!(got, want, "row {a}");
    }
}

#[test]
fn median_by_selection_equals_the_sorted_median() {
    let mut rng = SplitMix64::new(5);
    for n in 0..40 {
        let v: Vec<f32> = (0..n)
            .map(|_| ((rng.next_u64() % 41) as f32 - 20.0) * 0.25)
            .collect();
        let mut sorted = v.clone();
        sorted.sort_by(f32::total_cmp);
        let want = match n {
            0 => 0.0,
            _ if n % 2 == 1 => sorted[n / 2],
            _ => 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]),
        };
        assert_eq!(
            super::median(&mut v.clone()).to_bits(),
            want.to_bits(),
            "n = {n}"
        );
    }
}
