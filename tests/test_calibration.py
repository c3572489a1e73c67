"""Tests of stereovision.calibration: validation, file round trips, dataset parsers, Q, rectify."""

from __future__ import annotations

import dataclasses
import json
import os
import re
import sys
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from stereovision.calibration import (
    Calibration,
    _inner_rectangle,
    parse_kitti_calib,
    parse_middlebury_calib,
)

SIZE = (320, 240)


def raw_calib(**overrides: object) -> Calibration:
    """An unrectified, distorted synthetic rig: 12 cm baseline, slight toe-in, metres."""
    fields: dict[str, object] = {
        "K1": np.array([[300.0, 0.0, 161.3], [0.0, 302.0, 118.7], [0.0, 0.0, 1.0]]),
        "D1": np.array([-0.12, 0.05, 0.001, -0.0005, -0.01]),
        "K2": np.array([[305.0, 0.0, 158.2], [0.0, 306.5, 121.4], [0.0, 0.0, 1.0]]),
        "D2": np.array([-0.10, 0.03, -0.0008, 0.0007, 0.0]),
        "R": cv2.Rodrigues(np.array([0.01, -0.03, 0.004]))[0],
        "T": np.array([-0.12, 0.002, 0.003]),
        "image_size": SIZE,
        "unit": "m",
    }
    fields.update(overrides)
    return Calibration(**fields)  # type: ignore[arg-type]


