//! Hopfield-network stereo matching of interest points (algorithms.md C, with the C.10 changes).
//!
//! Pipeline:
//! 1. Moravec interest points of the left image ([`interest`]: squares, 3x3 NMS, 0.1 % of max).
//! 2. Candidates per left point ([`CandidateMode`]): 7x7 ZNCC peaks along the epipolar row
//!    (default, C.10), or the right image's interest points in the epipolar band (the paper's
//!    point-to-point network, kept as a high-precision option). ZNCC `>= s_min`, best `k_cand`.
//! 3. The sparse binary Hopfield network ([`network`]) over the candidates: compatibility in the
//!    40x40 window (crossing 0 at `compat_theta + compat_grad * distance`), uniqueness on both
//!    sides, similarity input minus `edge_penalty` for depth-edge failures; asynchronous seeded
//!    sweeps from each point's best candidate ([`HopfieldParams::init_best`]) until a sweep
//!    without a flip.
//! 4. Final selection: points the network drops for a weak reason fall back to their best
//!    candidate ([`HopfieldParams::fallback`], and [`HopfieldParams::fallback_group`] for
//!    thin surfaces the window's inhibition removes); disambiguation of points left with several
//!    active candidates (C.5: local median of the vertical disparity of single matches,
//!    tie-break on similarity, both sides).
//! 5. Depth-edge filters (C.10): the four half-windows agree within +-1 px (or, failing that,
//!    the side rescue of [`HopfieldParams::rescue_min`]), centre grey-level check, at least 8
//!    agreeing neighbour matches; parabola sub-pixel refinement.
//!
//! [`best_match`] runs the same pipeline without the network (best ZNCC candidate per point):
//! the reference the network has to beat.

pub mod interest;
pub mod network;
pub mod zncc;

#[cfg(test)]
mod tests;

use std::collections::HashMap;

use rayon::prelude::*;

use crate::alloc::{try_collect, try_concat, try_filled, try_grow, try_reserve_len, try_zeroed};
use crate::error::{CoreError, Result};
use crate::image::ImageView;
use crate::simd::simd_fn;
pub use interest::{interest_points, moravec, InterestParams, InterestPoint};
pub use network::{
    build_weights, run_dynamics, Csr, Dynamics, EnergyWeights, Network, Neuron, Weights,
};
use zncc::{max_of, row_peaks, zncc_curves, Curves, RightStats, FULL, N_REGIONS, SIM_RADIUS};

/// Where the right candidates of a left point come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CandidateMode {
    /// ZNCC peaks along the epipolar row (C.10: contains the true match far more often).
    Row,
    /// Right-image interest points in the epipolar band (the paper's network).
    Points,
}

/// Parameters of the Hopfield channel (defaults: algorithms.md C.3 with the C.10 changes).
#[derive(Debug, Clone, PartialEq)]
pub struct HopfieldParams {
    /// Smallest disparity searched (px).
    pub d_min: usize,
    /// Largest disparity searched (px).
    pub d_max: usize,
    pub interest: InterestParams,
    pub candidates: CandidateMode,
    /// Epipolar band `|y_l - y_r|` for [`CandidateMode::Points`] (px, C.3).
    pub dy_window: usize,
    /// Minimum ZNCC of a candidate (the real gate of the network, C.10).
    /// A textureless left or right 7x7 window (undefined ZNCC, stored as 0) is never a
    /// candidate, whatever `s_min` (even <= 0).
    pub s_min: f32,
    /// Candidates kept per left point (C.3; C.10: never binds).
    pub k_cand: usize,
    pub weights: EnergyWeights,
    /// Neurons with `S >= s_init` start on (C.4 "preset possible matches").
    pub s_init: f32,
    /// ... only each point's best candidate among them (a start that already satisfies
    /// uniqueness along the row): the sweeps then flip about 1/6 as many neurons as from
    /// every candidate on, to the same final matches within a few per scene
    /// (docs/hopfield.md, "Round 4").
    pub init_best: bool,
    /// Upper bound on asynchronous sweeps.
    pub max_sweeps: usize,
    /// Seed of the update order.
    pub seed: u64,
    /// Disambiguation tolerance on the vertical disparity (px, C.5).
    pub tau_y: f32,
    /// Depth-edge test (half-windows, centre check, neighbour agreement; C.10).
    pub edge_test: bool,
    /// Half-window disparities must agree with the match within this many px (C.10: 1).
    pub edge_tol: usize,
    /// Half-window ZNCC at the match may fall this far below the half's best (0 = the match
    /// must be each half's best disparity, C.10's literal test).
    pub edge_margin: f32,
    /// Input penalty of neurons failing the depth-edge test (0 = the network ignores the test,
    /// which is then applied after the dynamics only).
    pub edge_penalty: f32,
    /// Centre grey-level difference allowed between the matched pixels (C.10: 0.05).
    pub centre_tol: f32,
    /// Side rescue of the half-window test: a match failing only half-window tests (centre
    /// check passed) is kept when, for every failing half, at least this many accepted matches
    /// lie on that side of it in the 40x40 window, all agree with it within `agree_tol` and
    /// their median sub-pixel disparity is within `rescue_med` of its own; repeated until no
    /// match is added (0 = off, C.10's test only). A half lying on another surface finds that
    /// surface's matches on its side; a spurious peak of a small half-window (repetitive or weak
    /// texture: KITTI's road and vegetation) finds its own surface there.
    pub rescue_min: usize,
    /// Largest distance (px) between a rescued match and the median of its side's matches.
    pub rescue_med: f32,
    /// Final selection: a point the network leaves without an active candidate falls back to
    /// its best candidate when the network's reason is weak and the right pixel is free (no
    /// active neuron of another point holds it). Weak: an active alternative candidate of the
    /// point has support (positive weights from active neurons) below `fallback_alt_support`,
    /// or, with no active alternative, the best candidate itself has support of at least
    /// `fallback_min_support`. Correct matches on a minority surface or on a slanted one are
    /// switched off by the inhibition of the dominant surface; they keep some support.
    pub fallback: bool,
    /// See [`HopfieldParams::fallback`] (2.0).
    pub fallback_alt_support: f32,
    /// See [`HopfieldParams::fallback`] (0.5).
    pub fallback_min_support: f32,
    /// Fallback of thin surfaces: a point left with nothing whose only candidate passed the
    /// depth-edge test, with no support, falls back too when at least `min_agree` other such
    /// points in its window agree with it within `agree_tol` (the network's 40x40 window
    /// inhibits a surface narrower than itself: wood2's strip at d = 24, 25 correct matches).
    pub fallback_group: bool,
    /// Agreeing neighbour matches required in the 40x40 window (C.10: 8).
    pub min_agree: usize,
    /// Sparse-area alternative to `min_agree`: this share of the neighbour matches agrees
    /// (0 = off, C.10's rule only). 0.8: weakly textured areas (wood2's plank, laundry's
    /// basket, playground's left edge) have fewer than 8 matched neighbours in the window.
    pub agree_share: f32,
    /// ... with at least this many agreeing neighbours (2: one neighbour could agree by chance).
    pub min_agree_sparse: usize,
    /// Neighbour matches agree when their disparities differ by at most this (px).
    pub agree_tol: i32,
    /// Parabola sub-pixel refinement of the final matches.
    pub subpixel: bool,
}

