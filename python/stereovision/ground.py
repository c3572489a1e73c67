"""The ground plane under a stereo rig, the camera's height and tilt above it, and obstacles.

A mobile robot wants three things from a depth map before anything else: where the floor is,
whether the camera still sits where its mount says (height, pitch, roll), and what stands up
from the floor. :func:`fit_ground_plane` finds the floor as a plane in *disparity space*: for a
rectified pair a 3-D plane ``n . X + h = 0`` is the plane ``d = a u + b v + c`` of the disparity
map, and a disparity's error is about the same everywhere (a fraction of a pixel), while a
depth's grows with its square. RANSAC with a threshold in pixels therefore treats near and far
floor alike, where a 3-D fit with a fixed threshold in metres drops the far floor, or lets walls
in once the threshold grows with the depth.

Conventions: the left rectified camera's frame (X right, Y down, Z forward, metres), as
:func:`stereovision.depth_map`'s points. The plane's normal points up, away from the floor
(``n_y < 0``); ``height`` is the camera's distance above the plane; ``pitch`` is how far the
optical axis points down (positive: towards the floor), ``roll`` the turn about the optical
axis (positive: the floor's normal leans to the camera's right, i.e. the camera is rolled
counter-clockwise as seen from behind).
"""

from __future__ import annotations

import math
import reprlib
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from stereovision._validate import NOT_NUMBERS, _real_array, known_unit, real_number
from stereovision._validate import require as _require_type

# at run time too, so that typing.get_type_hints resolves the public signatures
from stereovision.calibration import UNIT_TO_METRES, Calibration

__all__ = [
    "GROUND_FOCAL_PX",
    "GROUND_INLIER_PX",
    "MAX_TILT_DEG",
    "GroundPlane",
    "LaserScan",
    "OccupancyGrid",
    "fit_ground_plane",
    "floor_frame",
    "laser_scan",
    "obstacle_mask",
    "occupancy_grid",
]

F64 = npt.NDArray[np.float64]

