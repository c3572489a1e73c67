"""Stereo calibration: the :class:`Calibration` record, its file formats, rectification and depth.

Conventions (OpenCV's, same as Bouguet's toolbox and ``cv2.stereoCalibrate``):

* pixel ``(x, y)`` = (column, row), origin at the centre of the top-left pixel;
* ``X_R = R @ X_L + T`` maps a point from left-camera to right-camera coordinates, so a standard
  left/right rig has ``T ~ (-B, 0, 0)`` with ``B`` the baseline;
* distortion coefficients in OpenCV's order ``(k1, k2, p1, p2[, k3[, k4, k5, k6[, s1..s4[, tx,
  ty]]]])``; with ``model="fisheye"`` (wide-angle lenses), OpenCV's equidistant model
  ``cv2.fisheye`` (``theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)``,
  four coefficients; ROS's and Kalibr's ``equidistant``);
* lengths (``T``, baseline) are in the calibration's ``unit``; depths and points returned by
  :meth:`Calibration.depth_from_disparity` and :meth:`Calibration.reproject` are in metres.
"""

from __future__ import annotations

import json
import math
import os
import re
import reprlib
import sys
from collections.abc import Iterable, Sequence
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast, overload

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    MAX_SIDE,
    NOT_NUMBERS,
    as_image_array,
    as_path,
    calib_size_hint,
    crop_or_pad_hint,
    known_unit,
    number_shown,
    positive_finite,
    real_number,
    renamed_keyword,
    same_aspect,
    text_shown,
    too_large_for_float,
    user_stacklevel,
    xy_points,
)

__all__ = [
    "CAMERA_MODELS",
    "DISTORTION_LENGTHS",
    "ROS_DISTORTION_MODELS",
    "UNIT_TO_METRES",
    "Calibration",
    "fit_to_frames",
    "parse_kitti_calib",
    "parse_middlebury_calib",
    "parse_ros_camera_info",
]

PathLike = str | os.PathLike[str]
F64 = npt.NDArray[np.float64]

#: Length units a calibration may use, with their size in metres.
UNIT_TO_METRES: dict[str, float] = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "ft": 0.3048, "in": 0.0254}
#: Distortion vector lengths OpenCV accepts.
DISTORTION_LENGTHS: tuple[int, ...] = (4, 5, 8, 12, 14)
#: Lens models: OpenCV's pinhole with polynomial distortion, and its fisheye (equidistant) model.
CAMERA_MODELS: tuple[str, ...] = ("pinhole", "fisheye")
#: Tolerance of the rotation check on R (orthonormality and det = +1).
ROTATION_TOL = 1e-6
#: Relative tolerance for "equal" numbers of the two cameras of a rectified calibration.
RECTIFIED_REL_TOL = 1e-6
#: Smallest angle (degrees) between the baseline and either camera's optical axis that is
#: rectified. A stereo pair's baseline runs across the views (about 90 degrees); nearer an axis,
#: one camera looks at the other: a baseline along the view (T = (0.001, 0, 0.2)) made
#: stereoRectify return a negative focal length ("K1: focal lengths must be positive", of a
#: matrix the user never gave), and a right camera turned 90 degrees was rectified into a rig
#: reported as a normal one (focal length 500.6 px, 65 degrees of view) with no shared view.
MIN_BASELINE_AXIS_ANGLE_DEG = 45.0
#: Middlebury prints doffs and principal points with 3 decimals: allowed mismatch (px).
DOFFS_TOL_PX = 2e-3
#: Format tag written into saved files.
_FORMAT_TAG = "stereovision-calibration"
_FORMAT_VERSION = 1


def _as_float_array(value: object, name: str, shapes: tuple[tuple[int, ...], ...]) -> F64:
    if np.iscomplexobj(cast(Any, value)):  # NumPy would drop the imaginary part, with a warning
        raise ValueError(f"{name}: expected a real array, got complex values")
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a real array, got {type(value).__name__}") from None
    except OverflowError:
        # an int past a float (a K1 entry of 10**400 in a damaged JSON file) was a bare
        # "OverflowError: int too large to convert to float" naming no matrix (7c64ac6d named
        # image_width's only)
        raise ValueError(f"{name}: contains {_too_large_entry(value)}") from None
    for shape in shapes:
        if arr.shape == shape:
            break
    else:
        # Accept row/column vectors as produced by OpenCV (1, n) / (n, 1).
        if len(shapes[0]) == 1 and arr.ndim == 2 and 1 in arr.shape:
            arr = arr.ravel()
        if not any(arr.shape == s for s in shapes):
            raise ValueError(
                f"{name}: expected shape {' or '.join(map(str, shapes))}, got {arr.shape}"
            )
    if not np.isfinite(arr).all():
        raise ValueError(f"{name}: contains NaN or inf: {arr.tolist()}")
    arr.setflags(write=False)
    return arr


def _too_large_entry(value: object) -> str:
    """What a message says of the first int past a float's range in ``value`` (nested
    lists): ``too_large_for_float``'s words."""
    try:
        flat = np.array(value, dtype=object).ravel().tolist()
    except ValueError:  # ragged
        flat = []
    return next(filter(None, map(too_large_for_float, flat)), "an integer too large for a float")


#: The plausible stereo baseline (metres), the one range every baseline message uses: a
#: baseline outside it is warned about, and a unit suggested instead must bring it inside.
#: Below: the square size given in metres with unit="mm" (a 0.083 mm "rig" for 8.3 cm); the
#: smallest stereo rigs (endoscopes) have a few millimetres. Above: almost always T, or the
#: calibration board's square size, given in millimetres with the default unit "m" (83 m for
#: a 8 cm rig); long-range rigs on vehicles reach 1-2 m. (The unit hints used 5 mm .. 2 m while
#: the warning used 1 mm .. 5 m, so 4000 with unit "m" was warned about without the hint that
#: 4000 mm is a 4 m rig, a baseline the library takes without a word.)
PLAUSIBLE_BASELINE_M = (1e-3, 5.0)
SHORT_BASELINE_M, LONG_BASELINE_M = PLAUSIBLE_BASELINE_M
#: Largest camera-matrix skew (px) taken without a warning: OpenCV's calibration writes 0, and
#: a converted or hand-written file may carry rounding dust.
SKEW_IGNORED_PX = 1e-6


#: Set while this module derives a calibration from one already checked (the rectified pair,
#: a rescaled one): the baseline warnings were given for the original, once.
_DERIVING: ContextVar[bool] = ContextVar("_DERIVING", default=False)


def _plausible_units(
    value: float, unit: str, plausible: tuple[float, float] = PLAUSIBLE_BASELINE_M
) -> list[tuple[str, float]]:
    """The other units in which ``value`` (a number given in ``unit``) lies within
    ``plausible`` (metres), as ``(unit, metres)`` in :data:`UNIT_TO_METRES`' order."""
    lo, hi = plausible
    return [
        (other, value * factor)
        for other, factor in UNIT_TO_METRES.items()
        if other != unit and lo <= value * factor <= hi
    ]


def _unit_suggestion(baseline: float, unit: str) -> str:
    """The unit in which ``baseline`` (a number given in ``unit``) would be a plausible rig's,
    as ``" With unit='m' it would be 8.3 cm."``, or ``""``."""
    found = _plausible_units(baseline, unit)
    if not found:
        return ""
    other, m = found[0]
    return f" With unit={other!r} it would be {_format_length(m)}."


def _format_length(metres: float) -> str:
    """A length for people: ``"1.25 m"``, ``"8.3 cm"``, ``"0.0832 mm"`` (never ``"0.0 cm"``).

    Parameters
    ----------
    metres : float
        The length in metres (``inf`` and NaN are written as such).

    Returns
    -------
    str
        Metres from 1 m, centimetres from 1 cm, else millimetres with 3 significant digits.
    """
    m = float(metres)
    if not math.isfinite(m) or abs(m) >= 1:
        return f"{m:.2f} m"
    if abs(m) >= 0.01:
        return f"{100 * m:.1f} cm"
    return f"{1000 * m:.3g} mm"


def _check_camera_matrix(K: F64, name: str) -> None:
    fx, fy = K[0, 0], K[1, 1]
    if not (fx > 0 and fy > 0):
        raise ValueError(
            f"{name}: focal lengths must be positive, got fx={float(fx):g}, fy={float(fy):g}"
        )
    if K[1, 0] != 0 or not np.allclose(K[2], (0.0, 0.0, 1.0), rtol=0, atol=1e-12):
        # MATLAB's IntrinsicMatrix is K.T: said, as triangulation's check says it (a file's or
        # a script's transposed K1 got the form alone, with cx and cy in its bottom row)
        transposed = K[0, 1] == 0 and np.allclose(K[:, 2], (0.0, 0.0, 1.0), rtol=0, atol=1e-12)
        raise ValueError(
            f"{name}: expected a camera matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]], got "
            f"{K.tolist()}" + (f" (transposed? pass {name}.T)" if transposed else "")
        )
    if abs(K[0, 1]) > SKEW_IGNORED_PX:
        import warnings

        warnings.warn(
            f"{name}: skew K[0,1] = {float(K[0, 1]):g} px is ignored by the rectification "
            "(OpenCV's undistortion maps drop it) and the rectified depths are off by about "
            "skew / fx (0.2 % at 5 px on a synthetic rig); triangulate() uses it",
            UserWarning,
            stacklevel=user_stacklevel(),  # the user's line, also through load() or from_*()
        )


def _close(a: float, b: float, rel: float = RECTIFIED_REL_TOL) -> bool:
    return abs(a - b) <= rel * max(abs(a), abs(b), 1.0)


#: Fields that are vectors, read also from a 1-D array's ``!!opencv-nd-matrix`` (what
#: ``cv2.FileStorage`` writes for a 1-D NumPy array); the matrices K1/M1, K2/M2 and R are not.
_VECTOR_FIELDS = frozenset({"D1", "D2", "T"})


def _node_matrix(node: Any, key: str, source: str, vector: bool = False) -> npt.NDArray[np.float64]:
    """An ``!!opencv-matrix`` node read number by number, checked before anything is sized.

    With ``vector``, a one-dimensional ``!!opencv-nd-matrix`` (``sizes: [n]``; in XML, ``n``; what
    ``cv2.FileStorage`` writes for a 1-D NumPy array, such as distortion coefficients saved
    from ``dist.ravel()``) is read too, as an ``(n,)`` array; elsewhere it is refused as not
    a matrix.

    Not ``FileNode.mat()``: on a damaged matrix (``rows`` or ``cols`` missing, ``data`` shorter
    than ``rows x cols``) OpenCV 5.1 sizes the matrix before its own check fails and writes past
    the buffer; the heap corruption aborted the process a few calibration files later (seen under
    ``MALLOC_CHECK_=3`` in a fuzz of 150 damaged files)."""

    def bad(why: str) -> ValueError:
        return ValueError(f"{source}: field {key!r} is not a matrix: {why}")

    if not node.isMap():
        raise bad("expected rows, cols and data")
    sizes = node.getNode("sizes")
    data = node.getNode("data")
    if not sizes.isNone():
        # !!opencv-nd-matrix: FileStorage's form of an array that is not 2-D
        if not vector:
            raise bad("a !!opencv-nd-matrix (sizes, no rows and cols) where a matrix is expected")
        # YAML writes sizes as [n]; XML's "<sizes>n</sizes>" reads back as a bare integer
        if sizes.isSeq() and sizes.size() == 1:
            sizes = sizes.at(0)
        if not sizes.isInt():
            raise bad("expected a vector: sizes must be one integer, [n]")
        shape: tuple[int, ...] = (int(sizes.real()),)
    else:
        rows, cols = node.getNode("rows"), node.getNode("cols")
        if not (rows.isInt() and cols.isInt()):
            raise bad("rows and cols must be integers")
        shape = (int(rows.real()), int(cols.real()))
    if not data.isSeq():
        raise bad("data must be a list of numbers")
    n, want = int(data.size()), math.prod(shape)
    if min(shape) < 0 or n != want:
        raise bad(f"data holds {n} numbers for {' x '.join(map(str, shape))}")
    values = []
    for i in range(n):
        v = data.at(i)
        if not (v.isReal() or v.isInt()):
            raise bad(f"element {i} of data is not a number")
        values.append(v.real())
    return np.array(values, dtype=np.float64).reshape(shape)


def _open_filestorage(text: str, source: str) -> Any:
    """``cv2.FileStorage`` reading ``text`` (OpenCV YAML/XML or JSON), opened, or a ValueError
    naming ``source``. A damaged file makes OpenCV's parser raise cv2.error (or, from the
    constructor, a SystemError wrapping it): both are the file's fault.

    An XML file without its ``<?xml ...?>`` declaration (hand-edited, or from a tool that
    omits it) is read as XML: OpenCV took it for YAML ("line 1: Invalid or unsupported
    syntax"). The declaration goes on the first line, so the parser's line numbers stay the
    file's. OpenCV tells XML by ``<?xml`` at the very start: blank lines before it made it YAML
    too; they go after the declaration (the line numbers stay)."""
    body = text.lstrip()
    lead = "\n" * text[: len(text) - len(body)].count("\n")
    if body.startswith("<?xml"):
        declaration, end, rest = body.partition("?>")
        text = declaration + end + lead + rest
    elif body.startswith("<opencv_storage"):
        text = '<?xml version="1.0"?>' + lead + body
    # cv::FileStorage's JSON comes here too (Calibration._from_json_text): not "YAML/XML"
    kind = "JSON" if body.startswith("{") else "YAML/XML"
    try:
        fs = cv2.FileStorage(text, cv2.FILE_STORAGE_READ | cv2.FILE_STORAGE_MEMORY)
    except (cv2.error, SystemError) as exc:
        raise ValueError(f"cannot parse {source} as OpenCV {kind}: {_first_line(exc)}") from None
    if not fs.isOpened():
        raise ValueError(f"cannot parse {source} as OpenCV {kind}")
    return fs


def _first_line(exc: BaseException) -> str:
    """OpenCV's own words from a cv2.error (``... error: (-215:Assertion failed) WHAT in
    function ...``: WHAT), also through the SystemError its constructors wrap it in."""
    if isinstance(exc, SystemError) and exc.__cause__ is not None:
        exc = exc.__cause__
    text = str(exc).strip()
    m = re.search(r"error: \([^)]*\) (.*?)(?: in function '([^']*)')?\s*$", text, re.S)
    if m:
        # The YAML parser puts the line and the reason where the function name would be.
        where = re.fullmatch(r"\((\d+)\): (.*)", m.group(2) or "")
        return f"line {where.group(1)}: {where.group(2)}" if where else m.group(1).strip()
    return text.splitlines()[0] if text else type(exc).__name__


#: Fields of which an OpenCV YAML/XML calibration has at least one.
_CALIBRATION_FIELDS = ("image_width", "image_height", "K1", "M1", "K2", "M2", "R", "T")
# One of them as a mapping's key, in block style (at a line's start) or flow style (after "{" or
# ","), quoted or not: what a plain YAML of a calibration holds (Calibration._from_plain_yaml)
_PLAIN_YAML_KEY = re.compile(
    r"(?:^|[{,])[ \t]*([\"']?)(?:" + "|".join(_CALIBRATION_FIELDS) + r")\1[ \t]*:", re.MULTILINE
)


#: Fields of a ``stereovision calibrate`` report (``CalibrationReport.as_dict``).
_REPORT_FIELDS = frozenset(("rms", "used_pairs", "rejected_pairs", "calibration"))

#: Fields of MATLAB's ``stereoParameters`` (its ``toStruct``, saved or ``jsonencode``-d).
_MATLAB_FIELDS = ("CameraParameters1", "CameraParameters2", "RotationOfCamera2")


def _one_ros_camera_info(source: str) -> str:
    """What :meth:`Calibration.load` says of one camera's ROS ``camera_info`` (a file or a
    message echo): a rig is two of them, read by other means."""
    return (
        f"{source} is one camera's ROS camera_info: a rig needs both cameras' files; "
        "read them with Calibration.from_ros(left, right), or from_file on the folder "
        "holding left.yaml and right.yaml"
    )


def _matlab_export(source: str, what: str = "MATLAB's stereoParameters") -> str:
    """How to bring MATLAB's stereo calibration here: its own convention (a transposed
    ``IntrinsicMatrix``, the second camera's pose) is not read, OpenCV's is."""
    return (
        f"{source} is {what}, which is not read here: MATLAB's "
        "stereoParametersToOpenCV gives its K1, D1, K2, D2, R and T in OpenCV's convention; "
        "save them with image_width, image_height and unit (T's unit: MATLAB's default is mm) "
        "as a YAML or JSON file"
    )


def _not_a_calibration_keys(keys: list[str], source: str) -> str:
    """Why a YAML/XML/JSON mapping without any calibration field is not one: MATLAB's export
    (named), or which fields it has."""
    if any(k in _MATLAB_FIELDS for k in keys):
        return _matlab_export(source)
    if _REPORT_FIELDS <= set(keys):
        # report.json / report.yaml lie beside the calibration and were given for it
        return (
            f"{source} is a `stereovision calibrate` report (its figures), not a calibration: "
            "give the calibration file calibrate wrote (its -o / --output file)"
        )
    held = ", ".join(keys) if keys else "nothing"
    return (
        f"{source} is not a calibration: it has none of the fields image_width, K1, K2, R, T "
        f"(it holds: {held})"
    )


def _not_a_calibration(fs: Any, source: str) -> str:
    """Why an OpenCV YAML/XML file without any calibration field is not one: an image list
    (OpenCV's ``stereo_calib.xml`` sample names its chessboard pairs) or which fields it has."""
    root = fs.root()
    keys = [str(k) for k in root.keys()] if root.isMap() else []
    for key in keys:
        node = fs.getNode(key)
        if (
            node.isSeq()
            and node.size() > 0
            and all(node.at(i).isString() for i in range(node.size()))
        ):
            return (
                f"{source} is not a calibration but a list of images ({node.size()} file names "
                f"under {key!r}): calibrate the rig from those images with `stereovision "
                "calibrate --left ... --right ... --square SIZE -o calib.yaml`"
            )
    return _not_a_calibration_keys(keys, source)


# What a file holding cv2.stereoCalibrate's K1 D1 K2 D2 R T alone is told to add.
_SIZE_MISSING = (
    ": add image_width and image_height, the size in pixels of the images it was calibrated "
    "on (cv2.stereoCalibrate's K1, D1, K2, D2, R and T do not hold it)"
)
_UNIT_MISSING = (
    "unit, the length unit of T (that of the board's square size it was calibrated with): "
    "m, mm, cm, ft or in"
)
_MISSING = {
    "image_width": _SIZE_MISSING,
    "image_height": _SIZE_MISSING,
    "unit": ": add " + _UNIT_MISSING,
}


def _pixels(value: object, what: str) -> int:
    """A file's image width or height: a positive whole number of pixels (``1242.0`` is read as
    1242; ``inf``, ``nan``, ``-5`` and ``713.7`` are refused, naming the field and the file)."""
    v = float(value)  # type: ignore[arg-type]
    if not (math.isfinite(v) and v >= 1 and abs(v - round(v)) < 1e-6):
        raise ValueError(f"{what}: expected a positive whole number of pixels, got {v:g}")
    return round(v)


