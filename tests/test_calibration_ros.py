"""ROS camera_info calibrations: reading a rig from left.yaml / right.yaml, writing them."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
import tarfile
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml

from stereovision.calibration import Calibration, _ros_yaml, parse_ros_camera_info
from tests.test_calibration import SIZE, raw_calib, rect_calib

STEREOPI = Path("stereopi_rig") / "reference_calib_result"


def _write_pair(folder: Path, cams: list[tuple[np.ndarray, ...]], size=(320, 240)) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for side, (K, D, R, P) in zip(("left", "right"), cams, strict=True):
        (folder / f"{side}.yaml").write_text(_ros_yaml(side, size, K, D, R, P, "plumb_bob"))
    return folder


def test_rig_from_a_third_partys_rectification(data_dir: Path, tmp_path: Path) -> None:
    """The StereoPi tutorial's own cv2.stereoRectify output (R1, R2, P1, P2 from its R, T, in
    cm) written as ROS camera_info gives back its R and T (in metres): R = R2^T R1 and
    T = R2^T (t2 - t1) invert what ROS's camera_calibration writes."""
    ref = data_dir / STEREOPI
    cams = []
    for side in ("left", "right"):
        P = np.load(ref / f"proj_mats_{side}.npy").copy()
        P[:, 3] *= 0.01  # cm -> m, the ROS unit
        cams.append(
            (
                np.load(ref / f"cam_mats_{side}.npy"),
                np.load(ref / f"dist_coefs_{side}.npy").ravel(),
                np.load(ref / f"rect_trans_{side}.npy"),
                P,
            )
        )
    c = Calibration.from_file(_write_pair(tmp_path / "ros", cams))
    assert c.unit == "m" and not c.rectified
    np.testing.assert_allclose(c.R, np.load(ref / "rot_mat.npy"), atol=1e-12)
    np.testing.assert_allclose(c.T, np.load(ref / "trans_vec.npy").ravel() * 0.01, atol=1e-12)
    assert c.baseline_m == pytest.approx(0.05396, abs=1e-5)
    np.testing.assert_array_equal(c.K1, cams[0][0])
    np.testing.assert_array_equal(c.D2, cams[1][1])


def test_round_trip_of_a_raw_rig(tmp_path: Path) -> None:
    c = dataclasses.replace(raw_calib(), unit="cm", T=np.array([-12.0, 0.2, 0.3]))
    left, right = c.save_ros(tmp_path / "new" / "rig")
    assert (left.name, right.name) == ("left.yaml", "right.yaml")
    doc = yaml.safe_load(right.read_text())
    assert doc["distortion_model"] == "plumb_bob" and doc["camera_name"] == "right"
    P2 = np.array(doc["projection_matrix"]["data"]).reshape(3, 4)
    # ROS's convention: P2[0, 3] = -f B with B in metres; the rotation is stereoRectify's R2
    assert P2[0, 3] == pytest.approx(-P2[0, 0] * c.baseline_m, rel=1e-12)
    r1, r2, p1, _, _ = c._stereo_rectify(0.0)
    np.testing.assert_array_equal(np.array(doc["rectification_matrix"]["data"]).reshape(3, 3), r2)
    back = Calibration.from_file(tmp_path / "new" / "rig")
    assert back.unit == "m" and not back.rectified and back.image_size == c.image_size
    for name in ("K1", "D1", "K2", "D2"):
        np.testing.assert_array_equal(getattr(back, name), getattr(c, name))
    np.testing.assert_allclose(back.R, c.R, atol=1e-14)
    np.testing.assert_allclose(back.T, c.T * 0.01, atol=1e-15)
    # the same rectification follows from it (rows and focal length to 1e-9 px)
    np.testing.assert_allclose(back._stereo_rectify(0.0)[0], r1, atol=1e-12)
    np.testing.assert_allclose(back._stereo_rectify(0.0)[2][:, :3], p1[:, :3], atol=1e-9)
    # one of the two files names the other; a tarball like ROS camera_calibration's works too
    np.testing.assert_array_equal(Calibration.from_file(right).T, back.T)
    np.testing.assert_array_equal(Calibration.from_file(left).R, back.R)
    tar = tmp_path / "calibrationdata.tar.gz"
    with tarfile.open(tar, "w:gz") as t:
        t.add(left, arcname="left.yaml")
        t.add(right, arcname="right.yaml")
    assert Calibration.from_file(tar) == back


