"""Accuracy metrics exactly as evaluation.md defines them.

* :func:`dense_metrics` -- Middlebury-style bad-t (holes counted as errors), density, avgerr, rms;
* :func:`depth_metrics` -- metric depth: median ``|dZ|/Z``, share off by more than 5 %, RMSE as a
  percentage of the mean depth;
* :func:`table1_report` -- the paper's Table-1 test (per-point distances, average error, RMSE,
  RMSE %), in metres and feet;
* :func:`sparse_metrics` -- precision of sparse matches, count and 4x4 grid coverage.

Missing values: a disparity estimate is missing when it is not finite (NaN); an OpenCV ``0`` is a
valid estimate. A GT disparity is unknown when it is not finite. Depths (estimated or GT) are
missing when not finite or ``<= 0``. All percentages are in ``[0, 100]``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    NOT_NUMBERS,
    _refuse_masked,
    check_index_range,
    known_unit,
    number_shown,
    real_number,
    renamed_keyword,
    too_large_for_float,
)
from stereovision._validate import require as _require_type

# at run time too, so that typing.get_type_hints resolves the public signatures
from stereovision.calibration import Calibration

__all__ = [
    "DEFAULT_THRESHOLDS",
    "DenseMetrics",
    "DepthMetrics",
    "SparseMetrics",
    "Table1Report",
    "count_at_precision",
    "dense_metrics",
    "depth_metrics",
    "gt_depth",
    "sparse_metrics",
    "table1_report",
]

#: evaluation.md: bad-t thresholds in pixels; bad-2.0 is the headline figure.
DEFAULT_THRESHOLDS: tuple[float, ...] = (0.5, 1.0, 2.0, 4.0)
#: evaluation.md: a depth is "off" when its relative error exceeds 5 %.
DEPTH_OFF_FRACTION = 0.05
#: evaluation.md: sparse precision thresholds (px); precision@1 is the headline.
SPARSE_THRESHOLDS: tuple[float, ...] = (0.5, 1.0, 2.0)
#: evaluation.md: spread of sparse matches over a 4 x 4 grid of the image.
COVERAGE_GRID = 4

_FT_PER_M = 1.0 / 0.3048
_TO_METRES = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "ft": 0.3048, "in": 0.0254}


def _real_2d(a: object, name: str, field: str = "disparity") -> npt.NDArray[np.float64]:
    from stereovision._validate import not_a_result

    not_a_result(a, name, field)
    # a masked GT's pixels were scored by their data (depth_from_disparity's rule)
    _refuse_masked(a, name, "np.nan")  # non-finite: unknown, no estimate
    arr = np.asarray(a)
    if arr.ndim != 2 or arr.dtype.kind not in "iuf":
        raise ValueError(
            f"{name}: expected a real (H, W) array, got shape {arr.shape} dtype {arr.dtype}"
        )
    check_index_range(arr.shape, name, "map")  # before the float64 copy (8 bytes a pixel)
    return arr.astype(np.float64)


def _same_shape(a: np.ndarray, b: np.ndarray, na: str, nb: str) -> None:
    if a.shape != b.shape:
        raise ValueError(f"{na} and {nb} must have the same shape, got {a.shape} and {b.shape}")


def _bool_mask(mask: npt.ArrayLike) -> np.ndarray:
    """``mask`` as bool: bool, integers (non-zero inside, e.g. a 0/255 PNG) or floats of 0 and 1.

    ``astype(bool)`` took anything: a NaN counted as inside and strings by their emptiness.
    """
    m = np.asarray(mask)
    if m.dtype.kind in "biu" or (m.dtype.kind == "f" and np.isin(m, (0.0, 1.0)).all()):
        return m.astype(bool)
    raise ValueError(
        f"mask: expected a bool or integer array (or floats of only 0 and 1), "
        f"got dtype {m.dtype}" + (" holding other values" if m.dtype.kind == "f" else "")
    )


def _unit_factor(unit: str) -> float:
    return _TO_METRES[known_unit(unit, sorted(_TO_METRES))]


def _threshold_text(t: float) -> str:
    """``2.0`` -> ``"2.0"`` (the tracked keys), ``0.25`` -> ``"0.25"`` (not ``"0.2"``)."""
    one = f"{t:.1f}"
    return one if float(one) == t else repr(float(t))


def _pct(num: float, den: float) -> float:
    return 100.0 * num / den if den else math.nan


# ---------------------------------------------------------------------------------------- dense


@dataclass(frozen=True)
class DenseMetrics:
    """Dense disparity metrics over the pixels with known GT (evaluation.md).

    Attributes
    ----------
    bad : dict of float to float
        ``{t: percentage}`` of GT pixels whose estimate is missing or off by more than ``t`` px.
    density : float
        Percentage of GT pixels that have an estimate.
    avgerr, rms : float
        Mean and RMS absolute error (px) over pixels with both (NaN if there are none).
    n_gt : int
        Number of pixels with known GT.
    n_both : int
        Number of pixels with both GT and an estimate.
    """

    bad: dict[float, float]
    density: float
    avgerr: float
    rms: float
    n_gt: int
    n_both: int

    def as_dict(self) -> dict[str, float | int]:
        """Flat dict: ``bad_0.5``, ``bad_1.0``, ..., ``density``, ``avgerr``, ``rms``, counts.

        A threshold with more than one decimal keeps them all (``bad_0.25``), so that two
        thresholds never share a key.

        Returns
        -------
        dict
            ``bad_<t>`` per threshold, ``density``, ``avgerr``, ``rms``, ``n_gt``, ``n_both``.
        """
        out: dict[str, float | int] = {f"bad_{_threshold_text(t)}": v for t, v in self.bad.items()}
        out.update(
            density=self.density,
            avgerr=self.avgerr,
            rms=self.rms,
            n_gt=self.n_gt,
            n_both=self.n_both,
        )
        return out


def _real(value: object) -> bool:
    """Whether ``value`` is a real number (a bool is not one, nor a numeric string)."""
    return real_number(value)  # 3 ns is none either


def _positive_finite(value: object) -> bool:
    """Whether ``value`` is a real number above 0 within a float's range."""
    if not _real(value):
        return False
    try:
        return bool(value > 0 and math.isfinite(value))  # type: ignore[operator, arg-type]
    except OverflowError:  # an int beyond a float
        return False


