"""3-D views of a depth result: textured surface, coloured point cloud, the paper's camera controls.

Frames and units follow the package convention (architecture.md): metres, left rectified camera
frame, X right, Y down, Z forward. The virtual camera starts at the left camera's pose and is moved
with the paper's six controls (:class:`CameraControls`): ``roll``, ``pitch``, ``yaw`` in degrees and
``forward``, ``up``, ``right`` in metres. With all controls at zero and the calibration's
intrinsics, a render of the textured surface reproduces the left rectified image.

Rotation convention (all about the camera's own position, axes of the left camera frame)::

    R = R_y(yaw) @ R_x(pitch) @ R_z(roll)
    yaw   > 0: the camera turns right   (forward axis Z moves towards +X)
    pitch > 0: the camera looks up      (forward axis Z moves towards -Y)
    roll  > 0: the camera's right side goes down (+X moves towards +Y; clockwise from behind)

Translations are expressed in the (fixed) left camera frame, so the six sliders commute:
the camera sits at ``(right, -up, forward)``.

Everything renders offscreen (``pyvista.Plotter(off_screen=True)``); no display is needed.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from stereovision._validate import NOT_NUMBERS, as_path, escaped

# at run time too, so that typing.get_type_hints resolves the public signatures
from stereovision.depth import DepthResult

if TYPE_CHECKING:
    import pyvista as pv

__all__ = [
    "BACKGROUND",
    "DEFAULT_FOV_DEG",
    "FIT_PERCENTILE",
    "MAX_FIT_FOV_DEG",
    "MAX_RELATIVE_DEPTH_JUMP",
    "CameraControls",
    "CameraState",
    "apply_camera",
    "camera_pose",
    "cloud_view_intrinsics",
    "controls_from_pose",
    "display_subset",
    "orbit_controls",
    "point_cloud",
    "points_in_view",
    "pose_from_camera",
    "render_outputs",
    "render_view",
    "surface_mesh",
    "write_render",
]

#: A triangle is dropped when its largest vertex depth exceeds its smallest by more than this
#: fraction: neighbouring pixels on one surface differ by a few per cent at most (a 0.5 px
#: disparity error at 20 px is 2.5 %), while an occlusion edge jumps by tens of per cent.
MAX_RELATIVE_DEPTH_JUMP = 0.08

#: Vertical field of view used when there are no intrinsics (a bare PLY file), degrees.
DEFAULT_FOV_DEG = 60.0

#: Widest vertical field of view (degrees) ``view`` widens :data:`DEFAULT_FOV_DEG` to so that a
#: bare cloud fits its picture (:func:`cloud_view_intrinsics`): past it the picture is mostly
#: perspective distortion (a cloud around the camera cannot fit anyway).
MAX_FIT_FOV_DEG = 120.0

#: Percentile of the points' angles off the axis (across and down) that ``view`` widens a bare
#: cloud's view to fit (:func:`cloud_view_intrinsics`): the widest point alone let one stray
#: (a mismatched pixel 100 m to the side) widen the view to :data:`MAX_FIT_FOV_DEG` and shrink
#: the scene; 99.9 leaves none of ``depth``'s KITTI cloud (318 k points) outside.
FIT_PERCENTILE = 99.9

#: Size (width, height) of a render without intrinsics, pixels.
DEFAULT_VIEW_SIZE = (800, 600)

#: Size (width, height) of ``stereovision view``'s window, pixels.
VIEW_WINDOW_SIZE = (1024, 768)

#: Background of every render (RGB, 0-255): dark grey, so black texture pixels stay visible.
BACKGROUND = (32, 32, 36)

#: Point size (screen pixels) of rendered point clouds.
POINT_SIZE = 2.0

#: Default render.png view: orbit around the scene's median depth point by these angles (deg).
RENDER_YAW_DEG = -12.0
RENDER_PITCH_DEG = -8.0

#: Largest render side (pixels) of render.png; bigger images are scaled down.
RENDER_MAX_SIDE = 1024

#: Clipping range from the scene's point distances: robust percentiles with margins, so
#: outliers (near-zero disparities give depths of kilometres) cannot clip the whole scene away.
CLIP_LOW_PERCENTILE = 0.5
CLIP_HIGH_PERCENTILE = 99.5
NEAR_FACTOR = 0.5
FAR_FACTOR = 2.0
MIN_NEAR = 0.01  # metres
#: ... or this fraction of the far distance when that is less (VTK's own near-plane tolerance for
#: a 24-bit depth buffer): a cloud a few millimetres away (a stereo microscope's) was clipped
#: whole by the 1 cm floor.
MIN_NEAR_OF_FAR = 0.001
CLIP_SAMPLE = 20_000  # points used to estimate the range
#: :func:`point_cloud` leaves out a point farther than this many times the cloud's spread (the
#: median distance of its points from their median point) from that point. VTK draws in float32,
#: shifted to the middle of the bounds and scaled by their size: one point 1e8 m away from a
#: cloud of 2-4 m (spread 1 m) left its points metres apart and the picture blank; one 1e6 m
#: away moved 23 % of its pixels, 1e5 m 4 % (kept: a near-zero disparity is kilometres away, and
#: the robust clipping range hides it). Such points lie far past the far clipping plane.
DISPLAY_MAX_SPREADS = 1e6

#: The camera looks at a point this far ahead when there is no scene depth to use (metres).
_DEFAULT_FOCAL_DISTANCE = 1.0


# ----------------------------------------------------------------------------- camera controls


@dataclass(frozen=True)
class CameraControls:
    """The paper's six camera controls, relative to the left rectified camera's pose.

    Attributes
    ----------
    roll, pitch, yaw : float
        Rotations in degrees (see the module docstring for the axes and signs).
    forward, up, right : float
        Translations in metres along the left camera's forward (+Z), up (-Y) and right (+X) axes.
    """

    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    forward: float = 0.0
    up: float = 0.0
    right: float = 0.0

    def __post_init__(self) -> None:
        from stereovision._validate import finite_number, number_shown

        for f in fields(self):
            value = getattr(self, f.name)
            # NumPy numbers (np.float32 is no float) are numbers; a bool is not an angle
            try:
                number = finite_number(value, f.name)
            except ValueError:
                raise ValueError(
                    f"camera control {f.name} must be a finite number, got {number_shown(value)}"
                ) from None
            object.__setattr__(self, f.name, number)

    def pose(self) -> npt.NDArray[np.float64]:
        """4x4 camera-to-left-camera pose of these controls (see :func:`camera_pose`).

        Returns
        -------
        ndarray
            float64 ``(4, 4)``.
        """
        return camera_pose(
            roll=self.roll,
            pitch=self.pitch,
            yaw=self.yaw,
            forward=self.forward,
            up=self.up,
            right=self.right,
        )


def _rot_x(deg: float) -> npt.NDArray[np.float64]:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rot_y(deg: float) -> npt.NDArray[np.float64]:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rot_z(deg: float) -> npt.NDArray[np.float64]:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def camera_pose(
    roll: float = 0.0,
    pitch: float = 0.0,
    yaw: float = 0.0,
    forward: float = 0.0,
    up: float = 0.0,
    right: float = 0.0,
) -> npt.NDArray[np.float64]:
    """Pose of the virtual camera driven by the paper's controls.

    Parameters
    ----------
    roll, pitch, yaw : float
        Degrees. ``R = R_y(yaw) @ R_x(pitch) @ R_z(roll)`` about the camera's position, axes of the
        left camera frame (yaw > 0 turns right, pitch > 0 looks up, roll > 0 lowers the right side).
    forward, up, right : float
        Metres along +Z, -Y and +X of the left camera frame.

    Returns
    -------
    ndarray, float64 (4, 4)
        Camera-to-left-camera transform ``[[R, t], [0, 1]]``: the columns of ``R`` are the virtual
        camera's X (right), Y (down) and Z (forward) axes in the left camera frame, and
        ``t = (right, -up, forward)`` is its position. All zeros give the identity.

    Examples
    --------
    >>> import numpy as np
    >>> T = camera_pose(yaw=90.0)
    >>> np.allclose(T[:3, 2], [1, 0, 0])  # looking along the old +X (turned right)
    True
    """
    rot = _rot_y(yaw) @ _rot_x(pitch) @ _rot_z(roll)
    pose = np.eye(4)
    pose[:3, :3] = rot
    pose[:3, 3] = [right, -up, forward]
    return pose


#: Below this, ``cos(pitch)`` is taken as 0 by :func:`controls_from_pose` (gimbal lock).
_GIMBAL_LOCK_COS = 1e-12


def controls_from_pose(pose: npt.ArrayLike) -> CameraControls:
    """The controls whose :func:`camera_pose` is ``pose``: its inverse.

    ``R = R_y(yaw) @ R_x(pitch) @ R_z(roll)`` gives ``pitch = atan2(-R[1, 2], |R[(0, 2), 2]|)``
    in [-90, 90], ``yaw = atan2(R[0, 2], R[2, 2])`` and ``roll = atan2(R[1, 0], R[1, 1])`` in
    (-180, 180].
    Controls with ``|pitch| < 90`` and yaw and roll within +-90 (the GUI sliders' ranges) come
    back as they were, read back from a VTK camera too (measured: 1e-10 degrees up to 0.001
    degree off the vertical, 1e-7 at 1e-9 degree off; ``tests/test_render.py``), and the pose
    of the controls read back is ``pose`` (1e-15). Looking straight up or down (gimbal lock)
    only ``yaw - roll`` (up) or ``yaw + roll`` (down) is determined: roll is said 0. A camera
    turned past the sliders' range (a mouse drag around the scene: yaw 150) gives angles
    outside +-90, which the GUI's sliders cannot show (it clamps them:
    :func:`stereovision.gui.app.sliders_from_pose`).

    Parameters
    ----------
    pose : array_like, (4, 4)
        Camera-to-left-camera transform (:func:`camera_pose`, :func:`pose_from_camera`); its
        rotation part must be a rotation.

    Returns
    -------
    CameraControls

    Raises
    ------
    ValueError
        A pose that is not 4x4 or not finite.

    Examples
    --------
    >>> c = controls_from_pose(camera_pose(roll=10.0, pitch=-20.0, yaw=30.0, up=1.5))
    >>> round(c.roll, 9), round(c.pitch, 9), round(c.yaw, 9), round(c.up, 9)
    (10.0, -20.0, 30.0, 1.5)
    """
    m = np.asarray(pose, dtype=np.float64)
    if m.shape != (4, 4):
        raise ValueError(f"controls_from_pose: expected a 4x4 pose, got shape {m.shape}")
    if not np.isfinite(m).all():
        bad = int((~np.isfinite(m)).sum())
        raise ValueError(f"controls_from_pose: the pose holds {bad} NaN or infinite values")
    rot, t = m[:3, :3], m[:3, 3]
    cos_pitch = math.hypot(rot[0, 2], rot[2, 2])
    # atan2, not asin(-R[1, 2]): asin near 1 lost half the digits (1e-8 off the vertical)
    pitch = math.degrees(math.atan2(-rot[1, 2], cos_pitch))
    if cos_pitch < _GIMBAL_LOCK_COS:  # looking straight up or down
        yaw, roll = math.degrees(math.atan2(-rot[2, 0], rot[0, 0])), 0.0
    else:
        yaw = math.degrees(math.atan2(rot[0, 2], rot[2, 2]))
        roll = math.degrees(math.atan2(rot[1, 0], rot[1, 1]))
    return CameraControls(
        roll=roll,
        pitch=pitch,
        yaw=yaw,
        forward=float(t[2]),
        up=float(-t[1]),
        right=float(t[0]),
    )


def orbit_controls(yaw: float, pitch: float, center_depth: float) -> CameraControls:
    """Controls that look at the point ``(0, 0, center_depth)`` from a rotated position.

    The camera turns by ``yaw`` / ``pitch`` and moves so that the point straight ahead of the left
    camera at ``center_depth`` metres stays in the centre of the view, at the same distance.

    Parameters
    ----------
    yaw, pitch : float
        Degrees, as in :func:`camera_pose`.
    center_depth : float
        Distance of the orbit centre in metres (> 0), e.g. the median depth of the scene.

    Returns
    -------
    CameraControls

    Raises
    ------
    ValueError
        An angle that is not a finite number, or a ``center_depth`` that is no positive
        distance.
    """
    from stereovision._validate import finite_number

    try:  # a text or None raised math.isfinite's TypeError, not this ValueError
        depth = finite_number(center_depth, "center_depth")
    except ValueError:
        depth = math.nan
    if not depth > 0:
        raise ValueError(f"center_depth must be a positive distance, got {center_depth!r}")
    center_depth = depth
    # the angles checked first (CameraControls names them): math.radians of a text or None
    # raised a TypeError naming neither
    angles = CameraControls(yaw=yaw, pitch=pitch)
    yaw, pitch = angles.yaw, angles.pitch
    rot = camera_pose(yaw=yaw, pitch=pitch)[:3, :3]
    center = np.array([0.0, 0.0, center_depth])
    position = center - center_depth * rot[:, 2]
    return CameraControls(
        pitch=pitch,
        yaw=yaw,
        forward=float(position[2]),
        up=float(-position[1]),
        right=float(position[0]),
    )


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of the rendered view (pixels), origin at the top-left pixel's centre.

    ``f`` is the horizontal focal length (``fx``); ``fy`` the vertical one, None for square
    pixels (``fy = f``).

    Raises
    ------
    ValueError
        A focal length that is not a positive finite number, a principal point that is not
        finite, or a width or height that is no whole number of pixels >= 1 (a width of -5
        crashed the process in VTK's allocation, 0 was a ZeroDivisionError, a negative focal
        length a mirrored picture without a word).
    """

    f: float
    cx: float
    cy: float
    width: int
    height: int
    fy: float | None = None

    def __post_init__(self) -> None:
        from stereovision._validate import finite_number

        focal = ("f",) if self.fy is None else ("f", "fy")
        for name in (*focal, "cx", "cy"):
            value = finite_number(getattr(self, name), f"Intrinsics: {name}")
            if name in focal and not value > 0:
                raise ValueError(
                    f"Intrinsics: {name}: expected a positive focal length in pixels, got {value:g}"
                )
            object.__setattr__(self, name, value)
        for name in ("width", "height"):
            value = getattr(self, name)
            if not isinstance(value, (int, np.integer)) or isinstance(value, NOT_NUMBERS):
                raise ValueError(
                    f"Intrinsics: {name}: expected a whole number of pixels >= 1, got {value!r}"
                )
            if value < 1:
                raise ValueError(
                    f"Intrinsics: {name}: expected a whole number of pixels >= 1, got {value}"
                )
            object.__setattr__(self, name, int(value))

    @property
    def focal_y(self) -> float:
        """The vertical focal length (pixels): ``fy``, or ``f`` for square pixels."""
        return self.f if self.fy is None else self.fy

    @classmethod
    def from_result(cls, result: DepthResult) -> Intrinsics | None:
        """Intrinsics of the rectified left camera of ``result``, or None without calibration."""
        calib = result.calibration
        if calib is None:
            return None
        k = np.asarray(calib.K1, dtype=np.float64)
        h, w = result.disparity.shape[:2]
        # the points' Y is (v - cy) Z / fy: fx here rendered non-square pixels' rows off
        return cls(float(k[0, 0]), float(k[0, 2]), float(k[1, 2]), int(w), int(h), float(k[1, 1]))

    def scaled(self, factor: float) -> Intrinsics:
        """The same camera for an image scaled by ``factor`` (pixel centres kept consistent)."""
        return Intrinsics(
            self.f * factor,
            (self.cx + 0.5) * factor - 0.5,
            (self.cy + 0.5) * factor - 0.5,
            max(1, round(self.width * factor)),
            max(1, round(self.height * factor)),
            None if self.fy is None else self.fy * factor,
        )


