//! Colour segments and the planes fitted in them: the fused dense map's fill before the row rule
//! (NumPy reference: `tests/reference/planes_ref.py`).
//!
//! [`quantised_regions`] (what the fill uses) labels the connected regions of equal binned
//! colour in one union-find scan. [`graph_segments`] is Felzenszwalb and Huttenlocher's
//! graph-based segmentation (IJCV 2004) on the 4-connected pixel grid: edges in increasing
//! colour distance merge two components while the distance is at most each one's internal
//! difference plus `k / size`; components smaller than `min_size` then join a neighbour (with
//! `k = 0` it gives the same regions as [`quantised_regions`] on binned values). [`plane_fill`]
//! fits `d = a x + b y + c` to the measured disparities of each segment (least squares, re-fitted
//! twice on the pixels within `max(1, 2 * median residual)`) and gives the plane's value to the
//! segment's holes when the fit is good: a hole inside a surface takes that surface's disparity,
//! where the row fill would take whichever side happens to be farther.

use rayon::prelude::*;

use crate::alloc::{try_collect, try_filled, try_reserve_len, try_zeroed};
use crate::error::Result;

/// Union-find with the component size and internal difference `Int(C)` of the paper.
struct Forest {
    parent: Vec<u32>,
    size: Vec<u32>,
    thresh: Vec<f32>,
}

impl Forest {
    /// `n` single-pixel components, or [`OutOfMemory`](crate::CoreError::OutOfMemory) when a
    /// table cannot be allocated.
    fn new(n: usize, k: f32) -> Result<Self> {
        let what = "the graph segmentation's union-find forest";
        let mut parent = Vec::new();
        try_reserve_len(&mut parent, n, what)?;
        parent.extend(0..n as u32);
        Ok(Self {
            parent,
            size: try_filled(n, 1, what)?,
            thresh: try_filled(n, k, what)?,
        })
    }

    fn find(&mut self, mut a: u32) -> u32 {
        while self.parent[a as usize] != a {
            let p = self.parent[a as usize];
            // Path halving.
            self.parent[a as usize] = self.parent[p as usize];
            a = p;
        }
        a
    }

    /// Joins two roots; the larger (the first on a tie) stays root.
    fn join(&mut self, a: u32, b: u32) -> u32 {
        let (r, c) = if self.size[b as usize] > self.size[a as usize] {
            (b, a)
        } else {
            (a, b)
        };
        self.parent[c as usize] = r;
        self.size[r as usize] += self.size[c as usize];
        r
    }
}

/// Most pixels of [`graph_segments`]'s image: its sort keys hold the edge numbers (2 p to the
/// right, 2 p + 1 downwards) in their low 32 bits, so the last, 2 n - 1, must fit a `u32`.
pub const GRAPH_MAX_PIXELS: usize = 1 << 31;

/// Segments a row-major `(H, W, C)` image (`C` interleaved channels, any scale) into labels
/// `0..n`, numbered in raster order of each segment's first pixel. See the module docs; `k` is
/// in the image's units (255-scale images: a few hundred).
///
/// A buffer that cannot be allocated is [`OutOfMemory`](crate::CoreError::OutOfMemory)
/// (unchecked, it aborted the process); more than [`GRAPH_MAX_PIXELS`] pixels is
/// [`TooLarge`](crate::CoreError::TooLarge).
///
/// # Panics
/// If `img.len() != w * h * c` or `c == 0`.
pub fn graph_segments(
    img: &[f32],
    w: usize,
    h: usize,
    c: usize,
    k: f32,
    min_size: usize,
) -> Result<Vec<u32>> {
    // The forest holds pixel indices in u32, the sort keys edge numbers (two a pixel).
    crate::image::check_index_range_within(w, h, GRAPH_MAX_PIXELS)?;
    assert!(
        c > 0 && img.len() == w * h * c,
        "image size does not match w * h * c"
    );
    let n = w * h;
    if n == 0 {
        return Ok(Vec::new());
    }
    let dist = |p: usize, q: usize| -> f32 {
        let mut s = 0.0f32;
        for i in 0..c {
            let d = img[p * c + i] - img[q * c + i];
            s += d * d;
        }
        s.sqrt()
    };
    // Edge e: 2 * pixel (to the right), 2 * pixel + 1 (downwards). The key sorts by weight
    // (a non-negative f32's bits order like the value), then by edge index: a total order, so
    // the unstable parallel sort is deterministic, and the order they are written in does not
    // matter: all edges to the right (row by row), then all edges downwards, into one checked
    // buffer (a `collect` aborted the process when it could not allocate).
    let n_right = (w - 1) * h;
    let mut keys = try_zeroed::<u64>(n_right + w * (h - 1), "the graph segmentation's edges")?;
    let (right, down) = keys.split_at_mut(n_right);
    let key = |p: usize, q: usize, e: usize| ((dist(p, q).to_bits() as u64) << 32) | e as u64;
    if w > 1 {
        right
            .par_chunks_mut(w - 1)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, k) in row.iter_mut().enumerate() {
                    let p = y * w + x;
                    *k = key(p, p + 1, 2 * p);
                }
            });
    }
    down.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, k) in row.iter_mut().enumerate() {
            let p = y * w + x;
            *k = key(p, p + w, 2 * p + 1);
        }
    });
    keys.par_sort_unstable();
    let ends = |key: u64| -> (u32, u32) {
        let e = (key & 0xffff_ffff) as usize;
        let p = e / 2;
        let q = if e.is_multiple_of(2) { p + 1 } else { p + w };
        (p as u32, q as u32)
    };
    let mut f = Forest::new(n, k)?;
    for &key in &keys {
        let wgt = f32::from_bits((key >> 32) as u32);
        let (p, q) = ends(key);
        let (a, b) = (f.find(p), f.find(q));
        if a != b && wgt <= f.thresh[a as usize] && wgt <= f.thresh[b as usize] {
            let r = f.join(a, b);
            f.thresh[r as usize] = wgt + k / f.size[r as usize] as f32;
        }
    }
    for &key in &keys {
        let (p, q) = ends(key);
        let (a, b) = (f.find(p), f.find(q));
        if a != b
            && ((f.size[a as usize] as usize) < min_size
                || (f.size[b as usize] as usize) < min_size)
        {
            f.join(a, b);
        }
    }
    drop(keys);
    raster_labels(&mut f, n)
}

/// Labels `0..` of the forest's components, in raster order of their first pixel.
fn raster_labels(f: &mut Forest, n: usize) -> Result<Vec<u32>> {
    let mut id = try_filled(n, u32::MAX, "the graph segmentation's labels")?;
    let mut next = 0u32;
    let mut labels = try_zeroed::<u32>(n, "the graph segmentation's labels")?;
    for (p, l) in labels.iter_mut().enumerate() {
        let r = f.find(p as u32) as usize;
        if id[r] == u32::MAX {
            id[r] = next;
            next += 1;
        }
        *l = id[r];
    }
    Ok(labels)
}

