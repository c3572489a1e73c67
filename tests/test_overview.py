"""``overview.png`` (``depth``, ``demo``, ``batch``): its colour bars read the maps' values."""

from __future__ import annotations

import itertools
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from stereovision.calibration import Calibration
from stereovision.cli import depth_outputs, main
from stereovision.io import read_pfm
from stereovision.overview import (
    PANEL_WIDTH,
    ColourBar,
    Overview,
    colour_levels,
    colour_range,
    overview_image,
    overview_title,
)

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
        assert len(bar.ticks) >= 4, (name, bar.ticks)
        x = bar.box[0] + bar.box[2] // 2
        # both ends are labelled (they were not: the range could not be read), with the unit
        top, bottom = (1 / hi, 1 / lo) if name == "depth" else (hi, lo)
        unit = {"disparity": " px", "depth": " m", "confidence": ""}[name]
        _check_ends(bar, top, bottom, unit)
        for value, label, y in bar.ticks:
            assert _number(label) == pytest.approx(value, rel=5e-3)
            want = (mapped(value) - lo) * 255.0 / (hi - lo)
            assert abs(_level(img[y, x]) - want) <= 1.5, (name, label, want)
            if name == "depth" and (value, label, y) not in (bar.ticks[0], bar.ticks[-1]):
                # (not the ends: their colours hold every depth beyond them too)
                # the depth.png pixels of that colour lie at that depth (within a colour step)
                level = _level(img[y, x])
                same = np.all(depth_png == _TURBO[level], axis=2) & np.isfinite(depth)
                assert same.sum() > 20, label
                step = (hi - lo) / 255.0
                z = np.median(depth[same])
                assert 1 / (1 / value + 2 * step) <= z <= 1 / (1 / value - 2 * step), (label, z)
    assert ov.bars["disparity"].ticks[-1][:2] == (0.0, "0 px")  # 0 px at the bottom
    assert ov.bars["confidence"].ticks[0][:2] == (1.0, "1")
    assert "depth (m)" not in ov.title and ov.title == (
        f"terrace | fast | max_disparity 32 px | density {100 * res.density:.1f} %"
    )


def _number(label: str) -> float:
    """The number of a bar's label (``"52.2 px"``, ``"20"``)."""
    return float(label.split()[0])


def _check_ends(bar: ColourBar, top: float, bottom: float, unit: str) -> None:
    """The bar's first and last labels are at its top and bottom rows and say the colour
    range's ends as printed, with the unit; no inner label is closer to another than 16 px
    (one that would overlap an end is left out)."""
    _, y, _, h = bar.box
    (v0, label0, y0), (v1, label1, y1) = bar.ticks[0], bar.ticks[-1]
    assert (y0, y1) == (y, y + h - 1)
    assert (label0, label1) == (f"{top:.3g}{unit}", f"{bottom:.3g}{unit}")
    assert (v0, v1) == (pytest.approx(top, rel=1e-5), pytest.approx(bottom, rel=1e-5))
    rows = [t[2] for t in bar.ticks]
    assert all(b - a >= 16 for a, b in itertools.pairwise(rows)), rows


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


FT_PER_M = 3.28084  # 1 m in feet (1 ft = 0.3048 m)


