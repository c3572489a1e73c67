"""NumPy reference of the semi-global matcher (rust/core/src/matching/sgm.rs), in integers.

The same maths in plain array operations: a 9x7 census transform (bit set where the neighbour is
darker than the centre, borders replicated), the Hamming distance as the matching cost, 8-path
semi-global aggregation with an intensity-adaptive P2, winner-take-all with a uniqueness test, a
parabola vertex for the sub-pixel part, and a left-right check against the right view's winners
read off the same aggregated volume. Integer arithmetic throughout, so the Rust kernel must agree
exactly. Used by the parity tests in ``tests/test_sgm.py`` and to prototype the dense completion.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

#: Census window half-sizes (x, y): 9 x 7 = 62 bits without the centre.
RX, RY = 4, 3
#: Cost where no level's right pixel is inside the image: worse than any Hamming distance.
OUTSIDE = (2 * RX + 1) * (2 * RY + 1)  # 63: one more than the 62 bits
#: A level outside the right image costs the pixel's best inside level plus this (at most OUTSIDE).
OUTSIDE_MARGIN = 5

PATHS = ((0, 1), (0, -1), (1, 0), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1))
#: ``paths=3``: left to right, right to left, top to bottom (OpenCV SGBM-3WAY's set).
PATHS_3 = ((0, 1), (0, -1), (1, 0))


def census(img: npt.ArrayLike) -> npt.NDArray[np.uint64]:
    """9x7 census: bit ``k`` (row-major over the window, centre skipped) = neighbour < centre."""
    a = np.asarray(img, np.float32)
    h, w = a.shape
    p = np.pad(a, ((RY, RY), (RX, RX)), mode="edge")
    out = np.zeros((h, w), np.uint64)
    bit = 0
    for dy in range(-RY, RY + 1):
        for dx in range(-RX, RX + 1):
            if dy == 0 and dx == 0:
                continue
            nb = p[RY + dy : RY + dy + h, RX + dx : RX + dx + w]
            out |= (nb < a).astype(np.uint64) << np.uint64(bit)
            bit += 1
    return out


def cost_volume(left: npt.ArrayLike, right: npt.ArrayLike, d_min: int, d_max: int) -> np.ndarray:
    """``C[y, x, k]`` = Hamming distance of the census codes at ``x`` and ``x - (d_min + k)``."""
    cl, cr = census(left), census(right)
    h, w = cl.shape
    n = d_max - d_min + 1
    c = np.full((h, w, n), OUTSIDE, np.int32)
    xs = np.arange(w)
    inside = np.zeros((w, n), bool)
    for k in range(n):
        xr = xs - (d_min + k)
        ok = (xr >= 0) & (xr < w)
        inside[:, k] = ok
        c[:, ok, k] = np.bitwise_count(cl[:, ok] ^ cr[:, xr[ok]]).astype(np.int32)
    # Levels outside take the best inside cost of their pixel plus a margin (nearly neutral),
    # or just the best where every inside level costs the same (a flat patch); OUTSIDE stays
    # only where no level is inside.
    best = np.where(inside[None], c, OUTSIDE).min(axis=-1, keepdims=True)
    worst = np.where(inside[None], c, 0).max(axis=-1, keepdims=True)
    out = np.where(worst == best, best, np.minimum(best + OUTSIDE_MARGIN, OUTSIDE))
    return np.where(inside[None], c, out).astype(np.int32)


def _p2_map(img: np.ndarray, dy: int, dx: int, p1: int, p2: int, gamma: float) -> np.ndarray:
    """P2 at each pixel for a step from its predecessor on the path (dy, dx)."""
    a = np.asarray(img, np.float32) * np.float32(255.0)
    h, w = a.shape
    prev = np.full_like(a, np.nan)
    ys = slice(max(dy, 0), h + min(dy, 0))
    xs = slice(max(dx, 0), w + min(dx, 0))
    yp = slice(max(-dy, 0), h + min(-dy, 0))
    xp = slice(max(-dx, 0), w + min(-dx, 0))
    prev[ys, xs] = a[yp, xp]
    step = np.abs(a - prev)
    step = np.where(np.isfinite(step), step, 0.0).astype(np.float32)
    # Integer division keeps the Rust kernel bit-exact: P2 / (1 + step / gamma), at least P1 + 1.
    q = np.floor(step / np.float32(gamma)).astype(np.int32)
    return np.maximum(p2 // (1 + q), p1 + 1).astype(np.int32)


def _step(lp: np.ndarray, c: np.ndarray, p1: int, p2: np.ndarray) -> np.ndarray:
    """One path step: ``c + min(lp, lp[k+-1] + P1, min(lp) + P2) - min(lp)`` over the last axis."""
    big = np.iinfo(np.int32).max // 4
    m = lp.min(axis=-1, keepdims=True)
    up = np.concatenate([lp[..., 1:], np.full((*lp.shape[:-1], 1), big, np.int32)], axis=-1)
    dn = np.concatenate([np.full((*lp.shape[:-1], 1), big, np.int32), lp[..., :-1]], axis=-1)
    best = np.minimum(np.minimum(lp, np.minimum(up, dn) + p1), m + p2[..., None])
    return c + best - m


def aggregate(
    c: np.ndarray, img: npt.ArrayLike, p1: int, p2: int, gamma: float, paths=PATHS
) -> np.ndarray:
    """Sum over ``paths`` of the path costs ``L_r`` (Hirschmueller 2008)."""
    h, w, _ = c.shape
    s = np.zeros_like(c)
    for dy, dx in paths:
        p2m = _p2_map(np.asarray(img), dy, dx, p1, p2, gamma)
        lr = np.empty_like(c)
        if dy == 0:
            cols = range(w) if dx > 0 else range(w - 1, -1, -1)
            first = True
            for x in cols:
                if first:
                    lr[:, x] = c[:, x]
                    first = False
                else:
                    lr[:, x] = _step(lr[:, x - dx], c[:, x], p1, p2m[:, x])
        else:
            rows = range(h) if dy > 0 else range(h - 1, -1, -1)
            first = True
            for y in rows:
                if first:
                    lr[y] = c[y]
                    first = False
                    continue
                lp = lr[y - dy]
                if dx == 0:
                    lr[y] = _step(lp, c[y], p1, p2m[y])
                    continue
                row = c[y].copy()
                xs = np.arange(w)
                have = (xs - dx >= 0) & (xs - dx < w)
                row[have] = _step(lp[xs[have] - dx], c[y][have], p1, p2m[y][have])
                lr[y] = row
        s += lr
    return s


def select(
    s: np.ndarray, d_min: int, uniqueness: int, lr_tol: int, edge_margin: int = 4
) -> np.ndarray:
    """Winner, uniqueness, left-right check, parabola vertex: float32 disparity, NaN = none.

    In the left band only the levels whose match lands in the right image (``x - d >= 0``)
    compete, and a winner with ``x - d < edge_margin`` is rejected."""
    h, w, n = s.shape
    xs = np.arange(w)
    ks = np.arange(n)
    # Levels 0..inside-1 land in the right image (at most n).
    inside = np.minimum(xs - d_min + 1, n)
    big = np.iinfo(np.uint16).max  # the Rust min over no level
    sin = np.where(ks[None, None, :] < inside[None, :, None], s.astype(np.int64), big)
    k = sin.argmin(axis=-1)
    best = np.take_along_axis(sin, k[..., None], -1)[..., 0]
    far = np.abs(ks[None, None, :] - k[..., None]) > 1
    other = np.where(far, sin, big).min(axis=-1)
    unique = 100 * other > (100 + uniqueness) * best
    # The right view's winner at xr: argmin over k of S[y, xr + d_k, k] (first minimum).
    sr = np.full((h, w, n), np.iinfo(np.int32).max, np.int64)
    for j in range(n):
        xl = xs + d_min + j
        ok = (xl >= 0) & (xl < w)
        sr[:, ok, j] = s[:, xl[ok], j]
    kr = sr.argmin(axis=-1)
    xr = xs[None, :] - (d_min + k)
    in_right = (xr >= 0) & (xr < w)
    yy = np.arange(h)[:, None].repeat(w, 1)
    kr_at = np.where(in_right, kr[yy, np.clip(xr, 0, w - 1)], -(10**6))
    band = inside < n
    # inside - 1 - k = x - d: the winner's right column.
    kept = ((inside > 0) & (xs - d_min < w))[None, :] & ~(
        band[None, :] & (inside[None, :] - 1 - k < edge_margin)
    )
    consistent = kept & in_right & (np.abs(kr_at - k) <= lr_tol)
    # Parabola vertex through S[k-1], S[k], S[k+1] (interior winners only).
    km = np.clip(k - 1, 0, n - 1)
    kp = np.clip(k + 1, 0, n - 1)
    sm = np.take_along_axis(s, km[..., None], -1)[..., 0].astype(np.float64)
    sp = np.take_along_axis(s, kp[..., None], -1)[..., 0].astype(np.float64)
    den = sm + sp - 2.0 * best
    interior = (k > 0) & (k < inside[None, :] - 1) & (den > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.where(interior, (sm - sp) / (2.0 * den), 0.0)
    d = (d_min + k + frac).astype(np.float32)
    return np.where(unique & consistent, d, np.float32(np.nan)).astype(np.float32)


def sgm_disparity(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    d_min: int,
    d_max: int,
    *,
    p1: int = 8,
    p2: int = 96,
    gamma: float = 16.0,
    uniqueness: int = 5,
    lr_tol: int = 1,
    edge_margin: int = 4,
    paths: int = 8,
) -> np.ndarray:
    """The whole matcher: census cost, 8-path (or 3-path) aggregation, selection."""
    c = cost_volume(left, right, d_min, d_max)
    s = aggregate(c, left, p1, p2, gamma, PATHS if paths == 8 else PATHS_3)
    return select(s, d_min, uniqueness, lr_tol, edge_margin)