#: A pixel lies on the plane when its disparity is within this many pixels of the plane's, on a
#: rig whose rectified focal length is at least :data:`GROUND_FOCAL_PX` pixels; below it the
#: tolerance scales with the focal length (``GROUND_INLIER_PX * f / GROUND_FOCAL_PX``), the same
#: angle of disparity (``d / f = B / Z``), so that a rig run at a lower resolution keeps the band
#: of the scene it had. A fixed 1 px was four times as wide in the scene on images a quarter of
#: the size, and tilted planes through whatever stands in the view outvoted the floor: KITTI
#: 000005 matched at the GUI's 320 px width put the camera 8.10 m above the road (1.62 m at full
#: size). The rigs the fit was measured on have 320 (TartanAir) to 721 px (KITTI) at full size,
#: and keep their 1 px; so does the rendered floor of ``tests/test_ground.py`` (400 px), whose
#: 0.2-0.5 px of noise a tolerance of 0.56 px (1 px at 720) counted off the floor. The matchers'
#: noise does not shrink with the image (about 0.5 px at any size), so the tolerance is not
#: scaled further: ETH3D playground at half size (271 px) still finds a slope through its walls.
GROUND_INLIER_PX = 1.0
GROUND_FOCAL_PX = 320.0
#: The floor's normal may lean this far from the camera's "up" (-Y): the camera's own pitch and
#: roll on its mount. Planes tilted further (walls, ramps seen head-on) are not the floor. (At
#: 45 degrees, sloping structures of ETH3D playground outvote its floor.)
MAX_TILT_DEG = 35.0
#: RANSAC hypotheses, and pixels each is scored on (a random subset; the final fit uses all).
RANSAC_ITERATIONS = 500
RANSAC_SAMPLE = 40000
#: When the best plane of those holds under :data:`LOCAL_SHARE` of the sample, three random
#: pixels rarely all lie on the floor (at 10 %, one hypothesis in a thousand), so
#: :data:`LOCAL_ITERATIONS` more hypotheses take their second and third pixel in the first's
#: cell of a 6 x 6 grid over the image (:data:`LOCAL_WINDOW`), and join the first search's.
#: KITTI's road under the live maps (the Gabor channel unfilled, 58 % of the pixels measured)
#: was missed: a plane 19.5 degrees off, the camera 3.93 m up; found: 0.24 degrees off and
#: 1.637 m (GT 1.618 m). The fit then takes about twice as long.
LOCAL_SHARE = 0.2
LOCAL_ITERATIONS = 1000
LOCAL_WINDOW = 6
#: Which plane is the floor does not rest on the single best hypothesis, whose pick among planes
#: holding about as many pixels was the seed's luck (ETH3D playground's GT: 4 seeds of 12 found the
#: floor, 8 a slope 31 degrees off through its walls; KITTI under the fast unfilled map: 2 of 12 a
#: plane 31 degrees off). The best hypotheses, at least :data:`SAME_PLANE_DEG` degrees or
#: :data:`SAME_PLANE_HEIGHT` of the height apart, are each refined by least squares on
#: :data:`REFINE_SAMPLE` of the sample's pixels until their inliers stop changing (at most
#: :data:`REFINE_ROUNDS` rounds; :data:`CANDIDATES` distinct planes from at most :data:`REFINED_MAX`
#: refinements). Of those holding :data:`NEAR_BEST` of the most pixels, planes the tilt cone stopped
#: (the data would tilt them past ``max_tilt_deg``) count only when no other does; the floor is the
#: one holding the most pixels, unless more than :data:`BELOW_WARN_SHARE` of the points lie below it
#: and a plane with at most that share below, not the cone's, crosses it at more than
#: :data:`LEVEL_DEG` (then it cuts through the ground, and that plane is the floor). A flat plane
#: along it is a lower level beyond a drop, and the robot stands on the nearer level: a floor
#: dropping 0.3 m 4 m ahead gives the upper level and the warning, where the lower one holds about
#: as many pixels and has none below it.
CANDIDATES = 12
SAME_PLANE_DEG = 2.0
SAME_PLANE_HEIGHT = 0.05
REFINE_ROUNDS = 10
REFINED_MAX = 16
REFINE_SAMPLE = 10000
NEAR_BEST = 0.8
LEVEL_DEG = 5.0
#: Fewest disparities with a value for a fit to be tried.
MIN_PIXELS = 500
#: The floor must hold at least this share of the pixels with a disparity.
MIN_INLIER_SHARE = 0.03
#: ... and its pixels must spread over an area, not a line: their standard deviation across
#: their narrowest direction at least this share of the image's shorter side. Pixels along one
#: row (a kerb, a horizon, a band of texture) fix the plane along that row only, and the least
#: squares return one of the planes through it: one row of a floor 1.3 m under an 800 x 360
#: rig gave a camera 2.32 m above it, pitched 32 degrees (true: 8), on 100 % of the pixels at
#: RMS 0 px. Bands of 5-10 rows (spread 1.4-2.9 px) with matcher-like noise (0.2 px, blurred
#: over 4.5 px) were 2-4 degrees off, 15 rows 1.6; the floors found on KITTI, ETH3D and
#: TartanAir spread over 41-82 px.
MIN_SPREAD_SHARE = 0.01
#: A point counts as below the floor when it lies more than ``max(BELOW_M, BELOW_SIGMAS *
#: sigma_h)`` below the plane, ``sigma_h`` its height's uncertainty from the disparity's: along a
#: pixel's ray the height is ``h = H (d - d_floor) / (d + doffs)``, so this is a point more than
#: :data:`BELOW_M` below whose disparity lies more than ``BELOW_SIGMAS * rms_px`` (at most the
#: inlier tolerance: past it a pixel is off the plane by the fit's own measure) short of the
#: floor's. A plane with more than :data:`BELOW_WARN_SHARE` of the points below it is said not to
#: be one flat floor. With the 0.15 m alone, a far floor's noise counted: a flat floor with
#: 0.2 px of disparity noise had 3 % of its points below (camera level), 18 % (pitched up 20
#: degrees: every floor point over 15 m away), and was said not to be one floor. Measured now:
#: KITTI's road 0.2 %, the rendered floor 0 %, ETH3D playground 1.9 % (was 11 %), terrace 38 %
#: (12-42 % over seeds), TartanAir's street 0.7 % (was 26 %: from 8.3 m up, 0.15 m is under 1 px
#: of disparity at every pixel); a floor dropping 0.3 m 4 m ahead, a ditch or a ramp down
#: 13-25 %.
BELOW_M = 0.15
BELOW_SIGMAS = 3.0
BELOW_WARN_SHARE = 0.05


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity
class GroundPlane:
    """The floor under the rig (see the module docstring for frames and signs).

    Attributes
    ----------
    normal : numpy.ndarray
        ``(3,)`` unit normal pointing up, in the left rectified camera frame.
    height : float
        Camera's distance above the plane (metres, not negative): the plane is ``normal . X +
        height = 0``.
    disparity_plane : tuple of float
        ``(a, b, c)`` with the floor's disparity ``d = a u + b v + c`` (pixels).
    inliers : numpy.ndarray
        ``(H, W)`` bool: pixels whose disparity lies on the plane (a plane rebuilt from
        :meth:`as_dict`'s figures needs one of its images' size: all False will do).
    inlier_share : float
        Share of the pixels with a disparity that lie on the plane.
    rms_px : float
        RMS disparity residual of the inliers (pixels).
    below_share : float
        Share of the pixels with a disparity whose point lies measurably below the plane: more
        than :data:`BELOW_M` and more than :data:`BELOW_SIGMAS` times its height's uncertainty
        (from the inliers' disparity RMS, at most the inlier tolerance). Near 0 for a flat
        floor, however noisy; above :data:`BELOW_WARN_SHARE` the ground is not one plane
        (terraces, steps, slopes), and heights measured from it are approximate. A drop under
        the disparity noise (0.15 m seen from far or from high up) is not counted.
    """

    normal: F64
    height: float
    disparity_plane: tuple[float, float, float]
    inliers: npt.NDArray[np.bool_]
    inlier_share: float
    rms_px: float
    below_share: float = 0.0

    def __post_init__(self) -> None:
        # a plane rebuilt from ground.json (as_dict: the normal a list) described itself and
        # marked obstacles, then failed in floor_frame with Python's "can't multiply sequence
        # by non-int of type 'float'" (camera_in_floor, occupancy_grid, laser_scan, as_dict)
        # ['a', 'b', 'c'] was NumPy's "could not convert string to float: 'a'", naming no field
        raw = _real_array(self.normal)
        if raw is None or raw.dtype.kind == "b":
            raise ValueError(f"normal: expected 3 numbers, got {reprlib.repr(self.normal)}")
        normal = raw.astype(np.float64, copy=False)  # a fitted plane's: the same array
        if normal.shape != (3,):
            raise ValueError(f"normal: expected 3 numbers, got shape {normal.shape}")
        # a normal of another length scaled every height by it, without a word ([0, -2, 0]:
        # 'camera 1.000 m above it' of a floor 0.5 m under it, a point 1 m above it 2 m), and
        # zeros or a NaN gave heights of the camera's alone or NaN, 'roll +180.00' or '+nan'
        length = float(np.linalg.norm(normal)) if np.isfinite(normal).all() else math.nan
        if not abs(length - 1.0) <= 1e-3:
            hint = ": pass normal / np.linalg.norm(normal)" if length > 0 else ""
            raise ValueError(
                f"normal: expected a unit vector (finite, of length 1), got "
                f"{reprlib.repr(self.normal)} of length {length:g}{hint}"
            )
        object.__setattr__(self, "normal", normal)
        # a height of "1.5" or None built, then repr and every use failed in Python's words
        # ("unsupported operand type(s) for /: 'str' and 'float'"), naming no field
        for name in ("height", "inlier_share", "rms_px", "below_share"):
            _number(getattr(self, name), name)
        # a NaN made every height NaN, without a word; an infinity every height infinite (no
        # obstacle marked, 'camera inf m above it', as_dict's Infinity not JSON)
        if not math.isfinite(_number(self.height, "height")):
            raise ValueError(f"height: expected a finite number of metres, got {self.height!r}")
        # a negative one (another tool's sign) put the camera under the floor: "camera -1.000 m
        # above it", every point above the floor below it (no obstacle marked, no beam hit)
        if self.height < 0:
            raise ValueError(
                f"height: expected the camera's distance above the floor (>= 0 m), got "
                f"{self.height!r}: the same plane with the camera above it is -normal, -height"
            )
        # the fit's figures alike: a NaN or infinite one built, and went to as_dict as NaN or
        # Infinity (not JSON); a fitted plane's are finite
        for name in ("inlier_share", "rms_px", "below_share"):
            if not math.isfinite(_number(getattr(self, name), name)):
                raise ValueError(f"{name}: expected a finite number, got {getattr(self, name)!r}")
        # a share of 5.0 or an RMS of -1 built and went to describe() and as_dict as they were
        # (a fitted plane's shares are in [0, 1], its RMS not negative)
        for name in ("inlier_share", "below_share"):
            if not 0.0 <= _number(getattr(self, name), name) <= 1.0:
                raise ValueError(
                    f"{name}: expected a share from 0 to 1, got {getattr(self, name)!r}"
                )
        if _number(self.rms_px, "rms_px") < 0:
            raise ValueError(f"rms_px: expected a number of pixels >= 0, got {self.rms_px!r}")
        try:
            coef = _real_array(self.disparity_plane)
        except ValueError:  # ragged
            coef = None
        except OverflowError:  # an int past a float's range: infinite, as a height of 10**400 is
            coef = np.full(3, math.inf)
        # a bool among numbers ((True, 0, 0): NumPy's int array) was taken as 1
        mixed = isinstance(self.disparity_plane, (list, tuple)) and any(
            isinstance(v, NOT_NUMBERS) for v in self.disparity_plane
        )
        if coef is None or coef.dtype.kind == "b" or mixed or coef.shape != (3,):
            raise ValueError(
                "disparity_plane: expected 3 numbers (a, b, c), got "
                + reprlib.repr(self.disparity_plane)
            )
        if not np.isfinite(coef).all():
            # a NaN coefficient held no pixel on the plane: support 0, "the camera moved"
            raise ValueError(
                "disparity_plane: expected 3 finite numbers (a, b, c), got "
                + reprlib.repr(self.disparity_plane)
            )
        # None (no mask at hand: a plane rebuilt from ground.json) built, then repr and support
        # were AttributeError "'NoneType' object has no attribute 'shape'"
        mask = np.asarray(self.inliers)  # a fitted plane's: the same array
        if mask.ndim != 2 or mask.dtype != np.bool_:
            got = repr(self.inliers) if mask.ndim == 0 else f"{mask.dtype} of shape {mask.shape}"
            raise ValueError(
                f"inliers: expected an (H, W) bool mask (all False if none), got {got}"
            )
        object.__setattr__(self, "inliers", mask)

    @property
    def pitch_deg(self) -> float:
        """Optical axis below the horizon (degrees; positive: looking down at the floor)."""
        # Looking down by t puts the up vector at (0, -cos t, -sin t) in the camera frame.
        return math.degrees(math.asin(max(-1.0, min(1.0, -float(self.normal[2])))))

    @property
    def roll_deg(self) -> float:
        """Rotation about the optical axis (degrees; 0 when the image rows are level)."""
        return math.degrees(math.atan2(float(self.normal[0]), -float(self.normal[1])))

    def height_of(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Signed height above the floor of ``(..., 3)`` points (metres; NaN stays NaN).

        Parameters
        ----------
        points : array_like
            ``(..., 3)`` points in the camera frame the plane was fitted in, metres.

        Returns
        -------
        ndarray, float64
            ``(...)`` heights, metres.
        """
        pts = _points_array(points, "points")
        if pts.ndim == 0 or pts.shape[-1] != 3:
            raise ValueError(f"points: expected shape (..., 3), got {pts.shape}")
        # a point near float64's largest (1.7e308 m) is -inf or +inf high, far outside any
        # band, not NumPy's "overflow encountered in matmul"
        with np.errstate(over="ignore"):
            out: F64 = pts @ self.normal + self.height  # the camera (X = 0) is at +height
        return out

    def support(
        self, disparity: npt.ArrayLike, calib: Calibration, *, inlier_px: float | None = None
    ) -> float:
        """Share of the pixels with a disparity in ``disparity`` that lie on this plane, counted
        as :attr:`inlier_share` counts them: does this floor still hold in another frame?

        A fresh fit on uneven ground or on a noisy frame may settle on another part of the
        ground (on TartanAir's street, JPEG noise alone moved the fit by 4 degrees) while the
        first floor still holds its share; a camera turned on its mount by 2 degrees leaves
        the first floor under a tenth of it (``tests/test_stream.py``).

        Parameters
        ----------
        disparity : array_like
            ``(H, W)`` disparity of another frame of the same rig; NaN where unknown.
        calib : Calibration
            The rig.
        inlier_px : float, optional
            Disparity tolerance (pixels), as :func:`fit_ground_plane`'s; by default
            :data:`GROUND_INLIER_PX`, scaled down with the rig's focal length below
            :data:`GROUND_FOCAL_PX`.

        Returns
        -------
        float
            In [0, 1]; 0 when no pixel has a disparity.

        Raises
        ------
        ValueError
            If ``disparity`` is not a real 2-D map (a bool mask is not), or its size is not the
            calibration's and the plane's, or ``inlier_px`` is not a positive number.
        TypeError
            If ``disparity`` is a whole ``DepthResult`` (pass ``result.disparity``) or ``calib``
            is not a :class:`~stereovision.Calibration`.
        """
        _require_type(calib, "Calibration", "calib")
        from stereovision._validate import positive_finite

        # 0, a negative or NaN tolerance held no pixel: support 0, "the camera moved"
        tol = (
            _inlier_tolerance(calib)
            if inlier_px is None
            else positive_finite(inlier_px, "inlier_px")
        )
        # a DepthResult was "float() argument must be ... not 'DepthResult'", complex values
        # lost their imaginary part with NumPy's ComplexWarning: fit_ground_plane's checks
        disp = _disparity_map(disparity)
        w0, h0 = calib.image_size
        if disp.shape != (h0, w0) or disp.shape != self.inliers.shape:
            # another size: the plane's (u, v) coefficients mean other pixels there
            raise ValueError(
                f"disparity: map is {disp.shape[1]}x{disp.shape[0]}, the calibration's images "
                f"are {w0}x{h0} and this plane's {self.inliers.shape[1]}x{self.inliers.shape[0]}"
            )
        known = np.isfinite(disp) & (disp + _rig(calib)[4] > 0)
        vv, uu = np.nonzero(known)
        if len(vv) == 0:
            return 0.0
        a, b, c = self.disparity_plane
        return float(np.mean(np.abs(a * uu + b * vv + c - disp[known]) < tol))

    def camera_in_floor(self) -> F64:
        """``(4, 4)`` pose of the camera in the floor frame (ROS REP 103: ``x`` forward, ``y``
        left, ``z`` up; origin on the floor under the camera): ``X_floor = T @ X_camera``.

        The floor fixes the height, pitch and roll; the robot's heading and position are not
        seen, so ``x`` is the optical axis laid on the floor and the camera sits at ``(0, 0,
        height)``.

        Returns
        -------
        ndarray
            float64 ``(4, 4)`` homogeneous transform, camera to floor frame.
        """
        out: F64 = np.eye(4)
        out[:3, :3] = floor_frame(self)
        out[2, 3] = self.height
        return out

    def ros2_static_transform(
        self, parent: str = "base_footprint", child: str = "stereo_left_optical"
    ) -> str:
        """The ``ros2 run tf2_ros static_transform_publisher`` command publishing
        :meth:`camera_in_floor` (the camera's optical frame under ``parent``).

        Parameters
        ----------
        parent : str
            The floor-level frame the camera hangs under.
        child : str
            The camera's optical frame.

        Returns
        -------
        str
            The command, one line (a frame name the shell would split or read is quoted).

        Raises
        ------
        ValueError
            If ``parent`` or ``child`` is no tf frame name (not a string, empty, or with a
            leading ``/``), as :class:`~stereovision.rosbag.BagWriter` refuses them.
        """
        import shlex

        from stereovision.rosbag import _frame_name

        # 'base link' went out unquoted, which the shell split into two arguments; None was
        # a frame named "None", '' took the next option for the frame
        parent, child = _frame_name(parent, "parent"), _frame_name(child, "child")
        rot = floor_frame(self)  # floor <- camera: its columns are the camera's axes
        x, y, z, w = _quaternion(rot)
        return (
            "ros2 run tf2_ros static_transform_publisher --x 0 --y 0 "
            f"--z {self.height:.4f} --qx {x:.6f} --qy {y:.6f} --qz {z:.6f} --qw {w:.6f} "
            f"--frame-id {shlex.quote(parent)} --child-frame-id {shlex.quote(child)}"
        )

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready figures (no masks).

        Returns
        -------
        dict
            ``normal``, ``height_m``, ``pitch_deg``, ``roll_deg``, ``disparity_plane``,
            ``inlier_share``, ``rms_px``, ``below_share`` and ``camera_in_floor`` (4 x 4 rows).
        """
        # float(): a plane made by hand of float32 figures went to json.dumps as a TypeError
        return {
            "normal": [float(v) for v in self.normal],
            "height_m": float(self.height),
            "pitch_deg": self.pitch_deg,
            "roll_deg": self.roll_deg,
            "disparity_plane": [float(v) for v in self.disparity_plane],
            "inlier_share": float(self.inlier_share),
            "rms_px": float(self.rms_px),
            "below_share": float(self.below_share),
            "camera_in_floor": self.camera_in_floor().tolist(),
        }

    def __repr__(self) -> str:
        # describe()'s line, not the (H, W) inlier mask the dataclass repr printed.
        h, w = self.inliers.shape[:2]
        return f"GroundPlane({self.describe().removeprefix('ground plane: ')}; mask {w}x{h})"

    def describe(self, unit: str = "m") -> str:
        """One line for a terminal.

        Parameters
        ----------
        unit : str, optional
            Unit of the camera's height (a key of
            :data:`stereovision.calibration.UNIT_TO_METRES`; default metres).

        Returns
        -------
        str
            Height, pitch, roll, inlier share and RMS, and a warning when many points lie below
            the plane.

        Raises
        ------
        ValueError
            If ``unit`` is not a known unit.
        """
        unit = known_unit(unit, UNIT_TO_METRES)
        height = self.height / UNIT_TO_METRES[unit]
        text = (
            f"ground plane: camera {height:.3f} {unit} above it, pitch {self.pitch_deg:+.2f} deg, "
            f"roll {self.roll_deg:+.2f} deg ({100 * self.inlier_share:.0f} % of the pixels, "
            f"RMS {self.rms_px:.2f} px)"
        )
        if self.below_share > BELOW_WARN_SHARE:
            text += (
                f"; {100 * self.below_share:.0f} % of the points lie below it: the ground is not "
                "one flat floor"
            )
        return text


def _quaternion(rot: F64) -> tuple[float, float, float, float]:
    """``(x, y, z, w)`` of a rotation matrix (Shepperd's method; ``w >= 0``)."""
    m = np.asarray(rot, np.float64)
    tr = float(np.trace(m))
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        v = [0.0, 0.0, 0.0]
        v[i] = s / 4
        v[j] = (m[j, i] + m[i, j]) / s
        v[k] = (m[k, i] + m[i, k]) / s
        q = (v[0], v[1], v[2], (m[k, j] - m[j, k]) / s)
    if q[3] < 0:
        q = (-q[0], -q[1], -q[2], -q[3])
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def _rig(calib: Calibration) -> tuple[float, float, float, float, float, float]:
    """``(fx, cx, cy, B, doffs, fy)`` of the rig's rectified left camera (fy last: a camera
    with non-square pixels, e.g. binned 2x1, has fy != fx, and Y divides by fy)."""
    rc = calib if calib.rectified else calib.rectified_calibration()
    return (
        float(rc.K1[0, 0]),
        float(rc.K1[0, 2]),
        float(rc.K1[1, 2]),
        calib.baseline_m,
        rc.doffs_px,
        float(rc.K1[1, 1]),
    )


def _inlier_tolerance(calib: Calibration) -> float:
    """The default disparity tolerance of the floor (pixels): :data:`GROUND_INLIER_PX`, scaled
    down with the rig's rectified focal length below :data:`GROUND_FOCAL_PX`."""
    return GROUND_INLIER_PX * min(1.0, _rig(calib)[0] / GROUND_FOCAL_PX)


def _below_weight(calib: Calibration) -> float:
    """How much a point measurably below a plane counts against it (a pixel on it counts 1):
    ``1 - f / GROUND_FOCAL_PX`` below :data:`GROUND_FOCAL_PX`, else 0.

    The tolerance scaled down with the focal length keeps the band of the scene, but the
    matchers' noise does not shrink with the image (about 0.5 px at any size): the narrower
    the band in pixels, the more of the floor's pixels the noise puts off it, and the less the
    pixels on a plane tell the floor from a plane tilted through whatever stands in the view.
    Points below a plane tell it (there is no ground under the floor), and count the more, the
    narrower the band. KITTI 000005 at 320 px wide (f 186 px: tolerance 0.58 px, weight 0.42):
    planes tilted 25-33 degrees held 17 % of the pixels with 20 % of the points below them, the
    road 11 % with 3 %; ranked by the pixels alone the road was not among those near the most
    (:data:`NEAR_BEST`), and the camera came out 8.1 m above a plane 31 degrees off (it is found
    at weights of 0.15 to 1). At full size (f at least :data:`GROUND_FOCAL_PX`) nothing changes:
    with a weight of 0.25 there, ETH3D terrace's pick among its terraces turned 7 degrees from
    its GT's and spread over 20 degrees across seeds (9.9 without)."""
    return max(0.0, 1.0 - _rig(calib)[0] / GROUND_FOCAL_PX)


def _plane_3d(
    coef: npt.ArrayLike, rig: tuple[float, float, float, float, float, float]
) -> tuple[F64, float]:
    """The 3-D plane ``n . X + h = 0`` (n unit, h > 0) of the disparity plane ``coef``.

    With ``X = (u - cx) Z / f``, ``Y = (v - cy) Z / fy`` and ``Z = f B / (d + doffs)``, the
    plane divided by ``Z`` reads
    ``d + doffs = -(B / h) (n_x (u - cx) + n_y (f / fy) (v - cy) + f n_z)``.
    """
    f, cx, cy, b, doffs, fy = rig
    a, bb, c = (float(v) for v in np.asarray(coef, np.float64).ravel())
    m = np.array(
        [
            -a / b,
            -bb / b * (fy / f),  # times 1.0 exactly for square pixels
            -(c + doffs) / (f * b) - a * cx / (f * b) - bb * cy / (f * b),
        ]
    )
    norm = float(np.linalg.norm(m))
    if not norm > 0:
        return np.array([0.0, -1.0, 0.0]), math.inf
    return m / norm, 1.0 / norm


def _narrowest_spread(u: F64, v: F64) -> float:
    """Standard deviation (pixels) of the pixels ``(u, v)`` across their narrowest direction."""
    if len(u) < 3:
        return 0.0
    cov = np.cov(np.stack([u, v]))
    return float(math.sqrt(max(float(np.linalg.eigvalsh(cov)[0]), 0.0)))


def _refine(
    coef: F64, a_s: F64, d_s: F64, tol: float, rig: Any, cos_max: float
) -> tuple[F64, bool]:
    """Least squares on the inliers of ``coef`` until they stop changing (at most
    :data:`REFINE_ROUNDS` rounds), staying inside the tilt cone: the plane, and whether the
    cone stopped it (the data tilt it further than ``cos_max`` allows)."""
    inl = np.abs(a_s @ coef - d_s) < tol
    for _ in range(REFINE_ROUNDS):
        if int(inl.sum()) < 3:
            break
        a_in = a_s[inl]
        try:  # the normal equations: 3 x 3, several times faster than lstsq's SVD here
            refit = np.asarray(np.linalg.solve(a_in.T @ a_in, a_in.T @ d_s[inl]), np.float64)
        except np.linalg.LinAlgError:
            break
        if -_plane_3d(refit, rig)[0][1] < cos_max:
            return coef, True  # a floor at the edge of the tilt cone: the last fit inside it
        new = np.abs(a_s @ refit - d_s) < tol
        coef = refit
        if np.array_equal(new, inl):
            break
        inl = new
    return coef, False


def _select_floor(
    hypotheses: list[tuple[float, F64]],
    a_s: F64,
    d_s: F64,
    pts_s: F64,
    rig: Any,
    tol: float,
    cos_max: float,
    below_weight: float,
) -> F64 | None:
    """The floor among the RANSAC hypotheses ``(score, coefficients)`` (see :data:`CANDIDATES`;
    the score: pixels on it less ``below_weight`` per point below it, :func:`_below_weight`), or
    None."""
    taken: list[tuple[F64, float]] = []
    # (score: pixels on it less below_weight per point below it, points below it, normal,
    # height, coefficients, stopped by the cone)
    cands: list[tuple[float, int, F64, float, F64, bool]] = []
    same = math.cos(math.radians(SAME_PLANE_DEG))
    refined = 0
    for _count, coef0 in sorted(hypotheses, key=lambda t: -t[0]):
        if len(cands) >= CANDIDATES or refined >= REFINED_MAX:
            break
        normal, height = _plane_3d(coef0, rig)
        if any(
            float(normal @ n) > same and abs(height - h) < SAME_PLANE_HEIGHT * h for n, h in taken
        ):
            continue
        taken.append((normal, height))
        refined += 1
        # refined on part of the sample (a random subset already), counted on all of it
        coef, clipped = _refine(coef0, a_s[:REFINE_SAMPLE], d_s[:REFINE_SAMPLE], tol, rig, cos_max)
        normal, height = _plane_3d(coef, rig)
        if not math.isfinite(height) or any(
            float(normal @ c[2]) > same and abs(height - c[3]) < SAME_PLANE_HEIGHT * c[3]
            for c in cands
        ):
            continue  # converged to a plane already refined
        short = a_s @ coef - d_s
        on = np.abs(short) < tol
        if int(on.sum()) < 3:
            continue
        below = int(np.count_nonzero((pts_s @ normal + height < -BELOW_M) & (short > tol)))
        cands.append((int(on.sum()) - below_weight * below, below, normal, height, coef, clipped))
    if not cands:
        return None
    top = max(c[0] for c in cands)
    # within (1 - NEAR_BEST) of the best score: NEAR_BEST * top alone kept none when every score
    # was negative (more points below each plane than on it, weighted: a noisy map at f << 320)
    bound = NEAR_BEST * top if top >= 0 else (2 - NEAR_BEST) * top
    strong = [c for c in cands if c[0] >= bound]
    # a plane the tilt cone stopped is the cone's, not the data's: the others first
    strong = [c for c in strong if not c[5]] or strong
    floor = max(strong, key=lambda c: c[0])
    if floor[1] > BELOW_WARN_SHARE * len(d_s):
        level = math.cos(math.radians(LEVEL_DEG))
        # a flat plane across the best one: the best cuts through the ground; a flat one along
        # it is a lower level beyond a drop, and the robot stands on the best
        flat = [
            c
            for c in strong
            if c[1] <= BELOW_WARN_SHARE * len(d_s) and float(c[2] @ floor[2]) < level and not c[5]
        ]
        if flat:
            floor = max(flat, key=lambda c: c[0])
    return floor[4]


def fit_ground_plane(
    disparity: npt.ArrayLike,
    calib: Calibration,
    *,
    inlier_px: float | None = None,
    max_tilt_deg: float = MAX_TILT_DEG,
    seed: int = 0,
) -> GroundPlane | None:
    """Find the floor in a disparity map (RANSAC in disparity space, then least squares).

    Parameters
    ----------
    disparity : array_like
        ``(H, W)`` disparity of the rectified left image (``DepthResult.disparity``); NaN where
        unknown.
    calib : Calibration
        The rig (rectified or raw: its rectified geometry is used).
    inlier_px : float, optional
        Disparity tolerance of the plane (pixels). By default :data:`GROUND_INLIER_PX`, scaled
        down with the rig's rectified focal length below :data:`GROUND_FOCAL_PX`: a rig run at a
        lower resolution keeps the band of the scene (KITTI 000005's road at 1242, 621 and 320
        px wide: the camera 1.620, 1.626 and 1.677 m above it, 0.05 and 0.33 degrees from the
        full size's; 8.10 m at 320 px under 1 px and the pixels on a plane alone). Below
        :data:`GROUND_FOCAL_PX` the points measurably below a plane count against it whether
        the tolerance is given or not, so a given one does not fit as the fixed 1 px alone did
        there (``inlier_px=1.0`` on KITTI 000005 at 320 px: 1.79 m, not 8.10).
    max_tilt_deg : float
        Largest angle between the floor's normal and the camera's up axis.
    seed : int
        RANSAC's random seed (the result is deterministic for a seed; the candidates are
        refined until they settle, so a floor comes out the same for any seed: over seeds 0-11
        KITTI's road within 0.06 degrees, ETH3D playground's 0.3, TartanAir's street's 0.01;
        terraced ground, with many planes of about as many pixels, still 2-10).

    Returns
    -------
    GroundPlane or None
        None when no plane within the tilt holds :data:`MIN_INLIER_SHARE` of the pixels (no
        floor in view), when its pixels lie along a line rather than over an area (under
        :data:`MIN_SPREAD_SHARE`: the plane is not determined), or fewer than
        :data:`MIN_PIXELS` disparities are known.

    Raises
    ------
    ValueError
        If ``disparity`` is not a 2-D map of numbers (a bool mask is not) or its size is not
        the calibration's, or a parameter is out of range.
    """
    return _fit_ground(disparity, calib, inlier_px, max_tilt_deg, seed)[0]


def _fit_ground(
    disparity: npt.ArrayLike,
    calib: Calibration,
    inlier_px: float | None = None,
    max_tilt_deg: float = MAX_TILT_DEG,
    seed: int = 0,
) -> tuple[GroundPlane | None, str]:
    """:func:`fit_ground_plane`'s plane, and when there is none the line saying why
    (:func:`_no_floor_line`); "" with a plane."""
    _require_type(calib, "Calibration", "calib")
    from stereovision._validate import positive_finite

    disp = _disparity_map(disparity)
    w0, h0 = calib.image_size
    if disp.shape != (h0, w0):
        raise ValueError(
            f"disparity: map is {disp.shape[1]}x{disp.shape[0]}, the calibration's images are "
            f"{w0}x{h0}"
        )
    tol = _inlier_tolerance(calib) if inlier_px is None else positive_finite(inlier_px, "inlier_px")
    tilt = positive_finite(max_tilt_deg, "max_tilt_deg")
    if tilt >= 90:
        raise ValueError(f"max_tilt_deg: expected less than 90 degrees, got {max_tilt_deg!r}")
    # NumPy's own errors named no argument ("expected non-negative integer"), and took True as 1
    if not isinstance(seed, (int, np.integer)) or isinstance(seed, NOT_NUMBERS) or seed < 0:
        raise ValueError(f"seed: expected an integer >= 0, got {seed!r}")
    rig = _rig(calib)
    known = np.isfinite(disp) & (disp + rig[4] > 0)
    n_known = int(known.sum())
    if n_known < MIN_PIXELS:
        # disparities with no depth (d + doffs <= 0) named apart: OpenCV's SGBM gives a
        # textureless pair its lowest level, 0 px (its "none" is -1, NaN here), and the line
        # said "0 pixels have a disparity" of a map 86 % at 0 px
        n_far = int(np.isfinite(disp).sum()) - n_known
        far = (
            f" and {n_far} one of {-rig[4] + 0.0:g} px or less (no depth: at infinity or "
            "behind the camera)"
            if n_far
            else ""
        )
        return None, (
            f"ground plane: none found ({n_known} pixels have a disparity"
            f"{' giving a depth' if n_far else ''}{far}; a fit needs {MIN_PIXELS})"
        )
    vv, uu = np.nonzero(known)
    u, v, d = uu.astype(np.float64), vv.astype(np.float64), disp[known]
    design = np.column_stack([u, v, np.ones_like(u)])
    rng = np.random.default_rng(seed)
    sample = rng.choice(len(d), min(len(d), RANSAC_SAMPLE), replace=False)
    a_s, d_s = design[sample], d[sample]
    cos_max = math.cos(math.radians(tilt))
    f, cx, cy, b, doffs, fy = rig
    z_s = f * b / (d_s + doffs)
    pts_s = np.column_stack([(a_s[:, 0] - cx) * z_s / f, (a_s[:, 1] - cy) * z_s / fy, z_s])
    # (sample pixels on it less below_weight per sample point below it, coefficients)
    below_weight = _below_weight(calib)
    hypotheses: list[tuple[float, F64]] = []

    def score(pick: Any) -> float:
        try:
            coef = np.linalg.solve(a_s[pick], d_s[pick])
        except np.linalg.LinAlgError:
            return 0.0
        normal, height = _plane_3d(coef, rig)
        if -normal[1] < cos_max:  # not a floor (the normal must point up, within the tilt)
            return 0.0
        short = a_s @ coef - d_s
        value = float(np.count_nonzero(np.abs(short) < tol))
        if below_weight > 0:  # points below it count against it (a rig below GROUND_FOCAL_PX)
            below = (short > tol) & (pts_s @ normal + height < -BELOW_M)
            value -= below_weight * int(np.count_nonzero(below))
        hypotheses.append((value, coef))
        return value

    best_count = 0.0
    for _ in range(RANSAC_ITERATIONS):
        best_count = max(best_count, score(rng.choice(len(d_s), 3, replace=False)))
    if best_count < LOCAL_SHARE * len(d_s):
        # a Python int: np.int64(2**63 - 1) + 1 wrapped to a negative seed (NumPy's "expected
        # non-negative integer", naming no argument), np.uint64's largest to 0 with a warning
        near_rng = np.random.default_rng(int(seed) + 1)
        # the sample's pixels by cell of a LOCAL_WINDOW x LOCAL_WINDOW grid over the image
        gx = np.minimum((a_s[:, 0] * LOCAL_WINDOW / disp.shape[1]).astype(int), LOCAL_WINDOW - 1)
        gy = np.minimum((a_s[:, 1] * LOCAL_WINDOW / disp.shape[0]).astype(int), LOCAL_WINDOW - 1)
        cell = gy * LOCAL_WINDOW + gx
        order = np.argsort(cell, kind="stable")
        starts = np.searchsorted(cell[order], np.arange(LOCAL_WINDOW**2 + 1))
        for _ in range(LOCAL_ITERATIONS):
            i = int(near_rng.integers(len(d_s)))
            near = order[starts[cell[i]] : starts[cell[i] + 1]]
            if len(near) < 3:
                continue
            j, k = near_rng.choice(near, 2, replace=False)
            score([i, j, k])
    no_plane = (
        f"ground plane: none found (no near-level plane holds {100 * MIN_INLIER_SHARE:.0f} % "
        "of the pixels)"
    )
    best = _select_floor(hypotheses, a_s, d_s, pts_s, rig, tol, cos_max, below_weight)
    if best is None:
        return None, no_plane
    # least squares on all pixels (those near the plane: it moves little from the sample's)
    near_px = np.abs(design @ best - d) < 4 * tol
    coef = _refine(best, design[near_px], d[near_px], tol, rig, cos_max)[0]
    inl = np.abs(design @ coef - d) < tol
    share = float(inl.mean())
    normal, height = _plane_3d(coef, rig)
    if share < MIN_INLIER_SHARE or not math.isfinite(height):
        return None, no_plane
    spread, needed = _narrowest_spread(u[inl], v[inl]), MIN_SPREAD_SHARE * min(disp.shape)
    if spread < needed:  # pixels along a line: the plane turns freely about it
        return None, (
            f"ground plane: none found (the likeliest floor's pixels lie along a line, "
            f"{spread:.1f} px across where a fit needs {needed:.1f} px)"
        )
    mask = np.zeros(disp.shape, bool)
    mask[vv[inl], uu[inl]] = True
    resid = design[inl] @ coef - d[inl]
    rms = float(np.sqrt(np.mean(resid**2)))
    z = f * b / (d + doffs)
    pts = np.column_stack([(u - cx) * z / f, (v - cy) * z / fy, z])
    # below by more than BELOW_M and by more than BELOW_SIGMAS height sigmas (see BELOW_SIGMAS)
    short = design @ coef - d  # > 0: farther along its ray than the floor
    band = min(tol, BELOW_SIGMAS * rms)
    below = float(np.mean((pts @ normal + height < -BELOW_M) & (short > band)))
    plane = GroundPlane(
        normal=normal,
        height=height,
        disparity_plane=(float(coef[0]), float(coef[1]), float(coef[2])),
        inliers=mask,
        inlier_share=share,
        rms_px=rms,
        below_share=below,
    )
    return plane, ""


def _disparity_map(disparity: npt.ArrayLike) -> F64:
    """``disparity`` as a float64 ``(H, W)`` map, after the checks of what is none: a whole
    ``DepthResult`` (TypeError naming ``result.disparity``), complex values, a bool mask, a map
    past the kernels' 32-bit indices (before the copy), another number of dimensions."""
    from stereovision._validate import check_index_range, not_a_result

    not_a_result(disparity, "disparity", "disparity")
    if np.iscomplexobj(disparity):  # NumPy would drop the imaginary part with a warning
        raise ValueError("disparity: expected a real map, got complex values")
    if isinstance(disparity, np.ndarray) and disparity.ndim == 2:  # before the float64 copy
        check_index_range(disparity.shape, "disparity", "map")
    if np.asarray(disparity).dtype.kind == "b":
        # a mask (plane.inliers, obstacle_mask's) was a map of 0 and 1 px: no floor found, or
        # support 0.02 of the floor it was fitted on ("the camera moved")
        raise ValueError("disparity: expected a map of pixels (numbers), got a bool mask")
    disp = np.asarray(disparity, np.float64)
    if disp.ndim != 2:
        raise ValueError(f"disparity: expected a (H, W) map, got shape {disp.shape}")
    return disp


def _points_array(points: npt.ArrayLike, field: str) -> F64:
    """``points`` as a float64 array, after the checks of what is none: a whole
    ``DepthResult`` (TypeError naming ``result.<field>``: it was "float() argument must be ...
    not 'DepthResult'") and complex values (NumPy dropped the imaginary part with a warning).
    """
    from stereovision._validate import not_a_result

    not_a_result(points, "points", field)
    if np.iscomplexobj(points):
        raise ValueError("points: expected real points, got complex values")
    return np.asarray(points, np.float64)


def _no_floor_line(disparity: npt.ArrayLike, calib: Calibration) -> str:
    """The line for a map :func:`fit_ground_plane` (default parameters) found no floor in, with
    the reason that holds: under :data:`MIN_PIXELS` disparities (finite, in front of the
    camera) no fit is tried; else no near-level plane held :data:`MIN_INLIER_SHARE` of them, or
    the best one's pixels lay along a line (:data:`MIN_SPREAD_SHARE`). The fit is run again
    (the same seed: the same outcome): ``depth --ground`` and the GUI's Find floor take the
    line from their own fit (:func:`_fit_ground`) instead.
    """
    plane, why = _fit_ground(disparity, calib)
    return why if plane is None else ""


def _number(value: object, name: str) -> float:
    """``value`` as a float, after a ``ValueError`` naming ``name`` for what is not a real number:
    ``float()`` read ``"1"`` as 1 m and True as 1 without a word. An int beyond a float's range
    is an infinity of its sign (the range checks then name it)."""
    if not real_number(value):
        raise ValueError(f"{name}: expected a number, got {value!r}")
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def obstacle_mask(
    points: npt.ArrayLike,
    plane: GroundPlane,
    *,
    min_height: float = 0.15,
    max_height: float = 2.0,
    max_range: float = math.inf,
) -> npt.NDArray[np.bool_]:
    """Pixels whose point stands between ``min_height`` and ``max_height`` above the floor.

    Parameters
    ----------
    points : array_like
        ``(H, W, 3)`` points in the left rectified frame (``calib.reproject(disparity)``), NaN
        where unknown.
    plane : GroundPlane
    min_height, max_height : float
        Height band above the floor (metres): below it is floor (and its noise), above it what
        the robot passes under.
    max_range : float
        Farthest distance (metres, along the optical axis) considered.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` bool.

    Raises
    ------
    ValueError
        For points not real or not of shape ``(H, W, 3)``, or an empty or negative band.
    """
    _require_type(plane, "GroundPlane", "plane")
    pts = _points_array(points, "point_image()")
    if pts.ndim != 3 or pts.shape[2] != 3:
        # res.points is the cloud, one row per pixel with a depth: no image to mark
        cloud = pts.ndim == 2 and pts.shape[1:] == (3,)
        hint = ": the image-shaped points, result.point_image(filled=True)" if cloud else ""
        raise ValueError(f"points: expected shape (H, W, 3), got {pts.shape}{hint}")
    lo, hi = _number(min_height, "min_height"), _number(max_height, "max_height")
    if not (math.isfinite(lo) and lo >= 0 and hi > lo):
        raise ValueError(
            f"min_height, max_height: expected 0 <= min_height < max_height, got {lo!r}, {hi!r}"
        )
    far = _number(max_range, "max_range")
    if not far > 0:
        raise ValueError(f"max_range: expected a positive distance, got {max_range!r}")
    with np.errstate(invalid="ignore"):
        h = plane.height_of(pts)
        out: npt.NDArray[np.bool_] = (h > lo) & (h < hi) & (pts[..., 2] < far)
    return out


def _pair(value: Any, name: str, what: str) -> tuple[float, float]:
    """``value`` as two numbers (:func:`_number`), after a ``ValueError`` naming ``name`` for
    what is not a pair: unpacking said 'too many values to unpack' or 'object is not
    iterable', and ``float()`` read ``"0"`` as 0 m."""
    try:
        a, b = value
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected {what}, got {value!r}") from None
    return _number(a, name), _number(b, name)


#: nav_msgs/OccupancyGrid cell values.
UNKNOWN, FREE, OCCUPIED = -1, 0, 100
#: Obstacle points a cell needs to be occupied (one stray point is noise).
MIN_OBSTACLE_POINTS = 3


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity
class OccupancyGrid:
    """A bird's-eye grid of the floor around the rig, as ROS's ``nav_msgs/OccupancyGrid``.

    Frame (ROS REP 103): origin on the floor under the camera, ``x`` forward (the optical axis
    laid on the floor), ``y`` to the left, metres. Row ``i``, column ``j`` is the cell whose
    corner nearest the origin is ``origin + (j, i) * resolution``.

    Attributes
    ----------
    data : numpy.ndarray
        ``(rows, cols)`` int8: -1 unknown, 0 free (floor seen), 100 occupied (integers of
        another type are taken as int8; other values, no cells, bools are refused).
    resolution : float
        Cell side (metres, positive).
    origin : tuple of float
        ``(x, y)`` of cell ``(0, 0)``'s corner (metres, finite).
    """

    data: npt.NDArray[np.int8]
    resolution: float
    origin: tuple[float, float]

    def __post_init__(self) -> None:
        # a grid made by hand (or with dataclasses.replace) took anything: a resolution of 0
        # built, then cell_of was ZeroDivisionError and save wrote 'resolution: 0.0' (-0.1 and
        # NaN too), a list of cells was AttributeError "'list' object has no attribute
        # 'shape'", an origin of None "'NoneType' object is not subscriptable", and no cells
        # OpenCV's "!_img.empty()" from save; each is refused naming the field
        from stereovision._validate import positive_finite

        raw = _real_array(self.data)
        cells = None if raw is None or raw.dtype.kind not in "iu" else raw
        if cells is None or cells.ndim != 2 or cells.size == 0:
            shown = reprlib.repr(self.data) if raw is None else f"{raw.dtype} of shape {raw.shape}"
            raise ValueError(f"data: expected (rows, cols) integer cells, got {shown}")
        odd = cells[(cells != UNKNOWN) & (cells != FREE) & (cells != OCCUPIED)]
        if odd.size:  # image() drew any other value as unknown
            raise ValueError(
                f"data: expected cells of -1 (unknown), 0 (free) or 100 (occupied), "
                f"got {odd.flat[0]}"
            )
        if cells.dtype != np.int8:  # occupancy_grid's: the same array
            object.__setattr__(self, "data", cells.astype(np.int8))
        object.__setattr__(self, "resolution", positive_finite(self.resolution, "resolution"))
        x0, y0 = _pair(self.origin, "origin", "(x, y) in metres")
        if not (math.isfinite(x0) and math.isfinite(y0)):
            raise ValueError(f"origin: expected (x, y) in metres, got {self.origin!r}")
        object.__setattr__(self, "origin", (x0, y0))

    def __repr__(self) -> str:
        # A summary, not the (rows, cols) cells the dataclass repr printed.
        rows, cols = self.data.shape[:2]
        counts = {v: int((self.data == v).sum()) for v in (0, 100, -1)}
        return (
            f"OccupancyGrid({cols}x{rows} cells of {self.resolution:g} m, origin "
            f"({self.origin[0]:g}, {self.origin[1]:g}) m; {counts[0]} free, {counts[100]} "
            f"occupied, {counts[-1]} unknown)"
        )

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """``(row, col)`` of the cell holding floor point ``(x, y)``.

        Parameters
        ----------
        x, y : float
            Floor-frame coordinates in metres (``x`` forward, ``y`` left).

        Returns
        -------
        tuple of int
            ``(row, col)``; outside the grid when the point is (negative or past its size).

        Raises
        ------
        ValueError
            If ``x`` or ``y`` is not a finite number.
        """
        # NaN was math.floor's "cannot convert float NaN to integer", naming neither, inf an
        # OverflowError, "1" Python's "unsupported operand type(s)"
        for name, v in (("x", x), ("y", y)):
            if not math.isfinite(_number(v, name)):
                raise ValueError(
                    f"{name}: expected a finite number of metres, got {reprlib.repr(v)}"
                )
        return self._index(y, self.origin[1]), self._index(x, self.origin[0])

    def _index(self, v: float, origin: float) -> int:
        """Row or column of coordinate ``v``: a finite point so far out that its quotient
        overflows (``cell_of(1e308, 0)``) was math.floor's OverflowError; it is the exact index,
        far outside the grid, as for any point far outside it."""
        with np.errstate(over="ignore"):  # an np.float32 coordinate's quotient is float32
            q = (v - origin) / self.resolution
        if math.isfinite(q):
            return math.floor(q)
        exact = (Fraction(float(v)) - Fraction(float(origin))) / Fraction(float(self.resolution))
        return math.floor(exact)

    def image(self) -> npt.NDArray[np.uint8]:
        """map_server's picture: occupied 0 (black), free 254, unknown 205. As map_server reads
        it, the picture's columns run along ``x`` (forward, to the right) and its rows along
        ``y`` from the top (left) down: the grid's rows flipped.

        Returns
        -------
        ndarray
            uint8 ``(H, W)`` grey levels 0, 205 or 254.
        """
        img = np.full(self.data.shape, 205, np.uint8)
        img[self.data == FREE] = 254
        img[self.data == OCCUPIED] = 0
        out: npt.NDArray[np.uint8] = img[::-1]
        return out

    def save(self, directory: str | Path, name: str = "map") -> tuple[Path, Path]:
        """Write ``NAME.png`` and ``NAME.yaml`` for ROS ``map_server`` (nav2 loads them).

        The two files are written as a pair: both go to temporary files in ``directory`` first,
        then the picture and, last, the YAML replace the destinations. If anything fails, the
        temporary files are removed and a previous ``NAME.png``/``NAME.yaml`` pair is left as
        it was (never a new picture with an old YAML, nor the reverse).

        Parameters
        ----------
        directory : str or pathlib.Path
            The folder to write into; created if missing.
        name : str
            The files' stem.

        Returns
        -------
        tuple of pathlib.Path
            The picture and the YAML file.

        Raises
        ------
        ValueError
            A ``name`` that is empty or holds a folder (``"../x"``, ``"a/b"``), or a ``name``
            or ``directory`` holding a null byte.
        TypeError
            A ``directory`` that is bytes or no file name at all.
        RuntimeError
            If the grid could not be encoded as PNG.
        OSError
            If ``directory`` is a file (FileExistsError), a link to nothing or under a file
            (NotADirectoryError), or a file could not be written; the previous pair is then
            intact (should putting a previous file back fail too, its copy is kept and named in
            the exception's notes).
        """
        import json
        import re

        import cv2

        # a stem with a folder in it ("../x") wrote outside ``directory``
        if not isinstance(name, str) or name in ("", ".", "..") or Path(name).name != name:
            raise ValueError(f"name: expected a file stem without a folder, got {name!r}")
        if "\x00" in name:  # the OS's bare "embedded null byte" named no argument
            raise ValueError(f"name: expected a file stem without a null byte, got {name!r}")
        from stereovision._validate import as_path

        # Path(str(...)): b"/tmp/maps" wrote into a folder named "b'", None into "None"
        d = as_path(directory, "directory")  # a null byte too, in the argument's name
        if d.exists() and not d.is_dir():  # mkdir's "[Errno 17] File exists: 'maps'"
            raise FileExistsError(f"cannot write the map into {d}: it is a file, not a folder")
        from stereovision.io import make_folder

        # mkdir's words named no cause: "[Errno 17] File exists" of a link to nothing (a
        # maps/ link to an unmounted drive), "[Errno 20] Not a directory" under a file
        make_folder(d)
        png, yml = d / f"{name}.png", d / f"{name}.yaml"
        ok, buf = cv2.imencode(".png", self.image())
        if not ok:
            raise RuntimeError("could not encode the occupancy grid as PNG")
        # float(): a NumPy scalar's repr is "np.float64(0.05)", which map_server cannot read
        res, x0, y0 = (float(v) for v in (self.resolution, *self.origin))
        # quoted unless plain: 'image: run #3.png' read as 'run' (the rest a comment), and
        # 'lab: 2.png', '*x.png' or '[a].png' were no YAML at all; JSON's string is YAML's
        image = png.name
        if not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9._-]*", image):
            image = json.dumps(image, ensure_ascii=False)
        text = (
            f"image: {image}\nmode: trinary\nresolution: {res!r}\n"
            f"origin: [{x0!r}, {y0!r}, 0.0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
        )
        from stereovision.io import write_together

        write_together([(png, buf.tobytes()), (yml, text.encode("utf-8"))])
        return png, yml


def _cells(extent: float, res: float) -> int:
    """Cells of side ``res`` covering ``extent`` (metres): a whole number of them when the
    quotient is one but for rounding (2.1 m / 0.3 m is 7.000000000000001, and ``ceil`` added
    an eighth column past the extent asked for)."""
    q = extent / res
    return round(q) if math.isclose(q, round(q), rel_tol=1e-9) else math.ceil(q)


def floor_frame(plane: GroundPlane) -> F64:
    """``(3, 3)`` rows: the floor frame's ``x`` (forward), ``y`` (left), ``z`` (up) axes in the
    camera frame (REP 103).

    Parameters
    ----------
    plane : GroundPlane
        The floor, as :func:`fit_ground_plane` found it.

    Returns
    -------
    ndarray
        float64 ``(3, 3)``, one axis per row: a camera-frame vector ``v`` is ``R @ v`` in the
        floor frame.
    """
    up = plane.normal
    forward = np.array([0.0, 0.0, 1.0]) - up * up[2]  # the optical axis laid on the floor
    norm = float(np.linalg.norm(forward))
    if norm < 1e-6:  # looking straight down: forward is the image's up
        forward = np.array([0.0, -1.0, 0.0]) - up * (-up[1])
        norm = float(np.linalg.norm(forward))
    forward = forward / norm
    left = np.cross(up, forward)
    return np.stack([forward, left, up])


def occupancy_grid(
    points: npt.ArrayLike,
    plane: GroundPlane,
    *,
    resolution: float = 0.1,
    forward: tuple[float, float] = (0.0, 20.0),
    lateral: tuple[float, float] = (-10.0, 10.0),
    min_height: float = 0.15,
    max_height: float = 2.0,
) -> OccupancyGrid:
    """A bird's-eye occupancy grid from a depth map's points and its floor.

    A cell is occupied when at least :data:`MIN_OBSTACLE_POINTS` points stand in the height band
    over it, free when floor points (within ``min_height`` of the plane) fall in it and it is not
    occupied, unknown otherwise (not seen: behind an obstacle, out of view).

    Parameters
    ----------
    points : array_like
        ``(H, W, 3)`` or ``(N, 3)`` points in the left rectified frame (metres, NaN skipped).
    plane : GroundPlane
    resolution : float
        Cell side (metres).
    forward, lateral : tuple of float
        Extent along ``x`` (forward) and ``y`` (left), metres.
    min_height, max_height : float
        The obstacle band above the floor (as :func:`obstacle_mask`).

    Returns
    -------
    OccupancyGrid

    Raises
    ------
    ValueError
        For points not real or not of shape ``(..., 3)``, a non-positive resolution, an extent
        not two numbers or empty, a grid over 4096 cells a side, or a bad height band.
    """
    _require_type(plane, "GroundPlane", "plane")
    from stereovision._validate import positive_finite

    pts = _points_array(points, "point_image()")
    if pts.ndim == 0 or pts.shape[-1] != 3:
        raise ValueError(f"points: expected shape (..., 3), got {pts.shape}")
    res = positive_finite(resolution, "resolution")
    x0, x1 = _pair(forward, "forward", "(near, far)")
    y0, y1 = _pair(lateral, "lateral", "(right, left)")
    if not (math.isfinite(x0) and math.isfinite(x1) and x1 > x0):
        raise ValueError(f"forward: expected (near, far) with far > near, got {forward!r}")
    if not (math.isfinite(y0) and math.isfinite(y1) and y1 > y0):
        raise ValueError(f"lateral: expected (right, left) with left > right, got {lateral!r}")
    # a quotient past a float (1 m of 1e-308 m cells, or an extent of -1e308 to 1e308 m) is
    # inf, which _cells could not count (OverflowError "cannot convert float infinity")
    if not (math.isfinite((x1 - x0) / res) and math.isfinite((y1 - y0) / res)):
        raise ValueError(
            f"resolution: {res!r} m cells over {x1 - x0:g} x {y1 - y0:g} m are over 4096 a side"
        )
    cols, rows = _cells(x1 - x0, res), _cells(y1 - y0, res)
    if cols > 4096 or rows > 4096:
        # a count of a 1e-300 m cell was shown in its 300 digits
        shown = [str(n) if n < 10**9 else f"{n:.3g}" for n in (cols, rows)]
        raise ValueError(f"resolution: a {shown[0]} x {shown[1]} grid is over 4096 cells a side")
    lo, hi = _number(min_height, "min_height"), _number(max_height, "max_height")
    if not (math.isfinite(lo) and lo >= 0 and hi > lo):
        raise ValueError(
            f"min_height, max_height: expected 0 <= min_height < max_height, got {lo!r}, {hi!r}"
        )
    flat = pts.reshape(-1, 3)
    flat = flat[np.all(np.isfinite(flat), axis=1)]
    axes = floor_frame(plane)
    with np.errstate(over="ignore"):  # a point near float64's largest: infinite, outside
        xyz = flat @ axes.T
        h = xyz[:, 2] + plane.height  # height above the floor
    # a point 1e308 m away: its quotient inf (outside), not "overflow encountered in divide"
    with np.errstate(over="ignore"):
        fj = np.floor((xyz[:, 0] - x0) / res)
        fi = np.floor((xyz[:, 1] - y0) / res)
    # the cells are counted as floats, cast once inside: a finite point past int64's range
    # (1e30 m away) was NumPy's "RuntimeWarning: invalid value encountered in cast"
    inside = (fj >= 0) & (fj < cols) & (fi >= 0) & (fi < rows)
    j = np.where(inside, fj, 0).astype(np.int64)
    i = np.where(inside, fi, 0).astype(np.int64)
    obstacle = inside & (h > lo) & (h < hi)
    floor = inside & (np.abs(h) <= lo)
    n_obs = np.bincount(i[obstacle] * cols + j[obstacle], minlength=rows * cols)
    n_floor = np.bincount(i[floor] * cols + j[floor], minlength=rows * cols)
    data = np.full(rows * cols, UNKNOWN, np.int8)
    data[n_floor > 0] = FREE
    data[n_obs >= MIN_OBSTACLE_POINTS] = OCCUPIED
    return OccupancyGrid(data.reshape(rows, cols), res, (x0, y0))


# ---------------------------------------------------------------------------------- laser scan


@dataclass(frozen=True, eq=False)  # array fields: == and hash by identity
class LaserScan:
    """A planar scan of the obstacles around the rig, as ROS's ``sensor_msgs/LaserScan``.

    The scan lies in the floor plane, centred on the floor point under the camera, in the floor
    frame of :class:`OccupancyGrid` (REP 103: angle 0 along ``x``, the optical axis laid on the
    floor; positive angles to the left). Beam ``i`` points at ``angle_min + i *
    angle_increment``. Ranges follow REP 117: a distance where an obstacle was seen, ``+inf``
    where the floor was seen and nothing stands on it within ``range_max``, NaN where the beam
    saw neither (above the horizon, out of view).

    Attributes
    ----------
    angle_min, angle_max, angle_increment : float
        Radians (``angle_increment`` negative for a scan turning clockwise, ``angle_max``
        then at or below ``angle_min``).
    range_min, range_max : float
        Metres.
    ranges : numpy.ndarray
        ``(n,)`` float32 metres (given as :meth:`as_dict`'s list, ``null`` and ``"inf"`` /
        ``"-inf"`` included, it is read back as such an array).
    """

    angle_min: float
    angle_max: float
    angle_increment: float
    range_min: float
    range_max: float
    ranges: npt.NDArray[np.float32]

    def __post_init__(self) -> None:
        # a scan rebuilt from scan.json (as_dict: the ranges a list, NaN as null and +-inf as
        # "inf" / "-inf") failed in repr and endpoints with NumPy's "ufunc 'isfinite' not
        # supported for the input types", and as_dict with float()'s "not 'NoneType'"
        self._check_fields()
        r = self.ranges
        if isinstance(r, np.ndarray) and r.dtype == np.float32 and r.ndim == 1:
            return  # laser_scan's: the same array
        if isinstance(r, (list, tuple)):
            special = {"inf": math.inf, "-inf": -math.inf}
            r = [
                math.nan if v is None else special.get(v, v) if isinstance(v, str) else v for v in r
            ]
        try:  # True was a range of 1 m
            ranges = np.asarray(None if any(isinstance(v, NOT_NUMBERS) for v in r) else r)
        except (TypeError, ValueError):  # ragged; no sequence
            ranges = np.asarray(None)
        if ranges.ndim != 1 or ranges.dtype.kind not in "iuf":  # not bools, strings, complex
            raise ValueError(
                "ranges: expected (n,) metres (numbers, null for NaN, 'inf' / '-inf' as "
                f"as_dict writes them), got {reprlib.repr(self.ranges)}"
            )
        object.__setattr__(self, "ranges", ranges.astype(np.float32))

    def _check_fields(self) -> None:
        """The angles and range limits as floats, after a ``ValueError`` naming the field: a
        scan made by hand with an increment of 0 put every beam at ``angle_min`` (NaN: every
        endpoint NaN), without a word, and an angle of None or ``"a"`` was Python's "must be
        real number, not NoneType" from repr. ``"inf"`` / ``"-inf"`` are read as
        :meth:`as_dict` writes them."""
        values = {}
        for name in ("angle_min", "angle_max", "angle_increment", "range_min", "range_max"):
            v = getattr(self, name)
            v = {"inf": math.inf, "-inf": -math.inf}.get(v, v) if isinstance(v, str) else v
            values[name] = _number(v, name)
        a0, a1, inc = values["angle_min"], values["angle_max"], values["angle_increment"]
        if not (math.isfinite(a0) and math.isfinite(a1)):
            raise ValueError(f"angle_min, angle_max: expected finite radians, got {a0!r}, {a1!r}")
        # negative: a scan turning clockwise, as sensor_msgs/LaserScan allows (a lidar mounted
        # upside down); its beams go down from angle_min, angle_max at or below it
        if not (math.isfinite(inc) and inc != 0):
            raise ValueError(f"angle_increment: expected a nonzero finite number, got {inc!r}")
        if (a1 - a0) * inc < 0:  # beams that turn away from angle_max
            raise ValueError(
                "angle_min, angle_max: expected angle_max >= angle_min for a positive "
                f"angle_increment (<= for a negative one), got {a0!r}, {a1!r} and {inc!r}"
            )
        r0, r1 = values["range_min"], values["range_max"]
        if not (r0 >= 0 and r1 > r0):
            raise ValueError(
                f"range_min, range_max: expected 0 <= range_min < range_max, got {r0!r}, {r1!r}"
            )
        for name, v in values.items():
            object.__setattr__(self, name, v)

    def __repr__(self) -> str:
        # A summary, not the (n,) ranges the dataclass repr printed.
        r = self.ranges
        hit = r[np.isfinite(r)]
        nearest = f", nearest {float(hit.min()):.3g} m" if hit.size else ""
        return (
            f"LaserScan({len(r)} beams, {math.degrees(self.angle_min):+.1f} to "
            f"{math.degrees(self.angle_max):+.1f} deg, range {self.range_min:g}-"
            f"{self.range_max:g} m; {hit.size} hit an obstacle{nearest}, "
            f"{int(np.isposinf(r).sum())} free, {int(np.isnan(r).sum())} unseen)"
        )

    @property
    def angles(self) -> F64:
        """The beams' angles (radians)."""
        out: F64 = self.angle_min + self.angle_increment * np.arange(
            len(self.ranges), dtype=np.float64
        )
        return out

    def endpoints(self) -> F64:
        """Where the beams that hit an obstacle ended.

        Returns
        -------
        ndarray
            float64 ``(m, 2)`` floor-frame ``(x, y)`` in metres, one row per finite range.
        """
        hit = np.isfinite(self.ranges)
        r, a = self.ranges[hit].astype(np.float64), self.angles[hit]
        out: F64 = np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
        return out

    def as_dict(self) -> dict[str, Any]:
        """The ``sensor_msgs/LaserScan`` fields, JSON-ready: JSON has no NaN or infinity, so
        a NaN range is ``null``, ``+inf`` the string ``"inf"`` and ``-inf`` (REP 117: too near
        to measure) ``"-inf"``; so are the other fields of a scan made by hand.

        Returns
        -------
        dict
            ``sensor_msgs/LaserScan``'s field names (``time_increment`` and ``scan_time`` 0) to
            their values, ``ranges`` a list.
        """

        def number(v: Any, digits: int | None = None) -> Any:
            # "inf" for -inf too said "free" of an obstacle too near to measure, and a scalar
            # field of a hand-made scan went to json.dumps as Infinity or NaN (not JSON)
            v = float(v)
            if math.isnan(v):
                return None
            if math.isinf(v):
                return "inf" if v > 0 else "-inf"
            return v if digits is None else round(v, digits)

        return {
            "angle_min": number(self.angle_min),
            "angle_max": number(self.angle_max),
            "angle_increment": number(self.angle_increment),
            "time_increment": 0.0,
            "scan_time": 0.0,
            "range_min": number(self.range_min),
            "range_max": number(self.range_max),
            "ranges": [number(v, 4) for v in self.ranges],
            "intensities": [],
        }


def _beam_span(calib: Calibration, axes: F64) -> tuple[float, float, int]:
    """Floor-frame angles of the image's sides (the rays of its border pixels) and its width.

    The rays of the left rectified camera, the frame of the points: a raw rig's own ``K1``
    (another focal length and centre) would give another field of view.
    """
    rc = calib if calib.rectified else calib.rectified_calibration()
    w, h = rc.image_size
    k_inv = np.linalg.inv(np.asarray(rc.K1, np.float64))
    u = np.r_[np.zeros(h), np.full(h, w - 1.0), np.arange(w), np.arange(w)]
    v = np.r_[np.arange(h), np.arange(h), np.zeros(w), np.full(w, h - 1.0)]
    rays = np.stack([u, v, np.ones_like(u)], axis=1) @ k_inv.T @ axes[:2].T
    ang = np.arctan2(rays[:, 1], rays[:, 0])
    return float(ang.min()), float(ang.max()), w


def _same_image(pts: F64, plane: GroundPlane, calib: Calibration | None) -> None:
    """A ``ValueError`` for an image of points (``(H, W, 3)``) of another size than the plane's
    map, or than the calibration's images: points of another frame or rig, whose scan the beams
    of ``calib`` (one per column of its images) do not describe. A cloud (``(N, 3)``) has no
    image size to check."""
    if pts.ndim != 3:
        return
    h, w = pts.shape[:2]
    sizes = {"this plane's map is": plane.inliers.shape}
    if calib is not None:
        sizes["the calibration's images are"] = calib.image_size[::-1]
    if any(tuple(size) != (h, w) for size in sizes.values()):
        said = " and ".join(f"{what} {size[1]}x{size[0]}" for what, size in sizes.items())
        raise ValueError(f"points: an image of {w}x{h} points, where {said}")


def laser_scan(
    points: npt.ArrayLike,
    plane: GroundPlane,
    calib: Calibration | None = None,
    *,
    angle_min: float | None = None,
    angle_max: float | None = None,
    angle_increment: float | None = None,
    min_height: float = 0.15,
    max_height: float = 2.0,
    range_min: float = 0.0,
    range_max: float = 20.0,
    min_points: int = MIN_OBSTACLE_POINTS,
) -> LaserScan:
    """A ``LaserScan`` of the obstacles standing on the floor, for a 2-D navigation stack.

    What ROS's ``depthimage_to_laserscan`` does with a band of image rows, done on the floor:
    every point between ``min_height`` and ``max_height`` above the floor (as
    :func:`obstacle_mask`) is laid on the floor plane, and each beam's range is the distance of
    its ``min_points``-th nearest such point (one stray point is not an obstacle). A camera
    pitched towards the floor thus still gives a level scan, and the floor itself never shows
    up as an obstacle.

    Parameters
    ----------
    points : array_like
        ``(H, W, 3)`` or ``(N, 3)`` points in the left rectified frame (metres, NaN skipped).
    plane : GroundPlane
    calib : Calibration, optional
        The rig the points come from (rectified or raw: its rectified camera is used): sets
        the default angles, from the left to the right side of the rectified image, one beam
        per image column.
    angle_min, angle_max, angle_increment : float, optional
        The beams (radians; REP 103: positive to the left). Needed without ``calib``.
    min_height, max_height : float
        The obstacle band above the floor (metres).
    range_min, range_max : float
        Distances kept (metres, on the floor from the point under the camera).
    min_points : int
        Obstacle points a beam needs; its range is the distance of that many-th nearest. For
        an image of points, at most its pixels (or :data:`MIN_OBSTACLE_POINTS`); a cloud of
        fewer rows is taken (no beam holds an obstacle: a frame's cloud may be small).

    Returns
    -------
    LaserScan

    Raises
    ------
    ValueError
        For points not real or not of shape ``(..., 3)``, an image of points (``(H, W, 3)``)
        of another size than the plane's map or the calibration's images, no angles (no
        ``calib`` and no ``angle_min`` / ``angle_max``), ``angle_max <= angle_min``, beams over
        more than a full turn, a non-positive increment or over 100000 beams, a bad height band
        or range (``range_max`` infinite too), or ``min_points`` under 1 or more than the
        pixels of an image of points (and than :data:`MIN_OBSTACLE_POINTS`).
    TypeError
        If ``plane`` is not a :class:`GroundPlane`, or ``calib`` is given and is not a
        :class:`~stereovision.Calibration` (a path: read it with ``Calibration.from_file``).
    """
    _require_type(plane, "GroundPlane", "plane")
    if calib is not None:  # a path or a dict was AttributeError "'str' object has no attribute"
        _require_type(calib, "Calibration", "calib")
    from stereovision._validate import positive_finite

    pts = _points_array(points, "point_image()")
    if pts.ndim == 0 or pts.shape[-1] != 3:
        raise ValueError(f"points: expected shape (..., 3), got {pts.shape}")
    _same_image(pts, plane, calib)
    lo, hi = _number(min_height, "min_height"), _number(max_height, "max_height")
    if not (math.isfinite(lo) and lo >= 0 and hi > lo):
        raise ValueError(
            f"min_height, max_height: expected 0 <= min_height < max_height, got {lo!r}, {hi!r}"
        )
    r0, r1 = _number(range_min, "range_min"), _number(range_max, "range_max")
    if not (math.isfinite(r0) and r0 >= 0 and r1 > r0):
        raise ValueError(
            f"range_min, range_max: expected 0 <= range_min < range_max, got {r0!r}, {r1!r}"
        )
    if not math.isfinite(r1):  # as_dict() is JSON, which has no infinity; +inf ranges mean "free"
        raise ValueError(f"range_max: expected a finite distance, got {r1!r}")
    # a NumPy integer (a count from an array) was refused as not an integer, and 2**70 was
    # NumPy's OverflowError "Python int too large to convert to C long" further on
    if (
        not isinstance(min_points, (int, np.integer))
        or isinstance(min_points, NOT_NUMBERS)
        or min_points < 1
    ):
        raise ValueError(f"min_points: expected an integer >= 1, got {min_points!r}")
    # more than an image of points holds: no beam could hold an obstacle, and every beam that
    # saw the floor said free (+inf) whatever stood on it (10**30: every beam free or unseen).
    # Only an image's size is a bound of the rig: a cloud's rows vary frame to frame (a dark
    # frame's few points), and a live loop must not fail on one, so a cloud is never refused.
    n_given = pts.size // 3
    if pts.ndim == 3 and int(min_points) > max(n_given, MIN_OBSTACLE_POINTS):
        raise ValueError(
            f"min_points: {reprlib.repr(int(min_points))} is more than the {n_given} points "
            "of the image given: no beam could hold an obstacle, and each one seeing the floor "
            "would say free"
        )
    min_points = min(int(min_points), 2**62)  # more than any cloud's points: no beam returns
    axes = floor_frame(plane)
    if angle_min is None or angle_max is None:
        if calib is None:
            raise ValueError("laser_scan: give calib (the image's field of view) or the angles")
        a0, a1, n_cols = _beam_span(calib, axes)
        a0 = a0 if angle_min is None else _number(angle_min, "angle_min")
        a1 = a1 if angle_max is None else _number(angle_max, "angle_max")
        inc = (a1 - a0) / max(n_cols - 1, 1) if angle_increment is None else angle_increment
    else:
        a0, a1 = _number(angle_min, "angle_min"), _number(angle_max, "angle_max")
        inc = math.radians(0.25) if angle_increment is None else angle_increment
    inc = positive_finite(inc, "angle_increment")
    if not (math.isfinite(a0) and math.isfinite(a1) and a1 > a0):
        raise ValueError(f"angle_min, angle_max: expected angle_max > angle_min, got {a0}, {a1}")
    # a quotient past a float (5e-324 rad beams, or angles of -1e308 to 1e308) was
    # OverflowError "cannot convert float infinity to integer", and one short of it (1e-300
    # rad) said its count in 300 digits
    beams = (a1 - a0) / inc
    if not beams < 1e15:
        raise ValueError(
            f"angle_increment: {inc:g} rad beams over {a1 - a0:g} rad are {beams:.3g} beams; "
            "at most 100000"
        )
    n = math.floor(beams + 1e-9) + 1
    if n > 100_000:
        raise ValueError(f"angle_increment: {n} beams; at most 100000")
    if (n - 1) * inc > 2 * math.pi + 1e-6:
        # the beams past a turn repeat directions the earlier ones hold: each point went to
        # one of them only, and the later ones were NaN whatever stood there. (1e-6 rad: a
        # lidar's float32 -pi and pi, 2.4e-7 rad more than a turn apart, are a full turn)
        raise ValueError(
            f"angle_min, angle_max: beams from {a0:g} to {a0 + (n - 1) * inc:g} rad cover "
            "more than a full turn (2 pi rad)"
        )
    flat = pts.reshape(-1, 3)
    flat = flat[np.all(np.isfinite(flat), axis=1)]
    with np.errstate(over="ignore"):  # a point near float64's largest: infinitely far, out
        xyz = flat @ axes.T
        h = xyz[:, 2] + plane.height
        dist = np.hypot(xyz[:, 0], xyz[:, 1])
    # each point's angle from angle_min, taken once round the circle: arctan2's -pi..pi put
    # every point to the right (negative angles) outside a scan given as 0 to 2 pi, and KITTI
    # 000005's nearest obstacle (4.58 m) was missed. Angles already in the turn keep their bits.
    rel = np.arctan2(xyz[:, 1], xyz[:, 0]) - a0
    rel -= 2 * np.pi * np.floor((rel + inc / 2) / (2 * np.pi))
    beam = np.floor(rel / inc + 0.5).astype(np.int64)
    # a scan of a full turn with both ends (-pi to pi, ROS's 361 beams of 1 degree): its last
    # beam looks where its first does, but the turn above put every point there in beam 0
    # and the last beam was NaN; a point is in each beam of its direction
    again = np.floor((rel + 2 * np.pi) / inc + 0.5).astype(np.int64)
    twice = (again < n) & (again != beam)
    if twice.any():
        beam = np.r_[beam, again[twice]]
        dist, h = np.r_[dist, dist[twice]], np.r_[h, h[twice]]
    keep = (beam >= 0) & (beam < n) & (dist >= r0) & (dist <= r1)
    ranges = np.full(n, np.nan, np.float32)
    floor = keep & (np.abs(h) <= lo)
    ranges[np.unique(beam[floor])] = np.inf  # the floor seen along the beam: free
    obstacle = keep & (h > lo) & (h < hi)
    b, d = beam[obstacle], dist[obstacle]
    order = np.lexsort((d, b))  # by beam, then by distance
    b, d = b[order], d[order]
    counts = np.bincount(b, minlength=n)
    first = np.cumsum(counts) - counts
    hit = counts >= min_points
    ranges[hit] = d[first[hit] + min_points - 1]
    return LaserScan(a0, a0 + (n - 1) * inc, inc, r0, r1, ranges)
