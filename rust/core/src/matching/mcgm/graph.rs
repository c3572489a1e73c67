//! Candidate segment pairs, the segment adjacency graph and the association-graph matching
//! (algorithms.md B.4 steps 7, 9, 10, with B.8's readings).
//!
//! Adjacency: each left segment's `k` nearest centroids within `r_graph` px (the k-NN
//! alternative B.4.9 allows), symmetrised. Association graph: nodes = candidate pairs
//! `a = (A, A')`; `a` and `b = (B, B')` are joined when `(A, B)` are adjacent and `A' != B'`, with
//! the disparity-gradient compatibility `C_ab = 2 / (1 + exp(slope (g - g0))) - 1`,
//! `g = |t_a - t_b| / |c_A - c_B|`, weighted `A_w C_ab / sqrt(deg A deg B)` (B.8: normalised by
//! the degree; the geometric mean keeps the matrix symmetric); candidates sharing `A` or `A'`
//! inhibit each other with `-B`. The Hopfield network of module C
//! ([`crate::matching::hopfield::run_dynamics`]) minimises the energy; a segment left with
//! two active pairs keeps the one with the highest net input (B.8).

use rayon::prelude::*;

use super::rtable::{ght_vote_rows, voters, RTable, RowIndex};
use super::tracking::{wrap_angle, Segment};
use crate::alloc::{
    try_collect, try_concat, try_filled, try_grow, try_par_collect, try_reserve_len, try_zeroed,
};
use crate::error::Result;
use crate::matching::hopfield::{run_dynamics, Csr};

/// One candidate segment pair with its GHT evidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    pub left: u32,
    pub right: u32,
    pub score: f32,
    /// Translation `t = p - q` (left minus right, px): `tx` is the segment disparity.
    pub tx: f32,
    pub ty: f32,
}

/// Gates and GHT settings of the candidate search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CandParams {
    pub seg_theta_tol_deg: f32,
    /// Epipolar band (rows): y-ranges are widened by this and GHT rows are `-dy..=dy`.
    pub dy_band: i32,
    pub n_bins: usize,
    /// `+-` orientation bins an edge pixel votes through (B.2: 1; default 2, 25 degrees at 36
    /// bins: the finest channel's orientations are noisy, docs/mcgm.md).
    pub vote_bin_tol: usize,
    /// Lowest GHT score of a candidate pair (peak / larger segment length), also the lowest
    /// length ratio of a pair (B.8: 0.5; default 0.4, docs/mcgm.md).
    pub ght_min_score: f32,
    pub k_cand: usize,
}