def apply_camera(
    plotter: pv.Plotter,
    controls: CameraControls,
    *,
    intrinsics: Intrinsics | None = None,
    focal_distance: float = _DEFAULT_FOCAL_DISTANCE,
    points: npt.ArrayLike | None = None,
) -> None:
    """Place ``plotter``'s camera at the pose of ``controls``, in perspective.

    Parameters
    ----------
    plotter : pyvista.Plotter
    controls : CameraControls
    intrinsics : Intrinsics, optional
        With intrinsics the view angle is ``2 atan(H / 2 fy)`` (``fx != fy``: the columns
        scaled by ``fx / fy``) and the window centre is shifted to the principal point, so a
        zero-control render lines up with the left image pixel for pixel (when the window is
        ``width x height``).
        Without, a :data:`DEFAULT_FOV_DEG` view.
    focal_distance : float
        Distance of the focal point ahead of the camera (metres): the centre of mouse rotations.
    points : array_like (N, 3), optional
        The scene's points: the clipping range is set from robust percentiles of their distances
        (:func:`robust_clipping_range`), so a few absurdly far points (a disparity of 0.01 px is
        80 km away) cannot push the near plane beyond the scene. Without, VTK's automatic range.
    """
    pose = controls.pose()
    rot, pos = pose[:3, :3], pose[:3, 3]
    cam = plotter.camera
    cam.position = tuple(pos)
    cam.focal_point = tuple(pos + focal_distance * rot[:, 2])
    cam.up = tuple(-rot[:, 1])
    # a perspective view: one left orthographic (CameraState.apply) ignored the view angle
    cam.SetParallelProjection(False)
    if intrinsics is not None:
        fy = intrinsics.focal_y
        cam.view_angle = math.degrees(2 * math.atan(intrinsics.height / (2 * fy)))
        # VTK's pixels are square (fx = fy from the vertical view angle): for fx != fy the
        # columns are scaled by fx / fy after the projection. An explicit aspect ratio (the
        # image's width / height x fy / fx) stretched them in a window of another shape
        # (the GUI's view, at most 480 px high, is wider than the image in a wide column).
        pixel_aspect = None if fy == intrinsics.f else intrinsics.f / fy
        _set_pixel_aspect(cam, pixel_aspect)
        # VTK shifts the image by the window centre: a principal point right of / below the
        # image centre needs the opposite shift (measured: tests/test_render.py projection test).
        # The shift is scaled with the columns: given over fx / fy.
        wx = 1 - 2 * (intrinsics.cx + 0.5) / intrinsics.width
        wy = 2 * (intrinsics.cy + 0.5) / intrinsics.height - 1
        cam.SetWindowCenter(wx if pixel_aspect is None else wx / pixel_aspect, wy)
    else:
        cam.view_angle = DEFAULT_FOV_DEG
        cam.SetWindowCenter(0.0, 0.0)
        _set_pixel_aspect(cam, None)
    if points is not None:
        cam.clipping_range = robust_clipping_range(points, pos)
    else:
        plotter.reset_camera_clipping_range()
    plotter.camera_set = True  # keep this camera: the first render must not reset it to the bounds


def _set_pixel_aspect(cam: Any, pixel_aspect: float | None) -> None:
    """Scale ``cam``'s columns by ``pixel_aspect`` (``fx / fy``) after its projection (VTK's
    user transform), whatever the window's shape; None: square pixels (no transform)."""
    if pixel_aspect is None:
        cam.SetUserTransform(None)
        return
    import vtk

    scale = vtk.vtkTransform()
    scale.Scale(pixel_aspect, 1.0, 1.0)
    cam.SetUserTransform(scale)