@renamed_keyword("disp", "disparity")
def dense_metrics(
    disparity: npt.ArrayLike,
    gt: npt.ArrayLike,
    thresholds: tuple[float, ...] = DEFAULT_THRESHOLDS,
    mask: npt.ArrayLike | None = None,
) -> DenseMetrics:
    """Middlebury-style dense metrics, holes counted as errors.

    Parameters
    ----------
    disparity : array_like
        ``(H, W)`` estimated disparity (px), NaN = no estimate. The keyword ``disp=``, its
        former name, still works, with a DeprecationWarning.
    gt : array_like
        ``(H, W)`` GT disparity (px), non-finite = unknown.
    thresholds : iterable of float
        bad-t thresholds in px (a tuple, list, array, range, set, ...).
    mask : array_like of bool, optional
        ``(H, W)``; restrict the evaluation to these pixels (e.g. non-occluded). Integers
        count non-zero as inside (a 0/255 mask image); floats must hold only 0 and 1.

    Returns
    -------
    DenseMetrics

    Raises
    ------
    ValueError
        On non-2-D input, a :mod:`numpy.ma` map with masked pixels (pass
        ``gt.filled(np.nan)``), mismatched shapes, non-positive thresholds or a mask that is
        not bool, integer or 0/1 floats.

    Warns
    -----
    UserWarning
        For an integer ``gt`` that reads as a disparity PNG's values (scored as they are): one
        holding a disparity as wide as the map or wider (no match lies that far: KITTI's
        ``d * 256``), or 0s (a PNG's mark of unknown pixels; an integer map has no other),
        among the pixels ``mask`` keeps.

    Examples
    --------
    >>> m = dense_metrics(np.array([[1.0, np.nan, 5.0]]), np.array([[1.5, 2.0, 2.0]]))
    >>> m.bad[1.0], round(m.density, 2), m.avgerr
    (66.66666666666667, 66.67, 1.75)
    """
    d = _real_2d(disparity, "disparity")
    g = _real_2d(gt, "gt")
    _same_shape(d, g, "disparity", "gt")
    # a single number was "'float' object is not iterable", True a threshold of 1 px and "2"
    # a TypeError from the comparison; any collection of numbers is read (a range, a set), once
    # (a generator, used up by the check, gave no bad-t figure at all)
    ts = tuple(thresholds) if isinstance(thresholds, Iterable) else None
    if isinstance(thresholds, (str, bytes)) or ts is None or not all(map(_positive_finite, ts)):
        shown = repr(thresholds)
        if ts is not None and any(map(too_large_for_float, ts)):  # not the 401 digits of 10**400
            shown = f"({', '.join(map(number_shown, ts))})"
        raise ValueError(f"thresholds must be positive and finite, got {shown}")
    known = np.isfinite(g)
    if mask is not None:
        m = _bool_mask(mask)
        _same_shape(m, g, "mask", "gt")
        known &= m
    # after the mask: the 0s it leaves out are not scored
    _warn_if_png_gt(g, np.asarray(gt).dtype.kind in "iu", scored=known)
    n_gt = int(known.sum())
    est = np.isfinite(d) & known
    n_both = int(est.sum())
    # float64 maps beyond 1e154 overflow the squares (1e308 apart, the difference): those
    # figures are inf, as they were, without NumPy's RuntimeWarning on the way
    with np.errstate(over="ignore"):
        err = np.abs(d[est] - g[est])
        avgerr = float(err.mean()) if n_both else math.nan
        rms = float(np.sqrt(np.mean(err**2))) if n_both else math.nan
    bad = {float(t): _pct(n_gt - int(np.count_nonzero(err <= t)), n_gt) for t in ts}
    return DenseMetrics(
        bad=bad,
        density=_pct(n_both, n_gt),
        avgerr=avgerr,
        rms=rms,
        n_gt=n_gt,
        n_both=n_both,
    )


