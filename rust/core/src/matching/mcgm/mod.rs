//! Multi-Channel Graph Matching (algorithms.md B, with the B.8 changes).
//!
//! Per channel `sigma` (coarse to fine) and per image:
//! 1. [`log`]: separable scale-normalised zero-mean LoG; channels with `sigma >= half_res_sigma`
//!    run on the 2x-decimated image (`sigma / 2` there) and serve as priors only (B.8: the
//!    coarsest channel is the least precise).
//! 2. [`zerocross`]: one-pixel-thick zero crossings, sub-pixel x, strength, normal direction.
//! 3. [`tracking`]: hysteresis tracking into labelled segments.
//! 4. [`rtable`]: R-table per left segment; GHT votes score candidate pairs over the disparity
//!    window (narrowed by the coarser channels' prior, B.4.11).
//! 5. [`graph`]: k-NN segment graph, association graph, the Hopfield network of module C.
//! 6. Per-pixel disparities along the matched curves with sub-pixel x at both ends (B.4.12).
//!
//! The output is the finest channel's matches, coarser full-resolution channels filling rows
//! the finer ones left empty, then B.8's two occlusion filters ([`edge_filters`]): the
//! both-sides check and the discontinuity filter.

pub mod graph;
pub mod log;
pub mod rtable;
pub mod tracking;
pub mod zerocross;

#[cfg(test)]
mod tests;

use std::sync::Arc;

use rayon::prelude::*;

use crate::alloc::{try_collect, try_filled, try_reserve_len, try_zeroed};
use crate::error::{CoreError, Result};
use crate::image::{check_pair, Image};
use crate::simd::simd_fn;
use graph::{
    association_weights, candidates, knn_graph, solve, CandParams, Candidate, SolverParams,
};
use rtable::{build_rtable, RTable};
use tracking::{track, Curves, TrackParams};
use zerocross::{zero_crossings, ZeroCrossings};

/// Marr-Poggio channel width `w = 2 sqrt(2) sigma` in units of sigma (B.3, B.4.11).
pub const CHANNEL_WIDTH_SIGMAS: f32 = 2.0 * std::f32::consts::SQRT_2;

/// Parameters of the MCGM channel (defaults: algorithms.md B.2 with the B.8 changes).
#[derive(Debug, Clone, PartialEq)]
pub struct McgmParams {
    /// Smallest disparity searched (px).
    pub d_min: usize,
    /// Largest disparity searched (px).
    pub d_max: usize,
    /// LoG channels, coarse to fine (px, B.2: 4, 2, 1).
    pub sigmas: Vec<f32>,
    /// Channels with `sigma >= half_res_sigma` run at half resolution and are priors only.
    pub half_res_sigma: f32,
    pub track: TrackParams,
    /// Shortest kept segment: `max(min_len, min_len_sigmas * sigma)` pixels of the channel.
    pub min_len_sigmas: f32,
    pub cand: CandParams,
    /// Neighbours per segment in the adjacency graph (B.4.9: k-NN, k = 6).
    pub knn: usize,
    /// Longest adjacency edge (px, B.2: 60).
    pub r_graph: f32,
    pub solver: SolverParams,
    /// Curve pixels whose tangent is within this angle of horizontal get no disparity (deg).
    pub horiz_skip_deg: f32,
    /// Prior fill radius in sigmas of the next coarser channel (B.4.11: 4).
    pub prior_radius_sigmas: f32,
    /// Prior window half-width in sigmas of the channel (B.4.11: `2 sqrt 2`).
    pub prior_width_sigmas: f32,
    /// A coarser channel's match is dropped where a finer one lies within this many columns on
    /// the same row (px).
    pub fill_radius: i32,
    pub filters: FilterParams,
}

/// B.8's occlusion-boundary filters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterParams {
    /// Both-sides check on / off.
    pub sides: bool,
    /// Largest mean absolute grey difference of each half-window (grey in [0, 1]; B.8: 0.04,
    /// default 0.06 with 6-column half-windows: KITTI's matches with GT 248 -> 522 with
    /// `ght_min_score` 0.4, precision@1 >= 96 % on the other 16 GT scenes, docs/mcgm.md).
    pub sides_mad: f32,
    /// Half-window width (columns) and height (rows) (B.8: 4 x 7; default 6 x 7).
    pub sides_width: i32,
    pub sides_height: i32,
    /// Columns skipped between the edge pixel and each half-window (B.8: 1).
    pub sides_gap: i32,
    /// Each half-window must also match at least as well at the match's disparity as at any
    /// other disparity of the range more than 1 px away, up to `sides_best_margin` (MAD): the
    /// relative form catches low-contrast background an absolute threshold lets through.
    pub sides_best: bool,
    pub sides_best_margin: f32,
    /// Remove each half-window pair's mean difference before the MAD (exposure offsets).
    pub sides_mean_free: bool,
    /// Discontinuity filter on / off.
    pub disc: bool,
    /// Neighbourhood of the discontinuity filter (+- columns, +- rows; B.8: 6, 2).
    pub disc_dx: i32,
    pub disc_dy: i32,
    /// Largest disparity difference to a neighbour (px, B.8: 1).
    pub disc_tol: f32,
    /// Area check on / off: a 7x7 ZNCC re-measure of the disparity (best of the five integer
    /// disparities around the match's, parabola sub-pixel) must be an interior peak within
    /// `zncc_tol` px of the match's own (zero-crossing) disparity.
    pub zncc_check: bool,
    pub zncc_tol: f32,
}

impl FilterParams {
    /// Checks every field's range ([`mcgm_match`] and [`edge_filters`] call it: a
    /// `sides_width` below 1 indexed past the half-window's column table, a panic).
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("sides_mad", self.sides_mad),
            // Negative: no half-window passed (no matches, without a word); NaN: the test off.
            ("sides_best_margin", self.sides_best_margin),
            ("disc_tol", self.disc_tol),
            ("zncc_tol", self.zncc_tol),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(CoreError::param(
                    name,
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
        if self.sides_width < 1
            || self.sides_width as usize > MAX_SIDES_WIDTH
            || self.sides_height < 1
            || self.sides_gap < 0
            || self.disc_dx < 0
            || self.disc_dy < 0
        {
            return Err(CoreError::param(
                "filters",
                format!(
                    "sides_width in 1..={MAX_SIDES_WIDTH}, sides_height >= 1; sides_gap, \
                     disc_dx, disc_dy >= 0, got sides_width = {}, sides_height = {}, \
                     sides_gap = {}, disc_dx = {}, disc_dy = {}",
                    self.sides_width, self.sides_height, self.sides_gap, self.disc_dx, self.disc_dy
                ),
            ));
        }
        Ok(())
    }
}

impl Default for FilterParams {
    fn default() -> Self {
        FilterParams {
            sides: true,
            sides_mad: 0.06,
            sides_width: 6,
            sides_height: 7,
            sides_gap: 1,
            sides_best: true,
            sides_best_margin: 0.0,
            sides_mean_free: true,
            disc: true,
            disc_dx: 6,
            disc_dy: 2,
            disc_tol: 1.0,
            zncc_check: true,
            zncc_tol: 0.5,
        }
    }
}

impl Default for McgmParams {
    fn default() -> Self {
        McgmParams {
            d_min: 0,
            d_max: 64,
            sigmas: vec![4.0, 2.0, 1.0],
            half_res_sigma: 4.0,
            track: TrackParams {
                high_quantile: 0.5,
                low_ratio: 0.4,
                max_turn_deg: 60.0,
                min_len: 8,
            },
            min_len_sigmas: 4.0,
            cand: CandParams {
                seg_theta_tol_deg: 30.0,
                dy_band: 1,
                n_bins: 36,
                vote_bin_tol: 2,
                ght_min_score: 0.4,
                k_cand: 6,
            },
            knn: 6,
            r_graph: 60.0,
            solver: SolverParams {
                a: 1.0,
                b: 1.5,
                d: 1.0,
                theta: 0.3,
                dg_0: 0.5,
                dg_slope: 10.0,
                max_sweeps: 100,
                seed: 0,
            },
            horiz_skip_deg: 20.0,
            prior_radius_sigmas: 4.0,
            prior_width_sigmas: CHANNEL_WIDTH_SIGMAS,
            fill_radius: 1,
            filters: FilterParams::default(),
        }
    }
}

impl McgmParams {
    /// The tracking thresholds of a channel of `sigma` (its own pixels): the shortest kept
    /// segment is `max(min_len, min_len_sigmas * sigma)` pixels.
    pub fn track_params(&self, sigma: f32) -> TrackParams {
        TrackParams {
            min_len: self
                .track
                .min_len
                .max((self.min_len_sigmas * sigma).ceil() as usize),
            ..self.track
        }
    }
}

/// One per-pixel correspondence (full-resolution coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    /// Sub-pixel x of the left crossing and its row.
    pub xl: f32,
    pub yl: f32,
    /// Sub-pixel x of the right crossing and its row.
    pub xr: f32,
    pub yr: f32,
    /// GHT score of the matched segment pair.
    pub score: f32,
    /// Index of the channel in `sigmas`.
    pub channel: u8,
}

/// Zero crossings, curves and R-tables of one image in one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelCurves {
    /// `sigma` in the channel's own pixels (half the nominal value at half resolution).
    pub sigma: f32,
    /// 1 (full resolution) or 2 (decimated).
    pub scale: usize,
    pub width: usize,
    pub height: usize,
    pub log: Vec<f32>,
    pub zc: ZeroCrossings,
    pub curves: Curves,
    pub rtables: Vec<RTable>,
}

/// What one channel matched (for debugging and the GUI).
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelResult {
    pub sigma: f32,
    pub scale: usize,
    pub n_left: usize,
    pub n_right: usize,
    /// Disparity window per left segment (channel pixels), None = no candidates possible.
    pub windows: Vec<Option<(i32, i32)>>,
    pub candidates: Vec<Candidate>,
    /// Final network state of every candidate.
    pub state: Vec<u8>,
    /// Chosen candidate indices.
    pub chosen: Vec<usize>,
    /// Undirected adjacency edges of the left graph `(i, j)`, `i < j`.
    pub edges: Vec<(u32, u32)>,
    pub n_weights: usize,
    pub sweeps: usize,
    pub converged: bool,
    /// Per-pixel matches of this channel before combination and filters.
    pub matches: Vec<Match>,
}

