"""``stereovision.match``: sparse correspondences of a stereo pair (feature-based channels)."""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    _shown,
    as_bgr_uint8,
    check_pair,
    finite_number,
    real_number,
    refuse_unreachable_range,
    too_large_for_float,
)
from stereovision.calibration import Calibration
from stereovision.depth import (
    _below_automatic,
    _from_zero,
    _range_too_wide,
    _rectify_grey,
    _refuse_range_types,
    _rig_to_warp_by,
    _too_narrow,
    estimate_max_disparity,
)
from stereovision.matches import Matches
from stereovision.matching import hopfield as _hopfield
from stereovision.matching import mcgm as _mcgm
from stereovision.matching.fusion import _checked_channels
from stereovision.uncalibrated import UncalibratedRectification

__all__ = ["METHODS", "match"]

#: Matchers of :func:`match`: the Hopfield network (algorithms.md C) and its best-match
#: reference without the network; multi-channel graph matching of zero-crossing curves (B);
#: the valid members of the three channels' agreement (D); the Gabor phase channel's confident
#: pixels (A).
METHODS = ("hopfield", "best", "mcgm", "fused", "gabor")


def match(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    calib: Calibration | UncalibratedRectification | None = None,
    *,
    method: str = "hopfield",
    max_disparity: float | None = None,
    **params: Any,
) -> Matches:
    """Match interest points between the two images of a stereo pair.

    Parameters
    ----------
    left, right : array_like
        ``(H, W)`` grey or ``(H, W, 3)`` BGR images (uint8, uint16 or float in ``[0, 1]``), same
        shape. Rectified, unless ``calib`` is an unrectified rig calibration or an
        :class:`~stereovision.uncalibrated.UncalibratedRectification` (the pair is then
        rectified first and the matches are in rectified coordinates).
    calib : Calibration or UncalibratedRectification, optional
        Rig calibration of the pair, or the homographies
        :func:`~stereovision.uncalibrated.rectify_uncalibrated` found for a rig without one
        (whose ``max_disparity`` is then the default search range), as for
        :func:`~stereovision.depth_map`.
    method : {"hopfield", "best", "mcgm", "fused", "gabor"}
        ``"hopfield"``: the network (:func:`stereovision.matching.hopfield.hopfield_match`);
        ``"best"``: the best-match reference without the network; ``"mcgm"``: multi-channel
        graph matching of LoG zero-crossing curves (:func:`stereovision.matching.mcgm.mcgm_match`);
        ``"fused"``: the valid members where Gabor, MCGM and Hopfield agree, less those near a
        depth edge (:func:`stereovision.matching.fusion.fuse_pair`, which also runs the census
        semi-global map for that check; its ``count`` and ``sources`` per member are in
        ``stats``); ``"gabor"``: every pixel the Gabor phase channel is confident about
        (:func:`stereovision.matching.gabor.gabor_disparity`, dense: one match per pixel,
        ``xr = xl - d``, ``yr = yl``, ``score`` its confidence in ``[0, 1]``).
    max_disparity : float, optional
        Largest disparity searched (px), as :func:`~stereovision.depth_map`'s (e.g. a
        :attr:`DepthResult.max_disparity <stereovision.DepthResult.max_disparity>`). None
        estimates it from the pair (:func:`stereovision.estimate_max_disparity`), or takes an
        uncalibrated rectification's. ``"gabor"`` searches up to it as given;
        ``"hopfield"``, ``"best"`` and ``"mcgm"`` search whole pixels, up to its ceiling (17 for
        16.5), and ``"fused"`` runs its Gabor channel up to it, its other channels up to its
        ceiling. Either way every match returned has ``min_disparity <= xl - xr <= max_disparity``
        (sub-pixel estimates that left the range, and the integer searchers' matches between
        ``max_disparity`` and its ceiling, are dropped and counted in
        ``stats["n_out_of_range"]``).
    **params
        Matcher parameters (:data:`stereovision.matching.hopfield.DEFAULTS`,
        :data:`stereovision.matching.mcgm.DEFAULTS`,
        :data:`stereovision.matching.gabor.DEFAULTS`, or for ``"fused"`` those of
        :data:`stereovision.matching.fusion.DEFAULTS`), plus ``min_disparity``.

    Returns
    -------
    Matches
        The matches, in the (rectified) pair's pixel coordinates, with the matcher's ``stats``
        (its per-match entries, ``"mcgm"``'s ``channel`` and ``"fused"``'s ``count`` and
        ``sources``, for the matches kept) and ``stats["n_out_of_range"]``.

    Raises
    ------
    TypeError
        A ``max_disparity`` or ``min_disparity`` that is not one real number (None, a bool, a
        string, an array), as :func:`~stereovision.depth_map` refuses it.
    ValueError
        Bad images (shape, dtype, empty, NaN, mismatched sizes), a calibration or rectification
        for another image size, a ``calib`` of another type, an unknown method or parameter (a
        misspelling of this function's own keyword, ``max_disparty=``, named as such), a
        ``max_disparity`` that is not a finite number >= 0 (or below ``min_disparity``; equal
        to it, ``"gabor"`` and ``"fused"`` refuse it, the others search that one level), a
        ``min_disparity`` not below the image width (no pixel has a match that far: a pair with
        no edges in a range it can match in still returns zero matches, not an error), a range
        ``max_disparity - min_disparity`` not below the image width (or, with no
        ``max_disparity``, a pair too narrow for the automatic range: 16 px wide or less), as
        :func:`~stereovision.depth_map` refuses them, a negative ``min_disparity`` with a
        method other than ``"gabor"`` (they search from 0 px).
    """
    # a str first: an array as the method failed in the test ("truth value ... ambiguous")
    if not isinstance(method, str) or method not in METHODS:
        from stereovision.depth import METHODS as DEPTH_METHODS

        # depth_map's own ("census", "fast") said as unknown, as if no function had it, where
        # match(l, r, "census") and depth_map(method="hopfield") name the other function
        other = (
            f" ({method!r} is a method of stereovision.depth_map, not of match)"
            if isinstance(method, str) and method in DEPTH_METHODS
            else ""
        )
        raise ValueError(
            f"unknown method {_shown(method)}: expected one of {', '.join(METHODS)}{other}"
        )
    _refuse_own_typos(method, params)
    # the range's type first, in depth_map's words: a 0-d array, True or None passed "gabor"'s
    # check (or failed in another class) and was refused by the others as not "non-negative"
    _refuse_range_types(max_disparity, params.get("min_disparity", 0))
    gl, gr = check_pair(left, right)
    # a negative min_disparity the method cannot search: said as depth_map says it (the
    # matchers' own words named neither the method nor the one that takes it), before the
    # rectification and the automatic range's estimate when no range is given to check first;
    # anything not a finite number is left to the matchers' own words
    lo = params.get("min_disparity", 0)
    from_zero = method != "gabor" and real_number(lo) and -math.inf < lo < 0
    if from_zero and method == "fused" and "channels" in params:
        # checked (and read once) first, so the refusal names the channels that run: it named
        # a graph-matching channel with channels=("hopfield",), and came before the channels'
        # own error with ("gabor",). Only then: otherwise fuse_pair checks them after its
        # options and switches, as before (a bad channels beside check_members="no" turned
        # the switch's TypeError into the channels' ValueError)
        params["channels"] = _checked_channels(params["channels"])
    if from_zero and max_disparity is None:
        raise _from_zero(method, lo, ("gabor",), params.get("channels"))
    uint8 = np.asarray(left).dtype == np.uint8 and np.asarray(right).dtype == np.uint8
    h, w = gl.shape
    # the range an uncalibrated rectification suggests is no more the caller's than an estimate
    rig_range = max_disparity is None and isinstance(calib, UncalibratedRectification)
    # a calibrated rig not yet rectified, or an uncalibrated one: as depth_map does
    rig, _, max_disparity = _rig_to_warp_by(calib, w, h, max_disparity, "match", METHODS)
    if rig is not None:
        if uint8:
            lb, rb = rig.rectify(as_bgr_uint8(left, "left"), as_bgr_uint8(right, "right"))
            gl, gr = check_pair(lb, rb)
        else:
            gl, gr = _rectify_grey(rig, gl, gr)
    automatic = max_disparity is None
    if max_disparity is None:
        max_disparity = estimate_max_disparity(gl, gr)
    _refuse_unreachable(
        params.get("min_disparity", 0),
        max_disparity,
        gl.shape[1],
        automatic or rig_range,
        method,
        rig_range,
    )
    if from_zero:  # a range given: once it is known searchable
        raise _from_zero(method, lo, ("gabor",), params.get("channels"))
    if method == "mcgm":
        m = _mcgm.mcgm_match(gl, gr, max_disparity=max_disparity, **params)
        keep = _in_range(m, params.get("min_disparity", 0), max_disparity)
        out = _keep(m, keep)
        # one sigma per match: a match dropped out of range takes its channel along (cones at
        # max_disparity=32: 4760 channels were left for 4570 matches)
        out.stats["channel"] = m.stats["channel"][keep]
        return out
    elif method == "fused":
        from stereovision.matching.fusion import fuse_pair

        res = fuse_pair(gl, gr, max_disparity=max_disparity, **params)
        keep = _in_range(res.matches, params.get("min_disparity", 0), max_disparity)
        m = _keep(res.matches, keep)
        # per member, as the matches: a member dropped out of range takes its entries along
        # (they were left whole, longer than the matches)
        # (and its count: "members" still said those before the range, 5509 for 5425 on cones
        # at 37 px)
        m.stats.update(count=res.count[keep], sources=res.sources[keep], members=len(m))
        return m
    elif method == "gabor":
        m = _gabor_matches(gl, gr, max_disparity, params)
    else:
        run = _hopfield.hopfield_match if method == "hopfield" else _hopfield.best_match
        m = run(gl, gr, max_disparity=max_disparity, **params)
    return _keep(m, _in_range(m, params.get("min_disparity", 0), max_disparity))


