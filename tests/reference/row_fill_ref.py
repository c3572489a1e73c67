"""Plain NumPy reference of the row fill kernel (``rust/core/src/fill.rs``).

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