def rect_calib(**overrides: object) -> Calibration:
    K = np.array([[500.0, 0.0, 160.0], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    fields: dict[str, object] = {
        "K1": K,
        "D1": np.zeros(5),
        "K2": K,
        "D2": np.zeros(5),
        "R": np.eye(3),
        "T": np.array([-100.0, 0.0, 0.0]),
        "image_size": SIZE,
        "unit": "mm",
        "rectified": True,
    }
    fields.update(overrides)
    return Calibration(**fields)  # type: ignore[arg-type]


# ----------------------------------------------------------------------------------- validation


def test_valid_calibration_properties() -> None:
    c = raw_calib()
    assert c.K1.dtype == np.float64 and c.T.shape == (3,)
    assert not c.K1.flags.writeable  # cached maps cannot go stale
    assert c.baseline == pytest.approx(np.sqrt(0.12**2 + 0.002**2 + 0.003**2))
    assert c.baseline_m == c.baseline and c.to_metres_factor == 1.0
    r = rect_calib()
    assert r.baseline == 100.0 and r.baseline_m == pytest.approx(0.1)
    assert r.to_metres_factor == 1e-3 and r.focal_px == 500.0 and r.doffs_px == 0.0
    with pytest.warns(UserWarning, match=r"baseline 100 ft = 30.48 m, longer than a robot's"):
        assert rect_calib(unit="ft").baseline_m == pytest.approx(30.48)
    # OpenCV-shaped inputs: (1, 5) distortion and (3, 1) translation
    c2 = raw_calib(D1=np.zeros((1, 5)), T=np.array([[-0.12], [0.0], [0.0]]))
    assert c2.D1.shape == (5,) and c2.T.shape == (3,)
    for n in (4, 8, 12, 14):
        assert raw_calib(D2=np.zeros(n)).D2.shape == (n,)


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("K1", np.full((3, 3), np.nan), "K1: contains NaN"),
        ("K1", np.diag([300.0, 300.0, 1.0]) + 1j, "K1: expected a real array, got complex"),
        ("K2", np.diag([0.0, 300.0, 1.0]), "K2: focal lengths must be positive"),
        ("K1", np.diag([-300.0, 300.0, 1.0]), "K1: focal lengths must be positive"),
        ("K1", np.eye(2), r"K1: expected shape \(3, 3\)"),
        ("K1", np.array([[300.0, 0, 160], [0, 300, 120], [0, 0, 2]]), "K1: expected a camera"),
        ("D1", np.zeros(6), r"D1: expected shape \(4,\) or \(5,\)"),
        ("D2", np.array([np.inf, 0, 0, 0, 0]), "D2: contains NaN or inf"),
        ("R", 2 * np.eye(3), "R: not a rotation"),
        ("R", np.diag([1.0, 1.0, -1.0]), r"R: not a rotation.*det = -1"),
        ("R", np.eye(3) + 1e-4, "R: not a rotation"),
        ("T", np.zeros(3), "T: zero baseline"),
        ("T", np.array([np.nan, 0, 0]), "T: contains NaN"),
        ("T", np.zeros(2), r"T: expected shape \(3,\)"),
        ("image_size", (0, 240), "image_size: expected positive integers"),
        ("image_size", (320.5, 240), "image_size: expected positive integers"),
        ("image_size", 320, r"image_size: expected \(width, height\)"),
        ("unit", "furlong", "unit: expected one of"),
        ("rectified", "yes", "rectified: expected a bool"),
        ("doffs", 3.0, "doffs: only applies to a rectified"),
    ],
)
def test_bad_values_name_the_field(field: str, value: object, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        raw_calib(**{field: value})


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"R": cv2.Rodrigues(np.array([0.0, 0.01, 0.0]))[0]}, "R: a rectified calibration"),
        ({"T": np.array([-100.0, 1.0, 0.0])}, r"T: a rectified calibration needs T = \(-B"),
        ({"T": np.array([100.0, 0.0, 0.0])}, "T: T\\[0\\] must be negative"),
        ({"D1": np.array([0.1, 0, 0, 0, 0])}, "D1: a rectified calibration has no distortion"),
        ({"T": np.array([-100.0, 0.0, 1.0])}, r"T: a rectified calibration needs T = \(-B"),
        ({"K2": np.array([[510.0, 0, 160], [0, 500, 120], [0, 0, 1]])}, "K2: fx"),
        ({"K2": np.array([[500.0, 0, 160], [0, 500, 121], [0, 0, 1]])}, "K2: cy = 121 differs"),
        ({"doffs": 4.0}, r"doffs: 4.0 differs from cx2 - cx1 = 0.0"),
        ({"doffs": 0.01}, r"doffs: 0.01 differs from cx2 - cx1 = 0.0"),
        ({"doffs": float("nan")}, "doffs: expected a finite number"),
        # an OverflowError naming no field ("int too large to convert to float")
        (
            {"doffs": 10**400},
            r"^doffs: expected a finite number of pixels, got an integer of 401 digits "
            r"\(too large for a float\)$",
        ),
    ],
)
def test_bad_rectified_values(overrides: dict[str, object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        rect_calib(**overrides)


def test_doffs_derived_from_principal_points() -> None:
    K2 = np.array([[500.0, 0.0, 170.5], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    assert rect_calib(K2=K2).doffs_px == 10.5
    assert rect_calib(K2=K2, doffs=10.5).doffs_px == 10.5


def test_frozen_and_replace_revalidates() -> None:
    c = raw_calib()
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.unit = "mm"  # type: ignore[misc]
    with pytest.raises(ValueError, match="read-only"):
        c.T[0] = 5.0
    with pytest.warns(UserWarning, match="shorter than any stereo rig"):  # 0.12 mm: re-checked
        assert dataclasses.replace(c, unit="mm").baseline_m == pytest.approx(c.baseline / 1000)
    with pytest.raises(ValueError, match="T: zero baseline"):
        dataclasses.replace(c, T=np.zeros(3))


def test_equality() -> None:
    assert raw_calib() == raw_calib()
    with pytest.warns(UserWarning, match="shorter than any stereo rig"):
        assert raw_calib() != raw_calib(unit="mm")
    assert raw_calib() != raw_calib(T=np.array([-0.13, 0.0, 0.0]))
    # a given doffs is a field: within its 2e-3 px tolerance of cx2 - cx1, yet another value
    assert rect_calib(doffs=0.001) == rect_calib(doffs=0.001)
    assert rect_calib(doffs=0.001) != rect_calib() != rect_calib(doffs=0.0)


# ---------------------------------------------------------------------------------- round trips


def _bits_equal(a: Calibration, b: Calibration) -> None:
    for name in ("K1", "D1", "K2", "D2", "R", "T"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape and x.dtype == y.dtype == np.float64, name
        assert x.tobytes() == y.tobytes(), name  # bit-identical float64
    assert (a.image_size, a.unit, a.rectified, a.doffs) == (
        b.image_size,
        b.unit,
        b.rectified,
        b.doffs,
    )
    assert a == b


@pytest.mark.parametrize("suffix", [".yaml", ".yml", ".xml", ".json"])
@pytest.mark.parametrize("make", [raw_calib, lambda: rect_calib(doffs=0.0, unit="in")])
def test_save_load_round_trip_bit_identical(tmp_path: Path, suffix: str, make) -> None:
    rng = np.random.default_rng(7)
    c = make()
    if not c.rectified:  # awkward float64 values that do not print short
        c = raw_calib(D1=rng.standard_normal(8) * 1e-3, T=np.array([-0.1 / 3, 1e-17, np.pi * 1e-3]))
    path = tmp_path / f"calib{suffix}"
    assert c.save(path) == path
    for loaded in (Calibration.load(path), Calibration.from_file(path)):
        _bits_equal(c, loaded)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # atomic: no temp file left


def test_yaml_readable_by_opencv(tmp_path: Path) -> None:
    c = raw_calib()
    c.save(tmp_path / "c.yaml")
    text = (tmp_path / "c.yaml").read_text()
    assert text.startswith("%YAML")
    fs = cv2.FileStorage(str(tmp_path / "c.yaml"), cv2.FILE_STORAGE_READ)
    assert fs.isOpened()
    np.testing.assert_array_equal(fs.getNode("K1").mat(), c.K1)
    np.testing.assert_array_equal(fs.getNode("R").mat(), c.R)
    np.testing.assert_array_equal(fs.getNode("T").mat().ravel(), c.T)
    np.testing.assert_array_equal(fs.getNode("D2").mat().ravel(), c.D2)
    assert fs.getNode("unit").string() == "m"
    assert int(fs.getNode("image_width").real()) == 320
    assert int(fs.getNode("rectified").real()) == 0
    fs.release()


def test_a_calibration_written_as_json_by_opencv_filestorage_loads(tmp_path: Path) -> None:
    """cv::FileStorage writes JSON for a .json name (in C++, Python, ...), each matrix an object
    {"type_id": "opencv-matrix", "rows", "cols", "dt", "data"} (a 1-D array an
    "opencv-nd-matrix"): it was refused as "K1: expected a real array, got dict". It loads with
    OpenCV's meaning, bit for bit, also after a blank line (which OpenCV takes for YAML)."""
    rng = np.random.default_rng(5)
    c = raw_calib(D1=rng.standard_normal(8) * 1e-3, T=np.array([-0.1 / 3, 1e-17, np.pi * 1e-3]))
    path = tmp_path / "rig.json"
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    for key, value in c._to_record().items():
        # D1 as a 1-D array, T as a column, the rest as saved
        fs.write(key, value.reshape(-1, 1) if key == "T" else value)
    fs.release()
    text = path.read_text()
    assert text.lstrip().startswith("{") and '"type_id": "opencv-matrix"' in text
    assert '"type_id": "opencv-nd-matrix"' in text  # D1
    for body in (text, "\n  " + text):
        path.write_text(body)
        for loaded in (Calibration.load(path), Calibration.from_file(path)):
            _bits_equal(c, loaded)
    # a matrix of OpenCV's beside a nested list: the list is named, not read as a matrix
    obj = json.loads(text)
    obj["R"] = c.R.tolist()
    path.write_text(json.dumps(obj))
    with pytest.raises(ValueError, match=r"rig\.json: field 'R' is not a matrix: expected rows, "):
        Calibration.load(path)


def test_a_filestorage_json_opencv_cannot_parse_is_not_called_yaml(tmp_path: Path) -> None:
    """A cv::FileStorage JSON that OpenCV's parser refuses (a NaN Python's json wrote, which
    Python reads back) was said to be unparseable "as OpenCV YAML/XML": it is JSON."""
    path = tmp_path / "rig.json"
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    for key, value in raw_calib()._to_record().items():
        fs.write(key, value)
    fs.release()
    obj = json.loads(path.read_text())
    obj["K1"]["data"][1] = float("nan")
    path.write_text(json.dumps(obj, indent=1))
    with pytest.raises(ValueError, match=r"^cannot parse .*rig\.json as OpenCV JSON: line \d+: "):
        Calibration.load(path)


def test_json_content(tmp_path: Path) -> None:
    rect_calib(doffs=0.0).save(tmp_path / "c.json")
    obj = json.loads((tmp_path / "c.json").read_text())
    assert obj["K1"][0] == [500.0, 0.0, 160.0]
    assert obj["T"] == [-100.0, 0.0, 0.0]
    assert (obj["unit"], obj["rectified"], obj["doffs"]) == ("mm", 1, 0.0)
    assert (obj["image_width"], obj["image_height"]) == SIZE


def test_load_errors(tmp_path: Path) -> None:
    missing = tmp_path / "none.yaml"
    for fn in (Calibration.load, Calibration.from_file, Calibration.from_middlebury):
        with pytest.raises(FileNotFoundError, match=r"calibration file not found.*none\.yaml"):
            fn(missing)
    with pytest.raises(FileNotFoundError):
        Calibration.from_kitti(missing)
    (tmp_path / "g.txt").write_text("hello world\n")
    with pytest.raises(ValueError, match="unrecognised calibration format"):
        Calibration.from_file(tmp_path / "g.txt")
    with pytest.raises(ValueError, match="not a stereovision calibration"):
        Calibration.load(tmp_path / "g.txt")
    (tmp_path / "b.bin").write_bytes(b"\xff\xfe\x00\x81")
    with pytest.raises(ValueError, match="not a text calibration"):
        Calibration.from_file(tmp_path / "b.bin")
    rec = json.loads(json.dumps({"K1": np.eye(3).tolist()}))
    (tmp_path / "partial.json").write_text(json.dumps(rec))
    with pytest.raises(ValueError, match="lacks field 'image_width'"):
        Calibration.load(tmp_path / "partial.json")
    (tmp_path / "broken.json").write_text("{not json")
    with pytest.raises(ValueError, match="cannot parse"):
        Calibration.load(tmp_path / "broken.json")
    with pytest.raises(ValueError, match=r"use \.yaml, \.yml, \.xml or \.json"):
        raw_calib().save(tmp_path / "c.txt")
    # invalid values inside a well-formed file are reported by field
    raw_calib().save(tmp_path / "c.json")
    obj = json.loads((tmp_path / "c.json").read_text())
    obj["K1"][0][0] = -1.0
    (tmp_path / "c.json").write_text(json.dumps(obj))
    with pytest.raises(ValueError, match="K1: focal lengths must be positive"):
        Calibration.load(tmp_path / "c.json")


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("image_width", 1e400, "image_width must be an integer"),
        ("image_width", 10**400, r"image_width must be an integer, got an integer of 401 digits"),
        ("image_width", [640, 1], "image_width must be an integer"),
        ("image_height", 2.5, "image_height must be an integer"),
        ("rectified", [1], "rectified must be 0 or 1"),
        ("rectified", 7, "rectified must be 0 or 1"),
        ("doffs", "x", "doffs must be a number"),
        ("model", "omni", "model: expected one of"),
    ],
)
def test_damaged_json_fields_are_named(
    tmp_path: Path, field: str, value: object, message: str
) -> None:
    """A fuzz of 3000 damaged saved calibrations found an OverflowError (a width of 1e400) and a
    TypeError (a list): both are ValueErrors naming the field now."""
    rec = json.loads(raw_calib().save(tmp_path / "c.json").read_text())
    rec[field] = value
    (tmp_path / "e.json").write_text(json.dumps(rec).replace("Infinity", "1e400"))
    with pytest.raises(ValueError, match=message):
        Calibration.load(tmp_path / "e.json")


def test_a_matrix_entry_past_a_float_is_named(tmp_path: Path) -> None:
    """An int past a float in a matrix (a K1 entry of 10**400, a damaged file) was a bare
    'OverflowError: int too large to convert to float' from load (and the constructor),
    where image_width's (7c64ac6d) is named. It is named by its matrix and file."""
    rec = json.loads(raw_calib().save(tmp_path / "c.json").read_text())
    rec["K1"][0][2] = 10**400
    (tmp_path / "e.json").write_text(json.dumps(rec))
    with pytest.raises(
        ValueError,
        match=r"e\.json: K1: contains an integer of 401 digits \(too large for a float\)",
    ):
        Calibration.load(tmp_path / "e.json")
    with pytest.raises(ValueError, match=r"^T: contains a negative integer of 401 digits"):
        dataclasses.replace(raw_calib(), T=[-(10**400), 0, 0])


def test_an_image_size_past_opencvs_int_is_refused(tmp_path: Path) -> None:
    """image_size (2**70, 480) (or a damaged file's image_width of 2**70) was taken, and failed
    later in OpenCV's words ("stereoRectify ... Can't parse 'imageSize'"). It is refused."""
    with pytest.raises(ValueError, match=r"^image_size: at most 2147483647 px per side"):
        dataclasses.replace(raw_calib(), image_size=(2**70, 480))
    rec = json.loads(raw_calib().save(tmp_path / "c.json").read_text())
    rec["image_width"] = 2**70
    (tmp_path / "e.json").write_text(json.dumps(rec))
    with pytest.raises(ValueError, match=r"e\.json: image_size: at most 2147483647 px per side"):
        Calibration.load(tmp_path / "e.json")
    assert dataclasses.replace(raw_calib(), image_size=(2**31 - 1, 480)).image_size[0] == 2**31 - 1


def test_damaged_opencv_yaml_is_a_value_error_naming_the_problem(tmp_path: Path) -> None:
    """OpenCV's parser raises cv2.error (or a SystemError around it) on a damaged file: each
    reaches the user as a ValueError with the file, the field and OpenCV's reason (it was an
    internal error in the CLI)."""
    good = tmp_path / "rig.yaml"
    raw_calib().save(good)
    text = good.read_text()
    lines = text.splitlines()
    r = next(i for i, line in enumerate(lines) if line.startswith("R:"))
    cases = {
        # a matrix whose "rows" line is gone (FileNode.mat() wrote past its buffer on such a
        # matrix and corrupted the heap; the matrices are read number by number now)
        "no_rows.yaml": "\n".join(lines[: r + 1] + lines[r + 2 :]),
        # a matrix whose data holds a word
        "word.yaml": text.replace("data: [", "data: [ x,", 1),
        # a list cut in the middle, then more keys: a parse error with its line
        "cut.yaml": text.replace("]", "", 1),
    }
    expected = {
        "no_rows.yaml": r"no_rows\.yaml: field 'R' is not a matrix: rows and cols must be integers",
        "word.yaml": r"word\.yaml: field 'K1' is not a matrix: data holds 10 numbers for 3 x 3",
        "cut.yaml": r"cannot parse .*cut\.yaml as OpenCV YAML/XML: line \d+: ",
    }
    for name, body in cases.items():
        (tmp_path / name).write_text(body)
        with pytest.raises(ValueError, match=expected[name]):
            Calibration.from_file(tmp_path / name)


# --------------------------------------------------------------------------------- Middlebury


def test_from_middlebury_terrace(data_dir: Path) -> None:
    path = data_dir / "eth3d" / "terrace" / "calib.txt"
    c = Calibration.from_middlebury(path)
    np.testing.assert_array_equal(c.K1, [[711.499, 0, 376.135], [0, 711.499, 227.447], [0, 0, 1]])
    np.testing.assert_array_equal(c.K2, c.K1)
    np.testing.assert_array_equal(c.T, [-59.9432, 0, 0])
    np.testing.assert_array_equal(c.R, np.eye(3))
    assert (c.unit, c.rectified, c.doffs, c.image_size) == ("mm", True, 0.0, (713, 434))
    assert c.baseline_m == pytest.approx(0.0599432)
    assert c.focal_px == 711.499
    assert Calibration.from_file(path) == c
    v = parse_middlebury_calib(path)
    assert v["ndisp"] == 713.0 and v["baseline"] == 59.9432


def test_middlebury_matrices_in_matlab_syntax_with_commas_or_a_last_semicolon(
    tmp_path: Path,
) -> None:
    """calib.txt's matrices are MATLAB's syntax: "[f, 0, cx; 0, f, cy; 0, 0, 1]" and a last
    row ended by ';' were refused with NumPy's "setting an array element with a sequence ...
    inhomogeneous shape"; they are read, and a matrix of other rows says what it holds."""
    rest = "doffs=0\nbaseline=59.5\nwidth=64\nheight=48\n"
    k = np.array([[542.019, 0, 31.5], [0, 542.019, 23.5], [0, 0, 1]])
    for cam in (
        "[542.019, 0, 31.5; 0, 542.019, 23.5; 0, 0, 1]",
        "[542.019 0 31.5; 0 542.019 23.5; 0 0 1;]",
    ):
        (tmp_path / "calib.txt").write_text(f"cam0={cam}\ncam1={cam}\n{rest}")
        c = Calibration.from_middlebury(tmp_path / "calib.txt")
        assert np.array_equal(c.K1, k) and np.array_equal(c.K2, k)
    # a decimal comma (542,019) is no separator: its row has 5 numbers, not a misread matrix
    for cam, rows in (
        ("[542,019 0 31,5; 0 542,019 23,5; 0 0 1]", "5, 5, 3"),
        ("[1 0 0; 0 1 0]", "3, 3"),
        ("[1 0 0 0 1 0 0 0 1]", "9"),
    ):
        (tmp_path / "calib.txt").write_text(f"cam0={cam}\n")
        with pytest.raises(
            ValueError,
            match=r"calib\.txt:1: cannot parse cam0=.* \(expected 3 rows of 3 numbers, "
            rf"\[f 0 cx; 0 f cy; 0 0 1\], got rows of {rows} numbers\)$",
        ):
            parse_middlebury_calib(tmp_path / "calib.txt")


def test_middlebury_matrix_ended_as_a_matlab_statement(tmp_path: Path) -> None:
    """cam0=[...]; (a MATLAB statement's ';' after the ']') was "could not convert string to
    float: '1]'"; it is read as the matrix, and a row short of numbers still refused."""
    k = np.array([[542.019, 0, 31.5], [0, 542.019, 23.5], [0, 0, 1]])
    (tmp_path / "calib.txt").write_text(
        "cam0=[542.019 0 31.5; 0 542.019 23.5; 0 0 1];\ncam1 = [542.019, 0, 31.5; 0, 542.019, "
        "23.5; 0, 0, 1;] ;\nbaseline=59.5\n"
    )
    out = parse_middlebury_calib(tmp_path / "calib.txt")
    assert np.array_equal(out["cam0"], k) and np.array_equal(out["cam1"], k)
    (tmp_path / "calib.txt").write_text("cam0=[1 0 0; 0 1 0; 0 0];\n")
    with pytest.raises(ValueError, match=r"got rows of 3, 3, 2 numbers\)$"):
        parse_middlebury_calib(tmp_path / "calib.txt")


def test_middlebury_matrix_without_its_closing_bracket_is_refused(tmp_path: Path) -> None:
    """cam0=[... 0 0 1 without the ']' (a line cut short) was read as if complete; it is
    refused naming the key and the line."""
    for cam in (
        "[542.019 0 31.5; 0 542.019 23.5; 0 0 1",
        "[542.019 0 31.5; 0 542.019 23.5; 0 0 1;",
    ):
        (tmp_path / "calib.txt").write_text(f"baseline=59.5\ncam0={cam}\n")
        with pytest.raises(ValueError) as err:
            parse_middlebury_calib(tmp_path / "calib.txt")
        assert (
            str(err.value)
            == f"{tmp_path / 'calib.txt'}:2: cannot parse cam0={cam!r} (no closing ']')"
        )


def test_from_middlebury_with_doffs(tmp_path: Path) -> None:
    # Middlebury 2014 style: different principal points, doffs = cx1 - cx0
    (tmp_path / "calib.txt").write_text(
        "cam0=[3997.684 0 1176.728; 0 3997.684 1011.728; 0 0 1]\n"
        "cam1=[3997.684 0 1307.839; 0 3997.684 1011.728; 0 0 1]\n"
        "doffs=131.111\nbaseline=193.001\nwidth=2964\nheight=1988\nndisp=280\nisint=0\n"
        "vmin=31\nvmax=257\ndyavg=0.918\ndymax=1.516\n"
    )
    c = Calibration.from_middlebury(tmp_path / "calib.txt")
    assert c.doffs == 131.111 and c.doffs_px == 131.111
    assert c.Q[3, 3] == pytest.approx(131.111 / 193.001)
    (tmp_path / "bad.txt").write_text("cam0=[1 0 0; 0 1 0]\n")
    with pytest.raises(ValueError, match="cannot parse cam0"):
        Calibration.from_middlebury(tmp_path / "bad.txt")
    (tmp_path / "neg.txt").write_text(
        "cam0=[1 0 0; 0 1 0; 0 0 1]\ncam1=[1 0 0; 0 1 0; 0 0 1]\nbaseline=-5\nwidth=4\nheight=3\n"
    )
    with pytest.raises(ValueError, match=r"baseline in .*neg\.txt: expected a positive finite"):
        Calibration.from_middlebury(tmp_path / "neg.txt")
    (tmp_path / "partial.txt").write_text("cam0=[1 0 0; 0 1 0; 0 0 1]\nbaseline=1\n")
    with pytest.raises(ValueError, match="lacks 'cam1'"):
        Calibration.from_middlebury(tmp_path / "partial.txt")
    # the image size: a whole number of pixels, named with its file (inf was an OverflowError,
    # nan a bare "cannot convert float NaN to integer", 713.7 read as 713)
    cams = "cam0=[1 0 0; 0 1 0; 0 0 1]\ncam1=[1 0 0; 0 1 0; 0 0 1]\nbaseline=5\n"
    sizes = (("inf", "inf"), ("nan", "nan"), ("713.7", "713.7"), ("-4", "-4"), ("0", "0"))
    for width, shown in sizes:
        (tmp_path / "size.txt").write_text(f"{cams}width={width}\nheight=3\n")
        with pytest.raises(ValueError, match=rf"width in .*size\.txt: expected a positive whole "
                           rf"number of pixels, got {shown}$"):  # fmt: skip
            Calibration.from_middlebury(tmp_path / "size.txt")
    (tmp_path / "size.txt").write_text(f"{cams}width=4.0\nheight=3\n")
    assert Calibration.from_middlebury(tmp_path / "size.txt").image_size == (4, 3)


# -------------------------------------------------------------------------------------- KITTI


def test_from_kitti_shared_file(data_dir: Path) -> None:
    path = data_dir / "kitti2015" / "000005_10" / "calib_kitti.txt"
    c = Calibration.from_kitti(path)
    np.testing.assert_array_equal(
        c.K1, [[721.5377, 0, 609.5593], [0, 721.5377, 172.854], [0, 0, 1]]
    )
    expected_b = (4.485728e01 - -3.395242e02) / 7.215377e02  # (P2[0,3] - P3[0,3]) / f
    assert c.T[0] == pytest.approx(-expected_b, rel=1e-12)
    assert c.baseline_m == pytest.approx(0.5327254, abs=1e-7)
    assert (c.unit, c.rectified, c.image_size) == ("m", True, (1242, 375))  # from left.png
    # agrees with the Middlebury-style calib.txt of the same scene (532.725 mm)
    mb = Calibration.from_middlebury(path.parent / "calib.txt")
    assert c.baseline_m == pytest.approx(mb.baseline_m, abs=1e-6)
    assert Calibration.from_file(path) == c
    assert parse_kitti_calib(path)["T_03"][0] == -4.731050e-01


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX file names are bytes")
def test_from_kitti_sized_by_an_image_in_a_folder_whose_name_is_not_utf8(
    data_dir: Path, tmp_path: Path
) -> None:
    """A KITTI file without S_rect_02 is sized by the left.png beside it, which cv2.imread
    read by its name: a folder named with a byte that is not UTF-8 (a Latin-1 0xFF, the lone
    surrogate of os.fsdecode) crashed the process there (SIGSEGV, as capture's sources did)."""
    folder = tmp_path / os.fsdecode(b"k\xff")
    folder.mkdir()
    kitti = data_dir / "kitti2015" / "000005_10" / "calib_kitti.txt"
    (folder / "calib.txt").write_bytes(kitti.read_bytes())
    cv2.imwrite(str(tmp_path / "left.png"), np.zeros((5, 8, 3), np.uint8))
    (tmp_path / "left.png").rename(folder / "left.png")
    assert Calibration.from_kitti(folder / "calib.txt").image_size == (8, 5)


def test_from_kitti_passes_over_an_image_beside_it_that_cannot_be_read(
    data_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A left.png beside a KITTI file without S_rect_02 that cannot be read (no permission)
    was passed over by cv2.imread's None for the next image; read from its bytes (b418a20e) it
    was np.fromfile's bare PermissionError out of from_kitti, the left.jpg beside it unread."""
    kitti = data_dir / "kitti2015" / "000005_10" / "calib_kitti.txt"
    (tmp_path / "calib.txt").write_bytes(kitti.read_bytes())
    cv2.imwrite(str(tmp_path / "left.png"), np.zeros((5, 8, 3), np.uint8))
    cv2.imwrite(str(tmp_path / "left.jpg"), np.zeros((6, 9, 3), np.uint8))
    fromfile = np.fromfile

    def refused(file: Any, *args: Any, **kwargs: Any) -> Any:
        if Path(file).name == "left.png":
            raise PermissionError(13, "Permission denied", str(file))
        return fromfile(file, *args, **kwargs)

    monkeypatch.setattr(np, "fromfile", refused)
    assert Calibration.from_kitti(tmp_path / "calib.txt").image_size == (9, 6)


def test_from_kitti_says_cameras_given_right_first(data_dir: Path) -> None:
    # (3, 2) was refused as a baseline of -0.533 without the likely cause: the order swapped
    path = data_dir / "kitti2015" / "000005_10" / "calib_kitti.txt"
    with pytest.raises(
        ValueError,
        match=r"got -0\.5327\d* m; cameras=\(3, 2\) .*right camera first: pass cameras=\(2, 3\)$",
    ):
        Calibration.from_kitti(path, cameras=(3, 2))


def test_from_kitti_raw_and_object_formats(tmp_path: Path) -> None:
    p2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
    p3 = "7.2e+02 0 6.1e+02 -3.6e+02 0 7.2e+02 1.7e+02 0 0 0 1 0"
    (tmp_path / "calib_cam_to_cam.txt").write_text(
        f"calib_time: 09-Jan-2012 13:57:47\ncorner_dist: 9.950000e-02\n"
        f"S_rect_02: 1.242000e+03 3.750000e+02\nP_rect_02: {p2}\nP_rect_03: {p3}\n"
    )
    c = Calibration.from_file(tmp_path / "calib_cam_to_cam.txt")
    assert c.image_size == (1242, 375)
    assert c.baseline == pytest.approx(405.0 / 720.0)
    (tmp_path / "000000.txt").write_text(f"P0: {p2}\nP1: {p3}\nP2: {p2}\nP3: {p3}\n")
    with pytest.raises(ValueError, match="image_size"):
        Calibration.from_kitti(tmp_path / "000000.txt")
    c2 = Calibration.from_kitti(tmp_path / "000000.txt", image_size=(1242, 375))
    assert c2 == c
    (tmp_path / "short.txt").write_text("P2: 1 2 3\nP3: 1 2 3\n")
    with pytest.raises(ValueError, match="P2 has 3 values"):
        Calibration.from_kitti(tmp_path / "short.txt", image_size=(10, 10))
    (tmp_path / "none.txt").write_text("P0: 1 2 3\n")
    with pytest.raises(ValueError, match="lacks P_rect_02"):
        Calibration.from_kitti(tmp_path / "none.txt", image_size=(10, 10))
    (tmp_path / "inf.txt").write_text(f"P_rect_02: {p2}\nP_rect_03: {p3}\nS_rect_02: inf 375\n")
    with pytest.raises(ValueError, match=r"S_rect_02 width in .*inf\.txt: .* got inf$"):
        Calibration.from_kitti(tmp_path / "inf.txt")


def test_from_kitti_refuses_an_image_size_its_s_rect_02_contradicts(tmp_path: Path) -> None:
    """from_kitti kept S_rect_02's 1242x375 and dropped a contradicting image_size silently
    (from_file refused it, from_kitti did not); a file with a broken S_rect_02 was sized by the
    image_size or a left.png instead, as if it had none."""
    p2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
    p3 = "7.2e+02 0 6.1e+02 -3.6e+02 0 7.2e+02 1.7e+02 0 0 0 1 0"
    cam = tmp_path / "calib_cam_to_cam.txt"
    cam.write_text(f"S_rect_02: 1.242000e+03 3.750000e+02\nP_rect_02: {p2}\nP_rect_03: {p3}\n")
    assert Calibration.from_kitti(cam, image_size=(1242, 375)).image_size == (1242, 375)
    with pytest.raises(
        ValueError, match=r"1242x375 images \(S_rect_02\), not of the image_size \(621, 188\)"
    ):
        Calibration.from_kitti(cam, image_size=(621, 188))
    cam.write_text(f"S_rect_02: 1242\nP_rect_02: {p2}\nP_rect_03: {p3}\n")
    with pytest.raises(ValueError, match=r"S_rect_02 has 1 values, not 2"):
        Calibration.from_kitti(cam, image_size=(1242, 375))


def test_a_kitti_value_that_is_no_number_is_named(tmp_path: Path) -> None:
    """A key with a value that is no number is skipped by the parser: a damaged P_rect_03
    (or one parted by commas) was "lacks P_rect_02/P_rect_03", a damaged S_rect_02 left the
    size to the image_size given or an image beside the file."""
    p2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
    p3 = "7.2e+02 0 6.1e+02 -3.6e+O1 0 7.2e+02 1.7e+02 0 0 0 1 0"
    cam = tmp_path / "calib_cam_to_cam.txt"
    cam.write_text(f"S_rect_02: 1.242000e+03 3.750000e+02\nP_rect_02: {p2}\nP_rect_03: {p3}\n")
    with pytest.raises(
        ValueError,
        match=r"calib_cam_to_cam\.txt: P_rect_03 holds '-3\.6e\+O1', not a number \(its values "
        r"are numbers parted by spaces\)$",
    ):
        Calibration.from_file(cam)
    cam.write_text(f"S_rect_02: 1242, 375\nP_rect_02: {p2}\nP_rect_03: {p2}\n")
    with pytest.raises(ValueError, match=r"S_rect_02 holds '1242,', not a number"):
        Calibration.from_kitti(cam, image_size=(1242, 375))


# ------------------------------------------------------------------------------------ Q, rectify


def test_q_rectified_formula() -> None:
    c = rect_calib(K2=np.array([[500.0, 0, 168.0], [0, 500.0, 120.0], [0, 0, 1]]))
    Q = c.Q
    np.testing.assert_array_equal(
        Q,
        [[1, 0, 0, -160], [0, 1, 0, -120], [0, 0, 0, 500], [0, 0, 1 / 100, 8 / 100]],
    )
    # a pixel with d = 42: Z = f B / (d + doffs) = 500 * 100 / 50 = 1000 mm
    X = Q @ np.array([170.0, 130.0, 42.0, 1.0])
    np.testing.assert_allclose(X[:3] / X[3], [20.0, 20.0, 1000.0])


def test_q_unrectified_is_stereo_rectify_q() -> None:
    c = raw_calib()
    q = cv2.stereoRectify(
        c.K1,
        c.D1,
        c.K2,
        c.D2,
        SIZE,
        c.R,
        c.T.reshape(3, 1),
        flags=cv2.CALIB_ZERO_DISPARITY,
        alpha=0,
    )[4]
    np.testing.assert_array_equal(c.Q, q)
    rc = c.rectified_calibration()
    assert rc.rectified and rc.unit == "m" and rc.image_size == SIZE
    assert rc.baseline == pytest.approx(c.baseline, rel=1e-9)  # rectification keeps |T|
    assert rc.doffs_px == pytest.approx(0.0, abs=1e-9)  # CALIB_ZERO_DISPARITY
    np.testing.assert_allclose(rc.Q, q, rtol=1e-12, atol=1e-12)
    assert c.focal_px == rc.K1[0, 0]
    assert c.rectified_calibration() is rc  # cached


def test_rectify_rectified_is_identity() -> None:
    c = rect_calib()
    left = np.zeros((240, 320, 3), np.uint8)
    right = np.ones((240, 320), np.float32)
    out_l, out_r = c.rectify(left, right)
    assert out_l is left and out_r is right
    with pytest.raises(
        ValueError, match="left: image is 100x240, calibration image_size is 320x240"
    ):
        c.rectify(np.zeros((240, 100)), right)


@pytest.mark.parametrize(
    ("size", "hint"),
    [
        ((320, 240), "(images resized, not cropped: calib.scaled_to((320, 240)))"),
        ((640, 400), "(another aspect ratio: another camera mode or camera, or cropped images)"),
        ((640, 481), "(images cropped or padded, not resized (1 row more): crop or pad them to "),
    ],
)
def test_rectify_of_another_size_says_what_the_pair_is(size: tuple[int, int], hint: str) -> None:
    """A pair of a lower camera mode (320x240 frames, a 640x480 calibration) was told the two
    sizes only; depth_map, for the same pair, said to scale the calibration: now both do."""
    c = Calibration.ideal((640, 480), 60.0, 0.1)
    img = np.zeros((size[1], size[0]), np.uint8)
    said = f"left: image is {size[0]}x{size[1]}, calibration image_size is 640x480 {hint}"
    with pytest.raises(ValueError, match=re.escape(said)):
        c.rectify(img, img)


def _render_blobs(points_px: np.ndarray, size: tuple[int, int], sigma: float = 1.2) -> np.ndarray:
    w, h = size
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    img = np.zeros((h, w))
    for x, y in points_px:
        img += np.exp(-((xx - x) ** 2 + (yy - y) ** 2) / (2 * sigma**2))
    return np.clip(img, 0, 1).astype(np.float32)


def _centroid(img: np.ndarray, x: float, y: float, r: int = 4) -> tuple[float, float]:
    x0, y0 = round(x), round(y)
    win = img[y0 - r : y0 + r + 1, x0 - r : x0 + r + 1].astype(np.float64)
    yy, xx = np.mgrid[y0 - r : y0 + r + 1, x0 - r : x0 + r + 1]
    return float((win * xx).sum() / win.sum()), float((win * yy).sum() / win.sum())


def test_rectify_raw_pair_rows_and_depth() -> None:
    """Blobs projected through the distorted raw cameras land on equal rows after rectify(),
    at the disparity f B / Z of rectified_calibration()."""
    c = raw_calib()
    gx, gy = np.meshgrid(np.linspace(-0.35, 0.35, 5), np.linspace(-0.25, 0.25, 4))
    Z = 1.5 + 0.5 * (np.arange(gx.size) % 3)
    pts = np.column_stack([gx.ravel() * Z, gy.ravel() * Z, Z])
    pl = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), c.K1, c.D1)[0].reshape(-1, 2)
    pr = cv2.projectPoints(pts, cv2.Rodrigues(c.R)[0], c.T, c.K2, c.D2)[0].reshape(-1, 2)
    left, right = _render_blobs(pl, SIZE), _render_blobs(pr, SIZE)
    rl, rr = c.rectify(left, right)
    assert rl.shape == left.shape and rl.dtype == np.float32
    assert len([k for k in c._cache if k[0] == "maps"]) == 1
    # float16 and long double, which OpenCV's remap refuses, come back in their own dtype
    for dt in (np.float16, np.longdouble):
        hl, hr = c.rectify(left.astype(dt), right.astype(dt))
        assert hl.dtype == hr.dtype == dt
        np.testing.assert_allclose(hl.astype(np.float32), rl, atol=1e-2)  # float16 steps
    rc = c.rectified_calibration()
    r1, r2, p1, p2, _ = c._stereo_rectify(0.0)
    el = cv2.undistortPoints(pl.reshape(-1, 1, 2), c.K1, c.D1, R=r1, P=p1).reshape(-1, 2)
    er = cv2.undistortPoints(pr.reshape(-1, 1, 2), c.K2, c.D2, R=r2, P=p2).reshape(-1, 2)
    depth_rect = (pts @ r1.T)[:, 2]  # Z in the rectified left frame
    for i in range(len(pts)):
        xl, yl = _centroid(rl, *el[i])
        xr, yr = _centroid(rr, *er[i])
        assert abs(yl - yr) < 0.15, i  # same row
        assert xl == pytest.approx(el[i, 0], abs=0.15) and yl == pytest.approx(el[i, 1], abs=0.15)
        d = xl - xr
        expected = rc.focal_px * rc.baseline / depth_rect[i]
        assert d == pytest.approx(expected, abs=0.25), i
        z = rc.depth_from_disparity(np.array([[d]]))[0, 0]
        assert z == pytest.approx(depth_rect[i], rel=0.01)
    rl2, _ = c.rectify(left, right)
    np.testing.assert_array_equal(rl, rl2)
    with pytest.raises(ValueError, match="alpha"):
        c.rectify(left, right, alpha=2.0)


def stereopi_calib(data_dir: Path) -> Calibration:
    """The StereoPi tutorial's own cv2.stereoCalibrate output (320x240, unit cm)."""
    ref = data_dir / "stereopi_rig" / "reference_calib_result"
    return Calibration(
        K1=np.load(ref / "cam_mats_left.npy"),
        D1=np.load(ref / "dist_coefs_left.npy"),
        K2=np.load(ref / "cam_mats_right.npy"),
        D2=np.load(ref / "dist_coefs_right.npy"),
        R=np.load(ref / "rot_mat.npy"),
        T=np.load(ref / "trans_vec.npy"),
        image_size=(320, 240),
        unit="cm",
    )


def test_stereopi_reference_calibration(data_dir: Path) -> None:
    """The StereoPi tutorial's cv2.stereoCalibrate output loads (unit cm) and our convention
    X_R = R X_L + T reproduces its rectification rotations."""
    ref = data_dir / "stereopi_rig" / "reference_calib_result"
    c = stereopi_calib(data_dir)
    assert c.baseline_m == pytest.approx(0.05396, abs=1e-5)
    r1, r2, *_ = c._stereo_rectify(0.0)
    # 2.4e-4 apart (another OpenCV version); R transposed or inverted rigs are 0.009 to 0.04 off
    np.testing.assert_allclose(r1, np.load(ref / "rect_trans_left.npy"), atol=1e-3)
    np.testing.assert_allclose(r2, np.load(ref / "rect_trans_right.npy"), atol=1e-3)
    # their P2[0, 3] = f * Tx = -1295.248 (alpha -1): same sign and size as ours
    rc = c.rectified_calibration(alpha=-1)
    assert rc.K2[0, 0] * rc.T[0] == pytest.approx(
        np.load(ref / "proj_mats_right.npy")[0, 3], abs=0.05
    )


def test_rectify_points_reaches_the_corners_of_a_wide_lens(data_dir: Path) -> None:
    """OpenCV's undistortion capped at 40 rounds left 524 of the StereoPi left camera's pixels
    (k1 0.53, k2 -3.09, k3 4.93; within 44 px of its corners) up to 2.8 px from where rectify
    puts them, as triangulate's 100 did (c2808b73). They are mapped onto their pixels now:
    the rectified point's ray projects back onto the raw pixel."""
    c = stereopi_calib(data_dir)
    px = np.array([[32.0, 0.0], [16.0, 16.0], [312.0, 24.0], [160.0, 120.0]])
    got = c.rectify_points(px, "left")
    r1, _, p1, _, _ = c._stereo_rectify(0.0)
    ray = np.column_stack([(got - p1[:2, 2]) / np.diag(p1)[:2], np.ones(len(got))]) @ r1
    back = cv2.projectPoints(ray, np.zeros(3), np.zeros(3), c.K1, c.D1)[0].reshape(-1, 2)
    np.testing.assert_allclose(back, px, rtol=0, atol=1e-9)


def test_valid_roi_depends_on_alpha() -> None:
    c = raw_calib()
    (_, _, w0, h0), roi_r0 = c.valid_roi(0.0)
    (x1, y1, w1, h1), _ = c.valid_roi(1.0)
    # alpha = 0 zooms so (nearly) every rectified pixel is valid; alpha = 1 keeps every source
    # pixel, so the all-valid rectangle shrinks inside black borders.
    assert w0 * h0 > 0.9 * SIZE[0] * SIZE[1]
    assert w1 * h1 < w0 * h0
    assert 0 <= x1 and 0 <= y1 and x1 + w1 <= SIZE[0] and y1 + h1 <= SIZE[1]
    # The rectangle really is valid: remapped pixels of an all-white image are white inside it.
    white = np.full((SIZE[1], SIZE[0]), 255, np.uint8)
    rl, _ = c.rectify(white, white, alpha=1.0)
    assert rl[y1 + 1 : y1 + h1 - 1, x1 + 1 : x1 + w1 - 1].min() > 200
    assert rect_calib().valid_roi() == ((0, 0, *SIZE), (0, 0, *SIZE))
    assert len(roi_r0) == 4
    with pytest.raises(ValueError, match="alpha"):
        c.valid_roi(-0.5)


def test_points_back_to_the_left_cameras_own_frame() -> None:
    """Points triangulated in the rectified frame, mapped by to_camera_frame, are the points
    the raw cameras saw (R1 turns 3.4 degrees on this rig; without it they are cm off)."""
    c = raw_calib()
    gx, gy = np.meshgrid(np.linspace(-0.3, 0.3, 4), np.linspace(-0.2, 0.2, 3))
    Z = 1.0 + 0.5 * (np.arange(gx.size) % 4)
    pts = np.column_stack([gx.ravel() * Z, gy.ravel() * Z, Z])
    pl = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), c.K1, c.D1)[0]
    pr = cv2.projectPoints(pts, cv2.Rodrigues(c.R)[0], c.T, c.K2, c.D2)[0]
    r1, r2, p1, p2, _ = c._stereo_rectify(0.0)
    el = cv2.undistortPoints(pl, c.K1, c.D1, R=r1, P=p1).reshape(-1, 2)
    er = cv2.undistortPoints(pr, c.K2, c.D2, R=r2, P=p2).reshape(-1, 2)
    rc = c.rectified_calibration()
    z = rc.focal_px * rc.baseline / (el[:, 0] - er[:, 0])
    rect = np.column_stack(
        [(el[:, 0] - rc.K1[0, 2]) * z / rc.focal_px, (el[:, 1] - rc.K1[1, 2]) * z / rc.K1[1, 1], z]
    )
    assert np.abs(rect - pts).max() > 0.01  # the rectified frame is not the camera's
    back = c.to_camera_frame(rect)
    np.testing.assert_allclose(back, pts, atol=1e-6)
    assert c.to_camera_frame(rect.astype(np.float32)).dtype == np.float32
    assert c.to_camera_frame(rect.reshape(3, 4, 3)).shape == (3, 4, 3)
    np.testing.assert_array_equal(rect_calib().to_camera_frame(rect), rect)
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        c.to_camera_frame(np.zeros((4, 2)))


