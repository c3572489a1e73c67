//! Sub-pixel refinement and validated completion of a disparity map (the pipeline stage between
//! correspondence and triangulation).
//!
//! The Gabor channel's phase estimates are right to about a third of a pixel; that is 3 % of the
//! depth at a 10 px disparity. This stage re-measures every pixel with a zero-mean normalised
//! cross-correlation (ZNCC) of Gaussian windows on the *warped* right image, so the windows
//! follow the surface (slanted ground, walls) instead of being fronto-parallel:
//!
//! 1. `base = NC_sigma(D)`: normalised-convolution smoothing of the input map (NaN = no value;
//!    three box passes, so a wide sigma costs no more than a narrow one).
//! 2. For the shifts `s = k step`, `k = -search..=search` (half a pixel apart by default):
//!    `Rw_s(x, y) = R(x - base(x, y) - s, y)` (Catmull-Rom cubic along the row) and
//!    `z_s = ZNCC(L, Rw_s)` over a Gaussian window.
//! 3. A measured pixel keeps `base + step * (parabola vertex around k = 0)` when the correlation
//!    peaks at `|k| <= 1` and is curved there (a peak, not a slope); otherwise it becomes NaN (the
//!    estimate and the correlation disagree: an occlusion edge or a wrong lock).
//! 4. Fill passes: each hole takes `base' + fill_step * (k + vertex)` from a wider smoothing
//!    `base'` of the map so far (shifts a whole pixel apart: a wider reach), when the peak `k`
//!    has `|k| <= 1`, is curved and its ZNCC reaches `min_score`.
//!
//! Everything is row-band parallel with per-row arithmetic in a fixed order, so the output does
//! not depend on the thread count. `tests/reference/refine_ref.py` is the same maths in NumPy.

use crate::alloc::{try_collect, try_filled, try_reserve_len, try_zeroed, ZeroBits};
use crate::error::{CoreError, Result};
use crate::image::check_map_pair;
use crate::parallel::for_each_row;
use crate::simd::simd_fn;
use crate::ImageView;

/// One fill pass: smoothing sigma of the map so far (px) and the ZNCC a filled pixel must reach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FillPass {
    pub sigma: f32,
    pub min_score: f32,
}

/// Parameters of [`refine_disparity`].
#[derive(Debug, Clone, PartialEq)]
pub struct RefineParams {
    /// Normalised-convolution smoothing of the input map before warping (px).
    pub base_sigma: f32,
    /// Gaussian correlation window: sigma and radius (px).
    pub win_sigma: f32,
    pub win_radius: usize,
    /// Shifts searched on each side of the warped estimate when re-measuring, `step` px apart.
    pub search: usize,
    /// Spacing of the searched shifts when re-measuring (px). Half a pixel: a parabola through
    /// correlations a whole pixel apart is biased towards whole pixels by up to 0.05 px (pixel
    /// locking); half a pixel apart, by under 0.01 px.
    pub step: f32,
    /// Shifts on each side, and their spacing (px), of the fill passes: a whole pixel apart,
    /// two each side, so a fill reaches 2 px either side of its smoothed start.
    pub fill_search: usize,
    pub fill_step: f32,
    /// Window variance below which a pixel has no texture to correlate (grey levels in [0, 1]).
    pub var_floor: f32,
    /// Fill passes, in order (empty = refine only).
    pub fills: Vec<FillPass>,
    /// Confidence given to a filled pixel (its input confidence is 0).
    pub fill_confidence: f32,
    /// A fill starts from the local plane fit of the map so far ([`nc_plane`]) rather than its
    /// local mean, and only where the values around it lie within this RMS distance of that
    /// plane (px; infinite = no test): one surface, not a depth edge or foliage.
    pub fill_plane: bool,
    pub fill_max_residual: f32,
}

impl Default for RefineParams {
    fn default() -> Self {
        RefineParams {
            base_sigma: 4.0,
            win_sigma: 4.5,
            win_radius: 9,
            search: 2,
            step: 0.5,
            fill_search: 2,
            fill_step: 1.0,
            var_floor: 1e-6,
            fills: vec![FillPass {
                sigma: 16.0,
                min_score: 0.3,
            }],
            fill_confidence: 0.25,
            fill_plane: true,
            fill_max_residual: f32::INFINITY,
        }
    }
}

impl RefineParams {
    fn validate(&self) -> Result<()> {
        let pos = |name: &'static str, v: f32| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(CoreError::param(name, format!("must be > 0, got {v}")))
            }
        };
        pos("base_sigma", self.base_sigma)?;
        pos("win_sigma", self.win_sigma)?;
        pos("var_floor", self.var_floor)?;
        pos("step", self.step)?;
        pos("fill_step", self.fill_step)?;
        if self.win_radius == 0 || self.win_radius > 64 {
            return Err(CoreError::param(
                "win_radius",
                format!("must be in 1..=64, got {}", self.win_radius),
            ));
        }
        for (name, v) in [("search", self.search), ("fill_search", self.fill_search)] {
            if v == 0 || v > 16 {
                return Err(CoreError::param(
                    name,
                    format!("must be in 1..=16, got {v}"),
                ));
            }
        }
        if self.fill_max_residual.is_nan() || self.fill_max_residual <= 0.0 {
            return Err(CoreError::param(
                "fill_max_residual",
                format!(
                    "must be > 0 (inf = no test), got {}",
                    self.fill_max_residual
                ),
            ));
        }
        if !(0.0..=1.0).contains(&self.fill_confidence) {
            return Err(CoreError::param(
                "fill_confidence",
                format!("must be in [0, 1], got {}", self.fill_confidence),
            ));
        }
        for f in &self.fills {
            pos("fill sigma", f.sigma)?;
            if !(f.min_score.is_finite() && f.min_score > -1.0 && f.min_score < 1.0) {
                return Err(CoreError::param(
                    "fill min_score",
                    format!("must be in (-1, 1), got {}", f.min_score),
                ));
            }
        }
        Ok(())
    }
}

/// Unnormalised Gaussian taps `exp(-i^2 / (2 sigma^2))`, `i = -r..=r`.
pub fn gaussian_taps(sigma: f32, radius: usize) -> Vec<f32> {
    let r = radius as i64;
    (-r..=r)
        .map(|i| (-((i * i) as f32) / (2.0 * sigma * sigma)).exp())
        .collect()
}

/// Half-width of the box whose three-fold repetition has the variance of a Gaussian of
/// `sigma`: `(2b + 1)^2 = 4 sigma^2 + 1`, rounded, at least 1.
pub fn box3_radius(sigma: f32) -> usize {
    (((4.0 * sigma * sigma + 1.0).sqrt() - 1.0) / 2.0)
        .round()
        .max(1.0) as usize
}

/// A sample type of the box sums: `f32` maps, `f64` moments (running sums are always f64).
pub trait BoxSample: Copy + Default + Send + Sync + ZeroBits {
    fn to64(self) -> f64;
    fn from64(v: f64) -> Self;
}

impl BoxSample for f32 {
    #[inline]
    fn to64(self) -> f64 {
        self as f64
    }
    #[inline]
    fn from64(v: f64) -> Self {
        v as f32
    }
}

impl BoxSample for f64 {
    #[inline]
    fn to64(self) -> f64 {
        self
    }
    #[inline]
    fn from64(v: f64) -> Self {
        v
    }
}

/// Box sum of half-width `b` along a row with zero padding, by a running sum (O(1) a pixel).
fn box_row<T: BoxSample>(src: &[T], dst: &mut [T], b: usize) {
    let n = src.len();
    let mut acc = 0f64; // f64: the running sum must not drift along a long row
    for v in src.iter().take(b.min(n)) {
        acc += v.to64();
    }
    for x in 0..n {
        if x + b < n {
            acc += src[x + b].to64();
        }
        if x > b {
            acc -= src[x - b - 1].to64();
        }
        dst[x] = T::from64(acc);
    }
}

/// Rows [`box3_zero`] sums together.
const ROWS_AT_ONCE: usize = 4;

/// [`box_row`] of `N` consecutive rows of width `w` (`src`, `dst`: `N * w` values), the rows'
/// running sums interleaved: each row's values are exactly [`box_row`]'s.
#[inline(always)]
fn box_rows<T: BoxSample, const N: usize>(src: &[T], dst: &mut [T], w: usize, b: usize) {
    let mut acc = [0f64; N];
    for (r, a) in acc.iter_mut().enumerate() {
        for v in src[r * w..].iter().take(b.min(w)) {
            *a += v.to64();
        }
    }
    for x in 0..w {
        for (r, a) in acc.iter_mut().enumerate() {
            let row = &src[r * w..(r + 1) * w];
            if x + b < w {
                *a += row[x + b].to64();
            }
            if x > b {
                *a -= row[x - b - 1].to64();
            }
            dst[r * w + x] = T::from64(*a);
        }
    }
}

/// Box sum of half-width `b` down the columns (zero padding): a running sum per column, whole
/// rows at a time (vectorised over x).
fn box_cols<T: BoxSample>(src: &[T], dst: &mut [T], w: usize, h: usize, b: usize) {
    let mut acc = vec![0f64; w];
    let row = |y: usize| &src[y * w..(y + 1) * w];
    for y in 0..b.min(h) {
        for (a, &v) in acc.iter_mut().zip(row(y)) {
            *a += v.to64();
        }
    }
    for y in 0..h {
        if y + b < h {
            for (a, &v) in acc.iter_mut().zip(row(y + b)) {
                *a += v.to64();
            }
        }
        if y > b {
            for (a, &v) in acc.iter_mut().zip(row(y - b - 1)) {
                *a -= v.to64();
            }
        }
        for (d, &a) in dst[y * w..(y + 1) * w].iter_mut().zip(&acc) {
            *d = T::from64(a);
        }
    }
}