impl Default for HopfieldParams {
    fn default() -> Self {
        HopfieldParams {
            d_min: 0,
            d_max: 64,
            interest: InterestParams::default(),
            candidates: CandidateMode::Row,
            dy_window: 2,
            s_min: DEFAULT_S_MIN,
            k_cand: 8,
            weights: EnergyWeights::default(),
            s_init: 0.8,
            init_best: true,
            max_sweeps: 100,
            seed: 0,
            tau_y: 1.0,
            edge_test: true,
            edge_tol: 1,
            edge_margin: 0.0,
            edge_penalty: 0.5,
            centre_tol: 0.05,
            rescue_min: 3,
            rescue_med: 0.75,
            fallback: true,
            fallback_alt_support: 2.0,
            fallback_min_support: 0.5,
            fallback_group: true,
            min_agree: 8,
            agree_tol: 1,
            agree_share: 0.8,
            min_agree_sparse: 2,
            subpixel: true,
        }
    }
}

/// Default minimum candidate ZNCC.
pub const DEFAULT_S_MIN: f32 = 0.8;

/// Largest `nbr_half` (px): the neighbourhood window's half-size.
pub const MAX_NBR_HALF: i32 = 4096;

/// One final match.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    pub xl: f32,
    pub yl: f32,
    pub xr: f32,
    pub yr: f32,
    /// ZNCC of the 7x7 windows at the integer match.
    pub score: f32,
}

/// Result of [`hopfield_match`] / [`best_match`], with the network's statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct HopfieldOutput {
    pub matches: Vec<Match>,
    /// Energy of the initial state, then after every sweep (empty for [`best_match`]).
    pub energy_trace: Vec<f64>,
    pub n_points: usize,
    pub n_neurons: usize,
    pub n_weights: usize,
    pub sweeps: usize,
    pub converged: bool,
    /// Matches chosen before the depth-edge filters.
    pub n_selected: usize,
}

fn validate(left: &ImageView<'_>, right: &ImageView<'_>, p: &HopfieldParams) -> Result<()> {
    if left.size() != right.size() {
        return Err(CoreError::SizeMismatch {
            left: left.size(),
            right: right.size(),
        });
    }
    // Interest points are numbered in u32, matched positions held in i32.
    crate::image::check_index_range(left.width, left.height)?;
    if p.d_max < p.d_min {
        return Err(CoreError::param(
            "max_disparity",
            format!("must be >= min_disparity ({}), got {}", p.d_min, p.d_max),
        ));
    }
    if !(p.interest.rel_threshold.is_finite() && (0.0..=1.0).contains(&p.interest.rel_threshold)) {
        return Err(CoreError::param("rel_threshold", "must lie in [0, 1]"));
    }
    if !(p.interest.floor_rel.is_finite() && (0.0..=1.0).contains(&p.interest.floor_rel)) {
        return Err(CoreError::param("floor_rel", "must lie in [0, 1]"));
    }
    if p.interest.nms_half == 0 {
        return Err(CoreError::param("nms_half", "must be >= 1"));
    }
    for (name, v) in [("s_min", p.s_min), ("s_init", p.s_init)] {
        if !v.is_finite() || !(-1.0..=1.0).contains(&v) {
            return Err(CoreError::param(
                name,
                format!("must lie in [-1, 1], got {v}"),
            ));
        }
    }
    if p.k_cand == 0 {
        return Err(CoreError::param("k_cand", "must be >= 1"));
    }
    if p.max_sweeps == 0 {
        return Err(CoreError::param("max_sweeps", "must be >= 1"));
    }
    let w = &p.weights;
    // Supports may be negative; a NaN or inf anywhere is refused.
    for (name, v) in [
        ("fallback_alt_support", p.fallback_alt_support),
        ("fallback_min_support", p.fallback_min_support),
    ] {
        if !v.is_finite() {
            return Err(CoreError::param(name, format!("must be finite, got {v}")));
        }
    }
    if p.agree_tol < 0 {
        return Err(CoreError::param(
            "agree_tol",
            format!("must be finite and >= 0, got {}", p.agree_tol),
        ));
    }
    // A negative value of these means nothing, as MCGM refuses its own: the energy's weights
    // and input offset (A=-1 made neighbours of another disparity support a match), the
    // compatibility's crossing, slope and growth, the edge test's penalty (negative: a bonus)
    // and the tolerances (negative: nothing passes; agree_tol=-1 gave no match at all). A NaN
    // or negative slack / tolerance failed every edge or centre test without a word.
    for (name, v) in [
        ("A", w.a),
        ("B", w.b),
        ("D", w.d),
        ("theta", w.theta),
        ("compat_theta", w.compat_theta),
        ("compat_slope", w.compat_slope),
        ("compat_grad", w.compat_grad),
        ("tau_y", p.tau_y),
        ("edge_penalty", p.edge_penalty),
        ("rescue_med", p.rescue_med),
        ("edge_margin", p.edge_margin),
        ("centre_tol", p.centre_tol),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(CoreError::param(
                name,
                format!("must be finite and >= 0, got {v}"),
            ));
        }
    }
    if !(p.agree_share.is_finite() && (0.0..=1.0).contains(&p.agree_share)) {
        return Err(CoreError::param(
            "agree_share",
            format!("must lie in [0, 1], got {}", p.agree_share),
        ));
    }
    // 1e6 px took a minute on a 100 x 160 crop and 1e9 did not finish: a window beyond any
    // image is refused.
    if !(1..=MAX_NBR_HALF).contains(&w.nbr_half) {
        return Err(CoreError::param(
            "nbr_half",
            format!("must be in 1..={MAX_NBR_HALF} px, got {}", w.nbr_half),
        ));
    }
    Ok(())
}

