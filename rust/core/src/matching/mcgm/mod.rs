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

use rayon::prelude::*;

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
    /// Largest mean absolute grey difference of each half-window (grey in [0, 1]; B.8: 0.04).
    pub sides_mad: f32,
    /// Half-window width (columns) and height (rows) (B.8: 4 x 7).
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
}

impl Default for FilterParams {
    fn default() -> Self {
        FilterParams {
            sides: true,
            sides_mad: 0.04,
            sides_width: 4,
            sides_height: 7,
            sides_gap: 1,
            sides_best: true,
            sides_best_margin: 0.0,
            sides_mean_free: true,
            disc: true,
            disc_dx: 6,
            disc_dy: 2,
            disc_tol: 1.0,
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
                vote_bin_tol: 1,
                ght_min_score: 0.5,
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
}

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
    if p.cand.n_bins < 3 || 2 * p.cand.vote_bin_tol + 1 > p.cand.n_bins {
        return Err(CoreError::param(
            "n_theta_bins",
            "needs >= 3 bins and 2 * vote_bin_tol + 1 <= n_theta_bins",
        ));
    }
    if p.cand.k_cand == 0 {
        return Err(CoreError::param("k_cand", "must be >= 1"));
    }
    if p.cand.dy_band < 0 {
        return Err(CoreError::param("dy_band", "must be >= 0"));
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
    ] {
        if !v.is_finite() || v < 0.0 {
            return Err(CoreError::param(
                name,
                format!("must be finite and >= 0, got {v}"),
            ));
        }
    }
    let f = &p.filters;
    if f.sides_width < 1
        || f.sides_width as usize > MAX_SIDES_WIDTH
        || f.sides_height < 1
        || f.sides_gap < 0
        || f.disc_dx < 0
        || f.disc_dy < 0
    {
        return Err(CoreError::param(
            "filters",
            "sides_width in 1..=16, sides_height >= 1; sides_gap, disc_dx, disc_dy >= 0",
        ));
    }
    if p.fill_radius < 0 {
        return Err(CoreError::param("fill_radius", "must be >= 0"));
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

/// LoG, zero crossings, curves and R-tables of `img` (already at the channel's resolution).
pub fn channel_curves(img: &Image, sigma: f32, scale: usize, p: &McgmParams) -> ChannelCurves {
    let (w, h) = img.size();
    let log = log::log_filter(img, sigma);
    let zc = zero_crossings(&log, w, h);
    let tp = TrackParams {
        min_len: p
            .track
            .min_len
            .max((p.min_len_sigmas * sigma).ceil() as usize),
        ..p.track
    };
    let curves = track(&zc, &tp);
    let rtables = curves
        .segments
        .iter()
        .map(|s| build_rtable(s, &zc.theta, w, p.cand.n_bins))
        .collect();
    ChannelCurves {
        sigma,
        scale,
        width: w,
        height: h,
        log,
        zc,
        curves,
        rtables,
    }
}

/// Curves of every channel of one image (the debugging / GUI view of `curves(image)`).
pub fn image_curves(img: &Image, p: &McgmParams) -> Result<Vec<ChannelCurves>> {
    validate_params(p)?;
    let half = p
        .sigmas
        .iter()
        .any(|&s| s >= p.half_res_sigma)
        .then(|| log::decimate2(img));
    Ok(p.sigmas
        .par_iter()
        .map(|&s| {
            let (sig, scale) = channel_geometry(s, p);
            let src = if scale == 2 {
                half.as_ref().unwrap_or(img)
            } else {
                img
            };
            channel_curves(src, sig, scale, p)
        })
        .collect())
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
    w: usize,
    h: usize,
    far: u16,
}

impl<'a> SpreadPrior<'a> {
    /// The distance transform of `map` (`w x h`, NaN = no value), capped at `radius + 1`
    /// (`radius <= 0`: no spread).
    pub fn new(map: &'a [f32], w: usize, h: usize, radius: i32) -> Self {
        let far = radius.clamp(0, u16::MAX as i32 - 1) as u16 + 1;
        let mut dist: Vec<u16> = map
            .iter()
            .map(|v| if v.is_finite() { 0 } else { far })
            .collect();
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
                    for x in 0..w {
                        let mut m = p[x];
                        if x > 0 {
                            m = m.min(p[x - 1]);
                        }
                        if x + 1 < w {
                            m = m.min(p[x + 1]);
                        }
                        row[x] = row[x].min(m + 1);
                    }
                }
                if pass == 0 {
                    for x in 1..w {
                        row[x] = row[x].min(row[x - 1] + 1);
                    }
                } else {
                    for x in (0..w.saturating_sub(1)).rev() {
                        row[x] = row[x].min(row[x + 1] + 1);
                    }
                }
                for v in row.iter_mut() {
                    *v = (*v).min(far);
                }
            }
        }
        SpreadPrior {
            map,
            dist,
            w,
            h,
            far,
        }
    }

