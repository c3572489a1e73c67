//! Gabor-wavelet phase disparity (algorithms.md A.5 with the A.9 fixes).
//!
//! Pipeline per direction (left reference; the right reference is the same code on the mirrored,
//! swapped pair):
//! 1. Gaussian pyramids; every level filtered ONCE per image with a quadrature bank (`filter`).
//! 2. Top level: position-shift search of the normalised binocular energy over the scaled range.
//! 3. Every finer level: up-sample, +-`research_radius` px position-shift re-search, then
//!    `iters_per_level` Newton steps (phase difference / local frequency, WLS over orientations,
//!    normalised-convolution smoothing, separable 5x5 median).
//! 4. Confidence = max over levels of the smoothed confidence; left-right check; speckle removal.
//!
//! Right responses are never recomputed for a warp: the smooth baseband is shifted (`level`).
//!
//! Profiling aid: with the environment variable `SV_GABOR_TIMING` set, per-level stage times
//! (per direction) and the wall-clock time at the end of each post-processing stage are printed
//! to stderr.

mod fastmath;
pub mod filter;
mod gather;
pub mod level;
pub mod pool;
pub mod post;
pub mod search;

use crate::error::{CoreError, Result};
use crate::image::{check_pair, Image, ImageView};
use filter::Channel;
use level::{chan_consts, level_data, newton_step};
use pool::Buf;
use search::search;
use std::borrow::Cow;

/// Parameters of the Gabor channel (defaults: algorithms.md A.3 with the A.9 fixes).
#[derive(Debug, Clone, PartialEq)]
pub struct GaborParams {
    /// Smallest disparity searched (px).
    pub d_min: f32,
    /// Largest disparity searched (px).
    pub d_max: f32,
    /// Carrier frequency at every pyramid level (cycles/px).
    pub freq: f32,
    /// Orientations of the frequency vector from the x-axis (degrees, each in (-90, 90), <= 8).
    pub orientations_deg: Vec<f32>,
    /// Radial bandwidth (octaves); sets the envelope sigma.
    pub bandwidth_oct: f32,
    /// Envelope aspect ratio `sigma_x / sigma_y` (the paper's lambda).
    pub aspect: f32,
    /// Pyramid depth; `None` = automatic (A.3 rule).
    pub n_levels: Option<usize>,
    /// Newton iterations per level.
    pub iters_per_level: usize,
    /// Amplitude threshold relative to the 95th percentile of the channel's amplitude.
    pub amp_rel_thresh: f32,
    /// Fleet-Jepson stability threshold (in units of 1/sigma_x).
    pub stability_tau: f32,
    /// Std (px) of the normalised-convolution smoothing; `None` = the filter's envelope sigma.
    pub smooth_sigma: Option<f32>,
    /// Minimum smoothed confidence to update / report a pixel.
    pub conf_min: f32,
    /// Position-shift re-search radius at each level below the top (px at that level).
    pub research_radius: usize,
    /// Half-size of the box over which the search energy is pooled (px at that level).
    pub search_pool_radius: usize,
    /// Left-right consistency check.
    pub lr_check: bool,
    /// Left-right tolerance (px).
    pub lr_tol: f32,
    /// The right-reference run of the left-right check stops this many levels above full
    /// resolution (its map is up-sampled); 0 = full resolution.
    pub lr_coarse_levels: usize,
    /// Newton iterations at full resolution (the finest level dominates the run time).
    pub iters_finest: usize,
    /// Position-shift re-search at full resolution too.
    pub research_finest: bool,
    /// Number of orientations (the first ones of `orientations_deg`) used at the finest
    /// `fine_levels` levels.
    pub orientations_finest: usize,
    /// How many of the finest levels use `orientations_finest` orientations.
    pub fine_levels: usize,
    /// The right-reference run of the LR check uses a light full-resolution level (at most
    /// [`LIGHT_ORIENTATIONS`] orientations, one Newton step, no re-search): it only has to agree
    /// within `lr_tol`, and it costs as much as the main run otherwise.
    pub lr_light: bool,
    /// Speckle removal: regions smaller than this many pixels are dropped (0 = off).
    pub speckle_size: usize,
    /// Speckle removal: neighbouring pixels within this many px belong to one region.
    pub speckle_range: f32,
}