#: :func:`match`'s own keywords, which a misspelling sends to ``**params``.
_OWN_KEYWORDS = ("calib", "method", "max_disparity", "min_disparity")


def _refuse_own_typos(method: str, params: dict[str, Any]) -> None:
    """Refuse a ``**params`` key that is no parameter of ``method`` and nearest to one of
    :func:`match`'s own keywords, naming that keyword: the matcher's check named its own
    parameters only (``max_disparty=8`` was "unknown Hopfield parameter(s) ['max_disparty']"
    with no hint, and with ``"fused"`` "did you mean 'min_disparity'?"). Any other unknown
    key is left to the matcher, which lists its parameters."""
    import difflib

    from stereovision.matching import fusion, gabor

    # fuse_pair's own keywords too, as it takes them
    own = ["channels", "remeasure_gabor", "check_members", "edge_members", "census_members"]
    valid: list[str] = {
        "mcgm": list(_mcgm.DEFAULTS),
        "gabor": list(gabor.DEFAULTS),
        "fused": [*fusion.DEFAULTS, *own, "dense_sgm"],
    }.get(method, list(_hopfield.DEFAULTS))
    for key in params:
        if key in valid or key == "min_disparity":
            continue
        near = difflib.get_close_matches(key, [*valid, *_OWN_KEYWORDS], n=1, cutoff=0.6)
        if near and near[0] in _OWN_KEYWORDS:
            raise ValueError(f"match: unknown keyword argument {key!r} (did you mean {near[0]!r}?)")


