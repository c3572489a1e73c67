"""Triple-channel agreement: the paper's "valid members" (algorithms.md D, vote mode by default).

The dense Gabor channel (A), the graph-matching curves (B) and the Hopfield points (C) each give a
disparity at some left pixels. A pixel where a sparse channel measured something is a
*candidate*; there the available values are collected -- A at the pixel (when its confidence
passes ``a_conf_min``), each sparse channel's nearest measurement within ``r_spatial`` (D.2: a
corner almost never sits exactly on a zero-crossing pixel) -- and the largest subset whose members
agree pairwise within ``tau_dx`` / ``tau_dy`` is kept when it has at least ``min_agree`` members
(``"vote"``), or only when every channel is present and agrees (``"intersection"``, the paper's
rule with tolerances).
The fused value is the weighted mean of the agreeing subset (weights: A's confidence, 1 for the
sparse channels).

This is orchestration over the channels' outputs (NumPy, O(HW) shifts plus O(|P|) work); the
channels themselves are the Rust kernels.
"""

from __future__ import annotations

import functools
import itertools
import time
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, TypedDict

import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    _plain_option,
    _real_array,
    _shown,
    finite_number,
    float32_reach,
    real_number,
    refuse_unknown,
    whole_value,
)
from stereovision.matches import Matches

# at run time too, so that typing.get_type_hints resolves ChannelOutputs (and DepthChannels)
from stereovision.matching.gabor import GaborResult

__all__ = [
    "CHANNEL_BITS",
    "DEFAULTS",
    "DENSE_DEFAULTS",
    "MEMBER_MCGM",
    "ChannelOutputs",
    "FusionResult",
    "census_clear",
    "fill_enclosed_far",
    "fuse",
    "fuse_pair",
    "fused_dense",
    "remeasure",
]

F32 = npt.NDArray[np.float32]

#: Bit of each channel in :attr:`FusionResult.sources` (algorithms.md D.1: 1 = A, 2 = B, 4 = C).
CHANNEL_BITS: dict[str, int] = {"gabor": 1, "mcgm": 2, "hopfield": 4}

#: MCGM's settings in the vote: B.8's stricter GHT score and both-sides check (0.5; 4x7
#: half-windows, MAD 0.04), not the channel's own defaults (0.4; 6x7, 0.06). The looser ones
#: give 10-70 % more matches at precision@1 >= 96 %, which the channel's bars ask for; the
#: members need >= 99 %: with the looser MCGM their precision@1 fell on 12 of the 17 GT scenes
#: (reindeer 99.46 -> 98.53 %, TartanAir 97.53 -> 96.78 %) for a dense map no better (mean
#: bad-2.0 ratio to SGBM-3WAY + fill 0.5268 -> 0.5271). The members' both-sides check uses
#: them too.
MEMBER_MCGM: dict[str, Any] = {"ght_min_score": 0.5, "sides_mad": 0.04, "sides_width": 4}

#: algorithms.md D.3 defaults.
DEFAULTS = {
    "mode": "vote",
    "r_spatial": 1.5,  # px: a sparse value this close counts as present (3x3 at 1.5)
    "tau_dx": 1.0,  # px: two channels agree on x-disparity within this
    "tau_dy": 1.0,  # px: ... and on y-disparity
    "a_conf_min": 0.15,  # Gabor confidence needed to take part
    "min_agree": 2,  # vote mode: at least two channels must agree
}


class ChannelOutputs(TypedDict, total=False):
    """What each channel returned, :attr:`FusionResult.channel_outputs` (:func:`fuse_pair`
    fills it; which keys are there depends on its ``channels`` and options).

    Attributes
    ----------
    gabor : GaborResult
        The Gabor phase channel's map.
    gabor_remeasured : numpy.ndarray
        ``(H, W)`` float32: the Gabor map the vote used, when :func:`fuse_pair` re-measured it
        (:func:`remeasure`).
    mcgm, hopfield : Matches
        The graph-matching and Hopfield channels' matches.
    sgm : numpy.ndarray
        ``(H, W)`` float32: the census semi-global map (``dense_sgm=True``; NaN = none).
    """

    gabor: GaborResult
    gabor_remeasured: F32
    mcgm: Matches
    hopfield: Matches
    sgm: F32


@dataclass(frozen=True, eq=False)
class FusionResult:
    """The valid members of the channels' agreement.

    Attributes
    ----------
    matches : Matches
        One correspondence per valid member: ``(xl, yl)`` the left pixel (integer positions),
        ``xr = xl - dispx``, ``yr = yl - dispy``; ``score`` = the fraction of the available
        channels that agree.
    count, sources : numpy.ndarray
        ``(N,)`` uint8 per member: how many channels agree, and which (:data:`CHANNEL_BITS`).
    dispx, dispy : numpy.ndarray
        ``(H, W)`` float32 fused disparities at the members, NaN elsewhere.
    count_map, sources_map : numpy.ndarray
        ``(H, W)`` uint8 rasters of ``count`` and ``sources`` (0 off the members).
    channels : tuple of str
        The channels that took part, in bit order.
    channel_outputs : ChannelOutputs
        What each channel returned, by name (:func:`fuse_pair` fills it: ``"gabor"`` a
        :class:`~stereovision.matching.gabor.GaborResult`, the sparse ones :class:`Matches`),
        and ``"gabor_remeasured"``, the Gabor map the vote used (:func:`remeasure`), when
        :func:`fuse_pair` re-measured it; ``"sgm"`` the census map when asked for.
    """

    matches: Matches
    count: npt.NDArray[np.uint8]
    sources: npt.NDArray[np.uint8]
    dispx: F32
    dispy: F32
    count_map: npt.NDArray[np.uint8]
    sources_map: npt.NDArray[np.uint8]
    channels: tuple[str, ...]
    channel_outputs: ChannelOutputs = field(default_factory=lambda: ChannelOutputs())

    def __len__(self) -> int:
        return len(self.matches)

    def __repr__(self) -> str:
        # A summary: the dataclass repr printed six arrays and every channel's output (3.4 kB
        # for a 150x100 pair)
        h, w = self.matches.image_shape
        values, times = np.unique(np.asarray(self.count).reshape(-1), return_counts=True)
        counts = ", ".join(
            f"{k}: {n}" for k, n in zip(values.tolist(), times.tolist(), strict=True)
        )
        outputs = ", ".join(self.channel_outputs) or "none"
        return (
            f"FusionResult({len(self)} members in {w}x{h} of {', '.join(self.channels)}"
            f"{'; count ' + counts if counts else ''}; channel outputs: {outputs})"
        )


#: px: the largest ``r_spatial`` :func:`fuse` takes (12853 offsets; the default is 1.5).
MAX_R_SPATIAL = 64.0


def _radius_offsets(r: float) -> list[tuple[int, int]]:
    """Integer offsets ``(dy, dx)`` within ``r``, nearest first (ties in a fixed order)."""
    k = int(np.floor(r))
    offs = [
        (dy, dx) for dy in range(-k, k + 1) for dx in range(-k, k + 1) if dy * dy + dx * dx <= r * r
    ]
    return sorted(offs, key=lambda o: (o[0] ** 2 + o[1] ** 2, o[0], o[1]))


def _nearest_within_at(
    dx: F32, dy: F32, r: float, ys: npt.NDArray[np.intp], xs: npt.NDArray[np.intp]
) -> tuple[F32, F32]:
    """The nearest measured ``(dx, dy)`` within ``r`` px of each pixel ``(ys[k], xs[k])``.

    "Nearest" is the first offset of :func:`_radius_offsets` whose pixel is measured (finite
    ``dx``); NaN if none. Each pixel looks at its offsets nearest first and stops at the first
    measured one, so the work follows the (sparse) pixels asked for, not the whole image.
    """
    h, w = dx.shape
    out_x = np.full(len(ys), np.nan, np.float32)
    out_y = np.full(len(ys), np.nan, np.float32)
    todo = np.arange(len(ys))
    for oy, ox in _radius_offsets(r):
        if len(todo) == 0:
            break
        sy, sx = ys[todo] + oy, xs[todo] + ox
        inside = np.nonzero((sy >= 0) & (sy < h) & (sx >= 0) & (sx < w))[0]
        sy, sx = sy[inside], sx[inside]
        v = dx[sy, sx]
        hit = np.isfinite(v)
        found = todo[inside[hit]]
        out_x[found] = v[hit]
        out_y[found] = dy[sy[hit], sx[hit]]
        done = np.zeros(len(todo), bool)
        done[inside[hit]] = True
        todo = todo[~done]
    return out_x, out_y