def test_depth_unit_ft_labels_the_bar_and_the_summary_and_leaves_the_files(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``depth --unit ft``: overview.png's depth bar and the printed depths in feet, read back
    against depth.npy x 3.28084 (and the floor's lines against ground.json and scan.json);
    every other file byte for byte the metres run's, the overview's
    pictures too (only the bar's labels and the caption change)."""
    scene = data_dir / "eth3d" / "terrace"
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png"), "--calib"]
    argv += [str(scene / "calib.txt"), "--method", "fast", "--max-disparity", "32", "--ground"]
    outs = {}
    import stereovision.overview as overview_module

    drawn: list[Any] = []  # the results the runs drew: no file holds their confidence

    def recording(result: Any, title: str, unit: str = "m") -> Overview:
        drawn.append(result)
        return overview_image(result, title, unit)

    monkeypatch.setattr(overview_module, "overview_image", recording)
    for unit in ("m", "ft"):
        outs[unit] = tmp_path / unit
        extra = [] if unit == "m" else ["--unit", "ft"]
        capsys.readouterr()
        assert main([*argv, *extra, "-o", str(outs[unit])]) == 0
        lines = capsys.readouterr().out.splitlines()
        summary = next(line for line in lines if line.startswith("fast: "))
        # the floor's height and the nearest obstacle of the scan in the unit too
        scale = FT_PER_M if unit == "ft" else 1.0
        height = json.loads((outs[unit] / "ground.json").read_text())["height_m"] * scale
        assert lines[0].startswith(f"ground plane: camera {height:.3f} {unit} above it, pitch")
        ranges = json.loads((outs[unit] / "scan.json").read_text())["ranges"]
        nearest = min(r for r in ranges if isinstance(r, float)) * scale  # not None, "inf"
        scan = next(line for line in lines if line.startswith("scan: "))
        assert f", the nearest {nearest:.2f} {unit} away at " in scan
        depth = np.load(outs[unit] / "depth.npy")
        z = depth[np.isfinite(depth)] * scale
        lo, hi, mid = z.min(), z.max(), np.median(z)
        assert f", depth {lo:.3g}-{hi:.3g} {unit} (median {mid:.3g} {unit}), " in summary
    files = sorted(p.name for p in outs["m"].iterdir())
    assert files == sorted(p.name for p in outs["ft"].iterdir()) and "depth.npy" in files
    for name in files:
        if name != "overview.png":
            assert (outs["m"] / name).read_bytes() == (outs["ft"] / name).read_bytes(), name
    img_m = cv2.imread(str(outs["m"] / "overview.png"))
    img = cv2.imread(str(outs["ft"] / "overview.png"))
    depth = np.load(outs["ft"] / "depth.npy")
    res = _result_of(outs["ft"], depth, drawn[-1].confidence)
    ov = overview_image(res, overview_title("terrace/left.png", res), "ft")
    # the file's depth cell (caption, map, bar and labels) is this one's
    px, py, _, ph = ov.panels["depth"]
    cell = np.s_[py - 22 : py + ph, px : ov.bars["depth"].box[0] + 16 + 64]
    np.testing.assert_array_equal(img[cell], ov.image[cell])
    assert not np.array_equal(img[cell], img_m[cell])  # the labels are not the metres run's
    for x, y, w, h in ov.panels.values():  # the same pictures, the same colours
        np.testing.assert_array_equal(img[y : y + h, x : x + w], img_m[y : y + h, x : x + w])
    # the bar's labels are feet: each tick's colour is the one depth.png gives that many feet
    inv = 1.0 / (depth[np.isfinite(depth)] * FT_PER_M)
    lo, hi = float(np.percentile(inv, 1)), float(np.percentile(inv, 99))
    bar = ov.bars["depth"]
    assert len(bar.ticks) >= 4, bar.ticks
    _check_ends(bar, 1 / hi, 1 / lo, " ft")  # the near and far ends in feet
    x = bar.box[0] + bar.box[2] // 2
    depth_png = cv2.imread(str(outs["ft"] / "depth.png"))
    feet = depth * FT_PER_M
    for value, label, y in bar.ticks:
        assert _number(label) == pytest.approx(value, rel=5e-3)
        want = (1 / value - lo) * 255.0 / (hi - lo)
        assert abs(_level(img[y, x]) - want) <= 1.5, (label, want)
        if (value, label, y) in (bar.ticks[0], bar.ticks[-1]):
            continue  # the ends' colours hold every depth beyond them too
        same = np.all(depth_png == _TURBO[_level(img[y, x])], axis=2) & np.isfinite(depth)
        assert same.sum() > 20, label
        step = (hi - lo) / 255.0
        z = float(np.median(feet[same]))
        assert 1 / (1 / value + 2 * step) <= z <= 1 / (1 / value - 2 * step), (label, z)
    # in metres the labels were metres: the same tick colours would read 3.28 x smaller
    assert "depth (ft)" not in ov.title
    metres_ticks = overview_image(res, "t").bars["depth"].ticks
    assert [t[1] for t in metres_ticks] != [t[1] for t in bar.ticks]


def _result_of(out: Path, depth: np.ndarray, confidence: np.ndarray) -> object:
    """The run's DepthResult as its files hold it (disparity.pfm, depth.npy), for
    overview_image: the same maps the CLI drew; its ``confidence`` (0 where filled: the depth
    caption's reasons read it), which no file holds."""
    import stereovision as sv

    disp = read_pfm(out / "disparity.pfm")
    return sv.DepthResult(
        disparity=disp,
        confidence=confidence,
        depth=depth,
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
        method="fast",
        max_disparity=32,
    )


def test_depth_unit_unknown_is_one_line_and_exit_2(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = data_dir / "eth3d" / "terrace"
    argv = ["depth", str(scene / "left.png"), str(scene / "right.png"), "--unit", "feet"]
    capsys.readouterr()
    with pytest.raises(SystemExit) as stop:
        main([*argv, "-o", str(tmp_path / "o")])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    choices = "'m', 'mm', 'cm', 'ft', 'in'"
    assert f"argument --unit: invalid choice: 'feet' (choose from {choices})" in err
    assert not (tmp_path / "o").exists()
    with pytest.raises(ValueError, match=r"^unit: expected one of \['m', 'mm', 'cm', 'ft', 'in'\]"):
        overview_image(_result_without_depth(), "t", "feet")


def _result_without_depth() -> object:
    import stereovision as sv

    return sv.DepthResult(
        disparity=np.ones((4, 4), np.float32),
        confidence=np.ones((4, 4), np.float32),
        depth=None,
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
        method="fast",
        max_disparity=16,
    )


def test_the_depth_caption_says_where_there_is_depth(terrace_run: tuple) -> None:
    """The demo's depth panel had holes on 16 % of the pixels under a title saying "density
    100.0 %" (the disparity's): the depth caption gives the share with a depth and why the
    rest has none; a panel too narrow for the reason keeps the share."""
    _, res, _, _ = terrace_run
    share = 100 * float(np.isfinite(res.depth).mean())
    assert share < 95.0  # the fast map's filled pixels have no depth
    ov = overview_image(res, "terrace")
    assert ov.captions == {
        "left": "left image",
        "disparity": "disparity (px)",
        # 32492 filled pixels, and 16 measured ones within sigma_d of infinite depth
        "depth": f"depth (m) on {share:.1f} %, none where filled or too far to tell",
        "confidence": "confidence (0-1)",
    }
    small = res.filtered(max_depth=float(np.nanmax(res.depth)))  # the same depths, a copy
    small.disparity, small.confidence = res.disparity[:40, :60], res.confidence[:40, :60]
    small.depth, small.left_rectified = res.depth[:40, :60], None
    part = 100 * float(np.isfinite(small.depth).mean())
    assert overview_image(small, "t", "ft").captions["depth"] == f"depth (ft) on {part:.1f} %"


def _label_boxes(ov: Overview) -> list[tuple[str, str, tuple[int, int, int, int]]]:
    """``(bar, label, (x0, y0, x1, y1))`` of every bar label as drawn: 7 px right of its bar,
    its baseline 4 rows below its tick, as large as ``cv2.getTextSize`` says (0.4 HERSHEY)."""
    out = []
    for name, bar in ov.bars.items():
        x0 = bar.box[0] + bar.box[2] + 7
        for _, label, y in bar.ticks:
            (tw, th), base = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.4, 1)
            out.append((name, label, (x0, y + 4 - th, x0 + tw, y + 4 + base)))
    return out


def _result_with_depth(h: int, w: int, near: float, far: float) -> object:
    """A DepthResult ``h`` x ``w`` whose depths (metres) span ``near`` to ``far`` with 1 / Z
    uniform, 3 % of the pixels at each end: the depth bar's ends are ``near`` and ``far``."""
    import stereovision as sv

    rng = np.random.default_rng(0)
    inv = rng.uniform(1 / far, 1 / near, h * w)
    k = max(1, h * w * 3 // 100)
    inv[:k], inv[k : 2 * k] = 1 / near, 1 / far
    inv = rng.permutation(inv).reshape(h, w)
    return sv.DepthResult(
        disparity=(60 * inv).astype(np.float32),
        confidence=rng.uniform(0, 1, (h, w)).astype(np.float32),
        depth=(1 / inv).astype(np.float32),
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
        method="fast",
        max_disparity=64,
    )


def _kitti_gt_result(data_dir: Path) -> object:
    """KITTI 000005_10's ground-truth disparity and its depth (f B / d) as a DepthResult."""
    import stereovision as sv

    scene = data_dir / "kitti2015" / "000005_10"
    calib = Calibration.from_file(scene / "calib.txt")
    disp = read_pfm(scene / "gt_disp.pfm").astype(np.float32)
    disp[~(np.isfinite(disp) & (disp > 0))] = np.nan  # the pfm's inf: no ground truth
    return sv.DepthResult(
        disparity=disp,
        confidence=np.where(np.isfinite(disp), 1.0, 0.0).astype(np.float32),
        depth=(calib.focal_px * calib.baseline_m / disp).astype(np.float32),
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
        method="fast",
        max_disparity=192,
    )


def _check_labels_inside_their_cells(ov: Overview) -> None:
    """Every label box lies inside the picture and inside its cell: it ends at least the
    figure's 10 px margin before the picture's right edge and before any panel right of it
    (the label column was 64 px: '12500 mm' ran 2 px into the margin, '116123 mm' to 1 px
    of the next panel, '2000000 mm' over it); no two label boxes overlap."""
    height, width = ov.image.shape[:2]
    boxes = _label_boxes(ov)
    lefts = [x for x, _, _, _ in ov.panels.values()]
    for name, label, (x0, y0, x1, y1) in boxes:
        right = min([x - 10 for x in lefts if x > x0] + [width - 10])
        assert 0 <= y0 and y1 <= height and x1 <= right, (name, label, (x0, x1), right)
    for (n1, t1, a), (n2, t2, b) in itertools.combinations(boxes, 2):
        overlap = a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]
        assert not overlap, (n1, t1, a, n2, t2, b)


@pytest.mark.parametrize("unit", ["m", "mm", "cm", "ft", "in"])
def test_overview_long_labels_fit_their_column_kitti(data_dir: Path, unit: str) -> None:
    """KITTI's ground truth reaches 70 m: its depth bar's far end in mm is 6 characters and
    the unit; the label column is as wide as it, the metres figure as wide as before."""
    res = _kitti_gt_result(data_dir)
    ov = overview_image(res, "000005_10", unit)
    _check_labels_inside_their_cells(ov)
    _check_clear_of_the_ends(ov)
    widest = max(x1 - x0 for _, _, (x0, _, x1, _) in _label_boxes(ov))
    pw = ov.panels["left"][2]
    # 10 + 2 x (panel + 8 + bar 16 + label column + 10), the column 7 px + the widest label
    assert ov.image.shape[1] == 30 + 2 * (pw + 24 + max(64, 7 + widest))
    if unit == "m":
        assert ov.image.shape[1] == 30 + 2 * (pw + 24 + 64)
    far = ov.bars["depth"].ticks[-1][1]
    assert far.endswith(f" {unit}") and (unit != "mm" or len(far) >= len("12345 mm")), far


@pytest.mark.parametrize("unit", ["m", "mm", "cm", "ft", "in"])
@pytest.mark.parametrize("size", [(60, 80), (288, 384), (375, 1242)])
@pytest.mark.parametrize("ends", [(0.4, 3.0), (1.5, 12.5), (4.0, 116.0), (0.3, 2000.0)])
def test_overview_labels_inside_their_cells(
    unit: str, size: tuple[int, int], ends: tuple[float, float]
) -> None:
    ov = overview_image(_result_with_depth(*size, *ends), "t", unit)
    _check_labels_inside_their_cells(ov)
    _check_clear_of_the_ends(ov)
    # the ends are the depths given, in the unit
    from stereovision.calibration import UNIT_TO_METRES

    ticks = ov.bars["depth"].ticks
    near, far = (e / UNIT_TO_METRES[unit] for e in ends)
    assert (ticks[0][0], ticks[-1][0]) == (
        pytest.approx(near, rel=1e-3),
        pytest.approx(far, rel=1e-3),
    )


def _check_clear_of_the_ends(ov: Overview) -> None:
    """Between each end's label box and its neighbour's, 6 blank rows at least (8 between the
    inks, about a digit's height)."""
    boxes = _label_boxes(ov)
    for name in ov.bars:
        rows = [box for bar, _, box in boxes if bar == name]
        labels = [label for bar, label, _ in boxes if bar == name]
        if len(rows) < 3:
            continue
        assert rows[1][1] - rows[0][3] >= 6, (name, labels[:2], rows[:2])
        assert rows[-1][1] - rows[-2][3] >= 6, (name, labels[-2:], rows[-2:])


def test_overview_inner_label_next_to_an_end_is_left_out() -> None:
    """The demo's depth bar (cones, 2.17-6.5 m, 375 rows) had "6" 16 rows over "6.5 m": 4 blank
    rows between their boxes, read as one label; it is left out, the others stay where they
    were."""
    ov = overview_image(_result_with_depth(375, 450, 2.17, 6.5), "t")
    bar = ov.bars["depth"]
    ticks = [(label, y - bar.box[1]) for _, label, y in bar.ticks]
    assert ticks == [("2.17 m", 0), ("3", 155), ("4", 257), ("5", 318), ("6.5 m", 374)]
    _check_clear_of_the_ends(ov)
    # the disparity and confidence bars' ticks are where they were (no label near an end)
    assert [t[1] for t in ov.bars["confidence"].ticks] == ["1", "0.8", "0.6", "0.4", "0.2", "0"]


def test_colour_levels_of_infinities_without_an_overflow() -> None:
    """KITTI's gt_disp.pfm stores "no ground truth" as inf: it became float32's largest value
    and the scaling overflowed (a RuntimeWarning); the levels are the same, warning-free."""
    import warnings

    from stereovision.overview import colour_levels

    values = np.array([np.inf, -np.inf, np.nan, 1.0, 3.0, 2.0], np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        levels = colour_levels(values, 1.0, 3.0)
    assert levels.tolist() == [255, 0, 0, 0, 255, 127]
    # finite float32 values further apart than float32's largest: the difference overflowed
    # (a RuntimeWarning, said as a 'warning:' line by the CLI's colorize)
    wide = np.array([-3e38, 0.0, 3e38], np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert colour_levels(wide, -3e38, 3e38).tolist() == [0, 127, 255]


def test_the_depth_caption_names_the_limits_and_no_fill_it_did_not_make(terrace_run: tuple) -> None:
    """The caption said "none where filled" whatever made the holes: with --max-depth most of
    the depth panel's holes are the depths cut beyond it (not filled pixels), and a map with
    nothing filled (the Gabor channel's) has no filled pixels to blame. The reason names the
    limits when the result has them, and is left out when nothing was filled."""
    import dataclasses

    _, res, _, _ = terrace_run
    near = res.filtered(max_depth=float(np.nanmedian(res.depth)))
    share = 100 * float(np.isfinite(near.depth).mean())
    assert share < 60.0
    # the 16 measured pixels without a depth before the cut are told from the 138,464 it cut
    assert overview_image(near, "terrace").captions["depth"] == (
        f"depth (m) on {share:.1f} %, none where filled, beyond the limits or too far to tell"
    )
    # a max_depth that cut nothing: "beyond the limits" was said of those 16 pixels alone
    far = res.filtered(max_depth=1e6)
    share = 100 * float(np.isfinite(far.depth).mean())
    assert overview_image(far, "terrace").captions["depth"] == (
        f"depth (m) on {share:.1f} %, none where filled or too far to tell"
    )
    # the Gabor channel's: holes where the disparity has none, every measured pixel a depth
    unfilled = dataclasses.replace(
        res,
        disparity=np.where(np.isfinite(res.depth), res.disparity, np.float32(np.nan)),
        confidence=np.ones_like(res.confidence),
    )
    share = 100 * float(np.isfinite(res.depth).mean())
    assert overview_image(unfilled, "terrace").captions["depth"] == f"depth (m) on {share:.1f} %"


def test_depth_of_a_pair_in_a_non_utf8_folder_writes_its_overview(
    data_dir: Path, tmp_path: Path
) -> None:
    """A folder name with a byte that is not UTF-8 (a lone surrogate in the title) crashed
    ``cv2.getTextSize`` with a segmentation fault (exit -11, no output); the title draws it as
    ``?``. In a subprocess: the old crash would take pytest down with it."""
    scene = data_dir / "middlebury2001" / "tsukuba"
    folder = os.fsencode(tmp_path) + b"/pair\xff"
    os.mkdir(folder)
    for side in ("left", "right"):
        with open(folder + f"/{side}.png".encode(), "wb") as f:
            f.write((scene / f"{side}.png").read_bytes())
    out = tmp_path / "o"
    pair = [os.fsdecode(folder + b"/left.png"), os.fsdecode(folder + b"/right.png")]
    argv = ["depth", *pair, "--method", "fast", "--max-disparity", "16", "-o", str(out)]
    proc = subprocess.run(
        [sys.executable, "-m", "stereovision", *argv],
        capture_output=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr.decode(errors="replace")
    img = cv2.imread(str(out / "overview.png"))
    assert img is not None and img.shape[1] > 2 * 384


def test_overview_title_outside_ascii_is_drawn_as_question_marks(terrace_run: tuple) -> None:
    """The title keeps its ASCII and shows every other character as one ``?``."""
    picture = overview_image(terrace_run[1], "caf\u00e9 | x")
    assert picture.title == "caf? | x"


def _boxes_overlap(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


@pytest.mark.parametrize("width", [1, 2, 8, 17, 33, 64, 99, 120, 230, 300])
@pytest.mark.parametrize("unit", ["m", "mm"])
def test_overview_captions_clear_of_the_bar_labels_on_narrow_images(width: int, unit: str) -> None:
    """Under about 120 px wide the captions ("disparity (px)", "confidence (0-1)", the depth's)
    reach over their bar's label column and were drawn over its top label ("52.3 px"); a
    caption box (``cv2.getTextSize``, where the caption's ink is) overlaps no label box, no
    panel and no other caption, and lies inside the picture, the depth's with the units'."""
    res = _result_with_depth(24, width, 0.5, 4.0)
    res.confidence[:, : max(1, width // 3)] = 0.0  # filled: "none where filled" when it fits
    res.depth[:, : max(1, width // 3)] = np.nan
    ov = overview_image(res, "t", unit)
    img_w = ov.image.shape[1]
    assert set(ov.caption_boxes) == set(ov.captions) == set(ov.panels)
    labels = _label_boxes(ov)
    for name, box in ov.caption_boxes.items():
        (tw, th), base = cv2.getTextSize(ov.captions[name], cv2.FONT_HERSHEY_SIMPLEX, 0.5, 1)
        assert (box[2] - box[0], box[3] - box[1]) == (tw, th + base)
        assert 0 <= box[0] and box[2] <= img_w - 10 and 34 <= box[1], (name, box, img_w)
        ink = ov.image[box[1] : box[3], box[0] : box[2]].max(axis=2) > 200
        assert ink.any(), name  # the caption is drawn there
        for bar, label, lbox in labels:
            assert not _boxes_overlap(box, lbox), (name, box, bar, label, lbox)
        for panel, (x, y, pw, ph) in ov.panels.items():
            assert not _boxes_overlap(box, (x, y, x + pw, y + ph)), (name, panel)
        for other, obox in ov.caption_boxes.items():
            assert other == name or not _boxes_overlap(box, obox), (name, other)
    _check_labels_inside_their_cells(ov)


def _small_result(h: int, w: int) -> object:
    """A DepthResult ``h`` x ``w`` with disparities 1-40 px, its depth 40 / d m and a hole
    (NaN disparity and depth, confidence 0.7) in its top-left quarter."""
    import stereovision as sv

    rng = np.random.default_rng(5)
    disp = rng.uniform(1, 40, (h, w)).astype(np.float32)
    disp[: h // 2, : w // 2] = np.nan
    conf = rng.uniform(0, 1, (h, w)).astype(np.float32)
    conf[: h // 2, : w // 2] = 0.7
    return sv.DepthResult(
        disparity=disp,
        confidence=conf,
        depth=(40.0 / disp).astype(np.float32),
        points=np.zeros((0, 3), np.float32),
        colors=np.zeros((0, 3), np.uint8),
        pixels=np.zeros((0, 2), np.int32),
        method="fast",
        max_disparity=64,
    )


def test_map_panels_are_black_without_a_value_and_turbo_elsewhere() -> None:
    """A mutation audit found nothing asserting the maps' panels: the pixels without a
    disparity are black in the disparity, depth and confidence panels (the confidence of a
    pixel without a disparity is not shown), and a map downscaled to the panel keeps only
    colours of the map (nearest, not a blend that lies on no bar)."""
    res = _small_result(40, 2 * PANEL_WIDTH)
    ov = overview_image(res, "t")
    assert ov.scale == 0.5
    turbo = {tuple(c) for c in _TURBO.tolist()}
    for name in ("disparity", "depth", "confidence"):
        x, y, w, h = ov.panels[name]
        panel = ov.image[y : y + h, x : x + w]
        assert not panel[: h // 2, : w // 2].any(), name  # the hole: black
        rest = panel[h // 2 :].reshape(-1, 3)
        assert all(tuple(c) in turbo for c in rest.tolist()), name


def test_a_grey_left_image_is_drawn_grey() -> None:
    res = _small_result(30, 40)
    res.left_rectified = np.arange(30 * 40, dtype=np.uint32).reshape(30, 40).astype(np.uint8)
    ov = overview_image(res, "t")
    x, y, w, h = ov.panels["left"]
    drawn = ov.image[y : y + h, x : x + w]
    np.testing.assert_array_equal(drawn, np.repeat(res.left_rectified[:, :, None], 3, axis=2))


@pytest.mark.parametrize("channels", [None, 1, 3, 4])
def test_grey_bgr_and_bgra_left_images_are_drawn_as_bgr(channels: int | None) -> None:
    """A hand-made result whose left image was (H, W, 1) or BGRA failed with NumPy's "could
    not broadcast" (the panel has 3 channels): grey ones are drawn grey, BGR and BGRA ones
    as their BGR, alpha left out."""
    res = _small_result(30, 40)
    rng = np.random.default_rng(7)
    bgr = rng.integers(0, 256, (30, 40, 3), dtype=np.uint8)
    if channels is None:
        grey = bgr[:, :, 0].copy()
        res.left_rectified, expected = grey, np.repeat(grey[:, :, None], 3, axis=2)
    elif channels == 1:
        grey = bgr[:, :, :1].copy()
        res.left_rectified, expected = grey, np.repeat(grey, 3, axis=2)
    elif channels == 3:
        res.left_rectified, expected = bgr, bgr
    else:
        alpha = rng.integers(0, 256, (30, 40, 1), dtype=np.uint8)
        res.left_rectified, expected = np.concatenate([bgr, alpha], axis=2), bgr
    ov = overview_image(res, "t")
    x, y, w, h = ov.panels["left"]
    np.testing.assert_array_equal(ov.image[y : y + h, x : x + w], expected)


@pytest.mark.parametrize(
    ("disparity", "left", "match"),
    [
        (
            (0, 0),
            (0, 0, 3),
            r"^result: expected a \(H, W\) disparity map with pixels, got shape \(0, 0\)$",
        ),
        ((0, 40), None, r"disparity map with pixels, got shape \(0, 40\)$"),
        ((30, 40, 2), None, r"disparity map with pixels, got shape \(30, 40, 2\)$"),
        (
            (30, 40),
            (30, 40, 2),
            r"^result: expected a grey .* BGRA left image, got shape \(30, 40, 2\)$",
        ),
        ((30, 40), (0, 0, 3), r"BGRA left image, got shape \(0, 0, 3\)$"),
        ((30, 40), (30,), r"BGRA left image, got shape \(30,\)$"),
    ],
)
def test_an_empty_result_or_a_left_image_of_other_channels_is_a_value_error(
    disparity: tuple[int, ...], left: tuple[int, ...] | None, match: str
) -> None:
    """A 0x0 result divided by its width (ZeroDivisionError); a left image of 2 channels or
    none was NumPy's broadcast error or OpenCV's: each is a ValueError naming the shape."""
    res = _small_result(30, 40)
    res.disparity = np.zeros(disparity, np.float32)
    res.confidence = np.zeros(disparity, np.float32)
    res.depth = None
    res.left_rectified = None if left is None else np.zeros(left, np.uint8)
    with pytest.raises(ValueError, match=match):
        overview_image(res, "t")


@pytest.mark.parametrize(
    ("dtype", "value"), [(np.uint16, 1000), (np.float32, 0.5), (np.float64, 200.0), (bool, True)]
)
def test_a_left_image_that_is_not_uint8_is_a_value_error(dtype: Any, value: Any) -> None:
    """The left panel is uint8: a hand-made uint16 left image of 1000 was drawn as 232 (wrapped
    modulo 256), a float one of 0.5 black, without a word; each is a ValueError naming it."""
    res = _small_result(30, 40)
    res.left_rectified = np.full((30, 40, 3), value, dtype)
    with pytest.raises(
        ValueError, match=rf"^result: expected a uint8 left image, got {np.dtype(dtype)}$"
    ):
        overview_image(res, "t")


def test_holes_of_the_disparity_are_not_called_filled() -> None:
    """The depth's "none where filled" is for pixels with a disparity (confidence 0) but no
    depth; where the disparity itself is missing nothing was filled."""
    res = _small_result(30, 300)  # wide enough for the reason in the caption
    res.confidence[:15, :150] = 0.0  # no disparity there: not a filled pixel
    share = 100 * float(np.isfinite(res.depth).mean())
    assert overview_image(res, "t").captions["depth"] == f"depth (m) on {share:.1f} %"


def test_measured_pixels_without_a_depth_are_called_too_far_to_tell() -> None:
    """A measured disparity not above its sigma_d gets no depth (its one-sigma interval reaches
    infinity: 5449 px of playground's gabor map, 12582 of its fast one); the caption gave the
    share alone or blamed the fill for them. They are named; with limits, as before."""
    res = _small_result(30, 500)  # wide enough for both reasons in the caption
    res.depth[20:, 200:] = np.nan  # measured (confidence > 0), no depth
    share = 100 * float(np.isfinite(res.depth).mean())
    assert overview_image(res, "t").captions["depth"] == (
        f"depth (m) on {share:.1f} %, none where too far to tell"
    )
    res.confidence[20:, 350:] = 0.0  # part of them filled
    assert overview_image(res, "t").captions["depth"] == (
        f"depth (m) on {share:.1f} %, none where filled or too far to tell"
    )
    res.limits = {"max_depth": 30.0}  # a filtered result's measured holes: one reason
    assert overview_image(res, "t").captions["depth"] == (
        f"depth (m) on {share:.1f} %, none where filled or beyond the limits"
    )


def test_a_unit_that_is_not_a_string_is_a_value_error() -> None:
    with pytest.raises(ValueError, match=r"^unit: expected one of"):
        overview_image(_small_result(8, 8), "t", ["m"])  # type: ignore[arg-type]


@pytest.mark.parametrize(("rows", "labels"), [(16, 1), (17, 2)])
def test_a_bar_labels_its_bottom_end_from_17_rows(rows: int, labels: int) -> None:
    """Two labels 16 rows apart are far enough (as for the inner ticks): a bar of 17 rows
    labels both ends, one of 16 its top only."""
    ov = overview_image(_small_result(rows, 40), "t")
    for bar in ov.bars.values():
        assert len(bar.ticks) == labels, bar.ticks


def test_bar_runs_from_level_255_at_its_top_to_0_at_its_bottom() -> None:
    ov = overview_image(_small_result(60, 80), "t")
    for bar in ov.bars.values():
        x, y, w, h = bar.box
        assert _level(ov.image[y, x + w // 2]) == 255
        assert _level(ov.image[y + h - 1, x + w // 2]) == 0


def test_end_labels_just_under_1000_are_not_written_in_exponent() -> None:
    """A depth bar's near end of 999.6 mm was labelled "1e+03 mm" (``.3g`` rounds it to 1000,
    written with an exponent); it reads "1000 mm", as 1000 mm does."""
    for near in (0.9996, 1.0):
        ov = overview_image(_result_with_depth(60, 80, near, 3.0), "t", "mm")
        assert ov.bars["depth"].ticks[0][1] == "1000 mm"
    ov = overview_image(_result_with_depth(60, 80, 0.9994, 3.0), "t", "mm")
    assert ov.bars["depth"].ticks[0][1] == "999 mm"


def test_bar_labels_of_a_far_depth_are_in_exponent_form() -> None:
    """A depth map of ~0 px disparities (3e38 m) was labelled with all 39 digits of 3e38, a
    label column that made the overview (446 px wide) 906 px wide; 1e9 and up are now
    written as ``3e+38``, a depth under a billion as before."""
    ov = overview_image(_result_with_depth(30, 40, 1e38, 3e38), "t")
    assert [t[1] for t in ov.bars["depth"].ticks] == ["1e+38 m", "3e+38 m"]
    near = overview_image(_result_with_depth(30, 40, 1e6, 3e6), "t")
    assert [t[1] for t in near.bars["depth"].ticks] == ["1000000 m", "3000000 m"]
    assert ov.image.shape == near.image.shape


@pytest.mark.parametrize("length", [60, 200])
def test_a_long_title_is_scaled_into_the_picture(length: int) -> None:
    """200 x's scaled by the ratio of the widths still ran out of the picture (cv2 rounds
    each glyph's advance: 401 px in 308); the title is measured again until it fits."""
    ov = overview_image(_small_result(20, 20), "x" * length)
    width = ov.image.shape[1]
    title_rows = ov.image[:34].max(axis=2) > 40  # the background is (40, 40, 40)
    assert title_rows[:, : width // 2].any() and not title_rows[:, width - 10 :].any()


def test_infinite_depths_leave_the_depth_bar_alone() -> None:
    """Infinite depths (a disparity of 0) have no colour on the depth bar: its ends are those
    of the finite depths."""
    res = _result_with_depth(60, 80, 0.5, 4.0)
    before = overview_image(res, "t").bars["depth"].ticks
    res.depth[:10] = np.inf
    after = overview_image(res, "t").bars["depth"].ticks
    assert (after[0][1], after[-1][1]) == (before[0][1], before[-1][1]) == ("0.5 m", "4 m")


@pytest.mark.parametrize("width", [1, 8, 33, 64])
def test_a_caption_over_the_label_column_keeps_3_rows_above_the_top_label(width: int) -> None:
    """_CAPTION_GAP: where a caption reaches over its bar's label column, 3 blank rows at least
    separate its box from the top label's (boxes of ``cv2.getTextSize``)."""
    ov = overview_image(_result_with_depth(24, width, 0.5, 4.0), "t")
    tops = {name: box for name, _, box in reversed(_label_boxes(ov))}  # the first of each bar
    reaching = 0
    for name, (_, _, x1, y1) in ov.caption_boxes.items():
        if name in tops and x1 > tops[name][0]:
            reaching += 1
            assert tops[name][1] - y1 >= 3, (name, ov.caption_boxes[name], tops[name])
    assert reaching >= 1


def test_colour_levels_clip_values_beyond_the_ends() -> None:
    """A value below the colour range's low end is level 0, one above its high end 255 (as
    ``colorize`` draws them): unclipped, -5 and 20 of 0-10 wrapped round in uint8."""
    from stereovision.overview import colour_levels

    got = colour_levels(np.array([-5.0, 0.0, 5.0, 10.0, 20.0]), 0.0, 10.0)
    np.testing.assert_array_equal(got, [0, 0, 127, 255, 255])


def test_depth_ticks_are_even_steps_within_a_decade_and_1_2_5_beyond() -> None:
    """Depths of 1.5-12.5 m (under a decade) are labelled in even steps (2, 4, 6, 8 m); those
    of 0.3-60 m in 1-2-5 steps of each decade, the 2s included."""
    from stereovision.overview import _nice_values

    ov = overview_image(_result_with_depth(288, 384, 1.5, 12.5), "t")
    assert [t[1] for t in ov.bars["depth"].ticks] == ["1.5 m", "2", "4", "6", "8", "12.5 m"]
    assert _nice_values(0.3, 60.0) == [0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0]


def test_tick_values_include_ends_that_are_round_values() -> None:
    """A range's end that is itself a round value is one of its ticks: 1-2-5 steps of 1 to
    10 m are 1, 2, 5 and 10 (the 1 was left out), even steps of 0-10 run up to 10 (the 10
    was left out)."""
    from stereovision.overview import _linear_ticks, _nice_values

    assert _nice_values(1.0, 10.0) == [1.0, 2.0, 5.0, 10.0]
    assert _linear_ticks(0.0, 10.0) == [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]


def test_a_tall_image_narrower_than_a_panel_is_not_downscaled() -> None:
    """PANEL_WIDTH bounds the panels' width: a portrait image 400 px wide and 700 tall is
    shown at full size (scaling its height to 640 shrank it to 366 x 640)."""
    ov = overview_image(_small_result(700, 400), "t")
    assert ov.scale == 1.0
    assert ov.panels["left"][2:] == (400, 700)


def test_a_map_without_any_value_has_no_colour_bar() -> None:
    """A pair matched nowhere: its maps are black and carry no colour bar (there is no range
    to label; a 0-1 bar was drawn beside the empty disparity map)."""
    res = _small_result(40, 60)
    res.disparity[:] = np.nan
    res.depth[:] = np.nan
    ov = overview_image(res, "t")
    assert ov.bars == {}
    for name in ("disparity", "depth", "confidence"):
        x, y, w, h = ov.panels[name]
        assert not ov.image[y : y + h, x : x + w].any()


def test_the_depth_caption_drops_its_reason_only_where_it_would_reach_the_labels() -> None:
    """The reasons for the depth holes are left out of the caption exactly when the whole
    caption would reach over the bar's label column (left of it, they stay)."""
    full = "depth (m) on 97.5 %, none where filled"
    text_w = cv2.getTextSize(full, cv2.FONT_HERSHEY_SIMPLEX, 0.5, 1)[0][0]
    reach = 8 + 16 + 7  # bar gap, bar, label offset right of the panel
    for width, caption in ((text_w - reach, full), (text_w - reach - 20, full.split(",")[0])):
        res = _small_result(40, width)
        res.disparity[np.isnan(res.disparity)] = 5.0  # no hole but the filled row
        res.depth[:] = 40.0 / res.disparity
        res.depth[0] = np.nan  # one row of 40 filled: a disparity, confidence 0, no depth
        res.confidence[0] = 0.0
        assert overview_image(res, "t").captions["depth"] == caption


@pytest.mark.parametrize("unit", ["m", "mm"])
def test_the_depth_bar_names_its_far_end_past_a_million_metres(unit: str) -> None:
    """The bar's bottom row has depth.png's colour of its far end, 1 / (1st percentile of 1 / Z):
    it was labelled min(that, 1e6 m), so depths of 1e2 to 5e7 m (a disparity near 0 on a
    long baseline) had a bar from "100 m" down to "1000000 m" where depth.png's blue was
    5e7 m, and depths of 2e6 to 3e7 m a far end nearer than its near end."""
    from stereovision.calibration import UNIT_TO_METRES

    size = UNIT_TO_METRES[unit]
    for near, far in ((100.0, 5e7), (2e6, 3e7)):
        ov = overview_image(_result_with_depth(60, 80, near, far), "t", unit)
        ticks = ov.bars["depth"].ticks
        assert (ticks[0][0], ticks[-1][0]) == (
            pytest.approx(near / size, rel=1e-3),
            pytest.approx(far / size, rel=1e-3),
        )
        assert ticks[-1][1].endswith(f" {unit}")
        assert _number(ticks[-1][1]) == pytest.approx(far / size, rel=1e-3)
        _check_labels_inside_their_cells(ov)


def test_a_map_of_negative_disparities_is_coloured_by_its_values() -> None:
    """disparity.png is coloured from 0 px up to the 99th percentile: a map of negative
    disparities (a swapped pair's) had its top below its bottom, so every pixel took level 0
    (one colour) and its bar read upside down (-1.4 px at the top, 0 px at the bottom). Its
    ends are now its 1st and 99th percentiles, the lowest value blue, the highest red."""
    from stereovision.cli import colorize

    disparity = np.linspace(-40.0, -1.0, 100, dtype=np.float32).reshape(10, 10)
    lo, hi = colour_range(disparity, 0.0, None)
    assert (lo, hi) == pytest.approx(
        (float(np.percentile(disparity, 1)), float(np.percentile(disparity, 99)))
    )
    assert lo < hi
    levels = colour_levels(disparity, lo, hi).ravel()
    assert levels[0] == 0 and levels[-1] == 255 and np.all(np.diff(levels.astype(int)) >= 0)
    assert len({tuple(c) for c in colorize(disparity, lo=0.0).reshape(-1, 3)}) > 50
    # a map reaching above the given end keeps it, as before
    assert colour_range(np.array([[-5.0, 3.0, 10.0]]), 0.0, None)[0] == 0.0


def test_a_map_of_negative_disparities_with_a_few_positive_ones_is_coloured_by_its_values() -> None:
    """A map of negative disparities with 5 % of its pixels at +3 px (a swapped pair's, a few
    mismatches above 0) was coloured from the given 0 px to its 99th percentile: 95 % of it
    at level 0, two colours in disparity.png. More than half of the map below the given end
    takes its 1st and 99th percentiles, as a map wholly below 0 px does."""
    from stereovision.cli import colorize

    disparity = np.linspace(-40.0, -1.0, 10_000, dtype=np.float32)
    disparity[::20] = 3.0
    disparity = disparity.reshape(100, 100)
    lo, hi = colour_range(disparity, 0.0, None)
    assert (lo, hi) == pytest.approx(
        (float(np.percentile(disparity, 1)), float(np.percentile(disparity, 99)))
    )
    assert np.mean(colour_levels(disparity, lo, hi) == 0) < 0.02
    assert len({tuple(c) for c in colorize(disparity, lo=0.0).reshape(-1, 3)}) > 200
    # half of the map at or above the given end keeps it (a disparity map's few negative
    # sub-pixel values, or a half-empty one)
    assert colour_range(np.array([[-5.0, -4.0, 0.0, 10.0]]), 0.0, None)[0] == 0.0
    assert colour_range(np.array([[-5.0, -4.0, -3.0, 10.0]]), 0.0, None)[0] < 0.0


@pytest.mark.parametrize("title", ["night run\nleft.png | fast", "night\trun\x00left.png | fast"])
def test_a_title_with_a_newline_or_a_nul_stays_on_its_line(title: str) -> None:
    """cv2.putText started a second line at a newline (a folder name's) over the captions
    under the title, which cv2.getTextSize did not measure, and ended the text at a NUL.
    Control characters are drawn as '?', as non-ASCII ones are: one line, whole."""
    from types import SimpleNamespace

    from stereovision.overview import _TITLE_H, cv2_text

    disparity = np.tile(np.linspace(1.0, 40.0, 200, dtype=np.float32), (120, 1))
    result = SimpleNamespace(
        disparity=disparity, depth=None, confidence=np.ones_like(disparity), left_rectified=None
    )
    shown = title.replace("\n", "?").replace("\t", "?").replace("\x00", "?")
    assert cv2_text(title) == shown
    ov = overview_image(result, title)
    plain = overview_image(result, shown)
    assert ov.title == shown
    np.testing.assert_array_equal(ov.image, plain.image)
    # below the title band, the picture of a one-word title
    one_word = overview_image(result, "x").image
    np.testing.assert_array_equal(ov.image[_TITLE_H:], one_word[_TITLE_H:])


@pytest.mark.parametrize("name", ["depth", "confidence"])
def test_a_map_of_another_size_than_the_disparity_is_named(name: str) -> None:
    """A hand-made result whose depth or confidence map had another size than its disparity
    map gave NumPy's "operands could not be broadcast together with shapes (120,200)
    (60,100)", naming neither map. The message names the map and both shapes."""
    from types import SimpleNamespace

    disparity = np.tile(np.linspace(1.0, 40.0, 200, dtype=np.float32), (120, 1))
    maps = {"depth": None, "confidence": np.ones_like(disparity)}
    maps[name] = np.ones((60, 100), np.float32)
    result = SimpleNamespace(disparity=disparity, left_rectified=None, **maps)
    with pytest.raises(
        ValueError,
        match=rf"^result: expected a {name} map of the disparity "
        r"map's shape \(120, 200\), got shape \(60, 100\)$",
    ):
        overview_image(result, "t")


def test_a_left_image_of_another_size_than_the_disparity_is_named() -> None:
    """A hand-made result's 100x60 left image beside a 200x120 disparity map was stretched to
    the panel without a word (its pixels beside another place's disparities). The message
    names both shapes, as for a depth or confidence map; a left image of the map's size, or
    none, is drawn as before."""
    from types import SimpleNamespace

    disparity = np.tile(np.linspace(1.0, 40.0, 200, dtype=np.float32), (120, 1))
    conf = np.ones_like(disparity)
    small = SimpleNamespace(
        disparity=disparity,
        confidence=conf,
        depth=None,
        left_rectified=np.zeros((60, 100, 3), np.uint8),
    )
    with pytest.raises(
        ValueError,
        match=r"^result: expected a left image of the disparity map's shape \(120, 200\), got "
        r"shape \(60, 100, 3\)$",
    ):
        overview_image(small, "t")
    for left in (np.zeros((120, 200), np.uint8), None):
        same = SimpleNamespace(
            disparity=disparity, confidence=conf, depth=None, left_rectified=left
        )
        assert overview_image(same, "t").image.shape[2] == 3


def test_overviews_compare_by_identity() -> None:
    """Two overviews of one picture: ``a == b`` (and ``b in [a]``) compared their images and
    raised NumPy's 'truth value of an array ... is ambiguous'. Equal to itself only."""
    img = np.zeros((4, 6, 3), np.uint8)
    a, b = Overview(img.copy(), "t", {}, {}, 1.0), Overview(img.copy(), "t", {}, {}, 1.0)
    assert a == a and a != b and b not in [a] and len({a, b, a}) == 2
