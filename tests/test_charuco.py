"""ChArUco boards: detection against the rendering's exact corners, the dictionary and layout
found from the images, partial views, a synthetic stereo rig recovered through boards cut by the
image edges, errors, the printable board and the CLI."""

from __future__ import annotations

import contextlib
import io
import json
import math
import re
import struct
import subprocess
import warnings
import zlib
from dataclasses import replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from stereovision.calibrate import calibrate, calibrate_from_video
from stereovision.charuco import (
    MIN_CORNERS,
    CharucoBoard,
    board_png,
    corners_span_plane,
    dictionary_name,
    find_charuco_corners,
    render_charuco,
)

SIZE = (640, 480)
K1 = np.array([[600.0, 0, 330], [0, 602, 238], [0, 0, 1]])
D1 = np.array([-0.30, 0.12, 0.0008, -0.0004, 0])
K2 = np.array([[605.0, 0, 316], [0, 604, 244], [0, 0, 1]])
D2 = np.array([-0.28, 0.10, -0.0006, 0.0005, 0])
ROT = cv2.Rodrigues(np.array([0.01, -0.03, 0.005]))[0]
T = np.array([-0.12, 0.002, 0.001])
#: 10x7 squares = the 9x6 inner corners of OpenCV's sample chessboard.
BOARD = CharucoBoard("10x7", 0.03, 0.022, "DICT_5X5_100")
SS = 2  # supersampling of the renderings (2 keeps the module's set-up near 2 s)


def _project(board: CharucoBoard, ids: Any, rv: Any, tv: Any, K: Any, D: Any) -> np.ndarray:
    p, _ = cv2.projectPoints(board.object_points(ids).astype(np.float64), rv, tv, K, D)
    return np.asarray(p).reshape(-1, 2)


