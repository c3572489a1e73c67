"""NumPy reference of the refinement stage (rust/core/src/refine.rs), in float64.

The same maths in plain array operations: normalised-convolution smoothing (three box passes,
zero padding), Catmull-Rom warping of the right image by the smoothed estimate plus each
integer shift, Gaussian-window ZNCC of the centred images, the peak test and the parabola vertex,
then the fill passes. Used by the parity tests in ``tests/test_refine.py``.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]


def gaussian_taps(sigma: float, radius: int) -> F64:
    i = np.arange(-radius, radius + 1, dtype=np.float64)
    return np.exp(-(i * i) / (2.0 * sigma * sigma))


def conv_sep_zero(a: npt.ArrayLike, taps: F64) -> F64:
    """Separable convolution, zero padding, rows first then columns."""
    arr = np.asarray(a, np.float64)
    r = len(taps) // 2
    h, w = arr.shape
    p = np.pad(arr, ((0, 0), (r, r)))
    tmp = sum(g * p[:, k : k + w] for k, g in enumerate(taps))
    p = np.pad(tmp, ((r, r), (0, 0)))
    return np.asarray(sum(g * p[k : k + h, :] for k, g in enumerate(taps)), np.float64)


def box3_radius(sigma: float) -> int:
    """Half-width of the box whose three-fold repetition has a Gaussian's variance."""
    return max(1, round((math.sqrt(4.0 * sigma * sigma + 1.0) - 1.0) / 2.0))


def _box(a: F64, b: int, axis: int) -> F64:
    """Box sum of half-width ``b`` along ``axis``, zero padding."""
    n = a.shape[axis]
    pad = [(0, 0), (0, 0)]
    pad[axis] = (b + 1, b)
    c = np.cumsum(np.pad(a, pad), axis=axis)
    hi = np.take(c, np.arange(2 * b + 1, 2 * b + 1 + n), axis=axis)
    lo = np.take(c, np.arange(0, n), axis=axis)
    return np.asarray(hi - lo, np.float64)


def box3(a: npt.ArrayLike, b: int) -> F64:
    """Three box passes along x, then three along y (zero padding)."""
    out = np.asarray(a, np.float64)
    for axis in (1, 1, 1, 0, 0, 0):
        out = _box(out, b, axis)
    return out


def nc_smooth(d: npt.ArrayLike, sigma: float) -> F64:
    """``K*(v m) / K*m`` with the three-box kernel; NaN where no value is within reach."""
    dd = np.asarray(d, np.float64)
    m = np.isfinite(dd)
    b = box3_radius(sigma)
    num = box3(np.where(m, dd, 0.0), b)
    den = box3(m.astype(np.float64), b)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0.5, num / den, np.nan)


def nc_plane(d: npt.ArrayLike, sigma: float) -> tuple[F64, F64]:
    """Local weighted least-squares plane ``a + b dx + c dy`` (three-box kernel): ``(a, rms)``.

    ``rms`` is the weighted RMS residual of the values about the plane; a flat plane (the mean)
    where the positions do not fix one; NaN where no value is within reach.
    """
    dd = np.asarray(d, np.float64)
    h, w = dd.shape
    m = np.isfinite(dd)
    v = np.where(m, dd, 0.0)
    u = np.arange(w, dtype=np.float64)[None, :] - (w - 1) / 2.0
    t = np.arange(h, dtype=np.float64)[:, None] - (h - 1) / 2.0
    u, t = np.broadcast_to(u, dd.shape), np.broadcast_to(t, dd.shape)
    b = box3_radius(sigma)
    mf = m.astype(np.float64)
    s = [box3(mf * q, b) for q in (1.0, u, t, u * u, u * t, t * t, v, u * v, t * v, v * v)]
    m0 = s[0]
    mu, mv = s[1] - u * m0, s[2] - t * m0
    muu = s[3] - 2 * u * s[1] + u * u * m0
    muv = s[4] - u * s[2] - t * s[1] + u * t * m0
    mvv = s[5] - 2 * t * s[2] + t * t * m0
    md, mud, mvd, mdd = s[6], s[7] - u * s[6], s[8] - t * s[6], s[9]
    with np.errstate(invalid="ignore", divide="ignore"):
        det = m0 * (muu * mvv - muv**2) - mu * (mu * mvv - muv * mv) + mv * (mu * muv - muu * mv)
        full = det > 1e-9 * m0 * np.maximum(muu * mvv, 1e-300)
        dets = np.where(full, det, 1.0)
        a = md * (muu * mvv - muv**2) - mu * (mud * mvv - muv * mvd) + mv * (mud * muv - muu * mvd)
        bb = m0 * (mud * mvv - muv * mvd) - md * (mu * mvv - muv * mv) + mv * (mu * mvd - mud * mv)
        c = m0 * (muu * mvd - mud * muv) - mu * (mu * mvd - mud * mv) + md * (mu * muv - muu * mv)
        a, bb, c = a / dets, bb / dets, c / dets
        flat = md / m0
        plane = np.where(full, a, flat)
        fit = np.where(full, a * md + bb * mud + c * mvd, flat * md)
        rms = np.sqrt(np.maximum((mdd - fit) / m0, 0.0))
    ok = m0 > 0.5
    return np.where(ok, plane, np.nan), np.where(ok, rms, np.nan)


