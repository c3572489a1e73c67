//! Moravec interest operator with the squares put back (algorithms.md C.1, densities of C.10).
//!
//! `M(x, y) = min(S_h, S_v, S_d, S_a)` where each `S` is the 5x5 window sum of squared differences
//! of adjacent pixels in one direction. Everything is `f32` in a fixed order (squared difference,
//! horizontal 5-sum left to right, then vertical 5-sum top to bottom: no running sums), so the
//! NumPy reference reproduces every value bit for bit.

use rayon::prelude::*;

use crate::alloc::{try_concat, try_grow, try_reserve_len, try_zeroed};
use crate::error::{CoreError, Result};
use crate::image::ImageView;
use crate::simd::simd_fn;

/// Half-size of the Moravec window (5x5, the paper's size).
pub const MORAVEC_HALF: usize = 2;
/// Pixels at the border where `M` is not defined (set to 0): the 5x5 window plus the one-pixel
/// step of the differences, and the 7x7 similarity window (radius 3) must fit in the image.
pub const BORDER: usize = 3;

/// Parameters of [`interest_points`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterestParams {
    /// Threshold relative to the image's largest `M` (C.10: 0.1 % keeps the dense set that gives
    /// thousands of correct matches; the paper's 1 % filters little more).
    pub rel_threshold: f32,
    /// Half-size of the non-maximum suppression neighbourhood (C.10: 1 = 3x3; 5x5 sets the
    /// count far too low).
    pub nms_half: usize,
    /// The threshold is `rel_threshold` times the largest `M` of the `tile x tile` block holding
    /// the pixel (0 = of the whole image, C.10). 64 px (a few 40x40 compatibility windows)
    /// keeps weakly textured areas represented (C.3 "per grid cell for spread"): wood2's plank
    /// and laundry's basket get points, so the 4x4 coverage reaches 16/16.
    pub tile: usize,
    /// ... but never below `floor_rel` times the image's largest `M` (1e-4: truly flat areas,
    /// sensor noise only, stay empty).
    pub floor_rel: f32,
}

impl Default for InterestParams {
    fn default() -> Self {
        InterestParams {
            rel_threshold: 1e-3,
            nms_half: 1,
            tile: 64,
            floor_rel: 1e-4,
        }
    }
}

/// One interest point: integer pixel position and its Moravec value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterestPoint {
    pub x: u32,
    pub y: u32,
    pub value: f32,
}

/// Output rows per parallel task of [`moravec`]: each task recomputes the `2 * MORAVEC_HALF`
/// rows of horizontal sums it shares with its neighbours (12 % extra at 32 rows).
const ROWS_PER_TASK: usize = 32;

/// Rows of horizontal sums a vertical 5-sum reads: a ring of this many rows per direction
/// (row `y` in slot `y % RING`) keeps a task's sums in L1 instead of a whole band of them.
const RING: usize = 2 * MORAVEC_HALF + 1;

/// The four steps `(sx, sy)`: horizontal, vertical, 45 degrees (down-right), 135 (up-right).
const DIRS: [(usize, isize); 4] = [(1, 0), (0, 1), (1, 1), (1, -1)];

simd_fn! {
/// Horizontal 5-sums of the squared differences between row `a` and row `b` shifted by `sx`:
/// `out[x] = sq[x-2] + sq[x-1] + sq[x] + sq[x+1] + sq[x+2]` (left to right, `f32`) for
/// `x in 2..w-2-sx`; the other entries of `out` are left as they are (never read: they only
/// feed the zeroed border of `M`). `sq` is scratch of at least `w` values; `w >= 5 + sx`.
fn hsum_row(a: &[f32], b: &[f32], sx: usize, sq: &mut [f32], out: &mut [f32]) {
    let w = a.len();
    let r = MORAVEC_HALF;
    let m = w - 2 * r - sx;
    let sq = &mut sq[..w - sx];
    for ((o, &p), &q) in sq.iter_mut().zip(&a[..w - sx]).zip(&b[sx..]) {
        let d = p - q;
        *o = d * d;
    }
    // One pass with five loads instead of a copy and four read-modify-write passes.
    let (s0, s1, s2, s3, s4) = (&sq[..m], &sq[1..m + 1], &sq[2..m + 2], &sq[3..m + 3], &sq[4..m + 4]);
    for (i, o) in out[r..r + m].iter_mut().enumerate() {
        *o = (((s0[i] + s1[i]) + s2[i]) + s3[i]) + s4[i];
    }
}
}