def _right_pose(rv: np.ndarray, tv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r, t = cv2.composeRT(
        rv.reshape(3, 1), tv.reshape(3, 1), cv2.Rodrigues(ROT)[0].reshape(3, 1), T.reshape(3, 1)
    )[:2]
    return np.asarray(r).ravel(), np.asarray(t).ravel()


def _poses(n: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Board poses 0.35-0.6 m away whose centres range over the whole image (and past it)."""
    rng = np.random.default_rng(seed)
    out = []
    centre = np.array([5 * BOARD.square_size, 3.5 * BOARD.square_size, 0])
    for _ in range(n):
        rv = rng.normal(0, 0.25, 3)
        z = rng.uniform(0.35, 0.6)
        c = np.array([rng.uniform(-0.25, 0.25) * z, rng.uniform(-0.18, 0.18) * z, z])
        out.append((rv, c - cv2.Rodrigues(rv)[0] @ centre))
    return out


def _noisy(img: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    return np.clip(img + rng.normal(0, 1.0, img.shape), 0, 255).astype(np.uint8)


@pytest.fixture(scope="module")
def rig() -> dict[str, Any]:
    rng = np.random.default_rng(3)
    poses = _poses(14, seed=7)
    left, right = [], []
    for rv, tv in poses:
        left.append(_noisy(render_charuco(BOARD, K1, D1, rv, tv, supersample=SS), rng))
        r2, t2 = _right_pose(rv, tv)
        right.append(_noisy(render_charuco(BOARD, K2, D2, r2, t2, supersample=SS), rng))
    return {"poses": poses, "left": left, "right": right}


@pytest.fixture(scope="module")
def six(rig: dict[str, Any]) -> tuple[Any, Any]:
    """The first 6 pairs calibrated with ``BOARD``: one calibration that the tests which only
    read it share (each made the same one of its own)."""
    return calibrate(rig["left"][:6], rig["right"][:6], board=BOARD)


# ---------------------------------------------------------------------------------- detection


def test_corners_agree_with_the_rendered_board() -> None:
    """Every corner found lies within 0.4 px of its projection (0.04-0.08 px mean measured)."""
    for rv, tv in _poses(4, seed=1):
        img = render_charuco(BOARD, K1, D1, rv, tv, supersample=SS)
        found = find_charuco_corners(img, BOARD)
        assert found is not None
        ids, pts = found
        assert np.all(np.diff(ids) > 0) and ids.min() >= 0 and ids.max() < BOARD.n_corners
        err = np.linalg.norm(pts - _project(BOARD, ids, rv, tv, K1, D1), axis=1)
        assert err.mean() < 0.15 and err.max() < 0.4, (err.mean(), err.max())


def test_a_board_cut_by_the_image_edge_gives_its_visible_corners() -> None:
    """Shifted right until a third of it leaves the image, the board still gives corners (those
    whose two neighbouring markers are in view), each with its right id."""
    rv = np.array([0.1, 0.2, 0.0])
    counts = []
    for shift in (0.0, 0.2, 0.25):
        tv = np.array([-0.17 + shift, -0.1, 0.5])
        img = render_charuco(BOARD, K1, D1, rv, tv, supersample=SS)
        found = find_charuco_corners(img, BOARD)
        assert found is not None
        ids, pts = found
        truth = _project(BOARD, np.arange(BOARD.n_corners), rv, tv, K1, D1)
        assert np.all(truth[ids, 0] < SIZE[0] - 1)
        err = np.linalg.norm(pts - truth[ids], axis=1)
        assert err.max() < 0.4
        counts.append(len(ids))
    # measured 54, 37, 30 (of 54, 42 and 36 inside the image)
    assert counts[0] == BOARD.n_corners
    assert 30 <= counts[2] < counts[1] < counts[0]


@pytest.mark.parametrize(
    ("dictionary", "squares", "legacy"),
    [
        ("DICT_4X4_50", "8x6", False),
        ("DICT_6X6_250", "8x6", True),
        ("DICT_7X7_1000", "7x5", False),
        ("DICT_ARUCO_ORIGINAL", "8x6", False),
        ("DICT_APRILTAG_36H11", "7x5", False),
    ],
)
def test_dictionary_and_layout_are_found_from_the_image(
    dictionary: str, squares: str, legacy: bool
) -> None:
    true = CharucoBoard(squares, 0.04, 0.03, dictionary, legacy=legacy)
    rv, tv = np.array([0.2, -0.3, 0.1]), np.array([-0.12, -0.08, 0.5])
    img = render_charuco(true, K1, D1, rv, tv, supersample=SS)
    found = CharucoBoard(squares, 0.04, 0.03).resolve(img)
    assert found is not None
    family = dictionary.rsplit("_", 1)[0] if dictionary[5].isdigit() else dictionary
    assert found.dictionary.startswith(family)  # the smallest of the family that holds the board
    assert found.legacy is legacy
    a = find_charuco_corners(img, CharucoBoard(squares, 0.04, 0.03))
    b = find_charuco_corners(img, true)
    assert a is not None and b is not None
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_allclose(a[1], b[1], atol=1e-9)
    assert len(a[0]) == true.n_corners


def test_the_wrong_layout_finds_fewer_corners() -> None:
    """An even-rowed board printed in the legacy layout: read with the current one, fewer
    corners (the two layouts put the markers in different squares)."""
    true = CharucoBoard("8x6", 0.04, 0.03, "DICT_5X5_100", legacy=True)
    rv, tv = np.array([0.1, -0.2, 0.0]), np.array([-0.15, -0.1, 0.5])
    img = render_charuco(true, K1, D1, rv, tv, supersample=SS)
    right = find_charuco_corners(img, true)
    wrong = find_charuco_corners(img, CharucoBoard("8x6", 0.04, 0.03, "DICT_5X5_100", False))
    assert right is not None and len(right[0]) == true.n_corners
    assert wrong is None or len(wrong[0]) < len(right[0]) // 2


def test_no_board_no_corners() -> None:
    flat = np.full((240, 320), 128, np.uint8)
    assert find_charuco_corners(flat, BOARD) is None
    assert CharucoBoard("10x7", 0.03, 0.022).resolve(flat) is None
    noise = np.random.default_rng(0).integers(0, 256, (240, 320)).astype(np.uint8)
    assert find_charuco_corners(noise, CharucoBoard("10x7", 0.03, 0.022)) is None


# -------------------------------------------------------------------------------- calibration


def _truth_errors(cal: Any) -> tuple[np.ndarray, np.ndarray]:
    """Points seen by the true rig, rectified with the estimate: row offsets (px) and relative
    range errors."""
    rng = np.random.default_rng(11)
    R1, R2, P1, P2, *_ = cv2.stereoRectify(
        cal.K1, cal.D1, cal.K2, cal.D2, SIZE, cal.R, cal.T.reshape(3, 1),
        flags=cv2.CALIB_ZERO_DISPARITY, alpha=0,
    )  # fmt: skip
    pts = np.c_[rng.uniform(-1.5, 1.5, 4000), rng.uniform(-1, 1, 4000), rng.uniform(2, 6, 4000)]
    pl = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), K1, D1)[0].reshape(-1, 2)
    pr = cv2.projectPoints(pts, cv2.Rodrigues(ROT)[0], T, K2, D2)[0].reshape(-1, 2)
    w, h = SIZE
    ok = np.all((pl >= 0) & (pl < (w, h)) & (pr >= 0) & (pr < (w, h)), axis=1)
    ul = cv2.undistortPoints(pl[ok].reshape(-1, 1, 2), cal.K1, cal.D1, R=R1, P=P1).reshape(-1, 2)
    ur = cv2.undistortPoints(pr[ok].reshape(-1, 1, 2), cal.K2, cal.D2, R=R2, P=P2).reshape(-1, 2)
    X = cv2.triangulatePoints(P1, P2, ul.T, ur.T)
    rng_est = np.linalg.norm((X[:3] / X[3]).T, axis=1)
    return np.abs(ul[:, 1] - ur[:, 1]), np.abs(rng_est / np.linalg.norm(pts[ok], axis=1) - 1)


def test_stereo_calibration_recovers_the_rig_through_cut_boards(rig: dict[str, Any]) -> None:
    """14 pairs whose boards are often cut by an image edge: all are used, and the rig comes
    back (measured: |T| within 0.01 mm, rotation 0.06 degrees, rows 0.03 px at the 95th
    percentile, ranges 0.2 %)."""
    cal, rep = calibrate(rig["left"], rig["right"], board=BOARD)
    assert len(rep.used_pairs) == 14 and not rep.rejected_pairs
    partial = [n for n, ids in rep._ids.items() if len(ids) < BOARD.n_corners]
    assert len(partial) >= 4  # the point of the exercise: views a chessboard could not use
    assert rep.corners_used == sum(len(ids) for ids in rep._ids.values())
    assert rep.rms < 0.15
    assert abs(np.linalg.norm(cal.T) - np.linalg.norm(T)) < 2e-4
    angle = math.degrees(float(np.linalg.norm(cv2.Rodrigues(cal.R @ ROT.T)[0])))
    assert angle < 0.15
    assert abs(cal.K1[0, 0] - K1[0, 0]) < 1.5 and abs(cal.K2[0, 0] - K2[0, 0]) < 1.5
    assert abs(rep.square_size_measured / BOARD.square_size - 1) < 0.002
    dy, rel = _truth_errors(cal)
    assert np.percentile(dy, 95) < 0.1 and np.median(rel) < 0.003
    assert "ChArUco 10x7 squares" in rep.summary() and "DICT_5X5_100" in rep.board


def test_dictionary_auto_calibrates_the_same(rig: dict[str, Any], six: tuple[Any, Any]) -> None:
    """dictionary='auto' settles on DICT_5X5_50 (a prefix of 5X5_100): the same corners, the
    same calibration."""
    sub = slice(0, 6)
    a, ra = six  # calibrate(rig["left"][sub], rig["right"][sub], board=BOARD)
    auto = CharucoBoard("10x7", 0.03, 0.022)
    b, rb = calibrate(rig["left"][sub], rig["right"][sub], board=auto)
    assert "DICT_5X5_50" in rb.board
    assert ra.corners_used == rb.corners_used
    np.testing.assert_allclose(b.T, a.T, atol=1e-9)


def test_pairs_with_too_few_common_corners_are_rejected_by_name(rig: dict[str, Any]) -> None:
    """A pair whose cameras see different parts of the board is rejected with the count."""
    left = list(rig["left"][:6])
    right = list(rig["right"][:6])
    # Pair 4 sees the whole board in both images: the left image keeps the board's columns 0-5,
    # the right one columns 3-8; corners need both neighbouring markers, so 4 remain in common.
    rv, tv = rig["poses"][4]
    r2, t2 = _right_pose(rv, tv)
    grid = np.arange(BOARD.n_corners)
    pl = _project(BOARD, grid, rv, tv, K1, D1).reshape(6, 9, 2)
    pr = _project(BOARD, grid, r2, t2, K2, D2).reshape(6, 9, 2)
    left[4] = left[4].copy()
    left[4][:, int((pl[:, 5, 0].max() + pl[:, 6, 0].min()) / 2) :] = 60
    right[4] = right[4].copy()
    right[4][:, : int((pr[:, 2, 0].max() + pr[:, 3, 0].min()) / 2)] = 60
    right[1] = np.full_like(right[1], 60)
    _, rep = calibrate(left, right, board=BOARD, names=[f"p{i}" for i in range(6)])
    assert rep.rejected_pairs == {
        "p1": "board not found in right",
        "p4": "only 4 corners seen in both images (at least 6, not all on one line)",
    }
    assert len(rep.used_pairs) == 4


def test_report_pictures_with_partial_boards(six: tuple[Any, Any], tmp_path: Path) -> None:
    _, rep = six
    paths = rep.write(tmp_path)
    page = paths["html"].read_text()
    assert "ChArUco 10x7 squares" in page and f"{rep.corners_used} corners used" in page
    assert page.count("data:image/png;base64,") >= 3
    assert 0.2 < rep.coverage_left < 1.0


# ------------------------------------------------------------------------------------- errors


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (("2x5", 0.03, 0.02), "squares"),
        (("7", 0.03, 0.02), "squares"),
        ((("a", 5), 0.03, 0.02), "squares"),
        (("7x5", 0.03, 0.03), "marker_size"),
        (("7x5", -0.03, 0.02), "square_size"),
        (("7x5", 0.03, float("nan")), "marker_size"),
        (("7x5", 0.03, 0.02, "DICT_9X9_50"), "unknown ArUco dictionary"),
        (("100x100", 0.03, 0.02), "5000 markers; no predefined dictionary holds more than 2320"),
        (("12x10", 0.03, 0.02, "DICT_4X4_50"), "has 50 markers, but a 12x10 board needs 60"),
    ],
)
def test_bad_boards_are_named(args: tuple[Any, ...], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        CharucoBoard(*args)


def test_a_board_of_unknown_dictionary_says_how_to_give_it() -> None:
    """CharucoBoard("10x7", 0.03, 0.022).image(), the README's board printed from Python, said
    only "the board's dictionary is not known yet (dictionary='auto')"."""
    board = CharucoBoard("10x7", 0.03, 0.022)
    want = re.escape(
        "the board's dictionary is not known yet (dictionary='auto'): give one (e.g. "
        "dictionary='DICT_5X5_100' for a board to print), or resolve() the board on an image "
        "of it"
    )
    with pytest.raises(ValueError, match=f"^{want}$"):
        board.image()
    assert CharucoBoard("10x7", 0.03, 0.022, "DICT_5X5_100").image(20).shape == (180, 240)


def test_dictionary_names() -> None:
    assert dictionary_name("5x5_100") == "DICT_5X5_100"
    assert dictionary_name("apriltag_36h11") == "DICT_APRILTAG_36H11"
    with pytest.raises(ValueError, match="expected one of 4X4_50"):
        dictionary_name("nope")


def test_calibrate_argument_errors(rig: dict[str, Any]) -> None:
    left, right = rig["left"][:3], rig["right"][:3]
    differs = "square_size: 0.05 differs from the board's 0.03"
    with pytest.raises(ValueError, match=re.escape(differs)):
        calibrate(left, right, board=BOARD, square_size=0.05)
    with pytest.raises(
        TypeError, match=re.escape("board: expected a stereovision.charuco.CharucoBoard")
    ):
        calibrate(left, right, board="charuco")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="square_size: required for a chessboard"):
        calibrate(left, right)
    flat = [np.full((480, 640), 90, np.uint8)] * 3
    with pytest.raises(ValueError, match="no image shows enough markers"):
        calibrate(flat, flat, board=CharucoBoard("10x7", 0.03, 0.022))


def test_an_unresolved_board_blames_what_is_unknown(tmp_path: Path) -> None:
    """With the dictionary given (an even number of rows, so the layout unknown), the error
    still said "to tell its dictionary; give dictionary= ...", also from the CLI."""
    import argparse

    from stereovision.calibrate import add_cli

    flat = [np.full((480, 640), 90, np.uint8)] * 3
    with pytest.raises(ValueError) as err:
        calibrate(flat, flat, board=CharucoBoard("10x6", 0.03, 0.022, "DICT_5X5_100"))
    msg = str(err.value)
    assert msg.startswith(
        "no image shows the 10x6 ChArUco board's DICT_5X5_100 markers well enough to tell its "
        "layout: check that the board has these squares and markers of that dictionary"
    )
    assert "legacy=True for OpenCV's pre-4.6" in msg and "give it" not in msg
    for i in range(3):
        cv2.imwrite(str(tmp_path / f"L{i}.png"), flat[0])
    parser = argparse.ArgumentParser(prog="stereovision")
    add_cli(parser.add_subparsers(dest="command", required=True))
    base = ["calibrate", "--left", str(tmp_path / "L*.png"), "--right", str(tmp_path / "L*.png"),
            "--board", "charuco", "--square", "0.03", "--marker", "0.022",
            "-o", str(tmp_path / "rig.yaml")]  # fmt: skip
    for extra, said in (
        (["--pattern", "10x6", "--dictionary", "DICT_5X5_100"], "(--legacy for OpenCV's pre-4.6 "),
        (["--pattern", "10x7"], "dictionary; give it (e.g. --dictionary DICT_5X5_100)"),
    ):
        args = parser.parse_args([*base, *extra])
        with pytest.raises(ValueError) as err:
            args.func(args)
        assert said in str(err.value) and "=" not in str(err.value), str(err.value)


# -------------------------------------------------------------------------- printable board


def _png_chunks(data: bytes) -> dict[bytes, bytes]:
    out, pos = {}, 8
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        (crc,) = struct.unpack(">I", data[pos + 8 + n : pos + 12 + n])
        assert crc == zlib.crc32(kind + body) & 0xFFFFFFFF
        out[kind] = body
        pos += 12 + n
    return out


def test_board_png_prints_at_its_true_size() -> None:
    """The file stored the requested 300 dpi (11811 px/m) while the square is a whole 354 px:
    it printed at 29.97 mm. It stores 354 px / 30 mm = 11800 px/m, the square's exact size."""
    data, (w, h) = board_png(BOARD, 0.03, dpi=300)
    ppm = struct.unpack(">IIB", _png_chunks(data)[b"pHYs"])
    side = round(0.03 / 0.0254 * 300)  # 354 px per 30 mm square
    assert ppm == (11800, 11800, 1) and side / ppm[0] == pytest.approx(0.03, abs=1e-9)
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_GRAYSCALE)
    assert img.shape == (h, w) == (9 * side, 12 * side)
    found = find_charuco_corners(img, CharucoBoard("10x7", 0.03, 0.022))
    assert found is not None and len(found[0]) == BOARD.n_corners
    # Corner id 0 sits one margin plus one square from the top-left, at pixel centre - 0.5.
    np.testing.assert_allclose(found[1][0], (2 * side - 0.5, 2 * side - 0.5), atol=0.1)
    chess, (cw, ch) = board_png((9, 6), 0.025, dpi=200)
    img = cv2.imdecode(np.frombuffer(chess, np.uint8), cv2.IMREAD_GRAYSCALE)
    assert img.shape == (ch, cw) and cv2.findChessboardCornersSB(img, (9, 6))[0]
    with pytest.raises(ValueError, match="10 to 20000 px per square"):
        board_png(BOARD, 0.0005, dpi=300)


# ---------------------------------------------------------------------------------------- CLI


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    """``stereovision *args`` run in-process (1 s of CPU a subprocess spent importing; no test
    here is about the process): its exit status (``main``'s, or argparse's ``SystemExit``),
    stdout and stderr, as ``subprocess.run`` gives them."""
    from stereovision.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(list(args))
        except SystemExit as stop:
            code = stop.code if isinstance(stop.code, int) else 1
    return subprocess.CompletedProcess(
        ["stereovision", *args], code, out.getvalue(), err.getvalue()
    )


def test_cli_board_then_calibrate(rig: dict[str, Any], tmp_path: Path) -> None:
    run = _cli("board", "-o", str(tmp_path / "b.png"), "--board", "charuco", "--pattern", "10x7",
               "--square", "30", "--unit", "mm", "--marker", "22")  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "DICT_5X5_50" in run.stdout and "30.00 mm squares" in run.stdout
    assert "4248x3186 px at 11800 px/m (299.72 dpi: 354 px per square at 300 dpi)" in run.stdout
    assert "it is 360.0 x 270.0 mm" in run.stdout
    data = (tmp_path / "b.png").read_bytes()
    assert struct.unpack(">IIB", _png_chunks(data)[b"pHYs"]) == (11800, 11800, 1)
    assert find_charuco_corners(cv2.imread(str(tmp_path / "b.png"), 0), BOARD) is not None
    for i in range(6):
        cv2.imwrite(str(tmp_path / f"left{i:02d}.png"), rig["left"][i])
        cv2.imwrite(str(tmp_path / f"right{i:02d}.png"), rig["right"][i])
    out = tmp_path / "rig.yaml"
    run = _cli("calibrate", "--left", str(tmp_path / "left*.png"), "--right",
               str(tmp_path / "right*.png"), "--board", "charuco", "--pattern", "10x7",
               "--square", "30", "--unit", "mm", "--marker", "22", "-o", str(out))  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "6/6 pairs used" in run.stdout and "ChArUco 10x7 squares" in run.stdout
    from stereovision.calibration import Calibration

    cal = Calibration.load(out)
    assert cal.unit == "mm" and abs(np.linalg.norm(cal.T) - 120.0) < 0.5


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--board", "charuco", "--pattern", "10x7"], "--marker: give the ChArUco marker's side"),
        (["--board", "charuco", "--marker", "0.02"], "--pattern: give the ChArUco board's"),
        (["--marker", "0.02"], "--marker, --dictionary and --legacy are for --board charuco"),
        (
            ["--board", "charuco", "--pattern", "10x7", "--marker", "0.04"],
            "--marker: 0.04 must be smaller than --square 0.03",
        ),
    ],
)
def test_cli_board_errors_are_one_line(args: list[str], match: str, tmp_path: Path) -> None:
    (tmp_path / "x.png").write_bytes(b"")
    images = ["--left", str(tmp_path / "x.png"), "--right", str(tmp_path / "x.png")]
    for cmd in (
        ["board", "-o", str(tmp_path / "b.png")],
        ["calibrate", "-o", str(tmp_path / "c.yaml"), *images],
    ):
        run = _cli(*cmd, "--square", "0.03", *args)
        assert run.returncode == 2 and run.stderr.count("\n") == 1, run.stderr
        assert match in run.stderr
    assert not (tmp_path / "b.png").exists() and not (tmp_path / "c.yaml").exists()