def _check_map(a: npt.ArrayLike, name: str, shape: tuple[int, int] | None) -> F32:
    raw = _real_array(a)
    # a complex map lost its imaginary part with NumPy's warning only; text raised NumPy's
    # "could not convert string to float", naming no argument
    if raw is None:
        raise ValueError(f"{name}: expected a real (H, W) map, got dtype {np.asarray(a).dtype}")
    arr = np.asarray(raw, dtype=np.float32)
    if arr.ndim != 2:
        raise ValueError(f"{name}: expected an (H, W) map, got shape {arr.shape}")
    if shape is not None and arr.shape != shape:
        raise ValueError(f"{name}: shape {arr.shape} differs from the others' {shape}")
    return arr


def remeasure(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    disparity: npt.ArrayLike,
    confidence: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0.0,
) -> F32:
    """The Gabor map re-measured to sub-pixel precision where it measured.

    :func:`stereovision.refine.refine_disparity`'s correlation on the right image warped by the
    map gives each measured pixel a new value; a pixel the correlation drops keeps the Gabor
    value, and holes stay holes (the refinement's fill is not run: the vote and the members'
    completion decide there). On ETH3D terrace the median error falls from 0.356 to 0.135 px
    (off by more than 0.5 px: 37.2 -> 11.8 %), which the members' average and the dense map
    inherit.

    Parameters
    ----------
    left, right : array_like
        The rectified grey pair.
    disparity, confidence : array_like
        ``(H, W)`` Gabor disparity (NaN = none) and confidence.
    max_disparity, min_disparity : float
        The range the channels searched (px).

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` float32, NaN exactly where ``disparity`` is.
    """
    from stereovision.refine import _refine

    d = _check_map(disparity, "disparity", None)
    r = _refine(
        left,
        right,
        d,
        confidence,
        min_disparity=min_disparity,
        max_disparity=max_disparity,
        warn_fixed_point=False,  # a matcher's map over this range, not a caller's
        fills=(),
    )
    return np.where(np.isfinite(r.disparity), r.disparity, d).astype(np.float32)


def _fuse_options(
    mode: str,
    r_spatial: Any,
    tau_dx: Any,
    tau_dy: Any,
    a_conf_min: Any,
    min_agree: Any,
) -> tuple[str, Any, Any, Any, Any, int]:
    """Check :func:`fuse`'s options (:data:`DEFAULTS`' keys); all of them, in that order, as
    ``fuse`` uses them (:func:`_plain_option`). :func:`fuse_pair` and ``depth_map`` check them
    before the channels run (a bad one was said only after every matcher had run: 0.4 s on
    cones)."""
    if mode not in ("vote", "intersection"):
        raise ValueError(f"mode: expected 'vote' or 'intersection', got {mode!r}")
    r_spatial, tau_dx, tau_dy = (_plain_option(v) for v in (r_spatial, tau_dx, tau_dy))
    for pname, v in (("r_spatial", r_spatial), ("tau_dx", tau_dx), ("tau_dy", tau_dy)):
        if finite_number(v, pname) <= 0:
            raise ValueError(f"{pname}: expected a positive number, got {v}")
    # the search visits every offset within r (about 3.14 r^2 of them): 1e6 px, or a uint64's
    # maximum, ran for ever instead of failing
    if r_spatial > MAX_R_SPATIAL:
        raise ValueError(
            f"r_spatial: expected at most {MAX_R_SPATIAL} px (a sparse value this far is no "
            f"longer at the pixel), got {r_spatial}"
        )
    # NaN took no Gabor value without a word (every ``conf >= nan`` is False), a string or None
    # failed in NumPy's comparison naming no parameter
    a_conf_min = _plain_option(a_conf_min)
    if not 0 <= finite_number(a_conf_min, "a_conf_min") <= 1:
        raise ValueError(f"a_conf_min: expected a confidence in [0, 1], got {a_conf_min}")
    # a string, None or NaN failed in a comparison or in range(), naming no parameter; a whole
    # number given as 2.0 or a size-1 array (a value read from one) is its count
    # (whole_value, the library's one rule of a count: a bool or an np.timedelta64 -- an
    # np.integer: 2 ns was taken as 2 channels -- is none)
    agree = whole_value(min_agree)
    if agree is None:
        raise ValueError(f"min_agree: expected a whole number of channels, got {min_agree!r}")
    min_agree = agree
    if min_agree < 2:
        raise ValueError(f"min_agree: expected at least 2, got {min_agree}")
    return mode, r_spatial, tau_dx, tau_dy, a_conf_min, min_agree


def _check_agree(mode: str, min_agree: int, channels: Iterable[str]) -> None:
    """Refuse a vote no pixel can win: ``min_agree`` above the number of ``channels`` taking
    part. ``range(n, min_agree - 1, -1)`` was then empty and :func:`fuse` returned no member
    without a word (``min_agree=4`` of three channels; ``match(method="fused",
    channels=("mcgm",))`` at the default 2), and ``depth_map`` a dense map with no member."""
    names = [n for n in CHANNEL_BITS if n in set(channels)]
    if mode == "vote" and min_agree > len(names):
        raise ValueError(
            # _shown: 10**5000 (a count to whole_value) has no str, Python's error named nothing
            f"min_agree: {_shown(min_agree)} channels must agree but {len(names)} take part "
            f"({', '.join(names)}), so no pixel could be a member: give more channels, a "
            "smaller min_agree or mode='intersection'"
        )