/// What the candidate search's allocations are named in an out-of-memory error.
const CANDIDATES: &str = "the Hopfield matcher's candidate neurons";

/// Rows of the right image holding right interest points (points mode).
fn right_rows(right: &ImageView<'_>, p: &HopfieldParams) -> Result<HashMap<usize, Vec<usize>>> {
    if p.candidates == CandidateMode::Points {
        rows_of(&interest_points(right, &p.interest)?)
    } else {
        Ok(HashMap::new())
    }
}

/// What [`rows_of`]'s allocations are named in an out-of-memory error.
const RIGHT_ROWS: &str = "the Hopfield matcher's right points by row";

/// The x of `pts` per row (in the order of `pts`). A failed allocation of the map or a row's
/// list is [`CoreError::OutOfMemory`] (`entry().or_default().push()` aborted the process); the
/// size named for the map is its entries' (the table adds control bytes and free slots).
fn rows_of(pts: &[InterestPoint]) -> Result<HashMap<usize, Vec<usize>>> {
    let mut rows: HashMap<usize, Vec<usize>> = HashMap::new();
    let entry = std::mem::size_of::<(usize, Vec<usize>)>();
    let oom = |n: usize| CoreError::oom(n.saturating_mul(entry), RIGHT_ROWS);
    // Points come in raster order: room for one entry per run of a row (grown below if not).
    let n_rows = pts.chunk_by(|a, b| a.y == b.y).count();
    rows.try_reserve(n_rows).map_err(|_| oom(n_rows))?;
    for run in pts.chunk_by(|a, b| a.y == b.y) {
        if !rows.contains_key(&(run[0].y as usize)) {
            rows.try_reserve(1).map_err(|_| oom(rows.len() + 1))?;
        }
        let xs = rows.entry(run[0].y as usize).or_default();
        try_grow(xs, run.len(), RIGHT_ROWS)?;
        xs.extend(run.iter().map(|rp| rp.x as usize));
    }
    Ok(rows)
}

/// Parabola vertex offset through `(d-1, a), (d, b), (d+1, c)`, clamped to +-0.5.
fn parabola(a: f32, b: f32, c: f32) -> f32 {
    let den = a - 2.0 * b + c;
    if den >= 0.0 {
        return 0.0;
    }
    (0.5 * (a - c) / den).clamp(-0.5, 0.5)
}

/// Image rows per parallel task of the candidate search: its right-image statistics are
/// computed for these rows only (small enough for an even split over the threads).
const ROWS_PER_TASK: usize = 16;

/// Scratch of [`point_candidates`], reused across the points of a thread.
#[derive(Default)]
struct CandScratch {
    curves: Curves,
    ds: Vec<usize>,
    found: Vec<Neuron>,
}