def _pixel_aspect(cam: Any) -> float | None:
    """The ``fx / fy`` :func:`_set_pixel_aspect` gave ``cam``, or None (square pixels)."""
    user = cam.GetUserTransform()
    return None if user is None else float(user.GetMatrix().GetElement(0, 0))


def robust_clipping_range(points: npt.ArrayLike, position: npt.ArrayLike) -> tuple[float, float]:
    """Near and far clipping distances covering the bulk of ``points`` seen from ``position``.

    ``near = NEAR_FACTOR x`` the :data:`CLIP_LOW_PERCENTILE` distance (at least
    :data:`MIN_NEAR`, or :data:`MIN_NEAR_OF_FAR` of the far distance when that is less: a scene
    within 10 m), ``far = FAR_FACTOR x`` the :data:`CLIP_HIGH_PERCENTILE` distance; at most
    :data:`CLIP_SAMPLE` evenly spaced points are used.

    Returns
    -------
    (float, float)
        ``(near, far)`` in metres, ``0 < near < far``.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) > CLIP_SAMPLE:
        pts = pts[np.linspace(0, len(pts) - 1, CLIP_SAMPLE).astype(np.int64)]
    dist = np.linalg.norm(pts - np.asarray(position, dtype=np.float64), axis=1)
    dist = dist[np.isfinite(dist)]
    if dist.size == 0:
        return MIN_NEAR, 1000.0 * MIN_NEAR
    reach = FAR_FACTOR * float(np.percentile(dist, CLIP_HIGH_PERCENTILE))
    floor = min(MIN_NEAR, MIN_NEAR_OF_FAR * reach) if reach > 0 else MIN_NEAR
    near = max(floor, NEAR_FACTOR * float(np.percentile(dist, CLIP_LOW_PERCENTILE)))
    far = max(near * 10, reach)
    return near, far


def keep_robust_clipping(plotter: pv.Plotter, points: npt.ArrayLike) -> int:
    """Re-apply :func:`robust_clipping_range` at the start of every render of ``plotter``.

    Mouse interaction lets VTK reset the clipping range from the bounds of everything shown, which
    a few far outliers can ruin; this observer puts the robust range back before each frame.

    Returns
    -------
    int
        Observer tag (``plotter.renderer.RemoveObserver(tag)`` removes it).
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) > CLIP_SAMPLE:
        pts = pts[np.linspace(0, len(pts) - 1, CLIP_SAMPLE).astype(np.int64)]
    renderer = plotter.renderer

    def on_start(_obj: Any, _event: str) -> None:
        cam = renderer.GetActiveCamera()
        cam.SetClippingRange(*robust_clipping_range(pts, cam.GetPosition()))

    return int(renderer.AddObserver("StartEvent", on_start))


def pose_from_camera(camera: Any) -> npt.NDArray[np.float64]:
    """4x4 pose (same layout as :func:`camera_pose`) read back from a pyvista/VTK camera.

    Parameters
    ----------
    camera : pyvista.Camera
        Its position, focal point and view-up are used (view-up orthogonalised).

    Returns
    -------
    ndarray, float64 (4, 4)
    """
    pos = np.asarray(camera.position, dtype=np.float64)
    z = np.asarray(camera.focal_point, dtype=np.float64) - pos
    z /= np.linalg.norm(z)
    up = np.asarray(camera.up, dtype=np.float64)
    up = up - np.dot(up, z) * z
    y = -up / np.linalg.norm(up)
    x = np.cross(y, z)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = x, y, z, pos
    return pose


@dataclass(frozen=True)
class CameraState:
    """A VTK camera's view as it stands: where it is, what it looks at, which way is up, how
    wide it sees and where its image centre is. It holds what the mouse changes in an
    interactive view (which :class:`CameraControls` does not follow), so that the view can be
    rendered again elsewhere (:func:`render_view`).

    Attributes
    ----------
    position, focal_point, up : tuple of float
        Metres, left camera frame (``up``: the view-up direction).
    view_angle : float
        Vertical field of view, degrees.
    window_center : tuple of float
        VTK's window centre (the principal point's shift, :func:`apply_camera`).
    parallel_projection : bool
        An orthographic view (VTK's parallel projection) instead of a perspective one.
    parallel_scale : float
        Half the height of an orthographic view, metres (its zoom; VTK's parallel scale).
    pixel_aspect : float or None
        ``fx / fy`` of non-square pixels, the columns' scale :func:`apply_camera` sets (in a
        window of any shape); None: square pixels.

    Raises
    ------
    ValueError
        A number that is not finite, a vector of another length, a view angle outside
        0-180 degrees, a parallel scale or pixel aspect <= 0, a focal point at the position,
        or an ``up`` along the view direction (or zero).
    """

    position: tuple[float, float, float]
    focal_point: tuple[float, float, float]
    up: tuple[float, float, float]
    view_angle: float
    window_center: tuple[float, float] = (0.0, 0.0)
    parallel_projection: bool = False
    parallel_scale: float = 1.0
    pixel_aspect: float | None = None

    def __post_init__(self) -> None:
        # a NaN, a zero view angle or a camera on its focal point rendered an empty or
        # arbitrary picture without a word
        from stereovision._validate import finite_number

        def numbers(name: str, count: int) -> tuple[float, ...]:
            value = getattr(self, name)
            try:
                if len(value) != count:
                    raise TypeError
            except TypeError:
                raise ValueError(
                    f"CameraState: {name}: expected {count} numbers, got {value!r}"
                ) from None
            got = tuple(finite_number(v, f"CameraState: {name}") for v in value)
            object.__setattr__(self, name, got)
            return got

        position, focal_point, up = (numbers(n, 3) for n in ("position", "focal_point", "up"))
        numbers("window_center", 2)
        angle = finite_number(self.view_angle, "CameraState: view_angle")
        if not 0 < angle < 180:
            raise ValueError(f"CameraState: view_angle: expected 0-180 degrees, got {angle:g}")
        scale = finite_number(self.parallel_scale, "CameraState: parallel_scale")
        if scale <= 0:
            raise ValueError(f"CameraState: parallel_scale: expected > 0, got {scale:g}")
        object.__setattr__(self, "view_angle", angle)
        object.__setattr__(self, "parallel_scale", scale)
        object.__setattr__(self, "parallel_projection", bool(self.parallel_projection))
        if self.pixel_aspect is not None:
            aspect = finite_number(self.pixel_aspect, "CameraState: pixel_aspect")
            if aspect <= 0:
                raise ValueError(f"CameraState: pixel_aspect: expected > 0, got {aspect:g}")
            object.__setattr__(self, "pixel_aspect", aspect)
        ahead = np.subtract(focal_point, position)
        distance = float(np.linalg.norm(ahead))
        if not distance > 0:
            raise ValueError(f"CameraState: the focal point is the position, {position}")
        # up's part across the view direction: none (or none to speak of) leaves no way up
        across = float(np.linalg.norm(np.cross(ahead / distance, up)))
        if not across > 1e-6 * float(np.linalg.norm(up)):
            raise ValueError(
                f"CameraState: up {up} is along the view direction (or zero): no way is up"
            )

    @classmethod
    def of(cls, camera: Any) -> CameraState:
        """The state of a pyvista / VTK ``camera`` now.

        Parameters
        ----------
        camera : pyvista.Camera or vtkCamera

        Returns
        -------
        CameraState
        """

        def floats(values: Any) -> tuple[float, ...]:
            return tuple(float(v) for v in values)

        return cls(
            floats(camera.GetPosition()),  # type: ignore[arg-type]
            floats(camera.GetFocalPoint()),  # type: ignore[arg-type]
            floats(camera.GetViewUp()),  # type: ignore[arg-type]
            float(camera.GetViewAngle()),
            floats(camera.GetWindowCenter()),  # type: ignore[arg-type]
            bool(camera.GetParallelProjection()),
            float(camera.GetParallelScale()),
            _pixel_aspect(camera),
        )

    def same_view(self, other: CameraState, tolerance: float = 1e-9) -> bool:
        """Whether ``other`` is this view (each number within ``tolerance`` of this one's,
        relative to its size).

        Parameters
        ----------
        other : CameraState
            The view to compare.
        tolerance : float
            Relative (and, near zero, absolute) difference allowed per number, >= 0.

        Returns
        -------
        bool

        Raises
        ------
        ValueError
            A negative or non-finite ``tolerance``.
        """
        from stereovision._validate import finite_number

        tol = finite_number(tolerance, "tolerance")
        if tol < 0:
            raise ValueError(f"tolerance: expected >= 0, got {tol:g}")
        return bool(np.allclose(self._numbers(), other._numbers(), rtol=tol, atol=tol))

    def _numbers(self) -> npt.NDArray[np.float64]:
        return np.array(
            [
                *self.position,
                *self.focal_point,
                *self.up,
                self.view_angle,
                *self.window_center,
                float(self.parallel_projection),
                self.parallel_scale,
                0.0 if self.pixel_aspect is None else self.pixel_aspect,
            ]
        )

    def apply(self, plotter: pv.Plotter, points: npt.ArrayLike | None = None) -> None:
        """Give ``plotter``'s camera this view.

        Parameters
        ----------
        plotter : pyvista.Plotter
        points : array_like (N, 3), optional
            The scene's points, for a robust clipping range (as :func:`apply_camera`).
        """
        cam = plotter.camera
        cam.position = self.position
        cam.focal_point = self.focal_point
        cam.up = self.up
        cam.view_angle = self.view_angle
        cam.SetWindowCenter(*self.window_center)
        cam.SetParallelProjection(bool(self.parallel_projection))
        cam.SetParallelScale(self.parallel_scale)
        _set_pixel_aspect(cam, self.pixel_aspect)
        if points is not None:
            cam.clipping_range = robust_clipping_range(points, self.position)
        else:
            plotter.reset_camera_clipping_range()
        plotter.camera_set = True