def fuse(
    gabor: tuple[npt.ArrayLike, npt.ArrayLike] | GaborResult | None,
    sparse: Mapping[str, Matches],
    *,
    mode: str = "vote",
    r_spatial: float = 1.5,
    tau_dx: float = 1.0,
    tau_dy: float = 1.0,
    a_conf_min: float = 0.15,
    min_agree: int = 2,
) -> FusionResult:
    """Valid members of the channels' agreement (algorithms.md D.4).

    Parameters
    ----------
    gabor : (dispx, conf), GaborResult or None
        The dense channel: ``(H, W)`` float32 disparity (NaN = none) and confidence in ``[0, 1]``,
        or :func:`~stereovision.matching.gabor.gabor_disparity`'s result holding them. Its
        vertical disparity is taken as 0 (rectified pairs).
    sparse : mapping of str to Matches
        The sparse channels by name (``"mcgm"``, ``"hopfield"``), each on the same image size.
    mode : {"vote", "intersection"}
        ``"vote"``: the largest pairwise-agreeing subset with at least ``min_agree`` members
        (ties: the smaller x spread); ``"intersection"``: every channel present and agreeing.
    r_spatial : float
        A sparse channel's measurement within this distance (px, at most 64) of a candidate
        counts there.
    tau_dx, tau_dy : float
        Agreement tolerances (px) on x- and y-disparity.
    a_conf_min : float
        Minimum Gabor confidence for its value to take part.
    min_agree : int
        Vote mode: smallest agreeing subset that makes a valid member (>= 2).

    Returns
    -------
    FusionResult

    Raises
    ------
    ValueError
        No sparse channel, an unknown channel name, maps of different sizes, a bad mode, a
        non-positive tolerance, an ``r_spatial`` past ``MAX_R_SPATIAL`` (64 px), an
        ``a_conf_min`` that is not a number in ``[0, 1]`` or a
        ``min_agree`` that is not a whole number of at least 2 or, in vote mode, is more than
        the channels given.
    TypeError
        A ``gabor`` that is neither a ``(dispx, conf)`` pair nor a
        :class:`~stereovision.matching.gabor.GaborResult` (one map alone), a ``sparse`` that
        is no mapping (a list of the channels' matches), or a sparse channel that is no
        :class:`~stereovision.Matches` (its ``to_array()``).
    """
    if isinstance(gabor, GaborResult):
        # gabor_disparity's own result (FusionResult.channel_outputs["gabor"]) was Python's
        # "'GaborResult' object is not subscriptable"
        gabor = (gabor.disparity, gabor.confidence)
    elif gabor is not None:
        pair = isinstance(gabor, (tuple, list)) and len(gabor) == 2
        stacked = isinstance(gabor, np.ndarray) and gabor.ndim == 3 and len(gabor) == 2
        if not (pair or stacked):
            # the disparity map alone: its first row was said to be no (H, W) map
            got = _shown(gabor) if isinstance(gabor, np.ndarray) else type(gabor).__name__
            raise TypeError(f"gabor: expected the (dispx, conf) maps or a GaborResult, got {got}")
    if mode not in ("vote", "intersection"):
        raise ValueError(f"mode: expected 'vote' or 'intersection', got {mode!r}")
    if not isinstance(sparse, Mapping):
        # a list of Matches was "unknown sparse channel Matches(...)", naming a channel's matches
        raise TypeError(
            "sparse: expected the sparse channels by name, {'mcgm': ..., 'hopfield': ...}, "
            f"got {type(sparse).__name__}"
        )
    if not sparse:
        raise ValueError("fuse needs at least one sparse channel (mcgm or hopfield)")
    for name in sparse:
        if name not in CHANNEL_BITS or name == "gabor":
            raise ValueError(f"unknown sparse channel {name!r}: expected mcgm or hopfield")
        if not isinstance(sparse[name], Matches):
            # an (N, 4) to_array() was "'numpy.ndarray' object has no attribute 'image_shape'"
            raise TypeError(
                f"sparse[{name!r}]: expected a stereovision.Matches, got "
                f"{type(sparse[name]).__name__}"
            )
    # the checked values, not the raw ones: np.array([1.5]) passed the check and failed below
    mode, r_spatial, tau_dx, tau_dy, a_conf_min, min_agree = _fuse_options(
        mode, r_spatial, tau_dx, tau_dy, a_conf_min, min_agree
    )
    # compared with float32 offsets: 1e308 as its float32 infinity, without NumPy's warning
    tau_dx, tau_dy = float32_reach(tau_dx), float32_reach(tau_dy)
    _check_agree(mode, min_agree, [*sparse, *(["gabor"] if gabor is not None else [])])

    names: list[str] = []
    shape: tuple[int, int] | None = None
    gabor_maps: tuple[F32, F32] | None = None
    if gabor is not None:
        gx = _check_map(gabor[0], "gabor dispx", None)
        gc = _check_map(gabor[1], "gabor conf", gx.shape)
        shape = (int(gx.shape[0]), int(gx.shape[1]))
        names.append("gabor")
        gabor_maps = (gx, gc)
    order = sorted(sparse, key=CHANNEL_BITS.__getitem__)
    measured = None
    raster: list[tuple[F32, F32]] = []
    for name in order:
        m = sparse[name]
        if shape is None:
            shape = m.image_shape
        elif m.image_shape != shape:
            raise ValueError(
                f"{name}: image shape {m.image_shape} differs from the others' {shape}"
            )
        dx, dy = m.dispx, m.dispy
        here = np.isfinite(dx)
        measured = here if measured is None else measured | here
        raster.append((dx, dy))
        names.append(name)
    assert shape is not None and measured is not None

    # Candidates: the sparse channels' own pixels (D.4 step 3), in row-major order; every
    # channel's value there (a sparse channel's: its nearest measurement within r_spatial).
    yy, xx = np.nonzero(measured)
    cols_x: list[F32] = []
    cols_y: list[F32] = []
    cols_w: list[F32] = []
    if gabor_maps is not None:
        gxv, gcv = gabor_maps[0][yy, xx], gabor_maps[1][yy, xx]
        ok = np.isfinite(gxv) & (gcv >= a_conf_min)
        cols_x.append(np.where(ok, gxv, np.nan).astype(np.float32))
        cols_y.append(np.where(ok, 0.0, np.nan).astype(np.float32))
        cols_w.append(np.where(ok, gcv, 0.0).astype(np.float32))
    for dx, dy in raster:
        nx, ny = _nearest_within_at(dx, dy, r_spatial, yy, xx)
        cols_x.append(nx)
        cols_y.append(ny)
        cols_w.append(np.ones_like(nx))
    n_ch = len(names)
    vx = np.stack(cols_x)  # (n_ch, P)
    vy = np.stack(cols_y)
    vw = np.stack(cols_w)
    present = np.isfinite(vx)

    best = np.zeros(len(yy), np.int64)  # chosen subset mask (bits over channel positions)
    best_size = np.zeros(len(yy), np.int64)
    best_spread = np.full(len(yy), np.inf)
    sizes = [n_ch] if mode == "intersection" else range(n_ch, min_agree - 1, -1)
    for size in sizes:
        for subset in itertools.combinations(range(n_ch), size):
            ok = np.all(present[list(subset)], axis=0)
            for i, j in itertools.combinations(subset, 2):
                with np.errstate(invalid="ignore"):
                    ok &= (np.abs(vx[i] - vx[j]) <= tau_dx) & (np.abs(vy[i] - vy[j]) <= tau_dy)
            sub = np.where(ok[None, :], vx[list(subset)], 0.0)  # no NaN where it counts
            spread = np.where(ok, sub.max(axis=0) - sub.min(axis=0), np.inf)
            better = ok & ((size > best_size) | ((size == best_size) & (spread < best_spread)))
            best = np.where(better, sum(1 << k for k in subset), best)
            best_size = np.where(better, size, best_size)
            best_spread = np.where(better, spread, best_spread)

    keep = best_size > 0
    chosen = ((best[None, :] >> np.arange(n_ch)[:, None]) & 1).astype(bool) & keep[None, :]
    w = np.where(chosen, vw, 0.0)
    wsum = w.sum(axis=0)
    # A member whose only weight is a zero-confidence Gabor value cannot happen (a_conf_min > 0
    # or the sparse weights are 1), but guard the division anyway.
    wsum = np.where(wsum > 0, wsum, 1.0)
    fx = (np.where(chosen, vx, 0.0) * w).sum(axis=0) / wsum
    fy = (np.where(chosen, vy, 0.0) * w).sum(axis=0) / wsum
    bits = np.array([CHANNEL_BITS[n] for n in names], np.uint8)
    sources = (chosen * bits[:, None]).sum(axis=0).astype(np.uint8)
    count = chosen.sum(axis=0).astype(np.uint8)
    avail = present.sum(axis=0)

    sel = np.nonzero(keep)[0]
    xl = xx[sel].astype(np.float32)
    yl = yy[sel].astype(np.float32)
    dxs = fx[sel].astype(np.float32)
    dys = fy[sel].astype(np.float32)
    score = (count[sel] / np.maximum(avail[sel], 1)).astype(np.float32)
    matches = Matches(
        xl=xl,
        yl=yl,
        xr=xl - dxs,
        yr=yl - dys,
        score=score,
        image_shape=shape,
        stats={"candidates": len(yy), "members": len(sel), "channels": list(names)},
    )
    h, w_ = shape
    dispx = np.full((h, w_), np.nan, np.float32)
    dispy = np.full((h, w_), np.nan, np.float32)
    cmap = np.zeros((h, w_), np.uint8)
    smap = np.zeros((h, w_), np.uint8)
    ys, xs = yy[sel], xx[sel]
    dispx[ys, xs], dispy[ys, xs] = dxs, dys
    cmap[ys, xs], smap[ys, xs] = count[sel], sources[sel]
    return FusionResult(
        matches=matches,
        count=count[sel],
        sources=sources[sel],
        dispx=dispx,
        dispy=dispy,
        count_map=cmap,
        sources_map=smap,
        channels=tuple(names),
    )