def _write_video(path: Path, frames: list[np.ndarray]) -> Path:
    vw = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10.0, SIZE)
    assert vw.isOpened()
    for f in frames:
        vw.write(cv2.cvtColor(f, cv2.COLOR_GRAY2BGR))
    vw.release()
    return path


def test_calibrate_from_two_videos(rig: dict[str, Any], tmp_path: Path) -> None:
    """Two MJPG recordings of the board waved about, each pose held for two frames: the
    distinct poses are kept (the repeats are not) and the rig comes back (|T| within 0.5 mm);
    the CLI takes the two videos in place of the image globs."""
    from stereovision.calibrate import calibrate_from_video

    frames = [i for i in range(10) for _ in range(2)]
    left = _write_video(tmp_path / "l.avi", [rig["left"][i] for i in frames])
    right = _write_video(tmp_path / "r.avi", [rig["right"][i] for i in frames])
    lines: list[str] = []
    cal, rep = calibrate_from_video(left, right, board=CharucoBoard("10x7", 0.03, 0.022),
                                    log=lines.append)  # fmt: skip
    kept = len(rep.used_pairs) + len(rep.rejected_pairs)
    assert lines == [
        f"{kept} of 20 frame pairs kept (a quick look saw the board in both views, in a new pose)"
    ]
    assert 7 <= kept <= 10 and all(n.startswith("frame_") for n in rep.used_pairs)
    assert abs(np.linalg.norm(cal.T) - np.linalg.norm(T)) < 5e-4
    assert "DICT_5X5_50" in rep.board  # found while reading
    out = tmp_path / "rig.yaml"
    board_args = [
        "--board",
        "charuco",
        "--pattern",
        "10x7",
        "--square",
        "0.03",
        "--marker",
        "0.022",
    ]
    run = _cli("calibrate", "--left", str(left), "--right", str(right), *board_args, "-o", str(out))
    assert run.returncode == 0, run.stderr
    assert "of 20 frame pairs kept" in run.stdout and out.is_file()
    run = _cli("calibrate", "--left", str(left), "--right", str(tmp_path / "x*.png"),
               "--square", "0.03", "-o", str(out))  # fmt: skip
    assert run.returncode == 2 and "give two videos, or two sets of images" in run.stderr
    with pytest.raises(FileNotFoundError, match="left source not found"):
        calibrate_from_video(tmp_path / "none.avi", right, board=BOARD)
    with pytest.raises(ValueError, match="max_pairs"):
        calibrate_from_video(str(left), str(right), board=BOARD, max_pairs=2)


def test_a_recording_cut_short_by_max_pairs_is_said_and_recorded(
    rig: dict[str, Any], tmp_path: Path
) -> None:
    """``max_pairs`` (``--max-pairs``, 60 by default) stops reading a recording once that many
    poses are kept; the line said "3 of 3 frame pairs kept" and the report nothing, so a run cut
    short looked like a short recording. The line and report.json's ``pair_selection`` say where
    the reading stopped."""
    from stereovision.calibrate import calibrate_from_video

    left = _write_video(tmp_path / "l.avi", rig["left"][:8])
    right = _write_video(tmp_path / "r.avi", rig["right"][:8])
    lines: list[str] = []
    _, rep = calibrate_from_video(left, right, board=BOARD, max_pairs=3, log=lines.append)
    last = max([*rep.used_pairs, *rep.rejected_pairs])
    read = int(last.split("_")[1]) + 1
    assert lines == [
        f"3 of {read} frame pairs kept (a quick look saw the board in both views, in a new "
        f"pose); max_pairs=3 reached: what follows {last} was not read"
    ]
    assert rep.pair_selection == {
        "option": "max_pairs=3",
        "rule": f"the first 3 distinct board poses in the recording's order; what follows {last} "
        "was not read",
        "frames_read": read,
        "kept": 3,
        "last_frame_read": last,
    }
    assert rep.summary().splitlines()[4] == (
        f"reading stopped by max_pairs=3 (the first 3 distinct board poses in the recording's "
        f"order; what follows {last} was not read)"
    )
    board_args = ["--board", "charuco", "--pattern", "10x7", "--square", "0.03"]
    board_args += ["--marker", "0.022", "--max-pairs", "3", "--report", str(tmp_path / "rep")]
    run = _cli("calibrate", "--left", str(left), "--right", str(right), *board_args,
               "-o", str(tmp_path / "rig.yaml"))  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert f"; --max-pairs 3 reached: what follows {last} was not read\n" in run.stdout
    assert "reading stopped by --max-pairs 3 (the first 3 " in run.stdout
    saved = json.loads((tmp_path / "rep" / "report.json").read_text())["pair_selection"]
    assert saved == {**rep.pair_selection, "option": "--max-pairs 3"}
    # all of a recording read: nothing recorded
    _, rep = calibrate_from_video(left, right, board=BOARD, max_pairs=60)
    assert rep.pair_selection == {}


def test_a_wrong_dictionary_or_squares_is_named_from_the_markers_seen(
    rig: dict[str, Any],
) -> None:
    """The 10x7 DICT_5X5 board given as DICT_4X4_100 was "found in both images of only 0 of 4
    pairs" with no word of why; given as 7x10 (rows first) with the dictionary found from the
    images, the error said to give the dictionary, which was not what was wrong. Both now say
    what the first image's markers show."""
    left, right = rig["left"][:4], rig["right"][:4]
    with pytest.raises(
        ValueError,
        match=r"found in both images of only 0 of 4 pairs; at least 3 are needed; "
        r"left_images\[0\] shows 35 markers of DICT_5X5, not of DICT_4X4_100: give the board's "
        r"dictionary \(e\.g\. dictionary='DICT_5X5_50'\)",
    ):
        calibrate(left, right, board=CharucoBoard("10x7", 0.03, 0.022, "DICT_4X4_100"))
    with pytest.raises(
        ValueError,
        match=r"^the 7x10 ChArUco board was not found: left_images\[0\] shows 35 of its DICT_5X5 "
        r"markers, but not as a 7x10-square board's: check the squares \(columns x rows\)",
    ):
        calibrate(left, right, board=CharucoBoard("7x10", 0.03, 0.022))
    # Boards found, only too few pairs: no word of dictionary or squares.
    with pytest.raises(ValueError) as err:
        calibrate(left[:2], right[:2], board=BOARD)
    assert str(err.value).endswith(
        "found in both images of only 2 of 2 pairs; at least 3 are needed"
    )
    from stereovision.calibrate import _cli_words

    assert _cli_words("(e.g. dictionary='DICT_5X5_50')") == "(e.g. --dictionary DICT_5X5_50)"


def test_a_wrong_dictionary_of_a_family_with_the_same_prefix_is_named() -> None:
    """A board of DICT_APRILTAG_36H11 markers given as DICT_APRILTAG_25H9 (or DICT_ARUCO_ORIGINAL
    as DICT_ARUCO_MIP_36H12) was said to show "35 of its DICT_APRILTAG markers, but not as a
    10x7-square board's: check the squares": the family was the name up to its last '_', so
    two families sharing a prefix were taken for one. The squares were right, the dictionary
    was not."""
    for printed, given in (
        ("DICT_APRILTAG_36H11", "DICT_APRILTAG_25H9"),
        ("DICT_ARUCO_ORIGINAL", "DICT_ARUCO_MIP_36H12"),
    ):
        board = CharucoBoard("10x7", 0.03, 0.022, printed)
        left, right = [], []
        for rv, tv in _poses(3, seed=7):
            left.append(render_charuco(board, K1, D1, rv, tv, supersample=SS))
            r2, t2 = _right_pose(rv, tv)
            right.append(render_charuco(board, K2, D2, r2, t2, supersample=SS))
        with pytest.raises(
            ValueError,
            match=rf"left_images\[0\] shows 35 markers of {printed}, not of {given}: give the "
            rf"board's dictionary \(e\.g\. dictionary='{printed}'\)",
        ):
            calibrate(left, right, board=CharucoBoard("10x7", 0.03, 0.022, given))


def test_an_odd_rowed_board_is_not_described_as_a_legacy_layout() -> None:
    """OpenCV's legacy layout differs only with an even number of rows; ``board --legacy
    --pattern 9x7`` printed the same image as without it, yet said '(legacy layout)' (and the
    calibration's report after it), as if the print needed --legacy to be read."""
    odd = CharucoBoard("9x7", 0.03, 0.022, "DICT_5X5_50", legacy=True)
    assert odd.describe("m") == (
        "ChArUco 9x7 squares (8x6 inner corners), square 0.03 m, marker 0.022 m, DICT_5X5_50"
    )
    assert np.array_equal(odd.image(40), CharucoBoard("9x7", 0.03, 0.022, "DICT_5X5_50").image(40))
    even = CharucoBoard("10x8", 0.03, 0.022, "DICT_5X5_50", legacy=True)
    assert even.describe().endswith("DICT_5X5_50 (legacy layout)")


def test_cli_board_keeps_a_file_it_replaces(tmp_path: Path) -> None:
    """``board -o board.png`` over an existing file (another board printed earlier, the user's
    picture) replaced it without a word; it is copied aside as board.previous.png, said."""
    out = tmp_path / "board.png"
    out.write_bytes(b"my picture")
    run = _cli("board", "-o", str(out), "--pattern", "9x6", "--square", "0.03")
    assert run.returncode == 0, run.stderr
    kept = tmp_path / "board.previous.png"
    assert kept.read_bytes() == b"my picture"
    assert run.stdout.splitlines()[0].endswith(f"(the one it replaced kept as {kept})")
    assert cv2.imread(str(out)) is not None


def test_cli_board_written_again_keeps_no_copy_of_itself(tmp_path: Path) -> None:
    """The same ``board -o board.png`` run twice made board.previous.png, the new board byte
    for byte, and said it kept "the one it replaced": the same bytes again replace nothing."""
    out = tmp_path / "board.png"
    for _ in range(2):
        run = _cli("board", "-o", str(out), "--pattern", "9x6", "--square", "0.03")
        assert run.returncode == 0, run.stderr
        assert run.stdout.splitlines()[0] == f"{out}: chessboard 9x6 inner corners, square 0.03 m"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["board.png"]