/// Result of [`mcgm_match`].
#[derive(Debug, Clone, PartialEq)]
pub struct McgmOutput {
    pub matches: Vec<Match>,
    pub channels: Vec<ChannelResult>,
    /// Matches after the channel combination, before the filters.
    pub n_combined: usize,
    /// ... after the both-sides check.
    pub n_sides: usize,
    /// ... after the discontinuity filter (before the area check).
    pub n_disc: usize,
}

/// Largest `dy_band` (rows): a rectified pair's matches lie within a row or two.
pub const MAX_DY_BAND: i32 = 64;
/// Largest `fill_radius` (px).
pub const MAX_RADIUS: i32 = 4096;
/// Largest `n_theta_bins` (a tenth of a degree per bin).
pub const MAX_THETA_BINS: usize = 3600;

fn validate_params(p: &McgmParams) -> Result<()> {
    if p.d_max < p.d_min {
        return Err(CoreError::param(
            "max_disparity",
            format!("must be >= min_disparity ({}), got {}", p.d_min, p.d_max),
        ));
    }
    if p.sigmas.is_empty() {
        return Err(CoreError::param("sigmas", "needs at least one channel"));
    }
    for &s in &p.sigmas {
        if !(s.is_finite() && (0.3..=64.0).contains(&s)) {
            return Err(CoreError::param(
                "sigmas",
                format!("each sigma must lie in [0.3, 64] px, got {s}"),
            ));
        }
    }
    let unit = |v: f32| v.is_finite() && (0.0..=1.0).contains(&v);
    if !unit(p.track.high_quantile) {
        return Err(CoreError::param("high_quantile", "must lie in [0, 1]"));
    }
    if !unit(p.track.low_ratio) {
        return Err(CoreError::param("low_ratio", "must lie in [0, 1]"));
    }
    if !(p.track.max_turn_deg.is_finite() && p.track.max_turn_deg > 0.0) {
        return Err(CoreError::param("max_turn_deg", "must be > 0"));
    }
    // The R-tables hold n_bins entries per segment: an unbounded count is an allocation that
    // aborts the process instead of an error.
    if !(3..=MAX_THETA_BINS).contains(&p.cand.n_bins)
        || 2 * p.cand.vote_bin_tol.min(MAX_THETA_BINS) + 1 > p.cand.n_bins
    {
        return Err(CoreError::param(
            "n_theta_bins",
            format!(
                "needs 3..={MAX_THETA_BINS} bins and 2 * vote_bin_tol + 1 <= n_theta_bins, got {} and {}",
                p.cand.n_bins, p.cand.vote_bin_tol
            ),
        ));
    }
    if p.cand.k_cand == 0 {
        return Err(CoreError::param("k_cand", "must be >= 1"));
    }
    // Upper bounds keep the row index small and the window arithmetic inside i32: 1e9 rows of
    // band asked for 136 GB (an abort), a fill radius of i32::MAX overflowed into a bad index.
    if !(0..=MAX_DY_BAND).contains(&p.cand.dy_band) {
        return Err(CoreError::param(
            "dy_band",
            format!("must be in 0..={MAX_DY_BAND} rows, got {}", p.cand.dy_band),
        ));
    }
    if p.solver.max_sweeps == 0 {
        return Err(CoreError::param("max_sweeps", "must be >= 1"));
    }
    for (name, v) in [
        ("half_res_sigma", p.half_res_sigma),
        ("min_len_sigmas", p.min_len_sigmas),
        ("seg_theta_tol_deg", p.cand.seg_theta_tol_deg),
        ("ght_min_score", p.cand.ght_min_score),
        ("r_graph", p.r_graph),
        ("A", p.solver.a),
        ("B", p.solver.b),
        ("D", p.solver.d),
        ("theta", p.solver.theta),
        ("dg_0", p.solver.dg_0),
        ("dg_slope", p.solver.dg_slope),
        ("horiz_skip_deg", p.horiz_skip_deg),
        ("prior_radius_sigmas", p.prior_radius_sigmas),
        ("prior_width_sigmas", p.prior_width_sigmas),
        ("sides_mad", p.filters.sides_mad),
        ("disc_tol", p.filters.disc_tol),
        ("zncc_tol", p.filters.zncc_tol),
    ] {
        if !v.is_finite() || v < 0.0 {
            return Err(CoreError::param(
                name,
                format!("must be finite and >= 0, got {v}"),
            ));
        }
    }
    // A GHT score is at most 1 (graph.rs: the peak is at most the shorter segment's length):
    // a larger threshold kept no candidate, 0 matches without a word.
    if p.cand.ght_min_score > 1.0 {
        return Err(CoreError::param(
            "ght_min_score",
            format!(
                "must be in [0, 1] (a GHT score is at most 1), got {}",
                p.cand.ght_min_score
            ),
        ));
    }
    // An angle to the horizontal: above 90 degrees its sine (the skip's threshold) came round
    // again, 180 skipping nothing and 1e30 what sin(1e30 deg) happened to give.
    if p.horiz_skip_deg > 90.0 {
        return Err(CoreError::param(
            "horiz_skip_deg",
            format!("must be in [0, 90] degrees, got {}", p.horiz_skip_deg),
        ));
    }
    p.filters.validate()?;
    if !(0..=MAX_RADIUS).contains(&p.fill_radius) {
        return Err(CoreError::param(
            "fill_radius",
            format!("must be in 0..={MAX_RADIUS} px, got {}", p.fill_radius),
        ));
    }
    Ok(())
}

/// `(sigma in the channel's pixels, scale)` of nominal channel `sigma`.
fn channel_geometry(sigma: f32, p: &McgmParams) -> (f32, usize) {
    if sigma >= p.half_res_sigma {
        (sigma / 2.0, 2)
    } else {
        (sigma, 1)
    }
}

/// Whether some channel runs on the 2x-decimated image.
fn needs_half(p: &McgmParams) -> bool {
    p.sigmas.iter().any(|&s| s >= p.half_res_sigma)
}

/// The curves of nominal channel `sigma` of an image (`half`: its decimation, when some
/// channel needs it).
fn curves_at(
    img: &Image,
    half: Option<&Image>,
    sigma: f32,
    p: &McgmParams,
) -> Result<ChannelCurves> {
    let (sig, scale) = channel_geometry(sigma, p);
    let src = match (half, scale) {
        (Some(h), 2) => h,
        _ => img,
    };
    channel_curves(src, sig, scale, p)
}

/// LoG, zero crossings, curves and R-tables of `img` (already at the channel's resolution).
///
/// A failed allocation of a per-pixel plane is [`CoreError::OutOfMemory`].
pub fn channel_curves(
    img: &Image,
    sigma: f32,
    scale: usize,
    p: &McgmParams,
) -> Result<ChannelCurves> {
    let (w, h) = img.size();
    let log = log::log_filter(img, sigma)?;
    let zc = zero_crossings(&log, w, h)?;
    let tp = p.track_params(sigma);
    let curves = track(&zc, &tp)?;
    // One per segment: the list allocated checked (a `collect` aborted the process).
    let rtables = crate::alloc::try_par_collect(
        curves
            .segments
            .par_iter()
            .map(|s| build_rtable(s, &zc.theta, w, p.cand.n_bins)),
        "the MCGM matcher's R-tables per segment",
    )?;
    Ok(ChannelCurves {
        sigma,
        scale,
        width: w,
        height: h,
        log,
        zc,
        curves,
        rtables,
    })
}

/// Curves of every channel of one image (the debugging / GUI view of `curves(image)`).
pub fn image_curves(img: &Image, p: &McgmParams) -> Result<Vec<ChannelCurves>> {
    validate_params(p)?;
    crate::image::check_index_range(img.width, img.height)?;
    let half = needs_half(p).then(|| log::decimate2(img)).transpose()?;
    p.sigmas
        .par_iter()
        .map(|&s| curves_at(img, half.as_ref(), s, p))
        .collect()
}

/// Fixed neighbour order of the prior spreading (ties go to the first filled neighbour).
const SPREAD_ORDER: [(i32, i32); 8] = [
    (0, -1),
    (-1, 0),
    (1, 0),
    (0, 1),
    (-1, -1),
    (1, -1),
    (-1, 1),
    (1, 1),
];

/// Nearest-valid fill of a NaN map up to `radius` px in chessboard distance (B.4.11's
/// distance-limited spread), read pixel by pixel: the value of `radius` synchronous
/// 8-neighbour dilations, each new pixel taking the value of its first valid neighbour from the
/// previous step, in the order of `SPREAD_ORDER` (up, left, right, down, then the diagonals).
/// Computed without the dilations: the pixels a dilation fills at step `t` are those at
/// chessboard distance `t` from the valid ones (an exact two-pass distance transform), and
/// their valid neighbours one step before are the neighbours at distance `t - 1`; so a pixel's
/// value is found by following its first such neighbour down to distance 0. Only the pixels
/// asked for are followed (the windows need the segments' pixels, not the whole image).
pub struct SpreadPrior<'a> {
    map: &'a [f32],
    dist: Vec<u16>,
    /// Per pixel inside the border: the index in `SPREAD_ORDER` of its first neighbour one
    /// step closer (meaningful where `0 < dist < far`).
    parent: Vec<u8>,
    w: usize,
    h: usize,
    far: u16,
}

