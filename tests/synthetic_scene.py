"""A small synthetic depth result with a known geometry, for the render / export / GUI tests.

A textured back wall at ``WALL_Z`` metres with a box face at ``BOX_Z`` metres in front of its
centre (a depth discontinuity all around the box), a hole of NaN in the top-left corner, seen by
a rectified rig with focal ``F`` px and baseline ``B`` m.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stereovision.calibration import Calibration
from stereovision.depth import DepthResult

W, H = 160, 120
F = 150.0
CX, CY = 79.5, 59.5
B = 0.1
WALL_Z = 4.0
BOX_Z = 2.0
BOX = (slice(40, 80), slice(50, 110))  # rows, columns of the box face
HOLE = (slice(0, 10), slice(0, 10))


def calibration() -> Calibration:
    """Rectified calibration of the synthetic rig (metres)."""
    k = np.array([[F, 0.0, CX], [0.0, F, CY], [0.0, 0.0, 1.0]])
    return Calibration(
        K1=k,
        D1=np.zeros(5),
        K2=k.copy(),
        D2=np.zeros(5),
        R=np.eye(3),
        T=np.array([-B, 0.0, 0.0]),
        image_size=(W, H),
        unit="m",
        rectified=True,
    )


def left_image(seed: int = 0) -> np.ndarray:
    """BGR uint8 texture: coloured 10 px checkerboard with a little noise."""
    rng = np.random.default_rng(seed)
    ys, xs = np.mgrid[0:H, 0:W]
    check = ((xs // 10 + ys // 10) % 2).astype(np.float64)
    img = np.stack([60 + 150 * check, 90 + 100 * (1 - check), 40 + 180 * (xs / W)], axis=-1)
    img += rng.normal(0, 4, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def depth_result(seed: int = 0) -> DepthResult:
    """The synthetic scene as a :class:`DepthResult` (metres, left rectified frame)."""
    z = np.full((H, W), WALL_Z, dtype=np.float64)
    z[BOX] = BOX_Z
    z[HOLE] = np.nan
    disp = (F * B / z).astype(np.float32)
    ys, xs = np.mgrid[0:H, 0:W]
    xyz = np.stack([(xs - CX) * z / F, (ys - CY) * z / F, z], axis=-1).astype(np.float32)
    ok = np.isfinite(z)
    yy, xx = np.nonzero(ok)
    left = left_image(seed)
    return DepthResult(
        disparity=disp,
        confidence=np.where(ok, 1.0, 0.0).astype(np.float32),
        depth=z.astype(np.float32),
        points=np.ascontiguousarray(xyz[yy, xx]),
        colors=np.ascontiguousarray(left[yy, xx, ::-1]),
        pixels=np.stack([xx, yy], axis=1).astype(np.int32),
        method="gabor",
        max_disparity=16,
        calibration=calibration(),
        left_rectified=left,
    )


def narrow_scene(folder: Path, height: int = 3, width: int = 8) -> Path:
    """A scene folder ``folder/tiny`` (left.png, right.png 2 px apart, gt_disp.pfm of 2 px)
    of ``width`` px: too narrow for evaluation.md's range of 16 px at least."""
    import cv2

    from stereovision.io import write_pfm

    rng = np.random.default_rng(0)
    row = (rng.random((height, width + 2)) * 255).astype(np.uint8)
    scene = folder / "tiny"
    scene.mkdir()
    cv2.imwrite(str(scene / "left.png"), row[:, :width])
    cv2.imwrite(str(scene / "right.png"), row[:, 2:])
    write_pfm(scene / "gt_disp.pfm", np.full((height, width), 2.0, np.float32))
    return scene