/// Three box passes of half-width `b` along x, then three along y (zero padding): a
/// Gaussian-like smoothing whose cost does not grow with its width. The column strips (an
/// image's worth in all) are allocated checked: [`CoreError::OutOfMemory`] naming `what`.
pub fn box3_zero<T: BoxSample>(
    a: Vec<T>,
    w: usize,
    h: usize,
    b: usize,
    what: &'static str,
) -> Result<Vec<T>> {
    // A box reaching past both ends sums the whole row (column) whatever its width, so the
    // half-width is held to the longer side: a sigma of 1e19 px or more made it usize::MAX
    // (`box3_radius` saturates), and `x + b` wrapped (a debug build panicked, a release build
    // added the wrong pixels: fills differed from a sigma of 1e15 on the same 20x30 map).
    let b = b.min(w.max(h));
    let mut rows = a;
    // Rows in groups of ROWS_AT_ONCE: their running sums interleaved, so the adds of one row do
    // not wait on each other (each row's sums in its own order, as box_row).
    {
        use rayon::prelude::*;
        if w > 0 {
            rows.par_chunks_mut(w * ROWS_AT_ONCE).for_each_init(
                Vec::new,
                |tmp: &mut Vec<T>, group| {
                    tmp.resize(group.len(), T::default());
                    for _ in 0..3 {
                        if group.len() == w * ROWS_AT_ONCE {
                            box_rows::<T, ROWS_AT_ONCE>(group, tmp, w, b);
                        } else {
                            for (src, dst) in group.chunks(w).zip(tmp.chunks_mut(w)) {
                                box_row(src, dst, b);
                            }
                        }
                        group.copy_from_slice(tmp);
                    }
                },
            );
        }
    }
    // Columns in parallel strips of 64 (each strip's running sums are independent).
    const STRIP: usize = 64;
    let strips: Vec<usize> = (0..w).step_by(STRIP).collect();
    let done: Vec<(usize, Vec<T>)> = {
        use rayon::prelude::*;
        strips
            .par_iter()
            .map(|&x0| {
                let sw = STRIP.min(w - x0);
                let mut cur = try_collect(
                    sw * h,
                    (0..h).flat_map(|y| rows[y * w + x0..y * w + x0 + sw].iter().copied()),
                    what,
                )?;
                let mut tmp = try_zeroed::<T>(sw * h, what)?;
                for _ in 0..3 {
                    box_cols(&cur, &mut tmp, sw, h, b);
                    std::mem::swap(&mut cur, &mut tmp);
                }
                Ok((x0, cur))
            })
            .collect::<Result<_>>()?
    };
    // Back into rows (the row-pass buffer, no longer read), in parallel over the rows.
    let mut out = rows;
    for_each_row(&mut out, w, |y, row| {
        for (x0, strip) in &done {
            let sw = STRIP.min(w - x0);
            row[*x0..x0 + sw].copy_from_slice(&strip[y * sw..(y + 1) * sw]);
        }
    });
    Ok(out)
}

/// Local plane fit of a map with holes (first-order normalised convolution with the three-box
/// kernel of [`box3_radius`]): at each pixel, the weighted least-squares plane
/// `d = a + b dx + c dy` through the values around it. Returns the plane's value `a` there and
/// (with `residual`; NaN otherwise) the weighted RMS residual of the values about the plane
/// (px): how far the neighbourhood is from one surface (a slanted road fits; a depth edge or
/// foliage does not). Where the
/// neighbourhood's positions do not fix a plane (fewer than three, or all on a line) the plane
/// is flat (the mean). NaN where no value lies within reach. Moments in f64, about the image
/// centre. A failed allocation of a map is [`CoreError::OutOfMemory`].
pub fn nc_plane(
    d: &[f32],
    w: usize,
    h: usize,
    sigma: f32,
    residual: bool,
) -> Result<(Vec<f32>, Vec<f32>)> {
    let what = "the refinement's local plane fit";
    use rayon::prelude::*;
    let b = box3_radius(sigma);
    let (cx, cy) = ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0);
    let n = w * h;
    // m, m u, m v, m u^2, m u v, m v^2, m d, m u d, m v d, m d^2 (u, v about the image centre)
    let moment = |k: usize, x: usize, y: usize| -> f64 {
        let v = d[y * w + x];
        if !v.is_finite() {
            return 0.0;
        }
        let (u, t, dd) = (x as f64 - cx, y as f64 - cy, v as f64);
        match k {
            0 => 1.0,
            1 => u,
            2 => t,
            3 => u * u,
            4 => u * t,
            5 => t * t,
            6 => dd,
            7 => u * dd,
            8 => t * dd,
            _ => dd * dd,
        }
    };
    // The d^2 moment serves the residual only.
    let n_maps = if residual { 10 } else { 9 };
    // The maps are independent: one parallel job each (each also parallel inside).
    let s: Vec<Vec<f64>> = (0..n_maps)
        .into_par_iter()
        .map(|k| {
            let mut m = try_zeroed::<f64>(n, what)?;
            for_each_row(&mut m, w, |y, row| {
                for (x, v) in row.iter_mut().enumerate() {
                    *v = moment(k, x, y);
                }
            });
            box3_zero(m, w, h, b, what)
        })
        .collect::<Result<_>>()?;
    let mut plane = try_filled(n, f32::NAN, what)?;
    let mut resid = try_filled(n, f32::NAN, what)?;
    plane
        .par_chunks_mut(w)
        .zip(resid.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (prow, rrow))| {
            for x in 0..w {
                let i = y * w + x;
                if let Some((a, r)) = plane_at(&s, i, x as f64 - cx, y as f64 - cy) {
                    prow[x] = a as f32;
                    rrow[x] = r as f32;
                }
            }
        });
    Ok((plane, resid))
}

/// The plane's value and RMS residual at pixel `i` (at `(up, vp)` about the image centre) from
/// the ten box-summed moments of [`nc_plane`]; None where no value is within reach.
#[inline]
fn plane_at(s: &[Vec<f64>], i: usize, up: f64, vp: f64) -> Option<(f64, f64)> {
    let m0 = s[0][i];
    if m0 <= 0.5 {
        return None;
    }
    // Moments about the pixel itself.
    let mu = s[1][i] - up * m0;
    let mv = s[2][i] - vp * m0;
    let muu = s[3][i] - 2.0 * up * s[1][i] + up * up * m0;
    let muv = s[4][i] - up * s[2][i] - vp * s[1][i] + up * vp * m0;
    let mvv = s[5][i] - 2.0 * vp * s[2][i] + vp * vp * m0;
    let md = s[6][i];
    let mud = s[7][i] - up * md;
    let mvd = s[8][i] - vp * md;
    // Solve [m0 mu mv; mu muu muv; mv muv mvv] (a b c) = (md mud mvd) by Cramer's rule.
    let det =
        m0 * (muu * mvv - muv * muv) - mu * (mu * mvv - muv * mv) + mv * (mu * muv - muu * mv);
    let scale = m0 * (muu * mvv).max(1e-300);
    let (a, fit) = if det > 1e-9 * scale {
        let a = (md * (muu * mvv - muv * muv) - mu * (mud * mvv - muv * mvd)
            + mv * (mud * muv - muu * mvd))
            / det;
        let bb = (m0 * (mud * mvv - muv * mvd) - md * (mu * mvv - muv * mv)
            + mv * (mu * mvd - mud * mv))
            / det;
        let c = (m0 * (muu * mvd - mud * muv) - mu * (mu * mvd - mud * mv)
            + md * (mu * muv - muu * mv))
            / det;
        (a, a * md + bb * mud + c * mvd)
    } else {
        let a = md / m0;
        (a, a * md)
    };
    let rms = s
        .get(9)
        .map_or(f64::NAN, |mdd| ((mdd[i] - fit) / m0).max(0.0).sqrt());
    Some((a, rms))
}

/// Normalised-convolution smoothing of a map with holes (NaN): `K*(v m) / K*m` with the
/// three-box kernel of [`box3_radius`]; NaN where no value lies within the kernel's reach.
/// A failed allocation of a map is [`CoreError::OutOfMemory`].
pub fn nc_smooth(d: &[f32], w: usize, h: usize, sigma: f32) -> Result<Vec<f32>> {
    let what = "the refinement's smoothed map";
    let b = box3_radius(sigma);
    let m = try_collect(d.len(), d.iter().map(|v| v.is_finite() as u8 as f32), what)?;
    let vm = try_collect(
        d.len(),
        d.iter().map(|&v| if v.is_finite() { v } else { 0.0 }),
        what,
    )?;
    let num = box3_zero(vm, w, h, b, what)?;
    let den = box3_zero(m, w, h, b, what)?;
    try_collect(
        num.len(),
        num.iter()
            .zip(&den)
            .map(|(&n, &dd)| if dd > 0.5 { n / dd } else { f32::NAN }),
        what,
    )
}

/// Catmull-Rom weights of the samples at `i - 1, i, i + 1, i + 2` for a position `i + f`.
#[inline]
pub fn cubic_weights(f: f32) -> [f32; 4] {
    let (f2, f3) = (f * f, f * f * f);
    [
        0.5 * (-f3 + 2.0 * f2 - f),
        0.5 * (3.0 * f3 - 5.0 * f2 + 2.0),
        0.5 * (-3.0 * f3 + 4.0 * f2 + f),
        0.5 * (f3 - f2),
    ]
}

/// `q . row[i - 1 ..= i + 2]`, the indices clamped to the row only near its ends.
#[inline(always)]
fn sample4(row: &[f32], i: i32, q: [f32; 4]) -> f32 {
    let n = row.len() as i32;
    if i >= 1 && i + 2 < n {
        let r = &row[(i - 1) as usize..(i + 3) as usize];
        q[0] * r[0] + q[1] * r[1] + q[2] * r[2] + q[3] * r[3]
    } else {
        let at = |j: i32| row[(i + j).clamp(0, n - 1) as usize];
        q[0] * at(-1) + q[1] * at(0) + q[2] * at(1) + q[3] * at(2)
    }
}

/// Catmull-Rom sample of `row` at real position `t` (indices clamped to the row: from a whole
/// sample past either end on, `t <= -1` or `t >= row.len()`, the end's value to within float32
/// rounding; nearer, the curve still bends towards the end's neighbour).
#[inline]
pub fn cubic_sample(row: &[f32], t: f32) -> f32 {
    // Held within two samples of the row, as `warp_row` holds it: a `t` of 2**31 or more (or
    // -2**31 or less) saturated the i32 index, and `i + 2` (`i - 1`) overflowed (a debug build
    // panicked, a release build indexed past the row). Every position beyond reads the end.
    let fl = t.floor().max(-2.0).min(row.len() as f32 + 1.0);
    sample4(row, fl as i32, cubic_weights((t - fl).clamp(0.0, 1.0)))
}