impl<'a> SpreadPrior<'a> {
    /// The distance transform of `map` (`w x h`, NaN = no value), capped at `radius + 1`
    /// (`radius <= 0`: no spread).
    ///
    /// A failed allocation of its planes is [`CoreError::OutOfMemory`].
    pub fn new(map: &'a [f32], w: usize, h: usize, radius: i32) -> Result<Self> {
        let far = radius.clamp(0, u16::MAX as i32 - 1) as u16 + 1;
        let mut dist: Vec<u16> = Vec::new();
        crate::alloc::try_reserve_len(&mut dist, map.len(), "the MCGM prior's distances")?;
        dist.extend(map.iter().map(|v| if v.is_finite() { 0 } else { far }));
        // Forward pass (neighbours above and to the left), then backward (below and right): each
        // row takes its vertical and diagonal terms from the row before, then the chain along x.
        for pass in 0..2 {
            for k in 0..h {
                let y = if pass == 0 { k } else { h - 1 - k };
                let (row, prev) = if k == 0 {
                    (&mut dist[y * w..(y + 1) * w], None)
                } else {
                    let py = if pass == 0 { y - 1 } else { y + 1 };
                    let (lo, hi) = dist.split_at_mut(y.max(py) * w);
                    if pass == 0 {
                        (&mut hi[..w], Some(&lo[py * w..(py + 1) * w]))
                    } else {
                        (&mut lo[y * w..(y + 1) * w], Some(&hi[..w]))
                    }
                };
                if let Some(p) = prev {
                    // The three pixels above (or below); the interior without branches.
                    let up = |m: u16| m.saturating_add(1);
                    if w == 1 {
                        row[0] = row[0].min(up(p[0]));
                    } else {
                        row[0] = row[0].min(up(p[0].min(p[1])));
                        row[w - 1] = row[w - 1].min(up(p[w - 1].min(p[w - 2])));
                        for ((o, a), (b, c)) in row[1..w - 1]
                            .iter_mut()
                            .zip(&p[..w - 2])
                            .zip(p[1..w - 1].iter().zip(&p[2..]))
                        {
                            *o = (*o).min(up((*a).min(*b).min(*c)));
                        }
                    }
                }
                // The chain along the row, its running value kept in a register. (Every value
                // stays <= far: it starts at 0 or far and only takes minima.)
                let mut run = far;
                if pass == 0 {
                    for v in row.iter_mut() {
                        run = (*v).min(run.saturating_add(1));
                        *v = run;
                    }
                } else {
                    for v in row.iter_mut().rev() {
                        run = (*v).min(run.saturating_add(1));
                        *v = run;
                    }
                }
            }
        }
        // The first closer neighbour of every pixel inside the border, for all directions at
        // once (rows in parallel, compares without branches): the last match in reverse order
        // is the first in SPREAD_ORDER.
        let mut parent = crate::alloc::try_zeroed::<u8>(w * h, "the MCGM prior's directions")?;
        if w >= 3 && h >= 3 {
            let dist = &dist;
            crate::parallel::for_each_row(&mut parent, w, |y, out| {
                if y == 0 || y + 1 == h {
                    return;
                }
                let c = &dist[y * w + 1..(y + 1) * w - 1];
                for (k, &(dx, dy)) in SPREAD_ORDER.iter().enumerate().rev() {
                    let o = ((y as i32 + dy) as usize) * w + (1 + dx) as usize;
                    let q = &dist[o..o + w - 2];
                    for ((p, &dc), &dq) in out[1..w - 1].iter_mut().zip(c).zip(q) {
                        *p = if dq.wrapping_add(1) == dc {
                            k as u8
                        } else {
                            *p
                        };
                    }
                }
            });
        }
        Ok(SpreadPrior {
            map,
            dist,
            parent,
            w,
            h,
            far,
        })
    }

    /// The spread value at `(x, y)` (beyond the radius: the map's own value, NaN or infinite).
    pub fn at(&self, x: usize, y: usize) -> f32 {
        let (w, h) = (self.w as i32, self.h as i32);
        let mut i = y * self.w + x;
        let mut d = self.dist[i];
        if d >= self.far {
            return self.map[i];
        }
        let (mut x, mut y) = (x as i32, y as i32);
        let step = SPREAD_ORDER.map(|(dx, dy)| dy as isize * self.w as isize + dx as isize);
        while d > 0 {
            // A pixel at distance d >= 1 has a neighbour at d - 1 (exact transform): the
            // first in SPREAD_ORDER, looked up away from the border.
            let k = if x >= 1 && y >= 1 && x + 1 < w && y + 1 < h {
                Some(self.parent[i] as usize)
            } else {
                SPREAD_ORDER.iter().position(|&(dx, dy)| {
                    let (nx, ny) = (x + dx, y + dy);
                    nx >= 0
                        && ny >= 0
                        && nx < w
                        && ny < h
                        && self.dist[ny as usize * self.w + nx as usize] == d - 1
                })
            }
            .expect("an exact chessboard distance has a neighbour one step closer");
            (x, y, d) = (x + SPREAD_ORDER[k].0, y + SPREAD_ORDER[k].1, d - 1);
            i = (i as isize + step[k]) as usize;
        }
        self.map[i]
    }
}

/// The whole spread map of [`SpreadPrior`] (`radius <= 0`: `map` itself).
pub fn spread_prior(map: &[f32], w: usize, h: usize, radius: i32) -> Result<Vec<f32>> {
    let sp = SpreadPrior::new(map, w, h, radius)?;
    let mut out = Vec::new();
    crate::alloc::try_reserve_len(&mut out, w * h, "the MCGM prior")?;
    out.extend((0..w * h).map(|i| sp.at(i % w, i / w)));
    Ok(out)
}

/// Median (lower of the two middle values for even counts: a value that exists).
fn median_lower(v: &mut [f32]) -> Option<f32> {
    if v.is_empty() {
        return None;
    }
    // The element a total-order sort would put there (a selection: no full sort).
    let k = (v.len() - 1) / 2;
    Some(*v.select_nth_unstable_by(k, f32::total_cmp).1)
}

/// Disparity windows of the left segments of a channel from the spread prior map
/// (full-resolution disparities, NaN = none): the median of the prior over the segment's pixels,
/// `+- width` channel px around it; the full range without a prior.
fn windows(
    cc: &ChannelCurves,
    prior: Option<&SpreadPrior>,
    fw: usize,
    width: f32,
    lo_c: i32,
    hi_c: i32,
) -> Result<Vec<Option<(i32, i32)>>> {
    // One window per segment, and a segment's prior values (as long as the segment): checked,
    // they were allocated by vec!/collect/with_capacity.
    const WHAT: &str = "the MCGM matcher's disparity windows";
    let full = Some((lo_c, hi_c)).filter(|w| w.0 <= w.1);
    let mut out = crate::alloc::try_filled(cc.curves.segments.len(), full, WHAT)?;
    let Some(prior) = prior else {
        return Ok(out);
    };
    let s = cc.scale as f32;
    let (w, sc) = (cc.width, cc.scale);
    let fh = prior.h;
    out.par_iter_mut()
        .zip(&cc.curves.segments)
        .try_for_each(|(win, seg)| -> Result<()> {
            let mut vals: Vec<f32> = Vec::new();
            crate::alloc::try_reserve_len(&mut vals, seg.pixels.len(), WHAT)?;
            for &i in &seg.pixels {
                let (x, y) = (i as usize % w, i as usize / w);
                // Channel pixel centre in full-resolution coordinates, rounded (half away
                // from zero): `round(s x + (s - 1) / 2) = s x + s / 2` for integer s, x.
                let fx = (sc * x + sc / 2).min(fw - 1);
                let fy = (sc * y + sc / 2).min(fh - 1);
                let v = prior.at(fx, fy);
                if v.is_finite() {
                    vals.push(v / s);
                }
            }
            *win = match median_lower(&mut vals) {
                None => full,
                Some(d) => {
                    let lo = ((d - width).floor() as i32).max(lo_c);
                    let hi = ((d + width).ceil() as i32).min(hi_c);
                    (lo <= hi).then_some((lo, hi))
                }
            };
            Ok(())
        })?;
    Ok(out)
}

/// Per-pixel correspondences along the chosen pairs (B.4.12), in full-resolution coordinates.
fn decompose(
    l: &ChannelCurves,
    r: &ChannelCurves,
    cands: &[Candidate],
    chosen: &[usize],
    horiz_skip_deg: f32,
    channel: u8,
) -> Result<Vec<Match>> {
    let (w, h) = (l.width, l.height);
    let min_cos = (horiz_skip_deg as f64).to_radians().sin();
    let half = 0.5 * CHANNEL_WIDTH_SIGMAS * l.sigma;
    let s = l.scale as f32;
    let to_full = |v: f32| s * v + 0.5 * (s - 1.0);
    // The matches of each chosen pair (up to one a pixel of its left segment), and their list:
    // checked, they grew by push and collect.
    const WHAT: &str = "the MCGM matcher's curve matches";
    let mut per: Vec<Vec<Match>> = crate::alloc::try_filled(chosen.len(), Vec::new(), WHAT)?;
    per.par_iter_mut()
        .zip(chosen)
        .try_for_each(|(out, &ci)| -> Result<()> {
            let c = &cands[ci];
            let seg = &l.curves.segments[c.left as usize];
            for &i in &seg.pixels {
                let i = i as usize;
                if (l.zc.theta[i] as f64).cos().abs() < min_cos {
                    continue; // near-horizontal tangent: x-disparity ill-defined
                }
                let (x, y) = (i % w, i / w);
                let xp = l.zc.xsub[i];
                let target = xp - c.tx;
                let yq = y as i32; // rectified input: the same row (B.4.12)
                if yq < 0 || yq >= h as i32 {
                    continue;
                }
                let x0 = ((target - half).floor() as i32).max(0);
                let x1 = ((target + half).ceil() as i32).min(w as i32 - 1);
                let mut best: Option<(f32, usize)> = None;
                for xq in x0..=x1 {
                    let q = yq as usize * w + xq as usize;
                    if r.curves.labels[q] != c.right as i32 {
                        continue;
                    }
                    let dist = (r.zc.xsub[q] - target).abs();
                    if dist <= half && best.is_none_or(|b| dist < b.0) {
                        best = Some((dist, q));
                    }
                }
                let _ = x;
                if let Some((_, q)) = best {
                    crate::alloc::try_grow(out, 1, WHAT)?;
                    out.push(Match {
                        xl: to_full(xp),
                        yl: to_full(y as f32),
                        xr: to_full(r.zc.xsub[q]),
                        yr: to_full(yq as f32),
                        score: c.score,
                        channel,
                    });
                }
            }
            Ok(())
        })?;
    crate::alloc::try_concat(per, WHAT)
}

/// Mean absolute difference of one half-window (columns `xi + side * (inner..=outer)`, rows
/// `yl +- hh`) against the right image shifted by `d` (linear interpolation along x). With
/// `mean_free` the two windows' mean grey levels are removed first: insensitive to an exposure
/// offset between the cameras (ETH3D), still sensitive to different content.
#[allow(clippy::too_many_arguments)]
fn half_mad(
    left: &Image,
    right: &Image,
    xi: i32,
    yl: i32,
    yr: i32,
    d: f32,
    side: i32,
    (inner, outer, hh): (i32, i32, i32),
    mean_free: bool,
    diffs: &mut Vec<f32>,
) -> f32 {
    let n = ((outer - inner + 1) * (2 * hh + 1)) as f32;
    // Per column: the left x, the two right columns of the linear interpolation and its weight
    // (the same on every row: computed once, not once per row and pass).
    let mut cols = [(0usize, 0usize, 0usize, 0.0f32); MAX_SIDES_WIDTH];
    let nc = (outer - inner + 1) as usize;
    for (c, k) in (inner..=outer).enumerate() {
        let x = xi + side * k;
        let pos = x as f32 - d;
        let x0 = (pos.floor() as usize).min(right.width - 1);
        let x1 = (x0 + 1).min(right.width - 1);
        cols[c] = (x as usize, x0, x1, pos - x0 as f32);
    }
    // The differences once, in raster order, for both passes (`diffs`: the caller's buffer);
    // each row's left and right slices taken once, not once per pixel.
    diffs.clear();
    for dy in -hh..=hh {
        let (ly, ry) = ((yl + dy) as usize, (yr + dy) as usize);
        let lrow = &left.data[ly * left.width..(ly + 1) * left.width];
        let rrow = &right.data[ry * right.width..(ry + 1) * right.width];
        diffs.extend(
            cols[..nc]
                .iter()
                .map(|&(x, x0, x1, f)| lrow[x] - (rrow[x0] + f * (rrow[x1] - rrow[x0]))),
        );
    }
    let mut offset = 0.0f32;
    if mean_free {
        for &e in diffs.iter() {
            offset += e;
        }
        offset /= n;
    }
    let mut sad = 0.0f32;
    for &e in diffs.iter() {
        sad += (e - offset).abs();
    }
    sad / n
}

