//! Hysteresis curve tracking of zero crossings into labelled segments (algorithms.md B.4 steps
//! 4-5 with B.8's readings: `t_high` a percentile of the strengths, steps only into the forward
//! half-plane, the tangent sign that agrees with the previous step).

use std::f64::consts::{PI, TAU};

use super::zerocross::ZeroCrossings;
use crate::alloc::{try_collect, try_filled, try_grow, try_reserve_len, try_zeroed};
use crate::error::Result;

/// Names the tracker's per-pixel buffers in an out-of-memory error.
const WHAT: &str = "a tracking plane of the MCGM matcher";
/// Names a segment's pixel lists (growth buffers, the kept curve, the segments) likewise.
const SEG: &str = "a tracked segment of the MCGM matcher";

/// 8-neighbour offsets in the fixed scan order that breaks exact ties.
const NEIGHBOURS: [(i32, i32); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// Tracking thresholds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackParams {
    /// Seed threshold as a quantile of the marked pixels' strengths (B.8: 0.5).
    pub high_quantile: f32,
    /// Continuation threshold as a fraction of the seed threshold (B.2: 0.4).
    pub low_ratio: f32,
    /// Bound on the change of the normal direction between consecutive pixels, which must be
    /// strictly below it (degrees; B.4 "differs by less than"; B.8: 60).
    pub max_turn_deg: f32,
    /// Shortest kept segment (pixels).
    pub min_len: usize,
}

/// One tracked curve segment.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Pixel indices `y * w + x`, ordered along the curve.
    pub pixels: Vec<u32>,
    /// Mean of the integer pixel positions `(x, y)`.
    pub centroid: (f32, f32),
    pub x_min: i32,
    pub x_max: i32,
    pub y_min: i32,
    pub y_max: i32,
    /// Circular mean of the normal directions, `[0, 2 pi)`.
    pub mean_theta: f32,
}

/// Segments and the label map of one image.
#[derive(Debug, Clone, PartialEq)]
pub struct Curves {
    pub segments: Vec<Segment>,
    /// Segment id per pixel, -1 = none.
    pub labels: Vec<i32>,
    /// The thresholds used (`t_high`, `t_low`).
    pub t_high: f32,
    pub t_low: f32,
}

/// A difference of two angles in `[0, 2 pi)` wrapped to `(-pi, pi]` (no `fmod`: hot loop).
#[inline]
pub fn wrap_angle(d: f64) -> f64 {
    let mut d = d;
    if d > PI {
        d -= TAU;
    } else if d <= -PI {
        d += TAU;
    }
    d
}

/// Seed threshold: the `q` quantile ("lower": sorted value at `floor(q (n - 1))`) of the
/// strengths of marked pixels; 0 when nothing is marked. A failed allocation of the list of
/// marked pixels (4 bytes each) is [`crate::CoreError::OutOfMemory`]; an image past
/// [`crate::image::check_index_range`] is [`crate::CoreError::TooLarge`] (as in [`track`]).
pub fn high_threshold(zc: &ZeroCrossings, q: f32) -> Result<f32> {
    // The marked pixels are listed in u32: refused first, not wrapped.
    crate::image::check_index_range(zc.width, zc.height)?;
    let n = zc.marked().count();
    let marked = try_collect(n, zc.marked().map(|i| i as u32), WHAT)?;
    marked_quantile(&marked, &zc.strength, q)
}

/// [`high_threshold`] over the marked pixels' indices `marked` (ascending).
fn marked_quantile(marked: &[u32], strength: &[f32], q: f32) -> Result<f32> {
    // Marked strengths are >= MIN_STRENGTH > 0, so their bit patterns order as the values
    // do: the k-th is found in the bucket of its upper 12 bits (one histogram pass), then by
    // selection among that bucket's values only.
    const SHIFT: u32 = 20;
    const BUCKETS: usize = 1 << (32 - SHIFT);
    let count = marked.len();
    if count == 0 {
        return Ok(0.0);
    }
    let mut hist = vec![0usize; BUCKETS];
    for &i in marked {
        hist[(strength[i as usize].to_bits() >> SHIFT) as usize] += 1;
    }
    let k = (((q as f64) * (count - 1) as f64).floor() as usize).min(count - 1);
    let (mut below, mut bucket) = (0usize, 0usize);
    for (b, &c) in hist.iter().enumerate() {
        if below + c > k {
            bucket = b;
            break;
        }
        below += c;
    }
    // The bucket's values in raster order (branch-free compaction: its size is known).
    let mut vals = try_zeroed::<f32>(hist[bucket] + 1, WHAT)?;
    let mut c = 0;
    for &i in marked {
        let s = strength[i as usize];
        vals[c] = s;
        c += usize::from((s.to_bits() >> SHIFT) as usize == bucket);
    }
    vals.truncate(c);
    Ok(*vals.select_nth_unstable_by(k - below, f32::total_cmp).1)
}

