"""Multi-Channel Graph Matching channel (algorithms.md B + B.8), a thin wrapper of Rust.

The kernel lives in ``rust/core/src/matching/mcgm``: per LoG channel (sigma 4, 2, 1 px, coarse to
fine; sigma 4 on the 2x-decimated image, used as a prior only) zero crossings one pixel thick
with sub-pixel x, hysteresis curve tracking into labelled segments, an R-table per segment and
Generalized-Hough voting over the disparity window (narrowed by the coarser channels), a k-NN
graph of segment centroids and tolerant association-graph matching with the Hopfield network of
module C, then per-pixel disparities along the matched curves (sub-pixel at both ends) and B.8's
occlusion filters (both-sides check, discontinuity filter).

:func:`curves` gives the intermediate outputs of one image (LoG, zero crossings, labelled
curves, segments, R-tables); :func:`mcgm_match` with ``debug=True`` adds the candidate pairs,
the network state and the segment graph of every channel. :func:`zncc_reference` is the plain
reference the channel is measured against (ZNCC winner along the row on the same zero-crossing
pixels, left-right check, the same filters).
"""

from __future__ import annotations

import itertools
import math
import reprlib
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from stereovision import _core
from stereovision._validate import (
    NOT_NUMBERS,
    _plain_real,
    _shown,
    as_gray_float,
    check_pair,
    float_sized,
    read_numbers,
    real_number,
    refuse_not_numbers,
    refuse_unknown,
    refuse_unreachable_range,
    xy_points,
)
from stereovision.matches import Matches

__all__ = [
    "DEFAULTS",
    "ChannelCurves",
    "curves",
    "edge_filters",
    "log_filter",
    "mcgm_match",
    "zncc_reference",
]