def _checked_channels(channels: Iterable[Any]) -> tuple[str, ...]:
    """``channels`` as :func:`fuse_pair` takes them, read once into a tuple, or the
    ValueError naming what is wrong: a string, unknown names, no sparse channel.
    :func:`stereovision.match` checks them with it before its own refusals, which name the
    channels that run."""
    if isinstance(channels, (str, bytes)):  # "gabor,mcgm" was read letter by letter
        raise ValueError(f"channels: expected a tuple of channel names, got {channels!r}")
    # once: a generator was used up by the first check, then said to hold no sparse channel
    try:
        channels = tuple(channels)
    except TypeError:
        raise ValueError(f"channels: expected a tuple of channel names, got {channels!r}") from None
    # no set() or sorted() of the raw entries: a list among them was "unhashable type", a
    # number beside a name "'<' not supported", naming nothing
    # told apart by repr: ``c not in bad`` compared an array entry with == ("truth value of
    # an array ... is ambiguous", naming nothing)
    bad: list[Any] = []
    seen: set[str] = set()
    for c in channels:
        if (not isinstance(c, str) or c not in CHANNEL_BITS) and repr(c) not in seen:
            seen.add(repr(c))
            bad.append(c)
    if bad:
        shown = sorted(bad, key=repr)
        raise ValueError(f"unknown channel(s) {shown}: expected {sorted(CHANNEL_BITS)}")
    if not set(channels) & {"mcgm", "hopfield"}:
        # fuse refused it only after the channels had run (match(method="fused") on a whole
        # pair), and () without the census map was ThreadPoolExecutor's "max_workers must be
        # greater than 0"
        raise ValueError(
            f"channels: expected at least one sparse channel (mcgm or hopfield), got {channels!r}"
        )
    return channels


def fuse_pair(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    max_disparity: float,
    min_disparity: float = 0.0,
    channels: tuple[str, ...] = ("gabor", "mcgm", "hopfield"),
    remeasure_gabor: bool = True,
    check_members: bool = True,
    edge_members: bool = True,
    census_members: bool = True,
    dense_sgm: bool = False,
    **params: Any,
) -> FusionResult:
    """Run the channels on a rectified pair and fuse them (:func:`fuse`).

    Parameters
    ----------
    left, right : array_like
        Rectified pair, ``(H, W)`` grey float32 in ``[0, 1]`` (or anything
        :func:`stereovision._validate.as_gray_float` takes), same shape.
    max_disparity, min_disparity : float
        Disparity range every channel searches (px). A range past the image's width is searched to
        the image's edge, without the error :func:`stereovision.match` raises (see
        :mod:`stereovision.matching`).
    channels : tuple of str
        Which channels take part: ``"gabor"`` and at least one of ``"mcgm"``, ``"hopfield"``.
        MCGM runs with :data:`MEMBER_MCGM`.
    remeasure_gabor : bool
        Re-measure the Gabor map where it measured (:func:`remeasure`, in the Gabor channel's
        thread while the sparse channels run) and vote with that; it is kept in
        ``channel_outputs["gabor_remeasured"]``. Default True: on the 17 shared scenes the
        members' precision@1 rose on 10 (>= 99 % on 10 of the 16 Middlebury/ETH3D/TartanAir
        scenes instead of 8), terrace's member depth RMSE fell from 3.19 to 2.77 %, and the
        dense map built on it (:func:`fused_dense`) has a lower bad-2.0 on 12 and a lower
        bad-0.5 on all 17 (docs/fusion.md).
    check_members : bool
        Keep only the members that pass B.8's both-sides check on the pair
        (:func:`stereovision.matching.mcgm.edge_filters` with ``sides`` alone, settings of
        :data:`MEMBER_MCGM`: the 4x7 half-windows either side of the pixel fit at the
        member's disparity, and no other disparity fits one of them better); members MCGM is
        part of passed it as MCGM matches and are not tested again. Gabor and Hopfield can
        agree on a foreground disparity that a fattened edge carried onto the background; the
        background's half-window then does not fit it. Default True (docs/fusion.md).
    edge_members : bool
        Drop the members that lie where a foreground edge of the (re-measured) Gabor map is
        carried past the image's edge (:func:`fused_dense`'s step 7 on the Gabor map, 7 px
        either side, an intensity step 1.5 x that at the jump): the wrong members sit on depth
        edges, on the foreground's disparity. Default True: over the 17 GT scenes precision@1
        rose on 15 (teddyH 98.92 -> 99.03 %, dolls 98.08 -> 98.33 %) and fell by at most 0.03
        point, with 0.2-1.9 % fewer members.
    census_members : bool
        Drop the members near a depth edge of the census semi-global map
        (:func:`census_clear`); runs that matcher beside the channels if ``dense_sgm`` does
        not. Default True: over the 17 GT scenes precision@1 >= 99 % on all 16
        Middlebury/ETH3D/TartanAir scenes (teddy 97.89 -> 99.47 %, dolls 98.33 -> 99.39 %,
        TartanAir 97.53 -> 99.03 %; KITTI @2 98.60 -> 98.86 %) with 13 % fewer members
        (docs/fusion.md).
    dense_sgm : bool
        Also run the census semi-global matcher (:func:`stereovision.matching.sgm.sgm_disparity`)
        beside the channels, for :func:`fused_dense`'s ``second``; its map is kept in
        ``channel_outputs["sgm"]``. It takes no part in the vote (``census_members`` checks
        the members against it afterwards). ``depth_map`` turns it on
        (``semi_global=False`` there turns it off). Not re-measured: the re-measure moved
        values it filled by more than 2 px often enough to cost 0.04 of the mean ratio.
    **params
        :func:`fuse`'s options (:data:`DEFAULTS`).

    Returns
    -------
    FusionResult
        ``matches.stats`` also holds each channel's match count and seconds.

    Raises
    ------
    ValueError
        Bad images, an unknown channel or option, a ``channels`` with no sparse channel or
        given as one string, a ``min_agree`` above the number of ``channels`` in vote mode, a
        negative ``min_disparity`` (the sparse channels search from 0 px; before any channel
        runs).
    TypeError
        A switch (``remeasure_gabor``, ``check_members``, ``edge_members``,
        ``census_members``, ``dense_sgm``) that is not True or False, or a range bound that is
        not one real number (an array, a string, None; before any channel runs).
    """
    from stereovision._validate import as_gray_float, check_pair
    from stereovision.matching.gabor import gabor_disparity
    from stereovision.matching.hopfield import hopfield_match
    from stereovision.matching.mcgm import mcgm_match
    from stereovision.matching.sgm import sgm_disparity

    # fuse_pair's own keywords are valid too: a misspelt one lands in params
    own = ["channels", "remeasure_gabor", "check_members", "edge_members", "census_members"]
    refuse_unknown("fusion option", params, [*DEFAULTS, *own, "dense_sgm", "min_disparity"])
    for name, flag in (
        ("remeasure_gabor", remeasure_gabor),
        ("check_members", check_members),
        ("edge_members", edge_members),
        ("census_members", census_members),
        ("dense_sgm", dense_sgm),
    ):
        # as depth_map's switches: "no" (true) ran the check, None (false) skipped it
        if not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"{name}: expected True or False, got {flag!r}")
    channels = _checked_channels(channels)
    # before the channels run, not after
    mode, *_, min_agree = _fuse_options(**{**DEFAULTS, **params})
    _check_agree(mode, min_agree, channels)
    # as match() and depth_map say it: np.array([60]) or a Fraction was refused by the sparse
    # channels only after the Gabor channel and the census map had run (0.44 s on cones), as
    # 'max_disparity must be a non-negative number of pixels, got array([60])'
    for name, value in (("max_disparity", max_disparity), ("min_disparity", min_disparity)):
        if not real_number(value):
            raise TypeError(f"{name}: expected a number of pixels, got {_shown(value)}")
    # The sparse channels search from 0 px: a negative min_disparity was their own error only
    # after the Gabor channel and the census map had run on the whole pair (0.46 s on cones).
    if real_number(min_disparity) and min_disparity < 0:
        from_zero = [c for c in ("mcgm", "hopfield") if c in channels]
        raise ValueError(
            f"min_disparity must be a non-negative number of pixels, got "
            f"{_shown(min_disparity)}: the {' and '.join(from_zero)} channel"
            f"{' searches' if len(from_zero) == 1 else 's search'} from 0 px"
        )
    gl, gr = check_pair(as_gray_float(left, "left"), as_gray_float(right, "right"))
    rng: dict[str, Any] = {"max_disparity": max_disparity, "min_disparity": min_disparity}
    runs: dict[str, Callable[..., Any]] = {
        "gabor": gabor_disparity,
        "mcgm": functools.partial(mcgm_match, **MEMBER_MCGM),
        "hopfield": hopfield_match,
        "sgm": sgm_disparity,
    }

    outputs: ChannelOutputs = {}

    def timed(name: str) -> tuple[Any, float]:
        t0 = time.perf_counter()
        out = runs[name](gl, gr, **rng)
        if name == "gabor" and remeasure_gabor:
            # In this thread (its seconds include it): it needs only the Gabor map, and the
            # sparse channels run on meanwhile.
            outputs["gabor_remeasured"] = remeasure(gl, gr, out.disparity, out.confidence, **rng)
        return out, time.perf_counter() - t0

    # The channels run side by side: each kernel releases the GIL and has sequential stretches
    # (MCGM's tracking and spreading, the Hopfield sweeps) where the other core would idle.
    # Their outputs do not depend on the scheduling (every kernel is bit-identical across
    # thread counts).
    names: list[str] = [n for n in ("gabor", "mcgm", "hopfield") if n in channels]
    names += ["sgm"] if dense_sgm or census_members else []
    with ThreadPoolExecutor(max_workers=len(names)) as pool:
        done = dict(zip(names, pool.map(timed, names), strict=True))
    seconds: dict[str, float] = {n: done[n][1] for n in names}
    sgm_map = done.pop("sgm")[0] if "sgm" in done else None
    if dense_sgm and sgm_map is not None:  # not None: dense_sgm ran it
        outputs["sgm"] = sgm_map
    dense = None
    if "gabor" in done:
        g = done["gabor"][0]
        dense = (outputs.get("gabor_remeasured", g.disparity), g.confidence)
        outputs["gabor"] = g
    sparse: dict[str, Matches] = {n: done[n][0] for n in ("mcgm", "hopfield") if n in done}
    t = time.perf_counter()
    res = fuse(dense, sparse, **params)
    keep = np.ones(len(res), bool)
    if check_members:
        # MCGM's own matches passed the check already: only the members it is not part of are
        # tested (60-70 % fewer; the check would cost 30 ms on cloth3's 27500 members).
        test = (res.sources & CHANNEL_BITS["mcgm"]) == 0
        keep[test] = _sides_ok(gl, gr, res.matches, test, max_disparity, min_disparity)
    if edge_members and dense is not None:
        base = dense[0]
        r, ratio, jump = _EDGE_MEMBERS
        fat = _fattened(base, gl, r, ratio, jump)
        keep &= ~fat[res.matches.yl.astype(np.intp), res.matches.xl.astype(np.intp)]
    if check_members or edge_members:
        res = _members_where(res, keep)
    if census_members and sgm_map is not None:
        res = census_clear(res, sgm_map)
    seconds["fuse"] = time.perf_counter() - t
    res.channel_outputs.update(outputs)
    if "mcgm" in sparse:
        res.channel_outputs["mcgm"] = sparse["mcgm"]
    if "hopfield" in sparse:
        res.channel_outputs["hopfield"] = sparse["hopfield"]
    res.matches.stats.update(
        channel_matches={k: len(v) for k, v in sparse.items()}, seconds=seconds
    )
    return res