/// Default orientations: 0 and +-60 degrees. A.9 found five (0, +-30, +-60) better than three
/// with the old pooled +-2 px re-search; with the unpooled +-3 px re-search (and the other
/// defaults), (0, +-60) measured 14.2 % mean filled bad-2 on the 17 shared scenes against 14.3 %
/// for five orientations, at 3/5 of the filtering and Newton work of the coarse levels.
pub const DEFAULT_ORIENTATIONS: [f32; 3] = [0.0, 60.0, -60.0];

impl Default for GaborParams {
    fn default() -> Self {
        GaborParams {
            d_min: 0.0,
            d_max: 64.0,
            freq: 0.25,
            orientations_deg: DEFAULT_ORIENTATIONS.to_vec(),
            // 1.5 octaves (sigma = 1.57 px at F = 1/4) instead of A.3's 1.0: a smaller envelope
            // blurs depth edges and slanted surfaces less (mean bad-2 -1.1 points, 11 taps not 15).
            bandwidth_oct: 1.5,
            aspect: 1.0,
            n_levels: None,
            // One Newton step per level: a second one changes the mean filled bad-2 by <= 0.1 point.
            iters_per_level: 1,
            // A.9: 0.1 passes only 26-57 % of correctly matched pixels.
            amp_rel_thresh: 0.02,
            stability_tau: 1.25,
            smooth_sigma: None,
            conf_min: 0.15,
            // +-3 px, unpooled (A.9 pooled 5x5 over +-2 px): the per-pixel normalised energy keeps
            // depth edges a pool blurs. With the former defaults otherwise, mean filled bad-2
            // 15.9 % (pooled +-2) -> 14.6 % (unpooled +-2) -> 13.4 % (unpooled +-3); and no
            // pooling pass.
            research_radius: 3,
            search_pool_radius: 0,
            lr_check: true,
            // The right-reference run stops at half resolution (its map is up-sampled, so it
            // carries up to 0.5 px more error; hence 1.5 px, not A.3's 1.0): 28 % less work
            // for +0.5 point of mean filled bad-2 and +3 points of density (1.0 px: -5 points).
            lr_tol: 1.5,
            lr_coarse_levels: 1,
            // A second full-resolution step changed no figure of the evaluation (17 scenes).
            iters_finest: 1,
            research_finest: true,
            // Full resolution with the 0 degree channel only (one real-tap filter per image, a
            // third of the level's work): +0.4 point of mean filled bad-2, -4 points of density.
            // The oblique channels matter at the coarse levels, where they help lock onto the
            // right disparity.
            orientations_finest: 1,
            fine_levels: 1,
            // The full right-reference run kept 6 points more density than the light one (which
            // only changes the full-resolution level, so it does nothing with lr_coarse_levels > 0).
            lr_light: false,
            // Same rule as the SGBM reference (100 px, 1 px step): -1.2 points of mean bad-2.
            speckle_size: 100,
            speckle_range: 1.0,
        }
    }
}

/// Orientations of the light full-resolution level (0 and +-30 degrees: the channels with the
/// highest horizontal frequency, which carry most of the horizontal disparity information).
pub const LIGHT_ORIENTATIONS: usize = 3;

/// Widest disparity range accepted (px).
pub const MAX_RANGE: f32 = 8192.0;
/// Maximum pyramid depth accepted.
const MAX_LEVELS: usize = 10;
/// The automatic pyramid stops before the top level gets narrower than this (px).
const MIN_TOP_WIDTH: usize = 32;
/// ... or lower than this (px).
const MIN_TOP_HEIGHT: usize = 16;