/// A half-window's columns (`x = xi + side * (inner..=outer)`): each one's right interpolation
/// base and weight (`x - d` split into floor and fraction), the smallest and largest base, and
/// the range `(k_lo, k_hi)` of integer steps whose samples `r[b - k]`, `r[b - k + 1]` all lie
/// inside a row of `width` (empty when `k_hi < k_lo`).
#[allow(clippy::type_complexity)]
fn window_bases(
    (xi, _, _, d): (i32, i32, i32, f32),
    side: i32,
    (inner, outer, _): (i32, i32, i32),
    ks: (i32, i32),
    width: usize,
) -> ([(i32, f32); MAX_SIDES_WIDTH], (i32, i32), (i32, i32)) {
    let mut base = [(0i32, 0.0f32); MAX_SIDES_WIDTH];
    let (mut b_min, mut b_max) = (i32::MAX, i32::MIN);
    for (c, k) in (inner..=outer).enumerate() {
        let pos = (xi + side * k) as f32 - d;
        let b = pos.floor();
        base[c] = (b as i32, pos - b);
        b_min = b_min.min(b as i32);
        b_max = b_max.max(b as i32);
    }
    let ks = (ks.0.max(b_max + 2 - width as i32), ks.1.min(b_min));
    (base, (b_min, b_max), ks)
}

/// A half-window's pixels in raster order, appended to `els`: (offset of `r[b - k_hi]` in a
/// right image `right_width` wide, left value, interpolation weight), with `base` from
/// [`window_bases`].
fn window_elements(
    left: &Image,
    right_width: usize,
    (xi, yl, yr, _): (i32, i32, i32, f32),
    side: i32,
    (inner, outer, hh): (i32, i32, i32),
    (base, k_hi): (&[(i32, f32); MAX_SIDES_WIDTH], i32),
    els: &mut Vec<(usize, f32, f32)>,
) {
    for dy in -hh..=hh {
        let lrow = &left.data[(yl + dy) as usize * left.width..][..left.width];
        let rrow = (yr + dy) as usize * right_width;
        for (c, k) in (inner..=outer).enumerate() {
            let (b, fr) = base[c];
            els.push((
                rrow + (b - k_hi) as usize,
                lrow[(xi + side * k) as usize],
                fr,
            ));
        }
    }
}

simd_fn! {
/// Whether one half-window fits another disparity better: its mean absolute difference (as
/// [`half_mad`]) at some `d + k`, `k` integer in `ks`, `|k| > 1`, every right sample inside the
/// row, plus `margin` is below `here` (its value at `d`). Integer steps keep the interpolation
/// weights of `d` (right samples `r[b - k] + f (r[b - k + 1] - r[b - k])` with
/// `b = floor(x - d)`, `f = x - d - b`), so every `k` is compared fairly with `k = 0`, whose
/// value would be exactly [`half_mad`]'s (the same terms summed in the same order). The right
/// samples of one window pixel are contiguous in `j = k_hi - k`: a block of 8 `j` keeps its
/// sums in registers over the window's pixels (raster order), the mean-free pass recomputes
/// each difference instead of storing it, only the blocks with a lane that [`SidesBound`]
/// leaves open are summed, and the scan stops at the first lane that fits better. `at`: the
/// match `(x, left row, right row, disparity)`; `limit`: `(here, margin)`.
fn half_better(
    left: &Image,
    right: &Image,
    at: (i32, i32, i32, f32),
    side: i32,
    geom: (i32, i32, i32),
    mean_free: bool,
    ks: (i32, i32),
    limit: (f32, f32),
    scratch: &mut SidesScratch,
) -> bool {
    let (base, b_range, (k_lo, k_hi)) = window_bases(at, side, geom, ks, right.width);
    if k_hi < k_lo {
        return false;
    }
    let nk = (k_hi - k_lo + 1) as usize;
    scratch.els.clear();
    let bound = SidesBound::new(left, right, at, side, geom, (k_hi, nk), (&base, b_range), scratch);
    let (here, margin) = limit;
    // Rounding: every sum of the bound and of the exact test adds at most 2 nc nr terms of
    // magnitude <= 2 max|value| (`scale`: the pair's largest); 1e-4 of that is far above
    // their f32 error.
    let open_below = here - margin + 1e-4 * (1.0 + scratch.scale);
    // Lanes `j` whose `k = k_hi - j` is within 1 px of the match are not compared.
    let near = |j0: usize| -> u32 {
        (-1..=1).fold(0u32, |m, k| {
            let j = k_hi - k - j0 as i32;
            if (0..8).contains(&j) {
                m | 1 << j
            } else {
                m
            }
        })
    };
    let r = &right.data[..];
    let mut n = 0.0;
    // Block by block (8 lanes): the bound first, then the exact sums of the lanes it leaves
    // open (a lane's sum is the same in a block of 8 as alone: the same terms in the same
    // order); the scan stops at the first lane that fits better.
    if bound.shared_weight {
        bound.lane_sums(&mut scratch.rows, nk.div_ceil(8) * 8, mean_free);
        // Usually no lane is open at all: then no block is, and the answer is `false`
        // without the block scan.
        if !bound.any_open(&scratch.rows.lane_acc[..nk], k_hi, open_below) {
            return false;
        }
    }
    for j0 in (0..nk).step_by(8) {
        let lanes = (nk - j0).min(8);
        let open = if bound.shared_weight {
            let mut acc = [0.0f32; 8];
            acc.copy_from_slice(&scratch.rows.lane_acc[j0..j0 + 8]);
            bound.lane_bits(&acc, open_below)
        } else {
            bound.open_lanes(&scratch.rows, &mut scratch.tb, j0, mean_free, open_below)
        }
            & ((1u32 << lanes) - 1)
            & !near(j0);
        if open == 0 {
            continue;
        }
        let els = &mut scratch.els;
        if els.is_empty() {
            window_elements(left, right.width, at, side, geom, (&base, k_hi), els);
            n = els.len() as f32;
        }
        let fits = if lanes == 8 {
            sads_fit_mask::<8>(r, els, j0, n, mean_free, limit)
        } else {
            (0..lanes).fold(0u32, |m, t| {
                m | (sads_fit_mask::<1>(r, els, j0 + t, n, mean_free, limit) << t)
            })
        };
        if fits & open != 0 {
            return true;
        }
    }
    false
}
}

/// A lower bound of [`half_better`]'s sums, lane by lane (`j`, disparity `d + k_hi - j`): for
/// any grouping of the window's differences `e_i` (their mean `m` removed with `mean_free`,
/// else `m = 0`), `sum |e_i - m| >= sum over groups |sum_g e_i - n_g m|`; the groups are each
/// column's upper and lower half. Their right sums are interpolated from the column-wise sums
/// of the right rows ([`BoundRows`] in the scratch), a few operations per lane where the
/// exact sums take a few hundred. On 600 of cloth3's MCGM matches it leaves 0.3 % of the lanes
/// open and 1.5 % of the blocks of 8 (each column whole: 5.9 % and 20 %). A lane it rules out
/// cannot fit better, so [`half_better`]'s answer is the same as without it.
struct SidesBound {
    nc: usize,
    /// Per window column: the offset of its right base from the smallest one, its
    /// interpolation weight, and the left sums of its upper and lower half.
    cols: [(usize, f32, f32, f32); MAX_SIDES_WIDTH],
    ltot: f32,
    /// Rows in the upper and lower half.
    rows: (f32, f32),
    n: f32,
    /// Every column has the same interpolation weight (the usual case: `x - d` rounds alike
    /// for all columns unless they straddle a power of two): its interpolated sums were
    /// computed once per window ([`BoundRows`]'s `lerp_*`), not once per column and block.
    shared_weight: bool,
}

/// The right rows' column-wise sums of [`SidesBound`], and with one interpolation weight
/// for every column, those sums interpolated (`v[p] + f (v[p + 1] - v[p])`, the bound's
/// operation) and their upper + lower total.
#[derive(Default)]
struct BoundRows {
    v_top: Vec<f32>,
    v_bot: Vec<f32>,
    lerp_top: Vec<f32>,
    lerp_bot: Vec<f32>,
    lerp_sum: Vec<f32>,
    /// [`SidesBound::lane_sums`]' per-lane mean and bound sums.
    lane_m: Vec<f32>,
    lane_acc: Vec<f32>,
}

