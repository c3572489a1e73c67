"""``stereovision batch`` on a real 2-worker Dask LocalCluster: outputs, re-run, failures."""

from __future__ import annotations

import contextlib
import gc
import io
import json
import logging
import math
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import warnings
from collections import deque
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, cast

import cv2
import distributed
import numpy as np
import pytest

from stereovision.batch import SUMMARY_NAME, PairJob, find_pairs
from stereovision.calibration import Calibration
from stereovision.cli import main
from stereovision.depth import depth_map
from stereovision.io import imread, read_pfm, read_ply

SCALE = 0.5  # half-size copies keep the cluster run short
DISPARITY_FILES = {"disparity.png", "disparity.pfm", "overview.png"}
DEPTH_FILES = DISPARITY_FILES | {
    "depth.png",
    "depth.npy",
    "depth_mm.png",
    "cloud.ply",
    "render.png",
}


def _half(src: Path, dst: Path) -> None:
    dst.mkdir(parents=True)
    for side in ("left", "right"):
        img = cv2.imread(str(src / f"{side}.png"))
        small = cv2.resize(img, None, fx=SCALE, fy=SCALE, interpolation=cv2.INTER_AREA)
        cv2.imwrite(str(dst / f"{side}.png"), small)


def _half_calib(src: Path, dst: Path, size: tuple[int, int]) -> None:
    """A Middlebury calib.txt for the half-size images (focal, centre and doffs halved)."""
    cal = Calibration.from_file(src)
    f, cx, cy = (SCALE * cal.K1[0, 0], SCALE * cal.K1[0, 2], SCALE * cal.K1[1, 2])
    cam = f"[{f} 0 {cx}; 0 {f} {cy}; 0 0 1]"
    dst.write_text(
        f"cam0={cam}\ncam1={cam}\ndoffs={SCALE * cal.doffs_px}\nbaseline={cal.baseline}\n"
        f"width={size[0]}\nheight={size[1]}\nndisp=128\n"
    )


