"""``stereovision stream``: live depth from two 640x480 MJPG videos of a real scene."""

from __future__ import annotations

import ipaddress
import json
import math
import os
import re
import shutil
import threading
import time
import urllib.error
import urllib.request
import warnings
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from stereovision.calibration import Calibration
from stereovision.capture import StereoCamera
from stereovision.cli import main
from stereovision.depth import depth_map
from stereovision.io import load_scene
from stereovision.stream import STAGES, FrameServer, StreamReport, run_stream

SCENE = "tartanair/oldtown_easy_p000_001116"  # 640x480, metric rectified calibration
N_FRAMES = 6
FPS = 30.0
#: Tests that run the pipelined stream (its grab thread; a ``stream`` command without
#: --no-pipeline). A deadlock of the grab thread and the matcher (a slot not given back, an
#: end or error never put) hung them until the suite's 600 s timeout: they now fail within
#: these seconds, with every thread's stack (pytest-timeout). Each takes at most 3 s alone, the
#: slow ones 7-12 s; the margin is for a loaded two-core machine.
PIPELINED = pytest.mark.timeout(30)
SLOW_PIPELINED = pytest.mark.timeout(45)


@pytest.fixture(scope="module")
def videos(data_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two MJPG videos of the scene (each frame shifted down by 0..2 rows) and its calib.txt."""
    scene = data_dir / SCENE
    out = tmp_path_factory.mktemp("stream")
    paths: dict[str, Path] = {}
    for side in ("left", "right"):
        img = cv2.imread(str(scene / f"{side}.png"))
        assert img.shape == (480, 640, 3)
        path = out / f"{side}.avi"
        vw = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), FPS, (640, 480))
        assert vw.isOpened()
        for i in range(N_FRAMES):
            vw.write(np.roll(img, i % 3, axis=0))
        vw.release()
        paths[side] = path
    paths["calib"] = Path(shutil.copy(scene / "calib.txt", out / "calib.txt"))
    return paths


def _json_lines(text: str) -> list[dict]:
    lines = [ln for ln in text.splitlines() if ln.strip()]
    return [json.loads(ln) for ln in lines]


@PIPELINED
def test_stream_json_reports(videos: dict[str, Path], capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--max-disparity", "64", "--no-display", "--json"]
    assert main(argv) == 0
    objs = _json_lines(capsys.readouterr().out)  # every stdout line is one JSON object
    reports, summary = objs[:-1], objs[-1]
    assert reports and all("summary" not in r for r in reports)
    # the first pair's rows were checked: the scene is rectified
    assert summary["rectification"]["ok"] is True
    assert summary["rectification"]["median_dy"] < 0.3
    # Every pair is in exactly one per-second report; the counts add up.
    assert sum(r["frames"] for r in reports) == N_FRAMES
    assert [r["total_frames"] for r in reports] == list(np.cumsum([r["frames"] for r in reports]))
    assert [r["t"] for r in reports] == sorted(r["t"] for r in reports)
    for r in reports:
        assert r["fps"] > 0
        assert set(r["stage_ms"]) == set(STAGES)
        for k in ("grab", "prepare", "match", "triangulate"):
            assert r["stage_ms"][k] > 0, k
        assert r["stage_ms"]["rectify"] >= 0  # rectified calibration: nothing to remap
        assert r["stage_ms"]["fill"] == 0  # the Gabor channel leaves its holes
        # A pair's latency covers at least its own grab and matching.
        assert r["latency_ms"] >= r["stage_ms"]["match"] + r["stage_ms"]["grab"] - 1e-6
        # Each pair's skew lies within its grab (no wall-clock bound: speed belongs in benches/).
        assert 0 <= r["skew_ms"]["mean"] <= r["skew_ms"]["max"]
        assert r["skew_ms"]["mean"] <= r["stage_ms"]["grab"] + 1e-3
        assert r["max_disparity"] == 64
        assert r["pipelined"] is True
        assert 0.6 < r["density"] <= 1.0  # a real scene: the matcher measures most pixels
    assert summary["summary"] is True
    assert summary["frames"] == N_FRAMES
    assert summary["ended"] == "end of stream"
    assert summary["fps"] == pytest.approx(N_FRAMES / summary["seconds"], rel=1e-2)
    assert summary["stage_ms"]["match"] > 0


@pytest.mark.parametrize("fill", [None, False])
@PIPELINED
def test_stream_census_fills_unless_told(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str], fill: bool | None
) -> None:
    """``--method census`` fills its holes (a stage of its own in the reports); ``--no-fill``
    leaves them."""
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--max-disparity", "64", "--no-display", "--json"]
    argv += ["--method", "census", "--frames", "2"] + (["--no-fill"] if fill is False else [])
    assert main(argv) == 0
    objs = _json_lines(capsys.readouterr().out)
    reports, summary = objs[:-1], objs[-1]
    assert summary["frames"] == 2
    if fill is None:
        assert summary["stage_ms"]["fill"] > 0
        assert all(r["density"] == 1.0 for r in reports)
    else:
        assert summary["stage_ms"]["fill"] == 0
        assert all(0.6 < r["density"] < 1.0 for r in reports)  # measured: 0.83


@PIPELINED
def test_stream_results_are_the_frames_depth(videos: dict[str, Path]) -> None:
    """Pipelined, each result is depth_map of its own pair (no mix-up between frames).

    The stream leaves the refinement off by default (live rate): the reference is too.
    """
    calib = Calibration.from_file(videos["calib"])
    got: list[tuple[np.ndarray, np.ndarray]] = []
    with StereoCamera(str(videos["left"]), str(videos["right"])) as cam:
        rep = run_stream(
            cam,
            calib,
            max_disparity=64,
            frames=4,
            on_result=lambda left, res: got.append((left.copy(), res.disparity)),
        )
    assert rep.frames == 4 and rep.ended == "frames"
    assert len(got) == 4
    caps = [cv2.VideoCapture(str(videos[s])) for s in ("left", "right")]
    try:
        for left, disp in got:
            lf, rf = caps[0].read()[1], caps[1].read()[1]
            np.testing.assert_array_equal(left, lf)
            ref = depth_map(lf, rf, calib, method="gabor", max_disparity=64, refine=False).disparity
            np.testing.assert_array_equal(disp, ref)
    finally:
        for c in caps:
            c.release()
    # Frames 0, 1, 2 are shifted by 0, 1, 2 rows: their disparity maps differ.
    assert not np.array_equal(got[0][1], got[1][1])


def test_stream_unpipelined_with_raw_rig(
    videos: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A raw (unrectified) rig calibration: the rectify stage does work; --frames stops early."""
    k = np.array([[320.0, 0, 320], [0, 320.0, 240], [0, 0, 1]])
    rvec = np.array([0.0, 0.01, 0.0])
    rig = Calibration(
        K1=k,
        D1=np.zeros(5),
        K2=k,
        D2=np.zeros(5),
        R=cv2.Rodrigues(rvec)[0],
        T=np.array([-0.25, 0.0, 0.0]),
        image_size=(640, 480),
        unit="m",
    )
    calib_path = rig.save(tmp_path / "rig.yaml")
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(calib_path), "--max-disparity", "64", "--no-display", "--json"]
    argv += ["--frames", "3", "--no-pipeline"]
    assert main(argv) == 0
    objs = _json_lines(capsys.readouterr().out)
    summary = objs[-1]
    assert summary["frames"] == 3 and summary["ended"] == "frames"
    assert summary["pipelined"] is False
    assert summary["stage_ms"]["rectify"] > 0
    assert sum(r["frames"] for r in objs[:-1]) == 3


@PIPELINED
def test_stream_estimates_range_and_prints_text(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--frames", "2", "--no-display"]
    assert main(argv) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert "fps" in out[0] and "match" in out[0]
    assert out[-1].startswith("2 pairs in ")
    # No calibration: disparity only; the range came from the first pair (multiple of 16).
    md = int(out[-1].rsplit("max_disparity ", 1)[1])
    assert md % 16 == 0 and 16 <= md <= 320


def test_stream_errors_are_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc = main(["stream", "--left", str(tmp_path / "nope.avi"), "--right", "x.avi", "--no-display"])
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not found" in err[0] and "nope.avi" in err[0]


def _get(url: str) -> tuple[int, str, bytes]:
    try:
        with urllib.request.urlopen(url, timeout=60) as r:
            return r.status, r.headers["Content-Type"], r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.headers["Content-Type"], e.read()


def test_frame_server_refuses_a_port_out_of_range() -> None:
    # bind() raised OverflowError ("internal ... please report this" from the CLI); said in
    # --serve's and gui --port's words (it said 'expected 0 to 65535 (0 = any free port)')
    words = "port: expected a port 1 to 65535, or 0 for a free one, got"
    for port in (-1, 65536, 99999):
        with pytest.raises(ValueError, match=rf"^{words} {port}$"):
            FrameServer("127.0.0.1", port)
    # a bool is an int: True bound port 1
    with pytest.raises(ValueError, match=rf"^{words} True$"):
        FrameServer("127.0.0.1", True)


def test_frame_server_serves_left_and_disparity() -> None:
    srv = FrameServer("127.0.0.1", 0)
    try:
        base = srv.url
        assert _get(base + "frame.jpg")[0] == 503
        status, ctype, body = _get(base)
        assert status == 200 and "text/html" in ctype and b"/stream.mjpg" in body
        left = np.full((48, 64, 3), (30, 120, 200), np.uint8)
        disp = np.full((48, 64), 16.0, np.float32)
        disp[:, :32] = np.nan
        srv.update(left, disp, 64.0)
        status, ctype, body = _get(base + "frame.jpg")
        assert status == 200 and ctype == "image/jpeg"
        img = cv2.imdecode(np.frombuffer(body, np.uint8), cv2.IMREAD_COLOR)
        assert img.shape == (48, 128, 3)
        assert np.abs(img[8:40, 8:56].astype(int) - (30, 120, 200)).max() < 12  # left image
        assert img[8:40, 72:88].max() < 12  # NaN disparity is black
        expected = cv2.applyColorMap(np.array([[64]], np.uint8), cv2.COLORMAP_TURBO)[0, 0]
        assert np.abs(img[8:40, 104:120].astype(int) - expected).max() < 16  # 16 / 64 of TURBO
        # The MJPEG stream delivers the same frame as a multipart part.
        with urllib.request.urlopen(base + "stream.mjpg", timeout=60) as r:
            assert r.headers["Content-Type"].startswith("multipart/x-mixed-replace")
            head = r.read(200)
        assert head.startswith(b"--frame\r\nContent-Type: image/jpeg\r\n")
        assert _get(base + "nope")[0] == 404
    finally:
        srv.close()


@PIPELINED
def test_stream_warns_when_the_rig_is_not_rectified(
    videos: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A calibration whose right camera is pitched 1 degree more than the rectified frames show:
    the first pair's rows are about 6 px apart (6.12 on the PNG pair), and the stream says so in
    one line."""
    k = np.array([[320.0, 0, 320], [0, 320.0, 240], [0, 0, 1]])
    rig = Calibration(
        K1=k,
        D1=np.zeros(5),
        K2=k,
        D2=np.zeros(5),
        R=cv2.Rodrigues(np.array([np.radians(1.0), 0.0, 0.0]))[0],
        T=np.array([-0.25, 0.0, 0.0]),
        image_size=(640, 480),
        unit="m",
    )
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(rig.save(tmp_path / "rig.yaml")), "--max-disparity", "64"]
    argv += ["--no-display", "--json", "--frames", "1"]
    assert main(argv) == 0
    cap = capsys.readouterr()
    check = _json_lines(cap.out)[-1]["rectification"]
    assert check["ok"] is False and abs(check["offset"]) > 3
    warned = [ln for ln in cap.err.splitlines() if "NOT rectified" in ln]
    assert len(warned) == 1 and warned[0].startswith("stereovision: warning: first pair:")
    assert main([*argv, "--no-check"]) == 0
    cap = capsys.readouterr()
    assert _json_lines(cap.out)[-1]["rectification"] is None and "NOT" not in cap.err


@PIPELINED
def test_stream_scales_a_calibration_made_at_another_resolution(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """--size 320x240 with the scene's 640x480 calibration: the frames and the calibration are
    halved (one warning line each), and depth is computed at the lower resolution. --size
    320x180 of the same 640x480 videos: another shape, so the frames are kept at 640x480 and
    the calibration fits them as it is (it was fitted to the 320x180 asked, and refused as of
    "another aspect ratio" frames it was made for)."""
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--size", "320x240", "--max-disparity", "32"]
    argv += ["--no-display", "--json", "--frames", "2"]
    assert main(argv) == 0
    cap = capsys.readouterr()
    summary = _json_lines(cap.out)[-1]
    assert summary["frames"] == 2 and summary["stage_ms"]["triangulate"] > 0
    assert summary["rectification"]["ok"] is True
    notes = [ln for ln in cap.err.splitlines() if "calibration is for 640x480" in ln]
    assert len(notes) == 1 and "frames are 320x240: scaled" in notes[0]
    argv[argv.index("320x240")] = "320x180"
    assert main(argv) == 0
    cap = capsys.readouterr()
    assert _json_lines(cap.out)[-1]["frames"] == 2
    assert "frames are kept at 640x480" in cap.err and "calibration is for" not in cap.err


@SLOW_PIPELINED
@pytest.mark.usefixtures("sift_once")
def test_stream_checks_every_nth_pair_and_warns_once_when_the_rows_drift(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Eight pairs, the right camera 'bumped' 3 px down from pair 4 on; checked every 2nd pair:
    pairs 0 and 2 pass, 4 and 6 fail, and one warning names pair 4 (pipelined and not). The
    frames repeat (two distinct pairs): their features are found once each
    (the ``sift_once`` fixture)."""
    scene = data_dir / SCENE
    paths = {}
    for side in ("left", "right"):
        img = cv2.imread(str(scene / f"{side}.png"))
        path = tmp_path / f"{side}.avi"
        vw = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), FPS, (640, 480))
        for i in range(8):
            vw.write(np.roll(img, 3, axis=0) if side == "right" and i >= 4 else img)
        vw.release()
        paths[side] = path
    argv = ["stream", "--left", str(paths["left"]), "--right", str(paths["right"])]
    argv += ["--max-disparity", "64", "--no-display", "--json", "--check-every", "2"]
    for extra in ([], ["--no-pipeline"]):
        assert main([*argv, *extra]) == 0
        cap = capsys.readouterr()
        summary = _json_lines(cap.out)[-1]
        assert [(c["pair"], c["ok"]) for c in summary["checks"]] == [
            (0, True),
            (2, True),
            (4, False),
            (6, False),
        ]
        assert summary["checks"][2]["offset"] == pytest.approx(-3.0, abs=0.3)
        assert summary["rectification"] == summary["checks"][0]
        warned = [ln for ln in cap.err.splitlines() if "NOT rectified" in ln]
        assert len(warned) == 1 and warned[0].startswith("stereovision: warning: pair 4:")
    with pytest.raises(SystemExit) as info:  # refused by argparse, in the option's name
        main([*argv, "--check-every", "0"])
    assert info.value.code == 2
    assert "argument --check-every: expected a whole number above 0" in capsys.readouterr().err


@PIPELINED
def test_stream_watches_the_floor_and_warns_once_when_the_mount_moves(
    data_dir: Path, tmp_path: Path
) -> None:
    """Rendered frames of a floor 1.1 m below a camera pitched 12 degrees down; from pair 4 on
    the camera looks 16 degrees down. Fits on pairs 0, 2, 4, 6: the first two agree, pair 4 is
    flagged and named in one warning."""
    from tests.test_ground import RIG, composite, floor_scene

    tex = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "left.png"), cv2.IMREAD_GRAYSCALE)
    frames = {12.0: composite(*floor_scene(tex, 12.0)), 16.0: composite(*floor_scene(tex, 16.0))}
    for n in range(8):
        left, right = frames[12.0 if n < 4 else 16.0]
        cv2.imwrite(str(tmp_path / f"left_{n:03d}.png"), left)
        cv2.imwrite(str(tmp_path / f"right_{n:03d}.png"), right)
    cam = StereoCamera(str(tmp_path / "left_%03d.png"), str(tmp_path / "right_%03d.png"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = run_stream(cam, RIG, max_disparity=64, ground_every=2, check=False)
    cam.close()
    assert [g["pair"] for g in rep.grounds] == [0, 2, 4, 6]
    assert all(g["found"] for g in rep.grounds)
    assert [g["moved"] for g in rep.grounds] == [False, False, True, True]
    assert rep.grounds[0]["height_m"] == pytest.approx(1.1, rel=0.02)
    assert rep.grounds[0]["pitch_deg"] == pytest.approx(12.0, abs=0.5)
    assert rep.grounds[2]["pitch_deg"] == pytest.approx(16.0, abs=0.5)
    moved = [str(w.message) for w in caught if "moved on its mount" in str(w.message)]
    assert len(moved) == 1 and moved[0].startswith("pair 4:")
    assert [w.filename for w in caught if "moved on its mount" in str(w.message)] == [__file__]
    assert rep.as_dict()["grounds"][1]["pair"] == 2
    # the first floor no longer holds once the camera turned (measured: 0.00)
    kept = [g["first_plane_kept"] for g in rep.grounds[1:]]
    assert kept[0] > 0.9 and max(kept[1:]) < 0.1
    with pytest.raises(ValueError, match="give a calibration"):
        run_stream(StereoCamera(str(tmp_path / "left_%03d.png"), str(tmp_path / "right_%03d.png")),
                   None, ground_every=2)  # fmt: skip


@PIPELINED
def test_a_still_rig_on_uneven_ground_is_not_a_moved_mount(data_dir: Path, tmp_path: Path) -> None:
    """TartanAir's street from 9 m up, the same pair at four JPEG qualities (a webcam's MJPG
    frames differ that way): the fresh floor fits differ by more than the 2 degrees that flag a
    mount (measured: pitch 25.5-34.1), but the first fit's plane holds on every frame (0.85-1.0
    of its share), so no warning."""
    sc = load_scene(data_dir / "tartanair" / "oldtown_easy_p000_001116")
    for n, q in enumerate((95, 60, 40, 25)):
        for side, img in (("left", sc.left), ("right", sc.right)):
            _, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, q])
            cv2.imwrite(str(tmp_path / f"{side}_{n:03d}.png"), cv2.imdecode(buf, cv2.IMREAD_COLOR))
    cam = StereoCamera(str(tmp_path / "left_%03d.png"), str(tmp_path / "right_%03d.png"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = run_stream(cam, sc.calib, max_disparity=32, ground_every=1, check=False)
    cam.close()
    assert all(g["found"] for g in rep.grounds) and len(rep.grounds) == 4
    pitch = [g["pitch_deg"] for g in rep.grounds]
    assert max(pitch) - min(pitch) > 2.0  # the old rule, fits alone, flagged this rig
    assert not any(g["moved"] for g in rep.grounds)
    assert min(g["first_plane_kept"] for g in rep.grounds[1:]) > 0.7
    assert not [w for w in caught if "moved on its mount" in str(w.message)]


@PIPELINED
def test_stream_records_a_ros2_bag(data_dir: Path, tmp_path: Path) -> None:
    """`stream --bag DIR` writes every frame's four topics into a new ROS 2 bag that rosbags'
    reader reads back; without --calib it is a one-line error."""
    pytest.importorskip("rosbags")
    from rosbags.rosbag2 import Reader

    from tests.test_ground import RIG, composite, floor_scene

    tex = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "left.png"), cv2.IMREAD_GRAYSCALE)
    left, right = composite(*floor_scene(tex))
    for n in range(3):
        cv2.imwrite(str(tmp_path / f"left_{n:03d}.png"), left)
        cv2.imwrite(str(tmp_path / f"right_{n:03d}.png"), right)
    RIG.save(tmp_path / "rig.yaml")
    src = ["--left", str(tmp_path / "left_%03d.png"), "--right", str(tmp_path / "right_%03d.png")]
    bag = tmp_path / "bag"
    rc = main(["stream", *src, "--calib", str(tmp_path / "rig.yaml"), "--no-display",
               "--max-disparity", "64", "--no-check", "--bag", str(bag)])  # fmt: skip
    assert rc == 0
    with Reader(bag) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
    assert counts == {"/stereo/left/image_rect_color": 3, "/stereo/left/camera_info": 3,
                      "/stereo/right/camera_info": 3, "/stereo/camera_info": 3,
                      "/stereo/depth": 3, "/stereo/disparity": 3,
                      "/stereo/points": 3}  # fmt: skip
    assert main(["stream", *src, "--no-display", "--bag", str(tmp_path / "b2")]) == 2