impl SidesBound {
    /// Left group sums, and the right rows' column-wise sums into `scratch` (padded by a
    /// block of lanes).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn new(
        left: &Image,
        right: &Image,
        (xi, yl, yr, _): (i32, i32, i32, f32),
        side: i32,
        (inner, outer, hh): (i32, i32, i32),
        (k_hi, nk): (i32, usize),
        (base, (b_min, b_max)): (&[(i32, f32); MAX_SIDES_WIDTH], (i32, i32)),
        scratch: &mut SidesScratch,
    ) -> Self {
        let nc = (outer - inner + 1) as usize;
        let nr = (2 * hh + 1) as usize;
        let n_top = nr.div_ceil(2);
        // Each column keeps its own base and weight, as the exact sums do (the bases are
        // consecutive but for rounding of x - d next to a whole pixel).
        let mut cols = [(0usize, 0.0f32, 0.0f32, 0.0f32); MAX_SIDES_WIDTH];
        // The edge filters' column sums when they were computed for this half-height (the
        // same additions in the same order as below, so the same bits).
        let planes = scratch.sums.as_deref().filter(|s| s[0].hh == hh);
        for (c, k) in (inner..=outer).enumerate() {
            let (b, f) = base[c];
            let x = (xi + side * k) as usize;
            let (top, bot) = if let Some([l, _]) = planes {
                let i = yl as usize * left.width + x;
                (l.top[i], l.bot[i])
            } else {
                let (mut top, mut bot) = (0.0f32, 0.0f32);
                for (ri, dy) in (-hh..=hh).enumerate() {
                    let v = left.data[(yl + dy) as usize * left.width + x];
                    if ri < n_top {
                        top += v;
                    } else {
                        bot += v;
                    }
                }
                (top, bot)
            };
            cols[c] = ((b - b_min) as usize, f, top, bot);
        }
        let ltot: f32 = cols[..nc].iter().map(|c| c.2 + c.3).sum();
        // Right samples p0 ..= p0 + (b_max - b_min) + nk: lane j of a column at offset o reads
        // p0 + o + j and the next one (inside the row: half_better's lane range ensures it).
        let span = (b_max - b_min) as usize + nk + 1;
        let p0 = (b_min - k_hi) as usize;
        let rows = &mut scratch.rows;
        let (v_top, v_bot) = (&mut rows.v_top, &mut rows.v_bot);
        let padded = span + nk.div_ceil(8) * 8 - nk;
        if let Some([_, r]) = planes {
            // Copied from the right image's column sums (no zero-fill and 2 hh + 1 row adds).
            let o = yr as usize * right.width + p0;
            for (v, plane) in [(&mut *v_top, &r.top), (&mut *v_bot, &r.bot)] {
                v.clear();
                v.extend_from_slice(&plane[o..o + span]);
                v.resize(padded, 0.0);
            }
        } else {
            for v in [&mut *v_top, &mut *v_bot] {
                v.clear();
                v.resize(padded, 0.0);
            }
            for (ri, dy) in (-hh..=hh).enumerate() {
                let o = (yr + dy) as usize * right.width + p0;
                let rrow = &right.data[o..o + span];
                let v = if ri < n_top { &mut *v_top } else { &mut *v_bot };
                for (a, &x) in v.iter_mut().zip(rrow) {
                    *a += x;
                }
            }
        }
        // One weight for all columns: each sum interpolated once here (every column and
        // block then reads it), the same operation on the same values as per column.
        let f0 = cols[0].1;
        let shared_weight = cols[..nc].iter().all(|c| c.1.to_bits() == f0.to_bits());
        if shared_weight {
            let lerp = |v: &[f32], out: &mut Vec<f32>| {
                out.clear();
                out.extend(v.iter().zip(&v[1..]).map(|(&a, &b)| a + f0 * (b - a)));
            };
            lerp(&rows.v_top, &mut rows.lerp_top);
            lerp(&rows.v_bot, &mut rows.lerp_bot);
            rows.lerp_sum.clear();
            rows.lerp_sum.extend(
                rows.lerp_top
                    .iter()
                    .zip(&rows.lerp_bot)
                    .map(|(&t, &b)| t + b),
            );
        }
        Self {
            nc,
            cols,
            ltot,
            rows: (n_top as f32, (nr - n_top) as f32),
            n: (nc * nr) as f32,
            shared_weight,
        }
    }

    /// Bit `t` set when lane `j0 + t` is not ruled out: its bound / n is below `open_below`.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn open_lanes(
        &self,
        sums: &BoundRows,
        tb: &mut [([f32; 8], [f32; 8]); MAX_SIDES_WIDTH],
        j0: usize,
        mean_free: bool,
        open_below: f32,
    ) -> u32 {
        let (v_top, v_bot) = (&sums.v_top[..], &sums.v_bot[..]);
        let interp = |v: &[f32], o: usize, f: f32| -> [f32; 8] {
            let v = &v[o + j0..o + j0 + 9];
            std::array::from_fn(|t| v[t] + f * (v[t + 1] - v[t]))
        };
        let cols = &self.cols[..self.nc];
        // Each column's interpolated right sums, once for both passes (the mean pass and the
        // bound read the same values), in the caller's buffer (no per-block array to zero).
        for (s, &(o, f, _, _)) in tb.iter_mut().zip(cols) {
            *s = (interp(v_top, o, f), interp(v_bot, o, f));
        }
        let tb = &tb[..self.nc];
        let mut m = [0.0f32; 8];
        if mean_free {
            for (t, b) in tb {
                for q in 0..8 {
                    m[q] += t[q] + b[q];
                }
            }
            for q in &mut m {
                *q = (self.ltot - *q) / self.n;
            }
        }
        let (wt, wb) = self.rows;
        let mut acc = [0.0f32; 8];
        for (&(_, _, lt, lb), (t, b)) in cols.iter().zip(tb) {
            for q in 0..8 {
                acc[q] += (lt - t[q] - wt * m[q]).abs() + (lb - b[q] - wb * m[q]).abs();
            }
        }
        self.lane_bits(&acc, open_below)
    }

    /// With one interpolation weight for every column ([`Self::shared_weight`]): the bound's
    /// sums of every lane `0..nl` at once, into `sums.lane_acc` (`nl`: the lane count rounded
    /// up to a block). Per lane the same values are added in the same order as
    /// [`Self::open_lanes`] adds them (columns in order), so `lane_bits` of a block of them
    /// gives its bits; a column's lanes are one run of loads, not a block of 8 at a time.
    #[inline(always)]
    fn lane_sums(&self, sums: &mut BoundRows, nl: usize, mean_free: bool) {
        let cols = &self.cols[..self.nc];
        let BoundRows {
            lerp_top,
            lerp_bot,
            lerp_sum,
            lane_m: m,
            lane_acc: acc,
            ..
        } = sums;
        m.clear();
        m.resize(nl, 0.0);
        if mean_free {
            for &(o, _, _, _) in cols {
                for (q, &s) in m.iter_mut().zip(&lerp_sum[o..o + nl]) {
                    *q += s;
                }
            }
            for q in m.iter_mut() {
                *q = (self.ltot - *q) / self.n;
            }
        }
        acc.clear();
        acc.resize(nl, 0.0);
        let (wt, wb) = self.rows;
        for &(o, _, lt, lb) in cols {
            let lanes = acc
                .iter_mut()
                .zip(&m[..])
                .zip(lerp_top[o..o + nl].iter().zip(&lerp_bot[o..o + nl]));
            for ((a, &q), (&t, &b)) in lanes {
                *a += (lt - t - wt * q).abs() + (lb - b - wb * q).abs();
            }
        }
    }

    /// Whether [`Self::lane_bits`] would set a bit for some lane of `acc` (lanes `0..nk`) that
    /// is more than 1 px from the match (`k = k_hi - j` outside `-1..=1`). One test on the
    /// smallest sum: `/ n` (n > 0) is monotone, so `acc[t] / n < open_below` holds for some
    /// lane iff it holds for their minimum (a NaN sum, never open, is skipped by the `<`).
    #[inline(always)]
    fn any_open(&self, acc: &[f32], k_hi: i32, open_below: f32) -> bool {
        let nk = acc.len() as i64;
        let near = |k: i64| (i64::from(k_hi) - k).clamp(0, nk) as usize;
        // Eight running minima (`v < low ? v : low`, a vector min), then theirs.
        let mut low = [f32::INFINITY; 8];
        for part in [&acc[..near(1)], &acc[near(-2)..]] {
            let mut blocks = part.chunks_exact(8);
            for b in &mut blocks {
                for (l, &v) in low.iter_mut().zip(b) {
                    *l = if v < *l { v } else { *l };
                }
            }
            for (l, &v) in low.iter_mut().zip(blocks.remainder()) {
                *l = if v < *l { v } else { *l };
            }
        }
        let low = low
            .iter()
            .fold(f32::INFINITY, |m, &v| if v < m { v } else { m });
        low / self.n < open_below
    }

    /// Bit `t` set when `acc[t] / n` is below `open_below`.
    #[inline(always)]
    fn lane_bits(&self, acc: &[f32; 8], open_below: f32) -> u32 {
        // Compares first, then the bits (a vector compare and a mask, not eight branches).
        let below: [bool; 8] = std::array::from_fn(|t| acc[t] / self.n < open_below);
        below
            .iter()
            .enumerate()
            .fold(0u32, |bits, (t, &b)| bits | (u32::from(b) << t))
    }
}

/// For `J` consecutive `j` from `j0` (`J` = 1, 8 or 32), bit `t` set when lane `j0 + t` fits
/// better: its sum over the window's pixels (in order) of the absolute deviations of the
/// differences from their mean (with `mean_free`; 0 otherwise), divided by `n`, plus `margin`,
/// is below `here` (`limit = (here, margin)`). AVX2 when the CPU has it, the same operations in
/// the same order per lane otherwise (bit-identical).
#[inline(always)]
fn sads_fit_mask<const J: usize>(
    r: &[f32],
    els: &[(usize, f32, f32)],
    j0: usize,
    n: f32,
    mean_free: bool,
    limit: (f32, f32),
) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if J.is_multiple_of(8) && crate::simd::has_avx2() {
        // SAFETY: AVX2 is present; every element's `J + 1` samples from `o + j0` lie in `r`
        // (checked by the slice below).
        return unsafe { sads_fit_mask_avx2::<J>(r, els, j0, n, mean_free, limit) };
    }
    let (here, margin) = limit;
    let mut m = 0u32;
    for (t, &a) in sads_scalar::<J>(r, els, j0, n, mean_free)
        .iter()
        .enumerate()
    {
        m |= u32::from(a / n + margin < here) << t;
    }
    m
}

/// The sums of [`sads_fit_mask`] (portable).
#[inline(always)]
fn sads_scalar<const J: usize>(
    r: &[f32],
    els: &[(usize, f32, f32)],
    j0: usize,
    n: f32,
    mean_free: bool,
) -> [f32; J] {
    // `lv - (r[o] + fr (r[o + 1] - r[o]))`: left value minus the interpolated right one.
    let diffs = |&(o, lv, fr): &(usize, f32, f32)| -> [f32; J] {
        let s = &r[o + j0..o + j0 + J + 1];
        std::array::from_fn(|t| lv - (s[t] + fr * (s[t + 1] - s[t])))
    };
    let mut off = [0.0f32; J];
    if mean_free {
        for e in els {
            let v = diffs(e);
            for t in 0..J {
                off[t] += v[t];
            }
        }
        for o in off.iter_mut() {
            *o /= n;
        }
    }
    let mut acc = [0.0f32; J];
    for e in els {
        let v = diffs(e);
        for t in 0..J {
            acc[t] += (v[t] - off[t]).abs();
        }
    }
    acc
}