# ----------------------------------------------------------------------------- geometry


def _pv() -> Any:
    """pyvista, imported with Ctrl-C held: a KeyboardInterrupt raised while one of VTK's
    extension modules initialises crashed the process (SIGSEGV, exit 139, 6 of 30 Ctrl-Cs
    during the import), as ``gui`` interrupted on its way up. The signal is raised once VTK is
    whole (:class:`~stereovision._interrupt.HeldInterrupts`), so Ctrl-C still stops it."""
    from stereovision._interrupt import HeldInterrupts

    with HeldInterrupts():
        import pyvista as pv

        if not _has_display():
            # Without X, VTK tries the X window first and logs "bad X server connection" before
            # it falls back to offscreen rendering: harmless, but it reads like an error in CLI
            # output.
            import vtk

            vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_ERROR)
    return pv


def _cloud_of(
    result: DepthResult,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8], npt.NDArray[np.int32]]:
    """``(points, colors, pixels)`` of ``result``, rebuilt from its depth map for a
    ``depth_map(cloud=False)`` result (empty ``points``, as ``DepthResult.to_ply`` rebuilds
    them): its surface was refused as "the matcher found no depth" and render.png skipped."""
    points, colors, pixels = result.points, result.colors, result.pixels
    calib, depth = result.calibration, result.depth
    if len(points) == 0 and calib is not None and depth is not None:
        from stereovision.depth import _cloud
        from stereovision.export import _check_left_size

        _check_left_size(result)  # its pixels colour the points: NumPy's IndexError, unnamed
        left = result.left_rectified
        if left is None or left.ndim != 3:  # black, as DepthResult._cloud_points colours it
            left = np.zeros((*depth.shape, 3), np.uint8)
        points, colors, pixels = _cloud(depth, calib, left)
    return points, colors, pixels


def _check_result(result: DepthResult) -> None:
    if result.depth is None or result.calibration is None:
        raise ValueError("no 3-D points: the depth result has no calibration")
    if not np.isfinite(result.depth).any():
        raise ValueError("empty point cloud: the matcher found no depth in this pair")


def surface_mesh(
    result: DepthResult,
    *,
    step: int = 1,
    max_jump: float = MAX_RELATIVE_DEPTH_JUMP,
) -> pv.PolyData:
    """Textured triangle mesh of the depth map, one vertex per (sub-sampled) pixel with a depth.

    Neighbouring pixels ``(x, y), (x+s, y), (x, y+s), (x+s, y+s)`` form two triangles; a triangle
    is kept only if its three pixels have a depth and ``max(Z) / min(Z) <= (1 + max_jump) ** s``
    (``max_jump`` per pixel of its side: no triangle spans a depth discontinuity or a hole, and
    a slanted surface is kept at any step).

    Parameters
    ----------
    result : DepthResult
        A result computed with a calibration (metric points); of ``depth_map(cloud=False)``
        too (its points are rebuilt from the depth map, as ``to_ply`` does).
    step : int
        Pixel stride of the vertex grid (1 = every pixel; 2 = a quarter of the vertices).
    max_jump : float
        Relative depth jump per pixel above which a triangle is dropped (default
        :data:`MAX_RELATIVE_DEPTH_JUMP`).

    Returns
    -------
    pyvista.PolyData
        Vertices in metres (left rectified frame), triangles, texture coordinates, point data
        ``"RGB"`` (uint8 colours) and the texture (rectified left image, RGB) in
        ``mesh.field_data["texture_rgb"]`` (use :func:`texture_of`).

    Raises
    ------
    ValueError
        Without calibration, with no points (none on the grid of ``step``), or with a bad
        ``step`` / ``max_jump``.
    """
    pv = _pv()
    _check_result(result)
    from stereovision._validate import _real_scalar, float_sized

    # a bool was taken as a stride of 1, and a text or None for max_jump raised a TypeError
    # naming neither ('>' not supported)
    if not isinstance(step, (int, np.integer)) or isinstance(step, NOT_NUMBERS) or step < 1:
        raise ValueError(f"step must be a positive integer, got {step!r}")
    # as an int: np.uint64 made the indices float64, np.int8 overflowed at column 160
    step = int(step)
    float_sized(max_jump, "max_jump")  # 10**400: float()'s OverflowError named nothing
    try:
        jump = math.nan if isinstance(max_jump, bool) else _real_scalar(max_jump)
    except TypeError:
        jump = math.nan
    if not jump > 0:  # inf is no limit: every triangle between depths is kept
        raise ValueError(f"max_jump must be positive, got {max_jump!r}")
    max_jump = jump
    h, w = result.disparity.shape[:2]
    points, colors, pixels = _cloud_of(result)
    xs, ys = pixels[:, 0], pixels[:, 1]
    on_grid = (xs % step == 0) & (ys % step == 0)
    sel = np.nonzero(on_grid)[0]
    if len(sel) == 0:
        # a sparse result's pixels all off the grid: pyvista's "Invalid array shape. Empty
        # arrays are not allowed. Array 'RGB' cannot have shape (0, 3)" named no cause
        raise ValueError(
            f"empty point cloud: none of the {len(pixels)} pixels with a depth lies on the "
            f"mesh's grid (every {step}th row and column); a smaller step keeps them"
        )
    gh, gw = (h + step - 1) // step, (w + step - 1) // step
    index = np.full((gh, gw), -1, dtype=np.int64)
    index[ys[sel] // step, xs[sel] // step] = np.arange(len(sel))
    pts = points[sel].astype(np.float32)
    z = pts[:, 2].astype(np.float64)
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    c, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    tris = np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)])
    tris = tris[(tris >= 0).all(axis=1)]
    if len(tris):
        zt = z[tris]
        # max_jump per pixel: a triangle spans `step` of them, and a slanted surface (the
        # floor towards the horizon) changes by that much more across it; 1 + max_jump alone
        # cut the floor 12-25 rows under the horizon from render.png's step-2 mesh
        try:
            limit = (1 + max_jump) ** step
        except OverflowError:  # (1e200) ** 2: no limit, as inf
            limit = math.inf
        tris = tris[zt.max(axis=1) <= zt.min(axis=1) * limit]
    faces = np.hstack([np.full((len(tris), 1), 3, np.int64), tris]).ravel()
    mesh = pv.PolyData(pts, faces=faces) if len(tris) else pv.PolyData(pts)
    u = (xs[sel] + 0.5) / w
    v = 1.0 - (ys[sel] + 0.5) / h
    mesh.active_texture_coordinates = np.stack([u, v], axis=1).astype(np.float32)
    mesh.point_data["RGB"] = colors[sel]
    img = result.left_rectified
    if img is not None:
        # a grey (H, W) image has no channels to reverse: [..., ::-1] mirrored its columns
        # into a texture of the wrong size; an (H, W, 1) one is grey too; BGRA's alpha is no
        # colour
        grey = img.ndim == 2 or img.shape[2] == 1
        rgb = np.ascontiguousarray(
            np.repeat(img.reshape(img.shape[:2])[..., None], 3, axis=2) if grey else img[..., 2::-1]
        )
        mesh.field_data["texture_rgb"] = rgb.reshape(-1, 3)
        mesh.field_data["texture_shape"] = np.array(rgb.shape[:2], dtype=np.int64)
    return mesh


def texture_of(mesh: pv.PolyData) -> pv.Texture | None:
    """The texture stored by :func:`surface_mesh` (None when the result had no left image)."""
    if "texture_rgb" not in mesh.field_data:
        return None
    pv = _pv()
    h, w = (int(v) for v in mesh.field_data["texture_shape"])
    rgb = np.asarray(mesh.field_data["texture_rgb"], dtype=np.uint8).reshape(h, w, 3)
    return pv.Texture(rgb)


def _far_points(pts: npt.NDArray[np.float32], keep: npt.NDArray[np.bool_]) -> Any:
    """The finite points (``keep``) over :data:`DISPLAY_MAX_SPREADS` spreads from the cloud's
    median point, after a warning counting them, or None when there are none."""
    from stereovision._validate import source_warning

    idx = np.flatnonzero(keep)
    sample = idx[np.linspace(0, len(idx) - 1, min(len(idx), CLIP_SAMPLE)).astype(np.int64)]
    mid = np.median(pts[sample].astype(np.float64), axis=0)
    spread = float(np.median(np.linalg.norm(pts[sample] - mid, axis=1)))
    if not spread > 0:  # most points in one place: no scale to measure against
        return None
    # the largest coordinate first (fmin / fmax skip NaN; over the flat array, one fast pass):
    # when every point is within reach of the middle, none is far (the distances of 2 M points
    # took 0.7-1 s)
    flat = pts.reshape(-1)
    reach = max(float(np.fmax.reduce(flat)), -float(np.fmin.reduce(flat)))
    if (reach + float(np.abs(mid).max())) * math.sqrt(3) <= DISPLAY_MAX_SPREADS * spread:
        return None
    dist = np.zeros(len(pts))
    dist[idx] = np.linalg.norm(pts[idx].astype(np.float64) - mid, axis=1)
    far = dist > DISPLAY_MAX_SPREADS * spread
    if not far.any():
        return None
    source_warning(
        f"points: {int(far.sum())} point(s) over {DISPLAY_MAX_SPREADS:g} times the cloud's "
        f"spread ({spread:.3g} m) from its middle (e.g. {float(dist[far][0]):.3g} m away) left "
        "out (not shown): drawn in float32 with it, they blur or blank the picture"
    )
    out: npt.NDArray[np.bool_] = far
    return out


