//! Per-level data of the phase matcher and the pointwise kernels that use it.
//!
//! Position-shift receptive fields (Chen & Qian 2004): each pyramid level is filtered once per
//! image. The right responses are stored as the smooth *baseband* `b = exp(-j k.x) (y + c L)`
//! (the carrier removed; `y + c L` is the response before the zero-DC term), so shifting them by
//! the current disparity is a linear interpolation followed by the exact carrier phase
//! `exp(-j kx D)`; a Newton iteration never re-filters a warped image and its work is pointwise.
//!
//! Row kernels run in two passes: a scalar gather of the interpolated right data, then plain
//! vectorisable arithmetic over the row (`simd_fn!` adds an AVX2+FMA build chosen at run time).

// Row kernels index several equally long rows in lockstep; index loops are the clearest form
// and the one LLVM vectorises once the slices are re-bounded to the row length.
#![allow(clippy::needless_range_loop)]

use super::fastmath::{atan2, floor_fast, ln, round_fast, sincos};
use super::filter::{blur_real, complex_col_pass, row_pass, Channel};
use super::gather::gather_lerp;
use super::pool::Buf;
use crate::alloc::try_zeroed;
use crate::error::Result;
use crate::parallel::{for_each_row, for_each_row_pair, ROWS_PER_TASK};
use crate::simd::simd_fn;
use rayon::prelude::*;

/// A response below this amplitude is numerical noise (a constant image gives ~1e-7; one grey
/// level of texture, 1/255, gives ~1e-3), so its phase is never used whatever the percentile says.
pub const AMP_ABS_FLOOR: f32 = 1e-4;
/// Every n-th pixel enters the amplitude percentile (deterministic subsample, 3x cheaper).
const PERCENTILE_STRIDE: usize = 3;
/// Percentile of the amplitude distribution the relative threshold refers to (A.3).
const AMP_PERCENTILE: f32 = 0.95;
/// A local frequency below this fraction of the tuning is a singularity (A.5 step 4e).
pub const MIN_FREQ_RATIO: f32 = 0.5;
/// Guards `ln(0)` in the amplitude log-derivative.
const LN_EPS: f32 = 1e-30;

/// Sub-rows stored per image row and channel (see [`LevelData::chan`]).
pub const SUBROWS: usize = 6;

/// Filtered data of one image at one level, laid out for the pointwise kernels.
pub struct LevelData {
    pub w: usize,
    pub h: usize,
    /// Per channel, "row-planar": image row `y` holds [`SUBROWS`] sub-rows `re, im, f_re, f_im,
    /// y_re, y_im` at `(SUBROWS y + k) w`, where `(re, im)` is the demodulated response
    /// `beta = exp(-j k.x) y` (left) or the baseband `b = exp(-j k.x) (y + c L)` (right),
    /// `f = y(x+1) conj y(x) + y(x) conj y(x-1)` the local-frequency phasor and `y` the zero-DC
    /// response itself (for the integer-shift search). Planar rows keep the loops vectorisable.
    pub chan: Vec<Buf>,
    /// Shared low-pass `L = G * I` (the right image uses it for the zero-DC term).
    pub lowpass: Buf,
    /// Bit `c` set where channel `c` passes the stability test.
    pub stable: Vec<u8>,
    /// `|y|^2` samples for the percentile, per channel.
    pub amp2_samples: Vec<Vec<f32>>,
    /// Per channel: carrier phasors `exp(-j kx x)` (re, im) per column and `exp(-j ky y)` per row.
    pub colph: Vec<(Vec<f32>, Vec<f32>)>,
    pub rowph: Vec<(Vec<f32>, Vec<f32>)>,
    /// `sum_c |y_c|^2` per pixel.
    pub energy: Buf,
}

/// A shared complex row pass: the x taps and the (re, im) planes they produced.
type RowGroup<'a> = (&'a [[f32; 2]], Buf, Buf);