def _sides_ok(
    gl: F32,
    gr: F32,
    m: Matches,
    which: npt.NDArray[np.bool_],
    max_disparity: float,
    min_disparity: float,
) -> npt.NDArray[np.bool_]:
    """B.8's both-sides check alone (:func:`stereovision.matching.mcgm.edge_filters`) on the
    matches of ``m`` where ``which``."""
    from stereovision.matching.mcgm import edge_filters

    arr = np.stack([m.xl, m.yl, m.xr, m.yr], axis=1)[which]
    return edge_filters(
        gl,
        gr,
        arr,
        max_disparity=max_disparity,
        min_disparity=min_disparity,
        disc=False,
        zncc_check=False,
        **{k: v for k, v in MEMBER_MCGM.items() if k.startswith("sides")},
    )


def census_clear(
    res: FusionResult,
    census: npt.ArrayLike,
    *,
    radius: int = 7,
    jump: float = 1.5,
) -> FusionResult:
    """Keep the members that no depth edge of the census map lies near.

    A member is dropped where the census semi-global map
    (:func:`stereovision.matching.sgm.sgm_disparity`) has a value more than ``jump`` px below
    the member's disparity within ``radius`` px (a square window). The wrong members sit on
    depth edges with the foreground's disparity, on a background pixel: Gabor, MCGM and
    Hopfield all carry the foreground's edge there, and so does the census map, by a few
    pixels; its values beyond that reach show where the background is.

    Parameters
    ----------
    res : FusionResult
        Members (:func:`fuse`).
    census : array_like
        ``(H, W)`` census map of the same pair, NaN where it has no value.
    radius : int
        Half-width of the window (px). Default 7: the census window's half-width (4) plus the
        few pixels the aggregation carries an edge.
    jump : float
        How far below the member's disparity a census value must lie (px). Default 1.5.

    Returns
    -------
    FusionResult
        The members kept (:func:`fuse_pair` with ``census_members=True``, the default).

    Raises
    ------
    ValueError
        A census map of another shape, a negative radius or jump, or a jump that is no number
        (a string, None, a bool).
    """
    import cv2

    c = _check_map(census, "census", res.dispx.shape)
    # the library's one rule of a count (whole_value), as jump reads its number: np.array([7])
    # was NumPy's bare "only 0-dimensional arrays can be converted to Python scalars" and
    # Fraction(7) "radius: expected a finite number"
    size = whole_value(radius)
    if size is None or size < 0:
        raise ValueError(f"radius must be a non-negative integer, got {_shown(radius)}")
    # a string or None failed in the comparison as Python's "'>=' not supported", naming
    # nothing, and True was a jump of 1 px; a size-1 array or a Fraction is its number
    jump = _plain_option(jump)
    if not real_number(jump) or not jump >= 0:
        raise ValueError(f"jump must be >= 0, got {_shown(jump)}")
    # A window wider than the map is the whole map (the border is replicated): 2**70 was NumPy's
    # "Maximum allowed dimension exceeded", 10**5 a 40 GB kernel.
    r = min(size, max(c.shape))
    k = np.ones((2 * r + 1, 2 * r + 1), np.uint8)
    # The window's minimum (an erosion); NaN as +inf so that unmeasured pixels never count.
    low = cv2.erode(
        np.where(np.isfinite(c), c, np.inf).astype(np.float32), k, borderType=cv2.BORDER_REPLICATE
    )
    m = res.matches
    lowest = low[m.yl.astype(np.intp), m.xl.astype(np.intp)]
    out = _members_where(res, ~(lowest < (m.xl - m.xr) - jump))
    out.matches.stats["members_before_census"] = len(m)
    return out


def _members_in_range(res: FusionResult, lo: float, hi: float) -> FusionResult:
    """``res`` with only the members whose disparity ``xl - xr`` is in ``[lo, hi]``, as
    ``match(method="fused")`` keeps them: a member's sub-pixel average can leave the range
    searched (cones at max_disparity=37: 84 members up to 37.79 px)."""
    d = res.matches.xl - res.matches.xr
    inside = (d >= lo) & (d <= hi)
    return res if inside.all() else _members_where(res, inside)


