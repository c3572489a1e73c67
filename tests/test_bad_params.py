"""Every tuning parameter of every channel, the refinement and the plane fills, given a value
out of its range (negative, huge, NaN, infinite, of the wrong type), either works or raises
ValueError / TypeError naming the problem: never another exception, and never a process abort
(an allocation of terabytes from a huge bin count or disparity range ended the interpreter, and a
huge blur ran for minutes or raised cv2.error, before these checks existed)."""

from __future__ import annotations

import inspect
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import stereovision as sv
from stereovision import refine
from stereovision._validate import as_gray_float
from stereovision.io import load_scene
from stereovision.matching import fusion, gabor, hopfield, mcgm, planes, sgm

BAD_VALUES: list[Any] = [
    -1,
    0,
    0.5,
    1e-9,  # tiny and positive: a Gabor freq of 1e-9 asked for a 10^9 px envelope
    10**9,
    2**31 - 1,
    10**12,
    -(10**12),
    2**70,  # beyond 64 bits: the bindings' OverflowError, NumPy's "ufunc 'isfinite'" TypeError
    -(2**70),
    10**400,  # beyond a float: float()'s and the bindings' OverflowError
    float("nan"),
    float("inf"),
    "x",
    None,
]


@pytest.fixture(scope="module")
def crop(data_dir: Path) -> tuple[np.ndarray, np.ndarray]:
    """A 100 x 160 crop of cones: real texture, small enough for about 1500 calls."""
    s = load_scene(data_dir / "middlebury2003" / "cones")
    return s.left[100:200, 100:260], s.right[100:200, 100:260]


@pytest.fixture(scope="module")
def ctx(crop: tuple[np.ndarray, np.ndarray]) -> dict[str, Any]:
    """The crop, its grey pair and its Gabor map (the refinement's and the fills' input)."""
    gl, gr = (as_gray_float(a) for a in crop)
    g = gabor.gabor_disparity(gl, gr, max_disparity=32)
    return {"bgr": crop[0], "gl": gl, "gr": gr, "disp": g.disparity, "conf": g.confidence}


def _keyword_defaults(fn: Callable[..., Any], skip: set[str]) -> list[str]:
    sig = inspect.signature(fn)
    empty = inspect.Parameter.empty
    return [k for k, p in sig.parameters.items() if p.default is not empty and k not in skip]


Call = Callable[[dict[str, Any], dict[str, Any]], object]


def _on_pair(fn: Callable[..., object]) -> Call:
    """A channel called on the grey pair over 0..32 px with the keyword under test."""
    return lambda c, kw: fn(c["gl"], c["gr"], max_disparity=32, **kw)


CALLS: dict[str, tuple[list[str], Call]] = {
    "mcgm": (list(mcgm.DEFAULTS), _on_pair(mcgm.mcgm_match)),
    "hopfield": (list(hopfield.DEFAULTS), _on_pair(hopfield.hopfield_match)),
    "gabor": (list(gabor.DEFAULTS), _on_pair(gabor.gabor_disparity)),
    "sgm": (list(sgm.DEFAULTS), _on_pair(sgm.sgm_disparity)),
    # Its other keywords are on/off flags.
    "fuse_pair": (["min_disparity", "channels"], _on_pair(fusion.fuse_pair)),
    "refine": (
        [*refine.DEFAULTS, "min_disparity"],
        lambda c, kw: refine.refine_disparity(
            c["gl"], c["gr"], c["disp"], c["conf"], max_disparity=32, **kw
        ),
    ),
    "fill_planes": (
        ["passes", "blur", "max_residual"],
        lambda c, kw: planes.fill_planes(c["disp"], c["bgr"], **kw),
    ),
    "segments": (
        ["blur", "step", "offset", "k", "min_size"],
        lambda c, kw: planes.segments(c["bgr"], **kw),
    ),
    "plane_fill": (
        ["min_pixels", "max_residual", "lo", "hi"],
        lambda c, kw: planes.plane_fill(c["disp"], planes.segments(c["bgr"]), **kw),
    ),
    "side_fill": (["tau", "blur"], lambda c, kw: planes.side_fill(c["disp"], c["bgr"], **kw)),
    "interest_points": (
        ["rel_threshold", "nms_half", "tile", "floor_rel"],
        lambda c, kw: hopfield.interest_points(c["gl"], **kw),
    ),
    "fused_dense": (
        list(fusion.DENSE_DEFAULTS),
        lambda c, kw: fusion.fused_dense(c["disp"], c["conf"], c["disp"], guide=c["gl"], **kw),
    ),
    "fill_enclosed_far": (
        ["floor", "far", "jump", "ring"],
        lambda c, kw: fusion.fill_enclosed_far(c["disp"], c["gl"], **kw),
    ),
}