def test_rectified_scene_to_ros_keeps_depth(data_dir: Path, tmp_path: Path) -> None:
    """An ETH3D calib.txt (Middlebury format, mm) and a rig with doffs 11.5 px, written as ROS
    camera_info and read back, are the same rectified rigs in metres; depth by image_geometry's
    formula from the files' numbers equals ours."""
    k2 = np.array([[500.0, 0.0, 171.5], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    for c in (
        Calibration.from_file(data_dir / "eth3d" / "terrace" / "calib.txt"),
        rect_calib(K2=k2, doffs=11.5),
    ):
        _check_rectified_round_trip(c, tmp_path)


def _check_rectified_round_trip(c: Calibration, tmp_path: Path) -> None:
    left, right = c.save_ros(tmp_path)
    back = Calibration.from_file(tmp_path)
    assert back.rectified and back.unit == "m"
    np.testing.assert_array_equal(back.K2, c.K2)
    assert back.baseline_m == pytest.approx(c.baseline_m, rel=1e-14)
    assert back.doffs_px == pytest.approx(c.doffs_px, abs=1e-12)
    disp = np.array([[10.0, 55.5, 120.25]])
    np.testing.assert_allclose(back.depth_from_disparity(disp), c.depth_from_disparity(disp))
    # image_geometry::StereoCameraModel: Tx = P2[0, 3] / fx (-B), Z = -Tx fx / (d - (cxl - cxr))
    pl = np.array(yaml.safe_load(left.read_text())["projection_matrix"]["data"]).reshape(3, 4)
    pr = np.array(yaml.safe_load(right.read_text())["projection_matrix"]["data"]).reshape(3, 4)
    fx, tx = pr[0, 0], pr[0, 3] / pr[0, 0]
    z_ros = -tx * fx / (disp - (pl[0, 2] - pr[0, 2]))
    np.testing.assert_allclose(c.depth_from_disparity(disp), z_ros, rtol=1e-6)


def test_kitti_and_rect_calib_round_trip(data_dir: Path, tmp_path: Path) -> None:
    for c in (
        Calibration.from_file(data_dir / "kitti2015" / "000005_10" / "calib.txt"),
        rect_calib(),
    ):
        c.save_ros(tmp_path)
        back = Calibration.from_ros(tmp_path / "left.yaml", tmp_path / "right.yaml")
        assert back.rectified
        assert back.focal_px == c.focal_px and back.baseline_m == pytest.approx(c.baseline_m)


def test_files_as_other_tools_write_them(tmp_path: Path) -> None:
    """OpenCV's FileStorage header and tags, the old 'distortion_coefficents' spelling, flat
    lists, 4 plumb_bob coefficients and rounded rectifying rotations all read."""
    c = raw_calib()
    r1, r2, p1, p2, _ = c._stereo_rectify(0.0)
    p2 = p2.copy()
    p2[:, 3] *= c.to_metres_factor

    def fmt(a: np.ndarray) -> str:
        return "[" + ", ".join(f"{v:.6f}" for v in np.ravel(a)) + "]"

    texts = []
    for side, K, D, R, P in (("left", c.K1, c.D1, r1, p1), ("right", c.K2, c.D2, r2, p2)):
        texts.append(
            "%YAML:1.0\n"
            f"image_width: 320\nimage_height: 240\ncamera_name: narrow_stereo/{side}\n"
            f"camera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: {fmt(K)}\n"
            "camera_model: plumb_bob\n"
            f"distortion_coefficents:\n  rows: 1\n  cols: 4\n  data: {fmt(D[:4])}\n"
            f"rectification_matrix: {fmt(R)}\n"
            f"projection_matrix:\n  rows: 3\n  cols: 4\n  data: {fmt(P)}\n"
        )
    (tmp_path / "cam_left.yml").write_text(texts[0])
    (tmp_path / "cam_right.yml").write_text(texts[1])
    back = Calibration.from_file(tmp_path / "cam_left.yml")
    assert back.D1.tolist() == pytest.approx([*c.D1[:4], 0.0], abs=1e-6)
    # six decimals in R1, R2 and P: the rig to about 1e-5
    np.testing.assert_allclose(back.R, c.R, atol=2e-5)
    np.testing.assert_allclose(back.T, c.T, atol=2e-5)
    info = parse_ros_camera_info(texts[1], "right")
    assert info["camera_name"] == "narrow_stereo/right" and info["image_size"] == (320, 240)


def _cam_text(**changes: object) -> str:
    doc: dict[str, object] = {
        "image_width": 320,
        "image_height": 240,
        "camera_matrix": {"rows": 3, "cols": 3, "data": [300, 0, 160, 0, 300, 120, 0, 0, 1]},
        "distortion_model": "plumb_bob",
        "distortion_coefficients": {"rows": 1, "cols": 5, "data": [0.0] * 5},
        "rectification_matrix": {"rows": 3, "cols": 3, "data": [1, 0, 0, 0, 1, 0, 0, 0, 1]},
        "projection_matrix": {
            "rows": 3,
            "cols": 4,
            "data": [300, 0, 160, -30.0, 0, 300, 120, 0, 0, 0, 1, 0],
        },
    }
    for key, value in changes.items():
        if value is None:
            doc.pop(key)
        else:
            doc[key] = value
    return yaml.safe_dump(doc)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"projection_matrix": None}, "lacks field 'projection_matrix'"),
        ({"distortion_model": "equidistant"}, "'equidistant' takes \\(4,\\) coefficients"),
        (
            {
                "distortion_model": "equidistant",
                "distortion_coefficients": {"rows": 1, "cols": 4, "data": [0.0] * 4},
            },
            "'plumb_bob', .* is 'equidistant'; a rig needs one lens model",
        ),
        ({"distortion_model": "kannala_brandt"}, "distortion_model 'kannala_brandt'"),
        ({"distortion_model": "rational_polynomial"}, "takes \\(8,\\) coefficients"),
        ({"camera_matrix": {"rows": 3, "cols": 3, "data": [1, 2]}}, "holds 2 numbers"),
        ({"camera_matrix": {"rows": 2, "cols": 3, "data": list(range(9))}}, "rows=2"),
        ({"camera_matrix": [1, 0, 0, 0, "x", 0, 0, 0, 1]}, "not a number"),
        ({"camera_matrix": [float("nan")] * 9}, "NaN"),
        ({"image_width": -3}, "image_width must be a positive integer"),
        ({"image_height": 0}, "image_height must be a positive integer"),
        ({"rectification_matrix": [2, 0, 0, 0, 1, 0, 0, 0, 1]}, "does not hold a rotation"),
        ({"rectification_matrix": [1, 0, 0, 0, 1, 0, 0, 0, -1]}, "does not hold a rotation"),
        ({"projection_matrix": [0] * 12}, "positive fx"),
        ({"projection_matrix": [300, 0, 160, -30, 0, 0, 120, 0, 0, 0, 1, 0]}, "positive fx, fy"),
    ],
)
def test_bad_camera_info_names_the_field(
    tmp_path: Path, changes: dict[str, object], message: str
) -> None:
    left = _cam_text(projection_matrix=[300, 0, 160, 0, 0, 300, 120, 0, 0, 0, 1, 0])
    (tmp_path / "left.yaml").write_text(left)
    (tmp_path / "right.yaml").write_text(_cam_text(**changes))
    with pytest.raises(ValueError, match=message):
        Calibration.from_file(tmp_path)


def test_pairs_that_are_not_a_rig(tmp_path: Path) -> None:
    mono = _cam_text(projection_matrix=[300, 0, 160, 0, 0, 300, 120, 0, 0, 0, 1, 0])
    (tmp_path / "left.yaml").write_text(mono)
    (tmp_path / "right.yaml").write_text(mono)
    with pytest.raises(ValueError, match="two monocular calibrations"):
        Calibration.from_file(tmp_path)
    (tmp_path / "right.yaml").write_text(_cam_text(image_width=640))
    with pytest.raises(ValueError, match="a rig needs one size"):
        Calibration.from_file(tmp_path)
    (tmp_path / "right.yaml").write_text("camera_matrix: [1, 2\n")
    with pytest.raises(ValueError, match=r"cannot parse .* line"):
        Calibration.from_file(tmp_path / "left.yaml")
    (tmp_path / "right.yaml").unlink()
    with pytest.raises(ValueError, match=r"partner .* is not beside it"):
        Calibration.from_file(tmp_path / "left.yaml")
    with pytest.raises(ValueError, match=r"holds left.yaml but not right.yaml \(ROS "):
        Calibration.from_file(tmp_path)
    tar = tmp_path / "calibrationdata.tar.gz"
    with tarfile.open(tar, "w:gz") as t:
        t.add(tmp_path / "left.yaml", arcname="left.yaml")
    with pytest.raises(ValueError, match=r"holds no right.yaml"):
        Calibration.from_file(tar)
    tar.write_bytes(b"not a tar archive")
    with pytest.raises(ValueError, match=r"cannot read .* as a tar archive"):
        Calibration.from_file(tar)
    with pytest.raises(FileNotFoundError):
        Calibration.from_ros(tmp_path / "left.yaml", tmp_path / "nowhere.yaml")