/// Per-channel constants used by the kernels.
#[derive(Debug, Clone)]
pub struct ChanConst {
    pub kx: f32,
    pub ky: f32,
    pub dc: [f32; 2],
    /// Squared amplitude threshold of this channel at this level.
    pub thr2: f32,
    /// Index of this channel's `kx` in the list of distinct `kx` (shared carrier rotations).
    pub kx_slot: usize,
}

fn phasors(k: f32, n: usize) -> (Vec<f32>, Vec<f32>) {
    // f64 so that exp(-j k x) stays exact to f32 precision even at x ~ 4000.
    (0..n)
        .map(|i| {
            let a = -(k as f64) * i as f64;
            (a.cos() as f32, a.sin() as f32)
        })
        .unzip()
}

/// Builds the level data of one image. `right` selects the baseband layout.
pub fn level_data(
    img: &[f32],
    w: usize,
    h: usize,
    chans: &[Channel],
    tau: f32,
    right: bool,
) -> Result<LevelData> {
    let lowpass = match chans.first() {
        Some(c) => blur_real(img, w, h, &c.gx, &c.gy)?,
        None => Buf::zeroed(w * h)?,
    };
    // Row passes are shared by channels with identical x taps (+-theta).
    let mut groups: Vec<RowGroup<'_>> = Vec::new();
    let mut group_of = Vec::with_capacity(chans.len());
    for c in chans {
        if let Some(g) = groups.iter().position(|(hx, _, _)| *hx == c.hx.as_slice()) {
            group_of.push(g);
        } else {
            let (re, im) = row_pass(img, w, h, &c.hx)?;
            groups.push((&c.hx, re, im));
            group_of.push(groups.len() - 1);
        }
    }
    let mut chan = Vec::with_capacity(chans.len());
    let mut stable = try_zeroed::<u8>(w * h, "the Gabor matcher's stability mask")?;
    let mut amp2_samples = Vec::with_capacity(chans.len());
    let mut colph = Vec::with_capacity(chans.len());
    let mut rowph = Vec::with_capacity(chans.len());
    let mut amp2 = Buf::scratch(w * h)?;
    let mut energy = Buf::zeroed(w * h)?;
    for (ci, (c, &g)) in chans.iter().zip(&group_of).enumerate() {
        let (_, hre, him) = &groups[g];
        let cph = phasors(c.kx, w);
        let rph = phasors(c.ky, h);
        let mut out = Buf::scratch(SUBROWS * w * h)?;
        for_each_row_pair(&mut out, SUBROWS * w, &mut amp2, w, |y, orow, arow| {
            build_row(
                hre, him, w, h, y, &c.hy, c.dc, &lowpass, &cph.0, &cph.1, rph.0[y], rph.1[y],
                right, orow, arow,
            )
        });
        for_each_row(&mut energy, w, |y, erow| {
            for (e, a) in erow.iter_mut().zip(&amp2[y * w..(y + 1) * w]) {
                *e += a;
            }
        });
        // Stability (A.5 step 4e with the A.9 correction): Im psi = mean phase increment,
        // Re psi = central difference of ln rho; |psi - j k0| <= tau / sigma_x, Im psi >= k0 / 2.
        let lim2 = (tau / c.sigma_x).powi(2);
        let bit = 1u8 << ci;
        for_each_row(&mut stable, w, |y, srow| {
            let o = SUBROWS * y * w;
            let (fr, fi) = (&out[o + 2 * w..o + 3 * w], &out[o + 3 * w..o + 4 * w]);
            stability_row(fr, fi, &amp2[y * w..(y + 1) * w], c.kx, lim2, bit, srow)
        });
        amp2_samples.push(amp2.iter().step_by(PERCENTILE_STRIDE).copied().collect());
        chan.push(out);
        colph.push(cph);
        rowph.push(rph);
    }
    Ok(LevelData {
        w,
        h,
        chan,
        lowpass,
        stable,
        amp2_samples,
        colph,
        rowph,
        energy,
    })
}

