"""A robot's path through the package: calibrate from chessboard pairs, depth on the raw pairs
through that calibration, the bag it records and the tools that read it back."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from stereovision.cli import main


def _chessboard_rig() -> object:
    """The rig `stereovision calibrate` finds on OpenCV's 13 chessboard pairs (`--square
    0.025`: stereo RMS 0.197 px), its figures rounded."""
    import cv2

    from stereovision import Calibration

    k1 = np.array([[533.79, 0.0, 342.17], [0.0, 533.78, 235.0], [0.0, 0.0, 1.0]])
    k2 = np.array([[537.03, 0.0, 327.14], [0.0, 536.6, 249.88], [0.0, 0.0, 1.0]])
    d1 = np.array([-0.28901, 0.09568, 0.0011, -0.00013, 0.0])
    d2 = np.array([-0.28925, 0.10495, -0.00054, 0.00024, 0.0])
    rot = cv2.Rodrigues(np.array([0.006627, 0.004007, -0.003493]))[0]
    return Calibration(k1, d1, k2, d2, rot, np.array([-0.08317, 0.000934, -0.000134]), (640, 480))


def test_a_rectified_chessboard_is_not_said_unrectified(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`depth raw_left raw_right --calib rig.yaml` on the calibration's own chessboard pairs
    warned on 9 of the 13 "the left and right images look unrectified ... give the calibration
    of the rig that took them (--calib ...)", a calibration given and applied: the automatic
    range's ORB matches, cross-checked only, pair a chessboard's corners with the wrong ones of
    its repeated squares. The rows check's SIFT matches (ratio-tested) put them within 0.3 px;
    the warning now waits for it to agree."""
    import cv2

    import stereovision as sv

    rig = _chessboard_rig()
    board = data_dir / "chessboard"
    for n in ("02", "05"):
        raw = cv2.imread(str(board / f"left{n}.jpg")), cv2.imread(str(board / f"right{n}.jpg"))
        left, right = rig.rectify(*raw)  # type: ignore[attr-defined]
        assert sv.check_rectification(left, right).ok is True
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            sv.estimate_max_disparity(left, right)
        assert [str(w.message) for w in seen if "unrectified" in str(w.message)] == [], n
    # the command line, as the walkthrough ran it: no warning
    rig.save(tmp_path / "rig.yaml")  # type: ignore[attr-defined]
    argv = ["depth", str(board / "left02.jpg"), str(board / "right02.jpg")]
    argv += ["--calib", str(tmp_path / "rig.yaml"), "--method", "gabor", "-o", str(tmp_path / "o")]
    assert main(argv) == 0
    assert "unrectified" not in capsys.readouterr().err
    # the same board with its right image 6 rows lower is still said to be unrectified
    left, right = rig.rectify(  # type: ignore[attr-defined]
        cv2.imread(str(board / "left02.jpg")), cv2.imread(str(board / "right02.jpg"))
    )
    lower = cv2.warpAffine(right, np.float32([[1, 0, 0], [0, 1, 6]]), right.shape[1::-1])
    with pytest.warns(UserWarning, match=r"look unrectified: \d+% of the feature matches"):
        sv.estimate_max_disparity(left, lower)


def test_info_lists_the_topics_of_a_bag_without_a_pair(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision info depth_run/` on the bag `stream --bag depth_run/` had written printed
    one error line ("no left/right pair among the bag's image topics ...") and nothing of what
    the bag holds, where `info BAG` is documented as "its topics, the stereo pair found". The
    topics are listed, then the reason (exit 2 as before)."""
    pytest.importorskip("rosbags")
    from importlib import resources

    import stereovision as sv
    from stereovision.io import load_scene
    from stereovision.rosbag import BagWriter

    sc = load_scene(Path(str(resources.files("stereovision") / "data" / "cones")))
    res = sv.depth_map(sc.left, sc.right, sc.calib, method="gabor", max_disparity=64)
    with BagWriter(tmp_path / "depth_run") as bag:
        bag.write(res, 1_700_000_000_000_000_000)
    assert main(["info", str(tmp_path / "depth_run")]) == 2
    out, err = capsys.readouterr()
    assert out.startswith(f"bag {tmp_path / 'depth_run'} (ROS 2, ")
    listed = [ln.split()[:2] for ln in out.splitlines()[1:]]
    assert ["/stereo/depth", "sensor_msgs/msg/Image"] in listed
    assert ["/stereo/points", "sensor_msgs/msg/PointCloud2"] in listed
    assert err.count("\n") == 1 and "no left/right pair among the bag's image topics" in err
    # a path that is no bag is still one line, nothing listed
    (tmp_path / "empty").mkdir()
    assert main(["info", str(tmp_path / "empty")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1


@pytest.mark.usefixtures("sift_once")  # both depth runs check the same rectified pair's rows
def test_rectify_with_a_calibration_writes_the_rectified_pair_s(
    data_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """`rectify raw_left raw_right --calib rig.yaml -o rect/` wrote the rectified pair and no
    calibration for it: `depth rect/left_rect.png rect/right_rect.png --calib rig.yaml`
    rectified it a second time (rows 11.5 px apart, a warning, wrong depths), and the rectified
    rig was only to be had in Python (`calib.rectified_calibration()`). It writes
    `calib_rect.yaml`, with which depth on the rectified pair is the raw pair's, bit for bit;
    a later run without --calib removes it with the rest of its run's files."""
    rig = _chessboard_rig()
    rig.save(tmp_path / "rig.yaml")  # type: ignore[attr-defined]
    board = data_dir / "chessboard"
    raw = [str(board / "left01.jpg"), str(board / "right01.jpg")]
    rect = tmp_path / "rect"
    assert main(["rectify", *raw, "--calib", str(tmp_path / "rig.yaml"), "-o", str(rect)]) == 0
    out = capsys.readouterr().out
    assert f"  calib_rect.yaml     {rect / 'calib_rect.yaml'}" in out
    assert f"--calib {rect / 'calib_rect.yaml'}" in out  # the next command, said
    opts = ["--method", "gabor", "--max-disparity", "96"]
    pair = [str(rect / "left_rect.png"), str(rect / "right_rect.png")]
    on_rect = [*pair, "--calib", str(rect / "calib_rect.yaml"), *opts, "-o", str(tmp_path / "a")]
    assert main(["depth", *on_rect]) == 0
    on_raw = [*raw, "--calib", str(tmp_path / "rig.yaml"), *opts, "-o", str(tmp_path / "b")]
    assert main(["depth", *on_raw]) == 0
    assert "warning" not in capsys.readouterr().err
    np.testing.assert_array_equal(np.load(tmp_path / "a" / "depth.npy"),
                                  np.load(tmp_path / "b" / "depth.npy"))  # fmt: skip
    # the pair rectified from its features instead: the calibration of the earlier run goes
    assert main(["rectify", *raw, "-o", str(rect)]) == 0
    assert "removed calib_rect.yaml of an earlier run" in capsys.readouterr().out
    assert not (rect / "calib_rect.yaml").exists() and (rect / "rectification.json").is_file()