def test_each_cameras_stereo_rms_pools_every_corner(six: tuple[Any, Any]) -> None:
    """Each camera's share of the stereo RMS is over all its corners, so a view of a cut board
    (fewer corners) weighs less; a mutation audit found it checked on whole boards only, where
    the mean of the views' RMS is the same. Independently: cv2.stereoCalibrateExtended, re-run
    from the solution, gives each view's board pose; cv2.projectPoints the pooled residuals."""
    from stereovision.calibrate import board_object_points

    cal, rep = six
    names = rep.used_pairs
    assert len({len(rep._ids[n]) for n in names}) > 1  # views with different corner counts
    grid = board_object_points(BOARD.inner, BOARD.square_size)
    obj = [grid[rep._ids[n]] for n in names]
    left = [rep._corners[n][0].astype(np.float32) for n in names]
    right = [rep._corners[n][1].astype(np.float32) for n in names]
    out = cv2.stereoCalibrateExtended(
        obj, left, right, cal.K1.copy(), cal.D1.copy(), cal.K2.copy(), cal.D2.copy(),
        cal.image_size, cal.R.copy(), cal.T.reshape(3, 1).copy(),
        flags=cv2.CALIB_FIX_INTRINSIC | cv2.CALIB_USE_EXTRINSIC_GUESS,
    )  # fmt: skip
    rvecs, tvecs = out[9], out[10]
    for side, K, D, pts in (("left", cal.K1, cal.D1, left), ("right", cal.K2, cal.D2, right)):
        sq: list[np.ndarray] = []
        for o, p, rv, tv in zip(obj, pts, rvecs, tvecs, strict=True):
            if side == "right":
                rv, tv = cv2.composeRT(rv, tv, cv2.Rodrigues(cal.R)[0], cal.T.reshape(3, 1))[:2]
            proj = cv2.projectPoints(o.astype(np.float64), rv, tv, K, D)[0].reshape(-1, 2)
            sq.append(np.sum((proj - p) ** 2, axis=1))
        pooled = math.sqrt(float(np.mean(np.concatenate(sq))))
        assert getattr(rep, f"stereo_rms_{side}") == pytest.approx(pooled, rel=1e-4)


def test_board_limits_are_inclusive() -> None:
    """A mutation audit found the limits unasserted at their edges: a board of exactly 2320
    markers (the largest dictionary's size) and one of exactly a dictionary's size are boards;
    an odd count of squares has ``cols * rows // 2`` markers, as OpenCV's board."""
    assert CharucoBoard("80x58", 0.03, 0.02).n_markers == 2320
    full = CharucoBoard("10x10", 0.03, 0.02, "DICT_4X4_50")
    assert full.n_markers == 50 and full.dictionary == "DICT_4X4_50"
    odd = CharucoBoard("7x5", 0.03, 0.02, "DICT_4X4_50")
    assert odd.n_markers == len(odd.cv_board().getIds()) == 17
    assert odd.n_corners == 24 and odd.inner == (6, 4)


def test_dictionary_auto_takes_the_smallest_that_holds_the_board() -> None:
    """A 10x10 board has 50 markers: DICT_4X4_50 holds them all (not DICT_4X4_100)."""
    img = CharucoBoard("10x10", 0.03, 0.02, "DICT_4X4_50").image(40)
    found = CharucoBoard("10x10", 0.03, 0.02).resolve(img)
    assert found is not None and found.dictionary == "DICT_4X4_50"


def test_the_legacy_layout_is_told_by_the_rows_not_the_columns() -> None:
    """Only an even number of rows has two layouts: 9x8 is described as legacy, 8x7 not."""
    even_rows = CharucoBoard("9x8", 0.03, 0.02, "DICT_4X4_50", legacy=True)
    odd_rows = CharucoBoard("8x7", 0.03, 0.02, "DICT_4X4_50", legacy=True)
    assert even_rows.describe().endswith("DICT_4X4_50 (legacy layout)")
    assert odd_rows.describe().endswith("marker 0.02, DICT_4X4_50")


def test_board_image_size_and_its_limits() -> None:
    """The default margin is one square; a marker of exactly its dictionary's bits and
    border (7 px for 5x5) is drawn, a smaller one is refused by name, and so is an image
    over MAX_IMAGE_PIXELS."""
    board = CharucoBoard("7x5", 0.03, 0.02, "DICT_4X4_50")
    assert board.image(40).shape == (5 * 40 + 80, 7 * 40 + 80)
    assert board.image(40, margin=0).shape == (200, 280)
    assert CharucoBoard("5x5", 1.0, 0.7, "DICT_5X5_50").image(10).shape == (70, 70)
    with pytest.raises(ValueError, match=r"is 6.9 px at 10 px per square; DICT_5X5_50's "):
        CharucoBoard("5x5", 1.0, 0.69, "DICT_5X5_50").image(10)
    with pytest.raises(ValueError, match=r"a 19200x14400 image is over 2.5e\+08 pixels"):
        CharucoBoard("10x7", 0.03, 0.022, "DICT_5X5_50").image(1600)


def test_corners_on_one_line_do_not_span_the_board() -> None:
    from stereovision.charuco import corners_span_plane

    assert not corners_span_plane(BOARD, np.arange(9))  # one row
    assert not corners_span_plane(BOARD, np.array([0, 10, 20, 30]))  # a diagonal
    assert corners_span_plane(BOARD, np.array([0, 1, 9]))
    assert not corners_span_plane(BOARD, np.array([3]))
    assert not corners_span_plane(BOARD, np.array([], np.int64))
    # a strip of the board with its first row of corners: nine corners on one line, no view
    img = CharucoBoard("10x7", 0.03, 0.022, "DICT_5X5_50").image(40)
    assert find_charuco_corners(np.ascontiguousarray(img[:130]), BOARD) is None


def test_printed_chessboard_starts_black_and_refuses_a_huge_one() -> None:
    """The chessboard's first square (top left, inside the one-square margin) is black, as
    OpenCV's pattern; one over MAX_IMAGE_PIXELS is refused before it is drawn."""
    data, (w, h) = board_png((9, 6), 0.01, dpi=254)  # 100 px squares
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_GRAYSCALE)
    assert (w, h) == (1200, 900)
    assert img[100:200, 100:200].max() == 0 and img[100:200, 200:300].min() == 255
    assert img[:100].min() == 255  # the margin
    with pytest.raises(ValueError, match="a 60x40 chessboard at 354 px per square is too large"):
        board_png((60, 40), 0.03)
    # 10 px per square is the least: a 25.4 mm square at 10 dpi is one
    assert board_png((3, 3), 0.0254, dpi=10)[1] == (60, 60)
    with pytest.raises(ValueError, match=r"is 9\.99 px; .*giving 10 to 20000 px per square"):
        board_png((3, 3), 0.0254, dpi=9.99)  # it said "is 10.0 px" of a square it refused


def test_the_layout_of_an_even_rowed_board_is_found_whatever_its_columns() -> None:
    """A 7x8 board (odd columns, even rows) printed in the legacy layout, given with its
    dictionary but not its layout: the layout is looked for (the rows decide), all corners."""
    printed = CharucoBoard("7x8", 0.03, 0.02, "DICT_4X4_50", legacy=True)
    given = CharucoBoard("7x8", 0.03, 0.02, "DICT_4X4_50")
    assert not given.resolved
    found = find_charuco_corners(printed.image(40), given)
    assert found is not None and len(found[0]) == printed.n_corners == 42


def test_markers_seen_counts_the_boards_ids_and_two_settle_the_dictionary() -> None:
    """A 10x7 board's image shows 35 markers; a 7x5 board counts the 17 with its ids (0-16).
    A corner of the image with two of them (AUTO_MIN_MARKERS) settles the dictionary, one
    does not."""
    img = CharucoBoard("10x7", 0.03, 0.022, "DICT_5X5_50").image(40)
    assert CharucoBoard("7x5", 0.03, 0.02).markers_seen(img) == ("DICT_5X5_50", 17)
    auto = CharucoBoard("10x7", 0.03, 0.022)
    two, one = np.ascontiguousarray(img[:200, :100]), np.ascontiguousarray(img[:180, :100])
    assert auto.markers_seen(two) == ("DICT_5X5_50", 2)
    resolved = auto.resolve(two)
    assert resolved is not None and resolved.dictionary == "DICT_5X5_50"
    assert auto.markers_seen(one) == ("DICT_5X5_50", 1) and auto.resolve(one) is None


def test_six_corners_are_enough_and_four_are_not() -> None:
    """MIN_CORNERS (6) corners are found; 4 are not a view. The ids are those of the board's
    top-left corner, at their printed pixels (one margin and one square in: 80 px)."""
    img = CharucoBoard("10x7", 0.03, 0.022, "DICT_5X5_50").image(40)
    six = find_charuco_corners(np.ascontiguousarray(img[:160, :200]), BOARD)
    assert six is not None and six[0].tolist() == [0, 1, 2, 9, 10, 11]
    np.testing.assert_allclose(six[1][4], (120 - 0.5, 120 - 0.5), atol=0.2)
    assert find_charuco_corners(np.ascontiguousarray(img[:160, :160]), BOARD) is None