/// Hints the CPU to fetch the cache line of `v[i]` (no effect on any value; `i` in range).
#[inline(always)]
fn prefetch<T>(v: &[T], i: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = v[i..].as_ptr() as *const i8;
        // SAFETY: `p` points into `v` (the slice above is bounds-checked); a prefetch only
        // reads ahead into the cache.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (v, i);
}

fn tangent(theta: f32) -> (f64, f64) {
    let t = theta as f64;
    (-t.sin(), t.cos())
}

/// Sorts `keys` ascending by their upper 32 bits, equal ones keeping their order (LSD radix
/// sort, 11 + 11 + 10 bits): for keys `(k << 32) | i` listed by ascending `i`, the order of
/// a full sort, several times faster on the 10^5 seeds of a channel.
fn radix_sort_upper(keys: &mut Vec<u64>) -> Result<()> {
    let mut tmp = try_zeroed::<u64>(keys.len(), WHAT)?;
    for (shift, bits) in [(32u32, 11u32), (43, 11), (54, 10)] {
        let mask = (1u64 << bits) - 1;
        let mut count = vec![0usize; (1 << bits) + 1];
        for &k in keys.iter() {
            count[((k >> shift) & mask) as usize + 1] += 1;
        }
        if count.contains(&keys.len()) {
            continue; // one bucket: the pass would not move anything
        }
        for b in 1..count.len() {
            count[b] += count[b - 1];
        }
        for &k in keys.iter() {
            let b = ((k >> shift) & mask) as usize;
            tmp[count[b]] = k;
            count[b] += 1;
        }
        std::mem::swap(keys, &mut tmp);
    }
    Ok(())
}