impl GaborParams {
    /// Checks every parameter; errors are [`CoreError::InvalidParameter`].
    pub fn validate(&self) -> Result<()> {
        let fin = |name: &'static str, v: f32| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(CoreError::param(name, format!("must be finite, got {v}")))
            }
        };
        fin("d_min", self.d_min)?;
        fin("d_max", self.d_max)?;
        if self.d_max <= self.d_min {
            return Err(CoreError::param(
                "d_max",
                format!("must be > d_min ({}), got {}", self.d_min, self.d_max),
            ));
        }
        // The coarsest level searches every whole disparity of the range: a range wider than any
        // image would only allocate (1e12 px asked for terabytes and aborted the process).
        if self.d_max - self.d_min > MAX_RANGE {
            return Err(CoreError::param(
                "d_max",
                format!(
                    "the range d_max - d_min is at most {MAX_RANGE} px, got {}",
                    self.d_max - self.d_min
                ),
            ));
        }
        if self.orientations_deg.is_empty() || self.orientations_deg.len() > 8 {
            return Err(CoreError::param(
                "orientations_deg",
                format!(
                    "needs 1 to 8 orientations, got {}",
                    self.orientations_deg.len()
                ),
            ));
        }
        // Channel::new validates freq, bandwidth, aspect and each orientation.
        if let Some(n) = self.n_levels {
            if n == 0 || n > MAX_LEVELS {
                return Err(CoreError::param(
                    "n_levels",
                    format!("must be in 1..={MAX_LEVELS}, got {n}"),
                ));
            }
        }
        if self.iters_per_level > 20 || self.iters_finest > 20 {
            return Err(CoreError::param(
                "iters_per_level",
                "iterations must be <= 20",
            ));
        }
        if self.orientations_finest == 0 {
            return Err(CoreError::param("orientations_finest", "must be >= 1"));
        }
        if self.lr_coarse_levels > 4 {
            return Err(CoreError::param("lr_coarse_levels", "must be <= 4"));
        }
        let unit = |name: &'static str, v: f32| {
            if v.is_finite() && (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(CoreError::param(
                    name,
                    format!("must be in [0, 1], got {v}"),
                ))
            }
        };
        unit("amp_rel_thresh", self.amp_rel_thresh)?;
        unit("conf_min", self.conf_min)?;
        if !(self.stability_tau.is_finite() && self.stability_tau > 0.0) {
            return Err(CoreError::param("stability_tau", "must be finite and > 0"));
        }
        for (name, r) in [
            ("research_radius", self.research_radius),
            ("search_pool_radius", self.search_pool_radius),
        ] {
            if r > 16 {
                return Err(CoreError::param(name, format!("must be <= 16 px, got {r}")));
            }
        }
        if let Some(s) = self.smooth_sigma {
            if !(s.is_finite() && s > 0.0 && s <= 16.0) {
                return Err(CoreError::param(
                    "smooth_sigma",
                    format!("must be in (0, 16] px, got {s}"),
                ));
            }
        }
        if !(self.lr_tol.is_finite() && self.lr_tol >= 0.0) {
            return Err(CoreError::param("lr_tol", "must be finite and >= 0"));
        }
        if !(self.speckle_range.is_finite() && self.speckle_range >= 0.0) {
            return Err(CoreError::param("speckle_range", "must be finite and >= 0"));
        }
        Ok(())
    }

    /// The filter bank (one channel per orientation).
    pub fn channels(&self) -> Result<Vec<Channel>> {
        self.orientations_deg
            .iter()
            .map(|&t| Channel::new(self.freq, t, self.bandwidth_oct, self.aspect))
            .collect()
    }

    /// Pyramid depth for a `w` x `h` image: the smallest `L` whose top level's half-wavelength
    /// capture range covers half the disparity range (A.3), capped by the top-level size.
    pub fn levels_for(&self, w: usize, h: usize) -> usize {
        if let Some(n) = self.n_levels {
            return n;
        }
        let half_range = 0.5 * (self.d_max - self.d_min);
        let mut l = 1;
        while l < MAX_LEVELS && (0.5 / self.freq) * 2f32.powi(l as i32 - 1) < half_range {
            let (tw, th) = (w >> l, h >> l);
            if tw < MIN_TOP_WIDTH || th < MIN_TOP_HEIGHT {
                break;
            }
            l += 1;
        }
        l
    }
}

