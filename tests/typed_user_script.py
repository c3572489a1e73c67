"""A user's script, as the README's "Using it" writes one, that must pass ``mypy --strict``.

Not a test module: ``test_typing.py`` type-checks this file against the installed package
(a type error here is one every typed user of the API meets) and runs :func:`run` on a scene.
Every value is annotated with the type the README promises, so a public signature that turns
``Any``, ``Optional`` or the wrong array type fails the check. Every call of the README's
Python example ("Using it") is here (:func:`run`, :func:`modes`), and so is docs/robotics.md's
pipeline ("From chessboard to a robot's inputs", :func:`robot`); :func:`modes` is only
type-checked (each mode's values are tested elsewhere), the other two also run.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

import stereovision as sv
from stereovision import export
from stereovision.depth import DepthChannels
from stereovision.ground import GroundPlane
from stereovision.rectification_check import RectificationCheck

F32 = npt.NDArray[np.float32]


def _read(path: Path) -> npt.NDArray[np.uint8]:
    image = cv2.imread(str(path))
    if image is None:
        raise FileNotFoundError(path)
    return np.asarray(image, dtype=np.uint8)


def corrected(
    left: npt.NDArray[np.uint8], right: npt.NDArray[np.uint8], calib: sv.Calibration
) -> sv.Calibration:
    """The rig's calibration with its rows lined up again, if the check says they drifted.

    Parameters
    ----------
    left, right : ndarray
        A raw pair of the rig.
    calib : Calibration
        Its calibration.

    Returns
    -------
    Calibration
        ``calib`` or its correction.
    """
    check: RectificationCheck = sv.check_rectification(left, right, calib)
    if check.ok is not False:
        return calib
    fixed, _after = sv.refine_rectification(left, right, calib, check=check)
    return fixed


def run(scene: Path, out: Path) -> dict[str, float]:
    """Depth, cloud and matches of ``scene`` (``calib.txt``, ``left.png``, ``right.png``).

    Parameters
    ----------
    scene : Path
        The scene's folder.
    out : Path
        A folder for the files written.

    Returns
    -------
    dict
        A few numbers from each part of the API, for the test to check.
    """
    calib: sv.Calibration = sv.Calibration.from_file(scene / "calib.txt")
    left, right = _read(scene / "left.png"), _read(scene / "right.png")
    res: sv.DepthResult = sv.depth_map(left, right, calib, method="gabor", refine=False)
    disparity: F32 = res.disparity
    maybe_depth: F32 | None = res.depth
    depth: F32 = res.require_depth()
    maybe_sigma: F32 | None = res.depth_sigma
    sigma: F32 = res.require_depth_sigma()
    points: F32 = res.points
    colors: npt.NDArray[np.uint8] = res.colors
    image: F32 = res.point_image()
    image_filled: F32 = res.point_image(filled=True)
    camera: F32 = calib.to_camera_frame(points)
    step: float = calib.depth_step(5.0)
    steps: npt.NDArray[np.float64] = calib.depth_step(np.array([1.0, 2.0]))
    described: str = calib.describe()
    near: sv.DepthResult = res.filtered(max_depth=5.0, max_sigma=0.05)
    depth_ft: F32 = res.depth_in("ft")
    points_ft: F32 = res.points_in("ft")
    sigma_ft: F32 = res.depth_sigma_in("ft")
    ply: Path = res.to_ply(out / "cloud.ply")
    png: Path = export.write_depth_png(out / "depth_mm.png", res)
    disp_png: Path = export.write_disparity_png(out / "disp.png", res)
    pts, rgb = export.voxel_downsample(res.points, res.colors, voxel=0.05)
    pts_typed: F32 = pts
    rgb_typed: npt.NDArray[np.uint8] = rgb
    live: sv.DepthResult = sv.depth_map(
        left, right, calib, method="gabor", cloud=False, refine=False
    )

    m: sv.Matches = sv.match(left, right, method="hopfield")
    table: F32 = m.to_array()
    dispx: F32 = m.dispx
    dispy: F32 = m.dispy
    csv: Path = m.save_csv(out / "matches.csv")
    back: sv.Matches = sv.Matches.from_csv(csv, image_shape=m.image_shape)
    strong: sv.Matches = m[m.score > 0.5]
    xyz: F32 = strong.to_points(calib)
    released: int = sv.release_memory()
    return {
        "disparity_px": float(np.nanmedian(disparity)),
        "depth_m": float(np.nanmedian(depth)),
        "sigma_m": float(np.nanmedian(sigma)),
        "optional_same": float(maybe_depth is depth and maybe_sigma is sigma),
        "depth_ft": float(np.nanmedian(depth_ft)),
        "points_ft": float(np.nanmedian(points_ft[:, 2])),
        "sigma_ft": float(np.nanmedian(sigma_ft)),
        "camera_points": float(len(camera)),
        "camera_dtype_f32": float(camera.dtype == np.float32),
        "described": float(len(described)),
        "points": float(len(points)),
        "colors": float(len(colors)),
        "image_points": float(np.isfinite(image[..., 2]).sum()),
        "image_filled_points": float(np.isfinite(image_filled[..., 2]).sum()),
        "near_points": float(len(near.points)),
        "files": float(all(p.stat().st_size > 0 for p in (ply, png, disp_png))),
        "voxels": float(len(pts_typed)),
        "voxel_colors": float(len(rgb_typed)),
        "live_points": float(len(live.points)),
        "step_5m": step,
        "steps": float(steps.sum()),
        "matches": float(len(table)),
        "strong_xyz": float(len(xyz)),
        "read_back": float(len(back)),
        "dispx": float(np.isfinite(dispx).sum()),
        "dispy": float(np.isfinite(dispy).sum()),
        "released": float(released >= 0),
    }


def modes(left: npt.NDArray[np.uint8], right: npt.NDArray[np.uint8], calib: sv.Calibration) -> int:
    """The README's other modes and matchers, type-checked only (not run by the test).

    Parameters
    ----------
    left, right : ndarray
        A rectified pair.
    calib : Calibration
        Its calibration.

    Returns
    -------
    int
        The number of values, so that none is unused.
    """
    res: sv.DepthResult = sv.depth_map(left, right, calib)
    fused: sv.DepthResult = sv.depth_map(left, right, calib, return_channels=True)
    dense: F32 = fused.disparity
    channels: DepthChannels | None = fused.channels
    no_sgm: sv.DepthResult = sv.depth_map(left, right, calib, semi_global=False)
    census: sv.DepthResult = sv.depth_map(left, right, calib, method="census")
    fast: sv.DepthResult = sv.depth_map(left, right, calib, method="fast")
    found: list[sv.Matches] = [
        sv.match(left, right, method=method) for method in ("mcgm", "fused", "gabor")
    ]
    xyz: F32 = found[0][found[0].score > 0.9].to_points(calib)
    return len([res, dense, channels, no_sgm, census, fast, found, xyz])


def robot(
    left: npt.NDArray[np.uint8], right: npt.NDArray[np.uint8], calib_path: Path, out: Path
) -> dict[str, float]:
    """docs/robotics.md's pipeline: check and fix the rig, depth, floor, hand-over.

    Its depth map is the Gabor channel's (``method="gabor", refine=False``), not the fused
    default's, to keep the test fast; the result's type is the same (:func:`modes`).

    Parameters
    ----------
    left, right : ndarray
        A pair of the rig.
    calib_path : Path
        Its calibration file.
    out : Path
        A folder for the files written.

    Returns
    -------
    dict
        A few numbers from each step, for the test to check.
    """
    calib: sv.Calibration = sv.Calibration.from_file(calib_path)
    described: str = calib.describe()
    check: RectificationCheck = sv.check_rectification(left, right, calib)
    saved: Path | None = None
    if check.ok is False:
        calib, check = sv.refine_rectification(left, right, calib)
        saved = calib.save(out / "rig_fixed.yaml")
    res: sv.DepthResult = sv.depth_map(left, right, calib, method="gabor", refine=False).filtered(
        max_depth=8.0, max_relative_sigma=0.03
    )
    plane: GroundPlane | None = sv.fit_ground_plane(res.disparity, calib)
    obstacles: npt.NDArray[np.bool_] | None = None
    if plane is not None:
        line: str = plane.describe()
        described += line
        obstacles = sv.obstacle_mask(res.point_image(filled=True), plane)
    points: F32 = calib.to_camera_frame(res.points)
    png: Path = export.write_depth_png(out / "depth_mm.png", res)
    pts, rgb = export.voxel_downsample(points, res.colors, voxel=0.05)
    pts_typed: F32 = pts
    rgb_typed: npt.NDArray[np.uint8] = rgb
    return {
        "described": float(len(described)),
        "saved": float(saved is not None),
        "points": float(len(points)),
        "obstacles": -1.0 if obstacles is None else float(obstacles.sum()),
        "files": float(png.stat().st_size > 0),
        "voxels": float(len(pts_typed)),
        "voxel_colors": float(len(rgb_typed)),
    }