def point_cloud(points: npt.ArrayLike, colors: npt.ArrayLike | None = None) -> pv.PolyData:
    """Coloured point cloud as pyvista vertices.

    Parameters
    ----------
    points : array_like, (N, 3)
        Metres; non-finite rows are dropped.
    colors : array_like, uint8 (N, 3), optional
        RGB per point (stored as point data ``"RGB"``).

    Returns
    -------
    pyvista.PolyData

    Raises
    ------
    ValueError
        Wrong shapes, or no finite point ("empty point cloud").

    Warns
    -----
    UserWarning
        Naming how many points have a finite coordinate beyond float32's range (``1e39``):
        they become inf in the cast and are dropped; and how many lie over
        :data:`DISPLAY_MAX_SPREADS` times the cloud's spread from its median point: they are
        left out, as drawn they blanked the picture (a point 1e8 m away from a cloud of metres).
    """
    pv = _pv()
    from stereovision._validate import points_as_float32, source_warning

    pts, lost = points_as_float32(np.asarray(points))
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points: expected shape (N, 3), got {pts.shape}")
    if lost is not None:
        source_warning(f"points: {lost} dropped (not shown)")
    keep = np.isfinite(pts).all(axis=1)
    if not keep.any():
        raise ValueError("empty point cloud: no finite 3-D point to show")
    far = _far_points(pts, keep)
    if far is not None:
        keep &= ~far
    cloud = pv.PolyData(pts[keep])
    if colors is not None:
        cols = np.asarray(colors)
        if cols.shape != pts.shape or cols.dtype != np.uint8:
            raise ValueError(
                f"colors: expected uint8 shape {pts.shape}, got {cols.dtype} {cols.shape}"
            )
        cloud.point_data["RGB"] = cols[keep]
    return cloud


#: Most points ``stereovision view`` shows by default (``--max-points``). A cloud of tens of
#: millions (a KITTI-size map at full resolution, several merged clouds) is shown as an evenly
#: spaced subset of this many: a 15 M point PLY took 66 s and 2.4 GB to screenshot on a 2-core
#: machine, 13 s and 0.75 GB (mostly reading the file) with the subset; 2 M points still fill a
#: 1024-pixel window several times over.
VIEW_MAX_POINTS = 2_000_000

#: Key of ``field_data`` in which :func:`load_view_source` keeps the cloud's point count when it
#: shows a subset of it.
POINTS_IN_SOURCE = "points_in_source"


def display_subset(
    points: npt.ArrayLike,
    colors: npt.ArrayLike | None = None,
    max_points: int | None = VIEW_MAX_POINTS,
) -> tuple[npt.NDArray[Any], npt.NDArray[Any] | None]:
    """At most ``max_points`` of ``points`` (and their colours), evenly spaced, for display.

    Point ``floor(i * N / max_points)`` for ``i = 0 .. max_points - 1``: deterministic (the
    same cloud always shows the same points), in the cloud's own order, a point of every part
    of a cloud written region by region. For showing only: files are never decimated.

    Parameters
    ----------
    points : array_like, (N, 3)
    colors : array_like, (N, 3), optional
    max_points : int or None
        The cap; None or 0 keeps every point.

    Returns
    -------
    tuple
        ``(points, colors)``, the input arrays themselves when ``N <= max_points``.

    Raises
    ------
    ValueError
        ``max_points`` negative or not an integer.

    Examples
    --------
    >>> pts, _ = display_subset(np.arange(30.0).reshape(10, 3), max_points=4)
    >>> pts[:, 0].tolist()
    [0.0, 6.0, 15.0, 21.0]
    """
    if max_points is not None and (
        not isinstance(max_points, (int, np.integer))
        or isinstance(max_points, NOT_NUMBERS)
        or max_points < 0
    ):
        raise ValueError(
            f"max_points: expected a whole number of points (0 = all), got {max_points!r}"
        )
    pts = np.asarray(points)
    cols = None if colors is None else np.asarray(colors)
    n = len(pts)
    if not max_points or n <= max_points:
        return pts, cols
    idx = (np.arange(int(max_points), dtype=np.int64) * n) // int(max_points)
    return pts[idx], None if cols is None else cols[idx]


# ----------------------------------------------------------------------------- rendering


def make_plotter(size: tuple[int, int], *, off_screen: bool = True) -> pv.Plotter:
    """A plotter of ``size = (width, height)`` pixels with the package background."""
    pv = _pv()
    plotter = pv.Plotter(off_screen=off_screen, window_size=list(size))
    plotter.set_background([c / 255 for c in BACKGROUND])
    return plotter


#: Title of the scale bar of a cloud without colours, coloured by its depth.
DEPTH_BAR_TITLE = "depth Z (m)"


def _turbo_table(lo: float, hi: float) -> Any:
    """A 256-entry TURBO lookup table over ``lo..hi`` (OpenCV's colours: no matplotlib)."""
    import cv2

    pv = _pv()
    bgr = cv2.applyColorMap(np.arange(256, dtype=np.uint8).reshape(-1, 1), cv2.COLORMAP_TURBO)
    rgba = np.concatenate([bgr[:, 0, ::-1], np.full((256, 1), 255, np.uint8)], axis=1)
    table = pv.LookupTable(values=rgba)
    table.scalar_range = (lo, hi)
    return table


def _bar_label_format(lo: float, hi: float) -> str:
    """The scale bar's label format over ``lo..hi`` metres: two decimals, more where its five
    labels (a quarter of the range apart) would need them to differ (a stereo microscope's
    cloud 4-6 mm ahead was labelled "0.00 0.00 0.01 0.01 0.01"). Past a million metres or
    under a nanometre step, significant digits (``%g``): a far cloud's labels were hundreds of
    digits long, a tiny range's all "0.000000000", and +-1e308 an OverflowError. An empty
    range (a flat cloud) has two decimals, or 3 significant digits past a million metres: a
    flat cloud at 1e20 m, whose +-0.5 m range is empty in doubles, read
    "100000002004087734272.00"."""
    step = hi / 4 - lo / 4  # (hi - lo) / 4 overflowed to inf for +-1e308
    big = max(abs(lo), abs(hi))
    if not step > 0 or not math.isfinite(step):
        return "%.2f" if big < 1e6 else "%.3g"
    decimals = max(2, math.ceil(-math.log10(step)))
    if decimals <= 9 and big < 1e6:
        return f"%.{decimals}f"
    # enough significant digits for labels a step apart to differ (17 hold any double)
    return f"%.{min(17, max(3, math.ceil(math.log10(big / step)) + 2))}g"


def add_geometry(plotter: pv.Plotter, geometry: pv.PolyData) -> Any:
    """Add a surface mesh (textured, unlit) or a point cloud (RGB points) to ``plotter``.

    A point cloud without colours (a PLY / PCD of another tool) is coloured by its depth Z
    (TURBO over the 1st-99th percentiles) with a scale bar in metres (:data:`DEPTH_BAR_TITLE`,
    two decimals, more for a range under 4 cm); plain points of one colour showed no
    depth at all.
    """
    texture = texture_of(geometry) if geometry.n_cells and geometry.n_faces else None
    has_rgb = "RGB" in geometry.point_data
    if not has_rgb and not geometry.n_faces and geometry.n_points:
        z = np.asarray(geometry.points, dtype=np.float64)[:, 2]
        finite = z[np.isfinite(z)]
        lo, hi = (float(v) for v in np.percentile(finite, [1, 99])) if finite.size else (0, 1)
        if not hi > lo:
            lo, hi = lo - 0.5, lo + 0.5
        coloured = geometry.copy(deep=False)  # the caller's geometry stays as it was
        coloured.point_data[DEPTH_BAR_TITLE] = z
        return plotter.add_mesh(
            coloured,
            scalars=DEPTH_BAR_TITLE,
            cmap=_turbo_table(lo, hi),
            clim=(lo, hi),
            point_size=POINT_SIZE,
            style="points",
            lighting=False,
            name="scene",
            scalar_bar_args={
                "title": DEPTH_BAR_TITLE,
                "color": "white",
                "fmt": _bar_label_format(lo, hi),
            },
        )
    if geometry.n_faces:
        if texture is not None:
            return plotter.add_mesh(geometry, texture=texture, lighting=False, name="scene")
        return plotter.add_mesh(
            geometry, scalars="RGB" if has_rgb else None, rgb=has_rgb, lighting=False, name="scene"
        )
    return plotter.add_mesh(
        geometry,
        scalars="RGB" if has_rgb else None,
        rgb=has_rgb,
        point_size=POINT_SIZE,
        style="points",
        lighting=False,
        name="scene",
    )


def median_depth(geometry: pv.PolyData) -> float:
    """Median Z of the geometry's points (metres), or the default focal distance if unusable."""
    z = np.asarray(geometry.points)[:, 2] if geometry.n_points else np.zeros(0)
    z = z[np.isfinite(z) & (z > 0)]
    return float(np.median(z)) if z.size else _DEFAULT_FOCAL_DISTANCE


def _render_size(size: Any) -> tuple[int, int]:
    """``render_view``'s ``size`` as ``(width, height)`` ints, checked: VTK took (0, 0) for its
    default 300 x 300, (0, 50) for the screen's 1920 x 1080, and (-5, 10) for a 21849 x 300
    picture of shader errors, all without a word."""
    from stereovision._validate import check_index_range

    try:
        items = list(size)
    except TypeError:
        items = []
    whole = len(items) == 2 and all(
        isinstance(v, (int, np.integer)) and not isinstance(v, NOT_NUMBERS) for v in items
    )
    if not whole or min(int(v) for v in items) < 1:
        # NumPy numbers as plain ones: "(0, 0)", not "(np.int64(0), np.int64(0))"
        shown = tuple(v.item() if isinstance(v, np.generic) else v for v in items)
        shown = shown if len(items) == 2 else size
        raise ValueError(f"size: expected (width, height) in whole pixels >= 1, got {shown!r}")
    width, height = (int(v) for v in items)
    check_index_range((height, width), "size", "render")
    return width, height


