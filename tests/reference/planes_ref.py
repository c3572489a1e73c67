"""Plain NumPy/Python reference of the segment and plane kernels (``rust/core/src/segment.rs``).

``graph_segments``: Felzenszwalb-Huttenlocher on the 4-connected grid, edges sorted by (float32
colour distance, edge index), edge ``2 p`` to the right of pixel ``p`` and ``2 p + 1`` below it;
labels numbered in raster order. ``plane_fill``: per segment, least squares in coordinates
centred on the measured pixels' mean, re-fitted twice on the pixels within
``max(1, 2 * median residual)``; the holes take the plane when the last median residual is at
most ``max_residual`` and the value lies in ``[lo, hi]``. (NumPy's ``lstsq`` solves what the
kernel's 3x3 normal equations solve, in another order: values agree to float rounding.)
``fill_planes``: the passes and the two cuts of each, with the kernels given.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt


def graph_segments(image: npt.ArrayLike, k: float, min_size: int) -> np.ndarray:
    img = np.asarray(image, dtype=np.float32)
    h, w, c = img.shape
    n = h * w
    flat = img.reshape(n, c)
    p = np.arange(n)
    edges = []  # (weight, edge index, p, q)
    for e_off, q_off, ok in ((0, 1, (p % w) + 1 < w), (1, w, (p // w) + 1 < h)):
        ps = p[ok]
        d = flat[ps] - flat[ps + q_off]
        wgt = np.sqrt((d * d).sum(axis=1, dtype=np.float32)).astype(np.float32)
        edges += zip(
            wgt.tolist(), (2 * ps + e_off).tolist(), ps.tolist(), (ps + q_off).tolist(), strict=True
        )
    edges.sort(key=lambda t: (np.float32(t[0]), t[1]))
    parent = list(range(n))
    size = [1] * n
    thresh = [np.float32(k)] * n

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def join(a: int, b: int) -> int:
        r, s = (b, a) if size[b] > size[a] else (a, b)
        parent[s] = r
        size[r] += size[s]
        return r

    for wgt, _, pp, qq in edges:
        a, b = find(pp), find(qq)
        wf = np.float32(wgt)
        if a != b and wf <= thresh[a] and wf <= thresh[b]:
            r = join(a, b)
            thresh[r] = np.float32(wf + np.float32(k) / np.float32(size[r]))
    for _, _, pp, qq in edges:
        a, b = find(pp), find(qq)
        if a != b and (size[a] < min_size or size[b] < min_size):
            join(a, b)
    roots = np.array([find(i) for i in range(n)])
    _, first, inv = np.unique(roots, return_index=True, return_inverse=True)
    rank = np.empty(len(first), np.int64)
    rank[np.argsort(first)] = np.arange(len(first))
    return rank[inv].reshape(h, w).astype(np.uint32)


def plane_fill(
    disp: npt.ArrayLike,
    labels: npt.ArrayLike,
    min_pixels: int,
    max_residual: float,
    lo: float,
    hi: float,
) -> np.ndarray:
    d = np.asarray(disp, dtype=np.float32)
    lab = np.asarray(labels)
    out = d.copy()
    ys, xs = np.mgrid[0 : d.shape[0], 0 : d.shape[1]]
    for s in np.unique(lab):
        seg = lab == s
        meas = seg & np.isfinite(d)
        holes = seg & ~np.isfinite(d)
        if not holes.any() or meas.sum() < max(min_pixels, 3):
            continue
        x, y, v = xs[meas].astype(float), ys[meas].astype(float), d[meas].astype(float)
        cx, cy = x.mean(), y.mean()
        a = np.stack([x - cx, y - cy, np.ones_like(x)], axis=1)
        keep = np.ones(len(v), bool)
        ok = True
        for _ in range(3):
            m = a[keep].T @ a[keep]
            scale = m.diagonal().max()
            if abs(np.linalg.det(m)) <= 1e-9 * scale**3:
                ok = False
                break
            coef = np.linalg.solve(m, a[keep].T @ v[keep])
            res = np.abs(a @ coef - v).astype(np.float32)
            keep = res < max(1.0, 2.0 * _median(res))
        if not ok or _median(res) > max_residual:
            continue
        val = (coef[0] * (xs[holes] - cx) + coef[1] * (ys[holes] - cy) + coef[2]).astype(np.float32)
        inside = (val >= lo) & (val <= hi)
        hy, hx = np.nonzero(holes)
        out[hy[inside], hx[inside]] = val[inside]
    return out


def _median(r: np.ndarray) -> float:
    """The kernel's median: the element at index n // 2 of the sorted values (the upper one)."""
    return float(np.sort(r)[len(r) // 2])


def fill_planes(
    disp: npt.ArrayLike,
    image_u8: np.ndarray,
    passes: tuple[tuple[int, int], ...],
    max_residual: float,
    regions: Callable[[np.ndarray, int, int], np.ndarray],
    fill: Callable[[np.ndarray, np.ndarray, int, float, float, float], np.ndarray],
) -> np.ndarray:
    """The passes of ``planes.fill_planes`` on the blurred ``(H, W, C)`` uint8 image, with the
    region and plane kernels given (``regions(image, step, offset)`` -> labels,
    ``fill(disp, labels, min_pixels, max_residual, lo, hi)`` -> filled copy): per pass two cuts
    half a step apart, the mean where both fill."""
    d = np.asarray(disp, np.float32).copy()
    for step, min_pixels in passes:
        ok = np.isfinite(d)
        if not ok.any() or ok.all():
            continue
        lo, hi = float(d[ok].min()), float(d[ok].max())
        a, b = (
            fill(d, regions(image_u8, step, off), min_pixels, max_residual, lo, hi)
            for off in (0, step // 2)
        )
        out = np.where(np.isfinite(a), a, b)
        both = ~ok & np.isfinite(a) & np.isfinite(b)
        out[both] = np.float32(0.5) * (a[both] + b[both])
        d = out.astype(np.float32)
    return d