simd_fn! {
/// The candidate neurons of left point `i` in `sc.found` (best ZNCC first, at most `k_cand`),
/// with their depth-edge verdict and sub-pixel offset. Compiled for AVX2 too: the
/// curves' maxima then run eight lanes wide.
fn point_candidates(
    left: &ImageView<'_>,
    right: &ImageView<'_>,
    stats: &RightStats,
    rows: &HashMap<usize, Vec<usize>>,
    p: &HopfieldParams,
    i: usize,
    pt: &InterestPoint,
    sc: &mut CandScratch,
) {
    sc.found.clear();
    let (w, h) = right.size();
    let (x, y) = (pt.x as usize, pt.y as usize);
    let d_hi = p.d_max.min(x.saturating_sub(SIM_RADIUS));
    if x < SIM_RADIUS || x + SIM_RADIUS >= w || d_hi < p.d_min {
        return;
    }
    let (lo_row, hi_row) = match p.candidates {
        CandidateMode::Row => (y, y),
        CandidateMode::Points => (
            y.saturating_sub(p.dy_window).max(SIM_RADIUS),
            // Saturating, as `hi` below: a band past the image (up to usize::MAX) wrapped.
            y.saturating_add(p.dy_window)
                .min(h.saturating_sub(SIM_RADIUS + 1)),
        ),
    };
    for yr in lo_row..=hi_row {
        let right_xs = rows.get(&yr).map(|v| v.as_slice()).unwrap_or(&[]);
        if p.candidates == CandidateMode::Points && right_xs.is_empty() {
            continue;
        }
        zncc_curves(left, right, stats, x, y, yr, d_hi, &mut sc.curves);
        let cv = &sc.curves;
        let full = &cv.curve[FULL];
        // No disparity reaches s_min: no candidate (most rejected points end here).
        if max_of(&full[p.d_min..=d_hi]) < p.s_min {
            continue;
        }
        // Best ZNCC of every half-window over the range (None: undefined / textureless).
        let halves: [Option<f32>; N_REGIONS - 1] = std::array::from_fn(|k| {
            Some(max_of(&cv.curve[k + 1][p.d_min..=d_hi])).filter(|&b| b > 0.0)
        });
        sc.ds.clear();
        match p.candidates {
            CandidateMode::Row => row_peaks(full, p.d_min, d_hi, p.s_min, &mut sc.ds),
            CandidateMode::Points => {
                for &xr in right_xs {
                    if xr <= x && (p.d_min..=d_hi).contains(&(x - xr)) && full[x - xr] >= p.s_min {
                        sc.ds.push(x - xr);
                    }
                }
            }
        }
        for &d in &sc.ds {
            let xr = x - d;
            // An undefined ZNCC reads 0: with s_min <= 0 it passed as a candidate (a flat right
            // image gave every point a "match" of score 0). Never one at s_min > 0.
            if !cv.left_defined || !stats.defined(xr, yr) {
                continue;
            }
            // Each half-window must find this disparity (within edge_tol px) as good as
            // its best anywhere in the range, up to edge_margin: a half lying on another
            // surface prefers that surface's disparity by far more, while a periodic
            // texture's equal peaks (laundry's basket) stay acceptable.
            let lo = d.saturating_sub(p.edge_tol).max(p.d_min);
            // Saturating: a tolerance past the range (up to usize::MAX) wrapped to d - 1.
            let hi = d.saturating_add(p.edge_tol).min(d_hi);
            let halves_fail = halves.iter().enumerate().fold(0u8, |acc, (k, best)| {
                let ok = best
                    .is_some_and(|best| max_of(&cv.curve[k + 1][lo..=hi]) >= best - p.edge_margin);
                acc | (u8::from(!ok) << k)
            });
            // Centre check on window-mean-free grey levels: insensitive to the exposure
            // offset between the cameras (ETH3D, KITTI), still catches a centre pixel
            // that belongs to the other surface.
            let lc = left.at(x, y) - cv.left_mean;
            let rc = right.at(xr, yr) - stats.mean(xr, yr);
            let centre_ok = (lc - rc).abs() <= p.centre_tol;
            let sub = if p.subpixel && d >= 1 && d < d_hi {
                parabola(full[d - 1], full[d], full[d + 1])
            } else {
                0.0
            };
            sc.found.push(Neuron {
                point: i as u32,
                xl: x as i32,
                yl: y as i32,
                xr: xr as i32,
                yr: yr as i32,
                sim: full[d],
                edge_ok: halves_fail == 0 && centre_ok,
                halves_fail,
                centre_ok,
                sub,
            });
        }
    }
    sc.found.sort_by(|a, b| {
        b.sim
            .total_cmp(&a.sim)
            .then(a.xr.cmp(&b.xr))
            .then(a.yr.cmp(&b.yr))
    });
    sc.found.truncate(p.k_cand);
}
}

/// Candidate neurons of every left point, grouped by point (point order, then best ZNCC first),
/// with their depth-edge verdict and sub-pixel offset. Points are processed in fixed chunks
/// whose outputs are concatenated in order: the result does not depend on the thread count.
fn candidates(
    left: &ImageView<'_>,
    right: &ImageView<'_>,
    pts: &[InterestPoint],
    p: &HopfieldParams,
) -> Result<Vec<Neuron>> {
    let rows = right_rows(right, p)?;
    // Tasks: bands of image rows, each with its own right-image statistics (the rows its
    // points search, +- dy_window in points mode).
    let band_of = |pt: &InterestPoint| pt.y as usize / ROWS_PER_TASK;
    let mut tasks: Vec<(usize, usize)> = Vec::new(); // point index ranges, raster order
    let mut s0 = 0;
    for i in 1..=pts.len() {
        if i == pts.len() || band_of(&pts[i]) != band_of(&pts[s0]) {
            try_grow(&mut tasks, 1, CANDIDATES)?;
            tasks.push((s0, i));
            s0 = i;
        }
    }
    let reach = match p.candidates {
        CandidateMode::Row => 0,
        CandidateMode::Points => p.dy_window,
    };
    let mut per_task: Vec<Result<Vec<Neuron>>> = Vec::new();
    try_reserve_len(&mut per_task, tasks.len(), CANDIDATES)?;
    tasks
        .par_iter()
        .map_init(
            || (CandScratch::default(), RightStats::default()),
            |(sc, stats), &(i0, i1)| {
                let y_lo = pts[i0].y as usize;
                let y_hi = pts[i1 - 1].y as usize + 1;
                stats.fill_band(
                    right,
                    y_lo.saturating_sub(reach),
                    y_hi.saturating_add(reach),
                )?;
                let mut out = Vec::new();
                try_reserve_len(&mut out, 2 * (i1 - i0), CANDIDATES)?;
                for (i, pt) in pts.iter().enumerate().take(i1).skip(i0) {
                    point_candidates(left, right, stats, &rows, p, i, pt, sc);
                    // The point's best `k_cand`, appended as `extend` grows, checked.
                    try_grow(&mut out, sc.found.len(), CANDIDATES)?;
                    out.extend_from_slice(&sc.found);
                }
                Ok(out)
            },
        )
        .collect_into_vec(&mut per_task);
    try_concat(per_task.into_iter().collect::<Result<_>>()?, CANDIDATES)
}

/// Median (mean of the two middle values for an even count; 0 if empty), by selection: the
/// values of a full sort, in linear time. Reorders `v`.
fn median(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    let n = v.len();
    let (lower, &mut mid, _) = v.select_nth_unstable_by(n / 2, f32::total_cmp);
    if n % 2 == 1 {
        mid
    } else {
        let below = lower
            .iter()
            .copied()
            .max_by(f32::total_cmp)
            .expect("n >= 2");
        0.5 * (below + mid)
    }
}

