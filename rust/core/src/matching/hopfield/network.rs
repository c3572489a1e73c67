//! The sparse binary Hopfield network over candidate pairs (algorithms.md C.4, C.6).
//!
//! Weights `T_ab = A * C~_ab - B [same left point] - B [same right pixel]` (zero diagonal,
//! symmetric by construction: every entry is a symmetric function of the pair), inputs
//! `I_a = D * S_a - theta`. The Hopfield channel never stores the matrix: a [`Network`] row is
//! computed when it is read, 8 window neighbours at a time (AVX2, with a portable twin giving
//! identical values), from the left points sorted into strips of rows; the dynamics read every row once
//! for the initial net inputs (in parallel) and the row of each flip. A stored [`Csr`] (what
//! [`build_weights`] returns, and what the graph-matching channel builds) gives the same
//! entries in the same order. Dynamics: asynchronous binary threshold updates in a seeded
//! random order, net inputs maintained incrementally, until a sweep without a flip.

use rayon::prelude::*;

use crate::alloc::{try_collect, try_filled, try_grow, try_reserve_len, try_zeroed};
use crate::error::Result;
#[cfg(target_arch = "x86_64")]
use crate::simd::has_avx2;

/// One neuron: left point index, right position and disparity vector `(x_l - x_r, y_l - y_r)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neuron {
    pub point: u32,
    pub xl: i32,
    pub yl: i32,
    pub xr: i32,
    pub yr: i32,
    pub sim: f32,
    /// Passed the depth-edge test (four half-windows agree, centre grey-level check).
    pub edge_ok: bool,
    /// Half-windows that failed their test (bit `k`: left, right, top, bottom).
    pub halves_fail: u8,
    /// Passed the centre grey-level check.
    pub centre_ok: bool,
    /// Parabola sub-pixel offset of the disparity (px, in [-0.5, 0.5]).
    pub sub: f32,
}

impl Neuron {
    #[inline]
    pub fn dx(&self) -> i32 {
        self.xl - self.xr
    }
    #[inline]
    pub fn dy(&self) -> i32 {
        self.yl - self.yr
    }
}

/// Weights of the energy (C.4 with the C.10 defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyWeights {
    /// Compatibility weight `A` (C.10: 3; 1 is less precise than no network).
    pub a: f32,
    /// Uniqueness inhibition `B` (C.3: 1.5).
    pub b: f32,
    /// Similarity weight `D` (C.3: 1).
    pub d: f32,
    /// Input offset `theta` (C.10: 0.6): a neuron needs `D S > theta` or support to switch on.
    pub theta: f32,
    /// Compatibility neighbourhood half-size (px): the paper's 40x40 window.
    pub nbr_half: i32,
    /// Disparity difference (px) at which compatibility crosses 0 (C.3).
    pub compat_theta: f32,
    /// Steepness of the compatibility sigmoid (1/px, C.3).
    pub compat_slope: f32,
    /// Growth of the compatibility crossing with the points' distance (px of disparity per px
    /// of Chebyshev distance): the crossing is `compat_theta + compat_grad * r`, so that
    /// neighbours on a slanted surface 20 px away still support each other (0 = C.3's form).
    pub compat_grad: f32,
}

impl Default for EnergyWeights {
    fn default() -> Self {
        EnergyWeights {
            a: 3.0,
            b: 1.5,
            d: 1.0,
            theta: 0.6,
            nbr_half: 20,
            compat_theta: 2.0,
            compat_slope: 2.0,
            compat_grad: 0.05,
        }
    }
}

/// `C(dist) = 2 / (1 + exp(slope (dist - theta))) - 1`, in `(-1, 1)`.
pub fn compat(dist: f64, theta: f64, slope: f64) -> f64 {
    2.0 / (1.0 + (slope * (dist - theta)).exp()) - 1.0
}

/// Symmetric sparse weight matrix in CSR form.
#[derive(Debug, Clone, Default)]
pub struct Csr {
    pub indptr: Vec<usize>,
    pub indices: Vec<u32>,
    pub data: Vec<f32>,
}

impl Csr {
    pub fn n(&self) -> usize {
        self.indptr.len().saturating_sub(1)
    }
    pub fn nnz(&self) -> usize {
        self.indices.len()
    }
    #[inline]
    pub fn row(&self, a: usize) -> (&[u32], &[f32]) {
        let (s, e) = (self.indptr[a], self.indptr[a + 1]);
        (&self.indices[s..e], &self.data[s..e])
    }
}

/// Cells per window half-size of [`PointGrid`]: cells of `ceil(half / 2)` px, so a window
/// query scans 5x5 cells (50x50 px for the 41x41 window: 67 % of the scanned points are
/// inside, against 47 % with cells of `half`).
const GRID_SUB: i32 = 2;

/// `floor(x / d)` for `0 <= x < 2^31` by a multiply and a shift (the round-up method of
/// Granlund and Montgomery: `m = ceil(2^(31 + l) / d)` with `2^l >= d` is exact for 31-bit `x`).
#[derive(Debug, Clone, Copy)]
struct DivBy {
    m: u64,
    shift: u32,
}

impl DivBy {
    fn new(d: u32) -> Self {
        assert!(d >= 1, "division by zero");
        let l = 32 - (d - 1).leading_zeros(); // ceil(log2 d)
        let shift = 31 + l;
        let m = (1u128 << shift).div_ceil(d as u128) as u64;
        DivBy { m, shift }
    }

    #[inline]
    fn of(self, x: i32) -> i32 {
        debug_assert!(x >= 0);
        ((x as u64 * self.m) >> self.shift) as i32
    }
}

/// Stable counting sort of `items` by `key(item) < n_keys`: each key's start in the result
/// (`n_keys + 1` values) and the items by key, in their given order within a key. A failed
/// allocation is [`crate::CoreError::OutOfMemory`] naming `what`.
fn counting_sort(
    items: impl Iterator<Item = u32> + Clone,
    key: impl Fn(u32) -> usize,
    n_keys: usize,
    what: &'static str,
) -> Result<(Vec<usize>, Vec<u32>)> {
    let mut start = try_zeroed::<usize>(n_keys + 1, what)?;
    for it in items.clone() {
        start[key(it) + 1] += 1;
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut fill = try_collect(start.len(), start.iter().copied(), what)?;
    let mut out = try_zeroed::<u32>(start[n_keys], what)?;
    for it in items {
        let k = key(it);
        out[fill[k]] = it;
        fill[k] += 1;
    }
    Ok((start, out))
}

/// What [`PointGrid`]'s allocations are named in an out-of-memory error.
const POINT_GRID: &str = "the Hopfield matcher's point grid";

/// Uniform grid over the left points, counting-sorted: `items` lists the point indices cell by
/// cell (raster order of the cells, point order within a cell) with their coordinates beside
/// them, so the cells of one grid row around a point form ONE contiguous range.
pub(crate) struct PointGrid {
    cell: DivBy,
    gw: i32,
    gh: i32,
    start: Vec<usize>,
    pub(crate) items: Vec<u32>,
    pub(crate) xs: Vec<i32>,
    pub(crate) ys: Vec<i32>,
}

impl PointGrid {
    /// Grid over points with non-negative coordinates, for window queries of half-size `half`
    /// (>= 1). A failed allocation of its tables (about 20 bytes a point) is
    /// [`crate::CoreError::OutOfMemory`].
    pub(crate) fn new(pxy: &[(i32, i32)], half: i32) -> Result<Self> {
        let cell = (half.max(1) + GRID_SUB - 1) / GRID_SUB;
        // Coordinates are >= 0: the largest cell index is the largest coordinate's. Each
        // point's cell computed once, by a multiply (divisions were most of the build).
        let cell = DivBy::new(cell as u32);
        let gw = cell.of(pxy.iter().map(|p| p.0).max().unwrap_or(0)) + 1;
        let gh = cell.of(pxy.iter().map(|p| p.1).max().unwrap_or(0)) + 1;
        let cells = try_collect(
            pxy.len(),
            pxy.iter()
                .map(|p| (cell.of(p.1) * gw + cell.of(p.0)) as u32),
            POINT_GRID,
        )?;
        let n_cells = (gw * gh) as usize;
        let (start, items) = counting_sort(
            0..pxy.len() as u32,
            |k| cells[k as usize] as usize,
            n_cells,
            POINT_GRID,
        )?;
        drop(cells);
        // Coordinates padded with LANES far-away entries: a block of lanes may read past the
        // last point (its lanes beyond a range are masked, these are never inside a window).
        let far = i32::MIN / 4;
        let pad = std::iter::repeat_n(far, LANES);
        let n = items.len() + LANES;
        let xs = try_collect(
            n,
            items.iter().map(|&k| pxy[k as usize].0).chain(pad.clone()),
            POINT_GRID,
        )?;
        let ys = try_collect(
            n,
            items.iter().map(|&k| pxy[k as usize].1).chain(pad),
            POINT_GRID,
        )?;
        Ok(PointGrid {
            cell,
            gw,
            gh,
            start,
            items,
            xs,
            ys,
        })
    }

    /// The (possibly empty) ranges of `items` positions covering the cells within
    /// `GRID_SUB` cells of `(x, y)`'s cell, one per grid row, in cell raster order.
    #[inline]
    pub(crate) fn ranges(&self, x: i32, y: i32) -> [(usize, usize); 2 * GRID_SUB as usize + 1] {
        let (cx, cy) = (self.cell.of(x.max(0)), self.cell.of(y.max(0)));
        let (gx0, gx1) = ((cx - GRID_SUB).max(0), (cx + GRID_SUB).min(self.gw - 1));
        std::array::from_fn(|k| {
            let gy = cy - GRID_SUB + k as i32;
            if gy < 0 || gy >= self.gh || gx0 > gx1 {
                return (0, 0);
            }
            let row = gy * self.gw;
            (
                self.start[(row + gx0) as usize],
                self.start[(row + gx1) as usize + 1],
            )
        })
    }

    /// Points within `half` of `(x, y)` in both coordinates, and those of them whose value
    /// (`vals`, in grid order like `xs` and as long: padded) is within `tol` of `v` (the
    /// point itself included).
    pub(crate) fn count_in_window(
        &self,
        (x, y): (i32, i32),
        half: i32,
        vals: &[i32],
        v: i32,
        tol: i32,
    ) -> (usize, usize) {
        assert_eq!(vals.len(), self.xs.len(), "vals must be padded like xs");
        #[cfg(target_arch = "x86_64")]
        if has_avx2() {
            // SAFETY: AVX2 is present; every range ends at most LANES before the padded end.
            return unsafe { count_avx2(self, vals, (x, y, half, v, tol)) };
        }
        count_portable(self, vals, (x, y, half, v, tol))
    }

    /// Calls `f(q)` for every point `q` within `half` of `(x, y)` in both coordinates
    /// (`half` at most the grid's), in cell order.
    pub(crate) fn for_each_in_window(
        &self,
        (x, y): (i32, i32),
        half: i32,
        mut f: impl FnMut(usize),
    ) {
        self.for_each_pos_in_window((x, y), half, |k| f(self.items[k] as usize));
    }

    /// `f(t)` of every point `t` in grid order, padded like `xs` (the `vals` of
    /// [`PointGrid::count_in_window`]). A failed allocation is
    /// [`crate::CoreError::OutOfMemory`].
    pub(crate) fn values_in_grid_order(&self, f: impl Fn(usize) -> i32) -> Result<Vec<i32>> {
        let pad = std::iter::repeat_n(0, self.xs.len() - self.items.len());
        let vals = self.items.iter().map(|&t| f(t as usize)).chain(pad);
        try_collect(self.xs.len(), vals, POINT_GRID)
    }

    /// Calls `f(k)` with the grid position `k` (index into `items`, `xs`, `ys`) of every point
    /// within `half` of `(x, y)`, in the order of [`PointGrid::for_each_in_window`]: for data
    /// kept in grid order.
    pub(crate) fn for_each_pos_in_window(
        &self,
        (x, y): (i32, i32),
        half: i32,
        mut f: impl FnMut(usize),
    ) {
        for (s, e) in self.ranges(x, y) {
            for k in s..e {
                if (self.xs[k] - x).abs() <= half && (self.ys[k] - y).abs() <= half {
                    f(k);
                }
            }
        }
    }
}

/// Portable body of [`PointGrid::count_in_window`].
fn count_portable(
    g: &PointGrid,
    vals: &[i32],
    (x, y, half, v, tol): (i32, i32, i32, i32, i32),
) -> (usize, usize) {
    let (mut near, mut agree) = (0usize, 0usize);
    for (s, e) in g.ranges(x, y) {
        let cells = g.xs[s..e].iter().zip(&g.ys[s..e]).zip(&vals[s..e]);
        for ((&qx, &qy), &qv) in cells {
            let inside = (qx - x).abs() <= half && (qy - y).abs() <= half;
            near += usize::from(inside);
            agree += usize::from(inside & ((qv - v).abs() <= tol));
        }
    }
    (near, agree)
}

/// AVX2 body of [`PointGrid::count_in_window`]: 8 points at a time, the lanes past a range's
/// end masked.
///
/// # Safety
/// The CPU must support AVX2; `g.xs`, `g.ys` and `vals` hold LANES entries past every range.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn count_avx2(
    g: &PointGrid,
    vals: &[i32],
    (x, y, half, v, tol): (i32, i32, i32, i32, i32),
) -> (usize, usize) {
    use std::arch::x86_64::*;
    let ld = |a: &[i32], k: usize| _mm256_loadu_si256(a.as_ptr().add(k) as *const __m256i);
    let (vx, vy, vv) = (
        _mm256_set1_epi32(x),
        _mm256_set1_epi32(y),
        _mm256_set1_epi32(v),
    );
    let (vh, vt) = (_mm256_set1_epi32(half), _mm256_set1_epi32(tol));
    let (mut near, mut agree) = (0u32, 0u32);
    debug_assert!(g.ys.len() == g.xs.len() && vals.len() == g.xs.len());
    for (s, e) in g.ranges(x, y) {
        // SAFETY: the 8-lane loads at k < e read up to k + 7 < e + LANES <= xs.len() (the
        // grid pads xs and ys by LANES; `vals` is as long, asserted by the caller).
        debug_assert!(e + LANES <= g.xs.len());
        for k in (s..e).step_by(LANES) {
            let valid = (1u32 << (e - k).min(LANES)) - 1;
            let out_x =
                _mm256_cmpgt_epi32(_mm256_abs_epi32(_mm256_sub_epi32(ld(&g.xs, k), vx)), vh);
            let out_y =
                _mm256_cmpgt_epi32(_mm256_abs_epi32(_mm256_sub_epi32(ld(&g.ys, k), vy)), vh);
            let off = _mm256_cmpgt_epi32(_mm256_abs_epi32(_mm256_sub_epi32(ld(vals, k), vv)), vt);
            let out = _mm256_or_si256(out_x, out_y);
            let m_in = !(_mm256_movemask_ps(_mm256_castsi256_ps(out)) as u32) & valid;
            let bad = _mm256_or_si256(out, off);
            let m_ok = !(_mm256_movemask_ps(_mm256_castsi256_ps(bad)) as u32) & valid;
            near += m_in.count_ones();
            agree += m_ok.count_ones();
        }
    }
    (near as usize, agree as usize)
}