simd_fn! {
    /// `out[x] = sum_k g_k src[x + k - r]` over the taps inside the row (zero padding), the
    /// taps added in order from 0.
    fn hconv(src: &[f32], out: &mut [f32], taps: &[f32]) {
        let w = src.len();
        let r = taps.len() / 2;
        // Pixels whose window lies inside the row, LANES at a time with the sums in registers.
        const LANES: usize = 8;
        let (a, b) = (r.min(w), w.saturating_sub(r));
        let mut x = a;
        while x + LANES <= b {
            let mut acc = [0.0f32; LANES];
            for (k, &g) in taps.iter().enumerate() {
                let s = &src[x + k - r..x + k - r + LANES];
                for l in 0..LANES {
                    acc[l] += g * s[l];
                }
            }
            out[x..x + LANES].copy_from_slice(&acc);
            x += LANES;
        }
        // The borders and the interior's tail: the taps inside the row, in the same order.
        for xx in (0..a).chain(x..w) {
            let mut acc = 0.0f32;
            for (k, &g) in taps.iter().enumerate() {
                let j = xx as isize + k as isize - r as isize;
                if j >= 0 && (j as usize) < w {
                    acc += g * src[j as usize];
                }
            }
            out[xx] = acc;
        }
    }
}

simd_fn! {
    /// `a[x] = sum_t g_t sa[o_t + x]` over `taps` = `(g_t, o_t)` in order from 0, LANES columns at
    /// a time with the sums in registers (the column pass of the window sums).
    fn vsum1(a: &mut [f32], taps: &[(f32, usize)], sa: &[f32]) {
        const LANES: usize = 8;
        let w = a.len();
        let mut x = 0;
        while x + LANES <= w {
            let mut p = [0.0f32; LANES];
            for &(g, o) in taps {
                let u = &sa[o + x..o + x + LANES];
                for l in 0..LANES {
                    p[l] += g * u[l];
                }
            }
            a[x..x + LANES].copy_from_slice(&p);
            x += LANES;
        }
        for xx in x..w {
            let mut p = 0.0f32;
            for &(g, o) in taps {
                p += g * sa[o + xx];
            }
            a[xx] = p;
        }
    }
}

simd_fn! {
    /// One row of ZNCC values from the window sums of the warped row (`s1`, `s2`, `s12`) and
    /// the left image's window statistics; NaN where the counterpart `t = x - base - s` falls
    /// outside the right image, the base is NaN, or either window is flatter than `floor`.
    fn zncc_row(
        z: &mut [f32], s1: &[f32], s2: &[f32], s12: &[f32], mass: &[f32], mean: &[f32],
        var: &[f32], base: &[f32], s: f32, floor: f32,
    ) {
        let wmax = (z.len() - 1) as f32;
        for x in 0..z.len() {
            let m = mass[x];
            let mr = s1[x] / m;
            let vr = s2[x] / m - mr * mr;
            let vl = var[x];
            let c = s12[x] / m - mean[x] * mr;
            let t = x as f32 - base[x] - s;
            let ok = (t >= 0.0) & (t <= wmax) & (vl > floor) & (vr > floor);
            let v = c / (vl * vr).sqrt();
            z[x] = if ok { v } else { f32::NAN };
        }
    }
}

simd_fn! {
    /// The warped row's square and its product with the centred left row.
    fn products(rw: &[f32], lc: &[f32], sq: &mut [f32], lr: &mut [f32]) {
        for (((q, p), &v), &l) in sq.iter_mut().zip(lr.iter_mut()).zip(rw).zip(lc) {
            *q = v * v;
            *p = v * l;
        }
    }
}

simd_fn! {
    /// A row of the right image warped by `base + s` (Catmull-Rom, minus `center`; 0 where
    /// the base is NaN). Two passes: positions and weights (vectorised, structure of arrays),
    /// then the four samples of each (clamped to the row only near its ends).
    fn warp_row(
        row: &[f32], base: &[f32], s: f32, center: f32, out: &mut [f32], idx: &mut [i32],
        q: &mut [Vec<f32>; 4],
    ) {
        let n = row.len() as i32;
        let w = row.len();
        let [q0, q1, q2, q3] = q;
        let (q0, q1, q2, q3) = (&mut q0[..w], &mut q1[..w], &mut q2[..w], &mut q3[..w]);
        let idx = &mut idx[..w];
        let hi = n as f32 + 1.0;
        for x in 0..w {
            let t = x as f32 - base[x] - s;
            // NaN base: t is NaN, max/min turn it into -2 (any index: its output is 0 below)
            // and the clamp keeps f NaN, which only reaches that discarded output.
            let fl = t.floor().max(-2.0).min(hi);
            [q0[x], q1[x], q2[x], q3[x]] = cubic_weights((t - fl).clamp(0.0, 1.0));
            idx[x] = fl as i32;
        }
        for x in 0..w {
            let v = sample4(row, idx[x], [q0[x], q1[x], q2[x], q3[x]]);
            out[x] = if base[x].is_finite() { v - center } else { 0.0 };
        }
    }
}

/// Local Gaussian-window statistics of the centred left image, shared by every shift. Both
/// images are centred on their own mean (ZNCC does not see it): it keeps `E[x^2] - E[x]^2`
/// away from float32 cancellation in dark or bright images.
struct LeftStats {
    mass: Vec<f32>,
    mean: Vec<f32>,
    var: Vec<f32>,
    lc: Vec<f32>,
    /// Mean of the right image, subtracted from its warped rows.
    right_mean: f32,
}

/// The name of the left image's window statistics in an out-of-memory error.
const STATS: &str = "the refinement's window statistics";

/// Separable Gaussian-window sums (zero padding, rows then columns) of a full image.
fn window_sum(a: &[f32], w: usize, h: usize, taps: &[f32]) -> Result<Vec<f32>> {
    let mut tmp = try_zeroed::<f32>(w * h, STATS)?;
    for_each_row(&mut tmp, w, |y, out| {
        hconv(&a[y * w..(y + 1) * w], out, taps)
    });
    let mut out = try_zeroed::<f32>(w * h, STATS)?;
    for_each_row(&mut out, w, |y, o| {
        vsum1(o, &taps_inside(taps, y, h, |yy| yy * w), &tmp);
    });
    Ok(out)
}

/// Mean of an image, summed in f64 in a fixed order.
fn image_mean(a: &[f32]) -> f32 {
    (a.iter().map(|&v| v as f64).sum::<f64>() / a.len().max(1) as f64) as f32
}

/// The taps of a column window centred on row `y` whose row lies inside the image (`h` rows),
/// in order, as `(weight, offset(row))`: the `taps` argument of [`vsum1`].
fn taps_inside(
    taps: &[f32],
    y: usize,
    h: usize,
    offset: impl Fn(usize) -> usize,
) -> Vec<(f32, usize)> {
    let r = taps.len() / 2;
    taps.iter()
        .enumerate()
        .filter_map(|(k, &g)| {
            let yy = y as i64 + k as i64 - r as i64;
            (yy >= 0 && yy < h as i64).then(|| (g, offset(yy as usize)))
        })
        .collect()
}

/// [`window_sum`] of an image of ones, without the passes: every row of the row pass is the
/// same, so every row whose column window lies inside the image sums the same terms in the same
/// order; those rows are one copied row, the others (the top and bottom `r`) are summed.
fn window_mass(w: usize, h: usize, taps: &[f32]) -> Result<Vec<f32>> {
    let r = taps.len() / 2;
    let ones = vec![1f32; w];
    let mut row = vec![0f32; w];
    hconv(&ones, &mut row, taps);
    // Every tap reads the same row (offset 0).
    let column = |y: usize, o: &mut [f32]| vsum1(o, &taps_inside(taps, y, h, |_| 0), &row);
    let mut inner = vec![0f32; w];
    if h > 2 * r {
        column(r, &mut inner);
    }
    let mut out = try_zeroed::<f32>(w * h, STATS)?;
    for_each_row(&mut out, w, |y, o| {
        if y >= r && y + r < h {
            o.copy_from_slice(&inner);
        } else {
            column(y, o);
        }
    });
    Ok(out)
}

fn left_stats(l: &[f32], r: &[f32], w: usize, h: usize, taps: &[f32]) -> Result<LeftStats> {
    let lm = image_mean(l);
    let lc = try_collect(l.len(), l.iter().map(|v| v - lm), STATS)?;
    let mass = window_mass(w, h, taps)?;
    let s1 = window_sum(&lc, w, h, taps)?;
    let sq = try_collect(lc.len(), lc.iter().map(|v| v * v), STATS)?;
    let s2 = window_sum(&sq, w, h, taps)?;
    drop(sq);
    let mean = try_collect(s1.len(), s1.iter().zip(&mass).map(|(a, m)| a / m), STATS)?;
    let var = try_collect(
        s2.len(),
        s2.iter()
            .zip(&mass)
            .zip(&mean)
            .map(|((a, m), mu)| a / m - mu * mu),
        STATS,
    )?;
    Ok(LeftStats {
        mass,
        mean,
        var,
        lc,
        right_mean: image_mean(r),
    })
}

/// Rows per band of the fused correlation pass (the window's rows above and below are
/// recomputed per band: 18 of 128 at the default radius).
const BAND: usize = 128;

/// Per-thread buffers of [`zncc_band`], reused from band to band (fresh multi-megabyte
/// allocations per band cost as much in page faults as the arithmetic).
#[derive(Default)]
struct Scratch {
    h1: Vec<f32>,
    h2: Vec<f32>,
    h12: Vec<f32>,
    rw: Vec<f32>,
    idx: Vec<i32>,
    q: [Vec<f32>; 4],
    sq: Vec<f32>,
    lr: Vec<f32>,
    a1: Vec<f32>,
    a2: Vec<f32>,
    a12: Vec<f32>,
    /// Correlations of the band, shift-major: `z[k * band_len + j]`.
    z: Vec<f32>,
}

fn sized(v: &mut Vec<f32>, n: usize) -> &mut [f32] {
    if v.len() < n {
        v.resize(n, 0.0);
    }
    &mut v[..n]
}

impl Scratch {
    /// Room for a band of `band_len` pixels, `n_s` shifts and `rows` rows of width `w` (the
    /// band's with the window's margins): [`sized`] then grows nothing. `z` holds up to 33
    /// values a pixel of the band and the row sums up to 256 rows, per worker: a failed
    /// `resize` aborted the process, a failed reservation is [`CoreError::OutOfMemory`].
    fn reserve(&mut self, band_len: usize, n_s: usize, rows: usize, w: usize) -> Result<()> {
        let what = "the refinement's band buffers";
        try_reserve_len(&mut self.z, band_len.saturating_mul(n_s), what)?;
        let win = rows.saturating_mul(w);
        for v in [&mut self.h1, &mut self.h2, &mut self.h12] {
            try_reserve_len(v, win, what)?;
        }
        let rows = [
            &mut self.rw,
            &mut self.sq,
            &mut self.lr,
            &mut self.a1,
            &mut self.a2,
            &mut self.a12,
        ];
        for v in rows.into_iter().chain(self.q.iter_mut()) {
            try_reserve_len(v, w, what)?;
        }
        try_reserve_len(&mut self.idx, w, what)
    }
}

