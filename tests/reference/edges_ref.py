"""Plain NumPy reference of the fattened-edge kernel (``rust/core/src/edges.rs``).

Along each row (and each column), a jump of more than ``jump`` between neighbours of the
row-filled map looks ``radius`` pixels either side for the strongest step of the guide image
(the first of equal ones); if it is ``ratio`` times the step at the jump and lies on the
background side, the pixels from the jump up to it are marked.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from tests.reference.row_fill_ref import row_fill


def fattened(
    d: npt.NDArray[np.float32],
    guide: npt.NDArray[np.float32],
    radius: int,
    ratio: float,
    jump: float,
) -> npt.NDArray[np.bool_]:
    rows = _fattened_rows(d, guide, radius, ratio, jump)
    return rows | _fattened_rows(d.T, guide.T, radius, ratio, jump).T


def _fattened_rows(
    d: npt.NDArray[np.float32],
    guide: npt.NDArray[np.float32],
    radius: int,
    ratio: float,
    jump: float,
) -> npt.NDArray[np.bool_]:
    h, w = d.shape
    if w < 3:
        return np.zeros((h, w), bool)
    # step[y, x]: the intensity step between x - 1 and x (0 at x = 0).
    step = np.zeros((h, w), np.float32)
    step[:, 1:] = np.abs(np.diff(guide.astype(np.float32), axis=1))
    f = row_fill(d)
    with np.errstate(invalid="ignore"):
        ys, js = np.nonzero(np.abs(np.diff(f, axis=1)) > np.float32(jump))
    js = js + 1  # the jump lies between js - 1 and js
    xs = np.clip(js[:, None] + np.arange(-radius, radius + 1)[None, :], 1, w - 1)
    e = xs[np.arange(len(js)), np.argmax(step[ys[:, None], xs], axis=1)]
    strong = step[ys, e] >= np.float32(ratio) * step[ys, js]
    fg_right = f[ys, js] > f[ys, js - 1]
    # Foreground on the right carried leftwards: [j, e) with e > j; on the left: [e, j), e < j.
    lo = np.where(fg_right, js, e)
    hi = np.where(fg_right, e, js)
    keep = strong & (hi > lo)
    marks = np.zeros(h * w + 1, np.int32)
    np.add.at(marks, ys[keep] * w + lo[keep], 1)
    np.add.at(marks, ys[keep] * w + hi[keep], -1)
    return (np.cumsum(marks[:-1]) > 0).reshape(h, w)