/// `idx` (neuron indices) sorted by right pixel `(yr, xr)`, then index: one `u64` key per
/// neuron (coordinates non-negative; below 2^21, else a tuple sort), sorted per right row when
/// the rows already come in order, else in parallel.
pub(crate) fn right_pixel_order(
    neurons: &[Neuron],
    mut idx: Vec<usize>,
    what: &'static str,
) -> Result<Vec<u32>> {
    let fits = neurons.len() < 1 << 22 && neurons.iter().all(|n| n.xr < 1 << 21 && n.yr < 1 << 21);
    if !fits {
        idx.sort_unstable_by_key(|&a| (neurons[a].yr, neurons[a].xr, a));
        return try_collect(idx.len(), idx.into_iter().map(|a| a as u32), what);
    }
    let mut keys: Vec<u64> = try_collect(
        idx.len(),
        idx.iter().map(|&a| {
            let n = &neurons[a];
            ((n.yr as u64) << 43) | ((n.xr as u64) << 22) | a as u64
        }),
        what,
    )?;
    if keys.windows(2).all(|w| w[0] >> 43 <= w[1] >> 43) {
        // Right rows already in order (row candidates of raster-ordered points: yr = yl): the
        // order is each row's run sorted on its own, a few dozen keys each.
        for run in keys.chunk_by_mut(|a, b| a >> 43 == b >> 43) {
            run.sort_unstable();
        }
    } else {
        keys.par_sort_unstable();
    }
    try_collect(
        keys.len(),
        keys.iter().map(|&k| (k & ((1 << 22) - 1)) as u32),
        what,
    )
}

/// `f(a)` = (row sum, entry count) for every row, in parallel; the sums in row order and the
/// total count (each row's sum in its own fixed order: independent of the thread count). A
/// failed allocation of the sums is [`crate::CoreError::OutOfMemory`].
fn row_sums(
    n: usize,
    f: impl Fn(usize) -> (f64, usize) + Sync + Send,
) -> Result<(Vec<f64>, usize)> {
    // Written in place (an unzip into sums and counts allocated 16 bytes a row unchecked).
    let mut u = try_zeroed::<f64>(n, INITIAL_INPUT)?;
    let nnz = u
        .par_iter_mut()
        .enumerate()
        .map(|(a, ua)| {
            let (s, c) = f(a);
            *ua = s;
            c
        })
        .sum();
    Ok((u, nnz))
}

/// What [`Weights::initial_input`]'s allocations are named in an out-of-memory error.
const INITIAL_INPUT: &str = "the Hopfield dynamics' initial net inputs";

/// A net-input sum over row entries: every entry counted, those of active neurons added.
struct ActiveSum<'a> {
    s: f64,
    n: usize,
    state: &'a [u8],
}

impl<'a> ActiveSum<'a> {
    fn new(start: f64, state: &'a [u8]) -> Self {
        ActiveSum {
            s: start,
            n: 0,
            state,
        }
    }
    #[inline]
    fn add(&mut self, b: u32, t: f32) {
        self.n += 1;
        if self.state[b as usize] == 1 {
            self.s += t as f64;
        }
    }
}

/// Read access to a symmetric weight matrix, one row at a time: the dynamics only ever need
/// whole rows (the initial net inputs, then the row of each flipped neuron).
pub trait Weights: Sync {
    /// Number of neurons.
    fn n(&self) -> usize;
    /// Calls `f(b, T_ab)` for every stored entry of row `a`, always in the same order.
    fn for_each_in_row(&self, a: usize, f: impl FnMut(u32, f32));
    /// The net inputs `u_a = input_a + sum_b T_ab [state_b == 1]` of every neuron (each summed
    /// in a fixed order in `f64`, independent of the thread count) and the number of entries.
    /// A failed allocation is [`crate::CoreError::OutOfMemory`].
    fn initial_input(&self, state: &[u8], input: &[f64]) -> Result<(Vec<f64>, usize)> {
        row_sums(self.n(), |a| {
            let mut acc = ActiveSum::new(input[a], state);
            self.for_each_in_row(a, |b, t| acc.add(b, t));
            (acc.s, acc.n)
        })
    }
    /// Length of the dynamics' net-input buffer (at least [`Weights::n`]).
    fn slots(&self) -> usize {
        self.n()
    }
    /// Where `u_a` lives in that buffer (identity unless rows are faster to add in another
    /// order).
    #[inline]
    fn slot(&self, a: usize) -> usize {
        a
    }
    /// `u[slot(b)] += sign * T_ab` for every entry of row `a` (`u`: [`Weights::slots`] long).
    fn add_row(&self, a: usize, sign: f64, u: &mut [f64]) {
        self.for_each_in_row(a, |b, t| u[self.slot(b as usize)] += sign * t as f64);
    }
}

impl Weights for Csr {
    fn n(&self) -> usize {
        Csr::n(self)
    }
    #[inline]
    fn for_each_in_row(&self, a: usize, mut f: impl FnMut(u32, f32)) {
        let (idx, val) = self.row(a);
        for (&b, &t) in idx.iter().zip(val) {
            f(b, t);
        }
    }
}

/// The Hopfield channel's weights, computed when a row is read instead of stored: a row is a
/// scan of the neighbours in the strips of rows around the neuron's left point (each strip's
/// part cut to the window's x-range), while a stored matrix (1-4 M entries on a Middlebury or
/// KITTI pair) has to be built, written and paged in first. Row `a` (left point `p`), in this
/// order:
/// 1. the other candidates of `p`: `-B` (uniqueness along the row);
/// 2. the candidates of other points with `a`'s right pixel, in right-pixel order: `-B`
///    (uniqueness along the column);
/// 3. the candidates of the other points in `p`'s 41x41 window, in strip order, except those
///    with `a`'s right pixel (already in 2): `A / max(n_p, n_q, 1) * C(|d_a - d_b|, r)`,
///    `n` = the points' window neighbour counts, `r` = their Chebyshev distance.
///
/// Every entry is a symmetric function of the pair, so `T` is symmetric.
pub struct Network {
    b: f32,
    half: i32,
    /// Neuron range of every left point (`starts[p]..starts[p + 1]`).
    starts: Vec<usize>,
    p_of: Vec<u32>,
    pxy: Vec<(i32, i32)>,
    /// `A / max(n_p, 1)` per point.
    a_over_n: Vec<f32>,
    a_pos: bool,
    /// Neuron indices sorted by right pixel, each neuron's range in that order, and the rank
    /// of its right pixel among the distinct right pixels.
    by_right: Vec<u32>,
    group: Vec<(u32, u32)>,
    rank: Vec<u32>,
    n_rpix: usize,
    /// Per point: the `cells` ranges of its window, one per strip of rows it touches.
    wranges: Vec<[(u32, u32); MAX_STRIPS]>,
    cells: Cells,
    /// Per neuron (original order): its position in `cells`, where the dynamics keep its net
    /// input (a flip then adds whole lane blocks to contiguous net inputs, no scatter).
    slot_of: Vec<u32>,
    /// First `cells` position of every strip (and the end).
    cell_strip: Vec<u32>,
    /// Per neuron (original order): disparity vector.
    dxs: Vec<i32>,
    dys: Vec<i32>,
    /// Compatibility per Chebyshev distance `r` (row `r`, `lut_stride` entries) over the
    /// squared disparity-vector difference, each row padded with its saturated last value.
    lut: Vec<f32>,
    lut_stride: usize,
}

/// Strips of `ceil(half / 2)` rows a window of `2 half + 1` rows can touch: at most 6.
const MAX_STRIPS: usize = 6;