simd_fn! {
/// One row of `M` over `out.len()` columns: per direction the vertical 5-sum of its horizontal
/// sums (top to bottom), then the minimum over the four directions, in one pass.
/// `hs[dir][k]` holds row `y - 2 + k` from the first output column on.
fn min_row(hs: &[[&[f32]; RING]; 4], out: &mut [f32]) {
    let n = out.len();
    // Slicing every row to `n` first lets the compiler drop the bounds checks and vectorise.
    let [a, b, c, d] = hs.map(|rows| rows.map(|row| &row[..n]));
    let vsum = |rows: &[&[f32]; RING], x: usize| {
        (((rows[0][x] + rows[1][x]) + rows[2][x]) + rows[3][x]) + rows[4][x]
    };
    for (x, o) in out.iter_mut().enumerate() {
        *o = vsum(&a, x).min(vsum(&b, x)).min(vsum(&c, x)).min(vsum(&d, x));
    }
}
}

/// The Moravec interest map `M` (f32, row-major `(H, W)`); 0 within [`BORDER`] px of the edge.
/// Row bands in parallel; every value is computed in the fixed order of the module docs, so the
/// map does not depend on the thread count.
///
/// A failed allocation of the map or of a thread's scratch (84 bytes a column) is
/// [`crate::CoreError::OutOfMemory`].
pub fn moravec<'a>(img: impl Into<ImageView<'a>>) -> Result<Vec<f32>> {
    let img = &img.into();
    let (w, h) = img.size();
    let mut out = try_zeroed::<f32>(w * h, "the Hopfield matcher's interest map")?;
    if w < 2 * BORDER + 1 || h < 2 * BORDER + 1 {
        return Ok(out);
    }
    let r = MORAVEC_HALF;
    let row = |y: usize| &img.data[y * w..(y + 1) * w];
    let inner = &mut out[BORDER * w..(h - BORDER) * w];
    // A thread's scratch is allocated checked in rayon's init; a failure is recorded here (the
    // first one) and that thread's bands are skipped: the map is then not returned.
    const SCRATCH: &str = "the Hopfield matcher's interest-map scratch";
    let failed: std::sync::Mutex<Option<CoreError>> = std::sync::Mutex::new(None);
    inner
        .par_chunks_mut(ROWS_PER_TASK * w)
        .enumerate()
        .for_each_init(
            || -> Result<(Vec<f32>, Vec<f32>)> {
                let ring = try_zeroed::<f32>(4 * RING * w, SCRATCH)?;
                Ok((ring, try_zeroed::<f32>(w, SCRATCH)?))
            },
            |bufs, (t, band)| {
                let (ring, sq) = match bufs {
                    Ok((ring, sq)) => (ring, sq),
                    Err(e) => {
                        let mut f = failed.lock().unwrap_or_else(|p| p.into_inner());
                        f.get_or_insert_with(|| e.clone());
                        return;
                    }
                };
                let y0 = BORDER + t * ROWS_PER_TASK;
                // Horizontal sums of image row y (y - 1 and y + 1 stay inside the image: rows
                // y0 - 2 ..= y_last + 2 with BORDER = 3), every direction, into its ring slot.
                let mut fill = |ring: &mut [f32], y: usize| {
                    for (d, &(sx, sy)) in DIRS.iter().enumerate() {
                        let yy = (y as isize + sy) as usize;
                        let o = (d * RING + y % RING) * w;
                        hsum_row(row(y), row(yy), sx, sq, &mut ring[o..o + w]);
                    }
                };
                for y in y0 - r..y0 + r {
                    fill(ring, y);
                }
                for (i, orow) in band.chunks_mut(w).enumerate() {
                    let y = y0 + i;
                    fill(ring, y + r);
                    let hs: [[&[f32]; RING]; 4] = std::array::from_fn(|d| {
                        std::array::from_fn(|k| {
                            let o = (d * RING + (y + k - r) % RING) * w + BORDER;
                            &ring[o..o + w - 2 * BORDER]
                        })
                    });
                    min_row(&hs, &mut orow[BORDER..w - BORDER]);
                }
            },
        );
    match failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

/// Interest points of `img`: local maxima of [`moravec`] over a `(2 nms_half + 1)^2`
/// neighbourhood (strictly greater than neighbours earlier in raster order, at least as large as
/// later ones), with `M > 0` and `M >= max(rel_threshold * max_tile(M), floor_rel * max(M))`;
/// raster order.
pub fn interest_points<'a>(
    img: impl Into<ImageView<'a>>,
    p: &InterestParams,
) -> Result<Vec<InterestPoint>> {
    let img = img.into();
    let m = moravec(img)?;
    let (w, h) = img.size();
    select_points(&m, w, h, p)
}