/// Output of the Gabor channel: disparity (`NaN` = no estimate) and confidence in `[0, 1]`.
#[derive(Debug, Clone)]
pub struct GaborOutput {
    pub disparity: Image,
    pub confidence: Image,
}

/// Raw result of one direction: disparity (every pixel) and max-over-levels confidence.
struct Direction {
    disp: Buf,
    conf: Buf,
}

/// Dense phase-based disparity of a rectified pair.
///
/// `left`, `right`: grey `f32` images in `[0, 1]` of the same size. Returns the disparity
/// `x_left - x_right` at left pixels (`NaN` where not confident or inconsistent) and the
/// confidence (0 where `NaN`). A textureless pair gives an all-`NaN` map, not an error.
pub fn gabor_disparity(left: &Image, right: &Image, params: &GaborParams) -> Result<GaborOutput> {
    gabor_disparity_view(left.view(), right.view(), params)
}

/// [`gabor_disparity`] on borrowed images (the Python binding passes the NumPy buffers).
pub fn gabor_disparity_view(
    left: ImageView<'_>,
    right: ImageView<'_>,
    params: &GaborParams,
) -> Result<GaborOutput> {
    crate::parallel::run_hot(|| gabor_disparity_hot(left, right, params))
}

/// The body of [`gabor_disparity_view`], run inside the pool ([`crate::parallel::run_hot`]).
fn gabor_disparity_hot(
    left: ImageView<'_>,
    right: ImageView<'_>,
    params: &GaborParams,
) -> Result<GaborOutput> {
    if left.size() != right.size() {
        return Err(CoreError::SizeMismatch {
            left: left.size(),
            right: right.size(),
        });
    }
    // The post-processing labels its components in u32.
    crate::image::check_index_range(left.width, left.height)?;
    params.validate()?;
    let chans = params.channels()?;
    let (w, h) = left.size();
    let timing = std::env::var_os("SV_GABOR_TIMING").is_some();
    let t_all = std::time::Instant::now();
    let wall = |what: &str| {
        if timing {
            eprintln!("wall {what}: {:.1} ms", t_all.elapsed().as_secs_f64() * 1e3);
        }
    };
    let (fwd, bwd) = if params.lr_check {
        let fl = post::flip_x(right.data, w, h)?;
        let fr = post::flip_x(left.data, w, h)?;
        let back = if params.lr_light {
            GaborParams {
                orientations_finest: params.orientations_finest.min(LIGHT_ORIENTATIONS),
                iters_finest: params.iters_finest.min(1),
                research_finest: false,
                ..params.clone()
            }
        } else {
            params.clone()
        };
        let (a, b) = rayon::join(
            || one_direction(left.data, right.data, w, h, params, &chans, 0),
            || one_direction(&fl, &fr, w, h, &back, &chans, params.lr_coarse_levels),
        );
        (a?, Some(b?))
    } else {
        (
            one_direction(left.data, right.data, w, h, params, &chans, 0)?,
            None,
        )
    };
    wall("directions");
    let mut disp = fwd.disp.into_vec();
    let mut conf = fwd.conf.into_vec();
    // Validity, with the left-right check (post::lr_check's rule) read straight from the
    // mirrored right-reference map: no flipped copy, no mask image.
    let bwd = bwd.as_ref();
    crate::parallel::for_each_row2(&mut disp, &mut conf, w, |y, drow, crow| {
        let brow = bwd.map_or(&[][..], |b| &b.disp[y * w..(y + 1) * w]);
        post::validity_row(drow, crow, brow, params.conf_min, params.lr_tol)
    });
    wall("lr check");
    post::remove_speckles(&mut disp, w, h, params.speckle_size, params.speckle_range)?;
    wall("speckles");
    crate::parallel::for_each_row(&mut conf, w, |y, crow| {
        for (c, d) in crow.iter_mut().zip(&disp[y * w..(y + 1) * w]) {
            *c = if d.is_finite() {
                c.clamp(0.0, 1.0)
            } else {
                0.0
            };
        }
    });
    wall("done");
    Ok(GaborOutput {
        disparity: Image {
            width: w,
            height: h,
            data: disp,
        },
        confidence: Image {
            width: w,
            height: h,
            data: conf,
        },
    })
}