def test_writing_refuses_what_ros_cannot_hold(tmp_path: Path) -> None:
    d14 = np.zeros(14)
    d14[12] = 0.01  # a tilted sensor: no ROS model
    with pytest.raises(ValueError, match="D1: ROS camera_info has no model"):
        raw_calib(D1=d14).to_ros()
    d14[12] = 0.0
    d14[:8] = 0.01
    text = raw_calib(D1=d14).to_ros()[0]
    assert "rational_polynomial" in text
    assert len(parse_ros_camera_info(text)["D"]) == 8
    with pytest.raises(ValueError, match="alpha"):
        raw_calib().to_ros(alpha=1.5)
    for names in ("lr", ("left",), ("left", 3)):
        with pytest.raises(ValueError, match="names"):
            raw_calib().to_ros(names=names)  # type: ignore[arg-type]
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match="is a file, not a folder"):
        raw_calib().save_ros(tmp_path / "file")
    assert (tmp_path / "file").read_text() == "x"


def test_cli_calibrate_writes_ros_and_depth_reads_it(
    data_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`stereovision calibrate --ros DIR` on OpenCV's chessboard pairs writes camera_info that
    reads back as the calibration it saved, and `depth --calib DIR` uses it (both in-process;
    the refusal's exit code and one line are a subprocess's)."""
    from stereovision.cli import main

    board = data_dir / "chessboard"
    out = tmp_path / "rig.yaml"
    cmd = [sys.executable, "-m", "stereovision.cli", "calibrate"]
    args = ["--left", str(board / "left*.jpg"), "--right", str(board / "right*.jpg")]
    args += ["--square", "25", "--unit", "mm", "-o", str(out), "--ros", str(tmp_path / "ros")]
    code = main(["calibrate", *args])
    said = capsys.readouterr()
    assert code == 0, said.err
    assert "ROS camera_info written to" in said.out
    saved = Calibration.load(out)
    ros = Calibration.from_file(tmp_path / "ros")
    np.testing.assert_allclose(ros.R, saved.R, atol=1e-12)
    np.testing.assert_allclose(ros.T, saved.T * 1e-3, atol=1e-15)
    np.testing.assert_array_equal(ros.K1, saved.K1)
    left = cv2.imread(str(board / "left01.jpg"))
    right = cv2.imread(str(board / "right01.jpg"))
    cv2.imwrite(str(tmp_path / "l.png"), left)
    cv2.imwrite(str(tmp_path / "r.png"), right)
    code = main(
        [
            "depth",
            *(str(tmp_path / "l.png"), str(tmp_path / "r.png")),
            *("--calib", str(tmp_path / "ros"), "--method", "gabor", "-o", str(tmp_path / "out")),
        ]
    )
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "out" / "cloud.ply").is_file()
    run = subprocess.run(cmd + args[:-1] + [str(out)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and run.stderr.count("\n") == 1
    assert "--ros" in run.stderr and "is a file" in run.stderr


# ------------------------------------------------------------------------------ Kalibr


def _camchain(cams: list[dict]) -> str:
    """A camchain.yaml as Kalibr writes it (block lists for T_cn_cnm1, flow lists elsewhere)."""
    out = []
    for n, cam in enumerate(cams):
        out.append(f"cam{n}:")
        if "T" in cam:
            out.append("  T_cn_cnm1:")
            out += [f"  - [{', '.join(repr(float(v)) for v in row)}]" for row in cam["T"]]
        out.append(f"  cam_overlaps: [{1 - n if len(cams) == 2 else 0}]")
        out.append(f"  camera_model: {cam.get('model', 'pinhole')}")
        d = ", ".join(repr(float(v)) for v in cam["D"][:4])
        out.append(f"  distortion_coeffs: [{d}]")
        out.append(f"  distortion_model: {cam.get('dist', 'radtan')}")
        k = cam["K"]
        fu, fv, pu, pv = (float(k[i, j]) for i, j in ((0, 0), (1, 1), (0, 2), (1, 2)))
        out.append(f"  intrinsics: [{fu!r}, {fv!r}, {pu!r}, {pv!r}]")
        out.append(f"  resolution: [{cam['size'][0]}, {cam['size'][1]}]")
        out.append(f"  rostopic: /cam{n}/image_raw")
    return "\n".join(out) + "\n"


def _pose(rot: np.ndarray, t: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = rot, t
    return m


def test_kalibr_camchain(tmp_path: Path) -> None:
    """cam1's T_cn_cnm1 (X_cam1 = T X_cam0) is the rig's R, T; radtan is OpenCV's k1 k2 p1 p2;
    a third camera's pose chains through cam1."""
    c = raw_calib(D1=np.array([-0.12, 0.05, 0.001, -0.0005, 0.0]))
    turn = cv2.Rodrigues(np.array([0.0, 0.02, 0.01]))[0]
    cams = [
        {"K": c.K1, "D": c.D1, "size": c.image_size},
        {"K": c.K2, "D": c.D2, "size": c.image_size, "T": _pose(c.R, c.T)},
        {"K": c.K2, "D": c.D2, "size": c.image_size, "T": _pose(turn, np.array([-0.1, 0, 0]))},
    ]
    path = tmp_path / "camchain.yaml"
    path.write_text(_camchain(cams))
    rig = Calibration.from_file(path)
    assert rig.unit == "m" and rig.image_size == c.image_size and not rig.rectified
    for name in ("K1", "D1", "K2", "D2"):
        np.testing.assert_array_equal(getattr(rig, name), getattr(c, name))
    np.testing.assert_allclose(rig.R, c.R, atol=1e-15)
    np.testing.assert_allclose(rig.T, c.T, atol=1e-15)
    far = Calibration.from_kalibr(path, cameras=("cam0", "cam2"))
    np.testing.assert_allclose(far.R, turn @ c.R, atol=1e-12)
    np.testing.assert_allclose(far.T, turn @ c.T + [-0.1, 0, 0], atol=1e-12)
    # printed to 6 decimals, as some tools do: snapped to a rotation
    rounded = tmp_path / "rounded.yaml"
    rounded.write_text(
        _camchain(
            [cams[0], {**cams[1], "T": np.round(_pose(c.R, c.T), 6)}],
        )
    )
    np.testing.assert_allclose(Calibration.from_file(rounded).R, c.R, atol=2e-6)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"dist": "equidistant"}, "use different distortion models; a rig needs one"),
        ({"dist": "double_sphere"}, "expected 'radtan', 'equidistant' or 'none'"),
        ({"model": "omni"}, "only 'pinhole'"),
        ({"size": (640, 480)}, "a rig needs one size"),
        ({"size": (320.5, 240)}, "resolution must be two positive integers"),
        ({"T": np.zeros((4, 4))}, "last row"),
        ({"T": _pose(2 * np.eye(3), np.zeros(3))}, "does not hold a rotation"),
    ],
)
def test_kalibr_errors_name_the_problem(tmp_path: Path, change: dict, message: str) -> None:
    c = raw_calib()
    cam1 = {"K": c.K2, "D": c.D2, "size": c.image_size, "T": _pose(c.R, c.T), **change}
    path = tmp_path / "camchain.yaml"
    path.write_text(_camchain([{"K": c.K1, "D": c.D1, "size": c.image_size}, cam1]))
    with pytest.raises(ValueError, match=message):
        Calibration.from_file(path)