/// Lanes of the window scan: one AVX2 register of `f32`.
const LANES: usize = 8;

/// What a row's window scan reads of the neurons, as arrays in strip order (strips of
/// `ceil(half / 2)` rows, by x within a strip: a window's neurons in one strip are contiguous),
/// each padded with `LANES` entries so that a block of lanes never reads past the end.
#[derive(Default)]
struct Cells {
    x: Vec<i32>,
    y: Vec<i32>,
    dx: Vec<i32>,
    dy: Vec<i32>,
    point: Vec<u32>,
    rank: Vec<u32>,
    /// `A / max(n_q, 1)` of the neuron's point.
    norm: Vec<f32>,
    /// Neuron index (original order).
    idx: Vec<u32>,
}

/// The row's own values a window scan compares against.
#[derive(Clone, Copy)]
struct RowKey {
    x: i32,
    y: i32,
    dx: i32,
    dy: i32,
    point: u32,
    rank: u32,
    np: f32,
    half: i32,
    stride: usize,
    /// `log2(stride)`.
    shift: u32,
    a_pos: bool,
}

/// `T_ab` of the `LANES` neurons `j0..j0 + LANES` of `cells` (0 for those at or past `e` and
/// for those not in the row: outside the window, the row's own point or right pixel), and
/// which of them are in the row. The AVX2 version ([`lane_weights_avx2`]) performs the same
/// integer and `f32` operations lane by lane: identical results.
#[inline(always)]
fn lane_weights(
    c: &Cells,
    lut: &[f32],
    k: &RowKey,
    j0: usize,
    e: usize,
) -> ([f32; LANES], [bool; LANES]) {
    let (half, stride) = (k.half, k.stride as i32);
    let n_valid = e.saturating_sub(j0).min(LANES);
    let mut t = [0.0f32; LANES];
    let mut in_row = [false; LANES];
    for l in 0..LANES {
        let j = j0 + l;
        let (ddx, ddy) = ((c.x[j] - k.x).abs(), (c.y[j] - k.y).abs());
        let stored = l < n_valid
            && ddx <= half
            && ddy <= half
            && c.point[j] != k.point
            && c.rank[j] != k.rank;
        let nq = c.norm[j];
        let nrm = if (k.np < nq) == k.a_pos { k.np } else { nq };
        // Out-of-window lanes read row `half` (any valid row: their value is zeroed).
        let r = ddx.max(ddy).min(half);
        let (ex, ey) = (k.dx.wrapping_sub(c.dx[j]), k.dy.wrapping_sub(c.dy[j]));
        let q = ex.wrapping_mul(ex).wrapping_add(ey.wrapping_mul(ey));
        let q = (q as u32).min(stride as u32 - 1) as i32;
        let cv = lut[((r << k.shift) + q) as usize];
        t[l] = if stored { nrm * cv } else { 0.0 };
        in_row[l] = stored;
    }
    (t, in_row)
}

/// AVX2 body of [`lane_weights`]: the values as one register, the row membership as a lane
/// mask (all ones where stored).
///
/// # Safety
/// The CPU must support AVX2; `j0 + LANES` must not exceed the (padded) `cells` arrays, and
/// `lut` must hold `(k.half + 1) * k.stride` values.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn lane_weights_avx2(
    c: &Cells,
    lut: &[f32],
    k: &RowKey,
    j0: usize,
    e: usize,
) -> (std::arch::x86_64::__m256, std::arch::x86_64::__m256i) {
    use std::arch::x86_64::*;
    // SAFETY: the loads read j0..j0 + 8 of arrays padded by LANES past every range end
    // (`Network::new`); the gather index is (r << shift) + q with r in 0..=half (coordinates
    // are non-negative, so the distances are) and q in 0..stride (unsigned minimum), below
    // (half + 1) * stride = lut.len() as stride = 1 << shift; the i32 index cannot wrap while
    // the table has fewer than 2^31 entries.
    debug_assert!(j0 + LANES <= c.x.len());
    debug_assert!(
        k.stride == 1 << k.shift
            && lut.len() >= (k.half as usize + 1) * k.stride
            && lut.len() <= i32::MAX as usize
    );
    let ld = |v: &[i32]| _mm256_loadu_si256(v.as_ptr().add(j0) as *const __m256i);
    let ldu = |v: &[u32]| _mm256_loadu_si256(v.as_ptr().add(j0) as *const __m256i);
    let stride = k.stride as i32;
    let half = _mm256_set1_epi32(k.half);
    let ddx = _mm256_abs_epi32(_mm256_sub_epi32(ld(&c.x), _mm256_set1_epi32(k.x)));
    let ddy = _mm256_abs_epi32(_mm256_sub_epi32(ld(&c.y), _mm256_set1_epi32(k.y)));
    let n_valid = e.saturating_sub(j0).min(LANES) as i32;
    let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(n_valid), lane);
    // Not in the row: outside the window, the row's own point or right pixel (one `andnot`
    // at the end instead of a negation per test: fewer live registers, no spills).
    let out = _mm256_or_si256(
        _mm256_or_si256(_mm256_cmpgt_epi32(ddx, half), _mm256_cmpgt_epi32(ddy, half)),
        _mm256_or_si256(
            _mm256_cmpeq_epi32(ldu(&c.point), _mm256_set1_epi32(k.point as i32)),
            _mm256_cmpeq_epi32(ldu(&c.rank), _mm256_set1_epi32(k.rank as i32)),
        ),
    );
    let stored = _mm256_andnot_si256(out, valid);
    let nq = _mm256_loadu_ps(c.norm.as_ptr().add(j0));
    let np = _mm256_set1_ps(k.np);
    // (np < nq) == a_pos picks np; NaN-free inputs, so LT_OQ is `<`.
    let lt = _mm256_cmp_ps::<_CMP_LT_OQ>(np, nq);
    let nrm = if k.a_pos {
        _mm256_blendv_ps(nq, np, lt)
    } else {
        _mm256_blendv_ps(np, nq, lt)
    };
    let r = _mm256_min_epi32(_mm256_max_epi32(ddx, ddy), half);
    let ex = _mm256_sub_epi32(_mm256_set1_epi32(k.dx), ld(&c.dx));
    let ey = _mm256_sub_epi32(_mm256_set1_epi32(k.dy), ld(&c.dy));
    let q = _mm256_add_epi32(_mm256_mullo_epi32(ex, ex), _mm256_mullo_epi32(ey, ey));
    // Unsigned minimum: a (wrapped) negative sum saturates like a large one.
    let q = _mm256_min_epu32(q, _mm256_set1_epi32(stride - 1));
    let idx = _mm256_add_epi32(_mm256_sllv_epi32(r, _mm256_set1_epi32(k.shift as i32)), q);
    let cv = _mm256_i32gather_ps::<4>(lut.as_ptr(), idx);
    let t = _mm256_and_ps(_mm256_mul_ps(nrm, cv), _mm256_castsi256_ps(stored));
    (t, stored)
}

/// Sum over the window part of a row of `T_ab * on_b` (`on` in strip order; with `POS`, the
/// positive `T_ab` only): one `f64` accumulator per lane, added up in lane order at the end;
/// and the part's entry count. With `push = Some((buf, base))`, also `T_ab` added to
/// `buf[j - base]` for every lane `j` (the symmetric initial pass hands a row's upper part to
/// the later rows this way; lanes not in the row add +-0).
fn window_input<const POS: bool>(
    c: &Cells,
    lut: &[f32],
    k: &RowKey,
    ranges: &[(usize, usize)],
    on: &[f32],
    push: Option<(&mut [f64], usize)>,
) -> (f64, usize) {
    // Checked on every call (a compare per row): `Network::support` hands in a caller's `on`,
    // and the AVX2 body reads 8 lanes at each step unchecked.
    assert!(
        on.len() >= c.x.len(),
        "`on` holds {} values, the padded cells {} (see Network::lane_state)",
        on.len(),
        c.x.len()
    );
    if let Some((buf, base)) = &push {
        for &(s, e) in ranges.iter().filter(|r| r.0 < r.1) {
            assert!(
                s >= *base && e - base + LANES <= buf.len(),
                "push buffer of {} values from {base} does not reach {e} + LANES",
                buf.len()
            );
        }
    }
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: AVX2 is present; `cells` is padded by LANES past every range and `on` is as
        // long (asserted above); `lut` holds (half + 1) * stride values (built so in
        // `Network::new`); `buf` reaches LANES past every range end (minus base, asserted).
        return unsafe { window_input_avx2::<POS>(c, lut, k, ranges, on, push) };
    }
    window_input_portable::<POS>(c, lut, k, ranges, on, push)
}

/// Portable body of [`window_input`].
fn window_input_portable<const POS: bool>(
    c: &Cells,
    lut: &[f32],
    k: &RowKey,
    ranges: &[(usize, usize)],
    on: &[f32],
    mut push: Option<(&mut [f64], usize)>,
) -> (f64, usize) {
    let mut acc = [0.0f64; LANES];
    let mut n = 0usize;
    for &(s, e) in ranges {
        for j0 in (s..e).step_by(LANES) {
            let (t, in_row) = lane_weights(c, lut, k, j0, e);
            for l in 0..LANES {
                let tl = if !POS || t[l] > 0.0 { t[l] } else { 0.0 };
                acc[l] += (tl * on[j0 + l]) as f64;
            }
            n += in_row.iter().filter(|&&v| v).count();
            if let Some((buf, base)) = push.as_mut() {
                for (l, &tl) in t.iter().enumerate() {
                    buf[j0 + l - *base] += tl as f64;
                }
            }
        }
    }
    (acc.iter().sum(), n)
}

/// AVX2 body of [`window_input`].
///
/// # Safety
/// As [`lane_weights_avx2`]; `on` padded like `cells`; `buf[j - base]` valid for every lane.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn window_input_avx2<const POS: bool>(
    c: &Cells,
    lut: &[f32],
    k: &RowKey,
    ranges: &[(usize, usize)],
    on: &[f32],
    push: Option<(&mut [f64], usize)>,
) -> (f64, usize) {
    use std::arch::x86_64::*;
    let (mut lo, mut hi) = (_mm256_setzero_pd(), _mm256_setzero_pd());
    let mut n = 0usize;
    // SAFETY: `on` is padded like `cells` (its 8-lane loads at j0 < e stay inside); the push
    // buffer `buf[j0 - base..j0 - base + 8]` is in bounds when it reaches LANES past every
    // non-empty range's end (minus base) and no range starts below base (checked here in
    // debug builds).
    debug_assert!(on.len() >= c.x.len());
    debug_assert!(match &push {
        Some((buf, base)) => ranges
            .iter()
            .all(|&(s, e)| s >= e || (s >= *base && e - base + LANES <= buf.len())),
        None => true,
    });
    let (bp, base) = match push {
        Some((buf, base)) => (buf.as_mut_ptr(), base),
        None => (std::ptr::null_mut(), 0),
    };
    for &(s, e) in ranges {
        for j0 in (s..e).step_by(LANES) {
            let (t0, stored) = lane_weights_avx2(c, lut, k, j0, e);
            let t = if POS {
                _mm256_and_ps(t0, _mm256_cmp_ps::<_CMP_GT_OQ>(t0, _mm256_setzero_ps()))
            } else {
                t0
            };
            let v = _mm256_mul_ps(t, _mm256_loadu_ps(on.as_ptr().add(j0)));
            lo = _mm256_add_pd(lo, _mm256_cvtps_pd(_mm256_castps256_ps128(v)));
            hi = _mm256_add_pd(hi, _mm256_cvtps_pd(_mm256_extractf128_ps::<1>(v)));
            n += _mm256_movemask_ps(_mm256_castsi256_ps(stored)).count_ones() as usize;
            if !bp.is_null() {
                let p = bp.add(j0 - base);
                let tl = _mm256_cvtps_pd(_mm256_castps256_ps128(t0));
                let th = _mm256_cvtps_pd(_mm256_extractf128_ps::<1>(t0));
                _mm256_storeu_pd(p, _mm256_add_pd(_mm256_loadu_pd(p), tl));
                _mm256_storeu_pd(p.add(4), _mm256_add_pd(_mm256_loadu_pd(p.add(4)), th));
            }
        }
    }
    let mut acc = [0.0f64; LANES];
    _mm256_storeu_pd(acc.as_mut_ptr(), lo);
    _mm256_storeu_pd(acc.as_mut_ptr().add(4), hi);
    (acc.iter().sum(), n)
}

