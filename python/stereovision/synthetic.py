"""Rendered views of a textured plane through a calibrated camera, for tests, benches and demos.

:func:`render_plane` traces every (supersampled) pixel's ray -- the lens distortion undone by
OpenCV's own inverse, ``cv2.undistortPoints`` or ``cv2.fisheye.undistortPoints`` -- to the plane
and looks up the texture there, then area-averages the samples down. Boards
(:func:`stereovision.charuco.render_charuco`) and textured walls seen by a pinhole or a fisheye
rig are rendered this way, so that a test knows the exact geometry behind every pixel.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from stereovision._validate import int_in_range, positive_finite, real_number
from stereovision.triangulation import _check_matrix_form

__all__ = ["render_plane"]

F64 = npt.NDArray[np.float64]

_RAYS: dict[tuple[Any, ...], F64] = {}
#: Bytes of rays :func:`pixel_rays` keeps (the least recently used go first; the newest camera's
#: are kept even when larger). Nine cameras were kept whatever their size: three 1080p ones
#: at supersample 3 held 896 MB after their renders. 256 MiB, as the SGM cost volume's bound.
_RAYS_MAX_BYTES = 256 << 20
#: Guards :data:`_RAYS`: renders from several threads (the GUI's, a batch's) raced on it, and one
#: thread's eviction left another's lookup a KeyError or its byte sum "dictionary changed size
#: during iteration" (8 threads of 200 small renders each: up to 16 of them failed).
_RAYS_LOCK = threading.Lock()
#: Most pixels a side of the texture and of the supersampled picture (cv2.remap's
#: ``SHRT_MAX - 1``).
_REMAP_MAX_SIDE = 32766


def pixel_rays(K: F64, D: F64, size: tuple[int, int], ss: int, model: str = "pinhole") -> F64:
    """Normalised undistorted ray ``(x, y)`` (``z = 1``) of every supersampled pixel centre.

    Cached per camera (at most :data:`_RAYS_MAX_BYTES` of rays besides the newest camera's).
    Supersampled pixel ``j`` covers ``[j / ss - 0.5, (j + 1) / ss - 0.5]``
    of the image's x axis (pixel centres at integers).

    Returns
    -------
    numpy.ndarray
        ``(h * ss, w * ss, 2)`` float64; NaN where the model has no ray in front of the camera.
    """
    key = (K.tobytes(), D.tobytes(), size, ss, model)
    with _RAYS_LOCK:
        cached = _RAYS.pop(key, None)
        if cached is not None:
            _RAYS[key] = cached  # the most recently used last
            return cached
    # computed unlocked (OpenCV releases the GIL: threads of other cameras go on); two threads
    # of one camera compute the same rays, and the last one's are kept
    w, h = size
    xs = (np.arange(w * ss) + 0.5) / ss - 0.5
    ys = (np.arange(h * ss) + 0.5) / ss - 0.5
    gx, gy = np.meshgrid(xs, ys)
    pts = np.stack([gx.ravel(), gy.ravel()], axis=1).reshape(-1, 1, 2)
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 40, 1e-12)
    if model == "fisheye":
        und = cv2.fisheye.undistortPoints(pts, K, D, criteria=crit)
    else:
        und = cv2.undistortPoints(pts, K, D, R=None, P=None, criteria=crit)
    rays = np.asarray(und, np.float64).reshape(h * ss, w * ss, 2)
    if model == "fisheye":
        # Past 90 degrees off axis there is no ray with z = 1: OpenCV returns a mirrored ray
        # (tan < 0) or its -1e6 sentinel there. The limit is on the ray's angle theta, not
        # on the distorted theta_d = r / f (the two differ by the k1..k4 polynomial: the
        # old theta_d cut left out rays in front for k1 > 0 and kept mirrored ones behind
        # for k1 < 0), so each ray is projected back and kept where it lands on its pixel.
        theta = np.arctan(np.hypot(rays[..., 0], rays[..., 1]))
        back = cv2.fisheye.distortPoints(und.reshape(-1, 1, 2), K, D)
        off = np.hypot(*(np.asarray(back, np.float64).reshape(-1, 2) - pts[:, 0]).T)
        bad = (theta >= np.pi / 2 * 0.999) | (off.reshape(theta.shape) > 0.01)
        if bad.any():
            # OpenCV clamps theta_d at 90 degrees: for k1 > 0 the rays in front beyond
            # r = f pi / 2 came back wrong and were cut (f 300 px, k 0.1, -0.02, 0.005,
            # -0.001: 243808 pixels of a 2000 x 1500 image seeing the background)
            rays[bad] = _fisheye_rays(pts[bad.ravel(), 0], K, D)
    with _RAYS_LOCK:
        _RAYS.pop(key, None)  # another thread's rays of this camera
        # the least recently used first, until the rest and these fit (or none is left)
        kept = sum(r.nbytes for r in _RAYS.values())
        while _RAYS and (len(_RAYS) > 8 or kept + rays.nbytes > _RAYS_MAX_BYTES):
            kept -= _RAYS.pop(next(iter(_RAYS))).nbytes
        _RAYS[key] = rays
    return rays


def _fisheye_rays(px: F64, K: F64, D: F64) -> F64:
    """Rays ``(x, y)`` (``z = 1``) of fisheye pixels ``px`` ``(N, 2)``, solved here; NaN where
    no ray within 89.91 degrees of the axis projects back within 0.01 px of its pixel.

    ``theta_d = theta (1 + k1 theta^2 + ... + k4 theta^8)`` is solved for the smallest
    ``theta`` in ``[0, 0.999 pi / 2]`` (cv2.fisheye.undistortPoints clamps
    ``theta_d`` to 90 degrees, which a lens with k1 > 0 exceeds in front of the camera).
    """
    lim = np.pi / 2 * 0.999
    # K's skew K[0, 1] ignored, as cv2.fisheye's undistortPoints and distortPoints ignore it:
    # a ray solved with it failed their round trip below and the pixel saw the background
    yd = (px[:, 1] - K[1, 2]) / K[1, 1]
    xd = (px[:, 0] - K[0, 2]) / K[0, 0]
    theta_d = np.hypot(xd, yd)

    def poly(t: F64) -> F64:
        t2 = t * t
        return t * (1 + t2 * (D[0] + t2 * (D[1] + t2 * (D[2] + t2 * D[3]))))

    # the first crossing (the smallest theta) lies below the first grid angle past theta_d
    grid = np.linspace(0.0, lim, 2049)
    vals = poly(grid)
    out = np.full((len(px), 2), np.nan)
    # past the polynomial's largest value no angle within the limit reaches theta_d: no ray.
    # Those are most of a wide image's pixels (behind the camera), and solving them too
    # made render_plane 2.5 times slower (f 300 px on 2000 x 1500: 1.24 s vs 0.49 s before)
    sel = np.flatnonzero(theta_d <= vals.max())
    px, xd, yd, theta_d = px[sel], xd[sel], yd[sel], theta_d[sel]
    # the first grid value >= theta_d is the first of their running maximum (sorted)
    first = np.searchsorted(np.maximum.accumulate(vals), theta_d)
    i0 = np.maximum(first - 1, 0)
    lo, hi = grid[i0], grid[first]
    # the chord's angle, then Newton within the bracket (the bracket is 0.0008 rad wide:
    # quadratic convergence to float64 in two or three steps)
    span = np.where(vals[first] > vals[i0], vals[first] - vals[i0], 1.0)
    theta = np.clip(lo + (hi - lo) * (theta_d - vals[i0]) / span, lo, hi)
    for _ in range(4):
        t2 = theta * theta
        slope = 1 + t2 * (3 * D[0] + t2 * (5 * D[1] + t2 * (7 * D[2] + t2 * 9 * D[3])))
        step = (poly(theta) - theta_d) / np.where(slope > 0, slope, np.inf)
        theta = np.clip(theta - step, lo, hi)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(theta_d > 0, np.tan(theta) / theta_d, 1.0)
    rays = np.stack([xd * scale, yd * scale], axis=1)
    back = cv2.fisheye.distortPoints(rays.reshape(-1, 1, 2), K, D).reshape(-1, 2)
    ok = np.hypot(*(np.asarray(back, np.float64) - px).T) <= 0.01
    out[sel[ok]] = rays[ok]
    return out


def _camera_pose(
    K: object, D: object, rvec: object, tvec: object, model: str | None = None
) -> tuple[F64, F64, F64, F64]:
    """``K``, ``D``, ``rvec`` and ``tvec`` of a rendered view as float64 (``D``, ``rvec`` and
    ``tvec`` flat), refused in :func:`render_plane`'s words (also ``render_chessboard``'s:
    ``model`` None names no model in the message)."""
    # bools refused, as triangulate refuses them: an identity mask was a camera of focal
    # length 1 px, a mask of five a D of zeros, each drawn without a word
    bools = {
        name: np.asarray(v).dtype.kind == "b"
        for name, v in (("K", K), ("D", D), ("rvec", rvec), ("tvec", tvec))
        if v is not None
    }
    Kf = np.asarray(K, np.float64)
    # None is no distortion, as the message below and OpenCV's distCoeffs have it: it was
    # asarray's NaN, "... (or none) for model 'pinhole' (finite), got shape (1,)"
    Df = np.zeros(0) if D is None and model != "fisheye" else np.asarray(D, np.float64).ravel()
    rv = np.asarray(rvec, np.float64).ravel()
    t = np.asarray(tvec, np.float64).ravel()
    # OpenCV's lengths; none at all is no distortion for the pinhole model
    lengths = (4,) if model == "fisheye" else (0, 4, 5, 8, 12, 14)
    for name, arr, ok in (
        ("K", Kf, Kf.shape == (3, 3)),
        ("D", Df, len(Df) in lengths),
        ("rvec", rv, rv.shape == (3,)),
        ("tvec", t, t.shape == (3,)),
    ):
        if not (ok and np.isfinite(arr).all()) or bools.get(name):
            want = {"K": "a 3 x 3 camera matrix", "rvec": "3 numbers", "tvec": "3 numbers"}.get(
                name,
                "4 coefficients for model 'fisheye'"
                if model == "fisheye"
                else "4, 5, 8, 12 or 14 coefficients (or none)"
                + (f" for model {model!r}" if model else ""),
            )
            got = "None" if name == "D" and D is None else f"shape {arr.shape}"
            got += " dtype bool" if bools.get(name) else ""
            raise ValueError(f"{name}: expected {want} (finite), got {got}")
    # a zero focal length (the K = 0 of an uncalibrated camera's camera_info) gave every ray
    # NaN and a picture of background only, with NumPy's "invalid value" warnings; a negative
    # one a mirrored picture. Calibration's words
    if not (Kf[0, 0] > 0 and Kf[1, 1] > 0):
        raise ValueError(f"K: focal lengths must be positive, got fx={Kf[0, 0]:g}, fy={Kf[1, 1]:g}")
    # a transposed K (MATLAB's IntrinsicMatrix) drew the plane seen from a centre at (0, 0)
    _check_matrix_form(Kf, "K")
    return Kf, Df, rv, t


def render_plane(
    texture: npt.ArrayLike,
    units_per_pixel: float,
    K: npt.ArrayLike,
    D: npt.ArrayLike,
    rvec: npt.ArrayLike,
    tvec: npt.ArrayLike,
    *,
    image_size: tuple[int, int] = (640, 480),
    supersample: int = 3,
    background: float = 60.0,
    model: str = "pinhole",
    origin_px: tuple[float, float] = (-0.5, -0.5),
) -> np.ndarray:
    """Render a textured plane seen by a camera (antialiased, through its lens distortion).

    The plane is the ``Z = 0`` plane of its own frame; texture pixel ``(i, j)`` (row, column)
    covers ``[(j + 0.5 + origin_px[0]) s, ...]`` with ``s = units_per_pixel``, i.e. the plane
    point ``(u, v)`` reads the texture at pixel ``(u / s + origin_px[0], v / s + origin_px[1])``
    (bilinear). The default origin puts ``(0, 0)`` at the texture's top-left pixel corner.

    Parameters
    ----------
    texture : array_like
        Grey ``(H, W)`` or ``(H, W, C)`` image of 1 to 4 channels (colour ``(H, W, 3)``), of
        integers or floats (not bool).
    units_per_pixel : float
        Size of one texture pixel on the plane (in the unit of ``tvec``).
    K, D : array_like
        Camera matrix and distortion coefficients (OpenCV's order; 4 for ``model="fisheye"``;
        for ``"pinhole"`` None or none at all is no distortion).
    rvec, tvec : array_like
        Plane-to-camera rotation (Rodrigues) and translation.
    image_size : tuple of int
        ``(width, height)``.
    supersample : int
        Samples per pixel side (1 to 8; at most 32766 samples a side in all).
    background : float
        Value off the plane (NaN for a float texture; within an integer texture's range).
    model : str
        ``"pinhole"`` or ``"fisheye"`` (``cv2.fisheye``'s equidistant model).
    origin_px : tuple of float
        Texture pixel coordinate of the plane's origin.

    Returns
    -------
    numpy.ndarray
        ``(height, width[, C])``, the texture's ``C`` channels (one included), of the
        texture's dtype (float textures stay float).

    Raises
    ------
    ValueError
        For a bad size, supersampling or model, or a supersampled picture or a texture over
        32766 pixels a side (OpenCV's remap); a ``units_per_pixel`` that is not a positive
        number, a ``background`` that is no number or not a value of an integer texture, an
        ``origin_px`` that is not two finite numbers; a texture that is empty, not ``(H, W)``
        or ``(H, W, C)`` with 1 to 4 channels, or not of integers or floats (bool, complex);
        ``K`` not 3 x 3, of a focal length that is not positive or not of the form
        ``[[fx, s, cx], [0, fy, cy], [0, 0, 1]]`` (a transposed one), ``D`` of a length the
        model does not take, ``rvec`` or ``tvec`` not 3 numbers; a camera in the plane (seen
        edge-on).
    """
    if model not in ("pinhole", "fisheye"):
        raise ValueError(f"model: expected 'pinhole' or 'fisheye', got {model!r}")
    try:
        w, h = (int_in_range(v, "image_size", 1, 20000) for v in image_size)
    except (TypeError, ValueError):
        raise ValueError(
            f"image_size: expected (width, height) in pixels, got {image_size!r}"
        ) from None
    ss = int_in_range(supersample, "supersample", 1, 8)
    # cv2.remap's sides are below SHRT_MAX: past them its assertion named no argument, and
    # only after every supersampled pixel's rays (10000 x 8000 at 4: 20 GB of them)
    if max(w, h) * ss > _REMAP_MAX_SIDE:
        raise ValueError(
            f"supersample: {ss} samples a side of a {w} x {h} image are {w * ss} x {h * ss}, "
            f"past OpenCV's remap's {_REMAP_MAX_SIDE} a side: use a lower supersample"
        )
    tex = np.asarray(texture)
    # OpenCV's and NumPy's own errors named no argument ("!_src.empty() in function 'remap'",
    # "Singular matrix"), and a 1-D texture was drawn as one column
    if tex.size == 0 or not (tex.ndim == 2 or (tex.ndim == 3 and 1 <= tex.shape[2] <= 4)):
        raise ValueError(
            f"texture: expected a non-empty (H, W) or (H, W, 1-4) image, got shape {tex.shape}"
        )
    if max(tex.shape[:2]) > _REMAP_MAX_SIDE:  # a long strip: a 40 m corridor at 1 mm a pixel
        raise ValueError(
            f"texture: expected at most {_REMAP_MAX_SIDE} pixels a side (OpenCV's remap), got "
            f"shape {tex.shape}: shrink it and scale units_per_pixel up as much"
        )
    # remap works in float32: a bool texture (a mask) came back as any value over 0, True at
    # every blended edge and on the background (74 % True of a half-True board), and a complex
    # one lost its imaginary part with NumPy's ComplexWarning alone (an object array of
    # numbers is read as before)
    if tex.dtype.kind not in "iufO":
        hint = " (a mask: pass mask.astype(np.uint8) * 255)" if tex.dtype.kind == "b" else ""
        raise ValueError(f"texture: expected integer or float grey levels, got {tex.dtype}{hint}")
    # the package's numbers (positive_finite): "0.01" and True (1) were taken as sizes
    s = positive_finite(units_per_pixel, "units_per_pixel")
    if not real_number(background):  # "60" was 60, True 1
        raise ValueError(f"background: expected a number, got {background!r}")
    if np.issubdtype(tex.dtype, np.integer):
        # NaN was NumPy's "invalid value encountered in cast" and 0 (a uint8 texture), 300
        # clipped to 255 (render_charuco's background is refused there too)
        info = np.iinfo(tex.dtype)
        if not (info.min <= background <= info.max):
            raise ValueError(
                f"background: expected a value of the {tex.dtype} texture ({info.min} to "
                f"{info.max}), got {background!r}"
            )
    # a string was NumPy's UFuncTypeError "ufunc 'add' did not contain a loop", naming no
    # argument, and a NaN drew the background alone (every texture coordinate NaN)
    try:
        ox, oy = (float(v) if real_number(v) else math.nan for v in origin_px)
    except (TypeError, ValueError, OverflowError):  # no pair; an int past a float
        ox = oy = math.nan
    if not (math.isfinite(ox) and math.isfinite(oy)):
        raise ValueError(f"origin_px: expected two finite numbers (x, y), got {origin_px!r}")
    Kf, Df, rv, t = _camera_pose(K, D, rvec, tvec, model)
    Rb, _ = cv2.Rodrigues(rv.reshape(3, 1))
    plane = np.column_stack([Rb[:, 0], Rb[:, 1], t])
    if abs(np.linalg.det(plane)) <= 1e-12 * max(1.0, float(np.abs(t).max())):
        raise ValueError("tvec: the camera lies in the plane (seen edge-on): nothing to render")
    Hi = np.linalg.inv(plane)  # ray -> (u, v, 1) on the plane
    rays = pixel_rays(Kf, Df, (w, h), ss, model)
    x, y = rays[..., 0], rays[..., 1]
    u = Hi[0, 0] * x + Hi[0, 1] * y + Hi[0, 2]
    v = Hi[1, 0] * x + Hi[1, 1] * y + Hi[1, 2]
    q = Hi[2, 0] * x + Hi[2, 1] * y + Hi[2, 2]
    # Rays that meet the plane behind the camera (q <= 0 for a plane in front) see background.
    front = np.isfinite(q) & (q > 1e-12)
    qs = np.where(front, q, 1.0)
    mx = np.where(front, u / qs / s + ox, -1e6).astype(np.float32)
    my = np.where(front, v / qs / s + oy, -1e6).astype(np.float32)
    work = tex.astype(np.float32)
    fill = (float(background),) * (tex.shape[2] if tex.ndim == 3 else 1)  # grey in every channel
    canvas = cv2.remap(
        work, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=fill
    )
    # cv2.remap and resize drop the channel axis of an (H, W, 1) texture, which is taken
    out = cv2.resize(canvas, (w, h), interpolation=cv2.INTER_AREA).reshape((h, w, *tex.shape[2:]))
    if np.issubdtype(tex.dtype, np.integer):
        info = np.iinfo(tex.dtype)
        return np.clip(np.round(out), info.min, info.max).astype(tex.dtype)
    return out.astype(tex.dtype)
