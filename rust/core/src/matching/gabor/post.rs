//! Image-domain helpers of the matcher: normalised convolution, median, up-sampling, LR check.

// Row kernels index several equally long rows in lockstep; index loops are the clearest form
// and the one LLVM vectorises once the slices are re-bounded to the row length.
#![allow(clippy::needless_range_loop)]

use super::filter::{blur_real, gaussian_taps, radius_for};
use super::pool::Buf;
use crate::alloc::{try_collect, try_filled, try_reserve_len, try_zeroed};
use crate::error::Result;
use crate::parallel::for_each_row;
use crate::simd::simd_fn;

/// Normalised-convolution smoothing (A.5 step 3h): `cbar = G * c`, `dbar = G * (c d) / cbar`.
pub fn normalized_conv(
    delta: &[f32],
    conf: &[f32],
    w: usize,
    h: usize,
    sigma: f32,
) -> Result<(Buf, Buf)> {
    let g = gaussian_taps(sigma, radius_for(sigma));
    // The pointwise passes run in row bands too (serial, they idled the other core).
    let mut cd = Buf::scratch(w * h)?;
    for_each_row(&mut cd, w, |y, row| {
        let (d, c) = (&delta[y * w..(y + 1) * w], &conf[y * w..(y + 1) * w]);
        for ((o, d), c) in row.iter_mut().zip(d).zip(c) {
            *o = d * c;
        }
    });
    let cbar = blur_real(conf, w, h, &g, &g)?;
    let mut dbar = blur_real(&cd, w, h, &g, &g)?;
    for_each_row(&mut dbar, w, |y, row| {
        for (n, c) in row.iter_mut().zip(&cbar[y * w..(y + 1) * w]) {
            *n = if *c > NC_EPS { *n / c } else { 0.0 };
        }
    });
    Ok((dbar, cbar))
}

/// Denominator floor of the normalised convolution (A.5 step 3h).
const NC_EPS: f32 = 1e-6;

#[inline(always)]
fn cas(a: &mut f32, b: &mut f32) {
    let (lo, hi) = (a.min(*b), a.max(*b));
    *a = lo;
    *b = hi;
}

/// Median of five (branch-free compare-and-swap network).
#[inline(always)]
fn med5(mut a: f32, mut b: f32, mut c: f32, mut d: f32, mut e: f32) -> f32 {
    cas(&mut a, &mut b);
    cas(&mut d, &mut e);
    cas(&mut a, &mut d);
    cas(&mut b, &mut e);
    cas(&mut b, &mut c);
    cas(&mut c, &mut d);
    cas(&mut b, &mut c);
    c
}

/// Separable 5x5 median (5x1 median of the 1x5 medians), clamped borders. Cheaper than the exact
/// 5x5 median (two 5-networks instead of a 25-sort) with the same job here: removing isolated
/// disparity outliers after each Newton step.
pub fn median5(src: &[f32], w: usize, h: usize) -> Result<Buf> {
    let mut tmp = Buf::scratch(w * h)?;
    for_each_row(&mut tmp, w, |y, row| {
        median5_h(&src[y * w..(y + 1) * w], row)
    });
    let mut out = Buf::scratch(w * h)?;
    for_each_row(&mut out, w, |y, row| {
        let r = |dy: isize| {
            let yy = (y as isize + dy).clamp(0, h as isize - 1) as usize;
            &tmp[yy * w..(yy + 1) * w]
        };
        median5_v([r(-2), r(-1), r(0), r(1), r(2)], row)
    });
    Ok(out)
}

/// Radius of the median window (5 taps).
const MED_R: usize = 2;

