//! Per-level data of the phase matcher and the pointwise kernels that use it.
//!
//! Position-shift receptive fields (Chen & Qian 2004): each pyramid level is filtered once per
//! image. The right responses are stored as the smooth *baseband* `b = exp(-j k.x) (y + c L)`
//! (the carrier removed), so shifting them by the current disparity is a cheap linear
//! interpolation followed by an exact carrier phase `exp(-j kx D)`; a Newton iteration never
//! re-filters a warped image and its work is pointwise.

use super::fastmath::{atan2, sincos};
use super::filter::{filter_bank, Channel, Responses};
use crate::parallel::{for_each_row, for_each_row2};

/// A response below this amplitude is numerical noise (a constant image gives ~1e-7; one grey
/// level of texture, 1/255, gives ~1e-3), so its phase is never used whatever the percentile says.
pub const AMP_ABS_FLOOR: f32 = 1e-4;
/// Fraction of pixels sampled (every n-th) for the amplitude percentile; deterministic.
const PERCENTILE_STRIDE: usize = 3;
/// Percentile of the amplitude distribution the relative threshold refers to (A.3).
const AMP_PERCENTILE: f32 = 0.95;
/// A local frequency below this fraction of the tuning is a singularity (A.5 step 4e).
pub const MIN_FREQ_RATIO: f32 = 0.5;

/// Filtered data of one image at one level, laid out for the pointwise kernels.
pub struct LevelData {
    pub w: usize,
    pub h: usize,
    /// Per channel, per pixel: `[re, im, f_re, f_im]` where `(re, im)` is the demodulated response
    /// `beta = exp(-j k.x) y` (left) or the baseband `b = exp(-j k.x) (y + c L)` (right), and
    /// `f = y(x+1) conj y(x) + y(x) conj y(x-1)` the local-frequency phasor.
    pub chan: Vec<Vec<[f32; 4]>>,
    /// Shared low-pass `L = G * I` (right image only uses it, for the zero-DC term).
    pub lowpass: Vec<f32>,
    /// Bit `c` set where channel `c` passes the stability test.
    pub stable: Vec<u8>,
    /// `|y|` samples for the percentile, per channel.
    pub amp_samples: Vec<Vec<f32>>,
}

/// Per-channel constants used by the kernels.
#[derive(Debug, Clone)]
pub struct ChanConst {
    pub kx: f32,
    pub ky: f32,
    pub dc: [f32; 2],
    /// Squared amplitude threshold of this channel at this level.
    pub thr2: f32,
}

/// Builds the level data of one image. `right` selects the baseband layout.
pub fn level_data(
    img: &[f32],
    w: usize,
    h: usize,
    chans: &[Channel],
    tau: f32,
    right: bool,
) -> LevelData {
    let r: Responses = filter_bank(img, w, h, chans);
    let mut data = Vec::with_capacity(chans.len());
    let mut stable = vec![0u8; w * h];
    let mut amp_samples = Vec::with_capacity(chans.len());
    for (ci, c) in chans.iter().enumerate() {
        let (re, im) = (&r.re[ci], &r.im[ci]);
        let mut out = vec![[0f32; 4]; w * h];
        let (cr, cim) = (c.dc[0], c.dc[1]);
        let (kx, ky) = (c.kx, c.ky);
        let lp = &r.lowpass;
        for_each_row(&mut out, w, |y, row| {
            let o = y * w;
            for (x, v) in row.iter_mut().enumerate() {
                let i = o + x;
                let (yr, yi) = (re[i], im[i]);
                // Local-frequency phasor (central pair of products, clamped at the borders).
                let (il, ir) = (o + x.saturating_sub(1), o + (x + 1).min(w - 1));
                let (ar, ai) = (re[ir] * yr + im[ir] * yi, im[ir] * yr - re[ir] * yi);
                let (br, bi) = (yr * re[il] + yi * im[il], yi * re[il] - yr * im[il]);
                let (s, cth) = sincos(-(kx * x as f32 + ky * y as f32));
                // Demodulate: left uses y itself, right adds back c L so the result is smooth.
                let (pr, pi) = if right {
                    (yr + cr * lp[i], yi + cim * lp[i])
                } else {
                    (yr, yi)
                };
                *v = [pr * cth - pi * s, pr * s + pi * cth, ar + br, ai + bi];
            }
        });
        // Stability (A.5 step 4e with the A.9 correction): Im psi = mean phase increment,
        // Re psi = central difference of ln rho; |psi - j k0| <= tau / sigma_x, Im psi >= k0 / 2.
        let lim2 = (tau / c.sigma_x).powi(2);
        let k0 = c.kx;
        let bit = 1u8 << ci;
        for_each_row(&mut stable, w, |y, row| {
            let o = y * w;
            if w < 3 {
                return;
            }
            for x in 1..w - 1 {
                let f = out[o + x];
                let im_psi = atan2(f[3], f[2]);
                let l2 = |j: usize| (re[j] * re[j] + im[j] * im[j] + 1e-30).ln();
                let re_psi = 0.25 * (l2(o + x + 1) - l2(o + x - 1));
                let dk = im_psi - k0;
                if re_psi * re_psi + dk * dk <= lim2 && im_psi >= MIN_FREQ_RATIO * k0 {
                    row[x] |= bit;
                }
            }
        });
        amp_samples.push(
            (0..w * h)
                .step_by(PERCENTILE_STRIDE)
                .map(|i| (re[i] * re[i] + im[i] * im[i]).sqrt())
                .collect(),
        );
        data.push(out);
    }
    LevelData {
        w,
        h,
        chan: data,
        lowpass: r.lowpass,
        stable,
        amp_samples,
    }
}