def test_kalibr_camera_choice_errors(tmp_path: Path) -> None:
    c = raw_calib()
    path = tmp_path / "camchain.yaml"
    cams = [{"K": c.K1, "D": c.D1, "size": c.image_size}]
    path.write_text(_camchain([*cams, {**cams[0], "T": _pose(c.R, c.T)}]))
    with pytest.raises(ValueError, match="no camera 'cam5'"):
        Calibration.from_kalibr(path, cameras=("cam0", "cam5"))
    with pytest.raises(ValueError, match="must come after"):
        Calibration.from_kalibr(path, cameras=("cam1", "cam0"))
    with pytest.raises(ValueError, match="'cam0' must come after 'cam0'"):
        Calibration.from_kalibr(path, cameras=("cam0", "cam0"))  # not a zero baseline
    # "cam0" and ("cam0",) were "too many (not enough) values to unpack", None a TypeError
    for cameras, shown in (("cam0", "'cam0'"), (("cam0",), r"\('cam0',\)"), (None, "None")):
        with pytest.raises(
            ValueError,
            match=rf"^cameras: expected the left and right camera's keys, \('cam0', 'cam1'\), "
            rf"got {shown}$",
        ):
            Calibration.from_kalibr(path, cameras=cameras)  # type: ignore[arg-type]
    path.write_text(_camchain([*cams, {**cams[0]}]))  # cam1 without its pose
    with pytest.raises(ValueError, match="lacks field 'T_cn_cnm1'"):
        Calibration.from_file(path)


def test_kalibr_chain_with_a_camera_cut_out_is_refused(tmp_path: Path) -> None:
    """cam1 deleted from a three-camera camchain: cam2's T_cn_cnm1 (its pose from cam1) was
    taken as its pose from cam0, a rig of silently wrong R and T."""
    c = raw_calib()
    cams = [{"K": c.K1, "D": c.D1, "size": c.image_size}]
    text = _camchain([*cams, {**cams[0], "T": _pose(c.R, c.T)}]).replace("cam1:", "cam2:")
    path = tmp_path / "camchain.yaml"
    path.write_text(text)
    with pytest.raises(
        ValueError,
        match=r"camchain\.yaml: no cam1 between 'cam0' and 'cam2'; the T_cn_cnm1 of 'cam2' "
        r"is its pose from cam1: keep every camera between$",
    ):
        Calibration.from_kalibr(path, cameras=("cam0", "cam2"))


def test_a_four_coefficient_pinhole_rig_is_written_as_five_plumb_bob_ones() -> None:
    """ROS's plumb_bob model has five coefficients (k1 k2 p1 p2 k3): a rig calibrated with four
    is written with k3 = 0 (a mutation audit found the padding unchecked). Parsed back with
    yaml.safe_load."""
    c = raw_calib(D1=np.array([-0.12, 0.05, 0.001, -0.0005]), D2=np.array([-0.1, 0.03, 0.0, 0.0]))
    for text, d in zip(c.to_ros(), (c.D1, c.D2), strict=True):
        doc = yaml.safe_load(text)
        assert doc["distortion_model"] == "plumb_bob"
        assert doc["distortion_coefficients"]["cols"] == 5
        assert doc["distortion_coefficients"]["data"] == [*d[:4].tolist(), 0.0]


def test_the_old_camera_model_spelling_names_the_distortion_model() -> None:
    """Older camera_info files say camera_model where ROS now writes distortion_model; its
    value is the model (dropped, 8 rational_polynomial coefficients were refused as plumb_bob)."""
    text = _cam_text(
        distortion_model=None,
        camera_model="rational_polynomial",
        distortion_coefficients={"rows": 1, "cols": 8, "data": [0.1, 0.01, 0, 0, 0, 0.2, 0, 0]},
    )
    info = parse_ros_camera_info(text, "cam")
    assert info["distortion_model"] == "rational_polynomial"
    assert info["D"].tolist() == [0.1, 0.01, 0, 0, 0, 0.2, 0, 0]


@pytest.mark.parametrize("failing", ["left.yaml", "right.yaml"])
def test_a_failed_save_ros_keeps_the_earlier_pair(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, failing: str
) -> None:
    """left.yaml was replaced before right.yaml was written: a failure at right.yaml (disk
    full) left the new left camera beside the old right one, a pair that loads as a rig neither
    calibration is. Written both first, a failure at the second replacement (left.yaml there)
    still did. The pair is written all or nothing."""
    earlier = [p.read_bytes() for p in rect_calib().save_ros(tmp_path)]
    import stereovision.io as sio

    real_replace = sio.os.replace

    def replace(src: str, dst: object) -> None:
        if Path(str(dst)).name == failing:
            raise OSError(28, "No space left on device")
        real_replace(src, dst)

    monkeypatch.setattr(sio.os, "replace", replace)
    with pytest.raises(OSError, match="No space left"):
        raw_calib().save_ros(tmp_path)
    monkeypatch.undo()
    assert [(tmp_path / n).read_bytes() for n in ("left.yaml", "right.yaml")] == earlier
    assert sorted(p.name for p in tmp_path.iterdir()) == ["left.yaml", "right.yaml"]


