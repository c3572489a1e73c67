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
    let csr = build_weights(&neurons, &p.weights).unwrap();
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
    let d = run_dynamics(&csr, &input, &init, 3, 100).unwrap();
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
    let flat = Image::filled(60, 40, 0.5).unwrap();
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
    // A negative weight, offset or tolerance (agree_tol -1 gave no match at all), named.
    type Set = fn(&mut HopfieldParams);
    let negatives: [(&str, Set); 4] = [
        ("A", |p| p.weights.a = -0.5),
        ("B", |p| p.weights.b = -0.5),
        ("tau_y", |p| p.tau_y = -0.5),
        ("agree_tol", |p| p.agree_tol = -1),
    ];
    for (name, set) in negatives {
        let mut p = params(8);
        set(&mut p);
        match hopfield_match(&l, &r, &p) {
            Err(CoreError::InvalidParameter { name: got, reason }) => {
                assert_eq!(got, name);
                assert!(
                    reason.starts_with("must be finite and >= 0, got -"),
                    "{reason}"
                );
            }
            other => panic!(
                "{name}: expected InvalidParameter, got {:?}",
                other.map(|_| ())
            ),
        }
    }
    let small = Image::filled(20, 30, 0.5).unwrap();
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
                let csr = build_weights(&neurons, &p.weights).unwrap();
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
    let csr = build_weights(&neurons, &p.weights).unwrap();
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

/// A neuron of point `point` at left `(x, y)` with disparity `d` (same row).
fn neuron(point: u32, (x, y): (i32, i32), d: i32, sub: f32, edge_ok: bool) -> Neuron {
    Neuron {
        point,
        xl: x,
        yl: y,
        xr: x - d,
        yr: y,
        sim: 0.9,
        edge_ok,
        halves_fail: u8::from(!edge_ok),
        centre_ok: true,
        sub,
    }
}

#[test]
fn parabola_vertex_is_the_clamped_offset_and_zero_without_a_peak() {
    // Vertex of (-1, 0.5), (0, 1), (1, 0.7): 0.5 (0.5 - 0.7) / (0.5 - 2 + 0.7) = 0.125.
    assert!((parabola(0.5, 1.0, 0.7) - 0.125).abs() < 1e-6);
    assert!((parabola(0.7, 1.0, 0.5) + 0.125).abs() < 1e-6);
    assert_eq!(parabola(1.0, 1.0, 0.5), -0.5);
    // Flat or a valley: no offset.
    assert_eq!(parabola(1.0, 1.0, 1.0), 0.0);
    assert_eq!(parabola(1.0, 0.5, 1.0), 0.0);
}

#[test]
fn initial_state_switches_on_the_best_candidate_at_or_above_s_init() {
    let mut ns = vec![
        neuron(0, (10, 10), 3, 0.0, true),
        neuron(0, (10, 10), 5, 0.0, true),
        neuron(1, (20, 10), 3, 0.0, true),
    ];
    (ns[0].sim, ns[1].sim, ns[2].sim) = (0.8, 0.8, 0.79);
    let p = HopfieldParams::default();
    assert_eq!(initial_state(&ns, &p), [1, 0, 0]);
    let all = HopfieldParams {
        init_best: false,
        ..p
    };
    assert_eq!(initial_state(&ns, &all), [1, 1, 0]);
}

/// Neighbour agreement of [`finish`]: at least `min_agree` agreeing others (the match itself
/// not counted), or, in sparse areas, `agree_share` of the others; matches at `x - (d + sub)`.
#[test]
fn finish_keeps_matches_with_enough_agreeing_neighbours() {
    let img = Image::filled(400, 200, 0.5).unwrap();
    let v = ImageView::from(&img);
    // Dense: 9 matches, each with exactly min_agree = 8 agreeing others.
    let dense: Vec<Neuron> = (0..9)
        .map(|k| neuron(k, (100 + 2 * k as i32, 100), 10, 0.25, true))
        .collect();
    let chosen: Vec<usize> = (0..dense.len()).collect();
    let p = HopfieldParams {
        agree_share: 0.0,
        ..HopfieldParams::default()
    };
    let out = finish(&v, &v, &dense, &chosen, &p).unwrap();
    assert_eq!(out.len(), 9);
    assert!(out.iter().all(|m| m.xl - m.xr == 10.25 && m.yl == m.yr));
    // Sparse: 5 agreeing and one outlier; 4 of 5 others agree (exactly the 0.8 share).
    let mut sparse: Vec<Neuron> = (0..5)
        .map(|k| neuron(k, (300 + 2 * k as i32, 100), 10, 0.0, true))
        .collect();
    sparse.push(neuron(5, (310, 100), 20, 0.0, true));
    let chosen: Vec<usize> = (0..sparse.len()).collect();
    let out = finish(&v, &v, &sparse, &chosen, &HopfieldParams::default()).unwrap();
    let xs: Vec<f32> = out.iter().map(|m| m.xl).collect();
    assert_eq!(xs, [300.0, 302.0, 304.0, 306.0, 308.0]);
}

/// Side rescue: a match failing its left half (centre check passed) is kept when at least
/// `rescue_min` accepted matches lie strictly left of it in the window, all within `agree_tol`
/// of it, their median sub-pixel disparity within `rescue_med`; a match failing the centre
/// check is never rescued. All three limits are met exactly here.
#[test]
fn rescue_keeps_a_half_failure_backed_by_its_side() {
    let side = |x0: i32, first: u32| -> Vec<Neuron> {
        [(x0 - 10, 100), (x0 - 8, 100), (x0 - 6, 104)]
            .iter()
            .enumerate()
            .map(|(k, &xy)| neuron(first + k as u32, xy, 11, -0.25, true))
            .collect()
    };
    let mut ns = vec![neuron(0, (100, 100), 10, 0.0, false)];
    ns.extend(side(100, 1));
    // Same column, other surface: on no side of the left half.
    ns.push(neuron(4, (100, 110), 30, 0.0, true));
    let mut no_centre = neuron(5, (300, 100), 10, 0.0, false);
    no_centre.centre_ok = false;
    ns.push(no_centre);
    ns.extend(side(300, 6));
    let chosen: Vec<usize> = (0..ns.len()).collect();
    let ok = rescue(&ns, &chosen, &HopfieldParams::default()).unwrap();
    assert_eq!(ok, [true, true, true, true, true, false, true, true, true]);
}

