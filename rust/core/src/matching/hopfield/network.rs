//! The sparse binary Hopfield network over candidate pairs (algorithms.md C.4, C.6).
//!
//! Weights `T_ab = A * C~_ab - B [same left point] - B [same right pixel]` (zero diagonal,
//! symmetric by construction: every entry is a symmetric function of the pair), inputs
//! `I_a = D * S_a - theta`. The CSR rows are built independently per neuron (rayon) from a
//! uniform grid of the left points. Dynamics: asynchronous binary threshold updates in a seeded
//! random order, net inputs maintained incrementally, until a sweep without a flip.

use rayon::prelude::*;
use std::collections::HashMap;

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

/// Builds the CSR weights. `neurons` must be grouped by `point` in increasing order.
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
    // Compact point index of every neuron (neurons[a].point indexes all interest points).
    let mut compact = vec![0usize; m];
    for p in 0..n_pts {
        compact[starts[p]..starts[p + 1]].fill(p);
    }
    let pxy: Vec<(i32, i32)> = (0..n_pts)
        .map(|p| (neurons[starts[p]].xl, neurons[starts[p]].yl))
        .collect();
    // Uniform grid of cell = nbr_half px over the left points.
    let cell = w.nbr_half.max(1);
    let mut grid: HashMap<(i32, i32), Vec<u32>> = HashMap::new();
    for (p, &(x, y)) in pxy.iter().enumerate() {
        grid.entry((x.div_euclid(cell), y.div_euclid(cell)))
            .or_default()
            .push(p as u32);
    }
    let within = |p: usize, q: usize| {
        (pxy[p].0 - pxy[q].0).abs() <= w.nbr_half && (pxy[p].1 - pxy[q].1).abs() <= w.nbr_half
    };
    let neighbours = |p: usize| -> Vec<u32> {
        let (cx, cy) = (pxy[p].0.div_euclid(cell), pxy[p].1.div_euclid(cell));
        let mut out = Vec::new();
        for gy in cy - 1..=cy + 1 {
            for gx in cx - 1..=cx + 1 {
                if let Some(list) = grid.get(&(gx, gy)) {
                    out.extend(
                        list.iter()
                            .copied()
                            .filter(|&q| q as usize != p && within(p, q as usize)),
                    );
                }
            }
        }
        out.sort_unstable();
        out
    };
    let nbrs: Vec<Vec<u32>> = (0..n_pts).into_par_iter().map(neighbours).collect();
    let n_count: Vec<f32> = nbrs.iter().map(|v| v.len() as f32).collect();
    // Neurons sharing a right pixel (column inhibition), wherever their left points are.
    let mut by_right: HashMap<(i32, i32), Vec<u32>> = HashMap::new();
    for (a, nr) in neurons.iter().enumerate() {
        by_right.entry((nr.xr, nr.yr)).or_default().push(a as u32);
    }
    // Compatibility lookup over the integer squared disparity-vector difference.
    let max_dx = neurons.iter().map(|n| n.dx()).max().unwrap_or(0)
        - neurons.iter().map(|n| n.dx()).min().unwrap_or(0);
    let max_dy = neurons.iter().map(|n| n.dy()).max().unwrap_or(0)
        - neurons.iter().map(|n| n.dy()).min().unwrap_or(0);
    let q_max = (max_dx as usize).pow(2) + (max_dy as usize).pow(2);
    let lut: Vec<f32> = (0..=q_max)
        .map(|q| {
            compat(
                (q as f64).sqrt(),
                w.compat_theta as f64,
                w.compat_slope as f64,
            ) as f32
        })
        .collect();
    let rows: Vec<Vec<(u32, f32)>> = (0..m)
        .into_par_iter()
        .map(|a| {
            let na = &neurons[a];
            let p = compact[a];
            let mut row: Vec<(u32, f32)> = Vec::new();
            // Same left point: uniqueness (row) inhibition.
            for b in starts[p]..starts[p + 1] {
                if b != a {
                    row.push((b as u32, -w.b));
                }
            }
            // Same right pixel, other left point: uniqueness (column) inhibition.
            if let Some(list) = by_right.get(&(na.xr, na.yr)) {
                for &b in list {
                    if neurons[b as usize].point != na.point {
                        row.push((b, -w.b));
                    }
                }
            }
            // Compatibility with the candidates of the other points in the 40x40 window.
            for &q in &nbrs[p] {
                let norm = w.a / n_count[p].max(n_count[q as usize]).max(1.0);
                let (qs, qe) = (starts[q as usize], starts[q as usize + 1]);
                for (b, nb) in neurons.iter().enumerate().take(qe).skip(qs) {
                    if nb.xr == na.xr && nb.yr == na.yr {
                        continue; // already inhibited above; compatibility needs l != k
                    }
                    let ex = (na.dx() - nb.dx()).unsigned_abs() as usize;
                    let ey = (na.dy() - nb.dy()).unsigned_abs() as usize;
                    row.push((b as u32, norm * lut[ex * ex + ey * ey]));
                }
            }
            row.sort_unstable_by_key(|e| e.0);
            row
        })
        .collect();
    let mut indptr = Vec::with_capacity(m + 1);
    indptr.push(0usize);
    let nnz: usize = rows.iter().map(|r| r.len()).sum();
    let mut indices = Vec::with_capacity(nnz);
    let mut data = Vec::with_capacity(nnz);
    for r in rows {
        for (b, v) in r {
            indices.push(b);
            data.push(v);
        }
        indptr.push(indices.len());
    }
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
    let mut u = input.to_vec();
    for (a, &on) in init.iter().enumerate().take(m) {
        if on == 1 {
            let (idx, val) = csr.row(a);
            for (&b, &t) in idx.iter().zip(val) {
                u[b as usize] += t as f64;
            }
        }
    }
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
