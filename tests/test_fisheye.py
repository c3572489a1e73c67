"""Fisheye rigs: the Calibration's fisheye model (validation, files, ROS and Kalibr), its
rectification against a rendered rig's exact geometry, a fisheye calibration from rendered
ChArUco views beside the pinhole models, and depth of a rendered wall through the whole chain."""

from __future__ import annotations

import dataclasses
import hashlib
import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

import stereovision as sv
from stereovision import calibrate as calmod
from stereovision import charuco
from stereovision.calibrate import _cli_words, calibrate
from stereovision.calibration import Calibration
from stereovision.charuco import CharucoBoard, render_charuco
from stereovision.synthetic import render_plane

SIZE = (480, 360)
# About 120 x 105 degrees across the image (equidistant: r = f theta), 240 degrees diagonal-free.
K1 = np.array([[210.0, 0, 241.5], [0, 210.5, 178.5], [0, 0, 1]])
D1 = np.array([0.02, -0.01, 0.003, -0.0008])
K2 = np.array([[212.0, 0, 238.0], [0, 211.5, 182.0], [0, 0, 1]])
D2 = np.array([0.018, -0.008, 0.002, -0.0006])
ROT = cv2.Rodrigues(np.array([0.01, -0.03, 0.005]))[0]
T = np.array([-0.10, 0.001, 0.002])
TRUTH = Calibration(K1=K1, D1=D1, K2=K2, D2=D2, R=ROT, T=T, image_size=SIZE, model="fisheye")
BOARD = CharucoBoard("10x7", 0.06, 0.045, "DICT_5X5_100")