/// Connected regions (4-neighbours) of equal quantised colour of a row-major `(H, W, C)` u8
/// image, `C` in 1..=3: a pixel's bin in each channel is `(value + offset) / step`. Labels as
/// [`graph_segments`] numbers them (it gives the same labels with `k = 0` on the bins), in one
/// union-find scan whose roots are each region's first pixel.
///
/// A table that cannot be allocated is [`OutOfMemory`](crate::CoreError::OutOfMemory)
/// (unchecked, it aborted the process).
///
/// # Panics
/// If `img.len() != w * h * c`, `c` is not 1..=3, or `step` is 0.
pub fn quantised_regions(
    img: &[u8],
    w: usize,
    h: usize,
    c: usize,
    step: u32,
    offset: u32,
) -> Result<Vec<u32>> {
    let what = "the colour regions' tables";
    // The region forest holds pixel indices in u32.
    crate::image::check_index_range(w, h)?;
    assert!(
        (1..=3).contains(&c) && img.len() == w * h * c,
        "image size does not match w * h * c"
    );
    assert!(step > 0, "step must be positive");
    let n = w * h;
    // Each bin fits 9 bits ((255 + offset) / step < 512 for offset < 257 * step).
    // Bins by table: a division per channel and pixel would cost more than the labelling.
    let bin: Vec<u32> = (0..256u32)
        .map(|v| ((v + offset) / step).min(511))
        .collect();
    let mut keys = try_zeroed::<u32>(n, what)?;
    keys.par_chunks_mut(w.max(1))
        .zip(img.par_chunks(w.max(1) * c))
        .for_each(|(k, row)| {
            for (k, px) in k.iter_mut().zip(row.chunks_exact(c)) {
                let mut v = 0u32;
                for (i, &b) in px.iter().enumerate() {
                    v |= bin[b as usize] << (9 * i);
                }
                *k = v;
            }
        });
    // parent[p] <= p always: a region's root is its first pixel in raster order.
    let mut parent = try_collect(n, 0..n as u32, what)?;
    let find = |parent: &mut [u32], mut a: usize| -> usize {
        while parent[a] as usize != a {
            let p = parent[a] as usize;
            parent[a] = parent[p];
            a = p;
        }
        a
    };
    // By runs of equal keys along each row: a run's pixels point to its first one, and the run
    // joins each run of the same key that touches it from the row above (one `find` per such
    // run, not per pixel). Unions keep the smaller root, as a pixel-by-pixel scan would.
    for y in 0..h {
        let row = y * w;
        let mut x = 0;
        while x < w {
            let k = keys[row + x];
            let s = x;
            x += 1;
            while x < w && keys[row + x] == k {
                parent[row + x] = (row + s) as u32;
                x += 1;
            }
            if y == 0 {
                continue;
            }
            let mut rp = row + s; // the run's root so far (its first pixel, or a smaller one)
            let mut q = row - w + s;
            let end = row - w + x;
            while q < end {
                if keys[q] != k {
                    q += 1;
                    continue;
                }
                let b = find(&mut parent, q);
                if b != rp {
                    let (lo, hi) = (rp.min(b), rp.max(b));
                    parent[hi] = lo as u32;
                    rp = lo;
                }
                // Skip the rest of this run above: its pixels share the root just joined.
                while q < end && keys[q] == k {
                    q += 1;
                }
            }
        }
    }
    drop(keys);
    // parent[p] < p unless p is a root, and its label is final by then: no search needed.
    let mut labels = try_zeroed::<u32>(n, what)?;
    let mut next = 0u32;
    for p in 0..n {
        let q = parent[p] as usize;
        if q == p {
            labels[p] = next;
            next += 1;
        } else {
            labels[p] = labels[q];
        }
    }
    Ok(labels)
}

/// Outcome of [`plane_fill`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PlaneFillStats {
    /// Segments whose plane filled at least one hole.
    pub planes: usize,
    /// Holes filled.
    pub filled: usize,
}

/// Least-squares plane through `(x, y, d)` weighted 0/1 by `keep`, in coordinates centred on
/// `(cx, cy)`; None when the points do not span a plane.
fn fit_plane(pts: &[(f32, f32, f32)], keep: &[bool], cx: f64, cy: f64) -> Option<[f64; 3]> {
    let mut m = [[0.0f64; 3]; 3];
    let mut v = [0.0f64; 3];
    for (&(x, y, d), &k) in pts.iter().zip(keep) {
        if !k {
            continue;
        }
        let r = [x as f64 - cx, y as f64 - cy, 1.0];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += r[i] * r[j];
            }
            v[i] += r[i] * d as f64;
        }
    }
    let a = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
    let b = nalgebra::Vector3::from_column_slice(&v);
    // A segment one pixel wide (or tall) has no slope across itself: no plane.
    let scale = m[0][0].max(m[1][1]).max(m[2][2]);
    if a.determinant().abs() <= 1e-9 * scale * scale * scale {
        return None;
    }
    a.lu().solve(&b).map(|s| [s[0], s[1], s[2]])
}

fn median(v: &mut [f32]) -> f32 {
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
}

/// Fills the holes (non-finite values) of a row-major `(H, W)` disparity map in place with the
/// plane of their segment (see the module docs): segments with at least `min_pixels` measured
/// pixels whose fit has a median absolute residual of at most `max_residual`; a plane value
/// outside `[lo, hi]` leaves the hole. Segments run in parallel and write disjoint pixels, so
/// the result does not depend on the thread count.
///
/// A table that cannot be allocated is [`OutOfMemory`](crate::CoreError::OutOfMemory)
/// (unchecked, it aborted the process); a map of more than [`MAX_PIXELS`] pixels (or rows
/// longer than [`MAX_SIDE`]) is [`TooLarge`](crate::CoreError::TooLarge).
///
/// [`MAX_PIXELS`]: crate::image::MAX_PIXELS
/// [`MAX_SIDE`]: crate::image::MAX_SIDE
///
/// # Panics
/// If `labels.len() != disp.len()` or a label is not below it (labels as the segment functions
/// number them).
pub fn plane_fill(
    disp: &mut [f32],
    labels: &[u32],
    w: usize,
    min_pixels: usize,
    max_residual: f32,
    lo: f32,
    hi: f32,
) -> Result<PlaneFillStats> {
    let what = "the plane fill's segment tables";
    assert_eq!(
        labels.len(),
        disp.len(),
        "labels and disparity differ in size"
    );
    if disp.is_empty() || w == 0 {
        return Ok(PlaneFillStats::default());
    }
    // Pixels are listed (`order`, the fills) and counted per segment in u32: past u32::MAX
    // pixels they wrapped. The binding checks the shape before calling; a Rust caller reaches
    // this alone. `div_ceil`: a last row cut short still counts (w * h >= the length).
    crate::image::check_index_range(w, disp.len().div_ceil(w))?;
    let n_seg = labels.iter().max().map_or(0, |&m| m as usize + 1);
    assert!(
        n_seg <= labels.len(),
        "labels must be below the pixel count"
    );
    // Measured pixels and holes per segment: only a segment with a hole and enough measured
    // pixels can fill anything (`segment_fill` would return at once for the others).
    let mut meas = try_zeroed::<u32>(n_seg, what)?;
    let mut holes = try_zeroed::<u32>(n_seg, what)?;
    for (&l, &d) in labels.iter().zip(disp.iter()) {
        if d.is_finite() {
            meas[l as usize] += 1;
        } else {
            holes[l as usize] += 1;
        }
    }
    let min_meas = min_pixels.max(3);
    let is_active = |s: &usize| holes[*s] > 0 && meas[*s] as usize >= min_meas;
    let n_active = (0..n_seg).filter(is_active).count();
    let active = try_collect(n_active, (0..n_seg).filter(is_active), what)?;
    // Their pixels grouped by segment (counting sort), raster order inside each.
    let mut start = try_zeroed::<usize>(n_seg + 1, what)?;
    for &s in &active {
        start[s + 1] = (meas[s] + holes[s]) as usize;
    }
    for i in 0..n_seg {
        start[i + 1] += start[i];
    }
    let mut order = try_zeroed::<u32>(start[n_seg], what)?;
    let mut at = try_collect(start.len(), start.iter().copied(), what)?;
    for (p, &l) in labels.iter().enumerate() {
        let l = l as usize;
        if at[l] < start[l + 1] {
            order[at[l]] = p as u32;
            at[l] += 1;
        }
    }
    let src: &[f32] = disp;
    // Most segments fill nothing: one vector per task, not one per segment.
    let fills: Vec<(u32, f32)> = active
        .into_par_iter()
        .try_fold(Vec::new, |mut acc, s| {
            segment_fill(
                src,
                &order[start[s]..start[s + 1]],
                w,
                min_pixels,
                max_residual,
                lo,
                hi,
                &mut acc,
            )?;
            Ok(acc)
        })
        .try_reduce(Vec::new, |mut a, mut b| {
            reserve_fills(&mut a, b.len())?;
            a.append(&mut b);
            Ok(a)
        })?;
    let mut planes = 0;
    let mut last = u32::MAX;
    for &(p, v) in &fills {
        let l = labels[p as usize];
        if l != last {
            planes += 1;
            last = l;
        }
        disp[p as usize] = v;
    }
    Ok(PlaneFillStats {
        planes,
        filled: fills.len(),
    })
}