def test_calibrate_from_video_passes_numpy_indexes_as_cameras(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``np.int64(1)`` was made the file name "1" by ``str()`` (FileNotFoundError "left source
    not found: 1"); it is device 1, and a bool is refused as no source."""
    import stereovision.capture as capture

    seen: list[tuple[object, object]] = []

    class Opened(Exception):
        pass

    def fake(left: object, right: object, **_kw: object) -> None:
        seen.append((left, right))
        raise Opened

    with pytest.raises(ValueError, match=r"^left source: expected a device index or a path"):
        calibrate_from_video(np.True_, 0, board=BOARD)  # type: ignore[arg-type]
    monkeypatch.setattr(capture, "StereoCamera", fake)
    with pytest.raises(Opened):
        calibrate_from_video(np.int64(1), np.int32(2), board=BOARD)  # type: ignore[arg-type]
    assert seen == [(1, 2)] and all(isinstance(v, (int, np.integer)) for v in seen[0])


def test_no_marker_seen_names_no_dictionary() -> None:
    """An image without a marker: no family decodes any of the board's ids, and none is named
    (a tie at 0 took the last family tried, DICT_ARUCO_MIP_36H12)."""
    assert BOARD.markers_seen(np.full((240, 320), 200, np.uint8)) == ("", 0)
    auto = CharucoBoard("10x7", 0.03, 0.022)
    assert auto.markers_seen(np.full((240, 320), 200, np.uint8)) == ("", 0)


def test_board_png_refuses_over_20000_px_per_square_by_name() -> None:
    """A 1 m square at 600 dpi is 23622 px: refused by the square and dpi that make it, for a
    ChArUco board and a chessboard alike (not by the image's pixels_per_square it led to)."""
    for board in (BOARD, (9, 6)):
        with pytest.raises(ValueError, match=r"a 1000 mm square at 600 dpi is 23622 px; use a"):
            board_png(board, 1.0, 600)


def test_board_image_margin_is_checked() -> None:
    """The margin is 0 to 10 squares of pixels: a negative one or one over 10 squares is named."""
    board = CharucoBoard("7x5", 0.03, 0.02, "DICT_4X4_50")
    assert board.image(20, margin=200).shape == (5 * 20 + 400, 7 * 20 + 400)
    for bad in (-1, 201):
        with pytest.raises(ValueError, match="margin"):
            board.image(20, margin=bad)


def test_dictionary_names_ignore_surrounding_spaces() -> None:
    """A name as typed on a command line or read from a file, spaces around it, is the same
    dictionary."""
    assert dictionary_name(" 5x5_100 \n") == "DICT_5X5_100"


def test_rendered_board_grey_levels_run_from_25_to_230() -> None:
    """The board's black and white are drawn as 25 and 230 (a camera's, not 0 and 255), the
    background at its grey level."""
    rv, tv = np.zeros(3), np.array([-0.15, -0.1, 0.5])
    img = render_charuco(BOARD, K1, D1, rv, tv, supersample=SS, background=60)
    assert img.min() == 25 and img.max() == 230
    assert img[0, 0] == 60


def test_three_squares_a_side_is_a_board_and_two_are_not() -> None:
    """A mutation audit found the floor of 3 squares a side unasserted at its edge (``<= 3``
    refused a 3x4 board): 3x4 squares make 2x3 = 6 inner corners (:data:`MIN_CORNERS`)."""
    board = CharucoBoard("3x4", 0.03, 0.02, "DICT_4X4_50")
    assert board.inner == (2, 3) and board.n_corners == MIN_CORNERS and board.n_markers == 6
    for squares in ("2x4", "4x2"):
        with pytest.raises(ValueError, match="each at least 3"):
            CharucoBoard(squares, 0.03, 0.02)


def test_an_image_of_exactly_max_image_pixels_is_made(monkeypatch: pytest.MonkeyPatch) -> None:
    """The pixel limit is on the image as drawn, margins included, and inclusive: a ChArUco
    board's 360x280 image and a 9x6 chessboard's 1200x900 one are made at a limit of their
    own size and refused one pixel under it."""
    import stereovision.charuco as ch

    board = CharucoBoard("7x5", 0.03, 0.02, "DICT_4X4_50")
    for limit, made in ((360 * 280, True), (360 * 280 - 1, False)):
        monkeypatch.setattr(ch, "MAX_IMAGE_PIXELS", limit)
        if made:
            assert board.image(40).shape == (280, 360)
        else:
            with pytest.raises(ValueError, match="a 360x280 image is over"):
                board.image(40)
    for limit, made in ((1200 * 900, True), (1200 * 900 - 1, False)):
        monkeypatch.setattr(ch, "MAX_IMAGE_PIXELS", limit)
        if made:
            assert board_png((9, 6), 0.01, dpi=254)[1] == (1200, 900)
        else:
            with pytest.raises(ValueError, match="a 9x6 chessboard at 100 px per square is too"):
                board_png((9, 6), 0.01, dpi=254)


def test_a_layout_tie_keeps_the_current_layout(monkeypatch: pytest.MonkeyPatch) -> None:
    """A mutation audit found the layout's tie unasserted (``>=`` chose the legacy one): when
    both layouts give as many corners, the board keeps OpenCV's current layout, legacy only
    for more corners."""
    import stereovision.charuco as ch

    board = CharucoBoard("10x8", 0.03, 0.022, "DICT_5X5_100")
    img = CharucoBoard("10x8", 0.03, 0.022, "DICT_5X5_100", legacy=False).image(40)
    found = {False: 12, True: 12}
    fake = (np.arange(20), np.zeros((20, 2)))

    def corners(image: Any, b: CharucoBoard) -> Any:
        n = found[bool(b.legacy)]
        return (fake[0][:n], fake[1][:n])

    monkeypatch.setattr(ch, "find_charuco_corners", corners)
    resolved = board.resolve(img)
    assert resolved is not None and resolved.legacy is False
    found[True] = 13
    resolved = board.resolve(img)
    assert resolved is not None and resolved.legacy is True


def test_render_refuses_over_2000_px_per_square() -> None:
    """A mutation audit found render_charuco's bound unasserted (20000 let a small board through
    to a 10000x12000 lookup image): 2001 px per square is refused by name."""
    board = CharucoBoard("3x4", 0.03, 0.02, "DICT_4X4_50")
    with pytest.raises(ValueError, match="pixels_per_square"):
        render_charuco(board, K1, D1, np.zeros(3), np.array([0, 0, 0.5]), pixels_per_square=2001)


def test_render_names_pixels_per_square_of_a_board_image_past_remaps_sides() -> None:
    """A long board (25x3) at 1300 px a square is a 35100x6500 image, past cv2.remap's 32766
    a side: render_charuco drew it (5 s, 1 GB) and then failed with render_plane's 'texture:
    ... shrink it and scale units_per_pixel up as much', neither its argument; it now names
    pixels_per_square and its bound up front, before drawing the board."""
    board = CharucoBoard("25x3", 0.04, 0.03, "DICT_5X5_100")
    pose = (np.zeros(3), np.array([-0.2, -0.1, 0.6]))
    with pytest.raises(ValueError) as exc:
        render_charuco(board, K1, D1, *pose, image_size=(16, 12), pixels_per_square=1214)
    assert str(exc.value) == (
        "pixels_per_square: a 25x3 board of 1214 px squares is a 32778x6070 image (its margin "
        "of one square included), past OpenCV's remap's 32766 a side; use at most 1213 pixels "
        "per square"
    )


def test_a_boards_fields_are_stored_as_plain_python_values() -> None:
    """A mutation audit found the stored fields unasserted: sizes given as NumPy numbers (a
    size-1 array among them) are kept as floats (an array left the board unhashable for its
    OpenCV cache), a short dictionary name as OpenCV's (``getattr(cv2.aruco, "5x5_100")``
    failed), a NumPy bool layout as a bool (``json.dumps`` refused ``np.True_``)."""
    board = CharucoBoard("7x5", np.array([0.03]), np.float32(0.02), " 5x5_100", legacy=np.True_)
    assert type(board.square_size) is float and board.square_size == 0.03
    assert type(board.marker_size) is float and board.marker_size == float(np.float32(0.02))
    assert board.dictionary == "DICT_5X5_100" and board.legacy is True
    assert CharucoBoard("7x6", 0.03, 0.02, legacy=0).legacy is False
    assert json.loads(json.dumps([board.square_size, board.legacy])) == [0.03, True]
    assert board.image(40).shape == (280, 360)


def test_board_image_refuses_under_10_px_per_square() -> None:
    """10 px per square is the least :meth:`CharucoBoard.image` draws (a mutant taking 9 drew a
    4x4 marker of 6.3 px): 9 is refused by name."""
    board = CharucoBoard("5x5", 1.0, 0.7, "DICT_4X4_50")
    assert board.image(10).shape == (70, 70)
    with pytest.raises(ValueError, match="pixels_per_square"):
        board.image(9)


def test_a_row_of_corners_and_one_more_spans_the_board() -> None:
    """The collinearity test is relative to the spread of the corners, not a loose ratio: a
    whole row (9 corners) and the first corner of the next one span the board (their smaller
    singular value is 0.099 of the larger)."""
    from stereovision.charuco import corners_span_plane

    assert corners_span_plane(BOARD, np.arange(10))
    assert not corners_span_plane(BOARD, np.arange(9))


def test_found_ids_are_ascending_with_their_corners(monkeypatch: pytest.MonkeyPatch) -> None:
    """The ids are sorted, each corner kept with its id, whatever order the detector gave."""
    import stereovision.charuco as ch

    ids = np.array([10, 1, 2, 9, 0, 11])
    corners = np.stack([ids * 10.0, ids + 0.5], 1).astype(np.float32).reshape(-1, 1, 2)

    class Detector:
        def detectBoard(self, _gray: Any) -> tuple[Any, Any, None, None]:
            return corners, ids.reshape(-1, 1), None, None

    monkeypatch.setattr(ch, "_detector", lambda _board: Detector())
    found = find_charuco_corners(np.zeros((40, 40), np.uint8), BOARD)
    assert found is not None and found[0].tolist() == [0, 1, 2, 9, 10, 11]
    np.testing.assert_array_equal(found[1], np.stack([found[0] * 10.0, found[0] + 0.5], 1))


def test_each_board_gets_a_detector_of_its_own_marker_size() -> None:
    """The detector cache is keyed by the whole board: two boards differing only in their
    markers' size do not share OpenCV's detector (and its board)."""
    from stereovision.charuco import _detector

    big = CharucoBoard("5x4", 0.03, 0.022, "DICT_4X4_50", legacy=False)
    small = replace(big, marker_size=0.012)
    assert _detector(big).getBoard().getMarkerLength() == pytest.approx(0.022)
    assert _detector(small).getBoard().getMarkerLength() == pytest.approx(0.012)


def test_render_supersample_antialiases_the_edges() -> None:
    """One ray a pixel gives the board's few grey levels (25, 230, the background, and the
    lookup's own blend at its pixel edges); four a side blend the edges into many."""
    K = np.array([[200.0, 0, 79.5], [0, 200, 59.5], [0, 0, 1]])
    board = CharucoBoard("3x4", 0.03, 0.02, "DICT_4X4_50")
    pose = (np.zeros(3), np.array([-0.045, -0.06, 0.3]))
    kw: dict[str, Any] = {"image_size": (160, 120)}
    images = [render_charuco(board, K, np.zeros(5), *pose, supersample=s, **kw) for s in (1, 4)]
    levels = [len(np.unique(img)) for img in images]
    assert levels[0] <= 6 and levels[1] >= 15


def test_object_points_are_float32_at_the_corners() -> None:
    """OpenCV's calibration takes ``float32`` board points: corner 10 of a 9-wide grid is the
    second column of the second row, two squares in from the top-left outer corner."""
    pts = BOARD.object_points([0, 10])
    assert pts.dtype == np.float32
    np.testing.assert_allclose(pts, [[0.03, 0.03, 0], [0.06, 0.06, 0]], rtol=1e-6)


def test_board_png_rounds_its_resolution_to_the_nearest_pixel_per_metre() -> None:
    """A 30 mm square at 200 dpi is 236 px: 7866.67 px/m is stored as 7867, printing it 1.3 um
    short (truncated to 7866 it was 2.5 um long)."""
    data, _ = board_png((3, 3), 0.03, dpi=200)
    assert struct.unpack(">IIB", _png_chunks(data)[b"pHYs"]) == (7867, 7867, 1)


def test_an_even_rowed_board_in_the_current_layout_is_not_called_legacy() -> None:
    """``legacy=False`` (OpenCV's current layout, as decided) is not described as the legacy
    one, and an undecided layout (None) is not either."""
    for legacy in (False, None):
        board = CharucoBoard("9x8", 0.03, 0.02, "DICT_4X4_50", legacy=legacy)
        assert board.describe().endswith("marker 0.02, DICT_4X4_50")


def test_board_png_refuses_a_huge_charuco_board_by_its_square_and_dpi(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A 200 mm square at 600 dpi (4724 px) makes a ChArUco image over MAX_IMAGE_PIXELS: it was
    refused as "pixels_per_square: ... use fewer pixels per square", an argument board_png
    has not; it is named as the chessboard's is, by the board and its pixels per square (the
    limit inclusive, margins counted)."""
    import stereovision.charuco as ch

    with pytest.raises(ValueError, match=r"^a 10x7 ChArUco board at 4724 px per square is too"):
        board_png(BOARD, 0.2, 600)
    with pytest.raises(ValueError, match=r"^a 9x6 chessboard at 4724 px per square is too large"):
        board_png((9, 6), 0.2, 600)
    monkeypatch.setattr(ch, "MAX_IMAGE_PIXELS", 1200 * 900)  # 10x7 squares and margins, 100 px
    assert board_png(BOARD, 0.01, dpi=254)[1] == (1200, 900)
    monkeypatch.setattr(ch, "MAX_IMAGE_PIXELS", 1200 * 900 - 1)
    with pytest.raises(ValueError, match=r"^a 10x7 ChArUco board at 100 px per square is too"):
        board_png(BOARD, 0.01, dpi=254)


def test_a_board_too_large_to_print_says_the_largest_square_in_pixels_and_dpi(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """ "a 9x6 chessboard at 4724 px per square is too large" gave no limit: it says the most
    pixels per square the board may have (its image with margins within MAX_IMAGE_PIXELS) and
    the dpi giving them at the square asked for."""
    import stereovision.charuco as ch

    # 9x6 inner corners: 10x7 squares and a one-square margin, 12x9 squares of 1521 px at most
    assert 12 * 9 * 1521**2 <= ch.MAX_IMAGE_PIXELS < 12 * 9 * 1522**2
    with pytest.raises(
        ValueError,
        match=r"^a 9x6 chessboard at 4724 px per square is too large \(over 2\.5e\+08 pixels "
        r"with its margins\): at most 1521 px per square, 200 mm squares at up to 193\.167 dpi$",
    ):
        board_png((9, 6), 0.2, 600)
    with pytest.raises(ValueError, match=r"at most 1521 px per square, 200 mm squares at up to"):
        board_png(BOARD, 0.2, 600)  # 10x7 squares, as the 9x6 chessboard's
    # the limit said is one that passes: 100 px squares of 10 mm are 254 dpi
    monkeypatch.setattr(ch, "MAX_IMAGE_PIXELS", 12 * 9 * 100**2 + 99)
    with pytest.raises(
        ValueError, match=r"at most 100 px per square, 10 mm squares at up to 254 dpi"
    ):
        board_png((9, 6), 0.01, 260)
    assert board_png((9, 6), 0.01, 254)[1] == (1200, 900)
    # no square small enough: a board whose 10 px squares are already too many pixels
    monkeypatch.setattr(ch, "MAX_IMAGE_PIXELS", 12 * 9 * 10**2 - 1)
    with pytest.raises(
        ValueError, match=r"margins\), even at 10 px per square \(the least\): use fewer squares$"
    ):
        board_png((9, 6), 0.01, 254)


@pytest.mark.parametrize("most", [10, 11])
def test_the_dpi_a_too_large_board_suggests_is_accepted_typed_back(
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    most: int,
) -> None:
    """The dpi said for the largest square was rounded to 6 digits to the nearest: at the
    10 px floor, "70 mm squares at up to 3.62857 dpi" typed back is 9.99999 px, refused as
    under 10 px per square. It is rounded toward the side that is accepted: typed back (in
    metres, or in mm as the CLI's --square) it gives exactly the largest square said."""
    import stereovision.charuco as ch
    from stereovision.cli import main

    monkeypatch.setattr(ch, "MAX_IMAGE_PIXELS", 12 * 9 * most**2 + 99)
    said = re.compile(rf"at most {most} px per square, ([\d.]+) mm squares at up to ([\d.]+) dpi$")
    for tenth_mm in range(5, 3000, 7):  # 0.5 to 300 mm: at 10 px, 211 of 428 refused before
        with pytest.raises(ValueError, match=said) as refused:
            board_png((9, 6), tenth_mm / 10000, 1000 * 0.0254 / (tenth_mm / 10000))
        m = said.search(str(refused.value))
        assert m is not None and float(m[1]) == tenth_mm / 10
        for metres in (float(f"{m[1]}e-3"), float(m[1]) / 1000, float(m[1]) * 1e-3):
            assert board_png((9, 6), metres, float(m[2]))[1] == (12 * most, 9 * most)
    out = str(tmp_path / "b.png")
    argv = ["board", "-o", out, "--pattern", "9x6", "--square", "70", "--unit", "mm"]
    assert main([*argv, "--dpi", "300"]) == 2
    m = said.search(capsys.readouterr().err.strip())
    assert m is not None and m[1] == "70"
    assert main([*argv, "--dpi", m[2]]) == 0
    assert cv2.imread(out, cv2.IMREAD_GRAYSCALE).shape == (9 * most, 12 * most)


def test_the_triangulated_square_sides_pair_partial_boards_corners_by_their_ids(
    six: tuple[Any, Any],
) -> None:
    """The report's square sides are measured between grid neighbours, which a cut board's
    corners must be placed by their ids to find. A fourth mutation audit found them placed in
    the order seen unasserted: the median side passed (30.05 mm for 30.00: most consecutive
    corners are still neighbours) while the spread went from 0.45 % of the square to 152 %.
    Independently: cv2.stereoRectify (alpha 0), cv2.undistortPoints and cv2.triangulatePoints,
    each corner at its id in the 9x6 grid."""
    cal, rep = six
    assert any(len(rep._ids[n]) < BOARD.n_corners for n in rep.used_pairs)  # cut boards
    R1, R2, P1, P2, *_ = cv2.stereoRectify(
        cal.K1, cal.D1, cal.K2, cal.D2, cal.image_size, cal.R, cal.T.reshape(3, 1),
        flags=cv2.CALIB_ZERO_DISPARITY, alpha=0,
    )  # fmt: skip
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 40, 1e-12)
    cols, rows = BOARD.inner
    sides = []
    for name in rep.used_pairs:
        cl, cr = rep._corners[name]
        ul = cv2.undistortPoints(cl.reshape(-1, 1, 2), cal.K1, cal.D1, R=R1, P=P1, criteria=crit)
        ur = cv2.undistortPoints(cr.reshape(-1, 1, 2), cal.K2, cal.D2, R=R2, P=P2, criteria=crit)
        Xh = cv2.triangulatePoints(P1, P2, ul.reshape(-1, 2).T, ur.reshape(-1, 2).T)
        grid = np.full((rows * cols, 3), np.nan)
        grid[rep._ids[name]] = (Xh[:3] / Xh[3]).T
        X = grid.reshape(rows, cols, 3)
        sides += [np.linalg.norm(np.diff(X, axis=a), axis=2).ravel() for a in (0, 1)]
    side = np.concatenate(sides)
    side = side[np.isfinite(side)]
    assert rep.square_size_measured == pytest.approx(float(np.median(side)), rel=1e-6)
    assert rep.square_size_std == pytest.approx(float(side.std()), rel=1e-4)
    assert rep.square_size_std < 0.01 * BOARD.square_size


def test_a_cut_legacy_board_is_not_read_in_the_other_layout_a_square_off() -> None:
    """An 11x8 legacy board whose last column is out of view gave both layouts 27 corners and
    the tie chose the current layout: every id a square off (corners 55 px from where the board
    puts them). Its board reaches past the edge seen, black squares on the white margin: the
    legacy layout is found, and the corners are the board's."""
    true = CharucoBoard("11x8", 0.04, 0.03, "DICT_7X7_100", legacy=True)
    rv, tv = np.array([0.05, 0.1, 0.0]), np.array([-0.05, -0.06, 0.45])
    img = render_charuco(true, K1, D1, rv, tv, supersample=SS)
    wrong = find_charuco_corners(img, replace(true, legacy=False))
    right = find_charuco_corners(img, true)
    assert wrong is not None and right is not None and len(wrong[0]) == len(right[0])  # a tie
    found = CharucoBoard("11x8", 0.04, 0.03).resolve(img)
    assert found is not None and found.legacy is True
    got = find_charuco_corners(img, CharucoBoard("11x8", 0.04, 0.03))
    assert got is not None
    np.testing.assert_array_equal(got[0], right[0])
    err = np.linalg.norm(got[1] - _project(true, got[0], rv, tv, K1, D1), axis=1)
    assert err.max() < 0.5
    # the board in full view: either layout's count and squares still agree on the legacy one
    rv, tv = np.array([0.1, -0.2, 0.0]), np.array([-0.22, -0.15, 0.7])
    full = render_charuco(true, K1, D1, rv, tv, supersample=SS)
    found = CharucoBoard("11x8", 0.04, 0.03, "DICT_7X7_100").resolve(full)
    assert found is not None and found.legacy is True


def test_mutation_audit_5_white_black_squares_of_the_cut_legacy_board() -> None:
    """_white_black_squares of the cut legacy board above: none of the right layout's black
    squares is white, several of the wrong one's are (past the edge seen); an image without
    contrast where the corners were found tells nothing (None). The mutation audit found the
    count's threshold and the contrast check unasserted."""
    from stereovision.charuco import _white_black_squares

    true = CharucoBoard("11x8", 0.04, 0.03, "DICT_7X7_100", legacy=True)
    rv, tv = np.array([0.05, 0.1, 0.0]), np.array([-0.05, -0.06, 0.45])
    img = render_charuco(true, K1, D1, rv, tv, supersample=SS)
    gray = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    # a camera's noise: the black squares' centres are not all the darkest tone
    noise = np.random.default_rng(5).normal(0.0, 6.0, gray.shape)
    gray = np.clip(gray + noise, 0, 255).astype(np.uint8)
    wrong_board = replace(true, legacy=False)
    right, wrong = find_charuco_corners(img, true), find_charuco_corners(img, wrong_board)
    assert right is not None and wrong is not None
    assert _white_black_squares(gray, true, *right) == 0
    misplaced = _white_black_squares(gray, wrong_board, *wrong)
    assert misplaced is not None and misplaced >= 2
    assert _white_black_squares(np.full_like(gray, 128), true, *right) is None


def test_a_marker_size_opencv_cannot_draw_is_drawn_in_its_layout(tmp_path: Path) -> None:
    """OpenCV's generateImage fails its own ROI assertion for some marker sizes (21.6 px markers
    in 27 px squares: cv2.error; ``board --square 24 --unit mm --marker 21 --dpi 96``: "internal
    error"). Such a board is drawn in the same layout, and gives all its corners."""
    board = CharucoBoard((5, 4), 1.0, 0.8, "DICT_4X4_50")
    img = board.image(27)
    assert img.shape == (4 * 27 + 54, 5 * 27 + 54) and set(np.unique(img)) == {0, 255}
    big = cv2.resize(img, None, fx=4, fy=4, interpolation=cv2.INTER_LINEAR)
    found = find_charuco_corners(big, board)
    assert found is not None and len(found[0]) == board.n_corners
    want = board.object_points(found[0])[:, :2] * 27 * 4 + 27 * 4 - 0.5  # pixel centres, 4x
    assert np.abs(found[1] - want).max() < 1.0  # measured 0.57 px (of 108 px squares)
    run = _cli("board", "-o", str(tmp_path / "b.png"), "--board", "charuco", "--pattern", "5x4",
               "--square", "24", "--unit", "mm", "--marker", "21", "--dpi", "96",
               "--dictionary", "4x4_50")  # fmt: skip
    assert run.returncode == 0 and "internal error" not in run.stderr, run.stderr
    assert cv2.imread(str(tmp_path / "b.png"), 0).shape == (6 * 91, 7 * 91)


def test_the_drawn_board_is_opencvs_image_where_opencv_draws() -> None:
    """The drawing used where OpenCV's fails is OpenCV's image pixel for pixel where that one
    draws (80 px squares, 60 px markers; both layouts of an even number of rows)."""
    from stereovision.charuco import _drawn_board

    for squares, legacy in (((5, 4), False), ((8, 6), True), ((8, 6), False)):
        board = CharucoBoard(squares, 1.0, 0.75, "DICT_4X4_50", legacy)
        drawn = _drawn_board(board.cv_board(), board.squares, 80, 80, 60)
        assert np.array_equal(drawn, board.image(80))


def test_a_printable_board_whose_markers_no_detector_decodes_is_refused(tmp_path: Path) -> None:
    """3 mm markers in 30 mm squares at 72 dpi are 8.5 px, 1.2 px a cell of DICT_5X5_50's 7:
    ``board`` wrote them, and the board's own image decoded none of its 17 markers. Refused,
    nothing written, naming the dpi that gives 3 px a cell (178), whose board decodes all."""
    board = CharucoBoard((7, 5), 30, 3, "DICT_5X5_50")
    with pytest.raises(
        ValueError, match=r"marker_size: a 3 mm marker at 72 dpi is 8\.5 px, 1\.2 px"
    ):
        board_png(board, 0.03, 72)
    out = tmp_path / "b.png"
    run = _cli("board", "-o", str(out), "--board", "charuco", "--pattern", "7x5", "--square",
               "30", "--unit", "mm", "--marker", "3", "--dpi", "72")  # fmt: skip
    assert run.returncode == 2 and run.stderr.count("\n") == 1 and not out.exists()
    assert "use 178 dpi or more, or a larger marker" in run.stderr
    with pytest.raises(ValueError, match="use 178 dpi"):
        board_png(board, 0.03, 177)
    data, _ = board_png(board, 0.03, 178)
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_GRAYSCALE)
    detector = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_5X5_50))
    ids = detector.detectMarkers(img)[1]
    assert ids is not None and sorted(ids.ravel().tolist()) == list(range(17))