/// Image rows per parallel task of [`select_points`].
const SELECT_ROWS: usize = 16;

simd_fn! {
/// Peak flags of one row segment for the 3x3 neighbourhood: `mask[i]` is 1 when the centre
/// `v = mid[i + 1]` passes `v > 0`, `v >= thr`, is strictly greater than its neighbours earlier
/// in raster order (`up[i..i + 3]`, `mid[i]`) and at least as large as the later ones
/// (`mid[i + 2]`, `dn[i..i + 3]`). Non-short-circuit `&` so the loop vectorises.
fn peak_mask(up: &[f32], mid: &[f32], dn: &[f32], thr: f32, mask: &mut [u8]) {
    let n = mask.len();
    let (up, mid, dn) = (&up[..n + 2], &mid[..n + 2], &dn[..n + 2]);
    for (i, o) in mask.iter_mut().enumerate() {
        let v = mid[i + 1];
        let keep = (v > 0.0)
            & (v >= thr)
            & (v > up[i])
            & (v > up[i + 1])
            & (v > up[i + 2])
            & (v > mid[i])
            & (v >= mid[i + 2])
            & (v >= dn[i])
            & (v >= dn[i + 1])
            & (v >= dn[i + 2]);
        *o = u8::from(keep);
    }
}
}

/// Largest value of `seg` and 0, eight lanes at a time: `f32::max` is exact and ignores NaN,
/// so any order gives the value of a sequential fold.
fn seg_max(seg: &[f32]) -> f32 {
    let mut lanes = [0.0f32; 8];
    let mut chunks = seg.chunks_exact(8);
    for ch in &mut chunks {
        for (l, &v) in lanes.iter_mut().zip(ch) {
            *l = l.max(v);
        }
    }
    chunks
        .remainder()
        .iter()
        .chain(&lanes)
        .copied()
        .fold(0.0, f32::max)
}

/// Length of the blocks of [`window_max`] along a line of `n` values: the window's `2 r + 1`,
/// at most the line (saturating: `r` up to `usize::MAX`).
fn block_len(n: usize, r: usize) -> usize {
    r.saturating_mul(2).saturating_add(1).min(n).max(1)
}

/// Index `i`'s window `[i - r, i + r]` clipped to `0..n` as `(a, b)`, and which block maxima
/// give its maximum: blocks of `k` from 0 hold prefix maxima `pre` and suffix maxima `suf`
/// (a suffix ends at its block's end or the line's). A window spans at most two blocks; within
/// one it starts at the block (then `pre[b]`) or ends at the block's or line's end (`suf[a]`).
#[inline]
fn window_of(i: usize, r: usize, n: usize, k: usize) -> (usize, usize, bool, bool) {
    let (a, b) = (i.saturating_sub(r), i.saturating_add(r).min(n - 1));
    let two = a / k != b / k;
    (a, b, two || a % k != 0, two || a % k == 0)
}

