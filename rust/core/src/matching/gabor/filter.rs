//! Quadrature Gabor filter bank: separable complex kernels, zero-DC correction, reflect borders.
//!
//! The kernel of one channel is `h(x, y) = g(x) g(y) exp(j (kx x + ky y)) - c g(x) g(y)` with
//! normalised 1-D Gaussians `g`, and `c = sum of the carrier-modulated kernel` (Morlet correction,
//! algorithms.md A.1) so `sum h = 0` exactly on the truncated discrete kernel. Because the carrier
//! factors into an x-part and a y-part, `h * I = hx *_x (hy *_y I) - c (G * I)`: a complex row pass
//! (shared by +-theta, which have the same `kx`), a complex column pass per channel, and one real
//! Gaussian `G * I` shared by every channel. True convolution (not correlation) fixes the phase
//! sign: for `I = cos(w x)` the response phase grows as `+w x`.

// Row kernels index several equally long rows in lockstep; index loops are the clearest form
// and the one LLVM vectorises once the slices are re-bounded to the row length.
#![allow(clippy::needless_range_loop)]

use super::pool::{Buf, WHAT};
use crate::alloc::try_zeroed;
use crate::error::{CoreError, Result};
use crate::parallel::for_each_row;
use crate::simd::simd_fn;
use std::f32::consts::PI;

/// Half-amplitude half-width factor of a Gaussian spectrum: `a = sqrt(ln 2 / 2) / (pi sigma)`.
const HALF_WIDTH_FACTOR: f64 = 0.187_390_5; // sqrt(ln(2)/2)/pi
/// Kernel truncation in standard deviations (the Gaussian is 0.011 of its peak there).
pub const TRUNCATE_SIGMAS: f32 = 3.0;

/// `sigma` (px) of the spatial envelope giving a radial bandwidth of `bandwidth_oct` octaves at
/// centre frequency `freq` (cycles/px): `sigma = a0 (2^b + 1) / ((2^b - 1) F)`.
pub fn sigma_from_bandwidth(freq: f32, bandwidth_oct: f32) -> f32 {
    let b = 2f64.powf(bandwidth_oct as f64);
    (HALF_WIDTH_FACTOR * (b + 1.0) / ((b - 1.0) * freq as f64)) as f32
}

/// Truncation radius of a Gaussian of std `sigma`.
pub fn radius_for(sigma: f32) -> usize {
    (TRUNCATE_SIGMAS * sigma).ceil().max(1.0) as usize
}

/// Normalised (sum 1) sampled Gaussian of std `sigma`, taps `-r..=r`.
pub fn gaussian_taps(sigma: f32, r: usize) -> Vec<f32> {
    let s = sigma as f64;
    let raw: Vec<f64> = (-(r as isize)..=r as isize)
        .map(|t| (-((t * t) as f64) / (2.0 * s * s)).exp())
        .collect();
    let sum: f64 = raw.iter().sum();
    raw.iter().map(|v| (v / sum) as f32).collect()
}

/// One channel of the bank (one orientation at one centre frequency).
#[derive(Debug, Clone)]
pub struct Channel {
    /// Orientation of the frequency vector from the x-axis (degrees).
    pub theta_deg: f32,
    /// Angular carrier frequency along x and y (rad/px).
    pub kx: f32,
    pub ky: f32,
    /// Envelope standard deviations (px): `sigma_x = aspect * sigma`, `sigma_y = sigma`.
    pub sigma_x: f32,
    pub sigma_y: f32,
    /// Real Gaussian taps along x and y (sum 1).
    pub gx: Vec<f32>,
    pub gy: Vec<f32>,
    /// Complex taps `g(t) exp(j k t)` along x and y, as (re, im), index `t + r`.
    pub hx: Vec<[f32; 2]>,
    pub hy: Vec<[f32; 2]>,
    /// Zero-DC coefficient `c = sum_t hx(t) * sum_t hy(t)` (complex).
    pub dc: [f32; 2],
}

/// Largest Gaussian envelope of a channel (px, either axis): about 40 times the default's
/// (1.57 px at freq 1/4 and 1.5 octaves), and a filter of 2 x 3 x 64 + 1 taps.
pub const MAX_ENVELOPE_SIGMA: f32 = 64.0;