/// C.5 disambiguation: a point's single active neuron is kept (not its inactive ones); of
/// several, the one whose vertical disparity is closest to the window's singles' median
/// (here 0), then the higher similarity; none farther than `tau_y` (1 px: kept).
#[test]
fn disambiguation_keeps_singles_and_picks_by_vertical_disparity_then_similarity() {
    let at = |point: u32, x: i32, d: i32, dy: i32, sim: f32| Neuron {
        yr: 100 - dy,
        sim,
        ..neuron(point, (x, 100), d, 0.0, true)
    };
    let ns = vec![
        at(0, 100, 10, 0, 0.9),
        at(0, 100, 12, 0, 0.85),
        at(1, 104, 10, 0, 0.9),
        at(1, 104, 15, 0, 0.8),
        at(2, 108, 10, 0, 0.9),
        at(3, 112, 10, 0, 0.9),
        at(4, 116, 10, 1, 0.9),
        at(4, 116, 12, -2, 0.95),
    ];
    let state = [1, 1, 1, 0, 1, 1, 1, 1];
    let p = HopfieldParams::default();
    let net = Network::new(&ns, &p.weights).unwrap();
    assert_eq!(
        disambiguate(&ns, &net, &state, &p).unwrap(),
        [0, 2, 4, 5, 6]
    );
}

/// C.5 at a half-pixel reference: two singles of vertical disparity 0 and 1 (median 0.5); a
/// conflict of dy 2 and -1, both 1.5 px off, keeps the more similar (dy 2) only where `tau_y`
/// reaches 1.5 (inclusive): not at the default 1 px (a default of 1.5, or `<` for `<=`,
/// survived the tests), nor just under 1.5; of two equally similar, the lower index.
#[test]
fn disambiguation_tolerance_is_inclusive_at_a_half_pixel_reference() {
    let at = |point: u32, x: i32, d: i32, dy: i32, sim: f32| Neuron {
        yr: 100 - dy,
        sim,
        ..neuron(point, (x, 100), d, 0.0, true)
    };
    let ns = vec![
        at(0, 100, 10, 0, 0.9),
        at(1, 104, 10, 1, 0.9),
        at(2, 108, 10, -1, 0.8),
        at(2, 108, 12, 2, 0.9),
    ];
    let state = [1, 1, 1, 1];
    let p = HopfieldParams::default();
    assert_eq!(p.tau_y, 1.0);
    let net = Network::new(&ns, &p.weights).unwrap();
    assert_eq!(disambiguate(&ns, &net, &state, &p).unwrap(), [0, 1]);
    let mut p = HopfieldParams {
        tau_y: 1.5,
        ..HopfieldParams::default()
    };
    assert_eq!(disambiguate(&ns, &net, &state, &p).unwrap(), [0, 1, 3]);
    p.tau_y = 1.499;
    assert_eq!(disambiguate(&ns, &net, &state, &p).unwrap(), [0, 1]);
    // Equal distance and similarity: the lower index.
    let mut tie = ns.clone();
    tie[2].sim = 0.9;
    p.tau_y = 1.5;
    assert_eq!(disambiguate(&tie, &net, &state, &p).unwrap(), [0, 1, 2]);
}

/// C.5 on the right side: left points with one active neuron each but sharing a right pixel
/// are a conflict too, resolved by the same rule (vertical disparity closest to the median of
/// the singles in the 40x40 window, here 0, then the higher similarity; none farther than
/// `tau_y`). Five singles of dy 3 far away make the global median 1: the reference must be the
/// window's. Keeping every such pair (`>= 1` for `== 1` in the held count) and the global median
/// for the local one both survived the tests.
#[test]
fn disambiguation_resolves_a_shared_right_pixel_by_the_same_rule() {
    let at = |point: u32, (x, y): (i32, i32), xr: i32, yr: i32, sim: f32| Neuron {
        xr,
        yr,
        sim,
        ..neuron(point, (x, y), 0, 0.0, true)
    };
    let ns = vec![
        at(0, (100, 100), 90, 100, 0.9),
        at(1, (120, 100), 110, 100, 0.9),
        // Right pixel (120, 100): dy 1 against dy 0; the latter kept.
        at(2, (130, 101), 120, 100, 0.9),
        at(3, (132, 100), 120, 100, 0.8),
        // Right pixel (140, 100): both dy 0; the more similar kept.
        at(4, (150, 100), 140, 100, 0.8),
        at(5, (160, 100), 140, 100, 0.9),
        // Right pixel (170, 100): dy 3 and -2, both beyond tau_y of their references: none.
        at(6, (180, 103), 170, 100, 0.9),
        at(7, (185, 98), 170, 100, 0.9),
    ];
    let far = (0..5).map(|i| {
        at(
            8 + i,
            (400 + 5 * i as i32, 100),
            380 + 5 * i as i32,
            97,
            0.9,
        )
    });
    let ns: Vec<Neuron> = ns.into_iter().chain(far).collect();
    let state = [1u8; 13];
    let p = HopfieldParams::default();
    let net = Network::new(&ns, &p.weights).unwrap();
    assert_eq!(
        disambiguate(&ns, &net, &state, &p).unwrap(),
        [0, 1, 3, 5, 8, 9, 10, 11, 12]
    );
}

/// `right = 0.5 left(x + d) + 0.2` (an exposure offset): the centre check, on window-mean-free
/// grey levels, passes at the true disparity.
#[test]
fn centre_check_ignores_an_exposure_offset() {
    let (l, r) = shifted_pair(120, 80, 6);
    let scale = |img: &Image, off: f32| {
        Image::new(
            img.width,
            img.height,
            img.data.iter().map(|v| 0.5 * v + off).collect(),
        )
        .unwrap()
    };
    let (l, r) = (scale(&l, 0.1), scale(&r, 0.3));
    let (_, ns) = candidate_neurons(&l, &r, &params(16)).unwrap();
    let at_true: Vec<&Neuron> = ns.iter().filter(|n| n.dx() == 6).collect();
    assert!(at_true.len() > 50, "{}", at_true.len());
    assert!(at_true.iter().all(|n| n.centre_ok));
}

