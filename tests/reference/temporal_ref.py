"""Plain NumPy reference of the temporal filter's per-pixel passes (``rust/core/src/temporal.rs``).

The same ``float32`` operations in the same order as the kernel, so the two agree bit for bit:
the grey difference sums the channels in order (B, G, R weights 0.114, 0.587, 0.299; alpha 0),
and the update is ``mean + (frame - mean) * (1 / n')``.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

_WEIGHTS = {1: (1.0,), 3: (0.114, 0.587, 0.299), 4: (0.114, 0.587, 0.299)}


def _channels(a: np.ndarray) -> np.ndarray:
    return a[..., None] if a.ndim == 2 else a


def grey_difference(
    frame: npt.NDArray[np.uint8], mean: npt.NDArray[np.float32]
) -> npt.NDArray[np.float32]:
    f, m = _channels(frame), _channels(mean)
    acc = np.zeros(f.shape[:2], np.float32)
    for c, w in enumerate(_WEIGHTS[f.shape[2]]):
        acc += (f[..., c].astype(np.float32) - m[..., c]) * np.float32(w)
    return acc


def running_mean(
    frame: npt.NDArray[np.uint8],
    mean: npt.NDArray[np.float32],
    count: npt.NDArray[np.uint8],
    diff: npt.NDArray[np.float32],
    ks: float,
    max_frames: int,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
    n = np.maximum(count, 1).astype(np.float32)
    one = np.float32(1.0)
    limit = np.float32(ks) * np.sqrt(one + one / n)
    keep = np.abs(diff) <= limit
    n1 = np.where(keep, np.minimum(count.astype(np.int32) + 1, max_frames), 1).astype(np.uint8)
    w = one / n1.astype(np.float32)
    f, m = _channels(frame), _channels(mean)
    new = m + (f.astype(np.float32) - m) * w[..., None]
    out = np.clip(np.floor(new + np.float32(0.5)), 0, 255).astype(np.uint8)  # saturating
    if frame.ndim == 2:
        new, out = new[..., 0], out[..., 0]
    return new.astype(np.float32), n1, out