def test_an_empty_distortion_list_is_no_distortion(tmp_path: Path) -> None:
    """ROS's camera_calibration_parsers write an empty D as rows: 1, cols: 0, data: [] (a
    camera calibrated without distortion): it was refused as "says rows=1, cols=0 but holds 0
    numbers"; it is five zeros (plumb_bob)."""
    empty = {"rows": 1, "cols": 0, "data": []}
    proj = [300, 0, 160, -30.0, 0, 300, 120, 0, 0, 0, 1, 0]
    (tmp_path / "left.yaml").write_text(
        _cam_text(distortion_coefficients=empty, projection_matrix=[*proj[:3], 0.0, *proj[4:]])
    )
    (tmp_path / "right.yaml").write_text(_cam_text(distortion_coefficients=empty))
    c = Calibration.from_file(tmp_path)
    assert c.D1.tolist() == [0.0] * 5 and c.D2.tolist() == [0.0] * 5
    assert c.rectified and c.baseline_m == pytest.approx(0.1)


@pytest.mark.parametrize(("a", "b"), [("Left", "Right"), ("LEFT", "RIGHT")])
def test_one_file_names_its_partner_in_any_case(tmp_path: Path, a: str, b: str) -> None:
    """cam_Left.yaml names cam_Right.yaml (and LEFT names RIGHT): either file gives the rig."""
    c = raw_calib()
    left, right = c.save_ros(tmp_path / "ros")
    (tmp_path / f"cam_{a}.yaml").write_bytes(left.read_bytes())
    (tmp_path / f"cam_{b}.yaml").write_bytes(right.read_bytes())
    rig = Calibration.from_file(tmp_path / "ros")
    assert Calibration.from_file(tmp_path / f"cam_{b}.yaml") == rig
    assert Calibration.from_file(tmp_path / f"cam_{a}.yaml") == rig


def test_a_ros_pair_or_camchain_the_constructor_refuses_is_named(tmp_path: Path) -> None:
    """A camera matrix with a negative focal length passes each file's parser and was refused
    by the constructor as "K1: focal lengths must be positive", naming none of the files."""
    k = [300, 0, 160, 0, -300, 120, 0, 0, 1]
    (tmp_path / "left.yaml").write_text(
        _cam_text(
            camera_matrix=k,
            distortion_coefficients=[0.1, 0, 0, 0, 0],
            projection_matrix=[300, 0, 160, 0, 0, 300, 120, 0, 0, 0, 1, 0],
        )
    )
    (tmp_path / "right.yaml").write_text(_cam_text())
    with pytest.raises(
        ValueError, match=r"^ROS camera_info .*left\.yaml and .*right\.yaml: K1: focal lengths"
    ):
        Calibration.from_file(tmp_path)
    c = raw_calib()
    cams = [
        {"K": np.diag([300.0, -300.0, 1.0]), "D": c.D1, "size": c.image_size},
        {"K": c.K2, "D": c.D2, "size": c.image_size, "T": _pose(c.R, c.T)},
    ]
    (tmp_path / "camchain.yaml").write_text(_camchain(cams))
    with pytest.raises(ValueError, match=r"^.*camchain\.yaml: K1: focal lengths must be positive"):
        Calibration.from_file(tmp_path / "camchain.yaml")


def test_a_thin_prism_term_is_refused_by_to_ros() -> None:
    """ROS has no model for OpenCV's thin-prism terms s1..s4 (coefficients 9-12) either, not
    only for the tilt (13-14): a 12-term D with s1 set is refused, not written without it."""
    d12 = np.zeros(12)
    d12[:5] = [-0.1, 0.01, 0.0, 0.0, 0.0]
    d12[8] = 0.002  # s1
    with pytest.raises(ValueError, match=r"D2: .*thin-prism .*coefficients 9-12 are not zero"):
        raw_calib(D2=d12).to_ros()


def test_a_common_tilt_of_both_cameras_is_not_a_rectified_pair(tmp_path: Path) -> None:
    """No distortion and K = P[:, :3] but both rectification_matrix a 2 degree tilt: the
    images are not rectified yet (ROS warps them by R_i), so the rig is not read as rectified
    even though R = R2^T R1 = I and T is along x."""
    tilt = cv2.Rodrigues(np.array([np.radians(2.0), 0.0, 0.0]))[0]
    k = np.array([[300.0, 0.0, 160.0], [0.0, 300.0, 120.0], [0.0, 0.0, 1.0]])
    p1 = np.hstack([k, np.zeros((3, 1))])
    p2 = np.hstack([k, (k @ [-0.1, 0.0, 0.0]).reshape(3, 1)])
    _write_pair(tmp_path, [(k, np.zeros(5), tilt, p1), (k, np.zeros(5), tilt, p2)])
    c = Calibration.from_file(tmp_path)
    assert not c.rectified
    np.testing.assert_allclose(c.R, np.eye(3), atol=1e-15)
    np.testing.assert_allclose(c.T, [-0.1, 0.0, 0.0], atol=1e-15)


def test_save_ros_writes_the_alpha_given(tmp_path: Path) -> None:
    """save_ros(alpha=1) writes to_ros(alpha=1)'s projections (all pixels kept), not alpha 0's."""
    c = raw_calib()
    left, right = c.save_ros(tmp_path, alpha=1.0)
    assert (left.read_text(), right.read_text()) == c.to_ros(alpha=1.0)
    assert left.read_text() != c.to_ros(alpha=0.0)[0]


@pytest.mark.parametrize("name", ["calib.tgz", "calib.tar", "CALIB.TAR.GZ"])
def test_a_ros_tarball_is_read_by_any_of_its_names(tmp_path: Path, name: str) -> None:
    """ROS camera_calibration's tarball renamed .tgz or uncompressed .tar reads the same rig."""
    c = raw_calib()
    left, right = c.save_ros(tmp_path / "ros")
    with tarfile.open(tmp_path / name, "w:gz" if "gz" in name.lower() else "w") as t:
        t.add(left, arcname="left.yaml")
        t.add(right, arcname="right.yaml")
    assert Calibration.from_file(tmp_path / name) == Calibration.from_file(tmp_path / "ros")