def _members_where(res: FusionResult, keep: npt.NDArray[np.bool_]) -> FusionResult:
    """``res`` with only the members where ``keep`` (matches, per-member arrays, rasters)."""
    m = res.matches
    gone = ~keep
    ys, xs = m.yl[gone].astype(np.intp), m.xl[gone].astype(np.intp)
    dispx, dispy = res.dispx.copy(), res.dispy.copy()
    cmap, smap = res.count_map.copy(), res.sources_map.copy()
    dispx[ys, xs] = np.nan
    dispy[ys, xs] = np.nan
    cmap[ys, xs] = 0
    smap[ys, xs] = 0
    stats = {**m.stats, "members": int(keep.sum())}
    stats.setdefault("members_before_check", len(m))
    kept = Matches(
        xl=m.xl[keep],
        yl=m.yl[keep],
        xr=m.xr[keep],
        yr=m.yr[keep],
        score=m.score[keep],
        image_shape=m.image_shape,
        stats=stats,
    )
    return FusionResult(
        matches=kept,
        count=res.count[keep],
        sources=res.sources[keep],
        dispx=dispx,
        dispy=dispy,
        count_map=cmap,
        sources_map=smap,
        channels=res.channels,
        channel_outputs=res.channel_outputs,
    )


#: fuse_pair's member edge check: the step-7 rule on the Gabor map, wider and more eager than
#: the dense map's (7 px, an edge 1.5 x the step at the jump, jumps over 2 px): 5 px / 1.5 x
#: lifted teddyH to 99.00 %, 3 px / 2 x to 98.94 %.
_EDGE_MEMBERS = (7, 1.5, 2.0)


def fill_enclosed_far(
    disparity: npt.ArrayLike,
    guide: npt.ArrayLike,
    *,
    floor: float = 0.0,
    far: float = 0.5,
    jump: float = 3.0,
    ring: int = 3,
) -> tuple[F32, npt.NDArray[np.bool_]]:
    """Fill the dark regions locked to the far end of the range inside a nearer surround.

    In a dark, nearly flat region the census matcher compares noise: where the cameras' noise
    has a fixed pattern (dark-signal non-uniformity, a renderer's dithering) it is the same at
    the same pixel in both images and matches at the range's floor, disparity 0. A region at
    the floor that touches no image border, whose surround (``ring`` px wide) has a median
    disparity ``jump`` px or more above the floor, and that is darker on average than that
    surround takes the surround's median: a dark shop window in a wall gets the wall's
    disparity, the pane's rather than the locked noise's. Bright far regions seen through a
    gap (sky between branches) are not darker than their surround and keep their values; a
    dark one (a night sky between lit walls) would be filled: the step cannot tell it from a
    locked region.

    Over the 17 GT scenes (fused map, ``depth_map``'s last step): TartanAir's bad-2.0
    8.96 -> 7.55 % (4434 pixels of a shop window and awning, GT 5-6 px, matched at 0), ratio to
    SGBM-3WAY + fill 0.881 -> 0.743; 51 pixels elsewhere (playground, tsukuba, teddy), no
    figure moved by 0.01. ``far`` 1.0, ``jump`` 2 or 5, ``ring`` 5 or a surround 0.8 x as
    bright gave TartanAir 0.738-0.752.

    Parameters
    ----------
    disparity : array_like
        ``(H, W)`` disparity map (NaN = none; NaN pixels are never part of a region or a
        surround).
    guide : array_like
        ``(H, W)`` grey left image (any scale).
    floor : float
        The searched range's smallest disparity (px).
    far, jump : float
        px: how near the floor a region lies, how far above it its surround.
    ring : int
        Width of the surround (px).

    Returns
    -------
    disparity : numpy.ndarray
        ``(H, W)`` float32, a copy with the regions filled.
    filled : numpy.ndarray
        ``(H, W)`` bool, the pixels filled.

    Raises
    ------
    ValueError
        Maps of different shapes, a non-finite ``floor``, a non-finite or negative ``far`` /
        ``jump``, ``ring`` not a whole number >= 1.
    """
    import cv2

    d = _check_map(disparity, "disparity", None)
    shape = (int(d.shape[0]), int(d.shape[1]))
    g = _check_map(guide, "guide", shape)
    finite_number(floor, "floor")
    for name, v in (("far", far), ("jump", jump)):
        if finite_number(v, name) < 0:
            raise ValueError(f"{name}: expected a non-negative number, got {v}")
    if isinstance(ring, (bool, np.bool_)) or int(finite_number(ring, "ring")) != ring or ring < 1:
        raise ValueError(f"ring: expected a whole number >= 1, got {ring}")
    # A ring wider than the map reaches all of it: 2**70 was cv2's "Can't parse 'ksize'".
    r = min(int(ring), shape[0] + shape[1])
    out = d.copy()
    filled = np.zeros(shape, bool)
    with np.errstate(invalid="ignore"):
        low = (d < floor + far).astype(np.uint8)  # NaN compares False
    n, lab, stats, _ = cv2.connectedComponentsWithStats(low, connectivity=8)
    h, w = shape
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))
    for i in range(1, n):
        x, y, bw, bh = (int(v) for v in stats[i, :4])
        if x == 0 or y == 0 or x + bw == w or y + bh == h:
            continue  # open to the border: sky above a horizon, the far end of a street
        # The component's box grown by the ring (it touches no border, so the ring fits).
        y0, y1, x0, x1 = max(y - r, 0), min(y + bh + r, h), max(x - r, 0), min(x + bw + r, w)
        comp = lab[y0:y1, x0:x1] == i
        dc = d[y0:y1, x0:x1]
        around = cv2.dilate(comp.astype(np.uint8), kernel).astype(bool) & ~comp
        around &= np.isfinite(dc)
        if not around.any():
            continue
        med = float(np.median(dc[around]))
        gc = g[y0:y1, x0:x1]
        if med - floor >= jump and float(gc[comp].mean()) < float(gc[around].mean()):
            out[y0:y1, x0:x1][comp] = med
            filled[y0:y1, x0:x1] |= comp
    return out, filled


#: Dense completion defaults (measured on the 17 GT scenes with the Gabor + MCGM + Hopfield
#: members: filled bad-2.0 15.9 -> 14.5 % mean, lower on every scene than Gabor alone; a 25 px
#: radius starts to hurt books/laundry, 1.5 px is too strict for Gabor's sub-pixel spread).
DENSE_DEFAULTS = {
    "radius": 15.0,  # px: a member this close can veto the Gabor value
    "tau": 2.0,  # px: ... when they differ by more than this (the bad-2 bar)
    "fill_radius": 3.0,  # px: holes this close to a member take its value
    "fill_confidence": 0.25,  # confidence of such anchor-filled pixels
    "second_tol": 1.0,  # px: Gabor and the semi-global map further apart than this -> hole
    "second_confidence": 0.5,  # confidence of pixels only the semi-global map measured
    "occlusion_tau": 2.0,  # px: Gabor alone this far above the row fill -> hole (occluded strip)
    "speckle_area": 5e-5,  # share of the image, rounded down to pixels: smaller regions -> holes
    "speckle_diff": 1.0,  # px: neighbours at most this far apart are in one region
    "edge_radius": 3,  # px: a disparity jump looks this far along the row / column for an edge
    "edge_ratio": 2.0,  # ... and moves to one this many times stronger than the step at the jump
    "edge_jump": 2.0,  # px: smallest disparity step that counts as a jump
}