/// Tracks the crossings into segments.
pub fn track(zc: &ZeroCrossings, p: &TrackParams) -> Result<Curves> {
    let (w, h) = (zc.width, zc.height);
    // Pixel indices are u32 here (the marked list, the seeds' keys, the segments), positions
    // i32: a larger image is refused, not wrapped.
    crate::image::check_index_range(w, h)?;
    let n = w * h;
    // The marked pixels (a third or less of the image) listed once: the threshold, the
    // candidates and the seeds are found among them instead of in three passes over every
    // pixel (branch-free compaction: the i-th write lands at or before i).
    let mut marked = try_zeroed::<u32>(n, WHAT)?;
    let mut n_marked = 0;
    for (i, &m) in zc.mark.iter().enumerate() {
        marked[n_marked] = i as u32;
        n_marked += usize::from(m != 0);
    }
    marked.truncate(n_marked);
    let t_high = marked_quantile(&marked, &zc.strength, p.high_quantile)?;
    let t_low = p.low_ratio * t_high;
    // Per pixel: FREE = unvisited candidate (marked interior pixel, s >= t_low), TAKEN = on a
    // curve (or a seed already used), 0 = not a candidate.
    const FREE: u8 = 1;
    const TAKEN: u8 = 2;
    let mut state = try_zeroed::<u8>(n, WHAT)?;
    // Seeds (candidates with s >= t_high) by decreasing strength, then index: one key each,
    // `!bits(s) << 32 | i` (strengths are > 0, so their bit patterns order as the values do),
    // listed by index (branch-free) and radix-sorted on the upper half.
    let mut keys = try_zeroed::<u64>(marked.len(), WHAT)?;
    let mut n_seeds = 0;
    // (Images narrower or lower than 3 pixels have no interior.)
    if w >= 3 && h >= 3 {
        // The row of each index follows the ascending list (no division per pixel).
        let (mut y, mut row_end) = (0usize, w);
        for &i in &marked {
            let i = i as usize;
            while i >= row_end {
                y += 1;
                row_end += w;
            }
            let x = i + w - row_end;
            let s = zc.strength[i];
            let free = (y >= 1) & (y + 1 < h) & (x >= 1) & (x + 1 < w) & (s >= t_low) & (s > 0.0);
            state[i] = u8::from(free);
            keys[n_seeds] = (u64::from(!s.to_bits()) << 32) | i as u64;
            n_seeds += usize::from(free & (s >= t_high));
        }
    }
    keys.truncate(n_seeds);
    // The list is done with: freed before the sort's copy of the keys and the labels, so that
    // the peak stays the one of the whole-image passes it replaced (4 bytes a pixel less).
    drop(marked);
    radix_sort_upper(&mut keys)?;
    let max_turn = (p.max_turn_deg as f64).to_radians();
    let mut labels = try_filled(n, -1i32, WHAT)?;
    let mut segments = Vec::new();
    // Grows from `start` (tangent `t0`) along `sign * t0`, appending the pixels taken and their
    // tangents to `out` (a curve can run through the whole image: its growth is checked).
    let grow = |start: usize,
                t0: (f64, f64),
                sign: f64,
                state: &mut Vec<u8>,
                out: &mut Vec<(u32, (f64, f64))>|
     -> Result<()> {
        let mut cur = start;
        let mut dir = (sign * t0.0, sign * t0.1);
        // The position follows the steps (no division per step).
        let (mut cx, mut cy) = ((start % w) as i32, (start / w) as i32);
        loop {
            let tc = zc.theta[cur] as f64;
            let mut best: Option<(f64, f32, usize, (i32, i32))> = None;
            // `cur` is an interior pixel (see `state`): its neighbours are inside the image.
            debug_assert!(cx >= 1 && cy >= 1 && cx + 1 < w as i32 && cy + 1 < h as i32);
            // The free neighbours in the forward half-plane (`dx dir.0 + dy dir.1 > 0`; the
            // diagonals' `/ sqrt 2` keeps the sign), found without a branch per neighbour; then
            // those, in NEIGHBOURS order.
            let mut cand = 0u32;
            for (k, &(dx, dy)) in NEIGHBOURS.iter().enumerate() {
                let q = (cur as isize + dy as isize * w as isize + dx as isize) as usize;
                let proj = dx as f64 * dir.0 + dy as f64 * dir.1;
                cand |= u32::from((state[q] == FREE) & (proj > 0.0)) << k;
            }
            while cand != 0 {
                let k = cand.trailing_zeros() as usize;
                cand &= cand - 1;
                let (dx, dy) = NEIGHBOURS[k];
                let q = (cy + dy) as usize * w + (cx + dx) as usize;
                if wrap_angle(zc.theta[q] as f64 - tc).abs() >= max_turn {
                    continue;
                }
                let proj = dx as f64 * dir.0 + dy as f64 * dir.1;
                // An axis step's length is 1: no division (x / 1.0 == x).
                let dot = if dx != 0 && dy != 0 {
                    proj / std::f64::consts::SQRT_2
                } else {
                    proj
                };
                if dot <= 0.0 {
                    continue; // forward half-plane only
                }
                let s = zc.strength[q];
                if best.is_none_or(|b| dot > b.0 || (dot == b.0 && s > b.1)) {
                    best = Some((dot, s, q, (dx, dy)));
                }
            }
            let Some((_, _, q, (dx, dy))) = best else {
                break;
            };
            state[q] = TAKEN;
            let (tx, ty) = tangent(zc.theta[q]);
            try_grow(out, 1, SEG)?;
            out.push((q as u32, (tx, ty)));
            let sgn = if tx * dx as f64 + ty * dy as f64 >= 0.0 {
                1.0
            } else {
                -1.0
            };
            dir = (sgn * tx, sgn * ty);
            cur = q;
            (cx, cy) = (cx + dx, cy + dy);
            // Curves are smooth: the step after next most likely reads the pixels one more
            // step ahead. Ask for their cache lines now (a hint only; no effect on the result).
            let ahead = (cy + 2 * dy).clamp(0, h as i32 - 1) as usize * w
                + (cx + 2 * dx).clamp(0, w as i32 - 1) as usize;
            prefetch(&zc.theta, ahead);
            prefetch(&zc.strength, ahead);
            prefetch(state, ahead);
        }
        Ok(())
    };
    // Growth buffers and the kept curve's pixels, reused by every seed (a kept segment cost
    // three allocations: the collect, the push past its exact capacity, the extend).
    let (mut fwd, mut bwd, mut pixels) = (Vec::new(), Vec::new(), Vec::new());
    // Seeds lie anywhere in the image (strength order): ask for a later seed's cache lines
    // now, so its state and neighbourhood are there when its turn comes (a hint only).
    const AHEAD: usize = 8;
    for (i, &key) in keys.iter().enumerate() {
        if let Some(&next) = keys.get(i + AHEAD) {
            let q = next as u32 as usize;
            prefetch(&state, q);
            prefetch(&zc.theta, q.saturating_sub(w));
            prefetch(&zc.theta, q);
            prefetch(&zc.theta, (q + w).min(n - 1));
            prefetch(&zc.strength, q);
        }
        let s = key as u32 as usize;
        if state[s] != FREE {
            continue;
        }
        state[s] = TAKEN;
        let t0 = tangent(zc.theta[s]);
        fwd.clear();
        bwd.clear();
        grow(s, t0, 1.0, &mut state, &mut fwd)?;
        grow(s, t0, -1.0, &mut state, &mut bwd)?;
        if 1 + fwd.len() + bwd.len() < p.min_len {
            continue;
        }
        pixels.clear();
        try_reserve_len(&mut pixels, 1 + fwd.len() + bwd.len(), SEG)?;
        pixels.extend(bwd.iter().rev().copied());
        pixels.push((s as u32, t0));
        pixels.extend_from_slice(&fwd);
        let id = segments.len() as i32;
        let seg = make_segment(w, &pixels, &mut labels, id)?;
        try_grow(&mut segments, 1, SEG)?;
        segments.push(seg);
    }
    Ok(Curves {
        segments,
        labels,
        t_high,
        t_low,
    })
}