@pytest.mark.parametrize("what", list(CALLS))
def test_out_of_range_parameters_raise_value_or_type_error(what: str, ctx: dict[str, Any]) -> None:
    keys, call = CALLS[what]
    values = [*BAD_VALUES, ((10**9, 1),), ((-1, 5),)] if what == "fill_planes" else BAD_VALUES
    rejected = 0
    for key in keys:
        for value in values:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    call(ctx, {key: value})
            except (ValueError, TypeError):
                rejected += 1
            except Exception as exc:
                pytest.fail(f"{what}({key}={value!r}) raised {type(exc).__name__}: {exc}")
    # Most of these values are out of range for most keys: the checks are there, not bypassed.
    assert rejected > len(keys) * 3


#: (call, the message's start): an integer beyond 64 bits, each given where it reached the
#: native module (or NumPy, OpenCV) unchecked.
HUGE = 2**70
NAMED: list[tuple[Call, str]] = [
    (lambda c, kw: sv.depth_map(c["bgr"], c["bgr"], max_disparity=-HUGE), "max_disparity"),
    (
        lambda c, kw: sv.depth_map(c["bgr"], c["bgr"], max_disparity=32, min_disparity=HUGE),
        "max_disparity",
    ),
    (lambda c, kw: sv.depth_map(c["bgr"], c["bgr"], max_disparity=10**400), "max_disparity"),
    (lambda c, kw: hopfield.interest_points(c["gl"], nms_half=HUGE), "nms_half"),
    (lambda c, kw: hopfield.interest_points(c["gl"], tile=HUGE), "tile"),
    (lambda c, kw: hopfield.interest_points(c["gl"], nms_half=float("nan")), "nms_half"),
    (lambda c, kw: planes.segments(c["bgr"], blur=HUGE), "blur"),
    (lambda c, kw: planes.segments(c["bgr"], k=1.0, min_size=HUGE), "min_size"),
    (lambda c, kw: planes.side_fill(c["disp"], c["bgr"], blur=-HUGE), "blur"),
    (lambda c, kw: planes.fill_planes(c["disp"], c["bgr"], passes=((HUGE, 50),)), "passes"),
    (lambda c, kw: planes.fill_planes(c["disp"], c["bgr"], passes=((16, HUGE),)), "passes"),
    (lambda c, kw: gabor.gabor_disparity(c["gl"], c["gr"], max_disparity=10**400), "max_disp"),
    (
        lambda c, kw: gabor.gabor_disparity(c["gl"], c["gr"], max_disparity=32, min_disparity=HUGE),
        r"empty disparity range: max_disparity \(32\) must be larger than min_disparity",
    ),
    (
        lambda c, kw: gabor.gabor_disparity(c["gl"], c["gr"], max_disparity=32, lr_check=5),
        "lr_check",
    ),
    (
        lambda c, kw: fusion.fuse_pair(c["gl"], c["gr"], max_disparity=32, min_disparity=HUGE),
        r"empty disparity range: max_disparity \(32\) must be larger than min_disparity",
    ),
    (
        lambda c, kw: refine.refine_disparity(
            c["gl"], c["gr"], c["disp"], c["conf"], max_disparity=32, min_disparity=HUGE
        ),
        r"empty disparity range: max_disparity \(32\) must be larger than min_disparity",
    ),
    (
        lambda c, kw: refine.refine_disparity(
            c["gl"], c["gr"], c["disp"], c["conf"], max_disparity=32, win_radius=10**400
        ),
        "win_radius",
    ),
    (lambda c, kw: fusion.fused_dense(c["disp"], c["conf"], c["disp"], tau=10**400), "tau"),
    (lambda c, kw: fusion.fill_enclosed_far(c["disp"], c["gl"], ring=10**400), "ring"),
    # 10**400 where a float goes: float()'s or the binding's OverflowError
    (lambda c, kw: sgm.sgm_disparity(c["gl"], c["gr"], max_disparity=10**400), "max_disparity"),
    (lambda c, kw: gabor.gabor_disparity(c["gl"], c["gr"], max_disparity=32, freq=10**400), "freq"),
    (lambda c, kw: planes.side_fill(c["disp"], c["bgr"], tau=-(10**400)), "tau"),
    (lambda c, kw: mcgm.mcgm_match(c["gl"], c["gr"], max_disparity=32, sigmas=[10**400]), "sigmas"),
    # these four were the binding's bare "OverflowError: int too large to convert to float"
    (lambda c, kw: gabor.gabor_responses(c["gl"], freq=10**400), "freq"),
    (lambda c, kw: gabor.gabor_responses(c["gl"], theta_deg=-(10**400)), "theta_deg"),
    (lambda c, kw: gabor.gabor_responses(c["gl"], bandwidth_oct=10**400), "bandwidth_oct"),
    (lambda c, kw: mcgm.log_filter(c["gl"], 10**400), "sigma"),
    (
        lambda c, kw: gabor.gabor_disparity(
            c["gl"], c["gr"], max_disparity=32, orientations_deg=[0.0, 10**400]
        ),
        "orientations_deg",
    ),
]