def test_an_integral_float_size_is_taken_and_a_fractional_one_refused(tmp_path: Path) -> None:
    """``image_width: 320.0`` (a camera_info written by a tool that dumps floats) was refused as
    'must be a positive integer, got 320.0', though the native YAML loader takes it: a whole
    number of pixels is taken as an int; 320.5, inf and NaN are refused naming the field."""
    info = parse_ros_camera_info(_cam_text(image_width=320.0, image_height=240.0), "cam")
    assert info["image_size"] == (320, 240)
    assert all(type(v) is int for v in info["image_size"])
    for bad in (320.5, float("inf"), float("nan"), -320.0):
        with pytest.raises(ValueError, match=r"^cam: image_width must be a positive integer"):
            parse_ros_camera_info(_cam_text(image_width=bad), "cam")


def test_save_ros_refuses_right_yaml_linked_to_left_yaml(tmp_path: Path) -> None:
    """right.yaml -> left.yaml: written through the link, the right camera replaced the left
    one (a rig of one camera, said nowhere). Refused, the earlier file kept."""
    (tmp_path / "left.yaml").write_text("old")
    (tmp_path / "right.yaml").symlink_to("left.yaml")
    with pytest.raises(ValueError) as info:
        raw_calib().save_ros(tmp_path)
    assert str(info.value) == (
        f"cannot write {tmp_path / 'left.yaml'} and {tmp_path / 'right.yaml'} together: they "
        "are one file (the second would replace the first)"
    )
    assert (tmp_path / "left.yaml").read_text() == "old"
    assert sorted(os.listdir(tmp_path)) == ["left.yaml", "right.yaml"]


def _ros_pair(t: tuple[float, float, float], p22: float = 1.0) -> tuple[str, str]:
    k = np.array([[400.0, 0.0, 159.5], [0.0, 400.0, 119.5], [0.0, 0.0, 1.0]])
    p1 = np.hstack([k, np.zeros((3, 1))])
    p2 = np.hstack([k, (k @ np.array(t)).reshape(3, 1)])
    p1[2, 2] = p2[2, 2] = p22
    d, r = np.zeros(5), np.eye(3)
    return (
        _ros_yaml("left", (320, 240), k, d, r, p1, "plumb_bob"),
        _ros_yaml("right", (320, 240), k, d, r, p2, "plumb_bob"),
    )


def test_a_ros_pair_that_looks_rectified_but_is_vertical_is_a_raw_rig() -> None:
    """Identity rectification, no distortion, K = P[:, :3], but the baseline vertical: not a
    rectified pair (T is not (-B, 0, 0)), read as the raw rig that stereoRectify handles."""
    left, right = _ros_pair((0.0, -0.1, 0.0))
    c = Calibration._from_ros_texts(left, right, "left.yaml", "right.yaml")
    assert c.rectified is False
    np.testing.assert_allclose(c.T, [0.0, -0.1, 0.0], atol=1e-12)


def test_a_ros_projection_with_p22_zero_is_refused_by_name() -> None:
    """P[2, 2] = 0 made P[:, :3] singular: a bare LinAlgError, not the file's refusal."""
    left, right = _ros_pair((-0.1, 0.0, 0.0), p22=0.0)
    with pytest.raises(ValueError, match=r"^left\.yaml: projection_matrix needs positive fx"):
        Calibration._from_ros_texts(left, right, "left.yaml", "right.yaml")


def _kalibr_pair(tmp_path: Path, cam0: str, cam1: str) -> Path:
    """A camchain.yaml of two cameras given as YAML bodies (indented by the caller)."""
    path = tmp_path / "camchain.yaml"
    path.write_text(f"cam0:\n{cam0}cam1:\n{cam1}")
    return path


_KALIBR_CAM = (
    "  intrinsics: [500.0, 510.0, 320.0, 240.0]\n"
    "  distortion_coeffs: [-0.1, 0.02, 0.001, -0.002]\n"
    "  resolution: [640, 480]\n"
)
_KALIBR_POSE = "  T_cn_cnm1: [[1, 0, 0, -0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n"


def test_kalibr_defaults_pinhole_radtan_and_ignores_other_keys(tmp_path: Path) -> None:
    """A camera without camera_model or distortion_model is Kalibr's default pinhole-radtan
    (its four coefficients read as OpenCV's k1 k2 p1 p2); keys other than camN (a mutation
    audit found a loose ``cam`` prefix match and the defaults unasserted) are ignored."""
    path = _kalibr_pair(tmp_path, _KALIBR_CAM, _KALIBR_CAM + _KALIBR_POSE)
    path.write_text(path.read_text() + "cam0_notes: bench rig\ncamera_count: 2\n")
    rig = Calibration.from_kalibr(path)
    assert rig.model == "pinhole" and rig.image_size == (640, 480) and rig.unit == "m"
    np.testing.assert_array_equal(rig.D1, [-0.1, 0.02, 0.001, -0.002, 0.0])
    np.testing.assert_array_equal(rig.K2, [[500.0, 0, 320.0], [0, 510.0, 240.0], [0, 0, 1]])
    np.testing.assert_array_equal(rig.T, [-0.1, 0.0, 0.0])


def test_kalibr_camchain_ending_in_a_document_marker_is_read(tmp_path: Path) -> None:
    """A camchain ending in "---" (a second, empty document) was "cannot parse ... as Kalibr
    YAML: expected a single document in the stream"; its first document is read, as the plain
    YAML (a712fb3d) and ROS readers read theirs."""
    path = _kalibr_pair(tmp_path, _KALIBR_CAM, _KALIBR_CAM + _KALIBR_POSE)
    path.write_text(path.read_text() + "---\n")
    for read in (Calibration.from_kalibr, Calibration.from_file):
        np.testing.assert_array_equal(read(path).T, [-0.1, 0.0, 0.0])


def test_kalibr_camera_that_holds_itself_is_refused(tmp_path: Path) -> None:
    """A recursive alias in a camchain (T_cn_cnm1: &a [*a, *a]) hung from_kalibr (NumPy's cast
    of the list holding itself), as the plain YAML reader did before 15f74bf2."""
    path = _kalibr_pair(tmp_path, _KALIBR_CAM, _KALIBR_CAM + "  T_cn_cnm1: &a [*a, *a]\n")
    with pytest.raises(ValueError) as exc:
        Calibration.from_kalibr(path)
    assert str(exc.value) == (
        f"{path}:cam1: T_cn_cnm1 holds itself (a YAML alias inside its own anchor, "
        "'T_cn_cnm1: &a [*a]'): write its numbers out"
    )


def test_kalibr_cameras_are_ordered_by_number_not_text(tmp_path: Path) -> None:
    """cam10 comes after cam9 in the chain (a text sort put it first and refused the pair)."""
    path = tmp_path / "camchain.yaml"
    path.write_text(f"cam9:\n{_KALIBR_CAM}cam10:\n{_KALIBR_CAM}{_KALIBR_POSE}")
    rig = Calibration.from_kalibr(path, cameras=("cam9", "cam10"))
    np.testing.assert_array_equal(rig.T, [-0.1, 0.0, 0.0])