/// What the allocations of the final selection ([`fallback`], [`disambiguate`]) are named in an
/// out-of-memory error.
const SELECTION: &str = "the Hopfield matcher's final selection";

/// What the allocations of the depth-edge filters ([`rescue`], [`finish`]) are named in an
/// out-of-memory error.
const FILTERS: &str = "the Hopfield matcher's depth-edge filters";

/// The values of `it` that pass `keep`, collected checked (counted first: a `filter` then
/// `collect` grows its vector unchecked). [`CoreError::OutOfMemory`] names `what`.
fn try_filtered<T>(
    it: impl Iterator<Item = T> + Clone,
    keep: impl Fn(&T) -> bool,
    what: &'static str,
) -> Result<Vec<T>> {
    let n = it.clone().filter(&keep).count();
    try_collect(n, it.filter(keep), what)
}

/// C.5 disambiguation: indices of the kept active neurons (at most one per left point and one
/// per right pixel). A failed allocation of its lists (per active neuron, per conflict, per
/// right pixel) is [`CoreError::OutOfMemory`].
fn disambiguate(
    neurons: &[Neuron],
    net: &Network,
    state: &[u8],
    p: &HopfieldParams,
) -> Result<Vec<usize>> {
    // Active neurons per left point (neurons are grouped by point): singles kept as they are.
    let m = neurons.len();
    let mut singles: Vec<usize> = Vec::new();
    let mut ambiguous: Vec<Vec<usize>> = Vec::new();
    let mut a = 0;
    while a < m {
        let mut e = a;
        while e < m && neurons[e].point == neurons[a].point {
            e += 1;
        }
        let n_on = (a..e).filter(|&b| state[b] == 1).count();
        if n_on == 1 {
            try_grow(&mut singles, 1, SELECTION)?;
            singles.extend((a..e).filter(|&b| state[b] == 1));
        } else if n_on > 1 {
            try_grow(&mut ambiguous, 1, SELECTION)?;
            ambiguous.push(try_collect(
                n_on,
                (a..e).filter(|&b| state[b] == 1),
                SELECTION,
            )?);
        }
        a = e;
    }
    // Fallback reference of a window without single matches, computed when first needed.
    let global = std::sync::OnceLock::new();
    let global = || -> Result<f32> {
        global
            .get_or_init(|| {
                let dy = singles.iter().map(|&s| neurons[s].dy() as f32);
                let mut all_dy = try_collect(singles.len(), dy, SELECTION)?;
                Ok(median(&mut all_dy))
            })
            .clone()
    };
    let half = p.weights.nbr_half.max(1);
    // The singles' grid, built when a conflict first needs it (most scenes have few).
    let grid = std::sync::OnceLock::new();
    let grid = || -> Result<&network::PointGrid> {
        grid.get_or_init(|| {
            let xy = singles
                .iter()
                .map(|&s| (neurons[s].xl.max(0), neurons[s].yl.max(0)));
            network::PointGrid::new(&try_collect(singles.len(), xy, SELECTION)?, half)
        })
        .as_ref()
        .map_err(Clone::clone)
    };
    // Reference vertical disparity: median over the single matches in the 40x40 window.
    let local_ref = |a: usize| -> Result<f32> {
        let n = &neurons[a];
        let mut v: Vec<f32> = Vec::new();
        grid()?.for_each_in_window((n.xl.max(0), n.yl.max(0)), half, |k| {
            v.push(neurons[singles[k]].dy() as f32)
        });
        if v.is_empty() {
            global()
        } else {
            Ok(median(&mut v))
        }
    };
    // Closest to the reference, then higher similarity, then lower index; None if too far.
    let pick = |group: &[usize]| -> Result<Option<usize>> {
        let mut best: Option<(f32, f32, usize)> = None;
        for &a in group {
            let key = (
                (neurons[a].dy() as f32 - local_ref(a)?).abs(),
                -neurons[a].sim,
                a,
            );
            if best.is_none_or(|b| (key.0, key.1, key.2) < (b.0, b.1, b.2)) {
                best = Some(key);
            }
        }
        Ok(best.filter(|b| b.0 <= p.tau_y).map(|b| b.2))
    };
    // Every pick of a point's conflict, in point order (few conflicts, the usual case, on
    // this thread: no dispatch to the pool).
    let mut picks: Vec<Result<Option<usize>>> = Vec::new();
    try_reserve_len(&mut picks, ambiguous.len(), SELECTION)?;
    if ambiguous.len() < 256 {
        picks.extend(ambiguous.iter().map(|g| pick(g)));
    } else {
        ambiguous
            .par_iter()
            .map(|g| pick(g))
            .collect_into_vec(&mut picks);
    }
    let n_picked = picks.iter().filter(|r| !matches!(r, Ok(None))).count();
    let mut kept = Vec::new();
    try_reserve_len(&mut kept, singles.len() + n_picked, SELECTION)?;
    kept.extend_from_slice(&singles);
    for r in picks {
        kept.extend(r?);
    }
    // The same rule on the right side (neurons sharing a right pixel, by the network's
    // right-pixel rank): a pixel held once keeps its match, a conflict is picked as above
    // (`pick` depends on the group's members only, not on their order).
    let mut held = try_zeroed::<u32>(net.n_right_pixels(), SELECTION)?;
    for &a in &kept {
        held[net.right_pixel(a)] += 1;
    }
    // `out` takes the unique ones, then at most one pick per conflict.
    let mut out = try_filtered(
        kept.iter().copied(),
        |&a| held[net.right_pixel(a)] == 1,
        SELECTION,
    )?;
    let mut conflicts = try_filtered(
        kept.iter().copied(),
        |&a| held[net.right_pixel(a)] != 1,
        SELECTION,
    )?;
    try_reserve_len(&mut out, kept.len(), SELECTION)?;
    conflicts.sort_unstable_by_key(|&a| (net.right_pixel(a), a));
    for group in conflicts.chunk_by(|&a, &b| net.right_pixel(a) == net.right_pixel(b)) {
        out.extend(pick(group)?);
    }
    out.sort_unstable();
    Ok(out)
}