impl Channel {
    /// Builds the channel `(freq, theta_deg)` with radial bandwidth `bandwidth_oct` and envelope
    /// aspect ratio `aspect` (`sigma_x / sigma_y`).
    pub fn new(freq: f32, theta_deg: f32, bandwidth_oct: f32, aspect: f32) -> Result<Self> {
        if !(freq.is_finite() && freq > 0.0 && freq < 0.5) {
            return Err(CoreError::param(
                "freq",
                format!("must be in (0, 0.5) cycles/px, got {freq}"),
            ));
        }
        if !(bandwidth_oct.is_finite() && bandwidth_oct > 0.05 && bandwidth_oct <= 4.0) {
            return Err(CoreError::param(
                "bandwidth_oct",
                format!("must be in (0.05, 4] octaves, got {bandwidth_oct}"),
            ));
        }
        if !(aspect.is_finite() && aspect > 0.1 && aspect <= 10.0) {
            return Err(CoreError::param(
                "aspect",
                format!("must be in (0.1, 10], got {aspect}"),
            ));
        }
        if !(theta_deg.is_finite() && theta_deg.abs() < 90.0) {
            return Err(CoreError::param(
                "orientations_deg",
                format!("each must be in (-90, 90) degrees (needs a horizontal carrier), got {theta_deg}"),
            ));
        }
        let sigma = sigma_from_bandwidth(freq, bandwidth_oct);
        let (sigma_x, sigma_y) = (aspect * sigma, sigma);
        // The envelope grows as 1 / freq: freq 1e-9 asked for a filter of 10^10 taps per image
        // row and the process was killed for its memory.
        let widest = sigma_x.max(sigma_y);
        if widest.is_nan() || widest > MAX_ENVELOPE_SIGMA {
            return Err(CoreError::param(
                "freq",
                format!(
                    "freq {freq} with bandwidth {bandwidth_oct} octaves and aspect {aspect} \
                     gives an envelope of sigma {:.3e} px, at most {MAX_ENVELOPE_SIGMA} px: raise \
                     freq or the bandwidth",
                    widest
                ),
            ));
        }
        let th = (theta_deg as f64).to_radians();
        let k = 2.0 * std::f64::consts::PI * freq as f64;
        let (kx, ky) = (k * th.cos(), k * th.sin());
        let gx = gaussian_taps(sigma_x, radius_for(sigma_x));
        let gy = gaussian_taps(sigma_y, radius_for(sigma_y));
        let modulate = |g: &[f32], kk: f64| -> Vec<[f32; 2]> {
            let r = (g.len() / 2) as f64;
            g.iter()
                .enumerate()
                .map(|(i, &v)| {
                    let t = i as f64 - r;
                    [
                        (v as f64 * (kk * t).cos()) as f32,
                        (v as f64 * (kk * t).sin()) as f32,
                    ]
                })
                .collect()
        };
        let hx = modulate(&gx, kx);
        let hy = modulate(&gy, ky);
        let sum = |h: &[[f32; 2]]| {
            h.iter()
                .fold([0f64; 2], |a, v| [a[0] + v[0] as f64, a[1] + v[1] as f64])
        };
        let (sx, sy) = (sum(&hx), sum(&hy));
        let dc = [
            (sx[0] * sy[0] - sx[1] * sy[1]) as f32,
            (sx[0] * sy[1] + sx[1] * sy[0]) as f32,
        ];
        Ok(Channel {
            theta_deg,
            kx: kx as f32,
            ky: ky as f32,
            sigma_x,
            sigma_y,
            gx,
            gy,
            hx,
            hy,
            dc,
        })
    }

    /// Nominal horizontal carrier (rad/px), > 0.
    pub fn k0x(&self) -> f32 {
        self.kx
    }
}

/// Mirror index (reflect-101, OpenCV's default border / scipy "mirror"): `-1 -> 1`, `n -> n - 2`.
#[inline]
pub fn mirror(i: isize, n: usize) -> usize {
    if n == 1 {
        return 0;
    }
    let p = 2 * (n as isize - 1);
    let mut m = i.rem_euclid(p);
    if m >= n as isize {
        m = p - m;
    }
    m as usize
}