def _refuse_unreachable(
    min_disparity: object,
    max_disparity: object,
    width: int,
    automatic: bool,
    method: str,
    rig: bool = False,
) -> None:
    """Refuse a range no pixel can match in (:func:`stereovision.depth_map`'s rule): a
    ``min_disparity`` at the width or above returned 0 matches without a word (or, beyond
    float32's resolution, the kernel's "invalid parameter `d_max`"). Values that are not finite
    numbers, and a max_disparity the caller gave below min_disparity, are left to the
    matchers' own checks, which name them (one equal to it is a one-level search, which
    hopfield, best and mcgm run: at the width it returned 0 matches without a word); an
    estimated one (``automatic``) below such a min_disparity is not the problem, the
    min_disparity is. An int beyond a float's range is compared as it is: a min_disparity of
    10**400 returned 0 matches without a word (hopfield, best, mcgm). An estimated one below a
    reachable min_disparity (at it, for ``method`` ``"gabor"`` and ``"fused"``, which search no
    single level) is refused as :func:`stereovision.depth_map` refuses it: the matchers' own
    words named a max_disparity the caller never gave ("max_disparity (32) must be >=
    min_disparity (40)"); ``rig``: the automatic one is an uncalibrated rectification's. So is
    a range not below the width, given (``max_disparity=40`` on a 30 px wide pair; a bound
    beyond a float, 10**400, as not a finite number) or estimated (a pair 16 px wide or
    narrower): the matchers searched it, clipped to the image, without a word."""
    try:
        lo = _bound(min_disparity, "min_disparity")
        hi = _bound(max_disparity, "max_disparity")
    except ValueError:  # not a finite number: the matchers name it
        return
    if hi < lo and not automatic:
        return
    try:
        wide = hi - lo >= width  # as depth_map compares them
    except OverflowError:  # an int beyond a float beside a float: 10**400 - 0.0
        wide = Fraction(hi) - Fraction(lo) >= width
    if wide and automatic and not rig:
        # the estimate (at least 16 px) on a pair 16 px wide or narrower: depth_map's words
        finite_number(lo, "min_disparity")  # -10**400 named as depth_map names it
        raise _too_narrow(width, hi - lo, lo)
    refuse_unreachable_range(lo, hi, width)
    if automatic and (hi < lo or (hi == lo and method in ("gabor", "fused"))):
        raise _below_automatic(lo, hi, rig)
    if wide:
        # a range no pair this wide has (max_disparity=40 on a 30 px wide pair) was searched
        # silently where depth_map refuses it: refused in its words (a bound beyond a float,
        # 10**400, as depth_map names it, not as a range of 401 digits)
        for value, name in ((lo, "min_disparity"), (hi, "max_disparity")):
            finite_number(value, name)
        raise _range_too_wide(hi - lo, width, lo)