def _nearest_member(members: F32) -> tuple[F32, F32]:
    """Value of the nearest member and the distance to it, for every pixel.

    OpenCV's ``distanceTransformWithLabels`` with ``DIST_LABEL_PIXEL`` labels the zero pixels
    (here: the members) 1, 2, ... in row-major order; label 0 never occurs when a member exists.
    """
    import cv2

    inv = (~np.isfinite(members)).astype(np.uint8)
    dist, lab = cv2.distanceTransformWithLabels(
        inv, cv2.DIST_L2, cv2.DIST_MASK_5, labelType=cv2.DIST_LABEL_PIXEL
    )
    ys, xs = np.nonzero(inv == 0)
    values = np.concatenate([np.array([np.nan], np.float32), members[ys, xs]])
    return values[lab].astype(np.float32), dist.astype(np.float32)


#: the largest float32: the edge kernel's ``ratio`` and ``jump`` are float32.
_F32_MAX = float(np.finfo(np.float32).max)


def _dense_options(
    radius: Any,
    tau: Any,
    fill_radius: Any,
    fill_confidence: Any,
    second_tol: Any,
    second_confidence: Any,
    occlusion_tau: Any,
    speckle_area: Any,
    speckle_diff: Any,
    edge_radius: Any,
    edge_ratio: Any,
    edge_jump: Any,
) -> tuple[Any, ...]:
    """Check :func:`fused_dense`'s options (:data:`DENSE_DEFAULTS`' keys, in its order); all
    of them, in that order, as it uses them (:func:`_plain_option`). ``depth_map`` checks them
    before it matches (a bad one was said only after every matcher had run)."""
    radius, tau, fill_radius, fill_confidence, second_tol, second_confidence = (
        _plain_option(v)
        for v in (radius, tau, fill_radius, fill_confidence, second_tol, second_confidence)
    )
    occlusion_tau, speckle_area, speckle_diff, edge_radius, edge_ratio, edge_jump = (
        _plain_option(v)
        for v in (occlusion_tau, speckle_area, speckle_diff, edge_radius, edge_ratio, edge_jump)
    )
    for name, v in (
        ("radius", radius),
        ("tau", tau),
        ("fill_radius", fill_radius),
        ("second_tol", second_tol),
        ("occlusion_tau", occlusion_tau),
        ("speckle_area", speckle_area),
        ("speckle_diff", speckle_diff),
        ("edge_radius", edge_radius),
        ("edge_ratio", edge_ratio),
        ("edge_jump", edge_jump),
    ):
        if finite_number(v, name) < 0:
            raise ValueError(f"{name}: expected a non-negative number, got {v}")
    # the edge kernel takes them as float32: 1e308 became inf there, refused after every
    # matcher had run as "ratio: ... got inf", naming neither the option nor the value given
    for name, v in (("edge_ratio", edge_ratio), ("edge_jump", edge_jump)):
        if v > _F32_MAX:
            raise ValueError(f"{name}: expected at most {_F32_MAX:.6g} (float32), got {v}")
    # Confidence 0 marks a filled disparity (DepthResult.depth_counts, point_image(filled=True)):
    # 0 here would mark as such the anchor-filled pixels, which get a depth (a member's value),
    # or every pixel only the census map measured.
    # a string or None failed in the comparison, naming no parameter
    if not 0 < finite_number(fill_confidence, "fill_confidence") <= 1:
        raise ValueError(f"fill_confidence: expected a value in (0, 1], got {fill_confidence}")
    if not 0 < finite_number(second_confidence, "second_confidence") <= 1:
        raise ValueError(f"second_confidence: expected a value in (0, 1], got {second_confidence}")
    return (
        radius,
        tau,
        fill_radius,
        fill_confidence,
        second_tol,
        second_confidence,
        occlusion_tau,
        speckle_area,
        speckle_diff,
        edge_radius,
        edge_ratio,
        edge_jump,
    )


def fused_dense(
    disparity: npt.ArrayLike,
    confidence: npt.ArrayLike,
    members: npt.ArrayLike,
    *,
    radius: float = 15.0,
    tau: float = 2.0,
    fill_radius: float = 3.0,
    fill_confidence: float = 0.25,
    second: npt.ArrayLike | None = None,
    second_tol: float = 1.0,
    second_confidence: float = 0.5,
    occlusion_tau: float = 2.0,
    speckle_area: float = 5e-5,
    speckle_diff: float = 1.0,
    guide: npt.ArrayLike | None = None,
    edge_radius: int = 3,
    edge_ratio: float = 2.0,
    edge_jump: float = 2.0,
    _only_second: npt.NDArray[np.bool_] | None = None,
) -> tuple[F32, F32]:
    """The dense map built on the valid members: Gabor corrected and completed by the anchors.

    1. Members replace the Gabor value at their pixels (they agree with it within the fusion's
       tolerance where Gabor took part, and are more precise: two or three channels averaged).
    2. A Gabor pixel whose nearest member (within ``radius``) differs by more than ``tau`` is
       dropped: a region locked to a wrong phase cycle, or a fattened foreground edge.
    3. A hole within ``fill_radius`` of a member takes the member's value (confidence
       ``fill_confidence``); other holes stay NaN.
    4. With a ``second`` map (the census semi-global matcher's): where both have a value and
       differ by more than ``second_tol`` the pixel becomes a hole (one of them is wrong, and
       neither says which); where they agree the pixel keeps its value; a hole ``second`` measured
       takes its value (confidence ``second_confidence``). Members keep their values.
    5. A Gabor value ``second`` has no value at (and no member or anchor supports) that stands
       more than ``occlusion_tau`` above the reference row fill of the other pixels is dropped:
       Gabor's filters carry a foreground disparity into the strip it occludes, where the census
       map's left-right check leaves a hole; the row fill then gives the background.
    6. Speckles: a connected region (4-neighbours within ``speckle_diff``) of fewer than
       ``int(speckle_area * H * W)`` pixels (the share rounded down: 8 at 450x375 for 5e-5, so
       regions of up to 7 pixels) becomes a hole; below one pixel the step is off. Small
       islands that agree with nothing around them are mostly wrong: over the 17 GT scenes
       this step lowers the mean bad-2.0 ratio to SGBM-3WAY + fill from 0.74 to 0.68 (wood2
       0.78 -> 0.45, KITTI 0.88 -> 0.72).
       The Gabor channel's own speckle kernel does it (``_core.gabor_remove_speckles``).
    7. Edges (with a ``guide`` image, the left one): window matchers carry the foreground a few
       pixels past its outline. Along each row and each column, a disparity jump of more than
       ``edge_jump`` (found on the row-filled map, so across holes too) looks ``edge_radius``
       pixels either side for the strongest intensity step; if that is ``edge_ratio`` times the
       step at the jump and lies on the background side, the foreground pixels between the jump
       and it become holes (the row fill gives them the background). Members stay. Over the 17
       GT scenes: mean ratio 0.68 -> 0.66 (tsukuba 0.97 -> 0.89, venus 0.72 -> 0.51; playground
       0.71 -> 0.75, the largest loss).

    Parameters
    ----------
    disparity, confidence : array_like
        ``(H, W)`` Gabor disparity (NaN = none) and confidence.
    members : array_like
        ``(H, W)`` members' disparity (:attr:`FusionResult.dispx`), NaN elsewhere.
    radius, tau, fill_radius, fill_confidence, second_tol, second_confidence, occlusion_tau : float
        See above (:data:`DENSE_DEFAULTS`).
    speckle_area, speckle_diff : float
        See step 6; ``speckle_area`` is a share of ``H * W``, rounded down to whole pixels (0,
        or a share of less than one pixel, turns the step off).
    guide : array_like, optional
        ``(H, W)`` grey left image (any scale) for step 7; None skips the step.
    edge_radius, edge_ratio, edge_jump : int, float, float
        See step 7 (``edge_radius`` 0 turns it off).
    second : array_like, optional
        ``(H, W)`` second dense opinion (NaN = none), e.g. ``channel_outputs["sgm"]``.

    Returns
    -------
    disparity, confidence : numpy.ndarray
        ``(H, W)`` float32; members have confidence 1.

    Raises
    ------
    ValueError
        Maps of different shapes, a negative radius / tolerance, ``fill_confidence`` or
        ``second_confidence`` not a number in (0, 1] (0 is the filled pixels' mark), an
        ``edge_ratio`` or ``edge_jump`` past float32's largest value, or (when step 7 runs) a
        ``guide`` with NaN, inf or values past float32's range.
    """
    d = _check_map(disparity, "disparity", None)
    shape = (int(d.shape[0]), int(d.shape[1]))
    c = _check_map(confidence, "confidence", shape)
    a = _check_map(members, "members", shape)
    b = None if second is None else _check_map(second, "second", shape)
    # the checked values, not the raw ones: np.array([3]) as edge_radius passed the check and
    # failed in int() below
    (
        radius,
        tau,
        fill_radius,
        fill_confidence,
        second_tol,
        second_confidence,
        occlusion_tau,
        speckle_area,
        speckle_diff,
        edge_radius,
        edge_ratio,
        edge_jump,
    ) = _dense_options(
        radius,
        tau,
        fill_radius,
        fill_confidence,
        second_tol,
        second_confidence,
        occlusion_tau,
        speckle_area,
        speckle_diff,
        edge_radius,
        edge_ratio,
        edge_jump,
    )
    # compared with (or added to) float32 maps: 1e308 as its float32 infinity, which reads it
    # right, without NumPy's "overflow encountered in cast" after every matcher had run
    radius, tau, fill_radius, second_tol, occlusion_tau = (
        float32_reach(v) for v in (radius, tau, fill_radius, second_tol, occlusion_tau)
    )
    out = d.copy()
    conf = np.where(np.isfinite(d), c, 0.0).astype(np.float32)
    has = np.isfinite(a)
    anchored = has.copy()
    opinion = (b, second_tol, second_confidence, occlusion_tau, _only_second)
    # A look past the map's sides finds nothing more: the cap keeps it in the kernel's integers.
    reach = min(int(edge_radius), max(shape))
    g = None if guide is None else _check_guide(guide, shape, reach >= 1)
    finish = (speckle_area, speckle_diff, g, reach, edge_ratio, edge_jump, _only_second)
    if not has.any():
        _second_opinion(out, conf, has, anchored, *opinion)
        return _finish(out, conf, has, *finish)
    near, dist = _nearest_member(a)
    with np.errstate(invalid="ignore"):
        veto = (dist <= radius) & np.isfinite(out) & (np.abs(out - near) > tau)
    out[veto] = np.nan
    conf[veto] = 0.0
    out[has] = a[has]
    conf[has] = 1.0
    hole = ~np.isfinite(out) & (dist <= fill_radius)
    out[hole] = near[hole]
    conf[hole] = fill_confidence
    anchored |= hole
    _second_opinion(out, conf, has, anchored, *opinion)
    return _finish(out, conf, has, *finish)