/// Candidates of every left segment (grouped by left id, best score first). `window[A]` is the
/// integer disparity window `[lo, hi]` of segment `A` (None: no candidates). A failed
/// allocation of the list, of the right segments' row lists and voters or of a left segment's
/// row index is [`crate::CoreError::OutOfMemory`].
#[allow(clippy::too_many_arguments)]
pub fn candidates(
    left: &[Segment],
    rtables: &[RTable],
    right: &[Segment],
    theta_r: &[f32],
    w: usize,
    h: usize,
    window: &[Option<(i32, i32)>],
    p: &CandParams,
) -> Result<Vec<Candidate>> {
    // The right segments overlapping rows `y0..=y1` are those spanning row `y0` plus those
    // starting in `y0 + 1..=y1`: per row, the segments spanning it and the segments starting
    // on it (each segment met once, without scanning every row of a long left segment).
    const ROWS: &str = "the MCGM matcher's right segments by row";
    let mut rows: Vec<Vec<u32>> = try_filled(h, Vec::new(), ROWS)?;
    let mut starts: Vec<Vec<u32>> = try_filled(h, Vec::new(), ROWS)?;
    for (id, s) in right.iter().enumerate() {
        let (a, b) = (s.y_min.max(0), s.y_max.min(h as i32 - 1));
        if a <= b {
            try_grow(&mut starts[a as usize], 1, ROWS)?;
            starts[a as usize].push(id as u32);
        }
        for y in a..=b {
            try_grow(&mut rows[y as usize], 1, ROWS)?;
            rows[y as usize].push(id as u32);
        }
    }
    let tol = (p.seg_theta_tol_deg as f64).to_radians();
    // The lists of lists (one per right, one per left segment) allocated checked too: a
    // rayon `collect` aborted the process when it could not allocate.
    let right_voters: Vec<Vec<(i32, i32, u32)>> = try_par_collect(
        right
            .par_iter()
            .map(|s| voters(&s.pixels, theta_r, w, p.n_bins)),
        "the MCGM matcher's voters per right segment",
    )?;
    let per = left.par_iter().enumerate().map_init(
        Vec::<u32>::new,
        |acc, (ia, a)| -> Result<Vec<Candidate>> {
            let Some((lo, hi)) = window[ia] else {
                return Ok(Vec::new());
            };
            // Right segments on the rows of A (the order does not matter: the candidates
            // are sorted below).
            let y0 = (a.y_min - p.dy_band).max(0);
            let y1 = (a.y_max + p.dy_band).min(h as i32 - 1);
            let near = (y0 <= y1)
                .then(|| {
                    let later = starts[(y0 + 1) as usize..=y1 as usize].iter().flatten();
                    rows[y0 as usize].iter().chain(later)
                })
                .into_iter()
                .flatten();
            let ext_a = a.y_max - a.y_min + 1;
            let mut out: Vec<Candidate> = Vec::new();
            let mut index: Option<RowIndex> = None;
            for &ib in near {
                let b = &right[ib as usize];
                if wrap_angle(a.mean_theta as f64 - b.mean_theta as f64).abs() >= tol {
                    continue;
                }
                let ov =
                    (a.y_max + p.dy_band).min(b.y_max) - (a.y_min - p.dy_band).max(b.y_min) + 1;
                let ext_b = b.y_max - b.y_min + 1;
                if (ov as f32) < 0.5 * ext_a.min(ext_b) as f32 {
                    continue;
                }
                let slack = 0.5 * (a.x_max - a.x_min + 1).max(b.x_max - b.x_min + 1) as f32;
                let dc = a.centroid.0 - b.centroid.0;
                if dc < lo as f32 - slack || dc > hi as f32 + slack {
                    continue;
                }
                // A translation pairs each pixel of A with at most one of B and vice versa:
                // the peak is at most the shorter length, so the score at most shorter /
                // longer (the float quotient too: division is monotonic).
                let (la, lb) = (a.pixels.len(), b.pixels.len());
                if (la.min(lb) as f32 / la.max(lb).max(1) as f32) < p.ght_min_score {
                    continue;
                }
                let ix = match index {
                    Some(ref ix) => ix,
                    None => index.insert(RowIndex::new(&rtables[ia])?),
                };
                let Some(g) = ght_vote_rows(
                    ix,
                    a.pixels.len(),
                    &right_voters[ib as usize],
                    lo,
                    hi,
                    p.dy_band,
                    p.n_bins,
                    p.vote_bin_tol,
                    acc,
                ) else {
                    continue;
                };
                if g.score >= p.ght_min_score {
                    try_grow(&mut out, 1, "the MCGM matcher's candidate pairs")?;
                    out.push(Candidate {
                        left: ia as u32,
                        right: ib,
                        score: g.score,
                        tx: g.tx,
                        ty: g.ty,
                    });
                }
            }
            out.sort_by(|x, y| y.score.total_cmp(&x.score).then(x.right.cmp(&y.right)));
            out.truncate(p.k_cand);
            Ok(out)
        },
    );
    let per = try_par_collect(per, "the MCGM matcher's candidates per left segment")?;
    try_concat(per, "the MCGM matcher's candidate pairs")
}