def _right_pose(rv: np.ndarray, tv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r, t = cv2.composeRT(
        rv.reshape(3, 1), tv.reshape(3, 1), cv2.Rodrigues(ROT)[0], T.reshape(3, 1)
    )[:2]
    return np.asarray(r).ravel(), np.asarray(t).ravel()


def _truth_points(n: int = 20000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points 1-6 m away seen by both true cameras: 3-D (left frame), left and right pixels."""
    rng = np.random.default_rng(1)
    pts = np.c_[rng.uniform(-6, 6, n), rng.uniform(-4, 4, n), rng.uniform(1, 6, n)]
    pl = cv2.fisheye.projectPoints(pts.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K1, D1)[0]
    pr = cv2.fisheye.projectPoints(pts.reshape(-1, 1, 3), cv2.Rodrigues(ROT)[0], T, K2, D2)[0]
    pl, pr = pl.reshape(-1, 2), pr.reshape(-1, 2)
    w, h = SIZE
    ok = np.all((pl >= 0) & (pl < (w, h)) & (pr >= 0) & (pr < (w, h)), axis=1)
    ok &= ((ROT @ pts.T).T + T)[:, 2] > 0
    return pts[ok], pl[ok], pr[ok]


def _row_errors(cal: Calibration) -> np.ndarray:
    """|dy| of the true points rectified with ``cal``, inside both rectified images."""
    _, pl, pr = _truth_points()
    ul, ur = cal.rectify_points(pl, "left"), cal.rectify_points(pr, "right")
    w, h = SIZE
    inside = np.all((ul >= 0) & (ul < (w, h)) & (ur >= 0) & (ur < (w, h)), axis=1)
    assert inside.sum() > 5000
    return np.abs(ul[inside, 1] - ur[inside, 1])


# ------------------------------------------------------------------------------- the model


def test_fisheye_calibration_is_checked() -> None:
    with pytest.raises(ValueError, match="D1: the fisheye model takes 4 coefficients"):
        dataclasses.replace(TRUTH, D1=np.zeros(5))
    with pytest.raises(ValueError, match="model: expected one of"):
        dataclasses.replace(TRUTH, model="omni")
    rc = TRUTH.rectified_calibration()
    with pytest.raises(ValueError, match="a rectified calibration is a pinhole pair"):
        dataclasses.replace(rc, D1=np.zeros(4), D2=np.zeros(4), model="fisheye")
    assert TRUTH != dataclasses.replace(TRUTH, model="pinhole")


@pytest.mark.parametrize("suffix", [".yaml", ".json", ".xml"])
def test_fisheye_files_round_trip(tmp_path: Path, suffix: str) -> None:
    path = TRUTH.save(tmp_path / f"rig{suffix}")
    back = Calibration.load(path)
    assert back == TRUTH and back.model == "fisheye"
    # a pinhole file says nothing of the model, as before
    pinhole = dataclasses.replace(TRUTH, D1=np.zeros(5), D2=np.zeros(5), model="pinhole")
    pin = Calibration.load(pinhole.save(tmp_path / f"p{suffix}"))
    assert pin.model == "pinhole" and "model" not in (tmp_path / f"p{suffix}").read_text()


def test_rectification_puts_the_true_rigs_points_on_rows() -> None:
    """The exact rig, rectified by cv2.fisheye: every point seen by both cameras on one row
    (to 1e-6 px), and ranges from its disparity exact; the scaled rig the same."""
    dy = _row_errors(TRUTH)
    assert dy.max() < 1e-6
    pts, pl, pr = _truth_points()
    ul, ur = TRUTH.rectify_points(pl, "left"), TRUTH.rectify_points(pr, "right")
    rc = TRUTH.rectified_calibration()
    z = rc.K1[0, 0] * TRUTH.baseline / (ul[:, 0] - ur[:, 0] + rc.doffs_px)
    r1 = TRUTH._stereo_rectify(0.0)[0]
    np.testing.assert_allclose(z, (r1 @ pts.T)[2], rtol=1e-6)
    half = TRUTH.scaled_to((240, 180))
    assert half.model == "fisheye" and half.rectified_calibration().K1[0, 0] == pytest.approx(
        rc.K1[0, 0] / 2, rel=0.01
    )
    # rectify() and rectify_points() agree: a dot drawn at a raw pixel lands where predicted
    img = np.zeros((SIZE[1], SIZE[0]), np.float32)
    raw = np.array([[400.0, 80.0]])
    img[80, 400] = 1.0
    out, _ = TRUTH.rectify(img, img)
    yx = np.unravel_index(np.argmax(out), out.shape)
    np.testing.assert_allclose((yx[1], yx[0]), TRUTH.rectify_points(raw)[0], atol=1.0)
    w, h = TRUTH.valid_roi()[0][2:]
    assert w > SIZE[0] // 2 and h > SIZE[1] // 2


def test_ros_and_kalibr_fisheye(tmp_path: Path) -> None:
    left = TRUTH.save_ros(tmp_path / "ros")[0]
    assert "distortion_model: equidistant" in left.read_text()
    back = Calibration.from_file(tmp_path / "ros")
    assert back.model == "fisheye"
    np.testing.assert_allclose(back.K1, K1)
    np.testing.assert_allclose(back.D2, D2)
    np.testing.assert_allclose(back.R, ROT, atol=1e-12)
    np.testing.assert_allclose(back.T, T, atol=1e-12)
    chain = tmp_path / "camchain.yaml"
    tf = np.eye(4)
    tf[:3, :3], tf[:3, 3] = ROT, T
    cams = []
    for n, (K, D) in enumerate(((K1, D1), (K2, D2))):
        lines = [
            f"cam{n}:",
            "  camera_model: pinhole",
            f"  intrinsics: [{K[0, 0]}, {K[1, 1]}, {K[0, 2]}, {K[1, 2]}]",
            "  distortion_model: equidistant",
            f"  distortion_coeffs: [{', '.join(repr(float(v)) for v in D)}]",
            f"  resolution: [{SIZE[0]}, {SIZE[1]}]",
        ]
        if n:
            lines.append("  T_cn_cnm1:")
            lines += [f"  - [{', '.join(repr(float(v)) for v in row)}]" for row in tf]
        cams.append("\n".join(lines))
    chain.write_text("\n".join(cams) + "\n")
    kal = Calibration.from_file(chain)
    assert kal.model == "fisheye"
    np.testing.assert_allclose(kal.D1, D1)
    np.testing.assert_allclose(kal.R, ROT, atol=1e-9)


# -------------------------------------------------------------------------------- calibrating


@pytest.fixture(scope="module")
def views() -> tuple[list[np.ndarray], list[np.ndarray]]:
    return render_views()


def render_views() -> tuple[list[np.ndarray], list[np.ndarray]]:
    """40 ChArUco pairs, the board 0.3-0.55 m away and up to 50 degrees off axis."""
    rng = np.random.default_rng(5)
    centre = np.array([5 * 0.06, 3.5 * 0.06, 0])
    left, right = [], []
    for _ in range(40):
        rv = rng.normal(0, 0.25, 3)
        z = rng.uniform(0.3, 0.55)
        a = rng.uniform(-0.9, 0.9, 2)
        tv = np.array([math.tan(a[0]) * z, math.tan(a[1]) * z * 0.75, z])
        tv = tv - cv2.Rodrigues(rv)[0] @ centre
        r2, t2 = _right_pose(rv, tv)
        kw: dict[str, Any] = {"image_size": SIZE, "model": "fisheye", "supersample": 2}
        left.append(render_charuco(BOARD, K1, D1, rv, tv, **kw))
        right.append(render_charuco(BOARD, K2, D2, r2, t2, **kw))
    return left, right


def _memoised(find: Callable[..., Any]) -> Callable[..., Any]:
    """``find_charuco_corners`` memoised by image content and board: a second calibration of
    the same views does not detect the boards again (what is tested is the solvers)."""
    seen: dict[Any, Any] = {}

    def cached(image: Any, board: CharucoBoard) -> Any:
        arr = np.ascontiguousarray(image)
        key = (hashlib.sha1(arr.tobytes()).hexdigest(), arr.shape, arr.dtype.str, board)
        if key not in seen:
            seen[key] = find(arr, board)
        hit = seen[key]
        return None if hit is None else tuple(a.copy() for a in hit)

    return cached


def _memoised_unusable(unusable: Callable[..., list[int]]) -> Callable[..., list[int]]:
    """``calibrate._fisheye_unusable`` memoised by its views' content: the "auto" calibration's
    fisheye hint asks it of the views the fisheye calibration asked it of (1.2 s of CPU)."""
    seen: dict[str, list[int]] = {}

    def cached(obj: Any, left: Any, right: Any, size: tuple[int, int]) -> list[int]:
        h = hashlib.sha1(repr(tuple(size)).encode())
        for views in (obj, left, right):
            for v in views:
                a = np.ascontiguousarray(v, np.float64)
                h.update(repr(a.shape).encode() + a.tobytes())
        key = h.hexdigest()
        if key not in seen:
            seen[key] = unusable(obj, left, right, size)
        return list(seen[key])

    return cached


def test_fisheye_calibration_recovers_the_rig(
    views: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """distortion='fisheye' brings the rig back (measured: 34 pairs, rotation 0.041 degrees off,
    baseline within 0.02 mm, rows of the true points 0.023 px median and 0.084 px at the 95th
    percentile); the pinhole model cannot fit the lens (rotation 2.8 degrees off, rows 3.3 px at
    the 95th percentile)."""
    # the "auto" calibration below reads the boards the first one found
    monkeypatch.setattr(charuco, "find_charuco_corners", _memoised(charuco.find_charuco_corners))
    # and the views the fisheye solver cannot start from, which its hint asks again
    monkeypatch.setattr(calmod, "_fisheye_unusable", _memoised_unusable(calmod._fisheye_unusable))
    cal, rep = calibrate(*views, board=BOARD, distortion="fisheye")
    assert cal.model == "fisheye" and rep.distortion_model == "fisheye"
    assert len(rep.used_pairs) >= 30 and rep.rms < 0.3
    angle = math.degrees(float(np.linalg.norm(cv2.Rodrigues(cal.R @ ROT.T)[0])))
    assert angle < 0.12
    assert abs(cal.baseline - 0.1) < 5e-4
    assert abs(cal.K1[0, 0] - K1[0, 0]) < 1.5
    dy = _row_errors(cal)
    assert np.median(dy) < 0.08 and np.percentile(dy, 95) < 0.25
    page = rep.write(tmp_path)["html"].read_text()  # the report's pictures through the model
    assert "model fisheye" in rep.summary() and page.count("data:image/png;base64,") >= 3
    # The pinhole model's poor fit is said, with the option that fits (it was silent).
    with pytest.warns(
        UserWarning,
        match=r"^the k1k2p1p2 model fits these views with 0\.6\d\d / 0\.7\d\d px \(left / right\), "
        r"the fisheye model with 0\.[12]\d\d / 0\.[12]\d\d px: a wide-angle lens; calibrate with "
        r"distortion='fisheye'$",
    ):
        pin, prep = calibrate(*views, board=BOARD, distortion="auto")
    assert prep.rms > 2 * rep.rms
    assert (
        _cli_words("calibrate with distortion='fisheye'") == "calibrate with --distortion fisheye"
    )
    assert np.percentile(_row_errors(pin), 95) > 10 * np.percentile(dy, 95)


def test_the_fisheye_solver_names_its_failure() -> None:
    flat = [np.full((SIZE[1], SIZE[0]), 90, np.uint8)] * 3
    with pytest.raises(ValueError, match="found in both images of only 0"):
        calibrate(flat, flat, board=BOARD, distortion="fisheye")


# -------------------------------------------------------------------------------- depth


def render_wall(texture: np.ndarray, z_wall: float) -> tuple[np.ndarray, np.ndarray]:
    """A wall of the texture tiled 4 x 4, ``z_wall`` metres in front of the true rig and facing
    its left camera, rendered through both fisheye lenses (4 mm per texture pixel at 2.5 m,
    scaled with the distance so that the texture keeps its size in the image)."""
    tex = np.tile(texture, (4, 4, 1) if texture.ndim == 3 else (4, 4))
    s = 0.004 * z_wall / 2.5
    tv = np.array([-tex.shape[1] * s / 2, -tex.shape[0] * s / 2, z_wall])
    kw: dict[str, Any] = {"image_size": SIZE, "model": "fisheye", "supersample": 2}
    left = render_plane(tex, s, K1, D1, np.zeros(3), tv, **kw)
    r2, t2 = _right_pose(np.zeros(3), tv)
    return left, render_plane(tex, s, K2, D2, r2, t2, **kw)


def wall_depth(calib: Calibration, z_wall: float) -> np.ndarray:
    """The wall's depth at every pixel of ``calib``'s rectified left image (the wall's normal
    is the true left camera's axis, turned by the rectification's R1)."""
    n = calib._stereo_rectify(0.0)[0] @ np.array([0.0, 0.0, 1.0])
    rc = calib.rectified_calibration()
    w, h = calib.image_size
    xs, ys = np.meshgrid(np.arange(w), np.arange(h))
    rays = np.stack(
        [(xs - rc.K1[0, 2]) / rc.K1[0, 0], (ys - rc.K1[1, 2]) / rc.K1[1, 1], np.ones_like(xs)],
        axis=-1,
    )
    out: np.ndarray = z_wall / (rays @ n)
    return out


def test_depth_of_a_wall_through_the_fisheye_rig(data_dir: Path) -> None:
    """A textured wall 2.5 m in front of the true rig, rendered through both fisheye lenses: the
    default depth map, rectified with the rig, gives the wall's depth (median error within 1 %,
    3/4 of the rectified image covered)."""
    tex = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "left.png"), cv2.IMREAD_GRAYSCALE)
    left, right = render_wall(tex, 2.5)
    res = sv.depth_map(left, right, TRUTH, max_disparity=32)
    ok = np.isfinite(res.depth)
    assert ok.mean() > 0.75
    rel = np.abs(res.depth[ok] / wall_depth(TRUTH, 2.5)[ok] - 1)
    assert np.median(rel) < 0.01


def test_cli_depth_and_info_with_a_fisheye_calibration(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision info` and `depth --calib` take a fisheye calibration file (in-process:
    the test is not about the process)."""
    from stereovision.cli import main

    TRUTH.save(tmp_path / "rig.yaml")
    tex = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "left.png"))
    left, right = render_wall(tex, 2.5)
    cv2.imwrite(str(tmp_path / "l.png"), left)
    cv2.imwrite(str(tmp_path / "r.png"), right)
    assert main(["info", str(tmp_path / "rig.yaml")]) == 0
    said = capsys.readouterr()
    assert "raw fisheye rig" in said.out, said.err
    code = main(
        ["depth", str(tmp_path / "l.png"), str(tmp_path / "r.png"), "--calib",
         str(tmp_path / "rig.yaml"), "--max-disparity", "32", "-o", str(tmp_path / "out")]
    )  # fmt: skip
    assert code == 0, capsys.readouterr().err
    depth = np.load(tmp_path / "out" / "depth.npy")
    assert abs(float(np.nanmedian(depth)) - 2.5) < 0.1