/// `u[j] += sign * T_ab` over the window part of a row, `u` in `cells` order (lanes not in
/// the row add +-0, which leaves a net input bit-identical).
fn window_add(
    c: &Cells,
    lut: &[f32],
    k: &RowKey,
    ranges: &[(usize, usize)],
    sign: f64,
    u: &mut [f64],
) {
    // `Weights::add_row` is safe and takes the caller's `u`: checked on every call.
    assert!(
        u.len() >= c.idx.len(),
        "`u` holds {} values, the padded cells {} (see Weights::slots)",
        u.len(),
        c.idx.len()
    );
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: as in `window_input`; `u` is as long as the padded cells (asserted above).
        return unsafe { window_add_avx2(c, lut, k, ranges, sign, u) };
    }
    window_add_portable(c, lut, k, ranges, sign, u)
}

/// Portable body of [`window_add`].
fn window_add_portable(
    c: &Cells,
    lut: &[f32],
    k: &RowKey,
    ranges: &[(usize, usize)],
    sign: f64,
    u: &mut [f64],
) {
    for &(s, e) in ranges {
        for j0 in (s..e).step_by(LANES) {
            let (t, _) = lane_weights(c, lut, k, j0, e);
            for (l, &tl) in t.iter().enumerate() {
                u[j0 + l] += sign * tl as f64;
            }
        }
    }
}

/// AVX2 body of [`window_add`].
///
/// # Safety
/// As [`lane_weights_avx2`]; `u` as long as the padded `cells`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn window_add_avx2(
    c: &Cells,
    lut: &[f32],
    k: &RowKey,
    ranges: &[(usize, usize)],
    sign: f64,
    u: &mut [f64],
) {
    use std::arch::x86_64::*;
    debug_assert!(sign == 1.0 || sign == -1.0);
    debug_assert!(u.len() >= c.idx.len());
    let flip = _mm256_set1_ps(if sign < 0.0 { -0.0 } else { 0.0 });
    for &(s, e) in ranges {
        for j0 in (s..e).step_by(LANES) {
            let (tv, _) = lane_weights_avx2(c, lut, k, j0, e);
            // `sign * t` exactly, as a sign flip of the f32 (no multiply per lane).
            let v = _mm256_xor_ps(tv, flip);
            // SAFETY: j0 + LANES <= the padded cells length <= u.len().
            let p = u.as_mut_ptr().add(j0);
            _mm256_storeu_pd(
                p,
                _mm256_add_pd(
                    _mm256_loadu_pd(p),
                    _mm256_cvtps_pd(_mm256_castps256_ps128(v)),
                ),
            );
            _mm256_storeu_pd(
                p.add(4),
                _mm256_add_pd(
                    _mm256_loadu_pd(p.add(4)),
                    _mm256_cvtps_pd(_mm256_extractf128_ps::<1>(v)),
                ),
            );
        }
    }
}

/// A point's window: its ranges of strip-order positions, one per strip (see
/// [`strip_windows`]), and its neighbour count.
type PointWindow = ([(u32, u32); MAX_STRIPS], usize);

/// For every query point (`queries`, one of the points, in any order) of the points in strip
/// order (strips of `strip_h` rows, by x within a strip; `sx`, `sy` their coordinates,
/// `strip_start` the strips' starts): the ranges of strip-order positions within `half` of it
/// in x, one per strip its window's rows touch (from the top; unused ones empty), and the
/// number of other points within `half` in both coordinates. The ranges come from per-strip
/// prefix counts (the points of a strip left of each column; a strip's points come by
/// increasing x), without a search; the count is a range length for the strips inside the
/// window's rows and a scan of the range's rows for the (at most two) strips cut by it.
fn strip_windows(
    sx: &[i32],
    sy: &[i32],
    strip_start: &[usize],
    strip_h: i32,
    half: i32,
    queries: &[(i32, i32)],
) -> Result<Vec<PointWindow>> {
    const WHAT: &str = "the Hopfield network's point windows";
    let n_strips = strip_start.len() - 1;
    let w = sx.iter().copied().max().unwrap_or(0) as usize + 1;
    let stride = w + 1;
    // xp[t][x]: points of strip t with sx < x.
    let mut xp = try_zeroed::<u32>(n_strips.saturating_mul(stride), WHAT)?;
    xp.par_chunks_mut(stride).enumerate().for_each(|(t, row)| {
        for &x in &sx[strip_start[t]..strip_start[t + 1]] {
            row[x as usize + 1] += 1;
        }
        for x in 1..stride {
            row[x] += row[x - 1];
        }
    });
    let last = n_strips as i32 - 1;
    let mut wins = Vec::new();
    try_reserve_len(&mut wins, queries.len(), WHAT)?;
    queries
        .par_iter()
        .map(|&(x, y)| {
            let xa = (x - half).max(0) as usize;
            let xb = ((x + half + 1) as usize).min(w);
            let s_lo = (y - half).max(0) / strip_h;
            let s_hi = ((y + half) / strip_h).min(last);
            let mut r = [(0u32, 0u32); MAX_STRIPS];
            let mut count = 0usize;
            for t in s_lo..=s_hi {
                let base = strip_start[t as usize];
                let lo = base + xp[t as usize * stride + xa] as usize;
                let hi = base + xp[t as usize * stride + xb] as usize;
                r[(t - s_lo) as usize] = (lo as u32, hi as u32);
                let inside = t * strip_h >= y - half && t * strip_h + strip_h - 1 <= y + half;
                count += if inside {
                    hi - lo
                } else {
                    sy[lo..hi]
                        .iter()
                        .filter(|&&qy| (qy - y).abs() <= half)
                        .count()
                };
            }
            (r, count - 1) // the point itself
        })
        .collect_into_vec(&mut wins); // into the reserved room: no reallocation
    Ok(wins)
}

/// Strip order of the points `pxy` (strips of `(half + 1) / 2` rows, by x within a strip, so
/// that a window's points in one strip are ONE contiguous range cut exactly in x): the strips'
/// starts, the points in strip order and each point's window ([`strip_windows`], point order).
/// A failed allocation is [`crate::CoreError::OutOfMemory`].
#[allow(clippy::type_complexity)]
fn strip_order(pxy: &[(i32, i32)], half: i32) -> Result<(Vec<usize>, Vec<u32>, Vec<PointWindow>)> {
    const WHAT: &str = "the Hopfield network's strip order";
    let strip_h = (half + 1) / 2;
    let n_strips = pxy.iter().map(|p| p.1 / strip_h).max().unwrap_or(0) as usize + 1;
    let w_max = pxy.iter().map(|p| p.0).max().unwrap_or(0) as usize;
    // Strips by (x, index): a stable counting sort by x, then a stable one into strips.
    let (_, by_x) = counting_sort(
        0..pxy.len() as u32,
        |q| pxy[q as usize].0 as usize,
        w_max + 1,
        WHAT,
    )?;
    let strip_of = |q: u32| (pxy[q as usize].1 / strip_h) as usize;
    let (strip_start, sorder) = counting_sort(by_x.iter().copied(), strip_of, n_strips, WHAT)?;
    drop(by_x);
    let sx = try_collect(
        sorder.len(),
        sorder.iter().map(|&q| pxy[q as usize].0),
        WHAT,
    )?;
    let sy = try_collect(
        sorder.len(),
        sorder.iter().map(|&q| pxy[q as usize].1),
        WHAT,
    )?;
    // Per point (point order): its window's point ranges per strip and neighbour count n_p.
    let wins = strip_windows(&sx, &sy, &strip_start, strip_h, half, pxy)?;
    Ok((strip_start, sorder, wins))
}

/// Column groups: neurons sharing a right pixel, wherever their left points are. The neurons
/// in right-pixel order, each neuron's group (its range in that order) and its right pixel's
/// rank, and the number of right pixels. A failed allocation is
/// [`crate::CoreError::OutOfMemory`].
#[allow(clippy::type_complexity)]
fn right_groups(neurons: &[Neuron]) -> Result<(Vec<u32>, Vec<(u32, u32)>, Vec<u32>, u32)> {
    const WHAT: &str = "the Hopfield network's right-pixel groups";
    let m = neurons.len();
    let key = |a: u32| (neurons[a as usize].yr, neurons[a as usize].xr);
    let by_right = right_pixel_order(neurons, try_collect(m, 0..m, WHAT)?, WHAT)?;
    let mut group = try_filled(m, (0u32, 0u32), WHAT)?;
    let mut rank = try_zeroed::<u32>(m, WHAT)?;
    let (mut g0, mut n_groups) = (0, 0u32);
    for k in 1..=m {
        if k == m || key(by_right[k]) != key(by_right[g0]) {
            for &a in &by_right[g0..k] {
                group[a as usize] = (g0 as u32, k as u32);
                rank[a as usize] = n_groups;
            }
            g0 = k;
            n_groups += 1;
        }
    }
    Ok((by_right, group, rank, n_groups))
}

/// Strips per task of the symmetric initial pass: a fixed split of the rows, so the sums do
/// not depend on the thread count.
const SYM_STRIPS: usize = 4;