def _warn_if_png_gt(
    g: npt.NDArray[np.float64],
    integer: bool,
    stacklevel: int = 4,
    scored: npt.NDArray[np.bool_] | None = None,
) -> None:
    """Warn, at the caller of :func:`dense_metrics`, :func:`sparse_metrics` or
    :func:`count_at_precision` (``stacklevel`` frames up), of an integer GT map that reads as
    a disparity PNG's: a disparity as wide as the map or wider (no match lies that far), or 0s
    (a PNG's mark of unknown pixels; an integer map has no other). A float map is pixels.
    With ``scored`` (dense_metrics' mask), only those pixels are looked at: 0s a mask leaves
    out (KITTI's devkit's ``gt > 0``) are not scored, and were said to be.

    KITTI's GT PNG read with ``cv2.imread`` (``d * 256``, 0 = unknown) was scored as pixels
    with its unknown pixels known: SGBM-3WAY on 000005 bad-2.0 99.9 % (29.5 % against the GT
    in pixels), without a word; divided by 256 in integers, 86.0 % (its 0s still known).
    """
    if not integer:
        return
    import warnings

    width = g.shape[1]
    values = g if scored is None else g[scored]
    top = float(np.max(values, initial=-np.inf))
    zeros = int(np.count_nonzero(values == 0))
    if top < width and zeros == 0:
        return
    said = (
        f"values up to {top:g} px, as wide as the map ({width} px) or wider: no match lies that far"
        if top >= width
        else f"an integer map with {zeros} pixels at 0, scored as known 0 px disparities"
    )
    warnings.warn(
        f"gt: {said}; a disparity PNG (KITTI's d * 256, 0 = unknown) reads as pixels with "
        "stereovision.export.read_disparity_png (unknown pixels NaN)",
        UserWarning,
        stacklevel=stacklevel,  # 4: this, dense_metrics, renamed_keyword's frame, the caller
    )


def gt_at_zero_note(gt: npt.NDArray[np.floating[Any]] | None) -> str | None:
    """What ``eval`` and ``bench`` say of a scene's GT with known pixels at 0 px or below.

    A ``gt_disp.pfm`` marks unknown pixels non-finite; KITTI's and Middlebury's PNGs mark them
    0, and a GT converted keeping those 0s was scored against them without a word (a crop of
    KITTI 000005, half its pixels unknown: bad-2.0 55.1 % for 7.6 %). They stay known (a 0 px
    disparity is a point at infinity): this says so.

    Parameters
    ----------
    gt : numpy.ndarray or None
        GT disparity (px), non-finite = unknown; None for a scene without one.

    Returns
    -------
    str or None
        The note, or None when no known pixel is at 0 px or below (or there is no GT).
    """
    if gt is None:
        return None
    known = np.asarray(gt)[np.isfinite(gt)]
    low = int(np.count_nonzero(known <= 0))
    if low == 0:
        return None
    return (
        f"gt_disp.pfm: {low} of its {known.size} known pixels ({_pct(low, known.size):.1f} %) "
        "are at 0 px or below, scored as known disparities; if they mark unknown pixels (as 0 "
        "does in KITTI's and Middlebury's PNGs), write them as +inf"
    )


# ---------------------------------------------------------------------------------------- depth


@dataclass(frozen=True)
class DepthMetrics:
    """Metric depth accuracy over pixels where both depths exist (evaluation.md).

    Attributes
    ----------
    median_rel : float
        Median of ``|Z_est - Z_gt| / Z_gt``, percent.
    share_off_5 : float
        Percentage of those pixels with relative error above 5 %.
    rmse_pct : float
        RMSE of ``Z_est - Z_gt`` as a percentage of the mean GT depth.
    rmse : float
        The RMSE itself, in the depth maps' unit.
    n : int
        Number of pixels with both depths.
    density : float
        ``n`` as a percentage of all pixels.
    """

    median_rel: float
    share_off_5: float
    rmse_pct: float
    rmse: float
    n: int
    density: float

    def as_dict(self) -> dict[str, float | int]:
        """The fields as a flat dict.

        Returns
        -------
        dict
            Field name to value.
        """
        return asdict(self)