def _resize_advice(size: tuple[int, int], given: tuple[int, int]) -> str:
    """What to do when a file's calibration of ``size`` is given another ``image_size``: leave
    it out or scale the calibration, or, for ``size`` turned (``frame.shape[:2]`` given),
    swap the two, which :meth:`Calibration.scaled_to` refuses to scale to."""
    if not same_aspect(size, given) and same_aspect(size, (given[1], given[0])):
        return "width and height swapped? image_size is (width, height)"
    return (
        f"leave image_size out, or resize the calibration with .scaled_to({given}) if the "
        "images were resized"
    )


def _check_alpha(alpha: object, *, any_finite: bool = False) -> None:
    """A ``ValueError`` naming ``alpha`` unless it is a real number in ``[0, 1]`` (any finite
    one with ``any_finite``: :meth:`Calibration.rectified_calibration` passes OpenCV's -1, a
    pinhole rig's default scaling): ``"1"`` and None were a TypeError from the comparison
    ("'<=' not supported between instances of 'float' and 'str'"), True was read as 1."""
    real = real_number(alpha)
    if any_finite:
        try:
            finite = real and math.isfinite(alpha)  # type: ignore[arg-type]
        except OverflowError:  # an int beyond a float
            finite = False
        if not finite:
            raise ValueError(f"alpha: expected a finite number, got {number_shown(alpha)}")
    elif not (real and 0.0 <= alpha <= 1.0):  # type: ignore[operator]
        raise ValueError(f"alpha: expected a value in [0, 1], got {alpha!r}")


