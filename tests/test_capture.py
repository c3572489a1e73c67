"""Two-camera capture, end to end with video files and image sequences as sources."""

from __future__ import annotations

import argparse
import functools
import itertools
import math
import os
import re
import subprocess
import sys
import threading
import time
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any, ClassVar

import cv2
import numpy as np
import pytest

from stereovision import capture as capmod
from stereovision.calibrate import board_pose_params, render_chessboard
from stereovision.capture import (
    ChessboardCollector,
    SourceError,
    StereoCamera,
    add_cli,
    capture,
    charuco_pose_params,
    detect_board_live,
    fourcc_text,
    mask_url_secrets,
    next_pair_index,
    parse_fourcc,
    parse_size,
    parse_source,
    save_pair,
)
from stereovision.charuco import CharucoBoard, find_charuco_corners, render_charuco

#: Frame numbers are written as a row of black/white blocks (robust to MJPG) at the top left.
CODE_BITS = 10
CODE_BLOCK = 12
SMALL = (320, 240)
BOARD_SIZE = (640, 480)
FPS = 10.0

# A rig for the chessboard videos (metres).
K = np.array([[600.0, 0, 320], [0, 600.0, 240], [0, 0, 1]])
D = np.zeros(5)
RIG_R = np.eye(3)
RIG_T = np.array([-0.06, 0.0, 0.0])
SQUARE = 0.03


def _stamp(img: np.ndarray, n: int) -> np.ndarray:
    """Write ``n`` as CODE_BITS blocks (white = 1) plus a readable number."""
    for b in range(CODE_BITS):
        v = 255 if (n >> b) & 1 else 0
        x = 2 + b * CODE_BLOCK
        img[2 : 2 + CODE_BLOCK, x : x + CODE_BLOCK] = v
    cv2.putText(
        img, str(n), (4, 2 * CODE_BLOCK + 22), cv2.FONT_HERSHEY_SIMPLEX, 0.8, (0, 0, 255), 2
    )
    return img


def _read_stamp(img: np.ndarray) -> int:
    gray = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    n = 0
    for b in range(CODE_BITS):
        x = 2 + b * CODE_BLOCK
        block = gray[4:CODE_BLOCK, x + 2 : x + CODE_BLOCK - 2]
        n |= int(block.mean() > 128) << b
    return n


def _numbered(n: int, size: tuple[int, int] = SMALL, shade: int = 90) -> np.ndarray:
    w, h = size
    img = np.full((h, w, 3), shade, np.uint8)
    return _stamp(img, n)


def _write_video(path: Path, frames: list[np.ndarray], fps: float = FPS) -> Path:
    h, w = frames[0].shape[:2]
    vw = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), fps, (w, h))
    assert vw.isOpened()
    for f in frames:
        vw.write(f)
    vw.release()
    return path


def _write_sequence(directory: Path, side: str, frames: list[np.ndarray]) -> str:
    directory.mkdir(parents=True, exist_ok=True)
    for i, f in enumerate(frames):
        cv2.imwrite(str(directory / f"{side}_{i:03d}.png"), f)
    return str(directory / f"{side}_%03d.png")


def _videos(
    tmp: Path, n_left: int, n_right: int, size: tuple[int, int] = SMALL
) -> tuple[Path, Path]:
    left = _write_video(tmp / "left.avi", [_numbered(i, size) for i in range(n_left)])
    right = _write_video(tmp / "right.avi", [_numbered(i, size, 160) for i in range(n_right)])
    return left, right


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="stereovision")
    sub = parser.add_subparsers(dest="command", required=True)
    add_cli(sub)
    return parser


# ------------------------------------------------------------------------------- sources


def test_video_files_count_order_and_skew(tmp_path: Path) -> None:
    left, right = _videos(tmp_path, 12, 12)
    with StereoCamera(left, right) as cam:
        frames = list(cam.frames())
        report = cam.skew_report()
        assert cam.size == SMALL and cam.delivered_size == {"left": SMALL, "right": SMALL}
        assert cam.delivered_fps == {"left": FPS, "right": FPS}
    assert len(frames) == 12
    assert [_read_stamp(f.left) for f in frames] == list(range(12))
    assert [_read_stamp(f.right) for f in frames] == list(range(12))
    assert [f.index for f in frames] == list(range(12))
    # Media timestamps: 100 ms apart at 10 fps, equal left and right.
    assert [f.pos_left_ms for f in frames] == pytest.approx([100.0 * i for i in range(12)])
    assert [f.pos_right_ms for f in frames] == pytest.approx([f.pos_left_ms for f in frames])
    # Host timestamps: left grabbed first, then right, pairs in time order.
    assert all(f.t_right >= f.t_left for f in frames)
    assert all(b.t_left >= a.t_right for a, b in itertools.pairwise(frames))
    assert report["n"] == 12
    # The skew is the host time between the two grabs, in ms (no wall-clock bound: a loaded
    # machine may pause between them; speed belongs in benches/).
    skews = [1000.0 * (f.t_right - f.t_left) for f in frames]
    assert [f.skew_ms for f in frames] == pytest.approx(skews)
    assert report["max_ms"] == pytest.approx(max(skews))
    assert report["mean_ms"] == pytest.approx(sum(skews) / 12)
    assert 0.0 <= report["mean_ms"] <= report["max_ms"]


def test_videos_of_different_rates_drift_apart_once(tmp_path: Path) -> None:
    """10 fps left, 5 fps right: read in turn, the grab skew stays below a millisecond or so,
    but the media times part (pair 4 at 300 and 600 ms), more than the slower video's frame
    (200 ms): one warning naming both rates, and the pairs still come. Same rates: none."""
    left = _write_video(tmp_path / "l10.avi", [_numbered(i) for i in range(8)], fps=10.0)
    right = _write_video(tmp_path / "r5.avi", [_numbered(i, shade=160) for i in range(8)], fps=5.0)
    with pytest.warns(UserWarning) as rec:
        with StereoCamera(left, right) as cam:
            frames = list(cam.frames())
    assert len(frames) == 8 and len(rec) == 1
    assert str(rec[0].message) == (
        f"left source {str(left)!r} (10 fps) and right source {str(right)!r} (5 fps) drift "
        "apart: pair 4 is at 300 ms of the left video and 600 ms of the right, more than a "
        "frame (200 ms) from the first pair's offset; the pairs are not simultaneous (the grab "
        "skew only says when each frame was read)"
    )
    assert [f.pos_right_ms - f.pos_left_ms for f in frames[:4]] == pytest.approx([0, 100, 200, 300])
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with StereoCamera(left, left) as cam:
            assert len(list(cam.frames())) == 8
    # a video that gives no rate (OpenCV's 0): the warning said "(0 fps)", a source delivering
    # nothing; it says so as the description does
    with pytest.warns(UserWarning) as rec:
        with StereoCamera(left, right) as cam:
            cam.delivered_fps["right"] = 0.0
            assert len(list(cam.frames())) == 8
    assert len(rec) == 1
    assert str(rec[0].message).startswith(
        f"left source {str(left)!r} (10 fps) and right source {str(right)!r} (no frame rate "
        "given) drift apart: pair 3 is at 200 ms of the left video and 400 ms of the right, "
        "more than a frame (100 ms) "
    )


def test_skews_are_kept_in_bounded_memory() -> None:
    """The skews of a long run: the latest SKEW_WINDOW one by one (a sequence of float, as the
    list was), the count, mean and maximum of all exact, the median exact up to the window and
    within 0.5 % beyond; the camera reports them the same way."""
    import statistics

    rng = np.random.default_rng(5)
    values = [float(v) for v in rng.gamma(2.0, 0.2, 5000)] + [0.0, 3.5]
    stats = capmod.SkewStats()
    for v in values[:500]:
        stats.append(v)
    assert list(stats) == values[:500] and len(stats) == 500 and stats[-1] == values[499]
    assert stats.report() == {
        "n": 500,
        "mean_ms": pytest.approx(statistics.fmean(values[:500]), rel=1e-12),
        "median_ms": statistics.median(values[:500]),
        "max_ms": max(values[:500]),
    }
    for v in values[500:]:
        stats.append(v)
    assert len(stats) == capmod.SKEW_WINDOW == 1024 and list(stats) == values[-1024:]
    assert stats[:2] == values[-1024:-1022]
    rep = stats.report()
    assert rep["n"] == 5002 and rep["max_ms"] == 3.5
    assert rep["mean_ms"] == pytest.approx(statistics.fmean(values), rel=1e-12)
    assert rep["median_ms"] == pytest.approx(statistics.median(values), rel=0.005)
    assert capmod.SkewStats().report()["n"] == 0
    # The camera: 1100 pairs read, 1024 skews kept, the report over all 1100. Each fake
    # retrieve hands out a copy of one numbered frame (drawing 2200 was most of the test), and
    # only the pairs' skews are kept (the 1100 pairs' frames were 500 MB).
    frame = _numbered(0)

    class _Cap(_FakeCap):
        def retrieve(self) -> tuple[bool, np.ndarray]:
            self.log.append(f"{self.name}.retrieve")
            return True, frame.copy()

    cam = StereoCamera(_Cap("L", [], frames=2000), _Cap("R", [], frames=2000))
    skews = [cam.read().skew_ms for _ in range(1100)]
    assert len(cam.skews_ms) == 1024 and list(cam.skews_ms) == skews[76:]
    report = cam.skew_report()
    assert report["n"] == 1100 and report["max_ms"] == max(skews)
    cam.close()


def test_image_sequence_source_and_capture(tmp_path: Path) -> None:
    lpat = _write_sequence(tmp_path / "frames", "left", [_numbered(i) for i in range(7)])
    rpat = _write_sequence(
        tmp_path / "frames", "right", [_numbered(i, shade=160) for i in range(7)]
    )
    lines: list[str] = []
    with StereoCamera(lpat, rpat) as cam:
        result = capture(cam, tmp_path / "pairs", count=5, log=lines.append)
    assert len(result.saved) == 5 and result.frames_read == 5 and result.ended == "count reached"
    assert [p[0].name for p in result.saved] == [f"left_{i:04d}.png" for i in range(1, 6)]
    assert [p[1].name for p in result.saved] == [f"right_{i:04d}.png" for i in range(1, 6)]
    for k, (lp, rp) in enumerate(result.saved):
        a, b = cv2.imread(str(lp)), cv2.imread(str(rp))
        assert _read_stamp(a) == _read_stamp(b) == k
        assert np.array_equal(a, _numbered(k))  # PNG in, PNG out: lossless
    assert len(lines) == 5 and "skew" in lines[0]
    assert result.skew["n"] == 5


def test_a_camera_whose_grab_hangs_is_given_up(tmp_path: Path) -> None:
    """The right camera's grab never returning after 2 frames (a hung USB camera): capture
    waited forever. After ``read_timeout`` s it raises naming both sources, the 2 pairs saved
    kept and said."""
    lpat = _write_sequence(tmp_path / "frames", "left", [_numbered(i) for i in range(5)])
    rpat = _write_sequence(tmp_path / "frames", "right", [_numbered(i) for i in range(5)])
    unplug = threading.Event()

    class _HangsAfterTwo:
        def __init__(self, cap: Any) -> None:
            self._cap, self._grabs = cap, 0

        def grab(self) -> bool:
            self._grabs += 1
            if self._grabs > 2:
                unplug.wait()
            return bool(self._cap.grab())

        def __getattr__(self, name: str) -> Any:
            return getattr(self._cap, name)

    t0 = time.perf_counter()
    with StereoCamera(lpat, rpat) as cam:
        cam._caps["right"] = _HangsAfterTwo(cam._caps["right"])
        try:
            with pytest.raises(SourceError) as err:
                capture(cam, tmp_path / "pairs", read_timeout=0.3)
        finally:
            unplug.set()
    assert time.perf_counter() - t0 < 4.0
    assert str(err.value) == (
        f"{lpat!r} and {rpat!r} delivered no frame in 0.3 s (its read did not return: a hung "
        "or unplugged USB camera, a stalled stream); unplug and replug it; 2 pairs were saved "
        f"in {tmp_path / 'pairs'} and are kept"
    )
    assert err.value.end is False
    assert sorted(p.name for p in (tmp_path / "pairs").iterdir()) == [
        "left_0001.png", "left_0002.png", "right_0001.png", "right_0002.png"
    ]  # fmt: skip
    with pytest.raises(ValueError, match=r"read_timeout: expected a positive number of sec"):
        capture(cam, tmp_path / "p2", read_timeout=-1.0)
    # past threading's longest wait: was taken, then an OverflowError ("timestamp out of range
    # for platform time_t") out of the wait
    with pytest.raises(ValueError, match=r"^read_timeout: expected at most 9\.22337e\+09 sec"):
        capture(cam, tmp_path / "p2", read_timeout=1e10)
    assert not (tmp_path / "p2").exists()


def test_a_cli_whose_open_was_given_up_ends_on_its_one_line(tmp_path: Path) -> None:
    """``capture --read-timeout 1e-300``: the open given up, the error line said, then the
    open came back out of OpenCV while the interpreter shut down: "terminate called without an
    active exception" under the line, exit 134 (SIGABRT). The process now ends on its line."""
    import subprocess
    import sys

    lpat = _write_sequence(tmp_path / "frames", "left", [_numbered(i) for i in range(2)])
    rpat = _write_sequence(tmp_path / "frames", "right", [_numbered(i) for i in range(2)])
    argv = ["capture", "--left", lpat, "--right", rpat, "--read-timeout", "1e-300"]
    # on a loaded machine both opens (a few ms each) can finish before their waits begin: the
    # sources' sizes are then printed and a read is given up instead, which is not this test's
    # case; each such run must still end on exit 2, and a run whose open is given up is asked
    for attempt in range(5):
        proc = subprocess.run(
            [sys.executable, "-m", "stereovision", *argv, "-o", str(tmp_path / f"out{attempt}")],
            capture_output=True,
            text=True,
            check=False,
        )
        assert proc.returncode == 2, proc.stderr
        if proc.stdout == "":
            break
    assert (proc.returncode, proc.stdout) == (2, "")
    # which source, and which step of its open, is given up first is the scheduler's: on a
    # loaded machine the left one's open (a few ms) can finish before its 1e-300 s wait is even
    # begun, and then reading back its settings, or the right source, is named
    said = [
        f"stereovision: error: {side} source {pat!r} did not open within 1e-300 s ({step} did "
        "not return: a stalled stream or network share); give it a longer timeout\n"
        for side, pat in (("left", lpat), ("right", rpat))
        for step in ("its open", "reading back its settings")
    ]
    assert proc.stderr in said, proc.stderr


def test_a_grab_given_up_as_hung_keeps_its_capture_until_it_returns(tmp_path: Path) -> None:
    """A grab given up as hung stays inside OpenCV: ``close()`` released its capture under it
    and a second ``read`` grabbed it again, which crashed the process (SIGSEGV). Now the
    second read is refused, and the release waits for the grab to return; the grab's frame,
    when it comes, is dropped."""
    lpat = _write_sequence(tmp_path / "frames", "left", [_numbered(i) for i in range(3)])
    rpat = _write_sequence(tmp_path / "frames", "right", [_numbered(i) for i in range(3)])
    unplug, returned = threading.Event(), threading.Event()
    released: list[str] = []

    class _Hangs:
        def __init__(self, cap: Any, name: str) -> None:
            self._cap, self._name = cap, name

        def grab(self) -> bool:
            if self._name == "right":
                unplug.wait()
            return bool(self._cap.grab())

        def retrieve(self) -> Any:
            out = self._cap.retrieve()
            if self._name == "right":
                returned.set()
            return out

        def release(self) -> None:
            released.append(self._name)
            self._cap.release()

        def __getattr__(self, name: str) -> Any:
            return getattr(self._cap, name)

    cam = StereoCamera(lpat, rpat)
    for side in ("left", "right"):
        cam._caps[side] = _Hangs(cam._caps[side], side)
    try:
        with pytest.raises(SourceError, match=r"delivered no frame in 0\.2 s"):
            capmod.read_within(cam, 0.2)
        with pytest.raises(SourceError, match=r"an earlier read given up as hung has not returned"):
            capmod.read_within(cam, 0.2)
        cam.close()
        assert released == []  # the grab is still inside the capture
    finally:
        unplug.set()
    assert returned.wait(5.0)
    deadline = time.monotonic() + 5.0
    while len(released) < 2 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert sorted(released) == ["left", "right"]
    with pytest.raises(SourceError, match="the stereo camera is closed"):
        cam.read()


def test_a_grab_that_never_began_leaves_the_camera_usable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The grab's thread failing to start ("can't start new thread": the process out of
    threads) left the camera marked as grabbing: every later read was refused as "an earlier
    read given up as hung", and ``close()`` left the release to a grab that never ran, so the
    camera stayed open. The grab that never began is no grab: the next read reads, close
    releases."""
    lpat = _write_sequence(tmp_path / "frames", "left", [_numbered(i) for i in range(3)])
    rpat = _write_sequence(tmp_path / "frames", "right", [_numbered(i) for i in range(3)])
    released: list[str] = []

    class _Counted:
        def __init__(self, cap: Any, name: str) -> None:
            self._cap, self._name = cap, name

        def release(self) -> None:
            released.append(self._name)
            self._cap.release()

        def __getattr__(self, name: str) -> Any:
            return getattr(self._cap, name)

    class _NoThread(threading.Thread):
        def start(self) -> None:
            raise RuntimeError("can't start new thread")

    cam = StereoCamera(lpat, rpat)
    for side in ("left", "right"):
        cam._caps[side] = _Counted(cam._caps[side], side)
    with monkeypatch.context() as m:
        m.setattr(capmod.threading, "Thread", _NoThread)
        with pytest.raises(RuntimeError, match="can't start new thread"):
            capmod.read_within(cam, 1.0)
    frame = capmod.read_within(cam, 1.0)
    assert _read_stamp(frame.left) == 0  # the first pair: the grab that never ran took none
    cam.close()
    assert sorted(released) == ["left", "right"]


def test_ctrl_c_before_the_grab_began_grabs_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C while waiting for a grab whose thread has not begun yet: the read gives it up
    (the camera reads again at once) and the thread, when it runs, grabs nothing (the next
    read gets the first pair, not the second)."""
    lpat = _write_sequence(tmp_path / "frames", "left", [_numbered(i) for i in range(3)])
    rpat = _write_sequence(tmp_path / "frames", "right", [_numbered(i) for i in range(3)])
    gate = threading.Event()
    late: list[threading.Thread] = []

    class _LateThread(threading.Thread):
        def run(self) -> None:
            gate.wait()
            super().run()

        def start(self) -> None:
            late.append(self)
            super().start()

    class _Interrupted(threading.Event):
        def wait(self, timeout: float | None = None) -> bool:
            if timeout is None:  # Thread.start's own wait
                return super().wait()
            raise KeyboardInterrupt  # the read's wait for the grab

    cam = StereoCamera(lpat, rpat)
    try:
        with monkeypatch.context() as m:
            m.setattr(capmod.threading, "Thread", _LateThread)
            m.setattr(capmod.threading, "Event", _Interrupted)
            with pytest.raises(KeyboardInterrupt):
                capmod.read_within(cam, 1.0)
        gate.set()
        late[0].join(5.0)
        assert not late[0].is_alive()
        assert _read_stamp(capmod.read_within(cam, 1.0).left) == 0
    finally:
        gate.set()
        cam.close()