/// [`sads_fit_mask`] with AVX2 intrinsics: `J / 8` vectors of sums kept in registers, the
/// shifted samples loaded unaligned (the compiler otherwise builds them by shuffles).
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sads_fit_mask_avx2<const J: usize>(
    r: &[f32],
    els: &[(usize, f32, f32)],
    j0: usize,
    n: f32,
    mean_free: bool,
    (here, margin): (f32, f32),
) -> u32 {
    use std::arch::x86_64::*;
    const MAXQ: usize = 4;
    let q = J / 8;
    debug_assert!(q <= MAXQ);
    let mut off = [_mm256_setzero_ps(); MAXQ];
    let mut acc = [_mm256_setzero_ps(); MAXQ];
    // SAFETY: every `p` below starts a bounds-checked slice of J + 1 samples, and `diff` reads
    // p[8 v..8 v + 9] for v < q = J / 8, so at most p[J]: inside the slice.
    let diff = |p: *const f32, lv: __m256, fr: __m256| {
        let a = _mm256_loadu_ps(p);
        let b = _mm256_loadu_ps(p.add(1));
        _mm256_sub_ps(lv, _mm256_add_ps(a, _mm256_mul_ps(fr, _mm256_sub_ps(b, a))))
    };
    if mean_free {
        for &(o, lv, fr) in els {
            let p = r[o + j0..o + j0 + J + 1].as_ptr();
            let (lv, fr) = (_mm256_set1_ps(lv), _mm256_set1_ps(fr));
            for (v, off) in off.iter_mut().enumerate().take(q) {
                *off = _mm256_add_ps(*off, diff(p.add(8 * v), lv, fr));
            }
        }
        let nv = _mm256_set1_ps(n);
        for off in off.iter_mut().take(q) {
            *off = _mm256_div_ps(*off, nv);
        }
    }
    let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
    for &(o, lv, fr) in els {
        let p = r[o + j0..o + j0 + J + 1].as_ptr();
        let (lv, fr) = (_mm256_set1_ps(lv), _mm256_set1_ps(fr));
        for v in 0..q {
            let dev = _mm256_and_ps(_mm256_sub_ps(diff(p.add(8 * v), lv, fr), off[v]), abs);
            acc[v] = _mm256_add_ps(acc[v], dev);
        }
    }
    let (nv, mv, hv) = (
        _mm256_set1_ps(n),
        _mm256_set1_ps(margin),
        _mm256_set1_ps(here),
    );
    let mut m = 0u32;
    for (v, a) in acc.iter().enumerate().take(q) {
        let fit = _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_add_ps(_mm256_div_ps(*a, nv), mv), hv);
        m |= (_mm256_movemask_ps(fit) as u32) << (8 * v);
    }
    m
}

/// Per-thread buffer of [`half_better`] (no allocation per match).
#[derive(Default)]
struct SidesScratch {
    els: Vec<(usize, f32, f32)>,
    /// [`SidesBound`]'s column-wise sums of the right rows' upper and lower halves.
    rows: BoundRows,
    /// [`SidesBound::open_lanes`]' interpolated column sums (upper, lower half) of a block.
    tb: [([f32; 8], [f32; 8]); MAX_SIDES_WIDTH],
    /// [`half_mad`]'s differences of one half-window.
    diffs: Vec<f32>,
    /// The largest absolute grey value of the pair (the bound's rounding slack).
    scale: f32,
    /// The left and right images' [`HalfSums`] ([`edge_filters`] computes them once for all
    /// matches when there are enough of them; without them each window sums its rows).
    sums: Option<Arc<[HalfSums; 2]>>,
}

/// An image's column sums over the rows of [`SidesBound`]'s half-windows, for every pixel at
/// once: at `(x, y)`, `top` sums rows `y - hh ..= y` and `bot` rows `y + 1 ..= y + hh` of
/// column `x`, each from 0 in row order, the additions [`SidesBound::new`] makes for one
/// window (so the same bits). Neighbouring matches' windows share most of their columns:
/// summed once here instead of once per window. Rows within `hh` of the border stay 0 (no
/// half-window fits there).
struct HalfSums {
    hh: i32,
    top: Vec<f32>,
    bot: Vec<f32>,
}

impl HalfSums {
    /// The sums of `img` (`None` where its planes do not fit in memory: the windows then sum
    /// their own rows, as before).
    fn new(img: &Image, hh: i32) -> Option<Self> {
        let (w, h) = img.size();
        let mut top = try_zeroed::<f32>(w * h, FILTER_LISTS).ok()?;
        let mut bot = try_zeroed::<f32>(w * h, FILTER_LISTS).ok()?;
        let r = usize::try_from(hh).ok()?;
        if w > 0 {
            top.par_chunks_mut(w)
                .zip(bot.par_chunks_mut(w))
                .enumerate()
                .filter(|(y, _)| *y >= r && y + r < h)
                .for_each(|(y, (t, b))| half_sums_row(&img.data, w, y, r, t, b));
        }
        Some(Self { hh, top, bot })
    }
}

simd_fn! {
/// Row `y` of [`HalfSums`] (`r <= y < h - r`): rows `y - r ..= y` of `data` (`w` wide) added
/// into `top`, rows `y + 1 ..= y + r` into `bot`, in row order. Compiled for AVX2 too: the
/// same additions per element (lanes are independent), eight at a time.
fn half_sums_row(data: &[f32], w: usize, y: usize, r: usize, top: &mut [f32], bot: &mut [f32]) {
    for ry in y - r..=y {
        for (a, &v) in top.iter_mut().zip(&data[ry * w..(ry + 1) * w]) {
            *a += v;
        }
    }
    for ry in y + 1..=y + r {
        for (a, &v) in bot.iter_mut().zip(&data[ry * w..(ry + 1) * w]) {
            *a += v;
        }
    }
}
}

/// Widest half-window of the both-sides check (columns; validated).
const MAX_SIDES_WIDTH: usize = 16;

/// Both-sides check of one match: the half-windows left and right of the edge agree between
/// the images (mean absolute grey difference <= `sides_mad` on both sides) and, with
/// `sides_best`, neither half-window prefers another disparity of `range` (> 1 px away).
fn sides_ok(
    left: &Image,
    right: &Image,
    m: &Match,
    f: &FilterParams,
    range: (i32, i32),
    scratch: &mut SidesScratch,
) -> bool {
    let (w, h) = (left.width as i32, left.height as i32);
    let xi = m.xl.round() as i32;
    let (yl, yr) = (m.yl.round() as i32, m.yr.round() as i32);
    let d = m.xl - m.xr;
    let hh = f.sides_height / 2;
    if yl - hh < 0 || yr - hh < 0 || yl + hh >= h || yr + hh >= h {
        return false;
    }
    // Saturating and in i64: a `sides_gap` near i32::MAX (validate takes any >= 0) wrapped
    // `outer` negative, and columns far outside the image were indexed (a panic).
    let inner = f.sides_gap.saturating_add(1);
    let outer = f.sides_gap.saturating_add(f.sides_width);
    if i64::from(xi) - i64::from(outer) < 0 || i64::from(xi) + i64::from(outer) >= i64::from(w) {
        return false;
    }
    let fits =
        |dd: f32| (xi - outer) as f32 - dd >= 0.0 && (xi + outer) as f32 - dd <= (w - 1) as f32;
    if !fits(d) {
        return false;
    }
    let geom = (inner, outer, hh);
    let (k0, k1) = (
        (range.0 as f32 - d).ceil() as i32,
        (range.1 as f32 - d).floor() as i32,
    );
    // Both half-windows' own fit first (cheap), then the other disparities.
    let mut here = [0.0f32; 2];
    for (h, side) in here.iter_mut().zip([-1i32, 1]) {
        *h = half_mad(
            left,
            right,
            xi,
            yl,
            yr,
            d,
            side,
            geom,
            f.sides_mean_free,
            &mut scratch.diffs,
        );
        if *h > f.sides_mad {
            return false;
        }
    }
    if f.sides_best {
        for (h, side) in here.into_iter().zip([-1i32, 1]) {
            if half_better(
                left,
                right,
                (xi, yl, yr, d),
                side,
                geom,
                f.sides_mean_free,
                (k0, k1),
                (h, f.sides_best_margin),
                scratch,
            ) {
                return false;
            }
        }
    }
    true
}

/// Half-size of the area check's ZNCC window (7x7, as the ZNCC reference's).
const AREA_RADIUS: i32 = 3;
/// The area check searches the integer disparities `round(d) +- AREA_REACH`.
const AREA_REACH: i32 = 2;
/// A window flatter than this grey-level std has no ZNCC (as the reference's).
const AREA_MIN_STD: f64 = 1e-3;

/// Mean-free 7x7 window of `img` centred at `(x, y)` and its sum of squares, or `None` where
/// it leaves the image or is flat (std <= [`AREA_MIN_STD`]).
fn area_window(img: &Image, x: i32, y: i32) -> Option<([f64; 49], f64)> {
    let (w, h) = img.size();
    let r = AREA_RADIUS;
    if x < r || y < r || x + r >= w as i32 || y + r >= h as i32 {
        return None;
    }
    let mut v = [0.0f64; 49];
    for (k, dy) in (-r..=r).enumerate() {
        let o = (y + dy) as usize * w + (x - r) as usize;
        let row = &img.data[o..o + 7];
        for (j, &p) in row.iter().enumerate() {
            v[k * 7 + j] = f64::from(p);
        }
    }
    let mean = v.iter().sum::<f64>() / 49.0;
    let mut ss = 0.0;
    for p in &mut v {
        *p -= mean;
        ss += *p * *p;
    }
    ((ss / 49.0).sqrt() > AREA_MIN_STD).then_some((v, ss))
}