def test_scaled_to_a_lower_resolution() -> None:
    """A raw rig calibrated at 320x240 run at 640x480 (and back): points project where the
    resized image puts them, x' = (x + 0.5) s - 0.5; a rectified rig keeps its depth."""
    c = raw_calib()
    big = c.scaled_to((640, 480))
    assert big.image_size == (640, 480) and big.scaled_to(SIZE) == c
    assert c.scaled_to(SIZE) is c
    pts = np.array([[0.1, -0.05, 1.5], [-0.3, 0.2, 2.5], [0.0, 0.0, 4.0]])
    for cam, rvec, tvec in (("1", np.zeros(3), np.zeros(3)), ("2", cv2.Rodrigues(c.R)[0], c.T)):
        k, d = getattr(c, "K" + cam), getattr(c, "D" + cam)
        kb = getattr(big, "K" + cam)
        small = cv2.projectPoints(pts, rvec, tvec, k, d)[0].reshape(-1, 2)
        large = cv2.projectPoints(pts, rvec, tvec, kb, d)[0].reshape(-1, 2)
        np.testing.assert_allclose(large, (small + 0.5) * 2 - 0.5, atol=1e-9)
    # the rectified rig at the new size has twice the focal length, the same baseline
    assert big.focal_px == pytest.approx(2 * c.focal_px, rel=1e-3)
    r = rect_calib(K2=np.array([[500.0, 0, 170.0], [0, 500.0, 120.0], [0, 0, 1]]), doffs=10.0)
    half = r.scaled_to((160, 120))
    assert half.doffs == 5.0 and half.doffs_px == pytest.approx(5.0)
    disp = np.array([[20.0]])
    np.testing.assert_allclose(half.depth_from_disparity(disp / 2), r.depth_from_disparity(disp))
    with pytest.raises(ValueError, match="image_size"):
        c.scaled_to((0, 10))


def test_scaled_up_keeps_a_doffs_rounded_as_middlebury_prints_it(tmp_path: Path) -> None:
    """A doffs 1.5e-3 px off cx2 - cx1 (3 printed decimals, within DOFFS_TOL_PX) was refused
    at twice the size ("doffs: 20.003 differs from cx2 - cx1 = 20.0"): scaled, it is kept,
    K2's cx takes the rounding, and the scaled rig saved is read back."""
    from stereovision.calibration import fit_to_frames

    r = rect_calib(K2=np.array([[500.0, 0, 170.0], [0, 500.0, 120.0], [0, 0, 1]]), doffs=10.0015)
    big = r.scaled_to((640, 480))
    assert big.doffs == 20.003 and big.Q[3, 3] == pytest.approx(20.003 / 100.0)
    assert big.K1[0, 2] == 320.5 and big.K2[0, 2] == pytest.approx(340.503, abs=1e-12)
    assert Calibration.load(big.save(tmp_path / "big.yaml")) == big
    disp = np.array([[20.0]])
    np.testing.assert_allclose(big.depth_from_disparity(2 * disp), r.depth_from_disparity(disp))
    assert fit_to_frames(r, (640, 480))[0].doffs == 20.003


def test_fit_to_frames_scales_or_names_a_crop() -> None:
    from stereovision.calibration import fit_to_frames

    c = raw_calib()
    assert fit_to_frames(c, SIZE) == (c, None)
    scaled, note = fit_to_frames(c, (160, 120))
    assert scaled.image_size == (160, 120) and note is not None and "scaled" in note
    with pytest.raises(ValueError, match="another aspect ratio"):
        fit_to_frames(c, (320, 180))
    # the limit is 1 % of the larger scale: 160x121 (0.8 % apart) is scaled, 160x122 (1.6 %) not
    assert fit_to_frames(c, (160, 121))[0].image_size == (160, 121)
    with pytest.raises(ValueError, match="another aspect ratio"):
        fit_to_frames(c, (160, 122))
    for size in ((1,), (0, 0), (2.5, 3)):
        with pytest.raises(ValueError, match="image_size"):
            fit_to_frames(c, size)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("size", "said"),
    [
        ((320, 241), "1 row more"),  # KITTI's 1242x376 frames against a 1242x375 calibration
        ((320, 238), "2 rows fewer"),
        ((321, 239), "1 column more and 1 row fewer"),
    ],
)
def test_fit_to_frames_refuses_a_crop_or_pad_of_a_few_rows(
    size: tuple[int, int], said: str
) -> None:
    """Frames a row or two off the calibration (one side kept, or one larger and one smaller)
    were scaled to, a 0.4 % stretch of one axis moving the principal point ~0.5 px with only a
    note: no resize makes them. They are refused with depth's advice."""
    from stereovision.calibration import fit_to_frames

    with pytest.raises(
        ValueError,
        match=rf"^calibration is for 320x240 images, the frames are {size[0]}x{size[1]}: images "
        rf"cropped or padded, not resized \({said}\): crop or pad them to 320x240$",
    ):
        fit_to_frames(raw_calib(), size)


def test_fit_to_frames_still_scales_a_true_resize() -> None:
    """Both sides by one factor (320x240 -> 640x480, or 160x121 within the 1 %): scaled, the
    pixel centres kept (c' = (c + 0.5) s - 0.5)."""
    from stereovision.calibration import fit_to_frames

    c = raw_calib()
    big, note = fit_to_frames(c, (640, 480))
    assert note is not None and note.startswith(
        "the calibration is for 320x240 and the frames are 640x480: scaled to them"
    )
    np.testing.assert_allclose(big.K1, [[600.0, 0, 323.1], [0, 604.0, 237.9], [0, 0, 1]])
    np.testing.assert_allclose(big.K2, [[610.0, 0, 316.9], [0, 613.0, 243.3], [0, 0, 1]])
    np.testing.assert_array_equal(big.D1, c.D1)
    np.testing.assert_array_equal(big.T, c.T)
    near, _ = fit_to_frames(c, (160, 121))
    assert near.image_size == (160, 121)
    assert near.K1[1, 1] == pytest.approx(302.0 * 121 / 240)
    assert near.K1[1, 2] == pytest.approx((118.7 + 0.5) * 121 / 240 - 0.5)


def test_depth_step_and_describe() -> None:
    """f 500 px, B 0.1 m: fB = 50 m px, so one pixel of disparity is Z^2 / 50 of depth."""
    c = rect_calib()
    np.testing.assert_allclose(c.depth_step([1.0, 5.0]), [0.02, 0.5])
    assert float(c.depth_step(2.0, 0.25)) == pytest.approx(0.02)
    text = c.describe(depths=(1.0, 5.0))
    assert "baseline 10.0 cm (100 mm), focal length 500.0 px" in text
    # 2 atan(320 / 1000) and 2 atan(240 / 1000), about the principal point (160, 120)
    assert "field of view 35.5 x 27.0 degrees" in text
    # one off centre: atan(100.5 / 500) + atan(219.5 / 500), edge to edge
    off = rect_calib(K1=np.array([[500.0, 0.0, 100.0], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]]))
    assert "field of view 35.1 x 27.0 degrees" in off.describe()
    assert "depth Z = 50.000 m px / (d + 0.00 px)" in text
    assert "64 px 78.1 cm, 128 px 39.1 cm" in text
    assert "at 1 m 2.0 cm, at 5 m 50.0 cm" in text
    assert "farthest depth, at a disparity of 1 px: 50.00 m" in text
    raw = raw_calib().describe()
    assert "raw rig, rectified with alpha 0" in raw and "baseline 12.0 cm" in raw