/// A fractional shift (3.4, 3.6 px: the full window's peak at one integer, a half's at the
/// other): the half-window test accepts a half's best within `edge_tol` = 1 px either way.
#[test]
fn half_window_test_accepts_a_best_one_pixel_away() {
    for wt in [0.6f32, 0.4] {
        let (w, h) = (120, 80);
        let base = texture(w + 5, h, 11);
        let l: Vec<f32> = (0..w * h)
            .map(|i| base[(i / w) * (w + 5) + i % w])
            .collect();
        let r: Vec<f32> = (0..w * h)
            .map(|i| {
                let o = (i / w) * (w + 5) + i % w;
                wt * base[o + 3] + (1.0 - wt) * base[o + 4]
            })
            .collect();
        let (l, r) = (Image::new(w, h, l).unwrap(), Image::new(w, h, r).unwrap());
        let p = params(16);
        let (_, ns) = candidate_neurons(&l, &r, &p).unwrap();
        let best: Vec<&Neuron> = ns
            .iter()
            .enumerate()
            .filter(|&(a, n)| a == 0 || ns[a - 1].point != n.point)
            .map(|(_, n)| n)
            .collect();
        let ok = best.iter().filter(|n| n.halves_fail == 0).count();
        // With edge_tol 0, 14 (wt 0.6) and 25 (wt 0.4) of the 451 fail.
        assert!(best.len() > 400);
        assert_eq!(ok, best.len());
    }
}

/// Fallback of thin surfaces: lone points (one candidate, edge test passed, no support, all
/// off) come back when more than `min_agree` = 8 of them (each counting itself) agree.
#[test]
fn group_fallback_needs_more_than_min_agree_agreeing_lone_points() {
    let p = HopfieldParams::default();
    for (n, expect) in [(8u32, 0u8), (9, 1)] {
        let ns: Vec<Neuron> = (0..n)
            .map(|k| neuron(k, (100 + 2 * k as i32, 100), 10, 0.0, true))
            .collect();
        let net = Network::new(&ns, &p.weights).unwrap();
        let out = fallback(&ns, &net, &vec![0; ns.len()], &p).unwrap();
        assert!(out.iter().all(|&s| s == expect), "{n}: {out:?}");
    }
}

/// The sub-pixel offset is computed up to `d = d_hi - 1` (both neighbours of the peak in the
/// range): the same with `d_max` one above the true disparity as with a wide range.
#[test]
fn subpixel_offset_reaches_the_last_disparity_but_one() {
    let (l, r) = shifted_pair(120, 80, 6);
    let (_, narrow) = candidate_neurons(&l, &r, &params(7)).unwrap();
    let (_, wide) = candidate_neurons(&l, &r, &params(16)).unwrap();
    let at6 = |ns: &[Neuron]| -> Vec<(i32, i32, f32)> {
        ns.iter()
            .filter(|n| n.dx() == 6 && n.xl >= 20)
            .map(|n| (n.xl, n.yl, n.sub))
            .collect()
    };
    let (a, b) = (at6(&narrow), at6(&wide));
    assert!(a.len() > 50);
    assert_eq!(a, b);
    assert!(a.iter().any(|t| t.2 != 0.0));
}

/// A one-disparity range (`d_min = d_max`) is searched, not skipped as empty; and a point keeps
/// at most `k_cand` candidates, its best ZNCC first.
#[test]
fn one_disparity_range_is_searched_and_k_cand_cuts_each_point() {
    let (l, r) = shifted_pair(100, 60, 5);
    let one = HopfieldParams {
        d_min: 5,
        d_max: 5,
        ..HopfieldParams::default()
    };
    let (_, ns) = candidate_neurons(&l, &r, &one).unwrap();
    assert!(ns.len() > 50, "{}", ns.len());
    assert!(ns.iter().all(|n| n.dx() == 5));
    // A low s_min gives many points several peaks; k_cand 2 keeps the best two of each.
    let wide = HopfieldParams {
        s_min: 0.0,
        ..params(16)
    };
    let cut = HopfieldParams { k_cand: 2, ..wide };
    let (_, all) = candidate_neurons(&l, &r, &wide).unwrap();
    let (_, kept) = candidate_neurons(&l, &r, &cut).unwrap();
    let groups = |ns: &[Neuron]| -> Vec<Vec<Neuron>> {
        ns.chunk_by(|a, b| a.point == b.point)
            .map(|g| g.to_vec())
            .collect()
    };
    let (ga, gk) = (groups(&all), groups(&kept));
    assert_eq!(ga.len(), gk.len());
    assert!(ga.iter().filter(|g| g.len() > 2).count() > 20);
    for (a, k) in ga.iter().zip(&gk) {
        assert_eq!(&a[..a.len().min(2)], &k[..]);
    }
}

/// The sub-pixel offset is computed from `d = 1` on (its lower neighbour, `d = 0`, is in the
/// range): matches of a 1-px shift get a parabola offset, not 0.
#[test]
fn subpixel_offset_starts_at_disparity_one() {
    let (l, r) = shifted_pair(100, 60, 1);
    let (_, ns) = candidate_neurons(&l, &r, &params(8)).unwrap();
    let at1: Vec<f32> = ns.iter().filter(|n| n.dx() == 1).map(|n| n.sub).collect();
    assert!(at1.len() > 50, "{}", at1.len());
    assert!(at1.iter().filter(|&&s| s != 0.0).count() * 2 > at1.len());
}

/// The side rescue iterates to a fixed point: a match whose side holds too few accepted
/// matches (2 of `rescue_min` 3) is rescued once a neighbour on that side is rescued in an
/// earlier round (window half-size 5 px: the neighbour's own backers lie outside its window).
#[test]
fn rescue_repeats_until_no_match_is_added() {
    let mut ns = vec![
        neuron(0, (94, 100), 10, 0.0, false), // needs (90, 100) rescued first
        neuron(1, (90, 100), 10, 0.0, false),
    ];
    for (k, xy) in [(85, 100), (86, 100), (87, 100), (89, 99), (89, 101)]
        .into_iter()
        .enumerate()
    {
        ns.push(neuron(2 + k as u32, xy, 10, 0.0, true));
    }
    let mut p = HopfieldParams::default();
    p.weights.nbr_half = 5;
    let chosen: Vec<usize> = (0..ns.len()).collect();
    assert_eq!(rescue(&ns, &chosen, &p).unwrap(), [true; 7]);
    // Without its neighbour the first match stays rejected.
    let alone: Vec<usize> = [0, 2, 3, 4, 5, 6].into();
    assert_eq!(
        rescue(&ns, &alone, &p).unwrap(),
        [false, true, true, true, true, true]
    );
}

