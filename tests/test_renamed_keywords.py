"""One name per concept across the public API (the renames of 2026-12-04).

Each renamed keyword: the new name works without a warning, the old one gives the same value
with a DeprecationWarning naming both names at the caller's line, and both at once is a
TypeError naming both.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
import synthetic_scene as syn

import stereovision
from stereovision import export
from stereovision.baselines import row_fill
from stereovision.calibration import Calibration
from stereovision.capture import StereoCamera
from stereovision.evaluate import count_at_precision, depth_metrics, gt_depth, table1_report
from stereovision.matching.gabor import gabor_responses
from stereovision.matching.planes import fill_planes, plane_fill, side_fill
from stereovision.rosbag import BagCamera

NAN = np.nan
_DISP = np.array([[1.0, NAN, 5.0, 8.0], [2.0, 4.0, NAN, 6.0]], dtype=np.float32)
_GT_DISP = np.array([[1.5, 2.0, 2.0, NAN], [2.0, 4.5, 3.0, 6.0]], dtype=np.float32)
_DEPTH = np.array([[1.0, 2.0, NAN, 4.0], [5.0, 6.0, 7.0, 8.0]])
_GT_DEPTH = np.array([[1.1, 2.0, 3.0, 4.4], [NAN, 6.6, 7.0, 8.0]])
# a sloped disparity with holes and its image (a ramp): the plane fills have work to do
_RAMP = np.tile(np.arange(40, dtype=np.float32) / 4 + 5, (30, 1))
_HOLED = np.where(np.add.outer(np.arange(30), np.arange(40)) % 7 == 0, np.float32(NAN), _RAMP)
_IMAGE = np.tile(np.arange(40, dtype=np.uint8) * 6, (30, 1))


def _calib() -> Calibration:
    return Calibration.ideal((4, 2), 60.0, 0.1)


@dataclass
class Rename:
    """``func(*args, **kwargs, <name>=value)`` called with ``new`` and with ``old``."""

    func: Callable[..., Any]
    old: str
    new: str
    value: Callable[[Path], Any]  # given a folder of the test's own
    # the other positional arguments, given a folder of the test's own
    args: Callable[[Path], tuple[Any, ...]] = lambda _: ()
    kwargs: dict[str, Any] = field(default_factory=dict)
    # the deprecation message names the callable as this (a method: Class.method)
    called: str = ""
    # value is a folder to write in: a new one each call (value is then tmp_path / "new" or
    # "old"), the results compared by the files' names and contents
    folder: bool = False
    # how the two results are compared (default: _same, or _same_files for a folder)
    same: Callable[[Any, Any], None] | None = None

    def __str__(self) -> str:
        return f"{self.called or self.func.__name__}:{self.old}->{self.new}"


class _Cap:
    """A VideoCapture stand-in of 160x120 frames."""

    def isOpened(self) -> bool:
        return True

    def grab(self) -> bool:
        return True

    def retrieve(self) -> tuple[bool, np.ndarray]:
        return True, np.full((120, 160, 3), 90, np.uint8)

    def get(self, prop: int) -> float:
        return {cv2.CAP_PROP_FRAME_WIDTH: 160.0, cv2.CAP_PROP_FRAME_HEIGHT: 120.0}.get(prop, 0.0)

    def set(self, prop: int, value: float) -> bool:
        return False

    def release(self) -> None:
        pass


def _bag(folder: Path) -> tuple[Path]:
    """A ROS 2 bag of one 160x120 pair (written with test_rosbag_read's writer)."""
    pytest.importorskip("rosbags")
    from test_rosbag_read import T0, write_bag

    if (folder / "rig").exists():  # the test's second call
        return (folder / "rig",)
    frame = np.tile(np.arange(160, dtype=np.uint8)[None, :, None], (120, 1, 3))
    return (write_bag(folder / "rig", [(T0, frame, T0, frame)]),)


def _same_camera(a: Any, b: Any) -> None:
    """Two cameras asked the same size, whose first pairs are the same."""
    with a, b:
        assert a.requested_size == b.requested_size is not None
        fa, fb = a.read(), b.read()
        _same(fa.left, fb.left)
        _same(fa.right, fb.right)


def _written(name: str, text: str) -> Callable[[Path], Path]:
    """A file ``name`` of ``text`` in the test's folder."""

    def write(folder: Path) -> Path:
        (folder / name).write_text(text)
        return folder / name

    return write


_P2 = "7.2e+02 0 6.1e+02 4.5e+01 0 7.2e+02 1.7e+02 0 0 0 1 0"
_P3 = "7.2e+02 0 6.1e+02 -3.6e+02 0 7.2e+02 1.7e+02 0 0 0 1 0"
_CAM = (
    "  camera_model: pinhole\n  distortion_coeffs: [-0.1, 0.05, 0.001, 0.0]\n"
    "  distortion_model: radtan\n  intrinsics: [500.0, 500.0, 320.0, 240.0]\n"
    "  resolution: [640, 480]\n"
)
_CAMCHAIN = (
    f"cam0:\n{_CAM}cam1:\n  T_cn_cnm1:\n  - [1.0, 0.0, 0.0, -0.12]\n  - [0.0, 1.0, 0.0, 0.0]\n"
    f"  - [0.0, 0.0, 1.0, 0.0]\n  - [0.0, 0.0, 0.0, 1.0]\n{_CAM}"
)


def _same_files(a: dict[str, Path], b: dict[str, Path]) -> None:
    """Two ``{name: path}`` of files written: the same names, the same contents."""
    assert a.keys() == b.keys() and a
    for name in a:
        if name.endswith(".npz"):  # a zip: its entries' times may differ
            with np.load(a[name]) as x, np.load(b[name]) as y:
                assert x.files == y.files
                for k in x.files:
                    _same(x[k], y[k])
        else:
            assert a[name].read_bytes() == b[name].read_bytes(), name


def _same(a: Any, b: Any) -> None:
    """``a`` and ``b`` are the same value: arrays (NaN where NaN), dataclasses field by field."""
    if isinstance(a, np.ndarray):
        np.testing.assert_array_equal(a, b)
    elif hasattr(a, "__dataclass_fields__"):
        assert type(a) is type(b)
        for name in a.__dataclass_fields__:
            _same(getattr(a, name), getattr(b, name))
    elif isinstance(a, (tuple, list)):
        assert len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _same(x, y)
    elif isinstance(a, float) and np.isnan(a):
        assert isinstance(b, float) and np.isnan(b)
    else:
        assert a == b


RENAMES = [
    # ground truth: gt (as dense_metrics, sparse_metrics, count_at_precision, io.Scene.gt)
    # halved: e625fbe6 warns of a GT wider than the 4 px calibration (6 px), a fixed-point map
    Rename(gt_depth, "gt_disp", "gt", lambda _: _GT_DISP / 2, kwargs={"calib": _calib()}),
    Rename(depth_metrics, "depth_gt", "gt", lambda _: _GT_DEPTH, lambda _: (_DEPTH,)),
    Rename(table1_report, "depth_gt", "gt", lambda _: _GT_DEPTH, lambda _: (_DEPTH,)),
    # an estimate is named by its quantity (as dense_metrics' disparity): depth
    Rename(depth_metrics, "depth_est", "depth", lambda _: _DEPTH, kwargs={"gt": _GT_DEPTH}),
    Rename(table1_report, "depth_est", "depth", lambda _: _DEPTH, kwargs={"gt": _GT_DEPTH}),
    # a folder to write in: directory (as Calibration.save_ros, CalibrationReport.write,
    # capture.capture, OccupancyGrid.save)
    Rename(
        export.export_result,
        "out_dir",
        "directory",
        tuple,
        lambda _: (syn.depth_result(),),
        folder=True,
    ),
    # (width, height) of an image: image_size (as Calibration, Calibration.from_file, from_q,
    # from_kitti, ideal, scaled_to, render_plane, render_charuco)
    Rename(
        StereoCamera,
        "size",
        "image_size",
        lambda _: "160x120",
        lambda _: (_Cap(), _Cap()),
        same=_same_camera,
    ),
    Rename(BagCamera, "size", "image_size", lambda _: (80, 60), _bag, same=_same_camera),
    # a file to read: path (as Calibration.from_file, Calibration.load, Matches.from_csv,
    # BagCamera, io.imread, export.read_depth_png)
    Rename(
        Calibration.from_middlebury,
        "calib_txt",
        "path",
        lambda _: Path(stereovision.__file__).parent / "data" / "cones" / "calib.txt",
        called="Calibration.from_middlebury",
    ),
    Rename(
        Calibration.from_q,
        "q_file",
        "path",
        _written("Q.dat", "1 0 0 -32\n0 1 0 -24\n0 0 0 50\n0 0 10 0\n"),
        kwargs={"image_size": (64, 48)},
        called="Calibration.from_q",
    ),
    Rename(
        Calibration.from_kitti,
        "calib_file",
        "path",
        _written("000000.txt", f"P0: {_P2}\nP1: {_P3}\nP2: {_P2}\nP3: {_P3}\n"),
        kwargs={"image_size": (1242, 375)},
        called="Calibration.from_kitti",
    ),
    Rename(
        Calibration.from_kalibr,
        "camchain",
        "path",
        _written("camchain.yaml", _CAMCHAIN),
        called="Calibration.from_kalibr",
    ),
    # a bound in pixels: tolerance (as check_rectification, refine_rectification and
    # RectificationCheck.tolerance; triangulate's solver tol, with max_iter, stays scipy's)
    Rename(
        count_at_precision,
        "tol",
        "tolerance",
        lambda _: 3.0,
        lambda _: ([1.0, 2.0, 3.0, 0.0], [0.0, 1.0, 1.0, 0.0], [0.5, -1.0, 2.5, -1.9]),
        {"score": [4.0, 3.0, 2.0, 1.0], "gt": _GT_DISP, "target": 100.0},
    ),
    # an image: image (as find_corners, noise_sigma, fill_planes, interest_points)
    Rename(
        gabor_responses, "img", "image", lambda _: _IMAGE / np.float32(255), kwargs={"freq": 0.2}
    ),
    # disparity: disparity (as depth_from_disparity, dense_metrics, DepthResult.disparity)
    Rename(row_fill, "disp", "disparity", lambda _: _DISP),
    Rename(fill_planes, "disp", "disparity", lambda _: _HOLED, kwargs={"image": _IMAGE}),
    Rename(side_fill, "disp", "disparity", lambda _: _HOLED, kwargs={"image": _IMAGE}),
    Rename(
        plane_fill,
        "disp",
        "disparity",
        lambda _: _HOLED,
        kwargs={"labels": np.zeros((30, 40), int)},
    ),
]


@pytest.mark.parametrize("case", RENAMES, ids=str)
def test_old_keyword_warns_and_gives_the_same_value(case: Rename, tmp_path: Path) -> None:
    def value(which: str) -> Any:
        return tmp_path / which if case.folder else case.value(tmp_path)

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        new = case.func(*case.args(tmp_path), **case.kwargs, **{case.new: value("new")})
    with pytest.warns(DeprecationWarning) as caught:
        old = case.func(*case.args(tmp_path), **case.kwargs, **{case.old: value("old")})
    (case.same or (_same_files if case.folder else _same))(old, new)
    name = case.called or case.func.__name__
    assert len(caught) == 1
    assert str(caught[0].message) == (
        f"{name}(): the keyword {case.old}= is now {case.new}= ({case.old}= will be removed)"
    )
    assert caught[0].filename == __file__


@pytest.mark.parametrize("case", RENAMES, ids=str)
def test_old_and_new_keyword_together_is_a_type_error(case: Rename, tmp_path: Path) -> None:
    name = case.called or case.func.__name__
    value = tmp_path / "out" if case.folder else case.value(tmp_path)
    args = case.args(tmp_path)
    before = sorted(tmp_path.rglob("*"))
    both = {case.new: value, case.old: value}
    with pytest.raises(TypeError, match=rf"^{name}\(\) got {case.old}= and {case.new}="):
        case.func(*args, **case.kwargs, **both)
    assert sorted(tmp_path.rglob("*")) == before  # refused before anything was written


def test_two_renames_of_one_function_are_one_wrapper() -> None:
    """depth_metrics lost depth_est= and depth_gt=: both old names at once still work, each
    warned about at the caller's line (one wrapper frame, not one per rename)."""
    import inspect

    assert list(inspect.signature(depth_metrics).parameters) == ["depth", "gt"]
    new = depth_metrics(depth=_DEPTH, gt=_GT_DEPTH)
    with pytest.warns(DeprecationWarning) as caught:
        old = depth_metrics(depth_est=_DEPTH, depth_gt=_GT_DEPTH)
    _same(old, new)
    assert new.n == 6 and new.median_rel == pytest.approx(100 / 22)  # rel. errors 0, 0, 0, 1/11 x3
    assert sorted(str(w.message).split(":")[1] for w in caught) == [
        " the keyword depth_est= is now depth= (depth_est= will be removed)",
        " the keyword depth_gt= is now gt= (depth_gt= will be removed)",
    ]
    assert {w.filename for w in caught} == {__file__}
    with pytest.raises(TypeError, match=r"^depth_metrics\(\) got depth_gt= and gt="):
        depth_metrics(_DEPTH, _GT_DEPTH, depth_gt=_GT_DEPTH)


class _NoFormatCapture:
    """A source with the ``cv2.VideoCapture`` methods that reports no pixel format."""

    def isOpened(self) -> bool:
        return True

    def grab(self) -> bool:
        return True

    def retrieve(self) -> tuple[bool, np.ndarray]:
        return True, np.zeros((24, 32, 3), np.uint8)

    def get(self, _prop: int) -> float:
        return 0.0

    def set(self, _prop: int, _value: float) -> bool:
        return False

    def release(self) -> None:
        pass


def test_a_warning_of_a_renamed_init_is_at_the_callers_line() -> None:
    """StereoCamera's __init__ is wrapped for size= -> image_size=: the fourcc it did not get was
    said at the wrapper's line in _validate.py, not at the caller's (stacklevel counted one
    frame less)."""
    with pytest.warns(UserWarning, match="delivers no reported format") as caught:
        StereoCamera(_NoFormatCapture(), _NoFormatCapture(), fourcc="MJPG").close()
    assert [w.filename for w in caught] == [__file__, __file__]
    assert [str(w.message) for w in caught] == [
        f"{side} source _NoFormatCapture delivers no reported format, not 'MJPG'"
        for side in ("left", "right")
    ]


@pytest.mark.parametrize("size", [(0, 240), "320 by 240", (20000, 240)])
@pytest.mark.parametrize("keyword", ["image_size", "size"])
def test_a_bad_image_size_is_named_image_size(size: Any, keyword: str, tmp_path: Path) -> None:
    """StereoCamera's and BagCamera's requested size is image_size= now: a bad one was still
    called size (parse_size's name for the command line's --size), also when given as size=."""
    bag = tmp_path / "x.bag"
    bag.write_bytes(b"")  # the size is checked before the bag is read
    for open_it in (
        lambda: StereoCamera(_NoFormatCapture(), _NoFormatCapture(), **{keyword: size}),
        lambda: BagCamera(bag, **{keyword: size}),
    ):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # size=: tested above
            with pytest.raises(ValueError, match=r"^image_size: (expected WIDTHxHEIGHT|at most)"):
                open_it()