/// The segment of `pixels` (with their tangents `(-sin theta, cos theta)`), labelled `id`.
fn make_segment(
    w: usize,
    pixels: &[(u32, (f64, f64))],
    labels: &mut [i32],
    id: i32,
) -> Result<Segment> {
    let (mut sx, mut sy, mut sc, mut ss) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut x_min, mut x_max, mut y_min, mut y_max) = (i32::MAX, i32::MIN, i32::MAX, i32::MIN);
    for &(i, (tx, ty)) in pixels {
        let i = i as usize;
        labels[i] = id;
        let (x, y) = ((i % w) as i32, (i / w) as i32);
        sx += x as f64;
        sy += y as f64;
        sc += ty; // cos theta
        ss += -tx; // sin theta
        x_min = x_min.min(x);
        x_max = x_max.max(x);
        y_min = y_min.min(y);
        y_max = y_max.max(y);
    }
    let k = pixels.len() as f64;
    let m = ss.atan2(sc);
    Ok(Segment {
        centroid: ((sx / k) as f32, (sy / k) as f32),
        x_min,
        x_max,
        y_min,
        y_max,
        mean_theta: (if m < 0.0 { m + TAU } else { m }) as f32 % std::f32::consts::TAU,
        pixels: try_collect(pixels.len(), pixels.iter().map(|&(i, _)| i), SEG)?,
    })
}

#[cfg(test)]
mod tests {
    //! The one-pass threshold, candidate and seed lists and the reused segment buffer against
    //! the plain hysteresis tracker of the channel's tests (full sorts, a neighbour loop with
    //! branches), on the inputs real scenes do not hold: nothing or everything marked, images 1
    //! or 2 pixels wide or high, equal strengths (ties of the quantile and of the seed order),
    //! NaN of either sign, infinite, zero and negative strengths, segments rejected after
    //! partial growth.
    use super::*;
    use crate::matching::mcgm::tests::{high_threshold_reference, track_reference};
    use crate::matching::mcgm::zerocross::{ZC_H, ZC_V};

    /// A segment's pixels, float fields by their bits, and bounds.
    type SegmentBits = (Vec<u32>, [u32; 3], [i32; 4]);

    /// Every field of `c`, floats by their bits (NaN centroids and directions compare). A NaN
    /// computed by arithmetic is one NaN: Rust leaves its sign unspecified (the kernel's
    /// `ss += -tx` and the reference's `ss += sin` gave opposite signs on a NaN normal).
    /// `t_high` is picked from the strengths, not computed: its bits are compared as they are,
    /// NaN sign included.
    fn bits(c: &Curves) -> (Vec<SegmentBits>, &[i32], [u32; 2]) {
        let any_nan = |v: f32| if v.is_nan() { f32::NAN } else { v }.to_bits();
        let segs = c
            .segments
            .iter()
            .map(|s| {
                let f = [s.centroid.0, s.centroid.1, s.mean_theta].map(any_nan);
                (s.pixels.clone(), f, [s.x_min, s.x_max, s.y_min, s.y_max])
            })
            .collect();
        (segs, &c.labels, [c.t_high.to_bits(), any_nan(c.t_low)])
    }