def test_auto_is_read_in_any_case_as_the_dictionary_names_are(tmp_path: Path) -> None:
    """``dictionary="5x5_100"`` is DICT_5X5_100, but ``"AUTO"`` (``--dictionary AUTO``) was
    refused as an unknown ArUco dictionary: it is "auto" now, in any case and spacing."""
    for given in ("AUTO", "Auto", " auto "):
        assert CharucoBoard("7x5", 0.03, 0.022, given).dictionary == "auto"
    out = tmp_path / "b.png"
    run = _cli("board", "-o", str(out), "--board", "charuco", "--pattern", "7x5", "--square",
               "30", "--unit", "mm", "--marker", "22", "--dictionary", "AUTO")  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "DICT_5X5_50" in run.stdout and out.is_file()


def test_the_dpi_named_for_markers_of_a_tiny_square_is_found_at_once() -> None:
    """ba8ed54 found the dpi to name a dpi at a time from 1.5 px below it, a step being
    square / 25.4 mm px: 1e-6 mm squares took 9 s, 1e-9 mm ones hung past a minute. It is
    bisected now: the same least dpi, at once. (board_png now refuses past 1.09e8 dpi first,
    what a PNG stores: the check itself is timed; the dpi found is said to be past it.)"""
    import time

    from stereovision.charuco import _check_marker_cells

    for square_m, want in ((1e-9, 901_700_000), (1e-12, 901_700_000_000)):
        board = CharucoBoard((5, 7), 1.0, 0.5, "DICT_4X4_50")
        said = rf"{want} dpi gives that, past the about 1\.09e\+08 dpi a PNG"
        start = time.perf_counter()
        with pytest.raises(ValueError, match=said):
            _check_marker_cells(board, 20, square_m, 20 * 0.0254 / square_m)  # 1.7 px a cell
        assert time.perf_counter() - start < 1.0
        for dpi, pix in ((want - 1, 35), (want, 36)):  # 35 px squares: 2.9 px a cell
            assert round(square_m / 0.0254 * dpi) == pix
        with pytest.raises(ValueError, match=said):
            _check_marker_cells(board, 35, square_m, want - 1)
        assert _check_marker_cells(board, 36, square_m, want) is None  # 3.0 px a cell: taken


