"""Is a rig still rectified? Row alignment of a pair measured from its features, no chessboard.

A bump, heat or a loose mount turns one camera by a fraction of a degree and the calibration no
longer rectifies: matched features stop lying on the same row, and every row-searching matcher
(ours, OpenCV's, ROS's) loses accuracy quickly (rows 2.4 px apart raise the default depth
map's bad-2.0 on Middlebury cones from 7.6 to 39.8 %). :func:`check_rectification` measures it
on any textured pair: SIFT features on the rectified pair, mutual nearest matches with Lowe's ratio
test, then a robust fit of the row offset ``dy = a + b (x - cx) + c (y - cy)`` (``a``: a pitch
between the cameras; ``b``: a roll; ``c``: a focal-length or pitch difference).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    as_gray_uint8,
    as_image_array,
    number_shown,
    real_number,
    remap_image,
    too_large_for_float,
)
from stereovision._validate import require as _require_type
from stereovision.calibration import Calibration, _check_alpha

__all__ = [
    "RectificationCheck",
    "align_rows",
    "already_rectified",
    "check_rectification",
    "draw_rectification_check",
    "refine_rectification",
]

#: Median row error (px) of the matched features up to which a pair counts as rectified.
DEFAULT_TOLERANCE_PX = 0.5
#: Fewest consistent matches for a verdict.
MIN_MATCHES = 30
#: SIFT runs on a copy at most this wide or tall (its coordinates scaled back).
_MAX_SIDE = 1600
_RATIO = 0.75
_INLIER_PX = 1.0
_RANSAC_ROUNDS = 400
#: Rows of the first descriptors per block of :func:`_mutual_matches`' distances (16 MB).
_MATCH_ROWS = 1024


@dataclass(frozen=True)
class RectificationCheck:
    """Row alignment of a rectified pair (:func:`check_rectification`).

    Attributes
    ----------
    matches : int
        Feature matches consistent with one row-offset model (the fit's inliers).
    median_dy, p95_dy : float
        Median and 95th percentile of ``|y_left - y_right|`` over those matches (px).
    offset : float
        Fitted row offset at the image centre, ``y_left - y_right`` (px).
    slope_x, slope_y : float
        Fitted change of the offset per 1000 px along x (a roll between the cameras) and y.
    ok : bool or None
        ``median_dy <= tolerance``; None when fewer than ``MIN_MATCHES`` matches were found
        (too little texture to tell), or the two images are identical.
    tolerance : float
        The tolerance used (px).
    swapped : bool
        Most matches have a negative disparity: the left and right images look swapped.
    identical : bool
        The two images are the same pixels (one file or one camera twice): every feature
        matches itself on its own row, so ``ok`` is None (cannot tell), not True.
    points : ndarray, float32 (N, 4)
        The matches the figures are over, ``[x_left, y_left, x_right, y_right]`` in the
        rectified pair (for :func:`draw_rectification_check`; not in :meth:`as_dict`).
    size : tuple of int or None
        ``(width, height)`` of the pair checked, px (:func:`align_rows` refuses a pair of
        another size; not in :meth:`as_dict`); None for a check made by hand.

    Notes
    -----
    When the matches fit no common row model (a pair far from rectified) ``offset`` and the
    slopes are NaN and ``median_dy`` is over all matches.
    """

    matches: int
    median_dy: float
    p95_dy: float
    offset: float
    slope_x: float
    slope_y: float
    ok: bool | None
    tolerance: float
    swapped: bool = False
    identical: bool = False
    points: npt.NDArray[np.float32] = field(
        default_factory=lambda: np.zeros((0, 4), np.float32), repr=False, compare=False
    )
    size: tuple[int, int] | None = field(default=None, repr=False, compare=False)

    def as_dict(self) -> dict[str, Any]:
        """The fields as a JSON-ready dict (NaN as None).

        Returns
        -------
        dict
            Field name to value, ``points`` and ``size`` left out.
        """
        out: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name not in ("points", "size"):
                out[f.name] = None if isinstance(v, float) and not np.isfinite(v) else v
        return out

    def rows_agree(self) -> str:
        """How the rows agree, for a pair used as given (:func:`already_rectified`):
        ``"rows median |dy| 0.08 px over 412 matches, tolerance 0.5"``.

        Returns
        -------
        str
            One line.
        """
        return (
            f"rows median |dy| {self.median_dy:.2f} px over {self.matches} matches, tolerance "
            f"{self.tolerance:g}"
        )

    def summary(self) -> str:
        """One line for a log or a terminal.

        Returns
        -------
        str
            The verdict (ok, NOT rectified, swapped, cannot tell) and the figures behind it.
        """
        if self.identical:
            return (
                "rectification: cannot tell, the two images are identical (the same file, or "
                "one camera twice?)"
            )
        if self.ok is None:
            return (
                f"rectification: cannot tell, only {self.matches} feature matches "
                f"(at least {MIN_MATCHES} needed: point the cameras at something textured)"
            )
        if self.swapped:
            return (
                f"rectification: the left and right images look swapped (most of "
                f"{self.matches} feature matches have a negative disparity)"
            )
        # "rectification NOT rectified" said it twice: the pair is what is not rectified
        verdict = "rectification ok" if self.ok else "pair NOT rectified"
        if not np.isfinite(self.offset):
            return (
                f"{verdict}: median |dy| {self.median_dy:.1f} px over "
                f"{self.matches} matches, which fit no common row offset"
            )
        return (
            f"{verdict}: median |dy| {self.median_dy:.2f} px (95 % "
            f"{self.p95_dy:.2f}, tolerance {self.tolerance:g}) over {self.matches} matches; "
            f"offset {self.offset:+.2f} px, roll {self.slope_x:+.2f} px per 1000 px"
        )


def _features(gray: npt.NDArray[np.uint8]) -> tuple[npt.NDArray[np.float64], np.ndarray | None]:
    h, w = gray.shape
    s = min(1.0, _MAX_SIDE / max(h, w))
    size = (max(1, round(w * s)), max(1, round(h * s)))
    img = gray if s == 1.0 else cv2.resize(gray, size, interpolation=cv2.INTER_AREA)
    sift = cv2.SIFT.create(nfeatures=4000)
    kps, desc = sift.detectAndCompute(img, None)
    pts = np.array([k.pt for k in kps], dtype=np.float64).reshape(-1, 2)
    if s != 1.0:  # pixel centres, each axis by its own rounded scale: x + 0.5 = (x' + 0.5) w / w'
        pts = (pts + 0.5) * np.array([w / size[0], h / size[1]]) - 0.5
    return pts, desc


def _mutual_matches(da: np.ndarray, db: np.ndarray) -> npt.NDArray[np.intp]:
    """Mutual nearest matches ``[[i_a, i_b], ...]`` (in ``i_a`` order) passing Lowe's ratio
    test, exactly as OpenCV's ``BFMatcher(NORM_L2)`` ``knnMatch`` both ways finds them.

    SIFT's descriptors are whole numbers 0-255: their squared distances are whole numbers
    below 2**24, which float32 holds exactly whatever the order of the sums, so one matrix
    product gives OpenCV's very distances (``sqrt`` in float32, as its ``std::sqrt``), and
    ``argmin``'s first index its tie break (a later index replaces only a strictly smaller
    distance). BFMatcher's two passes took 0.68 s CPU of KITTI's 1.25 s check, this 0.25 s;
    descriptors that are not whole numbers 0-255 still go through it.
    """
    if not (_whole_bytes(da) and _whole_bytes(db) and len(da) >= 1 and len(db) >= 2):
        return _mutual_matches_bf(da, db)
    a = np.ascontiguousarray(da, dtype=np.float32)
    b = np.ascontiguousarray(db, dtype=np.float32)
    na, nb = (a * a).sum(axis=1), (b * b).sum(axis=1)
    best = np.empty(len(a), dtype=np.intp)  # the nearest b of each a
    ratio_ok = np.empty(len(a), dtype=bool)
    back_d = np.full(len(b), np.inf, dtype=np.float32)  # the nearest a of each b, so far
    back = np.full(len(b), -1, dtype=np.intp)
    rows = np.arange(_MATCH_ROWS)
    for start in range(0, len(a), _MATCH_ROWS):  # in blocks: 4000 x 4000 distances are 64 MB
        stop = min(start + _MATCH_ROWS, len(a))
        d = a[start:stop] @ b.T
        d *= -2.0
        d += na[start:stop, None]
        d += nb[None, :]
        np.sqrt(np.maximum(d, 0.0, out=d), out=d)
        col, col_d = d.argmin(axis=0), d.min(axis=0)
        closer = col_d < back_d  # strictly: an earlier block keeps a tie, as OpenCV's scan
        back_d[closer] = col_d[closer]
        back[closer] = col[closer] + start
        r = rows[: stop - start]
        j0 = d.argmin(axis=1)
        d0 = d[r, j0].astype(np.float64)
        d[r, j0] = np.inf
        d1 = d.min(axis=1).astype(np.float64)  # the second smallest, a tie of d0 included
        best[start:stop] = j0
        ratio_ok[start:stop] = d0 < _RATIO * d1
    ia = np.flatnonzero(ratio_ok & (back[best] == np.arange(len(a))))
    return np.column_stack([ia, best[ia]]).astype(np.intp).reshape(-1, 2)


def _whole_bytes(desc: np.ndarray) -> bool:
    """Descriptors whose values are all whole numbers 0-255 (SIFT's, stored as float32)."""
    d = np.asarray(desc)
    return (
        d.ndim == 2
        and d.shape[1] <= 128
        and bool(np.all((d >= 0) & (d <= 255) & (d == np.floor(d))))
    )


def _mutual_matches_bf(da: np.ndarray, db: np.ndarray) -> npt.NDArray[np.intp]:
    """:func:`_mutual_matches` through OpenCV's brute-force matcher (any descriptors)."""
    bf = cv2.BFMatcher(cv2.NORM_L2)
    fwd = bf.knnMatch(da, db, k=2)
    back = {m[0].queryIdx: m[0].trainIdx for m in bf.knnMatch(db, da, k=1) if m}
    pairs = [
        (m[0].queryIdx, m[0].trainIdx)
        for m in fwd
        if len(m) == 2
        and m[0].distance < _RATIO * m[1].distance
        and back.get(m[0].trainIdx) == m[0].queryIdx
    ]
    return np.array(pairs, dtype=np.intp).reshape(-1, 2)


def _robust_fit(
    a: npt.NDArray[np.float64], dy: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
    # RANSAC over 3-match samples with a fixed seed (the same pair gives the same answer), then
    # least squares on the largest consensus set.
    rng = np.random.default_rng(0)
    n = len(dy)
    best = np.zeros(n, dtype=bool)
    for _ in range(_RANSAC_ROUNDS):
        idx = rng.choice(n, 3, replace=False)
        try:
            coef = np.linalg.solve(a[idx], dy[idx])
        except np.linalg.LinAlgError:
            continue
        inl = np.abs(a @ coef - dy) <= _INLIER_PX
        if inl.sum() > best.sum():
            best = inl
    fit: npt.NDArray[np.float64] = np.asarray(
        np.linalg.lstsq(a[best], dy[best], rcond=None)[0], dtype=np.float64
    )
    return fit, np.abs(a @ fit - dy) <= _INLIER_PX


def check_rectification(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    calib: Calibration | None = None,
    *,
    tolerance: float = DEFAULT_TOLERANCE_PX,
    alpha: float = 0.0,
) -> RectificationCheck:
    """Measure how far the features of a pair lie off each other's rows after rectification.

    Parameters
    ----------
    left, right : array_like
        A raw pair (rectified with ``calib`` first) or, without ``calib``, a rectified pair;
        grey or colour, any dtype the package reads. A dark pair (brightest grey under a
        quarter of the range: a 12-bit camera's data in 16 bits) is stretched by one gain
        for its features.
    calib : Calibration, optional
        The rig's calibration; omit it for a pair that is already rectified.
    tolerance : float
        Median ``|dy|`` (px) up to which the pair counts as rectified.
    alpha : float
        Rectification scaling, as in :meth:`Calibration.rectify`.

    Returns
    -------
    RectificationCheck
        ``ok`` True / False, or None when the pair has too little texture to tell or its two
        images are identical (``identical``).

    Raises
    ------
    TypeError
        If ``calib`` is given and is not a :class:`~stereovision.Calibration` (a file name:
        load it with ``Calibration.load``; homographies of
        :func:`~stereovision.uncalibrated.rectify_uncalibrated`: their own ``check``).
    ValueError
        Images that are not images, of different sizes or of the wrong size for ``calib``, or
        a tolerance that is not a positive number (Python or NumPy real).
    """
    # 10**400: np.isfinite's bare TypeError "ufunc 'isfinite' not supported", naming nothing
    if (
        too_large_for_float(tolerance)
        or not real_number(tolerance)
        or not (np.isfinite(tolerance) and tolerance > 0)
    ):
        raise ValueError(
            f"tolerance: expected a positive number of pixels, got {number_shown(tolerance)}"
        )
    _check_alpha(alpha)  # also without a calibration (it took any alpha without a word)
    if calib is not None:
        _not_homographies(calib, "its own check(left, right) checks a raw pair through them")
        _require_type(calib, "Calibration", "calib")
        left, right = calib.rectify(left, right, alpha=alpha)
    gl, gr = _grey_pair(left, right)
    if gl.shape != gr.shape:
        (hl, wl), (hr, wr) = gl.shape, gr.shape
        raise ValueError(_two_sizes(wl, hl, wr, hr))
    h, w = gl.shape
    tol = float(tolerance)
    if gl.min() < gl.max() and np.array_equal(gl, gr):
        # every feature matched itself at its own row: "rectification ok, median |dy| 0.00 px"
        # of one image twice (the library, the stream and the GUI said nothing else); a blank
        # pair (lens caps) is told to point the cameras at texture, as before
        nan = float("nan")
        return RectificationCheck(
            0, nan, nan, nan, nan, nan, None, tol, identical=True, size=(w, h)
        )
    from stereovision.uncalibrated import _exposure_matched

    # two exposures (each camera its own auto-exposure): the darker view kept too few SIFT
    # features, so a rectified pair was "cannot tell" and rectify warped it (as f9e666ed)
    gl, gr = _exposure_matched(gl, gr)
    pl, dl = _features(gl)
    pr, dr = _features(gr)
    pairs = (
        _mutual_matches(dl, dr)
        if dl is not None and dr is not None and len(pl) >= 2 and len(pr) >= 2
        else np.zeros((0, 2), dtype=np.intp)
    )
    xl, yl = pl[pairs[:, 0]].T
    xr, yr = pr[pairs[:, 1]].T
    return _judge_rows(np.column_stack([xl, yl, xr, yr]), w, h, tol)


def _not_homographies(calib: object, what: str) -> None:
    """A TypeError saying ``what`` to do with an
    :class:`~stereovision.uncalibrated.UncalibratedRectification` given as ``calib``: "expected
    a stereovision.Calibration, got UncalibratedRectification" did not say where its check is
    (``depth_map`` takes one as ``calib``, so it was passed here too)."""
    from stereovision.uncalibrated import UncalibratedRectification

    if isinstance(calib, UncalibratedRectification):
        raise TypeError(
            "calib: expected a stereovision.Calibration, got an UncalibratedRectification "
            f"(homographies found without a calibration): {what}"
        )


def _two_sizes(wl: int, hl: int, wr: int, hr: int) -> str:
    """The refusal of a pair of two sizes; one the other's turned is named as a camera mounted
    on its side, as rectify_uncalibrated names it (rectify and depth said only "have one
    size", rectify before rectify_uncalibrated could say more)."""
    turned = (
        " (the right image is the left's size turned 90 degrees: a camera mounted on its side? "
        "turn it back first)"
        if (wl, hl) == (hr, wr)
        else ""
    )
    return (
        f"left is {wl}x{hl} px, right is {wr}x{hr} px: the two images of a pair have one size"
        f"{turned}"
    )


def _grey_pair(
    left: npt.ArrayLike, right: npt.ArrayLike
) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
    """The pair's 8-bit grey images for SIFT; a dark pair (a 12-bit camera's data in 16 bits)
    stretched by one gain, as ``depth_map``'s automatic range stretches it: cut to 8 bits it
    kept 0-16 grey levels, no features, and the check said "cannot tell, only 0 feature
    matches (... point the cameras at something textured)" of a textured pair."""
    fl, fr, gain = _dark_pair_gain(left, right)
    if gain is None:  # the others as before: OpenCV's grey of an 8-bit image
        return as_gray_uint8(left, "left"), as_gray_uint8(right, "right")
    gain = np.float32(255.0 * gain)
    return np.rint(fl * gain).astype(np.uint8), np.rint(fr * gain).astype(np.uint8)


def _dark_pair_gain(
    left: npt.ArrayLike, right: npt.ArrayLike
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32], np.float32 | None]:
    """The pair's grey images in [0, 1] and the gain that brings its brightest grey to 1 when
    the pair is dark (under ``depth._DARK_PAIR`` of the range); None for the others."""
    from stereovision._validate import as_gray_float
    from stereovision.depth import _DARK_PAIR

    fl = as_gray_float(left, "left", warn=False)
    fr = as_gray_float(right, "right", warn=False)
    top = max(float(fl.max()), float(fr.max())) if fl.shape == fr.shape else 1.0
    return fl, fr, np.float32(1.0 / top) if 0.0 < top < _DARK_PAIR else None


def _judge_rows(quad: npt.NDArray[np.float64], w: int, h: int, tol: float) -> RectificationCheck:
    """The check's rule on matched points ``[x_left, y_left, x_right, y_right]`` of a rectified
    ``w`` x ``h`` pair: fewer than :data:`MIN_MATCHES` cannot tell; matches near their rows at a
    disparity not well below zero are fitted one row-offset model, whose inliers (within 1 px)
    give the verdict; swapped when most lie on common rows at negative disparities."""
    quad = np.asarray(quad, np.float64).reshape(-1, 4)
    nan = float("nan")
    if len(quad) < MIN_MATCHES:
        return RectificationCheck(len(quad), nan, nan, nan, nan, nan, None, tol, size=(w, h))
    xl, yl, xr, yr = quad.T
    dy, dx = yl - yr, xl - xr
    # A rectified side-by-side rig: a match far off its row, or with a disparity well below
    # zero, is a wrong match, not drift, unless most matches are like that.
    near_row = np.abs(dy) <= 0.1 * h
    keep = near_row & (dx >= -max(8.0, 0.02 * w))
    a = np.column_stack([np.ones(len(dy)), (xl - (w - 1) / 2) / 1000, (yl - (h - 1) / 2) / 1000])
    # Swapped: most matches near their rows have a negative disparity, and those lie on common
    # rows (the pair is rectified the other way round). Matches merely within 10 % of the
    # height of their rows, at negative disparities, are an unrectified pair (OpenCV's
    # hand-held books: 66 of 107 at median |dy| 24 px, only 23 on a common row model).
    neg = near_row & (dx < -1.0)
    swapped = bool(near_row.sum() >= MIN_MATCHES and (dx[near_row] < -1.0).mean() > 0.5)
    if swapped:
        neg_inl = _robust_fit(a[neg], dy[neg])[1]
        swapped = bool(neg_inl.sum() >= MIN_MATCHES and neg_inl.mean() > 0.5)
    inl = np.zeros(len(dy), dtype=bool)
    coef = np.full(3, nan)
    if keep.sum() >= MIN_MATCHES:
        coef, fit_inl = _robust_fit(a[keep], dy[keep])
        inl[np.flatnonzero(keep)[fit_inl]] = True
    pts = quad.astype(np.float32)
    if inl.sum() >= MIN_MATCHES and not swapped:
        ady = np.abs(dy[inl])
        med = float(np.median(ady))
        return RectificationCheck(
            int(inl.sum()),
            med,
            float(np.percentile(ady, 95)),
            float(coef[0]),
            float(coef[1]),
            float(coef[2]),
            med <= tol,
            tol,
            points=pts[inl],
            size=(w, h),
        )
    # Plenty of matches, but not on a common row model (a pair far from rectified, or not a
    # side-by-side pair at all) or mostly at negative disparities: not rectified.
    ady = np.abs(dy)
    return RectificationCheck(
        len(quad),
        float(np.median(ady)),
        float(np.percentile(ady, 95)),
        nan,
        nan,
        nan,
        False,
        tol,
        swapped=swapped,
        points=pts,
        size=(w, h),
    )


def already_rectified(left: npt.ArrayLike, right: npt.ArrayLike) -> RectificationCheck | None:
    """The pair's own rows check when its features already lie on common rows, else None.

    Such a pair (a rectified dataset, a camera that rectifies on board) needs no rectification
    from its features: homographies fitted to those same rows only resample it and change its
    size. ``stereovision rectify`` without ``--calib`` and the GUI's "Rectify" use it as given.

    Parameters
    ----------
    left, right : array_like
        The pair as it comes (no calibration).

    Returns
    -------
    RectificationCheck or None
        The passing check (:func:`check_rectification`); None when the rows are apart, there
        is too little texture to tell, or the images look swapped.
    """
    check = check_rectification(left, right)
    return check if check.ok is True and not check.swapped else None


#: :func:`draw_rectification_check`'s dimming of the pair under its dots, grey level -> level.
_DIM = (np.arange(256) * 0.7).astype(np.uint8)


def draw_rectification_check(
    left: npt.ArrayLike, right: npt.ArrayLike, check: RectificationCheck
) -> npt.NDArray[np.uint8]:
    """The rectified pair side by side with the check's matches, coloured by their row error.

    Each match is a dot in both images (a dark pair stretched as :func:`check_rectification`
    stretches it), green where ``|dy|`` is within the tolerance, yellow up to 3 times it, red
    beyond; in the left image a tick from the dot shows ``10 dy`` (where the
    right image has the feature, ten times magnified). Faint lines every 40 px mark rows.

    Parameters
    ----------
    left, right : array_like
        The *rectified* pair the check ran on (``calib.rectify(left, right)`` for a raw rig).
    check : RectificationCheck
        Its result.

    Returns
    -------
    numpy.ndarray
        ``(H + band, 2 W, 3)`` BGR ``uint8`` image, the summary in a band above the pair.

    Raises
    ------
    ValueError
        Images that are not images, of different sizes, or of another size than the pair
        ``check`` was made on.
    """
    from stereovision._validate import _to_unit_float, as_bgr_uint8

    gain = _dark_pair_gain(left, right)[2]
    if gain is None:
        lb, rb = as_bgr_uint8(left, "left"), as_bgr_uint8(right, "right")
    else:
        # a dark pair (12-bit data in 16 bits) drawn as it is was black; stretched by the
        # check's gain, the picture shows what its features are on
        lb, rb = (
            as_bgr_uint8(np.clip(_to_unit_float(as_image_array(im, n), n, False) * gain, 0, 1), n)
            for im, n in ((left, "left"), (right, "right"))
        )
    if lb.shape != rb.shape:
        # NumPy's concatenation error named neither image ("along dimension 1, the array at
        # index 0 has size 120"), and a narrower right image was found only at the band
        (hl, wl), (hr, wr) = lb.shape[:2], rb.shape[:2]
        raise ValueError(
            f"left is {wl}x{hl} px, right is {wr}x{hr} px: the two images of a pair have one size"
        )
    h, w = lb.shape[:2]
    if check.size is not None and check.size != (w, h):
        # its dots are at the checked pair's pixels: a full-size check over a half-size copy
        # put 327 of cones' 523 left dots past the left image, into the right one
        raise ValueError(
            f"check: made on a {check.size[0]}x{check.size[1]} px pair, the pair is {w}x{h} "
            "px: draw the pair that was checked"
        )
    canvas = np.concatenate([lb, rb], axis=1)
    # dimmed to 0.7 by a table: ``canvas * 0.7`` made a float64 copy of the whole picture
    # (576 MB for a 12 MP pair side by side), for the same grey levels
    canvas = cv2.LUT(canvas, _DIM)
    for y in range(20, h, 40):
        cv2.line(canvas, (0, y), (2 * w - 1, y), (200, 200, 200), 1, cv2.LINE_AA)
    tol = check.tolerance
    for xl, yl, xr, yr in check.points:
        e = abs(float(yl - yr))
        colour = (0, 200, 0) if e <= tol else (0, 220, 255) if e <= 3 * tol else (0, 0, 255)
        # each match a dot in both images, and in the left one a tick ten times its row error
        pl = (round(float(xl)), round(float(yl)))
        pr = (round(float(xr)) + w, round(float(yr)))
        cv2.line(canvas, pl, (pl[0], round(float(yl + 10 * (yr - yl)))), colour, 1, cv2.LINE_AA)
        cv2.circle(canvas, pl, 2, colour, -1, cv2.LINE_AA)
        cv2.circle(canvas, pr, 2, colour, -1, cv2.LINE_AA)
    # the summary above the pair, wrapped to its width
    font, scale = cv2.FONT_HERSHEY_SIMPLEX, 0.5
    lines: list[str] = []
    for word in check.summary().split(" "):
        trial = f"{lines[-1]} {word}" if lines else word
        if lines and cv2.getTextSize(trial, font, scale, 1)[0][0] <= 2 * w - 16:
            lines[-1] = trial
        else:
            lines.append(word)
    band = np.full((8 + 20 * len(lines), 2 * w, 3), 255, np.uint8)
    for i, line in enumerate(lines):
        cv2.putText(band, line, (8, 20 + 20 * i), font, scale, (0, 0, 0), 1, cv2.LINE_AA)
    canvas = np.concatenate([band, canvas], axis=0)
    return canvas


#: Largest turn (degrees) :func:`refine_rectification` makes: more is not a drift.
MAX_CORRECTION_DEG = 3.0


def _turn_rows(
    q: npt.NDArray[np.float64], w: npt.NDArray[np.float64], fy: float, cy: float
) -> npt.NDArray[np.float64]:
    """Rows of the rays ``q`` (3, N) after turning them by ``Rodrigues(w)``."""
    r = cv2.Rodrigues(w.reshape(3, 1))[0]
    p = r @ q
    out: npt.NDArray[np.float64] = fy * p[1] / p[2] + cy
    return out


def refine_rectification(
    left: npt.ArrayLike,
    right: npt.ArrayLike,
    calib: Calibration,
    *,
    tolerance: float = DEFAULT_TOLERANCE_PX,
    alpha: float = 0.0,
    check: RectificationCheck | None = None,
) -> tuple[Calibration, RectificationCheck]:
    """Correct a rig's rotation from one textured pair, so that its rows line up again.

    A bump or heat turns a camera by a fraction of a degree: its pitch and roll relative to the
    other camera put features off each other's rows (:func:`check_rectification`). This fits
    the small turn ``dR`` (about the rectified x axis, pitch, and the optical axis, roll) of
    the right camera that brings the matched features of the rectified pair onto their rows
    (Gauss-Newton on the rows of the turned rays, twice, the second time without the matches
    off by more than 1 px), then updates the rig: with the rectifying rotation ``R2`` of the
    old calibration, ``R' = R2^T dR^T R2 R`` and ``T' = R2^T dR^T R2 T`` (the baseline keeps
    its length). A turn about the vertical axis (yaw) changes disparities, not rows, so one
    pair cannot tell it: it is left as it was, and with it the depth scale.

    Parameters
    ----------
    left, right : array_like
        A raw pair of the rig (for a ``rectified`` calibration: the rectified pair).
    calib : Calibration
        The calibration to correct.
    tolerance : float
        As in :func:`check_rectification`, for the check after the correction.
    alpha : float
        Rectification scaling, as in :meth:`Calibration.rectify`.
    check : RectificationCheck, optional
        :func:`check_rectification` of this pair with ``calib`` and ``alpha``, when already
        computed; else it is run here.

    Returns
    -------
    tuple
        ``(corrected Calibration, RectificationCheck after the correction)``. The corrected
        calibration is not ``rectified`` (its ``R`` is no longer the identity).

    Raises
    ------
    TypeError
        If ``calib`` is not a :class:`~stereovision.Calibration` (homographies of
        :func:`~stereovision.uncalibrated.rectify_uncalibrated` included: no rig to correct).
    ValueError
        Too little texture, a pair that looks swapped or fits no row model, a correction of
        more than :data:`MAX_CORRECTION_DEG` degrees (not a drift: calibrate again), or a
        ``check`` made on a pair of another size than the calibration's images.
    """
    _not_homographies(
        calib, "they have no rig to correct; rectify_uncalibrated finds them anew from a pair"
    )
    _require_type(calib, "Calibration", "calib")
    # before rectified_calibration(alpha), which takes any finite scaling (OpenCV's -1)
    _check_alpha(alpha)
    from dataclasses import replace

    if check is not None and check.size is not None and check.size != calib.image_size:
        # its points are another pair's pixels: a check of cones' half-size copy (rows 1 px
        # apart there) turned the full-size rig by that copy's rows, and the "fixed" rig was
        # still 1.07 px off (2 px before), without a word
        (cw, ch), (iw, ih) = check.size, calib.image_size
        raise ValueError(
            f"check: made on a {cw}x{ch} px pair, the calibration's images are {iw}x{ih} px: "
            "check the pair that is refined"
        )
    before = (
        check
        if check is not None
        else check_rectification(left, right, calib, tolerance=tolerance, alpha=alpha)
    )
    if before.ok is None:
        raise ValueError(f"cannot refine: {before.summary()}")
    if before.swapped or not np.isfinite(before.offset):
        raise ValueError(f"cannot refine: {before.summary()}")
    rc = calib.rectified_calibration(alpha) if not calib.rectified else calib
    k2 = rc.K2
    xl, yl, xr, yr = before.points.astype(np.float64).T
    q = np.linalg.solve(k2, np.vstack([xr, yr, np.ones_like(xr)]))
    fy, cy = float(k2[1, 1]), float(k2[1, 2])
    keep = np.ones(len(xl), dtype=bool)
    w = np.zeros(3)
    for _ in range(2):
        for _ in range(10):
            base = _turn_rows(q[:, keep], w, fy, cy) - yl[keep]
            jac = np.empty((int(keep.sum()), 2))
            for j, axis in enumerate((0, 2)):
                step = np.zeros(3)
                step[axis] = 1e-7
                jac[:, j] = (_turn_rows(q[:, keep], w + step, fy, cy) - yl[keep] - base) / 1e-7
            delta = np.linalg.lstsq(jac, -base, rcond=None)[0]
            w[[0, 2]] += delta
            if np.abs(delta).max() < 1e-10:
                break
        keep = np.abs(_turn_rows(q, w, fy, cy) - yl) <= 1.0
        if keep.sum() < MIN_MATCHES:
            raise ValueError(f"cannot refine: {int(keep.sum())} matches fit a turn within 1 px")
    turn = float(np.degrees(np.linalg.norm(w)))
    if turn > MAX_CORRECTION_DEG:
        raise ValueError(
            f"the rows need the right camera turned by {turn:.1f} degrees, more than a drift "
            f"(at most {MAX_CORRECTION_DEG:g}): calibrate the rig again"
        )
    d_r = cv2.Rodrigues(w.reshape(3, 1))[0]
    r2 = np.eye(3) if calib.rectified else calib._stereo_rectify(alpha)[1]
    turn_rig = r2.T @ d_r.T @ r2
    fixed = replace(
        calib,
        R=turn_rig @ calib.R,
        T=turn_rig @ calib.T,
        rectified=False,
        doffs=None,
    )
    after = check_rectification(left, right, fixed, tolerance=tolerance, alpha=alpha)
    return fixed, after


def align_rows(
    left: npt.ArrayLike, right: npt.ArrayLike, check: RectificationCheck | None = None
) -> tuple[npt.NDArray[Any], RectificationCheck]:
    """Resample the right image of a rectified pair so that its rows match the left image's.

    For a pair whose calibration cannot be corrected (a dataset's rectified images, or a
    camera that rectifies on board): the fitted row offset ``dy = a + b x + c y`` of
    :func:`check_rectification` is undone by moving the right image's content by ``dy``
    (bicubic), refitted to the check's matches at the right image's columns (where its pixels
    are moved; the check's ``offset`` is at the left image's). The left image, and so the
    disparity map's frame, stay as they are.

    Parameters
    ----------
    left, right : array_like
        The rectified pair.
    check : RectificationCheck, optional
        Its check, when already computed; else it is run here.

    Returns
    -------
    tuple
        ``(right_aligned, check)``: the right image (same shape and dtype; a float image
        within its own range, bicubic's overshoot clipped) and the check it was aligned by.
        The right image is returned unchanged when the check found no common row model (too
        little texture, or far from rectified).

    Raises
    ------
    ValueError
        A ``check`` made on a pair of another size than ``right`` (its row model's offsets
        and slopes are of that pair).
    """
    ra = as_image_array(right, "right")
    res = check if check is not None else check_rectification(left, right)
    if res.size is not None and res.size != (ra.shape[1], ra.shape[0]):
        # its row model (offsets about the centre of the pair it was fitted on) moved the rows
        # of a half-size pair by a full-size pair's offsets: 0.9 px apart, without a word
        raise ValueError(
            f"check: made on a {res.size[0]}x{res.size[1]} px pair, the right image is "
            f"{ra.shape[1]}x{ra.shape[0]} px: check the pair that is aligned"
        )
    if res.ok is None or not np.isfinite(res.offset):
        return ra, res
    h, w = ra.shape[:2]
    coef = np.array([res.offset, res.slope_x, res.slope_y])
    if len(res.points) >= MIN_MATCHES:
        # The check fits dy at the left image's x; the remap below moves the right image's
        # pixel at its own x, a disparity to the left of where its feature is in the left
        # image. Fitted at the left x, the roll's term was a slope times the disparity off
        # (art turned 0.6 degrees: 11 px per 1000 px x 46 px = 0.5 px of rows left apart).
        # Refitted at the right x (and the left row, where the aligned content lands).
        _, yl, xr, yr = np.asarray(res.points, np.float64).T
        a = np.column_stack(
            [np.ones(len(xr)), (xr - (w - 1) / 2) / 1000, (yl - (h - 1) / 2) / 1000]
        )
        coef = np.linalg.lstsq(a, yl - yr, rcond=None)[0]
    xx, yy = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
    dy = coef[0] + coef[1] * (xx - (w - 1) / 2) / 1000 + coef[2] * (yy - (h - 1) / 2) / 1000
    out = remap_image(
        ra, xx, (yy - dy).astype(np.float32), cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE
    )
    if ra.dtype.kind == "f" and np.isfinite(ra).any():
        # bicubic overshoots an edge (a float [0, 1] pair: -0.06 .. 1.12), which the matchers
        # then refused as out of range: kept within the right image's own range
        out = np.clip(out, np.nanmin(ra), np.nanmax(ra))
    # cv2.remap drops the channel axis of an (H, W, 1) image: given back in the right's shape
    return out.reshape(ra.shape), res