simd_fn! {
    /// One output row of a channel: column pass, zero-DC term, `|y|^2`, demodulation, local
    /// frequency phasor.
    fn build_row(
        hre: &[f32],
        him: &[f32],
        w: usize,
        h: usize,
        y: usize,
        hy: &[[f32; 2]],
        dc: [f32; 2],
        lowpass: &[f32],
        cre: &[f32],
        cim: &[f32],
        rre: f32,
        rim: f32,
        right: bool,
        orow: &mut [f32],
        arow: &mut [f32],
    ) {
        // Taken out of the thread-local, not borrowed in a closure: a closure would be compiled
        // outside this AVX2 function. Every entry of the two rows is written before it is read.
        let mut buf = ROW_SCRATCH.take();
        buf.resize(2 * w, 0.0);
        let (ar, ai) = buf.split_at_mut(w);
        let (ar, ai) = (&mut ar[..w], &mut ai[..w]);
        complex_col_pass(hre, him, w, h, y, hy, ar, ai);
        // The zero-DC response goes straight into its sub-rows (no scratch row and copy).
        let (ore, rest) = orow.split_at_mut(w);
        let (oim, rest) = rest.split_at_mut(w);
        let (ofr, rest) = rest.split_at_mut(w);
        let (ofi, rest) = rest.split_at_mut(w);
        let (yr, yi) = rest.split_at_mut(w);
        let (yr, yi) = (&mut yr[..w], &mut yi[..w]);
        let lp = &lowpass[y * w..(y + 1) * w];
        let arow = &mut arow[..w];
        for x in 0..w {
            // Zero-DC: y = a - c L (a = response of the uncorrected kernel).
            yr[x] = ar[x] - dc[0] * lp[x];
            yi[x] = ai[x] - dc[1] * lp[x];
            arow[x] = yr[x] * yr[x] + yi[x] * yi[x];
        }
        let (yr, yi) = (&yr[..w], &yi[..w]);
        // The left keeps the zero-DC response, the right the smooth uncorrected one.
        let (pr, pi) = if right { (&ar[..w], &ai[..w]) } else { (yr, yi) };
        let (cre, cim) = (&cre[..w], &cim[..w]);
        let (ore, oim) = (&mut ore[..w], &mut oim[..w]);
        let (ofr, ofi) = (&mut ofr[..w], &mut ofi[..w]);
        for x in 0..w {
            // exp(-j k.(x, y)) = colph[x] * rowph[y]
            let qr = cre[x] * rre - cim[x] * rim;
            let qi = cre[x] * rim + cim[x] * rre;
            ore[x] = pr[x] * qr - pi[x] * qi;
            oim[x] = pr[x] * qi + pi[x] * qr;
        }
        // f = y(x+1) conj y(x) + y(x) conj y(x-1), borders clamped.
        let f = |x: usize, xl: usize, xr: usize| {
            (
                yr[xr] * yr[x] + yi[xr] * yi[x] + yr[x] * yr[xl] + yi[x] * yi[xl],
                yi[xr] * yr[x] - yr[xr] * yi[x] + yi[x] * yr[xl] - yr[x] * yi[xl],
            )
        };
        (ofr[0], ofi[0]) = f(0, 0, 1.min(w - 1));
        (ofr[w - 1], ofi[w - 1]) = f(w - 1, w.saturating_sub(2), w - 1);
        if w > 2 {
            let (yr0, yr1, yr2) = (&yr[..w - 2], &yr[1..w - 1], &yr[2..w]);
            let (yi0, yi1, yi2) = (&yi[..w - 2], &yi[1..w - 1], &yi[2..w]);
            let (fr, fi) = (&mut ofr[1..w - 1], &mut ofi[1..w - 1]);
            for x in 0..w - 2 {
                fr[x] = yr2[x] * yr1[x] + yi2[x] * yi1[x] + yr1[x] * yr0[x] + yi1[x] * yi0[x];
                fi[x] = yi2[x] * yr1[x] - yr2[x] * yi1[x] + yi1[x] * yr0[x] - yr1[x] * yi0[x];
            }
        }
        ROW_SCRATCH.set(buf);
    }
}