def test_too_small_markers_are_not_told_a_dpi_the_board_refuses() -> None:
    """The dpi named for too-small markers was one board_png then refused: 3e-9 m squares
    (2.1e-9 m markers) at 8.5e7 dpi were told "use 249766667 dpi or more", which gives 1e10 px
    per metre ("past ... a PNG's resolution holds; use a lower dpi"); 0.5 mm markers on 1 m
    squares at 10 dpi "use 1067 dpi", 42008 px squares ("10 to 20000 px per square"). They
    now say why no dpi serves; a dpi named is taken."""
    board = CharucoBoard((5, 4), 3.0, 2.1, "DICT_5X5_50")
    with pytest.raises(ValueError, match=r"needs 3 to be decoded: 249766667 dpi gives that, "
                       r"past the about 1\.09e\+08 dpi a PNG's resolution holds: use a larger "
                       r"square and marker$"):  # fmt: skip
        board_png(board, 3e-9, 8.5e7)
    with pytest.raises(ValueError, match=r"PNG's resolution holds"):
        board_png(board, 3e-9, 249766667)  # the dpi the old message named
    board = CharucoBoard((5, 4), 1000.0, 0.5, "DICT_5X5_50")
    with pytest.raises(ValueError, match=r"needs 3 to be decoded: 1067 dpi gives that, with "
                       r"42008 px squares, past the 20000 a board image takes: use a larger "
                       r"marker$"):  # fmt: skip
        board_png(board, 1.0, 10)
    with pytest.raises(ValueError, match=r"10 to 20000 px per square"):
        board_png(board, 1.0, 1067)
    board = CharucoBoard((5, 4), 8.0, 4.0, "DICT_5X5_50")
    with pytest.raises(ValueError, match=r"use 132 dpi or more, or a larger marker$"):
        board_png(board, 8e-3, 50)
    board_png(board, 8e-3, 132)  # named, and taken


def test_a_dpi_past_what_a_png_stores_is_refused_by_name() -> None:
    """A board's resolution goes in the PNG as pixels per metre, an unsigned 32-bit count:
    ``board --square 1e-6 --unit mm --dpi 5.08e8`` (2e10 px/m) was struct.pack's bare
    "'I' format requires 0 <= number <= 4294967295", said as an internal error."""
    with pytest.raises(ValueError, match=r"^a 1e-06 mm square at 5\.08e\+08 dpi is 20 px, "
                       r"2e\+10 px per metre: past the 4294967295 a PNG's resolution holds "
                       r"\(about 1\.09e\+08 dpi\); use a lower dpi$"):  # fmt: skip
        board_png((9, 6), 1e-9, 5.08e8)
    data, _ = board_png((9, 6), 1e-7, 1e8)  # 3.94e9 px per metre: stored
    assert struct.unpack(">I", data[41:45])[0] == round(394 / 1e-7)


def test_the_dpi_named_for_too_small_markers_is_the_least_that_is_taken() -> None:
    """A board refused for markers under 3 px a cell names "use N dpi or more": N was rounded
    up from the whole pixels a square needs, where the square is itself a rounded count, so
    N - 1 dpi often gave the same square (8 mm squares of 4 mm DICT_4X4_50 markers at 72 dpi:
    'use 115 dpi', and 114 was taken: 36 px squares, 3.0 px a cell; 160 of 207 boards swept).
    N is now the least whole dpi taken, and its board decodes every marker."""
    for dictionary, square_mm, marker_mm in (
        ("DICT_4X4_50", 8, 4),
        ("DICT_4X4_50", 10, 2),
        ("DICT_5X5_50", 30, 3),
        ("DICT_6X6_250", 15, 5),
        ("DICT_APRILTAG_36h11", 24, 8),
        ("DICT_5X5_50", 10, 7),  # 3 x 7 / 0.7 px is 30.000000000000004: 76 dpi, not 77
    ):
        board = CharucoBoard((5, 4), square_mm, marker_mm, dictionary)
        with pytest.raises(ValueError, match=r"use \d+ dpi or more") as info:
            board_png(board, square_mm / 1000, 72)
        need = int(re.search(r"use (\d+) dpi", str(info.value)).group(1))  # type: ignore[union-attr]
        with pytest.raises(ValueError, match=rf"use {need} dpi or more"):
            board_png(board, square_mm / 1000, need - 1)
        data, _ = board_png(board, square_mm / 1000, need)
        img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_GRAYSCALE)
        detector = cv2.aruco.ArucoDetector(
            cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary))
        )
        ids = detector.detectMarkers(img)[1]
        assert ids is not None and sorted(ids.ravel().tolist()) == list(range(10)), (
            dictionary,
            need,
        )


@pytest.mark.parametrize("value", ["no", "false", 0.5, 2, -1])
def test_a_layout_that_is_no_switch_is_refused_by_name(value: object) -> None:
    """CharucoBoard stored bool(legacy): "no", "false" and 0.5 became True, OpenCV's pre-4.6
    layout, in which an even-rowed board's ids are read a square off. Only True, False (NumPy's
    bools, 0 and 1) and None are a layout; anything else is a ValueError naming legacy."""
    with pytest.raises(ValueError, match=r"^legacy: expected True, False or None, got "):
        CharucoBoard("7x6", 0.03, 0.02, legacy=value)
    for ok, want in ((np.False_, False), (1, True), (np.int64(0), False), (None, None)):
        assert CharucoBoard("7x6", 0.03, 0.02, legacy=ok).legacy is want


@pytest.mark.parametrize("ids", [[24], [-1], [0, 30], [1.7], [np.nan], [True]])
def test_object_points_refuse_ids_off_the_board(ids: list[object]) -> None:
    """object_points cast the ids to int64 and placed any: id 24 of a 7x5 board's 24 corners
    (0 to 23) gave a point on a fifth row of its four, -1 one on the board's edge (0.24, 0), 1.7 the
    point of corner 1. Each is a ValueError naming ids; whole ids (floats too) still give
    their corners."""
    board = CharucoBoard("7x5", 0.04, 0.03, "DICT_5X5_100")
    with pytest.raises(ValueError, match=r"^ids: expected"):
        board.object_points(ids)
    got = board.object_points(np.array([0.0, 23.0]))
    np.testing.assert_array_equal(got, board.object_points([0, 23]))
    np.testing.assert_allclose(got, [[0.04, 0.04, 0], [0.24, 0.16, 0]], rtol=1e-6)
    assert board.object_points([]).shape == (0, 3)


def test_object_points_names_ids_that_are_not_whole_on_one_line() -> None:
    """The message showed the ids as NumPy's repr, which wraps past 75 characters: eight ids
    such as 0.12345679 broke it over two lines (a message is one line)."""
    board = CharucoBoard("7x5", 0.04, 0.03, "DICT_5X5_100")
    with pytest.raises(ValueError) as exc:
        board.object_points(np.arange(10) + 0.123456789)
    assert str(exc.value) == (
        "ids: expected whole corner ids, got [0.12345679, 1.12345679, 2.12345679, 3.12345679, "
        "4.12345679, 5.12345679, 6.12345679, 7.12345679, ...]"
    )