def test_an_interrupt_before_the_grab_began_does_not_wait_for_it_to_grab(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C while the grab's thread has started but not yet begun the grab: the interrupt's
    wait for a grab under way (_INTERRUPT_GRACE_S) let that thread begin and grab a pair,
    which was lost (the next read got the second pair). A grab not begun is given up before
    the wait, as it was before the wait came in."""
    lpat = _write_sequence(tmp_path / "frames", "left", [_numbered(i) for i in range(3)])
    rpat = _write_sequence(tmp_path / "frames", "right", [_numbered(i) for i in range(3)])
    gate = threading.Event()
    opens = threading.Timer(0.3, gate.set)  # the late thread goes on within the grace wait
    late: list[threading.Thread] = []

    class _LateThread(threading.Thread):
        def run(self) -> None:
            gate.wait()
            super().run()

        def start(self) -> None:
            late.append(self)
            super().start()

    interrupted: list[bool] = []

    class _InterruptedOnce(threading.Event):
        def wait(self, timeout: float | None = None) -> bool:
            if timeout is not None and not interrupted:  # the read's wait for the grab
                interrupted.append(True)
                opens.start()
                raise KeyboardInterrupt
            return super().wait(timeout)  # Thread.start's, and the grace wait

    cam = StereoCamera(lpat, rpat)
    try:
        with monkeypatch.context() as m:
            m.setattr(capmod.threading, "Thread", _LateThread)
            m.setattr(capmod.threading, "Event", _InterruptedOnce)
            t0 = time.monotonic()
            with pytest.raises(KeyboardInterrupt):
                capmod.read_within(cam, 5.0)
            waited = time.monotonic() - t0
        gate.set()
        late[0].join(5.0)
        assert not late[0].is_alive()
        assert _read_stamp(capmod.read_within(cam, 1.0).left) == 0
        assert waited < 0.2
    finally:
        gate.set()
        opens.cancel()
        cam.close()


def test_an_interrupt_while_a_grab_starts_lets_the_grab_come_back(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Ctrl-C landing while the grab's thread starts: the interrupt went on at once, the grab
    came back out of OpenCV while the interpreter shut down, and the process aborted (SIGABRT,
    exit -6 instead of 130, in 2 of 12 interrupted captures). The interrupt now waits for it."""
    came_back = threading.Event()

    def grab() -> int:
        time.sleep(0.2)
        came_back.set()
        return 1

    real_start = threading.Thread.start

    def start_then_interrupted(self: threading.Thread) -> None:
        real_start(self)
        raise KeyboardInterrupt

    monkeypatch.setattr(threading.Thread, "start", start_then_interrupted)
    with pytest.raises(KeyboardInterrupt):
        capmod._within(grab, 5.0, "camera 0 and camera 1")
    assert came_back.is_set()
    monkeypatch.setattr(threading.Thread, "start", real_start)
    with pytest.raises(SourceError, match=r"^camera 0 and camera 1 delivered no frame in 0\.05 s"):
        capmod._within(lambda: time.sleep(1.0), 0.05, "camera 0 and camera 1")


def test_a_gap_in_an_image_sequence_is_said(tmp_path: Path) -> None:
    """Pair 3 deleted from both numbered sequences (a blurred pair taken out): the capture
    stops there and says the images after the gap were not read (it said "end of stream", the
    4 pairs after it silently left out)."""
    frames = tmp_path / "frames"
    lpat = _write_sequence(frames, "left", [_numbered(i) for i in range(8)])
    rpat = _write_sequence(frames, "right", [_numbered(i, shade=160) for i in range(8)])
    for side in ("left", "right"):
        (frames / f"{side}_003.png").unlink()
    with StereoCamera(lpat, rpat) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 3
    assert result.ended == "; ".join(
        f"{side} source {pat!r} ended after 3 images: {side}_003.png is missing, so the 4 "
        "images numbered after it were not read (renumber them without the gap)"
        for side, pat in (("left", lpat), ("right", rpat))
    )
    (frames / "right_004.png").rename(frames / "right_003.png")  # no image after the gap
    for side in ("left", "right"):
        for i in range(4, 8):
            (frames / f"{side}_{i:03d}.png").unlink(missing_ok=True)
    (frames / "left_003.png").write_bytes((frames / "right_003.png").read_bytes())
    with StereoCamera(lpat, rpat) as cam:
        assert capture(cam, tmp_path / "more").ended == "end of stream"


def test_image_sequence_frames_keep_their_own_size(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A pattern is read by OpenCV's image reader: a frame of another size comes at its own size
    (FFmpeg's reader stretched a 300x300 frame of a 384x288 sequence to 384x288 unseen), so a
    frame of another shape stops the pairs and one of another size of the same shape is
    resized with a warning. Its end logs nothing."""
    frames = [_numbered(i) for i in range(6)]
    frames[3] = _numbered(3, (100, 100))
    lpat = _write_sequence(tmp_path / "odd", "left", frames)
    rpat = _write_sequence(tmp_path / "odd", "right", [_numbered(i) for i in range(6)])
    with StereoCamera(lpat, rpat) as cam:
        assert [cam.read().left.shape for _ in range(3)] == [(240, 320, 3)] * 3
        with pytest.raises(SourceError) as ei:
            cam.read()
    assert str(ei.value) == (
        f"left source {lpat!r} delivers 100x100 in pair 4, after 3 pairs of 320x240: a frame "
        "of another shape cannot be paired without stretching it"
    )
    assert (ei.value.side, ei.value.end, ei.value.frames) == ("left", False, 3)
    frames[3] = cv2.resize(_numbered(3), (160, 120), interpolation=cv2.INTER_AREA)  # half size
    lpat = _write_sequence(tmp_path / "half", "left", frames)
    rpat = _write_sequence(tmp_path / "half", "right", [_numbered(i) for i in range(6)])
    capfd.readouterr()
    with pytest.warns(UserWarning, match=r"delivers 160x120, not 320x240: its frames are resized"):
        with StereoCamera(lpat, rpat) as cam:
            got = list(cam.frames())
            assert cam.delivered_fps == {"left": 0.0, "right": 0.0}  # a sequence has no rate
    assert len(got) == 6 and got[3].left.shape == (240, 320, 3)
    assert [_read_stamp(f.left) for f in got] == list(range(6))
    assert capfd.readouterr().err == ""  # OpenCV's warning for the file after the last is quiet
    # A sequence starting at 2-4 (FFmpeg's image2 looks at 0-4) opens from its first file.
    for first in (2, 4):
        late = tmp_path / f"late{first}"
        late.mkdir()
        for i in range(first, 5):
            cv2.imwrite(str(late / f"f_{i:03d}.png"), _numbered(i))
        with StereoCamera(str(late / "f_%03d.png"), str(late / "f_%03d.png")) as cam:
            got = list(cam.frames())
            # read by OpenCV's image reader, as a sequence from 0 or 1 (no media time, no rate)
            assert cam.delivered_fps == {"left": 0.0, "right": 0.0}
        assert [_read_stamp(f.left) for f in got] == list(range(first, 5))
        assert all(math.isnan(f.pos_left_ms) for f in got)


class _FakeCap:
    """A VideoCapture stand-in that logs calls into a shared list."""

    def __init__(self, name: str, log: list[str], frames: int = 3, opened: bool = True) -> None:
        self.name, self.log, self.left, self.opened = name, log, frames, opened
        self.released = 0

    def isOpened(self) -> bool:
        return self.opened

    def grab(self) -> bool:
        self.log.append(f"{self.name}.grab")
        self.left -= 1
        return self.left >= 0

    def retrieve(self) -> tuple[bool, np.ndarray]:
        self.log.append(f"{self.name}.retrieve")
        return True, _numbered(0)

    def get(self, prop: int) -> float:
        return {cv2.CAP_PROP_FRAME_WIDTH: SMALL[0], cv2.CAP_PROP_FRAME_HEIGHT: SMALL[1]}.get(
            prop, 0.0
        )

    def set(self, prop: int, value: float) -> bool:
        self.log.append(f"{self.name}.set")
        return False

    def release(self) -> None:
        self.released += 1


def test_grab_both_then_retrieve_both() -> None:
    log: list[str] = []
    cam = StereoCamera(_FakeCap("L", log), _FakeCap("R", log))
    cam.read()
    assert log == ["L.grab", "R.grab", "L.retrieve", "R.retrieve"]
    cam.close()


class _FormatCap(_FakeCap):
    """A webcam stand-in with V4L2's habit: it offers sizes per pixel format, so it logs each
    property set in order and keeps the format only if it has it."""

    def __init__(self, name: str, log: list[str], formats: tuple[str, ...]) -> None:
        super().__init__(name, log)
        self.formats = formats
        self.fourcc = cv2.VideoWriter.fourcc(*formats[0])

    def get(self, prop: int) -> float:
        return float(self.fourcc) if prop == cv2.CAP_PROP_FOURCC else super().get(prop)

    def set(self, prop: int, value: float) -> bool:
        self.log.append(f"{self.name}.set {prop}")
        if prop == cv2.CAP_PROP_FOURCC and fourcc_text(value) in self.formats:
            self.fourcc = int(value)
            return True
        return False


def test_pixel_format_asked_first_and_reported() -> None:
    log: list[str] = []
    caps = [_FormatCap(n, log, ("YUYV", "MJPG")) for n in "LR"]
    cam = StereoCamera(*caps, image_size=(320, 240), fps=30, fourcc="MJPG")
    # The format before the size and the rate (the camera's sizes depend on it), for each side.
    assert log == [
        f"{n}.set {p}"
        for n in "LR"
        for p in (cv2.CAP_PROP_FOURCC, cv2.CAP_PROP_FRAME_WIDTH, cv2.CAP_PROP_FRAME_HEIGHT,
                  cv2.CAP_PROP_FPS)
    ]  # fmt: skip
    assert cam.delivered_fourcc == {"left": "MJPG", "right": "MJPG"}
    assert cam.describe().startswith("asked 320x240 MJPG;")
    assert cam.describe().endswith("format left MJPG, right MJPG")
    cam.close()
    # Not asked: nothing set, the camera's own format reported.
    log.clear()
    cam = StereoCamera(*(_FormatCap(n, log, ("YUYV",)) for n in "LR"))
    assert log == [] and cam.delivered_fourcc == {"left": "YUYV", "right": "YUYV"}
    cam.close()


def test_pixel_format_refused_is_named() -> None:
    log: list[str] = []
    caps = [_FormatCap("L", log, ("YUYV", "MJPG")), _FormatCap("R", log, ("YUYV",))]
    with pytest.warns(UserWarning, match=r"right source .* delivers 'YUYV', not 'MJPG'") as rec:
        cam = StereoCamera(*caps, fourcc="MJPG")
    assert len(rec) == 1 and cam.delivered_fourcc == {"left": "MJPG", "right": "YUYV"}
    cam.close()
    with pytest.warns(UserWarning, match="delivers no reported format, not 'YUYV'"):
        StereoCamera(_FakeCap("L", log), _FakeCap("R", log), fourcc="YUYV").close()


class _RateCap(_FakeCap):
    """A webcam stand-in that keeps a frame rate asked of it only among the ones it has (V4L2
    answers a rate it cannot give with its nearest), and reports its rate."""

    def __init__(self, name: str, rates: tuple[float, ...]) -> None:
        super().__init__(name, [])
        self.rates, self.fps = rates, rates[0]

    def get(self, prop: int) -> float:
        return self.fps if prop == cv2.CAP_PROP_FPS else super().get(prop)

    def set(self, prop: int, value: float) -> bool:
        if prop == cv2.CAP_PROP_FPS:
            self.fps = min(self.rates, key=lambda r: abs(r - value))
        return super().set(prop, value)


def test_a_frame_rate_the_camera_does_not_give_is_said() -> None:
    """``--fps 60`` of a webcam that gives 30 at that size streamed at 30 without a word (the
    size and the format asked are said when not given; stream prints no describe() line, and
    capture's says no rate asked). One warning per side that reports another rate; none for a
    rate given (within 1 %: V4L2's 29.97 for 30), for a camera reporting none (0), or for a file,
    which is read as it is."""
    with pytest.warns(UserWarning) as rec:
        cam = StereoCamera(_RateCap("L", (30.0, 15.0)), _RateCap("R", (60.0, 30.0)), fps=60)
    assert [str(w.message) for w in rec] == [
        "left source _RateCap reports 30 fps, not the 60 fps asked (a rate this camera does "
        "not give at this size and format?)"
    ]
    assert rec[0].filename == __file__  # said at the caller's line
    assert cam.delivered_fps == {"left": 30.0, "right": 60.0}
    cam.close()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        StereoCamera(_RateCap("L", (29.97,)), _RateCap("R", (30.0,)), fps=30).close()
        StereoCamera(_FakeCap("L", []), _FakeCap("R", []), fps=60).close()  # reports no rate
        StereoCamera(_RateCap("L", (30.0,)), _RateCap("R", (30.0,))).close()  # none asked


def test_a_frame_rate_asked_of_a_file_is_not_said(tmp_path: Path) -> None:
    """A video file is read as it is (``--fps`` asks the cameras): no warning for its rate."""
    left = _write_video(tmp_path / "l.avi", [_numbered(i) for i in range(2)], fps=10.0)
    right = _write_video(tmp_path / "r.avi", [_numbered(i) for i in range(2)], fps=10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with StereoCamera(left, right, fps=30) as cam:
            assert cam.delivered_fps == {"left": 10.0, "right": 10.0}


def test_a_frame_rate_asked_of_an_http_url_is_not_said(monkeypatch: pytest.MonkeyPatch) -> None:
    """An ``http(s)://`` URL may name a video file (a live stream ends only for the other
    schemes, 20c7f0a): ``--fps 30`` of one warned "a rate this camera does not give". It is
    read as it is, as a file; an ``rtsp://`` camera's other rate is still said."""
    from stereovision import capture as capmod

    class _UrlCap(_RateCap):  # a URL's capture reports its backend, as OpenCV's do
        def getBackendName(self) -> str:
            return "FFMPEG"

    monkeypatch.setattr(capmod, "_open_path", lambda path, first: _UrlCap(path, (25.0,)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        StereoCamera("http://host/l.mp4", "HTTPS://host/r.mp4", fps=30).close()
    with pytest.warns(UserWarning) as rec:
        StereoCamera("https://host/l.mp4", "rtsp://cam/0", fps=30).close()
    assert [str(w.message) for w in rec] == [
        "right source 'rtsp://cam/0' reports 25 fps, not the 30 fps asked (a rate this camera "
        "does not give at this size and format?)"
    ]


def test_fourcc_codes() -> None:
    assert parse_fourcc(None) is None and parse_fourcc("Y800") == "Y800"
    for bad in ("MJPEG", "YUV", "", "MJ\tG", 1196444237):
        with pytest.raises(ValueError, match="four characters such as 'MJPG'"):
            parse_fourcc(bad)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="fourcc"):
        StereoCamera(_FakeCap("L", []), _FakeCap("R", []), fourcc="mjpeg")
    assert fourcc_text(cv2.VideoWriter.fourcc(*"YUYV")) == "YUYV"
    assert fourcc_text(1196444237.0) == "MJPG"  # what OpenCV reports for a V4L2 MJPG stream
    assert fourcc_text(0.0) == fourcc_text(-1.0) == fourcc_text(float("nan")) == ""
    assert fourcc_text(7.0) == ""  # unprintable bytes are not a format


def test_frames_of_another_shape_are_not_stretched(tmp_path: Path) -> None:
    """Asked 16:9 of a 4:3 source: the frames stay 4:3 at their own size (one warning), as a
    resize would stretch them and every calibration made of them; a right source of another
    shape than the left's is refused."""
    left, right = _videos(tmp_path, 3, 3, size=(160, 120))
    with pytest.warns(UserWarning, match=r"delivers 160x120, not 320x180: another shape") as rec:
        with StereoCamera(left, right, image_size=(320, 180)) as cam:
            frame = cam.read()
            assert cam.size == (160, 120)
    assert len(rec) == 1  # the right source then matches the size kept
    assert frame.left.shape == frame.right.shape == (120, 160, 3)
    wide = _write_video(tmp_path / "wide.avi", [_numbered(i, (160, 90)) for i in range(3)])
    with StereoCamera(left, wide) as cam:
        with pytest.raises(SourceError, match=r"right source .* delivers 160x90, the left "
                           r"source 160x120: frames of another shape"):  # fmt: skip
            cam.read()


def test_resolution_request_and_resize_warning(tmp_path: Path) -> None:
    left, right = _videos(tmp_path, 3, 3, size=(160, 120))
    with pytest.warns(UserWarning, match=r"delivers 160x120, not 320x240") as rec:
        with StereoCamera(left, right, image_size=(320, 240), fps=30) as cam:
            frame = cam.read()
            cam.read()
            assert cam.delivered_size == {"left": (160, 120), "right": (160, 120)}
            assert "asked 320x240" in cam.describe() and "160x120" in cam.describe()
    assert len(rec) == 2  # one warning per camera, not per frame
    assert frame.left.shape == (240, 320, 3) and frame.right.shape == (240, 320, 3)
    assert _read_stamp(frame.left) == 0
    # Asking for the size a source gives: no warning, no resize.
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with StereoCamera(left, right, image_size="160x120") as cam:
            assert cam.read().left.shape == (120, 160, 3)
    assert parse_size("1280x720") == (1280, 720)
    assert parse_size(" 640X480 ") == (640, 480)  # an upper-case X and spaces are taken
    for bad in ("big", "0x5", "12x"):
        with pytest.raises(ValueError, match="WIDTHxHEIGHT"):
            parse_size(bad)
    assert parse_size("16384x8640") == (16384, 8640)
    assert parse_size((640, 480)) == parse_size([640.0, np.int64(480)]) == (640, 480)
    for bad in (
        (640.7, 480),
        (True, 480),
        (640,),
        (640, 480, 3),
        640,
        (640, float("nan")),
        np.array(640),
        np.ones((2, 2)),
        ((640, 1), 480),
    ):
        with pytest.raises(ValueError, match="WIDTHxHEIGHT"):  # 640.7 was cut, True taken as 1
            parse_size(bad)
    with pytest.raises(ValueError, match="at most 16384 px per side, got 100000x100000"):
        parse_size("100000x100000")
    assert parse_source("0") == 0 and parse_source("a.avi") == "a.avi"


def test_open_failures_name_the_source(tmp_path: Path) -> None:
    left, _ = _videos(tmp_path, 2, 2)
    with pytest.raises(FileNotFoundError, match=r"right source not found: .*missing\.avi"):
        StereoCamera(left, tmp_path / "missing.avi")
    pattern = str(tmp_path / "none_%03d.png")
    with pytest.raises(FileNotFoundError, match=r"left source: no file matches .*none_%03d\.png"):
        StereoCamera(pattern, left)
    log: list[str] = []
    good = _FakeCap("L", log)
    with pytest.raises(SourceError, match="cannot open right source _FakeCap"):
        StereoCamera(good, _FakeCap("R", log, opened=False))
    assert good.released == 1  # the camera opened first is released
    for fps in (-1, 0, float("nan"), float("inf"), True, "30"):
        with pytest.raises(ValueError, match=r"^fps: expected a positive number"):
            StereoCamera(left, left, fps=fps)
    assert issubclass(SourceError, OSError)


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX file names are bytes")
def test_a_source_whose_name_is_not_utf8_is_refused_not_a_crash(tmp_path: Path) -> None:
    """A video or image sequence whose name holds a byte that is not UTF-8 (a Latin-1 0xFF,
    os.fsdecode's lone surrogate) crashed the process in OpenCV's argument conversion
    (SIGSEGV, exit 139, not a word): it is refused, named, before OpenCV sees it."""
    left, right = _videos(tmp_path, 2, 2)
    odd = tmp_path / os.fsdecode(b"l\xff.avi")
    left.rename(odd)
    folder = Path(_write_sequence(tmp_path / "seq", "right", [_numbered(0)])).parent
    seq = folder.rename(tmp_path / os.fsdecode(b"s\xff")) / "right_%03d.png"
    why = "its name holds a byte that is not UTF-8, which OpenCV cannot take; rename it, or "
    why += "give a link to it with a UTF-8 name"
    with pytest.raises(SourceError) as info:
        StereoCamera(odd, right)
    assert str(info.value) == f"cannot open left source {str(odd)!r}: {why}"
    assert (info.value.side, info.value.end) == ("left", False)
    with pytest.raises(SourceError) as info:
        StereoCamera(right, seq)
    assert str(info.value) == f"cannot open right source {str(seq)!r}: {why}"
    with pytest.raises(SourceError, match=r"^cannot open source .*: its name holds a byte"):
        capmod._open_path(str(seq), (0, str(seq)))  # the GUI's opener too
    (tmp_path / "l.avi").symlink_to(odd)  # the advice works
    with StereoCamera(tmp_path / "l.avi", right) as cam:
        assert cam.read().left.shape == (SMALL[1], SMALL[0], 3)


def test_a_second_capture_on_one_camera_reports_its_own_pairs(tmp_path: Path) -> None:
    """A camera kept open for captures one after another (a pair per pose of a script) had
    each result say the camera's pairs since its open: the second capture of 3 pairs said
    frames_read 6 and a skew over 6 pairs. Each capture says its own."""
    left, right = _videos(tmp_path, 10, 10)
    out = tmp_path / "pairs"
    with StereoCamera(left, right) as cam:
        first = capture(cam, out, count=3)
        second = capture(cam, out, count=3)
        rest = capture(cam, out)
    assert (first.frames_read, first.skew["n"]) == (3, 3)
    assert (second.frames_read, second.skew["n"]) == (3, 3)
    assert (rest.frames_read, rest.skew["n"], len(rest.saved)) == (4, 4, 4)
    assert rest.ended == "end of stream"
    assert math.isfinite(second.skew["mean_ms"]) and second.skew["max_ms"] >= 0


def test_disconnect_mid_run_keeps_saved_pairs(tmp_path: Path) -> None:
    left, right = _videos(tmp_path, 10, 4)
    out = tmp_path / "pairs"
    with StereoCamera(left, right) as cam:
        with pytest.raises(SourceError) as ei:
            capture(cam, out, count=8)
    assert str(ei.value) == (
        f"right source {str(right)!r} ended after 4 frames; the left source still had frames; "
        f"4 of 8 pairs were saved in {out} and are kept"
    )
    assert (ei.value.side, ei.value.end, ei.value.frames) == ("right", True, 4)
    assert ei.value.other_had_frames and ei.value.expected_frames is None
    names = sorted(p.name for p in out.iterdir())
    assert names == [f"{s}_{i:04d}.png" for s in ("left", "right") for i in range(1, 5)]
    for i in range(1, 5):
        assert _read_stamp(cv2.imread(str(out / f"left_{i:04d}.png"))) == i - 1
    # Without --count the end of a source ends the capture, said as it is (the right video
    # ended, the left one had more); numbering continues.
    with StereoCamera(left, right) as cam:
        result = capture(cam, out, every=2)
    assert result.ended == (
        f"right source {str(right)!r} ended after 4 frames; the left source still had frames"
    )
    assert result.frames_read == 4
    assert [p[0].name for p in result.saved] == ["left_0005.png", "left_0006.png"]
    assert [_read_stamp(cv2.imread(str(p[0]))) for p in result.saved] == [0, 2]
    # The left one shorter: named the same way; both ending together is a plain end.
    with StereoCamera(right, left) as cam:
        assert capture(cam, tmp_path / "p2").ended == (
            f"left source {str(right)!r} ended after 4 frames; the right source still had frames"
        )
    with StereoCamera(left, left) as cam:
        with pytest.raises(SourceError, match=r"^both sources ended after 10 frames; 10 of 11 "):
            capture(cam, tmp_path / "p3", count=11)
    with StereoCamera(left, left) as cam:
        assert capture(cam, tmp_path / "p4").ended == "end of stream"


def test_truncated_video_is_named_and_its_last_pair_too(tmp_path: Path) -> None:
    """A video cut at 60 % of its bytes: 11 of the 20 frames its header announces are read, the
    end says the file ended early and which saved pair holds its last (maybe half-decoded)
    frame. A frame of another shape stops the capture with an error, not as an end."""
    left, right = _videos(tmp_path, 20, 20)
    data = left.read_bytes()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: len(data) * 6 // 10])
    with StereoCamera(cut, right) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == result.frames_read == 11
    assert result.ended == (
        f"left source {str(cut)!r} ended after 11 of the 20 frames its header announces: the "
        "file ended early (likely truncated or damaged; its last frame, in pair 11, may be "
        "incomplete); the right source still had frames; that pair was saved as "
        "left_0011.png, right_0011.png"
    )
    with StereoCamera(cut, right) as cam:
        with pytest.raises(SourceError) as ei:
            for _ in range(12):
                cam.read()
    assert (ei.value.side, ei.value.frames, ei.value.expected_frames) == ("left", 11, 20)
    assert ei.value.ended_early and ei.value.end
    # Both cut: both named.
    with StereoCamera(cut, cut) as cam:
        both = capture(cam, tmp_path / "both", every=100)
    assert both.ended.count("ended after 11 of the 20 frames its header announces") == 2
    assert both.ended.startswith("left source") and "; right source" in both.ended
    # A sequence whose frame 3 has another shape: an error even without a count.
    frames = [_numbered(i) for i in range(6)]
    frames[3] = _numbered(3, (100, 100))
    lpat = _write_sequence(tmp_path / "odd", "left", frames)
    rpat = _write_sequence(tmp_path / "odd", "right", [_numbered(i) for i in range(6)])
    with StereoCamera(lpat, rpat) as cam:
        with pytest.raises(SourceError, match=r"delivers 100x100 in pair 4, .*; 3 pairs were "):
            capture(cam, tmp_path / "odd_pairs")
        with pytest.raises(SourceError, match="closed"):
            cam.close()
            capture(cam, tmp_path / "odd_pairs")
    assert len(list((tmp_path / "odd_pairs").glob("right_*.png"))) == 3


# -------------------------------------------------------------------------------- saving


def test_atomic_pair_writes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "pairs"
    img = _numbered(7, (640, 480))
    real_link = os.link
    seen: list[tuple[str, str]] = []

    def checked_link(src: Any, dst: Any) -> None:
        src, dst = Path(src), Path(dst)
        assert src.parent == dst.parent  # same directory: a link, never a copy
        assert src.name.startswith(".") and src.name.endswith(".tmp")
        assert not dst.exists()  # the final name appears only complete
        assert cv2.imread(str(src)) is not None  # temp file complete before the link
        seen.append((src.name, dst.name))
        real_link(src, dst)

    monkeypatch.setattr(os, "link", checked_link)
    lp, rp = save_pair(out, 1, img, img)
    assert [d for _, d in seen] == ["left_0001.png", "right_0001.png"]  # right last
    assert np.array_equal(cv2.imread(str(lp)), img) and np.array_equal(cv2.imread(str(rp)), img)
    monkeypatch.setattr(os, "link", real_link)

    # A write failing half-way leaves no partial or temporary file.
    calls = {"n": 0}
    real_fsync = os.fsync

    def failing_fsync(fd: int) -> None:
        calls["n"] += 1
        if calls["n"] == 2:
            raise OSError("disk full")
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", failing_fsync)
    with pytest.raises(OSError, match="disk full"):
        save_pair(out, 2, img, img)
    monkeypatch.setattr(os, "fsync", real_fsync)
    names = sorted(p.name for p in out.iterdir())
    assert names == ["left_0001.png", "right_0001.png"]  # no left_0002.png alone
    assert next_pair_index(out) == 2
    with pytest.raises(ValueError, match="encode"):
        save_pair(out, 3, img, img, ext=".nope")


def test_a_disk_that_fills_mid_capture_names_the_file_and_the_pairs_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """An output disk that fills up (a robot's SD card) said "[Errno 28] No space left on
    device" alone, out of capture and `stereovision capture`: neither the file nor the pairs
    saved before. The file is named, and the pairs kept are said as for a source's failure."""
    import errno

    from stereovision.cli import main

    left, right = _videos(tmp_path, 6, 6)
    out = tmp_path / "pairs"
    real_fsync, calls = os.fsync, [0]

    def full_after_two_pairs(fd: int) -> None:
        calls[0] += 1
        if calls[0] > 4:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", full_after_two_pairs)
    with StereoCamera(left, right) as cam, pytest.raises(OSError) as ei:
        capture(cam, out, count=5)
    assert str(ei.value) == (
        f"cannot write {out / 'left_0003.png'}: No space left on device; "
        f"2 of 5 pairs were saved in {out} and are kept"
    )
    assert ei.value.errno == errno.ENOSPC
    calls[0] = 0
    with StereoCamera(left, right) as cam, pytest.raises(OSError) as ei:
        capture(cam, out)  # without a count: the pairs saved by this capture
    assert str(ei.value).endswith(
        f"left_0005.png: No space left on device; 2 pairs were saved in {out} and are kept"
    )
    names = sorted(p.name for p in out.iterdir())  # whole pairs, no temporary file
    assert names == [f"{s}_{i:04d}.png" for s in ("left", "right") for i in range(1, 5)]
    # the CLI's one line says it too
    calls[0] = 0
    capsys.readouterr()
    assert main(["capture", "--left", str(left), "--right", str(right), "-o", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: cannot write {out / 'left_0007.png'}: No space left on device; "
        f"2 pairs were saved in {out} and are kept\n"
    )


def test_an_extension_that_is_no_image_formats_is_refused_before_any_read(
    tmp_path: Path,
) -> None:
    """capture(ext="png") (no dot) read the camera's first pair, then said "cannot encode the
    left image as png"; ext="/x.png" wrote below the folder and ".png " saved names the
    numbering does not read. Refused before any read, nothing made."""
    left, right = _videos(tmp_path, 4, 4)
    out = tmp_path / "pairs"
    img = _numbered(1)
    for ext in ("png", "", "/x.png", ".png ", "../x", None):
        words = f"ext: expected an image format's extension such as '.png', got {ext!r}"
        with StereoCamera(left, right) as cam:
            with pytest.raises(ValueError) as ei:
                capture(cam, out, ext=ext)  # type: ignore[arg-type]
            assert str(ei.value) == words and cam.count == 0
        with pytest.raises(ValueError) as ei:
            save_pair(out, 1, img, img, ext=ext)  # type: ignore[arg-type]
        assert str(ei.value) == words
    with StereoCamera(left, right) as cam, pytest.raises(ValueError) as ei:
        capture(cam, out, ext=".nope")
    assert str(ei.value) == "ext: cannot encode images as .nope: OpenCV has no writer for it"
    assert cam.count == 0 and not out.exists()
    with StereoCamera(left, right) as cam:  # any case of a format's extension is one
        assert [p.name for p in capture(cam, out, count=1, ext=".JPG").saved[0]] == [
            "left_0001.JPG",
            "right_0001.JPG",
        ]


def test_an_image_the_format_cannot_hold_is_refused_not_saved_as_8_bits(tmp_path: Path) -> None:
    """save_pair of a float image in [0, 1] wrote it as 8 bits, 0 and 1 (a black picture), and
    a 16-bit one as .jpg clipped to white, without a word: refused now, nothing written; a
    format that holds the type keeps it (and is the one advised: a float32 image as .png was
    told to become uint8)."""
    img = _numbered(1)
    for bad, ext, advice in (
        (img.astype(np.float32) / 255, ".png", ".tiff holds float32"),
        (img.astype(np.uint16) * 257, ".jpg", ".png and .tiff hold uint16"),
        (img > 100, ".png", "convert it to uint8 first (True as 255)"),
    ):  # fmt: skip
        with pytest.raises(ValueError) as ei:
            save_pair(tmp_path, 1, img, bad, ext=ext)
        assert str(ei.value) == (
            f"cannot save the right image ({bad.dtype}) as {ext} without loss: that format "
            f"would write it as 8 bits; {advice}"
        )
    # .hdr writes float32 whatever it is given: a 16-bit image was said "written as 8 bits",
    # and uint8 advised, which .hdr writes as float32 too
    for bad, holders in (
        (img.astype(np.uint16) * 257, ".png and .tiff hold"),
        (img.astype(np.float64) / 255, ".tiff holds"),
    ):
        with pytest.raises(ValueError) as ei:
            save_pair(tmp_path, 1, img, bad, ext=".hdr")
        assert str(ei.value) == (
            f"cannot save the right image ({bad.dtype}) as .hdr without loss: that format "
            f"would write it as float32; {holders} {bad.dtype}"
        )
    assert list(tmp_path.iterdir()) == []
    deep = img.astype(np.uint16) * 257
    for kept, ext in ((deep, ".png"), (img.astype(np.float32) / 255, ".tiff"), (img, ".jpg")):
        lp, _ = save_pair(tmp_path, next_pair_index(tmp_path), kept, kept, ext=ext)
        assert cv2.imread(str(lp), cv2.IMREAD_UNCHANGED).dtype == kept.dtype


@pytest.mark.parametrize("ext", [".png", ".jpg", ".tiff", ".hdr", ".pfm"])
def test_save_pairs_advice_names_a_format_that_holds_the_type(tmp_path: Path, ext: str) -> None:
    """save_pair's advice for each type a format refuses: a float16 or bool image as .hdr was
    told ".tiff holds float16" (".tiff holds bool"), which .tiff writes as 8 bits; a uint16 one
    as .jpg, int16 as .png, to convert it to uint8 "(a float image in [0, 1]: times 255)",
    though .png (.tiff) holds it. Every format it names holds the type, and every conversion
    it advises saves in the format asked (or the one named)."""
    img = _numbered(1)[:8, :8]
    said = {}
    for dtype in (np.int8, np.uint16, np.int16, np.int32, np.int64, np.float16, np.float32,
                  np.float64, np.bool_):  # fmt: skip
        bad = img.astype(dtype)
        try:
            lp, _ = save_pair(tmp_path / np.dtype(dtype).name, 0, bad, bad, ext=ext)
        except ValueError as exc:
            said[np.dtype(dtype).name] = advice = str(exc).split("; ", 1)[1]
        else:  # kept (.tiff), or float32 as .hdr / .pfm write every image
            assert cv2.imread(str(lp), cv2.IMREAD_UNCHANGED).dtype in (dtype, np.float32)
            continue
        held = re.fullmatch(r"(\.\w+)(?: and (\.\w+))? holds? (\w+)", advice)
        if held:
            for fmt in filter(None, held.groups()[:2]):
                out = tmp_path / fmt
                lp, _ = save_pair(out, next_pair_index(out), bad, bad, ext=fmt)
                assert cv2.imread(str(lp), cv2.IMREAD_UNCHANGED).dtype == dtype, (fmt, dtype)
            continue
        to = re.match(r"convert it to (\w+)", advice)
        assert to, advice
        fmt = ".tiff" if ".tiff holds" in advice else ext
        good = bad.astype(to[1])
        save_pair(tmp_path / "conv", next_pair_index(tmp_path / "conv"), good, good, ext=fmt)
    if ext in (".hdr", ".pfm"):
        assert said["float16"] == "convert it to float32 first (no loss)"
        assert said["bool"] == "convert it to uint8 first (True as 255)"
    if ext in (".png", ".jpg"):
        # a float32 image was told to become uint8 (256 levels), where .tiff keeps it
        assert said["float32"] == ".tiff holds float32"
        assert said["float64"] == ".tiff holds float64"
        assert said["float16"] == "convert it to float32 first (.tiff holds float32)"
    if ext == ".jpg":
        assert said["uint16"] == ".png and .tiff hold uint16"
        assert said["int16"] == ".tiff holds int16"
    if ext == ".tiff":
        assert said == {
            "int64": "convert it to int32 or float64 first",
            "float16": "convert it to float32 first (.tiff holds float32)",
            "bool": "convert it to uint8 first (True as 255)",
        }


@pytest.mark.parametrize("where", ["fdopen", "write", "fsync", "link"])
def test_interrupted_pair_save_leaves_no_temp_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, where: str
) -> None:
    """KeyboardInterrupt (SIGTERM in the CLI) at any step after the temporary file exists:
    it is removed, and no final name appears for the image being written."""
    img = _numbered(1)
    real = {"fdopen": os.fdopen, "fsync": os.fsync, "link": os.link}

    def interrupt(*args: Any, **kwargs: Any) -> Any:
        raise KeyboardInterrupt

    if where == "write":

        class _File:
            def __init__(self, fd: int, mode: str) -> None:
                self.fh = real["fdopen"](fd, mode)

            def __enter__(self) -> _File:
                return self

            def __exit__(self, *exc: object) -> None:
                self.fh.close()

            def write(self, data: bytes) -> int:
                self.fh.write(data[: len(data) // 2])
                raise KeyboardInterrupt

        monkeypatch.setattr(os, "fdopen", _File)
    else:
        monkeypatch.setattr(os, where, interrupt)
    with pytest.raises(KeyboardInterrupt):
        save_pair(tmp_path, 1, img, img)
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_pair_that_cannot_be_put_in_place_names_its_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without hard links (FAT), the rename putting the left image in place failing (a full
    card) said "[Errno 28] No space left on device: '.../.left_0001.png.1234-9f2c.tmp' ->
    '.../left_0001.png'", the temporary file first; the pair's file is named, nothing stays."""
    import errno

    img = _numbered(1)

    def refused(src: object, dst: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device", str(src), None, str(dst))

    monkeypatch.setattr(os, "link", refused)
    monkeypatch.setattr(os, "replace", refused)
    with pytest.raises(OSError) as info:
        save_pair(tmp_path, 1, img, img)
    assert str(info.value) == f"cannot write {tmp_path / 'left_0001.png'}: No space left on device"
    assert info.value.errno == errno.ENOSPC and list(tmp_path.iterdir()) == []


def test_a_folder_refusing_the_temporary_file_names_the_pairs_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """save_pair into a folder that refuses new files (/proc: ENOENT; a read-only card: EROFS)
    said '[Errno 2] No such file or directory: '/proc/.left_0001.png.32467-0f59063e.tmp'', a
    file the user never named; the pair's file and its folder are named, as io's writers do."""
    import errno

    img = _numbered(1)
    real_open = os.open

    def read_only(path: Any, flags: int, mode: int = 0o777) -> int:
        if str(path).endswith(".tmp"):
            raise OSError(errno.EROFS, "Read-only file system", str(path))
        return real_open(path, flags, mode)

    monkeypatch.setattr(os, "open", read_only)
    with pytest.raises(OSError) as info:
        save_pair(tmp_path, 1, img, img)
    monkeypatch.undo()
    assert str(info.value) == (
        f"cannot write {tmp_path / 'left_0001.png'}: no file can be made in its folder "
        f"{tmp_path} (Read-only file system)"
    )
    assert info.value.errno == errno.EROFS and not list(tmp_path.iterdir())


def test_ctrl_c_never_leaves_half_a_pair(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C while a pair is saved: a signal is held until the pair is whole, an interrupt
    raised while the right image is written removes the left one. (The left image stayed
    alone: `calibrate --left 'left_*' --right 'right_*'` refused the folder, 2 files vs 1.)"""
    import signal

    img = _numbered(1)
    real_fsync, real_link = os.fsync, os.link
    calls = {"fsync": 0, "link": 0}

    def fsync_with_ctrl_c(fd: int) -> None:
        calls["fsync"] += 1
        if calls["fsync"] == 1:  # the user presses Ctrl-C while the left image is written
            signal.raise_signal(signal.SIGINT)
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync_with_ctrl_c)
    with pytest.raises(KeyboardInterrupt):
        save_pair(tmp_path, 1, img, img)
    monkeypatch.setattr(os, "fsync", real_fsync)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["left_0001.png", "right_0001.png"]
    assert np.array_equal(cv2.imread(str(tmp_path / "right_0001.png")), img)

    def link_interrupted(src: Any, dst: Any) -> None:
        calls["link"] += 1
        if calls["link"] == 2:  # the right image's naming
            raise KeyboardInterrupt
        real_link(src, dst)

    monkeypatch.setattr(os, "link", link_interrupted)
    with pytest.raises(KeyboardInterrupt):
        save_pair(tmp_path, 2, img, img)
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["left_0001.png", "right_0001.png"]
    assert next_pair_index(tmp_path) == 2


def test_capture_removes_temp_files_a_killed_capture_left(tmp_path: Path) -> None:
    """A capture killed outright (SIGKILL, SIGTERM without a handler) cannot remove its
    temporary file; the next capture into the folder does, and says so. A file of a process
    still running, and other hidden files, are kept."""
    out = tmp_path / "pairs"
    out.mkdir()
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)  # fmt: skip
    dead = int(done.stdout)  # a process that has ended
    names = [
        f".left_0003.png.{dead}-9f2c01ab.tmp",  # left by a killed capture
        ".right_0002.png.k3x_9a2b.tmp",  # tempfile's name (before the process id was in it)
        f".left_0004.png.{os.getppid()}-00aa11bb.tmp",  # a capture still writing
        ".notes.txt.tmp",  # not ours
    ]
    for name in names:
        (out / name).write_bytes(b"half a png")
    left, right = _videos(tmp_path, 2, 2)
    lines: list[str] = []
    with StereoCamera(left, right) as cam:
        result = capture(cam, out, count=1, log=lines.append)
    assert result.removed_temps == sorted(names[:2])
    assert lines[0] == (
        f"removed 2 temporary files an interrupted capture left in {out}: "
        f"{', '.join(sorted(names[:2]))}"
    )
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [*names[2:], "left_0001.png", "right_0001.png"]
    )
    assert capmod.remove_stale_temps(tmp_path / "none") == []


def test_no_partial_file_visible_to_a_concurrent_reader(tmp_path: Path) -> None:
    out = tmp_path / "pairs"
    out.mkdir()
    img = _numbered(3, (640, 480))
    stop = threading.Event()
    bad: list[str] = []
    checked = {"n": 0}

    def reader() -> None:
        # At least one pass after the last pair is saved: a loaded machine may not run this
        # thread at all while the 20 pairs are written, and no file checked proves nothing.
        while True:
            last = stop.is_set()
            for p in out.glob("*.png"):
                data = p.read_bytes()
                decoded = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
                checked["n"] += 1
                if decoded is None or decoded.shape != img.shape:
                    bad.append(p.name)
            if last:
                return

    t = threading.Thread(target=reader)
    t.start()
    try:
        for i in range(1, 21):
            save_pair(out, i, img, img)
    finally:
        stop.set()
        t.join()
    assert bad == [] and checked["n"] >= 40
    assert len(list(out.iterdir())) == 40


# ---------------------------------------------------------------------------- chessboard


def _board(
    pose: tuple[np.ndarray, np.ndarray] | None, n: int, right: bool, charuco: bool = False
) -> np.ndarray:
    """The 9x6 chessboard (or the 10x7-square ChArUco board with the same corners) at ``pose``
    seen by the left or right camera, stamped with frame number ``n``."""
    if pose is None:
        img = np.full((BOARD_SIZE[1], BOARD_SIZE[0]), 60, np.uint8)
    else:
        img = _rendered_board(pose, right, charuco)
    return _stamp(cv2.cvtColor(img, cv2.COLOR_GRAY2BGR), n)


#: :func:`_rendered_board`'s renders (read only), by pose, camera and board: the sequences
#: show the same few poses again and again (the 11-frame SEQUENCE: 19 boards, 7 renders).
_RENDERS: dict[tuple[bytes, bytes, bool, bool], np.ndarray] = {}


def _rendered_board(pose: tuple[np.ndarray, np.ndarray], right: bool, charuco: bool) -> np.ndarray:
    """The board at ``pose`` as the left or right camera sees it, grey, unstamped; rendered
    once per pose (the renders are deterministic) and handed out read only."""
    key = (np.asarray(pose[0], float).tobytes(), np.asarray(pose[1], float).tobytes(), right,
           charuco)  # fmt: skip
    if key not in _RENDERS:
        rv, tv = pose
        if right:
            rv = cv2.Rodrigues(RIG_R @ cv2.Rodrigues(rv)[0])[0].ravel()
            tv = RIG_R @ tv + RIG_T
        if charuco:
            # The ChArUco board's corner 0 is one square in from its outer corner.
            t0 = tv - cv2.Rodrigues(rv)[0] @ np.array([SQUARE, SQUARE, 0.0])
            img = render_charuco(CHARUCO, K, D, rv, t0, image_size=BOARD_SIZE, supersample=2)
        else:
            img = render_chessboard(
                K, D, rv, tv, pattern=(9, 6), square_size=SQUARE, image_size=BOARD_SIZE
            )
        img.setflags(write=False)
        _RENDERS[key] = img
    return _RENDERS[key]


def _pose(
    dx: float, dy: float, z: float, tilt: tuple[float, float] = (0.0, 0.0)
) -> tuple[np.ndarray, np.ndarray]:
    rv = np.array([tilt[0], tilt[1], 0.0])
    rb = cv2.Rodrigues(rv)[0]
    centre = np.array([4 * SQUARE, 2.5 * SQUARE, 0.0])
    return rv, np.array([dx + 0.03, dy, z]) - rb @ centre


#: Distinct test poses are at least this much further apart than the threshold.
POSE_MARGIN = 0.05
POSE_A = _pose(0.0, 0.0, 0.55)
POSE_B = _pose(0.1, 0.06, 0.55)
POSE_C = _pose(0.02, 0.0, 0.5, tilt=(0.5, 0.5))
POSE_D = _pose(-0.1, -0.07, 0.6)
#: Frames of the auto-capture video: repeats of A, B, C; D seen by the left camera only; a
#: board-less frame. Only frames 0 (A), 3 (B) and 6 (C) are new poses seen by both cameras.
SEQUENCE: list[tuple[Any, Any]] = [
    (POSE_A, POSE_A), (POSE_A, POSE_A), (POSE_A, POSE_A), (POSE_B, POSE_B), (POSE_B, POSE_B),
    (POSE_A, POSE_A), (POSE_C, POSE_C), (POSE_C, POSE_C), (POSE_D, None), (None, None),
    (POSE_A, POSE_A),
]  # fmt: skip


@pytest.fixture(scope="module")
def board_videos(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    d = tmp_path_factory.mktemp("boards")
    left = _write_video(d / "left.avi", [_board(a, i, False) for i, (a, _) in enumerate(SEQUENCE)])
    right = _write_video(d / "right.avi", [_board(b, i, True) for i, (_, b) in enumerate(SEQUENCE)])
    return left, right


def test_a_16_bit_or_alpha_sequence_is_searched_for_the_board(tmp_path: Path) -> None:
    """An image sequence is read as its files are (16-bit PNGs of a machine-vision camera stay
    16-bit): the chessboard mode's live detection gave them to findChessboardCorners, whose
    cv2.error came out raw ("internal error ... please report this" from the CLI). They are
    searched as 8-bit grey now, as calibrate and the ChArUco mode search them."""
    board = _board(POSE_A, 0, False)
    want = detect_board_live(board, (9, 6))
    assert want is not None
    grey = cv2.cvtColor(board, cv2.COLOR_BGR2GRAY)
    for img in (
        board.astype(np.uint16) * 257,
        grey.astype(np.uint16) * 257,
        grey[:, :, None],
        cv2.cvtColor(board, cv2.COLOR_BGR2BGRA),
    ):
        got = detect_board_live(img, (9, 6))
        assert got is not None and np.abs(got - want).max() < 0.5
    d = tmp_path / "seq"
    d.mkdir()
    for i, pose in enumerate((POSE_A, POSE_B)):
        for side, right in (("left", False), ("right", True)):
            img = cv2.cvtColor(_board(pose, i, right), cv2.COLOR_BGR2GRAY).astype(np.uint16)
            assert cv2.imwrite(str(d / f"{side}_{i:03d}.png"), img * 257)
    with StereoCamera(str(d / "left_%03d.png"), str(d / "right_%03d.png")) as cam:
        res = capture(cam, tmp_path / "pairs", chessboard=(9, 6))
    assert len(res.saved) == 2 and res.ended == "end of stream"
    saved = cv2.imread(str(res.saved[1][0]), cv2.IMREAD_UNCHANGED)
    assert saved.dtype == np.uint16  # saved as delivered


def test_a_sequence_with_alpha_is_delivered_as_bgr(tmp_path: Path) -> None:
    """An image sequence is read as its files are: PNGs with alpha (a renderer's) came as
    4-channel frames where a pair's frames are BGR, which a right sequence without alpha (or a
    one-channel image) could not be paired with: ``--temporal`` refused "left and right differ
    in shape: (40, 60, 4) and (40, 60, 3)", and capture saved 4-channel images. Alpha is
    dropped now, as a grey frame is made BGR; the pixels are kept."""
    d = tmp_path / "seq"
    d.mkdir()
    for i in range(3):
        bgr = _numbered(i, (60, 40))
        assert cv2.imwrite(str(d / f"left_{i:03d}.png"), cv2.cvtColor(bgr, cv2.COLOR_BGR2BGRA))
        assert cv2.imwrite(str(d / f"right_{i:03d}.png"), bgr)
    with StereoCamera(str(d / "left_%03d.png"), str(d / "right_%03d.png")) as cam:
        pairs = list(cam.frames())
    assert len(pairs) == 3
    for i, fr in enumerate(pairs):
        assert fr.left.shape == fr.right.shape == (40, 60, 3)
        assert (fr.left == _numbered(i, (60, 40))).all() and (fr.left == fr.right).all()


def test_test_poses_are_distinct_enough() -> None:
    """The video's design: A, B, C, D seen whole by both cameras (the stamp included), pairwise
    further apart than the ROS threshold."""
    params = []
    for pose in (POSE_A, POSE_B, POSE_C, POSE_D):
        c = detect_board_live(_board(pose, 0, False), (9, 6))
        assert c is not None and detect_board_live(_board(pose, 0, True), (9, 6)) is not None
        params.append(board_pose_params(c, (9, 6), BOARD_SIZE))
    for i in range(4):
        for j in range(i):
            dist = sum(abs(a - b) for a, b in zip(params[i], params[j], strict=True))
            assert dist > capmod.MIN_POSE_DISTANCE + POSE_MARGIN


def test_chessboard_autocapture_saves_distinct_poses_only(
    board_videos: tuple[Path, Path], tmp_path: Path
) -> None:
    lines: list[str] = []
    with StereoCamera(*board_videos) as cam:
        result = capture(cam, tmp_path / "cb", chessboard="9x6", log=lines.append)
    assert result.frames_read == len(SEQUENCE) and result.ended == "end of stream"
    stamps = [_read_stamp(cv2.imread(str(p[0]))) for p in result.saved]
    assert stamps == [0, 3, 6]
    assert [_read_stamp(cv2.imread(str(p[1]))) for p in result.saved] == [0, 3, 6]
    assert len(lines) == 3 and all("x [" in s and "skew [" in s for s in lines)
    assert result.coverage is not None
    assert result.coverage["x"] > 0.2 and result.coverage["skew"] > 0.3
    # With a count the capture stops as soon as it is reached ...
    with StereoCamera(*board_videos) as cam:
        res2 = capture(cam, tmp_path / "cb2", chessboard=(9, 6), count=2)
    assert [_read_stamp(cv2.imread(str(p[0]))) for p in res2.saved] == [0, 3]
    assert res2.frames_read == 4
    # ... and a stream ending before it is an error that keeps the saved pairs.
    with StereoCamera(*board_videos) as cam:
        with pytest.raises(SourceError, match="3 of 5 pairs were saved"):
            capture(cam, tmp_path / "cb3", chessboard=(9, 6), count=5)
    assert len(list((tmp_path / "cb3").glob("*.png"))) == 6


@functools.cache
def _half_board() -> np.ndarray:
    """The 9x6 board at POSE_A at half size (320x240): a quick search, rendered once."""
    return cv2.resize(_board(POSE_A, 0, False), (320, 240), interpolation=cv2.INTER_AREA)


def test_a_board_capture_that_saved_no_pair_says_why(tmp_path: Path) -> None:
    """capture --chessboard 10x7 of a 9x6 board (its squares counted, the most common slip)
    said "0 pairs saved (end of stream)" alone; a line now says why no pair was saved and,
    when the left image shows a board of one corner fewer each way, names that pattern."""
    board = _half_board()  # one view for both (the left image decides)
    left = _write_sequence(tmp_path / "seq", "left", [board])
    right = _write_sequence(tmp_path / "seq", "right", [board])
    lines: list[str] = []
    with StereoCamera(left, right) as cam:
        result = capture(cam, tmp_path / "a", chessboard="10x7", log=lines.append)
    assert (result.saved, result.ended) == ([], "end of stream")
    assert lines == [
        "no pair saved of the 1 pair judged: no board in left (1 pair); the last left image "
        "shows a board of 9x6 inner corners: the pattern counts the points where four squares "
        "meet, one fewer each way than the squares (chessboard=(9, 6), --chessboard 9x6)"
    ]
    blank = _write_sequence(tmp_path / "blank", "right", [np.full((240, 320), 60, np.uint8)])
    lines.clear()
    with StereoCamera(left, blank) as cam:
        capture(cam, tmp_path / "b", chessboard="9x6", log=lines.append)
    assert lines == ["no pair saved of the 1 pair judged: no board in right (1 pair)"]


def test_a_board_capture_resumed_into_its_folder_judges_against_the_pairs_there(
    tmp_path: Path,
) -> None:
    """A board capture run again into its folder ("run again to add more", as an interrupted
    one says) judged new poses against none: the pose saved before was saved again, the
    coverage from 0 %. The pairs there are counted now, and said."""
    board = _half_board()
    left = _write_sequence(tmp_path / "seq", "left", [board])
    right = _write_sequence(tmp_path / "seq", "right", [board])
    out = tmp_path / "pairs"
    with StereoCamera(left, right) as cam:
        assert len(capture(cam, out, chessboard="9x6").saved) == 1
    lines: list[str] = []
    with StereoCamera(left, right) as cam:
        result = capture(cam, out, chessboard="9x6", log=lines.append)
    assert result.saved == [] and sorted(p.name for p in out.iterdir()) == [
        "left_0001.png",
        "right_0001.png",
    ]
    bars = "  ".join(f"{k} [----------]   0%" for k in ("x", "y", "size", "skew"))
    assert lines == [
        f"1 pair already in {out} with the board: new poses must differ from it too  {bars}",
        "no pair saved of the 1 pair judged: pose too close to a saved one (1 pair)",
    ]


def test_a_board_capture_resumed_into_a_full_folder_reads_its_last_pairs_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A board capture resumed into its folder read and searched every pair there before its
    first pair (200 board-less VGA pairs: 12 s of CPU in silence); it reads the last
    RESUME_POSES_MAX, and says how many earlier ones it did not read."""
    out = tmp_path / "pairs"
    out.mkdir()
    blank = np.full((240, 320, 3), 128, np.uint8)
    for i, image in enumerate([blank, _half_board(), blank], start=1):
        for side in ("left", "right"):
            cv2.imwrite(str(out / f"{side}_{i:04d}.png"), image)
    monkeypatch.setattr(capmod, "RESUME_POSES_MAX", 2, raising=False)
    import stereovision.io as svio

    read: list[str] = []
    real_read = svio.read_image

    def read_image(path: Path) -> np.ndarray:
        read.append(Path(path).name)
        return real_read(path)

    monkeypatch.setattr(svio, "read_image", read_image)
    left = _write_sequence(tmp_path / "seq", "left", [_half_board()])
    right = _write_sequence(tmp_path / "seq", "right", [_half_board()])
    lines: list[str] = []
    with StereoCamera(left, right) as cam:
        result = capture(cam, out, chessboard="9x6", log=lines.append)
    assert read == ["left_0002.png", "right_0002.png", "left_0003.png", "right_0003.png"]
    assert result.saved == []  # the pose of pair 2, read
    bars = "  ".join(f"{k} [----------]   0%" for k in ("x", "y", "size", "skew"))
    assert lines == [
        f"1 of the last 2 pairs in {out} shows the board (1 before them not read, for a quick "
        f"start): new poses must differ from it too  {bars}",
        "no pair saved of the 1 pair judged: pose too close to a saved one (1 pair)",
    ]


def _still_noisy_sequence(
    data_dir: Path, directory: Path, n: int, shift_per_frame: int = 0
) -> tuple[str, str]:
    """``n`` PNG frames per side of a textured scene with fresh grey noise (sigma 8) in each,
    the scene moved ``shift_per_frame`` px to the right per frame."""
    from tests.test_exposure import noisy

    rng = np.random.default_rng(7)
    base = cv2.resize(cv2.imread(str(data_dir / "middlebury2003/teddy/left.png")), SMALL)
    frames = [np.roll(base, i * shift_per_frame, axis=1) for i in range(n)]
    left = _write_sequence(directory, "left", [noisy(f, 8.0, rng) for f in frames])
    right = _write_sequence(directory, "right", [noisy(f, 8.0, rng) for f in frames])
    return left, right


def test_a_second_capture_on_an_ended_source_is_a_source_error(tmp_path: Path) -> None:
    """A capture on an image sequence another capture had read to its end read nothing and
    returned "0 pairs saved (end of stream)" (the CLI's exit 0), where an end before a first
    pair is a SourceError: the earlier capture's pairs counted as this one's. It says the
    source ended before this capture read a pair, and to open it again."""
    frames = [_numbered(i) for i in range(3)]
    left = _write_sequence(tmp_path / "seq", "left", frames)
    right = _write_sequence(tmp_path / "seq", "right", frames)
    with StereoCamera(left, right) as cam:
        first = capture(cam, tmp_path / "a")
        assert len(first.saved) == 3 and first.ended == "end of stream"
        for count, kept in ((None, "0 pairs were"), (2, "0 of 2 pairs were")):
            with pytest.raises(SourceError) as err:
                capture(cam, tmp_path / "b", count=count)
            assert str(err.value) == (
                "both sources ended after 3 frames, before this capture read a pair (an earlier "
                f"read of this camera took its frames: open it again); {kept} saved in "
                f"{tmp_path / 'b'} and are kept"
            )
    with StereoCamera(left, right) as cam:  # opened again: its frames again
        assert len(capture(cam, tmp_path / "c").saved) == 3


@pytest.fixture(scope="module")
def five_still_frames(data_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[str, str]:
    """``_still_noisy_sequence(..., 5)``'s patterns, written once for the tests that only read
    them (the same frames each time: its noise is seeded)."""
    return _still_noisy_sequence(data_dir, tmp_path_factory.mktemp("still5"), 5)


def test_temporal_capture_saves_the_mean_of_still_frames(data_dir: Path, tmp_path: Path) -> None:
    """``temporal=4``: a pair per 4 frames of a still view, each with less noise than one frame
    (Immerkaer's estimate, which the texture raises too: measured 5.74 -> 3.21-3.27 grey
    levels); a view that moves every frame saves nothing."""
    from stereovision.temporal import noise_sigma

    lpat, rpat = _still_noisy_sequence(data_dir, tmp_path / "still", 16)
    lines: list[str] = []
    with StereoCamera(lpat, rpat) as cam:
        result = capture(cam, tmp_path / "pairs", temporal=4, log=lines.append)
    assert result.frames_read == 16 and len(result.saved) == 4
    assert all("mean of 4.0 frames" in ln for ln in lines), lines
    one = cv2.imread(lpat % 0)
    for lp, rp in result.saved:
        for p in (lp, rp):
            assert noise_sigma(cv2.imread(str(p))) < 0.62 * noise_sigma(one)
    lpat, rpat = _still_noisy_sequence(data_dir, tmp_path / "moving", 12, shift_per_frame=2)
    with StereoCamera(lpat, rpat) as cam:
        moving = capture(cam, tmp_path / "none", temporal=4)
    assert moving.saved == [] and moving.frames_read == 12 and moving.ended == "end of stream"


def test_a_temporal_mean_the_source_ends_is_said_unsaved(
    data_dir: Path,
    five_still_frames: tuple[str, str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``--temporal 3`` over 5 still frames saved the mean of the first 3 and dropped the last
    2 frames' mean without a word ("1 pair saved (end of stream); 5 pairs read"); a line says
    it now. 6 frames (two whole means) leave nothing unsaved, and no such line."""
    from stereovision.cli import main

    lpat, rpat = five_still_frames
    lines: list[str] = []
    with StereoCamera(lpat, rpat) as cam:
        result = capture(cam, tmp_path / "five", temporal=3, log=lines.append)
    assert len(result.saved) == 1 and result.ended == "end of stream", lines
    assert lines[1:] == [
        "not saved: the last mean, of 2.0 frames of the 3 asked, was unfinished when the "
        "source ended"
    ]
    lpat, rpat = _still_noisy_sequence(data_dir, tmp_path / "six_frames", 6)
    capsys.readouterr()
    assert main(["capture", "--left", lpat, "--right", rpat, "-o", str(tmp_path / "six"),
                 "--temporal", "3"]) == 0  # fmt: skip
    out = capsys.readouterr().out
    assert out.count("mean of 3.0 frames") == 2 and "not saved" not in out, out


def test_a_temporal_mean_the_source_ends_before_the_count_is_said_unsaved(
    five_still_frames: tuple[str, str], tmp_path: Path
) -> None:
    """``temporal=3, count=4`` over 5 still frames: the end is an error ("1 of 4 pairs were
    saved"), and the last 2 frames' mean was dropped without the line the end without a count
    says (fc77903); it is said before the error."""
    lpat, rpat = five_still_frames
    lines: list[str] = []
    with StereoCamera(lpat, rpat) as cam, pytest.raises(SourceError, match="1 of 4 pairs"):
        capture(cam, tmp_path / "five", temporal=3, count=4, log=lines.append)
    assert len(lines) == 2 and lines[0].startswith("saved left_0001.png"), lines
    assert lines[1] == (
        "not saved: the last mean, of 2.0 frames of the 3 asked, was unfinished when the "
        "source ended"
    )


@pytest.mark.parametrize("where", ["read_within", "temporal_average"])
def test_a_temporal_mean_an_interrupt_cuts_is_said_unsaved(
    five_still_frames: tuple[str, str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    where: str,
) -> None:
    """Ctrl-C while ``temporal=2`` awaits its 4th frame (``read_within``), or averages it
    (``temporal_average``, after 3cc84f4f): the pair of frames 1-2 is saved, frame 3's
    unfinished mean was dropped without a word; a line says so before the interrupt goes on
    (the CLI then says the pairs kept)."""
    lpat, rpat = five_still_frames
    real = getattr(capmod, where)
    calls = []

    def interrupted_4th(*args: Any) -> Any:
        calls.append(1)
        if len(calls) == 4:
            raise KeyboardInterrupt
        return real(*args)

    monkeypatch.setattr(capmod, where, interrupted_4th)
    lines: list[str] = []
    with StereoCamera(lpat, rpat) as cam, pytest.raises(KeyboardInterrupt):
        capture(cam, tmp_path / "pairs", temporal=2, log=lines.append)
    assert len(lines) == 2 and lines[0].startswith("saved left_0001.png"), lines
    assert lines[1] == (
        "not saved: the last mean, of 1.0 frames of the 2 asked, was unfinished when the "
        "capture was interrupted"
    )


def test_temporal_averaging_of_16_bit_frames_is_refused_naming_the_source(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """capture --temporal (and stream --temporal) of a 16-bit image sequence said "left:
    expected a uint8 image, got uint16", the filter's words for an argument the user never
    passed; it now names the averaging and the source that delivers such frames."""
    from stereovision.cli import main

    deep = [(_numbered(i).astype(np.uint16) * 257) for i in range(4)]
    left16 = _write_sequence(tmp_path / "deep", "left", deep)
    right16 = _write_sequence(tmp_path / "deep", "right", deep)
    right8 = _write_sequence(tmp_path / "flat", "right", [_numbered(i) for i in range(4)])
    left8 = _write_sequence(tmp_path / "flat", "left", [_numbered(i) for i in range(4)])
    words = (
        "temporal averaging takes 8-bit frames: the {} source delivers uint16 ones (a 16-bit "
        "image sequence?); convert them to 8 bits, or leave the averaging out"
    )
    for (left, right), side in (((left16, right8), "left"), ((left8, right16), "right")):
        with StereoCamera(left, right) as cam, pytest.raises(ValueError) as ei:
            capture(cam, tmp_path / "pairs", temporal=2)
        assert str(ei.value) == words.format(side)
    assert not (tmp_path / "pairs").exists() or not list((tmp_path / "pairs").iterdir())
    capsys.readouterr()
    src = ["--left", left8, "--right", right16, "--temporal", "2"]
    assert main(["capture", *src, "-o", str(tmp_path / "pairs")]) == 2
    assert capsys.readouterr().err == f"stereovision: error: {words.format('right')}\n"
    assert main(["stream", *src, "--no-display", "--frames", "2"]) == 2
    assert capsys.readouterr().err.endswith(f"stereovision: error: {words.format('right')}\n")


def test_temporal_chessboard_capture_waits_for_a_still_board(tmp_path: Path) -> None:
    """Poses A A A B B A C C (D) (-) A in PNG frames with grey noise (sigma 6), ``temporal=2``:
    A is taken on its 2nd frame, B and C on theirs; the third A frame and the later A are the
    same pose, and a pose held for one frame is never taken."""
    from tests.test_exposure import noisy

    rng = np.random.default_rng(3)
    seqs = []
    for side, right in (("left", False), ("right", True)):
        frames = [noisy(_board(pose[right], 0, right), 6.0, rng) for pose in SEQUENCE]
        seqs.append(_write_sequence(tmp_path / "boards", side, frames))
    lines: list[str] = []
    with StereoCamera(*seqs) as cam:
        result = capture(cam, tmp_path / "cb", chessboard="9x6", temporal=2, log=lines.append)
    assert result.frames_read == len(SEQUENCE) and len(result.saved) == 3, lines
    # the last A, one frame after the board left, is an unfinished mean the end leaves unsaved
    assert lines[-1] == (
        "not saved: the last mean, of 1.0 frames of the 2 asked, was unfinished when the "
        "source ended"
    )
    assert all("mean of 2.0 frames" in ln for ln in lines[:-1]), lines
    # Each saved pair is a pose seen by both cameras: the board is found in both images.
    for lp, rp in result.saved:
        assert detect_board_live(cv2.imread(str(lp)), (9, 6)) is not None
        assert detect_board_live(cv2.imread(str(rp)), (9, 6)) is not None
    with StereoCamera(*seqs) as cam:
        with pytest.raises(ValueError, match="temporal: expected 2-255"):
            capture(cam, tmp_path / "x", temporal=1)
        with pytest.raises(ValueError, match="every and temporal"):
            capture(cam, tmp_path / "x", temporal=4, every=2)


def test_collector_decisions() -> None:
    col = ChessboardCollector((9, 6))
    frames = [_board(POSE_A, 0, False), _board(POSE_A, 1, False), _board(None, 2, False)]
    mk = capmod.StereoFrame
    d1 = col.consider(mk(frames[0], frames[0], 0.0, 0.0, 0))
    d2 = col.consider(mk(frames[1], frames[1], 0.0, 0.0, 1))
    d3 = col.consider(mk(frames[2], frames[0], 0.0, 0.0, 2))
    d4 = col.consider(mk(frames[0], frames[2], 0.0, 0.0, 3))
    assert (d1.save, d1.reason) == (True, "new pose")
    assert not d2.save and d2.reason.startswith("pose too close")
    assert (d3.save, d3.reason) == (False, "no board in left")
    assert (d4.save, d4.reason) == (False, "no board in right")
    assert col.progress() == {"x": 0.0, "y": 0.0, "size": 0.0, "skew": 0.0}


def test_collector_checks_its_arguments_when_made() -> None:
    """The pattern "9x6" was a raw cv2.error from findChessboardCorners, board="9x6" AttributeError
    "'str' object has no attribute 'resolved'" at the first pair, and min_distance NaN kept
    the same pose over and over."""
    frame = _board(POSE_A, 0, False)
    pair = capmod.StereoFrame(frame, frame, 0.0, 0.0, 0)
    as_text = ChessboardCollector("9x6")  # type: ignore[arg-type]
    assert as_text.pattern == (9, 6)
    assert as_text.consider(pair) == ChessboardCollector((9, 6)).consider(pair)
    want = r"^board: expected a stereovision\.charuco\.CharucoBoard, got str$"
    with pytest.raises(TypeError, match=want):
        ChessboardCollector((9, 6), board="9x6")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^pattern: expected inner corners as COLSxROWS"):
        ChessboardCollector("nine by six")  # type: ignore[arg-type]
    for bad, said in ((math.nan, "nan"), ("0.2", "'0.2'")):
        with pytest.raises(
            ValueError, match=f"^min_distance: expected a finite number, got {said}$"
        ):
            ChessboardCollector((9, 6), min_distance=bad)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^min_distance: expected a finite number of 0 or more"):
        ChessboardCollector((9, 6), min_distance=-1.0)
    assert ChessboardCollector((9, 6), min_distance=np.float32(0.5)).min_distance == 0.5


def test_collector_takes_its_parameters_in_the_documented_order() -> None:
    """The docstring's Parameters are pattern, min_distance, board; the constructor took the
    list of kept poses third, so ChessboardCollector(pattern, 0.2, board) put the board there
    and collected chessboards (board None); kept is state now, never a parameter."""
    import inspect

    board = CharucoBoard("10x7", 0.03, 0.022)
    col = ChessboardCollector(board.inner, 0.2, board)
    assert col.board is board and col.kept == [] and col.min_distance == 0.2
    assert list(inspect.signature(ChessboardCollector).parameters) == [
        "pattern",
        "min_distance",
        "board",
    ]
    with pytest.raises(TypeError, match="unexpected keyword argument 'kept'"):
        ChessboardCollector((9, 6), kept=[])  # type: ignore[call-arg]


def test_capture_names_a_charuco_that_is_no_board(tmp_path: Path) -> None:
    """capture(charuco="10x7"), a pattern's words given for the board, was AttributeError
    "'str' object has no attribute 'inner'" (ChessboardCollector's own check came after):
    a TypeError naming charuco now, before the camera is read or the folder made."""
    for bad, kind in (("10x7", "str"), ((10, 7), "tuple")):
        with pytest.raises(
            TypeError,
            match=rf"^charuco: expected a stereovision\.charuco\.CharucoBoard, got {kind}$",
        ):
            capmod.capture(None, tmp_path / "out", count=1, charuco=bad)  # type: ignore[arg-type]
    assert not (tmp_path / "out").exists()


#: 10x7 squares: the same 9x6 inner corners as the chessboard above.
CHARUCO = CharucoBoard("10x7", SQUARE, 0.022, "DICT_5X5_100")
#: POSE_B moved right until a quarter of the board leaves the left image.
POSE_CUT = _pose(0.2, 0.06, 0.55)


def test_charuco_pose_is_the_whole_boards() -> None:
    """A board cut by the edge gets its whole pose: x beyond the centroid of the part seen."""
    found = find_charuco_corners(_board(POSE_CUT, 0, False, charuco=True), CHARUCO)
    assert found is not None and 20 <= len(found[0]) < CHARUCO.n_corners
    x = charuco_pose_params(found[0], found[1], CHARUCO, BOARD_SIZE)[0]
    assert x > found[1][:, 0].mean() / BOARD_SIZE[0] + 0.05
    whole = find_charuco_corners(_board(POSE_A, 0, False, charuco=True), CHARUCO)
    chess = detect_board_live(_board(POSE_A, 0, False), (9, 6))
    assert whole is not None and chess is not None
    p = charuco_pose_params(whole[0], whole[1], CHARUCO, BOARD_SIZE)
    np.testing.assert_allclose(p, board_pose_params(chess, (9, 6), BOARD_SIZE), atol=0.01)


def test_charuco_autocapture_keeps_cut_boards(tmp_path: Path) -> None:
    """Frames: A, the board cut by the left image's edge, A again, tilted C, a board in the left
    camera only, none. Saved: 0, 1 and 3."""
    seq = [(POSE_A, POSE_A), (POSE_CUT, POSE_CUT), (POSE_A, POSE_A), (POSE_C, POSE_C),
           (POSE_D, None), (None, None)]  # fmt: skip
    left = _write_video(
        tmp_path / "l.avi", [_board(a, i, False, charuco=True) for i, (a, _) in enumerate(seq)]
    )
    right = _write_video(
        tmp_path / "r.avi", [_board(b, i, True, charuco=True) for i, (_, b) in enumerate(seq)]
    )
    auto = CharucoBoard("10x7", SQUARE, 0.022)  # dictionary found from the first frame
    with StereoCamera(left, right) as cam:
        result = capture(cam, tmp_path / "ch", charuco=auto)
    assert [_read_stamp(cv2.imread(str(p[0]))) for p in result.saved] == [0, 1, 3]
    with pytest.raises(ValueError, match="give one calibration target"):
        capture(StereoCamera(left, right), tmp_path / "x", chessboard="9x6", charuco=auto)
    col = ChessboardCollector(CHARUCO.inner, board=CHARUCO)
    mk = capmod.StereoFrame
    img = _board(POSE_A, 0, False, charuco=True)
    flat = _board(None, 0, False, charuco=True)
    assert col.consider(mk(flat, img, 0.0, 0.0, 0)).reason == "no board in left"
    assert col.consider(mk(img, flat, 0.0, 0.0, 0)).reason == "no board in right"


# ---------------------------------------------------------------------------------- CLI


def test_cli_capture(
    board_videos: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    left, right = _videos(tmp_path, 6, 6)
    out = tmp_path / "pairs"
    args = _parser().parse_args(
        ["capture", "--left", str(left), "--right", str(right), "--size", "320x240",
         "--count", "3", "-o", str(out)]
    )  # fmt: skip
    assert args.func(args) == 0
    text = capsys.readouterr().out
    assert "3 pairs saved" in text and "skew mean" in text and "320x240" in text
    assert len(list(out.glob("left_*.png"))) == 3
    args = _parser().parse_args(
        ["capture", "--left", str(left), "--right", str(right), "--count", "1",
         "-o", str(tmp_path / "one")]
    )  # fmt: skip
    assert args.func(args) == 0
    assert f"1 pair saved in {tmp_path / 'one'} (count reached)" in capsys.readouterr().out
    args = _parser().parse_args(
        ["capture", "--left", str(board_videos[0]), "--right", str(board_videos[1]),
         "--chessboard", "9x6", "-o", str(tmp_path / "cb")]
    )  # fmt: skip
    assert args.func(args) == 0
    text = capsys.readouterr().out
    assert text.count("saved left_") == 3 and "size [" in text

    def run(*argv: str) -> int:
        a = _parser().parse_args(["capture", *argv])
        return int(a.func(a))

    with pytest.raises(FileNotFoundError, match="left source not found"):
        run("--left", str(tmp_path / "x.avi"), "--right", str(right), "-o", str(out))
    with pytest.raises(ValueError, match="WIDTHxHEIGHT"):
        run("--left", str(left), "--right", str(right), "--size", "big", "-o", str(out))
    with pytest.raises(ValueError, match="count"):
        run("--left", str(left), "--right", str(right), "--count", "0", "-o", str(out))
    with pytest.raises(ValueError, match=r"--chessboard: expected inner corners as COLSxROWS"):
        run("--left", str(left), "--right", str(right), "--chessboard", "9", "-o", str(out))
    src = ("--left", str(left), "--right", str(right), "-o", str(out))
    with pytest.raises(ValueError, match="give the board's --square and --marker sides too"):
        run(*src, "--charuco", "10x7")
    with pytest.raises(ValueError, match="--square, --marker and --dictionary are for --charuco"):
        run(*src, "--square", "0.03")
    with pytest.raises(ValueError, match="give one calibration target, not both"):
        run(*src, "--charuco", "10x7", "--chessboard", "9x6", "--square", "3", "--marker", "2")
    with pytest.raises(ValueError, match=r"^--marker: 4 must be smaller than --square 3"):
        run(*src, "--charuco", "10x7", "--square", "3", "--marker", "4")
    with pytest.raises(SourceError, match="both sources ended after 6 frames; 6 of 9 pairs"):
        run("--left", str(left), "--right", str(right), "--count", "9", "-o", str(out))
    with pytest.raises(SystemExit):  # refused by argparse, in the option's name
        run(*src, "--fourcc", "MJPEG")
    with pytest.raises(ValueError, match=r"^--left-topic, --right-topic and --max-skew-ms are for"):
        run(*src, "--max-skew-ms", "5")
    for frames in ("1", "256"):
        with pytest.raises(ValueError, match="--temporal: expected 2-255"):
            run(*src, "--temporal", frames)
    with pytest.raises(FileNotFoundError, match="left source not found"):  # 255 is taken
        run("--left", str(tmp_path / "x.avi"), "--right", str(right), "--temporal", "255",
            "-o", str(out))  # fmt: skip
    with pytest.raises(ValueError, match="--every and --temporal"):
        run(*src, "--temporal", "4", "--every", "3")
    with pytest.raises(ValueError, match="--fourcc asks a camera for a format"):
        run("--from-bag", str(tmp_path), "--fourcc", "MJPG", "-o", str(out))


def test_capture_temporal_of_a_fraction_is_said_as_its_range(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """capture --temporal 8.5 said "expected a whole number, got '8.5'" where 1 and 256 are
    "expected 2-255 frames a pair": two wordings of one refusal; the range is said for both."""
    from stereovision.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["capture", "--left", "0", "--right", "1", "--temporal", "8.5", "-o", "out"])
    assert exc.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1] == (
        "stereovision capture: error: argument --temporal: expected 2-255 frames a pair, "
        "got '8.5' (see stereovision capture --help)"
    )


def test_a_folder_a_glob_or_a_misnumbered_pattern_names_the_source_that_would_work(
    tmp_path: Path,
) -> None:
    """``--left pairs/`` was "cannot open left source 'pairs/'", ``--left 'pairs/left*.png'``
    "left source not found" and ``left_%03d.png`` for ``left_0001.png ...`` FFmpeg's line and
    "cannot open": none named what works. The one line names the pattern of the files there
    (or a video file, or a bag's --from-bag)."""
    pairs = tmp_path / "pairs"
    pairs.mkdir()
    img = np.zeros((8, 8, 3), np.uint8)
    for i in (1, 2, 3):
        for side in ("left", "right"):
            cv2.imwrite(str(pairs / f"{side}_{i:04d}.png"), img)
    right = str(pairs / "right_%04d.png")
    seq = f"a pattern such as {pairs}/left_%04d.png (its files are named left_0001.png, "
    seq += "left_0002.png ...)"
    for given, error, said in (
        (f"{pairs}/", SourceError, f"left source {pairs}/ is a folder: give {seq}"),
        (str(pairs), SourceError, f"left source {pairs} is a folder: give {seq}"),
        (
            f"{pairs}/left*.png",
            FileNotFoundError,
            f"left source {pairs}/left*.png is a glob, which OpenCV does not expand: give {seq}",
        ),
        (
            f"{pairs}/left_%03d.png",
            FileNotFoundError,
            f"left source: no file fits {pairs}/left_%03d.png; give {seq}",
        ),
        (
            f"{pairs}/left_*1.png",
            FileNotFoundError,
            f"left source {pairs}/left_*1.png is a glob, which OpenCV does not expand: give the "
            f"file it matches, {pairs}/left_0001.png",
        ),
    ):
        with pytest.raises(error) as err:
            StereoCamera(given, right)
        assert str(err.value) == said
    # the right side is told its own files; an unpadded run is %d
    for i in (1, 2, 10):
        cv2.imwrite(str(pairs / f"R{i}.jpg"), img)
    (pairs / "right_0001.png").unlink()
    with pytest.raises(SourceError) as err:
        StereoCamera(f"{pairs}/left_%04d.png", pairs)
    assert str(err.value) == (
        f"right source {pairs} is a folder: give a pattern such as {pairs}/right_%04d.png (its "
        "files are named right_0002.png, right_0003.png)"
    )
    videos = tmp_path / "videos"
    videos.mkdir()
    _videos(videos, 1, 1)
    with pytest.raises(SourceError) as err:
        StereoCamera(videos / "left.avi", videos)
    assert str(err.value) == (
        f"right source {videos} is a folder: give a video file such as {videos}/right.avi"
    )
    bag = tmp_path / "bag"
    bag.mkdir()
    (bag / "metadata.yaml").write_text("")
    with pytest.raises(SourceError, match="is a folder holding a ROS 2 bag: read it with --from"):
        StereoCamera(bag, right)
    with pytest.raises(FileNotFoundError) as nothing:
        StereoCamera(f"{tmp_path}/empty/*.png", right)
    assert str(nothing.value).endswith(
        "(it matches no file): give a video file, an image-sequence pattern such as "
        f"{tmp_path}/empty/left_%04d.png or a camera index"
    )


def test_a_glob_with_a_wildcard_in_a_folder_part_names_a_source_that_opens(
    tmp_path: Path,
) -> None:
    """``--left 'runs/run*/left_*.png'`` was told "give a video file, an image-sequence pattern
    such as runs/run*/left_%04d.png or a camera index": a pattern with the star still in it,
    which opens nothing. The hint names one matched folder's pattern, or says plainly that a
    sequence is one folder's."""
    img = np.zeros((8, 8, 3), np.uint8)
    for run, count in (("run1", 3), ("run2", 2)):
        (tmp_path / run).mkdir()
        for i in range(1, count + 1):
            cv2.imwrite(str(tmp_path / run / f"left_{i:04d}.png"), img)
    right = str(tmp_path / "right_%04d.png")
    said = "is a glob, which OpenCV does not expand"
    for given, hint in (
        (
            f"{tmp_path}/run*/left_*.png",
            f"it matches files in 2 folders ({tmp_path}/run1, {tmp_path}/run2) and a source is "
            f"one folder's: give e.g. a pattern such as {tmp_path}/run1/left_%04d.png (its "
            "files are named left_0001.png, left_0002.png ...)",
        ),
        (  # one folder matched: its own pattern
            f"{tmp_path}/run[1]/*.png",
            f"give a pattern such as {tmp_path}/run1/left_%04d.png (its files are named "
            "left_0001.png, left_0002.png ...)",
        ),
    ):
        with pytest.raises(FileNotFoundError) as err:
            StereoCamera(given, right)
        assert str(err.value) == f"left source {given} {said}: {hint}"
        assert "*" not in hint and "[" not in hint
    given = f"{tmp_path}/run*/nothing_*.png"
    with pytest.raises(FileNotFoundError) as err:
        StereoCamera(given, right)
    assert str(err.value) == (
        f"left source {given} {said} (it matches no file): give a video file, an image-sequence "
        "pattern in one folder (no wildcard in it; the number as %04d: left_%04d.png) or a "
        "camera index"
    )


def test_sources_that_opened_before_the_folder_and_pattern_hints_still_open(
    tmp_path: Path,
) -> None:
    """The hints for a folder, a glob or a misnumbered pattern refused sources that open: a
    video file whose name holds ``%d`` ("no file numbered 0-4 fits take_%d.avi; give a video
    file such as take_left.avi", the file beside it) and a pattern in a folder whose name
    holds brackets ("no file matches run[1]/left_%04d.png", the brackets taken for a glob's)."""
    videos = tmp_path / "videos"
    videos.mkdir()
    _videos(videos, 2, 2)
    (videos / "left.avi").rename(videos / "take_%d.avi")
    (videos / "right.avi").rename(videos / "take_left.avi")
    _videos(videos, 2, 2)
    with StereoCamera(videos / "take_%d.avi", videos / "right.avi") as cam:
        assert cam.read().left.shape[:2] == (240, 320)
    run = tmp_path / "run[1]"
    run.mkdir()
    img = np.zeros((8, 8, 3), np.uint8)
    for i in (0, 1):
        for side in ("left", "right"):
            cv2.imwrite(str(run / f"{side}_{i:04d}.png"), img)
    with StereoCamera(f"{run}/left_%04d.png", f"{run}/right_%04d.png") as cam:
        assert cam.read().left.shape[:2] == (8, 8)


def test_a_misnumbered_pattern_is_told_a_pattern_that_opens(tmp_path: Path) -> None:
    """Files left_0001.png ... left_10000.png (the last one digit wider) were told the
    pattern left_%d.png, which names left_1.png and opens nothing; %04d prints 10000 too."""
    pairs = tmp_path / "pairs"
    pairs.mkdir()
    img = np.zeros((8, 8, 3), np.uint8)
    for i in (1, 2, 10000):
        cv2.imwrite(str(pairs / f"left_{i:04d}.png"), img)
    cv2.imwrite(str(pairs / "right_0001.png"), img)
    with pytest.raises(FileNotFoundError) as err:
        StereoCamera(f"{pairs}/left_%03d.png", f"{pairs}/right_%04d.png")
    assert str(err.value) == (
        f"left source: no file fits {pairs}/left_%03d.png; give a pattern such as "
        f"{pairs}/left_%04d.png (its files are named left_0001.png, left_0002.png ...)"
    )


def test_cli_folder_source_is_one_line_naming_its_pattern(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``stream`` and ``capture`` share the source parsing: a folder is one line naming the
    pattern of its files, exit 2."""
    from stereovision.cli import main

    pairs = tmp_path / "pairs"
    pairs.mkdir()
    for side in ("left", "right"):
        cv2.imwrite(str(pairs / f"{side}_0001.png"), np.zeros((8, 8, 3), np.uint8))
    src = ["--left", str(pairs), "--right", str(pairs / "right_%04d.png")]
    said = (
        f"stereovision: error: left source {pairs} is a folder: give a pattern such as "
        f"{pairs}/left_%04d.png (its files are named left_0001.png)\n"
    )
    assert main(["stream", *src, "--no-display", "--frames", "1"]) == 2
    assert capsys.readouterr().err == said
    assert main(["capture", *src, "--count", "1", "-o", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err == said


def test_cli_float32_tiff_sequence_is_saved_with_format_tiff(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A float32 TIFF sequence could not be captured from the CLI: its pairs failed as .png
    ("... .tiff holds float32"), no option chose .tiff, and -o was left made and empty. The
    refusal names --format tiff and leaves no folder; --format tiff saves them as they are."""
    from stereovision.cli import main

    rng = np.random.default_rng(0)
    frames = [rng.random((6, 8)).astype(np.float32) for _ in range(2)]
    for side in ("left", "right"):
        for i, f in enumerate(frames):
            cv2.imwrite(str(tmp_path / f"{side}{i:02d}.tif"), f)
    src = ["--left", str(tmp_path / "left%02d.tif"), "--right", str(tmp_path / "right%02d.tif")]
    out = tmp_path / "new" / "out"
    assert main(["capture", *src, "-o", str(out)]) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: cannot save the left image (float32) as .png without loss: that "
        "format would write it as 8 bits; .tiff holds float32: give --format tiff\n"
    )
    assert not (tmp_path / "new").exists()
    assert main(["capture", *src, "-o", str(out), "--format", "tiff"]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "left_0001.tiff", "left_0002.tiff", "right_0001.tiff", "right_0002.tiff"
    ]  # fmt: skip
    got = cv2.imread(str(out / "right_0002.tiff"), cv2.IMREAD_UNCHANGED)
    np.testing.assert_array_equal(got, np.dstack([frames[1]] * 3))  # grey made BGR, values kept


def test_cli_missing_camera_is_one_line_naming_its_device(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    # OpenCV's backends log each failed attempt to stderr; the CLI's one line says it instead.
    # In process (cli.main): capfd reads file descriptor 2, where OpenCV's C++ logs too.
    from stereovision.cli import main

    if os.path.exists("/dev/video97") or not os.path.isdir("/dev"):
        pytest.skip("needs a /dev without video97")
    capfd.readouterr()
    argv = ["capture", "--left", "97", "--right", "98", "--count", "1"]
    assert main([*argv, "-o", str(tmp_path / "pairs")]) == 2
    assert capfd.readouterr().err.splitlines() == [
        "stereovision: error: cannot open left source camera 97 "
        "(no /dev/video97: is the camera plugged in?)"
    ]
    assert not (tmp_path / "pairs").exists() or not any((tmp_path / "pairs").iterdir())


def test_cli_missing_image_sequence_is_one_line(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    # FFmpeg printed "[image2 @ 0x...] Could find no file ..." before the CLI's own line
    # In process (cli.main): capfd reads file descriptor 2, where FFmpeg logs too.
    from stereovision.cli import main

    pattern = str(tmp_path / "none_%03d.png")
    capfd.readouterr()
    argv = ["capture", "--left", pattern, "--right", pattern, "--count", "1"]
    assert main([*argv, "-o", str(tmp_path / "pairs")]) == 2
    said = f"stereovision: error: left source: no file matches {pattern}"
    assert capfd.readouterr().err.splitlines() == [said]


def test_an_output_folder_that_is_a_file_is_said_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """-o naming a file, or a folder below one: one line saying so, before the sources are
    opened (it was "[Errno 17] File exists: ..." after opening them)."""
    from stereovision.cli import main

    left, right = _videos(tmp_path, 2, 2)
    (tmp_path / "taken").write_text("mine")
    for out, said in (
        (tmp_path / "taken", f"-o {tmp_path / 'taken'}: is a file, not a folder"),
        (tmp_path / "taken" / "x", f"-o {tmp_path / 'taken' / 'x'}: {tmp_path / 'taken'} is a "
         "file, not a folder"),
    ):  # fmt: skip
        argv = ["capture", "--left", str(left), "--right", str(right), "-o", str(out)]
        assert main(argv) == 2
        assert capsys.readouterr().err.splitlines() == [f"stereovision: error: {said}"]
    assert (tmp_path / "taken").read_text() == "mine"
    with StereoCamera(left, right) as cam, pytest.raises(ValueError, match="is a file, not a"):
        capture(cam, tmp_path / "taken", count=1)


def test_capture_refuses_to_save_into_the_sequence_it_reads(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--left pairs/left_%04d.png -o pairs: each pair saved (left_0004.png) would be the
    sequence's next frame; refused, one line (the capture never ended, filling the disk). A
    pattern that cannot match the saved names may share the folder."""
    from stereovision.cli import main

    pairs = tmp_path / "pairs"
    pairs.mkdir()
    for i in range(1, 4):
        cv2.imwrite(str(pairs / f"left_{i:04d}.png"), _numbered(i))
        cv2.imwrite(str(pairs / f"right_{i:04d}.png"), _numbered(i, shade=160))
    lpat, rpat = str(pairs / "left_%04d.png"), str(pairs / "right_%04d.png")
    before = sorted(p.name for p in pairs.iterdir())
    # count bounds each call: without the refusal they would save pairs for ever, not fail
    argv = ["capture", "--left", lpat, "--right", rpat, "-o", str(pairs), "--count", "20"]
    assert main(argv) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: error: -o {pairs}: the source {lpat} would read the pairs saved there as "
        "its next frames, without end; save them in another folder"
    ]
    with StereoCamera(lpat, rpat) as cam, pytest.raises(ValueError, match="without end"):
        capture(cam, pairs, count=20)
    other = _write_sequence(tmp_path / "other", "left", [_numbered(i) for i in range(3)])
    with pytest.warns(UserWarning, match="images are paired in order"):  # 0 beside 1
        cam = StereoCamera(other, rpat)
    with cam:  # the right pattern alone reads them too
        with pytest.raises(ValueError, match=f"the source {re.escape(rpat)} would read"):
            capture(cam, pairs, count=20)
    assert sorted(p.name for p in pairs.iterdir()) == before
    lcam = _write_sequence(pairs, "cam0", [_numbered(i) for i in range(3)])
    rcam = _write_sequence(pairs, "cam1", [_numbered(i, shade=160) for i in range(3)])
    with StereoCamera(lcam, rcam) as cam:
        result = capture(cam, pairs)
    assert [p[0].name for p in result.saved] == ["left_0004.png", "left_0005.png", "left_0006.png"]
    assert result.ended == "end of stream"


def test_two_captures_into_one_folder_never_overwrite_a_pair(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Another capture saves pair 2 while this one runs: this one's pairs take the next free
    numbers, the other's pair is kept (a rename replaced it: two captures into one folder lost
    pairs, or mixed one's left image with the other's right). save_pair never replaces a
    file, on a filesystem without hard links too."""
    out = tmp_path / "pairs"
    left, right = _videos(tmp_path, 4, 4)
    other = _numbered(99)
    real_save = capmod.save_pair

    def save_after_the_other(directory: Any, index: int, *args: Any, **kw: Any) -> Any:
        if index == 2 and not (out / "left_0002.png").exists():
            real_save(directory, 2, other, other)  # the other capture, just before
        return real_save(directory, index, *args, **kw)

    monkeypatch.setattr(capmod, "save_pair", save_after_the_other)
    with StereoCamera(left, right) as cam:
        result = capture(cam, out)
    assert [p[0].name for p in result.saved] == [f"left_{i:04d}.png" for i in (1, 3, 4, 5)]
    for side in ("left", "right"):
        assert np.array_equal(cv2.imread(str(out / f"{side}_0002.png")), other)
    assert [_read_stamp(cv2.imread(str(lp))) for lp, _ in result.saved] == [0, 1, 2, 3]
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == []
    monkeypatch.undo()

    def no_links(src: Any, dst: Any) -> None:
        raise PermissionError(1, "Operation not permitted")  # FAT, exFAT

    monkeypatch.setattr(os, "link", no_links)
    with pytest.raises(FileExistsError):
        save_pair(out, 2, _numbered(5), _numbered(5))
    assert np.array_equal(cv2.imread(str(out / "left_0002.png")), other)
    assert save_pair(out, 6, other, other)[1].name == "right_0006.png"
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == []


class _Terminal:
    """A stderr that says it is a terminal, keeping what is written to it."""

    def __init__(self) -> None:
        self.text = ""

    def write(self, s: str) -> int:
        self.text += s
        return len(s)

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return True


def test_cli_capture_of_one_pair_says_it_in_the_singular(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``capture --count 1``'s last line said "1 pair saved in ... (count reached); 1 pairs
    read": the saved count was singular, the read count not."""
    from stereovision.cli import main

    left = _write_sequence(tmp_path / "seq", "left", [_numbered(0)])
    right = _write_sequence(tmp_path / "seq", "right", [_numbered(0)])
    out = tmp_path / "pairs"
    argv = ["capture", "--left", left, "--right", right, "--count", "1", "-o", str(out)]
    assert main(argv) == 0
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.startswith(f"1 pair saved in {out} (count reached); 1 pair read; sources: ")


def test_a_source_that_ends_after_one_frame_says_it_in_the_singular(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A left sequence of one frame beside a right one of two ended the capture "(left
    source ... ended after 1 frames; the right source still had frames)"."""
    from stereovision.cli import main

    left = _write_sequence(tmp_path / "seq", "left", [_numbered(0)])
    right = _write_sequence(tmp_path / "seq", "right", [_numbered(0), _numbered(1)])
    out = tmp_path / "pairs"
    assert main(["capture", "--left", left, "--right", right, "-o", str(out)]) == 0
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.startswith(
        f"1 pair saved in {out} (left source {left!r} ended after 1 frame; the right source "
        "still had frames); 1 pair read; "
    )


def test_cli_capture_from_a_recording_shows_its_frames_bar_on_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`capture` from a recording read its frames without a word between two "saved" lines (a
    board search through hundreds of pairs): on a terminal a bar now counts the frames read
    of those the recording announces (6), gone before the last line; the "saved" lines are
    on stdout as before, and off a terminal (a log) nothing is added."""
    from stereovision.cli import main

    frames = [_numbered(i) for i in range(6)]
    left = _write_sequence(tmp_path / "seq", "left", frames)
    right = _write_sequence(tmp_path / "seq", "right", frames)
    args = ["capture", "--left", left, "--right", right, "--every", "2"]
    terminal = _Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    assert main([*args, "-o", str(tmp_path / "a")]) == 0
    assert "frames:   0%" in terminal.text and "| 0/6 [" in terminal.text
    assert terminal.text.rsplit("\r", 2)[-2].strip() == ""  # cleared from the screen
    saved = [f"saved left_{i:04d}.png right_{i:04d}.png" for i in (1, 2, 3)]
    out = capsys.readouterr().out.splitlines()
    assert [line.split(" (")[0] for line in out[1:4]] == saved
    assert out[4].startswith("3 pairs saved in") and "6 pairs read" in out[4]
    monkeypatch.undo()
    assert main([*args, "-o", str(tmp_path / "b")]) == 0
    logged = capsys.readouterr()
    assert "frames" not in logged.err and "%" not in logged.err
    assert [line.split(" (")[0] for line in logged.out.splitlines()[1:4]] == saved
    # a recording holding more frames than it announces (a container's guess): past the
    # count, the bar counts on without a total, not "6/3 200%"
    monkeypatch.setattr(StereoCamera, "_announced", lambda self, side: 3)
    monkeypatch.setattr("sys.stderr", terminal := _Terminal())
    assert main([*args, "-o", str(tmp_path / "c")]) == 0
    assert "| 0/3 [" in terminal.text and re.search(r"frames: [4-6]frame \[", terminal.text)
    assert not re.search(r"[4-6]/3 ", terminal.text)


def test_the_frames_bars_total_is_the_fewer_announced_and_zero_when_one_is_unknown(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The frames bar's total (``_frames_announced``) is the fewer of the two sources' frame
    counts (the pairs a recording can give), 0 (no total) when either says none: a source
    given as an object (its count may mean anything) or a count that is no count (0, NaN,
    inf: ``int(nan)`` raised). A bar of total 0 is not drawn, and the warnings' routing ends
    with the bar."""

    class _Counted(_FakeCap):
        def get(self, prop: int) -> float:
            return 6.0 if prop == cv2.CAP_PROP_FRAME_COUNT else super().get(prop)

    left, right = _videos(tmp_path, 6, 4)
    with StereoCamera(str(left), str(right)) as cam:
        assert [cam._announced(side) for side in ("left", "right")] == [6, 4]
        assert capmod._frames_announced(cam) == 4
        real = cam._caps["left"]
        for said in (0.0, -1.0, math.nan, math.inf):

            class _Says:
                def get(self, prop: int, said: float = said) -> float:
                    return said if prop == cv2.CAP_PROP_FRAME_COUNT else real.get(prop)

            cam._caps["left"] = _Says()
            assert cam._announced("left") is None, said
            assert capmod._frames_announced(cam) == 0
        cam._caps["left"] = real
    with StereoCamera(_Counted("L", []), str(right)) as cam:
        assert cam._announced("left") is None and cam._announced("right") == 4
        assert capmod._frames_announced(cam) == 0
    assert capmod._frames_announced(object()) == 0

    monkeypatch.setattr("sys.stderr", terminal := _Terminal())
    shown = warnings.showwarning
    bar = capmod._FramesBar()
    bar.start(0)  # a camera's: no bar, warnings as they were
    assert bar.bar is None and terminal.text == "" and warnings.showwarning is shown
    bar.start(6)
    assert bar.bar is not None and warnings.showwarning is not shown
    bar.close()
    assert bar.bar is None and warnings.showwarning is shown


def test_cli_capture_warning_while_reading_goes_above_the_frames_bar(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A warning while the bar was drawn (the right frames resized at the first read) was
    printed onto the bar's line, "| 0/6 [00:00<?, ?frame/s]stereovision: warning: ...": the
    bar is now cleared first, the warning a line of its own, and the bar drawn again below."""
    from stereovision.cli import main

    left = _write_sequence(tmp_path / "seq", "left", [_numbered(i, (64, 48)) for i in range(6)])
    right = _write_sequence(tmp_path / "seq", "right", [_numbered(i, (32, 24)) for i in range(6)])
    terminal = _Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    args = ["capture", "--left", left, "--right", right, "--every", "2"]
    assert main([*args, "-o", str(tmp_path / "a")]) == 0
    warning = "stereovision: warning: right source "
    assert terminal.text.count(warning) == 1
    before, after = terminal.text.split(warning)
    assert before.endswith("\r") and before.rsplit("\r", 2)[-2].strip() == ""  # cleared
    assert after.split("\n")[0].endswith("delivers 32x24, not 64x48: its frames are resized")
    assert "| 0/6 [" in after.split("\n", 1)[1]  # drawn again below it
    assert terminal.text.rsplit("\r", 2)[-2].strip() == ""  # and gone at the end
    assert capsys.readouterr().out.splitlines()[-1].startswith("3 pairs saved in")


@pytest.fixture(scope="module")
def long_videos(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """400 numbered frames a side (1 s to write), read only: shared by the tests they outlast."""
    return _videos(tmp_path_factory.mktemp("long"), 400, 400)


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize(
    ("sig", "status", "what"), [(2, 130, "interrupted"), (15, 143, "terminated (SIGTERM)")]
)
def test_cli_capture_stopped_says_what_it_kept(
    tmp_path: Path, long_videos: tuple[Path, Path], sig: int, status: int, what: str
) -> None:
    """Ctrl-C or SIGTERM mid-capture: one line saying how many pairs were saved and kept (it
    said "stereovision: interrupted" alone), every pair whole."""
    import signal

    left, right = long_videos
    out = tmp_path / "pairs"
    proc = subprocess.Popen(
        [sys.executable, "-m", "stereovision", "capture", "--left", str(left), "--right",
         str(right), "-o", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )  # fmt: skip
    try:
        assert proc.stdout is not None
        for line in proc.stdout:
            if line.startswith("saved left_0005.png"):
                break
        proc.send_signal(signal.Signals(sig))
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == status
    n = len(list(out.glob("left_*.png")))
    assert n >= 5 and len(list(out.glob("right_*.png"))) == n
    assert err.splitlines() == [
        f"stereovision: {what}: {n} pairs saved in {out} this run are kept; run again to add more"
    ]
    assert all(cv2.imread(str(p)) is not None for p in out.iterdir())
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


def test_cli_capture_interrupted_counts_its_own_pairs_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Another capture saves pair 2 into the folder meanwhile, and Ctrl-C comes while this one
    saves its third pair (held until the pair is whole): 3 pairs saved this run, said as such
    (the count was the span of the numbers, 4, the other capture's pair included), and the
    pair saved under the held Ctrl-C is said too."""
    from stereovision.cli import main

    out = tmp_path / "pairs"
    left, right = _videos(tmp_path, 8, 8)
    other = _numbered(99)
    real_save = capmod.save_pair
    own: list[int] = []

    def save_beside_another(directory: Any, index: int, *args: Any, **kw: Any) -> Any:
        if index == 2 and not (out / "left_0002.png").exists():
            real_save(directory, 2, other, other)  # the other capture, just before
        paths = real_save(directory, index, *args, **kw)
        own.append(index)
        if len(own) == 3:
            raise KeyboardInterrupt  # as HeldInterrupts replays it once the pair is whole
        return paths

    monkeypatch.setattr(capmod, "save_pair", save_beside_another)
    argv = ["capture", "--left", str(left), "--right", str(right), "-o", str(out)]
    assert main(argv) == 130
    got = capsys.readouterr()
    assert own == [1, 3, 4]
    assert [ln.split()[1] for ln in got.out.splitlines() if ln.startswith("saved ")] == [
        "left_0001.png",
        "left_0003.png",
        "left_0004.png",
    ]
    assert got.err.splitlines() == [
        f"stereovision: interrupted: 3 pairs saved in {out} this run are kept; run again to "
        "add more"
    ]


def test_capture_into_a_folder_replaced_by_a_file_stops(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The output folder replaced by a file while capturing: FileExistsError, not a retry on
    the next number without end (each save's mkdir raised FileExistsError, read as a number
    another capture took)."""
    import shutil

    out = tmp_path / "pairs"
    left, right = _videos(tmp_path, 6, 6)
    real_save = capmod.save_pair
    calls: list[int] = []

    def save(directory: Any, index: int, *args: Any, **kw: Any) -> Any:
        calls.append(index)
        if len(calls) == 2:
            shutil.rmtree(out)
            out.write_text("not a folder")
        if len(calls) > 20:
            raise RuntimeError(f"retried without end: {calls[-3:]}")
        return real_save(directory, index, *args, **kw)

    monkeypatch.setattr(capmod, "save_pair", save)
    with StereoCamera(left, right) as cam, pytest.raises(FileExistsError):
        capture(cam, out)
    assert calls == [1, 2]
    assert out.read_text() == "not a folder"


def test_a_frame_resized_after_a_dropped_size_is_said(tmp_path: Path) -> None:
    """image_size=(320, 180) of a 4:3 sequence is dropped (its frames kept at 320x240, one warning);
    a later frame of half that size is then resized to it: one more warning says so (the
    warning about the dropped size took the side's only warning, and the resize was silent)."""
    frames = [_numbered(i) for i in range(3)]
    frames[1] = cv2.resize(frames[1], (160, 120), interpolation=cv2.INTER_AREA)
    lpat = _write_sequence(tmp_path, "left", frames)
    rpat = _write_sequence(tmp_path, "right", [_numbered(i) for i in range(3)])
    with (
        pytest.warns(UserWarning) as caught,
        StereoCamera(lpat, rpat, image_size=(320, 180)) as cam,
    ):
        got = list(cam.frames())
    assert [str(w.message) for w in caught] == [
        f"left source {lpat!r} delivers 320x240, not 320x180: another shape, so its frames are "
        "kept at 320x240 (a resize would stretch them)",
        f"left source {lpat!r} delivers 160x120, not 320x240: its frames are resized",
    ]
    assert [f.left.shape for f in got] == [(240, 320, 3)] * 3


def test_temporal_averaging_of_enlarged_frames_is_said(tmp_path: Path) -> None:
    """image_size=(320, 240) of a 160x120 left and a 320x240 right source: the left frames are
    enlarged before the filter (whose means are of one shape), whose motion test takes their
    interpolated noise for motion; one warning says so (none did)."""
    frames = [_numbered(0, (160, 120)) for _ in range(4)]
    lpat = _write_sequence(tmp_path / "in", "left", frames)
    rpat = _write_sequence(tmp_path / "in", "right", [_numbered(0, (320, 240))] * 4)
    with (
        pytest.warns(UserWarning) as caught,
        StereoCamera(lpat, rpat, image_size=(320, 240)) as cam,
    ):
        capture(cam, tmp_path / "pairs", temporal=2)
    said = [str(w.message) for w in caught if str(w.message).startswith("temporal")]
    assert said == [
        "temporal averaging: the left frames are enlarged from 160x120 to 320x240, and "
        "interpolation spreads their noise, which the filter takes for motion (it may average "
        "nothing); ask for the cameras' own size"
    ]


def test_temporal_capture_averages_frames_before_enlarging_them(
    data_dir: Path, tmp_path: Path
) -> None:
    """size twice the sources': the filter got the enlarged frames, whose interpolated noise
    its motion test took for motion, so a still noisy view saved no pair (and a warning said
    so). The frames are now averaged as delivered, then enlarged: a pair per 4 frames, at the
    size asked, half as far from the noiseless scene as one frame enlarged (RMS 2.6 grey
    levels against 5.0), and nothing to warn about."""
    lpat, rpat = _still_noisy_sequence(data_dir, tmp_path / "still", 8)
    big = (2 * SMALL[0], 2 * SMALL[1])
    lines: list[str] = []
    with (
        warnings.catch_warnings(record=True) as caught,
        StereoCamera(lpat, rpat, image_size=big) as cam,
    ):
        warnings.simplefilter("always")
        result = capture(cam, tmp_path / "pairs", temporal=4, log=lines.append)
    assert not [w for w in caught if str(w.message).startswith("temporal")]
    assert len(result.saved) == 2 and all("mean of 4.0 frames" in ln for ln in lines), lines
    clean = cv2.resize(cv2.imread(str(data_dir / "middlebury2003/teddy/left.png")), SMALL)
    clean = cv2.resize(clean, big, interpolation=cv2.INTER_LINEAR).astype(np.float64)

    def rms(img: np.ndarray) -> float:
        return float(np.sqrt(np.mean((img.astype(np.float64) - clean) ** 2)))

    one = rms(cv2.resize(cv2.imread(lpat % 0), big, interpolation=cv2.INTER_LINEAR))
    errors = [rms(cv2.imread(str(p))) for pair in result.saved for p in pair]
    assert all(e < 0.6 * one for e in errors), (errors, one)


def test_the_same_source_on_both_sides_is_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--left l.avi --right ./l.avi` (a typo): every pair was one view twice, saved or matched
    (every disparity 0) without a word; now one warning says so. `--left 0 --right 0` failed
    on the second open with a hint about another program using the camera; now it says both
    are camera 0, before opening either."""
    from stereovision.cli import main

    left, _right = _videos(tmp_path, 3, 3)
    same = ["--left", str(left), "--right", f"{tmp_path}/./{left.name}"]  # Path drops "."
    assert main(["capture", *same, "-o", str(tmp_path / "pairs"), "--count", "1"]) == 0
    warned = [ln for ln in capsys.readouterr().err.splitlines() if "same source" in ln]
    assert warned == [
        f"stereovision: warning: --left and --right are the same source {str(left)!r}: every "
        "pair is one view twice and every disparity comes out 0 (two cameras' views are needed)"
    ]
    # an image-sequence pattern is no file: the two spellings are compared as paths
    pat = _write_sequence(tmp_path / "seq", "left", [_numbered(i) for i in range(2)])
    same = ["--left", pat, "--right", f"{tmp_path}/seq/./left_%03d.png"]  # not Path: it drops "."
    assert main(["capture", *same, "-o", str(tmp_path / "seqpairs"), "--count", "1"]) == 0
    assert f"are the same source {pat!r}" in capsys.readouterr().err
    assert main(["capture", "--left", "7", "--right", "7", "-o", str(tmp_path / "x")]) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: --left and --right are both camera 7: give the rig's two cameras\n"
    )
    # one camera named two ways: an index and its device node, or a link to the node
    argv = ["capture", "--left", "7", "--right", "/dev/video7", "-o", str(tmp_path / "x")]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: --left '7' and --right '/dev/video7' are both camera /dev/video7: "
        "give the rig's two cameras\n"
    )
    link = tmp_path / "by-id-cam"
    link.symlink_to("/dev/video7")
    argv = ["stream", "--left", "/dev/video7", "--right", str(link), "--no-display"]
    assert main([*argv, "--frames", "1"]) == 2
    assert capsys.readouterr().err.startswith("stereovision: error: --left '/dev/video7' and")
    assert (
        main(["capture", "--left", "12", "--right", "/dev/video12", "-o", str(tmp_path / "x")]) == 2
    )
    assert "are both camera /dev/video12" in capsys.readouterr().err  # two digits too
    assert not (tmp_path / "x").exists()


def test_a_negative_camera_index_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--left -1` was taken for a file and refused as "left source not found: -1"; the index
    -1 itself (OpenCV's "any camera", no side of a rig) crashed the process in
    cv2.VideoCapture(-1) with no camera present (a segmentation fault). Both say what is wrong.
    `--left ²` (a digit to str.isdigit, no number to int) was "invalid literal for int()"."""
    from stereovision.cli import main

    says = "camera index {0} is negative: cameras are numbered from 0 (./{0} for a file)"
    for text in ("-1", " -2 ", -1):
        n = int(text)
        with pytest.raises(ValueError, match=f"^{re.escape(says.format(n))}$"):
            parse_source(text)
    with pytest.raises(ValueError, match=r"^left source: camera index -1 is negative"):
        StereoCamera(-1, 0)
    assert parse_source("²") == "²" and parse_source(" 3 ") == 3 and parse_source("-x") == "-x"
    argv = ["capture", "--left", "-1", "--right", "0", "-o", str(tmp_path / "x")]
    assert main(argv) == 2
    assert capsys.readouterr().err == f"stereovision: error: {says.format(-1)}\n"
    assert main(["capture", "--left", "²", "--right", "0", "-o", str(tmp_path / "x")]) == 2
    assert capsys.readouterr().err == "stereovision: error: left source not found: ²\n"
    assert not (tmp_path / "x").exists()


def test_a_negative_index_message_names_the_file_as_typed() -> None:
    """The negative index's hint spelt the file from int(): `--left -01` said "./-1 for a
    file" (another file) and `--left -0` "camera index 0 is negative" (0 is no negative
    index, and ./0 another file). -01 is refused pointing at ./-01; -0, no negative number,
    is a path as before the refusal."""
    with pytest.raises(
        ValueError, match=r"^camera index -1 is negative: .* \(\./-01 for a file\)$"
    ):
        parse_source(" -01 ")
    assert parse_source("-0") == "-0" and parse_source("-00") == "-00"
    with pytest.raises(FileNotFoundError, match=r"^left source not found: -0$"):
        StereoCamera("-0", 0)


def test_a_camera_index_opencv_cannot_take_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An index past a C int (`--left 99999999999999999999`, a typo; the GUI's camera field)
    reached cv2.VideoCapture, whose overload resolution failed: "left source camera 99999999999
    999999999 did not open: OpenCV failed (in function 'VideoCapture'", cut there. It is refused
    as a negative one is; the largest index OpenCV takes is still an index."""
    from stereovision.cli import main

    says = (
        "camera index {0} is too large: cameras are numbered from 0 to 2147483647 "
        "(./{1} for a file)"
    )
    for text in ("99999999999999999999", " 2147483648 ", 2**31, np.int64(2**40)):
        n = int(text)
        with pytest.raises(ValueError, match=f"^{re.escape(says.format(n, str(text).strip()))}$"):
            parse_source(text)
    from stereovision.capture import MAX_CAMERA_INDEX

    assert parse_source(str(MAX_CAMERA_INDEX)) == MAX_CAMERA_INDEX == 2**31 - 1
    argv = ["capture", "--left", "99999999999999999999", "--right", "0", "-o", str(tmp_path / "x")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert (
        err == f"stereovision: error: {says.format(99999999999999999999, 99999999999999999999)}\n"
    )
    assert not (tmp_path / "x").exists()


def test_every_with_a_board_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`--chessboard 9x6 --every 10` ignored --every (the board's poses choose the pairs) and
    said nothing; it is refused in one line, nothing opened or saved."""
    from stereovision.cli import main

    left, right = _videos(tmp_path, 2, 2)
    src = ["capture", "--left", str(left), "--right", str(right), "-o", str(tmp_path / "p")]
    for board in (["--chessboard", "9x6"], ["--charuco", "5x7", "--square", "4", "--marker", "3"]):
        assert main([*src, *board, "--every", "10"]) == 2
        assert capsys.readouterr().err == (
            "stereovision: error: --every is for a capture without a board: --chessboard and "
            "--charuco save a pair for each new pose of the board\n"
        )
    assert not (tmp_path / "p").exists()


def test_temporal_average_of_shrunk_frames_runs_at_the_size_asked(
    data_dir: Path, tmp_path: Path
) -> None:
    """size half the sources': 319faa6 averaged every resized pair as delivered, so a 1080p
    camera streamed at 640x360 ran the filter at 1920x1080 (243 ms a pair in the grab thread,
    against 21 ms). A shrink (INTER_AREA) leaves no spread noise: the filter gets the frames
    at the size asked, the still view restarts on none, and an enlargement is still averaged
    as delivered."""
    from stereovision.temporal import TemporalFilter

    lpat, rpat = _still_noisy_sequence(data_dir, tmp_path / "still", 4)  # 320x240

    class Spy(TemporalFilter):
        shapes: list[tuple[int, ...]]

        def __call__(self, left: Any, right: Any) -> Any:
            self.shapes.append(np.asarray(left).shape)
            return super().__call__(left, right)

    for size, fed in (((160, 120), (120, 160, 3)), ((640, 480), (240, 320, 3))):
        tf = Spy(max_frames=4)
        tf.shapes = []
        with (
            pytest.warns(UserWarning, match="its frames are resized"),
            StereoCamera(lpat, rpat, image_size=size) as cam,
        ):
            out = [capmod.temporal_average(tf, cam.read()) for _ in range(4)]
        assert tf.shapes == [fed] * 4, size
        assert all(left.shape == (size[1], size[0], 3) for left, _ in out)
        assert tf.restarts == 0 and tf.mean_frames() > capmod._TEMPORAL_FULL * 4


# ------------------------------------------------------------- values the mutation audit found


def test_an_image_sequence_has_no_media_time(tmp_path: Path) -> None:
    """OpenCV's image reader has no media time (POS_MSEC -1): the frames say NaN, not a time of
    0 ms that reads as the start of a video."""
    lpat = _write_sequence(tmp_path / "f", "left", [_numbered(i) for i in range(3)])
    rpat = _write_sequence(tmp_path / "f", "right", [_numbered(i, shade=160) for i in range(3)])
    with StereoCamera(lpat, rpat) as cam:
        frames = [cam.read() for _ in range(3)]
    assert all(np.isnan(f.pos_left_ms) and np.isnan(f.pos_right_ms) for f in frames)


def test_skew_median_beyond_the_window_averages_the_two_middle_skews() -> None:
    """Past the window the median comes from the histogram: for an even count it is the mean
    of the two middle skews (1..6 ms: 3.5 ms), within the bins' 0.5 %."""
    import statistics

    stats = capmod.SkewStats(window=4)
    values = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
    for v in values:
        stats.append(v)
    assert stats.n == 6 and len(stats) == 4
    assert stats.median_ms() == pytest.approx(statistics.median(values), rel=0.005)  # 3.5


def test_collector_default_distance_is_ros_good_sample_threshold() -> None:
    """ROS camera_calibration keeps a view whose (x, y, size, skew) differ from every kept one
    by more than 0.2 in sum: 0.15 away is refused, 0.25 away kept, with the default."""
    img = _board(POSE_A, 0, False)
    frame = capmod.StereoFrame(img, img, 0.0, 0.0, 0)
    corners = detect_board_live(img, (9, 6))
    assert corners is not None
    p = board_pose_params(corners, (9, 6), BOARD_SIZE)
    for shift, save in ((0.15, False), (0.25, True)):
        col = ChessboardCollector((9, 6))
        col.kept = [(p[0] + shift, p[1], p[2], p[3])]
        d = col.consider(frame)
        assert d.save is save, (shift, d.reason)
        if not save:
            assert d.reason == f"pose too close to a saved one ({shift:.3f})"


def test_live_board_corners_are_in_full_resolution_pixels() -> None:
    """A frame wider than DETECT_MAX_WIDTH is detected scaled down; the corners come back in
    the frame's own pixels (against OpenCV's detector on the full frame)."""
    big = cv2.resize(_board(POSE_A, 0, False), (1280, 960), interpolation=cv2.INTER_LINEAR)
    got = detect_board_live(big, (9, 6))
    gray = cv2.cvtColor(big, cv2.COLOR_BGR2GRAY)
    ok, ref = cv2.findChessboardCorners(gray, (9, 6))
    assert got is not None and ok
    ref = ref.reshape(-1, 2).astype(np.float64)
    if ref[0].sum() > ref[-1].sum():
        ref = ref[::-1]
    assert got.shape == (54, 2)
    assert np.abs(got - ref).max() < 2.0


def test_a_shape_five_percent_off_is_not_stretched(tmp_path: Path) -> None:
    """Asked 160x128 (5:4) of a 160x120 (4:3) source: 6.7 % another shape, beyond the 1 %
    tolerance, so the frames stay 160x120 (a resize would stretch them by 6.7 %)."""
    left, right = _videos(tmp_path, 2, 2, size=(160, 120))
    with pytest.warns(UserWarning, match=r"delivers 160x120, not 160x128: another shape"):
        with StereoCamera(left, right, image_size=(160, 128)) as cam:
            frame = cam.read()
    assert frame.left.shape == frame.right.shape == (120, 160, 3)


def test_a_frame_count_estimated_one_too_many_is_no_truncation(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A container without an index estimates its frame count (off by one or so): 20 frames
    read of 21 announced is the end of the stream; of 23 announced, a file that ended early."""
    left, right = _videos(tmp_path, 20, 20)
    for announced, early in ((21, False), (23, True)):
        monkeypatch.setattr(StereoCamera, "_announced", lambda self, side, n=announced: n)
        with StereoCamera(left, right) as cam:
            result = capture(cam, tmp_path / f"p{announced}", every=100)
        assert result.frames_read == 20
        if early:
            assert "ended after 20 of the 23 frames its header announces" in result.ended
        else:
            assert result.ended == "end of stream"


def test_cli_count_is_checked_before_the_cameras_open(tmp_path: Path) -> None:
    """--count 0 is said as the option, before any source opens (a missing file is not met)."""
    args = _parser().parse_args(
        ["capture", "--left", str(tmp_path / "none.avi"), "--right", str(tmp_path / "no.avi"),
         "--count", "0", "-o", str(tmp_path / "out")]
    )  # fmt: skip
    with pytest.raises(ValueError, match=r"^--count: expected a positive number, got 0$"):
        args.func(args)


SIDES = ("left", "right")


class _ModeCam(_FakeCap):
    """A webcam stand-in with a few fixed modes: it takes the mode nearest the width and height
    asked (as V4L2 does) and delivers a real image at that size."""

    MODES = ((640, 480), (1280, 720))

    def __init__(self, name: str, image: np.ndarray) -> None:
        super().__init__(name, [], frames=2)
        self.image, self.asked = image, [640.0, 480.0]

    def mode(self) -> tuple[int, int]:
        w, h = self.asked
        return min(self.MODES, key=lambda m: abs(m[0] - w) + abs(m[1] - h))

    def get(self, prop: int) -> float:
        axis = {cv2.CAP_PROP_FRAME_WIDTH: 0, cv2.CAP_PROP_FRAME_HEIGHT: 1}.get(prop)
        return 0.0 if axis is None else float(self.mode()[axis])

    def set(self, prop: int, value: float) -> bool:
        axis = {cv2.CAP_PROP_FRAME_WIDTH: 0, cv2.CAP_PROP_FRAME_HEIGHT: 1}.get(prop)
        if axis is not None:
            self.asked[axis] = value
        return axis is not None

    def retrieve(self) -> tuple[bool, np.ndarray]:
        return True, cv2.resize(self.image, self.mode(), interpolation=cv2.INTER_AREA)


def test_a_mode_the_camera_has_is_delivered_and_another_is_reported(data_dir: Path) -> None:
    """Asked 1280x720 of webcams offering it: width and height go to their own properties, the
    frames come at 1280x720, unresized and without a warning. Asked 800x600, they give their
    nearest mode 640x480: that is what is reported, and the frames are resized to 800x600
    with one warning per camera."""
    img = {s: cv2.imread(str(data_dir / f"middlebury2001/tsukuba/{s}.png")) for s in SIDES}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with StereoCamera(*(_ModeCam(s, img[s]) for s in SIDES), image_size="1280x720") as cam:
            frame = cam.read()
            assert cam.delivered_size == {"left": (1280, 720), "right": (1280, 720)}
    assert frame.left.shape == frame.right.shape == (720, 1280, 3) and frame.delivered is None
    assert np.array_equal(
        frame.left, cv2.resize(img["left"], (1280, 720), interpolation=cv2.INTER_AREA)
    )
    with pytest.warns(
        UserWarning, match=r"delivers 640x480, not 800x600: its frames are resized"
    ) as rec:
        with StereoCamera(*(_ModeCam(s, img[s]) for s in SIDES), image_size="800x600") as cam:
            frame = cam.read()
            assert cam.delivered_size == {"left": (640, 480), "right": (640, 480)}
            assert cam.describe() == (
                "asked 800x600; left _ModeCam: 640x480 (no frame rate given); right _ModeCam: "
                "640x480 (no frame rate given)"
            )
    assert len(rec) == 2 and frame.left.shape == (600, 800, 3)
    assert frame.delivered is not None and frame.delivered[0].shape == (480, 640, 3)


def test_numbering_continues_after_a_lone_right_image(tmp_path: Path) -> None:
    """A left image deleted by hand (a blurred view) leaves right_0007: the next pair is 8, and
    a file of another format counts too (its number is taken)."""
    (tmp_path / "right_0007.png").write_bytes(b"")
    assert next_pair_index(tmp_path) == 8
    (tmp_path / "left_0009.jpg").write_bytes(b"")
    assert next_pair_index(tmp_path) == 10
    (tmp_path / "right_0012.png.bak").write_bytes(b"")  # not a pair's name
    assert next_pair_index(tmp_path) == 10


def test_sources_that_deliver_nothing_are_an_error(tmp_path: Path) -> None:
    """Sources that open but end before a first pair: an error, with or without count (it was
    "0 pairs saved (end of stream)" without, as if the run had done its work)."""
    for count in (None, 3):
        with StereoCamera(_FakeCap("L", [], frames=0), _FakeCap("R", [], frames=0)) as cam:
            with pytest.raises(SourceError) as ei:
                capture(cam, tmp_path / "pairs", count=count)
        kept = f"0 of {count} pairs were" if count else "0 pairs were"
        assert str(ei.value) == (
            f"both sources ended after 0 frames; {kept} saved in {tmp_path / 'pairs'} and are kept"
        )
        assert ei.value.end and ei.value.frames == 0
    assert list((tmp_path / "pairs").iterdir()) == []


def test_temporal_pair_is_taken_at_95_percent_of_the_frames(data_dir: Path, tmp_path: Path) -> None:
    """A still noiseless view with temporal=20: the pair is taken once the means hold 19
    frames (95 %), not 20, and it is the view itself."""
    base = cv2.resize(cv2.imread(str(data_dir / "middlebury2001/venus/left.png")), SMALL)
    lpat = _write_sequence(tmp_path / "still", "left", [base] * 25)
    rpat = _write_sequence(tmp_path / "still", "right", [base] * 25)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # frames at their own size: nothing to warn about
        with StereoCamera(lpat, rpat) as cam:
            result = capture(cam, tmp_path / "pairs", count=1, temporal=20)
    assert result.frames_read == 19
    assert np.array_equal(cv2.imread(str(result.saved[0][0])), base)


def test_a_pose_equal_to_a_kept_one_is_refused_at_distance_zero() -> None:
    """ROS's rule keeps a view only when its distance is *above* min_distance: with 0, the
    very pose kept already is still refused."""
    img = _board(POSE_A, 0, False)
    frame = capmod.StereoFrame(img, img, 0.0, 0.0, 0)
    col = ChessboardCollector((9, 6), min_distance=0.0)
    assert col.consider(frame).save
    d = col.consider(frame)
    assert not d.save and d.reason == "pose too close to a saved one (0.000)"
    assert len(col.kept) == 1


class _SlowGrab(_FakeCap):
    def grab(self) -> bool:
        time.sleep(0.05)
        return super().grab()


def test_skew_includes_the_right_grab(tmp_path: Path) -> None:
    """The skew runs from the end of the left grab to the end of the right one: a right camera
    that takes 50 ms to grab gives pairs at least 50 ms apart."""
    with StereoCamera(_FakeCap("L", []), _SlowGrab("R", [])) as cam:
        frame = cam.read()
    assert frame.skew_ms >= 50.0 and frame.t_right - frame.t_left >= 0.05


class _Undecodable(_FakeCap):
    def retrieve(self) -> tuple[bool, np.ndarray]:
        return False, np.zeros((SMALL[1], SMALL[0], 3), np.uint8)  # a buffer, but no frame


def test_a_frame_the_source_says_it_could_not_decode_is_refused() -> None:
    """retrieve() answering False is a failed frame even when it hands back a buffer."""
    with StereoCamera(_FakeCap("L", []), _Undecodable("R", [])) as cam:
        with pytest.raises(SourceError) as ei:
            cam.read()
    assert str(ei.value) == "right source _Undecodable could not decode a frame after 0 pairs"
    assert (ei.value.side, ei.value.end) == ("right", False)


class _Delivers(_FakeCap):
    """A capture of the user's (a camera SDK's wrapper) that hands out the given frames in turn."""

    def __init__(self, name: str, frames: list[np.ndarray]) -> None:
        super().__init__(name, [], frames=len(frames))
        self.frames = frames

    def retrieve(self) -> tuple[bool, np.ndarray]:
        return True, self.frames[len(self.frames) - 1 - self.left]


@pytest.mark.parametrize(
    ("bad", "said"),
    [
        (np.zeros((0, 0, 3), np.uint8), "delivered an empty frame (0x0)"),
        (np.zeros((SMALL[1], 0), np.uint8), "delivered an empty frame (0x240)"),
        (np.zeros(SMALL[0], np.uint8), "delivered a frame of shape (320,), not an image"),
        (
            np.zeros((*SMALL[::-1], 2), np.uint8),
            "delivered a frame of shape (240, 320, 2), not an image",
        ),
    ],
)
def test_a_frame_that_is_no_image_is_refused_naming_the_source(
    bad: np.ndarray, said: str, tmp_path: Path
) -> None:
    """A capture that says True with an empty frame (a dropped frame of a camera SDK's wrapper)
    or an array that is no image: an empty one was taken as the frame, and after a first pair
    its size divided by zero (ZeroDivisionError out of capture and stream); a 1-D one raised
    IndexError. Each is now a failed frame, as one that does not decode is (``end`` False),
    naming the side; the pair saved before it is kept."""
    good = _numbered(0)
    cam = StereoCamera(_FakeCap("L", [], frames=2), _Delivers("R", [good, bad]))
    with pytest.raises(SourceError) as ei:
        capture(cam, tmp_path, count=2)
    cam.close()
    assert str(ei.value) == (
        f"right source _Delivers {said} after 1 pair; 1 of 2 pairs were saved in {tmp_path} "
        "and are kept"
    )
    assert (ei.value.side, ei.value.end) == ("right", False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["left_0001.png", "right_0001.png"]


def test_pairs_are_saved_whole_without_hard_links(
    data_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a filesystem without hard links (FAT) the name is given by a rename after a check:
    the pair appears, intact, no temporary file stays, and an existing pair is not replaced."""
    img = {s: cv2.imread(str(data_dir / f"middlebury2001/tsukuba/{s}.png")) for s in SIDES}

    def no_link(src: Any, dst: Any) -> None:
        raise OSError(1, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_link)
    out = tmp_path / "fat" / "pairs"  # missing folders are created
    lp, rp = save_pair(out, 1, img["left"], img["right"])
    assert (lp.name, rp.name) == ("left_0001.png", "right_0001.png")
    assert np.array_equal(cv2.imread(str(lp)), img["left"])
    assert np.array_equal(cv2.imread(str(rp)), img["right"])
    with pytest.raises(FileExistsError):
        save_pair(out, 1, img["right"], img["left"])
    assert np.array_equal(cv2.imread(str(lp)), img["left"])  # not replaced
    assert sorted(p.name for p in out.iterdir()) == ["left_0001.png", "right_0001.png"]


def test_a_pair_number_half_taken_by_another_capture_is_skipped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Another capture into the folder has written left_0001 but not yet right_0001: this one
    takes the next number (it stopped with FileExistsError when only one image was there)."""
    real = capmod.save_pair
    out = tmp_path / "pairs"

    def raced(directory: Any, index: int, *a: Any, **kw: Any) -> tuple[Path, Path]:
        if index == 1:
            (out / "left_0001.png").write_bytes(b"the other capture's")
        return real(directory, index, *a, **kw)

    monkeypatch.setattr(capmod, "save_pair", raced)
    left, right = _videos(tmp_path, 2, 2)
    with StereoCamera(left, right) as cam:
        result = capture(cam, out, count=1)
    assert [(a.name, b.name) for a, b in result.saved] == [("left_0002.png", "right_0002.png")]
    assert (out / "left_0001.png").read_bytes() == b"the other capture's"


def test_cli_capture_releases_the_cameras(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The cameras are released when the capture ends normally, and when it fails."""
    caps: list[_FakeCap] = []

    def cameras(args: Any, fps: float | None = None) -> StereoCamera:
        caps[:] = [_FakeCap("L", [], frames=3), _FakeCap("R", [], frames=3)]
        return StereoCamera(*caps)

    monkeypatch.setattr(capmod, "open_source", cameras)
    for count, code in (("2", 0), ("5", None)):
        args = _parser().parse_args(
            [
                "capture",
                "--left",
                "0",
                "--right",
                "1",
                "--count",
                count,
                "-o",
                str(tmp_path / count),
            ]
        )
        if code is None:
            with pytest.raises(SourceError, match="both sources ended after 3 frames"):
                args.func(args)
        else:
            assert args.func(args) == code
        assert [c.released for c in caps] == [1, 1]
    assert "2 pairs saved" in capsys.readouterr().out


class _SlowFirstGrab(_FakeCap):
    """A camera slow to deliver its first frame (a GigE or USB3 camera on a cold start): its
    first ``grab`` takes ``delay`` s."""

    def __init__(self, name: str, delay: float) -> None:
        super().__init__(name, [], frames=3)
        self.delay = delay

    def grab(self) -> bool:
        if self.left == 3:
            time.sleep(self.delay)
        return super().grab()


@pytest.fixture
def slow_cameras(monkeypatch: pytest.MonkeyPatch) -> list[float | None]:
    """``--left 0 --right 1`` opens two cameras, the left's first grab taking 0.5 s; returns the
    ``read_timeout`` of every read, as :func:`~stereovision.capture.read_within` got it."""
    from stereovision import stream as streammod

    timeouts: list[float | None] = []

    def cameras(*args: Any, **kwargs: Any) -> StereoCamera:
        return StereoCamera(_SlowFirstGrab("L", 0.5), _FakeCap("R", [], frames=3))

    def spy(camera: Any, timeout: float | None = capmod.DEFAULT_READ_TIMEOUT) -> Any:
        timeouts.append(timeout)
        return real(camera, timeout)

    real = capmod.read_within
    monkeypatch.setattr(capmod, "StereoCamera", cameras)
    monkeypatch.setattr(capmod, "read_within", spy)
    monkeypatch.setattr(streammod, "read_within", spy)
    return timeouts


# stream runs pipelined (its grab thread), as test_stream marks its own: a deadlock fails it
# within 30 s, with every thread's stack, not at the suite's 600 s (it takes 2 s)
@pytest.mark.parametrize(
    "command", ["capture", pytest.param("stream", marks=pytest.mark.timeout(30))]
)
def test_cli_read_timeout_reaches_the_read(
    command: str,
    tmp_path: Path,
    slow_cameras: list[float | None],
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A camera slow to deliver its first frame could not be used from the CLI: the library's
    ``read_timeout`` had no option. ``--read-timeout`` reaches every read: 0.2 s gives the
    0.5 s first grab up as hung (the CLI's error, exit 2), 2 s and ``none`` (no limit) wait for
    it, and without it the default (10 s) is kept."""
    from stereovision.cli import main

    argv = [command, "--left", "0", "--right", "1"]
    if command == "capture":
        argv += ["--count", "1"]
    else:
        argv += ["--frames", "1", "--no-display", "--no-check", "--max-disparity", "16"]

    def run(*extra: str) -> tuple[int, str]:
        slow_cameras.clear()
        out = ["-o", str(tmp_path / str(len(list(tmp_path.iterdir()))))]
        code = main([*argv, *(out if command == "capture" else []), *extra])
        return code, capsys.readouterr().err

    t0 = time.perf_counter()
    code, err = run("--read-timeout", "0.2")
    assert code == 2
    assert re.fullmatch(
        r"stereovision: error: .* delivered no frame in 0\.2 s \(its read did not return: .*\n",
        err,
    ), err
    assert slow_cameras == [0.2]
    assert time.perf_counter() - t0 < 1.5  # given up at 0.2 s, the grab waited for by close
    for extra, timeout in ((["--read-timeout", "2"], 2.0), (["--read-timeout", "none"], None)):
        code, err = run(*extra)
        assert (code, err) == (0, ""), err
        assert slow_cameras and set(slow_cameras) == {timeout}
    code, _ = run()
    assert code == 0
    assert slow_cameras and set(slow_cameras) == {capmod.DEFAULT_READ_TIMEOUT}


class _WedgedDevice:
    """A ``cv2.VideoCapture`` stand-in whose constructor never returns for the device indices
    in ``wedged`` (a wedged V4L2 device) until ``unplug`` is set (3 s at most, so that the old
    code's test ends); the others open at once, and every one made records its release."""

    wedged: ClassVar[set[int]] = set()
    #: ``(src, prop)``: that source's ``set`` (``get``) of ``prop`` hangs until ``unplug``.
    wedged_props: ClassVar[set[tuple[Any, int]]] = set()
    unplug = threading.Event()
    made: ClassVar[list[_WedgedDevice]] = []

    def __init__(self, src: Any, *args: Any) -> None:
        if src in type(self).wedged:
            type(self).unplug.wait(3.0)
        self.src, self.released = src, 0
        self.threads = {threading.get_ident()}  # the threads that opened and configured it
        self.busy = False  # inside a set or get
        self.released_busy = False  # released under a set or get (crashed OpenCV)
        type(self).made.append(self)

    def _call(self, prop: int) -> None:
        self.threads.add(threading.get_ident())
        if (self.src, prop) in type(self).wedged_props:
            self.busy = True
            type(self).unplug.wait(3.0)
            self.busy = False

    def isOpened(self) -> bool:
        return True

    def get(self, prop: int) -> float:
        self._call(prop)
        return 0.0

    def set(self, prop: int, value: float) -> bool:
        self._call(prop)
        return True

    def release(self) -> None:
        self.released_busy |= self.busy
        self.released += 1


@pytest.fixture
def wedged(monkeypatch: pytest.MonkeyPatch) -> Iterator[type[_WedgedDevice]]:
    """Device indices whose open hangs (``wedged.wedged``); unplugged at teardown."""
    _WedgedDevice.wedged, _WedgedDevice.made = set(), []
    _WedgedDevice.wedged_props = set()
    _WedgedDevice.unplug = threading.Event()
    monkeypatch.setattr(cv2, "VideoCapture", _WedgedDevice)
    yield _WedgedDevice
    _WedgedDevice.unplug.set()


def _released_soon(cap: _WedgedDevice) -> bool:
    deadline = time.monotonic() + 2.0
    while not cap.released and time.monotonic() < deadline:
        time.sleep(0.01)
    return cap.released == 1


@pytest.mark.parametrize("side", ["left", "right"])
def test_a_camera_whose_open_hangs_is_given_up(wedged: type[_WedgedDevice], side: str) -> None:
    """A wedged V4L2 device can keep OpenCV's open from ever returning: StereoCamera waited
    forever (reads were bounded, opens not). After ``open_timeout`` s it raises naming the
    source and the seconds; the other camera, opened, is released, and the wedged one's
    capture too once its open returns (it holds the device)."""
    index = 0 if side == "left" else 1
    wedged.wedged = {index}
    t0 = time.perf_counter()
    with pytest.raises(SourceError) as err:
        StereoCamera(0, 1, open_timeout=0.2)
    assert time.perf_counter() - t0 < 1.0
    assert str(err.value) == (
        f"{side} source camera {index} did not open within 0.2 s (its open did not return: a "
        "wedged camera or driver); unplug and replug it, or give it a longer timeout"
    )
    assert (err.value.side, err.value.end) == (side, False)
    assert [c.released for c in wedged.made] == ([1] if side == "right" else [])
    wedged.unplug.set()  # the open returns at last: its capture is released, not kept
    deadline = time.monotonic() + 2.0
    while len(wedged.made) < (2 if side == "right" else 1) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert [c.src for c in wedged.made] == ([0, 1] if side == "right" else [0])
    assert all(_released_soon(c) for c in wedged.made)
    with pytest.raises(ValueError, match=r"^open_timeout: expected a positive number of sec"):
        StereoCamera(0, 1, open_timeout=0)


_SET_HANGS = {
    "fourcc": (cv2.CAP_PROP_FOURCC, "setting its pixel format to 'MJPG'"),
    "width": (cv2.CAP_PROP_FRAME_WIDTH, "setting its frame width to 640"),
    "height": (cv2.CAP_PROP_FRAME_HEIGHT, "setting its frame height to 480"),
    "fps": (cv2.CAP_PROP_FPS, "setting its frame rate to 30 fps"),
}


@pytest.mark.filterwarnings("ignore:.* delivers no reported format:UserWarning")
@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("what", sorted(_SET_HANGS))
def test_a_camera_whose_set_hangs_is_given_up(
    wedged: type[_WedgedDevice], side: str, what: str
) -> None:
    """The open was bounded, but the size, rate and format asked of the camera after it
    (``cap.set``) ran on the caller's thread unbounded: a wedged V4L2 device hung there as in
    its open. Open and settings together are given up after ``open_timeout`` s, naming the
    source, the seconds and the setting; the capture is released once its set returns, never
    under it."""
    index = 0 if side == "left" else 1
    prop, doing = _SET_HANGS[what]
    wedged.wedged_props = {(index, prop)}
    t0 = time.perf_counter()
    with pytest.raises(SourceError) as err:
        StereoCamera(0, 1, image_size=(640, 480), fps=30, fourcc="MJPG", open_timeout=0.2)
    assert time.perf_counter() - t0 < 1.0
    assert str(err.value) == (
        f"{side} source camera {index} did not open within 0.2 s ({doing} did not return: a "
        "wedged camera or driver); unplug and replug it, or give it a longer timeout"
    )
    assert (err.value.side, err.value.end) == (side, False)
    wedged.unplug.set()  # the set returns at last: its capture is released then, not under it
    assert [c.src for c in wedged.made] == ([0, 1] if side == "right" else [0])
    assert all(_released_soon(c) for c in wedged.made)
    assert not any(c.released_busy for c in wedged.made)


def test_a_camera_whose_settings_read_hangs_is_given_up(wedged: type[_WedgedDevice]) -> None:
    """Reading back what the camera delivers (``cap.get``) hung as a set does."""
    wedged.wedged_props = {(1, cv2.CAP_PROP_FPS)}
    with pytest.raises(SourceError) as err:
        StereoCamera(0, 1, open_timeout=0.2)
    assert str(err.value) == (
        "right source camera 1 did not open within 0.2 s (reading back its settings did not "
        "return: a wedged camera or driver); unplug and replug it, or give it a longer timeout"
    )
    wedged.unplug.set()
    assert all(_released_soon(c) for c in wedged.made)
    assert not any(c.released_busy for c in wedged.made)


def test_a_given_capture_whose_set_hangs_is_given_up(wedged: type[_WedgedDevice]) -> None:
    """A capture object handed to StereoCamera is set up with the same bound."""
    left, right = _WedgedDevice("L"), _WedgedDevice("R")
    wedged.wedged_props = {("R", cv2.CAP_PROP_FRAME_WIDTH)}
    with pytest.raises(SourceError) as err:
        StereoCamera(left, right, image_size=(640, 480), open_timeout=0.2)
    # it was open already, and may be a camera: "did not open ... a stalled stream or network
    # share" said neither
    assert str(err.value) == (
        "right source _WedgedDevice was not set up within 0.2 s (setting its frame width to "
        "640 did not return: a wedged camera or driver, or a stalled stream); give it a longer "
        "timeout, or unplug and replug the camera"
    )
    wedged.unplug.set()
    assert _released_soon(left) and _released_soon(right) and not right.released_busy


def test_a_camera_is_opened_and_set_up_by_one_thread(wedged: type[_WedgedDevice]) -> None:
    """Bounding the settings costs no thread of their own: each source's open and settings run
    in one worker (None: in the caller's thread), and what it delivers is read as before."""
    main = threading.get_ident()
    for timeout in (0.5, None):
        cam = StereoCamera(0, 1, image_size=(640, 480), fps=30, open_timeout=timeout)
        for c in wedged.made:
            assert len(c.threads) == 1
            assert (next(iter(c.threads)) == main) == (timeout is None)
        assert cam.delivered_fps == {"left": 0.0, "right": 0.0}
        cam.close()
        assert [c.released for c in wedged.made] == [1, 1]
        wedged.made.clear()


@pytest.mark.parametrize("command", ["capture", "stream"])
def test_cli_read_timeout_bounds_the_settings(
    command: str, tmp_path: Path, wedged: type[_WedgedDevice], capsys: pytest.CaptureFixture[str]
) -> None:
    """``--read-timeout`` bounds what ``--size`` asks of a camera as it bounds the open."""
    from stereovision.cli import main

    wedged.wedged_props = {(0, cv2.CAP_PROP_FRAME_WIDTH)}
    argv = [command, "--left", "0", "--right", "1", "--read-timeout", "0.2", "--size", "640x480"]
    argv += ["-o", str(tmp_path / "p")] if command == "capture" else ["--no-display"]
    t0 = time.perf_counter()
    assert main(argv) == 2
    assert time.perf_counter() - t0 < 1.0
    assert capsys.readouterr().err == (
        "stereovision: error: left source camera 0 did not open within 0.2 s (setting its frame "
        "width to 640 did not return: a wedged camera or driver); unplug and replug it, or give "
        "it a longer timeout\n"
    )
    wedged.unplug.set()
    assert all(_released_soon(c) for c in wedged.made)


def test_calibrate_from_video_bounds_the_settings_read(wedged: type[_WedgedDevice]) -> None:
    """calibrate_from_video's cameras read back their settings after the open, bounded by
    ``read_timeout`` with it."""
    from stereovision.calibrate import calibrate_from_video

    wedged.wedged_props = {(0, cv2.CAP_PROP_FRAME_WIDTH)}
    t0 = time.perf_counter()
    with pytest.raises(SourceError, match=r"^left source camera 0 did not open within 0\.2 s \(re"):
        calibrate_from_video(0, 1, square_size=1.0, read_timeout=0.2)
    assert time.perf_counter() - t0 < 1.0
    wedged.unplug.set()
    assert all(_released_soon(c) for c in wedged.made)


def test_opencv_stays_quiet_until_a_given_up_open_returns(wedged: type[_WedgedDevice]) -> None:
    """The open's quiet OpenCV log ended when the open was given up, while the open went on in
    its thread: a late open (and its capture's release) could print OpenCV's lines to stderr.
    The log stays silent until that open returns, then is as it was."""
    log = cv2.utils.logging  # type: ignore[attr-defined]
    before = log.getLogLevel()
    assert before != log.LOG_LEVEL_SILENT
    wedged.wedged = {0}
    with pytest.raises(SourceError, match=r"did not open within 0\.2 s"):
        StereoCamera(0, 1, open_timeout=0.2)
    assert log.getLogLevel() == log.LOG_LEVEL_SILENT  # the open is still under way
    wedged.unplug.set()
    deadline = time.monotonic() + 2.0
    while log.getLogLevel() != before and time.monotonic() < deadline:
        time.sleep(0.01)
    assert log.getLogLevel() == before
    assert [c.src for c in wedged.made] == [0] and _released_soon(wedged.made[0])


@pytest.mark.parametrize("timeout", [math.inf, True])
def test_an_infinite_or_boolean_timeout_is_refused_by_name(timeout: object) -> None:
    """``open_timeout=math.inf`` (no limit meant; None is) passed the check and then overflowed
    the wait with "timestamp out of range for platform time_t", naming nothing; True passed as
    one second. Both are refused naming the keyword, before anything opens."""
    for call in (
        lambda: StereoCamera(0, 1, open_timeout=timeout),  # type: ignore[arg-type]
        lambda: capmod.read_within(object(), timeout),  # type: ignore[arg-type]
    ):
        with pytest.raises(ValueError, match=r"_timeout: expected a positive number of sec.*None"):
            call()


def test_a_stream_whose_open_hangs_is_not_told_to_be_unplugged(
    wedged: type[_WedgedDevice],
) -> None:
    """A network stream's open given up was told "unplug and replug it" (a device's advice), and
    nothing of a longer limit, though FFmpeg's own open waits 30 s to the 10 s default's."""
    url = "rtsp://192.0.2.1/stream"
    wedged.wedged = {url}  # type: ignore[assignment]
    with pytest.raises(SourceError) as err:
        StereoCamera(url, 1, open_timeout=0.2)
    assert str(err.value) == (
        f"left source {url!r} did not open within 0.2 s (its open did not return: a stalled "
        "stream or network share); give it a longer timeout"
    )
    wedged.unplug.set()  # its open returns: released (and not left to the next test)
    deadline = time.monotonic() + 2.0
    while not wedged.made and time.monotonic() < deadline:
        time.sleep(0.01)
    assert [c.src for c in wedged.made] == [url] and _released_soon(wedged.made[0])


def test_a_device_node_whose_setting_hangs_is_told_to_be_unplugged(
    wedged: type[_WedgedDevice], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """A camera named by its V4L2 node (``/dev/video7``, or a ``/dev/v4l/by-id`` link to it) is
    a device as its index is: its hung setting was said "a stalled stream or network share",
    with no word of unplugging it."""
    node = "/dev/video7"
    link = tmp_path / "usb-cam-video-index0"
    link.symlink_to(node)
    exists = os.path.exists
    monkeypatch.setattr(os.path, "exists", lambda p: os.fspath(p) in (node, str(link)) or exists(p))
    for src in (node, link):
        wedged.wedged_props = {(os.fspath(src), cv2.CAP_PROP_FRAME_WIDTH)}
        with pytest.raises(SourceError) as err:
            StereoCamera(src, 1, image_size=(640, 480), open_timeout=0.2)
        assert str(err.value) == (
            f"left source {capmod._describe_source(src)} did not open within 0.2 s (setting its "
            "frame width to 640 did not return: a wedged camera or driver); unplug and replug "
            "it, or give it a longer timeout"
        )
        wedged.unplug.set()
        assert _released_soon(wedged.made[-1])
        wedged.unplug.clear()


def test_a_camera_opened_in_time_is_kept(wedged: type[_WedgedDevice]) -> None:
    """Bounded opens keep what opens in time, unreleased; None opens without a thread."""
    for timeout in (0.5, None):
        cam = StereoCamera(0, 1, open_timeout=timeout)
        assert [c.released for c in wedged.made] == [0, 0]
        cam.close()
        assert [c.released for c in wedged.made] == [1, 1]
        wedged.made.clear()


@pytest.mark.parametrize("command", ["capture", "stream"])
def test_cli_read_timeout_bounds_the_open(
    command: str, tmp_path: Path, wedged: type[_WedgedDevice], capsys: pytest.CaptureFixture[str]
) -> None:
    """``--read-timeout`` bounds a camera's open as its reads: a wedged device hung the CLI
    before its first read, Ctrl-C held off by the open in native code."""
    from stereovision.cli import main

    wedged.wedged = {0}
    argv = [command, "--left", "0", "--right", "1", "--read-timeout", "0.2"]
    argv += ["-o", str(tmp_path / "p")] if command == "capture" else ["--no-display"]
    t0 = time.perf_counter()
    assert main(argv) == 2
    assert time.perf_counter() - t0 < 1.0
    assert capsys.readouterr().err == (
        "stereovision: error: left source camera 0 did not open within 0.2 s (its open did not "
        "return: a wedged camera or driver); unplug and replug it, or give it a longer timeout\n"
    )
    wedged.unplug.set()  # its open returns: released, not kept (nor left to the next test)
    deadline = time.monotonic() + 2.0
    while not wedged.made and time.monotonic() < deadline:
        time.sleep(0.01)
    assert [c.src for c in wedged.made] == [0] and _released_soon(wedged.made[0])


def test_cli_read_timeout_is_refused_with_a_bag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A bag's read waits on no camera: ``--read-timeout`` with ``--from-bag`` is refused (as
    ``--fps`` and ``--fourcc`` are), not ignored."""
    from stereovision.cli import main

    bag = ["--from-bag", str(tmp_path / "run.bag"), "--read-timeout", "30"]
    for argv in (["capture", *bag, "-o", str(tmp_path / "p")], ["stream", *bag, "--no-display"]):
        assert main(argv) == 2
        assert capsys.readouterr().err == (
            "stereovision: error: --read-timeout bounds a camera's read: a bag is read from disk\n"
        )
    assert not (tmp_path / "p").exists()


def test_capture_refuses_a_count_or_every_below_one(tmp_path: Path) -> None:
    for kw, said in (
        ({"count": 0}, r"^count: expected a positive number of pairs, got 0$"),
        ({"every": 0}, r"^every: expected a positive integer, got 0$"),
    ):
        with StereoCamera(_FakeCap("L", []), _FakeCap("R", [])) as cam:
            with pytest.raises(ValueError, match=said):
                capture(cam, tmp_path / "pairs", **kw)
            assert cam.count == 0  # nothing read
    assert not (tmp_path / "pairs").exists()


def test_capture_refuses_a_count_or_every_that_is_no_whole_number(tmp_path: Path) -> None:
    """count=2.5 saved 3 pairs, count=nan none ("count reached", at once), count=True one;
    every=nan saved no pair to the end of the source, every=2.5 every fifth. Each is refused
    before any read; a whole float (3.0) is still its integer."""
    nan = float("nan")
    for kw, said in (
        ({"count": 2.5}, "count: expected a positive number of pairs, got 2.5"),
        ({"count": nan}, "count: expected a positive number of pairs, got nan"),
        (
            {"count": np.float64(nan)},
            "count: expected a positive number of pairs, got np.float64(nan)",
        ),
        ({"count": True}, "count: expected a positive number of pairs, got True"),
        ({"count": "2"}, "count: expected a positive number of pairs, got '2'"),
        ({"every": 2.5}, "every: expected a positive integer, got 2.5"),
        ({"every": nan}, "every: expected a positive integer, got nan"),
        ({"every": np.True_}, "every: expected a positive integer, got np.True_"),
        ({"every": "2"}, "every: expected a positive integer, got '2'"),
    ):
        with StereoCamera(_FakeCap("L", [], frames=6), _FakeCap("R", [], frames=6)) as cam:
            with pytest.raises(ValueError) as err:
                capture(cam, tmp_path / "pairs", **kw)  # type: ignore[arg-type]
            assert str(err.value) == said and cam.count == 0  # nothing read
    assert not (tmp_path / "pairs").exists()
    with StereoCamera(_FakeCap("L", [], frames=6), _FakeCap("R", [], frames=6)) as cam:
        res = capture(cam, tmp_path / "pairs", count=3.0, every=2.0)  # type: ignore[arg-type]
    assert [p[0].name for p in res.saved] == ["left_0001.png", "left_0002.png", "left_0003.png"]
    assert res.frames_read == 5  # pairs 0, 2 and 4


def test_an_integer_beyond_a_float_is_refused_by_name(tmp_path: Path) -> None:
    """A Python int beyond a float's range (10**400) as a size side, a timeout or a rate
    raised math.isfinite's OverflowError ("int too large to convert to float"), naming
    nothing; each is refused as too large for what it is now, before any open."""
    from stereovision.capture import check_read_timeout

    big = 10**400
    with pytest.raises(
        ValueError,
        match=r"^image_size: at most 16384 px per side, got \(an integer of 401 digits, 480\)$",
    ):
        parse_size((big, 480), "image_size")
    for name in ("read_timeout", "open_timeout"):
        with pytest.raises(
            ValueError,
            match=rf"^{name}: expected at most [\d.e+]+ seconds .*got an integer of 401 digits$",
        ):
            check_read_timeout(big, name)  # type: ignore[arg-type]
    # its size, not its digits: 10**5000 has no str (Python's "Exceeds the limit (4300
    # digits)" ValueError, naming no keyword)
    huge = 10**5000
    with pytest.raises(
        ValueError, match=r"^image_size: at most .*got \(640, an integer of 5001 digits\)$"
    ):
        parse_size((640, huge), "image_size")
    with pytest.raises(
        ValueError,
        match=r"^image_size: expected .*got \(a negative integer of 5001 digits, 480\)$",
    ):
        parse_size([-huge, 480], "image_size")
    with pytest.raises(
        ValueError, match=r"^read_timeout: expected at most .*got an integer of 5001"
    ):
        check_read_timeout(huge)  # type: ignore[arg-type]
    with pytest.raises(
        ValueError,
        match=r"^open_timeout: expected a positive .*got a negative integer of 5001 digits$",
    ):
        check_read_timeout(-huge, "open_timeout")  # type: ignore[arg-type]
    missing = str(tmp_path / "none.avi")  # refused before the open: no FileNotFoundError
    with pytest.raises(ValueError, match=r"^fps: an integer of 401 digits is beyond a float's"):
        StereoCamera(missing, missing, fps=big)
    with pytest.raises(ValueError, match=r"^open_timeout: expected at most"):
        StereoCamera(missing, missing, open_timeout=big)


def test_source_errors_keep_their_attributes_when_reworded_or_pickled() -> None:
    import pickle

    err = SourceError("x", side="left", frames=3, other_had_frames=False, gap="left_003.png")
    for copy in (err.with_message("y"), pickle.loads(pickle.dumps(err))):
        assert copy._kwargs() == err._kwargs() and copy.ended_early
    assert str(err.with_message("y")) == "y" and str(pickle.loads(pickle.dumps(err))) == "x"


def test_frames_raise_a_failure_that_is_no_end() -> None:
    """frames() ends at a source's end, but a frame that does not decode is raised."""
    with StereoCamera(_FakeCap("L", []), _Undecodable("R", [])) as cam:
        with pytest.raises(SourceError, match="could not decode a frame"):
            list(cam.frames())
    with StereoCamera(_FakeCap("L", [], frames=2), _FakeCap("R", [], frames=2)) as cam:
        assert len(list(cam.frames())) == 2


def test_coverage_is_capped_and_its_bars_rounded() -> None:
    """Coverage is span / ROS's target span, at most 1; a bar has round(10 * coverage) marks."""
    col = ChessboardCollector((9, 6))
    col.kept = [(0.0, 0.0, 0.0, 0.0), (0.5, 3.0, 0.0, 0.0)]
    ranges = dict(zip(capmod.POSE_PARAM_NAMES, capmod.POSE_PARAM_RANGES, strict=True))
    prog = col.progress()
    assert prog["x"] == pytest.approx(min(1.0, 0.5 / ranges["x"])) and prog["y"] == 1.0
    assert prog["size"] == prog["skew"] == 0.0
    col.kept = [(0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.07 * ranges["skew"])]
    assert "skew [#---------]   7%" in col.format_progress()  # 0.7 of a mark rounds to 1


def test_live_board_corners_start_at_the_top_left_whichever_way_the_board_turns() -> None:
    """A board turned half round is found with its corners in the opposite order; they are
    given back starting at the top left, as calibrate.find_corners orders them."""
    img = _board(POSE_A, 0, False)
    for view in (img, np.ascontiguousarray(img[::-1, ::-1])):
        c = detect_board_live(view, (9, 6))
        assert c is not None and c[0].sum() < c[-1].sum()


def test_save_pair_through_a_link_to_nothing_or_under_a_file_says_so(tmp_path: Path) -> None:
    """A pairs/ link to a folder that is not there (an unmounted drive) was mkdir's bare
    "[Errno 17] File exists", as if the folder were there, and a folder under a file
    "[Errno 20] Not a directory"; both name what stands in the way (io.make_folder)."""
    img = np.zeros((4, 6), np.uint8)
    (tmp_path / "pairs").symlink_to(tmp_path / "drive" / "pairs")
    (tmp_path / "notes").write_bytes(b"x")
    for folder, says in (
        ("pairs", f"pairs is a link to {tmp_path / 'drive' / 'pairs'}, which does not exist"),
        ("notes/pairs", "notes is a file, not a folder"),
    ):
        with pytest.raises(NotADirectoryError) as exc:
            save_pair(tmp_path / folder, 0, img, img)
        assert str(exc.value) == f"cannot make the folder {tmp_path / folder}: {tmp_path / says}"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes", "pairs"]
    with pytest.raises(FileExistsError) as fe:  # capture() stops on it: not a number taken
        save_pair(tmp_path / "notes", 0, img, img)
    assert (
        str(fe.value)
        == f"cannot write the pair into {tmp_path / 'notes'}: it is a file, not a folder"
    )


def test_save_pair_refuses_a_negative_or_fractional_index(tmp_path: Path) -> None:
    """save_pair(-1) wrote left_-001.png, a name no pair numbering reads (next_pair_index
    skipped it); 1.0 failed on the format code. Both are refused naming the index, before any
    folder or file is made."""
    img = np.zeros((8, 8, 3), np.uint8)
    for bad in (-1, 1.0, True):
        with pytest.raises(ValueError, match=rf"^index: expected a pair number >= 0, got {bad!r}$"):
            save_pair(tmp_path / "pairs", bad, img, img)  # type: ignore[arg-type]
    assert not (tmp_path / "pairs").exists()
    assert [p.name for p in save_pair(tmp_path / "pairs", np.int64(0), img, img)] == [
        "left_0000.png",
        "right_0000.png",
    ]


def test_numpy_and_bool_sources() -> None:
    """A NumPy integer is a device index (parse_source failed with "'numpy.int64' object has no
    attribute 'strip'"); a bool is no camera (True opened camera 1)."""
    assert parse_source(np.int64(2)) == 2 and type(parse_source(np.int64(2))) is int
    with pytest.raises(ValueError, match=r"^camera index -3 is negative"):
        parse_source(np.int32(-3))
    for flag in (True, np.True_):
        with pytest.raises(ValueError, match=r"^camera source: expected a device index or a path"):
            parse_source(flag)  # type: ignore[arg-type]
        with pytest.raises(ValueError, match=r"^left source: expected a device index or a path"):
            StereoCamera(flag, 0)  # type: ignore[arg-type]


def test_a_numpy_device_index_that_cannot_open_is_named_a_camera() -> None:
    """A NumPy index now reaches StereoCamera as a device (calibrate_from_video passes it on);
    one that could not open was 'cannot open left source int64', the type's name for the
    camera's number."""
    with pytest.raises(SourceError, match=r"^cannot open left source camera 97 "):
        StereoCamera(np.int64(97), np.int64(98))


def test_a_resized_sources_warning_points_at_the_callers_line(tmp_path: Path) -> None:
    """StereoCamera's resized-frames and another-shape warnings had ``stacklevel=3``, right for
    a ``read()`` of the user's only: through ``frames()`` they named capture.py's loop, through
    ``capture()`` its line; each is the caller's line now (through ``frames()``, the user's
    ``for``, the line that advanced the generator)."""
    frames = [_numbered(i) for i in range(3)]
    frames[1] = cv2.resize(frames[1], (160, 120), interpolation=cv2.INTER_AREA)  # half size
    lpat = _write_sequence(tmp_path / "seq", "left", frames)
    rpat = _write_sequence(tmp_path / "seq", "right", [_numbered(i) for i in range(3)])
    size = (320, 180)  # another shape than the frames': dropped, with a warning
    with (
        warnings.catch_warnings(record=True) as caught,
        StereoCamera(lpat, rpat, image_size=size) as cam,
    ):
        warnings.simplefilter("always")
        for _ in range(3):
            cam.read()
    assert [w.filename for w in caught] == [__file__, __file__], [str(w.message) for w in caught]
    with (
        warnings.catch_warnings(record=True) as caught,
        StereoCamera(lpat, rpat, image_size=size) as cam,
    ):
        warnings.simplefilter("always")
        for _ in cam.frames():
            pass
    assert [w.filename for w in caught] == [__file__, __file__]
    with (
        warnings.catch_warnings(record=True) as caught,
        StereoCamera(lpat, rpat, image_size=size) as cam,
    ):
        warnings.simplefilter("always")
        capture(cam, tmp_path / "pairs")
    said = [w.filename for w in caught if "delivers" in str(w.message)]
    assert said == [__file__, __file__]


def test_skew_median_is_exact_up_to_a_full_window() -> None:
    """With exactly SKEW_WINDOW skews the window still holds every one: the median is exact,
    not the histogram's estimate (a mutation audit's '<' for '<=' survived)."""
    import statistics

    values = [float(v) for v in np.random.default_rng(7).gamma(2.0, 0.2, capmod.SKEW_WINDOW)]
    stats = capmod.SkewStats()
    for v in values:
        stats.append(v)
    assert stats.median_ms() == statistics.median(values)


def test_resize_frame_shrinks_by_area_and_enlarges_linearly() -> None:
    """resize_frame is the sources' resize: INTER_AREA to shrink (no aliasing), INTER_LINEAR to
    enlarge, the frame itself at its own size (a mutation audit's linear shrink survived)."""
    img = np.random.default_rng(3).integers(0, 256, (60, 80, 3), dtype=np.uint8)
    assert capmod.resize_frame(img, (80, 60)) is img
    small = cv2.resize(img, (30, 20), interpolation=cv2.INTER_AREA)
    np.testing.assert_array_equal(capmod.resize_frame(img, (30, 20)), small)
    big = cv2.resize(img, (160, 120), interpolation=cv2.INTER_LINEAR)
    np.testing.assert_array_equal(capmod.resize_frame(img, (160, 120)), big)


def test_stale_temps_are_listed_sorted_and_another_users_are_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """remove_stale_temps returns the names it removed sorted, whatever the folder's order; a
    process it may not signal (another user's: PermissionError) is taken as alive and its
    temporary file kept (both survived a mutation audit)."""
    names = [f".left_{i:04d}.png.{999_999_000 + i}-0a1b2c3d.tmp" for i in range(12)]
    for name in reversed(names):
        (tmp_path / name).write_bytes(b"half a png")
    assert capmod.remove_stale_temps(tmp_path) == sorted(names)
    assert list(tmp_path.iterdir()) == []

    def denied(pid: int, sig: int) -> None:
        raise PermissionError(1, "Operation not permitted")

    (tmp_path / names[0]).write_bytes(b"half a png")
    monkeypatch.setattr(capmod.os, "kill", denied)
    assert capmod.remove_stale_temps(tmp_path) == []
    assert [p.name for p in tmp_path.iterdir()] == [names[0]]


def test_a_sequence_gap_counts_from_the_first_number_and_a_read_only_node_is_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A sequence from 1 read to 3 images stopped at its missing 4th file (not the 3rd, as
    counting from 0 put it); a camera node readable but not writable is said not readable, as
    the capture needs both (each survived a mutation audit)."""
    for i in (1, 2, 3, 5):
        cv2.imwrite(str(tmp_path / f"left_{i:04d}.png"), np.zeros((4, 4), np.uint8))
    assert capmod._sequence_gap(str(tmp_path / "left_%04d.png"), 3) == ("left_0004.png", 1)
    monkeypatch.setattr(capmod.os.path, "exists", lambda p: True)
    monkeypatch.setattr(capmod.os.path, "isdir", lambda p: True)
    monkeypatch.setattr(capmod.os, "access", lambda p, mode: mode == os.R_OK)
    assert (
        capmod.camera_hint(3)
        == " (/dev/video3 is not readable: is this user in the 'video' group?)"
    )


_SET_REFUSED = (
    "OpenCV(5.1.0) /io/opencv/modules/videoio/src/cap.cpp:606: error: (-2:Unspecified error) "
    "could not set prop 3 = 640.000000 in function 'set'\n"
)


@pytest.mark.parametrize("timeout", [0.5, None])
def test_a_setting_opencv_raises_on_names_the_source_and_the_step(
    tmp_path: Path, timeout: float | None
) -> None:
    """A capture in OpenCV's exception mode raises cv2.error on a setting it refuses (a video
    file asked for 640 px): it came out raw, naming neither the side nor the setting. It is a
    SourceError as a hung setting's, with OpenCV's words, chaining the cv2.error; the capture
    is released as a hung one is."""
    video = str(_write_video(tmp_path / "v.avi", [_numbered(i) for i in range(3)]))
    caps = [cv2.VideoCapture(video), cv2.VideoCapture(video)]
    for cap in caps:
        cap.setExceptionMode(True)
    with pytest.raises(SourceError) as err:
        StereoCamera(*caps, image_size=(640, 480), open_timeout=timeout)
    assert str(err.value) == (
        "left source VideoCapture was not set up: setting its frame width to 640 failed in "
        "OpenCV (could not set prop 3 = 640.000000)"
    )
    assert (err.value.side, err.value.end) == ("left", False)
    assert isinstance(err.value.__cause__, cv2.error)
    assert not caps[0].isOpened()
    caps[1].release()  # not reached: the left source failed first


@pytest.mark.parametrize("command", ["capture", "stream"])
def test_cli_says_a_setting_opencv_raised_on_in_one_line(
    command: str,
    tmp_path: Path,
    wedged: type[_WedgedDevice],
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The CLI printed OpenCV's cv2.error as an internal error ("please report this"): it is
    the camera's, said in one line naming the source and the setting, exit 2."""
    from stereovision.cli import main

    def refused(self: _WedgedDevice, prop: int, value: float) -> bool:
        if self.src == 1 and prop == cv2.CAP_PROP_FRAME_WIDTH:
            raise cv2.error(_SET_REFUSED)
        return True

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_WedgedDevice, "set", refused)
        argv = [command, "--left", "0", "--right", "1", "--size", "640x480"]
        argv += ["-o", str(tmp_path / "p")] if command == "capture" else ["--no-display"]
        assert main(argv) == 2
    assert capsys.readouterr().err == (
        "stereovision: error: right source camera 1 was not set up: setting its frame width to "
        "640 failed in OpenCV (could not set prop 3 = 640.000000)\n"
    )
    assert [c.released for c in wedged.made] == [1, 1]


@pytest.mark.parametrize("timeout", [0.5, None])
def test_an_open_opencv_raises_on_names_the_source(
    monkeypatch: pytest.MonkeyPatch, timeout: float | None
) -> None:
    """cv2.error out of the open itself (a backend in exception mode) came out raw as well: a
    SourceError naming the source, chaining it."""

    def refused(src: Any, *args: Any) -> Any:
        raise cv2.error(
            "OpenCV(5.1.0) cap.cpp:1: error: (-2:Unspecified error) could not open camera 0 in "
            "function 'open'\n"
        )

    monkeypatch.setattr(cv2, "VideoCapture", refused)
    with pytest.raises(SourceError) as err:
        StereoCamera(0, 1, open_timeout=timeout)
    assert str(err.value) == (
        "left source camera 0 did not open: OpenCV failed (could not open camera 0)"
    )
    assert (err.value.side, err.value.end) == ("left", False)
    assert isinstance(err.value.__cause__, cv2.error)


@pytest.mark.parametrize(
    ("name", "first"),
    [
        ("f_%03d.png", 5),
        ("f_%04d.png", 1007),
        ("f_%d.png", 12),
        ("cam2_%03d.png", 3),
        ("cam2_%03d.png", 9),
    ],
)
def test_an_image_sequence_opens_from_its_first_number_however_late(
    tmp_path: Path, name: str, first: int
) -> None:
    """OpenCV's image reader and FFmpeg's look for a sequence's first file among numbers 0-4:
    one starting at 5 or later did not open ("cannot open left source"), and one at 2-4 opened
    by its first file had OpenCV take the other digits in its name for the number (cam2_003.png
    read as "cam%01d_003.png" from 2: one frame). Each opens from its first number, reads
    every image in turn and tells a gap as a sequence from 0 does."""
    folder = tmp_path / "seq"
    folder.mkdir()
    for i in range(first, first + 4):
        cv2.imwrite(str(folder / (name % i)), _numbered(i))
    pattern = str(folder / name)
    with StereoCamera(pattern, pattern) as cam:
        got = list(cam.frames())
        assert cam.delivered_fps == {"left": 0.0, "right": 0.0}  # no rate, as CAP_IMAGES
        assert cam.delivered_size == {"left": SMALL, "right": SMALL}
    assert [_read_stamp(f.left) for f in got] == list(range(first, first + 4))
    assert all(math.isnan(f.pos_left_ms) for f in got)
    (folder / (name % (first + 1))).unlink()
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 1
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 1 image: {name % (first + 1)} is missing, so the "
        "2 images numbered after it were not read"
    )


def test_a_pattern_with_a_literal_percent_sign_opens(tmp_path: Path) -> None:
    """``%%`` is printf's (and OpenCV's) literal percent sign: ``take_50%%_%03d.png`` names
    take_50%_000.png ... Our pattern code matched it as two percent signs ("no file matches
    take_50%%_%03d.png"); it opens, and a misnumbered one is told a pattern, escaped, that
    opens."""
    folder = tmp_path / "seq"
    folder.mkdir()
    for i in range(3):
        cv2.imwrite(str(folder / f"take_50%_{i:03d}.png"), _numbered(i))
        cv2.imwrite(str(folder / f"right_{i:03d}.png"), _numbered(i))
    right = str(folder / "right_%03d.png")
    with StereoCamera(str(folder / "take_50%%_%03d.png"), right) as cam:
        assert [_read_stamp(f.left) for f in cam.frames()] == [0, 1, 2]
    with pytest.raises(FileNotFoundError) as err:
        StereoCamera(str(folder / "take_50%%_%04d.png"), right)
    told = str(folder / "take_50%%_%03d.png")
    assert str(err.value) == (
        f"left source: no file fits {folder}/take_50%%_%04d.png; give a pattern such as {told} "
        "(its files are named take_50%_000.png, take_50%_001.png ...)"
    )
    with StereoCamera(told, right) as cam:  # what it was told opens
        assert cam.read().left.shape == (240, 320, 3)
    # a file whose name holds a single percent sign is that file, as before
    cv2.imwrite(str(folder / "50%.png"), _numbered(7))
    with StereoCamera(str(folder / "50%.png"), str(folder / "right_000.png")) as cam:
        assert _read_stamp(cam.read().left) == 7


class _FailsToRead(_FakeCap):
    """A backend in OpenCV's exception mode failing mid-stream: ``step`` raises cv2.error on
    its ``at``-th call."""

    def __init__(self, name: str, log: list[str], step: str, at: int) -> None:
        super().__init__(name, log, frames=10)
        self.step, self.at, self.calls = step, at, 0

    def _maybe_fail(self, step: str) -> None:
        if step == self.step:
            self.calls += 1
            if self.calls == self.at:
                raise cv2.error(
                    "OpenCV(5.1.0) cap_ffmpeg.cpp:1: error: (-2:Unspecified error) packet read "
                    "failed in function 'grabFrame'\n"
                )

    def getBackendName(self) -> str:
        return "FFMPEG"

    def grab(self) -> bool:
        self._maybe_fail("grab")
        return super().grab()

    def retrieve(self) -> tuple[bool, np.ndarray]:
        self._maybe_fail("retrieve")
        return super().retrieve()


@pytest.mark.parametrize("step", ["grab", "retrieve"])
@pytest.mark.parametrize("timeout", [0.5, None])
def test_a_read_opencv_raises_on_is_a_source_error_naming_the_side(
    tmp_path: Path, step: str, timeout: float | None
) -> None:
    """A cv2.error out of a grab or retrieve after the open came out raw (the CLI called it an
    internal error): a SourceError naming the side, the step and the pair, not an end, chaining
    it; the pairs saved before it are kept and said."""
    log: list[str] = []
    cam = StereoCamera(_FakeCap("L", log, frames=10), _FailsToRead("R", log, step, at=2))
    with pytest.raises(SourceError) as err:
        capture(cam, tmp_path / "pairs", read_timeout=timeout)
    assert str(err.value) == (
        f"right source _FailsToRead failed in OpenCV's {step} of pair 2 (packet read failed); "
        f"1 pair was saved in {tmp_path / 'pairs'} and is kept"
    )
    assert (err.value.side, err.value.end, err.value.frames) == ("right", False, 1)
    assert isinstance(err.value.__cause__, SourceError)  # the read's, said with what was kept
    assert isinstance(err.value.__cause__.__cause__, cv2.error)
    assert sorted(p.name for p in (tmp_path / "pairs").iterdir()) == [
        "left_0001.png",
        "right_0001.png",
    ]
    cam.close()


@pytest.mark.parametrize("command", ["capture", "stream"])
def test_cli_says_a_read_opencv_raised_on_in_one_line(
    command: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The CLI printed a cv2.error of a read as an internal error: one line naming the side,
    exit 2."""
    from stereovision.cli import main

    left, right = _videos(tmp_path, 3, 3)
    log: list[str] = []
    made = {
        str(left): _FailsToRead("L", log, "none", at=1),
        str(right): _FailsToRead("R", log, "grab", at=1),
    }
    monkeypatch.setattr(capmod, "_open_path", lambda path, first: made[path])
    argv = [command, "--left", str(left), "--right", str(right)]
    argv += ["-o", str(tmp_path / "p")] if command == "capture" else ["--no-display"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        f"stereovision: error: right source {str(right)!r} failed in OpenCV's grab of pair 1 "
        "(packet read failed)"
    )
    assert err.count("\n") == 1 and "internal" not in err


@pytest.mark.parametrize(
    ("name", "files", "told"),
    [
        ("left_%d.png", [f"left_{i:02d}.png" for i in range(1, 151)], "left_%02d.png"),
        ("left_%03d.png", [f"left_{i:02d}.png" for i in range(1, 151)], "left_%02d.png"),
        ("left_%d.png", [f"left_{i:04d}.png" for i in range(1, 1101)], "left_%04d.png"),
    ],
)
def test_a_misnumbered_pattern_over_a_long_run_is_told_not_opened_part_way(
    tmp_path: Path, name: str, files: list[str], told: str
) -> None:
    """A pattern that prints the numbers of a run's later files alone (left_%d.png over
    left_01.png ... left_150.png prints 10-150 as they are named) opened the run from the
    lowest of those, the images before it silently left out (left_%d.png read from left_10.png,
    left_%03d.png from left_100.png); it was, and is again, told the pattern of the files."""
    folder = tmp_path / "seq"
    folder.mkdir()
    img = np.zeros((8, 8, 3), np.uint8)
    for f in files:
        cv2.imwrite(str(folder / f), img)
    with pytest.raises(FileNotFoundError) as err:
        StereoCamera(str(folder / name), str(folder / name))
    assert str(err.value) == (
        f"left source: no file fits {folder / name}; give a pattern such as {folder / told} "
        f"(its files are named {files[0]}, {files[1]} ...)"
    )


@pytest.mark.parametrize("first", [0, 7])
def test_a_gap_counts_every_image_after_it_in_a_folder_of_more_files_than_a_hint_lists(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, first: int
) -> None:
    """The start of a late sequence and the images after a gap were looked for among the
    first _HINT_MAX_FILES files the folder lists (in the file system's order, 20000): a
    longer sequence was told fewer images after its gap than there are (and a late one could
    start at a later number). Every file counts; the cap is made 3 here to stand for a folder
    of more files than it."""
    monkeypatch.setattr(capmod, "_HINT_MAX_FILES", 3)
    folder = tmp_path / "seq"
    folder.mkdir()
    for i in range(first, first + 10):
        if i != first + 2:
            cv2.imwrite(str(folder / f"f_{i:03d}.png"), _numbered(i))
    pattern = str(folder / "f_%03d.png")
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 2
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 2 images: f_{first + 2:03d}.png is missing, so the "
        "7 images numbered after it were not read"
    )


def test_capture_refuses_to_save_into_the_sequence_it_reads_through_a_folder_with_a_percent(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A folder named with a percent sign is written ``%%`` in a pattern (printf's, OpenCV's):
    ``50%% done/left_%04d.png`` reads ``50% done/``. The guard against saving into the
    sequence read compared the folder as written (``50%% done``, which is no folder), so
    ``-o '50% done'`` was let through: each pair saved became the next frame, the source's
    own images overwritten (left_0001.png) and the capture without end. It is refused, one
    line, nothing written."""
    from stereovision.cli import main

    pairs = tmp_path / "50% done"
    pairs.mkdir()
    for i in range(1, 4):
        cv2.imwrite(str(pairs / f"left_{i:04d}.png"), _numbered(i))
        cv2.imwrite(str(pairs / f"right_{i:04d}.png"), _numbered(i, shade=160))
    written = tmp_path / "50%% done"
    lpat, rpat = str(written / "left_%04d.png"), str(written / "right_%04d.png")
    before = {p.name: p.read_bytes() for p in pairs.iterdir()}
    # count bounds each call: without the refusal they would save pairs for ever, not fail
    argv = ["capture", "--left", lpat, "--right", rpat, "-o", str(pairs), "--count", "5"]
    assert main(argv) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: error: -o {pairs}: the source {lpat} would read the pairs saved there as "
        "its next frames, without end; save them in another folder"
    ]
    with StereoCamera(lpat, rpat) as cam, pytest.raises(ValueError, match="without end"):
        capture(cam, pairs, count=5)
    assert {p.name: p.read_bytes() for p in pairs.iterdir()} == before


@pytest.mark.parametrize("first", [0, 7])
def test_an_image_that_does_not_read_is_not_told_missing(tmp_path: Path, first: int) -> None:
    """A sequence stopped by an image that is there but does not read (damaged) was told
    "f_003.png is missing, so the 1 image numbered after it was not read (renumber them without
    the gap)": it is told it does not read, the images after it still counted."""
    folder = tmp_path / "seq"
    folder.mkdir()
    for i in range(first, first + 5):
        cv2.imwrite(str(folder / f"f_{i:03d}.png"), _numbered(i))
    (folder / f"f_{first + 3:03d}.png").write_bytes(b"not a png")
    pattern = str(folder / "f_%03d.png")
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 3
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 3 images: f_{first + 3:03d}.png does not read "
        "(damaged?), so the 1 image numbered after it was not read (replace or remove it)"
    )


@pytest.mark.parametrize(("first", "at_open"), [(0, 0), (7, 2)])
def test_a_sequence_lists_its_folder_once_a_side_to_open_and_once_at_its_end(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, first: int, at_open: int
) -> None:
    """Each listing of a folder of 200,000 files takes a fifth of a second or more: a sequence
    starting at 7 listed its folder three times a side to open (the files-match check, the
    start looked for, then again in the open) and twice a side at its end (10 pairs among
    200,000 files: 3.0 s, now 1.1 s, median of 5), one from 0 once a side to open for that check
    alone (1.3 s, now 0.6 s). A sequence found needs no listing to know it has files; a late one
    is listed once, and its end looks once for images after a gap."""
    folder = tmp_path / "seq"
    folder.mkdir()
    for side in ("l", "r"):
        for i in range(first, first + 3):
            cv2.imwrite(str(folder / f"{side}_{i:03d}.png"), _numbered(i))
    listed: list[str] = []
    scandir = os.scandir

    def counting(path: Any = ".") -> Any:
        if os.fspath(path) == str(folder):
            listed.append(os.fspath(path))
        return scandir(path)

    monkeypatch.setattr(os, "scandir", counting)
    with StereoCamera(str(folder / "l_%03d.png"), str(folder / "r_%03d.png")) as cam:
        assert len(listed) == at_open
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 3
    assert result.ended == "end of stream"
    assert len(listed) == at_open + 2


def test_an_image_that_does_not_read_in_a_folder_with_a_percent_is_not_told_missing(
    tmp_path: Path,
) -> None:
    """The damaged image was looked for in the folder as written ("50%% done"), where it is
    not: in "50% done" a sequence stopped by an image that does not read was still told "is
    missing ... (renumber them without the gap)"."""
    folder = tmp_path / "50% done"
    folder.mkdir()
    for i in range(5):
        cv2.imwrite(str(folder / f"f_{i:03d}.png"), _numbered(i))
    (folder / "f_003.png").write_bytes(b"not a png")
    pattern = str(tmp_path / "50%% done" / "f_%03d.png")
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 3
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 3 images: f_003.png does not read "
        "(damaged?), so the 1 image numbered after it was not read (replace or remove it)"
    )


@pytest.mark.parametrize("folder_name", ["100%", "50%%"])
def test_a_sequence_in_a_folder_named_with_a_percent_sign_opens(
    tmp_path: Path, folder_name: str
) -> None:
    """CAP_IMAGES takes a path's first "%" for the number and FFmpeg refuses a lone one, so
    "100%/l_%03d.png" (read by our pattern code as the folder 100%) was "cannot open left
    source"; it is read by _ImageSequence as a "%%" is. A folder "50%%" is written "50%%%%"."""
    folder = tmp_path / folder_name
    folder.mkdir()
    for i in range(3):
        cv2.imwrite(str(folder / f"l_{i:03d}.png"), _numbered(i))
    pattern = str(tmp_path / folder_name.replace("%", "%%") / "l_%03d.png")
    with StereoCamera(pattern, pattern) as cam:
        assert [_read_stamp(f.left) for f in cam.frames()] == [0, 1, 2]
    if folder_name == "100%":  # the folder as written, its lone "%" read as itself
        lone = str(folder / "l_%03d.png")
        with StereoCamera(lone, lone) as cam:
            assert [_read_stamp(f.right) for f in cam.frames()] == [0, 1, 2]


def test_the_image_sequence_reader_seeks_and_counts_as_opencvs(tmp_path: Path) -> None:
    """_ImageSequence stands in for CAP_IMAGES, but its set() refused every property, "as
    CAP_IMAGES refuses them too": CAP_IMAGES seeks on CAP_PROP_POS_FRAMES (kept within its
    count). Both readers now give the same frames, positions and answers for the same calls."""
    for i in range(6):
        cv2.imwrite(str(tmp_path / f"s_{i:03d}.png"), _numbered(i))
    pattern = str(tmp_path / "s_%03d.png")

    def session(cap: Any) -> list[object]:
        said: list[object] = [cap.get(cv2.CAP_PROP_FRAME_COUNT), cap.get(cv2.CAP_PROP_POS_FRAMES)]
        for seek in (None, None, 0, 99, -3, 2.6, None):
            if seek is not None:
                said.append(cap.set(cv2.CAP_PROP_POS_FRAMES, seek))
            ok, frame = cap.read()
            said += [ok, _read_stamp(frame) if ok else None, cap.get(cv2.CAP_PROP_POS_FRAMES)]
        said.append(cap.set(cv2.CAP_PROP_FPS, 5.0))
        cap.release()
        cap.release()  # twice, as OpenCV allows
        said += [cap.isOpened(), cap.read()[0]]
        return said

    opencv = session(cv2.VideoCapture(pattern, cv2.CAP_IMAGES))
    assert opencv[:2] == [6.0, 0.0]
    assert opencv[2:5] == [True, 0, 1.0]  # the first image, then position 1
    assert session(capmod._ImageSequence(pattern, 0)) == opencv


def test_the_image_sequence_reader_answers_ratio_count_and_size_as_opencvs(
    tmp_path: Path,
) -> None:
    """Beside CAP_IMAGES on the same sequences (from 0, where both open), _ImageSequence
    refused a seek by CAP_PROP_POS_AVI_RATIO and said 0 for it, counted a stray file that is
    no image in the numbering among its frames (FRAME_COUNT 6 where CAP_IMAGES says 3, and 3
    are read), and said the first frame's size after a frame of another size was read. Both
    now give the same answers, frames and positions; where they differ (a seek by
    milliseconds, the ratio past the last frame) ours is the documented answer."""
    sizes = {2: (200, 150)}  # frame 2 at another size: each frame is read at its own
    for i in range(6):
        cv2.imwrite(str(tmp_path / f"s_{i:03d}.png"), _numbered(i, sizes.get(i, SMALL)))
    pattern = str(tmp_path / "s_%03d.png")

    def session(cap: Any) -> list[object]:
        said: list[object] = [cap.get(cv2.CAP_PROP_FRAME_COUNT)]
        for seek in (None, 0.5, None, 1.0, -0.5, 0.3, 7.0, 0.0, 0.1):
            if seek is not None:
                said.append(cap.set(cv2.CAP_PROP_POS_AVI_RATIO, seek))
            said.append(cap.get(cv2.CAP_PROP_POS_AVI_RATIO))
            ok, frame = cap.read()
            said += [ok, _read_stamp(frame) if ok else None, cap.get(cv2.CAP_PROP_POS_FRAMES)]
            said += [cap.get(cv2.CAP_PROP_FRAME_WIDTH), cap.get(cv2.CAP_PROP_FRAME_HEIGHT)]
            if cap.get(cv2.CAP_PROP_POS_FRAMES) < 6:  # past the last frame: below
                said.append(cap.get(cv2.CAP_PROP_POS_AVI_RATIO))
        return said

    opencv = session(cv2.VideoCapture(pattern, cv2.CAP_IMAGES))
    # ratio 0.5 of 5 frames' span is frame 2.5, rounded half to even: the 200x150 frame 2
    assert opencv[:10] == [6.0, 0.0, True, 0, 1.0, *SMALL, 0.2, True, 0.4]
    assert opencv[10:16] == [True, 2, 3.0, 200.0, 150.0, 0.6]
    assert session(capmod._ImageSequence(pattern, 0)) == opencv

    # a gap (s_003.png missing), then a stray file that is no image in its place: both count
    # and read the 3 images before it
    (tmp_path / "s_003.png").unlink()
    for stray in (False, True):
        if stray:
            (tmp_path / "s_003.png").write_text("not an image")
        caps = (cv2.VideoCapture(pattern, cv2.CAP_IMAGES), capmod._ImageSequence(pattern, 0))
        for cap in caps:
            assert cap.get(cv2.CAP_PROP_FRAME_COUNT) == 3.0
            assert [cap.read()[0] for _ in range(5)] == [True] * 3 + [False] * 2
            assert cap.set(cv2.CAP_PROP_POS_AVI_RATIO, 1.0) is True
            assert _read_stamp(cap.read()[1]) == 2  # the last of the 3

    # where ours differs, as documented: a seek by milliseconds (an image has no media time)
    # CAP_IMAGES takes for a frame number; the ratio past the last frame it says above 1
    cv_cap, ours = cv2.VideoCapture(pattern, cv2.CAP_IMAGES), capmod._ImageSequence(pattern, 0)
    assert cv_cap.set(cv2.CAP_PROP_POS_MSEC, 2.0) is True
    assert cv_cap.get(cv2.CAP_PROP_POS_FRAMES) == 2.0 and cv_cap.get(cv2.CAP_PROP_POS_MSEC) == -1
    assert ours.set(cv2.CAP_PROP_POS_MSEC, 2.0) is False
    assert ours.get(cv2.CAP_PROP_POS_FRAMES) == 0.0 and ours.get(cv2.CAP_PROP_POS_MSEC) == -1
    for cap in (cv_cap, ours):
        cap.set(cv2.CAP_PROP_POS_FRAMES, 2)
        assert cap.read()[0] and not cap.read()[0]
    assert cv_cap.get(cv2.CAP_PROP_POS_AVI_RATIO) == 1.5  # 3 read of 3, over the span 2
    assert ours.get(cv2.CAP_PROP_POS_AVI_RATIO) == 1.0
    one = tmp_path / "one_%d.png"
    cv2.imwrite(str(tmp_path / "one_0.png"), _numbered(0))
    single = capmod._ImageSequence(str(one), 0)
    assert single.get(cv2.CAP_PROP_POS_AVI_RATIO) == 0.0  # CAP_IMAGES: NaN (0 / 0)
    assert single.read()[0] and single.get(cv2.CAP_PROP_POS_AVI_RATIO) == 1.0  # inf


def test_the_image_sequence_reader_opens_without_opencvs_missing_file_warning(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """_ImageSequence counted its frames with cv2.haveImageReader (f6c5c37), which on the
    missing file ending the run logs OpenCV's "can't open/read file" warning: a line on
    stderr at every open of a sequence from 5 on. The count asks the file's presence first:
    the open says nothing, the count is the same."""
    for i in range(7, 10):
        cv2.imwrite(str(tmp_path / f"s_{i:03d}.png"), _numbered(i))
    capfd.readouterr()
    seq = capmod._ImageSequence(str(tmp_path / "s_%03d.png"), 7)
    assert seq.get(cv2.CAP_PROP_FRAME_COUNT) == 3.0
    assert "s_010.png" not in capfd.readouterr().err


def test_a_space_padded_sequence_opens_from_its_first_number_however_late(
    tmp_path: Path,
) -> None:
    """printf's (and CAP_IMAGES's) "%3d" pads with spaces: sp_  7.png ... sp_ 12.png. From 0-4
    it opened; from 7 our listing took only digits for numbers and told "no file fits
    sp_%3d.png; give a pattern such as sp_  %d.png", which reads 7-9 alone. It opens, all six
    read, and a gap in it is told."""
    for i in range(7, 13):
        cv2.imwrite(str(tmp_path / f"sp_{i:3d}.png"), _numbered(i))
    pattern = str(tmp_path / "sp_%3d.png")
    with StereoCamera(pattern, pattern) as cam:
        assert [_read_stamp(f.left) for f in cam.frames()] == list(range(7, 13))
    (tmp_path / "sp_ 10.png").unlink()
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 3
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 3 images: sp_ 10.png is missing, so the 2 images "
        "numbered after it were not read"
    )


def test_a_misnumbered_pattern_lists_its_folder_twice_to_be_told(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A pattern misnumbered for its files (l_%02d.png over l_000.png ...) listed its folder
    three times before its hint (the start looked for, the files-match glob, the hint's own
    glob): 0.5 s among 200,000 files, twice the 0.24 s before af641c1. The hint takes the
    files the check listed: two listings, the hint unchanged."""
    for i in range(3):
        cv2.imwrite(str(tmp_path / f"l_{i:03d}.png"), _numbered(i))
    listed: list[str] = []
    scandir = os.scandir

    def counting(path: Any = ".") -> Any:
        if os.fspath(path) == str(tmp_path):
            listed.append(os.fspath(path))
        return scandir(path)

    monkeypatch.setattr(os, "scandir", counting)
    with pytest.raises(FileNotFoundError) as err:
        StereoCamera(str(tmp_path / "l_%02d.png"), str(tmp_path / "l_%03d.png"))
    assert str(err.value) == (
        f"left source: no file fits {tmp_path}/l_%02d.png; give a pattern such as "
        f"{tmp_path}/l_%03d.png (its files are named l_000.png, l_001.png ...)"
    )
    assert len(listed) == 2


def test_a_sequence_numbered_with_u_opens_from_its_first_number_however_late(
    tmp_path: Path,
) -> None:
    """CAP_IMAGES takes "%03u" as "%03d" (printf's unsigned): u_%03u.png from 0 opened, but our
    pattern code knew only "d", so from 7 it was "cannot open left source"; it opens."""
    for i in range(7, 10):
        cv2.imwrite(str(tmp_path / f"u_{i:03d}.png"), _numbered(i))
    pattern = str(tmp_path / "u_%03u.png")
    with StereoCamera(pattern, pattern) as cam:
        assert [_read_stamp(f.left) for f in cam.frames()] == [7, 8, 9]


def test_the_image_sequence_reader_refuses_a_nan_position_without_raising(
    tmp_path: Path,
) -> None:
    """_ImageSequence.set(CAP_PROP_POS_FRAMES, nan) raised ValueError from round(), where a
    cv2.VideoCapture's set() never raises: a NaN position is refused (False), the position
    and the frames read after it unchanged."""
    for i in range(7, 10):
        cv2.imwrite(str(tmp_path / f"s_{i:03d}.png"), _numbered(i))
    seq = capmod._ImageSequence(str(tmp_path / "s_%03d.png"), 7)
    # the first image's size before any read (width, height)
    assert (seq.get(cv2.CAP_PROP_FRAME_WIDTH), seq.get(cv2.CAP_PROP_FRAME_HEIGHT)) == SMALL
    assert seq.read()[0]
    assert seq.set(cv2.CAP_PROP_POS_FRAMES, float("nan")) is False
    assert seq.get(cv2.CAP_PROP_POS_FRAMES) == 1.0
    ok, frame = seq.read()
    assert ok and _read_stamp(frame) == 8
    assert seq.set(cv2.CAP_PROP_POS_FRAMES, float("inf")) is True  # clamped to the last
    assert _read_stamp(seq.read()[1]) == 9
    assert seq.grab() is False and seq.retrieve() == (False, None)  # not the last again
    # none there: no seek (CAP_IMAGES unopened refuses too), where the position went to -1
    empty = capmod._ImageSequence(str(tmp_path / "none_%03d.png"), 7)
    for prop in (cv2.CAP_PROP_POS_FRAMES, cv2.CAP_PROP_POS_AVI_RATIO):
        assert empty.set(prop, 0.0) is False and empty.get(cv2.CAP_PROP_POS_FRAMES) == 0.0


@pytest.mark.parametrize(
    ("start", "change"),
    [(7, "l_005.png copied in"), (7, "l_007.png moved away"), (0, "l_000.png moved away")],
)
def test_a_gap_is_told_from_the_start_the_sequence_opened_at(
    tmp_path: Path, start: int, change: str
) -> None:
    """The image that stopped a sequence was found from its first number looked up again at
    the end: a folder changed since the open (an earlier image copied in, the images read moved
    away as they are done) named another file ("l_003.png is missing, so the 4 images ...") or
    no gap at all ("ended after 3 frames"). It is counted from the number the sequence opened
    at (CAP_IMAGES's 0, ours 7)."""
    for i in (start, start + 1, start + 2, start + 4):
        cv2.imwrite(str(tmp_path / f"l_{i:03d}.png"), _numbered(i))
    pattern = str(tmp_path / "l_%03d.png")
    with StereoCamera(pattern, pattern) as cam:
        assert [_read_stamp(cam.read().left) for _ in range(3)] == [start, start + 1, start + 2]
        name = change.split()[0]
        if change.endswith("copied in"):
            cv2.imwrite(str(tmp_path / name), _numbered(5))
        else:
            (tmp_path / name).unlink()
        with pytest.raises(SourceError) as err:
            cam.read()
    assert (
        f"left source {pattern!r} ended after 3 images: l_{start + 3:03d}.png is missing, so "
        "the 1 image numbered after it was not read (renumber them without the gap)"
    ) in str(err.value)


def test_a_misnumbered_pattern_over_space_padded_files_is_told_the_padding(
    tmp_path: Path,
) -> None:
    """Over sp_  7.png ... sp_ 12.png (printf's "%3d", which opens since 274d300) the hint for
    a misnumbered pattern took the two-digit names for the run and told "give a pattern such as
    sp_ %02d.png", which opens nothing (the "%02d" run starts after files it does not print).
    It names "%3d", the pattern that reads all six; one-space names of every width (frame 1.png
    ... frame 12.png) are still "frame %d.png"."""
    for i in range(7, 13):
        cv2.imwrite(str(tmp_path / f"sp_{i:3d}.png"), _numbered(i))
    for given in ("sp_%03d.png", "sp_%d.png"):
        with pytest.raises(FileNotFoundError) as err:
            StereoCamera(str(tmp_path / given), str(tmp_path / given))
        assert str(err.value) == (
            f"left source: no file fits {tmp_path}/{given}; give a pattern such as "
            f"{tmp_path}/sp_%3d.png (its files are named sp_  7.png, sp_  8.png ...)"
        )
    told = str(tmp_path / "sp_%3d.png")
    with StereoCamera(told, told) as cam:
        assert [_read_stamp(f.left) for f in cam.frames()] == list(range(7, 13))
    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(1, 13):
        cv2.imwrite(str(frames / f"frame {i}.png"), _numbered(i))
    with pytest.raises(FileNotFoundError) as err:
        StereoCamera(str(frames / "frame %02d.png"), str(frames / "frame %02d.png"))
    assert f"give a pattern such as {frames}/frame %d.png (its files" in str(err.value)


def test_a_pattern_with_a_doubled_slash_opens_late_and_tells_its_gap(tmp_path: Path) -> None:
    """glob gives "dir//l_*.png" as "dir/l_007.png": the number, sliced at the pattern's
    length, lost its first digit ("07", which %03d does not print), so "dir//l_%03d.png" (a
    folder joined with a trailing slash) from 7 was "no file fits ... give a pattern such as
    dir/l_%03d.png" and a gap in one from 0 went untold. Both read as with one slash."""
    late, early = tmp_path / "late", tmp_path / "early"
    late.mkdir()
    early.mkdir()
    for i in (7, 8, 9):
        cv2.imwrite(str(late / f"l_{i:03d}.png"), _numbered(i))
    pattern = f"{late}//l_%03d.png"
    with StereoCamera(pattern, pattern) as cam:
        assert [_read_stamp(f.left) for f in cam.frames()] == [7, 8, 9]
    for i in (0, 1, 2, 4):
        cv2.imwrite(str(early / f"l_{i:03d}.png"), _numbered(i))
    pattern = f"{early}//l_%03d.png"
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 3
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 3 images: l_003.png is missing, so the 1 image "
        "numbered after it was not read"
    )


def test_a_pattern_ten_digits_wide_is_read_as_an_image_sequence(tmp_path: Path) -> None:
    """CAP_IMAGES refuses a width of 10 or more (l_%010d.png: its pattern is 0?[1-9][du]), so a
    sequence of them from 0 went to FFmpeg, which rescales a frame of another size to the
    first's, and its end was told as a video's ("ended after 3 of the 5 frames ... truncated or
    damaged"). It is read by our reader, as one from 7 was: the gap is told."""
    for i in (0, 1, 2, 4):
        cv2.imwrite(str(tmp_path / f"l_{i:010d}.png"), _numbered(i))
    pattern = str(tmp_path / "l_%010d.png")
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert [_read_stamp(cv2.imread(str(left))) for left, _ in result.saved] == [0, 1, 2]
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 3 images: l_0000000003.png is missing, so the 1 "
        "image numbered after it was not read"
    )


def test_a_numbered_folder_after_a_doubled_slash_opens_late_and_tells_its_gap(
    tmp_path: Path,
) -> None:
    """glob gives "dir//run*/x.png" (and "run*//x.png") with one slash: the number of a
    numbered folder, sliced at the pattern's lengths, was lost (978a6ab mended a number in the
    file's name alone), so "dir//run%d/x.png" from 7 was "cannot open" and a gap in one from 0
    went untold. Both read as with one slash."""
    late, early = tmp_path / "late", tmp_path / "early"
    for i in (7, 8, 9):
        (late / f"run{i}").mkdir(parents=True)
        cv2.imwrite(str(late / f"run{i}" / "x.png"), _numbered(i))
    for i in (0, 1, 2, 4):
        (early / f"run{i}").mkdir(parents=True)
        cv2.imwrite(str(early / f"run{i}" / "x.png"), _numbered(i))
    for pattern in (f"{late}//run%d/x.png", f"{late}/run%d//x.png"):
        with StereoCamera(pattern, pattern) as cam:
            assert [_read_stamp(f.left) for f in cam.frames()] == [7, 8, 9]
    pattern = f"{early}//run%d/x.png"
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert len(result.saved) == 3
    assert result.ended.startswith(f"left source {pattern!r} ended after 3 images: ")
    assert "so the 1 image numbered after it was not read" in result.ended


def test_a_gap_in_numbered_folders_names_the_folder(tmp_path: Path) -> None:
    """Of run%d/x.png the gap was told by its basename, "x.png is missing", every image's name,
    and an image there that does not read was "missing" too (looked for as x.png in the
    pattern's folder). It names run3/x.png, missing or damaged as it is."""
    for i in (0, 1, 2, 4):
        (tmp_path / f"run{i}").mkdir()
        cv2.imwrite(str(tmp_path / f"run{i}" / "x.png"), _numbered(i))
    pattern = str(tmp_path / "run%d" / "x.png")
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs")
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 3 images: run3/x.png is missing, so the 1 image "
        "numbered after it was not read (renumber them without the gap)"
    )
    (tmp_path / "run3").mkdir()
    (tmp_path / "run3" / "x.png").write_bytes(b"not a png")
    with StereoCamera(pattern, pattern) as cam:
        result = capture(cam, tmp_path / "pairs2")
    assert result.ended.startswith(
        f"left source {pattern!r} ended after 3 images: run3/x.png does not read (damaged?), "
        "so the 1 image numbered after it was not read (replace or remove it)"
    )


def test_a_stray_name_beside_a_space_padded_sequence_keeps_its_hint(tmp_path: Path) -> None:
    """One stray name beside sp_  7.png ... sp_ 12.png (printf's "%3d"), sp_007.png, left the
    whole space-padded group unmerged: the hint named a part of it ("sp_  %d.png", which reads
    3 of the 6, or "sp_ %02d.png", which opens nothing). It names sp_%3d.png, which reads all
    six; a stray number before the run (q 5.png) leaves it unmerged, the hint one that opens."""
    sp, q = tmp_path / "sp", tmp_path / "q"
    sp.mkdir()
    q.mkdir()
    for i in range(7, 13):
        cv2.imwrite(str(sp / f"sp_{i:3d}.png"), _numbered(i))
        cv2.imwrite(str(q / f"q{i:3d}.png"), _numbered(i))
    cv2.imwrite(str(sp / "sp_007.png"), _numbered(7))
    cv2.imwrite(str(q / "q 5.png"), _numbered(5))
    with pytest.raises(SourceError) as err:
        StereoCamera(str(sp), str(sp))
    told = f"{sp}/sp_%3d.png"
    assert str(err.value) == (
        f"left source {sp} is a folder: give a pattern such as {told} (its files are named "
        "sp_  7.png, sp_  8.png ...)"
    )
    with StereoCamera(told, told) as cam:
        assert [_read_stamp(f.left) for f in cam.frames()] == list(range(7, 13))
    with pytest.raises(SourceError) as err:
        StereoCamera(str(q), str(q))
    told = str(err.value).split("such as ")[1].split(" (its files")[0]
    assert told == f"{q}/q %d.png"
    with StereoCamera(told, told) as cam:
        assert _read_stamp(cam.read().left) == 5


@pytest.mark.parametrize(("start", "junk"), [(0, b"truncated"), (5, b"text")])
def test_a_sequence_whose_first_image_does_not_read_names_it(
    tmp_path: Path, start: int, junk: bytes
) -> None:
    """A sequence whose first image is there but does not read: from 0 with a truncated PNG,
    neither CAP_IMAGES nor _ImageSequence opened it and FFmpeg's did, then "ended after 0 of
    the 4 frames its header announces: the file ended early", as of a video; from 5 with a
    text file in its place, "cannot open" without a word of the file. Both now name it."""
    frames = [_numbered(i) for i in range(start + 4)]
    left = _write_sequence(tmp_path, "left", frames)
    right = _write_sequence(tmp_path, "right", frames)
    for i in range(start):
        (tmp_path / f"left_{i:03d}.png").unlink()
        (tmp_path / f"right_{i:03d}.png").unlink()
    first = tmp_path / f"left_{start:03d}.png"
    first.write_bytes(first.read_bytes()[:60] if junk == b"truncated" else junk)
    with pytest.raises(SourceError) as info:
        StereoCamera(left, right)
    assert str(info.value) == (
        f"cannot open left source {left!r}: its first image, left_{start:03d}.png, does not "
        "read (damaged?)"
    )


def test_stereo_camera_quiets_only_the_sequences_grab(tmp_path: Path) -> None:
    """A video paired with an image sequence: both grabs ran with OpenCV's process-wide log
    silenced, so the video's (or a camera's) own warnings were lost, and every other
    thread's meanwhile. Only the sequence's grab is quiet now; the level is put back."""
    log = cv2.utils.logging
    video = _write_video(tmp_path / "left.avi", [_numbered(i) for i in range(3)])
    seq = _write_sequence(tmp_path / "frames", "right", [_numbered(i, shade=160) for i in range(3)])

    class Recorder:
        """A capture that records OpenCV's log level at each grab."""

        def __init__(self, cap: Any, levels: list[int]) -> None:
            self.cap, self.levels = cap, levels

        def grab(self) -> bool:
            self.levels.append(log.getLogLevel())
            return bool(self.cap.grab())

        def __getattr__(self, name: str) -> Any:
            return getattr(self.cap, name)

    before = log.getLogLevel()
    log.setLogLevel(log.LOG_LEVEL_WARNING)
    try:
        seen: dict[str, list[int]] = {"left": [], "right": []}
        with StereoCamera(str(video), seq) as cam:
            cam._caps = {side: Recorder(c, seen[side]) for side, c in cam._caps.items()}
            got = [_read_stamp(cam.read().right) for _ in range(3)]
        assert got == [0, 1, 2]
        assert seen["left"] == [log.LOG_LEVEL_WARNING] * 3  # the video's warnings are said
        assert seen["right"] == [log.LOG_LEVEL_SILENT] * 3
        assert log.getLogLevel() == log.LOG_LEVEL_WARNING
    finally:
        log.setLogLevel(before)


@pytest.mark.parametrize(
    ("url", "said"),
    [
        ("rtsp://admin:s3cret@cam/0", "rtsp://admin:***@cam/0"),
        ("http://user:pw@host/x", "http://user:***@host/x"),
        # FFmpeg's split: the authority ends at "/", "?" or "#", the user part at its last "@"
        ("rtsp://admin:p@ss:w@cam:554/1?x=a:b@c", "rtsp://admin:***@cam:554/1?x=a:b@c"),
        ("http://u:pw@host?key=1", "http://u:***@host?key=***"),
        (
            "http://cam/x?size=2&TOKEN=abc;access_token=d#f&pwd=e",
            "http://cam/x?size=2&TOKEN=***;access_token=***#f&pwd=e",
        ),
        (
            "http://cam/x?passwd=a&password=b&api_key=c",
            "http://cam/x?passwd=***&password=***&api_key=***",
        ),
        # a path's "&key=" is no parameter
        ("http://h/a&key=1/x?q=1&key=1", "http://h/a&key=1/x?q=1&key=***"),
        # no secret: as given (a port, a user alone, an "@" in the path, empty or longer keys)
        ("rtsp://cam:554/0", "rtsp://cam:554/0"),
        ("rtsp://admin@cam/0", "rtsp://admin@cam/0"),
        ("http://cam:80/a:b@c", "http://cam:80/a:b@c"),
        ("http://cam/x?token=&tokens=1&monkey=2", "http://cam/x?token=&tokens=1&monkey=2"),
        # a path is no URL, whatever its name holds
        ("/data/a:b@c/x?token=1.avi", "/data/a:b@c/x?token=1.avi"),
        ("/data/run@2/left_%03d.png", "/data/run@2/left_%03d.png"),
        ("frames:left/%d.png", "frames:left/%d.png"),
        ("a?key=1.png", "a?key=1.png"),
        ("user@host:path", "user@host:path"),
        ("C:\\data\\left_%03d.png", "C:\\data\\left_%03d.png"),
        ("/data/rtsp://u:pw@h/0", "/data/rtsp://u:pw@h/0"),
        ("v4l2src device=/dev/video0 ! videoconvert ! appsink",) * 2,
        ("rtsp://[::1]:554/0?keyframe=3", "rtsp://[::1]:554/0?keyframe=3"),
        ("rtsp://u:pw@[::1]:554/0", "rtsp://u:***@[::1]:554/0"),
        # a URL in a GStreamer pipeline: its password was said, and a masked parameter's
        # value ran on over the rest of the pipeline ('?token=***' ate '" ! appsink')
        (
            "rtspsrc location=rtsp://u:pw@cam/0 latency=0 ! decodebin ! appsink",
            "rtspsrc location=rtsp://u:***@cam/0 latency=0 ! decodebin ! appsink",
        ),
        (
            'souphttpsrc location="http://u:pw@cam/x?token=abc" ! jpegdec ! appsink',
            'souphttpsrc location="http://u:***@cam/x?token=***" ! jpegdec ! appsink',
        ),
        (" rtsp://admin:s3cret@cam/0", " rtsp://admin:***@cam/0"),
        # a password typed with a raw "#" or "?" (masked by the page's own masker, 2897ee8)
        ("rtsp://admin:pa#ss@cam/0", "rtsp://admin:***@cam/0"),
        ("rtsp://admin:pa?ss@cam/0?token=t", "rtsp://admin:***@cam/0?token=***"),
        # FFmpeg's split first: an "@" in the query is not the password's end
        ("http://u:pw@host?mail=a@b", "http://u:***@host?mail=a@b"),
        # a presigned URL's signature and token (S3's, a CDN's sig=), an OAuth client secret
        (
            "https://b.s3.amazonaws.com/v.mp4?X-Amz-Credential=AK%2F1&X-Amz-Signature=ab12"
            "&X-Amz-Security-Token=tk&X-Amz-Expires=60",
            "https://b.s3.amazonaws.com/v.mp4?X-Amz-Credential=***&X-Amz-Signature=***"
            "&X-Amz-Security-Token=***&X-Amz-Expires=60",
        ),
        (
            "https://cdn/v.m3u8?sig=ab&signature=cd&client_secret=ef&signed=1",
            "https://cdn/v.m3u8?sig=***&signature=***&client_secret=***&signed=1",
        ),
        # a user named by an e-mail address: FFmpeg's user ends at the last "@"'s first ":"
        # (its password was said in full); an "@" before a port is no password's end
        ("rtsp://me@mail.com:pw@cam/0", "rtsp://me@mail.com:***@cam/0"),
        ("rtsp://me@mail.com:p@ss@cam/0?token=t", "rtsp://me@mail.com:***@cam/0?token=***"),
        ("http://u@host:8080?mail=a@b", "http://u@host:8080?mail=a@b"),
        # the query is looked for after the password: a "?key=" in a password is the password's
        ("rtsp://u:a?key=b@cam/0", "rtsp://u:***@cam/0"),
        # no "@" in the authority (RFC 3986: up to the first "/", "?" or "#"): a port then a
        # query holding an "@" reads as a password with a raw "?" too, and stays hidden (said
        # in full, "admin:1234?pw=x@" leaked); the secret parameters after it are masked (the
        # token was said when they were looked for after a "?" only)
        ("rtsp://cam:554?x=a@b", "rtsp://cam:***@b"),
        ("rtsp://admin:1234?pw=x@cam/0", "rtsp://admin:***@cam/0"),
        ("rtsp://cam:554?mail=a@b&token=t", "rtsp://cam:***@b&token=***"),
        (
            "rtspsrc location=rtsp://cam:554?x=a@b ! appsink",
            "rtspsrc location=rtsp://cam:***@b ! appsink",
        ),
        ("rtsp://u:1234?x@cam/0", "rtsp://u:***@cam/0"),
        ("rtsp://cam:554#a@b", "rtsp://cam:***@b"),
        ("rtsp://u:12?w@cam:554?x=a@b", "rtsp://u:***@b"),
        # an IPv6 host's port, then a query holding an "@", is a query as a name's is: the
        # ":" inside the brackets was taken for a user's, "rtsp://[:***@b" said
        ("rtsp://[::1]:554?x=a@b", "rtsp://[::1]:554?x=a@b"),
        (
            "rtsp://[fe80::1%eth0]:554?mail=a@b&token=t",
            "rtsp://[fe80::1%eth0]:554?mail=a@b&token=***",
        ),
        ("rtsp://[::1]?x=a@b", "rtsp://[::1]?x=a@b"),
        ("rtsp://u:p?w@[::1]:554/0", "rtsp://u:***@[::1]:554/0"),
        # no port but 1 to 5 digits before the "?" (6 digits, none), and a "#" is no query:
        # passwords still
        ("rtsp://u:123456?k=v@cam/0", "rtsp://u:***@cam/0"),
        ("rtsp://u:?k=v@cam/0", "rtsp://u:***@cam/0"),
        ("rtsp://cam:554#k=v@b", "rtsp://cam:***@b"),
        # one URL is the whole source, spaces and all (a leading space too)
        ("http://cam/my video.avi?token=x", "http://cam/my video.avi?token=***"),
        (" http://cam/a b?token=x", " http://cam/a b?token=***"),
        ("http://cam/x?auth=a&secret=b&apikey=c", "http://cam/x?auth=***&secret=***&apikey=***"),
    ],
)
def test_a_urls_secrets_are_masked(url: str, said: str) -> None:
    assert mask_url_secrets(url) == said
    if "://" in url:  # another library's words for a URL lose them too (Dask's own)
        text = f"a: bad address {url.split('://')[1]!r} (a=a, user u, key c)"
        assert capmod._mask_secrets_of(text, url) == (
            f"a: bad address {said.split('://')[1]!r} (a=a, user u, key c)"
        )


def test_another_librarys_words_for_a_urls_parts_lose_their_secrets() -> None:
    """A message naming a URL's parts alone, not the URL (the user part without its scheme,
    the query), says them masked as the URL is."""
    url = "rtsp://admin:s3cret@cam/0?token=abc"
    text = "refused admin:s3cret@ (query ?token=abc)"
    assert capmod._mask_secrets_of(text, url) == "refused admin:***@ (query ?token=***)"


def test_capture_calls_progress_with_the_pairs_read_so_far(tmp_path: Path) -> None:
    """``capture(progress=)`` (the frames bar's update) is told the pairs read after each."""
    left, right = _videos(tmp_path, 3, 3)
    seen: list[int] = []
    with StereoCamera(str(left), str(right)) as cam:
        result = capture(cam, tmp_path / "pairs", every=2, progress=seen.append)
    assert seen == [1, 2, 3] and result.frames_read == 3 and len(result.saved) == 2


#: Streams with a password and a token: what the capture code says must not hold these.
_LEFT_URL, _RIGHT_URL = "rtsp://admin:s3cret@cam/0?token=tok77", "http://u:pw99@cam/1.avi"
_SECRETS = ("s3cret", "tok77", "pw99")


@pytest.mark.parametrize(
    "argv",
    [
        ["capture", "--count", "1", "-o", "pairs"],
        ["stream", "--no-display", "--json"],
        ["calibrate", "--square", "0.025", "-o", "calib.yaml"],
    ],
    ids=["capture", "stream", "calibrate"],
)
def test_a_stream_that_does_not_open_is_said_without_its_password(
    argv: list[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A stream URL with a password that does not open: "cannot open left source
    'rtsp://admin:s3cret@cam/0'", the one line of capture, stream and calibrate, said it. It
    is said as ***; the URL opened is the one given."""
    from stereovision.cli import main

    opened: list[str] = []

    def down(path: str, first: Any) -> Any:
        opened.append(path)
        return cv2.VideoCapture()  # not open

    monkeypatch.setattr(capmod, "_open_path", down)
    monkeypatch.chdir(tmp_path)
    # calibrate takes a video by its suffix: a query after it is no video
    video = argv[0] == "calibrate"
    left = "rtsp://admin:s3cret@cam/0.avi" if video else _LEFT_URL
    assert main([*argv, "--left", left, "--right", _RIGHT_URL]) == 2
    out, err = capsys.readouterr()
    name = "rtsp://admin:***@cam/0" + (".avi" if video else "?token=***")
    assert err.splitlines() == [f"stereovision: error: cannot open left source '{name}'"]
    assert opened == [left]
    assert not any(s in out + err for s in _SECRETS)
    assert not list(tmp_path.iterdir())  # nothing written


def test_a_streams_password_is_not_said_in_captures_lines(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Streams given by URLs with a password: capture's description of its sources, its
    end (a stream ending early) and the warning of one source given twice named them with it.
    They are said as ***; nothing written holds them."""
    from stereovision.cli import main

    left, right = _videos(tmp_path, 4, 2)
    real = capmod._open_path
    files = {_LEFT_URL: str(left), _RIGHT_URL: str(right)}
    monkeypatch.setattr(capmod, "_open_path", lambda path, first: real(files[path], first))
    out = tmp_path / "pairs"
    argv = ["capture", "--count", "3", "-o", str(out), "--left", _LEFT_URL, "--right", _RIGHT_URL]
    assert main(argv) == 2
    said, err = capsys.readouterr()
    left_name, right_name = "'rtsp://admin:***@cam/0?token=***'", "'http://u:***@cam/1.avi'"
    assert said.splitlines()[0].startswith(f"native size; left {left_name}: ")
    assert f"; right {right_name}: " in said.splitlines()[0]
    assert err.splitlines()[-1].startswith(
        f"stereovision: error: right source {right_name} ended after 2 frames"
    )
    assert len(list(out.iterdir())) == 4  # the 2 pairs saved, kept
    argv = ["capture", "--count", "1", "-o", str(out), "--left", _LEFT_URL, "--right", _LEFT_URL]
    assert main(argv) == 0
    said2, err2 = capsys.readouterr()
    assert err2.splitlines()[0] == (
        f"stereovision: warning: --left and --right are the same source {left_name}: every "
        "pair is one view twice and every disparity comes out 0 (two cameras' views are needed)"
    )
    assert not any(s in said + err + said2 + err2 for s in _SECRETS)
    for path in out.iterdir():
        assert not any(s.encode() in path.read_bytes() for s in _SECRETS)


def test_a_glob_matching_one_folder_is_not_told_to_be_given_as_that_file(
    tmp_path: Path,
) -> None:
    """A mutation audit: one match that is a folder (``--left 'runs/run*'``) was told "give
    the file it matches, runs/run1" when the file check was dropped; a folder opens nothing."""
    from stereovision.capture import _glob_hint

    (tmp_path / "run1").mkdir()
    assert _glob_hint("left", f"{tmp_path}/run*") == (
        f"left source {tmp_path}/run* is a glob, which OpenCV does not expand: give a video "
        f"file, an image-sequence pattern such as {tmp_path}/left_%04d.png or a camera index"
    )


def test_sequences_that_start_at_other_numbers_are_said_to_pair_in_order(tmp_path: Path) -> None:
    """A left image sequence that starts at 1 (its image 0 deleted, blurred) beside a right
    one starting at 0 paired every left image with the right one before its own, without a
    word until the end (one source ended first). One line now says so at the open, naming both
    first images; sequences starting at the same number are paired as before, silently."""
    for i in range(4):
        if i:
            cv2.imwrite(str(tmp_path / f"left_{i:04d}.png"), _numbered(i))
        cv2.imwrite(str(tmp_path / f"right_{i:04d}.png"), _numbered(i))
    left, right = str(tmp_path / "left_%04d.png"), str(tmp_path / "right_%04d.png")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with StereoCamera(left, right) as cam:
            fr = cam.read()
    assert [str(w.message) for w in caught] == [
        "the left sequence starts at left_0001.png, the right one at right_0000.png: images are "
        "paired in order (left_0001.png with right_0000.png), not by their numbers; if the "
        "numbers name the pairs, remove the images without a partner (or renumber)"
    ]
    assert caught[0].filename == __file__  # the caller's line
    assert (_read_stamp(fr.left), _read_stamp(fr.right)) == (1, 0)  # what it warns of
    (tmp_path / "right_0000.png").unlink()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with StereoCamera(left, right) as cam:
            fr = cam.read()
    assert (_read_stamp(fr.left), _read_stamp(fr.right)) == (1, 1)


def test_a_warning_made_an_error_at_the_open_closes_what_was_opened(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Under ``python -W error`` the open's warnings raise: the sequences' start mismatch was
    warned after the open's clean-up, so both captures stayed open (the object never came
    back to be closed); a pixel format not delivered left the capture that said it open."""
    for i in range(3):
        if i:
            cv2.imwrite(str(tmp_path / f"left_{i:04d}.png"), _numbered(i))
        cv2.imwrite(str(tmp_path / f"right_{i:04d}.png"), _numbered(i))
    opened: list[Any] = []
    real = capmod._open_path

    def recording(path: str, first: Any) -> Any:
        opened.append(real(path, first))
        return opened[-1]

    monkeypatch.setattr(capmod, "_open_path", recording)
    left, right = str(tmp_path / "left_%04d.png"), str(tmp_path / "right_%04d.png")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match=r"^the left sequence starts at left_0001\.png"):
            StereoCamera(left, right)
    assert len(opened) == 2 and not any(c.isOpened() for c in opened)
    # The format's warning: both captures released (the right one said it).
    caps = [_FormatCap("L", [], ("MJPG",)), _FormatCap("R", [], ("YUYV",))]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match=r"right source .* delivers 'YUYV', not 'MJPG'"):
            StereoCamera(*caps, fourcc="MJPG")
    assert [c.released for c in caps] == [1, 1]


def test_open_sources_same_source_warning_made_an_error_closes_the_camera(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """open_source's own open warning (--left and --right one file) under ``python -W error``
    raised after the StereoCamera was open: both captures stayed open, no object returned to
    close them (the clean-up StereoCamera's warnings got left this one out)."""
    left, _right = _videos(tmp_path, 3, 3)
    opened: list[Any] = []
    real = capmod._open_path

    def recording(path: str, first: Any) -> Any:
        opened.append(real(path, first))
        return opened[-1]

    monkeypatch.setattr(capmod, "_open_path", recording)
    args = _parser().parse_args(
        ["capture", "--left", str(left), "--right", f"{tmp_path}/./{left.name}", "-o",
         str(tmp_path / "pairs")]
    )  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match=r"^--left and --right are the same source "):
            capmod.open_source(args)
    assert len(opened) == 2 and not any(c.isOpened() for c in opened)


class _UnpluggedCamera:
    """A camera device (``cv2.VideoCapture(index)`` stand-in) that delivers 3 frames, then
    none if its index is in ``gone``: unplugged."""

    gone: tuple[int, ...] = (0, 1)

    def __init__(self, index: int, *args: Any) -> None:
        self.index, self.n = index, 0
        rng = np.random.default_rng(0)
        left = cv2.GaussianBlur(rng.integers(0, 255, (48, 64, 3), dtype=np.uint8), (7, 7), 2.0)
        self.frame = left if index == 0 else np.roll(left, -2, axis=1)

    def isOpened(self) -> bool:
        return True

    def grab(self) -> bool:
        self.n += 1
        return self.n <= 3 or self.index not in self.gone

    def retrieve(self) -> tuple[bool, np.ndarray]:
        return True, self.frame.copy()

    def get(self, prop: int) -> float:
        return {cv2.CAP_PROP_FRAME_WIDTH: 64.0, cv2.CAP_PROP_FRAME_HEIGHT: 48.0}.get(prop, 0.0)

    def set(self, prop: int, value: float) -> bool:
        return False

    def release(self) -> None:
        pass


@pytest.mark.parametrize("gone", [(0,), (0, 1)])
def test_capture_of_a_camera_that_stops_delivering_fails_and_keeps_its_pairs(
    gone: tuple[int, ...],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A camera has no end: ``capture`` of two unplugged ones said "3 pairs saved (end of
    stream)", exit 0, as of two videos read to their end (of one, its reason, exit 0 too),
    where ``stream`` fails (2fda8ab). It fails as ``stream`` does, exit 2, the pairs kept."""
    from stereovision.cli import main

    monkeypatch.setattr(_UnpluggedCamera, "gone", gone)
    monkeypatch.setattr(cv2, "VideoCapture", _UnpluggedCamera)
    out = tmp_path / "pairs"
    assert main(["capture", "--left", "0", "--right", "1", "-o", str(out)]) == 2
    said = "left source camera 0 stopped delivering frames after 3 (disconnected?); " + (
        "the right source still had frames"
        if gone == (0,)
        else "right source camera 1 stopped delivering frames after 3 (disconnected?)"
    )
    err = capsys.readouterr().err
    assert err.splitlines()[-1] == (
        f"stereovision: error: {said}; 3 pairs were saved in {out} and are kept"
    )
    assert sorted(p.name for p in out.iterdir()) == [
        f"{side}_{i:04d}.png" for side in ("left", "right") for i in (1, 2, 3)
    ]


def test_mutation_audit_a_one_channel_frame_is_delivered_as_bgr() -> None:
    """Mutation audit of b0727eb: a camera handing (h, w, 1) frames (a grey driver's) is made
    BGR as a 2-D grey frame is, its grey in each channel; without that branch the frame stayed
    one channel beside a BGR right frame."""

    class _OneChannelCap(_FakeCap):
        def retrieve(self) -> tuple[bool, np.ndarray]:
            return True, cv2.cvtColor(_numbered(0), cv2.COLOR_BGR2GRAY)[:, :, None]

    with StereoCamera(_OneChannelCap("L", []), _FakeCap("R", [])) as cam:
        fr = cam.read()
    grey = cv2.cvtColor(_numbered(0), cv2.COLOR_BGR2GRAY)
    assert fr.left.shape == fr.right.shape == (*grey.shape, 3)
    assert all((fr.left[:, :, c] == grey).all() for c in range(3))


def test_capture_folder_entry_points_refuse_a_bytes_or_no_path_naming_the_argument(
    tmp_path: Path,
) -> None:
    """save_pair, next_pair_index, remove_stale_temps and capture given a bytes folder name (or
    None) raised pathlib's "argument should be a str object or an os.PathLike object returning
    str, not <class 'bytes'>", naming no argument: they now say it as io's readers do, and no
    folder is made."""
    name = str(tmp_path / "pairs")
    img = np.zeros((4, 4), np.uint8)
    cases = [
        lambda d: save_pair(d, 1, img, img),
        lambda d: next_pair_index(d),
        lambda d: capmod.remove_stale_temps(d),
        lambda d: capture(None, d, count=1),  # type: ignore[arg-type]
    ]
    for call in cases:
        with pytest.raises(TypeError) as info:
            call(name.encode())
        assert str(info.value) == (
            f"directory: expected a str or os.PathLike file name, got the bytes {name!r}: "
            "decode it first (os.fsdecode(directory))"
        )
        with pytest.raises(TypeError) as info:
            call(None)
        assert str(info.value) == "directory: expected a str or os.PathLike file name, got NoneType"
    assert not list(tmp_path.iterdir())  # no folder made


def test_stereo_camera_refuses_a_bytes_source_naming_it(tmp_path: Path) -> None:
    """StereoCamera(b'left.png', ...) took the bytes for a capture object of the caller's and
    failed in "'bytes' object has no attribute 'isOpened'": it now says which side and to
    decode it, as the library's other path arguments do."""
    name = str(tmp_path / "left_%04d.png")
    for left, right, side in ((name.encode(), name, "left"), (name, name.encode(), "right")):
        with pytest.raises(TypeError) as info:
            StereoCamera(left, right)
        assert str(info.value) == (
            f"{side}: expected a str or os.PathLike file name, got the bytes {name!r}: decode "
            f"it first (os.fsdecode({side}))"
        )


def test_stereo_camera_refuses_a_source_of_no_kind_naming_it(tmp_path: Path) -> None:
    """StereoCamera(None, ...) (a setting left out), a float or a bytearray was taken for a
    capture object of the caller's and failed in "'NoneType' object has no attribute
    'isOpened'", naming neither the side nor what it takes; refused before anything is opened."""
    name = str(tmp_path / "left_%04d.png")
    for bad, kind in ((None, "NoneType"), (1.5, "float"), (bytearray(b"x"), "bytearray")):
        for left, right, side in ((bad, name, "left"), (name, bad, "right"), (bad, bad, "left")):
            with pytest.raises(TypeError) as info:
                StereoCamera(left, right)
            assert str(info.value) == (
                f"{side} source: expected a device index, a path or a capture object "
                f"(cv2.VideoCapture's methods), got {kind}"
            )


def test_frames_compare_by_identity() -> None:
    """Two frames of one picture: ``a == b`` (and ``b in [a]``) compared their images and
    raised NumPy's 'truth value of an array ... is ambiguous'. Equal to itself only."""
    img = np.zeros((4, 6), np.uint8)
    a = capmod.StereoFrame(img.copy(), img.copy(), 0.0, 0.0, 0)
    b = capmod.StereoFrame(img.copy(), img.copy(), 0.0, 0.0, 0)
    assert a == a and a != b and b not in [a] and len({a, b, a}) == 2


def test_save_pair_names_a_dropped_frame_or_a_path(tmp_path: Path) -> None:
    """A frame the camera dropped (cap.read()'s None) or a path was "cannot encode the left
    image as .png", as if the format were at fault, and the folder was made. Both are said in
    the package's words, as TemporalFilter says them, before anything is made."""
    img = np.zeros((4, 6), np.uint8)
    folder = tmp_path / "pairs"
    with pytest.raises(ValueError) as err:
        capmod.save_pair(folder, 1, None, img)
    assert str(err.value) == (
        "left: got None, not an image (cv2.imread returns None for a file it cannot read: "
        "check the path)"
    )
    with pytest.raises(ValueError, match=r"^right: got the path 'r\.png', not an image: read"):
        capmod.save_pair(folder, 1, img, "r.png")
    assert not folder.exists()
    assert [p.name for p in capmod.save_pair(folder, 1, img, img)] == [
        "left_0001.png",
        "right_0001.png",
    ]


def test_save_pair_names_an_empty_frame_or_encoded_bytes(tmp_path: Path) -> None:
    """An empty frame (a camera's dropped frame as a 0 x 0 array) or a file's bytes was
    "cannot encode the left image as .png", as if the format were at fault, and the folder
    was made: said in as_image_array's words, as None and a path are, before anything is
    made."""
    img = np.zeros((4, 6), np.uint8)
    folder = tmp_path / "pairs"
    with pytest.raises(ValueError, match=r"^left: image is empty \(shape \(0, 0\)\)"):
        capmod.save_pair(folder, 1, np.zeros((0, 0), np.uint8), img)
    with pytest.raises(ValueError, match=r"^right: got 5 bytes, not an image: decode"):
        capmod.save_pair(folder, 1, img, b"\x89PNG\x00")
    assert not folder.exists()


class _Piped:
    """A stdout that is a pipe: what is written waits until flushed, as Python buffers a pipe
    (``flushed`` is what a reader, or a log after a kill, would have)."""

    def __init__(self) -> None:
        self.pending = ""
        self.flushed = ""

    def write(self, s: str) -> int:
        self.pending += s
        return len(s)

    def flush(self) -> None:
        self.flushed += self.pending
        self.pending = ""

    def isatty(self) -> bool:
        return False


@pytest.mark.parametrize("terminal", [False, True], ids=["log", "frames-bar"])
def test_cli_capture_flushes_each_saved_line_into_a_pipe(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, terminal: bool
) -> None:
    """`capture ... | tee log` saw no "saved" line while pairs were written: stdout was
    buffered, and a SIGKILL (measured: 161 pairs on disk, 0 lines read from the pipe) lost
    them all. The source's line and each "saved" line are flushed as they are said, with the
    frames bar on a terminal too."""
    from stereovision.cli import main

    frames = [_numbered(i) for i in range(3)]
    left = _write_sequence(tmp_path / "seq", "left", frames)
    right = _write_sequence(tmp_path / "seq", "right", frames)
    piped = _Piped()
    said: list[str] = []  # what a reader of the pipe had as each line was said
    wrapped = capmod._FramesBar.write
    monkeypatch.setattr(
        capmod._FramesBar,
        "write",
        lambda self, line: (wrapped(self, line), said.append(piped.flushed)),
    )
    monkeypatch.setattr("sys.stdout", piped)
    if terminal:
        monkeypatch.setattr("sys.stderr", _Terminal())
    out = tmp_path / "pairs"
    assert main(["capture", "--left", left, "--right", right, "-o", str(out)]) == 0
    monkeypatch.undo()
    lines = [text.splitlines() for text in said]
    assert [len(seen) for seen in lines] == [2, 3, 4]
    assert lines[0][0].startswith(f"native size; left {left!r}: 320x240")
    assert [line.split(" (")[0] for line in lines[-1][1:]] == [
        f"saved left_{i:04d}.png right_{i:04d}.png" for i in (1, 2, 3)
    ]


def test_a_dark_10_or_12_bit_board_is_stretched_for_the_live_search(tmp_path: Path) -> None:
    """A 10-bit camera's frames in 16-bit PNGs (a board of levels 120-426) were cut to their top
    8 bits for the live search: 3 grey levels, no chessboard or ChArUco board found in any
    frame (calibrate, which stretches a dark image, found each), and a warning of the image's
    bits for every frame. A dark frame of more than 8 bits is stretched as calibrate reads it;
    8-bit frames are searched as before, a black 16-bit frame is no board, without a word."""

    def dim(grey: np.ndarray, bits: int) -> np.ndarray:  # 0.3 of the range, 30 levels up
        return np.rint((grey * 0.3 + 30) * 2 ** (bits - 8)).astype(np.uint16)

    chess = cv2.cvtColor(_board(POSE_A, 0, False), cv2.COLOR_BGR2GRAY)
    want = detect_board_live(chess, (9, 6))
    assert want is not None
    rv, tv = POSE_A
    t0 = tv - cv2.Rodrigues(rv)[0] @ np.array([SQUARE, SQUARE, 0.0])
    charuco = [
        render_charuco(CHARUCO, K, D, r, t, image_size=BOARD_SIZE, supersample=1)
        for r, t in ((rv, t0), (rv, RIG_T + t0))
    ]
    mk = capmod.StereoFrame
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        for bits in (10, 12):
            got = detect_board_live(dim(chess, bits), (9, 6))
            assert got is not None and np.abs(got - want).max() < 1.0, bits
            col = ChessboardCollector(CHARUCO.inner, board=CHARUCO)
            frame = mk(dim(charuco[0], bits), dim(charuco[1], bits), 0.0, 0.0, 0)
            assert col.consider(frame).reason == "new pose", bits
        assert detect_board_live(np.zeros((48, 64), np.uint16), (9, 6)) is None
    assert [str(w.message) for w in said] == []


def test_every_with_a_board_is_refused_before_any_read(tmp_path: Path) -> None:
    """capture(chessboard=..., every=3) ignored every without a word (3 new poses read, 3
    saved), where the CLI refuses --every with a board: refused in the API too, before the
    camera is read or the folder made."""
    log: list[str] = []
    out = tmp_path / "pairs"
    for board in ({"chessboard": "9x6"}, {"charuco": CHARUCO}):
        cam = StereoCamera(_FakeCap("L", log), _FakeCap("R", log))
        with pytest.raises(ValueError) as err:
            capture(cam, out, every=3, **board)
        assert str(err.value) == (
            "every is for a capture without a board: chessboard and charuco save a pair for "
            "each new pose of the board"
        )
        cam.close()
    assert log == [] and not out.exists()


def test_two_cameras_of_other_frame_rates_are_said(tmp_path: Path) -> None:
    """Two webcams of other rates (30 and 15 fps) were paired without a word: describe() gave
    both rates in passing and the grab skew said a fraction of a ms, while each pair waits for
    the slower camera and the faster one's frames queue. One warning at the open says so; none
    for rates within 1 %, a camera reporting none, a rate asked (said per side), or files (read
    as they are: their media times are compared instead)."""
    with pytest.warns(UserWarning) as rec:
        cam = StereoCamera(_RateCap("L", (30.0,)), _RateCap("R", (15.0,)))
    assert [str(w.message) for w in rec] == [
        "left source _RateCap reports 30 fps, right source _RateCap 15 fps: each pair waits for "
        "the slower camera while the faster one's frames queue in its buffer, so a pair's two "
        "frames may be taken a frame or more apart, which the grab skew does not show; ask "
        "both for one rate (fps=15, --fps 15)"
    ]
    assert rec[0].filename == __file__  # said at the caller's line
    cam.close()
    left = _write_video(tmp_path / "l.avi", [_numbered(0)], fps=10.0)
    right = _write_video(tmp_path / "r.avi", [_numbered(0)], fps=5.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        StereoCamera(_RateCap("L", (29.97,)), _RateCap("R", (30.0,))).close()
        StereoCamera(_RateCap("L", (30.0,)), _FakeCap("R", [])).close()  # reports no rate
        StereoCamera(left, right).close()
    with pytest.warns(UserWarning) as rec:
        StereoCamera(_RateCap("L", (30.0,)), _RateCap("R", (30.0, 15.0)), fps=15).close()
    assert [str(w.message) for w in rec] == [
        "left source _RateCap reports 30 fps, not the 15 fps asked (a rate this camera does "
        "not give at this size and format?)"
    ]


def test_an_image_the_format_cannot_hold_is_refused_without_opencvs_log_line(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """save_pair of a float32 image as .png was refused in the package's words, but OpenCV's
    log line came first on stderr ("[ WARN:0@0.640] ... imencodeWithMetadata Unsupported depth
    image for selected encoder is fallbacked to CV_8U"), as if the image had been written as 8
    bits. Only the refusal is said now; a uint16 .png is saved as before."""
    img = np.zeros((4, 6), np.uint8)
    capfd.readouterr()
    with pytest.raises(ValueError, match=r"^cannot save the left image \(float32\) as \.png"):
        capmod.save_pair(tmp_path, 1, img.astype(np.float32), img)
    assert capfd.readouterr().err == ""
    paths = capmod.save_pair(tmp_path, 2, img.astype(np.uint16), img)
    assert cv2.imread(str(paths[0]), cv2.IMREAD_UNCHANGED).dtype == np.uint16


def test_cli_capture_names_a_folder_with_a_newline_escaped_on_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """capture's last line, and its line of a killed capture's temporary files removed,
    printed -o as it is: 'o\\nut' cut them in two ('3 pairs saved in .../o' then 'ut (end of
    stream); ...'), as depth's list of files did before 895b579. One line each now, the
    newline escaped (the "saved" lines name the files alone)."""
    from stereovision.cli import main

    seq = tmp_path / "seq"
    seq.mkdir()
    for i in range(2):
        for side in ("left", "right"):
            cv2.imwrite(str(seq / f"{side}_{i:03d}.png"), np.full((8, 12), 10 * i, np.uint8))
    out = tmp_path / "o\nut"
    out.mkdir()
    (out / ".left_0003.png.k3x_9a2b.tmp").write_bytes(b"")  # left by a killed capture
    shown = str(out).replace("\n", "\\n")
    argv = ["capture", "--left", str(seq / "left_%03d.png"), "--right", str(seq / "right_%03d.png")]
    assert main([*argv, "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == (
        f"removed 1 temporary file an interrupted capture left in {shown}: "
        ".left_0003.png.k3x_9a2b.tmp"
    )
    assert lines[-1].startswith(f"2 pairs saved in {shown} (end of stream); 2 pairs read; ")
    assert len(lines) == 5 and (out / "right_0002.png").is_file()


def test_cli_capture_says_its_sources_in_a_sentence_and_a_folder_with_a_newline_escaped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The summary read "1 pair read; delivered native size; left ...", describe()'s words put
    after "delivered"; ``-o $'a\\nb'`` split the summary and the interrupt's line in two. The
    sources are said as "sources: ...", and the folder escaped, as cli.py's lines name a path."""
    from stereovision import capture as capture_module
    from stereovision.cli import EXIT_INTERRUPTED, main

    left = _write_sequence(tmp_path / "seq", "left", [_numbered(0)])
    right = _write_sequence(tmp_path / "seq", "right", [_numbered(0)])
    monkeypatch.chdir(tmp_path)
    argv = ["capture", "--left", left, "--right", right, "--count", "1", "-o", "a\nb"]
    assert main(argv) == 0
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.startswith("1 pair saved in a\\nb (count reached); 1 pair read; sources: native "
                           f"size; left '{left}': ")  # fmt: skip
    assert (tmp_path / "a\nb" / "left_0001.png").is_file()

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(capture_module, "capture", interrupted)
    assert main(argv) == EXIT_INTERRUPTED
    assert capsys.readouterr().err.splitlines() == [
        "stereovision: interrupted: 0 pairs saved in a\\nb this run are kept; run again to add more"
    ]


def test_a_source_link_whose_target_moved_names_it(tmp_path: Path) -> None:
    """A video given as a link whose target moved (a recording on a disk since unmounted) was
    "left source not found: v.mp4", of a name ls lists; the link's target is named, as io's
    readers name it; a missing file as before."""
    link = tmp_path / "v.mp4"
    link.symlink_to("moved/v.mp4")
    with pytest.raises(FileNotFoundError) as info:
        StereoCamera(link, link)
    assert str(info.value) == (
        f"left source not found: {link} (a link to moved/v.mp4, which does not exist)"
    )
    with pytest.raises(FileNotFoundError) as info:
        StereoCamera(tmp_path / "none.mp4", link)
    assert str(info.value) == f"left source not found: {tmp_path / 'none.mp4'}"


def test_a_source_out_of_reach_is_said_unreadable_not_missing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A video behind a folder this user may not enter (EACCES), or a link to one, was "left
    source not found: v.mp4 (a link to secret/v.mp4, which does not exist)": it is there."""
    import errno

    (tmp_path / "secret").mkdir()
    (tmp_path / "secret" / "v.mp4").write_bytes(b"x")
    link = tmp_path / "v.mp4"
    link.symlink_to("secret/v.mp4")
    stat = os.stat

    def denied(p: Any, *args: Any, **kwargs: Any) -> Any:  # as for a user other than root
        if "secret" in os.fspath(p) or (os.fspath(p) == str(link) and not args and not kwargs):
            raise PermissionError(errno.EACCES, "Permission denied", os.fspath(p))
        return stat(p, *args, **kwargs)

    monkeypatch.setattr(os, "stat", denied)
    with pytest.raises(PermissionError) as info:
        StereoCamera(link, link)
    assert str(info.value) == (
        f"left source cannot be read: {link} (a link to secret/v.mp4): Permission denied"
    )
    with pytest.raises(PermissionError) as info:
        StereoCamera(tmp_path / "secret" / "v.mp4", link)
    assert str(info.value) == (
        f"left source cannot be read: {tmp_path / 'secret' / 'v.mp4'}: Permission denied"
    )


def test_a_source_path_with_a_null_byte_is_named(tmp_path: Path) -> None:
    """A path holding a null byte (a name pasted from a C string) was "left source not found:
    a<NUL>b.mp4", the byte printed raw; it is refused as the io writers refuse it (34a60829)."""
    bad = str(tmp_path / "a\x00b.mp4")
    with pytest.raises(ValueError) as info:
        StereoCamera(bad, str(tmp_path / "b.mp4"))
    assert str(info.value) == f"left source: expected a path without a null byte, got {bad!r}"