/// Room for `more` fills in `v`, grown as `extend` or `append` would (amortised: one vector
/// takes many segments' fills), but checked: [`OutOfMemory`](crate::CoreError::OutOfMemory).
fn reserve_fills(v: &mut Vec<(u32, f32)>, more: usize) -> Result<()> {
    v.try_reserve(more).map_err(|_| {
        let n = v.len().saturating_add(more);
        crate::CoreError::oom(n.saturating_mul(8), "the plane fill's fills")
    })
}

/// The holes of one segment (`pix`, raster order) and their plane values, appended to `out`.
/// One large segment (a flat image is one) needs 21 bytes a measured pixel: allocated checked,
/// [`OutOfMemory`](crate::CoreError::OutOfMemory) (a `collect` or `vec!` aborted the process).
#[allow(clippy::too_many_arguments)]
fn segment_fill(
    disp: &[f32],
    pix: &[u32],
    w: usize,
    min_pixels: usize,
    max_residual: f32,
    lo: f32,
    hi: f32,
    out: &mut Vec<(u32, f32)>,
) -> Result<()> {
    let what = "the plane fill's segment fit";
    // Most segments are small: count before collecting anything.
    let n_meas = pix
        .iter()
        .filter(|&&p| disp[p as usize].is_finite())
        .count();
    if n_meas == pix.len() || n_meas < min_pixels.max(3) {
        return Ok(());
    }
    let holes = try_collect(
        pix.len() - n_meas,
        pix.iter()
            .copied()
            .filter(|&p| !disp[p as usize].is_finite()),
        what,
    )?;
    let pts: Vec<(f32, f32, f32)> = try_collect(
        n_meas,
        pix.iter()
            .filter(|&&p| disp[p as usize].is_finite())
            .map(|&p| {
                (
                    (p as usize % w) as f32,
                    (p as usize / w) as f32,
                    disp[p as usize],
                )
            }),
        what,
    )?;
    let cx = pts.iter().map(|p| p.0 as f64).sum::<f64>() / pts.len() as f64;
    let cy = pts.iter().map(|p| p.1 as f64).sum::<f64>() / pts.len() as f64;
    let mut keep = try_filled(pts.len(), true, what)?;
    let mut res = try_zeroed::<f32>(pts.len(), what)?;
    let mut plane = [0.0f64; 3];
    let mut med = 0.0f32;
    let mut scratch = try_zeroed::<f32>(pts.len(), what)?;
    for _ in 0..3 {
        let Some(c) = fit_plane(&pts, &keep, cx, cy) else {
            return Ok(());
        };
        plane = c;
        for (r, &(x, y, d)) in res.iter_mut().zip(&pts) {
            let e = c[0] * (x as f64 - cx) + c[1] * (y as f64 - cy) + c[2] - d as f64;
            *r = e.abs() as f32;
        }
        scratch.copy_from_slice(&res);
        med = median(&mut scratch);
        let cut = (2.0 * med).max(1.0);
        for (k, &r) in keep.iter_mut().zip(&res) {
            *k = r < cut;
        }
    }
    // The last fit's median residual (the cut above used it too).
    if med > max_residual {
        return Ok(());
    }
    reserve_fills(out, holes.len())?;
    out.extend(holes.into_iter().filter_map(|p| {
        let (x, y) = ((p as usize % w) as f64, (p as usize / w) as f64);
        let v = (plane[0] * (x - cx) + plane[1] * (y - cy) + plane[2]) as f32;
        (v >= lo && v <= hi).then_some((p, v))
    }));
    Ok(())
}

/// One pass of [`fill_planes`]: `(step, min_pixels)`.
pub type PlanePass = (u32, usize);

