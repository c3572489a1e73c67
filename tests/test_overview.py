"""``overview.png`` (``depth``, ``demo``, ``batch``): its colour bars read the maps' values."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from stereovision.calibration import Calibration
from stereovision.cli import depth_outputs, main
from stereovision.io import read_pfm
from stereovision.overview import PANEL_WIDTH, overview_image, overview_title

_TURBO = cv2.applyColorMap(np.arange(256, dtype=np.uint8)[:, None], cv2.COLORMAP_TURBO)[:, 0]


def _level(bgr: np.ndarray) -> int:
    """The TURBO level (0-255) of a colour of the map (it must be one, within rounding)."""
    dist = np.abs(_TURBO.astype(int) - np.asarray(bgr, int)).sum(axis=1)
    assert dist.min() <= 3, bgr
    return int(dist.argmin())


@pytest.fixture(scope="module")
def terrace_run(data_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple:
    scene = data_dir / "eth3d" / "terrace"
    left = cv2.imread(str(scene / "left.png"))
    right = cv2.imread(str(scene / "right.png"))
    out = tmp_path_factory.mktemp("overview")
    calib = Calibration.from_file(scene / "calib.txt")
    res, written = depth_outputs(
        left, right, calib, out, method="fast", max_disparity=32, name="terrace"
    )
    return left, res, written, out


def test_overview_bars_read_the_values_of_the_written_maps(terrace_run: tuple) -> None:
    """At each labelled tick the bar's colour is the one disparity.png / depth.png give that
    value (the depth one on its inverse): read back from the files, not from the code."""
    _, res, written, out = terrace_run
    img = cv2.imread(str(written["overview.png"]))
    ov = overview_image(res, overview_title("terrace", res))
    np.testing.assert_array_equal(img, ov.image)  # the file is this picture
    disp = read_pfm(out / "disparity.pfm")
    depth = np.load(out / "depth.npy")
    inv = 1.0 / depth[np.isfinite(depth)]
    ends = {
        "disparity": (0.0, float(np.percentile(disp[np.isfinite(disp)], 99)), lambda v: v),
        "depth": (float(np.percentile(inv, 1)), float(np.percentile(inv, 99)), lambda z: 1 / z),
        "confidence": (0.0, 1.0, lambda v: v),
    }
    depth_png = cv2.imread(str(out / "depth.png"))
    for name, (lo, hi, mapped) in ends.items():
        bar = ov.bars[name]
        assert len(bar.ticks) >= 3, (name, bar.ticks)
        x = bar.box[0] + bar.box[2] // 2
        for value, label, y in bar.ticks:
            assert float(label) == pytest.approx(value, rel=1e-3)
            want = (mapped(value) - lo) * 255.0 / (hi - lo)
            assert abs(_level(img[y, x]) - want) <= 1.5, (name, label, want)
            if name == "depth":
                # the depth.png pixels of that colour lie at that depth (within a colour step)
                level = _level(img[y, x])
                same = np.all(depth_png == _TURBO[level], axis=2) & np.isfinite(depth)
                assert same.sum() > 20, label
                step = (hi - lo) / 255.0
                z = np.median(depth[same])
                assert 1 / (1 / value + 2 * step) <= z <= 1 / (1 / value - 2 * step), (label, z)
    assert ov.bars["disparity"].ticks[-1][0] == 0.0  # 0 px at the bottom
    assert "depth (m)" not in ov.title and ov.title == (
        f"terrace | fast | max_disparity 32 px | density {100 * res.density:.1f} %"
    )


def test_overview_left_panel_is_the_input_downscaled(terrace_run: tuple) -> None:
    left, res, written, _ = terrace_run
    img = cv2.imread(str(written["overview.png"]))
    ov = overview_image(res, "t")
    x, y, w, h = ov.panels["left"]
    assert ov.scale == PANEL_WIDTH / left.shape[1] and w == PANEL_WIDTH
    assert h == round(left.shape[0] * ov.scale)
    small = cv2.resize(left, (w, h), interpolation=cv2.INTER_AREA)
    np.testing.assert_array_equal(img[y : y + h, x : x + w], small)
    # the maps' panels beside it are as large, and disparity.png / depth.png keep the input size
    assert ov.panels["disparity"][2:] == ov.panels["depth"][2:] == (w, h)
    for name in ("disparity.png", "depth.png"):
        assert cv2.imread(str(written[name])).shape == left.shape


def test_overview_is_an_output_of_depth_and_demo(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Listed in the manifest (a rerun replaces it) and refused as a user's file."""
    scene = data_dir / "middlebury2001" / "tsukuba"
    out = tmp_path / "o"
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png"), "--method", "fast"]
    argv += ["--max-disparity", "16", "-o", str(out)]
    assert main(argv) == 0
    assert "overview.png" in json.loads((out / ".stereovision-depth.json").read_text())
    img = cv2.imread(str(out / "overview.png"))
    assert img is not None and img.shape[1] > 2 * 384  # two panels of 384 px side by side
    assert main(argv) == 0  # its own file: replaced
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "overview.png").write_bytes(b"my picture")
    capsys.readouterr()
    assert main([*argv[:-1], str(mine)]) == 2
    assert "overview.png is not listed as an earlier run's output" in capsys.readouterr().err
    assert (mine / "overview.png").read_bytes() == b"my picture"