/// One pyramid level: left and right images and their size.
type PyrLevel<'a> = (Cow<'a, [f32]>, Cow<'a, [f32]>, usize, usize);

/// Coarse-to-fine estimate with `l` as reference, stopping at level `finest` (then up-sampled).
fn one_direction(
    l: &[f32],
    r: &[f32],
    w: usize,
    h: usize,
    p: &GaborParams,
    all_chans: &[Channel],
    finest: usize,
) -> Result<Direction> {
    let n_levels = p.levels_for(w, h).max(finest + 1);
    // Level 0 borrows the input images (no full-resolution copies).
    let mut pyr: Vec<PyrLevel<'_>> = vec![(Cow::Borrowed(l), Cow::Borrowed(r), w, h)];
    for _ in 1..n_levels {
        let Some((pl, pr, pw, ph)) = pyr.last() else {
            break;
        };
        if *pw < 2 || *ph < 2 {
            break;
        }
        let (nl, nw, nh) = filter::pyr_down(pl, *pw, *ph)?;
        let (nr, _, _) = filter::pyr_down(pr, *pw, *ph)?;
        pyr.push((Cow::Owned(nl), Cow::Owned(nr), nw, nh));
    }
    let tau = p.stability_tau;
    let sigma_s = p
        .smooth_sigma
        .unwrap_or_else(|| all_chans.first().map_or(1.0, |c| c.sigma_x));
    let mut state: Option<(Buf, Buf, usize, usize)> = None;
    let timing = std::env::var_os("SV_GABOR_TIMING").is_some();
    let mut t0 = std::time::Instant::now();
    let mut lap = |what: &str, lvl: usize| {
        if timing {
            eprintln!(
                "  L{lvl} {what}: {:.1} ms",
                t0.elapsed().as_secs_f64() * 1e3
            );
            t0 = std::time::Instant::now();
        }
    };
    lap("pyramid", 0);
    for (lvl, (il, ir, lw, lh)) in pyr.iter().enumerate().rev() {
        if lvl < finest {
            break;
        }
        let (lw, lh) = (*lw, *lh);
        let chans = if lvl < p.fine_levels {
            &all_chans[..p.orientations_finest.min(all_chans.len())]
        } else {
            all_chans
        };
        let scale = 0.5f32.powi(lvl as i32);
        let (lo, hi) = (p.d_min * scale - 1.0, p.d_max * scale + 1.0);
        let (ld, rd) = rayon::join(
            || level_data(il, lw, lh, chans, tau, false),
            || level_data(ir, lw, lh, chans, tau, true),
        );
        let (ld, rd) = (ld?, rd?);
        let cc = chan_consts(chans, &ld, &rd, p.amp_rel_thresh);
        lap("filter", lvl);
        let (mut disp, mut conf_max) = match state.take() {
            None => {
                let mut init = Buf::scratch(lw * lh)?;
                init.iter_mut().for_each(|v| *v = p.d_min * scale);
                let n = ((p.d_max - p.d_min) * scale).ceil().max(0.0) as usize;
                let offs: Vec<f32> = (0..=n).map(|k| k as f32).collect();
                (
                    search(&ld, &rd, &init, &offs, p.search_pool_radius)?,
                    Buf::zeroed(lw * lh)?,
                )
            }
            Some((d, c, sw, sh)) => {
                let d = post::upsample(&d, sw, sh, lw, lh, 2.0)?;
                let c = post::upsample(&c, sw, sh, lw, lh, 1.0)?;
                let rr = p.research_radius as i32;
                let d = if rr > 0 && (lvl > 0 || p.research_finest) {
                    let offs: Vec<f32> = (-rr..=rr).map(|k| k as f32).collect();
                    search(&ld, &rd, &d, &offs, p.search_pool_radius)?
                } else {
                    d
                };
                (d, c)
            }
        };
        crate::parallel::for_each_row(&mut disp, lw, |_, row| {
            row.iter_mut().for_each(|d| *d = d.clamp(lo, hi))
        });
        lap("search", lvl);
        let iters = if lvl == 0 {
            p.iters_finest
        } else {
            p.iters_per_level
        };
        for _ in 0..iters {
            let (delta, c) = newton_step(&ld, &rd, &cc, &disp)?;
            lap("newton", lvl);
            let (dbar, cbar) = post::normalized_conv(&delta, &c, lw, lh, sigma_s)?;
            post::apply_update(&mut disp, &dbar, &cbar, p.conf_min, lo, hi, lw);
            lap("nc", lvl);
            disp = post::median5(&disp, lw, lh)?;
            post::max_into(&mut conf_max, &cbar);
            lap("median", lvl);
        }
        state = Some((disp, conf_max, lw, lh));
    }
    match state {
        Some((mut disp, mut conf, mut sw, mut sh)) => {
            // Up-sample a map that stopped above full resolution, level by level.
            for lvl in (0..finest).rev() {
                let (_, _, lw, lh) = pyr[lvl];
                disp = post::upsample(&disp, sw, sh, lw, lh, 2.0)?;
                conf = post::upsample(&conf, sw, sh, lw, lh, 1.0)?;
                (sw, sh) = (lw, lh);
            }
            Ok(Direction { disp, conf })
        }
        None => {
            let mut disp = Buf::zeroed(w * h)?;
            disp.iter_mut().for_each(|v| *v = f32::NAN);
            Ok(Direction {
                disp,
                conf: Buf::zeroed(w * h)?,
            })
        }
    }
}