simd_fn! {
    /// 1x5 median of one row, clamped borders (a padded copy keeps the loop branch-free).
    fn median5_h(s: &[f32], row: &mut [f32]) {
        let w = s.len();
        let mut pad = vec![0f32; w + 2 * MED_R];
        pad[MED_R..MED_R + w].copy_from_slice(s);
        for i in 0..MED_R {
            pad[i] = s[0];
            pad[MED_R + w + i] = s[w - 1];
        }
        let (a, b, c, d, e) = (&pad[..w], &pad[1..w + 1], &pad[2..w + 2], &pad[3..w + 3], &pad[4..w + 4]);
        let row = &mut row[..w];
        for x in 0..w {
            row[x] = med5(a[x], b[x], c[x], d[x], e[x]);
        }
    }
}

simd_fn! {
    /// 5x1 median of five rows.
    fn median5_v(rows: [&[f32]; 5], row: &mut [f32]) {
        let w = row.len();
        let [a, b, c, d, e] = rows;
        let (a, b, c, d, e) = (&a[..w], &b[..w], &c[..w], &d[..w], &e[..w]);
        for x in 0..w {
            row[x] = med5(a[x], b[x], c[x], d[x], e[x]);
        }
    }
}

/// Up-samples a coarse map to `(w, h)` (pixel `x` at the fine level is `x / 2` at the coarse one),
/// multiplying values by `scale` (2 for disparities, 1 for confidences). Bilinear, clamped to the
/// coarse image: fine pixels fall on coarse samples or half-way between two, so each output row
/// blends two x-interpolated coarse rows with the weights 0 or 1/2 (no per-pixel `floor`).
pub fn upsample(src: &[f32], sw: usize, sh: usize, w: usize, h: usize, scale: f32) -> Result<Buf> {
    let mut out = Buf::scratch(w * h)?;
    if sw == 0 || sh == 0 {
        out.iter_mut().for_each(|v| *v = 0.0);
        return Ok(out);
    }
    for_each_row(&mut out, w, |y, row| {
        let y0 = (y / 2).min(sh - 1);
        let y1 = (y0 + 1).min(sh - 1);
        let ty = if y % 2 == 1 && y / 2 < sh - 1 {
            0.5
        } else {
            0.0
        };
        upsample_row(
            &src[y0 * sw..(y0 + 1) * sw],
            &src[y1 * sw..(y1 + 1) * sw],
            ty,
            scale,
            row,
        )
    });
    Ok(out)
}

simd_fn! {
    /// One output row of [`upsample`]: `scale (a + ty (b - a))` with `a`, `b` the coarse rows
    /// `s0`, `s1` interpolated along x (`v + tx (next - v)`, `tx` 0 at even fine columns and 1/2
    /// at odd ones, 0 past the last coarse column). Fine columns `2k`, `2k + 1` come from coarse
    /// column `k`.
    fn upsample_row(s0: &[f32], s1: &[f32], ty: f32, scale: f32, row: &mut [f32]) {
        let (sw, w) = (s0.len(), row.len());
        if sw == 0 || s1.len() != sw {
            return;
        }
        let at = |a: f32, b: f32| scale * (a + ty * (b - a));
        let pairs = (w / 2).min(sw - 1);
        let (s0n, s1n) = (&s0[1..], &s1[1..]);
        for (k, px) in row[..2 * pairs].chunks_exact_mut(2).enumerate() {
            let (v0, n0, v1, n1) = (s0[k], s0n[k], s1[k], s1n[k]);
            px[0] = at(v0 + 0.0 * (n0 - v0), v1 + 0.0 * (n1 - v1));
            px[1] = at(v0 + 0.5 * (n0 - v0), v1 + 0.5 * (n1 - v1));
        }
        // Columns from 2 (sw - 1) on read the last coarse column (its "next" is itself).
        let (v0, v1) = (s0[sw - 1], s1[sw - 1]);
        for (x, v) in row.iter_mut().enumerate().skip(2 * pairs) {
            let k = (x / 2).min(sw - 1);
            let (a, b) = if k < sw - 1 { (s0[k], s1[k]) } else { (v0, v1) };
            let (na, nb) = if k < sw - 1 { (s0[k + 1], s1[k + 1]) } else { (v0, v1) };
            let t = if x % 2 == 1 && k < sw - 1 { 0.5 } else { 0.0 };
            *v = at(a + t * (na - a), b + t * (nb - b));
        }
    }
}