def test_markers_too_large_for_their_border_are_warned_of_in_the_packages_words(
    capfd: pytest.CaptureFixture[str],
) -> None:
    """Markers nearly as large as their squares (0.028 in 0.03) leave a white border OpenCV
    finds too narrow to place the corners well (a rendered view's corners 0.49 px off on
    average, against 0.08 px with 0.022 markers): it said so only in its log, "[ WARN:0@1.8]
    ... Please increase markerSeparation or decrease markerLength", parameters this package
    has not, and `board` printed such a board with that line. It is a warning now, naming the
    sizes and the largest marker to print; OpenCV's line is not printed. Sizes of its own
    (0.0301) so that no other test built this board first (warned once a board)."""
    board = CharucoBoard("5x4", 0.0301, 0.028, "DICT_5X5_50")
    with pytest.warns(UserWarning) as rec:
        board.cv_board()
    assert [str(w.message) for w in rec] == [
        "ChArUco markers of 0.028 in squares of 0.0301 leave a white border of 0.001 around "
        "them, under the 0.0028 (70 % of a marker's cell) that OpenCV needs to place the "
        "corners well (0.028 in 0.03: a rendered view's corners 0.49 px off on average, 0.08 px "
        "with 0.022); a board to print needs markers of at most 0.025"
    ]
    assert "markerSeparation" not in capfd.readouterr().err
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        CharucoBoard("5x4", 0.0301, 0.025, "DICT_5X5_50").cv_board()  # the largest: no word


def test_board_png_of_a_board_whose_dictionary_is_auto_names_the_dictionary() -> None:
    """board_png of CharucoBoard("7x5", ..., dictionary="auto") (its default) looked "auto" up
    in cv2.aruco for its marker check: AttributeError "module 'cv2.aruco' has no attribute
    'auto'". It is a ValueError naming the dictionary; the same board with one is printed."""
    auto = CharucoBoard("7x5", 0.04, 0.03)
    with pytest.raises(ValueError, match=r"^dictionary: a printed board needs its dictionary"):
        board_png(auto, 0.04, dpi=100)
    _, size = board_png(replace(auto, dictionary="DICT_5X5_100"), 0.04, dpi=100)
    assert size == (9 * 157, 7 * 157)  # round(40 mm / 25.4 mm x 100) px, one-square margins


@pytest.mark.parametrize("background", [300, -5, True, "60", None, float("nan")])
def test_render_charuco_names_a_background_that_is_no_grey_level(background: object) -> None:
    """render_charuco clipped its uint8 output: background=300 rendered 255 and -5 rendered 0,
    True was 1 and "60" 60, each without a word. A background that is no grey level from 0 to
    255 is a ValueError naming it; 0, 255 and 60.0 are still the grey off the board."""
    board = CharucoBoard("5x4", 0.04, 0.03, "DICT_4X4_50")
    pose = (np.zeros(3), np.array([-0.1, -0.08, 0.5]))
    with pytest.raises(ValueError, match=r"^background: expected a grey level from 0 to 255"):
        render_charuco(board, K1, D1, *pose, background=background)
    for grey in (0, 255, 60.0):
        img = render_charuco(board, K1, D1, *pose, background=grey, supersample=1)
        assert img[0, 0] == round(grey)


@pytest.mark.parametrize("given", ["10x7", None, (10, 7)])
def test_board_functions_name_a_board_that_is_no_charuco_board(given: object) -> None:
    # a pattern string or None was AttributeError "'str' object has no attribute 'resolved'"
    # (or 'image', 'object_points') from deep inside
    want = rf"^board: expected a stereovision\.charuco\.CharucoBoard, got {type(given).__name__}$"
    img = np.full((48, 64), 128, np.uint8)
    K = np.array([[60.0, 0, 32], [0, 60, 24], [0, 0, 1]])
    calls = [
        lambda: find_charuco_corners(img, given),
        lambda: corners_span_plane(given, np.arange(3)),
        lambda: render_charuco(given, K, np.zeros(5), np.zeros(3), np.array([0, 0, 1.0])),
    ]
    for call in calls:
        with pytest.raises(TypeError, match=want):
            call()


@pytest.mark.parametrize("given", ["10x7", (10, 7)])
def test_calibration_from_recordings_names_a_board_that_is_no_charuco_board(
    tmp_path: Path, given: object
) -> None:
    """A pattern as board was AttributeError "'str' object has no attribute 'inner'" from
    deep inside, after both recordings were opened; now calibrate's own error, first. A
    TypeError, as find_charuco_corners' for the same board (calibrate's was ValueError)."""
    from stereovision.calibrate import calibrate_from_bag

    want = rf"^board: expected a stereovision\.charuco\.CharucoBoard, got {type(given).__name__}$"
    frame = tmp_path / "frame.png"  # a recording of one frame, opened before (now not)
    cv2.imwrite(str(frame), np.full((48, 64), 128, np.uint8))
    with pytest.raises(TypeError, match=want):
        calibrate_from_video(frame, frame, board=given)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=want):
        calibrate_from_bag(tmp_path / "none.bag", board=given)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=want):
        calibrate([frame] * 3, [frame] * 3, board=given)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=want):
        find_charuco_corners(cv2.imread(str(frame)), given)  # type: ignore[arg-type]


def test_a_dark_uint16_board_is_read_at_its_own_range() -> None:
    """find_charuco_corners on a 12-bit board in a uint16 array used its top 8 bits (0-15 grey
    levels), with only the matchers' 16-bit container warning: no board found where the 8-bit
    image gives 18 corners. It stretches by the image's range, as calibrate does (c74a955)."""
    k = np.array([[300.0, 0.0, 159.5], [0.0, 300.0, 119.5], [0.0, 0.0, 1.0]])
    rv, tv = np.array([0.15, -0.2, 0.05]), np.array([-0.15, -0.1, 0.42])
    img = render_charuco(BOARD, k, None, rv, tv, image_size=(320, 240), supersample=2)
    ref = find_charuco_corners(img, BOARD)
    deep = np.rint(img * (4095 / 255)).astype(np.uint16)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found = find_charuco_corners(deep, BOARD)
    assert ref is not None and found is not None
    np.testing.assert_array_equal(found[0], ref[0])
    assert np.abs(found[1] - ref[1]).max() < 0.02


def test_resolve_reads_a_dark_uint16_board_at_its_own_range() -> None:
    """CharucoBoard.resolve and markers_seen on a 12-bit board in a uint16 array used its top 8
    bits with the matchers' 16-bit container warning, as find_charuco_corners did (c59fa44):
    no board (None, ('', 0) markers) where the 8-bit image gives DICT_5X5_50 and 21 markers.
    They stretch by the image's range now, as find_charuco_corners does."""
    k = np.array([[300.0, 0.0, 159.5], [0.0, 300.0, 119.5], [0.0, 0.0, 1.0]])
    rv, tv = np.array([0.15, -0.2, 0.05]), np.array([-0.15, -0.1, 0.42])
    img = render_charuco(BOARD, k, None, rv, tv, image_size=(320, 240), supersample=2)
    deep = np.rint(img * (4095 / 255)).astype(np.uint16)
    auto = CharucoBoard("10x7", 0.03, 0.022)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert auto.markers_seen(deep) == ("DICT_5X5_50", 21)
        found = auto.resolve(deep)
    assert found is not None and found.dictionary == "DICT_5X5_50"


@pytest.mark.parametrize("printed", [True, False])
def test_a_board_given_in_the_other_layout_is_told_to_give_the_layout(printed: bool) -> None:
    """A 6x4 board (an even number of rows) printed in OpenCV's pre-4.6 layout and given
    legacy=False (or the reverse) was not found, and the hint said 'shows 12 of its DICT_4X4
    markers, but not as a 6x4-square board's: check the squares (columns x rows) and the
    marker size', neither of which was wrong. The other layout is tried on the first image
    and named (the CLI says it as --legacy / --no-legacy)."""
    from stereovision.calibrate import _cli_words

    k = np.array([[300.0, 0, 159.5], [0, 300, 119.5], [0, 0, 1]])
    board = CharucoBoard("6x4", 0.04, 0.03, "DICT_4X4_50", legacy=printed)
    view = render_charuco(
        board, k, None, np.array([0.1, -0.2, 0.05]), np.array([-0.12, -0.08, 0.6]),
        image_size=(320, 240), supersample=2, pixels_per_square=60,
    )  # fmt: skip
    with pytest.raises(ValueError) as err:
        calibrate([view], [view], board=replace(board, legacy=not printed))
    layout = "pre-4.6 (legacy)" if printed else "current (4.6 and later)"
    said = (
        f"left_images[0] shows the board in OpenCV's {layout} layout, not the one given: give "
        f"legacy={printed} (or leave the layout out, to be found from the images)"
    )
    assert said in str(err.value)
    flag = "--legacy" if printed else "--no-legacy"
    assert f"give {flag} (or leave" in _cli_words(str(err.value))


def test_opencvs_dictionary_constant_is_its_dictionary() -> None:
    """OpenCV's samples give the dictionary as its constant: ``dictionary=cv2.aruco.DICT_5X5_100``
    (the integer 5) was refused as 'unknown ArUco dictionary 5'. Each predefined constant is
    now its name; a bool, an integer no dictionary has, or a float is refused as before."""
    for name in ("DICT_4X4_50", "DICT_5X5_100", "DICT_APRILTAG_36H11", "DICT_ARUCO_MIP_36H12"):
        const = getattr(cv2.aruco, name)
        assert CharucoBoard("6x5", 0.03, 0.022, const).dictionary == name
        assert CharucoBoard("6x5", 0.03, 0.022, np.int64(const)).dictionary == name
    for bad in (True, 99, -1, 5.0):
        with pytest.raises(ValueError, match=r"^dictionary: unknown ArUco dictionary "):
            CharucoBoard("6x5", 0.03, 0.022, bad)


def test_a_board_of_fewer_inner_corners_than_a_view_needs_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """A 3x3-square board (2x2 = 4 inner corners) was taken, printed by ``board``, and then
    never found: find_charuco_corners wants MIN_CORNERS (6) corners of a view, so calibrate
    found it in none of the images. It is refused where it is defined, naming the corners;
    4x3 and 3x4 (6 corners) are boards as before."""
    from stereovision import cli

    with pytest.raises(ValueError) as err:
        CharucoBoard("3x3", 0.05, 0.035, "DICT_4X4_50")
    assert str(err.value) == (
        "squares: a 3x3 board has 4 inner corners, and a view of it needs at least 6 (e.g. 4x3 "
        "squares)"
    )
    assert CharucoBoard("4x3", 0.05, 0.035).n_corners == CharucoBoard("3x4", 0.05, 0.035).n_corners
    out = tmp_path / "b.png"
    code = cli.main(["board", "-o", str(out), "--board", "charuco", "--pattern", "3x3",
                     "--square", "30", "--unit", "mm", "--marker", "22"])  # fmt: skip
    assert code == 2 and not out.exists()
    assert capsys.readouterr().err == (
        "stereovision: error: --pattern: a 3x3 board has 4 inner corners, and a view of it "
        "needs at least 6 (e.g. 4x3 squares)\n"
    )