#: Default parameters (mirror ``McgmParams::default`` in Rust; algorithms.md B.2 + B.8).
DEFAULTS: dict[str, Any] = {
    "sigmas": [4.0, 2.0, 1.0],  # LoG channels, coarse to fine (px, B.2)
    # channels this coarse run on the 2x-decimated image, prior only (one must be finer)
    "half_res_sigma": 4.0,
    "high_quantile": 0.5,  # t_high = this quantile of crossing strengths (B.8: 50th percentile)
    "low_ratio": 0.4,  # t_low = 0.4 t_high (B.2)
    "max_turn_deg": 60.0,  # normal change allowed between curve pixels (B.8: 60, paper 18)
    "min_len": 8,  # shortest segment (px) ...
    "min_len_sigmas": 4.0,  # ... or 4 sigma if longer (B.2)
    "seg_theta_tol_deg": 30.0,  # mean-orientation difference of candidate segments (B.2)
    "dy_band": 1,  # epipolar band (rows; B.8: t_y in {-1, 0, 1} for 1.5 px)
    "n_theta_bins": 36,  # R-table orientation bins over [0, 2 pi) (B.2)
    "vote_bin_tol": 2,  # +- bins when indexing the R-table (B.2: 1; 2 measured, docs/mcgm.md)
    "ght_min_score": 0.4,  # GHT peak / max(|A|, |A'|), 0 to 1 (B.8: 0.5; docs/mcgm.md)
    "k_cand": 6,  # candidates per left segment (B.2)
    "knn": 6,  # neighbours in the segment graph (B.4.9)
    "r_graph": 60.0,  # longest graph edge (px, B.2)
    "A": 1.0,  # compatibility weight (B.2 / C.4)
    "B": 1.5,  # uniqueness inhibition
    "D": 1.0,  # GHT-score weight
    "theta": 0.3,  # input offset
    "dg_0": 0.5,  # disparity-gradient limit of the compatibility (B.2)
    "dg_slope": 10.0,  # steepness of the compatibility sigmoid (B.2)
    "max_sweeps": 100,  # bound on network sweeps
    "seed": 0,  # update-order seed
    # no per-pixel disparity where the tangent is this near horizontal (degrees, 0 to 90)
    "horiz_skip_deg": 20.0,
    "prior_radius_sigmas": 4.0,  # coarse prior spread radius, in coarse sigmas (B.4.11)
    "prior_width_sigmas": 2.0 * float(np.sqrt(2.0)),  # window around the prior, fine sigmas
    "fill_radius": 1,  # coarser matches only where no finer one within +- 1 column
    "sides": True,  # B.8 both-sides check
    "sides_mad": 0.06,  # mean absolute grey difference per half-window (B.8: 0.04)
    "sides_width": 6,  # half-window columns (B.8: 4 x 7; docs/mcgm.md)
    "sides_height": 7,  # half-window rows
    "sides_gap": 1,  # columns between the edge and each half-window (B.8)
    "sides_best": True,  # ... and no other disparity (> 1 px away) fits a half-window better
    "sides_best_margin": 0.0,  # ... by more than this MAD (0: the literal test, as C.10)
    "sides_mean_free": True,  # half-window means removed first (exposure offsets, ETH3D)
    "disc": True,  # B.8 discontinuity filter
    "disc_dx": 6,  # +- columns (B.8)
    "disc_dy": 2,  # +- rows (B.8)
    "disc_tol": 1.0,  # largest disparity difference to a neighbour (px, B.8)
    "zncc_check": True,  # area check: 7x7 ZNCC re-measure around the disparity agrees ...
    "zncc_tol": 0.5,  # ... within this many px (an interior peak of round(d) +- 2)
}


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity (== raised)
class ChannelCurves:
    """Intermediate outputs of one LoG channel of one image.

    Attributes
    ----------
    sigma : float
        LoG sigma in the channel's own pixels (half the nominal sigma when ``scale == 2``).
    scale : int
        1 = full resolution, 2 = the 2x2-mean-decimated image (pixel ``(i, j)`` centred at
        full-resolution ``(2i + 0.5, 2j + 0.5)``).
    log : numpy.ndarray
        ``(h, w)`` float32 LoG response.
    mark : numpy.ndarray
        ``(h, w)`` uint8 zero-crossing bits: 1 = horizontal scan, 2 = vertical scan.
    xsub, strength, theta : numpy.ndarray
        ``(h, w)`` float32 sub-pixel x of the crossing (NaN elsewhere), ``|grad L|`` and the
        normal direction in ``[0, 2 pi)`` at marked pixels.
    labels : numpy.ndarray
        ``(h, w)`` int32 segment id per pixel, -1 = none.
    seg_offsets : numpy.ndarray
        ``(n + 1,)`` int64: segment ``k`` owns ``seg_pixels[seg_offsets[k]:seg_offsets[k+1]]``.
    seg_pixels : numpy.ndarray
        ``(N, 2)`` int32 ``(x, y)`` ordered along each curve.
    centroids : numpy.ndarray
        ``(n, 2)`` float32 segment centroids.
    mean_theta : numpy.ndarray
        ``(n,)`` float32 circular mean normal direction.
    rtable_offsets : numpy.ndarray
        ``(n, K + 1)`` int32 bin offsets of each segment's R-table (into its own entries).
    rtable_vecs : numpy.ndarray
        ``(N, 2)`` float32 R-table vectors ``c - p``, per segment, grouped by bin.
    t_high, t_low : float
        Hysteresis thresholds used.
    """

    sigma: float
    scale: int
    log: npt.NDArray[np.float32]
    mark: npt.NDArray[np.uint8]
    xsub: npt.NDArray[np.float32]
    strength: npt.NDArray[np.float32]
    theta: npt.NDArray[np.float32]
    labels: npt.NDArray[np.int32]
    seg_offsets: npt.NDArray[np.int64]
    seg_pixels: npt.NDArray[np.int32]
    centroids: npt.NDArray[np.float32]
    mean_theta: npt.NDArray[np.float32]
    rtable_offsets: npt.NDArray[np.int32]
    rtable_vecs: npt.NDArray[np.float32]
    t_high: float
    t_low: float

    @property
    def n_segments(self) -> int:
        """Number of segments."""
        return int(self.centroids.shape[0])

    def __repr__(self) -> str:
        # A summary: the dataclass repr printed its twelve arrays (curves() of a 150x100 image:
        # 3 channels, about 11 kB each)
        shape = np.shape(self.log)
        size = f"{shape[1]}x{shape[0]}" if len(shape) == 2 else f"a map of shape {shape}"
        return (
            f"ChannelCurves(sigma {self.sigma:g}, scale {self.scale}; {self.n_segments} "
            f"segments in {size}; t_high {self.t_high:.3g}, t_low {self.t_low:.3g})"
        )

    def segment(self, k: int) -> npt.NDArray[np.int32]:
        """The pixels of one segment.

        Parameters
        ----------
        k : int
            Segment index, ``0 <= k < n_segments``; a negative ``k`` counts from the end as in
            a Python list (``-1`` is the last segment).

        Returns
        -------
        numpy.ndarray
            ``(n_k, 2)`` int32 ``(x, y)`` pixels of segment ``k``, in curve order (a view of
            ``seg_pixels``).

        Raises
        ------
        TypeError
            If ``k`` is not an integer.
        IndexError
            If ``k`` is outside ``-n_segments <= k < n_segments``.
        """
        if not isinstance(k, (int, np.integer)) or isinstance(k, NOT_NUMBERS):
            raise TypeError(f"k: expected an integer segment index, got {type(k).__name__} {k!r}")
        n = self.n_segments
        if not -n <= k < n:
            raise IndexError(
                f"k: segment {int(k)} out of range; this channel has {n} segment"
                f"{'' if n == 1 else 's'} (0 to {n - 1}, or -{n} to -1 from the end)"
                if n
                else f"k: segment {int(k)} out of range; this channel has no segment"
            )
        i = int(k) % n
        return self.seg_pixels[self.seg_offsets[i] : self.seg_offsets[i + 1]]


