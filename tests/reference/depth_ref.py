"""NumPy reference of the rectified depth kernel (rust/core/src/triangulation.rs).

``Z = f B / (d + doffs)`` and ``sigma_Z = Z sigma_d / (d + doffs)`` with
``sigma_d = max(s0 + slope * clip(conf, 0, 1), s_min)`` (``s_fill`` where ``conf < 0``: a pixel
the refinement filled), in float32, NaN where the disparity is
not finite, ``d + doffs <= sigma_d`` (or ``<= 0``) or the depth is not finite; a NaN confidence
counts as 0: the same operations in the same order.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt


def depth_rectified(
    disp: npt.NDArray[np.float32],
    conf: npt.NDArray[np.float32],
    fb: float,
    doffs: float,
    s0: float,
    slope: float,
    s_min: float,
    s_fill: float,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """``(depth, sigma)`` float32 arrays of ``disp``'s shape."""
    d = np.asarray(disp, np.float32)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        denom = d + np.float32(doffs)
        z = np.float32(fb) / denom
        raw = np.asarray(conf, np.float32)
        # The kernel reads a NaN confidence as 0 (26ad946); here it made sigma_d NaN: no depth.
        c = np.clip(np.where(np.isnan(raw), np.float32(0), raw), np.float32(0), np.float32(1))
        sd = np.maximum(np.float32(s0) + np.float32(slope) * c, np.float32(s_min))
        sd = np.where(raw < 0, np.float32(s_fill), sd)
        # An infinite disparity is no depth in the kernel (4305c3b); here it was the depth 0.
        ok = np.isfinite(denom) & (denom > 0) & (denom > sd) & np.isfinite(z)
        s = z * sd / denom
    return np.where(ok, z, np.float32(np.nan)), np.where(ok, s, np.float32(np.nan))
