"""Stereo calibration from chessboard or ChArUco pairs, with a report people can check.

Pipeline (:func:`calibrate`):

1. **Corners.** A ChArUco board (``board=CharucoBoard(...)``, :mod:`stereovision.charuco`) gives
   each corner an id, so a pair whose board is cut by an image edge still counts: the corners seen
   by both cameras are used. For a chessboard, ``cv2.findChessboardCornersSB`` (the sector-based
   detector, robust to blur and glare) finds the board; if it fails, the classic
   ``cv2.findChessboardCorners`` is tried. Every corner is then refined by ``cv2.cornerSubPix``
   with a window sized to the board's square in that image (:data:`SUBPIX_WINDOW_FRACTION`): on
   OpenCV's sample pairs this lowers the per-camera RMS from 0.25 px (SB alone) and 0.41-0.46 px
   (classic + the usual fixed 11x11 window) to 0.18 px. The right corners are put in the same
   order as the left ones. A chessboard whose grid continues past the corners found (a pattern
   given smaller than the board: 8x6 for a 9x6 board) is refused, as a pattern error when most
   boards do.
2. **Each camera alone** (``cv2.calibrateCamera``), with a distortion model chosen by
   leave-one-view-out cross-validation (``distortion="auto"``, see :data:`DISTORTION_MODELS`).
   A pinhole fit poorer than :data:`FISHEYE_HINT_MIN_RMS_PX` is compared with ``cv2.fisheye``'s,
   and a warning says to use ``distortion="fisheye"`` when that fits far better (a wide-angle
   lens).
3. **Extrinsics** (``cv2.stereoCalibrate`` with ``CALIB_FIX_INTRINSIC``), then an optional joint
   refinement of all parameters (``CALIB_USE_INTRINSIC_GUESS``), kept only if it lowers the RMS.
4. **Outliers.** A pair whose reprojection error is above :data:`OUTLIER_FACTOR` x the median
   (and above :data:`OUTLIER_MIN_PX`) is reported; with ``drop_outliers=True`` it is dropped and
   the solve repeated. A final stereo RMS above :data:`MAX_STEREO_RMS_PX` and
   :data:`MISPAIRED_RMS_RATIO` x each camera's own RMS is refused as mis-paired images (a
   ValueError naming the worst pairs), and left and right file names numbered differently are
   warned about. Boards whose planes are all within :data:`MIN_TILT_SPREAD_DEG` of one another
   (the board never tilted: no focal length) are refused, within :data:`TILT_SPREAD_WARN_DEG`
   warned about.
5. **Checks** reported in :class:`CalibrationReport`: rectified epipolar error of all corners,
   the spread of the square sides between triangulated corners, image coverage. (The
   triangulation's scale comes from the given square size, through ``T``: their median is the
   given size by construction, +0.02 % on OpenCV's sample pairs for any size given, so a wrong
   square size cannot be detected from the images; measure the printed board.)

:meth:`CalibrationReport.write` writes ``report.html`` (self-contained: pictures are embedded PNG),
``report.yaml`` and ``report.json``.
"""

from __future__ import annotations

import argparse
import base64
import glob
import html
import json
import math
import os
import re
import sys
import warnings
from collections.abc import Callable, Sequence
from dataclasses import MISSING, dataclass, field, fields, replace
from pathlib import Path
from typing import Any, cast

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import as_path, escaped, whole_value

# at run time too, so that typing.get_type_hints resolves the public signatures
from stereovision.calibration import Calibration
from stereovision.charuco import CharucoBoard, _require_board
from stereovision.overview import cv2_text

__all__ = [
    "DISTORTION_MODELS",
    "OUTLIER_FACTOR",
    "OUTLIER_MIN_PX",
    "CalibrationReport",
    "add_cli",
    "board_object_points",
    "board_pose_params",
    "calibrate",
    "calibrate_from_bag",
    "calibrate_from_video",
    "find_corners",
    "parse_pattern",
    "render_chessboard",
]

PathLike = str | os.PathLike[str]
ImageInput = PathLike | npt.ArrayLike
F64 = npt.NDArray[np.float64]

# ------------------------------------------------------------------------------ named constants

#: Shortest image side the classic chessboard detector takes: below 15 px its adaptive threshold
#: failed an OpenCV assertion (``blockSize % 2 == 1 && blockSize > 1``: an "internal error" of
#: ``calibrate`` on a 1x1 px image); no board of 4x4 squares fits there anyway.
MIN_BOARD_IMAGE_SIDE = 15
#: Flag sets tried in turn with ``findChessboardCornersSB``. ``ACCURACY`` asks for its sub-pixel
#: mode; ``NORMALIZE_IMAGE`` equalises the histogram first, which finds all 26 boards of OpenCV's
#: sample set; ``EXHAUSTIVE`` is slower and only a fallback (alone it misses one sample board).
SB_FLAG_SETS: tuple[int, ...] = (
    cv2.CALIB_CB_ACCURACY | cv2.CALIB_CB_NORMALIZE_IMAGE,
    cv2.CALIB_CB_ACCURACY,
    cv2.CALIB_CB_ACCURACY | cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_EXHAUSTIVE,
)
#: Fewest inner corners of a chessboard each way: OpenCV's detectors refuse fewer (2x5 was an
#: "internal error" from cv2.error).
MIN_PATTERN_CORNERS = 3
#: Most inner corners of a chessboard each way: a 16384 px image side (the largest the CLI
#: takes) over 4 px squares. ``--pattern 99999x99999`` ended in "Unable to allocate 74.5 GiB".
MAX_PATTERN_CORNERS = 4096
#: Flags of the classic detector, the last resort.
CLASSIC_FLAGS = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
#: ``cornerSubPix`` half-window as a fraction of the smallest corner spacing in the image.
#: Measured on OpenCV's sample pairs (per-camera RMS, k1 k2 p1 p2): 0.20 -> 0.19/0.20 px,
#: 0.30 -> 0.18/0.19, 0.35 -> 0.18/0.18, 0.40 -> 0.28/0.35 (the window then reaches the board's
#: outer edge and pulls the outer corners), 0.50 -> 0.91/1.18. 0.30 keeps a margin below the cliff.
SUBPIX_WINDOW_FRACTION = 0.30
#: Bounds of that half-window (px): at least 2 so that the gradient has support, at most 15
#: (a 31x31 window) to stay local on large boards.
SUBPIX_HALF_WINDOW_MIN = 2
SUBPIX_HALF_WINDOW_MAX = 15
#: ``cornerSubPix`` stops after 100 iterations or a move below 1e-4 px (far below the noise).
SUBPIX_CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-4)
#: A detected board's outermost corners must be X-junctions (two dark squares on one diagonal,
#: two light on the other). When a board is cut by the image edge, ``findChessboardCornersSB``
#: can take the L-shaped outer corners of the border squares for a row or column of inner corners
#: and return the board shifted by one square (seen on 1 of 240 rendered views cut by the edge;
#: the stereo RMS went from 0.08 to 5.2 px). The four squares around a corner are sampled at this
#: fraction of the grid step along both diagonals ...
RING_SAMPLE_FRACTION = 0.35
#: ... and a corner is an X-junction when its diagonals differ by less than this fraction of the
#: contrast between them (an L-corner's ratio is about 2, an X's about 0; OpenCV's 26 sample
#: views: every outer corner passes). A side whose majority fails rejects the board.
X_JUNCTION_RATIO = 0.5
#: Levenberg-Marquardt stopping rule of the calibration solvers: the default (30 iterations,
#: eps 2e-16 relative) can stop before convergence on 13+ views; 200 iterations costs < 50 ms.
SOLVER_CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 200, 1e-12)

#: Distortion models (OpenCV coefficient order k1 k2 p1 p2 k3 [k4 k5 k6]) and their flags.
DISTORTION_MODELS: dict[str, int] = {
    "k1k2": cv2.CALIB_FIX_K3 | cv2.CALIB_ZERO_TANGENT_DIST,
    "k1k2p1p2": cv2.CALIB_FIX_K3,
    "k1k2p1p2k3": 0,
    "rational": cv2.CALIB_RATIONAL_MODEL,
}
#: ``cv2.fisheye`` calibration flags (``distortion="fisheye"``): extrinsics re-estimated at each
#: step (the solver's own advice for convergence), no skew.
FISHEYE_FLAGS = cv2.fisheye.CALIB_RECOMPUTE_EXTRINSIC | cv2.fisheye.CALIB_FIX_SKEW
#: A pinhole solution whose per-camera RMS exceeds this (px) is compared with ``cv2.fisheye``'s
#: fit of the same views ...
FISHEYE_HINT_MIN_RMS_PX = 0.4
#: ... and when the fisheye fit's RMS is lower by this factor in both cameras, a warning says to
#: calibrate with ``distortion="fisheye"``. A ~120 degree fisheye lens's rendered ChArUco views:
#: pinhole (auto) 0.65 / 0.74 px, rows of the true points 3.3 px off at the 95th percentile;
#: fisheye 0.18 / 0.19 px. OpenCV's sample pairs (a narrow lens): 0.18 / 0.19 px, not compared.
FISHEYE_HINT_GAIN = 2.0
#: Candidates of ``distortion="auto"``, simplest first. The rational model is not a candidate:
#: on OpenCV's sample pairs it fits the corners as well as k1 k2 p1 p2 but extrapolates wildly
#: outside them (5 of 13 boards no longer found after rectification).
AUTO_CANDIDATES: tuple[str, ...] = ("k1k2p1p2", "k1k2p1p2k3")
#: A richer model must lower the leave-one-view-out RMS by at least this fraction to be chosen.
MODEL_SELECTION_GAIN = 0.01
#: Below this many views the cross-validation is too noisy: "auto" means the first candidate.
MODEL_SELECTION_MIN_VIEWS = 6
#: Radial models are checked to stay monotonic out to this multiple of the image's largest
#: (distorted, normalised) radius: a non-monotonic model folds the image when rectifying.
MONOTONIC_RADIUS_MARGIN = 1.05

#: A pair is an outlier when its error exceeds this multiple of the median pair error ...
OUTLIER_FACTOR = 3.0
#: ... and this many pixels (errors below half a pixel are within ordinary corner noise).
OUTLIER_MIN_PX = 0.5
#: The fewest pairs a stereo calibration is attempted with (intrinsics need several views).
MIN_PAIRS = 3

#: The stages :func:`calibrate` reports to its ``progress`` callback: the board search in each
#: pair, then the leave-one-out fits that choose the distortion model; before them
#: :func:`calibrate_from_video` and :func:`calibrate_from_bag` report each frame pair read.
PROGRESS_BOARDS = "boards"
PROGRESS_MODELS = "distortion models"
PROGRESS_FRAMES = "frames"

#: Fewest ChArUco corners seen by both cameras for a pair to be used (see charuco.MIN_CORNERS).
CHARUCO_MIN_COMMON = 6
#: Outlier rejection rounds at most (each round re-solves once).
MAX_OUTLIER_ROUNDS = 3
#: A stereo solution is refused when its RMS exceeds this (px) ...
MAX_STEREO_RMS_PX = 3.0
#: ... and this multiple of each camera's own RMS. A correct rig's stereo RMS is close to the
#: single-camera ones (OpenCV's sample pairs: 0.20 px stereo, 0.18 / 0.19 px alone; the
#: ChArUco set: 0.08 / 0.07 / 0.09 px): each camera fits its own boards, so a stereo error far
#: above theirs means the pairs do not show one rig. One pair of those samples mis-paired (a
#: dropped frame shifting the pairing) gave 11.6 px; the pairing shifted from the fifth pair on,
#: 27.1 px; one pair swapped left for right, 30.8 px, with baselines of 0.25-1.7 m for 0.08 m.
MISPAIRED_RMS_RATIO = 3.0
#: Boards whose planes all lie within this angle (degrees) of one another are refused, and within
#: :data:`TILT_SPREAD_WARN_DEG` warned about: with the board held at one tilt (only moved or
#: brought nearer), the focal length cannot be told from the distance. Four copies of OpenCV's
#: sample pair 12, scaled by 0.9-1.05 (planes 3.8 degrees apart), gave 777 px for 533 and an
#: 83 mm baseline as 99 mm, in silence. Simulated sets of 10 views (0.15 px noise): the focal
#: length off by 17-24 % at 3-4 degrees apart, 3-7 % at 7-8, 0.4-1.2 % at 19-21; the sample
#: pairs' planes are 65 degrees apart.
MIN_TILT_SPREAD_DEG = 5.0
TILT_SPREAD_WARN_DEG = 15.0
#: Left and right corners closer than this (px) in every pair: the two image sets are one
#: (the solver then returned a 2e-11 m baseline and the rectification called the rig vertical).
IDENTICAL_CORNERS_PX = 0.01
#: Pairs named in the error of a refused solution (the worst first).
WORST_PAIRS_SHOWN = 3
#: The API's and the CLI's words for dropping the outliers (a message says the one its reader
#: can type).
DROP_OUTLIERS_API = "drop_outliers=True"
DROP_OUTLIERS_CLI = "--drop-outliers"

#: The coverage mask is computed at 1/4 resolution (the figure is a percentage).
COVERAGE_DOWNSCALE = 4
#: Pose parameters (x, y, size, skew) and the spans a "complete" set covers, as ROS's
#: camera_calibration does (x and y: board centre over the image; size: sqrt(board area /
#: image area); skew: how far the board's corner angle is from 90 degrees).
POSE_PARAM_NAMES: tuple[str, ...] = ("x", "y", "size", "skew")
POSE_PARAM_RANGES: tuple[float, ...] = (0.7, 0.7, 0.4, 0.5)

#: Width of the report's pictures (px).
FIGURE_WIDTH = 960

#: File suffixes read as videos by ``calibrate`` (a pair of recordings of the board waved about).
VIDEO_SUFFIXES: tuple[str, ...] = (".avi", ".mp4", ".mkv", ".mov", ".webm")
#: Most pairs :func:`calibrate_from_video` keeps: the first distinct board poses (a calibration
#: gains little past a few dozen views, and each view costs solver time).
MAX_VIDEO_PAIRS = 60
#: Seconds a camera's open or ``read`` may take before it is given up as hung
#: (:func:`stereovision.capture.read_within`; re-exported as ``capture.DEFAULT_READ_TIMEOUT``,
#: defined here as capture imports this module). A hung USB camera (or a network stream that
#: stalls) never returned: the stream waited forever, and a read in native code, holding off
#: Ctrl-C until it returned, made it unkillable but by SIGKILL. 10 s is OpenCV's own V4L2 select
#: timeout, and well above a camera's first frame (1-3 s).
DEFAULT_READ_TIMEOUT = 10.0


# ------------------------------------------------------------------------------------- helpers


def parse_pattern(text: str | Sequence[int], name: str = "pattern") -> tuple[int, int]:
    """Parse a chessboard pattern ``"9x6"`` (inner corners per row x per column).

    Parameters
    ----------
    text : str or sequence of int
        ``"COLSxROWS"`` or ``(cols, rows)`` (Python or NumPy integers, or whole numbers of
        another type: ``(9.0, 6.0)``).
    name : str
        How the caller calls it, for the messages (the CLI's ``"--pattern"``).

    Returns
    -------
    tuple of int
        ``(cols, rows)``, both from :data:`MIN_PATTERN_CORNERS` to :data:`MAX_PATTERN_CORNERS`.

    Raises
    ------
    TypeError
        If ``text`` is neither a string nor a pair of integers (``9``, ``(9.5, 6)``).
    ValueError
        If the text is not two integers separated by ``x``, or a count is below
        :data:`MIN_PATTERN_CORNERS` (OpenCV's detectors need a corner inside each side) or
        above :data:`MAX_PATTERN_CORNERS`.
    """
    if isinstance(text, str):
        parts = text.lower().replace("*", "x").split("x")
        try:
            vals = [int(p) for p in parts]
        except ValueError:
            vals = []
        if len(vals) != 2:
            raise ValueError(
                f"{name}: expected inner corners as COLSxROWS (e.g. 9x6), got {text!r}"
            )
    else:
        try:
            items = list(text)
        except TypeError:
            raise TypeError(
                f"{name}: expected inner corners as (cols, rows) or 'COLSxROWS' (e.g. '9x6'), "
                f"got {type(text).__name__} {text!r}"
            ) from None
        if len(items) != 2:
            raise ValueError(
                f"{name}: expected inner corners as (cols, rows), got {len(items)} values {text!r}"
            )
        # whole_value, every count's rule: (9.0, 6.0) read from a config or an array is 9x6
        # (it was refused as no integer); 9.5 is still refused, not truncated
        wholes = [whole_value(v) for v in items]
        for v, whole in zip(items, wholes, strict=True):
            if whole is None:
                raise TypeError(
                    f"{name}: corner counts must be integers, got {v!r} "
                    f"({type(v).__name__}) in {text!r}"
                )
        vals = [int(v) for v in wholes if v is not None]
    if min(vals) < MIN_PATTERN_CORNERS:
        raise ValueError(
            f"{name}: {vals[0]}x{vals[1]} inner corners; a chessboard needs at least "
            f"{MIN_PATTERN_CORNERS} each way (e.g. 9x6 for a board of 10x7 squares)"
        )
    if max(vals) > MAX_PATTERN_CORNERS:
        raise ValueError(
            f"{name}: {vals[0]}x{vals[1]} inner corners; a chessboard has at most "
            f"{MAX_PATTERN_CORNERS} each way (4 px squares across a 16384 px image)"
        )
    return vals[0], vals[1]