/// Stage 1 of [`finish`]: which of `chosen` pass the depth-edge test, with the side rescue of
/// [`HopfieldParams::rescue_min`] iterated to a fixed point (every round tests the remaining
/// candidates against the matches accepted before it, so the order of the points is irrelevant).
/// A failed allocation of its per-match lists or grids is [`CoreError::OutOfMemory`].
fn rescue(neurons: &[Neuron], chosen: &[usize], p: &HopfieldParams) -> Result<Vec<bool>> {
    if !p.edge_test {
        return try_filled(chosen.len(), true, FILTERS);
    }
    let mut ok = try_collect(
        chosen.len(),
        chosen.iter().map(|&a| neurons[a].edge_ok),
        FILTERS,
    )?;
    if p.rescue_min == 0 {
        return Ok(ok);
    }
    // Candidates of the rescue: failed half-window tests only.
    let cands = try_filtered(
        0..chosen.len(),
        |&c| {
            let n = &neurons[chosen[c]];
            !n.edge_ok && n.centre_ok && n.halves_fail != 0
        },
        FILTERS,
    )?;
    let half = p.weights.nbr_half.max(1);
    // One grid over every chosen match (filtered by `ok` when read) and one over the
    // candidates: no grid is rebuilt per round.
    let cxy = try_collect(
        chosen.len(),
        chosen
            .iter()
            .map(|&a| (neurons[a].xl.max(0), neurons[a].yl.max(0))),
        FILTERS,
    )?;
    let grid = network::PointGrid::new(&cxy, half)?;
    // The chosen matches' disparity, sub-pixel disparity and verdict in grid order: a window
    // scan reads them in place (same positions, same order as `for_each_in_window`).
    let g_dx = grid.values_in_grid_order(|t| neurons[chosen[t]].dx())?;
    let g_v = try_collect(
        grid.items.len(),
        grid.items.iter().map(|&t| {
            let b = &neurons[chosen[t as usize]];
            b.dx() as f32 + b.sub
        }),
        FILTERS,
    )?;
    let mut g_of = try_zeroed::<usize>(chosen.len(), FILTERS)?;
    for (g, &t) in grid.items.iter().enumerate() {
        g_of[t as usize] = g;
    }
    let mut ok_g = try_collect(
        grid.items.len(),
        grid.items.iter().map(|&t| ok[t as usize]),
        FILTERS,
    )?;
    let kxy = try_collect(cands.len(), cands.iter().map(|&c| cxy[c]), FILTERS)?;
    let cand_grid = network::PointGrid::new(&kxy, half)?;
    // Round 1 tests every candidate; a later round only those with a point accepted in the
    // round before in their window (the others see the same side sets and keep their verdict).
    let mut to_test = try_collect(cands.len(), 0..cands.len(), FILTERS)?;
    loop {
        // Candidates are tested independently within a round (in parallel, kept in order),
        // against the matches accepted before the round.
        let test = |sides: &mut [Vec<f32>; 4], k: usize| -> bool {
            let c = cands[k];
            let n = &neurons[chosen[c]];
            let (x, y, d) = (cxy[c].0, cxy[c].1, n.dx());
            let dsub = d as f32 + n.sub;
            // One pass over the window fills the side sets of every failing half (in
            // window order, as one pass per half would).
            let fails: [bool; 4] = std::array::from_fn(|h| n.halves_fail >> h & 1 == 1);
            let mut all_agree = [true; 4];
            sides.iter_mut().for_each(Vec::clear);
            grid.for_each_pos_in_window((x, y), half, |g| {
                if !ok_g[g] {
                    return;
                }
                let (qx, qy) = (grid.xs[g], grid.ys[g]);
                let agree = (g_dx[g] - d).abs() <= p.agree_tol;
                for (h, on_side) in [qx < x, qx > x, qy < y, qy > y].into_iter().enumerate() {
                    if fails[h] && on_side {
                        all_agree[h] &= agree;
                        sides[h].push(g_v[g]);
                    }
                }
            });
            (0..4).filter(|&h| fails[h]).all(|h| {
                all_agree[h]
                    && sides[h].len() >= p.rescue_min
                    && (median(&mut sides[h]) - dsub).abs() <= p.rescue_med
            })
        };
        // The round's verdicts (in `to_test` order); small rounds (the later ones) run on this
        // thread: no dispatch to the pool.
        let mut pass = try_zeroed::<bool>(to_test.len(), FILTERS)?;
        if to_test.len() < 256 {
            let mut sides = std::array::from_fn(|_| Vec::new());
            for (v, &k) in pass.iter_mut().zip(&to_test) {
                *v = test(&mut sides, k);
            }
        } else {
            pass.par_iter_mut().zip(&to_test).for_each_init(
                || std::array::from_fn::<Vec<f32>, 4, _>(|_| Vec::new()),
                |sides, (v, &k)| *v = test(sides, k),
            );
        }
        let added = try_filtered(to_test.iter().zip(&pass), |&(_, &v)| v, FILTERS)?;
        if added.is_empty() {
            return Ok(ok);
        }
        for &(&k, _) in &added {
            ok[cands[k]] = true;
            ok_g[g_of[cands[k]]] = true;
        }
        let mut near = try_zeroed::<bool>(cands.len(), FILTERS)?;
        for &(&k, _) in &added {
            cand_grid.for_each_in_window(kxy[k], half, |j| near[j] = true);
        }
        to_test = try_filtered(0..cands.len(), |&j| near[j] && !ok[cands[j]], FILTERS)?;
    }
}