/// Maximum of every pixel's `(2 r + 1)^2` neighbourhood clipped to the `w x h` map (`f32::max`:
/// a NaN is skipped), by van Herk / Gil-Werman block maxima along rows, then along columns
/// (whole rows at a time): O(1) per pixel whatever `r`. Each value is one of the window's, so
/// `v < max` proves a larger neighbour. A failed allocation (12 bytes a pixel) is
/// [`CoreError::OutOfMemory`].
fn window_max(m: &[f32], w: usize, h: usize, r: usize) -> Result<Vec<f32>> {
    const WHAT: &str = "the Hopfield matcher's interest-point suppression";
    let mut out = try_zeroed::<f32>(w * h, WHAT)?;
    let mut pre = try_zeroed::<f32>(w * h, WHAT)?;
    let mut suf = try_zeroed::<f32>(w * h, WHAT)?;
    // Rows.
    let k = block_len(w, r);
    for y in 0..h {
        let o = y * w;
        let (src, p, s) = (&m[o..o + w], &mut pre[o..o + w], &mut suf[o..o + w]);
        for i in 0..w {
            p[i] = if i % k == 0 {
                src[i]
            } else {
                p[i - 1].max(src[i])
            };
        }
        for i in (0..w).rev() {
            let end = i + 1 == w || (i + 1) % k == 0;
            s[i] = if end { src[i] } else { s[i + 1].max(src[i]) };
        }
        for (i, o) in out[o..o + w].iter_mut().enumerate() {
            let (a, b, use_suf, use_pre) = window_of(i, r, w, k);
            *o = match (use_suf, use_pre) {
                (true, true) => s[a].max(p[b]),
                (true, false) => s[a],
                _ => p[b],
            };
        }
    }
    // Columns, a whole row of them at a time.
    let k = block_len(h, r);
    for y in 0..h {
        let o = y * w;
        if y % k == 0 {
            pre[o..o + w].copy_from_slice(&out[o..o + w]);
        } else {
            let (done, row) = pre.split_at_mut(o);
            for ((d, &q), &v) in row[..w].iter_mut().zip(&done[o - w..]).zip(&out[o..o + w]) {
                *d = q.max(v);
            }
        }
    }
    for y in (0..h).rev() {
        let o = y * w;
        if y + 1 == h || (y + 1) % k == 0 {
            suf[o..o + w].copy_from_slice(&out[o..o + w]);
        } else {
            let (row, next) = suf.split_at_mut(o + w);
            for ((d, &q), &v) in row[o..].iter_mut().zip(&next[..w]).zip(&out[o..o + w]) {
                *d = q.max(v);
            }
        }
    }
    for y in 0..h {
        let (a, b, use_suf, use_pre) = window_of(y, r, h, k);
        let (sa, pb) = (&suf[a * w..(a + 1) * w], &pre[b * w..(b + 1) * w]);
        for ((o, &s), &p) in out[y * w..(y + 1) * w].iter_mut().zip(sa).zip(pb) {
            *o = match (use_suf, use_pre) {
                (true, true) => s.max(p),
                (true, false) => s,
                _ => p,
            };
        }
    }
    Ok(out)
}