@pytest.mark.parametrize("case", range(len(NAMED)))
def test_huge_integers_are_value_errors_naming_the_parameter(
    case: int, ctx: dict[str, Any]
) -> None:
    call, says = NAMED[case]
    with pytest.raises((ValueError, TypeError), match=f"^{says}"):
        call(ctx, {})


def test_huge_sizes_act_as_the_whole_image(ctx: dict[str, Any]) -> None:
    """A range, a window or a count beyond the image is the image (they overflowed the
    bindings' integers, or asked NumPy / OpenCV for a kernel of 2**71 px)."""
    gl, gr = ctx["gl"], ctx["gr"]
    w = gl.shape[1]
    ref = hopfield.hopfield_match(gl, gr, max_disparity=w)
    got = hopfield.hopfield_match(gl, gr, max_disparity=HUGE)
    assert len(got) == len(ref) > 0 and np.array_equal(got.xr, ref.xr)
    big = hopfield.interest_points(gl, nms_half=10**6, tile=10**6)
    assert len(hopfield.interest_points(gl, nms_half=HUGE // 2**40, tile=2**31 - 1)) == len(big)
    args = (ctx["disp"], ctx["conf"], ctx["disp"])
    a = fusion.fused_dense(*args, guide=gl, edge_radius=HUGE, speckle_area=1e30)
    b = fusion.fused_dense(*args, guide=gl, edge_radius=max(gl.shape), speckle_area=1.0)
    np.testing.assert_array_equal(a[0], b[0])
    assert np.isnan(a[0]).all()  # a speckle area above the image's: every region goes
    # a 50 x 80 part of the crop, which has floors to fill (26 px): a ring of the whole crop's
    # size took ~3 s a call
    d = np.where(np.isfinite(ctx["disp"]), ctx["disp"], 0).astype(np.float32)[25:75, 40:120]
    g = np.ascontiguousarray(gl[25:75, 40:120])
    far = fusion.fill_enclosed_far(d, g, ring=HUGE)
    near = fusion.fill_enclosed_far(d, g, ring=sum(g.shape))
    assert np.count_nonzero(near[0] != d) > 0
    np.testing.assert_array_equal(far[0], near[0])


@pytest.mark.parametrize("key", _keyword_defaults(sv.depth_map, {"calib", "progress"}))
def test_depth_map_keywords_out_of_range(key: str, crop: tuple[np.ndarray, np.ndarray]) -> None:
    for value in BAD_VALUES:
        kw: dict[str, Any] = {key: value}
        if key != "max_disparity":
            kw["max_disparity"] = 32
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sv.depth_map(*crop, **kw)
        except (ValueError, TypeError):
            pass
        except Exception as exc:
            pytest.fail(f"depth_map({key}={value!r}) raised {type(exc).__name__}: {exc}")


def test_rig_and_export_helpers_refuse_bad_values(crop: tuple[np.ndarray, np.ndarray]) -> None:
    """The calibration's size and ROS helpers, the depth filters, the voxel grid and the
    rectification check, given each bad value (and bad sizes and names): ValueError or
    TypeError only (an IndexError came from a one-element size or a string of names)."""
    from stereovision import export
    from stereovision.calibration import fit_to_frames
    from stereovision.rectification_check import check_rectification
    from tests.test_calibration import raw_calib

    c = raw_calib()
    pts = np.random.default_rng(0).normal(size=(50, 3))
    shapes: list[Any] = [(1,), (0, 0), (1, 1), (-5, 10), (2.5, 3), "lr", ("left", 3)]
    res = sv.depth_map(
        crop[0],
        crop[1],
        c.rectified_calibration().scaled_to((160, 100)),
        method="gabor",
        max_disparity=16,
    )
    calls: list[Callable[[Any], object]] = [
        c.scaled_to,
        lambda v: fit_to_frames(c, v),
        lambda v: c.to_ros(alpha=v),
        lambda v: c.to_ros(names=v),
        c.to_camera_frame,
        lambda v: export.voxel_downsample(pts, voxel=v),
        lambda v: check_rectification(crop[0], crop[1], tolerance=v),
        lambda v: res.filtered(max_depth=v),
        lambda v: res.filtered(min_depth=v, max_relative_sigma=v),
    ]
    n = 0
    for call in calls:
        for v in [*BAD_VALUES, *shapes]:
            try:
                call(v)
            except (ValueError, TypeError):
                pass
            n += 1
    assert n == len(calls) * (len(BAD_VALUES) + len(shapes))


def test_charuco_helpers_refuse_bad_values() -> None:
    """A ChArUco board's sizes, dictionary and layout, its images, the printable PNG and the
    renderer, given each bad value: ValueError or TypeError only."""
    from stereovision.charuco import CharucoBoard, board_png, find_charuco_corners, render_charuco

    board = CharucoBoard("7x5", 0.03, 0.02, "DICT_4X4_50", legacy=False)
    K = np.array([[300.0, 0, 80], [0, 300, 60], [0, 0, 1]])
    pose = (np.zeros(3), np.array([-0.1, -0.07, 0.5]))
    calls: list[Callable[[Any], object]] = [
        lambda v: CharucoBoard(v, 0.03, 0.02),
        lambda v: CharucoBoard("7x5", v, 0.02),
        lambda v: CharucoBoard("7x5", 0.03, v),
        lambda v: CharucoBoard("7x5", 0.03, v, "DICT_4X4_50").image(100),  # 1e-9: cv2.error
        lambda v: CharucoBoard("7x5", 0.03, 0.02, v),
        lambda v: find_charuco_corners(v, board),
        board.image,
        lambda v: board.image(100, margin=v),
        lambda v: board_png(board, v),
        lambda v: board_png(board, 0.03, dpi=v),
        lambda v: board_png((9, 6), v),
        lambda v: render_charuco(
            board, K, np.zeros(5), *pose, image_size=(160, 120), supersample=v
        ),
        lambda v: render_charuco(board, K, np.zeros(5), *pose, image_size=v),
        lambda v: render_charuco(
            board, K, np.zeros(5), *pose, image_size=(160, 120), pixels_per_square=v
        ),
    ]
    shapes: list[Any] = [(1,), (0, 0), (-5, 10), (2.5, 3), "lr", ("left", 3), np.zeros((2, 2, 7))]
    rejected = 0
    for call in calls:
        for v in [*BAD_VALUES, *shapes]:
            try:
                call(v)
            except (ValueError, TypeError):
                rejected += 1
            except Exception as exc:
                pytest.fail(f"{v!r}: {type(exc).__name__}: {exc}")
    assert rejected > len(calls) * 8


def test_wrong_objects_are_type_errors_naming_the_argument(tmp_path: Path) -> None:
    """None (or a string) where a calibration, a floor or a result goes: a TypeError naming
    the argument (they were AttributeErrors from deep inside)."""
    from stereovision import export
    from stereovision.evaluate import gt_depth
    from stereovision.ground import occupancy_grid
    from stereovision.triangulation import depth_from_disparity, reproject, triangulate

    d = np.ones((4, 4), np.float32)
    pts = np.zeros((4, 4, 3))
    cases: list[tuple[Callable[[], object], str]] = [
        (lambda: sv.fit_ground_plane(d, None), "calib: expected a stereovision.Calibration"),
        (lambda: gt_depth(d, None), "calib: expected a stereovision.Calibration"),
        (lambda: triangulate([1.0], [1.0], None), "calib: expected"),
        (lambda: depth_from_disparity(d, "rig.yaml"), r"calib: got the path 'rig\.yaml'"),
        (lambda: reproject(d, None), "calib: expected"),
        (lambda: sv.refine_rectification(d, d, None), "calib: expected"),
        (lambda: sv.obstacle_mask(pts, None), "plane: expected a stereovision.GroundPlane"),
        (lambda: occupancy_grid(pts, None), "plane: expected"),
        (lambda: sv.laser_scan(pts, None), "plane: expected"),
        (lambda: export.write_cloud_ply(tmp_path / "c.ply", "r"), "result: expected .*, got str"),
        (lambda: export.write_pcd(tmp_path / "c.pcd", None), "result: expected"),
        (lambda: export.write_npz(tmp_path / "c.npz", None), "result: expected"),
    ]  # fmt: skip
    for call, says in cases:
        with pytest.raises(TypeError, match=says):
            call()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "run", [hopfield.hopfield_match, hopfield.best_match, mcgm.mcgm_match], ids=lambda f: f.__name__
)
def test_a_range_beyond_a_float_is_named_by_its_size(run: Any, ctx: dict[str, Any]) -> None:
    """A max_disparity of -10**400, or one of 10**400 below a min_disparity of 10**401, was
    refused with all 400 digits on the error's one line; its size is shown."""
    gl, gr = ctx["gl"], ctx["gr"]
    with pytest.raises(ValueError) as err:
        run(gl, gr, max_disparity=-(10**400))
    assert str(err.value) == (
        "max_disparity must be a non-negative number of pixels, got a negative integer of 401 "
        "digits"
    )
    with pytest.raises(ValueError) as err:
        run(gl, gr, min_disparity=10**401, max_disparity=10**400)
    assert str(err.value) == (
        "max_disparity (an integer of 401 digits) must be >= min_disparity (an integer of 402 "
        "digits)"
    )