def _depth_valid(z: np.ndarray) -> npt.NDArray[np.bool_]:
    with np.errstate(invalid="ignore"):
        return np.isfinite(z) & (z > 0)


@renamed_keyword("depth_est", "depth")
@renamed_keyword("depth_gt", "gt")
def depth_metrics(depth: npt.ArrayLike, gt: npt.ArrayLike) -> DepthMetrics:
    """Median relative error, share off by > 5 % and RMSE % over pixels with both depths.

    Parameters
    ----------
    depth, gt : array_like
        Same-shape estimated and ground-truth depth maps in the same unit; non-finite or
        ``<= 0`` = missing. The keywords ``depth_est=`` and ``depth_gt=``, their former names,
        still work, with a DeprecationWarning.

    Returns
    -------
    DepthMetrics
        NaN figures and ``n = 0`` when no pixel has both.

    Raises
    ------
    ValueError
        On mismatched shapes, non-real input or a :mod:`numpy.ma` map with masked pixels
        (pass ``gt.filled(np.nan)``).
    TypeError
        If a whole ``DepthResult`` is given for a map (its ``depth`` is meant).
    """
    from stereovision._validate import not_a_result

    # a whole result was "depth maps must be real arrays, got object and float32"
    not_a_result(depth, "depth", "depth")
    not_a_result(gt, "gt", "depth")
    _refuse_masked(depth, "depth", "np.nan")  # non-finite: missing
    _refuse_masked(gt, "gt", "np.nan")
    e = np.asarray(depth)
    g = np.asarray(gt)
    if e.dtype.kind not in "iuf" or g.dtype.kind not in "iuf":
        raise ValueError(f"depth maps must be real arrays, got {e.dtype} and {g.dtype}")
    _same_shape(e, g, "depth", "gt")
    if e.ndim == 2:  # before the float64 copies (any shape is taken: a map's is checked)
        check_index_range(e.shape, "depth", "map")
    e = e.astype(np.float64)
    g = g.astype(np.float64)
    both = _depth_valid(e) & _depth_valid(g)
    n = int(both.sum())
    if n == 0:
        return DepthMetrics(math.nan, math.nan, math.nan, math.nan, 0, 0.0)
    with np.errstate(over="ignore"):  # as dense_metrics: inf beyond float64, unwarned
        diff = e[both] - g[both]
        rel = np.abs(diff) / g[both]
        rmse = float(np.sqrt(np.mean(diff**2)))
        mean_gt = float(np.mean(g[both]))
    return DepthMetrics(
        median_rel=100.0 * float(np.median(rel)),
        share_off_5=_pct(int(np.count_nonzero(rel > DEPTH_OFF_FRACTION)), n),
        rmse_pct=100.0 * rmse / mean_gt,
        rmse=rmse,
        n=n,
        density=_pct(n, e.size),
    )


@renamed_keyword("gt_disp", "gt")
def gt_depth(gt: npt.ArrayLike, calib: Calibration) -> npt.NDArray[np.float32]:
    """GT depth in metres from a GT disparity map and a rectified calibration.

    ``Z = f * B / (d + doffs)`` (algorithms.md E.3); unknown or ``d <= -doffs`` gives NaN.

    Parameters
    ----------
    gt : array_like
        ``(H, W)`` GT disparity in pixels (non-finite = unknown). The keyword ``gt_disp=``, its
        former name, still works, with a DeprecationWarning.
    calib : Calibration
        Calibration of the (rectified) pair.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``float32`` depth in metres, NaN where unknown.

    Warns
    -----
    UserWarning
        As :func:`~stereovision.triangulation.depth_from_disparity`, at the caller's line: for a
        map of the pair resized or of fixed-point values.
    """
    _require_type(calib, "Calibration", "calib")
    from stereovision.triangulation import _depth_from_disparity

    # 3: renamed_keyword's frame; a map of the pair resized or of fixed-point values (a KITTI
    # GT PNG read with cv2.imread) was warned about at this line, not the caller's
    return _depth_from_disparity(gt, calib, "m", 3)


#: float16's largest value (65504): a GT depth stored as float16 saturates there (TartanAir's
#: sky), so a GT depth of that many metres is the format's clamp, not a measured distance.
GT_DEPTH_SATURATED_M = float(np.finfo(np.float16).max)


