"""Gabor phase-disparity channel (algorithms.md A.5 with the A.9 fixes), a thin wrapper of Rust.

The kernel lives in ``rust/core/src/matching/gabor``: a multi-scale quadrature Gabor bank
(0 and +-60 degrees, zero-DC kernels; the 0 degree channel alone at full resolution),
coarse-to-fine phase-difference disparity with position-shifted right responses, local
frequency, amplitude / stability confidence, normalised-convolution smoothing, a 5x5 median per
Newton step, a +-3 px position-shift re-search per level, a left-right check and speckle
removal. Pixels that are not confident are ``NaN``.
"""

from __future__ import annotations

import decimal
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from stereovision import _core
from stereovision._validate import (
    NOT_NUMBERS,
    _shown,
    check_index_range,
    check_unit_range,
    disparity_range,
    float_sized,
    real_number,
    refuse_unknown,
    refuse_unreachable_range,
    renamed_keyword,
    whole_value,
)

__all__ = ["DEFAULTS", "GaborResult", "gabor_disparity", "gabor_responses"]

#: Default parameters of :func:`gabor_disparity` (mirrors ``GaborParams::default`` in Rust,
#: whose comments say how each was chosen).
DEFAULTS: dict[str, object] = {
    "freq": 0.25,  # carrier frequency at every pyramid level (cycles/px)
    # orientations of the frequency vector from the x-axis (degrees, each in (-90, 90), <= 8)
    "orientations_deg": (0.0, 60.0, -60.0),
    "bandwidth_oct": 1.5,  # radial bandwidth (octaves): sets the envelope's sigma
    "aspect": 1.0,  # envelope aspect ratio sigma_x / sigma_y
    "n_levels": None,  # pyramid depth; None = automatic (algorithms.md A.3)
    "iters_per_level": 1,  # Newton steps per level above full resolution (<= 20)
    "amp_rel_thresh": 0.02,  # amplitude threshold, fraction of the channel's 95th percentile
    "stability_tau": 1.25,  # Fleet-Jepson stability threshold (units of 1 / sigma_x)
    "smooth_sigma": None,  # normalised-convolution smoothing (px); None = the envelope's sigma
    "conf_min": 0.15,  # smoothed confidence a pixel needs to be updated and reported (0..1)
    # position-shift re-search at each level below the top (px at that level, <= 16)
    "research_radius": 3,
    "search_pool_radius": 0,  # half-size of the box pooling the search energy (px, <= 16)
    "lr_check": True,  # left-right consistency check
    "lr_tol": 1.5,  # ... its tolerance (px)
    # the check's right-reference run stops this many levels above full resolution (<= 4)
    "lr_coarse_levels": 1,
    "iters_finest": 1,  # Newton steps at full resolution (<= 20)
    "research_finest": True,  # the re-search at full resolution too
    "orientations_finest": 1,  # orientations (the first of orientations_deg, >= 1) at the ...
    "fine_levels": 1,  # ... this many finest levels
    "lr_light": False,  # a light right-reference run (<= 3 orientations, one step, no re-search)
    "speckle_size": 100,  # speckle removal: regions of fewer pixels are dropped (0 = off) ...
    "speckle_range": 1.0,  # ... neighbours within this many px are one region
}


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity (== raised)
class GaborResult:
    """Output of :func:`gabor_disparity`.

    Attributes
    ----------
    disparity : numpy.ndarray
        ``(H, W)`` float32, ``x_left - x_right`` in pixels at left-image pixels; ``NaN`` where
        the channel has no confident estimate.
    confidence : numpy.ndarray
        ``(H, W)`` float32 in ``[0, 1]``; ``0`` where ``disparity`` is ``NaN``.
    """

    disparity: npt.NDArray[np.float32]
    confidence: npt.NDArray[np.float32]

    def __repr__(self) -> str:
        # A summary, as Matches and DepthResult give: the dataclass repr printed both maps'
        # values (1.2 kB for a 150x100 pair, 2 kB of fuse_pair's channel outputs)
        d = np.asarray(self.disparity)
        if d.ndim != 2:
            return f"GaborResult(disparity of shape {d.shape})"
        h, w = d.shape
        ok = d[np.isfinite(d)]
        if not ok.size:
            return f"GaborResult({w}x{h}; no disparity)"
        lo, hi, share = float(ok.min()), float(ok.max()), 100 * ok.size / d.size
        return f"GaborResult({w}x{h}; disparity {lo:.2f}-{hi:.2f} px on {share:.1f} % of pixels)"


#: Widest search range ``max_disparity - min_disparity`` (px) of the kernel.
MAX_RANGE = 8192
#: Most Newton steps per level (``iters_per_level``, ``iters_finest``) the kernel takes.
_MAX_ITERS = 20

# Parameters the kernel takes as counts (usize): a negative or fractional value is a ValueError
# naming the key here, not an OverflowError from the binding.
_COUNT_KEYS = (
    "n_levels",
    "iters_per_level",
    "research_radius",
    "search_pool_radius",
    "lr_coarse_levels",
    "iters_finest",
    "orientations_finest",
    "fine_levels",
    "speckle_size",
)