def cubic_warp(right: F64, t: F64) -> F64:
    """Catmull-Rom samples of each row of ``right`` at the real columns ``t`` (clamped)."""
    h, w = right.shape
    i0 = np.floor(t)
    f = t - i0
    i0 = i0.astype(np.int64)
    rows = np.arange(h)[:, None]
    at = lambda k: right[rows, np.clip(i0 + k, 0, w - 1)]  # noqa: E731
    f2, f3 = f * f, f * f * f
    return (
        0.5 * (-f3 + 2 * f2 - f) * at(-1)
        + 0.5 * (3 * f3 - 5 * f2 + 2) * at(0)
        + 0.5 * (-3 * f3 + 4 * f2 + f) * at(1)
        + 0.5 * (f3 - f2) * at(2)
    )


def zncc_shift(left: F64, right: F64, base: F64, s: float, taps: F64, var_floor: float) -> F64:
    """ZNCC of the left image and the right image warped by ``base + s``; NaN where undefined.

    Each image is centred on its own mean first (ZNCC does not see it; the Rust float32 sums
    need it).
    """
    w = left.shape[1]
    lc = left - left.mean()
    ok_b = np.isfinite(base)
    x = np.arange(w, dtype=np.float64)[None, :]
    t = x - np.where(ok_b, base, 0.0) - s
    rw = np.where(ok_b, cubic_warp(right, t) - right.mean(), 0.0)
    mass = conv_sep_zero(np.ones_like(left), taps)
    ml = conv_sep_zero(lc, taps) / mass
    vl = conv_sep_zero(lc * lc, taps) / mass - ml * ml
    mr = conv_sep_zero(rw, taps) / mass
    vr = conv_sep_zero(rw * rw, taps) / mass - mr * mr
    c = conv_sep_zero(lc * rw, taps) / mass - ml * mr
    ok = ok_b & (t >= 0) & (t <= w - 1) & (vl > var_floor) & (vr > var_floor)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(ok, c / np.sqrt(vl * vr), np.nan)


def _parabola(a: F64, b: F64, c: F64) -> tuple[F64, npt.NDArray[np.bool_]]:
    curv = a - 2 * b + c
    ok = curv < -1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        off = np.clip(0.5 * (a - c) / np.where(ok, curv, -1.0), -1.0, 1.0)
    return off, ok


def refine_disparity(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    disp: npt.ArrayLike,
    conf: npt.ArrayLike,
    d_min: float,
    d_max: float,
    base_sigma: float = 4.0,
    win_sigma: float = 4.5,
    win_radius: int = 9,
    search: int = 2,
    step: float = 0.5,
    fill_search: int = 2,
    fill_step: float = 1.0,
    var_floor: float = 1e-6,
    fills: tuple[tuple[float, float], ...] = ((16.0, 0.3),),
    fill_confidence: float = 0.25,
    fill_plane: bool = True,
    fill_max_residual: float = np.inf,
) -> tuple[F64, F64, int]:
    """``(disparity, confidence, n_filled)`` as ``refine_disparity`` in Rust."""
    lf = np.asarray(left, np.float64)
    rf = np.asarray(right, np.float64)
    d = np.asarray(disp, np.float64)
    cf = np.clip(np.asarray(conf, np.float64), 0.0, 1.0)
    taps = gaussian_taps(win_sigma, win_radius)

    def stack(base: F64, search: int, step: float) -> F64:
        ks = np.arange(-search, search + 1)
        return np.stack([zncc_shift(lf, rf, base, float(k * step), taps, var_floor) for k in ks])

    def peaks(z: F64, c0: int) -> tuple[npt.NDArray[np.int64], F64, npt.NDArray[np.bool_]]:
        finite = np.all(np.isfinite(z), axis=0)
        k = np.argmax(np.where(np.isfinite(z), z, -np.inf), axis=0)
        zk = np.take_along_axis(z, k[None], 0)[0]
        return k, zk, finite & (k >= c0 - 1) & (k <= c0 + 1)

    base = nc_smooth(d, base_sigma)
    c0 = search
    z = stack(base, search, step)
    _, _, ok = peaks(z, c0)
    off, curved = _parabola(z[c0 - 1], z[c0], z[c0 + 1])
    v = base + step * off
    keep = np.isfinite(d) & ok & curved & (v >= d_min) & (v <= d_max)
    out = np.where(keep, v, np.nan)
    oconf = np.where(keep, cf, 0.0)
    filled = 0
    for sigma, min_score in fills:
        # A pixel off its plane is no fill target, but its plane value stays in the warp base
        # its neighbours' windows sample (as the kernel; a NaN base there counted as 0).
        planar = np.ones(out.shape, bool)
        if fill_plane:
            base, resid = nc_plane(out, sigma)
            if np.isfinite(fill_max_residual):
                planar = resid < fill_max_residual
        else:
            base = nc_smooth(out, sigma)
        z = stack(base, fill_search, fill_step)
        k, zk, ok = peaks(z, fill_search)
        ok &= (k >= 1) & (k <= 2 * fill_search - 1)  # a vertex needs both neighbours
        kc = np.clip(k, 1, 2 * fill_search - 1)
        za, zb, zc = (np.take_along_axis(z, j[None], 0)[0] for j in (kc - 1, kc, kc + 1))
        off, curved = _parabola(za, zb, zc)
        v = base + fill_step * (kc - fill_search + off)
        new = ~np.isfinite(out) & ok & (zk >= min_score) & curved & (v >= d_min) & (v <= d_max)
        new &= planar
        out = np.where(new, v, out)
        oconf = np.where(new, fill_confidence, oconf)
        filled += int(new.sum())
    return out, oconf, filled