def test_field_check_and_correction_on_a_fisheye_rig(data_dir: Path) -> None:
    """`check_rectification` and `refine_rectification` work through the fisheye model: the
    rendered wall passes with the true rig (measured 0.06 px), fails with a calibration whose
    right camera is pitched 0.4 degrees off (1.55 px), and the correction brings the rig back
    to 0.006 degrees of the truth."""
    tex = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "left.png"))
    left, right = render_wall(tex, 2.5)
    assert sv.check_rectification(left, right, TRUTH).ok is True
    bump = cv2.Rodrigues(np.array([math.radians(0.4), 0.0, 0.0]))[0]
    bad = dataclasses.replace(TRUTH, R=bump @ ROT, T=bump @ T)
    assert sv.check_rectification(left, right, bad).ok is False
    fixed, after = sv.refine_rectification(left, right, bad)
    assert after.ok is True and fixed.model == "fisheye"
    angle = math.degrees(float(np.linalg.norm(cv2.Rodrigues(fixed.R @ ROT.T)[0])))
    assert angle < 0.03


@pytest.mark.parametrize("t_y", [-0.10, 0.10])
def test_a_vertical_fisheye_rig_is_refused_like_a_pinhole_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], t_y: float
) -> None:
    """cv2.fisheye.stereoRectify lays any baseline along the rows by turning both views about
    90 degrees: a vertical fisheye rig came out turned (info's field of view swapped, depth
    rotated) where the pinhole path refuses a vertical rig."""
    from stereovision.cli import main

    vertical = dataclasses.replace(TRUTH, T=np.array([0.001, t_y, 0.002]))
    with pytest.raises(ValueError) as err:
        vertical.rectified_calibration()
    assert re.fullmatch(
        r"R, T: the rig is vertical \(fisheye stereoRectify turned the views (89|90|91) degrees "
        r"to lay its baseline along the rows\); only horizontal rigs are supported",
        str(err.value),
    )
    pinhole = dataclasses.replace(vertical, model="pinhole", D1=np.zeros(5), D2=np.zeros(5))
    with pytest.raises(ValueError, match=r"^R, T: the rig is vertical .* only horizontal rigs"):
        pinhole.rectified_calibration()
    path = vertical.save(tmp_path / "vertical.yaml")
    assert main(["info", str(path)]) == 2
    assert capsys.readouterr().err == f"stereovision: error: {err.value}\n"
    assert TRUTH.rectified_calibration().image_size == SIZE  # a horizontal one still works


