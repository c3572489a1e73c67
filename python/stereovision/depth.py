"""The main entry point: a stereo pair (and its calibration) in, a metric depth map out.

``depth_map`` runs one of :data:`METHODS` on the rectified pair: ``"fused"`` (the default: the
Gabor, graph-matching and Hopfield channels' valid members on the Gabor map, checked and completed
by a census semi-global map, algorithms.md D), ``"gabor"`` (the Gabor channel alone), ``"census"``
(the census semi-global map alone) or ``"fast"`` (that map over three paths in one pass). It
re-measures the disparity to sub-pixel precision (:mod:`stereovision.refine`; not for
``"fast"`` unless asked), fills holes (not for ``"gabor"`` unless asked), then triangulates with
the rectified shortcut (algorithms.md E.3): ``Z = f * B / (d + doffs)``, in metres.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
import warnings
from collections.abc import Callable, Collection, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    ADVICE,
    NO_DEPTH,
    _real_array,
    _shown,
    as_bgr_uint8,
    as_gray_float,
    as_path,
    calib_size_hint,
    check_pair,
    figure_shown,
    finite_number,
    known_unit,
    number_shown,
    pair_shape_error,
    path_given,
    real_number,
    refuse_unknown,
    unreachable_range,
    user_stacklevel,
)
from stereovision._validate import pixels_shown as _px
from stereovision.calibration import Calibration

# at run time too, so that typing.get_type_hints resolves the public signatures
from stereovision.matching.fusion import ChannelOutputs, FusionResult
from stereovision.uncalibrated import UncalibratedRectification

__all__ = [
    "METHODS",
    "DepthChannels",
    "DepthResult",
    "depth_map",
    "disparity_sigma",
    "estimate_max_disparity",
]

_D = TypeVar("_D", int, float)  # a max_disparity (match and depth_map take a float)

#: Matchers ``depth_map`` knows, by name; the first is its default.
METHODS = ("fused", "gabor", "census", "fast")
#: Methods whose output is dense by default (holes filled, ``fill=None``).
_DENSE_METHODS = ("fused", "census", "fast")
#: Every method name of :func:`depth_map` and :func:`stereovision.match`, to tell one given in
#: the calibration's place from a file's name.
_ALL_METHODS = frozenset((*METHODS, "hopfield", "best", "mcgm"))
#: Methods that re-measure (``refine=None``) unless told not to; ``"fast"`` does not.
_REFINED_BY_DEFAULT = ("fused", "gabor", "census")
#: ``fused_dense`` options that apply to ``method="census"`` (the speckle and edge checks, and
#: the confidence given to the census map's pixels).
_CENSUS_DENSE = (
    "second_confidence",
    "speckle_area",
    "speckle_diff",
    "edge_radius",
    "edge_ratio",
    "edge_jump",
)
#: px: ``method="census"``'s re-measure may move a value this far (over the 17 GT scenes, mean
#: bad-2.0 ratio to SGBM-3WAY + fill: no re-measure 0.520, 0.5 px 0.515, 1 px 0.513, 1.5 px
#: 0.523, unbounded 0.584; moved values dropped instead of kept: 1 px 0.521).
_CENSUS_REMEASURE_STEP = 1.0
#: :func:`~stereovision.matching.fusion.fuse_pair` switches ``depth_map(method="fused")`` sets
#: itself, and the argument of its own that stands for each (None: none does).
_FUSED_SET_HERE = {"remeasure_gabor": "refine", "dense_sgm": "semi_global", "census_members": None}


#: :func:`depth_map`'s own keywords, which a misspelling sends to ``**params``.
_OWN_KEYWORDS = (
    "calib",
    "method",
    "max_disparity",
    "min_disparity",
    "fill",
    "refine",
    "return_channels",
    "cloud",
    "progress",
)


def _refuse_own_typos(method: str, params: dict[str, Any]) -> None:
    """Refuse a ``**params`` key that is no option of ``method`` and nearest to one of
    :func:`depth_map`'s own keywords, naming that keyword, as :func:`stereovision.match` does:
    ``max_disparty=8`` was "unknown fusion option(s) ['max_disparty']", a list of 22 options
    without the one meant. Any other unknown key is left to :func:`_refuse_unknown_params`."""
    import difflib

    # the options depth_map sets itself are refused in their own words, not as typos
    valid = [*_method_params(method), *(_FUSED_SET_HERE if method == "fused" else ())]
    for key in params:
        if key in valid:
            continue
        near = difflib.get_close_matches(key, [*valid, *_OWN_KEYWORDS], n=1, cutoff=0.6)
        if near and near[0] in _OWN_KEYWORDS:
            raise ValueError(
                f"depth_map: unknown keyword argument {key!r} (did you mean {near[0]!r}?)"
            )


def _method_params(method: str) -> list[str]:
    """The ``**params`` keys :func:`depth_map`'s ``method`` takes (one list for the typo hint
    and the refusal)."""
    from stereovision.matching import fusion, gabor, sgm

    if method == "gabor":
        return list(gabor.DEFAULTS)
    if method == "fused":
        own = ("channels", "check_members", "edge_members", "semi_global")
        return [*fusion.DEFAULTS, *own, *fusion.DENSE_DEFAULTS]
    return [*sgm.DEFAULTS, *_CENSUS_DENSE]


def _refuse_unknown_params(method: str, params: dict[str, Any]) -> None:
    """Refuse the ``**params`` :func:`depth_map`'s ``method`` does not take, naming the ones it
    does, a ``semi_global`` that is not a bool and a bad value of the fusion's or the dense
    map's options, before the pair is rectified and matched.

    The matchers' own checks named their own keys only: ``"census"`` left out the dense map's
    (``second_confidence``, ...), which it takes, and ``"fused"`` the dense map's and
    ``semi_global`` while naming ``remeasure_gabor``, ``dense_sgm`` and ``census_members``,
    which then failed as ``fuse_pair() got multiple values for keyword argument``."""
    from stereovision.matching import fusion

    _refuse_own_typos(method, params)
    if method == "gabor":
        refuse_unknown(
            "Gabor parameter",
            params,
            _method_params(method),
            "stereovision.matching.gabor.DEFAULTS",
        )
    elif method == "fused":
        for key, instead in _FUSED_SET_HERE.items():
            if key in params:
                how = f"give {instead}= instead" if instead else "its dense map is checked anyway"
                raise ValueError(f"{key}: depth_map sets this fuse_pair option itself ({how})")
        refuse_unknown(
            "fusion option",
            params,
            _method_params(method),
            "stereovision.matching.fusion.DEFAULTS and DENSE_DEFAULTS",
        )
        for switch in ("semi_global", "check_members", "edge_members"):
            flag = params.get(switch, True)
            if not isinstance(flag, (bool, np.bool_)):
                # as the other switches: "no" ran the census map or the check, None skipped it
                raise TypeError(f"{switch}: expected True or False, got {_shown(flag)}")
        mode, *_, agree = fusion._fuse_options(
            **{**fusion.DEFAULTS, **_given(params, fusion.DEFAULTS)}
        )
        if "channels" in params:
            _check_fused_channels(params["channels"])
        # fuse_pair's default channels are all three
        fusion._check_agree(mode, agree, params.get("channels", fusion.CHANNEL_BITS))
    else:
        refuse_unknown(
            "SGM option",
            params,
            _method_params(method),
            "stereovision.matching.sgm.DEFAULTS and the dense map's",
        )
    if method != "gabor":
        # the dense map's values too: a bad one was said after every matcher had run
        fusion._dense_options(**{**fusion.DENSE_DEFAULTS, **_given(params, fusion.DENSE_DEFAULTS)})


def _check_fused_channels(channels: object) -> None:
    """Refuse a ``channels`` the fused dense map cannot be built from: it is the Gabor map
    corrected by the members, so it needs ``"gabor"`` and a sparse channel. Without
    ``"gabor"`` it was a bare ``KeyError: 'gabor'`` after every channel had run, a string
    was taken letter by letter."""
    from stereovision.matching import fusion

    try:
        names = set(channels) if isinstance(channels, Collection) else set()
    except TypeError:  # unhashable entries: no channel names
        names = set()
    if (
        isinstance(channels, (str, bytes))
        or "gabor" not in names
        or not names & {"mcgm", "hopfield"}
        or names - set(fusion.CHANNEL_BITS)
    ):
        raise ValueError(
            "channels: depth_map(method='fused') needs 'gabor' (its dense map is the Gabor "
            f"map's) and at least one of 'mcgm', 'hopfield', and no other, got {_shown(channels)}"
        )


def _given(params: dict[str, Any], keys: Iterable[str]) -> dict[str, Any]:
    """The entries of ``params`` whose key is one of ``keys``."""
    return {k: v for k, v in params.items() if k in keys}


# Automatic disparity range: ORB matches on the epipolar band, a high percentile with margin.
_AUTO_DY_TOL = 2.0  # px: rectified pairs keep matches within a couple of rows
_AUTO_PERCENTILE = 99.0  # robust "largest" disparity: ignore the top 1 % (mismatches)
_AUTO_MARGIN = 1.15  # headroom above the observed largest disparity
_AUTO_MIN_MATCHES = 12  # fewer than this and the estimate is noise: fall back
_AUTO_FALLBACK_FRACTION = 1 / 8  # of the width, when the pair has too few features
# A dense second opinion: OpenCV SGBM on the pair shrunk 4x, its 99.5th percentile (sparse
# features miss the textureless near ground: KITTI's ORB 99th percentile is 62 px, its GT
# reaches 101 px; the shrunk SGBM's 99 px).
_AUTO_COARSE_SCALE = 4
_AUTO_ORB_HALF_FROM = 256  # px, shorter side: ORB runs on the pair at half resolution
_AUTO_ORB_FEATURES = 1500  # ... with this many features
_AUTO_ORB_FEATURES_FULL = 4000  # features on a smaller pair, matched at full resolution
_AUTO_COARSE_PERCENTILE = 99.5
_AUTO_COARSE_MIN_SIZE = (16, 64)  # (rows, columns) of the shrunk pair, else no second opinion
# ORB keeps keypoints 31 px (its edge threshold) from every border: a side shorter than 63 px has
# none, and a 1-px side makes its pyramid fail inside OpenCV.
_AUTO_ORB_MIN_SIDE = 63
# Share of the feature matches with a negative disparity above which the pair looks swapped.
_SWAPPED_SHARE = 0.5
# Share of the feature matches within _AUTO_DY_TOL rows below which the pair looks unrectified:
# 0.45-0.95 on the 18 rectified scenes of ../shared/data (art the lowest: ORB's mismatches),
# 0.02 on OpenCV's uncalibrated books pair; cones and terrace with the right image 3 / 6 rows
# lower: 0.24 and 0.22 / 0.04 and 0.01.
_UNRECTIFIED_SHARE = 0.2
_DISPARITY_STEP = 16  # ranges are multiples of 16, like the evaluation protocol's

# Disparity uncertainty from the matcher's confidence: sigma_d = max(s0 + slope * conf, s_min)
# (px), a line through the robust spread (1.4826 x median |error|) per confidence bin over the 17
# GT scenes. It is the spread of the correctly locked pixels, not of gross outliers.
# The Gabor channel as it comes (refine=False; 2.8 M pixels): 0.65 px at confidence 0.1, 0.47 at
# 0.55, 0.23 at 0.95.
_SIGMA_RAW = (0.74, -0.52, 0.2)
# After the refinement (the default; 3.1 M pixels): 0.34 px at confidence 0.18, 0.30 at 0.52,
# 0.20 at 0.86; the pixels it filled (13 % of them) spread by 0.63 px, whatever their neighbours'
# confidence. The fused map on the re-measured Gabor map fits the same line (2.8 M pixels: 0.31 px
# at confidence 0.47, 0.24 at 0.77, members 0.21; error / sigma median 0.69, 64 % within 1 sigma).
_SIGMA_REFINED = (0.405, -0.221, 0.18)
_SIGMA_FILLED = 0.63


# How far past the range searched a value may lie and still count as measured: a sub-pixel
# vertex of a cost peak at the range's end is within half a pixel of it.
_RANGE_TOL = 0.5


def _whole_or_float(value: float) -> float:
    """``value`` as an int when it is a whole number of pixels (64, not 64.0), else a float."""
    v = float(value)
    return int(v) if v.is_integer() else v


#: A pair whose brightest grey value is below this share of the full range (64 of 255 grey levels)
#: is stretched by one gain for the automatic range's features (12-bit data in 16 bits: 1/16).
_DARK_PAIR = 0.25


def _rig_to_warp_by(
    calib: Calibration | UncalibratedRectification | None,
    width: int,
    height: int,
    max_disparity: _D | None,
    caller: str = "depth_map",
    methods: tuple[str, ...] = METHODS,
) -> tuple[Calibration | UncalibratedRectification | None, Calibration | None, _D | int | None]:
    """What ``calib`` asks of a ``width`` x ``height`` pair (:func:`depth_map`'s and
    ``match``'s): ``(rig, calibration, max_disparity)``, ``rig`` the rectification to warp the
    pair by (None: matched as given), ``calibration`` the rig's calibration (None for an
    :class:`UncalibratedRectification`, whose search range then stands in for a
    ``max_disparity`` of None). ``caller`` and its ``methods`` name a method given in
    ``calib``'s place.

    Raises
    ------
    ValueError
        ``calib`` of another type, or a calibration for another image size (with a hint).
    """
    if isinstance(calib, UncalibratedRectification):
        # a rig without a calibration: its pair through the homographies, disparity only
        return calib, None, calib.max_disparity if max_disparity is None else max_disparity
    if calib is None:
        return None, None, max_disparity
    path = path_given(calib)
    if path in _ALL_METHODS:  # match(left, right, "mcgm"): method is keyword-only
        # the other function's method (depth_map(l, r, "mcgm")) was told to go as method=,
        # which then refused it as unknown
        other = "stereovision.match" if caller == "depth_map" else "stereovision.depth_map"
        how = (
            f"give it as method={path!r}"
            if path in methods
            else f"it is a method of {other}, not of {caller} ({', '.join(methods)})"
        )
        raise ValueError(
            f"calib: got {path!r}, a method's name, not a calibration: {how} "
            "(the third argument is the calibration)"
        )
    if path is not None:  # a calib.txt's name: said, not just "got str"
        raise ValueError(
            f"calib: got the path {path!r}, not a calibration: read it first "
            "(stereovision.Calibration.from_file(path))"
        )
    if not isinstance(calib, Calibration):
        raise ValueError(
            "calib must be a stereovision.Calibration (or an UncalibratedRectification), "
            f"got {type(calib).__name__}"
        )
    if tuple(calib.image_size) != (width, height):
        cw, ch = calib.image_size
        hint = calib_size_hint((cw, ch), (width, height))
        raise ValueError(f"calibration is for {cw}x{ch} images, got {width}x{height} ({hint})")
    return (None if calib.rectified else calib), calib, max_disparity


def _rectify_grey(
    rig: Calibration | UncalibratedRectification, left: npt.ArrayLike, right: npt.ArrayLike
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """A 16-bit or float pair's own grey levels through ``rig``'s rectification (its 8-bit copy
    keeps 8 bits of them), in ``[0, 1]`` (:func:`depth_map`'s and ``match``'s)."""
    rl, rr = rig.rectify(
        as_gray_float(left, "left", warn=False), as_gray_float(right, "right", warn=False)
    )
    # bilinear warps of [0, 1] images stay in [0, 1] up to rounding
    return (
        np.ascontiguousarray(np.clip(rl, 0.0, 1.0), np.float32),
        np.ascontiguousarray(np.clip(rr, 0.0, 1.0), np.float32),
    )


def _round_up(value: float, step: int = _DISPARITY_STEP) -> int:
    return int(max(step, int(np.ceil(value / step)) * step))


def _finite(v: float) -> bool:
    """Whether a real number is finite: ``np.isfinite`` of a Python int beyond 64 bits (2**70) was
    NumPy's TypeError "ufunc 'isfinite' not supported", one beyond a float's range is not."""
    try:
        return math.isfinite(v)
    except OverflowError:
        return False


def _too_narrow(width: int, automatic_range: float, min_disparity: float = 0) -> ValueError:
    """The error of a pair narrower than the disparity range chosen for it (never below
    ``_DISPARITY_STEP``: a pair at most 16 px wide is always refused). A pair 2 px wide or more
    is told the ``max_disparity`` that fits it; a 1 px wide one, which no range of a pixel or
    more fits (the range must be below the width), the width such a range needs."""
    need = math.floor(automatic_range) + 1
    # with a min_disparity the range is shorter than the automatic max_disparity (at least 16):
    # "(at least 16 px) needs images at least 12 px wide" contradicted itself
    what = (
        f"(at least {_DISPARITY_STEP} px)"
        if min_disparity == 0
        else f"({_px(min_disparity)} to {_px(automatic_range + min_disparity)} px: "
        f"{_px(automatic_range)} px, its max_disparity at least {_DISPARITY_STEP})"
    )
    text = (
        f"image too narrow for stereo matching: {width} px wide, and the automatic "
        f"disparity range {what} needs images at least {need} px wide"
    )
    # ADVICE's words: the CLI's error line and batch's summary name --max-disparity instead
    if width < 2:
        own = ADVICE["own_range"]["api"]
        return ValueError(f"{text}; {own} needs images at least 2 px wide")
    below = ADVICE["range"]["api"].format(n=_px(width + min_disparity))
    return ValueError(f"{text}; {below} to match it")


def _below_automatic(min_disparity: float, automatic_range: float, rig: bool = False) -> ValueError:
    """The error of a ``min_disparity`` not below the ``max_disparity`` estimated for the pair
    (:func:`estimate_max_disparity`; :func:`depth_map`'s and ``match``'s), or ``rig``: an
    :class:`UncalibratedRectification`'s search range. The caller gave no max_disparity, so
    the error names the automatic one as such and asks for one."""
    whose = "the rectification's search range" if rig else "estimated from the pair"
    return ValueError(
        f"min_disparity ({_px(min_disparity)}) is not below the automatic max_disparity "
        f"({_px(automatic_range)}, {whose}): give a max_disparity above {_px(min_disparity)}"
    )


def _range_too_wide(span: float, width: int, min_disparity: float = 0) -> ValueError:
    """The error of a disparity range the caller gave that is not below the pair's width: the
    width it needs, and the ``max_disparity`` that fits this pair (none for a 1 px wide one)."""
    text = (
        f"disparity range {_px(span)} is not smaller than the image width {width}: it needs "
        f"images at least {_px(math.floor(span) + 1)} px wide"
    )
    if width < 2:
        return ValueError(f"{text} (a range of a pixel or more needs 2 px)")
    below = ADVICE["range"]["api"].format(n=_px(width + min_disparity))  # as _too_narrow's
    return ValueError(f"{text}, or {below}")


def estimate_max_disparity(left: npt.ArrayLike, right: npt.ArrayLike) -> int:
    """Choose a disparity search range from the pair itself.

    Two estimates of the largest disparity, the larger taken: ORB features matched between the
    images (at half resolution from 256 px up; Hamming distance, mutual best match; matches
    more than 2 rows apart or with negative disparity discarded), their 99th percentile; and
    OpenCV's SGBM on the pair shrunk 4x (a dense map: it sees the textureless near ground
    sparse features miss), its 99.5th percentile. The range is 1.15 x that, rounded up to a
    multiple of 16 and clamped to [16, width / 2 rounded up to a multiple of 16] (112 px for a
    200 px wide pair). With too few features (fewer than 12
    matches) the dense estimate alone is used, or, on a pair too small for it, width / 8. A
    dark pair (brightest grey under a quarter of the range: a 12-bit camera's data in 16 bits)
    is first stretched by one gain, so its 8-bit copy keeps its features. Over
    the 17 GT scenes of ``../shared/data`` the range covers the GT's 99.5th percentile on all of
    them, in 8-41 ms (ORB alone, as before: 15 of them, KITTI 80 px for a GT that reaches 101
    px, in 50-200 ms). The feature matches also warn of a pair that looks swapped (most of
    them with a negative disparity) or unrectified (fewer than 20 % of them within 2 rows, and
    :func:`~stereovision.rectification_check.check_rectification` does not pass the pair).

    Parameters
    ----------
    left, right : ndarray
        Rectified images, grey or BGR, any dtype accepted by :func:`depth_map`.

    Returns
    -------
    int
        Largest disparity to search, in pixels (a multiple of 16).
    """
    fl = as_gray_float(left, "left", warn=False)
    fr = as_gray_float(right, "right", warn=False)
    top = max(float(fl.max()), float(fr.max()))
    if 0.0 < top < _DARK_PAIR:
        # A 12-bit camera's pair in 16 bits (at most 4095 / 65535): cut to 8 bits it kept 0-16
        # grey levels, too few for ORB's features. One gain for both keeps them comparable;
        # ordinary 8-bit pairs (all 17 GT scenes reach 240 and more) are not touched.
        fl, fr = fl / np.float32(top), fr / np.float32(top)
    gl = (fl * 255).astype(np.uint8)
    gr = (fr * 255).astype(np.uint8)
    check_pair(gl, gr)
    width = gl.shape[1]
    upper = _round_up(width / 2)
    fallback = min(upper, _round_up(width * _AUTO_FALLBACK_FRACTION))
    tops = [t for t in (_orb_top(gl, gr), _coarse_top(gl, gr)) if t is not None]
    if not tops:
        return fallback
    return int(min(upper, _round_up(max(tops) * _AUTO_MARGIN)))


def _orb_top(gl: npt.NDArray[np.uint8], gr: npt.NDArray[np.uint8]) -> float | None:
    """99th percentile of the ORB matches' disparities (full-resolution pixels); None with too
    few matches. A pair at least 256 px on its shorter side is matched at half resolution with
    1500 features: over the 17 GT scenes the range is the same as with 4000 at full resolution
    on 16 (laundry: 96 px instead of 144, for a GT reaching 77 px), in 5-33 ms instead of
    12-191 ms."""
    if min(gl.shape) < _AUTO_ORB_MIN_SIDE:
        return None
    s = 2 if min(gl.shape) >= _AUTO_ORB_HALF_FROM else 1
    full = (gl, gr)  # for the rows check that confirms an unrectified verdict
    if s > 1:
        size = (gl.shape[1] // s, gl.shape[0] // s)
        gl = np.asarray(cv2.resize(gl, size, interpolation=cv2.INTER_AREA), np.uint8)
        gr = np.asarray(cv2.resize(gr, size, interpolation=cv2.INTER_AREA), np.uint8)
    n = _AUTO_ORB_FEATURES if s > 1 else _AUTO_ORB_FEATURES_FULL
    orb = cv2.ORB_create(nfeatures=n)  # type: ignore[attr-defined]
    kl, dl = orb.detectAndCompute(gl, None)
    kr, dr = orb.detectAndCompute(gr, None)
    if dl is None or dr is None or len(kl) < _AUTO_MIN_MATCHES or len(kr) < _AUTO_MIN_MATCHES:
        return None
    matches = cv2.BFMatcher(cv2.NORM_HAMMING, crossCheck=True).match(dl, dr)
    pl = np.array([kl[m.queryIdx].pt for m in matches], dtype=np.float64).reshape(-1, 2)
    pr = np.array([kr[m.trainIdx].pt for m in matches], dtype=np.float64).reshape(-1, 2)
    d = pl[:, 0] - pr[:, 0]
    dy = np.abs(pl[:, 1] - pr[:, 1])
    same_row = dy <= _AUTO_DY_TOL / s
    _warn_if_unrectified(same_row, dy * s, *full)
    _warn_if_swapped(d[same_row] * s)
    keep = same_row & (d >= 0)
    if int(keep.sum()) < _AUTO_MIN_MATCHES:
        return None
    return float(np.percentile(d[keep], _AUTO_PERCENTILE)) * s


def _warn_if_unrectified(
    same_row: npt.NDArray[np.bool_],
    dy: npt.NDArray[np.float64],
    gl: npt.NDArray[np.uint8],
    gr: npt.NDArray[np.uint8],
) -> None:
    """Warn when the pair looks unrectified: few of the feature matches lie within
    ``_AUTO_DY_TOL`` rows of each other (two raw camera images, matched along rows they do not
    share, gave a map of noise without a word). ``dy`` in full-resolution pixels, ``gl``/``gr``
    the full-resolution grey pair.

    ORB's matches are cross-checked only, so on a repeated texture (a chessboard: 9 of OpenCV's
    13 sample pairs, rectified by their own calibration, had 8-20 % within 2 rows) most pair a
    corner with the wrong copy of it. The verdict is then confirmed by the rows check's SIFT
    matches (ratio-tested, :func:`~stereovision.rectification_check.check_rectification`): a
    pair they find on common rows is not warned about.
    """
    if same_row.size < _AUTO_MIN_MATCHES:
        return
    share = float(np.mean(same_row))
    if share < _UNRECTIFIED_SHARE:
        from stereovision.rectification_check import check_rectification

        if check_rectification(gl, gr).ok is True:
            return
        warnings.warn(
            f"the left and right images look unrectified: {share:.0%} of the feature matches "
            f"lie within {_AUTO_DY_TOL:g} rows of each other ({same_row.size} matches, median "
            f"{float(np.median(dy)):.0f} px apart; a rectified pair keeps most on one row); "
            # also said with a calibration given: one marked rectified is not applied
            f"give the calibration of the rig that took them {ADVICE['unrectified']['api']}",
            UserWarning,
            stacklevel=user_stacklevel(),
        )


def _warn_if_swapped(d: npt.NDArray[np.float64]) -> None:
    """Warn when the pair looks swapped: most feature matches that are off by more than a pixel
    have a negative disparity (``x_left < x_right``). On the 18 scenes of ``../shared/data``
    that share is at most 2 % as given and at least 98 % swapped (both extremes: playground,
    whose far sky puts a third of its matches within 1 px)."""
    off = d[np.abs(d) > 1.0]
    if off.size < _AUTO_MIN_MATCHES:
        return
    share = float(np.mean(off < 0))
    if share > _SWAPPED_SHARE:
        warnings.warn(
            f"the left and right images look swapped: {share:.0%} of the {off.size} feature "
            "matches have a negative disparity (x_left < x_right); pass the left camera's "
            "image first",
            UserWarning,
            stacklevel=user_stacklevel(),  # the user's line, through depth_map or match too
        )


def _coarse_top(gl: npt.NDArray[np.uint8], gr: npt.NDArray[np.uint8]) -> float | None:
    """99.5th percentile of OpenCV SGBM's disparities on the pair shrunk 4x (full-resolution
    pixels), searched up to half the width; None on a pair too small or with no disparity."""
    s = _AUTO_COARSE_SCALE
    h, w = gl.shape[0] // s, gl.shape[1] // s
    if h < _AUTO_COARSE_MIN_SIZE[0] or w < _AUTO_COARSE_MIN_SIZE[1]:
        return None
    a = cv2.resize(gl, (w, h), interpolation=cv2.INTER_AREA)
    b = cv2.resize(gr, (w, h), interpolation=cv2.INTER_AREA)
    n = _round_up(w / 2)
    sgbm = cv2.StereoSGBM_create(  # type: ignore[attr-defined]
        minDisparity=0,
        numDisparities=n,
        blockSize=5,
        P1=8 * 25,
        P2=32 * 25,
        disp12MaxDiff=1,
        uniquenessRatio=15,
        speckleWindowSize=50,
        speckleRange=2,
    )
    d = sgbm.compute(a, b).astype(np.float32) / 16.0
    d = d[d > 0]
    if d.size < _AUTO_MIN_MATCHES:
        return None
    return float(np.percentile(d, _AUTO_COARSE_PERCENTILE)) * s


class DepthChannels(ChannelOutputs, total=False):
    """Each channel's own output, :attr:`DepthResult.channels` (``return_channels=True``).

    Which keys are there depends on the method (``depth_map``'s ``method``):

    Attributes
    ----------
    gabor : GaborResult
        The Gabor phase channel's map (``"gabor"`` and ``"fused"``).
    gabor_remeasured : numpy.ndarray
        ``(H, W)`` float32: the re-measured Gabor map the vote used (``"fused"`` with
        ``refine``, :func:`stereovision.matching.fusion.remeasure`).
    mcgm, hopfield : Matches
        The graph-matching and Hopfield channels' matches (``"fused"``).
    members : FusionResult
        The valid members with their ``count`` and ``sources``, checked against the census map
        and within the range searched, as ``match(method="fused")`` gives them (``"fused"``;
        with ``semi_global=False`` there is no census map to check them against, as
        ``match(..., census_members=False)``, and with ``refine=False`` they are voted on the
        Gabor map as measured, as ``match(..., remeasure_gabor=False)``).
    sgm : numpy.ndarray
        ``(H, W)`` float32: the census semi-global disparity map (``"fused"``, ``"census"``,
        ``"fast"``; NaN = none).

    The keys but ``members`` are :class:`~stereovision.matching.fusion.ChannelOutputs`'s,
    :attr:`FusionResult.channel_outputs <stereovision.matching.fusion.FusionResult>`.
    """

    members: FusionResult


def _in_unit(metres: npt.NDArray[np.float32], unit: str) -> npt.NDArray[np.float32]:
    """A float32 copy of ``metres`` in ``unit`` (a key of ``UNIT_TO_METRES``, as
    :func:`~stereovision.triangulation.triangulate` takes)."""
    from stereovision.calibration import UNIT_TO_METRES

    unit = known_unit(unit, UNIT_TO_METRES)
    if unit == "m":
        return np.array(metres, dtype=np.float32)
    return (np.asarray(metres, np.float64) / UNIT_TO_METRES[unit]).astype(np.float32)


@dataclass(eq=False)  # array fields: == by identity (it raised on the arrays' truth value)
class DepthResult:
    """Output of :func:`depth_map`.

    One built by hand needs ``disparity``'s shape in ``confidence``, ``depth`` and
    ``depth_sigma`` (each but ``confidence`` may be None), and one row per point in
    ``points``, ``colors`` and ``pixels`` (a ValueError otherwise).

    Attributes
    ----------
    disparity : ndarray, float32 (H, W)
        ``x_left - x_right`` in pixels at left rectified pixels; NaN = no estimate.
    confidence : ndarray, float32 (H, W)
        Matcher confidence in [0, 1]; 0 where there is no estimate.
    depth : ndarray, float32 (H, W) or None
        Depth ``Z`` along the optical axis in metres (NaN where none); None without calibration.
        :meth:`depth_in`, :meth:`points_in` and :meth:`depth_sigma_in` give copies in feet (or
        mm, cm, in).
        NaN on the pixels the fill completed (confidence 0: their disparity is a guess from
        their neighbours, not a measurement; 16 % of the demo scene's pixels), and where the
        disparity is not above its predicted uncertainty ``sigma_d`` (``depth_sigma``): such a
        depth's one-sigma interval reaches infinity (the far sky, a wrong lock at the range's
        floor). :meth:`depth_counts` counts both.
    points : ndarray, float32 (N, 3)
        3-D points in metres in the left rectified camera frame (X right, Y down, Z forward), one
        per pixel with a depth, in row-major pixel order. Empty without calibration or with
        ``depth_map(cloud=False)``.
    colors : ndarray, uint8 (N, 3)
        RGB colour of each point, from the left image.
    pixels : ndarray, int32 (N, 2)
        ``(x, y)`` pixel of each point.
    method : str
        Matcher used.
    max_disparity : float
        Disparity range searched, ``[min_disparity, max_disparity]``, as given or estimated: an
        int for a whole number of pixels (the estimated range always is), else the float given
        (37.5 stays 37.5: the Gabor channel searches up to it, the census semi-global map up to
        the next whole pixel, 38).
    min_disparity : float
        Smallest disparity searched (``depth_map``'s ``min_disparity``, 0 by default).
    calibration : Calibration or None
        Calibration of the rectified pair the depth was computed with.
    left_rectified : ndarray, uint8 (H, W, 3) or None
        The left image as matched, BGR (rectified when ``calib`` rectified the pair; a copy,
        not the caller's buffer): the cloud's colours (also of the cloud :meth:`to_ply` rebuilds
        after ``cloud=False``; black without it) and ``overview.png``'s left panel.
    timings : dict
        Seconds spent per stage (``rectify``, ``prepare``, ``match``, ``refine`` and ``fill``
        when they ran, ``triangulate`` with a calibration).
    depth_sigma : ndarray, float32 (H, W) or None
        One-sigma depth uncertainty in metres where ``depth`` is known (NaN elsewhere; None
        without a calibration): ``sigma_Z = Z^2 sigma_d / (f B)`` with ``sigma_d`` the disparity
        uncertainty predicted from the confidence (:func:`disparity_sigma`), except on the
        pixels the refinement filled and, in the fused map, those only the census map
        measured: they take 0.63 px whatever their confidence (so ``disparity_sigma(
        confidence)`` gives back ``depth_sigma`` on the other pixels only). ``"census"`` and
        ``"fast"`` give every measured pixel one confidence (``second_confidence``, 0.5), hence
        one ``sigma_d``: 0.29 px when re-measured (``"census"``'s default), 0.63 px, as filled
        pixels, when not (``"fast"``'s default, and ``refine=False``): their census values are
        pixel-locked.
    channels : DepthChannels or None
        With ``return_channels=True``: each channel's own output by name (``"gabor"``: a
        :class:`~stereovision.matching.gabor.GaborResult`; with ``method="fused"`` also
        ``"mcgm"`` and ``"hopfield"`` :class:`~stereovision.Matches`, ``"members"``, the
        :class:`~stereovision.matching.fusion.FusionResult` with ``count`` and ``sources``, and
        ``"gabor_remeasured"``, the re-measured Gabor map the vote used; with ``"fused"``,
        ``"census"`` and ``"fast"``, ``"sgm"``: the census semi-global disparity map).
    limits : dict
        The limits :meth:`filtered` applied (``min_depth``, ``max_depth``, ``max_sigma``,
        ``max_relative_sigma``; empty for an unfiltered result).
    """

    disparity: npt.NDArray[np.float32]
    confidence: npt.NDArray[np.float32]
    depth: npt.NDArray[np.float32] | None
    points: npt.NDArray[np.float32]
    colors: npt.NDArray[np.uint8]
    pixels: npt.NDArray[np.int32]
    method: str
    max_disparity: float
    min_disparity: float = 0.0
    calibration: Calibration | None = None
    left_rectified: npt.NDArray[np.uint8] | None = field(default=None, repr=False)
    timings: dict[str, float] = field(default_factory=dict)
    depth_sigma: npt.NDArray[np.float32] | None = None
    channels: DepthChannels | None = field(default=None, repr=False)
    limits: dict[str, float] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        # one shape for the maps: a hand-made result with a (3, 3) depth beside a (2, 3)
        # disparity failed in NumPy's words in depth_counts() and filtered() ("operands could
        # not be broadcast together"), and a 1-D disparity in repr ("not enough values to unpack")
        shape = np.shape(self.disparity)
        if len(shape) != 2:
            raise ValueError(f"disparity: expected an (H, W) map, got shape {shape}")
        for name in ("confidence", "depth", "depth_sigma"):
            value = getattr(self, name)
            if (value is not None or name == "confidence") and np.shape(value) != shape:
                raise ValueError(
                    f"{name}: expected the disparity's shape {shape}, got {np.shape(value)}"
                )
        # one row per point in each: a hand-made result with 5 colours for 6 points was built
        # without a word, then failed in NumPy's words in filtered() ("boolean index did not
        # match indexed array along axis 0") or in to_ply's
        shapes = {name: np.shape(getattr(self, name)) for name in ("points", "colors", "pixels")}
        widths = {"points": 3, "colors": 3, "pixels": 2}
        for name, shape in shapes.items():
            if len(shape) != 2 or shape[1] != widths[name]:
                raise ValueError(
                    f"{name}: expected an (N, {widths[name]}) array, one row per point, got "
                    f"shape {shape}"
                )
        rows = [shape[0] for shape in shapes.values()]
        if len(set(rows)) != 1:
            raise ValueError(
                "points, colors, pixels: expected one row per point in each, got "
                f"{rows[0]}, {rows[1]} and {rows[2]} rows"
            )

    @property
    def valid(self) -> npt.NDArray[np.bool_]:
        """Boolean (H, W) mask of pixels with a disparity estimate."""
        return np.isfinite(self.disparity)

    @property
    def density(self) -> float:
        """Fraction of pixels with a disparity estimate."""
        return float(self.valid.mean())

    def depth_counts(self) -> dict[str, int]:
        """How many pixels have a disparity, how many a depth, and why the others have none.

        A pixel with a disparity gets no depth when its disparity was filled (confidence 0: a
        guess from its neighbours, see ``depth``; also an enclosed far region the fill took
        over, as 1,992 pixels of TartanAir's sky measured at 0 px with the scene's
        ``max_disparity`` of 48; 1,985 with 64, 2,127 with the automatic 32) or, measured,
        when it is not above its uncertainty ``sigma_d`` (its one-sigma depth interval reaches
        infinity) or lies outside the :attr:`limits` of :meth:`filtered`.

        Returns
        -------
        dict of str to int
            ``"pixels"`` (all), ``"disparity"`` (with a disparity), ``"depth"`` (with a depth),
            ``"filled"`` (a filled disparity, no depth) and ``"dropped"`` (a measured disparity,
            no depth: within ``sigma_d`` of ``d + doffs = 0``, or outside the limits);
            ``disparity == depth + filled + dropped``.

        Raises
        ------
        ValueError
            A result without depth (no calibration).
        """
        depth = self.require_depth()
        has_disp = np.isfinite(self.disparity)
        lost = has_disp & ~np.isfinite(depth)
        filled = int(np.count_nonzero(lost & (self.confidence == 0)))
        return {
            "pixels": int(depth.size),
            "disparity": int(np.count_nonzero(has_disp)),
            "depth": int(np.count_nonzero(np.isfinite(depth))),
            "filled": filled,
            "dropped": int(np.count_nonzero(lost)) - filled,
        }

    def __repr__(self) -> str:
        # A summary, not the arrays (the dataclass repr printed 3.5 kB of them at a prompt).
        h, w = self.disparity.shape[:2]
        parts = [
            f"method={self.method!r}",
            f"{w}x{h}",
            f"disparity [{self.min_disparity:g}, {self.max_disparity}] px, "
            f"{100 * self.density:.1f} % of pixels",
        ]
        if self.depth is not None:
            z = self.depth[np.isfinite(self.depth)]
            if z.size:
                # whole metres from 999.5 m, as the CLI's summary: ".3g" said "2e+03 m"
                lo, hi, mid = (figure_shown(float(v)) for v in (z.min(), z.max(), np.median(z)))
                share = 100 * z.size / self.depth.size
                parts.append(f"depth {lo}-{hi} m (median {mid} m) on {share:.1f} %")
            else:
                parts.append("no depth")
            parts.append(f"{len(self.points)} points")
        else:
            parts.append("no calibration: no depth")
        if self.limits:
            parts.append("limits " + ", ".join(f"{k}={v:g}" for k, v in self.limits.items()))
        if self.timings:
            parts.append(f"{1e3 * sum(self.timings.values()):.0f} ms")
        return f"DepthResult({'; '.join(parts)})"

    def require_depth(self) -> npt.NDArray[np.float32]:
        """``depth``, typed as an array: for code that passed a calibration and wants no None.

        ``depth`` is None when :func:`depth_map` had no metric calibration (none given, or an
        :class:`~stereovision.uncalibrated.UncalibratedRectification`), so a type checker sees
        ``ndarray | None``; this returns the same array (not a copy) or says why there is none.

        Returns
        -------
        ndarray
            float32 ``(H, W)`` metres, NaN where none: ``depth`` itself.

        Raises
        ------
        ValueError
            A result without depth (no calibration).
        """
        if self.depth is None:
            raise ValueError(NO_DEPTH.format(what="depth"))
        return self.depth

    def require_depth_sigma(self) -> npt.NDArray[np.float32]:
        """``depth_sigma``, typed as an array, as :meth:`require_depth` gives ``depth``.

        Returns
        -------
        ndarray
            float32 ``(H, W)`` one-sigma depth uncertainty in metres: ``depth_sigma`` itself.

        Raises
        ------
        ValueError
            A result without depth (no calibration).
        """
        if self.depth_sigma is None:
            raise ValueError(NO_DEPTH.format(what="depth uncertainty"))
        return self.depth_sigma

    def depth_in(self, unit: str = "m") -> npt.NDArray[np.float32]:
        """``depth`` in ``unit``: a converted copy (the result itself stays in metres).

        Parameters
        ----------
        unit : str
            ``"m"`` (default), ``"ft"``, ``"mm"``, ``"cm"`` or ``"in"``: the units
            :func:`~stereovision.triangulation.triangulate` takes
            (:data:`~stereovision.calibration.UNIT_TO_METRES`).

        Returns
        -------
        ndarray
            float32 ``(H, W)`` depth in ``unit``, NaN where none (1 m = 3.28084 ft).

        Raises
        ------
        ValueError
            An unknown unit (the message names the allowed ones), or a result without depth
            (no calibration; :meth:`require_depth`'s message).
        """
        return _in_unit(self.require_depth(), unit)

    def depth_sigma_in(self, unit: str = "m") -> npt.NDArray[np.float32]:
        """``depth_sigma`` in ``unit``, as :meth:`depth_in` gives ``depth``.

        Parameters
        ----------
        unit : str
            One of :data:`~stereovision.calibration.UNIT_TO_METRES` (default ``"m"``).

        Returns
        -------
        ndarray
            float32 ``(H, W)`` one-sigma depth uncertainty in ``unit``, NaN where none.

        Raises
        ------
        ValueError
            An unknown unit, or a result without depth (no calibration).
        """
        return _in_unit(self.require_depth_sigma(), unit)

    def points_in(self, unit: str = "m") -> npt.NDArray[np.float32]:
        """``points`` in ``unit``, as :meth:`depth_in` gives ``depth``.

        Parameters
        ----------
        unit : str
            One of :data:`~stereovision.calibration.UNIT_TO_METRES` (default ``"m"``).

        Returns
        -------
        ndarray
            float32 ``(N, 3)`` points in ``unit``, in the left rectified camera's frame (empty
            for a ``depth_map(cloud=False)`` result, as ``points`` is).

        Raises
        ------
        ValueError
            An unknown unit, or a result without depth (no calibration).
        """
        self.require_depth()  # no calibration: said as require_depth says it
        return _in_unit(self.points, unit)

    def point_image(self, *, filled: bool = False) -> npt.NDArray[np.float32]:
        """``(H, W, 3)`` float32 points in metres, NaN where the pixel has none.

        The left rectified camera's frame (X right, Y down, Z forward), image-shaped: what
        :func:`~stereovision.obstacle_mask`, :func:`~stereovision.laser_scan` and
        :func:`~stereovision.ground.occupancy_grid` take. It does not need the cloud
        (``cloud=False`` results have one too).

        Parameters
        ----------
        filled : bool
            False: the pixels with a depth only (the cloud's). True: also the filled pixels
            (confidence 0), guesses from their neighbours that get no depth of their own (not
            the measured pixels dropped within ``sigma_d`` of infinity), within the working
            range of :meth:`filtered` (none when it asked for a ``max_sigma`` or
            ``max_relative_sigma``: a guess has no uncertainty to pass). For obstacles the
            filled pixels count: on KITTI the obstacle recall is 0.975 with them and 0.65
            without, at the same precision (``benches/bench_ground.py``).

        Returns
        -------
        ndarray
            float32 ``(H, W, 3)``: Z is ``depth`` (and the guesses' own), X and Y are the
            cloud's (``points`` at ``pixels``, bit for bit).

        Raises
        ------
        ValueError
            A result without depth (no calibration).
        TypeError
            If ``filled`` is not True or False.
        """
        if not isinstance(filled, (bool, np.bool_)):
            # "no" (true) gave the filled pixels, None (false) left them out, without a word
            raise TypeError(f"filled: expected True or False, got {_shown(filled)}")
        if self.depth is None or self.calibration is None:
            raise ValueError(NO_DEPTH.format(what="3-D points"))
        cal = self.calibration
        cal = cal if cal.rectified else cal.rectified_calibration()
        # Z is ``depth`` itself, X and Y as the cloud computes them: rebuilt from ``disparity``
        # (clipped to the range) a value measured up to half a pixel past it was 3 % off
        z = self.depth
        lim = self.limits
        if filled and "max_sigma" not in lim and "max_relative_sigma" not in lim:
            z = z.copy()
            from stereovision.triangulation import _depth_from_disparity

            # filled pixels have no depth; a map wider than the calibration's images is warned
            # of at the caller's line (Calibration.depth_from_disparity's pointed at this one)
            guessed = _depth_from_disparity(self.disparity, cal, "m", user_stacklevel())
            # confidence 0 marks a filled disparity; a measured one without a depth was dropped
            # (within sigma_d of infinity, or outside the limits) and stays out
            guess = ~np.isfinite(z) & np.isfinite(guessed) & (self.confidence == 0)
            with np.errstate(invalid="ignore"):
                if "min_depth" in lim:
                    guess &= guessed >= lim["min_depth"]
                if "max_depth" in lim:
                    guess &= guessed <= lim["max_depth"]
            z[guess] = guessed[guess]
        h, w = z.shape
        k = cal.K1
        rx, ry, _, _ = _pixel_grids(
            w, h, float(k[0, 0]), float(k[1, 1]), float(k[0, 2]), float(k[1, 2])
        )
        pts = np.empty((h, w, 3), np.float32)
        np.multiply(rx.reshape(h, w), z, out=pts[..., 0])  # NaN where z is NaN
        np.multiply(ry.reshape(h, w), z, out=pts[..., 1])
        pts[..., 2] = z
        return pts

    def filtered(
        self,
        *,
        min_depth: float | None = None,
        max_depth: float | None = None,
        max_sigma: float | None = None,
        max_relative_sigma: float | None = None,
    ) -> DepthResult:
        """A copy whose depth, uncertainty and points keep only the depths asked for.

        What a robot keeps before planning: a working range, and the depths it can trust
        (``depth_sigma``, the one-sigma uncertainty, in metres or relative to the depth). The
        disparity and confidence maps are kept whole; only ``depth``, ``depth_sigma``,
        ``points``, ``colors`` and ``pixels`` lose the pixels outside the limits.

        Parameters
        ----------
        min_depth, max_depth : float, optional
            Working range in metres.
        max_sigma : float, optional
            Largest one-sigma depth uncertainty in metres.
        max_relative_sigma : float, optional
            Largest ``depth_sigma / depth`` (0.02 = 2 %).

        Returns
        -------
        DepthResult
            The filtered copy (this result is unchanged). Filtering a filtered result keeps
            the tighter of each limit (:attr:`limits`).

        Raises
        ------
        ValueError
            A result without depth (no calibration), a limit that is not a positive
            number (``min_depth`` may be 0), or a ``min_depth`` above ``max_depth``, one of
            them given to an earlier call (``filtered(max_depth=2.5).filtered(min_depth=3)``
            is refused as ``filtered(min_depth=3, max_depth=2.5)`` is).
            A hand-made result whose ``pixels`` are not integers inside the map.
        """
        if self.depth is None:
            raise ValueError(NO_DEPTH.format(what="depth to filter"))
        limits = {
            "min_depth": min_depth,
            "max_depth": max_depth,
            "max_sigma": max_sigma,
            "max_relative_sigma": max_relative_sigma,
        }
        for name, v in limits.items():
            ok_number = real_number(v)
            if v is not None and not (
                ok_number and _finite(v) and (v > 0 or (name == "min_depth" and v == 0))
            ):
                raise ValueError(f"{name}: expected a positive number, got {number_shown(v)}")
        tighter = {"min_depth": max}  # the other limits: the smaller of two
        merged = dict(self.limits)
        for name, v in limits.items():
            if v is not None:
                merged[name] = float(tighter.get(name, min)(merged.get(name, v), v))
        lo, hi = merged.get("min_depth"), merged.get("max_depth")
        if lo is not None and hi is not None and lo > hi:
            # a chained call's empty range was a silently empty result
            now = {k: limits[k] for k in ("min_depth", "max_depth") if limits[k] == merged[k]}
            earlier = [k for k in ("min_depth", "max_depth") if k not in now]
            said = f" ({' and '.join(earlier)} from an earlier filtered())" if earlier else ""
            lo = now.get("min_depth", _whole_or_float(lo))  # 3 as given, not 3.0
            hi = now.get("max_depth", _whole_or_float(hi))
            raise ValueError(
                f"min_depth, max_depth: an empty range, {_shown(lo)} > {_shown(hi)} m{said}"
            )
        z = self.depth
        keep = np.isfinite(z)
        # a limit beyond float32 (1e300, 2**200) is its inf in the comparison, which reads it
        # right; the cast's RuntimeWarning "overflow encountered in cast" is noise
        with np.errstate(invalid="ignore", over="ignore"):
            if min_depth is not None:
                keep &= z >= min_depth
            if max_depth is not None:
                keep &= z <= max_depth
            if max_sigma is not None or max_relative_sigma is not None:
                sig = self.depth_sigma
                if sig is None:
                    given = "max_sigma" if max_sigma is not None else "max_relative_sigma"
                    raise ValueError(f"{given}: this result has no depth_sigma")
                if max_sigma is not None:
                    keep &= sig <= max_sigma
                if max_relative_sigma is not None:
                    keep &= sig <= max_relative_sigma * z
        nan = np.float32(np.nan)
        sigma = None if self.depth_sigma is None else np.where(keep, self.depth_sigma, nan)
        if len(self.points):
            _check_pixels(self.pixels, z.shape)
            on = keep[self.pixels[:, 1], self.pixels[:, 0]]
            points, colors, pixels = self.points[on], self.colors[on], self.pixels[on]
        else:
            points, colors, pixels = self.points, self.colors, self.pixels
        return dataclasses.replace(
            self,
            limits=merged,
            # a copy: writing into the filtered maps must not change this result's
            disparity=self.disparity.copy(),
            confidence=self.confidence.copy(),
            left_rectified=None if self.left_rectified is None else self.left_rectified.copy(),
            timings=dict(self.timings),  # the same dict: a stage timed on one was on both
            # so too the channels' dict (their arrays are shared, as return_channels gives them)
            channels=None if self.channels is None else self.channels.copy(),
            depth=np.where(keep, z, nan).astype(np.float32),
            depth_sigma=None if sigma is None else sigma.astype(np.float32),
            points=points,
            colors=colors,
            pixels=pixels,
        )

    def to_ply(self, path: str | Path) -> Path:
        """Write the coloured point cloud as a binary PLY (metres), atomically.

        Parameters
        ----------
        path : str or os.PathLike
            Destination ``.ply`` file.

        Returns
        -------
        pathlib.Path
            The path written.

        Raises
        ------
        ValueError
            If the result has no calibration (no metric points to write), or ``path`` is empty
            or not a ``.ply`` file.
        """
        from stereovision.io import write_ply

        if self.depth is None:
            raise ValueError(NO_DEPTH.format(what="point cloud"))
        # '' was ": to_ply writes a .ply file", naming nothing
        as_path(path, file=True)
        if Path(path).suffix.lower() != ".ply":
            raise ValueError(
                f"{path}: to_ply writes a .ply file (export.write_pcd writes .pcd, "
                "export.write_npz .npz)"
            )
        points, colors = self._cloud_points()
        return Path(write_ply(path, points, colors))

    def _cloud_points(self) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8]]:
        """``(points, colors)`` of the cloud, rebuilt from the depth map for ``cloud=False``.

        What :meth:`to_ply` and :func:`stereovision.export.write_cloud_ply` write: the result's
        own ``points`` and ``colors`` when it has them, otherwise the same cloud ``depth_map``
        would have built (one point per pixel with a depth, row-major; black without the left
        image).
        """
        points, colors = self.points, self.colors
        cal, depth = self.calibration, self.depth
        if len(points) == 0 and cal is not None and depth is not None:  # depth_map(cloud=False)
            left = self.left_rectified
            if left is None or left.ndim != 3:
                left = np.zeros((*depth.shape, 3), np.uint8)
            points, colors, _ = _cloud(depth, cal, left)
        return points, colors


def _check_pixels(pixels: npt.NDArray[np.int32], shape: tuple[int, ...]) -> None:
    """Refuse ``(x, y)`` pixels that are not integers inside a map of ``shape``: a hand-made
    result's x of -1 read the map's last column without a word, an x past it was NumPy's
    "index 2 is out of bounds for axis 0 with size 2"."""
    px = np.asarray(pixels)
    h, w = shape[:2]
    if px.dtype.kind not in "iu":
        raise ValueError(f"pixels: expected integer (x, y) pixels, got dtype {px.dtype}")
    xs, ys = px[:, 0], px[:, 1]
    if xs.min() < 0 or ys.min() < 0 or xs.max() >= w or ys.max() >= h:
        raise ValueError(
            f"pixels: each point's (x, y) must lie in the {w}x{h} map, got x "
            f"{xs.min()} to {xs.max()}, y {ys.min()} to {ys.max()}"
        )


def disparity_sigma(
    confidence: npt.ArrayLike, *, refined: bool = True, filled: npt.ArrayLike | None = None
) -> npt.NDArray[np.float32]:
    """Predicted one-sigma disparity error (px) of a pixel from its matcher confidence.

    ``sigma_d = max(s0 + slope * conf, s_min)``: a line through the robust error spread per
    confidence bin, measured on the 17 shared GT scenes; ``0.405 - 0.221 conf`` (at least
    0.18 px) for the refined map :func:`depth_map` gives by default, ``0.74 - 0.52 conf`` (at
    least 0.2 px) for the Gabor channel as it comes (``refine=False``). Pixels the refinement
    filled have a spread of their own: 0.63 px.

    Parameters
    ----------
    confidence : array_like
        Confidence in ``[0, 1]`` (values outside are clipped; NaN counts as 0, as in
        :func:`depth_map`'s depth sigma).
    refined : bool
        Whether the map was refined (:mod:`stereovision.refine`).
    filled : array_like of bool, optional
        Pixels the refinement filled (same shape as ``confidence``; a single bool for every
        pixel).

    Returns
    -------
    numpy.ndarray
        float32 array of the same shape, pixels.

    Raises
    ------
    ValueError
        If ``confidence`` is not real numbers (None, complex, text), or ``filled`` is not of
        its shape.
    TypeError
        If ``refined`` is not True or False.
    """
    if not isinstance(refined, (bool, np.bool_)):
        # as depth_map's switches: "no" (true) gave the refined line, None (false) the raw one
        raise TypeError(f"refined: expected True or False, got {_shown(refined)}")
    s0, slope, s_min = _SIGMA_REFINED if refined else _SIGMA_RAW
    raw = _real_array(confidence)
    # None became a NaN sigma, a complex map lost its imaginary part with NumPy's warning only
    if raw is None:
        got = np.asarray(confidence).dtype
        raise ValueError(f"confidence: expected real numbers in [0, 1], got dtype {got}")
    c = np.clip(raw.astype(np.float32), 0.0, 1.0)
    # NaN passed the clip and gave a NaN sigma, where the depth kernel (triangulation.rs) takes
    # it as 0: the two gave different sigmas for one confidence
    c = np.where(np.isnan(c), np.float32(0), c)
    out = np.maximum(np.float32(s0) + np.float32(slope) * c, np.float32(s_min))
    if filled is not None:
        mask = np.asarray(filled, bool)
        # a single True or False says it of every pixel, as it did before shapes were checked
        if mask.ndim and mask.shape != c.shape:
            # NumPy broadcast a (1, W) mask over every row, and refused others in its own words
            raise ValueError(f"filled: expected the confidence's shape {c.shape}, got {mask.shape}")
        out = np.where(mask, np.float32(_SIGMA_FILLED), out)
    return np.asarray(out, np.float32)


def _run_matcher(
    method: str,
    left: np.ndarray,
    right: np.ndarray,
    d_min: float,
    d_max: float,
    params: dict,
    channels: DepthChannels | None = None,
    remeasure: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """``(disparity, confidence, coarse)``: ``coarse`` marks the pixels whose value has a
    larger spread than the confidence line predicts (the census map's, in ``"fused"``)."""
    if method == "gabor":
        from stereovision.matching.gabor import gabor_disparity

        res = gabor_disparity(left, right, max_disparity=d_max, min_disparity=d_min, **params)
        if channels is not None:
            channels["gabor"] = res
        return res.disparity, res.confidence, None
    if method == "fused":
        from stereovision.matching import fusion

        dense_kw = {k: params.pop(k) for k in list(params) if k in fusion.DENSE_DEFAULTS}
        semi_global = bool(params.pop("semi_global", True))  # a bool (_refuse_unknown_params)
        fr = fusion.fuse_pair(
            left,
            right,
            max_disparity=d_max,
            min_disparity=d_min,
            remeasure_gabor=remeasure,
            dense_sgm=semi_global,
            census_members=False,
            **params,
        )
        g = fr.channel_outputs["gabor"]
        base = fr.channel_outputs.get("gabor_remeasured", g.disparity)
        only_second = np.zeros(base.shape, bool)
        disp, conf = fusion.fused_dense(
            base,
            g.confidence,
            fr.dispx,
            second=fr.channel_outputs.get("sgm"),
            guide=left,
            _only_second=only_second,
            **dense_kw,
        )
        if channels is not None:
            # The dense map anchors on all members (the census check's dropped ones are 96 %
            # right and the census map checks the dense map anyway); the members reported are
            # the checked ones, as ``match(method="fused")`` gives them.
            sgm = fr.channel_outputs.get("sgm")
            members = fusion.census_clear(fr, sgm) if sgm is not None else fr
            # and, as match() keeps them, in the range searched
            members = fusion._members_in_range(members, d_min, d_max)
            channels.update({**fr.channel_outputs, "members": members})
        return disp, conf, only_second
    if method in ("census", "fast"):
        from stereovision.matching import fusion
        from stereovision.matching.sgm import sgm_disparity

        if method == "fast":
            # Three paths in one pass, no cost volume (OpenCV SGBM-3WAY's path set).
            params.setdefault("paths", 3)
        dense_kw = {k: params.pop(k) for k in list(params) if k in _CENSUS_DENSE}
        sgm = sgm_disparity(left, right, max_disparity=d_max, min_disparity=d_min, **params)
        if channels is not None:
            channels["sgm"] = sgm
        if remeasure:
            # Sub-pixel by the refinement's correlation (the census map's parabola vertices are
            # pixel-locked); a value it moves by more than _CENSUS_REMEASURE_STEP px jumped to
            # another peak and keeps the census value.
            c0 = np.where(np.isfinite(sgm), np.float32(0.5), np.float32(0))
            r = fusion.remeasure(left, right, sgm, c0, max_disparity=d_max, min_disparity=d_min)
            with np.errstate(invalid="ignore"):
                near = np.abs(r - sgm) <= _CENSUS_REMEASURE_STEP
            sgm = np.where(near, r, sgm).astype(np.float32)
        # The fused dense map with no Gabor map and no members: the census map's values, with
        # its speckles and the pixels fattened past an edge (steps 6 and 7) dropped.
        empty = np.full(sgm.shape, np.nan, np.float32)
        disp, conf = fusion.fused_dense(
            empty, np.zeros_like(empty), empty, second=sgm, guide=left, **dense_kw
        )
        # Re-measured, its pixels spread as the refined line predicts at their confidence 0.5
        # (pooled over the 17 GT scenes: 0.275 px, the fused map's 0.278); as it comes, as
        # filled pixels do (a median error of 0.37 px).
        return disp, conf, None if remeasure else np.isfinite(disp)
    raise ValueError(f"unknown method {method!r}: expected one of {', '.join(METHODS)}")


def fill_holes(
    disp: npt.NDArray[np.float32],
    left_bgr: npt.NDArray[np.uint8],
    *,
    fused: bool,
    floor: float = 0.0,
    grey: npt.NDArray[np.float32] | None = None,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.bool_] | None]:
    """``depth_map``'s fill (``fill=True``): ``(filled map, enclosed far regions or None)``.

    The planes of colour segments (:func:`stereovision.matching.planes.fill_planes`), then the
    reference row rule. ``fused``: the colour side rule between the two
    (:func:`stereovision.matching.planes.side_fill`; on the Gabor channel's own holes it moved
    the 17-scene mean bad-2.0 by 0.01 point, so that path keeps the row rule), and the dark
    regions locked to the range's ``floor`` inside a nearer surround take the surround's value
    (:func:`stereovision.matching.fusion.fill_enclosed_far`); their mask is returned (they get
    no depth: the locked values were not the scene's).

    Parameters
    ----------
    disp : numpy.ndarray
        ``(H, W)`` float32 disparity, NaN = hole.
    left_bgr : numpy.ndarray
        The left (rectified) image, ``(H, W, 3)`` BGR uint8.
    fused : bool
        The fused map's fill (side rule, enclosed far regions) or the Gabor channel's.
    floor : float
        The range's smallest disparity (``min_disparity``).
    grey : numpy.ndarray, optional
        The left image as ``(H, W)`` float32 in ``[0, 1]`` (``depth_map``'s); None: made from
        ``left_bgr``.

    Returns
    -------
    disparity : numpy.ndarray
        ``(H, W)`` float32, NaN only in rows with no valid value.
    far : numpy.ndarray or None
        ``(H, W)`` bool, the enclosed far regions (``fused`` only).
    """
    from stereovision.baselines import row_fill
    from stereovision.matching.planes import fill_planes, side_fill

    planed = fill_planes(disp, left_bgr)
    if not fused:
        return row_fill(planed).astype(np.float32), None
    from stereovision.matching.fusion import fill_enclosed_far

    sided = row_fill(side_fill(planed, left_bgr))
    # The far regions are found on the row rule's fill: the side rule can give a locked
    # region's holes a nearer neighbour's value, and the region would then not be found whole.
    gl = as_gray_float(left_bgr, "left") if grey is None else grey
    base, far = fill_enclosed_far(row_fill(planed), gl, floor=floor)
    return np.where(far, base, sided).astype(np.float32), far


@functools.lru_cache(maxsize=2)
def _pixel_grids(
    w: int, h: int, fx: float, fy: float, cx: float, cy: float
) -> tuple[
    npt.NDArray[np.float32], npt.NDArray[np.float32], npt.NDArray[np.int32], npt.NDArray[np.int32]
]:
    """Flat per-pixel ``(x - cx) / fx``, ``(y - cy) / fy``, ``x`` and ``y`` (int32), read-only.

    Cached (the last two sizes and calibrations: 16 bytes per pixel each, 33 MB at 1080p): a live
    stream triangulates every frame with the same calibration, and a lookup by flat index is ~5x
    faster than numpy's integer division of the indices.
    """
    xs = np.ascontiguousarray(np.broadcast_to(np.arange(w, dtype=np.int32), (h, w))).ravel()
    ys = np.repeat(np.arange(h, dtype=np.int32), w)
    rx = ((xs - cx) / fx).astype(np.float32)
    ry = ((ys - cy) / fy).astype(np.float32)
    for a in (rx, ry, xs, ys):
        a.flags.writeable = False
    return rx, ry, xs, ys


def _depth_rectified(
    measured_disp: npt.NDArray[np.float32],
    conf: npt.NDArray[np.float32],
    calib: Calibration,
    refined: bool,
    filled: npt.NDArray[np.bool_] | None,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """Depth in metres and its one-sigma uncertainty of a rectified pair's measured disparity.

    ``Z = f B / (d + doffs)`` (:func:`stereovision.triangulation.depth_from_disparity`) in
    float32 where ``measured_disp`` has a value (NaN = not measured: row-filled pixels are
    guesses, not measurements, and get no depth; nor do pixels with ``d + doffs <= sigma_d``);
    ``sigma_Z = Z sigma_d / (d + doffs)``
    (:func:`disparity_sigma`). One parallel Rust pass; ``tests/reference/depth_ref.py`` is the
    same maths in NumPy. Pixels the refinement filled are passed with confidence -1, the
    kernel's mark for ``s_fill``.
    """
    from stereovision import _core

    s0, slope, s_min = _SIGMA_REFINED if refined else _SIGMA_RAW
    c = np.ascontiguousarray(conf, dtype=np.float32)
    if filled is not None and filled.any():
        c = np.where(filled, np.float32(-1), c)
    return _core.depth_rectified(
        np.ascontiguousarray(measured_disp, dtype=np.float32),
        c,
        calib.focal_px * calib.baseline_m,
        calib.doffs_px,
        s0,
        slope,
        s_min,
        _SIGMA_FILLED,
    )


def _cloud(
    depth: npt.NDArray[np.float32], calib: Calibration, left_bgr: npt.NDArray[np.uint8]
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8], npt.NDArray[np.int32]]:
    """Points (metres), RGB colours and ``(x, y)`` pixels of every pixel with a depth.

    ``X, Y`` as :func:`stereovision.triangulation.reproject`, on the valid pixels only and by
    table lookup (no ``(H, W, 3)`` image, no integer division): live rates.
    """
    h, w = depth.shape
    idx = np.flatnonzero(np.isfinite(depth))
    k = calib.K1
    rx, ry, xs, ys = _pixel_grids(
        w, h, float(k[0, 0]), float(k[1, 1]), float(k[0, 2]), float(k[1, 2])
    )
    z = depth.ravel()[idx]
    points = np.empty((len(idx), 3), np.float32)
    np.multiply(np.take(rx, idx), z, out=points[:, 0])
    np.multiply(np.take(ry, idx), z, out=points[:, 1])
    points[:, 2] = z
    rgb = cv2.cvtColor(left_bgr, cv2.COLOR_BGR2RGB).reshape(-1, 3)
    colors: npt.NDArray[np.uint8] = np.take(rgb, idx, axis=0)
    pixels: npt.NDArray[np.int32] = np.stack([np.take(xs, idx), np.take(ys, idx)], axis=1)
    return points, colors, pixels


# Why each method searching from 0 px does: the words of :func:`_from_zero`.
_FROM_ZERO = {
    "mcgm": "graph matching takes no negative disparity",
    "hopfield": "the Hopfield network takes no negative disparity",
    "best": "the best-match search takes no negative disparity",
}
# "fused"'s sparse channels, each by the name its refusal gives it
_SPARSE_CHANNELS = {"mcgm": "graph-matching", "hopfield": "Hopfield"}


def _from_zero(
    method: str,
    min_disparity: float,
    takers: tuple[str, ...],
    channels: Iterable[str] | None = None,
) -> ValueError:
    """The refusal of a negative ``min_disparity`` by a method searching from 0 px
    (:data:`_FROM_ZERO`), naming the methods that take one (``takers``: depth_map's and
    match()'s differ): the sparse matchers' own error ("must be a non-negative number of
    pixels, got -2.0") named neither the method nor those. ``"fused"``'s words name the
    sparse ones of its ``channels`` (checked already): with ``("gabor", "hopfield")`` they
    named a graph-matching channel that does not run. None: fuse_pair's default, all three."""
    names = ", ".join(repr(t) for t in takers[:-1])
    alternatives = (
        f"method={names} or {takers[-1]!r} search" if names else f"method={takers[-1]!r} searches"
    )
    if method == "fused":
        runs = set(_SPARSE_CHANNELS if channels is None else channels)
        sparse = [said for name, said in _SPARSE_CHANNELS.items() if name in runs]
        why = (
            f"its {' and '.join(sparse)} channels take no negative disparity"
            if len(sparse) > 1
            else f"its {sparse[0]} channel takes no negative disparity"
        )
    else:
        why = _FROM_ZERO[method]
    return ValueError(
        f"min_disparity: method={method!r} searches from 0 px ({why}), "
        f"got {_px(min_disparity)}; {alternatives} a negative range"
    )


def _refuse_range_types(max_disparity: object, min_disparity: object) -> None:
    """A disparity range that is not one real number (a string, a bool, an array, None for
    ``min_disparity``; None for ``max_disparity`` is "estimated") refused as a TypeError, in the
    words :func:`depth_map` and :func:`~stereovision.match` share."""
    for name, value in (("max_disparity", max_disparity), ("min_disparity", min_disparity)):
        if value is None and name == "max_disparity":
            continue  # estimated from the images
        # real_number: a timedelta (an np.integer) passed here, refused later in other words
        if not real_number(value):
            raise TypeError(f"{name}: expected a number of pixels, got {_shown(value)}")


def depth_map(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    calib: Calibration | UncalibratedRectification | None = None,
    *,
    method: str = "fused",
    max_disparity: float | None = None,
    min_disparity: float = 0.0,
    fill: bool | None = None,
    refine: bool | None = None,
    return_channels: bool = False,
    cloud: bool = True,
    progress: Callable[[str], None] | None = None,
    **params: Any,
) -> DepthResult:
    """Disparity, metric depth and a coloured point cloud from a stereo pair.

    Parameters
    ----------
    left, right : ndarray
        The two images, (H, W) grey or (H, W, 3) BGR as ``cv2.imread`` gives, uint8, uint16 or
        float in [0, 1]. Raw camera images when ``calib`` is an unrectified rig calibration
        (they are rectified first); already rectified images otherwise.
    calib : Calibration or UncalibratedRectification, optional
        Rig calibration. Without it only disparity is computed (``depth`` is None); so too with
        the homographies :func:`~stereovision.uncalibrated.rectify_uncalibrated` found for a rig
        without a calibration, which rectify the raw pair first (their search range is the
        default ``max_disparity``).
    method : {"fused", "gabor", "census", "fast"}
        ``"fused"`` (default): the Gabor map corrected and completed by the valid members where
        the Gabor, graph-matching and Hopfield channels agree (algorithms.md D), checked and
        completed by a census semi-global map (:func:`stereovision.matching.fusion.fused_dense`;
        the most accurate: mean bad-2.0 6.7 % over the 17 GT scenes, README). ``"gabor"``: the
        dense Gabor phase channel alone (algorithms.md A), 3-4 times faster and less accurate
        (16 % filled): the choice for a live view. ``"census"``: the census semi-global map
        alone (:mod:`stereovision.matching.sgm`, not one of the paper's channels), re-measured
        to sub-pixel, its speckles and edge-fattened pixels dropped as in the fused map, then
        filled: about 2.2 times faster than ``"fused"`` (median over the 17 GT scenes) and as
        accurate on average, but worse where the census cost is fooled (a periodic texture on
        ETH3D playground: bad-2.0 0.85 x SGBM-3WAY + fill's, ``"fused"`` 0.52 x; README
        "Choosing a mode"). ``"fast"``: ``"census"`` over three aggregation paths (left to right,
        right to left, top to bottom: OpenCV SGBM-3WAY's set) in one pass with no cost volume
        (``paths=3``), not re-measured (``refine=False`` unless asked), checked and filled the
        same way: about 0.65 x ``"census"``'s time (0.85 x without its re-measure; median over
        the 17 GT scenes), mean bad-2.0 0.55 x SGBM-3WAY + fill's
        (``"census"`` 0.51 x), worse than it only on ETH3D playground (1.05 x); unfilled
        (``fill=False``) it measures more pixels than the Gabor channel with half its errors
        at 0.75 x its frame rate (README "Choosing a mode").
    max_disparity : float, optional
        Largest disparity searched, in pixels (the census semi-global map searches whole pixels,
        up to the next one above a fractional range). None chooses it from the images
        (:func:`estimate_max_disparity`: the larger of ORB matches' 99th percentile and a
        coarse SGBM map's 99.5th, times 1.15, a multiple of 16).
    min_disparity : float
        Smallest disparity searched (default 0). Negative for ``"gabor"``, ``"census"`` and
        ``"fast"`` only: ``"fused"``'s graph-matching and Hopfield channels search from 0.
    fill : bool, optional
        Fill holes: first with the plane fitted to the measured pixels of the hole's colour
        segment, where one fits (:func:`stereovision.matching.planes.fill_planes`), then with
        the reference row rule (evaluation.md: each hole takes the smaller of the nearest valid
        disparities left and right of it, i.e. the background, which is what an occluded pixel
        shows). Over the 17 GT scenes the planes lower the mean bad-2.0 ratio to SGBM-3WAY +
        fill from 0.63 to 0.53 (``"fused"``) and from 1.44 to 1.01 (``"gabor"``, whose refinement
        then only re-measures); they cost about 60 ms on a 900x750 frame. ``"fused"`` runs the
        colour side rule between the two (:func:`stereovision.matching.planes.side_fill`: a
        hole whose left neighbour is the nearer one is no occlusion, and takes the side its
        colour matches; mean ratio 0.519 -> 0.514, largest 0.795 -> 0.779). None (default) =
        the method's own choice: ``"fused"`` returns a dense map (filled), ``"gabor"`` leaves a
        pixel it is not sure of NaN. Filled pixels keep confidence 0 and get no depth or 3-D
        point. ``"fused"`` then fills dark regions locked to the range's floor inside a nearer
        surround (:func:`stereovision.matching.fusion.fill_enclosed_far`) the same way.
    refine : bool, optional
        Re-measure the disparity to sub-pixel precision by a correlation that follows the
        surface (:func:`stereovision.refine.refine_disparity`). ``"gabor"``: the output is
        re-measured, pixels where the correlation disagrees are dropped, and holes next to
        measured pixels are filled where it peaks clearly (filled pixels are measurements with
        confidence 0.25 and get a depth); it takes 2-3 times the Gabor channel's time. With
        ``fill=True`` only the re-measure runs (pixels it drops keep the Gabor value, as in
        ``"fused"``) and the fill completes the map: a more accurate map, with depth on fewer
        pixels (terrace: 247 k instead of 288 k; the fill gives none). ``"fused"``:
        the Gabor map is re-measured before the vote
        (:func:`stereovision.matching.fusion.remeasure`, about the Gabor channel's time, beside
        the sparse channels). ``"census"``: the census map is re-measured the same way (a value
        the correlation moves by more than 1 px keeps the census value), and so is ``"fast"``'s
        when asked. None (default) = on, off for ``"fast"``; live use can pass False.
    return_channels : bool
        Keep each channel's own output in :attr:`DepthResult.channels`.
    cloud : bool
        Compute ``points``, ``colors`` and ``pixels`` (default). False leaves them empty, for
        live depth that does not use the cloud every frame (at VGA it is about a tenth of the
        frame time); :meth:`DepthResult.to_ply` still writes the full cloud.
    progress : callable, optional
        Called with a stage name as the pipeline advances.
    **params
        Passed to the matcher (see :func:`stereovision.matching.gabor.gabor_disparity`). For
        ``"fused"``: :func:`stereovision.matching.fusion.fuse`'s options,
        :func:`~stereovision.matching.fusion.fuse_pair`'s ``channels`` (``"gabor"``, on whose
        map the dense map is built, and one or both sparse ones), ``check_members`` and
        ``edge_members`` (its other switches are this function's ``refine`` and
        ``semi_global``), the dense map's (:data:`stereovision.matching.fusion.DENSE_DEFAULTS`),
        and ``semi_global`` (default True: the census semi-global map,
        :mod:`stereovision.matching.sgm`, completes and checks the Gabor map; False skips it,
        about 0.15 s less on a 0.35-megapixel pair). For ``"census"`` and ``"fast"``:
        :data:`stereovision.matching.sgm.DEFAULTS`' keys and the dense map's
        ``second_confidence`` (the confidence of every measured pixel, default 0.5),
        ``speckle_area``, ``speckle_diff``, ``edge_radius``, ``edge_ratio`` and ``edge_jump``.

    Returns
    -------
    DepthResult

    Raises
    ------
    ValueError
        Bad images (shape, dtype, empty, NaN, mismatched sizes), a bad range or unknown method,
        a parameter the method does not take (the message names those it does; a misspelling
        of this function's own keyword, ``max_disparty=``, named as such); a range no pixel
        can match in (``min_disparity`` not below the image width, or
        ``max_disparity`` not above minus it) or one float32 cannot tell apart (10 to
        10.0000001), a negative ``min_disparity`` with ``method="fused"``.
    TypeError
        A switch that is no bool: ``fill`` or ``refine`` (which also take None),
        ``return_channels``, ``cloud`` or ``"fused"``'s ``semi_global``, ``check_members`` or
        ``edge_members`` (1 and 0 are refused too); a ``max_disparity`` or ``min_disparity``
        that is no number, a ``progress`` that is not callable, or ``calibration=`` given in
        ``calib``'s place.
    MemoryError
        With ``method="fused"`` or ``"census"``, before the census semi-global map allocates
        more than the memory available (3 bytes per pixel and disparity level: about 14 GiB for
        a 3840 x 2160 pair over 576 px, 2 GiB at 1920 x 1080 over 288 px). With any method,
        when a kernel's image-sized buffer cannot be allocated: the message names the buffer
        and its size, and the process goes on.

    Examples
    --------
    >>> import numpy as np, stereovision as sv
    >>> rng = np.random.default_rng(0)
    >>> left = rng.random((64, 96), dtype=np.float32)
    >>> right = np.roll(left, -4, axis=1)  # everything 4 px closer on the right image
    >>> res = sv.depth_map(left, right, max_disparity=16)
    >>> bool(abs(np.nanmedian(res.disparity) - 4.0) < 0.1)
    True
    """
    t0 = time.perf_counter()
    timings: dict[str, float] = {}

    def stage(name: str) -> None:
        nonlocal t0
        now = time.perf_counter()
        timings[name] = now - t0
        t0 = now
        if progress is not None:
            progress(name)

    # a str first: an array as the method failed in the test ("truth value ... ambiguous")
    if not isinstance(method, str) or method not in METHODS:
        # match's own ("hopfield", "best", "mcgm") said as unknown, as if no matcher had it,
        # where depth_map(l, r, "hopfield") names stereovision.match
        other = (
            f" ({method!r} is a method of stereovision.match, not of depth_map)"
            if isinstance(method, str) and method in _ALL_METHODS
            else ""
        )
        raise ValueError(
            f"unknown method {_shown(method)}: expected one of {', '.join(METHODS)}{other}"
        )
    if "calibration" in params:  # the result's field is .calibration; the argument is calib
        raise TypeError("depth_map: the calibration is the argument calib, not calibration")
    names = params.get("channels")
    if isinstance(names, Iterable) and not isinstance(names, Collection):
        # read once, as fuse_pair does: the checks would use up a one-pass iterator, and an
        # iterable that is no collection (no len) was refused though fuse_pair and match take it
        params["channels"] = tuple(names)
    _refuse_unknown_params(method, params)
    # The switches and the range are checked for their type first: "no" would be true, True
    # a disparity of 1, and "32" failed in NumPy's isfinite.
    for name, flag in (("fill", fill), ("refine", refine)):
        if flag is not None and not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"{name}: expected True, False or None, got {_shown(flag)}")
    # so too the output switches ("no" returned the channels, None dropped the cloud) and the
    # callback (3 failed after the rectification, "'int' object is not callable")
    for name, flag in (("return_channels", return_channels), ("cloud", cloud)):
        if not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"{name}: expected True or False, got {_shown(flag)}")
    if progress is not None and not callable(progress):
        raise TypeError(
            f"progress: expected a callable taking a stage name, or None, got {_shown(progress)}"
        )
    _refuse_range_types(max_disparity, min_disparity)
    # NaN, inf or an int beyond 64 bits refused in its own words (finite_number, as below for
    # max_disparity), before the images' work as the refusal after it
    finite_number(min_disparity, "min_disparity")
    if method == "fused" and min_disparity < 0 and max_disparity is None:
        # no range given to be refused first: up front, not after the rectification and the
        # automatic range's estimate (1.4 s of a 3600 x 3000 pair, for nothing)
        raise _from_zero(
            "fused", min_disparity, ("gabor", "census", "fast"), params.get("channels")
        )
    left_bgr = as_bgr_uint8(left, "left")
    right_bgr = as_bgr_uint8(right, "right")
    # Each image is validated by as_bgr_uint8; the pair check without check_pair's grey
    # conversions (the grey pair is made once, below). Before the grey one is made BGR: a grey
    # and a colour image are not a pair (match() refuses them too).
    shapes = [np.shape(left), np.shape(right)]
    if left_bgr.shape != right_bgr.shape or len(shapes[0]) != len(shapes[1]):
        raise pair_shape_error(shapes[0], shapes[1])
    if np.may_share_memory(left_bgr, left):
        # the result keeps the left image (its cloud's colours, exports): not the caller's
        # buffer, which a camera loop refills (cap.read(frame)) before the cloud is written
        left_bgr = left_bgr.copy()

    # A 16-bit or float pair is matched on its own grey levels, rectified as they are: the 8-bit
    # BGR copy (for colours and the fill) keeps 8 bits of them (a dark 13-bit exposure of ETH3D
    # terrace through an identity raw rig: bad-2.0 11.1 % on the 8-bit copy, 1.6 % on its own
    # levels). An 8-bit pair keeps its path (grey levels of the rectified BGR images).
    deep = np.asarray(left).dtype != np.uint8 or np.asarray(right).dtype != np.uint8
    grey: tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]] | None = None
    h, w = left_bgr.shape[:2]
    # the range an uncalibrated rectification suggests is no more the caller's than an estimate
    rig_range = max_disparity is None and isinstance(calib, UncalibratedRectification)
    rig, calib, max_disparity = _rig_to_warp_by(calib, w, h, max_disparity)
    if rig is not None:
        if deep:
            grey = _rectify_grey(rig, left, right)
        left_bgr, right_bgr = rig.rectify(left_bgr, right_bgr)
        left, right = left_bgr, right_bgr
        if calib is not None:
            calib = calib.rectified_calibration()
    stage("rectify")
    if grey is not None:
        gl, gr = grey
    else:
        # as_bgr_uint8 warned about a 12-bit pair in 16 bits already (once per image)
        gl = as_gray_float(left, "left", warn=False)
        gr = as_gray_float(right, "right", warn=False)
    automatic = max_disparity is None  # the range is this function's choice, not the caller's
    if max_disparity is None:
        max_disparity = estimate_max_disparity(gl, gr)
    # a ValueError naming the argument for NaN, inf and ints beyond 64 bits (2**70 was NumPy's
    # TypeError "ufunc 'isfinite' not supported")
    finite_number(max_disparity, "max_disparity")
    if max_disparity <= min_disparity and (automatic or rig_range):
        # "max_disparity (16) must be larger than min_disparity (20)" named a value never given;
        # "give a max_disparity above 100" to a min_disparity no pixel reaches sent the caller
        # to the error below
        unreachable = unreachable_range(min_disparity, math.inf, gl.shape[1])
        if unreachable is not None:
            raise unreachable
        raise _below_automatic(min_disparity, max_disparity, rig_range)
    if max_disparity <= min_disparity:
        raise ValueError(
            f"max_disparity ({max_disparity}) must be larger than min_disparity ({min_disparity})"
        )
    if max_disparity - min_disparity >= gl.shape[1] and automatic:
        # a range the caller never gave: the image is the problem (the automatic range is at
        # least 16 px, so 16 px wide images and narrower are refused)
        raise _too_narrow(gl.shape[1], max_disparity - min_disparity, min_disparity)
    unreachable = unreachable_range(min_disparity, max_disparity, gl.shape[1])
    if unreachable is not None:
        raise unreachable
    if max_disparity - min_disparity >= gl.shape[1]:
        raise _range_too_wide(max_disparity - min_disparity, gl.shape[1], min_disparity)
    if method == "fused" and min_disparity < 0:  # a range given: once it is known searchable
        raise _from_zero(
            "fused", min_disparity, ("gabor", "census", "fast"), params.get("channels")
        )
    stage("prepare")
    channels: DepthChannels | None = {} if return_channels else None
    if refine is None:
        refine = method in _REFINED_BY_DEFAULT
    # "gabor" refines its output below; "fused" re-measures the Gabor map before the vote (its
    # output is already completed, and the refinement's drops would reopen holes).
    disp, conf, coarse = _run_matcher(
        method,
        gl,
        gr,
        float(min_disparity),
        float(max_disparity),
        dict(params),
        channels,
        remeasure=refine,
    )
    disp = np.ascontiguousarray(disp, dtype=np.float32)
    conf = np.ascontiguousarray(conf, dtype=np.float32)
    hi = float(max_disparity) if method == "gabor" else float(math.ceil(max_disparity))
    lo = float(min_disparity)
    # The range searched (the census map's reaches the next whole pixel above a fractional
    # one). The fused map's Gabor input ran past it (cones with 37: up to 38.6, its surfaces at
    # 55 px), values no matcher measured: holes, as match() drops them. Within half a pixel
    # they are kept (TartanAir's sky at -0.47 px is right; as a hole or clipped to the floor
    # it became an enclosed far region and the fill lost 0.3 point of bad-2.0 there).
    with np.errstate(invalid="ignore"):
        out = (disp < lo - _RANGE_TOL) | (disp > hi + _RANGE_TOL)
    if out.any():  # a new array: disp may be a channel's own output, kept in ``channels``
        disp = np.where(out, np.float32(np.nan), disp)
    measured = np.isfinite(disp)
    conf = np.where(measured, conf, np.float32(0)).astype(np.float32)
    stage("match")
    post_refine = refine and method not in _DENSE_METHODS
    # The census map's values (pixel-locked parabola vertices: pooled over the 17 GT scenes a
    # median error of 0.37 px) get the spread of filled pixels, not the confidence line's.
    filled: npt.NDArray[np.bool_] | None = coarse
    if fill is None:
        fill = method in _DENSE_METHODS
    if post_refine and fill:
        # The planes and the row rule complete the map below: only the re-measure, as the fused
        # map's Gabor input gets (the refinement's own fill passes lose to the planes: over the
        # 17 GT scenes the filled map's mean bad-2.0 ratio to SGBM-3WAY + fill is 1.01 this
        # way, 1.18 with them, 1.05 with no refinement).
        from stereovision.matching.fusion import remeasure

        disp = remeasure(
            gl, gr, disp, conf, min_disparity=min_disparity, max_disparity=max_disparity
        )
        stage("refine")
    elif post_refine:
        from stereovision.refine import _refine

        # the Gabor map over this range: refine_disparity's fixed-point warning is not for it
        ref = _refine(
            gl,
            gr,
            disp,
            conf,
            min_disparity=min_disparity,
            max_disparity=max_disparity,
            warn_fixed_point=False,
        )
        filled = ~measured & np.isfinite(ref.disparity)
        disp, conf = ref.disparity, ref.confidence
        stage("refine")
    measured_disp = disp  # NaN where not measured; the fill below makes a new array
    if fill:
        fused = method != "gabor"  # the fused map's fill suits the census map too
        disp, far = fill_holes(disp, left_bgr, fused=fused, floor=float(min_disparity), grey=gl)
        if far is not None:
            measured_disp[far] = np.nan  # fused_dense's own array, as is conf
            conf[far] = 0
        stage("fill")
    # the map in the range (a plane may run past it at a hole's far end; the half pixel kept
    # above); a new array: unfilled, disp is still measured_disp
    disp = np.clip(disp, lo, hi)
    depth = None
    depth_sigma = None
    points = np.zeros((0, 3), np.float32)
    colors = np.zeros((0, 3), np.uint8)
    pixels = np.zeros((0, 2), np.int32)
    if calib is not None:
        depth, depth_sigma = _depth_rectified(measured_disp, conf, calib, bool(refine), filled)
        if cloud:
            points, colors, pixels = _cloud(depth, calib, left_bgr)
        stage("triangulate")
    return DepthResult(
        disparity=disp,
        confidence=conf,
        depth=depth,
        points=points,
        colors=colors,
        pixels=pixels,
        method=method,
        # the range as searched (int(37.5) reported 37 for a Gabor search up to 37.5)
        max_disparity=_whole_or_float(max_disparity),
        min_disparity=float(min_disparity),
        calibration=calib,
        left_rectified=left_bgr,
        timings=timings,
        depth_sigma=depth_sigma,
        channels=channels,
    )