@SLOW_PIPELINED
def test_stream_no_tf_leaves_the_floor_transform_out_of_the_bag(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stream --bag DIR --ground-every N` puts /tf in every frame with a floor; a robot whose
    own tree (robot_state_publisher) already places the camera needs it out (BagWriter's
    tf=False), which the CLI could not ask for. `--no-tf` leaves it out, the floor's scan kept;
    without --bag (or --ground-every, the only /tf) it is a one-line error before any open."""
    pytest.importorskip("rosbags")
    from rosbags.rosbag2 import Reader

    from tests.test_ground import RIG, composite, floor_scene

    tex = cv2.imread(str(data_dir / "middlebury2003" / "cones" / "left.png"), cv2.IMREAD_GRAYSCALE)
    left, right = composite(*floor_scene(tex))
    for n in range(2):
        cv2.imwrite(str(tmp_path / f"left_{n:03d}.png"), left)
        cv2.imwrite(str(tmp_path / f"right_{n:03d}.png"), right)
    RIG.save(tmp_path / "rig.yaml")
    src = ["--left", str(tmp_path / "left_%03d.png"), "--right", str(tmp_path / "right_%03d.png")]
    common = ["stream", *src, "--calib", str(tmp_path / "rig.yaml"), "--no-display",
              "--max-disparity", "64", "--no-check", "--ground-every", "1"]  # fmt: skip
    counts = {}
    for name, flag in (("with_tf", []), ("own_tree", ["--no-tf"])):
        assert main([*common, "--bag", str(tmp_path / name), *flag]) == 0
        with Reader(tmp_path / name) as reader:
            counts[name] = {c.topic: c.msgcount for c in reader.connections}
    assert counts["with_tf"]["/tf"] == 2 and counts["with_tf"]["/stereo/scan"] == 2
    assert "/tf" not in counts["own_tree"]
    assert counts["own_tree"] == {k: v for k, v in counts["with_tf"].items() if k != "/tf"}
    capsys.readouterr()
    for argv, said in (
        ([*common, "--no-tf"], "--no-tf leaves /tf out of a --bag: give --bag DIR"),
        (
            [*common[:-2], "--bag", str(tmp_path / "b3"), "--no-tf"],
            "--no-tf: a bag has /tf only with --ground-every (the floor places the camera)",
        ),
    ):
        assert main(argv) == 2
        assert capsys.readouterr().err == f"stereovision: error: {said}\n"
    assert not (tmp_path / "b3").exists()


@SLOW_PIPELINED
@pytest.mark.usefixtures("sift_once")
def test_stream_averages_a_still_noisy_rig(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Six PNG frames of the still scene with fresh noise each (8 grey levels): with --temporal
    the matcher gets the running mean (1, 2, ... 6 frames), its noise down by more than half on
    the last pair; the moving videos above restart on every pair and pass through. Its three
    streams check the same first pair: its features are found once
    (the ``sift_once`` fixture)."""
    from stereovision.temporal import TemporalFilter
    from tests.test_exposure import noisy

    scene = data_dir / SCENE
    rng = np.random.default_rng(0)
    clean = {s: cv2.imread(str(scene / f"{s}.png")) for s in ("left", "right")}
    for i in range(6):
        for side, img in clean.items():
            cv2.imwrite(str(tmp_path / f"{side}_{i:02d}.png"), noisy(img, 8.0, rng))
    calib = Calibration.from_file(scene / "calib.txt")
    got: list[np.ndarray] = []
    with StereoCamera(str(tmp_path / "left_%02d.png"), str(tmp_path / "right_%02d.png")) as cam:
        rep = run_stream(
            cam,
            calib,
            max_disparity=64,
            temporal=TemporalFilter(),
            on_result=lambda left, res: got.append(left.copy()),
        )
    assert rep.frames == 6 and rep.temporal is not None
    assert rep.temporal["restarts"] == 0 and rep.temporal["frames_averaged"] > 3.4  # (1+..+6)/6
    assert 4.8 < rep.temporal["noise_sigma"] < 7.0
    assert rep.stage_ms["temporal"] > 0
    last_raw = cv2.imread(str(tmp_path / "left_05.png")).astype(np.float32)
    ref = clean["left"].astype(np.float32)
    assert np.std(got[-1] - ref) < 0.5 * np.std(last_raw - ref)

    argv = ["stream", "--left", str(tmp_path / "left_%02d.png"), "--right"]
    argv += [str(tmp_path / "right_%02d.png"), "--calib", str(scene / "calib.txt")]
    argv += ["--max-disparity", "64", "--no-display", "--temporal", "8"]
    assert main(argv) == 0
    cap = capsys.readouterr()
    assert "temporal: 3.5 frames averaged per pixel on average, 0 restarts" in cap.out
    assert "noisy" not in cap.err  # averaging already
    # Without --temporal the first frame's noise (5.5 grey levels) brings a one-line hint.
    assert main([*argv[:-2], "--json"]) == 0
    cap = capsys.readouterr()
    hints = [ln for ln in cap.err.splitlines() if "noisy" in ln]
    assert len(hints) == 1 and hints[0].startswith("stereovision: warning: the cameras are noisy")
    assert "--temporal 8" in hints[0]
    assert 4.8 < _json_lines(cap.out)[-1]["noise_sigma"] < 7.0
    # --temporal 1 and 256 are refused when the command line is read (42047c09):
    # test_a_temporal_stream_averages_up_to_255_pairs, test_temporal_is_refused_at_parse_time


@PIPELINED
def test_stream_averages_a_raw_rig_before_rectifying(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A still raw rig (the StereoPi scene pair, its own calibration) with fresh noise of 8 grey
    levels on each frame: the filter averages the frames as grabbed. It averaged the rectified
    ones, whose interpolated noise read 0.9 grey levels: every pair restarted (5 of 5), nothing
    was averaged, and the noise hint, read on the rectified frame, never came."""
    from tests.test_calibration import stereopi_calib
    from tests.test_exposure import noisy

    scene = data_dir / "stereopi_rig" / "scene_photo"
    calib = stereopi_calib(data_dir)
    calib.save(tmp_path / "rig.yaml")
    rng = np.random.default_rng(0)
    for i in range(6):
        for side in ("left", "right"):
            img = cv2.imread(str(scene / f"{side}.png"))
            cv2.imwrite(str(tmp_path / f"{side}_{i:02d}.png"), noisy(img, 8.0, rng))
    argv = ["stream", "--left", str(tmp_path / "left_%02d.png"), "--right"]
    argv += [str(tmp_path / "right_%02d.png"), "--calib", str(tmp_path / "rig.yaml")]
    argv += ["--max-disparity", "32", "--no-display", "--no-check", "--json"]
    assert main([*argv, "--temporal", "8"]) == 0
    summary = _json_lines(capsys.readouterr().out)[-1]
    assert summary["temporal"]["restarts"] == 0
    assert summary["temporal"]["frames_averaged"] > 3.4  # (1 + ... + 6) / 6
    assert summary["temporal"]["noise_sigma"] > 4.5
    assert main(argv) == 0
    cap = capsys.readouterr()
    assert _json_lines(cap.out)[-1]["noise_sigma"] > 4.5
    assert "the cameras are noisy" in cap.err


@PIPELINED
def test_stream_temporal_restarts_on_a_moving_view(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """The videos' frames move by a row each: every pair after the first restarts the mean."""
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--max-disparity", "64", "--no-display", "--json", "--temporal", "8"]
    assert main(argv) == 0
    cap = capsys.readouterr()
    summary = _json_lines(cap.out)[-1]
    assert summary["temporal"]["restarts"] == N_FRAMES - 1
    assert summary["temporal"]["frames_averaged"] == 1.0
    assert summary["noise_sigma"] < 3.0 and "noisy" not in cap.err  # a clean scene: no hint


def test_signals_wait_for_the_end_of_a_deferred_block() -> None:
    """A Ctrl-C in the middle of a bag frame waited for the frame's last message."""
    import os
    import signal

    from stereovision._interrupt import HeldInterrupts

    done = []
    with pytest.raises(KeyboardInterrupt):
        with HeldInterrupts():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # the handler would have run here
            done.append("frame")
    assert done == ["frame"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_the_summary_keeps_bounded_figures(monkeypatch: pytest.MonkeyPatch) -> None:
    """Medians over the latest MEDIAN_PAIRS pairs, means, maximum and count over all."""
    from stereovision import stream

    monkeypatch.setattr(stream, "MEDIAN_PAIRS", 4)
    tally = stream._Tally()
    for i in range(11):
        stages = dict.fromkeys(STAGES, float(i))
        tally.add(stream._Done(stages, float(i), 0.0, skew_ms=float(i % 5), density=float(i)))
    assert tally.n == 11
    assert tally.median("match") == 8.5  # of 7, 8, 9, 10
    assert len(tally._cols["match"]) < 8  # the oldest dropped
    assert tally.mean("density") == 5.0 and tally.skew_max == 4.0


def test_stream_results_are_stamped_at_their_grab(videos: dict[str, Path], tmp_path: Path) -> None:
    """A live pair's stamp is its grab time, not the time its depth was done (the bag's
    messages were stamped a frame's latency late, against TF and odometry). Read from image
    sequences, which have no time of their own as cameras (a video file's pairs carry its)."""
    for side in ("left", "right"):
        cap = cv2.VideoCapture(str(videos[side]))
        for i in range(3):
            ok, img = cap.read()
            assert ok
            cv2.imwrite(str(tmp_path / f"{side}_{i:03d}.png"), img)
        cap.release()
    cam = StereoCamera(str(tmp_path / "left_%03d.png"), str(tmp_path / "right_%03d.png"))
    assert not cam.media_clock
    seen: list[tuple[int, int, float]] = []

    def on_stamped(left: np.ndarray, res: object, stamp_ns: int) -> None:
        seen.append((stamp_ns, time.time_ns(), sum(res.timings.values())))  # type: ignore[attr-defined]

    t0 = time.time_ns()
    run_stream(cam, method="gabor", max_disparity=64, frames=3, pipelined=False,
               check=False, on_stamped_result=on_stamped)  # fmt: skip
    cam.close()
    assert len(seen) == 3
    for stamp, called, compute_s in seen:
        assert t0 <= stamp <= called - 0.9e9 * compute_s  # the matching came after the stamp


@PIPELINED
def test_a_bag_written_from_video_files_steps_by_their_frame_period(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``stream --left L.avi --right R.avi --bag`` stamped each frame with the wall clock of its
    read, so the bag's stamps followed the processing speed; a video file's pairs carry its
    own time (the first pair's grab time plus the left video's CAP_PROP_POS_MSEC), and the
    stamps step by 1/fps. An image sequence (no media time) keeps the grab's wall clock."""
    pytest.importorskip("rosbags")
    from rosbags.rosbag2 import Reader

    fps, n, size = 7.0, 4, (160, 120)
    scene = data_dir / SCENE
    Calibration.from_file(scene / "calib.txt").scaled_to(size).save(tmp_path / "rig.yaml")
    for side in ("left", "right"):
        img = cv2.resize(cv2.imread(str(scene / f"{side}.png")), size)
        vw = cv2.VideoWriter(str(tmp_path / f"{side}.avi"), cv2.VideoWriter_fourcc(*"MJPG"),
                             fps, size)  # fmt: skip
        for i in range(n):
            vw.write(img)
            cv2.imwrite(str(tmp_path / f"{side}_{i:03d}.png"), img)
        vw.release()
    common = ["--calib", str(tmp_path / "rig.yaml"), "--no-display", "--no-check",
              "--max-disparity", "16", "--no-pipeline"]  # fmt: skip

    def stamps(name: str, left: str, right: str) -> tuple[list[int], int]:
        t0 = time.time_ns()
        argv = ["stream", "--left", str(tmp_path / left), "--right", str(tmp_path / right)]
        assert main([*argv, *common, "--bag", str(tmp_path / name)]) == 0
        end = time.time_ns()
        with Reader(tmp_path / name) as reader:
            got = [t for c, t, _ in reader.messages() if c.topic == "/stereo/depth"]
        assert len(got) == n and t0 <= got[0] <= end  # the first: its grab
        capsys.readouterr()
        return got, end

    got, _ = stamps("video", "left.avi", "right.avi")
    assert np.diff(got).tolist() == [round(1e9 / fps)] * (n - 1)
    got, end = stamps("sequence", "left_%03d.png", "right_%03d.png")
    assert got == sorted(got) and got[-1] <= end  # each read's wall clock


@SLOW_PIPELINED
def test_sigterm_finishes_the_bag_of_a_stream(data_dir: Path, tmp_path: Path) -> None:
    """SIGTERM (kill, systemd) to `stream --bag` left a .db3 without metadata.yaml that no
    reader opens: the bag was one transaction, finished only by a normal end or Ctrl-C. Now
    the CLI turns SIGTERM into an interrupt: the bag is finished, every frame whole.

    The videos hold 100 pairs, far more than the stream gets through before the signal
    (measured: 2 frames in the bag; 300 pairs before, their encoding most of the set-up)."""
    import signal
    import subprocess
    import sys

    pytest.importorskip("rosbags")
    from rosbags.rosbag2 import Reader

    scene = data_dir / SCENE
    for side in ("left", "right"):
        img = cv2.imread(str(scene / f"{side}.png"))
        vw = cv2.VideoWriter(str(tmp_path / f"{side}.avi"), cv2.VideoWriter_fourcc(*"MJPG"),
                             FPS, (640, 480))  # fmt: skip
        for i in range(100):
            vw.write(np.roll(img, i % 3, axis=0))
        vw.release()
    bag = tmp_path / "bag"
    cmd = [sys.executable, "-m", "stereovision.cli", "stream",
           "--left", str(tmp_path / "left.avi"), "--right", str(tmp_path / "right.avi"),
           "--calib", str(scene / "calib.txt"), "--no-display", "--max-disparity", "64",
           "--no-check", "--bag", str(bag)]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            db = bag / "bag.db3"
            if db.exists() and db.stat().st_size > 4e6:  # a few frames in (about 1.5 MB each)
                break
            time.sleep(0.2)
        time.sleep(0.5)
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
    finally:  # a stream that deadlocked (the test's timeout) is not left running
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 143, err  # 128 + SIGTERM, after the summary and the bag
    assert " s (terminated): " in out and "Traceback" not in err
    assert err.strip().splitlines()[-1].startswith(f"ROS 2 bag written to {bag} (")
    with Reader(bag) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        rows = sum(1 for _ in reader.messages())
    assert len(counts) == 7 and len(set(counts.values())) == 1, counts  # whole frames
    assert 1 <= counts["/stereo/depth"] < 100 and rows == sum(counts.values())


def test_stream_says_when_one_video_ends_first(data_dir: Path, tmp_path: Path) -> None:
    """Two videos of different lengths: the stream ended at the shorter one as if both had
    ended; now a warning names the source that ended and that the other had more."""
    scene = data_dir / SCENE
    for side, n in (("left", 5), ("right", 3)):
        img = cv2.resize(cv2.imread(str(scene / f"{side}.png")), (320, 240))
        vw = cv2.VideoWriter(str(tmp_path / f"{side}.avi"), cv2.VideoWriter_fourcc(*"MJPG"),
                             FPS, (320, 240))  # fmt: skip
        for _ in range(n):
            vw.write(img)
        vw.release()
    cam = StereoCamera(str(tmp_path / "left.avi"), str(tmp_path / "right.avi"))
    with pytest.warns(UserWarning, match=r"right source .* ended after 3 frames; the left"):
        rep = run_stream(cam, method="gabor", max_disparity=32, pipelined=False, check=False)
    cam.close()
    assert rep.frames == 3 and rep.ended == "end of stream"


def test_a_port_in_use_is_said_with_its_number() -> None:
    """The view's port taken (another stream): the error names the address and the way out
    (it was "[Errno 98] Address already in use")."""
    import errno

    taken = FrameServer("127.0.0.1", 0)
    try:
        with pytest.raises(OSError) as info:
            FrameServer("127.0.0.1", taken.port)
    finally:
        taken.close()
    assert info.value.errno == errno.EADDRINUSE
    assert str(info.value) == (
        f"cannot serve the view on 127.0.0.1:{taken.port}: Address already in use (another "
        "stream running? choose another port with --serve PORT, or --no-display)"
    )
    with pytest.raises(OSError, match=r"cannot serve the view on no\.such\.host\.invalid:0: .* "
                                      r"\(check --host, or --no-display\)$"):  # fmt: skip
        FrameServer("no.such.host.invalid", 0)


def _request_threads() -> list[threading.Thread]:
    """The FrameServer's request handlers still running (socketserver names each thread after
    its target)."""
    return [t for t in threading.enumerate() if "process_request_thread" in t.name]


@pytest.mark.timeout(60)
def test_a_viewer_that_disconnects_mid_answer_prints_no_traceback(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A browser tab closed, or ffplay quit, while the view answered it (the page, a frame,
    the MJPEG stream's headers): socketserver printed its ~20-line traceback of the
    ConnectionResetError on the stream's stderr, among its reports. A viewer gone is no error:
    nothing is said, and the view still serves the next client."""
    import socket
    import struct

    srv = FrameServer("127.0.0.1", 0)
    try:
        rng = np.random.default_rng(0)  # a frame that does not compress to nothing
        left = rng.integers(0, 256, (240, 320, 3), dtype=np.uint8)
        srv.update(left, rng.random((240, 320), dtype=np.float32) * 64, 64.0)
        for path in ("/", "/frame.jpg", "/stream.mjpg"):
            client = socket.create_connection(("127.0.0.1", srv.port), timeout=10)
            client.sendall(f"GET {path} HTTP/1.1\r\nHost: x\r\n\r\n".encode())
            # closed at once with a reset (SO_LINGER 0), as a killed player's socket is
            client.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            client.close()
        # answered after the server accepted the three (one thread each, started at the accept)
        assert _get(srv.url + "frame.jpg")[:2] == (200, "image/jpeg")
        deadline = time.monotonic() + 20
        while _request_threads() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert _request_threads() == []
    finally:
        srv.close()
    assert capsys.readouterr().err == ""


@PIPELINED
def test_a_stream_stopped_before_its_first_frame_leaves_no_empty_bag(
    videos: dict[str, Path], data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A calibration for other frames stops the stream before its first frame: no empty bag is
    left in the way, so the same --bag works once the calibration is fixed (it was refused:
    "bag folder already exists")."""
    pytest.importorskip("rosbags")
    from rosbags.rosbag2 import Reader

    wrong = data_dir / "kitti2015/000005_10/calib.txt"  # 1242x375 frames
    bag = tmp_path / "bag"
    src = ["--left", str(videos["left"]), "--right", str(videos["right"]), "--no-display"]
    argv = [*src, "--frames", "2", "--max-disparity", "16", "--no-check", "--bag", str(bag)]
    assert main(["stream", *argv, "--calib", str(wrong)]) == 2
    assert "another aspect ratio" in capsys.readouterr().err
    assert not bag.exists()
    assert main(["stream", *argv, "--calib", str(videos["calib"])]) == 0
    with Reader(bag) as reader:
        assert {c.topic: c.msgcount for c in reader.connections}["/stereo/depth"] == 2


@PIPELINED
def test_a_source_failing_mid_stream_keeps_the_summary(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A right frame of another shape in pair 4: the stream printed the error alone (exit 2),
    the figures of the three pairs done lost. Now it ends there: the summary of those pairs,
    ``ended`` "source failed" with the error, then the error line, exit 2."""
    scene = data_dir / "middlebury2003" / "cones"
    for side in ("left", "right"):
        img = cv2.imread(str(scene / f"{side}.png"))
        for n in range(5):
            rows = 64 if side == "left" or n != 3 else 80
            cv2.imwrite(str(tmp_path / f"{side}_{n:03d}.png"), img[100 : 100 + rows, 100:196])
    argv = ["stream", "--left", str(tmp_path / "left_%03d.png"), "--no-display", "--no-check"]
    argv += ["--right", str(tmp_path / "right_%03d.png"), "--max-disparity", "16"]
    assert main(argv) == 2
    cap = capsys.readouterr()
    assert cap.out.splitlines()[-1].startswith("3 pairs in ")
    assert " s (source failed): " in cap.out
    err = cap.err.strip().splitlines()
    assert err[-1].startswith("stereovision: error: right source ") and "96x80 in pair 4" in err[-1]
    assert main([*argv, "--json"]) == 2
    summary = _json_lines(capsys.readouterr().out)[-1]
    assert summary["summary"] and summary["frames"] == 3
    assert summary["ended"] == "source failed" and "96x80 in pair 4" in summary["error"]
    cam = StereoCamera(str(tmp_path / "left_%03d.png"), str(tmp_path / "right_%03d.png"))
    with cam:
        rep = run_stream(cam, method="gabor", max_disparity=16, pipelined=False, check=False)
    assert (rep.frames, rep.ended) == (3, "source failed") and "pair 4" in (rep.error or "")


def test_stream_averages_frames_before_enlarging_them(data_dir: Path, tmp_path: Path) -> None:
    """160x120 sources of a still noisy view (8 grey levels) asked for at 320x240: the filter
    averaged the enlarged frames, whose interpolated noise (0.5 grey levels read) its motion
    test took for motion: 5 restarts of 6 pairs, nothing averaged, and the noise hint read the
    enlarged frame. Averaged as delivered, then enlarged: as at the sources' own size."""
    from stereovision.temporal import TemporalFilter
    from tests.test_exposure import noisy

    rng = np.random.default_rng(0)
    for side in ("left", "right"):
        img = cv2.imread(str(data_dir / "middlebury2003" / "cones" / f"{side}.png"))
        small = cv2.resize(img, (160, 120), interpolation=cv2.INTER_AREA)
        for i in range(6):
            cv2.imwrite(str(tmp_path / f"{side}_{i:02d}.png"), noisy(small, 8.0, rng))
    src = (str(tmp_path / "left_%02d.png"), str(tmp_path / "right_%02d.png"))
    shapes: list[tuple[int, ...]] = []
    with (
        warnings.catch_warnings(record=True) as caught,
        StereoCamera(*src, image_size="320x240") as cam,
    ):
        warnings.simplefilter("always")
        rep = run_stream(
            cam,
            method="gabor",
            max_disparity=16,
            pipelined=False,
            check=False,
            temporal=TemporalFilter(max_frames=4),
            on_result=lambda left, res: shapes.append(left.shape),
        )
    assert not [w for w in caught if "temporal averaging" in str(w.message)]
    assert rep.temporal is not None and rep.temporal["restarts"] == 0
    assert rep.temporal["frames_averaged"] > 2.9  # (1 + 2 + 3 + 4 + 4 + 4) / 6 = 3
    assert 4.8 < rep.noise_sigma < 7.0 and 4.8 < rep.temporal["noise_sigma"] < 7.0
    assert shapes == [(240, 320, 3)] * 6


@pytest.mark.parametrize("command", ["stream", "capture"])
def test_size_help_says_what_another_shape_does(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stream --help` said "frames are resized if needed", but a source of another shape
    keeps its own size (a resize would stretch it; tests/test_capture.py): said now, in both
    commands."""
    with pytest.raises(SystemExit) as info:
        main([command, "--help"])
    assert info.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert (
        "--size SIZE requested size WIDTHxHEIGHT (frames of the same shape are resized if "
        "needed; another shape keeps its own size, with a warning)"
    ) in text


@PIPELINED
def test_stream_asks_the_cameras_for_a_frame_rate(
    videos: dict[str, Path], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stream` had --size and --fourcc but no --fps (docs/robotics.md: "capture and stream ask
    for a format ... before the size and rate"): webcams ran at their default rate. It is asked
    now, as `capture --fps` asks it; a bag has none to ask."""
    from stereovision import capture as capmod

    asked: list[float | None] = []
    real = capmod.StereoCamera

    def camera(*args: Any, **kw: Any) -> StereoCamera:
        asked.append(kw.get("fps"))
        return real(*args, **kw)

    monkeypatch.setattr(capmod, "StereoCamera", camera)
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--max-disparity", "16", "--no-display", "--no-check", "--frames", "1"]
    assert main([*argv, "--fps", "15"]) == 0
    assert asked == [15.0]
    assert main(["stream", "--from-bag", "x", "--fps", "15", "--no-display"]) == 2
    assert capsys.readouterr().err.strip().splitlines()[-1] == (
        "stereovision: error: --fps: a bag is read as recorded, it has no frame rate to ask for"
    )
    # and --help says so (it said "a file or a bag is read as it is")
    with pytest.raises(SystemExit):
        main(["stream", "--help"])
    text = " ".join(capsys.readouterr().out.split())  # (help wraps at hyphens: none below)
    assert "format; a file is read as it is; refused with" in text
    assert "a bag has no rate to ask)" in text and "a file or a bag" not in text


@PIPELINED
def test_the_noise_hint_reads_the_frames_matched_when_the_source_shrinks_them(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """320x240 sources with noise 8 asked for at 160x120: the hint read the frames as delivered
    (6.0 grey levels) and warned that the depth maps suffered, but the halved frames matched
    read 4.2 (INTER_AREA averages the noise): no hint, as before StereoFrame.delivered. Frames
    the source enlarges are still read as delivered (their spread noise reads low)."""
    from tests.test_exposure import noisy

    rng = np.random.default_rng(0)
    scene = data_dir / "middlebury2003" / "cones"
    for side in ("left", "right"):
        img = cv2.imread(str(scene / f"{side}.png"))
        for size, name in (((320, 240), "big"), ((160, 120), "small")):
            small = cv2.resize(img, size, interpolation=cv2.INTER_AREA)
            for i in range(2):
                cv2.imwrite(str(tmp_path / f"{name}_{side}_{i:02d}.png"), noisy(small, 8.0, rng))

    def stream(name: str, size: str) -> tuple[float, list[str]]:
        argv = ["stream", "--left", str(tmp_path / f"{name}_left_%02d.png"), "--right"]
        argv += [str(tmp_path / f"{name}_right_%02d.png"), "--size", size, "--json"]
        argv += ["--max-disparity", "16", "--no-display", "--no-check"]
        assert main(argv) == 0
        cap = capsys.readouterr()
        hints = [ln for ln in cap.err.splitlines() if "the cameras are noisy" in ln]
        return _json_lines(cap.out)[-1]["noise_sigma"], hints

    sigma, hints = stream("big", "160x120")
    assert 3.5 < sigma < 4.5 and hints == []
    sigma, hints = stream("small", "320x240")  # enlarged: read as delivered
    assert sigma > 4.5 and len(hints) == 1


@PIPELINED
def test_stream_sizes_opencv_stereo_calib_output_by_the_frames(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """OpenCV stereo_calib's intrinsics.yml + extrinsics.yml hold no image size: stream refused
    them ("this command cannot read it from its images, so save the rig once in Python ..."),
    exit 2. The frames size them now (an image sequence's 640x480)."""
    from test_calibration import _opencv_stereo_calib

    import stereovision.stream as stream

    rig = tmp_path / "rig"
    rig.mkdir()
    _opencv_stereo_calib(rig)  # 640x480, T (-120, 1.5, 0.8) mm
    for n in ("01", "02"):
        for side in ("left", "right"):
            shutil.copy(data_dir / "chessboard" / f"{side}{n}.jpg", tmp_path / f"{side}{n}.jpg")
    got: list[Calibration] = []
    real = stream.run_stream

    def spy(camera: Any, calib: Any = None, **kw: Any) -> Any:
        got.append(calib)
        return real(camera, calib, **kw)

    monkeypatch.setattr(stream, "run_stream", spy)
    argv = ["stream", "--left", str(tmp_path / "left%02d.jpg"), "--right"]
    argv += [str(tmp_path / "right%02d.jpg"), "--calib", str(rig), "--no-display", "--no-check"]
    argv += ["--max-disparity", "16", "--json"]
    capsys.readouterr()
    assert main(argv) == 2  # the unit is still needed, said with the option
    assert capsys.readouterr().err.endswith(
        "(the board's square size): pass --calib-unit (m, mm, cm, ft or in)\n"
    )
    assert main([*argv, "--calib-unit", "mm"]) == 0
    assert _json_lines(capsys.readouterr().out)[-1]["frames"] == 2
    (calib,) = got
    assert calib.image_size == (640, 480) and calib.unit == "mm"
    assert calib.baseline_m == pytest.approx(np.linalg.norm([120.0, 1.5, 0.8]) / 1000)


def test_a_source_without_a_size_asks_for_one_for_stereo_calib_output(tmp_path: Path) -> None:
    """A source that states no size before its frames (a bag) cannot size a calibration that
    holds none: the error asks for --size, not for a Python call."""
    from types import SimpleNamespace

    from test_calibration import _opencv_stereo_calib

    from stereovision.stream import _sized_calibration

    _opencv_stereo_calib(tmp_path)
    with pytest.raises(ValueError) as err:
        _sized_calibration(str(tmp_path), "mm", SimpleNamespace(size=None, delivered_size={}))
    assert str(err.value).endswith(
        "(the board's square size): pass the image size: --size WxH (this source states none "
        "before its frames)"
    )
    sized = SimpleNamespace(size=(320, 240), delivered_size={"left": (640, 480)})
    assert _sized_calibration(str(tmp_path), "mm", sized).image_size == (320, 240)


class _ModeCap:
    """A webcam stand-in whose driver reports one mode (640x480) and delivers another: its
    frames are ``images``, read in turn until they run out."""

    def __init__(self, images: list[np.ndarray]) -> None:
        self.images = list(images)
        self.frame: np.ndarray | None = None

    def isOpened(self) -> bool:
        return True

    def grab(self) -> bool:
        self.frame = self.images.pop(0) if self.images else None
        return self.frame is not None

    def retrieve(self) -> tuple[bool, np.ndarray | None]:
        return self.frame is not None, self.frame

    def get(self, prop: int) -> float:
        return {cv2.CAP_PROP_FRAME_WIDTH: 640.0, cv2.CAP_PROP_FRAME_HEIGHT: 480.0}.get(prop, 0.0)

    def set(self, prop: int, value: float) -> bool:
        return False

    def release(self) -> None:
        pass


class _Interrupted(_ModeCap):
    """A camera pressed Ctrl-C on before it delivered a frame."""

    def grab(self) -> bool:
        raise KeyboardInterrupt


def _interrupted_cameras(args: Any, fps: float | None = None) -> StereoCamera:
    """``open_source`` of two cameras interrupted before their first frame."""
    return StereoCamera(_Interrupted([]), _Interrupted([]))


@PIPELINED
def test_stream_sizes_stereo_calib_output_by_the_frames_delivered_not_the_mode_reported(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A calibration that holds no image size (OpenCV stereo_calib output) was sized by the
    camera's reported mode: a driver that reports 640x480 and delivers 320x240 failed every
    pair with 'calibration is for 640x480 images, got 320x240'. Without --size it is sized by
    the first pair delivered; --size still wins."""
    from test_calibration import _opencv_stereo_calib

    import stereovision.stream as stream

    rig = tmp_path / "rig"
    rig.mkdir()
    _opencv_stereo_calib(rig)
    small = {
        side: [
            cv2.resize(cv2.imread(str(data_dir / "chessboard" / f"{side}{n}.jpg")), (320, 240))
            for n in ("01", "02")
        ]
        for side in ("left", "right")
    }

    def cameras(args: Any, fps: float | None = None) -> StereoCamera:
        return StereoCamera(_ModeCap(small["left"]), _ModeCap(small["right"]), image_size=args.size)

    got: list[Calibration] = []
    real = stream.run_stream

    def spy(camera: Any, calib: Any = None, **kw: Any) -> Any:
        got.append(calib)
        return real(camera, calib, **kw)

    monkeypatch.setattr(stream, "open_source", cameras)
    monkeypatch.setattr(stream, "run_stream", spy)
    argv = ["stream", "--left", "0", "--right", "1", "--calib", str(rig), "--calib-unit", "mm"]
    argv += ["--no-display", "--no-check", "--max-disparity", "16", "--json"]
    capsys.readouterr()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(argv) == 0, capsys.readouterr().err
        assert _json_lines(capsys.readouterr().out)[-1]["frames"] == 2
        assert got[-1].image_size == (320, 240)
        assert main([*argv, "--size", "160x120"]) == 0, capsys.readouterr().err
    assert got[-1].image_size == (160, 120)


@PIPELINED
def test_stream_fits_a_calibration_to_the_frames_delivered_not_the_mode_reported(
    data_dir: Path,
) -> None:
    """A calibration made at 640x480 was fitted to the camera's reported mode (640x480, so left
    as is) while the driver delivered 320x240: the first pair failed. It is fitted to the first
    pair delivered now (halved), each depth map is the halved pair's with the halved
    calibration, and one line says the camera delivers another size than it reports."""
    scene = data_dir / SCENE
    calib = Calibration.from_file(scene / "calib.txt")
    assert calib.image_size == (640, 480)
    small = {
        side: cv2.resize(cv2.imread(str(scene / f"{side}.png")), (320, 240), cv2.INTER_AREA)
        for side in ("left", "right")
    }
    got: list[np.ndarray] = []
    for pipelined in (True, False):
        got.clear()
        cam = StereoCamera(_ModeCap([small["left"]] * 2), _ModeCap([small["right"]] * 2))
        with cam, warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            rep = run_stream(
                cam,
                calib,
                max_disparity=32,
                check=False,
                pipelined=pipelined,
                on_result=lambda left, res: got.append(res.disparity),
            )
        assert rep.frames == 2 and rep.ended == "end of stream" and rep.error is None
        said = [str(w.message) for w in caught]
        assert said == [
            "the calibration is for 640x480 and the frames are 320x240: scaled to them (a "
            "camera mode that crops instead of scaling needs its own calibration)",
            "the left camera reports 640x480 but delivers 320x240: the calibration is fitted "
            "to the frames delivered",
        ]
        ref = depth_map(
            small["left"],
            small["right"],
            calib.scaled_to((320, 240)),
            method="gabor",
            max_disparity=32,
            refine=False,
        ).disparity
        assert len(got) == 2
        for disp in got:
            np.testing.assert_array_equal(disp, ref)


@PIPELINED
def test_a_stream_interrupted_before_its_first_pair_writes_strict_json(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C before the first pair was done: the --json summary's figures with nothing to
    measure were written as NaN, which a strict JSON parser refuses; they are null now."""
    import stereovision.stream as stream

    monkeypatch.setattr(stream, "open_source", _interrupted_cameras)
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--json"]
    argv += ["--max-disparity", "16"]
    assert main(argv) == 130

    def refuse(word: str) -> None:
        raise ValueError(f"not strict JSON: {word}")

    (line,) = capsys.readouterr().out.splitlines()
    summary = json.loads(line, parse_constant=refuse)
    assert (summary["frames"], summary["ended"]) == (0, "interrupted")
    assert summary["density"] is None and summary["noise_sigma"] is None
    assert summary["latency_ms"] is None and set(summary["stage_ms"].values()) == {None}


def test_a_calibrated_streams_seconds_count_from_its_first_grab(data_dir: Path) -> None:
    """With a calibration the first pair is read before the pipeline (to fit the calibration to
    it), and the run's time started after that grab: a camera taking 0.3 s for it streamed one
    pair in 0.05 s (fps 20 for 2.5) with a latency of 0.35 s. It counts from the first grab, as
    a run without a calibration does."""
    scene = data_dir / SCENE
    calib = Calibration.from_file(scene / "calib.txt").scaled_to((160, 120))
    imgs = {
        side: cv2.resize(cv2.imread(str(scene / f"{side}.png")), (160, 120), cv2.INTER_AREA)
        for side in ("left", "right")
    }

    class _SlowFirst(_ModeCap):
        def grab(self) -> bool:
            if len(self.images) == 1:
                time.sleep(0.3)
            return super().grab()

    for c in (None, calib):
        cam = StereoCamera(_SlowFirst([imgs["left"]]), _SlowFirst([imgs["right"]]))
        with cam, warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the mode reported (640x480) is not the frames'
            rep = run_stream(cam, c, max_disparity=8, check=False, pipelined=False, frames=1)
        assert rep.frames == 1 and rep.stage_ms["grab"] >= 300
        assert rep.seconds >= 0.3 and 1e3 * rep.seconds >= rep.latency_ms - 1e-6
        assert rep.fps == pytest.approx(1 / rep.seconds)


@PIPELINED
def test_a_calibrated_stream_interrupted_before_its_first_pair_writes_its_summary(
    data_dir: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """With a calibration the first pair is read before the pipeline: Ctrl-C (or SIGTERM) while
    the camera had not delivered it left run_stream with the KeyboardInterrupt, and the CLI said
    'interrupted' without the summary a stream without a calibration writes. It is the summary
    of no pair now, ended 'interrupted' ('terminated'), exit 130."""
    import stereovision.stream as stream
    from stereovision._interrupt import Terminated

    calib = Calibration.from_file(data_dir / SCENE / "calib.txt")
    for signal, ended in ((KeyboardInterrupt, "interrupted"), (Terminated, "terminated")):

        class _Stopped(_ModeCap):
            raised: type[BaseException] = signal

            def grab(self) -> bool:
                raise self.raised

        rep = run_stream(StereoCamera(_Stopped([]), _Stopped([])), calib, max_disparity=16)
        assert (rep.frames, rep.ended, rep.error) == (0, ended, None)

    monkeypatch.setattr(stream, "open_source", _interrupted_cameras)
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--json"]
    argv += ["--max-disparity", "16", "--calib", str(data_dir / SCENE / "calib.txt")]
    assert main(argv) == 130
    cap = capsys.readouterr()
    (line,) = cap.out.splitlines()
    summary = json.loads(line)
    assert (summary["frames"], summary["ended"], summary["latency_ms"]) == (0, "interrupted", None)


def test_run_streams_usage_errors_come_before_the_first_grab(data_dir: Path) -> None:
    """With a calibration the first pair is read before the pipeline; check_every and
    ground_every were checked after it: a usage error took a pair off the camera first (and a
    camera with no frame said that instead). They are refused before any grab now."""
    calib = Calibration.from_file(data_dir / SCENE / "calib.txt")
    img = cv2.imread(str(data_dir / SCENE / "left.png"))
    for kw, said in (
        ({"check_every": 0}, "check_every: expected a positive number of pairs, got 0"),
        ({"ground_every": -1}, "ground_every: expected a positive number of pairs, got -1"),
    ):
        cam = StereoCamera(_ModeCap([img]), _ModeCap([img]))
        with cam, pytest.raises(ValueError) as err:
            run_stream(cam, calib, max_disparity=16, **kw)
        assert str(err.value) == said and cam.count == 0


def test_an_unknown_method_is_refused_before_the_first_grab(data_dir: Path) -> None:
    """run_stream left the method to depth_map, on the first pair: an unknown one took a pair
    off the camera first (read ahead with a calibration, grabbed by the pipeline without), and
    a camera with no frame said that instead. It is refused before any grab now."""
    calib = Calibration.from_file(data_dir / SCENE / "calib.txt")
    img = cv2.imread(str(data_dir / SCENE / "left.png"))
    for rig in (calib, None):
        cam = StereoCamera(_ModeCap([img]), _ModeCap([img]))
        with cam, pytest.raises(ValueError) as err:
            run_stream(cam, rig, max_disparity=16, method="bogus")
        assert (
            str(err.value) == ("unknown method 'bogus': expected one of fused, gabor, census, fast")
            and cam.count == 0
        ), rig


@PIPELINED
def test_a_stream_sized_by_its_first_pair_interrupted_before_it_writes_its_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A calibration that holds no image size (OpenCV stereo_calib output) is sized by the
    first pair, read before the stream starts: Ctrl-C (or SIGTERM) before the cameras delivered
    it gave 'interrupted' and no summary, unlike every other interrupt. It is the summary of no
    pair now, ended 'interrupted' (exit 130) or 'terminated' (exit 143)."""
    from test_calibration import _opencv_stereo_calib

    import stereovision.stream as stream
    from stereovision._interrupt import Terminated

    _opencv_stereo_calib(tmp_path)
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--max-disparity", "16"]
    argv += ["--calib", str(tmp_path), "--calib-unit", "mm"]
    for raised, ended, status in (
        (KeyboardInterrupt, "interrupted", 130),
        (Terminated, "terminated", 143),
    ):

        class _Stopped(_ModeCap):
            signal: type[KeyboardInterrupt] = raised

            def grab(self) -> bool:
                raise self.signal("signal")

        monkeypatch.setattr(
            stream,
            "open_source",
            lambda args, fps=None: StereoCamera(_Stopped([]), _Stopped([])),
        )
        assert main([*argv, "--json"]) == status
        cap = capsys.readouterr()
        (line,) = cap.out.splitlines()
        summary = json.loads(line)
        assert (summary["frames"], summary["ended"], summary["max_disparity"]) == (0, ended, 16)
        assert summary["latency_ms"] is None and cap.err == ""
        assert main(argv) == status
        assert capsys.readouterr().out.startswith(f"0 pairs in 0.00 s ({ended}): 0.0 fps;")


@PIPELINED
def test_a_temporal_stream_stopped_before_its_first_pair_measured_no_noise(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """--temporal, Ctrl-C before the first pair: the summary's temporal noise said 0.0 grey
    levels, a measurement of frames never seen (the filter's starting value). It is null (NaN)
    now, as the summary's own noise_sigma is; the frames averaged too."""
    import stereovision.stream as stream
    from stereovision.temporal import TemporalFilter

    rep = run_stream(_interrupted_cameras(None), max_disparity=16, temporal=TemporalFilter())
    assert rep.frames == 0 and rep.ended == "interrupted"
    assert rep.temporal is not None and rep.temporal["restarts"] == 0
    assert np.isnan(rep.temporal["noise_sigma"]) and np.isnan(rep.temporal["frames_averaged"])
    monkeypatch.setattr(stream, "open_source", _interrupted_cameras)
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--json", "--temporal", "8"]
    assert main([*argv, "--max-disparity", "16"]) == 130
    (line,) = capsys.readouterr().out.splitlines()
    assert json.loads(line)["temporal"] == {
        "frames_averaged": None,
        "restarts": 0,
        "noise_sigma": None,
    }


@PIPELINED
def test_a_bag_that_cannot_be_written_mid_stream_keeps_the_summary(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """--bag on a disk that filled after two pairs: the stream printed the error alone (exit 2),
    no summary (with --json nothing at all on stdout), the figures of the pairs done lost, where
    a failing source keeps them. It ends there now as that does: the summary of the pairs done,
    ``ended`` "output failed" with the error, then the error line, exit 2."""
    import stereovision.rosbag as rosbag

    class _FullDisk:
        def __init__(self, path: Any, **kw: Any) -> None:
            self.path, self.messages, self.frames = Path(path), 0, 0

        def write(self, res: Any, stamp_ns: int, **kw: Any) -> None:
            if self.messages == 14:  # two pairs of 7 messages
                raise OSError(f"bag {self.path}: database or disk is full")
            self.messages += 7
            self.frames += 1

        def close(self) -> None:
            pass

    monkeypatch.setattr(rosbag, "BagWriter", _FullDisk)
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"]), "--json"]
    argv += ["--calib", str(videos["calib"]), "--no-display", "--no-check", "--max-disparity", "16"]
    assert main([*argv, "--bag", "b"]) == 2
    cap = capsys.readouterr()
    summary = _json_lines(cap.out)[-1]
    assert (summary["summary"], summary["frames"], summary["ended"]) == (True, 2, "output failed")
    assert summary["error"] == "bag b: database or disk is full"
    err = cap.err.strip().splitlines()
    assert err[-1] == "stereovision: error: bag b: database or disk is full"
    assert "ROS 2 bag written to b (2 of the 2 pairs processed, 14 messages)" in cap.err


@PIPELINED
def test_a_closed_stdout_still_says_what_the_bag_holds(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """`stream --json --bag DIR | head -n1`: the reader went away after the first report, and
    the next report's BrokenPipeError went past the summary (exit 141) without the line saying
    what the bag holds, on stderr that is still open. It stops as before (141), with that line."""
    import io

    import stereovision.rosbag as rosbag
    import stereovision.stream as stream

    class _Bag:
        def __init__(self, path: Any, **kw: Any) -> None:
            self.path, self.messages, self.frames = Path(path), 0, 0

        def write(self, res: Any, stamp_ns: int, **kw: Any) -> None:
            self.messages += 7
            self.frames += 1

        def close(self) -> None:
            pass

    class _HeadOne(io.StringIO):  # a pipe whose reader (head -n1) left after the first line
        def write(self, text: str) -> int:
            if "\n" in self.getvalue():
                raise BrokenPipeError(32, "Broken pipe")
            return super().write(text)

    run = stream.run_stream
    monkeypatch.setattr(rosbag, "BagWriter", _Bag)
    # a report for every pair: the second pair's is the write that fails
    monkeypatch.setattr(stream, "run_stream", lambda *a, **kw: run(*a, **kw, report_period=0))
    monkeypatch.setattr("sys.stdout", _HeadOne())
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"]), "--json"]
    argv += ["--calib", str(videos["calib"]), "--no-display", "--no-check", "--max-disparity", "16"]
    assert main([*argv, "--frames", "4", "--bag", "b"]) == 141
    assert capsys.readouterr().err.splitlines() == [
        "ROS 2 bag written to b (2 of the 2 pairs processed, 14 messages)"
    ]


@PIPELINED
def test_the_text_summary_of_no_pair_says_so_not_nan(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A stream stopped before its first pair printed "nan ms" for every stage, the latency
    and the skew, and "nan frames averaged ... noise nan grey levels" with --temporal. The text
    says no pair was processed now; --json keeps its nulls."""
    import stereovision.stream as stream

    monkeypatch.setattr(stream, "open_source", _interrupted_cameras)
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--max-disparity", "16"]
    assert main([*argv, "--temporal", "8"]) == 130
    out = capsys.readouterr().out
    assert out.splitlines() == [
        "0 pairs in 0.00 s (interrupted): 0.0 fps; no pair processed; max_disparity 16",
        "temporal: no pair filtered, 0 restarts",
    ]
    assert "nan" not in out
    assert main(argv) == 130
    assert capsys.readouterr().out.splitlines() == [
        "0 pairs in 0.00 s (interrupted): 0.0 fps; no pair processed; max_disparity 16"
    ]
    assert main([*argv, "--json"]) == 130
    summary = json.loads(capsys.readouterr().out)
    assert summary["stage_ms"]["match"] is None and summary["latency_ms"] is None


@PIPELINED
def test_a_bag_of_no_frame_is_not_said_written(
    videos: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """--bag, stopped before the first pair: the empty bag folder is removed (so the next run
    can use it), yet the summary said "ROS 2 bag written to DIR (0 messages)"."""
    import stereovision.stream as stream

    monkeypatch.setattr(stream, "open_source", _interrupted_cameras)
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--max-disparity", "16"]
    argv += ["--calib", str(videos["calib"]), "--bag", str(tmp_path / "b")]
    assert main(argv) == 130
    assert capsys.readouterr().err == f"no ROS 2 bag written to {tmp_path / 'b'}: no frame in it\n"
    assert not (tmp_path / "b").exists()


@pytest.mark.parametrize("committed", [0, 1, 2])
def test_the_frames_a_full_disk_undid_are_said(
    videos: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    committed: int,
) -> None:
    """--bag on a disk that filled at the fourth pair: SQLite undid every frame since the bag's
    last commit, and the stream said "3 pairs ... (output failed)" and "no ROS 2 bag written:
    no frame in it" (or a bag of fewer frames) without saying the pairs processed were lost.
    The bag line says how many of them the bag holds, and that the disk undid the rest."""
    import stereovision.rosbag as rosbag

    monkeypatch.setattr(rosbag, "COMMIT_PERIOD_S", 3600.0)  # no commit but those made here
    real = rosbag.BagWriter

    class _FillingBag(real):  # type: ignore[misc,valid-type]
        def write(self, res: Any, stamp_ns: int, **kw: Any) -> None:
            if self.frames == committed:
                self._commit()
            if self.frames == 3:  # a real full database: sqlite rolls its transaction back
                conn = self._writer.storage.conn
                pages = conn.execute("PRAGMA page_count").fetchone()[0]
                conn.execute(f"PRAGMA max_page_count = {pages}")
            super().write(res, stamp_ns, **kw)

    monkeypatch.setattr(rosbag, "BagWriter", _FillingBag)
    bag = tmp_path / "b"
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--no-display", "--no-check", "--no-pipeline"]
    assert main([*argv, "--max-disparity", "16", "--bag", str(bag)]) == 2
    cap = capsys.readouterr()
    assert "3 pairs in " in cap.out and "(output failed)" in cap.out
    err = cap.err.strip().splitlines()
    lost = "the disk filled and SQLite undid the frames since the bag's last commit"
    if committed:  # one frame lost is said so ("(1 frames lost)" before)
        n_lost = 3 - committed
        assert err[-2] == (
            f"ROS 2 bag written to {bag} ({committed} of the 3 pairs processed, "
            f"{7 * committed} messages); {lost} ({n_lost} frame{'s' if n_lost > 1 else ''} lost)"
        )
    else:
        none = f"no ROS 2 bag written to {bag}: none of the 3 pairs processed"
        assert err[-2] == f"{none}; {lost} (3 frames lost)"
        assert not bag.exists()
    assert err[-1] == f"stereovision: error: bag {bag}: database or disk is full"


@pytest.mark.parametrize("pipelined", [False, True])
@PIPELINED
def test_the_temporal_figures_are_those_of_the_pairs_counted(
    videos: dict[str, Path], pipelined: bool
) -> None:
    """An output that failed at the third pair (a full disk): the summary counted 2 pairs, but
    its temporal restarts and noise came from the filter, which had also taken the third (and,
    pipelined, those grabbed ahead): 2 restarts or more of 2 pairs on the videos' moving view,
    where each pair after the first restarts. They are those of the pairs counted now."""
    from stereovision.temporal import TemporalFilter

    calls = [0]

    def full_at_3(left: np.ndarray, res: Any, stamp_ns: int) -> None:
        calls[0] += 1
        if calls[0] == 3:
            raise OSError("bag b: database or disk is full")

    tf = TemporalFilter()
    with StereoCamera(str(videos["left"]), str(videos["right"])) as cam:
        rep = run_stream(
            cam,
            max_disparity=16,
            pipelined=pipelined,
            check=False,
            temporal=tf,
            on_stamped_result=full_at_3,
        )
    assert (rep.frames, rep.ended) == (2, "output failed")
    assert rep.temporal is not None
    assert rep.temporal["restarts"] == 1  # the second pair's, of the pairs counted
    assert rep.temporal["frames_averaged"] == 1.0
    assert tf.frames >= 3 and tf.restarts >= 2  # the filter itself took the third pair too


def _unclosable_bag(fail_write_at: int | None = None) -> type:
    """A BagWriter whose close raises as a disk still full at its last commit does (and whose
    write fails at frame ``fail_write_at``)."""

    class _Unclosable:
        def __init__(self, path: Any, **kw: Any) -> None:
            self.path, self.messages, self.frames = Path(path), 0, 0

        def write(self, res: Any, stamp_ns: int, **kw: Any) -> None:
            if self.frames == fail_write_at:
                raise OSError(f"bag {self.path}: database or disk is full")
            self.messages += 7
            self.frames += 1

        def close(self) -> None:
            raise OSError(
                f"bag {self.path} could not be finished (database or disk is full): the frames "
                f"committed before are in its .db3; `ros2 bag reindex {self.path}` rebuilds its "
                "metadata.yaml"
            )

    return _Unclosable


CLOSE_ERROR = (
    "stereovision: error: bag b could not be finished (database or disk is full): the frames "
    "committed before are in its .db3; `ros2 bag reindex b` rebuilds its metadata.yaml"
)


@PIPELINED
def test_a_bag_that_cannot_be_finished_keeps_the_summary(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """--bag whose close failed (the disk still full at its last commit): the OSError raised
    from the ``finally`` past the summary, the user left with the error alone (nothing on
    stdout with --json). The run ends as an output failing mid-stream does: the summary of the
    pairs processed (``ended`` "output failed", its error), the bag line, then the error line
    naming the bag and ``ros2 bag reindex``, exit 2."""
    import stereovision.rosbag as rosbag

    monkeypatch.setattr(rosbag, "BagWriter", _unclosable_bag())
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--no-display", "--no-check", "--max-disparity", "16"]
    argv += ["--frames", "2", "--bag", "b"]
    assert main([*argv, "--json"]) == 2
    cap = capsys.readouterr()
    summary = _json_lines(cap.out)[-1]
    assert (summary["summary"], summary["frames"], summary["ended"]) == (True, 2, "output failed")
    assert summary["error"] == CLOSE_ERROR.removeprefix("stereovision: error: ")
    err = cap.err.strip().splitlines()
    assert err[-2:] == [
        "ROS 2 bag written to b (2 of the 2 pairs processed, 14 messages)",
        CLOSE_ERROR,
    ]
    assert main(argv) == 2
    cap = capsys.readouterr()
    last = cap.out.splitlines()[-1]
    assert last.startswith("2 pairs in ") and " s (output failed): " in last
    assert cap.err.strip().splitlines()[-1] == CLOSE_ERROR


@PIPELINED
def test_a_bag_that_cannot_be_finished_does_not_replace_an_earlier_error(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A bag whose close failed after an earlier failure: the close's OSError replaced it (a
    write that failed, an interrupt's exit 130, an error raised out of the stream). Both are
    said now, the first one's first, and the first one's exit status is kept."""
    import stereovision.rosbag as rosbag
    import stereovision.stream as stream

    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--no-display", "--no-check", "--max-disparity", "16"]
    argv += ["--bag", "b"]
    # a write failed at the third pair, then the close
    monkeypatch.setattr(rosbag, "BagWriter", _unclosable_bag(fail_write_at=2))
    assert main([*argv, "--json"]) == 2
    cap = capsys.readouterr()
    summary = _json_lines(cap.out)[-1]
    assert (summary["frames"], summary["ended"]) == (2, "output failed")
    assert summary["error"] == "bag b: database or disk is full"
    err = cap.err.strip().splitlines()
    assert err[-2:] == ["stereovision: error: bag b: database or disk is full", CLOSE_ERROR]
    # Ctrl-C: the summary says it was interrupted, with the close's error; still exit 130
    monkeypatch.setattr(rosbag, "BagWriter", _unclosable_bag())
    monkeypatch.setattr(stream, "open_source", _interrupted_cameras)
    assert main([*argv, "--json"]) == 130
    cap = capsys.readouterr()
    summary = json.loads(cap.out)
    assert (summary["frames"], summary["ended"]) == (0, "interrupted")
    assert summary["error"] == CLOSE_ERROR.removeprefix("stereovision: error: ")
    assert cap.err.strip().splitlines()[-1] == CLOSE_ERROR

    # an error or interrupt raised out of the stream: said after the close's, its status kept
    def raising(exc: BaseException) -> Any:
        def run(*a: Any, **kw: Any) -> Any:
            raise exc

        return run

    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: _interrupted_cameras(args))
    for exc, status, last in (
        (RuntimeError("matcher failed"), 2, "stereovision: error: matcher failed"),
        (KeyboardInterrupt(), 130, "stereovision: interrupted"),
    ):
        monkeypatch.setattr(stream, "run_stream", raising(exc))
        assert main(argv) == status
        cap = capsys.readouterr()
        assert cap.out == ""
        assert cap.err.strip().splitlines() == [CLOSE_ERROR, last]


@PIPELINED
def test_a_camera_that_fails_to_close_still_lets_the_bag_be_finished(
    videos: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The stream closed the camera (and the live view's server) before the bag in one
    ``finally``: a camera whose close raised left the bag unfinished, no metadata.yaml (a bag
    ``ros2 bag play`` refuses until reindexed). The bag is finished whatever the camera does."""
    pytest.importorskip("rosbags")
    from rosbags.rosbag2 import Reader

    import stereovision.stream as stream

    real_open = stream.open_source

    def _opens_a_camera_that_fails_to_close(*a: Any, **kw: Any) -> Any:
        cam = real_open(*a, **kw)
        closing = cam.close

        def close() -> None:
            closing()
            raise RuntimeError("camera: the driver did not let go of /dev/video0")

        cam.close = close
        return cam

    monkeypatch.setattr(stream, "open_source", _opens_a_camera_that_fails_to_close)
    bag = tmp_path / "b"
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--no-display", "--no-check", "--frames", "2"]
    assert main([*argv, "--max-disparity", "16", "--bag", str(bag)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == "stereovision: error: camera: the driver did not let go of /dev/video0"
    assert (bag / "metadata.yaml").is_file()
    with Reader(bag) as reader:
        assert {c.msgcount for c in reader.connections} == {2}


class _FakeRig:
    """A stereo camera stand-in: ``read`` hands out ``pairs`` (a StereoFrame or an exception
    to raise) in turn; ``stamps_ns`` (a recording's stamps) grows by one per pair when given."""

    def __init__(self, pairs: list[Any], stamps_ns: list[int] | None = None) -> None:
        self._pairs = list(pairs)
        self.count = 0
        self.size = None
        self.delivered_size: dict[str, tuple[int, int]] = {}
        self._stamps = stamps_ns
        if stamps_ns is not None:
            self.stamps_ns: list[int] = []

    def read(self) -> Any:
        from stereovision.capture import SourceError

        if not self._pairs:
            raise SourceError("ended", end=True)
        item = self._pairs.pop(0)
        if isinstance(item, BaseException):
            raise item
        if self._stamps is not None:
            self.stamps_ns.append(self._stamps[self.count])
        self.count += 1
        return item


def _frame(index: int, t_left: float | None = None, t_right: float | None = None) -> Any:
    from stereovision.capture import StereoFrame

    rng = np.random.default_rng(index)
    # smooth texture: no noise warning
    left = cv2.GaussianBlur(rng.integers(0, 255, (48, 64, 3), dtype=np.uint8), (7, 7), 2.0)
    now = time.monotonic()
    return StereoFrame(left, np.roll(left, -2, axis=1), now if t_left is None else t_left,
                       now if t_right is None else t_right, index)  # fmt: skip


def test_run_stream_refuses_no_frames() -> None:
    """frames=0 (nothing to do) is a usage error, as a negative count is."""
    with pytest.raises(ValueError, match="frames: expected a positive number of pairs, got 0"):
        run_stream(_FakeRig([_frame(0)]), max_disparity=8, frames=0)  # type: ignore[arg-type]


def test_run_stream_refuses_counts_that_are_no_whole_number() -> None:
    """frames=nan matched no pair and said "end of stream", frames=2.5 matched 3 and
    frames=True one; check_every=2.5 checked pairs 0, 5, 10. Each is refused before any grab
    now; a whole float (2.0) is still its integer."""
    nan = float("nan")
    for kw, said in (
        ({"frames": nan}, "frames: expected a positive number of pairs, got nan"),
        ({"frames": 2.5}, "frames: expected a positive number of pairs, got 2.5"),
        ({"frames": True}, "frames: expected a positive number of pairs, got True"),
        ({"frames": "2"}, "frames: expected a positive number of pairs, got '2'"),
        ({"check_every": 2.5}, "check_every: expected a positive number of pairs, got 2.5"),
        ({"check_every": nan}, "check_every: expected a positive number of pairs, got nan"),
        ({"ground_every": 2.5}, "ground_every: expected a positive number of pairs, got 2.5"),
    ):
        rig = _FakeRig([_frame(i) for i in range(4)])
        with pytest.raises(ValueError) as err:
            run_stream(rig, max_disparity=8, check=False, **kw)  # type: ignore[arg-type]
        assert str(err.value) == said and rig.count == 0
    rig = _FakeRig([_frame(i) for i in range(4)])
    rep = run_stream(rig, max_disparity=8, pipelined=False, check=False, frames=2.0)  # type: ignore[arg-type]
    assert (rep.frames, rep.ended, rig.count) == (2, "frames", 2)


def test_run_stream_refuses_a_report_period_that_is_no_number_of_seconds() -> None:
    """report_period="1" raised TypeError from the loop once the first pair was matched (a pair
    taken off the camera); NaN gave no report but the last, -1 one per pair as 0 does. Each is
    refused before any grab now; 0 (a report per pair) and inf (the last alone) still work."""
    for period in (float("nan"), -1, "1", True, None):
        rig = _FakeRig([_frame(i) for i in range(3)])
        with pytest.raises(ValueError) as err:
            run_stream(rig, max_disparity=8, pipelined=False, check=False, report_period=period)  # type: ignore[arg-type]
        assert str(err.value) == (
            f"report_period: expected a number of seconds >= 0, got {period!r}"
        )
        assert rig.count == 0
    # a timedelta64 (an np.integer) passed, and the loop's UFuncTypeError came after a pair was
    # taken; -10**5000 has no repr (Python's "Exceeds the limit (4300 digits)", naming nothing)
    for period, shown in (
        (np.timedelta64(1, "s"), "np.timedelta64(1,'s')"),
        (-(10**5000), "a negative integer of 5001 digits"),
    ):
        rig = _FakeRig([_frame(i) for i in range(3)])
        with pytest.raises(ValueError) as err:
            run_stream(rig, max_disparity=8, pipelined=False, check=False, report_period=period)  # type: ignore[arg-type]
        assert str(err.value) == f"report_period: expected a number of seconds >= 0, got {shown}"
        assert rig.count == 0
    for period, reports in ((0.0, 3), (float("inf"), 1)):
        rig = _FakeRig([_frame(i) for i in range(3)])
        rep = run_stream(rig, max_disparity=8, pipelined=False, check=False, report_period=period)  # type: ignore[arg-type]
        assert (rep.frames, len(rep.reports)) == (3, reports)


def test_the_report_keeps_the_latest_reports_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """StreamReport.reports kept every per-second report, 1.3 kB each: 114 MB a day at the
    default period, 140 MB an hour with one per pair at 30 fps. It keeps the latest
    REPORTS_KEPT; on_report still gets every one."""
    import stereovision.stream as stream

    monkeypatch.setattr(stream, "REPORTS_KEPT", 2, raising=False)  # (fails on the old code)
    got: list[dict[str, Any]] = []
    rig = _FakeRig([_frame(i) for i in range(4)])
    rep = run_stream(rig, max_disparity=8, pipelined=False, check=False, report_period=0.0,  # type: ignore[arg-type]
                     on_report=got.append)  # fmt: skip
    assert [r["total_frames"] for r in got] == [1, 2, 3, 4]
    assert rep.reports == got[2:] and isinstance(rep.reports, list)


def test_a_first_pair_that_does_not_decode_is_a_value_error() -> None:
    """A recording's first frame that does not decode raises its ValueError as it is; only a
    later one becomes the source failing (SourceError, the stream's summary)."""
    bad = ValueError("frame 0 does not decode")
    with pytest.raises(ValueError, match="does not decode") as err:
        run_stream(_FakeRig([bad]), max_disparity=8, pipelined=False, check=False)  # type: ignore[arg-type]
    assert type(err.value) is ValueError
    rep = run_stream(_FakeRig([_frame(0), ValueError("frame 1 does not decode")]),  # type: ignore[arg-type]
                     max_disparity=8, pipelined=False, check=False)  # fmt: skip
    assert (rep.frames, rep.ended, rep.error) == (1, "source failed", "frame 1 does not decode")


def test_a_later_frame_the_temporal_filter_cannot_average_ends_the_stream() -> None:
    """A 16-bit image after 8-bit pairs (a sequence mixing them) with ``temporal`` raised the
    filter's ValueError out of run_stream, the summary of the pairs done lost (the CLI said the
    error line alone); it ends the stream as a source failing, those pairs reported. On the
    first pair it is raised as before."""
    from stereovision.capture import StereoFrame
    from stereovision.temporal import TemporalFilter

    deep = _frame(2)
    deep = StereoFrame(deep.left.astype(np.uint16) * 257, deep.right.astype(np.uint16) * 257,
                       deep.t_left, deep.t_right, 2)  # fmt: skip
    rig = _FakeRig([_frame(0), _frame(1), deep])
    rep = run_stream(rig, max_disparity=8, pipelined=False, check=False, temporal=TemporalFilter(4))  # type: ignore[arg-type]
    assert (rep.frames, rep.ended) == (2, "source failed")
    assert rep.error == (
        "temporal averaging takes 8-bit frames: the left source delivers uint16 ones (a 16-bit "
        "image sequence?); convert them to 8 bits, or leave the averaging out"
    )
    with pytest.raises(ValueError, match="temporal averaging takes 8-bit frames") as err:
        run_stream(_FakeRig([deep]), max_disparity=8, pipelined=False, check=False,  # type: ignore[arg-type]
                   temporal=TemporalFilter(4))  # fmt: skip
    assert type(err.value) is ValueError


def test_a_later_frame_that_does_not_decode_is_no_end_of_the_source() -> None:
    """A camera whose first pair was read before the stream (a preview) and whose next frame
    does not decode: no pair was done, so the error is raised, a SourceError that is not an end
    (``end`` False, as capture's failing sources say; a mutation audit left it unasserted)."""
    from stereovision.capture import SourceError

    rig = _FakeRig([_frame(0), ValueError("frame 1 does not decode")])
    rig.read()
    with pytest.raises(SourceError, match="frame 1 does not decode") as err:
        run_stream(rig, max_disparity=8, pipelined=False, check=False)  # type: ignore[arg-type]
    assert (err.value.end, err.value.frames) == (False, 1)


def test_a_recordings_results_carry_each_pairs_own_stamp() -> None:
    """A recording's pair is stamped with its own stamp (the latest read), not its first's."""
    stamps = [1_000_000_000, 1_033_000_000, 1_066_000_000]
    seen: list[int] = []
    run_stream(_FakeRig([_frame(i) for i in range(3)], stamps_ns=stamps),  # type: ignore[arg-type]
               max_disparity=8, pipelined=False, check=False,
               on_stamped_result=lambda left, res, ns: seen.append(ns))  # fmt: skip
    assert seen == stamps


def test_a_live_pair_is_stamped_between_its_two_grabs() -> None:
    """A live pair's stamp is the middle of its left and right grabs (host monotonic times)."""
    now = time.monotonic()
    seen: list[tuple[int, int]] = []

    def on_stamped(left: np.ndarray, res: object, ns: int) -> None:
        seen.append((ns, time.time_ns()))

    rig: Any = _FakeRig([_frame(0, t_left=now - 2.0, t_right=now)])
    run_stream(rig, max_disparity=8, pipelined=False, check=False, on_stamped_result=on_stamped)
    ((stamp, called),) = seen
    ago_s = (called - stamp) / 1e9
    assert 1.0 <= ago_s < 1.5  # the left grab 2 s, the right 0 s before the stamp was taken


def test_the_text_report_names_averaged_frames_only_when_averaging() -> None:
    """A report line says "frames averaged" only when pairs were averaged (more than one)."""
    from stereovision.stream import _format_report

    rep = {"fps": 10.0, "stage_ms": dict.fromkeys(STAGES, 1.0), "latency_ms": 5.0,
           "wait_ms": 0.0, "skew_ms": {"mean": 0.1}, "density": 0.5}  # fmt: skip
    assert "averaged" not in _format_report({**rep, "frames_averaged": 1.0})
    assert _format_report({**rep, "frames_averaged": 2.5}).endswith("| 2.5 frames averaged")


def test_run_stream_refuses_no_disparity_range_and_a_bool_check_every() -> None:
    """max_disparity=0 and check_every=True are usage errors, refused before any grab."""
    for kw, said in (
        ({"max_disparity": 0}, "max_disparity: expected a positive number, got 0"),
        ({"max_disparity": 8, "check_every": True}, "check_every: expected a positive number"),
    ):
        rig = _FakeRig([_frame(0)])
        with pytest.raises(ValueError, match=said):
            run_stream(rig, **kw)  # type: ignore[arg-type]
        assert rig.count == 0


def test_run_stream_refuses_a_disparity_range_that_is_no_number_before_any_grab() -> None:
    """A range that is no positive number is refused before any grab, in depth_map's words:
    "64" raised "'<=' not supported between instances of 'str' and 'int'", and NaN, inf, True
    and a timedelta were refused by depth_map after a pair was taken off the camera; 0 with
    homographies silently searched their range."""
    for md, err, said in (
        ("64", TypeError, "max_disparity: expected a number of pixels, got '64'"),
        (True, TypeError, "max_disparity: expected a number of pixels, got True"),
        (np.timedelta64(16), TypeError, "max_disparity: expected a number of pixels, got"),
        (math.nan, ValueError, "max_disparity: expected a positive number, got nan"),
        (math.inf, ValueError, "max_disparity: expected a positive number, got inf"),
        (10**400, ValueError, "max_disparity: expected a finite number, got an integer of 401"),
    ):
        rig = _FakeRig([_frame(0)])
        with pytest.raises(err, match=re.escape(said)):
            run_stream(rig, max_disparity=md, pipelined=False)  # type: ignore[arg-type]
        assert rig.count == 0, md
    rig = _FakeRig([_frame(0)])
    with pytest.raises(ValueError, match="max_disparity: expected a positive number, got 0"):
        run_stream(rig, max_disparity=0, homographies=_Homographies())  # type: ignore[arg-type]
    assert rig.count == 0


def test_run_stream_refuses_the_wrong_objects_by_name_before_any_grab() -> None:
    """A calib.txt's path failed with "'str' object has no attribute 'rectified'" once a pair
    was taken off the camera, temporal=8 (capture's temporal is a count) with "'int' object has
    no attribute 'frames'", a callback that is none with "'int' object is not callable" after
    the first pair was matched, fill="no" after a grab. Each is a TypeError naming it now,
    before any grab."""
    for kw, said in (
        (
            {"calib": "calib.txt"},
            "calib: got the path 'calib.txt', not a calibration: read it first "
            "(stereovision.Calibration.from_file(path))",
        ),
        (
            {"homographies": Path("h.json")},
            "homographies: got the path 'h.json', not the homographies: read them first "
            "(stereovision.uncalibrated.UncalibratedRectification.load(path))",
        ),
        (
            {"homographies": 3},
            "homographies: expected a stereovision.uncalibrated.UncalibratedRectification, got int",
        ),
        (
            {"temporal": 8},
            "temporal: expected a stereovision.TemporalFilter, got int (a filter averaging up "
            "to 8 frames: TemporalFilter(max_frames=8))",
        ),
        ({"temporal": True}, "temporal: expected a stereovision.TemporalFilter, got bool"),
        ({"fill": "no"}, "fill: expected True, False or None, got 'no'"),
        ({"refine": 1}, "refine: expected True, False or None, got 1"),
        ({"on_result": 5}, "on_result: expected a callable, or None, got 5"),
        ({"on_report": "print"}, "on_report: expected a callable, or None, got 'print'"),
    ):
        for pipelined in (False, True):
            rig = _FakeRig([_frame(0)])
            with pytest.raises(TypeError) as err:
                run_stream(rig, max_disparity=8, pipelined=pipelined, **kw)  # type: ignore[arg-type]
            assert (str(err.value), rig.count) == (said, 0)


def test_run_stream_refuses_a_check_or_pipelined_that_is_no_bool_before_any_grab() -> None:
    """check="no" (a config file's text) was true: the first pair was checked, and with
    check_every every n-th too; pipelined="no" ran pipelined, its summary saying
    "pipelined": "no". Each is a TypeError naming it now, before any grab, as fill's is."""
    for kw, said in (
        ({"check": "no"}, "check: expected True or False, got 'no'"),
        ({"check": "no", "check_every": 2}, "check: expected True or False, got 'no'"),
        ({"check": None}, "check: expected True or False, got None"),
        ({"pipelined": "no"}, "pipelined: expected True or False, got 'no'"),
    ):
        rig = _FakeRig([_frame(0)])
        with pytest.raises(TypeError) as err:
            run_stream(rig, max_disparity=8, **kw)  # type: ignore[arg-type]
        assert (str(err.value), rig.count) == (said, 0)
    rep = run_stream(_FakeRig([_frame(0)]), max_disparity=8, pipelined=np.False_, check=np.True_)
    assert (rep.pipelined, len(rep.checks)) == (False, 1)
    assert json.loads(json.dumps(rep.as_dict()))["pipelined"] is False


def test_the_summary_says_a_fractional_range_as_searched() -> None:
    """run_stream(max_disparity=8.5), a range it accepts, searched 8.5 px and the per-second
    reports said 8.5, but the summary int()'s 8 (0.5: 0, a range it refuses). It says the range
    searched now, an int when whole as before."""
    for md, said in ((8.5, 8.5), (0.5, 0.5), (np.float64(8.0), 8), (np.int64(8), 8)):
        rep = run_stream(_FakeRig([_frame(0)]), max_disparity=md, pipelined=False, check=False)
        assert [r["max_disparity"] for r in rep.reports] == [md]
        assert (rep.max_disparity, type(rep.max_disparity)) == (said, type(said))
        assert json.loads(json.dumps(rep.as_dict()))["max_disparity"] == said


def test_a_window_reports_its_own_pairs_per_second() -> None:
    """A per-second report's fps is its window's pairs over its length, not the run's total."""
    from stereovision.stream import _Done, _window_report

    done = [_Done(dict.fromkeys(STAGES, 0.001), 0.01, 0.0, 0.1, 0.5) for _ in range(2)]
    rep = _window_report(done, 0.5, 10, 5.0, 8, False)
    assert (rep["frames"], rep["total_frames"], rep["fps"]) == (2, 10, 4.0)


def test_a_window_reports_the_mean_of_its_pairs_averaged_frames() -> None:
    """A per-second report's ``frames_averaged`` is the mean over its pairs (1 and 3: 2), not
    the last pair's (a mutation audit's survivor)."""
    from stereovision.stream import _Done, _window_report

    done = [_Done(dict.fromkeys(STAGES, 0.001), 0.01, 0.0, 0.1, 0.5, averaged=a) for a in (1, 3)]
    assert _window_report(done, 0.5, 2, 0.5, 8, False)["frames_averaged"] == 2.0


def test_a_temporal_stream_warns_once_of_frames_resampled_before_it() -> None:
    """With ``temporal``, a source whose frames come resampled (a bag's rectified topics) is
    said once, on the first pair: the filter takes the spread noise for motion."""
    from stereovision.temporal import TemporalFilter

    rig: Any = _FakeRig([_frame(0), _frame(0)])
    rig.rectified_topics, rig.topics = True, {"left": "/l/rect", "right": "/r/rect"}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = run_stream(rig, max_disparity=8, pipelined=False, check=False,
                         temporal=TemporalFilter(max_frames=4))  # fmt: skip
    said = [str(w.message) for w in caught if "temporal averaging" in str(w.message)]
    assert rep.frames == 2
    assert len(said) == 1 and said[0].startswith(
        "temporal averaging: the topics /l/rect and /r/rect are rectified"
    )
    # said on the first pair: a one-pair stream says it too (a mutation audit's survivor)
    rig = _FakeRig([_frame(0), _frame(0)])
    rig.rectified_topics, rig.topics = True, {"left": "/l/rect", "right": "/r/rect"}
    with pytest.warns(UserWarning, match="temporal averaging: the topics"):
        run_stream(rig, max_disparity=8, pipelined=False, check=False, frames=1,
                   temporal=TemporalFilter(max_frames=4))  # fmt: skip


class _Homographies:
    """An UncalibratedRectification stand-in: pairs as they are, a search range of 32 px."""

    max_disparity = 32

    def rectify(self, left: np.ndarray, right: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return left, right


def test_an_explicit_disparity_range_wins_over_the_homographies() -> None:
    """With ``homographies``, their range is the default: a ``max_disparity`` given is kept."""
    for given, used in ((None, 32), (8, 8)):
        rep = run_stream(_FakeRig([_frame(0)]), max_disparity=given,  # type: ignore[arg-type]
                         pipelined=False, check=False, homographies=_Homographies())  # fmt: skip
        assert (rep.frames, rep.max_disparity) == (1, used)


def test_the_homographies_rectify_every_pair() -> None:
    """Each pair is rectified through the homographies before matching: ``on_result`` gets the
    rectified left image (a mutation audit dropped the call and no test failed)."""

    class Flips(_Homographies):
        def rectify(self, left: np.ndarray, right: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return left[::-1].copy(), right[::-1].copy()

    pairs = [_frame(i) for i in range(2)]
    seen: list[np.ndarray] = []
    rep = run_stream(_FakeRig(pairs), pipelined=False, check=False, homographies=Flips(),  # type: ignore[arg-type]
                     on_result=lambda left, res: seen.append(left))  # fmt: skip
    assert rep.frames == 2
    for got, fr in zip(seen, pairs, strict=True):
        assert np.array_equal(got, fr.left[::-1])


def test_check_every_one_checks_every_pair() -> None:
    """``check_every=1`` checks the rows of every pair, not only the first (a mutation audit
    took the 1 for "none after the first" and no test failed)."""
    rep = run_stream(_FakeRig([_frame(i) for i in range(3)]), max_disparity=8,  # type: ignore[arg-type]
                     pipelined=False, check_every=1)  # fmt: skip
    assert [c["pair"] for c in rep.checks] == [0, 1, 2]


def test_a_check_that_cannot_tell_does_not_warn_of_the_same_bump_again() -> None:
    """Rows that stopped agreeing warn once; a check that could not tell in between (ok None:
    too few matches, a dark or bare view) made the next failing one warn again, for the same
    bump. Rows that agree again, then fail, still warn."""
    from types import SimpleNamespace

    from stereovision.stream import _note_check

    def result(ok: bool | None) -> Any:
        return SimpleNamespace(ok=ok, as_dict=lambda: {"ok": ok}, summary=lambda: f"ok {ok}")

    checks: list[dict[str, Any]] = []
    with pytest.warns(UserWarning) as said:
        for pair, ok in enumerate((True, False, None, False, None, True, False)):
            _note_check(pair, result(ok), checks)
    assert [str(w.message) for w in said] == ["pair 1: ok False", "pair 6: ok False"]
    assert [c["pair"] for c in checks] == list(range(7))


@pytest.mark.parametrize("pipelined", [False, True])
@PIPELINED
def test_a_source_failing_on_the_first_pair_is_raised(pipelined: bool) -> None:
    """A source that fails on pair 0 (a frame of another shape) raises its SourceError: no
    pair done, no summary of a "source failed" run of nothing."""
    from stereovision.capture import SourceError

    bad = SourceError("right source: frame 0 is 64x40, not 64x48", end=False)
    with pytest.raises(SourceError, match="frame 0 is 64x40") as err:
        run_stream(_FakeRig([bad]), max_disparity=8, pipelined=pipelined)  # type: ignore[arg-type]
    assert err.value is bad


class _HangsAfter:
    """A capture whose ``grab`` never returns after ``n`` grabs (a hung USB camera), until
    ``unplug`` is set; everything else is the wrapped capture's."""

    def __init__(self, cap: Any, n: int, unplug: threading.Event) -> None:
        self._cap, self._n, self._unplug = cap, n, unplug

    def grab(self) -> bool:
        self._n -= 1
        if self._n < 0:
            self._unplug.wait()
        return bool(self._cap.grab())

    def __getattr__(self, name: str) -> Any:
        return getattr(self._cap, name)


@pytest.mark.parametrize("pipelined", [False, True])
@pytest.mark.parametrize("done", [0, 2])
@PIPELINED
def test_a_camera_whose_read_hangs_is_given_up(
    videos: dict[str, Path], pipelined: bool, done: int
) -> None:
    """A camera whose grab never returns (a hung USB camera): the stream waited forever, its
    summary never said. After ``read_timeout`` s the camera is named as failing: raised on the
    first pair, the stream's end ("source failed") after pairs were done."""
    from stereovision.capture import SourceError

    unplug = threading.Event()
    cam = StereoCamera(str(videos["left"]), str(videos["right"]))
    cam._caps["right"] = _HangsAfter(cam._caps["right"], done, unplug)  # type: ignore[assignment]
    names = f"{str(videos['left'])!r} and {str(videos['right'])!r}"
    says = re.escape(f"{names} delivered no frame in 0.3 s (its read did not return")
    t0 = time.perf_counter()
    try:
        if done == 0:
            with pytest.raises(SourceError, match=says):
                run_stream(cam, max_disparity=16, pipelined=pipelined, read_timeout=0.3)
        else:
            rep = run_stream(cam, max_disparity=16, pipelined=pipelined, read_timeout=0.3)
            assert (rep.frames, rep.ended) == (done, "source failed")
            assert re.match(says, rep.error or "")
    finally:
        unplug.set()
        cam.close()
    # given up after read_timeout, not waited on: the bound leaves room for a loaded machine
    # (6.4 s measured with the suite on both cores and other work beside it)
    assert time.perf_counter() - t0 < 20.0
    with pytest.raises(ValueError, match=r"read_timeout: expected a positive number of seconds"):
        run_stream(_FakeRig([_frame(0)]), max_disparity=8, read_timeout=0)  # type: ignore[arg-type]


@PIPELINED
def test_a_calibrated_streams_first_pair_read_ahead_is_given_up_on_a_hung_camera(
    videos: dict[str, Path],
) -> None:
    """With a calibration the first pair is read ahead (to fit the calibration to the frames
    delivered): that read too gives up after ``read_timeout`` s, not when the camera comes back
    (a mutation audit read it without the timeout and no test failed)."""
    from stereovision.capture import SourceError

    unplug = threading.Event()
    back = threading.Timer(4.0, unplug.set)  # the camera "comes back": the mutant returned then
    back.start()
    cam = StereoCamera(str(videos["left"]), str(videos["right"]))
    cam._caps["right"] = _HangsAfter(cam._caps["right"], 0, unplug)  # type: ignore[assignment]
    t0 = time.perf_counter()
    try:
        with pytest.raises(SourceError, match=r"delivered no frame in 0\.3 s"):
            run_stream(cam, Calibration.from_file(videos["calib"]), max_disparity=16,
                       read_timeout=0.3)  # fmt: skip
        assert time.perf_counter() - t0 < 3.0
    finally:
        unplug.set()
        back.cancel()
        cam.close()


@PIPELINED
def test_a_grab_thread_hung_past_the_join_is_said(
    videos: dict[str, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """With no read limit, a camera that hangs in the read the grab thread took ahead kept that
    thread past the end's join (here an output failing on pair 1 ends the run while pair 2 is
    read): the stream returned as if it had stopped, nothing said a thread was still inside the
    camera's read. A warning now names the camera and the seconds waited;
    the thread, a daemon, is left behind (no wait at exit) and ends once the read returns."""
    import stereovision.stream as streammod

    monkeypatch.setattr(streammod, "GRAB_JOIN_TIMEOUT", 0.2, raising=False)
    unplug = threading.Event()
    cam = StereoCamera(str(videos["left"]), str(videos["right"]))
    # pairs 0 and 1 are read; the thread's read of pair 2 (one ahead) hangs
    cam._caps["right"] = _HangsAfter(cam._caps["right"], 2, unplug)  # type: ignore[assignment]
    names = f"{str(videos['left'])!r} and {str(videos['right'])!r}"

    done: list[int] = []

    def on_result(left: np.ndarray, res: Any) -> None:
        done.append(1)
        if len(done) == 2:
            raise OSError("disk full")

    try:
        t0 = time.perf_counter()
        with pytest.warns(UserWarning) as said:
            rep = run_stream(
                cam, max_disparity=16, check=False, on_result=on_result, read_timeout=None
            )
        waited = time.perf_counter() - t0
        assert (rep.frames, rep.ended) == (1, "output failed")
        left = [t for t in threading.enumerate() if isinstance(t, streammod._Producer)]
        assert len(left) == 1 and left[0].daemon  # left behind: no wait at the interpreter's exit
        assert [str(w.message) for w in said] == [
            f"the grab thread is still inside a read of {names}, 0.2 s after the stream ended "
            "(a hung camera): it is left behind; the pair it reads, if any, is dropped"
        ]
        assert waited < 3.0
    finally:
        unplug.set()
        cam.close()
    left[0].join(5.0)
    assert not left[0].is_alive()


@PIPELINED
def test_a_grab_thread_left_behind_leaves_the_callers_temporal_filter_alone(
    videos: dict[str, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The grab thread left behind (a read hung past the end's join) went on with the pair it
    read once the read returned: averaged into the caller's TemporalFilter, after run_stream
    had returned, so a filter reused for the next stream held a frame of the old one. The
    thread now drops that pair at once: the filter is as run_stream left it."""
    import stereovision.stream as streammod
    from stereovision.temporal import TemporalFilter

    monkeypatch.setattr(streammod, "GRAB_JOIN_TIMEOUT", 0.2, raising=False)
    unplug = threading.Event()
    cam = StereoCamera(str(videos["left"]), str(videos["right"]))
    # pairs 0 and 1 are read; the thread's read of pair 2 (one ahead) hangs until released
    cam._caps["right"] = _HangsAfter(cam._caps["right"], 2, unplug)  # type: ignore[assignment]
    tf = TemporalFilter(max_frames=4)
    done: list[int] = []

    def on_result(left: np.ndarray, res: Any) -> None:
        done.append(1)
        if len(done) == 2:
            raise OSError("disk full")

    try:
        with pytest.warns(UserWarning, match="the grab thread is still inside a read"):
            rep = run_stream(
                cam,
                max_disparity=16,
                check=False,
                on_result=on_result,
                read_timeout=None,
                temporal=tf,
            )
        assert (rep.frames, rep.ended) == (1, "output failed")
        behind = [t for t in threading.enumerate() if isinstance(t, streammod._Producer)]
        assert len(behind) == 1
        before = (tf.frames, tf.restarts, tf.sigma, tf.mean_frames())
        assert before[0] == 2  # pairs 0 and 1
        unplug.set()  # the hung read returns now, after run_stream did
        behind[0].join(5.0)
        assert not behind[0].is_alive()
        assert (tf.frames, tf.restarts, tf.sigma, tf.mean_frames()) == before
    finally:
        unplug.set()
        cam.close()


@PIPELINED
def test_a_second_ctrl_c_while_the_grab_thread_finishes_its_read_keeps_the_summary() -> None:
    """Ctrl-C, then Ctrl-C again while the stream waited for the grab thread's read (a slow
    camera in low light, a hung one: up to GRAB_JOIN_TIMEOUT s): the second interrupt raised
    out of run_stream, the summary of the pairs done lost (the CLI said 'interrupted' alone).
    The wait stops there: the summary of the pair done, ended "interrupted", and a warning that
    the thread is left behind (Python 3.11's is_alive() said False after the cut join)."""
    import signal

    import stereovision.stream as streammod

    release = threading.Event()

    class SlowRig(_FakeRig):
        def read(self) -> Any:
            if self.count == 2:  # the read ahead of pair 2 waits for its frame
                release.wait(10.0)
            return super().read()

    def ctrl_c_during_the_join() -> None:
        grab = next(t for t in threading.enumerate() if isinstance(t, streammod._Producer))
        grab.stop.wait(5.0)  # the stream ended: run_stream now waits for the thread
        time.sleep(0.05)
        signal.pthread_kill(threading.main_thread().ident or 0, signal.SIGINT)

    again = threading.Thread(target=ctrl_c_during_the_join, daemon=True)
    done: list[int] = []

    def on_result(left: np.ndarray, res: Any) -> None:
        done.append(1)
        if len(done) == 2:
            again.start()
            raise KeyboardInterrupt  # the first Ctrl-C

    try:
        t0 = time.perf_counter()
        with pytest.warns(UserWarning) as said:
            try:
                rep = run_stream(SlowRig([_frame(i) for i in range(4)]), max_disparity=16,
                                 check=False, on_result=on_result, read_timeout=None)  # fmt: skip
            except KeyboardInterrupt:  # (not to stop the test session)
                pytest.fail("the second Ctrl-C raised out of run_stream: the summary lost")
        assert time.perf_counter() - t0 < 3.0
        assert (rep.frames, rep.ended, rep.error) == (1, "interrupted", None)
        assert [str(w.message) for w in said] == [
            "the grab thread is still inside a read of SlowRig, interrupted while waiting for "
            "it: it is left behind; the pair it reads, if any, is dropped"
        ]
    finally:
        release.set()
        again.join(5.0)


def test_a_bag_without_a_calibration_is_refused(
    videos: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--bag`` records depth, which needs ``--calib``: refused in one line, no bag made."""
    bag = tmp_path / "b"
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--no-display", "--no-check", "--frames", "1", "--max-disparity", "16"]
    assert main([*argv, "--bag", str(bag)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["stereovision: error: --bag: a bag holds depth; give --calib"]
    assert not bag.exists()


def test_ground_every_without_a_calibration_is_said_in_the_cli_words(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """``--ground-every`` without ``--calib`` was refused as "ground_every: ... give a
    calibration", run_stream's keyword: said with the option and the option to give."""
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--no-display", "--no-check", "--frames", "1", "--max-disparity", "16"]
    assert main([*argv, "--ground-every", "2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "stereovision: error: --ground-every: the floor is found in metres; give --calib"
    ]


def test_a_bag_folder_in_the_way_is_said_of_the_option(
    videos: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--bag DIR`` where DIR exists said "bag folder already exists: DIR" without the option
    (BagWriter's own words), unlike the other refusals of --bag; the user's folder is kept."""
    bag = tmp_path / "b"
    bag.mkdir()
    (bag / "mine.txt").write_text("mine")
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--no-display", "--no-check", "--frames", "1"]
    assert main([*argv, "--max-disparity", "16", "--bag", str(bag)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"stereovision: error: --bag: bag folder already exists: {bag} (choose a new one)"
    ]
    assert (bag / "mine.txt").read_text() == "mine"
    assert [p.name for p in bag.iterdir()] == ["mine.txt"]


def test_the_prepare_stage_counts_depth_maps_input_conversion(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``prepare`` is depth_map's ``rectify`` (input conversion of a rectified pair) and its
    ``prepare``: the time spent before matching, not half of it."""
    import stereovision.depth as depth

    real = depth.depth_map

    def timed(*args: Any, **kw: Any) -> Any:
        res = real(*args, **kw)
        res.timings.update(rectify=0.25, prepare=0.125)
        return res

    monkeypatch.setattr(depth, "depth_map", timed)
    rep = run_stream(_FakeRig([_frame(0)]), max_disparity=8, pipelined=False, check=False)  # type: ignore[arg-type]
    assert rep.stage_ms["prepare"] == 375.0
    assert rep.reports[-1]["stage_ms"]["prepare"] == 375.0


def test_a_one_pair_source_ends_its_stream() -> None:
    """A source read to its end after a single pair ends the stream (its summary), as after
    more pairs; only a source without a first pair is an error."""
    from stereovision.capture import SourceError

    rep = run_stream(_FakeRig([_frame(0)]), max_disparity=8, pipelined=False, check=False)  # type: ignore[arg-type]
    assert (rep.frames, rep.ended, rep.error) == (1, "end of stream", None)
    with pytest.raises(SourceError, match="ended"):
        run_stream(_FakeRig([]), max_disparity=8, pipelined=False, check=False)  # type: ignore[arg-type]


def test_the_mode_note_says_a_resize_to_the_size_asked() -> None:
    """A camera delivering another size than the mode it reports is said; the frames then
    resized to another size (``--size``) are said too, and only then."""
    from types import SimpleNamespace

    from stereovision.stream import _mode_note

    cam: Any = SimpleNamespace(reported=(640, 480), delivered_size={"left": (320, 240)})
    said = "the left camera reports 640x480 but delivers 320x240{}: the calibration is fitted"
    assert _mode_note(cam, (320, 240)) == said.format("") + " to the frames delivered"
    assert _mode_note(cam, (480, 360)) == said.format(", resized to 480x360") + (
        " to the frames delivered"
    )
    cam.delivered_size = {"left": (640, 480)}
    assert _mode_note(cam, (480, 360)) is None


class _SkippingRig(_FakeRig):
    """A ``--realtime`` recording stand-in that skipped 3 pairs a slow matcher missed."""

    skipped = 3

    def close(self) -> None:
        pass


def test_the_temporal_line_says_one_restart_in_the_singular(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The summary's temporal line said "1 restarts" (pairs and frames are said in the
    singular since fd8a1f4): a still view, then another one, restarts once."""
    import stereovision.stream as stream

    rig = _SkippingRig([_frame(0), _frame(0), _frame(1)])
    rig.skipped = 0
    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: rig)
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--no-check"]
    assert main([*argv, "--no-pipeline", "--max-disparity", "8", "--temporal", "4"]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    assert line.startswith("temporal: 1.3 frames averaged per pixel on average, 1 restart (the")


@PIPELINED
def test_the_pairs_a_realtime_stream_skipped_are_said(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The recorded pairs a slower matcher skipped are said (stderr) and in the summary."""
    import stereovision.stream as stream

    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: _SkippingRig([_frame(0)]))
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--no-check"]
    assert main([*argv, "--max-disparity", "8", "--json"]) == 0
    cap = capsys.readouterr()
    summary = _json_lines(cap.out)[-1]
    assert (summary["frames"], summary["skipped"]) == (1, 3)
    assert cap.err.strip().splitlines()[-1] == (
        "3 recorded pairs skipped: the matcher was slower than the recording (--realtime)"
    )


@PIPELINED
def test_the_live_view_is_given_every_pair(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without ``--no-display`` every pair's left image and disparity reach the served view."""
    import stereovision.stream as stream

    got: list[tuple[tuple[int, ...], tuple[int, ...], float]] = []
    made: list[FrameServer] = []

    class _Watched(FrameServer):
        def __init__(self, host: str, port: int) -> None:
            super().__init__(host, port)
            made.append(self)

        def update(self, left: np.ndarray, disparity: np.ndarray, max_disparity: float) -> None:
            got.append((left.shape, disparity.shape, max_disparity))
            super().update(left, disparity, max_disparity)

    rig = _SkippingRig([_frame(0), _frame(1)])
    rig.skipped = 0
    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: rig)
    monkeypatch.setattr(stream, "FrameServer", _Watched)
    argv = ["stream", "--left", "0", "--right", "1", "--serve", "0", "--no-check"]
    assert main([*argv, "--max-disparity", "8"]) == 0
    assert got == [((48, 64, 3), (48, 64), 8.0)] * 2
    assert len(made) == 1 and made[0].closed  # its port let go of
    assert "serving the live view on http://127.0.0.1:" in capsys.readouterr().err


def test_the_view_shows_a_left_image_with_alpha_or_of_16_bits() -> None:
    """An image sequence of PNGs with alpha (a renderer's) or of 16 bits, or a mono16 bag,
    hands the stream such left images: the view's hstack with the 3-channel colour map raised
    in the server's thread (the client's connection closed without a response, a traceback on
    stderr, for every frame), and a 16-bit image was clipped to white in the JPEG. Each is
    shown as the 8-bit BGR image it stands for now (16 bits divided by 257)."""
    from stereovision.stream import _compose

    disp = np.full((4, 4), 8.0, np.float32)
    colour = _compose(np.zeros((4, 4, 3), np.uint8), disp, 16.0)[:, 4:]
    for left, shown in (
        (np.full((4, 4, 4), (30, 120, 200, 0), np.uint8), (30, 120, 200)),
        (np.full((4, 4, 3), (30 * 257, 120 * 257, 200 * 257), np.uint16), (30, 120, 200)),
        (np.full((4, 4), 120 * 257, np.uint16), (120, 120, 120)),
        (np.full((4, 4, 1), 120, np.uint8), (120, 120, 120)),
        (np.full((4, 4, 3), (0.5, 0.0, 1.0), np.float32), (128, 0, 255)),  # floats in [0, 1]
    ):
        img = _compose(left, disp, 16.0)
        assert img.dtype == np.uint8 and img.shape == (4, 8, 3)
        assert (img[:, :4] == shown).all() and (img[:, 4:] == colour).all()
    srv = FrameServer("127.0.0.1", 0)
    try:
        left = np.full((48, 64, 4), (30, 120, 200, 0), np.uint8)
        srv.update(left, np.full((48, 64), 8.0, np.float32), 16.0)
        status, ctype, body = _get(srv.url + "frame.jpg")
        assert status == 200 and ctype == "image/jpeg"
        img = cv2.imdecode(np.frombuffer(body, np.uint8), cv2.IMREAD_COLOR)
        assert np.abs(img[8:40, 8:56].astype(int) - (30, 120, 200)).max() < 12
    finally:
        srv.close()


def test_the_view_colours_the_whole_range_and_waits_for_a_new_frame() -> None:
    """A disparity at or above the top of the range is the colour map's end, not black; a
    client that has the latest frame waits for the next one (None and its own number after
    the timeout) instead of spinning."""
    from stereovision.stream import _compose

    left = np.zeros((4, 4, 3), np.uint8)
    disp = np.full((4, 4), 64.0, np.float32)
    disp[:, 2:] = 80.0  # beyond the range (a sub-pixel refinement's): clipped to its top
    img = _compose(left, disp, 64.0)
    top = cv2.applyColorMap(np.array([[255]], np.uint8), cv2.COLORMAP_TURBO)[0, 0]
    assert img.shape == (4, 8, 3) and (img[:, 4:] == top).all() and top.any()
    # the middle of a range of 16 is the colour map's middle (8 * 255 / 16 = 127.5: 127)
    mid = cv2.applyColorMap(np.array([[127]], np.uint8), cv2.COLORMAP_TURBO)[0, 0]
    assert (_compose(left, np.full((4, 4), 8.0, np.float32), 16.0)[:, 4:] == mid).all()
    srv = FrameServer("127.0.0.1", 0)
    try:
        srv.update(left, np.zeros((4, 4), np.float32), 8.0)
        jpg, seen = srv.wait_jpeg(0, timeout=1.0)
        assert jpg is not None and seen == 1
        t0 = time.monotonic()
        assert srv.wait_jpeg(seen, timeout=0.3) == (None, 1)
        assert time.monotonic() - t0 >= 0.25
    finally:
        srv.close()


def test_the_view_closes_at_once() -> None:
    """close() waited for socketserver's 0.5 s poll to see the stop: every stream with a view
    ended 0.45-0.5 s late (after Ctrl-C too); it waits one SERVE_POLL_S now."""
    srv = FrameServer("127.0.0.1", 0)
    t0 = time.perf_counter()
    srv.close()
    assert time.perf_counter() - t0 < 0.25 and srv.closed


def test_the_view_answers_a_head_request() -> None:
    """A health check's HEAD (``curl -I``, a monitor's probe) got 501 "Unsupported method", as
    if the view were down: it gets the GET's status and headers, without the body."""
    srv = FrameServer("127.0.0.1", 0)
    try:

        def head(path: str) -> tuple[int, str, bytes]:
            req = urllib.request.Request(srv.url + path, method="HEAD")
            try:
                with urllib.request.urlopen(req, timeout=60) as r:
                    return r.status, r.headers["Content-Type"], r.read()
            except urllib.error.HTTPError as e:
                return e.code, e.headers["Content-Type"], e.read()

        assert head("frame.jpg") == (503, "text/plain", b"")
        srv.update(np.zeros((8, 8, 3), np.uint8), np.zeros((8, 8), np.float32), 8.0)
        assert head("frame.jpg") == (200, "image/jpeg", b"")
        assert head("")[:2] == (200, "text/html; charset=utf-8")
        assert head("stream.mjpg")[:2] == (200, "multipart/x-mixed-replace; boundary=frame")
    finally:
        srv.close()


def test_the_view_encodes_each_frame_once_for_every_viewer(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Each viewer (a browser's MJPEG stream, a dashboard polling /frame.jpg) composed and
    encoded every frame again, 8.5 ms a 640x480 pair on the cores the matcher runs on: a frame
    is encoded once, and the next frame again once."""
    import stereovision.stream as stream

    composed: list[float] = []
    compose = stream._compose

    def counted(left: np.ndarray, disparity: np.ndarray, top: float) -> np.ndarray:
        composed.append(top)
        return compose(left, disparity, top)

    monkeypatch.setattr(stream, "_compose", counted)
    srv = FrameServer("127.0.0.1", 0)
    try:
        left, disp = np.zeros((8, 8, 3), np.uint8), np.full((8, 8), 4.0, np.float32)
        srv.update(left, disp, 8.0)
        first = srv.latest_jpeg()
        assert srv.latest_jpeg() == first and srv.wait_jpeg(0, timeout=0.0) == (first, 1)
        assert composed == [8.0]
        srv.update(left, disp, 16.0)
        jpg, seen = srv.wait_jpeg(1, timeout=0.0)
        assert seen == 2 and jpg == srv.latest_jpeg() and jpg is not None and jpg != first
        assert composed == [8.0, 16.0]
    finally:
        srv.close()


def test_a_window_reports_its_largest_skew_and_the_bag_line_its_frames() -> None:
    """A report's skew ``max`` is its pairs' largest; the bag line says the frames it holds,
    with the frames lost only when it holds fewer than the pairs processed."""
    from types import SimpleNamespace

    from stereovision.stream import _bag_line, _Done, _window_report

    done = [_Done(dict.fromkeys(STAGES, 0.001), 0.01, 0.0, s, 0.5) for s in (0.5, 2.0)]
    assert _window_report(done, 1.0, 2, 1.0, 8, False)["skew_ms"] == {"mean": 1.25, "max": 2.0}
    bag: Any = SimpleNamespace(frames=3, messages=12, path="b")
    assert _bag_line(bag, 3) == "ROS 2 bag written to b (3 of the 3 pairs processed, 12 messages)"
    assert _bag_line(bag, 2) == "ROS 2 bag written to b (3 frames, 12 messages)"


def test_a_calibration_is_sized_by_the_size_asked_before_the_size_delivered() -> None:
    """The frames' size is the size asked (``--size``: the frames are resized to it), not the
    size the source delivers before that resize."""
    from types import SimpleNamespace

    from stereovision.stream import _frame_size

    cam = SimpleNamespace(size=(480, 360), delivered_size={"left": (320, 240)})
    assert _frame_size(cam) == (480, 360)
    cam.size = None
    assert _frame_size(cam) == (320, 240)


@PIPELINED
def test_a_temporal_stream_averages_up_to_255_pairs(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--temporal 255``, the largest count the filter takes, is accepted; 1 (a mean of one
    pair: nothing averaged) and 256 are refused in one line."""
    import stereovision.stream as stream

    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: _SkippingRig([_frame(0)]))
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--no-check"]
    assert main([*argv, "--max-disparity", "8", "--temporal", "255", "--json"]) == 0
    summary = _json_lines(capsys.readouterr().out)[-1]
    assert summary["frames"] == 1 and summary["temporal"]["frames_averaged"] == 1.0
    for n in (1, 256):  # refused by argparse (test_temporal_is_refused_at_parse_time)
        with pytest.raises(SystemExit) as info:
            main([*argv, "--max-disparity", "8", "--temporal", str(n)])
        assert info.value.code == 2
        assert capsys.readouterr().err.strip().splitlines() == [
            "stereovision stream: error: argument --temporal: expected 2-255 pairs to average, "
            f"got '{n}' (see stereovision stream --help)"
        ]


@PIPELINED
def test_a_temporal_stream_of_black_frames_measured_no_noise(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """--temporal on frames all black (a capped lens, a dark room): the filter has no noise
    estimate (no pixel neither black nor white), and the summary said "noise 0.0 grey levels"
    (JSON 0.0), a noise it never measured. It says none was measured now (JSON null)."""
    import stereovision.stream as stream
    from stereovision.capture import StereoFrame

    class _Rig(_FakeRig):
        def close(self) -> None:
            pass

    black = np.zeros((48, 64, 3), np.uint8)
    pairs = [StereoFrame(black, black.copy(), 0.0, 0.0, i) for i in range(2)]
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--no-check"]
    argv += ["--max-disparity", "8", "--temporal", "3"]
    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: _Rig(list(pairs)))
    assert main(argv) == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        "temporal: 1.5 frames averaged per pixel on average, 0 restarts (the rig or the view "
        "moved), no noise measured (frames all black or white)"
    )
    assert main([*argv, "--json"]) == 0
    temporal = _json_lines(capsys.readouterr().out)[-1]["temporal"]
    assert temporal == {"frames_averaged": 1.5, "restarts": 0, "noise_sigma": None}


def test_the_noise_of_a_black_first_frame_is_not_measured() -> None:
    """A first frame all black (a capped lens, a dark room) has no pixel to measure the noise
    on: the summary's noise_sigma said 0.0 (noise_sigma's 0 for such an image), a noise never
    measured; it is NaN (JSON null) now, as with no pair. noise_sigma itself still says 0."""
    from stereovision._jsonout import json_line
    from stereovision.capture import StereoFrame
    from stereovision.temporal import noise_sigma

    black = np.zeros((48, 64, 3), np.uint8)
    rig = _FakeRig([StereoFrame(black, black.copy(), 0.0, 0.0, 0)])
    rep = run_stream(rig, max_disparity=8, pipelined=False, check=False)
    assert rep.frames == 1 and math.isnan(rep.noise_sigma)
    assert json.loads(json_line(rep.as_dict()))["noise_sigma"] is None
    assert noise_sigma(black) == 0.0
    rep = run_stream(_FakeRig([_frame(0)]), max_disparity=8, pipelined=False, check=False)
    assert rep.noise_sigma == noise_sigma(_frame(0).left)


def test_run_stream_refuses_a_bool_ground_every_and_two_ways_to_rectify() -> None:
    """``ground_every=True`` or 0, ``ground_every`` without a calibration (a floor in metres)
    and homographies with a calibration are usage errors, said as such before any grab."""
    rig = _FakeRig([_frame(0)])
    for every in (True, 0):
        with pytest.raises(ValueError, match="ground_every: expected a positive number of pairs"):
            run_stream(rig, object(), max_disparity=8, ground_every=every)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="ground_every: the floor is found in metres; give a"):
        run_stream(rig, max_disparity=8, ground_every=2)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="homographies and calib: give one way"):
        run_stream(rig, object(), max_disparity=8, homographies=_Homographies())  # type: ignore[arg-type]
    assert rig.count == 0


def test_each_floor_fit_reaches_on_ground(data_dir: Path) -> None:
    """With ``ground_every``, every fit (None: no floor found) is handed to ``on_ground``."""
    calib = Calibration.from_file(data_dir / SCENE / "calib.txt").scaled_to((64, 48))
    seen: list[Any] = []
    rig: Any = _FakeRig([_frame(i) for i in range(3)])
    rep = run_stream(rig, calib, max_disparity=8, pipelined=False, check=False,
                     ground_every=2, on_ground=seen.append)  # fmt: skip
    assert rep.frames == 3 and [g["pair"] for g in rep.grounds] == [0, 2]
    assert [p is not None for p in seen] == [g["found"] for g in rep.grounds]


def _blank_frame(index: int) -> Any:
    """A textureless pair 64x48: no pixel has a disparity, so no floor is found in it."""
    from stereovision.capture import StereoFrame

    img = np.full((48, 64, 3), 128, np.uint8)
    now = time.monotonic()
    return StereoFrame(img, img.copy(), now, now, index)


def test_a_range_estimated_from_a_flat_first_pair_is_said() -> None:
    """A first pair of one flat level (a capped lens, a webcam's first black frames) gave the
    estimate's fallback, searched for the whole run without a word; it is said. A textured
    first pair, or a range given, says nothing."""
    from stereovision.capture import StereoFrame

    black = StereoFrame(np.zeros((48, 64, 3), np.uint8), np.zeros((48, 64, 3), np.uint8),
                        0.0, 0.0, 0)  # fmt: skip
    rig: Any = _FakeRig([black, _frame(1)])
    with pytest.warns(UserWarning) as said:
        rep = run_stream(rig, pipelined=False, check=False)
    assert rep.max_disparity == 16 and [str(w.message) for w in said] == [
        "the first pair, which the disparity range is estimated from, is one flat level (a "
        "capped lens, a dark room, a camera still starting): the stream searches 16 px, a "
        "guess, throughout; give the range (--max-disparity N)"
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run_stream(_FakeRig([_frame(0)]), pipelined=False, check=False)  # type: ignore[arg-type]
        run_stream(_FakeRig([black]), max_disparity=8, pipelined=False, check=False)  # type: ignore[arg-type]


def test_a_stream_without_a_floor_says_why(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--ground-every`` on pairs without a floor ended on "floor: 0 of 2 fits", not saying
    why; the line now gives the last fit's reason (fit_ground_plane's). The no-floor records
    keep their documented keys ({"pair": n, "found": False}); the report holds the reason."""
    import stereovision.stream as stream

    calib = Calibration.from_file(data_dir / SCENE / "calib.txt").scaled_to((64, 48))
    why = "ground plane: none found (0 pixels have a disparity; a fit needs 500)"
    calib.save(tmp_path / "rig.yaml")
    monkeypatch.setattr(
        stream,
        "open_source",
        lambda args, fps=None: _SkippingRig([_blank_frame(i) for i in range(3)]),
    )
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--no-check"]
    argv += ["--calib", str(tmp_path / "rig.yaml"), "--max-disparity", "8"]
    assert main([*argv, "--ground-every", "2"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == f"floor: 0 of 2 fits; last (pair 2): {why}"
    rig: Any = _FakeRig([_blank_frame(i) for i in range(3)])
    rep = run_stream(rig, calib, max_disparity=8, pipelined=False, check=False, ground_every=2)
    assert rep.grounds == [{"pair": 0, "found": False}, {"pair": 2, "found": False}]
    assert rep.ground_reason == why and "ground_reason" not in rep.as_dict()


@PIPELINED
def test_the_stream_command_passes_its_options_on(
    videos: dict[str, Path], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--refine`` and ``--ground-every`` reach run_stream; ``--rectification`` with
    ``--calib`` is refused in one line."""
    import stereovision.stream as stream

    calls: list[dict[str, Any]] = []
    real = stream.run_stream

    def recorded(*args: Any, **kw: Any) -> StreamReport:
        calls.append(kw)
        return real(*args, **kw)

    monkeypatch.setattr(stream, "run_stream", recorded)
    argv = ["stream", "--left", str(videos["left"]), "--right", str(videos["right"])]
    argv += ["--calib", str(videos["calib"]), "--no-display", "--no-check", "--frames", "1"]
    assert main([*argv, "--max-disparity", "16", "--refine", "--ground-every", "1"]) == 0
    assert (calls[0]["refine"], calls[0]["ground_every"]) == (True, 1)
    assert capsys.readouterr().out.splitlines()[-1].startswith("floor: ")
    assert main([*argv, "--rectification", "h.json"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "stereovision: error: --rectification and --calib: give one way to rectify the pairs"
    ]


def test_a_raw_rigs_pairs_are_rectified_once() -> None:
    """A raw rig's pairs, rectified in the grab stage, are matched as they are: the depth of
    the frames rectified once, not warped again by the raw calibration."""
    k = np.array([[32.0, 0, 32], [0, 32.0, 24], [0, 0, 1]])
    rig = Calibration(K1=k, D1=np.zeros(5), K2=k, D2=np.zeros(5),
                      R=cv2.Rodrigues(np.array([0.0, 0.05, 0.0]))[0], T=np.array([-0.25, 0.0, 0.0]),
                      image_size=(64, 48), unit="m")  # fmt: skip
    fr = _frame(0)
    got: list[np.ndarray] = []
    run_stream(_FakeRig([fr]), rig, max_disparity=8, pipelined=False, check=False,  # type: ignore[arg-type]
               on_result=lambda left, res: got.append(res.disparity))  # fmt: skip
    ref = depth_map(fr.left, fr.right, rig, method="gabor", max_disparity=8, refine=False)
    np.testing.assert_array_equal(got[0], ref.disparity)


def test_the_wait_is_for_the_pair_not_its_matching(monkeypatch: pytest.MonkeyPatch) -> None:
    """``wait_ms`` is the time the matcher waited for its pair, not that and the matching."""
    import stereovision.depth as depth

    real = depth.depth_map

    def slow(*args: Any, **kw: Any) -> Any:
        time.sleep(0.2)
        return real(*args, **kw)

    monkeypatch.setattr(depth, "depth_map", slow)
    rep = run_stream(_FakeRig([_frame(0)]), max_disparity=8, pipelined=False, check=False)  # type: ignore[arg-type]
    assert rep.latency_ms >= 200 and rep.wait_ms < 100


def _fake_clock(monkeypatch: pytest.MonkeyPatch, match_s: float) -> list[float]:
    """The stream's ``perf_counter`` made a clock that moves only when told (returned: its
    time, a one-item list); each depth_map advances it by ``match_s``."""
    from types import SimpleNamespace

    import stereovision.depth as depth
    import stereovision.stream as stream

    now = [0.0]
    monkeypatch.setattr(stream, "time", SimpleNamespace(
        perf_counter=lambda: now[0], monotonic=time.monotonic, time_ns=time.time_ns))  # fmt: skip
    real = depth.depth_map

    def timed(*args: Any, **kw: Any) -> Any:
        now[0] += match_s
        return real(*args, **kw)

    monkeypatch.setattr(depth, "depth_map", timed)
    return now


def test_each_report_covers_its_own_window(monkeypatch: pytest.MonkeyPatch) -> None:
    """A per-second report counts the pairs done since the previous one, over the time since
    it: pairs of 0.25 s reported every 0.5 s are 2 pairs at 4 fps each time."""
    _fake_clock(monkeypatch, 0.25)
    rep = run_stream(_FakeRig([_frame(i) for i in range(6)]), max_disparity=8,  # type: ignore[arg-type]
                     pipelined=False, check=False, report_period=0.5)  # fmt: skip
    assert [(r["t"], r["frames"], r["total_frames"], r["fps"]) for r in rep.reports] == [
        (0.5, 2, 2, 4.0), (1.0, 2, 4, 4.0), (1.5, 2, 6, 4.0)]  # fmt: skip
    assert (rep.frames, rep.seconds, rep.fps) == (6, 1.5, 4.0)


class _SlowRig(_FakeRig):
    """A rig whose every grab takes ``grab_s`` on the clock ``now`` (:func:`_fake_clock`)."""

    def __init__(self, pairs: list[Any], now: list[float], grab_s: float) -> None:
        super().__init__(pairs)
        self._now, self._grab_s = now, grab_s

    def read(self) -> Any:
        self._now[0] += self._grab_s
        return super().read()


def test_each_pairs_latency_runs_from_its_own_grab(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A pair's latency is its own grab (0.1 s) and matching (0.25 s): not counted from the
    matching alone, nor, for pair 1 of a calibrated stream (whose pair 0 was read ahead to
    fit the calibration), from the grab of pair 0."""
    calib = Calibration.from_file(data_dir / SCENE / "calib.txt").scaled_to((64, 48))
    now = _fake_clock(monkeypatch, 0.25)
    rig = _SlowRig([_frame(i) for i in range(3)], now, 0.1)
    rep = run_stream(rig, calib, max_disparity=8, pipelined=False, check=False,  # type: ignore[arg-type]
                     report_period=0.0)  # fmt: skip
    assert [r["latency_ms"] for r in rep.reports] == pytest.approx([350.0] * 3)
    assert [r["stage_ms"]["grab"] for r in rep.reports] == pytest.approx([100.0] * 3)
    # pair 0 was grabbed before the loop waited; the others while it waited
    assert [r["wait_ms"] for r in rep.reports] == pytest.approx([0.0, 100.0, 100.0])
    assert rep.latency_ms == pytest.approx(350.0) and rep.seconds == pytest.approx(1.05)


@pytest.mark.parametrize("stop", [OSError("disk full"), KeyboardInterrupt()])
@PIPELINED
def test_the_grab_thread_runs_one_pair_ahead_and_is_joined_at_the_end(
    stop: BaseException,
) -> None:
    """Pipelined, the grab thread takes one pair ahead of the one being matched, not more (a
    live camera's pairs would age in a queue); a run that ends early (an output failing,
    Ctrl-C) stops and joins it, leaving no thread reading the camera it closes next."""
    import threading

    rig = _FakeRig([_frame(i) for i in range(8)])
    read: list[int] = []

    def on_result(left: np.ndarray, res: Any) -> None:
        time.sleep(0.3)  # a slow output: room for the grab thread to run ahead if it could
        read.append(rig.count)
        if len(read) == 3:
            raise stop

    t0 = time.monotonic()
    rep = run_stream(rig, max_disparity=8, check=False, on_result=on_result)  # type: ignore[arg-type]
    assert read == [2, 3, 4]
    assert (rep.frames, rep.ended) == (
        2,
        "output failed" if isinstance(stop, OSError) else "interrupted",
    )
    assert not [t for t in threading.enumerate() if t.name == "stereovision-grab"]
    assert time.monotonic() - t0 < 3.0  # stopped, not waited for until the join's timeout


class _WarningRig(_FakeRig):
    """A rig whose every read warns (a source's own warning, held by the grab thread when
    pipelined), the read that finds its end too."""

    def read(self) -> Any:
        from stereovision._validate import source_warning

        source_warning(f"read {self.count}")
        return super().read()


@PIPELINED
def test_a_sources_own_warnings_take_no_slot_and_the_last_one_is_given() -> None:
    """A source's warnings ride with its pairs without taking a grab slot: a mutation audit
    giving a slot back for each (the grab thread ran two pairs ahead, aging a live camera's
    frames) and one handing over the held warnings only after the end was met (the last
    read's warning lost) both survived the stream tests."""
    rig = _WarningRig([_frame(i) for i in range(4)])
    read: list[int] = []

    def on_result(left: np.ndarray, res: Any) -> None:
        time.sleep(0.3)  # a slow output: room for the grab thread to run ahead if it could
        read.append(rig.count)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = run_stream(rig, max_disparity=8, check=False, on_result=on_result)  # type: ignore[arg-type]
    assert (rep.frames, rep.ended) == (4, "end of stream")
    assert read == [2, 3, 4, 4]  # one pair ahead of the one matched, not more
    said = [(str(w.message), w.filename) for w in caught]
    assert said == [(f"read {i}", __file__) for i in range(5)], said


@pytest.mark.parametrize("pipelined", [False, True])
@PIPELINED
def test_a_sources_own_warning_keeps_its_category(pipelined: bool) -> None:
    """A source's warning of another category than UserWarning (a RuntimeWarning) is given as
    that category from the grab thread too (a mutation audit gave every held warning as a
    UserWarning and no test failed)."""
    from stereovision._validate import source_warning

    class Rig(_FakeRig):
        def read(self) -> Any:
            source_warning(f"read {self.count}", RuntimeWarning)
            return super().read()

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run_stream(Rig([_frame(0)]), max_disparity=8, check=False, pipelined=pipelined)  # type: ignore[arg-type]
    assert [(str(w.message), w.category) for w in caught] == [
        ("read 0", RuntimeWarning),
        ("read 1", RuntimeWarning),
    ]


@PIPELINED
def test_the_warning_of_a_read_that_fails_is_given() -> None:
    """A source's warning held by the grab thread on the read that then fails reaches the
    caller before the failure ends the stream, as unpipelined: a mutation audit dropping the
    hand-over on the grab thread's error path survived."""
    from stereovision.capture import SourceError

    for pipelined in (False, True):
        rig = _WarningRig([_frame(0), _frame(1), SourceError("broken frame", end=False)])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            rep = run_stream(rig, max_disparity=8, check=False, pipelined=pipelined)  # type: ignore[arg-type]
        assert (rep.frames, rep.ended, rep.error) == (2, "source failed", "broken frame")
        said = [(str(w.message), w.filename) for w in caught]
        assert said == [(f"read {i}", __file__) for i in range(3)], (pipelined, said)


def test_a_calibration_that_cannot_be_sized_closes_the_cameras(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A calibration sized by the frames (stereo_calib output) that fails to load after the
    cameras opened (no unit given) is said in one line, and the cameras are let go of."""
    from test_calibration import _opencv_stereo_calib

    import stereovision.stream as stream

    _opencv_stereo_calib(tmp_path)
    closed: list[bool] = []
    rig = _SkippingRig([_frame(0)])
    rig.close = lambda: closed.append(True)  # type: ignore[method-assign]
    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: rig)
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--calib", str(tmp_path)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("stereovision: error: ")
    assert closed == [True]


@PIPELINED
def test_a_sizeless_source_interrupted_before_its_first_pair_is_not_asked_for_a_size(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Cameras that state no size, stopped (Ctrl-C) while their first pair was read to size a
    calibration that holds none: the summary of no pair (exit 130), not the error asking for
    ``--size`` that sizing the calibration without that pair would give."""
    from test_calibration import _opencv_stereo_calib

    import stereovision.stream as stream

    class _Sizeless(_ModeCap):
        def get(self, prop: int) -> float:
            return 0.0

        def grab(self) -> bool:
            raise KeyboardInterrupt

    _opencv_stereo_calib(tmp_path)
    monkeypatch.setattr(
        stream, "open_source", lambda args, fps=None: StereoCamera(_Sizeless([]), _Sizeless([]))
    )
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--max-disparity", "16"]
    assert main([*argv, "--calib", str(tmp_path), "--calib-unit", "mm", "--json"]) == 130
    cap = capsys.readouterr()
    summary = json.loads(cap.out)
    assert (summary["frames"], summary["ended"], cap.err) == (0, "interrupted", "")


def test_the_view_listens_on_the_loopback_by_default() -> None:
    """A FrameServer made without a host serves on 127.0.0.1 only (a robot is often on a
    shared network): not on every interface."""
    srv = FrameServer(port=0)
    try:
        assert srv.url == f"http://127.0.0.1:{srv.port}/"
        assert srv._httpd.server_address[0] == "127.0.0.1"
    finally:
        srv.close()
    # an empty host (a bind's "every interface") is refused, not served on 0.0.0.0; a host
    # with a newline (read from a file) reached the bind, its error cut at the newline; so
    # did a bracket around no IPv6 address ("Name or service not known")
    for host in ("", " ", "127.0.0.1\n", "local host", "[::1", "[]", "[127.0.0.1]"):
        with pytest.raises(
            ValueError, match=rf"^host: expected an address .*got {re.escape(repr(host))}$"
        ):
            FrameServer(host, 0)


def test_a_view_on_every_interface_says_where_to_open_it(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--host 0.0.0.0`` (to watch from a laptop) said "serving the live view on
    http://0.0.0.0:PORT/", an address browsers refuse: the line says where to open it."""
    import stereovision.stream as stream

    rig = _SkippingRig([_frame(0)])
    rig.skipped = 0
    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: rig)
    argv = ["stream", "--left", "0", "--right", "1", "--serve", "0", "--no-check", "--no-pipeline"]
    assert main([*argv, "--host", "0.0.0.0", "--max-disparity", "8"]) == 0
    line = capsys.readouterr().err.splitlines()[0]
    port = re.fullmatch(r"serving the live view on http://0\.0\.0\.0:(\d+)/ .*", line)
    assert port is not None and line.endswith(
        f"/ (every interface: http://127.0.0.1:{port[1]}/ on this machine, its network address "
        "from others)"
    )


def _ipv6_loopback() -> bool:
    import socket

    try:
        with socket.socket(socket.AF_INET6) as s:
            s.bind(("::1", 0))
    except OSError:
        return False
    return True


@pytest.mark.skipif(not _ipv6_loopback(), reason="no IPv6 loopback here")
def test_the_view_serves_on_an_ipv6_address() -> None:
    """``--host ::1`` (or ``::``, every interface) was refused: the server was IPv4 only,
    'cannot serve the view on ::1:8765: Address family for hostname not supported', where
    ``gui --host ::1`` serves. It serves now, its address said with the brackets a URL needs;
    an IPv4 address still serves as before."""
    srv = FrameServer("::1", 0)
    try:
        assert srv.url == f"http://[::1]:{srv.port}/"
        assert srv._httpd.server_address[0] == "::1"
        assert _get(srv.url + "frame.jpg")[:2] == (503, "text/plain")
        srv.update(np.zeros((8, 8, 3), np.uint8), np.zeros((8, 8), np.float32), 16.0)
        assert _get(srv.url + "frame.jpg")[:2] == (200, "image/jpeg")
        import errno

        with pytest.raises(OSError) as info:  # its port taken: the address as a URL says it
            FrameServer("::1", srv.port)
        assert info.value.errno == errno.EADDRINUSE
        assert str(info.value).startswith(f"cannot serve the view on [::1]:{srv.port}: ")
    finally:
        srv.close()
    # as a URL writes it: it was bound as a host name (not found), said '[[::1]]:0'
    srv = FrameServer("[::1]", 0)
    try:
        assert srv.url == f"http://[::1]:{srv.port}/"
        assert srv._httpd.server_address[0] == "::1"
        assert _get(srv.url + "frame.jpg")[:2] == (503, "text/plain")
    finally:
        srv.close()


def _link_local_address() -> str | None:
    """A link-local IPv6 address of this machine with its interface (``fe80::1%eth0``)."""
    try:
        lines = Path("/proc/net/if_inet6").read_text().splitlines()
    except OSError:
        return None
    for line in lines:
        hexaddr, _, _, scope, _, name = line.split()
        if scope == "20":  # link scope
            words = [hexaddr[k : k + 4] for k in range(0, 32, 4)]
            return f"{ipaddress.IPv6Address(':'.join(words))}%{name}"
    return None


def test_the_view_serves_on_a_link_local_address_with_its_interface() -> None:
    """``--serve --host fe80::...%eth0`` (which ``gui --host`` serves on) was refused: bound
    as (host, port) the address lost its interface, 'cannot serve the view on
    [fe80::fc:ff:fe00:1%eth0]:0: Invalid argument'. It is bound with its scope id now."""
    host = _link_local_address()
    if host is None:
        pytest.skip("no link-local IPv6 address here")
    srv = FrameServer(host, 0)
    try:
        assert srv.url == f"http://[{host.replace('%', '%25')}]:{srv.port}/"  # RFC 6874
        assert srv._httpd.server_address[3] != 0  # the interface's scope id
        assert _get(srv.url + "frame.jpg")[:2] == (503, "text/plain")
    finally:
        srv.close()


@pytest.mark.parametrize("json_out", [True, False])
@PIPELINED
def test_each_report_line_is_flushed_as_it_is_written(
    json_out: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every report line reaches a pipe when it is printed (a process reading ``--json`` live
    got the lines of a block-buffered stdout only at its end): each is flushed at once."""
    import io
    import sys

    import stereovision.stream as stream

    class _Piped(io.StringIO):
        def __init__(self) -> None:
            super().__init__()
            self.flushed: list[str] = []

        def flush(self) -> None:
            self.flushed.append(self.getvalue())

    out = _Piped()
    monkeypatch.setattr(sys, "stdout", out)
    monkeypatch.setattr(stream, "open_source", lambda args, fps=None: _SkippingRig([_frame(0)]))
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--no-check"]
    assert main([*argv, "--max-disparity", "8", *(["--json"] if json_out else [])]) == 0
    report = out.getvalue().splitlines()[0]
    assert ("fps" in json.loads(report)) if json_out else ("fps |" in report)
    assert report + "\n" in out.flushed  # flushed alone, before the summary was written


@pytest.mark.parametrize("pipelined", [False, True])
@PIPELINED
def test_the_warnings_of_the_grabbing_point_at_the_callers_line(pipelined: bool) -> None:
    """A source that ended before the other and frames resampled before ``temporal`` were warned
    about in :func:`_pairs`: unpipelined that named a line of stream.py, pipelined one of
    threading.py (the grabbing thread's). ``run_stream`` now gives them, at its caller's line."""
    from stereovision.capture import SourceError
    from stereovision.temporal import TemporalFilter

    early = SourceError("right source ended after 2 frames", side="right", other_had_frames=True)
    rig: Any = _FakeRig([_frame(0), _frame(0), early])
    rig.rectified_topics, rig.topics = True, {"left": "/l/rect", "right": "/r/rect"}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = run_stream(rig, max_disparity=8, pipelined=pipelined, check=False,
                         temporal=TemporalFilter(max_frames=4))  # fmt: skip
    assert rep.frames == 2
    said = [(str(w.message)[:35], w.filename) for w in caught]
    assert said == [
        ("temporal averaging: the topics /l/r", __file__),
        ("right source ended after 2 frames", __file__),
    ]


@PIPELINED
def test_the_warnings_of_a_streams_pairs_point_at_the_callers_line(data_dir: Path) -> None:
    """The warnings :func:`run_stream` gives itself of its pairs (noisy cameras, rows that do not
    agree) name the caller's line, pipelined or not."""
    from stereovision.capture import StereoFrame
    from tests.test_exposure import noisy

    cones = load_scene(data_dir / "middlebury2003" / "cones")
    rng = np.random.default_rng(1)
    for pipelined in (False, True):
        frames = []
        for i in range(2):
            right = np.roll(cones.right, 4, axis=0)  # rows 4 px apart: not rectified
            frames.append(StereoFrame(noisy(cones.left, 12.0, rng), noisy(right, 12.0, rng),
                                      time.monotonic(), time.monotonic(), i))  # fmt: skip
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            run_stream(_FakeRig(frames), max_disparity=16, pipelined=pipelined)  # type: ignore[arg-type]
        said = sorted((str(w.message)[:20], w.filename) for w in caught)
        assert [s[0][:11] for s in said] == ["first pair:", "the cameras"], said
        assert [s[1] for s in said] == [__file__, __file__], said


@pytest.mark.parametrize("pipelined", [False, True])
@PIPELINED
def test_a_cameras_own_warnings_point_at_the_callers_line(tmp_path: Path, pipelined: bool) -> None:
    """A StereoCamera's warning of its own (a source delivering another size, resized) raised
    in the grabbing thread of a pipelined stream named threading.py; the stream hands it to
    its caller's line, as unpipelined, and before the pair's own warnings."""
    rng = np.random.default_rng(0)
    for i in range(3):
        img = (rng.random((60, 80, 3)) * 255).astype(np.uint8)
        cv2.imwrite(str(tmp_path / f"left_{i:02d}.png"), img)
        cv2.imwrite(str(tmp_path / f"right_{i:02d}.png"), cv2.resize(img, (160, 120)))
    with (
        warnings.catch_warnings(record=True) as caught,
        StereoCamera(str(tmp_path / "left_%02d.png"), str(tmp_path / "right_%02d.png")) as cam,
    ):
        warnings.simplefilter("always")
        rep = run_stream(cam, max_disparity=8, check=False, pipelined=pipelined)
    assert rep.frames == 3
    said = [(str(w.message)[:12], w.filename) for w in caught]
    assert said == [("right source", __file__), ("the cameras ", __file__)], said


@PIPELINED
def test_the_calibration_fitted_to_the_frames_is_said_at_the_callers_line(
    data_dir: Path, tmp_path: Path
) -> None:
    """The note of a calibration scaled to the frames delivered names the caller's line."""
    scene = data_dir / SCENE
    for side in ("left", "right"):
        img = cv2.resize(cv2.imread(str(scene / f"{side}.png")), (320, 240))
        cv2.imwrite(str(tmp_path / f"{side}_00.png"), img)
    calib = Calibration.from_file(scene / "calib.txt")  # 640x480
    with (
        warnings.catch_warnings(record=True) as caught,
        StereoCamera(str(tmp_path / "left_%02d.png"), str(tmp_path / "right_%02d.png")) as cam,
    ):
        warnings.simplefilter("always")
        run_stream(cam, calib, max_disparity=32, check=False)
    said = [w for w in caught if "calibration is for 640x480" in str(w.message)]
    assert [w.filename for w in said] == [__file__]


@pytest.mark.parametrize(
    ("positions", "fps"),
    [([0.0] * 5, 10.0), ([0.0, 100.0, 200.0, 100.0, 400.0], 10.0), ([0.0] * 5, 0.0)],
    ids=["stalled", "backwards", "no rate"],
)
@pytest.mark.parametrize("pipelined", [False, True])
def test_video_stamps_increase_when_the_media_time_stalls_or_goes_back(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    positions: list[float],
    fps: float,
    pipelined: bool,
) -> None:
    """Two video files are stamped by the left one's media time (CAP_PROP_POS_MSEC); a
    container or backend that reports 0 throughout, or a position that goes back, gave pairs
    one stamp, or a stamp before the last. From there the frame period steps them (the wall
    clock without a rate), strictly increasing, said once."""
    from stereovision import capture as capmod

    size = (64, 48)
    for side in ("left", "right"):
        vw = cv2.VideoWriter(str(tmp_path / f"{side}.avi"), cv2.VideoWriter_fourcc(*"MJPG"),
                             10.0, size)  # fmt: skip
        for i in range(len(positions)):
            vw.write(np.full((size[1], size[0], 3), 40 * i, np.uint8))
        vw.release()
    told = iter([p for p in positions for _ in ("left", "right")])
    monkeypatch.setattr(capmod, "_media_ms", lambda cap: next(told))
    seen: list[int] = []
    with StereoCamera(tmp_path / "left.avi", tmp_path / "right.avi") as cam:
        assert cam.media_clock
        cam.delivered_fps["left"] = fps
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            run_stream(cam, max_disparity=8, pipelined=pipelined, check=False,
                       on_stamped_result=lambda left, res, ns: seen.append(ns))  # fmt: skip
    assert len(seen) == len(positions)
    assert (np.diff(seen) > 0).all()
    if fps:
        assert np.diff(seen).tolist() == [100_000_000] * (len(positions) - 1)
    stalled = [str(w.message) for w in caught if "media time" in str(w.message)]
    at = 4 if positions[3] < positions[2] else 2
    step = "the frame index and the video's frame rate" if fps else "the wall clock of their read"
    assert stalled == [
        f"left source {str(tmp_path / 'left.avi')!r}: its media time did not move on at pair "
        f"{at} (position {positions[at - 1]:.0f} ms; the container or backend reports a stalled "
        f"or repeated one): this pair and the next are stamped by {step}"
        + (" (the video reports no frame rate)" if not fps else "")
    ]


@PIPELINED
def test_a_streams_password_is_not_said_in_its_reports(
    videos: dict[str, Path], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Streams given by URLs with a password (and a token parameter): the failing source
    was named with them in the error line and the JSON summary's ``error``. They are said as
    ``***``; the URLs opened are the ones given."""
    from stereovision import capture as capmod

    left_url, right_url = "rtsp://admin:s3cret@cam/0?token=tok77", "http://u:pw99@cam/1"
    real = capmod._open_path
    opened: list[str] = []

    class FailsAtThird:
        """The right stream: a backend error in its third grab."""

        def __init__(self, cap: Any) -> None:
            self.cap, self.grabs = cap, 0

        def grab(self) -> bool:
            self.grabs += 1
            if self.grabs == 3:
                raise cv2.error("connection reset")
            return bool(self.cap.grab())

        def __getattr__(self, name: str) -> Any:
            return getattr(self.cap, name)

    def open_path(path: str, first: Any) -> Any:
        opened.append(path)
        if path == right_url:
            return FailsAtThird(real(str(videos["right"]), first))
        return real(str(videos["left"]) if path == left_url else path, first)

    monkeypatch.setattr(capmod, "_open_path", open_path)
    argv = ["stream", "--left", left_url, "--right", right_url, "--no-pipeline"]
    argv += ["--calib", str(videos["calib"]), "--max-disparity", "64", "--no-display", "--json"]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    said = "right source 'http://u:***@cam/1' failed in OpenCV's grab of pair 3 ("
    assert _json_lines(out)[-1]["error"].startswith(said)
    assert err.splitlines()[-1].startswith(f"stereovision: error: {said}")
    assert opened == [left_url, right_url]
    for secret in ("s3cret", "tok77", "pw99"):
        assert secret not in out + err


class _Unplugged:
    """A camera device (``cv2.VideoCapture(index)`` stand-in) that delivers ``frames`` frames,
    then none: unplugged, a loose cable."""

    frames = 3
    gone: tuple[int, ...] = (0, 1)  # the device indexes unplugged

    def __init__(self, index: int, *args: Any) -> None:
        self.index, self.n = index, 0
        self.frame = _frame(0).left if index == 0 else np.roll(_frame(0).left, -2, axis=1)

    def isOpened(self) -> bool:
        return True

    def grab(self) -> bool:
        self.n += 1
        return self.n <= self.frames or self.index not in self.gone

    def retrieve(self) -> tuple[bool, np.ndarray]:
        return True, self.frame.copy()

    def get(self, prop: int) -> float:
        return {cv2.CAP_PROP_FRAME_WIDTH: 64.0, cv2.CAP_PROP_FRAME_HEIGHT: 48.0}.get(prop, 0.0)

    def set(self, prop: int, value: float) -> bool:
        return False

    def release(self) -> None:
        pass


@PIPELINED
@pytest.mark.parametrize(
    ("gone", "said"),
    [
        ((0,), "left source camera 0 stopped delivering frames after 3 (disconnected?); the "
               "right source still had frames"),
        ((0, 1), "left source camera 0 stopped delivering frames after 3 (disconnected?); "
                 "right source camera 1 stopped delivering frames after 3 (disconnected?)"),
    ],
)  # fmt: skip
def test_a_camera_that_stops_delivering_fails_the_stream(
    gone: tuple[int, ...],
    said: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A camera device has no end: one unplugged mid-stream ended it as ``"end of stream"``,
    exit 0 (with one warning; both unplugged, without a word). It ends as ``"source failed"``
    now, the error naming the cameras, the pairs done kept in the summary; exit 2."""
    monkeypatch.setattr(_Unplugged, "gone", gone)
    monkeypatch.setattr(cv2, "VideoCapture", _Unplugged)
    for pipelined in (True, False):
        with StereoCamera(0, 1) as cam, warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            rep = run_stream(cam, max_disparity=8, check=False, pipelined=pipelined)
        assert (rep.frames, rep.ended, rep.error) == (3, "source failed", said)
        assert [str(w.message) for w in caught] == []
    argv = ["stream", "--left", "0", "--right", "1", "--no-display", "--no-check", "--json"]
    assert main([*argv, "--max-disparity", "8"]) == 2
    out, err = capsys.readouterr()
    summary = json.loads(out.splitlines()[-1])
    assert (summary["frames"], summary["ended"], summary["error"]) == (3, "source failed", said)
    assert err.splitlines()[-1] == f"stereovision: error: {said}"


def test_a_video_file_read_to_its_end_still_ends_its_stream(tmp_path: Path) -> None:
    """Files and sequences do end: read to their last frame, the stream ends as before."""
    for side, shift in (("l", 0), ("r", -2)):
        for i in range(3):
            cv2.imwrite(str(tmp_path / f"{side}{i}.png"), np.roll(_frame(0).left, shift, axis=1))
    with StereoCamera(str(tmp_path / "l%d.png"), str(tmp_path / "r%d.png")) as cam:
        rep = run_stream(cam, max_disparity=8, check=False)
    assert (rep.frames, rep.ended, rep.error) == (3, "end of stream", None)


class _UnpluggedNode(_Unplugged):
    """A camera opened by its V4L2 node (``/dev/video0``, a ``/dev/v4l/by-id`` link): the
    path OpenCV gets, with the backend a device reports."""

    def __init__(self, path: Any, *args: Any) -> None:
        super().__init__(0 if "0" in str(path) else 1)

    def getBackendName(self) -> str:
        return "V4L2"


@PIPELINED
def test_a_camera_opened_by_its_device_node_that_stops_fails_the_stream(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--left /dev/video0`` is a camera as ``--left 0`` is: unplugged mid-stream, it ended the
    stream as ``"end of stream"``, exit 0 (only a camera index was taken for a device). So
    does a ``/dev/v4l/by-id`` link, whose link is gone once the camera is unplugged."""
    link = tmp_path / "usb-cam-video-index0"
    link.symlink_to("/dev/video0")  # as udev's by-id link: dangling here, no camera
    real_exists = os.path.exists
    nodes = ("/dev/video0", "/dev/video1", str(link))
    monkeypatch.setattr(os.path, "exists", lambda p: str(p) in nodes or real_exists(p))
    monkeypatch.setattr(cv2, "VideoCapture", _UnpluggedNode)
    said = (
        "left source '{}' stopped delivering frames after 3 (disconnected?); right source "
        "'/dev/video1' stopped delivering frames after 3 (disconnected?)"
    )
    for left in ("/dev/video0", str(link)):
        with StereoCamera(left, "/dev/video1") as cam:
            if left == str(link):
                link.unlink()  # unplugged: udev removes the link
            rep = run_stream(cam, max_disparity=8, check=False, pipelined=False)
        assert (rep.frames, rep.ended, rep.error) == (3, "source failed", said.format(left))
    argv = ["stream", "--left", "/dev/video0", "--right", "/dev/video1", "--no-display"]
    assert main([*argv, "--no-check", "--json", "--max-disparity", "8"]) == 2
    out, err = capsys.readouterr()
    summary = json.loads(out.splitlines()[-1])
    assert (summary["frames"], summary["ended"]) == (3, "source failed")
    assert err.splitlines()[-1] == f"stereovision: error: {said.format('/dev/video0')}"


@PIPELINED
def test_a_network_camera_that_stops_delivering_fails_the_stream(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """An IP camera's live stream (``rtsp://``, as ``rtmp``, ``srt``, ``udp`` ...) has no end
    either: its network dropped mid-stream ended the stream as ``"end of stream"``, exit 0,
    without a word when both went, as a video file's end (only device indexes and nodes were
    taken for cameras). It fails now as an unplugged camera does; an ``http://`` URL, which may
    name a video file, still ends."""
    from stereovision import capture as capmod

    # the URL's capture (_UnpluggedNode: one that reports its backend, as OpenCV's do)
    monkeypatch.setattr(capmod, "_open_path", lambda path, first: _UnpluggedNode(path[-1]))
    said = (
        "left source 'rtsp://cam/0' stopped delivering frames after 3 (disconnected?); right "
        "source 'srt://cam:9000/1' stopped delivering frames after 3 (disconnected?)"
    )
    with StereoCamera("rtsp://cam/0", "srt://cam:9000/1") as cam:
        rep = run_stream(cam, max_disparity=8, check=False, pipelined=False)
    assert (rep.frames, rep.ended, rep.error) == (3, "source failed", said)
    argv = ["stream", "--left", "rtsp://cam/0", "--right", "srt://cam:9000/1", "--no-display"]
    assert main([*argv, "--no-check", "--json", "--max-disparity", "8"]) == 2
    out, err = capsys.readouterr()
    summary = json.loads(out.splitlines()[-1])
    assert (summary["frames"], summary["ended"]) == (3, "source failed")
    assert err.splitlines()[-1] == f"stereovision: error: {said}"
    with StereoCamera("http://host/l.mp4", "https://host/r1.mp4") as cam:
        rep = run_stream(cam, max_disparity=8, check=False, pipelined=False)
    assert (rep.frames, rep.ended, rep.error) == (3, "end of stream", None)
    # capture without --count: its pairs kept, the loss said (it ended as 'end of stream')
    from stereovision.capture import SourceError, capture

    with StereoCamera("rtsp://cam/0", "srt://cam:9000/1") as cam:
        with pytest.raises(SourceError) as info:
            capture(cam, tmp_path)
    assert str(info.value) == f"{said}; 3 pairs were saved in {tmp_path} and are kept"
    assert len(list(tmp_path.glob("right_*.png"))) == 3


@PIPELINED
def test_a_count_of_one_pair_is_said_in_the_singular(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A one-pair stream's summary said "1 pairs in 0.09 s", and its --bag line "1 of the 1
    pairs processed" ("1 frames", "none of the 1 pairs"), where capture says "1 pair"."""
    from types import SimpleNamespace

    from stereovision.stream import _bag_line

    scene = data_dir / "middlebury2003" / "cones"
    for side in ("left", "right"):
        img = cv2.imread(str(scene / f"{side}.png"))
        cv2.imwrite(str(tmp_path / f"{side}_000.png"), img[100:164, 100:196])
    argv = ["stream", "--left", str(tmp_path / "left_%03d.png"), "--no-display", "--no-check"]
    argv += ["--right", str(tmp_path / "right_%03d.png"), "--max-disparity", "16"]
    assert main(argv) == 0
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.startswith("1 pair in ") and " s (end of stream): " in last

    def bag(frames: int, messages: int) -> SimpleNamespace:
        return SimpleNamespace(path="b", frames=frames, messages=messages)

    assert (
        _bag_line(bag(1, 7), 1) == "ROS 2 bag written to b (1 of the 1 pair processed, 7 messages)"
    )
    assert (
        _bag_line(bag(2, 14), 2)
        == "ROS 2 bag written to b (2 of the 2 pairs processed, 14 messages)"
    )
    assert _bag_line(bag(1, 7), 0) == "ROS 2 bag written to b (1 frame, 7 messages)"
    assert _bag_line(bag(0, 0), 1).startswith(
        "no ROS 2 bag written to b: none of the 1 pair processed; "
    )


@pytest.mark.parametrize(
    ("sources", "side", "lost"),
    [
        ({"left": "a.mp4", "right": 1}, "left", False),  # the file ended, not the camera
        ({"left": "a.mp4", "right": 1}, "right", True),
        ({"left": "a.mp4", "right": 1}, None, True),  # both ended: one was a camera
        ({"left": np.int64(0), "right": "b.mp4"}, "both", True),
        ({"left": "a.mp4", "right": "b.mp4"}, "both", False),
    ],
)
def test_mutation_audit_5_a_device_ended_of_a_camera_and_a_file(
    sources: dict[str, object], side: str | None, lost: bool
) -> None:
    """_device_ended looks at the side(s) that ended only: of a file beside a camera, the file's
    end is an end, the camera's a loss; both ended, one camera is a loss. The mutation audit
    found the side choice unasserted (every test had two cameras or two files)."""
    from types import SimpleNamespace

    from stereovision.capture import SourceError
    from stereovision.stream import _device_ended

    camera = SimpleNamespace(sources=sources)
    assert _device_ended(camera, SourceError("ended", side=side, frames=3)) is lost


def test_mutation_audit_the_view_rounds_16_bits_as_the_pipeline_does() -> None:
    """Mutation audit of 06b636b: the view shows a 16-bit left image as as_bgr_uint8 makes it
    8-bit (divided by 257, rounded to nearest) for every one of the 65536 values, not truncated
    (129 is 1, not 0; 65407 is 255, 65406 254)."""
    from stereovision._validate import as_bgr_uint8
    from stereovision.stream import _view_bgr

    grey = np.arange(65536, dtype=np.uint16).reshape(256, 256)
    shown = _view_bgr(grey)
    np.testing.assert_array_equal(shown, as_bgr_uint8(grey))
    assert shown[0, 129, 0] == 1 and tuple(shown.reshape(-1, 3)[65406:65408, 0]) == (254, 255)


@pytest.mark.parametrize(
    ("extra", "said"),
    [
        (["--serve", "9000"], "--serve: it places"),
        (["--host", "0.0.0.0"], "--host: it places"),
        (["--host", "::1", "--serve", "0"], "--serve and --host: they place"),
    ],
)
def test_serve_or_host_with_no_display_is_refused_before_any_open(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], said: str
) -> None:
    """``stream --no-display --serve 9000`` (or ``--host 0.0.0.0``) streamed headless, the view
    asked for at that address never served and nothing said; refused now in one line, exit 2,
    before the cameras are opened (these do not exist)."""
    from stereovision.cli import main

    argv = ["stream", "--left", str(tmp_path / "l.avi"), "--right", str(tmp_path / "r.avi")]
    assert main([*argv, "--no-display", *extra]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        f"stereovision: error: {said} the live view, which --no-display turns off; give one or "
        "the other\n"
    )


def test_a_scoped_ipv6_hosts_url_escapes_its_zone() -> None:
    """--host fe80::1%eth0 (a link-local address, its interface named) was printed as
    'http://[fe80::1%eth0]:8765/', '%et' an invalid escape to a strict URL parser; the zone's
    '%' is '%25' (RFC 6874), in stream --serve's URL and gui's alike."""
    from stereovision.gui import url_for
    from stereovision.stream import _host_port

    assert _host_port("fe80::1%eth0", 8765) == "[fe80::1%25eth0]:8765"
    assert url_for("fe80::1%eth0", 8080) == "http://[fe80::1%25eth0]:8080/"
    assert _host_port("::1", 8765) == "[::1]:8765"  # unscoped: unchanged
    assert _host_port("127.0.0.1", 8765) == "127.0.0.1:8765"


def test_check_every_with_no_check_is_refused_before_any_open(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``stream --no-check --check-every 1`` (run_stream's check=False, check_every=1) checked
    no pair at all, the summary's checks [] and nothing said; refused now before any grab (the
    CLI's cameras do not exist: before any open), in one line, exit 2."""
    rig = _FakeRig([_frame(0)])
    with pytest.raises(ValueError) as err:
        run_stream(rig, max_disparity=8, check=False, check_every=1)  # type: ignore[arg-type]
    assert str(err.value) == (
        "check_every: it checks the rows of pairs, which check=False turns off; give one or the "
        "other"
    )
    assert rig.count == 0
    argv = ["stream", "--left", str(tmp_path / "l.avi"), "--right", str(tmp_path / "r.avi")]
    assert main([*argv, "--no-display", "--no-check", "--check-every", "1"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        "stereovision: error: --check-every: it checks the rows of pairs, which --no-check turns "
        "off; give one or the other\n"
    )


@pytest.mark.parametrize("pipelined", [False, True])
def test_a_reused_temporal_filter_reports_the_restarts_of_its_own_run(pipelined: bool) -> None:
    """A TemporalFilter reused from a stream before (reset()'s note allows it): the summary's
    restarts were the filter's over both runs (a still view that restarted once, on its first
    pair against the run before's mean, said 4, the first run's 3 with it). They are the run's."""
    from stereovision.temporal import TemporalFilter

    tf = TemporalFilter(max_frames=4)
    kw: dict[str, Any] = {"max_disparity": 8, "check": False, "temporal": tf}
    moving = run_stream(_FakeRig([_frame(i) for i in range(4)]), pipelined=False, **kw)  # type: ignore[arg-type]
    assert moving.temporal is not None and moving.temporal["restarts"] == 3 == tf.restarts
    still = run_stream(_FakeRig([_frame(9)] * 4), pipelined=pipelined, **kw)  # type: ignore[arg-type]
    assert still.temporal is not None
    assert (still.temporal["restarts"], tf.restarts) == (1, 4)
    assert still.temporal["frames_averaged"] == 2.5


def test_the_view_refuses_a_disparity_of_another_size_than_its_left_image(
    capfd: pytest.CaptureFixture[str],
) -> None:
    """FrameServer.update(left, disparity) with a disparity of another size (matched at half
    size) was taken, then every request failed in the server's thread: no answer, NumPy's
    hstack traceback on stderr. It is refused in the caller's thread now, the view kept."""
    left = np.zeros((40, 60, 3), np.uint8)
    server = FrameServer("127.0.0.1", 0)
    try:
        server.update(left, np.zeros((40, 60), np.float32), 16)
        for disparity, shape in (
            (np.zeros((20, 30), np.float32), "(20, 30)"),
            (np.zeros((40, 60, 1), np.float32), "(40, 60, 1)"),
        ):
            with pytest.raises(ValueError) as err:
                server.update(left, disparity, 16)
            assert str(err.value) == (
                f"disparity: expected a map of the left image's 60x40 px, got shape {shape}"
            )
        with pytest.raises(ValueError, match=re.escape("left: expected an (H, W) or (H, W, C)")):
            server.update(np.zeros(5, np.uint8), np.zeros((40, 60), np.float32), 16)
        status, ctype, body = _get(server.url + "frame.jpg")
        assert (status, ctype) == (200, "image/jpeg")
        assert cv2.imdecode(np.frombuffer(body, np.uint8), cv2.IMREAD_COLOR).shape == (40, 120, 3)
    finally:
        server.close()
    assert "Traceback" not in capfd.readouterr().err


def test_the_view_refuses_a_colour_scale_that_is_no_positive_number(
    capfd: pytest.CaptureFixture[str],
) -> None:
    """FrameServer.update(..., max_disparity=nan) (np.nanmax of a map without a value) was
    taken: every frame's colours were the cast of NaN, with NumPy's "invalid value encountered
    in cast" from the server's thread; -5 or "16" passed too. Refused in the caller's thread."""
    left = np.zeros((8, 8, 3), np.uint8)
    disparity = np.full((8, 8), 4.0, np.float32)
    server = FrameServer("127.0.0.1", 0)
    try:
        for top, said in (
            (math.nan, "max_disparity: expected a finite number, got nan"),
            (None, "max_disparity: expected a finite number, got None"),
            ("16", "max_disparity: expected a finite number, got '16'"),
            (-5.0, "max_disparity: expected a positive number, got -5.0"),
            (0, "max_disparity: expected a positive number, got 0"),
        ):
            with pytest.raises(ValueError) as err:
                server.update(left, disparity, top)  # type: ignore[arg-type]
            assert str(err.value) == said
        assert _get(server.url + "frame.jpg")[0] == 503  # nothing was published
        server.update(left, disparity, np.float32(8))
        assert _get(server.url + "frame.jpg")[:2] == (200, "image/jpeg")
    finally:
        server.close()
    assert "RuntimeWarning" not in capfd.readouterr().err


def test_the_view_refuses_a_left_it_cannot_show(capfd: pytest.CaptureFixture[str]) -> None:
    """FrameServer.update took a left of 2 channels, an empty one and a nested list (its shape
    alone was checked), and every request then failed in the server's thread (NumPy's hstack,
    OpenCV's JPEG encoder, "'list' object has no attribute 'dtype'"): no answer, a traceback on
    stderr. They are refused in the caller's thread, the view kept; a list is shown as its
    array."""
    disparity = np.zeros((40, 60), np.float32)
    server = FrameServer("127.0.0.1", 0)
    try:
        server.update(np.zeros((40, 60, 3), np.uint8), disparity, 16)
        for left, said in (
            (np.zeros((40, 60, 2), np.uint8), "left: expected 1, 3 or 4 channels, got 2"),
            (np.zeros((0, 0), np.uint8), "left: expected an (H, W) or (H, W, C) image, got (0, 0)"),
        ):
            with pytest.raises(ValueError) as err:
                server.update(left, np.zeros(left.shape[:2], np.float32), 16)
            assert str(err.value) == said
        # a float image's [0, 1], as run_stream's frames of floats are shown
        server.update(np.full((40, 60), 200 / 255).tolist(), disparity, 16)  # type: ignore[arg-type]
        status, ctype, body = _get(server.url + "frame.jpg")
        assert (status, ctype) == (200, "image/jpeg")
        view = cv2.imdecode(np.frombuffer(body, np.uint8), cv2.IMREAD_GRAYSCALE)
        assert view.shape == (40, 120) and abs(int(view[20, 30]) - 200) <= 2
    finally:
        server.close()
    assert "Traceback" not in capfd.readouterr().err


def test_the_view_refuses_a_float_left_outside_0_1() -> None:
    """FrameServer.update showed a float left as [0, 1]: one of 0-255 floats came out all
    white, without a word. It is refused in the package's words for such an image (a NaN pixel
    does not hide the range); a [0, 1] one with a NaN is still taken."""
    disparity = np.zeros((4, 6), np.float32)
    left = np.full((4, 6), 200.0, np.float32)
    left[0, 0] = np.nan
    server = FrameServer("127.0.0.1", 0)
    try:
        with pytest.raises(ValueError) as err:
            server.update(left, disparity, 16)
        assert str(err.value) == (
            "left: float image values must lie in [0, 1], got range [200, 200] (divide 8-bit "
            "data by 255, or pass the uint8 array itself)"
        )
        assert server.latest_jpeg() is None
        server.update(left / 255, disparity, 16)
        assert server.latest_jpeg() is not None
    finally:
        server.close()


def test_the_view_refuses_a_left_of_no_image_dtype(capfd: pytest.CaptureFixture[str]) -> None:
    """FrameServer.update took a left of any dtype: a list of grey levels (int64) was shown
    white (as floats past 1), strings failed in the server's thread (NumPy's UFuncTypeError).
    They are refused as the package's images are; a big-endian uint16 is shown as its values."""
    disparity = np.zeros((40, 60), np.float32)
    server = FrameServer("127.0.0.1", 0)
    try:
        for left, said in (
            ([[100] * 60] * 40, "unsupported dtype int64"),
            (np.zeros((40, 60), bool), "unsupported dtype bool"),
            (np.full((40, 60), "a"), "expected a numeric image array"),
        ):
            with pytest.raises(ValueError, match=rf"^left: {said}"):
                server.update(left, disparity, 16)  # type: ignore[arg-type]
        server.update(np.full((40, 60), 200 * 257, ">u2"), disparity, 16)
        status, _, body = _get(server.url + "frame.jpg")
        view = cv2.imdecode(np.frombuffer(body, np.uint8), cv2.IMREAD_GRAYSCALE)
        assert status == 200 and abs(int(view[20, 30]) - 200) <= 2
    finally:
        server.close()
    assert "Traceback" not in capfd.readouterr().err


def test_the_bag_line_names_a_folder_with_a_newline_escaped_on_one_line() -> None:
    """--bag named with a newline: the bag line printed it as it is, cut in two ('ROS 2 bag
    written to o' then 'ut (3 of the 3 pairs ...)'), where capture and batch escape -o."""
    from types import SimpleNamespace

    from stereovision.stream import _bag_line

    def bag(frames: int, messages: int) -> Any:
        return SimpleNamespace(path=Path("o\nut"), frames=frames, messages=messages)

    assert _bag_line(bag(3, 12), 3) == (
        "ROS 2 bag written to o\\nut (3 of the 3 pairs processed, 12 messages)"
    )
    assert _bag_line(bag(0, 0), 0) == "no ROS 2 bag written to o\\nut: no frame in it"
    assert _bag_line(bag(0, 0), 2).startswith(
        "no ROS 2 bag written to o\\nut: none of the 2 pairs processed; "
    )


def test_temporal_is_refused_at_parse_time(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """``--temporal 8.5`` was argparse's "invalid int value: '8.5'" where the other counts say
    what they expect, and ``--temporal 1`` was refused only after ``--calib`` was read (a
    missing calibration was said first); both are refused by argparse, in the option's name."""
    argv = ["stream", "--left", "0", "--right", "1", "--calib", str(tmp_path / "no.yaml")]
    for n in ("8.5", "1"):
        with pytest.raises(SystemExit) as info:
            main([*argv, "--temporal", n])
        assert info.value.code == 2
        err = capsys.readouterr().err
        assert f"argument --temporal: expected 2-255 pairs to average, got '{n}'" in err
        assert "no.yaml" not in err