/// `row` extended by `r` mirrored (reflect-101) samples on each side, written into `pad` (a
/// reused per-thread buffer: an allocation per row was a visible share of the row passes). Only
/// the borders go through [`mirror`] (an integer division): per-pixel mirroring dominated.
fn mirror_pad_into(row: &[f32], r: usize, pad: &mut Vec<f32>) {
    let w = row.len();
    pad.clear();
    pad.extend((0..r).map(|i| row[mirror(i as isize - r as isize, w)]));
    pad.extend_from_slice(row);
    pad.extend((0..r).map(|i| row[mirror((w + i) as isize, w)]));
}

thread_local! {
    /// Per-thread padded row of the row passes (taken and put back, so that the AVX2 function
    /// bodies do not run inside a closure compiled without AVX2).
    static PAD_SCRATCH: std::cell::RefCell<Vec<f32>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Real separable convolution with reflect-101 borders (symmetric taps, so conv = correlation).
pub fn blur_real(src: &[f32], w: usize, h: usize, gx: &[f32], gy: &[f32]) -> Result<Buf> {
    let mut tmp = Buf::scratch(w * h)?;
    for_each_row(&mut tmp, w, |y, out| {
        real_row_pass(&src[y * w..(y + 1) * w], gx, out)
    });
    let mut dst = Buf::scratch(w * h)?;
    for_each_row(&mut dst, w, |y, out| real_col_pass(&tmp, w, h, y, gy, out));
    Ok(dst)
}

simd_fn! {
    /// `out(x) = sum_k g[k] row(mirror(x + k - r))`.
    fn real_row_pass(row: &[f32], g: &[f32], out: &mut [f32]) {
        let w = row.len();
        let r = g.len() / 2;
        let Some((&g0, rest)) = g.split_first() else {
            return;
        };
        let mut pad = PAD_SCRATCH.take();
        mirror_pad_into(row, r, &mut pad);
        // Register-blocked: each chunk of CHUNK outputs sums every tap in registers, in tap order
        // (the first tap initialises the sum), then is stored once.
        let n = w / CHUNK * CHUNK;
        for x0 in (0..n).step_by(CHUNK) {
            let mut acc = [0f32; CHUNK];
            let p0 = &pad[x0..x0 + CHUNK];
            for i in 0..CHUNK {
                acc[i] = g0 * p0[i];
            }
            for (k, &gk) in rest.iter().enumerate() {
                let pk = &pad[x0 + k + 1..x0 + k + 1 + CHUNK];
                for i in 0..CHUNK {
                    acc[i] += gk * pk[i];
                }
            }
            out[x0..x0 + CHUNK].copy_from_slice(&acc);
        }
        for x in n..w {
            let mut a = g0 * pad[x];
            for (k, &gk) in rest.iter().enumerate() {
                a += gk * pad[x + k + 1];
            }
            out[x] = a;
        }
        PAD_SCRATCH.set(pad);
    }
}

simd_fn! {
    /// Column pass of a real separable blur for output row `y`.
    fn real_col_pass(src: &[f32], w: usize, h: usize, y: usize, g: &[f32], out: &mut [f32]) {
        let r = g.len() / 2;
        let Some((&g0, rest)) = g.split_first() else {
            return;
        };
        let row = |k: usize| {
            let yy = mirror(y as isize + k as isize - r as isize, h);
            &src[yy * w..(yy + 1) * w]
        };
        let s0 = row(0);
        let rows: Vec<&[f32]> = (1..g.len()).map(row).collect();
        let out = &mut out[..w];
        // Register-blocked, taps summed in order (the first initialises the sum).
        let n = w / CHUNK * CHUNK;
        for x0 in (0..n).step_by(CHUNK) {
            let mut acc = [0f32; CHUNK];
            let p0 = &s0[x0..x0 + CHUNK];
            for i in 0..CHUNK {
                acc[i] = g0 * p0[i];
            }
            for (&gk, sk) in rest.iter().zip(&rows) {
                let pk = &sk[x0..x0 + CHUNK];
                for i in 0..CHUNK {
                    acc[i] += gk * pk[i];
                }
            }
            out[x0..x0 + CHUNK].copy_from_slice(&acc);
        }
        for x in n..w {
            let mut a = g0 * s0[x];
            for (&gk, sk) in rest.iter().zip(&rows) {
                a += gk * sk[x];
            }
            out[x] = a;
        }
    }
}

/// Outputs per register block of the separable passes (two AVX2 registers per plane).
const CHUNK: usize = 16;

/// A shared complex row pass: x taps and the (re, im) planes they produced.
type OwnedRowGroup = (Vec<[f32; 2]>, Buf, Buf);

/// Complex responses `y = h * I` of one image for every channel, as planar (re, im) planes,
/// plus the shared low-pass `L = G * I` (Gaussian of the first channel; all channels share it).
pub struct Responses {
    pub w: usize,
    pub h: usize,
    /// `re[c]`, `im[c]`: planes of channel `c`.
    pub re: Vec<Vec<f32>>,
    pub im: Vec<Vec<f32>>,
    pub lowpass: Vec<f32>,
}

/// Filters `img` (`w` x `h`, row-major) with every channel. All channels must share the same
/// envelope (same frequency, bandwidth and aspect), which the bank guarantees.
pub fn filter_bank(img: &[f32], w: usize, h: usize, chans: &[Channel]) -> Result<Responses> {
    let lowpass = match chans.first() {
        Some(c) => blur_real(img, w, h, &c.gx, &c.gy)?.into_vec(),
        None => try_zeroed(w * h, WHAT)?,
    };
    // Row passes are shared by channels with identical x taps (+-theta).
    let mut groups: Vec<OwnedRowGroup> = Vec::new();
    let mut group_of = Vec::with_capacity(chans.len());
    for c in chans {
        if let Some(g) = groups.iter().position(|(hx, _, _)| *hx == c.hx) {
            group_of.push(g);
        } else {
            let (re, im) = row_pass(img, w, h, &c.hx)?;
            groups.push((c.hx.clone(), re, im));
            group_of.push(groups.len() - 1);
        }
    }
    let mut re_out = Vec::with_capacity(chans.len());
    let mut im_out = Vec::with_capacity(chans.len());
    for (c, &g) in chans.iter().zip(&group_of) {
        let (_, hre, him) = &groups[g];
        let mut re = try_zeroed::<f32>(w * h, WHAT)?;
        let mut im = try_zeroed::<f32>(w * h, WHAT)?;
        crate::parallel::for_each_row2(&mut re, &mut im, w, |y, ore, oim| {
            complex_col_pass(hre, him, w, h, y, &c.hy, ore, oim)
        });
        // Zero-DC correction: y = a - c L.
        let [cr, ci] = c.dc;
        for ((r, i), &l) in re.iter_mut().zip(im.iter_mut()).zip(&lowpass) {
            *r -= cr * l;
            *i -= ci * l;
        }
        re_out.push(re);
        im_out.push(im);
    }
    Ok(Responses {
        w,
        h,
        re: re_out,
        im: im_out,
        lowpass,
    })
}

/// Complex row pass of a real image: `H(x) = sum_t hx(t) I(x - t)`.
pub fn row_pass(img: &[f32], w: usize, h: usize, hx: &[[f32; 2]]) -> Result<(Buf, Buf)> {
    let mut re = Buf::scratch(w * h)?;
    let mut im = Buf::scratch(w * h)?;
    crate::parallel::for_each_row2(&mut re, &mut im, w, |y, ore, oim| {
        complex_row_pass(&img[y * w..(y + 1) * w], hx, ore, oim)
    });
    Ok((re, im))
}

simd_fn! {
    /// One row of [`row_pass`].
    fn complex_row_pass(row: &[f32], hx: &[[f32; 2]], ore: &mut [f32], oim: &mut [f32]) {
        let w = row.len();
        let r = hx.len() / 2;
        // pad[i] = I(i - r); output x needs I(x - t) = pad[x + 2r - k], with k = t + r.
        let mut pad = PAD_SCRATCH.take();
        mirror_pad_into(row, r, &mut pad);
        let (ore, oim) = (&mut ore[..w], &mut oim[..w]);
        // Register-blocked; the sums start at 0 and add the taps in order.
        let n = w / CHUNK * CHUNK;
        for x0 in (0..n).step_by(CHUNK) {
            let (mut ar, mut ai) = ([0f32; CHUNK], [0f32; CHUNK]);
            for (k, &[hr, hi]) in hx.iter().enumerate() {
                let seg = &pad[2 * r - k + x0..2 * r - k + x0 + CHUNK];
                for i in 0..CHUNK {
                    ar[i] += hr * seg[i];
                    ai[i] += hi * seg[i];
                }
            }
            ore[x0..x0 + CHUNK].copy_from_slice(&ar);
            oim[x0..x0 + CHUNK].copy_from_slice(&ai);
        }
        for x in n..w {
            let (mut a, mut b) = (0f32, 0f32);
            for (k, &[hr, hi]) in hx.iter().enumerate() {
                let p = pad[2 * r - k + x];
                a += hr * p;
                b += hi * p;
            }
            ore[x] = a;
            oim[x] = b;
        }
        PAD_SCRATCH.set(pad);
    }
}

simd_fn! {
    /// Complex column pass for output row `y`: `a(y) = sum_s hy(s) H(y - s)`.
    pub fn complex_col_pass(
        hre: &[f32],
        him: &[f32],
        w: usize,
        h: usize,
        y: usize,
        hy: &[[f32; 2]],
        ore: &mut [f32],
        oim: &mut [f32],
    ) {
        let r = hy.len() / 2;
        let real_taps = hy.iter().all(|t| t[1] == 0.0);
        // tap s = k - r reads row y - s
        let rows: Vec<(&[f32], &[f32])> = (0..hy.len())
            .map(|k| {
                let yy = mirror(y as isize - (k as isize - r as isize), h);
                (&hre[yy * w..(yy + 1) * w], &him[yy * w..(yy + 1) * w])
            })
            .collect();
        let (ore, oim) = (&mut ore[..w], &mut oim[..w]);
        // Register-blocked; the sums start at 0 and add the taps in order.
        let n = w / CHUNK * CHUNK;
        for x0 in (0..n).step_by(CHUNK) {
            let (mut a, mut b) = ([0f32; CHUNK], [0f32; CHUNK]);
            for (&[gr, gi], &(sr, si)) in hy.iter().zip(&rows) {
                let (sr, si) = (&sr[x0..x0 + CHUNK], &si[x0..x0 + CHUNK]);
                if real_taps {
                    for i in 0..CHUNK {
                        a[i] += gr * sr[i];
                        b[i] += gr * si[i];
                    }
                } else {
                    for i in 0..CHUNK {
                        a[i] += gr * sr[i] - gi * si[i];
                        b[i] += gr * si[i] + gi * sr[i];
                    }
                }
            }
            ore[x0..x0 + CHUNK].copy_from_slice(&a);
            oim[x0..x0 + CHUNK].copy_from_slice(&b);
        }
        for x in n..w {
            let (mut a, mut b) = (0f32, 0f32);
            for (&[gr, gi], &(sr, si)) in hy.iter().zip(&rows) {
                if real_taps {
                    a += gr * sr[x];
                    b += gr * si[x];
                } else {
                    a += gr * sr[x] - gi * si[x];
                    b += gr * si[x] + gi * sr[x];
                }
            }
            ore[x] = a;
            oim[x] = b;
        }
    }
}

/// Gaussian pyramid level: blur with `sigma = 1` and keep even pixels (`ceil(n / 2)`).
pub fn pyr_down(img: &[f32], w: usize, h: usize) -> Result<(Vec<f32>, usize, usize)> {
    let g = gaussian_taps(PYR_SIGMA, radius_for(PYR_SIGMA));
    let b = blur_real(img, w, h, &g, &g)?;
    let (w2, h2) = (w.div_ceil(2), h.div_ceil(2));
    let mut out = try_zeroed::<f32>(w2 * h2, WHAT)?;
    for_each_row(&mut out, w2, |y, row| {
        let src = &b[(2 * y) * w..(2 * y + 1) * w];
        for (x, v) in row.iter_mut().enumerate() {
            *v = src[2 * x];
        }
    });
    Ok((out, w2, h2))
}

/// Anti-alias blur of the pyramid (algorithms.md A.5 step 1).
pub const PYR_SIGMA: f32 = 1.0;

/// Nominal angular frequency `2 pi F` (rad/px).
pub fn angular(freq: f32) -> f32 {
    2.0 * PI * freq
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_is_zero_dc() {
        for th in [0.0, 30.0, -30.0, 60.0, -60.0] {
            let c = Channel::new(0.25, th, 1.0, 1.0).unwrap();
            // Response to a constant image must vanish.
            let img = vec![0.7f32; 40 * 30];
            let r = filter_bank(&img, 40, 30, std::slice::from_ref(&c)).unwrap();
            let m = r.re[0]
                .iter()
                .chain(&r.im[0])
                .fold(0f32, |a, v| a.max(v.abs()));
            assert!(m < 1e-6, "theta {th}: max |y| = {m}");
            assert!(c.dc[0].abs() < 0.01 && c.dc[1].abs() < 1e-6);
        }
    }

    #[test]
    fn phase_grows_with_x_for_a_tuned_sinusoid() {
        let (w, h) = (64, 8);
        let k = angular(0.25);
        let img: Vec<f32> = (0..w * h)
            .map(|i| 0.5 + 0.3 * (k * (i % w) as f32).cos())
            .collect();
        let c = Channel::new(0.25, 0.0, 1.0, 1.0).unwrap();
        let r = filter_bank(&img, w, h, std::slice::from_ref(&c)).unwrap();
        let p = |x: usize| r.im[0][4 * w + x].atan2(r.re[0][4 * w + x]);
        let step = (p(31) - p(30) + 3.0 * PI) % (2.0 * PI) - PI;
        assert!((step - k).abs() < 1e-3, "phase step {step}");
    }

    #[test]
    fn mirror_index() {
        assert_eq!(mirror(-1, 5), 1);
        assert_eq!(mirror(5, 5), 3);
        assert_eq!(mirror(-7, 5), 1);
        assert_eq!(mirror(3, 1), 0);
    }

    /// A deterministic pseudo-random image in [0, 1].
    fn noise(w: usize, h: usize, seed: u32) -> Vec<f32> {
        let mut s = seed;
        (0..w * h)
            .map(|_| {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (s >> 8) as f32 / (1u32 << 24) as f32
            })
            .collect()
    }

    /// The response by its definition, in f64: `y(x, y) = sum_{t, s} h(t, s) I(x - t, y - s)` with
    /// `h(t, s) = hx(t) hy(s) - dc gx(t) gy(s)` and reflect-101 borders.
    fn direct_response(img: &[f32], w: usize, h: usize, c: &Channel) -> (Vec<f64>, Vec<f64>) {
        let (rx, ry) = ((c.hx.len() / 2) as isize, (c.hy.len() / 2) as isize);
        let (mut re, mut im) = (vec![0f64; w * h], vec![0f64; w * h]);
        for y in 0..h {
            for x in 0..w {
                let (mut a, mut b) = (0f64, 0f64);
                for (ks, hy) in c.hy.iter().enumerate() {
                    let yy = mirror(y as isize - (ks as isize - ry), h);
                    for (kt, hx) in c.hx.iter().enumerate() {
                        let v = img[yy * w + mirror(x as isize - (kt as isize - rx), w)] as f64;
                        let (hxr, hxi, hyr, hyi) =
                            (hx[0] as f64, hx[1] as f64, hy[0] as f64, hy[1] as f64);
                        let g = c.gx[kt] as f64 * c.gy[ks] as f64;
                        a += (hxr * hyr - hxi * hyi - c.dc[0] as f64 * g) * v;
                        b += (hxr * hyi + hxi * hyr - c.dc[1] as f64 * g) * v;
                    }
                }
                re[y * w + x] = a;
                im[y * w + x] = b;
            }
        }
        (re, im)
    }

    #[test]
    fn filter_bank_equals_the_direct_convolution() {
        // 37 px: two register blocks of 16 and a tail of 5; 13 rows, fewer than a kernel's taps
        // with the narrow bandwidth (the borders mirror more than once). A real-tap channel
        // (0 degrees) and complex-tap ones; +-60 share their row pass.
        let (w, h) = (37, 13);
        let img = noise(w, h, 7);
        for (bw, aspect) in [(1.5, 1.0), (0.6, 1.5)] {
            let chans: Vec<Channel> = [0.0, 60.0, -60.0]
                .iter()
                .map(|&t| Channel::new(0.25, t, bw, aspect).unwrap())
                .collect();
            let r = filter_bank(&img, w, h, &chans).unwrap();
            for (ci, c) in chans.iter().enumerate() {
                let (re, im) = direct_response(&img, w, h, c);
                for i in 0..w * h {
                    let (dr, di) = (r.re[ci][i] as f64 - re[i], r.im[ci][i] as f64 - im[i]);
                    assert!(
                        dr.abs() < 2e-6 && di.abs() < 2e-6,
                        "bw {bw} theta {} pixel ({}, {}): ({}, {}) vs ({re_i}, {im_i})",
                        c.theta_deg,
                        i % w,
                        i / w,
                        r.re[ci][i],
                        r.im[ci][i],
                        re_i = re[i],
                        im_i = im[i]
                    );
                }
            }
        }
    }

    #[test]
    fn channel_geometry_follows_the_formulas() {
        // sigma = sqrt(ln 2 / 2) / pi * (2^b + 1) / ((2^b - 1) F): 0.18739 * 3 / 0.25 at b = 1.
        let s = sigma_from_bandwidth(0.25, 1.0);
        assert!((s - 2.248_686).abs() < 1e-5, "{s}");
        // Radius ceil(3 sigma): 6.75 -> 7 taps each side.
        assert_eq!(radius_for(s), 7);
        assert_eq!(radius_for(2.0), 6);
        let c = Channel::new(0.25, 60.0, 1.0, 2.0).unwrap();
        // sigma_x = aspect * sigma along x, sigma along y.
        assert!((c.sigma_x - 2.0 * s).abs() < 1e-5 && (c.sigma_y - s).abs() < 1e-6);
        assert_eq!((c.gx.len(), c.gy.len()), (2 * 14 + 1, 2 * 7 + 1));
        // The frequency vector at +60 degrees: (k cos 60, k sin 60), k = 2 pi F.
        let k = angular(0.25);
        assert!((c.kx - 0.5 * k).abs() < 1e-6);
        assert!((c.ky - 0.75f32.sqrt() * k).abs() < 1e-6);
        // Gaussian taps: sum 1, exp(-t^2 / (2 sigma^2)) profile.
        let g = gaussian_taps(2.0, 6);
        assert!((g.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        assert!((g[6 + 2] / g[6] - (-0.5f32).exp()).abs() < 1e-6);
        // The carrier's dc coefficient is real (the taps' imaginary parts cancel in pairs).
        assert!(c.dc[1].abs() < 1e-7);
    }

    #[test]
    fn pyr_down_keeps_the_even_pixels_of_the_sigma_1_blur() {
        // Odd sizes: ceil(n / 2) samples each way, the last from the last (even) row / column.
        let (w, h) = (37, 11);
        let img = noise(w, h, 3);
        let (out, w2, h2) = pyr_down(&img, w, h).unwrap();
        assert_eq!((w2, h2), (19, 6));
        let g = gaussian_taps(PYR_SIGMA, radius_for(PYR_SIGMA));
        let r = (g.len() / 2) as isize;
        for y2 in 0..h2 {
            for x2 in 0..w2 {
                let (x, y) = ((2 * x2) as isize, (2 * y2) as isize);
                let mut v = 0f64;
                for (i, gy) in g.iter().enumerate() {
                    for (j, gx) in g.iter().enumerate() {
                        let (yy, xx) =
                            (mirror(y + i as isize - r, h), mirror(x + j as isize - r, w));
                        v += (*gy as f64) * (*gx as f64) * img[yy * w + xx] as f64;
                    }
                }
                let got = out[y2 * w2 + x2] as f64;
                assert!((got - v).abs() < 1e-6, "({x2}, {y2}): {got} vs {v}");
            }
        }
    }
}
