"""NumPy/SciPy reference of the Gabor phase-disparity kernel (rust/core/src/matching/gabor).

Stage by stage, the same maths as the Rust code, written for clarity (float64 where it is free):

* :func:`channel` / :func:`responses` -- the zero-DC quadrature Gabor filter bank (true
  convolution, reflect-101 borders);
* :func:`level_data` / :func:`newton_step` -- one level's phase difference, local frequency,
  amplitude / stability confidence and weighted least squares over orientations, with the right
  responses shifted by the current disparity (position-shift receptive fields);
* :func:`lr_check` -- the left-right consistency mask;
* :func:`disparity_one_level` -- the whole pipeline at one pyramid level (search, Newton steps,
  normalised convolution, separable median, validity) without the left-right check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

HALF_WIDTH_FACTOR = math.sqrt(math.log(2.0) / 2.0) / math.pi
AMP_ABS_FLOOR = 1e-4
AMP_PERCENTILE = 0.95
PERCENTILE_STRIDE = 3
MIN_FREQ_RATIO = 0.5
ORIENTATIONS = (0.0, 60.0, -60.0)
BANDWIDTH_OCT = 1.5
#: Orientations used at full resolution (the first ones of ``ORIENTATIONS``).
ORIENTATIONS_FINEST = 1


def sigma_from_bandwidth(freq: float, bandwidth_oct: float) -> float:
    """Envelope sigma (px) for a radial bandwidth in octaves at ``freq`` cycles/px."""
    b = 2.0**bandwidth_oct
    return HALF_WIDTH_FACTOR * (b + 1.0) / ((b - 1.0) * freq)


def gaussian_taps(sigma: float) -> np.ndarray:
    """Normalised Gaussian taps ``-r..r`` with ``r = ceil(3 sigma)``."""
    r = max(1, math.ceil(3.0 * sigma))
    t = np.arange(-r, r + 1, dtype=np.float64)
    g = np.exp(-(t * t) / (2.0 * sigma * sigma))
    return g / g.sum()


@dataclass
class Channel:
    """One channel: carrier ``(kx, ky)`` rad/px, separable taps and zero-DC coefficient."""

    kx: float
    ky: float
    sigma_x: float
    gx: np.ndarray
    gy: np.ndarray
    hx: np.ndarray
    hy: np.ndarray
    dc: complex


def channel(
    freq: float = 0.25,
    theta_deg: float = 0.0,
    bandwidth_oct: float = BANDWIDTH_OCT,
    aspect: float = 1.0,
) -> Channel:
    """Build the channel like ``Channel::new`` (taps rounded to float32 as in Rust)."""
    sigma = np.float32(sigma_from_bandwidth(freq, bandwidth_oct))
    sx, sy = float(np.float32(aspect) * sigma), float(sigma)
    th = math.radians(float(np.float32(theta_deg)))
    k = 2.0 * math.pi * float(np.float32(freq))
    kx, ky = k * math.cos(th), k * math.sin(th)
    gx, gy = gaussian_taps(sx), gaussian_taps(sy)
    tx = np.arange(gx.size) - gx.size // 2
    ty = np.arange(gy.size) - gy.size // 2
    hx = (gx * np.exp(1j * kx * tx)).astype(np.complex64).astype(np.complex128)
    hy = (gy * np.exp(1j * ky * ty)).astype(np.complex64).astype(np.complex128)
    gx = gx.astype(np.float32).astype(np.float64)
    gy = gy.astype(np.float32).astype(np.float64)
    dc = complex(hx.sum() * hy.sum())
    return Channel(float(np.float32(kx)), float(np.float32(ky)), sx, gx, gy, hx, hy, dc)


def _conv(img: np.ndarray, taps: np.ndarray, axis: int) -> np.ndarray:
    """True 1-D convolution with reflect-101 borders (scipy "mirror"), complex-safe."""
    if np.iscomplexobj(img) or np.iscomplexobj(taps):
        img = np.asarray(img, np.complex128)
        taps = np.asarray(taps, np.complex128)
        rr = ndimage.convolve1d(img.real, taps.real, axis=axis, mode="mirror")
        ii = ndimage.convolve1d(img.imag, taps.imag, axis=axis, mode="mirror")
        ri = ndimage.convolve1d(img.real, taps.imag, axis=axis, mode="mirror")
        ir = ndimage.convolve1d(img.imag, taps.real, axis=axis, mode="mirror")
        return (rr - ii) + 1j * (ri + ir)
    return ndimage.convolve1d(np.asarray(img, np.float64), taps, axis=axis, mode="mirror")


def lowpass(img: np.ndarray, ch: Channel) -> np.ndarray:
    """The shared Gaussian low-pass ``L = G * I``."""
    return _conv(_conv(img, ch.gx, 1), ch.gy, 0)


def responses(img: np.ndarray, ch: Channel) -> np.ndarray:
    """Zero-DC complex response ``y = h * I - c (G * I)`` of one channel, ``(H, W)`` complex."""
    a = _conv(_conv(np.asarray(img, np.float64), ch.hx, 1), ch.hy, 0)
    return a - ch.dc * lowpass(img, ch)


def _phasor(kx: float, ky: float, h: int, w: int) -> np.ndarray:
    x = np.arange(w)[None, :]
    y = np.arange(h)[:, None]
    return np.exp(-1j * kx * x) * np.exp(-1j * ky * y)


def _freq_phasor(y: np.ndarray) -> np.ndarray:
    """``y(x+1) conj y(x) + y(x) conj y(x-1)`` with clamped borders."""
    yp = np.concatenate([y[:, 1:], y[:, -1:]], axis=1)
    ym = np.concatenate([y[:, :1], y[:, :-1]], axis=1)
    return yp * np.conj(y) + y * np.conj(ym)


def _stable(y: np.ndarray, f: np.ndarray, ch: Channel, tau: float) -> np.ndarray:
    """Fleet-Jepson stability with the A.9 correction (borders never stable)."""
    a2 = np.abs(y) ** 2
    im_psi = np.angle(f)
    ok = np.zeros(y.shape, bool)
    re_psi = 0.25 * (np.log(a2[:, 2:] + 1e-30) - np.log(a2[:, :-2] + 1e-30))
    dk = im_psi[:, 1:-1] - ch.kx
    lim2 = (tau / ch.sigma_x) ** 2
    ok[:, 1:-1] = (re_psi**2 + dk**2 <= lim2) & (im_psi[:, 1:-1] >= MIN_FREQ_RATIO * ch.kx)
    return ok


@dataclass
class Level:
    """Per-image data of one level (lists over channels)."""

    y: list[np.ndarray]
    f: list[np.ndarray]
    stable: list[np.ndarray]
    low: np.ndarray


def level_data(img: np.ndarray, chans: list[Channel], tau: float = 1.25) -> Level:
    """Responses, local-frequency phasors and stability of every channel."""
    ys = [responses(img, c) for c in chans]
    fs = [_freq_phasor(y) for y in ys]
    st = [_stable(y, f, c, tau) for y, f, c in zip(ys, fs, chans, strict=True)]
    return Level(ys, fs, st, lowpass(img, chans[0]))


def thresholds2(lv: Level, rv: Level, amp_rel: float) -> list[float]:
    """Squared amplitude thresholds ``(amp_rel * P95 |y|)^2`` over both images, per channel."""
    out = []
    for yl, yr in zip(lv.y, rv.y, strict=True):
        s = np.concatenate(
            [
                np.abs(yl.ravel()[::PERCENTILE_STRIDE]) ** 2,
                np.abs(yr.ravel()[::PERCENTILE_STRIDE]) ** 2,
            ]
        )
        k = min(round(AMP_PERCENTILE * (s.size - 1)), s.size - 1)
        p95 = np.partition(s, k)[k]
        thr = max(amp_rel * math.sqrt(p95), AMP_ABS_FLOOR)
        out.append(thr * thr)
    return out


def _shift32(disp: np.ndarray) -> np.ndarray:
    """``x - d`` as the kernel computes it: in float32 (one rounding), as float64.

    Near a half pixel the float32 difference can round onto the tie (``100 - 0.50000006`` is
    ``99.5``), which the rounding sites then send to the other pixel than float64 does.
    """
    x = np.arange(disp.shape[1], dtype=np.float32)[None, :]
    return (x - disp.astype(np.float32)).astype(np.float64)


def _round_away(s: np.ndarray) -> np.ndarray:
    """``f32::round``: half away from zero (exact on float32 values held in float64)."""
    return np.sign(s) * np.floor(np.abs(s) + 0.5)


def _interp_row(v: np.ndarray, i0: np.ndarray, i1: np.ndarray, t: np.ndarray) -> np.ndarray:
    rows = np.arange(v.shape[0])[:, None]
    return v[rows, i0] + t * (v[rows, i1] - v[rows, i0])


def shifted(
    rv: Level, c: int, ch: Channel, disp: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Right response of channel ``c`` at ``x - d`` and its local-frequency phasor.

    The smooth baseband ``exp(-j k.x) (y + c L)`` is interpolated linearly and re-modulated
    exactly. Returns ``(y_r(x - d), f_r(x - d), valid, nearest index)``.
    """
    h, w = disp.shape
    s = _shift32(disp)
    valid = (s >= 0) & (s <= w - 1)
    sc = np.clip(s, 0, w - 1)
    i0 = np.minimum(np.floor(sc).astype(int), max(w - 2, 0))
    i1 = np.minimum(i0 + 1, w - 1)
    t = sc - i0
    ph = _phasor(ch.kx, ch.ky, h, w)
    base = (rv.y[c] + ch.dc * rv.low) * ph
    b = _interp_row(base, i0, i1, t)
    low = _interp_row(rv.low, i0, i1, t)
    f = _interp_row(rv.f[c], i0, i1, t)
    yy = np.arange(h)[:, None]
    carrier = np.exp(1j * (ch.kx * sc + ch.ky * yy))
    y = carrier * b - ch.dc * low
    # The kernel's rounding: ties to even (fastmath round_fast), not half up.
    near = np.minimum(np.rint(sc).astype(int), w - 1)
    return y, f, valid, near