/// Left-right consistency (A.5 step 5): left pixel `x` keeps its value only if the right map at
/// `round(x - d)` agrees within `tol` px. `dr` is on the right grid, in `x_L - x_R` convention.
pub fn lr_check(dl: &[f32], dr: &[f32], w: usize, h: usize, tol: f32) -> Result<Vec<bool>> {
    let mut ok = try_filled(w * h, false, "the left-right check's mask")?;
    for_each_row(&mut ok, w, |y, row| {
        for (x, v) in row.iter_mut().enumerate() {
            let d = dl[y * w + x];
            let xr = (x as f32 - d).round();
            *v = d.is_finite()
                && xr >= 0.0
                && xr <= (w - 1) as f32
                && (d - dr[y * w + xr as usize]).abs() <= tol;
        }
    });
    Ok(ok)
}

simd_fn! {
    /// Final validity of one row: a pixel keeps its disparity if its confidence reaches
    /// `conf_min`, its match `x - d` is inside the row and, when `brow` (the right-reference
    /// run's row, mirrored: right pixel `xr` at `brow[w - 1 - xr]`) is not empty, the right map
    /// agrees within `tol` ([`lr_check`]'s rule). Others become NaN. In an AVX2 function so that
    /// `round` is an instruction, not a libm call per pixel.
    pub fn validity_row(drow: &mut [f32], crow: &[f32], brow: &[f32], conf_min: f32, tol: f32) {
        let w = drow.len();
        if w == 0 || crow.len() != w || !(brow.is_empty() || brow.len() == w) {
            return;
        }
        let last = (w - 1) as f32;
        let check = !brow.is_empty();
        let crow = &crow[..w];
        for x in 0..w {
            let d = drow[x];
            let s = x as f32 - d;
            // Branch-free: the right map is read at the clamped position, the range test decides.
            let xr = s.round();
            let inside = d.is_finite() & (xr >= 0.0) & (xr <= last);
            let lr = !check || {
                let i = xr.max(0.0).min(last) as usize;
                inside & ((d - brow[w - 1 - i]).abs() <= tol)
            };
            let valid = (crow[x] >= conf_min) & (s >= 0.0) & (s <= last) & lr;
            drow[x] = if valid { d } else { f32::NAN };
        }
    }
}

/// Mirrors a row-major image left-right.
pub fn flip_x(src: &[f32], w: usize, h: usize) -> Result<Vec<f32>> {
    let mut out = try_zeroed::<f32>(w * h, "a mirrored image of the Gabor matcher")?;
    for_each_row(&mut out, w, |y, row| {
        for (x, v) in row.iter_mut().enumerate() {
            *v = src[y * w + (w - 1 - x)];
        }
    });
    Ok(out)
}

/// Rows per band of the speckle labelling (each band is labelled by one task).
const SPECKLE_BAND: usize = 32;
/// No label (an invalid pixel).
const NO_LABEL: u32 = u32::MAX;

