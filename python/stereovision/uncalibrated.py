"""Rectification without a calibration: two cameras row-aligned from their own features.

A robot's two cameras may need a look at disparity before anyone has waved a board in front of
them. :func:`rectify_uncalibrated` finds SIFT matches between the two views (mutual nearest
neighbours with Lowe's ratio test, as :func:`~stereovision.rectification_check.check_rectification`
does), keeps those that fit one fundamental matrix ``F`` (OpenCV's MAGSAC++; RANSAC where it
fails an assertion), and finds two homographies that put every pair of corresponding points on
the same row:

- **The model.** Two cameras side by side, each turned a little about its centre: Fusiello and
  Irsara's quasi-Euclidean rectification (five angles and a focal length, here with a second
  focal length for the right camera), fitted by Levenberg-Marquardt to the matches' Sampson
  distances: it describes what a rig is (two cameras, not any two views), so it cannot
  distort the images as freely as a general homography. When the turns do not fit (a hand-held
  pair, very different views), Hartley's projective homographies of ``F``
  (``cv2.stereoRectifyUncalibrated``) are used. On 17 bumped GT scenes the two leave the rows
  within 0.1 px of each other on 13; the turned cameras are better on 4 (docs/robotics.md).
- **Orientation**: the two images keep their sense (no mirror, not upside down).
- **Shape**: each image is sheared along its rows so that its middle lines stay perpendicular
  and keep their length ratio (Loop and Zhang's shearing transform, "Computing rectifying
  homographies for stereo vision", CVPR 1999): Hartley's homographies alone can skew an image by
  degrees and double its aspect ratio. A shear along the rows leaves the rows alone.
- **Size and disparities**: one scale for both keeps the matched part's area, the output holds
  the matched part and a margin, and the left image is shifted along its rows so that the
  disparities start near 0; the search range comes from the matches and a coarse dense match
  (SGBM at a quarter size), which sees the textureless background the features miss.

The result gives disparity, not metric depth: without a calibration the scale of the scene is
unknown, and the rectified images are a projective, not a Euclidean, view. Calibrate
(``stereovision calibrate``) for depth in metres.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    as_image_array,
    as_path,
    number_shown,
    real_number,
    too_large_for_float,
    whole_value,
    xy_points,
)
from stereovision.rectification_check import (
    DEFAULT_TOLERANCE_PX,
    MIN_MATCHES,
    RectificationCheck,
    _features,
    _grey_pair,
    _judge_rows,
    _mutual_matches,
)

__all__ = [
    "MAX_STRETCH",
    "MODELS",
    "UncalibratedRectification",
    "rectify_uncalibrated",
]

F64 = npt.NDArray[np.float64]

#: The epipolar distance (px) up to which a match fits the fundamental matrix.
RANSAC_PX = 1.0
#: A rectified image may be at most this many times the input's width or height; more means the
#: epipole lies near the image (the cameras look along their baseline) or the views hardly differ.
MAX_STRETCH = 4.0
#: The matches' disparities from this percentile to its complement span the scene (wrong matches
#: along an epipolar line still fit ``F``: on repetitive texture a few per cent of them); the
#: search range reaches this share of that span beyond it on both sides (a textureless
#: background has no matches to say how far it is: measured up to 23 % of the span below them),
#: starts at this disparity (px) and is at least 16 px.
_SPAN_PERCENTILE = 5.0
#: The coarse dense match that completes the features' span runs on the pair shrunk this much.
_PROBE_SCALE = 4
_RANGE_MARGIN = 0.3
_LOW_DISPARITY = 2.0
#: The output reaches this share of the matched part's size beyond it (within the images).
_MARGIN = 0.25
#: Levenberg-Marquardt steps of the quasi-Euclidean fit, the Huber scale of its residuals (px),
#: and the median residual (px) above which its model (turned cameras) is taken not to fit and
#: Hartley's projective homographies are used instead.
_QE_ITERATIONS = 60
_QE_HUBER_PX = 1.0
_QE_MAX_MEDIAN_PX = 0.5
#: A quasi-Euclidean fit turning a camera further than this (degrees) is not of a side-by-side
#: rig (it can fold an image onto a sliver, where every match fits): the projective way is used.
_QE_MAX_TURN_DEG = 30.0
#: Two cameras side by side, turned a little (the quasi-Euclidean model fits): a point lies
#: further right in the left image than in the right one, so most matches have ``x_left -
#: x_right > 0`` as taken. When at most this share of them does, the images were given the wrong
#: way round. Measured on 21 real side-by-side pairs: 0.97 to 1.00 in the right order, at most
#: 0.03 swapped. With the right camera bumped 1.5 degrees (6 of them): 0.99 to 1.00 in the right
#: order on Middlebury, 0.91 TartanAir, 0.64 and 0.31 ETH3D terrace and playground (disparities
#: of a few px: the bump's turn moves more); swapped 0.09 TartanAir, 0.35 and 0.69 ETH3D. The
#: check refuses 24 of the 27 swapped pairs; it misses bumped ETH3D terrace and playground, and
#: a chessboard pair, which swapped fits only Hartley's homographies (Tsukuba did too, before the
#: turned cameras' focal length was kept from running off: 0 % in the right order). Not checked
#: under them: a hand-held or converging pair's turn can move every match one way (OpenCV's
#: books pair, in the right order: 0 of 91).
_SWAPPED_SHARE = 0.2
#: When this share of the matches that fit ``F`` also fit one homography (within
#: :data:`RANSAC_PX`), the views have no parallax. Measured: 21 to 77 % on 21 real side-by-side
#: pairs (the 17 GT scenes, StereoPi, three of OpenCV's chessboard pairs), 43 % on its books
#: pair; 98.6 to 99.5 % with one image turned 1.5 to 4 degrees in place (cones, KITTI, ETH3D).
_ONE_HOMOGRAPHY_SHARE = 0.95


#: Two views whose brightest grey levels (99.5th percentile) differ by more than this factor
#: were taken at different exposures: the darker is brought up to the brighter's level for
#: SIFT, whose contrast threshold is absolute (cones with the right image two stops darker:
#: 13 matches, refused as "point the cameras at something textured"; brought up, 530). Real
#: pairs measured: at most 1.08 (17 GT scenes, StereoPi, OpenCV's books and chessboard pairs).
_EXPOSURE_RATIO = 1.5


def _exposure_matched(
    gl: npt.NDArray[np.uint8], gr: npt.NDArray[np.uint8]
) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
    """The pair's grey images with the darker one brought to the other's level when their
    exposures differ (see :data:`_EXPOSURE_RATIO`); other pairs as given."""
    tops = [float(np.percentile(g, 99.5)) if g.size else 0.0 for g in (gl, gr)]
    dark = int(tops[1] < tops[0])
    if not (tops[dark] > 0 and tops[1 - dark] > _EXPOSURE_RATIO * tops[dark]):
        return gl, gr
    gain = np.float32(tops[1 - dark] / tops[dark])
    out = [gl, gr]
    out[dark] = np.clip(np.rint(out[dark] * gain), 0, 255).astype(np.uint8)
    return out[0], out[1]


def _apply(h: F64, pts: F64) -> F64:
    q = np.column_stack([pts, np.ones(len(pts))]) @ h.T
    out: F64 = q[:, :2] / q[:, 2:3]
    return out


def _turn_deg(p1: F64, p2: F64) -> float | None:
    """The in-plane turn (degrees, clockwise as shown: y points down) that takes the matches
    ``p1`` onto ``p2`` (a similarity fitted by RANSAC), or None when none fits."""
    try:
        sim, _ = cv2.estimateAffinePartial2D(p1, p2)
    except cv2.error:
        return None
    if sim is None:
        return None
    return math.degrees(math.atan2(float(sim[1, 0]), float(sim[0, 0])))


#: An epipole further than this many image diagonals from the image's centre is of cameras side
#: by side (or one above the other): 6 to 233 on cones, turned or not; a camera stepped forward
#: and cut off its epipole's rows, 0.3.
_FAR_EPIPOLE_DIAGONALS = 2.0


#: Matches whose median vertical shift is over this many times their median horizontal one
#: moved along the columns: 110 to 153 on cones turned 90 degrees; at most 3 (tsukuba with its
#: right camera bumped) on side-by-side pairs, about 1 for a camera stepped forward.
_COLUMNS_RATIO = 10.0


def _epipole_far(fm: F64, w: int, h: int) -> bool:
    """Whether the left image's epipole (``fm @ e = 0``) lies further than
    :data:`_FAR_EPIPOLE_DIAGONALS` image diagonals from its centre (or at infinity)."""
    e = np.linalg.svd(fm)[2][-1]
    centre = np.array([(w - 1) / 2, (h - 1) / 2]) * e[2]
    reach = _FAR_EPIPOLE_DIAGONALS * math.hypot(w, h) * abs(e[2])
    return bool(np.linalg.norm(e[:2] - centre) > reach)


def _mirrored(pl: F64, dl: np.ndarray | None, gr: npt.NDArray[np.uint8], found: int) -> str:
    """What to do when the right image ``gr`` flipped left to right matches the left one's
    features (``pl``, ``dl``) far better than the ``found`` matches as given: a camera's mirror
    or flip setting (``""`` otherwise). SIFT matches no mirrored view: cones with its right image
    mirrored gave 42 matches, 25 fitting F, said as "the views share too little"; flipped back,
    549. Flipped upside down, the flip shows as a half turn."""
    pf, df = _features(np.ascontiguousarray(gr[:, ::-1]))  # cv2.flip(gr, 1)
    if dl is None or df is None or len(pl) < 2 or len(pf) < 2:
        return ""
    pairs = _mutual_matches(dl, df)
    if len(pairs) < max(MIN_MATCHES, 3 * found):
        return ""
    turn = _turn_deg(pl[pairs[:, 0]], pf[pairs[:, 1]])
    way, code = ("upside down", 0) if turn is not None and abs(turn) > 135 else ("left to right", 1)
    return (  # which of the two is mirrored the matches cannot tell
        f"one image is mirrored {way} against the other ({len(pairs)} matches with the right "
        "one flipped: a camera's mirror or flip setting?): flip the mirrored one back first "
        f"(cv2.flip(image, {code}))"
    )


def _midpoints(w: int, h: int) -> F64:
    """The middles of the top, right, bottom and left edges."""
    return np.array(
        [[(w - 1) / 2, 0.0], [w - 1.0, (h - 1) / 2], [(w - 1) / 2, h - 1.0], [0.0, (h - 1) / 2]]
    )


def _shape(h: F64, w: int, hgt: int) -> tuple[float, float]:
    """Loop and Zhang's distortion figures of an image under ``h``: how far its middle lines are
    from perpendicular (degrees), and their length ratio against the original's (1: kept)."""
    a, b, c, d = _apply(h, _midpoints(w, hgt))
    x, y = b - d, c - a
    cos = float(x @ y / (np.linalg.norm(x) * np.linalg.norm(y)))
    skew = abs(90.0 - math.degrees(math.acos(max(-1.0, min(1.0, cos)))))
    aspect = float(np.linalg.norm(x) / np.linalg.norm(y)) / ((w - 1) / (hgt - 1))
    return skew, aspect