thread_local! {
    /// Per-thread row buffers of [`build_row`] (a fresh allocation per row and channel was a
    /// visible share of the filtering time).
    static ROW_SCRATCH: std::cell::RefCell<Vec<f32>> = const { std::cell::RefCell::new(Vec::new()) };
}

simd_fn! {
    /// Stability bits of one channel for one row (borders are never stable).
    fn stability_row(fr: &[f32], fi: &[f32], arow: &[f32], k0: f32, lim2: f32, bit: u8, srow: &mut [u8]) {
        let w = fr.len();
        if w < 3 || fi.len() != w || arow.len() != w || srow.len() != w {
            return;
        }
        // ln rho^2 once per pixel (each is used by both neighbours).
        // (An index loop, not an iterator chain, so it is compiled inside this AVX2 function.)
        let mut lr = vec![0f32; w];
        for x in 0..w {
            lr[x] = ln(arow[x] + LN_EPS);
        }
        let n = w - 2;
        let (fr, fi, l0, l2) = (&fr[1..w - 1], &fi[1..w - 1], &lr[..n], &lr[2..]);
        let s = &mut srow[1..w - 1];
        for x in 0..n {
            let im_psi = atan2(fi[x], fr[x]);
            let re_psi = 0.25 * (l2[x] - l0[x]);
            let dk = im_psi - k0;
            let ok = (re_psi * re_psi + dk * dk <= lim2) & (im_psi >= MIN_FREQ_RATIO * k0);
            s[x] |= if ok { bit } else { 0 };
        }
    }
}

/// Deterministic percentile (`q` in [0, 1]) of a sample (nearest rank).
pub fn percentile(v: &[f32], q: f32) -> f32 {
    percentile_in_place(&mut v.to_vec(), q)
}

/// [`percentile`] that reorders `v` instead of copying it.
fn percentile_in_place(v: &mut [f32], q: f32) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    let k = ((q * (v.len() - 1) as f32).round() as usize).min(v.len() - 1);
    let (_, m, _) = v.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    *m
}

/// Bits of the top-level histogram of [`percentile_of_two`] (sign, exponent, 3 mantissa bits).
const HIST_BITS: u32 = 12;

/// [`percentile`] of the concatenation of `a` and `b` (non-negative finite values, as `|y|^2`):
/// the same nearest-rank element, by a parallel histogram of the top bits of the IEEE
/// representation (monotonic for non-negative floats) and a selection among the elements of the
/// one bin that holds it. No concatenated copy, and both cores work.
pub fn percentile_of_two(a: &[f32], b: &[f32], q: f32) -> f32 {
    let n = a.len() + b.len();
    if n == 0 {
        return 0.0;
    }
    let k = ((q * (n - 1) as f32).round() as usize).min(n - 1);
    let shift = 32 - HIST_BITS;
    let bins = 1usize << HIST_BITS;
    let hist_of = |v: &[f32]| {
        let mut h = vec![0u32; bins];
        for x in v {
            h[(x.to_bits() >> shift) as usize] += 1;
        }
        h
    };
    let chunk = n.div_ceil(2).max(1);
    let hist = [a, b]
        .par_iter()
        .flat_map(|v| v.par_chunks(chunk))
        .map(hist_of)
        .reduce(
            || vec![0u32; bins],
            |mut x, y| {
                x.iter_mut().zip(&y).for_each(|(p, q)| *p += q);
                x
            },
        );
    // The bin holding rank k, and k's rank inside it.
    let (mut bin, mut below) = (0usize, 0usize);
    for (i, &c) in hist.iter().enumerate() {
        if below + c as usize > k {
            bin = i;
            break;
        }
        below += c as usize;
    }
    let mut inside: Vec<f32> = [a, b]
        .par_iter()
        .flat_map(|v| v.par_chunks(chunk))
        .flat_map_iter(|c| {
            c.iter()
                .copied()
                .filter(move |x| (x.to_bits() >> shift) as usize == bin)
        })
        .collect();
    let j = k - below;
    if inside.is_empty() || j >= inside.len() {
        // Unreachable for non-negative finite input; fall back to the plain selection.
        let mut all: Vec<f32> = a.iter().chain(b).copied().collect();
        return percentile_in_place(&mut all, q);
    }
    let (_, m, _) = inside.select_nth_unstable_by(j, |x, y| x.total_cmp(y));
    *m
}