/// The final selection's fallback to the best candidate (see [`HopfieldParams::fallback`]):
/// the network's state with the best candidate of some points switched on. A failed allocation
/// of its per-neuron, per-point or per-right-pixel lists is [`CoreError::OutOfMemory`].
fn fallback(
    neurons: &[Neuron],
    net: &Network,
    state: &[u8],
    p: &HopfieldParams,
) -> Result<Vec<u8>> {
    let mut out = try_collect(state.len(), state.iter().copied(), SELECTION)?;
    if !p.fallback {
        return Ok(out);
    }
    // Groups of neurons per point (best ZNCC first) whose best candidate is off.
    let mut groups: Vec<(usize, usize)> = Vec::new();
    let mut a = 0;
    while a < neurons.len() {
        let mut e = a;
        while e < neurons.len() && neurons[e].point == neurons[a].point {
            e += 1;
        }
        if state[a] == 0 {
            try_grow(&mut groups, 1, SELECTION)?;
            groups.push((a, e));
        }
        a = e;
    }
    // Support (positive weights from active neurons, summed in row order in f64) of the
    // neurons the rule reads: the active alternatives, else the best candidate.
    let on = net.lane_state(state, SELECTION)?;
    let support_of = |a: usize| net.support(a, state, &on);
    let mut weak = Vec::new();
    try_reserve_len(&mut weak, groups.len(), SELECTION)?;
    groups
        .par_iter()
        .map(|&(a, e)| {
            let alt = (a + 1..e)
                .filter(|&b| state[b] == 1)
                .map(support_of)
                .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
            match alt {
                Some(s) => s < p.fallback_alt_support as f64,
                None => support_of(a) >= p.fallback_min_support as f64,
            }
        })
        .collect_into_vec(&mut weak); // into the reserved room: no reallocation
    if p.fallback_group {
        // Thin surfaces: points the network left with nothing (one candidate, edge test passed,
        // no support) because the window's dominant surface inhibits them. Where at least
        // `min_agree` other such points in the window agree with one (within `agree_tol`),
        // they are a surface of their own, the evidence the final agreement filter asks for.
        let lone = try_filtered(
            0..groups.len(),
            |&g| {
                let (a, e) = groups[g];
                !weak[g] && e - a == 1 && neurons[a].edge_ok
            },
            SELECTION,
        )?;
        let half = p.weights.nbr_half.max(1);
        let lxy = try_collect(
            lone.len(),
            lone.iter().map(|&g| {
                (
                    neurons[groups[g].0].xl.max(0),
                    neurons[groups[g].0].yl.max(0),
                )
            }),
            SELECTION,
        )?;
        let grid = network::PointGrid::new(&lxy, half)?;
        let ld = grid.values_in_grid_order(|t| neurons[groups[lone[t]].0].dx())?;
        let mut coherent = Vec::new();
        try_reserve_len(&mut coherent, lone.len(), SELECTION)?;
        lone.par_iter()
            .zip(&lxy)
            .map(|(&g, &xy)| {
                let d = neurons[groups[g].0].dx();
                // The count includes the point itself.
                grid.count_in_window(xy, half, &ld, d, p.agree_tol).1 > p.min_agree
            })
            .collect_into_vec(&mut coherent);
        for (&g, &c) in lone.iter().zip(&coherent) {
            weak[g] |= c;
        }
    }
    // Right pixels held by an active neuron: its left point (FREE: none, SEVERAL: several).
    const FREE: u32 = u32::MAX;
    const SEVERAL: u32 = u32::MAX - 1;
    let mut held = try_filled(net.n_right_pixels(), FREE, SELECTION)?;
    for (a, n) in neurons.iter().enumerate().filter(|&(a, _)| state[a] == 1) {
        let h = &mut held[net.right_pixel(a)];
        if *h == FREE {
            *h = n.point;
        } else if *h != n.point {
            *h = SEVERAL;
        }
    }
    for (&(a, _), &weak) in groups.iter().zip(&weak) {
        let n = &neurons[a];
        let h = held[net.right_pixel(a)];
        let free = h == FREE || h == n.point;
        if weak && free {
            out[a] = 1;
        }
    }
    Ok(out)
}

/// Depth-edge filters and sub-pixel refinement of the selected neurons. A failed allocation of
/// their per-match lists or grids is [`CoreError::OutOfMemory`].
fn finish(
    left: &ImageView<'_>,
    right: &ImageView<'_>,
    neurons: &[Neuron],
    chosen: &[usize],
    p: &HopfieldParams,
) -> Result<Vec<Match>> {
    let _ = (left, right);
    // Stage 1: the per-candidate depth-edge verdict (computed with the ZNCC curves), then the
    // side rescue of half-window failures.
    let accepted = rescue(neurons, chosen, p)?;
    let survivors = try_filtered(
        chosen
            .iter()
            .zip(&accepted)
            .map(|(&a, &ok)| (a, neurons[a].dx() as f32 + neurons[a].sub, ok)),
        |&(_, _, ok)| ok,
        FILTERS,
    )?;
    // Stage 2: neighbour agreement among the survivors (uniform grid, cell = window half-size).
    let half = p.weights.nbr_half.max(1);
    let sxy = try_collect(
        survivors.len(),
        survivors
            .iter()
            .map(|&(a, _, _)| (neurons[a].xl.max(0), neurons[a].yl.max(0))),
        FILTERS,
    )?;
    let grid = network::PointGrid::new(&sxy, half)?;
    // Survivor disparities in grid order.
    let sd = grid.values_in_grid_order(|t| neurons[survivors[t].0].dx())?;
    // Each survivor's verdict, then the matches of those that pass (counted first: a parallel
    // filter's collect grows its vector unchecked).
    let mut pass = try_zeroed::<bool>(survivors.len(), FILTERS)?;
    pass.par_iter_mut()
        .zip(&survivors)
        .enumerate()
        .for_each(|(s, (v, &(a, _, _)))| {
            *v = !p.edge_test || {
                let d = neurons[a].dx();
                let (x, y) = sxy[s];
                let (mut near, mut agree) = grid.count_in_window((x, y), half, &sd, d, p.agree_tol);
                near -= 1;
                agree -= usize::from(p.agree_tol >= 0); // the survivor itself
                                                        // Dense areas: at least min_agree agreeing neighbours (C.10). Sparse areas
                                                        // (weak texture) optionally: a large share of the few neighbours, at least
                                                        // min_agree_sparse.
                agree >= p.min_agree
                    || (p.agree_share > 0.0
                        && agree >= p.min_agree_sparse
                        && agree as f32 >= p.agree_share * near as f32)
            };
        });
    let matches = survivors
        .iter()
        .zip(&pass)
        .filter(|&(_, &v)| v)
        .map(|(&(a, dsub, _), _)| {
            let n = &neurons[a];
            Match {
                xl: n.xl as f32,
                yl: n.yl as f32,
                xr: n.xl as f32 - dsub,
                yr: n.yr as f32,
                score: n.sim,
            }
        });
    try_collect(pass.iter().filter(|&&v| v).count(), matches, FILTERS)
}