impl Network {
    /// The network of `neurons`, which must be grouped by `point` in increasing order and
    /// have non-negative coordinates. A failed allocation of its per-neuron and per-point
    /// tables is [`crate::CoreError::OutOfMemory`].
    pub fn new(neurons: &[Neuron], w: &EnergyWeights) -> Result<Self> {
        const WHAT: &str = "the Hopfield network's tables";
        let m = neurons.len();
        let mut starts: Vec<usize> = Vec::new();
        try_reserve_len(&mut starts, m + 1, WHAT)?; // at most one point a neuron
        for (a, nr) in neurons.iter().enumerate() {
            if a == 0 || nr.point != neurons[a - 1].point {
                starts.push(a);
            }
        }
        let n_pts = starts.len();
        starts.push(m);
        let pxy = try_collect(
            n_pts,
            (0..n_pts).map(|p| (neurons[starts[p]].xl.max(0), neurons[starts[p]].yl.max(0))),
            WHAT,
        )?;
        let half = w.nbr_half.max(1);
        let p_of = try_collect(
            m,
            (0..n_pts).flat_map(|p| std::iter::repeat_n(p as u32, starts[p + 1] - starts[p])),
            WHAT,
        )?;
        let dxs = try_collect(m, neurons.iter().map(Neuron::dx), WHAT)?;
        let dys = try_collect(m, neurons.iter().map(Neuron::dy), WHAT)?;
        // The strip order and windows, and the right-pixel groups, are independent: built side
        // by side.
        let (strips, groups) = rayon::join(|| strip_order(&pxy, half), || right_groups(neurons));
        let ((strip_start, sorder, wins), (by_right, group, rank, n_groups)) = (strips?, groups?);
        // A / max(n_p, n_q, 1) = min(A / max(n_p, 1), A / max(n_q, 1)) exactly: division rounds
        // monotonically (max for a negative A). One division per point instead of per pair.
        let a_over_n = try_collect(
            wins.len(),
            wins.iter().map(|&(_, n)| w.a / (n as f32).max(1.0)),
            WHAT,
        )?;
        // Strip-ordered neuron arrays: the neuron order first, then each array by an
        // exact-size map over it (padded with LANES entries).
        let mut gstart = Vec::new();
        try_reserve_len(&mut gstart, n_pts + 1, WHAT)?;
        gstart.push(0u32);
        let mut idx: Vec<u32> = Vec::new();
        try_reserve_len(&mut idx, m + LANES, WHAT)?;
        for &q in &sorder {
            let q = q as usize;
            idx.extend(starts[q] as u32..starts[q + 1] as u32);
            gstart.push(idx.len() as u32);
        }
        fn padded<T: Copy + Default>(idx: &[u32], f: impl Fn(usize) -> T) -> Result<Vec<T>> {
            let mut v: Vec<T> = Vec::new();
            try_reserve_len(&mut v, idx.len() + LANES, WHAT)?;
            v.extend(idx.iter().map(|&b| f(b as usize)));
            v.resize(idx.len() + LANES, T::default());
            Ok(v)
        }
        let cells = Cells {
            x: padded(&idx, |b| pxy[p_of[b] as usize].0)?,
            y: padded(&idx, |b| pxy[p_of[b] as usize].1)?,
            dx: padded(&idx, |b| dxs[b])?,
            dy: padded(&idx, |b| dys[b])?,
            point: padded(&idx, |b| p_of[b])?,
            rank: padded(&idx, |b| rank[b])?,
            norm: padded(&idx, |b| a_over_n[p_of[b] as usize])?,
            idx: padded(&idx, |b| b as u32)?,
        };
        let padded = cells.idx.len();
        let mut slot_of = try_zeroed::<u32>(m, WHAT)?;
        for (j, &b) in cells.idx[..padded - LANES].iter().enumerate() {
            slot_of[b as usize] = j as u32;
        }
        let cell_strip = try_collect(
            strip_start.len(),
            strip_start.iter().map(|&q| gstart[q]),
            WHAT,
        )?;
        // Per point, the `cells` range of its window in each strip the window's rows touch.
        let mut wranges: Vec<[(u32, u32); MAX_STRIPS]> = Vec::new();
        try_reserve_len(&mut wranges, wins.len(), WHAT)?;
        wins.par_iter()
            .map(|(r, _)| r.map(|(lo, hi)| (gstart[lo as usize], gstart[hi as usize])))
            .collect_into_vec(&mut wranges);
        // Compatibility lookup per Chebyshev distance r of the two points (0..=half) over the
        // integer squared disparity-vector difference q. A row ends where the f32 value has
        // saturated at -1 (slope > 0, q past the crossing): larger q read the last entry, which
        // is exactly what the formula gives there.
        let span = |v: &[i32]| {
            let lo = v.iter().copied().min().unwrap_or(0);
            let hi = v.iter().copied().max().unwrap_or(0);
            (hi - lo) as usize
        };
        // Checked: a row is as long as the squared disparity span when the values never
        // saturate (compat_slope = 0: 2^22 entries a row for a span of 2048 px).
        const LUT: &str = "the Hopfield network's compatibility table";
        let (max_dx, max_dy) = (span(&dxs), span(&dys));
        let max_q = max_dx * max_dx + max_dy * max_dy;
        let mut rows: Vec<Vec<f32>> = Vec::new();
        try_reserve_len(&mut rows, half as usize + 1, LUT)?;
        for r in 0..=half {
            let theta = w.compat_theta as f64 + w.compat_grad as f64 * r as f64;
            let mut row = Vec::new();
            for q in 0..=max_q {
                let v = compat((q as f64).sqrt(), theta, w.compat_slope as f64) as f32;
                try_grow(&mut row, 1, LUT)?; // as `push` grows, checked
                row.push(v);
                if v == -1.0 && w.compat_slope > 0.0 && (q as f64).sqrt() > theta {
                    break;
                }
            }
            rows.push(row);
        }
        // A power-of-two stride: the lanes index the table with a shift, not a multiply.
        let lut_stride = rows
            .iter()
            .map(Vec::len)
            .max()
            .unwrap_or(1)
            .next_power_of_two();
        let mut lut = Vec::new();
        try_reserve_len(&mut lut, rows.len().saturating_mul(lut_stride), LUT)?;
        for row in &rows {
            lut.extend_from_slice(row);
            let last = row[row.len() - 1];
            lut.resize(lut.len() + lut_stride - row.len(), last);
        }
        Ok(Network {
            b: w.b,
            half,
            starts,
            p_of,
            pxy,
            a_over_n,
            a_pos: w.a >= 0.0,
            by_right,
            group,
            rank,
            n_rpix: n_groups as usize,
            wranges,
            cells,
            slot_of,
            cell_strip,
            dxs,
            dys,
            lut,
            lut_stride,
        })
    }

    /// The rank of neuron `a`'s right pixel among the distinct right pixels (`0..`
    /// [`Network::n_right_pixels`]).
    pub fn right_pixel(&self, a: usize) -> usize {
        self.rank[a] as usize
    }

    /// Number of distinct right pixels of the neurons.
    pub fn n_right_pixels(&self) -> usize {
        self.n_rpix
    }

    /// `state` (0/1 per neuron) in strip order, as `f32` factors of the lanes (padding 0).
    /// A failed allocation is [`crate::CoreError::OutOfMemory`] naming `what`.
    pub fn lane_state(&self, state: &[u8], what: &'static str) -> Result<Vec<f32>> {
        let n = self.cells.idx.len() - LANES;
        let mut on = try_zeroed::<f32>(n + LANES, what)?;
        for (o, &b) in on.iter_mut().zip(&self.cells.idx[..n]) {
            *o = f32::from(state[b as usize]);
        }
        Ok(on)
    }

    /// Support of neuron `a`: the sum of its positive weights from active neurons (`on` from
    /// [`Network::lane_state`]), in a fixed order.
    pub fn support(&self, a: usize, state: &[u8], on: &[f32]) -> f64 {
        let mut s = 0.0f64;
        self.for_each_unique(a, |b, t| {
            if t > 0.0 && state[b as usize] == 1 {
                s += t as f64;
            }
        });
        let k = self.key(a);
        let ranges = self.window_ranges(a);
        s + window_input::<true>(&self.cells, &self.lut, &k, &ranges, on, None).0
    }

    fn key(&self, a: usize) -> RowKey {
        let p = self.p_of[a] as usize;
        RowKey {
            x: self.pxy[p].0,
            y: self.pxy[p].1,
            dx: self.dxs[a],
            dy: self.dys[a],
            point: p as u32,
            rank: self.rank[a],
            np: self.a_over_n[p],
            half: self.half,
            stride: self.lut_stride,
            shift: self.lut_stride.trailing_zeros(),
            a_pos: self.a_pos,
        }
    }

    /// The `cells` ranges of the window of `a`'s point (empty ones past its strips).
    fn window_ranges(&self, a: usize) -> [(usize, usize); MAX_STRIPS] {
        self.wranges[self.p_of[a] as usize].map(|(s, e)| (s as usize, e as usize))
    }

    /// Calls `f(b, -B)` for the uniqueness part of row `a`: the other candidates of its point,
    /// then the other points' candidates with its right pixel.
    #[inline]
    fn for_each_unique(&self, a: usize, mut f: impl FnMut(u32, f32)) {
        let p = self.p_of[a] as usize;
        for b in self.starts[p]..self.starts[p + 1] {
            if b != a {
                f(b as u32, -self.b);
            }
        }
        let (gs, ge) = self.group[a];
        for &b in &self.by_right[gs as usize..ge as usize] {
            if self.p_of[b as usize] as usize != p {
                f(b, -self.b);
            }
        }
    }
}

impl Weights for Network {
    fn n(&self) -> usize {
        self.p_of.len()
    }

    fn for_each_in_row(&self, a: usize, mut f: impl FnMut(u32, f32)) {
        self.for_each_unique(a, &mut f);
        let k = self.key(a);
        for (s, e) in self.window_ranges(a) {
            for j0 in (s..e).step_by(LANES) {
                let (t, in_row) = lane_weights(&self.cells, &self.lut, &k, j0, e);
                for l in 0..LANES {
                    if in_row[l] {
                        f(self.cells.idx[j0 + l], t[l]);
                    }
                }
            }
        }
    }

    /// Each window pair once (`T` is symmetric): a row scans only the positions after its own,
    /// sums `T_ab V_b` there and pushes `T_ab V_a` to the later rows; in fixed tasks of
    /// `SYM_STRIPS` strips, each with its own push buffer, then added up in task order. Half
    /// the lane work of one full scan per row; independent of the thread count.
    fn initial_input(&self, state: &[u8], input: &[f64]) -> Result<(Vec<f64>, usize)> {
        let on = self.lane_state(state, INITIAL_INPUT)?;
        let slots = self.cells.idx.len();
        let n_strips = self.cell_strip.len() - 1;
        let tasks: Vec<(usize, usize)> = (0..n_strips)
            .step_by(SYM_STRIPS)
            .map(|st| {
                let end = (st + SYM_STRIPS).min(n_strips);
                (self.cell_strip[st] as usize, self.cell_strip[end] as usize)
            })
            .collect();
        // Per task: the rows' own sums (input, uniqueness part, upper window part), the push
        // buffer from `j0`, and the entry count.
        let parts: Vec<(Vec<f64>, Vec<f64>, usize)> = tasks
            .par_iter()
            .map(|&(j0, j1)| {
                let reach = (j0..j1)
                    .map(|j| {
                        let a = self.cells.idx[j] as usize;
                        self.window_ranges(a).iter().map(|r| r.1).max().unwrap_or(0)
                    })
                    .max()
                    .unwrap_or(j1)
                    .max(j1);
                let mut buf = try_zeroed::<f64>(reach - j0 + LANES, INITIAL_INPUT)?;
                let mut own = Vec::new();
                try_reserve_len(&mut own, j1 - j0, INITIAL_INPUT)?;
                let mut n = 0usize;
                for j in j0..j1 {
                    let a = self.cells.idx[j] as usize;
                    let mut acc = ActiveSum::new(input[a], state);
                    self.for_each_unique(a, |b, t| acc.add(b, t));
                    let ranges = self
                        .window_ranges(a)
                        .map(|(s, e)| (s.max(j + 1), e.max(j + 1)));
                    let push = (on[j] != 0.0).then_some((&mut buf[..], j0));
                    let k = self.key(a);
                    let (w, nw) =
                        window_input::<false>(&self.cells, &self.lut, &k, &ranges, &on, push);
                    own.push(acc.s + w);
                    n += acc.n + 2 * nw;
                }
                Ok((own, buf, n))
            })
            .collect::<Result<_>>()?;
        let mut u_slot = try_zeroed::<f64>(slots, INITIAL_INPUT)?;
        let mut nnz = 0usize;
        for (&(j0, j1), (own, _, n)) in tasks.iter().zip(&parts) {
            u_slot[j0..j1].copy_from_slice(own);
            nnz += n;
        }
        for (&(j0, _), (_, buf, _)) in tasks.iter().zip(&parts) {
            let end = (j0 + buf.len()).min(slots);
            for (u, &b) in u_slot[j0..end].iter_mut().zip(buf) {
                *u += b;
            }
        }
        let u = try_collect(
            self.n(),
            (0..self.n()).map(|a| u_slot[self.slot_of[a] as usize]),
            INITIAL_INPUT,
        )?;
        Ok((u, nnz))
    }