/// Channel constants with the amplitude thresholds `amp_rel * P95(|y|)` over both images.
pub fn chan_consts(
    chans: &[Channel],
    l: &LevelData,
    r: &LevelData,
    amp_rel: f32,
) -> Vec<ChanConst> {
    // One selection per channel (itself parallel: with one channel, at full resolution, a
    // sequential selection left the other core idle).
    let thr: Vec<f32> = (0..chans.len())
        .into_par_iter()
        .map(|ci| {
            let p = percentile_of_two(&l.amp2_samples[ci], &r.amp2_samples[ci], AMP_PERCENTILE);
            (amp_rel * p.sqrt()).max(AMP_ABS_FLOOR)
        })
        .collect();
    let mut slots: Vec<f32> = Vec::new();
    chans
        .iter()
        .zip(thr)
        .map(|(c, thr)| {
            let kx_slot = match slots.iter().position(|&k| k == c.kx) {
                Some(p) => p,
                None => {
                    slots.push(c.kx);
                    slots.len() - 1
                }
            };
            ChanConst {
                kx: c.kx,
                ky: c.ky,
                dc: c.dc,
                thr2: thr * thr,
                kx_slot,
            }
        })
        .collect()
}

/// Distinct `kx` values of the channels, in slot order.
pub fn kx_slots(cc: &[ChanConst]) -> Vec<f32> {
    let mut v: Vec<f32> = Vec::new();
    for c in cc {
        if c.kx_slot == v.len() {
            v.push(c.kx);
        }
    }
    v
}

/// Row-level preparation shared by the kernels: sub-pixel positions, validity, stability,
/// interpolated low-pass and the carrier rotations `exp(-j kx d)` per distinct `kx`.
struct RowPrep {
    i0: Vec<u32>,
    t: Vec<f32>,
    /// `round(x - d)` clamped to the row, and 1 where `x - d` is inside it.
    near: Vec<u32>,
    valid: Vec<u8>,
    stab: Vec<u8>,
    lp: Vec<f32>,
    sn: Vec<Vec<f32>>,
    cs: Vec<Vec<f32>>,
}

impl RowPrep {
    fn new(w: usize, n_slots: usize) -> Self {
        RowPrep {
            i0: vec![0; w],
            t: vec![0.0; w],
            near: vec![0; w],
            valid: vec![0; w],
            stab: vec![0; w],
            lp: vec![0.0; w],
            sn: vec![vec![0.0; w]; n_slots],
            cs: vec![vec![0.0; w]; n_slots],
        }
    }
}

/// Row work buffers of the Newton step (reused across the rows of a band).
struct RowWork {
    num: Vec<f32>,
    den: Vec<f32>,
    csum: Vec<f32>,
    bwr: Vec<f32>,
    bwi: Vec<f32>,
    gfr: Vec<f32>,
    gfi: Vec<f32>,
}

impl RowWork {
    fn new(w: usize) -> Self {
        let z = || vec![0f32; w];
        RowWork {
            num: z(),
            den: z(),
            csum: z(),
            bwr: z(),
            bwi: z(),
            gfr: z(),
            gfi: z(),
        }
    }
}