@pytest.mark.parametrize(
    ("cam1", "message"),
    [
        ("  5\n", "cam1: expected a camera mapping"),
        (_KALIBR_CAM.replace("  resolution: [640, 480]\n", ""), "lacks field 'resolution'"),
        (_KALIBR_CAM.replace("[640, 480]", "[0, 480]"), "two positive integers"),
        (_KALIBR_CAM.replace("500.0, ", ".nan, "), "intrinsics needs 4 finite numbers"),
        (_KALIBR_CAM.replace("240.0]", "240.0, 1.0]"), "intrinsics needs 4 finite numbers"),
        (_KALIBR_CAM.replace("500.0", "abc"), "intrinsics is not a list of numbers"),
        (_KALIBR_CAM + "  distortion_model: fov\n", "expected 'radtan', 'equidistant'"),
        (
            _KALIBR_CAM + _KALIBR_POSE.replace("0, 0, 1]]", "0, 0, 1.0001]]"),
            "last row must be",
        ),
    ],
)
def test_kalibr_bad_camera_fields_are_named(tmp_path: Path, cam1: str, message: str) -> None:
    """Each malformed field is a ValueError naming it (a mutation audit found these checks
    unasserted: non-finite or too many numbers, a zero size, a non-mapping camera, fov)."""
    path = _kalibr_pair(tmp_path, _KALIBR_CAM, cam1 if "T_cn" in cam1 else cam1 + _KALIBR_POSE)
    if cam1 == "  5\n":
        path.write_text(f"cam0:\n{_KALIBR_CAM}cam1: 5\n")
    with pytest.raises(ValueError, match=message):
        Calibration.from_kalibr(path)


def test_kalibr_unreadable_documents_are_named(tmp_path: Path) -> None:
    """Broken YAML, a list instead of the mapping, and a skipped-over camera that is not a
    mapping are ValueErrors naming the problem (they leaked yaml/Type errors on mutants)."""
    path = tmp_path / "camchain.yaml"
    path.write_text("cam0: [unclosed\n")
    with pytest.raises(ValueError, match=r"cannot parse .* as Kalibr YAML"):
        Calibration.from_kalibr(path)
    path.write_text("- cam0\n- cam1\n")
    with pytest.raises(ValueError, match="expected Kalibr's camchain mapping"):
        Calibration.from_kalibr(path)
    path.write_text(f"cam0:\n{_KALIBR_CAM}cam1: 5\ncam2:\n{_KALIBR_CAM}{_KALIBR_POSE}")
    with pytest.raises(ValueError, match="cam1 lacks field 'T_cn_cnm1'"):
        Calibration.from_kalibr(path, cameras=("cam0", "cam2"))


def test_kalibr_yaml_errors_are_one_line_naming_the_line_and_column(tmp_path: Path) -> None:
    """PyYAML's error was passed on whole: five lines ("in "<unicode string>"", carets), of which
    the CLI showed the first, "cannot parse ... as Kalibr YAML: while parsing a flow sequence",
    without the line or the problem. One line now, the file, line and column named."""
    path = tmp_path / "camchain.yaml"
    path.write_text("cam0:\n  intrinsics: [1, 2, 3\n  resolution: [640, 480]\n")
    with pytest.raises(ValueError) as err:
        Calibration.from_file(path)
    assert str(err.value) == (
        f"cannot parse {path} as Kalibr YAML: line 3, column 13: expected ',' or ']', but got "
        "':' (while parsing a flow sequence at line 2, column 15)"
    )
    path.write_text('cam0:\n  intrinsics: "1\x01"\n')  # a control character: PyYAML's reader
    with pytest.raises(ValueError) as err:
        Calibration.from_kalibr(path)
    assert str(err.value) == (
        f"cannot parse {path} as Kalibr YAML: line 2, column 17: character #x0001: special "
        "characters are not allowed"
    )


def test_from_file_sends_each_format_to_its_reader(tmp_path: Path) -> None:
    """Format detection, from a mutation audit: a ROS pair named "intrinsics" is not Kalibr, a
    YAML of camN device names is no calibration, a .yml ROS pair is a ROS folder, a Q.dat
    sized by the image_size given needs no left.png, and 17 numbers or a
    lone camera_matrix are not a known format."""
    c = raw_calib()
    rc = c.rectified_calibration()
    cams = [
        (c.K1, c.D1, rc.R, rc.K1 @ np.eye(3, 4)),
        (c.K2, c.D2, rc.R, rc.K1 @ np.hstack([np.eye(3), rc.T.reshape(3, 1)])),
    ]
    ros = _write_pair(tmp_path / "ros", cams)
    for side in ("left", "right"):
        text = (
            (ros / f"{side}.yaml")
            .read_text()
            .replace(f'camera_name: "{side}"', 'camera_name: "intrinsics"')
        )
        (ros / f"{side}.yaml").write_text(text)
        (tmp_path / "yml").mkdir(exist_ok=True)
        (tmp_path / "yml" / f"{side}.yml").write_text(text)
    assert "intrinsics" in (ros / "left.yaml").read_text()
    expected = Calibration.from_file(ros)
    assert Calibration.from_file(ros / "left.yaml") == expected
    assert Calibration.from_file(tmp_path / "yml") == expected
    q = tmp_path / "q" / "Q.dat"
    q.parent.mkdir()
    q.write_text("\n".join(" ".join(repr(float(v)) for v in r) for r in rc.Q))
    assert Calibration.from_file(q, image_size=SIZE).image_size == SIZE
    for name, text in (
        ("devices.yaml", "cam0: /dev/video0\ncam1: /dev/video2\n"),
        ("q17.dat", " ".join(["1.0"] * 17)),
        ("lone.yaml", "camera_matrix:\n  rows: 3\n"),
    ):
        (tmp_path / name).write_text(text)
        with pytest.raises(ValueError, match="unrecognised calibration format"):
            Calibration.from_file(tmp_path / name)


