"""Sub-pixel refinement and validated completion of a disparity map (between matching and depth).

A matcher's disparity is re-measured at every pixel by a zero-mean normalised cross-correlation
(ZNCC) of Gaussian windows between the left image and the right image *warped by the smoothed
estimate*, so the windows follow slanted surfaces. A pixel keeps the parabola vertex of the
correlation (shifts half a pixel apart) when the peak lies within half a pixel of its smoothed
estimate, and becomes NaN otherwise (the matcher and the correlation disagree: an occlusion edge
or a wrong lock). A fill pass then gives holes near measured pixels a value from the local plane
through them, again only on a clear correlation peak (ZNCC >= ``min_score``), so a filled pixel
is a measurement, not a guess.

Why: the Gabor channel's phase estimates spread by about a third of a pixel, which at the small
disparities of a robot's working range is several per cent of the depth; on the shared scenes
with a metric calibration this stage brings the median depth error below OpenCV SGBM-3WAY's
(see ``docs/refine.md`` for the figures). The kernel is Rust (``rust/core/src/refine.rs``);
``tests/reference/refine_ref.py`` is the same maths in NumPy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from stereovision import _core
from stereovision._validate import (
    _warn_low_uint16,
    as_gray_float,
    check_index_range,
    check_unit_range,
    disparity_range,
    not_a_result,
    number_shown,
    real_number,
    refuse_no_image,
    refuse_unknown,
)

__all__ = ["DEFAULTS", "RefineResult", "refine_disparity"]

#: Defaults of :func:`refine_disparity` (mirror ``RefineParams::default`` in Rust): global, chosen
#: on the shared scenes once (docs/refine.md), never per scene.
DEFAULTS: dict[str, object] = {
    "base_sigma": 4.0,
    "win_sigma": 4.5,
    "win_radius": 9,
    "search": 2,
    "step": 0.5,
    "fill_search": 2,
    "fill_step": 1.0,
    "var_floor": 1e-6,
    "fills": ((16.0, 0.3),),
    "fill_confidence": 0.25,
    "fill_plane": True,
    "fill_max_residual": float("inf"),
}


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity (== raised)
class RefineResult:
    """Output of :func:`refine_disparity`.

    Attributes
    ----------
    disparity : numpy.ndarray
        ``(H, W)`` float32 refined disparity (px), NaN = no estimate.
    confidence : numpy.ndarray
        ``(H, W)`` float32: the input confidence of refined pixels, ``fill_confidence`` for
        filled ones, 0 where NaN.
    n_filled : int
        Pixels the fill passes gave a value: holes of the input, and pixels whose input value
        the re-measure dropped (a disagreeing correlation, or outside the range) and the fill
        then measured again (on cones' Gabor map 1,564 of the 11,589: with
        ``fill_confidence``, not their input confidence).
    """

    disparity: npt.NDArray[np.float32]
    confidence: npt.NDArray[np.float32]
    n_filled: int


_FLOAT_KEYS = (
    "base_sigma",
    "win_sigma",
    "step",
    "fill_step",
    "var_floor",
    "fill_confidence",
    "fill_max_residual",
)


def _number(v: object, name: str, whole: bool = False) -> float:
    """A real parameter value (a non-negative whole number when ``whole``), else ValueError
    naming it."""
    if not real_number(v):  # a bool, or 3 ns taken as 3
        raise ValueError(f"{name} must be a number, got {v!r}")
    try:
        out = float(v)
    except OverflowError:  # an int beyond a float's range (2**1100)
        raise ValueError(f"{name} must be a finite number, got {number_shown(v)}") from None
    # Whole numbers are the kernel's counts and radii (usize).
    if whole and not (math.isfinite(out) and 0 <= v < 2**31 and int(v) == v):
        raise ValueError(f"{name} must be a non-negative whole number, got {v!r}")
    return out


#: What a 12-bit image in uint16 does to the refinement (the matchers' warning's ending).
_LOW_UINT16_EFFECT = ", its contrast then below the refinement's var_floor"


def _grey(a: object, name: str) -> npt.NDArray[np.float32]:
    from stereovision._validate import _refuse_masked

    # the masked pixels' values were refined as measured ones (depth_from_disparity's rule)
    _refuse_masked(a, name, "np.nan" if name == "disparity" else "value")
    if name in ("left", "right"):
        # "left must be real numbers, got dtype object" (a path: "<U8") of cv2.imread's None
        refuse_no_image(a, name)
    arr = np.asarray(a)
    # The float32 cast dropped a complex array's imaginary part with only NumPy's warning.
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"{name} must be real numbers, got dtype {arr.dtype}")
    image = name in ("left", "right")
    if image and arr.ndim == 3 and arr.shape[2] in (1, 3, 4) and arr.size:
        # a colour image, as the matchers take it (cv2.imread's BGR): grey by as_gray_float's
        # luma weights, depth_map's grey of the pair; it was refused as "must be a non-empty
        # 2-D (H, W) array" after depth_map had taken the same pair
        check_index_range(arr.shape, name, "image")  # before the float32 copy
        if arr.dtype == np.uint16:
            _warn_low_uint16(arr, name, _LOW_UINT16_EFFECT)
        return as_gray_float(arr, name, warn=False)
    if arr.ndim != 2 or arr.size == 0:
        # an image may be a colour one too (above): "2-D (H, W)" alone told the caller of a
        # two-channel or (3, H, W) image that only grey ones are taken
        colour = " or an (H, W, 3) BGR / (H, W, 4) BGRA colour image" if image else ""
        raise ValueError(
            f"{name} must be a non-empty 2-D (H, W) array{colour}, got shape {arr.shape}"
        )
    # before the float32 copy: a broadcast image past the kernel's limit may not fit in memory
    check_index_range(arr.shape, name, "image" if image else "map")
    if image and arr.dtype in (np.uint8, np.uint16):
        # 8- and 16-bit images at full scale, as every matcher takes them: the range check's
        # advice ("pass the uint8 array itself") refused the uint8 array it had been given
        if arr.dtype == np.uint16:
            # as the matchers warn (as_gray_float): 12-bit data scaled by 65535 lies 16 times
            # darker, its contrast below var_floor (teddy: 16 % fewer pixels kept), unsaid
            _warn_low_uint16(arr, name, _LOW_UINT16_EFFECT)
        return np.ascontiguousarray(arr, dtype=np.float32) / np.float32(np.iinfo(arr.dtype).max)
    return np.ascontiguousarray(arr, dtype=np.float32)


def _warn_if_mostly_above_range(d: npt.NDArray[np.float32], lo: float, hi: float) -> None:
    """Warn when most of the map's values not below ``min_disparity`` lie above
    ``max_disparity``, which the refinement drops: OpenCV StereoSGBM's int16 map (``d * 16``,
    -16 = none) gave tsukuba's refined map 1 % of its pixels (its values / 16: 89 %), without
    a word. Values below the range (the -16 of no match) are not counted against it: KITTI's
    StereoBM map, 52 % of it -16, was not warned of with 45 % of its values above."""
    values = d[np.isfinite(d)]
    above = int(np.count_nonzero(values > hi))
    if above * 2 <= values.size - int(np.count_nonzero(values < lo)):
        return
    import warnings

    warnings.warn(
        f"disparity: {above} of its {values.size} values ({100 * above / values.size:.1f} %) "
        f"lie above max_disparity {hi:g} px and are dropped (the largest "
        f"{float(values.max()):g} px); fixed-point values? OpenCV StereoBM / StereoSGBM's int16 "
        "map is d * 16 (divide by 16; its -16 is no match), a 16-bit disparity PNG d * 256 "
        "(stereovision.export.read_disparity_png)",
        UserWarning,
        stacklevel=4,
    )


def refine_disparity(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    disparity: npt.ArrayLike,
    confidence: npt.ArrayLike | None = None,
    *,
    min_disparity: float = 0.0,
    max_disparity: float,
    **params: object,
) -> RefineResult:
    """Refine a disparity map to sub-pixel precision and fill holes that correlate clearly.

    Parameters
    ----------
    left, right : array_like
        Rectified grey images, ``(H, W)`` float in ``[0, 1]``, or ``uint8`` / ``uint16``
        (divided by 255 / 65535; a ``uint16`` image below 4096, 12-bit data, is warned of);
        colour ones, ``(H, W, 3)`` BGR or ``(H, W, 4)`` BGRA (or ``(H, W, 1)``), are made grey
        as the matchers and :func:`~stereovision.depth_map` make them.
    disparity : array_like
        ``(H, W)`` disparity of the left image (px), NaN = no estimate.
    confidence : array_like, optional
        ``(H, W)`` confidence in ``[0, 1]`` carried over to refined pixels (default 1); where
        the disparity is NaN it is not read (NaN allowed).
    min_disparity, max_disparity : float
        Values outside this range become NaN.
    **params
        Overrides of :data:`DEFAULTS`: ``base_sigma`` (px), ``win_sigma`` (px), ``win_radius``
        (px), ``search`` (shifts each side), ``step`` (px between shifts), ``fill_search`` and
        ``fill_step`` (the same for the fill passes), ``var_floor``, ``fills`` (a sequence of
        ``(sigma_px, min_score)``; empty = no fill), ``fill_confidence``, ``fill_plane`` (start
        a fill from the local plane, else from the local mean), ``fill_max_residual`` (px: fill
        only where the measured values lie within this RMS distance of that plane).

    Returns
    -------
    RefineResult

    Warns
    -----
    UserWarning
        When most of the map's values not below ``min_disparity`` lie above ``max_disparity``
        (fixed-point values: OpenCV's int16 ``d * 16``, whose -16 is no match, a 16-bit
        disparity PNG's ``d * 256``), all of which are dropped.

    Raises
    ------
    TypeError
        A :class:`~stereovision.DepthResult` given for ``disparity`` or ``confidence`` (pass
        its array: ``result.disparity``, ``result.confidence``).
    ValueError
        An image that is None (``cv2.imread``'s answer for a file it cannot read) or a path,
        shapes differ, an array is not real (complex), an image is empty, not finite or has
        values outside ``[0, 1]``, a confidence is NaN or outside ``[0, 1]`` where the disparity
        has a value, an array is a :mod:`numpy.ma` one with masked pixels (pass
        ``disparity.filled(np.nan)``: NaN is no estimate), a parameter is unknown, no number (a
        bool, a string) or out of range, ``fill_plane`` not a bool.
    """
    return _refine(
        left,
        right,
        disparity,
        confidence,
        min_disparity=min_disparity,
        max_disparity=max_disparity,
        warn_fixed_point=True,
        **params,
    )


def _refine(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    disparity: npt.ArrayLike,
    confidence: npt.ArrayLike | None,
    *,
    min_disparity: float,
    max_disparity: float,
    warn_fixed_point: bool,
    **params: object,
) -> RefineResult:
    """:func:`refine_disparity`; ``warn_fixed_point=False`` for the pipeline's own maps
    (depth_map, fusion), which come from a matcher over this range: the fixed-point warning
    is for a caller's map, and fired inside depth_map on a map whose values lay above a
    range the caller had set (tests/test_depth.py's point image, 99 % above 16 px)."""
    # the valid keys and the nearest spelling too ("unknown refinement parameter(s):
    # ['win_sigmma']" named neither), as the matchers' own parameters are refused
    refuse_unknown("refinement parameter", params, DEFAULTS, "stereovision.refine.DEFAULTS")
    # a depth_map result for its map was "disparity must be real numbers, got dtype object",
    # not what to pass; the words of depth_from_disparity and the other takers of its arrays
    not_a_result(disparity, "disparity", "disparity")
    not_a_result(confidence, "confidence", "confidence")
    lft, rgt, dsp = _grey(left, "left"), _grey(right, "right"), _grey(disparity, "disparity")
    check_unit_range(lft, "left")
    check_unit_range(rgt, "right")
    if not lft.shape == rgt.shape == dsp.shape:
        raise ValueError(
            f"left {lft.shape}, right {rgt.shape} and disparity {dsp.shape} differ in shape"
        )
    conf = np.ones_like(dsp) if confidence is None else _grey(confidence, "confidence")
    if confidence is not None:
        if conf.shape != dsp.shape:
            raise ValueError(f"confidence {conf.shape} and disparity {dsp.shape} differ in shape")
        # Where the disparity has a value its confidence is carried over: a NaN there came out
        # as a NaN confidence of a refined pixel, a value outside [0, 1] clipped without a word.
        measured = np.isfinite(dsp)
        bad = measured & ~((conf >= 0) & (conf <= 1))
        if bad.any():
            raise ValueError(
                "confidence: expected values in [0, 1] where the disparity has one; "
                f"{int(bad.sum())} pixels are not (e.g. {float(conf[bad][0])!r})"
            )
        conf = np.where(measured | np.isfinite(conf), conf, np.float32(0))
    # the checked floats go to the kernel (float() of np.array([8.0]) was NumPy's bare TypeError)
    lo, hi = disparity_range(min_disparity, max_disparity)
    top = float(np.finfo(np.float32).max)
    for name, v in (("min_disparity", lo), ("max_disparity", hi)):
        # inf in the kernel's float32: max_disparity=1e39 was "invalid parameter `range`: need
        # finite d_min < d_max, got 0, inf", naming neither argument nor the value given
        if abs(v) > top:
            raise ValueError(
                f"{name}: expected a finite number in float32, the kernel's precision, got "
                f"{number_shown(v)}"
            )
    if warn_fixed_point:
        _warn_if_mostly_above_range(dsp, lo, hi)
    kw = {**DEFAULTS, **params}
    fills_raw = kw.pop("fills")
    try:
        items = list(fills_raw)  # type: ignore[call-overload]
    except TypeError as exc:
        raise ValueError(
            f"fills must be a sequence of (sigma, min_score), got {fills_raw!r}"
        ) from exc
    for pos, item in enumerate(items):
        # text, bytes and a dict unpack as two values but are no pair: b"\x10\x00" was read
        # as (16, 0) where the kernel refuses it; in the kernel's words (a text or bytes
        # `fills` itself is no sequence of pairs, said below)
        if isinstance(item, (str, bytes, bytearray, dict)) and not isinstance(
            fills_raw, (str, bytes, bytearray)
        ):
            raise ValueError(
                f"invalid parameter `fills`: element {pos} ({item!r}): expected a (sigma, "
                "min_score) pair"
            )
    try:
        pairs = [(s, m) for s, m in items]
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"fills must be a sequence of (sigma, min_score), got {fills_raw!r}"
        ) from exc
    # Numbers as every other parameter: float() took True and "16" and raised a bare
    # OverflowError for 2**1100. Named as the kernel names them: a pair's bad number was
    # "fills must be a sequence of (sigma, min_score)" of a sequence of pairs, hiding why.
    fills = [(_number(s, "fill sigma"), _number(m, "fill min_score")) for s, m in pairs]
    f = {k: _number(kw[k], k) for k in _FLOAT_KEYS}
    # The kernel's float32 reads an infinity, or a value past float32 (1e39), as inf: "invalid
    # parameter `base_sigma`: must be > 0, got inf" told the caller to give a larger value.
    # fill_max_residual's inf means no test; NaN is left to the kernel's words.
    for k, v in [*f.items(), *(("fill sigma", s) for s, _ in fills)]:
        if k != "fill_max_residual" and abs(v) > top:
            raise ValueError(f"{k} must be a finite number, got {number_shown(v)}")
    i = {k: _number(kw[k], k, whole=True) for k in ("win_radius", "search", "fill_search")}
    # A switch, not a truth value: "no" or 0.5 went through bool() as True, None as False.
    if not isinstance(kw["fill_plane"], (bool, np.bool_)):
        raise ValueError(f"fill_plane must be True or False, got {kw['fill_plane']!r}")
    d, c, n = _core.refine_disparity(
        lft,
        rgt,
        dsp,
        conf,
        lo,
        hi,
        f["base_sigma"],
        f["win_sigma"],
        int(i["win_radius"]),
        int(i["search"]),
        f["step"],
        int(i["fill_search"]),
        f["fill_step"],
        f["var_floor"],
        fills,
        f["fill_confidence"],
        bool(kw["fill_plane"]),
        f["fill_max_residual"],
    )
    return RefineResult(disparity=d, confidence=c, n_filled=int(n))
