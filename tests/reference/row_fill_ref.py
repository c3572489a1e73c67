"""Plain NumPy reference of the row fill and side fill kernels (``rust/core/src/fill.rs``).

evaluation.md's rule: along each row a hole (non-finite) takes the smaller of the nearest valid
disparity to its left and to its right; one side only: that one; none: NaN.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt


def row_fill(disp: npt.ArrayLike) -> np.ndarray:
    d = np.asarray(disp, dtype=np.float32)
    h, w = d.shape
    if d.size == 0:
        return d.copy()
    valid = np.isfinite(d)
    cols = np.broadcast_to(np.arange(w), (h, w))
    # Index of the nearest valid pixel at or to the left (-1: none) and at or to the right (w).
    left_idx = np.maximum.accumulate(np.where(valid, cols, -1), axis=1)
    right_idx = np.minimum.accumulate(np.where(valid, cols, w)[:, ::-1], axis=1)[:, ::-1]
    rows = np.arange(h)[:, None]
    left_val = np.where(left_idx >= 0, d[rows, np.clip(left_idx, 0, w - 1)], np.nan)
    right_val = np.where(right_idx < w, d[rows, np.clip(right_idx, 0, w - 1)], np.nan)
    filled = np.fmin(left_val, right_val).astype(np.float32)  # fmin ignores a missing side
    return np.where(valid, d, filled).astype(np.float32)


def side_fill(disp: npt.ArrayLike, lab: npt.ArrayLike, tau: float) -> np.ndarray:
    """The colour side rule: a hole run between a nearer left and a farther right valid value
    takes, per pixel, the left value where its colour is closer to the left neighbour's by more
    than ``tau`` (Euclidean), else the right value; every other hole stays."""
    d = np.array(disp, dtype=np.float32)
    c = np.asarray(lab, dtype=np.float32)
    h, w = d.shape
    out = d.copy()
    for y in range(h):
        valid = np.isfinite(d[y])
        x = 0
        while x < w:
            if valid[x]:
                x += 1
                continue
            a = x
            while x < w and not valid[x]:
                x += 1
            if a == 0 or x == w or not d[y, a - 1] > d[y, x]:
                continue
            run = c[y, a:x]
            dl = np.sqrt(((run - c[y, a - 1]) ** 2).sum(axis=1))
            dr = np.sqrt(((run - c[y, x]) ** 2).sum(axis=1))
            out[y, a:x] = np.where(dl + np.float32(tau) < dr, d[y, a - 1], d[y, x])
    return out