    /// The spread value at `(x, y)` (beyond the radius: the map's own value, NaN or infinite).
    pub fn at(&self, x: usize, y: usize) -> f32 {
        let (w, h) = (self.w as i32, self.h as i32);
        let i = y * self.w + x;
        let mut d = self.dist[i];
        if d >= self.far {
            return self.map[i];
        }
        let (mut x, mut y) = (x as i32, y as i32);
        while d > 0 {
            // A pixel at distance d >= 1 has a neighbour at d - 1 (exact transform).
            let (nx, ny) = SPREAD_ORDER
                .iter()
                .map(|&(dx, dy)| (x + dx, y + dy))
                .find(|&(nx, ny)| {
                    nx >= 0
                        && ny >= 0
                        && nx < w
                        && ny < h
                        && self.dist[ny as usize * self.w + nx as usize] == d - 1
                })
                .expect("an exact chessboard distance has a neighbour one step closer");
            (x, y, d) = (nx, ny, d - 1);
        }
        self.map[y as usize * self.w + x as usize]
    }
}

/// The whole spread map of [`SpreadPrior`] (`radius <= 0`: `map` itself).
pub fn spread_prior(map: &[f32], w: usize, h: usize, radius: i32) -> Vec<f32> {
    let sp = SpreadPrior::new(map, w, h, radius);
    (0..w * h).map(|i| sp.at(i % w, i / w)).collect()
}

/// Median (lower of the two middle values for even counts: a value that exists).
fn median_lower(v: &mut [f32]) -> Option<f32> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f32::total_cmp);
    Some(v[(v.len() - 1) / 2])
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
) -> Vec<Option<(i32, i32)>> {
    let full = Some((lo_c, hi_c)).filter(|w| w.0 <= w.1);
    let Some(prior) = prior else {
        return vec![full; cc.curves.segments.len()];
    };
    let s = cc.scale as f32;
    let w = cc.width;
    let fh = prior.h;
    cc.curves
        .segments
        .par_iter()
        .map(|seg| {
            let mut vals: Vec<f32> = Vec::with_capacity(seg.pixels.len());
            for &i in &seg.pixels {
                let (x, y) = ((i as usize % w) as f32, (i as usize / w) as f32);
                // Channel pixel centre in full-resolution coordinates.
                let fx = ((s * x + 0.5 * (s - 1.0)).round() as usize).min(fw - 1);
                let fy = ((s * y + 0.5 * (s - 1.0)).round() as usize).min(fh - 1);
                let v = prior.at(fx, fy);
                if v.is_finite() {
                    vals.push(v / s);
                }
            }
            match median_lower(&mut vals) {
                None => full,
                Some(d) => {
                    let lo = ((d - width).floor() as i32).max(lo_c);
                    let hi = ((d + width).ceil() as i32).min(hi_c);
                    (lo <= hi).then_some((lo, hi))
                }
            }
        })
        .collect()
}

/// Per-pixel correspondences along the chosen pairs (B.4.12), in full-resolution coordinates.
fn decompose(
    l: &ChannelCurves,
    r: &ChannelCurves,
    cands: &[Candidate],
    chosen: &[usize],
    horiz_skip_deg: f32,
    channel: u8,
) -> Vec<Match> {
    let (w, h) = (l.width, l.height);
    let min_cos = (horiz_skip_deg as f64).to_radians().sin();
    let half = 0.5 * CHANNEL_WIDTH_SIGMAS * l.sigma;
    let s = l.scale as f32;
    let to_full = |v: f32| s * v + 0.5 * (s - 1.0);
    let per: Vec<Vec<Match>> = chosen
        .par_iter()
        .map(|&ci| {
            let c = &cands[ci];
            let seg = &l.curves.segments[c.left as usize];
            let mut out = Vec::new();
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
            out
        })
        .collect();
    per.into_iter().flatten().collect()
}