/// The area check of one match (see [`FilterParams::zncc_check`]): ZNCC of the left window at
/// the rounded left pixel against the right windows at the five integer disparities around
/// the match's; the best must be an interior peak (ties: the first) whose parabola vertex lies
/// within `tol` px of the match's disparity.
fn area_ok(left: &Image, right: &Image, m: &Match, tol: f32) -> bool {
    const SIDE: usize = (2 * AREA_RADIUS + 1) as usize;
    const NK: usize = (2 * AREA_REACH + 1) as usize;
    const SPAN: usize = SIDE + NK - 1;
    let (x, y, yr) = (
        m.xl.round() as i32,
        m.yl.round() as i32,
        m.yr.round() as i32,
    );
    let d = m.xl - m.xr;
    let d0 = d.round() as i32;
    let Some((a, sa)) = area_window(left, x, y) else {
        return false;
    };
    let (w, h) = right.size();
    if yr < AREA_RADIUS || yr + AREA_RADIUS >= h as i32 {
        return false;
    }
    // The five right windows share one 7 x 11 block: its columns' sums and sums of squares
    // give each window's statistics, and since the left window is mean-free its dot product
    // with the raw right window is the covariance.
    let bx = x - d0 - AREA_REACH - AREA_RADIUS;
    let mut blk = [[0.0f64; SPAN]; SIDE];
    let mut col_ok = [false; SPAN];
    let (mut cs, mut cq) = ([0.0f64; SPAN], [0.0f64; SPAN]);
    for j in 0..SPAN {
        let c = bx + j as i32;
        if c < 0 || c >= w as i32 {
            continue;
        }
        col_ok[j] = true;
        for (r, row) in blk.iter_mut().enumerate() {
            let v = f64::from(right.data[(yr - AREA_RADIUS + r as i32) as usize * w + c as usize]);
            row[j] = v;
            cs[j] += v;
            cq[j] += v * v;
        }
    }
    let n = (SIDE * SIDE) as f64;
    let mut z = [f64::NEG_INFINITY; NK];
    for (k, zk) in z.iter_mut().enumerate() {
        // Window k (disparity d0 + k - AREA_REACH) starts AREA_REACH * 2 - k columns in.
        let off = NK - 1 - k;
        if !col_ok[off..off + SIDE].iter().all(|&ok| ok) {
            continue;
        }
        let sum: f64 = cs[off..off + SIDE].iter().sum();
        let sq: f64 = cq[off..off + SIDE].iter().sum();
        let ss = (sq - sum * sum / n).max(0.0);
        if (ss / n).sqrt() <= AREA_MIN_STD {
            continue;
        }
        let mut dot = 0.0;
        for (r, row) in blk.iter().enumerate() {
            for c in 0..SIDE {
                dot += a[r * SIDE + c] * row[off + c];
            }
        }
        *zk = dot / (sa * ss).sqrt();
    }
    let mut best = 0;
    for k in 1..NK {
        if z[k] > z[best] {
            best = k;
        }
    }
    if best == 0 || best == NK - 1 {
        return false;
    }
    let (c0, c1, c2) = (z[best - 1], z[best], z[best + 1]);
    let den = c0 - 2.0 * c1 + c2;
    if !(c0.is_finite() && c2.is_finite() && den < 0.0) {
        return false;
    }
    let off = (0.5 * (c0 - c2) / den).clamp(-0.5, 0.5);
    let dz = f64::from(d0) + (best as f64 - f64::from(AREA_REACH)) + off;
    (dz - f64::from(d)).abs() <= f64::from(tol)
}

/// Indices of `matches` by the row, then the column, of the rounded left pixel (ties in index
/// order; non-finite positions last). A failed allocation is [`CoreError::OutOfMemory`].
fn raster_order(matches: &[Match]) -> Result<Vec<u32>> {
    let key = |m: &Match| -> u64 {
        if !(m.xl.is_finite() && m.yl.is_finite()) {
            return u64::MAX;
        }
        // Rows and columns as offset 32-bit values: the order of (row, column) for any i32.
        let (x, y) = (m.xl.round() as i32, m.yl.round() as i32);
        ((y as u32 ^ 0x8000_0000) as u64) << 32 | (x as u32 ^ 0x8000_0000) as u64
    };
    let mut keyed = try_collect(
        matches.len(),
        matches.iter().enumerate().map(|(i, m)| (key(m), i as u32)),
        FILTER_LISTS,
    )?;
    keyed.sort_unstable();
    // A second list, allocated checked: a `collect` from `keyed.into_iter()` is not done in
    // place ((u64, u32) and u32 differ in alignment), it allocated unchecked (an abort).
    try_collect(keyed.len(), keyed.iter().map(|&(_, i)| i), FILTER_LISTS)
}

/// What [`edge_filters`]' per-match lists are called in an
/// [`OutOfMemory`](CoreError::OutOfMemory).
const FILTER_LISTS: &str = "the MCGM matcher's edge-filter lists";

/// Most matches [`edge_filters`] takes: it numbers them in u32.
pub const MAX_FILTER_MATCHES: usize = u32::MAX as usize;

/// Counts of [`edge_filters`]' survivors after each step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FilterCounts {
    /// After the both-sides check.
    pub sides: usize,
    /// After the discontinuity filter.
    pub disc: usize,
}