/// Correlations of every shift `k step`, `k = -search..=search`, around `base` for the rows
/// `y0..y1`, into `sc.z` (shift-major): per shift, warp, products, row sums and column sums in
/// one streaming pass over the band. NaN where undefined: no base, no counterpart in the right
/// image, or too little texture in either window.
#[allow(clippy::too_many_arguments)]
fn zncc_band(
    sc: &mut Scratch,
    ls: &LeftStats,
    r: &[f32],
    base: &[f32],
    p: &RefineParams,
    (search, step): (usize, f32),
    taps: &[f32],
    w: usize,
    h: usize,
    y0: usize,
    y1: usize,
) -> Result<()> {
    let rad = taps.len() / 2;
    let ya = y0.saturating_sub(rad);
    let yb = (y1 + rad).min(h);
    let nr = yb - ya;
    let n_s = 2 * search + 1;
    let band_len = (y1 - y0) * w;
    sc.reserve(band_len, n_s, nr, w)?;
    sized(&mut sc.z, n_s * band_len);
    for k in 0..n_s {
        let s = (k as f32 - search as f32) * step;
        let h1 = sized(&mut sc.h1, nr * w);
        let h2 = sized(&mut sc.h2, nr * w);
        let h12 = sized(&mut sc.h12, nr * w);
        let rw = sized(&mut sc.rw, w);
        let sq = sized(&mut sc.sq, w);
        let lr = sized(&mut sc.lr, w);
        sc.idx.resize(w, 0);
        for v in sc.q.iter_mut() {
            v.resize(w, 0.0);
        }
        for y in ya..yb {
            let (row, b) = (&r[y * w..(y + 1) * w], &base[y * w..(y + 1) * w]);
            warp_row(row, b, s, ls.right_mean, rw, &mut sc.idx, &mut sc.q);
            products(rw, &ls.lc[y * w..(y + 1) * w], sq, lr);
            let o = (y - ya) * w;
            hconv(rw, &mut h1[o..o + w], taps);
            hconv(sq, &mut h2[o..o + w], taps);
            hconv(lr, &mut h12[o..o + w], taps);
        }
        let (h1, h2, h12) = (&sc.h1[..nr * w], &sc.h2[..nr * w], &sc.h12[..nr * w]);
        let a1 = sized(&mut sc.a1, w);
        let a2 = sized(&mut sc.a2, w);
        let a12 = sized(&mut sc.a12, w);
        let z = &mut sc.z[k * band_len..(k + 1) * band_len];
        for y in y0..y1 {
            // The taps whose row is inside the image (offsets in the band's rows).
            let rows_in = taps_inside(taps, y, h, |yy| (yy - ya) * w);
            vsum1(a1, &rows_in, h1);
            vsum1(a2, &rows_in, h2);
            vsum1(a12, &rows_in, h12);
            let rows = y * w..(y + 1) * w;
            zncc_row(
                &mut z[(y - y0) * w..(y - y0 + 1) * w],
                a1,
                a2,
                a12,
                &ls.mass[rows.clone()],
                &ls.mean[rows.clone()],
                &ls.var[rows.clone()],
                &base[rows],
                s,
                p.var_floor,
            );
        }
    }
    Ok(())
}

/// The peak of a pixel's correlations `z[0..n]` (shift `k - search`): `(k, z_k)` of the first
/// maximum, or None when any value is NaN.
#[inline]
fn peak(z: &[f32]) -> Option<(usize, f32)> {
    let mut best = (0usize, f32::NEG_INFINITY);
    for (k, &v) in z.iter().enumerate() {
        if !v.is_finite() {
            return None;
        }
        if v > best.1 {
            best = (k, v);
        }
    }
    Some(best)
}

/// Parabola vertex offset through `(-1, a) (0, b) (1, c)`, clamped to `[-1, 1]`; None when the
/// three points are not a peak (curvature `a - 2b + c >= -1e-6`).
#[inline]
pub fn parabola_offset(a: f32, b: f32, c: f32) -> Option<f32> {
    let curv = a - 2.0 * b + c;
    if curv < -1e-6 {
        Some((0.5 * (a - c) / curv).clamp(-1.0, 1.0))
    } else {
        None
    }
}

/// One stage over the whole image: for every pixel where `todo(i)` holds, the correlations at
/// the shifts `step` apart around `base` and `decide(i, z)` give the new value (None = leave
/// `out` as is).
#[allow(clippy::too_many_arguments)]
fn stage<T, D>(
    ls: &LeftStats,
    r: &[f32],
    base: &[f32],
    p: &RefineParams,
    shifts: (usize, f32),
    taps: &[f32],
    w: usize,
    h: usize,
    out: &mut [f32],
    todo: T,
    decide: D,
) -> Result<()>
where
    T: Fn(usize) -> bool + Sync,
    D: Fn(usize, &[f32]) -> Option<f32> + Sync,
{
    use rayon::prelude::*;
    let n_s = 2 * shifts.0 + 1;
    out.par_chunks_mut(w * BAND).enumerate().try_for_each_init(
        || (Scratch::default(), vec![0f32; n_s]),
        |(sc, zb), (bi, chunk)| {
            let y0 = bi * BAND;
            let y1 = (y0 + BAND).min(h);
            if !(y0 * w..y1 * w).any(&todo) {
                return Ok(());
            }
            zncc_band(sc, ls, r, base, p, shifts, taps, w, h, y0, y1)?;
            let band_len = (y1 - y0) * w;
            for (j, o) in chunk.iter_mut().enumerate().take(band_len) {
                let i = y0 * w + j;
                if !todo(i) {
                    continue;
                }
                for (k, v) in zb.iter_mut().enumerate() {
                    *v = sc.z[k * band_len + j];
                }
                if let Some(v) = decide(i, zb) {
                    *o = v;
                }
            }
            Ok(())
        },
    )
}

/// Refines and completes a disparity map of a rectified grey pair (module docs).
///
/// `disp` and `conf` are `w` x `h` (NaN = no estimate); returns the refined map, its confidence
/// (the input's for refined pixels, `fill_confidence` for filled ones, 0 where NaN), and the
/// number of pixels filled. Disparities outside `[d_min, d_max]` become NaN.
#[allow(clippy::too_many_arguments)]
pub fn refine_disparity(
    left: ImageView<'_>,
    right: ImageView<'_>,
    disp: &[f32],
    conf: &[f32],
    d_min: f32,
    d_max: f32,
    p: &RefineParams,
) -> Result<(Vec<f32>, Vec<f32>, usize)> {
    crate::parallel::run_hot(|| refine_disparity_hot(left, right, disp, conf, d_min, d_max, p))
}