/// Linear interpolation of row `y` of `img` at column `x` (caller keeps `0 <= x <= w - 1`).
#[inline]
fn sample(img: &Image, x: f32, y: usize) -> f32 {
    let x0 = (x.floor() as usize).min(img.width - 1);
    let x1 = (x0 + 1).min(img.width - 1);
    let f = x - x0 as f32;
    let row = &img.data[y * img.width..(y + 1) * img.width];
    row[x0] + f * (row[x1] - row[x0])
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
) -> f32 {
    let n = ((outer - inner + 1) * (2 * hh + 1)) as f32;
    let mut offset = 0.0f32;
    if mean_free {
        for dy in -hh..=hh {
            let (ly, ry) = ((yl + dy) as usize, (yr + dy) as usize);
            for k in inner..=outer {
                let x = xi + side * k;
                offset += left.at(x as usize, ly) - sample(right, x as f32 - d, ry);
            }
        }
        offset /= n;
    }
    let mut sad = 0.0f32;
    for dy in -hh..=hh {
        let (ly, ry) = ((yl + dy) as usize, (yr + dy) as usize);
        for k in inner..=outer {
            let x = xi + side * k;
            sad += (left.at(x as usize, ly) - sample(right, x as f32 - d, ry) - offset).abs();
        }
    }
    sad / n
}

simd_fn! {
/// Mean absolute differences of one half-window (as [`half_mad`]) at the disparities `d + k`,
/// `k` integer in `ks` and such that every right sample lies inside the row, into `scratch.sad`
/// (the sums; `sad[j] / n` is the value at `k = k_hi - j`). Returns `(k_lo, k_hi, n)`, or `None`
/// when no `k` is left. Integer steps keep the interpolation weights of `d` (right samples
/// `r[b - k] + f (r[b - k + 1] - r[b - k])` with `b = floor(x - d)`, `f = x - d - b`), so every
/// `k` is compared fairly with `k = 0`, whose value is exactly [`half_mad`]'s (the same terms
/// summed in the same order). The right samples of one window pixel are contiguous in `j`:
/// blocks of 32 `j` keep their sums in registers over the window's pixels (raster order), and
/// the mean-free pass recomputes each difference instead of storing it.
fn half_sads(
    left: &Image,
    right: &Image,
    xi: i32,
    yl: i32,
    yr: i32,
    d: f32,
    side: i32,
    geom: (i32, i32, i32),
    mean_free: bool,
    ks: (i32, i32),
    scratch: &mut SidesScratch,
) -> Option<(i32, i32, f32)> {
    // One feature dispatch per half-window (this whole body is compiled for AVX2 as well): the
    // block kernels below are inlined into it.
    let (inner, outer, hh) = geom;
    let w = right.width as i32;
    // Window columns and their interpolation bases.
    let mut base = [(0i32, 0.0f32); MAX_SIDES_WIDTH];
    let (mut b_min, mut b_max) = (i32::MAX, i32::MIN);
    for (c, k) in (inner..=outer).enumerate() {
        let pos = (xi + side * k) as f32 - d;
        let b = pos.floor();
        base[c] = (b as i32, pos - b);
        b_min = b_min.min(b as i32);
        b_max = b_max.max(b as i32);
    }
    // Every sample r[b - k], r[b - k + 1] must lie inside the row.
    let k_hi = ks.1.min(b_min);
    let k_lo = ks.0.max(b_max + 2 - w);
    if k_hi < k_lo {
        return None;
    }
    // j = k_hi - k.
    let nk = (k_hi - k_lo + 1) as usize;
    let SidesScratch { els, sad } = scratch;
    // The window's pixels in raster order: (offset of r[b - k_hi] in the right image, left
    // value, interpolation weight).
    els.clear();
    for dy in -hh..=hh {
        let lrow = &left.data[(yl + dy) as usize * left.width..][..left.width];
        let rrow = (yr + dy) as usize * right.width;
        for (c, k) in (inner..=outer).enumerate() {
            let (b, fr) = base[c];
            els.push((rrow + (b - k_hi) as usize, lrow[(xi + side * k) as usize], fr));
        }
    }
    let n = els.len() as f32;
    sad.clear();
    sad.resize(nk, 0.0);
    let r = &right.data[..];
    let mut j = 0;
    while j + 32 <= nk {
        sads_block::<32>(r, els, j, n, mean_free, &mut sad[j..j + 32]);
        j += 32;
    }
    while j + 8 <= nk {
        sads_block::<8>(r, els, j, n, mean_free, &mut sad[j..j + 8]);
        j += 8;
    }
    while j < nk {
        sads_block::<1>(r, els, j, n, mean_free, &mut sad[j..j + 1]);
        j += 1;
    }
    Some((k_lo, k_hi, n))
}
}