def render_view(
    geometry: pv.PolyData,
    controls: CameraControls | None = None,
    *,
    intrinsics: Intrinsics | None = None,
    size: tuple[int, int] | None = None,
    camera: CameraState | None = None,
) -> npt.NDArray[np.uint8]:
    """Render ``geometry`` offscreen from the camera of ``controls`` (or ``camera``).

    Parameters
    ----------
    geometry : pyvista.PolyData
        From :func:`surface_mesh` or :func:`point_cloud`.
    controls : CameraControls, optional
        Default: the left camera's pose.
    intrinsics : Intrinsics, optional
        Camera model (e.g. :meth:`Intrinsics.from_result`); the render size defaults to its image
        size. Without intrinsics a :data:`DEFAULT_FOV_DEG` view of ``size`` (default 800x600).
    size : (int, int), optional
        ``(width, height)`` of the picture. With intrinsics only the width counts: they are
        scaled to it and keep their aspect ratio (the picture is ``width`` wide, as tall as the
        scaled intrinsics).
    camera : CameraState, optional
        A view to render instead of the controls' pose (an interactive view's camera as the
        mouse left it): its position, focal point, view-up, view angle, window centre and
        projection; ``intrinsics`` then give only the picture's size.

    Returns
    -------
    ndarray, uint8 (height, width, 3)
        RGB screenshot.

    Raises
    ------
    ValueError
        Both ``controls`` and ``camera`` given, or a ``size`` that is not two whole numbers of
        pixels >= 1 (within the writer's 32-bit pixel indices), or a picture past those indices
        once ``intrinsics`` are scaled to ``size`` (or given alone).
    """
    if camera is not None and controls is not None:
        raise ValueError("render_view: give controls or camera, not both")
    controls = controls or CameraControls()
    if size is not None:
        size = _render_size(size)
    if intrinsics is not None:
        # the picture is the intrinsics' (scaled to size's width): (100000, 1) made a 400 x 300
        # camera's 100000 x 75000, past the check of size alone
        from stereovision._validate import check_index_range

        what = "intrinsics" if size is None else "size"
        if size is not None:
            intrinsics = intrinsics.scaled(size[0] / intrinsics.width)
        size = (intrinsics.width, intrinsics.height)
        check_index_range((size[1], size[0]), what, "render")
    size = DEFAULT_VIEW_SIZE if size is None else size  # not `or`: a NumPy size has no truth value
    plotter = make_plotter(size)
    try:
        add_geometry(plotter, geometry)
        if camera is not None:
            camera.apply(plotter, points=geometry.points)
        else:
            apply_camera(
                plotter,
                controls,
                intrinsics=intrinsics,
                focal_distance=median_depth(geometry),
                points=geometry.points,
            )
        img = plotter.screenshot(return_img=True)
    finally:
        plotter.close()
    if img is None:
        raise RuntimeError("the offscreen render returned no image")
    return np.ascontiguousarray(np.asarray(img)[..., :3], dtype=np.uint8)


def cloud_view_intrinsics(
    points: npt.ArrayLike, size: tuple[int, int] = DEFAULT_VIEW_SIZE
) -> Intrinsics:
    """A centred camera of ``size`` that sees the points of ``points`` from the left camera's
    pose: :data:`DEFAULT_FOV_DEG` vertically, widened (up to :data:`MAX_FIT_FOV_DEG`) when
    the cloud's points lie outside it.

    The default view of a cloud without intrinsics (a ``cloud.ply``): a wide camera's cloud
    (KITTI's, 81 degrees across) lost its sides to the fixed 60 degrees (75 across at 4:3):
    6 % of ``depth``'s own KITTI cloud was out of the picture.

    The view fits the :data:`FIT_PERCENTILE` th percentile of the points' angles across and
    down, not the widest point: a few stray points (mismatches far to the side, common in
    stereo clouds) may stay outside rather than widen the view and shrink the scene.

    Parameters
    ----------
    points : array_like (N, 3)
        Metres, left camera frame; points that are not finite or not in front (Z <= 0) are
        left out of the fit.
    size : (int, int)
        ``(width, height)`` of the picture.

    Returns
    -------
    Intrinsics
        Square pixels, principal point at the picture's centre.
    """
    w, h = _render_size(size)
    f = (h / 2) / math.tan(math.radians(DEFAULT_FOV_DEG / 2))
    f_min = (h / 2) / math.tan(math.radians(MAX_FIT_FOV_DEG / 2))
    pts = np.asarray(points).reshape(-1, 3)  # no float64 copy: 15 M points are 360 MB
    ahead = np.nonzero(np.isfinite(pts).all(axis=1) & (pts[:, 2] > 0))[0]
    if len(ahead):
        # the outer pixels' outer edges are w / 2 and h / 2 from the centre; 1 % to spare
        z = pts[ahead, 2].astype(np.float64)
        across = float(np.percentile(np.abs(pts[ahead, 0]) / z, FIT_PERCENTILE))
        down = float(np.percentile(np.abs(pts[ahead, 1]) / z, FIT_PERCENTILE))
        for extent, half in ((across, w / 2), (down, h / 2)):
            if extent * f > 0.99 * half:
                f = 0.99 * half / extent
        f = max(f, f_min)
    return Intrinsics(f, w / 2 - 0.5, h / 2 - 0.5, w, h)


def points_in_view(
    points: npt.ArrayLike,
    controls: CameraControls,
    size: tuple[int, int],
    intrinsics: Intrinsics | None = None,
) -> int:
    """How many of ``points`` project inside a ``size = (width, height)`` render of ``controls``.

    The camera model of :func:`render_view`: ``intrinsics`` scaled to ``width``, or a
    :data:`DEFAULT_FOV_DEG` vertical field of view centred on the picture.

    Parameters
    ----------
    points : array_like (N, 3)
        Metres, left camera frame; non-finite rows count as not in view.
    controls : CameraControls
    size : (int, int)
    intrinsics : Intrinsics, optional

    Returns
    -------
    int
        Points in front of the camera and inside the picture.

    Raises
    ------
    ValueError
        A ``size`` that is not two whole numbers of pixels >= 1 (as :func:`render_view`): a
        size of (0, 0) counted 0 points without a word, with intrinsics it was refused as
        their focal length.
    """
    w, h = _render_size(size)
    if intrinsics is not None:
        k = intrinsics.scaled(w / intrinsics.width)
        f, fy, cx, cy = k.f, k.focal_y, k.cx, k.cy
    else:
        f = fy = (h / 2) / math.tan(math.radians(DEFAULT_FOV_DEG / 2))
        cx, cy = w / 2 - 0.5, h / 2 - 0.5
    pose = controls.pose()
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    cam = (pts - pose[:3, 3]) @ pose[:3, :3]  # R^T (p - t)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = f * cam[:, 0] / cam[:, 2] + cx
        y = fy * cam[:, 1] / cam[:, 2] + cy
    inside = (cam[:, 2] > 0) & (x >= -0.5) & (x < w - 0.5) & (y >= -0.5) & (y < h - 0.5)
    return int(np.count_nonzero(inside))


def is_blank(image: npt.NDArray[np.uint8], *, min_fraction: float = 0.01) -> bool:
    """True when fewer than ``min_fraction`` of the pixels differ from the render background."""
    bg = np.asarray(BACKGROUND, dtype=np.int16)
    differs = np.abs(image[..., :3].astype(np.int16) - bg).max(axis=-1) > 8
    return bool(differs.mean() < min_fraction)