@pytest.fixture
def scenes(data_dir: Path, tmp_path: Path) -> Path:
    """Three half-size scenes (one with a metric calibration) and a pair with a corrupt image."""
    root = tmp_path / "in"
    for name in ("middlebury2001/tsukuba", "middlebury2001/venus", "eth3d/terrace"):
        _half(data_dir / name, root / name)
    terrace = root / "eth3d/terrace"
    h, w = cv2.imread(str(terrace / "left.png")).shape[:2]
    _half_calib(data_dir / "eth3d/terrace/calib.txt", terrace / "calib.txt", (w, h))
    seq = root / "seq"
    seq.mkdir()
    shutil.copy(root / "middlebury2001/tsukuba/left.png", seq / "left_0001.png")
    good = (root / "middlebury2001/tsukuba/right.png").read_bytes()
    (seq / "right_0001.png").write_bytes(good[: len(good) // 3])  # truncated: cannot decode
    return root


def _summary(out: Path) -> dict:
    return json.loads((out / SUMMARY_NAME).read_text())


def _tree(out: Path) -> dict[str, float]:
    return {
        p.relative_to(out).as_posix(): p.stat().st_mtime_ns
        for p in out.rglob("*")
        if p.is_file() and p.name != SUMMARY_NAME
    }


def _stereo_calib_input(
    tmp_path: Path, data_dir: Path, pairs: tuple[str, ...]
) -> tuple[Path, Path, Path]:
    """``rig`` (OpenCV stereo_calib's intrinsics.yml + extrinsics.yml: 640x480, T in mm), ``in``
    holding the chessboard pairs ``pairs`` (``left01.jpg`` + ``right01.jpg``, ...) and ``out``
    (not created), under ``tmp_path``."""
    from test_calibration import _opencv_stereo_calib

    rig, root, out = tmp_path / "rig", tmp_path / "in", tmp_path / "out"
    rig.mkdir()
    root.mkdir()
    _opencv_stereo_calib(rig)
    for n in pairs:
        for side in ("left", "right"):
            shutil.copy(data_dir / "chessboard" / f"{side}{n}.jpg", root / f"{side}{n}.jpg")
    return rig, root, out


def _noise_pair(scene: Path) -> None:
    """``scene/left.png`` and ``right.png``: one 48 x 32 noise image twice."""
    scene.mkdir(parents=True)
    img = np.random.default_rng(0).integers(0, 255, (32, 48, 3), np.uint8)
    for side in ("left", "right"):
        cv2.imwrite(str(scene / f"{side}.png"), img)


def _not_ours(out: Path, pair: str, name: str) -> str:
    """batch's line refusing to replace ``out / pair / name``, which no earlier run listed."""
    return (
        f"stereovision: error: output folder {out}: {out / pair / name} is not listed as an "
        "earlier run's output there and would be replaced: give another output folder, or "
        "move or remove that file"
    )


def test_batch_runs_skips_and_records_failures(
    scenes: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    rc = main(["batch", str(scenes), "-o", str(out), "--workers", "2"])
    assert rc == 1  # one pair failed; the others completed
    s = _summary(out)
    pairs = s["pairs"]
    done = ["eth3d/terrace", "middlebury2001/tsukuba", "middlebury2001/venus"]
    assert sorted(pairs) == [*done, "seq/0001"]
    assert s["counts"] == {"done": 3, "failed": 1, "pending": 0}
    assert s["run"]["processed"] == 3 and s["run"]["failed"] == 1 and s["run"]["skipped"] == 0
    assert s["run"]["scheduler"] == "LocalCluster(2 worker processes)"
    bad = pairs["seq/0001"]
    assert bad["status"] == "failed" and "cannot decode" in bad["error"]
    assert "right_0001.png" in bad["error"] and not (out / "seq" / "0001").exists()
    for name in done:
        entry = pairs[name]
        assert entry["status"] == "done" and entry["this_run"] == "processed"
        expected = DEPTH_FILES if name == "eth3d/terrace" else DISPARITY_FILES
        assert set(entry["outputs"]) == expected
        assert {p.name for p in (out / name).iterdir()} == expected
        # The worker's disparity is what depth_map gives on the same pair, bit for bit.
        left, right = imread(scenes / name / "left.png"), imread(scenes / name / "right.png")
        calib = None
        if name == "eth3d/terrace":
            calib = Calibration.from_file(scenes / name / "calib.txt")
        ref = depth_map(left, right, calib)
        np.testing.assert_array_equal(read_pfm(out / name / "disparity.pfm"), ref.disparity)
        assert entry["max_disparity"] == ref.max_disparity
        assert entry["density"] == pytest.approx(ref.density, abs=1e-4)
        if calib is not None:
            assert ref.depth is not None
            np.testing.assert_array_equal(np.load(out / name / "depth.npy"), ref.depth)
    assert len(read_ply(out / "eth3d/terrace/cloud.ply")[0]) == pairs["eth3d/terrace"]["points"]
    assert not [p for p in out.rglob(".*")]  # no temporary folder left behind

    # Second run: everything is skipped, nothing rewritten, no cluster started.
    before = _tree(out)
    rc = main(["batch", str(scenes), "-o", str(out), "--workers", "2"])
    assert rc == 1  # the corrupt pair still has no outputs
    said = capsys.readouterr().out
    assert "0 failed in" in said and "exit status 1: 1 pair(s) still without outputs" in said
    s = _summary(out)
    assert s["run"]["processed"] == 0 and s["run"]["skipped"] == 3
    assert s["run"]["skipped_failed"] == 1 and s["run"]["scheduler"] is None
    assert all(p["this_run"] == "skipped" for p in s["pairs"].values())
    assert _tree(out) == before

    # The image is repaired: the next run, on an existing scheduler, redoes that pair only.
    shutil.copy(scenes / "middlebury2001/tsukuba/right.png", scenes / "seq/right_0001.png")
    with (
        distributed.LocalCluster(
            n_workers=1,  # one pair to redo: a second worker process would start for nothing
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            silence_logs=logging.CRITICAL,
        ) as cluster,
    ):
        rc = main(["batch", str(scenes), "-o", str(out), "--scheduler", cluster.scheduler_address])
    assert rc == 0
    s = _summary(out)
    assert s["run"]["scheduler"] == cluster.scheduler_address
    assert s["run"]["processed"] == 1 and s["run"]["skipped"] == 3
    entry = s["pairs"]["seq/0001"]
    assert entry["status"] == "done" and "error" not in entry
    np.testing.assert_array_equal(
        read_pfm(out / "seq/0001/disparity.pfm"),
        read_pfm(out / "middlebury2001/tsukuba/disparity.pfm"),
    )
    assert s["counts"] == {"done": 4, "failed": 0, "pending": 0}


def test_unreachable_scheduler_leaves_no_new_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A run whose scheduler cannot be reached never starts: it left the folder it had just
    made holding a summary with every pair pending. Nothing it made is left now; an output
    folder that was there stays."""
    import stereovision.batch as batch

    monkeypatch.setattr(batch, "CONNECT_TIMEOUT", "1s")
    _noise_pair(tmp_path / "in" / "scene")
    out = tmp_path / "new" / "out"
    rc = main(["batch", str(tmp_path / "in"), "-o", str(out), "--scheduler", "tcp://127.0.0.1:1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2
    assert len(err) == 1 and "cannot reach the Dask scheduler at tcp://127.0.0.1:1" in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]
    # through "..": mkdir -p made new2/ and out2/, both go (new2/ was left)
    out = tmp_path / "new2" / ".." / "out2"
    rc = main(["batch", str(tmp_path / "in"), "-o", str(out), "--scheduler", "tcp://127.0.0.1:1"])
    assert rc == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]
    kept = tmp_path / "kept"
    kept.mkdir()
    rc = main(["batch", str(tmp_path / "in"), "-o", str(kept), "--scheduler", "tcp://127.0.0.1:1"])
    assert rc == 2 and kept.is_dir()
    # the summary it wrote there (every pair pending, of a run that never started) goes too
    assert list(kept.iterdir()) == []


def test_a_password_in_an_address_is_not_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A scheduler address, or an input given as a URL, with a password: the one line said
    it (Dask's "invalid address 'admin:s3cret@127.0.0.1:1'", "input folder not found:
    rtsp:/admin:s3cret@cam/0"). It is said as ***; nothing is left written."""
    _noise_pair(tmp_path / "in" / "scene")
    out = tmp_path / "out"
    argv = ["batch", str(tmp_path / "in"), "-o", str(out)]
    assert main([*argv, "--scheduler", "tcp://admin:s3cret@127.0.0.1:1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'admin:***@127.0.0.1:1'" in err[0] and "s3cret" not in err[0]
    assert main(["batch", "rtsp://admin:s3cret@cam/0?token=tok77", "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["stereovision: error: input folder not found: rtsp://admin:***@cam/0?token=***"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]


def test_find_pairs_names(tmp_path: Path) -> None:
    img = np.zeros((8, 8, 3), np.uint8)
    files = [
        "a/scene1/left.png",
        "a/scene1/right.png",
        "a/scene1/calib.txt",
        "caps/left_0001.png",
        "caps/right_0001.png",
        "caps/left_0002.png",  # no right image: ignored
        "cams/000_Left.jpg",
        "cams/000_Right.jpg",
        "cams/.left_hidden.png",
        "cams/.right_hidden.png",
    ]
    for f in files:
        p = tmp_path / f
        p.parent.mkdir(parents=True, exist_ok=True)
        if p.suffix == ".txt":
            p.write_text("x")
        else:
            cv2.imwrite(str(p), img)
    jobs = find_pairs(tmp_path)
    assert [j.name for j in jobs] == ["a/scene1", "cams/000", "caps/0001"]
    assert jobs[0] == PairJob(
        "a/scene1",
        tmp_path / "a/scene1/left.png",
        tmp_path / "a/scene1/right.png",
        tmp_path / "a/scene1/calib.txt",
    )
    assert jobs[1].right == tmp_path / "cams/000_Right.jpg"
    assert jobs[2].right == tmp_path / "caps/right_0001.png" and jobs[2].calib is None
    # A scene folder given itself is named after the folder; --calib applies to every pair.
    Calibration.ideal((8, 8), 60.0, 0.1).save(tmp_path / "rig.yaml")
    solo = find_pairs(tmp_path / "a/scene1", calib=tmp_path / "rig.yaml")
    assert [(j.name, j.calib) for j in solo] == [("scene1", tmp_path / "rig.yaml")]


def test_find_pairs_keeps_the_case_of_left_and_takes_the_last_left(tmp_path: Path) -> None:
    """``000_LEFT.png`` pairs with ``000_RIGHT.png`` (the case of the word kept, as
    ``000_Left`` with ``000_Right``); in ``cleft_left_0001.png`` the ``left`` replaced is the
    last one (``cleft_right_0001.png``), and the pair is named without it."""
    img = np.zeros((8, 8, 3), np.uint8)
    for f in ("up/000_LEFT.png", "up/000_RIGHT.png", "c/cleft_left_0001.png",
              "c/cleft_right_0001.png"):  # fmt: skip
        p = tmp_path / f
        p.parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(p), img)
    jobs = find_pairs(tmp_path)
    assert [(j.name, j.left.name, j.right.name) for j in jobs] == [
        ("c/cleft_0001", "cleft_left_0001.png", "cleft_right_0001.png"),
        ("up/000", "000_LEFT.png", "000_RIGHT.png"),
    ]


def test_find_pairs_pairs_images_whose_extensions_differ_in_case(tmp_path: Path) -> None:
    """``left.PNG`` + ``right.png`` (one camera's spelling and a tool's) were two half pairs,
    "no right.PNG beside left.PNG" and "no left.png beside right.png": one pair now, a scene
    with its calib.txt; the same for ``cam_left_1.JPG`` + ``cam_right_1.jpg``."""
    _blank(tmp_path, "s/left.PNG", "s/right.png", "q/cam_left_1.JPG", "q/cam_right_1.jpg")
    (tmp_path / "s/calib.txt").write_text("")
    import stereovision.batch as batch

    jobs, unpaired, _ = batch._scan(tmp_path)
    assert [(j.name, j.left.name, j.right.name, j.calib) for j in jobs] == [
        ("q/cam_1", "cam_left_1.JPG", "cam_right_1.jpg", None),
        ("s", "left.PNG", "right.png", tmp_path / "s/calib.txt"),
    ]
    assert unpaired == []
    # left.PNG beside left.png: right.png is left.png's (as before, left.PNG has no pair)
    _blank(tmp_path / "two", "left.png", "left.PNG", "right.png", "x_left.PNG", "x_left.png")
    _blank(tmp_path / "two", "x_right.png")
    jobs, unpaired, _ = batch._scan(tmp_path / "two")
    assert [(j.name, j.left.name, j.right.name) for j in jobs] == [
        ("two", "left.png", "right.png"),
        ("x", "x_left.png", "x_right.png"),
    ]
    assert [(u.name, u.present.name, u.missing.name) for u in unpaired] == [
        ("two~2", "left.PNG", "right.PNG"),
        ("x~2", "x_left.PNG", "x_right.PNG"),
    ]


def _blank(root: Path, *names: str) -> None:
    """An 8 x 8 black image under each name (``find_pairs`` reads names only)."""
    for name in names:
        p = root / name
        p.parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(p), np.zeros((8, 8, 3), np.uint8))


def test_find_pairs_layouts_it_leaves_out_or_names_by_the_root(tmp_path: Path) -> None:
    """Edge cases of the search: the root's own ``left.jpg`` pair takes the root's name,
    upper-case extensions count, hidden folders and a second link to one folder do not, and
    camera folders are not guessed (two spellings of ``left``, images of two sub-folders,
    a number that two images of one side carry)."""
    solo = tmp_path / "solo"
    _blank(solo, "left.jpg", "right.jpg")
    assert [j.name for j in find_pairs(solo)] == ["solo"]
    upper = tmp_path / "upper"
    _blank(upper, "s/left_1.PNG", "s/right_1.PNG", ".hidden/left.png", ".hidden/right.png")
    assert [(j.name, j.right.name) for j in find_pairs(upper)] == [("s/1", "right_1.PNG")]
    ext, linked = tmp_path / "ext", tmp_path / "linked"
    _blank(ext, "left.png", "right.png")
    linked.mkdir()
    for link in ("a", "b"):
        (linked / link).symlink_to(ext, target_is_directory=True)
    assert [j.name for j in find_pairs(linked)] == ["a"]  # the first link, whatever the listing
    cams = tmp_path / "cams"
    _blank(cams, "two/left/0001.png", "two/Left/0001.png", "two/right/0001.png")
    _blank(cams, "sub/left/a/0001.png", "sub/right/b/0001.png")
    _blank(cams, "dup/left/0001.png", "dup/left/1.png", "dup/right/01.png")
    import stereovision.batch as batch

    jobs, unpaired, _ = batch._scan(cams)
    assert jobs == []
    assert sorted(u.name for u in unpaired) == [
        "dup/0001",
        "dup/01",
        "dup/1",
        "sub/a/0001",
        "sub/b/0001",
    ]
    # an image without its pair takes the next name free after the pairs' clash
    clash = tmp_path / "clash"
    _blank(clash, "x_left.png", "x_right.png", "x/left.png", "x/right.png", "x-left.png")
    jobs, unpaired, _ = batch._scan(clash)
    assert [(j.name, j.left.relative_to(clash).as_posix()) for j in jobs] == [
        ("x", "x_left.png"),
        ("x~2", "x/left.png"),
    ]
    assert [(u.name, u.present.name) for u in unpaired] == [("x~3", "x-left.png")]


def test_a_clash_suffix_does_not_take_a_pair_s_own_name(tmp_path: Path) -> None:
    """Two pairs named ``x`` were told apart as ``x`` and ``x~2`` though a folder ``x~2`` held a
    pair of its own: two pairs named ``x~2``, one output folder and one summary entry for both.
    The suffix skips the names pairs have; names without a clash are unchanged."""
    _blank(tmp_path, "x/left.png", "x/right.png", "x/left.jpg", "x/right.jpg")
    _blank(tmp_path, "x~2/left.png", "x~2/right.png", "y/left_1.png", "y/right_1.png")
    jobs = find_pairs(tmp_path)
    assert [(j.name, j.left.relative_to(tmp_path).as_posix()) for j in jobs] == [
        ("x", "x/left.png"),
        ("x~2", "x~2/left.png"),
        ("x~3", "x/left.jpg"),
        ("y/1", "y/left_1.png"),
    ]


def test_batch_errors_are_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["batch", str(tmp_path / "missing"), "-o", str(tmp_path / "o")]) == 2
    assert main(["batch", str(tmp_path), "-o", str(tmp_path / "o")]) == 2
    assert main(["batch", str(tmp_path), "-o", str(tmp_path / "o"), "--workers", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3
    assert "not found" in err[0] and "no pair under" in err[1] and "workers" in err[2]
    # a bad --calib is one error before any pair runs (it was one failed pair per scene)
    for i in range(3):
        (tmp_path / f"s{i}").mkdir()
        for side in ("left", "right"):
            cv2.imwrite(str(tmp_path / f"s{i}" / f"{side}.png"), np.zeros((8, 8, 3), np.uint8))
    (tmp_path / "bad.yaml").write_text("K1: [1, 2]\n")
    assert main(["batch", str(tmp_path), "-o", str(tmp_path / "o"), "--calib",
                 str(tmp_path / "bad.yaml")]) == 2  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.yaml" in err[0], err
    assert not (tmp_path / "o").exists()
    # -o naming a file: said so (it was "[Errno 17] File exists: ...")
    (tmp_path / "taken").write_text("mine")
    assert main(["batch", str(tmp_path), "-o", str(tmp_path / "taken")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: error: -o {tmp_path / 'taken'}: is a file, not a folder"
    ]
    from stereovision.batch import run_batch

    with pytest.raises(ValueError, match=r"output folder .*taken/x: .*taken is a file, not a"):
        run_batch(tmp_path, tmp_path / "taken" / "x")
    assert (tmp_path / "taken").read_text() == "mine"
    with pytest.raises(NotADirectoryError, match=r"^input is not a folder: .*taken$"):
        run_batch(tmp_path / "taken", tmp_path / "o")


def test_batch_ctrl_c_keeps_finished_pairs(
    data_dir: Path, tmp_path: Path, in_process_dask: None
) -> None:
    """SIGINT in the middle: exit 130, finished pairs written and recorded, a re-run continues.
    The interrupted run is a process of its own with real worker processes; the re-run, whose
    point is the bookkeeping (what is skipped, what is done), has its worker in process."""
    root = tmp_path / "in"
    for i in range(12):
        _half(data_dir / "middlebury2001/tsukuba", root / f"s{i:02d}")
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "stereovision.cli", "batch", str(root), "-o", str(out)]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([*cmd, "--workers", "1"], env=env, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            try:
                if _summary(out)["counts"]["done"] >= 2:
                    break
            except (OSError, ValueError, KeyError):
                pass
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    s = _summary(out)
    done = sorted(n for n, p in s["pairs"].items() if p["status"] == "done")
    assert len(done) >= 2
    for n in done:
        assert {p.name for p in (out / n).iterdir()} == DISPARITY_FILES
        assert read_pfm(out / n / "disparity.pfm").shape == (144, 192)
    if len(done) < 12:  # interrupted before the end (the usual case)
        assert proc.returncode == 130 and "interrupted" in err
        assert s["run"]["interrupted"] is True
        assert s["counts"]["pending"] == 12 - len(done)
    assert not [p for p in out.rglob(".*")]
    # The re-run (in-process) does only what was left.
    assert main([*cmd[3:], "--workers", "1"]) == 0
    s = _summary(out)
    assert s["run"]["skipped"] == len(done) and s["run"]["processed"] == 12 - len(done)


def test_ros_camera_info_folder_as_batch_calibration(scenes: Path, tmp_path: Path) -> None:
    """--calib may be a ROS camera_info folder: the worker gets it as one JSON file and gives
    the depth depth_map gives with that calibration."""
    from stereovision.batch import _task, process_pair

    terrace = scenes / "eth3d/terrace"
    cal = Calibration.from_file(terrace / "calib.txt")
    cal.save_ros(tmp_path / "ros")
    (job,) = find_pairs(terrace, calib=tmp_path / "ros")
    task = _task(job, {"method": "gabor", "max_disparity": 32, "fill": None})
    assert task["calib"][0] == "calib.json"
    out = process_pair(task)
    left, right = imread(terrace / "left.png"), imread(terrace / "right.png")
    ref = depth_map(
        left, right, Calibration.from_file(tmp_path / "ros"), method="gabor", max_disparity=32
    )
    assert ref.depth is not None
    depth = np.load(io.BytesIO(out["files"]["depth.npy"]))
    np.testing.assert_array_equal(depth, ref.depth)


def test_batch_ground_outputs(data_dir: Path, tmp_path: Path, in_process_dask: None) -> None:
    """--ground: a worker writes the pair's floor and obstacles (and with --grid its occupancy
    grid) beside the depth outputs; the options of a run without it are those of earlier
    versions (outputs made before stay valid)."""
    from stereovision.batch import _task, process_pair, run_batch

    kitti = data_dir / "kitti2015" / "000005_10"
    (job,) = find_pairs(kitti)
    out = process_pair(_task(job, {"method": None, "max_disparity": None, "fill": None,
                                   "ground": True, "grid": 0.2}))  # fmt: skip
    files = out["files"]
    assert {"ground.json", "obstacles.png", "scan.json", "map.png", "map.yaml"} <= set(files)
    floor = json.loads(files["ground.json"])
    assert floor["height_m"] == pytest.approx(1.62, abs=0.03)
    with pytest.raises(ValueError, match="it needs ground=True"):
        run_batch(kitti, tmp_path / "o", grid=0.2)
    tsukuba = data_dir / "middlebury2001" / "tsukuba"  # no metric calibration: a failed pair
    (job,) = find_pairs(tsukuba)
    # Python's words, not the CLI's (a CLI run's summary swaps them: _error_line)
    with pytest.raises(ValueError, match=r"^ground=True needs calib=\.\.\. or a calib\.txt"):
        process_pair(_task(job, {"method": "gabor", "max_disparity": 16, "fill": None,
                                 "ground": True}))  # fmt: skip


def test_a_fractional_max_disparity_is_recorded_as_searched(tmp_path: Path) -> None:
    """max_disparity=20.5 (run_batch takes any positive number, as depth_map does) was recorded
    as the pair's max_disparity 20, int() cutting the range searched; a whole one stays an int."""
    from stereovision.batch import _task, process_pair

    _noise_pair(tmp_path / "s")
    (job,) = find_pairs(tmp_path / "s")
    for given in (20.5, 16):
        out = process_pair(_task(job, {"method": "fast", "max_disparity": given, "fill": None}))
        assert out["max_disparity"] == given and type(out["max_disparity"]) is type(given)


def test_batch_max_disparity_zero_is_refused(tmp_path: Path) -> None:
    """max_disparity=0 is no disparity range (0 is not "estimated"): refused by name, before
    the input is searched."""
    from stereovision.batch import run_batch

    with pytest.raises(ValueError, match=r"^max_disparity: expected a positive number, got 0$"):
        run_batch(tmp_path / "missing", tmp_path / "o", max_disparity=0)


def test_batch_unknown_method_or_fill_is_refused_before_the_run(
    data_dir: Path, tmp_path: Path
) -> None:
    """run_batch(method="censu") or fill="no" started a cluster, failed every pair with the same
    error ("unknown method 'censu'") and recorded them all as failed (a finished pair's record
    too), an output folder made; refused by name now, before the input is searched, as
    depth_map and run_stream refuse them. fill=numpy.True_ is True (it reached the summary's
    JSON, which cannot hold it)."""
    from stereovision.batch import run_batch

    root, out = tmp_path / "in", tmp_path / "o"
    _tiny(root, data_dir, "a_left.png", "a_right.png")
    with pytest.raises(
        ValueError, match=r"^unknown method 'censu': expected one of fused, gabor, census, fast$"
    ):
        run_batch(root, out, workers=1, method="censu", progress=False)
    with pytest.raises(TypeError, match=r"^fill: expected True, False or None, got 'no'$"):
        run_batch(root, out, workers=1, fill="no", progress=False)  # type: ignore[arg-type]
    assert not out.exists()
    res = run_batch(root, out, workers=1, max_disparity=16, fill=np.True_, progress=False)
    assert res.processed == ["a"] and _summary(out)["pairs"]["a"]["options"]["fill"] is True


def test_batch_max_disparity_is_checked_as_depth_map_checks_it(
    data_dir: Path, tmp_path: Path
) -> None:
    """max_disparity=True passed the check (True > 0) and every pair failed in the workers
    ("expected a number of pixels, got True"); "16" was Python's "'<=' not supported between
    instances of 'str' and 'int'"; NaN passed and failed every pair. All are refused by name
    now, before the input is searched. A NumPy integer (a range computed with NumPy) crashed
    the run at the summary's first write ("Object of type int64 is not JSON serializable"):
    it is taken as the number it is."""
    from stereovision.batch import run_batch

    root, out = tmp_path / "in", tmp_path / "o"
    _tiny(root, data_dir, "a_left.png", "a_right.png")
    for bad in (True, "16"):
        with pytest.raises(
            TypeError, match=rf"^max_disparity: expected a number of pixels, got {bad!r}$"
        ):
            run_batch(root, out, workers=1, max_disparity=bad, progress=False)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^max_disparity: expected a positive number, got nan$"):
        run_batch(root, out, workers=1, max_disparity=math.nan, progress=False)  # type: ignore[arg-type]
    assert not out.exists()
    res = run_batch(root, out, workers=1, max_disparity=np.int64(16), progress=False)  # type: ignore[arg-type]
    assert res.processed == ["a"] and _summary(out)["pairs"]["a"]["max_disparity"] == 16
    assert _summary(out)["pairs"]["a"]["options"]["max_disparity"] == 16


def test_batch_workers_must_be_a_whole_number(data_dir: Path, tmp_path: Path) -> None:
    """run_batch(workers=1.5) started the run and failed in the LocalCluster's start ("'float'
    object cannot be interpreted as an integer"), workers="2" in the check ("'<=' not
    supported between instances of 'str' and 'int'"), True passed as 1: refused by name, in
    the words of the CLI's --workers, before the input is searched."""
    from stereovision.batch import run_batch

    root, out = tmp_path / "in", tmp_path / "o"
    _tiny(root, data_dir, "a_left.png", "a_right.png")
    for bad in (1.5, "2", True, 0, math.nan):
        with pytest.raises(ValueError) as info:
            run_batch(root, out, workers=bad, progress=False)  # type: ignore[arg-type]
        assert str(info.value) == f"workers: expected a whole number above 0, got {bad!r}"
    assert not out.exists()


def test_batch_grid_is_a_number(data_dir: Path, tmp_path: Path) -> None:
    """run_batch(ground=True, grid=numpy.float32(0.25)) crashed at the summary's first write
    ("Object of type float32 is not JSON serializable"); grid="0.2" failed in Python's
    isfinite ("must be real number, not str"). A NumPy float is the number it is; a string is
    refused by name."""
    from stereovision.batch import run_batch

    root, out = tmp_path / "in", tmp_path / "o"
    _tiny(root, data_dir, "a_left.png", "a_right.png")
    with pytest.raises(TypeError, match=r"^grid: expected a cell side in metres, got '0.2'$"):
        run_batch(root, out, workers=1, ground=True, grid="0.2", progress=False)  # type: ignore[arg-type]
    assert not out.exists()
    # no calibration: the pair fails (ground needs one), recorded with the grid asked for
    res = run_batch(root, out, workers=1, ground=True, grid=np.float32(0.25), progress=False)  # type: ignore[arg-type]
    assert res.failed == ["a"]
    assert _summary(out)["pairs"]["a"]["options"]["grid"] == 0.25


def test_batch_a_range_or_cell_too_large_for_a_float_is_refused_by_name(
    data_dir: Path, tmp_path: Path
) -> None:
    """grid=10**400 passed the number check and failed in float() with Python's bare
    "OverflowError: int too large to convert to float"; max_disparity=10**400 passed as
    positive, and every pair failed alike in the workers with depth_map's refusal ("expected a
    finite number"), a cluster started and an output folder made. Both are refused by name,
    before the input is searched, max_disparity in depth_map's words."""
    from stereovision.batch import run_batch

    root, out = tmp_path / "in", tmp_path / "o"
    _tiny(root, data_dir, "a_left.png", "a_right.png")
    with pytest.raises(
        ValueError,
        match=r"^grid: expected a cell side from 0\.01 to 10 m, got an integer of 401 digits",
    ):
        run_batch(root, out, workers=1, ground=True, grid=10**400, progress=False)
    with pytest.raises(
        ValueError,
        match=r"^max_disparity: expected a finite number, got an integer of 401 digits",
    ):
        run_batch(root, out, workers=1, max_disparity=10**400, progress=False)
    assert not out.exists()


def test_batch_switches_are_true_or_false(tmp_path: Path) -> None:
    """run_batch(ground="no") went by truthiness (a floor asked for, every pair failing without a
    calibration) and retry_failed="no" redid the failed pairs; the CLI gives them as True or
    False (store_true). Anything else is refused by name, before the input is searched, as
    depth_map refuses such a switch."""
    from stereovision.batch import run_batch

    missing = tmp_path / "missing"
    for name in ("ground", "retry_failed"):
        for bad in ("no", 1, None):
            with pytest.raises(TypeError) as info:
                run_batch(missing, tmp_path / "o", **{name: bad})  # type: ignore[arg-type]
            assert str(info.value) == f"{name}: expected True or False, got {bad!r}"
        # NumPy's bools are taken (the missing input is the error)
        with pytest.raises(FileNotFoundError, match=r"^input folder not found: "):
            run_batch(missing, tmp_path / "o", **{name: np.True_})  # type: ignore[arg-type]
    assert not (tmp_path / "o").exists()


def test_batch_a_pair_failed_on_an_obstacle_is_done_once_it_is_gone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A file where pair a's output folder goes failed the pair with its fingerprint and
    options recorded: once the file was moved away the rerun skipped a as 'failed before'
    (exit 1, '--retry-failed redoes them'), though the code said a rerun meets the obstacle
    again. Such a failure is the output folder's, not the inputs': the pair is tried again on
    every run, as one whose image could not be read."""
    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, "a/left.png", "a/right.png")
    out.mkdir()
    (out / "a").write_text("notes")
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 1
    assert _summary(out)["pairs"]["a"]["status"] == "failed"
    (out / "a").unlink()
    capsys.readouterr()
    assert main(args) == 0, capsys.readouterr()
    pair = _summary(out)["pairs"]["a"]
    assert pair["status"] == "done" and pair["this_run"] == "processed"
    assert (out / "a" / "disparity.pfm").is_file()


def test_batch_grid_bounds_are_accepted_and_calib_unit_needs_calib(tmp_path: Path) -> None:
    """A grid cell of 0.01 m and of 10 m, the bounds, pass the options' check (the missing input
    is the error); past them, and a calib_unit without calib, are refused by name."""
    from stereovision.batch import run_batch

    missing = tmp_path / "missing"
    for cell in (0.01, 10.0):
        with pytest.raises(FileNotFoundError, match=r"^input folder not found: "):
            run_batch(missing, tmp_path / "o", ground=True, grid=cell)
    for cell in (0.0099, 10.5, math.nan):
        with pytest.raises(ValueError, match=r"^grid: expected a cell side from 0.01 to 10 m"):
            run_batch(missing, tmp_path / "o", ground=True, grid=cell)
    with pytest.raises(ValueError, match=r"^calib_unit is the unit of calib's file: give calib"):
        run_batch(missing, tmp_path / "o", calib_unit="mm")
    assert not (tmp_path / "o").exists()


def test_batch_redoes_the_pairs_when_the_grid_cell_changes(
    data_dir: Path, tmp_path: Path, in_process_dask: None
) -> None:
    """--grid is one of the options a pair was done with: a run with another cell side redoes
    it (it was skipped as done, its map.yaml still of the old cell), said as grid 0.2 -> 0.5."""
    from stereovision.batch import run_batch

    root, out = tmp_path / "in", tmp_path / "out"
    # columns 400-799 of the KITTI pair (its road ahead), the calibration's centre and width
    # made the crop's: the grid is the point, not the image's size
    kitti, k = data_dir / "kitti2015" / "000005_10", root / "k"
    k.mkdir(parents=True)
    for name in ("left.png", "right.png"):
        assert cv2.imwrite(str(k / name), cv2.imread(str(kitti / name))[:, 400:800])
    calib = (kitti / "calib.txt").read_text()
    assert "609.5593" in calib and "width=1242" in calib
    calib = calib.replace("609.5593", "209.5593").replace("width=1242", "width=400")
    (k / "calib.txt").write_text(calib)
    first = run_batch(root, out, workers=1, ground=True, grid=0.2, progress=False)
    assert first.processed == ["k"]
    lines: list[str] = []
    again = run_batch(root, out, workers=1, ground=True, grid=0.5, progress=False, log=lines.append)
    assert again.processed == ["k"] and again.redone == ["k"] and again.skipped == []
    assert "grid: 0.2 -> 0.5" in lines[0]
    assert _summary(out)["pairs"]["k"]["options"]["grid"] == 0.5
    meta = dict(
        line.split(":", 1)
        for line in (out / "k" / "map.yaml").read_text().splitlines()
        if ":" in line
    )
    assert float(meta["resolution"]) == pytest.approx(0.5)


# --------------------------------------------------------------------- interrupts (SIGINT, SIGTERM)


def _copies(data_dir: Path, root: Path, n: int) -> None:
    """``n`` scene folders holding the full-size Tsukuba pair (a few tenths of a second each)."""
    src = data_dir / "middlebury2001/tsukuba"
    for i in range(n):
        (root / f"s{i:02d}").mkdir(parents=True)
        for side in ("left.png", "right.png"):
            shutil.copy(src / side, root / f"s{i:02d}" / side)


def _children(pid: int) -> int:
    """Processes started by any thread of ``pid`` (Linux)."""
    n = 0
    for t in os.listdir(f"/proc/{pid}/task"):
        with contextlib.suppress(OSError):
            n += len(Path(f"/proc/{pid}/task/{t}/children").read_text().split())
    return n


def _done(out: Path) -> int:
    try:
        return int(_summary(out)["counts"]["done"])
    except (OSError, ValueError, KeyError):
        return -1


def _not_progress(err: str) -> list[str]:
    return [line for line in err.splitlines() if not re.match(r"batch: \d+/\d+ pairs", line)]


def _interrupted_run(
    root: Path, out: Path, sig: int, group: bool, ready: Callable[[int], bool]
) -> tuple[int, list[str]]:
    """Run the CLI in its own session, send ``sig`` (to the whole group: a terminal's Ctrl-C)
    once ``ready(pid)``; the exit status and the stderr lines other than progress lines."""
    cmd = [sys.executable, "-m", "stereovision.cli", "batch", str(root), "-o", str(out)]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(
        [*cmd, "--workers", "1"], env=env, stderr=subprocess.PIPE, text=True,
        start_new_session=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not ready(proc.pid) and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert proc.poll() is None, "the run ended before the signal"
        if group:
            os.killpg(proc.pid, sig)
        else:
            proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return proc.returncode, _not_progress(err)


@pytest.fixture
def dask_dashboard_port_taken() -> Iterator[None]:
    """Dask's default dashboard port, 8787, held on this machine as a Jupyter server or another
    cluster's dashboard holds it (held by something else already, it stays so)."""
    holder = socket.socket()
    try:
        with contextlib.suppress(OSError):
            holder.bind(("127.0.0.1", 8787))
            holder.listen()
        yield
    finally:
        holder.close()


def test_batch_says_nothing_of_dask_where_its_dashboard_port_is_taken(
    data_dir: Path, tmp_path: Path, dask_dashboard_port_taken: None
) -> None:
    """Port 8787 taken: the run's stderr holds its progress lines and nothing else (the
    LocalCluster's scheduler served its HTTP routes on 8787 despite dashboard_address=None and
    warned "Port 8787 is already in use", and the socket of its failed bind was reported
    unclosed: two lines from Dask)."""
    root, out = tmp_path / "in", tmp_path / "out"
    _copies(data_dir, root, 2)
    cmd = [sys.executable, "-m", "stereovision.cli", "batch", str(root), "-o", str(out)]
    proc = subprocess.run(
        [*cmd, "--workers", "1"], capture_output=True, text=True, timeout=300, check=False
    )
    assert proc.returncode == 0, proc.stderr
    assert _not_progress(proc.stderr) == []
    assert _summary(out)["counts"] == {"done": 2, "failed": 0, "pending": 0}


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="process groups, /proc")
@pytest.mark.parametrize(
    ("sig", "group"),
    [(signal.SIGINT, True), (signal.SIGTERM, True), (signal.SIGTERM, False)],
    ids=["ctrl-c-group", "term-group", "term"],
)
def test_batch_interrupt_is_one_line(
    data_dir: Path, tmp_path: Path, sig: int, group: bool, dask_dashboard_port_taken: None
) -> None:
    """Ctrl-C in a terminal (SIGINT to the process and its Dask workers) or SIGTERM: one line,
    exit 130 (143 for SIGTERM), the summary marked as interrupted with the finished pairs kept
    (the workers printed a KeyboardInterrupt traceback each; SIGTERM exited 143 silently with
    the run not
    marked, and a resource_tracker warning)."""
    root, out = tmp_path / "in", tmp_path / "out"
    _copies(data_dir, root, 40)
    rc, err = _interrupted_run(root, out, sig, group, lambda pid: _done(out) >= 1)
    s = _summary(out)
    done = s["counts"]["done"]
    what = "terminated (SIGTERM)" if sig == signal.SIGTERM else "interrupted"
    assert rc == (143 if sig == signal.SIGTERM else 130)
    assert len(err) == 1 and err[0].startswith(f"stereovision: {what}: "), err
    assert f"{done} of 40 pairs finished this run" in err[0] and "run again" in err[0]
    assert s["run"]["interrupted"] is True and "finished" in s["run"]
    assert 1 <= done < 40 and s["counts"] == {"done": done, "failed": 0, "pending": 40 - done}
    for name, entry in s["pairs"].items():
        assert (entry["status"] == "done") == (out / name / "disparity.pfm").is_file()
    assert not [p for p in out.rglob(".*")]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="process groups, /proc")
def test_batch_ctrl_c_while_the_cluster_starts(
    data_dir: Path, tmp_path: Path, dask_dashboard_port_taken: None
) -> None:
    """Ctrl-C while the LocalCluster starts its workers: held until it is up, then the same one
    line (it was distributed's atexit traceback, AssertionError: Status.init, and a summary
    left with "interrupted": false)."""
    root, out = tmp_path / "in", tmp_path / "out"
    _copies(data_dir, root, 4)
    rc, err = _interrupted_run(
        root, out, signal.SIGINT, True, lambda pid: _done(out) == 0 and _children(pid) >= 2
    )
    assert rc == 130
    assert err == [
        f"stereovision: interrupted: 0 of 4 pairs finished this run, in {out} and recorded in "
        f"{out / SUMMARY_NAME}; run again to continue"
    ]
    s = _summary(out)
    assert s["run"]["interrupted"] is True and "finished" in s["run"]
    assert s["counts"] == {"done": 0, "failed": 0, "pending": 4}


def test_batch_keeps_a_sigterm_handler_that_raises_keyboardinterrupt(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A caller's SIGTERM handler is left in place after the run (the CLI's main uses its own
    while it runs: SIGTERM ends the run as Ctrl-C does, said as terminated, exit 143)."""
    root, out = tmp_path / "in", tmp_path / "out"
    _copies(data_dir, root, 40)

    def to_interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    def send_when_one_is_done() -> None:
        deadline = time.monotonic() + 60
        while _done(out) < 1 and time.monotonic() < deadline:
            time.sleep(0.02)
        os.kill(os.getpid(), signal.SIGTERM)

    old = signal.signal(signal.SIGTERM, to_interrupt)
    try:
        sender = threading.Thread(target=send_when_one_is_done, daemon=True)
        sender.start()
        rc = main(["batch", str(root), "-o", str(out), "--workers", "1"])
        sender.join()
        assert signal.getsignal(signal.SIGTERM) is to_interrupt
    finally:
        signal.signal(signal.SIGTERM, old)
    assert rc == 143
    err = _not_progress(capsys.readouterr().err)
    assert len(err) == 1 and err[0].startswith("stereovision: terminated (SIGTERM): "), err
    s = _summary(out)
    assert s["run"]["interrupted"] is True and 1 <= s["counts"]["done"] < 40


def _tiny(root: Path, data_dir: Path, *names: str) -> None:
    """A 96 x 64 crop of Tsukuba under each name: the left image's for ``...left...`` names."""
    src = data_dir / "middlebury2001/tsukuba"
    crops = {s: cv2.imread(str(src / f"{s}.png"))[100:164, 150:246] for s in ("left", "right")}
    for name in names:
        p = root / name
        p.parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(p), crops["left" if "left" in p.name.lower() else "right"])


def _change(path: Path) -> None:
    """A new version of the image: one pixel changed (a new modification time alone, with the
    same bytes, is not a change: the pair is not redone)."""
    img = cv2.imread(str(path))
    img[0, 0] = 255 - img[0, 0]
    cv2.imwrite(str(path), img)
    os.utime(path, ns=(1, 1))


def test_batch_reports_an_image_without_its_pair(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """left.png without right.png, x_left.png without x_right.png, y_right.png without
    y_left.png: each a failed pair saying which file is missing, exit 1 (they were ignored:
    "1 processed ... 0 failed", exit 0, nowhere in the summary). The pairs found are the same."""
    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, "a/left.png", "a/right.png", "b/left.png", "c/x_left.png",
          "c/y_right.png", "c/.z_left.png")  # fmt: skip
    (root / "c/notes_left.txt").write_text("not an image")
    assert [j.name for j in find_pairs(root)] == ["a"]
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 1
    said = capsys.readouterr()
    assert said.out.startswith(
        "1 processed, 0 skipped (done before), 3 failed (3 with an image missing) in "
    )
    missing = {"b": ("right.png", "b/left.png"), "c/x": ("x_right.png", "c/x_left.png"),
               "c/y": ("y_left.png", "c/y_right.png")}  # fmt: skip
    s = _summary(out)
    assert sorted(s["pairs"]) == ["a", "b", "c/x", "c/y"]
    assert s["counts"] == {"done": 1, "failed": 3, "pending": 0}
    assert s["run"]["pairs"] == 4 and s["run"]["unpaired"] == 3 and s["run"]["failed"] == 3
    for name, (gone, there) in missing.items():
        entry = s["pairs"][name]
        error = f"unpaired image: no {gone} beside {root / there}"
        assert entry["status"] == "failed" and entry["error"] == error
        assert f"failed {name}: {error}" in said.err
    assert s["pairs"]["c/y"]["left"] == str(root / "c/y_left.png")
    assert all(s["pairs"][name]["this_run"] == "failed" for name in missing)
    # the missing image comes: that pair is done, the others stay failed
    _tiny(root, data_dir, "b/right.png")
    assert main(args) == 1
    assert capsys.readouterr().out.startswith("1 processed, 1 skipped (done before), 2 failed (2 ")
    assert _summary(out)["counts"] == {"done": 2, "failed": 2, "pending": 0}
    # images without their pair only: the error says so
    assert main(["batch", str(root / "c"), "-o", str(tmp_path / "o2")]) == 2
    assert capsys.readouterr().err.strip() == (
        f"stereovision: error: no pair under {root / 'c'} (scene folders with left.png + "
        "right.png or im0.png + im1.png, files named ...left... / ...right..., or the same file "
        "names in sibling camera folders left/ + right/, L/ + R/, image_2/ + image_3/, "
        "image_02/ + image_03/, cam0/ + cam1/, image_left/ + image_right/); 2 "
        f"image(s) without the other of their pair, e.g. no x_right.png beside "
        f"{root / 'c/x_left.png'}"
    )


def _holding(needle: bytes) -> int:
    """How many containers Python tracks hold a bytes-like value with ``needle`` in it."""
    gc.collect()
    found = 0
    for obj in gc.get_objects():
        if isinstance(obj, dict):
            values: Any = obj.values()
        elif isinstance(obj, (list, tuple, deque)):
            values = obj
        else:
            continue
        with contextlib.suppress(Exception):  # a container changed by another thread
            for v in list(values):
                if isinstance(v, (bytes, bytearray, memoryview)) and len(v) >= len(needle):
                    found += needle in bytes(v)
    return found


def test_batch_keeps_no_copy_of_finished_pairs_inputs(
    data_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Dask's client logged its last 1000 messages under 1 MB, each submitted pair's image
    bytes in them (and its LocalCluster's scheduler its tasks): the client grew by the pairs'
    size, 62 MB over 90 Tsukuba pairs (flat with the fix). Once the last pair is written, the
    first pair's left image is held nowhere."""
    import stereovision.batch as batch

    root = tmp_path / "in"
    names = [f"seq/{i}_left.png" for i in range(5)] + [f"seq/{i}_right.png" for i in range(5)]
    _tiny(root, data_dir, *names)
    for i in range(5):  # each pair's images their own bytes
        img = cv2.imread(str(root / f"seq/{i}_left.png"))
        img[0, : i + 1] = 0
        cv2.imwrite(str(root / f"seq/{i}_left.png"), img)
    first = (root / "seq/0_left.png").read_bytes()
    held: list[int] = []
    commit = batch._commit_pair

    def counting(out: Path, name: str, *args: Any) -> Path:
        if name == "seq/4":
            held.append(_holding(first))
        return commit(out, name, *args)

    monkeypatch.setattr(batch, "_commit_pair", counting)
    res = batch.run_batch(root, tmp_path / "out", workers=1, progress=False)
    assert len(res.processed) == 5 and held == [0]


def test_batch_progress_lines_when_stderr_is_not_a_terminal(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    in_process_dask: None,
) -> None:
    """Without a terminal (a log file, a pipe) a plain line every tenth of the pairs, or every
    PROGRESS_SECONDS (there was none: tqdm only shows on a terminal)."""
    import stereovision.batch as batch

    root = tmp_path / "in"
    _tiny(root, data_dir, *(f"seq/{i:04d}_{s}.png" for i in range(12) for s in ("left", "right")))
    args = ["batch", str(root), "--workers", "1", "--max-disparity", "16"]
    line = re.compile(r"batch: (\d+)/12 pairs, \d+ s, about \d+ s left")

    def counts() -> list[int]:
        err = capsys.readouterr().err.splitlines()
        assert all(line.fullmatch(x) for x in err), err
        return [int(m[1]) for x in err if (m := line.fullmatch(x))]

    # The tenth-of-the-pairs rule alone: the clock's rule said one more line wherever 10 s
    # passed between two of those (the cluster's start counts, on a loaded machine 10 s).
    monkeypatch.setattr(batch, "PROGRESS_SECONDS", math.inf)
    assert main([*args, "-o", str(tmp_path / "o1")]) == 0
    assert counts() == [2, 4, 6, 8, 10]  # every tenth, rounded up: 2 pairs
    monkeypatch.setattr(batch, "PROGRESS_SECONDS", 0.0)
    assert main([*args, "-o", str(tmp_path / "o2")]) == 0
    assert counts() == list(range(1, 12))


def test_batch_output_folder_moved_during_the_run(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    in_process_dask: None,
) -> None:
    """The output folder moved away after two pairs: the pairs written before are counted as
    missing (pending in the summary), exit 1, and a re-run redoes them (the summary said all
    were done, exit 0)."""
    import stereovision.batch as batch

    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, *(f"seq/{i:04d}_{s}.png" for i in range(4) for s in ("left", "right")))
    commit = batch._commit_pair
    written: list[str] = []

    def commit_then_move(out_dir: Path, name: str, files: dict[str, bytes], *more: Any) -> Path:
        dest = commit(out_dir, name, files, *more)
        written.append(name)
        if len(written) == 2:
            out_dir.rename(tmp_path / "moved")
        return dest

    monkeypatch.setattr(batch, "_commit_pair", commit_then_move)
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 1
    said = capsys.readouterr()
    assert said.out.splitlines()[1] == (
        f"exit status 1: 2 pair(s) recorded as done have no outputs in {out} any more (moved or "
        "deleted during the run?); run again to redo them"
    )
    assert f"{out} is gone (moved or deleted?): made again for the pairs to come" in said.err
    s = _summary(out)
    assert s["counts"] == {"done": 2, "failed": 0, "pending": 2} and s["run"]["missing"] == 2
    for name in written[:2]:
        assert (
            s["pairs"][name]["status"] == "pending"
            and "moved or deleted" in s["pairs"][name]["note"]
        )
        assert not (out / name).exists() and (tmp_path / "moved" / name / "disparity.pfm").is_file()
    monkeypatch.setattr(batch, "_commit_pair", commit)
    assert main(args) == 0
    s = _summary(out)
    assert s["run"]["processed"] == 2 and s["run"]["skipped"] == 2 and s["run"]["missing"] == 0
    assert s["counts"] == {"done": 4, "failed": 0, "pending": 0}


def test_batch_says_when_other_options_redo_finished_pairs(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """Another --method redoes every finished pair: one line says so before (it was silent)."""
    from stereovision.batch import _changes

    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, *(f"seq/{i:04d}_{s}.png" for i in range(2) for s in ("left", "right")))
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main([*args, "--method", "fast"]) == 0
    assert "other options" not in capsys.readouterr().err
    assert main([*args, "--method", "census"]) == 0
    said = capsys.readouterr()
    assert said.out.startswith("2 processed, 0 skipped (done before), 0 failed in ")
    assert said.err.splitlines()[0] == (
        "2 pair(s) were done with other options (method: fast -> census); they are redone and "
        "their outputs replaced"
    )
    assert all(p["options"]["method"] == "census" for p in _summary(out)["pairs"].values())
    assert main([*args, "--method", "census"]) == 0  # the same options: skipped, nothing said
    said = capsys.readouterr()
    assert "other options" not in said.err and said.out.startswith("0 processed, 2 skipped")
    # --ground added to a run made without it (whose options have no ground key)
    before = {"method": None, "max_disparity": None, "fill": None}
    assert _changes(before, {**before, "ground": True, "grid": 0.2}) == [
        "ground: off -> on",
        "grid: default -> 0.2",
    ]


def test_batch_never_deletes_what_an_output_folder_already_holds(
    data_dir: Path, tmp_path: Path, in_process_dask: None
) -> None:
    """A pair's outputs go into a folder that holds other things: the input images (-o given as
    the input folder), the outputs of a pair nested in it, a user's file. They are kept; a pair
    redone without --ground loses the ground files of its earlier run only. (The folder was
    replaced whole: -o IN deleted IN/a/left.png and right.png, a redone pair `a` deleted the
    outputs of `a/b`.)"""
    root = tmp_path / "in"
    _tiny(root, data_dir, "a/left.png", "a/right.png", "a/b/left.png", "a/b/right.png")
    images = {p: p.read_bytes() for p in root.rglob("*.png")}
    (root / "a/notes.txt").write_text("mine")
    args = ["batch", str(root), "-o", str(root), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    assert {p: p.read_bytes() for p in images} == images  # the inputs are all there
    assert (root / "a/notes.txt").read_text() == "mine"
    assert {p.name for p in (root / "a/b").iterdir()} == {"left.png", "right.png", *DISPARITY_FILES}
    # `a` redone (its image changed): the outputs of `a/b`, nested in its folder, stay
    _change(root / "a/left.png")
    assert main(args) == 0
    s = _summary(root)
    assert s["run"]["processed"] == 1 and s["run"]["skipped"] == 1 and s["run"]["missing"] == 0
    assert (root / "a/b/disparity.pfm").is_file() and (root / "a/left.png").is_file()
    # an earlier run's file this run does not write is removed, a user's file stays
    (root / "a/ground.json").write_text("{}")
    entry = s["pairs"]["a"]
    entry["outputs"] = [*entry["outputs"], "ground.json"]
    entry["fingerprint"] = {}
    (root / SUMMARY_NAME).write_text(json.dumps(s))
    assert main(args) == 0
    assert not (root / "a/ground.json").exists() and (root / "a/notes.txt").is_file()
    assert {p.name for p in (root / "a").iterdir() if p.is_file()} == {
        "left.png",
        "right.png",
        "notes.txt",
        *DISPARITY_FILES,
    }
    assert not [p for p in root.rglob(".*")]  # no temporary folder left behind


def test_batch_starts_no_more_workers_than_pairs(data_dir: Path, tmp_path: Path) -> None:
    """2 pairs, --workers 4: 2 worker processes (each starts Python, NumPy and OpenCV; the
    default, one per core, started 64 on a 64-core machine for 2 pairs)."""
    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, *(f"seq/{i:04d}_{s}.png" for i in range(2) for s in ("left", "right")))
    args = ["batch", str(root), "-o", str(out), "--workers", "4", "--max-disparity", "16"]
    assert main(args) == 0
    assert _summary(out)["run"]["scheduler"] == "LocalCluster(2 worker processes)"


def test_a_large_summary_is_not_rewritten_after_every_pair(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A summary that takes 0.5 s to write (10000 pairs), pairs finishing every 0.125 s: written
    once ten times its writing time has passed, not after each pair (that made a long run
    quadratic: 0.5 s a pair at 10000 pairs); what is held back is written by flush()."""
    import stereovision.batch as batch

    clock = [0.0]
    monkeypatch.setattr(batch.time, "monotonic", lambda: clock[0])
    real_dump = batch.json.dump

    def slow_dump(*args: Any, **kwargs: Any) -> None:
        clock[0] += 0.5  # the write of a large summary
        real_dump(*args, **kwargs)

    monkeypatch.setattr(batch.json, "dump", slow_dump)
    summary = batch._Summary(tmp_path)
    writes = []
    for k in range(100):
        summary.pairs[f"p{k}"] = {"status": "done"}
        before = clock[0]
        summary.record()
        if clock[0] != before:
            writes.append(k)
        clock[0] += 0.125  # the next pair
    # written after the first pair, then each time 5 s (10 x 0.5 s) had passed since
    assert writes == [0, 40, 80]
    assert len(_summary(tmp_path)["pairs"]) == 81
    summary.flush()
    assert len(_summary(tmp_path)["pairs"]) == 100
    clock[0] += 1.0
    summary.flush()  # nothing left: not written again
    assert clock[0] == 0.5 * 4 + 100 * 0.125 + 1.0


def test_batch_refuses_to_replace_the_outputs_of_another_input(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A second drive whose pairs have the first one's names, into the same -o: refused before
    any work, one line (the first drive's outputs were replaced without a word). The same input
    with a changed image is still redone, and the first input moved elsewhere is skipped."""
    one, two, out = tmp_path / "drive1", tmp_path / "drive2", tmp_path / "out"
    names = [f"seq/{i:04d}_{s}.png" for i in range(2) for s in ("left", "right")]
    _tiny(one, data_dir, *names)
    _tiny(two, data_dir, *names)
    cv2.imwrite(str(two / "seq/0001_left.png"), np.zeros((64, 96, 3), np.uint8))
    _change(two / "seq/0000_left.png")  # other images (the same bytes are the same pair)
    args = ["--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(one), "-o", str(out), *args]) == 0
    before = _tree(out)
    capsys.readouterr()
    assert main(["batch", str(two), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"stereovision: error: output folder {out} holds the outputs of 2 pair(s) of the same "
        f"names made from other images (e.g. seq/0000 from "
        f"{one / 'seq/0000_left.png'}); give another output folder, or remove those pairs' "
        "folders to replace them"
    ]
    assert _tree(out) == before and _summary(out)["input"] == str(one)
    _change(one / "seq/0001_left.png")  # the same input, an image changed
    assert main(["batch", str(one), "-o", str(out), *args]) == 0
    assert _summary(out)["run"]["processed"] == 1
    shutil.move(one, tmp_path / "moved")  # the input moved: its pairs are done, skipped
    assert main(["batch", str(tmp_path / "moved"), "-o", str(out), *args]) == 0
    assert _summary(out)["run"]["skipped"] == 2


def test_batch_skipped_pairs_record_where_their_images_are_now(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """An input folder moved (its images' times kept) and run again: its pairs are skipped,
    and their records name the images where they are now. They named the old place, a path
    gone, beside the summary's new ``input``; a new drive made at that old place was then
    taken for the pairs' own images, and its other images replaced the moved drive's
    outputs without a word (refused for any other folder as 'made from other images')."""
    one, out = tmp_path / "drive1", tmp_path / "out"
    names = [f"seq/{i:04d}_{s}.png" for i in range(2) for s in ("left", "right")]
    _tiny(one, data_dir, *names)
    args = ["--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(one), "-o", str(out), *args]) == 0
    moved = tmp_path / "moved"
    shutil.move(one, moved)  # mv keeps the times: the pairs are skipped
    assert main(["batch", str(moved), "-o", str(out), *args]) == 0
    pairs = _summary(out)["pairs"]
    assert _summary(out)["run"]["skipped"] == 2
    assert [(pairs[n]["left"], pairs[n]["right"]) for n in ("seq/0000", "seq/0001")] == [
        (str(moved / f"seq/{i:04d}_left.png"), str(moved / f"seq/{i:04d}_right.png"))
        for i in range(2)
    ]
    # another drive at the first one's old place: its pairs are not the moved drive's
    _tiny(one, data_dir, *names)
    _change(one / "seq/0000_left.png")
    _change(one / "seq/0001_left.png")
    before = _tree(out)
    capsys.readouterr()
    assert main(["batch", str(one), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"stereovision: error: output folder {out} holds the outputs of 2 pair(s) of the same "
        f"names made from other images (e.g. seq/0000 from "
        f"{moved / 'seq/0000_left.png'}); give another output folder, or remove those pairs' "
        "folders to replace them"
    ]
    assert _tree(out) == before and _summary(out)["input"] == str(moved)


def test_batch_a_skip_through_a_link_keeps_the_images_it_recorded(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A drive run as it is, then through a link to it (its pairs skipped): the skip rewrote
    the records to name the images through the link, so once the link was pointed at another
    drive its other images passed for the pairs' own (_same_file resolves the link) and
    replaced the first drive's outputs without a word (exit 0, 1 processed), where before
    caa148b, and for any other folder, they are refused as 'made from other images'. A skip
    now keeps a recorded path that still names the pair's image; one gone (the input moved)
    is replaced as before."""
    one, two, out = tmp_path / "drive1", tmp_path / "drive2", tmp_path / "out"
    _tiny(one, data_dir, "a/left.png", "a/right.png")
    _tiny(two, data_dir, "a/left.png", "a/right.png")
    _change(two / "a/left.png")
    link = tmp_path / "current"
    link.symlink_to(one)
    args = ["--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(one), "-o", str(out), *args]) == 0
    assert main(["batch", str(link), "-o", str(out), *args]) == 0
    assert _summary(out)["run"]["skipped"] == 1
    assert _summary(out)["pairs"]["a"]["left"] == str(one / "a/left.png")
    link.unlink()
    link.symlink_to(two)
    before = _tree(out)
    capsys.readouterr()
    assert main(["batch", str(link), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"stereovision: error: output folder {out} holds the outputs of 1 pair(s) of the same "
        f"names made from other images (e.g. a from {one / 'a/left.png'}); give another output "
        "folder, or remove those pairs' folders to replace them"
    ]
    assert _tree(out) == before


def test_batch_refuses_to_replace_a_file_it_did_not_write(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A pair's output folder holding the user's own disparity.png (no run recorded writing it):
    it was replaced silently; now refused before any work, one line naming it, exit 2. A rerun
    over the pair's own outputs (recorded in the summary) still replaces them."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png")
    (out / "a").mkdir(parents=True)
    (out / "a" / "disparity.png").write_text("mine")
    args = ["--workers", "1", "--max-disparity", "16"]
    capsys.readouterr()
    assert main(["batch", str(src), "-o", str(out), *args]) == 2
    assert capsys.readouterr().err.splitlines() == [_not_ours(out, "a", "disparity.png")]
    assert (out / "a" / "disparity.png").read_text() == "mine"
    assert sorted(p.name for p in (out / "a").iterdir()) == ["disparity.png"]
    (out / "a" / "disparity.png").unlink()
    assert main(["batch", str(src), "-o", str(out), *args]) == 0
    _change(src / "a/left.png")  # changed: redone over its own outputs
    assert main(["batch", str(src), "-o", str(out), *args]) == 0
    assert _summary(out)["run"]["processed"] == 1
    assert cv2.imread(str(out / "a" / "disparity.png")) is not None


def test_batch_refuses_to_replace_a_link_put_under_an_output_name_it_wrote(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A pair's disparity.png (recorded as written) that the user replaced by a link to a file
    of theirs: the redo replaced the link with its own file, unsaid (a redo that does not write
    the name keeps such a link). Refused before any work, one line naming it, exit 2."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png")
    args = ["--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(src), "-o", str(out), *args]) == 0
    mine = tmp_path / "mine.png"
    mine.write_bytes(b"mine")
    (out / "a" / "disparity.png").unlink()
    (out / "a" / "disparity.png").symlink_to(mine)
    _change(src / "a/left.png")  # changed: to be redone
    capsys.readouterr()
    assert main(["batch", str(src), "-o", str(out), *args]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: error: output folder {out}: {out / 'a' / 'disparity.png'} is a link, "
        "not the file an earlier run wrote there, and would be replaced: give another output "
        "folder, or move or remove that file"
    ]
    assert (out / "a" / "disparity.png").is_symlink() and mine.read_bytes() == b"mine"


def test_batch_resumes_a_pair_written_by_a_run_killed_before_recording_it(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A run killed after writing a pair's folder but before its summary recorded it (record()
    holds writes back; SIGKILL, the OOM killer) leaves the pair "pending" with no outputs
    listed: the rerun refused the pair's own disparity.png as a file it did not write, exit 2.
    The run that left it pending had checked the folder before it began, so the files under
    the names it would write are its own: the pair is redone over them."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png")
    args = ["--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(src), "-o", str(out), *args]) == 0
    data = _summary(out)
    entry = data["pairs"]["a"]
    killed = {k: entry[k] for k in ("left", "right", "calib", "options", "fingerprint")}
    data["pairs"]["a"] = {"status": "pending", **killed}  # as saved before the pair was written
    (out / SUMMARY_NAME).write_text(json.dumps(data))
    capsys.readouterr()
    assert main(["batch", str(src), "-o", str(out), *args]) == 0, capsys.readouterr().err
    assert _summary(out)["run"]["processed"] == 1
    assert _summary(out)["pairs"]["a"]["outputs"] == sorted(DISPARITY_FILES)


def test_batch_refuses_to_replace_a_summary_json_it_did_not_write(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """-o naming a folder with the user's own summary.json (not a batch summary): it was read
    as unreadable and replaced by the run's. Refused before any work, one line naming it."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png")
    out.mkdir()
    for text in ("my notes", '{"mine": 1}'):
        (out / SUMMARY_NAME).write_text(text)
        capsys.readouterr()
        assert main(["batch", str(src), "-o", str(out), "--workers", "1"]) == 2
        assert capsys.readouterr().err.splitlines() == [
            f"stereovision: error: output folder {out}: {out / SUMMARY_NAME} is not a batch "
            "summary and would be replaced: give another output folder, or move or remove that "
            "file"
        ]
        assert (out / SUMMARY_NAME).read_text() == text
        assert sorted(p.name for p in out.iterdir()) == [SUMMARY_NAME]


def test_batch_redoes_a_changed_pair_of_its_input_after_a_run_over_another_one(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """Two input folders with pairs of other names share one -o; a changed image of the first
    is redone when the first is run again (it was refused as 'made from other images, in
    drive2', the input of the last run, though the pair's images are drive1's own)."""
    one, two, out = tmp_path / "drive1", tmp_path / "drive2", tmp_path / "out"
    _tiny(one, data_dir, "a/left.png", "a/right.png")
    _tiny(two, data_dir, "b/left.png", "b/right.png")
    args = ["--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(one), "-o", str(out), *args]) == 0
    assert main(["batch", str(two), "-o", str(out), *args]) == 0
    _change(one / "a/left.png")
    capsys.readouterr()
    assert main(["batch", str(one), "-o", str(out), *args]) == 0, capsys.readouterr().err
    summary = _summary(out)
    assert summary["run"]["processed"] == 1
    assert summary["pairs"]["a"]["status"] == "done"
    assert summary["pairs"]["b"]["status"] == "done"


def test_a_broken_link_where_a_pair_folder_goes_is_named(tmp_path: Path) -> None:
    """OUT/a (or OUT/seq above OUT/seq/0001) a link to a disk not mounted: the pair failed
    with "Not a directory: '.../.a.partial-1a2b3c4d' -> '.../a'", a hidden folder the user
    never made, and under such a link mkdir's FileExistsError stopped the whole run. The link
    is named now, as a file in the way is (the pair alone fails), and kept."""
    from stereovision import batch

    out = tmp_path / "out"
    out.mkdir()
    for link, name in (("a", "a"), ("seq", "seq/0001")):
        (out / link).symlink_to(tmp_path / "unmounted" / link)
        with pytest.raises(NotADirectoryError) as info:
            batch._commit_pair(out, name, {"disparity.pfm": b"x"})
        assert str(info.value) == (
            f"{out / link} is a link to {tmp_path / 'unmounted' / link}, which does not exist, "
            f"where the pair's output folder {out / name} goes: make its target, or remove "
            "the link"
        )
        assert (out / link).is_symlink()
    assert sorted(p.name for p in out.iterdir()) == ["a", "seq"]  # no partial folder left


def test_a_pair_folder_linked_to_another_disk_is_written(tmp_path: Path) -> None:
    """OUT/a a link to a folder on another disk (outputs spread over disks): each file was
    renamed from OUT/.a.partial-... across the disks, "Invalid cross-device link", which
    stopped the run, every run. The files are staged inside the folder now; a killed run's
    staging folder there is removed by the next run over the pair."""
    from stereovision import batch

    shm = Path("/dev/shm")
    if not (shm.is_dir() and os.access(shm, os.W_OK)):
        pytest.skip("no /dev/shm")
    other = Path(tempfile.mkdtemp(dir=shm))
    try:
        if os.stat(other).st_dev == os.stat(tmp_path).st_dev:
            pytest.skip("/dev/shm is on the disk of tmp_path")
        out = tmp_path / "out"
        out.mkdir()
        (other / "a").mkdir()
        (out / "a").symlink_to(other / "a")
        batch._commit_pair(out, "a", {"disparity.pfm": b"new"})
        assert [p.name for p in (other / "a").iterdir()] == ["disparity.pfm"]
        assert (other / "a" / "disparity.pfm").read_bytes() == b"new"
        assert sorted(p.name for p in out.iterdir()) == ["a"]
        (other / "a" / ".a.partial-1a2b3c4d").mkdir()  # a killed run's
        batch._remove_partials(out, ["a"])
        assert [p.name for p in (other / "a").iterdir()] == ["disparity.pfm"]
    finally:
        shutil.rmtree(other)


def test_batch_a_file_where_a_pair_folder_goes_fails_that_pair_alone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """OUT/a is a user's file: pair a fails naming it, the file is kept, pair b is done (the
    run stopped at '[Errno 20] Not a directory: .../.a.partial-.../disparity.png', b undone;
    before that, the file was moved to a hidden .a.old-... name)."""
    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    out.mkdir()
    (out / "a").write_text("notes")
    assert main(["batch", str(root), "-o", str(out), "--workers", "1"]) == 1
    err = capsys.readouterr().err
    assert (
        f"failed a: NotADirectoryError: {out / 'a'} is a file, where the pair's output folder "
        f"{out / 'a'} goes: move it away"
    ) in err
    assert (out / "a").read_text() == "notes"
    assert (out / "b" / "disparity.pfm").is_file()
    assert sorted(p.name for p in out.iterdir()) == ["a", "b", SUMMARY_NAME]
    pairs = _summary(out)["pairs"]
    assert pairs["a"]["status"] == "failed" and pairs["b"]["status"] == "done"


def test_batch_a_folder_where_an_output_file_goes_fails_that_pair_alone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A rerun where OUT/a/disparity.pfm is a user's folder: the run stopped there ("cannot
    write the outputs of a ...: Is a directory; ... run again to continue", exit 2, as for a
    full disk, though a rerun meets it again and the pairs to come could be written), pair b
    undone, and a's earlier disparity.png already replaced by the new one. As a file where a
    pair's folder goes, pair a fails naming the folder, its files as they were; b is done."""
    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    (out / "a" / "disparity.pfm").unlink()
    (out / "a" / "disparity.pfm").mkdir()
    (out / "a" / "disparity.pfm" / "notes.txt").write_text("mine")
    before = (out / "a" / "disparity.png").read_bytes()
    _change(root / "a/left.png")
    _change(root / "b/left.png")
    b_before = (out / "b" / "disparity.png").read_bytes()
    capsys.readouterr()
    assert main(args) == 1
    err = capsys.readouterr().err
    assert (
        f"failed a: IsADirectoryError: {out / 'a' / 'disparity.pfm'} is a folder, where the "
        f"pair's disparity.pfm goes: move it away (the pair's earlier outputs are kept)"
    ) in err
    assert (out / "a" / "disparity.pfm" / "notes.txt").read_text() == "mine"
    assert (out / "a" / "disparity.png").read_bytes() == before
    assert (out / "b" / "disparity.png").read_bytes() != b_before
    pairs = _summary(out)["pairs"]
    assert pairs["a"]["status"] == "failed" and pairs["b"]["status"] == "done"


def test_batch_reads_16_bit_files_as_depth_does(
    data_dir: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A 12-bit camera's pair in 16-bit PNGs: batch's disparity is the one `stereovision depth`
    writes for it (batch decoded the top 8 bits of each pixel, 0-15 of 0-4095, while depth
    keeps the 16 bits since it reads with io.read_image). Depth's warning of the 12-bit data is
    the pair's, one line naming it and in the summary: the worker printed it as Python does
    ('.../dask/_task_spec.py:768: UserWarning: left: uint16 image ...', its advice in Python's
    words, no pair named) and a remote worker into its own log."""
    src = data_dir / "middlebury2001/tsukuba"
    scene = tmp_path / "in/a"
    scene.mkdir(parents=True)
    for side in ("left", "right"):
        crop = cv2.imread(str(src / f"{side}.png"))[100:164, 150:246]
        cv2.imwrite(str(scene / f"{side}.png"), crop.astype(np.uint16) * 16)
    args = ["--max-disparity", "16"]
    argv = [
        "depth",
        str(scene / "left.png"),
        str(scene / "right.png"),
        "-o",
        str(tmp_path / "depth"),
    ]
    assert main([*argv, *args]) == 0
    depth_err = capfd.readouterr().err
    assert main(["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out"), "--workers", "1",
                 *args]) == 0  # fmt: skip
    want = read_pfm(tmp_path / "depth/disparity.pfm")
    got = read_pfm(tmp_path / "out/a/disparity.pfm")
    np.testing.assert_array_equal(got, want)
    err = capfd.readouterr().err
    said = _summary(tmp_path / "out")["pairs"]["a"]["warnings"]
    # depth's own warnings, in the CLI's words (12-bit data shifted left, not img << 4)
    assert [f"stereovision: warning: {w}" for w in said] == depth_err.splitlines()[:2]
    assert [w.split(" is ")[0] for w in said] == [
        "left: uint16 image whose largest value",
        "right: uint16 image whose largest value",
    ]
    warned = [x for x in err.splitlines() if "warning" in x.lower()]
    assert warned == [f"a: warning: {w}" for w in said]
    assert "UserWarning" not in err and "_task_spec" not in err
    # the worker's function gives them back, none left to its process
    from stereovision.batch import _task, process_pair

    (job,) = find_pairs(tmp_path / "in")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = process_pair(_task(job, {"method": None, "max_disparity": 16, "fill": None}))
    # the API's words there: run_batch's summary says them in its callers' (words=)
    assert [w.split(" (")[0] for w in out["warnings"]] == [w.split(" (")[0] for w in said]
    assert "img << 4" in out["warnings"][0]


def _crops(root: Path, data_dir: Path, left: list[str], right: list[str]) -> None:
    """The 96 x 64 Tsukuba crops of :func:`_tiny`: the left image's at each of ``left``, the
    right image's at each of ``right`` (whatever their names)."""
    src = data_dir / "middlebury2001/tsukuba"
    for side, names in (("left", left), ("right", right)):
        crop = cv2.imread(str(src / f"{side}.png"))[100:164, 150:246]
        for name in names:
            (root / name).parent.mkdir(parents=True, exist_ok=True)
            cv2.imwrite(str(root / name), crop)


@pytest.mark.parametrize(
    ("left", "right", "names"),
    [
        (["seq/left/0001.png", "seq/left/0002.png"], ["seq/right/0001.png", "seq/right/0002.png"],
         ["seq/0001", "seq/0002"]),
        (["L/a.jpg"], ["R/a.jpg"], ["a"]),
        (["training/image_2/000000_10.png", "training/image_2/000000_11.png"],
         ["training/image_3/000000_10.png", "training/image_3/000000_11.png"],
         ["training/000000_10", "training/000000_11"]),
        (["mav0/cam0/data/1403636579763555584.png"], ["mav0/cam1/data/1403636579763555584.png"],
         ["mav0/data/1403636579763555584"]),
    ],
    ids=["left-right", "L-R", "kitti", "euroc"],
)  # fmt: skip
def test_batch_pairs_images_of_the_same_name_in_sibling_camera_folders(
    data_dir: Path,
    tmp_path: Path,
    left: list[str],
    right: list[str],
    names: list[str],
    in_process_dask: None,
) -> None:
    """left/0001.png + right/0001.png (L/ R/, KITTI's image_2/ image_3/, EuRoC's cam0/data/
    cam1/data/) are pairs, named by the parent and the path under the camera folder, whose
    outputs are those of the same images named x_left.png / x_right.png (they were no pairs:
    "no pair under ..."). The other files of the folders are not images of a pair."""
    root, out = tmp_path / "in", tmp_path / "out"
    ext = Path(left[0]).suffix  # the reference pair's images are encoded alike (JPEG)
    _crops(root, data_dir, [*left, f"ref_left{ext}"], [*right, f"ref_right{ext}"])
    (root / left[0]).with_name("sensor.yaml").write_text("rate_hz: 20\n")
    jobs = find_pairs(root)
    assert [j.name for j in jobs] == sorted([*names, "ref"])
    by_name = {j.name: j for j in jobs}
    for name, lp, rp in zip(names, left, right, strict=True):
        assert (by_name[name].left, by_name[name].right) == (root / lp, root / rp)
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    s = _summary(out)
    assert sorted(s["pairs"]) == sorted([*names, "ref"])
    assert s["counts"] == {"done": len(names) + 1, "failed": 0, "pending": 0}
    ref = read_pfm(out / "ref/disparity.pfm")
    assert np.isfinite(ref).mean() > 0.5
    for name in names:
        assert {p.name for p in (out / name).iterdir()} == DISPARITY_FILES
        np.testing.assert_array_equal(read_pfm(out / name / "disparity.pfm"), ref)
    assert main(args) == 0  # a re-run skips them all
    assert _summary(out)["run"]["skipped"] == len(names) + 1


def test_camera_folders_half_pairs_clashes_and_the_other_layouts(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """An image in one camera folder without the other is a failed pair saying which file is
    missing; several rigs in one folder keep their left camera's folder in the names; a clash
    with a pair of another layout leaves that one its name; files named ...left... in camera
    folders are paired by name as before."""
    root, out = tmp_path / "in", tmp_path / "out"
    old = ["s/0001_left.png", "s/0001_right.png", "s/left/x_left.png", "s/left/x_right.png",
           "s/0001/left.png", "s/0001/right.png"]  # fmt: skip
    _tiny(root, data_dir, *old)
    before = [(j.name, j.left, j.right) for j in find_pairs(root)]
    assert [n for n, *_ in before] == ["s/0001", "s/0001~2", "s/left/x"]
    lefts = ["s/left/0001.png", "s/left/0002.png", "k/image_0/7.png", "k/image_2/7.png"]
    rights = ["s/right/0001.png", "s/right/0003.png", "k/image_1/7.png", "k/image_3/7.png"]
    _crops(root, data_dir, lefts, rights)
    jobs = find_pairs(root)
    assert [(j.name, j.left, j.right) for j in jobs if j.left.name != "0001.png"] == [
        ("k/image_0/7", root / "k/image_0/7.png", root / "k/image_1/7.png"),
        ("k/image_2/7", root / "k/image_2/7.png", root / "k/image_3/7.png"),
        *before,
    ]
    assert jobs[4] == PairJob("s/0001~3", root / "s/left/0001.png", root / "s/right/0001.png")
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 1
    said = capsys.readouterr()
    assert said.out.startswith("6 processed, 0 skipped (done before), 2 failed (2 with an image ")
    s = _summary(out)
    for name, there, gone in (("s/0002", "left", "right"), ("s/0003", "right", "left")):
        n = name[-4:]
        error = f"unpaired image: no {root / f's/{gone}/{n}.png'} for {root / f's/{there}/{n}.png'}"
        assert s["pairs"][name]["error"] == error and f"failed {name}: {error}" in said.err
        assert s["pairs"][name]["left"] == str(root / f"s/left/{n}.png")
    assert {p.name for p in (out / "k/image_2/7").iterdir()} == DISPARITY_FILES


def test_a_kitti_raw_drive_is_two_rigs_of_camera_folders(tmp_path: Path) -> None:
    """A KITTI raw drive (image_00/ ... image_03/, each with data/ and timestamps.txt, its
    calib_cam_to_cam.txt read by --calib) was 'no pair under ...': its camera folders are
    image_02/ + image_03/ (colour) and image_00/ + image_01/ (grey), not the odometry's image_2/
    + image_3/. Each rig's pairs keep its left camera's folder, as in an odometry sequence."""
    drive = tmp_path / "2011_09_26" / "2011_09_26_drive_0001_sync"
    frames = ("0000000000", "0000000001")
    _blank(drive, *(f"image_0{c}/data/{f}.png" for c in range(4) for f in frames))
    for c in range(4):
        (drive / f"image_0{c}/timestamps.txt").write_text("2011-09-26 13:02:25.964389445\n")
    jobs = find_pairs(tmp_path / "2011_09_26")
    rel = "2011_09_26_drive_0001_sync"
    assert [(j.name, j.left, j.right) for j in jobs] == [
        (f"{rel}/{left}/data/{f}", drive / f"{left}/data/{f}.png", drive / f"{right}/data/{f}.png")
        for left, right in (("image_00", "image_01"), ("image_02", "image_03"))
        for f in frames
    ]


def test_a_tartanair_trajectory_is_camera_folders_paired_by_number(
    data_dir: Path, tmp_path: Path
) -> None:
    """TartanAir's own layout (P000/image_left/000000_left.png + image_right/000000_right.png)
    was no pair: every image 'unpaired' (no 000000_right.png beside 000000_left.png). The two
    folders are camera folders, their images paired by number; --calib (its fixed calibration,
    a calib.txt as the shared scene's) calibrates them, as any camera folders' pairs."""
    from stereovision.batch import _scan

    traj = tmp_path / "oldtown" / "Easy" / "P000"
    frames = ("000000", "000001")
    _blank(traj, *(f"image_{s}/{f}_{s}.png" for s in ("left", "right") for f in frames))
    (traj / "pose_left.txt").write_text("0 0 0 0 0 0 1\n")
    jobs, unpaired, _ = _scan(tmp_path / "oldtown")
    assert unpaired == []
    assert [(j.name, j.left, j.right, j.calib) for j in jobs] == [
        (f"Easy/P000/{f}", traj / f"image_left/{f}_left.png", traj / f"image_right/{f}_right.png",
         None)
        for f in frames
    ]  # fmt: skip
    cal = data_dir / "tartanair/oldtown_easy_p000_001116/calib.txt"
    assert {j.calib for j in find_pairs(tmp_path / "oldtown", calib=cal)} == {cal}


def test_a_named_frame_of_a_camera_folder_without_its_other_names_the_other_folder(
    tmp_path: Path,
) -> None:
    """A TartanAir frame whose right image was dropped (image_left/000002_left.png alone) was
    reported by its folder's own walk: 'P000/image_left/000002: unpaired image: no
    000002_right.png beside .../image_left/000002_left.png', sending the user to the wrong
    folder (seq/left/left_0002.png alike). It is the half pair P000/000002, the missing file in
    the other camera's folder; an unnamed frame (k/left/0002.png) as before."""
    from stereovision.batch import _scan

    traj = tmp_path / "P000"
    _blank(
        traj,
        *(f"image_{s}/000000_{s}.png" for s in ("left", "right")),
        "image_left/000002_left.png",
        "image_right/000003_right.png",
    )
    jobs, unpaired, _ = _scan(tmp_path)
    assert [j.name for j in jobs] == ["P000/000000"]
    left, right = traj / "image_left", traj / "image_right"
    assert sorted((u.name, u.what) for u in unpaired) == [
        ("P000/000002", f"no {right}/000002_right.png for {left}/000002_left.png"),
        ("P000/000003", f"no {left}/000003_left.png for {right}/000003_right.png"),
    ]


def test_an_output_folder_inside_the_input_is_not_searched_for_pairs(
    data_dir: Path, tmp_path: Path
) -> None:
    """``batch seq -o seq/left/out``: the run's own outputs (out/0001/disparity.png, in the
    left camera folder) were searched as input on the next run, each a failed pair ("unpaired
    image: no seq/right/out/0001/disparity.png"), exit 1. The output folder is not searched
    (run_batch's scan); a folder beside it still is, and one named as an image is no image."""
    from stereovision.batch import _scan

    root = tmp_path / "seq"
    out = root / "left" / "out"
    _crops(root, data_dir, ["left/0001.png", "left/old/0002.png"], ["right/0001.png"])
    _crops(root, data_dir, [], ["left/out/0001/disparity.png", "left/out/0001/overview.png"])
    (root / "left" / "pair.png").mkdir()
    jobs, unpaired, _ = _scan(root, output=out)
    assert jobs == [PairJob("0001", root / "left/0001.png", root / "right/0001.png")]
    assert [(u.name, u.present) for u in unpaired] == [("old/0002", root / "left/old/0002.png")]
    # another output folder, or none: the folder is input as any other
    for other in (tmp_path / "o", None):
        found = {u.name for u in _scan(root, output=other)[1]}
        assert found == {"old/0002", "out/0001/disparity", "out/0001/overview"}


def test_a_left_camera_folder_without_its_right_one_is_reported(tmp_path: Path) -> None:
    """seq/left/ without seq/right/ at all (a copy cut short) was passed over without a word,
    where a right/ short of some images has each reported; its images are half pairs now.
    A lone cam0/ or image_2/ (a mono recording, KITTI's object benchmark) still is no pair."""
    from stereovision.batch import _scan

    root = tmp_path / "in"
    img = np.zeros((4, 6), np.uint8)
    for f in (
        "a/left.png",
        "a/right.png",
        "seq/left/0001.png",
        "seq/left/0002.png",
        "mono/cam0/0001.png",
        "kitti/image_2/000000_10.png",
        "tartan/image_Right/9.png",
    ):
        (root / f).parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(root / f), img)  # fmt: skip
    jobs, unpaired, _ = _scan(root)
    assert [j.name for j in jobs] == ["a"]
    assert [(u.name, u.error) for u in unpaired] == [
        ("seq/0001", f"unpaired image: no {root}/seq/right/0001.png for {root}/seq/left/0001.png"),
        ("seq/0002", f"unpaired image: no {root}/seq/right/0002.png for {root}/seq/left/0002.png"),
        ("tartan/9", f"unpaired image: no {root}/tartan/image_Left/9.png for "
                     f"{root}/tartan/image_Right/9.png"),
    ]  # fmt: skip


def test_an_image_of_a_lone_left_camera_folder_is_reported_once(tmp_path: Path) -> None:
    """seq/left/im0.png, its folder without seq/right/ (8d17cab1), was two failed pairs for one
    file: 'seq/left' (no im1.png beside it) and 'seq/im0' (no seq/right/im0.png for it). Once
    now, as the camera folder's half pair, as in a rig whose right/ holds no im0.png."""
    from stereovision.batch import _scan

    root = tmp_path / "in"
    for f in ("seq/left/im0.png", "seq/left/0001.png"):
        (root / f).parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(root / f), np.zeros((4, 6), np.uint8))
    assert [(u.name, u.error) for u in _scan(root)[1]] == [
        ("seq/0001", f"unpaired image: no {root}/seq/right/0001.png for {root}/seq/left/0001.png"),
        ("seq/im0", f"unpaired image: no {root}/seq/right/im0.png for {root}/seq/left/im0.png"),
    ]


def test_a_folder_that_cannot_be_listed_is_warned_of(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, unlistable: Callable[[Any], None]
) -> None:
    """A sub-folder of the input that cannot be listed (no permission: a copy from another
    user, mode 700) was passed over by os.walk without a word, its pairs left out of a run
    that said '1 processed' and exit 0. It is warned of, naming it; the others pair as before."""
    from stereovision.batch import _scan

    root = tmp_path / "in"
    img = np.zeros((4, 6), np.uint8)
    for scene in ("a", "locked"):
        (root / scene).mkdir(parents=True)
        for side in ("left", "right"):
            cv2.imwrite(str(root / scene / f"{side}.png"), img)
    unlistable(str(root / "locked"))
    with pytest.warns(UserWarning) as said:
        jobs, unpaired, _ = _scan(root)
    assert [j.name for j in jobs] == ["a"] and unpaired == []
    assert [str(w.message) for w in said] == [
        f"cannot search folder {root / 'locked'}: Permission denied; the pairs in it, if any, "
        "are left out"
    ]


def test_a_folder_that_cannot_be_listed_is_warned_of_once_at_the_callers_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, unlistable: Callable[[Any], None]
) -> None:
    """seq/right/sub/ that cannot be listed, under a camera folder the search walks three
    times (its images, its named images, the input's walk), was warned of three times, each
    at ``<frozen os>`` (os.walk's onerror gave it): once now, at the line calling find_pairs."""
    root = tmp_path / "in"
    _blank(root, "seq/left/0001.png", "seq/right/0001.png", "seq/right/sub/0002.png")
    locked = str(root / "seq/right/sub")
    unlistable(locked)
    with pytest.warns(UserWarning) as said:
        line = sys._getframe().f_lineno + 1
        jobs = find_pairs(root)
    assert [j.name for j in jobs] == ["seq/0001"]
    assert [(str(w.message), w.filename, w.lineno) for w in said] == [
        (
            f"cannot search folder {locked}: Permission denied; the pairs in it, if any, are "
            "left out",
            __file__,
            line,
        )
    ]


def test_an_input_folder_that_cannot_be_listed_is_an_error(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    unlistable: Callable[[Any], None],
) -> None:
    """The input folder itself that cannot be listed (no permission) was os.walk's warning
    'cannot search folder in: ...; the pairs in it, if any, are left out' and then 'no pair
    under in (scene folders with left.png + right.png ...)', as if it held none of the
    layouts: an error now, naming it, and the CLI's one line."""
    from stereovision import cli
    from stereovision.batch import _scan

    root = tmp_path / "in"
    (root / "a").mkdir(parents=True)
    unlistable(str(root))
    said = f"cannot search input folder {root}: Permission denied"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the error alone, no warning before it
        with pytest.raises(PermissionError) as err:
            _scan(root)
    assert str(err.value) == said
    assert cli.main(["batch", str(root), "-o", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err == f"stereovision: error: {said}\n"
    assert not (tmp_path / "out").exists()


def test_images_of_a_camera_folder_whose_sibling_cannot_be_listed_are_no_half_pairs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, unlistable: Callable[[Any], None]
) -> None:
    """seq/right/sub/ that cannot be listed (no permission) is warned of as left out, but
    seq/left/sub/0002.png was also a failed pair, 'unpaired image: no seq/right/sub/0002.png
    for ...', a file that may well be there. Its pair is left out as the warning says; a
    right/ short of an image it can list is reported as before."""
    from stereovision.batch import _scan

    root = tmp_path / "in"
    img = np.zeros((4, 6), np.uint8)
    for f in ("0001.png", "0003.png", "sub/0002.png"):
        for side in ("left", "right"):
            if not (side == "right" and f == "0003.png"):
                (root / "seq" / side / f).parent.mkdir(parents=True, exist_ok=True)
                cv2.imwrite(str(root / "seq" / side / f), img)
    locked = str(root / "seq/right/sub")
    unlistable(locked)
    with pytest.warns(UserWarning, match="cannot search folder .*right/sub: Permission denied"):
        jobs, unpaired, _ = _scan(root)
    assert [j.name for j in jobs] == ["seq/0001"]
    assert [(u.name, u.error) for u in unpaired] == [
        ("seq/0003", f"unpaired image: no {root}/seq/right/0003.png for {root}/seq/left/0003.png")
    ]


def test_images_under_an_execute_only_sibling_camera_folder_are_no_half_pairs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, unlistable: Callable[[Any], None]
) -> None:
    """seq/right/ that cannot be listed but can be entered (execute-only, d--x--x--x): the walk
    never reached seq/right/sub/, which can be listed, so d2c43757's check of the missing
    file's own folder still reported seq/left/sub/0002.png as 'no seq/right/sub/0002.png', a
    file that is there. Left out as the warning says, as the images of right/ itself are."""
    from stereovision.batch import _scan

    root = tmp_path / "in"
    for f in ("0001.png", "sub/0002.png"):
        for side in ("left", "right"):
            (root / "seq" / side / f).parent.mkdir(parents=True, exist_ok=True)
            cv2.imwrite(str(root / "seq" / side / f), np.zeros((4, 6), np.uint8))
    locked = str(root / "seq/right")
    unlistable(locked)
    with pytest.warns(UserWarning, match="cannot search folder .*seq/right: Permission denied"):
        jobs, unpaired, _ = _scan(root)
    assert (jobs, [(u.name, u.error) for u in unpaired]) == ([], [])


def test_outputs_written_into_the_input_are_not_reported_as_half_pairs(tmp_path: Path) -> None:
    """``batch 00 -o 00`` (-o given as the input) over a KITTI sequence of two rigs: each
    pair's folder lies in its left camera folder (00/image_0/000000/), and the next run
    reported its disparity.png and overview.png as images without their pair ("no
    00/image_1/000000/disparity.png for ..."), exit 1 every run. They are the run's own; an
    image there under another name, and the same files with another -o, are reported."""
    from stereovision.batch import _scan

    root = tmp_path / "00"
    img = np.zeros((4, 6), np.uint8)
    for cam in range(4):
        (root / f"image_{cam}").mkdir(parents=True)
        cv2.imwrite(str(root / f"image_{cam}/000000.png"), img)
    for cam in (0, 2):
        (root / f"image_{cam}/000000").mkdir()
        for f in ("disparity.png", "overview.png", "mine.png"):
            cv2.imwrite(str(root / f"image_{cam}/000000/{f}"), img)
    jobs, unpaired, _ = _scan(root, output=root)
    assert [j.name for j in jobs] == ["image_0/000000", "image_2/000000"]
    assert [u.name for u in unpaired] == ["image_0/000000/mine", "image_2/000000/mine"]
    # the same files with the outputs elsewhere: images of the input, reported as before
    found = sorted(u.name for u in _scan(root, output=tmp_path / "o")[1])
    assert found == [f"image_{c}/000000/{f}" for c in (0, 2) for f in ("disparity", "mine",
                                                                        "overview")]  # fmt: skip


def test_outputs_of_a_pair_whose_image_was_deleted_are_not_reported_as_half_pairs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``batch 00 -o 00`` after 00/image_0/000001.png was deleted: the pair's outputs from the
    run that did it (00/image_0/000001/disparity.png, overview.png) were reported again as
    images without their pair, two failed pairs of this run. The summary lists them as that
    pair's outputs: not reported; the half pair and an image there it does not list are."""
    import stereovision.batch as batch

    root = tmp_path / "00"
    names = ["image_1/000001.png", "image_0/000001/disparity.png", "image_0/000001/overview.png"]
    names += ["image_0/000001/mine.png"]
    _blank(root, *[f"image_{cam}/000000.png" for cam in range(4)], *names)
    pair = {"status": "done", "outputs": ["disparity.png", "disparity.pfm", "overview.png"]}
    summary = {"version": 3, "pairs": {"image_0/000001": pair}}
    (root / SUMMARY_NAME).write_text(json.dumps(summary))
    monkeypatch.setattr(batch, "_run_jobs", lambda *args: None)  # only the search is looked at
    res = batch.run_batch(root, root, progress=False)
    assert res.unpaired == ["image_0/000001", "image_0/000001/mine"]
    assert res.pending == ["image_0/000000", "image_2/000000"]


def test_a_redo_stopped_before_a_pair_is_written_keeps_its_earlier_outputs_listed(
    data_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, in_process_dask: None
) -> None:
    """A pair done with --ground, redone without it by a run stopped before the pair was
    written: the summary still lists the earlier run's outputs (it listed none), so the next
    run removes the ground.json it does not write (it stayed, from the run with --ground)."""
    import stereovision.batch as batch

    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, "a/left.png", "a/right.png")
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    # as a run with --ground left it: its ground.json written and recorded
    (out / "a/ground.json").write_text("{}")
    s = _summary(out)
    entry = s["pairs"]["a"]
    entry["outputs"] = sorted([*entry["outputs"], "ground.json"])
    entry["options"] = {**entry["options"], "ground": True, "grid": None}
    (out / SUMMARY_NAME).write_text(json.dumps(s))

    def stopped(*_args: Any, **_kwargs: Any) -> None:
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(batch, "_run_jobs", stopped)
        with pytest.raises(batch.BatchInterrupted):
            batch.run_batch(root, out, workers=1, max_disparity=16)
    pending = _summary(out)["pairs"]["a"]
    assert pending["status"] == "pending"
    assert pending["outputs"] == sorted([*DISPARITY_FILES, "ground.json"])
    assert main(args) == 0
    assert {p.name for p in (out / "a").iterdir()} == DISPARITY_FILES
    assert _summary(out)["pairs"]["a"]["outputs"] == sorted(DISPARITY_FILES)


def test_a_second_batch_into_an_output_folder_in_use_is_refused(
    data_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    in_process_dask: None,
) -> None:
    """A run started while another one writes into the same -o stops before any work, one
    line; each run replaced the whole summary with its own, so the one that finished last
    dropped the other's records without a word."""
    import stereovision.batch as batch

    one, two, out = tmp_path / "drive1", tmp_path / "drive2", tmp_path / "out"
    _tiny(one, data_dir, "a/left.png", "a/right.png")
    _tiny(two, data_dir, "b/left.png", "b/right.png")
    said: dict[str, Any] = {}

    def meanwhile(*_args: Any, **_kwargs: Any) -> None:
        if said:  # the second run, on the code that let it in
            return
        said["rc"] = main(["batch", str(two), "-o", str(out), "--max-disparity", "16"])
        said["err"] = capsys.readouterr().err.splitlines()

    monkeypatch.setattr(batch, "_run_jobs", meanwhile)
    batch.run_batch(one, out, workers=1, max_disparity=16)
    assert said["rc"] == 2
    assert said["err"] == [
        f"stereovision: error: output folder {out} is in use by another stereovision batch "
        "run; wait for it to end, or give another output folder"
    ]
    assert set(_summary(out)["pairs"]) == {"a"}
    monkeypatch.undo()  # the folder is free again once the run is over
    assert main(["batch", str(two), "-o", str(out), "--workers", "1", "--max-disparity", "16"]) == 0
    assert set(_summary(out)["pairs"]) == {"a", "b"}


def test_camera_folders_pair_names_with_left_and_right_by_their_number(
    data_dir: Path, tmp_path: Path
) -> None:
    """left/left_0001.png + right/right_0001.png is a pair (named by the folder and the frame
    number, as seq/left_0001.png + seq/right_0001.png are); each image was reported as
    unpaired, for want of a right_0001.png beside left_0001.png. Pairs named so in one folder
    stay as they were, a number twice on one side is not guessed, a number alone stays alone,
    and names that differ otherwise (KITTI's 000000_11 and 000001_11) are not paired."""
    import stereovision.batch as batch

    root = tmp_path / "in"
    _tiny(
        root,
        data_dir,
        *("s/left/left_0001.png", "s/right/right_0001.png"),
        *("s/left/left_0002.png", "s/left/left_0003.png", "s/right/right_0003.png"),
        *("s/left/x_left.png", "s/left/x_right.png"),
        *("d/left/a_left_5.png", "d/left/b_left_5.png", "d/right/right_5.png"),
        *(
            "k/image_2/000000_11.png",
            "k/image_3/000001_11.png",
            "k/L/Left-7.png",
            "k/R/right_07.png",
        ),
    )
    jobs, unpaired, _ = batch._scan(root)
    assert [(j.name, j.left, j.right) for j in jobs] == [
        ("k/L/7", root / "k/L/Left-7.png", root / "k/R/right_07.png"),
        ("s/0001", root / "s/left/left_0001.png", root / "s/right/right_0001.png"),
        ("s/0003", root / "s/left/left_0003.png", root / "s/right/right_0003.png"),
        ("s/left/x", root / "s/left/x_left.png", root / "s/left/x_right.png"),
    ]
    assert sorted(u.present.relative_to(root).as_posix() for u in unpaired) == [
        "d/left/a_left_5.png",
        "d/left/b_left_5.png",
        "d/right/right_5.png",
        "k/image_2/000000_11.png",
        "k/image_3/000001_11.png",
        "s/left/left_0002.png",
    ]


def test_a_scene_with_only_q_dat_is_calibrated_as_load_scene_calibrates_it(
    data_dir: Path, tmp_path: Path
) -> None:
    """load_scene reads a scene's Q.dat when it has no calib.txt (middeval3/teddyH), but batch
    (and the GUI's image-folder source, which pairs as batch does) took the scene as
    uncalibrated: no depth, no cloud. Its Q.dat is now the pair's calibration; calib.txt still
    wins when both are there (TartanAir)."""
    from stereovision.io import load_scene

    teddy = data_dir / "middeval3" / "teddyH"
    scene = tmp_path / "teddyH"
    scene.mkdir()
    for name in ("left.png", "right.png", "Q.dat"):
        shutil.copy(teddy / name, scene / name)
    tartan = data_dir / "tartanair" / "oldtown_easy_p000_001116"
    (job,) = find_pairs(scene)
    assert job.calib == scene / "Q.dat"
    calib = Calibration.from_file(job.calib)
    expected = load_scene(teddy).calib
    assert expected is not None and calib.image_size == (900, 750)
    np.testing.assert_allclose(calib.Q, expected.Q, rtol=1e-12)
    assert calib.baseline_m == pytest.approx(0.08) and calib.unit == "m"
    (job,) = find_pairs(tartan)
    assert job.calib == tartan / "calib.txt"


def test_a_scene_with_only_q_dat_is_batched_with_depth(
    data_dir: Path, tmp_path: Path, in_process_dask: None
) -> None:
    """The worker got the scene's Q.dat alone, in a temporary folder without the left.png
    that sizes it: every such pair failed ('Q.dat does not give the image size and there is
    no left.png beside it'). It is shipped as the calibration read beside its images."""
    from stereovision.batch import _task, process_pair
    from stereovision.io import load_scene

    teddy = data_dir / "middeval3" / "teddyH"
    scene = tmp_path / "teddyH"
    scene.mkdir()
    for name in ("left.png", "right.png", "Q.dat"):
        shutil.copy(teddy / name, scene / name)
    (job,) = find_pairs(scene)
    task = _task(job, {"method": "fast", "max_disparity": 64, "fill": None})
    out = process_pair(task)
    assert task["calib"][0] == "calib.json"
    ref = load_scene(teddy)
    expected = depth_map(ref.left, ref.right, ref.calib, method="fast", max_disparity=64)
    assert expected.depth is not None
    depth = np.load(io.BytesIO(out["files"]["depth.npy"]))
    np.testing.assert_array_equal(depth, expected.depth)


def test_a_scene_with_a_bad_q_dat_fails_that_pair_alone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A scene's Q.dat is read before its pair is sent (8ab621e): one that is not a Q matrix
    stopped the whole run ('error: .../b/Q.dat: not a rectified Q matrix', exit 2, pair a left
    pending). It fails pair b alone, naming the file; a is done."""
    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    (root / "b" / "Q.dat").write_text("0 0 0 -5\n0 1 0 -4\n0 0 0 100\n0 0 4 0\n")
    assert main(["batch", str(root), "-o", str(out), "--workers", "1"]) == 1
    err = capsys.readouterr().err
    q = root / "b" / "Q.dat"
    assert f"failed b: ValueError: {q}: not a rectified Q matrix: Q[0,0] = 0, expected 1" in err
    pairs = _summary(out)["pairs"]
    assert pairs["a"]["status"] == "done" and pairs["b"]["status"] == "failed"
    assert (out / "a" / "disparity.pfm").is_file() and not (out / "b").exists()


def test_an_older_batch_summary_does_not_make_a_users_overview_png_ours(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A version 1 summary's entry without an outputs list takes the standard output names
    in its folder as its own, but no version 1 batch wrote overview.png (4715e5e came after
    version 2): the user's overview.png there was taken for ours and replaced by the rerun
    without a word. It is refused as not listed, the file untouched."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png")
    (out / "a").mkdir(parents=True)
    (out / "a" / "disparity.png").write_text("old")  # the older batch's
    (out / "a" / "overview.png").write_text("mine")  # the user's: a name it never wrote
    summary = {
        "version": 1,
        "pairs": {
            "a": {
                "status": "failed",
                "finished": "2026-11-30T10:00:00+00:00",
                "this_run": "failed",
                "left": str(src / "a/left.png"),
                "right": str(src / "a/right.png"),
                "calib": None,
                "error": "ValueError: cannot decode .../a/right.png as an image",
            }
        },
        "input": str(src.resolve()),
        "output": str(out.resolve()),
    }
    (out / SUMMARY_NAME).write_text(json.dumps(summary, indent=1))
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    capsys.readouterr()
    assert main(args) == 2
    assert capsys.readouterr().err.splitlines() == [_not_ours(out, "a", "overview.png")]
    assert (out / "a" / "overview.png").read_text() == "mine"
    assert json.loads((out / SUMMARY_NAME).read_text()) == summary  # untouched


def test_batch_redoes_pairs_an_older_batch_left_without_an_outputs_list(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A summary.json of a batch before ed0f5f2 (version 1): a pair done, then redone on a
    damaged image, was recorded failed without its outputs list, and a pair whose right image
    went missing was too, their folders still holding the done run's files. Rerun with the
    images mended, the pairs' own disparity.png was refused as not listed, exit 2: a user
    upgrading could not go on in their output folder. The standard output names in such an
    entry's folder count as listed now; a user's file in a folder no entry records is still
    refused."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    for name in ("a", "b"):  # the done run's files, as an older batch wrote them
        (out / name).mkdir(parents=True)
        for f in DISPARITY_FILES - {"overview.png"}:  # no version 1 batch wrote overview.png
            (out / name / f).write_text("old")
    old = {"status": "failed", "finished": "2026-11-30T10:00:00+00:00", "this_run": "failed"}
    summary = {  # as batch wrote it before ed0f5f2
        "version": 1,
        "pairs": {
            "a": {
                **old,
                "left": str(src / "a/left.png"),
                "right": str(src / "a/right.png"),
                "calib": None,
                "options": {"method": None, "max_disparity": 16, "fill": None},
                "fingerprint": {"left": [10, 1], "right": [10, 1]},
                "error": "ValueError: cannot decode .../a/right.png as an image",
            },
            "b": {
                **old,
                "left": str(src / "b/left.png"),
                "right": str(src / "b/right.png"),
                "calib": None,
                "error": f"unpaired image: no right.png beside {src / 'b/left.png'}",
            },
        },
        "input": str(src.resolve()),
        "output": str(out.resolve()),
        "run": {"started": "2026-11-30T10:00:00+00:00", "pairs": 2, "processed": 0,
                "skipped": 0, "skipped_failed": 0, "failed": 2, "interrupted": False},
        "counts": {"done": 0, "failed": 2, "pending": 0},
    }  # fmt: skip
    (out / SUMMARY_NAME).write_text(json.dumps(summary, indent=1))
    _tiny(src, data_dir, "c/left.png", "c/right.png")
    (out / "c").mkdir()
    (out / "c" / "disparity.png").write_text("mine")  # the user's, in a folder no run wrote
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    capsys.readouterr()
    assert main(args) == 2
    assert capsys.readouterr().err.splitlines() == [_not_ours(out, "c", "disparity.png")]
    assert json.loads((out / SUMMARY_NAME).read_text()) == summary  # untouched
    (out / "c" / "disparity.png").unlink()
    assert main(args) == 0, capsys.readouterr().err
    s = _summary(out)
    assert s["run"]["processed"] == 3 and s["counts"] == {"done": 3, "failed": 0, "pending": 0}
    for name in ("a", "b", "c"):
        assert s["pairs"][name]["outputs"] == sorted(DISPARITY_FILES)
        assert {p.name for p in (out / name).iterdir()} == DISPARITY_FILES
        assert read_pfm(out / name / "disparity.pfm").shape == (64, 96)
    assert main(args) == 0
    assert _summary(out)["run"]["skipped"] == 3


def test_a_pair_gone_from_the_input_is_not_recorded_as_processed_this_run(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A pair removed from the input (or of another input folder run into the same -o) kept
    its record's "this_run": "processed" from the run that did it, so a script reading the
    summary took it for one of this run's pairs. It says "not in input" now; its record and
    outputs are kept."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    shutil.rmtree(src / "b")
    capsys.readouterr()
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("0 processed, 1 skipped (done before), 0 failed")
    s = _summary(out)
    assert s["run"]["pairs"] == 1
    assert s["pairs"]["a"]["this_run"] == "skipped"
    b = s["pairs"]["b"]
    assert b["this_run"] == "not in input" and b["status"] == "done"
    assert b["outputs"] == sorted(DISPARITY_FILES)
    assert {p.name for p in (out / "b").iterdir()} == DISPARITY_FILES
    _tiny(src, data_dir, "b/left.png", "b/right.png")  # back, new times, the same bytes
    assert main(args) == 0
    assert _summary(out)["pairs"]["b"]["this_run"] == "skipped"
    _change(src / "b/left.png")  # another image: redone
    assert main(args) == 0
    assert _summary(out)["pairs"]["b"]["this_run"] == "processed"
    # gone from the input and its outputs deleted: not this run's pair, not said as missing
    shutil.rmtree(src / "b")
    shutil.rmtree(out / "b")
    assert main(args) == 0
    s = _summary(out)
    assert s["run"]["missing"] == 0 and s["pairs"]["b"]["status"] == "done"


def test_a_pair_whose_outputs_were_deleted_between_runs_is_redone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A pair recorded as done whose folder the user deleted since: the next run redoes it (it
    is not skipped as done), and its outputs are there again."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    shutil.rmtree(out / "b")
    capsys.readouterr()
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("1 processed, 1 skipped (done before), 0 failed")
    s = _summary(out)
    assert s["pairs"]["a"]["this_run"] == "skipped" and s["pairs"]["b"]["this_run"] == "processed"
    assert {p.name for p in (out / "b").iterdir()} == DISPARITY_FILES


def test_retry_failed_redoes_the_pairs_that_failed_on_the_same_images(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A pair that failed is skipped on unchanged images, and tried again with --retry-failed
    (the done pairs stay skipped)."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png", "b/left.png")
    (src / "b/right.png").write_bytes((src / "a/right.png").read_bytes()[:200])  # truncated
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 1
    capsys.readouterr()
    assert main(args) == 1
    assert capsys.readouterr().out.startswith(
        "0 processed, 1 skipped (done before), 1 skipped (failed before; --retry-failed "
        "redoes them), 0 failed in "
    )
    assert main([*args, "--retry-failed"]) == 1
    assert capsys.readouterr().out.startswith("0 processed, 1 skipped (done before), 1 failed in ")
    s = _summary(out)
    assert s["run"]["failed"] == 1 and s["run"]["skipped_failed"] == 0
    assert s["pairs"]["b"]["this_run"] == "failed" and "cannot decode" in s["pairs"]["b"]["error"]
    assert s["pairs"]["a"]["this_run"] == "skipped"
    # a new failure beside it: the line on pairs still without outputs is for runs without one
    _tiny(src, data_dir, "c/left.png")
    (src / "c/right.png").write_bytes((src / "a/right.png").read_bytes()[:200])
    assert main(args) == 1
    said = capsys.readouterr().out
    assert "1 skipped (failed before; --retry-failed redoes them), 1 failed in " in said
    assert "still without outputs" not in said


def test_a_pair_whose_image_went_keeps_its_outputs_and_a_resized_image_is_redone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A done pair whose right image goes is a failed pair that keeps its outputs listed: when
    the image comes back the pair is redone over them (not refused as files no run wrote). An
    image rewritten to another size is redone even with its old modification time."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    right = (src / "b/right.png").read_bytes()
    (src / "b/right.png").unlink()
    assert main(args) == 1  # no cluster: a is skipped, b has an image missing
    b = _summary(out)["pairs"]["b"]
    assert b["status"] == "failed" and b["error"].startswith("unpaired image: no right.png")
    assert b["outputs"] == sorted(DISPARITY_FILES)
    (src / "b/right.png").write_bytes(right)
    capsys.readouterr()
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("1 processed, 1 skipped (done before), 0 failed")
    assert {p.name for p in (out / "b").iterdir()} == DISPARITY_FILES
    left = src / "b/left.png"
    st = left.stat()
    cv2.imwrite(str(left), cv2.flip(cv2.imread(str(left)), 1))
    assert left.stat().st_size != st.st_size
    os.utime(left, ns=(st.st_atime_ns, st.st_mtime_ns))  # the time it had: the size differs
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("1 processed, 1 skipped (done before), 0 failed")
    assert _summary(out)["pairs"]["b"]["this_run"] == "processed"


def test_a_pair_name_taken_by_other_files_of_the_same_input_is_redone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """The scene folder ``a/`` replaced by ``a_left.png`` + ``a_right.png`` (other images, the
    same pair name) in the same input folder: redone; only another input's pairs are refused
    as 'made from other images'."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    shutil.rmtree(src / "a")
    _tiny(src, data_dir, "a_left.png", "a_right.png")
    _change(src / "a_left.png")
    capsys.readouterr()
    assert main(args) == 0, capsys.readouterr().err
    assert capsys.readouterr().out.startswith("1 processed, 0 skipped (done before), 0 failed")
    assert _summary(out)["pairs"]["a"]["left"] == str(src / "a_left.png")


def test_a_run_killed_after_one_with_other_outputs_is_resumed_over_both(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A run with --calib wrote depth files; a run without it was killed before recording the
    pair (pending, calib None, the first run's outputs still listed). A third run with --calib
    takes the folder's files as both runs' outputs: it is not refused as another's file."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "seq/0000_left.bmp", "seq/0000_right.bmp")
    Calibration.ideal((96, 64), 60.0, 0.1).save(tmp_path / "rig.yaml")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    args += ["--calib", str(tmp_path / "rig.yaml")]
    assert main(args) == 0
    s = _summary(out)
    assert set(s["pairs"]["seq/0000"]["outputs"]) == DEPTH_FILES
    s["pairs"]["seq/0000"].update(status="pending", calib=None)  # as the killed run left it
    (out / SUMMARY_NAME).write_text(json.dumps(s))
    capsys.readouterr()
    assert main(args) == 0, capsys.readouterr().err
    assert capsys.readouterr().out.startswith("1 processed, 0 skipped (done before), 0 failed")
    assert {p.name for p in (out / "seq/0000").iterdir()} == DEPTH_FILES


def test_a_redo_without_calib_removes_the_stale_depth_files_but_not_a_link(
    data_dir: Path, tmp_path: Path, in_process_dask: None
) -> None:
    """A pair done with --calib, redone without it: its depth files (an earlier run's, not
    written now) are removed; one the user replaced with a link is left alone."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "seq/0000_left.bmp", "seq/0000_right.bmp")
    Calibration.ideal((96, 64), 60.0, 0.1).save(tmp_path / "rig.yaml")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main([*args, "--calib", str(tmp_path / "rig.yaml")]) == 0
    pair = out / "seq/0000"
    mine = tmp_path / "mine.png"
    mine.write_bytes((pair / "depth.png").read_bytes())
    (pair / "depth.png").unlink()
    (pair / "depth.png").symlink_to(mine)
    assert main(args) == 0
    assert {p.name for p in pair.iterdir()} == DISPARITY_FILES | {"depth.png"}
    assert (pair / "depth.png").is_symlink() and mine.is_file()


def test_batch_keeps_dask_logs_off_for_a_restarted_worker_and_restores_the_config() -> None:
    """The low-level log length was 0 only while the client and cluster started: a worker
    killed (OOM, a crash) and restarted by its nanny met a scheduler that logged its last 1000
    messages to it again, each pair's image bytes in them (4 MB after 20 tasks of 200 kB).
    It stays 0 until the run closes Dask, and is as it was after."""
    import dask

    from stereovision.batch import _Dask

    before = dask.config.get("distributed.admin.low-level-log-length")
    runner = _Dask()
    runner.start(None, 1)
    try:
        sched = runner.cluster.scheduler
        old = set(sched.workers)
        for pid in runner.client.run(os.getpid).values():
            os.kill(pid, signal.SIGKILL)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and (not sched.workers or set(sched.workers) == old):
            time.sleep(0.2)
        new = set(sched.workers) - old
        assert new, "the nanny did not restart the worker"
        assert runner.client.submit(len, b"x" * 1000, pure=False).result() == 1000
        assert [sched.stream_comms[w].recent_message_log.maxlen for w in new] == [0]
        assert dask.config.get("distributed.admin.low-level-log-length") == 0
    finally:
        runner.close([])
    assert dask.config.get("distributed.admin.low-level-log-length") == before


def test_a_done_pair_missing_one_of_its_outputs_is_done_again(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A pair done before whose cloud.ply had gone (deleted, lost in a copy) was skipped as done
    on a rerun (only disparity.pfm was looked for): its cloud was never written again. It is
    done again, said in one line; a pair with all its outputs is still skipped."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "seq/0000_left.png", "seq/0000_right.png")
    _tiny(src, data_dir, "seq/0001_left.png", "seq/0001_right.png")
    Calibration.ideal((96, 64), 60.0, 0.1).save(tmp_path / "rig.yaml")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    args += ["--calib", str(tmp_path / "rig.yaml")]
    assert main(args) == 0
    cloud = out / "seq/0000/cloud.ply"
    points = read_ply(cloud)[0]
    cloud.unlink()
    capsys.readouterr()
    assert main(args) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("1 processed, 1 skipped (done before), 0 failed")
    assert _not_progress(captured.err) == [
        "1 pair(s) done before miss some of their outputs (e.g. seq/0000: cloud.ply); they are "
        "done again"
    ]
    np.testing.assert_array_equal(read_ply(cloud)[0], points)
    s = _summary(out)["pairs"]
    assert (s["seq/0000"]["this_run"], s["seq/0001"]["this_run"]) == ("processed", "skipped")
    # mutation audit: of several such pairs the line counts them all and names the first
    # one's missing outputs, each of them, in its record's order
    gone = [f for f in s["seq/0000"]["outputs"] if f != "disparity.pfm"][:2]
    assert len(gone) == 2, s["seq/0000"]["outputs"]
    for f in gone:
        (out / "seq/0000" / f).unlink()
    (out / "seq/0001/cloud.ply").unlink()
    capsys.readouterr()
    assert main(args) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("2 processed, 0 skipped (done before), 0 failed")
    assert _not_progress(captured.err) == [
        f"2 pair(s) done before miss some of their outputs (e.g. seq/0000: {', '.join(gone)}); "
        "they are done again"
    ]


def test_a_done_pair_of_an_older_summary_without_its_disparity_pfm_is_done_again(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A version 1 summary lists no outputs: its entries take the files found in their folders
    as their list, so one whose disparity.pfm had gone listed the others alone, and a done pair
    was skipped with every output it listed there, its disparity.pfm never written again (only
    disparity.pfm was looked for before). disparity.pfm, written for every pair, is always
    looked for."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    pfm = out / "a" / "disparity.pfm"
    disparity = read_pfm(pfm)
    summary = json.loads((out / SUMMARY_NAME).read_text())
    summary["version"] = 1  # as a batch before ed0f5f2 wrote it: no outputs list
    del summary["pairs"]["a"]["outputs"]
    (out / SUMMARY_NAME).write_text(json.dumps(summary, indent=1))
    (out / "a" / "overview.png").unlink()  # no version 1 batch wrote one
    pfm.unlink()
    capsys.readouterr()
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("1 processed, 0 skipped (done before), 0 failed")
    np.testing.assert_array_equal(read_pfm(pfm), disparity)
    assert _summary(out)["pairs"]["a"]["outputs"] == sorted(DISPARITY_FILES)


def test_a_changed_pair_is_redone_from_another_working_directory(
    data_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, in_process_dask: None
) -> None:
    """The summary recorded a pair's images as given (``drive/a/left.png`` for ``batch drive``),
    and read them against the working directory of the next run: after a run over another
    input into the same -o, the first input's changed pair, run from another directory (a
    service, cron), was refused as 'made from other images (e.g. a from drive/a/left.png)',
    exit 2. The summary records absolute paths now."""
    _tiny(tmp_path, data_dir, "drive/a/left.png", "drive/a/right.png")
    _tiny(tmp_path, data_dir, "other/b/left.png", "other/b/right.png")
    args = ["-o", "out", "--workers", "1", "--max-disparity", "16"]
    monkeypatch.chdir(tmp_path)
    assert main(["batch", "drive", *args]) == 0
    assert _summary(tmp_path / "out")["pairs"]["a"]["left"] == str(tmp_path / "drive/a/left.png")
    assert main(["batch", "other", *args]) == 0
    _change(tmp_path / "drive/a/left.png")  # changed: to be redone
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    assert main(["batch", str(tmp_path / "drive"), "-o", str(tmp_path / "out"), *args[2:]]) == 0
    s = _summary(tmp_path / "out")
    assert s["run"]["processed"] == 1 and s["pairs"]["a"]["this_run"] == "processed"


def test_the_summary_records_the_files_read_through_a_link_and_dotdot(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """``batch home/link/../drive`` with ``link`` a link to ``real/sub``: the OS reads
    ``real/drive``, but the summary recorded ``home/drive`` (os.path.abspath folds '..' as
    text), a file never read; after a run over another input, the changed pair was then
    refused as made from other images (exit 2). It records the files read (io.load_scene's
    rule: a '..' after a link goes up from its target)."""
    _tiny(tmp_path, data_dir, "real/drive/a/left.png", "real/drive/a/right.png")
    _tiny(tmp_path, data_dir, "other/b/left.png", "other/b/right.png")
    (tmp_path / "real/sub").mkdir()
    (tmp_path / "home").mkdir()
    (tmp_path / "home/link").symlink_to(tmp_path / "real/sub", target_is_directory=True)
    given, out = tmp_path / "home/link/../drive", tmp_path / "out"
    args = ["-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(given), *args]) == 0
    pair = _summary(out)["pairs"]["a"]
    assert pair["left"] == str(tmp_path / "real/drive/a/left.png")
    assert pair["right"] == str(tmp_path / "real/drive/a/right.png")
    assert main(["batch", str(tmp_path / "other"), *args]) == 0
    _change(tmp_path / "real/drive/a/left.png")  # changed: to be redone
    capsys.readouterr()
    assert main(["batch", str(given), *args]) == 0, capsys.readouterr().err
    s = _summary(out)
    assert s["run"]["processed"] == 1 and s["pairs"]["a"]["this_run"] == "processed"


def test_the_progress_lines_estimate_the_time_left_from_the_pairs_pace(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The time left counted the cluster's start as the first pair's time: 20 s to start the
    workers and 2 s a pair said 'about 66 s left' after the first of 4 pairs (6 s were left).
    The elapsed time still counts from the start."""
    import stereovision.batch as batch

    clock = [100.0]
    monkeypatch.setattr(batch.time, "monotonic", lambda: clock[0])
    bar = batch._Progress(4, enabled=True)  # stderr is not a terminal here: plain lines
    clock[0] += 20.0
    bar.started()
    for _ in range(2):
        clock[0] += 2.0
        bar.update()
    bar.close()
    assert capsys.readouterr().err.splitlines() == [
        "batch: 1/4 pairs, 22 s, about 6 s left",
        "batch: 2/4 pairs, 24 s, about 4 s left",
    ]


def test_the_time_left_does_not_count_pairs_that_failed_before_reaching_the_workers(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """3 pairs failing at once (an unreadable image, never sent to a worker) beside 1 done in
    10 s said 'about 15 s left' for 6 more pairs: the pace counted them as done in those 10 s.
    The pace is the workers' pairs' (done, or failed there: they took the time); before a
    worker finished one, no time left is said."""
    import stereovision.batch as batch

    clock = [100.0]
    monkeypatch.setattr(batch.time, "monotonic", lambda: clock[0])
    bar = batch._Progress(10, enabled=True)  # stderr is not a terminal here: plain lines
    clock[0] += 20.0
    bar.started()
    for _ in range(3):
        bar.update(failed=True, instant=True)
    clock[0] += 10.0
    bar.update()
    clock[0] += 10.0
    bar.update(failed=True)  # failed in the worker, after 10 s of it
    bar.close()
    assert capsys.readouterr().err.splitlines() == [
        "batch: 1/10 pairs, 1 failed, 20 s",
        "batch: 2/10 pairs, 2 failed, 20 s",
        "batch: 3/10 pairs, 3 failed, 20 s",
        "batch: 4/10 pairs, 3 failed, 30 s, about 60 s left",
        "batch: 5/10 pairs, 4 failed, 40 s, about 50 s left",
    ]


def test_scene_folders_linked_into_the_input_are_batched(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A drive's scenes linked into the input folder (in/b -> /data/b, camera folders too) were
    not entered: their pairs were left out without a word ('1 processed ... 0 failed', exit 0).
    They are batched now, named by the link; a link to a folder of the input (an alias) or to
    one holding it (a loop) is not entered, but camera folders linked in are paired as before."""
    root, data = tmp_path / "in", tmp_path / "data"
    _tiny(root, data_dir, "a/left.png", "a/right.png")
    _tiny(data, data_dir, "b/left.png", "b/right.png", "cams/left/7.png", "cams/right/7.png")
    (root / "b").symlink_to(data / "b")
    (root / "seq").mkdir()
    (root / "seq/left").symlink_to(data / "cams/left")
    (root / "seq/right").symlink_to(data / "cams/right")
    (root / "alias").symlink_to(root / "a")
    (root / "a/loop").symlink_to(root)
    (root / "up").symlink_to(tmp_path)
    # camera folders named left/ and right/ by links to folders of the input: a pair there
    _tiny(root, data_dir, "raw/cam_l/9.png", "raw/cam_r/9.png")
    (root / "seq2").mkdir()
    (root / "seq2/left").symlink_to(root / "raw/cam_l")
    (root / "seq2/right").symlink_to(root / "raw/cam_r")
    assert [j.name for j in find_pairs(root)] == ["a", "b", "seq/7", "seq2/9"]
    assert find_pairs(root)[1].left == root / "b/left.png"
    out = tmp_path / "out"
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("4 processed, 0 skipped (done before), 0 failed")
    assert {p.name for p in (out / "b").iterdir()} == DISPARITY_FILES


def test_a_run_killed_while_writing_a_pair_leaves_no_temporary_folder_for_good(
    data_dir: Path, tmp_path: Path, in_process_dask: None
) -> None:
    """A run killed (SIGKILL, the OOM killer) while writing a pair left its hidden temporary
    folder (.a.partial-1a2b3c4d, the pair's outputs) beside the pair's folder, and no run
    removed it. The next run over the pair removes those of its pairs; other hidden folders
    stay."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png", "s/b/left.png", "s/b/right.png")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    for partial in (".a.partial-1a2b3c4d", "s/.b.partial-00ff00ff"):
        (out / partial).mkdir(parents=True)
        (out / partial / "cloud.ply").write_text("half written")
    mine = [out / ".a.partial-notmine", out / ".c.partial-1a2b3c4d", out / ".mine"]
    for p in mine:
        p.mkdir()
    assert main(args) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [".a.partial-notmine", ".c.partial-1a2b3c4d", ".mine", "a", "s", SUMMARY_NAME]
    )
    assert sorted(p.name for p in (out / "s").iterdir()) == ["b"]


def test_a_pair_folder_name_near_the_longest_is_written_and_its_leftovers_removed(
    tmp_path: Path,
) -> None:
    """A pair named with 238 to 255 bytes (its folder can be made) was staged in
    '.NAME.partial-1a2b3c4d', past a file name's 255 bytes: 'File name too long', and the
    run stopped there ('cannot write the outputs of ...; 0 of N pairs finished'), every run.
    Its staging folder takes as much of the name as fits, and a killed run's is removed."""
    from stereovision.batch import _commit_pair, _remove_partials

    out = tmp_path / "out"
    out.mkdir()
    name = "\u00e9" * 120  # 240 bytes in UTF-8
    dest = _commit_pair(out, name, {"disparity.pfm": b"1"})
    assert (dest / "disparity.pfm").read_bytes() == b"1"
    _commit_pair(out, name, {"disparity.pfm": b"2"})  # into the folder there
    assert os.listdir(out) == [name] and (dest / "disparity.pfm").read_bytes() == b"2"
    # a killed run's staging folder: the name's first 237 bytes, a character cut in two
    left = os.path.join(os.fsencode(out), b"." + os.fsencode(name)[:237] + b".partial-1a2b3c4d")
    os.mkdir(left)
    _remove_partials(out, [name])
    assert os.listdir(out) == [name]


def test_an_image_that_cannot_be_read_fails_its_pair_alone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A pair's image that is a broken link (a drive not mounted, a sync not finished) stopped
    the whole run before any pair, '[Errno 2] No such file or directory: ...', exit 2. That
    pair alone fails now, its error in one line and in the summary, the others are done, exit
    1; it is tried again on the next run and done once the image is there."""
    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "b/left.png", "b/right.png")
    (src / "a/right.png").symlink_to(tmp_path / "not-mounted/right.png")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    capsys.readouterr()
    assert main(args) == 1
    said = capsys.readouterr()
    error = f"FileNotFoundError: [Errno 2] No such file or directory: '{src / 'a/right.png'}'"
    assert f"failed a: {error}" in said.err.splitlines()
    assert said.out.startswith("1 processed, 0 skipped (done before), 1 failed in ")
    s = _summary(out)
    assert s["pairs"]["a"]["status"] == "failed" and s["pairs"]["a"]["error"] == error
    assert s["pairs"]["b"]["status"] == "done" and s["run"]["failed"] == 1
    _tiny(tmp_path, data_dir, "not-mounted/right.png")  # mounted
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("1 processed, 1 skipped (done before), 0 failed")
    assert _summary(out)["pairs"]["a"]["outputs"] == sorted(DISPARITY_FILES)


def test_an_image_that_cannot_be_read_when_sent_is_tried_again(
    data_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An image whose size and time could be read but not its bytes (permission denied, an I/O
    error, a network share gone between the check and the read) failed its pair with its
    images' fingerprint recorded: the next run skipped it as 'failed before' (until
    --retry-failed), though the file was readable again with the same size and time (chmod
    changes neither). As an image whose size cannot be read, it is now tried again every run;
    its record has no options or fingerprint, as batch.md says of such a pair."""
    from stereovision import batch

    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    denied = src / "a/right.png"
    real_read = Path.read_bytes

    def read_bytes(self: Path) -> bytes:
        if self == denied:
            raise PermissionError(13, "Permission denied", str(self))
        return real_read(self)

    monkeypatch.setattr(Path, "read_bytes", read_bytes)
    # a failure before the workers took none of their time: not counted in the time left's pace
    finished: list[tuple[bool, bool]] = []
    update = batch._Progress.update

    def seen(bar: batch._Progress, failed: bool = False, instant: bool = False) -> None:
        finished.append((failed, instant))
        update(bar, failed, instant)

    monkeypatch.setattr(batch._Progress, "update", seen)
    first = batch.run_batch(src, out, workers=1, max_disparity=16, progress=False)
    assert (first.processed, first.failed) == (["b"], ["a"])
    assert finished == [(True, True), (False, False)]
    entry = _summary(out)["pairs"]["a"]
    assert entry["error"] == f"PermissionError: [Errno 13] Permission denied: '{denied}'"
    assert "fingerprint" not in entry and "options" not in entry
    monkeypatch.setattr(Path, "read_bytes", real_read)  # readable again, same size and time
    again = batch.run_batch(src, out, workers=1, max_disparity=16, progress=False)
    assert (again.processed, again.skipped, again.failed_before) == (["a"], ["b"], [])
    assert _summary(out)["pairs"]["a"]["status"] == "done"


def test_a_calibration_that_cannot_be_read_for_its_hash_fails_its_pair_alone(
    data_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, in_process_dask: None
) -> None:
    """A pair's calibration file read for its sha256 after its task was made (permission
    denied, an I/O error, a share gone between the two reads) raised out of the run: it
    stopped ("PermissionError ...; 0 of 2 pairs finished this run"), the pairs to come undone,
    where an unreadable file is a failed pair. It is one now, tried again on the next run."""
    from stereovision import batch

    src, out = tmp_path / "drive", tmp_path / "out"
    _tiny(src, data_dir, "a/left.png", "a/right.png", "b/left.png", "b/right.png")
    cam = "[100 0 48; 0 100 32; 0 0 1]"
    for name in ("a", "b"):
        (src / name / "calib.txt").write_text(
            f"cam0={cam}\ncam1={cam}\ndoffs=0\nbaseline=100\nwidth=96\nheight=64\nndisp=16\n"
        )
    denied = src / "a/calib.txt"
    real_sha256 = batch._sha256

    def sha256(path: Path) -> str:
        if path == denied:
            raise PermissionError(13, "Permission denied", str(path))
        return real_sha256(path)

    monkeypatch.setattr(batch, "_sha256", sha256)
    first = batch.run_batch(src, out, workers=1, max_disparity=16, progress=False)
    assert (first.processed, first.failed) == (["b"], ["a"])
    entry = _summary(out)["pairs"]["a"]
    assert entry["error"] == f"PermissionError: [Errno 13] Permission denied: '{denied}'"
    assert "fingerprint" not in entry and "options" not in entry
    monkeypatch.setattr(batch, "_sha256", real_sha256)
    again = batch.run_batch(src, out, workers=1, max_disparity=16, progress=False)
    assert (again.processed, again.skipped, again.failed_before) == (["a"], ["b"], [])


def test_calib_unit_reaches_the_workers(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--calib had no unit to go with it: a Q.dat (which states none) was read in metres, and
    the worker read the file shipped to it again without one. The unit given is the unit of
    the calibration the worker gets; a file stating another is refused before a pair runs."""
    from stereovision.batch import _task
    from stereovision.cli import main

    teddy = data_dir / "middeval3" / "teddyH"
    scene = tmp_path / "teddyH"
    scene.mkdir()
    for name in ("left.png", "right.png", "Q.dat"):
        shutil.copy(teddy / name, scene / name)
    (job,) = find_pairs(scene, calib=scene / "Q.dat")
    with pytest.warns(UserWarning, match="unit='cm'"):  # teddyH's B is 0.08 (m): 0.8 mm in cm
        name, data = _task(job, {"method": None, "max_disparity": None, "fill": None,
                                 "calib_unit": "cm"})["calib"]  # fmt: skip
    shipped = json.loads(data)
    assert (name, shipped["unit"], shipped["T"][0]) == ("calib.json", "cm", pytest.approx(-0.08))
    calib_txt = data_dir / "eth3d" / "terrace" / "calib.txt"
    out = tmp_path / "out"
    args = ["batch", str(scene), "-o", str(out), "--calib", str(calib_txt), "--calib-unit", "m"]
    assert main(args) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {calib_txt} states its lengths in 'mm', not in --calib-unit m: "
        "leave --calib-unit out (it is for files that do not state theirs: OpenCV stereo_calib "
        "output, an OpenCV YAML/XML or JSON file without a unit field, Q.dat)\n"
    )
    assert not out.exists()


def test_batch_sizes_opencv_stereo_calib_output_by_the_first_pair(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """OpenCV stereo_calib's intrinsics.yml + extrinsics.yml hold no image size: batch refused
    them ("this command cannot read it from its images, so save the rig once in Python ..."),
    exit 2. The first pair's left image sizes them now; a pair of another size fails with
    depth's own message, the others are done with the rig (metric outputs)."""
    rig, root, out = _stereo_calib_input(tmp_path, data_dir, ("01", "02"))
    for n in ("01", "02"):
        for side in ("left", "right"):
            small = cv2.resize(cv2.imread(str(root / f"{side}{n}.jpg")), (320, 240))
            cv2.imwrite(str(root / f"{side}9{n}.png"), small)  # another size: pairs 901, 902
    (root / "right902.png").unlink()  # one small pair only
    (root / "left902.png").unlink()
    args = ["batch", str(root), "-o", str(out), "--calib", str(rig), "--workers", "1"]
    args += ["--max-disparity", "16", "--calib-unit", "mm"]
    capsys.readouterr()
    assert main(args) == 1
    said = capsys.readouterr()
    assert said.out.startswith("2 processed, 0 skipped (done before), 1 failed in ")
    pairs = _summary(out)["pairs"]
    assert [pairs[n]["status"] for n in ("01", "02", "901")] == ["done", "done", "failed"]
    assert pairs["901"]["error"].startswith(
        "ValueError: calibration is for 640x480 images, got 320x240"
    )
    assert pairs["01"]["options"]["calib_size"] == [640, 480]
    assert set(pairs["01"]["outputs"]) == DEPTH_FILES
    assert np.load(out / "01" / "depth.npy").shape == (480, 640)
    assert main(args) == 1  # the same run again: nothing redone
    assert capsys.readouterr().out.startswith("0 processed, 2 skipped (done before), 1 skipped")


def test_batch_searches_the_input_once_to_size_a_sizeless_calibration(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """--calib of OpenCV stereo_calib output (no image size) searched the input twice: once in
    cmd_batch for the first pair's left image that sizes it, to refuse it in the command
    line's words, and again in run_batch (a large tree's walk, twice). Once now, its refusal in
    the same words."""
    from test_calibration import _opencv_stereo_calib

    import stereovision.batch as batch

    rig, out = tmp_path / "rig", tmp_path / "out"
    rig.mkdir()
    _opencv_stereo_calib(rig)
    _blank(tmp_path / "in", "s/left.png", "s/right.png")
    searches: list[Any] = []
    search = batch._search

    def counted(*args: Any) -> Any:
        searches.append(args[0])
        return search(*args)

    monkeypatch.setattr(batch, "_search", counted)
    monkeypatch.setattr(batch, "_run_jobs", lambda *args: None)  # the search alone looked at
    args = ["batch", str(tmp_path / "in"), "-o", str(out), "--calib", str(rig)]
    capsys.readouterr()
    assert main(args) == 2
    assert capsys.readouterr().err == (
        f"stereovision: error: {rig} is OpenCV stereo_calib output (intrinsics.yml + "
        "extrinsics.yml), which holds neither the image size nor the unit of T (the board's "
        "square size): pass --calib-unit (m, mm, cm, ft or in)\n"
    )
    assert len(searches) == 1 and not out.exists()
    assert main([*args, "--calib-unit", "mm"]) == 0
    assert len(searches) == 2


def test_a_copy_without_its_times_is_up_to_date_and_a_changed_byte_is_redone(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A dataset copied without its modification times (cp -r) and run into the same -o was
    refused as 'made from other images' (size + time only), exit 2. The summary records each
    input's sha256; a time that differs is checked against it: the same bytes are up to date
    (their new times recorded), one byte changed redoes that pair. A pair recorded without
    hashes (a version 2 summary) is redone on a new time, as before, and records them."""
    import hashlib

    src, copy, out = tmp_path / "drive", tmp_path / "copy", tmp_path / "out"
    _tiny(src, data_dir, *(f"seq/{i:04d}_{s}.bmp" for i in range(2) for s in ("left", "right")))
    args = ["-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(src), *args]) == 0
    entry = _summary(out)["pairs"]["seq/0000"]
    left = src / "seq/0000_left.bmp"
    assert entry["hashes"]["left"] == hashlib.sha256(left.read_bytes()).hexdigest()
    assert _summary(out)["version"] == 3
    shutil.copytree(src, copy, copy_function=shutil.copyfile)  # times not kept
    for p in copy.rglob("*.bmp"):
        os.utime(p, ns=(10**18, 10**18))
    before = _tree(out)
    capsys.readouterr()
    assert main(["batch", str(copy), *args]) == 0, capsys.readouterr().err
    assert capsys.readouterr().out.startswith("0 processed, 2 skipped (done before), 0 failed")
    assert _tree(out) == before  # nothing rewritten
    entry = _summary(out)["pairs"]["seq/0000"]
    assert entry["fingerprint"]["left"][1] == 10**18
    assert entry["left"] == str(copy / "seq/0000_left.bmp")
    changed = copy / "seq/0001_left.bmp"
    data = bytearray(changed.read_bytes())
    data[-1] ^= 1  # a pixel of the last row: the size kept, the image still decodes
    changed.write_bytes(bytes(data))
    os.utime(changed, ns=(10**18, 10**18))  # even the time kept: the copy's
    os.utime(copy / "seq/0000_left.bmp", ns=(2 * 10**18, 2 * 10**18))  # bytes kept
    assert main(["batch", str(copy), *args]) == 0
    s = _summary(out)
    assert s["run"]["processed"] == 0 and s["run"]["skipped"] == 2  # the same time: as before
    os.utime(changed, ns=(3 * 10**18, 3 * 10**18))
    assert main(["batch", str(copy), *args]) == 0
    s = _summary(out)
    assert s["run"]["processed"] == 1 and s["run"]["skipped"] == 1
    assert s["pairs"]["seq/0001"]["this_run"] == "processed"
    assert s["pairs"]["seq/0001"]["hashes"]["left"] == hashlib.sha256(data).hexdigest()
    # a record without hashes (version 2): a new time is a change, and the hashes are recorded
    for e in s["pairs"].values():
        del e["hashes"]
    (out / SUMMARY_NAME).write_text(json.dumps({**s, "version": 2}))
    os.utime(copy / "seq/0000_left.bmp", ns=(4 * 10**18, 4 * 10**18))
    assert main(["batch", str(copy), *args]) == 0
    s = _summary(out)
    assert s["run"]["processed"] == 1 and s["pairs"]["seq/0000"]["this_run"] == "processed"
    assert "hashes" in s["pairs"]["seq/0000"] and "hashes" not in s["pairs"]["seq/0001"]


class _Terminal(io.StringIO):
    """A stderr that says it is a terminal (batch draws its bars on one only)."""

    def isatty(self) -> bool:
        return True


def test_the_check_of_a_copy_without_its_times_shows_its_progress(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    in_process_dask: None,
) -> None:
    """Files copied without their times are read again (their sha256 against the summary's)
    before the pairs' bar starts, which took long on a large dataset with nothing shown. That
    check now has its bar on a terminal once it runs CHECK_BAR_DELAY seconds (a quick one draws
    none), its total the pairs; elsewhere a plain line every PROGRESS_SECONDS while files are
    read. stdout and every output file stay as they were."""
    import stereovision.batch as batch

    src, copy, out = tmp_path / "drive", tmp_path / "copy", tmp_path / "out"
    _tiny(src, data_dir, *(f"seq/{i:04d}_{s}.bmp" for i in range(3) for s in ("left", "right")))
    args = ["-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(src), *args]) == 0
    shutil.copytree(src, copy, copy_function=shutil.copyfile)  # times not kept
    before = _tree(out)
    capsys.readouterr()

    def rerun(err: io.StringIO, stamp: int) -> str:
        for p in copy.rglob("*.bmp"):  # new times again: every pair's files are read again
            os.utime(p, ns=(stamp, stamp))
        monkeypatch.setattr("sys.stderr", err)
        assert main(["batch", str(copy), *args]) == 0
        assert capsys.readouterr().out.startswith("0 processed, 3 skipped (done before), 0 ")
        assert _tree(out) == before
        return err.getvalue()

    # raising=False: the code before this bar fails on its output, not on the name
    monkeypatch.setattr(batch, "CHECK_BAR_DELAY", 0.0, raising=False)  # a long check, to the bar
    shown = re.findall(r"checking files: +(\d+)%\|[^|]*\| (\d+)/(\d+) ", rerun(_Terminal(), 10**18))
    assert shown and shown[-1] == ("100", "3", "3"), shown
    monkeypatch.setattr(batch, "CHECK_BAR_DELAY", 60.0)  # a quick check: no bar
    assert "checking" not in rerun(_Terminal(), 2 * 10**18)
    monkeypatch.setattr(batch, "PROGRESS_SECONDS", 0.0)  # not a terminal: plain lines
    lines = rerun(io.StringIO(), 3 * 10**18).splitlines()
    line = re.compile(
        r"batch: checking the pairs' files \(their times changed\): (\d)/3 pairs, \d+ s"
    )
    assert [m[1] if (m := line.fullmatch(x)) else x for x in lines] == ["1", "2"]
    monkeypatch.setattr(batch, "PROGRESS_SECONDS", math.inf)  # a quick check: no line
    assert rerun(io.StringIO(), 4 * 10**18) == ""


def test_a_copy_without_its_times_of_a_calibration_is_up_to_date(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """The --calib file copied without its time beside the images is checked against its
    recorded sha256 as they are: the same bytes, the pairs are up to date."""
    src, copy, out = tmp_path / "drive", tmp_path / "copy", tmp_path / "out"
    _tiny(src, data_dir, "seq/0000_left.bmp", "seq/0000_right.bmp")
    Calibration.ideal((96, 64), 60.0, 0.1).save(src / "rig.yaml")
    args = ["-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(["batch", str(src), *args, "--calib", str(src / "rig.yaml")]) == 0
    assert "calib" in _summary(out)["pairs"]["seq/0000"]["hashes"]
    shutil.copytree(src, copy, copy_function=shutil.copyfile)  # times not kept
    for p in copy.rglob("*.*"):
        os.utime(p, ns=(10**18, 10**18))
    capsys.readouterr()
    assert main(["batch", str(copy), *args, "--calib", str(copy / "rig.yaml")]) == 0
    assert capsys.readouterr().out.startswith("0 processed, 1 skipped (done before), 0 failed")
    assert _summary(out)["pairs"]["seq/0000"]["calib"] == str(copy / "rig.yaml")


def test_a_run_that_never_starts_keeps_the_summary_of_earlier_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The summary a run removes when its scheduler cannot be reached is only one it wrote
    into a folder that had none: an earlier run's record (here a pair done) stays."""
    import stereovision.batch as batch

    monkeypatch.setattr(batch, "CONNECT_TIMEOUT", "1s")
    _noise_pair(tmp_path / "in" / "scene")
    out = tmp_path / "out"
    out.mkdir()
    earlier = {"version": 3, "pairs": {"old": {"status": "done", "outputs": []}}}
    (out / SUMMARY_NAME).write_text(json.dumps(earlier))
    rc = main(["batch", str(tmp_path / "in"), "-o", str(out), "--scheduler", "tcp://127.0.0.1:1"])
    assert rc == 2 and "cannot reach the Dask scheduler" in capsys.readouterr().err
    assert _summary(out)["pairs"]["old"] == {
        "status": "done",
        "outputs": [],
        "this_run": "not in input",
    }


def test_one_cameras_ros_file_reaches_the_workers_with_its_partner(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--calib ros/left.yaml (its right.yaml beside it, as calibration reads it) was checked
    here and then shipped alone: every pair failed in the worker with 'its partner (left/right
    swapped in the name) is not beside it'. It is read here and shipped as the rig's JSON."""
    rig, root, out = _stereo_calib_input(tmp_path, data_dir, ("01",))
    ros = tmp_path / "ros"
    Calibration.from_file(rig, image_size=(640, 480), unit="mm").save_ros(ros)
    args = ["batch", str(root), "-o", str(out), "--calib", str(ros / "left.yaml")]
    capsys.readouterr()
    assert main([*args, "--workers", "1", "--max-disparity", "16"]) == 0, capsys.readouterr().err
    pair = _summary(out)["pairs"]["01"]
    assert pair["status"] == "done" and set(pair["outputs"]) == DEPTH_FILES
    assert np.load(out / "01" / "depth.npy").shape == (480, 640)


def test_a_calibration_file_rewritten_in_its_folder_redoes_the_pairs(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """--calib rig/ (OpenCV stereo_calib's two files): the folder's own size and time were the
    calibration's fingerprint, and a file rewritten in place in it (a baseline of 240 mm for
    120) changes neither: the pair was skipped as done, its depth that of the old rig. The
    files read are fingerprinted; the same bytes with new times (a copy) are still up to date."""
    rig, root, out = _stereo_calib_input(tmp_path, data_dir, ("01",))  # T (-120, 1.5, 0.8) mm
    args = ["batch", str(root), "-o", str(out), "--calib", str(rig), "--calib-unit", "mm"]
    args += ["--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    z120 = np.load(out / "01" / "depth.npy")
    extrinsics = rig / "extrinsics.yml"
    text = extrinsics.read_text()
    os.utime(extrinsics, ns=(1, 1))  # the same bytes, another time: nothing redone
    assert main(args) == 0
    assert _summary(out)["pairs"]["01"]["this_run"] == "skipped"
    folder_time = rig.stat().st_mtime_ns
    with open(extrinsics, "w") as fh:  # in place: the folder's time does not change
        fh.write(text.replace("-120.", "-240."))
    assert rig.stat().st_mtime_ns == folder_time
    capsys.readouterr()
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("1 processed, 0 skipped")
    z240 = np.load(out / "01" / "depth.npy")
    both = np.isfinite(z120) & np.isfinite(z240)
    assert both.sum() > 1000
    np.testing.assert_allclose(np.median(z240[both] / z120[both]), 2.0, rtol=0.02)


def test_a_rerun_keeps_the_size_its_summary_recorded_for_a_sizeless_calibration(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """OpenCV stereo_calib output is sized by the first pair by name: a pair of another size
    added later that sorts first (00 before 01) changed calib_size for every pair, so all were
    redone and all but it failed ('calibration is for 320x240 images'). A rerun into the same
    output folder keeps the size its summary recorded for the same calibration: the new pair
    fails alone, the others are skipped as done."""
    rig, root, out = _stereo_calib_input(tmp_path, data_dir, ("01", "02"))
    args = ["batch", str(root), "-o", str(out), "--calib", str(rig), "--workers", "1"]
    args += ["--max-disparity", "16", "--calib-unit", "mm"]
    assert main(args) == 0
    for side in ("left", "right"):
        small = cv2.resize(cv2.imread(str(root / f"{side}01.jpg")), (320, 240))
        cv2.imwrite(str(root / f"{side}00.png"), small)  # sorts first, another size
    capsys.readouterr()
    assert main(args) == 1
    assert capsys.readouterr().out.startswith("0 processed, 2 skipped (done before), 1 failed")
    pairs = _summary(out)["pairs"]
    assert [pairs[n]["status"] for n in ("00", "01", "02")] == ["failed", "done", "done"]
    assert pairs["00"]["error"].startswith(
        "ValueError: calibration is for 640x480 images, got 320x240"
    )
    assert pairs["00"]["options"]["calib_size"] == [640, 480]
    assert np.load(out / "01" / "depth.npy").shape == (480, 640)


def test_the_image_sizing_a_calibration_is_fingerprinted_as_its_files_are(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """--calib rig/Q.dat is sized by the rig/left.png beside it (a Q matrix holds no image
    size), which was not fingerprinted: another image there (192x128 for 96x64) changed the
    calibration read, and the pair was skipped as done. It is fingerprinted as a calibration
    file; a rewritten Q.dat redoes the pair too (depth doubled with the focal length)."""
    root, out, rig = tmp_path / "in", tmp_path / "out", tmp_path / "rig"
    _tiny(root, data_dir, "a/left.png", "a/right.png", "rig/left.png")
    shutil.move(root / "rig", rig)
    q = rig / "Q.dat"
    q.write_text("1 0 0 -48\n0 1 0 -32\n0 0 0 100\n0 0 10 0\n")
    args = ["batch", str(root), "-o", str(out), "--calib", str(q), "--workers", "1"]
    args += ["--max-disparity", "16"]
    assert main(args) == 0
    z100 = np.load(out / "a" / "depth.npy")
    fp = _summary(out)["pairs"]["a"]["fingerprint"]
    assert sorted(fp) == ["calib", "calib:left.png", "left", "right"]
    q.write_text("1 0 0 -48\n0 1 0 -32\n0 0 0 200\n0 0 10 0\n")
    capsys.readouterr()
    assert main(args) == 0
    assert capsys.readouterr().out.startswith("1 processed, 0 skipped")
    z200 = np.load(out / "a" / "depth.npy")
    both = np.isfinite(z100) & np.isfinite(z200)
    assert both.sum() > 1000
    np.testing.assert_allclose(z200[both], 2 * z100[both], rtol=1e-5)
    big = cv2.resize(cv2.imread(str(rig / "left.png")), (192, 128))
    cv2.imwrite(str(rig / "left.png"), big)
    assert main(args) == 1
    assert capsys.readouterr().out.startswith("0 processed, 0 skipped (done before), 1 failed")
    pair = _summary(out)["pairs"]["a"]
    assert pair["status"] == "failed"
    assert pair["error"].startswith("ValueError: calibration is for 192x128 images, got 96x64")


def test_the_calibration_inputs_fingerprinted_are_those_read(tmp_path: Path) -> None:
    """The image read to size a calibration: a folder's Q.dat's left.png, a KITTI file's
    image_2.png (no S_rect_02); none for a scene's Q.dat (its left.png is the pair's own, the
    keys an earlier run recorded) nor for a KITTI file that states its size."""
    from stereovision.batch import _fingerprint

    rig = tmp_path / "rig"
    rig.mkdir()
    (rig / "Q.dat").write_text("1 0 0 -48\n0 1 0 -32\n0 0 0 100\n0 0 10 0\n")
    for name in ("left.png", "image_2.png", "l.png", "r.png"):
        (rig / name).write_bytes(b"x")
    kitti = tmp_path / "kitti"
    kitti.mkdir()
    p2 = "P2: 100 0 48 0 0 100 32 0 0 0 1 0\nP3: 100 0 48 -50 0 100 32 0 0 0 1 0\n"
    (kitti / "calib.txt").write_text(p2)
    shutil.copy(rig / "image_2.png", kitti / "image_2.png")
    sized = tmp_path / "sized.txt"
    sized.write_text(p2 + "S_rect_02: 96 64\n")
    shutil.copy(rig / "left.png", tmp_path / "left.png")
    lp, rp = rig / "l.png", rig / "r.png"
    keys = {
        "folder": sorted(_fingerprint(PairJob("a", lp, rp, rig))),
        "kitti": sorted(_fingerprint(PairJob("a", lp, rp, kitti / "calib.txt"))),
        "kitti folder": sorted(_fingerprint(PairJob("a", lp, rp, kitti))),
        "scene": sorted(_fingerprint(PairJob("a", rig / "left.png", rp, rig / "Q.dat"))),
        "sized": sorted(_fingerprint(PairJob("a", lp, rp, sized))),
    }
    assert keys == {
        "folder": ["calib:Q.dat", "calib:left.png", "left", "right"],
        "kitti": ["calib", "calib:image_2.png", "left", "right"],
        "kitti folder": ["calib:calib.txt", "calib:image_2.png", "left", "right"],
        "scene": ["calib", "left", "right"],
        "sized": ["calib", "left", "right"],
    }


def test_a_full_output_disk_names_the_pair_and_closes_the_record(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    in_process_dask: None,
) -> None:
    """The output disk full (a robot's SD card) while the third pair was written: the run
    stopped with "stereovision: error: [Errno 28] No space left on device", naming neither the
    pair nor the folder, and its summary's record of the run was left without its end. The
    line names both and what is kept; the record is closed with the error; a re-run resumes."""
    import errno

    import stereovision.batch as batch

    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, *(f"seq/{i:04d}_{s}.png" for i in range(4) for s in ("left", "right")))
    commit = batch._commit_pair
    tried: list[str] = []

    def fill_the_disk(out_dir: Path, name: str, files: dict[str, bytes], *more: Any) -> Path:
        tried.append(name)
        if len(tried) == 3:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return commit(out_dir, name, files, *more)

    monkeypatch.setattr(batch, "_commit_pair", fill_the_disk)
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == (
        f"stereovision: error: cannot write the outputs of {tried[2]} into {out / tried[2]}: "
        f"No space left on device; 2 of 4 pairs finished this run, kept in {out} and "
        f"recorded in {out / SUMMARY_NAME}; run again to continue"
    )
    s = _summary(out)
    assert s["counts"] == {"done": 2, "failed": 0, "pending": 2}
    assert s["run"]["processed"] == 2 and s["run"]["interrupted"] is False
    assert s["run"]["error"] == (
        f"OSError: cannot write the outputs of {tried[2]} into {out / tried[2]}: No space left "
        "on device"
    )
    assert "finished" in s["run"] and s["run"]["seconds"] > 0
    assert s["pairs"][tried[2]]["status"] == "pending"
    assert sorted(f"seq/{p.name}" for p in (out / "seq").iterdir()) == sorted(tried[:2])
    monkeypatch.setattr(batch, "_commit_pair", commit)
    assert main(args) == 0
    s = _summary(out)
    assert (s["run"]["processed"], s["run"]["skipped"]) == (2, 2) and "error" not in s["run"]


def test_a_full_output_disk_that_the_summary_cannot_be_written_to_is_said(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    in_process_dask: None,
) -> None:
    """The disk full while the third pair was written, and summary.json (a long run's, written
    every few pairs) not writable either: the summary's own "[Errno 28] No space left on
    device", raised from the run's last flush, took the place of the error naming the pair,
    and the line said the pairs finished were "recorded in OUT/summary.json", where none of
    them was. The line names the pair and says the summary could not be updated."""
    import errno

    import stereovision.batch as batch

    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, *(f"seq/{i:04d}_{s}.png" for i in range(4) for s in ("left", "right")))
    commit, save = batch._commit_pair, batch._Summary.save
    tried: list[str] = []
    full = [False]

    def fill_the_disk(out_dir: Path, name: str, files: dict[str, bytes], *more: Any) -> Path:
        tried.append(name)
        if len(tried) == 3:
            full[0] = True
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return commit(out_dir, name, files, *more)

    def save_unless_full(self: Any) -> None:
        if full[0]:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        save(self)

    monkeypatch.setattr(batch, "_commit_pair", fill_the_disk)
    monkeypatch.setattr(batch._Summary, "save", save_unless_full)
    monkeypatch.setattr(batch, "SAVE_COST_RATIO", 1e12)  # a long run's: written now and then
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == (
        f"stereovision: error: cannot write the outputs of {tried[2]} into {out / tried[2]}: "
        f"No space left on device; 2 of 4 pairs finished this run, kept in {out}; "
        f"{out / SUMMARY_NAME} could not be updated (No space left on device): the pairs "
        "finished since it was last written are not recorded in it; run again to continue"
    )
    assert _summary(out)["counts"] == {"done": 0, "failed": 0, "pending": 4}


def test_find_pairs_separators_hidden_camera_images_ambiguous_folders_and_dot(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Pair names drop the '.' and ' ' around 'left' as they drop '_' and '-'; a hidden image in
    a camera folder is no pair; 'left' beside 'Left' is not guessed a camera folder; '.' as the
    scene, or a folder of Left.jpg and Right.jpg, is named by the folder it is (each survived a
    mutation audit)."""
    img = np.zeros((8, 8, 3), np.uint8)
    files = [
        "dots/img.left.png",
        "dots/img.right.png",
        "dots/shot left 7.png",
        "dots/shot right 7.png",
        "rig/left/0001.png",
        "rig/right/0001.png",
        "rig/left/.0002.png",
        "rig/right/.0002.png",
        "two/left/0001.png",
        "two/Left/0001.png",
        "two/right/0001.png",
        "scene/left.png",
        "scene/right.png",
        "cam/Left.jpg",
        "cam/Right.jpg",
    ]
    for f in files:
        (tmp_path / f).parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(tmp_path / f), img)
    jobs = find_pairs(tmp_path)
    assert [(j.name, j.left.relative_to(tmp_path).as_posix()) for j in jobs] == [
        ("cam", "cam/Left.jpg"),
        ("dots/img", "dots/img.left.png"),
        ("dots/shot_7", "dots/shot left 7.png"),
        ("rig/0001", "rig/left/0001.png"),
        ("scene", "scene/left.png"),
    ]
    for scene in ("scene", "cam"):
        monkeypatch.chdir(tmp_path / scene)
        assert [j.name for j in find_pairs(".")] == [scene]


def test_camera_folders_pair_by_number_only_when_one_image_of_a_subfolder_carries_it(
    tmp_path: Path,
) -> None:
    """Sibling camera folders pair images by number when the names are otherwise the same but
    for the side and separators ('.' too); two left images of number 1 (left_1, left_01) are not
    guessed between, nor are images of other sub-folders paired (each survived a mutation
    audit)."""
    img = np.zeros((8, 8, 3), np.uint8)
    files = [
        "r1/left/a.left.1.png",
        "r1/right/a_right_01.png",
        "r2/left/left_1.png",
        "r2/left/left_01.png",
        "r2/right/right_1.png",
        "r3/left/a/left_1.png",
        "r3/right/b/right_1.png",
    ]
    for f in files:
        (tmp_path / f).parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(tmp_path / f), img)
    jobs = find_pairs(tmp_path)
    assert [(j.name, j.right.relative_to(tmp_path).as_posix()) for j in jobs] == [
        ("r1/a_1", "r1/right/a_right_01.png"),
    ]


def test_a_failed_pairs_error_is_the_first_line_of_its_message() -> None:
    """OpenCV's errors run over several lines: a pair's error is the first, after the type
    (the last line survived a mutation audit); a message-less one is its type alone."""
    from stereovision.batch import _error_line

    assert _error_line(ValueError("cannot decode a.png\n  detail")) == (
        "ValueError: cannot decode a.png"
    )
    assert _error_line(MemoryError()) == "MemoryError"


class _NoStrError(Exception):
    def __str__(self) -> str:
        return 5  # type: ignore[return-value]  # a __str__ not returning a str: TypeError


@pytest.mark.parametrize("exc", [KeyError(10**5000), _NoStrError(), ValueError(-(10**4400))])
def test_a_failed_pairs_error_that_cannot_say_its_message_is_its_type(exc: Exception) -> None:
    # _error_line took str(exc) before first_line, which ab716d7 taught such an error: a
    # failed run's record (run["error"]) raised in its handler and was left without its end
    from stereovision.batch import _error_line

    assert _error_line(exc) == type(exc).__name__
    assert _error_line(exc, "cli") == type(exc).__name__


def test_a_run_killed_without_calib_does_not_own_the_depth_names(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A run without --calib killed before recording its pair (pending, calib None) wrote no
    depth files: a cloud.ply the user put in the pair's folder is not taken for its output by a
    rerun with --calib, which refuses to replace it (the pending run's names taken as with a
    calibration survived a mutation audit)."""
    src, out = tmp_path / "in", tmp_path / "out"
    _tiny(src, data_dir, "seq/0000_left.bmp", "seq/0000_right.bmp")
    Calibration.ideal((96, 64), 60.0, 0.1).save(tmp_path / "rig.yaml")
    args = ["batch", str(src), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    assert main(args) == 0
    data = _summary(out)
    entry = data["pairs"]["seq/0000"]
    killed = {k: entry[k] for k in ("left", "right", "calib", "options", "fingerprint")}
    data["pairs"]["seq/0000"] = {"status": "pending", **killed}
    (out / SUMMARY_NAME).write_text(json.dumps(data))
    (out / "seq/0000/cloud.ply").write_bytes(b"mine")
    capsys.readouterr()
    assert main([*args, "--calib", str(tmp_path / "rig.yaml")]) == 2
    assert "cloud.ply is not listed as an earlier run's output" in capsys.readouterr().err
    assert (out / "seq/0000/cloud.ply").read_bytes() == b"mine"


def test_the_summary_of_a_cli_run_says_its_errors_in_the_clis_words(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """`stereovision batch` logged a pair's error in the CLI's words but recorded it in
    summary.json in Python's: "calib.scaled_to((225, 188))" for a resized pair, "give a
    max_disparity below 96" for a pair too narrow for --max-disparity. A CLI run records the
    flags and files (as depth's error line says them); run_batch keeps Python's words."""
    from stereovision.batch import _error_line
    from stereovision.cli import _demo_scene_dir

    cones, root, out = _demo_scene_dir(), tmp_path / "in", tmp_path / "out"
    (root / "half").mkdir(parents=True)
    for side in ("left", "right"):
        img = cv2.imread(str(cones / f"{side}.png"))
        cv2.imwrite(str(root / "half" / f"{side}.png"), cv2.resize(img, (225, 188)))
    shutil.copy(cones / "calib.txt", root / "half" / "calib.txt")
    _tiny(root, data_dir, "narrow/left.png", "narrow/right.png")  # 96 px wide
    argv = ["batch", str(root), "-o", str(out), "--max-disparity", "200", "--workers", "1"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    resized = (
        "ValueError: calibration is for 450x375 images, got 225x188 (images resized, not "
        "cropped: resize them back to the calibration's size, or save it scaled to them once "
        "in Python with Calibration.from_file(path).scaled_to((225, 188)).save('rig.yaml') and "
        "give rig.yaml)"
    )
    narrow = (
        "ValueError: disparity range 200 is not smaller than the image width 96: it needs "
        "images at least 201 px wide, or give a --max-disparity below 96"
    )
    pairs = _summary(out)["pairs"]
    assert pairs["half"]["error"] == resized
    assert pairs["narrow"]["error"] == narrow
    assert f"failed half: {resized}\n" in err and f"failed narrow: {narrow}\n" in err
    # the Python API's words where they are raised
    api = ValueError("... got 225x188 (images resized, not cropped: calib.scaled_to((225, 188)))")
    assert _error_line(api) == f"ValueError: {api}"
    assert _error_line(api, "cli").endswith(resized[-40:])
    with pytest.raises(ValueError, match=r"or give a max_disparity below 96$"):
        depth_map(
            *(cv2.imread(str(root / "narrow" / f"{s}.png")) for s in ("left", "right")),
            max_disparity=200,
        )
    left, right = (str(root / "narrow" / f"{s}.png") for s in ("left", "right"))
    assert main(["depth", left, right, "--max-disparity", "200", "-o", str(tmp_path / "d")]) == 2
    assert capsys.readouterr().err == f"stereovision: error: {narrow[12:]}\n"


def test_ground_without_a_calibration_is_said_in_the_callers_words(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """run_batch(ground=True) on a pair with no calibration recorded "CliError: --ground needs
    --calib": the command line's option and an internal class of the CLI's in the Python API
    (the workers share the CLI's depth_outputs). run_batch says it in Python's words, a CLI run
    (words="cli") in the command line's, as `stereovision depth --ground` says it."""
    from stereovision.batch import run_batch

    root = tmp_path / "in"
    _tiny(root, data_dir, "a/left.png", "a/right.png")  # no calib.txt, no calib=
    api = (
        "ValueError: ground=True needs calib=... or a calib.txt beside the pair (the floor is "
        "found in metres)"
    )
    cli = "ValueError: --ground needs --calib (the floor is found in metres)"
    res = run_batch(root, tmp_path / "o1", workers=1, ground=True, progress=False)
    assert res.failed == ["a"]
    assert _summary(tmp_path / "o1")["pairs"]["a"]["error"] == api
    res = run_batch(root, tmp_path / "o2", workers=1, ground=True, progress=False, words="cli")
    assert _summary(tmp_path / "o2")["pairs"]["a"]["error"] == cli
    capsys.readouterr()
    argv = ["batch", str(root), "-o", str(tmp_path / "o3"), "--ground", "--workers", "1"]
    assert main(argv) == 1
    assert f"failed a: {cli}\n" in capsys.readouterr().err
    assert _summary(tmp_path / "o3")["pairs"]["a"]["error"] == cli


@pytest.mark.parametrize("words", ["page", "CLI", ""])
def test_run_batch_refuses_words_it_has_no_summary_for(tmp_path: Path, words: str) -> None:
    """words is "api" or "cli": another (the GUI's "page", a capital) is refused by name before
    anything is read or written, not met by advice_for after a pair's work."""
    from stereovision.batch import run_batch

    with pytest.raises(ValueError, match=rf"^words: expected 'api' or 'cli', got '{words}'$"):
        run_batch(tmp_path / "missing", tmp_path / "o", words=words)
    assert not (tmp_path / "o").exists()


def test_a_cli_runs_words_said_again_are_the_same() -> None:
    """stereovision batch logs a pair's error through advice_for again, after run_batch(words=
    "cli") has worded it: every entry's command-line words, and the range errors' numbers
    (a fraction too), come through a second swap unchanged."""
    from stereovision._validate import ADVICE, advice_for

    for key, said in ADVICE.items():
        cli = said["cli"].format(w=225, h=188, n=96)
        assert advice_for(cli, "cli") == cli, key
        assert advice_for(said["api"].format(w=225, h=188, n=96), "cli") == cli, key
    line = "disparity range 199.5 is not smaller than the image width 96: ... or give a "
    assert (
        advice_for(line + "max_disparity below 96.5", "cli") == line + "--max-disparity below 96.5"
    )


def test_the_checking_progress_says_a_plain_line_every_progress_seconds_while_reading(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A mutation audit: _Checking's clock was not asserted (a line at each pair, or none at
    exactly PROGRESS_SECONDS), nor that a stream that is no terminal gets no bar whatever
    CHECK_BAR_DELAY, nor that no line is said while no file is read again."""
    import stereovision.batch as batch

    clock = iter([0.0, 4.0, 10.0, 13.0, 21.0, 30.0, 40.0])  # t0, then one per pair
    monkeypatch.setattr(batch.time, "monotonic", lambda: next(clock))
    monkeypatch.setattr(batch, "PROGRESS_SECONDS", 10.0)
    monkeypatch.setattr(batch, "CHECK_BAR_DELAY", 0.0)
    err = io.StringIO()
    monkeypatch.setattr("sys.stderr", err)
    checking = batch._Checking(6, True)
    for i, _ in enumerate(checking.over([cast(Any, None)] * 6)):
        checking.reading = i >= 1  # the first pair's files not read again
    said = re.findall(r": (\d)/6 pairs, (\d+) s$", err.getvalue(), re.MULTILINE)
    # 1 (4 s): no file read yet; 2 (10 s) and 4 (21 s, 11 s after) said; 3 and 5 too soon;
    # 6: the last, the pairs' bar follows
    assert said == [("2", "10"), ("4", "21")], err.getvalue()
    assert "checking files" not in err.getvalue()
    clock = iter([0.0, 20.0, 40.0, 60.0])  # progress off (enabled False): nothing said
    quiet = batch._Checking(3, False)
    quiet.reading = True
    before = err.getvalue()
    assert list(quiet.over([cast(Any, None)] * 3)) == [None] * 3
    assert err.getvalue() == before


def test_a_float_tiff_pair_says_why_it_is_no_image(tmp_path: Path) -> None:
    """A float32 TIFF pair (a disparity or depth map given as images) failed in batch as
    "cannot decode left.tif as an image" alone, the words of a damaged file, where `depth`
    and imread say its pixels are float32 values; batch now says the same."""
    from stereovision.batch import _task, process_pair

    values = np.dstack([np.array([[0.5, 300.0], [2.0, 7.5]], np.float32)] * 3)
    for name in ("left.tif", "right.tif"):
        assert cv2.imwrite(str(tmp_path / name), values)
    (job,) = find_pairs(tmp_path)
    says = (
        r"^cannot decode .*left\.tif as an image: its pixels are float32 values, not 8- or "
        r"16-bit ones \(save it as an 8- or 16-bit PNG or TIFF\)$"
    )
    with pytest.raises(ValueError, match=says):
        process_pair(_task(job, {"method": "gabor", "max_disparity": 16, "fill": None}))


def test_workers_with_a_scheduler_is_refused_before_any_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``batch IN -o OUT --workers 8 --scheduler tcp://...`` ran on the cluster's own workers,
    --workers ignored without a word (run_batch ignores it with a scheduler); refused now in
    one line, exit 2, before the scheduler is asked or OUT made."""
    _noise_pair(tmp_path / "in" / "scene")
    out = tmp_path / "out"
    argv = ["batch", str(tmp_path / "in"), "-o", str(out), "--scheduler", "tcp://127.0.0.1:1"]
    assert main([*argv, "--workers", "8"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        "stereovision: error: --workers sizes the local cluster; --scheduler's workers are the "
        "cluster's own: give one of them\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]


def test_run_batch_refuses_workers_with_a_scheduler_before_any_work(tmp_path: Path) -> None:
    """run_batch(workers=2, scheduler=...) ran on the cluster's own workers, workers ignored
    without a word, where the CLI refuses the pair of options: refused alike, in the
    parameters' names, before the scheduler is asked or the output folder made."""
    from stereovision.batch import run_batch

    _noise_pair(tmp_path / "in" / "scene")
    says = (
        "^workers sizes the local cluster; scheduler's workers are the cluster's own: "
        "give one of them$"
    )
    with pytest.raises(ValueError, match=says):
        run_batch(tmp_path / "in", tmp_path / "out", workers=2, scheduler="tcp://127.0.0.1:1")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]


def _scan_tiny_images(tmp_path: Path, files: list[str]) -> tuple[list, list]:
    """Write an 8x8 image at each of ``files`` (relative to ``tmp_path``) and give back the
    pairs and unpaired images batch's scan finds there."""
    import stereovision.batch as batch

    img = np.zeros((8, 8, 3), np.uint8)
    for f in files:
        (tmp_path / f).parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(tmp_path / f), img)
    pairs, unpaired, _ = batch._scan(tmp_path)
    return pairs, unpaired


def test_camera_folders_pair_names_whose_camera_index_is_not_the_pairs_number(
    tmp_path: Path,
) -> None:
    """Camera folders of names carrying the camera's index last (OpenCV's pair01_cam0.png /
    pair01_cam1.png) paired nothing: batch read each name's last number, the camera index (0
    on every left, 1 on every right). Each side's names are now read as calibrate reads them
    (the last number that differs between them), the numbers after it not compared; those
    before it still are (cam0_pair01.png + cam1_pair01.png, KITTI's other frames: not
    paired). Images without a partner stay unpaired."""
    from stereovision.calibrate import _file_numbers

    files = [
        *("a/left/pair01_cam0.png", "a/left/pair02_cam0.png", "a/left/pair03_cam0.png"),
        *("a/right/pair01_cam1.png", "a/right/pair03_cam1.png", "a/right/pair04_cam1.png"),
        *("b/left/cam0_pair9.png", "b/left/cam0_pair10.png"),
        *("b/right/cam1_pair09.png", "b/right/cam1_pair10.png"),
        *("c/left/left_001_2026.png", "c/left/left_002_2026.png"),
        *("c/right/right_001_2026.png", "c/right/right_002_2026.png"),
        # one image on a side: nothing tells its numbers apart, the names pair as before
        *("d/left/seq_5_left_0001.png", "d/left/seq_5_left_0002.png"),
        *("d/right/seq_5_right_0001.png",),
        *("e/left/left_001_2026.png", "e/left/left_002_2026.png", "e/right/right_001_2026.png"),
        # the numbers before the pair's are compared: other KITTI frames, other cameras
        *("k/image_2/000000_10.png", "k/image_2/000000_11.png"),
        *("k/image_3/000001_10.png", "k/image_3/000001_11.png"),
    ]
    pairs, unpaired = _scan_tiny_images(tmp_path, files)
    assert [(j.left.name, j.right.name) for j in pairs] == [
        ("pair01_cam0.png", "pair01_cam1.png"),
        ("pair03_cam0.png", "pair03_cam1.png"),
        ("left_001_2026.png", "right_001_2026.png"),
        ("left_002_2026.png", "right_002_2026.png"),
        ("seq_5_left_0001.png", "seq_5_right_0001.png"),
        ("left_001_2026.png", "right_001_2026.png"),
    ]
    assert sorted(u.present.name for u in unpaired) == [
        "000000_10.png",
        "000000_11.png",
        "000001_10.png",
        "000001_11.png",
        "cam0_pair10.png",
        "cam0_pair9.png",
        "cam1_pair09.png",
        "cam1_pair10.png",
        "left_002_2026.png",
        "pair02_cam0.png",
        "pair04_cam1.png",
        "seq_5_left_0002.png",
    ]
    # one rule with calibrate: the numbers batch paired on are calibrate's
    lefts = ["pair01_cam0.png", "pair02_cam0.png", "pair03_cam0.png"]
    assert _file_numbers(lefts) == [1, 2, 3]


def test_camera_folders_do_not_pair_other_frames_by_a_number_after_the_pairs(
    tmp_path: Path,
) -> None:
    """74be79a left the numbers after the pair's out of the comparison, so a KITTI image_2
    holding only the _10 frames and an image_3 holding only the _11 ones paired 000000_10 with
    000000_11 (another frame), and left_001_2026 with right_001_2027; before it they were not
    paired. Only a number glued to a word (the camera's index in pair01_cam0.png) is now left
    out; a number on its own after the pair's (a frame, a year) is compared."""
    files = [
        *("k/image_2/000000_10.png", "k/image_2/000001_10.png"),
        *("k/image_3/000000_11.png", "k/image_3/000001_11.png"),
        *("y/left/left_001_2026.png", "y/left/left_002_2026.png"),
        *("y/right/right_001_2027.png", "y/right/right_002_2027.png"),
        *("c/left/pair01_cam0.png", "c/left/pair02_cam0.png"),
        *("c/right/pair01_cam1.png", "c/right/pair02_cam1.png"),
    ]
    pairs, unpaired = _scan_tiny_images(tmp_path, files)
    assert [(j.name, j.left.name, j.right.name) for j in pairs] == [
        ("c/pair01_cam0", "pair01_cam0.png", "pair01_cam1.png"),
        ("c/pair02_cam0", "pair02_cam0.png", "pair02_cam1.png"),
    ]
    assert sorted(u.present.name for u in unpaired) == [
        "000000_10.png",
        "000000_11.png",
        "000001_10.png",
        "000001_11.png",
        "left_001_2026.png",
        "left_002_2026.png",
        "right_001_2027.png",
        "right_002_2027.png",
    ]


def test_camera_folders_pair_a_side_of_one_image_at_the_other_sides_number(
    tmp_path: Path,
) -> None:
    """74be79a read each side's pair number where that side's names differ; a side holding one
    image (a camera folder with gaps) tells no place, its last number (the camera's index in
    pair01_cam1.png) was read and pair01_cam0.png + pair01_cam1.png was not paired. Such a side
    is now read at the other side's place; a side's names that tell one keep their own."""
    files = [
        *("a/left/pair01_cam0.png", "a/left/pair02_cam0.png", "a/right/pair02_cam1.png"),
        *("b/left/pair05_cam0.png", "b/right/pair05_cam1.png", "b/right/pair06_cam1.png"),
        # KITTI's frames still told apart: a lone _10 does not take the other side's _11
        *("k/image_2/000000_10.png", "k/image_3/000000_11.png", "k/image_3/000001_11.png"),
    ]
    pairs, unpaired = _scan_tiny_images(tmp_path, files)
    assert [(j.name, j.left.name, j.right.name) for j in pairs] == [
        ("a/pair02_cam0", "pair02_cam0.png", "pair02_cam1.png"),
        ("b/pair05_cam0", "pair05_cam0.png", "pair05_cam1.png"),
    ]
    assert sorted(u.present.name for u in unpaired) == [
        "000000_10.png",
        "000000_11.png",
        "000001_11.png",
        "pair01_cam0.png",
        "pair06_cam1.png",
    ]


@pytest.mark.parametrize(
    ("address", "says"),
    [
        ("bogus", "missing port number in address 'bogus'"),
        ("foo://a:1", "unknown address scheme 'foo'"),
        ("tcp://admin:s3cret@127.0.0.1:1", "invalid address 'admin:***@127.0.0.1:1'"),
        # Dask named a piece of these its own way, the password in it
        ("tcp://admin:s3cret@127.0.0.1", "invalid address 'admin:***@127.0.0.1': a sched"),
        ("tls://admin:s3cret@host", "invalid address 'admin:***@host': a scheduler's"),
        ("admin:s3cret@127.0.0.1:1", "invalid address 'admin:***@127.0.0.1:1': a sch"),
        ("tcp://127.0.0.1:1?token=s3cret", "invalid address '127.0.0.1:1?token=***'"),
    ],
)
def test_a_bad_scheduler_address_is_refused_when_every_pair_is_done(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    address: str,
    says: str,
    in_process_dask: None,
) -> None:
    """``--scheduler`` was only read by Dask once a pair was to be done: a rerun with every pair
    done took any value and exited 0. It is refused before any work now, as Dask says it."""
    pytest.importorskip("distributed")
    _noise_pair(tmp_path / "in" / "scene")
    out = tmp_path / "out"
    argv = ["batch", str(tmp_path / "in"), "-o", str(out)]
    assert main([*argv, "--workers", "1"]) == 0
    summary = (out / "summary.json").read_bytes()
    capsys.readouterr()
    assert main([*argv, "--scheduler", address]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"stereovision: error: --scheduler: {says}") and err.count("\n") == 1
    assert "s3cret" not in err
    assert (out / "summary.json").read_bytes() == summary


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_a_fifo_named_as_an_image_fails_its_pair_and_does_not_hang(
    data_dir: Path, tmp_path: Path
) -> None:
    root = tmp_path / "in"
    _crops(root, data_dir, ["left/0002.png"], ["right/0002.png"])
    shutil.copy(root / "right" / "0002.png", root / "right" / "0001.png")
    os.mkfifo(root / "left" / "0001.png")  # read_bytes waited for a writer: the run hung
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "stereovision",
            "batch",
            str(root),
            "-o",
            str(tmp_path / "out"),
            "--workers",
            "1",
        ],
        capture_output=True,
        text=True,
        check=False,
        timeout=240,
    )
    assert proc.returncode == 1, proc.stderr
    left = root / "left" / "0001.png"
    assert (
        f"failed 0001: ValueError: image file is not a regular file: {left} (a FIFO)\n"
        in proc.stderr
    )
    summary = json.loads((tmp_path / "out" / SUMMARY_NAME).read_text())
    assert summary["pairs"]["0001"]["status"] == "failed"
    assert summary["pairs"]["0002"]["status"] == "done"


def test_a_pair_name_with_a_newline_is_shown_escaped_when_it_fails(
    data_dir: Path, tmp_path: Path, in_process_dask: None
) -> None:
    root = tmp_path / "in"
    _crops(root, data_dir, ["left/0001.png"], ["right/0001.png"])
    (root / "s\nx").mkdir()
    (root / "s\nx" / "a_left.png").write_bytes(b"not an image")
    (root / "s\nx" / "a_right.png").write_bytes(b"not an image")
    lines: list[str] = []
    from stereovision.batch import run_batch

    run_batch(root, tmp_path / "out", workers=1, progress=False, log=lines.append)
    failed = [line for line in lines if line.startswith("failed")]
    assert len(failed) == 1 and "\n" not in failed[0]
    assert failed[0].startswith("failed s\\nx/a: ")
    assert "s\\nx/a_left.png" in failed[0], failed[0]


def test_a_pair_output_folder_with_a_newline_is_shown_escaped_when_it_fails(
    data_dir: Path, tmp_path: Path, in_process_dask: None
) -> None:
    """The pair's output folder (OUT/<name>/, its name from the images') was not among the
    paths its error line escapes (its images' and calib's alone, whose part is ``a\\nb.png``):
    a failure naming it was cut at the newline, ``failed a\\nb: NotADirectoryError: .../a``."""
    root = tmp_path / "in"
    _crops(root, data_dir, ["left/a\nb.png"], ["right/a\nb.png"])
    out = tmp_path / "out"
    out.mkdir()
    (out / "a\nb").write_text("a file where the pair's folder goes")
    lines: list[str] = []
    from stereovision.batch import run_batch

    run_batch(root, out, workers=1, progress=False, log=lines.append)
    failed = [line for line in lines if line.startswith("failed")]
    assert len(failed) == 1 and "\n" not in failed[0], failed
    assert failed[0].startswith("failed a\\nb: NotADirectoryError: "), failed[0]
    assert f"{out}/a\\nb is a file, where the pair's output folder" in failed[0], failed[0]


@pytest.mark.parametrize(("left", "right"), [("left.jpg", "right.jpg"), ("LEFT.PNG", "RIGHT.PNG")])
def test_a_scene_of_left_and_right_of_another_suffix_reads_its_calib(
    data_dir: Path, tmp_path: Path, left: str, right: str
) -> None:
    scene = tmp_path / "in" / "terrace"
    scene.mkdir(parents=True)
    src = data_dir / "eth3d" / "terrace"
    for name, side in ((left, "left"), (right, "right")):
        cv2.imwrite(str(scene / name), cv2.imread(str(src / f"{side}.png")))
    shutil.copy(src / "calib.txt", scene / "calib.txt")
    # its calib.txt was passed over: no depth came out, unsaid
    assert find_pairs(tmp_path / "in") == [
        PairJob("terrace", scene / left, scene / right, scene / "calib.txt")
    ]


@pytest.mark.parametrize("address", ["ucx://10.0.0.1:13337", "inproc://10.0.0.1/123/1"])
def test_a_scheduler_address_dask_reads_no_port_of_is_left_to_dask(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], address: str, in_process_dask: None
) -> None:
    """The check read every address as a host and a port, which the UCX and in-process
    transports' addresses have none of to Dask before it connects: a UCX scheduler was refused
    ("--scheduler: don't know how to extract host and port for address 'ucx://...'"), where
    Dask takes it. A rerun with every pair done exits 0 with it, as before the check."""
    pytest.importorskip("distributed")
    _noise_pair(tmp_path / "in" / "scene")
    out = tmp_path / "out"
    argv = ["batch", str(tmp_path / "in"), "-o", str(out)]
    assert main([*argv, "--workers", "1"]) == 0
    capsys.readouterr()
    assert main([*argv, "--scheduler", address]) == 0, capsys.readouterr().err


def test_a_jpg_scene_with_a_kitti_calib_without_its_size_is_sized_by_its_left_jpg(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], in_process_dask: None
) -> None:
    """A scene of left.jpg + right.jpg with a KITTI calib.txt lacking S_rect_02 failed its pair
    with "... pass image_size=(width, height)", Python advice a batch user cannot act on: the
    KITTI file was sized by a left.png or image_2.png beside it, not a left.jpg (a Q.dat is).
    It is sized by the scene's left.jpg now, as a Q.dat is."""
    scene = tmp_path / "in" / "s"
    scene.mkdir(parents=True)
    img = np.random.default_rng(0).integers(0, 255, (32, 48, 3), np.uint8)
    for side in ("left", "right"):
        cv2.imwrite(str(scene / f"{side}.jpg"), img)
    (scene / "calib.txt").write_text(
        "P2: 100 0 24 0 0 100 16 0 0 0 1 0\nP3: 100 0 24 -50 0 100 16 0 0 0 1 0\n"
    )
    out = tmp_path / "out"
    assert main(["batch", str(tmp_path / "in"), "-o", str(out), "--workers", "1"]) == 0
    assert capsys.readouterr().out.startswith("1 processed, 0 skipped (done before), 0 failed")
    assert _summary(out)["pairs"]["s"]["status"] == "done"
    assert Calibration.from_file(scene / "calib.txt").image_size == (48, 32)


def test_batch_entry_points_refuse_a_bytes_or_no_path_naming_the_argument(tmp_path: Path) -> None:
    """find_pairs and run_batch given a bytes folder or calibration name (or None) raised
    pathlib's "argument should be a str object or an os.PathLike object returning str, not
    <class 'bytes'>", naming no argument: they now say it as io's readers do, before any output
    folder is made."""
    from stereovision.batch import run_batch

    name = str(tmp_path / "in")
    out = tmp_path / "out"
    cases = [
        (lambda p: find_pairs(p), "root"),
        (lambda p: find_pairs(tmp_path, p), "calib"),
        (lambda p: run_batch(p, out), "input_dir"),
        (lambda p: run_batch(tmp_path, p), "output_dir"),
    ]
    for call, arg in cases:
        with pytest.raises(TypeError) as info:
            call(name.encode())
        assert str(info.value) == (
            f"{arg}: expected a str or os.PathLike file name, got the bytes {name!r}: decode "
            f"it first (os.fsdecode({arg}))"
        )
        if arg != "calib":  # calib=None is no calibration
            with pytest.raises(TypeError) as info:
                call(None)
            assert str(info.value) == (
                f"{arg}: expected a str or os.PathLike file name, got NoneType"
            )
    assert not list(tmp_path.iterdir())  # nothing made


def test_a_calib_link_to_nothing_names_its_target_as_depth_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """batch --calib gone.yaml, a link whose target moved, said 'calibration file not found:
    gone.yaml', the link unsaid (depth --calib names its target, db745a1): named now, in the
    API and the CLI alike."""
    from stereovision.cli import main

    (tmp_path / "in").mkdir()
    img = np.zeros((32, 48), np.uint8)
    for side in ("left", "right"):
        assert cv2.imwrite(str(tmp_path / "in" / f"{side}_0.png"), img)
    gone = tmp_path / "gone.yaml"
    gone.symlink_to("moved.yaml")
    said = f"calibration file not found: {gone} (a link to moved.yaml, which does not exist)"
    with pytest.raises(FileNotFoundError, match=f"^{re.escape(said)}$"):
        find_pairs(tmp_path / "in", gone)
    assert (
        main(["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out"), "--calib", str(gone)])
        == 2
    )
    assert capsys.readouterr().err == f"stereovision: error: {said}\n"
    assert not (tmp_path / "out").exists()


def test_a_pair_whose_workers_die_says_the_workers_memory_share(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A pair whose worker processes all died (Dask's KilledWorker: a LocalCluster's nanny stops
    a worker past 95 % of its memory limit, the machine's memory over the workers, one per core:
    2 GB each on 8 cores and 16 GB, where a 1920x1080 pair peaks at 2.2 GB) was recorded in
    Dask's words: 'Attempted to run task 'stereovision-5bf7...' on 4 different workers, but all
    those workers died ... Inspecting worker logs is often a good next step', logs batch
    silences. It says the workers' share and the remedy, in the caller's words. An in-process
    client (no cluster processes) whose pair raises what Dask raises then."""
    from types import SimpleNamespace

    from distributed import Client, KilledWorker

    from stereovision import batch

    def start(self: Any, scheduler: str | None, workers: int) -> None:
        self.client = Client(processes=False, n_workers=2, threads_per_worker=1,
                             dashboard_address=None, memory_limit="400MiB")  # fmt: skip
        self.desc = "in-process"

    def killed(task: dict[str, Any]) -> dict[str, Any]:
        raise KilledWorker("stereovision-x", SimpleNamespace(address="tcp://127.0.0.1:1"), 3)

    monkeypatch.setattr(batch._Dask, "start", start)
    monkeypatch.setattr(batch, "process_pair", killed)
    _noise_pair(tmp_path / "in" / "s")
    lines: list[str] = []
    res = batch.run_batch(tmp_path / "in", tmp_path / "out", progress=False, log=lines.append,
                          words="cli")  # fmt: skip
    assert res.failed == ["s"]
    error = (
        "KilledWorker: the worker processes computing it died on every try: out of memory? "
        "Each of the 2 workers is stopped past 95 % of its share of the memory, 0.39 GiB; "
        "fewer --workers give each more"
    )
    assert _summary(tmp_path / "out")["pairs"]["s"]["error"] == error
    assert lines == [f"failed s: {error}"]


def test_process_pair_warnings_stay_with_their_pair_across_threads(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A worker with two threads (``dask worker --nthreads 2``, in-process workers) computes two
    pairs at once: catch_warnings swapped process-wide state, so each warning given once both
    had started went to the pair started last. Each pair keeps its own; the process's warning
    state is restored after, and a later pair in the same thread still gets a warning from a
    line an earlier pair warned from."""
    from stereovision import batch

    both = threading.Barrier(2, timeout=5)

    def compute(task: dict[str, Any]) -> dict[str, Any]:
        for i in range(2):
            warnings.warn(f"{task['name']} {i}", UserWarning, stacklevel=2)
            if task.get("wait"):
                both.wait()
        return {}

    monkeypatch.setattr(batch, "_compute_pair", compute)
    shown = warnings.showwarning
    got: dict[str, list[str]] = {}

    def run(name: str) -> None:
        got[name] = batch.process_pair({"name": name, "wait": True})["warnings"]

    threads = [threading.Thread(target=run, args=(n,)) for n in ("a", "b")]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert got == {"a": ["a 0", "a 1"], "b": ["b 0", "b 1"]}
    assert warnings.showwarning is shown
    assert batch.process_pair({"name": "a"})["warnings"] == ["a 0", "a 1"]


def test_a_kitti_file_calibrates_the_grey_pairs_by_the_grey_cameras(tmp_path: Path) -> None:
    """A raw drive's (or an odometry sequence's) grey pairs, image_00/ + image_01/, were given
    the colour cameras' calibration of --calib calib_cam_to_cam.txt (P_rect_02/03, as the file
    reads by default): baseline 0.5327 m for 0.5372, every depth 0.8 % short. They are read by
    cameras 0 and 1 now; the colour pairs as before."""
    from stereovision import batch

    drive = tmp_path / "2011_09_26_drive_0001_sync"
    for cam in ("00", "01", "02", "03"):
        (drive / f"image_{cam}" / "data").mkdir(parents=True)
        cv2.imwrite(str(drive / f"image_{cam}" / "data" / "0.png"), np.zeros((4, 6), np.uint8))
    k = "7.2e+02 0 6.1e+02 {} 0 7.2e+02 1.7e+02 0 0 0 1 0"
    cal = drive / "calib_cam_to_cam.txt"
    cal.write_text(
        "".join(
            f"P_rect_0{c}: {k.format(tx)}\nS_rect_0{c}: 6 4\n"
            for c, tx in enumerate(("0", "-3.87e+02", "4.5e+01", "-3.4e+02"))
        )
    )
    got = {}
    for job in find_pairs(drive, calib=cal):
        name, data = batch._task(job, {}, {})["calib"]
        (tmp_path / name).write_bytes(data)
        got[job.name] = round(Calibration.from_file(tmp_path / name).baseline, 4)
    assert got == {"image_00/data/0": 0.5375, "image_02/data/0": 0.5347}


def test_find_pairs_takes_a_middlebury_scene_of_im0_and_im1(tmp_path: Path) -> None:
    """A folder of Middlebury 2014's / ETH3D's ``im0.png`` + ``im1.png`` was passed over without
    a word (a/left.png + a/right.png and b/im0.png + b/im1.png: 1 pair, b unsaid): it is a
    scene pair with its calib.txt; a folder holding both namings is one pair, left + right."""
    _blank(tmp_path, "a/left.png", "a/right.png", "b/im0.png", "b/im1.png",
           "c/left.png", "c/right.png", "c/im0.png", "c/im1.png")  # fmt: skip
    (tmp_path / "b" / "calib.txt").write_text("x")
    assert find_pairs(tmp_path) == [
        PairJob("a", tmp_path / "a/left.png", tmp_path / "a/right.png", None),
        PairJob("b", tmp_path / "b/im0.png", tmp_path / "b/im1.png", tmp_path / "b/calib.txt"),
        PairJob("c", tmp_path / "c/left.png", tmp_path / "c/right.png", None),
    ]
    assert [(j.name, j.left.name) for j in find_pairs(tmp_path / "b")] == [("b", "im0.png")]


def test_a_lone_im0_or_im1_is_reported_as_a_half_scene(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A Middlebury 2014 / ETH3D scene folder of im0.png without its im1.png was left out without
    a word (no pair, no 'unpaired image'), where a left.png alone is reported: it is now a half
    pair named as the scene, either way round; camera folders' im0.png are theirs as before."""
    from stereovision.batch import _scan

    _blank(tmp_path, "a/im0.png", "a/im1.png", "b/im0.png", "c/im1.png",
           "d/left/im0.png", "d/right/im0.png", "d/left/x/im0.png")  # fmt: skip
    jobs, unpaired, _ = _scan(tmp_path)
    assert [j.name for j in jobs] == ["a", "d/im0"]
    assert [(u.name, u.present, u.missing, u.side) for u in unpaired] == [
        ("b", tmp_path / "b/im0.png", tmp_path / "b/im1.png", "left"),
        ("c", tmp_path / "c/im1.png", tmp_path / "c/im0.png", "right"),
        ("d/x/im0", tmp_path / "d/left/x/im0.png", tmp_path / "d/right/x/im0.png", "left"),
    ]
    assert main(["batch", str(tmp_path / "b"), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(f"; 1 image(s) without the other of their pair, e.g. no im1.png beside "
                        f"{tmp_path / 'b/im0.png'}")  # fmt: skip


def test_batch_takes_method_fused_as_the_default_it_is(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--method fused`` after a run without ``--method`` (fused is the default) redid every
    pair ("method: default -> fused"): the method is now recorded by its name, and a summary's
    None (as batch recorded the default before) is read as it, so nothing done is redone."""
    from stereovision.batch import _fingerprint, _recorded

    root, out = tmp_path / "in", tmp_path / "out"
    _tiny(root, data_dir, "s/left.png", "s/right.png")
    (job,) = find_pairs(root)
    (out / "s").mkdir(parents=True)
    for f in DISPARITY_FILES:  # the done run's files
        (out / "s" / f).write_text("done")
    done = {"status": "done", "left": _recorded(job.left), "right": _recorded(job.right),
            "calib": None, "options": {"method": None, "max_disparity": 16, "fill": None},
            "fingerprint": _fingerprint(job), "outputs": sorted(DISPARITY_FILES)}  # fmt: skip
    summary = {"version": 3, "pairs": {"s": done}, "input": str(root.resolve()),
               "output": str(out.resolve())}  # fmt: skip
    (out / SUMMARY_NAME).write_text(json.dumps(summary))
    args = ["batch", str(root), "-o", str(out), "--workers", "1", "--max-disparity", "16"]
    for method in (["--method", "fused"], []):
        assert main([*args, *method]) == 0
        said = capsys.readouterr()
        assert said.out.startswith("0 processed, 1 skipped (done before), 0 failed in ")
        assert "other options" not in said.err
    assert (out / "s" / "disparity.pfm").read_text() == "done"  # not redone


def test_cli_batch_names_a_folder_with_a_newline_escaped_on_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """-o named with a newline: the last line, the missing outputs' line and the interrupted
    line each name it escaped on one line (they printed it as it is: cut in two). run_batch
    stands in: the point is the CLI's lines, not a cluster."""
    import stereovision.batch as batch_mod

    out = tmp_path / "o\nut"
    shown = str(out).replace("\n", "\\n")
    res = batch_mod.BatchResult(
        processed=["seq/0000"], skipped=[], failed=[], pending=[], seconds=0.5,
        summary_path=out / "summary.json", missing=["seq/0001"],
    )  # fmt: skip
    monkeypatch.setattr(batch_mod, "run_batch", lambda *a, **k: res)
    assert main(["batch", str(tmp_path), "-o", str(out)]) == 1
    said = capsys.readouterr().out.splitlines()
    assert said == [
        f"1 processed, 0 skipped (done before), 0 failed in 0.5 s; summary: {shown}/summary.json",
        f"exit status 1: 1 pair(s) recorded as done have no outputs in {shown} any more (moved "
        "or deleted during the run?); run again to redo them",
    ]

    def interrupted(*a: Any, **k: Any) -> None:
        raise batch_mod.BatchInterrupted(res)

    monkeypatch.setattr(batch_mod, "run_batch", interrupted)
    assert main(["batch", str(tmp_path), "-o", str(out)]) == 130
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: interrupted: 1 of 1 pairs finished this run, in {shown} and recorded "
        f"in {shown}/summary.json; run again to continue"
    ]

    def searching(*a: Any, **k: Any) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(batch_mod, "run_batch", searching)
    assert main(["batch", str(tmp_path), "-o", str(out)]) == 130
    assert capsys.readouterr().err.splitlines() == [
        f"stereovision: interrupted; finished pairs are kept in {shown}, run again to continue"
    ]


def test_a_middlebury_scene_with_a_q_dat_is_sized_by_its_im0(tmp_path: Path) -> None:
    """A scene of im0.png + im1.png (6ba651a4) with a Q.dat and no left.png failed its pair
    ('Q.dat does not give the image size and there is no left.png beside it'): its im0.png
    now sizes the Q.dat, as a left.png does."""
    from stereovision.batch import _task

    scene = tmp_path / "s"
    scene.mkdir()
    for name in ("im0.png", "im1.png"):
        cv2.imwrite(str(scene / name), np.zeros((30, 40), np.uint8))
    (scene / "Q.dat").write_text("1 0 0 -20\n0 1 0 -15\n0 0 0 100\n0 0 10 0\n")
    (job,) = find_pairs(scene)
    assert job.calib == scene / "Q.dat"
    name, data = _task(job, {})["calib"]
    (tmp_path / name).write_bytes(data)
    assert Calibration.from_file(tmp_path / name).image_size == (40, 30)


def test_an_input_link_whose_target_moved_names_it(tmp_path: Path) -> None:
    """``batch data -o out`` with data -> /mnt/usb/data (the disk unmounted) said "input
    folder not found: data", of a name ls lists, where the file readers name a link's target
    (b7feb4e7). Now named; a missing folder as before."""
    (tmp_path / "data").symlink_to(tmp_path / "moved" / "data")
    with pytest.raises(FileNotFoundError) as err:
        find_pairs(tmp_path / "data")
    assert str(err.value) == (
        f"input folder not found: {tmp_path / 'data'} (a link to {tmp_path / 'moved' / 'data'}, "
        "which does not exist)"
    )
    with pytest.raises(FileNotFoundError) as err:
        find_pairs(tmp_path / "none")
    assert str(err.value) == f"input folder not found: {tmp_path / 'none'}"
