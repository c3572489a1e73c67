"""What ``stereovision depth -o DIR`` writes holds the returned DepthResult's values."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from stereovision.calibration import Calibration
from stereovision.cli import depth_outputs
from stereovision.io import read_pfm, read_ply


def test_depth_files_hold_the_results_values(data_dir: Path, tmp_path: Path) -> None:
    """On a real metric scene: disparity.pfm and depth.npy bit for bit (NaN where none),
    depth_mm.png to the millimetre (0 where none), cloud.ply the result's points and colours
    in its order, disparity.png black exactly where there is no disparity."""
    scene = data_dir / "eth3d" / "terrace"
    left, right = cv2.imread(str(scene / "left.png")), cv2.imread(str(scene / "right.png"))
    calib = Calibration.from_file(scene / "calib.txt")
    res, written = depth_outputs(left, right, calib, tmp_path, method="gabor", max_disparity=32)
    assert res.depth is not None and 0.5 < res.density < 1.0  # holes: NaN must round-trip
    disp = read_pfm(written["disparity.pfm"])
    np.testing.assert_array_equal(disp, res.disparity)  # NaN in the same places
    depth = np.load(written["depth.npy"])
    assert depth.dtype == np.float32
    np.testing.assert_array_equal(depth, res.depth)
    mm = cv2.imread(str(written["depth_mm.png"]), cv2.IMREAD_UNCHANGED)
    assert mm.dtype == np.uint16 and mm.shape == res.depth.shape
    known = np.isfinite(res.depth)
    np.testing.assert_array_equal(mm > 0, known)  # every depth of terrace is below 65.535 m
    assert np.abs(mm[known] / 1000.0 - res.depth[known]).max() <= 0.0005 + 1e-6
    pts, colors = read_ply(written["cloud.ply"])
    assert len(pts) == len(res.points) == known.sum()
    np.testing.assert_allclose(pts, res.points, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(colors, res.colors)
    # each point is its pixel's depth, along the optical axis
    x, y = res.pixels[:, 0], res.pixels[:, 1]
    np.testing.assert_allclose(pts[:, 2], res.depth[y, x], rtol=1e-5)
    png = cv2.imread(str(written["disparity.png"]))
    assert png.shape == left.shape
    np.testing.assert_array_equal(png.max(axis=2) == 0, ~np.isfinite(res.disparity))


@pytest.mark.parametrize("name", ["disparity.pfm", "depth.npy"])
def test_depth_files_are_the_filtered_results(data_dir: Path, tmp_path: Path, name: str) -> None:
    """--max-depth: the written maps are the filtered result's, not the unfiltered one's."""
    scene = data_dir / "eth3d" / "terrace"
    left, right = cv2.imread(str(scene / "left.png")), cv2.imread(str(scene / "right.png"))
    calib = Calibration.from_file(scene / "calib.txt")
    res, written = depth_outputs(
        left, right, calib, tmp_path, method="fast", max_disparity=32, max_depth=4.0
    )
    assert res.depth is not None and np.nanmax(res.depth) <= 4.0
    got = read_pfm(written[name]) if name.endswith(".pfm") else np.load(written[name])
    want = res.disparity if name.endswith(".pfm") else res.depth
    np.testing.assert_array_equal(got, want)
    pts, _ = read_ply(written["cloud.ply"])
    assert len(pts) == len(res.points) and pts[:, 2].max() <= 4.0