def render_result(
    result: DepthResult,
    controls: CameraControls | None = None,
    *,
    max_side: int = RENDER_MAX_SIDE,
) -> npt.NDArray[np.uint8]:
    """Textured surface of ``result`` seen through its own intrinsics, scaled to ``max_side``.

    An image at least twice ``max_side`` is meshed every ``longer side // max_side`` pixels
    (:func:`surface_mesh`'s ``step``): about one vertex per picture pixel, the texture whole.

    ``controls`` default to an orbit of :data:`RENDER_YAW_DEG` / :data:`RENDER_PITCH_DEG` around
    the scene's median depth (a 3-D impression rather than the left image itself).

    Returns
    -------
    numpy.ndarray
        ``(H, W, 3)`` uint8 in **RGB** order, as VTK renders (``img[..., ::-1]`` for
        ``cv2.imwrite``).

    Raises
    ------
    ValueError
        A result without calibration or 3-D points, or ``max_side`` below 16.
    """
    if (
        not isinstance(max_side, (int, np.integer))
        or isinstance(max_side, NOT_NUMBERS)
        or max_side < 16
    ):
        raise ValueError(f"max_side: expected at least 16 pixels, got {max_side!r}")
    _check_result(result)
    intr = Intrinsics.from_result(result)
    assert intr is not None  # _check_result
    longest = max(intr.width, intr.height)
    scale = min(1.0, max_side / longest)
    # about one vertex per picture pixel is all the picture shows (the texture keeps every
    # pixel of the image): a 3000 x 2000 result's full mesh took 52-70 s and 2.1 GB over the
    # data for a 1024 px render.png. Images under twice max_side keep every vertex.
    step = max(1, longest // int(max_side))
    if step > 1:
        # a sparse result (a few pixels with a depth) may have none on the sub-sampled grid: its
        # every vertex then (few of them), not the error that failed `depth -o` whole
        if len(result.points):
            on_grid = bool((result.pixels % step == 0).all(axis=1).any())
        else:  # depth_map(cloud=False): its depth map's pixels (the cloud is not rebuilt twice)
            assert result.depth is not None  # _check_result
            on_grid = bool(np.isfinite(result.depth[::step, ::step]).any())
        if not on_grid:
            step = 1
    mesh = surface_mesh(result, step=step)
    if controls is None:
        controls = orbit_controls(RENDER_YAW_DEG, RENDER_PITCH_DEG, median_depth(mesh))
    return render_view(mesh, controls, intrinsics=intr.scaled(scale))


def render_outputs(result: DepthResult, out_dir: str | os.PathLike[str]) -> dict[str, Path]:
    """Write ``render.png``, an offscreen 3-D view of the textured surface, into ``out_dir``.

    Meant for ``stereovision depth``: results without calibration or without any 3-D point have
    nothing to render and write nothing.

    Parameters
    ----------
    result : DepthResult
    out_dir : path
        Output folder (created if missing). The file is replaced atomically.

    Returns
    -------
    dict
        ``{"render.png": path}``, or ``{}`` when there is nothing to render.
    """
    # a bytes name was pathlib's TypeError naming no argument, and after the render
    as_path(out_dir, "out_dir")
    # a depth_map(cloud=False) result has no points but a depth map to build them from
    if result.depth is None or result.calibration is None or not np.isfinite(result.depth).any():
        return {}
    return write_render(render_result(result), out_dir)


def write_render(image: npt.NDArray[np.uint8], out_dir: str | os.PathLike[str]) -> dict[str, Path]:
    """Write ``image`` (a render, RGB) as ``render.png`` into ``out_dir``.

    The writer of :func:`render_outputs`, for a view rendered otherwise (the GUI's Save: the
    3-D view's own pose).

    Parameters
    ----------
    image : ndarray, uint8 (H, W, 3)
        RGB, as :func:`render_view` returns it.
    out_dir : path
        Output folder (created if missing). The file is replaced atomically.

    Returns
    -------
    dict
        ``{"render.png": path}``.

    Raises
    ------
    ValueError
        ``image`` is None, not ``(H, W, 3)`` uint8, empty, or past the kernels' 32-bit pixel
        indices (checked from its shape, before the BGR copy).
    NotADirectoryError
        ``out_dir`` or a folder above it is a file or a link to nothing.
    OSError
        The image could not be encoded or written.
    """
    import cv2

    from stereovision._validate import check_index_range
    from stereovision.io import atomic_write, make_folder

    # unchecked, a grey image came out mirrored (its columns reversed as if channels), RGBA as
    # ABGR, uint16 or float as a 16-bit or clipped PNG, and a broadcast 70000 x 70000 render
    # was a MemoryError for its 14 GiB BGR copy
    if image is None:
        raise ValueError("image: expected a (H, W, 3) uint8 RGB render, got None")
    img = image if isinstance(image, np.ndarray) else np.asarray(image)
    if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
        raise ValueError(
            f"image: expected a (H, W, 3) uint8 RGB render, got {img.dtype} {img.shape}"
        )
    if img.size == 0:
        raise ValueError(f"image: the render has no pixel (shape {img.shape})")
    check_index_range(img.shape, "image")
    ok, buf = cv2.imencode(".png", np.ascontiguousarray(img[..., ::-1]))
    if not ok:
        raise OSError("could not encode render.png")
    # bytes: pathlib's TypeError named no argument; mkdir's bare "[Errno 17] File exists" of a
    # link to nothing, or "[Errno 20] Not a directory" under a file, named no cause
    out = make_folder(as_path(out_dir, "out_dir"))
    path = out / "render.png"
    with atomic_write(path) as fh:
        fh.write(buf.tobytes())
    return {"render.png": path}


# ----------------------------------------------------------------------------- `stereovision view`


#: X display name -> whether its server accepted a connection (asked once per process).
_X_DISPLAYS: dict[str, bool] = {}


def _x_server_answers(name: str) -> bool:
    """Whether the X server ``name`` (a ``$DISPLAY`` value) accepts a connection.

    libX11's ``XOpenDisplay``, closed again at once: the call VTK's window makes first. False
    when libX11 cannot be loaded (VTK cannot open a window without it either).

    Parameters
    ----------
    name : str
        The display, e.g. ``":0"`` or ``"localhost:10.0"``.

    Returns
    -------
    bool
    """
    if name not in _X_DISPLAYS:
        import ctypes
        import ctypes.util

        x11 = None
        for lib in ("libX11.so.6", ctypes.util.find_library("X11")):
            if lib:
                try:
                    x11 = ctypes.CDLL(lib)
                    break
                except OSError:
                    continue
        answers = False
        if x11 is not None:
            x11.XOpenDisplay.restype = ctypes.c_void_p
            x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
            x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
            dpy = x11.XOpenDisplay(name.encode())
            if dpy:
                x11.XCloseDisplay(dpy)
                answers = True
        _X_DISPLAYS[name] = answers
    return _X_DISPLAYS[name]


def _has_display() -> bool:
    """Whether a window can be shown: on Linux an X server that answers at ``$DISPLAY`` (a
    ``DISPLAY`` naming no running server counted before, and ``view`` then showed nothing and
    wrote nothing); on Windows and macOS always (VTK opens a native window there, no X server:
    ``DISPLAY`` is unset and ``view`` wrote a screenshot instead of opening one); on other Unix
    systems ``DISPLAY`` or ``WAYLAND_DISPLAY`` set."""
    if sys.platform in ("win32", "darwin"):
        return True
    x = os.environ.get("DISPLAY")
    if x and sys.platform.startswith("linux"):
        return _x_server_answers(x)
    return bool(x or os.environ.get("WAYLAND_DISPLAY"))


def load_view_source(
    path: str | os.PathLike[str], max_points: int | None = VIEW_MAX_POINTS
) -> tuple[pv.PolyData, Intrinsics | None]:
    """Geometry to show for ``stereovision view``: a cloud file, an output folder or a scene.

    Parameters
    ----------
    path : path
        A ``.ply`` / ``.pcd`` / ``.npz`` file (see :func:`stereovision.export.load_cloud`); a
        folder with ``cloud.ply`` (``stereovision depth`` output); or a scene folder with
        ``left.png``, ``right.png`` and ``calib.txt`` (depth is computed and the textured surface
        shown).
    max_points : int or None
        A cloud of more finite points is shown as an evenly spaced subset of this many
        (:func:`display_subset`); its full count is then in
        ``geometry.field_data[POINTS_IN_SOURCE]``. None or 0: every point. The file is only read.

    Returns
    -------
    geometry : pyvista.PolyData
    intrinsics : Intrinsics or None

    Raises
    ------
    FileNotFoundError, ValueError
        Missing path, not a point cloud file, an empty cloud, a folder with nothing to show, a
        scene too narrow for its disparity range.
    """
    from stereovision.export import load_cloud

    p = Path(path)
    if not p.exists():
        from stereovision.io import _broken_link

        # a link whose target moved was "no such file or folder" of a name ls lists
        gone = f" ({_broken_link(p)})" if p.is_symlink() else ""
        raise FileNotFoundError(f"no such file or folder: {p}{gone}")
    if p.is_dir():
        if (p / "cloud.ply").is_file():
            p = p / "cloud.ply"
        elif (p / "left.png").is_file() and (p / "right.png").is_file():
            from stereovision.depth import depth_map
            from stereovision.io import load_scene, scene_too_narrow

            scene = load_scene(p, full_bits=True)  # a 16-bit pair as `depth` reads it
            if scene.calib is None:
                raise ValueError(f"scene {p} has no calib.txt: no metric 3-D points to show")
            narrow = scene_too_narrow(scene)
            if narrow:  # as eval says it: the range is the scene's, view has no max_disparity
                raise ValueError(f"scene {p}: {narrow}")
            result = depth_map(
                scene.left, scene.right, scene.calib, max_disparity=scene.max_disparity
            )
            return surface_mesh(result), Intrinsics.from_result(result)
        elif (p / "disparity.pfm").is_file():
            # `stereovision depth` without --calib: disparities only, no metric point
            raise FileNotFoundError(
                f"{p}: a depth output without cloud.ply (depth writes the cloud only with "
                "--calib: no metric 3-D points without one)"
            )
        else:
            from stereovision.io import _MIDDLEBURY_NAMES, _cased_pair

            # Left.png + Right.png: "no scene (left.png + right.png)" alone, beside them
            cased = _cased_pair(p)
            # and a folder as Middlebury ships it (im0.png + im1.png), as load_scene, eval and
            # bench say it: the names to use were unsaid
            if not any(os.path.lexists(p / n) for n in ("left.png", "right.png")) and all(
                (p / n).is_file() for n in ("im0.png", "im1.png")
            ):
                cased = _MIDDLEBURY_NAMES
            raise FileNotFoundError(
                f"{p}: no cloud.ply and no scene (left.png + right.png) in this folder"
                + (f"; it {cased}" if cased else "")
            )
    points, colors = load_cloud(p)
    shown, shown_colors = display_subset(points, colors, max_points)
    cloud = point_cloud(shown, shown_colors)
    if len(shown) < len(points):
        cloud.field_data[POINTS_IN_SOURCE] = np.array([len(points)], dtype=np.int64)
    return cloud, None


#: Screenshot formats of ``view -o`` (OpenCV writes each by its suffix; none: PNG).
SCREENSHOT_SUFFIXES = ("", ".png", ".jpg", ".jpeg", ".bmp")


#: Screenshot of ``view`` without ``-o`` and without a display (in the working folder).
DEFAULT_SCREENSHOT = "view.png"


def _free_name(path: Path) -> Path:
    """``path`` if nothing is there, else the first free ``stem-2.suffix``, ``stem-3.suffix``..."""
    k = 2
    free = path
    while free.exists() or free.is_symlink():
        free = path.with_name(f"{path.stem}-{k}{path.suffix}")
        k += 1
    return free


def _check_screenshot_path(output: str | os.PathLike[str], source: str | os.PathLike[str]) -> Path:
    """``view -o``'s file, checked before anything is loaded or rendered.

    Parameters
    ----------
    output : path
        The screenshot file.
    source : path
        What ``view`` shows (a cloud file, a ``depth`` output folder or a scene folder).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ValueError
        An unsupported suffix, or ``output`` is one of the files ``view`` reads (a scene's
        ``left.png`` / ``right.png``): the screenshot would replace it.
    FileNotFoundError
        The folder of ``output`` does not exist.
    IsADirectoryError, NotADirectoryError
        ``output`` is a folder, or its folder is a file.
    PermissionError
        No file can be made in the folder of ``output`` (the system's reason).
    OSError
        ``output`` is a FIFO or a device (or a link to one).
    """
    from stereovision.io import _special_kind, _through_links, cannot_write_in, refuse_an_input

    out = Path(output)
    if out.suffix.lower() not in SCREENSHOT_SUFFIXES:
        raise ValueError(f"{out}: a screenshot is written as .png, .jpg or .bmp")
    if out.is_dir():
        raise IsADirectoryError(f"-o {out}: is a folder; give the screenshot a file name")
    # a link is written through: the new file is made beside its target, not beside the link
    dest = _through_links(out)
    if dest.exists() and not dest.is_file():
        # a FIFO or a device, refused by atomic_write only after the depth map and the render
        raise OSError(
            f"-o {out}: cannot write {dest}: it is not a regular file ({_special_kind(dest)})"
        )
    parent = dest.parent
    if parent.exists() and not parent.is_dir():
        raise NotADirectoryError(f"-o {out}: {parent} is a file, not a folder")
    if not parent.exists():
        raise FileNotFoundError(f"output folder does not exist: {parent}")
    why = cannot_write_in(parent)
    if why:  # found after the depth map and the render, by the writer
        raise PermissionError(f"-o {out}: cannot write in {parent} ({why})")
    src = Path(source)
    if src.is_dir():
        inputs = {f"the scene's {side} image": src / f"{side}.png" for side in ("left", "right")}
    else:
        inputs = {"the cloud shown": src}
    refuse_an_input("-o", out, {what: str(p) for what, p in inputs.items() if p.exists()})
    return out


def cmd_view(args: argparse.Namespace) -> int:
    """``stereovision view FILE.ply|DIR [--roll ...] [-o shot.png]``."""
    import cv2

    controls = CameraControls(
        roll=args.roll,
        pitch=args.pitch,
        yaw=args.yaw,
        forward=args.forward,
        up=args.up,
        right=args.right,
    )
    # the screenshot's name is checked before the work (a scene folder computes its depth)
    out = None if args.output is None else _check_screenshot_path(args.output, args.source)
    max_points = getattr(args, "max_points", VIEW_MAX_POINTS)
    if max_points is not None and max_points < 0:
        raise ValueError(f"--max-points: expected 0 (all) or more, got {max_points}")
    window = out is None and _has_display()
    if out is None and not window:
        from stereovision.io import cannot_write_in

        # the screenshot goes to ./view.png: a folder that cannot be written is said now, not
        # after the source was loaded (a scene's depth map computed) and rendered
        why = cannot_write_in(".")
        if why:
            raise PermissionError(
                f"no display, so the screenshot goes to {DEFAULT_SCREENSHOT} here: cannot write "
                f"in {Path.cwd()} ({why}); -o names another file"
            )
    geometry, intr = load_view_source(args.source, max_points)
    if POINTS_IN_SOURCE in geometry.field_data:
        total = int(geometry.field_data[POINTS_IN_SOURCE][0])
        print(
            f"note: showing {geometry.n_points} of the {total} points (evenly spaced, for "
            "display only; --max-points 0 shows all)",
            file=sys.stderr,
        )
    if window:
        size = VIEW_WINDOW_SIZE
        plotter = make_plotter(size, off_screen=False)
        add_geometry(plotter, geometry)
        # a mouse drag resets the clipping range from the bounds, which far outliers ruin
        keep_robust_clipping(plotter, geometry.points)
        apply_camera(
            plotter,
            controls,
            # a view wide enough for all of it, a scene's too: its own camera (KITTI's is 3.3:1)
            # would not fill the window's 4:3, and the fixed 60 degrees lost a wide one's sides
            intrinsics=cloud_view_intrinsics(geometry.points, size),
            focal_distance=median_depth(geometry),
            points=geometry.points,
        )
        plotter.show()
        return 0
    if out is None:
        import warnings

        # a view.png already there (the user's, or an earlier view's) is kept: the next free name
        out = _free_name(Path(DEFAULT_SCREENSHOT))
        display = os.environ.get("DISPLAY")
        why = f"no X server answers at DISPLAY={display}" if display else "no display"
        warnings.warn(
            f"{why}: no window; writing a screenshot to {out} instead (-o names another)",
            stacklevel=1,
        )
    if intr is None:  # a bare cloud: a view wide enough for all of it
        intr = cloud_view_intrinsics(geometry.points)
    img = render_view(geometry, controls, intrinsics=intr)
    if points_in_view(geometry.points, controls, (img.shape[1], img.shape[0]), intr) == 0:
        import warnings

        # a cloud in another frame (ROS's X forward, Z up) or controls turned away from it
        warnings.warn(
            f"none of the {geometry.n_points} points is in view (behind the camera or outside "
            "its field of view): the screenshot is empty; the cloud must be in the camera "
            "frame (metres, X right, Y down, Z forward)",
            stacklevel=1,
        )
    # the format the name asks for (a .jpg got PNG bytes); PNG for a name without one
    ok, buf = cv2.imencode(out.suffix.lower() or ".png", img[..., ::-1])
    if not ok:
        raise OSError(f"could not encode {out}")
    from stereovision.io import atomic_write, keep_previous

    data = buf.tobytes()
    kept = keep_previous(out, data)  # a file already there (an earlier shot, a picture) stays
    with atomic_write(out) as fh:
        fh.write(data)
    # a cloud's cells are its points: "N points, N cells" read as if it were a mesh
    shown = geometry.n_points
    if POINTS_IN_SOURCE in geometry.field_data:
        total = int(geometry.field_data[POINTS_IN_SOURCE][0])
        what = f"{shown} of {total} points shown"
    else:
        what = f"{shown} point{'s' if shown != 1 else ''}"  # a one-point cloud: "1 points"
    faces = geometry.n_faces
    what += f", {faces} triangle{'s' if faces != 1 else ''}" if faces else ""
    # a folder named with a newline cut the line in two (escaped, as its warnings name it)
    replaced = f" (the one it replaced kept as {escaped(str(kept))})" if kept else ""
    print(f"{what} -> {escaped(str(out))}{replaced}", file=sys.stdout)
    return 0


#: Farthest ``view --forward`` / ``--up`` / ``--right`` moves the camera, in metres: 1000 km, far
#: past any cloud a stereo rig measures (``--forward 1e200`` overflowed NumPy's distances: a
#: RuntimeWarning, an empty screenshot and exit 0).
VIEW_MAX_MOVE_M = 1e6


def _camera_move(text: str) -> float:
    """argparse type of ``view``'s ``--forward``, ``--up`` and ``--right``: finite metres within
    :data:`VIEW_MAX_MOVE_M` either way, refused in the option's name."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and abs(value) <= VIEW_MAX_MOVE_M):
        raise argparse.ArgumentTypeError(
            f"expected metres from -{VIEW_MAX_MOVE_M:g} to {VIEW_MAX_MOVE_M:g}, got {text!r}"
        )
    return value


def _point_count(text: str) -> int:
    """argparse type of ``view``'s ``--max-points``: a whole number of 0 or more, refused in
    one wording (-1 was the command's "--max-points: expected 0 (all) or more", 1.5 argparse's
    "expected a whole number")."""
    from stereovision.cli import whole_number  # 1000.0 too, as every whole-number option

    value = whole_number(text)
    if value is None or value < 0:
        raise argparse.ArgumentTypeError(
            f"expected a whole number of points, 0 (all) or more, got {text!r}"
        )
    return value


def _camera_turn(text: str) -> float:
    """argparse type of ``view``'s ``--roll``, ``--pitch`` and ``--yaw``: finite degrees,
    refused in the option's name (``--roll nan`` was the library's "camera control roll must
    be a finite number", naming no option)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number of degrees, got {text!r}")
    return value


