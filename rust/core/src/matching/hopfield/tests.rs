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
    let img = Image::filled(400, 200, 0.5);
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
    let out = finish(&v, &v, &dense, &chosen, &p);
    assert_eq!(out.len(), 9);
    assert!(out.iter().all(|m| m.xl - m.xr == 10.25 && m.yl == m.yr));
    // Sparse: 5 agreeing and one outlier; 4 of 5 others agree (exactly the 0.8 share).
    let mut sparse: Vec<Neuron> = (0..5)
        .map(|k| neuron(k, (300 + 2 * k as i32, 100), 10, 0.0, true))
        .collect();
    sparse.push(neuron(5, (310, 100), 20, 0.0, true));
    let chosen: Vec<usize> = (0..sparse.len()).collect();
    let out = finish(&v, &v, &sparse, &chosen, &HopfieldParams::default());
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
    let ok = rescue(&ns, &chosen, &HopfieldParams::default());
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
    let net = Network::new(&ns, &p.weights);
    assert_eq!(disambiguate(&ns, &net, &state, &p), [0, 2, 4, 5, 6]);
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
        let net = Network::new(&ns, &p.weights);
        let out = fallback(&ns, &net, &vec![0; ns.len()], &p);
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
    assert_eq!(rescue(&ns, &chosen, &p), [true; 7]);
    // Without its neighbour the first match stays rejected.
    let alone: Vec<usize> = [0, 2, 3, 4, 5, 6].into();
    assert_eq!(
        rescue(&ns, &alone, &p),
        [false, true, true, true, true, true]
    );
}