/// Deterministic percentile (`q` in [0, 1]) of a sample (nearest rank).
pub fn percentile(v: &[f32], q: f32) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    let k = ((q * (s.len() - 1) as f32).round() as usize).min(s.len() - 1);
    let (_, m, _) = s.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    *m
}

/// Channel constants with the amplitude thresholds `amp_rel * P95(|y|)` over both images.
pub fn chan_consts(
    chans: &[Channel],
    l: &LevelData,
    r: &LevelData,
    amp_rel: f32,
) -> Vec<ChanConst> {
    chans
        .iter()
        .enumerate()
        .map(|(ci, c)| {
            let mut s = l.amp_samples[ci].clone();
            s.extend_from_slice(&r.amp_samples[ci]);
            let thr = (amp_rel * percentile(&s, AMP_PERCENTILE)).max(AMP_ABS_FLOOR);
            ChanConst {
                kx: c.kx,
                ky: c.ky,
                dc: c.dc,
                thr2: thr * thr,
            }
        })
        .collect()
}

/// The right response of channel `c` at sub-pixel position `s` of row `y`, demodulated by the
/// LEFT pixel's carrier: returns `exp(-j k.(x, y)) y_r(s, y)` with `d = x - s`, plus the
/// interpolated local-frequency phasor. `None` outside the image.
#[inline(always)]
fn shifted(
    r: &LevelData,
    cc: &ChanConst,
    ci: usize,
    y: usize,
    x: usize,
    d: f32,
) -> Option<([f32; 2], [f32; 2])> {
    let w = r.w;
    let s = x as f32 - d;
    if !(s >= 0.0 && s <= (w - 1) as f32) {
        return None;
    }
    let i0 = (s.floor() as usize).min(w.saturating_sub(2));
    let i1 = (i0 + 1).min(w - 1);
    let t = s - i0 as f32;
    let o = y * w;
    let (a, b) = (r.chan[ci][o + i0], r.chan[ci][o + i1]);
    let lerp = |p: f32, q: f32| p + t * (q - p);
    let (br, bi) = (lerp(a[0], b[0]), lerp(a[1], b[1]));
    let (fr, fi) = (lerp(a[2], b[2]), lerp(a[3], b[3]));
    let lp = lerp(r.lowpass[o + i0], r.lowpass[o + i1]);
    // exp(-j k.x) y_r(s) = exp(-j kx d) b(s) - c L(s) exp(-j k.x).
    let (sn, cs) = sincos(cc.kx * d);
    let (sp, cp) = sincos(-(cc.kx * x as f32 + cc.ky * y as f32));
    let (wr, wi) = (br * cs + bi * sn, bi * cs - br * sn);
    let (dr, di) = (cc.dc[0] * lp, cc.dc[1] * lp);
    let (er, ei) = (dr * cp - di * sp, dr * sp + di * cp);
    Some(([wr - er, wi - ei], [fr, fi]))
}