    /// Crossings of a `w x h` image: marks with probability `density`, strengths by `kind`
    /// (0: all equal, 1: three levels, 2: continuous, 3: with 0, NaN of either sign, inf,
    /// denormal and negative values among them), normals by `kind` too (smooth, random, NaN
    /// of either sign).
    fn crossings(w: usize, h: usize, density: f32, kind: usize, seed: u64) -> ZeroCrossings {
        let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
        let mut rnd = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let n = w * h;
        let mark: Vec<u8> = (0..n)
            .map(|_| {
                [0, ZC_H, ZC_V, ZC_H | ZC_V][(rnd() * 3.0) as usize + 1] * u8::from(rnd() < density)
            })
            .collect();
        let specials = [
            0.0,
            -0.0,
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            1e-40,
            -2.0,
            1e-5,
        ];
        let (mut strength, mut theta) = (vec![0.0f32; n], vec![0.0f32; n]);
        for i in 0..n {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            theta[i] = match (kind + i) % 3 {
                0 => (0.3 * x - 0.2 * y + 0.4 * rnd()).rem_euclid(std::f32::consts::TAU),
                1 => [0.0, 0.0, 0.5, 5.9][(rnd() * 4.0) as usize],
                _ if kind == 3 && rnd() < 0.05 => [f32::NAN, -f32::NAN][i & 1],
                _ => std::f32::consts::TAU * rnd(),
            };
            if mark[i] != 0 {
                strength[i] = match kind {
                    0 => 0.25,
                    1 => [1e-5, 2e-5, 3e-5][(rnd() * 3.0) as usize],
                    2 => 1e-5 + rnd(),
                    _ if rnd() < 0.3 => specials[(rnd() * 8.0) as usize],
                    _ => 1e-5 * (1 + (rnd() * 4.0) as i32) as f32,
                };
            }
        }
        let xsub = (0..n)
            .map(|i| {
                if mark[i] != 0 {
                    (i % w) as f32
                } else {
                    f32::NAN
                }
            })
            .collect();
        ZeroCrossings {
            width: w,
            height: h,
            mark,
            xsub,
            strength,
            theta,
        }
    }

    #[test]
    fn one_pass_lists_and_reused_buffer_equal_the_plain_tracker_on_edge_cases() {
        let base = TrackParams {
            high_quantile: 0.5,
            low_ratio: 0.4,
            max_turn_deg: 60.0,
            min_len: 5,
        };
        let params = [
            base,
            TrackParams { min_len: 1, ..base },
            TrackParams { min_len: 2, ..base },
            TrackParams {
                min_len: 12,
                max_turn_deg: 120.0,
                ..base
            },
            TrackParams {
                high_quantile: 0.0,
                low_ratio: 0.0,
                ..base
            },
            TrackParams {
                high_quantile: 1.0,
                low_ratio: 1.0,
                ..base
            },
            TrackParams {
                high_quantile: 2.0,
                ..base
            },
            TrackParams {
                high_quantile: -1.0,
                ..base
            },
            TrackParams {
                high_quantile: f32::NAN,
                ..base
            },
        ];
        let sizes = [
            (0, 0),
            (1, 1),
            (1, 17),
            (17, 1),
            (2, 2),
            (2, 9),
            (9, 2),
            (3, 3),
            (3, 40),
            (40, 3),
            (31, 23),
            (64, 48),
        ];
        let (mut cases, mut segments, mut short) = (0, 0, 0);
        for (s, &(w, h)) in sizes.iter().enumerate() {
            for density in [0.0, 1.0, 0.6, 0.25] {
                for kind in 0..4 {
                    let zc = crossings(w, h, density, kind, (s * 16 + kind) as u64 + 1);
                    for q in [0.0, 0.3, 0.5, 0.99, 1.0] {
                        let (new, want) = (
                            high_threshold(&zc, q).unwrap(),
                            high_threshold_reference(&zc, q),
                        );
                        assert_eq!(
                            new.to_bits(),
                            want.to_bits(),
                            "{w}x{h} {density} {kind} {q}"
                        );
                    }
                    for p in &params {
                        let new = track(&zc, p).unwrap();
                        let want = track_reference(&zc, p);
                        assert_eq!(bits(&new), bits(&want), "{w}x{h} {density} {kind} {p:?}");
                        segments += new.segments.len();
                        // Segments a longer min_len rejects after they grew.
                        short += new
                            .segments
                            .iter()
                            .filter(|s| (2..12).contains(&s.pixels.len()))
                            .count();
                        cases += 1;
                    }
                }
            }
        }
        // The inputs reach every path: segments kept, and ones min_len rejects after growth.
        assert_eq!(cases, 12 * 4 * 4 * params.len());
        assert!(
            segments > 1000 && short > 500,
            "{segments} segments, {short} short"
        );
    }