def newton_step(
    lv: Level, rv: Level, chans: list[Channel], thr2: list[float], disp: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """One raw Newton step: ``(delta, conf)`` before smoothing (A.5 steps 3c-3g)."""
    num = np.zeros(disp.shape)
    den = np.zeros(disp.shape)
    csum = np.zeros(disp.shape)
    rows = np.arange(disp.shape[0])[:, None]
    for c, ch in enumerate(chans):
        yw, fr, valid, near = shifted(rv, c, ch, disp)
        yl = lv.y[c]
        z = yw * np.conj(yl)
        pl, pw = np.abs(yl) ** 2, np.abs(yw) ** 2
        k = np.angle(lv.f[c] + fr)
        stab = lv.stable[c] & rv.stable[c][rows, near] & valid
        ok = stab & (np.minimum(pl, pw) >= thr2[c]) & (k >= MIN_FREQ_RATIO * ch.kx)
        with np.errstate(invalid="ignore", divide="ignore"):
            m = np.where(ok, 2.0 * np.abs(z) / (pl + pw), 0.0)
        dphi = np.angle(z)
        num += m * k * dphi
        den += m * k * k
        csum += m
    max_delta = min(math.pi / ch.kx for ch in chans)
    with np.errstate(invalid="ignore", divide="ignore"):
        delta = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    return np.clip(delta, -max_delta, max_delta), csum / len(chans)


def lr_check(dl: np.ndarray, dr: np.ndarray, tol: float = 1.0) -> np.ndarray:
    """``True`` where ``|dl(x) - dr(round(x - dl(x)))| <= tol`` (``dr`` on the right grid)."""
    h, w = dl.shape
    with np.errstate(invalid="ignore"):
        # The kernel's rounding (f32::round): ties away from zero, so -0.5 is -1, outside.
        xr = _round_away(_shift32(dl))
        inside = np.isfinite(dl) & (xr >= 0) & (xr <= w - 1)
    xi = np.where(inside, xr, 0).astype(int)
    other = dr[np.arange(h)[:, None], xi]
    with np.errstate(invalid="ignore"):
        # the difference in float32 as in the kernel: 1.7 - 0.7 is 1 there, 1 + 6e-8 in float64
        diff = np.abs(dl.astype(np.float32) - other.astype(np.float32))
        return inside & (diff <= np.float32(tol))


def energy_terms(lv: Level, rv: Level, disp: np.ndarray, off: float) -> tuple[np.ndarray, ...]:
    """Binocular energy terms at the integer shift ``round(d + off)`` (zero outside)."""
    h, w = disp.shape
    # The kernel: floor(x - d + 0.5) in float32, then the (integer) offset subtracted.
    s = np.floor(_shift32(disp).astype(np.float32) + np.float32(0.5)).astype(np.float64) - off
    valid = (s >= 0) & (s <= w - 1)
    si = np.where(valid, s, 0).astype(int)
    rows = np.arange(h)[:, None]
    num = np.zeros((h, w))
    den = np.zeros((h, w))
    for yl, yr in zip(lv.y, rv.y, strict=True):
        ys = yr[rows, si]
        num += 2.0 * np.real(yl * np.conj(ys))
        den += np.abs(yl) ** 2 + np.abs(ys) ** 2
    return np.where(valid, num, 0.0), np.where(valid, den, 0.0)


def _box(a: np.ndarray, r: int) -> np.ndarray:
    return ndimage.uniform_filter(a, size=2 * r + 1, mode="nearest") * (2 * r + 1) ** 2


def search(lv: Level, rv: Level, base: np.ndarray, offs: list[float], pool: int) -> np.ndarray:
    """Per-pixel argmax of the box-pooled normalised energy over ``base + offs``."""
    best = np.full(base.shape, -np.inf)
    out = base.copy()
    for o in offs:
        num, den = energy_terms(lv, rv, base, o)
        num, den = _box(num, pool), _box(den, pool)
        e = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
        better = e > best
        best = np.where(better, e, best)
        out = np.where(better, base + o, out)
    return out


def median5(d: np.ndarray) -> np.ndarray:
    """Separable 5x5 median: 1x5 then 5x1, nearest borders."""
    m = ndimage.median_filter(d, size=(1, 5), mode="nearest")
    return ndimage.median_filter(m, size=(5, 1), mode="nearest")


def disparity_one_level(
    left: np.ndarray,
    right: np.ndarray,
    d_min: float,
    d_max: float,
    *,
    iters: int = 1,  # iters_finest: with n_levels=1 the only level is the finest
    amp_rel: float = 0.02,
    tau: float = 1.25,
    conf_min: float = 0.15,
    pool: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Whole pipeline at one level (``n_levels=1``, no LR check, no speckle removal)."""
    # With one level, that level is the finest: it uses the full-resolution orientations.
    chans = [channel(0.25, t) for t in ORIENTATIONS[:ORIENTATIONS_FINEST]]
    lv, rv = level_data(left, chans, tau), level_data(right, chans, tau)
    thr2 = thresholds2(lv, rv, amp_rel)
    h, w = left.shape
    n = math.ceil(d_max - d_min)
    disp = search(lv, rv, np.full((h, w), d_min), [float(k) for k in range(n + 1)], pool)
    disp = np.clip(disp, d_min - 1.0, d_max + 1.0)
    conf = np.zeros((h, w))
    g = gaussian_taps(chans[0].sigma_x).astype(np.float32).astype(np.float64)
    for _ in range(iters):
        delta, c = newton_step(lv, rv, chans, thr2, disp)
        cbar = _conv(_conv(c, g, 1), g, 0)
        num = _conv(_conv(c * delta, g, 1), g, 0)
        dbar = np.where(cbar > 1e-6, num / np.where(cbar > 1e-6, cbar, 1.0), 0.0)
        disp = np.where(cbar >= conf_min, np.clip(disp + dbar, d_min - 1.0, d_max + 1.0), disp)
        disp = median5(disp)
        conf = np.maximum(conf, cbar)
    # The kernel's validity (post::validity_row): x - d itself (float32, not rounded) in the row.
    s = _shift32(disp)
    valid = (conf >= conf_min) & (s >= 0) & (s <= w - 1)
    return np.where(valid, disp, np.nan), np.where(valid, np.clip(conf, 0, 1), 0.0)
