"""OpenCV reference matchers and the reference hole fill, exactly as evaluation.md defines them.

Every accuracy or speed figure of the project is reported beside these references:

* :func:`opencv_bm` -- ``cv2.StereoBM_create(D16, 15)`` on the grey pair;
* :func:`opencv_sgbm` -- ``cv2.StereoSGBM_create`` in ``SGBM_3WAY`` mode on the BGR pair with the
  configuration of evaluation.md "Speed";
* :func:`row_fill` -- the "filled reference" rule (a hole takes the smaller of the nearest valid
  disparities to its left and right in its row).

And, for ``benches/bench_tools.py``, the matchers robotics users run as their tools ship them:

* :func:`ros_stereo_image_proc` -- ROS 2 ``stereo_image_proc``'s disparity node (BM or SGBM) with
  the node's default parameters;
* :func:`stereovision_1_0` -- the ``StereoVision`` 1.0.4 package on PyPI (2017, Python 2 and
  OpenCV 2: it no longer imports with the OpenCV of today) with its ``StereoBM`` /
  ``StereoSGBM`` defaults, set through the current API (OpenCV 5.1 or later, as required).

Outputs follow the project's convention: ``float32`` disparity in pixels, ``d = x_left - x_right``
at left-image pixels, NaN for "no estimate" (OpenCV's 16x fixed point divided by 16, negative
values turned into NaN).
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    _warn_low_uint16,
    as_bgr_uint8,
    as_gray_uint8,
    as_image_array,
    pair_shape_error,
    renamed_keyword,
)

__all__ = [
    "BM_BLOCK_SIZE",
    "SGBM_BLOCK_SIZE",
    "bm_reference_range",
    "bm_reference_refusal",
    "bm_widest_range",
    "opencv_bm",
    "opencv_sgbm",
    "ros_stereo_image_proc",
    "round_up16",
    "row_fill",
    "stereovision_1_0",
]

#: OpenCV disparities are fixed point with 4 fractional bits.
_OPENCV_DISP_SCALE = 16.0
#: evaluation.md "Speed": ``cv2.StereoBM_create(D16, 15)``.
BM_BLOCK_SIZE = 15
#: evaluation.md "Speed": SGBM-3WAY block size; P1/P2 are ``8*3*5^2`` and ``32*3*5^2``.
SGBM_BLOCK_SIZE = 5
_SGBM_CHANNELS = 3
_SGBM_P1 = 8 * _SGBM_CHANNELS * SGBM_BLOCK_SIZE**2
_SGBM_P2 = 32 * _SGBM_CHANNELS * SGBM_BLOCK_SIZE**2
_SGBM_DISP12_MAX_DIFF = 1
_SGBM_UNIQUENESS = 10
_SGBM_SPECKLE_WINDOW = 100
_SGBM_SPECKLE_RANGE = 2


def round_up16(n: float) -> int:
    """Round a disparity range up to a positive multiple of 16 (OpenCV's requirement).

    Parameters
    ----------
    n : float
        Disparity range in pixels (finite, ``>= 0``).

    Returns
    -------
    int
        Smallest multiple of 16 that is ``>= n``, and at least 16.

    Raises
    ------
    ValueError
        If ``n`` is no real number (a bool, a string, None, a list), negative, NaN or
        infinite.

    Examples
    --------
    >>> round_up16(15.4), round_up16(16), round_up16(16.5), round_up16(0)
    (16, 16, 32, 16)
    """
    from stereovision._validate import number_shown, real_number

    # None or [64] was float()'s TypeError naming nothing, "64", True (1 px) and 3 ns were
    # taken, 10**400 an OverflowError
    if not real_number(n):
        raise ValueError(f"disparity range must be a number of pixels, finite and >= 0, got {n!r}")
    try:
        x = float(n)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x) or x < 0:
        raise ValueError(f"disparity range must be finite and >= 0, got {number_shown(n)}")
    return max(16, 16 * math.ceil(x / 16.0))


def bm_widest_range(width: int, block: int = BM_BLOCK_SIZE) -> int:
    """The widest disparity range :func:`opencv_bm` searches in an image ``width`` px wide: the
    largest multiple of 16 that leaves its :data:`BM_BLOCK_SIZE` px block inside the image
    (``range + BM_BLOCK_SIZE - 1 <= width``; 0 when none does). ``block``: that of another
    StereoBM (StereoVision 1.0's 21 px).

    Examples
    --------
    >>> bm_widest_range(450), bm_widest_range(30), bm_widest_range(29), bm_widest_range(450, 21)
    (432, 16, 0, 416)
    """
    return max(0, (int(width) - block + 1) // 16 * 16)


def _refuse_bm_range(num: int, shape: tuple[int, ...], block: int) -> None:
    """Refuse a StereoBM range ``num`` whose ``block`` px block has no room in the images.

    StereoBM computed such a range anyway: disparities past it and past the width (2041 px on
    a 450 px pair at 448 px), most pixels "valid", a run's density not the next's (cones at
    448 px: 49 %, 75 %, 62 %). Images no higher than the block were a cv2.error in OpenCV's
    words ("SADWindowSize ... not larger than image width or height").
    """
    height, width = shape[:2]
    if height <= block:
        raise ValueError(
            f"StereoBM's {block} px block needs images at least {block + 1} px high, got {height}"
        )
    widest = bm_widest_range(width, block)
    if num > widest:
        fits = f"; give a max_disparity of at most {widest}" if widest >= 16 else ""
        raise ValueError(
            f"StereoBM's {block} px block and a {num} px disparity range (a multiple "
            f"of 16) need images at least {num + block - 1} px wide, got {width}{fits}"
        )


def bm_reference_range(max_disparity: float, width: int) -> float:
    """``max_disparity`` for :func:`opencv_bm` as a reference beside another matcher (``eval``,
    ``bench``): as given, or :func:`bm_widest_range` where its block has no room for it (a
    scene narrower than its range + 14 px), so that the reference runs on its widest range
    rather than refusing the whole scene; as given when no range fits (under 30 px), for
    :func:`opencv_bm` to refuse.

    Examples
    --------
    >>> bm_reference_range(64, 450), bm_reference_range(64, 70), bm_reference_range(64, 20)
    (64, 48, 64)
    """
    widest = bm_widest_range(width)
    return widest if round_up16(max_disparity) > widest >= 16 else max_disparity


def bm_reference_refusal(max_disparity: float, shape: tuple[int, ...]) -> str | None:
    """Why :func:`opencv_bm` cannot run as a reference on images of ``shape`` at
    :func:`bm_reference_range`, or None: images no higher than its block, or under 30 px wide
    (no range fits). ``eval`` and ``bench`` then score the other matchers and leave StereoBM
    out, saying this, rather than fail the whole scene.

    Examples
    --------
    >>> bm_reference_refusal(64, (375, 450)) is None, bm_reference_refusal(64, (375, 70)) is None
    (True, True)
    >>> bm_reference_refusal(16, (12, 384))
    "StereoBM's 15 px block needs images at least 16 px high, got 12"
    """
    num = round_up16(bm_reference_range(max_disparity, shape[1]))
    try:
        _refuse_bm_range(num, shape, BM_BLOCK_SIZE)
    except ValueError as e:
        return str(e)
    return None


def _refuse_sgbm_range(num: int, width: int, block: int) -> None:
    """Refuse a MODE_SGBM range ``num`` that leaves less than half its ``block`` beside it.

    OpenCV refused it in its own words, a ``cv2.error`` naming neither the range nor the width
    ("'params.calcSADWindowSize().width/2' is 7").
    """
    need = num + block // 2 + 1
    if width < need:
        widest = (width - block // 2 - 1) // 16 * 16
        fits = f"; give a max_disparity of at most {widest}" if widest >= 16 else ""
        raise ValueError(
            f"StereoSGBM's {block} px block and a {num} px disparity range (a multiple of 16) "
            f"need images at least {need} px wide, got {width}{fits}"
        )


def _check_pair_shapes(left: np.ndarray, right: np.ndarray, colour: bool = False) -> None:
    """Refuse a pair of two sizes (:func:`pair_shape_error`, the API's words). ``colour``: the
    matcher reads the BGR pair (SGBM), so a one-channel image beside a colour one is refused
    too: grey replicated against colour matched other costs without a word (cones: bad-2
    31.4 % for 21.6 %); beside a grey file read in colour (three equal channels) it is the
    same pair. Two three-channel images are never judged by their content: a dark or
    saturated colour frame (a covered lens) has equal channels too. The grey matchers (BM)
    convert both, so to them it is the grey pair."""
    if left.shape[:2] != right.shape[:2]:
        raise pair_shape_error(left.shape, right.shape)
    if not colour:
        return
    one = _one_channel(left), _one_channel(right)
    if one[0] == one[1] or _equal_channels(right if one[0] else left):
        return
    raise pair_shape_error(left.shape, right.shape)


def _one_channel(img: np.ndarray) -> bool:
    return img.ndim == 2 or img.shape[2] == 1


def _equal_channels(img: np.ndarray) -> bool:
    """Whether a colour image holds grey levels only (a grey file read in colour)."""
    return bool(
        np.array_equal(img[..., 0], img[..., 1]) and np.array_equal(img[..., 0], img[..., 2])
    )


#: What the 8-bit copy of a 12-bit image in 16 bits does to OpenCV's matchers, in the low-values
#: warning: the package's own words ("the matchers read all its bits") are its matchers'.
_OPENCV_READS_8_BITS = "; OpenCV's matchers read its 8-bit copy, about {bits} bits of it"


def _opencv_8bit(img: np.ndarray, name: str, grey: bool) -> npt.NDArray[np.uint8]:
    """``img`` as OpenCV's matchers read it: grey or BGR ``uint8``, a ``uint16`` image whose
    values all lie below 4096 (12-bit data) warned about in those matchers' terms."""
    if img.dtype == np.uint16:
        _warn_low_uint16(img, name, _OPENCV_READS_8_BITS)
    return (as_gray_uint8 if grey else as_bgr_uint8)(img, name, warn=False)


def _from_opencv(raw: np.ndarray) -> npt.NDArray[np.float32]:
    disp = raw.astype(np.float32) / np.float32(_OPENCV_DISP_SCALE)
    disp[disp < 0] = np.nan
    return disp


def opencv_bm(left: object, right: object, max_disparity: float) -> npt.NDArray[np.float32]:
    """OpenCV block matching reference: ``cv2.StereoBM_create(D16, 15)`` on the grey pair.

    Parameters
    ----------
    left, right : array_like
        Rectified pair, grey ``(H, W)`` or BGR ``(H, W, 3)`` (``uint8``, ``uint16`` or float in
        ``[0, 1]``); colour is converted with ``cv2.cvtColor(BGR2GRAY)`` on 8-bit data.
    max_disparity : float
        Largest disparity searched, in pixels; rounded up to a multiple of 16 (``D16``).

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``float32`` disparity in pixels, NaN where BM reports none.

    Raises
    ------
    ValueError
        On invalid images, mismatched sizes or a negative/non-finite ``max_disparity``, images
        no higher than the block, or a range (rounded up to a multiple of 16) that leaves no
        room for the block in the image's width (:func:`bm_widest_range`).
    """
    la, ra = as_image_array(left, "left"), as_image_array(right, "right")
    _check_pair_shapes(la, ra)
    num = round_up16(max_disparity)
    _refuse_bm_range(num, la.shape, BM_BLOCK_SIZE)
    matcher = cv2.StereoBM.create(numDisparities=num, blockSize=BM_BLOCK_SIZE)
    raw = matcher.compute(_opencv_8bit(la, "left", True), _opencv_8bit(ra, "right", True))
    return _from_opencv(raw)


def opencv_sgbm(left: object, right: object, max_disparity: float) -> npt.NDArray[np.float32]:
    """OpenCV SGBM-3WAY reference with evaluation.md's configuration, on the BGR pair.

    ``minDisparity=0, numDisparities=D16, blockSize=5, P1=8*3*25, P2=32*3*25, disp12MaxDiff=1,
    uniquenessRatio=10, speckleWindowSize=100, speckleRange=2, mode=STEREO_SGBM_MODE_SGBM_3WAY``.

    Parameters
    ----------
    left, right : array_like
        Rectified pair, both BGR ``(H, W, 3)`` or both grey ``(H, W)`` (replicated to three
        channels); ``uint8``, ``uint16`` or float in ``[0, 1]``.
    max_disparity : float
        Largest disparity searched, in pixels; rounded up to a multiple of 16 (``D16``).

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``float32`` disparity in pixels, NaN where SGBM reports none.

    Raises
    ------
    ValueError
        On invalid images, mismatched sizes, a grey image beside a colour one (SGBM matches
        colour; beside a grey file read in colour, three equal channels, it is the grey pair), a
        negative/non-finite ``max_disparity``, or a range (rounded up to a multiple of 16) not
        narrower than the images.
    """
    la, ra = as_image_array(left, "left"), as_image_array(right, "right")
    _check_pair_shapes(la, ra, colour=True)
    num = round_up16(max_disparity)
    width = la.shape[1]
    if num >= width:
        # OpenCV's SGBM-3WAY killed the process at a width of num - 1 (a segmentation fault:
        # 63 px at 64) and failed in its own words at the other widths up to num ("Failed to
        # allocate 18446744073709548353 bytes"); num + 1 px is computed
        widest = (width - 1) // 16 * 16
        fits = f"; give a max_disparity of at most {widest}" if widest >= 16 else ""
        raise ValueError(
            f"SGBM-3WAY's {num} px disparity range (max_disparity rounded up to a multiple of "
            f"16) needs images at least {num + 1} px wide, got {width}{fits}"
        )
    matcher = cv2.StereoSGBM.create(
        minDisparity=0,
        numDisparities=num,
        blockSize=SGBM_BLOCK_SIZE,
        P1=_SGBM_P1,
        P2=_SGBM_P2,
        disp12MaxDiff=_SGBM_DISP12_MAX_DIFF,
        uniquenessRatio=_SGBM_UNIQUENESS,
        speckleWindowSize=_SGBM_SPECKLE_WINDOW,
        speckleRange=_SGBM_SPECKLE_RANGE,
        mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY,
    )
    raw = matcher.compute(_opencv_8bit(la, "left", False), _opencv_8bit(ra, "right", False))
    return _from_opencv(raw)


def _algorithm(algorithm: str) -> str:
    if algorithm not in ("bm", "sgbm"):
        raise ValueError(f"algorithm: expected 'bm' or 'sgbm', got {algorithm!r}")
    return algorithm


def ros_stereo_image_proc(
    left: object, right: object, max_disparity: float, algorithm: str = "bm"
) -> npt.NDArray[np.float32]:
    """ROS 2 ``stereo_image_proc``'s disparity node with its default parameters, on the grey
    pair (the node takes ``mono8`` rectified images).

    The defaults are those ``disparity_node.cpp`` declares (ros-perception/image_pipeline):
    ``stereo_algorithm`` 0 (BM), ``prefilter_size`` 9, ``prefilter_cap`` 31,
    ``correlation_window_size`` 15, ``min_disparity`` 0, ``uniqueness_ratio`` 15,
    ``speckle_size`` 100, ``speckle_range`` 4, and for SGBM ``P1`` 200, ``P2`` 400,
    ``disp12_max_diff`` 0, ``full_dp`` false (``MODE_SGBM``). The node declares the texture
    threshold as ``texture_ratio`` but reads ``texture_threshold``, so BM keeps OpenCV's 10.
    ``disparity_range`` (64 by default) is the one setting a user must fit to the rig: here it
    is ``max_disparity`` rounded up to a multiple of 16, as for every matcher of the benches.
    The node's disparity image also subtracts ``cx_left - cx_right``; this returns the matcher's
    disparity ``x_left - x_right`` in pixels, as the other references do.

    Parameters
    ----------
    left, right : array_like
        Rectified pair, grey or BGR (converted to grey), ``uint8``, ``uint16`` or float in
        ``[0, 1]``.
    max_disparity : float
        Largest disparity searched, in pixels (rounded up to a multiple of 16).
    algorithm : {"bm", "sgbm"}
        The node's ``stereo_algorithm`` 0 or 1.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``float32`` disparity in pixels, NaN where the matcher reports none.

    Raises
    ------
    ValueError
        On invalid images, mismatched sizes, a negative or non-finite ``max_disparity``, an
        unknown ``algorithm``, or a range that leaves the 15 px window no room in the images'
        width (BM: the whole window, as :func:`opencv_bm`, and images no higher than it; SGBM:
        half of it).
    """
    algo = _algorithm(algorithm)
    la, ra = as_image_array(left, "left"), as_image_array(right, "right")
    _check_pair_shapes(la, ra)
    num = round_up16(max_disparity)
    if algo == "bm":  # its window of 15 px, as opencv_bm's
        _refuse_bm_range(num, la.shape, 15)
    else:
        _refuse_sgbm_range(num, la.shape[1], 15)
    gl, gr = _opencv_8bit(la, "left", True), _opencv_8bit(ra, "right", True)
    matcher: cv2.StereoMatcher
    if algo == "bm":
        bm = cv2.StereoBM.create()
        bm.setPreFilterSize(9)
        bm.setPreFilterCap(31)
        matcher = bm
    else:
        sg = cv2.StereoSGBM.create(1, 1, 10)  # as stereo_processor.hpp creates it
        sg.setPreFilterCap(31)
        sg.setMode(cv2.STEREO_SGBM_MODE_SGBM)
        sg.setP1(200)
        sg.setP2(400)
        sg.setDisp12MaxDiff(0)
        matcher = sg
    matcher.setBlockSize(15)
    matcher.setMinDisparity(0)
    matcher.setNumDisparities(num)
    matcher.setSpeckleWindowSize(100)
    matcher.setSpeckleRange(4)
    if algo == "bm":
        bm.setUniquenessRatio(15)
    else:
        sg.setUniquenessRatio(15)
    return _from_opencv(matcher.compute(gl, gr))


def stereovision_1_0(
    left: object, right: object, max_disparity: float, algorithm: str = "bm"
) -> npt.NDArray[np.float32]:
    """The ``StereoVision`` 1.0.4 package on PyPI (erget/StereoVision, 2017) with the defaults
    of its ``blockmatchers.StereoBM`` / ``StereoSGBM`` classes.

    That package is Python 2 and OpenCV 2 code (``cv2.STEREO_BM_BASIC_PRESET``,
    ``cv2.StereoSGBM()``) and does not import with the OpenCV of today; this sets the same
    parameters through the current API (OpenCV 5.1 or later, as the package requires).
    BM: ``window_size`` 21 on the grey pair, the rest OpenCV's BM
    defaults (prefilter 9 / 31, texture 10, uniqueness 15, no speckle filter) -- what OpenCV 2's
    basic preset set. SGBM on the pair as given (BGR): ``sad_window_size`` 3, ``uniqueness`` 10,
    ``speckle_window_size`` 100, ``speckle_range`` 32, ``p1`` 216, ``p2`` 864,
    ``max_disparity`` (OpenCV's ``disp12MaxDiff``) 1, ``full_dp`` False. The search range is
    ``max_disparity`` rounded up to a multiple of 16 from 0 (the package's defaults, 80 for BM
    and 16..112 for SGBM, are what a user changes for the rig).

    Parameters
    ----------
    left, right : array_like
        Rectified pair, grey or BGR (both alike for SGBM), ``uint8``, ``uint16`` or float in
        ``[0, 1]``.
    max_disparity : float
        Largest disparity searched, in pixels (rounded up to a multiple of 16).
    algorithm : {"bm", "sgbm"}
        Which of the package's block matchers.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``float32`` disparity in pixels, NaN where the matcher reports none.

    Raises
    ------
    ValueError
        On invalid images, mismatched sizes (SGBM: a grey image beside a colour one, as
        :func:`opencv_sgbm`), a negative or non-finite ``max_disparity``, an unknown
        ``algorithm``, or a range that leaves the window no room in the images' width (BM: its
        21 px, as :func:`opencv_bm`, and images no higher than it; SGBM: half its 3 px).
    """
    algo = _algorithm(algorithm)
    la, ra = as_image_array(left, "left"), as_image_array(right, "right")
    _check_pair_shapes(la, ra, colour=algo == "sgbm")  # BM reads the grey pair
    num = round_up16(max_disparity)
    if algo == "bm":
        _refuse_bm_range(num, la.shape, 21)
        bm = cv2.StereoBM.create(numDisparities=num, blockSize=21)
        return _from_opencv(
            bm.compute(_opencv_8bit(la, "left", True), _opencv_8bit(ra, "right", True))
        )
    _refuse_sgbm_range(num, la.shape[1], 3)
    sg = cv2.StereoSGBM.create(
        minDisparity=0,
        numDisparities=num,
        blockSize=3,
        P1=216,
        P2=864,
        disp12MaxDiff=1,
        uniquenessRatio=10,
        speckleWindowSize=100,
        speckleRange=32,
        mode=cv2.STEREO_SGBM_MODE_SGBM,
    )
    return _from_opencv(
        sg.compute(_opencv_8bit(la, "left", False), _opencv_8bit(ra, "right", False))
    )


@renamed_keyword("disp", "disparity")
def row_fill(disparity: npt.ArrayLike) -> npt.NDArray[np.float32]:
    """The reference hole fill of evaluation.md (a Rust kernel; rows in parallel).

    Along each row, a hole (NaN) takes the smaller (background) of the nearest valid disparity
    to its left and the nearest valid disparity to its right; with a valid value on one side
    only it takes that one; a row with no valid value stays NaN.

    Parameters
    ----------
    disparity : array_like
        ``(H, W)`` disparity, NaN (or any non-finite value) = hole.
        The keyword ``disp=``, its former name, still works, with a DeprecationWarning.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``float32``, a new array; valid input values are unchanged.

    Raises
    ------
    ValueError
        If ``disparity`` is not a 2-D real array, or holds finite values beyond float32's
        range (the float32 map would read them as holes).

    Examples
    --------
    >>> row_fill(np.array([[np.nan, 3, np.nan, np.nan, 1, np.nan]]))
    array([[3., 3., 1., 1., 1., 1.]], dtype=float32)
    """
    d = np.asarray(disparity)
    if d.ndim != 2 or d.dtype.kind not in "iuf":
        raise ValueError(
            f"disparity: expected a real (H, W) array, got shape {d.shape} dtype {d.dtype}"
        )
    if d.size == 0:
        return d.astype(np.float32)
    from stereovision._validate import refuse_beyond_float32

    # the float32 cast made a finite 1e300 an inf, filled over as a hole
    refuse_beyond_float32(d, "disparity", "would be filled over as holes")
    from stereovision import _core

    # The Rust kernel (rust/core/src/fill.rs; NumPy reference tests/reference/row_fill_ref.py):
    # the fused map fills rows four times per frame, and this is 15-25 x the vectorised NumPy.
    return _core.row_fill(np.ascontiguousarray(d, dtype=np.float32))