/// Filter-bank responses of one image for one channel (debugging and parity tests):
/// the complex response `y = h * I` as `(re, im)` planes, row-major `(h, w)`.
pub fn gabor_responses(
    img: &Image,
    freq: f32,
    theta_deg: f32,
    bandwidth_oct: f32,
    aspect: f32,
) -> Result<(Vec<f32>, Vec<f32>)> {
    let c = Channel::new(freq, theta_deg, bandwidth_oct, aspect)?;
    let r = filter::filter_bank(&img.data, img.width, img.height, std::slice::from_ref(&c))?;
    let (mut re, mut im) = (r.re, r.im);
    Ok((re.pop().unwrap_or_default(), im.pop().unwrap_or_default()))
}

/// One raw Newton step at the full resolution for a given disparity map (parity tests): returns
/// the per-pixel WLS update `delta` and mean channel confidence `c`, before any smoothing.
pub fn gabor_newton_step(
    left: &Image,
    right: &Image,
    disp: &Image,
    params: &GaborParams,
) -> Result<(Vec<f32>, Vec<f32>)> {
    check_pair(left, right)?;
    check_pair(left, disp)?;
    params.validate()?;
    let chans = params.channels()?;
    let (w, h) = left.size();
    let ld = level_data(&left.data, w, h, &chans, params.stability_tau, false)?;
    let rd = level_data(&right.data, w, h, &chans, params.stability_tau, true)?;
    let cc = chan_consts(&chans, &ld, &rd, params.amp_rel_thresh);
    let (delta, conf) = newton_step(&ld, &rd, &cc, &disp.data)?;
    Ok((delta.into_vec(), conf.into_vec()))
}

#[cfg(test)]
mod tests;