def test_from_file_names_a_truncated_tar_and_skips_txt_stereo_calib_names(tmp_path: Path) -> None:
    """A calibrationdata.tar.gz cut short (an EOFError from gzip) is a ValueError naming the
    archive; intrinsics.txt beside extrinsics.txt is not OpenCV stereo_calib output (only
    .yml/.yaml/.xml are). Both survived a mutation audit."""
    c = raw_calib()
    rc = c.rectified_calibration()
    p2 = rc.K1 @ np.hstack([np.eye(3), rc.T.reshape(3, 1)])
    ros = _write_pair(
        tmp_path / "ros", [(c.K1, c.D1, rc.R, rc.K1 @ np.eye(3, 4)), (c.K2, c.D2, rc.R, p2)]
    )
    for side in ("left", "right"):  # padded so that the cut falls inside the gzip stream
        with (ros / f"{side}.yaml").open("a") as fh:
            fh.write("".join(f"# {os.urandom(32).hex()}\n" for _ in range(400)))
    tar = tmp_path / "calibrationdata.tar.gz"
    with tarfile.open(tar, "w:gz") as archive:
        for side in ("left", "right"):
            archive.add(ros / f"{side}.yaml", f"{side}.yaml")
    data = tar.read_bytes()
    tar.write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="as a tar archive"):
        Calibration.from_file(tar)
    for name in ("intrinsics.txt", "extrinsics.txt"):
        (tmp_path / name).write_text("M1 and D1 as text\n")
    with pytest.raises(ValueError, match="unrecognised calibration format"):
        Calibration.from_file(tmp_path / "intrinsics.txt")


def _echoed(text: str, ros2: bool | str = True, **changes: object) -> str:
    """A camera_info file's content as the message `ros2 topic echo --once` (or ROS 1's
    `rostopic echo -n 1`) prints it: k d r p (K D R P), width and height, a header, binning and
    roi, and the `---` after it; ``ros2="flow"``: `ros2 topic echo --flow-style`, the message
    on one line (``{header: {...}, height: 480, ...}``)."""
    info = parse_ros_camera_info(text)
    w, h = info["image_size"]
    fields: dict[str, object] = {
        "header": {"stamp": {"sec": 1, "nanosec": 0}, "frame_id": "cam_optical"},
        "height": h,
        "width": w,
        "distortion_model": info["distortion_model"],
        **{(k.lower() if ros2 else k): info[k].ravel().tolist() for k in "DKRP"},
        "binning_x": 0,
        "binning_y": 0,
        "roi": {"x_offset": 0, "y_offset": 0, "height": 0, "width": 0, "do_rectify": False},
    }
    fields.update(changes)
    # ROS 1 prints the arrays inline ([..]), ROS 2 one item a line, --flow-style all inline
    flow = True if ros2 == "flow" else False if ros2 else None
    out = yaml.safe_dump(fields, default_flow_style=flow, sort_keys=False, width=2**31)
    return out + "---\n"


@pytest.mark.parametrize("ros2", [True, False, "flow"], ids=["ros2", "ros1", "ros2-flow"])
def test_camera_info_messages_echoed_to_files_are_read(tmp_path: Path, ros2: bool | str) -> None:
    """`ros2 topic echo --once /left/camera_info > left.yaml` (the message, not
    camera_calibration's file: k, d, r, p, width, height, a trailing ---) was refused as an
    unrecognised format, a folder of two as a YAML parse error; they give the rig of the files.
    With --flow-style (the message on one line, its keys after "{" and ", ") a file was read
    as an OpenCV JSON calibration and refused."""
    c = raw_calib()
    texts = c.to_ros()
    for side, text in zip(("left", "right"), texts, strict=True):
        (tmp_path / f"{side}.yaml").write_text(_echoed(text, ros2))
    want = Calibration._from_ros_texts(*texts, "left", "right")
    for path in (tmp_path, tmp_path / "left.yaml"):
        got = Calibration.from_file(path)
        assert got == want
    info = parse_ros_camera_info(_echoed(texts[1], ros2), "right")
    assert info["image_size"] == c.image_size and info["distortion_model"] == "plumb_bob"


@pytest.mark.parametrize("ros2", [True, False], ids=["ros2", "ros1"])
def test_an_echo_stopped_mid_message_reads_its_first_message(tmp_path: Path, ros2: bool) -> None:
    """`rostopic echo /left/camera_info > left.yaml` stopped by Ctrl-C holds whole messages and
    a last one cut (ROS 1 mid-array): every message was parsed, the cut one refused the file as
    a YAML parse error although the first one, the one read, is whole."""
    c = raw_calib()
    texts = c.to_ros()
    for side, text in zip(("left", "right"), texts, strict=True):
        one = _echoed(text, ros2)
        cut = one[: one.index("K:" if not ros2 else "k:") + 12]
        (tmp_path / f"{side}.yaml").write_text(one + one + cut)
    want = Calibration._from_ros_texts(*texts, "left", "right")
    assert Calibration.from_file(tmp_path) == want
    assert Calibration.from_file(tmp_path / "left.yaml") == want


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"binning_x": 2, "binning_y": 2}, "binning_x 2"),
        (
            {"roi": {"x_offset": 8, "y_offset": 0, "height": 240, "width": 300}},
            "region of interest",
        ),
        ({"p": None}, "lacks field 'p'"),
        # an uncalibrated camera's driver publishes zeros: was "image_width must be a positive
        # integer, got 0", a field the message does not have
        (
            {"width": 0, "height": 0, "k": [0.0] * 9, "p": [0.0] * 12},
            "k is all zeros: the camera_info of a camera not calibrated yet",
        ),
    ],
)
def test_an_echoed_camera_info_this_cannot_read_is_named(changes: dict, message: str) -> None:
    """A binned or cropped camera's message (its K is not the image's), or one without P."""
    text = _echoed(raw_calib().to_ros()[0], **changes)
    if changes.get("p", 0) is None:
        text = "\n".join(line for line in text.splitlines() if not line.startswith("p:"))
    with pytest.raises(ValueError, match=message):
        parse_ros_camera_info(text, "left")


def test_one_camera_info_alone_names_the_partner_it_looked_for(tmp_path: Path) -> None:
    """A lone file was told 'its partner (left/right swapped in the name) is not beside it',
    also when its name holds neither (ROS's monocular head_camera.yaml): the partner looked for
    is named, and a name without a side is said to be one."""
    left = raw_calib().save_ros(tmp_path / "ros")[0]
    (tmp_path / "ros" / "right.yaml").unlink()
    with pytest.raises(ValueError, match=r"its partner .*right\.yaml is not beside it"):
        Calibration.from_file(left)
    head = tmp_path / "head_camera.yaml"
    head.write_bytes(left.read_bytes())
    with pytest.raises(ValueError, match="its name says neither left nor right") as err:
        Calibration.from_file(head)
    assert "swapped" not in str(err.value)