/// Interest points and candidate neurons (exposed for tests and the reference comparison).
pub fn candidate_neurons<'a>(
    left: impl Into<ImageView<'a>>,
    right: impl Into<ImageView<'a>>,
    p: &HopfieldParams,
) -> Result<(Vec<InterestPoint>, Vec<Neuron>)> {
    let (left, right) = (&left.into(), &right.into());
    validate(left, right, p)?;
    let pts = interest_points(left, &p.interest)?;
    let neurons = candidates(left, right, &pts, p)?;
    Ok((pts, neurons))
}

/// The preset state (C.4): neurons with `S >= s_init` on, with [`HopfieldParams::init_best`]
/// only the first (best) candidate of each point.
pub fn initial_state(neurons: &[Neuron], p: &HopfieldParams) -> Vec<u8> {
    initial_states(neurons, p).collect()
}

/// The values of [`initial_state`], one per neuron.
fn initial_states<'a>(
    neurons: &'a [Neuron],
    p: &'a HopfieldParams,
) -> impl Iterator<Item = u8> + 'a {
    neurons.iter().enumerate().map(|(a, n)| {
        let first = a == 0 || neurons[a - 1].point != n.point;
        u8::from(n.sim >= p.s_init && (first || !p.init_best))
    })
}

/// The Hopfield channel: interest points matched by energy minimisation (see the module docs).
pub fn hopfield_match<'a>(
    left: impl Into<ImageView<'a>>,
    right: impl Into<ImageView<'a>>,
    p: &HopfieldParams,
) -> Result<HopfieldOutput> {
    let (left, right) = (&left.into(), &right.into());
    crate::parallel::run_hot(|| match_hot(left, right, p))
}

/// The body of [`hopfield_match`], run inside the pool.
fn match_hot(
    left: &ImageView<'_>,
    right: &ImageView<'_>,
    p: &HopfieldParams,
) -> Result<HopfieldOutput> {
    let (pts, neurons) = candidate_neurons(left, right, p)?;
    let net = Network::new(&neurons, &p.weights)?;
    const WHAT: &str = "the Hopfield dynamics' inputs";
    let input = try_collect(
        neurons.len(),
        neurons.iter().map(|n| {
            let penalty = if p.edge_test && !n.edge_ok {
                p.edge_penalty
            } else {
                0.0
            };
            (p.weights.d * n.sim - p.weights.theta - penalty) as f64
        }),
        WHAT,
    )?;
    let init = try_collect(neurons.len(), initial_states(&neurons, p), WHAT)?;
    let dynamics = run_dynamics(&net, &input, &init, p.seed, p.max_sweeps)?;
    let selected = fallback(&neurons, &net, &dynamics.state, p)?;
    let chosen = disambiguate(&neurons, &net, &selected, p)?;
    let matches = finish(left, right, &neurons, &chosen, p)?;
    Ok(HopfieldOutput {
        matches,
        energy_trace: dynamics.energy_trace,
        n_points: pts.len(),
        n_neurons: neurons.len(),
        n_weights: dynamics.nnz,
        sweeps: dynamics.sweeps,
        converged: dynamics.converged,
        n_selected: chosen.len(),
    })
}

/// The best-match reference: same points, candidates and filters, no network (the best ZNCC
/// candidate of every point).
pub fn best_match<'a>(
    left: impl Into<ImageView<'a>>,
    right: impl Into<ImageView<'a>>,
    p: &HopfieldParams,
) -> Result<HopfieldOutput> {
    let (left, right) = (&left.into(), &right.into());
    crate::parallel::run_hot(|| best_hot(left, right, p))
}

/// The body of [`best_match`], run inside the pool.
fn best_hot(
    left: &ImageView<'_>,
    right: &ImageView<'_>,
    p: &HopfieldParams,
) -> Result<HopfieldOutput> {
    let (pts, neurons) = candidate_neurons(left, right, p)?;
    // Each point's first candidate (candidates are sorted best first within a point).
    let chosen = try_filtered(
        0..neurons.len(),
        |&a| a == 0 || neurons[a - 1].point != neurons[a].point,
        SELECTION,
    )?;
    let matches = finish(left, right, &neurons, &chosen, p)?;
    Ok(HopfieldOutput {
        matches,
        energy_trace: Vec::new(),
        n_points: pts.len(),
        n_neurons: neurons.len(),
        n_weights: 0,
        sweeps: 0,
        converged: true,
        n_selected: chosen.len(),
    })
}