/// Removes 4-connected regions of valid pixels smaller than `min_size` whose neighbours differ by
/// at most `max_diff` px (OpenCV's `filterSpeckles` rule). NaN marks invalid pixels.
///
/// Two-pass union-find labelling in bands of rows, run in parallel, then the labels of pixels
/// that connect across a band boundary are merged. The regions are the connected components of
/// a fixed graph, so the result does not depend on the band split or the thread count (it
/// equals the sequential flood fill, which left the other core idle for 5 % of the matcher).
///
/// A failed allocation of the label image, of a band's labels (reserved for one label a pixel)
/// or of the tables of its labels (up to one label a pixel, 4 bytes each per table) is
/// [`crate::CoreError::OutOfMemory`] (`disp` unchanged); an image past
/// [`crate::image::check_index_range`] is [`crate::CoreError::TooLarge`].
pub fn remove_speckles(
    disp: &mut [f32],
    w: usize,
    h: usize,
    min_size: usize,
    max_diff: f32,
) -> Result<()> {
    use rayon::prelude::*;
    // Labels are u32 (NO_LABEL = u32::MAX): the binding's gabor_remove_speckles reaches this
    // without gabor_disparity's check.
    crate::image::check_index_range(w, h)?;
    if min_size == 0 || w == 0 || h == 0 {
        return Ok(());
    }
    let joins = |a: f32, b: f32| a.is_finite() && b.is_finite() && (a - b).abs() <= max_diff;
    let mut labels = try_filled(w * h, NO_LABEL, "the speckle filter's labels")?;
    // Per band: local labels 0..n, their union-find parents and pixel counts.
    const WHAT: &str = "the speckle filter's label tables";
    let bands: Vec<(Vec<u32>, Vec<u32>)> = labels
        .par_chunks_mut(w * SPECKLE_BAND)
        .enumerate()
        .map(|(band, lab)| {
            let y0 = band * SPECKLE_BAND;
            let rows = lab.len() / w;
            let d = &disp[y0 * w..(y0 + rows) * w];
            // At most one label a pixel: reserved checked once, so the pushes below never
            // reallocate (the last session's checked push in the loop was 20 % slower).
            let mut parent: Vec<u32> = Vec::new();
            try_reserve_len(&mut parent, lab.len(), "the speckle filter's band labels")?;
            for y in 0..rows {
                for x in 0..w {
                    let p = y * w + x;
                    let v = d[p];
                    if !v.is_finite() {
                        continue;
                    }
                    let left = (x > 0 && joins(v, d[p - 1])).then(|| lab[p - 1]);
                    let up = (y > 0 && joins(v, d[p - w])).then(|| lab[p - w]);
                    lab[p] = match (left, up) {
                        (Some(a), Some(b)) => {
                            union(&mut parent, a, b);
                            a
                        }
                        (Some(a), None) | (None, Some(a)) => a,
                        (None, None) => {
                            parent.push(parent.len() as u32);
                            parent.len() as u32 - 1
                        }
                    };
                }
            }
            let mut count = try_zeroed::<u32>(parent.len(), WHAT)?;
            for &l in lab.iter().filter(|&&l| l != NO_LABEL) {
                count[l as usize] += 1;
            }
            Ok((parent, count))
        })
        .collect::<Result<_>>()?;
    // Global labels: band-local ones shifted by the labels of the bands above. The tables are
    // allocated at once, checked (they grew by extend and vec!, aborting on a failure).
    let n_labels: usize = bands.iter().map(|(bp, _)| bp.len()).sum();
    let mut offset = Vec::with_capacity(bands.len());
    let (mut parent, mut count) = (Vec::new(), Vec::new());
    try_reserve_len(&mut parent, n_labels, WHAT)?;
    try_reserve_len(&mut count, n_labels, WHAT)?;
    for (bp, bc) in &bands {
        let off = parent.len() as u32;
        offset.push(off);
        parent.extend(bp.iter().map(|&q| q + off));
        count.extend_from_slice(bc);
    }
    for (band, &off) in offset.iter().enumerate().skip(1) {
        let y = band * SPECKLE_BAND;
        let prev = offset[band - 1];
        for x in 0..w {
            let (p, q) = (y * w + x, (y - 1) * w + x);
            if joins(disp[p], disp[q]) {
                union(&mut parent, labels[p] + off, labels[q] + prev);
            }
        }
    }
    let mut size = try_zeroed::<u32>(parent.len(), WHAT)?;
    let root = try_collect(
        parent.len(),
        (0..parent.len() as u32).map(|l| find(&mut parent, l)),
        WHAT,
    )?;
    for (l, &c) in count.iter().enumerate() {
        size[root[l] as usize] += c;
    }
    disp.par_chunks_mut(w * SPECKLE_BAND)
        .zip(labels.par_chunks(w * SPECKLE_BAND))
        .enumerate()
        .for_each(|(band, (d, lab))| {
            let off = offset[band];
            for (v, &l) in d.iter_mut().zip(lab) {
                if l != NO_LABEL && (size[root[(l + off) as usize] as usize] as usize) < min_size {
                    *v = f32::NAN;
                }
            }
        });
    Ok(())
}