def _sigmas(sig: object) -> list[float]:
    """``sigmas`` (one number or a 1-D sequence of them) as floats, after a ``ValueError`` naming
    it for anything else: NumPy's conversion read ``True`` and ``"2"`` as sigmas 1 and 2, None
    as NaN ("got NaN"), and a nested list or a set was a TypeError naming nothing; and for a
    list not coarse to fine (each sigma smaller than the one before), the kernel's order."""
    if isinstance(sig, np.ndarray) and sig.ndim <= 1:
        items = list(sig.reshape(-1))
    elif isinstance(sig, (list, tuple)):
        items = list(sig)
    else:
        items = [sig]
    # a Fraction or a Decimal (a config read with parse_float=Decimal) as its float, as
    # half_res_sigma and curves' sigma read it: it was "expected a number of pixels"
    items = [_plain_real(s) for s in items]
    for s in items:
        if not real_number(s):
            raise ValueError(
                f"sigmas: expected a number of pixels or a list of them, got {reprlib.repr(sig)}"
            )
        float_sized(s, "sigmas")
    out = [float(s) for s in items]
    # The kernel takes the list as coarse to fine: each channel's matches narrow the next one's
    # search, the last is the finest and fills first. [1, 2, 4] ran sigma 4 as the finest (at
    # half resolution: a prior only, none of its matches kept) and sigma 1 as a coarse prior
    # of sigma 2, without a word (tsukuba, max_disparity 32: 4847 matches, 1.5 % off by over
    # 1 px, against [4, 2, 1]'s 4877 and 1.3 %).
    if any(a <= b for a, b in itertools.pairwise(out)):  # NaN: the kernel names it
        raise ValueError(
            f"sigmas: expected the channels coarse to fine, each sigma smaller than the one "
            f"before (as the default {DEFAULTS['sigmas']}), got {reprlib.repr(sig)}"
        )
    return out