def saturated_gt_depth(gt: npt.ArrayLike) -> npt.NDArray[np.bool_]:
    """Pixels of a GT depth map (metres) at float16's largest value, 65504 m: unknown, not GT.

    TartanAir's sky holds that depth (its GT disparity ~0.0012 px at f B = 80 m px), where the
    validated matches measured ~10 px (7.9 m): scored as GT, those pixels took the matches'
    depth RMSE to 2060.75 % of the mean depth. ``eval`` leaves them out of the depth figures
    and Table-1 tests (evaluation.md: over pixels where the GT depth exists) and says how many.

    Parameters
    ----------
    gt : array_like
        GT depth in metres, as :func:`gt_depth` gives it (NaN = unknown).

    Returns
    -------
    numpy.ndarray
        Boolean map, True within 1e-6 (relative) of 65504 m: the float32 round trip through
        the disparity moves the value by a few units in the last place.
    """
    z = np.asarray(gt, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        return np.abs(z - GT_DEPTH_SATURATED_M) <= 1e-6 * GT_DEPTH_SATURATED_M


# -------------------------------------------------------------------------------------- Table 1


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity (== raised)
class Table1Report:
    """The paper's Table-1 test: triangulated vs GT distances at N points (metres).

    Attributes
    ----------
    x, y : numpy.ndarray
        ``(N,)`` ``int64`` pixel columns and rows of the points.
    estimated, ground_truth : numpy.ndarray
        ``(N,)`` ``float64`` distances in metres.
    mean_error : float
        Mean signed error ``estimated - ground_truth`` (m).
    mean_abs_error : float
        Mean absolute error (m).
    rmse : float
        Root-mean-square error (m).
    rmse_pct : float
        RMSE as a percentage of the mean GT distance.
    mean_distance : float
        Mean GT distance (m).
    n_points : int
        N, the number of points (set from ``x``).
    """

    x: npt.NDArray[np.int64]
    y: npt.NDArray[np.int64]
    estimated: npt.NDArray[np.float64]
    ground_truth: npt.NDArray[np.float64]
    mean_error: float
    mean_abs_error: float
    rmse: float
    rmse_pct: float
    mean_distance: float
    n_points: int = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "n_points", len(self.x))

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict: summary figures in metres and feet plus the per-point rows.

        Returns
        -------
        dict
            The summary figures by name and the per-point rows.
        """
        return {
            "n_points": self.n_points,
            "mean_error_m": self.mean_error,
            "mean_abs_error_m": self.mean_abs_error,
            "rmse_m": self.rmse,
            "rmse_pct": self.rmse_pct,
            "mean_distance_m": self.mean_distance,
            "mean_error_ft": self.mean_error * _FT_PER_M,
            "mean_abs_error_ft": self.mean_abs_error * _FT_PER_M,
            "rmse_ft": self.rmse * _FT_PER_M,
            "mean_distance_ft": self.mean_distance * _FT_PER_M,
            "points": [
                {
                    "x": int(x),
                    "y": int(y),
                    "estimated_m": float(e),
                    "ground_truth_m": float(g),
                    "error_m": float(e - g),
                    "estimated_ft": float(e) * _FT_PER_M,
                    "ground_truth_ft": float(g) * _FT_PER_M,
                    "error_ft": float(e - g) * _FT_PER_M,
                }
                for x, y, e, g in zip(
                    self.x, self.y, self.estimated, self.ground_truth, strict=True
                )
            ],
        }

    def format(self) -> str:
        """Plain-text table (per point, then the summary), in metres and feet.

        Returns
        -------
        str
            Lines joined by newlines.
        """
        head = (
            f"{'#':>3} {'x':>5} {'y':>5} {'est m':>9} {'GT m':>9} {'err m':>8} "
            f"{'est ft':>9} {'GT ft':>9} {'err ft':>8}"
        )
        lines = ["Table-1 test: triangulated vs ground-truth distance", head, "-" * len(head)]
        for i, (x, y, e, g) in enumerate(
            zip(self.x, self.y, self.estimated, self.ground_truth, strict=True), start=1
        ):
            ft = _FT_PER_M
            lines.append(
                f"{i:>3} {x:>5} {y:>5} {_cell(e, 9)} {_cell(g, 9)} {_cell(e - g, 8, '+')} "
                f"{_cell(e * ft, 9)} {_cell(g * ft, 9)} {_cell((e - g) * ft, 8, '+')}"
            )
        lines += [
            "-" * len(head),
            f"points: {self.n_points}   mean distance: {_num(self.mean_distance)} m "
            f"({_num(self.mean_distance * _FT_PER_M)} ft)",
            f"average error: {_num(self.mean_error, '+')} m "
            f"({_num(self.mean_error * _FT_PER_M, '+')} ft)   "
            f"mean |error|: {_num(self.mean_abs_error)} m "
            f"({_num(self.mean_abs_error * _FT_PER_M)} ft)",
            f"RMSE: {_num(self.rmse)} m ({_num(self.rmse * _FT_PER_M)} ft) = "
            f"{_num(self.rmse_pct, decimals=2)} % of the mean distance",
        ]
        return "\n".join(lines)


def _num(value: float, sign: str = "", decimals: int = 3) -> str:
    """``value`` with ``decimals`` decimals, in exponent form from a million up: a point
    triangulated from a disparity of ~0 px (a far validated member, 3e38 m) was printed with
    39 digits, in the table and in its mean, |error| and RMSE."""
    if math.isfinite(value) and abs(value) >= 1e6:
        return f"{value:{sign}.{decimals}e}"
    return f"{value:{sign}.{decimals}f}"


def _cell(value: float, width: int, sign: str = "") -> str:
    """``value`` in a table column ``width`` wide: 3 decimals, or as many digits of the
    exponent form as fit (426500.000 m had pushed the row's other columns out of line)."""
    text = f"{value:{sign}{width}.3f}"
    digits = 3
    while len(text) > width and digits >= 0:
        text = f"{value:{sign}{width}.{digits}e}"
        digits -= 1
    return text


@renamed_keyword("depth_est", "depth")
@renamed_keyword("depth_gt", "gt")
def table1_report(
    depth: npt.ArrayLike,
    gt: npt.ArrayLike,
    n_points: int = 10,
    seed: int | None = 0,
    points: npt.ArrayLike | None = None,
    unit: str = "m",
) -> Table1Report:
    """The paper's Table-1 test on a distance map against a GT distance map.

    Works for any per-pixel distance (depth ``Z`` or range): ``N`` random pixels where both
    exist (drawn without replacement with ``numpy.random.default_rng(seed)``, listed in
    row-major order) or the given ``points``.

    Parameters
    ----------
    depth, gt : array_like
        ``(H, W)`` estimated and ground-truth distances in ``unit``; non-finite or ``<= 0`` =
        missing. The keywords ``depth_est=`` and ``depth_gt=``, their former names, still work,
        with a DeprecationWarning.
    n_points : int
        Number of random points (all valid pixels if fewer exist). Ignored with ``points``.
    seed : int or None
        Seed of the random draw (an integer >= 0); None draws from fresh entropy, as
        ``numpy.random.default_rng(None)``.
    points : array_like, optional
        ``(N, 2)`` integer ``(x, y)`` pixels to use instead of a random draw; each must lie in
        the image and have both distances.
    unit : str
        Unit of the input maps: ``"m"``, ``"mm"``, ``"cm"``, ``"ft"`` or ``"in"``. The report is
        in metres (and feet in :meth:`Table1Report.format`).

    Returns
    -------
    Table1Report

    Raises
    ------
    ValueError
        On mismatched shapes, an unknown ``unit``, ``n_points < 1``, no pixel with both
        distances, or a given point outside the image or without both distances.
    """
    e = _real_2d(depth, "depth", "depth")
    g = _real_2d(gt, "gt", "depth")
    _same_shape(e, g, "depth", "gt")
    factor = _unit_factor(unit)
    both = _depth_valid(e) & _depth_valid(g)
    if points is None:
        # NumPy's messages named neither (n_points NaN: "negative dimensions are not allowed",
        # seed -5: "expected non-negative integer"), and n_points 2.5 or True was taken
        if not isinstance(n_points, (int, np.integer)) or isinstance(n_points, NOT_NUMBERS):
            raise ValueError(f"n_points must be an integer >= 1, got {n_points!r}")
        if n_points < 1:
            raise ValueError(f"n_points must be >= 1, got {n_points}")
        if seed is not None and (
            not isinstance(seed, (int, np.integer))
            or isinstance(seed, NOT_NUMBERS)  # True, or 3 ns seeded as 3
            or seed < 0
        ):
            raise ValueError(f"seed must be an integer >= 0 or None, got {seed!r}")
        flat = np.flatnonzero(both)
        if flat.size == 0:
            raise ValueError("no pixel has both an estimated and a ground-truth distance")
        rng = np.random.default_rng(seed)
        pick = np.sort(rng.choice(flat, size=min(n_points, flat.size), replace=False))
        ys, xs = np.unravel_index(pick, e.shape)
    else:
        pts = np.asarray(points)
        if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] == 0 or pts.dtype.kind not in "iu":
            raise ValueError(
                f"points: expected a non-empty integer (N, 2) array of (x, y), got shape "
                f"{pts.shape} dtype {pts.dtype}"
            )
        xs, ys = pts[:, 0], pts[:, 1]
        h, w = e.shape
        inside = (xs >= 0) & (xs < w) & (ys >= 0) & (ys < h)
        if not inside.all():
            raise ValueError(f"points: {pts[~inside].tolist()} lie outside the {w}x{h} image")
        missing = ~both[ys, xs]
        if missing.any():
            raise ValueError(f"points: {pts[missing].tolist()} lack an estimated or GT distance")
    with np.errstate(over="ignore"):  # as dense_metrics: inf beyond float64, unwarned
        est = e[ys, xs] * factor
        ref = g[ys, xs] * factor
        err = est - ref
        rmse = float(np.sqrt(np.mean(err**2)))
        mean_d = float(np.mean(ref))
        mean_error = float(np.mean(err))
        mean_abs_error = float(np.mean(np.abs(err)))
    return Table1Report(
        x=np.asarray(xs, dtype=np.int64),
        y=np.asarray(ys, dtype=np.int64),
        estimated=est,
        ground_truth=ref,
        mean_error=mean_error,
        mean_abs_error=mean_abs_error,
        rmse=rmse,
        rmse_pct=100.0 * rmse / mean_d,
        mean_distance=mean_d,
    )