    fn slots(&self) -> usize {
        self.cells.idx.len()
    }

    #[inline]
    fn slot(&self, a: usize) -> usize {
        self.slot_of[a] as usize
    }

    fn add_row(&self, a: usize, sign: f64, u: &mut [f64]) {
        self.for_each_unique(a, |b, t| {
            u[self.slot_of[b as usize] as usize] += sign * t as f64
        });
        let k = self.key(a);
        window_add(&self.cells, &self.lut, &k, &self.window_ranges(a), sign, u);
    }
}

/// Builds the CSR weights (the [`Network`]'s rows, stored). `neurons` must be grouped by
/// `point` in increasing order and have non-negative coordinates. A failed allocation of the
/// network's tables is [`crate::CoreError::OutOfMemory`].
pub fn build_weights(neurons: &[Neuron], w: &EnergyWeights) -> Result<Csr> {
    let net = Network::new(neurons, w)?;
    let rows: Vec<(Vec<u32>, Vec<f32>)> = (0..net.n())
        .into_par_iter()
        .map(|a| {
            let (mut idx, mut val) = (Vec::new(), Vec::new());
            net.for_each_in_row(a, |b, t| {
                idx.push(b);
                val.push(t);
            });
            (idx, val)
        })
        .collect();
    let mut csr = Csr {
        indptr: vec![0],
        ..Csr::default()
    };
    for (idx, val) in rows {
        csr.indices.extend(idx);
        csr.data.extend(val);
        csr.indptr.push(csr.indices.len());
    }
    Ok(csr)
}

/// SplitMix64: a tiny, well-mixed generator (mirrored exactly by the NumPy reference).
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Fisher-Yates shuffle (`j = next % (i + 1)` for `i = n-1 .. 1`).
    pub fn shuffle(&mut self, v: &mut [u32]) {
        for i in (1..v.len()).rev() {
            let j = (self.next_u64() % (i as u64 + 1)) as usize;
            v.swap(i, j);
        }
    }
}

/// Final state of the dynamics.
#[derive(Debug, Clone, PartialEq)]
pub struct Dynamics {
    /// Neuron states (0/1).
    pub state: Vec<u8>,
    /// Energy of the initial state, then after every sweep.
    pub energy_trace: Vec<f64>,
    /// Sweeps run (the last one without a flip when `converged`).
    pub sweeps: usize,
    pub converged: bool,
    /// Entries of the weight matrix (counted while the initial net inputs are summed).
    pub nnz: usize,
}

/// Energy `E = -1/2 V^T T V - I^T V` from the net inputs `u = T V + I` (neuron order).
fn energy(state: &[u8], u: &[f64], input: &[f64]) -> f64 {
    state
        .iter()
        .zip(u.iter().zip(input))
        .filter(|(&v, _)| v == 1)
        .map(|(_, (&ua, &ia))| -(0.5 * (ua - ia) + ia))
        .sum()
}

/// The slot-ordered arrays of [`run_dynamics`] (slot of each neuron, net inputs, states, the
/// neuron in each slot, the visiting order), allocated checked out of line (no error path near
/// the sweeps).
#[allow(clippy::type_complexity)]
#[inline(never)]
fn slot_arrays<W: Weights>(net: &W) -> Result<(Vec<u32>, Vec<f64>, Vec<u8>, Vec<u32>, Vec<u32>)> {
    const WHAT: &str = "the Hopfield dynamics' slot arrays";
    let m = net.n();
    let slot = try_collect(m, (0..m).map(|a| net.slot(a) as u32), WHAT)?;
    let u = try_zeroed::<f64>(net.slots(), WHAT)?;
    let st = try_zeroed::<u8>(net.slots(), WHAT)?;
    let neuron_at = try_zeroed::<u32>(net.slots(), WHAT)?;
    let order = try_collect(m, slot.iter().copied(), WHAT)?;
    Ok((slot, u, st, neuron_at, order))
}