@pytest.mark.parametrize("alpha", [0.0, 1.0])
def test_fisheye_alpha_is_the_balance_and_the_roi_holds_valid_pixels(alpha: float) -> None:
    """A mutation audit found a fisheye rig's ``alpha`` unchecked (``balance=0`` whatever the
    alpha went unseen) and its ``valid_roi`` (drawn from the maps, OpenCV gives none) unchecked
    against the maps (x and y maps swapped went unseen). Against cv2.fisheye.stereoRectify and
    initUndistortRectifyMap on the same rig: the rectified focal length is ``P1``'s, and the
    left ROI holds only pixels mapped from inside the image, spanning the valid centre row
    and column."""
    r1, _, p1, _, _ = cv2.fisheye.stereoRectify(
        K1, D1, K2, D2, SIZE, ROT, T.reshape(3, 1),
        flags=cv2.fisheye.CALIB_ZERO_DISPARITY, newImageSize=SIZE, balance=alpha, fov_scale=1.0,
    )  # fmt: skip
    np.testing.assert_allclose(TRUTH.rectified_calibration(alpha).K1, p1[:, :3], rtol=1e-9)
    mx, my = cv2.fisheye.initUndistortRectifyMap(K1, D1, r1, p1, SIZE, cv2.CV_32FC1)
    w, h = SIZE
    valid = (mx >= 0) & (mx <= w - 1) & (my >= 0) & (my <= h - 1)
    x, y, rw, rh = TRUTH.valid_roi(alpha)[0]
    assert rw > 0 and rh > 0 and valid[y : y + rh, x : x + rw].all()
    cy, cx = y + rh // 2, x + rw // 2
    assert rw >= 0.9 * np.count_nonzero(valid[cy]) and rh >= 0.9 * np.count_nonzero(valid[:, cx])


def test_fisheye_right_roi_comes_from_the_right_maps() -> None:
    """The right ROI is drawn from the right camera's maps (the left's maps for both went
    unseen by a mutation audit): at alpha 1 it starts 29 px in, where the left's starts at 0,
    and holds only pixels mapped from inside the right image."""
    _, r2, _, p2, _ = cv2.fisheye.stereoRectify(
        K1, D1, K2, D2, SIZE, ROT, T.reshape(3, 1),
        flags=cv2.fisheye.CALIB_ZERO_DISPARITY, newImageSize=SIZE, balance=1.0, fov_scale=1.0,
    )  # fmt: skip
    mx, my = cv2.fisheye.initUndistortRectifyMap(K2, D2, r2, p2, SIZE, cv2.CV_32FC1)
    w, h = SIZE
    valid = (mx >= 0) & (mx <= w - 1) & (my >= 0) & (my <= h - 1)
    roi_l, (x, y, rw, rh) = TRUTH.valid_roi(1.0)
    assert roi_l[0] == 0 and x == 29 and rw > 0.8 * w
    assert valid[y : y + rh, x : x + rw].all() and not valid[y : y + rh, x - 1 : x + rw].all()