/// Fills `p` for row `y` at the disparities `drow + off` (every entry is overwritten).
#[inline(always)]
fn prep_row(
    l: &LevelData,
    r: &LevelData,
    slots: &[f32],
    y: usize,
    drow: &[f32],
    off: f32,
    p: &mut RowPrep,
) {
    let w = l.w;
    let o = y * w;
    let last = (w - 1) as f32;
    let i0max = w.saturating_sub(2) as f32;
    // Index arithmetic in f32 and one conversion per value, so this loop vectorises (with
    // `usize` casts and `min` it stayed scalar, a fifth of the Newton row). Same values: the
    // indices are integers below 2^24, exact in f32.
    let (pi0, pt, pnear, pv) = (
        &mut p.i0[..w],
        &mut p.t[..w],
        &mut p.near[..w],
        &mut p.valid[..w],
    );
    let drow = &drow[..w];
    for x in 0..w {
        let d = drow[x] + off;
        let s = x as f32 - d;
        pv[x] = (s >= 0.0 && s <= last) as u8;
        let sc = s.max(0.0).min(last);
        let i0 = floor_fast(sc).min(i0max);
        pi0[x] = i0 as i32 as u32;
        pt[x] = sc - i0;
        pnear[x] = round_fast(sc).min(last) as i32 as u32;
    }
    // Validity is folded into the stability byte: an out-of-image shift has no stable channel.
    let (ls, rs) = (&l.stable[o..o + w], &r.stable[o..o + w]);
    for x in 0..w {
        let rn = rs[(pnear[x] as usize).min(w - 1)];
        p.stab[x] = (ls[x] & rn) * pv[x];
    }
    gather_lerp(&r.lowpass[o..o + w], &p.i0, &p.t, &mut p.lp);
    for (k, &kx) in slots.iter().enumerate() {
        let (sn, cs) = (&mut p.sn[k][..w], &mut p.cs[k][..w]);
        for x in 0..w {
            let (s, c) = sincos(kx * (drow[x] + off));
            sn[x] = s;
            cs[x] = c;
        }
    }
}

/// Fills `(bwr, bwi)` with the shifted right response of channel `ci`, demodulated by the left
/// pixel's carrier: `exp(-j k.(x, y)) y_r(x - d, y) = exp(-j kx d) b(x - d) - c L(x - d) exp(-j k.(x, y))`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn shifted_row(
    l: &LevelData,
    r: &LevelData,
    c: &ChanConst,
    ci: usize,
    y: usize,
    p: &RowPrep,
    bwr: &mut [f32],
    bwi: &mut [f32],
    gfr: &mut [f32],
    gfi: &mut [f32],
) {
    let w = l.w;
    let o = SUBROWS * y * w;
    let rc = &r.chan[ci];
    let (rre, rim) = (&rc[o..o + w], &rc[o + w..o + 2 * w]);
    let (rfr, rfi) = (&rc[o + 2 * w..o + 3 * w], &rc[o + 3 * w..o + 4 * w]);
    // Gather + linear interpolation of the smooth baseband and frequency phasor.
    for (src, dst) in [
        (rre, &mut *bwr),
        (rim, &mut *bwi),
        (rfr, &mut *gfr),
        (rfi, &mut *gfi),
    ] {
        gather_lerp(src, &p.i0, &p.t, dst);
    }
    let (cre, cim) = (&l.colph[ci].0[..w], &l.colph[ci].1[..w]);
    let (rre, rim) = (l.rowph[ci].0[y], l.rowph[ci].1[y]);
    let (sn, cs) = (&p.sn[c.kx_slot][..w], &p.cs[c.kx_slot][..w]);
    let lp = &p.lp[..w];
    let (bwr, bwi) = (&mut bwr[..w], &mut bwi[..w]);
    for x in 0..w {
        let (br, bi) = (bwr[x], bwi[x]);
        let (wr, wi) = (br * cs[x] + bi * sn[x], bi * cs[x] - br * sn[x]);
        let qr = cre[x] * rre - cim[x] * rim;
        let qi = cre[x] * rim + cim[x] * rre;
        let (dr, di) = (c.dc[0] * lp[x], c.dc[1] * lp[x]);
        bwr[x] = wr - (dr * qr - di * qi);
        bwi[x] = wi - (dr * qi + di * qr);
    }
}