/// Symmetrised k-nearest-neighbour adjacency of segment centroids within `r_max` px (sorted
/// lists; ties by id). Uniform grid of cell `r_max / 4`, searched ring by ring around each
/// centroid's cell until the `k` nearest are known: a point in a further ring is at least the
/// ring's inner distance away, so the search stops once the `k`-th nearest is closer than
/// that (with a margin for rounding) or the rings pass `r_max`. A failed allocation of the
/// lists or of the grid (which grows with the spread of the centroids) is
/// [`crate::CoreError::OutOfMemory`].
pub fn knn_graph(segs: &[Segment], k: usize, r_max: f32) -> Result<Vec<Vec<u32>>> {
    const WHAT: &str = "the MCGM matcher's segment adjacency";
    const GRID: &str = "the MCGM matcher's centroid grid";
    let n = segs.len();
    let mut adj: Vec<Vec<u32>> = try_filled(n, Vec::new(), WHAT)?;
    if n == 0 || k == 0 {
        return Ok(adj);
    }
    // Centroids apart from the segments (their pixel lists made the scan miss the cache).
    let cs: Vec<(f32, f32)> = try_collect(n, segs.iter().map(|s| s.centroid), WHAT)?;
    let cell = (r_max / 4.0).max(1.0);
    let (x0, y0) = cs.iter().fold((f32::INFINITY, f32::INFINITY), |a, c| {
        (a.0.min(c.0), a.1.min(c.1))
    });
    let key = |c: (f32, f32)| {
        (
            ((c.0 - x0) / cell).floor().max(0.0) as usize,
            ((c.1 - y0) / cell).floor().max(0.0) as usize,
        )
    };
    let (gw, gh) = cs.iter().fold((1, 1), |a, &c| {
        let (x, y) = key(c);
        (a.0.max(x + 1), a.1.max(y + 1))
    });
    // Cells in CSR form, each listing its points by id.
    let cells = gw.checked_mul(gh).and_then(|c| c.checked_add(1));
    let mut start = try_zeroed::<u32>(cells.unwrap_or(usize::MAX), GRID)?;
    for &c in &cs {
        let (x, y) = key(c);
        start[y * gw + x + 1] += 1;
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut fill = try_collect(start.len(), start.iter().copied(), GRID)?;
    let mut items = try_zeroed::<u32>(n, GRID)?;
    for (i, &c) in cs.iter().enumerate() {
        let (x, y) = key(c);
        items[fill[y * gw + x] as usize] = i as u32;
        fill[y * gw + x] += 1;
    }
    let by_dist = |a: &(f32, u32), b: &(f32, u32)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
    let max_ring = (r_max / cell).ceil() as i64 + 1;
    // The k nearest of every segment, and the points within r_max of one (`d`, up to every
    // other centroid): checked, they grew by collect and push.
    const NEAR: &str = "the MCGM matcher's nearest segments";
    let mut nearest: Vec<Vec<u32>> = try_filled(n, Vec::new(), NEAR)?;
    nearest.par_iter_mut().enumerate().try_for_each_init(
        Vec::new,
        |d: &mut Vec<(f32, u32)>, (i, out)| -> Result<()> {
            let (cx, cy) = key(cs[i]);
            let (cx, cy) = (cx as i64, cy as i64);
            let (x, y) = cs[i];
            d.clear();
            for ring in 0..=max_ring {
                // The points not yet seen (rings `ring` and beyond) are at least
                // `(ring - 1) * cell` away.
                let beyond = (ring - 1) as f32 * cell;
                if d.len() >= k {
                    d.select_nth_unstable_by(k - 1, by_dist);
                    if d[k - 1].0 < beyond * (1.0 - 1e-5) - 1e-3 {
                        break;
                    }
                }
                if beyond > r_max + 1e-3 {
                    break;
                }
                for gy in cy - ring..=cy + ring {
                    if gy < 0 || gy >= gh as i64 {
                        continue;
                    }
                    let edge_row = gy == cy - ring || gy == cy + ring;
                    let step = if edge_row { 1 } else { (2 * ring).max(1) };
                    let mut gx = cx - ring;
                    while gx <= cx + ring {
                        if gx >= 0 && gx < gw as i64 {
                            let c = gy as usize * gw + gx as usize;
                            for &j in &items[start[c] as usize..start[c + 1] as usize] {
                                if j as usize == i {
                                    continue;
                                }
                                let (u, v) = cs[j as usize];
                                let dd = ((u - x) * (u - x) + (v - y) * (v - y)).sqrt();
                                if dd <= r_max {
                                    try_grow(d, 1, NEAR)?;
                                    d.push((dd, j));
                                }
                            }
                        }
                        gx += step;
                    }
                }
            }
            // The k nearest (ties by id), then in that order: a selection, not a full sort.
            if d.len() > k {
                d.select_nth_unstable_by(k - 1, by_dist);
                d.truncate(k);
            }
            d.sort_by(by_dist);
            *out = try_collect(d.len(), d.iter().map(|&(_, j)| j), NEAR)?;
            Ok(())
        },
    )?;
    for (i, nb) in nearest.iter().enumerate() {
        for &j in nb {
            try_grow(&mut adj[i], 1, WHAT)?;
            adj[i].push(j);
            try_grow(&mut adj[j as usize], 1, WHAT)?;
            adj[j as usize].push(i as u32);
        }
    }
    for a in adj.iter_mut() {
        a.sort_unstable();
        a.dedup();
    }
    Ok(adj)
}

/// Solver weights (B.2: the module C defaults `A = 1, B = 1.5, D = 1, theta = 0.3`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverParams {
    pub a: f32,
    pub b: f32,
    pub d: f32,
    pub theta: f32,
    pub dg_0: f32,
    pub dg_slope: f32,
    pub max_sweeps: usize,
    pub seed: u64,
}