def _shear(h: F64, w: int, hgt: int) -> F64:
    """Loop and Zhang's shearing transform ``S`` (x' = k1 x + k2 y): ``S h`` keeps the image's
    middle lines perpendicular and their length ratio."""
    a, b, c, d = _apply(h, _midpoints(w, hgt))
    x, y = b - d, c - a
    den = hgt * w
    cross = x[1] * y[0] - x[0] * y[1]
    if abs(cross) < 1e-12:
        return np.eye(3)
    k1 = (hgt**2 * x[1] ** 2 + w**2 * y[1] ** 2) / (den * cross)
    k2 = (hgt**2 * x[0] * x[1] + w**2 * y[0] * y[1]) / (den * -cross)
    if k1 < 0:
        k1, k2 = -k1, -k2
    return np.array([[k1, k2, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def _rotation(ax: float, ay: float, az: float) -> F64:
    cx, sx, cy, sy, cz, sz = (
        math.cos(ax),
        math.sin(ax),
        math.cos(ay),
        math.sin(ay),
        math.cos(az),
        math.sin(az),
    )
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    out: F64 = rz @ ry @ rx
    return out


#: The fundamental matrix of a rectified pair: corresponding points share their row.
_RECTIFIED_F = np.array([[0.0, 0, 0], [0, 0, -1], [0, 1, 0]])


def _qe_homographies(params: F64, w: int, h: int) -> tuple[F64, F64]:
    """Fusiello and Irsara's quasi-Euclidean rectification ("Quasi-Euclidean epipolar
    rectification of uncalibrated images", MVA 2011): each camera turned about its centre,
    ``H = K R K^-1`` with ``K`` of focal ``3^a (w + h)`` and the principal point at the image's
    centre; the left camera turns about y and z, the right about x, y and z. A seventh
    parameter, beyond the paper, lets the right camera's focal length differ from the left's
    by a share (two lenses of one model differ by a per cent or so)."""
    ayl, azl, axr, ayr, azr, a, zoom = (float(v) for v in params)
    f = 3.0 ** min(3.0, max(-3.0, a)) * (w + h)  # a focal length 1/27 to 27 times w + h
    k = np.array([[f, 0, (w - 1) / 2], [0, f, (h - 1) / 2], [0, 0, 1.0]])
    fr = f * (1.0 + min(0.5, max(-0.5, zoom)))  # the right camera's focal length
    kr = np.array([[fr, 0, (w - 1) / 2], [0, fr, (h - 1) / 2], [0, 0, 1.0]])
    return k @ _rotation(0.0, ayl, azl) @ np.linalg.inv(k), k @ _rotation(axr, ayr, azr) @ (
        np.linalg.inv(kr)
    )


def _sampson(fm: F64, x1: F64, x2: F64) -> F64:
    """Signed Sampson distances (px) of the matches ``x1``, ``x2`` (homogeneous rows) to ``fm``."""
    fx1 = x1 @ fm.T
    ftx2 = x2 @ fm
    num = np.sum(x2 * fx1, axis=1)
    den = np.sqrt(fx1[:, 0] ** 2 + fx1[:, 1] ** 2 + ftx2[:, 0] ** 2 + ftx2[:, 1] ** 2)
    out: F64 = num / np.maximum(den, 1e-12)
    return out


def _quasi_euclidean(p1: F64, p2: F64, w: int, h: int) -> tuple[F64, F64, float]:
    """Fit :func:`_qe_homographies`' seven parameters to the matches (Levenberg-Marquardt on their
    Sampson distances to the rectified pair's ``F``, Huber-weighted at 1 px), from no turn."""
    x1 = np.column_stack([p1, np.ones(len(p1))])
    x2 = np.column_stack([p2, np.ones(len(p2))])

    def resid(q: F64) -> F64:
        hl, hr = _qe_homographies(q, w, h)
        return _sampson(hr.T @ _RECTIFIED_F @ hl, x1, x2)

    n_par = 7
    q = np.zeros(n_par)
    r = resid(q)
    lam = 1e-2
    for _ in range(_QE_ITERATIONS):
        wts = np.sqrt(np.minimum(1.0, _QE_HUBER_PX / np.maximum(np.abs(r), 1e-12)))
        jac = np.empty((len(r), n_par))
        for i in range(n_par):
            step = np.zeros(n_par)
            step[i] = 1e-6
            jac[:, i] = (resid(q + step) - resid(q - step)) / 2e-6
        # Unturned cameras do not depend on the focal length (K I K^-1 = I): its column is
        # rounding noise (1e-8 against 1e2-1e4), whose step in the damped solve was thousands
        # (Tsukuba, right image 2 px lower: a = -2168), and the clamped focal length, (w + h) / 27,
        # stayed there: rows 0.37 px apart and a 448x468 output, where a pitch of the right
        # camera gives 0.05 px. A column at rounding level does not move its parameter.
        norms = np.linalg.norm(jac, axis=0)
        jac[:, norms <= 1e-9 * norms.max()] = 0.0
        jw, rw = jac * wts[:, None], r * wts
        a_mat, g = jw.T @ jw, jw.T @ rw
        cost = float(rw @ rw)
        while True:
            try:
                delta = np.linalg.solve(a_mat + lam * np.diag(np.diag(a_mat) + 1e-12), -g)
            except np.linalg.LinAlgError:
                delta = np.zeros(n_par)
            r_new = resid(q + delta)
            new_cost = float(np.sum((r_new * wts) ** 2))
            if (math.isfinite(new_cost) and new_cost < cost) or lam > 1e8:
                break
            lam *= 10
        if lam > 1e8:
            break
        q, r = q + delta, r_new
        lam = max(lam / 10, 1e-9)
        if float(np.abs(delta).max()) < 1e-10:
            break
    hl, hr = _qe_homographies(q, w, h)
    turned = max(abs(v) for v in q[:5])
    if turned > math.radians(_QE_MAX_TURN_DEG) or abs(q[6]) > 0.3 or not np.isfinite(r).all():
        return hl, hr, math.inf  # not two cameras side by side: a collapsed or wild fit
    return hl, hr, float(np.median(np.abs(r)))


def _dense_span(
    gl: npt.NDArray[np.uint8],
    gr: npt.NDArray[np.uint8],
    h1: F64,
    h2: F64,
    s: float,
    tx: tuple[float, float],
    y0: float,
    size: tuple[int, int],
    search: int,
) -> tuple[float, float] | None:
    """0.5th and 99.5th percentile of OpenCV SGBM's disparities (px of the output), searched up
    to ``search``, on the pair rectified with these offsets and shrunk :data:`_PROBE_SCALE`
    times; None when too small or nothing matched. Both images are moved right by the search
    range first: SGBM leaves the first ``numDisparities`` columns without a value."""
    k = _PROBE_SCALE
    n = 16 * max(1, math.ceil(search / k / 16))
    shape = (max(1, (size[0] + n * k) // k), max(1, size[1] // k))
    if shape[1] < 16 or shape[0] < n + 16:
        return None
    imgs = []
    for img, hom, t in ((gl, h1, tx[0]), (gr, h2, tx[1])):
        move = np.array([[s / k, 0, t / k + n], [0, s / k, -s * y0 / k], [0, 0, 1.0]])
        # Linear, as it always was: it asked for INTER_AREA, which warpPerspective does as
        # INTER_LINEAR (the same pixels). A probe warped at full size and then averaged
        # (resize INTER_AREA) was not better: of the 17 GT scenes' disparities inside the
        # search range, 3 lost (wood2 74.92 -> 74.49 %, art, books 0.1 point), 2 gained.
        imgs.append(cv2.warpPerspective(img, move @ hom, shape, flags=cv2.INTER_LINEAR))
    sgbm = cv2.StereoSGBM_create(  # type: ignore[attr-defined]
        minDisparity=0, numDisparities=n, blockSize=5, P1=8 * 25, P2=32 * 25,
        disp12MaxDiff=1, uniquenessRatio=15, speckleWindowSize=50, speckleRange=2,
    )  # fmt: skip
    d = sgbm.compute(imgs[0], imgs[1]).astype(np.float32) / 16.0
    d = d[d > 0]
    if d.size < 100:
        return None
    lo, hi = np.percentile(d, [0.5, 99.5])
    return float(lo) * k, float(hi) * k


#: The interpolation methods OpenCV's warpPerspective does (INTER_AREA it does as INTER_LINEAR).
_WARP_METHODS = (
    cv2.INTER_NEAREST,
    cv2.INTER_LINEAR,
    cv2.INTER_CUBIC,
    cv2.INTER_LANCZOS4,
)


def _corners(w: int, h: int) -> F64:
    return np.array([[0.0, 0.0], [w - 1.0, 0.0], [w - 1.0, h - 1.0], [0.0, h - 1.0]])


def _hull_area(pts: F64) -> float:
    return float(cv2.contourArea(cv2.convexHull(pts.astype(np.float32))))


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity (== raised)
class UncalibratedRectification:
    """Two homographies that rectify a pair, found from its features (see the module doc).

    Attributes
    ----------
    H1, H2 : numpy.ndarray
        ``(3, 3)``: input left / right pixel -> rectified pixel.
    size : tuple of int
        ``(width, height)`` of the rectified images.
    input_size : tuple of int
        ``(width, height)`` of the input images.
    F : numpy.ndarray
        ``(3, 3)`` fundamental matrix, ``x_r^T F x_l = 0``.
    matches : int
        Feature matches that fit ``F`` (within :data:`RANSAC_PX`).
    median_dy, p95_dy : float
        ``|y_left - y_right|`` of those matches after rectification (px).
    disparity_range : tuple of float
        Their disparities after rectification, 5th to 95th percentile (px).
    max_disparity : int
        Suggested search range for the matchers.
    skew_deg : tuple of float
        Each rectified image's middle lines off perpendicular (degrees; 0: kept).
    aspect : tuple of float
        Each rectified image's middle-line length ratio against the input's (1: kept).
    model : str
        ``"quasi-euclidean"`` (the cameras turned about their centres) or ``"projective"``
        (Hartley's homographies of ``F``, when the turns do not fit the matches).
    """

    H1: F64
    H2: F64
    size: tuple[int, int]
    input_size: tuple[int, int]
    F: F64
    matches: int
    median_dy: float
    p95_dy: float
    disparity_range: tuple[float, float]
    max_disparity: int
    skew_deg: tuple[float, float]
    aspect: tuple[float, float]
    model: str = "quasi-euclidean"

    def rectify(
        self, left: npt.ArrayLike, right: npt.ArrayLike, *, interpolation: int = cv2.INTER_LINEAR
    ) -> tuple[np.ndarray, np.ndarray]:
        """Warp a pair of this rig (input size) into its rectified pair (black outside).

        Parameters
        ----------
        left, right : array_like
            The raw pair, of :attr:`input_size`.
        interpolation : int
            OpenCV interpolation flag (default ``cv2.INTER_LINEAR``).

        Returns
        -------
        tuple of ndarray
            The rectified left and right images, of :attr:`size`, the input's dtype and
            channels (an ``(H, W, 1)`` image stays one); a float image within its own range
            and the black border's 0 (cubic and Lanczos's overshoot clipped).

        Raises
        ------
        ValueError
            If an image is not an image array (as :meth:`Calibration.rectify
            <stereovision.calibration.Calibration.rectify>`: bool, signed integer or other
            dtypes, a wrong shape) or not of :attr:`input_size`, or ``interpolation`` is not
            one of OpenCV's four methods of a warp (``cv2.INTER_NEAREST``, ``INTER_LINEAR``,
            ``INTER_CUBIC``, ``INTER_LANCZOS4``; ``INTER_AREA`` averages only in a resize:
            a warp gave ``INTER_LINEAR``'s pixels for it).
        """
        # True or "linear" were OpenCV's bare "Overload resolution failed" (2.0 too: now 2, as
        # the package reads a whole number), 5 to 7 its "Unknown interpolation method", and a
        # flag beside a method warped otherwise without a word (cv2.WARP_INVERSE_MAP: with the
        # inverse homographies, another pair)
        method = whole_value(interpolation)
        if method == cv2.INTER_AREA:
            # warpPerspective does it as INTER_LINEAR: the pair came back linear, not averaged
            raise ValueError(
                "interpolation: cv2.INTER_AREA averages only in a resize; a warp does "
                "INTER_LINEAR for it (the same pixels): give cv2.INTER_LINEAR, or resize the "
                "rectified pair with INTER_AREA"
            )
        if method is None or method not in _WARP_METHODS:
            raise ValueError(
                "interpolation: expected one of OpenCV's cv2.INTER_NEAREST, INTER_LINEAR, "
                f"INTER_CUBIC or INTER_LANCZOS4 (0, 1, 2 or 4), got {interpolation!r}"
            )
        out = []
        for name, img, hom in (("left", left, self.H1), ("right", right, self.H2)):
            # OpenCV's own assertion ("ifunc != 0 in function 'remap'") of a bool or int64
            # array, or of a float16 image the package otherwise takes, said nothing of it
            arr = as_image_array(img, name)
            self._check_input_size(name, arr.shape)
            work = arr
            if arr.dtype.kind == "f" and arr.dtype.itemsize not in (4, 8):  # float16, long double
                work = arr.astype(np.float32 if arr.dtype.itemsize == 2 else np.float64)
            warped = np.asarray(cv2.warpPerspective(work, hom, self.size, flags=method))
            overshoots = method in (cv2.INTER_CUBIC, cv2.INTER_LANCZOS4)
            if overshoots and arr.dtype.kind == "f" and np.isfinite(arr).any():
                # cubic and Lanczos overshoot an edge (a [0, 1] pair: -0.10 .. 1.10), which
                # depth_map then refused as out of range: kept within the image's own range and
                # the black border's 0, as align_rows keeps it. Only they: a linear warp's clip
                # moved float64 pixels by an ulp and slowed a colour float pair ~1.8x
                lo, hi = min(0.0, float(np.nanmin(arr))), max(0.0, float(np.nanmax(arr)))
                warped = np.clip(warped, lo, hi)
            if arr.ndim == 3 and warped.ndim == 2:  # OpenCV drops an (H, W, 1) image's channel
                warped = warped[..., None]
            out.append(warped if warped.dtype == arr.dtype else warped.astype(arr.dtype))
        return out[0], out[1]

    def _check_input_size(self, name: str, shape: tuple[int, ...]) -> None:
        """Refuse an image not of :attr:`input_size`, naming the mix-up of the rectified
        pair's images (``left_rect.png``) for the raw pair they came from.

        Parameters
        ----------
        name : str
            ``"left"`` or ``"right"``, for the message.
        shape : tuple of int
            The image's shape, ``(H, W)`` or ``(H, W, C)``.

        Raises
        ------
        ValueError
            If ``shape`` is not of :attr:`input_size`.
        """
        w, h = shape[1], shape[0]
        if (w, h) == self.input_size:
            return
        rectified = (w, h) == self.size  # `rectify`'s output, which a second warp would spoil
        raise ValueError(
            f"{name} image is {w}x{h} px"
            + (", the rectified pair's size" if rectified else "")
            + f"; this rectification is for {self.input_size[0]}x{self.input_size[1]}"
            + (
                ", the raw pair: match the rectified pair as it is (depth without --rectification)"
                if rectified
                else ""
            )
        )

    def rectify_points(self, points: npt.ArrayLike, side: str = "left") -> F64:
        """Input pixel positions of one image -> their positions in the rectified image.

        Parameters
        ----------
        points : array_like
            ``(N, 2)`` pixel coordinates ``(x, y)`` in the input image.
        side : str
            ``"left"`` or ``"right"``.

        Returns
        -------
        numpy.ndarray
            ``(N, 2)`` float64 rectified pixel coordinates.

        Raises
        ------
        ValueError
            For points not of shape ``(N, 2)`` (a ``(2, N)`` array, Bouguet's layout, or
            homogeneous ``(N, 3)`` points were read as other points) or an unknown ``side``.
        """
        if side not in ("left", "right"):
            raise ValueError(f"side: expected 'left' or 'right', got {side!r}")
        return _apply(self.H1 if side == "left" else self.H2, xy_points(points))

    def check(
        self, left: npt.ArrayLike, right: npt.ArrayLike, *, tolerance: float = DEFAULT_TOLERANCE_PX
    ) -> RectificationCheck:
        """How the rows of the rectified pair agree: the raw pair's feature matches moved by
        :attr:`H1` and :attr:`H2`, judged by :func:`check_rectification`'s rule.

        :func:`check_rectification` on the warped images finds its features anew, and a
        projective warp that squeezes or shears one image (a hand-held pair) leaves SIFT few to
        match: on OpenCV's books pair 18 of the raw pair's 107, too few to tell, while the
        homographies put those 107 on common rows to 0.24 px. The matches here are the raw
        pair's (where SIFT sees the views as taken), their positions exact under the warp; those
        off the rectified images are left out. ``matches`` counts the ones on one row model.

        Parameters
        ----------
        left, right : array_like
            The raw pair, of :attr:`input_size`.
        tolerance : float
            Median ``|dy|`` (px) up to which the pair counts as rectified.

        Returns
        -------
        RectificationCheck
            As :func:`check_rectification` returns; its ``points`` are in the rectified pair.

        Raises
        ------
        ValueError
            If an image is not of :attr:`input_size`, or a tolerance that is not a positive
            number.
        """
        # real_number (2f65049's rule, lost here in a merge): 3 ns was 3 px; and 10**400 was
        # np.isfinite's bare TypeError
        if (
            too_large_for_float(tolerance)
            or not real_number(tolerance)
            or not (np.isfinite(tolerance) and tolerance > 0)
        ):
            raise ValueError(
                f"tolerance: expected a positive number of pixels, got {number_shown(tolerance)}"
            )
        # a dark pair (12-bit data in 16 bits) stretched as check_rectification stretches it
        grays = _exposure_matched(*_grey_pair(left, right))  # as rectify_uncalibrated's
        for name, g in zip(("left", "right"), grays, strict=True):
            self._check_input_size(name, g.shape)
        pl, dl = _features(grays[0])
        pr, dr = _features(grays[1])
        pairs = (
            _mutual_matches(dl, dr)
            if dl is not None and dr is not None and len(pl) >= 2 and len(pr) >= 2
            else np.zeros((0, 2), dtype=np.intp)
        )
        q1 = _apply(self.H1, pl[pairs[:, 0]].reshape(-1, 2))
        q2 = _apply(self.H2, pr[pairs[:, 1]].reshape(-1, 2))
        w, h = self.size
        inside = np.all((q1 >= -0.5) & (q2 >= -0.5), axis=1)
        inside &= (q1[:, 0] <= w - 0.5) & (q2[:, 0] <= w - 0.5)
        inside &= (q1[:, 1] <= h - 0.5) & (q2[:, 1] <= h - 0.5)
        quad = np.column_stack([q1, q2])[inside]
        return _judge_rows(quad, w, h, float(tolerance))

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: the homographies, ``F`` and the figures.

        Returns
        -------
        dict
            Field name to value, arrays as nested lists.
        """
        return {
            "H1": self.H1.tolist(),
            "H2": self.H2.tolist(),
            "size": list(self.size),
            "input_size": list(self.input_size),
            "F": self.F.tolist(),
            "matches": self.matches,
            "median_dy": self.median_dy,
            "p95_dy": self.p95_dy,
            "disparity_range": list(self.disparity_range),
            "max_disparity": self.max_disparity,
            "skew_deg": list(self.skew_deg),
            "aspect": list(self.aspect),
            "model": self.model,
        }

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`as_dict` as JSON (atomically; a NaN or infinite value as null).

        Parameters
        ----------
        path : str or os.PathLike
            The file to write.

        Returns
        -------
        Path
            ``path``.
        """
        from stereovision._jsonout import json_ready
        from stereovision.io import atomic_write

        as_path(path, file=True)  # '' was "cannot write .: it is a folder"
        p = Path(path)
        # strict JSON, as the package's other JSON: a NaN or infinite figure was written as
        # the bare NaN / Infinity that jq and JavaScript refuse; it is null, read back as NaN
        text = json.dumps(json_ready(self.as_dict()), indent=2, allow_nan=False)
        with atomic_write(p, "w") as fh:
            fh.write(text)
        return p

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> UncalibratedRectification:
        """Read a file written by :meth:`save`.

        Parameters
        ----------
        path : str or os.PathLike
            The file.

        Returns
        -------
        UncalibratedRectification
            The rectification it holds.

        Raises
        ------
        FileNotFoundError
            If it does not exist (a link to nothing: its target named).
        ValueError
            If ``path`` is empty, if it is not a regular file (a FIFO) or not such a file (the
            field named), or its
            values cannot rectify a pair
            (NaN or singular homographies, sizes of 0 or less, an unknown model).
        """
        as_path(path, file=True)  # '' was "not found: . is a folder", a folder not named
        p = Path(path)
        if p.is_dir():  # "not found" alone, of a folder that is there (the type kept: API)
            inside = p / "rectification.json"
            raise FileNotFoundError(
                f"rectification file not found: {p} is a folder; give "
                + (f"its {inside}" if inside.is_file() else "the rectification.json in it")
            )
        # a FIFO was "not found", a file that is there, and a link whose target moved said
        # without the link: in imread's words (a FIFO is not opened: its read would block)
        from stereovision.io import _existing_file

        _existing_file(p, "rectification file")
        try:
            # utf-8-sig: a file edited in a Windows editor (a BOM) was "not JSON text", as the
            # calibration readers read it without
            d = json.loads(p.read_text(encoding="utf-8-sig"))
        except (UnicodeDecodeError, json.JSONDecodeError):
            # json's "Expecting value: line 1 column 1 (char 0)", or utf-8's "can't decode byte
            # 0x89", of an image given for it: neither said what was expected
            raise ValueError(
                f"{p} is not an uncalibrated rectification: not JSON text (expected the "
                "rectification.json that `stereovision rectify` writes)"
            ) from None
        if not isinstance(d, dict):
            # a JSON list or number (another tool's file) said "list indices must be integers
            # or slices, not str", Python's words of the lookup, not what was expected
            kind = {list: "array", str: "string", bool: "true/false"}.get(type(d), "number")
            raise ValueError(
                f"{p} is not an uncalibrated rectification: a JSON "
                f"{'null' if d is None else kind}, not an object (expected the "
                "rectification.json that `stereovision rectify` writes)"
            )
        try:
            mats = {k: _matrix(d[k], k) for k in ("H1", "H2", "F")}
            out = cls(
                mats["H1"],
                mats["H2"],
                _size(d["size"], "size"),
                _size(d["input_size"], "input_size"),
                mats["F"],
                _whole(d["matches"], "matches"),
                _figure(d["median_dy"], "median_dy"),
                _figure(d["p95_dy"], "p95_dy"),
                _figures(d["disparity_range"], "disparity_range", "min, max"),
                _whole(d["max_disparity"], "max_disparity"),
                _figures(d["skew_deg"], "skew_deg", "left, right"),
                _figures(d["aspect"], "aspect", "left, right"),
                str(d.get("model", "projective")),
            )
        except (ValueError, KeyError, TypeError, IndexError) as exc:
            what = f"field {exc}" if isinstance(exc, KeyError) else str(exc)
            raise ValueError(f"{p} is not an uncalibrated rectification: {what}") from None
        problem = _damaged(out)
        if problem:
            raise ValueError(f"{p} is not a usable uncalibrated rectification: {problem}")
        return out

    def describe(self) -> str:
        """One line for a terminal.

        Returns
        -------
        str
            The model, the matches, the rows' agreement, the disparity range and the size.
        """
        return (
            f"rectified without a calibration ({self.model}) from {self.matches} feature "
            "matches: rows "
            f"median |dy| {self.median_dy:.2f} px (95 % {self.p95_dy:.2f}); disparities "
            f"{self.disparity_range[0]:.0f}-{self.disparity_range[1]:.0f} px (max_disparity "
            f"{self.max_disparity}); {self.size[0]}x{self.size[1]} px, skew "
            f"{max(self.skew_deg):.2f} deg, aspect {self.aspect[0]:.3f} / {self.aspect[1]:.3f}"
        )


def _whole(value: Any, field: str) -> int:
    """A count of a rectification file (a JSON integer, or a whole float such as 16.0); int()
    read 40.7 as 40, true as 1 and "16" as 16, so a damaged or hand-edited file passed."""
    whole = None if isinstance(value, str) else whole_value(value)
    if whole is None:
        raise ValueError(f"{field}: expected a whole number, got {value!r}")
    return whole


def _size(value: Any, field: str) -> tuple[int, int]:
    """A ``[width, height]`` of a rectification file, each :func:`_whole` (a third entry was
    left out without a word)."""
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"{field}: expected [width, height], got {value!r}")
    return _whole(value[0], field), _whole(value[1], field)


def _figure(value: Any, field: str) -> float:
    """A figure of a rectification file: :meth:`UncalibratedRectification.save` writes a NaN
    or infinite one as null (strict JSON), read back as NaN. Anything but a JSON number or
    null is refused naming the field (float() said "could not convert string to float: 'abc'"
    and read true as 1.0), and so is an integer past a float (float()'s OverflowError, which
    went past :meth:`UncalibratedRectification.load`'s ValueError)."""
    if value is None:
        return math.nan
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{field}: expected a number, got {value!r}")
    if too_large_for_float(value):
        raise ValueError(f"{field}: expected a number, got {number_shown(value)}")
    return float(value)


def _matrix(value: Any, field: str) -> F64:
    """A 3 x 3 matrix of a rectification file (``[[a, b, c], [d, e, f], [g, h, i]]``), each
    entry :func:`_figure` (a null entry NaN, refused by :func:`_damaged`): a 3 x 4 one said
    NumPy's "cannot reshape array of size 12 into shape (3,3)", "abc" "could not convert
    string to float", neither naming the field, and true was read as 1.0."""
    if not (
        isinstance(value, list)
        and len(value) == 3
        and all(isinstance(row, list) and len(row) == 3 for row in value)
    ):
        raise ValueError(
            f"{field}: expected a 3 x 3 matrix [[a, b, c], [d, e, f], [g, h, i]], got {value!r}"
        )
    return np.array([[_figure(v, field) for v in row] for row in value], np.float64)


def _figures(value: Any, field: str, names: str) -> tuple[float, float]:
    """A pair of figures of a rectification file (``names``: ``"left, right"``), each
    :func:`_figure`: a null or one-entry pair (hand-edited) said "'NoneType' object is not
    subscriptable" or "list index out of range", the field unnamed."""
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"{field}: expected [{names}], got {value!r}")
    return _figure(value[0], field), _figure(value[1], field)


def _damaged(rect: UncalibratedRectification) -> str | None:
    """What makes a read rectification unusable (a damaged or hand-edited file), or None.

    NaN or singular homographies warp every pixel to black and ``depth --rectification``
    went on to write a disparity map of the black pair; a size of 0 or less made OpenCV fall
    back to the input's size.
    """
    for name in ("H1", "H2", "F"):
        if not np.isfinite(getattr(rect, name)).all():
            return f"{name} has a NaN or infinite entry"
    for name in ("H1", "H2"):
        hom = getattr(rect, name)
        top = float(np.abs(hom).max())
        if not (top > 0 and abs(float(np.linalg.det(hom / top))) > 1e-12):
            return f"{name} is singular (no homography)"
    for name in ("size", "input_size"):
        w, h = getattr(rect, name)
        if not (0 < w <= 100_000 and 0 < h <= 100_000):
            return f"{name} {w}x{h} px: expected positive sizes up to 100000"
    # rectify_uncalibrated refuses a rectified size past MAX_STRETCH times the input's: a
    # larger one (hand-edited, 100000x100000 for a 612x459 pair) had OpenCV allocate 30 GB
    # for the warp ("internal error: ... Failed to allocate 30000000000 bytes")
    (w, h), (w0, h0) = rect.size, rect.input_size
    if w > MAX_STRETCH * w0 or h > MAX_STRETCH * h0:
        return (
            f"size {w}x{h} px: more than {MAX_STRETCH:g} times the input's {w0}x{h0} px "
            "(rectify_uncalibrated makes none larger)"
        )
    if rect.max_disparity < 1:
        return f"max_disparity {rect.max_disparity}: expected at least 1"
    if rect.model not in MODELS[1:]:
        return f"model {rect.model!r}: expected one of {', '.join(MODELS[1:])}"
    return None


#: The rectification models :func:`rectify_uncalibrated` offers.
MODELS = ("auto", "quasi-euclidean", "projective")


def rectify_uncalibrated(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    *,
    ransac_px: float = RANSAC_PX,
    model: str = "auto",
) -> UncalibratedRectification:
    """Find the homographies that rectify a pair from the pair itself (see the module doc).

    Parameters
    ----------
    left, right : array_like
        The two views, the same size; grey or colour, any dtype the package reads. The left
        camera is the one on the left (its image's matches lie to the right of the other's).
    ransac_px : float
        Epipolar distance (px) up to which a match fits the fundamental matrix.
    model : str
        ``"auto"``: the two cameras turned about their centres (quasi-Euclidean), or Hartley's
        projective homographies of ``F`` when the turns do not fit; ``"quasi-euclidean"`` or
        ``"projective"`` to choose one.

    Returns
    -------
    UncalibratedRectification
        Its :meth:`~UncalibratedRectification.rectify` warps the pair.

    Raises
    ------
    ValueError
        Images of different sizes, fewer than 30 matches or fewer than 30 that fit one
        fundamental matrix (too little texture in common; or one image mirrored against the
        other, a camera's mirror setting: named, with the flip), two views with no parallax (the
        same view, or nearly all matches fitting one homography: a camera turned in place, a
        flat scene), an
        epipole inside the image (the cameras look along their baseline), homographies that
        would stretch an image more than :data:`MAX_STRETCH` times, left and right given the
        wrong way round (two cameras side by side, at most a fifth of whose matches lie further
        right in the left image than in the right one), the right image turned upside down
        or on its side against the left one (a camera mounted so: the turn is named), or
        cameras one above the other (the 90-degree turn of both images that puts them side by
        side is named).
    """
    if model not in MODELS:
        raise ValueError(f"model: expected one of {', '.join(MODELS)}, got {model!r}")
    # NumPy reals too (np.float32(1.0) was "not a positive number"), as check()'s tolerance
    if too_large_for_float(ransac_px):  # 10**400: math.isfinite's OverflowError
        raise ValueError(
            f"ransac_px: expected a positive number of pixels, got {number_shown(ransac_px)}"
        )
    if not (real_number(ransac_px) and math.isfinite(ransac_px) and ransac_px > 0):
        raise ValueError(f"ransac_px: expected a positive number of pixels, got {ransac_px!r}")
    ransac = float(ransac_px)
    # a 12-bit camera's pair in 16 bits cut to 8 bits kept 0-16 grey levels: "only 0 feature
    # matches (... point the cameras at something textured)" of a textured pair; a dark pair
    # is stretched by one gain, as check_rectification stretches it
    gl, gr = _grey_pair(left, right)
    if gl.shape != gr.shape:
        # a camera mounted on its side gives the other's size turned: resizing is no cure
        turned = gl.shape == gr.shape[::-1]
        raise ValueError(
            f"left is {gl.shape[1]}x{gl.shape[0]} px, right is {gr.shape[1]}x{gr.shape[0]} px: "
            "rectification without a calibration needs one size "
            + (
                "(the right image is the left's turned 90 degrees, a camera mounted on its "
                "side?: turn it back first, cv2.rotate(right, cv2.ROTATE_90_CLOCKWISE or "
                "ROTATE_90_COUNTERCLOCKWISE))"
                if turned
                else "(resize one first)"
            )
        )
    gl, gr = _exposure_matched(gl, gr)  # one view darker (its own auto-exposure): SIFT saw none
    h, w = gl.shape
    pl, dl = _features(gl)
    pr, dr = _features(gr)
    pairs = (
        _mutual_matches(dl, dr)
        if dl is not None and dr is not None and len(pl) >= 2 and len(pr) >= 2
        else np.zeros((0, 2), dtype=np.intp)
    )
    if len(pairs) < MIN_MATCHES:
        raise ValueError(
            f"only {len(pairs)} feature matches between the two images (at least {MIN_MATCHES} "
            "needed): "
            + (
                _mirrored(pl, dl, gr, len(pairs))
                or "point the cameras at something textured that both see"
            )
        )
    p1, p2 = pl[pairs[:, 0]], pr[pairs[:, 1]]
    if float(np.median(np.linalg.norm(p1 - p2, axis=1))) < 0.5:
        raise ValueError("the two images show the same view (no parallax): nothing to rectify")
    try:
        found, mask = cv2.findFundamentalMat(p1, p2, cv2.USAC_MAGSAC, ransac, 0.9999, 10000)
    except cv2.error:
        # OpenCV 5's USAC asserts ("!model.empty()") instead of returning None, also where a
        # model is there to find (Tsukuba with its right image 2 px lower: every USAC method
        # asserted, "0 of 389 matches fit"; 370 fit RANSAC's): then RANSAC's, same threshold
        try:
            found, mask = cv2.findFundamentalMat(p1, p2, cv2.FM_RANSAC, ransac, 0.9999, 10000)
        except cv2.error:
            found, mask = None, None
    inl = np.zeros(len(p1), bool) if mask is None else mask.ravel().astype(bool)
    if found is None or found.shape != (3, 3) or inl.sum() < MIN_MATCHES:
        raise ValueError(
            f"{int(inl.sum())} of {len(p1)} feature matches fit one fundamental matrix (at least "
            f"{MIN_MATCHES} needed): "
            + (_mirrored(pl, dl, gr, len(p1)) or "the views share too little, or a moving scene")
        )
    fm: F64 = np.asarray(found, np.float64)
    p1, p2 = p1[inl], p2[inl]
    # Views that one homography maps onto each other (a camera turned in place, or a flat scene)
    # have no parallax: every F through that homography fits them, and the one found rectifies
    # nothing (a camera turned 1.5 degrees was "rectified", rows 0.03 px, disparities 8-27 px).
    try:
        _, on_plane = cv2.findHomography(p1, p2, cv2.RANSAC, RANSAC_PX, maxIters=2000)
    except cv2.error:
        on_plane = None
    share = 0.0 if on_plane is None else float(np.mean(on_plane))
    if share >= _ONE_HOMOGRAPHY_SHARE:
        raise ValueError(
            f"{100 * share:.0f} % of the {len(p1)} feature matches fit one homography: the views "
            "have no parallax (a camera turned in place, or a flat scene such as a wall), and "
            "give no rows to align; point the cameras at a scene with depth"
        )
    for name, mat in (("left", fm), ("right", fm.T)):
        e = np.linalg.svd(mat)[2][-1]  # mat @ e = 0: the epipole of that image
        if abs(e[2]) > 1e-12:
            ex, ey = e[0] / e[2], e[1] / e[2]
            if 0 <= ex <= w - 1 and 0 <= ey <= h - 1:
                # or a nearly flat scene: OpenCV's chessboard pair 03, side by side (its
                # calibration's epipole at x = -43235), was said to look along its baseline,
                # F placed by the few matches off the board's plane (59 % on it)
                raise ValueError(
                    f"the {name} image's epipole lies at ({ex:.0f}, {ey:.0f}), in the image: "
                    "the cameras look along their baseline (one in front of the other), or the "
                    f"scene is too flat to place it ({100 * share:.0f} % of the {len(p1)} "
                    "matches fit one homography: a board held up to the cameras); no homography "
                    "rectifies the pair from these matches"
                )
    # Two cameras side by side, turned a little (five angles, two focal lengths); Hartley's
    # homographies of F when that does not fit.
    qe_median = math.inf
    if model != "projective":
        h1, h2, qe_median = _quasi_euclidean(p1, p2, w, h)
    used = "quasi-euclidean"
    if model == "quasi-euclidean" and not qe_median <= _QE_MAX_MEDIAN_PX:
        raise ValueError(
            f"two turned cameras do not fit the matches (median residual {qe_median:.2f} px, "
            f"at most {_QE_MAX_MEDIAN_PX} px): use model='projective' or 'auto' (--model "
            "projective or auto)"  # the command line's words too, as the swap refusal's
        )
    if qe_median <= _QE_MAX_MEDIAN_PX:
        ahead = float(np.mean(p1[:, 0] > p2[:, 0]))
        if ahead <= _SWAPPED_SHARE:
            raise ValueError(
                f"left and right look swapped: {100 * ahead:.0f} % of the {len(p1)} feature "
                "matches lie further right in the left image than in the right one (a left "
                "camera's do, nearly all); give the images the other way round (a converging "
                "rig looking past where its axes cross: model='projective', --model projective)"
            )
    else:
        ok, h1_cv, h2_cv = cv2.stereoRectifyUncalibrated(p1, p2, fm, (w, h))
        if not ok:
            raise ValueError("OpenCV found no rectifying homographies for these matches")
        h1, h2 = np.asarray(h1_cv, np.float64), np.asarray(h2_cv, np.float64)
        used = "projective"
    # Orientation: the left image's x and y keep their sense; the right one follows (its rows
    # must stay the left's rows).
    cx, cy = (w - 1) / 2, (h - 1) / 2
    axes = np.array([[cx, cy], [cx + 1, cy], [cx, cy + 1]])
    o, ex_, ey_ = _apply(h1, axes)
    dy = float(np.median(p1[:, 1] - p2[:, 1]))  # > 0: the right camera sees things higher
    along_columns = abs(dy) > _COLUMNS_RATIO * float(np.median(np.abs(p1[:, 0] - p2[:, 0])))
    if abs(ex_[1] - o[1]) > abs(ex_[0] - o[0]) and (along_columns or _epipole_far(fm, w, h)):
        # The rows would be the input's columns, the matches moved along them or the epipole
        # far above or below: cameras one above the other. The flip below then read the sense
        # of x from a component near 0 (cones turned 90 degrees: by its size, disparities
        # inverted with the check "ok", or "mirrored: swapped?"). A camera stepped forward,
        # its epipole near and its matches fanned out, is left to the size's check.
        way, where, seen = (
            ("counter-clockwise", "below", "higher") if dy > 0 else ("clockwise", "above", "lower")
        )
        undo = "COUNTERCLOCKWISE" if dy > 0 else "CLOCKWISE"
        raise ValueError(
            f"the matches lie along the columns, not the rows: the right camera sits {where} "
            f"the left one (things appear {abs(dy):.1f} px {seen} in its image, median); turn "
            f"both images 90 degrees {way} to put it on the right (cv2.rotate(image, "
            f"cv2.ROTATE_90_{undo}))"
        )
    flip = np.diag([1.0 if ex_[0] > o[0] else -1.0, 1.0 if ey_[1] > o[1] else -1.0, 1.0])
    h1, h2 = flip @ h1, flip @ h2
    o, ex_, _ = _apply(h2, axes)
    if ex_[0] <= o[0]:
        # a camera mounted upside down or on its side (cones, right image turned 180 or 90
        # degrees) ended here too, told to swap the images, which does not help
        turn = _turn_deg(p1, p2)
        if turn is not None and abs(turn) > 135:
            raise ValueError(
                f"the right image is upside down against the left one (turned {abs(turn):.0f} "
                "degrees: a camera mounted upside down?): turn it back first "
                "(cv2.rotate(right, cv2.ROTATE_180))"
            )
        if turn is not None and abs(turn) > 45:
            way = "clockwise" if turn > 0 else "counter-clockwise"
            undo = "COUNTERCLOCKWISE" if turn > 0 else "CLOCKWISE"
            raise ValueError(
                f"the right image is turned {abs(turn):.0f} degrees {way} "
                "against the left one (a camera mounted on its side?): turn it back first "
                f"(cv2.rotate(right, cv2.ROTATE_90_{undo}))"
            )
        raise ValueError("the rectified right image would be mirrored: are left and right swapped?")
    h1, h2 = _shear(h1, w, h) @ h1, _shear(h2, w, h) @ h2
    corners = np.column_stack([_corners(w, h), np.ones(4)])
    for name, hom in (("left", h1), ("right", h2)):
        depth = corners @ hom[2]  # the homogeneous scale of each corner
        if not (np.all(depth > 0) or np.all(depth < 0)):
            raise ValueError(
                f"the {name} image would be folded across the horizon (its epipole lies too "
                "close to it): the views differ too much for a rectification by homographies"
            )
    # One scale for both: the matched part of the left image keeps its area. The output holds
    # the rows and columns of the matched part and a margin, within the images: an image whose
    # epipole lies near it is stretched without bound towards the epipole, where nothing is
    # matched anyway.
    r1, r2 = _apply(h1, p1), _apply(h2, p2)
    area = _hull_area(r1)
    if not area > 0:
        raise ValueError("the rectifying homographies collapse the left image")
    s = math.sqrt(_hull_area(p1) / area)
    q1, q2 = _apply(h1, _corners(w, h)), _apply(h2, _corners(w, h))

    def span(lo_img: float, hi_img: float, vals: F64) -> tuple[float, float]:
        lo, hi = float(vals.min()), float(vals.max())
        m = _MARGIN * (hi - lo)
        return max(lo_img, lo - m), min(hi_img, hi + m)

    rows = np.concatenate([r1[:, 1], r2[:, 1]])
    y0, y1 = span(max(q1[:, 1].min(), q2[:, 1].min()), min(q1[:, 1].max(), q2[:, 1].max()), rows)
    x1_hi = span(q1[:, 0].min(), q1[:, 0].max(), r1[:, 0])[1]
    x2_lo, x2_hi = span(q2[:, 0].min(), q2[:, 0].max(), r2[:, 0])
    p_lo, p_hi = np.percentile(r1[:, 0] - r2[:, 0], [_SPAN_PERCENTILE, 100 - _SPAN_PERCENTILE])
    spread = float(p_hi - p_lo)
    low = float(p_lo) - _RANGE_MARGIN * spread
    high = float(p_hi) + _RANGE_MARGIN * spread
    tx2 = -s * x2_lo
    height = math.ceil(s * (y1 - y0))
    # The features say where the textured part of the scene is; a coarse dense match of the
    # pair, shifted so that everything down to three spans below them is in front, says where
    # the rest is (a textureless wall far behind them, a floor up close).
    probe_low = float(p_lo) - 3 * spread - 8 / s
    probe_tx1 = tx2 - s * probe_low
    probe_width = math.ceil(max(s * x1_hi + probe_tx1, s * x2_hi + tx2))
    probe_range = math.ceil(s * (float(p_hi) + 3 * spread - probe_low) + 8)
    probe = _dense_span(gl, gr, h1, h2, s, (probe_tx1, tx2), y0, (probe_width, height), probe_range)
    if probe is not None:
        p_low = min(low, probe_low + probe[0] / s)
        p_high = max(high, probe_low + probe[1] / s)
        # A coarse match that ran to the end of its search found no end there, and a range
        # wider than half the output leaves a matcher little to match: the features' span then.
        # (OpenCV's hand-held books pair: the probe ran to 956 of 960 px, for a range of 697 px
        # on a 575 px wide output; the features' alone: 132-260 px.)
        ran_out = probe[1] >= _PROBE_SCALE * (probe_range / _PROBE_SCALE - 2)
        p_tx1 = tx2 - s * p_low + _LOW_DISPARITY
        p_width = max(s * x1_hi + p_tx1, s * x2_hi + tx2)
        if not ran_out and s * (p_high - p_low) + 2 * _LOW_DISPARITY <= p_width / 2:
            low, high = p_low, p_high
    tx1 = tx2 - s * low + _LOW_DISPARITY
    move1 = np.array([[s, 0, tx1], [0, s, -s * y0], [0, 0, 1.0]])
    move2 = np.array([[s, 0, tx2], [0, s, -s * y0], [0, 0, 1.0]])
    h1, h2 = move1 @ h1, move2 @ h2
    width = math.ceil(max(s * x1_hi + tx1, s * x2_hi + tx2))
    if not (0 < height <= MAX_STRETCH * h and 0 < width <= MAX_STRETCH * w):
        raise ValueError(
            f"the rectified images would be {width}x{height} px from {w}x{h}: the views hardly "
            "differ, or the epipole lies near the image; rectification needs cameras side by side"
        )
    r1, r2 = _apply(h1, p1), _apply(h2, p2)
    ady = np.abs(r1[:, 1] - r2[:, 1])
    disp = r1[:, 0] - r2[:, 0]
    lo, hi = (float(v) for v in np.percentile(disp, [_SPAN_PERCENTILE, 100 - _SPAN_PERCENTILE]))
    max_disp = max(16, math.ceil(s * (high - low) + 2 * _LOW_DISPARITY))
    shapes = [_shape(hm, w, h) for hm in (h1, h2)]
    return UncalibratedRectification(
        H1=h1 / h1[2, 2],
        H2=h2 / h2[2, 2],
        size=(width, height),
        input_size=(w, h),
        F=fm,
        matches=len(p1),
        median_dy=float(np.median(ady)),
        p95_dy=float(np.percentile(ady, 95)),
        disparity_range=(lo, hi),
        max_disparity=max_disp,
        skew_deg=(shapes[0][0], shapes[1][0]),
        aspect=(shapes[0][1], shapes[1][1]),
        model=used,
    )