/// [`texture`] quantised to sixteenths: window sums are exact, so equal windows give
/// bit-identical ZNCC values and means.
fn quantised(w: usize, h: usize, seed: u64) -> Vec<f32> {
    texture(w, h, seed)
        .into_iter()
        .map(|v| (v * 16.0).round() / 16.0)
        .collect()
}

/// The candidates of one left point `(x, y)` by [`point_candidates`], in points mode against
/// every column of the rows `y - dy_window ..= y + dy_window` (all disparities offered).
fn one_point(l: &Image, r: &Image, p: &HopfieldParams, (x, y): (u32, u32)) -> Vec<Neuron> {
    let (lv, rv) = (ImageView::from(l), ImageView::from(r));
    let stats = RightStats::new(&rv);
    let rows: HashMap<usize, Vec<usize>> = (y as usize - p.dy_window..=y as usize + p.dy_window)
        .map(|yr| (yr, (0..x as usize).collect()))
        .collect();
    let pt = InterestPoint { x, y, value: 1.0 };
    let mut sc = CandScratch::default();
    point_candidates(&lv, &rv, &stats, &rows, p, 0, &pt, &mut sc);
    sc.found
}

/// Points mode keeps a right point whose ZNCC equals `s_min` exactly (`>=`): with `s_min` set
/// to each candidate's similarity, the candidates are those at or above it.
#[test]
fn points_mode_keeps_a_candidate_at_exactly_s_min() {
    let (l, r) = shifted_pair(80, 40, 5);
    let all_p = HopfieldParams {
        candidates: CandidateMode::Points,
        s_min: -1.0,
        k_cand: 1000,
        ..params(30)
    };
    let all = one_point(&l, &r, &all_p, (50, 20));
    assert!(all.len() > 50, "{}", all.len());
    for v in [all[0].sim, all[3].sim, all[10].sim] {
        let p = HopfieldParams {
            s_min: v,
            ..all_p.clone()
        };
        let want: Vec<Neuron> = all.iter().copied().filter(|n| n.sim >= v).collect();
        assert_eq!(one_point(&l, &r, &p, (50, 20)), want, "s_min {v}");
    }
}

/// Candidates of equal similarity (a texture periodic in x, period 8, and in y, period 2) are
/// ordered by `xr`, then by `yr`, both ascending.
#[test]
fn tied_candidates_are_ordered_by_xr_then_yr() {
    let (w, h) = (90, 30);
    let tile = quantised(8, 2, 3);
    let img = |shift: usize| -> Image {
        let v = (0..w * h)
            .map(|i| tile[(i / w % 2) * 8 + (i % w + shift) % 8])
            .collect();
        Image::new(w, h, v).unwrap()
    };
    let (l, r) = (img(0), img(3));
    for mode in [CandidateMode::Row, CandidateMode::Points] {
        let p = HopfieldParams {
            candidates: mode,
            s_min: 0.5,
            k_cand: 1000,
            ..params(40)
        };
        let ns = one_point(&l, &r, &p, (60, 15));
        let key = |n: &Neuron| (-n.sim, n.xr, n.yr);
        let xr_ties = ns
            .windows(2)
            .filter(|w| w[0].sim == w[1].sim && w[0].xr != w[1].xr)
            .count();
        assert!(xr_ties >= 3, "{mode:?}: {ns:?}");
        if mode == CandidateMode::Points {
            let yr_ties = ns
                .windows(2)
                .filter(|w| w[0].sim == w[1].sim && w[0].xr == w[1].xr)
                .count();
            assert!(yr_ties >= 3, "{ns:?}");
        }
        for w in ns.windows(2) {
            assert!(
                key(&w[0]) < key(&w[1]),
                "{mode:?}: {:?} then {:?}",
                w[0],
                w[1]
            );
        }
    }
}

/// The centre check allows a difference equal to `centre_tol` (`<=`): at the true disparity of
/// an exact shift the windows are equal, the difference is 0, and `centre_tol` 0 passes.
#[test]
fn centre_check_passes_a_difference_equal_to_the_tolerance() {
    let (w, h, s) = (100, 50, 6);
    let base = quantised(w + s, h, 7);
    let crop = |o: usize| -> Image {
        let v = (0..w * h)
            .map(|i| base[(i / w) * (w + s) + i % w + o])
            .collect();
        Image::new(w, h, v).unwrap()
    };
    let (l, r) = (crop(0), crop(s));
    let p = HopfieldParams {
        centre_tol: 0.0,
        s_min: 0.0,
        ..params(16)
    };
    let (_, ns) = candidate_neurons(&l, &r, &p).unwrap();
    let at_true: Vec<&Neuron> = ns.iter().filter(|n| n.dx() == s as i32).collect();
    assert!(at_true.len() > 50, "{}", at_true.len());
    assert!(at_true.iter().all(|n| n.centre_ok));
    // Elsewhere the centre pixels differ.
    assert!(ns.iter().any(|n| !n.centre_ok));
}