/// Union-find root with path halving.
fn find(parent: &mut [u32], mut a: u32) -> u32 {
    while parent[a as usize] != a {
        let g = parent[parent[a as usize] as usize];
        parent[a as usize] = g;
        a = g;
    }
    a
}

/// Joins the sets of `a` and `b` (the smaller root becomes the parent: any rule works, the
/// components are what matters).
fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        parent[hi as usize] = lo;
    }
}

#[cfg(test)]
/// The sequential flood-fill form of [`remove_speckles`] (the reference of its test): removes
/// 4-connected regions of valid pixels smaller than `min_size` whose neighbours differ by
/// at most `max_diff` px (OpenCV's `filterSpeckles` rule). Sequential flood fill; the result is
/// deterministic. NaN marks invalid pixels.
pub fn remove_speckles_flood(disp: &mut [f32], w: usize, h: usize, min_size: usize, max_diff: f32) {
    if min_size == 0 {
        return;
    }
    // Coordinates travel with the pixels (no division per visited pixel), and a region's pixel
    // list is kept only while it could still be too small to survive.
    let mut seen = vec![false; w * h];
    let mut stack: Vec<(usize, usize)> = Vec::new();
    let mut region = Vec::with_capacity(min_size);
    for sy in 0..h {
        for sx in 0..w {
            let start = sy * w + sx;
            if seen[start] || !disp[start].is_finite() {
                continue;
            }
            region.clear();
            let mut size = 0usize;
            stack.push((sx, sy));
            seen[start] = true;
            while let Some((x, y)) = stack.pop() {
                let p = y * w + x;
                size += 1;
                if region.len() < min_size {
                    region.push(p);
                }
                let dp = disp[p];
                let mut visit = |q: usize, qx: usize, qy: usize| {
                    if !seen[q] && disp[q].is_finite() && (disp[q] - dp).abs() <= max_diff {
                        seen[q] = true;
                        stack.push((qx, qy));
                    }
                };
                if x > 0 {
                    visit(p - 1, x - 1, y);
                }
                if x + 1 < w {
                    visit(p + 1, x + 1, y);
                }
                if y > 0 {
                    visit(p - w, x, y - 1);
                }
                if y + 1 < h {
                    visit(p + w, x, y + 1);
                }
            }
            if size < min_size {
                for &p in &region {
                    disp[p] = f32::NAN;
                }
            }
        }
    }
}

/// Sets `out[i] = max(out[i], other[i])` (in parallel chunks).
pub fn max_into(out: &mut [f32], other: &[f32]) {
    use rayon::prelude::*;
    const CH: usize = 1 << 14;
    out.par_chunks_mut(CH)
        .zip(other.par_chunks(CH))
        .for_each(|(a, b)| a.iter_mut().zip(b).for_each(|(a, b)| *a = a.max(*b)));
}

/// Applies `disp += dbar` where `cbar >= conf_min`, clamping to `[lo, hi]`.
pub fn apply_update(
    disp: &mut [f32],
    dbar: &[f32],
    cbar: &[f32],
    conf_min: f32,
    lo: f32,
    hi: f32,
    w: usize,
) {
    for_each_row(disp, w, |y, row| {
        for (x, d) in row.iter_mut().enumerate() {
            let i = y * w + x;
            if cbar[i] >= conf_min {
                *d = (*d + dbar[i]).clamp(lo, hi);
            }
        }
    });
}