/// The sums of [`half_sads`] for `J` consecutive `j` from `j0`: per `j`, the mean difference
/// (with `mean_free`; 0 otherwise) summed over the window's pixels in order and divided by
/// `n`, then the absolute deviations from it summed in the same order.
#[inline(always)]
fn sads_block<const J: usize>(
    r: &[f32],
    els: &[(usize, f32, f32)],
    j0: usize,
    n: f32,
    mean_free: bool,
    out: &mut [f32],
) {
    // `lv - (r[o] + fr (r[o + 1] - r[o]))`: left value minus the interpolated right one.
    #[inline(always)]
    fn diffs<const J: usize>(r: &[f32], &(o, lv, fr): &(usize, f32, f32), j0: usize) -> [f32; J] {
        let (a, b) = (&r[o + j0..o + j0 + J], &r[o + j0 + 1..o + j0 + J + 1]);
        std::array::from_fn(|t| lv - (a[t] + fr * (b[t] - a[t])))
    }
    let mut off = [0.0f32; J];
    if mean_free {
        for e in els {
            let v = diffs::<J>(r, e, j0);
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
        let v = diffs::<J>(r, e, j0);
        for t in 0..J {
            acc[t] += (v[t] - off[t]).abs();
        }
    }
    out.copy_from_slice(&acc);
}

/// Per-thread buffers of [`half_sads`] (no allocation per match).
#[derive(Default)]
struct SidesScratch {
    els: Vec<(usize, f32, f32)>,
    sad: Vec<f32>,
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
    let inner = f.sides_gap + 1;
    let outer = f.sides_gap + f.sides_width;
    if xi - outer < 0 || xi + outer >= w {
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
    for side in [-1i32, 1] {
        // With the other-disparity test, one pass gives the other disparities (k in k0..=k1)
        // and `here` (k = 0; added to the span when the range does not hold it).
        let sads = if f.sides_best {
            let span = (k0.min(0), k1.max(0));
            half_sads(
                left,
                right,
                xi,
                yl,
                yr,
                d,
                side,
                geom,
                f.sides_mean_free,
                span,
                scratch,
            )
        } else {
            None
        };
        // Without the test, or with k = 0 cut off at the row's end: half_mad (clamped samples).
        let here = match sads {
            Some((lo, hi, n)) if lo <= 0 && 0 <= hi => scratch.sad[hi as usize] / n,
            _ => half_mad(left, right, xi, yl, yr, d, side, geom, f.sides_mean_free),
        };
        if here > f.sides_mad {
            return false;
        }
        // Another disparity of the range, more than 1 px away, fits better.
        if let Some((lo, hi, n)) = sads {
            let better = (lo.max(k0)..=hi.min(k1)).any(|k| {
                k.abs() > 1 && scratch.sad[(hi - k) as usize] / n + f.sides_best_margin < here
            });
            if better {
                return false;
            }
        }
    }
    true
}

/// B.8's two occlusion-boundary filters on a match list (also applied to the ZNCC reference):
/// the both-sides check, then the discontinuity filter among its survivors (drop a match if
/// another one within `+- disc_dx` columns and `+- disc_dy` rows differs by more than
/// `disc_tol` px). `range` is the searched disparity range (`sides_best`). Returns the kept
/// flags and the count after the first filter.
pub fn edge_filters(
    left: &Image,
    right: &Image,
    matches: &[Match],
    f: &FilterParams,
    range: (i32, i32),
) -> Result<(Vec<bool>, usize)> {
    check_pair(left, right)?;
    let (w, h) = left.size();
    let mut keep: Vec<bool> = matches
        .par_iter()
        .map_init(SidesScratch::default, |scratch, m| {
            m.xl.is_finite()
                && m.xr.is_finite()
                && m.yl.is_finite()
                && m.yr.is_finite()
                && (!f.sides || sides_ok(left, right, m, f, range, scratch))
        })
        .collect();
    let n_sides = keep.iter().filter(|&&k| k).count();
    if f.disc {
        // Survivors bucketed by rounded left pixel (counting sort: several per pixel possible).
        let pos = |m: &Match| -> Option<(i32, i32)> {
            let (x, y) = (m.xl.round() as i32, m.yl.round() as i32);
            (x >= 0 && y >= 0 && x < w as i32 && y < h as i32).then_some((x, y))
        };
        let cell: Vec<Option<usize>> = matches
            .iter()
            .zip(&keep)
            .map(|(m, &k)| if k { pos(m) } else { None })
            .map(|o| o.map(|(x, y)| y as usize * w + x as usize))
            .collect();
        let mut start = vec![0u32; w * h + 1];
        for c in cell.iter().flatten() {
            start[c + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; start[w * h] as usize];
        for (i, c) in cell.iter().enumerate() {
            if let Some(c) = *c {
                items[fill[c] as usize] = i as u32;
                fill[c] += 1;
            }
        }
        let bucket = |c: usize| &items[start[c] as usize..start[c + 1] as usize];
        let drop: Vec<bool> = matches
            .par_iter()
            .enumerate()
            .map(|(i, m)| {
                if !keep[i] {
                    return false;
                }
                let Some((x, y)) = pos(m) else {
                    return true;
                };
                let d = m.xl - m.xr;
                for yy in (y - f.disc_dy).max(0)..=(y + f.disc_dy).min(h as i32 - 1) {
                    for xx in (x - f.disc_dx).max(0)..=(x + f.disc_dx).min(w as i32 - 1) {
                        for &j in bucket(yy as usize * w + xx as usize) {
                            let o = &matches[j as usize];
                            if j as usize != i && ((o.xl - o.xr) - d).abs() > f.disc_tol {
                                return true;
                            }
                        }
                    }
                }
                false
            })
            .collect();
        for (k, d) in keep.iter_mut().zip(drop) {
            *k &= !d;
        }
    }
    Ok((keep, n_sides))
}

/// The MCGM channel end to end (see the module docs).
pub fn mcgm_match(left: &Image, right: &Image, p: &McgmParams) -> Result<McgmOutput> {
    crate::parallel::run_hot(|| mcgm_match_hot(left, right, p))
}

/// The body of [`mcgm_match`], run inside the pool ([`crate::parallel::run_hot`]).
fn mcgm_match_hot(left: &Image, right: &Image, p: &McgmParams) -> Result<McgmOutput> {
    check_pair(left, right)?;
    validate_params(p)?;
    let (fw, fh) = left.size();
    let (cl, cr) = rayon::join(|| image_curves(left, p), || image_curves(right, p));
    let (cl, cr) = (cl?, cr?);
    let mut prior: Option<Vec<f32>> = None;
    let mut channels: Vec<ChannelResult> = Vec::with_capacity(p.sigmas.len());
    for (ci, (l, r)) in cl.iter().zip(&cr).enumerate() {
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
        let spread = prior
            .as_deref()
            .map(|m| SpreadPrior::new(m, fw, fh, radius));
        let win = windows(
            l,
            spread.as_ref(),
            fw,
            p.prior_width_sigmas * l.sigma,
            lo_c,
            hi_c,
        );
        let cands = candidates(
            &l.curves.segments,
            &l.rtables,
            &r.curves.segments,
            &r.zc.theta,
            l.width,
            l.height,
            &win,
            &p.cand,
        );
        let adj = knn_graph(&l.curves.segments, p.knn, p.r_graph / s);
        let csr = association_weights(
            &cands,
            &l.curves.segments,
            &adj,
            r.curves.segments.len(),
            &p.solver,
        );
        let sol = solve(&cands, &csr, l.curves.segments.len(), &p.solver);
        let matches = decompose(l, r, &cands, &sol.chosen, p.horiz_skip_deg, ci as u8);
        // Prior for the finer channels: this channel's disparities over the coarser ones'.
        let map = prior.get_or_insert_with(|| vec![f32::NAN; fw * fh]);
        for m in &matches {
            let (x, y) = (m.xl.round() as i64, m.yl.round() as i64);
            if x >= 0 && y >= 0 && (x as usize) < fw && (y as usize) < fh {
                map[y as usize * fw + x as usize] = m.xl - m.xr;
            }
        }
        let edges = adj
            .iter()
            .enumerate()
            .flat_map(|(i, nb)| {
                nb.iter()
                    .filter(move |&&j| (j as usize) > i)
                    .map(move |&j| (i as u32, j))
            })
            .collect();
        channels.push(ChannelResult {
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
        });
    }
    // Combination: finest full-resolution channel first; coarser ones fill empty places.
    let mut taken = vec![false; fw * fh];
    let mut combined: Vec<Match> = Vec::new();
    for ch in channels.iter().rev().filter(|c| c.scale == 1) {
        let mut mine: Vec<(usize, usize)> = Vec::new();
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
    let (keep, n_sides) = edge_filters(
        left,
        right,
        &combined,
        &p.filters,
        (p.d_min.min(fw) as i32, p.d_max.min(fw) as i32),
    )?;
    let n_combined = combined.len();
    let matches = combined
        .into_iter()
        .zip(keep)
        .filter_map(|(m, k)| k.then_some(m))
        .collect();
    Ok(McgmOutput {
        matches,
        channels,
        n_combined,
        n_sides,
    })
}