/// The half-window verdict, similarity and sub-pixel offset of every candidate equal their
/// definition on the ZNCC curves: a half fails when its best over `d_min..=d_hi` is not
/// positive (a textureless half: the left quarter of the image is flat) or when its best within
/// `edge_tol` of the candidate, clipped to the range, is more than `edge_margin` below it.
#[test]
fn half_window_verdicts_equal_the_definition() {
    let (w, h, s) = (100, 40, 6);
    let mut base = quantised(w + s, h, 5);
    for (i, v) in base.iter_mut().enumerate() {
        if i % (w + s) < 30 {
            *v = 0.5;
        }
    }
    let crop = |o: usize| -> Image {
        let v = (0..w * h)
            .map(|i| base[(i / w) * (w + s) + i % w + o])
            .collect();
        Image::new(w, h, v).unwrap()
    };
    let (l, r) = (crop(0), crop(s));
    let (lv, rv) = (ImageView::from(&l), ImageView::from(&r));
    let stats = RightStats::new(&rv);
    let pts: Vec<InterestPoint> = (3..h as u32 - 3)
        .flat_map(|y| (3..w as u32 - 3).map(move |x| InterestPoint { x, y, value: 1.0 }))
        .collect();
    let configs = [
        params(16),
        HopfieldParams {
            d_min: s + 1,
            s_min: 0.0,
            ..params(16)
        },
        HopfieldParams {
            edge_tol: 0,
            s_min: 0.3,
            ..params(16)
        },
        HopfieldParams {
            edge_margin: 0.1,
            s_min: 0.3,
            ..params(16)
        },
    ];
    let mut textureless = 0;
    for p in &configs {
        let ns = candidates(&lv, &rv, &pts, p).unwrap();
        assert!(ns.len() > 500, "{}", ns.len());
        let mut cv = Curves::default();
        for n in &ns {
            let (x, y, d) = (n.xl as usize, n.yl as usize, n.dx() as usize);
            let d_hi = p.d_max.min(x - SIM_RADIUS);
            zncc_curves(&lv, &rv, &stats, x, y, n.yr as usize, d_hi, &mut cv);
            let top = |k: usize, a: usize, b: usize| {
                cv.curve[k][a..=b].iter().copied().fold(f32::MIN, f32::max)
            };
            let lo = d.saturating_sub(p.edge_tol).max(p.d_min);
            let hi = (d + p.edge_tol).min(d_hi);
            let mut want = 0u8;
            for k in 0..4 {
                let best = top(k + 1, p.d_min, d_hi);
                textureless += usize::from(best == 0.0);
                if !(best > 0.0 && top(k + 1, lo, hi) >= best - p.edge_margin) {
                    want |= 1 << k;
                }
            }
            let full = &cv.curve[FULL];
            let sub = if d >= 1 && d < d_hi {
                parabola(full[d - 1], full[d], full[d + 1])
            } else {
                0.0
            };
            assert_eq!(
                (n.halves_fail, n.sim, n.sub),
                (want, full[d], sub),
                "{n:?} {p:?}"
            );
            assert_eq!(n.edge_ok, want == 0 && n.centre_ok);
        }
    }
    assert!(textureless > 10, "{textureless}");
}

/// The rescue compares the side's median with the match's sub-pixel disparity: side at 11.0,
/// match at 10 + 0.4 (0.6 away: kept; its integer disparity is 1.0 away).
#[test]
fn rescue_compares_the_side_median_with_the_subpixel_disparity() {
    let mut ns = vec![neuron(0, (100, 100), 10, 0.4, false)];
    for (k, xy) in [(90, 100), (92, 100), (94, 104)].into_iter().enumerate() {
        ns.push(neuron(1 + k as u32, xy, 11, 0.0, true));
    }
    let chosen: Vec<usize> = (0..ns.len()).collect();
    assert_eq!(
        rescue(&ns, &chosen, &HopfieldParams::default()).unwrap(),
        [true; 4]
    );
}

/// Sparse areas: exactly `min_agree_sparse` = 2 agreeing neighbours (all of them) suffice.
#[test]
fn finish_keeps_sparse_matches_with_exactly_min_agree_sparse_neighbours() {
    let img = Image::filled(400, 200, 0.5).unwrap();
    let v = ImageView::from(&img);
    let ns: Vec<Neuron> = (0..3)
        .map(|k| neuron(k, (300 + 2 * k as i32, 100), 10, 0.0, true))
        .collect();
    let out = finish(&v, &v, &ns, &[0, 1, 2], &HopfieldParams::default()).unwrap();
    assert_eq!(out.len(), 3);
}

/// A conflict far from every single match (none in its window) is resolved against the median
/// vertical disparity of all singles (2 here), not 0: the lower-similarity candidate at dy 2.
#[test]
fn disambiguation_without_local_singles_uses_the_global_median() {
    let at = |point: u32, x: i32, dy: i32, sim: f32| Neuron {
        yr: 100 - dy,
        sim,
        ..neuron(point, (x, 100), 10, 0.0, true)
    };
    let ns = vec![
        at(0, 300, 2, 0.9),
        at(1, 304, 2, 0.9),
        at(2, 308, 1, 0.9),
        at(3, 100, 0, 0.95),
        at(3, 100, 2, 0.85),
    ];
    let p = HopfieldParams::default();
    let net = Network::new(&ns, &p.weights).unwrap();
    assert_eq!(
        disambiguate(&ns, &net, &[1, 1, 1, 1, 1], &p).unwrap(),
        [0, 1, 2, 4]
    );
}

/// Fallback thresholds at equality: an active alternative with support equal to
/// `fallback_alt_support` is not weak (`<`); a best candidate with support equal to
/// `fallback_min_support` is (`>=`). Both supports are 0 (no other active neuron).
#[test]
fn fallback_support_thresholds_at_equality() {
    let p = HopfieldParams {
        fallback_alt_support: 0.0,
        fallback_min_support: 0.0,
        fallback_group: false,
        ..HopfieldParams::default()
    };
    let ns = vec![
        neuron(0, (100, 100), 10, 0.0, true),
        neuron(0, (100, 100), 30, 0.0, true),
    ];
    let net = Network::new(&ns, &p.weights).unwrap();
    assert_eq!(fallback(&ns, &net, &[0, 1], &p).unwrap(), [0, 1]);
    let one = vec![neuron(0, (100, 100), 10, 0.0, true)];
    let net = Network::new(&one, &p.weights).unwrap();
    assert_eq!(fallback(&one, &net, &[0], &p).unwrap(), [1]);
}

/// The group fallback takes lone points only: one candidate that passed the edge test. Ten
/// agreeing points, all off; the first fails the edge test, or has a second candidate: it stays
/// off, the other nine (more than `min_agree` = 8) come back.
#[test]
fn group_fallback_skips_edge_failures_and_points_with_several_candidates() {
    let p = HopfieldParams::default();
    let row = || -> Vec<Neuron> {
        (0..10)
            .map(|k| neuron(k, (100 + 2 * k as i32, 100), 10, 0.0, true))
            .collect()
    };
    let mut edge = row();
    edge[0].edge_ok = false;
    let net = Network::new(&edge, &p.weights).unwrap();
    let out = fallback(&edge, &net, &[0; 10], &p).unwrap();
    assert_eq!(out, [0, 1, 1, 1, 1, 1, 1, 1, 1, 1]);
    let mut two = row();
    two.insert(1, neuron(0, (100, 100), 30, 0.0, true));
    let net = Network::new(&two, &p.weights).unwrap();
    let out = fallback(&two, &net, &[0; 11], &p).unwrap();
    assert_eq!(out, [0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1]);
}