def _params(max_disparity: float, min_disparity: float, params: dict[str, Any]) -> dict[str, Any]:
    refuse_unknown("MCGM parameter", params, DEFAULTS, "stereovision.matching.mcgm.DEFAULTS")
    refuse_not_numbers(params, DEFAULTS)  # the kernel read True as 1 (A=True), 3 ns as 3
    params = read_numbers(params, DEFAULTS)  # knn=6.0, r_graph=np.array([60.0]): their numbers
    for name, v in (("max_disparity", max_disparity), ("min_disparity", min_disparity)):
        if (
            not real_number(v)  # a bool, 3 ns
            or (isinstance(v, (float, np.floating)) and not math.isfinite(v))
            or v < 0
        ):
            raise ValueError(f"{name} must be a non-negative number of pixels, got {_shown(v)}")
    # The kernel clips the range to the image; the clip here keeps it within its integers
    # (without a float of an int beyond a float's range: 2**1100 was an OverflowError).
    big = 2**31 - 1
    # a NumPy scalar as its Python number: min() cast 2**31 - 1 to a float16 range bound
    # (NumPy's "overflow encountered in cast"); the same whole bounds
    lo_v, hi_v = (
        v.item() if isinstance(v, np.generic) else v for v in (min_disparity, max_disparity)
    )
    lo = math.floor(min(lo_v, big))
    hi = math.ceil(min(hi_v, big))
    # the range as given, not as rounded and clipped: min_disparity 32.5 over a max_disparity of 32
    # (lo 32 <= hi 32) gave no match without a word, and 1e300 was shown as its clip 2147483647
    if max_disparity < min_disparity:
        raise ValueError(
            f"max_disparity ({_shown(max_disparity)}) must be >= min_disparity "
            f"({_shown(min_disparity)})"
        )
    kw = {**DEFAULTS, **params, "min_disparity": lo, "max_disparity": hi}
    kw["sigmas"] = _sigmas(kw["sigmas"])
    return kw


def _refuse_priors_only(kw: dict[str, Any]) -> None:
    """A ``ValueError`` naming ``sigmas`` and ``half_res_sigma`` when every channel is at or
    above ``half_res_sigma``: each then runs at half resolution as a prior only, and the run
    gave 0 matches without a word (cones crop: ``sigmas=[4.0]`` 0 matches of 14 pairs, where
    ``[3.9]`` gave 136; ``half_res_sigma=1.0`` 0 instead of 1430). A half_res_sigma that is
    no number >= 0, or no channel at all, is left to the kernel, which names it."""
    # a Fraction or a Decimal (a config read with parse_float=Decimal) as its float: the kernel
    # reads it so, and half_res_sigma=Fraction(1) still gave 0 matches without a word
    half = _plain_real(kw["half_res_sigma"])
    if not real_number(half) or not 0 <= half < math.inf:
        return
    # no channel is the kernel's "needs at least one channel", not "every channel ([])"
    if kw["sigmas"] and all(s >= half for s in kw["sigmas"]):
        raise ValueError(
            f"sigmas: every channel ({reprlib.repr(kw['sigmas'])}) is at or above "
            f"half_res_sigma ({half}), so each runs at half resolution as a prior only and "
            "none gives a match: add a finer sigma or raise half_res_sigma"
        )


def log_filter(image: npt.ArrayLike, sigma: float) -> npt.NDArray[np.float32]:
    """Separable zero-mean scale-normalised LoG ``sigma^2 lap(G)`` (B.3), ``(H, W)`` float32.

    Parameters
    ----------
    image : array_like
        ``(H, W)`` grey or ``(H, W, 3)`` BGR image, uint8, uint16 or float in ``[0, 1]``.
    sigma : float
        Gaussian standard deviation (px), in ``[0.3, 64]``.

    Returns
    -------
    numpy.ndarray
        The response (reflect-101 borders).

    Raises
    ------
    ValueError
        Bad image or sigma.
    """
    if isinstance(sigma, np.ndarray) and sigma.size == 1 and sigma.dtype.kind != "O":
        # its number, as mcgm_match reads sigmas: float() of np.array([2.0]) was NumPy's bare
        # TypeError "only 0-dimensional arrays can be converted"; any other as its scalar,
        # refused below: float() read np.array(True) as sigma 1, and a 0-d array of "2", b"2"
        # or 2 ns since the epoch as 2
        sigma = sigma.reshape(())[()]
    no_number = isinstance(sigma, np.ndarray) and sigma.dtype.kind == "O"  # a 0-d "2": 2
    if no_number or isinstance(sigma, (*NOT_NUMBERS, str, bytes, np.datetime64)):
        # float() read True as sigma 1, "2" and b"2" as 2, and 2 ns as 2 (mcgm_match's sigmas
        # refuse them all); a Fraction or a Decimal is still its number
        raise ValueError(f"sigma: expected a number of pixels, got {reprlib.repr(sigma)}")
    try:
        # 10**400 was float()'s bare OverflowError
        value = float(float_sized(sigma, "sigma"))
    except (TypeError, ValueError) as e:
        if str(e).startswith("sigma: "):
            raise
        # np.array([2.0, 1.0]), None, "abc": NumPy's or float()'s bare words, naming no sigma
        raise ValueError(f"sigma: expected a number of pixels, got {reprlib.repr(sigma)}") from None
    return _core.mcgm_log(as_gray_float(image, "image"), value)