/// The body of [`refine_disparity`], run inside the pool ([`crate::parallel::run_hot`]).
fn refine_disparity_hot(
    left: ImageView<'_>,
    right: ImageView<'_>,
    disp: &[f32],
    conf: &[f32],
    d_min: f32,
    d_max: f32,
    p: &RefineParams,
) -> Result<(Vec<f32>, Vec<f32>, usize)> {
    p.validate()?;
    let (w, h) = (left.width, left.height);
    if (right.width, right.height) != (w, h) {
        return Err(CoreError::SizeMismatch {
            left: (w, h),
            right: (right.width, right.height),
        });
    }
    // The warp holds columns in i32.
    crate::image::check_index_range(w, h)?;
    check_map_pair(disp, conf, w, h)?;
    // Each bound by its own name, in GaborParams::validate's words ("`range`: need finite
    // d_min < d_max, got NaN, 10" named no argument the caller passed).
    for (name, v) in [("d_min", d_min), ("d_max", d_max)] {
        if !v.is_finite() {
            return Err(CoreError::param(name, format!("must be finite, got {v}")));
        }
    }
    if d_max <= d_min {
        return Err(CoreError::param(
            "d_max",
            format!("must be > d_min ({d_min}), got {d_max}"),
        ));
    }
    let taps = gaussian_taps(p.win_sigma, p.win_radius);
    let ls = left_stats(left.data, right.data, w, h, &taps)?;
    let c0 = p.search;
    let fc = p.fill_search;
    let in_range = |v: f32| v >= d_min && v <= d_max;

    // Stage 1: re-measure every pixel with a value; NaN where the correlation disagrees.
    let base = nc_smooth(disp, w, h, p.base_sigma)?;
    let mut out = try_filled(w * h, f32::NAN, "the refinement's refined map")?;
    stage(
        &ls,
        right.data,
        &base,
        p,
        (p.search, p.step),
        &taps,
        w,
        h,
        &mut out,
        |i| disp[i].is_finite(),
        |i, z| {
            let (k, _) = peak(z)?;
            if k + 1 < c0 || k > c0 + 1 {
                return None;
            }
            let v = base[i] + p.step * parabola_offset(z[c0 - 1], z[c0], z[c0 + 1])?;
            in_range(v).then_some(v)
        },
    )?;
    let mut oconf = try_collect(
        out.len(),
        out.iter().zip(conf).map(|(v, c)| {
            if v.is_finite() {
                c.clamp(0.0, 1.0)
            } else {
                0.0
            }
        }),
        "the refinement's confidence map",
    )?;

    // Fill passes: holes near measured pixels, accepted on a clear correlation peak.
    let mut filled = 0usize;
    for f in &p.fills {
        let (base, resid) = if p.fill_plane {
            nc_plane(&out, w, h, f.sigma, p.fill_max_residual.is_finite())?
        } else {
            (nc_smooth(&out, w, h, f.sigma)?, Vec::new())
        };
        let planar = |i: usize| {
            !(p.fill_plane && p.fill_max_residual.is_finite()) || resid[i] < p.fill_max_residual
        };
        let before = try_collect(
            out.len(),
            out.iter().copied(),
            "the refinement's refined map",
        )?;
        stage(
            &ls,
            right.data,
            &base,
            p,
            (p.fill_search, p.fill_step),
            &taps,
            w,
            h,
            &mut out,
            |i| !before[i].is_finite() && base[i].is_finite() && planar(i),
            |i, z| {
                let (k, zk) = peak(z)?;
                // Within one shift of the start, and not at either end (a vertex needs both
                // neighbours; with search = 1 the ends are one shift away).
                if k + 1 < fc || k > fc + 1 || k == 0 || k + 1 == z.len() || zk < f.min_score {
                    return None;
                }
                let off = parabola_offset(z[k - 1], z[k], z[k + 1])?;
                let v = base[i] + p.fill_step * (k as f32 - fc as f32 + off);
                in_range(v).then_some(v)
            },
        )?;
        for i in 0..w * h {
            if out[i].is_finite() && !before[i].is_finite() {
                oconf[i] = p.fill_confidence;
                filled += 1;
            }
        }
    }
    Ok((out, oconf, filled))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_wider_than_the_image_sums_it_whole() {
        // A half-width of usize::MAX (box3_radius of a sigma of 1e19 px or more) wrapped
        // `x + b`: it must give what any box reaching past both ends gives.
        let (w, h) = (7, 5);
        let a: Vec<f64> = (0..w * h).map(|i| ((i * 37) % 11) as f64 - 3.0).collect();
        let whole = box3_zero(a.clone(), w, h, w.max(h), "test").unwrap();
        for b in [w.max(h) + 1, 1 << 40, usize::MAX / 2 + 1, usize::MAX] {
            assert_eq!(
                box3_zero(a.clone(), w, h, b, "test").unwrap(),
                whole,
                "b = {b}"
            );
        }
        assert_eq!(box3_radius(1e20), usize::MAX);
        let d: Vec<f32> = (0..w * h)
            .map(|i| if i % 3 == 0 { f32::NAN } else { i as f32 })
            .collect();
        let want = nc_smooth(&d, w, h, 1e6).unwrap();
        assert_eq!(nc_smooth(&d, w, h, 1e20).unwrap(), want);
        assert_eq!(nc_smooth(&d, w, h, f32::MAX).unwrap(), want);
        let (pw, rw) = nc_plane(&d, w, h, 1e6, true).unwrap();
        let (p, r) = nc_plane(&d, w, h, 1e20, true).unwrap();
        assert_eq!((p, r), (pw, rw));
    }

    #[test]
    fn column_strips_too_large_to_allocate_are_an_error() {
        // The strips were a `collect` and a `vec!`: a failed allocation aborted the process.
        let e = box3_zero(Vec::<f32>::new(), 64, 1 << 56, 1, "the test's strips").unwrap_err();
        assert!(matches!(
            e,
            CoreError::OutOfMemory {
                what: "the test's strips",
                ..
            }
        ));
    }

    #[test]
    fn band_buffers_too_large_to_allocate_are_an_error() {
        // They grew by `resize`: a failed allocation aborted the process.
        let mut sc = Scratch::default();
        assert!(matches!(
            sc.reserve(1 << 60, 33, 256, 1 << 20),
            Err(CoreError::OutOfMemory {
                what: "the refinement's band buffers",
                ..
            })
        ));
        sc.reserve(64, 5, 20, 8).unwrap();
        let cap = sc.z.capacity();
        assert!(cap >= 320);
        sized(&mut sc.z, 320);
        assert_eq!(sc.z.capacity(), cap);
    }

    #[test]
    fn window_mass_equals_the_window_sum_of_ones() {
        let taps = gaussian_taps(4.5, 9);
        for (w, h) in [(30, 40), (7, 5), (50, 19), (12, 18), (3, 1)] {
            let want = window_sum(&vec![1f32; w * h], w, h, &taps).unwrap();
            let got = window_mass(w, h, &taps).unwrap();
            assert!(
                want.iter()
                    .zip(&got)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{w}x{h}"
            );
        }
    }

    /// A textured pair with a known sub-pixel slanted disparity `d(x, y) = 6.3 + 0.01 y`.
    fn slanted_pair(w: usize, h: usize) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let tex = |x: f32, y: f32| {
            0.5 + 0.2 * (0.7 * x).sin() * (0.3 * y).cos() + 0.15 * (0.23 * x + 0.41 * y).sin()
        };
        let mut l = vec![0f32; w * h];
        let mut r = vec![0f32; w * h];
        let mut d = vec![0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let dd = 6.3 + 0.01 * y as f32;
                l[y * w + x] = tex(x as f32, y as f32);
                // right(x') = left(x' + d): a left pixel x matches right x - d.
                r[y * w + x] = tex(x as f32 + dd, y as f32);
                d[y * w + x] = dd;
            }
        }
        (l, r, d)
    }

    #[test]
    fn recovers_subpixel_disparity_from_a_rounded_start() {
        let (w, h) = (96, 64);
        let (l, r, d) = slanted_pair(w, h);
        let start: Vec<f32> = d.iter().map(|v| v.round()).collect();
        let conf = vec![1f32; w * h];
        let lv = ImageView::new(w, h, &l).unwrap();
        let rv = ImageView::new(w, h, &r).unwrap();
        let p = RefineParams::default();
        let (out, _, _) = refine_disparity(lv, rv, &start, &conf, 0.0, 16.0, &p).unwrap();
        let mut errs: Vec<f32> = (0..w * h)
            .filter(|&i| i % w > 20 && i % w < w - 10 && out[i].is_finite())
            .map(|i| (out[i] - d[i]).abs())
            .collect();
        assert!(errs.len() > (w - 30) * h * 9 / 10, "kept {}", errs.len());
        errs.sort_by(f32::total_cmp);
        let med = errs[errs.len() / 2];
        // The rounded start is off by up to 0.5 px (0.25 on average).
        assert!(med < 0.05, "median error {med}");
    }

    #[test]
    fn fills_a_hole_and_flat_pair_gives_nothing() {
        let (w, h) = (96, 64);
        let (l, r, d) = slanted_pair(w, h);
        let mut start = d.clone();
        for y in 20..40 {
            for x in 40..60 {
                start[y * w + x] = f32::NAN;
            }
        }
        let conf = vec![1f32; w * h];
        let lv = ImageView::new(w, h, &l).unwrap();
        let rv = ImageView::new(w, h, &r).unwrap();
        let (out, oc, filled) =
            refine_disparity(lv, rv, &start, &conf, 0.0, 16.0, &RefineParams::default()).unwrap();
        assert!(filled >= 350, "filled {filled}");
        let i = 30 * w + 50;
        assert!((out[i] - d[i]).abs() < 0.05, "{} vs {}", out[i], d[i]);
        assert_eq!(oc[i], 0.25);
        // A constant pair has no texture: every pixel becomes NaN, no error.
        let flat = vec![0.5f32; w * h];
        let fv = ImageView::new(w, h, &flat).unwrap();
        let (out, _, filled) =
            refine_disparity(fv, fv, &d, &conf, 0.0, 16.0, &RefineParams::default()).unwrap();
        assert!(out.iter().all(|v| v.is_nan()));
        assert_eq!(filled, 0);
    }

    #[test]
    fn rejects_bad_parameters_and_shapes() {
        let (w, h) = (8, 8);
        let a = vec![0.5f32; w * h];
        let v = ImageView::new(w, h, &a).unwrap();
        let p = RefineParams {
            win_sigma: 0.0,
            ..Default::default()
        };
        assert!(refine_disparity(v, v, &a, &a, 0.0, 4.0, &p).is_err());
        let short = vec![0f32; 3];
        assert!(refine_disparity(v, v, &short, &a, 0.0, 4.0, &RefineParams::default()).is_err());
        assert!(refine_disparity(v, v, &a, &a, 4.0, 4.0, &RefineParams::default()).is_err());
        // The smallest search (one shift each side) is valid, not a panic.
        let (l, r, d) = slanted_pair(48, 32);
        let (lv, rv) = (
            ImageView::new(48, 32, &l).unwrap(),
            ImageView::new(48, 32, &r).unwrap(),
        );
        let mut holes = d.clone();
        holes[16 * 48 + 20..16 * 48 + 30].fill(f32::NAN);
        let p = RefineParams {
            search: 1,
            ..Default::default()
        };
        let ones = vec![1f32; 48 * 32];
        assert!(refine_disparity(lv, rv, &holes, &ones, 0.0, 16.0, &p).is_ok());
    }

    #[test]
    fn plane_fit_is_exact_on_a_slanted_plane_with_holes() {
        let (w, h) = (40, 30);
        let mut d: Vec<f32> = (0..w * h)
            .map(|i| 3.0 + 0.25 * (i % w) as f32 - 0.4 * (i / w) as f32)
            .collect();
        for i in (0..w * h).filter(|i| (i * 7) % 5 == 0) {
            d[i] = f32::NAN;
        }
        let (plane, resid) = nc_plane(&d, w, h, 4.0, true).unwrap();
        for i in 0..w * h {
            let exact = 3.0 + 0.25 * (i % w) as f32 - 0.4 * (i / w) as f32;
            assert!(
                (plane[i] - exact).abs() < 1e-3,
                "{i}: {} vs {exact}",
                plane[i]
            );
            assert!(resid[i] < 1e-2, "{i}: residual {}", resid[i]);
        }
        // A step is not a plane: the residual says so at the edge.
        let step: Vec<f32> = (0..w * h)
            .map(|i| if i % w < 20 { 5.0 } else { 15.0 })
            .collect();
        let (_, r) = nc_plane(&step, w, h, 4.0, true).unwrap();
        assert!(r[15 * w + 20] > 2.0 && r[15 * w + 2] < 1e-3);
    }

    #[test]
    fn parabola_and_cubic_basics() {
        assert_eq!(parabola_offset(0.5, 1.0, 0.5), Some(0.0));
        assert!(parabola_offset(0.0, 0.5, 1.0).is_none()); // a slope, not a peak
        let off = parabola_offset(0.8, 1.0, 0.9).unwrap();
        assert!(off > 0.0 && off < 0.5);
        let row: Vec<f32> = (0..10).map(|i| i as f32).collect();
        assert!((cubic_sample(&row, 3.25) - 3.25).abs() < 1e-6); // exact on a line
        assert_eq!(cubic_sample(&row, 4.0), 4.0);
    }

    /// Three box sums of half-width `b` along x, then three along y, zero padding: the
    /// definition of [`box3_zero`], summed term by term.
    fn box3_direct(a: &[f64], w: usize, h: usize, b: usize) -> Vec<f64> {
        let pass = |src: &[f64], len: usize, lines: usize, at: &dyn Fn(usize, usize) -> usize| {
            let mut out = vec![0f64; w * h];
            for line in 0..lines {
                for i in 0..len {
                    let lo = i.saturating_sub(b);
                    let hi = (i + b).min(len - 1);
                    out[at(line, i)] = (lo..=hi).map(|j| src[at(line, j)]).sum();
                }
            }
            out
        };
        let mut v = a.to_vec();
        for _ in 0..3 {
            v = pass(&v, w, h, &|y, x| y * w + x);
        }
        for _ in 0..3 {
            v = pass(&v, h, w, &|x, y| y * w + x);
        }
        v
    }

    #[test]
    fn box3_zero_equals_the_direct_triple_box_sum() {
        // Small integers: every sum is exact in either order. 70 columns: two column strips;
        // 11 rows: two groups of four rows and a remainder of three.
        let (w, h) = (70, 11);
        let a: Vec<f64> = (0..w * h).map(|i| ((i * 7) % 13) as f64).collect();
        for b in [1, 2, 7] {
            let want = box3_direct(&a, w, h, b);
            assert_eq!(
                box3_zero(a.clone(), w, h, b, "t").unwrap(),
                want,
                "f64, b {b}"
            );
        }
        let a32: Vec<f32> = a.iter().map(|&v| v as f32).collect();
        let got: Vec<f64> = box3_zero(a32, w, h, 2, "t")
            .unwrap()
            .iter()
            .map(|&v| v as f64)
            .collect();
        assert_eq!(got, box3_direct(&a, w, h, 2), "f32");
    }

    #[test]
    fn box_radius_and_gaussian_taps_values() {
        // (2b + 1)^2 = 4 sigma^2 + 1 rounded: sigma 4 gives b = 3.53 -> 4, sigma 16 15.51 -> 16.
        assert_eq!(
            [0.1, 1.0, 2.0, 4.0, 16.0].map(box3_radius),
            [1, 1, 2, 4, 16]
        );
        let g = gaussian_taps(2.0, 2);
        let want = [
            (-0.5f32).exp(),
            (-0.125f32).exp(),
            1.0,
            (-0.125f32).exp(),
            (-0.5f32).exp(),
        ];
        assert_eq!(g, want);
    }

    #[test]
    fn a_single_value_reaches_the_three_boxes_extent() {
        // One value at (10, 10), b = 1: three boxes reach 3 px in x and y (the corner with
        // weight 1 * 1), and both smoothings give the value itself there, NaN beyond.
        let (w, h) = (25, 25);
        let mut d = vec![f32::NAN; w * h];
        d[10 * w + 10] = 3.0;
        let s = nc_smooth(&d, w, h, 1.0).unwrap();
        let (pl, res) = nc_plane(&d, w, h, 1.0, true).unwrap();
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let near = x.abs_diff(10) <= 3 && y.abs_diff(10) <= 3;
                if near {
                    assert_eq!((s[i], pl[i], res[i]), (3.0, 3.0, 0.0), "({x}, {y})");
                } else {
                    assert!(
                        s[i].is_nan() && pl[i].is_nan() && res[i].is_nan(),
                        "({x}, {y})"
                    );
                }
            }
        }
    }

    /// Weighted least-squares plane at pixel `(x, y)` with the three-box kernel, by direct sums
    /// (f64): the definition of [`nc_plane`]'s value and RMS residual.
    fn plane_direct(d: &[f32], w: usize, h: usize, b: usize, x: usize, y: usize) -> (f64, f64) {
        // The 1-D weight of sample q at p: three boxes of 2b + 1 ones, each pass zero-padded
        // (a path through a position outside the image counts for nothing), so near a border
        // it is not the full kernel cut off.
        let k1 = |n: usize, p: i64, q: i64| -> f64 {
            let mut v = vec![0f64; n];
            v[q as usize] = 1.0;
            for _ in 0..3 {
                v = (0..n)
                    .map(|i| {
                        (i.saturating_sub(b)..=(i + b).min(n - 1))
                            .map(|j| v[j])
                            .sum()
                    })
                    .collect();
            }
            v[p as usize]
        };
        let r = 3 * b as i64;
        let mut m = [[0f64; 3]; 3];
        let mut v = [0f64; 3];
        let mut pts = Vec::new();
        for dy in -r..=r {
            for dx in -r..=r {
                let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                if xx < 0 || yy < 0 || xx >= w as i64 || yy >= h as i64 {
                    continue;
                }
                let val = d[yy as usize * w + xx as usize];
                if !val.is_finite() {
                    continue;
                }
                let g = k1(w, x as i64, xx) * k1(h, y as i64, yy);
                let row = [1.0, dx as f64, dy as f64];
                for i in 0..3 {
                    for j in 0..3 {
                        m[i][j] += g * row[i] * row[j];
                    }
                    v[i] += g * row[i] * val as f64;
                }
                pts.push((g, dx as f64, dy as f64, val as f64));
            }
        }
        // Gaussian elimination (the test maps fix a plane everywhere).
        for c in 0..3 {
            for rr in c + 1..3 {
                let (pivot, f) = (m[c], m[rr][c] / m[c][c]);
                for (a, p) in m[rr].iter_mut().zip(pivot).skip(c) {
                    *a -= f * p;
                }
                v[rr] -= f * v[c];
            }
        }
        let mut s = [0f64; 3];
        for c in (0..3).rev() {
            let t: f64 = (c + 1..3).map(|k| m[c][k] * s[k]).sum();
            s[c] = (v[c] - t) / m[c][c];
        }
        let (mut e2, mut g0) = (0f64, 0f64);
        for (g, dx, dy, val) in pts {
            let e = val - (s[0] + s[1] * dx + s[2] * dy);
            e2 += g * e * e;
            g0 += g;
        }
        (s[0], (e2 / g0).sqrt())
    }

    #[test]
    fn plane_fit_and_residual_equal_the_direct_weighted_fit() {
        let (w, h) = (23, 19);
        let d: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                if (i * 11) % 7 == 0 {
                    f32::NAN
                } else {
                    4.0 + 0.3 * x - 0.2 * y + (0.9 * x).sin() * (0.5 * y).cos()
                }
            })
            .collect();
        let b = box3_radius(2.0);
        let (pl, res) = nc_plane(&d, w, h, 2.0, true).unwrap();
        for (x, y) in [(0, 0), (22, 18), (11, 9), (3, 17), (20, 2), (7, 7)] {
            let (a, rms) = plane_direct(&d, w, h, b, x, y);
            let i = y * w + x;
            assert!(
                (pl[i] as f64 - a).abs() < 1e-4,
                "({x}, {y}): {} vs {a}",
                pl[i]
            );
            assert!(
                (res[i] as f64 - rms).abs() < 1e-4,
                "({x}, {y}): {} vs {rms}",
                res[i]
            );
            assert!(rms > 0.1, "({x}, {y}): the map is not one plane there");
        }
        // Positions on one line (a single row) fix no plane: the flat weighted mean (at x = 0,
        // b = 1: weights 4 5 3 1 on the values 0 1 2 3).
        let row: Vec<f32> = (0..w).map(|x| x as f32).collect();
        let (pl, _) = nc_plane(&row, w, 1, 1.0, false).unwrap();
        assert!((pl[0] - 14.0 / 13.0).abs() < 1e-6, "{}", pl[0]);
        // Nearly one line: a diagonal and one pixel beside it, all on d = x + y, still fix
        // that plane (poorly conditioned, not degenerate); the far corner gets x + y.
        let n = 40;
        let mut diag = vec![f32::NAN; n * n];
        for x in 0..n {
            diag[x * n + x] = 2.0 * x as f32;
        }
        diag[21 * n + 20] = 41.0;
        let (pl, res) = nc_plane(&diag, n, n, 16.0, true).unwrap();
        let i = (n - 1) * n;
        assert!((pl[i] - 39.0).abs() < 1e-3, "{}", pl[i]);
        assert!(res[i] < 1e-2, "{}", res[i]);
    }

    #[test]
    fn cubic_sample_is_catmull_rom_with_clamped_ends() {
        let row: Vec<f32> = (0..10).map(|i| ((i * i) % 7) as f32).collect();
        let at = |i: i64| row[i.clamp(0, 9) as usize] as f64;
        for t in [0.0f32, 0.3, 2.75, 5.5, 7.9, 8.5, 8.99, 9.0] {
            let i = t.floor() as i64;
            let f = (t - t.floor()) as f64;
            let (p0, p1, p2, p3) = (at(i - 1), at(i), at(i + 1), at(i + 2));
            let want = 0.5
                * (2.0 * p1
                    + (p2 - p0) * f
                    + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * f * f
                    + (3.0 * p1 - p0 - 3.0 * p2 + p3) * f * f * f);
            let got = cubic_sample(&row, t) as f64;
            assert!((got - want).abs() < 1e-5, "t {t}: {got} vs {want}");
        }
    }

    #[test]
    fn cubic_sample_reads_an_end_from_a_whole_sample_past_it() {
        // Half a sample past an end the clamped indices still weigh its neighbour: 5.25 and
        // 3.125, not the ends' 5 and 3; from a whole sample on, the end up to rounding.
        let row = [3.0f32, 1.0, 4.0, 1.0, 5.0];
        assert_eq!(cubic_sample(&row, 4.5), 5.25);
        assert_eq!(cubic_sample(&row, -0.5), 3.125);
        for k in 0..=60 {
            let t = k as f32 * 0.05;
            let (hi, lo) = (cubic_sample(&row, 5.0 + t), cubic_sample(&row, -1.0 - t));
            assert!((hi - 5.0).abs() <= 5.0 * f32::EPSILON, "t {} {hi}", 5.0 + t);
            assert!(
                (lo - 3.0).abs() <= 3.0 * f32::EPSILON,
                "t {} {lo}",
                -1.0 - t
            );
        }
    }

    #[test]
    fn cubic_sample_far_past_the_row_reads_its_end() {
        // The i32 index saturated and `i + 2` / `i - 1` overflowed: a panic in a debug build,
        // an index past the row in a release build.
        let row = [3.0f32, 1.0, 4.0, 1.0, 5.0];
        for t in [-2.5f32, -1e3, -3e9, -1e30, f32::MIN] {
            assert_eq!(cubic_sample(&row, t), 3.0, "t {t}");
        }
        for t in [6.5f32, 1e3, 3e9, 1e30, f32::MAX] {
            assert_eq!(cubic_sample(&row, t), 5.0, "t {t}");
        }
    }

    /// ZNCC of the left window and the warped right window at `(x, y)`, shift `s`, by direct
    /// Gaussian-weighted sums (f64): the definition [`zncc_band`] computes. None where the
    /// kernel's NaN rules apply; Some(None) where `vl` or `vr` is too close to the floor for
    /// f32 and f64 to agree on the side.
    #[allow(clippy::too_many_arguments)]
    fn zncc_direct(
        l: &[f32],
        r: &[f32],
        base: &[f32],
        taps: &[f32],
        floor: f32,
        means: (f64, f64),
        (w, h): (usize, usize),
        (x, y): (usize, usize),
        s: f32,
    ) -> Option<Option<f64>> {
        // Both images centred on their means (as the kernel; ZNCC does not see them).
        let (lm, rm) = means;
        let rad = (taps.len() / 2) as i64;
        let (mut m, mut s1, mut s2, mut t1, mut t2, mut st) = (0f64, 0f64, 0f64, 0f64, 0f64, 0f64);
        for dy in -rad..=rad {
            for dx in -rad..=rad {
                let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                if xx < 0 || yy < 0 || xx >= w as i64 || yy >= h as i64 {
                    continue;
                }
                let (xx, yy) = (xx as usize, yy as usize);
                let g = taps[(dx + rad) as usize] as f64 * taps[(dy + rad) as usize] as f64;
                let lv = l[yy * w + xx] as f64 - lm;
                let b = base[yy * w + xx];
                let rv = if b.is_finite() {
                    let row = &r[yy * w..(yy + 1) * w];
                    cubic_sample(row, xx as f32 - b - s) as f64 - rm
                } else {
                    0.0
                };
                m += g;
                s1 += g * lv;
                s2 += g * lv * lv;
                t1 += g * rv;
                t2 += g * rv * rv;
                st += g * lv * rv;
            }
        }
        let t = x as f32 - base[y * w + x] - s;
        if !(t >= 0.0 && t <= (w - 1) as f32) {
            return None;
        }
        let (ml, mr) = (s1 / m, t1 / m);
        let (vl, vr) = (s2 / m - ml * ml, t2 / m - mr * mr);
        let f = floor as f64;
        if (vl - f).abs() < 1e-6 || (vr - f).abs() < 1e-6 {
            return Some(None);
        }
        if vl <= f || vr <= f {
            return None;
        }
        Some(Some((st / m - ml * mr) / (vl * vr).sqrt()))
    }

    #[test]
    fn band_correlations_equal_the_direct_window_sums() {
        // 140 rows: two bands (the second's window reaches into the first); 43 columns: the
        // eight-lane sums' tail too. Rows of three kinds
        // of base: a slant, a negative disparity (both borders in reach), holes. A patch of the
        // right image has almost no contrast (under the variance floor).
        let (w, h) = (43, 140);
        let tex = |x: f32, y: f32| {
            0.3 + 0.4 * x / 40.0
                + 0.2 * (0.7 * x + 0.2 * y).sin() * (0.3 * y).cos()
                + 0.1 * (1.9 * x - 0.4 * y).sin()
        };
        let mut l = vec![0f32; w * h];
        let mut r = vec![0f32; w * h];
        let mut base = vec![0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                l[i] = tex(x as f32, y as f32);
                r[i] = if (20..28).contains(&x) && (60..80).contains(&y) {
                    0.5 + 0.01 * (0.9 * x as f32).sin()
                } else {
                    tex(x as f32 + 5.0, y as f32) + 0.05 * (y as f32).sin()
                };
                base[i] = match y % 3 {
                    0 => 5.2 + 0.01 * y as f32,
                    // A whole-pixel base: t = x + 1 - s lands on 0 and on w - 1 exactly
                    // (s = 1), both inside.
                    1 if y % 2 == 0 => -1.0,
                    1 => -0.6,
                    _ if x % 7 == 3 => f32::NAN,
                    _ => 4.7,
                };
            }
        }
        let taps = gaussian_taps(1.5, 3);
        let p = RefineParams {
            var_floor: 1e-3,
            ..Default::default()
        };
        let ls = left_stats(&l, &r, w, h, &taps).unwrap();
        let (search, step) = (2usize, 0.5f32);
        let n_s = 2 * search + 1;
        let means = (image_mean(&l) as f64, image_mean(&r) as f64);
        let mut sc = Scratch::default();
        let (mut checked, mut nan) = (0, 0);
        for (y0, y1) in [(0, BAND), (BAND, h)] {
            zncc_band(
                &mut sc,
                &ls,
                &r,
                &base,
                &p,
                (search, step),
                &taps,
                w,
                h,
                y0,
                y1,
            )
            .unwrap();
            let band_len = (y1 - y0) * w;
            for y in y0..y1 {
                for x in 0..w {
                    for k in 0..n_s {
                        let s = (k as f32 - search as f32) * step;
                        let got = sc.z[k * band_len + (y - y0) * w + x];
                        match zncc_direct(
                            &l,
                            &r,
                            &base,
                            &taps,
                            p.var_floor,
                            means,
                            (w, h),
                            (x, y),
                            s,
                        ) {
                            None => {
                                assert!(got.is_nan(), "({x}, {y}) s {s}: {got}, want NaN");
                                nan += 1;
                            }
                            Some(None) => {}
                            Some(Some(want)) => {
                                assert!(
                                    (got as f64 - want).abs() < 1e-3,
                                    "({x}, {y}) s {s}: {got} vs {want}"
                                );
                                checked += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(
            checked > 10_000 && nan > 3_000,
            "{checked} values, {nan} NaN"
        );
    }

    /// A pair whose left image sees the texture at disparity `d(x, y)`: `L(x) = T(x - d)`,
    /// `R = T` (occlusions ignored), with the slanted pair's texture.
    fn pair_of(d: &[f32], w: usize, h: usize) -> (Vec<f32>, Vec<f32>) {
        let tex = |x: f32, y: f32| {
            0.5 + 0.2 * (0.7 * x).sin() * (0.3 * y).cos() + 0.15 * (0.23 * x + 0.41 * y).sin()
        };
        let l = (0..w * h)
            .map(|i| tex((i % w) as f32 - d[i], (i / w) as f32))
            .collect();
        let r = (0..w * h)
            .map(|i| tex((i % w) as f32, (i / w) as f32))
            .collect();
        (l, r)
    }

    fn run(
        l: &[f32],
        r: &[f32],
        start: &[f32],
        conf: &[f32],
        (w, h): (usize, usize),
        range: (f32, f32),
        p: &RefineParams,
    ) -> (Vec<f32>, Vec<f32>, usize) {
        let lv = ImageView::new(w, h, l).unwrap();
        let rv = ImageView::new(w, h, r).unwrap();
        refine_disparity(lv, rv, start, conf, range.0, range.1, p).unwrap()
    }

    #[test]
    fn refine_keeps_only_a_central_peak_in_range_with_every_shift_defined() {
        let (w, h) = (96, 64);
        let (l, r, d) = slanted_pair(w, h);
        let ones = vec![1f32; w * h];
        let p = RefineParams {
            fills: vec![],
            ..Default::default()
        };
        // A start a whole pixel off puts the peak two half-pixel shifts away: rejected, not
        // moved half-way.
        let off: Vec<f32> = d.iter().map(|v| v + 1.0).collect();
        let (out, _, _) = run(&l, &r, &off, &ones, (w, h), (0.0, 16.0), &p);
        let kept = out.iter().filter(|v| v.is_finite()).count();
        assert!(kept < w * h / 50, "kept {kept}");
        // Values outside [d_min, d_max] become NaN (the truth is 6.3..6.93).
        let (out, _, _) = run(&l, &r, &d, &ones, (w, h), (0.0, 6.0), &p);
        assert!(out.iter().all(|v| v.is_nan()));
        // Column 7: the shift +1 looks left of the right image (t = 7 - 6.3 - 1 < 0), so no
        // peak is known there; column 9 has every shift.
        let conf: Vec<f32> = (0..w * h)
            .map(|i| if i % 2 == 0 { 2.0 } else { -1.0 })
            .collect();
        let (out, oc, _) = run(&l, &r, &d, &conf, (w, h), (0.0, 16.0), &p);
        assert!((0..h).all(|y| out[y * w + 7].is_nan()));
        assert!((0..h).filter(|y| out[y * w + 9].is_finite()).count() > h / 2);
        // The confidence is clamped to [0, 1] where a value is kept, 0 elsewhere.
        for i in 0..w * h {
            let want = if out[i].is_nan() {
                0.0
            } else {
                conf[i].clamp(0.0, 1.0)
            };
            assert_eq!(oc[i], want, "{i}");
        }
    }

    #[test]
    fn a_fill_keeps_the_measured_pixels_and_reaches_by_its_own_sigma() {
        // A 48 x 48 hole: its centre lies 24 px from any value, beyond the base smoothing's
        // reach (b = 4, 12 px) and within the fill pass's (sigma 16: b = 16, 48 px).
        let (w, h) = (96, 64);
        let (l, r, d) = slanted_pair(w, h);
        let mut start = d.clone();
        for y in 8..56 {
            start[y * w + 24..y * w + 72].fill(f32::NAN);
        }
        let ones = vec![1f32; w * h];
        let bare = RefineParams {
            fills: vec![],
            ..Default::default()
        };
        let (refined, _, none) = run(&l, &r, &start, &ones, (w, h), (0.0, 16.0), &bare);
        assert_eq!(none, 0);
        let centre = 32 * w + 48;
        for (plane, max_residual) in [(true, f32::INFINITY), (true, 0.5), (false, f32::INFINITY)] {
            let p = RefineParams {
                fill_plane: plane,
                fill_max_residual: max_residual,
                ..Default::default()
            };
            let (out, oc, filled) = run(&l, &r, &start, &ones, (w, h), (0.0, 16.0), &p);
            let what = format!("plane {plane}, max_residual {max_residual}");
            assert!(
                (out[centre] - d[centre]).abs() < 0.05,
                "{what}: {}",
                out[centre]
            );
            // Measured pixels keep their refined values; every new value is counted.
            let mut new = 0;
            for i in 0..w * h {
                if refined[i].is_finite() {
                    assert_eq!(out[i].to_bits(), refined[i].to_bits(), "{what}: {i}");
                } else if out[i].is_finite() {
                    assert_eq!(oc[i], 0.25);
                    new += 1;
                }
            }
            assert_eq!(new, filled, "{what}");
        }
    }

    #[test]
    fn a_fill_takes_a_peak_one_shift_away_and_no_farther() {
        // A block 1 (or 2) px nearer than the surface around it, with no values: the fill
        // starts from the surface's plane (6.3) and finds the block's peak one shift away (or
        // two: beyond |k| <= 1 even with fill_search 3).
        let (w, h) = (96, 64);
        let inside = |i: usize| (36..68).contains(&(i % w)) && (16..48).contains(&(i / w));
        let interior = |i: usize| (46..58).contains(&(i % w)) && (26..38).contains(&(i / w));
        let ones = vec![1f32; w * h];
        for (gap, fill_search) in [(1.0f32, 2usize), (2.0, 3)] {
            let d: Vec<f32> = (0..w * h)
                .map(|i| if inside(i) { 6.3 - gap } else { 6.3 })
                .collect();
            let (l, r) = pair_of(&d, w, h);
            let start: Vec<f32> = (0..w * h)
                .map(|i| if inside(i) { f32::NAN } else { d[i] })
                .collect();
            let p = RefineParams {
                fill_search,
                ..Default::default()
            };
            let (out, _, _) = run(&l, &r, &start, &ones, (w, h), (0.0, 16.0), &p);
            let cells: Vec<usize> = (0..w * h).filter(|&i| interior(i)).collect();
            let got: Vec<f32> = cells.iter().map(|&i| out[i]).collect();
            if gap == 1.0 {
                assert!(
                    got.iter().all(|v| (v - 5.3).abs() < 0.1),
                    "one shift: {got:?}"
                );
            } else {
                assert!(got.iter().all(|v| v.is_nan()), "two shifts: {got:?}");
            }
        }
    }

    #[test]
    fn a_fill_needs_its_correlation_to_reach_min_score() {
        // The right image's texture is replaced by an unrelated one in a block: the block's
        // holes have no correlation peak worth min_score, and stay holes.
        let (w, h) = (96, 64);
        let (l, mut r, d) = slanted_pair(w, h);
        let block = |i: usize| (30..70).contains(&(i % w)) && (12..52).contains(&(i / w));
        let mut state = 7u64;
        for i in (0..w * h).filter(|&i| block(i)) {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            r[i] = ((state >> 40) % 1000) as f32 / 1000.0;
        }
        let start: Vec<f32> = (0..w * h)
            .map(|i| if block(i) { f32::NAN } else { d[i] })
            .collect();
        let ones = vec![1f32; w * h];
        let (out, _, _) = run(
            &l,
            &r,
            &start,
            &ones,
            (w, h),
            (0.0, 16.0),
            &RefineParams::default(),
        );
        let inner = |i: usize| (42..62).contains(&(i % w)) && (22..42).contains(&(i / w));
        let n = (0..w * h)
            .filter(|&i| inner(i) && out[i].is_finite())
            .count();
        assert_eq!(n, 0);
    }

    #[test]
    fn parameter_bounds_are_inclusive_where_documented() {
        let ok = |p: RefineParams| p.validate().is_ok();
        let d = RefineParams::default;
        assert!(ok(RefineParams {
            search: 16,
            fill_search: 1,
            win_radius: 64,
            ..d()
        }));
        assert!(!ok(RefineParams { search: 0, ..d() }));
        assert!(!ok(RefineParams {
            fill_search: 17,
            ..d()
        }));
        assert!(!ok(RefineParams {
            win_radius: 65,
            ..d()
        }));
        assert!(ok(RefineParams {
            fill_confidence: 1.0,
            ..d()
        }));
        assert!(!ok(RefineParams {
            fill_confidence: 1.01,
            ..d()
        }));
        let pass = |min_score: f32| RefineParams {
            fills: vec![FillPass {
                sigma: 8.0,
                min_score,
            }],
            ..d()
        };
        assert!(ok(pass(-0.99)) && ok(pass(0.99)));
        assert!(!ok(pass(-1.0)) && !ok(pass(1.0)));
        // fill_max_residual: > 0, so 0 is refused and the smallest positive is taken.
        assert!(!ok(RefineParams {
            fill_max_residual: 0.0,
            ..d()
        }));
        assert!(ok(RefineParams {
            fill_max_residual: f32::MIN_POSITIVE,
            ..d()
        }));
    }

    #[test]
    fn peak_parabola_and_mean_edge_values() {
        // The first of equal maxima; any NaN or infinite shift: no peak.
        assert_eq!(peak(&[0.5, 1.0, 1.0, 0.2]), Some((1, 1.0)));
        assert_eq!(peak(&[-0.5, -0.2, -0.2]), Some((1, -0.2)));
        assert_eq!(peak(&[0.5, f32::NAN, 1.0]), None);
        assert_eq!(peak(&[0.5, f32::NEG_INFINITY, 1.0]), None);
        // A weak peak (curvature -0.002) is still a peak; a flat top is not.
        assert_eq!(parabola_offset(0.0, 0.001, 0.0), Some(0.0));
        assert_eq!(parabola_offset(0.5, 0.5, 0.5), None);
        // The documented threshold: curvature -8e-7 (>= -1e-6) is no peak, -1.2e-6 is one.
        assert_eq!(parabola_offset(0.0, 4e-7, 0.0), None);
        assert_eq!(parabola_offset(0.0, 6e-7, 0.0), Some(0.0));
        // The offset is the vertex's: peak 0.25 to the right, and clamped to one shift.
        assert_eq!(parabola_offset(0.0, 1.0, 0.5), Some(0.5 * -0.5 / -1.5));
        assert_eq!(parabola_offset(0.0, 0.5, 0.999), Some(1.0));
        assert_eq!(parabola_offset(0.999, 0.5, 0.0), Some(-1.0));
        // The mean of an image (0 for none).
        assert_eq!(image_mean(&[1.0, 2.0, 3.0, 6.0]), 3.0);
        assert_eq!(image_mean(&[]), 0.0);
    }

    #[test]
    fn refine_takes_a_peak_one_shift_either_side_of_the_start() {
        // A fronto-parallel surface at 6.3 started half a pixel off either way: the peak lies
        // one shift (0.5) from the centre and is taken, moved towards the truth.
        let (w, h) = (64, 48);
        let d = vec![6.3f32; w * h];
        let (l, r) = pair_of(&d, w, h);
        let ones = vec![1f32; w * h];
        let p = RefineParams {
            fills: vec![],
            ..Default::default()
        };
        for off in [0.5f32, -0.5] {
            let start: Vec<f32> = d.iter().map(|v| v + off).collect();
            let (out, _, _) = run(&l, &r, &start, &ones, (w, h), (0.0, 16.0), &p);
            for y in 12..36 {
                for x in 16..48 {
                    let v = out[y * w + x];
                    assert!((v - 6.3).abs() < 0.25, "start {off:+}: ({x}, {y}) {v}");
                }
            }
        }
    }

    #[test]
    fn the_range_is_inclusive_at_both_ends() {
        // A range equal to the values' own extent keeps every one of them.
        let (w, h) = (96, 64);
        let (l, r, d) = slanted_pair(w, h);
        let mut start = d.clone();
        for y in 20..44 {
            start[y * w + 36..y * w + 60].fill(f32::NAN);
        }
        let ones = vec![1f32; w * h];
        let p = RefineParams::default();
        let (out, _, filled) = run(&l, &r, &start, &ones, (w, h), (0.0, 16.0), &p);
        assert!(filled > 100, "filled {filled}");
        let vals = out.iter().filter(|v| v.is_finite());
        let lo = vals.clone().fold(f32::INFINITY, |a, &v| a.min(v));
        let hi = vals.fold(f32::NEG_INFINITY, |a, &v| a.max(v));
        let (again, _, n) = run(&l, &r, &start, &ones, (w, h), (lo, hi), &p);
        assert_eq!(n, filled);
        let bits = |a: &[f32]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&again), bits(&out));
    }

    #[test]
    fn a_fill_search_of_one_takes_no_peak_at_its_ends() {
        // fill_search 1 has the shifts -1, 0, 1: a block one pixel nearer peaks at the end
        // (k = 0), where no parabola fits; it stays a hole.
        let (w, h) = (96, 64);
        let inside = |i: usize| (36..68).contains(&(i % w)) && (16..48).contains(&(i / w));
        let interior = |i: usize| (46..58).contains(&(i % w)) && (26..38).contains(&(i / w));
        let ones = vec![1f32; w * h];
        for gap in [1.0f32, -1.0] {
            let d: Vec<f32> = (0..w * h)
                .map(|i| if inside(i) { 6.3 - gap } else { 6.3 })
                .collect();
            let (l, r) = pair_of(&d, w, h);
            let start: Vec<f32> = (0..w * h)
                .map(|i| if inside(i) { f32::NAN } else { d[i] })
                .collect();
            let p = RefineParams {
                fill_search: 1,
                ..Default::default()
            };
            let (out, _, _) = run(&l, &r, &start, &ones, (w, h), (0.0, 16.0), &p);
            assert!(
                (0..w * h).filter(|&i| interior(i)).all(|i| out[i].is_nan()),
                "gap {gap}"
            );
        }
    }

    #[test]
    fn every_band_row_and_the_last_pixel_are_refined() {
        // 130 rows: two bands of rows (128 + 2); the only hole is the last pixel, the one
        // pixel of the fill's work. Its confidence is fill_confidence's.
        let (w, h) = (40, 130);
        let (l, r, d) = slanted_pair(w, h);
        let mut start = d.clone();
        start[w * h - 1] = f32::NAN;
        let ones = vec![1f32; w * h];
        let p = RefineParams {
            fill_confidence: 0.6,
            ..Default::default()
        };
        let (out, oc, filled) = run(&l, &r, &start, &ones, (w, h), (0.0, 16.0), &p);
        for y in [0, 126, 127, 128, 129] {
            let i = y * w + 20;
            assert!(
                (out[i] - d[i]).abs() < 0.05,
                "row {y}: {} vs {}",
                out[i],
                d[i]
            );
        }
        let last = w * h - 1;
        assert_eq!(filled, 1);
        assert!(
            (out[last] - d[last]).abs() < 0.1,
            "{} vs {}",
            out[last],
            d[last]
        );
        assert_eq!(oc[last], 0.6);
        // A start with one value, the last pixel: the second band's only work in stage 1.
        let mut one = vec![f32::NAN; w * h];
        one[last] = d[last];
        let bare = RefineParams {
            fills: vec![],
            ..Default::default()
        };
        let (out, _, _) = run(&l, &r, &one, &ones, (w, h), (0.0, 16.0), &bare);
        assert!(
            (out[last] - d[last]).abs() < 0.1,
            "{} vs {}",
            out[last],
            d[last]
        );
    }

    #[test]
    fn an_infinite_start_value_is_a_hole_as_nan_is() {
        let (w, h) = (96, 64);
        let (l, r, d) = slanted_pair(w, h);
        let mut nan = d.clone();
        let mut inf = d.clone();
        for y in 20..44 {
            for x in 30..60 {
                nan[y * w + x] = f32::NAN;
                inf[y * w + x] = if x % 2 == 0 { f32::INFINITY } else { f32::NAN };
            }
        }
        let ones = vec![1f32; w * h];
        let p = RefineParams::default();
        let (a, ca, na) = run(&l, &r, &nan, &ones, (w, h), (0.0, 16.0), &p);
        let (b, cb, nb) = run(&l, &r, &inf, &ones, (w, h), (0.0, 16.0), &p);
        let bits = |a: &[f32]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert!(na > 100, "filled {na}");
        assert_eq!((bits(&a), bits(&ca), na), (bits(&b), bits(&cb), nb));
    }
}