def test_a_rig_on_paper(data_dir: Path) -> None:
    """``Calibration.ideal``: KITTI's image size, field of view and baseline give back its focal
    length and depth steps; ``info --size --hfov --baseline`` prints them."""
    import math
    import subprocess
    import sys

    kitti = Calibration.from_file(data_dir / "kitti2015" / "000005_10" / "calib.txt")
    w, h = kitti.image_size
    hfov = math.degrees(2 * math.atan(w / (2 * kitti.focal_px)))
    paper = Calibration.ideal((w, h), hfov, kitti.baseline_m)
    assert paper.rectified and paper.focal_px == pytest.approx(kitti.focal_px, rel=1e-12)
    np.testing.assert_allclose(paper.depth_step([1.0, 5.0, 20.0]),
                               kitti.depth_step([1.0, 5.0, 20.0]), rtol=1e-9)  # fmt: skip
    for bad in ((0.0, 0.1), (180.0, 0.1), (90.0, 0.0), (True, 0.1), (90.0, float("nan"))):
        with pytest.raises(ValueError, match=r"hfov_deg|baseline_m"):
            Calibration.ideal((640, 480), *bad)
    cli = [sys.executable, "-m", "stereovision.cli", "info"]
    run = subprocess.run([*cli, "--size", "1280x720", "--hfov", "90", "--baseline", "0.12"],
                         capture_output=True, text=True, timeout=60)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "a rig on paper" in run.stdout and "focal length 640.0 px" in run.stdout
    run = subprocess.run([*cli, "--size", "1280x720"], capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and "a rig on paper: --size, --hfov and --baseline" in run.stderr


def test_a_skewed_camera_matrix_is_named_in_a_warning() -> None:
    """OpenCV's undistortion maps drop K[0,1]: a skewed K (a converted or hand-written file)
    is rectified as if it had none, so the user is told; OpenCV's own zero takes none."""
    import warnings

    skewed = np.array([[300.0, 5.0, 161.3], [0.0, 302.0, 118.7], [0.0, 0.0, 1.0]])
    with pytest.warns(UserWarning, match=r"K1: skew K\[0,1\] = 5 px is ignored by the rectif"):
        raw_calib(K1=skewed)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        raw_calib()
        raw_calib(K1=np.array([[300.0, 1e-9, 161.3], [0.0, 302.0, 118.7], [0.0, 0.0, 1.0]]))


def test_a_transposed_camera_matrix_is_said_transposed(tmp_path: Path) -> None:
    """A K1 transposed (MATLAB's IntrinsicMatrix, cx and cy in the bottom row) was refused by
    its form alone, where triangulation's check says the transpose."""
    k = raw_calib().K1
    form = "K1: expected a camera matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]], got "
    with pytest.raises(ValueError) as err:
        raw_calib(K1=k.T)
    assert str(err.value) == form + f"{k.T.tolist()} (transposed? pass K1.T)"
    with pytest.raises(ValueError) as err:
        raw_calib(K1=2 * k)  # a bottom row (0, 0, 2): no transpose to suggest
    assert str(err.value) == form + f"{(2 * k).tolist()}"


def test_a_raw_rig_with_the_right_camera_on_the_left_is_named() -> None:
    """``from_ros(right.yaml, left.yaml)`` built a rig with T[0] > 0 without a word (a rectified
    one is refused)."""
    with pytest.warns(UserWarning, match=r"T: the right camera sits to the left of the left one"):
        raw_calib(T=np.array([0.12, 0.002, 0.003]))


def test_baseline_implausible_for_its_unit_is_warned_once_and_printed_readably() -> None:
    """A 0.03 m square given with unit="mm" made a 0.12 mm "rig" without a word, whose describe
    said "baseline 0.0 cm"; the long-baseline warning suggested unit='mm' whatever the unit was
    and came again from every derived calibration (describe, rescaling)."""
    import warnings

    with pytest.warns(
        UserWarning,
        match=r"^baseline 0\.12 mm = 0\.00012 m, shorter than any stereo rig's \(1 mm\): are T "
        r"\(or the board's square size\) in another unit than unit='mm'\? With unit='m' it "
        r"would be 12\.0 cm\.$",
    ):
        tiny = raw_calib(T=np.array([-0.12, 0.0, 0.0]), unit="mm")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # derived calibrations do not warn again
        text = tiny.describe()
        tiny.scaled_to((160, 120)).rectified_calibration()
    assert "baseline 0.12 mm (0.12 mm)" in text and "0.0 cm" not in text
    # in metres already, the baseline is said once ("120 m = 120 m" said nothing)
    with pytest.warns(
        UserWarning,
        match=r"^baseline 120 m, longer than a robot's rig \(5 m\): .* unit='m'\? With ",
    ):
        raw_calib(T=np.array([-120.0, 0.0, 0.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        raw_calib(T=np.array([-4.0, 0.0, 0.0]), unit="mm")  # an endoscope's 4 mm
    # one range for the warning and the unit it suggests: 4000 "m" would be a 4 m rig in mm,
    # which is taken without a warning, so it is suggested (the hint's 5 mm .. 2 m left it out)
    with pytest.warns(UserWarning, match=r"\(5 m\): .* With unit='mm' it would be 4(\.0+)? m\.$"):
        raw_calib(T=np.array([-4000.0, 0.0, 0.0]))


def test_a_rig_whose_baseline_runs_along_a_view_is_not_rectified(tmp_path: Path) -> None:
    """A baseline along the optical axis made stereoRectify return a negative focal length, and
    the error blamed "K1: focal lengths must be positive, got fx=-76.7" (a matrix the user never
    gave); a right camera turned 90 degrees (no shared view) was described as a normal rig
    (focal length 500.6 px, 65 degrees of view, depths to 50 m). Both now name R and T and the
    angle; ``info`` says it in one line. A slight toe-in and a 30-degree one still rectify."""
    forward = raw_calib(T=np.array([0.001, 0.0, 0.2]))
    with pytest.raises(
        ValueError,
        match=r"^R, T: the baseline \(T = \(0\.001, 0, 0\.2\) m\) is 2\.1 degrees from the left "
        r"camera's optical axis; a stereo pair's cameras sit side by side",
    ):
        forward.rectified_calibration()
    turned = raw_calib(R=cv2.Rodrigues(np.array([0.0, np.pi / 2, 0.0]))[0])
    with pytest.raises(ValueError, match=r"is \d\.\d degrees from the left camera's optical axis"):
        turned.describe()
    with pytest.raises(ValueError, match=r"^R, T: the baseline"):
        turned.rectify(np.zeros((240, 320), np.uint8), np.zeros((240, 320), np.uint8))
    assert raw_calib().rectified_calibration().focal_px > 0
    toe_in = raw_calib(R=cv2.Rodrigues(np.array([0.0, np.pi / 6, 0.0]))[0])
    assert toe_in.rectified_calibration().focal_px > 0
    from stereovision.cli import main

    path = forward.save(tmp_path / "forward.yaml")
    assert main(["info", str(path)]) == 2


def test_describe_lists_no_step_past_the_farthest_depth() -> None:
    """doffs +100 px (cx2 = cx1 + 100): the farthest depth is fB / 101 = 0.50 m, yet depth
    steps at 1, 2, 5 and 10 m were listed as if reachable. fB = 50 m px."""
    K2 = np.array([[500.0, 0.0, 260.0], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    text = rect_calib(K2=K2).describe()
    assert "farthest depth, at a disparity of 1 px: 49.5 cm" in text
    assert (
        "depth step per pixel of disparity: at 1 m none, at 2 m none, at 5 m none, at 10 m none "
        "(none: beyond the farthest depth) (a 0.1 px error: a tenth of it)"
    ) in text
    near = rect_calib().describe()  # doffs 0: farthest 50 m, every step listed
    assert " none" not in near.splitlines()[4]


@pytest.mark.parametrize(
    ("cx2", "far", "near"),
    [
        (140.0, "farthest depth, at a disparity of 21.00 px (1 px above infinity's 20.00 px): "
         "50.00 m", "64 px 1.14 m, 128 px 46.3 cm, 256 px 21.2 cm"),
        (-140.0, "farthest depth, at a disparity of 301.00 px (1 px above infinity's 300.00 "
         "px): 50.00 m", "none (a depth needs a disparity above 300.00 px)"),
    ],
)  # fmt: skip
def test_describe_with_a_negative_doffs(cx2: float, far: str, near: str) -> None:
    """cx2 < cx1 (doffs -20 px, say): a disparity of 1 px is beyond infinity, yet the farthest
    depth was "inf m" (and "(d + -20.00 px)"); at doffs -300 every range was left out, leaving
    "nearest depth a disparity range reaches: " with nothing after it. fB = 50 m px."""
    K2 = np.array([[500.0, 0.0, cx2], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    text = rect_calib(K2=K2).describe()
    doffs = 160.0 - cx2
    assert f"depth Z = 50.000 m px / (d - {doffs:.2f} px)" in text
    assert far in text and "inf m" not in text
    assert f"nearest depth a disparity range reaches: {near}\n" in text


def _opencv_stereo_calib(folder: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Write what OpenCV's stereo_calib sample writes: intrinsics.yml (M1 D1 M2 D2) and
    extrinsics.yml (R T R1 R2 P1 P2 Q), T in the board's square unit (here mm)."""
    K1 = np.array([[700.0, 0, 330], [0, 702, 238], [0, 0, 1]])
    K2 = np.array([[705.0, 0, 318], [0, 704, 242], [0, 0, 1]])
    D = np.array([[0.05, -0.1, 0.001, 0.0, 0.0]])
    R = cv2.Rodrigues(np.array([0.01, -0.02, 0.005]))[0]
    T = np.array([[-120.0], [1.5], [0.8]])
    fs = cv2.FileStorage(str(folder / "intrinsics.yml"), cv2.FILE_STORAGE_WRITE)
    for name, value in (("M1", K1), ("D1", D), ("M2", K2), ("D2", D)):
        fs.write(name, value)
    fs.release()
    R1, R2, P1, P2, Q, _, _ = cv2.stereoRectify(K1, D, K2, D, (640, 480), R, T)
    fs = cv2.FileStorage(str(folder / "extrinsics.yml"), cv2.FILE_STORAGE_WRITE)
    for name, value in (("R", R), ("T", T), ("R1", R1), ("R2", R2), ("P1", P1), ("P2", P2)):
        fs.write(name, value)
    fs.write("Q", Q)
    fs.release()
    return K1, R, T


@pytest.mark.parametrize("which", [".", "intrinsics.yml", "extrinsics.yml"])
def test_from_file_reads_opencv_stereo_calib_output(tmp_path: Path, which: str) -> None:
    K1, R, T = _opencv_stereo_calib(tmp_path)
    calib = Calibration.from_file(tmp_path / which, image_size=(640, 480), unit="mm")
    np.testing.assert_array_equal(calib.K1, K1)
    np.testing.assert_array_equal(calib.R, R)
    np.testing.assert_array_equal(calib.T, T.ravel())
    assert calib.image_size == (640, 480)
    assert calib.unit == "mm"
    assert calib.baseline_m == pytest.approx(np.linalg.norm(T) / 1000)
    assert not calib.rectified


def test_opencv_stereo_calib_output_needs_image_size_and_unit(tmp_path: Path) -> None:
    _opencv_stereo_calib(tmp_path)
    with pytest.raises(ValueError, match=r"stereo_calib output .*pass image_size=.* and unit="):
        Calibration.from_file(tmp_path / "intrinsics.yml")
    with pytest.raises(ValueError, match=r"the unit of T .*: pass unit="):
        Calibration.from_file(tmp_path, image_size=(640, 480))


def test_opencv_stereo_calib_output_missing_one_file_names_it(tmp_path: Path) -> None:
    """One of stereo_calib's two files alone (a copy cut short) was, as a folder, "a folder
    without left.yaml and right.yaml (ROS camera_info), calib.txt or Q.dat" (not naming the
    format at all) and, as the file, intrinsics.yml "lacks field 'image_width'": what is
    missing is its partner."""
    _opencv_stereo_calib(tmp_path)
    (tmp_path / "extrinsics.yml").unlink()
    said = (
        "OpenCV stereo_calib's intrinsics.yml without its extrinsics.yml beside it: the rig's "
        "calibration is the two files together (intrinsics M1 D1 M2 D2, extrinsics R T)"
    )
    with pytest.raises(ValueError) as folder:
        Calibration.from_file(tmp_path, image_size=(640, 480), unit="mm")
    assert str(folder.value) == f"calibration path {tmp_path} holds {said}"
    with pytest.raises(ValueError) as file:
        Calibration.from_file(tmp_path / "intrinsics.yml", image_size=(640, 480), unit="mm")
    assert str(file.value) == f"{tmp_path / 'intrinsics.yml'} is {said}"
    (tmp_path / "intrinsics.yml").unlink()
    with pytest.raises(ValueError, match=r"intrinsics\.yml and extrinsics\.yml \(OpenCV stereo"):
        Calibration.from_file(tmp_path)  # the formats a folder may hold, stereo_calib's too


def test_a_ros_folder_missing_one_camera_names_it(tmp_path: Path) -> None:
    """A ROS camera_info folder holding left.yaml alone (the right camera's file not copied)
    was "a folder without left.yaml and right.yaml ...", as if neither were there."""
    rect_calib().save_ros(tmp_path)
    (tmp_path / "right.yaml").unlink()
    with pytest.raises(ValueError) as exc:
        Calibration.from_file(tmp_path)
    assert str(exc.value) == (
        f"calibration path {tmp_path} holds left.yaml but not right.yaml (ROS camera_info: a "
        "rig needs both cameras' files)"
    )


def test_from_file_refuses_a_unit_the_file_contradicts(data_dir: Path) -> None:
    """unit was read for stereo_calib output only and dropped silently for every other
    format: a Middlebury calib.txt (mm) with unit="m" came back in mm as if agreed."""
    calib_txt = data_dir / "eth3d" / "playground" / "calib.txt"
    if not calib_txt.is_file():
        pytest.skip(f"{calib_txt} not found")
    assert Calibration.from_file(calib_txt, unit="mm").unit == "mm"
    with pytest.raises(
        ValueError, match=r"calib\.txt states its lengths in 'mm', not in the unit 'm'"
    ):
        Calibration.from_file(calib_txt, unit="m")
    with pytest.raises(
        ValueError, match=r"unit: expected one of \['m', 'mm', 'cm', 'ft', 'in'\], got 'yd'"
    ):
        Calibration.from_file(calib_txt, unit="yd")


def test_from_file_reads_a_q_dat_in_the_unit_given(data_dir: Path) -> None:
    """A Q.dat does not state the unit of its baseline: it was read in metres whatever unit was
    given; the unit given is its unit now (metres still by default)."""
    q = next(p for p in sorted(data_dir.rglob("Q.dat")) if (p.parent / "left.png").is_file())
    in_m = Calibration.from_file(q)
    with pytest.warns(UserWarning, match=r"in another unit than unit='mm'\? With unit='m'"):
        in_mm = Calibration.from_file(q, unit="mm")  # a sample's B in metres, read as mm
    assert (in_m.unit, in_mm.unit) == ("m", "mm")
    assert in_mm.baseline == in_m.baseline
    assert in_mm.baseline_m == pytest.approx(in_m.baseline_m / 1000, rel=1e-12)
    with pytest.warns(UserWarning, match="unit='mm'"):
        assert Calibration.from_file(q.parent, unit="mm") == in_mm


@pytest.mark.parametrize("own", ["calib.txt", "Q.dat"])
def test_folder_calibration_wins_over_stereo_calib_files_beside_it(
    tmp_path: Path, data_dir: Path, own: str
) -> None:
    """A scene folder holding its calib.txt or Q.dat and, beside them, OpenCV stereo_calib's
    intrinsics.yml + extrinsics.yml was read as the stereo_calib pair and refused for lacking
    image_size and unit, where it loaded its own calibration before that format was read."""
    import shutil

    scene = next(p.parent for p in sorted(data_dir.rglob(own)) if (p.parent / "left.png").is_file())
    shutil.copy(scene / own, tmp_path / own)
    shutil.copy(scene / "left.png", tmp_path / "left.png")
    _opencv_stereo_calib(tmp_path)
    calib = Calibration.from_file(tmp_path)
    assert calib == Calibration.from_file(tmp_path / own)
    assert calib.rectified


def test_opencv_stereo_calib_missing_field_is_named(tmp_path: Path) -> None:
    _opencv_stereo_calib(tmp_path)
    fs = cv2.FileStorage(str(tmp_path / "extrinsics.yml"), cv2.FILE_STORAGE_WRITE)
    fs.write("R", np.eye(3))
    fs.release()
    with pytest.raises(ValueError, match=r"extrinsics.yml lacks field 'T'"):
        Calibration.from_opencv_stereo_calib(
            tmp_path / "intrinsics.yml", tmp_path / "extrinsics.yml", (640, 480), "mm"
        )


def test_repr_is_one_line_summary_not_the_arrays(tmp_path: Path) -> None:
    rect = Calibration(
        K1=[[542.0, 0, 541.8], [0, 542.0, 255.2], [0, 0, 1]],
        D1=np.zeros(5),
        K2=[[542.0, 0, 541.8], [0, 542.0, 255.2], [0, 0, 1]],
        D2=np.zeros(5),
        R=np.eye(3),
        T=[-59.55, 0, 0],
        image_size=(941, 490),
        unit="mm",
        rectified=True,
    )
    assert repr(rect) == (
        "Calibration(941x490 px; pinhole; rectified; baseline 59.55 mm (0.05955 m); focal 542 px)"
    )
    _opencv_stereo_calib(tmp_path)
    raw = Calibration.from_file(tmp_path, image_size=(640, 480), unit="mm")
    assert repr(raw) == (
        "Calibration(640x480 px; pinhole; unrectified; baseline 120 mm (0.12 m); focal left "
        "700/702 px, right 705/704 px; R 1.31 deg from identity; distorted)"
    )
    assert str(raw) == repr(raw)


def test_from_file_refuses_an_image_size_the_file_contradicts(data_dir: Path) -> None:
    calib_txt = data_dir / "eth3d" / "playground" / "calib.txt"
    if not calib_txt.is_file():
        pytest.skip(f"{calib_txt} not found")
    assert Calibration.from_file(calib_txt, image_size=(941, 490)).image_size == (941, 490)
    with pytest.raises(ValueError, match=r"941x490 images, not of the image_size \(1280, 720\)"):
        Calibration.from_file(calib_txt, image_size=(1280, 720))
    # a size taken from an array (img.shape, a camera's settings) is said as numbers, not as
    # "(np.int64(1280), np.int64(720))"
    with pytest.raises(ValueError) as info:
        Calibration.from_file(calib_txt, image_size=np.array([1280, 720]))
    assert str(info.value) == (
        f"{calib_txt} is a calibration of 941x490 images, not of the image_size (1280, 720) "
        "given: leave image_size out, or resize the calibration with .scaled_to((1280, 720)) if "
        "the images were resized"
    )


def test_a_saved_file_with_a_bad_value_is_named(tmp_path: Path) -> None:
    """A value the class refuses in a saved (or hand-edited) YAML/JSON file was said without
    the file: "unit: expected one of [...], got 'meters'"."""
    import json

    path = Calibration.ideal((640, 480), 60.0, 0.1).save(tmp_path / "rig.json")
    record = json.loads(path.read_text())
    path.write_text(json.dumps({**record, "unit": "meters"}))
    with pytest.raises(ValueError, match=r"^calibration file \S+rig\.json: unit: expected one of "):
        Calibration.from_file(path)
    yaml = Calibration.ideal((640, 480), 60.0, 0.1).save(tmp_path / "rig.yaml")
    yaml.write_text(yaml.read_text().replace("image_width: 640", "image_width: 0"))
    with pytest.raises(
        ValueError, match=r"^calibration file \S+rig\.yaml: image_size: expected positive integers"
    ):
        Calibration.from_file(yaml)


def test_opencv_stereo_calib_reads_1d_vectors_saved_by_filestorage(
    tmp_path: Path, data_dir: Path
) -> None:
    """A distortion vector or T saved by cv2.FileStorage from a 1-D array is an
    !!opencv-nd-matrix (sizes [n]): it was refused as "field 'D1' is not a matrix"; it is read
    as the vector it is (the StereoPi rig's own calibration), and a wrong length or a matrix
    field saved 1-D is still refused."""
    ref = data_dir / "stereopi_rig" / "reference_calib_result"
    K1, K2 = np.load(ref / "cam_mats_left.npy"), np.load(ref / "cam_mats_right.npy")
    D1, D2 = np.load(ref / "dist_coefs_left.npy").ravel(), np.load(ref / "dist_coefs_right.npy")
    E = np.load(ref / "e_mat.npy")
    Ra, Rb, t = cv2.decomposeEssentialMat(E)  # the rig's R (the one near I) and T (|E| / sqrt 2)
    R = max((Ra, Rb), key=lambda r: float(np.trace(r)))
    T = t.ravel() * np.linalg.norm(E) / np.sqrt(2)
    T = -T if T[0] > 0 else T  # the right camera on the right: T's x is negative
    np.testing.assert_allclose(np.cross(T, R, axisb=0, axisc=0), E, atol=1e-6)  # E = [T]x R

    def write(intr: dict[str, np.ndarray], extr: dict[str, np.ndarray]) -> None:
        for name, fields in (("intrinsics.yml", intr), ("extrinsics.yml", extr)):
            fs = cv2.FileStorage(str(tmp_path / name), cv2.FILE_STORAGE_WRITE)
            for key, value in fields.items():
                fs.write(key, value)
            fs.release()

    write({"M1": K1, "D1": D1, "M2": K2, "D2": D2.ravel()}, {"R": R, "T": T})
    text = (tmp_path / "intrinsics.yml").read_text()
    assert "D1: !!opencv-nd-matrix" in text and "sizes: [ 5 ]" in text
    calib = Calibration.from_file(tmp_path, image_size=(320, 240), unit="cm")
    np.testing.assert_array_equal(calib.D1, D1)
    np.testing.assert_array_equal(calib.D2, D2.ravel())
    np.testing.assert_array_equal(calib.T, T)
    np.testing.assert_array_equal(calib.K1, K1)
    assert calib.baseline_m == pytest.approx(0.0540, abs=1e-4)  # the tutorial's 5.40 cm
    # a 2-D (1, 5) D2 beside them still reads the same
    write({"M1": K1, "D1": D1, "M2": K2, "D2": D2}, {"R": R, "T": T})
    assert Calibration.from_file(tmp_path, image_size=(320, 240), unit="cm") == calib
    # a vector of the wrong length: refused by its length, as the constructor refuses it
    write({"M1": K1, "D1": np.append(D1, 0.0), "M2": K2, "D2": D2}, {"R": R, "T": T})
    with pytest.raises(
        ValueError, match=r"extrinsics\.yml: D1: expected shape \(4,\) or \(5,\).*got \(6,\)$"
    ):
        Calibration.from_file(tmp_path, image_size=(320, 240), unit="cm")
    # a matrix saved 1-D is not a matrix
    write({"M1": K1.ravel(), "D1": D1, "M2": K2, "D2": D2}, {"R": R, "T": T})
    with pytest.raises(
        ValueError,
        match=r"intrinsics\.yml: field 'M1' is not a matrix: a !!opencv-nd-matrix \(sizes, no "
        r"rows and cols\) where a matrix is expected$",
    ):
        Calibration.from_file(tmp_path, image_size=(320, 240), unit="cm")


@pytest.mark.parametrize("suffix", [".yaml", ".xml"])
def test_opencv_calibration_file_reads_1d_vectors_saved_by_filestorage(
    tmp_path: Path, data_dir: Path, suffix: str
) -> None:
    """The general OpenCV YAML/XML reader (K1/D1/K2/D2/R/T, image size, unit) refused D1, D2 and
    T saved by cv2.FileStorage from 1-D arrays (!!opencv-nd-matrix) as "field 'D1' is not a
    matrix", though the stereo_calib reader takes them; it reads them as the vectors they are,
    and still refuses a wrong length and a matrix saved 1-D."""
    ref = data_dir / "stereopi_rig" / "reference_calib_result"
    K1, K2 = np.load(ref / "cam_mats_left.npy"), np.load(ref / "cam_mats_right.npy")
    D1 = np.load(ref / "dist_coefs_left.npy").ravel()
    D2 = np.load(ref / "dist_coefs_right.npy").ravel()
    E = np.load(ref / "e_mat.npy")
    Ra, Rb, t = cv2.decomposeEssentialMat(E)
    R = max((Ra, Rb), key=lambda r: float(np.trace(r)))
    T = t.ravel() * np.linalg.norm(E) / np.sqrt(2)
    T = -T if T[0] > 0 else T
    path = tmp_path / f"rig{suffix}"

    def write(**over: np.ndarray) -> None:
        fields = {"K1": K1, "D1": D1, "K2": K2, "D2": D2, "R": R, "T": T, **over}
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
        for key, value in fields.items():
            fs.write(key, value)
        fs.write("image_width", 320)
        fs.write("image_height", 240)
        fs.write("unit", "cm")
        fs.release()

    write()
    text = path.read_text()
    assert ("D1: !!opencv-nd-matrix" in text) if suffix == ".yaml" else ("opencv-nd-matrix" in text)
    for calib in (Calibration.from_file(path), Calibration.load(path)):
        np.testing.assert_array_equal(calib.D1, D1)
        np.testing.assert_array_equal(calib.D2, D2)
        np.testing.assert_array_equal(calib.T, T)
        np.testing.assert_array_equal(calib.K1, K1)
        assert calib.baseline_m == pytest.approx(0.0540, abs=1e-4)  # the tutorial's 5.40 cm
    # a vector of the wrong length: refused by its length, naming the file
    write(T=np.append(T, 0.0))
    with pytest.raises(ValueError, match=r"rig\.(yaml|xml): T: expected shape \(3,\).*got \(4,\)"):
        Calibration.from_file(path)
    # a matrix saved 1-D is not a matrix
    write(R=R.ravel())
    with pytest.raises(
        ValueError,
        match=r"rig\.(yaml|xml): field 'R' is not a matrix: a !!opencv-nd-matrix \(sizes, no "
        r"rows and cols\) where a matrix is expected$",
    ):
        Calibration.from_file(path)


@pytest.mark.parametrize("alpha", ["1", None, True, [0.5]])
def test_alpha_that_is_not_a_number_is_named(alpha: object) -> None:
    # "1" and None were a TypeError from the comparison ("'<=' not supported between instances
    # of 'float' and 'str'"), True was read as 1, and rectified_calibration took any of them
    c = raw_calib()
    pts = np.array([[10.0, 20.0]])
    img = np.zeros((SIZE[1], SIZE[0]), np.uint8)
    says = re.escape(f"alpha: expected a value in [0, 1], got {alpha!r}")
    for call in (
        lambda: c.valid_roi(alpha),  # type: ignore[arg-type]
        lambda: c.rectify(img, img, alpha=alpha),  # type: ignore[arg-type]
        lambda: c.rectify_points(pts, alpha=alpha),  # type: ignore[arg-type]
        lambda: c.to_ros(alpha=alpha),  # type: ignore[arg-type]
    ):
        with pytest.raises(ValueError, match=says):
            call()
    with pytest.raises(
        ValueError, match=re.escape(f"alpha: expected a finite number, got {alpha!r}")
    ):
        c.rectified_calibration(alpha)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "alpha", [float("nan"), float("inf"), 10**400], ids=["nan", "inf", "1e400"]
)
def test_rectified_calibration_alpha_must_be_finite(alpha: float) -> None:
    # NaN went to cv2.stereoRectify; OpenCV's -1 (its default scaling) stays accepted
    c = raw_calib()
    with pytest.raises(
        ValueError,
        match=r"^alpha: expected a finite number, got (nan|inf|an integer of 401 digits \(too)",
    ):
        c.rectified_calibration(alpha)
    assert c.rectified_calibration(-1).rectified


@pytest.mark.parametrize(
    ("depth", "step", "says"),
    [
        ("5", 1.0, "depth_m: expected depths in metres (real numbers), got str '5'"),
        (None, 1.0, "depth_m: expected depths in metres (real numbers), got NoneType None"),
        (True, 1.0, "depth_m: expected depths in metres (real numbers), got bool True"),
        (5.0, 0.0, "disparity_step: expected a positive finite number, got 0.0"),
        (5.0, -1.0, "disparity_step: expected a positive finite number, got -1.0"),
        (5.0, float("nan"), "disparity_step: expected a positive finite number, got nan"),
        (5.0, "1", "disparity_step: expected a positive finite number, got str '1'"),
        # Z^2 gave -1 m the step of +1 m
        (-1.0, 1.0, "depth_m: expected depths in metres, 0 or more, got -1.0"),
        (-np.inf, 1.0, "depth_m: expected depths in metres, 0 or more, got -inf"),
        (
            np.array([[5.0, np.nan], [-2.0, -3.0]]),
            1.0,
            "depth_m: expected depths in metres, 0 or more, got 2 of 4 negative, the first -2.0",
        ),
    ],
)
def test_depth_step_refuses_what_is_not_a_depth_or_a_step(
    depth: object, step: object, says: str
) -> None:
    # NumPy read "5" as 5 m, None as NaN and True as 1; a step of 0, -1 or NaN gave 0, a
    # negative resolution or NaN
    c = rect_calib()
    assert c.depth_step(5.0) == pytest.approx(25.0 / (c.focal_px * c.baseline_m))
    assert np.isnan(c.depth_step(np.array([np.nan, 5.0]))[0])  # a map's pixels without depth
    assert c.depth_step(0.0) == 0.0
    with pytest.raises(ValueError, match=re.escape(says)):
        c.depth_step(depth, step)  # type: ignore[arg-type]


def test_middlebury_calib_with_blank_lines_and_without_a_baseline(tmp_path: Path) -> None:
    # blank lines (a file edited by hand, a trailing empty line) are no key=value error
    (tmp_path / "calib.txt").write_text(
        "\ncam0=[700 0 300; 0 700 200; 0 0 1]\n\ncam1=[700 0 310; 0 700 200; 0 0 1]\n"
        "doffs=10\n  \nbaseline=160\nwidth=640\nheight=480\nndisp=64\n\n\n"
    )
    v = parse_middlebury_calib(tmp_path / "calib.txt")
    assert sorted(v) == ["baseline", "cam0", "cam1", "doffs", "height", "ndisp", "width"]
    assert v["cam1"][0, 2] == 310.0 and v["baseline"] == 160.0
    c = Calibration.from_middlebury(tmp_path / "calib.txt")
    assert c.image_size == (640, 480) and c.doffs == 10.0
    assert c.T.tolist() == [-160.0, 0.0, 0.0]
    # a missing baseline is named (it was a bare KeyError: 'baseline')
    (tmp_path / "nobase.txt").write_text(
        "cam0=[700 0 300; 0 700 200; 0 0 1]\ncam1=[700 0 310; 0 700 200; 0 0 1]\n"
        "width=640\nheight=480\n"
    )
    with pytest.raises(ValueError, match=r"nobase\.txt lacks 'baseline'"):
        Calibration.from_middlebury(tmp_path / "nobase.txt")


def test_scaled_to_a_different_aspect_scales_x_and_y_apart() -> None:
    """A mutation audit found ``scaled_to`` checked at one scale for both axes only: ``c_y``
    scaled by ``s_x`` (or the skew by ``s_y``) went unseen. 320x240 run at 640x360 (s_x = 2,
    s_y = 1.5): points project where the resized image puts them, ``x' = (x + 0.5) s_x - 0.5``,
    ``y' = (y + 0.5) s_y - 0.5`` (cv2.projectPoints both ways; it ignores the skew, which
    scales as ``x``: ``s' = s_x s``)."""
    skewed = np.array([[300.0, 4.0, 161.3], [0.0, 302.0, 118.7], [0.0, 0.0, 1.0]])
    with pytest.warns(UserWarning, match="skew"):
        c = raw_calib(K1=skewed)
        wide = c.scaled_to((640, 360))
    pts = np.array([[0.1, -0.05, 1.5], [-0.3, 0.2, 2.5], [0.2, 0.25, 4.0]])
    scale = np.array([2.0, 1.5])
    for cam, rvec, tvec in (("1", np.zeros(3), np.zeros(3)), ("2", cv2.Rodrigues(c.R)[0], c.T)):
        k, d = getattr(c, "K" + cam), getattr(c, "D" + cam)
        small = cv2.projectPoints(pts, rvec, tvec, k, d)[0].reshape(-1, 2)
        large = cv2.projectPoints(pts, rvec, tvec, getattr(wide, "K" + cam), d)[0].reshape(-1, 2)
        np.testing.assert_allclose(large, (small + 0.5) * scale - 0.5, atol=1e-9)
    assert wide.K1[0, 1] == 2.0 * 4.0


def test_scaled_to_a_size_turned_is_said_swapped(data_dir: Path) -> None:
    """scaled_to(frame.shape[:2]) (height, width) for a 320x240 rig run at 160x120 scaled by
    0.375 and 0.667, a calibration of no camera, without a word (depth_map then said the
    calibration's 120x160 turned); the calibration's size turned is refused as swapped, and
    from_file's image_size turned no longer advises that scaled_to. Another aspect ratio not
    turned is still scaled (test_scaled_to_a_different_aspect_scales_x_and_y_apart)."""
    c = raw_calib()
    frame = np.zeros((120, 160), np.uint8)
    with pytest.raises(ValueError) as err:
        c.scaled_to(frame.shape[:2])  # type: ignore[arg-type]
    assert str(err.value) == (
        "image_size: 120x160 is the calibration's 320x240 turned: width and height swapped? "
        "image_size is (width, height): (160, 120) (an image's shape[1::-1], not its shape[:2])"
    )
    with pytest.raises(ValueError, match=r"^image_size: 240x320 is the calibration's 320x240"):
        c.scaled_to((240, 320))
    assert c.scaled_to(frame.shape[1::-1]).image_size == (160, 120)  # type: ignore[arg-type]
    assert c.scaled_to((160, 160)).image_size == (160, 160)  # not turned: scaled, as before
    square = raw_calib(image_size=(240, 240))
    assert square.scaled_to((120, 120)).image_size == (120, 120)
    calib_txt = data_dir / "eth3d" / "playground" / "calib.txt"
    if calib_txt.is_file():
        with pytest.raises(ValueError) as err:
            Calibration.from_file(calib_txt, image_size=(490, 941))
        assert str(err.value) == (
            f"{calib_txt} is a calibration of 941x490 images, not of the image_size (490, 941) "
            "given: width and height swapped? image_size is (width, height)"
        )


def test_saved_yaml_holds_opencvs_shapes_and_every_field(tmp_path: Path) -> None:
    """The YAML is for OpenCV readers in any language: T a 3x1 column and D1/D2 rows, as
    OpenCV's stereo_calib writes them (a mutation audit found T written as a row unseen: this
    package's own reader takes either). Read back with cv2.FileStorage alone."""
    c = raw_calib()
    fs = cv2.FileStorage(str(c.save(tmp_path / "c.yaml")), cv2.FILE_STORAGE_READ)
    try:
        assert fs.getNode("T").mat().shape == (3, 1) and fs.getNode("R").mat().shape == (3, 3)
        assert fs.getNode("D1").mat().shape == (1, 5) and fs.getNode("K2").mat().shape == (3, 3)
        np.testing.assert_array_equal(fs.getNode("T").mat().ravel(), c.T)
        assert (fs.getNode("image_width").real(), fs.getNode("image_height").real()) == SIZE
        assert fs.getNode("unit").string() == "m" and fs.getNode("rectified").real() == 0
    finally:
        fs.release()


def test_a_plain_yaml_of_the_fields_is_read_as_its_json_twin(tmp_path: Path) -> None:
    """The fields as a script's yaml.safe_dump writes them (nested lists, no '%YAML:1.0'
    header, no !!opencv-matrix tags) were 'unrecognised calibration format in rig.yaml:
    expected OpenCV YAML/XML, JSON, ...' (load: 'not a stereovision calibration file'), though
    the same mapping as JSON is read (with PyYAML's '%YAML 1.1' directive, 'cannot parse ... as
    OpenCV YAML/XML: line 4: Incorrect indentation'). Read as the JSON is, with its checks; a
    YAML holding no calibration field is still unrecognised."""
    import yaml

    c = raw_calib()
    fields = {k: getattr(c, k).tolist() for k in ("K1", "D1", "K2", "D2", "R", "T")}
    fields.update(image_width=SIZE[0], image_height=SIZE[1], unit="m")
    rig = tmp_path / "rig.yaml"
    rig.write_text(yaml.safe_dump(fields))
    assert Calibration.from_file(rig) == c and Calibration.load(rig) == c
    rig.write_text(yaml.safe_dump(fields, version=(1, 1)))  # "%YAML 1.1": not OpenCV's header
    assert rig.read_text().startswith("%YAML 1.1") and Calibration.from_file(rig) == c
    del fields["unit"]  # no unit of its own: from_file's, as for a JSON file
    rig.write_text(yaml.safe_dump(fields))
    assert Calibration.from_file(rig, unit="m") == c
    with pytest.raises(ValueError, match=r"^calibration file .*rig\.yaml lacks field 'unit'"):
        Calibration.from_file(rig)
    (tmp_path / "devices.yaml").write_text("left: /dev/video0\nright: /dev/video2\n")
    with pytest.raises(ValueError, match="unrecognised calibration format"):
        Calibration.from_file(tmp_path / "devices.yaml")


def test_a_file_pyyaml_fails_on_otherwise_than_yamlerror_is_unrecognised(tmp_path: Path) -> None:
    """Every file unrecognised before is tried as a plain YAML of the fields, and PyYAML raises
    more than YAMLError: a date that is none ('stamp: 2024-13-01') was from_file's bare
    'month must be in 1..12' naming no file (a deep nesting of '[' a RecursionError, the CLI's
    'internal RecursionError ... (please report this)'). It is unrecognised, as before."""
    log = tmp_path / "log.txt"
    log.write_text("stamp: 2024-13-01\nimage_width: 640\n")
    with pytest.raises(ValueError, match=r"^unrecognised calibration format in .*log\.txt"):
        Calibration.from_file(log)
    with pytest.raises(ValueError, match=r"^not a stereovision calibration file .*log\.txt"):
        Calibration.load(log)


def test_a_file_with_a_bad_explicit_yaml_tag_is_unrecognised(tmp_path: Path) -> None:
    """PyYAML refuses an explicit tag's bad value with bare Python errors: 'K1: !!bool maybe'
    was KeyError: 'maybe', "!!float ''" IndexError, '!!timestamp x' AttributeError (the CLI's
    'internal ... (please report this)'). It is unrecognised, as a date that is none."""
    log = tmp_path / "log.txt"
    for value in ("!!bool maybe", "!!float ''", "!!timestamp x"):
        log.write_text(f"image_width: 640\nK1: {value}\n")
        with pytest.raises(ValueError, match=r"^unrecognised calibration format in .*log\.txt"):
            Calibration.from_file(log)
        with pytest.raises(ValueError, match=r"^not a stereovision calibration file .*log\.txt"):
            Calibration.load(log)


def test_ros_and_kalibr_files_pyyaml_fails_on_otherwise_are_named(tmp_path: Path) -> None:
    """The ROS camera_info and Kalibr readers caught YAMLError alone: a date that is none
    ('stamp: 2024-13-01') was a bare 'month must be in 1..12' naming no file, 'x: !!bool y' a
    KeyError. Both say the file cannot be parsed, as a YAML error."""
    from stereovision.calibration import parse_ros_camera_info

    for bad in ("stamp: 2024-13-01", "x: !!bool y"):
        with pytest.raises(ValueError, match=r"^cannot parse left\.yaml as ROS camera_info YAML"):
            parse_ros_camera_info(f"image_width: 640\n{bad}\n", "left.yaml")
        chain = tmp_path / "camchain.yaml"
        chain.write_text(f"cam0:\n  intrinsics: [1, 1, 1, 1]\n  {bad}\n")
        with pytest.raises(ValueError, match=r"^cannot parse .*camchain\.yaml as Kalibr YAML"):
            Calibration.from_file(chain)


def test_ros_and_kalibr_matrix_entries_past_a_float_are_named(tmp_path: Path) -> None:
    """An int past a float in a ROS camera_info matrix or a Kalibr intrinsics list (10**400, a
    damaged file) was a bare 'OverflowError: int too large to convert to float' naming no file.
    Both name the file and the field."""
    big = "1" + "0" * 400
    ros = (
        "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
        "  data: [{}, 0, 320, 0, 500, 240, 0, 0, 1]\ndistortion_model: plumb_bob\n"
        "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n"
        "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
        "projection_matrix:\n  rows: 3\n  cols: 4\n"
        "  data: [500, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0]\n"
    )
    (tmp_path / "left.yaml").write_text(ros.format(big))
    (tmp_path / "right.yaml").write_text(ros.format(500))
    with pytest.raises(
        ValueError, match=r"left\.yaml: camera_matrix holds an integer of 401 digits \(too large"
    ):
        Calibration.from_file(tmp_path)
    chain = tmp_path / "camchain.yaml"
    cam = "  intrinsics: [{}, 500, 320, 240]\n  resolution: [640, 480]\n"
    chain.write_text("cam0:\n" + cam.format(big) + "cam1:\n" + cam.format(500))
    with pytest.raises(
        ValueError, match=r"camchain\.yaml:cam0: intrinsics needs 4 finite numbers, got an integer"
    ):
        Calibration.from_file(chain)


def test_a_ros_size_past_a_float_is_said_by_its_digits(tmp_path: Path) -> None:
    """An image_width of 10**400 (a damaged file) in one ROS camera_info printed its 401 digits
    in the check that the two cameras have one size; the number of digits is said (Kalibr's
    resolution is refused before its check)."""
    ros = (
        "image_width: {}\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
        "  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\ndistortion_model: plumb_bob\n"
        "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n"
        "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
        "projection_matrix:\n  rows: 3\n  cols: 4\n"
        "  data: [500, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0]\n"
    )
    big = "1" + "0" * 400
    (tmp_path / "left.yaml").write_text(ros.format(big))
    (tmp_path / "right.yaml").write_text(ros.format(640))
    with pytest.raises(ValueError) as exc:
        Calibration.from_file(tmp_path)
    assert str(exc.value) == (
        f"ROS camera_info: {tmp_path / 'left.yaml'} is (an integer of 401 digits, 480) px, "
        f"{tmp_path / 'right.yaml'} is (640, 480) px (width, height); a rig needs one size"
    )


def test_a_text_without_a_field_as_a_key_is_not_parsed_as_yaml(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every file unrecognised so far was parsed whole by PyYAML's pure-Python parser for a
    plain YAML of the fields: a 2.7 MB list of points given as --calib by mistake took 5.5 s
    more to be 'unrecognised calibration format' (a larger one minutes). A text holding no
    field as a key is not parsed; the message is the same."""
    import yaml

    parsed: list[str] = []
    real, real_load = yaml.safe_load, yaml.load

    def safe_load(text: str) -> object:
        parsed.append(text)
        return real(text)

    def load(text: str, Loader: type) -> object:
        parsed.append(text)
        return real_load(text, Loader=Loader)

    # both: the plain YAML is read with yaml.load and a SafeLoader since 577db24e, and a spy
    # on safe_load alone saw no parse with the check or without it
    monkeypatch.setattr(yaml, "safe_load", safe_load)
    monkeypatch.setattr(yaml, "load", load)
    pts = tmp_path / "cloud.xyz"
    pts.write_text("0.1 0.2 0.3\n0.4 0.5 0.6\n")
    with pytest.raises(ValueError, match=r"^unrecognised calibration format in .*cloud\.xyz"):
        Calibration.from_file(pts)
    assert parsed == []


def test_a_yaml_dump_of_numpy_arrays_is_said(tmp_path: Path) -> None:
    """yaml.dump of the fields as NumPy arrays (a script's first way: !!python/object tags,
    which safe loading constructs no object of) was 'unrecognised calibration format in
    rig.yaml: expected OpenCV YAML/XML, JSON, ...', a YAML of the fields all the same. It is
    said, with the lists to write instead."""
    import yaml

    c = raw_calib()
    fields = {k: getattr(c, k) for k in ("K1", "D1", "K2", "D2", "R", "T")}
    fields.update(image_width=SIZE[0], image_height=SIZE[1], unit="m")
    rig = tmp_path / "rig.yaml"
    rig.write_text(yaml.dump(fields))
    for read in (Calibration.from_file, Calibration.load):
        with pytest.raises(ValueError, match=r"rig\.yaml holds Python objects .*\.tolist\(\)"):
            read(rig)


def test_a_flow_style_yaml_dump_of_numpy_arrays_is_said(tmp_path: Path) -> None:
    """yaml.dump(fields, default_flow_style=True) of NumPy arrays ('{D1: !!python/object/...')
    went to JSON alone: 'cannot parse rig.yaml as JSON: Expecting property name ...', the
    Python objects unsaid (the block style's words looked for a field at a line's start)."""
    import yaml

    c = raw_calib()
    fields = {k: getattr(c, k) for k in ("K1", "D1", "K2", "D2", "R", "T")}
    fields.update(image_width=SIZE[0], image_height=SIZE[1], unit="m")
    rig = tmp_path / "rig.yaml"
    rig.write_text(yaml.dump(fields, default_flow_style=True))
    for read in (Calibration.from_file, Calibration.load):
        with pytest.raises(ValueError, match=r"rig\.yaml holds Python objects .*\.tolist\(\)"):
            read(rig)


def test_a_flow_style_yaml_of_the_fields_is_read(tmp_path: Path) -> None:
    """yaml.safe_dump(fields, default_flow_style=True) writes '{D1: [...], K1: ...}', a plain
    YAML of the fields whose first '{' sent it to JSON: 'cannot parse rig.yaml as JSON:
    Expecting property name enclosed in double quotes'. It is read as the block style is; a
    JSON that is broken and no such YAML keeps JSON's words."""
    import yaml

    c = raw_calib()
    fields = {k: getattr(c, k).tolist() for k in ("K1", "D1", "K2", "D2", "R", "T")}
    fields.update(image_width=SIZE[0], image_height=SIZE[1], unit="m")
    rig = tmp_path / "rig.yaml"
    rig.write_text(yaml.safe_dump(fields, default_flow_style=True))
    assert rig.read_text().startswith("{D1: ")
    assert Calibration.from_file(rig) == c and Calibration.load(rig) == c
    rig.write_text('{"image_width": 320 "image_height": 240}')
    with pytest.raises(ValueError, match=r"^cannot parse .*rig\.yaml as JSON: Expecting ','"):
        Calibration.from_file(rig)


def test_load_of_one_ros_camera_info_says_what_it_is(tmp_path: Path) -> None:
    """load(left.yaml), a ROS camera_info, was read as a plain YAML of the fields for its
    image_width: 'calibration file left.yaml lacks field 'K1'' (before the plain YAML: 'not a
    stereovision calibration file'). It is named, with the readers of a ROS pair."""
    left = tmp_path / "left.yaml"
    left.write_text(
        "image_width: 640\nimage_height: 480\ncamera_name: left\ncamera_matrix:\n  rows: 3\n"
        "  cols: 3\n  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\ndistortion_model: plumb_bob\n"
    )
    with pytest.raises(
        ValueError, match=r"left\.yaml is one camera's ROS camera_info: .*Calibration\.from_ros"
    ):
        Calibration.load(left)
    # a message echoed to a file (ROS 1: K, R, P, its R one of the fields) without the echo's
    # closing '---': "lacks field 'image_width': ... cv2.stereoCalibrate's ..."
    left.write_text(
        "height: 480\nwidth: 640\ndistortion_model: plumb_bob\nD: [0, 0, 0, 0, 0]\n"
        "K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\nR: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
    )
    with pytest.raises(ValueError, match=r"left\.yaml is one camera's ROS camera_info: "):
        Calibration.load(left)


def test_load_of_a_ros2_camera_info_echo_says_what_it_is(tmp_path: Path) -> None:
    """load of a ROS 2 echo of one camera's camera_info (k, d, r, p: none of them a field) said
    'not a stereovision calibration file (OpenCV YAML/XML or JSON)', where ROS 1's (its R a
    field) is named as one camera's ROS camera_info. It is named alike."""
    left = tmp_path / "left.yaml"
    left.write_text(
        "header:\n  frame_id: cam\nheight: 480\nwidth: 640\ndistortion_model: plumb_bob\n"
        "d: [0.0, 0.0, 0.0, 0.0, 0.0]\nk: [500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0]\n"
        "r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
        "p: [500.0, 0.0, 320.0, 0.0, 0.0, 500.0, 240.0, 0.0, 0.0, 0.0, 1.0, 0.0]\n---\n"
    )
    with pytest.raises(
        ValueError, match=r"left\.yaml is one camera's ROS camera_info: .*Calibration\.from_ros"
    ):
        Calibration.load(left)


def test_load_of_a_flow_style_ros2_camera_info_echo_says_what_it_is(tmp_path: Path) -> None:
    """load of a ROS 2 echo in flow style (ros2 topic echo --flow-style: "{header: ..., width:
    640, ...}") said 'cannot parse left.yaml as JSON: Expecting property name enclosed in double
    quotes', where its block style is named as one camera's ROS camera_info. It is named alike."""
    left = tmp_path / "left.yaml"
    left.write_text(
        "{header: {frame_id: cam}, height: 480, width: 640, distortion_model: plumb_bob, "
        "d: [0.0, 0.0, 0.0, 0.0, 0.0], k: [500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0], "
        "r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], "
        "p: [500.0, 0.0, 320.0, 0.0, 0.0, 500.0, 240.0, 0.0, 0.0, 0.0, 1.0, 0.0]}\n---\n"
    )
    with pytest.raises(
        ValueError, match=r"left\.yaml is one camera's ROS camera_info: .*Calibration\.from_ros"
    ):
        Calibration.load(left)


# ------------------------------------------------------ rectification geometry (mutation audit)


def test_rectify_refuses_a_transposed_image() -> None:
    """A portrait 240x320 image for a 320x240 calibration holds the same number of pixels; it
    is refused naming both sizes, not remapped into a landscape picture of the wrong pixels."""
    c = raw_calib()
    good = np.zeros((240, 320), np.uint8)
    with pytest.raises(
        ValueError, match="right: image is 240x320, calibration image_size is 320x240"
    ):
        c.rectify(good, np.zeros((320, 240), np.uint8))


def test_rectify_points_lands_where_the_raw_camera_sees_it_far_off_axis() -> None:
    """A rectified point, turned back by R1^T and projected with K1/D1, is the raw pixel it
    came from, to 1e-4 px even in a strongly distorted corner (OpenCV's default 5 iterations
    leave more there)."""
    c = raw_calib(D1=np.array([-0.45, 0.25, 0.0, 0.0, -0.08]))
    raw = np.array([[2.0, 2.0], [317.0, 3.0], [5.0, 236.0], [300.0, 230.0], [160.0, 120.0]])
    rect = c.rectify_points(raw, "left")
    r1, _, p1, _, _ = c._stereo_rectify(0.0)
    f, cx, cy = p1[0, 0], p1[0, 2], p1[1, 2]
    rays = np.column_stack(
        [(rect[:, 0] - cx) / f, (rect[:, 1] - cy) / p1[1, 1], np.ones(len(rect))]
    )
    back = cv2.projectPoints(rays @ r1, np.zeros(3), np.zeros(3), c.K1, c.D1)[0].reshape(-1, 2)
    np.testing.assert_allclose(back, raw, atol=1e-4)


def test_rectified_calibration_keeps_the_unit() -> None:
    """A raw rig in millimetres rectifies to a millimetre pair: same baseline in metres, and the
    same depths as the rig given in metres (T read as metres would put them 1000x too far)."""
    metres = raw_calib()
    mm = raw_calib(T=metres.T * 1000.0, unit="mm")
    rc = mm.rectified_calibration()
    assert rc.unit == "mm"
    assert rc.baseline_m == pytest.approx(metres.baseline_m, rel=1e-9)
    disp = np.array([[10.0, 25.0]])
    np.testing.assert_allclose(
        mm.depth_from_disparity(disp), metres.depth_from_disparity(disp), rtol=1e-6
    )
    np.testing.assert_allclose(
        mm.depth_from_disparity(disp, unit="mm"),
        1000.0 * metres.depth_from_disparity(disp),
        rtol=1e-6,
    )


def test_to_camera_frame_of_a_rectified_rig_returns_a_copy() -> None:
    """As for a raw rig, the result is a new array: writing to it leaves the caller's points."""
    pts = np.array([[0.1, 0.2, 1.5]])
    out = rect_calib().to_camera_frame(pts)
    out[0, 0] = 99.0
    assert pts[0, 0] == 0.1


def test_from_q_keeps_a_positive_doffs(tmp_path: Path) -> None:
    """A Q written from a rectified rig with doffs (cx2 - cx1 = 12.5 px) reads back as that rig:
    K2's cx on the right side of K1's, same Q, same depths."""
    k1 = np.array([[500.0, 0.0, 150.0], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    k2 = k1.copy()
    k2[0, 2] = 162.5
    rig = rect_calib(K1=k1, K2=k2, T=np.array([-0.1, 0.0, 0.0]), unit="m")
    (tmp_path / "Q.dat").write_text("\n".join(" ".join(repr(float(v)) for v in r) for r in rig.Q))
    back = Calibration.from_q(tmp_path / "Q.dat", SIZE)
    assert back.doffs_px == pytest.approx(12.5, abs=1e-9)
    np.testing.assert_allclose(back.K2, k2, atol=1e-9)
    np.testing.assert_allclose(back.Q, rig.Q, atol=1e-9)


@pytest.mark.parametrize(("f", "inv_b"), [(0.0, 10.0), (500.0, 0.0)])
def test_from_q_refuses_a_zero_focal_length_or_inverse_baseline(
    tmp_path: Path, f: float, inv_b: float
) -> None:
    """Q[2,3] = 0 or Q[3,2] = 0 gives no depth: named as such (Q[3,2] = 0 was 1/0 otherwise)."""
    (tmp_path / "Q.dat").write_text(f"1 0 0 -5\n0 1 0 -4\n0 0 0 {f}\n0 0 {inv_b} 0\n")
    with pytest.raises(ValueError, match=r"Q\[2,3\] \(focal length .*must be positive"):
        Calibration.from_q(tmp_path / "Q.dat", (10, 8))


def test_from_q_names_a_non_finite_entry_and_a_missing_image_size(tmp_path: Path) -> None:
    """A Q holding NaN or inf was refused as "16 finite numbers expected, got 16", which read as
    if the file held what was expected; the entry is named. ``image_size=None`` (or a size of
    three numbers) raised TypeError "'NoneType' object is not iterable" (ValueError "too many
    values to unpack"), naming neither the argument nor the file."""
    (tmp_path / "Q.dat").write_text("1 0 0 -5\n0 1 0 -4\n0 0 0 nan\n0 0 10 inf\n")
    with pytest.raises(
        ValueError,
        match=r"Q\.dat: not a Q matrix \(16 finite numbers expected, got Q\[2,3\] = nan\)$",
    ):
        Calibration.from_q(tmp_path / "Q.dat", (10, 8))
    (tmp_path / "Q.dat").write_text("1 0 0 -5\n0 1 0 -4\n0 0 0 100\n0 0 10 0\n")
    for size in (None, (10, 8, 3), 10):
        said = re.escape(repr(size))
        with pytest.raises(
            ValueError, match=rf"image_size for .*Q\.dat: expected \(width, height\), got {said}$"
        ):
            Calibration.from_q(tmp_path / "Q.dat", size)  # type: ignore[arg-type]
    assert Calibration.from_q(tmp_path / "Q.dat", np.array([10, 8])).image_size == (10, 8)


def test_from_q_takes_any_two_numbers_and_names_image_size_otherwise(tmp_path: Path) -> None:
    """Today's check of image_size took only a tuple, a list or an array: a map or generator
    (``map(int, "10 8".split())``) and an ``array.array``, read before, were refused; a 0-d
    array raised TypeError "len() of unsized object" and ``(10, None)`` float()'s TypeError,
    ``("a", 8)`` its ValueError, naming neither argument nor file; ``(True, 8)`` was 1 px."""
    import array

    (tmp_path / "Q.dat").write_text("1 0 0 -5\n0 1 0 -4\n0 0 0 100\n0 0 10 0\n")
    for size in (map(int, "10 8".split()), (v for v in (10, 8)), array.array("i", [10, 8])):
        assert Calibration.from_q(tmp_path / "Q.dat", size).image_size == (10, 8)  # type: ignore[arg-type]
    for size in (np.array(10), (10, None), ("a", 8), (True, 8), (10 + 0j, 8), "10", {10: 8}):
        said = re.escape(repr(size))
        with pytest.raises(
            ValueError, match=rf"image_size for .*Q\.dat: expected \(width, height\), got {said}$"
        ):
            Calibration.from_q(tmp_path / "Q.dat", size)  # type: ignore[arg-type]


def test_fit_to_frames_refuses_a_two_percent_crop() -> None:
    """Aspect ratios 1 % apart are the limit: 160x117 for 320x240 (2.5 % apart) is a crop,
    160x119 (0.8 %) a scaling."""
    from stereovision.calibration import fit_to_frames

    c = raw_calib()
    with pytest.raises(ValueError, match="another aspect ratio"):
        fit_to_frames(c, (160, 117))
    scaled, note = fit_to_frames(c, (160, 119))
    assert scaled.image_size == (160, 119) and note is not None


def test_an_ideal_rigs_principal_point_is_the_image_centre() -> None:
    """Pixel centres run 0 .. w - 1, so the centre of a 1280x720 image is (639.5, 359.5); a
    90 degree field of view over 1280 px is f = 640 px."""
    paper = Calibration.ideal((1280, 720), 90.0, 0.12)
    np.testing.assert_allclose(
        paper.K1, [[640.0, 0.0, 639.5], [0.0, 640.0, 359.5], [0.0, 0.0, 1.0]], rtol=1e-12
    )
    assert paper.doffs_px == 0.0 and paper.baseline_m == 0.12


def test_rectify_points_of_no_points_on_a_raw_rig() -> None:
    """An empty (0, 2) list (a tracker that lost every feature) gives an empty (0, 2) list."""
    for c in (raw_calib(), rect_calib()):
        out = c.rectify_points(np.zeros((0, 2)), "right")
        assert out.shape == (0, 2) and out.dtype == np.float64


def test_depth_from_disparity_in_every_unit() -> None:
    """A rig in inches gives depths in metres by default and in any unit asked: 1 in =
    0.0254 m, 1 ft = 0.3048 m, 1 cm = 0.01 m exactly."""
    inches = rect_calib(T=np.array([-5.0, 0.0, 0.0]), unit="in")  # 5 in = 0.127 m
    assert inches.baseline_m == pytest.approx(0.127, rel=1e-12)
    disp = np.array([[10.0, 50.0]])
    z_m = inches.depth_from_disparity(disp)
    np.testing.assert_allclose(z_m, 500.0 * 0.127 / disp, rtol=1e-6)
    for unit, metres in (("in", 0.0254), ("ft", 0.3048), ("cm", 0.01), ("mm", 0.001)):
        np.testing.assert_allclose(
            inches.depth_from_disparity(disp, unit=unit), z_m / metres, rtol=1e-6
        )


def test_describe_field_of_view_runs_edge_to_edge() -> None:
    """8 px at f = 4 px about a centred principal point (3.5) span 90 degrees: from the left
    edge (-0.5) to the right one (7.5), not to the last pixel's far side."""
    assert "field of view 90.0 x 73.7 degrees" in Calibration.ideal((8, 6), 90.0, 0.1).describe()


# ------------------------------------------------- loading, saving and conversion (mutation audit)


def test_saved_xml_is_xml_and_saved_yaml_is_yaml(tmp_path: Path) -> None:
    """The extension picks the format OpenCV readers get: the round trip reads either, so a
    .xml written as YAML (or a .yml as XML) passed every other test."""
    c = raw_calib()
    assert c.save(tmp_path / "c.xml").read_text().startswith("<?xml")
    for suffix in (".yml", ".yaml", ".YAML"):
        assert c.save(tmp_path / f"c{suffix}").read_text().startswith("%YAML")


def test_an_xml_file_without_its_declaration_is_read(tmp_path: Path) -> None:
    """An OpenCV XML calibration without its ``<?xml ...?>`` line (hand-edited, or from a tool
    that omits it) was taken for OpenCV XML and parsed as YAML: "cannot parse ... line 1:
    Invalid or unsupported syntax". It reads as the file with the line; a real error in it is
    said at the file's own line number."""
    c = raw_calib()
    xml = c.save(tmp_path / "c.xml").read_text()
    head, body = xml.split("\n", 1)
    assert head == '<?xml version="1.0"?>' and body.startswith("<opencv_storage>")
    for name, text in (("bare.xml", body), ("indented.xml", "\n  " + body)):
        (tmp_path / name).write_text(text)
        assert Calibration.load(tmp_path / name) == c
        assert Calibration.from_file(tmp_path / name) == c
    lines = body.splitlines()
    n = next(i for i, line in enumerate(lines) if "<rows>" in line)
    lines[n] = lines[n].replace("</rows>", "</rowz>")
    (tmp_path / "broken.xml").write_text("\n".join(lines))
    says = rf"^cannot parse .*broken\.xml as OpenCV YAML/XML: line {n + 1}: Mismatched closing tag$"
    with pytest.raises(ValueError, match=says):
        Calibration.load(tmp_path / "broken.xml")


def test_an_xml_or_yaml_file_after_blank_lines_or_a_bom_is_read(tmp_path: Path) -> None:
    """Blank lines before the ``<?xml ...?>`` declaration made OpenCV read the file as YAML
    ("line 2: Invalid or unsupported syntax"; the file was taken for OpenCV XML), and a UTF-8
    byte-order mark (Windows editors write one) hid the ``<?xml``/``%YAML`` start: "not a
    stereovision calibration file". Each reads as the file without them; an error in the
    indented file is said at the file's own line number."""
    c = raw_calib()
    xml = c.save(tmp_path / "c.xml").read_text()
    yml = c.save(tmp_path / "c.yaml").read_text()
    body = xml.split("\n", 1)[1]
    for name, text in (
        ("blank.xml", "\n\n" + xml),
        ("crlf.xml", ("\n" + xml).replace("\n", "\r\n")),
        ("bom.xml", "\ufeff" + xml),
        ("bom_bare.xml", "\ufeff" + body),
        ("bom.yaml", "\ufeff" + yml),
    ):
        (tmp_path / name).write_bytes(text.encode("utf-8"))
        assert Calibration.load(tmp_path / name) == c, name
        assert Calibration.from_file(tmp_path / name) == c, name
    lines = ("\n\n" + xml).splitlines()
    n = next(i for i, line in enumerate(lines) if "<rows>" in line)
    lines[n] = lines[n].replace("</rows>", "</rowz>")
    (tmp_path / "broken.xml").write_text("\n".join(lines))
    says = rf"^cannot parse .*broken\.xml as OpenCV YAML/XML: line {n + 1}: Mismatched closing tag$"
    with pytest.raises(ValueError, match=says):
        Calibration.load(tmp_path / "broken.xml")


def test_opencv_stereo_calib_names_m1_m2_load_as_k1_k2(tmp_path: Path) -> None:
    """OpenCV's stereo_calib names the camera matrices M1/M2 (in YAML and XML): they load as
    K1/K2, the same rig."""
    c = raw_calib()
    text = c.save(tmp_path / "c.yaml").read_text()
    (tmp_path / "m.yaml").write_text(text.replace("K1:", "M1:").replace("K2:", "M2:"))
    assert Calibration.load(tmp_path / "m.yaml") == c
    xml = c.save(tmp_path / "c.xml").read_text()
    (tmp_path / "m.xml").write_text(re.sub(r"(</?)K([12])([ >])", r"\1M\2\3", xml))
    assert "<M1" in (tmp_path / "m.xml").read_text()
    assert Calibration.load(tmp_path / "m.xml") == c


def test_a_saved_file_without_its_unit_is_refused_not_read_in_metres(tmp_path: Path) -> None:
    """The unit of T is the one number a reader cannot guess (a mm rig read in metres is 1000x
    off): a file without it is refused naming the field, not given a default."""
    rec = json.loads(rect_calib().save(tmp_path / "c.json").read_text())
    del rec["unit"]
    (tmp_path / "e.json").write_text(json.dumps(rec))
    with pytest.raises(ValueError, match=r"e\.json lacks field 'unit'"):
        Calibration.load(tmp_path / "e.json")


def test_a_file_without_its_unit_is_read_in_the_unit_given(tmp_path: Path) -> None:
    """An OpenCV YAML or a JSON without 'unit' (a script's cv::FileStorage) was refused by
    from_file(unit='mm') and depth --calib-unit mm alike: 'lacks field 'unit': add unit', the
    unit given ignored. It is read in that unit now; a file's own unit still wins (refused when
    it disagrees) and without a unit the CLI's refusal names --calib-unit."""
    from stereovision.cli import load_calibration

    cal = rect_calib()
    rec = json.loads(cal.save(tmp_path / "c.json").read_text())
    del rec["unit"]
    (tmp_path / "e.json").write_text(json.dumps(rec))
    fs = cv2.FileStorage(str(tmp_path / "e.yml"), cv2.FILE_STORAGE_WRITE)
    for key in ("K1", "D1", "K2", "D2", "R", "T"):
        fs.write(key, np.asarray(getattr(cal, key), float))
    fs.write("image_width", cal.image_size[0])
    fs.write("image_height", cal.image_size[1])
    fs.release()
    for name in ("e.json", "e.yml"):
        got = Calibration.from_file(tmp_path / name, unit="cm")
        assert got.unit == "cm"
        assert np.array_equal(got.T, cal.T) and np.array_equal(got.K1, cal.K1)
        with pytest.raises(ValueError, match=r"lacks field 'unit'.* \(or give --calib-unit\)$"):
            load_calibration(tmp_path / name)
    with pytest.raises(ValueError, match=r"states its lengths in 'mm', not in the unit 'cm'"):
        Calibration.from_file(tmp_path / "c.json", unit="cm")


@pytest.mark.parametrize(("field", "value"), [("rectified", 2), ("doffs", True)])
def test_a_saved_rectified_rigs_flag_and_doffs_are_checked(
    tmp_path: Path, field: str, value: object
) -> None:
    """rectified=2 is not a flag and doffs=true not a number of pixels (it read as 1 px, the
    rig's own cx2 - cx1 here, so it passed the constructor's check): each is named."""
    k2 = np.array([[500.0, 0.0, 161.0], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    rec = json.loads(rect_calib(K2=k2).save(tmp_path / "c.json").read_text())
    rec[field] = value
    (tmp_path / "e.json").write_text(json.dumps(rec))
    with pytest.raises(ValueError, match=rf"e\.json: {field} must be"):
        Calibration.load(tmp_path / "e.json")


def test_a_camera_matrix_saved_as_a_vector_is_named(tmp_path: Path) -> None:
    """D1, D2 and T may be 1-D (!!opencv-nd-matrix); K1 written so (its 9 numbers in a row) is
    not a camera matrix and is refused as the field that is not a matrix."""
    fs = cv2.FileStorage(str(tmp_path / "c.yaml"), cv2.FILE_STORAGE_WRITE)
    for key, value in raw_calib()._to_record().items():
        fs.write(key, value.ravel().copy() if key == "K1" else value)
    fs.release()
    with pytest.raises(ValueError, match=r"field 'K1' is not a matrix: a !!opencv-nd-matrix"):
        Calibration.load(tmp_path / "c.yaml")


def test_a_kitti_file_without_a_space_after_its_keys_reads_the_same(tmp_path: Path) -> None:
    """A key's colon may touch its first number ("P2:7.2e+02 ..."): the values are the same as
    with the space KITTI's files have, not a key "P2:7.2e+02" that is no key at all."""
    p2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
    p3 = "7.2e+02 0 6.1e+02 -3.6e+02 0 7.2e+02 1.7e+02 0 0 0 1 0"
    (tmp_path / "spaced.txt").write_text(f"P2: {p2}\nP3: {p3}\n")
    (tmp_path / "tight.txt").write_text(f"P2:{p2}\nP3:{p3}\n")
    spaced = Calibration.from_file(tmp_path / "spaced.txt", image_size=(1242, 375))
    assert Calibration.from_file(tmp_path / "tight.txt", image_size=(1242, 375)) == spaced
    assert parse_kitti_calib(tmp_path / "tight.txt")["P3"][3] == -360.0


def test_a_folder_with_a_sizeless_kitti_calib_txt_takes_the_image_size_given(
    tmp_path: Path,
) -> None:
    """A folder's calib.txt is read with the image_size given: an object/odometry KITTI file
    (no S_rect_02) with no image beside it needs it, and was refused as unsized without it."""
    p2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
    p3 = "7.2e+02 0 6.1e+02 -3.6e+02 0 7.2e+02 1.7e+02 0 0 0 1 0"
    (tmp_path / "calib.txt").write_text(f"P2: {p2}\nP3: {p3}\n")
    c = Calibration.from_file(tmp_path, image_size=(1242, 375))
    assert c.image_size == (1242, 375) and c.baseline == pytest.approx(405.0 / 720.0)


def test_a_dataset_file_the_constructor_refuses_is_named(tmp_path: Path) -> None:
    """A Middlebury or KITTI file whose numbers are not a rectified pair (doffs off cx2 - cx1,
    the two focal lengths apart) was refused as "doffs: 31.111 differs from ..." naming no file,
    where a saved calibration's refusal names it; each names its file now."""
    (tmp_path / "calib.txt").write_text(
        "cam0=[3997.684 0 1176.728; 0 3997.684 1011.728; 0 0 1]\n"
        "cam1=[3997.684 0 1307.839; 0 3997.684 1011.728; 0 0 1]\n"
        "doffs=31.111\nbaseline=193.001\nwidth=2964\nheight=1988\n"
    )
    with pytest.raises(
        ValueError, match=r"^Middlebury calibration .*calib\.txt: doffs: 31\.111 differs from"
    ):
        Calibration.from_file(tmp_path / "calib.txt")
    (tmp_path / "k.txt").write_text(
        "P2: 7.2e+02 0 6.1e+02 4.5e+01 0 7.0e+02 1.7e+02 0 0 0 1 0\n"
        "P3: 7.2e+02 0 6.1e+02 -3.6e+02 0 7.2e+02 1.7e+02 0 0 0 1 0\n"
    )
    with pytest.raises(
        ValueError, match=r"^KITTI calibration .*k\.txt: K2: fy = 720 differs from K1's 700"
    ):
        Calibration.from_file(tmp_path / "k.txt", image_size=(1242, 375))


def test_homographies_json_and_damaged_q_and_kitti_files_are_named(tmp_path: Path) -> None:
    """What a mutation audit found unchecked: `stereovision rectify`'s homographies given as a
    calibration are named as such (not 'lacks field image_width'), a Q.dat holding inf is not
    16 finite numbers (it reached the constructor as "K2: contains NaN or inf", no file), and
    a KITTI P2 of 13 values is counted (numpy's reshape error named neither file nor key)."""
    (tmp_path / "h.json").write_text(json.dumps({"H1": [[1.0]], "H2": [[1.0]], "F": [[1.0]]}))
    with pytest.raises(ValueError, match=r"h\.json holds the homographies .* --rectification"):
        Calibration.from_file(tmp_path / "h.json")
    (tmp_path / "Q.dat").write_text("1 0 0 -160\n0 1 0 -120\n0 0 0 500\n0 0 10 inf\n")
    with pytest.raises(ValueError, match=r"Q\.dat: not a Q matrix \(16 finite numbers"):
        Calibration.from_q(tmp_path / "Q.dat", (320, 240))
    p2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
    (tmp_path / "k.txt").write_text(f"P2: {p2} 5\nP3: {p2}\n")
    with pytest.raises(ValueError, match=r"k\.txt: P2 has 13 values, not 12"):
        Calibration.from_kitti(tmp_path / "k.txt", image_size=(1242, 375))


def test_an_object_kitti_file_is_sized_by_the_image_2_png_beside_it(tmp_path: Path) -> None:
    """Without S_rect_02 the size comes from a left.png, else from KITTI's own image_2.png."""
    p2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
    p3 = "7.2e+02 0 6.1e+02 -3.6e+02 0 7.2e+02 1.7e+02 0 0 0 1 0"
    (tmp_path / "000000.txt").write_text(f"P2: {p2}\nP3: {p3}\n")
    cv2.imwrite(str(tmp_path / "image_2.png"), np.zeros((375, 1242), np.uint8))
    assert Calibration.from_file(tmp_path / "000000.txt").image_size == (1242, 375)


def test_opencv_stereo_calib_numbers_the_constructor_refuses_name_the_files(
    tmp_path: Path,
) -> None:
    """An R that is not a rotation in extrinsics.yml was "R: not a rotation matrix", naming
    neither file; the arguments image_size and unit are still refused as themselves."""
    _opencv_stereo_calib(tmp_path)
    fs = cv2.FileStorage(str(tmp_path / "extrinsics.yml"), cv2.FILE_STORAGE_WRITE)
    fs.write("R", 2 * np.eye(3))
    fs.write("T", np.array([[-60.0], [0.0], [0.0]]))
    fs.release()
    files = (tmp_path / "intrinsics.yml", tmp_path / "extrinsics.yml")
    with pytest.raises(
        ValueError,
        match=r"^OpenCV stereo_calib files .*intrinsics\.yml and .*extrinsics\.yml: R: not a rot",
    ):
        Calibration.from_opencv_stereo_calib(*files, (640, 480), "mm")
    with pytest.raises(ValueError, match=r"^unit: expected one of .* got 'yd'$"):
        Calibration.from_opencv_stereo_calib(*files, (640, 480), "yd")
    with pytest.raises(ValueError, match=r"^image_size: expected positive integers"):
        Calibration.from_opencv_stereo_calib(*files, (640, 0), "mm")


def test_loading_a_folder_or_a_binary_file_is_named(tmp_path: Path) -> None:
    """load() of a folder is 'not a file' (a ValueError, not open()'s IsADirectoryError), and
    of a binary file 'not a text calibration file', each naming the path."""
    with pytest.raises(ValueError, match=r"^calibration path is not a file: "):
        Calibration.load(tmp_path)
    (tmp_path / "c.yaml").write_bytes(b"%YAML:1.0\n\xff\xfe\x00")
    with pytest.raises(ValueError, match=r"^not a text calibration file: .*c\.yaml$"):
        Calibration.load(tmp_path / "c.yaml")


def test_a_word_among_a_matrixs_numbers_is_named_not_read_as_zero(tmp_path: Path) -> None:
    """FileNode.real() of a string is 0: a word where K1's skew is was read as a skew of 0."""
    text = raw_calib().save(tmp_path / "c.yaml").read_text()
    k1 = text.index("K1:")
    start = text.index("data: [", k1) + len("data: [")
    comma = text.index(",", start)
    (tmp_path / "w.yaml").write_text(
        text[: comma + 1] + ' "abc",' + text[text.index(",", comma + 1) + 1 :]
    )
    with pytest.raises(ValueError, match=r"field 'K1' is not a matrix: element 1 of data is not"):
        Calibration.load(tmp_path / "w.yaml")


_SKEWED = np.array([[300.0, 5.0, 161.3], [0.0, 302.0, 118.7], [0.0, 0.0, 1.0]])


@pytest.mark.parametrize(
    "fields",
    [
        {"K1": _SKEWED},
        {"T": np.array([0.12, 0.002, 0.003])},
        {"T": np.array([-0.12, 0.0, 0.0]), "unit": "mm"},
    ],
    ids=["skew", "swapped", "tiny"],
)
def test_the_warnings_of_a_calibrations_numbers_point_at_the_callers_line(
    fields: dict[str, object], tmp_path: Path
) -> None:
    """The skew, swapped-cameras and baseline-unit warnings had a fixed ``stacklevel``, right for
    the constructor only: ``load``, ``from_file`` and ``scaled_to`` were attributed to a line of
    calibration.py, ``dataclasses.replace`` to dataclasses.py; each is the caller's line now."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        calib = raw_calib(**fields)
    path = calib.save(tmp_path / "rig.yaml")
    calls = {
        "load": lambda: Calibration.load(path),
        "from_file": lambda: Calibration.from_file(path),
        "replace": lambda: dataclasses.replace(calib, unit=calib.unit),
        "scaled_to": lambda: calib.scaled_to((160, 120)),
    }
    for how, call in calls.items():
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            call()
        # a derived calibration (scaled_to) does not say its baseline again
        want = [] if ("unit" in fields and how == "scaled_to") else [__file__]
        assert [w.filename for w in caught] == want, (how, [str(w.message) for w in caught])


@pytest.mark.parametrize("alpha", [5.0, -1, "1"])
@pytest.mark.parametrize("rectified", [False, True])
def test_alpha_out_of_range_is_refused_whatever_the_calibration(
    alpha: object, rectified: bool
) -> None:
    """valid_roi, rectify and rectify_points checked alpha after returning early for a rectified
    calibration (and rectify_points for no points): alpha=5 or "1" passed there without a word,
    while the same call on a raw rig was refused; rectified_calibration likewise took "1" of a
    rectified one. Refused now before any early return."""
    c = rect_calib() if rectified else raw_calib()
    img = np.zeros((SIZE[1], SIZE[0]), np.uint8)
    says = re.escape(f"alpha: expected a value in [0, 1], got {alpha!r}")
    for call in (
        lambda: c.valid_roi(alpha),  # type: ignore[arg-type]
        lambda: c.rectify(img, img, alpha=alpha),  # type: ignore[arg-type]
        lambda: c.rectify_points(np.array([[10.0, 20.0]]), alpha=alpha),  # type: ignore[arg-type]
        lambda: c.rectify_points(np.zeros((0, 2)), alpha=alpha),  # type: ignore[arg-type]
        lambda: c.to_ros(alpha=alpha),  # type: ignore[arg-type]
    ):
        with pytest.raises(ValueError, match=says):
            call()
    if isinstance(alpha, str):
        with pytest.raises(ValueError, match=r"^alpha: expected a finite number, got '1'$"):
            c.rectified_calibration(alpha)  # type: ignore[arg-type]
    else:  # OpenCV's scaling: any finite number
        assert c.rectified_calibration(alpha).rectified


# ------------------------------------------------------------ second mutation audit (round 2)


def test_a_fisheye_rig_scaled_stays_fisheye_and_differs_from_its_pinhole_twin() -> None:
    """scaled_to dropping ``model`` made a scaled fisheye rig a pinhole one (4 coefficients
    are a valid pinhole D), and == ignoring ``model`` called the two the same rig."""
    d = np.array([0.05, -0.01, 0.002, -0.0005])
    fish = raw_calib(D1=d, D2=d, model="fisheye")
    half = fish.scaled_to((160, 120))
    assert half.model == "fisheye" and np.array_equal(half.D1, d)
    assert fish != raw_calib(D1=d, D2=d) and fish == raw_calib(D1=d, D2=d, model="fisheye")


def test_rectify_remaps_both_images_bilinearly() -> None:
    """rectify's documented cv2.remap interpolation is bilinear, for the right image too."""
    c = raw_calib()
    rng = np.random.default_rng(5)
    left = rng.integers(0, 256, (SIZE[1], SIZE[0]), dtype=np.uint8)
    right = rng.integers(0, 256, (SIZE[1], SIZE[0]), dtype=np.uint8)
    m1x, m1y, m2x, m2y = c._maps(0.0)
    rl, rr = c.rectify(left, right)
    assert np.array_equal(rl, cv2.remap(left, m1x, m1y, cv2.INTER_LINEAR))
    assert np.array_equal(rr, cv2.remap(right, m2x, m2y, cv2.INTER_LINEAR))


def test_a_rig_mostly_vertical_is_refused_and_not_warned_swapped() -> None:
    """A baseline 53 degrees from the rows (T = (-6, -8, 0) cm) is rectified by OpenCV to a
    vertical one: refused as vertical. A vertical rig whose small T[0] is positive is not a
    left-right pair the other way round: no 'swapped' warning."""
    import warnings

    with pytest.raises(ValueError, match=r"^R, T: the rig is vertical \(stereoRectify"):
        raw_calib(T=np.array([-0.06, -0.08, 0.0])).rectified_calibration()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        raw_calib(T=np.array([0.01, -0.12, 0.0]))
    with pytest.warns(UserWarning, match="the right camera sits to the left"):
        raw_calib(T=np.array([0.12, 0.0, 0.0]))


def test_describe_at_a_doffs_that_puts_a_disparity_at_infinity() -> None:
    """doffs -64 px: a disparity of 64 px is at infinity, no nearest depth (it divided by
    zero); doffs -1 px: 1 px is at infinity, the farthest depth is at 2 px."""
    k1 = np.array([[500.0, 0.0, 160.0], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    for doffs in (-64.0, -1.0):
        k2 = k1.copy()
        k2[0, 2] += doffs
        text = rect_calib(K2=k2).describe()
        if doffs == -64.0:
            assert "nearest depth a disparity range reaches: 128 px 78.1 cm, 256 px 26.0 cm" in text
        else:
            assert text.splitlines()[-1] == (
                "farthest depth, at a disparity of 2.00 px (1 px above infinity's 1.00 px): 50.00 m"
            )


def test_rectify_points_of_a_rectified_rig_are_a_copy() -> None:
    pts = np.array([[10.0, 20.0], [30.5, 40.25]])
    out = rect_calib().rectify_points(pts)
    assert np.array_equal(out, pts) and not np.shares_memory(out, pts)


def test_ideal_refuses_an_infinite_baseline_by_name() -> None:
    with pytest.raises(ValueError, match=r"^baseline_m: expected a positive number of metres"):
        Calibration.ideal((640, 480), 90.0, float("inf"))
    # |T| of a 1e-300 m baseline underflows to 0: it was "T: zero baseline", naming no argument
    with pytest.raises(ValueError, match=r"^baseline_m: .* got 1e-300 \(too small to compute"):
        Calibration.ideal((640, 480), 90.0, 1e-300)
    with pytest.warns(UserWarning, match=r"^baseline 1e-150 m, shorter than any stereo rig"):
        assert Calibration.ideal((640, 480), 90.0, 1e-150).baseline_m == 1e-150


def test_from_q_reads_a_negative_multiple_and_refuses_a_q31(tmp_path: Path) -> None:
    """-Q is the same homogeneous matrix as Q (divided by its Q[0,0] = -1); a Q[3,1] other
    than 0 is not a rectified Q and is named."""
    k1 = np.array([[500.0, 0.0, 150.0], [0.0, 500.0, 120.0], [0.0, 0.0, 1.0]])
    k2 = k1.copy()
    k2[0, 2] = 162.5
    rig = rect_calib(K1=k1, K2=k2, T=np.array([-0.1, 0.0, 0.0]), unit="m")

    def write(q: np.ndarray) -> Path:
        (tmp_path / "Q.dat").write_text("\n".join(" ".join(repr(float(v)) for v in r) for r in q))
        return tmp_path / "Q.dat"

    back = Calibration.from_q(write(-rig.Q), SIZE)
    np.testing.assert_allclose(back.Q, rig.Q, atol=1e-12)
    assert back.doffs_px == pytest.approx(12.5, abs=1e-9)
    q = rig.Q.copy()
    q[3, 1] = 0.5
    with pytest.raises(ValueError, match=r"not a rectified Q matrix: Q\[3,1\] = 0\.5, expected 0$"):
        Calibration.from_q(write(q), SIZE)


def test_from_kitti_refuses_cameras_2_and_3_swapped(tmp_path: Path) -> None:
    """P3's x offset left of P2's (the files' cameras swapped) is a negative baseline: refused
    by name, not read as its absolute value."""
    p2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
    p3 = "7.2e+02 0 6.1e+02 -3.6e+02 0 7.2e+02 1.7e+02 0 0 0 1 0"
    (tmp_path / "calib.txt").write_text(f"P2: {p3}\nP3: {p2}\n")
    with pytest.raises(ValueError, match=r"baseline \(P2\[0, 3\] - P3\[0, 3\]\) / f in .*calib"):
        Calibration.from_kitti(tmp_path / "calib.txt", image_size=(1242, 375))


def _roi_of(invalid: list[tuple[int, int]], size: tuple[int, int] = (10, 8)) -> tuple:
    """:func:`_inner_rectangle` of an identity map of ``size`` with ``(y, x)`` pixels sent out."""
    w, h = size
    my, mx = np.mgrid[0:h, 0:w].astype(np.float32)
    for y, x in invalid:
        mx[y, x] = -5.0
    return _inner_rectangle(mx, my, size)


@pytest.mark.parametrize(
    ("invalid", "expected"),
    [
        ([], (0, 0, 10, 8)),
        ([(0, x) for x in range(5)], (0, 1, 10, 7)),  # top row worst: dropped
        ([(7, x) for x in range(5)], (0, 0, 10, 7)),  # bottom row
        ([(y, 0) for y in range(5)], (1, 0, 9, 8)),  # left column
        ([(y, 9) for y in range(5)], (0, 0, 9, 8)),  # right column
        # right column 3 (its bottom pixel counted), bottom row 3: the bottom first (a tie),
        # then the right column; a 9x7 rectangle, not 10x5
        ([(5, 9), (6, 9), (7, 9), (7, 0), (7, 1)], (0, 0, 9, 7)),
        ([(y, x) for y in range(8) for x in range(10) if x != 3], (3, 0, 1, 8)),  # one column
        ([(y, x) for y in range(8) for x in range(10)], (0, 0, 0, 0)),  # nothing valid
    ],
)
def test_inner_rectangle_drops_the_worst_side_first(invalid: list, expected: tuple) -> None:
    """The all-valid rectangle shrinks on the side with most invalid pixels (a mutation audit
    found _inner_rectangle's sides, its width/height and its empty cases unasserted)."""
    assert _roi_of(invalid) == expected


def test_inner_rectangle_takes_the_last_pixel_and_not_beyond() -> None:
    """A source coordinate of exactly 0 or w - 1 (h - 1) is inside the image; half a pixel
    beyond either edge is not (remap would read the border there)."""
    size = (10, 8)
    my, mx = np.mgrid[0:8, 0:10].astype(np.float32)
    assert _inner_rectangle(mx, my, size) == (0, 0, 10, 8)
    for arr, idx, value, expected in (
        (mx, (slice(None), 9), 9.5, (0, 0, 9, 8)),
        (mx, (slice(None), 0), -0.5, (1, 0, 9, 8)),
        (my, (7, slice(None)), 7.5, (0, 0, 10, 7)),
        (my, (0, slice(None)), -0.5, (0, 1, 10, 7)),
    ):
        saved = arr[idx].copy()
        arr[idx] = value
        assert _inner_rectangle(mx, my, size) == expected
        arr[idx] = saved


def test_from_file_reads_an_indented_middlebury_calib(data_dir: Path, tmp_path: Path) -> None:
    """Middlebury lines with leading blanks are still its calib.txt (a mutation audit found the
    detection's ``^\\s*cam0=`` unasserted: without the blanks they were an unknown format)."""
    src = data_dir / "eth3d" / "terrace" / "calib.txt"
    indented = tmp_path / "calib.txt"
    indented.write_text("".join(f"  {line}\n" for line in src.read_text().splitlines()))
    assert Calibration.from_file(indented) == Calibration.from_file(src)


def test_a_middlebury_calib_saved_with_a_byte_order_mark_reads(
    data_dir: Path, tmp_path: Path
) -> None:
    """A calib.txt saved by Windows Notepad (a UTF-8 BOM, CRLF lines) was "calib.txt:1:
    expected key=value, got '\\ufeffcam0=[...]'" from from_middlebury, from_file (the CLI's
    --calib) and load_scene (eval's scenes): parse_middlebury_calib read it again without the
    "-sig" that from_middlebury's own reading has. It reads as the file without them."""
    from stereovision.baselines import round_up16
    from stereovision.calibration import parse_middlebury_calib
    from stereovision.io import load_scene

    scene = data_dir / "eth3d" / "terrace"
    src = scene / "calib.txt"
    noted = tmp_path / "terrace"
    noted.mkdir()
    for name in ("left.png", "right.png"):
        (noted / name).write_bytes((scene / name).read_bytes())
    calib = noted / "calib.txt"
    calib.write_bytes(b"\xef\xbb\xbf" + src.read_bytes().replace(b"\n", b"\r\n"))
    assert Calibration.from_middlebury(calib) == Calibration.from_middlebury(src)
    assert Calibration.from_file(calib) == Calibration.from_file(src)
    assert parse_middlebury_calib(calib).keys() == parse_middlebury_calib(src).keys()
    loaded = load_scene(noted)
    assert loaded.calib == Calibration.from_middlebury(src)
    # no GT in the copy, and calib.txt's ndisp is ETH3D's width (713 px), a range the images
    # have no room for (03f71efe): the width's rule, round_up16(713 // 4)
    assert parse_middlebury_calib(calib)["ndisp"] == parse_middlebury_calib(src)["ndisp"] == 713
    assert loaded.max_disparity == round_up16(713 // 4) == 192


def test_a_middlebury_key_given_twice_is_refused(data_dir: Path, tmp_path: Path) -> None:
    """A calib.txt edited by hand with a second baseline= line (the old one kept) was read
    with the last one, without a word: 1 mm instead of 193 mm is depth 193 times off."""
    src = data_dir / "eth3d" / "terrace" / "calib.txt"
    lines = src.read_text().splitlines()
    twice = tmp_path / "calib.txt"
    twice.write_text("\n".join([*lines, "", "baseline=1"]) + "\n")
    n = next(i for i, line in enumerate(lines, 1) if line.startswith("baseline="))
    with pytest.raises(ValueError) as err:
        Calibration.from_middlebury(twice)
    assert str(err.value) == (
        f"{twice}:{len(lines) + 2}: baseline given again (first on line {n}); keep one of them"
    )


def test_from_kitti_reads_the_grey_pair_when_asked(tmp_path: Path) -> None:
    """KITTI's files hold four cameras; from_kitti read the colour pair (2, 3) alone, so the
    grey sequences (image_0/ + image_1/, the odometry benchmark's) got the colour pair's
    baseline: 0.5323 against 0.5372 m on odometry sequence 00, depth 0.9 % off without a word.
    cameras=(0, 1) reads theirs, from the odometry file (P0, P1) and the raw one (P_rect_00,
    P_rect_01, S_rect_00)."""
    f = 7.188560e02

    def p(tx: float, ty: float = 0.0, tz: float = 0.0) -> str:
        return f"{f} 0 607.1928 {tx} 0 {f} 185.2157 {ty} 0 0 1 {tz}"

    odo = tmp_path / "calib.txt"
    odo.write_text(
        f"P0: {p(0.0)}\nP1: {p(-386.1448)}\nP2: {p(45.38225, -0.1130887, 0.003779761)}\n"
        f"P3: {p(-337.2877, 2.369057, 0.004915215)}\n"
    )
    colour = Calibration.from_kitti(odo, image_size=(1241, 376))
    grey = Calibration.from_kitti(odo, image_size=(1241, 376), cameras=(0, 1))
    assert colour.baseline_m == pytest.approx((45.38225 + 337.2877) / f, rel=1e-12)
    assert grey.baseline_m == pytest.approx(386.1448 / f, rel=1e-12)
    raw = tmp_path / "calib_cam_to_cam.txt"
    raw.write_text(
        f"S_rect_00: 1.241e+03 3.76e+02\nP_rect_00: {p(0.0)}\nP_rect_01: {p(-386.1448)}\n"
    )
    assert Calibration.from_kitti(raw, cameras=(0, 1)) == grey
    # a pair taken from an array (np.int64) was refused as not two of cameras 0-3
    assert Calibration.from_kitti(raw, cameras=tuple(np.array([0, 1]))) == grey
    with pytest.raises(ValueError, match=r"cameras: expected two of KITTI's cameras 0-3"):
        Calibration.from_kitti(raw, cameras=(np.True_, np.int64(1)))
    with pytest.raises(ValueError, match=r"lacks P_rect_02/P_rect_03 \(or P2/P3\)"):
        Calibration.from_kitti(raw)
    with pytest.raises(ValueError, match=r"cameras: expected two of KITTI's cameras 0-3"):
        Calibration.from_kitti(odo, image_size=(1241, 376), cameras=(1, 1))
    # a NumPy array (cameras=np.array([0, 1])) was refused as not two of cameras 0-3; any
    # sequence of two integers is the pair, anything else is refused naming it by its values
    for given in (np.array([0, 1]), np.array([0, 1], np.uint8), range(2), [np.int64(0), 1]):
        assert Calibration.from_kitti(raw, cameras=given) == grey  # type: ignore[arg-type]
    for bad, shown in (
        (np.array([0, 5]), r"\[0, 5\]"),
        ((np.int64(0), np.int64(5)), r"\(0, 5\)"),  # not "(np.int64(0), np.int64(5))"
        ([np.int64(0), np.int64(5)], r"\[0, 5\]"),  # a list too, not "[np.int64(0), ...]"
        (np.array([[0, 1]]), r"\[\[0, 1\]\]"),
        (np.array([0.0, 1.0]), r"\[0\.0, 1\.0\]"),
        ("01", "'01'"),
        (np.array([0, 1, 2]), r"\[0, 1, 2\]"),
    ):
        with pytest.raises(
            ValueError, match=r"^cameras: expected two of KITTI's cameras 0-3 .*got "
        ):
            Calibration.from_kitti(raw, cameras=bad)  # type: ignore[arg-type]
        with pytest.raises(ValueError, match=shown + "$"):
            Calibration.from_kitti(raw, cameras=bad)  # type: ignore[arg-type]


def test_a_numpy_string_unit_is_said_as_its_text(tmp_path: Path) -> None:
    """A unit read from an array (``np.str_``) was said by repr: "got np.str_('yd')", and a valid
    one stayed an np.str_, so the baseline warning read "unit=np.str_('cm')"."""
    with pytest.raises(ValueError, match=r"got 'yd'$"):
        raw_calib(unit=np.str_("yd"))
    with pytest.raises(ValueError, match=r"got \['m'\]$"):  # was "unhashable type: 'list'"
        raw_calib(unit=["m"])
    with pytest.warns(UserWarning, match=r"unit='cm'\?"):
        calib = raw_calib(unit=np.str_("cm"), T=np.array([-5000.0, 0.0, 0.0]))
    assert type(calib.unit) is str
    saved = tmp_path / "rig.json"
    rect_calib().save(saved)
    with pytest.raises(ValueError, match=r"got 'yd'$"):
        Calibration.from_file(saved, unit=np.str_("yd"))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"not in the unit 'cm' given"):
        Calibration.from_file(saved, unit=np.str_("cm"))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^unit: expected one of .* got 'yd'$"):
        Calibration.from_opencv_stereo_calib(
            tmp_path / "i.yml", tmp_path / "e.yml", (640, 480), np.str_("yd")
        )


def test_from_file_takes_a_numpy_image_size_for_a_q_dat(data_dir: Path) -> None:
    """A Q.dat's ``image_size`` given as a NumPy array (a frame's ``shape[1::-1]``) raised NumPy's
    "truth value of an array ... is ambiguous" (``image_size or`` the scene's size); it is read as
    the same size given as a tuple, for the file and for its folder."""
    import numpy as np

    q = next(p for p in sorted(data_dir.rglob("Q.dat")) if (p.parent / "left.png").is_file())
    for where in (q, q.parent):
        as_tuple = Calibration.from_file(where, image_size=(320, 240))
        as_array = Calibration.from_file(where, image_size=np.array([320, 240]))
        assert as_array == as_tuple
        assert as_array.image_size == (320, 240)


def test_a_vertical_rig_is_refused_by_rectify_as_by_rectified_calibration(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A vertical rig (a ROS or Kalibr file, or calibrate's own result in Python) was rectified
    by rectify() to columns without a word, though it says rows, and everything after it
    (rectified_calibration, describe, depth) refuses the rig: `stereovision check --calib`
    then said "pair NOT rectified ... the calibration no longer rectifies this rig:
    recalibrate". rectify() and rectify_points() now refuse it as rectified_calibration()
    does, for the pinhole and the fisheye model; a side-by-side rig is rectified as before."""
    from stereovision.cli import main
    from stereovision.rectification_check import check_rectification

    rng = np.random.default_rng(3)
    img = rng.integers(0, 255, (SIZE[1], SIZE[0]), dtype=np.uint8)
    vertical = r"^R, T: the rig is vertical \((fisheye )?stereoRectify"
    d = np.array([0.01, -0.002, 0.0003, 0.0])
    for cal in (
        raw_calib(T=np.array([0.002, -0.12, 0.003])),
        raw_calib(T=np.array([0.002, -0.12, 0.003]), D1=d, D2=d, model="fisheye"),
    ):
        with pytest.raises(ValueError, match=vertical):
            cal.rectified_calibration()
        with pytest.raises(ValueError, match=vertical):
            cal.rectify(img, img)
        with pytest.raises(ValueError, match=vertical):
            cal.rectify(img, img, alpha=1.0)
        for side in ("left", "right"):
            with pytest.raises(ValueError, match=vertical):
                cal.rectify_points([[10.0, 20.0]], side)
            with pytest.raises(ValueError, match=vertical):
                cal.rectify_points(np.zeros((0, 2)), side)
        with pytest.raises(ValueError, match=vertical):
            check_rectification(img, img, calib=cal)
    cal = raw_calib(T=np.array([0.002, -0.12, 0.003]))
    cal.save(tmp_path / "vertical.yaml")
    cv2.imwrite(str(tmp_path / "left.png"), img)
    cv2.imwrite(str(tmp_path / "right.png"), np.roll(img, 5, axis=0))
    pair = [str(tmp_path / "left.png"), str(tmp_path / "right.png")]
    capsys.readouterr()
    assert main(["check", *pair, "--calib", str(tmp_path / "vertical.yaml")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("stereovision: error: R, T: the rig is vertical")
    assert err.count("\n") == 1
    # a side-by-side rig: unchanged
    side_by_side = raw_calib()
    rl, rr = side_by_side.rectify(img, img)
    assert rl.shape == img.shape and rl.dtype == np.uint8 and rl.any()
    m = side_by_side._maps(0.0)
    assert np.array_equal(rl, cv2.remap(img, m[0], m[1], cv2.INTER_LINEAR))
    assert np.array_equal(rr, cv2.remap(img, m[2], m[3], cv2.INTER_LINEAR))
    p = side_by_side.rectify_points([[10.0, 20.0]], "right")
    assert p.shape == (1, 2) and np.all(np.isfinite(p))


def test_from_file_refuses_a_bytes_path_naming_the_argument(tmp_path):
    """Calibration.from_file(b'calib.txt') gave pathlib's TypeError ("argument should be a str
    object or an os.PathLike object returning str, not <class 'bytes'>"), naming no argument;
    the library's paths are str or os.PathLike: refused naming path, the name decoded."""
    with pytest.raises(TypeError) as info:
        Calibration.from_file(os.fsencode(tmp_path / "calib.txt"))
    assert str(info.value) == (
        f"path: expected a str or os.PathLike file name, got the bytes "
        f"{str(tmp_path / 'calib.txt')!r}: decode it first (os.fsdecode(path))"
    )


def test_calib_parsers_and_save_ros_refuse_a_bytes_or_empty_name_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """parse_middlebury_calib, parse_kitti_calib and save_ros, missed when the other readers and
    writers took _validate.as_path: a bytes name gave pathlib's TypeError ("argument should be
    a str object or an os.PathLike object returning str, not <class 'bytes'>"), naming no
    argument, and parse_middlebury_calib('') said "Middlebury calibration not found: ."."""
    monkeypatch.chdir(tmp_path)
    name = tmp_path / "calib.txt"
    for call, arg in (
        (lambda: parse_middlebury_calib(os.fsencode(name)), "path"),
        (lambda: parse_kitti_calib(os.fsencode(name)), "path"),
        (lambda: raw_calib().save_ros(os.fsencode(name)), "directory"),
    ):
        with pytest.raises(TypeError) as info:
            call()
        assert str(info.value) == (
            f"{arg}: expected a str or os.PathLike file name, got the bytes {str(name)!r}: "
            f"decode it first (os.fsdecode({arg}))"
        )
    for parse in (parse_middlebury_calib, parse_kitti_calib):
        with pytest.raises(ValueError) as err:
            parse("")
        assert str(err.value) == "path: expected a file name, got ''"
    assert not list(tmp_path.iterdir())  # nothing written


def test_rectify_gives_a_one_channel_image_back_in_its_shape() -> None:
    """An (H, W, 1) pair came back (H, W) from a raw rig's rectify (cv2.remap drops the channel
    axis) but (H, W, 1) from a rectified rig's, though rectify says same shapes as the inputs:
    it is (H, W, 1) both ways, the values those of the (H, W) pair's."""
    c = raw_calib()
    rng = np.random.default_rng(7)
    left = rng.integers(0, 256, (SIZE[1], SIZE[0]), dtype=np.uint8)
    right = rng.integers(0, 256, (SIZE[1], SIZE[0]), dtype=np.uint8)
    flat = c.rectify(left, right)
    for out, grey in zip(c.rectify(left[:, :, None], right[:, :, None]), flat, strict=True):
        assert out.shape == (SIZE[1], SIZE[0], 1) and out.dtype == np.uint8
        np.testing.assert_array_equal(out[:, :, 0], grey)
    assert rect_calib().rectify(left[:, :, None], right)[0].shape == (SIZE[1], SIZE[0], 1)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs os.mkfifo")
def test_a_folder_whose_calibration_is_a_fifo_says_so(tmp_path: Path) -> None:
    """A scene folder whose Q.dat (or calib.txt, or a ROS left.yaml/right.yaml) is a FIFO or a
    folder was said to be 'a folder without left.yaml and right.yaml (ROS camera_info),
    calib.txt or Q.dat', a file the user could see there; it is said not to be a file, as the
    file given alone is. Nothing is opened: a FIFO read would block."""
    for names in (("Q.dat",), ("calib.txt",), ("left.yaml", "right.yaml")):
        folder = tmp_path / names[0].replace(".", "_")
        folder.mkdir()
        for name in names:
            os.mkfifo(folder / name)
        with pytest.raises(
            ValueError, match=rf"^calibration path is not a file: {re.escape(str(folder))}/"
        ):
            Calibration.from_file(folder)
    (tmp_path / "dir" / "calib.txt").mkdir(parents=True)
    with pytest.raises(ValueError, match=r"^calibration path is not a file: .*dir/calib\.txt$"):
        Calibration.from_file(tmp_path / "dir")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match=r"is a folder without left\.yaml and right\.yaml"):
        Calibration.from_file(tmp_path / "empty")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs os.mkfifo")
def test_the_public_parsers_say_a_fifo_a_folder_or_a_link_to_nothing_as_imread_does(
    tmp_path: Path,
) -> None:
    """parse_middlebury_calib and parse_kitti_calib said a FIFO and a folder "not found", a
    file that is there, and a link whose target moved without the link: in imread's words now
    (the FIFO not opened), a missing file as before."""
    os.mkfifo(tmp_path / "pipe.txt")
    (tmp_path / "gone.txt").symlink_to("moved.txt")
    (tmp_path / "dir").mkdir()
    for parse, who in ((parse_middlebury_calib, "Middlebury"), (parse_kitti_calib, "KITTI")):
        for name in ("pipe.txt", "dir"):
            with pytest.raises(ValueError) as info:
                parse(tmp_path / name)
            assert str(info.value) == f"{who} calibration is not a regular file: {tmp_path / name}"
        with pytest.raises(FileNotFoundError) as gone:
            parse(tmp_path / "gone.txt")
        assert str(gone.value) == (
            f"{who} calibration not found: {tmp_path / 'gone.txt'} (a link to moved.txt, which "
            "does not exist)"
        )
        with pytest.raises(FileNotFoundError, match=f"^{who} calibration not found: .*none"):
            parse(tmp_path / "none.txt")


def test_a_calibration_link_to_nothing_names_its_target_in_a_folder_or_alone(
    tmp_path: Path,
) -> None:
    """A scene folder whose Q.dat (or calib.txt) is a link whose target moved was said to be 'a
    folder without left.yaml and right.yaml (ROS camera_info), calib.txt or Q.dat' (the file
    c26efd0 named for a FIFO there), and the link given alone 'calibration file not found:
    Q.dat', without the link: both now say it as imread does, naming the missing target."""
    for name in ("Q.dat", "calib.txt"):
        folder = tmp_path / name.replace(".", "_")
        folder.mkdir()
        (folder / name).symlink_to(tmp_path / "moved" / name)
        said = (
            f"calibration file not found: {folder / name} (a link to "
            f"{tmp_path / 'moved' / name}, which does not exist)"
        )
        for given in (folder, folder / name):
            with pytest.raises(FileNotFoundError) as info:
                Calibration.from_file(given)
            assert str(info.value) == said
    with pytest.raises(FileNotFoundError) as plain:
        Calibration.from_file(tmp_path / "none.yaml")  # no link: said as before
    assert str(plain.value) == f"calibration file not found: {tmp_path / 'none.yaml'}"


def test_describe_refuses_depths_without_a_depth_step() -> None:
    """describe(depths=...) said a negative depth's step ('at -1 m 2.3 cm'), NaN's ('at nan m
    none'), an empty tuple as a line without steps, and one number was TypeError "'float'
    object is not iterable"; each is a ValueError naming depths, the default unchanged."""
    c = rect_calib()
    assert c.describe((1.0, 2)).splitlines() == c.describe((1.0, 2.0)).splitlines()
    for bad, said in (
        ((-1.0,), r"depths: expected a positive finite number, got -1\.0"),
        ((float("nan"),), r"depths: expected a positive finite number, got nan"),
        ((0.0, 1.0), r"depths: expected a positive finite number, got 0\.0"),
        ((), r"depths: expected at least one depth in metres, got none"),
        (5.0, r"depths: expected a sequence of depths in metres, got 5\.0"),
        ("5", r"depths: expected a sequence of depths in metres, got '5'"),
        # Iterable, but "iteration over a 0-d array" (TypeError)
        (np.array(5.0), r"depths: expected a sequence of depths in metres, got array\(5\.\)"),
    ):
        with pytest.raises(ValueError, match=rf"^{said}$"):
            c.describe(bad)  # type: ignore[arg-type]
    assert "at 1 m " in c.describe()


def test_from_file_refuses_an_empty_path_by_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Calibration.from_file('') was read as the current folder ('calibration path . is a
    folder without left.yaml and right.yaml ...', or a calib.txt there read unasked), where
    Calibration.load('') and the parsers name the empty path."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "calib.txt").write_text("x")
    with pytest.raises(ValueError) as err:
        Calibration.from_file("")
    assert str(err.value) == "path: expected a file name, got ''"


def test_a_q_dat_with_a_byte_order_mark_is_sized_by_the_commands_pair(tmp_path: Path) -> None:
    """A Q.dat saved by a Windows editor (a UTF-8 BOM) is read by from_file, but its check of
    a Q.dat read it without the "-sig": ``depth l.png r.png --calib q.dat`` refused it ("does
    not give the image size ...: this command cannot read it from its images") where the file
    without the mark is sized by the pair, and ``info --size`` left out its size line."""
    from stereovision.calibration import _sizeless
    from stereovision.cli import load_calibration

    text = b"1 0 0 -32\n0 1 0 -24\n0 0 0 50\n0 0 10 0\n"
    plain, marked = tmp_path / "q.dat", tmp_path / "qb.dat"
    plain.write_bytes(text)
    marked.write_bytes(b"\xef\xbb\xbf" + text.replace(b"\n", b"\r\n"))
    assert _sizeless(marked) and _sizeless(plain)
    pair = np.zeros((48, 64), np.uint8)
    got = load_calibration(marked, pair=pair)
    assert got.image_size == (64, 48)
    assert got == load_calibration(plain, pair=pair)


def test_a_kitti_file_with_a_byte_order_mark_keeps_its_first_key(tmp_path: Path) -> None:
    """An odometry calib.txt saved by a Windows editor (a UTF-8 BOM) lost its first key, P0
    (read as '\\ufeffP0'): from_kitti(cameras=(0, 1)) said it "lacks P_rect_00/P_rect_01 (or
    P0/P1)" and batch read its grey pairs as the colour pair (depth 0.9 % off, unsaid). Read
    as the file without the mark, as the Middlebury and Q.dat readers read it."""
    from stereovision.calibration import parse_kitti_calib

    def p(tx: float) -> str:
        return f"718.856 0 607.1928 {tx} 0 718.856 185.2157 0 0 0 1 0"

    text = f"P0: {p(0.0)}\nP1: {p(-386.1448)}\nP2: {p(45.38225)}\nP3: {p(-337.2877)}\n"
    plain, marked = tmp_path / "plain.txt", tmp_path / "marked.txt"
    plain.write_text(text)
    marked.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    assert list(parse_kitti_calib(marked)) == ["P0", "P1", "P2", "P3"]
    grey = Calibration.from_kitti(marked, image_size=(1241, 376), cameras=(0, 1))
    assert grey == Calibration.from_kitti(plain, image_size=(1241, 376), cameras=(0, 1))


def test_from_q_reads_commas_and_brackets_and_names_what_is_no_number(tmp_path: Path) -> None:
    """A Q.dat of ``np.savetxt(..., delimiter=',')`` or a pasted ``Q.tolist()`` was refused as
    "not a Q matrix (16 numbers expected)" without a reason; commas, semicolons and brackets
    part the entries, and an entry that is no number is named."""
    q = np.array([[1, 0, 0, -5], [0, 1, 0, -4], [0, 0, 0, 100], [0, 0, 10, 0]], dtype=float)
    plain = tmp_path / "plain.dat"
    np.savetxt(plain, q)
    want = Calibration.from_q(plain, (10, 8))
    np.savetxt(tmp_path / "comma.dat", q, delimiter=",")
    (tmp_path / "list.dat").write_text(str(q.tolist()))
    (tmp_path / "matlab.dat").write_text("[1 0 0 -5; 0 1 0 -4; 0 0 0 100; 0 0 10 0]")
    for name in ("comma.dat", "list.dat", "matlab.dat"):
        got = Calibration.from_q(tmp_path / name, (10, 8))
        assert (got.K1 == want.K1).all() and (got.T == want.T).all(), name
    assert Calibration.from_file(tmp_path / "comma.dat", image_size=(10, 8)).K1[0, 0] == 100
    (tmp_path / "Q.dat").write_text("Q = 1 0 0 -5 0 1 0 -4 0 0 0 100 0 0 10 0")
    with pytest.raises(
        ValueError, match=r"Q\.dat: not a Q matrix \(16 numbers expected, got 'Q'\)$"
    ):
        Calibration.from_q(tmp_path / "Q.dat", (10, 8))


def test_a_q_dat_with_np_savetxt_header_is_read(tmp_path: Path) -> None:
    """np.savetxt(path, Q, header=...) writes '# ...' lines, which np.loadtxt skips: from_q
    said "not a Q matrix (16 numbers expected, got '#')", from_file 'unrecognised calibration
    format'. A '#' starts a comment, to the end of its line."""
    q = np.array([[1, 0, 0, -5], [0, 1, 0, -4], [0, 0, 0, 100], [0, 0, 10, 0]], dtype=float)
    np.savetxt(tmp_path / "plain.dat", q)
    want = Calibration.from_q(tmp_path / "plain.dat", (10, 8))
    np.savetxt(tmp_path / "Q.dat", q, header="Q of cv2.stereoRectify\nrig 2", footer="end")
    got = Calibration.from_q(tmp_path / "Q.dat", (10, 8))
    assert (got.K1 == want.K1).all() and (got.T == want.T).all()
    got = Calibration.from_file(tmp_path / "Q.dat", image_size=(10, 8))
    assert (got.K1 == want.K1).all() and (got.T == want.T).all()


def test_middlebury_calib_skips_comments(tmp_path: Path) -> None:
    """A calib.txt with a '# comment' line or a note after a value was refused: "calib.txt:1:
    expected key=value, got '# ...'"; the rest of a line from '#' on is skipped."""
    (tmp_path / "calib.txt").write_text(
        "# my rig, 2026-12-07\n"
        "cam0=[500 0 320; 0 500 240; 0 0 1]  # left\n"
        "cam1=[500 0 320; 0 500 240; 0 0 1]\n"
        "doffs=0\nbaseline=100 # mm\nwidth=640\nheight=480\n"
    )
    v = parse_middlebury_calib(tmp_path / "calib.txt")
    assert v["baseline"] == 100.0 and v["cam0"][0, 2] == 320.0 and "#" not in str(v.keys())
    assert Calibration.from_file(tmp_path / "calib.txt").baseline == 100.0


def test_a_plain_yaml_reads_numbers_written_without_a_point(tmp_path: Path) -> None:
    """PyYAML (YAML 1.1) reads ``1e-3`` (no '.', or an unsigned exponent) as a string: a plain
    YAML's ``doffs: 1e-3`` was "doffs must be a number, got '1e-3'", and such a number in a
    matrix failed too; every scalar field and matrix entry reads it as a number."""
    rig = tmp_path / "rig.yaml"
    rig.write_text(
        "image_width: 640\nimage_height: 480\nunit: m\nrectified: 1\ndoffs: 1e-3\n"
        "K1: [[5e2, 0, 320], [0, 5E+2, 240], [0, 0, 1]]\nD1: [0, 0, 0, 0, 0]\n"
        "K2: [[5e2, 0, 320], [0, 5E+2, 240], [0, 0, 1]]\nD2: [0, 0, 0, 0, 0]\n"
        "R: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\nT: [-1e-1, 0, 0]\n"
    )
    c = Calibration.from_file(rig)
    assert c.doffs == 1e-3 and c.K1[1, 1] == 500.0 and c.T[0] == -0.1


def test_a_plain_yaml_ending_in_a_document_marker_is_read(tmp_path: Path) -> None:
    """A plain YAML calibration ending in ``---`` (a second, empty document, as a topic echo
    or a concatenation leaves it) was "not a stereovision calibration file": yaml.load wants a
    single document. The first document is read."""
    rig = tmp_path / "rig.yaml"
    rig.write_text(
        "image_width: 640\nimage_height: 480\nunit: m\nD1: [0, 0, 0, 0, 0]\n"
        "D2: [0, 0, 0, 0, 0]\nK1: [[500, 0, 320], [0, 500, 240], [0, 0, 1]]\n"
        "K2: [[500, 0, 320], [0, 500, 240], [0, 0, 1]]\n"
        "R: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\nT: [-0.1, 0, 0]\n---\n"
    )
    c = Calibration.load(rig)
    assert c.K1[0, 0] == 500.0 and c.T[0] == -0.1


def test_a_plain_yaml_field_that_holds_itself_is_refused(tmp_path: Path) -> None:
    """A recursive YAML alias (``K1: &a [*a, *a]``) hung load: NumPy's cast of the list that
    holds itself went 32 levels deep. It is refused naming the field; an alias used twice
    (no cycle) reads as before."""
    body = (
        "image_width: 640\nimage_height: 480\nunit: m\nD1: &z [0, 0, 0, 0, 0]\nD2: *z\n"
        "K2: [[500, 0, 320], [0, 500, 240], [0, 0, 1]]\n"
        "R: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\nT: [-0.1, 0, 0]\n"
    )
    rig = tmp_path / "rig.yaml"
    rig.write_text(body + "K1: &a [*a, *a]\n")
    with pytest.raises(ValueError) as exc:
        Calibration.from_file(rig)
    assert str(exc.value) == (
        f"calibration file {rig}: K1 holds itself (a YAML alias inside its own anchor, "
        "'K1: &a [*a]'): write its numbers out"
    )
    rig.write_text(body + "K1: &k [&r [500, 0, 320], [0, 500, 240], [0, 0, 1]]\nM2: *k\n")
    assert Calibration.from_file(rig).K1[0, 0] == 500.0


def test_a_calibrate_report_given_as_a_calibration_is_named(tmp_path: Path) -> None:
    """``stereovision calibrate``'s report.json / report.yaml, given for the calibration beside
    them, was "is not a calibration: it has none of the fields ..." (JSON) or "unrecognised
    calibration format" (YAML); it is named a report and the calibration file pointed to."""
    import yaml

    from stereovision.calibrate import CalibrationReport

    c = raw_calib()
    report = {"rms": 0.3, "used_pairs": ["01"], "rejected_pairs": {}, "image_size": [64, 48]}
    report["calibration"] = {k: getattr(c, k).tolist() for k in ("K1", "D1", "K2", "D2", "R", "T")}
    assert set(report) - {"calibration"} <= set(CalibrationReport.__dataclass_fields__)
    (tmp_path / "report.json").write_text(json.dumps(report))
    (tmp_path / "report.yaml").write_text(yaml.safe_dump(report, sort_keys=False))
    for name in ("report.json", "report.yaml"):
        for read in (Calibration.from_file, Calibration.load):
            with pytest.raises(
                ValueError,
                match=rf"{name} is a `stereovision calibrate` report \(its figures\), not a "
                r"calibration: give the calibration file calibrate wrote \(its -o / --output",
            ):
                read(tmp_path / name)
