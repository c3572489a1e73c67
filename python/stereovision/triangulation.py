"""Stereo triangulation: Bouguet's midpoint method and the rectified shortcut (algorithms.md E).

* :func:`triangulate` -- unrectified pixel correspondences to 3-D points (E.2): normalise and
  undistort each point by fixed-point iteration, intersect the two rays in the least-squares
  sense, take the midpoint of the closest points.
* :func:`depth_from_disparity` / :func:`reproject` -- rectified disparity to depth / points
  (E.3): ``Z = f B / (d + doffs)``, ``X = (x - cx) Z / f``, ``Y = (y - cy) Z / fy``.

Frames: points are in the left camera frame (rectified left camera for the shortcut), X right,
Y down, Z forward; ``X_R = R X_L + T``. Output lengths are in metres unless ``unit`` says
otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from stereovision._validate import (
    _real_array,
    _refuse_masked,
    _shown,
    int_in_range,
    known_unit,
    positive_finite,
)
from stereovision._validate import require as _require_type
from stereovision.calibration import UNIT_TO_METRES, Calibration

__all__ = [
    "FISHEYE_ROUND_TRIP_PX",
    "PARALLEL_SIN2_TOL",
    "RESIZED_MIN_SIDE",
    "UNDISTORT_MAX_ITER",
    "UNDISTORT_TOL",
    "TriangulationResult",
    "depth_from_disparity",
    "reproject",
    "triangulate",
    "undistort_normalized",
]

#: Fixed-point undistortion stops when the update is below this (normalised image units,
#: algorithms.md E.2: ``< 1e-12``).
UNDISTORT_TOL = 1e-12
#: Iteration cap of the undistortion; points still moving after it are flagged (the toolbox
#: runs 20 fixed rounds; strong distortion near the corners needs more or diverges). Near the
#: corners of a wide lens the iteration creeps: a StereoPi rig's 320x240 camera (k1 0.53, k2
#: -3.09, k3 4.93) had 3.1 % of its pixels flagged at 100 rounds, 1.2 % at 1000 (all within
#: 34 px of a corner: those cycle, and OpenCV's solver takes them over). Points that converge
#: stop where they did, a point back on its iterate of two rounds before stops there (the
#: rounds after would repeat it); only the others go on.
UNDISTORT_MAX_ITER = 1000
#: Rays whose squared sine of their angle is below this are treated as parallel (angle below
#: 1e-6 rad: at a 0.1 m baseline that is beyond 100 km).
PARALLEL_SIN2_TOL = 1e-12

F64 = npt.NDArray[np.float64]


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity (== raised)
class TriangulationResult:
    """3-D points of :func:`triangulate`.

    Attributes
    ----------
    XL : numpy.ndarray
        ``(N, 3)`` ``float64`` points in the left camera frame, NaN where invalid.
    XR : numpy.ndarray
        ``(N, 3)`` ``float64`` the same points in the right camera frame (``R XL + T``).
    valid : numpy.ndarray
        ``(N,)`` bool: False for parallel rays, undistortion that did not converge, or a point
        behind either camera.
    unit : str
        Length unit of ``XL`` and ``XR``.
    """

    XL: F64
    XR: F64
    valid: npt.NDArray[np.bool_]
    unit: str = "m"


def _unit_scale(calib: Calibration, unit: str) -> float:
    unit = known_unit(unit, UNIT_TO_METRES)
    return calib.to_metres_factor / UNIT_TO_METRES[unit]


def _points(x: npt.ArrayLike, name: str) -> F64:
    a = np.asarray(x)
    if a.dtype.kind not in "iuf" or a.ndim != 2 or a.shape[1] != 2:
        hint = (
            " (transpose a (2, N) array)"
            if a.ndim == 2 and a.shape[0] == 2 and a.shape[1] != 2
            # one correspondence given as its pixel: the shape alone did not say what to pass
            else " (one point: [[x, y]])"
            if a.shape == (2,) and a.dtype.kind in "iuf"
            else ""
        )
        raise ValueError(
            f"{name}: expected an (N, 2) real array of (x, y) pixels, got shape {a.shape} "
            f"dtype {a.dtype}{hint}"
        )
    return a.astype(np.float64)


def _reals(x: object, name: str, expected: str) -> F64:
    """``x`` as float64, refused naming ``name`` unless of real numbers: text was NumPy's
    "could not convert string to float: 'abc'", a ragged list "setting an array element with
    a sequence", neither naming K or D, and a complex one lost its imaginary part (a
    ComplexWarning alone). Bools are refused, as triangulate's points are: an identity mask
    was a camera matrix of focal length 1, a mask of five a D of zeros."""
    try:
        raw = _real_array(x)  # (an object array of numbers too)
    except ValueError:  # ragged
        raw = None
    if raw is None or raw.dtype.kind == "b":
        raise ValueError(f"{name}: expected {expected}, got {_shown(x)}")
    return raw.astype(np.float64)


def _check_matrix_form(K: F64, name: str) -> None:
    """Refuse a 3 x 3 ``K`` not of the form ``[[fx, s, cx], [0, fy, cy], [0, 0, 1]]``, in
    Calibration's words: a transposed one (MATLAB's ``IntrinsicMatrix`` is ``K.T``) was read
    with its centre at (0, 0) and every ray ``(cx, cy) / f`` off, without a word."""
    if K[1, 0] != 0 or not np.allclose(K[2], (0.0, 0.0, 1.0), rtol=0, atol=1e-12):
        transposed = K[0, 1] == 0 and np.allclose(K[:, 2], (0.0, 0.0, 1.0), rtol=0, atol=1e-12)
        raise ValueError(
            f"{name}: expected a camera matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]], got "
            f"{K.tolist()}" + (f" (transposed? pass {name}.T)" if transposed else "")
        )


def undistort_normalized(
    pts: npt.ArrayLike,
    K: npt.ArrayLike,
    D: npt.ArrayLike | None,
    max_iter: int = UNDISTORT_MAX_ITER,
    tol: float = UNDISTORT_TOL,
) -> tuple[F64, npt.NDArray[np.bool_]]:
    """Normalised, undistorted image coordinates of pixel points (algorithms.md E.2 step 1).

    Removes ``K`` (including skew) and inverts OpenCV's distortion model (radial with the
    rational terms ``k4..k6``, tangential ``p1, p2``, thin prism ``s1..s4``) by the fixed-point
    iteration ``x <- (x_d - delta(x)) / radial(x)`` started at ``x = x_d``, stopping when the
    update is below ``tol``. A point the iteration does not settle on within ``max_iter``
    rounds, or that comes back to its iterate of two rounds before (near a wide lens' corners
    it can 2-cycle around the preimage, for ever), gets ``cv2.undistortPoints``' solution when
    the model maps that back within ``tol`` of it.

    Parameters
    ----------
    pts : array_like
        ``(N, 2)`` pixel coordinates ``(x, y)``.
    K : array_like
        ``(3, 3)`` camera matrix.
    D : array_like or None
        ``(n,)`` OpenCV distortion coefficients (``n`` in 4, 5, 8, 12, 14; the tilt terms of
        the 14-coefficient model must be zero); None or empty: no distortion.
    max_iter : int
        Iteration cap.
    tol : float
        Convergence threshold on the update (normalised units).

    Returns
    -------
    xy : numpy.ndarray
        ``(N, 2)`` ``float64`` normalised coordinates (ray ``(x, y, 1)``), NaN where not
        converged.
    converged : numpy.ndarray
        ``(N,)`` bool.

    Raises
    ------
    ValueError
        On a bad shape, a ``K`` that is no 3 x 3 camera matrix (non-finite, a focal length
        not positive, or not of the form ``[[fx, s, cx], [0, fy, cy], [0, 0, 1]]``: a
        transposed one), non-finite or non-zero tilt coefficients, a ``max_iter`` that is not an
        integer >= 1 or a ``tol`` that is not a positive finite number.
    """
    p = _points(pts, "pts")
    # as triangulate checks them: 0 or -5 iterations, a tol of 0, -1 or NaN made every point NaN
    # without a word (never converged), tol "1" was NumPy's UFuncTypeError from the comparison
    max_iter = int_in_range(max_iter, "max_iter", 1, 2**31 - 1)
    tol = positive_finite(tol, "tol")
    Km = _reals(K, "K", "a 3 x 3 camera matrix of finite numbers with positive focal lengths")
    # a (2, 2) K was NumPy's IndexError, a zero focal length a RuntimeWarning and every point
    # inf, a NaN coefficient every point NaN: each without naming what was wrong
    if Km.shape != (3, 3) or not np.isfinite(Km).all() or not (Km[0, 0] > 0 and Km[1, 1] > 0):
        raise ValueError(
            f"K: expected a 3 x 3 camera matrix of finite numbers with positive focal lengths, "
            f"got shape {Km.shape}" + (f": {Km.tolist()}" if Km.size <= 9 else "")
        )
    _check_matrix_form(Km, "K")
    d = np.zeros(14)
    # None is no distortion, as OpenCV takes it (np.asarray(None) is one NaN: "got 1")
    dist = np.zeros(0) if D is None else _reals(D, "D", "finite coefficients").ravel()
    if dist.size not in (0, 4, 5, 8, 12, 14):
        raise ValueError(f"D: expected 4, 5, 8, 12 or 14 coefficients, got {dist.size}")
    if not np.isfinite(dist).all():
        raise ValueError(f"D: expected finite coefficients, got {dist.tolist()}")
    d[: dist.size] = dist
    if d[12] != 0 or d[13] != 0:
        raise ValueError(
            f"D: the tilted-sensor terms (tx, ty) = {d[12:].tolist()} are not supported"
        )
    k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4 = d[:12]
    fx, fy, cx, cy, skew = Km[0, 0], Km[1, 1], Km[0, 2], Km[1, 2], Km[0, 1]
    with np.errstate(invalid="ignore"):  # an infinite y times a zero skew: no point, NaN
        yd = (p[:, 1] - cy) / fy
        xd = (p[:, 0] - cx - skew * yd) / fx
    x, y = xd.copy(), yd.copy()
    if not np.any(d):
        ok = np.isfinite(x) & np.isfinite(y)
        # NaN where not converged, as below: an infinite pixel came back as inf (flagged
        # False), and triangulate's products with it warned "invalid value encountered"
        x[~ok] = np.nan
        y[~ok] = np.nan
        return np.stack([x, y], axis=1), ok
    converged = np.zeros(len(x), dtype=bool)
    # the points still moving, by index: each round costs what they are, not all N (a million
    # points with a few creeping near a corner went through all N every round)
    idx = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
    xa, ya, xda, yda = x[idx], y[idx], xd[idx], yd[idx]
    # each point's iterate of the round before (none yet): a point back where it was two rounds
    # ago repeats that 2-cycle for ever, never converging (the StereoPi corners within 21 to 95
    # rounds), and ran all max_iter rounds before OpenCV's solution below took it over
    xp, yp = np.full_like(xa, np.nan), np.full_like(ya, np.nan)
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            if not idx.size:
                break
            r2 = xa * xa + ya * ya
            r4 = r2 * r2
            radial = (1 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)))
            dx = 2 * p1 * xa * ya + p2 * (r2 + 2 * xa * xa) + s1 * r2 + s2 * r4
            dy = p1 * (r2 + 2 * ya * ya) + 2 * p2 * xa * ya + s3 * r2 + s4 * r4
            xn = (xda - dx) / radial
            yn = (yda - dy) / radial
            step = np.hypot(xn - xa, yn - ya)
            x[idx], y[idx] = xn, yn
            done = step < tol
            converged[idx[done]] = True
            cycling = (xn == xp) & (yn == yp)
            going = ~(done | ~np.isfinite(step) | cycling)
            xp, yp = xa[going], ya[going]
            idx, xa, ya, xda, yda = idx[going], xn[going], yn[going], xda[going], yda[going]
        # Near a wide lens' corners the fixed point can repel: the iteration 2-cycles (a step of
        # 0.3 for ever) where the model has a preimage, 1.2 % of a StereoPi camera's pixels
        # (k1 0.53, k2 -3.09, k3 4.93) that cv2.undistortPoints inverts. Those get OpenCV's
        # solution of the normalised point, kept where the model maps it back within tol.
        rest = np.flatnonzero(~converged & np.isfinite(xd) & np.isfinite(yd))
        if rest.size:
            import cv2

            crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, max_iter, tol)
            src = np.column_stack([xd[rest], yd[rest]]).reshape(-1, 1, 2)
            und = cv2.undistortPoints(src, np.eye(3), d[:12], criteria=crit).reshape(-1, 2)
            ux, uy = und[:, 0].astype(np.float64), und[:, 1].astype(np.float64)
            r2 = ux * ux + uy * uy
            r4 = r2 * r2
            radial = (1 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)))
            fx_ = ux * radial + 2 * p1 * ux * uy + p2 * (r2 + 2 * ux * ux) + s1 * r2 + s2 * r4
            fy_ = uy * radial + p1 * (r2 + 2 * uy * uy) + 2 * p2 * ux * uy + s3 * r2 + s4 * r4
            back = np.hypot(fx_ - xd[rest], fy_ - yd[rest]) <= tol
            x[rest[back]], y[rest[back]] = ux[back], uy[back]
            converged[rest[back]] = True
    x[~converged] = np.nan
    y[~converged] = np.nan
    return np.stack([x, y], axis=1), converged


#: Pixels: a fisheye point whose undistorted ray projects back further than this from where it
#: was measured did not converge (OpenCV's fisheye inversion has no flag of its own; a point
#: beyond the lens' reach comes back at -1e6).
FISHEYE_ROUND_TRIP_PX = 1e-6


def _undistort_fisheye(
    pts: F64, K: F64, D: F64, max_iter: int, tol: float
) -> tuple[F64, npt.NDArray[np.bool_]]:
    """:func:`undistort_normalized` for the equidistant (fisheye) model of
    ``Calibration(model="fisheye")``: ``cv2.fisheye.undistortPoints`` iterated to ``tol``, each
    point checked by projecting its ray back (``cv2.fisheye.distortPoints``)."""
    import cv2

    xy = np.full(pts.shape, np.nan)
    finite = np.isfinite(pts).all(axis=1)
    converged = np.zeros(len(pts), dtype=bool)
    if finite.any():
        src = pts[finite].reshape(-1, 1, 2)
        crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, int(max_iter), float(tol))
        und = np.asarray(cv2.fisheye.undistortPoints(src, K, D, criteria=crit), np.float64)
        back = np.asarray(cv2.fisheye.distortPoints(und, K, D), np.float64).reshape(-1, 2)
        und = und.reshape(-1, 2)
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(und).all(axis=1) & (
                np.hypot(*(back - pts[finite]).T) <= FISHEYE_ROUND_TRIP_PX
            )
        idx = np.flatnonzero(finite)
        converged[idx] = ok
        xy[idx[ok]] = und[ok]
    return xy, converged


def triangulate(
    xl: npt.ArrayLike,
    xr: npt.ArrayLike,
    calib: Calibration,
    unit: str = "m",
    max_iter: int = UNDISTORT_MAX_ITER,
    tol: float = UNDISTORT_TOL,
) -> TriangulationResult:
    """Triangulate unrectified pixel correspondences with Bouguet's midpoint method (E.2).

    Each point is normalised and undistorted (:func:`undistort_normalized`; for a
    ``model="fisheye"`` rig ``cv2.fisheye.undistortPoints``, each point checked by projecting
    it back within :data:`FISHEYE_ROUND_TRIP_PX`) into a ray
    ``x = (x, y, 1)``. With ``u = R xL`` the depths along both optical axes minimise
    ``|ZR xR - ZL u - T|^2``::

        D  = (u.u)(xR.xR) - (u.xR)^2
        ZL = ((u.xR)(xR.T) - (xR.xR)(u.T)) / D
        ZR = ((u.u)(xR.T) - (u.T)(u.xR)) / D

    and the point is the midpoint of ``ZL xL`` and ``R^T (ZR xR - T)``; ``XR = R XL + T``.

    Parameters
    ----------
    xl, xr : array_like
        ``(N, 2)`` pixel coordinates ``(x, y)`` of corresponding points in the raw (unrectified,
        distorted) left and right images.
    calib : Calibration
        Stereo calibration (``rectified`` ones work too: their distortion is zero).
    unit : str
        Output length unit: ``"m"`` (default), ``"ft"``, ``"mm"``, ``"cm"`` or ``"in"``.
    max_iter, tol : int, float
        Undistortion iteration cap and convergence threshold.

    Returns
    -------
    TriangulationResult
        ``XL``, ``XR`` ``(N, 3)`` and ``valid`` ``(N,)``; invalid points (parallel rays, no
        undistortion convergence, negative depth in either camera) are NaN.

    Raises
    ------
    ValueError
        If ``xl``/``xr`` are not ``(N, 2)`` of equal length, ``unit`` is unknown, ``max_iter``
        is not an integer >= 1 or ``tol`` not a positive finite number.
    """
    _require_type(calib, "Calibration", "calib")
    pl = _points(xl, "xl")
    pr = _points(xr, "xr")
    if pl.shape != pr.shape:
        raise ValueError(f"xl and xr must have the same shape, got {pl.shape} and {pr.shape}")
    # a plain str: an np.str_ unit was kept as given, and the result's repr read np.str_('ft')
    unit = known_unit(unit, UNIT_TO_METRES)
    scale = _unit_scale(calib, unit)
    # 0 or -5 iterations, a tol of 0, -1 or NaN made every point NaN without a word (never
    # converged); "1" was NumPy's UFuncTypeError from the comparison
    max_iter = int_in_range(max_iter, "max_iter", 1, 2**31 - 1)
    tol = positive_finite(tol, "tol")
    # The fisheye model's four coefficients are k1..k4 of the equidistant model, not the
    # pinhole model's k1, k2, p1, p2 (read as those, a fisheye rig's points were metres off).
    normalise = _undistort_fisheye if calib.model == "fisheye" else undistort_normalized
    nl, okl = normalise(pl, calib.K1, calib.D1, max_iter, tol)
    nr, okr = normalise(pr, calib.K2, calib.D2, max_iter, tol)
    n = len(pl)
    ray_l = np.column_stack([nl, np.ones(n)])
    ray_r = np.column_stack([nr, np.ones(n)])
    R, T = calib.R, calib.T
    # a far pixel (1e300 px) squares past float64: inf - inf in delta warned "invalid value
    # encountered in subtract" for a point rightly invalid
    with np.errstate(all="ignore"):
        u = ray_l @ R.T
        uu = np.einsum("ij,ij->i", u, u)
        rr = np.einsum("ij,ij->i", ray_r, ray_r)
        ur = np.einsum("ij,ij->i", u, ray_r)
        ut = u @ T
        rt = ray_r @ T
        delta = uu * rr - ur * ur
        not_parallel = delta > PARALLEL_SIN2_TOL * uu * rr
        zl = (ur * rt - rr * ut) / delta
        zr = (uu * rt - ut * ur) / delta
        p1 = zl[:, None] * ray_l
        p2 = (zr[:, None] * ray_r - T) @ R  # R^T (ZR xR - T), row-wise
        XL = 0.5 * (p1 + p2)
        XR = XL @ R.T + T
        valid = okl & okr & not_parallel & (zl > 0) & (zr > 0) & (XL[:, 2] > 0) & (XR[:, 2] > 0)
    XL[~valid] = np.nan
    XR[~valid] = np.nan
    return TriangulationResult(XL=XL * scale, XR=XR * scale, valid=valid, unit=unit)


def _disparity(disparity: npt.ArrayLike) -> F64:
    from stereovision._validate import check_index_range, not_a_result

    not_a_result(disparity, "disparity", "disparity")
    _refuse_masked(disparity, "disparity", "np.nan")  # NaN: no disparity
    d = np.asarray(disparity)
    if d.ndim != 2 or d.dtype.kind not in "iuf":
        raise ValueError(
            f"disparity: expected a real (H, W) array, got shape {d.shape} dtype {d.dtype}"
        )
    check_index_range(d.shape, "disparity", "map")  # before the float64 copy (8 bytes a pixel)
    return d.astype(np.float64)


#: A disparity map at least this many pixels on each side whose size is the calibration's
#: image size scaled by one factor (within a pixel of rounding) is taken for a resized pair's
#: (smaller ones are crops or test arrays: nobody matches a pair shrunk to 48 rows).
RESIZED_MIN_SIDE = 64


def _warn_if_resized(shape: tuple[int, ...], calib: Calibration, stacklevel: int) -> None:
    """Warn when a map looks like one of the pair resized: read against the calibration's own
    image size its depths are off by the factor (``f`` and ``doffs`` scale with the images),
    silently. A map of the calibration's size, or not of its shape (a crop, a row of matches),
    passes."""
    h, w = shape[:2]
    cw, ch = calib.image_size
    if (w, h) == (cw, ch) or min(w, h) < RESIZED_MIN_SIDE:
        return
    if abs(h - ch * w / cw) > 1.0 or abs(w - cw * h / ch) > 1.0:
        return
    import warnings

    from stereovision._validate import ADVICE

    # ADVICE's Python words: the CLI's warning line swaps them for its own (advice_for)
    warnings.warn(
        f"disparity map is {w}x{h} px, the calibration's images {cw}x{ch}: read with it, a map "
        f"of the pair resized by {w / cw:.3g} gives about {cw / w:.3g} x the true depths; "
        f"{ADVICE['resized_map']['api'].format(w=w, h=h)} (a map of the images' top-left "
        f"{w}x{h} px is read right)",
        UserWarning,
        stacklevel=stacklevel + 1,
    )


def _warn_if_fixed_point(d: F64, calib: Calibration, stacklevel: int) -> None:
    """Warn when the map's largest disparity is past the calibration's image width: no pixel of
    the pair has its match that far away, so the map holds fixed-point values (a 16-bit
    disparity PNG, KITTI's ``d * 256``; OpenCV's StereoBM / StereoSGBM int16, ``d * 16``),
    whose depths read as pixels are that factor too small, silently."""
    width = calib.image_size[0]
    top = float(np.max(d, where=np.isfinite(d), initial=-np.inf))
    if top <= width:
        return
    import warnings

    warnings.warn(
        f"disparity: values up to {top:g} px, wider than the calibration's images ({width} px): "
        "no match lies that far; fixed-point values (a 16-bit disparity PNG, KITTI's d * 256: "
        "read it with stereovision.export.read_disparity_png; OpenCV StereoSGBM's int16, "
        "d * 16: divide by 16) give depths that many times too small",
        UserWarning,
        stacklevel=stacklevel + 1,
    )


def depth_from_disparity(
    disparity: npt.ArrayLike, calib: Calibration, unit: str = "m"
) -> npt.NDArray[np.float32]:
    """Depth from a rectified disparity map (algorithms.md E.3).

    ``Z = f B / (d + doffs)``, with ``f`` the rectified focal length (px), ``B`` the baseline
    and ``doffs = cx_right - cx_left``; ``d + doffs <= 0``, non-finite ``d`` and a depth past
    float32 give NaN. For an unrectified calibration the disparity must be in the frame of
    :meth:`Calibration.rectify` (``alpha=0``) and :meth:`Calibration.rectified_calibration` is
    used.

    Parameters
    ----------
    disparity : array_like
        ``(H, W)`` disparity ``x_left - x_right`` in pixels, NaN = none.
    calib : Calibration
        Calibration of the pair.
    unit : str
        Output unit, metres by default.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``float32`` depth, NaN where invalid.

    Raises
    ------
    ValueError
        If ``disparity`` is not a real 2-D array, is a :mod:`numpy.ma` array with masked
        pixels (pass ``disparity.filled(np.nan)``: NaN is no disparity) or ``unit`` is unknown.

    Warns
    -----
    UserWarning
        When the map is the calibration's image size scaled by one factor (a resized pair's
        map, whose depths would be off by that factor: :meth:`Calibration.scaled_to`), or
        holds a disparity past the calibration's image width (fixed-point values: a 16-bit
        disparity PNG's ``d * 256``, OpenCV's ``d * 16``).
    """
    return _depth_from_disparity(disparity, calib, unit, 2)


def _depth_from_disparity(
    disparity: npt.ArrayLike, calib: Calibration, unit: str, stacklevel: int
) -> npt.NDArray[np.float32]:
    """:func:`depth_from_disparity`, its warning ``stacklevel`` frames up from the caller."""
    _require_type(calib, "Calibration", "calib")
    d = _disparity(disparity)
    _warn_if_resized(d.shape, calib, stacklevel + 1)
    _warn_if_fixed_point(d, calib, stacklevel + 1)
    return _depth(d, calib, unit)


def _depth(d: F64, calib: Calibration, unit: str) -> npt.NDArray[np.float32]:
    cal = calib if calib.rectified else calib.rectified_calibration()
    scale = _unit_scale(cal, unit)
    denom = d + cal.doffs_px
    with np.errstate(all="ignore"):
        z = cal.focal_px * cal.baseline * scale / denom
        # past float32 (a disparity of 1e-34 px at f B = 3.8e5 mm px) the depth was +inf, with
        # NumPy's "overflow encountered in cast": no depth, as the depth_map kernel's NaN
        z32 = z.astype(np.float32)
    z32[~(np.isfinite(denom) & (denom > 0) & np.isfinite(z32))] = np.nan
    return z32


def reproject(
    disparity: npt.ArrayLike, calib: Calibration, unit: str = "m"
) -> npt.NDArray[np.float32]:
    """3-D points of every pixel of a rectified disparity map (algorithms.md E.3).

    ``Z`` as :func:`depth_from_disparity`, ``X = (x - cx) Z / fx``, ``Y = (y - cy) Z / fy``
    with ``(x, y)`` the pixel column and row (left rectified camera frame: X right, Y down,
    Z forward). Equals ``cv2.reprojectImageTo3D(disparity, calib.Q)`` times
    ``calib.to_metres_factor`` where valid when ``fx == fy`` (as ``cv2.stereoRectify`` gives);
    ``Q`` holds one focal length, so for ``fx != fy`` OpenCV scales ``Y`` by ``fx`` where this
    uses ``fy``, the pixel's own ray. As there, a map of another size than the
    calibration's images is read as their top-left corner (a map of a resized pair needs
    :meth:`Calibration.scaled_to`).

    Parameters
    ----------
    disparity : array_like
        ``(H, W)`` disparity in pixels, NaN = none.
    calib : Calibration
        Calibration of the pair.
    unit : str
        Output unit, metres by default.

    Returns
    -------
    numpy.ndarray
        ``(H, W, 3)`` ``float32``, NaN where the depth is invalid or a
        coordinate passes float32.

    Raises
    ------
    ValueError
        As :func:`depth_from_disparity`: a disparity that is not a real 2-D array or a
        :mod:`numpy.ma` array with masked pixels, an unknown ``unit``.

    Warns
    -----
    UserWarning
        As :func:`depth_from_disparity`, for a map of the pair resized or of fixed-point
        values.
    """
    return _reproject(disparity, calib, unit, 2)


def _reproject(
    disparity: npt.ArrayLike, calib: Calibration, unit: str, stacklevel: int
) -> npt.NDArray[np.float32]:
    """:func:`reproject`, its warning ``stacklevel`` frames up from the caller."""
    _require_type(calib, "Calibration", "calib")
    d = _disparity(disparity)
    _warn_if_resized(d.shape, calib, stacklevel + 1)
    _warn_if_fixed_point(d, calib, stacklevel + 1)
    z = _depth(d, calib, unit).astype(np.float64)
    cal = calib if calib.rectified else calib.rectified_calibration()
    h, w = z.shape
    fx, fy, cx, cy = cal.K1[0, 0], cal.K1[1, 1], cal.K1[0, 2], cal.K1[1, 2]
    xs = (np.arange(w, dtype=np.float64) - cx) / fx
    ys = (np.arange(h, dtype=np.float64) - cy) / fy
    out = np.empty((h, w, 3), dtype=np.float32)
    with np.errstate(over="ignore"):
        # a wide view's X, Y pass float32 where Z is near its largest (|x - cx| / fx = 2.1 at
        # Z = 2e38 mm): +inf, with NumPy's "overflow encountered in cast"; no point, as the
        # depth past float32 is none
        out[:, :, 0] = xs[None, :] * z
        out[:, :, 1] = ys[:, None] * z
    out[:, :, 2] = z
    out[~np.isfinite(out).all(axis=2)] = np.nan
    return out