def _check_guide(guide: npt.ArrayLike, shape: tuple[int, int], used: bool) -> F32:
    """Step 7's ``guide`` as a float32 map of ``shape``; if the step runs (``used``), refused
    unless every value is finite in float32 (the kernel's edge search cannot read NaN or inf).

    The kernel refused it only after steps 1-6 had run, and counted a float64 guide's finite
    values past float32's range ("any scale") as "NaN or inf", after NumPy's overflow warning.
    """
    with np.errstate(over="ignore"):  # a value past float32's range: named below
        g = _check_map(guide, "guide", shape)
    if used and not np.isfinite(g).all():
        with np.errstate(over="ignore"):
            n_bad = int(np.count_nonzero(~np.isfinite(np.asarray(guide, np.float64))))
        n_big = int(np.count_nonzero(~np.isfinite(g))) - n_bad
        got = [f"{n_bad} NaN or inf"] if n_bad else []
        got += [f"{n_big} value(s) past float32's range ({_F32_MAX:.6g})"] if n_big else []
        raise ValueError(f"guide: expected a finite grey image, got {' and '.join(got)}")
    return g


def _finish(
    out: F32,
    conf: F32,
    members: npt.NDArray[np.bool_],
    area: float,
    diff: float,
    guide: F32 | None,
    radius: int,
    ratio: float,
    jump: float,
    only_second: npt.NDArray[np.bool_] | None,
) -> tuple[F32, F32]:
    """Steps 6 and 7 of :func:`fused_dense` (in place)."""
    _drop_speckles(out, conf, area, diff, only_second)
    if guide is None or radius < 1:
        return out, conf
    gone = _fattened(out, guide, radius, ratio, jump) & ~members & np.isfinite(out)
    out[gone] = np.nan
    conf[gone] = 0.0
    if only_second is not None:
        only_second[gone] = False
    return out, conf


def _fattened(d: F32, guide: F32, radius: int, ratio: float, jump: float) -> npt.NDArray[np.bool_]:
    """Step 7's pixels: those between a jump and the stronger edge on its background side, along
    the rows and along the columns of ``d`` (Rust kernel ``_core.fattened``; NumPy reference
    ``tests/reference/edges_ref.py``)."""
    from stereovision import _core

    return _core.fattened(
        np.ascontiguousarray(d, np.float32),
        np.ascontiguousarray(guide, np.float32),
        int(radius),
        float(ratio),
        float(jump),
    )


def _drop_speckles(
    out: F32,
    conf: F32,
    area: float,
    diff: float,
    only_second: npt.NDArray[np.bool_] | None,
) -> tuple[F32, F32]:
    """Step 6 of :func:`fused_dense` (in place), with the Gabor channel's speckle kernel (OpenCV's
    ``filterSpeckles`` rule, on the float disparities)."""
    from stereovision import _core

    # Above the map's size every region is smaller: the cap keeps it in the kernel's integers
    # (capped before int(): 1e308 of the map is inf, OverflowError naming nothing)
    size = int(min(area * out.size, out.size + 1))
    ok = np.isfinite(out)
    if size < 1 or not ok.any():
        return out, conf
    q = _core.gabor_remove_speckles(np.ascontiguousarray(out), size, float(diff))
    gone = ok & np.isnan(q)
    out[gone] = np.nan
    conf[gone] = 0.0
    if only_second is not None:
        only_second[gone] = False
    return out, conf


def _second_opinion(
    out: F32,
    conf: F32,
    members: npt.NDArray[np.bool_],
    anchored: npt.NDArray[np.bool_],
    second: F32 | None,
    tol: float,
    confidence: float,
    occlusion_tau: float,
    out_only: npt.NDArray[np.bool_] | None = None,
) -> tuple[F32, F32]:
    """Steps 4 and 5 of :func:`fused_dense` (in place; members are left alone, and by step 5
    their anchor fills too). Also sets ``out_only`` (when given) where the value came from
    ``second`` alone."""
    if second is None:
        return out, conf
    from stereovision.baselines import row_fill

    s_ok = np.isfinite(second)
    mine = np.isfinite(out) & ~members
    if not members.any() and not mine.any():
        # No map of its own and no members (``method="census"`` / ``"fast"``): ``second`` as it
        # is, the same outcome as the steps below with less work (a live frame's 3 ms of 40).
        np.copyto(out, second, where=s_ok)
        conf[s_ok] = confidence
        if out_only is not None:
            out_only |= s_ok
        return out, conf
    both = mine & s_ok
    with np.errstate(invalid="ignore"):
        off = both & (np.abs(out - second) > tol)
    # Where they agree the value stays: the re-measured Gabor map is the finer one (averaging in
    # the census map's raised terrace's share of depths off by > 5 % from 10.0 to 15.2 %).
    out[off] = np.nan
    conf[off] = 0.0
    only = ~np.isfinite(out) & ~off & s_ok
    out[only] = second[only]
    conf[only] = confidence
    if out_only is not None:
        out_only[only] = True
    alone = mine & ~anchored & ~s_ok
    if alone.any():
        with np.errstate(invalid="ignore"):
            fattened = alone & (
                out > row_fill(np.where(alone, np.float32(np.nan), out)) + occlusion_tau
            )
        out[fattened] = np.nan
        conf[fattened] = 0.0
    return out, conf