def curves(image: npt.ArrayLike, **params: Any) -> list[ChannelCurves]:
    """Zero crossings, labelled curves, segments and R-tables of every channel of one image.

    Parameters
    ----------
    image : array_like
        ``(H, W)`` grey or ``(H, W, 3)`` BGR image, uint8, uint16 or float in ``[0, 1]``.
    **params
        Overrides of :data:`DEFAULTS` (``sigmas``, ``half_res_sigma``, the tracking and R-table
        parameters).

    Returns
    -------
    list of ChannelCurves
        One per sigma, coarse to fine.

    Raises
    ------
    ValueError
        Bad image, an unknown parameter or a value out of range.
    """
    img = as_gray_float(image, "image")
    out = []
    for d in _core.mcgm_curves(img, _params(0, 0, params)):
        out.append(ChannelCurves(**d))
    return out


def mcgm_match(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0,
    debug: bool = False,
    **params: Any,
) -> Matches:
    """Match zero-crossing curves of a rectified pair (the MCGM channel).

    Parameters
    ----------
    left, right : array_like
        Rectified pair, ``(H, W)`` grey or ``(H, W, 3)`` BGR, uint8, uint16 or float in
        ``[0, 1]``, same shape.
    max_disparity : float
        Largest disparity searched (px). A range past the image's width is searched to the
        image's edge, without the error :func:`stereovision.match` raises (see
        :mod:`stereovision.matching`).
    min_disparity : float, optional
        Smallest disparity searched (px, default 0).
    debug : bool, optional
        Also return, in ``stats["channels"]``, one dict per channel with the candidate pairs
        (``candidates``: ``(M, 5)`` float32 ``[left_id, right_id, score, tx, ty]``), the network
        state, the chosen pairs, the left segment graph (``edges``), the disparity windows and
        the channel's own per-pixel matches ``(P, 6)``.
    **params
        Overrides of :data:`DEFAULTS` (each documented there).

    Returns
    -------
    Matches
        Per-pixel correspondences: ``xl`` / ``xr`` the sub-pixel crossings, ``yl == yr`` the row,
        ``score`` the GHT score of the matched segment pair; ``stats`` has the counters
        (``n_candidates``, ``n_pairs``, ``n_combined``, ``n_sides``, ``n_disc``, ``n_matches``) and
        ``channel`` (``(N,)`` int index into ``sigmas`` of each match).

    Raises
    ------
    ValueError
        Bad images (shape, dtype, empty, NaN, mismatched sizes), an unknown parameter, a value
        out of range, ``sigmas`` not coarse to fine or all at or above ``half_res_sigma``
        (priors only: no channel could give a match), a ``debug`` that is not True or False, or
        a ``min_disparity`` not below the image width (as :func:`stereovision.match`: no pixel
        has a match that far).
    MemoryError
        When an image-sized buffer of the kernel cannot be allocated (the message names it and
        its size); the process is not aborted.

    Examples
    --------
    >>> import numpy as np
    >>> yy, xx = np.mgrid[0:80, 0:120].astype(np.float32)
    >>> def scene(s):
    ...     return (0.5 + 0.4 * np.sin((xx + s) / 5.0) * np.cos(yy / 7.0)).astype(np.float32)
    >>> m = mcgm_match(scene(0.0), scene(3.4), max_disparity=8)
    >>> bool(abs(np.median(m.xl - m.xr) - 3.4) < 0.05) and len(m) > 100
    True
    """
    # a switch, as the kernel's (subpixel="no" is refused by name): "no" and 0.5 were taken
    # as True and 0 as False
    if not isinstance(debug, (bool, np.bool_)):
        raise ValueError(f"debug: expected True or False, got {debug!r}")
    gl, gr = check_pair(left, right)
    kw = _params(max_disparity, min_disparity, params)
    _refuse_priors_only(kw)
    refuse_unreachable_range(min_disparity, max_disparity, gl.shape[1])
    m, stats, chans = _core.mcgm_match(gl, gr, kw)
    st: dict[str, Any] = dict(stats)
    st["channel"] = m[:, 5].astype(np.int64)
    if debug:
        st["channels"] = [dict(c) for c in chans]
    return Matches(
        xl=m[:, 0],
        yl=m[:, 1],
        xr=m[:, 2],
        yr=m[:, 3],
        score=m[:, 4],
        image_shape=(gl.shape[0], gl.shape[1]),
        stats=st,
    )