/// Run by [`network_tables_too_large_to_allocate_are_an_error`] in a child process: 2^20
/// neurons, each its own point, under an address-space limit of 4 MiB more than is mapped: the
/// network's point starts (8 bytes a point) do not fit.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of network_tables_too_large_to_allocate_are_an_error"]
fn network_tables_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let neurons: Vec<Neuron> = (0..1u32 << 20)
        .map(|a| {
            let (x, y) = ((a % 1024) as i32, (a / 1024) as i32);
            Neuron {
                point: a,
                xl: x,
                yl: y,
                xr: x,
                yr: y,
                sim: 0.8,
                edge_ok: true,
                halves_fail: 0,
                centre_ok: true,
                sub: 0.0,
            }
        })
        .collect();
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (4 << 20));
    match Network::new(&neurons, &HopfieldParams::default().weights) {
        Ok(net) => println!("child: network of {}", net.n()),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn network_tables_too_large_to_allocate_are_an_error() {
    // Network::new built its per-point and per-neuron tables (starts, coordinates, the padded
    // cell arrays, slots) with push/collect/vec!: a failed allocation aborted the process
    // (SIGABRT) instead of returning OutOfMemory.
    let stdout = crate::segment::tests::run_oom_child(
        "matching::hopfield::tests::network_tables_under_a_memory_limit",
    );
    let want = "child: error: out of memory: the Hopfield network's tables needs 8.00 MiB \
                (8388616 bytes)";
    assert!(stdout.contains(want), "{want} not in {stdout}");
}

/// Run by [`dynamics_arrays_too_large_to_allocate_are_an_error`] in a child process: 2^20
/// neurons without weights under an address-space limit of 19 MiB more than is mapped. The
/// state and the initial net inputs (17 MiB at the peak) fit; the slot-ordered net inputs
/// (8 MiB) after the slots (4 MiB) do not.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of dynamics_arrays_too_large_to_allocate_are_an_error"]
fn dynamics_arrays_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let m = 1usize << 20;
    let csr = Csr {
        indptr: vec![0; m + 1],
        ..Csr::default()
    };
    let (input, init) = (vec![0.5f64; m], vec![0u8; m]);
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (19 << 20));
    match run_dynamics(&csr, &input, &init, 1, 10) {
        Ok(d) => println!("child: {} sweeps", d.sweeps),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn dynamics_arrays_too_large_to_allocate_are_an_error() {
    // run_dynamics allocated its slot-ordered arrays with vec!/collect/clone: a failed
    // allocation aborted the process (SIGABRT) instead of returning OutOfMemory.
    let stdout = crate::segment::tests::run_oom_child(
        "matching::hopfield::tests::dynamics_arrays_under_a_memory_limit",
    );
    let want = "child: error: out of memory: the Hopfield dynamics' slot arrays needs 8.00 MiB \
                (8388608 bytes)";
    assert!(stdout.contains(want), "{want} not in {stdout}");
}

/// 2^20 neurons, each its own point 1 px from the next (no weights between them; see
/// [`network_tables_under_a_memory_limit`]).
#[cfg(target_os = "linux")]
fn lone_neurons() -> Vec<Neuron> {
    lone_neurons_in(1024)
}

/// [`lone_neurons`] in `rows` rows of 1024.
#[cfg(target_os = "linux")]
fn lone_neurons_in(rows: u32) -> Vec<Neuron> {
    (0..rows << 10)
        .map(|a| {
            let (x, y) = ((a % 1024) as i32, (a / 1024) as i32);
            Neuron {
                point: a,
                xl: x,
                yl: y,
                xr: x,
                yr: y,
                sim: 0.8,
                edge_ok: true,
                halves_fail: 0,
                centre_ok: true,
                sub: 0.0,
            }
        })
        .collect()
}

/// Run by [`initial_net_inputs_too_large_to_allocate_are_an_error`] in a child process:
/// 2^18 neurons (stored weights, then the channel's implicit ones: building their network in
/// debug code is most of the child's time) under an address-space limit of 0.75 MiB more than
/// is mapped. The state (0.25 MiB) fits; the initial net inputs (2 MiB, the implicit weights'
/// lane states 1 MiB first) do not.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of initial_net_inputs_too_large_to_allocate_are_an_error"]
fn initial_net_inputs_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let m = 1usize << 18;
    let (input, init) = (vec![0.5f64; m], vec![0u8; m]);
    let implicit = std::env::var_os("SV_OOM_IMPLICIT").is_some();
    let net =
        implicit.then(|| Network::new(&lone_neurons_in(256), &HopfieldParams::default().weights));
    let csr = Csr {
        indptr: vec![0; m + 1],
        ..Csr::default()
    };
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (3 << 18));
    let got = match net {
        Some(net) => run_dynamics(&net.unwrap(), &input, &init, 1, 10),
        None => run_dynamics(&csr, &input, &init, 1, 10),
    };
    match got {
        Ok(d) => println!("child: {} sweeps", d.sweeps),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn initial_net_inputs_too_large_to_allocate_are_an_error() {
    // run_dynamics checked its slot-ordered arrays, but the initial net inputs before them
    // (Weights::initial_input: the sums and entry counts, 16 bytes a neuron stored; lane
    // states, slot-ordered sums and push buffers implicit) were still allocated unchecked: a
    // failed allocation aborted the process (SIGABRT) instead of returning OutOfMemory.
    for (implicit, size) in [
        (false, "2.00 MiB (2097152 bytes)"),
        (true, "1.00 MiB (1048608 bytes)"),
    ] {
        let stdout = crate::segment::tests::run_oom_child_with(
            "matching::hopfield::tests::initial_net_inputs_under_a_memory_limit",
            implicit.then_some(("SV_OOM_IMPLICIT", "1")),
        );
        let want = format!(
            "child: error: out of memory: the Hopfield dynamics' initial net inputs needs {size}"
        );
        assert!(
            stdout.contains(&want),
            "implicit {implicit}: {want} not in {stdout}"
        );
    }
}

/// Run by [`network_orders_too_large_to_allocate_are_an_error`] in a child process: 2^18
/// lone neurons (256 rows of 1024: building their network in debug code is most of the
/// child's time) under an address-space limit of `SV_OOM_MIB` MiB more than is mapped. The
/// checked per-point and per-neuron tables before the orders take 7 MiB; then (one rayon
/// thread) the strip order (1 MiB sorts, 1 MiB coordinates), the point windows (14 MiB) and
/// the right-pixel groups (2 MiB indices and keys, 1 MiB order, 2 + 1 MiB groups and ranks).
/// Measured: the strip order fails at 7.5 to 11 MiB, the point windows at 12 to 24, the
/// groups' 2 MiB at 24.5 to 26.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of network_orders_too_large_to_allocate_are_an_error"]
fn network_orders_under_a_memory_limit() {
    let Some(mib) = std::env::var_os("SV_OOM_MIB") else {
        return;
    };
    let mib: f64 = mib.to_str().unwrap().parse().unwrap();
    let neurons = lone_neurons_in(256);
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(
        crate::segment::tests::vm_size() + (mib * f64::from(1 << 20)) as usize,
    );
    match Network::new(&neurons, &HopfieldParams::default().weights) {
        Ok(net) => println!("child: network of {}", net.n()),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn network_orders_too_large_to_allocate_are_an_error() {
    // Network::new checked its cell arrays, slots and window ranges, but the strip order
    // (counting sorts, strip coordinates), the point windows and the right-pixel groups before
    // them (about 90 bytes a neuron) were still allocated unchecked: a failed allocation
    // aborted the process (SIGABRT) instead of returning OutOfMemory.
    for (mib, want) in [
        (
            "8.5",
            "the Hopfield network's strip order needs 1.00 MiB (1048576 bytes)",
        ),
        (
            "17.5",
            "the Hopfield network's point windows needs 14.00 MiB (14680064 bytes)",
        ),
        (
            "25.25",
            "the Hopfield network's right-pixel groups needs 2.00 MiB (2097152 bytes)",
        ),
    ] {
        let stdout = crate::segment::tests::run_oom_child_with(
            "matching::hopfield::tests::network_orders_under_a_memory_limit",
            Some(("SV_OOM_MIB", mib)),
        );
        let want = format!("child: error: out of memory: {want}");
        assert!(stdout.contains(&want), "{mib} MiB: {want} not in {stdout}");
    }
}

/// Run by [`final_stages_too_large_to_allocate_are_an_error`] in a child process: the final
/// selection and the depth-edge filters of 2^18 lone neurons (256 rows of 1024: building
/// their network in debug code is most of the child's time, done once, on a pool of its own,
/// before a fork per limit), all on (the network built before), under an address-space limit
/// of each of the comma-separated `SV_OOM_MIB` MiB more than is mapped. Measured in the
/// forks (half-MiB steps): the selection fails at 0.25 to 5.5 MiB, the point grid at 6 to
/// 7.5, the filters at 8 to 15 (one process a limit: 0.25 to 4, 6, 8 to 14).
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of final_stages_too_large_to_allocate_are_an_error"]
fn final_stages_under_a_memory_limit() {
    let Some(mibs) = std::env::var_os("SV_OOM_MIB") else {
        return;
    };
    let neurons = lone_neurons_in(256);
    let p = HopfieldParams::default();
    // Not on the global pool: a fork would wait on its thread, which the fork has not.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let net = pool.install(|| Network::new(&neurons, &p.weights)).unwrap();
    let state = vec![1u8; neurons.len()];
    let img = vec![0.0f32; 4];
    let v = ImageView::new(2, 2, &img).unwrap();
    for mib in mibs.to_str().unwrap().split(',') {
        crate::segment::tests::in_a_fork(|| {
            let limit: f64 = mib.parse().unwrap();
            rayon::join(|| (), || ()); // the pool's thread started before the limit
            crate::segment::tests::limit_address_space(
                crate::segment::tests::vm_size() + (limit * f64::from(1 << 20)) as usize,
            );
            let run = || -> Result<usize> {
                let selected = fallback(&neurons, &net, &state, &p)?;
                let chosen = disambiguate(&neurons, &net, &selected, &p)?;
                Ok(finish(&v, &v, &neurons, &chosen, &p)?.len())
            };
            match run() {
                Ok(n) => println!("child: {mib} MiB: {n} matches"),
                Err(e) => println!("child: {mib} MiB: error: {e}"),
            }
        });
    }
}

#[cfg(target_os = "linux")]
#[test]
fn final_stages_too_large_to_allocate_are_an_error() {
    // The stages after the dynamics (fallback, disambiguation, the rescue and the neighbour
    // agreement) built their per-neuron, per-point and per-match lists and their point grids
    // (PointGrid::new) with collect/vec!/push: a failed allocation aborted the process
    // (SIGABRT) instead of returning OutOfMemory.
    let stdout = crate::segment::tests::run_oom_child_with(
        "matching::hopfield::tests::final_stages_under_a_memory_limit",
        Some(("SV_OOM_MIB", "0.25,6,10")),
    );
    for (mib, want) in [
        ("0.25", "the Hopfield matcher's final selection needs "),
        ("6", "the Hopfield matcher's point grid needs "),
        ("10", "the Hopfield matcher's depth-edge filters needs "),
    ] {
        let want = format!("child: {mib} MiB: error: out of memory: {want}");
        assert!(stdout.contains(&want), "{want} not in {stdout}");
    }
}

/// Run by [`a_compatibility_table_too_large_to_allocate_is_an_error`] in a child process: two
/// points with a disparity span of 2048 px and a compatibility that never saturates
/// (`compat_slope` 0: 21 rows of 2^22 + 1 entries, 352 MiB) under an address-space limit of
/// 64 MiB more than is mapped.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of a_compatibility_table_too_large_to_allocate_is_an_error"]
fn compatibility_table_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let mut neurons = lone_neurons();
    neurons.truncate(2);
    neurons[0].xl = 2048;
    let w = EnergyWeights {
        compat_slope: 0.0,
        ..HopfieldParams::default().weights
    };
    rayon::join(|| (), || ()); // the pool's thread started before the limit
    crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (64 << 20));
    match Network::new(&neurons, &w) {
        Ok(net) => println!("child: network of {}", net.n()),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn a_compatibility_table_too_large_to_allocate_is_an_error() {
    // Network::new built the compatibility table (one row per window distance, as long as the
    // squared disparity span where the values do not saturate) with push/collect: a failed
    // allocation aborted the process (SIGABRT) instead of returning OutOfMemory.
    let stdout = crate::segment::tests::run_oom_child(
        "matching::hopfield::tests::compatibility_table_under_a_memory_limit",
    );
    let want = "child: error: out of memory: the Hopfield network's compatibility table needs ";
    assert!(stdout.contains(want), "{want} not in {stdout}");
}

/// `rows_of` holds the same lists as the `entry().or_default().push()` it replaced, in point
/// order, also for points not in raster order (a row met twice).
#[test]
fn rows_of_lists_each_rows_points_in_order() {
    let pt = |x: u32, y: u32| InterestPoint { x, y, value: 1.0 };
    let pts = [pt(5, 2), pt(9, 2), pt(1, 7), pt(3, 2), pt(4, 7), pt(0, 0)];
    let got = rows_of(&pts).unwrap();
    let mut want: HashMap<usize, Vec<usize>> = HashMap::new();
    for p in &pts {
        want.entry(p.y as usize).or_default().push(p.x as usize);
    }
    assert_eq!(got, want);
    assert_eq!(got[&2], [5, 9, 3]);
    assert!(rows_of(&[]).unwrap().is_empty());
}

/// Run by [`right_rows_too_large_to_allocate_are_an_error`] in a child process: 2^20 right
/// points, one a row (their map: 32 MiB of entries), under an address-space limit of 8 MiB
/// more than is mapped.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "a child of right_rows_too_large_to_allocate_are_an_error"]
fn right_rows_under_a_memory_limit() {
    if std::env::var_os("SV_OOM_CHILD").is_none() {
        return;
    }
    let pts: Vec<InterestPoint> = (0..1u32 << 20)
        .map(|y| InterestPoint {
            x: 1,
            y,
            value: 1.0,
        })
        .collect();
    crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (8 << 20));
    match rows_of(&pts) {
        Ok(rows) => println!("child: {} rows", rows.len()),
        Err(e) => println!("child: error: {e}"),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn right_rows_too_large_to_allocate_are_an_error() {
    // Points mode built its rows map with entry().or_default().push(): a failed allocation
    // aborted the process (SIGABRT) instead of returning OutOfMemory.
    let stdout = crate::segment::tests::run_oom_child(
        "matching::hopfield::tests::right_rows_under_a_memory_limit",
    );
    let want = "child: error: out of memory: the Hopfield matcher's right points by row needs \
                32.00 MiB (33554432 bytes)";
    assert!(stdout.contains(want), "{want} not in {stdout}");
}

/// A window past every pixel is the whole image, up to `usize::MAX`: the NMS, the half-window
/// tolerance and the points mode's band added their size to a coordinate (`x + nms_half`,
/// `d + edge_tol`, `y + dy_window`), which wrapped (a panic in a debug build) to a window
/// ending before the point itself: 412 interest points instead of 1 on a teddy crop, and no
/// match at all for `edge_tol` or `dy_window` = 2^64 - 1, values the binding accepts.
#[test]
fn windows_wider_than_the_image_cover_it_up_to_usize_max() {
    let (l, r) = shifted_pair(120, 45, 7);
    let pts = |nms_half: usize| {
        let p = InterestParams {
            nms_half,
            ..InterestParams::default()
        };
        interest_points(&l, &p).unwrap()
    };
    // One window over the image keeps its largest M only (earlier ties are suppressed).
    let whole = pts(10_000);
    assert_eq!(whole.len(), 1);
    assert_eq!(pts(usize::MAX), whole);
    assert_eq!(pts(usize::MAX / 2 + 1), whole);
    for (mode, wide) in [
        // Half-window tolerance past the disparity range: only the halves' textures decide.
        (
            CandidateMode::Row,
            HopfieldParams {
                edge_tol: 10_000,
                ..params(16)
            },
        ),
        // Points mode's band over every row.
        (
            CandidateMode::Points,
            HopfieldParams {
                candidates: CandidateMode::Points,
                dy_window: 10_000,
                ..params(16)
            },
        ),
    ] {
        let huge = HopfieldParams {
            edge_tol: if wide.edge_tol > 1 { usize::MAX } else { 1 },
            dy_window: if wide.dy_window > 2 { usize::MAX } else { 2 },
            ..wide.clone()
        };
        let (_, want) = candidate_neurons(&l, &r, &wide).unwrap();
        assert!(want.len() > 100, "{mode:?}: {} neurons", want.len());
        let (_, got) = candidate_neurons(&l, &r, &huge).unwrap();
        assert_eq!(got, want, "{mode:?}");
        let (a, b) = (
            hopfield_match(&l, &r, &wide).unwrap(),
            hopfield_match(&l, &r, &huge).unwrap(),
        );
        assert!(
            a.matches.len() > 100,
            "{mode:?}: {} matches",
            a.matches.len()
        );
        assert_eq!(a.matches, b.matches, "{mode:?}");
    }
}

/// An undefined ZNCC (a textureless window, read as 0) is no candidate at any `s_min`: with
/// `s_min <= 0` (accepted) a flat right image gave every left point a candidate of score 0,
/// and `best_match` a "match" for each with the edge test off.
#[test]
fn textureless_right_windows_are_no_candidates_at_any_s_min() {
    let (l, r) = shifted_pair(120, 60, 3);
    let flat = Image::new(120, 60, vec![0.5; 120 * 60]).unwrap();
    // The right image flat over columns 40..70: windows centred in 43..67 lie inside it.
    let mut band = r.clone();
    for row in band.data.chunks_mut(120) {
        row[40..70].fill(0.5);
    }
    for s_min in [0.0, -1.0] {
        let p = HopfieldParams {
            s_min,
            s_init: 0.0,
            edge_test: false,
            ..params(16)
        };
        let (pts, ns) = candidate_neurons(&l, &flat, &p).unwrap();
        assert!(pts.len() > 50, "{} points", pts.len());
        assert!(ns.is_empty(), "s_min {s_min}: {} candidates", ns.len());
        assert!(best_match(&l, &flat, &p).unwrap().matches.is_empty());
        assert!(hopfield_match(&l, &flat, &p).unwrap().matches.is_empty());
        let (_, ns) = candidate_neurons(&l, &band, &p).unwrap();
        assert!(ns.len() > 100, "s_min {s_min}: {} candidates", ns.len());
        assert!(
            ns.iter().all(|n| !(43..=66).contains(&n.xr)),
            "s_min {s_min}"
        );
        // Defined negative similarities still pass a negative s_min.
        assert!(
            s_min >= 0.0 || ns.iter().any(|n| n.sim < 0.0),
            "s_min {s_min}"
        );
    }
}