/// Runs the asynchronous dynamics from `init` until a sweep without a flip (or `max_sweeps`).
/// A failed allocation of its per-neuron arrays is [`crate::CoreError::OutOfMemory`].
pub fn run_dynamics<W: Weights>(
    net: &W,
    input: &[f64],
    init: &[u8],
    seed: u64,
    max_sweeps: usize,
) -> Result<Dynamics> {
    let m = net.n();
    let mut state = try_collect(
        init.len(),
        init.iter().copied(),
        "the Hopfield dynamics' state",
    )?;
    // Initial net inputs u_a = I_a + sum_b T_ab V_b, each from its own row (T is symmetric):
    // in parallel, every sum in row order, so independent of the thread count.
    let (u0, nnz) = net.initial_input(init, input)?;
    let mut trace = vec![energy(&state, &u0, input)];
    // The sweeps work in the weights' slot order (see `Weights::slot`): net inputs, states and
    // the visiting order are indexed by slot, so a visit reads two arrays at one index.
    let (slot, mut u, mut st, mut neuron_at, mut order) = slot_arrays(net)?;
    for (a, &j) in slot.iter().enumerate() {
        u[j as usize] = u0[a];
        st[j as usize] = state[a];
        neuron_at[j as usize] = a as u32;
    }
    // The shuffle moves entries by position only, so shuffling the slots of 0..m visits the
    // same neurons in the same sequence as shuffling 0..m (`order` starts as a copy of `slot`).
    let mut rng = SplitMix64::new(seed);
    // Energy tracked per flip: switching `a` on changes E by -u_a, off by +u_a (T_aa = 0), and
    // a flip happens only against the sign of u_a, so every step lowers E.
    let mut e = trace[0];
    let mut sweeps = 0;
    let mut converged = m == 0;
    while !converged && sweeps < max_sweeps {
        rng.shuffle(&mut order);
        let mut flips = 0usize;
        for &j in &order {
            let j = j as usize;
            let (ua, old) = (u[j], st[j]);
            let new = if ua > 0.0 {
                1
            } else if ua < 0.0 {
                0
            } else {
                old
            };
            if new != old {
                st[j] = new;
                flips += 1;
                let sign = if new == 1 { 1.0 } else { -1.0 };
                e -= sign * ua;
                net.add_row(neuron_at[j] as usize, sign, &mut u);
            }
        }
        sweeps += 1;
        trace.push(e);
        converged = flips == 0;
    }
    for (a, &j) in slot.iter().enumerate() {
        state[a] = st[j as usize];
    }
    Ok(Dynamics {
        state,
        energy_trace: trace,
        sweeps,
        converged,
        nnz,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random neurons: points on a 160x120 image, 1-3 candidates each, some sharing a right
    /// pixel, disparities 0-40 and vertical disparities -1..=1.
    fn random_neurons(seed: u64) -> Vec<Neuron> {
        let mut rng = SplitMix64::new(seed);
        let mut next = |n: u64| (rng.next_u64() % n) as i32;
        let mut out = Vec::new();
        for p in 0..900u32 {
            let (x, y) = (next(160) + 40, next(120));
            for _ in 0..1 + next(3) {
                let d = next(41);
                out.push(Neuron {
                    point: p,
                    xl: x,
                    yl: y,
                    xr: x - d,
                    yr: (y + next(3) - 1).max(0),
                    sim: 0.8,
                    edge_ok: true,
                    halves_fail: 0,
                    centre_ok: true,
                    sub: 0.0,
                });
            }
        }
        out
    }

    #[test]
    fn division_by_multiply_is_exact() {
        let mut rng = SplitMix64::new(5);
        for d in (1..=300u32).chain([1 << 10, 1000, 4095, 65_537, (1 << 31) - 1]) {
            let div = DivBy::new(d);
            let edges = [0, 1, d - 1, d, d + 1, i32::MAX as u32 - 1, i32::MAX as u32];
            let random = (0..200).map(|_| (rng.next_u64() >> 33) as u32);
            for x in edges
                .into_iter()
                .chain(random)
                .filter(|&x| x <= i32::MAX as u32)
            {
                assert_eq!(div.of(x as i32), (x / d) as i32, "{x} / {d}");
            }
        }
    }

    #[test]
    fn strip_windows_equal_searches_and_brute_force_counts() {
        let mut rng = SplitMix64::new(11);
        let (half, strip_h) = (20, 10);
        // 700 distinct points on a 300x200 image, in strip order.
        let mut pts: Vec<(i32, i32)> = (0..700)
            .map(|_| ((rng.next_u64() % 300) as i32, (rng.next_u64() % 200) as i32))
            .collect();
        pts.sort_unstable_by_key(|&(x, y)| (y / strip_h, x, y));
        pts.dedup();
        let n_strips = (pts.iter().map(|p| p.1).max().unwrap() / strip_h + 1) as usize;
        let mut strip_start = vec![0usize; n_strips + 1];
        for &(_, y) in &pts {
            strip_start[(y / strip_h) as usize + 1] += 1;
        }
        for i in 1..=n_strips {
            strip_start[i] += strip_start[i - 1];
        }
        let sx: Vec<i32> = pts.iter().map(|p| p.0).collect();
        let sy: Vec<i32> = pts.iter().map(|p| p.1).collect();
        let wins = strip_windows(&sx, &sy, &strip_start, strip_h, half, &pts).unwrap();
        for (i, &(x, y)) in pts.iter().enumerate() {
            let brute = pts
                .iter()
                .filter(|&&(qx, qy)| (qx - x).abs() <= half && (qy - y).abs() <= half)
                .count();
            assert_eq!(wins[i].1, brute - 1, "count of point {i}");
            let s_lo = ((y - half).max(0) / strip_h) as usize;
            let s_hi = (((y + half) / strip_h) as usize).min(n_strips - 1);
            for (k, st) in (s_lo..=s_hi).enumerate() {
                let (a, b) = (strip_start[st], strip_start[st + 1]);
                let lo = a + sx[a..b].partition_point(|&v| v < x - half);
                let hi = a + sx[a..b].partition_point(|&v| v <= x + half);
                assert_eq!(
                    wins[i].0[k],
                    (lo as u32, hi as u32),
                    "strip {st} of point {i}"
                );
            }
            assert!(wins[i].0[s_hi - s_lo + 1..].iter().all(|&r| r == (0, 0)));
        }
        // The queries in any order: the same answer per point.
        let rev: Vec<(i32, i32)> = pts.iter().rev().copied().collect();
        let mut wins_rev = strip_windows(&sx, &sy, &strip_start, strip_h, half, &rev).unwrap();
        wins_rev.reverse();
        assert_eq!(wins_rev, wins);
    }

    #[test]
    fn avx2_and_portable_row_scans_are_bit_identical() {
        for seed in 0..3 {
            let neurons = random_neurons(seed);
            let net = Network::new(&neurons, &EnergyWeights::default()).unwrap();
            let on: Vec<f32> = (0..net.cells.idx.len())
                .map(|j| {
                    if j % 3 == 0 || j >= net.cells.idx.len() - LANES {
                        0.0
                    } else {
                        1.0
                    }
                })
                .collect();
            let m = neurons.len();
            let (mut u_simd, mut u_port) = (
                vec![0.5f64; net.cells.idx.len()],
                vec![0.5f64; net.cells.idx.len()],
            );
            for a in 0..m {
                let k = net.key(a);
                let ranges = net.window_ranges(a);
                let want =
                    window_input_portable::<false>(&net.cells, &net.lut, &k, &ranges, &on, None);
                assert_eq!(
                    window_input::<false>(&net.cells, &net.lut, &k, &ranges, &on, None),
                    want
                );
                let want =
                    window_input_portable::<true>(&net.cells, &net.lut, &k, &ranges, &on, None);
                assert_eq!(
                    window_input::<true>(&net.cells, &net.lut, &k, &ranges, &on, None),
                    want
                );
                let sign = if a % 2 == 0 { 1.0 } else { -1.0 };
                window_add(&net.cells, &net.lut, &k, &ranges, sign, &mut u_simd);
                window_add_portable(&net.cells, &net.lut, &k, &ranges, sign, &mut u_port);
                // The upper part of the row with its pushes, from position j + 1.
                let j = net.slot_of[a] as usize;
                let upper = ranges.map(|(s, e)| (s.max(j + 1), e.max(j + 1)));
                let (mut b_simd, mut b_port) =
                    (vec![0.0f64; net.slots()], vec![0.0f64; net.slots()]);
                assert_eq!(
                    window_input::<false>(
                        &net.cells,
                        &net.lut,
                        &k,
                        &upper,
                        &on,
                        Some((&mut b_simd, 0))
                    ),
                    window_input_portable::<false>(
                        &net.cells,
                        &net.lut,
                        &k,
                        &upper,
                        &on,
                        Some((&mut b_port, 0))
                    )
                );
                assert_eq!(b_simd, b_port);
            }
            assert_eq!(u_simd, u_port);
        }
    }

    #[test]
    fn implicit_rows_give_the_stored_matrix_dynamics() {
        let neurons = random_neurons(7);
        let w = EnergyWeights::default();
        let net = Network::new(&neurons, &w).unwrap();
        let csr = build_weights(&neurons, &w).unwrap();
        let m = neurons.len();
        let input: Vec<f64> = (0..m).map(|a| 0.2 - 0.01 * (a % 7) as f64).collect();
        let init: Vec<u8> = (0..m).map(|a| u8::from(a % 4 != 0)).collect();
        // The initial net inputs differ only by the order of the f64 sums.
        let (u_net, nnz) = net.initial_input(&init, &input).unwrap();
        let (u_csr, nnz_csr) = csr.initial_input(&init, &input).unwrap();
        assert_eq!((nnz, nnz_csr), (csr.nnz(), csr.nnz()));
        assert!(nnz > 10_000, "{nnz}");
        for (a, b) in u_net.iter().zip(&u_csr) {
            assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
        }
        let (dn, dc) = (
            run_dynamics(&net, &input, &init, 5, 100).unwrap(),
            run_dynamics(&csr, &input, &init, 5, 100).unwrap(),
        );
        assert!(dn.converged && dn.sweeps >= 2);
        assert_eq!(dn.state, dc.state);
        assert_eq!(dn.nnz, dc.nnz);
    }

    #[test]
    fn window_counts_equal_a_brute_force_count_in_both_paths() {
        let neurons = random_neurons(3);
        let pxy: Vec<(i32, i32)> = neurons.iter().map(|n| (n.xl, n.yl)).collect();
        let mut pxy_u = pxy.clone();
        pxy_u.dedup();
        for half in [1, 7, 20] {
            let grid = PointGrid::new(&pxy_u, half).unwrap();
            let mut vals: Vec<i32> = grid.items.iter().map(|&k| (k % 5) as i32).collect();
            vals.resize(grid.xs.len(), 0);
            for &(x, y) in &pxy_u {
                let inside =
                    |&(qx, qy): &(i32, i32)| (qx - x).abs() <= half && (qy - y).abs() <= half;
                let want = pxy_u.iter().filter(|q| inside(q)).count();
                let agree = grid
                    .items
                    .iter()
                    .zip(&vals)
                    .filter(|&(&k, &v)| inside(&pxy_u[k as usize]) && (v - 2).abs() <= 1)
                    .count();
                assert_eq!(
                    count_portable(&grid, &vals, (x, y, half, 2, 1)),
                    (want, agree)
                );
                assert_eq!(
                    grid.count_in_window((x, y), half, &vals, 2, 1),
                    (want, agree)
                );
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn window_counts_agree_for_every_point_count() {
        // 1..=70 points (ranges ending 0..=7 lanes before the padding), clustered so that a
        // window's range holds up to all of them, points at the grid's edges; the AVX2 count
        // (8 lanes, the tail masked) against the portable one.
        if !has_avx2() {
            return;
        }
        let mut rng = SplitMix64::new(17);
        for n in 1..=70usize {
            for spread in [3u64, 12, 40] {
                let pxy: Vec<(i32, i32)> = (0..n)
                    .map(|_| {
                        let x = (rng.next_u64() % spread) as i32;
                        (x, (rng.next_u64() % spread) as i32)
                    })
                    .collect();
                for half in [1, 4, 9] {
                    let grid = PointGrid::new(&pxy, half).unwrap();
                    let vals = grid.values_in_grid_order(|t| (t % 5) as i32).unwrap();
                    for &(x, y) in pxy.iter().chain(&[(0, 0), (spread as i32, spread as i32)]) {
                        let want = count_portable(&grid, &vals, (x, y, half, 2, 1));
                        // SAFETY: AVX2 is present; `PointGrid::new` pads xs and ys, and `vals`
                        // is padded like them.
                        let got = unsafe { count_avx2(&grid, &vals, (x, y, half, 2, 1)) };
                        assert_eq!(got, want, "n {n} spread {spread} half {half} at ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn short_buffers_are_refused_not_read_past() {
        // `Network::support` and `Weights::add_row` are safe public functions: an `on` or `u`
        // shorter than the padded cells was read and written past its end by the AVX2 row
        // kernels (they only checked it in debug builds, or not at all). Now a panic naming
        // the buffer, on every CPU.
        let neurons = random_neurons(2);
        let net = Network::new(&neurons, &EnergyWeights::default()).unwrap();
        let state = vec![1u8; neurons.len()];
        let on = net.lane_state(&state, "t").unwrap();
        let a = (0..neurons.len())
            .max_by_key(|&a| net.window_ranges(a).iter().map(|r| r.1).max())
            .unwrap();
        let full = net.support(a, &state, &on);
        assert!(full > 0.0);
        let short = std::panic::catch_unwind(|| net.support(a, &state, &on[..on.len() - LANES]));
        let msg = short.unwrap_err();
        let msg = msg.downcast_ref::<String>().unwrap();
        assert!(msg.contains("`on` holds"), "{msg}");
        let mut u = vec![0.0f64; net.slots() - LANES];
        let short =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| net.add_row(a, 1.0, &mut u)));
        let msg = short.unwrap_err();
        let msg = msg.downcast_ref::<String>().unwrap();
        assert!(msg.contains("`u` holds"), "{msg}");
    }

    /// The rows of `T` from the rule of C.4 as the NumPy reference writes it
    /// (`tests/reference/hopfield_ref.py::build_weights`), pair by pair: `-B` for the other
    /// candidates of the same point and for other points' candidates with the same right
    /// pixel; for the candidates of the other points in the window (any other right pixel)
    /// `A / max(n_p, n_q, 1) * C(|d_a - d_b|, theta + grad * r)`, `n` the points' window
    /// neighbour counts and `r` their Chebyshev distance. Each row sorted by neuron.
    fn reference_rows(neurons: &[Neuron], w: &EnergyWeights) -> Vec<Vec<(u32, f32)>> {
        let half = w.nbr_half;
        let near = |a: &Neuron, b: &Neuron| {
            a.point != b.point && (a.xl - b.xl).abs() <= half && (a.yl - b.yl).abs() <= half
        };
        // Window neighbour count per point (other points, counted once each).
        let mut n_of = std::collections::HashMap::new();
        for a in neurons {
            n_of.entry(a.point).or_insert_with(|| {
                let mut others: Vec<u32> = neurons
                    .iter()
                    .filter(|b| near(a, b))
                    .map(|b| b.point)
                    .collect();
                others.dedup();
                others.len()
            });
        }
        neurons
            .iter()
            .map(|na| {
                let mut row: Vec<(u32, f32)> = Vec::new();
                for (b, nb) in neurons.iter().enumerate() {
                    let same_right = (nb.xr, nb.yr) == (na.xr, na.yr);
                    if std::ptr::eq(na, nb) {
                        continue;
                    } else if nb.point == na.point || same_right {
                        row.push((b as u32, -w.b));
                    } else if near(na, nb) {
                        let n = n_of[&na.point].max(n_of[&nb.point]).max(1);
                        let norm = w.a / n as f32;
                        let r = (na.xl - nb.xl).abs().max((na.yl - nb.yl).abs());
                        let theta = w.compat_theta as f64 + w.compat_grad as f64 * r as f64;
                        let (ex, ey) = ((na.dx() - nb.dx()) as f64, (na.dy() - nb.dy()) as f64);
                        let c = compat((ex * ex + ey * ey).sqrt(), theta, w.compat_slope as f64);
                        row.push((b as u32, norm * c as f32));
                    }
                }
                row
            })
            .collect()
    }

    /// Every stored weight, bit for bit, against the pair-by-pair rule: the default weights,
    /// a negative `A`, a small window without the distance term, a steep sigmoid.
    #[test]
    fn weights_equal_the_pairwise_rule() {
        let variants = [
            EnergyWeights::default(),
            EnergyWeights {
                a: -2.0,
                b: 0.7,
                ..EnergyWeights::default()
            },
            EnergyWeights {
                nbr_half: 5,
                compat_grad: 0.0,
                compat_theta: 3.5,
                ..EnergyWeights::default()
            },
            EnergyWeights {
                compat_slope: 9.0,
                nbr_half: 11,
                ..EnergyWeights::default()
            },
        ];
        for (seed, w) in variants.iter().enumerate() {
            // Fewer points than random_neurons' 900 keep the O(n^2) rule fast in debug builds.
            let mut neurons: Vec<Neuron> = random_neurons(seed as u64)
                .into_iter()
                .filter(|n| n.point < 300)
                .collect();
            if seed == 2 {
                // Left points squeezed into 9 columns: a window spans whole strips, so a
                // block's lanes past a range's end hold the next strip's first neurons.
                for n in &mut neurons {
                    let d = n.dx();
                    n.xl = 40 + n.xl % 9;
                    n.xr = n.xl - d;
                }
            }
            let csr = build_weights(&neurons, w).unwrap();
            let want = reference_rows(&neurons, w);
            let (mut pos, mut neg) = (0, 0);
            for (a, want_row) in want.iter().enumerate() {
                let (idx, val) = csr.row(a);
                let mut got: Vec<(u32, f32)> =
                    idx.iter().copied().zip(val.iter().copied()).collect();
                got.sort_by_key(|e| e.0);
                let bits =
                    |r: &[(u32, f32)]| r.iter().map(|e| (e.0, e.1.to_bits())).collect::<Vec<_>>();
                assert_eq!(bits(&got), bits(want_row), "weights {seed} row {a}");
                pos += want_row.iter().filter(|e| e.1 > 0.0).count();
                neg += want_row
                    .iter()
                    .filter(|e| e.1 < -0.0 && e.1 != -w.b)
                    .count();
            }
            assert!(
                pos > 100 && neg > 100,
                "weights {seed}: {pos} positive, {neg} negative"
            );
        }
    }

    /// The asynchronous dynamics written out plainly (the NumPy reference's loop): net inputs
    /// from the rows, a seeded shuffle per sweep, `u > 0` on, `u < 0` off, `0` unchanged, the
    /// energy recomputed after every sweep, stop after a sweep without a flip.
    fn reference_dynamics(
        csr: &Csr,
        input: &[f64],
        init: &[u8],
        seed: u64,
        max_sweeps: usize,
    ) -> (Vec<u8>, Vec<f64>, usize, bool) {
        let m = csr.n();
        let mut v = init.to_vec();
        let mut u = input.to_vec();
        for (a, &on) in init.iter().enumerate() {
            if on == 1 {
                let (idx, val) = csr.row(a);
                for (&b, &t) in idx.iter().zip(val) {
                    u[b as usize] += t as f64;
                }
            }
        }
        let energy = |v: &[u8], u: &[f64]| -> f64 {
            (0..m)
                .filter(|&a| v[a] == 1)
                .map(|a| -(0.5 * (u[a] - input[a]) + input[a]))
                .sum()
        };
        let mut trace = vec![energy(&v, &u)];
        let mut order: Vec<u32> = (0..m as u32).collect();
        let mut rng = SplitMix64::new(seed);
        let (mut sweeps, mut converged) = (0, m == 0);
        while !converged && sweeps < max_sweeps {
            rng.shuffle(&mut order);
            let mut flips = 0;
            for &a in &order {
                let a = a as usize;
                let new = if u[a] > 0.0 {
                    1
                } else if u[a] < 0.0 {
                    0
                } else {
                    v[a]
                };
                if new != v[a] {
                    v[a] = new;
                    flips += 1;
                    let s = if new == 1 { 1.0 } else { -1.0 };
                    let (idx, val) = csr.row(a);
                    for (&b, &t) in idx.iter().zip(val) {
                        u[b as usize] += s * t as f64;
                    }
                }
            }
            sweeps += 1;
            trace.push(energy(&v, &u));
            converged = flips == 0;
        }
        (v, trace, sweeps, converged)
    }

    /// Final state, sweeps and energy trace of both weight forms against the plain loop, from
    /// a few starts (inputs with exact zeros: the "unchanged" case), and a sweep cap.
    #[test]
    fn dynamics_equal_the_plain_loop() {
        let neurons: Vec<Neuron> = random_neurons(9)
            .into_iter()
            .filter(|n| n.point < 400)
            .collect();
        let w = EnergyWeights::default();
        let (net, csr) = (
            Network::new(&neurons, &w).unwrap(),
            build_weights(&neurons, &w).unwrap(),
        );
        let m = neurons.len();
        for (seed, max_sweeps) in [(0u64, 100usize), (3, 100), (8, 1)] {
            let input: Vec<f64> = (0..m)
                .map(|a| [0.25, -0.5, 0.0, 1.0, -0.125][(a + seed as usize) % 5])
                .collect();
            let init: Vec<u8> = (0..m)
                .map(|a| u8::from((a * 7 + seed as usize).is_multiple_of(3)))
                .collect();
            let (v, trace, sweeps, converged) =
                reference_dynamics(&csr, &input, &init, seed, max_sweeps);
            for d in [
                run_dynamics(&csr, &input, &init, seed, max_sweeps).unwrap(),
                run_dynamics(&net, &input, &init, seed, max_sweeps).unwrap(),
            ] {
                assert_eq!(d.state, v, "seed {seed}");
                assert_eq!(d.sweeps, sweeps, "seed {seed}");
                assert_eq!(d.converged, converged, "seed {seed}");
                assert_eq!(d.energy_trace.len(), trace.len());
                for (e, f) in d.energy_trace.iter().zip(&trace) {
                    assert!(
                        (e - f).abs() <= 1e-9 * (1.0 + f.abs()),
                        "seed {seed}: {e} vs {f}"
                    );
                }
                assert_eq!(d.nnz, csr.nnz());
            }
            assert!(sweeps >= 1 && v != init, "seed {seed}");
        }
    }

    /// The compatibility sigmoid of C.4 by value: 0 at the crossing, +-(2 / (1 + e^-4) - 1)
    /// one crossing-width either side for slope 2, odd about the crossing, towards -1 far out.
    #[test]
    fn compatibility_has_its_sign_and_crossing() {
        assert_eq!(compat(2.0, 2.0, 2.0), 0.0);
        let near = 2.0 / (1.0 + (-4.0f64).exp()) - 1.0;
        assert!((compat(0.0, 2.0, 2.0) - near).abs() < 1e-15);
        assert!((compat(4.0, 2.0, 2.0) + near).abs() < 1e-15);
        assert!(compat(20.0, 2.0, 2.0) < -0.999_999);
        assert!((compat(1.0, 3.0, 0.5) + compat(5.0, 3.0, 0.5)).abs() < 1e-15);
    }

    /// SplitMix64's first outputs for seed 0 (the published sequence the NumPy reference
    /// mirrors) and the Fisher-Yates shuffle step by step: `j = next % (i + 1)` for
    /// `i = n - 1 .. 1`, swapping `i` and `j`.
    #[test]
    fn generator_and_shuffle_follow_their_definitions() {
        let mut g = SplitMix64::new(0);
        assert_eq!(
            [g.next_u64(), g.next_u64(), g.next_u64()],
            [
                0xe220_a839_7b1d_cdaf,
                0x6e78_9e6a_a1b9_65f4,
                0x06c4_5d18_8009_454f
            ]
        );
        for (seed, n) in [(1u64, 2usize), (2, 3), (7, 10), (9, 33)] {
            let mut v: Vec<u32> = (0..n as u32).collect();
            SplitMix64::new(seed).shuffle(&mut v);
            let mut want: Vec<u32> = (0..n as u32).collect();
            let mut g = SplitMix64::new(seed);
            let mut i = n - 1;
            while i >= 1 {
                let j = (g.next_u64() % (i as u64 + 1)) as usize;
                want.swap(i, j);
                i -= 1;
            }
            assert_eq!(v, want, "seed {seed} n {n}");
        }
    }

    /// Neurons without any weight keep their state when their net input is exactly 0, switch
    /// on for a positive one and off for a negative one; one sweep of flips, one without.
    #[test]
    fn a_zero_net_input_leaves_the_state_alone() {
        let lone = |point: u32, x: i32| Neuron {
            point,
            xl: x,
            yl: 10,
            xr: x - 3,
            yr: 10,
            sim: 0.8,
            edge_ok: true,
            halves_fail: 0,
            centre_ok: true,
            sub: 0.0,
        };
        // 100 px apart: outside each other's 41x41 windows, distinct right pixels.
        let neurons: Vec<Neuron> = (0..4).map(|p| lone(p, 10 + 100 * p as i32)).collect();
        let w = EnergyWeights::default();
        let net = Network::new(&neurons, &w).unwrap();
        let input = [0.0, 0.0, 0.5, -0.5];
        let init = [1u8, 0, 0, 1];
        let d = run_dynamics(&net, &input, &init, 1, 10).unwrap();
        assert_eq!(d.nnz, 0);
        assert_eq!(d.state, vec![1, 0, 1, 0]);
        assert_eq!((d.sweeps, d.converged), (2, true));
        assert_eq!(d.energy_trace, vec![0.5, -0.5, -0.5]);
    }

    /// Support: the positive weights from active neurons only. With a negative `B` (-1) the
    /// point's other candidate and the candidate sharing the right pixel weigh +1 each, and count
    /// only when on; the window neighbour (4 px away, same disparity) adds `A C(0)` with the
    /// crossing at `2 + 0.05 * 4` (one neighbour each: `n` = 1).
    #[test]
    fn support_counts_positive_weights_of_active_neurons_only() {
        let nrn = |point: u32, x: i32, d: i32| Neuron {
            point,
            xl: x,
            yl: 10,
            xr: x - d,
            yr: 10,
            sim: 0.8,
            edge_ok: true,
            halves_fail: 0,
            centre_ok: true,
            sub: 0.0,
        };
        // 0, 1: one point; 2 shares 0's right pixel (100 px away); 3 is 0's window neighbour.
        let neurons = [
            nrn(0, 50, 10),
            nrn(0, 50, 30),
            nrn(1, 150, 110),
            nrn(2, 54, 10),
        ];
        let w = EnergyWeights {
            b: -1.0,
            ..EnergyWeights::default()
        };
        let net = Network::new(&neurons, &w).unwrap();
        let support =
            |state: [u8; 4]| net.support(0, &state, &net.lane_state(&state, "t").unwrap());
        let c = (3.0 * compat(0.0, 2.0 + 0.05 * 4.0, 2.0) as f32) as f64;
        assert_eq!(support([1, 0, 0, 0]), 0.0);
        assert_eq!(support([0, 1, 0, 0]), 1.0);
        assert_eq!(support([0, 1, 1, 0]), 2.0);
        assert!(
            (support([0, 0, 0, 1]) - c).abs() < 1e-6,
            "{}",
            support([0, 0, 0, 1])
        );
        assert!((support([1, 1, 1, 1]) - (2.0 + c)).abs() < 1e-6);
    }

    /// The compatibility table reaches the largest squared disparity-vector difference of the
    /// neurons (here 3^2 = 9: same horizontal disparity, vertical ones 0 and 3), read as
    /// `C(3)`; a gentle sigmoid (slope 0.5, crossing 10 + 0.05 * 4) keeps it far from -1.
    #[test]
    fn compatibility_reads_the_full_disparity_difference() {
        let nrn = |point: u32, x: i32, dy: i32| Neuron {
            point,
            xl: x,
            yl: 10,
            xr: x - 5,
            yr: 10 - dy,
            sim: 0.8,
            edge_ok: true,
            halves_fail: 0,
            centre_ok: true,
            sub: 0.0,
        };
        let neurons = [nrn(0, 50, 0), nrn(1, 54, 3)];
        let w = EnergyWeights {
            compat_theta: 10.0,
            compat_slope: 0.5,
            ..EnergyWeights::default()
        };
        let net = Network::new(&neurons, &w).unwrap();
        let state = [0u8, 1];
        let got = net.support(0, &state, &net.lane_state(&state, "t").unwrap());
        let want = (3.0 * compat(3.0, 10.0 + 0.05 * 4.0, 0.5) as f32) as f64;
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    }

    /// The window of `for_each_in_window` is closed: points exactly `half` away in x or in y
    /// are in it, one further are not.
    #[test]
    fn window_visits_points_exactly_half_away() {
        let pxy = [
            (10, 10),
            (10, 15),
            (15, 10),
            (10, 16),
            (16, 10),
            (5, 5),
            (4, 10),
        ];
        let grid = PointGrid::new(&pxy, 5).unwrap();
        let mut got = Vec::new();
        grid.for_each_in_window((10, 10), 5, |k| got.push(k));
        got.sort_unstable();
        assert_eq!(got, [0, 1, 2, 5]);
    }
}