/// Result of the association-graph matching.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Indices of the chosen candidates (at most one per left and per right segment).
    pub chosen: Vec<usize>,
    /// Final binary state of every candidate.
    pub state: Vec<u8>,
    pub n_weights: usize,
    pub sweeps: usize,
    pub converged: bool,
}

/// Builds the association graph's weights (CSR, symmetric, zero diagonal). A failed allocation
/// of the matrix (8 bytes a weight) or of the candidate lists per segment is
/// [`crate::CoreError::OutOfMemory`].
pub fn association_weights(
    cands: &[Candidate],
    left: &[Segment],
    adj: &[Vec<u32>],
    n_right: usize,
    p: &SolverParams,
) -> Result<Csr> {
    let n_left = left.len();
    // Candidates per left segment (contiguous) and per right segment.
    const BY: &str = "the MCGM matcher's candidates per segment";
    let mut by_left: Vec<Vec<u32>> = try_filled(n_left, Vec::new(), BY)?;
    let mut by_right: Vec<Vec<u32>> = try_filled(n_right, Vec::new(), BY)?;
    for (i, c) in cands.iter().enumerate() {
        try_grow(&mut by_left[c.left as usize], 1, BY)?;
        by_left[c.left as usize].push(i as u32);
        try_grow(&mut by_right[c.right as usize], 1, BY)?;
        by_right[c.right as usize].push(i as u32);
    }
    // A row per candidate, as long as its segments' candidates and its neighbours' together:
    // checked (the rows grew by push, their list by collect).
    const WHAT: &str = "the MCGM matcher's association weights";
    let mut rows: Vec<Vec<(u32, f32)>> = try_filled(cands.len(), Vec::new(), WHAT)?;
    rows.par_iter_mut()
        .zip(cands)
        .enumerate()
        .try_for_each(|(ia, (row, ca))| -> Result<()> {
            for &ib in by_left[ca.left as usize]
                .iter()
                .chain(&by_right[ca.right as usize])
            {
                if ib as usize != ia {
                    try_grow(row, 1, WHAT)?;
                    row.push((ib, -p.b));
                }
            }
            let sa = &left[ca.left as usize];
            let deg_a = adj[ca.left as usize].len() as f32;
            for &nb in &adj[ca.left as usize] {
                let sb = &left[nb as usize];
                let dist = ((sa.centroid.0 - sb.centroid.0).powi(2)
                    + (sa.centroid.1 - sb.centroid.1).powi(2))
                .sqrt()
                .max(1.0);
                let deg_b = adj[nb as usize].len() as f32;
                let norm = p.a / (deg_a * deg_b).sqrt();
                for &ib in &by_left[nb as usize] {
                    let cb = &cands[ib as usize];
                    if cb.right == ca.right {
                        continue; // already inhibited
                    }
                    let g = ((ca.tx - cb.tx).powi(2) + (ca.ty - cb.ty).powi(2)).sqrt() / dist;
                    let c = 2.0 / (1.0 + (p.dg_slope * (g - p.dg_0)).exp()) - 1.0;
                    try_grow(row, 1, WHAT)?;
                    row.push((ib, norm * c));
                }
            }
            // A pair sharing both segments cannot occur (one candidate per (A, A')); sharing
            // A and A' twice (same left and same right) would be the same candidate.
            row.sort_by_key(|e| e.0);
            row.dedup_by_key(|e| e.0);
            Ok(())
        })?;
    // Allocated at once, checked (they grew by push, aborting on a failure).
    let nnz = rows.iter().map(Vec::len).sum();
    let mut csr = Csr::default();
    try_reserve_len(&mut csr.indptr, rows.len() + 1, WHAT)?;
    try_reserve_len(&mut csr.indices, nnz, WHAT)?;
    try_reserve_len(&mut csr.data, nnz, WHAT)?;
    csr.indptr.push(0);
    for r in rows {
        for (j, v) in r {
            csr.indices.push(j);
            csr.data.push(v);
        }
        csr.indptr.push(csr.indices.len());
    }
    Ok(csr)
}