simd_fn! {
    /// One Newton row: per-channel phase difference, local frequency, confidence, WLS over channels.
    fn newton_row(
        l: &LevelData,
        r: &LevelData,
        cc: &[ChanConst],
        slots: &[f32],
        y: usize,
        drow: &[f32],
        max_delta: f32,
        p: &mut RowPrep,
        wk: &mut RowWork,
        dout: &mut [f32],
        cout: &mut [f32],
    ) {
        let w = l.w;
        prep_row(l, r, slots, y, drow, 0.0, p);
        let RowWork { num, den, csum, bwr, bwi, gfr, gfi } = wk;
        for v in [&mut *num, &mut *den, &mut *csum] {
            v.iter_mut().for_each(|v| *v = 0.0);
        }
        for (ci, c) in cc.iter().enumerate() {
            shifted_row(l, r, c, ci, y, p, bwr, bwi, gfr, gfi);
            let o = SUBROWS * y * w;
            let lc = &l.chan[ci];
            let (lre, lim) = (&lc[o..o + w], &lc[o + w..o + 2 * w]);
            let (lfr, lfi) = (&lc[o + 2 * w..o + 3 * w], &lc[o + 3 * w..o + 4 * w]);
            let kmin = MIN_FREQ_RATIO * c.kx;
            let (bwr, bwi, gfr, gfi) = (&bwr[..w], &bwi[..w], &gfr[..w], &gfi[..w]);
            let stab = &p.stab[..w];
            let (num, den, csum) = (&mut num[..w], &mut den[..w], &mut csum[..w]);
            let bit = 1u8 << ci;
            for x in 0..w {
                let bl = [lre[x], lim[x], lfr[x], lfi[x]];
                let (zr, zi) = (bwr[x] * bl[0] + bwi[x] * bl[1], bwi[x] * bl[0] - bwr[x] * bl[1]);
                let pl = bl[0] * bl[0] + bl[1] * bl[1];
                let pw = bwr[x] * bwr[x] + bwi[x] * bwi[x];
                let k = atan2(bl[3] + gfi[x], bl[2] + gfr[x]);
                let ok = (stab[x] & bit != 0) & (pl.min(pw) >= c.thr2) & (k >= kmin);
                let m = 2.0 * (zr * zr + zi * zi).sqrt() / (pl + pw);
                let m = if ok { m } else { 0.0 };
                let dphi = atan2(zi, zr);
                num[x] += m * k * dphi;
                den[x] += m * k * k;
                csum[x] += m;
            }
        }
        let inv_n = 1.0 / cc.len().max(1) as f32;
        for x in 0..w {
            let d = if den[x] > 0.0 { num[x] / den[x] } else { 0.0 };
            dout[x] = d.clamp(-max_delta, max_delta);
            cout[x] = csum[x] * inv_n;
        }
    }
}

/// One Newton step at every pixel. Returns `(delta, c)`: the WLS phase update (clamped to half
/// the shortest carrier wavelength) and the mean channel confidence in [0, 1].
pub fn newton_step(
    l: &LevelData,
    r: &LevelData,
    cc: &[ChanConst],
    disp: &[f32],
) -> Result<(Buf, Buf)> {
    let (w, h) = (l.w, l.h);
    let mut delta = Buf::scratch(w * h)?;
    let mut conf = Buf::scratch(w * h)?;
    let slots = kx_slots(cc);
    let max_delta = cc
        .iter()
        .map(|c| std::f32::consts::PI / c.kx)
        .fold(f32::INFINITY, f32::min);
    let n_slots = slots.len();
    delta
        .par_chunks_mut(w * ROWS_PER_TASK)
        .zip(conf.par_chunks_mut(w * ROWS_PER_TASK))
        .enumerate()
        .for_each(|(band, (dband, cband))| {
            let (mut p, mut wk) = (RowPrep::new(w, n_slots), RowWork::new(w));
            for (i, (drow, crow)) in dband.chunks_mut(w).zip(cband.chunks_mut(w)).enumerate() {
                let y = band * ROWS_PER_TASK + i;
                newton_row(
                    l,
                    r,
                    cc,
                    &slots,
                    y,
                    &disp[y * w..(y + 1) * w],
                    max_delta,
                    &mut p,
                    &mut wk,
                    drow,
                    crow,
                )
            }
        });
    Ok((delta, conf))
}
