//! The sparse binary Hopfield network over candidate pairs (algorithms.md C.4, C.6).
//!
//! Weights `T_ab = A * C~_ab - B [same left point] - B [same right pixel]` (zero diagonal,
//! symmetric by construction: every entry is a symmetric function of the pair), inputs
//! `I_a = D * S_a - theta`. The CSR rows are built independently per neuron (rayon) from a
//! uniform grid of the left points. Dynamics: asynchronous binary threshold updates in a seeded
//! random order, net inputs maintained incrementally, until a sweep without a flip.

use rayon::prelude::*;

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

/// Uniform grid over the left points, counting-sorted: `items` lists the point indices cell by
/// cell (raster order of the cells, point order within a cell) with their coordinates beside
/// them, so the cells of one grid row around a point form ONE contiguous range.
pub(crate) struct PointGrid {
    cell: i32,
    gw: i32,
    gh: i32,
    start: Vec<usize>,
    pub(crate) items: Vec<u32>,
    pub(crate) xs: Vec<i32>,
    pub(crate) ys: Vec<i32>,
}

impl PointGrid {
    /// Grid for window queries of half-size `half` (>= 1).
    pub(crate) fn new(pxy: &[(i32, i32)], half: i32) -> Self {
        let cell = (half.max(1) + GRID_SUB - 1) / GRID_SUB;
        let gw = pxy.iter().map(|p| p.0 / cell).max().unwrap_or(0) + 1;
        let gh = pxy.iter().map(|p| p.1 / cell).max().unwrap_or(0) + 1;
        let idx = |p: &(i32, i32)| ((p.1 / cell) * gw + p.0 / cell) as usize;
        let mut start = vec![0usize; (gw * gh) as usize + 1];
        for p in pxy {
            start[idx(p) + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; pxy.len()];
        for (k, p) in pxy.iter().enumerate() {
            let c = idx(p);
            items[fill[c]] = k as u32;
            fill[c] += 1;
        }
        let xs = items.iter().map(|&k| pxy[k as usize].0).collect();
        let ys = items.iter().map(|&k| pxy[k as usize].1).collect();
        PointGrid {
            cell,
            gw,
            gh,
            start,
            items,
            xs,
            ys,
        }
    }

    /// The (possibly empty) ranges of `items` positions covering the cells within
    /// `GRID_SUB` cells of `(x, y)`'s cell, one per grid row, in cell raster order.
    #[inline]
    pub(crate) fn ranges(&self, x: i32, y: i32) -> [(usize, usize); 2 * GRID_SUB as usize + 1] {
        let (cx, cy) = (x / self.cell, y / self.cell);
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

    /// Calls `f(q)` for every point `q` within `half` of `(x, y)` in both coordinates
    /// (`half` at most the grid's), in cell order.
    pub(crate) fn for_each_in_window(
        &self,
        (x, y): (i32, i32),
        half: i32,
        mut f: impl FnMut(usize),
    ) {
        for (s, e) in self.ranges(x, y) {
            for k in s..e {
                if (self.xs[k] - x).abs() <= half && (self.ys[k] - y).abs() <= half {
                    f(self.items[k] as usize);
                }
            }
        }
    }
}

/// Left points per parallel task of [`build_weights`] (rows are built per task, then
/// concatenated in order: the matrix does not depend on the thread count).
const POINTS_PER_TASK: usize = 64;

/// Builds the CSR weights. `neurons` must be grouped by `point` in increasing order and have
/// non-negative coordinates.
pub fn build_weights(neurons: &[Neuron], w: &EnergyWeights) -> Csr {
    let m = neurons.len();
    if m == 0 {
        return Csr {
            indptr: vec![0],
            ..Csr::default()
        };
    }
    // Points and their neuron ranges.
    let mut starts: Vec<usize> = Vec::new();
    for (a, nr) in neurons.iter().enumerate() {
        if a == 0 || nr.point != neurons[a - 1].point {
            starts.push(a);
        }
    }
    let n_pts = starts.len();
    starts.push(m);
    let pxy: Vec<(i32, i32)> = (0..n_pts)
        .map(|p| (neurons[starts[p]].xl.max(0), neurons[starts[p]].yl.max(0)))
        .collect();
    let half = w.nbr_half.max(1);
    let grid = PointGrid::new(&pxy, half);
    // Neighbour lists (left points with candidates in the 40x40 window, grid order), n_i =
    // their count. Branch-free: every point of the 3x3 cells is written, the cursor advances
    // only for those inside the window.
    let near_parts: Vec<Vec<Vec<u32>>> = (0..n_pts)
        .collect::<Vec<_>>()
        .par_chunks(POINTS_PER_TASK)
        .map(|ps| {
            ps.iter()
                .map(|&p| {
                    let (x, y) = pxy[p];
                    let rs = grid.ranges(x, y);
                    let mut items = vec![0u32; rs.iter().map(|&(s, e)| e - s).sum()];
                    let mut n = 0;
                    for (s, e) in rs {
                        for k in s..e {
                            let q = grid.items[k];
                            items[n] = q;
                            let inside = (grid.xs[k] - x).abs() <= half
                                && (grid.ys[k] - y).abs() <= half
                                && q as usize != p;
                            n += usize::from(inside);
                        }
                    }
                    items.truncate(n);
                    items
                })
                .collect()
        })
        .collect();
    let near: Vec<Vec<u32>> = near_parts.into_iter().flatten().collect();
    // A / max(n_p, n_q, 1) = min(A / max(n_p, 1), A / max(n_q, 1)) exactly: division rounds
    // monotonically (max for a negative A). One division per point instead of per pair.
    let a_over_n: Vec<f32> = near
        .iter()
        .map(|v| w.a / (v.len() as f32).max(1.0))
        .collect();
    let a_pos = w.a >= 0.0;
    // Neurons sharing a right pixel (column inhibition), wherever their left points are:
    // neuron indices sorted by right pixel, and each neuron's group range in that order.
    let mut by_right: Vec<u32> = (0..m as u32).collect();
    let key = |a: u32| (neurons[a as usize].yr, neurons[a as usize].xr);
    by_right.sort_unstable_by_key(|&a| (key(a), a));
    let mut group = vec![(0usize, 0usize); m];
    let mut g0 = 0;
    for k in 1..=m {
        if k == m || key(by_right[k]) != key(by_right[g0]) {
            for &a in &by_right[g0..k] {
                group[a as usize] = (g0, k);
            }
            g0 = k;
        }
    }
    // Compatibility lookup per Chebyshev distance r of the two points (0..=half) over the
    // integer squared disparity-vector difference q. A row ends where the f32 value has
    // saturated at -1 (slope > 0, q past the crossing): larger q read the last entry, which is
    // exactly what the formula gives there.
    let span = |f: fn(&Neuron) -> i32| {
        let lo = neurons.iter().map(f).min().unwrap_or(0);
        let hi = neurons.iter().map(f).max().unwrap_or(0);
        (hi - lo) as usize
    };
    let (max_dx, max_dy) = (span(Neuron::dx), span(Neuron::dy));
    let max_q = max_dx * max_dx + max_dy * max_dy;
    let luts: Vec<Vec<f32>> = (0..=half)
        .map(|r| {
            let theta = w.compat_theta as f64 + w.compat_grad as f64 * r as f64;
            let mut row = Vec::new();
            for q in 0..=max_q {
                let v = compat((q as f64).sqrt(), theta, w.compat_slope as f64) as f32;
                row.push(v);
                if v == -1.0 && w.compat_slope > 0.0 && (q as f64).sqrt() > theta {
                    break;
                }
            }
            row
        })
        .collect();
    // Structure of arrays of what the rows read.
    let dxs: Vec<i32> = neurons.iter().map(Neuron::dx).collect();
    let dys: Vec<i32> = neurons.iter().map(Neuron::dy).collect();
    let rkey: Vec<u64> = neurons
        .iter()
        .map(|n| ((n.yr as u32 as u64) << 32) | n.xr as u32 as u64)
        .collect();
    let p_of: Vec<u32> = (0..n_pts)
        .flat_map(|p| std::iter::repeat_n(p as u32, starts[p + 1] - starts[p]))
        .collect();
    // Pass 1: row lengths. Row of `a` (point p): the other candidates of p, the other points'
    // candidates with a's right pixel, and every candidate of p's window points except those
    // with a's right pixel (already in the column part).
    let win_cands: Vec<usize> = near
        .par_iter()
        .map(|nb| {
            nb.iter()
                .map(|&q| starts[q as usize + 1] - starts[q as usize])
                .sum()
        })
        .collect();
    let lens: Vec<usize> = (0..m)
        .into_par_iter()
        .map(|a| {
            let p = p_of[a] as usize;
            let (gs, ge) = group[a];
            let (mut col, mut col_in_win) = (0, 0);
            for &b in &by_right[gs..ge] {
                let q = p_of[b as usize] as usize;
                if q != p {
                    col += 1;
                    let (dx, dy) = (pxy[q].0 - pxy[p].0, pxy[q].1 - pxy[p].1);
                    col_in_win += usize::from(dx.abs() <= half && dy.abs() <= half);
                }
            }
            (starts[p + 1] - starts[p] - 1) + col + win_cands[p] - col_in_win
        })
        .collect();
    let mut indptr = Vec::with_capacity(m + 1);
    indptr.push(0usize);
    for &l in &lens {
        indptr.push(indptr[indptr.len() - 1] + l);
    }
    let nnz = indptr[m];
    let mut indices = vec![0u32; nnz];
    let mut data = vec![0.0f32; nnz];
    // Pass 2: every task writes its points' rows straight into its slice of the CSR arrays.
    let mut tasks: Vec<(usize, &mut [u32], &mut [f32])> = Vec::new();
    {
        let (mut ri, mut rd) = (indices.as_mut_slice(), data.as_mut_slice());
        for p0 in (0..n_pts).step_by(POINTS_PER_TASK) {
            let p1 = (p0 + POINTS_PER_TASK).min(n_pts);
            let n = indptr[starts[p1]] - indptr[starts[p0]];
            let (ti, rest_i) = std::mem::take(&mut ri).split_at_mut(n);
            let (td, rest_d) = std::mem::take(&mut rd).split_at_mut(n);
            tasks.push((p0, ti, td));
            ri = rest_i;
            rd = rest_d;
        }
    }
    tasks.into_par_iter().for_each(|(p0, ti, td)| {
        let p1 = (p0 + POINTS_PER_TASK).min(n_pts);
        let mut k = 0usize;
        let mut put = |b: u32, v: f32| {
            ti[k] = b;
            td[k] = v;
            k += 1;
        };
        for p in p0..p1 {
            for a in starts[p]..starts[p + 1] {
                // Same left point: uniqueness (row) inhibition.
                for b in starts[p]..starts[p + 1] {
                    if b != a {
                        put(b as u32, -w.b);
                    }
                }
                // Same right pixel, other left point: uniqueness (column) inhibition.
                let (gs, ge) = group[a];
                for &b in &by_right[gs..ge] {
                    if p_of[b as usize] as usize != p {
                        put(b, -w.b);
                    }
                }
                // Compatibility with the candidates of the other points in the 40x40 window
                // (l != k: a shared right pixel is inhibited above instead).
                let (ka, dxa, dya) = (rkey[a], dxs[a], dys[a]);
                for &q in &near[p] {
                    let q = q as usize;
                    let (np, nq) = (a_over_n[p], a_over_n[q]);
                    let norm = if (np < nq) == a_pos { np } else { nq };
                    let r = (pxy[q].0 - pxy[p].0).abs().max((pxy[q].1 - pxy[p].1).abs()) as usize;
                    let lut = &luts[r];
                    let last = lut.len() - 1;
                    for b in starts[q]..starts[q + 1] {
                        if rkey[b] != ka {
                            let ex = (dxa - dxs[b]).unsigned_abs() as usize;
                            let ey = (dya - dys[b]).unsigned_abs() as usize;
                            put(b as u32, norm * lut[(ex * ex + ey * ey).min(last)]);
                        }
                    }
                }
            }
        }
        debug_assert_eq!(k, ti.len());
    });
    Csr {
        indptr,
        indices,
        data,
    }
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
}

/// Energy `E = -1/2 V^T T V - I^T V` from the net inputs `u = T V + I`.
fn energy(state: &[u8], u: &[f64], input: &[f64]) -> f64 {
    state
        .iter()
        .zip(u.iter().zip(input))
        .filter(|(&v, _)| v == 1)
        .map(|(_, (&ua, &ia))| -(0.5 * (ua - ia) + ia))
        .sum()
}

/// Runs the asynchronous dynamics from `init` until a sweep without a flip (or `max_sweeps`).
pub fn run_dynamics(
    csr: &Csr,
    input: &[f64],
    init: &[u8],
    seed: u64,
    max_sweeps: usize,
) -> Dynamics {
    let m = csr.n();
    let mut state = init.to_vec();
    // Initial net inputs u_a = I_a + sum_b T_ab V_b, each from its own row (T is symmetric):
    // in parallel, every sum in row order, so independent of the thread count.
    let mut u: Vec<f64> = (0..m)
        .into_par_iter()
        .map(|a| {
            let (idx, val) = csr.row(a);
            let mut s = input[a];
            for (&b, &t) in idx.iter().zip(val) {
                if init[b as usize] == 1 {
                    s += t as f64;
                }
            }
            s
        })
        .collect();
    let mut trace = vec![energy(&state, &u, input)];
    let mut rng = SplitMix64::new(seed);
    let mut order: Vec<u32> = (0..m as u32).collect();
    let mut sweeps = 0;
    let mut converged = m == 0;
    while !converged && sweeps < max_sweeps {
        rng.shuffle(&mut order);
        let mut flips = 0usize;
        for &a in &order {
            let a = a as usize;
            let new = if u[a] > 0.0 {
                1
            } else if u[a] < 0.0 {
                0
            } else {
                state[a]
            };
            if new != state[a] {
                state[a] = new;
                flips += 1;
                let sign = if new == 1 { 1.0 } else { -1.0 };
                let (idx, val) = csr.row(a);
                for (&b, &t) in idx.iter().zip(val) {
                    u[b as usize] += sign * t as f64;
                }
            }
        }
        sweeps += 1;
        trace.push(energy(&state, &u, input));
        converged = flips == 0;
    }
    Dynamics {
        state,
        energy_trace: trace,
        sweeps,
        converged,
    }
}
