"""Hopfield-network channel (algorithms.md C with the C.10 changes), a thin wrapper of Rust.

The kernel lives in ``rust/core/src/matching/hopfield``: Moravec interest points (squared
differences, 3x3 non-maximum suppression, 0.1 % of the maximum), right candidates as 7x7 ZNCC
peaks along the epipolar row (or the right image's interest points), a sparse binary Hopfield
network over the candidate pairs (compatibility in the 40x40 window growing with distance,
uniqueness on both sides, similarity input) with asynchronous seeded sweeps until a sweep
without a flip, a fallback to the best candidate where the network drops a point for a weak
reason, C.5 disambiguation, the C.10 depth-edge test with the side rescue of half-window
failures, and parabola sub-pixel refinement.

:func:`best_match` is the same pipeline without the network (the best ZNCC candidate of every
point): the reference the network is measured against.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from stereovision import _core
from stereovision._validate import (
    _plain_option,
    _shown,
    as_gray_float,
    check_pair,
    float_sized,
    int_in_range,
    luma_weights,
    read_numbers,
    real_number,
    refuse_not_numbers,
    refuse_unknown,
    refuse_unreachable_range,
    u8_pair,
)
from stereovision.matches import Matches

__all__ = [
    "DEFAULTS",
    "InterestPoints",
    "best_match",
    "hopfield_candidates",
    "hopfield_match",
    "interest_points",
    "moravec",
]

#: Default parameters (mirror ``HopfieldParams::default`` in Rust; algorithms.md C.3 + C.10).
DEFAULTS: dict[str, Any] = {
    "rel_threshold": 1e-3,  # interest threshold, fraction of max(M) (C.10: 0.1 %)
    "nms_half": 1,  # 3x3 non-maximum suppression (C.10)
    "tile": 64,  # threshold relative to the max of each 64x64 tile (spread; 0 = whole image)
    "floor_rel": 1e-4,  # ... but never below 0.01 % of the image's max (flat areas stay empty)
    "candidates": "row",  # "row": ZNCC peaks along the row (C.10); "points": right interest points
    "dy_window": 2,  # epipolar band for "points" (px, C.3)
    "s_min": 0.8,  # minimum candidate ZNCC (the real gate, C.10); a flat window never passes
    "k_cand": 8,  # candidates per left point (C.3)
    "A": 3.0,  # compatibility weight (C.10)
    "B": 1.5,  # uniqueness inhibition (C.3)
    "D": 1.0,  # similarity weight (C.3)
    "theta": 0.6,  # input offset (C.10)
    "nbr_half": 20,  # compatibility window half-size: the paper's 40x40 (px)
    "compat_theta": 2.0,  # disparity difference where compatibility crosses 0 (px, C.3)
    "compat_slope": 2.0,  # steepness of the compatibility sigmoid (1/px, C.3)
    "compat_grad": 0.05,  # crossing grows by this per px of point distance (slanted surfaces)
    "s_init": 0.8,  # neurons with ZNCC >= s_init start on (C.4) ...
    "init_best": True,  # ... only each point's best one (uniqueness holds from the start)
    "max_sweeps": 100,  # bound on asynchronous sweeps
    "seed": 0,  # update-order seed
    "tau_y": 1.0,  # disambiguation tolerance (px, C.5)
    "edge_test": True,  # C.10 depth-edge test
    "edge_tol": 1,  # half-window disparities agree within +-1 px (C.10)
    "edge_margin": 0.0,  # half-window ZNCC slack vs its best (0 = C.10's literal test)
    "edge_penalty": 0.5,  # input penalty of edge-test failures in the network (0 = test after)
    "centre_tol": 0.05,  # centre grey-level difference (C.10)
    "rescue_min": 3,  # side rescue: >= 3 accepted matches on a failing half's side, all agreeing
    "rescue_med": 0.75,  # ... and their median within 0.75 px of the match (0 rescue_min = off)
    "fallback": True,  # final selection: weakly dropped points keep their best candidate ...
    "fallback_alt_support": 2.0,  # ... if an active alternative has support below this
    "fallback_min_support": 0.5,  # ... or (no active alternative) it has support >= this
    "fallback_group": True,  # ... or >= min_agree such unsupported single-candidate points agree
    "min_agree": 8,  # agreeing neighbour matches in the 40x40 window (C.10)
    "agree_tol": 1,  # neighbours agree within +-1 px
    "agree_share": 0.8,  # sparse areas: this share of the (< 8) neighbour matches agrees ...
    "min_agree_sparse": 2,  # ... with at least 2 agreeing (0 share = C.10's rule only)
    "subpixel": True,  # parabola refinement
}


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity (== raised)
class InterestPoints:
    """Moravec interest points of one image.

    Attributes
    ----------
    xy : numpy.ndarray
        ``(N, 2)`` float32 ``(x, y)`` pixel positions, raster order.
    values : numpy.ndarray
        ``(N,)`` float32 interest values ``M`` (sums of squared grey-level differences).
    response : numpy.ndarray
        ``(H, W)`` float32 interest map ``M`` (0 within 3 px of the border).
    """

    xy: npt.NDArray[np.float32]
    values: npt.NDArray[np.float32]
    response: npt.NDArray[np.float32]

    def __len__(self) -> int:
        return int(self.xy.shape[0])

    def __repr__(self) -> str:
        # A summary: the dataclass repr printed every point and value (9 kB for a 150x100 image)
        shape = np.shape(self.response)
        size = f"{shape[1]}x{shape[0]}" if len(shape) == 2 else f"a map of shape {shape}"
        return f"InterestPoints({len(self)} points in {size})"


def interest_points(
    image: npt.ArrayLike,
    *,
    rel_threshold: float = 1e-3,
    nms_half: int = 1,
    tile: int = 64,
    floor_rel: float = 1e-4,
) -> InterestPoints:
    """Moravec interest points (algorithms.md C.1 with the squares, C.10 densities).

    ``M(x, y) = min(S_h, S_v, S_d, S_a)``, each ``S`` the 5x5 window sum of squared differences
    of adjacent pixels in one direction; kept where ``M`` is a local maximum of its
    ``(2 nms_half + 1)^2`` neighbourhood (ties go to the earlier pixel in raster order), ``M > 0``
    and ``M >= max(rel_threshold * max_tile(M), floor_rel * max(M))`` where ``max_tile`` is the
    largest ``M`` of the ``tile x tile`` block holding the pixel.

    Parameters
    ----------
    image : array_like
        ``(H, W)`` grey or ``(H, W, 3)`` BGR image, uint8, uint16 or float in ``[0, 1]``.
    rel_threshold : float
        Threshold as a fraction of the largest interest value, in ``[0, 1]``.
    nms_half : int
        Half-size of the non-maximum suppression neighbourhood (1 to 2**31 - 1).
    tile : int
        Block size (px) of the relative threshold (0 = the whole image; at most 2**31 - 1).
    floor_rel : float
        Lowest threshold, as a fraction of the image's largest interest value, in ``[0, 1]``.

    Returns
    -------
    InterestPoints

    Raises
    ------
    ValueError
        Bad image (shape, dtype, empty, NaN) or parameters out of range.
    """
    img = as_gray_float(image, "image")
    fractions: list[float] = []
    for name, v in (("rel_threshold", rel_threshold), ("floor_rel", floor_rel)):
        # as hopfield_match reads them: a size-1 array, a Fraction or a Decimal is its number
        # (np.array([0.001]) was "must lie in [0, 1], got array([0.001])")
        value = _plain_option(v)
        # a string or None reached float(): its message named no parameter
        number = real_number(float_sized(value, name))  # True was 1.0, 0 ns was 0.0
        if not (number and 0.0 <= float(value) <= 1.0):
            raise ValueError(f"{name} must lie in [0, 1], got {_shown(v)}")
        fractions.append(float(value))
    # Sizes beyond the image act as the image: the cap keeps them within the kernel's integers.
    nms = int_in_range(nms_half, "nms_half", 1, 2**31 - 1)
    tiles = int_in_range(tile, "tile", 0, 2**31 - 1)
    resp, xy, vals = _core.hopfield_interest(img, fractions[0], nms, tiles, fractions[1])
    return InterestPoints(xy=xy.astype(np.float32), values=vals, response=resp)


def moravec(image: npt.ArrayLike) -> npt.NDArray[np.float32]:
    """The Moravec interest map ``M`` of :func:`interest_points`.

    Parameters
    ----------
    image : array_like
        ``(H, W)`` grey or ``(H, W, 3)`` BGR image, uint8, uint16 or float in ``[0, 1]``.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` float32, ``min(S_h, S_v, S_d, S_a)`` at every pixel.
    """
    return interest_points(image).response


def _params(max_disparity: float, min_disparity: float, params: dict[str, Any]) -> dict[str, Any]:
    refuse_unknown(
        "Hopfield parameter", params, DEFAULTS, "stereovision.matching.hopfield.DEFAULTS"
    )
    for name, v in (("max_disparity", max_disparity), ("min_disparity", min_disparity)):
        # real_number: 3 ns was a range of 3 px
        finite = not isinstance(v, (float, np.floating)) or math.isfinite(v)  # 10**400 is
        if not real_number(v) or not finite or v < 0:
            raise ValueError(f"{name} must be a non-negative number of pixels, got {_shown(v)}")
    refuse_not_numbers(params, DEFAULTS)  # the kernel read True as 1 (A=True), 3 ns as 3
    params = read_numbers(params, DEFAULTS)  # k_cand=8.0, A=np.array([3.0]): their numbers
    # The kernel clips the range to the image; the clip here keeps it within its integers (2**70
    # was the binding's "OverflowError: int too big to convert").
    big = 2**31 - 1
    # a NumPy scalar as its Python number: min() cast 2**31 - 1 to a float16 range bound
    # (NumPy's "overflow encountered in cast"); the same whole bounds
    lo_v, hi_v = (
        v.item() if isinstance(v, np.generic) else v for v in (min_disparity, max_disparity)
    )
    lo, hi = math.floor(min(lo_v, big)), math.ceil(min(hi_v, big))
    # the range as given, not as rounded and clipped: min_disparity 32.5 over a max_disparity of 32
    # (lo 32 <= hi 32) gave no match without a word, and 1e300 was shown as its clip 2147483647
    if max_disparity < min_disparity:
        raise ValueError(
            f"max_disparity ({_shown(max_disparity)}) must be >= min_disparity "
            f"({_shown(min_disparity)})"
        )
    return {**DEFAULTS, **params, "min_disparity": lo, "max_disparity": hi}


def _run(
    method: str,
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    max_disparity: float,
    min_disparity: float,
    params: dict[str, Any],
) -> Matches:
    pair = u8_pair(left, right)
    if pair is None:
        gl, gr = check_pair(left, right)
        kw = _params(max_disparity, min_disparity, params)
        refuse_unreachable_range(min_disparity, max_disparity, gl.shape[1])
        kw["method"] = method
        m, trace, stats = _core.hopfield_match(gl, gr, kw)
        shape = gl.shape
    else:
        # 8-bit input (camera frames): the grey conversion runs in the kernel's call, with the
        # same values as check_pair's (no float32 intermediates).
        kw = _params(max_disparity, min_disparity, params)
        refuse_unreachable_range(min_disparity, max_disparity, pair[0].shape[1])
        kw["method"] = method
        m, trace, stats = _core.hopfield_match_u8(pair[0], pair[1], luma_weights(), kw)
        shape = pair[0].shape
    return Matches(
        xl=m[:, 0],
        yl=m[:, 1],
        xr=m[:, 2],
        yr=m[:, 3],
        score=m[:, 4],
        image_shape=(shape[0], shape[1]),
        energy_trace=trace,
        stats=dict(stats),
    )


def hopfield_match(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0,
    **params: Any,
) -> Matches:
    """Match interest points of a rectified pair with the Hopfield network.

    Parameters
    ----------
    left, right : array_like
        Rectified pair, ``(H, W)`` grey or ``(H, W, 3)`` BGR, uint8, uint16 or float in
        ``[0, 1]``, same shape.
    max_disparity : float
        Largest disparity searched (px). The network searches whole pixels: a fractional value
        searches up to its ceiling (:func:`stereovision.match` then drops the matches above it). A
        range past the image's width is searched to the image's edge, without the error
        :func:`stereovision.match` raises (see :mod:`stereovision.matching`).
    min_disparity : float, optional
        Smallest disparity searched (px, default 0; a fractional value: from its floor).
    **params
        Overrides of :data:`DEFAULTS` (each documented there): ``rel_threshold``, ``nms_half``,
        ``tile`` (px), ``floor_rel``,
        ``candidates`` (``"row"`` or ``"points"``), ``dy_window`` (px), ``s_min``, ``k_cand``,
        ``A``, ``B``, ``D``, ``theta``, ``nbr_half`` (px), ``compat_theta`` (px),
        ``compat_slope`` (1/px), ``compat_grad`` (px per px), ``s_init``, ``init_best``,
        ``max_sweeps``, ``seed``, ``tau_y`` (px), ``edge_test``, ``edge_tol`` (px),
        ``edge_margin`` (ZNCC), ``edge_penalty``,
        ``centre_tol`` (window-mean-free grey levels in [0, 1]), ``rescue_min``,
        ``rescue_med`` (px), ``fallback``, ``fallback_alt_support``,
        ``fallback_min_support``, ``fallback_group``, ``min_agree``, ``agree_tol`` (px),
        ``agree_share``, ``min_agree_sparse``, ``subpixel``.

    Returns
    -------
    Matches
        With ``energy_trace`` (initial energy, then one value per sweep) and ``stats``
        (``n_points``, ``n_neurons``, ``n_weights``, ``sweeps``, ``converged``, ``n_selected``).

    Raises
    ------
    ValueError
        Bad images (shape, dtype, empty, NaN, mismatched sizes), an unknown parameter, a value
        out of range, or a ``min_disparity`` not below the image width (as
        :func:`stereovision.match`: no pixel has a match that far).
    MemoryError
        When an image-sized buffer of the kernel cannot be allocated (the message names it and
        its size); the process is not aborted.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> left = rng.random((60, 80), dtype=np.float32)
    >>> right = np.roll(left, -5, axis=1)
    >>> m = hopfield_match(left, right, max_disparity=16, min_agree=0)
    >>> bool(np.all(np.abs((m.xl - m.xr) - 5) < 0.5)) and len(m) > 100
    True
    """
    return _run("hopfield", left, right, max_disparity, min_disparity, params)


def best_match(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0,
    **params: Any,
) -> Matches:
    """The reference without the network: best ZNCC candidate per point, same points and filters.

    The network parameters (``A``, ``B``, ``D``, ``theta``, ...) are ignored.

    Parameters
    ----------
    left, right : array_like
        Rectified pair, as :func:`hopfield_match`'s.
    max_disparity : float
        Largest disparity searched (px; a fractional value: up to its ceiling).
    min_disparity : float, optional
        Smallest disparity searched (px, default 0).
    **params
        Overrides of :data:`DEFAULTS`, as :func:`hopfield_match`'s.

    Returns
    -------
    Matches
        As :func:`hopfield_match`'s, with an empty ``energy_trace``.

    Raises
    ------
    ValueError
        As :func:`hopfield_match`.
    """
    return _run("best", left, right, max_disparity, min_disparity, params)


def hopfield_candidates(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0,
    **params: Any,
) -> npt.NDArray[np.float32]:
    """The candidate neurons the network starts from (for parity tests).

    Parameters
    ----------
    left, right : array_like
        Rectified pair, as :func:`hopfield_match`'s.
    max_disparity : float
        Largest disparity searched (px; a fractional value: up to its ceiling).
    min_disparity : float, optional
        Smallest disparity searched (px, default 0).
    **params
        Overrides of :data:`DEFAULTS`, as :func:`hopfield_match`'s.

    Returns
    -------
    numpy.ndarray
        ``(M, 6)`` float32, one row per candidate: ``[point, xl, yl, xr, yr, zncc]``.

    Raises
    ------
    ValueError
        As :func:`hopfield_match` (a ``min_disparity`` not below the image width included).
    """
    gl, gr = check_pair(left, right)
    kw = _params(max_disparity, min_disparity, params)
    refuse_unreachable_range(min_disparity, max_disparity, gl.shape[1])
    return _core.hopfield_candidates(gl, gr, kw)