def add_cli(subparsers: Any) -> None:
    """Register ``stereovision view`` on the CLI's sub-parsers."""
    p = subparsers.add_parser(
        "view",
        help="show a point cloud / depth output (window, or a screenshot without a display)",
    )
    p.add_argument("source", help="cloud.ply / .pcd / .npz, a `depth` output folder or a scene")
    # the signs of camera_pose, said where a user looks for them
    for name, sign in (
        ("roll", "> 0 lowers the camera's right side"),
        ("pitch", "> 0 looks up"),
        ("yaw", "> 0 turns right"),
    ):
        p.add_argument(f"--{name}", type=_camera_turn, default=0.0, help=f"degrees; {sign}")
    for name, axis in (("forward", "+Z"), ("up", "-Y"), ("right", "+X")):
        p.add_argument(
            f"--{name}",
            type=_camera_move,
            default=0.0,
            help=f"move the camera {name}, metres (along the left camera's {axis})",
        )
    p.add_argument(
        "--max-points",
        type=_point_count,
        default=VIEW_MAX_POINTS,
        metavar="N",
        help="show a cloud of more points as an evenly spaced subset of N "
        f"(default {VIEW_MAX_POINTS}; 0 shows all); the file is not changed",
    )
    p.add_argument(
        "-o",
        "--output",
        default=None,
        help="screenshot .png/.jpg/.bmp (default without a display: view.png, or view-2.png... "
        "when it exists)",
    )
    p.set_defaults(func=cmd_view)