def _as_grey(img: object, name: str) -> npt.NDArray[np.float32]:
    arr = np.asarray(img)
    if arr.ndim != 2:
        raise ValueError(f"{name} must be a 2-D (H, W) grey image, got shape {arr.shape}")
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise ValueError(f"{name} is empty: shape {arr.shape}")
    if not np.issubdtype(arr.dtype, np.floating):
        raise ValueError(f"{name} must be float32 grey levels in [0, 1], got dtype {arr.dtype}")
    check_index_range(arr.shape, name)  # before the copy: a broadcast image may not fit in memory
    out = np.ascontiguousarray(arr, dtype=np.float32)
    check_unit_range(out, name)
    return out


def gabor_disparity(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0.0,
    **params: object,
) -> GaborResult:
    """Dense Gabor phase disparity of a rectified grey pair.

    Parameters
    ----------
    left, right : array_like
        Rectified grey images, ``(H, W)`` float32 in ``[0, 1]``, same shape.
    max_disparity : float
        Largest disparity searched, in pixels (> ``min_disparity``). A range past the image's width
        is searched to the image's edge, without the error :func:`stereovision.match` raises (see
        :mod:`stereovision.matching`).
    min_disparity : float, optional
        Smallest disparity searched, in pixels (default 0).
    **params
        Overrides of :data:`DEFAULTS` (each documented there): ``freq`` (cycles/px),
        ``orientations_deg`` (degrees), ``bandwidth_oct`` (octaves), ``aspect`` (sigma_x /
        sigma_y), ``n_levels`` (``None`` = automatic), ``iters_per_level``, ``amp_rel_thresh``
        (fraction of the 95th percentile), ``stability_tau`` (1/sigma_x units),
        ``smooth_sigma`` (px, ``None`` = the envelope's sigma), ``conf_min`` (0..1),
        ``research_radius`` (px), ``search_pool_radius`` (px), ``lr_check`` (bool), ``lr_tol``
        (px), ``lr_coarse_levels``, ``iters_finest``, ``research_finest`` (bool),
        ``orientations_finest``, ``fine_levels``, ``lr_light`` (bool), ``speckle_size``
        (pixels, 0 = off), ``speckle_range`` (px).

    Returns
    -------
    GaborResult
        ``disparity`` ``(H, W)`` float32 (``NaN`` = no estimate) and ``confidence`` ``(H, W)``
        float32 in ``[0, 1]``.

    Raises
    ------
    ValueError
        If an image is not 2-D, empty, not floating point, non-finite or has values outside
        ``[0, 1]``, the shapes differ, a parameter is unknown, no number (a string, None, a
        bool) or out of range, or the range is one no pixel can match in (``min_disparity``
        not below the image width, or ``max_disparity`` not above minus it; as
        :func:`stereovision.match`).
    TypeError
        If a switch (``lr_check``, ``research_finest``, ``lr_light``) is not True or False.
    MemoryError
        When an image-sized buffer of the kernel cannot be allocated (the message names it and
        its size); the process is not aborted.
    """
    refuse_unknown("Gabor parameter", params, DEFAULTS, "stereovision.matching.gabor.DEFAULTS")
    lft = _as_grey(left, "left")
    rgt = _as_grey(right, "right")
    if lft.shape != rgt.shape:
        raise ValueError(f"left {lft.shape} and right {rgt.shape} images differ in shape")
    lo, hi = disparity_range(min_disparity, max_disparity)
    refuse_unreachable_range(lo, hi, lft.shape[1])
    # the kernel's limits, in the caller's names (they were its own: "invalid parameter `d_max`:
    # must be finite, got inf" for 1e300, float32's inf)
    if hi - lo > MAX_RANGE:
        raise ValueError(
            f"max_disparity - min_disparity: the Gabor search range is at most {MAX_RANGE} px, "
            f"got {max_disparity!r} - {min_disparity!r}"
        )
    for name, v in (("min_disparity", lo), ("max_disparity", hi)):
        if abs(v) > float(np.finfo(np.float32).max):
            raise ValueError(f"{name}: {v!r} is beyond float32's range")
    kw: dict[str, Any] = {**DEFAULTS, **params}
    for name, default in DEFAULTS.items():
        if (isinstance(default, float) or default is None) and name not in _COUNT_KEYS:
            value: object = kw[name]
            if isinstance(value, np.ndarray) and value.size == 1 and value.dtype.kind in "iuf":
                # a value read from an array: its number (np.array([0.3]) was NumPy's "only
                # 0-dimensional arrays can be converted", naming no parameter)
                value = kw[name] = value.reshape(())[()]
            # a string or None (smooth_sigma's None is its default) was the binding's TypeError
            # "must be real number, not str", naming no parameter; True was a value of 1. A
            # Decimal (no numbers.Real) is a number the binding reads, as it did before.
            if not (value is None and default is None) and (
                isinstance(value, NOT_NUMBERS)  # True was 1, 3 ns the binding's TypeError
                or not isinstance(value, (numbers.Real, decimal.Decimal))
            ):
                raise ValueError(f"{name}: expected a number, got {value!r}")
            float_sized(value, name)  # 10**400: the binding's OverflowError
        # the switches: 5 was the binding's TypeError "'int' object is not an instance of 'bool'"
        if isinstance(default, bool):
            if not isinstance(kw[name], (bool, np.bool_)):
                raise TypeError(f"{name}: expected True or False, got {kw[name]!r}")
            kw[name] = bool(kw[name])
    for name in _COUNT_KEYS:
        v = kw[name]
        if v is None and name == "n_levels":
            continue
        # the library's one rule of a count (whole_value, as fuse's min_agree): 3.0 or
        # Fraction(3) was refused here and taken there, 3 ns was the binding's TypeError
        whole = whole_value(v)
        if whole is None or not 0 <= whole < 2**31:
            # _shown: 10**5000's repr was Python's "Exceeds the limit (4300 digits)", no name
            raise ValueError(f"{name} must be a non-negative integer, got {_shown(v)}")
        kw[name] = whole
    # Older kernels checked both radii in one test and named research_radius for either.
    if kw["search_pool_radius"] > 16:
        raise ValueError(
            f"search_pool_radius must be at most 16 px, got {kw['search_pool_radius']!r}"
        )
    # The kernel checks both step counts in one test and names iters_per_level for either:
    # iters_finest=21 was "invalid parameter `iters_per_level`: iterations must be <= 20".
    for name in ("iters_per_level", "iters_finest"):
        if kw[name] > _MAX_ITERS:
            raise ValueError(f"{name} must be at most {_MAX_ITERS}, got {kw[name]!r}")
    orient = kw["orientations_deg"]
    # a string or a None in the sequence reached float(): its message named no parameter
    if (
        isinstance(orient, str)
        or not isinstance(orient, (Sequence, np.ndarray))
        # a 0-d array (one number, as 0.0 itself is refused) was NumPy's bare TypeError
        # "iteration over a 0-d array", and a 2-D one's rows are no degrees
        or (isinstance(orient, np.ndarray) and orient.ndim != 1)
        or not all(real_number(t) for t in orient)
    ):
        raise ValueError(f"orientations_deg must be a sequence of degrees, got {orient!r}")
    kw["orientations_deg"] = [float(float_sized(t, "orientations_deg")) for t in orient]
    # lo, hi: the checked floats (float() of np.array([16.0]) was NumPy's bare TypeError)
    disp, conf = _core.gabor_disparity(lft, rgt, lo, hi, **kw)
    return GaborResult(disparity=disp, confidence=conf)