def edge_filters(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    matches: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0,
    **params: Any,
) -> npt.NDArray[np.bool_]:
    """Occlusion filters on any matches: B.8's both-sides check and discontinuity filter, then
    the area check (``zncc_check``).

    Parameters
    ----------
    left, right : array_like
        The rectified pair the matches come from.
    matches : array_like
        ``(N, 4)`` ``[xl, yl, xr, yr]``.
    max_disparity, min_disparity : float
        The searched range (the ``sides_best`` test looks for better disparities in it).
    **params
        ``sides``, ``sides_mad``, ``sides_width``, ``sides_height``, ``sides_gap``,
        ``sides_best``, ``sides_best_margin``, ``disc``, ``disc_dx``, ``disc_dy``, ``disc_tol``,
        ``zncc_check``, ``zncc_tol`` (:data:`DEFAULTS`).

    Returns
    -------
    numpy.ndarray
        ``(N,)`` bool, True = kept.

    Notes
    -----
    A match whose windows do not fit in the images (within a few pixels of the border) is not
    kept: the filters cannot check it.

    Raises
    ------
    ValueError
        Bad images, a matches array not of shape ``(N, 4)``, an unknown parameter, a
        ``min_disparity`` not below the image width (as :func:`stereovision.match`), or a match
        that is no match of this pair: a NaN or infinite coordinate, or a point outside the
        images (beyond the outer pixels' edges, ``-0.5 .. W - 0.5`` and ``-0.5 .. H - 0.5``).
        The filters used to keep such rows when switched off and drop them otherwise.
    """
    gl, gr = check_pair(left, right)
    arr = np.ascontiguousarray(matches, dtype=np.float32)
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise ValueError(f"matches: expected shape (N, 4), got {arr.shape}")
    h, w = gl.shape
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(
            f"matches: {int(bad.sum())} of {len(arr)} rows have a NaN or infinite coordinate "
            f"(row {i}: {_row(arr[i])})"
        )
    x, y = arr[:, [0, 2]], arr[:, [1, 3]]
    out = ((x < -0.5) | (x > w - 0.5) | (y < -0.5) | (y > h - 0.5)).any(axis=1)
    if out.any():
        i = int(np.argmax(out))
        raise ValueError(
            f"matches: {int(out.sum())} of {len(arr)} rows lie outside the {w}x{h} images "
            f"(row {i}: {_row(arr[i])})"
        )
    kw = _params(max_disparity, min_disparity, params)
    refuse_unreachable_range(min_disparity, max_disparity, w)
    return _core.mcgm_filter(gl, gr, arr, kw)


def _pixels(pixels: npt.ArrayLike) -> npt.NDArray[np.int64]:
    """:func:`zncc_reference`'s ``pixels`` as ``(N, 2)`` int64 ``(x, y)``, after a ``ValueError``
    naming them for another layout or a position that is no whole pixel: the reshape to
    ``(-1, 2)`` paired a ``(2, N)`` array's (``np.nonzero(mask)``'s rows, or x over y) values
    into other pixels, and the cast truncated 10.7 to 10, each without a word."""
    raw = np.asarray(pixels)
    if raw.size == 0:
        return np.zeros((0, 2), np.int64)
    if raw.dtype.kind not in "iuf":
        raise ValueError(f"pixels: expected whole (x, y) pixel positions, got dtype {raw.dtype}")
    # one (x, y) pixel as before; any other shape not (N, 2): xy_points names it
    pts = xy_points(raw.reshape(1, 2) if raw.shape == (2,) else raw, "pixels")
    whole = np.isfinite(pts) & (pts == np.round(pts))
    if not whole.all():
        i = int(np.argmin(whole.all(axis=1)))
        raise ValueError(
            f"pixels: expected whole (x, y) pixel positions, got ({pts[i, 0]:g}, {pts[i, 1]:g}) "
            f"at row {i}"
        )
    out: npt.NDArray[np.int64] = raw.reshape(-1, 2).astype(np.int64)
    return out