/// The fused dense map's plane fill (`stereovision.matching.planes.fill_planes`), in place on a
/// row-major `(H, W)` map with its (already blurred) `(H, W, C)` u8 image. Each pass cuts the
/// image twice, binned in steps of `step` grey levels at offsets 0 and `step / 2`
/// ([`quantised_regions`]), fills each cut's holes with [`plane_fill`] (planes within the
/// measured range), and takes the mean where both filled a hole; the next pass sees those fills
/// as measured. A pass on a map with no hole or no measured value leaves it. The two cuts run
/// side by side; each is computed as alone, so the result does not depend on the thread count.
///
/// A buffer that cannot be allocated is [`OutOfMemory`](crate::CoreError::OutOfMemory)
/// (unchecked, it aborted the process).
///
/// # Panics
/// As [`quantised_regions`] (image size, `c`, `step`) and [`plane_fill`].
pub fn fill_planes(
    disp: &mut [f32],
    img: &[u8],
    w: usize,
    c: usize,
    passes: &[PlanePass],
    max_residual: f32,
) -> Result<()> {
    let h = disp.len().checked_div(w).unwrap_or(0);
    for &(step, min_pixels) in passes {
        let (mut lo, mut hi, mut holes) = (f32::INFINITY, f32::NEG_INFINITY, false);
        for &v in disp.iter() {
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            } else {
                holes = true;
            }
        }
        if !holes || lo > hi {
            continue; // nothing to fill, or nothing to fit
        }
        let cut = |offset: u32| -> Result<Vec<f32>> {
            let labels = quantised_regions(img, w, h, c, step, offset)?;
            let copy = "the plane fill's copy of the map";
            let mut out = try_collect(disp.len(), disp.iter().copied(), copy)?;
            plane_fill(&mut out, &labels, w, min_pixels, max_residual, lo, hi)?;
            Ok(out)
        };
        let (a, b) = rayon::join(|| cut(0), || cut(step / 2));
        let (a, b) = (a?, b?);
        for ((d, &a), &b) in disp.iter_mut().zip(&a).zip(&b) {
            let hole = !d.is_finite();
            *d = if a.is_finite() { a } else { b };
            if hole && a.is_finite() && b.is_finite() {
                *d = 0.5 * (a + b);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn graph_segments_refuses_images_past_its_32_bit_edge_numbers() {
        // Edge numbers (two a pixel: 2 p, 2 p + 1) sit in the low 32 bits of the sort keys:
        // past 2^31 pixels they spilled into the weight bits (wrong order, wrong ends), yet
        // check_index_range let up to u32::MAX pixels through. The shape alone is checked
        // first (empty buffers: an image that size cannot be allocated in a test).
        let too_large = |w, h| {
            Err(crate::CoreError::TooLarge {
                width: w,
                height: h,
                max_pixels: GRAPH_MAX_PIXELS,
            })
        };
        for (w, h) in [(1 << 16, (1 << 15) + 1), ((1 << 31) + 1, 1), (3, 1 << 30)] {
            assert_eq!(
                graph_segments(&[], w, h, 1, 1.0, 1),
                too_large(w, h),
                "{w}x{h}"
            );
        }
        assert_eq!(GRAPH_MAX_PIXELS, 1 << 31);
        // At the limit the last edge number, 2 (n - 1) + 1, is u32::MAX: it fits.
        assert_eq!(2 * (GRAPH_MAX_PIXELS - 1) + 1, u32::MAX as usize);
        assert_eq!(
            too_large(1 << 16, 1 << 16).unwrap_err().to_string(),
            "image of 65536x65536 pixels is too large: the kernels index pixels with 32-bit \
             integers (at most 2147483648 pixels, 2147483647 per side)"
        );
    }

    #[test]
    fn tables_too_large_to_allocate_are_an_error() {
        // The forest was three `vec!`s and `collect`s: a failed allocation aborted the process.
        assert!(matches!(
            Forest::new(1 << 62, 1.0),
            Err(crate::CoreError::OutOfMemory {
                what: "the graph segmentation's union-find forest",
                ..
            })
        ));
        // An empty image (the checked edge count would wrap) has no labels.
        assert_eq!(
            graph_segments(&[], 0, 5, 1, 1.0, 1).unwrap(),
            Vec::<u32>::new()
        );
        assert_eq!(
            graph_segments(&[], 5, 0, 3, 1.0, 1).unwrap(),
            Vec::<u32>::new()
        );
    }

    /// `setrlimit(RLIMIT_AS, limit)` through the C library std links anyway (no `libc` crate).
    #[cfg(target_os = "linux")]
    pub(crate) fn limit_address_space(limit: usize) {
        #[repr(C)]
        struct Rlimit {
            cur: u64,
            max: u64,
        }
        extern "C" {
            fn setrlimit(resource: i32, rlim: *const Rlimit) -> i32;
        }
        const RLIMIT_AS: i32 = 9;
        let l = Rlimit {
            cur: limit as u64,
            max: limit as u64,
        };
        // SAFETY: a valid pointer to a `struct rlimit` (two 64-bit `rlim_t`) for the call.
        assert_eq!(unsafe { setrlimit(RLIMIT_AS, &l) }, 0, "setrlimit failed");
    }

    /// Runs this test binary's ignored test `name` as a child (one rayon thread, one malloc
    /// arena, `SV_OOM_CHILD` set, so that it may cap its own address space) and returns its
    /// stdout; fails the test when the child fails (an abort on a failed allocation).
    #[cfg(target_os = "linux")]
    pub(crate) fn run_oom_child(name: &str) -> String {
        run_oom_child_with(name, None)
    }

    /// [`run_oom_child`] with one more environment variable (a variant of the child test).
    #[cfg(target_os = "linux")]
    pub(crate) fn run_oom_child_with(name: &str, var: Option<(&str, &str)>) -> String {
        let mut cmd = std::process::Command::new(std::env::current_exe().unwrap());
        cmd.args([
            name,
            "--exact",
            "--ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("SV_OOM_CHILD", "1")
        .env("RAYON_NUM_THREADS", "1")
        .env("MALLOC_ARENA_MAX", "1");
        if let Some((k, v)) = var {
            cmd.env(k, v);
        }
        let out = cmd.output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "the child failed ({}): {stdout}{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        stdout
    }

    /// Runs `f` in a forked copy of this process and waits for it: the variants of one child
    /// test (several memory limits) share what it computed before the forks, each limit in a
    /// process of its own. Fails when the fork does not exit 0 (an abort on a failed
    /// allocation, a panic). The global rayon pool must not have started before the fork (a
    /// forked process has the forking thread only): the fork starts its own.
    #[cfg(target_os = "linux")]
    pub(crate) fn in_a_fork(f: impl FnOnce()) {
        use std::io::Write;
        extern "C" {
            fn fork() -> i32;
            fn waitpid(pid: i32, status: *mut i32, options: i32) -> i32;
            fn _exit(status: i32) -> !;
        }
        // flushed first, so nothing buffered is printed twice (by the fork too)
        std::io::stdout().flush().unwrap();
        // SAFETY: plain fork; the fork runs `f` and leaves by `_exit`, never returning here.
        let pid = unsafe { fork() };
        assert!(pid >= 0, "fork failed");
        if pid == 0 {
            let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).is_ok();
            let flushed = std::io::stdout().flush().is_ok();
            // SAFETY: ends the forked process without running the test harness on.
            unsafe { _exit(if ok && flushed { 0 } else { 101 }) }
        }
        let mut status = 0i32;
        // SAFETY: a valid pointer to an int for the wait status.
        assert_eq!(
            unsafe { waitpid(pid, &mut status, 0) },
            pid,
            "waitpid failed"
        );
        assert_eq!(status, 0, "the fork failed (wait status {status:#x})");
    }

    /// This process's mapped address space (`VmSize`), in bytes.
    #[cfg(target_os = "linux")]
    pub(crate) fn vm_size() -> usize {
        let status = std::fs::read_to_string("/proc/self/status").unwrap();
        let line = status.lines().find(|l| l.starts_with("VmSize:")).unwrap();
        let kb: usize = line.split_whitespace().nth(1).unwrap().parse().unwrap();
        kb * 1024
    }

    /// Run by [`a_plane_fit_too_large_to_allocate_is_an_error`] in a child process: a flat
    /// 1024x1024 image (one region) with one hole, under an address-space limit of 18 bytes a
    /// pixel more than is mapped. The cut's labels, its copy of the map and the pixel order
    /// (12 bytes a pixel) fit; the segment's fit points (12 more) do not.
    #[cfg(target_os = "linux")]
    #[test]
    #[ignore = "a child of a_plane_fit_too_large_to_allocate_is_an_error"]
    fn plane_fit_under_a_memory_limit() {
        if std::env::var_os("SV_OOM_CHILD").is_none() {
            return;
        }
        let (w, h) = (1024usize, 1024usize);
        let n = w * h;
        let img = vec![0u8; n];
        let mut d = vec![1.0f32; n];
        d[0] = f32::NAN;
        rayon::join(|| (), || ()); // the pool's thread started before the limit
        limit_address_space(vm_size() + 18 * n);
        match fill_planes(&mut d, &img, w, 1, &[(16, 50)], 0.7) {
            Ok(()) => println!("child: filled {}", d[0]),
            Err(e) => println!("child: error: {e}"),
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_plane_fit_too_large_to_allocate_is_an_error() {
        // segment_fill collected a segment's points, holes and residuals with collect/vec!
        // (up to 21 bytes a pixel for one large segment, more than the checked tables): a
        // failed allocation aborted the process (SIGABRT) instead of returning OutOfMemory.
        let stdout = run_oom_child("segment::tests::plane_fit_under_a_memory_limit");
        assert!(
            stdout.contains("child: error: out of memory: the plane fill's segment fit needs "),
            "{stdout}"
        );
    }

    #[test]
    fn two_flat_regions_are_two_segments() {
        let (w, h) = (8, 4);
        let img: Vec<f32> = (0..w * h)
            .map(|p| if p % w < 4 { 10.0 } else { 200.0 })
            .collect();
        let l = graph_segments(&img, w, h, 1, 300.0, 1).unwrap();
        assert!((0..w * h).all(|p| l[p] == if p % w < 4 { 0 } else { 1 }));
    }

    #[test]
    fn k_zero_merges_the_equal_value_regions() {
        // k = 0 merges exactly the zero-weight edges; min_size 2 changes nothing here (no region
        // is a single pixel).
        let (w, h) = (9, 7);
        let img: Vec<f32> = (0..w * h)
            .map(|p| ((p % w) / 3 + 3 * ((p / w) / 2)) as f32)
            .collect();
        let one = graph_segments(&img, w, h, 1, 0.0, 1).unwrap();
        assert_eq!(one, graph_segments(&img, w, h, 1, 0.0, 2).unwrap());
        assert_eq!(*one.iter().max().unwrap(), 11); // 3 columns x 4 row bands
    }

    #[test]
    fn quantised_regions_equal_graph_segments_on_the_bins() {
        let (w, h, c) = (23usize, 17usize, 3usize);
        // Smooth ramps with a few steps: regions of many shapes, some touching only diagonally.
        let img: Vec<u8> = (0..w * h * c)
            .map(|i| {
                let (p, ch) = (i / c, i % c);
                let (x, y) = (p % w, p / w);
                ((x * 7 + y * 3 * (ch + 1) + (x * y) % 5 * 20) % 256) as u8
            })
            .collect();
        for (step, offset) in [(16u32, 0u32), (16, 8), (24, 12), (1, 0)] {
            let bins: Vec<f32> = img
                .iter()
                .map(|&v| ((v as u32 + offset) / step) as f32)
                .collect();
            assert_eq!(
                quantised_regions(&img, w, h, c, step, offset).unwrap(),
                graph_segments(&bins, w, h, c, 0.0, 1).unwrap(),
                "step {step} offset {offset}"
            );
        }
    }

    #[test]
    fn quantised_regions_join_u_shapes_and_spirals() {
        // Random two- and three-level images: regions that meet only rows below where they
        // start (U shapes, spirals), which the run-by-run unions must join like a pixel scan.
        let (w, h) = (61usize, 47usize);
        let mut state = 12345u64;
        for levels in [2u64, 3] {
            let img: Vec<u8> = (0..w * h)
                .map(|_| {
                    state = state
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((state >> 33) % levels * 100) as u8
                })
                .collect();
            let bins: Vec<f32> = img.iter().map(|&v| (v as u32 / 16) as f32).collect();
            assert_eq!(
                quantised_regions(&img, w, h, 1, 16, 0).unwrap(),
                graph_segments(&bins, w, h, 1, 0.0, 1).unwrap(),
                "{levels} levels"
            );
        }
    }

    #[test]
    fn small_segments_join_a_neighbour() {
        let (w, h) = (6, 6);
        let mut img = vec![0.0f32; w * h];
        img[2 * w + 2] = 255.0; // a one-pixel island
        assert_eq!(
            *graph_segments(&img, w, h, 1, 1.0, 1)
                .unwrap()
                .iter()
                .max()
                .unwrap(),
            1
        );
        assert!(graph_segments(&img, w, h, 1, 1.0, 2)
            .unwrap()
            .iter()
            .all(|&l| l == 0));
    }

    #[test]
    fn a_slanted_plane_fills_its_holes() {
        let (w, h) = (10, 10);
        let mut d: Vec<f32> = (0..w * h)
            .map(|p| 5.0 + 0.5 * (p % w) as f32 + 0.25 * (p / w) as f32)
            .collect();
        let truth = d.clone();
        for p in [0, 11, 55, 99] {
            d[p] = f32::NAN;
        }
        let labels = vec![0u32; w * h];
        let s = plane_fill(&mut d, &labels, w, 10, 0.5, 0.0, 100.0).unwrap();
        assert_eq!(
            s,
            PlaneFillStats {
                planes: 1,
                filled: 4
            }
        );
        for p in [0, 11, 55, 99] {
            assert!((d[p] - truth[p]).abs() < 1e-4, "{} vs {}", d[p], truth[p]);
        }
    }

    #[test]
    fn a_bad_fit_or_too_few_pixels_leaves_the_holes() {
        let (w, h) = (10, 10);
        // A checkerboard of 0 and 10: no plane has a median residual under 1.
        let mut d: Vec<f32> = (0..w * h)
            .map(|p| if (p % w + p / w) % 2 == 0 { 0.0 } else { 10.0 })
            .collect();
        d[0] = f32::NAN;
        let labels = vec![0u32; w * h];
        assert_eq!(
            plane_fill(&mut d, &labels, w, 10, 1.0, -100.0, 100.0)
                .unwrap()
                .filled,
            0
        );
        let mut flat = vec![3.0f32; w * h];
        flat[0] = f32::NAN;
        assert_eq!(
            plane_fill(&mut flat, &labels, w, 200, 1.0, 0.0, 100.0)
                .unwrap()
                .filled,
            0
        );
        // ... and a plane value out of [lo, hi] too.
        assert_eq!(
            plane_fill(&mut flat, &labels, w, 10, 1.0, 0.0, 2.0)
                .unwrap()
                .filled,
            0
        );
        assert_eq!(
            plane_fill(&mut flat, &labels, w, 10, 1.0, 0.0, 5.0)
                .unwrap()
                .filled,
            1
        );
        assert_eq!(flat[0], 3.0);
    }

    #[test]
    fn fill_planes_takes_the_mean_of_the_two_cuts() {
        // Two columns of grey: 20 on the left half, 30 on the right. At step 16 the cut at
        // offset 0 joins them (bins 1 and 1), the cut at offset 8 parts them (bins 1 and 2).
        // Left half at disparity 4, right half at 8: the joined segment's plane is no fit
        // (median residual 2), so each hole takes its own half's plane from the parting cut.
        let (w, h) = (10, 10);
        let img: Vec<u8> = (0..w * h)
            .map(|p| if p % w < 5 { 20 } else { 30 })
            .collect();
        let mut d: Vec<f32> = (0..w * h)
            .map(|p| if p % w < 5 { 4.0 } else { 8.0 })
            .collect();
        for p in [22, 77] {
            d[p] = f32::NAN;
        }
        let mut one = d.clone();
        fill_planes(&mut one, &img, w, 1, &[(16, 10)], 0.5).unwrap();
        assert_eq!((one[22], one[77]), (4.0, 8.0));
        // Where both cuts fill, the mean: one colour, one plane each way.
        let flat = vec![20u8; w * h];
        let mut e: Vec<f32> = (0..w * h).map(|p| 2.0 + 0.5 * (p % w) as f32).collect();
        e[44] = f32::NAN;
        fill_planes(&mut e, &flat, w, 1, &[(16, 10)], 0.5).unwrap();
        assert!((e[44] - 4.0).abs() < 1e-5, "{}", e[44]);
        // No hole, or nothing measured: unchanged.
        let mut full = vec![1.0f32; w * h];
        fill_planes(&mut full, &img, w, 1, &[(16, 10)], 0.5).unwrap();
        assert!(full.iter().all(|&v| v == 1.0));
        let mut empty = vec![f32::NAN; w * h];
        fill_planes(&mut empty, &img, w, 1, &[(16, 10)], 0.5).unwrap();
        assert!(empty.iter().all(|v| v.is_nan()));
    }

    #[test]
    fn merges_follow_the_internal_difference_plus_k_over_size() {
        let row = |v: &[f32], k: f32, min_size: usize| {
            graph_segments(v, v.len(), 1, 1, k, min_size).unwrap()
        };
        // Unit steps, k = 2.5: each merge leaves Int + k / |C| = 1 + 2.5 / |C| >= 1.
        assert_eq!(row(&[0.0, 1.0, 2.0, 3.0], 2.5, 1), [0, 0, 0, 0]);
        // Two singletons merge when their distance (2, not its square) is at most k.
        assert_eq!(row(&[0.0, 2.0], 3.0, 1), [0, 0]);
        // Runs of equal values have thresholds 0 + 6 / 3, 6 / 2, 6 / 3: the step of 3 from the
        // first run exceeds its 2, the step of 6 both sides'.
        let runs = [0.0, 0.0, 0.0, 3.0, 3.0, 9.0, 9.0, 9.0];
        assert_eq!(row(&runs, 6.0, 1), [0, 0, 0, 1, 1, 2, 2, 2]);
        // min_size 3: the pair joins a neighbour along its lightest edge (3 before 6).
        assert_eq!(row(&runs, 6.0, 3), [0, 0, 0, 0, 0, 1, 1, 1]);
        // Both sides' thresholds count: the edge of 10 is within the singleton's 12 but not
        // the run 10 10.5 11's 0.5 + 12 / 3.
        assert_eq!(row(&[0.0, 10.0, 10.5, 11.0], 12.0, 1), [0, 1, 1, 1]);
        // min_size 3 joins the pair 30 31 (size 2) to its neighbour, not the runs of three.
        let three = [0.0, 2.0, 4.0, 10.0, 11.0, 12.0, 30.0, 31.0];
        assert_eq!(row(&three, 4.0, 1), [0, 0, 0, 1, 1, 1, 2, 2]);
        assert_eq!(row(&three, 4.0, 3), [0, 0, 0, 1, 1, 1, 1, 1]);
        // min_size 1 joins nothing: the single pixel 5 stays.
        assert_eq!(
            row(&[5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.5, 1.5], 1.0, 1),
            [0, 1, 1, 1, 1, 1, 2, 2]
        );
    }

    #[test]
    fn plane_fill_refits_without_its_outliers() {
        // A slanted plane whose measured values have every fifth one 1.5 px off: the first fit
        // is pulled towards them (by about 0.3), the re-fits on the values within
        // max(1, 2 median) px of it leave them out (1.2 px off) and are exact.
        let (w, h) = (12, 10);
        let truth = |p: usize| 5.0 + 0.5 * (p % w) as f32 + 0.25 * (p / w) as f32;
        let mut d: Vec<f32> = (0..w * h)
            .map(|p| truth(p) + if p % 5 == 2 { 1.5 } else { 0.0 })
            .collect();
        let holes = [0, 13, 59, 119];
        for p in holes {
            d[p] = f32::NAN;
        }
        let labels = vec![0u32; w * h];
        let s = plane_fill(&mut d, &labels, w, 10, 0.5, 0.0, 100.0).unwrap();
        assert_eq!(s.filled, 4);
        for p in holes {
            assert!(
                (d[p] - truth(p)).abs() < 1e-4,
                "{p}: {} vs {}",
                d[p],
                truth(p)
            );
        }
    }

    #[test]
    fn min_pixels_measured_values_are_enough() {
        // A 2 x 2 segment with three measured values (not on a line) and a hole: exactly
        // min_pixels = 3 fix the plane d = 1 + x + 2 y, whose value at the hole is 4.
        let (w, h) = (3, 2);
        let labels: Vec<u32> = (0..w * h).map(|p| u32::from(p % w == 2)).collect();
        let mut d = vec![1.0, 2.0, 7.0, 3.0, f32::NAN, 7.0];
        let s = plane_fill(&mut d, &labels, w, 3, 0.5, 0.0, 10.0).unwrap();
        assert_eq!(
            s,
            PlaneFillStats {
                planes: 1,
                filled: 1
            }
        );
        assert!((d[4] - 4.0).abs() < 1e-5, "{}", d[4]);
        let mut d = vec![1.0, 2.0, 7.0, 3.0, f32::NAN, 7.0];
        assert_eq!(
            plane_fill(&mut d, &labels, w, 4, 0.5, 0.0, 10.0)
                .unwrap()
                .filled,
            0
        );
    }

    #[test]
    fn the_median_residual_is_the_upper_one_and_may_equal_max_residual() {
        // 4 x 4 measured values symmetric about their centre, so the fit is flat and exact; a
        // fifth row of holes. A checkerboard of 0 and 1: every residual is 0.5, the limit.
        let (w, h) = (4, 5);
        let labels = vec![0u32; w * h];
        let with_holes = |f: &dyn Fn(usize, usize) -> f32| -> Vec<f32> {
            (0..w * h)
                .map(|p| {
                    if p / w == 4 {
                        f32::NAN
                    } else {
                        f(p % w, p / w)
                    }
                })
                .collect()
        };
        let checker = with_holes(&|x, y| ((x + y) % 2) as f32);
        let mut d = checker.clone();
        assert_eq!(
            plane_fill(&mut d, &labels, w, 3, 0.5, -9.0, 9.0)
                .unwrap()
                .filled,
            4
        );
        assert!(d[4 * w..].iter().all(|&v| v == 0.5), "{:?}", &d[4 * w..]);
        let mut d = checker;
        assert_eq!(
            plane_fill(&mut d, &labels, w, 3, 0.49, -9.0, 9.0)
                .unwrap()
                .filled,
            0
        );
        // Centre 1, corners -1, edges 0: residuals eight 0, then eight 1 (the mean is 0). The
        // median of 16 is the 9th smallest, 1: over a limit of 0.5.
        let rings = with_holes(&|x, y| {
            let (ex, ey) = (x == 0 || x == 3, y == 0 || y == 3);
            match (ex, ey) {
                (true, true) => -1.0,
                (false, false) => 1.0,
                _ => 0.0,
            }
        });
        let mut d = rings.clone();
        assert_eq!(
            plane_fill(&mut d, &labels, w, 3, 0.5, -9.0, 9.0)
                .unwrap()
                .filled,
            0
        );
        let mut d = rings;
        assert_eq!(
            plane_fill(&mut d, &labels, w, 3, 1.0, -9.0, 9.0)
                .unwrap()
                .filled,
            4
        );
    }

    #[test]
    fn fill_planes_means_two_different_cut_values() {
        // Grey 20 | 30 | 36 in thirds of 4 columns: at step 16 the cut at offset 0 bins them
        // 1 1 2, the cut at offset 8 bins them 1 2 2. The middle third has no values: one cut
        // fills it from the left third's plane (4), the other from the right third's (6).
        let (w, h) = (12, 6);
        let img: Vec<u8> = (0..w * h).map(|p| [20, 30, 36][(p % w) / 4]).collect();
        let mut d: Vec<f32> = (0..w * h)
            .map(|p| [4.0, f32::NAN, 6.0][(p % w) / 4])
            .collect();
        fill_planes(&mut d, &img, w, 1, &[(16, 5)], 0.5).unwrap();
        assert!(
            d.iter()
                .enumerate()
                .all(|(p, &v)| v == [4.0, 5.0, 6.0][(p % w) / 4]),
            "{d:?}"
        );
    }

    #[test]
    fn fill_planes_keeps_to_the_measured_range_and_runs_every_pass() {
        // A ramp d = x + 1 over one colour with a hole at each end: the plane's value there (1
        // and 10) lies outside the measured range [2, 9], so fill_planes leaves both holes.
        let (w, h) = (10, 6);
        let img = vec![50u8; w * h];
        let mut d: Vec<f32> = (0..w * h).map(|p| (p % w + 1) as f32).collect();
        for y in 0..h {
            d[y * w] = f32::NAN;
            d[y * w + w - 1] = f32::NAN;
        }
        let mut one = d.clone();
        fill_planes(&mut one, &img, w, 1, &[(16, 5)], 1.0).unwrap();
        assert_eq!(one.iter().filter(|v| v.is_nan()).count(), 2 * h);
        // An infinite value is a hole, not the range's top: the ends stay, it is filled.
        let mut inf = d.clone();
        inf[2 * w + 5] = f32::INFINITY;
        fill_planes(&mut inf, &img, w, 1, &[(16, 5)], 1.0).unwrap();
        assert_eq!(inf.iter().filter(|v| v.is_nan()).count(), 2 * h);
        assert!((inf[2 * w + 5] - 6.0).abs() < 1e-4, "{}", inf[2 * w + 5]);
        // A hole inside the range: the first pass needs 1000 measured pixels and fills
        // nothing, the second does.
        let mut two = d.clone();
        two[2 * w + 4] = f32::NAN;
        fill_planes(&mut two, &img, w, 1, &[(16, 1000), (16, 5)], 1.0).unwrap();
        assert!((two[2 * w + 4] - 5.0).abs() < 1e-4, "{}", two[2 * w + 4]);
    }

    #[test]
    fn bins_keep_nine_bits_each() {
        // Step 1, offset 1: 254 and 255 bin to 255 and 256, two regions (a bin cut at 255 or
        // 8-bit fields would merge them).
        assert_eq!(
            quantised_regions(&[254, 255], 2, 1, 1, 1, 1).unwrap(),
            [0, 1]
        );
        // Offset 2, two channels: bins (256, 2) and (256, 3) overlap in 8-bit fields.
        assert_eq!(
            quantised_regions(&[254, 0, 254, 1], 2, 1, 2, 1, 2).unwrap(),
            [0, 1]
        );
        assert_eq!(
            quantised_regions(&[254, 0, 254, 0], 2, 1, 2, 1, 2).unwrap(),
            [0, 0]
        );
    }

    #[test]
    fn a_thin_segment_two_pixels_wide_is_a_plane() {
        // Two columns by 100 rows: the slope across is poorly conditioned (det / scale**3
        // about 4e-7) but a plane; its holes take it.
        let (w, h) = (2, 100);
        let truth = |p: usize| 3.0 + 0.5 * (p % w) as f32 + 0.05 * (p / w) as f32;
        let mut d: Vec<f32> = (0..w * h).map(truth).collect();
        let holes = [10 * w, 50 * w + 1, 90 * w];
        for &p in &holes {
            d[p] = f32::NAN;
        }
        let labels = vec![0u32; w * h];
        let s = plane_fill(&mut d, &labels, w, 3, 0.5, 0.0, 20.0).unwrap();
        assert_eq!(
            s,
            PlaneFillStats {
                planes: 1,
                filled: 3
            }
        );
        for &p in &holes {
            assert!(
                (d[p] - truth(p)).abs() < 1e-3,
                "{p}: {} vs {}",
                d[p],
                truth(p)
            );
        }
    }

    #[test]
    fn collinear_points_are_no_plane_even_with_rounding_in_their_centre() {
        // Five measured pixels on the line x = 3 y + 1 (one label, not connected: plane_fill
        // takes any labels) span no plane. Their centre (8.2, 2.4) is inexact, so the normal
        // matrix's determinant is a rounding residue, not exactly 0: only the relative
        // threshold refuses it (with `<= 0` the solve filled the hole off the line).
        let (w, h) = (17, 6);
        let line = [(1, 0), (4, 1), (7, 2), (13, 4), (16, 5)];
        let mut d = vec![5.0f32; w * h];
        let mut labels = vec![1u32; w * h];
        for &(x, y) in &line {
            labels[y * w + x] = 0;
            d[y * w + x] = 2.0 + 0.1 * y as f32;
        }
        let hole = 5 * w; // (0, 5), off the line
        labels[hole] = 0;
        d[hole] = f32::NAN;
        let s = plane_fill(&mut d, &labels, w, 3, 1.0, f32::NEG_INFINITY, f32::INFINITY).unwrap();
        assert_eq!(s, PlaneFillStats::default());
        assert!(d[hole].is_nan(), "{}", d[hole]);
    }

    #[test]
    fn fill_planes_odd_step_offsets_by_half_rounded_down() {
        // Grey 1 | 2 at step 3: offset 0 bins them 0 0 (one region, a step no plane fits),
        // offset 1 (3 / 2) bins them 0 1 (two flat regions); offset 2 would bin them 1 1.
        let (w, h) = (8, 4);
        let img: Vec<u8> = (0..w * h).map(|p| if p % w < 4 { 1 } else { 2 }).collect();
        let mut d: Vec<f32> = (0..w * h)
            .map(|p| if p % w < 4 { 2.0 } else { 8.0 })
            .collect();
        d[w + 1] = f32::NAN;
        d[2 * w + 6] = f32::NAN;
        fill_planes(&mut d, &img, w, 1, &[(3, 3)], 0.5).unwrap();
        assert_eq!((d[w + 1], d[2 * w + 6]), (2.0, 8.0));
    }

    #[test]
    fn fill_planes_fills_from_one_measured_value() {
        // Every measured value equal (lo == hi): the pass runs and the hole takes it.
        let (w, h) = (5, 4);
        let img = vec![50u8; w * h];
        let mut d = vec![3.0f32; w * h];
        d[2 * w + 2] = f32::NAN;
        fill_planes(&mut d, &img, w, 1, &[(16, 5)], 1.0).unwrap();
        assert_eq!(d[2 * w + 2], 3.0);
    }

    /// The refit of one segment written out: three fits, each on the pixels whose residual to
    /// the previous one is below max(1, 2 * upper median); the last median against
    /// `max_residual`; values in `[lo, hi]`.
    fn segment_ref(d: &[f32], w: usize, max_residual: f32, lo: f32, hi: f32) -> Vec<f32> {
        let meas: Vec<usize> = (0..d.len()).filter(|&p| d[p].is_finite()).collect();
        let pts: Vec<(f32, f32, f32)> = meas
            .iter()
            .map(|&p| ((p % w) as f32, (p / w) as f32, d[p]))
            .collect();
        let n = pts.len() as f64;
        let cx = pts.iter().map(|p| p.0 as f64).sum::<f64>() / n;
        let cy = pts.iter().map(|p| p.1 as f64).sum::<f64>() / n;
        let mut keep = vec![true; pts.len()];
        let (mut plane, mut med) = ([0.0f64; 3], 0.0f32);
        for _ in 0..3 {
            plane = fit_plane(&pts, &keep, cx, cy).expect("a plane");
            let res: Vec<f32> = pts
                .iter()
                .map(|&(x, y, d)| {
                    let e = plane[0] * (x as f64 - cx) + plane[1] * (y as f64 - cy) + plane[2];
                    (e - d as f64).abs() as f32
                })
                .collect();
            let mut sorted = res.clone();
            sorted.sort_by(f32::total_cmp);
            med = sorted[sorted.len() / 2];
            let cut = (2.0 * med).max(1.0);
            keep = res.iter().map(|&r| r < cut).collect();
        }
        let mut out = d.to_vec();
        if med <= max_residual {
            for (p, o) in out.iter_mut().enumerate() {
                let (x, y) = ((p % w) as f64, (p / w) as f64);
                let v = (plane[0] * (x - cx) + plane[1] * (y - cy) + plane[2]) as f32;
                if !o.is_finite() && v >= lo && v <= hi {
                    *o = v;
                }
            }
        }
        out
    }

    #[test]
    fn plane_fill_equals_the_three_refits_written_out() {
        // One segment: a plane with outliers of every size (so later refits still drop some),
        // and holes; integer-valued residuals hit the cut exactly.
        let (w, h) = (9, 7);
        let mut rng = crate::testing::xorshift(0x2545_f491_4f6c_dd1d);
        let mut next = move |n: u64| rng() % n;
        let labels = vec![0u32; w * h];
        let (mut changed, mut filled) = (0, 0);
        for round in 0..200 {
            let (a, b) = (next(5) as f32 - 2.0, next(5) as f32 - 2.0);
            let d: Vec<f32> = (0..w * h)
                .map(|p| {
                    let v = 10.0 + a * (p % w) as f32 + b * (p / w) as f32;
                    match next(10) {
                        0 => f32::NAN,
                        1 | 2 => v + next(25) as f32 - 12.0,
                        3 => v + (next(9) as f32 - 4.0) * 0.25,
                        _ => v,
                    }
                })
                .collect();
            let max_residual = [0.25, 1.0, 3.0][round % 3];
            let want = segment_ref(&d, w, max_residual, -40.0, 60.0);
            let mut got = d.clone();
            let st = plane_fill(&mut got, &labels, w, 3, max_residual, -40.0, 60.0).unwrap();
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "round {round}");
            filled += st.filled;
            changed += (bits(&got) != bits(&d)) as usize;
        }
        assert!(
            changed > 50 && filled > 200,
            "{changed} segments, {filled} holes"
        );
    }

    /// A zero-filled, never-touched private mapping of `len` values that reserves no memory
    /// (`MAP_NORESERVE`): a slice longer than u32 counts, for a guard that must refuse it before
    /// reading it. `None` where the system will not map it (strict overcommit).
    #[cfg(target_os = "linux")]
    pub(crate) struct Unbacked<T> {
        ptr: *mut T,
        len: usize,
    }

    #[cfg(target_os = "linux")]
    extern "C" {
        fn mmap(addr: *mut u8, len: usize, prot: i32, flags: i32, fd: i32, off: i64) -> *mut u8;
        fn munmap(addr: *mut u8, len: usize) -> i32;
    }

    #[cfg(target_os = "linux")]
    impl<T: crate::alloc::ZeroBits> Unbacked<T> {
        pub(crate) fn new(len: usize) -> Option<Self> {
            const PROT_RW: i32 = 0x1 | 0x2;
            const FLAGS: i32 = 0x02 | 0x20 | 0x4000; // MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE
            let bytes = len.checked_mul(std::mem::size_of::<T>())?;
            // SAFETY: a fresh anonymous mapping; the result is checked below.
            let p = unsafe { mmap(std::ptr::null_mut(), bytes, PROT_RW, FLAGS, -1, 0) };
            (p as isize != -1 && !p.is_null()).then(|| Unbacked { ptr: p.cast(), len })
        }

        pub(crate) fn slice(&mut self) -> &mut [T] {
            // SAFETY: `len` page-aligned, zero-filled values (valid by `ZeroBits`), owned here.
            unsafe { std::slice::from_raw_parts_mut(self.ptr, self.len) }
        }
    }

    #[cfg(target_os = "linux")]
    impl<T> Drop for Unbacked<T> {
        fn drop(&mut self) {
            // SAFETY: the mapping made by `new`, unmapped once.
            unsafe { munmap(self.ptr.cast(), self.len * std::mem::size_of::<T>()) };
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn plane_fill_refuses_maps_past_its_32_bit_pixel_numbers() {
        // It lists pixels and counts them per segment in u32 and had no guard of its own (the
        // binding checks first): 2^32 pixels of one segment overflowed its count (a panic in a
        // debug build, a wrapped count in release). Refused from the length, before reading.
        let n = crate::image::MAX_PIXELS + 1;
        let (Some(mut d), Some(mut l)) = (Unbacked::<f32>::new(n), Unbacked::<u32>::new(n)) else {
            eprintln!("skipped: the system maps no 16 GiB without reserving it");
            return;
        };
        let (d, l) = (d.slice(), l.slice());
        for (w, h) in [(1 << 16, 1 << 16), (3, n.div_ceil(3)), (1, n), (n, 1)] {
            assert_eq!(
                plane_fill(d, l, w, 3, 1.0, 0.0, 9.0),
                Err(crate::CoreError::TooLarge {
                    width: w,
                    height: h,
                    max_pixels: crate::image::MAX_PIXELS,
                }),
                "{w}x{h}"
            );
        }
    }

    #[test]
    #[should_panic(expected = "labels must be below the pixel count")]
    fn a_label_at_the_pixel_count_is_refused() {
        plane_fill(&mut [1.0, f32::NAN], &[0, 2], 2, 3, 1.0, 0.0, 9.0).unwrap();
    }
}