/// One Newton step at every pixel: per-channel phase difference, local frequency, confidence,
/// weighted least squares over channels. Returns `(delta, c)` with `c` the mean channel
/// confidence in [0, 1] and `delta` clamped to half a carrier wavelength.
pub fn newton_step(
    l: &LevelData,
    r: &LevelData,
    cc: &[ChanConst],
    disp: &[f32],
) -> (Vec<f32>, Vec<f32>) {
    let (w, h) = (l.w, l.h);
    let mut delta = vec![0f32; w * h];
    let mut conf = vec![0f32; w * h];
    let n = cc.len().max(1) as f32;
    let max_delta = cc
        .iter()
        .map(|c| std::f32::consts::PI / c.kx)
        .fold(f32::INFINITY, f32::min);
    for_each_row2(&mut delta, &mut conf, w, |y, drow, crow| {
        for x in 0..w {
            let i = y * w + x;
            let d = disp[i];
            let s = x as f32 - d;
            if !(s >= 0.0 && s <= (w - 1) as f32) {
                drow[x] = 0.0;
                crow[x] = 0.0;
                continue;
            }
            let near = (s.round() as usize).min(w - 1);
            let stab = l.stable[i] & r.stable[y * w + near];
            let (mut num, mut den, mut csum) = (0f32, 0f32, 0f32);
            for (ci, c) in cc.iter().enumerate() {
                let Some((bw, fr)) = shifted(r, c, ci, y, x, d) else {
                    continue;
                };
                let bl = l.chan[ci][i];
                let (zr, zi) = (bw[0] * bl[0] + bw[1] * bl[1], bw[1] * bl[0] - bw[0] * bl[1]);
                let pl = bl[0] * bl[0] + bl[1] * bl[1];
                let pw = bw[0] * bw[0] + bw[1] * bw[1];
                let k = atan2(bl[3] + fr[1], bl[2] + fr[0]);
                let ok =
                    (stab >> ci) & 1 == 1 && pl.min(pw) >= c.thr2 && k >= MIN_FREQ_RATIO * c.kx;
                if !ok {
                    continue;
                }
                let m = 2.0 * (zr * zr + zi * zi).sqrt() / (pl + pw);
                let dphi = atan2(zi, zr);
                num += m * k * dphi;
                den += m * k * k;
                csum += m;
            }
            drow[x] = if den > 0.0 {
                (num / den).clamp(-max_delta, max_delta)
            } else {
                0.0
            };
            crow[x] = csum / n;
        }
    });
    (delta, conf)
}

/// Normalised binocular energy terms for a shift `d + off` at every pixel:
/// `num = sum_c 2 Re(y_l conj y_r)`, `den = sum_c |y_l|^2 + |y_r|^2` (zero outside the image).
pub fn energy_terms(
    l: &LevelData,
    r: &LevelData,
    cc: &[ChanConst],
    disp: &[f32],
    off: f32,
) -> (Vec<f32>, Vec<f32>) {
    let (w, h) = (l.w, l.h);
    let mut num = vec![0f32; w * h];
    let mut den = vec![0f32; w * h];
    for_each_row2(&mut num, &mut den, w, |y, nrow, drow| {
        for x in 0..w {
            let i = y * w + x;
            let d = disp[i] + off;
            let (mut a, mut b) = (0f32, 0f32);
            for (ci, c) in cc.iter().enumerate() {
                let Some((bw, _)) = shifted(r, c, ci, y, x, d) else {
                    break;
                };
                let bl = l.chan[ci][i];
                a += 2.0 * (bw[0] * bl[0] + bw[1] * bl[1]);
                b += bw[0] * bw[0] + bw[1] * bw[1] + bl[0] * bl[0] + bl[1] * bl[1];
            }
            nrow[x] = a;
            drow[x] = b;
        }
    });
    (num, den)
}