@renamed_keyword("img", "image")
def gabor_responses(
    image: npt.ArrayLike,
    freq: float = 0.25,
    theta_deg: float = 0.0,
    bandwidth_oct: float = 1.5,
    aspect: float = 1.0,
) -> npt.NDArray[np.complex64]:
    """Complex response of one zero-DC Gabor channel (debugging and parity tests).

    Parameters
    ----------
    image : array_like
        ``(H, W)`` float32 grey image.
        The keyword ``img=``, its former name, still works, with a DeprecationWarning.
    freq : float
        Centre frequency (cycles/px).
    theta_deg : float
        Orientation of the frequency vector from the x-axis (degrees).
    bandwidth_oct : float
        Radial bandwidth (octaves).
    aspect : float
        Envelope aspect ratio ``sigma_x / sigma_y``.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` complex64 response ``y = h * image`` (true convolution, reflect-101 borders).

    Raises
    ------
    ValueError
        A bad image (as :func:`gabor_disparity`'s), or a parameter that is no number (a string,
        None, a bool) or out of the kernel's range, named.
    """
    values: list[Any] = []
    for name, v in (
        ("freq", freq),
        ("theta_deg", theta_deg),
        ("bandwidth_oct", bandwidth_oct),
        ("aspect", aspect),
    ):
        if isinstance(v, np.ndarray) and v.size == 1 and v.dtype.kind in "iuf":
            # its number, as gabor_disparity reads freq: np.array([0.25]) was the binding's
            # bare TypeError "only 0-dimensional arrays can be converted"
            v = v.reshape(())[()]
        # as gabor_disparity's: a string or None was the binding's TypeError "must be real
        # number, not str", naming no parameter, and True ran as 1 (aspect=True as 1.0)
        if isinstance(v, NOT_NUMBERS) or not isinstance(v, (numbers.Real, decimal.Decimal)):
            raise ValueError(f"{name}: expected a number, got {v!r}")
        values.append(float_sized(v, name))  # 10**400: the binding's bare OverflowError
    img = _as_grey(image, "image")
    # the kernel names its own argument: "img: image contains non-finite values ..." for the
    # parameter renamed image (as gabor_disparity's kernel says it of "left")
    bad = int(np.count_nonzero(~np.isfinite(img)))
    if bad:
        raise ValueError(f"image: image contains non-finite values (NaN or inf) at {bad} pixels")
    re, im = _core.gabor_responses(img, *values)
    return (re + 1j * im).astype(np.complex64)