# --------------------------------------------------------------------------------------- sparse


@dataclass(frozen=True)
class SparseMetrics:
    """Sparse match metrics over the matches whose GT is known (evaluation.md).

    Attributes
    ----------
    precision : dict of float to float
        ``{t: percentage}`` of matches with GT whose ``|(xl - xr) - gt| <= t`` (t = 0.5, 1, 2).
    count : int
        Number of matches with known GT.
    n_matches : int
        Number of matches given.
    coverage : int
        Number of cells of a 4 x 4 grid over the image holding at least one match with GT
        (0 to 16).
    """

    precision: dict[float, float]
    count: int
    n_matches: int
    coverage: int

    def as_dict(self) -> dict[str, float | int]:
        """Flat dict: ``precision@0.5``, ``precision@1.0``, ``precision@2.0``, counts.

        Returns
        -------
        dict
            ``precision@<t>`` per threshold, ``count``, ``n_matches``, ``coverage``.
        """
        out: dict[str, float | int] = {f"precision@{t:.1f}": v for t, v in self.precision.items()}
        out.update(count=self.count, n_matches=self.n_matches, coverage=self.coverage)
        return out


def _coordinates(values: object, name: str) -> npt.NDArray[np.float64]:
    """``values`` (match positions or scores) as float64, refused naming ``name``.

    NumPy's words named nothing: a Matches given for xl was "setting an array element with a
    sequence. The requested array would exceed the maximum number of dimension of 64", a
    string "could not convert string to float: 'a'".
    """
    if isinstance(values, np.ndarray) and values.dtype.kind == "c":
        # the cast dropped the imaginary part with NumPy's ComplexWarning alone (1+4j read as 1);
        # a list of complex numbers is refused below (float() takes none)
        raise ValueError(f"{name}: expected a 1-D array of real numbers, got complex values")
    try:
        return np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        hint = ": pass its arrays, m.xl, m.yl, m.xr" if type(values).__name__ == "Matches" else ""
        raise ValueError(
            f"{name}: expected a 1-D array of numbers, got {type(values).__name__}{hint}"
        ) from None