/// Runs the network and resolves double activations by the highest net input. A failed
/// allocation of its per-candidate and per-segment arrays is [`crate::CoreError::OutOfMemory`].
pub fn solve(cands: &[Candidate], csr: &Csr, n_left: usize, p: &SolverParams) -> Result<Solution> {
    const WHAT: &str = "the MCGM network's arrays";
    let m = cands.len();
    let input = try_collect(
        m,
        cands.iter().map(|c| (p.d * c.score - p.theta) as f64),
        WHAT,
    )?;
    // Preset: the best candidate of every left segment on (candidates are best first).
    let init = try_collect(
        m,
        (0..m).map(|i| u8::from(i == 0 || cands[i - 1].left != cands[i].left)),
        WHAT,
    )?;
    let dynamics = run_dynamics(csr, &input, &init, p.seed, p.max_sweeps)?;
    let state = dynamics.state;
    let mut net = try_collect(m, input.iter().copied(), WHAT)?;
    for (a, &on) in state.iter().enumerate() {
        if on == 1 {
            let (idx, val) = csr.row(a);
            for (&b, &t) in idx.iter().zip(val) {
                net[b as usize] += t as f64;
            }
        }
    }
    let better = |a: usize, b: usize| net[a] > net[b] || (net[a] == net[b] && a < b);
    let mut best_left: Vec<Option<usize>> = try_filled(n_left, None, WHAT)?;
    for a in (0..m).filter(|&a| state[a] == 1) {
        let slot = &mut best_left[cands[a].left as usize];
        if slot.is_none_or(|b| better(a, b)) {
            *slot = Some(a);
        }
    }
    let n_right = cands
        .iter()
        .map(|c| c.right as usize + 1)
        .max()
        .unwrap_or(0);
    let mut best_right: Vec<Option<usize>> = try_filled(n_right, None, WHAT)?;
    for a in best_left.iter().flatten().copied() {
        let slot = &mut best_right[cands[a].right as usize];
        if slot.is_none_or(|b| better(a, b)) {
            *slot = Some(a);
        }
    }
    let n_chosen = best_right.iter().flatten().count();
    let mut chosen = try_collect(n_chosen, best_right.into_iter().flatten(), WHAT)?;
    chosen.sort_unstable();
    Ok(Solution {
        chosen,
        state,
        n_weights: csr.nnz(),
        sweeps: dynamics.sweeps,
        converged: dynamics.converged,
    })
}