/// Selection step of [`interest_points`] on a precomputed map (row bands in parallel, raster
/// order). A failed allocation of the list is [`crate::CoreError::OutOfMemory`]; a map past
/// [`crate::image::check_index_range`] is [`crate::CoreError::TooLarge`].
pub fn select_points(
    m: &[f32],
    w: usize,
    h: usize,
    p: &InterestParams,
) -> Result<Vec<InterestPoint>> {
    // Points hold their column and row in u32: past the limit they wrapped (the binding
    // checks the shape first; a Rust caller reaches this alone).
    crate::image::check_index_range(w, h)?;
    if w == 0 {
        return Ok(Vec::new());
    }
    // Largest M per tile (a single tile covering the image when `tile == 0`). A tile larger
    // than the image is that single tile too: `tile * w` of a huge tile wrapped to 0 and
    // panicked (`chunk_size must not be zero`) instead of using one tile.
    let tile = if p.tile == 0 {
        w.max(h)
    } else {
        p.tile.min(w.max(h))
    };
    let tiles_x = w.div_ceil(tile);
    let tile_max: Vec<f32> = m
        .par_chunks(tile * w)
        .flat_map_iter(|band| {
            let mut tm = vec![0.0f32; tiles_x];
            for row in band.chunks(w) {
                for (t, seg) in row.chunks(tile).enumerate() {
                    tm[t] = tm[t].max(seg_max(seg));
                }
            }
            tm
        })
        .collect();
    // The image's largest M is the largest tile maximum (max is exact: same value).
    let max = tile_max.iter().copied().fold(0.0f32, f32::max);
    if max <= 0.0 {
        return Ok(Vec::new());
    }
    let floor = max * p.floor_rel;
    let r = p.nms_half;
    // Beyond 3x3, the neighbourhood's maximum first: a value below it has a larger neighbour,
    // so only the neighbourhood maxima are scanned (the scan of every candidate's window took
    // 2.3 s at nms_half 1000 on 0.67 Mpx, now one pass over the map).
    let wmax = if r != 1 {
        window_max(m, w, h, r)?
    } else {
        Vec::new()
    };
    // Is `v` (at x, y) above its later and strictly above its earlier neighbours?
    // Saturating: `x + r` of a window wider than any image (nms_half up to usize::MAX) wrapped
    // to a window ending before the point.
    let is_peak = |x: usize, y: usize, v: f32| -> bool {
        let (x0, x1) = (x.saturating_sub(r), x.saturating_add(r).min(w - 1));
        for yy in y.saturating_sub(r)..=y.saturating_add(r).min(h - 1) {
            let nrow = &m[yy * w..(yy + 1) * w];
            for (xx, &n) in nrow.iter().enumerate().take(x1 + 1).skip(x0) {
                let earlier = yy < y || (yy == y && xx < x);
                if n > v || (earlier && n == v) {
                    return false;
                }
            }
        }
        true
    };
    let y_end = h.saturating_sub(BORDER);
    const POINTS: &str = "the Hopfield matcher's interest points";
    let rows: Vec<usize> = (BORDER..y_end).step_by(SELECT_ROWS).collect();
    // Each task's points, grown checked (as `push` grows) into room reserved for every task.
    let mut per_task: Vec<Result<Vec<InterestPoint>>> = Vec::new();
    try_reserve_len(&mut per_task, rows.len(), POINTS)?;
    rows.par_iter()
        .map(|&ya| {
            let mut out = Vec::new();
            let mut mask = try_zeroed::<u8>(w, POINTS)?;
            for y in ya..(ya + SELECT_ROWS).min(y_end) {
                let row = &m[y * w..(y + 1) * w];
                let tiles = &tile_max[(y / tile) * tiles_x..(y / tile + 1) * tiles_x];
                for (t, &tm) in tiles.iter().enumerate() {
                    let thr = (tm * p.rel_threshold).max(floor);
                    let (x0, x1) = (
                        (t * tile).max(BORDER),
                        ((t + 1) * tile).min(w.saturating_sub(BORDER)),
                    );
                    if x0 >= x1 {
                        continue;
                    }
                    if r != 1 {
                        for (x, &v) in row.iter().enumerate().take(x1).skip(x0) {
                            // Strictly greater than the neighbours earlier in raster order, at
                            // least as large as the later ones (deterministic ties); the centre
                            // compares equal to itself and is neither.
                            let beaten = wmax[y * w + x] > v;
                            if v > 0.0 && v >= thr && !beaten && is_peak(x, y, v) {
                                try_grow(&mut out, 1, POINTS)?;
                                out.push(InterestPoint {
                                    x: x as u32,
                                    y: y as u32,
                                    value: v,
                                });
                            }
                        }
                        continue;
                    }
                    // The 3x3 case (C.10's default) as flags over the segment, then a scan of
                    // the few set ones: BORDER >= 1 keeps every neighbour inside the image.
                    let nb = |yy: usize| &m[yy * w + x0 - 1..yy * w + x1 + 1];
                    let flags = &mut mask[..x1 - x0];
                    peak_mask(nb(y - 1), nb(y), nb(y + 1), thr, flags);
                    // Eight flags (0 or 1 bytes) at a time as one word: most are all zero.
                    let mut base = x0;
                    for chunk in flags.chunks(8) {
                        let mut word = [0u8; 8];
                        word[..chunk.len()].copy_from_slice(chunk);
                        let mut bits = u64::from_le_bytes(word);
                        while bits != 0 {
                            let x = base + bits.trailing_zeros() as usize / 8;
                            bits &= bits - 1;
                            try_grow(&mut out, 1, POINTS)?;
                            out.push(InterestPoint {
                                x: x as u32,
                                y: y as u32,
                                value: row[x],
                            });
                        }
                        base += chunk.len();
                    }
                }
            }
            Ok(out)
        })
        .collect_into_vec(&mut per_task);
    try_concat(per_task.into_iter().collect::<Result<_>>()?, POINTS)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Run by [`interest_scratch_and_points_too_large_to_allocate_are_an_error`] in a child
    /// process, under an address-space limit of `SV_OOM_MIB` MiB more than is mapped: "map",
    /// the Moravec map of a 2^18 x 7 image (7 MiB) fits in 10 MiB, its thread's scratch
    /// (20 MiB) does not; "points", the ~2^20 peaks of a 2^18 x 22 map (12 MiB) do not fit in 4.
    #[cfg(target_os = "linux")]
    #[test]
    #[ignore = "a child of interest_scratch_and_points_too_large_to_allocate_are_an_error"]
    fn interest_under_a_memory_limit() {
        let Some(which) = std::env::var_os("SV_OOM_WHICH") else {
            return;
        };
        let w = 1usize << 18;
        rayon::join(|| (), || ()); // the pool's thread started before the limit
        let limit = |mib: usize| {
            let vm = crate::segment::tests::vm_size();
            crate::segment::tests::limit_address_space(vm + (mib << 20));
        };
        let out = if which == "map" {
            let data = vec![0.5f32; w * 7];
            let img = ImageView::new(w, 7, &data).unwrap();
            limit(10);
            moravec(img).map(|m| m.len())
        } else {
            // 2 at even x and y, 1 elsewhere: every even pair inside the border is a peak.
            let h = 22;
            let m: Vec<f32> = (0..w * h)
                .map(|i| {
                    if (i % w).is_multiple_of(2) && (i / w).is_multiple_of(2) {
                        2.0
                    } else {
                        1.0
                    }
                })
                .collect();
            let p = InterestParams {
                tile: 0,
                rel_threshold: 0.0,
                floor_rel: 0.0,
                nms_half: 1,
            };
            limit(4);
            select_points(&m, w, h, &p).map(|v| v.len())
        };
        match out {
            Ok(n) => println!("child: {n} values"),
            Err(e) => println!("child: error: {e}"),
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn interest_scratch_and_points_too_large_to_allocate_are_an_error() {
        // moravec's per-thread scratch (vec! in rayon's init) and select_points' per-task point
        // lists (push) were allocated unchecked: a failed allocation aborted the process.
        for (which, want) in [
            (
                "map",
                "the Hopfield matcher's interest-map scratch needs 20.00 MiB (20971520 bytes)",
            ),
            ("points", "the Hopfield matcher's interest points needs "),
        ] {
            let stdout = crate::segment::tests::run_oom_child_with(
                "matching::hopfield::interest::tests::interest_under_a_memory_limit",
                Some(("SV_OOM_WHICH", which)),
            );
            let want = format!("child: error: out of memory: {want}");
            assert!(stdout.contains(&want), "{which}: {want} not in {stdout}");
        }
    }

    /// A tile of any size beyond the image's is the whole image (`tile == 0`), never a
    /// wrapped `tile * w` (a zero chunk size: a panic).
    #[test]
    fn huge_tile_is_the_whole_image() {
        let (w, h) = (23, 17);
        let m: Vec<f32> = (0..w * h).map(|i| ((i * 7919) % 101) as f32).collect();
        let at = |tile| {
            let p = InterestParams {
                tile,
                ..InterestParams::default()
            };
            select_points(&m, w, h, &p).unwrap()
        };
        let whole = at(0);
        assert!(!whole.is_empty());
        for tile in [24, 1 << 40, usize::MAX / 2 + 1, usize::MAX] {
            let got = at(tile);
            assert_eq!(got.len(), whole.len(), "tile {tile}");
            assert!(got
                .iter()
                .zip(&whole)
                .all(|(a, b)| (a.x, a.y) == (b.x, b.y)));
        }
    }

    /// The general neighbourhood (`nms_half` 3) reaches the map's last column and row: a
    /// larger value there, 3 px from a candidate at `x = w - 4` (or `y = h - 4`), suppresses it;
    /// a lone value away from the edges stays.
    #[test]
    fn neighbourhood_reaches_the_last_column_and_row() {
        let (w, h) = (20, 20);
        let mut m = vec![0.0f32; w * h];
        for (x, y, v) in [
            (16, 5, 1.0),
            (19, 5, 2.0),
            (5, 16, 1.0),
            (5, 19, 2.0),
            (8, 8, 1.0),
        ] {
            m[y * w + x] = v;
        }
        let p = InterestParams {
            nms_half: 3,
            ..InterestParams::default()
        };
        let got: Vec<(u32, u32)> = select_points(&m, w, h, &p)
            .unwrap()
            .iter()
            .map(|q| (q.x, q.y))
            .collect();
        assert_eq!(got, [(8, 8)]);
    }

    /// Deterministic integers in `0..levels`.
    fn noise(n: usize, seed: u64, levels: u64) -> Vec<u64> {
        let mut rng = crate::testing::xorshift(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
        (0..n).map(|_| rng() % levels).collect()
    }

    /// `M` straight from its definition (C.1) at one pixel: per direction the 5x5 window of
    /// squared differences, each window row summed left to right, the rows top to bottom (the
    /// module's fixed `f32` order), then the minimum of the four.
    fn moravec_at(img: &[f32], w: usize, x: usize, y: usize) -> f32 {
        let px = |x: usize, y: usize| img[y * w + x];
        let mut best = f32::INFINITY;
        for (sx, sy) in [(1isize, 0isize), (0, 1), (1, 1), (1, -1)] {
            let mut rows = [0.0f32; 5];
            for (k, r) in rows.iter_mut().enumerate() {
                let v = y + k - 2;
                let sq = |u: usize| {
                    let d = px(u, v) - px((u as isize + sx) as usize, (v as isize + sy) as usize);
                    d * d
                };
                *r = (((sq(x - 2) + sq(x - 1)) + sq(x)) + sq(x + 1)) + sq(x + 2);
            }
            let s = (((rows[0] + rows[1]) + rows[2]) + rows[3]) + rows[4];
            best = best.min(s);
        }
        best
    }

    /// Every value of the map, bit for bit, on sizes from the smallest with an interior (7 x 7)
    /// to one of more than a task's 32 rows, and 0 within 3 px of the edges.
    #[test]
    fn moravec_equals_the_definition_at_every_pixel() {
        for (w, h, seed) in [(7, 7, 1), (8, 9, 2), (6, 12, 3), (23, 41, 4), (40, 75, 5)] {
            let img: Vec<f32> = noise(w * h, seed, 251)
                .into_iter()
                .map(|k| k as f32 / 251.0)
                .collect();
            let m = moravec(ImageView::new(w, h, &img).expect("valid")).unwrap();
            for y in 0..h {
                for x in 0..w {
                    let inside = (BORDER..w.saturating_sub(BORDER)).contains(&x)
                        && (BORDER..h.saturating_sub(BORDER)).contains(&y);
                    let want = if inside {
                        moravec_at(&img, w, x, y)
                    } else {
                        0.0
                    };
                    assert_eq!(
                        m[y * w + x].to_bits(),
                        want.to_bits(),
                        "{w}x{h} at ({x}, {y})"
                    );
                }
            }
        }
    }

    /// Each pixel's tile maximum by brute force (`tile` 0: one tile over the map), the
    /// threshold's base in [`select_brute`].
    fn tile_max_brute(m: &[f32], w: usize, h: usize, tile: usize) -> Vec<f32> {
        let tile = if tile == 0 {
            w.max(h)
        } else {
            tile.min(w.max(h))
        };
        let mut out = vec![0.0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let (tx, ty) = (x / tile * tile, y / tile * tile);
                let mut tmax = 0.0f32;
                for yy in ty..(ty + tile).min(h) {
                    for xx in tx..(tx + tile).min(w) {
                        tmax = tmax.max(m[yy * w + xx]);
                    }
                }
                out[y * w + x] = tmax;
            }
        }
        out
    }

    /// Each pixel's window rule by brute force: strict against earlier neighbours within
    /// `nms_half`, at least as large as later ones (the part of [`select_brute`] that does
    /// not depend on the tile or the thresholds: computed once for all of them).
    fn nms_brute(m: &[f32], w: usize, h: usize, nms_half: usize) -> Vec<bool> {
        let r = nms_half as isize;
        let mut out = vec![true; w * h];
        for y in 0..h {
            for x in 0..w {
                let v = m[y * w + x];
                // Offsets of the window inside the image only: the others were skipped one by
                // one (14641 of them a pixel at nms_half 60, most of the test's time).
                let (x0, y0) = (x as isize, y as isize);
                for dy in (-r).max(-y0)..=r.min(h as isize - 1 - y0) {
                    for dx in (-r).max(-x0)..=r.min(w as isize - 1 - x0) {
                        let (xx, yy) = (x0 + dx, y0 + dy);
                        if (dx, dy) == (0, 0) {
                            continue;
                        }
                        let n = m[yy as usize * w + xx as usize];
                        let earlier = dy < 0 || (dy == 0 && dx < 0);
                        if n > v || (earlier && n == v) {
                            out[y * w + x] = false;
                        }
                    }
                }
            }
        }
        out
    }

    /// The selection rule of [`interest_points`] by brute force: threshold from the pixel's
    /// tile maximum (`tmax`: [`tile_max_brute`] of `p.tile`) and the floor from the map's
    /// maximum, strict against earlier neighbours, at least as large as later ones (`nms`:
    /// [`nms_brute`] of `p.nms_half`), raster order.
    fn select_brute(
        m: &[f32],
        w: usize,
        h: usize,
        p: &InterestParams,
        tmax: &[f32],
        nms: &[bool],
    ) -> Vec<(u32, u32, f32)> {
        let max = m.iter().copied().fold(0.0f32, f32::max);
        let mut out = Vec::new();
        for y in BORDER..h.saturating_sub(BORDER) {
            for x in BORDER..w.saturating_sub(BORDER) {
                let v = m[y * w + x];
                let thr = (tmax[y * w + x] * p.rel_threshold).max(max * p.floor_rel);
                if v > 0.0 && v >= thr && nms[y * w + x] {
                    out.push((x as u32, y as u32, v));
                }
            }
        }
        out
    }

    /// [`window_max`] against the maximum of each clipped window, on coarse maps (ties) with a
    /// NaN or two, every window size from 1 to past the map.
    #[test]
    fn window_max_is_the_maximum_of_each_window() {
        for (w, h, seed) in [(1, 1, 1), (1, 9, 2), (13, 1, 3), (9, 8, 4), (31, 17, 5)] {
            let mut m: Vec<f32> = noise(w * h, seed, 7)
                .into_iter()
                .map(|k| k as f32)
                .collect();
            if w * h > 20 {
                m[5] = f32::NAN;
                m[w * h - 3] = f32::NAN;
            }
            for r in [1, 2, 3, 4, 5, 8, 15, 16, 40, usize::MAX] {
                let got = window_max(&m, w, h, r).unwrap();
                for y in 0..h {
                    for x in 0..w {
                        let mut want = f32::NAN;
                        for yy in y.saturating_sub(r)..=y.saturating_add(r).min(h - 1) {
                            for xx in x.saturating_sub(r)..=x.saturating_add(r).min(w - 1) {
                                want = want.max(m[yy * w + xx]);
                            }
                        }
                        let g = got[y * w + x];
                        assert_eq!(g.to_bits(), want.to_bits(), "{w}x{h} r {r} at ({x}, {y})");
                    }
                }
            }
        }
    }

    /// Coarse random maps (plateaus, ties with the thresholds, zeros) against the brute-force
    /// rule, for the 3x3 fast path and the general one, whole-image and small tiles.
    #[test]
    fn selection_equals_the_brute_force_rule() {
        for (w, h, seed) in [(9, 8, 1), (30, 21, 2), (47, 37, 3)] {
            // Values k / 8 (k = 0..=8: plateaus, zeros, exact ties with the thresholds) times
            // 1/2 on the last 4 columns, 1/4 on the rest of the right half, 1/8 on the left:
            // tiles with different maxima, and the image's maximum (1/2) in one tile only.
            let m: Vec<f32> = noise(w * h, seed, 9)
                .into_iter()
                .enumerate()
                .map(|(i, k)| {
                    let x = i % w;
                    let scale = if x + 4 >= w {
                        0.5
                    } else if 2 * x >= w {
                        0.25
                    } else {
                        0.125
                    };
                    k as f32 / 8.0 * scale
                })
                .collect();
            let tiles = [0, 5, 16, 64];
            let tmaxes: Vec<Vec<f32>> =
                tiles.iter().map(|&t| tile_max_brute(&m, w, h, t)).collect();
            for nms_half in [1, 2, 3, 7, 20, 60] {
                let nms = nms_brute(&m, w, h, nms_half);
                for (&tile, tmax) in tiles.iter().zip(&tmaxes) {
                    for (rel_threshold, floor_rel) in [(0.5, 0.0), (0.25, 0.5), (1e-3, 1e-4)] {
                        let p = InterestParams {
                            rel_threshold,
                            nms_half,
                            tile,
                            floor_rel,
                        };
                        let got: Vec<(u32, u32, f32)> = select_points(&m, w, h, &p)
                            .unwrap()
                            .iter()
                            .map(|q| (q.x, q.y, q.value))
                            .collect();
                        assert_eq!(got, select_brute(&m, w, h, &p, tmax, &nms), "{w}x{h} {p:?}");
                    }
                }
            }
        }
    }
}