    /// Run by [`an_all_marked_image_tracks_in_the_memory_of_the_old_tracker`] in a child
    /// process: 1024 x 1024 pixels, every one marked with one strength (every interior pixel
    /// a seed), tracked under an address-space limit of 19 MiB more than is mapped.
    #[cfg(target_os = "linux")]
    #[test]
    #[ignore = "a child of an_all_marked_image_tracks_in_the_memory_of_the_old_tracker"]
    fn track_all_marked_under_a_memory_limit() {
        if std::env::var_os("SV_OOM_CHILD").is_none() {
            return;
        }
        let (w, h) = (1024, 1024);
        let n = w * h;
        let zc = ZeroCrossings {
            width: w,
            height: h,
            mark: vec![ZC_H; n],
            xsub: vec![0.0; n],
            strength: vec![1.0; n],
            theta: vec![0.0; n],
        };
        let p = TrackParams {
            high_quantile: 0.5,
            low_ratio: 0.4,
            max_turn_deg: 60.0,
            min_len: 5,
        };
        crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (19 << 20));
        match track(&zc, &p) {
            Ok(c) => println!("child: {} segments", c.segments.len()),
            Err(e) => println!("child: error: {e}"),
        }
    }

    /// Run by [`a_segment_too_long_to_allocate_is_an_error`] in a child process: a 2^20 x 3
    /// image, every pixel marked, tangents along the rows: one segment along the middle row
    /// (2^20 - 2 pixels, 24 bytes each while it grows). The planes (39 bytes a column) fit
    /// under the limit, the growing curve (24 MiB at the end) does not.
    #[cfg(target_os = "linux")]
    #[test]
    #[ignore = "a child of a_segment_too_long_to_allocate_is_an_error"]
    fn track_a_long_segment_under_a_memory_limit() {
        if std::env::var_os("SV_OOM_CHILD").is_none() {
            return;
        }
        let (w, h) = (1 << 20, 3);
        let n = w * h;
        let zc = ZeroCrossings {
            width: w,
            height: h,
            mark: vec![ZC_V; n],
            xsub: vec![0.0; n],
            strength: vec![1.0; n],
            // Normal straight down the columns: tangent (-sin, cos) = (1, 0).
            theta: vec![3.0 * std::f32::consts::FRAC_PI_2; n],
        };
        let p = TrackParams {
            high_quantile: 0.5,
            low_ratio: 0.4,
            max_turn_deg: 60.0,
            min_len: 5,
        };
        crate::segment::tests::limit_address_space(
            crate::segment::tests::vm_size() + 39 * w + (16 << 20),
        );
        match track(&zc, &p) {
            Ok(c) => println!("child: {} segments", c.segments.len()),
            Err(e) => println!("child: error: {e}"),
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_segment_too_long_to_allocate_is_an_error() {
        // A curve's growth buffers, its pixel list and the segment list grew by push/collect:
        // a curve through a large image that did not fit aborted the process (SIGABRT)
        // instead of returning OutOfMemory.
        let stdout = crate::segment::tests::run_oom_child(
            "matching::mcgm::tracking::tests::track_a_long_segment_under_a_memory_limit",
        );
        let want = "child: error: out of memory: a tracked segment of the MCGM matcher needs ";
        assert!(stdout.contains(want), "{want} not in {stdout}");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn an_all_marked_image_tracks_in_the_memory_of_the_old_tracker() {
        // 1a077a5 kept the list of marked pixels (4 bytes a pixel) alive to the end of track:
        // with every pixel marked and a seed, the radix sort's peak (state 1 + keys 8 + its
        // copy 8 bytes a pixel) grew from 17 to 21 bytes a pixel, an OutOfMemory where the old
        // tracker had room. The list is freed once the seeds are listed.
        let stdout = crate::segment::tests::run_oom_child(
            "matching::mcgm::tracking::tests::track_all_marked_under_a_memory_limit",
        );
        assert!(stdout.contains("child: 1022 segments"), "{stdout}");
    }
}