def sparse_metrics(
    xl: npt.ArrayLike, yl: npt.ArrayLike, xr: npt.ArrayLike, gt: npt.ArrayLike
) -> SparseMetrics:
    """Precision@0.5/1/2, count and 4x4 grid coverage of sparse matches ``(xl, yl) -> xr``.

    The GT is looked up at the rounded ``(xl, yl)`` (round half to even); matches outside the
    image or on unknown GT are not counted.

    Parameters
    ----------
    xl, yl, xr : array_like
        ``(N,)`` left-image coordinates (px) and the matched right-image column.
    gt : array_like
        ``(H, W)`` GT disparity of the left image, non-finite = unknown.

    Returns
    -------
    SparseMetrics
        Precision is NaN when no match has GT.

    Raises
    ------
    ValueError
        If ``xl``, ``yl``, ``xr`` are not 1-D arrays of real numbers of equal length or ``gt`` is
        not 2-D.

    Warns
    -----
    UserWarning
        As :func:`dense_metrics`, for an integer ``gt`` that reads as a disparity PNG's values.
    """
    g = _real_2d(gt, "gt")
    _warn_if_png_gt(g, np.asarray(gt).dtype.kind in "iu", 3)  # no renamed_keyword frame
    arrs = [_coordinates(a, n) for a, n in ((xl, "xl"), (yl, "yl"), (xr, "xr"))]
    if any(a.ndim != 1 for a in arrs) or len({a.shape for a in arrs}) != 1:
        raise ValueError(
            f"xl, yl, xr: expected 1-D arrays of equal length, got shapes {[a.shape for a in arrs]}"
        )
    x, y, x2 = arrs
    h, w = g.shape
    with np.errstate(invalid="ignore"):
        xi = np.rint(x)
        yi = np.rint(y)
        inside = np.isfinite(x2) & (xi >= 0) & (xi < w) & (yi >= 0) & (yi < h)
    xi = np.where(inside, xi, 0).astype(np.int64)
    yi = np.where(inside, yi, 0).astype(np.int64)
    # only the matches inside are looked up (an empty map has no (0, 0) to stand in for the rest)
    gv = np.full(len(x), np.nan)
    gv[inside] = g[yi[inside], xi[inside]]
    has_gt = np.isfinite(gv)
    count = int(has_gt.sum())
    err = np.abs((x - x2)[has_gt] - gv[has_gt])
    precision = {t: _pct(int(np.count_nonzero(err <= t)), count) for t in SPARSE_THRESHOLDS}
    cell_x = np.minimum(xi[has_gt] * COVERAGE_GRID // w, COVERAGE_GRID - 1)
    cell_y = np.minimum(yi[has_gt] * COVERAGE_GRID // h, COVERAGE_GRID - 1)
    coverage = len(set(zip(cell_y.tolist(), cell_x.tolist(), strict=True)))
    return SparseMetrics(precision=precision, count=count, n_matches=len(x), coverage=coverage)


@renamed_keyword("tol", "tolerance")
def count_at_precision(
    xl: npt.ArrayLike,
    yl: npt.ArrayLike,
    xr: npt.ArrayLike,
    score: npt.ArrayLike,
    gt: npt.ArrayLike,
    target: float,
    tolerance: float = 1.0,
) -> int:
    """How many matches with GT a matcher keeps at a given precision, taken best score first.

    The matches are ranked by decreasing ``score`` (stable) and cut to the longest prefix whose
    precision@``tolerance`` over its matches with GT is still >= ``target`` percent; the count
    with GT of that prefix is returned (0 if none qualifies). It compares two matchers at equal
    precision ("more matches than the other would give at that precision").

    Parameters
    ----------
    xl, yl, xr, score : array_like
        ``(N,)`` left positions, matched right column and the matcher's score.
    gt : array_like
        ``(H, W)`` GT disparity of the left image, non-finite = unknown (looked up as in
        :func:`sparse_metrics`).
    target : float
        Precision to hold, percent.
    tolerance : float
        Error bound of the precision (px).
        The keyword ``tol=``, its former name, still works, with a DeprecationWarning.

    Returns
    -------
    int

    Raises
    ------
    ValueError
        As :func:`sparse_metrics`, or if ``score`` has another length.

    Warns
    -----
    UserWarning
        As :func:`dense_metrics`, for an integer ``gt`` that reads as a disparity PNG's values.
    """
    # a target of NaN or above 100 % counted 0 matches, one below 0 all of them, a tolerance of 0,
    # -1 or NaN none, without a word ("1" was NumPy's UFuncTypeError)
    if not (_real(target) and 0.0 <= target <= 100.0):
        raise ValueError(f"target: expected a precision in percent, 0 to 100, got {target!r}")
    if not _positive_finite(tolerance):
        raise ValueError(
            f"tolerance: expected a positive finite number of pixels, got {number_shown(tolerance)}"
        )
    g = _real_2d(gt, "gt")
    _warn_if_png_gt(g, np.asarray(gt).dtype.kind in "iu")
    x, y, x2, s = (
        _coordinates(a, n) for a, n in ((xl, "xl"), (yl, "yl"), (xr, "xr"), (score, "score"))
    )
    if any(a.ndim != 1 for a in (x, y, x2, s)) or len({a.shape for a in (x, y, x2, s)}) != 1:
        raise ValueError(
            "xl, yl, xr, score: expected 1-D arrays of equal length, got shapes "
            f"{[a.shape for a in (x, y, x2, s)]}"
        )
    h, w = g.shape
    with np.errstate(invalid="ignore"):
        xi, yi = np.rint(x), np.rint(y)
        inside = np.isfinite(x2) & (xi >= 0) & (xi < w) & (yi >= 0) & (yi < h)
    gv = np.full(len(x), np.nan)
    gv[inside] = g[yi[inside].astype(np.int64), xi[inside].astype(np.int64)]
    has = np.isfinite(gv)
    order = np.argsort(-s[has], kind="stable")
    good = (np.abs((x - x2)[has] - gv[has]) <= tolerance)[order]
    prec = 100.0 * np.cumsum(good) / np.arange(1, len(good) + 1)
    ok = np.nonzero(prec >= target - 1e-9)[0]
    return int(ok[-1] + 1) if len(ok) else 0
