"""A user's script, as the README's "Using it" writes one, that must pass ``mypy --strict``.

Not a test module: ``test_typing.py`` type-checks this file against the installed package
(a type error here is one every typed user of the API meets) and runs :func:`run` on a scene.
Every value is annotated with the type the README promises, so a public signature that turns
``Any``, ``Optional`` or the wrong array type fails the check.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

import stereovision as sv
from stereovision import export
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
    depth: F32 = res.require_depth()
    sigma: F32 = res.require_depth_sigma()
    points: F32 = res.points
    colors: npt.NDArray[np.uint8] = res.colors
    image: F32 = res.point_image()
    near: sv.DepthResult = res.filtered(max_depth=5.0, max_sigma=0.05)
    ply: Path = res.to_ply(out / "cloud.ply")
    png: Path = export.write_depth_png(out / "depth_mm.png", res)
    step: float = calib.depth_step(5.0)
    steps: npt.NDArray[np.float64] = calib.depth_step(np.array([1.0, 2.0]))

    m: sv.Matches = sv.match(left, right, method="hopfield")
    table: F32 = m.to_array()
    strong: sv.Matches = m[m.score > 0.5]
    xyz: F32 = strong.to_points(calib)
    csv: Path = m.save_csv(out / "matches.csv")
    back: sv.Matches = sv.Matches.from_csv(csv, image_shape=m.image_shape)
    dispx: F32 = m.dispx
    released: int = sv.release_memory()
    return {
        "disparity_px": float(np.nanmedian(disparity)),
        "depth_m": float(np.nanmedian(depth)),
        "sigma_m": float(np.nanmedian(sigma)),
        "points": float(len(points)),
        "colors": float(len(colors)),
        "image_points": float(np.isfinite(image[..., 2]).sum()),
        "near_points": float(len(near.points)),
        "files": float(ply.stat().st_size > 0 and png.stat().st_size > 0),
        "step_5m": step,
        "steps": float(steps.sum()),
        "matches": float(len(table)),
        "strong_xyz": float(len(xyz)),
        "read_back": float(len(back)),
        "dispx": float(np.isfinite(dispx).sum()),
        "released": float(released >= 0),
    }