def _row(m: npt.NDArray[np.float32]) -> str:
    """One ``[xl, yl, xr, yr]`` row for a message."""
    return "(xl, yl, xr, yr) = (" + ", ".join(f"{float(v):g}" for v in m) + ")"


#: ZNCC window half-size of the reference (7x7, as the Hopfield channel's candidates).
ZNCC_RADIUS = 3
#: Left-right check tolerance of the reference (px).
ZNCC_LR_TOL = 1
#: Windows flatter than this grey-level std have no defined ZNCC.
ZNCC_MIN_STD = 1e-3


def _box(a: npt.NDArray[np.float64], r: int) -> npt.NDArray[np.float64]:
    """``(2r+1)^2`` window sums at every pixel (zero-padded integral image)."""
    c = np.pad(a, ((r + 1, r), (r + 1, r))).cumsum(0).cumsum(1)
    k = 2 * r + 1
    return c[k:, k:] - c[:-k, k:] - c[k:, :-k] + c[:-k, :-k]


def zncc_reference(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0,
    pixels: npt.ArrayLike | None = None,
    **params: Any,
) -> Matches:
    """Plain reference: best 7x7 ZNCC along the row at the channel's zero-crossing pixels.

    At every left pixel on a tracked full-resolution curve (the pixels the channel can match,
    or ``pixels``), the disparity with the highest ZNCC over the range, parabola sub-pixel
    refinement, a left-right check (the right pixel's best match returns within 1 px), then the
    same B.8 filters as the channel (:func:`edge_filters`).

    Parameters
    ----------
    left, right : array_like
        Rectified pair (as :func:`mcgm_match`).
    max_disparity, min_disparity : float
        Disparity range (px).
    pixels : array_like, optional
        ``(N, 2)`` integer ``(x, y)`` left pixels (whole numbers; those whose 7x7 window does
        not fit in the image are left out); default: every pixel of a full-resolution
        channel's segments, tangent at least ``horiz_skip_deg`` from horizontal.
    **params
        :data:`DEFAULTS` overrides (curves and filters).

    Returns
    -------
    Matches
        ``score`` = the ZNCC.

    Raises
    ------
    ValueError
        As :func:`mcgm_match` (a ``min_disparity`` not below the image width included), or
        ``pixels`` not of shape ``(N, 2)`` (a ``(2, N)`` array) or not whole pixel positions.
    """
    gl, gr = check_pair(left, right)
    kw = _params(max_disparity, min_disparity, params)
    h, w = gl.shape
    refuse_unreachable_range(min_disparity, max_disparity, w)
    if pixels is None:
        _refuse_priors_only(kw)  # no full-resolution channel: no pixel to match
        mask = np.zeros((h, w), dtype=bool)
        min_cos = np.sin(np.deg2rad(kw["horiz_skip_deg"]))
        for c in curves(gl, **params):
            if c.scale == 1:
                on = (c.labels >= 0) & (np.abs(np.cos(c.theta)) >= min_cos)
                mask |= on
        ys, xs = np.nonzero(mask)
    else:
        p = _pixels(pixels)
        xs, ys = p[:, 0], p[:, 1]
    # No disparity reaches past the image: keeps the (D, H, W) score volume bounded.
    lo, hi = min(kw["min_disparity"], w - 1), min(kw["max_disparity"], w - 1)
    r = ZNCC_RADIUS
    n_win = float((2 * r + 1) ** 2)
    a = gl.astype(np.float64)
    b = gr.astype(np.float64)
    ma, mb = _box(a, r) / n_win, _box(b, r) / n_win
    va = np.maximum(_box(a * a, r) / n_win - ma * ma, 0.0)
    vb = np.maximum(_box(b * b, r) / n_win - mb * mb, 0.0)
    sa, sb = np.sqrt(va), np.sqrt(vb)
    nd = hi - lo + 1
    # scores[d][y, x]: ZNCC of left (x, y) with right (x - d, y); -inf where undefined.
    vol = np.full((nd, h, w), -np.inf, dtype=np.float32)
    for k, d in enumerate(range(lo, hi + 1)):
        if d >= w:
            break
        prod = np.zeros((h, w))
        prod[:, d:] = a[:, d:] * b[:, : w - d]
        cov = np.zeros((h, w))
        cov[:, d:] = _box(prod, r)[:, d:] / n_win - ma[:, d:] * mb[:, : w - d]
        den = np.zeros((h, w))
        den[:, d:] = sa[:, d:] * sb[:, : w - d]
        ok = np.zeros((h, w), dtype=bool)
        ok[:, d:] = (sa[:, d:] > ZNCC_MIN_STD) & (sb[:, : w - d] > ZNCC_MIN_STD)
        ok[:, : d + r] = False
        # The box filter zero-pads the left window past the right border: those columns are
        # never matched forward (``inside``) but would be candidates of the left-right check.
        ok[:, w - r :] = False
        with np.errstate(invalid="ignore", divide="ignore"):
            z = np.where(ok, cov / np.where(ok, den, 1.0), -np.inf)
        vol[k] = z
    inside = (xs >= r) & (xs < w - r) & (ys >= r) & (ys < h - r)
    xs, ys = xs[inside], ys[inside]
    curve = vol[:, ys, xs]  # (nd, N)
    best = np.argmax(curve, axis=0)
    bval = curve[best, np.arange(len(xs))]
    ok = np.isfinite(bval)
    # Left-right check: the right pixel's best left match over the same range.
    xr_i = xs - (best + lo)
    ks = np.arange(nd)[:, None]
    xl_back = xr_i[None, :] + ks + lo
    valid = (xl_back >= 0) & (xl_back < w)
    back = np.where(valid, vol[ks, ys[None, :], np.clip(xl_back, 0, w - 1)], -np.inf)  # (nd, N)
    rbest = np.argmax(back, axis=0)
    ok &= np.abs(rbest - best) <= ZNCC_LR_TOL
    # Parabola sub-pixel refinement (interior disparities only).
    idx = np.arange(len(xs))
    bm = np.clip(best - 1, 0, nd - 1)
    bp = np.clip(best + 1, 0, nd - 1)
    c0, c1, c2 = curve[bm, idx], bval, curve[bp, idx]
    with np.errstate(invalid="ignore", divide="ignore"):  # -inf where the ZNCC is undefined
        den = c0 - 2.0 * c1 + c2
        interior = (best > 0) & (best < nd - 1) & np.isfinite(c0) & np.isfinite(c2) & (den < 0)
        off = np.where(
            interior, np.clip(0.5 * (c0 - c2) / np.where(interior, den, -1.0), -0.5, 0.5), 0.0
        )
    disp = (best + lo + off).astype(np.float32)
    xs, ys, disp, bval = xs[ok], ys[ok], disp[ok], bval[ok]
    xl = xs.astype(np.float32)
    yl = ys.astype(np.float32)
    xr = (xl - disp).astype(np.float32)
    arr = np.stack([xl, yl, xr, yl], axis=1)
    keep = edge_filters(
        gl,
        gr,
        arr,
        max_disparity=hi,
        min_disparity=lo,
        **{k: v for k, v in params.items() if k in _FILTER_KEYS},
    )
    return Matches(
        xl=xl[keep],
        yl=yl[keep],
        xr=xr[keep],
        yr=yl[keep],
        score=bval[keep].astype(np.float32),
        image_shape=(h, w),
        stats={"n_pixels": int(inside.sum()), "n_lr": int(ok.sum()), "n_matches": int(keep.sum())},
    )


_FILTER_KEYS = (
    "sides",
    "sides_mad",
    "sides_width",
    "sides_height",
    "sides_gap",
    "sides_best",
    "sides_best_margin",
    "sides_mean_free",
    "disc",
    "disc_dx",
    "disc_dy",
    "disc_tol",
    "zncc_check",
    "zncc_tol",
)