def _bound(value: object, name: str) -> float:
    """``value`` as a finite float (:func:`finite_number`), or an int beyond a float's range as
    it is (exact comparisons with the width; ``_validate.unreachable_range`` shows its size)."""
    if too_large_for_float(value):
        return value  # type: ignore[return-value]
    return finite_number(value, name)


def _gabor_matches(
    gl: npt.NDArray[np.float32],
    gr: npt.NDArray[np.float32],
    max_disparity: float,
    params: dict[str, Any],
) -> Matches:
    """The Gabor channel's confident pixels as matches along the row."""
    from stereovision.matching.gabor import gabor_disparity

    res = gabor_disparity(gl, gr, max_disparity=max_disparity, **params)
    ys, xs = np.nonzero(np.isfinite(res.disparity))
    x = xs.astype(np.float32)
    y = ys.astype(np.float32)
    return Matches(
        xl=x,
        yl=y,
        xr=x - res.disparity[ys, xs],
        yr=y,
        score=res.confidence[ys, xs],
        image_shape=(gl.shape[0], gl.shape[1]),
    )


#: Beyond any image's width: a bound clipped to it cuts the same matches, and stays comparable
#: with float32 (10**400 was an OverflowError, 1e300 NumPy's "overflow encountered in cast").
_BOUND_CLIP = 2**31 - 1


def _in_range(m: Matches, lo: float, hi: float) -> npt.NDArray[np.bool_]:
    """Which matches have a disparity ``xl - xr`` in ``[lo, hi]``.

    The matchers search that range, but their sub-pixel estimates can leave it: MCGM's crossings
    by up to 2 px (cones, ``max_disparity=32``: 190 of 4760 matches above 32, up to 34.0), the
    Hopfield parabola by half a pixel below ``min_disparity``. A caller who bounds the range
    (a working volume, a near limit) gets no match outside it.
    """
    d = m.xl - m.xr
    # a size-1 array is its number, as the matchers read it (float() of np.array([1.0]) was
    # NumPy's bare TypeError, np.array([[4.05]]) a 2-D mask)
    lo, hi = (v.reshape(())[()] if isinstance(v, np.ndarray) else v for v in (lo, hi))
    # lo as a Python float, as before (a NumPy float64 would compare in float64)
    lo = lo.item() if isinstance(lo, np.generic) else lo  # its float, without float16's cast
    lo = float(min(max(lo, -_BOUND_CLIP), _BOUND_CLIP))
    # a NumPy float within the clip is kept as it is (and compared as before): the clip cast
    # 2**31 - 1 to a float16 bound, NumPy's "overflow encountered in cast"
    inside = isinstance(hi, np.floating) and abs(float(hi)) <= _BOUND_CLIP
    hi = hi if inside else min(max(hi, -_BOUND_CLIP), _BOUND_CLIP)
    return (d >= lo) & (d <= hi)


def _keep(m: Matches, keep: npt.NDArray[np.bool_]) -> Matches:
    """``m[keep]``, with the matches dropped counted in ``stats["n_out_of_range"]``."""
    n_out = int(len(m) - np.count_nonzero(keep))
    out = m if n_out == 0 else m[keep]
    out.stats["n_out_of_range"] = n_out
    return out