def board_object_points(pattern: tuple[int, int], square_size: float) -> npt.NDArray[np.float32]:
    """3-D corner coordinates on the board plane, in OpenCV's order (x fastest).

    Parameters
    ----------
    pattern : tuple of int
        ``(cols, rows)`` inner corners.
    square_size : float
        Side of a square, in the calibration's unit.

    Returns
    -------
    numpy.ndarray
        ``(cols * rows, 3)`` ``float32``, ``Z = 0``.
    """
    cols, rows = pattern
    obj = np.zeros((cols * rows, 3), np.float32)
    obj[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * np.float32(square_size)
    return obj


def _min_spacing(corners: F64, pattern: tuple[int, int]) -> float:
    cols, rows = pattern
    g = corners.reshape(rows, cols, 2)
    dx = np.linalg.norm(np.diff(g, axis=1), axis=2)
    dy = np.linalg.norm(np.diff(g, axis=0), axis=2)
    return float(min(dx.min(), dy.min()))


def _grid_symmetries(pattern: tuple[int, int]) -> list[npt.NDArray[np.intp]]:
    """Index permutations that map the corner grid onto itself (the detector's ambiguities)."""
    cols, rows = pattern
    idx = np.arange(cols * rows).reshape(rows, cols)
    perms = [idx.ravel(), idx[::-1, ::-1].ravel()]
    if cols == rows:
        perms += [np.rot90(idx, 1).ravel(), np.rot90(idx, 3).ravel()]
    return perms


def _canonical_order(corners: F64, pattern: tuple[int, int]) -> F64:
    """Put the first corner nearest the image's top-left (x + y smallest of the two ends)."""
    if corners[0].sum() > corners[-1].sum():
        return corners[::-1].copy()
    return corners


def _match_order(reference: F64, corners: F64, pattern: tuple[int, int]) -> F64:
    """Reorder ``corners`` to correspond to ``reference`` (same board seen by the other camera).

    The candidate orderings are the grid's symmetries; the one whose centred layout is closest to
    the reference's wins (both cameras see the board with about the same in-plane rotation).
    """
    ref = reference - reference.mean(axis=0)
    best, best_cost = corners, math.inf
    for perm in _grid_symmetries(pattern):
        c = corners[perm]
        cost = float(np.sum((c - c.mean(axis=0) - ref) ** 2))
        if cost < best_cost:
            best, best_cost = c, cost
    return best


def _sides_are_x_junctions(gray: np.ndarray, corners: F64, pattern: tuple[int, int]) -> bool:
    """False if most corners of one side of the detected grid are not X-junctions."""
    cols, rows = pattern
    g = corners.reshape(rows, cols, 2)
    img = gray.astype(np.float32)
    a = RING_SAMPLE_FRACTION

    def sample(p: F64) -> float:
        return float(cv2.getRectSubPix(img, (3, 3), (float(p[0]), float(p[1]))).mean())

    sides = (
        [(0, j) for j in range(cols)],
        [(rows - 1, j) for j in range(cols)],
        [(i, 0) for i in range(rows)],
        [(i, cols - 1) for i in range(rows)],
    )
    for side in sides:
        bad = 0
        for i, j in side:
            # Grid steps along the row and the column at this corner (one-sided at the ends).
            u = (g[i, min(j + 1, cols - 1)] - g[i, max(j - 1, 0)]) / (2 if 0 < j < cols - 1 else 1)
            v = (g[min(i + 1, rows - 1), j] - g[max(i - 1, 0), j]) / (2 if 0 < i < rows - 1 else 1)
            p = g[i, j]
            s1, s2 = sample(p + a * (u + v)), sample(p + a * (u - v))
            s3, s4 = sample(p - a * (u + v)), sample(p - a * (u - v))
            contrast = abs((s1 + s3) - (s2 + s4)) / 2
            bad += max(abs(s1 - s3), abs(s2 - s4)) >= X_JUNCTION_RATIO * contrast
        if 2 * bad > len(side):
            return False
    return True


def _grid_continues(gray: np.ndarray, corners: F64, pattern: tuple[int, int]) -> tuple[bool, bool]:
    """Whether the board has more inner corners than ``pattern`` past the grid found.

    One grid step beyond each side of the detected corners, a correct pattern reaches the board's
    outer edge (squares against the white margin: no X-junctions); a pattern smaller than the
    board (8x6 given for a 9x6 board) reaches another row or column of X-junctions. A side
    continues when most of its extrapolated points inside the image are X-junctions (the test
    of :func:`_sides_are_x_junctions`).

    Returns
    -------
    tuple of bool
        ``(more columns, more rows)``: a column continues past the left or right side, a row
        past the top or bottom.
    """
    cols, rows = pattern
    g = corners.reshape(rows, cols, 2)
    img = gray.astype(np.float32)
    h, w = img.shape[:2]
    a = RING_SAMPLE_FRACTION

    def is_x(p: F64, u: F64, v: F64) -> bool:
        ring = [p + a * (u + v), p + a * (u - v), p - a * (u + v), p - a * (u - v)]
        if any(not (1 <= q[0] < w - 2 and 1 <= q[1] < h - 2) for q in ring):
            return False
        s1, s2, s3, s4 = (
            float(cv2.getRectSubPix(img, (3, 3), (float(q[0]), float(q[1]))).mean()) for q in ring
        )
        contrast = abs((s1 + s3) - (s2 + s4)) / 2
        return bool(contrast > 0 and max(abs(s1 - s3), abs(s2 - s4)) < X_JUNCTION_RATIO * contrast)

    def side_continues(edge: F64, in1: F64, in2: F64, along: F64) -> bool:
        # edge: the side's corners, in1 and in2 the next two lines in, along: the step along the
        # side. The step outward is extrapolated to second order (perspective shrinks or grows
        # the squares across the board).
        step = (edge - in1) + ((edge - in1) - (in1 - in2))
        hits = sum(is_x(edge[k] + step[k], along[k], step[k]) for k in range(len(edge)))
        return 2 * hits > len(edge)

    row_step: F64 = np.asarray(np.gradient(g, axis=1))  # along a row (to the next column)
    col_step: F64 = np.asarray(np.gradient(g, axis=0))  # along a column (to the next row)
    more_rows = side_continues(g[0], g[1], g[2], row_step[0]) or side_continues(
        g[-1], g[-2], g[-3], row_step[-1]
    )
    more_cols = side_continues(g[:, 0], g[:, 1], g[:, 2], col_step[:, 0]) or side_continues(
        g[:, -1], g[:, -2], g[:, -3], col_step[:, -1]
    )
    return more_cols, more_rows


def find_corners(image: npt.ArrayLike, pattern: tuple[int, int] = (9, 6)) -> F64 | None:
    """Find the inner corners of a chessboard with sub-pixel accuracy.

    ``findChessboardCornersSB`` with the flag sets of :data:`SB_FLAG_SETS`, then the classic
    detector; the corners are refined by ``cornerSubPix`` with a half-window of
    :data:`SUBPIX_WINDOW_FRACTION` x the smallest corner spacing.

    Parameters
    ----------
    image : array_like
        Grey or BGR image (``uint8``, ``uint16`` or float in [0, 1]).
        A dark image of more than 8 bits (12-bit data in ``uint16``) is stretched by its own
        range, as :func:`~stereovision.calibrate.calibrate` reads it.
    pattern : tuple of int
        ``(cols, rows)`` inner corners.

    Returns
    -------
    numpy.ndarray or None
        ``(cols * rows, 2)`` ``float64`` pixel coordinates ``(x, y)`` in OpenCV's order (the
        first corner the one nearest the top-left of the image), or None if no board was found,
        or if one side of the grid found is made of L-shaped corners: a board cut by the image
        edge read one square off (:data:`RING_SAMPLE_FRACTION`).

    Raises
    ------
    ValueError
        If ``image`` is not an image, or ``pattern`` is not a chessboard's (see
        :func:`parse_pattern`).
    TypeError
        If ``pattern`` is not a pair of integers or a ``"COLSxROWS"`` string.
    """
    pattern = parse_pattern(pattern)
    # a dark image of more than 8 bits at its own range, as calibrate reads it (c74a955): its
    # top 8 bits (a 12-bit board: 0-15 grey levels) moved the corners 0.07 px, with a warning
    gray = _board_gray(image, "image")
    if min(gray.shape[:2]) < MIN_BOARD_IMAGE_SIDE:
        return None  # no board fits (and the classic detector fails an assertion there)
    found: npt.NDArray[np.float32] | None = None
    # checkChessboard (~2 ms) is a quick look for a board: it saw all 26 sample boards; when it
    # sees none, only the first flag set is tried (each SB call on a board-less image is ~0.5 s).
    flag_sets = SB_FLAG_SETS if cv2.checkChessboard(gray, pattern) else SB_FLAG_SETS[:1]
    h, w = gray.shape[:2]

    def inside(c: Any) -> bool:
        # The detectors can return a grid with corners off the image (left08.jpg of OpenCV's
        # samples read as 8x4 by the exhaustive SB pass): not a board, and cornerSubPix
        # raised cv2.error on it.
        p = np.asarray(c, np.float64).reshape(-1, 2)
        return bool(np.all(np.isfinite(p)) and np.all((p >= 0) & (p <= (w - 1, h - 1))))

    for flags in flag_sets:
        ok, c = cv2.findChessboardCornersSB(gray, pattern, flags=flags)
        if ok and inside(c):
            found = np.asarray(c, np.float32).reshape(-1, 1, 2)
            break
    if found is None:
        ok, c = cv2.findChessboardCorners(gray, pattern, flags=CLASSIC_FLAGS)
        if not ok or not inside(c):
            return None
        found = np.asarray(c, np.float32).reshape(-1, 1, 2)
    spacing = _min_spacing(found.reshape(-1, 2).astype(np.float64), pattern)
    half = int(
        np.clip(
            round(SUBPIX_WINDOW_FRACTION * spacing), SUBPIX_HALF_WINDOW_MIN, SUBPIX_HALF_WINDOW_MAX
        )
    )
    refined = cv2.cornerSubPix(gray, found, (half, half), (-1, -1), SUBPIX_CRITERIA)
    corners = refined.reshape(-1, 2).astype(np.float64)
    if not _sides_are_x_junctions(gray, corners, pattern):
        return None  # a cut board read one square off (see RING_SAMPLE_FRACTION)
    return _canonical_order(corners, pattern)


def board_pose_params(
    corners: npt.ArrayLike, pattern: tuple[int, int], image_size: tuple[int, int]
) -> tuple[float, float, float, float]:
    """Describe a board view by ``(x, y, size, skew)``, each in about [0, 1] (as ROS does).

    Parameters
    ----------
    corners : array_like
        ``(cols * rows, 2)`` corners in OpenCV's order.
    pattern : tuple of int
        ``(cols, rows)``.
    image_size : tuple of int
        ``(width, height)``.

    Returns
    -------
    tuple of float
        ``x``, ``y``: board centre over the image width/height (0 = left/top edge, 1 =
        right/bottom edge); ``size``: sqrt(area of the outer corner quadrilateral / image area);
        ``skew``: ``min(1, 2 |pi/2 - angle|)`` with ``angle`` the board's angle at its first
        corner.
    """
    cols, rows = pattern
    c = np.asarray(corners, np.float64).reshape(-1, 2)
    w, h = image_size
    quad = c[[0, cols - 1, cols * rows - 1, cols * (rows - 1)]]
    area = 0.5 * abs(
        float(
            np.dot(quad[:, 0], np.roll(quad[:, 1], -1))
            - np.dot(quad[:, 1], np.roll(quad[:, 0], -1))
        )
    )
    a, b = quad[1] - quad[0], quad[3] - quad[0]
    cosang = float(np.dot(a, b) / max(np.linalg.norm(a) * np.linalg.norm(b), 1e-12))
    angle = math.acos(max(-1.0, min(1.0, cosang)))
    centre = c.mean(axis=0)
    return (
        float(centre[0] / w),
        float(centre[1] / h),
        math.sqrt(area / (w * h)),
        min(1.0, 2.0 * abs(math.pi / 2 - angle)),
    )


def _coverage_mask(
    corner_sets: Sequence[F64], pattern: tuple[int, int], image_size: tuple[int, int]
) -> npt.NDArray[np.uint16]:
    """Per-pixel count (at 1/:data:`COVERAGE_DOWNSCALE` resolution) of boards covering it.

    A whole board covers the quadrilateral of its outer corners; a partial one (ChArUco) the
    convex hull of the corners seen.
    """
    cols, rows = pattern
    w, h = image_size
    s = COVERAGE_DOWNSCALE
    count = np.zeros((max(1, h // s), max(1, w // s)), np.uint16)
    for c in corner_sets:
        if len(c) == cols * rows:
            poly = c[[0, cols - 1, cols * rows - 1, cols * (rows - 1)]] / s
        else:
            poly = cv2.convexHull(np.asarray(c, np.float32)).reshape(-1, 2) / s
        m = np.zeros(count.shape, np.uint8)
        cv2.fillConvexPoly(m, np.round(poly).astype(np.int32), 1)
        count += m
    return count


# ----------------------------------------------------------------------------- the result type


@dataclass
class CalibrationReport:
    """What :func:`calibrate` did and how good the result is.

    Attributes
    ----------
    rms : float
        Stereo reprojection RMS over both cameras and all used pairs (px).
    rms_left, rms_right : float
        RMS of each camera calibrated alone (px), before the stereo solve: lower than its share
        of the stereo solution (``stereo_rms_left``, ``stereo_rms_right``).
    per_pair_errors : dict of str to float
        RMS reprojection error of each used pair in the stereo solution (px), both cameras.
    per_pair_errors_left, per_pair_errors_right : dict of str to float
        The same, per camera.
    used_pairs : list of str
        Names of the pairs the final solution uses.
    rejected_pairs : dict of str to str
        Pairs not used and why (``"board not found in left"`` (``right``, ``either image``),
        ``"outlier: ..."``).
    outlier_pairs : list of str
        Pairs flagged as outliers (dropped or not, see ``drop_outliers``).
    epipolar_mean_dy, epipolar_max_dy : float
        Mean and max ``|y_left - y_right|`` of all used corners after rectification (px); of a
        vertical rig, which OpenCV rectifies to columns, ``|x_left - x_right|`` (``|dx|``).
    square_size, square_size_measured, square_size_std : float
        Given square side, median and standard deviation of the sides between triangulated
        adjacent corners (in ``unit``). The triangulation's scale is the given square's (``T``
        is solved in its unit), so the median equals the given size up to the solution's
        inconsistency: it does not check the square size. The spread is the figure to read
        (0.65 % of the square on OpenCV's sample pairs).
    coverage_left, coverage_right : float
        Fraction of each image covered by at least one board (the area inside the outer corners).
    distortion_model : str
        The model used (one of :data:`DISTORTION_MODELS`).
    model_selection : dict of str to float
        Leave-one-view-out RMS of each candidate model (px; empty unless ``"auto"``).
    refined : bool
        Whether the joint refinement was kept.
    pattern, image_size, unit, baseline, focal_left, focal_right : ...
        Board's inner corners ``(cols, rows)``, image size ``(w, h)``, length unit, ``|T|`` and
        ``fx`` of each camera.
    board : str
        The board, in words (``"chessboard 9x6 inner corners"`` or the ChArUco board's
        :meth:`~stereovision.charuco.CharucoBoard.describe`).
    corners_used : int
        Corners used over all pairs (each seen by both cameras).
    warnings : list of str
        The warnings :func:`calibrate` gave about this calibration (a lens the model does not
        fit, a model that folds the image, file numbers that differ), also on the HTML page.
    stereo_rms_left, stereo_rms_right : float
        Each camera's share of the stereo solution (px), over all its corners: the RMS of the
        ``per_pair_errors_left`` (``_right``) weighted by each pair's corners, ``rms`` their
        quadratic mean.
    pair_selection : dict
        The pairs given but left out before the board was looked for, and why (empty when every
        pair given was looked at): ``option`` (``"--max-pairs 5"``), ``rule`` (in words),
        ``given`` and ``kept`` (counts), ``left_out`` (the pairs' names, as in ``used_pairs``) and
        ``left_out_count``. ``stereovision calibrate --max-pairs N`` fills it for image lists;
        :func:`calibrate_from_video` and :func:`calibrate_from_bag` when ``max_pairs`` stopped
        the reading (``option``, ``rule``, ``frames_read``, ``kept``, ``last_frame_read``).
    """

    rms: float
    rms_left: float
    rms_right: float
    per_pair_errors: dict[str, float]
    per_pair_errors_left: dict[str, float]
    per_pair_errors_right: dict[str, float]
    used_pairs: list[str]
    rejected_pairs: dict[str, str]
    outlier_pairs: list[str]
    epipolar_mean_dy: float
    epipolar_max_dy: float
    square_size: float
    square_size_measured: float
    square_size_std: float
    coverage_left: float
    coverage_right: float
    distortion_model: str
    model_selection: dict[str, float]
    refined: bool
    pattern: tuple[int, int]
    image_size: tuple[int, int]
    unit: str
    baseline: float
    focal_left: float
    focal_right: float
    board: str = "chessboard"
    corners_used: int = 0
    warnings: list[str] = field(default_factory=list)
    pair_selection: dict[str, Any] = field(default_factory=dict)
    stereo_rms_left: float = math.nan
    stereo_rms_right: float = math.nan
    # Data for the pictures; not part of the serialised report.
    _calibration: Any = field(default=None, repr=False, compare=False)
    _corners: dict[str, tuple[F64, F64]] = field(default_factory=dict, repr=False, compare=False)
    _ids: dict[str, npt.NDArray[np.int64]] = field(default_factory=dict, repr=False, compare=False)
    _sample: tuple[str, np.ndarray, np.ndarray] | None = field(
        default=None, repr=False, compare=False
    )
    # why drop_outliers kept an outlier (the summary told the reader to drop it with the very
    # option given)
    _kept_why: dict[str, str] = field(default_factory=dict, repr=False, compare=False)

    @property
    def square_size_error(self) -> float:
        """``square_size_measured / square_size - 1``: a consistency figure of the solution, not
        an error of the given square size (whose scale the triangulation inherits)."""
        return self.square_size_measured / self.square_size - 1.0

    def as_dict(self) -> dict[str, Any]:
        """Plain-Python (JSON/YAML-ready) dictionary of the report's figures."""
        out: dict[str, Any] = {}
        for name in self.__dataclass_fields__:
            if name.startswith("_"):
                continue
            v = getattr(self, name)
            out[name] = list(v) if isinstance(v, tuple) else v
        out["square_size_error"] = self.square_size_error
        if self._calibration is not None:
            cal = self._calibration
            out["calibration"] = {
                k: np.asarray(getattr(cal, k)).tolist() for k in ("K1", "D1", "K2", "D2", "R", "T")
            }
        return out

    def summary(self, *, drop_option: str = DROP_OUTLIERS_API) -> str:
        """A few lines for a terminal.

        Parameters
        ----------
        drop_option : str
            How the reader drops outliers, named where outliers were kept (the CLI passes
            ``"--drop-outliers"``).

        Returns
        -------
        str
            The summary, one figure per line.
        """
        n = len(self.used_pairs)
        total = n + len(self.rejected_pairs)
        lines = [
            f"{n}/{total} pairs used ({self.corners_used} corners, {self.board}); "
            f"stereo RMS {self.rms:.3f} px "
            f"(left {self.stereo_rms_left:.3f}, right {self.stereo_rms_right:.3f}; each camera "
            f"calibrated alone {self.rms_left:.3f} / {self.rms_right:.3f}; "
            f"model {self.distortion_model})",
            f"rectified epipolar error {_epipolar_label(self)}: mean "
            f"{self.epipolar_mean_dy:.3f} px, "
            f"max {self.epipolar_max_dy:.3f} px",
            f"baseline {self.baseline:.6g} {self.unit}, fx {self.focal_left:.2f} / "
            f"{self.focal_right:.2f} px; triangulated square sides spread "
            f"{100 * self.square_size_std / self.square_size:.2f} % (in the given square's "
            "scale: a wrong square size is not detected)",
            f"coverage left {100 * self.coverage_left:.0f} %, "
            f"right {100 * self.coverage_right:.0f} %",
        ]
        sel = self.pair_selection
        if sel and "left_out" not in sel:  # a recording, read up to max_pairs poses
            lines.append(f"reading stopped by {sel['option']} ({sel['rule']})")
        elif sel:
            gone = sel["left_out"]
            more = f" and {len(gone) - LEFT_OUT_SHOWN} more" if len(gone) > LEFT_OUT_SHOWN else ""
            lines.append(
                f"left out by {sel['option']} ({sel['rule']}): {sel['left_out_count']} of the "
                f"{sel['given']} pairs given, {', '.join(gone[:LEFT_OUT_SHOWN])}{more}"
            )
        for name, reason in self.rejected_pairs.items():
            lines.append(f"  rejected {name}: {reason}")
        for name in self.outlier_pairs:
            if name not in self.rejected_pairs:
                why = self._kept_why.get(name, f"drop it with {drop_option}")
                lines.append(f"  outlier kept: {name} ({why})")
        return "\n".join(lines)

    def save(self, path: PathLike) -> None:
        """Write the figures as ``.json`` or ``.yaml``/``.yml`` (atomically).

        A figure with nothing to measure (NaN: the triangulated square of a board whose
        corners were never seen beside each other) or an infinite one (a model's leave-one-out
        RMS in ``model_selection`` when a view's pose was not found) is ``null`` in JSON, which
        has no such numbers, and ``.nan`` / ``.inf`` in YAML; :meth:`load` reads both back.

        Raises
        ------
        ValueError
            For another file extension.
        FileNotFoundError
            If the directory does not exist.
        """
        from stereovision.io import atomic_write

        p = as_path(path, file=True)  # bytes: pathlib's TypeError named no argument
        suffix = p.suffix.lower()
        data = self.as_dict()
        if suffix == ".json":
            from stereovision._jsonout import json_ready

            # strict JSON: the bare NaN / Infinity json.dumps wrote are refused by JSON.parse,
            # jq and json.loads(..., parse_constant=...)
            text = json.dumps(json_ready(data), indent=2, allow_nan=False)
        elif suffix in (".yaml", ".yml"):
            import yaml

            text = yaml.safe_dump(data, sort_keys=False)
        else:
            raise ValueError(f"cannot save a report as {p.name!r}: use .json, .yaml or .yml")
        with atomic_write(p, "w") as fh:
            fh.write(text)

    @classmethod
    def load(cls, path: PathLike) -> CalibrationReport:
        """Read a report :meth:`save` (or :meth:`write`) wrote, ``.json``, ``.yaml`` or ``.yml``.

        Parameters
        ----------
        path : str or os.PathLike
            The report file.

        Returns
        -------
        CalibrationReport
            Its figures, equal to those saved: a JSON ``null`` is read as NaN, in
            ``model_selection`` as infinity (see :meth:`save`); with the calibration, but
            without the corners and images the pictures of :meth:`write` are drawn from.

        Raises
        ------
        FileNotFoundError
            If the file does not exist.
        ValueError
            For another file extension, or a file that is not such a report (a missing or
            malformed field named).
        """
        from stereovision.io import _existing_file

        p = _existing_file(path, "report file")
        suffix = p.suffix.lower()
        if suffix not in (".json", ".yaml", ".yml"):
            raise ValueError(f"cannot load a report from {p.name!r}: use .json, .yaml or .yml")
        import yaml

        try:
            text = p.read_text(encoding="utf-8-sig")
            data = json.loads(text) if suffix == ".json" else yaml.safe_load(text)
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise ValueError(f"{p} is not a calibration report: {exc}") from None
        except yaml.YAMLError as exc:  # its text spans several lines
            mark = getattr(exc, "problem_mark", None)
            where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
            raise ValueError(f"{p} is not a calibration report: not YAML{where}") from None
        if not isinstance(data, dict):
            raise ValueError(f"{p} is not a calibration report: not a mapping of figures")
        # JSON's null back to what save wrote it for (model_selection's: a failed fit, inf)
        none_is = {"model_selection": math.inf}
        figures: dict[str, Any] = {}
        try:
            for f in fields(cls):
                optional = f.default is not MISSING or f.default_factory is not MISSING
                if f.name.startswith("_") or (f.name not in data and optional):
                    continue
                v = data[f.name]
                if f.type == "float" and v is None:
                    v = math.nan
                elif f.type == "dict[str, float]":
                    gone = none_is.get(f.name, math.nan)
                    v = {k: gone if x is None else x for k, x in v.items()}
                elif f.type == "tuple[int, int]":
                    v = (v[0], v[1])
                figures[f.name] = v
            cal = data.get("calibration")
            if cal is not None:
                model = "fisheye" if figures["distortion_model"] == "fisheye" else "pinhole"
                matrices = {k: cal[k] for k in ("K1", "D1", "K2", "D2", "R", "T")}
                figures["_calibration"] = Calibration(
                    **matrices, image_size=figures["image_size"], unit=figures["unit"], model=model
                )
        except KeyError as exc:
            raise ValueError(f"{p} is not a calibration report: no field {exc}") from None
        except (TypeError, AttributeError, IndexError, ValueError) as exc:
            raise ValueError(f"{p} is not a calibration report: {exc}") from None
        return cls(**figures)

    def write(self, directory: PathLike) -> dict[str, Path]:
        """Write ``report.html`` (self-contained), ``report.yaml`` and ``report.json``.

        Parameters
        ----------
        directory : str or os.PathLike
            Created if missing.

        Returns
        -------
        dict of str to pathlib.Path
            ``{"html": ..., "yaml": ..., "json": ...}``.

        Raises
        ------
        NotADirectoryError
            If ``directory`` or a folder above it is a file or a link to nothing.
        """
        from stereovision.io import atomic_write, make_folder

        # as save; mkdir's bare "[Errno 17] File exists" of a link to nothing, or "[Errno 20]
        # Not a directory" under a file, named no cause
        d = make_folder(as_path(directory, "directory"))
        page = _render_html(self)
        paths = {"html": d / "report.html", "yaml": d / "report.yaml", "json": d / "report.json"}
        self.save(paths["yaml"])
        self.save(paths["json"])
        # a file name's non-UTF-8 byte (a lone surrogate, os.fsdecode) as "\udcff", as Python
        # shows it: UTF-8 cannot encode a surrogate
        with atomic_write(paths["html"], "wb") as fh:
            fh.write(page.encode("utf-8", "backslashreplace"))
        return paths


# ------------------------------------------------------------------------------- solving steps


@dataclass
class _Solution:
    rms: float
    rms_left: float
    rms_right: float
    K1: F64
    D1: F64
    K2: F64
    D2: F64
    R: F64
    T: F64
    per_view: F64  # (n, 2) RMS per view and camera
    refined: bool
    model: str
    model_selection: dict[str, float]
    # the largest angle (degrees) between two boards' planes, the smaller of the cameras' own:
    # each camera's poses, as mis-paired images skew the stereo solve's (a 5.4 degree spread
    # for 65)
    tilt_spread: float


def _tilt_spread(rvecs: Sequence[np.ndarray]) -> float:
    """The largest angle (degrees) between the planes of two board poses (``rvecs``, the
    boards in one camera's frame): about 0 when the board kept one tilt in every view."""
    normals = np.array(
        [cv2.Rodrigues(np.asarray(r, np.float64).reshape(3, 1))[0][:, 2] for r in rvecs]
    )
    cosines = np.abs(normals @ normals.T)  # a plane's normal is only known up to its sign
    return float(np.degrees(np.arccos(min(1.0, float(cosines.min())))))


def _loo_rms(
    obj: Sequence[np.ndarray],
    pts: Sequence[np.ndarray],
    size: tuple[int, int],
    flags: int,
    *,
    fit: Any,
    step: Callable[[], None] | None = None,
) -> tuple[float, F64, F64]:
    """Leave-one-view-out RMS of a camera model; also the fit on all views (K, D): ``fit``,
    :func:`_fit_all`'s (:func:`_solve` keeps the chosen model's). ``step`` is called after
    each view left out (a progress bar's tick)."""
    K, D = np.asarray(fit[1], np.float64), np.asarray(fit[2], np.float64)
    sq = 0.0
    n = 0
    for i in range(len(pts)):
        rest = [j for j in range(len(pts)) if j != i]
        _, Ki, Di, _, _ = cv2.calibrateCamera(
            [obj[j] for j in rest],
            [pts[j] for j in rest],
            size,
            K.copy(),
            D.copy(),
            flags=flags | cv2.CALIB_USE_INTRINSIC_GUESS,
            criteria=SOLVER_CRITERIA,
        )
        if step is not None:
            step()
        ok, rvec, tvec = cv2.solvePnP(obj[i], pts[i], Ki, Di, flags=cv2.SOLVEPNP_IPPE)
        if not ok:
            return math.inf, K, D
        rvec, tvec = cv2.solvePnPRefineLM(obj[i], pts[i], Ki, Di, rvec, tvec)
        proj, _ = cv2.projectPoints(obj[i], rvec, tvec, Ki, Di)
        sq += float(np.sum((proj.reshape(-1, 2) - pts[i].reshape(-1, 2)) ** 2))
        n += len(obj[i])
    return math.sqrt(sq / n), K, D


def _fit_all(
    obj: Sequence[np.ndarray], pts: Sequence[np.ndarray], size: tuple[int, int], flags: int
) -> Any:
    """``cv2.calibrateCamera`` of one camera on all views, from no initial guess."""
    return cv2.calibrateCamera(obj, pts, size, None, None, flags=flags, criteria=SOLVER_CRITERIA)


def _radial_is_monotonic(K: F64, D: F64, size: tuple[int, int]) -> bool:
    """True if the radial distortion maps radii monotonically over the whole image."""
    d = np.zeros(8)
    flat = np.asarray(D, np.float64).ravel()
    d[: min(8, flat.size)] = flat[:8]
    k1, k2, _, _, k3, k4, k5, k6 = d
    w, h = size
    corners = np.array([[0, 0], [w - 1, 0], [0, h - 1], [w - 1, h - 1]], np.float64)
    xn = (corners[:, 0] - K[0, 2]) / K[0, 0]
    yn = (corners[:, 1] - K[1, 2]) / K[1, 1]
    rd_max = float(np.hypot(xn, yn).max()) * MONOTONIC_RADIUS_MARGIN
    r = np.linspace(0.0, 4.0 * rd_max, 4000)
    r2 = r * r
    num = 1 + k1 * r2 + k2 * r2**2 + k3 * r2**3
    den = 1 + k4 * r2 + k5 * r2**2 + k6 * r2**3
    # Up to the denominator's first zero (a pole): a pole past the radius where the model has
    # already reached the image's corners lies outside the view (the rational model of the
    # StereoPi right camera: corners at 0.70, reached before its turn at 1.01, pole at 1.21).
    pole = np.nonzero(den <= 0)[0]
    n = int(pole[0]) if pole.size else r.size
    rd = r[:n] * num[:n] / den[:n]
    turn = np.nonzero(np.diff(rd) <= 0)[0]
    reach = rd if turn.size == 0 else rd[: turn[0] + 1]
    return bool(reach.max() >= rd_max)


def _fisheye_is_monotonic(K: F64, D: F64, size: tuple[int, int]) -> bool:
    """True if ``cv2.fisheye``'s ``theta_d = theta (1 + k1 theta^2 + ... + k4 theta^8)`` grows
    from the centre out to the image's corners (else the outer image has no ray, and folds)."""
    k1, k2, k3, k4 = (list(np.asarray(D, np.float64).ravel()) + [0.0] * 4)[:4]
    w, h = size
    corners = np.array([[0, 0], [w - 1, 0], [0, h - 1], [w - 1, h - 1]], np.float64)
    xn = (corners[:, 0] - K[0, 2]) / K[0, 0]
    yn = (corners[:, 1] - K[1, 2]) / K[1, 1]
    rd_max = float(np.hypot(xn, yn).max()) * MONOTONIC_RADIUS_MARGIN
    t = np.linspace(0.0, math.pi, 4000)
    t2 = t * t
    td = t * (1 + k1 * t2 + k2 * t2**2 + k3 * t2**3 + k4 * t2**4)
    turn = np.nonzero(np.diff(td) <= 0)[0]
    reach = td if turn.size == 0 else td[: turn[0] + 1]
    return bool(reach.max() >= rd_max)


def _fisheye_unusable(
    obj: Sequence[np.ndarray],
    left: Sequence[np.ndarray],
    right: Sequence[np.ndarray],
    size: tuple[int, int],
) -> list[int]:
    """Views whose pose ``cv2.fisheye.calibrate`` cannot initialise (it then aborts the whole
    solve): each view is tried beside the view with the most corners, in both cameras."""
    o = [np.asarray(x, np.float64).reshape(-1, 1, 3) for x in obj]
    ref = int(np.argmax([len(x) for x in o]))
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 5, 1e-6)
    bad = []
    for i in range(len(o)):
        views = [ref] if i == ref else [ref, i]
        for pts in (left, right):
            p = [np.asarray(pts[k], np.float64).reshape(-1, 1, 2) for k in views]
            try:
                cv2.fisheye.calibrate(
                    [o[k] for k in views], p, size, np.eye(3), np.zeros(4),
                    flags=FISHEYE_FLAGS, criteria=crit,
                )  # fmt: skip
            except cv2.error:
                bad.append(i)
                break
    return bad


def _fisheye_mono_rms(
    obj: Sequence[np.ndarray],
    left: Sequence[np.ndarray],
    right: Sequence[np.ndarray],
    size: tuple[int, int],
) -> tuple[float, float] | None:
    """Each camera's RMS (px) under ``cv2.fisheye.calibrate`` on the views it can start from,
    or None when the solver fails (a comparison for a pinhole solution that fits poorly)."""
    skip = set(_fisheye_unusable(obj, left, right, size))
    keep = [k for k in range(len(obj)) if k not in skip]
    if len(keep) < MIN_PAIRS:
        return None
    o = [np.asarray(obj[k], np.float64).reshape(-1, 1, 3) for k in keep]
    rms = []
    for pts in (left, right):
        p = [np.asarray(pts[k], np.float64).reshape(-1, 1, 2) for k in keep]
        try:
            fit: Any = cv2.fisheye.calibrate(
                o, p, size, np.eye(3), np.zeros(4), flags=FISHEYE_FLAGS, criteria=SOLVER_CRITERIA
            )
        except cv2.error:
            return None
        rms.append(float(fit[0]))
    return rms[0], rms[1]


def _solve_fisheye(
    obj: Sequence[np.ndarray],
    left: Sequence[np.ndarray],
    right: Sequence[np.ndarray],
    size: tuple[int, int],
    refine: bool,
) -> _Solution:
    """``cv2.fisheye.calibrate`` per camera, then the rig from the undistorted corners.

    ``cv2.fisheye.stereoCalibrate`` cannot take views with different numbers of corners (OpenCV
    issue 21748: a reshape error), which every ChArUco pair has. So each camera's corners are
    undistorted with its own fisheye intrinsics into a virtual pinhole camera (no distortion,
    the mean focal length) and ``cv2.stereoCalibrateExtended`` solves ``R``, ``T`` and the board
    poses there with those intrinsics fixed; the errors reported are then measured in the real
    fisheye images. (``refine`` has no fisheye counterpart: the intrinsics stay as calibrated.)
    """
    o = [np.asarray(x, np.float64).reshape(-1, 1, 3) for x in obj]
    pl = [np.asarray(x, np.float64).reshape(-1, 1, 2) for x in left]
    pr = [np.asarray(x, np.float64).reshape(-1, 1, 2) for x in right]
    try:
        mono: Any = [
            cv2.fisheye.calibrate(
                o, pts, size, np.eye(3), np.zeros(4), flags=FISHEYE_FLAGS, criteria=SOLVER_CRITERIA
            )
            for pts in (pl, pr)
        ]
    except cv2.error as exc:
        raise ValueError(
            f"the fisheye solver failed ({str(exc).strip().splitlines()[-1]}); check that the "
            "lens is a fisheye one and that the boards are found"
        ) from None
    rms_l, K1, D1 = mono[0][:3]
    rms_r, K2, D2 = mono[1][:3]
    f_v = float(K1[0, 0] + K2[0, 0]) / 2
    k_v = np.array([[f_v, 0.0, 0.0], [0.0, f_v, 0.0], [0.0, 0.0, 1.0]])
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 40, 1e-12)

    def virtual(pts: np.ndarray, K: np.ndarray, D: np.ndarray) -> np.ndarray:
        und = cv2.fisheye.undistortPoints(pts, K, D, criteria=crit)
        return (np.asarray(und, np.float64) * f_v).astype(np.float32)

    vl = [virtual(p, K1, D1) for p in pl]
    vr = [virtual(p, K2, D2) for p in pr]
    of = [x.astype(np.float32) for x in o]
    out: Any = cv2.stereoCalibrateExtended(
        of, vl, vr, k_v, np.zeros(5), k_v, np.zeros(5), size, np.eye(3), np.zeros((3, 1)),
        flags=cv2.CALIB_FIX_INTRINSIC, criteria=SOLVER_CRITERIA,
    )  # fmt: skip
    R = np.asarray(out[5], np.float64)
    T = np.asarray(out[6], np.float64).reshape(3, 1)
    rvecs, tvecs = out[9], out[10]
    per_view = np.zeros((len(o), 2))
    sq, n = 0.0, 0
    for i in range(len(o)):
        rb = cv2.Rodrigues(np.asarray(rvecs[i], np.float64).reshape(3, 1))[0]
        tb = np.asarray(tvecs[i], np.float64).reshape(3, 1)
        poses = ((rb, tb, K1, D1, pl[i]), (R @ rb, R @ tb + T, K2, D2, pr[i]))
        for cam, (rot, t, K, D, pts) in enumerate(poses):
            proj, _ = cv2.fisheye.projectPoints(o[i], cv2.Rodrigues(rot)[0], t, K, D)
            err2 = np.sum((proj.reshape(-1, 2) - pts.reshape(-1, 2)) ** 2, axis=1)
            per_view[i, cam] = math.sqrt(float(np.mean(err2)))
            sq += float(np.sum(err2))
            n += len(err2)
    return _Solution(
        rms=math.sqrt(sq / max(n, 1)),
        rms_left=float(rms_l),
        rms_right=float(rms_r),
        K1=np.asarray(K1, np.float64),
        D1=np.asarray(D1, np.float64).ravel(),
        K2=np.asarray(K2, np.float64),
        D2=np.asarray(D2, np.float64).ravel(),
        R=R,
        T=T.ravel(),
        per_view=per_view,
        refined=False,
        model="fisheye",
        model_selection={},
        tilt_spread=min(_tilt_spread(m[3]) for m in mono),
    )


def _solve(
    obj: Sequence[np.ndarray],
    left: Sequence[np.ndarray],
    right: Sequence[np.ndarray],
    size: tuple[int, int],
    distortion: str,
    refine: bool,
    progress: Callable[[str, int, int], None] | None = None,
) -> _Solution:
    if distortion == "fisheye":
        return _solve_fisheye(obj, left, right, size, refine)
    selection: dict[str, float] = {}
    # each camera's fit on all views, by model: the leave-one-out's start and, for the model
    # chosen, the mono solution (made twice, it was 2 of 4n + 6 calibrateCamera calls)
    full: dict[tuple[str, int], Any] = {}
    if distortion == "auto":
        candidates = AUTO_CANDIDATES
        if len(obj) < MODEL_SELECTION_MIN_VIEWS:
            candidates = AUTO_CANDIDATES[:1]
    else:
        candidates = (distortion,)
    if len(candidates) == 1:
        model = candidates[0]
    else:
        best_model, best_loo = "", math.inf
        # each candidate is fitted once per view left out, per camera: n^2 solver work that
        # took 8 of the 22 s of 30 pairs, said on a progress bar as the corner search is
        fits = [0, 2 * len(candidates) * len(obj)]

        def step() -> None:
            fits[0] += 1
            if progress is not None:
                progress(PROGRESS_MODELS, fits[0], fits[1])

        def reach(done: int) -> None:
            # a view whose pose is not found ends a camera's leave-one-out early (its RMS inf):
            # the fits it skipped are counted, or the count stopped short of the total given
            if fits[0] < done:
                fits[0] = done
                if progress is not None:
                    progress(PROGRESS_MODELS, done, fits[1])

        for k, name in enumerate(candidates):
            flags = DISTORTION_MODELS[name]
            full[name, 0] = _fit_all(obj, left, size, flags)
            loo_l, K1, D1 = _loo_rms(obj, left, size, flags, step=step, fit=full[name, 0])
            reach((2 * k + 1) * len(obj))
            full[name, 1] = _fit_all(obj, right, size, flags)
            loo_r, K2, D2 = _loo_rms(obj, right, size, flags, step=step, fit=full[name, 1])
            reach((2 * k + 2) * len(obj))
            loo = math.sqrt((loo_l**2 + loo_r**2) / 2)
            selection[name] = loo
            sane = _radial_is_monotonic(K1, D1, size) and _radial_is_monotonic(K2, D2, size)
            if sane and (not best_model or loo < best_loo * (1 - MODEL_SELECTION_GAIN)):
                best_model, best_loo = name, loo
        model = best_model or candidates[0]
    flags = DISTORTION_MODELS[model]
    mono: Any = [
        full[model, side] if (model, side) in full else _fit_all(obj, pts, size, flags)
        for side, pts in enumerate((left, right))
    ]
    rms_l, K1, D1 = mono[0][:3]
    rms_r, K2, D2 = mono[1][:3]
    out: Any = cv2.stereoCalibrateExtended(
        obj, left, right, K1, D1, K2, D2, size, np.eye(3), np.zeros((3, 1)),
        flags=cv2.CALIB_FIX_INTRINSIC | flags, criteria=SOLVER_CRITERIA,
    )  # fmt: skip
    rms, K1, D1, K2, D2, R, T, _, _, _, _, per_view = out
    refined = False
    if refine:
        out2: Any = cv2.stereoCalibrateExtended(
            obj, left, right, K1.copy(), D1.copy(), K2.copy(), D2.copy(), size, R.copy(),
            T.copy(), flags=cv2.CALIB_USE_INTRINSIC_GUESS | flags, criteria=SOLVER_CRITERIA,
        )  # fmt: skip
        if np.isfinite(out2[0]) and out2[0] < rms:
            rms, K1, D1, K2, D2, R, T, _, _, _, _, per_view = out2
            refined = True
    return _Solution(
        rms=float(rms),
        rms_left=float(rms_l),
        rms_right=float(rms_r),
        K1=K1,
        D1=D1.ravel(),
        K2=K2,
        D2=D2.ravel(),
        R=R,
        T=T.ravel(),
        per_view=np.asarray(per_view, np.float64).reshape(-1, 2),
        refined=refined,
        model=model,
        model_selection=selection,
        tilt_spread=min(_tilt_spread(m[3]) for m in mono),
    )


def _rectified_checks(
    cal: Calibration,
    left: Sequence[F64],
    right: Sequence[F64],
    pattern: tuple[int, int],
    ids: Sequence[npt.NDArray[np.int64]],
) -> tuple[float, float, float, float]:
    """Epipolar |dy| (mean, max) and triangulated square size (median, std) of all corners.

    ``ids`` are each pair's corners' indices in the ``pattern`` grid (row-major); the square size
    is measured between grid neighbours both seen.
    """
    _, _, P1, P2, _ = cal._stereo_rectify(0.0)
    # the coordinate across the rectified baseline: a vertical rig's corners share columns (its
    # |dy| was the 140 px of the baseline's disparity, for a 0.19 px solution)
    across = _across_baseline(P2)
    dys: list[F64] = []
    sides: list[F64] = []
    cols, rows = pattern
    for cl, cr, idx in zip(left, right, ids, strict=True):
        ul = cal._moved_points(cl, "left", 0.0)  # a vertical rig's too, to columns
        ur = cal._moved_points(cr, "right", 0.0)
        dys.append(np.abs(ul[:, across] - ur[:, across]))
        Xh = cv2.triangulatePoints(P1, P2, ul.T, ur.T)
        flat = np.full((rows * cols, 3), np.nan)
        flat[idx] = (Xh[:3] / Xh[3]).T
        X = flat.reshape(rows, cols, 3)  # NaN where a corner was not seen by both
        sides.append(np.linalg.norm(np.diff(X, axis=1), axis=2).ravel())
        sides.append(np.linalg.norm(np.diff(X, axis=0), axis=2).ravel())
    dy = np.concatenate(dys)
    side = np.concatenate(sides)
    side = side[np.isfinite(side)]
    if side.size == 0:  # no two neighbouring corners seen together
        return float(dy.mean()), float(dy.max()), math.nan, math.nan
    return float(dy.mean()), float(dy.max()), float(np.median(side)), float(side.std())


# ------------------------------------------------------------------------------------ loading


def _across_baseline(p2: F64) -> int:
    """The rectified image axis across the baseline: 1 (y) for a side-by-side rig, 0 (x) for a
    vertical one, which ``cv2.stereoRectify`` aligns by columns (``P2[1, 3]`` holds its baseline).
    """
    return 0 if abs(p2[1, 3]) > abs(p2[0, 3]) else 1


def _epipolar_label(rep: CalibrationReport) -> str:
    """``|dy|``, or ``|dx|`` for a vertical rig's report (see :func:`_across_baseline`)."""
    cal = rep._calibration
    if cal is None or cal.rectified:
        return "|dy|"
    return "|dy|" if _across_baseline(cal._stereo_rectify(0.0)[3]) else "|dx|"


def _warn(notes: list[str], message: str, category: type[Warning]) -> None:
    """Give a warning of :func:`calibrate`'s caller and keep it for the report: the first line
    outside the package (a fixed level named calibrate.py through calibrate_from_video)."""
    from stereovision._validate import user_stacklevel

    notes.append(message)
    warnings.warn(message, category, stacklevel=user_stacklevel())


def _charuco_hint(board: CharucoBoard, gray: np.ndarray, name: str) -> str:
    """Why a ChArUco board may not be found, from the markers an image shows (``""``: none)."""
    from stereovision.charuco import AUTO_MIN_MARKERS, DICTIONARY_FAMILIES

    seen, count = board.markers_seen(gray)
    if count < AUTO_MIN_MARKERS:
        return ""
    # The family by membership, not by the name's prefix: DICT_APRILTAG_36H11 and
    # DICT_APRILTAG_25H9 (DICT_ARUCO_ORIGINAL and DICT_ARUCO_MIP_36H12) are different families.
    key = next(k for k, members in DICTIONARY_FAMILIES.items() if seen in dict(members))
    family = f"DICT_{key}"
    if board.dictionary != "auto" and board.dictionary not in dict(DICTIONARY_FAMILIES[key]):
        return (
            f"{name} shows {count} markers of {family}, not of {board.dictionary}: give the "
            f"board's dictionary (e.g. dictionary='{seen}')"
        )
    if board.legacy is not None and board.squares[1] % 2 == 0 and board.dictionary != "auto":
        # OpenCV's other layout of an even number of rows (a board printed before 4.6 given
        # legacy=False, or the reverse) was told to check its squares and marker size
        from stereovision.charuco import find_charuco_corners

        other = not board.legacy
        if find_charuco_corners(gray, replace(board, legacy=other)) is not None:
            return (
                f"{name} shows the board in OpenCV's "
                f"{'pre-4.6 (legacy)' if other else 'current (4.6 and later)'} layout, not the "
                f"one given: give legacy={other} (or leave the layout out, to be found from "
                "the images)"
            )
    return (
        f"{name} shows {count} of its {family} markers, but not as a "
        f"{board.squares[0]}x{board.squares[1]}-square board's: check the squares (columns x "
        "rows) and the marker size"
    )


def _load_gray(item: object, what: str) -> tuple[np.ndarray, str | None]:
    """Grey uint8 image from a path or an array (:func:`_board_gray`); the file name when it
    was a path."""
    name = None
    if isinstance(item, (str, os.PathLike)):
        from stereovision.io import read_image

        # read_image keeps a 16-bit file's bits (imread(gray=True) kept its top 8)
        name = Path(item).name
        item = read_image(item)
    return _board_gray(item, what), name


def _same_size(
    s: tuple[int, int], label: str, size: tuple[int, int] | None, first_name: str
) -> tuple[tuple[int, int], str]:
    """``(size, first_name)``: the first image's ``(w, h)`` and name, once one was seen; an
    image ``label`` of another size ``s`` is refused naming both."""
    if size is None:
        return s, label
    if s != size:
        raise ValueError(
            f"{label}: image is {s[0]}x{s[1]}, but {first_name} is {size[0]}x{size[1]}"
        )
    return size, first_name


def _image_size(item: object, what: str) -> tuple[tuple[int, int], str]:
    """``(w, h)`` of an image as :func:`_load_gray` reads it, and its name in messages (the
    file's name, else ``what``). A file is decoded grey alone (OpenCV turns it by its EXIF
    orientation as read_image does), cheaper than read_image's colour decode (which was two
    decodes when this pass came: 4 ms of OpenCV's JPEG pairs, 5 s over the calibrate tests); a
    file it cannot decode so is read by read_image, whose error names the problem."""
    if isinstance(item, (str, os.PathLike)):
        from stereovision.io import _imdecode, _is_pfm, read_image

        buf = np.fromfile(item, np.uint8)
        grey = None if _is_pfm(buf) else _imdecode(buf, cv2.IMREAD_GRAYSCALE)
        h, w = (read_image(item) if grey is None else grey).shape[:2]
        return (w, h), Path(item).name
    from stereovision._validate import as_image_array

    h, w = as_image_array(item, what).shape[:2]
    return (w, h), what


def _board_gray(image: object, what: str) -> npt.NDArray[np.uint8]:
    """Grey uint8 image of a board for OpenCV's detectors.

    An image of more than 8 bits that is dark (its brightest grey under ``_DARK_PAIR`` of the
    range: a 10- or 12-bit camera's frames in a 16-bit PNG) is stretched by the gain that brings
    its brightest grey to 255, as ``depth_map``'s automatic range and the rectification check
    stretch a dark pair: cut to its top 8 bits, a 10-bit frame kept 4 grey levels, and the
    board's corners were found from them (OpenCV's chessboard pairs: RMS 0.30 px, 0.20 px at
    8 bits). A black one (a lens cap, a camera's first frame) is black, without the warning of
    its bits ("largest value is 0 ... scale it"). An 8-bit image is read as before."""
    from stereovision._validate import as_gray_float, as_gray_uint8, as_image_array
    from stereovision.depth import _DARK_PAIR

    arr = as_image_array(image, what)
    if arr.dtype != np.uint8:
        if not arr.any():
            return np.zeros(arr.shape[:2], np.uint8)
        grey = as_gray_float(arr, what, warn=False)
        top = float(grey.max())
        if 0.0 < top < _DARK_PAIR:
            out: npt.NDArray[np.uint8] = np.rint(grey * np.float32(255.0 / top)).astype(np.uint8)
            return out
    return as_gray_uint8(arr, what)


def _pair_names(
    left_names: list[str | None], right_names: list[str | None], names: Sequence[str] | None
) -> list[str]:
    """Each pair's name: ``names``, else ``"left06.png / right06.png"`` (one name when both files
    have it), else ``pair_NN``; made unique with an index prefix."""
    n = len(left_names)
    if names is not None:
        out = [str(s) for s in names]
        if len(out) != n:
            raise ValueError(f"names: expected {n} names (one per pair), got {len(out)}")
    else:
        out = []
        for i, (a, b) in enumerate(zip(left_names, right_names, strict=True)):
            if a and b and a != b:
                out.append(f"{a} / {b}")
            else:
                out.append(a or b or f"pair_{i:02d}")
    if len(set(out)) != len(out):
        out = [f"{i:02d}:{s}" for i, s in enumerate(out)]
    return out


def _file_number(name: str | None) -> int | None:
    """The last number in a file name's stem (``left06.jpg`` -> 6), or None."""
    if not name:
        return None
    digits = re.findall(r"\d+", Path(name).stem)
    return int(digits[-1]) if digits else None


def _file_numbers(names: Sequence[str | None]) -> list[int | None]:
    """Each name's number (:func:`_file_number`) taken from one place in the names of one
    camera: the last number that differs between them. A number every name of the side
    carries alike (the camera's index in ``pair03_cam1.jpg``) is not the pair's: the
    pairs were then said to carry different numbers, and the names did not pair on them."""
    groups = [re.findall(r"\d+", Path(n).stem) if n else [] for n in names]
    at = _number_place(groups)
    return [int(g[at]) if g else None for g in groups]


def _number_place(groups: Sequence[Sequence[str]]) -> int:
    """Where the pair's number sits among the numbers (digit runs) ``groups`` of one camera's
    names, counted from the end: the last place whose number differs between them; ``-1`` (the
    last number) when none differs, when the names carry different counts of numbers, or
    when fewer than two carry any (:func:`_file_numbers`, and batch's camera folders)."""
    known = [g for g in groups if g]
    if len(known) >= 2 and len({len(g) for g in known}) == 1:
        for j in range(len(known[0]) - 1, -1, -1):
            if len({int(g[j]) for g in known}) > 1:
                return j - len(known[0])
    return -1


def _constant_shift(kl: Sequence[int | None], kr: Sequence[int | None]) -> int | None:
    """``d`` when the right numbers are the left ones + ``d`` (``d != 0``), both an unbroken
    run of as many numbers (``left_0001..0020`` and ``right_0101..0120``, in any order) that
    share at most half their numbers; else None.

    The rule: runs sharing more than half their numbers (``left_0001..0020`` with
    ``right_0002..0021``, 19 shared) are one run with an end file deleted on each side, paired
    by number; runs sharing half or fewer (``right_0011..0030``, 10 shared; ``right_0101..
    0120``, none) are each camera's counter started elsewhere, paired in order.
    """
    if len(kl) < 2 or len(kl) != len(kr) or None in kl or None in kr:
        return None
    nl, nr = sorted(k for k in kl if k is not None), sorted(k for k in kr if k is not None)
    if nl != list(range(nl[0], nl[0] + len(nl))) or nr != list(range(nr[0], nr[0] + len(nr))):
        return None
    if 2 * len(set(nl) & set(nr)) > len(nl):
        return None  # mostly the same numbers: an end file deleted on each side, not an offset
    return nr[0] - nl[0] or None


def _numbers_differ(
    left_names: Sequence[str | None], right_names: Sequence[str | None], pair_names: Sequence[str]
) -> list[str]:
    """Pairs whose left and right file names both carry a number, and not the same one; none
    when the numbers of two unbroken runs differ by one constant in every pair
    (:func:`_constant_shift`: each camera's counter started elsewhere, nothing shifted)."""
    kl, kr = _file_numbers(left_names), _file_numbers(right_names)
    shift = _constant_shift(kl, kr)
    if shift is not None and all(
        a is not None and b is not None and b - a == shift for a, b in zip(kl, kr, strict=True)
    ):
        return []
    out = []
    for na, nb, name in zip(kl, kr, pair_names, strict=True):
        if na is not None and nb is not None and na != nb:
            out.append(name)
    return out


def _shows_one_rig(sol: _Solution) -> bool:
    """Whether the stereo RMS is within :data:`MAX_STEREO_RMS_PX`, or
    :data:`MISPAIRED_RMS_RATIO` x each camera's own."""
    mono = max(sol.rms_left, sol.rms_right)
    return sol.rms <= MAX_STEREO_RMS_PX or sol.rms <= MISPAIRED_RMS_RATIO * mono


def _check_pairing(
    sol: _Solution, names: Sequence[str], differ: Sequence[str], dropped: bool
) -> None:
    """Refuse a solution whose pairs do not show one rig (see :data:`MISPAIRED_RMS_RATIO`)."""
    if _shows_one_rig(sol):
        return
    pair_err = np.sqrt(np.mean(sol.per_view**2, axis=1))
    worst = np.argsort(-pair_err)[:WORST_PAIRS_SHOWN]
    listed = ", ".join(f"{names[k]} ({pair_err[k]:.1f} px)" for k in worst)
    numbers = f"; the file numbers differ in {_first_shown(differ)}" if differ else ""
    raise ValueError(
        f"stereo RMS {sol.rms:.1f} px, while each camera alone fits its boards to "
        f"{sol.rms_left:.2f} / {sol.rms_right:.2f} px: the pairs do not show one rig; are they "
        f"mis-paired (a missing file shifting the pairing, or a pair swapped)? Worst pairs: "
        f"{listed}{numbers}. "
        + (
            "Dropping the outliers left too many such pairs: check the pairing of the files"
            if dropped
            else f"Check those pairs, or drop the outliers with {DROP_OUTLIERS_API}"
        )
    )


def _squares_counted(gray: np.ndarray, pat: tuple[int, int]) -> tuple[tuple[int, int], bool] | None:
    """The inner corners of the board ``gray`` shows when ``pat`` counted its squares, or
    missed a row or column of its corners.

    Both ways first (10x7 for 9x6), then one way alone (10x6 or 9x7: the squares counted along
    one side, the corners along the other), then one more along either side (9x5 for 9x6: a row
    of corners missed, which OpenCV does not find on OpenCV's left01.jpg); the first pattern
    found and whether it is one fewer, or None (a pattern under 3x3 is none).
    """
    for fewer in ((pat[0] - 1, pat[1] - 1), (pat[0] - 1, pat[1]), (pat[0], pat[1] - 1)):
        if min(fewer) >= MIN_PATTERN_CORNERS and find_corners(gray, fewer) is not None:
            return fewer, True
    for more in ((pat[0], pat[1] + 1), (pat[0] + 1, pat[1])):
        if max(more) <= MAX_PATTERN_CORNERS and find_corners(gray, more) is not None:
            return more, False
    return None


def _rejected_words(rejected: dict[str, str]) -> str:
    """The rejected pairs of a refusal, grouped by why: 'board not found in right' was left
    unsaid, the pairs' names alone giving no clue that one camera never saw the board."""
    groups: dict[str, list[str]] = {}
    for name, why in rejected.items():
        groups.setdefault(why, []).append(name)
    return "; ".join(f"{', '.join(names)}: {why}" for why, names in groups.items())


def _first_shown(names: Sequence[str]) -> str:
    """The first :data:`WORST_PAIRS_SHOWN` of ``names``, and how many more there are."""
    shown = ", ".join(names[:WORST_PAIRS_SHOWN])
    extra = len(names) - WORST_PAIRS_SHOWN
    return f"{shown} and {extra} more" if extra > 0 else shown


def _listed(given: Any, name: str, what: str) -> list[Any]:
    """``given`` as a list; one that is no sequence (None, a number) a TypeError naming it
    (list()'s "'int' object is not iterable" named no argument)."""
    try:
        items = iter(given)
    except TypeError:
        raise TypeError(f"{name}: expected a sequence of {what}, got {given!r}") from None
    return list(items)


# ------------------------------------------------------------------------------------- public


def calibrate(
    left_images: Sequence[ImageInput],
    right_images: Sequence[ImageInput],
    *,
    pattern: tuple[int, int] | str = (9, 6),
    square_size: float | None = None,
    board: CharucoBoard | None = None,
    unit: str = "m",
    distortion: str = "auto",
    refine: bool = True,
    drop_outliers: bool = False,
    names: Sequence[str] | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> tuple[Calibration, CalibrationReport]:
    """Calibrate a stereo rig from chessboard or ChArUco pairs.

    Parameters
    ----------
    left_images, right_images : sequence of path or array_like
        The pairs, in the same order: image files (any format OpenCV reads) or arrays (grey or
        BGR, ``uint8``/``uint16``/float in [0, 1]). All images must have one size.
    pattern : tuple of int or str
        A chessboard's inner corners ``(cols, rows)`` or ``"9x6"`` (ignored with ``board``).
    square_size : float
        Side of one chessboard square in ``unit``; ``T`` and the baseline come out in that unit.
        Required for a chessboard; with ``board`` it must be omitted or equal the board's.
    board : stereovision.charuco.CharucoBoard, optional
        A ChArUco board (its sizes in ``unit``). A pair is used when both cameras see at least
        :data:`~stereovision.charuco.MIN_CORNERS` common corners, not all on one line; the board
        may be cut by the image edges. ``dictionary="auto"`` is settled on the first image that
        shows the board.
    unit : str
        Length unit of ``square_size`` (``"m"``, ``"mm"``, ``"cm"``, ``"ft"``, ``"in"``).
    distortion : str
        ``"auto"`` (k1 k2 p1 p2, with k3 only when it predicts held-out views better), one of
        :data:`DISTORTION_MODELS`, or ``"fisheye"``: ``cv2.fisheye``'s equidistant model (k1..k4)
        for wide-angle lenses, giving a ``model="fisheye"`` calibration.
    refine : bool
        Run the joint refinement of intrinsics and extrinsics after the fixed-intrinsics solve.
    drop_outliers : bool
        Drop the outlier pairs (error > :data:`OUTLIER_FACTOR` x median and >
        :data:`OUTLIER_MIN_PX`) and solve again; otherwise they are only reported.
    names : sequence of str, optional
        Pair names for the report, one per pair (default: the file names, or ``pair_NN`` for
        arrays).
    progress : callable, optional
        Called as ``progress(stage, done, total)`` while the work goes on (``stereovision
        calibrate`` draws its progress bars with it): stage :data:`PROGRESS_BOARDS` after each
        pair's board search (``total`` pairs), :data:`PROGRESS_MODELS` after each leave-one-out
        fit while ``distortion="auto"`` chooses the model (``total`` fits; a second round when
        ``drop_outliers`` solves again).

    Returns
    -------
    calibration : stereovision.calibration.Calibration
        ``K1 D1 K2 D2 R T`` (OpenCV convention ``X_R = R X_L + T``), ``image_size``, ``unit``.
    report : CalibrationReport

    Raises
    ------
    FileNotFoundError
        If an image file does not exist (the message names it).
    TypeError
        If ``board`` is given and is not a :class:`~stereovision.charuco.CharucoBoard` (a
        chessboard's ``"9x6"`` goes in ``pattern``), ``left_images``, ``right_images`` or
        ``names`` is no sequence (one path, one string, one image array, None, a number), or
        ``progress`` is given and cannot be called.
    ValueError
        If a file cannot be decoded, the lists differ in length, the images differ in size, an
        argument is invalid, or fewer than :data:`MIN_PAIRS` pairs show the board in both images.
        With ``dictionary="auto"``, also if no image shows enough of the board's markers. If the
        pairs do not show one rig (stereo RMS above :data:`MAX_STEREO_RMS_PX` and
        :data:`MISPAIRED_RMS_RATIO` x each camera's; mis-paired or swapped images): the message
        names the worst pairs, or says that one camera is upside down when the right boards
        read turned half round fit.

    Warns
    -----
    UserWarning
        If the left and right file names of a pair carry different numbers (``left06.jpg`` with
        ``right05.jpg``).

    Examples
    --------
    ``chessboard`` is the folder of OpenCV's sample pairs ``left01.jpg`` ... ``right14.jpg``
    (9 x 6 inner corners; the tests give ``shared/data/chessboard`` beside the repository):

    >>> from pathlib import Path
    >>> from stereovision.calibrate import calibrate
    >>> d = Path(chessboard)
    >>> cal, rep = calibrate(sorted(d.glob("left*.jpg"))[:4],
    ...                      sorted(d.glob("right*.jpg"))[:4], square_size=1.0)
    >>> len(rep.used_pairs), rep.rms < 0.3
    (4, True)
    """
    from stereovision.calibration import Calibration
    from stereovision.charuco import corners_span_plane, find_charuco_corners

    pat, square, unit = _board_setup(pattern, square_size, board, unit, distortion)
    _check_progress(progress)
    for name, given in (("left_images", left_images), ("right_images", right_images)):
        if isinstance(given, (str, bytes, os.PathLike)):  # one path: list() would split it
            raise TypeError(
                f"{name}: expected a sequence of images or paths, got one path {given!r} "
                "(a list of one, or a glob through stereovision calibrate --left 'left*.png')"
            )
        shape = np.shape(given) if isinstance(given, np.ndarray) else ()
        if len(shape) == 2 or (len(shape) == 3 and shape[2] in (1, 3, 4)):
            # one image, not a stack of them: list() gave its rows as images, a colour one
            # "found in both images of only 0 of 48 pairs" after 48 board searches
            raise TypeError(
                f"{name}: expected a sequence of images or paths, got one image of shape "
                f"{shape} (a list of the pair's images: [image, ...])"
            )
    lefts = _listed(left_images, "left_images", "images or paths")
    rights = _listed(right_images, "right_images", "images or paths")
    if len(lefts) != len(rights):
        raise ValueError(
            f"left_images and right_images differ in length: {len(lefts)} vs {len(rights)}"
        )
    if not lefts:
        raise ValueError("no image pairs given")
    if names is not None:
        # before the boards are looked for (a minute for 30 pairs), not after, as it was
        if isinstance(names, (str, bytes)):  # list() would name the pairs by its letters
            raise TypeError(f"names: expected one name per pair, got one name {names!r}")
        names = _listed(names, "names", "names, one per pair")
        if len(names) != len(lefts):
            raise ValueError(f"names: expected {len(lefts)} names (one per pair), got {len(names)}")

    size: tuple[int, int] | None = None
    first_name = ""
    notes: list[str] = []  # the warnings given, for the report
    left_names: list[str | None] = []
    right_names: list[str | None] = []
    corners_l: list[F64 | None] = []
    corners_r: list[F64 | None] = []
    corner_ids: list[npt.NDArray[np.int64] | None] = []
    short: dict[int, str] = {}  # pairs whose boards were seen, but not enough of them in common
    full_ids = np.arange(pat[0] * pat[1], dtype=np.int64)
    # chessboards found, and those whose grid continues past a side (a pattern too small)
    n_boards = n_more_cols = n_more_rows = 0
    sample: tuple[int, np.ndarray, np.ndarray] | None = None
    for item in (*lefts, *rights):
        if isinstance(item, (str, os.PathLike)) and not Path(item).is_file():
            if Path(item).is_dir():
                raise ValueError(f"{item}: is a folder, not an image file; list its images")
            # in imread's words: a FIFO was "not found", a link whose target moved said bare
            from stereovision.io import _existing_file

            _existing_file(item, "image file")
    # every image's size before any board search: an image of another size late in the list
    # was refused after the searches of all pairs before it (0.6 s each, 30 ms for a read)
    for i, (li, ri) in enumerate(zip(lefts, rights, strict=True)):
        for item, what in ((li, f"left_images[{i}]"), (ri, f"right_images[{i}]")):
            s, label = _image_size(item, what)
            size, first_name = _same_size(s, label, size, first_name)

    first_gray: np.ndarray | None = None
    for i, (li, ri) in enumerate(zip(lefts, rights, strict=True)):
        gl, nl = _load_gray(li, f"left_images[{i}]")
        if first_gray is None:
            first_gray = gl
        gr, nr = _load_gray(ri, f"right_images[{i}]")
        left_names.append(nl)
        right_names.append(nr)
        for img, label in ((gl, nl or f"left_images[{i}]"), (gr, nr or f"right_images[{i}]")):
            # the images as read against the sizes read first (a file changed in between)
            size, first_name = _same_size((img.shape[1], img.shape[0]), label, size, first_name)
        ids: npt.NDArray[np.int64] | None = full_ids
        if board is not None:
            if not board.resolved:  # settle dictionary="auto" on the first image showing it
                board = board.resolve(gl) or board.resolve(gr) or board
            found_l = find_charuco_corners(gl, board) if board.resolved else None
            found_r = find_charuco_corners(gr, board) if board.resolved else None
            cl = cr = ids = None
            if found_l is not None and found_r is not None:
                common, il, ir = np.intersect1d(found_l[0], found_r[0], return_indices=True)
                if len(common) >= CHARUCO_MIN_COMMON and corners_span_plane(board, common):
                    ids, cl, cr = common, found_l[1][il], found_r[1][ir]
                else:
                    short[i] = (
                        f"only {len(common)} corners seen in both images (at least "
                        f"{CHARUCO_MIN_COMMON}, not all on one line)"
                    )
            else:
                cl = None if found_l is None else found_l[1]
                cr = None if found_r is None else found_r[1]
        else:
            # (findChessboardCornersSB already runs on all cores: no thread pool here)
            cl, cr = find_corners(gl, pat), find_corners(gr, pat)
            for gray, found in ((gl, cl), (gr, cr)):
                if found is not None:
                    n_boards += 1
                    more_cols, more_rows = _grid_continues(gray, found, pat)
                    n_more_cols += more_cols
                    n_more_rows += more_rows
                    if more_cols or more_rows:
                        short[i] = (
                            f"the board continues past the {pat[0]}x{pat[1]} corners found: it "
                            "has more inner corners than the pattern"
                        )
            if cl is not None and cr is not None:
                cr = _match_order(cl, cr, pat)
        if cl is not None and cr is not None and sample is None and i not in short:
            sample = (i, gl, gr)
        corners_l.append(cl)
        corners_r.append(cr)
        corner_ids.append(ids)
        if progress is not None:
            progress(PROGRESS_BOARDS, i + 1, len(lefts))
    assert size is not None
    n_more = max(n_more_cols, n_more_rows)
    if n_more and 2 * n_more >= n_boards:
        # A grid smaller than the board is found somewhere on it, a different part of the board
        # in each image: the corners' board coordinates are then wrong.
        bigger = (pat[0] + (2 * n_more_cols >= n_boards), pat[1] + (2 * n_more_rows >= n_boards))
        raise ValueError(
            f"pattern=({pat[0]}, {pat[1]}): the board has more inner corners than that (a "
            f"{'column' if n_more_cols >= n_more_rows else 'row'} of corners continues past the "
            f"grid found in {n_more} of the {n_boards} boards found); count the points where four "
            f"squares meet along a row and along a column (at least {bigger[0]}x{bigger[1]})"
        )
    pair_names = _pair_names(left_names, right_names, names)
    differ = _numbers_differ(left_names, right_names, pair_names)
    if differ:
        shown = _first_shown(differ)
        _warn(
            notes,
            f"the left and right file numbers differ in {shown}: the pairs are taken in "
            "order, so a missing or extra file shifts the pairing",
            UserWarning,
        )

    rejected: dict[str, str] = {}
    used: list[int] = []
    repeats: list[str] = []
    for i, (cl, cr) in enumerate(zip(corners_l, corners_r, strict=True)):
        if i in short:
            rejected[pair_names[i]] = short[i]
        elif cl is None or cr is None or corner_ids[i] is None:
            # "not found in both images" read as found in one of them
            where = (
                "either image" if cl is None and cr is None else "left" if cl is None else "right"
            )
            rejected[pair_names[i]] = f"board not found in {where}"
        elif (
            twin := next(
                (
                    j
                    for j in used
                    if np.array_equal(cast(F64, corners_l[j]), cl)
                    and np.array_equal(cast(F64, corners_r[j]), cr)
                    and np.array_equal(cast(Any, corner_ids[j]), cast(Any, corner_ids[i]))
                ),
                None,
            )
        ) is not None:
            # The same images given twice (overlapping globs, a file copied): counted twice, 2
            # views passed for the 3 needed, and a view left out kept its twin in the
            # cross-validation that picks the distortion model.
            repeats.append(pair_names[i])
            rejected[pair_names[i]] = (
                f"the same board corners as {pair_names[twin]} in both images (a repeated pair)"
            )
        else:
            used.append(i)
    if repeats:
        shown = _first_shown(repeats)
        _warn(
            notes,
            f"{shown} repeat{'s' if len(repeats) == 1 else ''} an earlier pair (the same "
            "board corners in both images): each view is used once",
            UserWarning,
        )
    board_text = (
        f"chessboard {pat[0]}x{pat[1]} inner corners" if board is None else board.describe(unit)
    )
    board_hint = ""  # a ChArUco board not found: what the first image's markers tell
    if (
        board is not None
        and first_gray is not None
        and len(used) < MIN_PAIRS
        and not short  # boards seen, but too few corners in common: not the board's words
        and all(c is None for c in (*corners_l, *corners_r))
    ):
        board_hint = _charuco_hint(board, first_gray, first_name)
    elif (
        board is None
        and first_gray is not None
        and len(used) < MIN_PAIRS
        and all(c is None for c in (*corners_l, *corners_r))
        and (counted := _squares_counted(first_gray, pat)) is not None
    ):  # the squares counted (10x7) for the inner corners (9x6), the most common slip, or a
        # row of corners missed (9x5)
        (cols, rows), fewer = counted
        board_hint = (
            f"{first_name} shows a board of {cols}x{rows} inner corners: "
            + (
                "the pattern counts the points where four squares meet, one fewer each way than "
                "the squares"
                if fewer
                else "count the points where four squares meet along a row and along a column"
            )
            + f" (pattern=({cols}, {rows}))"
        )
    if board is not None and not board.resolved:
        squares = f"{board.squares[0]}x{board.squares[1]}"
        if board_hint:
            raise ValueError(f"the {squares} ChArUco board was not found: {board_hint}")
        if board.dictionary == "auto":
            raise ValueError(
                f"no image shows enough markers of the {squares} ChArUco board to tell its "
                "dictionary; give it (e.g. dictionary='DICT_5X5_100')"
            )
        # the dictionary was given: the layout of an even number of rows was what stayed unknown
        raise ValueError(
            f"no image shows the {squares} ChArUco board's {board.dictionary} markers well "
            "enough to tell its layout: check that the board has these squares and markers "
            "of that dictionary, or give the layout (legacy=True for OpenCV's pre-4.6 boards, "
            "legacy=False for later ones)"
        )
    if len(used) < MIN_PAIRS:
        raise ValueError(
            f"the {board_text} was found in both images of only {len(used)} of "
            f"{len(lefts)} pairs"
            + (f" ({len(repeats)} more repeat an earlier pair)" if repeats else "")
            + f"; at least {MIN_PAIRS} are needed"
            + (f"; {board_hint}" if board_hint else "")
            + (f" (rejected: {_rejected_words(rejected)})" if rejected else "")
        )

    gap = max(float(np.abs(corners_l[i] - corners_r[i]).max()) for i in used)  # type: ignore[operator]
    if gap < IDENTICAL_CORNERS_PX:
        raise ValueError(
            f"the left and right images look identical: the board is at the same pixels (within "
            f"{IDENTICAL_CORNERS_PX:g} px) in both images of all {len(used)} pairs; are they the "
            "same files, or one camera twice?"
        )
    obj_pts = board_object_points(pat, square)
    if distortion == "fisheye":
        unusable = _fisheye_unusable(
            [obj_pts[corner_ids[i]] for i in used],  # type: ignore[index]
            [corners_l[i] for i in used],  # type: ignore[misc]
            [corners_r[i] for i in used],  # type: ignore[misc]
            size,
        )
        for k in unusable:
            rejected[pair_names[used[k]]] = (
                "the fisheye solver cannot start from this view (too few corners, or too close "
                "to a line)"
            )
        used = [i for k, i in enumerate(used) if k not in set(unusable)]
        if len(used) < MIN_PAIRS:
            raise ValueError(
                f"only {len(used)} pairs can start the fisheye solver; at least {MIN_PAIRS} are "
                f"needed (rejected: {_rejected_words(rejected)})"
            )
    outliers: list[str] = []
    kept_why: dict[str, str] = {}  # outliers drop_outliers kept, and why
    for rnd in range(MAX_OUTLIER_ROUNDS + 1):
        obj = [obj_pts[corner_ids[i]] for i in used]  # type: ignore[index]
        pl = [corners_l[i].astype(np.float32) for i in used]  # type: ignore[union-attr]
        pr = [corners_r[i].astype(np.float32) for i in used]  # type: ignore[union-attr]
        sol = _solve(obj, pl, pr, size, distortion, refine, progress)
        pair_err = np.sqrt(np.mean(sol.per_view**2, axis=1))
        limit = max(OUTLIER_FACTOR * float(np.median(pair_err)), OUTLIER_MIN_PX)
        bad = [k for k, e in enumerate(pair_err) if e > limit]
        for k in bad:
            name = pair_names[used[k]]
            if name not in outliers:
                outliers.append(name)
        # no rounds left: the outliers are kept (dropping them now would leave `used` and
        # the solution's per-pair errors out of step)
        last = rnd == MAX_OUTLIER_ROUNDS
        if bad and drop_outliers and (last or len(used) - len(bad) < MIN_PAIRS):
            why = (
                f"still an outlier after {MAX_OUTLIER_ROUNDS} rounds of dropping"
                if last
                else f"dropping it would leave {len(used) - len(bad)} pairs, fewer than the "
                f"{MIN_PAIRS} needed"
            )
            kept_why = {pair_names[used[k]]: why for k in bad}
        if not bad or not drop_outliers or last or len(used) - len(bad) < MIN_PAIRS:
            break
        for k in bad:
            rejected[pair_names[used[k]]] = (
                # the figures of the solve the pair was in (the chart's limit is the final one's)
                f"outlier: error {pair_err[k]:.3f} px > {limit:.3f} px "
                f"({OUTLIER_FACTOR:g} x median, at least {OUTLIER_MIN_PX:g} px) in the solve "
                "that included it"
            )
        used = [i for k, i in enumerate(used) if k not in set(bad)]
    # before the pairing check and the rectification: a focal length the views cannot fix
    # gave a garbage rig, refused there in words about R and T, or kept without a word
    tilt = (
        f"the boards' planes are at most {sol.tilt_spread:.1f} degrees apart over the "
        f"{len(used)} pairs: held at nearly one tilt (only moved, or brought nearer), the board "
        "does not fix the focal length (nor the baseline); tilt it by 20-45 degrees, left and "
        "right, up and down, between views"
    )
    if sol.tilt_spread < MIN_TILT_SPREAD_DEG:
        raise ValueError(f"{tilt} (at least {MIN_TILT_SPREAD_DEG:g} degrees apart are needed)")
    if sol.tilt_spread < TILT_SPREAD_WARN_DEG:
        _warn(
            notes,
            f"{tilt}: the focal length and baseline may be several % off "
            f"({TILT_SPREAD_WARN_DEG:g} degrees or more apart advised)",
            UserWarning,
        )
    if board is None and not _shows_one_rig(sol):
        # A camera mounted upside down shows the board turned half round: the right corners
        # were put in the left ones' image order, the opposite corners, and every pair looked
        # mis-paired (35.7 px stereo RMS on OpenCV's pairs, the right images turned).
        half_turn = _grid_symmetries(pat)[1]
        turned = _solve(obj, pl, [p[half_turn] for p in pr], size, sol.model, False)
        if _shows_one_rig(turned):
            # Which one: the turned solution's T is that of the cameras as they stand. The right
            # one upside down puts the left camera at +x in its frame (T's x > 0); the left one
            # upside down puts the right camera at -x in its own (T's x < 0, as in a sound rig),
            # where turning the right images, as was said, gave a rig refused as swapped (OpenCV's
            # pairs, left images turned). A vertical rig's sign is no one's convention: not said.
            tt = np.ravel(turned.T)
            side = "right" if tt[0] > 0 else "left"
            which = (
                f"the {side} camera is mounted upside down against the other; turn the {side} "
                "images"
                if abs(tt[0]) > abs(tt[1])
                else "one camera is mounted upside down against the other; turn its images"
            )
            raise ValueError(
                f"stereo RMS {sol.rms:.1f} px, {turned.rms:.2f} px with the right boards read "
                f"turned half round: {which} by 180 degrees (or the camera) and calibrate again"
            )
    _check_pairing(
        sol, [pair_names[i] for i in used], [d for d in differ if d not in rejected], drop_outliers
    )
    folded = [
        side
        for side, K, D in (("left", sol.K1, sol.D1), ("right", sol.K2, sol.D2))
        if not (_fisheye_is_monotonic if sol.model == "fisheye" else _radial_is_monotonic)(
            K, D, size
        )
    ]
    if folded:
        _warn(
            notes,
            f"the {sol.model} distortion model of the {' and '.join(folded)} camera"
            f"{'s' if len(folded) == 2 else ''} is not "
            "monotonic over the image: it folds the outer part of the image back inward, and the "
            "rectified images lose or repeat it; "
            + (
                # auto chose it (too few views to compare, or the joint refinement moved it)
                "add views with the board near the image corners, or calibrate with a simpler "
                "model (distortion='k1k2')"
                if distortion == "auto"
                # a true fisheye needs its model: its fold comes from the board missing the rim
                else "if the lens is a fisheye, add views with the board near the image corners; "
                "if not, calibrate with distortion='auto'"
                if sol.model == "fisheye"
                else "calibrate with distortion='auto' (or a simpler model), or add views with "
                "the board near the image corners"
            ),
            UserWarning,
        )
    if sol.model != "fisheye" and max(sol.rms_left, sol.rms_right) > FISHEYE_HINT_MIN_RMS_PX:
        fish = _fisheye_mono_rms(
            [obj_pts[corner_ids[i]] for i in used],  # type: ignore[index]
            [corners_l[i] for i in used],  # type: ignore[misc]
            [corners_r[i] for i in used],  # type: ignore[misc]
            size,
        )
        if fish is not None and all(
            f * FISHEYE_HINT_GAIN < p
            for f, p in zip(fish, (sol.rms_left, sol.rms_right), strict=True)
        ):
            _warn(
                notes,
                f"the {sol.model} model fits these views with {sol.rms_left:.3f} / "
                f"{sol.rms_right:.3f} px (left / right), the fisheye model with {fish[0]:.3f} / "
                f"{fish[1]:.3f} px: a wide-angle lens; calibrate with distortion='fisheye'",
                UserWarning,
            )

    t = np.ravel(sol.T)
    if t[0] > 0 and abs(t[0]) > abs(t[1]):
        # OpenCV's T is (-B, 0, 0) for a right camera on the right; rectifying would fail later
        # with a message about T's sign.
        raise ValueError(
            f"the right images' camera sits to the left of the left images' camera (T = "
            f"({t[0]:+.4g}, {t[1]:+.4g}, {t[2]:+.4g}) {unit}): left and right look swapped"
        )
    cal = Calibration(
        K1=sol.K1, D1=sol.D1, K2=sol.K2, D2=sol.D2, R=sol.R, T=sol.T, image_size=size, unit=unit,
        model="fisheye" if sol.model == "fisheye" else "pinhole",
    )  # fmt: skip
    used_l: list[F64] = []
    used_r: list[F64] = []
    used_ids: list[npt.NDArray[np.int64]] = []
    for i in used:
        cl, cr, ix = corners_l[i], corners_r[i], corner_ids[i]
        assert cl is not None and cr is not None and ix is not None
        used_l.append(cl)
        used_r.append(cr)
        used_ids.append(ix)
    mean_dy, max_dy, side_med, side_std = _rectified_checks(cal, used_l, used_r, pat, used_ids)
    cov_l = _coverage_mask(used_l, pat, size)
    cov_r = _coverage_mask(used_r, pat, size)
    names_used = [pair_names[i] for i in used]
    if sample is not None and sample[0] not in used:
        # the report's rectified pair was an outlier dropped (or a view the fisheye solver
        # could not start from): its misaligned rows looked like the calibration's failure
        first = used[0]
        sample = (first, _load_gray(lefts[first], "")[0], _load_gray(rights[first], "")[0])
    report = CalibrationReport(
        rms=sol.rms,
        rms_left=sol.rms_left,
        rms_right=sol.rms_right,
        per_pair_errors={
            n: float(math.sqrt(np.mean(e**2)))
            for n, e in zip(names_used, sol.per_view, strict=True)
        },
        per_pair_errors_left={
            n: float(e[0]) for n, e in zip(names_used, sol.per_view, strict=True)
        },
        per_pair_errors_right={
            n: float(e[1]) for n, e in zip(names_used, sol.per_view, strict=True)
        },
        used_pairs=names_used,
        rejected_pairs=rejected,
        outlier_pairs=outliers,
        epipolar_mean_dy=mean_dy,
        epipolar_max_dy=max_dy,
        square_size=square,
        square_size_measured=side_med,
        square_size_std=side_std,
        coverage_left=float(np.mean(cov_l > 0)),
        coverage_right=float(np.mean(cov_r > 0)),
        distortion_model=sol.model,
        model_selection=sol.model_selection,
        refined=sol.refined,
        pattern=pat,
        image_size=size,
        unit=unit,
        baseline=float(np.linalg.norm(sol.T)),
        focal_left=float(sol.K1[0, 0]),
        focal_right=float(sol.K2[0, 0]),
        board=board_text,
        corners_used=sum(len(ix) for ix in used_ids),
        warnings=notes,
        stereo_rms_left=_weighted_rms(sol.per_view[:, 0], [len(ix) for ix in used_ids]),
        stereo_rms_right=_weighted_rms(sol.per_view[:, 1], [len(ix) for ix in used_ids]),
        _calibration=cal,
        _corners={pair_names[i]: (corners_l[i], corners_r[i]) for i in used},  # type: ignore[misc]
        _ids={pair_names[i]: corner_ids[i] for i in used},  # type: ignore[misc]
        _sample=None if sample is None else (pair_names[sample[0]], sample[1], sample[2]),
        _kept_why=kept_why,
    )
    return cal, report


def _board_setup(
    pattern: tuple[int, int] | str,
    square_size: float | None,
    board: CharucoBoard | None,
    unit: str,
    distortion: str,
) -> tuple[tuple[int, int], float, str]:
    """:func:`calibrate`'s checks of its board, square, unit and distortion model.

    Returns
    -------
    tuple
        The inner corners ``(cols, rows)``, the square side and the unit (a plain str).

    Raises
    ------
    TypeError, ValueError
        As :func:`calibrate` says of these arguments.
    """
    from stereovision._validate import known_unit, positive_finite
    from stereovision.calibration import UNIT_TO_METRES

    if board is not None:
        _check_board(board)
        if square_size is not None and positive_finite(square_size, "square_size") != float(
            board.square_size
        ):
            raise ValueError(
                f"square_size: {square_size:g} differs from the board's {board.square_size:g}; "
                "give the size once, in the board"
            )
        pat = board.inner
        square = float(board.square_size)
    else:
        pat = parse_pattern(pattern)
        if square_size is None:
            raise ValueError("square_size: required for a chessboard (the side of one square)")
        square = positive_finite(square_size, "square_size")
    unit = known_unit(unit, UNIT_TO_METRES)
    # The board's corners are float32 for OpenCV: 1e308 overflowed them into inf and the solver
    # failed an assertion. No printed or built board has squares outside these bounds.
    metres = square * UNIT_TO_METRES[unit]
    if not 1e-9 <= metres <= 100.0:
        raise ValueError(
            f"square_size: {square:g} {unit} is {metres:g} m; expected a board square between "
            "1 nm and 100 m"
        )
    if distortion not in ("auto", "fisheye") and distortion not in DISTORTION_MODELS:
        raise ValueError(
            f"distortion: expected 'auto', 'fisheye' or one of {list(DISTORTION_MODELS)}, got "
            f"{distortion!r}"
        )
    return pat, square, unit


def _check_calibrate_args(
    caller: str,
    pattern: tuple[int, int] | str,
    square_size: float | None,
    board: CharucoBoard | None,
    kwargs: dict[str, Any],
) -> None:
    """The arguments a recording's frames are given to :func:`calibrate` with, checked before
    the recording is opened: a square_size left out, a unit or a distortion model mistyped (or
    a keyword calibrate does not take) was refused by calibrate once every frame was read, the
    board waved in front of live cameras for nothing."""
    import inspect

    params = inspect.signature(calibrate).parameters
    ours = {"left_images", "right_images", "pattern", "square_size", "board", "names"}
    for key in kwargs:
        if key not in params or key in ours:  # names: the frames are named frame_NNNNN
            raise TypeError(f"{caller}() got an unexpected keyword argument {key!r}")
    unit, distortion = (kwargs.get(k, params[k].default) for k in ("unit", "distortion"))
    _board_setup(pattern, square_size, board, unit, distortion)
    _check_progress(kwargs.get("progress"))


def _check_progress(progress: object) -> None:
    """Refuse a ``progress`` that cannot be called: it was "'int' object is not callable",
    naming no parameter, after the first pair's board search (a recording's first frame)."""
    if progress is not None and not callable(progress):
        from stereovision._validate import _shown

        raise TypeError(
            "progress: expected a callable progress(stage, done, total), or None, got "
            f"{_shown(progress)}"
        )


def _weighted_rms(per_view: npt.ArrayLike, counts: Sequence[int]) -> float:
    """The RMS over all points of views whose own RMS are ``per_view``, ``counts`` points each.

    Parameters
    ----------
    per_view : array_like
        Each view's RMS (px).
    counts : sequence of int
        Each view's number of points.

    Returns
    -------
    float
        ``sqrt(sum(n_i e_i^2) / sum(n_i))``.
    """
    e = np.asarray(per_view, np.float64)
    n = np.asarray(counts, np.float64)
    return float(math.sqrt(np.sum(n * e**2) / np.sum(n)))


def calibrate_from_video(
    left: PathLike | int,
    right: PathLike | int,
    *,
    pattern: tuple[int, int] | str = (9, 6),
    square_size: float | None = None,
    board: CharucoBoard | None = None,
    max_pairs: int = MAX_VIDEO_PAIRS,
    min_distance: float | None = None,
    log: Any = None,
    read_timeout: float | None = DEFAULT_READ_TIMEOUT,
    **kwargs: Any,
) -> tuple[Calibration, CalibrationReport]:
    """Calibrate from two recordings of the board waved about (or two live cameras).

    The pairs are read as ``stereovision capture`` reads them, and a pair is kept when both
    cameras see the board and its pose differs from every pair kept so far
    (:class:`~stereovision.capture.ChessboardCollector`, ROS's rule), up to ``max_pairs``; the
    kept pairs are then calibrated by :func:`calibrate`.

    Parameters
    ----------
    left, right : str or int
        Video files, image-sequence patterns (``frames/left_%03d.png``) or device indices.
    pattern, square_size, board :
        The board, as for :func:`calibrate`.
    max_pairs : int
        Stop reading once this many distinct poses are kept.
    min_distance : float, optional
        The collector's pose distance (default :data:`stereovision.capture.MIN_POSE_DISTANCE`).
    log : callable, optional
        Receives one line when the reading is done.
    read_timeout : float or None
        Seconds a camera's open or a pair's read may take (:data:`DEFAULT_READ_TIMEOUT`, 10;
        None: no limit), as :func:`stereovision.capture.capture`'s: a hung camera (a wedged
        USB device, a stalled stream) is given up with a
        :class:`~stereovision.capture.SourceError` naming it.
    **kwargs
        Passed to :func:`calibrate` (``unit``, ``distortion``, ``drop_outliers``, ...); its
        ``progress`` also hears the reading, stage :data:`PROGRESS_FRAMES` after each frame pair
        read (``total`` the pairs the recording announces, 0 when it announces none, a camera,
        or once more were read than it announced: ``done`` never passes a nonzero ``total``).

    Returns
    -------
    calibration, report
        As :func:`calibrate`; the pairs are named ``frame_NNNNN`` by their index in the videos.

    Raises
    ------
    FileNotFoundError
        If a video file does not exist (the message names the side).
    SourceError
        If a source cannot be opened, or does not open or deliver a pair within
        ``read_timeout`` s (:class:`stereovision.capture.SourceError`, an OSError).
    TypeError
        If ``board`` is given and is not a :class:`~stereovision.charuco.CharucoBoard`, a
        keyword is not one of :func:`calibrate`'s (``names`` included: the frames name the
        pairs), or ``progress`` cannot be called, before a camera is opened.
    ValueError
        As :func:`calibrate` (too few distinct poses with the board in both views, ...), or for
        a ``max_pairs`` below :data:`MIN_PAIRS`, a ``min_distance`` that is not a finite number
        of 0 or more, or a ``read_timeout`` that is not a positive number of seconds (or None),
        each before a camera is opened, as are calibrate's checks of ``pattern``,
        ``square_size`` (required for a chessboard), ``unit`` and ``distortion``.
    """
    from stereovision.capture import StereoCamera, check_min_distance, check_read_timeout

    # a pattern string '10x7' as board was AttributeError "'str' object has no attribute
    # 'inner'", after the cameras were opened
    _check_board(board)
    max_pairs = _check_max_pairs(max_pairs)
    if min_distance is not None:  # as board: a negative one was refused once both were open
        check_min_distance(min_distance)
    check_read_timeout(read_timeout)
    # a square_size left out (a unit mistyped) was refused once the whole recording was read
    _check_calibrate_args("calibrate_from_video", pattern, square_size, board, kwargs)

    # as given: StereoCamera takes paths and indexes (a str() made np.int64(1) the file "1")
    cam = StereoCamera(left, right, open_timeout=read_timeout)
    return _calibrate_from_camera(
        cam,
        pattern=pattern,
        square_size=square_size,
        board=board,
        max_pairs=max_pairs,
        min_distance=min_distance,
        log=log,
        read_timeout=read_timeout,
        **kwargs,
    )


def calibrate_from_bag(
    path: PathLike,
    *,
    left_topic: str | None = None,
    right_topic: str | None = None,
    max_skew_ms: float | None = None,
    pattern: tuple[int, int] | str = (9, 6),
    square_size: float | None = None,
    board: CharucoBoard | None = None,
    max_pairs: int = MAX_VIDEO_PAIRS,
    min_distance: float | None = None,
    log: Any = None,
    **kwargs: Any,
) -> tuple[Calibration, CalibrationReport]:
    """Calibrate from a ROS 1 or ROS 2 bag of the board waved in front of the rig.

    The pairs are read by :class:`~stereovision.rosbag.BagCamera` (topics found or given, pairs
    matched on their stamps) and kept as :func:`calibrate_from_video` keeps them.

    Parameters
    ----------
    path : str or os.PathLike
        The bag (a ROS 1 ``.bag`` file or a ROS 2 bag folder).
    left_topic, right_topic, max_skew_ms :
        As :class:`~stereovision.rosbag.BagCamera`.
    pattern, square_size, board, max_pairs, min_distance, log, **kwargs :
        As :func:`calibrate_from_video`.

    Returns
    -------
    calibration, report
        As :func:`calibrate`; the pairs are named ``frame_NNNNN`` by their index in the bag.

    Raises
    ------
    FileNotFoundError
        If the bag does not exist.
    TypeError
        If ``board`` is given and is not a :class:`~stereovision.charuco.CharucoBoard`, a
        keyword is not one of :func:`calibrate`'s, or ``progress`` cannot be called, before
        the bag is opened.
    ValueError
        As :class:`~stereovision.rosbag.BagCamera` and :func:`calibrate` (its checks of
        ``pattern``, ``square_size``, ``unit`` and ``distortion`` before the bag is opened).
    """
    from stereovision.capture import check_min_distance
    from stereovision.rosbag import BagCamera

    _check_board(board)  # '10x7' was AttributeError "'str' object has no attribute 'inner'"
    max_pairs = _check_max_pairs(max_pairs)
    if min_distance is not None:  # before the bag is read, as board
        check_min_distance(min_distance)
    # a square_size left out (a unit mistyped) was refused once the whole bag was read
    _check_calibrate_args("calibrate_from_bag", pattern, square_size, board, kwargs)
    cam = BagCamera(path, left_topic=left_topic, right_topic=right_topic, max_skew_ms=max_skew_ms)
    return _calibrate_from_camera(
        cam,
        pattern=pattern,
        square_size=square_size,
        board=board,
        max_pairs=max_pairs,
        min_distance=min_distance,
        log=log,
        **kwargs,
    )


def _check_board(board: object) -> None:
    """A TypeError naming ``board`` when it is given and is no ChArUco board (the charuco
    functions' check: a pattern string '10x7' was ValueError here, TypeError there)."""
    if board is not None:
        _require_board(board)


def _check_max_pairs(max_pairs: object) -> int:
    """``max_pairs`` as an int of at least :data:`MIN_PAIRS`, by a count's rule
    (:func:`~stereovision._validate.whole_value`: np.int64(40) read from an array was refused)."""
    whole = whole_value(max_pairs)
    if whole is None or whole < MIN_PAIRS:
        raise ValueError(
            f"max_pairs: expected an integer of at least {MIN_PAIRS}, got {max_pairs!r}"
        )
    return whole


def _calibrate_from_camera(
    cam: Any,
    *,
    pattern: tuple[int, int] | str,
    square_size: float | None,
    board: CharucoBoard | None,
    max_pairs: int,
    min_distance: float | None,
    log: Any,
    read_timeout: float | None = None,
    **kwargs: Any,
) -> tuple[Calibration, CalibrationReport]:
    """Keep the distinct board poses a camera (or recording) shows, then :func:`calibrate`;
    the camera is closed. A read taking over ``read_timeout`` s raises
    (:func:`~stereovision.capture.read_within`; None: no limit, a bag's)."""
    from stereovision.capture import (
        MIN_POSE_DISTANCE,
        ChessboardCollector,
        SourceError,
        _frames_announced,
        read_within,
    )

    lefts: list[np.ndarray] = []
    rights: list[np.ndarray] = []
    names: list[str] = []
    read = 0
    last = ""  # the last frame read
    progress = kwargs.get("progress")
    # a few hundred frames of a recording are read before calibrate's own stages: said too
    total = _frames_announced(cam) if progress is not None else 0
    try:
        pat = board.inner if board is not None else parse_pattern(pattern)
        # as given: the collector names a min_distance that is no number (a float() here said
        # "could not convert string to float: 'abc'")
        collector = ChessboardCollector(
            pat, MIN_POSE_DISTANCE if min_distance is None else min_distance, board=board
        )
        while len(lefts) < max_pairs:
            try:
                frame = read_within(cam, read_timeout)
            except SourceError as exc:
                if not getattr(exc, "end", True):
                    raise  # a frame that does not decode or of another shape: not an end
                break  # the end of a recording
            read += 1
            last = f"frame_{frame.index:05d}"
            if collector.consider(frame).save:
                lefts.append(frame.left)
                rights.append(frame.right)
                names.append(last)
            if progress is not None:
                # CAP_PROP_FRAME_COUNT is the container's guess: past it, the total is unknown
                progress(PROGRESS_FRAMES, read, total if read <= total else 0)
    finally:
        cam.close()
    what = board.describe() if board is not None else f"chessboard {pat[0]}x{pat[1]} inner corners"
    if not lefts:
        raise ValueError(
            f"no frame pair of the {read} read shows the {what} in both views"
            + (" (none read: an empty recording)" if read == 0 else "")
        )
    # The limit reached, the rest of the recording was not read: said, and kept in the report.
    selection: dict[str, Any] = {}
    if len(lefts) >= max_pairs:
        selection = {
            "option": f"max_pairs={max_pairs}",
            "rule": f"the first {max_pairs} distinct board poses in the recording's order; what "
            f"follows {last} was not read",
            "frames_read": read,
            "kept": len(lefts),
            "last_frame_read": last,
        }
    if log is not None:
        # The live detector's quick look; calibrate's own detector then has the last word.
        log(f"{len(lefts)} of {read} frame pairs kept (a quick look saw the board in both views, "
            "in a new pose)"
            + (f"; max_pairs={max_pairs} reached: what follows {last} was not read"
               if selection else ""))  # fmt: skip
    if board is not None and collector.board is not None and collector.board.resolved:
        board = collector.board  # the dictionary found while reading
    cal, rep = calibrate(
        lefts, rights, pattern=pattern, square_size=square_size, board=board, names=names, **kwargs
    )
    rep.pair_selection = selection
    return cal, rep


# ---------------------------------------------------------------------------------- pictures

_BLUE = (200, 120, 40)
_ORANGE = (40, 140, 240)
_RED = (40, 40, 220)
_GREY = (150, 150, 150)
_BLACK = (0, 0, 0)
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def _png_b64(img: np.ndarray) -> str:
    ok, buf = cv2.imencode(".png", img)
    if not ok:
        raise ValueError("could not encode a report picture as PNG")
    return base64.b64encode(buf.tobytes()).decode("ascii")


def _text(
    img: np.ndarray, s: str, org: tuple[int, int], scale: float = 0.45, color: Any = _BLACK
) -> None:
    cv2.putText(img, cv2_text(s), org, _FONT, scale, color, 1, cv2.LINE_AA)


def _label(
    img: np.ndarray,
    s: str,
    org: tuple[int, int],
    scale: float,
    color: Any,
    background: Any = (255, 255, 255),
) -> tuple[int, int, int, int]:
    """``s`` at ``org`` (its baseline's left end) on a ``background`` box, so that bars and lines
    under it cannot hide it; returns the box ``(x0, y0, x1, y1)``, ends included."""
    s = cv2_text(s)
    (tw, th), base = cv2.getTextSize(s, _FONT, scale, 1)
    x0, y0 = max(org[0] - 2, 0), max(org[1] - th - 2, 0)
    x1 = min(org[0] + tw + 2, img.shape[1] - 1)
    y1 = min(org[1] + base, img.shape[0] - 1)
    cv2.rectangle(img, (x0, y0), (x1, y1), background, -1)
    _text(img, s, org, scale, color)
    return x0, y0, x1, y1


def _nice_ticks(vmax: float, most: int = 6) -> list[float]:
    """Round tick values ``0, step, 2 step, ... <= vmax`` with ``step`` 1, 2 or 5 x 10^k and at most
    ``most`` ticks (the chart's axis read 0.00, 0.16, 0.31, 0.47, 0.63)."""
    if not vmax > 0:
        return [0.0]
    raw = vmax / (most - 1)
    mag = 10.0 ** np.floor(np.log10(raw))
    step = next(m * mag for m in (1, 2, 5, 10) if m * mag >= raw - 1e-12 * mag)
    n = int(np.floor(vmax / step + 1e-9))
    return [float(round(k * step, 12)) for k in range(n + 1)]


def _error_chart(rep: CalibrationReport) -> np.ndarray:
    """Bar chart of each used pair's left/right RMS, median and outlier threshold."""
    names = rep.used_pairs
    h, top, bottom, left_m = 360, 30, 110, 60
    w = FIGURE_WIDTH
    img = np.full((h, w, 3), 255, np.uint8)
    el = np.array([rep.per_pair_errors_left[n] for n in names])
    er = np.array([rep.per_pair_errors_right[n] for n in names])
    pair = np.array([rep.per_pair_errors[n] for n in names])
    med = float(np.median(pair))
    limit = max(OUTLIER_FACTOR * med, OUTLIER_MIN_PX)
    vmax = max(float(max(el.max(), er.max())), limit) * 1.1
    plot_h = h - top - bottom

    def ypix(v: float) -> int:
        return round(top + plot_h * (1 - v / vmax))

    slot = (w - left_m - 20) / max(1, len(names))
    bw = max(2, int(slot * 0.35))
    cv2.line(img, (left_m, top), (left_m, top + plot_h), _BLACK, 1)
    cv2.line(img, (left_m, top + plot_h), (w - 20, top + plot_h), _BLACK, 1)
    for t in _nice_ticks(vmax):
        y = ypix(t)
        cv2.line(img, (left_m - 4, y), (left_m, y), _BLACK, 1)
        _text(img, f"{t:.2f}", (5, y + 4), 0.4)
    for k, n in enumerate(names):
        x0 = int(left_m + k * slot + slot * 0.12)
        color_l = _RED if n in rep.outlier_pairs else _BLUE
        color_r = _RED if n in rep.outlier_pairs else _ORANGE
        cv2.rectangle(img, (x0, ypix(el[k])), (x0 + bw, top + plot_h), color_l, -1)
        cv2.rectangle(img, (x0 + bw, ypix(er[k])), (x0 + 2 * bw, top + plot_h), color_r, -1)
        label = cv2_text(n.split(" / ")[0])  # the left file's name: both do not fit the axis
        label = label if len(label) <= 16 else label[:15] + "~"
        (tw, th), _ = cv2.getTextSize(label, _FONT, 0.4, 1)
        tag = np.full((th + 6, tw + 4, 3), 255, np.uint8)
        _text(tag, label, (2, th + 2), 0.4)
        tag = np.asarray(cv2.rotate(tag, cv2.ROTATE_90_COUNTERCLOCKWISE), np.uint8)
        xt = x0 + bw - tag.shape[1] // 2
        yt = top + plot_h + 4
        hh = min(tag.shape[0], h - yt)
        ww = min(tag.shape[1], w - max(xt, 0))
        if xt >= 0 and hh > 0 and ww > 0:
            img[yt : yt + hh, xt : xt + ww] = np.minimum(
                img[yt : yt + hh, xt : xt + ww], tag[:hh, :ww]
            )
    for v, color, label in ((med, _GREY, "median"), (limit, _RED, "outlier limit")):
        y = ypix(v)
        for x in range(left_m, w - 20, 12):
            cv2.line(img, (x, y), (min(x + 6, w - 20), y), color, 1)
        _label(img, f"{label} {v:.3f} px", (w - 200, y - 4), 0.4, color)
    title = "per-pair RMS reprojection error (px): left"
    _text(img, title, (left_m + 5, 18), 0.5, _BLUE)
    (tw, _), _ = cv2.getTextSize(title + " ", _FONT, 0.5, 1)
    _text(img, "right", (left_m + 5 + tw, 18), 0.5, _ORANGE)
    return img


def _coverage_picture(rep: CalibrationReport) -> np.ndarray:
    """Heat map of how many boards cover each pixel, left and right, with the corners."""
    w, h = rep.image_size
    panels = []
    for side in (0, 1):
        sets = [c[side] for c in rep._corners.values()]
        count = _coverage_mask(sets, rep.pattern, rep.image_size).astype(np.float32)
        count = np.asarray(cv2.resize(count, (w, h), interpolation=cv2.INTER_NEAREST))
        top = max(1.0, float(count.max()))
        heat = cv2.applyColorMap(
            np.clip(count / top * 255, 0, 255).astype(np.uint8), cv2.COLORMAP_VIRIDIS
        )
        heat[count == 0] = (40, 40, 40)
        if rep._sample is not None:
            base = cv2.cvtColor(np.asarray(rep._sample[1 + side]), cv2.COLOR_GRAY2BGR)
            heat = cv2.addWeighted(heat, 0.75, base, 0.25, 0)
        for c in sets:
            for x, y in c:
                cv2.circle(heat, (round(x), round(y)), 2, (255, 255, 255), -1, cv2.LINE_AA)
        cov = rep.coverage_left if side == 0 else rep.coverage_right
        _text(
            heat,
            f"{'left' if side == 0 else 'right'}: {100 * cov:.0f} % covered, max {int(top)} boards",
            (8, 22),
            0.6,
            (255, 255, 255),
        )
        panels.append(heat)
    out = np.hstack(panels)
    return _fit_width(out)


def _fit_width(img: np.ndarray) -> np.ndarray:
    if img.shape[1] <= FIGURE_WIDTH:
        return img
    s = FIGURE_WIDTH / img.shape[1]
    return cv2.resize(img, (FIGURE_WIDTH, round(img.shape[0] * s)), interpolation=cv2.INTER_AREA)


def _rectified_picture(rep: CalibrationReport) -> np.ndarray | None:
    """The sample pair rectified side by side, with horizontal epipolar lines (a vertical rig's,
    which OpenCV aligns by columns, one above the other with vertical lines)."""
    if rep._sample is None or rep._calibration is None:
        return None
    cal = rep._calibration
    # not cal.rectify, which refuses a vertical rig: its report shows it as OpenCV rectifies it
    rl, rr = cal._remap_pair(rep._sample[1], rep._sample[2], 0.0)
    across = _across_baseline(cal._stereo_rectify(0.0)[3])
    pair = (np.hstack if across else np.vstack)(
        [cv2.cvtColor(im, cv2.COLOR_GRAY2BGR) for im in (rl, rr)]
    )
    h, w = pair.shape[:2]
    along = h if across else w
    step = max(8, along // 16)
    colors = [(0, 0, 255), (0, 200, 0), (255, 0, 0), (0, 200, 255)]
    for k, v in enumerate(range(step // 2, along, step)):
        a, b = ((0, v), (w - 1, v)) if across else ((v, 0), (v, h - 1))
        cv2.line(pair, a, b, colors[k % len(colors)], 1, cv2.LINE_AA)
    _label(pair, f"rectified pair {rep._sample[0]}", (8, 22), 0.6, (0, 0, 255))
    return _fit_width(pair)


def _rig_picture(rep: CalibrationReport) -> np.ndarray | None:
    """Top view (X right, Z forward) of both cameras and the board positions."""
    cal = rep._calibration
    if cal is None:
        return None
    Rm = np.asarray(cal.R)
    T = np.asarray(cal.T)
    c_right = -Rm.T @ T  # right camera centre in left coordinates
    axis_right = Rm.T @ np.array([0.0, 0.0, 1.0])
    # Board corners in the left camera frame (each view's pose from its corners).
    centres = []
    grid = board_object_points(rep.pattern, rep.square_size).astype(np.float64)
    for name, (cl, _) in rep._corners.items():
        ids = rep._ids.get(name)
        obj = grid if ids is None else grid[ids]
        if cal.model == "fisheye":  # the pose from the corners undistorted by the lens model
            und = cv2.fisheye.undistortPoints(cl.reshape(-1, 1, 2), cal.K1, cal.D1)
            ok, rvec, tvec = cv2.solvePnP(
                obj, und.reshape(-1, 2), np.eye(3), None, flags=cv2.SOLVEPNP_IPPE
            )
        else:
            ok, rvec, tvec = cv2.solvePnP(obj, cl, cal.K1, cal.D1, flags=cv2.SOLVEPNP_IPPE)
        if ok:
            Rb, _ = cv2.Rodrigues(rvec)
            pts = (Rb @ obj.T).T + tvec.ravel()
            centres.append(pts)
    w, h = FIGURE_WIDTH, 420
    img = np.full((h, w, 3), 255, np.uint8)
    xs = (
        [0.0, float(c_right[0])]
        + [float(p[:, 0].min()) for p in centres]
        + [float(p[:, 0].max()) for p in centres]
    )
    zs = [0.0, float(c_right[2])] + [float(p[:, 2].max()) for p in centres]
    base = max(float(np.linalg.norm(T)), 1e-9)
    xmin, xmax = min(xs) - base, max(xs) + base
    zmin, zmax = min(zs) - base, max(zs) + base * 0.5
    s = min((w - 80) / (xmax - xmin), (h - 80) / (zmax - zmin))

    def px(x: float, z: float) -> tuple[int, int]:
        return round(40 + (x - xmin) * s), round(h - 40 - (z - zmin) * s)

    for pts in centres:  # each board's outline seen from above
        top = np.array([px(p[0], p[2]) for p in pts], np.int32)
        hull = cv2.convexHull(top.reshape(-1, 1, 2))
        cv2.polylines(img, [hull], True, _GREY, 1, cv2.LINE_AA)
    fov = base * 0.8
    for c, ax, color, name in (
        (np.zeros(3), np.array([0.0, 0.0, 1.0]), _BLUE, "L"),
        (c_right, axis_right, _ORANGE, "R"),
    ):
        p0 = px(c[0], c[2])
        tip = c + ax * fov
        cv2.arrowedLine(img, p0, px(tip[0], tip[2]), color, 2, cv2.LINE_AA, tipLength=0.15)
        cv2.circle(img, p0, 6, color, -1, cv2.LINE_AA)
        _text(img, name, (p0[0] - 5, p0[1] + 22), 0.6, color)
    rvec, _ = cv2.Rodrigues(Rm)
    ang = math.degrees(float(np.linalg.norm(rvec)))
    _text(
        img, f"top view (X right, Z forward), unit {rep.unit}; grey: board positions", (10, 20), 0.5
    )
    _text(
        img,
        f"baseline |T| = {rep.baseline:.5g} {rep.unit}, "
        f"T = ({T[0]:.4g}, {T[1]:.4g}, {T[2]:.4g}), rotation {ang:.3f} deg",
        (10, 42),
        0.5,
    )
    return img


def _html_table(rows: Sequence[Sequence[str]], header: Sequence[str]) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


_PAIR_COLUMNS = ("pair", "left RMS (px)", "right RMS (px)", "pair RMS (px)", "status")


def _render_html(rep: CalibrationReport) -> str:
    """The self-contained HTML page (pictures as data: URIs, no external resources)."""
    u = rep.unit
    key = [
        (
            "stereo RMS",
            f"{rep.rms:.3f} px (left camera {rep.stereo_rms_left:.3f} px, right camera "
            f"{rep.stereo_rms_right:.3f} px)",
        ),
        ("left camera RMS, calibrated alone", f"{rep.rms_left:.3f} px"),
        ("right camera RMS, calibrated alone", f"{rep.rms_right:.3f} px"),
        (
            "pairs used",
            f"{len(rep.used_pairs)} of {len(rep.used_pairs) + len(rep.rejected_pairs)}"
            + (
                ""
                if not (sel := rep.pair_selection)
                else f" ({sel['left_out_count']} more of the {sel['given']} given left out by "
                f"{sel['option']})"
                if "left_out" in sel
                else f" (reading stopped by {sel['option']}: {sel['rule']})"
            ),
        ),
        (f"rectified {_epipolar_label(rep)} mean", f"{rep.epipolar_mean_dy:.3f} px"),
        (f"rectified {_epipolar_label(rep)} max", f"{rep.epipolar_max_dy:.3f} px"),
        (
            "triangulated square sides",
            f"spread {100 * rep.square_size_std / rep.square_size:.2f} % (std "
            f"{rep.square_size_std:.3g} {u}; median {rep.square_size_measured:.5g} {u}, in the "
            f"scale of the given {rep.square_size:.5g} {u} square: not a check of it)",
        ),
        ("baseline", f"{rep.baseline:.5g} {u}"),
        ("focal length", f"{rep.focal_left:.2f} px (left), {rep.focal_right:.2f} px (right)"),
        (
            "coverage",
            f"{100 * rep.coverage_left:.0f} % (left), {100 * rep.coverage_right:.0f} % (right)",
        ),
        (
            "distortion model",
            rep.distortion_model
            + (
                ""
                if not rep.model_selection
                else " (leave-one-out RMS: "
                + ", ".join(f"{k} {v:.3f} px" for k, v in rep.model_selection.items())
                + ")"
            ),
        ),
        ("joint refinement", "kept" if rep.refined else "not used"),
        (
            "board / image",
            f"{rep.board}, {rep.corners_used} corners used, "
            f"{rep.image_size[0]}x{rep.image_size[1]} px",
        ),
    ]
    pairs = [
        (
            n,
            f"{rep.per_pair_errors_left[n]:.3f}",
            f"{rep.per_pair_errors_right[n]:.3f}",
            f"{rep.per_pair_errors[n]:.3f}",
            "outlier (kept)" if n in rep.outlier_pairs else "used",
        )
        for n in rep.used_pairs
    ]
    pairs += [(n, "", "", "", f"rejected: {r}") for n, r in rep.rejected_pairs.items()]
    sel = rep.pair_selection
    pairs += [
        (n, "", "", "", f"left out by {sel['option']} ({sel['rule']})")
        for n in sel.get("left_out", [])
    ]
    figures: list[tuple[str, np.ndarray | None]] = [
        ("Per-pair reprojection error", _error_chart(rep)),
        ("Corner coverage", _coverage_picture(rep)),
        ("Rectified pair with epipolar lines", _rectified_picture(rep)),
        ("Rig extrinsics", _rig_picture(rep)),
    ]
    fig_html = "".join(
        f'<figure><img alt="{html.escape(t)}" src="data:image/png;base64,{_png_b64(img)}">'
        f"<figcaption>{html.escape(t)}</figcaption></figure>"
        for t, img in figures
        if img is not None
    )
    cal = rep._calibration
    mats = ""
    if cal is not None:
        with np.printoptions(precision=6, suppress=True):
            # T is in the board's unit (the square size's), the rest unitless or pixels
            heads = {"K1": "K1 (px)", "K2": "K2 (px)", "T": f"T ({html.escape(cal.unit)})"}
            mats = "".join(
                f"<h3>{heads.get(k, k)}</h3>"
                f"<pre>{html.escape(str(np.asarray(getattr(cal, k))))}</pre>"
                for k in ("K1", "D1", "K2", "D2", "R", "T")
            )
    style = (
        "body{font-family:sans-serif;margin:2em;max-width:1000px}"
        "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 8px;"
        "text-align:left}figure{margin:1.5em 0}img{max-width:100%;border:1px solid #ddd}"
        "pre{background:#f6f6f6;padding:6px}"
    )
    return (
        '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
        f"<title>Stereo calibration report</title><style>{style}</style></head><body>"
        "<h1>Stereo calibration report</h1>"
        + (
            "<h2>Warnings</h2><ul>"
            + "".join(f"<li>{html.escape(w)}</li>" for w in rep.warnings)
            + "</ul>"
            if rep.warnings
            else ""
        )
        + f"<h2>Key figures</h2>{_html_table(key, ('figure', 'value'))}"
        f"<h2>Pairs</h2>{_html_table(pairs, _PAIR_COLUMNS)}"
        f"<h2>Pictures</h2>{fig_html}<h2>Calibration</h2>{mats}"
        "</body></html>\n"
    )


# ----------------------------------------------------------------------------- synthetic views


def render_chessboard(
    K: npt.ArrayLike,
    D: npt.ArrayLike,
    rvec: npt.ArrayLike,
    tvec: npt.ArrayLike,
    *,
    pattern: tuple[int, int] = (9, 6),
    square_size: float = 1.0,
    image_size: tuple[int, int] = (640, 480),
    supersample: int = 4,
    edge_points: int = 8,
    background: int = 60,
) -> npt.NDArray[np.uint8]:
    """Render a chessboard seen by a camera, for tests and demos (antialiased, with distortion).

    The board (``pattern`` inner corners, one white square of margin around the outer squares)
    lies in its own ``Z = 0`` plane with corner ``(i, j)`` at ``(i * square_size, j *
    square_size, 0)``, as :func:`board_object_points`. Every square's outline is sampled with
    ``edge_points`` points per side, projected with ``cv2.projectPoints`` (so straight edges bend
    with the lens distortion), filled on a ``supersample`` x larger canvas with sub-pixel
    coordinates, and area-averaged down.

    Parameters
    ----------
    K, D : array_like
        Camera matrix ``(3, 3)`` and OpenCV distortion coefficients (None or none: no
        distortion).
    rvec, tvec : array_like
        Board-to-camera rotation (Rodrigues vector) and translation (in ``square_size`` units).
    pattern : tuple of int
        ``(cols, rows)`` inner corners.
    square_size : float
        Side of a square.
    image_size : tuple of int
        ``(width, height)``.
    supersample : int
        Supersampling factor of the area-averaged rendering.
    edge_points : int
        Points per square side (curved edges under distortion).
    background : int
        Grey level outside the board (black squares are 25, white 230).

    Returns
    -------
    numpy.ndarray
        ``(height, width)`` ``uint8`` grey image.

    Raises
    ------
    ValueError
        ``K`` not a finite 3 x 3 camera matrix of positive focal lengths of the form
        ``[[fx, s, cx], [0, fy, cy], [0, 0, 1]]`` (a transposed one), or ``D``, ``rvec`` or
        ``tvec`` not finite numbers of OpenCV's lengths, as
        :func:`~stereovision.synthetic.render_plane` refuses them.
    """
    from stereovision.synthetic import _camera_pose

    w, h = image_size
    ss = int(supersample)
    shift = 4  # fillPoly sub-pixel bits: 1/16 px on the supersampled canvas
    # a transposed K (MATLAB's IntrinsicMatrix) drew the board seen from a centre at (0, 0),
    # 70 % of a 640x480 view background, without a word; None for D was OpenCV's "Distortion
    # coefficients must be 1x4, ...", a NaN in D or tvec a picture of background only, a tvec
    # of two numbers NumPy's "cannot reshape": render_plane's checks, in its words
    Kf, Df, rv, tv = _camera_pose(K, D, rvec, tvec)
    cols, rows = pattern

    def outline(x0: float, y0: float, x1: float, y1: float) -> npt.NDArray[np.int32]:
        t = np.linspace(0.0, 1.0, edge_points, endpoint=False)
        sides = [
            np.c_[x0 + (x1 - x0) * t, np.full_like(t, y0)],
            np.c_[np.full_like(t, x1), y0 + (y1 - y0) * t],
            np.c_[x1 - (x1 - x0) * t, np.full_like(t, y1)],
            np.c_[np.full_like(t, x0), y1 - (y1 - y0) * t],
        ]
        q = np.vstack(sides) * square_size
        pts3 = np.c_[q, np.zeros(len(q))]
        p, _ = cv2.projectPoints(pts3, rv.reshape(3, 1), tv.reshape(3, 1), Kf, Df)
        p = p.reshape(-1, 2)
        # Pixel centres: image pixel (x, y) is the centre of canvas block [x*ss, (x+1)*ss).
        return np.round(((p + 0.5) * ss - 0.5) * (1 << shift)).astype(np.int32)

    canvas = np.full((h * ss, w * ss), background, np.uint8)
    cv2.fillPoly(canvas, [outline(-2, -2, cols + 1, rows + 1)], 230, cv2.LINE_AA, shift)
    black = [
        outline(a, b, a + 1, b + 1)
        for a in range(-1, cols)
        for b in range(-1, rows)
        if (a + b) % 2 == 0
    ]
    cv2.fillPoly(canvas, black, 25, cv2.LINE_AA, shift)
    return np.asarray(cv2.resize(canvas, (w, h), interpolation=cv2.INTER_AREA), np.uint8)


# ------------------------------------------------------------------------------------------ CLI


def _is_video(path: str) -> bool:
    """A video file or an image-sequence pattern (``left_%03d.png``), read frame by frame."""
    return "%" in path or Path(path).suffix.lower() in VIDEO_SUFFIXES


def _expand(pattern: str, option: str) -> list[str]:
    """Sorted files matching a glob pattern (or the file itself)."""
    from stereovision.capture import mask_url_secrets  # capture imports this module

    if glob.has_magic(pattern):  # a URL's "?" too
        files = sorted(glob.glob(os.path.expanduser(pattern)))
        if not files:
            raise FileNotFoundError(f"{option} {mask_url_secrets(pattern)!r}: no file matches")
        return files
    p = os.path.expanduser(pattern)
    if not os.path.exists(p):  # a stream's password is not said
        from stereovision.io import _broken_link

        # a link whose target moved (a folder of board images on a disk since unmounted) was
        # "not found" alone, of a name ls lists: its target is named, as io's readers name it
        gone = f" ({_broken_link(Path(p))})" if os.path.islink(p) else ""
        raise FileNotFoundError(f"{option}: file not found: {mask_url_secrets(pattern)}{gone}")
    if os.path.isdir(p):
        example = os.path.join(pattern, "*.png")
        raise ValueError(
            f"{option} {pattern}: is a folder; give its images as a quoted glob, e.g. '{example}'"
        )
    return [p]


def _pair_by_number(lefts: list[str], rights: list[str]) -> list[str]:
    """The right images in the order of their left partners, paired on the number in the name.

    Sorted globs pair by position, so one left and one other right image missing (``left05``
    and ``right09`` deleted as blurred) kept the counts equal and paired every image between
    them with the wrong partner: a calibration from mismatched views, without a word. When
    every name on both sides has a number, unique per side, and most numbers are on both
    sides, the pairs are made on them and an image without a partner is refused by name (unless
    the sorted position already pairs every shared number with itself: partners whose numbers
    differ, such as each camera's capture second). Two unbroken runs of as many numbers that
    differ by a constant and share at most half their numbers (``left_0001..0020`` with
    ``right_0101..0120`` or ``right_0011..0030``: each camera's counter started elsewhere) are
    paired in order, said in one UserWarning; runs sharing more than half (``left_0001..0020``
    with ``right_0002..0021``: an end file deleted on each side) are paired by number, their
    images without a partner refused by name.
    Names whose numbers do not correspond (timestamps taken by each camera) keep the
    position pairing.

    Parameters
    ----------
    lefts, rights : list of str
        The files ``--left`` and ``--right`` matched, sorted.

    Returns
    -------
    list of str
        ``rights`` reordered to follow ``lefts``, or unchanged where the names cannot pair.

    Raises
    ------
    ValueError
        If the numbers pair most images but some have no partner (named, the first few).
    """
    kl, kr = _file_numbers(lefts), _file_numbers(rights)
    if None in kl or None in kr or len(set(kl)) != len(kl) or len(set(kr)) != len(kr):
        return rights
    by_number = dict(zip(kr, rights, strict=True))
    common = set(kl) & set(kr)
    if len(common) == len(kl) == len(kr):
        return [by_number[k] for k in kl]
    shift = _constant_shift(kl, kr)
    if shift is not None:
        # Two unbroken runs of the same length (each camera's counter started elsewhere): the
        # n-th left goes with the n-th right. A missing file would break a run (refused below).
        nums = [k for k in kl if k is not None]
        paired = [by_number[k + shift] for k in nums]
        lo, hi = nums.index(min(nums)), nums.index(max(nums))
        name = os.path.basename
        warnings.warn(
            f"--left / --right: the right images are numbered {abs(shift)} "
            f"{'more' if shift > 0 else 'less'} than the left ones ({name(lefts[lo])}..."
            f"{name(lefts[hi])} with {name(paired[lo])}...{name(paired[hi])}, no gap on either "
            "side): paired in order",
            UserWarning,
            stacklevel=2,
        )
        return paired
    if len(common) < 2 or 2 * len(common) < min(len(kl), len(kr)):
        return rights  # numbers of their own on each side (or one file): the counts decide
    if len(kl) == len(kr) and all(
        a == b for a, b in zip(kl, kr, strict=True) if a in common or b in common
    ):
        # The sorted position pairs every shared number with itself: the others are partners
        # whose numbers differ (each camera's capture second, one pair saved across its turn).
        return rights
    alone = [
        f"{os.path.basename(f)} (no right)"
        for f, k in zip(lefts, kl, strict=True)
        if k not in common
    ]
    alone += [
        f"{os.path.basename(f)} (no left)"
        for f, k in zip(rights, kr, strict=True)
        if k not in common
    ]
    more = f" and {len(alone) - 6} more" if len(alone) > 6 else ""
    raise ValueError(
        f"--left / --right: {len(alone)} image(s) have no partner with the same number: "
        f"{', '.join(alone[:6])}{more}; remove them or restore their partners"
    )


def _check_output_file(
    out: Path, given: str, *, ros: str | None = None, report: str | None = None
) -> None:
    """Refuse, before the work, an ``-o`` that cannot be written or that another output of the
    same run would overwrite (the report's ``report.yaml``, the ROS ``left.yaml``).

    Parameters
    ----------
    out : pathlib.Path
        The calibration file.
    given : str
        ``-o`` as the user typed it, for the messages.
    ros, report : str, optional
        The ``--ros`` and ``--report`` folders.

    Raises
    ------
    ValueError
        If ``out`` is a folder, or is one of the files ``--ros`` or ``--report`` write.
    PermissionError
        If ``out``'s folder (a link's: its target's, where the file is written) or ``out``
        itself, when it exists, is not writable.
    OSError
        If ``out`` is a link that loops, or a FIFO or a device (or a link to one).
    """
    if out.is_dir():
        raise ValueError(f"-o {given}: is a folder; give a calibration file name")
    from stereovision.io import _special_kind, _through_links, cannot_write_in

    # a link is written through: the new file is made beside its target, not beside the link
    dest = _through_links(out)
    if dest.exists() and not dest.is_file():
        # a FIFO or a device, refused by atomic_write only after minutes of corner finding
        raise OSError(
            f"-o {given}: cannot write {dest}: it is not a regular file ({_special_kind(dest)})"
        )
    folder = dest.parent if str(dest.parent) else Path(".")
    why = cannot_write_in(folder)
    if why:
        raise PermissionError(f"-o {given}: cannot write in {folder} ({why})")
    if out.exists() and not os.access(out, os.W_OK):
        raise PermissionError(f"-o {given}: the file is not writable")
    # realpath, not resolve(): a --report file linked to itself raised "RuntimeError: Symlink
    # loop" here, before the link's own refusal (refuse_foreign_outputs) was reached
    target = os.path.realpath(out)
    for flag, where, files in (
        ("--report", report, ("report.html", "report.yaml", "report.json")),
        ("--ros", ros, ("left.yaml", "right.yaml")),
    ):
        if not where:
            continue
        for name in files:
            if os.path.realpath(Path(where) / name) == target:
                raise ValueError(
                    f"-o {given}: {flag} {where} writes {name} there too and would overwrite the "
                    "calibration; give -o another name or folder"
                )


def _cli_words(text: str) -> str:
    """A message of :func:`calibrate` in the CLI's words (``--drop-outliers``, ``--unit mm``)."""
    text = text.replace(DROP_OUTLIERS_API, DROP_OUTLIERS_CLI)
    text = text.replace("the board's square size", "--square")
    text = text.replace("legacy=True", "--legacy").replace("legacy=False", "--no-legacy")
    text = re.sub(r"\bdictionary='(\w+)'", r"--dictionary \1", text)
    text = re.sub(r"\bpattern=\((\d+), (\d+)\)", r"--pattern \1x\2", text)
    text = re.sub(r"\bdistortion='(\w+)'", r"--distortion \1", text)
    text = re.sub(r"\bmax_pairs=(\d+)", r"--max-pairs \1", text)
    # the square's bounds: "square_size: 1e-300 m is 1e-300 m", the parameter's name
    text = re.sub(r"^square_size: (\S+) (\w+) is ", r"--square \1 --unit \2 is ", text)
    return re.sub(r"\bunit='(\w+)'", r"--unit \1", text)


class _ProgressBars:
    """``stereovision calibrate``'s progress bars on a terminal (a tqdm bar per stage of
    :func:`calibrate`'s ``progress``: a recording's frames read, the board search, the
    distortion model's choice); nothing elsewhere, where the summary lines are the log. Thirty
    320x240 pairs took 22 s without a word: 14 s finding boards, 8 s choosing the model."""

    def __init__(self) -> None:
        self.enabled = sys.stderr.isatty()
        self.bar: Any = None
        self.stage = ""

    def __call__(self, stage: str, done: int, total: int) -> None:
        if not self.enabled:
            return
        if self.bar is None or stage != self.stage or done < self.bar.n:  # a new stage or round
            from tqdm import tqdm

            self.close()
            self.stage = stage
            unit = {PROGRESS_BOARDS: "pair", PROGRESS_FRAMES: "frame"}.get(stage, "fit")
            self.bar = tqdm(
                total=total or None, desc=stage, unit=unit, file=sys.stderr, leave=False
            )
        self.bar.update(done - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def _calibrate_source(
    args: argparse.Namespace,
    video: bool,
    lefts: list[str],
    rights: list[str],
    common: dict[str, Any],
) -> tuple[Calibration, CalibrationReport]:
    """Calibrate from the source the options give: a bag, two videos or two sets of images."""
    bars = common.get("progress")

    def log(line: str) -> None:
        if isinstance(bars, _ProgressBars):
            bars.close()  # the frames' bar off the screen first: it would share the line
        print(_cli_words(line))

    if args.from_bag:
        return calibrate_from_bag(
            args.from_bag,
            left_topic=args.left_topic,
            right_topic=args.right_topic,
            max_skew_ms=args.max_skew_ms,
            max_pairs=MAX_VIDEO_PAIRS if args.max_pairs is None else args.max_pairs,
            log=log,
            **common,
        )
    if video:
        return calibrate_from_video(
            args.left[0],
            args.right[0],
            max_pairs=MAX_VIDEO_PAIRS if args.max_pairs is None else args.max_pairs,
            log=log,
            **common,
        )
    selection: dict[str, Any] = {}
    if args.max_pairs is not None and args.max_pairs < len(lefts):
        keep = _spread(len(lefts), args.max_pairs)
        print(
            f"--max-pairs {args.max_pairs}: {len(keep)} of the {len(lefts)} image pairs kept, "
            "spread evenly over the list"
        )
        # named as calibrate names the pairs it uses (the file names, "left02.jpg / right02.jpg")
        names = _pair_names(
            [os.path.basename(f) for f in lefts], [os.path.basename(f) for f in rights], None
        )
        kept = set(keep)
        gone = [names[i] for i in range(len(lefts)) if i not in kept]
        selection = {
            "option": f"--max-pairs {args.max_pairs}",
            "rule": "spread evenly over the list, the first and the last kept, before the board "
            "was looked for",
            "given": len(lefts),
            "kept": len(keep),
            "left_out_count": len(gone),
            "left_out": gone,
        }
        lefts = [lefts[i] for i in keep]
        rights = [rights[i] for i in keep]
        # the pairs kept keep their names in the list given: files of one name in two folders
        # are numbered by their place in it ("13:left01.jpg / right01.jpg"), and numbered over
        # the pairs kept they took the numbers of pairs left out
        kept_names: list[str] | None = [names[i] for i in keep]
    else:
        kept_names = None
    try:
        cal, rep = calibrate(lefts, rights, names=kept_names, **common)
    except ValueError as exc:
        if selection and f"at least {MIN_PAIRS} are" in str(exc):  # too few: the rest unseen
            raise ValueError(
                f"{exc}; --max-pairs {args.max_pairs} left out {selection['left_out_count']} of "
                f"the {selection['given']} pairs given before the board was looked for (a larger "
                "--max-pairs looks at them)"
            ) from None
        raise
    rep.pair_selection = selection
    return cal, rep


def _spread(n: int, k: int) -> list[int]:
    """``k`` indices of ``range(n)`` spread evenly, the first and the last among them
    (``_spread(13, 5)`` is ``[0, 3, 6, 9, 12]``); all of them when ``k >= n``.

    Parameters
    ----------
    n : int
        How many items there are.
    k : int
        How many to keep (at least 2).

    Returns
    -------
    list of int
        Increasing, distinct indices.
    """
    if k >= n:
        return list(range(n))
    # round half up of i (n - 1) / (k - 1), in integers: steps of 1 or more stay distinct
    return [(2 * i * (n - 1) + (k - 1)) // (2 * (k - 1)) for i in range(k)]


#: How many of the pairs ``--max-pairs`` left out the summary names (report.json has them all).
LEFT_OUT_SHOWN = 6

#: The files ``stereovision calibrate`` writes into its ``--ros`` (the first two) and
#: ``--report`` folders.
CALIBRATE_OUTPUTS = ("left.yaml", "right.yaml", "report.html", "report.yaml", "report.json")

#: What ``stereovision calibrate`` wrote into its ``--report`` folder (JSON list of file names,
#: as ``depth``'s manifest): the files a later run replaces. ``--ros`` keeps none: its earlier
#: ``left.yaml`` / ``right.yaml`` are kept aside (:func:`stereovision.io.keep_previous`).
CALIBRATE_MANIFEST = ".stereovision-calibrate.json"


def cmd_calibrate(args: argparse.Namespace) -> int:
    """``stereovision calibrate --left GLOB --right GLOB --pattern 9x6 --square S -o FILE``
    (``--board charuco --marker M`` for a ChArUco board; ``--ros DIR`` also writes ROS
    ``camera_info`` files)."""
    # checked for every source: with images it was ignored without a word (0 or -1 included)
    if args.max_pairs is not None and args.max_pairs < MIN_PAIRS:
        raise ValueError(
            f"--max-pairs: expected an integer of at least {MIN_PAIRS}, got {args.max_pairs}"
        )
    # in the options' names, before the images are searched (calibrate said square_size: and
    # unit:, its parameters)
    from stereovision._validate import positive_finite
    from stereovision.calibration import UNIT_TO_METRES

    positive_finite(args.square, "--square")
    if args.unit not in UNIT_TO_METRES:
        raise ValueError(f"--unit: expected one of {list(UNIT_TO_METRES)}, got {args.unit!r}")
    if args.from_bag:
        if args.left or args.right:
            raise ValueError("--from-bag replaces --left and --right: give one source")
    elif args.left_topic or args.right_topic or args.max_skew_ms is not None:
        raise ValueError("--left-topic, --right-topic and --max-skew-ms are for --from-bag")
    elif not (args.left and args.right):
        raise ValueError("give the board's pairs (--left and --right) or a recording (--from-bag)")
    video = bool(args.left) and len(args.left) == 1 and _is_video(args.left[0])
    if args.right and video != (len(args.right) == 1 and _is_video(args.right[0])):
        raise ValueError("--left and --right: give two videos, or two sets of images")
    lefts: list[str] = []
    rights: list[str] = []
    if not video and not args.from_bag:
        lefts = [f for g in args.left for f in _expand(g, "--left")]
        rights = [f for g in args.right for f in _expand(g, "--right")]
        rights = _pair_by_number(lefts, rights)
        if len(lefts) != len(rights):
            raise ValueError(f"--left matches {len(lefts)} files but --right matches {len(rights)}")
    out = Path(args.output)
    if out.suffix.lower() not in (".yaml", ".yml", ".xml", ".json"):
        raise ValueError(f"-o {args.output}: use a .yaml, .yml, .xml or .json file name")
    if not out.parent.exists() and str(out.parent):
        raise FileNotFoundError(f"-o {args.output}: directory {out.parent} does not exist")
    ros_dir = Path(args.ros) if args.ros else None
    if ros_dir is not None and ros_dir.exists() and not ros_dir.is_dir():
        raise ValueError(f"--ros {args.ros}: is a file; give a folder for left.yaml and right.yaml")
    # Every output folder before the work: a report that cannot be written is said now, not
    # after minutes of corner finding and a calibration already saved. So is what stands
    # under --ros's names (a link to a file in a read-only folder, a folder): kept aside, not
    # refused, but written through.
    from stereovision.io import check_destinations, check_output_folder

    for flag, folder in (("--ros", args.ros), ("--report", args.report)):
        if folder:
            check_output_folder(folder, flag)
    if args.ros:
        check_destinations(args.ros, CALIBRATE_OUTPUTS[:2], "--ros")
    _check_output_file(out, args.output, ros=args.ros, report=args.report)
    # A report.html of the user's is not replaced; the files an earlier calibrate wrote there
    # (listed in its manifest) are. --ros's left.yaml / right.yaml (another rig's camera_info)
    # need no refusal: whatever they are, they are kept as left.previous.yaml ... (keep_previous).
    from stereovision.cli import record_outputs, refuse_foreign_outputs

    claims: dict[Path, set[str]] = {}
    for flag, folder, names in (("--report", args.report, CALIBRATE_OUTPUTS[2:]),):
        if folder:
            earlier = refuse_foreign_outputs(Path(folder), names, CALIBRATE_MANIFEST, flag)
            claims.setdefault(Path(folder).resolve(), set(earlier)).update(names)
            # a listed one made a folder passes the refusal above: said now, not after the
            # calibration with -o already written
            check_destinations(folder, names, flag)
    board = _cli_board(args, printing=False)
    common: dict[str, Any] = {
        "pattern": parse_pattern(args.pattern or "9x6", "--pattern"),
        "square_size": args.square,
        "board": board,
        "unit": args.unit,
        "distortion": args.distortion,
        "drop_outliers": args.drop_outliers,
        "progress": (bars := _ProgressBars()),
    }
    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            cal, rep = _calibrate_source(args, video, lefts, rights, common)
    except ValueError as exc:
        raise ValueError(_cli_words(str(exc))) from None
    finally:  # said in the CLI's words, once each (and also when the calibration failed)
        bars.close()  # before any line: a bar left on screen would share it
        seen: set[str] = set()
        for w in caught:
            text = _cli_words(str(w.message))
            if text not in seen:
                seen.add(text)
                warnings.warn(text, w.category, stacklevel=1)
    rep.warnings[:] = [_cli_words(w) for w in rep.warnings]  # the report in the CLI's words
    for key in ("option", "rule"):
        if key in rep.pair_selection:
            rep.pair_selection[key] = _cli_words(rep.pair_selection[key])
    from stereovision.io import keep_previous, replaced_words

    try:
        # before any file: a vertical rig (portrait images of a rig on its side) is calibrated,
        # but nothing here rectifies it, and describe() refused it after -o was written (exit 2,
        # the file written unsaid, --ros and --report not written)
        description = cal.describe()
    except ValueError as exc:
        raise ValueError(f"{exc}; nothing written{_upright_hint(cal)}") from None
    # the same result again (a rerun on the same pairs) replaces nothing: no copy is kept
    existed = Path(out).is_file()
    kept = keep_previous(out, cal._file_text(out).encode("utf-8"))
    for folder, claimed in claims.items():  # before the files: a run stopped keeps them its own
        record_outputs(folder, claimed, CALIBRATE_MANIFEST, CALIBRATE_OUTPUTS)
    cal.save(out)
    print(rep.summary(drop_option=DROP_OUTLIERS_CLI))
    print(description)
    # a folder named with a newline cut the line in two (escaped, as errors name it)
    print(f"calibration written to {escaped(str(out))}{replaced_words(kept, existed)}")
    if ros_dir is not None:
        try:
            # refused (a rig ROS cannot hold) before the earlier files are copied
            texts = cal.to_ros()
            ros_files = [ros_dir / f"{n}.yaml" for n in ("left", "right")]
            existed = all(p.is_file() for p in ros_files)
            ros_kept = [
                k
                for p, t in zip(ros_files, texts, strict=True)
                if (k := keep_previous(p, t.encode("utf-8")))
            ]
            left_yaml, right_yaml = cal.save_ros(ros_dir)
        except ValueError as exc:
            raise ValueError(
                f"calibration written to {out}, but not as ROS camera_info: {exc}"
            ) from None
        print(
            f"ROS camera_info written to {escaped(str(left_yaml))} and "
            f"{escaped(str(right_yaml))}"
            + replaced_words(" and ".join(map(str, ros_kept)), existed, "the ones they", "they")
        )
    if args.report:
        paths = rep.write(args.report)
        print(f"report written to {escaped(str(paths['html']))}")
    return 0


def _upright_hint(cal: Calibration) -> str:
    """How to turn the images of a vertical rig so that the right camera sits on the right
    (``""`` for a rig that is not vertical)."""
    centre = -cal.R.T @ cal.T  # the right camera's centre in the left camera's frame (y down)
    if abs(centre[1]) <= abs(centre[0]):
        return ""
    # turning an image by 90 degrees counter-clockwise takes its downward direction to the right
    way, where = ("counter-clockwise", "below") if centre[1] > 0 else ("clockwise", "above")
    return (
        f": the right camera sits {where} the left one; turn both cameras' images 90 degrees "
        f"{way} to put it on the right, and calibrate them"
    )


def _cli_board(args: argparse.Namespace, *, printing: bool) -> CharucoBoard | None:
    """The ChArUco board the options describe (None for a chessboard)."""
    if args.board != "charuco":
        if args.marker is not None or args.dictionary != "auto" or args.legacy is not None:
            raise ValueError("--marker, --dictionary and --legacy are for --board charuco")
        return None
    from stereovision.charuco import DICTIONARY_FAMILIES, CharucoBoard, board_error_words

    if args.pattern is None:
        raise ValueError("--pattern: give the ChArUco board's squares as COLSxROWS (e.g. 7x5)")
    if args.marker is None:
        raise ValueError("--marker: give the ChArUco marker's side, in --unit")
    try:
        board = CharucoBoard(
            args.pattern, args.square, args.marker, args.dictionary, legacy=args.legacy
        )
        if printing and board.dictionary == "auto":  # a print needs one: the smallest 5X5 fitting
            fitting = [n for n, k in DICTIONARY_FAMILIES["5X5"] if k >= board.n_markers]
            if not fitting:
                raise ValueError(
                    f"{board.n_markers} markers do not fit a 5X5 dictionary; give --dictionary"
                )
            board = replace(board, dictionary=fitting[0])
        if printing and board.legacy is None:
            board = replace(board, legacy=False)
    except ValueError as exc:
        raise ValueError(board_error_words(exc, "--pattern", "--board charuco")) from None
    return board


#: A printed board's plausible square side (metres): a few millimetres (a board for a close
#: microscope or endoscope rig) to a poster's 30 cm (a far-reaching rig's board).
PLAUSIBLE_SQUARE_M = (2e-3, 0.3)


def _square_unit_hint(square: float, unit: str) -> str:
    """What ``board`` says of a square too large in ``unit``: the units that make it a
    plausible one (:data:`PLAUSIBLE_SQUARE_M`; ``unit``'s own system first: 4 meant as inches
    with --unit ft), the likeliest given as the option (it said "mm or cm" for feet)."""
    from stereovision.calibration import _format_length, _plausible_units

    imperial = ("ft", "in")  # a slip within one system first: 4 ft for 4 in, not 4 mm
    found = sorted(
        _plausible_units(square, unit, PLAUSIBLE_SQUARE_M),
        key=lambda u: (u[0] in imperial) != (unit in imperial),
    )
    if not found:
        return "give its unit (--unit m, mm, cm, ft or in)"
    names = [u for u, _ in found]
    listed = names[0] if len(names) == 1 else f"{', '.join(names[:-1])} or {names[-1]}"
    best, m = found[0]
    return f"measured in {listed}? give its unit (--unit {best}: a {_format_length(m)} square)"


def cmd_board(args: argparse.Namespace) -> int:
    """``stereovision board -o board.png --pattern 9x6 --square 0.03`` (or ``--board charuco``):
    a printable board at its true size."""
    from stereovision.calibration import UNIT_TO_METRES
    from stereovision.charuco import _board_scale, board_png
    from stereovision.io import atomic_write

    out = Path(args.output)
    if out.suffix.lower() != ".png":
        raise ValueError(f"-o {args.output}: the board is written as a .png file")
    if not out.parent.exists() and str(out.parent):
        raise FileNotFoundError(f"-o {args.output}: directory {out.parent} does not exist")
    if args.unit not in UNIT_TO_METRES:
        raise ValueError(f"--unit: expected one of {list(UNIT_TO_METRES)}, got {args.unit!r}")
    board = _cli_board(args, printing=True)
    from stereovision._validate import positive_finite

    square = positive_finite(args.square, "--square")
    metres = square * UNIT_TO_METRES[args.unit]
    if metres > 1.0:
        # 30 meant as mm with --unit left at m was refused as "a 30000 mm square at 300 dpi is
        # 354331 px", or, up to 1.69 m, printed at that size
        warnings.warn(
            f"--square {square:g} {args.unit} is a {metres:g} m board square: "
            f"{_square_unit_hint(square, args.unit)}",
            UserWarning,
            stacklevel=2,
        )
    dpi = positive_finite(args.dpi, "--dpi")
    if board is not None:
        data, (w, h) = board_png(board, square * UNIT_TO_METRES[args.unit], dpi)
        what = board.describe(args.unit)
    else:
        pat = parse_pattern(args.pattern or "9x6", "--pattern")
        data, (w, h) = board_png(pat, square * UNIT_TO_METRES[args.unit], dpi)
        what = f"chessboard {pat[0]}x{pat[1]} inner corners, square {square:g} {args.unit}"
    from stereovision.io import keep_previous

    # a board.png already there (another board, a picture) stays; the same board again is no loss
    kept = keep_previous(out, data)
    with atomic_write(out) as fh:
        fh.write(data)
    # the PNG's resolution makes the whole-pixel square its exact size (_board_scale)
    pix, ppm = _board_scale(square * UNIT_TO_METRES[args.unit], dpi)
    mm = 1000 / ppm
    # a folder named with a newline cut the line in two (escaped, as its warnings name it)
    replaced = f" (the one it replaced kept as {escaped(str(kept))})" if kept else ""
    print(f"{escaped(str(out))}: {what}{replaced}")
    print(
        f"{w}x{h} px at {ppm} px/m ({ppm * 0.0254:.2f} dpi: {pix} px per square at {dpi:g} "
        f"dpi); printed at 100 % scale it is {w * mm:.1f} x {h * mm:.1f} mm with "
        f"{pix * mm:.2f} mm squares. Measure a square on the print and give that size to "
        "calibrate --square."
    )
    # a page the usual printers cannot take at 100 % is shrunk by their fit-to-page, and the
    # board then calibrates with squares smaller than the --square given (the README's 10x7
    # ChArUco board of 30 mm squares is 360 x 270 mm with its margins)
    too_big = [
        name
        for name, (a, b) in _PAPER_MM.items()
        if not ((w * mm <= a and h * mm <= b) or (w * mm <= b and h * mm <= a))
    ]
    if too_big:
        warnings.warn(
            f"{out} is {w * mm:.0f} x {h * mm:.0f} mm, larger than {' and '.join(too_big)} paper: "
            "print it on a larger sheet (A3, tabloid) or give a smaller --square (a printer's "
            "fit-to-page shrinks the squares)",
            UserWarning,
            stacklevel=2,
        )
    return 0


#: Sheets (mm, either way round) that ``board`` says its page outgrows: the usual office printers'.
_PAPER_MM = {"A4": (210.0, 297.0), "US Letter": (215.9, 279.4)}


def _add_board_options(p: argparse.ArgumentParser) -> None:
    """The options that describe a board, shared by ``calibrate`` and ``board``."""
    p.add_argument(
        "--board",
        default="chessboard",
        choices=["chessboard", "charuco"],
        help="calibration target (default chessboard)",
    )
    p.add_argument(
        "--pattern",
        default=None,
        help="chessboard: inner corners COLSxROWS (default 9x6); charuco: squares COLSxROWS",
    )
    p.add_argument("--square", required=True, type=length, help="square side in --unit")
    p.add_argument(
        "--unit", default="m", help="length unit of --square: m (default), mm, cm, ft or in"
    )
    p.add_argument("--marker", type=length, help="charuco: marker side in --unit")


def length(text: str) -> float:
    """argparse type of ``--square`` and ``--marker``: a number in ``--unit``'s unit; ``25mm``
    said only "expected a number", not where the unit goes. A value past any float (``1e400``)
    is refused here, as typed: after the parsing it was said as "got inf"."""
    from stereovision.cli import _UNIT_SUFFIXED

    try:
        value = float(text)
        if math.isinf(value) and "inf" not in text.lower():
            raise argparse.ArgumentTypeError(f"expected a positive finite number, got {text!r}")
        return value
    except ValueError:
        if _UNIT_SUFFIXED.match(text):
            raise argparse.ArgumentTypeError(
                f"expected a number, its unit given by --unit (25 --unit mm), got {text!r}"
            ) from None
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None


def add_cli(subparsers: Any) -> None:
    """Register the ``calibrate`` and ``board`` subcommands on an ``argparse`` subparsers
    object."""
    p = subparsers.add_parser(
        "calibrate",
        help="calibrate a stereo rig from chessboard or ChArUco pairs",
        description="Calibrate a stereo rig from chessboard or ChArUco image pairs (glob "
        "matches are paired on the number in their names, e.g. left07 with right07, or in sorted "
        "order where the names carry no common numbers).",
    )
    p.add_argument(
        "--left",
        nargs="+",
        help="left images (glob patterns, quoted), or one video (or %%03d pattern) of the board "
        "waved about",
    )
    p.add_argument("--right", nargs="+", help="right images (glob), or a video")
    from stereovision.capture import add_bag_args

    add_bag_args(p, "a ROS 1 / ROS 2 bag of the board waved about instead")
    p.add_argument(
        "--max-pairs",
        type=int,
        default=None,
        metavar="N",
        help="keep at most N board poses: videos and bags, the first N distinct ones (default "
        f"{MAX_VIDEO_PAIRS}); images, N pairs spread evenly over the list, before the board "
        "is looked for in them (default: all)",
    )
    _add_board_options(p)
    p.add_argument(
        "--dictionary",
        default="auto",
        help="charuco: ArUco dictionary, e.g. DICT_5X5_100 (default: found from the images)",
    )
    p.add_argument(
        "--legacy",
        default=None,
        action=argparse.BooleanOptionalAction,
        help="charuco: OpenCV's pre-4.6 layout for an even number of rows (default: found from "
        "the images)",
    )
    p.add_argument(
        "--distortion",
        default="auto",
        choices=["auto", *DISTORTION_MODELS, "fisheye"],
        help="distortion model (default: auto, chosen by cross-validation; fisheye: "
        "cv2.fisheye's equidistant model for wide-angle lenses)",
    )
    p.add_argument("--drop-outliers", action="store_true", help="drop outlier pairs and re-solve")
    p.add_argument(
        "-o", "--output", required=True, help="calibration file (.yaml, .yml, .xml or .json)"
    )
    p.add_argument("--report", metavar="DIR", help="write report.html/.yaml/.json into DIR")
    p.add_argument(
        "--ros",
        metavar="DIR",
        help="also write ROS camera_info left.yaml/right.yaml into DIR (metres, for "
        "stereo_image_proc)",
    )
    p.set_defaults(func=cmd_calibrate)

    b = subparsers.add_parser(
        "board",
        help="write a printable chessboard or ChArUco board (PNG at its true size)",
        description="Write a calibration board as a PNG whose DPI makes it print at its true "
        "size; calibrate with the same --board/--pattern/--square/--marker options.",
    )
    b.add_argument("-o", "--output", required=True, help="PNG file to write")
    _add_board_options(b)
    b.add_argument(
        "--dictionary",
        default="auto",
        help="charuco: ArUco dictionary (default: the smallest DICT_5X5 that holds the markers)",
    )
    b.add_argument(
        "--legacy",
        default=None,
        action=argparse.BooleanOptionalAction,
        help="charuco: OpenCV's pre-4.6 layout (default: the current one)",
    )
    b.add_argument(
        "--dpi",
        type=float,
        default=300.0,
        help="printer resolution the squares' whole pixels are counted at (default 300; the PNG "
        "stores the nearby resolution that prints them at their exact size)",
    )
    b.set_defaults(func=cmd_board)