@dataclass(eq=False, frozen=True)
class Calibration:
    """Intrinsics and extrinsics of a stereo pair (OpenCV conventions, see module docstring).

    Parameters
    ----------
    K1, K2 : array_like
        ``(3, 3)`` camera matrices of the left and right camera (pixels).
    D1, D2 : array_like
        ``(n,)`` distortion coefficients, ``n`` in 4, 5, 8, 12, 14 (``(1, n)`` is accepted).
    R : array_like
        ``(3, 3)`` rotation from left- to right-camera coordinates.
    T : array_like
        ``(3,)`` translation in ``unit``: ``X_R = R @ X_L + T``.
    image_size : tuple of int
        ``(width, height)`` in pixels.
    unit : str
        Length unit of ``T``: ``"m"``, ``"mm"``, ``"cm"``, ``"ft"`` or ``"in"``.
    rectified : bool
        True when the images are already rectified (Middlebury, KITTI): then ``R = I``,
        ``T = (-B, 0, 0)``, no distortion, equal focal lengths and rows.
    doffs : float, optional
        Rectified only: ``cx_right - cx_left`` in pixels (Middlebury's ``doffs``); derived from
        ``K1``/``K2`` when omitted, checked against them when given.
    model : str
        ``"pinhole"`` (OpenCV's polynomial distortion) or ``"fisheye"`` (``cv2.fisheye``'s
        equidistant model, ``D`` of 4 coefficients ``k1..k4``): a fisheye rig is rectified by
        ``cv2.fisheye.stereoRectify`` to a pinhole pair, and everything downstream is the same.

    Notes
    -----
    Instances are immutable (frozen, read-only arrays) so that cached rectification maps never
    go stale; use :func:`dataclasses.replace` to derive a modified, re-validated copy.

    Raises
    ------
    ValueError
        Naming the field: wrong shape, NaN/inf, non-positive focal length, ``R`` not a rotation,
        zero baseline, non-positive image size, unknown unit, or a rectified calibration whose
        numbers are not those of a rectified pair.
    """

    K1: F64
    D1: F64
    K2: F64
    D2: F64
    R: F64
    T: F64
    image_size: tuple[int, int]
    unit: str = "m"
    rectified: bool = False
    doffs: float | None = None
    model: str = "pinhole"
    _cache: dict[Any, Any] = field(default_factory=dict, init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "K1", _as_float_array(self.K1, "K1", ((3, 3),)))
        object.__setattr__(self, "K2", _as_float_array(self.K2, "K2", ((3, 3),)))
        dist_shapes = tuple((n,) for n in DISTORTION_LENGTHS)
        object.__setattr__(self, "D1", _as_float_array(self.D1, "D1", dist_shapes))
        object.__setattr__(self, "D2", _as_float_array(self.D2, "D2", dist_shapes))
        object.__setattr__(self, "R", _as_float_array(self.R, "R", ((3, 3),)))
        object.__setattr__(self, "T", _as_float_array(self.T, "T", ((3,),)))
        _check_camera_matrix(self.K1, "K1")
        _check_camera_matrix(self.K2, "K2")
        err = float(np.abs(self.R @ self.R.T - np.eye(3)).max())
        det = float(np.linalg.det(self.R))
        if err > ROTATION_TOL or abs(det - 1.0) > ROTATION_TOL:
            raise ValueError(
                f"R: not a rotation matrix (|R R^T - I| = {err:.3g}, det = {det:.6g}; "
                f"tolerance {ROTATION_TOL})"
            )
        if not float(np.linalg.norm(self.T)) > 0:
            raise ValueError(f"T: zero baseline (T = {self.T.tolist()})")
        object.__setattr__(self, "image_size", self._check_size(self.image_size))
        # a plain str: an np.str_ kept would be said "np.str_('cm')" by later messages
        object.__setattr__(self, "unit", known_unit(self.unit, UNIT_TO_METRES))
        if not isinstance(self.rectified, (bool, np.bool_)):
            raise ValueError(f"rectified: expected a bool, got {self.rectified!r}")
        object.__setattr__(self, "rectified", bool(self.rectified))
        if self.doffs is not None:
            try:
                d = float(self.doffs)
            except OverflowError:  # an int beyond a float: named, not "int too large to convert"
                d = math.nan
            if not math.isfinite(d):
                raise ValueError(
                    f"doffs: expected a finite number of pixels, got {number_shown(self.doffs)}"
                )
            if not self.rectified:
                raise ValueError("doffs: only applies to a rectified calibration")
            object.__setattr__(self, "doffs", d)
        if self.model not in CAMERA_MODELS:
            raise ValueError(f"model: expected one of {list(CAMERA_MODELS)}, got {self.model!r}")
        if self.model == "fisheye":
            for name, coeffs in (("D1", self.D1), ("D2", self.D2)):
                if coeffs.size != 4:
                    raise ValueError(
                        f"{name}: the fisheye model takes 4 coefficients (k1..k4), got "
                        f"{coeffs.size}"
                    )
            if self.rectified:
                raise ValueError("model: a rectified calibration is a pinhole pair, not fisheye")
        if self.rectified:
            self._check_rectified()
        tx, ty, tz = (abs(float(v)) for v in self.T)
        if float(self.T[0]) > 0 and tx > max(ty, tz):
            import warnings

            warnings.warn(
                f"T: the right camera sits to the left of the left one (T[0] = "
                f"{float(self.T[0]):+g} {self.unit}; a left-right rig has T[0] < 0): are the two "
                "cameras (or their files) swapped?",
                UserWarning,
                stacklevel=user_stacklevel(),
            )
        if _DERIVING.get():
            return
        if self.baseline_m > LONG_BASELINE_M or self.baseline_m < SHORT_BASELINE_M:
            import warnings

            long = self.baseline_m > LONG_BASELINE_M
            warnings.warn(
                f"baseline {self.baseline:g} {self.unit}"
                # Converted only when the unit is not metres already ("5 m = 5 m" said nothing).
                + ("" if self.unit == "m" else f" = {self.baseline_m:g} m")
                + ", "
                + (
                    f"longer than a robot's rig ({LONG_BASELINE_M:g} m)"
                    if long
                    else f"shorter than any stereo rig's ({1000 * SHORT_BASELINE_M:g} mm)"
                )
                + f": are T (or the board's square size) in another unit than "
                f"unit={self.unit!r}?{_unit_suggestion(self.baseline, self.unit)}",
                UserWarning,
                stacklevel=user_stacklevel(),
            )

    @staticmethod
    def _check_size(size: object) -> tuple[int, int]:
        if not isinstance(size, (tuple, list, np.ndarray)) or len(size) != 2:
            raise ValueError(f"image_size: expected (width, height), got {size!r}")
        out: list[int] = []
        for v in size:
            if not isinstance(v, (int, np.integer)) or isinstance(v, NOT_NUMBERS) or v <= 0:
                raise ValueError(
                    f"image_size: expected positive integers (width, height), got {size!r}"
                )
            if v > MAX_SIDE:
                # (2**70, 480) or a damaged file's 10**400 was taken, and failed later in
                # OpenCV's words ("stereoRectify ... Can't parse 'imageSize'")
                raise ValueError(
                    f"image_size: at most {MAX_SIDE} px per side (OpenCV's int), got "
                    f"{number_shown(v)}"
                )
            out.append(int(v))
        return out[0], out[1]

    def _check_rectified(self) -> None:
        if np.abs(self.R - np.eye(3)).max() > ROTATION_TOL:
            raise ValueError(f"R: a rectified calibration needs R = I, got {self.R.tolist()}")
        b = float(np.linalg.norm(self.T))
        if abs(self.T[1]) > RECTIFIED_REL_TOL * b or abs(self.T[2]) > RECTIFIED_REL_TOL * b:
            raise ValueError(
                f"T: a rectified calibration needs T = (-B, 0, 0), got {self.T.tolist()}"
            )
        if self.T[0] >= 0:
            raise ValueError(
                f"T: T[0] must be negative (right camera to the right of the left one) for "
                f"a rectified pair, got {self.T.tolist()}"
            )
        for name, d in (("D1", self.D1), ("D2", self.D2)):
            if np.any(d != 0):
                raise ValueError(f"{name}: a rectified calibration has no distortion, got {d}")
        for i, j, what in ((0, 0, "fx"), (1, 1, "fy"), (1, 2, "cy")):
            if not _close(self.K1[i, j], self.K2[i, j]):
                raise ValueError(
                    f"K2: {what} = {float(self.K2[i, j]):g} differs from K1's "
                    f"{float(self.K1[i, j]):g}; a "
                    "rectified pair shares focal length and image rows"
                )
        if self.doffs is not None:
            expected = float(self.K2[0, 2] - self.K1[0, 2])
            if abs(self.doffs - expected) > DOFFS_TOL_PX:
                raise ValueError(
                    f"doffs: {self.doffs!r} differs from cx2 - cx1 = {expected!r} (K2, K1)"
                )

    # ----------------------------------------------------------------------------- equality

    def __repr__(self) -> str:
        # A one-line summary, not the dataclass's five arrays (3 lines each at a prompt):
        # the numbers are the fields, describe() says what they mean.
        w, h = self.image_size
        parts = [f"{w}x{h} px", self.model, "rectified" if self.rectified else "unrectified"]
        metres = "" if self.unit == "m" else f" ({self.baseline_m:.4g} m)"
        parts.append(f"baseline {self.baseline:.4g} {self.unit}{metres}")
        f1 = (float(self.K1[0, 0]), float(self.K1[1, 1]))
        f2 = (float(self.K2[0, 0]), float(self.K2[1, 1]))
        if f1[0] == f1[1] == f2[0] == f2[1]:
            parts.append(f"focal {f1[0]:.5g} px")
        else:
            parts.append(f"focal left {f1[0]:.5g}/{f1[1]:.5g} px, right {f2[0]:.5g}/{f2[1]:.5g} px")
        if not self.rectified:
            angle = float(np.degrees(np.arccos(np.clip((np.trace(self.R) - 1) / 2, -1.0, 1.0))))
            parts.append(f"R {angle:.3g} deg from identity")
            parts.append("distorted" if np.any(self.D1) or np.any(self.D2) else "no distortion")
        elif self.doffs_px:
            parts.append(f"doffs {self.doffs_px:.4g} px")
        return "Calibration(" + "; ".join(parts) + ")"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Calibration):
            return NotImplemented
        arrays = ("K1", "D1", "K2", "D2", "R", "T")
        return (
            all(np.array_equal(getattr(self, a), getattr(other, a)) for a in arrays)
            and self.image_size == other.image_size
            and self.unit == other.unit
            and self.rectified == other.rectified
            and self.doffs == other.doffs
            and self.model == other.model
        )

    __hash__ = None  # type: ignore[assignment]

    # --------------------------------------------------------------------------- properties

    @property
    def to_metres_factor(self) -> float:
        """Size of one calibration ``unit`` in metres (``0.001`` for ``"mm"``)."""
        return UNIT_TO_METRES[self.unit]

    @property
    def baseline(self) -> float:
        """Baseline ``|T|`` in the calibration's unit."""
        return float(np.linalg.norm(self.T))

    @property
    def baseline_m(self) -> float:
        """Baseline ``|T|`` in metres."""
        return self.baseline * self.to_metres_factor

    @property
    def doffs_px(self) -> float:
        """Rectified: ``cx_right - cx_left`` (px), the given ``doffs`` or derived from K1/K2."""
        cal = self if self.rectified else self.rectified_calibration()
        if cal.doffs is not None:
            return cal.doffs
        return float(cal.K2[0, 2] - cal.K1[0, 2])

    @property
    def focal_px(self) -> float:
        """Focal length (px) of the rectified pair (``K1[0, 0]``, or ``P1[0, 0]`` after
        ``cv2.stereoRectify`` with ``alpha=0`` for an unrectified calibration)."""
        cal = self if self.rectified else self.rectified_calibration()
        return float(cal.K1[0, 0])

    @property
    def Q(self) -> F64:
        """``(4, 4)`` disparity-to-depth matrix (OpenCV convention, the calibration's unit).

        For a rectified calibration it is built from K1, K2 and T with ``doffs`` handled::

            [[1, 0, 0, -cx], [0, 1, 0, -cy], [0, 0, 0, f], [0, 0, 1/B, doffs/B]]

        so that ``cv2.reprojectImageTo3D(disp, Q)`` gives ``Z = f B / (d + doffs)``; otherwise
        it is ``cv2.stereoRectify``'s ``Q`` (``alpha=0``, ``CALIB_ZERO_DISPARITY``).
        """
        if not self.rectified:
            q: F64 = self._stereo_rectify(0.0)[4].copy()
            return q
        f = float(self.K1[0, 0])
        tx = float(self.T[0])  # = -B
        cx, cy = float(self.K1[0, 2]), float(self.K1[1, 2])
        return np.array(
            [
                [1.0, 0.0, 0.0, -cx],
                [0.0, 1.0, 0.0, -cy],
                [0.0, 0.0, 0.0, f],
                [0.0, 0.0, -1.0 / tx, -self.doffs_px / tx],
            ]
        )

    # ---------------------------------------------------------------------------- rectifying

    def _check_side_by_side(self) -> None:
        """Refuse to rectify a rig whose baseline is near a camera's optical axis.

        Raises
        ------
        ValueError
            If the baseline is within :data:`MIN_BASELINE_AXIS_ANGLE_DEG` of either optical axis.
        """
        centre = -self.R.T @ self.T  # the right camera's centre, in the left camera's frame
        b = centre / float(np.linalg.norm(centre))
        for side, axis in (("left", np.array([0.0, 0.0, 1.0])), ("right", self.R[2])):
            angle = math.degrees(math.acos(min(1.0, abs(float(b @ axis)))))
            if angle < MIN_BASELINE_AXIS_ANGLE_DEG:
                t = ", ".join(f"{float(v):.4g}" for v in self.T)
                raise ValueError(
                    f"R, T: the baseline (T = ({t}) {self.unit}) is {angle:.1f} degrees from the "
                    f"{side} camera's optical axis; a stereo pair's cameras sit side by side, "
                    f"looking the same way (the baseline at least {MIN_BASELINE_AXIS_ANGLE_DEG:g} "
                    "degrees from each axis): check R and T, and that they map left-camera "
                    "points to the right camera"
                )

    def _stereo_rectify(self, alpha: float) -> tuple[F64, F64, F64, F64, F64]:
        key = ("stereoRectify", float(alpha))
        if key not in self._cache:
            self._check_side_by_side()
            rig = (
                self.K1,
                self.D1,
                self.K2,
                self.D2,
                self.image_size,
                self.R,
                self.T.reshape(3, 1),
            )
            if self.model == "fisheye":
                # alpha plays the part of cv2.fisheye's balance: 0 the focal length that keeps
                # only valid pixels, 1 the one that keeps the whole field.
                r1, r2, p1, p2, q = cv2.fisheye.stereoRectify(
                    *rig,
                    flags=cv2.fisheye.CALIB_ZERO_DISPARITY,
                    newImageSize=self.image_size,
                    balance=float(alpha),
                    fov_scale=1.0,
                )
            else:
                r1, r2, p1, p2, q, roi1, roi2 = cv2.stereoRectify(
                    *rig, flags=cv2.CALIB_ZERO_DISPARITY, alpha=float(alpha)
                )
                self._cache[("roi", float(alpha))] = (tuple(roi1), tuple(roi2))
            self._cache[key] = (r1, r2, p1, p2, q)
        out: tuple[F64, F64, F64, F64, F64] = self._cache[key]
        return out

    def _check_horizontal(self, alpha: float) -> None:
        """Refuse a vertical rig, which nothing here matches: ``cv2.stereoRectify`` aligns its
        columns, not its rows, and ``cv2.fisheye.stereoRectify`` turns its views instead."""
        r1, _, _, p2, _ = self._stereo_rectify(alpha)
        if abs(p2[1, 3]) > abs(p2[0, 3]):
            raise ValueError(
                "R, T: the rig is vertical (stereoRectify produced a vertical baseline); "
                "only horizontal rigs are supported"
            )
        if abs(r1[0, 1]) > abs(r1[0, 0]):
            # cv2.fisheye.stereoRectify always puts the baseline along x: for a vertical
            # rig it turns both views by about 90 degrees instead (width and height swap)
            raise ValueError(
                "R, T: the rig is vertical (fisheye stereoRectify turned the views "
                f"{abs(math.degrees(math.atan2(r1[0, 1], r1[0, 0]))):.0f} degrees to lay its "
                "baseline along the rows); only horizontal rigs are supported"
            )

    def valid_roi(
        self, alpha: float = 0.0
    ) -> tuple[tuple[int, int, int, int], tuple[int, int, int, int]]:
        """Rectangles ``(x, y, width, height)`` of all-valid pixels in the rectified images.

        With ``alpha=0`` they cover (nearly) the whole image; with ``alpha=1`` every source pixel
        is kept and the black borders lie outside them. A ``rectified`` calibration has the full
        image as its ROI.

        Parameters
        ----------
        alpha : float
            Free scaling of :meth:`rectify`, in ``[0, 1]``.

        Returns
        -------
        tuple
            ``(roi_left, roi_right)``.
        """
        w, h = self.image_size
        _check_alpha(alpha)  # also of a rectified calibration: alpha=5 passed there unsaid
        if self.rectified:
            return (0, 0, w, h), (0, 0, w, h)
        self._stereo_rectify(alpha)
        if ("roi", float(alpha)) not in self._cache:  # fisheye: OpenCV gives none; from the maps
            m1x, m1y, m2x, m2y = self._maps(alpha)
            self._cache[("roi", float(alpha))] = (
                _inner_rectangle(m1x, m1y, self.image_size),
                _inner_rectangle(m2x, m2y, self.image_size),
            )
        rois: tuple[tuple[int, int, int, int], tuple[int, int, int, int]] = self._cache[
            ("roi", float(alpha))
        ]
        return rois

    def _maps(self, alpha: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        key = ("maps", float(alpha))
        if key not in self._cache:
            r1, r2, p1, p2, _ = self._stereo_rectify(alpha)
            init = (
                cv2.fisheye.initUndistortRectifyMap
                if self.model == "fisheye"
                else cv2.initUndistortRectifyMap
            )
            m1x, m1y = init(self.K1, self.D1, r1, p1, self.image_size, cv2.CV_32FC1)
            m2x, m2y = init(self.K2, self.D2, r2, p2, self.image_size, cv2.CV_32FC1)
            self._cache[key] = (m1x, m1y, m2x, m2y)
        out: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] = self._cache[key]
        return out

    def rectify(
        self, left: npt.ArrayLike, right: npt.ArrayLike, alpha: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """Rectify a raw pair so that epipolar lines are image rows.

        For a ``rectified`` calibration the inputs are returned unchanged (same objects, same
        pixel frame, no warping). Otherwise ``cv2.stereoRectify`` (``CALIB_ZERO_DISPARITY``),
        ``cv2.initUndistortRectifyMap`` and ``cv2.remap`` (bilinear) are applied; the maps are
        cached per ``alpha``. Use :meth:`rectified_calibration` with the same ``alpha`` for the
        geometry of the result.

        Parameters
        ----------
        left, right : array_like
            Images of size ``image_size`` (grey or colour, any dtype OpenCV remaps).
        alpha : float
            ``cv2.stereoRectify`` free scaling: 0 keeps only valid pixels, 1 keeps all pixels.

        Returns
        -------
        tuple of numpy.ndarray
            ``(left_rectified, right_rectified)``, same shapes and dtypes as the inputs.

        Raises
        ------
        ValueError
            If an image is not an image array or its size differs from ``image_size``,
            ``alpha`` is outside ``[0, 1]``, or the rig is vertical (as
            :meth:`rectified_calibration`).
        """
        la = as_image_array(left, "left")
        ra = as_image_array(right, "right")
        w, h = self.image_size
        for name, a in (("left", la), ("right", ra)):
            if a.shape[:2] != (h, w):
                # depth_map's hint too: a pair resized from the calibration's (a lower camera
                # mode) was told the two sizes only, not of scaled_to
                hint = calib_size_hint((w, h), (a.shape[1], a.shape[0]))
                raise ValueError(
                    f"{name}: image is {a.shape[1]}x{a.shape[0]}, calibration image_size is "
                    f"{w}x{h} ({hint})"
                )
        _check_alpha(alpha)  # also of a rectified calibration: alpha=5 passed there unsaid
        if self.rectified:
            return la, ra
        # a vertical rig came out aligned by columns without a word, and `stereovision check`
        # then said "the calibration no longer rectifies this rig: recalibrate"
        self._check_horizontal(alpha)
        return self._remap_pair(la, ra, alpha)

    def _remap_pair(
        self, la: np.ndarray, ra: np.ndarray, alpha: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`rectify`'s warp, of a vertical rig too (to columns: calibrate's report)."""
        m1x, m1y, m2x, m2y = self._maps(alpha)
        from stereovision._validate import remap_image

        # cv2.remap drops the channel axis of an (H, W, 1) image: given back in its own shape
        return (
            remap_image(la, m1x, m1y, cv2.INTER_LINEAR).reshape(la.shape),
            remap_image(ra, m2x, m2y, cv2.INTER_LINEAR).reshape(ra.shape),
        )

    def rectify_points(self, points: npt.ArrayLike, side: str = "left", alpha: float = 0.0) -> F64:
        """Raw pixel positions of one camera mapped to the rectified image of :meth:`rectify`.

        ``cv2.undistortPoints`` (``cv2.fisheye.undistortPoints`` for a fisheye rig) with that
        camera's rectifying rotation and projection: features found on raw frames (a tracker's,
        a board's corners) land where :meth:`rectify` puts their pixels. A ``rectified``
        calibration returns the points unchanged.

        Parameters
        ----------
        points : array_like
            ``(N, 2)`` raw pixel coordinates ``(x, y)``.
        side : str
            ``"left"`` or ``"right"``.
        alpha : float
            As in :meth:`rectify`.

        Returns
        -------
        numpy.ndarray
            ``(N, 2)`` float64 rectified pixel coordinates.

        Raises
        ------
        ValueError
            For points not of shape ``(N, 2)``, an unknown ``side``, ``alpha`` outside
            ``[0, 1]``, or a vertical rig (as :meth:`rectify`).
        """
        pts = xy_points(points)
        if side not in ("left", "right"):
            raise ValueError(f"side: expected 'left' or 'right', got {side!r}")
        _check_alpha(alpha)  # also of a rectified calibration or no points
        if self.rectified:
            return pts.copy()
        self._check_horizontal(alpha)
        return self._moved_points(pts, side, alpha)

    def _moved_points(self, pts: F64, side: str, alpha: float) -> F64:
        """:meth:`rectify_points`' mapping, of a vertical rig too (calibrate's checks)."""
        if len(pts) == 0:
            return pts.copy()
        r1, r2, p1, p2, _ = self._stereo_rectify(alpha)
        K, D, r, p = (self.K1, self.D1, r1, p1) if side == "left" else (self.K2, self.D2, r2, p2)
        src = pts.reshape(-1, 1, 2)
        # Iterate to convergence: OpenCV's default 5 steps leave a visible error far off axis,
        # and 40 left 524 of a StereoPi camera's pixels (within 44 px of its corners) up to
        # 2.8 px from where rectify puts them; a point stops once converged (triangulation's
        # UNDISTORT_MAX_ITER: those creep near a wide lens' corners)
        crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 1000, 1e-12)
        undistort = cv2.fisheye.undistortPoints if self.model == "fisheye" else cv2.undistortPoints
        out = undistort(src, K, D, R=r, P=p, criteria=crit)
        res: F64 = np.asarray(out, np.float64).reshape(-1, 2)
        return res

    def rectified_calibration(self, alpha: float = 0.0) -> Calibration:
        """Calibration of the pair produced by :meth:`rectify` with the same ``alpha``.

        ``K1``/``K2`` are ``P1[:, :3]``/``P2[:, :3]`` of ``cv2.stereoRectify``, no distortion,
        ``R = I``, ``T = (P2[0, 3] / P2[0, 0], 0, 0) = (-B, 0, 0)``, ``rectified=True``. A
        rectified calibration returns itself.

        Parameters
        ----------
        alpha : float
            ``cv2.stereoRectify`` free scaling, as given to :meth:`rectify`: 0 keeps only valid
            pixels, 1 keeps all pixels. Any finite number is passed on, so that OpenCV's -1
            (its default scaling) works on a pinhole rig; a fisheye rig's balance takes values
            outside [0, 1] as the nearer end (-1 gives the focal length of 0).

        Returns
        -------
        Calibration
            The rectified pair's calibration (``rectified=True``).

        Raises
        ------
        ValueError
            For a vertical rig (OpenCV rectifies a pinhole one to columns and turns a fisheye
            one's views by 90 degrees, neither of which this package handles) or a right camera
            to the left of the left one.
        """
        _check_alpha(alpha, any_finite=True)  # float() read "1" and True as 1, NaN went to OpenCV
        if self.rectified:
            return self
        key = ("rectified_calibration", float(alpha))
        if key not in self._cache:
            self._check_horizontal(alpha)
            _, _, p1, p2, _ = self._stereo_rectify(alpha)
            token = _DERIVING.set(True)
            try:
                self._cache[key] = Calibration(
                    K1=p1[:, :3],
                    D1=np.zeros(5),
                    K2=p2[:, :3],
                    D2=np.zeros(5),
                    R=np.eye(3),
                    T=np.array([p2[0, 3] / p2[0, 0], 0.0, 0.0]),
                    image_size=self.image_size,
                    unit=self.unit,
                    rectified=True,
                )
            finally:
                _DERIVING.reset(token)
        cal: Calibration = self._cache[key]
        return cal

    @overload
    def depth_step(
        self, depth_m: float | np.floating[Any] | np.integer[Any], disparity_step: float = 1.0
    ) -> float: ...
    @overload
    def depth_step(self, depth_m: npt.ArrayLike, disparity_step: float = 1.0) -> F64: ...
    def depth_step(self, depth_m: npt.ArrayLike, disparity_step: float = 1.0) -> float | F64:
        """Depth change (metres) that a disparity change of ``disparity_step`` px makes at
        ``depth_m``: ``Z^2 dd / (f B)``, the rig's depth resolution.

        Parameters
        ----------
        depth_m : float or array_like
            Depth or depths in metres.
        disparity_step : float
            Disparity change in pixels (1 for a whole pixel; a matcher's sub-pixel error).

        Returns
        -------
        float or numpy.ndarray
            For one depth (a Python or NumPy number, e.g. ``np.float32(5)``) a float
            (``numpy.float64``, a ``float``); else float64, the shape of ``depth_m``
            (NaN where ``depth_m`` is: a depth map's pixels without depth).

        Raises
        ------
        ValueError
            If ``depth_m`` is not real numbers, or a negative one, or ``disparity_step`` not a
            positive finite number.
        """
        # NumPy's conversions read "5" as 5 m, None as NaN and True as 1 without a word, and a
        # step of 0, -1 or NaN gave a resolution of 0, a negative one or NaN
        raw = np.asarray(depth_m)
        if raw.dtype.kind not in "iuf":
            raise ValueError(
                f"depth_m: expected depths in metres (real numbers), got {type(depth_m).__name__} "
                f"{reprlib.repr(depth_m)} (dtype {raw.dtype})"
            )
        step = positive_finite(disparity_step, "disparity_step")
        z = raw.astype(np.float64)
        # Z^2 gave -1 m the step of +1 m (a sign slip, a z axis pointing back) without a word
        behind = z[z < 0]  # NaN (no depth) compares False: still NaN below
        if behind.size:
            got = f"{float(behind[0])!r}"
            if z.ndim:
                got = f"{behind.size} of {z.size} negative, the first {got}"
            raise ValueError(f"depth_m: expected depths in metres, 0 or more, got {got}")
        fb = self.focal_px * self.baseline_m
        out: F64 = z * z * step / fb
        return out

    def describe(self, depths: tuple[float, ...] = (1.0, 2.0, 5.0, 10.0)) -> str:
        """What the rig can measure, in a few lines: baseline, focal length, field of view,
        nearest depth per disparity range, depth step per pixel, farthest depth.

        Parameters
        ----------
        depths : tuple of float
            Depths (metres) at which to give the depth step.

        Returns
        -------
        str
            Lines for a terminal or a log.

        Raises
        ------
        ValueError
            If ``depths`` is not one or more positive finite numbers, or the rig is vertical (as
            :meth:`rectified_calibration`).
        """
        # a negative depth was said to have a step ("at -1 m 2.3 cm"), NaN "at nan m none", no
        # depth an empty list, and one number TypeError "'float' object is not iterable"
        # a 0-d array is Iterable, but iterating it was TypeError "iteration over a 0-d array"
        if (
            isinstance(depths, (str, bytes))
            or not isinstance(depths, Iterable)
            or (isinstance(depths, np.ndarray) and depths.ndim == 0)
        ):
            raise ValueError(f"depths: expected a sequence of depths in metres, got {depths!r}")
        depths = tuple(positive_finite(z, "depths") for z in depths)
        if not depths:
            raise ValueError("depths: expected at least one depth in metres, got none")
        rc = self if self.rectified else self.rectified_calibration()
        w, h = self.image_size
        f, fy = float(rc.K1[0, 0]), float(rc.K1[1, 1])
        b = self.baseline_m
        doffs = rc.doffs_px
        # edge to edge (pixel centres at 0 .. w - 1) about the principal point, which need not
        # be centred (ETH3D's playground: 81.35, not 81.9 degrees)
        cx, cy = float(rc.K1[0, 2]), float(rc.K1[1, 2])
        hfov = math.degrees(math.atan((cx + 0.5) / f) + math.atan((w - 0.5 - cx) / f))
        vfov = math.degrees(math.atan((cy + 0.5) / fy) + math.atan((h - 0.5 - cy) / fy))

        length = _format_length
        near = ", ".join(
            f"{d} px {length(f * b / (d + doffs))}" for d in (64, 128, 256) if d + doffs > 0
        )
        if not near:  # doffs <= -256: every range ends before a disparity gives a depth
            near = f"none (a depth needs a disparity above {-doffs:.2f} px)"
        # d + doffs <= 0 is at or beyond infinity: with doffs <= -1 (cx2 < cx1 - 1) a disparity
        # of 1 px has no depth, and the farthest is one pixel above infinity's -doffs (it said
        # "inf m").
        if 1 + doffs > 0:
            far_m = f * b / (1 + doffs)
            far = f"farthest depth, at a disparity of 1 px: {length(far_m)}"
        else:
            far_m = f * b
            far = (
                f"farthest depth, at a disparity of {1 - doffs:.2f} px (1 px above infinity's "
                f"{-doffs:.2f} px): {length(far_m)}"
            )
        # a depth past the farthest has no step (doffs 100 px: farthest 0.5 m, yet steps at 5
        # and 10 m were listed)
        steps = ", ".join(
            f"at {z:g} m {length(float(self.depth_step(z)))}" if z <= far_m else f"at {z:g} m none"
            for z in depths
        )
        if any(z > far_m for z in depths):
            steps += " (none: beyond the farthest depth)"
        kind = (
            "rectified pair"
            if self.rectified
            else f"raw {'fisheye ' if self.model == 'fisheye' else ''}rig, rectified with alpha 0"
        )
        return "\n".join(
            [
                f"{w}x{h} px, {kind}: baseline {length(b)} ({self.baseline:g} {self.unit}), "
                f"focal length {f:.1f} px, doffs {doffs:.2f} px",
                f"field of view {hfov:.1f} x {vfov:.1f} degrees",
                f"depth Z = {f * b:.3f} m px / (d {'-' if doffs < 0 else '+'} {abs(doffs):.2f} px)",
                f"nearest depth a disparity range reaches: {near}",
                f"depth step per pixel of disparity: {steps} (a 0.1 px error: a tenth of it)",
                far,
            ]
        )

    def scaled_to(self, image_size: tuple[int, int]) -> Calibration:
        """The calibration of the same rig for its images resized (not cropped) to ``image_size``.

        A camera run at a lower resolution than it was calibrated at (640x360 from a 1280x720
        calibration) scales its pixels: ``x' = (x + 0.5) s_x - 0.5`` with ``s_x = W' / W``, so
        ``f_x' = s_x f_x``, ``c_x' = (c_x + 0.5) s_x - 0.5`` (likewise in y), ``doffs' =
        s_x doffs``. Distortion (in normalised coordinates), ``R`` and ``T`` are unchanged. A
        camera mode that crops the sensor instead needs a calibration of its own.

        Parameters
        ----------
        image_size : tuple of int
            ``(width, height)`` of the resized images.

        Returns
        -------
        Calibration
            This calibration when the size is already ``image_size``.

        Raises
        ------
        ValueError
            If ``image_size`` is not two positive integers, or is the calibration's size turned
            (``(height, width)``: ``frame.shape[:2]`` given for ``frame.shape[1::-1]``).
        """
        size = self._check_size(image_size)
        if size == self.image_size:
            return self
        turned = (size[1], size[0])
        if not same_aspect(self.image_size, size) and same_aspect(self.image_size, turned):
            # frame.shape[:2] for (width, height): scaled by 3/8 and 2/3 (a 640x480 rig, 320x240
            # frames), a calibration of no camera, said only by depth_map's size check later
            w, h = self.image_size
            raise ValueError(
                f"image_size: {size[0]}x{size[1]} is the calibration's {w}x{h} turned: width "
                f"and height swapped? image_size is (width, height): ({turned[0]}, "
                f"{turned[1]}) (an image's shape[1::-1], not its shape[:2])"
            )
        return self._scaled(size, size[0] / self.image_size[0], size[1] / self.image_size[1])

    def _scaled(self, size: tuple[int, int], sx: float, sy: float) -> Calibration:
        """:meth:`scaled_to` with its pixel scales given: a camera binning b pixels into one
        scales by exactly 1 / b, while its ``size`` (``W // b``) drops the rest of a row."""

        def scale(k: F64) -> F64:
            out = k.copy()
            out[0, 0], out[0, 1], out[1, 1] = k[0, 0] * sx, k[0, 1] * sx, k[1, 1] * sy
            out[0, 2] = (k[0, 2] + 0.5) * sx - 0.5
            out[1, 2] = (k[1, 2] + 0.5) * sy - 0.5
            return out

        k1, k2 = scale(self.K1), scale(self.K2)
        doffs = None if self.doffs is None else self.doffs * sx
        if doffs is not None and abs(doffs - (k2[0, 2] - k1[0, 2])) > DOFFS_TOL_PX:
            # a doffs within DOFFS_TOL_PX of cx2 - cx1 (Middlebury's 3 decimals) is off by more
            # once enlarged: a quarter-size calib.txt 1.5e-3 px off was refused at twice its size
            # ("doffs: 20.003 differs from cx2 - cx1 = 20.0"). The right camera's cx takes the
            # rounding: doffs gives the depths, and the file saved is read back.
            k2[0, 2] = k1[0, 2] + doffs
        token = _DERIVING.set(True)
        try:
            return Calibration(
                K1=k1,
                D1=self.D1,
                K2=k2,
                D2=self.D2,
                R=self.R,
                T=self.T,
                image_size=size,
                unit=self.unit,
                rectified=self.rectified,
                doffs=doffs,
                model=self.model,
            )
        finally:
            _DERIVING.reset(token)

    def to_camera_frame(self, points: npt.ArrayLike) -> npt.NDArray[np.floating[Any]]:
        """Points from the left *rectified* frame to the left camera's own frame.

        :func:`stereovision.depth_map` returns points in the rectified left camera's frame,
        which ``cv2.stereoRectify`` turns by ``R1`` away from the physical left camera (a
        degree or more on a hand-built rig). A robot's transform tree places the physical
        camera, so map the points back first: ``X_cam = R1^T X_rect``. ``R1`` does not depend
        on ``alpha``. For a ``rectified`` calibration the frames coincide.

        Parameters
        ----------
        points : array_like
            ``(..., 3)`` points in the left rectified frame (any unit).

        Returns
        -------
        numpy.ndarray
            The same shape and float dtype (float32 stays float32), in the left camera frame.

        Raises
        ------
        ValueError
            If the last axis is not 3.
        """
        pts = np.asarray(points)
        if pts.ndim == 0 or pts.shape[-1] != 3:
            raise ValueError(f"points: expected shape (..., 3), got {pts.shape}")
        dtype = pts.dtype if pts.dtype in (np.float32, np.float64) else np.float64
        if self.rectified:
            return pts.astype(dtype, copy=True)
        r1 = self._stereo_rectify(0.0)[0]
        # row vectors: (R1^T x)^T = x^T R1
        out: npt.NDArray[np.floating[Any]] = (pts.astype(np.float64) @ r1).astype(dtype)
        return out

    # ------------------------------------------------------------------------------- depth

    @renamed_keyword("disp", "disparity")
    def depth_from_disparity(
        self, disparity: npt.ArrayLike, unit: str = "m"
    ) -> npt.NDArray[np.float32]:
        """Depth from a rectified-frame disparity map (algorithms.md E.3), in metres unless
        ``unit`` says otherwise (as :func:`stereovision.depth_from_disparity`).

        ``Z = f B / (d + doffs)``; ``d <= -doffs`` or NaN gives NaN. See
        :func:`stereovision.triangulation.depth_from_disparity`.

        Parameters
        ----------
        disparity : array_like
            Disparity in pixels, left rectified image (NaN where none). The keyword ``disp=``,
            its former name, still works, with a DeprecationWarning.
        unit : str
            Length unit of the result: ``"m"``, ``"mm"``, ``"cm"``, ``"ft"`` or ``"in"``.

        Returns
        -------
        ndarray, float32
            Depth ``Z``, the shape of ``disparity``, NaN where none.
        """
        from stereovision.triangulation import _depth_from_disparity

        return _depth_from_disparity(disparity, self, unit, 3)  # 3: renamed_keyword's frame

    @renamed_keyword("disp", "disparity")
    def reproject(self, disparity: npt.ArrayLike, unit: str = "m") -> npt.NDArray[np.float32]:
        """``(H, W, 3)`` points in metres unless ``unit`` says otherwise (left rectified frame:
        X right, Y down, Z forward).

        See :func:`stereovision.triangulation.reproject`.

        Parameters
        ----------
        disparity : array_like
            ``(H, W)`` disparity in pixels, left rectified image (NaN where none). The keyword
            ``disp=``, its former name, still works, with a DeprecationWarning.
        unit : str
            Length unit of the result: ``"m"``, ``"mm"``, ``"cm"``, ``"ft"`` or ``"in"``.

        Returns
        -------
        ndarray, float32
            ``(H, W, 3)`` points ``X, Y, Z``, NaN where ``disparity`` has no depth.
        """
        from stereovision.triangulation import _reproject

        return _reproject(disparity, self, unit, 3)  # 3: renamed_keyword's frame

    # ------------------------------------------------------------------------------ saving

    def _to_record(self) -> dict[str, Any]:
        rec: dict[str, Any] = {
            "format": _FORMAT_TAG,
            "version": _FORMAT_VERSION,
            "K1": self.K1,
            "D1": self.D1,
            "K2": self.K2,
            "D2": self.D2,
            "R": self.R,
            "T": self.T,
            "image_width": self.image_size[0],
            "image_height": self.image_size[1],
            "unit": self.unit,
            "rectified": int(self.rectified),
        }
        if self.doffs is not None:
            rec["doffs"] = self.doffs
        if self.model != "pinhole":  # older files have no model: they are pinhole
            rec["model"] = self.model
        return rec

    def save(self, path: PathLike) -> Path:
        """Write the calibration atomically and return the path written.

        ``.yaml``/``.yml``/``.xml`` are written with ``cv2.FileStorage`` (readable by OpenCV in
        any language: matrices ``K1 D1 K2 D2 R T``, ``image_width``, ``image_height``, ``unit``,
        ``rectified``, ``doffs``); ``.json`` holds the same fields as nested lists. Both round
        trip every float64 bit-identically.

        Parameters
        ----------
        path : str or os.PathLike
            Destination, ``.yaml``, ``.yml``, ``.xml`` or ``.json``.

        Returns
        -------
        pathlib.Path
            The path written.

        Raises
        ------
        ValueError
            For another file extension.
        FileNotFoundError
            If the directory does not exist.
        """
        from stereovision.io import atomic_write

        p = as_path(path, file=True)
        text = self._file_text(p)
        with atomic_write(p, "w") as fh:
            fh.write(text)
        return p

    def _file_text(self, path: PathLike) -> str:
        """The text :meth:`save` writes to ``path`` (its format from the extension): what a
        command compares with the file there before replacing it
        (:func:`stereovision.io.keep_previous`). ValueError for another extension."""
        p = Path(path)
        suffix = p.suffix.lower()
        rec = self._to_record()
        if suffix in (".yaml", ".yml", ".xml"):
            fmt = cv2.FILE_STORAGE_FORMAT_XML if suffix == ".xml" else cv2.FILE_STORAGE_FORMAT_YAML
            fs = cv2.FileStorage("", cv2.FILE_STORAGE_WRITE | cv2.FILE_STORAGE_MEMORY | fmt)
            for key, value in rec.items():
                if isinstance(value, np.ndarray):
                    fs.write(
                        key,
                        value.reshape(-1, 1)
                        if key == "T"
                        else value.reshape(1, -1)
                        if key in ("D1", "D2")
                        else value,
                    )
                else:
                    fs.write(key, value)
            text = fs.releaseAndGetString()
        elif suffix == ".json":
            text = json.dumps(
                {k: v.tolist() if isinstance(v, np.ndarray) else v for k, v in rec.items()},
                indent=2,
            )
        else:
            raise ValueError(
                f"cannot save a calibration as {p.name!r}: use .yaml, .yml, .xml or .json"
            )
        return str(text)

    @classmethod
    def _made(cls, where: str, **fields: Any) -> Calibration:
        """The calibration of a file's numbers, a refusal naming the file: the constructor's
        "K2: fy = 720 differs from K1's 700" said nothing of which calib.txt among many."""
        try:
            return cls(**fields)
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None

    @classmethod
    def _from_mapping(cls, get: Any, source: str, unit: str | None = None) -> Calibration:
        # unit: from_file's, for a file without its own (a file's own unit wins; from_file
        # refuses a disagreeing one)
        def need(key: str, *aliases: str) -> Any:
            for k in (key, *aliases):
                v = get(k)
                if v is not None:
                    return v
            hint = _MISSING.get(key, "")
            if key.startswith("image_") and get("unit") is None:
                hint += ", and " + _UNIT_MISSING  # both missing: both said at once
            raise ValueError(f"calibration file {source} lacks field {key!r}{hint}")

        def integer(key: str) -> int:
            v = need(key)
            # an int past a float (a width of 10**400, JSON's or YAML's) was a bare
            # "OverflowError: int too large to convert to float"
            ok = real_number(v) and too_large_for_float(v) is None
            if not ok or not math.isfinite(float(v)) or float(v) != int(v):
                raise ValueError(
                    f"calibration file {source}: {key} must be an integer, got {number_shown(v)}"
                )
            return int(v)

        width = integer("image_width")
        height = integer("image_height")
        rectified = get("rectified") or 0
        if rectified not in (0, 1, True, False):
            raise ValueError(
                f"calibration file {source}: rectified must be 0 or 1, got {rectified!r}"
            )
        doffs = get("doffs")
        if doffs is not None and (not real_number(doffs)):
            raise ValueError(f"calibration file {source}: doffs must be a number, got {doffs!r}")
        model = get("model")
        fields = {
            "K1": need("K1", "M1"),
            "D1": need("D1"),
            "K2": need("K2", "M2"),
            "D2": need("D2"),
            "R": need("R"),
            "T": need("T"),
            "unit": str(need("unit")) if unit is None or get("unit") is not None else unit,
        }
        try:
            return cls(
                **fields,
                image_size=(width, height),
                rectified=bool(rectified),
                doffs=None if doffs is None else float(doffs),
                model="pinhole" if model is None else str(model),
            )
        except ValueError as exc:
            # a value refused by the class ("unit: expected one of [...], got 'meters'") named
            # no file: a hand-edited one among several said nothing of which
            raise ValueError(f"calibration file {source}: {exc}") from None

    @classmethod
    def _from_filestorage_text(cls, text: str, source: str, unit: str | None = None) -> Calibration:
        fs = _open_filestorage(text, source)

        def get(key: str) -> Any:
            node = fs.getNode(key)
            if node.isNone():
                return None
            if node.isString():
                return node.string()
            if node.isInt():
                return int(node.real())
            if node.isReal():
                return node.real()
            return _node_matrix(node, key, source, vector=key in _VECTOR_FIELDS)

        try:
            if all(fs.getNode(k).isNone() for k in _CALIBRATION_FIELDS):
                raise ValueError(_not_a_calibration(fs, source))
            return cls._from_mapping(get, source, unit)
        finally:
            fs.release()

    @classmethod
    def _from_json_text(cls, text: str, source: str, unit: str | None = None) -> Calibration:
        try:
            obj = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ValueError(f"cannot parse {source} as JSON: {exc}") from None
        if not isinstance(obj, dict):
            raise ValueError(f"{source}: expected a JSON object, got {type(obj).__name__}")
        if "H1" in obj and "H2" in obj and "F" in obj:
            raise ValueError(
                f"{source} holds the homographies `stereovision rectify` found for a rig without "
                "a calibration (disparity only): give it as --rectification (in Python: "
                "stereovision.uncalibrated.UncalibratedRectification.load(path), passed as calib)"
            )
        if not any(k in obj for k in _CALIBRATION_FIELDS):  # as a YAML file says it
            raise ValueError(_not_a_calibration_keys([str(k) for k in obj], source))
        if any(
            isinstance(v, dict) and str(v.get("type_id", "")).startswith("opencv-")
            for v in obj.values()
        ):
            # cv::FileStorage's JSON (a .json name in any language): its matrices are
            # {"type_id": "opencv-matrix", "rows", "cols", "data"}, refused as "K1: expected a
            # real array, got dict"; read as OpenCV reads it (which takes a file starting with a
            # blank for YAML)
            return cls._from_filestorage_text(text.lstrip(), source, unit)
        return cls._from_mapping(obj.get, source, unit)

    @staticmethod
    def _read_text(path: PathLike, name: str = "path") -> tuple[Path, str]:
        p = as_path(path, name, file=True)
        if not p.exists():
            # a link whose target moved, a ~ left as typed: said, as imread says them
            from stereovision.io import _missing_hint

            raise FileNotFoundError(f"calibration file not found: {p}{_missing_hint(path, p)}")
        if not p.is_file():
            raise ValueError(f"calibration path is not a file: {p}")
        try:
            # "-sig": a byte-order mark (Windows editors write one) hid the file's start
            return p, p.read_text(encoding="utf-8-sig")
        except UnicodeDecodeError:
            with p.open("rb") as fh:
                if fh.read(6) == b"MATLAB":  # a MAT-file's header (v5, v7, v7.3)
                    raise ValueError(_matlab_export(str(p), "a MATLAB MAT-file")) from None
            raise ValueError(f"not a text calibration file: {p}") from None

    @classmethod
    def load(cls, path: PathLike) -> Calibration:
        """Read a calibration written by :meth:`save` (OpenCV YAML/XML or JSON).

        The format is recognised from the content; JSON is :meth:`save`'s nested lists or
        ``cv::FileStorage``'s JSON (matrices as ``opencv-matrix`` objects); a YAML file without
        OpenCV's header (``%YAML:1.0`` from 4.x, ``%YAML 1.2`` from 5.x) and matrix tags (a
        script's ``yaml.safe_dump``) is read as the JSON's nested lists. ``M1``/``M2``
        (OpenCV's ``stereo_calib`` sample names) are accepted for ``K1``/``K2``.

        Parameters
        ----------
        path : str or os.PathLike
            A file written by :meth:`save` (or OpenCV YAML/XML / JSON with the same fields).

        Returns
        -------
        Calibration
            The calibration the file holds.

        Raises
        ------
        FileNotFoundError
            If ``path`` does not exist.
        ValueError
            If the file is not such a calibration, lacks a field (named), or holds invalid
            values (see :class:`Calibration`).
        """
        return cls._load(path)

    @classmethod
    def _load(cls, path: PathLike, unit: str | None = None) -> Calibration:
        """:meth:`load`, a file without ``unit`` given ``unit`` (:meth:`from_file`'s)."""
        p, text = cls._read_text(path)
        head = text.lstrip()
        if head.startswith("%YAML") and "!!opencv-matrix" not in text:
            # PyYAML's directive (yaml.safe_dump(..., version=(1, 1)): "%YAML 1.1"), which
            # OpenCV's parser refused ("line 4: Incorrect indentation"). OpenCV writes
            # "%YAML:1.0" (4.x) or "%YAML 1.2" (5.x) with its matrices tagged: those go to its
            # parser alone (PyYAML refuses the tags: 8 of save()'s 10 ms load were that try)
            calib = cls._from_plain_yaml(text, str(p), unit)
            if calib is not None:
                return calib
        if head.startswith("%YAML") or head.startswith("<?xml") or head.startswith("<opencv"):
            return cls._from_filestorage_text(text, str(p), unit)
        if head.startswith("{"):
            try:
                json.loads(text)
            except json.JSONDecodeError:
                # YAML's flow mapping (yaml.safe_dump(..., default_flow_style=True), a line
                # "{image_width: 640, ...}"), keys unquoted, was "cannot parse ... as JSON"
                calib = cls._from_plain_yaml(text, str(p), unit)
                if calib is not None:
                    return calib
                if all(r.search(text) for r in _ROS_MESSAGE):
                    # a ROS 2 echo in flow style (ros2 topic echo --flow-style, "{header: ...,
                    # width: 640, ...}") was "cannot parse ... as JSON: Expecting property name"
                    raise ValueError(_one_ros_camera_info(str(p))) from None
            return cls._from_json_text(text, str(p), unit)
        calib = cls._from_plain_yaml(text, str(p), unit)
        if calib is not None:
            return calib
        if all(r.search(text) for r in _ROS_MESSAGE):
            # a ROS 2 echo (k, d, r, p: none of the fields) was "not a stereovision calibration
            # file", where ROS 1's (its R a field) is named
            raise ValueError(_one_ros_camera_info(str(p)))
        raise ValueError(f"not a stereovision calibration file (OpenCV YAML/XML or JSON): {p}")

    @classmethod
    def _from_plain_yaml(cls, text: str, source: str, unit: str | None) -> Calibration | None:
        """A YAML mapping of :meth:`save`'s fields without OpenCV's ``!!opencv-matrix`` tags
        (nor its ``%YAML:1.0`` / ``%YAML 1.2`` header): a script's ``yaml.safe_dump`` of nested
        lists, a hand-written file, read as its JSON twin is; None when the text is no such
        mapping. It was 'unrecognised calibration format ... expected OpenCV YAML/XML, JSON,
        ...'."""
        if not _PLAIN_YAML_KEY.search(text):
            # no field as a key: not parsed (PyYAML's pure-Python parser took 5.5 s on a 2.7 MB
            # point list given as --calib by mistake, which this comes to unrecognised)
            return None
        import yaml

        try:
            # the first document: a file ending in "---" (a second, empty one) was "expected a
            # single document" to yaml.load, so "not a stereovision calibration file"
            docs = yaml.load_all(text, Loader=_yaml_loader())  # a SafeLoader
            doc = next((d for d in docs if d is not None), None)
        except (yaml.YAMLError, ValueError, RecursionError, LookupError, AttributeError):
            if "!!python/" in text:  # a field is a key: _PLAIN_YAML_KEY, in flow style too
                # yaml.dump of the NumPy arrays, the first way a script writes them: it was
                # "unrecognised calibration format" (safe_load constructs no Python object);
                # in flow style ("{D1: !!python/...}") "cannot parse ... as JSON"
                raise ValueError(
                    f"calibration file {source} holds Python objects (yaml.dump's !!python/ "
                    "tags: NumPy arrays), which are not loaded: write the arrays as lists "
                    "(yaml.safe_dump({'K1': K1.tolist(), ...})), or use Calibration.save"
                ) from None
            # not YAML: any file unrecognised so far comes here, and PyYAML raises more than
            # YAMLError ("d: 2024-13-01" -> "month must be in 1..12", a deep nesting of "[";
            # an explicit tag's bad value: "!!bool x" KeyError, "!!float ''" IndexError,
            # "!!timestamp x" AttributeError)
            return None
        if isinstance(doc, dict) and _REPORT_FIELDS <= set(doc):
            raise ValueError(_not_a_calibration_keys(list(doc), source))
        if not isinstance(doc, dict) or not any(k in doc for k in _CALIBRATION_FIELDS):
            return None
        for key, value in doc.items():
            if _holds_itself(value):
                # "K1: &a [*a, *a]": NumPy's cast of the list that holds itself looked 32
                # levels deep, 2**32 entries: from_file / load hung
                raise ValueError(
                    f"calibration file {source}: {key} holds itself (a YAML alias inside its "
                    f"own anchor, '{key}: &a [*a]'): write its numbers out"
                )
        ros = "camera_matrix" in doc or "distortion_model" in doc  # a file, a message echo
        if ros and not any(k in doc for k in ("K1", "M1", "K2", "M2")):
            # a ROS camera_info (load(left.yaml)): its image_width made it "lacks field 'K1'"
            # (a message's R: "lacks field 'image_width': ... cv2.stereoCalibrate's ...")
            raise ValueError(_one_ros_camera_info(source))
        return cls._from_mapping(doc.get, source, unit)

    @classmethod
    def from_file(
        cls,
        path: PathLike,
        image_size: tuple[int, int] | None = None,
        unit: str | None = None,
    ) -> Calibration:
        """Read any supported calibration, detecting the format from the content.

        OpenCV YAML/XML, JSON and a plain YAML of the same fields (:meth:`load`), Middlebury
        ``calib.txt`` (:meth:`from_middlebury`), KITTI ``calib_cam_to_cam`` / object calibration
        (:meth:`from_kitti`; ``image_size`` is passed on), and ROS ``camera_info``
        (:meth:`from_ros`): a folder holding ``left.yaml`` and ``right.yaml``, ROS
        ``camera_calibration``'s ``calibrationdata.tar.gz``, or one of the two files when the
        other lies beside it (``left`` and ``right`` swapped in its name), each file as
        ``camera_calibration`` writes it or a ``sensor_msgs/CameraInfo`` message as
        ``ros2 topic echo`` / ``rostopic echo`` prints it, and Kalibr's
        ``camchain.yaml`` (:meth:`from_kalibr`, ``cam0`` and ``cam1``). A scene folder
        (:func:`stereovision.io.load_scene`) gives its ``calib.txt``, else its ``Q.dat``
        (:meth:`from_q`, sized by ``image_size`` or the folder's ``left.png``); so does a
        ``Q.dat`` file itself (16 numbers, sized by ``image_size`` or the ``left.png`` beside
        it). OpenCV's ``stereo_calib`` sample output (:meth:`from_opencv_stereo_calib`): a
        folder holding ``intrinsics.yml`` and ``extrinsics.yml`` (and none of the folder
        calibrations above), or one of the two with the other beside it; those files hold
        neither the image size nor the unit of ``T``, so ``image_size`` and ``unit`` must be
        given.

        Parameters
        ----------
        path : str or os.PathLike
            The calibration file or folder.
        image_size : tuple of int, optional
            ``(width, height)`` in pixels, for the formats that do not hold it (KITTI, Q.dat,
            OpenCV's ``stereo_calib`` output); for the others a check: a file of another size
            is refused (:meth:`scaled_to` resizes a calibration), not silently kept.
        unit : str, optional
            Length unit of ``T`` (``"m"``, ``"mm"``, ...) for the files that do not state it:
            OpenCV's ``stereo_calib`` output (the unit of the board's square size; needed), an
            OpenCV YAML/XML or JSON file without a ``unit`` field (a script's
            ``cv::FileStorage``; needed) and ``Q.dat`` (default ``"m"``, :meth:`from_q`). For
            the others a check: a file that states another unit is refused, not silently kept.

        Returns
        -------
        Calibration
            The calibration the file holds.

        Raises
        ------
        FileNotFoundError
            If ``path`` does not exist.
        ValueError
            If the format is not recognised or the content is invalid, if ``image_size`` or
            ``unit`` is missing where the format needs it, if ``unit`` is not a known unit, or
            if ``image_size`` or ``unit`` is given and the file states another.
        TypeError
            If ``path`` is bytes: the library's paths are str or os.PathLike, as io's are.
        """
        # pathlib's own TypeError for a bytes name named no argument; '' (an unset variable)
        # was read as the current folder: "calibration path . is a folder without ..."
        as_path(path, file=True)
        if unit is not None:
            unit = known_unit(unit, UNIT_TO_METRES)
        calib = cls._read_any(path, image_size, unit)
        if unit is not None and calib.unit != unit:
            # a unit the file states (calib.txt's mm, KITTI's and ROS's m, a saved file's own)
            # wins over a given one that disagrees: said, not kept silently or converted
            raise ValueError(
                f"{path} states its lengths in {calib.unit!r}, not in the unit {unit!r} given: "
                "leave unit out (it is for files that do not state theirs: OpenCV stereo_calib "
                "output, an OpenCV YAML/XML or JSON file without a unit field, Q.dat)"
            )
        # the checked size in the message: an array's tuple() read "(np.int64(1280), ...)"
        given = None if image_size is None else cls._check_size(image_size)
        if given is not None and calib.image_size != given:
            w, h = calib.image_size
            raise ValueError(
                f"{path} is a calibration of {w}x{h} images, not of the image_size "
                f"{given} given: {_resize_advice(calib.image_size, given)}"
            )
        return calib

    @classmethod
    def _read_any(
        cls, path: PathLike, image_size: tuple[int, int] | None, unit: str | None
    ) -> Calibration:
        p = Path(path)
        opencv_pair = _stereo_calib_files(p)
        if opencv_pair is not None:
            if image_size is None or unit is None:
                missing = " and ".join(
                    f"{name}=" + ("(width, height)" if name == "image_size" else "'m'/'mm'/...")
                    for name, v in (("image_size", image_size), ("unit", unit))
                    if v is None
                )
                raise ValueError(
                    f"{p} is OpenCV stereo_calib output ({opencv_pair[0].name} + "
                    f"{opencv_pair[1].name}), which holds neither the image size nor the unit "
                    f"of T (the board's square size): pass {missing}"
                )
            return cls.from_opencv_stereo_calib(*opencv_pair, image_size=image_size, unit=unit)
        if p.is_dir():
            pair = _ros_pair_from_folder(p)
            if pair is not None:
                return cls.from_ros(*pair)
            if (p / "calib.txt").is_file():
                return cls.from_file(p / "calib.txt", image_size=image_size)
            if (p / "Q.dat").is_file():
                q = p / "Q.dat"
                return cls.from_q(
                    q,
                    _scene_image_size(q) if image_size is None else image_size,
                    unit=unit or "m",
                )
            # a FIFO, a device or a link to nothing under one of those names: it is there, but
            # not a file ("a folder without ... Q.dat" sent the user looking for a file they
            # could see); said as the file given alone is, nothing opened
            for name in ("left.yaml", "right.yaml", "left.yml", "right.yml", "calib.txt", "Q.dat"):
                if ((p / name).exists() or (p / name).is_symlink()) and not (p / name).is_file():
                    cls._read_text(p / name)
            # stereo_calib's output is read from a folder too (README, --calib): one of its two
            # files alone (a copy cut short) was told only of the other formats
            for ext in _OPENCV_EXTS:
                for name in ("intrinsics", "extrinsics"):
                    half = _stereo_calib_half(p / f"{name}{ext}")
                    if half is not None:
                        raise ValueError(f"calibration path {p} holds {half}")
            # a ROS folder's left.yaml alone was "a folder without left.yaml and right.yaml"
            for ext in (".yaml", ".yml"):
                has = [(p / f"{side}{ext}").is_file() for side in ("left", "right")]
                if has[0] != has[1]:
                    there, absent = ("left", "right")[:: 1 if has[0] else -1]
                    raise ValueError(
                        f"calibration path {p} holds {there}{ext} but not {absent}{ext} (ROS "
                        "camera_info: a rig needs both cameras' files)"
                    )
            raise ValueError(
                f"calibration path {p} is a folder without left.yaml and right.yaml "
                "(ROS camera_info), intrinsics.yml and extrinsics.yml (OpenCV stereo_calib "
                "output), calib.txt or Q.dat; pass a calibration file"
            )
        if p.is_file() and p.name.lower().endswith((".tar.gz", ".tgz", ".tar")):
            ltext, rtext = _read_ros_tar(p)
            return cls._from_ros_texts(ltext, rtext, f"{p}:left.yaml", f"{p}:right.yaml")
        p, text = cls._read_text(path)
        if re.search(r"^cam\d+\s*:", text, re.MULTILINE) and "intrinsics" in text:
            return cls.from_kalibr(p)
        if (_ROS_HEAD.search(text) and "projection_matrix" in text) or all(
            r.search(text) for r in _ROS_MESSAGE
        ):
            pair = _ros_partner(p)
            if pair is None:
                raise ValueError(
                    f"{p} is one camera's ROS camera_info, and its name says neither left nor "
                    "right: a rig needs both cameras' files; pass the folder holding left.yaml "
                    "and right.yaml"
                )
            other = pair[1] if pair[0] == p else pair[0]
            if not other.is_file():
                raise ValueError(
                    f"{p} is one camera's ROS camera_info and its partner {other} is not "
                    "beside it; pass the folder holding left.yaml and right.yaml"
                )
            return cls.from_ros(*pair)
        head = text.lstrip()
        if head.startswith(("%YAML", "<?xml", "<opencv", "{")):
            try:
                return cls._load(p, unit)  # unit: for a file without its own (a script's)
            except ValueError as exc:
                # stereo_calib's intrinsics.yml alone was "lacks field 'image_width'", sending
                # the user to edit a file whose partner (R, T) is what is missing
                half = _stereo_calib_half(p)
                if half is None or "lacks field" not in str(exc):
                    raise
                raise ValueError(f"{p} is {half}") from None
        if re.search(r"^\s*cam0\s*=", text, re.MULTILINE):
            return cls.from_middlebury(p)
        if re.search(r"^\s*(P_rect_02|P2)\s*:", text, re.MULTILINE):
            return cls.from_kitti(p, image_size=image_size)
        if _q_numbers(text):  # a Q.dat: OpenCV's Q, sized like load_scene sizes it
            return cls.from_q(
                p, _scene_image_size(p) if image_size is None else image_size, unit=unit or "m"
            )
        plain = cls._from_plain_yaml(text, str(p), unit)  # a YAML without OpenCV's header
        if plain is not None:
            return plain
        if any(re.search(rf"^{k}\s*:", text, re.MULTILINE) for k in _MATLAB_FIELDS):
            raise ValueError(_matlab_export(str(p)))  # a YAML written without OpenCV's header
        raise ValueError(
            f"unrecognised calibration format in {p}: expected OpenCV YAML/XML, JSON, "
            "Middlebury calib.txt, KITTI calibration, ROS camera_info, Kalibr camchain or "
            "OpenCV's Q matrix (Q.dat)"
        )

    @classmethod
    def from_opencv_stereo_calib(
        cls,
        intrinsics: PathLike,
        extrinsics: PathLike,
        image_size: tuple[int, int],
        unit: str,
    ) -> Calibration:
        """Read OpenCV's ``stereo_calib`` sample output: ``intrinsics.yml`` and
        ``extrinsics.yml``.

        ``intrinsics`` holds ``M1``, ``D1``, ``M2``, ``D2``; ``extrinsics`` holds ``R`` and
        ``T`` (its ``R1``, ``R2``, ``P1``, ``P2`` and ``Q`` are recomputed, not read). Neither
        holds the image size nor the unit of ``T``, which is the unit of the board's square
        size given to the sample. ``D1``, ``D2`` and ``T`` may also be 1-D (the
        ``!!opencv-nd-matrix`` ``cv2.FileStorage`` writes for a 1-D NumPy array); their
        lengths are checked as the constructor's.

        Parameters
        ----------
        intrinsics, extrinsics : str or os.PathLike
            The two files (OpenCV YAML or XML).
        image_size : tuple of int
            ``(width, height)`` of the calibration images, in pixels.
        unit : str
            Length unit of ``T``: ``"m"``, ``"mm"``, ``"cm"``, ``"ft"`` or ``"in"``.

        Returns
        -------
        Calibration
            The unrectified rig.

        Raises
        ------
        FileNotFoundError
            If a file does not exist.
        ValueError
            If a file cannot be parsed, lacks a field (named), or holds invalid values.
        """
        # the two arguments checked first: a refusal of the files' numbers names the files
        size = cls._check_size(image_size)
        unit = known_unit(unit, UNIT_TO_METRES)
        fields: dict[str, Any] = {}
        files: list[Path] = []
        for path, keys in ((intrinsics, ("M1", "D1", "M2", "D2")), (extrinsics, ("R", "T"))):
            p, text = cls._read_text(path)
            files.append(p)
            fs = _open_filestorage(text, str(p))
            try:
                for key in keys:
                    node = fs.getNode(key)
                    if node.isNone():
                        raise ValueError(f"OpenCV stereo_calib file {p} lacks field {key!r}")
                    vector = key in _VECTOR_FIELDS
                    fields[key] = _node_matrix(node, key, str(p), vector=vector)
            finally:
                fs.release()
        return cls._made(
            f"OpenCV stereo_calib files {files[0]} and {files[1]}",
            K1=fields["M1"],
            D1=fields["D1"],
            K2=fields["M2"],
            D2=fields["D2"],
            R=fields["R"],
            T=fields["T"],
            image_size=size,
            unit=unit,
        )

    # ------------------------------------------------------------------ dataset formats

    @classmethod
    def ideal(cls, image_size: tuple[int, int], hfov_deg: float, baseline_m: float) -> Calibration:
        """A rig on paper: two identical pinhole cameras side by side, already rectified, of
        this image size, horizontal field of view and baseline (square pixels, principal points
        at the centres). To compare rig designs before buying cameras
        (``stereovision info --size 1280x720 --hfov 90 --baseline 0.12``).

        Parameters
        ----------
        image_size : tuple of int
            ``(width, height)`` in pixels.
        hfov_deg : float
            Horizontal field of view in degrees, in (0, 180).
        baseline_m : float
            Distance between the optical centres, metres.

        Returns
        -------
        Calibration
            A rectified calibration, unit ``"m"``.

        Raises
        ------
        ValueError
            For a size that is not two positive integers, a field of view outside (0, 180)
            degrees, or a baseline that is not a positive number of metres.
        """
        size = cls._check_size(image_size)
        numbers = (int, float, np.integer, np.floating)
        if isinstance(hfov_deg, bool) or not (isinstance(hfov_deg, numbers) and 0 < hfov_deg < 180):
            raise ValueError(
                f"hfov_deg: expected a field of view in (0, 180) degrees, got {hfov_deg!r}"
            )
        if isinstance(baseline_m, bool) or not (
            isinstance(baseline_m, numbers) and math.isfinite(baseline_m) and baseline_m > 0
        ):
            raise ValueError(
                f"baseline_m: expected a positive number of metres, got {baseline_m!r}"
            )
        if float(baseline_m) ** 2 < sys.float_info.min:
            # |T| squares it: below ~1.5e-154 m that underflows, and a 1e-300 m rig was refused
            # as the calibration's "T: zero baseline", naming no argument given
            raise ValueError(
                f"baseline_m: expected a positive number of metres, got {baseline_m!r} "
                "(too small to compute with)"
            )
        w, h = size
        f = w / (2 * math.tan(math.radians(hfov_deg) / 2))
        k = np.array([[f, 0, (w - 1) / 2], [0, f, (h - 1) / 2], [0, 0, 1.0]])
        return cls(
            K1=k,
            D1=np.zeros(5),
            K2=k.copy(),
            D2=np.zeros(5),
            R=np.eye(3),
            T=np.array([-float(baseline_m), 0.0, 0.0]),
            image_size=size,
            unit="m",
            rectified=True,
        )

    @classmethod
    @renamed_keyword("calib_txt", "path")
    def from_middlebury(cls, path: PathLike) -> Calibration:
        """Rectified calibration from a Middlebury ``calib.txt``.

        ``cam0``/``cam1`` give K1/K2, ``baseline`` (mm) gives ``T = (-baseline, 0, 0)``,
        ``doffs`` is kept, ``width``/``height`` give ``image_size``; unit ``"mm"``,
        ``R = I``, no distortion, ``rectified=True``.

        Parameters
        ----------
        path : str or os.PathLike
            The Middlebury ``calib.txt``.
            The keyword ``calib_txt=``, its former name, still works, with a DeprecationWarning.

        Returns
        -------
        Calibration
            The rectified calibration, unit ``"mm"``.

        Raises
        ------
        FileNotFoundError
            If the file does not exist.
        ValueError
            If a key is missing (named) or a value is invalid.
        """
        p, _ = cls._read_text(path)
        v = parse_middlebury_calib(p)
        for key in ("cam0", "cam1", "baseline", "width", "height"):
            if key not in v:
                raise ValueError(f"Middlebury calibration {p} lacks {key!r}")
        return cls._made(
            f"Middlebury calibration {p}",
            K1=v["cam0"],
            D1=np.zeros(5),
            K2=v["cam1"],
            D2=np.zeros(5),
            R=np.eye(3),
            T=np.array([-positive_finite(v["baseline"], f"baseline in {p}"), 0.0, 0.0]),
            image_size=(
                _pixels(v["width"], f"width in {p}"),
                _pixels(v["height"], f"height in {p}"),
            ),
            unit="mm",
            rectified=True,
            doffs=float(v["doffs"]) if "doffs" in v else None,
        )

    @classmethod
    @renamed_keyword("q_file", "path")
    def from_q(cls, path: PathLike, image_size: tuple[int, int], unit: str = "m") -> Calibration:
        """Rectified calibration from a ``Q.dat``: OpenCV's 4x4 disparity-to-depth matrix.

        The text file holds the 16 numbers of ``Q`` (``cv2.stereoRectify``'s output, as in
        the MiddEval3/TartanAir/KITTI samples of huyaoyu/Tutorial2020_Stereo)::

            1 0 0   -cx
            0 1 0   -cy
            0 0 0    f
            0 0 1/B  (cx' - cx)/B

        ``Q`` does not say the unit of ``B`` (it is the unit of the board's square size);
        ``unit`` says it, by default metres (the samples' convention: TartanAir's gives 0.25 m,
        its ``calib.txt`` 250 mm; KITTI's 0.533 m). The result has that unit, ``R = I``,
        ``T = (-B, 0, 0)``, equal focal lengths, ``doffs = cx' - cx``.

        ``Q`` acts on homogeneous coordinates, so any multiple of it is the same matrix: one
        scaled by ``Q[0,0]`` (ROS ``image_geometry``'s ``StereoCameraModel`` writes it times
        ``-f B``) is read as that matrix divided by ``Q[0,0]``.

        White space, commas or semicolons part the numbers (brackets are dropped), and a
        ``#`` starts a comment, to the end of its line (``np.savetxt``'s ``header``).

        Parameters
        ----------
        path : str or os.PathLike
            The ``Q.dat`` file.
            The keyword ``q_file=``, its former name, still works, with a DeprecationWarning.
        image_size : tuple of int
            ``(width, height)`` of the images it belongs to (``Q`` does not say).
        unit : str, optional
            Length unit of ``B``: ``"m"`` (default), ``"mm"``, ``"cm"``, ``"ft"`` or ``"in"``.

        Returns
        -------
        Calibration
            The rectified calibration, in ``unit``.

        Raises
        ------
        FileNotFoundError
            If the file does not exist.
        ValueError
            If it does not hold 16 finite numbers of that form (the offending entry named), or
            ``image_size`` is not two positive whole numbers.
        """
        p, text = cls._read_text(path)
        tokens = _q_tokens(text)
        try:
            q = np.array([float(t) for t in tokens], dtype=np.float64)
        except ValueError:
            # which entry is no number: the refusal said only "16 numbers expected"
            word = next(t for t in tokens if not _is_float(t))
            raise ValueError(
                f"{p}: not a Q matrix (16 numbers expected, got {reprlib.repr(word)})"
            ) from None
        if q.size != 16:
            raise ValueError(f"{p}: not a Q matrix (16 finite numbers expected, got {q.size})")
        if not np.isfinite(q).all():
            # 'got 16' alone read as if the file held what was expected
            i = int(np.flatnonzero(~np.isfinite(q))[0])
            raise ValueError(
                f"{p}: not a Q matrix (16 finite numbers expected, got Q[{i // 4},{i % 4}] = "
                f"{q[i]:g})"
            )
        q = q.reshape(4, 4)
        scaled = ""
        if q[0, 0] not in (0.0, 1.0):  # a multiple of Q is the same Q (homogeneous coordinates)
            scaled = f" (the matrix divided by its Q[0,0] = {q[0, 0]:g})"
            q = q / q[0, 0]
        expect = {(0, 0): 1.0, (1, 1): 1.0, (0, 1): 0.0, (0, 2): 0.0, (1, 0): 0.0}
        expect.update({(1, 2): 0.0, (2, 0): 0.0, (2, 1): 0.0, (2, 2): 0.0})
        expect.update({(3, 0): 0.0, (3, 1): 0.0})
        for (i, j), want in expect.items():
            if q[i, j] != want:
                # Q[0,0] gets here at 0 only (any other value divides the matrix to 1)
                also = " (or any value but 0: a multiple of Q is read as Q)" if i == j == 0 else ""
                raise ValueError(
                    f"{p}: not a rectified Q matrix: Q[{i},{j}] = {q[i, j]:g}, expected "
                    f"{want:g}{also}{scaled}"
                )
        f, inv_b = float(q[2, 3]), float(q[3, 2])
        if f <= 0 or inv_b <= 0:
            raise ValueError(
                f"{p}: Q[2,3] (focal length {f:g} px) and Q[3,2] (1/baseline {inv_b:g}) must be "
                f"positive: this Q does not give positive depths for positive disparities{scaled}"
            )
        cx, cy = -float(q[0, 3]), -float(q[1, 3])
        cx_right = cx + float(q[3, 3]) / inv_b
        bad = ValueError(f"image_size for {p}: expected (width, height), got {image_size!r}")
        if isinstance(image_size, (str, bytes, dict)):
            raise bad
        try:
            # any two numbers, as before: a tuple, an array, map(int, "640 480".split())
            size = tuple(image_size)
        except TypeError:  # None raised "'NoneType' object is not iterable", naming neither
            raise bad from None
        # (np.timedelta64(640), 480) was 640x480 (float() reads a unitless timedelta)
        if len(size) != 2 or any(isinstance(v, NOT_NUMBERS) for v in size):
            raise bad
        try:
            [float(v) for v in size]  # (640, None), ("a", 480): float()'s words, naming nothing
        except (TypeError, ValueError):
            raise bad from None
        w, h = (_pixels(v, f"image size for {p}") for v in size)
        return cls(
            K1=np.array([[f, 0.0, cx], [0.0, f, cy], [0.0, 0.0, 1.0]]),
            D1=np.zeros(5),
            K2=np.array([[f, 0.0, cx_right], [0.0, f, cy], [0.0, 0.0, 1.0]]),
            D2=np.zeros(5),
            R=np.eye(3),
            T=np.array([-1.0 / inv_b, 0.0, 0.0]),
            image_size=(w, h),
            unit=unit,
            rectified=True,
        )

    @classmethod
    @renamed_keyword("calib_file", "path")
    def from_kitti(
        cls,
        path: PathLike,
        image_size: tuple[int, int] | None = None,
        cameras: Sequence[int] | npt.NDArray[np.integer] = (2, 3),
    ) -> Calibration:
        """Rectified calibration of KITTI's colour pair (cameras 2 and 3), metres.

        Reads ``P_rect_02``/``P_rect_03`` (raw ``calib_cam_to_cam.txt``, also when each matrix
        spans several lines) or ``P2``/``P3`` (object/odometry format). ``K = P[:, :3]``,
        baseline ``B = (P2[0, 3] - P3[0, 3]) / f``, ``T = (-B, 0, 0)``, ``R = I``. The small
        vertical and depth offsets of the rectified colour cameras in ``P[1:, 3]`` (a few
        millimetres) are ignored. The grey pair (``image_0/`` + ``image_1/``) has a baseline of
        its own (0.537 against 0.532 m on odometry sequence 00): ``cameras=(0, 1)`` reads it.

        The image size comes from ``S_rect_02`` (``S_rect_00`` ...: the left camera's), else
        from ``image_size``, else from a ``left.png``/``left.jpg``/``image_2.png``
        (``image_0.png`` ...) next to the file.

        Parameters
        ----------
        path : str or os.PathLike
            KITTI's ``calib_cam_to_cam.txt`` or an object/odometry ``calib`` file.
            The keyword ``calib_file=``, its former name, still works, with a DeprecationWarning.
        image_size : tuple of int, optional
            ``(width, height)``, used when the file has no ``S_rect_02``; else a check: a
            file of another size is refused.
        cameras : sequence of int
            The left and right camera's numbers: ``(2, 3)`` the colour pair (default),
            ``(0, 1)`` the grey one (a tuple, list or 1-D integer array of two).

        Returns
        -------
        Calibration
            The rectified calibration of the two cameras, unit ``"m"``.

        Raises
        ------
        FileNotFoundError
            If the file does not exist.
        ValueError
            If the projection matrices or the image size are missing, ``image_size``
            contradicts ``S_rect_02``, or ``cameras`` is not two of 0-3.
        """
        # any sequence of two integers: a tuple, a list, a range, a NumPy array (a pair taken
        # from a table; np.array([0, 1]) was refused as not two of cameras 0-3)
        given: object = cameras
        if isinstance(given, np.ndarray):
            given = given.tolist() if given.ndim == 1 else None
        elif isinstance(given, Sequence) and not isinstance(given, (str, bytes)):
            given = [c.item() if isinstance(c, np.generic) else c for c in given]
        else:
            given = None
        ok = (
            isinstance(given, list)
            and len(given) == 2
            and all(isinstance(c, int) and not isinstance(c, bool) for c in given)
            and set(given) <= {0, 1, 2, 3}
            and given[0] != given[1]
        )
        if not ok:
            # by its values: "[0, 5]", "(0, 5)", not "array([0, 5])", "(np.int64(0), ...)"
            if isinstance(cameras, np.ndarray):
                shown = repr(cameras.tolist())
            elif isinstance(cameras, (tuple, list)) and isinstance(given, list):
                shown = repr(tuple(given) if isinstance(cameras, tuple) else given)
            else:
                shown = text_shown(cameras)
            raise ValueError(
                f"cameras: expected two of KITTI's cameras 0-3 ((2, 3) colour, (0, 1) grey), "
                f"got {shown}"
            )
        assert isinstance(given, list)
        a, b = given
        p, text = cls._read_text(path)
        v = parse_kitti_calib(p)
        for k2, k3 in ((f"P_rect_0{a}", f"P_rect_0{b}"), (f"P{a}", f"P{b}")):
            if k2 in v and k3 in v:
                break
        else:
            # a key whose values are not all numbers is skipped by the parser: a damaged
            # P_rect_03 (or one parted by commas) was "lacks P_rect_02/P_rect_03"
            _kitti_check_numbers(text, p, (f"P_rect_0{a}", f"P_rect_0{b}", f"P{a}", f"P{b}"))
            raise ValueError(f"KITTI calibration {p} lacks P_rect_0{a}/P_rect_0{b} (or P{a}/P{b})")
        mats = []
        for key in (k2, k3):
            if v[key].size != 12:
                raise ValueError(f"KITTI calibration {p}: {key} has {v[key].size} values, not 12")
            mats.append(v[key].reshape(3, 4))
        p2, p3 = mats
        f = float(p2[0, 0])
        if not f > 0:
            raise ValueError(f"KITTI calibration {p}: {k2} focal length {f:g} is not positive")
        baseline = (p2[0, 3] - p3[0, 3]) / f
        if baseline < 0:  # the left camera has the higher P[0, 3]: most likely a swapped pair
            raise ValueError(
                f"baseline ({k2}[0, 3] - {k3}[0, 3]) / f in {p}: expected a positive finite "
                f"number, got {float(baseline)!r} m; cameras={(a, b)} looks like the right "
                f"camera first: pass cameras=({b}, {a})"
            )
        size: tuple[int, int] | None = None
        given = None if image_size is None else cls._check_size(image_size)
        s_rect = f"S_rect_0{a}"
        _kitti_check_numbers(text, p, () if s_rect in v else (s_rect,))  # not a fallback size
        if s_rect in v:
            if v[s_rect].size != 2:
                raise ValueError(
                    f"KITTI calibration {p}: {s_rect} has {v[s_rect].size} values, not 2 "
                    "(width height)"
                )
            size = (
                _pixels(v[s_rect][0], f"{s_rect} width in {p}"),
                _pixels(v[s_rect][1], f"{s_rect} height in {p}"),
            )
            if given is not None and given != size:
                # as from_file refuses it: the file's own size was kept, the given one dropped
                raise ValueError(
                    f"{p} is a calibration of {size[0]}x{size[1]} images ({s_rect}), not of "
                    f"the image_size {given} given: {_resize_advice(size, given)}"
                )
        elif given is not None:
            size = given
        else:
            # left.jpg too, as a Q.dat is sized: a left.jpg + right.jpg scene was refused
            for name in ("left.png", "left.jpg", f"image_{a}.png"):
                img = p.parent / name
                if img.is_file():
                    from stereovision.io import _imdecode

                    # from its bytes: cv2.imread of a folder named with a byte that is not
                    # UTF-8 (os.fsdecode's lone surrogate) crashed the process (SIGSEGV)
                    try:
                        buf = np.fromfile(img, np.uint8)
                    except OSError:  # no permission: passed over, as cv2.imread's None was
                        continue
                    hdr = _imdecode(buf, cv2.IMREAD_UNCHANGED)
                    if hdr is not None:
                        size = (int(hdr.shape[1]), int(hdr.shape[0]))
                        break
        if size is None:
            raise ValueError(
                f"image_size: KITTI calibration {p} has no {s_rect} and no image next to it; "
                "pass image_size=(width, height)"
            )
        return cls._made(
            f"KITTI calibration {p}",
            K1=p2[:, :3],
            D1=np.zeros(5),
            K2=p3[:, :3],
            D2=np.zeros(5),
            R=np.eye(3),
            T=np.array(
                [-positive_finite(baseline, f"baseline ({k2}[0, 3] - {k3}[0, 3]) / f in {p}"), 0, 0]
            ),
            image_size=size,
            unit="m",
            rectified=True,
        )

    @classmethod
    def from_ros(cls, left: PathLike, right: PathLike) -> Calibration:
        """Calibration of a rig from its two ROS ``camera_info`` files (metres).

        ROS ``camera_calibration`` (stereo) writes ``left.yaml`` and ``right.yaml``: each camera's
        ``K`` and ``D``, its rectifying rotation ``R_i`` and its rectified projection ``P_i``
        (``P_i[:, 3] = K' t_i``, ``t_i`` in metres). The rig follows from them: with
        ``t_i = P_i[:, :3]^-1 P_i[:, 3]``, ``R = R_2^T R_1`` and ``T = R_2^T (t_2 - t_1)``.
        Rectification is recomputed from ``K``, ``D``, ``R`` and ``T`` (``cv2.stereoRectify``,
        like ROS); the files' own ``P`` matrices are not kept. A pair that is already rectified
        (no distortion, ``R_i = I``, ``K_i = P_i[:, :3]``) gives a ``rectified`` calibration.
        Rectifying rotations rounded to a few decimals are snapped to the nearest rotation.

        Parameters
        ----------
        left, right : str or os.PathLike
            The left and right camera's ``camera_info`` YAML files.

        Returns
        -------
        Calibration
            ``unit="m"``.

        Raises
        ------
        FileNotFoundError
            If a file does not exist.
        ValueError
            If a file is not a ``camera_info`` (field named), the image sizes differ, a model is
            unsupported, or the files hold no baseline (two monocular calibrations).
        """
        lp, ltext = cls._read_text(left, "left")
        rp, rtext = cls._read_text(right, "right")
        return cls._from_ros_texts(ltext, rtext, str(lp), str(rp))

    @classmethod
    def _from_ros_texts(cls, ltext: str, rtext: str, lsrc: str, rsrc: str) -> Calibration:
        cams = [parse_ros_camera_info(ltext, lsrc), parse_ros_camera_info(rtext, rsrc)]
        if cams[0]["image_size"] != cams[1]["image_size"]:
            raise ValueError(
                f"ROS camera_info: {lsrc} is {_size_shown(cams[0]['image_size'])} px, {rsrc} is "
                f"{_size_shown(cams[1]['image_size'])} px (width, height); a rig needs one size"
            )
        rots, ts = [], []
        for cam, src in zip(cams, (lsrc, rsrc), strict=True):
            rots.append(_snap_rotation(cam["R"], f"{src}: rectification_matrix"))
            p = cam["P"]
            if not (p[0, 0] > 0 and p[1, 1] > 0 and p[2, 2] > 0):
                raise ValueError(
                    f"{src}: projection_matrix needs positive fx, fy and P[2, 2], got {p.tolist()}"
                )
            ts.append(np.linalg.solve(p[:, :3], p[:, 3]))
        R = rots[1].T @ rots[0]
        T = rots[1].T @ (ts[1] - ts[0])
        if not float(np.linalg.norm(T)) > 0:
            raise ValueError(
                f"ROS camera_info {rsrc}: projection_matrix has no baseline (P[0, 3] = 0): these "
                "are two monocular calibrations; calibrate the cameras as a stereo pair"
            )
        size = cams[0]["image_size"]
        fisheye = [c["distortion_model"] == "equidistant" for c in cams]
        if fisheye[0] != fisheye[1]:
            raise ValueError(
                f"ROS camera_info: {lsrc} is {cams[0]['distortion_model']!r}, {rsrc} is "
                f"{cams[1]['distortion_model']!r}; a rig needs one lens model"
            )
        looks_rectified = not fisheye[0] and all(
            not np.any(c["D"])
            and np.abs(c["R"] - np.eye(3)).max() <= _ROS_IDENTITY_TOL
            and np.allclose(c["K"], c["P"][:, :3], rtol=RECTIFIED_REL_TOL, atol=0)
            for c in cams
        )
        if looks_rectified:
            try:
                return cls(
                    K1=cams[0]["K"],
                    D1=np.zeros(5),
                    K2=cams[1]["K"],
                    D2=np.zeros(5),
                    R=np.eye(3),
                    T=T,
                    image_size=size,
                    unit="m",
                    rectified=True,
                )
            except ValueError:
                pass  # e.g. a vertical rig: keep it as a raw rig that stereoRectify handles
        return cls._made(
            f"ROS camera_info {lsrc} and {rsrc}",
            K1=cams[0]["K"],
            D1=cams[0]["D"],
            K2=cams[1]["K"],
            D2=cams[1]["D"],
            R=R,
            T=T,
            image_size=size,
            unit="m",
            model="fisheye" if fisheye[0] else "pinhole",
        )

    @classmethod
    @renamed_keyword("camchain", "path")
    def from_kalibr(
        cls, path: PathLike, cameras: tuple[str, str] = ("cam0", "cam1")
    ) -> Calibration:
        """A rig from Kalibr's ``camchain.yaml`` (or ``camchain-imucam.yaml``), metres.

        Kalibr, the usual calibrator of camera-IMU rigs, gives each camera ``intrinsics``
        ``[fu, fv, pu, pv]``, ``distortion_coeffs`` (``radtan``: OpenCV's ``k1 k2 p1 p2``;
        ``equidistant``: ``cv2.fisheye``'s ``k1..k4``, read as ``model="fisheye"``),
        ``resolution`` and, from the second camera on, ``T_cn_cnm1``: the 4x4 transform from the
        previous camera's frame to its own, ``X_n = T X_{n-1}`` in metres. The rig's ``R``,
        ``T`` are that transform (chained when the two cameras are not neighbours).

        Parameters
        ----------
        path : str or os.PathLike
            The YAML file.
            The keyword ``camchain=``, its former name, still works, with a DeprecationWarning.
        cameras : tuple of str
            The left and right camera's keys (the left one earlier in the chain).

        Returns
        -------
        Calibration
            ``unit="m"``.

        Raises
        ------
        FileNotFoundError
            If the file does not exist.
        ValueError
            ``cameras`` not two camera keys (str), a camera missing or out of order (or one
            between the two missing), a camera model
            other than ``pinhole`` or a distortion other than ``radtan``/``equidistant``/``none``,
            the two cameras with different distortion models, a malformed field (named), or
            cameras of different resolutions.
        """
        import yaml

        if not (
            isinstance(cameras, (tuple, list))
            and len(cameras) == 2
            and all(isinstance(c, str) for c in cameras)
        ):
            # "cam0" or ("cam0",) was Python's "too many (not enough) values to unpack", None
            # a TypeError: neither named the argument
            raise ValueError(
                f"cameras: expected the left and right camera's keys, ('cam0', 'cam1'), got "
                f"{text_shown(cameras)}"
            )
        p, text = cls._read_text(path)
        try:
            # the first document, as the plain YAML and ROS readers take it (a712fb3d): a file
            # ending in "---" (a second, empty one) was "expected a single document"
            doc = next((d for d in yaml.safe_load_all(text) if d is not None), None)
        except (yaml.YAMLError, ValueError, RecursionError, LookupError, AttributeError) as exc:
            # not YAMLError alone: "2024-13-01" was a bare "month must be in 1..12", "!!bool x"
            # a KeyError (as _from_plain_yaml catches)
            raise ValueError(f"cannot parse {p} as Kalibr YAML: {_yaml_error(exc, text)}") from None
        if not isinstance(doc, dict):
            raise ValueError(f"{p}: expected Kalibr's camchain mapping (cam0, cam1, ...)")
        chain = sorted(
            (k for k in doc if isinstance(k, str) and re.fullmatch(r"cam\d+", k)),
            key=lambda k: int(k[3:]),
        )
        left, right = cameras
        for name in (left, right):
            if name not in chain:
                raise ValueError(f"{p}: no camera {name!r} (has {chain})")
        i, j = chain.index(left), chain.index(right)
        if j <= i:
            raise ValueError(f"{p}: {right!r} must come after {left!r} in the chain")
        numbers = [int(k[3:]) for k in chain[i : j + 1]]
        missing = sorted(set(range(numbers[0], numbers[-1] + 1)) - set(numbers))
        if missing:
            # each T_cn_cnm1 is from camera n-1: with cam1 cut out of a three-camera chain,
            # cam2's pose from cam1 was taken as its pose from cam0 (a silently wrong R, T)
            raise ValueError(
                f"{p}: no cam{missing[0]} between {left!r} and {right!r}; the T_cn_cnm1 of "
                f"{right!r} is its pose from cam{numbers[-1] - 1}: keep every camera between"
            )
        for name in (left, right):
            cam = doc[name]
            for key, value in cam.items() if isinstance(cam, dict) else [(name, cam)]:
                if _holds_itself(value):
                    # "T_cn_cnm1: &a [*a, *a]": NumPy's cast of the list holding itself hung,
                    # as the plain YAML reader's did (15f74bf2)
                    raise ValueError(
                        f"{p}:{name}: {key} holds itself (a YAML alias inside its own anchor, "
                        f"'{key}: &a [*a]'): write its numbers out"
                    )
        cams = [_kalibr_camera(doc[name], f"{p}:{name}") for name in (left, right)]
        if cams[0]["resolution"] != cams[1]["resolution"]:
            raise ValueError(
                f"{p}: {left} is {cams[0]['resolution']} px, {right} is "
                f"{cams[1]['resolution']} px; a rig needs one size"
            )
        transform = np.eye(4)
        for name in chain[i + 1 : j + 1]:
            transform = _kalibr_transform(doc[name], f"{p}:{name}") @ transform
        transform[:3, :3] = _snap_rotation(transform[:3, :3], f"{p}: T_cn_cnm1 of {right!r}")
        if cams[0]["fisheye"] != cams[1]["fisheye"]:
            raise ValueError(
                f"{p}: {left} and {right} use different distortion models; a rig needs one"
            )
        return cls._made(
            str(p),
            K1=cams[0]["K"],
            D1=cams[0]["D"],
            K2=cams[1]["K"],
            D2=cams[1]["D"],
            R=transform[:3, :3],
            T=transform[:3, 3],
            image_size=cams[0]["resolution"],
            unit="m",
            model="fisheye" if cams[0]["fisheye"] else "pinhole",
        )

    def to_ros(
        self, alpha: float = 0.0, names: tuple[str, str] = ("left", "right")
    ) -> tuple[str, str]:
        """The rig as two ROS ``camera_info`` YAML texts (left, right), in metres.

        What ROS ``camera_calibration`` would write and ``stereo_image_proc`` reads: each
        camera's ``K`` and ``D``, and ``cv2.stereoRectify``'s rotation ``R_i`` and projection
        ``P_i`` (``alpha`` as in :meth:`rectify`), with ``P_2[0, 3] = -f B`` and ``B`` in metres.
        A ``rectified`` calibration gives ``R_i = I`` and ``P_i = [K_i | K_i t_i]``.

        Parameters
        ----------
        alpha : float
            Free scaling of the rectification, in ``[0, 1]``.
        names : tuple of str
            The ``camera_name`` fields.

        Returns
        -------
        tuple of str
            ``(left_yaml, right_yaml)``.

        Raises
        ------
        ValueError
            If ``alpha`` is outside ``[0, 1]``, ``names`` is not two strings, or the distortion
            has 12 or 14 coefficients with the thin-prism or tilt terms in use (ROS has no
            model for them).
        """
        _check_alpha(alpha)
        if not (
            isinstance(names, (tuple, list))
            and len(names) == 2
            and all(isinstance(n, str) for n in names)
        ):
            raise ValueError(f"names: expected two camera names (str), got {names!r}")
        metres = self.to_metres_factor
        if self.rectified:
            r1 = r2 = np.eye(3)
            p1 = np.hstack([self.K1, np.zeros((3, 1))])
            p2 = np.hstack([self.K2, (self.K2 @ self.T * metres).reshape(3, 1)])
        else:
            r1, r2, p1, p2, _ = self._stereo_rectify(alpha)
            p1, p2 = p1.copy(), p2.copy()
            p1[:, 3] *= metres
            p2[:, 3] *= metres
        texts = []
        for name, K, D, r, p, field_ in (
            (names[0], self.K1, self.D1, r1, p1, "D1"),
            (names[1], self.K2, self.D2, r2, p2, "D2"),
        ):
            if D.size > 8:
                if np.any(D[8:]):
                    raise ValueError(
                        f"{field_}: ROS camera_info has no model for the thin-prism or tilt "
                        f"terms (coefficients 9-{D.size} are not zero)"
                    )
                D = D[:8]
            if self.model == "fisheye":
                model = "equidistant"
            else:
                if D.size == 4:
                    D = np.append(D, 0.0)
                model = "plumb_bob" if D.size == 5 else "rational_polynomial"
            texts.append(_ros_yaml(name, self.image_size, K, D, r, p, model))
        return texts[0], texts[1]

    def save_ros(
        self, directory: PathLike, alpha: float = 0.0, names: tuple[str, str] = ("left", "right")
    ) -> tuple[Path, Path]:
        """Write ``left.yaml`` and ``right.yaml`` (ROS ``camera_info``, see :meth:`to_ros`).

        Parameters
        ----------
        directory : str or os.PathLike
            Created if missing. The pair is written all or nothing
            (:func:`stereovision.io.write_together`): a failure at any step keeps the earlier
            pair.
        alpha : float
            Free scaling of the rectification, in ``[0, 1]``.
        names : tuple of str
            The ``camera_name`` fields.

        Returns
        -------
        tuple of pathlib.Path
            The two files written.

        Raises
        ------
        ValueError
            As :meth:`to_ros`, or if ``directory`` is an existing file.
        """
        from stereovision.io import write_together

        d = as_path(directory, "directory")  # bytes: pathlib's TypeError named no argument
        if d.exists() and not d.is_dir():
            raise ValueError(f"cannot write ROS camera_info into {d}: it is a file, not a folder")
        texts = self.to_ros(alpha, names)
        from stereovision.io import make_folder

        make_folder(d)
        paths = (d / "left.yaml", d / "right.yaml")
        # all or nothing: one by one, a failure at right.yaml left the new left camera beside
        # the earlier right one, a rig neither calibration is (and a failure at the second
        # replacement did, when both were written first)
        write_together([(p, t.encode("utf-8")) for p, t in zip(paths, texts, strict=True)])
        return paths


def _inner_rectangle(
    mx: np.ndarray, my: np.ndarray, size: tuple[int, int]
) -> tuple[int, int, int, int]:
    """A rectangle ``(x, y, w, h)`` of a rectification map whose pixels all come from inside the
    source image: the map's valid bounding box, shrunk on its worst side until all are valid."""
    w, h = size
    valid = (mx >= 0) & (mx <= w - 1) & (my >= 0) & (my <= h - 1)
    ys, xs = np.nonzero(valid)
    if ys.size == 0:
        return 0, 0, 0, 0
    x0, x1, y0, y1 = int(xs.min()), int(xs.max()), int(ys.min()), int(ys.max())
    while x0 <= x1 and y0 <= y1:
        sides = (
            int(np.count_nonzero(~valid[y0, x0 : x1 + 1])),
            int(np.count_nonzero(~valid[y1, x0 : x1 + 1])),
            int(np.count_nonzero(~valid[y0 : y1 + 1, x0])),
            int(np.count_nonzero(~valid[y0 : y1 + 1, x1])),
        )
        worst = int(np.argmax(sides))
        if sides[worst] == 0:
            return x0, y0, x1 - x0 + 1, y1 - y0 + 1
        if worst == 0:
            y0 += 1
        elif worst == 1:
            y1 -= 1
        elif worst == 2:
            x0 += 1
        else:
            x1 -= 1
    return 0, 0, 0, 0


def fit_to_frames(calib: Calibration, size: tuple[int, int]) -> tuple[Calibration, str | None]:
    """``calib`` for frames of ``size``: itself, or scaled when only the resolution differs.

    Parameters
    ----------
    calib : Calibration
        The rig's calibration.
    size : tuple of int
        ``(width, height)`` of the frames.

    Returns
    -------
    tuple
        ``(calibration, note)``: the note (None when nothing changed) says what was scaled,
        for a warning or a status line.

    Raises
    ------
    ValueError
        If ``size`` is not two positive integers, the aspect ratios differ by more than 1 %
        (a camera mode that crops: it needs its own calibration), or one side is kept (or one
        larger, one smaller): frames cropped or padded by a few rows, which scaling would
        stretch along one axis.
    """
    (w0, h0), (w, h) = calib.image_size, Calibration._check_size(size)
    if (w0, h0) == (w, h):
        return calib, None
    # refused, not cropped or padded here: where the rows were added or cut is unknown (the
    # principal point moves with a crop at the top), and a camera mode delivers the size
    # it was calibrated at; frames a row off (KITTI's 1242x376) have their own calibration
    crop = crop_or_pad_hint((w0, h0), (w, h))
    if crop is not None:
        raise ValueError(f"calibration is for {w0}x{h0} images, the frames are {w}x{h}: {crop}")
    if not same_aspect((w0, h0), (w, h)):
        raise ValueError(
            f"calibration is for {w0}x{h0} images, the frames are {w}x{h}: another aspect "
            "ratio (a camera mode that crops), which needs its own calibration"
        )
    note = (
        f"the calibration is for {w0}x{h0} and the frames are {w}x{h}: scaled to them (a "
        "camera mode that crops instead of scaling needs its own calibration)"
    )
    return calib.scaled_to((w, h)), note


_MB_LINE = re.compile(r"^\s*([A-Za-z_]\w*)\s*=\s*(.*?)\s*$")


def parse_middlebury_calib(path: PathLike) -> dict[str, Any]:
    """Parse a Middlebury ``calib.txt`` into a dict.

    ``cam0``/``cam1`` (``[f 0 cx; 0 f cy; 0 0 1]``, MATLAB's syntax: commas may part the
    numbers, a ``;`` may end the last row or the line) become ``(3, 3)`` float64 arrays; every
    other ``key=number`` line (``doffs``, ``baseline``, ``width``, ``height``, ``ndisp``,
    ``vmin``, ...) a float. A ``#`` starts a comment, to the end of its line.

    Parameters
    ----------
    path : path
        The ``calib.txt`` file.

    Returns
    -------
    dict
        Key -> ``(3, 3)`` array (``cam0``, ``cam1``) or float.

    Raises
    ------
    FileNotFoundError
        If the file does not exist (a link to nothing: its target named).
    ValueError
        If it is not a regular file (a folder, a FIFO), a line is not ``key=value``, a value
        does not parse, or a key is given twice.
    """
    # a FIFO or a folder was "not found", a file that is there, and a link whose target moved
    # said without the link: in imread's words (a FIFO is not opened: its read would block)
    from stereovision.io import _existing_file

    p = _existing_file(path, "Middlebury calibration")
    out: dict[str, Any] = {}
    first: dict[str, int] = {}  # the line each key was given on, for a second one
    # "-sig": a byte-order mark (Windows Notepad writes one) made line 1 "expected key=value,
    # got '\ufeffcam0=[...]'", though from_middlebury's own _read_text skips it
    for n, line in enumerate(p.read_text(encoding="utf-8-sig", errors="replace").splitlines(), 1):
        # a '# comment' line (or one after a value) was "expected key=value, got '# ...'": no
        # key or value of the format holds a '#', so the rest of the line is a note
        line = line.split("#", 1)[0]
        if not line.strip():
            continue
        m = _MB_LINE.match(line)
        if m is None:
            raise ValueError(f"{p}:{n}: expected key=value, got {line!r}")
        key, val = m.group(1), m.group(2)
        if key in first:
            # the last one was taken without a word: which baseline (or cam0) was meant?
            raise ValueError(
                f"{p}:{n}: {key} given again (first on line {first[key]}); keep one of them"
            )
        first[key] = n
        try:
            if val.startswith("["):
                # the format is MATLAB's matrix syntax, which also parts numbers by commas and
                # may end the last row with ';' ([f, 0, cx; 0, f, cy; 0, 0, 1;]): both were
                # NumPy's "setting an array element with a sequence ... inhomogeneous shape"
                # a MATLAB statement's ';' after the ']' (cam0=[...];) was "could not convert
                # string to float: '1]'"
                body = re.sub(r"\]\s*;$", "]", val)
                if not body.endswith("]"):
                    # a line cut short (or a ']' forgotten) was read as if it were complete
                    raise ValueError("no closing ']'")
                rows = [re.split(r"[\s,]+", r.strip()) for r in body.strip("[]").split(";")]
                rows = [[x for x in r if x] for r in rows]
                if len(rows) > 1 and not rows[-1]:
                    rows.pop()
                if len(rows) != 3 or any(len(r) != 3 for r in rows):
                    raise ValueError(
                        "expected 3 rows of 3 numbers, [f 0 cx; 0 f cy; 0 0 1], got rows of "
                        + ", ".join(str(len(r)) for r in rows)
                        + " numbers"
                    )
                out[key] = np.array(rows, dtype=np.float64)
            else:
                out[key] = float(val)
        except ValueError as exc:
            raise ValueError(f"{p}:{n}: cannot parse {key}={val!r} ({exc})") from None
    return out


_KITTI_KEY = re.compile(r"^([A-Za-z_][\w]*):$")


def parse_kitti_calib(path: PathLike) -> dict[str, F64]:
    """Parse a KITTI calibration file into ``{key: float64 values}``.

    Handles ``key: v1 v2 ...`` on one line and values continued over following lines; keys whose
    values are not all numbers (``calib_time``) are skipped, as is free text before the first key.

    Parameters
    ----------
    path : path
        The calibration file (``calib_cam_to_cam.txt`` or a per-frame ``calib.txt``).

    Returns
    -------
    dict
        Key (``P_rect_02``, ``R_02``, ...) -> 1-D float64 array of its values, row-major.

    Raises
    ------
    FileNotFoundError
        If the file does not exist (a link to nothing: its target named).
    ValueError
        If it is not a regular file (a folder, a FIFO).
    """
    # a FIFO or a folder was "not found", a file that is there, and a link whose target moved
    # said without the link: in imread's words (a FIFO is not opened: its read would block)
    from stereovision.io import _existing_file

    p = _existing_file(path, "KITTI calibration")
    # utf-8-sig: a file saved by a Windows editor (a BOM) lost its first key, odometry's P0:
    # from_kitti(cameras=(0, 1)) said it "lacks P0/P1", batch read its grey pairs as the colour
    text = p.read_text(encoding="utf-8-sig", errors="replace")
    out: dict[str, F64] = {}
    key: str | None = None
    values: list[str] = []

    def flush() -> None:
        if key is None:
            return
        try:
            out[key] = np.array([float(t) for t in values], dtype=np.float64)
        except ValueError:
            pass

    for tok in re.sub(r":", ": ", text).split():
        m = _KITTI_KEY.match(tok)
        if m is not None:
            flush()
            key, values = m.group(1), []
        elif key is not None:
            values.append(tok)
    flush()
    return out


def _kitti_check_numbers(text: str, path: Path, keys: tuple[str, ...]) -> None:
    """Refuse the first of ``keys`` given in a KITTI file with a value that is no number, which
    :func:`parse_kitti_calib` skips (as it skips ``calib_time``), naming the value."""
    tokens = re.sub(r":", ": ", text).split()
    for key in keys:
        for i, tok in enumerate(tokens):
            if tok != f"{key}:":
                continue
            for t in tokens[i + 1 :]:
                if _KITTI_KEY.match(t):
                    break
                if not _is_float(t):
                    raise ValueError(
                        f"KITTI calibration {path}: {key} holds {reprlib.repr(t)}, not a number "
                        "(its values are numbers parted by spaces)"
                    )


# --------------------------------------------------------------------------- ROS camera_info

#: ROS ``distortion_model`` names this package can use, with the coefficient counts they take.
ROS_DISTORTION_MODELS: dict[str, tuple[int, ...]] = {
    "plumb_bob": (4, 5),
    "rational_polynomial": (8,),
    "equidistant": (4,),
}
_ROS_FIELDS = (
    "camera_matrix",
    "distortion_coefficients",
    "rectification_matrix",
    "projection_matrix",
)
_ROS_MATRIX_SHAPES = {
    "camera_matrix": (3, 3),
    "rectification_matrix": (3, 3),
    "projection_matrix": (3, 4),
}
#: How far from identity a ROS ``rectification_matrix`` may be for the pair to count as rectified.
_ROS_IDENTITY_TOL = 1e-12
_ROS_HEAD = re.compile(r"^\s*camera_matrix\s*:", re.MULTILINE)
#: A ``sensor_msgs/CameraInfo`` message as a topic echo prints it (``P:`` in ROS 1): each key
#: at the start of a line, or after ``{`` or ``,`` (``ros2 topic echo --flow-style`` prints the
#: message on one line, ``{header: {...}, height: 480, width: 640, ...}``).
_ROS_MESSAGE = (
    re.compile(r"(?:^|[{,]\s*)distortion_model\s*:", re.M),
    re.compile(r"(?:^|[{,]\s*)[pP]\s*:", re.M),
    re.compile(r"(?:^|[{,]\s*)width\s*:", re.M),
)


def _ros_matrix(value: object, key: str, source: str, size: int | None) -> F64:
    # camera_calibration writes {rows, cols, data}; hand-written files often give a flat list.
    rows = cols = None
    if isinstance(value, dict):
        rows, cols, value = value.get("rows"), value.get("cols"), value.get("data")
    if not isinstance(value, list):
        raise ValueError(f"{source}: {key} has no list of numbers (data)")
    try:
        arr = np.array([float(v) for v in value], dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{source}: {key} holds a value that is not a number") from None
    except OverflowError:  # 10**400: a bare "int too large to convert to float", no file named
        raise ValueError(f"{source}: {key} holds {_too_large_entry(value)}") from None
    if rows is not None and cols is not None:
        # cols: 0 with no data is what ROS writes for a camera without distortion (1 x 0)
        counts = all(
            isinstance(n, int) and not isinstance(n, bool) and n >= 0 for n in (rows, cols)
        )
        if not counts or rows * cols != arr.size:
            raise ValueError(
                f"{source}: {key} says rows={rows!r}, cols={cols!r} but holds {arr.size} numbers"
            )
    if size is not None and arr.size != size:
        raise ValueError(f"{source}: {key} holds {arr.size} numbers, expected {size}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{source}: {key} holds NaN or infinity")
    return arr


def _snap_rotation(rot: F64, what: str) -> F64:
    """The rotation nearest ``rot`` (a file prints it with a few decimals), if within 1e-4."""
    if np.abs(rot @ rot.T - np.eye(3)).max() > 1e-4 or np.linalg.det(rot) < 0:
        raise ValueError(f"{what} does not hold a rotation: {rot.tolist()}")
    u, _, vt = np.linalg.svd(rot)
    out: F64 = u @ vt
    return out


def parse_ros_camera_info(text: str, source: str = "<text>") -> dict[str, Any]:
    """Parse one camera's ROS ``camera_info`` YAML (as written by ROS ``camera_calibration``).

    Accepts ``{rows, cols, data}`` matrices or flat lists, OpenCV's header (4.x's
    ``%YAML:1.0``, 5.x's ``%YAML 1.2``) and ``!!opencv-matrix`` tags, the old spellings
    ``distortion_coefficents`` and ``camera_model``, and a ``sensor_msgs/CameraInfo`` message
    as a topic echo prints it (``width``, ``height``, ``k d r p`` or ROS 1's ``K D R P``; the
    first of several; on one line with ``ros2 topic echo --flow-style``).

    Parameters
    ----------
    text : str
        The file's content.
    source : str
        Name used in error messages.

    Returns
    -------
    dict
        ``image_size`` (width, height), ``camera_name`` (str or None), ``distortion_model``,
        ``K`` (3x3), ``D`` (n,), ``R`` (3x3) and ``P`` (3x4) as float64 arrays.

    Raises
    ------
    ValueError
        If the YAML does not parse, a field is missing or malformed (named), the distortion
        model is not one of :data:`ROS_DISTORTION_MODELS` (``equidistant`` is the fisheye model),
        or a message is a binned or cropped camera's.
    """
    import yaml

    # OpenCV 4.x writes "%YAML:1.0", which PyYAML reads as a bad directive (5.x's "%YAML 1.2"
    # it reads), and both tag their matrices.
    clean = re.sub(r"^%YAML:1\.0[^\n]*\n", "", text.lstrip("\ufeff"))
    clean = re.sub(r"!!opencv-matrix\b", "", clean)
    try:
        # a topic echo ends its message with "---" (and may print several): the first one,
        # the rest left unparsed (an echo stopped by Ctrl-C cut its last message mid-array)
        doc = next((d for d in yaml.safe_load_all(clean) if d is not None), None)
    except (ValueError, RecursionError, LookupError, AttributeError) as exc:
        # PyYAML raises more than YAMLError ("2024-13-01": "month must be in 1..12", no file
        # named; "!!bool x": a bare KeyError), as _from_plain_yaml catches
        raise ValueError(f"cannot parse {source} as ROS camera_info YAML: {exc}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}: " if mark is not None else ""
        raise ValueError(
            f"cannot parse {source} as ROS camera_info YAML: {where}"
            f"{getattr(exc, 'problem', None) or exc}"
        ) from None
    if not isinstance(doc, dict):
        raise ValueError(f"{source}: expected a ROS camera_info mapping")
    if _is_camera_info_message(doc):
        doc = _message_as_file(doc, source)
    if "distortion_coefficients" not in doc and "distortion_coefficents" in doc:
        doc["distortion_coefficients"] = doc["distortion_coefficents"]
    for key in (*_ROS_FIELDS, "image_width", "image_height"):
        if key not in doc:
            raise ValueError(f"ROS camera_info {source} lacks field {key!r}")
    size = []
    for key in ("image_width", "image_height"):
        v = doc[key]
        # 640.0 (a tool dumping floats) is a whole number of pixels, as the native loader takes
        whole = isinstance(v, int) or (isinstance(v, float) and math.isfinite(v) and v == int(v))
        if isinstance(v, bool) or not whole or v <= 0:
            raise ValueError(f"{source}: {key} must be a positive integer, got {v!r}")
        size.append(int(v))
    model = doc.get("distortion_model", doc.get("camera_model", "plumb_bob"))
    if model not in ROS_DISTORTION_MODELS:
        raise ValueError(
            f"{source}: distortion_model {model!r}; expected one of {list(ROS_DISTORTION_MODELS)}"
        )
    out: dict[str, Any] = {
        "image_size": (size[0], size[1]),
        "camera_name": None if doc.get("camera_name") is None else str(doc["camera_name"]),
        "distortion_model": model,
    }
    for key, short in zip(_ROS_FIELDS, "KDRP", strict=True):
        shape = _ROS_MATRIX_SHAPES.get(key)
        arr = _ros_matrix(doc[key], key, source, None if shape is None else shape[0] * shape[1])
        out[short] = arr if shape is None else arr.reshape(shape)
    d = out["D"]
    if d.size == 0:  # ROS writes an empty list for a camera calibrated without distortion
        out["D"] = d = np.zeros(5)
    if d.size not in ROS_DISTORTION_MODELS[model]:
        raise ValueError(
            f"{source}: distortion_model {model!r} takes {ROS_DISTORTION_MODELS[model]} "
            f"coefficients, distortion_coefficients holds {d.size}"
        )
    if d.size == 4 and model != "equidistant":
        out["D"] = np.append(d, 0.0)
    return out


def _is_camera_info_message(doc: dict[Any, Any]) -> bool:
    """Whether ``doc`` is a ``sensor_msgs/CameraInfo`` message (``width``, ``k`` or ``K``, ...),
    not ``camera_calibration``'s file (``image_width``, ``camera_matrix``, ...)."""
    return "camera_matrix" not in doc and "width" in doc and ("k" in doc or "K" in doc)


def _message_as_file(doc: dict[Any, Any], source: str) -> dict[str, Any]:
    """A ``sensor_msgs/CameraInfo`` message as ``ros2 topic echo --once`` (``k d r p``) or
    ROS 1's ``rostopic echo -n 1`` (``K D R P``) prints it, in ``camera_calibration``'s fields.

    Raises
    ------
    ValueError
        A field missing (named), or a binned or cropped camera: its ``K`` and ``P`` are the
        full sensor's, not the image's (the bag reader scales a binned one, a file is refused).
    """
    out: dict[str, Any] = {
        "image_width": doc["width"],
        "image_height": doc.get("height"),
        "distortion_model": doc.get("distortion_model") or "plumb_bob",
    }
    for short, key in zip("KDRP", _ROS_FIELDS, strict=True):
        name = next((n for n in (short.lower(), short) if doc.get(n) is not None), None)
        if name is None:
            raise ValueError(
                f"ROS camera_info message {source} lacks field {short.lower()!r} ({short!r})"
            )
        out[key] = doc[name]
    try:
        blank = not np.any(np.asarray(out["camera_matrix"], dtype=np.float64))
    except (TypeError, ValueError):  # malformed: said by the checks that follow
        blank = False
    if blank:
        # a driver with no calibration publishes zeros (width and height too, often): this was
        # told "image_width must be a positive integer, got 0", a field the message lacks
        raise ValueError(
            f"{source}: k is all zeros: the camera_info of a camera not calibrated yet (its "
            "driver found no calibration); calibrate the rig (stereovision calibrate)"
        )
    for axis in ("binning_x", "binning_y"):
        if doc.get(axis) not in (None, 0, 1):
            raise ValueError(
                f"{source}: {axis} {doc[axis]!r}: a binned camera's camera_info describes the "
                "full sensor, not these images; calibrate at the binned size"
            )
    roi = doc.get("roi")
    if isinstance(roi, dict) and (roi.get("width") or roi.get("height")):
        if (roi.get("width"), roi.get("height")) != (doc["width"], doc.get("height")):
            raise ValueError(
                f"{source}: camera_info has a region of interest ({roi.get('width')}x"
                f"{roi.get('height')} at {roi.get('x_offset')},{roi.get('y_offset')}); "
                "cropped cameras are not supported"
            )
    return out


def _ros_yaml(name: str, size: tuple[int, int], K: F64, D: F64, R: F64, P: F64, model: str) -> str:
    def mat(key: str, a: F64) -> str:
        rows, cols = (1, a.size) if a.ndim == 1 else a.shape
        data = ", ".join(repr(float(v)) for v in a.ravel())
        return f"{key}:\n  rows: {rows}\n  cols: {cols}\n  data: [{data}]\n"

    return (
        f"image_width: {size[0]}\nimage_height: {size[1]}\ncamera_name: {json.dumps(name)}\n"
        + mat("camera_matrix", K)
        + f"distortion_model: {model}\n"
        + mat("distortion_coefficients", D)
        + mat("rectification_matrix", R)
        + mat("projection_matrix", P)
    )


def _size_shown(size: Any) -> str:
    """A file's image size for a message, ``(640, 480)``: an int past a float's range as its
    number of digits (10**400 printed its 401 digits)."""
    return f"({', '.join(too_large_for_float(v, why=False) or repr(v) for v in size)})"


def _holds_itself(obj: object) -> bool:
    """Whether a list or dict PyYAML built holds itself (a recursive alias), at any depth.

    A node is walked once (an alias used many times is no cycle): linear in the file."""
    done: set[int] = set()
    on_path: set[int] = set()
    stack: list[tuple[object, bool]] = [(obj, False)]
    while stack:
        node, leaving = stack.pop()
        if leaving:
            on_path.discard(id(node))
            done.add(id(node))
            continue
        if not isinstance(node, (list, dict)) or id(node) in done:
            continue
        if id(node) in on_path:
            return True
        on_path.add(id(node))
        stack.append((node, True))
        stack.extend((v, False) for v in (node.values() if isinstance(node, dict) else node))
    return False


def _yaml_error(exc: BaseException, text: str) -> str:
    """PyYAML's error (parsing ``text``) in one line: ``line L, column C: PROBLEM``, and where
    the construct it was in began. Its own text spans five lines (each mark's line quoted, a
    caret under it, ``in "<unicode string>"`` for the file), and the CLI shows a message's
    first line only: "while parsing a flow sequence", without the line or what was wrong."""
    mark = getattr(exc, "problem_mark", None)
    problem = getattr(exc, "problem", None)
    reason, at = getattr(exc, "reason", None), getattr(exc, "position", None)
    if isinstance(at, int) and reason:  # a ReaderError (a control character): at an offset
        line = text.count("\n", 0, at) + 1
        column = at - text.rfind("\n", 0, at)
        code = getattr(exc, "character", None)
        what = f"character #x{code:04x}: " if isinstance(code, int) else ""
        return f"line {line}, column {column}: {what}{reason}"
    if mark is None or not problem:
        return " ".join(str(exc).split())  # a ValueError, a KeyError: as given
    text = f"line {mark.line + 1}, column {mark.column + 1}: {problem}"
    context, start = getattr(exc, "context", None), getattr(exc, "context_mark", None)
    if context and start is not None:
        text += f" ({context} at line {start.line + 1}, column {start.column + 1})"
    return text


def _yaml_loader() -> Any:
    """PyYAML's ``SafeLoader`` that also reads ``1e-3`` and ``2.5e3`` as numbers (YAML 1.2,
    JSON and Python do; PyYAML's YAML 1.1 wants a '.' and a signed exponent): a plain YAML's
    ``doffs: 1e-3`` was "doffs must be a number, got '1e-3'"."""
    import yaml

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_implicit_resolver(
        "tag:yaml.org,2002:float",
        re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
        list("-+0123456789."),
    )
    return Loader


def _q_tokens(text: str) -> list[str]:
    """The entries of a ``Q.dat``'s text: parted by white space, commas (``np.savetxt(...,
    delimiter=',')``) or semicolons, brackets dropped (a pasted ``print(Q)`` or
    ``Q.tolist()``): those were "not a Q matrix (16 numbers expected)" without a reason. A
    ``#`` starts a comment, to the end of its line (``np.savetxt``'s ``header=``, which
    ``np.loadtxt`` skips, was "16 numbers expected, got '#'")."""
    text = re.sub(r"#[^\r\n]*", "", text)
    return [t for t in re.split(r"[\s,;\[\]]+", text) if t]


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _q_numbers(text: str) -> bool:
    """Whether a text is 16 numbers and nothing else (OpenCV's 4x4 ``Q`` as a ``Q.dat``)."""
    tokens = _q_tokens(text)
    return len(tokens) == 16 and all(_is_float(t) for t in tokens)


def _q_file(path: Path) -> Path | None:
    """The ``Q.dat`` :meth:`Calibration.from_file` reads for ``path`` (the file itself, or a
    folder's without a ROS pair or ``calib.txt``), else None."""
    if path.is_dir():
        if _ros_pair_from_folder(path) is not None or (path / "calib.txt").is_file():
            return None
        q = path / "Q.dat"
        return q if q.is_file() else None
    try:
        if not path.is_file() or path.stat().st_size > 4096:
            return None
        # utf-8-sig: a Q.dat saved by a Windows editor (a BOM) is read by from_file, but was not
        # told one here: depth's --calib refused it for an image size its images give
        if not _q_numbers(path.read_text(encoding="utf-8-sig")):
            return None
    except (OSError, UnicodeDecodeError):
        return None
    return path


def _unsized_q(path: PathLike) -> bool:
    """Whether :meth:`Calibration.from_file` reads ``path`` as a ``Q.dat`` (the file, or a
    folder's without ``calib.txt``) with no ``left.png`` beside it to size it."""
    q = _q_file(Path(path))
    return q is not None and not any((q.parent / n).is_file() for n in ("left.png", "left.jpg"))


def _sizing_images(path: PathLike) -> tuple[Path, ...]:
    """The images beside a calibration that :meth:`Calibration.from_file` reads for its image
    size when none is given: a ``Q.dat``'s ``left.png`` (else ``left.jpg``), the ``left.png``,
    ``left.jpg`` and ``image_2.png`` beside a KITTI file without ``S_rect_02`` (a folder: those
    of the file it reads); none for a calibration that holds its size."""
    p = Path(path)
    q = _q_file(p)
    if q is not None:
        return tuple(f for f in (q.parent / "left.png", q.parent / "left.jpg") if f.is_file())[:1]
    if p.is_dir():
        if _ros_pair_from_folder(p) is not None:
            return ()
        p = p / "calib.txt"
    if not _sizeless_kitti_text(p):
        return ()
    kitti = ("left.png", "left.jpg", "image_2.png")
    return tuple(p.parent / n for n in kitti if (p.parent / n).is_file())


def _scene_image_size(q_file: Path) -> tuple[int, int]:
    """``(width, height)`` of the left image beside a ``Q.dat`` (a scene folder's)."""
    folder = q_file.parent
    for name in ("left.png", "left.jpg"):
        if (folder / name).is_file():
            from stereovision.io import imread

            h, w = imread(folder / name).shape[:2]
            return w, h
    raise ValueError(
        f"{q_file} does not give the image size and there is no left.png beside it: "
        "pass image_size=(width, height)"
    )


_OPENCV_EXTS = (".yml", ".yaml", ".xml")


def _opencv_stereo_calib_pair(path: Path) -> tuple[Path, Path] | None:
    """OpenCV ``stereo_calib``'s ``(intrinsics, extrinsics)`` files: in the folder ``path``, or
    ``path`` itself (named ``intrinsics.*`` or ``extrinsics.*``) with its partner beside it."""
    if path.is_dir():
        for ext in _OPENCV_EXTS:
            pair = path / f"intrinsics{ext}", path / f"extrinsics{ext}"
            if pair[0].is_file() and pair[1].is_file():
                return pair
        return None
    stem, ext = path.stem.lower(), path.suffix.lower()
    if not path.is_file() or ext not in _OPENCV_EXTS or stem not in ("intrinsics", "extrinsics"):
        return None
    other = path.with_name(("extrinsics" if stem == "intrinsics" else "intrinsics") + path.suffix)
    if not other.is_file():
        return None
    return (path, other) if stem == "intrinsics" else (other, path)


def _stereo_calib_half(path: Path) -> str | None:
    """What to say of ``path`` when it is one of OpenCV ``stereo_calib``'s two files (by name)
    and its partner is not beside it; None otherwise."""
    stem, ext = path.stem.lower(), path.suffix.lower()
    if not path.is_file() or ext not in _OPENCV_EXTS or stem not in ("intrinsics", "extrinsics"):
        return None
    lack = ("extrinsics" if stem == "intrinsics" else "intrinsics") + path.suffix
    if path.with_name(lack).is_file():
        return None
    return (
        f"OpenCV stereo_calib's {path.name} without its {lack} beside it: the rig's "
        "calibration is the two files together (intrinsics M1 D1 M2 D2, extrinsics R T)"
    )


def _stereo_calib_files(path: Path) -> tuple[Path, Path] | None:
    """:func:`_opencv_stereo_calib_pair` as :meth:`Calibration.from_file` reads ``path``: a
    folder's own calibration (ROS pair, calib.txt, Q.dat) comes first (one that also holds
    stereo_calib's two files loaded before that format was read, and still does)."""
    folder_calib = path.is_dir() and (
        _ros_pair_from_folder(path) is not None
        or (path / "calib.txt").is_file()
        or (path / "Q.dat").is_file()
    )
    return None if folder_calib else _opencv_stereo_calib_pair(path)


def _sizeless_kitti_text(path: Path) -> bool:
    """Whether :meth:`Calibration.from_file` reads ``path`` as a KITTI calibration without
    ``S_rect_02`` (the object/odometry ``calib`` files), sized by an image beside it if any."""
    try:
        if not path.is_file() or path.stat().st_size > 65536:
            return False
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return False
    if text.lstrip().startswith(("%YAML", "<?xml", "<opencv", "{")) or re.search(
        r"^\s*cam0\s*=", text, re.MULTILINE
    ):
        return False  # read as another format before KITTI's (as _read_any orders them)
    return bool(re.search(r"^\s*(P_rect_02|P2)\s*:", text, re.MULTILINE)) and (
        "S_rect_02" not in text
    )


def _unsized_kitti(path: Path) -> bool:
    """Whether :meth:`Calibration.from_file` reads ``path`` as a KITTI calibration without
    ``S_rect_02`` (the object/odometry ``calib`` files) and no image beside it to size it."""
    if not _sizeless_kitti_text(path):
        return False
    return not any((path.parent / n).is_file() for n in ("left.png", "left.jpg", "image_2.png"))


def _sizeless(path: PathLike) -> bool:
    """Whether :meth:`Calibration.from_file` needs an ``image_size`` for ``path``: a ``Q.dat``
    with no ``left.png`` beside it, OpenCV ``stereo_calib`` output, or a KITTI calibration
    without ``S_rect_02`` and no image beside it (none of them holds one)."""
    p = Path(path)
    return _unsized_q(p) or _stereo_calib_files(p) is not None or _unsized_kitti(p)


def _ros_pair_from_folder(folder: Path) -> tuple[Path, Path] | None:
    for ext in (".yaml", ".yml"):
        left, right = folder / f"left{ext}", folder / f"right{ext}"
        if left.is_file() and right.is_file():
            return left, right
    return None


def _ros_partner(path: Path) -> tuple[Path, Path] | None:
    """``(left, right)`` with ``path`` one of them and the other named by swapping ``left``
    and ``right`` in its name (any case), whether or not it exists; None for a name with
    neither."""
    # "left.yaml" names "right.yaml" (and cam_left_x.yml names cam_right_x.yml), and back.
    name = path.name
    for a, b in (("left", "right"), ("Left", "Right"), ("LEFT", "RIGHT")):
        if a in name:
            return path, path.with_name(name.replace(a, b))
        if b in name:
            return path.with_name(name.replace(b, a)), path
    return None


def _ros_sibling(path: Path) -> tuple[Path, Path] | None:
    pair = _ros_partner(path)
    return pair if pair is not None and all(p.is_file() for p in pair) else None


def _read_ros_tar(path: Path) -> tuple[str, str]:
    import tarfile

    try:
        with tarfile.open(path) as tar:
            found: dict[str, str] = {}
            for member in tar.getmembers():
                base = Path(member.name).name
                if member.isfile() and base in ("left.yaml", "right.yaml") and base not in found:
                    fh = tar.extractfile(member)
                    if fh is not None:
                        found[base] = fh.read().decode("utf-8", errors="replace")
    except (tarfile.TarError, EOFError, OSError) as exc:
        raise ValueError(f"cannot read {path} as a tar archive: {exc}") from None
    missing = [n for n in ("left.yaml", "right.yaml") if n not in found]
    if missing:
        raise ValueError(
            f"{path} holds no {' and no '.join(missing)} (ROS camera_calibration's "
            "calibrationdata.tar.gz has both)"
        )
    return found["left.yaml"], found["right.yaml"]


# ------------------------------------------------------------------------------ Kalibr


def _kalibr_numbers(value: object, key: str, source: str, size: int) -> F64:
    try:
        arr = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"{source}: {key} is not a list of numbers") from None
    except OverflowError:  # 10**400: a bare "int too large to convert to float", no file named
        raise ValueError(
            f"{source}: {key} needs {size} finite numbers, got {_too_large_entry(value)}"
        ) from None
    if arr.size != size or not np.all(np.isfinite(arr)):
        raise ValueError(f"{source}: {key} needs {size} finite numbers, got {value!r}")
    return arr


def _kalibr_camera(cam: object, source: str) -> dict[str, Any]:
    if not isinstance(cam, dict):
        raise ValueError(f"{source}: expected a camera mapping")
    for key in ("intrinsics", "resolution"):
        if key not in cam:
            raise ValueError(f"{source} lacks field {key!r}")
    model = cam.get("camera_model", "pinhole")
    if model != "pinhole":
        raise ValueError(f"{source}: camera_model {model!r}; only 'pinhole' is supported")
    dist = cam.get("distortion_model", "radtan")
    if dist not in ("radtan", "none", "equidistant"):
        raise ValueError(
            f"{source}: distortion_model {dist!r}; expected 'radtan', 'equidistant' or 'none'"
        )
    fu, fv, pu, pv = _kalibr_numbers(cam["intrinsics"], "intrinsics", source, 4)
    d = np.zeros(4 if dist == "equidistant" else 5)
    if dist in ("radtan", "equidistant"):
        d[:4] = _kalibr_numbers(cam.get("distortion_coeffs"), "distortion_coeffs", source, 4)
    res = _kalibr_numbers(cam["resolution"], "resolution", source, 2)
    if not np.all(res == np.round(res)) or np.any(res <= 0):
        raise ValueError(f"{source}: resolution must be two positive integers, got {res}")
    return {
        "K": np.array([[fu, 0.0, pu], [0.0, fv, pv], [0.0, 0.0, 1.0]]),
        "D": d,
        "resolution": (int(res[0]), int(res[1])),
        "fisheye": dist == "equidistant",
    }


def _kalibr_transform(cam: object, source: str) -> F64:
    if not isinstance(cam, dict) or "T_cn_cnm1" not in cam:
        raise ValueError(f"{source} lacks field 'T_cn_cnm1' (its pose in the chain)")
    t = _kalibr_numbers(cam["T_cn_cnm1"], "T_cn_cnm1", source, 16).reshape(4, 4)
    if np.abs(t[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-9:
        raise ValueError(f"{source}: T_cn_cnm1's last row must be [0, 0, 0, 1], got {t[3]}")
    return t