/// The occlusion-boundary filters on a match list (also applied to the ZNCC reference): B.8's
/// both-sides check, then B.8's discontinuity filter among its survivors (drop a match if
/// another one within `+- disc_dx` columns and `+- disc_dy` rows differs by more than
/// `disc_tol` px), then the area check ([`FilterParams::zncc_check`]). `range` is the
/// searched disparity range (`sides_best`). Returns the kept flags and the counts after the
/// first two filters.
///
/// More than [`MAX_FILTER_MATCHES`] matches is [`CoreError::InvalidParameter`] `matches`; a
/// failed allocation of a list that grows with the matches or the rows is
/// [`CoreError::OutOfMemory`] (they were `vec!`s and `collect`s: the process aborted).
pub fn edge_filters(
    left: &Image,
    right: &Image,
    matches: &[Match],
    f: &FilterParams,
    range: (i32, i32),
) -> Result<(Vec<bool>, FilterCounts)> {
    f.validate()?;
    check_pair(left, right)?;
    // Positions are compared with `w as i32`, rows and match numbers counted in u32: the
    // binding's mcgm_filter reaches this without mcgm_match's check.
    crate::image::check_index_range(left.width, left.height)?;
    if matches.len() > MAX_FILTER_MATCHES {
        return Err(CoreError::param(
            "matches",
            format!(
                "{} matches: at most {MAX_FILTER_MATCHES} (they are numbered in 32 bits)",
                matches.len()
            ),
        ));
    }
    let (w, h) = left.size();
    // Both per-match checks run in raster order of the left pixel: neighbouring checks read
    // the same image rows (in match order, the windows' rows were mostly cache misses).
    let order = raster_order(matches)?;
    let mut keep = try_zeroed::<bool>(matches.len(), FILTER_LISTS)?;
    let scale =
        left.data
            .iter()
            .chain(&right.data)
            .fold(0.0f32, |a, &v| if v.abs() > a { v.abs() } else { a });
    // The half-windows' column sums of both images, when the matches are many enough for
    // their windows to cover the image several times over (each half-window sums
    // `sides_height` rows over the disparity range; one per 64 pixels is far above break-even
    // on the scenes): the same values, so the same answers, either way.
    let hh = f.sides_height / 2;
    let sums = (f.sides
        && f.sides_best
        && 2 * i64::from(hh) < h as i64
        && matches.len().saturating_mul(64) >= w * h)
        .then(|| {
            let (l, r) = rayon::join(|| HalfSums::new(left, hh), || HalfSums::new(right, hh));
            Some(Arc::new([l?, r?]))
        })
        .flatten();
    let mut ok: Vec<bool> = Vec::new();
    try_reserve_len(&mut ok, order.len(), FILTER_LISTS)?;
    // Into the reserved room (no reallocation) by `par_extend`, the path `collect` took:
    // `collect_into_vec` compiled this hot loop into 4 % more instructions (callgrind).
    ok.par_extend(order.par_iter().map_init(
        || SidesScratch {
            scale,
            sums: sums.clone(),
            ..SidesScratch::default()
        },
        |scratch, &i| {
            let m = &matches[i as usize];
            m.xl.is_finite()
                && m.xr.is_finite()
                && m.yl.is_finite()
                && m.yr.is_finite()
                && (!f.sides || sides_ok(left, right, m, f, range, scratch))
        },
    ));
    for (&i, o) in order.iter().zip(ok) {
        keep[i as usize] = o;
    }
    let n_sides = keep.iter().filter(|&&k| k).count();
    if f.disc {
        // Survivors bucketed by the row of their rounded left pixel, by column within a row
        // (several per pixel possible): a neighbourhood is a few binary searches, not a scan
        // of its cells.
        let pos = |m: &Match| -> Option<(i32, i32)> {
            let (x, y) = (m.xl.round() as i32, m.yl.round() as i32);
            (x >= 0 && y >= 0 && x < w as i32 && y < h as i32).then_some((x, y))
        };
        let cell = try_collect(
            matches.len(),
            matches
                .iter()
                .zip(&keep)
                .map(|(m, &k)| if k { pos(m) } else { None }),
            FILTER_LISTS,
        )?;
        let mut start = try_zeroed::<u32>(h + 1, FILTER_LISTS)?;
        for &(_, y) in cell.iter().flatten() {
            start[y as usize + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = try_collect(start.len(), start.iter().copied(), FILTER_LISTS)?;
        // (column, match index) per row.
        let mut items = try_filled(start[h] as usize, (0i32, 0u32), FILTER_LISTS)?;
        for (i, c) in cell.iter().enumerate() {
            if let Some((x, y)) = *c {
                items[fill[y as usize] as usize] = (x, i as u32);
                fill[y as usize] += 1;
            }
        }
        for y in 0..h {
            items[start[y] as usize..start[y + 1] as usize].sort_unstable();
        }
        let mut drop: Vec<bool> = Vec::new();
        try_reserve_len(&mut drop, matches.len(), FILTER_LISTS)?;
        drop.par_extend(matches.par_iter().enumerate().map(|(i, m)| {
            if !keep[i] {
                return false;
            }
            let Some((x, y)) = cell[i] else {
                return true;
            };
            let d = m.xl - m.xr;
            // Saturating: `x + disc_dx` of a disc_dx near i32::MAX wrapped negative and the
            // neighbourhood was empty (every match kept), where it is the whole row.
            let (x0, x1) = (x.saturating_sub(f.disc_dx), x.saturating_add(f.disc_dx));
            let (y0, y1) = (y.saturating_sub(f.disc_dy), y.saturating_add(f.disc_dy));
            for yy in y0.max(0)..=y1.min(h as i32 - 1) {
                let row = &items[start[yy as usize] as usize..start[yy as usize + 1] as usize];
                let from = row.partition_point(|&(c, _)| c < x0);
                for &(c, j) in &row[from..] {
                    if c > x1 {
                        break;
                    }
                    let o = &matches[j as usize];
                    if j as usize != i && ((o.xl - o.xr) - d).abs() > f.disc_tol {
                        return true;
                    }
                }
            }
            false
        }));
        for (k, d) in keep.iter_mut().zip(drop) {
            *k &= !d;
        }
    }
    let n_disc = keep.iter().filter(|&&k| k).count();
    if f.zncc_check {
        let mut live = order; // in place: no allocation
        live.retain(|&i| keep[i as usize]);
        let mut ok: Vec<bool> = Vec::new();
        try_reserve_len(&mut ok, live.len(), FILTER_LISTS)?;
        ok.par_extend(
            live.par_iter()
                .map(|&i| area_ok(left, right, &matches[i as usize], f.zncc_tol)),
        );
        for (&i, o) in live.iter().zip(ok) {
            keep[i as usize] = o;
        }
    }
    Ok((
        keep,
        FilterCounts {
            sides: n_sides,
            disc: n_disc,
        },
    ))
}

/// Matches one channel (`ci`: its index in `sigmas`) given its curves in both images, with the
/// prior of the coarser channels (full-resolution disparities, NaN = none), which it extends.
fn match_channel(
    ci: usize,
    l: &ChannelCurves,
    r: &ChannelCurves,
    prior: &mut Option<Vec<f32>>,
    (fw, fh): (usize, usize),
    p: &McgmParams,
) -> Result<ChannelResult> {
    let s = l.scale as f32;
    // No disparity reaches past the image width: a huge max_disparity must not size the
    // GHT accumulators.
    let lo_c = (p.d_min.min(fw) as f32 / s).floor() as i32;
    let hi_c = (p.d_max.min(fw) as f32 / s).ceil() as i32;
    let radius = if ci > 0 {
        (p.prior_radius_sigmas * p.sigmas[ci - 1]).ceil() as i32
    } else {
        0
    };
    // The segment graph needs no prior: built beside the windows and candidates (whose
    // distance transform and row index are sequential).
    let prior_map = prior.as_deref();
    let (pairs, adj) = rayon::join(
        || -> Result<_> {
            let spread = prior_map
                .map(|m| SpreadPrior::new(m, fw, fh, radius))
                .transpose()?;
            let win = windows(
                l,
                spread.as_ref(),
                fw,
                p.prior_width_sigmas * l.sigma,
                lo_c,
                hi_c,
            )?;
            let cands = candidates(
                &l.curves.segments,
                &l.rtables,
                &r.curves.segments,
                &r.zc.theta,
                l.width,
                l.height,
                &win,
                &p.cand,
            )?;
            Ok((win, cands))
        },
        || knn_graph(&l.curves.segments, p.knn, p.r_graph / s),
    );
    let (win, cands) = pairs?;
    let adj = adj?;
    let csr = association_weights(
        &cands,
        &l.curves.segments,
        &adj,
        r.curves.segments.len(),
        &p.solver,
    )?;
    let sol = solve(&cands, &csr, l.curves.segments.len(), &p.solver)?;
    let matches = decompose(l, r, &cands, &sol.chosen, p.horiz_skip_deg, ci as u8)?;
    // Prior for the finer channels: this channel's disparities over the coarser ones'.
    if prior.is_none() {
        *prior = Some(crate::alloc::try_filled(
            fw * fh,
            f32::NAN,
            "the MCGM matcher's prior map",
        )?);
    }
    let map = prior.get_or_insert_with(Vec::new);
    for m in &matches {
        let (x, y) = (m.xl.round() as i64, m.yl.round() as i64);
        if x >= 0 && y >= 0 && (x as usize) < fw && (y as usize) < fh {
            map[y as usize * fw + x as usize] = m.xl - m.xr;
        }
    }
    // Each graph edge once (i < j), allocated at once, checked.
    let n_edges = adj
        .iter()
        .enumerate()
        .map(|(i, nb)| nb.iter().filter(|&&j| (j as usize) > i).count())
        .sum();
    let edges = crate::alloc::try_collect(
        n_edges,
        adj.iter().enumerate().flat_map(|(i, nb)| {
            nb.iter()
                .filter(move |&&j| (j as usize) > i)
                .map(move |&j| (i as u32, j))
        }),
        "the MCGM matcher's graph edges",
    )?;
    Ok(ChannelResult {
        sigma: l.sigma,
        scale: l.scale,
        n_left: l.curves.segments.len(),
        n_right: r.curves.segments.len(),
        windows: win,
        candidates: cands,
        state: sol.state,
        chosen: sol.chosen,
        edges,
        n_weights: sol.n_weights,
        sweeps: sol.sweeps,
        converged: sol.converged,
        matches,
    })
}

/// Drops exact repeats of a correspondence (the same `xl, yl, xr, yr` bits), keeping the first:
/// two curve pixels on one row can carry the same crossing (a vertical-only mark takes its
/// neighbour's horizontal crossing), and the pair would otherwise be reported, and counted,
/// twice. A failed allocation of its lists is [`CoreError::OutOfMemory`].
fn drop_repeats(ms: &mut Vec<Match>) -> Result<()> {
    let key = |m: &Match| {
        (
            m.yl.to_bits(),
            m.xl.to_bits(),
            m.xr.to_bits(),
            m.yr.to_bits(),
        )
    };
    const WHAT: &str = "the MCGM matcher's repeat check";
    let mut order = try_collect(ms.len(), 0..ms.len() as u32, WHAT)?;
    order.sort_unstable_by_key(|&i| (key(&ms[i as usize]), i));
    let mut keep = try_filled(ms.len(), true, WHAT)?;
    for pair in order.windows(2) {
        if key(&ms[pair[0] as usize]) == key(&ms[pair[1] as usize]) {
            keep[pair[1] as usize] = false;
        }
    }
    let mut k = keep.into_iter();
    ms.retain(|_| k.next().unwrap_or(true));
    Ok(())
}

/// The MCGM channel end to end (see the module docs).
pub fn mcgm_match(left: &Image, right: &Image, p: &McgmParams) -> Result<McgmOutput> {
    crate::parallel::run_hot(|| mcgm_match_hot(left, right, p))
}

/// The body of [`mcgm_match`], run inside the pool ([`crate::parallel::run_hot`]).
fn mcgm_match_hot(left: &Image, right: &Image, p: &McgmParams) -> Result<McgmOutput> {
    check_pair(left, right)?;
    // Segments and seeds index pixels in u32: refused before any plane is computed.
    crate::image::check_index_range(left.width, left.height)?;
    validate_params(p)?;
    let (fw, fh) = left.size();
    // Curves of every channel; the finest (the most pixels) computed beside the coarser
    // channels' curves and matching, whose sequential steps (distance transform, network,
    // assembly) would otherwise leave the other worker idle. Each channel's work and output is
    // the same as computed in order.
    let n = p.sigmas.len();
    // A failed allocation of any per-pixel plane is CoreError::OutOfMemory (the binding's
    // MemoryError), not an abort of the process.
    let half = match needs_half(p)
        .then(|| rayon::join(|| log::decimate2(left), || log::decimate2(right)))
    {
        Some((l, r)) => Some((l?, r?)),
        None => None,
    };
    let (half_l, half_r) = (half.as_ref().map(|h| &h.0), half.as_ref().map(|h| &h.1));
    let curves_of = |ci: usize| -> Result<(ChannelCurves, ChannelCurves)> {
        let s = p.sigmas[ci];
        let (l, r) = rayon::join(
            || curves_at(left, half_l, s, p),
            || curves_at(right, half_r, s, p),
        );
        Ok((l?, r?))
    };
    let (finest, coarse) = rayon::join(
        || curves_of(n - 1),
        || -> Result<(Vec<ChannelResult>, Option<Vec<f32>>)> {
            let coarse: Vec<_> = (0..n - 1)
                .into_par_iter()
                .map(curves_of)
                .collect::<Result<_>>()?;
            let mut prior: Option<Vec<f32>> = None;
            let channels: Vec<ChannelResult> = coarse
                .iter()
                .enumerate()
                .map(|(ci, (l, r))| match_channel(ci, l, r, &mut prior, (fw, fh), p))
                .collect::<Result<_>>()?;
            Ok((channels, prior))
        },
    );
    let (finest, (mut channels, mut prior)) = (finest?, coarse?);
    channels.push(match_channel(
        n - 1,
        &finest.0,
        &finest.1,
        &mut prior,
        (fw, fh),
        p,
    )?);
    // Combination: finest full-resolution channel first; coarser ones fill empty places.
    let mut taken = crate::alloc::try_filled(fw * fh, false, "the MCGM matcher's taken mask")?;
    // Every channel's matches at most, reserved checked (the pushes below never reallocate).
    let mut combined: Vec<Match> = Vec::new();
    crate::alloc::try_reserve_len(
        &mut combined,
        channels
            .iter()
            .filter(|c| c.scale == 1)
            .map(|c| c.matches.len())
            .sum(),
        "the MCGM matcher's combined matches",
    )?;
    for ch in channels.iter().rev().filter(|c| c.scale == 1) {
        // The places this channel takes, marked after its pass (its own matches do not block
        // each other).
        let mut mine: Vec<(usize, usize)> = Vec::new();
        crate::alloc::try_reserve_len(
            &mut mine,
            ch.matches.len(),
            "the MCGM matcher's channel places",
        )?;
        for m in &ch.matches {
            let (x, y) = (m.xl.round() as i32, m.yl.round() as i32);
            if x < 0 || y < 0 || x >= fw as i32 || y >= fh as i32 {
                continue;
            }
            let row = y as usize * fw;
            let x0 = (x - p.fill_radius).max(0) as usize;
            let x1 = (x + p.fill_radius).min(fw as i32 - 1) as usize;
            if (x0..=x1).any(|xx| taken[row + xx]) {
                continue;
            }
            combined.push(*m);
            mine.push((row, x as usize));
        }
        for (row, x) in mine {
            taken[row + x] = true;
        }
    }
    drop_repeats(&mut combined)?;
    let (keep, counts) = edge_filters(
        left,
        right,
        &combined,
        &p.filters,
        (p.d_min.min(fw) as i32, p.d_max.min(fw) as i32),
    )?;
    let n_combined = combined.len();
    let matches = crate::alloc::try_collect(
        keep.iter().filter(|&&k| k).count(),
        combined
            .into_iter()
            .zip(keep)
            .filter_map(|(m, k)| k.then_some(m)),
        "the MCGM matcher's matches",
    )?;
    Ok(McgmOutput {
        matches,
        channels,
        n_combined,
        n_sides: counts.sides,
        n_disc: counts.disc,
    })
}
